//! `certify_solid_boundary` (closed, oriented, embedded, outward) on a
//! torus and a UV sphere of 5 000 and 100 000 triangles.

use std::hint::black_box;

use bsp_core::certify_solid_boundary;
use bsp_fixtures as shapes;
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::DVec3;

mod common;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("certify_solid");
    for n in [5_000, 100_000] {
        let torus = common::torus(n);
        let (v, f) = shapes::uv_sphere(n);
        let faces: Vec<Vec<DVec3>> = f
            .iter()
            .map(|f| f.iter().map(|&i| v[i as usize]).collect())
            .collect();
        let sphere = common::import_loops(&faces);
        for (name, polys) in [("torus", torus), ("uv_sphere", sphere)] {
            certify_solid_boundary(&polys).expect("a solid's boundary");
            g.throughput(Throughput::Elements(polys.len() as u64));
            g.bench_function(format!("{name}/{}", polys.len()), |b| {
                b.iter(|| certify_solid_boundary(black_box(&polys)))
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
