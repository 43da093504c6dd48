//! Exact point membership (`BspTree::classify_point`) on the tree of a
//! closed torus, for 4096 random grid points in its bounding box.

use std::hint::black_box;

use bsp_core::{Membership, Point};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::DVec3;

mod common;
use common::Rng;

const BATCH: usize = 4096;

fn bench(c: &mut Criterion) {
    let grid = common::grid();
    let mut rng = Rng::new(0x3e3b);
    let points: Vec<Point> = (0..BATCH)
        .map(|_| {
            let p = DVec3::new(
                rng.range(-1.5, 1.5),
                rng.range(-1.5, 1.5),
                rng.range(-0.5, 0.5),
            );
            Point::Grid(grid.snap(p).expect("inside the grid"))
        })
        .collect();
    let mut g = c.benchmark_group("membership");
    g.throughput(Throughput::Elements(BATCH as u64));
    for n in [10_000, 100_000] {
        let tree = common::build(common::torus(n));
        let s = tree.stats();
        let inside = points
            .iter()
            .filter(|p| tree.classify_point(p) == Membership::Inside)
            .count();
        eprintln!(
            "membership torus {n}: {} nodes, depth {}, {inside} of {BATCH} probes inside",
            s.nodes, s.depth
        );
        g.bench_function(format!("torus_{n}"), |b| {
            b.iter(|| {
                let mut k = 0usize;
                for p in &points {
                    k += (tree.classify_point(black_box(p)) == Membership::Inside) as usize;
                }
                k
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
