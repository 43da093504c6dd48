//! Occluders a point may pass over when it looks at a light: the faces of
//! a closed solid it lies behind, for a point outside that solid.
//!
//! Let `x` be a point strictly outside a solid (not on its surface either)
//! and `l` any light point. If the open segment `(x, l)` runs through the
//! solid's inside, it enters it first through a face that `x` lies
//! strictly in front of (turned outward, the face's front is outside), at
//! a point after `x`. So the faces of the solid that `x` lies behind or on
//! hide nothing from `x` that its others do not, up to the light points
//! whose segment only grazes the surface, a set of no area: what `x` sees
//! of the light, by area, is the same without them. A point behind many
//! faces (the ground under a closed scan, seeing the scan's underside)
//! then clips the light by half as many cones.
//!
//! The solids are the parts [`bsp_core::certify_solid_parts`] certifies
//! (closed, oriented outward, embedded); a part lies in its box, so a
//! point strictly outside the box is outside it, and a point on the box's
//! side is outside it unless it lies on the part's faces there (the part
//! meets that plane only on its surface).

use bsp_core::{GridPoint, Plane, SolidParts};

use crate::area::Occluder;

/// Per blocker, the part and outward plane that let a point pass over it;
/// per certified part, where it lies.
pub(crate) struct SolidBacks {
    /// Per blocker: its part and its faces' plane, where every face merged
    /// into it is of one certified part and turned one way.
    of: Vec<Option<(u32, Plane)>>,
    /// Per part: its box and what it has on each of the box's six sides.
    parts: Vec<Option<PartBox>>,
}

/// A certified part's box, and per side of it (`2k` the low side of axis
/// `k`, `2k + 1` the high one) the convex hulls of its faces' corners on
/// that side (a corner, an edge or a whole face each).
struct PartBox {
    lo: GridPoint,
    hi: GridPoint,
    sides: [Vec<Vec<GridPoint>>; 6],
}

impl SolidBacks {
    /// For `blockers` made of `faces` (`sources[b]`: the faces of blocker
    /// `b`), `solids` being [`bsp_core::certify_solid_parts`] of `faces`.
    pub(crate) fn new(faces: &[Occluder], sources: &[Vec<u32>], solids: &SolidParts) -> Self {
        let of = sources
            .iter()
            .map(|from| {
                let (&first, rest) = from.split_first()?;
                let f = first as usize;
                solids.boundary(f)?;
                let (part, plane) = (solids.part(f), faces[f].plane());
                let alike = |&g: &u32| {
                    solids.part(g as usize) == part && faces[g as usize].plane() == plane
                };
                rest.iter().all(alike).then_some((part as u32, *plane))
            })
            .collect();
        let mut parts: Vec<Option<PartBox>> = (0..solids.len()).map(|_| None).collect();
        for (i, f) in faces.iter().enumerate() {
            let Some(b) = solids.boundary(i) else {
                continue;
            };
            let part = parts[solids.part(i)].get_or_insert_with(|| PartBox {
                lo: b.lo,
                hi: b.hi,
                sides: Default::default(),
            });
            for (s, side) in part.sides.iter_mut().enumerate() {
                let (k, at) = (s / 2, if s % 2 == 0 { b.lo[s / 2] } else { b.hi[s / 2] });
                let on: Vec<GridPoint> = (f.corners().iter())
                    .filter(|c| c[k] == at)
                    .copied()
                    .collect();
                if !on.is_empty() {
                    side.push(on);
                }
            }
        }
        SolidBacks { of, parts }
    }

    /// Blocker `b`'s part and outward plane, if a point outside the part
    /// may pass over `b` where it lies behind or on that plane.
    pub(crate) fn of(&self, b: usize) -> Option<(u32, Plane)> {
        self.of[b]
    }

    /// Whether `x` lies strictly outside part `part` (a part of some
    /// blocker's [`SolidBacks::of`]). Exact.
    pub(crate) fn outside(&self, part: u32, x: GridPoint) -> bool {
        let Some(b) = &self.parts[part as usize] else {
            return false;
        };
        if (0..3).any(|k| x[k] < b.lo[k] || x[k] > b.hi[k]) {
            return true;
        }
        // in the closed box: outside where it lies on a side and on none
        // of the part's faces there
        let Some(s) =
            (0..6).find(|&s| x[s / 2] == if s % 2 == 0 { b.lo[s / 2] } else { b.hi[s / 2] })
        else {
            return false;
        };
        !b.sides[s].iter().any(|hull| in_hull(hull, x, s / 2))
    }
}

/// Whether `x` lies in the convex hull of `hull`: one point, a segment's
/// two ends, or a convex polygon's corners in order, all with coordinate
/// `k` equal to `x`'s. Exact in `i128`.
fn in_hull(hull: &[GridPoint], x: GridPoint, k: usize) -> bool {
    let d = |a: GridPoint, b: GridPoint| [0, 1, 2].map(|i| i128::from(b[i]) - i128::from(a[i]));
    let cross = |u: [i128; 3], v: [i128; 3]| {
        [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ]
    };
    let dot = |u: [i128; 3], v: [i128; 3]| (0..3).map(|i| u[i] * v[i]).sum::<i128>();
    match hull {
        [] => false,
        [p] => *p == x,
        [a, b] => {
            let (u, v) = (d(*a, *b), d(*a, x));
            cross(u, v) == [0; 3] && (0..=dot(u, u)).contains(&dot(u, v))
        }
        _ => {
            // the polygon lies in the plane normal to axis `k`: every edge
            // turns `x` the way the polygon turns (or leaves it on the edge)
            let n = hull.len();
            let turn =
                |a: GridPoint, b: GridPoint, c: GridPoint| cross(d(a, b), d(a, c))[k].signum();
            let way = (0..n)
                .map(|i| turn(hull[i], hull[(i + 1) % n], hull[(i + 2) % n]))
                .find(|&t| t != 0)
                .unwrap_or(0);
            (0..n).all(|i| turn(hull[i], hull[(i + 1) % n], x) * way >= 0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hulls_hold_their_points_exactly() {
        // a corner, an edge and a square on the side z = 0
        assert!(in_hull(&[[1, 2, 0]], [1, 2, 0], 2));
        assert!(!in_hull(&[[1, 2, 0]], [1, 3, 0], 2));
        let edge = [[0, 0, 0], [4, 2, 0]];
        assert!(in_hull(&edge, [2, 1, 0], 2));
        assert!(in_hull(&edge, [4, 2, 0], 2));
        assert!(!in_hull(&edge, [6, 3, 0], 2));
        assert!(!in_hull(&edge, [2, 2, 0], 2));
        for square in [
            [[0, 0, 0], [4, 0, 0], [4, 4, 0], [0, 4, 0]],
            [[0, 4, 0], [4, 4, 0], [4, 0, 0], [0, 0, 0]],
        ] {
            assert!(in_hull(&square, [2, 2, 0], 2));
            assert!(in_hull(&square, [4, 1, 0], 2));
            assert!(in_hull(&square, [0, 0, 0], 2));
            assert!(!in_hull(&square, [5, 1, 0], 2));
            assert!(!in_hull(&square, [-1, -1, 0], 2));
        }
    }
}
