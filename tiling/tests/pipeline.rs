//! The real-time pipeline against the answer from scratch: every frame,
//! with either strategy, gives every face exactly the lit area per set of
//! flags that `svbsp::shadow_fragments` gives on the frame's whole scene
//! (static faces plus the moved object, snapped the same way), compared
//! as exact rationals. Motions: the room's axis object spinning and
//! wandering through the chairs' shadows, standing on the floor, crossing
//! tile and cube-face boundaries, and up against the light; random scenes
//! with random lights and motions.

use std::collections::{BTreeMap, HashMap};
use std::str::FromStr;

use bsp_core::{Grid, Polygon};
use glam::{DMat4, DVec3};
use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::Zero;
use proptest::prelude::*;
use svbsp::Vertex;
use svbsp::{Batch, Light, LightSpec, place_lights, shadow_fragments, shared_grid};
use tiling::{Dynamic, FragmentView, Motion, PipelineOptions, Strategy};

type Q = BigRational;

fn big(s: impl ToString) -> BigInt {
    BigInt::from_str(&s.to_string()).expect("an integer")
}

/// Exact homogeneous coordinates `(x, y, z, w)`, `w > 0`.
type H = [BigInt; 4];

fn of_vertex(v: &Vertex) -> H {
    match v {
        Vertex::Grid(g) => [big(g[0]), big(g[1]), big(g[2]), BigInt::from(1)],
        Vertex::Implicit(i) => (*i.coords()).map(big),
    }
}

/// Twice the signed area of a ring projected along `axis` (exact).
fn ring_area(ring: &[H], axis: usize) -> Q {
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
type Areas = BTreeMap<(u32, u64), Q>;

fn add(areas: &mut Areas, face: u32, lit: u64, rings: &[Vec<H>], axis: usize) {
    let mut s = Q::zero();
    for r in rings {
        s += ring_area(r, axis);
    }
    *areas.entry((face, lit)).or_insert_with(Q::zero) += s;
}

fn batch_areas(b: &Batch) -> Areas {
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

fn frame_areas(d: &Dynamic, frame: &tiling::Frame) -> Areas {
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
fn nonzero(a: Areas) -> Areas {
    a.into_iter().filter(|(_, v)| !v.is_zero()).collect()
}

/// Runs `frames` of `motion` with `strategy` and checks each against the
/// computation from scratch. Returns the frames' figures.
fn check_motion(
    statics: &[Vec<DVec3>],
    moving: &[Vec<DVec3>],
    lights: &[LightSpec],
    motion: &Motion,
    frames: u32,
    strategy: Strategy,
    tiles: Option<u32>,
) -> Vec<tiling::FrameStats> {
    // one grid for every frame: the static scene, the lights and every
    // position the object takes
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

/// The number of static polygons the faces import to.
fn d_polygons(st: &[Vec<DVec3>]) -> usize {
    let grid = Grid::fit_points(st.iter().flatten()).unwrap();
    bsp_core::import_faces_par(&grid, st).unwrap().0.len()
}

fn room_parts() -> (Vec<Vec<DVec3>>, Vec<Vec<DVec3>>) {
    let room = shadow_scene::room();
    let axes = room.group_index("axes").unwrap();
    let (mut st, mut dy) = (Vec::new(), Vec::new());
    for (i, f) in room.faces.iter().enumerate() {
        let l = room.face_points(i);
        if f.group == axes {
            dy.push(l);
        } else {
            st.push(l);
        }
    }
    (st, dy)
}

const ROOM_LIGHT: DVec3 = DVec3::new(0.9, 0.3, 2.45);

#[test]
fn room_axis_spins_exactly_with_both_strategies() {
    let (st, dy) = room_parts();
    let spin = Motion {
        axis: DVec3::Z,
        degrees: 37.0,
        centre: DVec3::ZERO,
        step: DVec3::ZERO,
    };
    for s in [Strategy::Fast, Strategy::Paper] {
        let rel = check_motion(&st, &dy, &[LightSpec::Point(ROOM_LIGHT)], &spin, 4, s, None);
        assert!(
            rel.iter().all(|f| f.related > 0 && f.related < st.len()),
            "{rel:?}"
        );
    }
}

#[test]
fn room_axis_walks_through_the_chairs_shadows_and_up_to_the_light() {
    let (st, dy) = room_parts();
    // from the middle toward the chair at (-1.9, -0.2) and the corner
    // under the light, tumbling about a tilted axis; the last frames bring
    // the object's box around the light
    let walk = Motion {
        axis: DVec3::new(0.3, 1.0, 0.2),
        degrees: 23.0,
        centre: DVec3::new(0.0, 0.0, 0.5),
        step: DVec3::new(-0.45, -0.05, 0.0),
    };
    check_motion(
        &st,
        &dy,
        &[LightSpec::Point(ROOM_LIGHT)],
        &walk,
        5,
        Strategy::Fast,
        Some(8),
    );
    let up = Motion {
        axis: DVec3::Z,
        degrees: 15.0,
        centre: DVec3::ZERO,
        step: (ROOM_LIGHT - DVec3::new(0.0, 0.0, 0.7)) / 3.0,
    };
    let rel = check_motion(
        &st,
        &dy,
        &[
            LightSpec::Point(ROOM_LIGHT),
            LightSpec::Sun(DVec3::new(1.0, -1.5, 2.0)),
        ],
        &up,
        4,
        Strategy::Fast,
        Some(8),
    );
    // around the light every static polygon is related
    let all = d_polygons(&st);
    assert_eq!(rel.last().unwrap().related, all);
    check_motion(
        &st,
        &dy,
        &[LightSpec::Point(ROOM_LIGHT)],
        &up,
        4,
        Strategy::Paper,
        Some(8),
    );
}

#[test]
fn room_axis_stands_on_the_floor() {
    let (st, mut dy) = room_parts();
    // the pedestal's base at exactly z = 0: coplanar with the floor's top
    let base = dy
        .iter()
        .flatten()
        .map(|p| p.z)
        .fold(f64::INFINITY, f64::min);
    for l in &mut dy {
        for p in l {
            p.z -= base;
        }
    }
    let slide = Motion {
        axis: DVec3::Z,
        degrees: 90.0,
        centre: DVec3::ZERO,
        step: DVec3::new(0.5, 0.25, 0.0),
    };
    for s in [Strategy::Fast, Strategy::Paper] {
        check_motion(
            &st,
            &dy,
            &[LightSpec::Point(ROOM_LIGHT)],
            &slide,
            3,
            s,
            Some(4),
        );
    }
}

use bsp_fixtures::cuboid;

fn tetra(at: DVec3, s: f64) -> Vec<Vec<DVec3>> {
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

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]

    /// A ground, random blocks and a tetrahedron moving among them, lit
    /// by a random point light (and sometimes a sun); random motions.
    #[test]
    fn random_scenes_and_motions_match_the_answer_from_scratch(
        blocks in prop::collection::vec(
            (prop::array::uniform3(-4.0f64..4.0), prop::array::uniform3(0.2f64..1.5)), 1..5),
        at in prop::array::uniform3(-2.0f64..2.0),
        light in prop::array::uniform3(-3.0f64..3.0),
        sun in any::<bool>(),
        axis in prop::array::uniform3(-1.0f64..1.0),
        degrees in -90.0f64..90.0,
        step in prop::array::uniform3(-0.8f64..0.8),
        paper in any::<bool>(),
        tiles in prop::sample::select(vec![None, Some(1u32), Some(3), Some(17)]),
    ) {
        let mut st = vec![vec![
            DVec3::new(-6.0, -6.0, 0.0),
            DVec3::new(6.0, -6.0, 0.0),
            DVec3::new(6.0, 6.0, 0.0),
            DVec3::new(-6.0, 6.0, 0.0),
        ]];
        for (p, s) in &blocks {
            let lo = DVec3::new(p[0], p[1], p[2].abs() * 0.5);
            st.extend(cuboid(lo, lo + DVec3::from_array(*s)));
        }
        let dy = tetra(DVec3::new(at[0], at[1], at[2].abs() + 0.3), 0.7);
        let mut lights = vec![LightSpec::Point(DVec3::new(light[0], light[1], light[2].abs() + 4.0))];
        if sun {
            lights.push(LightSpec::Sun(DVec3::new(0.4, -0.3, 1.0)));
        }
        let motion = Motion {
            axis: DVec3::from_array(axis),
            degrees,
            centre: DVec3::new(at[0], at[1], 1.0),
            step: DVec3::new(step[0], step[1], step[2] * 0.3),
        };
        let s = if paper { Strategy::Paper } else { Strategy::Fast };
        check_motion(&st, &dy, &lights, &motion, 3, s, tiles);
    }
}

#[test]
fn both_ways_of_shading_the_object_are_checked() {
    // a tall block between the light and a tetrahedron: many related
    // blockers (layered trees); the same with a small one (one tree)
    let ground = vec![vec![
        DVec3::new(-6.0, -6.0, 0.0),
        DVec3::new(6.0, -6.0, 0.0),
        DVec3::new(6.0, 6.0, 0.0),
        DVec3::new(-6.0, 6.0, 0.0),
    ]];
    let light = [LightSpec::Point(DVec3::new(0.0, 0.0, 8.0))];
    let slide = Motion {
        axis: DVec3::Z,
        degrees: 20.0,
        centre: DVec3::new(0.3, 0.2, 1.0),
        step: DVec3::new(0.2, 0.1, 0.0),
    };
    let mut many = ground.clone();
    for i in 0..6 {
        let z = 3.0 + i as f64 * 0.5;
        many.extend(cuboid(
            DVec3::new(-0.5, -0.5, z),
            DVec3::new(0.9, 0.8, z + 0.2),
        ));
    }
    let a = check_motion(
        &many,
        &tetra(DVec3::new(0.0, 0.0, 1.0), 0.5),
        &light,
        &slide,
        3,
        Strategy::Fast,
        None,
    );
    let mut one = ground;
    one.push(vec![
        DVec3::new(-3.0, -3.0, 5.0),
        DVec3::new(-2.0, -3.0, 5.0),
        DVec3::new(-2.0, -2.0, 5.0),
    ]);
    let b = check_motion(
        &one,
        &cuboid(DVec3::new(0.0, 0.0, 1.0), DVec3::new(1.0, 1.0, 2.0)),
        &light,
        &slide,
        3,
        Strategy::Fast,
        None,
    );
    assert!(a.iter().any(|f| f.layered), "no frame used layered trees");
    assert!(b.iter().any(|f| !f.layered), "no frame used one tree");
}

#[test]
fn frames_do_not_depend_on_what_came_before() {
    let (st, dy) = room_parts();
    let grid = shared_grid(
        &st.iter().chain(&dy).flatten().copied().collect::<Vec<_>>(),
        &[LightSpec::Point(ROOM_LIGHT)],
    )
    .unwrap();
    let light = place_lights(&grid, &[LightSpec::Point(ROOM_LIGHT)]).unwrap()[0].light;
    let d = Dynamic::new(&st, &dy, grid, &[light], PipelineOptions::default()).unwrap();
    let m = Motion {
        axis: DVec3::Z,
        degrees: 10.0,
        centre: DVec3::ZERO,
        step: DVec3::ZERO,
    };
    let direct = d.frame(&m.matrix(7)).unwrap();
    for k in 0..7 {
        d.frame(&m.matrix(k)).unwrap();
    }
    let after = d.frame(&m.matrix(7)).unwrap();
    let key = |f: &tiling::Frame| {
        let b = d.fragments(f);
        b.fragments()
            .map(|x| (x.face(), x.lit_mask(), x.outer().len()))
            .collect::<Vec<_>>()
    };
    assert_eq!(key(&direct), key(&after));
    // and a frame-0 motion is the object as given
    let still = d.frame(&DMat4::IDENTITY).unwrap();
    let mut counts: HashMap<u32, usize> = HashMap::new();
    for p in &still.moved {
        *counts.entry(p.tag()).or_default() += 1;
    }
    assert_eq!(counts.len(), dy.len());
}

#[test]
fn faces_turned_away_are_left_out_only_where_that_is_exact() {
    // the object's faces turned away from the light are left out of its
    // shadow tree when its snapped surface is certified to bound solids
    // and the light is outside them; every other case keeps them, and
    // each frame must still match the computation from scratch
    let ground = vec![vec![
        DVec3::new(-6.0, -6.0, 0.0),
        DVec3::new(6.0, -6.0, 0.0),
        DVec3::new(6.0, 6.0, 0.0),
        DVec3::new(-6.0, 6.0, 0.0),
    ]];
    let light = [LightSpec::Point(DVec3::new(0.2, 0.1, 8.0))];
    let turn = Motion {
        axis: DVec3::new(0.3, 1.0, 0.2),
        degrees: 25.0,
        centre: DVec3::new(0.5, 0.5, 2.0),
        step: DVec3::new(0.1, 0.05, 0.02),
    };
    let culled = |dy: &[Vec<DVec3>], lights: &[LightSpec]| -> Vec<usize> {
        check_motion(&ground, dy, lights, &turn, 3, Strategy::Fast, None)
            .iter()
            .map(|f| f.culled)
            .collect()
    };
    let cube = cuboid(DVec3::new(0.0, 0.0, 1.5), DVec3::new(1.0, 1.0, 2.5));
    // a closed outward box: left out, for the point light and a sun
    assert_eq!(culled(&cube, &light), vec![1; 3]);
    let both = [light[0], LightSpec::Sun(DVec3::new(0.3, -0.2, 1.0))];
    assert_eq!(culled(&cube, &both), vec![2; 3]);
    // turned inside out: its bottom faces the light and is shadowed by
    // its top, which faces away (leaving the top out would light it)
    let inside_out: Vec<Vec<DVec3>> = cube
        .iter()
        .map(|f| f.iter().rev().copied().collect())
        .collect();
    assert_eq!(culled(&inside_out, &light), vec![0; 3]);
    // two boxes through each other, and a box with its top missing
    let mut crossing = cube.clone();
    crossing.extend(cuboid(DVec3::new(0.5, 0.2, 1.2), DVec3::new(1.6, 0.8, 2.0)));
    assert_eq!(culled(&crossing, &light), vec![0; 3]);
    let open: Vec<Vec<DVec3>> = cube[..5].to_vec();
    assert_eq!(culled(&open, &light), vec![0; 3]);
    // the light inside the box: every face turns away from it, and the
    // box hides everything
    let around = cuboid(DVec3::new(-0.5, -0.5, 7.0), DVec3::new(1.0, 1.0, 9.0));
    let still = Motion {
        axis: DVec3::Z,
        degrees: 0.0,
        centre: DVec3::ZERO,
        step: DVec3::ZERO,
    };
    let f = check_motion(&ground, &around, &light, &still, 1, Strategy::Fast, None);
    assert_eq!(f[0].culled, 0);
}

/// The review's counterexample to the culling certificate: two tetrahedra
/// touching along `ab`, their faces through `ab` merged into two quads
/// that cross along it. Accepted, the object's faces turned away from the
/// light were left out and about 45% of the shadowed area of face
/// `(a, g2, b, g1)` came out lit. It must keep every face.
#[test]
fn regress_quads_crossing_along_a_diagonal_keep_every_face() {
    let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    let (a, b) = (p(0.0, 0.0, -3.0), p(0.0, 0.0, 3.0));
    let g = [
        p(-2.0, -1.0, 0.0),
        p(-2.0, 1.0, 0.0),
        p(4.0, -2.0, 0.0),
        p(4.0, 2.0, 0.0),
    ];
    let object = vec![
        vec![a, g[1], g[0]],
        vec![b, g[0], g[1]],
        vec![a, g[2], b, g[1]],
        vec![a, g[3], g[2]],
        vec![b, g[2], g[3]],
        vec![a, g[0], b, g[3]],
    ];
    let wall = vec![vec![
        p(20.0, -30.0, -30.0),
        p(20.0, -30.0, 30.0),
        p(20.0, 30.0, 30.0),
        p(20.0, 30.0, -30.0),
    ]];
    let light = [LightSpec::Point(p(-40.0, 1.0, 1.0))];
    let still = Motion {
        axis: DVec3::Z,
        degrees: 0.0,
        centre: DVec3::ZERO,
        step: DVec3::ZERO,
    };
    let f = check_motion(&wall, &object, &light, &still, 1, Strategy::Fast, None);
    assert_eq!(f[0].culled, 0);
}
