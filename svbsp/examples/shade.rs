//! Times the exact shadows of an OBJ/STL file phase by phase: load, snap
//! and import, shadow-volume trees, shading (fragments), for profiling.
//!
//! ```sh
//! cargo run --release -p svbsp --example shade -- scene.obj X,Y,Z [X,Y,Z ...] [sun:X,Y,Z ...]
//! ```

use std::time::Instant;

use bsp_core::import_faces;
use glam::DVec3;
use svbsp::{LightSpec, ShadeOptions, Shadows, place_lights, shared_grid};

fn vec3(s: &str) -> DVec3 {
    let v: Vec<f64> = s.split(',').map(|x| x.parse().expect("X,Y,Z")).collect();
    DVec3::new(v[0], v[1], v[2])
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = std::path::Path::new(&args[0]);
    let specs: Vec<LightSpec> = args[1..]
        .iter()
        .map(|a| match a.strip_prefix("sun:") {
            Some(d) => LightSpec::Sun(vec3(d)),
            None => LightSpec::Point(vec3(a)),
        })
        .collect();
    let t = Instant::now();
    let mesh = shadow_scene::load(path).expect("a mesh");
    let t_load = t.elapsed();
    let t = Instant::now();
    let grid = shared_grid(&mesh.positions, &specs).expect("a grid");
    let lights: Vec<_> = place_lights(&grid, &specs)
        .expect("lights")
        .into_iter()
        .map(|l| l.light)
        .collect();
    let loops = mesh.face_loops();
    let (polys, _) = import_faces(&grid, loops.iter().map(Vec::as_slice)).expect("import");
    let t_import = t.elapsed();
    let t = Instant::now();
    let shadows = Shadows::new(&polys, &lights).expect("trees");
    let t_trees = t.elapsed();
    let t = Instant::now();
    let batch = shadows.shade_all(&polys, &ShadeOptions::default().with_pieces(false));
    let t_shade = t.elapsed();
    let nodes: usize = shadows.volumes().iter().map(|v| v.node_count()).sum();
    let depth: usize = shadows
        .volumes()
        .iter()
        .map(|v| v.depth())
        .max()
        .unwrap_or(0);
    let holes: usize = batch.fragments().map(|f| f.hole_count()).sum();
    for v in shadows.volumes() {
        println!(
            "volumes: {} nodes, {} skeleton, {} grafted, depth {}",
            v.node_count(),
            v.skeleton_count(),
            v.grafted(),
            v.depth()
        );
    }
    println!(
        "{} faces, {} polygons, {} lights: {} fragments ({:.3} per face, {} holes), {} vertices; \
         {} tree nodes, depth {}",
        mesh.faces.len(),
        polys.len(),
        lights.len(),
        batch.len(),
        batch.len() as f64 / mesh.faces.len() as f64,
        holes,
        batch.vertex_count(),
        nodes,
        depth
    );
    println!(
        "load {:.1} ms, import {:.1} ms, trees {:.1} ms, shade {:.1} ms",
        t_load.as_secs_f64() * 1e3,
        t_import.as_secs_f64() * 1e3,
        t_trees.as_secs_f64() * 1e3,
        t_shade.as_secs_f64() * 1e3
    );
}
