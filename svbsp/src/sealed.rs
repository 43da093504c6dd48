//! Lights sealed inside a closed part of the scene: whatever lies strictly
//! outside the solid the part bounds sees none of the light.
//!
//! A polygon light strictly inside the solid of a certified closed part
//! ([`bsp_core::certify_solid_parts`]) reaches a point strictly outside it
//! only along segments that cross the part's boundary, which is made of
//! occluders. So every face certified to lie strictly outside the solid
//! is umbra for that light, whole: the per-occluder tests of
//! [`crate::area`] would leave it undecided (every light corner hidden,
//! by different faces). Both are certified exactly
//! ([`PartShadows::placed`], the part's triangles indexed once): no
//! triangle of the light (or the face) meets a triangle of the part's
//! faces, and the part winds once round the light and not round the face.

use bsp_core::{GridPoint, SolidParts};
use rayon::prelude::*;

use crate::area::{AreaLight, Occluder};
use crate::boxes::{grid_box, overlap};
use crate::cores::{PartShadows, certified_parts};
use crate::light::Light;

/// At most this many pairs of (face near the part, part's face) are
/// tested exactly for faces whose box meets the enclosing part's: beyond
/// it only faces whose box is apart from the part's are certified (a cost
/// rule: the others are classified as any face is).
const MAX_PAIRS: usize = 50_000_000;

/// Per face, whether it lies strictly outside the solid of a closed part
/// that holds light `light` strictly inside: umbra for that light, whole.
/// Empty where no part holds the light (and for a sun disc, or a light of
/// one corner).
pub(crate) fn sealed_faces(
    light: &AreaLight,
    faces: &[Occluder],
    solids: &SolidParts,
) -> Vec<bool> {
    let corners: Option<Vec<GridPoint>> = light.corners().iter().map(Light::point).collect();
    let Some(corners) = corners.filter(|c| c.len() >= 3) else {
        return Vec::new();
    };
    let lb = grid_box(&corners);
    let contains = |b: &[[i64; 2]; 3]| (0..3).all(|k| b[k][0] < lb[k][0] && lb[k][1] < b[k][1]);
    let parts = certified_parts(faces, solids, 1);
    let Some((members, pb, shadows)) = parts.iter().find_map(|(m, b)| {
        if !contains(b) {
            return None;
        }
        let part: Vec<&[GridPoint]> = m.iter().map(|&i| faces[i].corners()).collect();
        let shadows = PartShadows::new(&part, 0);
        (shadows.placed(&corners) == Some(1)).then_some((m, b, shadows))
    }) else {
        return Vec::new();
    };
    let mut own = vec![false; faces.len()];
    for &i in members {
        own[i] = true;
    }
    let near = faces
        .iter()
        .filter(|f| overlap(&grid_box(f.corners()), pb))
        .count();
    let exact = near.saturating_mul(members.len()) <= MAX_PAIRS;
    faces
        .par_iter()
        .enumerate()
        .map(|(i, f)| {
            !own[i]
                && (!overlap(&grid_box(f.corners()), pb)
                    || exact && shadows.placed(f.corners()) == Some(0))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A light inside a closed tetrahedron seals off the faces outside
    /// its solid, both far off and within its box (certified exactly),
    /// not those inside it, crossing it or of the tetrahedron itself; a
    /// light outside it, or through its wall, seals nothing, nor does one
    /// in a tetrahedron turned inside out (it bounds no solid).
    #[test]
    fn a_light_in_a_closed_solid_seals_off_what_is_outside() {
        let (o, a, b, c) = ([-60; 3], [100, -60, -60], [-60, 100, -60], [-60, -60, 100]);
        let mut faces: Vec<Vec<GridPoint>> =
            vec![vec![o, b, a], vec![o, c, b], vec![o, a, c], vec![a, b, c]];
        faces.push(vec![
            [-200, -200, -100],
            [200, -200, -100],
            [200, 200, -100],
        ]); // far below
        faces.push(vec![[-50, -50, -45], [-30, -50, -45], [-50, -30, -45]]); // inside
        faces.push(vec![[-50, -50, 0], [60, -50, 0], [-50, 60, 0]]); // through the slope
        faces.push(vec![[50, 50, 50], [70, 50, 50], [50, 70, 50]]); // outside, in its box
        let occluders: Vec<Occluder> = faces.iter().map(|f| Occluder::new(f).unwrap()).collect();
        let polygons: Vec<bsp_core::Polygon> = occluders.iter().map(Occluder::to_polygon).collect();
        let solids = bsp_core::certify_solid_parts(&polygons);
        let lamp = |z: i32, h: i32| {
            AreaLight::new(&[
                [-h - 45, -h - 45, z],
                [-h - 45, h - 45, z],
                [h - 45, h - 45, z],
                [h - 45, -h - 45, z],
            ])
            .unwrap()
        };
        let sealed = sealed_faces(&lamp(-40, 5), &occluders, &solids);
        assert_eq!(
            sealed,
            [vec![false; 4], vec![true, false, false, true]].concat()
        );
        assert!(sealed_faces(&lamp(150, 5), &occluders, &solids).is_empty());
        assert!(sealed_faces(&lamp(-40, 40), &occluders, &solids).is_empty());
        let inverted: Vec<Occluder> = faces
            .iter()
            .map(|f| Occluder::new(&f.iter().rev().copied().collect::<Vec<_>>()).unwrap())
            .collect();
        let polygons: Vec<bsp_core::Polygon> = inverted.iter().map(Occluder::to_polygon).collect();
        let solids = bsp_core::certify_solid_parts(&polygons);
        assert!(sealed_faces(&lamp(-40, 5), &inverted, &solids).is_empty());
    }
}
