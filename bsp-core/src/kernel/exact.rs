//! Exact homogeneous points of any integer width, and the one
//! floating-point filter every tier uses.
//!
//! A point is `(x, y, z, w)` with `w > 0` in fixed-width integers
//! (`bnum::BInt<N>`, `N` limbs of 64 bits), plus `f64` approximations of
//! its four coordinates. The input tier (points where three input planes
//! meet) uses `N = 4` (256 bits); the shadow tier of `svbsp` uses `N = 8`
//! (512 bits). Everything here is written once for every width:
//!
//! - [`filter_side`]: the sign of a plane at a point from the `f64`
//!   approximations, or `None` when rounding could have changed it;
//! - correctly rounded conversion to `f64` ([`Homogeneous::round_with`]),
//!   which multiplies and compares but does not divide in the common case;
//! - exact comparison of coordinates and exact point identity.
//!
//! The error bounds are in `docs/architecture.md` ("The floating-point
//! filter").

use std::cmp::Ordering;

use bnum::cast::As;
use bnum::{BInt, BUint};

use crate::kernel::Side;

/// `2^-48`: the filter's relative error bound. Each of the eight inputs
/// of a 4-term dot product carries a relative error of at most `3u`
/// (`u = 2^-53`, see [`approx`]), each product one more rounding and the
/// sum three: at most `10u · Σ|terms| < 2^-49.6 · Σ|terms|` in all, which
/// this bound covers three times over.
pub(crate) const FILTER_REL: f64 = 1.0 / (1u64 << 48) as f64;

/// The sign of `plane · point` (four terms) when the `f64` evaluation
/// certifies it, `None` when the value is too close to zero to tell.
///
/// Both arguments are approximations of exact integers with relative
/// error at most `3 · 2^-53` each (as [`approx`] and plain `i64 as f64`
/// conversions give). The answer is never wrong; `None` sends the caller
/// to its exact path.
#[inline]
pub fn filter_side(plane: &[f64; 4], point: &[f64; 4]) -> Option<Side> {
    let (v, m) = dot4(plane, point);
    sign_beyond(v, m * FILTER_REL)
}

/// The `f64` dot product of two 4-vectors, and the sum of its terms'
/// absolute values.
#[inline]
fn dot4(a: &[f64; 4], b: &[f64; 4]) -> (f64, f64) {
    let t = [a[0] * b[0], a[1] * b[1], a[2] * b[2], a[3] * b[3]];
    let v = (t[0] + t[1]) + (t[2] + t[3]);
    let m = (t[0].abs() + t[1].abs()) + (t[2].abs() + t[3].abs());
    (v, m)
}

/// The sign of `v` if it is beyond `±bound`.
#[inline]
fn sign_beyond(v: f64, bound: f64) -> Option<Side> {
    if v > bound {
        Some(Side::Front)
    } else if v < -bound {
        Some(Side::Back)
    } else {
        None
    }
}

/// [`filter_side`] for a point whose approximations carry absolute
/// errors: `|point[i] - x_i| <= err[i]` for the exact coordinates `x_i`.
///
/// With plane coefficients of relative error at most `3u`, the computed
/// value differs from the true one by at most `8u · Σ|terms| + (1 + 5u) ·
/// Σ|plane[i]| err[i]` (`u = 2^-53`); the bound used, `2^-48 · Σ|terms| +
/// 1.0625 · Σ|plane[i]| err[i]`, covers it with room for the rounding of
/// the bound itself. With `err = 0` this is [`filter_side`].
#[inline]
pub fn filter_side_err(plane: &[f64; 4], point: &[f64; 4], err: &[f64; 4]) -> Option<Side> {
    let (v, m) = dot4(plane, point);
    let e = (plane[0].abs() * err[0] + plane[1].abs() * err[1])
        + (plane[2].abs() * err[2] + plane[3].abs() * err[3]);
    sign_beyond(v, m * FILTER_REL + e * 1.0625)
}

/// The sign of twice the signed area of a ring, `Σ (x_i y_(i+1) −
/// x_(i+1) y_i)`, when its `f64` evaluation certifies it; `None` when the
/// value is too close to zero to tell (the caller then decides exactly).
///
/// Every coordinate must be its exact value correctly rounded (relative
/// error at most `u = 2^-53`). Each product then carries a relative error
/// of at most `γ3` (`γn = nu / (1 − nu)`), each difference one more
/// rounding and the running sum of `m` terms `m − 1` more, so the computed
/// sum is within `γ(m+3) · T` of the exact one, `T` the exact sum of the
/// products' magnitudes; the computed `t` is at least `T (1 − γ(m+4))`.
/// The bound used, `(m + 4) u · t`, is rounded once more (the factor
/// `2^-53` is exact), so it is at least `(m + 4) u (1 − u) (1 − γ(m+4)) T`.
/// Its excess over `γ(m+3) T` is about `u T (1 − 2 (m + 4)² u)`: it is
/// gone near `m = 2^26`. For `m < 2^24`, evaluated exactly at the worst
/// case `m = 2^24 − 1`, the excess is above `0.937 u T`. That margin also
/// covers the products that underflow (at most `2m`, each off by at most
/// `2^-1075`: below `2^-1050` in all) as long as `t >= 2^-968`. Longer
/// rings, smaller, infinite or NaN sums answer `None`.
pub fn filter_ring_area(ring: impl Iterator<Item = [f64; 2]> + Clone) -> Option<i32> {
    let mut pts = ring.clone().chain(ring.take(1));
    let Some(mut a) = pts.next() else {
        return Some(0);
    };
    let (mut s, mut t, mut m) = (0.0f64, 0.0f64, 0u64);
    for b in pts {
        let (x, y) = (a[0] * b[1], b[0] * a[1]);
        s += x - y;
        t += x.abs() + y.abs();
        m += 1;
        a = b;
    }
    if m >= 1 << 24 || !t.is_finite() || t < pow2(-968) {
        return None;
    }
    let bound = t * (m + 4) as f64 * pow2(-53);
    match sign_beyond(s, bound)? {
        Side::Front => Some(1),
        _ => Some(-1),
    }
}

/// `2^e` as an `f64`, for `-1022 <= e <= 1023`.
#[inline]
pub(crate) fn pow2(e: i32) -> f64 {
    debug_assert!((-1022..=1023).contains(&e));
    f64::from_bits(((1023 + e) as u64) << 52)
}

/// A fast approximation of a big integer, with relative error below
/// `3 · 2^-53`: the top two non-zero 64-bit limbs, converted and added.
#[inline]
pub fn approx<const N: usize>(x: &BInt<N>) -> f64 {
    let neg = x.is_negative();
    let u = x.unsigned_abs();
    let d = u.digits();
    let mut i = N;
    while i > 0 && d[i - 1] == 0 {
        i -= 1;
    }
    let v = match i {
        0 => return 0.0,
        1 => d[0] as f64,
        _ => (d[i - 1] as f64 * pow2(64) + d[i - 2] as f64) * pow2(64 * (i as i32 - 2)),
    };
    if neg { -v } else { v }
}

/// [`approx`] of an `i128`: the same value, without the wide integer.
#[inline]
pub(crate) fn approx_i128(x: i128) -> f64 {
    let u = x.unsigned_abs();
    let (hi, lo) = ((u >> 64) as u64, u as u64);
    let v = if hi == 0 {
        lo as f64
    } else {
        hi as f64 * pow2(64) + lo as f64
    };
    if x < 0 { -v } else { v }
}

/// `a / b` for unsigned `a`, `b > 0`, correctly rounded (ties to even) by
/// long division: `None` if `a` or `b` has more than `64 M - 64` bits.
fn ratio_by_division<const M: usize>(a: BUint<M>, b: BUint<M>) -> Option<f64> {
    if a.is_zero() {
        return Some(0.0);
    }
    let (la, lb) = (a.bits() as i32, b.bits() as i32);
    let room = 64 * M as i32 - 64;
    if la > room || lb > room || lb == 0 {
        return None;
    }
    // q = floor(a 2^shift / b) has 55 or 56 bits
    let shift = 55 - (la - lb);
    let (mut n, mut d) = (a, b);
    if shift >= 0 {
        if la + shift > 64 * M as i32 - 1 {
            return None;
        }
        n <<= shift as u32;
    } else {
        if lb - shift > 64 * M as i32 - 1 {
            return None;
        }
        d <<= (-shift) as u32;
    }
    let q = n / d;
    let sticky = !(n % d).is_zero();
    let mut q: u64 = q.as_::<u64>();
    let qbits = 64 - q.leading_zeros() as i32;
    let extra = qbits - 53;
    let rem = q & ((1u64 << extra) - 1);
    q >>= extra;
    let half = 1u64 << (extra - 1);
    if rem > half || (rem == half && (sticky || q & 1 == 1)) {
        q += 1;
    }
    let e = extra - shift;
    // q < 2^54 and |e| is moderate: the product is exact unless it
    // overflows or underflows, which the callers' bounds exclude
    Some(q as f64 * 2f64.powi(e))
}

/// Compares the positive rational `a / b` with `k · 2^e` exactly; `None`
/// if the scaled operands would not fit `M` limbs.
fn cmp_scaled<const M: usize>(a: &BUint<M>, b: &BUint<M>, k: u64, e: i32) -> Option<Ordering> {
    let cap = 64 * M as i32 - 2;
    let (sa, sb) = (e.min(0).unsigned_abs() as i32, e.max(0));
    if a.bits() as i32 + sa > cap || b.bits() as i32 + 56 + sb > cap {
        return None;
    }
    let lhs = *a << sa as u32;
    let rhs = (*b * BUint::<M>::from(k)) << sb as u32;
    Some(lhs.cmp(&rhs))
}

/// `(⌊x / w⌋, ⌈x / w⌉)` for `w > 0` by division (the `i64`s wrap beyond
/// their range).
fn floor_ceil_by_division<const N: usize>(x: &BInt<N>, w: &BInt<N>) -> (i64, i64) {
    let (q, r) = (*x / *w, *x % *w);
    let q = q.as_::<i64>();
    match (r.is_zero(), x.is_negative()) {
        (true, _) => (q, q),
        (false, true) => (q - 1, q),
        (false, false) => (q, q + 1),
    }
}

/// `x`'s top 126 bits as a double-double: `(hi, lo, s)` with
/// `(hi + lo) 2^s` within `2^-104 x` of `x > 0`.
fn double_double<const N: usize>(x: &BUint<N>) -> (f64, f64, i32) {
    // the top 128 bits, read from the limbs (a wide shift is slower)
    let d = x.digits();
    let top = (0..N).rev().find(|&i| d[i] != 0).unwrap_or(0);
    let (v, s) = if top < 2 {
        let low = |i: usize| if i < N { d[i] as u128 } else { 0 };
        (low(1) << 64 | low(0), 0)
    } else {
        // the three top limbs shifted up by `lz`, their top 128 bits:
        // `x` truncated to `w 2^(64 (top - 1) - lz)`, within 2^-127 of it
        let lz = d[top].leading_zeros();
        let pair = (d[top] as u128) << 64 | d[top - 1] as u128;
        let w = if lz == 0 {
            pair
        } else {
            pair << lz | (d[top - 2] >> (64 - lz)) as u128
        };
        (w, 64 * (top as i32 - 1) - lz as i32)
    };
    // 126 bits at most, so that the residual below is an `i128`
    let extra = (128 - v.leading_zeros() as i32 - 126).max(0);
    let (v, s) = (v >> extra, s + extra);
    let hi = v as f64;
    // the residual of the rounding, below 2^73: its own rounding is below
    // 2^-105 of `v`
    let lo = (v as i128 - hi as i128) as f64;
    (hi, lo, s)
}

/// `a b` exactly, as `p + e` (Dekker's product, no fused multiply-add):
/// for `|a b|` well inside the exponent range.
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let split = |v: f64| {
        let c = 134_217_729.0 * v; // 2^27 + 1
        let h = c - (c - v);
        (h, v - h)
    };
    let p = a * b;
    let ((ah, al), (bh, bl)) = (split(a), split(b));
    (p, ((ah * bh - p) + ah * bl + al * bh) + al * bl)
}

/// The correctly rounded value of `a / b` (unsigned, `b > 0`) from a
/// double-double quotient, when it is certain: `None` within `2^-90` of
/// the quotient of a midpoint between two doubles (a possible tie or a
/// rounding the approximation cannot decide), and outside the normal range.
/// The quotient's error is below `2^-100` of it (the inputs' `2^-104` each,
/// the division's steps a few `2^-106`), so the margin is wide.
fn round_ratio_filtered<const M: usize>(a: &BUint<M>, b: &BUint<M>) -> Option<f64> {
    let (xh, xl, sx) = double_double(a);
    let (wh, wl, sw) = double_double(b);
    let q = xh / wh;
    // xh − q wh is a double, found exactly from the product's two parts
    let (p, e) = two_product(q, wh);
    let r = (xh - p) - e;
    let q2 = (r + xl - q * wl) / wh;
    let c = q + q2;
    let tail = (q - c) + q2;
    let bits = c.to_bits();
    let exp = ((bits >> 52) & 0x7ff) as i32;
    let m = bits & ((1u64 << 52) - 1);
    // the distances to the midpoints above and below `c` (the one below is
    // half as far at a power of two)
    let ulp = pow2(exp - 1075);
    let below = if m == 0 { ulp / 2.0 } else { ulp };
    let margin = c.abs() * pow2(-90);
    let scale = sx - sw;
    let certain = (1..0x7fe).contains(&exp)
        && ulp / 2.0 - tail > margin
        && below / 2.0 + tail > margin
        && (-1000..=1000).contains(&(exp - 1023 + scale));
    // scaling by a power of two in the normal range is exact, and rounds
    // as the quotient it scales
    certain.then(|| {
        let half = scale / 2;
        c * pow2(half) * pow2(scale - half)
    })
}

/// The correctly rounded (ties to even) value of `num / den`, `den > 0`,
/// starting from an estimate `guess` within a few ulps: the estimate is
/// accepted when the exact quotient lies between the midpoints to its
/// neighbours, which takes two multiplications and two comparisons;
/// otherwise it moves one ulp toward the quotient and tries again. Falls
/// back to long division when the estimate is unusable.
fn round_ratio<const N: usize, const M: usize>(num: &BInt<N>, den: &BInt<N>, guess: f64) -> f64 {
    if num.is_zero() {
        return 0.0;
    }
    let neg = num.is_negative();
    let signed = |v: f64| if neg { -v } else { v };
    let (a, b) = (num.unsigned_abs(), den.unsigned_abs());
    if let Some(v) = round_ratio_filtered(&a, &b) {
        return signed(v);
    }
    let a: BUint<M> = a.as_::<BUint<M>>();
    let b: BUint<M> = b.as_::<BUint<M>>();
    let mut c = guess.abs();
    // normal numbers only: the bounds of every tier keep coordinates far
    // from the subnormal range, and anything else goes the slow way
    if c.is_finite() && c >= pow2(-1000) && (guess < 0.0) == neg {
        for _ in 0..16 {
            let bits = c.to_bits();
            let exp = ((bits >> 52) & 0x7ff) as i32;
            if exp <= 2 || exp >= 0x7fe {
                break;
            }
            let m = (bits & ((1u64 << 52) - 1)) | (1u64 << 52);
            let e = exp - 1075;
            // the midpoint above c, and the one below (closer at a power of two)
            let hi = cmp_scaled(&a, &b, 2 * m + 1, e - 1);
            let lo = if m == 1u64 << 52 {
                cmp_scaled(&a, &b, 4 * m - 1, e - 2)
            } else {
                cmp_scaled(&a, &b, 2 * m - 1, e - 1)
            };
            let (Some(hi), Some(lo)) = (hi, lo) else {
                break;
            };
            let even = m & 1 == 0;
            match (lo, hi) {
                (Ordering::Greater, Ordering::Less) => return signed(c),
                (_, Ordering::Greater) => c = f64::from_bits(bits + 1),
                (Ordering::Less, _) => c = f64::from_bits(bits - 1),
                (_, Ordering::Equal) => {
                    return signed(if even { c } else { f64::from_bits(bits + 1) });
                }
                (Ordering::Equal, _) => {
                    return signed(if even { c } else { f64::from_bits(bits - 1) });
                }
            }
        }
    }
    let v = ratio_by_division::<M>(a, b)
        .expect("round_ratio: operands exceed the width chosen by the tier");
    signed(v)
}

/// An exact point in homogeneous integer coordinates `(x, y, z, w)` with
/// `w > 0`, of `64 N` bits each, and their `f64` approximations; its
/// correctly rounded Cartesian coordinates are kept once computed (a
/// mesh's vertex is asked for them by each of its corners).
#[derive(Clone, Debug)]
pub struct Homogeneous<const N: usize> {
    h: [BInt<N>; 4],
    approx: [f64; 4],
    rounded: std::sync::OnceLock<[f64; 3]>,
}

impl<const N: usize> Homogeneous<N> {
    /// The point `(x, y, z) / w`; the signs are flipped if `w < 0`.
    /// `None` if `w = 0` (a point at infinity).
    pub fn new(mut h: [BInt<N>; 4]) -> Option<Self> {
        if h[3].is_zero() {
            return None;
        }
        if h[3].is_negative() {
            for c in &mut h {
                *c = -*c;
            }
        }
        Some(Homogeneous {
            approx: [approx(&h[0]), approx(&h[1]), approx(&h[2]), approx(&h[3])],
            h,
            rounded: std::sync::OnceLock::new(),
        })
    }

    /// The point from coordinates with `w > 0` and their approximations
    /// as [`approx`] gives them (for a caller that has them cheaper).
    pub(crate) fn with_approx(h: [BInt<N>; 4], approx: [f64; 4]) -> Self {
        debug_assert!(h[3].is_positive());
        debug_assert!((0..4).all(|i| approx[i] == self::approx(&h[i])));
        Homogeneous {
            h,
            approx,
            rounded: std::sync::OnceLock::new(),
        }
    }

    /// The correctly rounded coordinates, once computed.
    #[inline]
    pub(crate) fn rounded(&self) -> &std::sync::OnceLock<[f64; 3]> {
        &self.rounded
    }

    /// The homogeneous coordinates `(x, y, z, w)`, `w > 0`.
    #[inline]
    pub fn coords(&self) -> &[BInt<N>; 4] {
        &self.h
    }

    /// The `f64` approximations of the four coordinates (relative error
    /// below `3 · 2^-53` each).
    #[inline]
    pub fn approx(&self) -> &[f64; 4] {
        &self.approx
    }

    /// The filter for a plane given by its `f64` coefficients `[a, b, c, d]`
    /// (`a x + b y + c z + d w`): see [`filter_side`].
    #[inline]
    pub fn filter(&self, plane: &[f64; 4]) -> Option<Side> {
        filter_side(plane, &self.approx)
    }

    /// Cartesian coordinates from the approximations: within a few ulps,
    /// fast, not canonical.
    #[inline]
    pub fn approx_f64(&self) -> [f64; 3] {
        let a = &self.approx;
        [a[0] / a[3], a[1] / a[3], a[2] / a[3]]
    }

    /// The correctly rounded Cartesian coordinates, computing in `M`
    /// limbs (`M >= 2N + 1` always suffices).
    pub fn round_with<const M: usize>(&self) -> [f64; 3] {
        let g = self.approx_f64();
        [0, 1, 2].map(|k| round_ratio::<N, M>(&self.h[k], &self.h[3], g[k]))
    }

    /// Exact comparison of coordinate `k` (0, 1 or 2) with another point's:
    /// `x / w` against `x' / w'` is `x w'` against `x' w` (`w, w' > 0`).
    /// By the `f64` approximations when they tell; else by sign, then by
    /// the magnitudes' full products from widening multiplications of
    /// the `N`-limb values (a quarter of the limb products of a general
    /// multiplication in `2N` limbs).
    pub fn cmp_axis(&self, o: &Self, k: usize) -> Ordering {
        if let Some(ord) = self.cmp_axis_filtered(o, k) {
            return ord;
        }
        let sign = |x: &BInt<N>| (!x.is_zero() as i8) * if x.is_negative() { -1 } else { 1 };
        let (sa, sb) = (sign(&self.h[k]), sign(&o.h[k]));
        if sa != sb || sa == 0 {
            return sa.cmp(&sb);
        }
        let (lo, hi) = self.h[k].unsigned_abs().widening_mul(o.h[3].unsigned_abs());
        let (lo2, hi2) = o.h[k].unsigned_abs().widening_mul(self.h[3].unsigned_abs());
        let by_size = (hi, lo).cmp(&(hi2, lo2));
        if sa > 0 { by_size } else { by_size.reverse() }
    }

    /// Exact equality of the represented points ([`Homogeneous::cmp_axis`]).
    /// Equal coordinates (a point made twice from the same planes) are
    /// found without a product.
    pub fn same(&self, o: &Self) -> bool {
        self.h == o.h || (0..3).all(|k| self.cmp_axis(o, k) == Ordering::Equal)
    }

    /// [`Homogeneous::cmp_axis`] in the general arithmetic of `M >= 2N`
    /// limbs (the reference the tests check it against).
    pub fn cmp_axis_with<const M: usize>(&self, o: &Self, k: usize) -> Ordering {
        if let Some(ord) = self.cmp_axis_filtered(o, k) {
            return ord;
        }
        let w = |x: &BInt<N>| (*x).as_::<BInt<M>>();
        (w(&self.h[k]) * w(&o.h[3])).cmp(&(w(&o.h[k]) * w(&self.h[3])))
    }

    /// `(⌊x_k / w⌋, ⌈x_k / w⌉)` for coordinate `k`, exactly (as `i64`s,
    /// which a quotient beyond their range wraps): by the `f64`
    /// approximations where no integer lies within their error bound, by
    /// one exact product with the one integer that does, and by division
    /// beyond `2^40`.
    #[inline]
    pub fn floor_ceil(&self, k: usize) -> (i64, i64) {
        self.floor_ceil_fast(k)
            .unwrap_or_else(|| floor_ceil_by_division(&self.h[k], &self.h[3]))
    }

    /// [`Homogeneous::floor_ceil`] without a division: `None` when the
    /// quotient is beyond `2^40` in magnitude.
    #[inline]
    fn floor_ceil_fast(&self, k: usize) -> Option<(i64, i64)> {
        let p = self.approx[k] / self.approx[3];
        if p.is_nan() || p.abs() >= (1u64 << 40) as f64 {
            return None;
        }
        // the quotient is within 8u of the exact value (3u + 3u + u); its
        // interval widened to 16u stays outside that after rounding, and
        // is narrower than 2^-9: it holds one integer at most
        let err = p.abs() * (16.0 / (1u64 << 53) as f64);
        let (lo, hi) = (p - err, p + err);
        let f = lo.floor();
        if f != lo && hi < f + 1.0 {
            return Some((f as i64, f as i64 + 1));
        }
        let n = if f == lo { f as i64 } else { f as i64 + 1 };
        let nw = self.h[3].checked_mul(BInt::<N>::from(n))?;
        Some(match self.h[k].cmp(&nw) {
            Ordering::Equal => (n, n),
            Ordering::Less => (n - 1, n),
            Ordering::Greater => (n, n + 1),
        })
    }

    /// [`Homogeneous::cmp_axis`] by the `f64` approximations alone:
    /// `None` when they cannot tell.
    #[inline]
    pub(crate) fn cmp_axis_filtered(&self, o: &Self, k: usize) -> Option<Ordering> {
        let (p, q) = (self.approx[k] / self.approx[3], o.approx[k] / o.approx[3]);
        // each quotient is within 8u of the exact value (3u + 3u + u)
        let tol = (p.abs() + q.abs()) * (16.0 / (1u64 << 53) as f64);
        if p - q > tol {
            Some(Ordering::Greater)
        } else if q - p > tol {
            Some(Ordering::Less)
        } else {
            None
        }
    }

    /// [`Homogeneous::same`] in the general arithmetic of `M >= 2N` limbs.
    pub fn same_with<const M: usize>(&self, o: &Self) -> bool {
        (0..3).all(|k| self.cmp_axis_with::<M>(o, k) == Ordering::Equal)
    }

    /// `Some` integer coordinates if the point is a lattice point whose
    /// coordinates fit `i64`.
    pub fn as_integer(&self) -> Option<[i64; 3]> {
        let w = self.h[3];
        let mut out = [0i64; 3];
        for (o, h) in out.iter_mut().zip(&self.h[..3]) {
            if !(*h % w).is_zero() {
                return None;
            }
            let q = *h / w;
            if q.unsigned_abs().bits() > 62 {
                return None;
            }
            *o = q.as_::<i64>();
        }
        Some(out)
    }
}

/// The correctly rounded value of `num / den` (`den > 0`) for any width,
/// by long division in `M` limbs. Slow; [`Homogeneous::round_with`] is
/// the fast path.
#[cfg(test)]
pub(crate) fn ratio_to_f64_exact<const N: usize, const M: usize>(
    num: &BInt<N>,
    den: &BInt<N>,
) -> f64 {
    let neg = num.is_negative();
    let v = ratio_by_division::<M>(
        num.unsigned_abs().as_::<BUint<M>>(),
        den.unsigned_abs().as_::<BUint<M>>(),
    )
    .expect("ratio_to_f64_exact: operands exceed the width");
    if neg { -v } else { v }
}

/// A 256-bit two's complement integer in two `u128` halves, for sums of
/// products of `i128`s: the products and sums run on native 128-bit
/// operations (four 64 × 64-bit products each) instead of the general
/// 256-bit arithmetic. Sums wrap modulo `2^256`, so a sum whose true
/// value has fewer than 256 bits is exact whatever the order.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Wide {
    lo: u128,
    hi: u128,
}

impl Wide {
    pub(crate) const ZERO: Wide = Wide { lo: 0, hi: 0 };

    /// `a · b`, exactly (`|a|, |b| ≤ 2^127`: the magnitude is below
    /// `2^254`).
    #[inline]
    pub(crate) fn product(a: i128, b: i128) -> Wide {
        const M: u128 = u64::MAX as u128;
        let (ua, ub) = (a.unsigned_abs(), b.unsigned_abs());
        let (a0, a1) = (ua & M, ua >> 64);
        let (b0, b1) = (ub & M, ub >> 64);
        let (p00, p01, p10, p11) = (a0 * b0, a0 * b1, a1 * b0, a1 * b1);
        // the middle products' sum has up to 129 bits: its carry is 2^192
        let (mid, c_mid) = p01.overflowing_add(p10);
        let (lo, c_lo) = p00.overflowing_add(mid << 64);
        let hi = p11
            .wrapping_add(mid >> 64)
            .wrapping_add((c_mid as u128) << 64)
            .wrapping_add(c_lo as u128);
        let u = Wide { lo, hi };
        if (a < 0) != (b < 0) { u.neg() } else { u }
    }

    /// `self + o` (modulo `2^256`).
    #[inline]
    pub(crate) fn add(self, o: Wide) -> Wide {
        let (lo, c) = self.lo.overflowing_add(o.lo);
        Wide {
            lo,
            hi: self.hi.wrapping_add(o.hi).wrapping_add(c as u128),
        }
    }

    /// `-self` (modulo `2^256`).
    #[inline]
    pub(crate) fn neg(self) -> Wide {
        let (lo, c) = (!self.lo).overflowing_add(1);
        Wide {
            lo,
            hi: (!self.hi).wrapping_add(c as u128),
        }
    }

    #[inline]
    pub(crate) fn is_zero(self) -> bool {
        self.lo == 0 && self.hi == 0
    }

    #[inline]
    pub(crate) fn is_negative(self) -> bool {
        (self.hi as i128) < 0
    }

    /// [`crate::kernel::exact::approx`] of the same value, from the halves.
    #[inline]
    pub(crate) fn approx(self) -> f64 {
        use crate::kernel::exact::pow2;
        let neg = self.is_negative();
        let u = if neg { self.neg() } else { self };
        let d = [
            u.lo as u64,
            (u.lo >> 64) as u64,
            u.hi as u64,
            (u.hi >> 64) as u64,
        ];
        let v = match d.iter().rposition(|&x| x != 0) {
            None => return 0.0,
            Some(0) => d[0] as f64,
            Some(i) => (d[i] as f64 * pow2(64) + d[i - 1] as f64) * pow2(64 * (i as i32 - 1)),
        };
        if neg { -v } else { v }
    }

    /// The same value as a [`I256`](bnum::types::I256).
    #[inline]
    pub(crate) fn to_i256(self) -> bnum::types::I256 {
        let digits = [
            self.lo as u64,
            (self.lo >> 64) as u64,
            self.hi as u64,
            (self.hi >> 64) as u64,
        ];
        bnum::types::I256::from_bits(bnum::types::U256::from_digits(digits))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use bnum::types::{I256, I512};

    fn i(v: i128) -> I256 {
        I256::from(v)
    }

    #[test]
    fn approx_is_close() {
        let big = I256::from(3i128 << 100) * I256::from((1i128 << 90) + 12345) + I256::from(7);
        let exact = ratio_to_f64_exact::<4, 9>(&big, &I256::ONE);
        let a = approx(&big);
        assert!(((a - exact) / exact).abs() < 3.0 / (1u64 << 53) as f64);
        assert_eq!(approx(&i(-5)), -5.0);
        assert_eq!(approx(&I256::ZERO), 0.0);
        assert_eq!(approx(&i(1 << 70)), 2f64.powi(70));
    }

    #[test]
    fn rounding_matches_division() {
        // a deterministic sweep of awkward quotients
        let mut s = 0x1234_5678_9abc_def0u64;
        let mut next = || crate::xorshift(&mut s);
        for _ in 0..20_000 {
            let shift = next() % 150;
            let num = (I256::from(next() as i64) * I256::from((next() >> 3) as i64))
                << (shift as u32 / 2);
            let den = I256::from((next() >> 1) as i64 | 1) << (next() % 60) as u32;
            let p = Homogeneous::<4>::new([num, -num, num + I256::ONE, den]).unwrap();
            let got = p.round_with::<9>();
            let want = [
                ratio_to_f64_exact::<4, 9>(&num, &den),
                ratio_to_f64_exact::<4, 9>(&-num, &den),
                ratio_to_f64_exact::<4, 9>(&(num + I256::ONE), &den),
            ];
            assert_eq!(got, want, "{num} / {den}");
        }
    }

    #[test]
    fn floors_and_ceilings_are_exact() {
        // quotients near integers (k w ± 1, k w, k w ± w / 2) and of every
        // size: the answers are the exact ones, and come for every
        // quotient below 2^40
        let mut s = 0x0bad_cafe_f00d_1234u64;
        let mut next = || crate::xorshift(&mut s);
        let (mut small, mut answered) = (0, 0);
        for _ in 0..20_000 {
            let w = I256::from((next() >> 1) as i64 | 1) << (next() % 90) as u32;
            let k = I256::from((next() as i64) >> (next() % 64));
            let near = [I256::ZERO, I256::ONE, -I256::ONE][(next() % 3) as usize];
            let x = k * w + near + I256::from((next() % 3) as i64 - 1) * (w >> 1u32);
            let p = Homogeneous::<4>::new([x, -x, x + I256::ONE, w]).unwrap();
            for (c, x) in [x, -x, x + I256::ONE].into_iter().enumerate() {
                let exact = floor_ceil_by_division(&x, &w);
                small += (exact.1.abs() < 1 << 39) as usize;
                if let Some(got) = p.floor_ceil_fast(c) {
                    assert_eq!(got, exact, "{x} / {w}");
                    answered += 1;
                }
                assert_eq!(p.floor_ceil(c), exact);
            }
        }
        assert!(answered >= small, "{answered} of {small}");
        let whole = Homogeneous::<4>::new([i(6), i(-9), i(7), i(3)]).unwrap();
        assert_eq!(whole.floor_ceil_fast(0), Some((2, 2)));
        assert_eq!(whole.floor_ceil_fast(1), Some((-3, -3)));
        assert_eq!(whole.floor_ceil_fast(2), Some((2, 3)));
    }

    #[test]
    fn the_double_double_rounding_is_exact_or_declines() {
        // random quotients, and ones within a hair of a midpoint between
        // two doubles (2m + 1) 2^(e-1) ± d / den: the filter answers only
        // with the correctly rounded value, and answers most
        let mut s = 0x5eed_1234_abcd_9876u64;
        let mut next = || crate::xorshift(&mut s);
        let (mut answered, mut near_declined, total) = (0, 0, 30_000);
        for t in 0..total {
            let den = I256::from((next() >> 1) as i64 | 1) << (next() % 70) as u32;
            let num = if t % 2 == 0 {
                (I256::from(next() as i64).abs() * I256::from((next() >> 2) as i64))
                    << (next() % 60) as u32
            } else {
                let mid = I256::from(((next() >> 11) | 1 << 53) as i64 | 1);
                let d = [I256::ZERO, I256::ONE, -I256::ONE][(next() % 3) as usize];
                ((mid * den) << (next() % 40) as u32) + d
            };
            if num <= I256::ZERO {
                continue;
            }
            let (a, b) = (num.unsigned_abs(), den.unsigned_abs());
            let want = ratio_to_f64_exact::<4, 9>(&num, &den);
            match round_ratio_filtered::<4>(&a, &b) {
                Some(got) => {
                    assert_eq!(got, want, "{num} / {den}");
                    answered += 1;
                }
                None if t % 2 == 1 => near_declined += 1,
                None => {}
            }
        }
        // nearly every random quotient is answered (one in 2^37 or so is
        // near a midpoint)
        assert!(answered > total / 2 - 10, "{answered}");
        // the midpoints themselves and their nearest neighbours are left to
        // the exact path
        assert!(near_declined > total / 4, "{near_declined}");
    }

    #[test]
    fn ties_go_to_even() {
        // (2^53 + 1) / 1 is a tie between 2^53 and 2^53 + 2
        let p = Homogeneous::<4>::new([i((1 << 53) + 1), i((1 << 53) + 3), i(1), i(1)]).unwrap();
        assert_eq!(p.round_with::<9>()[0], 9007199254740992.0);
        assert_eq!(p.round_with::<9>()[1], 9007199254740996.0);
        // 1/3 and a tie below a power of two
        let q = Homogeneous::<4>::new([i(1), i(-2), i((1 << 54) - 1), i(3)]).unwrap();
        assert_eq!(q.round_with::<9>()[0], 1.0 / 3.0);
        assert_eq!(q.round_with::<9>()[1], -2.0 / 3.0);
        let r = Homogeneous::<4>::new([i((1 << 54) - 1), i(0), i(0), i(2)]).unwrap();
        assert_eq!(r.round_with::<9>()[0], ((1u64 << 54) - 1) as f64 / 2.0);
    }

    #[test]
    fn comparisons_and_identity_are_exact() {
        let a = Homogeneous::<4>::new([i(1), i(2), i(3), i(3)]).unwrap();
        let b = Homogeneous::<4>::new([i(-2), i(-4), i(-6), i(-6)]).unwrap();
        assert!(a.same_with::<8>(&b));
        let c = Homogeneous::<4>::new([i(1 << 100), i(2), i(3), i((1 << 100) * 3 + 1)]).unwrap();
        assert_eq!(c.cmp_axis_with::<8>(&a, 0), Ordering::Less);
        assert_eq!(a.cmp_axis_with::<8>(&c, 0), Ordering::Greater);
        assert!(!a.same_with::<8>(&c));
        assert_eq!(
            Homogeneous::<4>::new([i(6), i(-4), i(2), i(2)])
                .unwrap()
                .as_integer(),
            Some([3, -2, 1])
        );
        assert_eq!(a.as_integer(), None);
        assert!(Homogeneous::<4>::new([i(1), i(1), i(1), i(0)]).is_none());
        let w =
            Homogeneous::<8>::new([I512::from(5), I512::ONE, I512::ONE, I512::from(-10)]).unwrap();
        assert_eq!(w.round_with::<17>(), [-0.5, -0.1, -0.1]);
    }

    #[test]
    fn ring_area_filter_is_never_wrong() {
        let square = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]];
        assert_eq!(filter_ring_area(square.iter().copied()), Some(1));
        assert_eq!(filter_ring_area(square.iter().rev().copied()), Some(-1));
        // no area: the filter cannot certify a sign, the caller decides
        let flat = [[0.0, 0.0], [1.0, 1.0], [3.0, 3.0]];
        assert_eq!(filter_ring_area(flat.iter().copied()), None);
        // below the underflow guard
        let tiny = square.map(|p| p.map(|c| c * pow2(-1000)));
        assert_eq!(filter_ring_area(tiny.iter().copied()), None);
        // near-degenerate rings of large integers (exact in f64): a
        // certified sign is the exact one
        let mut rng = crate::tree::SplitMix(0x51de);
        let mut certified = 0;
        for _ in 0..20_000 {
            // offsets from 2^10 to 2^50: far ones leave the small area
            // below the filter's bound, near ones not
            let big = 1i64 << (10 + rng.next_u64() % 41);
            let a = [0, 1].map(|_| (rng.next_u64() % (2 * big as u64)) as i64 - big);
            let d = [0, 1].map(|_| (rng.next_u64() % 1000) as i64 + 1);
            // three nearly collinear points and a fourth off the line
            let k = (rng.next_u64() % 7) as i64 - 3;
            let ring = [
                a,
                [a[0] + d[0], a[1] + d[1]],
                [a[0] + 2 * d[0] + k, a[1] + 2 * d[1]],
                [
                    a[0] + 3 * d[0],
                    a[1] + 3 * d[1] + (rng.next_u64() % 3) as i64 - 1,
                ],
            ];
            let exact: i128 = (0..4)
                .map(|i| {
                    let (p, q) = (ring[i], ring[(i + 1) % 4]);
                    p[0] as i128 * q[1] as i128 - q[0] as i128 * p[1] as i128
                })
                .sum();
            let f = filter_ring_area(ring.iter().map(|p| [p[0] as f64, p[1] as f64]));
            if let Some(sign) = f {
                certified += 1;
                assert_eq!(sign as i128, exact.signum(), "{ring:?}");
            }
        }
        assert!(certified > 1000 && certified < 20_000, "{certified}");
    }

    #[test]
    fn ring_area_filter_declines_rings_of_2_24_corners_or_more() {
        // a convex ring (corners on the parabola y = x², counter-clockwise)
        // with a large area: certified up to 2^24 − 1 corners, left to
        // the exact path from 2^24 on, where the proof of the bound ends
        let ring = |n: u64| (0..n).map(|i| [i as f64, (i * i) as f64]);
        assert_eq!(filter_ring_area(ring(1000)), Some(1));
        assert_eq!(filter_ring_area(ring((1 << 24) - 1)), Some(1));
        assert_eq!(filter_ring_area(ring(1 << 24)), None);
    }
}
