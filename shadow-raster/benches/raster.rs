//! Benches of `shadow-raster` on the 100k-face scanned bunny at 1920×1080
//! (the goal: a frame with z-buffer and a 2048² shadow map in at
//! most 30 ms), with the phases apart, and the same frame at 960×540.
//!
//! A frame is visibility, shadows and shading, the scene already loaded
//! (also frame after frame in one `Renderer`, which keeps its buffers);
//! the PNG encoding is timed apart. The baseline in the same run is the
//! frame with one shadow ray per pixel (the `raycast` method). The camera and light are the defaults
//! of `shadow render --scene bunny-99k`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec3;
use shadow_raster::{
    Camera, Hsr, Method, RasterScene, RenderOptions, Renderer, SceneLight, ShadowOptions, render,
    visible_surfaces,
};
use svbsp::{LightSpec, place_lights, shared_grid};

struct Setup {
    scene: RasterScene,
    lights: Vec<SceneLight>,
    eye: DVec3,
    target: DVec3,
}

fn bunny(name: &str, sun: bool) -> Setup {
    let mesh = shadow_scene::scene(name).expect("a built-in scene");
    let (lo, hi) = mesh.bounds().unwrap();
    let (c, half) = ((lo + hi) * 0.5, (hi - lo).max_element() * 0.5);
    let spec = if sun {
        LightSpec::Sun(DVec3::new(3.0, 10.0, 2.0))
    } else {
        LightSpec::Point(c + DVec3::Y * 1.6 * half + DVec3::X * 0.4 * half + DVec3::Z * 0.6 * half)
    };
    let grid = shared_grid(&mesh.positions, &[spec]).unwrap();
    let lights = place_lights(&grid, &[spec])
        .unwrap()
        .iter()
        .map(SceneLight::from_placed)
        .collect();
    let (polys, _) = bsp_core::import_faces_par(&grid, &mesh.face_loops()).unwrap();
    Setup {
        scene: RasterScene::new(&grid, polys).unwrap(),
        lights,
        eye: c + DVec3::new(0.75 * half, 0.6 * half, 1.7 * half),
        target: c - DVec3::Y * 0.25 * half,
    }
}

fn frames(cr: &mut Criterion) {
    let point = bunny("bunny-99k", false);
    let sun = bunny("bunny-99k", true);
    let mut g = cr.benchmark_group("bunny-99k");
    g.sample_size(20).measurement_time(Duration::from_secs(6));
    for (w, h) in [(1920, 1080), (960, 540)] {
        let cam = Camera::look_at(point.eye, point.target, DVec3::Y, 50.0, w, h).unwrap();
        g.bench_function(format!("{w}x{h}/visibility zbuffer"), |b| {
            b.iter(|| black_box(visible_surfaces(&point.scene, &cam, Hsr::ZBuffer, false).unwrap()))
        });
        // the per-pixel reference, as a baseline in the same run
        let rays = RenderOptions::default().with_method(Method::Raycast);
        g.bench_function(
            format!("{w}x{h}/frame zbuffer + shadow rays, point light"),
            |b| {
                b.iter(|| black_box(render(&point.scene, &point.lights, &cam, &[], &rays).unwrap()))
            },
        );
        for (what, s) in [("point light", &point), ("sun", &sun)] {
            let opts = RenderOptions::default()
                .with_method(Method::ShadowMap)
                .with_shadow(ShadowOptions::default().with_map_size(2048));
            g.bench_function(
                format!("{w}x{h}/frame zbuffer + shadow map 2048, {what}"),
                |b| b.iter(|| black_box(render(&s.scene, &s.lights, &cam, &[], &opts).unwrap())),
            );
            // frame after frame in one Renderer (an animation): its buffers
            // are kept from the previous frame
            let mut renderer = Renderer::new();
            g.bench_function(
                format!("{w}x{h}/frame zbuffer + shadow map 2048, {what}, kept Renderer"),
                |b| {
                    b.iter(|| {
                        black_box(
                            renderer
                                .render(&s.scene, &s.lights, &cam, &[], &opts)
                                .unwrap()
                                .image
                                .width,
                        )
                    })
                },
            );
        }
    }
    let cam = Camera::look_at(point.eye, point.target, DVec3::Y, 50.0, 1920, 1080).unwrap();
    let out = render(
        &point.scene,
        &point.lights,
        &cam,
        &[],
        &RenderOptions::default().with_method(Method::ShadowMap),
    )
    .unwrap();
    g.bench_function("1920x1080/png encoding", |b| {
        b.iter(|| black_box(out.image.encode_png()))
    });
    g.finish();
}

criterion_group!(benches, frames);
criterion_main!(benches);
