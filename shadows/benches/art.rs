//! Shadow art: the exact hull of a closed mesh's three silhouettes (the
//! sphere of `data/meshes`, suns along the axes, 256² images), and its
//! check (the hull's shadows cast back and measured per pixel).
//! `docs/shadow-art.md` has the end-to-end figures at 512².

use std::hint::black_box;
use std::time::Duration;

use bsp_shadows::art::{axis_silhouettes, shadow_hull};
use criterion::{Criterion, criterion_group, criterion_main};

fn art(cr: &mut Criterion) {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../data/meshes/pyvista_sphere.obj"
    );
    let mesh = bsp_shadows::read_mesh(path).unwrap();
    let spec = axis_silhouettes(&mesh, 256).unwrap();
    let mut g = cr.benchmark_group("art/sphere 3x256");
    g.sample_size(10).measurement_time(Duration::from_secs(6));
    g.bench_function("hull", |b| {
        b.iter(|| black_box(shadow_hull(&spec).unwrap().hull.volume()))
    });
    let hull = shadow_hull(&spec).unwrap();
    g.bench_function("check", |b| {
        b.iter(|| black_box(hull.check(&spec).unwrap().len()))
    });
    g.finish();
}

criterion_group!(benches, art);
criterion_main!(benches);
