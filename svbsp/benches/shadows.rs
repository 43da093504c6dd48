//! Exact shadows against Chin & Feiner's algorithm, in one run (the
//! ray-casting baseline on the same scenes is `shadow-raster`'s `rays`
//! bench).
//!
//! Scenes (see `common`): Chin & Feiner's sizes (27, 258 and 1026
//! polygons: a floor under floating boxes, tetrahedra and parallelograms),
//! the paper's test room, a 10 000-polygon terrain with boxes, and the
//! scanned bunny refined to 99 199 faces on its ground; one point light,
//! and for some scenes four lights (three points and a sun).
//!
//! Groups, per scene:
//! - `psv/<scene>`: `LightVolumes::new` and `shade_all` (the default path:
//!   fragments per face, on every core);
//! - `chin_feiner/<scene>`: the scene BSP (`BspTree::build`) and
//!   `chin_feiner` (the baseline algorithm), up to 10 000 polygons;
//! - `area/<scene>`: a 0.4 × 0.4 area light facing down, centred on the
//!   key light, every face cut into lit, penumbra, umbra and undecided
//!   fragments (`AreaLight::classify_faces`: every face against every
//!   other, so up to 1 026 polygons), beside one point light's `1light`;
//!   and `soft_shadows`, the same classes with the visible share at each
//!   penumbra fragment's centroid and corners.
//!
//! Before each scene one timed run prints the counts criterion cannot
//! report: fragments per face, shadow-tree nodes, and the peak memory of
//! the shadows in bytes per input face (from the process's peak resident
//! size, reset before the run).
//!
//! Times are wall times: the work is parallel. `SVBSP_BENCH_SCENES=cf27,room`
//! restricts the scenes (default: all; the whole run takes a few minutes
//! on a 2-core machine).

use std::hint::black_box;
use std::time::{Duration, Instant};

use bsp_core::{BspTree, BuildOptions};
use criterion::{Criterion, SamplingMode, Throughput, criterion_group, criterion_main};
use svbsp::{AreaClass, AreaLight, LightVolumes, Occluder, ShadeOptions, chin_feiner};

mod common;

use common::Prepared;

const SCENES: [&str; 6] = [
    "cf27",
    "cf258",
    "cf1026",
    "room",
    "terrain10000",
    "bunny-99k",
];

fn scenes() -> Vec<String> {
    match std::env::var("SVBSP_BENCH_SCENES") {
        Ok(s) => s.split(',').map(|n| n.trim().to_string()).collect(),
        Err(_) => SCENES.iter().map(|s| s.to_string()).collect(),
    }
}

/// One point light everywhere; four lights for the larger scenes.
fn light_sets(name: &str) -> &'static [usize] {
    match name {
        "cf1026" | "terrain10000" | "bunny-99k" | "room" => &[1, 4],
        _ => &[1],
    }
}

fn configure(g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>, big: bool) {
    g.sample_size(10);
    if big {
        g.sampling_mode(SamplingMode::Flat);
        g.warm_up_time(Duration::from_millis(500));
        g.measurement_time(Duration::from_secs(4));
    } else {
        g.warm_up_time(Duration::from_secs(1));
        g.measurement_time(Duration::from_secs(3));
    }
}

/// The exact shadows of `p` for its first `nl` lights.
fn exact(p: &Prepared, nl: usize) -> (LightVolumes, svbsp::Batch) {
    let shadows = LightVolumes::new(&p.polys, &p.lights[..nl]).expect("lights on the grid");
    let b = shadows
        .set()
        .shade_all(&p.polys, &ShadeOptions::default().with_pieces(false));
    (shadows, b)
}

/// One timed run with the figures criterion cannot report.
fn report(p: &Prepared, nl: usize) {
    common::reset_peak();
    let before = common::memory();
    let t = Instant::now();
    let (shadows, b) = exact(p, nl);
    let time = t.elapsed();
    let after = common::memory();
    let nodes: usize = shadows.volumes().iter().map(|v| v.node_count()).sum();
    let faces = p.polys.len();
    let bytes = match (before, after) {
        (Some((rss, _)), Some((_, peak))) => format!(
            "{:.0} bytes per face at peak",
            peak.saturating_sub(rss) as f64 / faces as f64
        ),
        _ => "memory not measured".to_string(),
    };
    eprintln!(
        "{} / {nl} light(s): {faces} polygons, {} fragments ({:.3} per face), {nodes} \
         shadow-tree nodes, {bytes}; {:.1} ms",
        p.name,
        b.len(),
        b.len() as f64 / faces as f64,
        time.as_secs_f64() * 1e3
    );
}

fn bench_scene(c: &mut Criterion, name: &str) {
    let spec = common::scene(name);
    let p = common::prepare(&spec, &common::lights(&spec, 4));
    let n = p.polys.len();
    let big = n >= 10_000;
    let sets = light_sets(name);
    for &nl in sets {
        report(&p, nl);
    }

    let mut g = c.benchmark_group(format!("psv/{name}"));
    configure(&mut g, big);
    g.throughput(Throughput::Elements(n as u64));
    for &nl in sets {
        g.bench_function(format!("{nl}light"), |b| {
            b.iter(|| exact(black_box(&p), nl))
        });
    }
    g.finish();

    if n <= 10_000 {
        let mut g = c.benchmark_group(format!("chin_feiner/{name}"));
        configure(&mut g, big);
        g.throughput(Throughput::Elements(n as u64));
        for &nl in sets {
            g.bench_function(format!("{nl}light"), |b| {
                b.iter(|| {
                    let tree = BspTree::build(p.polys.clone(), &BuildOptions::default());
                    chin_feiner(&tree, &p.lights[..nl]).expect("lights on the grid")
                })
            });
        }
        g.finish();
    }
}

/// The scene's faces as occluders and a 0.4 × 0.4 area light centred on
/// its key light, facing down; the faces that do not snap to a convex
/// polygon are left out (counted).
fn area_scene(name: &str) -> (AreaLight, Vec<Occluder>, usize) {
    let spec = common::scene(name);
    let world = common::lights(&spec, 1);
    let p = common::prepare(&spec, &world);
    let common::WorldLight::Point(at) = world[0] else {
        panic!("the key light is a point light");
    };
    let corner = |dx: f64, dy: f64| p.grid.snap(at + glam::DVec3::new(dx, dy, 0.0)).unwrap();
    let light = AreaLight::new(&[
        corner(-0.2, -0.2),
        corner(-0.2, 0.2),
        corner(0.2, 0.2),
        corner(0.2, -0.2),
    ])
    .expect("a square light");
    let mut faces = Vec::new();
    let mut left_out = 0;
    for f in &spec.faces {
        let loop_: Vec<[i32; 3]> = f.iter().map(|&v| p.grid.snap(v).unwrap()).collect();
        match Occluder::new(&loop_) {
            Ok(o) => faces.push(o),
            Err(_) => left_out += 1,
        }
    }
    (light, faces, left_out)
}

fn bench_area(c: &mut Criterion, name: &str) {
    let (light, faces, left_out) = area_scene(name);
    let t = Instant::now();
    let all = light.classify_faces(&faces);
    let time = t.elapsed();
    let mut area = [0.0f64; 4];
    for f in all.iter().flatten() {
        let v: Vec<glam::DVec3> = f
            .polygon
            .vertices_f64()
            .iter()
            .map(|&c| glam::DVec3::from_array(c))
            .collect();
        let k = match f.class {
            AreaClass::Lit => 0,
            AreaClass::Penumbra => 1,
            AreaClass::Umbra => 2,
            AreaClass::Undecided => 3,
        };
        area[k] += svbsp::polygon_area(&v);
    }
    let total: f64 = area.iter().sum();
    let share = |k: usize| 100.0 * area[k] / total;
    let fragments: usize = all.iter().map(Vec::len).sum();
    eprintln!(
        "{name} / area light: {} faces ({left_out} left out: not convex once snapped), {fragments} \
         fragments ({:.3} per face); area lit {:.1}%, penumbra {:.1}%, umbra {:.1}%, \
         undecided {:.1}%; {:.1} ms",
        faces.len(),
        fragments as f64 / faces.len() as f64,
        share(0),
        share(1),
        share(2),
        share(3),
        time.as_secs_f64() * 1e3
    );
    let mut g = c.benchmark_group(format!("area/{name}"));
    configure(&mut g, false);
    g.throughput(Throughput::Elements(faces.len() as u64));
    g.bench_function("area_light", |b| {
        b.iter(|| light.classify_faces(black_box(&faces)))
    });
    // the classes again, with the visible share at every penumbra
    // fragment's centroid and corners (`soft_shadows`)
    let lights = std::slice::from_ref(&light);
    g.bench_function("soft_shadows", |b| {
        b.iter(|| svbsp::soft_shadows(lights, black_box(&faces)).expect("one light"))
    });
    g.finish();
}

fn bench(c: &mut Criterion) {
    for name in scenes() {
        bench_scene(c, &name);
        if common::scene(&name).faces.len() <= 1_026 {
            bench_area(c, &name);
        }
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
