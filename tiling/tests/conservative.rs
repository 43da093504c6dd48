//! The tiling never misses: every static polygon whose projection from the
//! light meets the projection of a query box is in the query's answer.
//! The brute-force check decides "the projections meet" exactly and
//! independently of the index (no cube, no tiles, no clipping):
//!
//! - point light: the cones of directions from the light to the polygon
//!   and to the box (conic hulls of the vertices' directions) meet in a
//!   ray unless a plane through the light strictly separates their
//!   generators (Gordan's alternative). If one does, the sum of every
//!   candidate plane normal `± g_i × g_j` (over pairs of generators) that
//!   separates weakly is such a plane, so the test is exact;
//! - sun: the projections of the vertices along the direction (a 2D
//!   affine map) have convex hulls that meet unless an axis among the
//!   directions and normals of the point pairs separates them strictly.

use bsp_core::{GridPoint, MAX_COORD, Polygon};
use num_bigint::BigInt;
use num_traits::{Signed, Zero};
use proptest::prelude::*;
use svbsp::Light;
use tiling::{Query, TileIndex};

type Z3 = [BigInt; 3];

fn z(v: [i64; 3]) -> Z3 {
    v.map(BigInt::from)
}

fn sub(a: &Z3, b: &Z3) -> Z3 {
    [&a[0] - &b[0], &a[1] - &b[1], &a[2] - &b[2]]
}

fn cross(a: &Z3, b: &Z3) -> Z3 {
    [
        &a[1] * &b[2] - &a[2] * &b[1],
        &a[2] * &b[0] - &a[0] * &b[2],
        &a[0] * &b[1] - &a[1] * &b[0],
    ]
}

fn dot(a: &Z3, b: &Z3) -> BigInt {
    &a[0] * &b[0] + &a[1] * &b[1] + &a[2] * &b[2]
}

/// Whether the cones of directions from `light` to the points `a` and to
/// the points `b` share a ray (both cones pointed: the light is off the
/// polygon's plane and outside the box).
fn cones_meet(light: [i64; 3], a: &[[i64; 3]], b: &[[i64; 3]]) -> bool {
    let l = z(light);
    let ga: Vec<Z3> = a.iter().map(|&p| sub(&z(p), &l)).collect();
    let gb: Vec<Z3> = b.iter().map(|&p| sub(&z(p), &l)).collect();
    let all: Vec<&Z3> = ga.iter().chain(&gb).collect();
    let weak = |h: &Z3| {
        ga.iter().all(|g| !dot(h, g).is_negative()) && gb.iter().all(|g| !dot(h, g).is_positive())
    };
    let mut sum: Z3 = [BigInt::zero(), BigInt::zero(), BigInt::zero()];
    for i in 0..all.len() {
        for j in 0..i {
            let c = cross(all[i], all[j]);
            for h in [c.clone(), c.map(|x| -x)] {
                if weak(&h) {
                    sum = [&sum[0] + &h[0], &sum[1] + &h[1], &sum[2] + &h[2]];
                }
            }
        }
    }
    let strict = ga.iter().all(|g| dot(&sum, g).is_positive())
        && gb.iter().all(|g| dot(&sum, g).is_negative());
    !strict
}

/// Whether the projections along `s` of the points `a` and `b` meet.
fn shadows_meet(s: [i64; 3], a: &[[i64; 3]], b: &[[i64; 3]]) -> bool {
    // an exact 2D frame across s: u = e1 · p, w = e2 · p
    let sz = z(s);
    let k = (0..3).min_by_key(|&k| s[k].abs()).unwrap();
    let mut ax = [0i64; 3];
    ax[k] = 1;
    let e1 = cross(&sz, &z(ax));
    let e2 = cross(&sz, &e1);
    let pr = |p: &[i64; 3]| [dot(&e1, &z(*p)), dot(&e2, &z(*p))];
    let pa: Vec<[BigInt; 2]> = a.iter().map(pr).collect();
    let pb: Vec<[BigInt; 2]> = b.iter().map(pr).collect();
    let mut axes: Vec<[BigInt; 2]> = Vec::new();
    for set in [&pa, &pb] {
        for i in 0..set.len() {
            for j in 0..i {
                let d = [&set[i][0] - &set[j][0], &set[i][1] - &set[j][1]];
                axes.push([-d[1].clone(), d[0].clone()]);
                axes.push(d);
            }
        }
    }
    let proj = |n: &[BigInt; 2], p: &[BigInt; 2]| &n[0] * &p[0] + &n[1] * &p[1];
    !axes.iter().any(|n| {
        let (amin, amax) = minmax(pa.iter().map(|p| proj(n, p)));
        let (bmin, bmax) = minmax(pb.iter().map(|p| proj(n, p)));
        amax < bmin || bmax < amin
    })
}

fn minmax(v: impl Iterator<Item = BigInt>) -> (BigInt, BigInt) {
    let v: Vec<BigInt> = v.collect();
    (
        v.iter().min().unwrap().clone(),
        v.iter().max().unwrap().clone(),
    )
}

fn box_corners(lo: GridPoint, hi: GridPoint) -> Vec<[i64; 3]> {
    let mut c = Vec::new();
    for m in 0..8 {
        c.push([0, 1, 2].map(|k| {
            if m >> k & 1 == 1 {
                hi[k] as i64
            } else {
                lo[k] as i64
            }
        }));
    }
    c
}

fn grid(p: &Polygon) -> Vec<[i64; 3]> {
    p.vertices()
        .iter()
        .map(|v| v.as_grid().unwrap().map(i64::from))
        .collect()
}

/// A scene of triangles and parallelograms around `centre` within `r`,
/// with `scale` stretching some of them far.
fn scene(centre: [i32; 3], r: i32, scale: i32) -> impl Strategy<Value = Vec<Polygon>> {
    let pt = move || {
        prop::array::uniform3(-r..=r)
            .prop_map(move |d| [0, 1, 2].map(|k| (centre[k] + d[k]).clamp(-MAX_COORD, MAX_COORD)))
    };
    let poly = (pt(), pt(), pt(), any::<bool>(), 1..=scale).prop_map(|(a, b, c, quad, s)| {
        // stretch the triangle about a by s (clamped to the grid)
        let st = |p: [i32; 3]| {
            [0, 1, 2].map(|k| {
                (a[k] as i64 + (p[k] - a[k]) as i64 * s as i64)
                    .clamp(-MAX_COORD as i64, MAX_COORD as i64) as i32
            })
        };
        let (b, c) = (st(b), st(c));
        if quad {
            let d = [0, 1, 2].map(|k| (b[k] + c[k] - a[k]).clamp(-MAX_COORD, MAX_COORD));
            vec![a, b, d, c]
        } else {
            vec![a, b, c]
        }
    });
    prop::collection::vec(poly, 1..24).prop_map(|loops| {
        loops
            .iter()
            .enumerate()
            .filter_map(|(i, l)| Polygon::from_grid_points(l, i as u32).ok())
            .collect()
    })
}

fn a_box(centre: [i32; 3], r: i32) -> impl Strategy<Value = (GridPoint, GridPoint)> {
    (
        prop::array::uniform3(-r..=r),
        prop::array::uniform3(0..=r / 2 + 1),
    )
        .prop_map(move |(d, size)| {
            let lo = [0, 1, 2].map(|k| (centre[k] + d[k]).clamp(-MAX_COORD, MAX_COORD));
            let hi = [0, 1, 2].map(|k| (lo[k] + size[k]).clamp(-MAX_COORD, MAX_COORD));
            (lo, hi)
        })
}

/// Checks the query of every box against the brute force; returns the
/// numbers of polygons that meet and of polygons returned.
fn check(
    light: &Light,
    polys: &[Polygon],
    boxes: &[(GridPoint, GridPoint)],
    n: u32,
) -> Result<(usize, usize), TestCaseError> {
    let index = TileIndex::build(light, polys, Some(n)).unwrap();
    let mut q = Query::default();
    let (mut meet, mut found) = (0, 0);
    for &(lo, hi) in boxes {
        let got = index.query_box(lo, hi, &mut q).to_vec();
        prop_assert!(got.windows(2).all(|w| w[0] < w[1]), "ascending, no repeats");
        let corners = box_corners(lo, hi);
        for (i, p) in polys.iter().enumerate() {
            let v = grid(p);
            let meets = match *light {
                Light::Point(l) => {
                    let l = l.map(i64::from);
                    let inside = (0..3).all(|k| lo[k] as i64 <= l[k] && l[k] <= hi[k] as i64);
                    let edge_on = svbsp::Light::Point(l.map(|c| c as i32)).eval(p.support()) == 0;
                    if inside || edge_on {
                        continue; // not a pointed cone: checked elsewhere
                    }
                    cones_meet(l, &v, &corners)
                }
                Light::Directional(d) => shadows_meet(d.map(i64::from), &v, &corners),
            };
            if meets {
                meet += 1;
                prop_assert!(
                    got.binary_search(&(i as u32)).is_ok(),
                    "polygon {i} {v:?} meets the box {lo:?}..{hi:?} from {light:?} (n = {n}) but \
                     is not found"
                );
            }
        }
        found += got.len();
    }
    Ok((meet, found))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    /// Small scenes around a point light: polygons across cube faces,
    /// touching tile edges, close to the light; coarse and fine tiles.
    #[test]
    fn point_light_queries_never_miss(
        polys in scene([0, 0, 0], 24, 1),
        boxes in prop::collection::vec(a_box([0, 0, 0], 24), 1..6),
        light in prop::array::uniform3(-6i32..=6),
        n in prop::sample::select(vec![1u32, 2, 3, 4, 7, 16, 64]),
    ) {
        check(&Light::Point(light), &polys, &boxes, n)?;
    }

    /// Scenes stretched over the whole grid with coarse tiles, and small
    /// scenes far from the light with the finest tiles: the exact
    /// arithmetic at its widest.
    #[test]
    fn point_light_queries_never_miss_at_the_grid_limits(
        polys in scene([0, 0, 0], MAX_COORD / 2, 3),
        boxes in prop::collection::vec(a_box([0, 0, 0], MAX_COORD / 2), 1..6),
        light in prop::array::uniform3(-MAX_COORD..=MAX_COORD),
        n in prop::sample::select(vec![1u32, 5, 33]),
    ) {
        check(&Light::Point(light), &polys, &boxes, n)?;
    }

    #[test]
    fn point_light_queries_never_miss_with_the_finest_tiles(
        (centre, polys, boxes) in prop::array::uniform3(-MAX_COORD + 64..=MAX_COORD - 64)
            .prop_flat_map(|c| (
                Just(c),
                scene(c, 60, 1),
                prop::collection::vec(a_box(c, 60), 1..6),
            )),
        light in prop::array::uniform3(-MAX_COORD..=MAX_COORD),
        n in prop::sample::select(vec![1024u32, 1023]),
    ) {
        let _ = centre;
        check(&Light::Point(light), &polys, &boxes, n)?;
    }

    /// Suns from any direction, over small and huge scenes.
    #[test]
    fn sun_queries_never_miss(
        polys in scene([0, 0, 0], 40, 2),
        boxes in prop::collection::vec(a_box([0, 0, 0], 60), 1..6),
        dir in prop::array::uniform3(-MAX_COORD..=MAX_COORD),
        small in prop::array::uniform3(-3i32..=3),
        n in prop::sample::select(vec![1u32, 3, 16, 100, 4096]),
        use_small in any::<bool>(),
    ) {
        let d = if use_small { small } else { dir };
        prop_assume!(d != [0, 0, 0]);
        check(&Light::Directional(d), &polys, &boxes, n)?;
    }
}

#[test]
fn polygons_through_the_light_are_found_along_their_plane() {
    // a quad in the plane z = 0 through the light, and boxes just above
    // and below that plane (whose projections meet the quad's only where
    // they reach the plane's trace)
    let quad =
        Polygon::from_grid_points(&[[-50, -50, 0], [50, -50, 0], [50, 50, 0], [-50, 50, 0]], 0)
            .unwrap();
    let index = TileIndex::build(&Light::Point([0, 0, 0]), &[quad], Some(32)).unwrap();
    let mut q = Query::default();
    // a box crossing z = 0 beside the light
    assert_eq!(index.query_box([10, -2, -1], [12, 2, 1], &mut q), &[0]);
    // a box touching z = 0 from above
    assert_eq!(index.query_box([10, -2, 0], [12, 2, 3], &mut q), &[0]);
}

#[test]
fn a_light_inside_the_box_relates_everything() {
    let far = Polygon::from_grid_points(&[[100, 0, 0], [101, 0, 0], [100, 1, 0]], 0).unwrap();
    let index = TileIndex::build(&Light::Point([0, 0, 0]), &[far], None).unwrap();
    let mut q = Query::default();
    assert_eq!(index.query_box([-1, -1, -1], [1, 1, 1], &mut q), &[0]);
    // a flat box through the light too
    assert_eq!(index.query_box([-1, -1, 0], [1, 1, 0], &mut q), &[0]);
}
