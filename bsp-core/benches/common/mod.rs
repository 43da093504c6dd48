//! Scene generators shared by the benches: fixed seeds, everything built
//! in code (no data files).

#![allow(dead_code, unreachable_pub)]

use bsp_core::{BspTree, BuildOptions, Grid, Plane, Polygon, import_faces};
use glam::DVec3;

/// The generator every bench draws from.
pub use bsp_fixtures::Rng;

/// A generic plane through three random grid points of the full range
/// (coefficients near the budget).
pub fn random_plane(rng: &mut Rng, m: i32) -> Plane {
    loop {
        if let Ok(p) = Plane::through(rng.grid_point(m), rng.grid_point(m), rng.grid_point(m)) {
            return p;
        }
    }
}

/// `n` random triangles in the cube `[-1, 1]^3`, each with edges of about
/// `size` (in cube units).
pub fn soup_faces(n: usize, size: f64, seed: u64) -> Vec<[DVec3; 3]> {
    let mut rng = Rng::new(seed);
    (0..n)
        .map(|_| {
            let c = DVec3::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            );
            let u = rng.unit_vector();
            let w = u.any_orthonormal_vector();
            let v = u.cross(w);
            let a = rng.range(0.0, std::f64::consts::TAU);
            let p = |t: f64| c + (w * t.cos() + v * t.sin()) * size * 0.6;
            [p(a), p(a + 2.1), p(a + 4.2)]
        })
        .collect()
}

/// A random triangle soup of `n` triangles whose size shrinks with
/// `n^(-1/3)` (each triangle's edge is about half the mean spacing), so the
/// expected number of triangles a plane meets grows like `n^(2/3)`.
pub fn soup(n: usize, seed: u64) -> Vec<Polygon> {
    let size = (n as f64).powf(-1.0 / 3.0);
    import(&soup_faces(n, size, seed))
}

/// A closed torus (major radius 1, minor 0.4) of `2 u v` triangles,
/// consistently oriented outwards.
pub fn torus_faces(u: usize, v: usize) -> Vec<[DVec3; 3]> {
    bsp_fixtures::torus(u, v, 1.0, 0.4)
}

/// A torus of about `n` triangles (`u = 2 v`).
pub fn torus(n: usize) -> Vec<Polygon> {
    let v = ((n as f64 / 4.0).sqrt().round() as usize).max(3);
    import(&torus_faces(2 * v, v))
}

/// The grid every bench scene is snapped to: fitted to `[-1.5, 1.5]^3`.
pub fn grid() -> Grid {
    Grid::fit(DVec3::splat(-1.5), DVec3::splat(1.5)).expect("a finite box")
}

pub fn import(faces: &[[DVec3; 3]]) -> Vec<Polygon> {
    let (polys, _report) =
        import_faces(&grid(), faces.iter().map(|f| &f[..])).expect("faces inside the grid");
    polys
}

pub fn build(polys: Vec<Polygon>) -> BspTree {
    BspTree::build(polys, &BuildOptions::default())
}

#[allow(dead_code)]
pub fn import_loops(faces: &[Vec<DVec3>]) -> Vec<Polygon> {
    let (polys, _report) =
        import_faces(&grid(), faces.iter().map(|f| &f[..])).expect("faces inside the grid");
    polys
}
