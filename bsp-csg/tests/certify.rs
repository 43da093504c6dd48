//! `bsp_core::certify_solid_boundary` checked against exact winding
//! numbers: on surfaces it certifies, the winding number is never
//! negative and is 0 outside the box — what leaving out faces turned away
//! from a light relies on (`tiling`'s frames). The surfaces are UV spheres
//! on a coarse grid with every vertex moved at random, so that faces fold
//! over, pass through each other and turn inside out often.

use bsp_core::{Polygon, certify_solid_boundary};
use bsp_csg::Solid;
use bsp_fixtures::{self as shapes, GridPoint, Rng as SplitMix};

/// Loops of grid points as polygons.
fn polys(loops: &[Vec<GridPoint>]) -> Vec<Polygon> {
    loops
        .iter()
        .map(|l| Polygon::from_grid_points(l, 0).unwrap())
        .collect()
}

#[test]
fn certified_surfaces_have_no_negative_winding() {
    let mut rng = SplitMix(0xce27);
    let (mut certified, mut refused_negative) = (0, 0);
    for case in 0..200 {
        let jitter = 1 + case % 4;
        let mut polys = polys(&shapes::jittered_uv_sphere(48, 7.0, jitter, &mut rng));
        if case % 4 == 3 {
            // a second sphere, apart, overlapping or inside
            let off = (rng.next_u64() % 20) as i32 - 4;
            let other = shapes::jittered_uv_sphere(24, 3.0, 1, &mut rng);
            polys.extend(other.iter().map(|p| {
                let l: Vec<GridPoint> = p.iter().map(|g| [g[0] + off, g[1], g[2]]).collect();
                Polygon::from_grid_points(&l, 0).unwrap()
            }));
        }
        let cert = certify_solid_boundary(&polys);
        let solid = Solid::from_polygons(polys);
        let mut lowest = 0;
        for x in -12..=18 {
            for y in -12..=12 {
                for z in -12..=12 {
                    let w = solid.winding([x, y, z]);
                    lowest = lowest.min(w);
                    if let Ok(c) = &cert {
                        assert!(w >= 0, "case {case}: winding {w} at {x},{y},{z}");
                        if c.outside([x, y, z]) {
                            assert_eq!(w, 0, "case {case}: outside the box at {x},{y},{z}");
                        }
                    }
                }
            }
        }
        match cert {
            Ok(_) => certified += 1,
            Err(_) if lowest < 0 => refused_negative += 1,
            Err(_) => {}
        }
    }
    // both sides are exercised: certified surfaces, and refused ones that
    // do have negative winding somewhere
    assert!(certified >= 60, "{certified} certified");
    assert!(
        refused_negative >= 15,
        "{refused_negative} refused with negative winding"
    );
}

/// Surfaces that cross themselves along a diagonal of two faces
/// (`shapes::crossing_along_diagonal`): the winding number is `-1` inside
/// the inverted solid, and the certificate refuses them.
#[test]
fn crossings_along_diagonals_have_negative_winding_and_are_refused() {
    for seed in 0..60u64 {
        let c = shapes::crossing_along_diagonal(&mut SplitMix(seed));
        let (surface, solids) = (polys(&c.surface), c.solids.map(|s| polys(&s)));
        assert!(certify_solid_boundary(&surface).is_err(), "seed {seed}");
        let solid = Solid::from_polygons(surface);
        assert_eq!(solid.winding(c.negative), -1, "seed {seed}");
        assert_eq!(solid.winding(c.positive), 1, "seed {seed}");
        for s in solids {
            assert_eq!(certify_solid_boundary(&s).map(|b| b.parts), Ok(1));
        }
    }
}
