//! The answer from scratch that the pipeline's frames are checked
//! against, shared by the tests and the `pipeline` fuzz target (which
//! includes this file by path): every face's exact lit area per set of
//! flags, as rationals, from `svbsp::shadow_fragments` on the frame's
//! whole scene.

use std::collections::BTreeMap;
use std::str::FromStr;

use bsp_core::{Grid, Polygon};
use glam::{DMat4, DVec3};
use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::Zero;
use svbsp::Vertex;
use svbsp::{Batch, Light, LightSpec, place_lights, shadow_fragments, shared_grid};
use tiling::{Dynamic, FragmentView, Motion, PipelineOptions, Strategy};

pub(crate) type Q = BigRational;

pub(crate) fn big(s: impl ToString) -> BigInt {
    BigInt::from_str(&s.to_string()).expect("an integer")
}

/// Exact homogeneous coordinates `(x, y, z, w)`, `w > 0`.
pub(crate) type H = [BigInt; 4];

pub(crate) fn of_vertex(v: &Vertex) -> H {
    match v {
        Vertex::Grid(g) => [big(g[0]), big(g[1]), big(g[2]), BigInt::from(1)],
        Vertex::Implicit(i) => (*i.coords()).map(big),
    }
}

/// Twice the signed area of a ring projected along `axis` (exact).
pub(crate) fn ring_area(ring: &[H], axis: usize) -> Q {
    let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
    let k = ring.len();
    let mut s = Q::zero();
    for i in 0..k {
        let (p, q) = (&ring[i], &ring[(i + 1) % k]);
        let num = &p[a] * &q[b] - &q[a] * &p[b];
        s += Q::new(num, &p[3] * &q[3]);
    }
    s
}

/// Per (face, lit mask): the exact area, as twice the area projected
/// along the face's dominant axis.
pub(crate) type Areas = BTreeMap<(u32, u64), Q>;

pub(crate) fn add(areas: &mut Areas, face: u32, lit: u64, rings: &[Vec<H>], axis: usize) {
    let mut s = Q::zero();
    for r in rings {
        s += ring_area(r, axis);
    }
    *areas.entry((face, lit)).or_insert_with(Q::zero) += s;
}

pub(crate) fn batch_areas(b: &Batch) -> Areas {
    let mut out = Areas::new();
    for f in b.fragments() {
        let axis = f.support().dominant_axis();
        let rings: Vec<Vec<H>> = f
            .rings()
            .map(|r| r.iter().map(|&v| of_vertex(b.vertex(v).unwrap())).collect())
            .collect();
        add(&mut out, f.face(), f.lit_mask(), &rings, axis);
    }
    out
}

pub(crate) fn frame_areas(d: &Dynamic, frame: &tiling::Frame) -> Areas {
    let mut out = Areas::new();
    d.each_fragment(frame, |v| match v {
        FragmentView::Region(f) => {
            let b = f.batch();
            let rings: Vec<Vec<H>> = f
                .rings()
                .map(|r| r.iter().map(|&v| of_vertex(b.vertex(v).unwrap())).collect())
                .collect();
            add(
                &mut out,
                f.face(),
                f.lit_mask(),
                &rings,
                f.support().dominant_axis(),
            );
        }
        FragmentView::Convex(f) => {
            let ring: Vec<H> = f.vertices().map(|p| (*p.homogeneous()).map(big)).collect();
            add(
                &mut out,
                f.face(),
                f.lit_mask(),
                &[ring],
                f.support().dominant_axis(),
            );
        }
    });
    out
}

/// Drops zero areas (a face lit one way over no area at all).
pub(crate) fn nonzero(a: Areas) -> Areas {
    a.into_iter().filter(|(_, v)| !v.is_zero()).collect()
}

/// One grid for every frame (the static scene, the lights and every
/// position the object takes in `frames` of `motion`), and the lights
/// placed on it.
pub(crate) fn grid_and_lights(
    statics: &[Vec<DVec3>],
    moving: &[Vec<DVec3>],
    lights: &[LightSpec],
    motion: &Motion,
    frames: u32,
) -> (Grid, Vec<Light>) {
    let mut pts: Vec<DVec3> = statics.iter().flatten().copied().collect();
    for k in 0..frames {
        let m = motion.matrix(k);
        pts.extend(moving.iter().flatten().map(|&p| m.transform_point3(p)));
    }
    let grid: Grid = shared_grid(&pts, lights).unwrap();
    let placed: Vec<Light> = place_lights(&grid, lights)
        .unwrap()
        .iter()
        .map(|l| l.light)
        .collect();
    (grid, placed)
}

/// Runs `frames` of `motion` with `strategy` and checks each against the
/// computation from scratch. Returns the frames' figures.
pub(crate) fn check_motion(
    statics: &[Vec<DVec3>],
    moving: &[Vec<DVec3>],
    lights: &[LightSpec],
    motion: &Motion,
    frames: u32,
    strategy: Strategy,
    tiles: Option<u32>,
) -> Vec<tiling::FrameStats> {
    let (grid, placed) = grid_and_lights(statics, moving, lights, motion, frames);
    let opts = PipelineOptions::default()
        .with_strategy(strategy)
        .with_tiles(tiles);
    let d = Dynamic::new(statics, moving, grid, &placed, opts).unwrap();
    let mut related = Vec::new();
    for k in 0..frames {
        let m: DMat4 = motion.matrix(k);
        let frame = d.frame(&m).unwrap();
        let mut all: Vec<Polygon> = d.static_polygons().to_vec();
        all.extend(frame.moved.iter().cloned());
        let (scratch, _) = shadow_fragments(&all, &placed).unwrap();
        let want = nonzero(batch_areas(&scratch));
        let got = nonzero(frame_areas(&d, &frame));
        if want != got {
            let keys: std::collections::BTreeSet<_> = want.keys().chain(got.keys()).collect();
            for key in keys {
                let (a, b) = (want.get(key), got.get(key));
                assert_eq!(
                    a, b,
                    "{strategy:?}, frame {k}: face {} lit {:b}: from scratch {:?}, pipeline {:?}",
                    key.0, key.1, a, b
                );
            }
        }
        // the assembled batch has every face's fragments, in face order;
        // the fast strategy's are maximal regions, as from scratch
        let b = d.fragments(&frame);
        if strategy == Strategy::Fast {
            let count = |x: &Batch| {
                let mut m: BTreeMap<u32, usize> = BTreeMap::new();
                for f in x.fragments() {
                    *m.entry(f.face()).or_default() += 1;
                }
                m
            };
            assert_eq!(count(&b), count(&scratch), "frame {k}: fragments per face");
        }
        assert_eq!(
            b.len(),
            frame.stats.total_drawn,
            "total_drawn counts the frame"
        );
        let faces: Vec<u32> = b.fragments().map(|f| f.face()).collect();
        assert!(faces.windows(2).all(|w| w[0] <= w[1]), "face order");
        related.push(frame.stats);
    }
    related
}

/// A tetrahedron with its corner at `at`, edges `s` long along the axes.
pub(crate) fn tetra(at: DVec3, s: f64) -> Vec<Vec<DVec3>> {
    let v = [
        at,
        at + DVec3::new(s, 0.0, 0.0),
        at + DVec3::new(0.0, s, 0.0),
        at + DVec3::new(0.0, 0.0, s),
    ];
    vec![
        vec![v[0], v[2], v[1]],
        vec![v[0], v[1], v[3]],
        vec![v[0], v[3], v[2]],
        vec![v[1], v[2], v[3]],
    ]
}

/// The ground of the random scenes: the square `[-6, 6]²` at height 0.
pub(crate) fn ground() -> Vec<DVec3> {
    vec![
        DVec3::new(-6.0, -6.0, 0.0),
        DVec3::new(6.0, -6.0, 0.0),
        DVec3::new(6.0, 6.0, 0.0),
        DVec3::new(-6.0, 6.0, 0.0),
    ]
}

/// Two tetrahedra touching along `ab`, their faces through `ab` merged
/// into two quads that cross along it (the certificate's counterexample),
/// scaled by `s` and moved to `at`.
pub(crate) fn crossing(at: DVec3, s: f64) -> Vec<Vec<DVec3>> {
    let p = |x: f64, y: f64, z: f64| at + DVec3::new(x, y, z) * s;
    let (a, b) = (p(0.0, 0.0, 0.0), p(0.0, 0.0, 6.0));
    let g = [
        p(-2.0, -1.0, 3.0),
        p(-2.0, 1.0, 3.0),
        p(4.0, -2.0, 3.0),
        p(4.0, 2.0, 3.0),
    ];
    vec![
        vec![a, g[1], g[0]],
        vec![b, g[0], g[1]],
        vec![a, g[2], b, g[1]],
        vec![a, g[3], g[2]],
        vec![b, g[2], g[3]],
        vec![a, g[0], b, g[3]],
    ]
}
