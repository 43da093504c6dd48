//! Polygon construction and splitting against the oracle: pieces are
//! valid, strictly convex, on the right side, share exactly the two cut
//! vertices and cover the original exactly (rational area vectors).

use bsp_core::{FaceDefect, GridPoint, Plane, Point, Polygon, PolygonSide, Side, Split};
use num_traits::{Signed, Zero};
use proptest::collection::vec;
use proptest::prelude::*;

use crate::classify::check_implicit;
use crate::oracle::{
    HPoint, OPlane, Q, Q3, add3, area_vector, cross3, dot3, grid_q, is_strictly_convex, point_q,
    polygon_side,
};
use crate::strategies::{PolyCase, convex_polygon, cut, make_cut, wide};

/// The exact vertices of a polygon.
pub(crate) fn poly_q(p: &Polygon) -> Vec<Q3> {
    p.vertices().iter().map(point_q).collect()
}

fn normal_q(p: &Plane) -> Q3 {
    p.normal().map(|c| Q::from_integer(c.into()))
}

fn same_vertices(a: &Polygon, b: &Polygon) -> bool {
    a.len() == b.len()
        && a.vertices()
            .iter()
            .zip(b.vertices())
            .all(|(x, y)| x.same_point(y))
}

/// Checks one split of `poly` (whose exact vertices are `v`) by `plane`
/// against the oracle, and returns the resulting pieces with their exact
/// vertices.
pub(crate) fn check_split(
    poly: &Polygon,
    v: &[Q3],
    plane: &Plane,
) -> Result<Vec<(Polygon, Vec<Q3>)>, TestCaseError> {
    let op = OPlane::of(plane);
    let expect = polygon_side(v, &op);
    let result = poly.clone().split(plane);
    let got = match &result {
        Split::Front(_) => PolygonSide::Front,
        Split::Back(_) => PolygonSide::Back,
        Split::Coplanar {
            same_orientation, ..
        } => PolygonSide::Coplanar {
            same_orientation: *same_orientation,
        },
        Split::Spanning { .. } => PolygonSide::Spanning,
    };
    prop_assert_eq!(got, expect, "split of {:?} by {:?}", poly, plane);
    match result {
        Split::Front(p) | Split::Back(p) | Split::Coplanar { polygon: p, .. } => {
            prop_assert!(same_vertices(&p, poly), "an unsplit polygon changed");
            prop_assert_eq!(p.tag(), poly.tag());
            Ok(vec![(p, v.to_vec())])
        }
        Split::Spanning { front, back } => {
            let n = normal_q(poly.support());
            let fv = poly_q(&front);
            let bv = poly_q(&back);
            for (piece, pv, side) in [(&front, &fv, Side::Front), (&back, &bv, Side::Back)] {
                if let Err(e) = piece.sanity_check() {
                    return Err(TestCaseError::fail(format!("{side:?} piece: {e}")));
                }
                if let Err(e) = is_strictly_convex(pv, &n) {
                    return Err(TestCaseError::fail(format!("{side:?} piece: {e}")));
                }
                prop_assert_eq!(piece.support(), poly.support());
                prop_assert_eq!(piece.tag(), poly.tag());
                for x in pv {
                    let s = op.side(x);
                    prop_assert!(
                        s == side || s == Side::On,
                        "{:?} piece has a {:?} vertex",
                        side,
                        s
                    );
                }
                // the vertices on the cut are exactly the two shared ones
                let on: Vec<&Point> = piece
                    .vertices()
                    .iter()
                    .zip(pv)
                    .filter(|(_, x)| op.side(x) == Side::On)
                    .map(|(p, _)| p)
                    .collect();
                prop_assert_eq!(
                    on.len(),
                    2,
                    "{:?} piece has {} vertices on the cut",
                    side,
                    on.len()
                );
            }
            let shared: Vec<&Point> = front
                .vertices()
                .iter()
                .filter(|p| back.vertices().iter().any(|q| q.same_point(p)))
                .collect();
            prop_assert_eq!(shared.len(), 2, "pieces share {} vertices", shared.len());
            for p in &shared {
                prop_assert_eq!(op.side(&point_q(p)), Side::On);
            }
            // original vertices go to their side's piece, both when on the cut
            for x in v {
                let in_front = fv.contains(x);
                let in_back = bv.contains(x);
                match op.side(x) {
                    Side::Front => prop_assert!(in_front && !in_back),
                    Side::Back => prop_assert!(in_back && !in_front),
                    Side::On => prop_assert!(in_front && in_back),
                }
            }
            // exact cover: the area vectors add up
            let total = add3(&area_vector(&fv), &area_vector(&bv));
            prop_assert_eq!(&total, &area_vector(v), "area changed");
            Ok(vec![(front, fv), (back, bv)])
        }
    }
}

/// The loop's hull as exact points, in the polygon's own vertex order
/// (a rotation of `hull`).
fn assert_is_rotation(poly: &Polygon, hull: &[GridPoint]) -> Result<(), TestCaseError> {
    let verts: Vec<GridPoint> = poly
        .vertices()
        .iter()
        .map(|p| match p {
            Point::Grid(g) => Ok(*g),
            Point::Implicit(_) => Err(TestCaseError::fail("implicit vertex in an input polygon")),
        })
        .collect::<Result<_, _>>()?;
    let k = hull.len();
    prop_assert_eq!(verts.len(), k, "{:?} vs hull {:?}", verts, hull);
    let start = hull.iter().position(|h| *h == verts[0]);
    prop_assert!(start.is_some());
    let s = start.expect("checked");
    for i in 0..k {
        prop_assert_eq!(verts[i], hull[(s + i) % k]);
    }
    Ok(())
}

fn check_construction(case: &PolyCase) -> Result<Polygon, TestCaseError> {
    let poly = match Polygon::from_grid_points(&case.input, 7) {
        Ok(p) => p,
        Err(e) => return Err(TestCaseError::fail(format!("{e}: {case:?}"))),
    };
    if let Err(e) = poly.sanity_check() {
        return Err(TestCaseError::fail(e.to_string()));
    }
    assert_is_rotation(&poly, &case.hull)?;
    let hq: Vec<Q3> = case.hull.iter().map(|g| grid_q(*g)).collect();
    let a = area_vector(&hq);
    // the support plane is the reduced plane of the hull, oriented by its winding
    let o = OPlane::through_grid(case.hull[0], case.hull[1], case.hull[2])
        .expect("hull vertices are not collinear")
        .reduced();
    let n = normal_q(poly.support());
    prop_assert!(cross3(&n, &a).iter().all(Zero::is_zero) && dot3(&n, &a).is_positive());
    prop_assert!(
        OPlane::of(poly.support()) == o || OPlane::of(poly.support()) == o.flip(),
        "support {:?} is not the hull's plane {:?}",
        poly.support(),
        o
    );
    if let Err(e) = is_strictly_convex(&hq, &n) {
        return Err(TestCaseError::fail(e.to_string()));
    }
    // edge plane i holds vertices i and i + 1 and has the rest strictly behind
    let k = hq.len();
    let vq = poly_q(&poly);
    for (i, e) in poly.edge_planes().iter().enumerate() {
        let oe = OPlane::of(e);
        for (j, x) in vq.iter().enumerate() {
            let want = if j == i || j == (i + 1) % k {
                Side::On
            } else {
                Side::Back
            };
            prop_assert_eq!(oe.side(x), want, "edge {} vertex {}", i, j);
        }
    }
    prop_assert_eq!(poly.tag(), 7);
    Ok(poly)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(192))]

    /// `from_grid_points` removes repeated and collinear vertices and
    /// yields the strictly convex hull loop, its plane and edge planes.
    #[test]
    fn polygon_from_grid_points_matches_oracle(case in convex_polygon()) {
        check_construction(&case)?;
    }

    /// Loops that are not one convex polygon are refused with the right
    /// defect: a vertex off the plane, two vertices swapped (self-crossing),
    /// fewer than three distinct vertices, all on one line.
    #[test]
    fn defective_loops_are_refused(case in convex_polygon(), e in [-3i64..=3, -3i64..=3, -3i64..=3], i in 0usize..16) {
        let h = &case.hull;
        let k = h.len();
        let o = OPlane::through_grid(h[0], h[1], h[2]).expect("not collinear");
        // a vertex moved off the plane
        let moved = crate::strategies::to_grid(crate::strategies::add(wide(h[i % k]), e));
        if let Some(m) = moved.filter(|m| k >= 4 && o.side(&grid_q(*m)) != Side::On) {
            let mut l = h.clone();
            l[i % k] = m;
            prop_assert_eq!(Polygon::from_grid_points(&l, 0).unwrap_err(), FaceDefect::NonPlanar);
        }
        // swapping two vertices of a polygon with four or more makes it cross itself
        if k >= 4 {
            let mut l = h.clone();
            l.swap(i % k, (i + 1) % k);
            let lq: Vec<Q3> = l.iter().map(|g| grid_q(*g)).collect();
            let want = if area_vector(&lq).iter().all(Zero::is_zero) {
                FaceDefect::ZeroArea
            } else {
                FaceDefect::NonConvex
            };
            prop_assert_eq!(Polygon::from_grid_points(&l, 0).unwrap_err(), want);
        }
        // a loop through one vertex twice, with two lobes, touches itself
        // (with one vertex between the visits it would be a zero-area
        // spike, which is removed)
        if k >= 5 {
            let mut l = h.clone();
            l.insert(3, h[0]);
            prop_assert_eq!(Polygon::from_grid_points(&l, 0).unwrap_err(), FaceDefect::NonConvex);
        }
        let two = [h[0], h[1], h[1], h[0]];
        prop_assert_eq!(Polygon::from_grid_points(&two, 0).unwrap_err(), FaceDefect::TooFewVertices);
        let line: Vec<GridPoint> = [h[0], h[1]]
            .iter()
            .chain(
                crate::strategies::to_grid(crate::strategies::add(wide(h[1]), crate::strategies::sub(wide(h[1]), wide(h[0])))).iter(),
            )
            .copied()
            .collect();
        if line.len() == 3 {
            prop_assert_eq!(Polygon::from_grid_points(&line, 0).unwrap_err(), FaceDefect::ZeroArea);
        }
    }

    /// One split by planes through random points, through vertices, a few
    /// units off vertices, or arbitrary, in both orientations.
    #[test]
    fn split_pieces_partition_the_polygon(case in convex_polygon(), cuts in vec(cut(), 1..5)) {
        let poly = check_construction(&case)?;
        let v = poly_q(&poly);
        for c in &cuts {
            let Some(plane) = make_cut(c, &case.hull) else { continue };
            check_split(&poly, &v, &plane)?;
            check_split(&poly, &v, &plane.flip())?;
        }
        check_split(&poly, &v, poly.support())?;
        check_split(&poly, &v, &poly.support().flip())?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(28))]

    /// Splitting every piece again, 5..20 times: every split keeps all
    /// invariants, and the pieces' area vectors always add up to the
    /// original's.
    #[test]
    fn repeated_splitting_keeps_invariants_and_area(case in convex_polygon(), cuts in vec(cut(), 5..=20)) {
        let poly = check_construction(&case)?;
        let v = poly_q(&poly);
        let area = area_vector(&v);
        let mut pieces = vec![(poly, v)];
        let mut spanning = 0;
        let mut planes = Vec::new();
        for c in &cuts {
            let Some(plane) = make_cut(c, &case.hull) else { continue };
            planes.push(plane);
            let mut next = Vec::with_capacity(pieces.len() * 2);
            for (p, pv) in &pieces {
                let out = check_split(p, pv, &plane)?;
                spanning += usize::from(out.len() == 2);
                next.extend(out);
            }
            pieces = next;
        }
        // every split was checked to keep its piece's area; the total too
        let sum = pieces
            .iter()
            .fold([Q::zero(), Q::zero(), Q::zero()], |s, (_, pv)| add3(&s, &area_vector(pv)));
        prop_assert_eq!(&sum, &area);
        prop_assert!(pieces.len() == spanning + 1);
        // the cut vertices against a share of the cutting planes (each one
        // is on two of them), filter and exact path
        let mut i = 0;
        for (p, pv) in &pieces {
            for (v, x) in p.vertices().iter().zip(pv) {
                if let Point::Implicit(imp) = v {
                    let h = HPoint::from_q(x);
                    i += 1;
                    for pl in planes.iter().skip(i % 3).step_by(3) {
                        check_implicit(imp, &h, pl)?;
                    }
                }
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// `flipped` reverses a polygon exactly and twice is the identity;
    /// `from_planes` rebuilds a polygon from its support and edge planes;
    /// for input polygons and for split pieces with implicit vertices.
    #[test]
    fn flipped_and_rebuilt_polygons(case in convex_polygon(), cuts in vec(cut(), 0..3)) {
        let poly = check_construction(&case)?;
        let mut polys = vec![poly.clone()];
        for c in &cuts {
            if let Some(plane) = make_cut(c, &case.hull)
                && let Split::Spanning { front, back } = poly.clone().split(&plane)
            {
                polys.extend([front, back]);
            }
        }
        for p in &polys {
            let pv = poly_q(p);
            let k = pv.len();
            let f = p.flipped();
            if let Err(e) = f.sanity_check() {
                return Err(TestCaseError::fail(format!("flipped: {e}")));
            }
            prop_assert_eq!(*f.support(), p.support().flip());
            prop_assert_eq!(f.tag(), p.tag());
            let fv = poly_q(&f);
            prop_assert_eq!(fv.len(), k);
            for j in 0..k {
                prop_assert_eq!(&fv[j], &pv[k - 1 - j]);
            }
            let a = area_vector(&pv);
            prop_assert_eq!(area_vector(&fv), a.clone().map(|c| -c));
            let back = f.flipped();
            prop_assert!(same_vertices(&back, p) && back.edge_planes() == p.edge_planes());
            prop_assert_eq!(back.support(), p.support());
            let rebuilt = Polygon::from_planes(*p.support(), p.edge_planes(), 9);
            prop_assert!(rebuilt.is_some());
            let rebuilt = rebuilt.expect("checked");
            prop_assert!(same_vertices(&rebuilt, p));
            prop_assert_eq!(rebuilt.tag(), 9);
            prop_assert_eq!(p.clone().with_tag(5).tag(), 5);
        }
    }
}
