//! The culling certificate (`bsp_core::certify_solid_boundary`) on
//! decoded surfaces that fold, cross, nest and turn inside out: UV spheres
//! on a coarse grid with every vertex moved at random, a second one beside,
//! across or inside, and surfaces crossing along a shared diagonal. A
//! certified surface must have a winding number of at least 0 at every
//! grid point around it, and 0 outside its box (what leaving out faces
//! turned away from a light relies on); a diagonal crossing must be
//! refused. The fourth kind is two integer boxes, apart, touching,
//! overlapping or nested, the second sometimes turned inward, both
//! sheared by one integer shear and turned by one of the lattice's
//! rotations (faces that are not axis-aligned).

use bsp_core::{Polygon, certify_solid_boundary};
use bsp_csg::Solid;
use bsp_fixtures::{Loop, Rng, crossing_along_diagonal, jittered_uv_sphere};

use crate::boolean::shear;
use crate::bytes::Bytes;
use crate::report::fail;

fn polys(loops: &[Loop]) -> Vec<Polygon> {
    loops
        .iter()
        .filter_map(|l| Polygon::from_grid_points(l, 0).ok())
        .collect()
}

/// What a surface case was, for a failure's message.
#[derive(Debug)]
struct Case {
    seed: u64,
    kind: u8,
}

/// Decodes a surface from `data` (a kind and a seed) and checks the
/// certificate on it (see the module docs). Returns whether it was
/// certified.
///
/// ```
/// bsp_testkit::certify_case(b"any bytes at all");
/// bsp_testkit::certify_case(&[]);
/// ```
pub fn certify_case(data: &[u8]) -> bool {
    let mut b = Bytes { data };
    let case = Case {
        kind: b.u8() % 4,
        seed: b.u64(),
    };
    let mut rng = Rng(case.seed);
    if case.kind == 2 {
        let c = crossing_along_diagonal(&mut rng);
        if certify_solid_boundary(&polys(&c.surface)).is_ok() {
            fail(
                &case,
                format_args!("a crossing along a diagonal was certified"),
            );
        }
        return false;
    }
    let mut surface = match case.kind {
        3 => sheared_boxes(&mut rng),
        _ => {
            let n = 8 + (rng.next_u64() % 24) as usize;
            let jitter = 1 + (rng.next_u64() % 3) as i32;
            jittered_uv_sphere(n, 6.0, jitter, &mut rng)
        }
    };
    if case.kind == 1 {
        // a second sphere beside, across or inside the first
        let off = (rng.next_u64() % 17) as i32 - 4;
        let other = jittered_uv_sphere(12, 3.0, 1, &mut rng);
        surface.extend(
            other
                .iter()
                .map(|l| l.iter().map(|g| [g[0] + off, g[1], g[2]]).collect()),
        );
    }
    let polys = polys(&surface);
    let Ok(cert) = certify_solid_boundary(&polys) else {
        return false;
    };
    let solid = Solid::from_polygons(polys);
    for x in -10..=14 {
        for y in -10..=10 {
            for z in -10..=10 {
                let w = solid.winding([x, y, z]);
                if w < 0 {
                    fail(
                        &case,
                        format_args!("certified, yet winding {w} at {x},{y},{z}"),
                    );
                }
                if cert.outside([x, y, z]) && w != 0 {
                    fail(
                        &case,
                        format_args!("winding {w} outside the box at {x},{y},{z}"),
                    );
                }
            }
        }
    }
    true
}

/// Two integer boxes (the second turned inward one time in four), both
/// sheared by `x += a·y + b·z`, `y += c·z` with `a`, `b`, `c` in `-1..=1`,
/// then turned by one of the lattice's rotations (an even permutation of
/// the axes, two of them possibly negated).
fn sheared_boxes(rng: &mut Rng) -> Vec<Loop> {
    let mut r = |n: u64| (rng.next_u64() % n) as i32;
    let s = [r(3) - 1, r(3) - 1, r(3) - 1];
    let axes = [[0, 1, 2], [1, 2, 0], [2, 0, 1]][r(3) as usize];
    let signs = [[1, 1, 1], [-1, -1, 1], [-1, 1, -1], [1, -1, -1]][r(4) as usize];
    let turn = |p: [i32; 3]| [0, 1, 2].map(|i| signs[i] * p[axes[i]]);
    let mut loops = Vec::new();
    for k in 0..2 {
        let lo = [r(7) - 5, r(7) - 5, r(7) - 5];
        let hi = [0, 1, 2].map(|i| lo[i] + 1 + r(6));
        let inward = k == 1 && r(4) == 0;
        for mut quad in bsp_fixtures::grid_cuboid(lo, hi) {
            if inward {
                quad.reverse();
            }
            loops.push(quad.into_iter().map(|p| turn(shear(s, p))).collect());
        }
    }
    loops
}
