//! proptest strategies, biased towards near-degenerate input: points
//! exactly on planes and a few grid steps off them, slivers, coplanar and
//! edge-sharing polygons, repeated and collinear vertices, nearly parallel
//! planes, coordinates at the grid limits, far-away viewpoints.

use bsp_core::internals::{MAX_NORMAL_BITS, MAX_OFFSET_BITS};
use bsp_core::{BuildOptions, GridPoint, MAX_COORD, MAX_VIEW_COORD, Plane};
use proptest::collection::vec;
use proptest::prelude::*;

/// Integer 3-vector arithmetic on `i64` (grid points and their
/// differences stay far below overflow).
pub(crate) type L3 = [i64; 3];

pub(crate) fn wide(p: GridPoint) -> L3 {
    p.map(i64::from)
}

pub(crate) fn add(a: L3, b: L3) -> L3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub(crate) fn sub(a: L3, b: L3) -> L3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn mul(a: L3, s: i64) -> L3 {
    a.map(|c| c * s)
}

/// Cross product in `i128` (inputs below `2^40`).
pub(crate) fn cross(a: L3, b: L3) -> [i128; 3] {
    let m = |x: i64, y: i64| x as i128 * y as i128;
    [
        m(a[1], b[2]) - m(a[2], b[1]),
        m(a[2], b[0]) - m(a[0], b[2]),
        m(a[0], b[1]) - m(a[1], b[0]),
    ]
}

pub(crate) fn collinear(a: GridPoint, b: GridPoint, c: GridPoint) -> bool {
    cross(sub(wide(b), wide(a)), sub(wide(c), wide(a))) == [0, 0, 0]
}

/// `Some` grid point if every coordinate is within the grid.
pub(crate) fn to_grid(p: L3) -> Option<GridPoint> {
    p.iter()
        .all(|c| c.unsigned_abs() <= MAX_COORD as u64)
        .then(|| p.map(|c| c as i32))
}

/// Translates a configuration into the grid if it is too far out on some
/// axis (pressing it against the limit, which is a case worth having);
/// `None` if it does not fit at all.
pub(crate) fn fit(points: &[L3]) -> Option<Vec<GridPoint>> {
    let m = MAX_COORD as i64;
    let mut shift = [0i64; 3];
    for (k, s) in shift.iter_mut().enumerate() {
        let lo = points.iter().map(|p| p[k]).min()?;
        let hi = points.iter().map(|p| p[k]).max()?;
        if hi - lo > 2 * m {
            return None;
        }
        if hi > m {
            *s = m - hi;
        } else if lo < -m {
            *s = -m - lo;
        }
    }
    points.iter().map(|p| to_grid(add(*p, shift))).collect()
}

/// Largest coordinate magnitude of a size class of `bits` bits.
pub(crate) fn limit(bits: u32) -> i32 {
    ((1i64 << bits) - 1).min(MAX_COORD as i64) as i32
}

/// A size class: tiny boxes (many exact coincidences), medium ones, and
/// the whole grid.
pub(crate) fn size_bits() -> BoxedStrategy<u32> {
    prop_oneof![
        2 => Just(3u32),
        2 => Just(7u32),
        1 => Just(14u32),
        1 => Just(20u32),
        2 => Just(26u32),
    ]
    .boxed()
}

/// One coordinate within `±limit(bits)`, biased towards the extremes and 0.
pub(crate) fn coord(bits: u32) -> BoxedStrategy<i32> {
    let m = limit(bits);
    prop_oneof![
        6 => -m..=m,
        1 => prop_oneof![Just(m), Just(-m)],
        1 => (0..=3i32).prop_map(move |k| m - k),
        1 => (0..=3i32).prop_map(move |k| k - m),
        1 => -3..=3i32,
    ]
    .boxed()
}

/// A grid point of one size class.
pub(crate) fn point(bits: u32) -> BoxedStrategy<GridPoint> {
    [coord(bits), coord(bits), coord(bits)].boxed()
}

/// A grid point of any size class.
pub(crate) fn any_point() -> BoxedStrategy<GridPoint> {
    size_bits().prop_flat_map(point).boxed()
}

/// Three non-collinear grid points: random, thin slivers, and triangles
/// with corners at the grid limits.
pub(crate) fn triangle() -> BoxedStrategy<[GridPoint; 3]> {
    prop_oneof![
        3 => size_bits().prop_flat_map(|b| [point(b), point(b), point(b)]),
        2 => sliver(),
        1 => limit_triangle(),
    ]
    .prop_filter("collinear", |t| !collinear(t[0], t[1], t[2]))
    .boxed()
}

/// `a`, `a + 2u`, `a + u + e`: a triangle whose third vertex is 1..3
/// grid steps off the opposite edge.
pub(crate) fn sliver() -> BoxedStrategy<[GridPoint; 3]> {
    (size_bits(), size_bits())
        .prop_flat_map(|(ba, bu)| (point(ba), point(bu), [-3i64..=3, -3i64..=3, -3i64..=3]))
        .prop_filter_map("does not fit", |(a, u, e)| {
            let (a, u) = (wide(a), wide(u));
            let f = fit(&[a, add(a, mul(u, 2)), add(add(a, u), e)])?;
            Some([f[0], f[1], f[2]])
        })
        .boxed()
}

/// A coordinate at or next to a grid limit, or zero.
pub(crate) fn limit_coord() -> BoxedStrategy<i32> {
    let m = MAX_COORD;
    prop_oneof![Just(m), Just(-m), Just(m - 1), Just(1 - m), Just(0)].boxed()
}

/// A triangle with every coordinate at a grid limit (or zero).
pub(crate) fn limit_triangle() -> BoxedStrategy<[GridPoint; 3]> {
    let p = || [limit_coord(), limit_coord(), limit_coord()];
    [p(), p(), p()].boxed()
}

/// A plane through three grid points together with grid points exactly on
/// it and points 1..3 steps off it.
#[derive(Clone, Debug)]
pub(crate) struct PlaneCase {
    pub(crate) tri: [GridPoint; 3],
    pub(crate) on: Vec<GridPoint>,
    pub(crate) near: Vec<GridPoint>,
}

fn primitive(v: L3) -> L3 {
    fn gcd(a: i64, b: i64) -> i64 {
        if b == 0 { a.abs() } else { gcd(b, a % b) }
    }
    let g = gcd(gcd(v[0], v[1]), v[2]);
    if g == 0 { v } else { v.map(|c| c / g) }
}

/// See [`PlaneCase`]: on-plane points are `a + s u + t v` with `u`, `v`
/// the primitive directions of the triangle's edges from `a`.
pub(crate) fn plane_case() -> BoxedStrategy<PlaneCase> {
    let step = || -40i64..=40;
    let off = [-3i64..=3, -3i64..=3, -3i64..=3];
    (triangle(), vec((step(), step(), off), 1..12))
        .prop_map(|(tri, combos)| {
            let a = wide(tri[0]);
            let u = primitive(sub(wide(tri[1]), a));
            let v = primitive(sub(wide(tri[2]), a));
            let mut on = tri.to_vec();
            let mut near = Vec::new();
            for (s, t, e) in combos {
                let p = add(a, add(mul(u, s), mul(v, t)));
                if let Some(g) = to_grid(p) {
                    on.push(g);
                }
                if let Some(g) = to_grid(add(p, e)).filter(|_| e != [0, 0, 0]) {
                    near.push(g);
                }
            }
            PlaneCase { tri, on, near }
        })
        .boxed()
}

/// A plane with arbitrary coefficients inside the budget, of every size.
pub(crate) fn raw_plane() -> BoxedStrategy<Plane> {
    (1u32..=MAX_NORMAL_BITS, 0u32..=MAX_OFFSET_BITS)
        .prop_flat_map(|(nb, db)| {
            let m = (1i64 << nb) - 1;
            let dm = (1i128 << db) - 1;
            ([-m..=m, -m..=m, -m..=m], -dm..=dm)
        })
        .prop_filter_map("zero normal", |(n, d)| Plane::new(n, d))
        .boxed()
}

/// An axis-aligned plane at a grid coordinate.
pub(crate) fn axis_plane() -> BoxedStrategy<Plane> {
    (0..3usize, any::<bool>(), size_bits().prop_flat_map(coord))
        .prop_map(|(k, neg, c)| {
            let mut n = [0i64; 3];
            n[k] = if neg { -1 } else { 1 };
            Plane::new(n, -(n[k] as i128) * c as i128).expect("axis plane")
        })
        .boxed()
}

/// A plane through three grid points, with raw coefficients, or
/// axis-aligned.
pub(crate) fn plane() -> BoxedStrategy<Plane> {
    prop_oneof![
        3 => triangle().prop_map(|t| Plane::through(t[0], t[1], t[2]).expect("not collinear")),
        1 => raw_plane(),
        1 => axis_plane(),
    ]
    .boxed()
}

/// Three planes: random; two nearly parallel ones (through a common edge
/// and third points a few steps apart) and a third; or three planes through
/// one grid point.
pub(crate) fn plane_triple() -> BoxedStrategy<[Plane; 3]> {
    prop_oneof![
        3 => [plane(), plane(), plane()],
        2 => (triangle(), [-3i64..=3, -3i64..=3, -3i64..=3], plane()).prop_filter_map(
            "degenerate",
            |(t, e, p3)| {
                let c2 = to_grid(add(wide(t[2]), e))?;
                let p1 = Plane::through(t[0], t[1], t[2]).ok()?;
                let p2 = Plane::through(t[0], t[1], c2).ok()?;
                Some([p1, p2, p3])
            }
        ),
        1 => (any_point(), [triangle(), triangle(), triangle()]).prop_filter_map(
            "degenerate",
            |(g, ts)| {
                // planes through g parallel to the given triangles' planes
                let mut out = Vec::new();
                for t in ts {
                    let p = Plane::through(t[0], t[1], t[2]).ok()?;
                    let n = p.normal();
                    let d = -(0..3).map(|k| n[k] as i128 * g[k] as i128).sum::<i128>();
                    out.push(Plane::new(n, d)?);
                }
                Some([out[0], out[1], out[2]])
            }
        ),
    ]
    .boxed()
}

/// Small integer combination weights, for planes through a common point.
pub(crate) fn weights() -> BoxedStrategy<[i64; 3]> {
    [-3i64..=3, -3i64..=3, -3i64..=3]
        .prop_filter("all zero", |w| w != &[0, 0, 0])
        .boxed()
}

/// The coefficients `Σ w_i (n_i, d_i)` (a plane through every point the
/// `p_i` share), unreduced, if they fit `i64` / `i128`.
pub(crate) fn combine_raw(planes: &[Plane; 3], w: [i64; 3]) -> Option<([i64; 3], i128)> {
    let mut n = [0i128; 3];
    let mut d = 0i128;
    for (p, &wi) in planes.iter().zip(&w) {
        for (k, nk) in n.iter_mut().enumerate() {
            *nk += wi as i128 * p.normal()[k] as i128;
        }
        d = d.checked_add((wi as i128).checked_mul(p.offset())?)?;
    }
    let n = [
        i64::try_from(n[0]).ok()?,
        i64::try_from(n[1]).ok()?,
        i64::try_from(n[2]).ok()?,
    ];
    Some((n, d))
}

/// The plane `Σ w_i p_i`, if it fits the budget.
pub(crate) fn combine(planes: &[Plane; 3], w: [i64; 3]) -> Option<Plane> {
    combine_raw(planes, w).and_then(|(n, d)| Plane::new(n, d))
}

/// A convex polygon as given to `Polygon::from_grid_points` (`input`,
/// possibly with repeated and collinear vertices) and the strictly convex
/// loop it describes (`hull`).
#[derive(Clone, Debug)]
pub(crate) struct PolyCase {
    pub(crate) input: Vec<GridPoint>,
    pub(crate) hull: Vec<GridPoint>,
}

fn cross2(o: [i64; 2], a: [i64; 2], b: [i64; 2]) -> i64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// Strict convex hull (Andrew's monotone chain), counter-clockwise.
pub(crate) fn hull_2d(mut pts: Vec<[i64; 2]>) -> Vec<[i64; 2]> {
    pts.sort();
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let mut h: Vec<[i64; 2]> = Vec::new();
    for pass in 0..2 {
        let start = h.len();
        let it: Box<dyn Iterator<Item = &[i64; 2]>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &p in it {
            while h.len() >= start + 2 && cross2(h[h.len() - 2], h[h.len() - 1], p) <= 0 {
                h.pop();
            }
            h.push(p);
        }
        h.pop();
    }
    h
}

/// A convex polygon `a + s u + t v` over a random strictly convex hull of
/// `(s, t)` points, translated into the grid; decorated with repeated
/// vertices, collinear mid-edge vertices and a closing repeat of the
/// first vertex. Also axis-aligned rectangles spanning the whole grid.
pub(crate) fn convex_polygon() -> BoxedStrategy<PolyCase> {
    let general = (
        size_bits(),
        0u32..5,
        prop_oneof![Just(1i64), Just(3), Just(20), Just(1000)],
    )
        .prop_flat_map(|(ba, bu, s)| {
            let ub = [1u32, 2, 5, 12, 20][bu as usize];
            (
                point(ba),
                point(ub),
                point(ub),
                vec([-s..=s, -s..=s], 3..9),
                vec(0u8..6, 9),
                any::<bool>(),
            )
        })
        .prop_filter_map("degenerate", |(a, u, v, st, deco, reverse)| {
            let (a, u, v) = (wide(a), wide(u), wide(v));
            if cross(u, v) == [0, 0, 0] {
                return None;
            }
            let h = hull_2d(st);
            if h.len() < 3 {
                return None;
            }
            let mut pts: Vec<L3> = h
                .iter()
                .map(|&[s, t]| add(a, add(mul(u, s), mul(v, t))))
                .collect();
            if reverse {
                pts.reverse();
            }
            let hull = fit(&pts)?;
            Some(decorate(&hull, &deco))
        });
    let m = MAX_COORD;
    let rect = (0..3usize, limit_coord(), any::<bool>()).prop_map(move |(k, c, reverse)| {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        let corner = |x: i32, y: i32| {
            let mut p = [0; 3];
            p[k] = c;
            p[i] = x;
            p[j] = y;
            p
        };
        let mut hull = vec![corner(-m, -m), corner(m, -m), corner(m, m), corner(-m, m)];
        if reverse {
            hull.reverse();
        }
        decorate(&hull, &[2, 0, 1, 0, 5])
    });
    prop_oneof![6 => general, 1 => rect].boxed()
}

/// Input loop for `hull`: per vertex, `deco` 1 repeats it, 2 inserts the
/// edge midpoint after it (when integral), 3 both; 5 on the first vertex
/// closes the loop with a copy of it.
fn decorate(hull: &[GridPoint], deco: &[u8]) -> PolyCase {
    let k = hull.len();
    let mut input = Vec::new();
    for i in 0..k {
        let d = deco.get(i).copied().unwrap_or(0);
        input.push(hull[i]);
        if d & 1 == 1 {
            input.push(hull[i]);
        }
        if d & 2 == 2 {
            let s = add(wide(hull[i]), wide(hull[(i + 1) % k]));
            if s.iter().all(|c| c % 2 == 0) {
                input.push(to_grid(s.map(|c| c / 2)).expect("midpoint is in the grid"));
            }
        }
    }
    if deco.first() == Some(&5) {
        input.push(hull[0]);
    }
    PolyCase {
        input,
        hull: hull.to_vec(),
    }
}

/// How to make a cutting plane for a polygon, resolved by [`make_cut`]
/// against the polygon's grid vertices. Fractions are in units of
/// 1/65535 of the (slightly enlarged) bounding box.
#[derive(Clone, Debug)]
pub(crate) enum Cut {
    /// Through three points of the bounding box.
    Points([[u16; 3]; 3]),
    /// Through a vertex and two bounding-box points.
    Vertex(usize, [[u16; 3]; 2]),
    /// Through two vertices and a bounding-box point.
    TwoVertices(usize, usize, [u16; 3]),
    /// Through a vertex, then moved by `delta` in the offset: the vertex
    /// is a few units off the plane.
    Nudged(usize, [[u16; 3]; 2], i8),
    /// Any plane.
    Raw(Plane),
}

pub(crate) fn cut() -> BoxedStrategy<Cut> {
    let f = || [any::<u16>(), any::<u16>(), any::<u16>()];
    prop_oneof![
        4 => [f(), f(), f()].prop_map(Cut::Points),
        2 => (0..16usize, [f(), f()]).prop_map(|(i, p)| Cut::Vertex(i, p)),
        2 => (0..16usize, 0..16usize, f()).prop_map(|(i, j, p)| Cut::TwoVertices(i, j, p)),
        1 => (0..16usize, [f(), f()], -3i8..=3).prop_map(|(i, p, d)| Cut::Nudged(i, p, d)),
        1 => plane().prop_map(Cut::Raw),
    ]
    .boxed()
}

/// The point at fractions `f` of the box `[lo - 2, hi + 2]`, clamped to
/// the grid.
pub(crate) fn box_point(lo: GridPoint, hi: GridPoint, f: [u16; 3]) -> GridPoint {
    let m = MAX_COORD as i64;
    [0, 1, 2].map(|k| {
        let l = (lo[k] as i64 - 2).max(-m);
        let h = (hi[k] as i64 + 2).min(m);
        (l + (h - l) * f[k] as i64 / 65535) as i32
    })
}

pub(crate) fn bbox(points: &[GridPoint]) -> (GridPoint, GridPoint) {
    let lo = [0, 1, 2].map(|k| points.iter().map(|p| p[k]).min().expect("points"));
    let hi = [0, 1, 2].map(|k| points.iter().map(|p| p[k]).max().expect("points"));
    (lo, hi)
}

/// The plane described by `cut` for a polygon with grid vertices `verts`.
pub(crate) fn make_cut(cut: &Cut, verts: &[GridPoint]) -> Option<Plane> {
    let (lo, hi) = bbox(verts);
    let b = |f| box_point(lo, hi, f);
    let v = |i: usize| verts[i % verts.len()];
    match cut {
        Cut::Points([p, q, r]) => Plane::through(b(*p), b(*q), b(*r)).ok(),
        Cut::Vertex(i, [p, q]) => Plane::through(v(*i), b(*p), b(*q)).ok(),
        Cut::TwoVertices(i, j, p) => Plane::through(v(*i), v(*j), b(*p)).ok(),
        Cut::Nudged(i, [p, q], d) => {
            let pl = Plane::through(v(*i), b(*p), b(*q)).ok()?;
            Plane::new(pl.normal(), pl.offset() + *d as i128)
        }
        Cut::Raw(p) => Some(*p),
    }
}

/// A polygon soup for painter's-order tests: random triangles and
/// parallelograms, edge-sharing pairs, coplanar pairs, stacks of parallel
/// copies; all in one size class.
pub(crate) fn scene() -> BoxedStrategy<Vec<Vec<GridPoint>>> {
    scene_of(prop_oneof![Just(3u32), Just(6u32), Just(12u32), Just(26u32)].boxed())
}

fn scene_of(bits: BoxedStrategy<u32>) -> BoxedStrategy<Vec<Vec<GridPoint>>> {
    bits.prop_flat_map(|b| vec(scene_item(b), 2..9))
        .prop_map(|items| items.into_iter().flatten().collect())
        .boxed()
}

fn scene_item(b: u32) -> BoxedStrategy<Vec<Vec<GridPoint>>> {
    let p = move || point(b);
    let tri = [p(), p(), p()].prop_map(|[a, b, c]| vec![vec![a, b, c]]);
    let quad = [p(), p(), p()].prop_filter_map("does not fit", |[a, b, c]| {
        let (a, b, c) = (wide(a), wide(b), wide(c));
        Some(vec![fit(&[a, b, add(b, sub(c, a)), c])?])
    });
    let shared = [p(), p(), p(), p()].prop_map(|[a, b, c, d]| vec![vec![a, b, c], vec![b, a, d]]);
    let coplanar = (
        [p(), p(), p()],
        [
            -3i64..=3,
            -3i64..=3,
            -3i64..=3,
            -3i64..=3,
            -3i64..=3,
            -3i64..=3,
        ],
    )
        .prop_filter_map("does not fit", |([a, b, c], w)| {
            let (a, b, c) = (wide(a), wide(b), wide(c));
            let (u, v) = (sub(b, a), sub(c, a));
            let on = |s: i64, t: i64| add(a, add(mul(u, s), mul(v, t)));
            let f = fit(&[a, b, c, on(w[0], w[1]), on(w[2], w[3]), on(w[4], w[5])])?;
            Some(vec![f[..3].to_vec(), f[3..].to_vec()])
        });
    let stack = (
        [p(), p(), p()],
        [-3i64..=3, -3i64..=3, -3i64..=3],
        2usize..5,
    )
        .prop_filter_map("does not fit", |([a, b, c], o, k)| {
            let (a, b, c) = (wide(a), wide(b), wide(c));
            let mut pts = Vec::new();
            for i in 0..k as i64 {
                let s = mul(o, i);
                pts.extend([add(a, s), add(b, s), add(c, s)]);
            }
            let f = fit(&pts)?;
            Some(f.chunks(3).map(<[GridPoint]>::to_vec).collect())
        });
    prop_oneof![3 => tri, 2 => quad, 1 => shared, 1 => coplanar, 1 => stack].boxed()
}

/// A viewpoint relative to a scene, resolved by [`make_eye`].
#[derive(Clone, Debug)]
pub(crate) enum Eye {
    /// Fractions of four times the scene's bounding box.
    Near([u16; 3]),
    /// Anywhere up to the viewpoint limit.
    Far([i64; 3]),
    /// At a vertex of input polygon `.0` (on its plane and maybe others).
    Vertex(usize, usize),
    /// On the plane of input polygon `.0`: `a + s (b - a) + t (c - a)`.
    OnPlane(usize, i64, i64),
}

pub(crate) fn eye() -> BoxedStrategy<Eye> {
    let far = MAX_VIEW_COORD;
    prop_oneof![
        3 => [any::<u16>(), any::<u16>(), any::<u16>()].prop_map(Eye::Near),
        1 => [-far..=far, -far..=far, -far..=far].prop_map(Eye::Far),
        1 => (any::<usize>(), any::<usize>()).prop_map(|(i, j)| Eye::Vertex(i, j)),
        2 => (any::<usize>(), -50i64..=50, -50i64..=50).prop_map(|(i, s, t)| Eye::OnPlane(i, s, t)),
    ]
    .boxed()
}

/// The viewpoint coordinates described by `eye` for the input polygons
/// `polys` (non-empty).
pub(crate) fn make_eye(eye: &Eye, polys: &[Vec<GridPoint>]) -> [i64; 3] {
    let all: Vec<GridPoint> = polys.iter().flatten().copied().collect();
    let (lo, hi) = bbox(&all);
    match eye {
        Eye::Near(f) => [0, 1, 2].map(|k| {
            let (l, h) = (lo[k] as i64, hi[k] as i64);
            let ext = (h - l).max(4);
            l - 2 * ext + 4 * ext * f[k] as i64 / 65535 + (h - l) / 2
        }),
        Eye::Far(p) => *p,
        Eye::Vertex(i, j) => {
            let p = &polys[i % polys.len()];
            wide(p[j % p.len()])
        }
        Eye::OnPlane(i, s, t) => {
            let p = &polys[i % polys.len()];
            let (a, b, c) = (wide(p[0]), wide(p[1]), wide(p[2]));
            add(a, add(mul(sub(b, a), *s), mul(sub(c, a), *t)))
        }
    }
}

/// A closed solid of convex faces, counter-clockwise seen from outside,
/// with points known to lie on its vertices, edges or faces.
#[derive(Clone, Debug)]
pub(crate) struct SolidCase {
    pub(crate) name: &'static str,
    pub(crate) faces: Vec<Vec<GridPoint>>,
    pub(crate) special: Vec<GridPoint>,
}

/// Reverses `face` if its normal does not point along `out`.
fn orient(face: &mut [L3], out: [i128; 3]) {
    let n = cross(sub(face[1], face[0]), sub(face[2], face[0]));
    let d: i128 = (0..3).map(|k| n[k] * out[k]).sum();
    if d < 0 {
        face.reverse();
    }
}

fn to_faces(faces: Vec<Vec<L3>>) -> Option<Vec<Vec<GridPoint>>> {
    faces
        .iter()
        .map(|f| f.iter().map(|p| to_grid(*p)).collect())
        .collect()
}

/// Parallelepipeds `o + 2(i u + j v + k w)`, `i, j, k ∈ {0, 1}` (boxes
/// when the vectors are axis-aligned, rotated boxes when they are
/// orthogonal), whose vertices, edge midpoints and
/// face centres are grid points.
pub(crate) fn parallelepiped() -> BoxedStrategy<SolidCase> {
    let axis = (1i64..=(1 << 24), 1i64..=(1 << 24), 1i64..=(1 << 24))
        .prop_map(|(a, b, c)| [[a, 0, 0], [0, b, 0], [0, 0, c]]);
    let skew = (0u32..4).prop_flat_map(|b| {
        let ub = [2u32, 6, 12, 23][b as usize];
        [point(ub), point(ub), point(ub)].prop_map(|v| v.map(wide))
    });
    // rectangular boxes in a rotated orthogonal integer frame u, u × r, u × (u × r)
    let rotated = (point(5), point(5)).prop_map(|(u, r)| {
        let (u, r) = (wide(u), wide(r));
        let v = cross(u, r).map(|c| c as i64);
        let w = cross(u, v).map(|c| c as i64);
        [u, v, w]
    });
    (
        size_bits().prop_flat_map(point),
        prop_oneof![1 => axis, 2 => skew, 1 => rotated],
    )
        .prop_filter_map("degenerate", |(o, [u, v, w])| {
            let det: i128 = (0..3).map(|k| cross(u, v)[k] * w[k] as i128).sum();
            if det == 0 {
                return None;
            }
            let o = wide(o);
            let c = |i: i64, j: i64, k: i64| {
                add(o, add(mul(u, 2 * i), add(mul(v, 2 * j), mul(w, 2 * k))))
            };
            let mut corners = Vec::new();
            for i in 0..2 {
                for j in 0..2 {
                    for k in 0..2 {
                        corners.push(c(i, j, k));
                    }
                }
            }
            let fitted = fit(&corners)?;
            let shift = sub(wide(fitted[0]), corners[0]);
            let c = |i, j, k| add(c(i, j, k), shift);
            let centre = add(add(c(0, 0, 0), add(u, v)), w);
            let quads = [
                [c(0, 0, 0), c(0, 1, 0), c(1, 1, 0), c(1, 0, 0)],
                [c(0, 0, 1), c(0, 1, 1), c(1, 1, 1), c(1, 0, 1)],
                [c(0, 0, 0), c(1, 0, 0), c(1, 0, 1), c(0, 0, 1)],
                [c(0, 1, 0), c(1, 1, 0), c(1, 1, 1), c(0, 1, 1)],
                [c(0, 0, 0), c(0, 0, 1), c(0, 1, 1), c(0, 1, 0)],
                [c(1, 0, 0), c(1, 0, 1), c(1, 1, 1), c(1, 1, 0)],
            ];
            let mut faces = Vec::new();
            let mut special = vec![centre];
            for q in quads {
                let mut f = q.to_vec();
                let fc = q.iter().fold([0; 3], |s, p| add(s, *p)).map(|x| x / 4);
                orient(&mut f, sub(fc, centre).map(i128::from));
                special.push(fc);
                for i in 0..4 {
                    special.push(f[i]);
                    special.push(add(f[i], f[(i + 1) % 4]).map(|x| x / 2));
                }
                faces.push(f);
            }
            Some(SolidCase {
                name: "parallelepiped",
                faces: to_faces(faces)?,
                special: special.into_iter().filter_map(to_grid).collect(),
            })
        })
        .boxed()
}

/// Tetrahedra with vertices on a 12-step lattice, so that edge midpoints,
/// face centroids and the centroid are grid points.
pub(crate) fn tetrahedron() -> BoxedStrategy<SolidCase> {
    prop_oneof![Just(2u32), Just(5), Just(10), Just(22)]
        .prop_flat_map(|b| [point(b), point(b), point(b), point(b)])
        .prop_filter_map("degenerate", |v| {
            let v = v.map(|p| mul(wide(p), 12));
            let det: i128 = {
                let n = cross(sub(v[1], v[0]), sub(v[2], v[0]));
                (0..3).map(|k| n[k] * sub(v[3], v[0])[k] as i128).sum()
            };
            if det == 0 {
                return None;
            }
            let centre = v.iter().fold([0; 3], |s, p| add(s, *p)).map(|x| x / 4);
            let mut faces = Vec::new();
            let mut special = vec![centre];
            for skip in 0..4 {
                let mut f: Vec<L3> = (0..4).filter(|&i| i != skip).map(|i| v[i]).collect();
                let fc = f.iter().fold([0; 3], |s, p| add(s, *p)).map(|x| x / 3);
                orient(&mut f, sub(fc, centre).map(i128::from));
                special.push(fc);
                faces.push(f);
            }
            for i in 0..4 {
                special.push(v[i]);
                for j in i + 1..4 {
                    special.push(add(v[i], v[j]).map(|x| x / 2));
                }
            }
            Some(SolidCase {
                name: "tetrahedron",
                faces: to_faces(faces)?,
                special: special.into_iter().filter_map(to_grid).collect(),
            })
        })
        .boxed()
}

/// A corner `(i, j)` of a height field's cell grid.
type Corner = (usize, usize);

/// A non-convex solid: a height field over an `n × m` grid of cells
/// (triangulated top, quad bottom cells, trapezoid walls).
pub(crate) fn terrain() -> BoxedStrategy<SolidCase> {
    (
        2usize..5,
        2usize..5,
        prop_oneof![Just(2i64), Just(6), Just(1000), Just(1 << 22)],
    )
        .prop_flat_map(|(n, m, step)| {
            (
                Just((n, m, step)),
                vec(1i64..=4 * step, (n + 1) * (m + 1)),
                point(20),
            )
        })
        .prop_filter_map("does not fit", |((n, m, step), h, o)| {
            let o = wide(o);
            let hgt = |i: usize, j: usize| h[i * (m + 1) + j];
            let top = |i: usize, j: usize| add(o, [i as i64 * step, j as i64 * step, hgt(i, j)]);
            let bot = |i: usize, j: usize| add(o, [i as i64 * step, j as i64 * step, 0]);
            let mut faces: Vec<Vec<L3>> = Vec::new();
            let mut special = Vec::new();
            for i in 0..n {
                for j in 0..m {
                    let (a, b, c, d) = (top(i, j), top(i + 1, j), top(i + 1, j + 1), top(i, j + 1));
                    for mut f in [vec![a, b, c], vec![a, c, d]] {
                        orient(&mut f, [0, 0, 1]);
                        faces.push(f);
                    }
                    let mut f = vec![bot(i, j), bot(i + 1, j), bot(i + 1, j + 1), bot(i, j + 1)];
                    orient(&mut f, [0, 0, -1]);
                    special.push(add(bot(i, j), [step / 2, step / 2, 0]));
                    faces.push(f);
                    special.extend([a, add(a, c).map(|x| x / 2)]);
                }
            }
            // (corner sequence, outward direction) of each side
            let walls: [(Vec<Corner>, [i128; 3]); 4] = [
                ((0..=n).map(|i| (i, 0)).collect(), [0, -1, 0]),
                ((0..=n).map(|i| (i, m)).collect(), [0, 1, 0]),
                ((0..=m).map(|j| (0, j)).collect(), [-1, 0, 0]),
                ((0..=m).map(|j| (n, j)).collect(), [1, 0, 0]),
            ];
            for (seq, out) in walls {
                for w in seq.windows(2) {
                    let ((i0, j0), (i1, j1)) = (w[0], w[1]);
                    let mut f = vec![bot(i0, j0), bot(i1, j1), top(i1, j1), top(i0, j0)];
                    orient(&mut f, out);
                    special.push(add(bot(i0, j0), [0, 0, 1]));
                    faces.push(f);
                }
            }
            special.retain(|p| p.iter().all(|c| c.unsigned_abs() <= MAX_COORD as u64));
            Some(SolidCase {
                name: "terrain",
                faces: to_faces(faces)?,
                special: special.into_iter().filter_map(to_grid).collect(),
            })
        })
        .boxed()
}

/// Any of the closed solids above.
pub(crate) fn solid() -> BoxedStrategy<SolidCase> {
    prop_oneof![2 => parallelepiped(), 2 => tetrahedron(), 1 => terrain()].boxed()
}

/// Build options over their whole range (one candidate and one sample
/// make the worst trees), without balance cuts.
pub(crate) fn options() -> BoxedStrategy<BuildOptions> {
    options_cut(Just(0usize).boxed())
}

/// Build options with balance cuts from the smallest threshold up.
pub(crate) fn options_with_cuts() -> BoxedStrategy<BuildOptions> {
    options_cut((1usize..12).boxed())
}

fn options_cut(cut: BoxedStrategy<usize>) -> BoxedStrategy<BuildOptions> {
    (1usize..10, 1usize..64, 0u32..8, any::<u64>(), cut)
        .prop_map(|(c, s, w, seed, cut)| {
            BuildOptions::default()
                .with_candidates(c)
                .with_sample(s)
                .with_split_weight(w)
                .with_seed(seed)
                .with_cut_threshold(cut)
        })
        .boxed()
}

/// A small deterministic generator for sampling inside a test case.
#[derive(Clone, Debug)]
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    pub(crate) fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    pub(crate) fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}
