//! Faces of the two operands that are the same polygon (a mesh with
//! itself, or with an edited copy of itself), and the cells where the two
//! surfaces are one: there the result is known without cutting anything.
//!
//! Where every face listed in a cell has its twin in the other operand
//! (the same plane, facing the same way, the same corners in the same
//! cyclic order), the two surfaces coincide in the cell, so the
//! difference of their winding numbers is one constant there; where it
//! is 0 (one exact winding number of each at a point of the cell), the
//! two solids are the same set in the cell. Then `a ∪ b` and `a ∩ b` are
//! `a` there, and `a − b` is empty: the cell keeps `a`'s faces and drops
//! `b`'s, or drops both, without clipping, and the octree does not split
//! it.

use bsp_core::internals::ConvexFace;
use bsp_core::par;
use rustc_hash::{FxHashMap, FxHashSet};
use smallvec::SmallVec;

use super::operands::Both;
use crate::Solid;
use crate::index::IBox;
use crate::solid::SolidFace;

/// No twin.
pub(super) const NONE: u32 = u32::MAX;

/// For each operand's faces `near` the shared box, by place there, the
/// place of its twin among the other's ([`NONE`] where it has none, or
/// where a face matches more than one: each twin is one face's).
pub(super) fn twins(solids: Both<&Solid>, near: &Both<Vec<u32>>) -> Both<Vec<u32>> {
    let key = |f: &SolidFace| {
        (0..f.corner_count()).fold(f.corner_count() as u64, |k, i| {
            k.wrapping_add(f.corner(i).to_point().approx_key())
        })
    };
    let mut by_key: FxHashMap<u64, SmallVec<[u32; 2]>> = FxHashMap::default();
    let keys_b = par::map_slice(&near.b, |&f| key(solids.b.face(f)));
    for (j, k) in keys_b.into_iter().enumerate() {
        by_key.entry(k).or_default().push(j as u32);
    }
    let mut twin_a = par::map_slice(&near.a, |&f| {
        let fa = solids.a.face(f);
        let Some(candidates) = by_key.get(&key(fa)) else {
            return NONE;
        };
        let mut same = candidates
            .iter()
            .filter(|&&j| same_polygon(fa, solids.b.face(near.b[j as usize])));
        match (same.next(), same.next()) {
            (Some(&j), None) => j,
            _ => NONE,
        }
    });
    // a face of b that two of a's repeat is nobody's twin
    let mut uses = vec![0u8; near.b.len()];
    for &j in twin_a.iter().filter(|&&j| j != NONE) {
        uses[j as usize] = uses[j as usize].saturating_add(1);
    }
    let mut twin_b = vec![NONE; near.b.len()];
    for (i, j) in twin_a.iter_mut().enumerate() {
        if *j != NONE {
            if uses[*j as usize] == 1 {
                twin_b[*j as usize] = i as u32;
            } else {
                *j = NONE;
            }
        }
    }
    Both {
        a: twin_a,
        b: twin_b,
    }
}

/// The faces of each operand that have a twin, by id.
pub(super) fn twinned(twins: &Both<Vec<u32>>, near: &Both<Vec<u32>>) -> Both<FxHashSet<u32>> {
    let ids = |t: &[u32], near: &[u32]| {
        (t.iter().zip(near))
            .filter(|(t, _)| **t != NONE)
            .map(|(_, &f)| f)
            .collect()
    };
    Both {
        a: ids(&twins.a, &near.a),
        b: ids(&twins.b, &near.b),
    }
}

/// Whether the two solids are one set in the cell `bx`, whose listed
/// faces `a` and `b` are all twins (`twin_a`, `twin_b` say which are): as
/// many of each, and the same winding number of both at the cell's low
/// corner (a grid point in it, displaced as [`Solid::winding`] does).
pub(super) fn one_set(
    solids: Both<&Solid>,
    bx: &IBox,
    (a, b): (&[u32], &[u32]),
    twin_a: impl Fn(u32) -> bool,
    twin_b: impl Fn(u32) -> bool,
) -> bool {
    if a.is_empty() || a.len() != b.len() {
        return false;
    }
    if !a.iter().all(|&f| twin_a(f)) || !b.iter().all(|&f| twin_b(f)) {
        return false;
    }
    let r = bx.0.map(|c| c as i32);
    solids.a.winding(r) == solids.b.winding(r)
}

/// The same polygon: the same plane, facing the same way, and the same
/// corners in the same cyclic order.
fn same_polygon(p: &SolidFace, q: &SolidFace) -> bool {
    let n = p.corner_count();
    if n != q.corner_count() || p.support() != q.support() {
        return false;
    }
    let first = p.corner(0).to_point();
    (0..n).any(|r| {
        q.corner(r).to_point().same_point(&first)
            && (1..n)
                .all(|i| (p.corner(i).to_point()).same_point(&q.corner((i + r) % n).to_point()))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use bsp_core::Polygon;

    fn solid(quads: &[Vec<[i32; 3]>], turned: bool) -> Solid {
        let polys = quads.iter().map(|q| {
            let p = Polygon::from_grid_points(q, 0).unwrap();
            if turned { p.flipped() } else { p }
        });
        Solid::from_polygons(polys.collect())
    }

    fn twins_of(a: &Solid, b: &Solid) -> Both<Vec<u32>> {
        let all: IBox = ([-100; 3], [100; 3]);
        let near = Both {
            a: a.faces_near(&all),
            b: b.faces_near(&all),
        };
        twins(Both { a, b }, &near)
    }

    /// The same box twice: every face has its twin, one to one; a face
    /// repeated in one operand is nobody's twin; faces turned around, or
    /// of another box, are not twins.
    #[test]
    fn twins_are_the_same_polygons_one_to_one() {
        let cube = bsp_fixtures::grid_cuboid([0; 3], [2; 3]);
        let a = solid(&cube, false);
        let t = twins_of(&a, &solid(&cube, false));
        assert!(t.a.iter().all(|&j| j != NONE) && t.b.iter().all(|&i| i != NONE));
        for (i, &j) in t.a.iter().enumerate() {
            assert_eq!(t.b[j as usize], i as u32);
        }
        let mut twice = cube.clone();
        twice.push(cube[0].clone());
        let t = twins_of(&a, &solid(&twice, false));
        assert_eq!(t.a.iter().filter(|&&j| j == NONE).count(), 1);
        assert_eq!(t.b.iter().filter(|&&i| i == NONE).count(), 2);
        let t = twins_of(&a, &solid(&cube, true));
        assert!(t.a.iter().all(|&j| j == NONE));
        let other = bsp_fixtures::grid_cuboid([0; 3], [3, 2, 2]);
        let t = twins_of(&a, &solid(&other, false));
        // the faces at x = 0, y = 0 and z = 0 differ in size but for the
        // one at x = 0, the same square
        assert_eq!(t.a.iter().filter(|&&j| j != NONE).count(), 1);
    }
}
