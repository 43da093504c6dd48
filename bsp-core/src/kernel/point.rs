//! Exact points: grid points and implicit intersections of three planes.

use std::sync::Arc;

use bnum::cast::As;
use bnum::types::I256;

use crate::kernel::Side;
use crate::kernel::exact::{Homogeneous, Wide};
use crate::kernel::grid::GridPoint;
use crate::kernel::plane::{Plane, cross_wide};

/// An exact point: either an input grid point or the intersection of three
/// planes of the input budget, held in homogeneous integer coordinates.
///
/// Implicit points are reference-counted: a split makes a new vertex once
/// and both pieces share it.
#[derive(Clone, Debug)]
pub enum Point {
    /// An input vertex on the grid.
    Grid(GridPoint),
    /// The intersection of three planes.
    Implicit(Arc<Implicit>),
}

/// The homogeneous coordinates `(x, y, z, w)`, `w > 0`, of the intersection
/// of three input-tier planes, in 256-bit integers, with their `f64`
/// approximations for the filter.
///
/// Bounds: `|w| < 2^168`, `|x|, |y|, |z| < 2^196`; see
/// `docs/architecture.md`.
pub type Implicit = Homogeneous<4>;

fn wide(x: i128) -> I256 {
    I256::from(x)
}

/// [`Implicit::from_planes`]'s coordinates `(x, y, z, w)` (`w ≥ 0`;
/// zero where the planes do not meet in one point) computed in `i128`,
/// where every product of them has at most 124 bits: then each sum of
/// three is below `2^126`, and the coordinates are exactly those of the
/// 256-bit evaluation. `None` where some product could be larger. A cell
/// wall (an axis-aligned plane with small coefficients) and an edge plane
/// with a support plane always fit: the cuts of a face by the walls of its
/// cell take this path.
fn from_planes_native(n1: [i64; 3], c: [[i128; 3]; 3], d: [i128; 3]) -> Option<[i128; 4]> {
    let bits = |x: i128| 128 - x.unsigned_abs().leading_zeros();
    let most = |v: &[i128; 3]| v.iter().map(|&x| bits(x)).max().unwrap_or(0);
    let n_bits = n1
        .iter()
        .map(|&x| 64 - x.unsigned_abs().leading_zeros())
        .max();
    let c_bits = c.map(|v| most(&v));
    let fits =
        (0..3).all(|j| c_bits[j] + bits(d[j]) <= 124) && n_bits.unwrap_or(0) + c_bits[0] <= 124;
    if !fits {
        return None;
    }
    let [c23, c31, c12] = c;
    let w: i128 = (0..3).map(|i| n1[i] as i128 * c23[i]).sum();
    // x · det = -(c23 d1 + c31 d2 + c12 d3), all four negated where
    // det < 0, for w > 0 (as the wide evaluation does)
    let sign = if w < 0 { 1 } else { -1 };
    let mut h = [0i128; 4];
    for i in 0..3 {
        h[i] = sign * (c23[i] * d[0] + c31[i] * d[1] + c12[i] * d[2]);
    }
    h[3] = -sign * w;
    Some(h)
}

/// [`Implicit::from_planes`] in 256-bit sums, for any planes within the
/// budget: with `c = [n2 × n3, n3 × n1, n1 × n2]` (`|c| < 2^111`) and the
/// offsets `d`, `det = n1 · c[0]` (`|det| < 2^168`) and
/// `x · det = -(c[0] d1 + c[1] d2 + c[2] d3)` (`|x| < 3 · 2^111 · 2^83 <
/// 2^196`), all four negated at once where `det < 0`, for `w > 0`.
fn from_planes_wide(n1: [i64; 3], c: [[i128; 3]; 3], d: [i128; 3]) -> Option<Implicit> {
    let [c23, c31, c12] = c;
    let w = (0..3).fold(Wide::ZERO, |s, i| {
        s.add(Wide::product(n1[i] as i128, c23[i]))
    });
    if w.is_zero() {
        return None;
    }
    let flip = w.is_negative();
    let mut h = [Wide::ZERO; 4];
    for i in 0..3 {
        let s = Wide::product(c23[i], d[0])
            .add(Wide::product(c31[i], d[1]))
            .add(Wide::product(c12[i], d[2]));
        h[i] = if flip { s } else { s.neg() };
    }
    h[3] = if flip { w.neg() } else { w };
    Some(Homogeneous::with_approx(
        h.map(Wide::to_i256),
        h.map(Wide::approx),
    ))
}

impl Homogeneous<4> {
    /// The intersection of three planes, or `None` if they do not meet in a
    /// single point.
    pub fn from_planes(p1: &Plane, p2: &Plane, p3: &Plane) -> Option<Implicit> {
        let n1 = p1.normal();
        let c = [
            cross_wide(p2.normal(), p3.normal()),
            cross_wide(p3.normal(), n1),
            cross_wide(n1, p2.normal()),
        ];
        let d = [p1.offset(), p2.offset(), p3.offset()];
        match from_planes_native(n1, c, d) {
            Some(h) if h[3] == 0 => None,
            Some(h) => Some(Homogeneous::with_approx(
                h.map(I256::from),
                h.map(crate::kernel::exact::approx_i128),
            )),
            None => from_planes_wide(n1, c, d),
        }
    }

    /// The point where the segment from the grid point `p` to `q` crosses
    /// `plane`, which has them strictly on opposite sides: with
    /// `s(x) = n · x + d`, the point `(s(q) p − s(p) q) / (s(q) − s(p))`.
    /// The same point as [`Implicit::from_planes`] of the segment's line
    /// and the plane gives, in smaller coordinates and a few native
    /// products: for any `i32` coordinates and a plane within the budget,
    /// `|s| < 2^88`, so `|w| < 2^89` and `|x|, |y|, |z| < 2^120` (in
    /// `i128`, and within [`Implicit`]'s bounds).
    pub fn on_segment(p: &GridPoint, q: &GridPoint, plane: &Plane) -> Implicit {
        let n = plane.normal();
        let s =
            |g: &GridPoint| (0..3).fold(plane.offset(), |acc, k| acc + n[k] as i128 * g[k] as i128);
        let (sp, sq) = (s(p), s(q));
        debug_assert!(sp != 0 && sq != 0 && (sp < 0) != (sq < 0));
        // w = s(q) − s(p) > 0 when p lies behind the plane; else all negated
        let sign = if sq > sp { 1 } else { -1 };
        let h = [0, 1, 2, 3].map(|k| {
            sign * if k == 3 {
                sq - sp
            } else {
                sq * p[k] as i128 - sp * q[k] as i128
            }
        });
        Homogeneous::with_approx(h.map(I256::from), h.map(crate::kernel::exact::approx_i128))
    }

    /// The homogeneous coordinates `(x, y, z, w)` with `w > 0`.
    pub fn homogeneous(&self) -> &[I256; 4] {
        self.coords()
    }

    /// Side of `plane`, decided by the floating-point filter when it can
    /// and by exact 256-bit arithmetic otherwise.
    #[inline]
    pub fn classify(&self, plane: &Plane) -> Side {
        match self.classify_filtered(plane) {
            Some(s) => s,
            None => self.classify_exact(plane),
        }
    }

    /// The filter alone: `None` when the `f64` evaluation cannot certify
    /// the sign.
    #[inline]
    pub fn classify_filtered(&self, plane: &Plane) -> Option<Side> {
        self.filter(&plane.approx())
    }

    /// The exact path: the sign of `n · (x, y, z) + d w` in 256 bits
    /// (`< 2^254` in magnitude).
    pub fn classify_exact(&self, plane: &Plane) -> Side {
        let n = plane.normal();
        let h = self.coords();
        let v = wide(n[0] as i128) * h[0]
            + wide(n[1] as i128) * h[1]
            + wide(n[2] as i128) * h[2]
            + wide(plane.offset()) * h[3];
        Side::from_sign(v.signum().as_::<i32>())
    }

    /// The correctly rounded Cartesian coordinates (see
    /// [`Homogeneous::round_with`]), computed once.
    pub fn to_f64(&self) -> [f64; 3] {
        *self.rounded().get_or_init(|| self.round_with::<9>())
    }

    /// Exact equality of the represented points (at once for the same
    /// allocation: equal new vertices are shared, see `share_points`).
    pub fn same_point(&self, o: &Implicit) -> bool {
        std::ptr::eq(self, o) || self.same(o)
    }
}

/// A point read where it is stored: a grid point by value, an implicit
/// one by reference (see [`ConvexFace::corner`](crate::internals::ConvexFace)).
#[derive(Clone, Copy, Debug)]
pub enum PointRef<'a> {
    /// An input vertex on the grid.
    Grid(GridPoint),
    /// The intersection of three planes.
    Implicit(&'a Arc<Implicit>),
}

impl PointRef<'_> {
    /// The point, owned (an implicit point's count goes up).
    pub fn to_point(self) -> Point {
        match self {
            PointRef::Grid(g) => Point::Grid(g),
            PointRef::Implicit(i) => Point::Implicit(i.clone()),
        }
    }

    /// Exact side of `plane`.
    #[inline]
    pub fn classify(self, plane: &Plane) -> Side {
        match self {
            PointRef::Grid(g) => plane.classify_grid(g),
            PointRef::Implicit(i) => i.classify(plane),
        }
    }

    /// [`Point::to_f64`].
    pub fn to_f64(self) -> [f64; 3] {
        match self {
            PointRef::Grid(g) => g.map(|c| c as f64),
            PointRef::Implicit(i) => i.to_f64(),
        }
    }

    /// [`Point::as_grid`].
    pub fn as_grid(self) -> Option<GridPoint> {
        match self {
            PointRef::Grid(g) => Some(g),
            PointRef::Implicit(i) => {
                let c = i.as_integer()?;
                c.iter()
                    .all(|v| v.abs() <= crate::kernel::MAX_COORD as i64)
                    .then(|| c.map(|v| v as i32))
            }
        }
    }

    /// The grid point, if it is stored as one.
    pub fn grid(self) -> Option<GridPoint> {
        match self {
            PointRef::Grid(g) => Some(g),
            PointRef::Implicit(_) => None,
        }
    }
}

impl Point {
    /// The point as a [`PointRef`].
    #[inline]
    pub fn as_ref(&self) -> PointRef<'_> {
        match self {
            Point::Grid(g) => PointRef::Grid(*g),
            Point::Implicit(i) => PointRef::Implicit(i),
        }
    }

    /// The intersection of three planes (see [`Implicit::from_planes`]).
    pub fn from_planes(p1: &Plane, p2: &Plane, p3: &Plane) -> Option<Point> {
        Implicit::from_planes(p1, p2, p3).map(|i| Point::Implicit(Arc::new(i)))
    }

    /// The point where the edge from `a` to `b`, on the planes `support`
    /// and `edge`, crosses `plane`, which has `a` and `b` strictly on
    /// opposite sides: from the segment when both ends are grid points
    /// ([`Implicit::on_segment`]), else from the three planes.
    pub fn crossing(a: &Point, b: &Point, support: &Plane, edge: &Plane, plane: &Plane) -> Point {
        if let (Point::Grid(p), Point::Grid(q)) = (a, b) {
            return Point::Implicit(Arc::new(Implicit::on_segment(p, q, plane)));
        }
        Point::from_planes(support, edge, plane)
            .expect("a spanning edge meets the cutting plane in one point")
    }

    /// Exact side of `plane`.
    #[inline]
    pub fn classify(&self, plane: &Plane) -> Side {
        match self {
            Point::Grid(g) => plane.classify_grid(*g),
            Point::Implicit(i) => i.classify(plane),
        }
    }

    /// Homogeneous coordinates, `w > 0`.
    pub fn homogeneous(&self) -> [I256; 4] {
        match self {
            Point::Grid(g) => [
                wide(g[0] as i128),
                wide(g[1] as i128),
                wide(g[2] as i128),
                I256::ONE,
            ],
            Point::Implicit(i) => *i.coords(),
        }
    }

    /// Grid coordinates as `f64`, within a few ulps of the exact values
    /// (from the cached approximations: fast, but not canonical — use
    /// [`Point::to_f64`] for output).
    #[inline]
    pub fn approx_f64(&self) -> [f64; 3] {
        match self {
            Point::Grid(g) => g.map(|c| c as f64),
            Point::Implicit(i) => i.approx_f64(),
        }
    }

    /// A hash of the approximate coordinates ([`Point::approx_f64`]), each
    /// mantissa rounded to its top 36 bits, for finding equal points
    /// cheaply. Equal points computed from different planes differ by a
    /// few ulps there, so they nearly always get equal keys (rounding, not
    /// truncation: a coordinate on a cell wall is a round number, which
    /// truncation would split between two keys); a rare pair straddling a
    /// boundary gets two, so a key only proposes a match, and the exact
    /// comparison decides. The correctly rounded coordinates
    /// ([`Point::to_f64`]) would be canonical, but cost an exact division
    /// per coordinate.
    pub fn approx_key(&self) -> u64 {
        approx_key(self.approx_f64())
    }

    /// Grid coordinates as `f64`, each the correctly rounded value of the
    /// exact rational coordinate. Equal points give equal results however
    /// they were constructed.
    pub fn to_f64(&self) -> [f64; 3] {
        match self {
            Point::Grid(g) => g.map(|c| c as f64),
            Point::Implicit(i) => i.to_f64(),
        }
    }

    /// `Some` grid point if this point has integer coordinates within the grid.
    pub fn as_grid(&self) -> Option<GridPoint> {
        self.as_ref().as_grid()
    }

    /// Exact equality of the represented points.
    pub fn same_point(&self, o: &Point) -> bool {
        match (self, o) {
            (Point::Grid(a), Point::Grid(b)) => a == b,
            (Point::Implicit(a), Point::Implicit(b)) => a.same_point(b),
            (Point::Grid(g), Point::Implicit(i)) | (Point::Implicit(i), Point::Grid(g)) => {
                grid_is(g, i)
            }
        }
    }
}

/// The turn `a → b → c` of three points seen along coordinate axis `k`
/// (projected onto the axes `k + 1` and `k + 2`, mod 3, in that order):
/// `1` counter-clockwise, `-1` clockwise, `0` collinear. The sign of the
/// 3 × 3 determinant of their homogeneous `(·, ·, w)` rows (every `w >
/// 0`), by the `f64` approximations when they certify it and exactly in
/// 640 bits otherwise (each term below `2^561`, see [`Implicit`]).
pub(crate) fn turn(a: &Point, b: &Point, c: &Point, k: usize) -> i32 {
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    let approx = |p: &Point| match p {
        Point::Grid(g) => [g[i] as f64, g[j] as f64, 1.0],
        Point::Implicit(h) => {
            let x = h.approx();
            [x[i], x[j], x[3]]
        }
    };
    let [a1, b1, c1] = [approx(a), approx(b), approx(c)];
    let terms = [
        a1[0] * b1[1] * c1[2],
        -a1[0] * b1[2] * c1[1],
        -a1[1] * b1[0] * c1[2],
        a1[1] * b1[2] * c1[0],
        a1[2] * b1[0] * c1[1],
        -a1[2] * b1[1] * c1[0],
    ];
    let det: f64 = terms.iter().sum();
    // each input within 3u of its integer, each product two roundings
    // more, the sum five: below 16u of the terms' magnitudes; 2^-47 is
    // four times that
    let bound = terms.iter().map(|t| t.abs()).sum::<f64>() * (1.0 / (1u64 << 47) as f64);
    if det.abs() > bound {
        return if det > 0.0 { 1 } else { -1 };
    }
    type W = bnum::BInt<10>;
    let exact = |p: &Point| {
        let h = p.homogeneous();
        [h[i], h[j], h[3]].map(|x| x.as_::<W>())
    };
    let [a, b, c] = [exact(a), exact(b), exact(c)];
    let det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
        + a[2] * (b[0] * c[1] - b[1] * c[0]);
    det.signum().as_::<i32>()
}

/// Whether the grid point `g` is the implicit point `i`, exactly.
pub(crate) fn grid_is(g: &crate::kernel::GridPoint, i: &Implicit) -> bool {
    let h = i.coords();
    (0..3).all(|k| h[k] == wide(g[k] as i128) * h[3])
}

/// The `f64` nearest to `num / den` (ties to even), `den > 0`.
#[cfg(test)]
fn ratio_to_f64(num: I256, den: I256) -> f64 {
    crate::kernel::exact::ratio_to_f64_exact::<4, 9>(&num, &den)
}

/// A hash of approximate coordinates, each mantissa rounded to its top 36
/// bits (see [`Point::approx_key`]).
pub(crate) fn approx_key(a: [f64; 3]) -> u64 {
    hash_bits(a.map(|c| ((c + 0.0).to_bits() + 0x8000) & !0xffff))
}

/// A hash of three coordinates' bits.
pub(crate) fn hash_bits(bits: [u64; 3]) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = rustc_hash::FxHasher::default();
    bits.hash(&mut h);
    h.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exact product of two `i128`s ([`Wide::product`]) as a 256-bit
    /// integer.
    fn mul_wide(a: i128, b: i128) -> I256 {
        Wide::product(a, b).to_i256()
    }

    #[test]
    fn turns_are_exact_for_grid_and_implicit_points() {
        let g = |x: i32, y: i32, z: i32| Point::Grid([x, y, z]);
        let (o, x, y) = (g(0, 0, 0), g(1, 0, 0), g(0, 1, 0));
        assert_eq!(turn(&o, &x, &y, 2), 1);
        assert_eq!(turn(&o, &y, &x, 2), -1);
        assert_eq!(turn(&o, &x, &g(5, 0, 9), 2), 0);
        // seen along x: the axes y then z
        assert_eq!(turn(&o, &y, &g(0, 0, 1), 0), 1);
        // (1/3, 1/3, 0) and (2/3, 2/3, 0): on the diagonal through the
        // origin exactly, and a step off it either way
        let third = |k: i128, dy: i128| {
            let p = |n: [i64; 3], d: i128| Plane::new(n, d).unwrap();
            let z = p([0, 0, 1], 0);
            Point::from_planes(&p([3, 0, 0], -k), &p([0, 3, 0], -k - dy), &z).unwrap()
        };
        let (a, b) = (third(1, 0), third(2, 0));
        assert_eq!(turn(&o, &a, &b, 2), 0);
        assert_eq!(turn(&a, &b, &g(1, 1, 0), 2), 0);
        assert_eq!(turn(&o, &a, &third(2, 1), 2), 1);
        assert_eq!(turn(&o, &a, &third(2, -1), 2), -1);
        // far from the origin, where the filter cannot tell
        let big = 1i32 << 30;
        let far = |k: i128| {
            let p = |n: [i64; 3], d: i128| Plane::new(n, d).unwrap();
            let at = 3 * i128::from(big) + k;
            Point::from_planes(&p([3, 0, 0], -at), &p([0, 3, 0], -at), &p([0, 0, 1], 0)).unwrap()
        };
        assert_eq!(turn(&g(big, big, 0), &far(1), &far(2), 2), 0);
    }

    #[test]
    fn ratio_rounds_correctly() {
        let r = |a: i128, b: i128| ratio_to_f64(I256::from(a), I256::from(b));
        assert_eq!(r(1, 3), 1.0 / 3.0);
        assert_eq!(r(-2, 3), -2.0 / 3.0);
        assert_eq!(r(10, 5), 2.0);
        assert_eq!(r(7, 1 << 100), 7.0 / 2f64.powi(100));
        // 2^53 + 1 is a tie between 2^53 and 2^53 + 2: ties to even
        assert_eq!(r((1 << 53) + 1, 1), 9007199254740992.0);
        assert_eq!(r((1 << 53) + 3, 1), 9007199254740996.0);
        // just above the tie rounds up
        assert_eq!(r((1 << 54) + 2 + 1, 2), 9007199254740994.0);
        let big = I256::from(1i128 << 100) * I256::from(1i128 << 95) + I256::ONE;
        assert_eq!(ratio_to_f64(big, I256::ONE), 2f64.powi(195));
    }

    #[test]
    fn wide_products_are_exact() {
        let cases = [
            (0i128, 5i128),
            (-1, 1),
            (i128::MAX, i128::MAX),
            (-(1 << 126), (1 << 120) + 12345),
            (0x1234_5678_9abc_def0_1234_5678, -0x0fed_cba9_8765_4321_0fed),
        ];
        for (a, b) in cases {
            assert_eq!(mul_wide(a, b), I256::from(a) * I256::from(b), "{a} * {b}");
            assert_eq!(mul_wide(b, -a), I256::from(b) * I256::from(-a));
        }
    }

    proptest::proptest! {
        /// Sums of signed products in the native 128-bit halves equal the
        /// general 256-bit arithmetic, signs and carries included.
        #[test]
        fn wide_sums_match_general_arithmetic(
            terms in proptest::collection::vec(
                (-(1i128 << 126)..(1i128 << 126), proptest::num::i128::ANY), 1..4),
        ) {
            let mut fast = Wide::ZERO;
            let mut slow = I256::ZERO;
            for &(a, b) in &terms {
                let b = b >> 1;
                fast = fast.add(Wide::product(a, b));
                slow += I256::from(a) * I256::from(b);
                proptest::prop_assert_eq!(Wide::product(a, b).neg().to_i256(), -(I256::from(a) * I256::from(b)));
            }
            proptest::prop_assert_eq!(fast.to_i256(), slow);
            proptest::prop_assert_eq!(fast.is_negative(), slow.is_negative());
            proptest::prop_assert_eq!(fast.is_zero(), slow.is_zero());
            proptest::prop_assert_eq!(fast.approx(), crate::kernel::exact::approx(&slow));
        }

        /// Comparing coordinates by sign and 512-bit magnitudes agrees with
        /// the general arithmetic, equal points included.
        #[test]
        fn coordinate_order_matches_general_arithmetic(
            n in proptest::collection::vec(-(1i64 << 40)..(1i64 << 40), 12),
            d in proptest::collection::vec(-(1i128 << 70)..(1i128 << 70), 4),
            same in proptest::bool::ANY,
        ) {
            let plane = |k: usize| Plane::new([n[3 * k], n[3 * k + 1], n[3 * k + 2]], d[k]);
            let planes: Vec<Plane> = (0..4).filter_map(plane).collect();
            proptest::prop_assume!(planes.len() == 4);
            let p = Implicit::from_planes(&planes[0], &planes[1], &planes[2]);
            // the same point from the planes in another order, or another point
            let q = if same {
                Implicit::from_planes(&planes[2], &planes[0], &planes[1])
            } else {
                Implicit::from_planes(&planes[0], &planes[1], &planes[3])
            };
            if let (Some(p), Some(q)) = (p, q) {
                for k in 0..3 {
                    proptest::prop_assert_eq!(p.cmp_axis(&q, k), p.cmp_axis_with::<8>(&q, k));
                    proptest::prop_assert_eq!(q.cmp_axis(&p, k), q.cmp_axis_with::<8>(&p, k));
                }
                proptest::prop_assert_eq!(p.same_point(&q), p.same_with::<8>(&q));
                if same {
                    proptest::prop_assert!(p.same_point(&q));
                }
                // the same point written with other coordinates
                let scaled = Implicit::new(p.coords().map(|c| c * I256::from(-3))).unwrap();
                proptest::prop_assert!(p.same_point(&scaled) && scaled.same_point(&p));
                for k in 0..3 {
                    proptest::prop_assert_eq!(scaled.cmp_axis(&q, k), p.cmp_axis_with::<8>(&q, k));
                }
            }
        }

        /// The crossing of a segment between grid points, at the ends of
        /// the grid, with a plane through three other grid points is the
        /// point the three planes give: the same point, on the plane,
        /// `w > 0`, and the `f64` approximations the filter expects.
        #[test]
        fn a_segment_crosses_a_plane_where_the_planes_meet(
            g in proptest::collection::vec(-crate::kernel::MAX_COORD..=crate::kernel::MAX_COORD, 18),
        ) {
            let pt = |k: usize| [g[3 * k], g[3 * k + 1], g[3 * k + 2]];
            let (p, q, r) = (pt(0), pt(1), pt(2));
            let Ok(plane) = Plane::through(pt(3), pt(4), pt(5)) else {
                return Ok(());
            };
            let (sp, sq) = (plane.classify_grid(p), plane.classify_grid(q));
            proptest::prop_assume!(sp != Side::On && sq != Side::On && sp != sq);
            let Ok(support) = Plane::through(p, q, r) else {
                return Ok(());
            };
            let edge = Plane::edge(p, q, &support).expect("a plane along the edge");
            let via_planes = Implicit::from_planes(&support, &edge, &plane)
                .expect("the edge crosses the plane");
            let direct = Implicit::on_segment(&p, &q, &plane);
            proptest::prop_assert!(direct.same_point(&via_planes));
            proptest::prop_assert!(direct.coords()[3].is_positive());
            for c in 0..4 {
                proptest::prop_assert_eq!(
                    direct.approx()[c],
                    crate::kernel::exact::approx(&direct.coords()[c])
                );
            }
            let (a, b) = (Point::Grid(p), Point::Grid(q));
            for x in [
                Point::crossing(&a, &b, &support, &edge, &plane),
                Point::crossing(&b, &a, &support, &edge.flip(), &plane),
            ] {
                proptest::prop_assert_eq!(x.classify(&plane), Side::On);
                proptest::prop_assert_eq!(x.classify(&support), Side::On);
                proptest::prop_assert!(x.same_point(&Point::Implicit(Arc::new(via_planes.clone()))));
            }
        }

        /// The intersection of three planes with large coefficients is the
        /// solution of the system, checked in the general arithmetic: the
        /// point lies on each plane and `w > 0`.
        #[test]
        fn implicit_points_lie_on_their_planes(
            n in proptest::collection::vec(-(1i64 << 40)..(1i64 << 40), 9),
            d in proptest::collection::vec(-(1i128 << 70)..(1i128 << 70), 3),
        ) {
            let planes: Vec<Plane> = (0..3)
                .filter_map(|k| Plane::new([n[3 * k], n[3 * k + 1], n[3 * k + 2]], d[k]))
                .collect();
            proptest::prop_assume!(planes.len() == 3);
            if let Some(p) = Implicit::from_planes(&planes[0], &planes[1], &planes[2]) {
                let h = p.coords();
                proptest::prop_assert!(h[3].is_positive());
                for q in &planes {
                    let m = q.normal();
                    let v = I256::from(m[0]) * h[0]
                        + I256::from(m[1]) * h[1]
                        + I256::from(m[2]) * h[2]
                        + I256::from(q.offset()) * h[3];
                    proptest::prop_assert!(v.is_zero());
                }
            }
        }
    }

    #[test]
    fn implicit_point_of_axis_planes() {
        let x = Plane::new([1, 0, 0], -3).unwrap();
        let y = Plane::new([0, 2, 0], 10).unwrap();
        let z = Plane::new([0, 0, -1], 7).unwrap();
        let p = Point::from_planes(&x, &y, &z).unwrap();
        assert_eq!(p.to_f64(), [3.0, -5.0, 7.0]);
        assert_eq!(p.as_grid(), Some([3, -5, 7]));
        assert!(p.same_point(&Point::Grid([3, -5, 7])));
        assert_eq!(p.classify(&x), Side::On);
        let q = Plane::new([1, 1, 1], -5).unwrap();
        assert_eq!(p.classify(&q), Side::On);
        assert!(Point::from_planes(&x, &x.flip(), &z).is_none());
    }

    #[test]
    fn native_plane_meets_give_the_wide_coordinates() {
        // plane triples of every size the kernel makes: cell walls (axis
        // planes at half steps), edge planes (one zero, |n| < 2^27),
        // supports (|n| < 2^55, |d| < 2^83), and planes of random size;
        // where the native path takes them, its coordinates are the wide
        // path's bit for bit (and `None` for `None`)
        use crate::xorshift as next;
        // a random integer of at most `bits` bits, either sign
        fn int(state: &mut u64, bits: u32) -> i128 {
            let v = ((next(state) as u128) << 64 | next(state) as u128) >> (128 - bits);
            if next(state) & 1 == 0 {
                v as i128
            } else {
                -(v as i128)
            }
        }
        fn plane(s: &mut u64, kind: u64) -> Option<Plane> {
            let axis = |s: &mut u64| (next(s) % 3) as usize;
            match kind % 4 {
                0 => {
                    let mut n = [0i64; 3];
                    n[axis(s)] = if next(s) & 1 == 0 { -2 } else { 2 };
                    Plane::new(n, 2 * int(s, 27) + 1)
                }
                1 => {
                    let mut n = [0; 3].map(|_| int(s, 27) as i64);
                    n[axis(s)] = 0;
                    Plane::new(n, int(s, 54))
                }
                2 => Plane::new([0; 3].map(|_| int(s, 55) as i64), int(s, 83)),
                _ => {
                    let b = 1 + (next(s) % 55) as u32;
                    let n = [0; 3].map(|_| int(s, b) as i64);
                    let bd = 1 + (next(s) % 83) as u32;
                    Plane::new(n, int(s, bd))
                }
            }
        }
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let (mut native, mut wide) = (0, 0);
        for i in 0..30_000u64 {
            let p: Option<Vec<Plane>> = [i, i / 4, i / 16]
                .into_iter()
                .map(|k| plane(&mut state, k))
                .collect();
            let Some(p) = p else {
                continue;
            };
            let n1 = p[0].normal();
            let c = [
                cross_wide(p[1].normal(), p[2].normal()),
                cross_wide(p[2].normal(), n1),
                cross_wide(n1, p[1].normal()),
            ];
            let d = [p[0].offset(), p[1].offset(), p[2].offset()];
            let reference = from_planes_wide(n1, c, d);
            let Some(h) = from_planes_native(n1, c, d) else {
                wide += 1;
                continue;
            };
            native += 1;
            match &reference {
                None => assert_eq!(h[3], 0, "{p:?}"),
                Some(r) => assert_eq!(r.coords(), &h.map(I256::from), "{p:?}"),
            }
            let via = Implicit::from_planes(&p[0], &p[1], &p[2]);
            assert_eq!(via.map(|v| *v.coords()), reference.map(|r| *r.coords()));
        }
        assert!(
            native > 5_000 && wide > 5_000,
            "native {native}, wide {wide}"
        );
    }
}
