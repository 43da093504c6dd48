//! Exact shadows against a ray-casting baseline, in one run.
//!
//! Scenes (see `common`): Chin & Feiner's sizes — 27, 258 and 1026
//! polygons, a floor under floating boxes, tetrahedra and parallelograms —
//! and terrain-and-boxes scenes of 10 000 and 100 000 polygons, each lit by
//! one point light, and 1026 and 10 000 also by three lights (two points
//! and a sun).
//!
//! Groups, per size `n`:
//! - `build/n`: `BspTree::build` with the default options and with
//!   `with_cut_threshold(64)`;
//! - `shadows/n`: `svbsp::shadow_fragments` on both trees, per light set;
//! - `baseline/n`: a median-split BVH over the scene's triangles (build),
//!   and one `f64` shadow ray per fragment and light toward the light
//!   (cast; throughput in rays), on the fragments of the `cut64` tree.
//!
//! Before each size, one timed run of every step is printed to stderr with
//! the counts criterion cannot report: BSP polygons, fragments, shadow-tree
//! nodes, rays, and how many baseline answers disagree with the exact flags.
//!
//! Times are the benchmarking thread's CPU time (`common::Clock`, from
//! `/proc/thread-self/schedstat`, 4 ms resolution), so that waiting for a
//! core on a shared machine does not count; `SVBSP_BENCH_CLOCK=wall`
//! measures wall time instead. `SVBSP_BENCH_SIZES=27,258` restricts the
//! sizes (default: all five; the whole run takes about 9 minutes on a
//! 2-core machine at load 3, more under heavier load).

use std::hint::black_box;
use std::time::Duration;

use bsp_core::BspTree;
use criterion::{
    BatchSize, BenchmarkId, Criterion, SamplingMode, Throughput, criterion_group, criterion_main,
};
use svbsp::shadow_fragments;

mod common;

use common::{Bvh, Clock, Prepared, RAY_EPS};

const SIZES: [usize; 5] = [27, 258, 1026, 10_000, 100_000];

fn sizes() -> Vec<usize> {
    match std::env::var("SVBSP_BENCH_SIZES") {
        Ok(s) => s
            .split(',')
            .map(|n| {
                n.trim()
                    .parse()
                    .expect("SVBSP_BENCH_SIZES: comma-separated counts")
            })
            .collect(),
        Err(_) => SIZES.to_vec(),
    }
}

/// One point light everywhere; three lights (two points and a sun) for
/// 1026 and 10 000 polygons.
fn light_sets(n: usize) -> &'static [usize] {
    if n == 1026 || n == 10_000 {
        &[1, 3]
    } else {
        &[1]
    }
}

/// Ten samples; for the big scenes flat sampling (one or a few
/// iterations per sample).
fn configure(g: &mut criterion::BenchmarkGroup<'_, Clock>, n: usize) {
    g.sample_size(10);
    if n >= 10_000 {
        g.sampling_mode(SamplingMode::Flat);
        g.warm_up_time(Duration::from_millis(500));
        g.measurement_time(Duration::from_secs(3));
    } else {
        g.warm_up_time(Duration::from_secs(1));
        g.measurement_time(Duration::from_secs(5));
    }
}

fn bench_size(c: &mut Criterion<Clock>, n: usize) {
    let p: Prepared = common::prepare(&common::scene(n), &common::lights(3));
    let sets = light_sets(n);
    // one timed run of everything, with the counts
    for &nl in sets {
        for cut in [false, true] {
            common::measure(&p, cut, nl, RAY_EPS).0.print();
        }
    }
    let trees: Vec<(bool, BspTree)> = [false, true]
        .into_iter()
        .map(|cut| {
            (
                cut,
                BspTree::build(p.polys.clone(), &common::build_options(cut)),
            )
        })
        .collect();

    let mut g = c.benchmark_group(format!("build/{n}"));
    configure(&mut g, n);
    g.throughput(Throughput::Elements(n as u64));
    for cut in [false, true] {
        g.bench_function(common::options_name(cut), |b| {
            b.iter_batched(
                || p.polys.clone(),
                |polys| BspTree::build(polys, &common::build_options(cut)),
                BatchSize::LargeInput,
            )
        });
    }
    g.finish();

    let mut g = c.benchmark_group(format!("shadows/{n}"));
    configure(&mut g, n);
    g.throughput(Throughput::Elements(n as u64));
    for &nl in sets {
        for (cut, tree) in &trees {
            let id = BenchmarkId::new(common::options_name(*cut), format!("{nl}light"));
            g.bench_with_input(id, tree, |b, tree| {
                b.iter(|| shadow_fragments(black_box(tree), &p.lights[..nl]).expect("lights"))
            });
        }
    }
    g.finish();

    let tris = common::triangles(&p.polys);
    let bvh = Bvh::build(&tris);
    let cut_tree = &trees[1].1;
    let mut g = c.benchmark_group(format!("baseline/{n}"));
    configure(&mut g, n);
    g.throughput(Throughput::Elements(tris.len() as u64));
    g.bench_function("bvh_build", |b| b.iter(|| Bvh::build(black_box(&tris))));
    for &nl in sets {
        let (frags, _) = shadow_fragments(cut_tree, &p.lights[..nl]).expect("lights");
        let (rays, _) = common::shadow_rays(&frags, &p.lights_f64[..nl], RAY_EPS);
        drop(frags);
        g.throughput(Throughput::Elements(rays.len() as u64));
        g.bench_function(format!("cast/{nl}light"), |b| {
            b.iter(|| common::cast(&bvh, black_box(&rays)))
        });
    }
    g.finish();
}

fn bench(c: &mut Criterion<Clock>) {
    eprintln!("measuring {}", Clock::from_env().name());
    for n in sizes() {
        bench_size(c, n);
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().with_measurement(Clock::from_env());
    targets = bench
}
criterion_main!(benches);
