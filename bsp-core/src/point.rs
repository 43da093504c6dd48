//! Exact points: grid points and implicit intersections of three planes.

use std::sync::Arc;

use bnum::cast::As;
use bnum::types::{I256, I512};

use crate::Side;
use crate::exact::Homogeneous;
use crate::grid::GridPoint;
use crate::plane::Plane;

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

/// The exact product of two `i128`s with magnitudes below `2^127`, as a
/// 256-bit integer: four 64 × 64-bit products (a general 256-bit
/// multiplication takes sixteen).
#[inline]
pub(crate) fn mul_wide(a: i128, b: i128) -> I256 {
    const M: u128 = u64::MAX as u128;
    let (ua, ub) = (a.unsigned_abs(), b.unsigned_abs());
    let (a0, a1) = (ua & M, ua >> 64);
    let (b0, b1) = (ub & M, ub >> 64);
    let (p00, p01, p10, p11) = (a0 * b0, a0 * b1, a1 * b0, a1 * b1);
    let t1 = (p00 >> 64) + (p01 & M) + (p10 & M);
    let t2 = (t1 >> 64) + (p01 >> 64) + (p10 >> 64) + (p11 & M);
    let t3 = (t2 >> 64) + (p11 >> 64);
    let u = bnum::types::U256::from_digits([p00 as u64, t1 as u64, t2 as u64, t3 as u64]);
    let v = u.as_::<I256>();
    if (a < 0) != (b < 0) { -v } else { v }
}

fn cross_wide(a: [i64; 3], b: [i64; 3]) -> [i128; 3] {
    let m = |x: i64, y: i64| x as i128 * y as i128;
    [
        m(a[1], b[2]) - m(a[2], b[1]),
        m(a[2], b[0]) - m(a[0], b[2]),
        m(a[0], b[1]) - m(a[1], b[0]),
    ]
}

impl Homogeneous<4> {
    /// The intersection of three planes, or `None` if they do not meet in a
    /// single point.
    pub fn from_planes(p1: &Plane, p2: &Plane, p3: &Plane) -> Option<Implicit> {
        let (n1, n2, n3) = (p1.normal(), p2.normal(), p3.normal());
        let c23 = cross_wide(n2, n3);
        let c31 = cross_wide(n3, n1);
        let c12 = cross_wide(n1, n2);
        // |c| < 2^111; det = n1 · c23, |det| < 2^168
        let mut w = I256::ZERO;
        for i in 0..3 {
            w += mul_wide(n1[i] as i128, c23[i]);
        }
        if w.is_zero() {
            return None;
        }
        let (d1, d2, d3) = (p1.offset(), p2.offset(), p3.offset());
        // x · det = -(c23 d1 + c31 d2 + c12 d3); |x| < 3 · 2^111 · 2^83 < 2^196
        let mut h = [I256::ZERO; 4];
        for i in 0..3 {
            h[i] = -(mul_wide(c23[i], d1) + mul_wide(c31[i], d2) + mul_wide(c12[i], d3));
        }
        h[3] = w;
        Homogeneous::new(h)
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
    /// [`Homogeneous::round_with`]).
    pub fn to_f64(&self) -> [f64; 3] {
        self.round_with::<9>()
    }

    /// Exact equality of the represented points (at once for the same
    /// allocation: equal new vertices are shared, see `share_points`).
    pub fn same_point(&self, o: &Implicit) -> bool {
        std::ptr::eq(self, o) || self.same_with::<8>(o)
    }

    /// Exact comparison of coordinate `k` with another point's.
    pub fn cmp_axis(&self, o: &Implicit, k: usize) -> std::cmp::Ordering {
        self.cmp_axis_with::<8>(o, k)
    }
}

impl Point {
    /// The intersection of three planes (see [`Implicit::from_planes`]).
    pub fn from_planes(p1: &Plane, p2: &Plane, p3: &Plane) -> Option<Point> {
        Implicit::from_planes(p1, p2, p3).map(|i| Point::Implicit(Arc::new(i)))
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
        match self {
            Point::Grid(g) => Some(*g),
            Point::Implicit(i) => {
                let c = i.as_integer()?;
                c.iter()
                    .all(|v| v.abs() <= crate::MAX_COORD as i64)
                    .then(|| c.map(|v| v as i32))
            }
        }
    }

    /// Exact equality of the represented points.
    pub fn same_point(&self, o: &Point) -> bool {
        match (self, o) {
            (Point::Grid(a), Point::Grid(b)) => a == b,
            (Point::Implicit(a), Point::Implicit(b)) => a.same_point(b),
            (Point::Grid(g), Point::Implicit(i)) | (Point::Implicit(i), Point::Grid(g)) => {
                let h = i.coords();
                (0..3).all(|k| h[k] == wide(g[k] as i128) * h[3])
            }
        }
    }
}

/// The `f64` nearest to `num / den` (ties to even), `den > 0`.
#[cfg(test)]
fn ratio_to_f64(num: I256, den: I256) -> f64 {
    crate::exact::ratio_to_f64_exact::<4, 9>(&num, &den)
}

/// The `f64` nearest to the rational `num / den` (round to nearest, ties
/// to even), by long division. Requires `den > 0`; equal rationals give
/// equal `f64`s however they are written.
///
/// ```
/// use bsp_core::rational_to_f64;
/// use bsp_core::I512;
/// assert_eq!(rational_to_f64(I512::from(1i32), I512::from(3i32)), 1.0 / 3.0);
/// assert_eq!(rational_to_f64(I512::from(-4i32), I512::from(2i32)), -2.0);
/// ```
pub fn rational_to_f64(num: I512, den: I512) -> f64 {
    assert!(
        den.is_positive(),
        "rational_to_f64: the denominator must be positive"
    );
    crate::exact::ratio_to_f64_exact::<8, 9>(&num, &den)
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
