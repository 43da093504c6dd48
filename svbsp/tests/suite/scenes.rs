//! The small scenes of the random tests and the `shadows` fuzz target,
//! described by generators: 3–12 triangles and quads in a small integer
//! box, biased toward degenerate input (shared edges, coplanar, repeated
//! and flipped faces), lit by lights often placed degenerately (on a
//! face's plane, on an edge's line, at a vertex, a sun parallel to a
//! face), the whole scene possibly scaled and moved far out on the grid.

use bsp_core::{MAX_COORD, Polygon};
use svbsp::Light;

pub(crate) type P3 = [i32; 3];

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
