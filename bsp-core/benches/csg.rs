//! Boolean set operations (union, intersection, difference) by BSP merging.
//!
//! Inputs, all generated in code except the bunny:
//! * `sphere N`: a unit UV sphere of about N triangles (1k, 10k; 100k with
//!   `BSP_BENCH_100K=1`) against a copy rotated 5° about (1, 2, 3) and
//!   shifted by (0.3, 0.1, 0.05) radii — the same formula as
//!   `scripts/manifold_compare.py`;
//! * `bunny`: `data/meshes/bunny.obj` against a copy shifted by
//!   (0.3, 0.1, 0.05) × half its largest extent.
//!
//! Groups: `csg_pipeline` (`Partition::solid` of both + boolean + `to_mesh`,
//! from imported polygons) and `csg_boolean` (the boolean alone, on prebuilt
//! partitions). Before each case, one timed pass of every phase and the node
//! / triangle counts are printed to stderr.
//!
//! Then a one-shot iterated case (not a criterion benchmark): 100 successive
//! subtractions of small spheres and boxes from a box, printing time and
//! node count every 10 steps (`BSP_BENCH_ITER_STEPS` changes the count).

use std::path::Path;
use std::time::{Duration, Instant};

use bsp_core::{BoolOp, Grid, Partition, Polygon, import_faces};
use criterion::{BatchSize, BenchmarkId, Criterion, criterion_group, criterion_main};
use glam::DVec3;

mod common;

const OPS: [(&str, BoolOp); 3] = [
    ("union", BoolOp::Union),
    ("intersection", BoolOp::Intersection),
    ("difference", BoolOp::Difference),
];
const ANGLE_DEG: f64 = 5.0;
const AXIS: DVec3 = DVec3::new(1.0, 2.0, 3.0);
const SHIFT: DVec3 = DVec3::new(0.3, 0.1, 0.05);

type Faces = Vec<Vec<DVec3>>;

/// Unit UV sphere of `4 s (s - 1)` triangles, `s = floor(sqrt(n/4) + 0.5)`
/// stacks and `2 s` slices, oriented outwards ([`bsp_fixtures::uv_sphere`]).
fn uv_sphere(n: usize) -> Faces {
    let (v, f) = bsp_fixtures::uv_sphere(n);
    f.iter()
        .map(|t| t.iter().map(|&i| v[i as usize]).collect())
        .collect()
}

/// Rodrigues rotation by `ANGLE_DEG` about `AXIS`.
fn rotate(p: DVec3) -> DVec3 {
    let k = AXIS.normalize();
    let (s, c) = ANGLE_DEG.to_radians().sin_cos();
    p * c + k.cross(p) * s + k * k.dot(p) * (1.0 - c)
}

fn map(faces: &Faces, f: impl Fn(DVec3) -> DVec3) -> Faces {
    faces
        .iter()
        .map(|l| l.iter().map(|&p| f(p)).collect())
        .collect()
}

fn bunny() -> Faces {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/meshes/bunny.obj");
    shadow_scene::load(&path)
        .expect("data/meshes/bunny.obj")
        .face_loops()
}

/// Snaps both operands to one grid fitted to both, as `shadow csg` does.
fn import_pair(a: &Faces, b: &Faces) -> (Vec<Polygon>, Vec<Polygon>) {
    let grid = Grid::fit_points(a.iter().chain(b).flatten()).expect("finite points");
    let imp = |f: &Faces| {
        let (polys, report) =
            import_faces(&grid, f.iter().map(Vec::as_slice)).expect("faces inside the grid");
        assert!(report.dropped.is_empty(), "faces dropped on import");
        polys
    };
    (imp(a), imp(b))
}

fn cases() -> Vec<(String, Vec<Polygon>, Vec<Polygon>)> {
    let mut sizes = vec![1_000, 10_000];
    if std::env::var_os("BSP_BENCH_100K").is_some() {
        sizes.push(100_000);
    }
    let mut out = Vec::new();
    for n in sizes {
        let a = uv_sphere(n);
        let b = map(&a, |p| rotate(p) + SHIFT);
        let (pa, pb) = import_pair(&a, &b);
        out.push((format!("sphere{}", a.len()), pa, pb));
    }
    let a = bunny();
    let (lo, hi) = a
        .iter()
        .flatten()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        });
    let half = (hi - lo).max_element() / 2.0;
    let b = map(&a, |p| p + SHIFT * half);
    let (pa, pb) = import_pair(&a, &b);
    out.push((format!("bunny{}", a.len()), pa, pb));
    out
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn report(name: &str, op: &str, pa: &[Polygon], pb: &[Polygon], bop: BoolOp) {
    let t0 = Instant::now();
    let a = Partition::solid(pa.to_vec());
    let t1 = Instant::now();
    let b = Partition::solid(pb.to_vec());
    let t2 = Instant::now();
    let r = a.boolean(&b, bop);
    let t3 = Instant::now();
    let mesh = r.to_mesh();
    let t4 = Instant::now();
    eprintln!(
        "csg {name} {op}: build A {:.1} ms, build B {:.1} ms, boolean {:.1} ms, to_mesh {:.1} ms; \
         nodes A {} B {} result {}; {} output triangles",
        ms(t1 - t0),
        ms(t2 - t1),
        ms(t3 - t2),
        ms(t4 - t3),
        a.nodes().len(),
        b.nodes().len(),
        r.nodes().len(),
        mesh.triangles.len()
    );
}

fn bench(c: &mut Criterion) {
    let cases = cases();
    for (name, pa, pb) in &cases {
        for (op, bop) in OPS {
            report(name, op, pa, pb, bop);
        }
    }
    let mut g = c.benchmark_group("csg_pipeline");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    for (name, pa, pb) in &cases {
        for (op, bop) in OPS {
            g.bench_function(BenchmarkId::new(name.as_str(), op), |bch| {
                bch.iter_batched(
                    || (pa.clone(), pb.clone()),
                    |(pa, pb)| {
                        let a = Partition::solid(pa);
                        let b = Partition::solid(pb);
                        a.boolean(&b, bop).to_mesh()
                    },
                    BatchSize::LargeInput,
                )
            });
        }
    }
    g.finish();
    let mut g = c.benchmark_group("csg_boolean");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    for (name, pa, pb) in &cases {
        let a = Partition::solid(pa.clone());
        let b = Partition::solid(pb.clone());
        for (op, bop) in OPS {
            g.bench_function(BenchmarkId::new(name.as_str(), op), |bch| {
                bch.iter(|| a.boolean(&b, bop))
            });
        }
    }
    g.finish();
    iterated();
}

/// An axis-aligned box `[lo, hi]` as six outward quads.
fn cuboid(lo: DVec3, hi: DVec3) -> Faces {
    bsp_fixtures::cuboid(lo, hi)
}

/// 100 successive subtractions (alternately a 168-triangle sphere of
/// radius 0.12–0.2 and an axis-aligned box of half-size 0.08–0.15, centres
/// uniform in [-1, 1]^3) from the box [-1, 1]^3, on the common bench grid.
fn iterated() {
    let steps: usize = std::env::var("BSP_BENCH_ITER_STEPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(100);
    let grid = common::grid();
    let imp = |f: &Faces| {
        import_faces(&grid, f.iter().map(Vec::as_slice))
            .expect("in grid")
            .0
    };
    let mut rng = common::Rng::new(0xc56);
    let sphere = uv_sphere(200);
    let mut solid = Partition::solid(imp(&cuboid(DVec3::splat(-1.0), DVec3::splat(1.0))));
    let start = Instant::now();
    let mut chunk = Instant::now();
    for k in 1..=steps {
        let c = DVec3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        );
        let tool = if k % 2 == 1 {
            let r = rng.range(0.12, 0.2);
            map(&sphere, |p| c + rotate(p) * r)
        } else {
            let h = DVec3::new(
                rng.range(0.08, 0.15),
                rng.range(0.08, 0.15),
                rng.range(0.08, 0.15),
            );
            cuboid(c - h, c + h)
        };
        let tool = Partition::solid(imp(&tool));
        solid = solid.boolean(&tool, BoolOp::Difference);
        if k % 10 == 0 || k == steps {
            eprintln!(
                "csg iterated step {k:3}: last 10 steps {:8.1} ms, total {:9.1} ms, nodes {}",
                ms(chunk.elapsed()),
                ms(start.elapsed()),
                solid.nodes().len()
            );
            chunk = Instant::now();
        }
    }
    let t = Instant::now();
    let mesh = solid.to_mesh();
    eprintln!(
        "csg iterated: {steps} subtractions {:.1} ms, final to_mesh {:.1} ms, {} triangles, {} nodes",
        ms(t - start),
        ms(t.elapsed()),
        mesh.triangles.len(),
        solid.nodes().len()
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
