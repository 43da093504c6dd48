//! Shadow art: the exact hull of a closed mesh's three silhouettes (the
//! sphere of `data/meshes`, suns along the axes, 256² images), and its
//! check (the hull's shadows cast back and measured per pixel).
//! `docs/shadow-art.md` has the end-to-end figures at 512².

use std::hint::black_box;
use std::time::Duration;

use bsp_shadows::DVec3;
use bsp_shadows::art::{ArtLight, ArtSpec, ArtView, Mask, ViewPlane, shadow_coverage, shadow_hull};
use criterion::{Criterion, criterion_group, criterion_main};

fn silhouettes(n: u32) -> ArtSpec {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../data/meshes/pyvista_sphere.obj"
    );
    let mesh = bsp_shadows::read_mesh(path).unwrap();
    let (lo, hi) = mesh.bounds().unwrap();
    let side = (hi - lo).max_element() * 1.1;
    let px = side / f64::from(n);
    let c = (lo + hi) * 0.5 - DVec3::splat(side / 2.0);
    let views = [
        (
            DVec3::X,
            DVec3::new(lo.x - 1.0, c.y, c.z),
            DVec3::Y,
            DVec3::Z,
        ),
        (
            DVec3::Y,
            DVec3::new(c.x, lo.y - 1.0, c.z),
            DVec3::Z,
            DVec3::X,
        ),
        (
            DVec3::Z,
            DVec3::new(c.x, c.y, lo.z - 1.0),
            DVec3::X,
            DVec3::Y,
        ),
    ]
    .into_iter()
    .map(|(sun, origin, u, v)| {
        let mask = Mask {
            width: n,
            height: n,
            wanted: vec![false; (n * n) as usize],
        };
        let plane = ViewPlane {
            origin,
            u: u * px,
            v: v * px,
        };
        let mut view = ArtView {
            image: "silhouette".into(),
            light: ArtLight::Sun(sun),
            plane,
            mask,
        };
        let cover = shadow_coverage(&mesh, &view).unwrap();
        view.mask.wanted = cover.iter().map(|&c| c >= 0.5).collect();
        view
    })
    .collect();
    ArtSpec {
        views,
        bounds: [lo - DVec3::splat(0.5), hi + DVec3::splat(0.5)],
    }
}

fn art(cr: &mut Criterion) {
    let spec = silhouettes(256);
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
