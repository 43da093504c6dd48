//! The renderer's alternative to exact shadows, on the scenes of
//! `svbsp`'s `shadows` bench: a BVH built over the scene and one `f64`
//! shadow ray per sample toward each light, for one million samples
//! spread over the faces by area (a 1-megapixel image's worth), on every
//! core: build and rays together (`rays/<scene>`).
//!
//! `SVBSP_BENCH_SCENES=cf27,room` restricts the scenes, as for the
//! `shadows` bench (default: all).

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, SamplingMode, Throughput, criterion_group, criterion_main};

mod baseline;

use baseline::Bvh;

const SCENES: [&str; 6] = [
    "cf27",
    "cf258",
    "cf1026",
    "room",
    "terrain10000",
    "bunny-99k",
];

/// Samples of the ray baseline.
const RAYS: usize = 1_000_000;

fn scenes() -> Vec<String> {
    match std::env::var("SVBSP_BENCH_SCENES") {
        Ok(s) => s.split(',').map(|n| n.trim().to_string()).collect(),
        Err(_) => SCENES.iter().map(|s| s.to_string()).collect(),
    }
}

/// One point light everywhere; four lights for the larger scenes (as the
/// `shadows` bench).
fn light_sets(name: &str) -> &'static [usize] {
    match name {
        "cf1026" | "terrain10000" | "bunny-99k" | "room" => &[1, 4],
        _ => &[1],
    }
}

fn bench(c: &mut Criterion) {
    for name in scenes() {
        let spec = baseline::scene(&name);
        let p = baseline::prepare(&spec, &baseline::lights(&spec, 4));
        let tris = baseline::triangles(&p.polys);
        let samples = baseline::surface_samples(&tris, RAYS, 0x5a3e);
        let mut g = c.benchmark_group(format!("rays/{name}"));
        g.sample_size(10);
        g.sampling_mode(SamplingMode::Flat);
        g.warm_up_time(Duration::from_millis(500));
        g.measurement_time(Duration::from_secs(4));
        g.throughput(Throughput::Elements(RAYS as u64));
        for &nl in light_sets(&name) {
            g.bench_function(format!("build+1M/{nl}light"), |b| {
                b.iter(|| {
                    let bvh = Bvh::build(black_box(&tris));
                    baseline::shadow_ray_pass(&bvh, &samples, &p.lights_f64[..nl])
                })
            });
        }
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
