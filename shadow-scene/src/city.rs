//! A generated city block for sun studies: sixteen buildings of several
//! heights (flat-roofed blocks, gabled houses, towers), each its own group,
//! on a ground of square tiles, each tile a face (so that per-face hours
//! map the ground).

use glam::DVec3;

use crate::prim::{Builder, q3};
use crate::{Face, Mesh};

/// The block's side, metres: 4 × 4 plots of 30 m.
pub const CITY_SIDE: f64 = 120.0;

/// The city block with `tiles × tiles` ground tiles: `z` up, `+y` north,
/// the ground `[0, 120]²` at `z = 0`. Plot `(i, j)` (30 m square, west to
/// east and south to north) holds building `b{i}{j}`: a flat-roofed
/// block, a gabled house or a tower, its footprint and height from a
/// fixed pattern, so the scene is the same every time.
///
/// ```
/// let city = shadow_scene::city_block(10);
/// assert_eq!(city.groups.len(), 17); // 16 buildings and the ground
/// assert!(city.faces.len() > 100);
/// ```
pub fn city_block(tiles: u32) -> Mesh {
    let mut b = Builder::new();
    let plot = CITY_SIDE / 4.0;
    for i in 0..4u32 {
        for j in 0..4u32 {
            // a fixed pattern: kinds in turn, heights and setbacks varied
            let k = (i * 7 + j * 3) % 8;
            let (x0, y0) = (f64::from(i) * plot, f64::from(j) * plot);
            let inset = 4.0 + f64::from(k % 3) * 2.0;
            let (lo, hi) = (
                DVec3::new(x0 + inset, y0 + inset, 0.0),
                DVec3::new(x0 + plot - inset, y0 + plot - inset - 2.0, 0.0),
            );
            b.group(&format!("b{i}{j}"));
            match k {
                0 | 4 => {
                    // a tower
                    let h = 36.0 + f64::from(k) * 6.0;
                    b.cuboid(
                        lo + DVec3::new(3.0, 3.0, 0.0),
                        DVec3::new(hi.x - 3.0, hi.y - 3.0, h),
                    );
                }
                1 | 3 | 6 => {
                    // a gabled house, its ridge east to west
                    let (wall, ridge) = (6.0 + f64::from(k), 10.0 + f64::from(k));
                    let mid = (lo.y + hi.y) / 2.0;
                    let profile = [
                        DVec3::new(lo.x, lo.y, 0.0),
                        DVec3::new(lo.x, hi.y, 0.0),
                        DVec3::new(lo.x, hi.y, wall),
                        DVec3::new(lo.x, mid, ridge),
                        DVec3::new(lo.x, lo.y, wall),
                    ];
                    b.prism(&profile, DVec3::new(hi.x - lo.x, 0.0, 0.0));
                }
                _ => {
                    let h = 12.0 + f64::from(k) * 3.0;
                    b.cuboid(lo, DVec3::new(hi.x, hi.y, h));
                }
            }
        }
    }
    let mut mesh = b.finish();
    let ground = mesh.add_group("ground");
    let n = tiles.max(1);
    let step = CITY_SIDE / f64::from(n);
    let first = mesh.positions.len() as u32;
    for y in 0..=n {
        for x in 0..=n {
            let p = DVec3::new(f64::from(x) * step, f64::from(y) * step, 0.0);
            mesh.positions.push(q3(p));
        }
    }
    let at = |x: u32, y: u32| first + y * (n + 1) + x;
    for y in 0..n {
        for x in 0..n {
            mesh.faces.push(Face {
                vertices: vec![at(x, y), at(x + 1, y), at(x + 1, y + 1), at(x, y + 1)],
                line: 0,
                group: ground,
            });
        }
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_buildings_are_closed_and_the_tiles_cover_the_ground() {
        let city = city_block(7);
        assert_eq!(city.groups.len(), 17);
        for g in &city.groups[..16] {
            let (_, building) = city.split_off_group(g).unwrap();
            assert!(building.is_closed_oriented(), "{g}");
            assert!(building.signed_volume() > 1000.0, "{g}");
        }
        let (_, ground) = city.split_off_group("ground").unwrap();
        assert_eq!(ground.faces.len(), 49);
        let area: f64 = ground
            .face_loops()
            .iter()
            .map(|p| (p[1] - p[0]).cross(p[3] - p[0]).z)
            .sum();
        assert!((area - CITY_SIDE * CITY_SIDE).abs() < 1e-6, "{area}");
        // the same block every time
        assert_eq!(city_block(7), city);
    }
}
