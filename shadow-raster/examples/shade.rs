//! Times the exact shadows of a scene phase by phase (load, snap and
//! import, shadow-volume trees, shading), with the counts, and in the same
//! process the renderer's alternative: a BVH over the scene and one `f64`
//! shadow ray per sample point toward each light, for a given number of
//! points spread over the faces by area (a megapixel image's worth by
//! default). Used by `scripts/bench_shadows.sh` and for profiling.
//!
//! ```sh
//! cargo run --profile dist -p shadow-raster --example shade -- SCENE [X,Y,Z | sun:X,Y,Z]... [rays=N]
//! ```
//!
//! `SCENE` is a mesh file (`.obj`, `.stl`) or a built-in scene name
//! (`room`, `bunny-99k`, ...). Without lights, the bench's lights for the
//! scene are used (one key light).

#[path = "../benches/baseline/mod.rs"]
mod common;

use std::time::Instant;

use bsp_core::import_faces;
use glam::DVec3;
use svbsp::{LightSpec, LightVolumes, ShadeOptions, place_lights, shared_grid};

fn vec3(s: &str) -> DVec3 {
    let v: Vec<f64> = s.split(',').map(|x| x.parse().expect("X,Y,Z")).collect();
    DVec3::new(v[0], v[1], v[2])
}

fn ms(t: std::time::Duration) -> f64 {
    t.as_secs_f64() * 1e3
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(source) = args.first() else {
        eprintln!("usage: shade SCENE [X,Y,Z | sun:X,Y,Z]... [rays=N]");
        std::process::exit(2);
    };
    let mut rays = 1_000_000usize;
    let mut specs: Vec<LightSpec> = Vec::new();
    for a in &args[1..] {
        if let Some(n) = a.strip_prefix("rays=") {
            rays = n.parse().expect("rays=N");
        } else if let Some(d) = a.strip_prefix("sun:") {
            specs.push(LightSpec::Sun(vec3(d)));
        } else {
            specs.push(LightSpec::Point(vec3(a)));
        }
    }
    let t = Instant::now();
    let mesh = if source.contains('.') {
        shadow_scene::load(std::path::Path::new(source)).expect("a mesh")
    } else {
        shadow_scene::scene(source).expect("a built-in scene")
    };
    let t_load = t.elapsed();
    if specs.is_empty() {
        let spec = common::SceneSpec {
            name: source.clone(),
            faces: mesh.face_loops(),
        };
        for l in common::lights(&spec, 1) {
            specs.push(match l {
                common::WorldLight::Point(p) => LightSpec::Point(p),
                common::WorldLight::Sun(d) => LightSpec::Sun(DVec3::from_array(d.map(f64::from))),
            });
        }
    }
    let t = Instant::now();
    let grid = shared_grid(&mesh.positions, &specs).expect("a grid");
    let placed = place_lights(&grid, &specs).expect("lights");
    let lights: Vec<_> = placed.iter().map(|l| l.light).collect();
    let loops = mesh.face_loops();
    let (polys, _) = import_faces(&grid, loops.iter().map(Vec::as_slice)).expect("import");
    let t_import = t.elapsed();
    let t = Instant::now();
    let shadows = LightVolumes::new(&polys, &lights).expect("trees");
    let t_trees = t.elapsed();
    let t = Instant::now();
    let batch = shadows
        .set()
        .shade_all(&polys, &ShadeOptions::default().with_pieces(false));
    let t_shade = t.elapsed();
    let nodes: usize = shadows.volumes().iter().map(|v| v.node_count()).sum();
    let holes: usize = batch.fragments().map(|f| f.hole_count()).sum();
    println!(
        "{source}: {} faces, {} polygons, {} light(s): {} fragments ({:.3} per face, {holes} \
         holes), {nodes} shadow-tree nodes",
        mesh.faces.len(),
        polys.len(),
        lights.len(),
        batch.len(),
        batch.len() as f64 / mesh.faces.len() as f64,
    );
    println!(
        "exact:    load {:.1} ms, import {:.1} ms, trees {:.1} ms, shade {:.1} ms; shadows {:.1} ms",
        ms(t_load),
        ms(t_import),
        ms(t_trees),
        ms(t_shade),
        ms(t_trees + t_shade)
    );
    if rays > 0 {
        let lights_f64: Vec<(bool, DVec3)> = placed
            .iter()
            .map(|l| match l.light {
                svbsp::Light::Point(p) => (true, DVec3::from_array(p.map(f64::from))),
                svbsp::Light::Directional(d) => (false, DVec3::from_array(d.map(f64::from))),
            })
            .collect();
        let tris = common::triangles(&polys);
        let samples = common::surface_samples(&tris, rays, 0x5a3e);
        let t = Instant::now();
        let bvh = common::Bvh::build(&tris);
        let t_bvh = t.elapsed();
        let t = Instant::now();
        let lit = common::shadow_ray_pass(&bvh, &samples, &lights_f64);
        let t_rays = t.elapsed();
        println!(
            "baseline: BVH of {} triangles {:.1} ms, {rays} samples ({lit} lit) {:.1} ms; \
             together {:.1} ms",
            tris.len(),
            ms(t_bvh),
            ms(t_rays),
            ms(t_bvh + t_rays)
        );
        println!(
            "ratio:    exact shadows / baseline = {:.2}",
            (t_trees + t_shade).as_secs_f64() / (t_bvh + t_rays).as_secs_f64()
        );
    }
}
