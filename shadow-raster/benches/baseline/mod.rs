//! The ray-casting baseline of `bench rays` and the `shade` example: what
//! a renderer does instead of exact shadows. A median-split BVH over the
//! scene's triangles (in `f64` grid units, [`shadow_raster::TriangleBvh`])
//! and one any-hit shadow ray per sample point toward each light, with a
//! Möller–Trumbore test; the points are spread over the faces by area, as
//! the pixels of an image would be. The scenes are `bsp_fixtures::scenes`.

#![allow(dead_code, unreachable_pub, unused_imports, missing_docs)]

use bsp_core::{Grid, Polygon, import_faces};
use bsp_fixtures::Rng;
use glam::DVec3;
use rayon::prelude::*;
use svbsp::Light;

pub use bsp_fixtures::scenes::{SceneSpec, WorldLight, lights, scene};
pub use shadow_raster::TriangleBvh as Bvh;

/// The scenes on their grids: the `shadows` bench's own helper, shared.
#[path = "../../../svbsp/benches/common/mod.rs"]
mod on_grids;
pub use on_grids::{Prepared, prepare};

/// The scene's triangles in `f64` grid units (each convex polygon as a
/// fan), for the baseline.
pub fn triangles(polys: &[Polygon]) -> Vec<[DVec3; 3]> {
    let mut out = Vec::new();
    for p in polys {
        let v: Vec<DVec3> = p.vertices_f64().into_iter().map(DVec3::from).collect();
        for i in 1..v.len() - 1 {
            out.push([v[0], v[i], v[i + 1]]);
        }
    }
    out
}

/// `n` sample points spread over the triangles by area (as an image's
/// pixels land on the surfaces), each with its triangle's normal.
pub fn surface_samples(tris: &[[DVec3; 3]], n: usize, seed: u64) -> Vec<(DVec3, DVec3)> {
    let mut cum = Vec::with_capacity(tris.len());
    let mut total = 0.0;
    for t in tris {
        total += (t[1] - t[0]).cross(t[2] - t[0]).length();
        cum.push(total);
    }
    let mut rng = Rng::new(seed);
    (0..n)
        .map(|_| {
            let x = rng.f64() * total;
            let i = cum.partition_point(|&c| c < x).min(tris.len() - 1);
            let t = &tris[i];
            let (mut u, mut v) = (rng.f64(), rng.f64());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            let p = t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * v;
            let nrm = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
            (p, nrm)
        })
        .collect()
}

/// Self-intersection margin of the shadow rays, in grid units of distance
/// along the ray.
pub const RAY_EPS: f64 = 1.0;

/// One shadow-ray pass, as a renderer's: for every sample, a ray toward
/// each light in front of it (in `f64`), ignoring hits closer than
/// [`RAY_EPS`]; samples with the light behind are in attached shadow.
/// In parallel. Returns how many (sample, light) pairs are lit.
pub fn shadow_ray_pass(bvh: &Bvh, samples: &[(DVec3, DVec3)], lights: &[(bool, DVec3)]) -> usize {
    samples
        .par_chunks(4096)
        .map(|chunk| {
            let mut lit = 0;
            for (p, n) in chunk {
                for &(point, l) in lights {
                    let d = if point { l - *p } else { l };
                    if n.dot(d) <= 0.0 {
                        continue;
                    }
                    let tmin = RAY_EPS / d.length();
                    let tmax = if point { 1.0 } else { f64::INFINITY };
                    if !bvh.occluded(*p, d, tmin, tmax) {
                        lit += 1;
                    }
                }
            }
            lit
        })
        .sum()
}
