//! One-shot timing of the `shadows` bench scenes with `std::time::Instant`:
//! every step once (BSP build, `shadow_fragments`, BVH build, shadow rays)
//! with the counts, a sweep of the baseline's ray epsilon, and a target for
//! `perf record`. Criterion (`cargo bench -p svbsp --bench shadows`)
//! measures the same scenes with repeated samples.
//!
//! ```sh
//! cargo run --release -p svbsp --example bench_100k                 # 100k, both build options, 1 and 3 lights
//! cargo run --release -p svbsp --example bench_100k -- 10000 cut64 1 eps=0,0.001,1,1000
//! perf record -g target/release/examples/bench_100k 100000 cut64 1 shadows-only
//! ```
//!
//! Arguments, all optional, in any order: polygon counts (27, 258, 1026 or
//! a multiple of 100 from 10 000 up; default 100 000), `default` / `cut64`
//! (build options; default both), `1` / `3` (lights: the key point light,
//! or two points and a sun; default both), `shadows-only` (time the build
//! and `shadow_fragments` only, no baseline: for profiling), `eps=X,Y,...`
//! (the shadow rays' self-intersection margins in grid units; the first is
//! timed, each is compared with the exact flags; default 1).

#[path = "../benches/common/mod.rs"]
mod common;

fn main() {
    let mut sizes = Vec::new();
    let mut options = Vec::new();
    let mut lights = Vec::new();
    let mut shadows_only = false;
    let mut eps = vec![common::RAY_EPS];
    for a in std::env::args().skip(1) {
        match a.as_str() {
            "default" => options.push(false),
            "cut64" => options.push(true),
            "1" => lights.push(1),
            "3" => lights.push(3),
            "shadows-only" => shadows_only = true,
            e if e.starts_with("eps=") => {
                eps = e[4..]
                    .split(',')
                    .map(|x| x.parse().expect("eps=<grid units>,..."))
                    .collect()
            }
            n => sizes.push(n.parse::<usize>().expect("a polygon count")),
        }
    }
    if sizes.is_empty() {
        sizes.push(100_000);
    }
    if options.is_empty() {
        options = vec![false, true];
    }
    if lights.is_empty() {
        lights = vec![1, 3];
    }
    for &n in &sizes {
        let p = common::prepare(&common::scene(n), &common::lights(3));
        for &nl in &lights {
            for &cut in &options {
                if shadows_only {
                    common::measure_shadows(&p, cut, nl);
                    continue;
                }
                let (row, _, frags) = common::measure(&p, cut, nl, eps[0]);
                row.print();
                if eps.len() > 1 {
                    let bvh = common::Bvh::build(&common::triangles(&p.polys));
                    for &e in &eps {
                        let (rays, facing) = common::shadow_rays(&frags, &p.lights_f64[..nl], e);
                        let blocked = common::cast(&bvh, &rays);
                        let (d, _) =
                            common::compare(&frags, &p.lights[..nl], &rays, &blocked, &facing);
                        eprintln!(
                            "    eps {e}: {} disagreements ({} false lit, {} false shadow), \
                             {} facing-test mismatches",
                            d.total(),
                            d.false_lit,
                            d.false_shadow,
                            d.facing
                        );
                    }
                }
            }
        }
    }
}
