//! Exact points: grid points and implicit intersections of three planes.

use bnum::cast::As;
use bnum::types::{I256, I512, U512};

use crate::Side;
use crate::grid::GridPoint;
use crate::plane::Plane;

/// An exact point: either an input grid point or the intersection of three
/// planes of the input budget, held in homogeneous integer coordinates.
#[derive(Clone, Debug)]
pub enum Point {
    /// An input vertex on the grid.
    Grid(GridPoint),
    /// The intersection of three planes.
    Implicit(Box<Implicit>),
}

/// The homogeneous coordinates `(x, y, z, w)`, `w > 0`, of the intersection
/// of three planes, with their `f64` roundings for the filter.
///
/// Bounds: `|w| < 2^168`, `|x|, |y|, |z| < 2^196`; see
/// `docs/architecture.md`.
#[derive(Clone, Debug)]
pub struct Implicit {
    h: [I256; 4],
    approx: [f64; 4],
}

/// `2^-48`: relative error bound of the filter (8 rounding errors of
/// `2^-53` are at most `2^-50`; a factor 4 margin).
const FILTER_REL: f64 = 1.0 / (1u64 << 48) as f64;

fn wide(x: i128) -> I256 {
    I256::from(x)
}

fn cross_wide(a: [i64; 3], b: [i64; 3]) -> [i128; 3] {
    let m = |x: i64, y: i64| x as i128 * y as i128;
    [
        m(a[1], b[2]) - m(a[2], b[1]),
        m(a[2], b[0]) - m(a[0], b[2]),
        m(a[0], b[1]) - m(a[1], b[0]),
    ]
}

impl Implicit {
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
            w += wide(n1[i] as i128) * wide(c23[i]);
        }
        if w.is_zero() {
            return None;
        }
        let (d1, d2, d3) = (wide(p1.offset()), wide(p2.offset()), wide(p3.offset()));
        // x · det = -(c23 d1 + c31 d2 + c12 d3); |x| < 3 · 2^111 · 2^83 < 2^196
        let mut h = [I256::ZERO; 4];
        for i in 0..3 {
            h[i] = -(wide(c23[i]) * d1 + wide(c31[i]) * d2 + wide(c12[i]) * d3);
        }
        h[3] = w;
        if w.is_negative() {
            for c in &mut h {
                *c = -*c;
            }
        }
        Some(Implicit::from_homogeneous(h))
    }

    fn from_homogeneous(h: [I256; 4]) -> Implicit {
        Implicit {
            approx: h.map(|c| c.as_::<f64>()),
            h,
        }
    }

    /// The homogeneous coordinates `(x, y, z, w)` with `w > 0`.
    pub fn homogeneous(&self) -> &[I256; 4] {
        &self.h
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
        let p = plane.approx();
        let a = &self.approx;
        let t = [p[0] * a[0], p[1] * a[1], p[2] * a[2], p[3] * a[3]];
        let v = (t[0] + t[1]) + (t[2] + t[3]);
        let m = (t[0].abs() + t[1].abs()) + (t[2].abs() + t[3].abs());
        let bound = m * FILTER_REL;
        if v > bound {
            Some(Side::Front)
        } else if v < -bound {
            Some(Side::Back)
        } else {
            None
        }
    }

    /// The exact path: the sign of `n · (x, y, z) + d w` in 256 bits
    /// (`< 2^254` in magnitude).
    pub fn classify_exact(&self, plane: &Plane) -> Side {
        let n = plane.normal();
        let h = &self.h;
        let v = wide(n[0] as i128) * h[0]
            + wide(n[1] as i128) * h[1]
            + wide(n[2] as i128) * h[2]
            + wide(plane.offset()) * h[3];
        Side::from_sign(v.signum().as_::<i32>())
    }
}

impl Point {
    /// The intersection of three planes (see [`Implicit::from_planes`]).
    pub fn from_planes(p1: &Plane, p2: &Plane, p3: &Plane) -> Option<Point> {
        Implicit::from_planes(p1, p2, p3).map(|i| Point::Implicit(Box::new(i)))
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
            Point::Implicit(i) => i.h,
        }
    }

    /// Grid coordinates as `f64`, within a few ulps of the exact values
    /// (from the cached roundings: fast, but not canonical — use
    /// [`Point::to_f64`] for output).
    #[inline]
    pub fn approx_f64(&self) -> [f64; 3] {
        match self {
            Point::Grid(g) => g.map(|c| c as f64),
            Point::Implicit(i) => {
                let a = &i.approx;
                [a[0] / a[3], a[1] / a[3], a[2] / a[3]]
            }
        }
    }

    /// Grid coordinates as `f64`, each the correctly rounded value of the
    /// exact rational coordinate. Equal points give equal results however
    /// they were constructed.
    pub fn to_f64(&self) -> [f64; 3] {
        match self {
            Point::Grid(g) => g.map(|c| c as f64),
            Point::Implicit(i) => [
                ratio_to_f64(i.h[0], i.h[3]),
                ratio_to_f64(i.h[1], i.h[3]),
                ratio_to_f64(i.h[2], i.h[3]),
            ],
        }
    }

    /// `Some` grid point if this point has integer coordinates within the grid.
    pub fn as_grid(&self) -> Option<GridPoint> {
        match self {
            Point::Grid(g) => Some(*g),
            Point::Implicit(i) => {
                let w = i.h[3];
                let mut out = [0i32; 3];
                for (o, h) in out.iter_mut().zip(&i.h[..3]) {
                    if !(*h % w).is_zero() {
                        return None;
                    }
                    let q = *h / w;
                    if q.unsigned_abs().bits() > 31 {
                        return None;
                    }
                    *o = q.as_::<i32>();
                }
                (out.iter().all(|c| c.abs() <= crate::MAX_COORD)).then_some(out)
            }
        }
    }

    /// Exact equality of the represented points.
    pub fn same_point(&self, o: &Point) -> bool {
        match (self, o) {
            (Point::Grid(a), Point::Grid(b)) => a == b,
            _ => {
                let a = self.homogeneous();
                let b = o.homogeneous();
                // a/aw == b/bw  <=>  a * bw == b * aw, in 512 bits
                let big = |x: I256| x.as_::<bnum::types::I512>();
                (0..3).all(|k| big(a[k]) * big(b[3]) == big(b[k]) * big(a[3]))
            }
        }
    }
}

/// The `f64` nearest to `num / den` (ties to even), `den > 0`.
fn ratio_to_f64(num: I256, den: I256) -> f64 {
    rational_to_f64(num.as_::<I512>(), den.as_::<I512>())
}

/// The `f64` nearest to the rational `num / den` (round to nearest, ties
/// to even). Requires `den > 0` and `|num|, den < 2^456`; the result is
/// then exact in the sense that equal rationals give equal `f64`s however
/// they are written.
///
/// ```
/// use bsp_core::rational_to_f64;
/// use bsp_core::I512;
/// assert_eq!(rational_to_f64(I512::from(1i32), I512::from(3i32)), 1.0 / 3.0);
/// assert_eq!(rational_to_f64(I512::from(-4i32), I512::from(2i32)), -2.0);
/// ```
pub fn rational_to_f64(num: I512, den: I512) -> f64 {
    if num.is_zero() {
        return 0.0;
    }
    let neg = num.is_negative();
    let a: U512 = num.unsigned_abs();
    let b: U512 = den.unsigned_abs();
    let (la, lb) = (a.bits() as i32, b.bits() as i32);
    assert!(
        la <= 456 && lb <= 456 && lb > 0,
        "rational_to_f64: operands out of range"
    );
    // choose shift so that q = floor(a 2^shift / b) has 55 or 56 bits
    let shift = 55 - (la - lb);
    let (mut n, mut d) = (a, b);
    if shift >= 0 {
        n <<= shift as u32;
    } else {
        d <<= (-shift) as u32;
    }
    let q = n / d;
    let sticky = !(n % d).is_zero();
    let mut q: u64 = q.as_::<u64>();
    let qbits = 64 - q.leading_zeros() as i32;
    let extra = qbits - 53;
    debug_assert!((2..=3).contains(&extra));
    let rem = q & ((1u64 << extra) - 1);
    q >>= extra;
    let half = 1u64 << (extra - 1);
    if rem > half || (rem == half && (sticky || q & 1 == 1)) {
        q += 1;
    }
    let e = extra - shift;
    let v = q as f64 * 2f64.powi(e);
    if neg { -v } else { v }
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
