//! Random small scenes (proptest): 3–12 triangles and quads in a small
//! integer box, biased toward degenerate input — shared edges, coplanar,
//! repeated and flipped faces — lit by 1–3 lights that are often placed
//! degenerately: on a face's plane, on an edge's line, at a vertex, or a
//! sun parallel to a face. Every flag is checked by the ray oracle and
//! every face's tiling exactly.

use bsp_core::{MAX_COORD, Polygon};
use proptest::prelude::*;
use svbsp::Light;

use crate::harness::{Opts, Sample, check, polygons, scene_of};
use crate::scenes::{FaceGen, LightGen, P3, Transform, make_faces, make_lights};

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

/// Small faces crowded in a larger box, with the same degenerate
/// relations as [`face_gen`] (shared edges, coplanar, repeated and flipped
/// faces), and sometimes a long triangle on an earlier face's edge.
fn crowd_face_gen() -> impl Strategy<Value = FaceGen> {
    let near = || (pt(0, 20), pt(-3, 3), pt(-3, 3));
    let add = |p: P3, d: P3| [0, 1, 2].map(|k| p[k] + d[k]);
    prop_oneof![
        3 => near().prop_map(move |(p, a, b)| FaceGen::Triangle(p, add(p, a), add(p, b))),
        2 => near().prop_map(|(p, a, b)| FaceGen::Parallelogram(p, a, b)),
        2 => (any::<usize>(), 0..4usize, pt(0, 20)).prop_map(|(f, e, p)| FaceGen::SharedEdge(f, e, p)),
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

/// The scene and lights the generators describe (at least `min_faces`
/// faces, else the case is rejected), checked by [`check`] with `opts`.
fn check_generated(
    faces: &[FaceGen],
    lights: &[LightGen],
    t: &Transform,
    opts: &Opts,
    min_faces: usize,
) -> Result<(), TestCaseError> {
    let loops = make_faces(faces, t);
    prop_assume!(loops.len() >= min_faces);
    let lights = make_lights(lights, &loops, t);
    let polys = polygons(&loops).map_err(TestCaseError::fail)?;
    match check(&polys, &scene_of(&loops), &lights, opts) {
        Ok(_) => Ok(()),
        Err(e) => Err(TestCaseError::fail(format!(
            "{e}\nloops: {loops:?}\nlights: {lights:?}"
        ))),
    }
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
        let opts = Opts { seeds: vec![1, 2], ..Opts::default() };
        check_generated(&faces, &lights, &t, &opts, 1)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: cases(2),
        ..ProptestConfig::default()
    })]

    /// More occluders than a skeleton leaf holds (`LEAF_SIZE`), so the
    /// shadow trees are cut into regions, with the faces turned away from
    /// a light going down the skeleton late: the paths the small scenes
    /// above never reach, with their degenerate relations. Fragments are
    /// sampled for the ray oracle (each face's tiling is checked whole).
    #[test]
    fn crowded_scenes_match_the_ray_oracle(
        faces in proptest::collection::vec(crowd_face_gen(), 120..=200),
        lights in proptest::collection::vec(light_gen(), 1..=2),
        t in transform(),
    ) {
        let opts = Opts { seeds: vec![1], sample: Sample::PerKind(16), ..Opts::default() };
        check_generated(&faces, &lights, &t, &opts, 101)?;
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
