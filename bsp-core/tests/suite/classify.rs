//! Planes, implicit points and every classification predicate, checked
//! against the oracle on random and adversarial input: points exactly on
//! planes (true value 0), one unit off them (true value ±1 or ±w), planes
//! whose value at an implicit point is a rounding error of its terms.

use bsp_core::{
    GridPoint, Implicit, MAX_VIEW_COORD, Plane, Point, Polygon, PolygonSide, Side, ViewPoint,
};
use num_bigint::BigInt;
use num_traits::{One, Signed, ToPrimitive};
use proptest::collection::vec;
use proptest::prelude::*;

use crate::oracle::{
    HPoint, OPlane, Q3, check_correctly_rounded, dot3, grid_q, grid_z, meet3, point_q,
    polygon_side, side_of,
};
use crate::strategies::{
    any_point, combine, combine_raw, convex_polygon, cut, make_cut, plane, plane_case,
    plane_triple, triangle, weights,
};

pub(crate) fn opposite(s: Side) -> Side {
    match s {
        Side::Front => Side::Back,
        Side::Back => Side::Front,
        Side::On => Side::On,
    }
}

/// A normal of any size within the budget (`|n_i| < 2^55`).
fn normal() -> impl Strategy<Value = [i64; 3]> {
    prop_oneof![Just(3u32), Just(12), Just(30), Just(55)].prop_flat_map(|b| {
        let m = (1i64 << b) - 1;
        [-m..=m, -m..=m, -m..=m]
    })
}

fn floor_div(a: &BigInt, b: &BigInt) -> BigInt {
    let q = a / b;
    if (a % b).is_negative() { q - 1 } else { q }
}

/// The plane with normal `n` whose offset makes it pass as close as an
/// integer offset can to the point `h`, moved by `delta`: its value at
/// `h` is at most `(1/2 + |delta|) w` while the terms are up to `2^250`.
fn nearest_plane(n: [i64; 3], h: &HPoint, delta: i64) -> Option<Plane> {
    let num = dot3(&n.map(BigInt::from), &h.x);
    let d0 = -floor_div(&(num * 2 + &h.w), &(&h.w * 2));
    Plane::new(n, (d0 + delta).to_i128()?)
}

/// Every classification path of an implicit point against `plane` agrees
/// with the oracle; the filter may abstain but never err.
pub(crate) fn check_implicit(
    imp: &Implicit,
    x: &HPoint,
    plane: &Plane,
) -> Result<bool, TestCaseError> {
    let expect = OPlane::of(plane).side_h(x);
    let filtered = imp.classify_filtered(plane);
    if let Some(s) = filtered {
        prop_assert_eq!(s, expect, "filter is wrong for {:?} at {:?}", plane, imp);
    }
    prop_assert_eq!(imp.classify_exact(plane), expect, "exact path, {:?}", plane);
    prop_assert_eq!(imp.classify(plane), expect);
    prop_assert_eq!(imp.classify(&plane.flip()), opposite(expect));
    Ok(filtered.is_some())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1024))]

    /// `Plane::through` is the oracle's `(b - a) × (c - a)` plane reduced by
    /// its gcd, with the same orientation; collinear points give `None`.
    #[test]
    fn plane_through_is_the_reduced_oracle_plane(t in triangle(), s in -3i64..=3) {
        let p = Plane::through(t[0], t[1], t[2]).expect("not collinear");
        let o = OPlane::through_grid(t[0], t[1], t[2]).expect("not collinear");
        prop_assert_eq!(OPlane::of(&p), o.reduced());
        prop_assert_eq!(OPlane::of(&p.flip()), o.flip().reduced());
        prop_assert!(p.is_coincident(&p.flip()) && !p.same_direction(&p.flip()));
        for v in t {
            prop_assert_eq!(p.classify_grid(v), Side::On);
        }
        // a third point on the line through the first two
        let c = [0, 1, 2].map(|k| t[0][k] as i64 + s * (t[1][k] as i64 - t[0][k] as i64));
        if let Some(c) = crate::strategies::to_grid(c) {
            prop_assert!(Plane::through(t[0], t[1], c).is_err());
        }
    }

    /// `Plane::new` on arbitrary coefficients (including `i64::MIN` and
    /// `i128::MIN`): the gcd-reduced plane when its normal is non-zero and
    /// it fits the budget, `None` otherwise, never a panic.
    #[test]
    fn plane_new_reduces_and_enforces_the_budget(
        n in [any::<i64>(), any::<i64>(), any::<i64>()],
        d in any::<i128>(),
        shift in 0u32..60,
        pick in 0u8..4,
    ) {
        // also coefficients sharing a large power of two, so that they only
        // fit after reduction
        let (n, d) = match pick {
            0 => (n, d),
            1 => (n.map(|c| (c >> 40) << shift.min(23)), (d >> 90) << shift),
            2 => (n.map(|c| c >> 9), d >> 45),
            _ => ([n[0], 0, 0], 0),
        };
        let got = Plane::new(n, d);
        let raw = OPlane { n: n.map(BigInt::from), d: BigInt::from(d) };
        if n == [0, 0, 0] {
            prop_assert!(got.is_none());
        } else {
            let r = raw.reduced();
            let fits = r.n.iter().all(|c| c.abs() < BigInt::one() << 55usize)
                && r.d.abs() < BigInt::one() << 83usize;
            prop_assert_eq!(got.is_some(), fits, "{:?} {}", n, d);
            if let Some(p) = got {
                prop_assert_eq!(OPlane::of(&p), r);
            }
        }
    }

    /// `classify_grid` and `Point::Grid::classify` on points exactly on the
    /// plane, 1..3 steps off, random, and with the plane moved by one unit
    /// (true values exactly ±1 at the on-plane points).
    #[test]
    fn grid_classification_matches_oracle(
        case in plane_case(),
        others in vec(any_point(), 0..4),
        raw in plane(),
    ) {
        let p = Plane::through(case.tri[0], case.tri[1], case.tri[2]).expect("not collinear");
        let o = OPlane::of(&p);
        for &g in &case.on {
            prop_assert_eq!(o.side_z(&grid_z(g)), Side::On, "generator: {:?} off the plane", g);
            prop_assert_eq!(p.classify_grid(g), Side::On);
            prop_assert_eq!(Point::Grid(g).classify(&p), Side::On);
            for delta in [-1i128, 1] {
                let moved = Plane::new(p.normal(), p.offset() + delta).expect("in budget");
                let expect = side_of(&BigInt::from(delta));
                prop_assert_eq!(OPlane::of(&moved).side_z(&grid_z(g)), expect);
                prop_assert_eq!(moved.classify_grid(g), expect);
            }
        }
        for &g in case.near.iter().chain(&others) {
            let expect = o.side_z(&grid_z(g));
            prop_assert_eq!(p.classify_grid(g), expect, "{:?} vs {:?}", g, p);
            prop_assert_eq!(p.flip().classify_grid(g), opposite(expect));
            prop_assert_eq!(Point::Grid(g).classify(&p), expect);
            prop_assert_eq!(raw.classify_grid(g), OPlane::of(&raw).side_z(&grid_z(g)));
        }
    }

    /// `classify_viewpoint` anywhere up to the viewpoint limit.
    #[test]
    fn viewpoint_classification_matches_oracle(
        p in plane(),
        v in vec(prop_oneof![
            Just(MAX_VIEW_COORD), Just(-MAX_VIEW_COORD), -MAX_VIEW_COORD..=MAX_VIEW_COORD, -9i64..=9
        ], 3),
        g in any_point(),
    ) {
        let o = OPlane::of(&p);
        let vp = ViewPoint::new([v[0], v[1], v[2]]).expect("in range");
        let expect = side_of(&o.eval_h(&vp.coords().map(BigInt::from), &BigInt::one()));
        prop_assert_eq!(p.classify_viewpoint(vp), expect);
        let gp = ViewPoint::from(g);
        prop_assert_eq!(p.classify_viewpoint(gp), p.classify_grid(g));
    }

    /// `Point::from_planes` is the Cramer solution (`None` exactly when the
    /// normals are dependent), lies on its three planes, and its `f64`
    /// coordinates are correctly rounded.
    #[test]
    fn implicit_points_are_cramer_solutions(planes in plane_triple()) {
        let o = planes.map(|p| OPlane::of(&p));
        let kernel = Point::from_planes(&planes[0], &planes[1], &planes[2]);
        let exact = meet3(&o[0], &o[1], &o[2]);
        match (kernel, exact) {
            (None, None) => {}
            (Some(p), Some(x)) => {
                prop_assert_eq!(&point_q(&p), &x);
                for pl in &planes {
                    prop_assert_eq!(p.classify(pl), Side::On);
                }
                let f = p.to_f64();
                for k in 0..3 {
                    if let Err(e) = check_correctly_rounded(f[k], &x[k]) {
                        return Err(TestCaseError::fail(format!("coordinate {k}: {e}")));
                    }
                }
                let as_grid = x.iter().all(|c| c.is_integer()
                    && c.abs() <= crate::oracle::q(bsp_core::MAX_COORD));
                prop_assert_eq!(p.as_grid().is_some(), as_grid);
                if let Some(g) = p.as_grid() {
                    prop_assert_eq!(&grid_q(g), &x);
                }
            }
            (k, e) => prop_assert!(false, "kernel {:?}, oracle {:?}", k, e),
        }
    }

    /// Implicit points against random planes, planes through them (true
    /// value 0), the same moved by one unit (true value exactly ±w), and
    /// planes through the nearest integer offset (value a rounding error
    /// of the terms): the filter never disagrees when it answers, the
    /// exact path always agrees.
    #[test]
    fn implicit_classification_matches_oracle(
        planes in plane_triple(),
        others in vec(plane(), 1..4),
        combos in vec((weights(), -1i128..=1), 1..4),
        normals in vec((normal(), -1i64..=1), 1..4),
    ) {
        let imp = Implicit::from_planes(&planes[0], &planes[1], &planes[2]);
        prop_assume!(imp.is_some(), "parallel planes");
        let imp = imp.expect("assumed");
        let o = planes.map(|p| OPlane::of(&p));
        let x = HPoint::from_q(&meet3(&o[0], &o[1], &o[2]).expect("oracle agrees it exists"));
        for pl in others.iter().chain(&planes) {
            check_implicit(&imp, &x, pl)?;
        }
        for (w, delta) in combos {
            let Some((n, d)) = combine_raw(&planes, w) else { continue };
            let Some(pl) = Plane::new(n, d + delta) else { continue };
            let expect = side_of(&BigInt::from(delta));
            prop_assert_eq!(OPlane::of(&pl).side_h(&x), expect);
            check_implicit(&imp, &x, &pl)?;
            if delta == 0 {
                prop_assert_eq!(imp.classify_filtered(&pl), None, "the filter certified a zero");
            }
        }
        for (n, delta) in normals {
            if let Some(pl) = nearest_plane(n, &x, delta) {
                check_implicit(&imp, &x, &pl)?;
            }
        }
    }

    /// Equal points built from different plane triples are `same_point`
    /// and give bitwise-equal `f64` coordinates.
    #[test]
    fn equal_points_round_identically(planes in plane_triple(), w in [weights(), weights(), weights()]) {
        let p = Point::from_planes(&planes[0], &planes[1], &planes[2]);
        let combos = [0, 1, 2].map(|i| combine(&planes, w[i]));
        prop_assume!(p.is_some() && combos.iter().all(Option::is_some), "parallel or over budget");
        let [a, b, c] = combos.map(|x| x.expect("assumed"));
        let p = p.expect("assumed");
        let p2 = Point::from_planes(&a, &b, &c);
        prop_assume!(p2.is_some(), "dependent combinations");
        let p2 = p2.expect("assumed");
        prop_assert!(p.same_point(&p2) && p2.same_point(&p));
        prop_assert_eq!(point_q(&p), point_q(&p2));
        prop_assert_eq!(p.to_f64().map(f64::to_bits), p2.to_f64().map(f64::to_bits));
        prop_assert_eq!(p.as_grid(), p2.as_grid());
    }

    /// A grid point rebuilt as the meet of three planes through it is
    /// recognised as that grid point and rounds to its coordinates.
    #[test]
    fn implicit_grid_points_are_recognised(g in any_point(), ts in [triangle(), triangle(), triangle()]) {
        let through_g = |t: &[GridPoint; 3]| {
            let n = Plane::through(t[0], t[1], t[2]).ok()?.normal();
            let d = -(0..3).map(|k| n[k] as i128 * g[k] as i128).sum::<i128>();
            Plane::new(n, d)
        };
        let (Some(a), Some(b), Some(c)) = (through_g(&ts[0]), through_g(&ts[1]), through_g(&ts[2]))
        else {
            unreachable!("planes through a grid point parallel to grid planes fit the budget")
        };
        let p = Point::from_planes(&a, &b, &c);
        prop_assume!(p.is_some(), "dependent normals");
        let p = p.expect("assumed");
        prop_assert_eq!(p.as_grid(), Some(g));
        prop_assert!(p.same_point(&Point::Grid(g)));
        prop_assert_eq!(p.to_f64(), g.map(f64::from));
        prop_assert_eq!(point_q(&p), grid_q(g));
    }

    /// `same_point` against exact rational equality, for unrelated points.
    #[test]
    fn same_point_matches_oracle(a in plane_triple(), b in plane_triple(), g in any_point()) {
        let pa = Point::from_planes(&a[0], &a[1], &a[2]);
        let pb = Point::from_planes(&b[0], &b[1], &b[2]);
        let all: Vec<Point> = [pa, pb, Some(Point::Grid(g))].into_iter().flatten().collect();
        for p in &all {
            for r in &all {
                prop_assert_eq!(p.same_point(r), point_q(p) == point_q(r));
            }
        }
    }

    /// `Polygon::classify` is decided by the oracle's vertex signs, for
    /// grid polygons and for split pieces with implicit vertices.
    #[test]
    fn polygon_classification_matches_vertex_signs(case in convex_polygon(), cuts in vec(cut(), 1..6)) {
        let poly = Polygon::from_grid_points(&case.input, 0).expect("convex input");
        let mut polys = vec![poly.clone()];
        let planes: Vec<Plane> = cuts.iter().filter_map(|c| make_cut(c, &case.hull)).collect();
        if let Some(first) = planes.first()
            && let bsp_core::Split::Spanning { front, back } = poly.clone().split(first)
        {
            polys.extend([front, back]);
        }
        for p in &polys {
            let v: Vec<Q3> = p.vertices().iter().map(point_q).collect();
            for pl in planes.iter().chain([*p.support(), p.support().flip()].iter()) {
                prop_assert_eq!(p.classify(pl), polygon_side(&v, &OPlane::of(pl)), "{:?}", pl);
            }
            prop_assert_eq!(p.classify(p.support()), PolygonSide::Coplanar { same_orientation: true });
        }
    }
}

/// Coordinates that are exact ties between two `f64`s round to even;
/// their neighbours round to nearest. The points are meets of axis
/// planes, so their coordinates are `-d / n`, chosen around half-ulp
/// multiples of large powers of two.
#[test]
fn to_f64_ties_go_to_even() {
    let mut ties = 0;
    for b in [53u32, 60, 79] {
        let base = 1i128 << b;
        let half_ulp = 1i128 << (b - 53);
        for k in -3i128..=3 {
            for j in -1i128..=1 {
                for den in [1i64, 2, 3, 4, 8] {
                    let num = base * den as i128 + k * half_ulp + j;
                    let y = Plane::new([0, 1, 0], -7).expect("in budget");
                    let z = Plane::new([0, 0, 3], -(base + 1)).expect("in budget");
                    for sign in [1, -1] {
                        let x = Plane::new([den, 0, 0], -sign * num).expect("in budget");
                        let p = Point::from_planes(&x, &y, &z).expect("axis planes meet");
                        let e = point_q(&p);
                        let f = p.to_f64();
                        for k in 0..3 {
                            ties += check_correctly_rounded(f[k], &e[k]).unwrap() as usize;
                        }
                        let neg = Plane::new([den, 0, 0], sign * num).expect("in budget");
                        let q = Point::from_planes(&neg, &y, &z).expect("axis planes meet");
                        assert_eq!(q.to_f64()[0], -f[0]);
                    }
                }
            }
        }
    }
    assert!(ties > 0, "the set must contain exact ties");
}

/// The three ways to be exactly on a plane — grid point, implicit point
/// with integer coordinates, implicit point with fractional ones — and one
/// unit either side, by hand-picked coefficients at the budget's edge.
#[test]
fn exact_zero_and_unit_values_at_the_budget_edge() {
    let big_n = (1i64 << 55) - 1;
    let a = Plane::new([big_n, big_n - 2, 1], -((1i128 << 83) - 1)).expect("in budget");
    let b = Plane::new([-(big_n - 4), -(big_n - 7), 3], (1i128 << 82) + 12345).expect("in budget");
    let c = Plane::new([5, -big_n, big_n - 8], -(1i128 << 81)).expect("in budget");
    let p = Implicit::from_planes(&a, &b, &c).expect("independent normals");
    let o = [a, b, c].map(|x| OPlane::of(&x));
    let x = HPoint::from_q(&meet3(&o[0], &o[1], &o[2]).expect("meet"));
    let mut zero_seen = 0;
    for w in [[1, 1, 0], [1, -1, 0], [0, 1, -1], [1, 0, 1]] {
        let (n, d) = combine_raw(&[a, b, c], w).expect("fits i64 / i128");
        for delta in [-1i128, 0, 1] {
            let Some(pl) = Plane::new(n, d + delta) else {
                continue;
            };
            let expect = side_of(&BigInt::from(delta));
            assert_eq!(OPlane::of(&pl).side_h(&x), expect);
            assert_eq!(p.classify_exact(&pl), expect);
            assert_eq!(p.classify(&pl), expect);
            if delta == 0 {
                assert_eq!(p.classify_filtered(&pl), None);
                zero_seen += 1;
            }
        }
    }
    assert!(zero_seen > 0, "no combination fitted the budget");
    // the value of `nearest_plane` is at most w / 2 + w: far below the terms
    for n in [[big_n, 1, -big_n], [1, 1, 1], [big_n, big_n, big_n]] {
        for delta in -1..=1 {
            if let Some(pl) = nearest_plane(n, &x, delta) {
                let v = OPlane::of(&pl).eval_h(&x.x, &x.w);
                assert!(v.abs() <= &x.w * 2, "value {v} larger than expected");
                assert_eq!(p.classify(&pl), side_of(&v));
                assert_eq!(p.classify_exact(&pl), side_of(&v));
            }
        }
    }
}
