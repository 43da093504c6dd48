//! Making conflicting views agree (`--optimize`): the paper's inner loop.
//!
//! Where a view misses a wanted pixel, the hull must gain a point on the
//! line from the light through that pixel. Of the points of that line in
//! the bounds (sampled), the one whose shadows in the other views fall
//! nearest to their wanted regions is chosen (the sum of its pixels'
//! distances to them, from a distance transform), and each other view's
//! image gains the pixel that point's shadow falls in. The images grow
//! as little as that choice allows; the hull of the grown images is made
//! exactly again, and the rounds go on until every view misses at most
//! the target share of its (grown) wanted area, or nothing changes.
//!
//! Mitra & Pauly also deform the images as rigidly as possible (their
//! outer loop): with [`Optimize::deform_rounds`] above 0 that comes
//! first (`deform`), and growing then answers what is left.

use glam::DVec3;

use super::check::hull_coverage;
use super::deform::{Deformation, Moved};
use super::region::Mask;
use super::{ArtError, ArtLight, ArtSpec, ArtView, ShadowHull, ViewCheck, shadow_hull};

/// Points tried along each missed pixel's line.
const SAMPLES: usize = 64;

/// How one view's image grew.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Growth {
    /// Pixels added.
    pub pixels: usize,
    /// The largest distance of an added pixel from the image's original
    /// wanted region, in pixels.
    pub max_displacement: f64,
    /// Their mean distance, in pixels.
    pub mean_displacement: f64,
}

/// A shadow-art run: the views (grown, after [`optimize`]), their exact
/// hull and its check, and how the images grew.
#[derive(Debug)]
pub struct ArtRun {
    /// The spec, with the grown images after [`optimize`].
    pub spec: ArtSpec,
    /// The views' hull.
    pub hull: ShadowHull,
    /// Its check against the (grown) images.
    pub checks: Vec<ViewCheck>,
    /// After [`optimize`]: how the images grew.
    pub grown: Option<Grown>,
}

/// How [`optimize`] grew the images.
#[derive(Clone, Debug, PartialEq)]
pub struct Grown {
    /// Per view, how its image grew.
    pub growth: Vec<Growth>,
    /// Per view, the missing area before growing (of the hull of the
    /// images as given).
    pub missing_before: Vec<f64>,
    /// Rounds of growing.
    pub rounds: usize,
    /// With [`Optimize::deform_rounds`] above 0: how the images were
    /// deformed before they grew.
    pub deformed: Option<Deformed>,
}

/// How [`optimize_with`] deformed the images.
#[derive(Clone, Debug, PartialEq)]
pub struct Deformed {
    /// Per view, how far its image moved (zero for a view that missed
    /// nothing).
    pub views: Vec<Deformation>,
    /// Rounds of deforming kept (a round is kept only where it lowers the
    /// views' summed missing shares).
    pub rounds: usize,
}

/// How [`optimize_with`] makes the views agree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Optimize {
    /// Done when every view misses at most this share of its wanted area
    /// (e.g. 0.005).
    pub target: f64,
    /// Rounds of growing, at most.
    pub rounds: usize,
    /// Rounds of deforming before the growing, at most: 0 grows only.
    pub deform_rounds: usize,
}

/// The hull of `spec`'s views and its check, as given ([`ArtRun::grown`]
/// `None`).
pub fn run(spec: ArtSpec) -> Result<ArtRun, ArtError> {
    let hull = shadow_hull(&spec)?;
    let checks = hull.check(&spec)?;
    Ok(ArtRun {
        spec,
        hull,
        checks,
        grown: None,
    })
}

impl ArtRun {
    /// The views a run as given leaves missing more than `share` of their
    /// wanted area: the views that conflict.
    pub fn conflicts(&self, share: f64) -> Vec<usize> {
        (self.checks.iter().enumerate())
            .filter(|(_, c)| c.missing_area > share * c.wanted_area)
            .map(|(i, _)| i)
            .collect()
    }

    /// What `shadow art` says: the hull written to `output` (as
    /// `triangles` triangles), whether the images were simplified, then
    /// the [`summary`](Self::summary).
    pub fn said(&self, output: &std::path::Path, triangles: usize) -> String {
        let mut text = format!(
            "wrote {}: the shadow hull of {} views, {triangles} triangles, volume {}\n",
            output.display(),
            self.spec.views.len(),
            self.hull.hull.volume()
        );
        if let Some(px) = self.spec.simplify {
            text += &format!(
                "the wanted regions simplified within {px} px (the areas below are theirs)\n"
            );
        }
        text + &self.summary()
    }

    /// For people, one line per view (its areas, and how it grew), then
    /// the rounds of growing.
    pub fn summary(&self) -> String {
        let mut text = String::new();
        for (i, c) in self.checks.iter().enumerate() {
            text += &format!(
                "view {i}: wanted {:.6}, shadow {:.6}, missing {:.6} ({:.3}%), extra {:.3e}\n",
                c.wanted_area,
                c.shadow_area,
                c.missing_area,
                100.0 * c.missing_area / c.wanted_area,
                c.extra_area
            );
            if let Some(d) = self.grown.as_ref().and_then(|g| g.deformed.as_ref()) {
                let d = &d.views[i];
                text += &format!(
                    "  deformed by {:.2} px on average and {:.2} at most\n",
                    d.mean_displacement, d.max_displacement
                );
            }
            if let Some(g) = &self.grown {
                let (w, before) = (&g.growth[i], g.missing_before[i]);
                text += &format!(
                    "  grown by {} pixels, {:.2} px on average and {:.2} at most; missing \
                     before {before:.6}\n",
                    w.pixels, w.mean_displacement, w.max_displacement
                );
            }
        }
        if let Some(d) = self.grown.as_ref().and_then(|g| g.deformed.as_ref()) {
            text += &format!("{} rounds of deforming\n", d.rounds);
        }
        match &self.grown {
            Some(g) => text += &format!("{} rounds of growing\n", g.rounds),
            None if !self.conflicts(0.005).is_empty() => {
                text += "the views conflict: growing the images (optimizing) makes them agree\n"
            }
            None => {}
        }
        text
    }

    /// Writes each view's picture ([`ViewCheck::picture`]) as
    /// `view{i}.png` into `dir` (made if need be).
    pub fn write_pictures(&self, dir: &std::path::Path) -> std::io::Result<()> {
        std::fs::create_dir_all(dir)?;
        for (i, (v, c)) in self.spec.views.iter().zip(&self.checks).enumerate() {
            std::fs::write(dir.join(format!("view{i}.png")), c.picture(v).encode_png())?;
        }
        Ok(())
    }
}

/// Per pixel, the distance (in pixels, by the 3-4 chamfer metric, /3) to
/// the nearest wanted pixel; 0 on wanted pixels.
fn distances(mask: &Mask) -> Vec<f64> {
    let (w, h) = (mask.width as usize, mask.height as usize);
    let big = u32::MAX / 4;
    let mut d: Vec<u32> = mask
        .wanted
        .iter()
        .map(|&x| if x { 0 } else { big })
        .collect();
    let at = |x: usize, y: usize| y * w + x;
    for y in 0..h {
        for x in 0..w {
            let mut v = d[at(x, y)];
            if x > 0 {
                v = v.min(d[at(x - 1, y)] + 3);
            }
            if y > 0 {
                v = v.min(d[at(x, y - 1)] + 3);
                if x > 0 {
                    v = v.min(d[at(x - 1, y - 1)] + 4);
                }
                if x + 1 < w {
                    v = v.min(d[at(x + 1, y - 1)] + 4);
                }
            }
            d[at(x, y)] = v;
        }
    }
    for y in (0..h).rev() {
        for x in (0..w).rev() {
            let mut v = d[at(x, y)];
            if x + 1 < w {
                v = v.min(d[at(x + 1, y)] + 3);
            }
            if y + 1 < h {
                v = v.min(d[at(x, y + 1)] + 3);
                if x + 1 < w {
                    v = v.min(d[at(x + 1, y + 1)] + 4);
                }
                if x > 0 {
                    v = v.min(d[at(x - 1, y + 1)] + 4);
                }
            }
            d[at(x, y)] = v;
        }
    }
    d.into_iter().map(|v| f64::from(v) / 3.0).collect()
}

/// The pixel of `view`'s image that the shadow of point `x` falls in.
fn pixel_of(view: &ArtView, x: DVec3) -> Option<(u32, u32)> {
    let pl = view.plane;
    let n = pl.normal();
    let on_plane = match view.light {
        ArtLight::Sun(d) => x - d * ((x - pl.origin).dot(n) / d.dot(n)),
        ArtLight::Point(l) => {
            let k = (x - l).dot(n);
            if k == 0.0 {
                return None;
            }
            l + (x - l) * ((pl.origin - l).dot(n) / k)
        }
    };
    let (a, b) = pl.coords(on_plane);
    let (c, r) = (a.floor(), b.floor());
    let inside =
        c >= 0.0 && r >= 0.0 && c < f64::from(view.mask.width) && r < f64::from(view.mask.height);
    inside.then_some((c as u32, r as u32))
}

/// The points of the line from `view`'s light through the centre of
/// pixel `(c, r)` that lie in `bounds`, between the light and the plane:
/// [`SAMPLES`] of them, evenly spread.
fn line_samples(view: &ArtView, (c, r): (u32, u32), [lo, hi]: [DVec3; 2]) -> Vec<DVec3> {
    let p = view.plane.at(f64::from(c) + 0.5, f64::from(r) + 0.5);
    // the line p + t·dir, t in (0, t_max]: toward the light
    let (dir, t_max) = match view.light {
        ArtLight::Sun(d) => (d, f64::INFINITY),
        ArtLight::Point(l) => (l - p, 1.0),
    };
    let (mut t0, mut t1) = (0.0f64, t_max);
    for k in 0..3 {
        if dir[k] == 0.0 {
            if p[k] < lo[k] || p[k] > hi[k] {
                return Vec::new();
            }
            continue;
        }
        let (a, b) = ((lo[k] - p[k]) / dir[k], (hi[k] - p[k]) / dir[k]);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    if t0 >= t1 {
        return Vec::new();
    }
    (0..SAMPLES)
        .map(|i| p + dir * (t0 + (t1 - t0) * (i as f64 + 0.5) / SAMPLES as f64))
        .collect()
}

/// One round: for every pixel a view misses (its shadow covers less than
/// half of it), the other views' images gain the pixels of the best point
/// on its line. Returns how many pixels were added.
fn grow_round(
    spec: &mut ArtSpec,
    checks: &[ViewCheck],
    original: &[Vec<f64>],
    growth: &mut [Growth],
) -> usize {
    let dist: Vec<Vec<f64>> = spec.views.iter().map(|v| distances(&v.mask)).collect();
    let mut add: Vec<Vec<usize>> = vec![Vec::new(); spec.views.len()];
    for (k, (view, check)) in spec.views.iter().zip(checks).enumerate() {
        let w = view.mask.width;
        for (p, (&wanted, &cov)) in view.mask.wanted.iter().zip(&check.coverage).enumerate() {
            if !wanted || cov >= 0.5 {
                continue;
            }
            let pixel = (p as u32 % w, p as u32 / w);
            let mut best: Option<(f64, Vec<(usize, usize)>)> = None;
            for x in line_samples(view, pixel, spec.bounds) {
                let mut cost = 0.0;
                let mut pixels = Vec::new();
                for (j, other) in spec.views.iter().enumerate().filter(|&(j, _)| j != k) {
                    let Some((c, r)) = pixel_of(other, x) else {
                        cost = f64::INFINITY;
                        break;
                    };
                    let q = (r * other.mask.width + c) as usize;
                    cost += dist[j][q];
                    pixels.push((j, q));
                }
                if cost.is_finite() && best.as_ref().is_none_or(|b| cost < b.0) {
                    best = Some((cost, pixels));
                }
            }
            for (j, q) in best.map(|b| b.1).unwrap_or_default() {
                add[j].push(q);
            }
        }
    }
    let mut added = 0;
    for (j, qs) in add.into_iter().enumerate() {
        let mask = &mut spec.views[j].mask;
        for q in qs {
            if !mask.wanted[q] {
                mask.wanted[q] = true;
                added += 1;
                let g = &mut growth[j];
                let d = original[j][q];
                g.mean_displacement =
                    (g.mean_displacement * g.pixels as f64 + d) / (g.pixels + 1) as f64;
                g.pixels += 1;
                g.max_displacement = g.max_displacement.max(d);
            }
        }
    }
    added
}

/// Grows `spec`'s images until every view's hull shadow misses at most
/// `target` of its wanted area (e.g. 0.005), in at most `rounds` rounds
/// (see the module docs). The hull is exact in every round.
pub fn optimize(spec: &ArtSpec, target: f64, rounds: usize) -> Result<ArtRun, ArtError> {
    optimize_with(
        spec,
        Optimize {
            target,
            rounds,
            deform_rounds: 0,
        },
    )
}

/// Whether every view misses at most `target` of its wanted area.
fn met(checks: &[ViewCheck], target: f64) -> bool {
    (checks.iter()).all(|c| c.missing_area <= target * c.wanted_area)
}

/// The views' missing shares, summed.
fn missing(checks: &[ViewCheck]) -> f64 {
    checks.iter().map(|c| c.missing_area / c.wanted_area).sum()
}

/// The pixels of view `k`'s image that the other views allow: those the
/// hull of their cones (and the bounds) shadows at least half of. `None`
/// if that hull is empty.
fn allowed(spec: &ArtSpec, k: usize) -> Result<Option<Vec<bool>>, ArtError> {
    let mut others = spec.clone();
    let view = others.views.remove(k);
    let hull = match shadow_hull(&others) {
        Ok(h) => h,
        Err(ArtError::Empty) => return Ok(None),
        Err(e) => return Err(e),
    };
    let coverage = hull_coverage(&hull.hull.mesh().to_mesh(), &view, spec.bounds)?;
    Ok(Some(coverage.iter().map(|&c| c >= 0.5).collect()))
}

/// Makes `spec`'s views agree as `how` says: deforms the images that
/// miss shadow as rigidly as possible (the paper's outer loop; a round
/// kept only if the views then miss less), then grows them (the inner
/// loop) until every view misses at most `how.target` of its wanted
/// area. The hull is exact in every round.
pub fn optimize_with(spec: &ArtSpec, how: Optimize) -> Result<ArtRun, ArtError> {
    let mut spec = spec.clone();
    let original: Vec<Vec<f64>> = spec.views.iter().map(|v| distances(&v.mask)).collect();
    let mut growth = vec![Growth::default(); spec.views.len()];
    let mut hull = shadow_hull(&spec)?;
    let mut checks = hull.check(&spec)?;
    let missing_before = checks.iter().map(|c| c.missing_area).collect();
    let mut moved: Vec<Moved> = spec.views.iter().map(|v| Moved::new(&v.mask)).collect();
    let mut deform_rounds = 0;
    // each view's allowed pixels, kept while no other view changes (a
    // hull of the other views a view and round otherwise)
    let mut allowed_of: Vec<Option<Option<Vec<bool>>>> = vec![None; spec.views.len()];
    while deform_rounds < how.deform_rounds && !met(&checks, how.target) {
        let mut trial = (spec.clone(), moved.clone());
        let mut changed = vec![false; spec.views.len()];
        for (k, c) in checks.iter().enumerate() {
            if c.missing_area <= how.target * c.wanted_area {
                continue;
            }
            if allowed_of[k].is_none() {
                allowed_of[k] = Some(allowed(&spec, k)?);
            }
            let Some(Some(allowed)) = &allowed_of[k] else {
                continue;
            };
            if let Some(m) = moved[k].deformed(&c.coverage, allowed) {
                trial.0.views[k].mask = m.mask.clone();
                trial.1[k] = m;
                changed[k] = true;
            }
        }
        if !changed.contains(&true) {
            break;
        }
        let made = match shadow_hull(&trial.0) {
            Ok(h) => {
                let c = h.check(&trial.0)?;
                (missing(&c) < missing(&checks)).then_some((h, c))
            }
            Err(ArtError::Empty) => None,
            Err(e) => return Err(e),
        };
        let Some((h, c)) = made else { break };
        (spec, moved) = trial;
        (hull, checks) = (h, c);
        deform_rounds += 1;
        for (k, slot) in allowed_of.iter_mut().enumerate() {
            if (changed.iter().enumerate()).any(|(j, &c)| c && j != k) {
                *slot = None;
            }
        }
    }
    let mut done = 0;
    while done < how.rounds {
        if met(&checks, how.target) || grow_round(&mut spec, &checks, &original, &mut growth) == 0 {
            break;
        }
        hull = shadow_hull(&spec)?;
        checks = hull.check(&spec)?;
        done += 1;
    }
    let deformed = (how.deform_rounds > 0).then(|| Deformed {
        views: moved.iter().map(Moved::deformation).collect(),
        rounds: deform_rounds,
    });
    Ok(ArtRun {
        spec,
        hull,
        checks,
        grown: Some(Grown {
            growth,
            missing_before,
            rounds: done,
            deformed,
        }),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distances_are_chamfer_pixels() {
        let m = Mask {
            width: 4,
            height: 1,
            wanted: vec![true, false, false, false],
        };
        assert_eq!(distances(&m), [0.0, 1.0, 2.0, 3.0]);
    }
}
