//! Random small scenes (proptest): 3–12 triangles and quads in a small
//! integer box, biased toward degenerate input — shared edges, coplanar,
//! repeated and flipped faces — lit by 1–3 lights that are often placed
//! degenerately: on a face's plane, on an edge's line, at a vertex, or a
//! sun parallel to a face. Every flag is checked by the ray oracle and
//! every face's tiling exactly.

use bsp_core::{MAX_COORD, Polygon};
use proptest::prelude::*;
use svbsp::Light;

use crate::harness::{Opts, check, polygons, scene_of};

type P3 = [i32; 3];

/// How to make one face, possibly from earlier ones (indices are taken
/// modulo the number of faces made so far).
#[derive(Clone, Debug)]
pub(crate) enum FaceGen {
    Triangle(P3, P3, P3),
    /// `p, p + a, p + a + b, p + b`.
    Parallelogram(P3, P3, P3),
    /// A triangle on edge `edge` of face `face` (reversed, as a closed
    /// mesh would have it), with a new apex.
    SharedEdge(usize, usize, P3),
    /// A triangle in the plane of face `face`: `v0 + a e1 + b e2`.
    Coplanar(usize, [(i32, i32); 3]),
    Copy(usize),
    Flipped(usize),
}

/// How to place one light, possibly from a face.
#[derive(Clone, Debug)]
pub(crate) enum LightGen {
    Point(P3),
    /// `v0 + a e1 + b e2` of face `face`: on its plane (at a vertex for
    /// `(0, 0)`, `(1, 0)`, `(0, 1)`, on an edge's line for `a = 0` or
    /// `b = 0`).
    OnPlane(usize, i32, i32),
    /// A point light `2^22` times farther out than `Point`'s range.
    Far(P3),
    Sun(P3),
    /// `a e1 + b e2` of face `face`: a sun parallel to it.
    SunAlong(usize, i32, i32),
}

fn add(a: P3, b: P3) -> P3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn sub(a: P3, b: P3) -> P3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn mul(a: P3, s: i32) -> P3 {
    a.map(|c| c * s)
}

/// `v0 + a (v1 - v0) + b (v2 - v0)` of a loop.
fn in_plane(l: &[P3], a: i32, b: i32) -> P3 {
    let (e1, e2) = (sub(l[1], l[0]), sub(l[2], l[0]));
    add(l[0], add(mul(e1, a), mul(e2, b)))
}

/// A scaling and translation of the whole scene (point lights too): the
/// same configurations with large coordinates, where the kernel's float
/// filters cannot decide and the exact tiers must.
#[derive(Clone, Debug)]
pub(crate) struct Transform {
    pub(crate) scale: i32,
    pub(crate) offset: P3,
}

impl Transform {
    fn apply(&self, p: P3) -> P3 {
        add(mul(p, self.scale), self.offset)
    }
}

/// The loops the generators describe, each cleaned to its polygon's
/// vertices; invalid ones (no area, not convex, off the grid once
/// transformed) are skipped.
pub(crate) fn make_faces(gens: &[FaceGen], t: &Transform) -> Vec<Vec<P3>> {
    let mut out: Vec<Vec<P3>> = Vec::new();
    for g in gens {
        let prev =
            |i: usize| -> Option<&Vec<P3>> { (!out.is_empty()).then(|| &out[i % out.len()]) };
        let l: Option<Vec<P3>> = match g {
            FaceGen::Triangle(a, b, c) => Some(vec![*a, *b, *c]),
            FaceGen::Parallelogram(p, a, b) => {
                Some(vec![*p, add(*p, *a), add(add(*p, *a), *b), add(*p, *b)])
            }
            FaceGen::SharedEdge(f, e, apex) => prev(*f).map(|l| {
                let i = e % l.len();
                vec![l[(i + 1) % l.len()], l[i], *apex]
            }),
            FaceGen::Coplanar(f, c) => {
                prev(*f).map(|l| c.iter().map(|&(a, b)| in_plane(l, a, b)).collect())
            }
            FaceGen::Copy(f) => prev(*f).cloned(),
            FaceGen::Flipped(f) => prev(*f).map(|l| l.iter().rev().copied().collect()),
        };
        if let Some(p) = l.and_then(|l| Polygon::from_grid_points(&l, 0).ok()) {
            out.push(
                p.vertices()
                    .iter()
                    .map(|v| v.as_grid().expect("grid vertex"))
                    .collect(),
            );
        }
    }
    // (faces the transform carries off the grid are left out: the
    // kernel refuses coordinates beyond MAX_COORD)
    out.into_iter()
        .map(|l| l.into_iter().map(|p| t.apply(p)).collect::<Vec<P3>>())
        .filter(|l| l.iter().flatten().all(|c| c.abs() <= MAX_COORD))
        .collect()
}

/// The lights the generators describe (a sun along a face that comes out
/// zero, and lights off the grid, are skipped).
pub(crate) fn make_lights(gens: &[LightGen], faces: &[Vec<P3>], t: &Transform) -> Vec<Light> {
    gens.iter()
        .filter_map(|g| {
            let face = |i: usize| &faces[i % faces.len()];
            match g {
                LightGen::Point(p) => Some(Light::Point(t.apply(*p))),
                LightGen::Far(p) => Some(Light::Point(mul(*p, 1 << 22))),
                LightGen::OnPlane(f, a, b) => Some(Light::Point(in_plane(face(*f), *a, *b))),
                LightGen::Sun(d) => (*d != [0, 0, 0]).then_some(Light::Directional(*d)),
                LightGen::SunAlong(f, a, b) => {
                    let l = face(*f);
                    let d = add(mul(sub(l[1], l[0]), *a), mul(sub(l[2], l[0]), *b));
                    (d != [0, 0, 0]).then_some(Light::Directional(d))
                }
            }
        })
        .filter(|l| l.validate().is_ok())
        .collect()
}

fn pt(lo: i32, hi: i32) -> impl Strategy<Value = P3> {
    [lo..=hi, lo..=hi, lo..=hi]
}

fn face_gen() -> impl Strategy<Value = FaceGen> {
    prop_oneof![
        3 => (pt(0, 6), pt(0, 6), pt(0, 6)).prop_map(|(a, b, c)| FaceGen::Triangle(a, b, c)),
        2 => (pt(0, 6), pt(-3, 3), pt(-3, 3)).prop_map(|(p, a, b)| FaceGen::Parallelogram(p, a, b)),
        2 => (any::<usize>(), 0..4usize, pt(0, 6)).prop_map(|(f, e, p)| FaceGen::SharedEdge(f, e, p)),
        1 => (any::<usize>(), [(-2..=2, -2..=2), (-2..=2, -2..=2), (-2..=2, -2..=2)])
            .prop_map(|(f, c)| FaceGen::Coplanar(f, c)),
        1 => any::<usize>().prop_map(FaceGen::Copy),
        1 => any::<usize>().prop_map(FaceGen::Flipped),
    ]
}

fn light_gen() -> impl Strategy<Value = LightGen> {
    prop_oneof![
        3 => pt(-2, 8).prop_map(LightGen::Point),
        1 => pt(-3, 3).prop_map(LightGen::Far),
        2 => (any::<usize>(), -2..=3, -2..=3).prop_map(|(f, a, b)| LightGen::OnPlane(f, a, b)),
        2 => pt(-3, 3).prop_map(LightGen::Sun),
        1 => (any::<usize>(), -2..=2, -2..=2).prop_map(|(f, a, b)| LightGen::SunAlong(f, a, b)),
    ]
}

fn transform() -> impl Strategy<Value = Transform> {
    let t = |scale: i32, offset: P3| Transform { scale, offset };
    prop_oneof![
        4 => Just(t(1, [0, 0, 0])),
        1 => Just(t(1, [-(1 << 25), 1 << 24, 12_345])),
        1 => Just(t((1 << 20) + 1, [-(1 << 25), 3, 1 << 24])),
        1 => Just(t(1_234_567, [5_000_000, -(1 << 25), 0])),
    ]
}

/// Cases per property: `SVBSP_CASES` in the environment, for longer
/// hunts, else `default`.
fn cases(default: u32) -> u32 {
    std::env::var("SVBSP_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

fn big_pt() -> impl Strategy<Value = P3> {
    let m = MAX_COORD;
    [-m..=m, -m..=m, -m..=m]
}

/// Faces spanning the whole grid: random triangles, and triangles in the
/// plane of an earlier one (`v0 + a e1 + b e2` with small `a`, `b`, kept
/// only if they stay on the grid).
fn big_faces() -> impl Strategy<Value = Vec<Vec<P3>>> {
    let face = prop_oneof![
        2 => (big_pt(), big_pt(), big_pt()).prop_map(|(a, b, c)| (vec![a, b, c], None)),
        1 => (any::<usize>(), [(-1..=1i64, -1..=1i64), (-1..=1, -1..=1), (-1..=1, -1..=1)])
            .prop_map(|(f, c)| (Vec::new(), Some((f, c)))),
    ];
    proptest::collection::vec(face, 3..=8).prop_map(|gens| {
        let mut out: Vec<Vec<P3>> = Vec::new();
        for (l, co) in gens {
            let l = match co {
                None => l,
                Some((f, c)) if !out.is_empty() => {
                    let b = &out[f % out.len()];
                    let w = |p: P3| p.map(i64::from);
                    let (v0, v1, v2) = (w(b[0]), w(b[1]), w(b[2]));
                    let pts: Option<Vec<P3>> = c
                        .iter()
                        .map(|&(x, y)| {
                            let p: [i64; 3] = [0, 1, 2]
                                .map(|k| v0[k] + x * (v1[k] - v0[k]) + y * (v2[k] - v0[k]));
                            p.iter()
                                .all(|c| c.abs() <= MAX_COORD as i64)
                                .then(|| p.map(|c| c as i32))
                        })
                        .collect();
                    match pts {
                        Some(p) => p,
                        None => continue,
                    }
                }
                Some(_) => continue,
            };
            if let Ok(p) = Polygon::from_grid_points(&l, 0) {
                out.push(
                    p.vertices()
                        .iter()
                        .map(|v| v.as_grid().expect("grid"))
                        .collect(),
                );
            }
        }
        out
    })
}

fn big_light() -> impl Strategy<Value = Light> {
    prop_oneof![
        big_pt().prop_map(Light::Point),
        big_pt().prop_map(Light::Directional),
        pt(-1, 1)
            .prop_filter("a sun needs a direction", |d| *d != [0, 0, 0])
            .prop_map(Light::Directional),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: cases(384),
        ..ProptestConfig::default()
    })]

    #[test]
    fn random_scenes_match_the_ray_oracle(
        faces in proptest::collection::vec(face_gen(), 3..=12),
        lights in proptest::collection::vec(light_gen(), 1..=3),
        t in transform(),
    ) {
        let loops = make_faces(&faces, &t);
        prop_assume!(!loops.is_empty());
        let lights = make_lights(&lights, &loops, &t);
        let polys = polygons(&loops).map_err(TestCaseError::fail)?;
        let opts = Opts { seeds: vec![1, 2], ..Opts::default() };
        let r = check(&polys, &scene_of(&loops), &lights, &opts);
        if let Err(e) = r {
            return Err(TestCaseError::fail(format!(
                "{e}\nloops: {loops:?}\nlights: {lights:?}"
            )));
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: cases(48),
        ..ProptestConfig::default()
    })]

    /// Coordinates and lights anywhere on the grid: the widest numbers
    /// the shadow tier must hold.
    #[test]
    fn grid_wide_scenes_match_the_ray_oracle(
        loops in big_faces(),
        lights in proptest::collection::vec(big_light(), 1..=3),
    ) {
        prop_assume!(!loops.is_empty());
        let polys = polygons(&loops).map_err(TestCaseError::fail)?;
        let opts = Opts { seeds: vec![1, 2], ..Opts::default() };
        let r = check(&polys, &scene_of(&loops), &lights, &opts);
        if let Err(e) = r {
            return Err(TestCaseError::fail(format!(
                "{e}\nloops: {loops:?}\nlights: {lights:?}"
            )));
        }
    }
}
