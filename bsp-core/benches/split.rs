//! Splitting convex polygons by spanning planes: triangles and quads with
//! grid vertices, and pieces of earlier splits (implicit vertices), 1024
//! splits per batch. The loop clones each polygon before splitting it
//! (`split` consumes it); the clone alone is measured separately.

use std::hint::black_box;

use bsp_core::{GridPoint, Plane, Polygon, PolygonSide, Split};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};

mod common;
use common::Rng;

const BATCH: usize = 1024;
const R: i32 = 1 << 20;

fn random_polygon(rng: &mut Rng, quad: bool) -> Option<Polygon> {
    let o = rng.grid_point(R);
    let u = rng.grid_point(R / 8);
    let v = rng.grid_point(R / 8);
    let at = |a: i32, b: i32| -> GridPoint { [0, 1, 2].map(|k| o[k] + a * u[k] + b * v[k]) };
    let pts: Vec<GridPoint> = if quad {
        vec![at(0, 0), at(1, 0), at(1, 1), at(0, 1)]
    } else {
        vec![at(0, 0), at(1, 0), at(0, 1)]
    };
    Polygon::from_grid_points(&pts, 0).ok()
}

/// A plane through a point inside `poly` (the mean of its vertices,
/// rounded) in a random direction; `None` if it does not span.
fn spanning_plane(rng: &mut Rng, poly: &Polygon) -> Option<Plane> {
    let vs = poly.vertices_f64();
    let c: GridPoint =
        [0, 1, 2].map(|k| (vs.iter().map(|v| v[k]).sum::<f64>() / vs.len() as f64).round() as i32);
    let d1 = rng.grid_point(1000);
    let d2 = rng.grid_point(1000);
    let plane = Plane::through(
        c,
        [0, 1, 2].map(|k| c[k] + d1[k]),
        [0, 1, 2].map(|k| c[k] + d2[k]),
    )
    .ok()?;
    (poly.classify(&plane) == PolygonSide::Spanning).then_some(plane)
}

fn cases(
    rng: &mut Rng,
    make: &mut dyn FnMut(&mut Rng) -> Option<Polygon>,
) -> Vec<(Polygon, Plane)> {
    let mut v = Vec::with_capacity(BATCH);
    while v.len() < BATCH {
        let Some(p) = make(rng) else { continue };
        if let Some(pl) = spanning_plane(rng, &p) {
            v.push((p, pl));
        }
    }
    v
}

fn bench(c: &mut Criterion) {
    let mut rng = Rng::new(0x5b11_7000);
    let tris = cases(&mut rng, &mut |r| random_polygon(r, false));
    let quads = cases(&mut rng, &mut |r| random_polygon(r, true));
    // pieces of a quad cut twice: mostly implicit vertices
    let pieces = cases(&mut rng, &mut |r| {
        let mut p = random_polygon(r, true)?;
        for _ in 0..2 {
            let pl = spanning_plane(r, &p)?;
            p = match p.split(&pl) {
                Split::Spanning { front, back } => {
                    if r.next_u64() & 1 == 0 {
                        front
                    } else {
                        back
                    }
                }
                _ => return None,
            };
        }
        Some(p)
    });
    let mean_len = pieces.iter().map(|(p, _)| p.len()).sum::<usize>() as f64 / BATCH as f64;
    eprintln!("split: the cut pieces have {mean_len:.2} vertices on average");

    let mut g = c.benchmark_group("split");
    g.throughput(Throughput::Elements(BATCH as u64));
    for (name, set) in [
        ("triangle", &tris),
        ("quad", &quads),
        ("cut_piece", &pieces),
    ] {
        g.bench_function(format!("{name}/clone_and_split"), |b| {
            b.iter(|| {
                let mut n = 0usize;
                for (p, pl) in set {
                    if let Split::Spanning { front, back } = black_box(p).clone().split(pl) {
                        n += front.len() + back.len();
                    }
                }
                n
            })
        });
        g.bench_function(format!("{name}/clone_only"), |b| {
            b.iter(|| {
                let mut n = 0usize;
                for (p, _) in set {
                    n += black_box(black_box(p).clone()).len();
                }
                n
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
