//! What a point sees of an area light (`AreaLight::view`), against the
//! exact ray-casting oracle: the light sampled at a lattice of grid points,
//! each a point light, and the point's verdict for each. A point that sees
//! all of the light must be lit by every sample, one that sees none must
//! be shadowed from every sample (both but for samples whose segment only
//! grazes an occluder, which the oracle calls degenerate), and the share
//! of the irradiance that arrives must match the samples' weighted share.

use bsp_core::{Plane, Polygon, Side};
use bsp_fixtures::Rng;
use glam::DVec3;
use svbsp::{AreaClass, AreaLight, Light, Occluder, Visibility};

use num_traits::{Signed, Zero};

use crate::harness::{hunt, rng};
use crate::meshes::mesh_loops;
use crate::oracle::{HPoint, Q, Scene, Verdict, twice_area_vector};

/// A number in `0..n`.
fn below(rng: &mut Rng, n: u64) -> i32 {
    (rng.next_u64() % n) as i32
}

/// Whether `fragments` tile the face of grid corners `corners` by area,
/// exactly: their area vectors (twice, exact rationals) add up to the
/// face's (each fragment turning as the face does, none with area the
/// face lacks).
fn tile_by_area<'a>(
    corners: &[[i32; 3]],
    fragments: impl IntoIterator<Item = &'a Polygon>,
) -> bool {
    let face: Vec<HPoint> = corners
        .iter()
        .map(|c| HPoint::grid(c.map(i64::from)))
        .collect();
    let mut sum: [Q; 3] = std::array::from_fn(|_| Q::zero());
    for f in fragments {
        let a = twice_area_vector(&exact_corners(f));
        for k in 0..3 {
            sum[k] += &a[k];
        }
    }
    sum == twice_area_vector(&face)
}

/// The corners of a polygon with exact corners, as exact points.
fn exact_corners(p: &Polygon) -> Vec<HPoint> {
    (p.vertices().iter())
        .map(|v| HPoint::of_vertex(&svbsp::Vertex::from_point(v)))
        .collect()
}

/// Per class (`AreaClass as usize`), twice the fragments' area, exactly:
/// their area vectors summed (fragments of one face are parallel and turn
/// alike), measured by the largest component's size.
fn class_areas(fs: &[svbsp::AreaFragment]) -> [Q; 4] {
    class_areas_of(fs.iter().map(|f| (&f.polygon, f.class as usize)))
}

/// [`class_areas`] of polygons given with their classes.
fn class_areas_of<'a>(fs: impl IntoIterator<Item = (&'a Polygon, usize)>) -> [Q; 4] {
    let mut sums: [[Q; 3]; 4] = std::array::from_fn(|_| std::array::from_fn(|_| Q::zero()));
    for (polygon, class) in fs {
        let a = twice_area_vector(&exact_corners(polygon));
        for k in 0..3 {
            sums[class][k] += &a[k];
        }
    }
    sums.map(|v| v.iter().map(Signed::abs).max().expect("three components"))
}

/// A convex polygon's area, from its correctly rounded corners.
fn area_of(p: &Polygon) -> f64 {
    let v: Vec<DVec3> = p
        .vertices_f64()
        .iter()
        .map(|&c| DVec3::from_array(c))
        .collect();
    svbsp::polygon_area(&v)
}

/// A triangle of corners within 40 of a centre within 40 of the axis,
/// at a height from 20 to 75 (slightly tilted).
fn random_triangle(rng: &mut Rng) -> [[i32; 3]; 3] {
    let z = 24 + below(rng, 48);
    let c = [below(rng, 80) - 40, below(rng, 80) - 40];
    let mut corner = || {
        [
            c[0] + below(rng, 81) - 40,
            c[1] + below(rng, 81) - 40,
            z + below(rng, 9) - 4,
        ]
    };
    [corner(), corner(), corner()]
}

/// The light: a `side`-square at height `h`, its corner at `(x0, y0)`,
/// shining down.
fn square_light(x0: i32, y0: i32, side: i32, h: i32) -> [[i32; 3]; 4] {
    [
        [x0, y0, h],
        [x0, y0 + side, h],
        [x0 + side, y0 + side, h],
        [x0 + side, y0, h],
    ]
}

/// The faces as polygons, each tagged with its index.
fn polygons(faces: &[Vec<[i32; 3]>]) -> Vec<Polygon> {
    faces
        .iter()
        .enumerate()
        .map(|(i, f)| Polygon::from_grid_points(f, i as u32).unwrap())
        .collect()
}

/// Whether every verdict but the degenerate ones (segments that only
/// graze an occluder) is `want`.
fn all_are(verdicts: &[Verdict], want: Verdict) -> bool {
    verdicts
        .iter()
        .all(|v| *v == want || matches!(v, Verdict::Degenerate { .. }))
}

/// The samples' verdicts at `x` on the ground (face 0 of `faces`) and the
/// irradiance-weighted share of lit samples: the light's lattice points
/// with odd coordinates (the centres of a `2 × 2` tiling, so the
/// weighted share is a midpoint rule for the form factor).
fn sampled(faces: &[Vec<[i32; 3]>], light: &[[i32; 3]; 4], x: [i32; 3]) -> (Vec<Verdict>, f64) {
    let polys = polygons(faces);
    let scene = Scene::from_polygons(&polys);
    let (lo, hi) = (light[0], light[2]);
    let hx = HPoint::grid(x.map(i64::from));
    let xf = DVec3::from_array(x.map(f64::from));
    let (mut verdicts, mut lit, mut all) = (Vec::new(), 0.0, 0.0);
    for sx in (lo[0] + 1..hi[0]).step_by(2) {
        for sy in (lo[1] + 1..hi[1]).step_by(2) {
            let s = [sx, sy, lo[2]];
            let d = DVec3::from_array(s.map(f64::from)) - xf;
            // cosines at the ground (normal +z) and at the light (-z)
            let w = (d.z / d.length()).powi(2) / d.length_squared();
            let v = scene.verdict(&Light::Point(s), 0, &hx);
            let seen = match v {
                Verdict::Lit => true,
                Verdict::Shadowed => false,
                Verdict::Degenerate { lit } => lit,
            };
            all += w;
            lit += if seen { w } else { 0.0 };
            verdicts.push(v);
        }
    }
    (verdicts, lit / all)
}

/// `view` at `x` on the ground of `faces` (face 0), checked against the
/// samples; returns the visibility.
fn check(faces: &[Vec<[i32; 3]>], light: &[[i32; 3]; 4], x: [i32; 3]) -> Visibility {
    let area = AreaLight::new(light).unwrap();
    let occluders: Vec<Occluder> = faces.iter().map(|f| Occluder::new(f).unwrap()).collect();
    let ground = *occluders[0].plane();
    let view = area.view(x, Some(&ground), &occluders).unwrap();
    let (verdicts, share) = sampled(faces, light, x);
    match view.visibility {
        Visibility::All => assert!(
            all_are(&verdicts, Verdict::Lit),
            "{x:?} sees all of the light, yet a sample is shadowed"
        ),
        Visibility::None => assert!(
            all_are(&verdicts, Verdict::Shadowed),
            "{x:?} sees none of the light, yet a sample is lit"
        ),
        Visibility::Part => {}
    }
    let fraction = view
        .fraction(DVec3::from_array(x.map(f64::from)), DVec3::Z)
        .unwrap();
    // (a shadow edge across the light leaves the 16 × 16 samples up to
    // about 0.03 off; beyond that, the scene scaled by 8 gives 64 times
    // the samples, whose share must then agree within 0.005)
    if (fraction - share).abs() >= 0.03 {
        let fine = |p: [i32; 3]| p.map(|c| c * 8);
        let faces: Vec<Vec<[i32; 3]>> = faces
            .iter()
            .map(|f| f.iter().map(|&p| fine(p)).collect())
            .collect();
        let (_, finer) = sampled(&faces, &light.map(fine), fine(x));
        assert!(
            (fraction - finer).abs() < 0.005,
            "{x:?}: fraction {fraction}, the samples' share {share}, at 64 times the samples {finer}"
        );
    }
    view.visibility
}

fn ground(r: i32) -> Vec<[i32; 3]> {
    vec![[-r, -r, 0], [r, -r, 0], [r, r, 0], [-r, r, 0]]
}

/// A face is cut only where a class changes (#30): under a square light
/// and under a sun disc, a ground with one square roof over it is three
/// fragments, whatever convex pieces the cutting made: the lit one with
/// the penumbra as its hole, the penumbra with the umbra as its hole, and
/// the umbra. The roof is one lit fragment. Each fragment's rings (outer
/// counter-clockwise, holes clockwise) hold exactly its pieces' area.
#[test]
fn a_face_is_cut_only_where_a_class_changes() {
    let roof = [[-20, -20, 40], [20, -20, 40], [20, 20, 40], [-20, 20, 40]];
    let faces = [
        Occluder::new(&ground(200)).unwrap(),
        Occluder::new(&roof).unwrap(),
    ];
    let lights = [
        AreaLight::new(&square_light(-10, -10, 20, 100)).unwrap(),
        AreaLight::sun_disc(DVec3::new(0.1, 0.2, 1.0), 2f64.to_radians()).unwrap(),
    ];
    for light in lights {
        let all = svbsp::soft_shadows(std::slice::from_ref(&light), &faces).unwrap();
        let holes = |class| -> Vec<usize> {
            (all[0].iter().filter(|f| f.class(0) == class))
                .map(|f| f.rings.len() - 1)
                .collect()
        };
        assert_eq!(holes(AreaClass::Lit), [1]);
        assert_eq!(holes(AreaClass::Penumbra), [1]);
        assert_eq!(holes(AreaClass::Umbra), [0]);
        assert_eq!(all[0].len(), 3);
        assert!(all[0].iter().any(|f| f.pieces.len() > 1), "nothing merged");
        assert_eq!(all[1].len(), 1);
        assert_eq!(all[1][0].class(0), AreaClass::Lit);
        for f in all.iter().flatten() {
            let mut rings: [Q; 3] = std::array::from_fn(|_| Q::zero());
            for ring in &f.rings {
                let exact: Vec<HPoint> = (ring.iter())
                    .map(|v| HPoint::of_vertex(&svbsp::Vertex::from_point(v)))
                    .collect();
                let a = twice_area_vector(&exact);
                (0..3).for_each(|k| rings[k] += &a[k]);
            }
            let mut pieces: [Q; 3] = std::array::from_fn(|_| Q::zero());
            for p in &f.pieces {
                let a = twice_area_vector(&exact_corners(&p.polygon));
                (0..3).for_each(|k| pieces[k] += &a[k]);
            }
            assert_eq!(rings, pieces);
        }
    }
}

/// A square occluder half-way under a square light: seen from below its
/// centre it hides the middle quarter; two occluders whose shadows only
/// together cover the light (each alone leaves some of it) make umbra.
#[test]
fn known_answers() {
    let light = square_light(0, 0, 40, 80);
    let small = vec![[15, 15, 40], [25, 15, 40], [25, 25, 40], [15, 25, 40]];
    assert_eq!(
        check(&[ground(200), small.clone()], &light, [20, 20, 0]),
        Visibility::Part
    );
    // the quarter, exactly: 1200 of 1600 seen
    let area = AreaLight::new(&light).unwrap();
    let view = area
        .view([20, 20, 0], None, &[Occluder::new(&small).unwrap()])
        .unwrap();
    let seen: f64 = view.seen.iter().map(area_of).sum();
    assert_eq!(seen, 1200.0);
    // two halves at different heights, each hiding half of the light
    let left = vec![[0, -20, 40], [10, -20, 40], [10, 60, 40], [0, 60, 40]];
    let right = vec![[10, -40, 60], [40, -40, 60], [40, 80, 60], [10, 80, 60]];
    let x = [10, 20, 0];
    assert_eq!(
        check(&[ground(200), left.clone()], &light, x),
        Visibility::Part
    );
    assert_eq!(
        check(&[ground(200), right.clone()], &light, x),
        Visibility::Part
    );
    assert_eq!(
        check(&[ground(200), left, right], &light, x),
        Visibility::None
    );
    // no occluder: all of it; behind the light: none
    assert_eq!(check(&[ground(200)], &light, [20, 20, 0]), Visibility::All);
    assert_eq!(
        area.view([20, 20, 90], None, &[]).unwrap().visibility,
        Visibility::None
    );
}

/// Random triangles between a square light and the ground, random points
/// on the ground: every class and fraction against the samples.
#[test]
fn random_occluders_against_the_oracle() {
    let mut rng = rng(0x0a4e_a116);
    let light = square_light(-16, -16, 32, 96);
    let mut seen = [0usize; 3];
    for _ in 0..24 {
        let mut faces = vec![ground(400)];
        for _ in 0..1 + below(&mut rng, 3) {
            let t = random_triangle(&mut rng);
            if Occluder::new(&t).is_ok() {
                faces.push(t.to_vec());
            }
        }
        for _ in 0..6 {
            let x = [below(&mut rng, 120) - 60, below(&mut rng, 120) - 60, 0];
            seen[match check(&faces, &light, x) {
                Visibility::All => 0,
                Visibility::Part => 1,
                Visibility::None => 2,
            }] += 1;
        }
    }
    // every class was met
    assert!(hunt().is_some() || seen.iter().all(|&n| n > 0), "{seen:?}");
}

/// Corners that make no light are refused, naming why.
#[test]
fn bad_lights_are_refused() {
    let msg = |c: &[[i32; 3]]| AreaLight::new(c).unwrap_err().to_string();
    assert!(msg(&[[0, 0, 0], [1, 0, 0]]).contains("three corners"));
    assert!(msg(&[[0, 0, 0], [1, 0, 0], [2, 0, 0]]).contains("zero area"));
    assert!(msg(&[[0, 0, 0], [2, 0, 0], [2, 2, 1], [0, 2, 0]]).contains("not in one plane"));
    let bow = msg(&[[0, 0, 0], [4, 0, 0], [1, 1, 0], [0, 4, 0]]);
    assert!(bow.contains("not convex"), "{bow}");
    // a bow tie whose halves cancel has no area, but its corners are not
    // on one line: it crosses itself
    let tie = msg(&[[0, 0, 0], [0, 2, 0], [2, 0, 0], [2, 2, 0]]);
    assert!(
        tie.contains("crosses itself") && !tie.contains("collinear"),
        "{tie}"
    );
}

/// Checks a fragment's class against what the exact view says at grid
/// point `x` strictly inside it, on a face of plane `plane` (undecided:
/// anything but all of the light).
fn assert_agrees(
    light: &AreaLight,
    (x, plane): ([i32; 3], &Plane),
    faces: &[Occluder],
    class: AreaClass,
) {
    let seen = light.view(x, Some(plane), faces).unwrap().visibility;
    let ok = match class {
        AreaClass::Lit => seen == Visibility::All,
        AreaClass::Umbra => seen == Visibility::None,
        AreaClass::Penumbra => seen == Visibility::Part,
        AreaClass::Undecided => seen != Visibility::All,
    };
    assert!(ok, "{x:?}: class {class:?}, the view says {seen:?}");
}

/// A random grid point of the ground (`z = 0`, `|x|, |y| < r`) and the
/// fragment of `fragments` it lies strictly inside, if any.
fn on_the_ground<'a>(
    rng: &mut Rng,
    r: i32,
    fragments: &'a [svbsp::SoftFragment],
) -> Option<([i32; 3], &'a svbsp::SoftFragment)> {
    let w = 2 * r as u64;
    let x = [below(rng, w) - r, below(rng, w) - r, 0];
    Some((x, soft_at(fragments, x)?))
}

/// The fragment of `fragments` one of whose convex pieces holds grid
/// point `x` strictly inside.
fn soft_at(fragments: &[svbsp::SoftFragment], x: [i32; 3]) -> Option<&svbsp::SoftFragment> {
    (fragments.iter()).find(|f| f.pieces.iter().any(|p| strictly_inside(&p.polygon, x)))
}

/// A soft fragment's ring corners, pieces' corners and classes.
type SoftKey = (Vec<[f64; 3]>, Vec<Vec<[f64; 3]>>, u64, u64, u64);

/// [`SoftKey`]s of soft fragments, for comparing runs.
fn soft_keys(fs: &[svbsp::SoftFragment]) -> Vec<SoftKey> {
    fs.iter()
        .map(|f| {
            let ring = (f.rings.iter().flatten()).map(|p| p.to_f64()).collect();
            let pieces = (f.pieces.iter())
                .map(|p| p.polygon.vertices_f64())
                .collect();
            (ring, pieces, f.lit, f.umbra, f.undecided)
        })
        .collect()
}

/// The convex pieces of soft fragments, with their fragments.
fn soft_pieces(
    fragments: &[svbsp::SoftFragment],
) -> impl Iterator<Item = (&svbsp::SoftPiece, &svbsp::SoftFragment)> {
    (fragments.iter()).flat_map(|f| f.pieces.iter().map(move |p| (p, f)))
}

/// `f` on a pool of its own of `threads` threads.
fn on_threads<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

/// Whether the grid point `x` lies strictly inside the convex `piece`.
fn strictly_inside(piece: &Polygon, x: [i32; 3]) -> bool {
    piece
        .edge_planes()
        .iter()
        .all(|h| h.classify_grid(x) == bsp_core::Side::Back)
}

/// Random occluders between a square light and the ground and a wall
/// (sometimes a square split into two triangles, whose umbra neither
/// makes alone, sometimes an upright fin whose plane cuts the light): each receiver cut into classes, and at grid points
/// strictly inside each piece the exact view agrees (lit: sees all;
/// umbra: none; penumbra: part; undecided: part or none), and the pieces
/// tile the receiver.
#[test]
fn classified_faces_agree_with_the_view() {
    let mut rng = rng(0x5eed_a4ea);
    let light = AreaLight::new(&square_light(-16, -16, 32, 96)).unwrap();
    let wall = [[60, -120, 0], [60, -120, 120], [60, 120, 120], [60, 120, 0]];
    let mut met = std::collections::HashMap::new();
    for round in 0..24 {
        let mut faces = vec![
            Occluder::new(&ground(120)).unwrap(),
            Occluder::new(&wall).unwrap(),
        ];
        for _ in 0..1 + below(&mut rng, 3) {
            if let Ok(o) = Occluder::new(&random_triangle(&mut rng)) {
                faces.push(o);
            }
        }
        if round % 3 == 1 {
            // a fin whose plane cuts the light in two
            let (x, y) = (below(&mut rng, 31) - 15, below(&mut rng, 60) - 30);
            let fin = [[x, y, 30], [x, y + 50, 30], [x, y + 30, 70]];
            faces.push(Occluder::new(&fin).unwrap());
        }
        if round % 3 == 2 {
            // a fin in the plane of two light corners (x = -16): it casts
            // no shadow volume from them, but hides light near them
            let (y, z) = (below(&mut rng, 60) - 40, 20 + below(&mut rng, 40));
            let fin = [[-16, y, z], [-16, y + 40, z], [-16, y + 20, z + 30]];
            faces.push(Occluder::new(&fin).unwrap());
        }
        if round % 3 == 0 {
            let (x, y, z) = (below(&mut rng, 40) - 40, below(&mut rng, 40) - 20, 48);
            let q = [
                [x, y, z],
                [x + 40, y, z],
                [x + 40, y + 40, z],
                [x, y + 40, z],
            ];
            faces.push(Occluder::new(&[q[0], q[1], q[2]]).unwrap());
            faces.push(Occluder::new(&[q[0], q[2], q[3]]).unwrap());
        }
        // one face against every occluder's volumes from each corner, and
        // every face with the corners' point-light shadow volumes
        let together = light.classify_faces(&faces);
        let ways = [(0, false), (1, false), (0, true), (1, true)];
        for (r, fragments) in ways.map(|(r, all)| match all {
            true => (r, together[r].clone()),
            false => (r, light.classify_face(&faces[r], &faces)),
        }) {
            let polygons = fragments.iter().map(|f| &f.polygon);
            assert!(tile_by_area(faces[r].corners(), polygons), "face {r}");
            let plane = *faces[r].plane();
            for _ in 0..96 {
                let (u, v) = (below(&mut rng, 240) - 120, below(&mut rng, 120));
                let x = if r == 0 { [u, v - 60, 0] } else { [60, u, v] };
                let Some(f) = fragments.iter().find(|f| strictly_inside(&f.polygon, x)) else {
                    continue;
                };
                // in an occluder's plane, it is edge-on: it hides no area
                // from the point, but some from points beside it
                let edge_on = |o: &Occluder| o.plane().classify_grid(x) == bsp_core::Side::On;
                if faces.iter().enumerate().any(|(i, o)| i != r && edge_on(o)) {
                    continue;
                }
                assert_agrees(&light, (x, &plane), &faces, f.class);
                *met.entry(f.class).or_insert(0) += 1;
            }
        }
    }
    for class in [
        AreaClass::Lit,
        AreaClass::Penumbra,
        AreaClass::Umbra,
        AreaClass::Undecided,
    ] {
        assert!(
            hunt().is_some() || met.contains_key(&class),
            "{class:?} never met: {met:?}"
        );
    }
}

/// A face just above an occluder, under the light, is lit: it lies on the
/// occluder's side of every separating plane (they cross between light
/// and occluder), and only the occluder's own plane bounds its penumbra
/// volume there.
#[test]
fn a_face_between_the_light_and_an_occluder_is_lit() {
    let light = AreaLight::new(&square_light(0, 0, 40, 80)).unwrap();
    let below = Occluder::new(&[[0, 0, 40], [40, 0, 40], [40, 40, 40], [0, 40, 40]]).unwrap();
    let above = Occluder::new(&[[10, 10, 44], [30, 10, 44], [30, 30, 44], [10, 30, 44]]).unwrap();
    let faces = [above.clone(), below];
    let fragments = light.classify_face(&above, &faces);
    assert!(fragments.iter().all(|f| f.class == AreaClass::Lit));
    assert_eq!(
        light
            .view([20, 20, 44], Some(above.plane()), &faces)
            .unwrap()
            .visibility,
        Visibility::All
    );
}

/// The faces snapped to `grid` as occluders (those that stay convex
/// polygons with area).
fn snapped(faces: &[Vec<DVec3>], grid: &bsp_core::Grid) -> Vec<Occluder> {
    faces
        .iter()
        .filter_map(|f| {
            let l: Vec<[i32; 3]> = f.iter().map(|&v| grid.snap(v).unwrap()).collect();
            Occluder::new(&l).ok()
        })
        .collect()
}

/// Chin & Feiner's 258-polygon scene under a square light: every face's
/// fragments tile it, and the result is the same on one thread as on
/// several.
#[test]
fn classified_scenes_tile_their_faces_on_any_thread_count() {
    let spec = bsp_fixtures::scenes::scene("cf258");
    let world = bsp_fixtures::scenes::lights(&spec, 1);
    let bsp_fixtures::scenes::WorldLight::Point(at) = world[0] else {
        panic!("the key light is a point light");
    };
    let mut pts: Vec<DVec3> = spec.faces.iter().flatten().copied().collect();
    pts.push(at);
    let grid = bsp_core::Grid::fit_points(&pts).unwrap();
    let corner = |dx: f64, dy: f64| grid.snap(at + DVec3::new(dx, dy, 0.0)).unwrap();
    let light = AreaLight::new(&[
        corner(-1.0, -1.0),
        corner(-1.0, 1.0),
        corner(1.0, 1.0),
        corner(1.0, -1.0),
    ])
    .unwrap();
    let faces = snapped(&spec.faces, &grid);
    assert!(faces.len() > 200);
    let run = |threads: usize| on_threads(threads, || light.classify_faces(&faces));
    let key = |all: &Vec<Vec<svbsp::AreaFragment>>| -> Vec<(Vec<[f64; 3]>, AreaClass)> {
        all.iter()
            .flatten()
            .map(|f| (f.polygon.vertices_f64(), f.class))
            .collect()
    };
    let one = run(1);
    assert_eq!(key(&one), key(&run(3)));
    let mut classes = std::collections::HashSet::new();
    for (face, fragments) in faces.iter().zip(&one) {
        assert!(tile_by_area(
            face.corners(),
            fragments.iter().map(|f| &f.polygon)
        ));
        classes.extend(fragments.iter().map(|f| f.class));
    }
    assert!(classes.contains(&AreaClass::Penumbra) && classes.contains(&AreaClass::Umbra));
}

/// Per face, the area classified lit by `light` in the area engine, and
/// the lit area of the same faces under `point` by the partitioned
/// shadow volumes.
fn lit_areas(
    light: &AreaLight,
    point: Light,
    faces: &[Vec<[i32; 3]>],
) -> (Vec<[Q; 3]>, Vec<[Q; 3]>) {
    let occluders: Vec<Occluder> = faces.iter().map(|f| Occluder::new(f).unwrap()).collect();
    let polys = polygons(faces);
    let zero = || -> [Q; 3] { std::array::from_fn(|_| Q::zero()) };
    let add = |sum: &mut [Q; 3], corners: Vec<HPoint>| {
        let a = twice_area_vector(&corners);
        for k in 0..3 {
            sum[k] += &a[k];
        }
    };
    let area = light
        .classify_faces(&occluders)
        .iter()
        .map(|fs| {
            assert!(
                fs.iter()
                    .all(|f| matches!(f.class, AreaClass::Lit | AreaClass::Umbra)),
                "a light of no extent makes no penumbra"
            );
            let mut sum = zero();
            for f in fs.iter().filter(|f| f.class == AreaClass::Lit) {
                let corners = (f.polygon.vertices().iter())
                    .map(|v| HPoint::of_vertex(&svbsp::Vertex::from_point(v)))
                    .collect();
                add(&mut sum, corners);
            }
            sum
        })
        .collect();
    // the lit parts the point light's tree finds of every face, exactly
    let (_, parts) = svbsp::ShadowVolumes::lit_parts(point, &polys).unwrap();
    let mut psv: Vec<[Q; 3]> = (0..faces.len()).map(|_| zero()).collect();
    for (i, corners) in parts {
        add(&mut psv[i], corners.iter().map(HPoint::of_vertex).collect());
    }
    (area, psv)
}

/// A light shrunk to a point is the point light, and a sun disc of radius
/// 0 the sun: the same lit area on every face as the partitioned shadow
/// volumes give (random triangles over a ground and a wall).
#[test]
fn lights_of_no_extent_equal_the_point_light_and_the_sun() {
    let mut rng = rng(0x11_6475);
    let wall = vec![[60, -120, 0], [60, -120, 120], [60, 120, 120], [60, 120, 0]];
    for round in 0..8 {
        let mut faces = vec![ground(120), wall.clone()];
        for _ in 0..4 {
            let t = random_triangle(&mut rng);
            if Occluder::new(&t).is_ok() {
                faces.push(t.to_vec());
            }
        }
        let at = [below(&mut rng, 40) - 20, below(&mut rng, 40) - 20, 90];
        let d = glam::DVec3::new(
            f64::from(below(&mut rng, 9)) - 4.0,
            f64::from(below(&mut rng, 9)) - 4.0,
            5.0,
        );
        let q = svbsp::quantize_direction(d).unwrap();
        let cases = [
            (AreaLight::point(at).unwrap(), Light::Point(at)),
            (AreaLight::sun_disc(d, 0.0).unwrap(), Light::Directional(q)),
        ];
        for (light, point) in cases {
            let (area, psv) = lit_areas(&light, point, &faces);
            for (i, (a, p)) in area.iter().zip(&psv).enumerate() {
                assert_eq!(
                    a, p,
                    "round {round}, face {i}: lit by the limit, and by {point:?}"
                );
            }
            assert!(area.iter().any(|a| a.iter().any(|c| !c.is_zero())));
        }
    }
}

/// A sun disc of 3° over random triangles: at grid points strictly inside
/// each fragment, directions sampled over the true disc (its rim and a
/// lattice inside) are all unblocked from a lit point, all blocked from an
/// umbra point, and both meet from penumbra points somewhere in the run.
#[test]
fn sun_disc_fragments_agree_with_sampled_directions() {
    let mut rng = rng(0x5_d15c);
    let d = glam::DVec3::new(0.3, -0.2, 1.0).normalize();
    let radius = 3f64.to_radians();
    let sun = AreaLight::sun_disc(d, radius).unwrap();
    let u = d.any_orthonormal_vector();
    let v = d.cross(u);
    let mut samples = Vec::new();
    for k in 0..32 {
        let a = std::f64::consts::TAU * f64::from(k) / 32.0;
        samples.push(d + (u * a.cos() + v * a.sin()) * radius.tan());
    }
    for i in -6..=6 {
        for j in -6..=6 {
            let (s, t) = (f64::from(i) / 6.0, f64::from(j) / 6.0);
            if s * s + t * t <= 1.0 {
                samples.push(d + (u * s + v * t) * radius.tan());
            }
        }
    }
    let samples: Vec<Light> = samples
        .iter()
        .map(|&s| Light::Directional(svbsp::quantize_direction(s).unwrap()))
        .collect();
    let mut met = std::collections::HashMap::new();
    let mut shares = 0;
    for _ in 0..6 {
        let mut faces = vec![ground(120)];
        for _ in 0..3 {
            let t = random_triangle(&mut rng);
            if Occluder::new(&t).is_ok() {
                faces.push(t.to_vec());
            }
        }
        let occluders: Vec<Occluder> = faces.iter().map(|f| Occluder::new(f).unwrap()).collect();
        let polys = polygons(&faces);
        let scene = Scene::from_polygons(&polys);
        let lattice: Vec<Light> = samples[32..].to_vec();
        shares += check_disc_shares(&sun, &occluders, &scene, &lattice);
        let fragments = sun.classify_face(&occluders[0], &occluders);
        for _ in 0..400 {
            let x = [below(&mut rng, 240) - 120, below(&mut rng, 240) - 120, 0];
            let Some(f) = fragments.iter().find(|f| strictly_inside(&f.polygon, x)) else {
                continue;
            };
            assert_disc_agrees(&scene, &samples, x, f.class, "");
            *met.entry(f.class).or_insert(0) += 1;
        }
    }
    for class in [AreaClass::Lit, AreaClass::Penumbra, AreaClass::Umbra] {
        assert!(
            hunt().is_some() || met.contains_key(&class),
            "{class:?} never met: {met:?}"
        );
    }
    assert!(
        hunt().is_some() || shares > 10,
        "{shares} penumbra shares checked"
    );
}

/// A sun disc's class at grid point `x` of face 0 of `scene` against the
/// ray oracle's verdicts for `directions` over the true disc: lit where
/// none is blocked, umbra where every one is (penumbra and undecided may
/// be either). `what` names the scene in the message.
fn assert_disc_agrees(
    scene: &Scene,
    directions: &[Light],
    x: [i32; 3],
    class: AreaClass,
    what: &str,
) {
    let hx = HPoint::grid(x.map(i64::from));
    let seen: Vec<Verdict> = directions
        .iter()
        .map(|s| scene.verdict(s, 0, &hx))
        .collect();
    match class {
        AreaClass::Lit => assert!(
            all_are(&seen, Verdict::Lit),
            "{what} {x:?} is lit, yet a direction of the disc is blocked"
        ),
        AreaClass::Umbra => assert!(
            all_are(&seen, Verdict::Shadowed),
            "{what} {x:?} is umbra, yet a direction of the disc is open"
        ),
        AreaClass::Penumbra | AreaClass::Undecided => {}
    }
}

/// The share of a sun disc a penumbra fragment sees, at the grid point
/// nearest its centroid, against the share of a lattice of directions over
/// the disc that reach that point (the share is the bounding octagon's, a
/// little wider than the disc: within 0.15).
fn check_disc_shares(
    sun: &AreaLight,
    occluders: &[Occluder],
    scene: &Scene,
    lattice: &[Light],
) -> usize {
    let fragments = &svbsp::soft_shadows(std::slice::from_ref(sun), occluders).unwrap()[0];
    let mut checked = 0;
    for (p, f) in soft_pieces(fragments).filter(|(_, f)| f.class(0) == AreaClass::Penumbra) {
        // a fragment's share is its largest piece's
        let whole = f.visible[0].as_ref().unwrap().centroid;
        assert!(
            f.pieces
                .iter()
                .any(|p| p.visible[0].as_ref().unwrap().centroid == whole)
        );
        let v = p.polygon.vertices_f64();
        let c = v
            .iter()
            .fold([0.0; 3], |s, p| [0, 1, 2].map(|k| s[k] + p[k]));
        let x = c.map(|s| (s / v.len() as f64).round() as i32);
        if !strictly_inside(&p.polygon, x) {
            continue;
        }
        let hx = HPoint::grid(x.map(i64::from));
        let open = lattice
            .iter()
            .filter(|s| !matches!(scene.verdict(s, 0, &hx), Verdict::Shadowed))
            .count();
        let want = open as f64 / lattice.len() as f64;
        let got = p.visible[0].as_ref().unwrap().centroid;
        assert!(
            (got - want).abs() < 0.15,
            "{x:?}: share {got}, the lattice's {want}"
        );
        checked += 1;
    }
    checked
}

/// A sun disc is checked: a zero direction or a radius out of range is an
/// error naming both.
#[test]
fn bad_sun_discs_are_errors() {
    let e = AreaLight::sun_disc(glam::DVec3::ZERO, 0.01).unwrap_err();
    assert!(e.to_string().contains("non-zero"), "{e}");
    let e = AreaLight::sun_disc(glam::DVec3::Z, 1.0).unwrap_err();
    assert!(e.to_string().contains("(given 57.29"), "{e}");
    assert!(AreaLight::sun_disc(glam::DVec3::Z, f64::NAN).is_err());
    assert!(AreaLight::point([1 << 27, 0, 0]).is_err());
    // at most 64 lights at once
    let many = vec![AreaLight::point([0, 0, 9]).unwrap(); 65];
    let e = svbsp::soft_shadows(&many, &[]).unwrap_err();
    assert_eq!(e, svbsp::LightError::TooMany(65));
}

/// Several lights at once (a square light, a sun disc, a point light):
/// at grid points strictly inside each fragment, the class of each light
/// is the class that light alone gives there; the fragments tile each
/// face; and the fragments are the same, face by face, when the faces
/// come in another order or on another thread count.
#[test]
fn soft_shadows_of_several_lights_agree_with_each_light_alone() {
    let mut rng = rng(0x50f7);
    let lights = [
        AreaLight::new(&square_light(-16, -16, 32, 96)).unwrap(),
        AreaLight::sun_disc(glam::DVec3::new(-0.4, 0.2, 1.0), 2f64.to_radians()).unwrap(),
        AreaLight::point([30, 10, 90]).unwrap(),
    ];
    let mut faces = vec![Occluder::new(&ground(120)).unwrap()];
    for _ in 0..5 {
        if let Ok(o) = Occluder::new(&random_triangle(&mut rng)) {
            faces.push(o);
        }
    }
    let all = svbsp::soft_shadows(&lights, &faces).unwrap();
    let alone: Vec<Vec<svbsp::AreaFragment>> = lights
        .iter()
        .map(|l| l.classify_face(&faces[0], &faces))
        .collect();
    let ground_fragments = &all[0];
    assert!(tile_by_area(
        faces[0].corners(),
        soft_pieces(ground_fragments).map(|(p, _)| &p.polygon)
    ));
    let mut checked = 0;
    let mut kinds = std::collections::HashSet::new();
    for _ in 0..2000 {
        let Some((x, f)) = on_the_ground(&mut rng, 120, ground_fragments) else {
            continue;
        };
        for (k, frags) in alone.iter().enumerate() {
            if let Some(a) = frags.iter().find(|a| strictly_inside(&a.polygon, x)) {
                assert_eq!(f.class(k), a.class, "{x:?}, light {k}");
                checked += 1;
            }
            kinds.insert((k, f.class(k)));
            let soft = matches!(f.class(k), AreaClass::Penumbra | AreaClass::Undecided);
            assert_eq!(f.visible[k].is_some(), k < 2 && soft, "light {k}");
        }
    }
    assert!(hunt().is_some() || checked > 3000, "{checked}");
    for k in 0..2 {
        for class in [AreaClass::Lit, AreaClass::Penumbra, AreaClass::Umbra] {
            let met = hunt().is_some() || kinds.contains(&(k, class));
            assert!(met, "light {k} never {class:?}");
        }
    }
    // another order of the faces, and one thread
    let mut order: Vec<usize> = (0..faces.len()).collect();
    order.reverse();
    order.swap(0, 2);
    let shuffled: Vec<Occluder> = order.iter().map(|&i| faces[i].clone()).collect();
    let one = on_threads(1, || svbsp::soft_shadows(&lights, &shuffled)).unwrap();
    for (s, &i) in order.iter().enumerate() {
        assert_eq!(soft_keys(&one[s]), soft_keys(&all[i]), "face {i}");
    }
}

/// The occluders a face meets are found through boxes of their penumbra
/// volumes (`classify_faces`, `soft_shadows`); every face of Chin &
/// Feiner's scene under a square light and under a sun disc gets the same
/// area of each class as when it meets every other face
/// (`classify_face`). The ground under the disc, whose check against every
/// face takes 30 s alone (ten times the rest), is
/// `the_ground_under_a_sun_disc_meets_only_its_near_occluders`, run with
/// `--ignored`.
#[test]
fn the_near_occluders_are_all_that_matter() {
    let (faces, lights) = cf258_under_area_lights();
    for (k, light) in lights.iter().enumerate() {
        let classes = near_against_every_occluder(light, &faces, |i| k == 0 || i != 0);
        assert!(classes.len() >= 3, "light {k}: {classes:?}");
    }
}

/// [`the_near_occluders_are_all_that_matter`] for the ground of Chin &
/// Feiner's scene under the sun disc.
#[test]
#[ignore = "30 s: the ground against every face under a 2° sun disc"]
fn the_ground_under_a_sun_disc_meets_only_its_near_occluders() {
    let (faces, lights) = cf258_under_area_lights();
    let classes = near_against_every_occluder(&lights[1], &faces, |i| i == 0);
    assert!(classes.len() >= 2, "{classes:?}");
}

/// Chin & Feiner's scene (258 faces), with a square light above its
/// middle and a sun disc of 2°.
fn cf258_under_area_lights() -> (Vec<Occluder>, [AreaLight; 2]) {
    let spec = bsp_fixtures::scenes::scene("cf258");
    let grid = bsp_core::Grid::fit_points(spec.faces.iter().flatten()).unwrap();
    let faces = snapped(&spec.faces, &grid);
    let (lo, hi) = faces.iter().flat_map(|f| f.corners()).fold(
        ([i32::MAX; 3], [i32::MIN; 3]),
        |(lo, hi), c| {
            (
                [0, 1, 2].map(|k| lo[k].min(c[k])),
                [0, 1, 2].map(|k| hi[k].max(c[k])),
            )
        },
    );
    let (cx, cy, top) = ((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, hi[2]);
    let side = (hi[0] - lo[0]) / 8;
    let lights = [
        AreaLight::new(&square_light(cx - side, cy - side, 2 * side, top + side)).unwrap(),
        AreaLight::sun_disc(glam::DVec3::new(0.3, -0.2, 1.0), 2f64.to_radians()).unwrap(),
    ];
    (faces, lights)
}

/// The faces `which` picks, each with the same area of each class from
/// its near occluders (`classify_faces`) as from every face
/// (`classify_face`); the classes met.
fn near_against_every_occluder(
    light: &AreaLight,
    faces: &[Occluder],
    which: impl Fn(usize) -> bool,
) -> std::collections::HashSet<AreaClass> {
    let fast = light.classify_faces(faces);
    let mut classes = std::collections::HashSet::new();
    for (i, face) in faces.iter().enumerate().filter(|(i, _)| which(*i)) {
        let (a, b) = (
            class_areas(&fast[i]),
            class_areas(&light.classify_face(face, faces)),
        );
        assert_eq!(a, b, "face {i}");
        classes.extend(fast[i].iter().map(|f| f.class));
    }
    classes
}

/// An occluder above a ceiling light that touches the light's plane with
/// one corner (beside the light) and has a light corner in its own plane
/// hides nothing from below: the separating planes of its penumbra volume
/// alone let a wedge of the ground in, which came out penumbra where
/// every point sees all of the light. With a tilted quad that hides the
/// light's other corners from a face, that face's fragments are the same
/// whether it meets its near occluders or every occluder (found by a
/// hunt of `crowded_scenes_classify_as_with_every_occluder`, seed 15,
/// reduced to these three faces).
#[test]
fn an_occluder_touching_the_lights_plane_from_behind_hides_nothing() {
    let light = AreaLight::new(&square_light(6, 5, 7, 12)).unwrap();
    let above = [[9, 18, 18], [10, 15, 12], [11, 17, 14]];
    let faces = [
        Occluder::new(&[[-40, -40, 0], [40, -40, 0], [40, 40, 0], [-40, 40, 0]]).unwrap(),
        Occluder::new(&above).unwrap(),
    ];
    // and a wall facing the light beside it, crossing the light's plane:
    // its part below that plane sees all of the light (the near lists let
    // the occluder meet this wall, and 92.5 of its 96 half-units came out
    // penumbra), the rest is behind the light
    let wall = [[8, 16, 0], [12, 16, 0], [12, 16, 14], [8, 16, 14]];
    let walled = [
        Occluder::new(&wall).unwrap(),
        Occluder::new(&above).unwrap(),
    ];
    let below = Occluder::new(&[[8, 16, 0], [12, 16, 0], [12, 16, 12], [8, 16, 12]]).unwrap();
    let mut want: [Q; 4] = std::array::from_fn(|_| Q::zero());
    want[AreaClass::Lit as usize] = Q::from_integer(96.into());
    want[AreaClass::Umbra as usize] = Q::from_integer(16.into());
    assert_eq!(class_areas(&light.classify_faces(&walled)[0]), want);
    assert_eq!(class_areas(&light.classify_face(&walled[0], &walled)), want);
    assert_eq!(
        class_areas(&light.classify_face(&below, &walled))[0],
        want[0]
    );
    for fragments in [
        light.classify_face(&faces[0], &faces),
        light.classify_faces(&faces).swap_remove(0),
    ] {
        let classes: Vec<AreaClass> = fragments.iter().map(|f| f.class).collect();
        assert!(classes.iter().all(|&c| c == AreaClass::Lit), "{classes:?}");
    }
    let faces = [
        Occluder::new(&[[9, 15, 8], [12, 12, 11], [9, 9, 10], [6, 12, 7]]).unwrap(),
        Occluder::new(&[[11, 2, 1], [11, 2, 3], [10, 21, 12]]).unwrap(),
        Occluder::new(&above).unwrap(),
    ];
    let fast = light.classify_faces(&faces);
    for (i, face) in faces.iter().enumerate() {
        let reference = light.classify_face(face, &faces);
        assert_eq!(class_areas(&fast[i]), class_areas(&reference), "face {i}");
    }
    assert!(fast[1].iter().any(|f| f.class == AreaClass::Undecided));
}

/// Random crowded scenes: small triangles and parallelograms in a box,
/// triangles on earlier faces' edges (reversed, as a mesh has them), in
/// their planes, repeated and flipped; lit by a square light above them,
/// one among them (faces above it turned away, faces crossing its plane)
/// and a sun disc. The near occluders classify every face with exactly
/// the area of each class it has when it meets every other face, as in
/// [`the_near_occluders_are_all_that_matter`], on the degenerate input
/// that scene lacks; and at lattice points of every third face (the
/// scenes are scaled by 8 for them) the exact view agrees with a polygon
/// light's classes. (`SVBSP_SEED` gives other scenes, for hunts.)
#[test]
fn crowded_scenes_classify_as_with_every_occluder() {
    use crate::scenes::{FaceGen, Transform, make_faces};
    let mut rng = rng(0x0c40_3d5e);
    let (mut classes, mut viewed) = (std::collections::HashSet::new(), 0);
    for _ in 0..2 {
        let pt = |rng: &mut Rng, lo: i32, hi: i32| {
            [0; 3].map(|_: i32| lo + below(rng, (hi - lo + 1) as u64))
        };
        let mut gens = Vec::new();
        for _ in 0..72 {
            let p = pt(&mut rng, 0, 20);
            let (a, b) = (pt(&mut rng, -3, 3), pt(&mut rng, -3, 3));
            let (i, e) = (
                below(&mut rng, 1 << 16) as usize,
                below(&mut rng, 4) as usize,
            );
            let c = [0; 3].map(|_| (below(&mut rng, 5) - 2, below(&mut rng, 5) - 2));
            let add = |p: [i32; 3], d: [i32; 3]| [0, 1, 2].map(|k| p[k] + d[k]);
            gens.push(match below(&mut rng, 10) {
                0..=2 => FaceGen::Triangle(p, add(p, a), add(p, b)),
                3 | 4 => FaceGen::Parallelogram(p, a, b),
                5 | 6 => FaceGen::SharedEdge(i, e, add(p, a)),
                7 => FaceGen::Coplanar(i, c),
                8 => FaceGen::Copy(i),
                _ => FaceGen::Flipped(i),
            });
        }
        // (scaled by 8, exactly: every relation kept, and lattice points
        // inside the faces for the view)
        let loops = make_faces(
            &gens,
            &Transform {
                scale: 8,
                offset: [0; 3],
            },
        );
        let faces: Vec<Occluder> = loops.iter().filter_map(|l| Occluder::new(l).ok()).collect();
        let squares = [square_light(32, 48, 64, 216), square_light(48, 40, 56, 96)];
        let lights = [
            AreaLight::new(&squares[0]).unwrap(),
            AreaLight::new(&squares[1]).unwrap(),
            AreaLight::sun_disc(glam::DVec3::new(0.4, -0.3, 1.0), 3f64.to_radians()).unwrap(),
        ];
        for (k, light) in lights.iter().enumerate() {
            let fast = light.classify_faces(&faces);
            for (i, face) in faces.iter().enumerate() {
                let (a, b) = (
                    class_areas(&fast[i]),
                    class_areas(&light.classify_face(face, &faces)),
                );
                assert_eq!(a, b, "face {i} of {loops:?}");
                classes.extend(fast[i].iter().map(|f| f.class));
                // a polygon light's classes against the exact view at
                // lattice points of every third face (a face with a light
                // corner not in front of it is never lit; the view then
                // sees the part of the light in front of it)
                let Some(square) = squares.get(k).filter(|_| i % 3 == 0) else {
                    continue;
                };
                let turned = (square.iter()).any(|&c| face.plane().classify_grid(c) != Side::Front);
                for x in on_face(&mut rng, face, 48) {
                    let Some(f) = fast[i].iter().find(|f| strictly_inside(&f.polygon, x)) else {
                        continue;
                    };
                    // (where another face pierces this one, a point on
                    // the line they cross at sees the light past it: a
                    // set of zero area inside its fragment, whose class is
                    // that of the points around it; `SVBSP_SEED=51`)
                    if pierced(&faces, face, x) {
                        continue;
                    }
                    match turned {
                        true => assert_ne!(f.class, AreaClass::Lit, "{x:?}"),
                        false => assert_agrees(light, (x, face.plane()), &faces, f.class),
                    }
                    viewed += 1;
                }
            }
        }
    }
    assert!(
        hunt().is_some() || classes.len() >= 3 && viewed > 50,
        "{classes:?}, {viewed} viewed"
    );
}

/// Whether grid point `x` of `face` lies in the plane of an occluder not
/// in `face`'s plane (either way round). An occluder through `x` hides
/// from it only the light points in its own plane, no area, so the exact
/// view there can differ from the view at the points around it.
fn pierced(faces: &[Occluder], face: &Occluder, x: [i32; 3]) -> bool {
    (faces.iter().map(Occluder::plane))
        .any(|q| !q.is_coincident(face.plane()) && q.classify_grid(x) == Side::On)
}

/// Grid points of `face`'s plane in its box, from `tries` random points
/// across the plane's largest normal axis (those that land on the grid).
fn on_face(rng: &mut Rng, face: &Occluder, tries: usize) -> Vec<[i32; 3]> {
    let (n, d) = (face.plane().normal(), face.plane().offset());
    let k = (0..3).max_by_key(|&k| n[k].abs()).expect("three axes");
    let (u, v) = ((k + 1) % 3, (k + 2) % 3);
    let c = face.corners();
    let span = |a: usize| {
        let lo = c.iter().map(|p| p[a]).min().expect("corners");
        (lo, c.iter().map(|p| p[a]).max().expect("corners") - lo + 1)
    };
    let ((lu, wu), (lv, wv)) = (span(u), span(v));
    let mut out = Vec::new();
    for _ in 0..tries {
        let mut x = [0; 3];
        x[u] = lu + below(rng, wu as u64);
        x[v] = lv + below(rng, wv as u64);
        let num = -(d + i128::from(n[u]) * i128::from(x[u]) + i128::from(n[v]) * i128::from(x[v]));
        if num % i128::from(n[k]) == 0 {
            x[k] = (num / i128::from(n[k])) as i32;
            out.push(x);
        }
    }
    out
}

/// A square occluder over the ground under a square light, in closed
/// form: light `[0, 40]²` at height 80, occluder `[0, 40]²` at height 40;
/// light point `l` shadows `2o − l`, so on the ground the umbra is the
/// intersection over `l` of `[−l, 80 − l]²`, `[0, 40]²` (1,600), and the
/// penumbra reaches their union `[−40, 80]²` (14,400). The same square
/// split into two triangles (faces of one plane sharing an edge, as a mesh
/// gives it) casts exactly the same regions: its halves are merged into
/// one occluder, so its umbra is umbra, not undecided.
#[test]
fn a_square_and_its_two_triangles_cast_the_same_umbra() {
    let light = AreaLight::new(&square_light(0, 0, 40, 80)).unwrap();
    let q = [[0, 0, 40], [40, 0, 40], [40, 40, 40], [0, 40, 40]];
    let ground = Occluder::new(&ground(200)).unwrap();
    let whole = vec![ground.clone(), Occluder::new(&q).unwrap()];
    let halves = vec![
        ground.clone(),
        Occluder::new(&[q[0], q[1], q[2]]).unwrap(),
        Occluder::new(&[q[0], q[2], q[3]]).unwrap(),
    ];
    let areas = |faces: &[Occluder]| class_areas(&light.classify_face(&ground, faces));
    // (twice the areas)
    let total = 2 * 400 * 400;
    let mut want: [Q; 4] = std::array::from_fn(|_| Q::zero());
    want[AreaClass::Lit as usize] = Q::from_integer((total - 2 * 14_400).into());
    want[AreaClass::Penumbra as usize] = Q::from_integer((2 * (14_400 - 1_600)).into());
    want[AreaClass::Umbra as usize] = Q::from_integer((2 * 1_600).into());
    for got in [areas(&whole), areas(&halves)] {
        assert_eq!(got, want);
    }
}

/// A 12 × 12 ground at height 0 (face 0), a copy of the mesh `v, tris`
/// moved by each of `at`, and a 1.2 × 1.2 light at height 6 whose corners
/// turn clockwise seen from above (it shines down), on the grid that fits
/// them.
fn spheres_under_a_light(
    v: &[DVec3],
    tris: &[Vec<u32>],
    at: &[DVec3],
) -> (bsp_core::Grid, Vec<Occluder>, AreaLight) {
    let mut world: Vec<Vec<DVec3>> = vec![vec![
        DVec3::new(-6.0, -6.0, 0.0),
        DVec3::new(6.0, -6.0, 0.0),
        DVec3::new(6.0, 6.0, 0.0),
        DVec3::new(-6.0, 6.0, 0.0),
    ]];
    for &d in at {
        world.extend(
            tris.iter()
                .map(|t| t.iter().map(|&i| v[i as usize] + d).collect()),
        );
    }
    let corners =
        [(-0.4, -0.6), (-0.4, 0.6), (0.8, 0.6), (0.8, -0.6)].map(|(x, y)| DVec3::new(x, y, 6.0));
    let grid = bsp_core::Grid::fit_points(world.iter().flatten().chain(&corners)).unwrap();
    let faces = snapped(&world, &grid);
    assert_eq!(faces.len(), world.len());
    let light = AreaLight::new(&corners.map(|c| grid.snap(c).unwrap())).unwrap();
    (grid, faces, light)
}

/// A closed mesh (a UV sphere of 400 triangles) over the ground under a
/// square light: its faces hide the light mostly together. The faces cut
/// with the corners' point-light trees and the sphere's inner occluders
/// (`classify_faces`) have the same lit and penumbra areas as when cut by
/// every occluder's volume from each corner (`classify_face`, no inner
/// occluders), and the same area hidden from every corner, of which the
/// inner occluders decide most of what `classify_face` leaves undecided
/// as umbra; at grid points strictly inside the ground's fragments the
/// exact view agrees with their class.
#[test]
fn a_mesh_cut_both_ways_agrees_with_the_view() {
    let (v, tris) = bsp_fixtures::shapes::uv_sphere(400);
    let (grid, faces, light) = spheres_under_a_light(&v, &tris, &[DVec3::new(0.2, -0.1, 2.0)]);
    let fast = light.classify_faces(&faces);
    let (lit, penumbra, umbra, undecided) = (0, 1, 2, 3);
    for i in (0..faces.len()).step_by(10).chain([0]) {
        let (a, b) = (
            class_areas(&fast[i]),
            class_areas(&light.classify_face(&faces[i], &faces)),
        );
        assert_eq!(a[lit], b[lit], "face {i}: {a:?} against {b:?}");
        assert_eq!(a[penumbra], b[penumbra], "face {i}: {a:?} against {b:?}");
        assert_eq!(
            &a[umbra] + &a[undecided],
            &b[umbra] + &b[undecided],
            "face {i}: {a:?} against {b:?}"
        );
        assert!(
            a[undecided] <= b[undecided],
            "face {i}: {a:?} against {b:?}"
        );
        if i == 0 {
            // the ground: the sphere's joint umbra, undecided without
            // the inner occluders, is mostly decided with them
            assert!(
                &b[undecided] * Q::from_integer(20.into()) > b[umbra]
                    && &a[undecided] * Q::from_integer(2.into()) < b[undecided],
                "the ground: {a:?} against {b:?}"
            );
        }
    }
    // the same through `soft_shadows` (whose faces with many occluders
    // near have their boxes narrowed to the slab round their plane)
    let soft = svbsp::soft_shadows(std::slice::from_ref(&light), &faces).unwrap();
    for i in (0..faces.len()).step_by(10).chain([0]) {
        let a =
            class_areas_of(soft_pieces(&soft[i]).map(|(p, f)| (&p.polygon, f.class(0) as usize)));
        let b = class_areas(&light.classify_face(&faces[i], &faces));
        assert!(
            a[lit] == b[lit] && a[penumbra] == b[penumbra],
            "face {i}: {a:?} against {b:?}"
        );
        assert_eq!(
            &a[umbra] + &a[undecided],
            &b[umbra] + &b[undecided],
            "face {i}: {a:?} against {b:?}"
        );
    }
    let mut rng = rng(0x005f_3e4e);
    let plane = *faces[0].plane();
    let half = grid.snap(DVec3::new(3.0, 3.0, 0.0)).unwrap();
    let mut met = std::collections::HashMap::new();
    for _ in 0..400 {
        let x = [
            below(&mut rng, 2 * half[0] as u64) - half[0],
            below(&mut rng, 2 * half[1] as u64) - half[1],
            grid.snap(DVec3::ZERO).unwrap()[2],
        ];
        let Some(f) = fast[0].iter().find(|f| strictly_inside(&f.polygon, x)) else {
            continue;
        };
        assert_agrees(&light, (x, &plane), &faces, f.class);
        *met.entry(f.class).or_insert(0) += 1;
    }
    for class in [
        AreaClass::Lit,
        AreaClass::Penumbra,
        AreaClass::Umbra,
        AreaClass::Undecided,
    ] {
        assert!(
            hunt().is_some() || met.contains_key(&class),
            "{class:?} never met: {met:?}"
        );
    }
}

/// The six faces of the box `[lo, hi]`, turned outward.
fn box_faces(lo: [i32; 3], hi: [i32; 3]) -> Vec<Vec<[i32; 3]>> {
    let c = |i: usize| [0, 1, 2].map(|k| if i >> k & 1 == 1 { hi[k] } else { lo[k] });
    [
        [0, 2, 3, 1], // z low, seen from below
        [4, 5, 7, 6], // z high
        [0, 1, 5, 4], // y low
        [2, 6, 7, 3], // y high
        [0, 4, 6, 2], // x low
        [1, 3, 7, 5], // x high
    ]
    .iter()
    .map(|q| q.iter().map(|&i| c(i)).collect())
    .collect()
}

/// A point outside a closed solid passes over the solid's faces it lies
/// behind when it takes its share of the light (they hide nothing its
/// others do not): the shares on the ground round a cube standing on it,
/// a cube tipped onto one edge and a tetrahedron on one corner, are those
/// of `AreaLight::view` with every face, at points far and near, on the
/// solids' contact with the ground (which see none of the light through
/// the solid above them) and just beside it.
#[test]
fn a_solids_far_side_hides_nothing_more() {
    let cube = box_faces([-20, -20, 0], [20, 20, 40]);
    // the cube turned 45° about x, resting on its edge along y = 0, z = 0
    let tipped: Vec<Vec<[i32; 3]>> = box_faces([-20, -20, -20], [20, 20, 20])
        .iter()
        .map(|f| {
            f.iter()
                .map(|p| [p[0], p[1] - p[2], p[1] + p[2] + 40])
                .collect()
        })
        .collect();
    // a tetrahedron standing on its corner at the origin, turned outward
    let (o, a, b, c) = ([0, 0, 0], [30, 0, 50], [-20, 30, 50], [-20, -30, 50]);
    let tetra = vec![vec![o, b, a], vec![o, c, b], vec![o, a, c], vec![a, b, c]];
    let light = AreaLight::new(&square_light(30, -20, 40, 140)).unwrap();
    for solid in [cube, tipped, tetra] {
        let mut faces = vec![ground(160)];
        faces.extend(solid);
        let occluders: Vec<Occluder> = faces.iter().map(|f| Occluder::new(f).unwrap()).collect();
        let run = svbsp::SoftVolumes::new(std::slice::from_ref(&light), &occluders).unwrap();
        let mut points: Vec<[i32; 3]> = Vec::new();
        for x in (-60..=60).step_by(5) {
            for y in (-60..=60).step_by(5) {
                points.push([x, y, 0]);
            }
        }
        points.extend([
            [0, 0, 0],
            [1, 0, 0],
            [0, 1, 0],
            [20, 20, 0],
            [21, 20, 0],
            [7, 0, 0],
        ]);
        let normal = DVec3::Z;
        let shares = run.shares(0, 0, &points);
        let (mut hidden, mut partly) = (0, 0);
        for (x, got) in points.iter().zip(shares) {
            let want = light
                .view(*x, Some(occluders[0].plane()), &occluders[1..])
                .and_then(|v| v.fraction(DVec3::from_array(x.map(f64::from)), normal));
            match (got, want) {
                (Some(g), Some(w)) => assert!((g - w).abs() <= 1e-9, "{x:?}: {g} against {w}"),
                _ => assert_eq!(got, want, "{x:?}"),
            }
            hidden += usize::from(want == Some(0.0));
            partly += usize::from(want.is_some_and(|w| w > 0.0 && w < 1.0));
        }
        assert!(
            hidden > 0 && partly > 10,
            "{hidden} hidden, {partly} in part"
        );
    }
}

/// The same on meshes: a closed UV sphere floating over the ground and one
/// standing on it on its pole, under a square light: every share on the
/// ground (random points, and the point the standing sphere touches)
/// equals `AreaLight::view` with every face.
#[test]
fn shares_past_closed_meshes_equal_the_view_with_every_face() {
    let (v, tris) = bsp_fixtures::shapes::uv_sphere(200);
    let lowest = v.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
    let at = [DVec3::new(-1.1, 0.2, 2.0), DVec3::new(1.2, -0.3, -lowest)];
    let (grid, faces, light) = spheres_under_a_light(&v, &tris, &at);
    let run = svbsp::SoftVolumes::new(std::slice::from_ref(&light), &faces).unwrap();
    let mut rng = rng(0x0b5c_0e11);
    let half = grid.snap(DVec3::new(3.0, 3.0, 0.0)).unwrap();
    let z = grid.snap(DVec3::ZERO).unwrap()[2];
    let touch = grid.snap(DVec3::new(1.2, -0.3, 0.0)).unwrap();
    let mut points = vec![touch];
    for _ in 0..300 {
        points.push([
            below(&mut rng, 2 * half[0] as u64) - half[0],
            below(&mut rng, 2 * half[1] as u64) - half[1],
            z,
        ]);
    }
    let shares = run.shares(0, 0, &points);
    let mut partly = 0;
    for (x, got) in points.iter().zip(shares) {
        let want = light
            .view(*x, Some(faces[0].plane()), &faces[1..])
            .and_then(|v| v.fraction(DVec3::from_array(x.map(f64::from)), DVec3::Z));
        match (got, want) {
            (Some(g), Some(w)) => assert!((g - w).abs() <= 1e-9, "{x:?}: {g} against {w}"),
            _ => assert_eq!(got, want, "{x:?}"),
        }
        partly += usize::from(want.is_some_and(|w| w > 0.0 && w < 1.0));
    }
    assert!(partly > 20, "{partly} points in part");
}

/// Inner occluders decide joint umbra only where it is: a torus (whose
/// slices are rings round the hole the light shines through) and a UV
/// sphere over the ground under a square light, through `soft_shadows`.
/// At grid points strictly inside the ground's fragments the exact view
/// agrees with their class, umbra is met under both meshes (where no one
/// of their faces hides the light alone), and the light seen through the
/// torus's hole is never called umbra.
#[test]
fn inner_occluders_decide_joint_umbra_only_where_it_is() {
    let mut world: Vec<Vec<DVec3>> = vec![vec![
        DVec3::new(-6.0, -6.0, 0.0),
        DVec3::new(6.0, -6.0, 0.0),
        DVec3::new(6.0, 6.0, 0.0),
        DVec3::new(-6.0, 6.0, 0.0),
    ]];
    let lift = DVec3::new(0.0, 0.0, 1.5);
    world.extend(
        bsp_fixtures::shapes::torus(24, 12, 1.2, 0.45)
            .iter()
            .map(|t| t.iter().map(|&p| p + lift).collect()),
    );
    let (v, tris) = bsp_fixtures::shapes::uv_sphere(400);
    let at = DVec3::new(3.0, 0.5, 1.2);
    world.extend(
        tris.iter()
            .map(|t| t.iter().map(|&i| v[i as usize] * 0.8 + at).collect()),
    );
    let corners =
        [(-0.6, -0.6), (-0.6, 0.6), (0.6, 0.6), (0.6, -0.6)].map(|(x, y)| DVec3::new(x, y, 6.0));
    let grid = bsp_core::Grid::fit_points(world.iter().flatten().chain(&corners)).unwrap();
    let faces = snapped(&world, &grid);
    assert_eq!(faces.len(), world.len());
    let light = AreaLight::new(&corners.map(|c| grid.snap(c).unwrap())).unwrap();
    let all = svbsp::soft_shadows(std::slice::from_ref(&light), &faces).unwrap();
    let plane = *faces[0].plane();
    let mut rng = rng(0x70_2e5);
    let half = grid.snap(DVec3::new(4.2, 2.0, 0.0)).unwrap();
    let z = grid.snap(DVec3::ZERO).unwrap()[2];
    // where the ground sees the light through the hole, and under each mesh
    let hole = grid.snap(DVec3::new(0.0, 0.0, 0.0)).unwrap();
    let mut umbra = [0; 2];
    for n in 0..1500 {
        let x = match n {
            0 => hole,
            _ => [
                below(&mut rng, 2 * half[0] as u64) - half[0] / 2,
                below(&mut rng, 2 * half[1] as u64) - half[1],
                z,
            ],
        };
        let Some(f) = soft_at(&all[0], x) else {
            continue;
        };
        let class = f.class(0);
        assert_agrees(&light, (x, &plane), &faces, class);
        if n == 0 {
            assert_ne!(class, AreaClass::Umbra, "the light seen through the hole");
        }
        if class == AreaClass::Umbra {
            umbra[usize::from(x[0] > grid.snap(DVec3::new(2.0, 0.0, 0.0)).unwrap()[0])] += 1;
        }
    }
    assert!(
        umbra[0] > 0 && umbra[1] > 0,
        "umbra met under the torus and the sphere: {umbra:?}"
    );
    // the same fragments with the faces in another order, on one thread
    let mut order: Vec<usize> = (0..faces.len()).collect();
    order.reverse();
    order.swap(0, faces.len() / 2);
    let shuffled: Vec<Occluder> = order.iter().map(|&i| faces[i].clone()).collect();
    let one = on_threads(1, || {
        svbsp::soft_shadows(std::slice::from_ref(&light), &shuffled)
    })
    .unwrap();
    for (s, &i) in order.iter().enumerate() {
        assert_eq!(soft_keys(&one[s]), soft_keys(&all[i]), "face {i}");
    }
}

/// A light sealed inside a closed box over the ground: every ground point
/// is umbra (the view agrees at points near and far), through
/// `soft_shadows` and `classify_faces` both, where each occluder alone
/// leaves the far ground undecided (its light corners hidden by
/// different walls).
#[test]
fn a_light_sealed_in_a_closed_box_leaves_the_outside_in_umbra() {
    let mut faces = vec![ground(400)];
    faces.extend(box_faces([-40, -40, 40], [40, 40, 120]));
    let occluders: Vec<Occluder> = faces.iter().map(|f| Occluder::new(f).unwrap()).collect();
    // shining down from inside the box
    let light = AreaLight::new(&[[-8, -8, 100], [-8, 8, 100], [8, 8, 100], [8, -8, 100]]).unwrap();
    let soft = svbsp::soft_shadows(std::slice::from_ref(&light), &occluders).unwrap();
    let classified = light.classify_faces(&occluders);
    assert!(soft[0].iter().all(|f| f.class(0) == AreaClass::Umbra));
    assert!(classified[0].iter().all(|f| f.class == AreaClass::Umbra));
    let plane = *occluders[0].plane();
    for x in [[0, 0, 0], [100, 0, 0], [300, -250, 0], [-390, 390, 0]] {
        assert_agrees(&light, (x, &plane), &occluders, AreaClass::Umbra);
    }
    // the ground alone under each wall: some of it undecided
    let alone = light.classify_face(&occluders[0], &occluders);
    let classes: Vec<AreaClass> = alone.iter().map(|f| f.class).collect();
    assert!(classes.contains(&AreaClass::Undecided), "{classes:?}");
}

/// A ground under more occluders than a face prepares one by one (a
/// field of 34 × 34 small triangles, every one's penumbra on the ground;
/// they are prepared, and the ground's many corner cells made, in
/// parallel): the ground's fragments tile it, none
/// is undecided (the gaps between the triangles are too wide for any
/// joint umbra), they agree with the exact view at grid points inside
/// them, carry at their centroids the share that
/// `SoftVolumes::shares` finds there (0 exactly where the view sees
/// nothing), and are the same on one thread and on three.
#[test]
fn a_ground_under_a_field_of_occluders_agrees_with_the_view() {
    let light = AreaLight::new(&square_light(-2, -2, 4, 96)).unwrap();
    let faces = field_of_occluders(17);
    let run = |threads: usize| {
        on_threads(threads, || {
            svbsp::soft_shadows(std::slice::from_ref(&light), &faces)
        })
        .unwrap()
    };
    // each fragment's corners, pieces, classes and centroid share's bits
    type Key = (Vec<[f64; 3]>, Vec<Vec<[f64; 3]>>, u64, u64, Option<u64>);
    let key = |fs: &[svbsp::SoftFragment]| -> Vec<Key> {
        fs.iter()
            .map(|f| {
                let share = f.visible[0].as_ref().map(|s| s.centroid.to_bits());
                let ring = (f.rings.iter().flatten()).map(|p| p.to_f64()).collect();
                let pieces = (f.pieces.iter())
                    .map(|p| p.polygon.vertices_f64())
                    .collect();
                (ring, pieces, f.lit, f.umbra, share)
            })
            .collect()
    };
    let one = run(1);
    let three = run(3);
    for (a, b) in one.iter().zip(&three) {
        assert_eq!(key(a), key(b));
    }
    let ground_fragments = &one[0];
    assert!(tile_by_area(
        faces[0].corners(),
        soft_pieces(ground_fragments).map(|(p, _)| &p.polygon)
    ));
    // the gaps between the triangles, seen from the ground, are wider
    // than the light: every corner hidden means hidden by one triangle,
    // whose umbra it is (nothing jointly hidden, nothing undecided)
    assert!(
        ground_fragments
            .iter()
            .all(|f| f.class(0) != AreaClass::Undecided)
    );
    let plane = *faces[0].plane();
    let mut rng = rng(0x00f1_e1d5);
    let mut met = std::collections::HashMap::new();
    for _ in 0..100 {
        let Some((x, f)) = on_the_ground(&mut rng, 240, ground_fragments) else {
            continue;
        };
        assert_agrees(&light, (x, &plane), &faces, f.class(0));
        *met.entry(f.class(0)).or_insert(0) += 1;
    }
    for class in [AreaClass::Lit, AreaClass::Penumbra, AreaClass::Umbra] {
        assert!(
            hunt().is_some() || met.contains_key(&class),
            "{class:?} never met: {met:?}"
        );
    }
    // the shares at the penumbra pieces' centroids, asked of the run
    let volumes = svbsp::SoftVolumes::new(std::slice::from_ref(&light), &faces).unwrap();
    let (mut asked, mut dark) = (0, 0);
    for (f, _) in soft_pieces(ground_fragments)
        .filter(|(p, _)| p.visible[0].is_some())
        .step_by(16)
    {
        let c = f.polygon.vertices_f64();
        let n = c.len() as f64;
        let centroid = [0, 1, 2].map(|k| (c.iter().map(|p| p[k]).sum::<f64>() / n).round() as i32);
        let share = volumes.shares(0, 0, &[centroid])[0].unwrap_or(0.0);
        assert_eq!(
            share,
            f.visible[0].as_ref().unwrap().centroid,
            "at {centroid:?}"
        );
        let seen = light
            .view(centroid, Some(&plane), &faces)
            .unwrap()
            .visibility;
        assert_eq!(seen == Visibility::None, share == 0.0, "at {centroid:?}");
        asked += 1;
        dark += usize::from(share == 0.0);
    }
    assert!(
        asked > 20 && dark > 0,
        "{asked} penumbra pieces asked, {dark} dark"
    );
}

/// A ground of side 480 and `(2 n)²` small triangles 20 above it, on a
/// grid of step 10.
fn field_of_occluders(n: i32) -> Vec<Occluder> {
    let mut faces = vec![Occluder::new(&ground(240)).unwrap()];
    for i in -n..n {
        for j in -n..n {
            let (x, y) = (i * 10, j * 10);
            faces.push(Occluder::new(&[[x, y, 20], [x + 7, y, 20], [x, y + 7, 21]]).unwrap());
        }
    }
    faces
}

/// The files' run (`soft_regions_with`: no shares for the pieces) gives
/// every fragment, its pieces and its shares (centroid, least, most and
/// each ring corner's, to the bit) as the full run does, under two square
/// lights together; on a ground whose regions are made of
/// many pieces, so a region's shares come from its rings' corners and its
/// largest piece's centroid.
#[test]
fn the_files_run_gives_the_fragments_shares_of_the_full_run() {
    let lights = [
        AreaLight::new(&square_light(-2, -2, 4, 96)).unwrap(),
        AreaLight::new(&square_light(30, -20, 3, 80)).unwrap(),
    ];
    let faces = field_of_occluders(8);
    let full = svbsp::soft_shadows(&lights, &faces).unwrap();
    let lean = svbsp::soft_regions_with(&lights, &faces, &|_| {}).unwrap();
    let bits = |s: &Option<svbsp::Share>| {
        s.as_ref().map(|s| {
            let corners: Vec<u64> = s.corners.iter().map(|c| c.to_bits()).collect();
            (
                s.centroid.to_bits(),
                s.min.to_bits(),
                s.max.to_bits(),
                corners,
            )
        })
    };
    let (mut shared, mut of_many) = (0, 0);
    assert_eq!(full.len(), lean.len());
    for (a, b) in full.iter().zip(&lean) {
        assert_eq!(a.len(), b.len());
        for (f, g) in a.iter().zip(b) {
            assert_eq!((f.lit, f.umbra, f.undecided), (g.lit, g.umbra, g.undecided));
            let ring = |f: &svbsp::SoftFragment| -> Vec<Vec<[f64; 3]>> {
                (f.rings.iter())
                    .map(|r| r.iter().map(|p| p.to_f64()).collect())
                    .collect()
            };
            assert_eq!(ring(f), ring(g));
            assert_eq!(f.pieces.len(), g.pieces.len());
            for (p, q) in f.pieces.iter().zip(&g.pieces) {
                assert_eq!(p.polygon.vertices_f64(), q.polygon.vertices_f64());
                assert!(q.visible.iter().all(Option::is_none));
            }
            for (s, t) in f.visible.iter().zip(&g.visible) {
                assert_eq!(bits(s), bits(t));
                shared += usize::from(s.is_some());
                of_many += usize::from(s.is_some() && f.pieces.len() > 1);
            }
        }
    }
    assert!(
        shared > 100 && of_many > 5,
        "{shared} shares, {of_many} of regions of many pieces"
    );
}

/// A real mesh over a ground under a square light placed at random above
/// it, and under a sun disc from a random direction: at random grid
/// points strictly inside the ground's fragments, the exact view agrees
/// with their class (the corners' trees, the near lists, the merged
/// coplanar faces and, for closed meshes, the inner occluders and the
/// culling of the faces a point lies behind all take part). The bunny by
/// default; a hunt (`SVBSP_SEED`) draws a mesh of `data/meshes` too.
#[test]
fn real_meshes_over_a_ground_agree_with_the_view() {
    let mut rng = rng(0x9e41_ae54);
    let names = [
        "bunny.obj",
        "teapot.obj",
        "pyvista_ant.obj",
        "pyvista_nut.obj",
        "cgal_eight.obj",
    ];
    let name = match hunt() {
        None => names[0],
        Some(_) => names[below(&mut rng, names.len() as u64) as usize],
    };
    let loops = mesh_loops(name);
    let pts: Vec<DVec3> = loops.iter().flatten().copied().collect();
    let (lo, hi) = pts
        .iter()
        .fold((pts[0], pts[0]), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let size = (hi - lo).max_element();
    let unit = |rng: &mut Rng| below(rng, 1 << 20) as f64 / f64::from(1 << 20);
    let (mid, z0) = ((lo + hi) / 2.0, lo.z - 0.05 * size);
    let r = 1.5 * size;
    let ground =
        [(-r, -r), (r, -r), (r, r), (-r, r)].map(|(x, y)| DVec3::new(mid.x + x, mid.y + y, z0));
    let (side, up) = (
        (0.05 + 0.5 * unit(&mut rng)) * size,
        (0.2 + unit(&mut rng)) * size,
    );
    let c = DVec3::new(
        mid.x + (unit(&mut rng) - 0.5) * size,
        mid.y + (unit(&mut rng) - 0.5) * size,
        hi.z + up,
    );
    let square = [(0.0, 0.0), (0.0, 1.0), (1.0, 1.0), (1.0, 0.0)]
        .map(|(x, y)| c + DVec3::new(x, y, 0.0) * side);
    let mut world = vec![ground.to_vec()];
    world.extend(loops);
    let grid = bsp_core::Grid::fit_points(world.iter().flatten().chain(&square)).unwrap();
    let faces = snapped(&world, &grid);
    let d = DVec3::new(
        unit(&mut rng) - 0.5,
        unit(&mut rng) - 0.5,
        0.5 + unit(&mut rng),
    )
    .normalize();
    let radius = (0.5 + 3.0 * unit(&mut rng)).to_radians();
    let lights = [
        AreaLight::new(&square.map(|c| grid.snap(c).unwrap())).unwrap(),
        AreaLight::sun_disc(d, radius).unwrap(),
    ];
    // the disc checked by directions over the true disc (its rim and
    // centre) and the ray oracle
    let (u, v) = (
        d.any_orthonormal_vector(),
        d.cross(d.any_orthonormal_vector()),
    );
    let directions: Vec<Light> = (0..12)
        .map(|k| {
            let a = std::f64::consts::TAU * f64::from(k) / 12.0;
            d + (u * a.cos() + v * a.sin()) * radius.tan()
        })
        .chain([d])
        .map(|s| Light::Directional(svbsp::quantize_direction(s).unwrap()))
        .collect();
    let corners: Vec<Vec<[i32; 3]>> = faces.iter().map(|f| f.corners().to_vec()).collect();
    let scene = Scene::from_polygons(&polygons(&corners));
    let g = ground.map(|c| grid.snap(c).unwrap());
    let plane = *faces[0].plane();
    for (k, light) in lights.iter().enumerate() {
        let fast = light.classify_faces(&faces);
        let mut met = std::collections::HashSet::new();
        for _ in 0..[300, 60][k] {
            let x = [0, 1].map(|k| g[0][k] + below(&mut rng, (g[2][k] - g[0][k]) as u64));
            let x = [x[0], x[1], g[0][2]];
            let Some(f) = fast[0].iter().find(|f| strictly_inside(&f.polygon, x)) else {
                continue;
            };
            met.insert(f.class);
            if k == 0 {
                assert_agrees(light, (x, &plane), &faces, f.class);
                continue;
            }
            assert_disc_agrees(&scene, &directions, x, f.class, name);
        }
        assert!(hunt().is_some() || met.len() >= 3, "{name}: {met:?}");
    }
}
