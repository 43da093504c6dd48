//! Benches of the soft-shadow methods: the room under the 0.4 × 0.4
//! ceiling light of `docs/area-lights.md`, at 640×360, by the exact
//! method (fragments, then the exact share at every penumbra pixel)
//! against N exact point lights spread over the light (`sampled:N`) and
//! PCSS on a 2048² shadow map, in the same run. `shadow compare` prints
//! each method's error against exact for the same scene.

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec3;
use shadow_raster::{Camera, Method, RasterScene, RenderOptions, render_soft};
use svbsp::{SoftSpec, place_soft_lights, shared_soft_grid};

fn soft(cr: &mut Criterion) {
    let mesh = shadow_scene::scene("room").expect("a built-in scene");
    let light = SoftSpec::Area(
        [[0.7, 0.1], [0.7, 0.5], [1.1, 0.5], [1.1, 0.1]]
            .map(|[x, y]| DVec3::new(x, y, 2.45))
            .to_vec(),
    );
    let specs = std::slice::from_ref(&light);
    let grid = shared_soft_grid(&mesh.positions, &[], specs).unwrap();
    let lights = place_soft_lights(&grid, &[], specs).unwrap();
    let (polys, _) = bsp_core::import_faces_par(&grid, &mesh.face_loops()).unwrap();
    let scene = RasterScene::new(&grid, polys).unwrap();
    let (lo, hi) = mesh.bounds().unwrap();
    let eye = DVec3::new(3.3, -7.4, 4.3);
    let cam = Camera::look_at(eye, (lo + hi) * 0.5, DVec3::Z, 50.0, 640, 360).unwrap();
    let mut g = cr.benchmark_group("soft/room 640x360");
    g.sample_size(10).measurement_time(Duration::from_secs(8));
    for m in [
        Method::Exact,
        Method::Sampled(16),
        Method::Sampled(64),
        Method::Pcss,
    ] {
        let opts = RenderOptions::default().with_method(m);
        g.bench_function(m.to_string(), |b| {
            b.iter(|| black_box(render_soft(&scene, &lights, &cam, &[], &opts).unwrap()))
        });
    }
    g.finish();
}

criterion_group!(benches, soft);
criterion_main!(benches);
