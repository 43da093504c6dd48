//! Self-checking drivers shared by the fuzz targets and the test suite of
//! `bsp-core`; a `publish = false` crate, so that a user of `bsp-core`
//! compiles only geometry.
//!
//! [`split_case`] and [`build_case`] turn arbitrary bytes into a geometric
//! input ([`SplitInput`], [`BuildInput`]) and run the kernel on it,
//! asserting its invariants exactly. The decoding never rejects: bytes that
//! run out read as zero, and every byte string decodes to some input. The
//! decoders favour the hard cases — shared and repeated vertices, coplanar
//! and touching polygons, cuts through vertices and along edges,
//! coordinates at the limits of the grid.
//!
//! A failed check panics with a message naming the invariant, followed by
//! the decoded input printed as a Rust expression, so that it pastes
//! straight into a regression test:
//!
//! ```
//! use bsp_testkit::SplitInput;
//! let input = SplitInput {
//!     polygon: vec![[0, 0, 0], [4, 0, 0], [4, 4, 0], [0, 4, 0]],
//!     cuts: vec![[[1, 0, 0], [1, 1, 0], [1, 0, 1]], [[0, 0, 0], [4, 4, 0], [0, 0, 1]]],
//! };
//! let report = input.check();
//! assert_eq!((report.spanning, report.pieces), (3, 4));
//! ```
//!
//! The same inputs are produced from bytes by [`SplitInput::decode`]; the
//! inverse, [`SplitInput::encode`], writes the seed corpus of `fuzz/`.

use std::collections::HashMap;
use std::fmt::{self, Debug};

#[macro_use]
mod report;
mod boolean;
mod build;
mod bytes;
mod certify;
mod exact;
mod files;
#[cfg(test)]
mod layout;
mod merge;
mod split;

pub use boolean::{Ball, BooleanInput, Curved, IntBox, Partner, mesh_boolean_case};
pub use build::*;
use bytes::*;
pub use certify::certify_case;
use exact::*;
pub use files::{obj_case, stl_case};
pub use merge::{MergeInput, merge_case};
use report::*;
pub use split::*;

use bsp_core::{
    BspTree, BuildOptions, FlatBsp, GridPoint, Link, MAX_COORD, MAX_VIEW_COORD, Membership, NodeId,
    Order, Plane, Point, Polygon, PolygonSide, Side, Split, ViewPoint,
};

const M: i64 = MAX_COORD as i64;

/// Decodes `data` as a [`SplitInput`] and checks it (see
/// [`SplitInput::check`]). Panics, with the input printed as a Rust
/// expression, if an invariant fails.
///
/// ```
/// bsp_testkit::split_case(b"any bytes at all");
/// bsp_testkit::split_case(&[]);
/// ```
pub fn split_case(data: &[u8]) {
    SplitInput::decode(data).check();
}

/// Decodes `data` as a [`BuildInput`] and checks it (see
/// [`BuildInput::check`]). Panics, with the input printed as a Rust
/// expression, if an invariant fails.
///
/// ```
/// bsp_testkit::build_case(b"any bytes at all");
/// bsp_testkit::build_case(&[]);
/// ```
pub fn build_case(data: &[u8]) {
    BuildInput::decode(data).check();
}

/// The README's example, compiled and run as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::{Path, PathBuf};

    const M32: i32 = MAX_COORD;

    fn corpus_dir(target: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../fuzz/corpus")
            .join(target)
    }

    /// Deterministic pseudo-random bytes.
    fn random_bytes(seed: u64, len: usize) -> Vec<u8> {
        let mut s = seed;
        (0..len)
            .map(|_| {
                s = s.wrapping_add(0x9e37_79b9_7f4a_7c15);
                let mut z = s;
                z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
                z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
                (z ^ (z >> 31)) as u8
            })
            .collect()
    }

    fn split_seeds() -> Vec<SplitInput> {
        let m = M32;
        let s = |polygon: &[GridPoint], cuts: &[[GridPoint; 3]]| SplitInput {
            polygon: polygon.to_vec(),
            cuts: cuts.to_vec(),
        };
        let square = [[0, 0, 0], [4, 0, 0], [4, 4, 0], [0, 4, 0]];
        let x1 = [[1, 0, 0], [1, 1, 0], [1, 0, 1]];
        let diag = [[0, 0, 0], [4, 4, 0], [0, 0, 1]];
        vec![
            // across two edges, then through two vertices
            s(&square, &[x1, diag]),
            // through a vertex and across the opposite edge
            s(
                &[[0, 0, 0], [6, 0, 0], [0, 6, 0]],
                &[[[0, 0, 0], [3, 3, 0], [0, 0, 5]]],
            ),
            // touching a vertex, along an edge, and in the plane (both ways)
            s(
                &[[0, 0, 0], [6, 0, 0], [0, 6, 0]],
                &[
                    [[6, 0, 0], [6, 1, 0], [6, 0, 1]],
                    [[0, 0, 0], [6, 0, 0], [0, 0, 1]],
                    [[0, 0, 0], [1, 0, 0], [0, 1, 0]],
                    [[0, 0, 0], [0, 1, 0], [1, 0, 0]],
                ],
            ),
            // four cuts: pieces with implicit vertices cut again
            s(
                &[
                    [1, 0, 0],
                    [2, 0, 0],
                    [3, 1, 0],
                    [2, 2, 0],
                    [1, 2, 0],
                    [0, 1, 0],
                ],
                &[
                    [[0, 0, 0], [3, 2, 0], [0, 0, 1]],
                    [[0, 2, 0], [3, 0, 0], [0, 2, 7]],
                    [[1, 0, -1], [2, 2, 1], [1, 3, 5]],
                    [[0, 1, 0], [3, 1, 0], [0, 1, 1]],
                ],
            ),
            // repeated and collinear vertices
            s(
                &[
                    [0, 0, 0],
                    [3, 0, 0],
                    [3, 0, 0],
                    [6, 0, 0],
                    [6, 6, 0],
                    [0, 6, 0],
                    [0, 0, 0],
                ],
                &[[[3, 0, 0], [3, 6, 0], [3, 0, 1]]],
            ),
            // the whole grid: a slanted triangle on the cube's corners
            s(
                &[[-m, -m, -m], [m, -m, m], [-m, m, m]],
                &[
                    [[m, m, -m], [-m, -m, m - 1], [m - 2, -m, 0]],
                    [[0, 0, 0], [1, 2, 3], [-m, m, -m]],
                ],
            ),
            // a face of the grid's cube, cut diagonally and near-parallel to an edge
            s(
                &[[-m, -m, m], [m, -m, m], [m, m, m], [-m, m, m]],
                &[
                    [[-m, -m, 0], [m, m, 0], [m, m, 1]],
                    [[-m, -m, 0], [m, -m + 1, 0], [0, 0, 1]],
                ],
            ),
            // a sliver of area 1/2 at the limit
            s(
                &[[-m, 0, 0], [m, 1, 0], [m - 2, 1, 0]],
                &[
                    [[0, -5, 0], [0, 5, 0], [0, 0, 1]],
                    [[m - 1, 0, 0], [m - 1, 1, 0], [m - 1, 0, 1]],
                ],
            ),
            // a tilted quad and a plane through three far points
            s(
                &[[0, 0, 0], [1000, 0, 1], [1000, 1000, 2], [0, 1000, 1]],
                &[
                    [[500, -m, 7], [499, m, -3], [501, 17, m]],
                    [[0, 0, 0], [1000, 1000, 2], [0, 0, 1]],
                ],
            ),
            // invalid polygons: a point, collinear, non-planar, a bow tie
            s(&[[5, 5, 5], [5, 5, 5], [5, 5, 5]], &[x1]),
            s(&[[0, 0, 0], [1, 1, 1], [2, 2, 2]], &[x1]),
            s(&[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 1]], &[x1]),
            s(&[[0, 0, 0], [2, 2, 0], [2, 0, 0], [0, 2, 0]], &[x1]),
            // collinear cut points are skipped
            s(&square, &[[[0, 0, 0], [1, 1, 1], [2, 2, 2]], x1]),
        ]
    }

    fn build_seeds() -> Vec<BuildInput> {
        let m = M32;
        let bi = |scene: Scene, eyes: &[[i64; 3]]| BuildInput {
            scene,
            candidates: 8,
            sample: 48,
            split_weight: 4,
            seed: 0x5eed,
            eyes: eyes.to_vec(),
        };
        let [unit, sheared, limit, flat] = seed_boxes();
        let [soup_shared, fan, crossing, invalid] = seed_soups();
        let far = MAX_VIEW_COORD;
        let mut worst = bi(Scene::Box(sheared.clone()), &[[0, 0, 0]]);
        worst.candidates = 1;
        worst.sample = 1;
        worst.split_weight = 0;
        vec![
            bi(Scene::Box(unit), &[[5, 5, 5], [0, 0, 0], [1, 0, 2]]),
            bi(Scene::Box(sheared), &[[1000, -77, 5], [-far, far, -far]]),
            bi(
                Scene::Box(limit),
                &[[far, far, far], [0, 0, 0], [m as i64, 0, 0]],
            ),
            bi(Scene::Box(flat), &[[50, 1, 50]]),
            worst,
            bi(soup_shared, &[[1, 1, 1], [2, 2, 0], [2, 2, -9]]),
            bi(fan, &[[0, 0, 0], [9, -9, 9]]),
            bi(crossing, &[[1, 2, 3], [-far, 0, 0], [0, 0, 0]]),
            bi(invalid, &[[0, 0, 0]]),
        ]
    }

    /// The boxes of the build seeds: a unit cube, a sheared, mirrored and
    /// moved box, one at the limits of the grid, and a flat one.
    fn seed_boxes() -> [BoxSolid; 4] {
        let m = M32;
        let unit = BoxSolid {
            lo: [0, 0, 0],
            hi: [1, 1, 1],
            splits: [0, 0, 0],
            triangulate: 0,
            shears: [(0, 0, 0); 3],
            mirror: false,
            offset: [0, 0, 0],
            probes: vec![],
            rational_probes: vec![([1, 1, 1], 2), ([2, 1, 1], 2), ([3, 1, 1], 2)],
        };
        let sheared = BoxSolid {
            lo: [-10, -3, 0],
            hi: [10, 7, 4],
            splits: [0, 2, 1],
            triangulate: 0b0110_1101,
            shears: [(0, 1, 3), (2, 0, -2), (1, 2, 5)],
            mirror: true,
            offset: [1000, -77, 5],
            probes: vec![
                [-10, 0, 2],
                [-11, 0, 2],
                [0, 2, 1],
                [10, 7, 4],
                [9, 6, 3],
                [0, 8, 0],
            ],
            rational_probes: vec![
                ([-10 * 4096 + 1, 1, 1], 4096),
                ([-10 * 4096 - 1, 1, 1], 4096),
                ([0, 2 * 3, 3], 3),
                ([1, 1, 1], 1 << 24),
            ],
        };
        let limit = BoxSolid {
            lo: [-m, -m, -m],
            hi: [m, m, m],
            splits: [0, 0, 0],
            triangulate: 0b0011_1111,
            shears: [(0, 0, 0); 3],
            mirror: false,
            offset: [0, 0, 0],
            probes: vec![[m, 0, 0], [m - 1, m - 1, m - 1], [0, 0, 0], [-m, -m, 5]],
            rational_probes: vec![
                ([m as i64 * 3 - 1, 0, 0], 3),
                ([m as i64 * 3 + 1, 0, 0], 3),
                ([m as i64 * (1 << 20), 1, -1], 1 << 20),
            ],
        };
        let flat = BoxSolid {
            lo: [0, 0, 0],
            hi: [100, 1, 100],
            splits: [50, 0, 50],
            triangulate: 0,
            shears: [(1, 0, 1), (0, 0, 0), (0, 0, 0)],
            mirror: false,
            offset: [0, 0, 0],
            probes: vec![[50, 0, 50], [50, 1, 50], [50, 2, 50], [1, 1, 1]],
            rational_probes: vec![([100, 1, 100], 2)],
        };
        [unit, sheared, limit, flat]
    }

    /// The polygon soups of the build seeds: triangles sharing edges with
    /// two quads (and a repeated triangle), a fan over six points, three
    /// planes and a triangle at the limits of the grid, and invalid
    /// polygons.
    fn seed_soups() -> [Scene; 4] {
        let m = M32;
        let tri = |a: GridPoint, b: GridPoint, c: GridPoint| vec![a, b, c];
        let soup_shared = Scene::Soup(vec![
            tri([0, 0, 0], [4, 0, 0], [0, 4, 0]),
            tri([4, 0, 0], [4, 4, 0], [0, 4, 0]),
            tri([0, 4, 0], [4, 0, 0], [0, 0, 0]),
            vec![[2, -1, -2], [2, 5, -2], [2, 5, 2], [2, -1, 2]],
            vec![[-1, 2, -2], [-1, 2, 2], [5, 2, 2], [5, 2, -2]],
            tri([0, 0, 0], [4, 0, 0], [0, 4, 0]),
        ]);
        let pool = [
            [0, 0, 0],
            [3, 0, 1],
            [0, 3, 2],
            [3, 3, -1],
            [1, 1, 5],
            [2, 2, -4],
        ];
        let fan = Scene::Soup(
            (0..12)
                .map(|i| tri(pool[i % 6], pool[(i + 1) % 6], pool[(i * 5 + 3) % 6]))
                .collect(),
        );
        let crossing = Scene::Soup(vec![
            vec![[-m, -m, 0], [m, -m, 0], [m, m, 0], [-m, m, 0]],
            vec![[-m, 0, -m], [-m, 0, m], [m, 0, m], [m, 0, -m]],
            vec![[0, -m, -m], [0, m, -m], [0, m, m], [0, -m, m]],
            tri([-m, -m, -m], [m, -m + 1, m], [m - 3, m, -m]),
        ]);
        let invalid = Scene::Soup(vec![
            tri([0, 0, 0], [1, 1, 1], [2, 2, 2]),
            tri([3, 3, 3], [3, 3, 3], [3, 3, 3]),
            vec![[0, 0, 0], [2, 2, 0], [2, 0, 0], [0, 2, 0]],
        ]);
        [soup_shared, fan, crossing, invalid]
    }

    /// Raw byte strings for the corpus: empty, constant, and random ones
    /// with each leading mode byte.
    fn raw_seeds(n: usize, modes: u8) -> Vec<Vec<u8>> {
        let mut v = vec![vec![], vec![0xff; 64], (0..=255).collect()];
        for i in 0..n {
            let mut b = random_bytes(i as u64 + 1, 24 + 16 * i);
            b[0] = (i % modes as usize) as u8;
            v.push(b);
        }
        v
    }

    /// Boxes `lo + [0, size]`, outward, or inward where `inward`.
    fn int_box(lo: [i32; 3], size: [i32; 3], inward: bool) -> IntBox {
        IntBox { lo, size, inward }
    }

    fn boolean_seeds() -> Vec<BooleanInput> {
        let b = |lo: [i32; 3], size: i32| int_box(lo, [size; 3], false);
        let case = |op, a: Vec<IntBox>, bb: Vec<IntBox>| BooleanInput {
            op,
            a,
            b: bb,
            shear: [0; 3],
            curved: None,
        };
        let ops = [
            BoolOpSeed::Union,
            BoolOpSeed::Intersection,
            BoolOpSeed::Difference,
        ];
        let mut v = Vec::new();
        for op in ops.map(BoolOpSeed::op) {
            // overlapping
            v.push(case(op, vec![b([0, 0, 0], 3)], vec![b([1, 1, 1], 3)]));
            // a shared face, and an edge only
            v.push(case(op, vec![b([0, 0, 0], 2)], vec![b([2, 0, 0], 2)]));
            v.push(case(op, vec![b([0, 0, 0], 2)], vec![b([2, 2, 0], 2)]));
            // the same box twice
            v.push(case(op, vec![b([1, 1, 1], 2)], vec![b([1, 1, 1], 2)]));
            // shells that overlap and nest in one operand, a cavity in the other
            v.push(case(
                op,
                vec![b([0, 0, 0], 3), b([2, 2, 2], 3), b([0, 0, 0], 1)],
                vec![b([1, 0, 1], 4), int_box([2, 1, 2], [1, 2, 1], true)],
            ));
            // overlapping and sharing a face, sheared
            for shear in [[1, 0, 0], [-2, 1, 2]] {
                let mut c = case(
                    op,
                    vec![b([0, 0, 0], 3), b([3, 0, 0], 2)],
                    vec![b([1, 1, 1], 3)],
                );
                c.shear = shear;
                v.push(c);
            }
        }
        // curved: overlapping spheres, a copy moved by nothing, by a bit
        // and by less than the grid step, one nested, one with boxes
        let ball = |stacks, radius, centre, turn| Ball {
            stacks,
            radius,
            centre,
            turn,
        };
        let a = ball(6, 2, [4, 4, 4], 0);
        let partners = [
            Partner::Ball(ball(5, 2, [5, 4, 3], 3)),
            Partner::Ball(ball(4, 1, [4, 4, 8], 1)),
            Partner::Copy { shift: 0 },
            Partner::Copy { shift: 3 },
            Partner::Copy { shift: 40 },
            Partner::Nested,
            Partner::Boxes,
        ];
        for (k, partner) in partners.into_iter().enumerate() {
            let mut c = case(
                bsp_core::BoolOp::Union,
                vec![b([0, 0, 0], 1)],
                vec![b([2, 1, 2], 3)],
            );
            c.curved = Some(Curved {
                a,
                b: partner,
                probes: k as u8,
                joined: false,
            });
            v.push(c);
        }
        // joined into one mesh that crosses itself: a coarse sphere's
        // faces across a fine one, a fine sphere across a box's faces
        let coarse_fine = (
            ball(3, 3, [4, 4, 4], 2),
            Partner::Ball(ball(8, 2, [5, 4, 4], 5)),
        );
        let fine_boxes = (ball(8, 2, [4, 4, 4], 1), Partner::Boxes);
        for (k, (a, partner)) in [coarse_fine, fine_boxes].into_iter().enumerate() {
            let mut c = case(
                bsp_core::BoolOp::Union,
                vec![b([0, 0, 0], 1)],
                vec![b([1, 2, 1], 3)],
            );
            c.curved = Some(Curved {
                a,
                b: partner,
                probes: 9 + k as u8,
                joined: true,
            });
            v.push(c);
        }
        v
    }

    /// [`BoolOp`](bsp_core::BoolOp) by name, for the seed table.
    #[derive(Clone, Copy)]
    enum BoolOpSeed {
        Union,
        Intersection,
        Difference,
    }

    impl BoolOpSeed {
        fn op(self) -> bsp_core::BoolOp {
            match self {
                BoolOpSeed::Union => bsp_core::BoolOp::Union,
                BoolOpSeed::Intersection => bsp_core::BoolOp::Intersection,
                BoolOpSeed::Difference => bsp_core::BoolOp::Difference,
            }
        }
    }

    /// Files for the readers: well-formed, odd and broken ones.
    fn file_seeds(target: &str) -> Vec<Vec<u8>> {
        match target {
            "obj" => [
                "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
                 f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n",
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\ng a\nf 1/1/1 2/1/1 3/1/1\n",
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\no x\nusemtl m\ns off\n",
                "v 0 0 0\nf 1 2 3\n",
                "v 1e400 0 0\nv nan 0 0\nv 0 0\nf 1 1 1\n",
                "v 0 0 0 1\nv 1 0 0\nv 0 1 0\nf 1 2 3 4294967296\n\\\n",
                "\u{feff}# comment\r\nv 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n",
            ]
            .map(|s| s.as_bytes().to_vec())
            .to_vec(),
            _ => {
                let ascii = b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n\
                              vertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
                let binary = |claimed: u32, triangles: usize| {
                    let mut b = vec![0u8; 80];
                    b.extend(claimed.to_le_bytes());
                    for t in 0..triangles {
                        b.extend([0u8; 12]);
                        for c in [[0.0f32, 0.0, 0.0], [1.0, 0.0, t as f32], [0.0, 1.0, 0.0]] {
                            c.iter().for_each(|x| b.extend(x.to_le_bytes()));
                        }
                        b.extend([0u8; 2]);
                    }
                    b
                };
                vec![
                    ascii.to_vec(),
                    binary(1, 1),
                    binary(3, 3),
                    binary(4_000_000_000, 1),
                    binary(2, 1),
                    b"solid x\nfacet\nvertex 1 2\nendsolid\n".to_vec(),
                    vec![0u8; 83],
                ]
            }
        }
    }

    fn seed_files(target: &str) -> Vec<(String, Vec<u8>)> {
        let (named, raw): (Vec<Vec<u8>>, Vec<Vec<u8>>) = match target {
            "split" => (
                split_seeds().iter().map(SplitInput::encode).collect(),
                raw_seeds(8, 4),
            ),
            "mesh_boolean" => (
                boolean_seeds().iter().map(BooleanInput::encode).collect(),
                raw_seeds(8, 3),
            ),
            "obj" | "stl" => (file_seeds(target), raw_seeds(4, 255)),
            "certify" => (
                (0..24u64)
                    .map(|i| {
                        let mut b = vec![(i % 4) as u8];
                        b.extend((0x5eed + i).to_le_bytes());
                        b
                    })
                    .collect(),
                raw_seeds(4, 3),
            ),
            _ => (
                build_seeds().iter().map(BuildInput::encode).collect(),
                raw_seeds(8, 4),
            ),
        };
        let named = named
            .into_iter()
            .enumerate()
            .map(|(i, b)| (format!("seed-{i:02}"), b));
        let raw = raw
            .into_iter()
            .enumerate()
            .map(|(i, b)| (format!("seed-raw-{i:02}"), b));
        named.chain(raw).collect()
    }

    /// The targets whose `seed-*` files come from the seeds above (merge's
    /// are its own, in `merge.rs`).
    const SEEDED: [&str; 6] = [
        "split",
        "build_tree",
        "mesh_boolean",
        "obj",
        "stl",
        "certify",
    ];

    /// Rewrites the `seed-*` files of `fuzz/corpus/` from the seeds above:
    /// `cargo test -p bsp-testkit --lib tests::write_seed_corpus -- --ignored`.
    #[test]
    #[ignore = "writes fuzz/corpus; run by hand after changing the seeds or the decoders"]
    fn write_seed_corpus() {
        for target in SEEDED {
            let dir = corpus_dir(target);
            std::fs::create_dir_all(&dir).unwrap();
            for e in std::fs::read_dir(&dir).unwrap() {
                let p = e.unwrap().path();
                if p.file_name()
                    .unwrap()
                    .to_string_lossy()
                    .starts_with("seed-")
                {
                    std::fs::remove_file(p).unwrap();
                }
            }
            for (name, bytes) in seed_files(target) {
                std::fs::write(dir.join(name), bytes).unwrap();
            }
        }
    }

    #[test]
    fn seed_corpus_is_up_to_date() {
        for target in SEEDED {
            for (name, bytes) in seed_files(target) {
                let path = corpus_dir(target).join(&name);
                let on_disk = std::fs::read(&path)
                    .unwrap_or_else(|e| panic!("{}: {e} (run write_seed_corpus)", path.display()));
                assert!(
                    on_disk == bytes,
                    "{} is stale (run write_seed_corpus)",
                    path.display()
                );
            }
        }
    }

    #[test]
    fn seeds_round_trip_through_bytes() {
        for s in split_seeds() {
            assert_eq!(SplitInput::decode(&s.encode()), s);
        }
        for s in build_seeds() {
            assert_eq!(BuildInput::decode(&s.encode()), s);
        }
        for s in boolean_seeds() {
            assert_eq!(BooleanInput::decode(&s.encode()), s);
        }
    }

    /// Runs `check` on the input, printing it as a Rust expression if the
    /// kernel panics (the checks themselves already print it).
    fn run_reporting<T: Debug, R>(name: &str, input: &T, check: impl FnOnce(&T) -> R) -> R {
        match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| check(input))) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("{name} failed; decoded input:\n{input:?}");
                std::panic::resume_unwind(e)
            }
        }
    }

    fn corpus_files(target: &str) -> Vec<PathBuf> {
        let mut files: Vec<PathBuf> = std::fs::read_dir(corpus_dir(target))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.is_file() && !p.file_name().unwrap().to_string_lossy().starts_with('.'))
            .collect();
        // BSP_CHECK_REPLAY=<file or directory>: also run those (e.g. a crash artifact)
        if let Some(extra) = std::env::var_os(format!("BSP_CHECK_REPLAY_{}", target.to_uppercase()))
        {
            let extra = PathBuf::from(extra);
            if extra.is_dir() {
                files.extend(std::fs::read_dir(extra).unwrap().map(|e| e.unwrap().path()));
            } else {
                files.push(extra);
            }
        }
        files.sort();
        files
    }

    #[test]
    fn split_corpus_passes_and_covers_the_cases() {
        let mut total = SplitReport::default();
        let mut valid = 0;
        let files = corpus_files("split");
        assert!(
            files.len() >= 10,
            "fuzz/corpus/split has {} files",
            files.len()
        );
        for f in &files {
            let input = SplitInput::decode(&std::fs::read(f).unwrap());
            let r = run_reporting(&f.display().to_string(), &input, SplitInput::check);
            valid += usize::from(r.valid);
            total.spanning += r.spanning;
            total.one_sided += r.one_sided;
            total.coplanar += r.coplanar;
            total.through_vertex += r.through_vertex;
        }
        eprintln!(
            "split corpus: {} files, {valid} valid polygons, {total:?}",
            files.len()
        );
        assert!(valid >= files.len() / 2, "only {valid} valid polygons");
        assert!(total.spanning >= 10, "{total:?}");
        assert!(total.through_vertex >= 3, "{total:?}");
        assert!(total.one_sided >= 3 && total.coplanar >= 2, "{total:?}");
    }

    #[test]
    fn build_corpus_passes_and_covers_the_cases() {
        let mut total = BuildReport::default();
        let files = corpus_files("build_tree");
        assert!(
            files.len() >= 10,
            "fuzz/corpus/build_tree has {} files",
            files.len()
        );
        for f in &files {
            let input = BuildInput::decode(&std::fs::read(f).unwrap());
            let r = run_reporting(&f.display().to_string(), &input, BuildInput::check);
            total.fragments += r.fragments;
            total.traversals += r.traversals;
            total.implicit_probes += r.implicit_probes;
            for k in 0..3 {
                total.membership[k] += r.membership[k];
            }
        }
        eprintln!("build corpus: {} files, {total:?}", files.len());
        assert!(
            total.fragments >= 100 && total.traversals >= 20,
            "{total:?}"
        );
        assert!(total.membership.iter().all(|&n| n >= 10), "{total:?}");
        assert!(total.implicit_probes >= 10, "{total:?}");
    }

    #[test]
    fn mesh_boolean_corpus_passes() {
        let files = corpus_files("mesh_boolean");
        assert!(
            files.len() >= 20,
            "fuzz/corpus/mesh_boolean has {} files",
            files.len()
        );
        let (mut checked, mut cells) = (0, 0);
        for f in &files {
            let input = BooleanInput::decode(&std::fs::read(f).unwrap());
            if let Some(n) = run_reporting(&f.display().to_string(), &input, BooleanInput::check) {
                checked += 1;
                cells += n;
            }
        }
        eprintln!(
            "mesh_boolean corpus: {} files, {checked} checked, {cells} cells",
            files.len()
        );
        assert!(checked >= files.len() * 3 / 4 && cells > 100);
    }

    /// The corpora of the targets whose case says yes or no (certified,
    /// read): every file passes, and both verdicts are exercised.
    #[test]
    fn verdict_corpora_pass() {
        type Case = fn(&[u8]) -> bool;
        let targets: [(&str, Case, usize); 3] = [
            ("certify", certify_case, 20),
            ("obj", obj_case, 10),
            ("stl", stl_case, 10),
        ];
        for (target, case, least) in targets {
            let files = corpus_files(target);
            let n = files.len();
            assert!(n >= least, "fuzz/corpus/{target} has {n} files");
            let yes = files
                .iter()
                .filter(|f| case(&std::fs::read(f).unwrap()))
                .count();
            assert!(yes >= 2 && yes < n, "{target}: {yes} of {n}");
        }
    }

    #[test]
    fn random_bytes_pass() {
        let mut spanning = 0;
        let mut membership = 0;
        for i in 0..400u64 {
            let b = random_bytes(0xabcd + i, (i as usize * 7) % 300);
            let s = SplitInput::decode(&b);
            spanning += run_reporting("split", &s, SplitInput::check).spanning;
            let t = BuildInput::decode(&b);
            membership += run_reporting("build", &t, BuildInput::check)
                .membership
                .iter()
                .sum::<usize>();
        }
        eprintln!("random bytes: {spanning} spans, {membership} probes");
        // random bytes reach the interesting paths, not only early returns
        assert!(
            spanning >= 50 && membership >= 50,
            "{spanning} spans, {membership} probes"
        );
    }

    #[test]
    fn splits_of_a_square() {
        let r = split_seeds()[0].check();
        assert!(r.valid);
        // x = 1 cuts the square; the diagonal cuts both pieces, through a vertex each
        assert_eq!((r.spanning, r.through_vertex, r.pieces), (3, 2, 4));
    }

    fn panic_message(f: impl FnOnce()) -> String {
        let e = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_err();
        *e.downcast::<String>().unwrap()
    }

    #[test]
    fn cover_check_catches_lost_and_stray_pieces() {
        let sq =
            Polygon::from_grid_points(&[[0, 0, 0], [4, 0, 0], [4, 4, 0], [0, 4, 0]], 0).unwrap();
        let Split::Spanning { front, back } = sq.clone().split(&Plane::new([1, 0, 0], -1).unwrap())
        else {
            panic!("x = 1 spans the square")
        };
        check_cover(&"demo", &sq, &[&front, &back], "both pieces");
        let msg = panic_message(|| check_cover(&"demo", &sq, &[&front], "one piece"));
        assert!(msg.contains("one piece: the pieces' area vector"), "{msg}");
        let big =
            Polygon::from_grid_points(&[[0, 0, 0], [5, 0, 0], [5, 4, 0], [0, 4, 0]], 0).unwrap();
        let msg = panic_message(|| check_cover(&"demo", &sq, &[&big], "stray"));
        assert!(msg.contains("is outside edge plane"), "{msg}");
        let tilted = Polygon::from_grid_points(&[[0, 0, 0], [4, 0, 1], [0, 4, 0]], 0).unwrap();
        let msg = panic_message(|| check_cover(&"demo", &sq, &[&tilted], "tilted"));
        assert!(msg.contains("has support"), "{msg}");
    }

    #[test]
    fn failures_print_the_input_as_rust() {
        let input = SplitInput {
            polygon: vec![[0, 0, 0], [1, 0, 0], [0, 1, 0]],
            cuts: vec![[[0, 0, 0], [0, 1, 0], [0, 0, 1]]],
        };
        let msg = panic_message(|| fail(&input, format_args!("demo")));
        assert!(msg.starts_with("check failed: demo"), "{msg}");
        assert!(
            msg.contains(
                "SplitInput { polygon: vec![[0, 0, 0], [1, 0, 0], [0, 1, 0]], \
                 cuts: vec![[[0, 0, 0], [0, 1, 0], [0, 0, 1]]] }"
            ),
            "{msg}"
        );
        let b = format!("{:?}", build_seeds()[1]);
        assert!(
            b.starts_with("BuildInput { scene: Scene::Box(BoxSolid { lo: [-10, -3, 0]"),
            "{b}"
        );
        assert!(b.contains("probes: vec![[-10, 0, 2]"), "{b}");
        let soup = format!("{:?}", build_seeds()[5].scene);
        assert!(
            soup.starts_with("Scene::Soup(vec![vec![[0, 0, 0]"),
            "{soup}"
        );
    }
}
