//! Painter's-order traversal of the 100k-triangle trees from a fixed eye:
//! `BspTree::traverse_recursive` vs `BspTree::traverse` (explicit stack)
//! vs `FlatBsp::traverse`, with a counting visitor. Throughput is in
//! nodes, so criterion's figure is time per node.

use std::hint::black_box;

use bsp_core::{BspTree, FlatBsp, Order, ViewPoint};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::DVec3;

mod common;

fn bench(c: &mut Criterion) {
    let eye: ViewPoint = common::grid()
        .snap_viewpoint(DVec3::new(3.0, 2.0, 1.5))
        .expect("eye in range");
    let mut g = c.benchmark_group("traverse");
    for (name, polys) in [
        ("soup_100k", common::soup(100_000, 0xb0b + 100_000)),
        ("torus_100k", common::torus(100_000)),
    ] {
        let tree: BspTree = common::build(polys);
        let flat = FlatBsp::new(&tree);
        let s = tree.stats();
        eprintln!(
            "traverse {name}: {} nodes, {} fragments, depth {}",
            s.nodes, s.polygons, s.depth
        );
        g.throughput(Throughput::Elements(s.nodes as u64));
        g.bench_function(format!("{name}/recursive"), |b| {
            b.iter(|| {
                let mut n = 0usize;
                tree.traverse_recursive(black_box(eye), Order::BackToFront, |_| n += 1);
                n
            })
        });
        g.bench_function(format!("{name}/explicit_stack"), |b| {
            b.iter(|| {
                let mut n = 0usize;
                tree.traverse(black_box(eye), Order::BackToFront, |_| n += 1);
                n
            })
        });
        g.bench_function(format!("{name}/flat"), |b| {
            b.iter(|| {
                let mut n = 0usize;
                flat.traverse(black_box(eye), Order::BackToFront, |_| n += 1);
                n
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
