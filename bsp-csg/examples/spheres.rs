//! Times the union of two UV spheres of about N triangles each (the inputs
//! of `scripts/manifold_compare.py`): snap and import, the Boolean, and the
//! output mesh.
//!
//! ```sh
//! cargo run --release -p bsp-csg --example spheres [N] [union|intersection|difference]
//! ```

use std::time::Instant;

use bsp_core::{BoolOp, Grid, import_faces_par};
use bsp_csg::Solid;
use bsp_fixtures::sphere_pair;
use glam::DVec3;

fn main() {
    let mut args = std::env::args().skip(1);
    let n: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(100_000);
    let op = match args.next().as_deref() {
        Some("intersection") => BoolOp::Intersection,
        Some("difference") => BoolOp::Difference,
        _ => BoolOp::Union,
    };
    let (va, vb, fa) = sphere_pair(n);
    let t = Instant::now();
    let grid = Grid::fit_points(va.iter().chain(&vb)).unwrap();
    let loops = |v: &[DVec3], f: &[Vec<u32>]| -> Vec<Vec<DVec3>> {
        f.iter()
            .map(|f| f.iter().map(|&i| v[i as usize]).collect())
            .collect()
    };
    let (pa, _) = import_faces_par(&grid, &loops(&va, &fa)).unwrap();
    let (pb, _) = import_faces_par(&grid, &loops(&vb, &fa)).unwrap();
    let t_import = t.elapsed();
    let t = Instant::now();
    let mut a = Solid::from_polygons(pa);
    let b = Solid::from_polygons(pb);
    let t_solid = t.elapsed();
    let t = Instant::now();
    let leaf = std::env::var("LEAF_SIZE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(bsp_csg::LEAF_SIZE);
    let stats = a
        .apply_with(&b, op, &bsp_csg::Options::default().with_leaf_size(leaf))
        .unwrap();
    let t_op = t.elapsed();
    let t = Instant::now();
    let mesh = a.to_mesh();
    let t_mesh = t.elapsed();
    println!(
        "{} triangles each, {op:?}: import {:.0} ms, solids {:.0} ms, boolean {:.0} ms, mesh {:.0} ms; \
         {} faces, {} triangles out",
        fa.len(),
        t_import.as_secs_f64() * 1e3,
        t_solid.as_secs_f64() * 1e3,
        t_op.as_secs_f64() * 1e3,
        t_mesh.as_secs_f64() * 1e3,
        a.len(),
        mesh.triangles.len()
    );
    println!(
        "cells {}, mixed {} (clean {}, easy {}, merged {}), cut faces {} into {} pieces",
        stats.cells,
        stats.mixed_cells,
        stats.clean_cells,
        stats.easy_cells,
        stats.merged_cells,
        stats.cut_faces,
        stats.pieces
    );
    mesh.check_watertight().unwrap();
}
