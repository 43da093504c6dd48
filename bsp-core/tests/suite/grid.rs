//! Snapping `f64` input to the grid: inputs a few ulps apart, boxes of
//! every scale and position, checked against exact rationals; and faces
//! whose vertices are a few ulps off a plane, through `import_faces`.

use bsp_core::internals::all_planar;
use bsp_core::{FaceDefect, Grid, GridPoint, MAX_COORD, import_faces};
use glam::DVec3;
use num_rational::BigRational;
use num_traits::{One, Signed, Zero};
use proptest::collection::vec;
use proptest::prelude::*;

use crate::oracle::{Q, Q3, area_vector, f64_q, grid_q, grid_z};
use crate::tree::loop_plane;

/// `x` moved by `n` ulps.
fn ulps(x: f64, n: i32) -> f64 {
    let mut y = x;
    for _ in 0..n.unsigned_abs() {
        y = if n > 0 { y.next_up() } else { y.next_down() };
    }
    y
}

/// A finite `f64` of magnitude around `2^e`.
fn float_around(e: i32, m: f64) -> f64 {
    m * 2f64.powi(e)
}

/// A box `[c - h, c + h]` of any scale and position.
fn a_box() -> BoxedStrategy<(DVec3, DVec3)> {
    (
        [-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0],
        -40i32..40,
        0.01f64..1.0,
        -30i32..30,
    )
        .prop_map(|(c, ce, h, he)| {
            let c = DVec3::from_array(c.map(|x| float_around(ce, x)));
            let h = DVec3::splat(float_around(he, h));
            (c - h, c + h)
        })
        .boxed()
}

/// `(x - origin) * scale`, exactly.
fn exact_grid_coord(grid: &Grid, x: f64, k: usize) -> Q {
    (f64_q(x) - f64_q(grid.origin().to_array()[k])) * f64_q(grid.scale())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    /// Points of a fitted box and their neighbours a few ulps away snap to
    /// a grid point at most half a step from the exact scaled coordinate,
    /// monotonically, within the grid.
    #[test]
    fn snapping_is_nearest_and_monotone(
        (lo, hi) in a_box(),
        f in vec([0.0f64..=1.0, 0.0f64..=1.0, 0.0f64..=1.0], 1..6),
        steps in vec(-4i32..=4, 1..6),
    ) {
        let grid = Grid::fit(lo, hi).expect("finite box");
        prop_assert_eq!(grid.scale().log2().fract(), 0.0);
        // the finest grid on which the box takes at most half the range
        let half_box = ((hi - lo) * 0.5).abs().max_element();
        let half_range = MAX_COORD as f64 * 0.5;
        prop_assert!(half_box * grid.scale() <= half_range);
        prop_assert!(
            half_box == 0.0 || half_box * grid.scale() * 2.0 > half_range || grid.scale() == 2f64.powi(1000)
        );
        let half = BigRational::new(1.into(), 2.into());
        for fr in f {
            let base = lo + (hi - lo) * DVec3::from_array(fr);
            let base = base.clamp(lo, hi);
            let mut prev: Option<(DVec3, GridPoint)> = None;
            let mut pts: Vec<DVec3> = steps
                .iter()
                .map(|&n| DVec3::from_array(base.to_array().map(|x| ulps(x, n))))
                .collect();
            pts.push(base);
            pts.sort_by(|a, b| a.x.total_cmp(&b.x));
            for p in pts {
                let Ok(g) = grid.snap(p) else {
                    // only points pushed out of the box by the ulps may fail
                    prop_assert!(p.cmplt(lo).any() || p.cmpgt(hi).any(), "{:?} in the box", p);
                    continue;
                };
                prop_assert!(g.iter().all(|c| c.abs() <= MAX_COORD));
                for (k, &gk) in g.iter().enumerate() {
                    let e = exact_grid_coord(&grid, p.to_array()[k], k);
                    let d = (e.clone() - Q::from_integer(gk.into())).abs();
                    prop_assert!(d <= half, "axis {}: {} snapped to {} ({:?})", k, e, gk, grid);
                    if let Some((q, h)) = prev
                        && p.to_array()[k] >= q.to_array()[k]
                    {
                        prop_assert!(gk >= h[k]);
                    }
                }
                prev = Some((p, g));
            }
        }
    }

    /// The same for grids made by `Grid::new`, whose origin need not lie
    /// on a grid point of its own scale.
    #[test]
    fn snapping_with_any_grid_is_nearest(
        origin in [-1e6f64..1e6, -1e6f64..1e6, -1e6f64..1e6],
        log2_scale in -8i32..=8,
        p in [-1e6f64..1e6, -1e6f64..1e6, -1e6f64..1e6],
        steps in -4i32..=4,
    ) {
        let grid = Grid::new(DVec3::from_array(origin), log2_scale).expect("valid grid");
        let half = BigRational::new(1.into(), 2.into());
        for x in [p, p.map(|c| ulps(c, steps))] {
            let Ok(g) = grid.snap(DVec3::from_array(x)) else { continue };
            for (k, &gk) in g.iter().enumerate() {
                let e = exact_grid_coord(&grid, x[k], k);
                let d = (e.clone() - Q::from_integer(gk.into())).abs();
                prop_assert!(d <= half, "axis {}: {} snapped to {} ({:?})", k, e, gk, grid);
            }
        }
    }

    /// A vertex that cannot be snapped (NaN, infinite, outside the grid)
    /// makes `import_faces` fail naming the first such face and vertex.
    #[test]
    fn unsnappable_vertices_are_named(
        faces in vec(proptest::array::uniform3([-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0]), 1..6),
        bad in vec((0usize..6, 0usize..3, 0usize..3), 1..3),
    ) {
        let grid = Grid::fit(DVec3::splat(-1.0), DVec3::splat(1.0)).expect("unit box");
        let mut faces: Vec<Vec<DVec3>> = faces
            .iter()
            .map(|f| f.iter().map(|p| DVec3::from_array(*p)).collect())
            .collect();
        let values = [f64::NAN, f64::INFINITY, 1e9];
        let mut first: Option<(usize, usize)> = None;
        for &(f, v, which) in &bad {
            let f = f % faces.len();
            faces[f][v].y = values[which];
            first = Some(first.map_or((f, v), |b| b.min((f, v))));
        }
        let (f, v) = first.expect("at least one bad vertex");
        let reason = if faces[f][v].y.is_finite() {
            bsp_core::SnapError::OutOfRange
        } else {
            bsp_core::SnapError::NonFinite
        };
        match import_faces(&grid, faces.iter().map(|l| &l[..])) {
            Err(bsp_core::InputError::Snap { face, vertex, reason: r, .. }) => {
                prop_assert_eq!((face, vertex, r), (f, v, reason));
            }
            other => prop_assert!(false, "expected a snap error, got {:?}", other.map(|r| r.1)),
        }
    }

    /// Quads whose vertices are a few ulps off a common plane: after
    /// snapping, planar loops stay one polygon, non-planar ones are
    /// fanned; every polygon is valid and planar.
    #[test]
    fn faces_a_few_ulps_off_a_plane(
        (lo, hi) in a_box(),
        corners in proptest::array::uniform3([0.0f64..=1.0, 0.0f64..=1.0]),
        wiggle in proptest::array::uniform4([-3i32..=3, -3i32..=3, -3i32..=3]),
        tilt in [-1.0f64..1.0, -1.0f64..1.0],
    ) {
        let grid = Grid::fit(lo, hi).expect("finite box");
        // a parallelogram in the plane z = tilt . (x, y) across the box
        let at = |u: [f64; 2]| {
            let x = lo.x + (hi.x - lo.x) * u[0];
            let y = lo.y + (hi.y - lo.y) * u[1];
            let z = (lo.z + hi.z) / 2.0 + (hi.z - lo.z) / 4.0 * (tilt[0] * (2.0 * u[0] - 1.0) + tilt[1] * (2.0 * u[1] - 1.0));
            DVec3::new(x, y, z)
        };
        let [a, b, c] = corners.map(at);
        let quad: Vec<DVec3> = [a, b, b + (c - a), c]
            .iter()
            .zip(wiggle)
            .map(|(p, w)| DVec3::new(ulps(p.x, w[0]), ulps(p.y, w[1]), ulps(p.z, w[2])))
            .collect();
        let snapped: Option<Vec<GridPoint>> = quad.iter().map(|p| grid.snap(*p).ok()).collect();
        prop_assume!(snapped.is_some(), "pushed out of the grid");
        let snapped = snapped.expect("assumed");
        let (polys, report) = import_faces(&grid, [&quad[..]]).expect("in the grid");
        prop_assert!(all_planar(&polys));
        for p in &polys {
            if let Err(e) = p.sanity_check() {
                return Err(TestCaseError::fail(e.to_string()));
            }
            for v in p.vertices() {
                prop_assert!(snapped.contains(&v.as_grid().expect("grid vertex")));
            }
        }
        let distinct = {
            let mut d = snapped.clone();
            d.sort();
            d.dedup();
            d.len()
        };
        let collinear = crate::strategies::collinear;
        let flat = (1..snapped.len()).all(|i| (i + 1..snapped.len()).all(|j| collinear(snapped[0], snapped[i], snapped[j])));
        if distinct < 3 || flat {
            prop_assert!(polys.is_empty());
        } else {
            let plane = loop_plane(&snapped);
            let planar = snapped.iter().all(|g| plane.side_z(&grid_z(*g)) == bsp_core::Side::On);
            // a corner whose two sides are collinear (straight through,
            // or a spike: a side running back along the one before) is
            // removed on import, which leaves a triangle, never a bow-tie
            let straight = (0..4).any(|i| collinear(snapped[(i + 3) % 4], snapped[i], snapped[(i + 1) % 4]));
            if planar && distinct == 4 && !straight && crosses_itself(&snapped) {
                // snapping made a bow-tie: dropped, as not simple, or as of
                // no area where its two triangles' areas cancel (both are
                // true; the area is asked first)
                let q: Vec<Q3> = snapped.iter().map(|g| grid_q(*g)).collect();
                let defect = match area_vector(&q).iter().all(Zero::is_zero) {
                    true => FaceDefect::ZeroArea,
                    false => FaceDefect::NotSimple,
                };
                prop_assert!(polys.is_empty());
                prop_assert_eq!(&report.dropped, &vec![(0, defect)]);
            } else if planar {
                // a loop like a, b, a, c has three points but no area
                let q: Vec<Q3> = snapped.iter().map(|g| grid_q(*g)).collect();
                let no_area = area_vector(&q).iter().all(Zero::is_zero);
                prop_assert_eq!(polys.is_empty(), no_area, "{:?}: {:?}", snapped, report);
            } else {
                prop_assert!(report.triangulated.iter().all(|t| t.1 == FaceDefect::NonPlanar));
                prop_assert!(polys.iter().all(|p| p.len() == 3));
            }
            prop_assert_eq!(polys.is_empty(), !report.dropped.is_empty());
        }
    }
}

/// Whether a planar loop of four distinct grid points crosses itself: a
/// side meets the side opposite it (closed segments), seen along the
/// largest axis of the plane's normal.
fn crosses_itself(q: &[GridPoint]) -> bool {
    let w = |p: GridPoint| p.map(i128::from);
    let d = |a: [i128; 3], b: [i128; 3]| [0, 1, 2].map(|k| b[k] - a[k]);
    let (a, b, c) = (w(q[0]), w(q[1]), w(q[2]));
    let (e, f) = (d(a, b), d(a, c));
    let n = [
        e[1] * f[2] - e[2] * f[1],
        e[2] * f[0] - e[0] * f[2],
        e[0] * f[1] - e[1] * f[0],
    ];
    let k = (0..3).max_by_key(|&k| n[k].abs()).unwrap_or(2);
    let flat = |p: GridPoint| [w(p)[(k + 1) % 3], w(p)[(k + 2) % 3]];
    let orient = |a: [i128; 2], b: [i128; 2], c: [i128; 2]| {
        ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).signum()
    };
    let within = |a: [i128; 2], b: [i128; 2], p: [i128; 2]| {
        (0..2).all(|i| a[i].min(b[i]) <= p[i] && p[i] <= a[i].max(b[i]))
    };
    let meet = |a, b, c, e| {
        let (o1, o2, o3, o4) = (
            orient(a, b, c),
            orient(a, b, e),
            orient(c, e, a),
            orient(c, e, b),
        );
        (o1 * o2 < 0 && o3 * o4 < 0)
            || (o1 == 0 && within(a, b, c))
            || (o2 == 0 && within(a, b, e))
            || (o3 == 0 && within(c, e, a))
            || (o4 == 0 && within(c, e, b))
    };
    let p = [0, 1, 2, 3].map(|i| flat(q[i]));
    meet(p[0], p[1], p[2], p[3]) || meet(p[1], p[2], p[3], p[0])
}

/// Far from its origin a box has coarse ulps: neighbouring inputs one ulp
/// apart may be several grid steps apart, and must still snap nearest.
#[test]
fn coarse_ulps_snap_nearest() {
    let one = BigRational::one();
    // (a box under about 2^-975 units across is refused by `Grid::fit`)
    for (c, h) in [(1e6, 1e-6), (-3.5e10, 1e-3), (1e-280, 1e-290), (7.0, 7.0)] {
        let lo = DVec3::splat(c - h);
        let hi = DVec3::splat(c + h);
        let grid = Grid::fit(lo, hi).unwrap();
        let mut x = lo.x;
        let mut last = i32::MIN;
        for _ in 0..64 {
            let g = grid.snap(DVec3::splat(x)).unwrap();
            let e = exact_grid_coord(&grid, x, 0);
            assert!(
                (e - Q::from_integer(g[0].into())).abs() * Q::from_integer(2.into()) <= one,
                "{x:e}"
            );
            assert!(g[0] >= last);
            last = g[0];
            x = x.next_up();
        }
    }
}

/// `Grid::snap` computes `((p - origin) * scale).round()` in `f64`, and
/// the subtraction rounds: a coordinate a hair past the midpoint between
/// two grid points can land exactly on the midpoint and then round away
/// from zero, to the farther grid point. Box `[-1, 3]^3`: origin 1, scale
/// `2^23`; `x = -1 + 2^-24 + 2^-53` is `-2^24 + 1/2 + 2^-30` grid units,
/// nearest `-2^24 + 1`, but `x - 1` rounds to `-2 + 2^-24` (ties to even)
/// and `-2^24 + 1/2` rounds to `-2^24`.
#[test]
fn regress_snap_rounds_difference_before_scaling() {
    let grid = Grid::fit(DVec3::splat(-1.0), DVec3::splat(3.0)).unwrap();
    let x = -1.0 + 2f64.powi(-24) + 2f64.powi(-53);
    let g = grid.snap(DVec3::splat(x)).unwrap();
    let e = exact_grid_coord(&grid, x, 0);
    let d = (e.clone() - Q::from_integer(g[0].into())).abs();
    assert!(
        d <= BigRational::new(1.into(), 2.into()),
        "{e} = {} snapped to {} ({grid:?})",
        f64_q(x),
        g[0]
    );
}

/// After the fix above, `Grid::snap` computes `round(p scale) - origin
/// scale`, which assumes that `origin` lies on a grid point of its own
/// scale, as `Grid::fit` makes it. `Grid::new` accepts any origin: with
/// origin `x = 0.25` and scale 1, the point `x = 1` is `0.75` grid units
/// from the origin, `round(1) - 0.25 = 0.75` is not an integer, and the
/// cast to `i32` truncates it to 0 instead of rounding to 1.
#[test]
fn regress_snap_with_origin_off_its_grid() {
    let grid = Grid::new(DVec3::new(0.25, 0.0, 0.0), 0).unwrap();
    let x = 1.0;
    let g = grid.snap(DVec3::new(x, 0.0, 0.0)).unwrap();
    let e = exact_grid_coord(&grid, x, 0);
    let d = (e.clone() - Q::from_integer(g[0].into())).abs();
    assert!(
        d <= BigRational::new(1.into(), 2.into()),
        "{e} snapped to {} ({grid:?})",
        g[0]
    );
}
