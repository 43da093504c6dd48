//! `import_faces` on non-convex and non-planar faces: the polygons it
//! makes must tile each planar face exactly (checked in the face's own
//! integer 2D coordinates), keep its orientation, and use only its
//! vertices.

use std::collections::HashMap;

use bsp_core::internals::all_planar;
use bsp_core::{FaceDefect, Grid, GridPoint, Polygon, import_faces};
use glam::DVec3;
use proptest::collection::vec;
use proptest::prelude::*;

use crate::strategies::{L3, add, fit, mul, point, size_bits, wide};

type P2 = [i64; 2];

fn orient(a: P2, b: P2, c: P2) -> i128 {
    let d = |p: P2, q: P2| [q[0] as i128 - p[0] as i128, q[1] as i128 - p[1] as i128];
    let (u, v) = (d(a, b), d(a, c));
    u[0] * v[1] - u[1] * v[0]
}

/// Twice the signed area.
fn area2(l: &[P2]) -> i128 {
    (1..l.len().saturating_sub(1))
        .map(|i| orient(l[0], l[i], l[i + 1]))
        .sum()
}

/// Interiors of two counter-clockwise convex polygons are disjoint iff an
/// edge line of one has the other entirely on its closed outer side.
fn interiors_disjoint(a: &[P2], b: &[P2]) -> bool {
    let separates = |p: &[P2], q: &[P2]| {
        (0..p.len()).any(|i| {
            let (s, e) = (p[i], p[(i + 1) % p.len()]);
            q.iter().all(|&x| orient(s, e, x) <= 0)
        })
    };
    separates(a, b) || separates(b, a)
}

fn properly_cross(a: P2, b: P2, c: P2, d: P2) -> bool {
    let s = |x: i128| x.signum();
    s(orient(a, b, c)) * s(orient(a, b, d)) < 0 && s(orient(c, d, a)) * s(orient(c, d, b)) < 0
}

/// Winding number of `p` about the loop (half-open crossing rule); `None`
/// if `p` is on the loop.
fn winding(l: &[P2], p: P2) -> Option<i32> {
    let mut w = 0;
    for i in 0..l.len() {
        let (a, b) = (l[i], l[(i + 1) % l.len()]);
        let o = orient(a, b, p);
        let within = |k: usize| a[k].min(b[k]) <= p[k] && p[k] <= a[k].max(b[k]);
        if o == 0 && within(0) && within(1) {
            return None;
        }
        if a[1] <= p[1] && p[1] < b[1] && o > 0 {
            w += 1;
        } else if b[1] <= p[1] && p[1] < a[1] && o < 0 {
            w -= 1;
        }
    }
    Some(w)
}

/// `true` if the convex polygon `t` (counter-clockwise, vertices among
/// the simple loop `l`'s) lies inside `l`: no edge of `t` properly crosses
/// an edge of `l`, no vertex of `l` is strictly inside `t`, and `t`'s
/// centroid is inside `l`.
fn inside(t: &[P2], l: &[P2]) -> bool {
    for i in 0..t.len() {
        let (a, b) = (t[i], t[(i + 1) % t.len()]);
        for j in 0..l.len() {
            if properly_cross(a, b, l[j], l[(j + 1) % l.len()]) {
                return false;
            }
        }
    }
    let strictly_in = |x: P2| (0..t.len()).all(|i| orient(t[i], t[(i + 1) % t.len()], x) > 0);
    if l.iter().any(|&x| strictly_in(x)) {
        return false;
    }
    let k = t.len() as i64;
    let c = t.iter().fold([0, 0], |s, p| [s[0] + p[0], s[1] + p[1]]);
    let scaled: Vec<P2> = l.iter().map(|p| [p[0] * k, p[1] * k]).collect();
    winding(&scaled, c) == Some(1)
}

/// A star-shaped simple loop around the origin of the `(s, t)` plane:
/// points sorted by angle with every turn about the origin less than a
/// half-turn (so the origin is strictly inside); often non-convex, with
/// collinear vertices on small coordinates.
fn star_loop() -> BoxedStrategy<Vec<P2>> {
    prop_oneof![Just(3i64), Just(6), Just(40), Just(1000)]
        .prop_flat_map(|r| vec([-r..=r, -r..=r], 4..14))
        .prop_filter_map("not star-shaped", |pts| {
            let mut pts: Vec<P2> = pts.into_iter().filter(|p| *p != [0, 0]).collect();
            let half = |p: &P2| !(p[1] > 0 || (p[1] == 0 && p[0] > 0));
            pts.sort_by(|a, b| {
                half(a)
                    .cmp(&half(b))
                    .then_with(|| 0.cmp(&orient([0, 0], *a, *b)))
            });
            pts.dedup_by(|a, b| orient([0, 0], *a, *b) == 0 && half(a) == half(b));
            let k = pts.len();
            (k >= 3 && (0..k).all(|i| orient([0, 0], pts[i], pts[(i + 1) % k]) > 0)).then_some(pts)
        })
        .boxed()
}

/// The boundary of a random polyomino (cells grown from one, rejected if
/// it has holes or cells touching only at a corner): a simple rectilinear
/// loop, very non-convex; with `all_points`, every lattice point of the
/// boundary is a vertex (runs of collinear vertices).
fn polyomino_loop() -> BoxedStrategy<Vec<P2>> {
    (vec((0usize..64, 0u8..4), 1..30), any::<bool>())
        .prop_filter_map("holes or pinches", |(steps, all_points)| {
            let mut cells: Vec<P2> = vec![[0, 0]];
            for (i, d) in steps {
                let c = cells[i % cells.len()];
                let n = match d {
                    0 => [c[0] + 1, c[1]],
                    1 => [c[0] - 1, c[1]],
                    2 => [c[0], c[1] + 1],
                    _ => [c[0], c[1] - 1],
                };
                if !cells.contains(&n) {
                    cells.push(n);
                }
            }
            // counter-clockwise unit edges of every cell; shared ones cancel
            let mut edges: HashMap<P2, Vec<P2>> = HashMap::new();
            let mut count = 0;
            for c in &cells {
                let q = [
                    c,
                    &[c[0] + 1, c[1]],
                    &[c[0] + 1, c[1] + 1],
                    &[c[0], c[1] + 1],
                ];
                for i in 0..4 {
                    let (a, b) = (*q[i], *q[(i + 1) % 4]);
                    let back = edges
                        .get_mut(&b)
                        .and_then(|v| v.iter().position(|x| *x == a).map(|j| v.remove(j)));
                    if back.is_some() {
                        count -= 1;
                    } else {
                        edges.entry(a).or_default().push(b);
                        count += 1;
                    }
                }
            }
            if edges.values().any(|v| v.len() > 1) {
                return None;
            }
            let start = *edges.iter().find(|(_, v)| !v.is_empty())?.0;
            let mut l = vec![start];
            let mut at = edges[&start][0];
            while at != start {
                l.push(at);
                at = edges[&at][0];
            }
            if l.len() != count {
                return None;
            }
            if !all_points {
                let k = l.len();
                l = (0..k)
                    .filter(|&i| orient(l[(i + k - 1) % k], l[i], l[(i + 1) % k]) != 0)
                    .map(|i| l[i])
                    .collect();
            }
            Some(l)
        })
        .boxed()
}

/// A star or polyomino loop placed in 3D as `a + s u + t v`, in the grid.
fn placed_loop() -> BoxedStrategy<(Vec<P2>, Vec<GridPoint>)> {
    let loops = prop_oneof![star_loop(), polyomino_loop()];
    (
        loops,
        size_bits().prop_flat_map(point),
        [point(4), point(4)],
    )
        .prop_filter_map("degenerate placement", |(l, a, [u, v])| {
            let (a, u, v) = (wide(a), wide(u), wide(v));
            if crate::strategies::cross(u, v) == [0, 0, 0] {
                return None;
            }
            let pts: Vec<L3> = l
                .iter()
                .map(|p| add(a, add(mul(u, p[0]), mul(v, p[1]))))
                .collect();
            Some((l, fit(&pts)?))
        })
        .boxed()
}

fn as_f64(l: &[GridPoint]) -> Vec<DVec3> {
    l.iter()
        .map(|g| DVec3::new(g[0] as f64, g[1] as f64, g[2] as f64))
        .collect()
}

/// The identity grid: grid coordinates are the input coordinates.
fn unit_grid() -> Grid {
    Grid::new(DVec3::ZERO, 0).expect("valid grid")
}

/// Checks that `polys` tile the planar simple loop `l2` (2D coordinates
/// of the 3D loop `l3`) exactly.
fn check_tiling(polys: &[Polygon], l2: &[P2], l3: &[GridPoint]) -> Result<(), TestCaseError> {
    let to2: HashMap<GridPoint, P2> = l3.iter().copied().zip(l2.iter().copied()).collect();
    let orientation = area2(l2).signum();
    let mut pieces: Vec<Vec<P2>> = Vec::new();
    for p in polys {
        if let Err(e) = p.sanity_check() {
            return Err(TestCaseError::fail(e.to_string()));
        }
        let mut v = Vec::new();
        for x in p.vertices() {
            let g = x.as_grid().expect("import makes grid vertices only");
            let q = to2.get(&g);
            prop_assert!(q.is_some(), "vertex {:?} is not an input vertex", g);
            v.push(*q.expect("checked"));
        }
        prop_assert_eq!(
            area2(&v).signum(),
            orientation,
            "a piece is flipped: {:?}",
            v
        );
        if orientation < 0 {
            v.reverse();
        }
        pieces.push(v);
    }
    let mut l = l2.to_vec();
    if orientation < 0 {
        l.reverse();
    }
    let total: i128 = pieces.iter().map(|v| area2(v)).sum();
    prop_assert_eq!(total, area2(&l), "areas do not add up");
    for (i, a) in pieces.iter().enumerate() {
        prop_assert!(inside(a, &l), "piece {:?} is not inside {:?}", a, l);
        for b in &pieces[i + 1..] {
            prop_assert!(
                interiors_disjoint(a, b),
                "pieces {:?} and {:?} overlap",
                a,
                b
            );
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    /// Star-shaped and polyomino (often non-convex, often with collinear
    /// vertices) planar faces: one polygon when convex, otherwise ear-clipped triangles that
    /// tile the face exactly with its orientation; nothing dropped.
    #[test]
    fn non_convex_faces_are_tiled_exactly((l2, l3) in placed_loop(), reverse in any::<bool>()) {
        let (mut l2, mut l3) = (l2, l3);
        if reverse {
            l2.reverse();
            l3.reverse();
        }
        let f = as_f64(&l3);
        let (polys, report) = import_faces(&unit_grid(), [&f[..]]).expect("in range");
        prop_assert!(report.dropped.is_empty(), "{}", report.summary());
        prop_assert!(all_planar(&polys));
        match Polygon::from_grid_points(&l3, 0) {
            Ok(_) => prop_assert!(polys.len() == 1 && report.triangulated.is_empty()),
            Err(e) => {
                prop_assert_eq!(e, FaceDefect::NonConvex);
                prop_assert_eq!(&report.triangulated, &vec![(0, FaceDefect::NonConvex)]);
            }
        }
        check_tiling(&polys, &l2, &l3)?;
    }

    /// A planar loop with one vertex lifted off its plane is fanned into
    /// triangles of its own vertices, each a valid polygon.
    #[test]
    fn non_planar_faces_are_fanned((_, l3) in placed_loop(), lift in 1i64..4, i in 0usize..16) {
        let mut l3 = l3;
        let k = l3.len();
        prop_assume!(k >= 4, "a triangle stays planar");
        // the loop's normal from its first non-collinear corners (the first
        // three may be collinear: lifting along an axis the normal lacks
        // would keep the loop planar)
        let n = (1..k)
            .flat_map(|a| (a + 1..k).map(move |b| (a, b)))
            .map(|(a, b)| {
                crate::strategies::cross(
                    crate::strategies::sub(wide(l3[a]), wide(l3[0])),
                    crate::strategies::sub(wide(l3[b]), wide(l3[0])),
                )
            })
            .find(|n| n.iter().any(|&c| c != 0))
            .expect("a placed loop has an area");
        let axis = (0..3).max_by_key(|&a| n[a].abs()).expect("3 axes");
        let mut moved = wide(l3[i % k]);
        moved[axis] += if moved[axis] > 0 { -lift } else { lift };
        l3[i % k] = crate::strategies::to_grid(moved).expect("moved towards 0");
        let f = as_f64(&l3);
        let (polys, report) = import_faces(&unit_grid(), [&f[..]]).expect("in range");
        prop_assert!(all_planar(&polys));
        prop_assert!(polys.len() <= k - 2);
        let planar = {
            let p = crate::tree::loop_plane(&l3);
            l3.iter().all(|g| p.side_z(&crate::oracle::grid_z(*g)) == bsp_core::Side::On)
        };
        if !planar && !polys.is_empty() {
            prop_assert_eq!(&report.triangulated, &vec![(0, FaceDefect::NonPlanar)]);
        }
        for p in &polys {
            if let Err(e) = p.sanity_check() {
                return Err(TestCaseError::fail(e.to_string()));
            }
            prop_assert_eq!(p.len(), 3);
            for v in p.vertices() {
                prop_assert!(l3.contains(&v.as_grid().expect("grid vertex")));
            }
        }
    }
}

/// An L-shaped face with collinear vertices on its long edges is ear
/// clipped into a tiling (the collinear vertices can never be ears).
#[test]
fn l_shape_with_collinear_vertices_is_tiled() {
    let l2: Vec<P2> = vec![
        [0, 0],
        [2, 0],
        [4, 0],
        [4, 2],
        [2, 2],
        [2, 4],
        [2, 6],
        [0, 6],
        [0, 3],
    ];
    let l3: Vec<GridPoint> = l2.iter().map(|p| [p[0] as i32, p[1] as i32, 5]).collect();
    let f = as_f64(&l3);
    let (polys, report) = import_faces(&unit_grid(), [&f[..]]).unwrap();
    assert!(report.dropped.is_empty());
    check_tiling(&polys, &l2, &l3).unwrap();
}
