//! Making planes through three grid points (`Plane::through`: a cross
//! product, the offset and the reduction by the coefficients' gcd), 1024
//! a batch: the supports of a fine mesh's triangles (edges of about 2^13
//! grid steps, coordinates up to 2^21) and the shadow planes of their
//! edges through a point light 2^23 steps away, as a shadow tree's
//! occluders make them.

use std::hint::black_box;

use bsp_core::{GridPoint, Plane};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};

mod common;
use common::Rng;

const BATCH: usize = 1024;

fn bench(c: &mut Criterion) {
    let mut rng = Rng::new(7);
    let light: GridPoint = [3 << 21, 1 << 23, 3 << 20];
    let mut supports = Vec::with_capacity(BATCH);
    let mut shadows = Vec::with_capacity(BATCH);
    while supports.len() < BATCH {
        let a = rng.grid_point(1 << 21);
        let [b, c] = [0, 1].map(|_| {
            let e = rng.grid_point(1 << 13);
            [0, 1, 2].map(|k| a[k] + e[k])
        });
        if Plane::through(a, b, c).is_ok() && Plane::through(light, a, b).is_ok() {
            supports.push([a, b, c]);
            shadows.push([light, a, b]);
        }
    }
    let mut g = c.benchmark_group("plane");
    g.throughput(Throughput::Elements(BATCH as u64));
    for (name, set) in [("support", &supports), ("shadow", &shadows)] {
        g.bench_function(format!("{name}/through"), |b| {
            b.iter(|| {
                let mut n = 0i64;
                for &[p, q, r] in set {
                    if let Ok(plane) = Plane::through(black_box(p), q, r) {
                        n = n.wrapping_add(plane.normal()[0]);
                    }
                }
                n
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
