//! The tiling index and the real-time pipeline.
//!
//! Scenes (built in code from the repository): the paper's room with its
//! coordinate-axis object (445 static faces, 51 moving) and its default
//! light; the scanned bunny refined to 99 199 faces on its ground with a
//! torus of 5 000 triangles circling it ([`shadow_scene::animated`]) and
//! the scene's light.
//!
//! Groups:
//! - `tiling_build/<scene>`: [`TileIndex::build`] of the static faces for
//!   the point light (default tile rule), and for a sun on the bunny;
//! - `tiling_query/<scene>`: one box query (the moving object's box at
//!   successive frames);
//! - `frame/<scene>/<strategy>`: one frame of [`Dynamic::frame`], the
//!   object at successive positions of its default motion.
//!
//! Before each scene one line gives what criterion cannot: the index's
//! size, and the share of the polygons a query returns whose projection
//! does not meet the box's (the false positives; decided in `f64`, which
//! is fine for a statistic: the exact, never-missing test is the tiling
//! crate's property test). `TILING_BENCH_SCENES=room` restricts the scenes.

use std::hint::black_box;
use std::time::Duration;

use bsp_core::{Grid, GridPoint, Polygon, import_faces_par};
use criterion::{Criterion, criterion_group, criterion_main};
use glam::{DMat4, DVec3};
use svbsp::{Light, LightSpec, place_lights, shared_grid};
use tiling::{Dynamic, Motion, PipelineOptions, Query, Strategy, TileIndex};

struct Scene {
    name: &'static str,
    statics: Vec<Vec<DVec3>>,
    moving: Vec<Vec<DVec3>>,
    motion: Motion,
    grid: Grid,
    light: Light,
    polys: Vec<Polygon>,
}

const FRAMES: u32 = 24;

fn scene(name: &'static str) -> Scene {
    let a = shadow_scene::animated(name).expect("a built-in animation");
    let statics = a.statics.face_loops();
    let moving = a.moving.face_loops();
    let (lo, hi) = a.moving.bounds().expect("a moving object");
    let motion = Motion {
        axis: a.axis,
        degrees: a.degrees,
        centre: a.centre.unwrap_or((lo + hi) * 0.5),
        step: DVec3::ZERO,
    };
    let mut pts: Vec<DVec3> = a.statics.positions.clone();
    for k in 0..FRAMES {
        let m = motion.matrix(k);
        pts.extend(a.moving.positions.iter().map(|&p| m.transform_point3(p)));
    }
    let spec = [LightSpec::Point(a.light)];
    let grid = shared_grid(&pts, &spec).expect("a grid");
    let light = place_lights(&grid, &spec).expect("the light")[0].light;
    let (polys, _) = import_faces_par(&grid, &statics).expect("the static faces");
    Scene {
        name,
        statics,
        moving,
        motion,
        grid,
        light,
        polys,
    }
}

/// The moving object's grid box at frame `k`.
fn moved_box(s: &Scene, k: u32) -> (GridPoint, GridPoint) {
    let m: DMat4 = s.motion.matrix(k);
    let mut lo = [i32::MAX; 3];
    let mut hi = [i32::MIN; 3];
    for p in s.moving.iter().flatten() {
        let g = s.grid.snap(m.transform_point3(*p)).expect("on the grid");
        for a in 0..3 {
            lo[a] = lo[a].min(g[a]);
            hi[a] = hi[a].max(g[a]);
        }
    }
    (lo, hi)
}

/// Whether the cones from `l` through the points `a` and `b` share a ray
/// (`f64`: for the false-positive statistic only).
fn cones_meet(l: [f64; 3], a: &[[f64; 3]], b: &[[f64; 3]]) -> bool {
    let d = |p: &[f64; 3]| DVec3::new(p[0] - l[0], p[1] - l[1], p[2] - l[2]);
    let ga: Vec<DVec3> = a.iter().map(d).collect();
    let gb: Vec<DVec3> = b.iter().map(d).collect();
    let all: Vec<DVec3> = ga.iter().chain(&gb).copied().collect();
    let mut sum = DVec3::ZERO;
    for i in 0..all.len() {
        for j in 0..i {
            let c = all[i].cross(all[j]);
            for h in [c, -c] {
                if ga.iter().all(|g| h.dot(*g) >= 0.0) && gb.iter().all(|g| h.dot(*g) <= 0.0) {
                    sum += h.normalize_or_zero();
                }
            }
        }
    }
    !(ga.iter().all(|g| sum.dot(*g) > 0.0) && gb.iter().all(|g| sum.dot(*g) < 0.0))
}

fn false_positives(s: &Scene, index: &TileIndex) -> (usize, usize) {
    let Light::Point(l) = s.light else {
        return (0, 0);
    };
    let l = l.map(f64::from);
    let mut q = Query::default();
    let (mut found, mut wrong) = (0, 0);
    for k in (0..FRAMES).step_by(4) {
        let (lo, hi) = moved_box(s, k);
        let corners: Vec<[f64; 3]> = (0..8)
            .map(|m| [0, 1, 2].map(|a| if m >> a & 1 == 1 { hi[a] } else { lo[a] } as f64))
            .collect();
        for &p in index.query_box(lo, hi, &mut q) {
            let v: Vec<[f64; 3]> = s.polys[p as usize].vertices_f64();
            found += 1;
            if !cones_meet(l, &v, &corners) {
                wrong += 1;
            }
        }
    }
    (found, wrong)
}

fn bench(c: &mut Criterion) {
    let names: Vec<String> = std::env::var("TILING_BENCH_SCENES")
        .map(|s| s.split(',').map(|x| x.trim().to_string()).collect())
        .unwrap_or_else(|_| vec!["room".into(), "bunny-99k".into()]);
    for name in ["room", "bunny-99k"] {
        if !names.iter().any(|n| n == name) {
            continue;
        }
        let s = scene(name);
        let index = TileIndex::build(&s.light, &s.polys, None).unwrap();
        let st = index.stats();
        let (found, wrong) = false_positives(&s, &index);
        println!(
            "{}: {} static polygons, {}x{} tiles a cube face, {} entries ({:.2} a polygon, {} KB); \
             queries returned {:.1} polygons on average, {:.1}% of them false positives",
            s.name,
            s.polys.len(),
            st.n,
            st.n,
            st.entries,
            st.entries as f64 / s.polys.len() as f64,
            st.bytes / 1024,
            found as f64 / (FRAMES / 4) as f64,
            100.0 * wrong as f64 / found.max(1) as f64
        );
        let mut g = c.benchmark_group("tiling_build");
        g.sample_size(10).measurement_time(Duration::from_secs(3));
        g.bench_function(s.name, |b| {
            b.iter(|| TileIndex::build(&s.light, black_box(&s.polys), None).unwrap())
        });
        if name == "bunny-99k" {
            let sun = Light::Directional([1, 3, 2]);
            g.bench_function(format!("{}/sun", s.name), |b| {
                b.iter(|| TileIndex::build(&sun, black_box(&s.polys), None).unwrap())
            });
        }
        g.finish();
        let mut g = c.benchmark_group("tiling_query");
        let boxes: Vec<(GridPoint, GridPoint)> = (0..FRAMES).map(|k| moved_box(&s, k)).collect();
        let mut q = Query::default();
        let mut k = 0;
        g.bench_function(s.name, |b| {
            b.iter(|| {
                k = (k + 1) % boxes.len();
                let (lo, hi) = boxes[k];
                black_box(index.query_box(lo, hi, &mut q).len())
            })
        });
        g.finish();
        let mut g = c.benchmark_group("frame");
        g.sample_size(10).measurement_time(Duration::from_secs(4));
        let strategies: &[Strategy] = if name == "room" {
            &[Strategy::Fast, Strategy::Paper]
        } else {
            &[Strategy::Fast]
        };
        for &strategy in strategies {
            let d = Dynamic::new(
                &s.statics,
                &s.moving,
                s.grid,
                &[s.light],
                PipelineOptions::default().with_strategy(strategy),
            )
            .unwrap();
            let mut k = 0;
            g.bench_function(format!("{}/{strategy:?}", s.name).to_lowercase(), |b| {
                b.iter(|| {
                    k = (k + 1) % FRAMES;
                    black_box(d.frame(&s.motion.matrix(k)).unwrap().stats.total_drawn)
                })
            });
        }
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
