//! BSP build time and fragment growth for a random triangle soup and a
//! closed torus of 10k and 100k triangles.
//!
//! One million triangles are out of the default run: set `BSP_BENCH_1M`
//! to `soup` (or `1`) for the soup, about 13 s per build, to `torus` for
//! the torus (about 26 s), or to `all`; criterion wants ten builds each.
//! An autopartition of a convex patch is a chain (every face plane has
//! the other faces behind it), so the torus is the case the default's
//! balance cuts are for: without them (`with_cut_threshold(0)`) its build
//! is quadratic, 10.6 s at 100k and well over half an hour at 1M. See
//! `docs/benchmarks.md`.
//!
//! Criterion reports time only; the fragment count, node count and depth
//! of each tree, and the time of one build, are printed to stderr before
//! each group runs.

use std::time::Instant;

use bsp_core::{BspTree, BuildOptions, Polygon};
use criterion::{BatchSize, BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};

mod common;

fn scene(kind: &str, n: usize) -> Vec<Polygon> {
    match kind {
        "soup" => common::soup(n, 0xb0b + n as u64),
        _ => common::torus(n),
    }
}

fn report(kind: &str, n: usize, polys: &[Polygon]) {
    let t = Instant::now();
    let tree = BspTree::build(polys.to_vec(), &BuildOptions::default());
    let dt = t.elapsed();
    let s = tree.stats();
    eprintln!(
        "build {kind} {n}: {} polygons in, {} fragments ({:.3}x), {} nodes, depth {}, one build {:.3} s",
        polys.len(),
        s.polygons,
        s.polygons as f64 / polys.len() as f64,
        s.nodes,
        s.depth,
        dt.as_secs_f64()
    );
}

fn run(c: &mut Criterion, group: &str, kinds: &[&str], sizes: &[usize]) {
    let mut g = c.benchmark_group(group);
    g.sample_size(10);
    for &kind in kinds {
        for &n in sizes {
            let polys = scene(kind, n);
            report(kind, n, &polys);
            g.throughput(Throughput::Elements(polys.len() as u64));
            g.bench_with_input(BenchmarkId::new(kind, n), &polys, |b, polys| {
                b.iter_batched(
                    || polys.clone(),
                    |p| BspTree::build(p, &BuildOptions::default()),
                    BatchSize::LargeInput,
                )
            });
        }
    }
    g.finish();
}

fn bench(c: &mut Criterion) {
    run(c, "build", &["soup", "torus"], &[10_000, 100_000]);
    let kinds: &[&str] = match std::env::var("BSP_BENCH_1M").as_deref() {
        Ok("1" | "soup") => &["soup"],
        Ok("torus") => &["torus"],
        Ok("all") => &["soup", "torus"],
        Ok(other) => panic!("BSP_BENCH_1M={other}: expected soup, torus, all or 1"),
        Err(_) => &[],
    };
    if !kinds.is_empty() {
        run(c, "build_1m", kinds, &[1_000_000]);
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
