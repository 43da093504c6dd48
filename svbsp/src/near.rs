//! Which occluders may hide part of a light from which faces: a box of
//! each occluder's penumbra volume within the scene, and a uniform grid of
//! the faces' boxes to find the faces it meets, so a scene of `n` faces is
//! not `n²` pairs. Boxes only ever let through more pairs than the exact
//! tests keep: the exact signs decide (see [`crate::area`]).

use bsp_core::GridPoint;
use rayon::prelude::*;

use crate::area::{Box3, HalfSpaces, Occluder, Reach, Regions, grid_box, overlap};
use crate::blockers::plane_key;
use crate::light::Light;

/// Per receiving face, the indices of the occluders not in its plane whose
/// penumbra volume (`regions`, per occluder; `None`: it hides nothing) may
/// meet it, in index order; and per occluder, boxes of its penumbra and
/// umbra volumes within the scene ([`Reach`]).
pub(crate) fn near_lists(
    lights: &[Light],
    faces: &[Occluder],
    (occluders, regions): (&[Occluder], &[Option<Regions>]),
) -> (Vec<Vec<u32>>, Vec<Reach>) {
    let boxes: Vec<Box3> = faces.iter().map(|f| grid_box(f.corners())).collect();
    let planes: Vec<_> = faces.iter().map(|f| plane_key(f.plane())).collect();
    let Some(scene) = boxes.iter().copied().reduce(union) else {
        return (Vec::new(), Vec::new());
    };
    let grid = CellGrid::new(scene, &boxes);
    let reaches: Vec<Reach> = occluders
        .par_iter()
        .map(|f| {
            // the umbra lies in the shadow volume from every corner
            let umbra = lights
                .iter()
                .map(|l| penumbra_box(std::slice::from_ref(l), f.corners(), scene))
                .fold(scene, |a, b| {
                    [0, 1, 2].map(|k| [a[k][0].max(b[k][0]), a[k][1].min(b[k][1])])
                });
            [penumbra_box(lights, f.corners(), scene), umbra]
        })
        .collect();
    // per occluder the faces it may reach, then turned into per face the
    // occluders (in index order): four bytes a pair in each form, and each
    // occluder's list freed as it is turned
    let hits: Vec<Vec<u32>> = regions
        .par_iter()
        .enumerate()
        .map(|(j, r)| {
            let mut hit = Vec::new();
            if let Some(r) = r {
                let reach = reaches[j][0];
                let plane = plane_key(occluders[j].plane());
                grid.visit(reach, |i| {
                    let i = i as usize;
                    if planes[i] != plane
                        && overlap(&boxes[i], &reach)
                        && !outside(faces[i].corners(), &r.penumbra)
                    {
                        hit.push(i as u32);
                    }
                });
                hit.sort_unstable();
                hit.dedup();
                hit.shrink_to_fit();
            }
            hit
        })
        .collect();
    let mut counts = vec![0usize; faces.len()];
    for &i in hits.iter().flatten() {
        counts[i as usize] += 1;
    }
    let mut near: Vec<Vec<u32>> = counts.into_iter().map(Vec::with_capacity).collect();
    for (j, hit) in hits.into_iter().enumerate() {
        for i in hit {
            near[i as usize].push(j as u32);
        }
    }
    (near, reaches)
}

/// Whether grid points `corners` lie in the closed outside of one of the
/// half-spaces `hs` (a face there has no area inside the volume).
pub(crate) fn outside(corners: &[GridPoint], hs: &HalfSpaces) -> bool {
    hs.iter()
        .any(|(h, inside)| corners.iter().all(|&c| h.classify_grid(c) != *inside))
}

fn union(a: Box3, b: Box3) -> Box3 {
    [0, 1, 2].map(|k| [a[k][0].min(b[k][0]), a[k][1].max(b[k][1])])
}

/// A box holding the part of occluder `o`'s penumbra volume inside
/// `scene`, in exact integers. Every point of the volume is `o + t(o − l)`
/// for an occluder point `o`, a light point `l` and `t ≥ 0` (for a
/// direction `d`, `o − t d`), unless the light touches the occluder (then
/// it may be anywhere). With `D` the box of the vectors `o − l`, along an
/// axis on which `D` has one sign the point leaves the scene once `t`
/// passes a bound `T = num / den` (the least over such axes), and the
/// volume lies in `box(O) + [0, T]·D`, its bounds rounded outward.
fn penumbra_box(lights: &[Light], o: &[GridPoint], scene: Box3) -> Box3 {
    let ob = grid_box(o);
    let points: Vec<GridPoint> = lights
        .iter()
        .filter_map(|l| match l {
            Light::Point(p) => Some(*p),
            Light::Directional(_) => None,
        })
        .collect();
    // a light point on the occluder's box: the volume may be anywhere
    if !points.is_empty() && overlap(&grid_box(&points), &ob) {
        return scene;
    }
    let mut d = [[i64::MAX, i64::MIN]; 3];
    for l in lights {
        for k in 0..3 {
            let (a, b) = match l {
                Light::Point(p) => (ob[k][0] - i64::from(p[k]), ob[k][1] - i64::from(p[k])),
                Light::Directional(v) => (-i64::from(v[k]), -i64::from(v[k])),
            };
            d[k] = [d[k][0].min(a), d[k][1].max(b)];
        }
    }
    // T = num / den, den > 0; None: no bound
    let mut t: Option<(i128, i128)> = None;
    for k in 0..3 {
        let bound = if d[k][0] > 0 {
            Some((scene[k][1] - ob[k][0], d[k][0]))
        } else if d[k][1] < 0 {
            Some((ob[k][1] - scene[k][0], -d[k][1]))
        } else {
            None
        };
        if let Some((num, den)) = bound {
            let c = (i128::from(num.max(0)), i128::from(den));
            if t.is_none_or(|(n, m)| c.0 * m < n * c.1) {
                t = Some(c);
            }
        }
    }
    let Some((num, den)) = t else {
        return scene;
    };
    let b = [0, 1, 2].map(|k| {
        let lo = num * i128::from(d[k][0].min(0));
        let hi = num * i128::from(d[k][1].max(0));
        [
            ob[k][0] + lo.div_euclid(den) as i64,
            ob[k][1] - (-hi).div_euclid(den) as i64,
        ]
    });
    [0, 1, 2].map(|k| [b[k][0].max(scene[k][0]), b[k][1].min(scene[k][1])])
}

/// A uniform grid of cells over the scene, each listing the faces whose
/// box meets it. A coordinate's cell is `(v − lo)·n / extent`, rounded
/// down, in integers: it never decreases as `v` grows, so a box meets
/// every cell of every face box it meets.
pub(crate) struct CellGrid {
    lo: [i64; 3],
    extent: [i64; 3],
    n: [usize; 3],
    cells: Vec<Vec<u32>>,
}

impl CellGrid {
    /// About one cell per face, cubes as far as the scene's shape allows.
    pub(crate) fn new(scene: Box3, boxes: &[Box3]) -> CellGrid {
        let extent = scene.map(|[lo, hi]| hi - lo + 1);
        let volume: f64 = extent.iter().map(|&e| e as f64).product();
        let target = boxes.len().max(1) as f64;
        let mut side = (volume / target).cbrt();
        // a flat scene (one face's box) would get too many thin cells
        let n = loop {
            let n = extent.map(|e| ((e as f64 / side).ceil() as usize).clamp(1, 512));
            if (n[0] * n[1] * n[2]) as f64 <= 2.0 * target + 8.0 {
                break n;
            }
            side *= 1.25;
        };
        let mut grid = CellGrid {
            lo: scene.map(|[lo, _]| lo),
            extent,
            n,
            cells: vec![Vec::new(); n[0] * n[1] * n[2]],
        };
        for (i, b) in boxes.iter().enumerate() {
            let (lo, hi) = grid.range(*b);
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        let c = grid.cell([x, y, z]);
                        grid.cells[c].push(i as u32);
                    }
                }
            }
        }
        grid
    }

    fn cell(&self, c: [usize; 3]) -> usize {
        (c[0] * self.n[1] + c[1]) * self.n[2] + c[2]
    }

    /// The cells a box meets, per axis from and to (inclusive).
    fn range(&self, b: Box3) -> ([usize; 3], [usize; 3]) {
        let at = |k: usize, v: i64| {
            let off = i128::from(v.clamp(self.lo[k], self.lo[k] + self.extent[k] - 1) - self.lo[k]);
            (off * self.n[k] as i128 / i128::from(self.extent[k])) as usize
        };
        (
            [0, 1, 2].map(|k| at(k, b[k][0])),
            [0, 1, 2].map(|k| at(k, b[k][1])),
        )
    }

    /// Calls `f` with every face listed in a cell that `b` meets (a face
    /// may come more than once).
    pub(crate) fn visit(&self, b: Box3, mut f: impl FnMut(u32)) {
        let (lo, hi) = self.range(b);
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    self.cells[self.cell([x, y, z])].iter().for_each(|&i| f(i));
                }
            }
        }
    }
}
