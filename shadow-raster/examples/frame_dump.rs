//! Renders the bench's frames (`bunny-99k`, default point light and a
//! sun) and writes their images, masks and lit amounts to a folder, for a
//! byte-for-byte comparison of two builds; `--repeat N` renders the
//! point-light shadow-map frame N more times (for `perf record`).
//!
//! ```sh
//! cargo run --release -p shadow-raster --example frame_dump -- OUT_DIR [--repeat N]
//! ```

use glam::DVec3;
use shadow_raster::{Camera, Method, RasterScene, RenderOptions, Renderer, render};

#[path = "../benches/common/mod.rs"]
mod common;

fn setup(sun: bool) -> (RasterScene, Vec<svbsp::PlacedLight>, Camera) {
    let s = common::bunny("bunny-99k", sun);
    let cam = Camera::look_at(s.eye, s.target, DVec3::Y, 50.0, 1920, 1080).unwrap();
    (s.scene, s.lights, cam)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let out = std::path::PathBuf::from(args.get(1).expect("an output folder"));
    let repeat: usize = match args.get(2).map(String::as_str) {
        Some("--repeat") => args[3].parse().unwrap(),
        _ => 0,
    };
    std::fs::create_dir_all(&out).unwrap();
    for (name, sun) in [("point", false), ("sun", true)] {
        let (scene, lights, cam) = setup(sun);
        for m in [Method::ShadowMap, Method::Raycast] {
            let o = RenderOptions::default().with_method(m);
            let r = render(&scene, &lights, &cam, &[], &o).unwrap();
            let stem = format!("{name}-{}", m.name());
            std::fs::write(out.join(format!("{stem}.rgb")), &r.image.rgb).unwrap();
            std::fs::write(out.join(format!("{stem}.mask")), r.mask()).unwrap();
            let lit: Vec<u8> = r.lit.amount.iter().flat_map(|a| a.to_le_bytes()).collect();
            std::fs::write(out.join(format!("{stem}.lit")), lit).unwrap();
            let prim: Vec<u8> = r
                .visibility
                .prim
                .iter()
                .flat_map(|a| a.to_le_bytes())
                .collect();
            std::fs::write(out.join(format!("{stem}.prim")), prim).unwrap();
        }
        if !sun && repeat > 0 {
            let o = RenderOptions::default().with_method(Method::ShadowMap);
            let mut r = Renderer::new();
            let t = std::time::Instant::now();
            for _ in 0..repeat {
                std::hint::black_box(r.render(&scene, &lights, &cam, &[], &o).unwrap());
            }
            eprintln!(
                "{:.1} ms a frame",
                t.elapsed().as_secs_f64() * 1e3 / repeat as f64
            );
            let once = render(&scene, &lights, &cam, &[], &o).unwrap();
            assert!(
                r.rendered().unwrap().image == once.image,
                "kept buffers change the image"
            );
        }
    }
}
