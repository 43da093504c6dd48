//! The occluders that may hide part of a light from a face's points
//! ([`Hiders`]): for each point, those whose penumbra volume holds it,
//! found through their boxes, less the faces of closed solids the point
//! lies outside of and behind.

use std::borrow::Cow;

use bsp_core::{GridPoint, Plane, Side};
use rayon::prelude::*;

use super::PARALLEL_OCCLUDERS;
use crate::area::{HalfSpaces, Occluder, Regions};
use crate::backs::SolidBacks;
use crate::boxes::{Box3, CellGrid, grid_box, meet};
use crate::light::Light;
use crate::near::{InSlab, slab_box};

/// An occluder that may hide part of a light from a face's points, the
/// half-spaces of its penumbra volume a point must be tested against, and
/// a box holding every such point inside it.
///
/// With it, the part and outward plane of a closed solid's face that a
/// point outside the solid may pass over where it lies behind the face
/// ([`SolidBacks`]).
type Hider<'a> = (
    &'a Occluder,
    Cow<'a, [(Plane, Side)]>,
    Box3,
    Option<(u32, Plane)>,
);

/// Fragments of fewer corners than this have their probe points near
/// their face ([`Probing::NearFace`]); a face with a larger one is probed
/// as if its points lay anywhere.
pub(super) const MAX_PROBED_CORNERS: usize = 2048;

/// Where the points a face's [`Hiders`] are asked about lie.
#[derive(Clone, Copy)]
pub(super) enum Probing {
    /// Anywhere (the exact tests decide everything).
    Anywhere,
    /// Within 1 (a grid unit, per coordinate, strictly) of a point of the
    /// face, as the grid points nearest its fragments' corners and
    /// centroids are: a corner's `f64` coordinates are its exact ones
    /// correctly rounded (within `2^-27`: `|c| < 2^27`), a centroid of `n`
    /// of them summed and divided in `f64` is within `n² 2^-26` of the
    /// exact centroid of those (below 1/4 for fewer than
    /// [`MAX_PROBED_CORNERS`]), which lies in the fragment, and rounding
    /// to the grid moves a point by at most 1/2. With `slab`, the
    /// occluders are also boxed by what their volumes hold of the slab
    /// around the face's plane ([`slab_box`]).
    NearFace { slab: bool },
}

/// The occluders near a face that may hide part of one light from its
/// points, found through a grid of cells over the face's box holding
/// their penumbra volumes' boxes. For points near the face, each keeps
/// only the half-spaces of its penumbra volume that such points may fall
/// on either side of: one the whole face is outside drops the occluder,
/// one the whole face is inside needs no test.
pub(super) struct Hiders<'a> {
    occluders: Vec<Hider<'a>>,
    /// Their boxes in cells, where many points ask ([`FEW_POINTS`]);
    /// else each point passes over them all.
    grid: Option<CellGrid>,
    backs: &'a SolidBacks,
}

/// For at most this many points, a face's [`Hiders`] are passed over one
/// by one: a grid of their boxes costs more than it saves (a small face
/// of a scan under a near light has thousands, and four points).
const FEW_POINTS: usize = 16;

/// A face's near occluders with their volumes, boxes and
/// [`SolidBacks::of`], and the run's [`SolidBacks`].
pub(super) type Near<'a> = (
    Vec<(&'a Occluder, &'a Regions, Box3, Option<(u32, Plane)>)>,
    &'a SolidBacks,
);

impl<'a> Hiders<'a> {
    /// Whether [`Hiders::new`] for `points` points with
    /// [`Probing::NearFace`] `{ slab: true }` narrows the occluders' boxes
    /// to the slab round the face's plane ([`slab_box`]).
    pub(super) fn narrows(points: usize) -> bool {
        points > FEW_POINTS
    }

    /// The hiders of `face` among `occluders`, for `points` points
    /// `probing` says where.
    pub(super) fn new(
        face: &Occluder,
        light: &[Light],
        (occluders, backs): Near<'a>,
        (probing, points): (Probing, usize),
    ) -> Hiders<'a> {
        // points near the face lie within 1 of its box, and in the slab
        // of `slab_box` around its plane
        let face_box = grid_box(face.corners());
        let near = face_box.map(|[lo, hi]| [lo - 1, hi + 1]);
        let hider = |(o, r, b, back): (&'a Occluder, &'a Regions, Box3, _)| {
            // (for a few points, every half-space tested at each costs less
            // than finding those that matter near the face)
            let slab = match probing {
                Probing::NearFace { slab } if Hiders::narrows(points) => slab,
                _ => return Some((o, Cow::Borrowed(&r.penumbra[..]), b, back)),
            };
            let tests = face_tests(face.corners(), &r.penumbra)?;
            let b = match slab.then(|| slab_box(light, o.corners(), face.plane())) {
                Some(InSlab::Nothing) => return None,
                Some(InSlab::Within(s)) => meet(meet(b, s)?, near)?,
                Some(InSlab::Unbounded) | None => meet(b, near)?,
            };
            Some((o, Cow::Owned(tests), b, back))
        };
        // (a ground under a mesh has them all: in parallel, in order)
        let occluders: Vec<Hider<'a>> = match occluders.len() > PARALLEL_OCCLUDERS {
            true => occluders.into_par_iter().filter_map(hider).collect(),
            false => occluders.into_iter().filter_map(hider).collect(),
        };
        let boxes: Vec<Box3> = occluders.iter().map(|o| o.2).collect();
        Hiders {
            grid: (points > FEW_POINTS).then(|| CellGrid::new(face_box, &boxes)),
            occluders,
            backs,
        }
    }

    /// The occluders that hide some of the light from grid point `x`:
    /// those whose penumbra volume holds it strictly (and so their box
    /// does), in the near list's order, less the faces of closed solids
    /// `x` lies outside of and behind ([`SolidBacks`]): what `x` sees of
    /// the light, by area, is the same without them.
    pub(super) fn at(&self, x: GridPoint) -> Vec<&'a Occluder> {
        let at = x.map(i64::from);
        let mut found = Vec::new();
        // per part met: whether `x` lies outside it
        let mut outside: Vec<(u32, bool)> = Vec::new();
        let test = |i: u32| {
            let (o, tests, b, back) = &self.occluders[i as usize];
            let in_box = (0..3).all(|k| b[k][0] <= at[k] && at[k] <= b[k][1]);
            if !in_box || !tests.iter().all(|(h, s)| h.classify_grid(x) == *s) {
                return;
            }
            if let Some((part, plane)) = back
                && plane.classify_grid(x) != Side::Front
            {
                let out = match outside.iter().find(|p| p.0 == *part) {
                    Some(&(_, out)) => out,
                    None => {
                        let out = self.backs.outside(*part, x);
                        outside.push((*part, out));
                        out
                    }
                };
                if out {
                    return;
                }
            }
            found.push((i, *o));
        };
        match &self.grid {
            Some(grid) => grid.visit([0, 1, 2].map(|k| [at[k], at[k]]), test),
            None => (0..self.occluders.len() as u32).for_each(test),
        }
        // a point meets one cell, but keep the order whatever the grid
        found.sort_unstable_by_key(|&(i, _)| i);
        found.dedup_by_key(|&mut (i, _)| i);
        found.into_iter().map(|(_, o)| o).collect()
    }
}

/// Of the convex region `volume` (each plane's side holding it strictly),
/// the half-spaces a point within 1 per coordinate of the convex polygon
/// `face` may be outside of; `None` where every such point is outside one.
/// At `x = y + e` (`y` in the face, `|e_i| < 1`) a plane's value differs
/// from its value at `y` by `n · e`, less than `|n|_1` in size; its value
/// at `y` lies between its values at the face's corners. So corners all
/// beyond `|n|_1` on the inner side put every such point inside, and all
/// beyond it on the outer side put every one outside (exact, in `i128`:
/// `|n_i| < 2^63`, corners within `2^31`).
fn face_tests(face: &[GridPoint], volume: &HalfSpaces) -> Option<HalfSpaces> {
    let mut tests = Vec::new();
    for (h, s) in volume {
        let inward = match s {
            Side::Front => 1,
            Side::Back => -1,
            Side::On => {
                tests.push((*h, *s));
                continue;
            }
        };
        let n = h.normal();
        let margin: i128 = n.iter().map(|&c| i128::from(c).abs()).sum();
        let (mut inner, mut outer) = (true, true);
        for c in face {
            let v = inward
                * (0..3)
                    .map(|k| i128::from(n[k]) * i128::from(c[k]))
                    .sum::<i128>()
                + inward * h.offset();
            inner &= v > margin;
            outer &= v < -margin;
        }
        if outer {
            return None;
        }
        if !inner {
            tests.push((*h, *s));
        }
    }
    Some(tests)
}
