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
    Camera, Hsr, Method, RenderOptions, Renderer, ShadowOptions, render, visible_surfaces,
};

mod common;
use common::bunny;

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
