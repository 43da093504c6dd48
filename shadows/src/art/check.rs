//! The hull's shadows on each view's plane, cast by the exact engine and
//! measured against the view's wanted region.

use glam::DVec2;
use shadow_scene::{Face, Mesh};

use super::{ArtError, ArtLight, ArtSpec, ArtView, ShadowHull};
use crate::Light;

/// One view's shadow against its wanted region, in the plane's units².
#[derive(Clone, Debug, PartialEq)]
pub struct ViewCheck {
    /// The wanted region's area.
    pub wanted_area: f64,
    /// The area of the hull's shadow on the plane, within the image.
    pub shadow_area: f64,
    /// Wanted but not in shadow.
    pub missing_area: f64,
    /// In shadow but not wanted (0 up to rounding: the hull lies in the
    /// view's cone).
    pub extra_area: f64,
    /// Per pixel (row by row), the share of it in the hull's shadow.
    pub coverage: Vec<f32>,
    /// Per pixel, the share of it wanted: 0 or 1, but for a simplified
    /// region ([`ArtSpec::simplify`]), the share its polygons cover.
    pub wanted: Vec<f32>,
}

impl ViewCheck {
    /// The wanted pixels the shadow misses more than `share` of.
    pub fn missing_pixels(&self, view: &ArtView, share: f32) -> Vec<(u32, u32)> {
        let w = view.mask.width;
        (0..self.coverage.len())
            .filter(|&p| self.wanted[p] > 0.0 && self.coverage[p] < self.wanted[p] - share)
            .map(|p| (p as u32 % w, p as u32 / w))
            .collect()
    }
}

impl ShadowHull {
    /// Each view's check: the hull's shadow on its plane under its light
    /// (the exact fragments of [`crate::shadows`], the image's rectangle a
    /// receiver facing the light), measured per pixel in `f64`.
    pub fn check(&self, spec: &ArtSpec) -> Result<Vec<ViewCheck>, ArtError> {
        (spec.views.iter())
            .map(|v| self.check_view(v, spec))
            .collect()
    }

    fn check_view(&self, view: &ArtView, spec: &ArtSpec) -> Result<ViewCheck, ArtError> {
        let simplify = spec.simplify;
        let coverage = hull_coverage(&self.hull.mesh().to_mesh(), view, spec.bounds)?;
        let mask = &view.mask;
        let px = view.plane.normal().length();
        let (wanted, overlap, wanted_share) = match simplify {
            None => {
                let overlap: f64 = (coverage.iter().zip(&mask.wanted))
                    .filter(|(_, w)| **w)
                    .map(|(c, _)| c.min(1.0))
                    .sum::<f64>();
                let share = mask.wanted.iter().map(|&w| f32::from(u8::from(w)));
                (mask.count() as f64 * px, overlap * px, share.collect())
            }
            Some(tolerance) => {
                // the simplified polygons' share of each pixel; the
                // shadow overlaps it by at most the lesser of the two
                let share = simplified_coverage(view, tolerance)?;
                let overlap: f64 = (coverage.iter().zip(&share)).map(|(c, w)| c.min(*w)).sum();
                let wanted = share.iter().sum::<f64>() * px;
                (
                    wanted,
                    overlap * px,
                    share.iter().map(|&w| w as f32).collect(),
                )
            }
        };
        let shadow: f64 = coverage.iter().sum::<f64>() * px;
        Ok(ViewCheck {
            wanted_area: wanted,
            shadow_area: shadow,
            missing_area: (wanted - overlap).max(0.0),
            extra_area: (shadow - overlap).max(0.0),
            coverage: coverage.into_iter().map(|c| c.min(1.0) as f32).collect(),
            wanted: wanted_share,
        })
    }
}

impl ViewCheck {
    /// The view's picture: wanted and in shadow dark grey, wanted and
    /// missed red (by the share missed), in shadow but not wanted blue,
    /// the rest white.
    pub fn picture(&self, view: &ArtView) -> shadow_raster::Image {
        let (w, h) = (view.mask.width, view.mask.height);
        let mut img = shadow_raster::Image::new(w, h, [255, 255, 255]);
        for (p, (&c, &wanted)) in self.coverage.iter().zip(&self.wanted).enumerate() {
            let (c, wanted) = (f64::from(c), wanted >= 0.5);
            let mix = |a: [f64; 3], b: [f64; 3], t: f64| {
                std::array::from_fn::<u8, 3, _>(|k| (a[k] * t + b[k] * (1.0 - t)).round() as u8)
            };
            let px = if wanted {
                mix([70.0, 70.0, 70.0], [230.0, 40.0, 40.0], c)
            } else {
                mix([40.0, 90.0, 230.0], [255.0, 255.0, 255.0], c)
            };
            img.rgb[3 * p..3 * p + 3].copy_from_slice(&px);
        }
        img
    }
}

/// [`shadow_coverage`] of a mesh within `bounds` (a hull): where the
/// bounds reach the view's point light, the mesh may touch the light, and
/// a face through the light casts nothing (a cone's walls), so its shadow
/// is measured on the plane twice as far from the light, where every
/// pixel is the same pixel scaled by 2 and the faces on the view's plane
/// cast too.
pub(crate) fn hull_coverage(
    mesh: &Mesh,
    view: &ArtView,
    bounds: [glam::DVec3; 2],
) -> Result<Vec<f64>, ArtError> {
    match super::cone::reaches_light(view, bounds) {
        false => shadow_coverage(mesh, view),
        true => shadow_coverage(mesh, &doubled(view)),
    }
}

/// `view` (with a point light) on the plane twice as far from its light:
/// pixel `(c, r)` is the scaled copy of pixel `(c, r)` of `view`.
fn doubled(view: &ArtView) -> ArtView {
    let ArtLight::Point(l) = view.light else {
        return view.clone();
    };
    let mut v = view.clone();
    v.plane.origin = l + (view.plane.origin - l) * 2.0;
    (v.plane.u, v.plane.v) = (view.plane.u * 2.0, view.plane.v * 2.0);
    v
}

/// How much of each pixel of `view`'s image the shadow of `mesh` (a
/// closed surface or any faces) covers on the view's plane under the
/// view's light, row by row, in `[0, 1]`: the exact fragments of
/// [`crate::shadows`] with the image's rectangle a receiver facing the
/// light, measured per pixel in `f64`. Silhouettes of a mesh, or the
/// check of a hull.
pub fn shadow_coverage(mesh: &Mesh, view: &ArtView) -> Result<Vec<f64>, ArtError> {
    let mut mesh = mesh.clone();
    let (w, h) = (f64::from(view.mask.width), f64::from(view.mask.height));
    let pl = view.plane;
    let base = mesh.positions.len() as u32;
    mesh.positions
        .extend([pl.at(0.0, 0.0), pl.at(w, 0.0), pl.at(w, h), pl.at(0.0, h)]);
    let toward = match view.light {
        ArtLight::Sun(d) => d,
        ArtLight::Point(l) => l - pl.origin,
    };
    let mut receiver = vec![base, base + 1, base + 2, base + 3];
    if toward.dot(pl.normal()) < 0.0 {
        receiver.reverse();
    }
    let receiver_face = mesh.faces.len();
    mesh.faces.push(Face {
        vertices: receiver,
        line: 0,
        group: 0,
    });
    let light = match view.light {
        ArtLight::Sun(d) => Light::Sun(d),
        ArtLight::Point(p) => Light::Point(p),
    };
    let shadows = crate::shadows(&mesh, &[light]).map_err(ArtError::Shadows)?;
    let mask = &view.mask;
    let mut coverage = vec![0.0f64; mask.wanted.len()];
    for f in shadows
        .fragments()
        .filter(|f| f.face == receiver_face && f.lit & 1 == 0)
    {
        let rings: Vec<Vec<DVec2>> = f
            .rings
            .iter()
            .map(|r| r.iter().map(|&p| DVec2::from(pl.coords(p))).collect())
            .collect();
        cover(&rings, (mask.width, mask.height), &mut coverage);
    }
    Ok(coverage)
}

/// How much of each pixel of `view`'s image its wanted region, simplified
/// within `tolerance` pixels, covers.
fn simplified_coverage(view: &ArtView, tolerance: f64) -> Result<Vec<f64>, ArtError> {
    let mask = &view.mask;
    let parts = super::cone::wanted_region(view, Some(tolerance)).map_err(ArtError::Spec)?;
    let mut coverage = vec![0.0f64; mask.wanted.len()];
    for part in &parts {
        let rings: Vec<Vec<DVec2>> = (part.loop_ranges())
            .map(|r| {
                let ring = part.corners[r].iter();
                ring.map(|&[a, b]| DVec2::new(f64::from(a), f64::from(b)))
                    .collect()
            })
            .collect();
        cover(&rings, (mask.width, mask.height), &mut coverage);
    }
    Ok(coverage)
}

/// The silhouettes of `mesh` under three suns along the axes, each an
/// `n × n` image (the pixels its exact shadow covers at least half of,
/// [`shadow_coverage`]) on a wall a tenth of the mesh's size away from
/// it (`x`, `y`, `z` in that order), and bounds that much around the
/// mesh: a spec whose views agree but for pixelization.
pub fn axis_silhouettes(mesh: &Mesh, n: u32) -> Result<super::ArtSpec, ArtError> {
    use glam::DVec3;
    let (lo, hi) = mesh
        .bounds()
        .ok_or_else(|| ArtError::Spec("a mesh without faces has no silhouette".into()))?;
    let side = (hi - lo).max_element() * 1.1;
    let (px, gap) = (side / f64::from(n), 0.1 * side);
    let c = (lo + hi) * 0.5 - DVec3::splat(side / 2.0);
    let walls = [
        (
            DVec3::X,
            DVec3::new(lo.x - gap, c.y, c.z),
            DVec3::Y,
            DVec3::Z,
            "x",
        ),
        (
            DVec3::Y,
            DVec3::new(c.x, lo.y - gap, c.z),
            DVec3::Z,
            DVec3::X,
            "y",
        ),
        (
            DVec3::Z,
            DVec3::new(c.x, c.y, lo.z - gap),
            DVec3::X,
            DVec3::Y,
            "z",
        ),
    ];
    let views = walls
        .into_iter()
        .map(|(sun, origin, u, v, name)| {
            let wanted = vec![false; n as usize * n as usize];
            let mut view = ArtView {
                image: format!("{name}.pgm").into(),
                light: ArtLight::Sun(sun),
                plane: super::ViewPlane {
                    origin,
                    u: u * px,
                    v: v * px,
                },
                mask: super::Mask {
                    width: n,
                    height: n,
                    wanted,
                },
            };
            let cover = shadow_coverage(mesh, &view)?;
            view.mask.wanted = cover.iter().map(|&c| c >= 0.5).collect();
            Ok(view)
        })
        .collect::<Result<_, ArtError>>()?;
    let margin = DVec3::splat(gap / 2.0);
    Ok(super::ArtSpec {
        views,
        bounds: [lo - margin, hi + margin],
        simplify: None,
    })
}

/// Adds to `coverage` (per pixel of a `w × h` image) the area of each
/// pixel square that the polygon of `rings` (pixel coordinates; holes
/// turning against the outer ring) covers.
fn cover(rings: &[Vec<DVec2>], (w, h): (u32, u32), coverage: &mut [f64]) {
    let (mut lo, mut hi) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
    for p in rings.iter().flatten() {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let c0 = (lo.x.floor().max(0.0)) as u32;
    let r0 = (lo.y.floor().max(0.0)) as u32;
    let c1 = (hi.x.ceil().min(f64::from(w))) as u32;
    let r1 = (hi.y.ceil().min(f64::from(h))) as u32;
    let total: f64 = rings.iter().map(|r| signed_area(r)).sum();
    let sign = if total < 0.0 { -1.0 } else { 1.0 };
    // row by row: each ring clipped to the row's strip once, then the
    // strip's small polygon to each pixel of the row
    for r in r0..r1 {
        let y = f64::from(r);
        for ring in rings {
            let strip = clip(&clip(ring, 1, y, false), 1, y + 1.0, true);
            if strip.len() < 3 {
                continue;
            }
            let (x0, x1) = strip
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                    (a.min(p.x), b.max(p.x))
                });
            let (x0, x1) = (
                (x0.floor().max(f64::from(c0))) as u32,
                (x1.ceil().min(f64::from(c1))) as u32,
            );
            for c in x0..x1 {
                let x = f64::from(c);
                let piece = clip(&clip(&strip, 0, x, false), 0, x + 1.0, true);
                coverage[(r * w + c) as usize] += sign * signed_area(&piece);
            }
        }
    }
}

/// The signed area of a polygon.
fn signed_area(p: &[DVec2]) -> f64 {
    let n = p.len();
    (0..n).map(|i| p[i].perp_dot(p[(i + 1) % n])).sum::<f64>() / 2.0
}

/// The part of `poly` on one side of the line `axis = bound` (`below`:
/// where the coordinate is at most `bound`), by Sutherland–Hodgman: a
/// polygon of any shape keeps its signed area.
fn clip(poly: &[DVec2], axis: usize, bound: f64, below: bool) -> Vec<DVec2> {
    let coord = |p: DVec2| if axis == 0 { p.x } else { p.y };
    let inside = |p: DVec2| {
        if below {
            coord(p) <= bound
        } else {
            coord(p) >= bound
        }
    };
    let mut out = Vec::with_capacity(poly.len() + 2);
    for (i, &a) in poly.iter().enumerate() {
        let b = poly[(i + 1) % poly.len()];
        if inside(a) {
            out.push(a);
        }
        if inside(a) != inside(b) {
            out.push(a + (b - a) * ((bound - coord(a)) / (coord(b) - coord(a))));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_triangle_covers_half_a_pixel() {
        let tri = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(0.0, 1.0),
        ];
        let mut cov = vec![0.0; 4];
        cover(&[tri], (2, 2), &mut cov);
        assert_eq!(cov, [0.5, 0.0, 0.0, 0.0]);
        // a square ring with a hole turning the other way
        let outer = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(2.0, 0.0),
            DVec2::new(2.0, 2.0),
            DVec2::new(0.0, 2.0),
        ];
        let hole = vec![
            DVec2::new(0.5, 0.5),
            DVec2::new(0.5, 1.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(1.0, 0.5),
        ];
        let mut cov = vec![0.0; 4];
        cover(&[outer, hole], (2, 2), &mut cov);
        assert_eq!(cov, [0.75, 1.0, 1.0, 1.0]);
    }
}
