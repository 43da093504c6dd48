//! Point-versus-plane classification: grid points (128-bit), implicit
//! points through the `f64` filter, the forced 256-bit exact path, and a
//! plain `f64` dot product with no exactness, on batches of 4096 pairs.

use std::hint::black_box;

use bnum::cast::As;
use bsp_core::{Implicit, MAX_COORD, Plane, Side};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};

mod common;
use common::{Rng, random_plane};

const BATCH: usize = 4096;

/// Random planes of the full budget and implicit points in general
/// position, plus degenerate pairs (the point lies on the plane, so the
/// filter cannot decide).
struct Pairs {
    planes: Vec<Plane>,
    grid: Vec<[i32; 3]>,
    implicit: Vec<Implicit>,
    /// The implicit points' homogeneous coordinates rounded to `f64`.
    approx: Vec<[f64; 4]>,
    on_planes: Vec<Plane>,
}

fn pairs() -> Pairs {
    let mut rng = Rng::new(0xc1a5_51f1);
    let m = MAX_COORD;
    let mut p = Pairs {
        planes: Vec::new(),
        grid: Vec::new(),
        implicit: Vec::new(),
        approx: Vec::new(),
        on_planes: Vec::new(),
    };
    while p.planes.len() < BATCH {
        let (a, b, c) = (
            random_plane(&mut rng, m),
            random_plane(&mut rng, m),
            random_plane(&mut rng, m),
        );
        let Some(x) = Implicit::from_planes(&a, &b, &c) else {
            continue;
        };
        // only points the filter decides count as generic
        let plane = random_plane(&mut rng, m);
        if x.classify_filtered(&plane).is_none() {
            continue;
        }
        p.approx.push(x.homogeneous().map(|c| c.as_::<f64>()));
        p.implicit.push(x);
        p.planes.push(plane);
        p.on_planes.push(a);
        p.grid.push(rng.grid_point(m));
    }
    p
}

fn bench(c: &mut Criterion) {
    let p = pairs();
    // how often does the unfiltered f64 sign agree with the exact one?
    let exact: Vec<Side> = p
        .implicit
        .iter()
        .zip(&p.planes)
        .map(|(x, pl)| x.classify_exact(pl))
        .collect();
    let naive_wrong = p
        .approx
        .iter()
        .zip(&p.planes)
        .zip(&exact)
        .filter(|((a, pl), s)| naive_side(a, pl) != **s)
        .count();
    let degenerate_naive_on = p
        .implicit
        .iter()
        .zip(&p.approx)
        .zip(&p.on_planes)
        .filter(|((x, a), pl)| {
            debug_assert_eq!(x.classify(pl), Side::On);
            naive_side(a, pl) == Side::On
        })
        .count();
    eprintln!(
        "classify: plain f64 sign differs from the exact one on {naive_wrong} of {BATCH} generic pairs; \
         on {} of {BATCH} degenerate pairs (point on the plane) it answers On",
        degenerate_naive_on
    );

    let mut g = c.benchmark_group("classify");
    g.throughput(Throughput::Elements(BATCH as u64));
    g.bench_function("grid_i128", |b| {
        b.iter(|| {
            let mut n = 0u32;
            for (pl, q) in p.planes.iter().zip(&p.grid) {
                n += (black_box(pl).classify_grid(*q) == Side::Front) as u32;
            }
            n
        })
    });
    g.bench_function("implicit_filter", |b| {
        b.iter(|| {
            let mut n = 0u32;
            for (x, pl) in p.implicit.iter().zip(&p.planes) {
                n += (black_box(x).classify_filtered(pl) == Some(Side::Front)) as u32;
            }
            n
        })
    });
    g.bench_function("implicit_exact_i256", |b| {
        b.iter(|| {
            let mut n = 0u32;
            for (x, pl) in p.implicit.iter().zip(&p.planes) {
                n += (black_box(x).classify_exact(pl) == Side::Front) as u32;
            }
            n
        })
    });
    g.bench_function("implicit_plain_f64", |b| {
        b.iter(|| {
            let mut n = 0u32;
            for (a, pl) in p.approx.iter().zip(&p.planes) {
                n += (naive_side(black_box(a), pl) == Side::Front) as u32;
            }
            n
        })
    });
    g.bench_function("implicit_degenerate_filter_then_exact", |b| {
        b.iter(|| {
            let mut n = 0u32;
            for (x, pl) in p.implicit.iter().zip(&p.on_planes) {
                n += (black_box(x).classify(pl) == Side::On) as u32;
            }
            n
        })
    });
    g.finish();
}

/// The same dot product as the filter, without its error bound.
#[inline]
fn naive_side(a: &[f64; 4], plane: &Plane) -> Side {
    let p = plane.approx();
    let v = (p[0] * a[0] + p[1] * a[1]) + (p[2] * a[2] + p[3] * a[3]);
    if v > 0.0 {
        Side::Front
    } else if v < 0.0 {
        Side::Back
    } else {
        Side::On
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
