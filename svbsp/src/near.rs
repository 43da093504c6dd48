//! Which occluders may hide part of a light from which faces: a box of
//! each occluder's penumbra volume within the scene, and a uniform grid of
//! the faces' boxes to find the faces it meets, so a scene of `n` faces is
//! not `n²` pairs. Boxes only ever let through more pairs than the exact
//! tests keep: the exact signs decide (see [`crate::area`]).

use bsp_core::GridPoint;
use rayon::prelude::*;

use crate::area::{Box3, Occluder, Regions, grid_box, may_reach, overlap};
use crate::blockers::plane_key;
use crate::light::Light;

/// Per receiving face, the indices of the occluders not in its plane whose
/// penumbra volume (`regions`, per occluder; `None`: it hides nothing) may
/// meet it, in index order; and per occluder, a box of its penumbra
/// volume within the scene.
pub(crate) fn near_lists(
    lights: &[Light],
    faces: &[Occluder],
    (occluders, regions): (&[Occluder], &[Option<Regions>]),
) -> (Vec<Vec<u32>>, Vec<Box3>) {
    let exact: Vec<[[i64; 2]; 3]> = faces.iter().map(|f| grid_box(f.corners())).collect();
    let planes: Vec<_> = faces.iter().map(|f| plane_key(f.plane())).collect();
    let boxes: Vec<Box3> = exact
        .iter()
        .map(|b| b.map(|[lo, hi]| [lo as f64, hi as f64]))
        .collect();
    let Some(scene) = boxes.iter().copied().reduce(union) else {
        return (Vec::new(), Vec::new());
    };
    let grid = CellGrid::new(scene, &boxes);
    let reaches: Vec<Box3> = occluders
        .par_iter()
        .map(|f| penumbra_box(lights, f.corners(), scene))
        .collect();
    let mut pairs: Vec<(u32, u32)> = regions
        .par_iter()
        .enumerate()
        .flat_map_iter(|(j, r)| {
            let mut hit = Vec::new();
            if let Some(r) = r {
                let reach = reaches[j];
                let plane = plane_key(occluders[j].plane());
                grid.visit(reach, |i| {
                    let i = i as usize;
                    if planes[i] != plane
                        && overlap(&boxes[i], &reach)
                        && may_reach(&exact[i], &r.reach)
                    {
                        hit.push(i as u32);
                    }
                });
                hit.sort_unstable();
                hit.dedup();
            }
            hit.into_iter().map(move |i| (i, j as u32))
        })
        .collect();
    pairs.par_sort_unstable();
    let mut near = vec![Vec::new(); faces.len()];
    for (i, j) in pairs {
        near[i as usize].push(j);
    }
    (near, reaches)
}

fn union(a: Box3, b: Box3) -> Box3 {
    [0, 1, 2].map(|k| [a[k][0].min(b[k][0]), a[k][1].max(b[k][1])])
}

/// A box holding the part of occluder `o`'s penumbra volume inside
/// `scene`, widened a little against rounding. Every point of the volume
/// is `o + t(o − l)` for an occluder point `o`, a light point `l` and
/// `t ≥ 0` (for a direction `d`, `o − t d`), unless the light touches
/// the occluder (then it may be anywhere). With `D` the box of the
/// vectors `o − l`, along an axis on which `D` has one sign the point
/// leaves the scene once `t` passes a bound `T`, and the volume lies in
/// `box(O) + [0, T]·D`.
fn penumbra_box(lights: &[Light], o: &[GridPoint], scene: Box3) -> Box3 {
    let ob = grid_box(o).map(|[lo, hi]| [lo as f64, hi as f64]);
    let mut d = [[f64::INFINITY, f64::NEG_INFINITY]; 3];
    let mut touches = true;
    for l in lights {
        let (lo, hi) = match l {
            Light::Point(p) => {
                let p = p.map(f64::from);
                (p, p)
            }
            Light::Directional(v) => {
                touches = false;
                let v = v.map(|c| -f64::from(c));
                (v, v)
            }
        };
        for k in 0..3 {
            let (a, b) = match l {
                Light::Point(_) => (ob[k][0] - hi[k], ob[k][1] - lo[k]),
                Light::Directional(_) => (lo[k], hi[k]),
            };
            d[k] = [d[k][0].min(a), d[k][1].max(b)];
        }
    }
    // a light point on the occluder's box: the volume may be anywhere
    if touches {
        let lb = grid_box(
            &lights
                .iter()
                .filter_map(|l| match l {
                    Light::Point(p) => Some(*p),
                    Light::Directional(_) => None,
                })
                .collect::<Vec<_>>(),
        );
        let lb = lb.map(|[lo, hi]| [lo as f64, hi as f64]);
        if overlap(&lb, &ob) {
            return widen(scene, scene);
        }
    }
    let mut t = f64::INFINITY;
    for k in 0..3 {
        if d[k][0] > 0.0 {
            t = t.min((scene[k][1] - ob[k][0]) / d[k][0]);
        } else if d[k][1] < 0.0 {
            t = t.min((ob[k][1] - scene[k][0]) / -d[k][1]);
        }
    }
    let t = t.max(0.0) * (1.0 + 1e-9);
    let b = [0, 1, 2].map(|k| {
        if t.is_finite() {
            [
                ob[k][0] + t * d[k][0].min(0.0),
                ob[k][1] + t * d[k][1].max(0.0),
            ]
        } else {
            [f64::NEG_INFINITY, f64::INFINITY]
        }
    });
    widen(b, scene)
}

/// `b` within `scene`, widened by two grid units and a billionth of the
/// scene's size against rounding.
fn widen(b: Box3, scene: Box3) -> Box3 {
    [0, 1, 2].map(|k| {
        let m = 2.0 + 1e-9 * (scene[k][1] - scene[k][0]);
        [b[k][0].max(scene[k][0]) - m, b[k][1].min(scene[k][1]) + m]
    })
}

/// A uniform grid of cells over the scene, each listing the faces whose
/// box meets it.
struct CellGrid {
    lo: [f64; 3],
    size: [f64; 3],
    n: [usize; 3],
    cells: Vec<Vec<u32>>,
}

impl CellGrid {
    /// About one cell per face, cubes as far as the scene's shape allows.
    fn new(scene: Box3, boxes: &[Box3]) -> CellGrid {
        let extent = scene.map(|[lo, hi]| (hi - lo).max(1.0));
        let volume: f64 = extent.iter().product();
        let side = (volume / boxes.len().max(1) as f64).cbrt();
        let n = extent.map(|e| ((e / side).ceil() as usize).clamp(1, 512));
        let size = [0, 1, 2].map(|k| extent[k] / n[k] as f64);
        let mut grid = CellGrid {
            lo: scene.map(|[lo, _]| lo),
            size,
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
        let at = |k: usize, v: f64| {
            let c = ((v - self.lo[k]) / self.size[k]).floor();
            (c.max(0.0) as usize).min(self.n[k] - 1)
        };
        (
            [0, 1, 2].map(|k| at(k, b[k][0])),
            [0, 1, 2].map(|k| at(k, b[k][1])),
        )
    }

    /// Calls `f` with every face listed in a cell that `b` meets (a face
    /// may come more than once).
    fn visit(&self, b: Box3, mut f: impl FnMut(u32)) {
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
