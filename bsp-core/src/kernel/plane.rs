//! Planes with integer coefficients.

use crate::kernel::Side;
use crate::kernel::grid::{GridPoint, ViewPoint};

/// Why an input face could not become one convex polygon.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FaceDefect {
    /// Fewer than three distinct vertices.
    TooFewVertices,
    /// All vertices on one line, or zero enclosed area.
    ZeroArea,
    /// Not all vertices lie in one plane (after snapping).
    NonPlanar,
    /// Planar but not convex.
    NonConvex,
    /// Planar, but its loop touches or crosses itself (after snapping) so
    /// that no triangles tile it.
    NotSimple,
    /// A coordinate beyond `±MAX_COORD`, the range the exact arithmetic
    /// is proved for (snap input with a [`Grid`](crate::kernel::Grid) first).
    OutOfRange,
}

impl std::fmt::Display for FaceDefect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            FaceDefect::TooFewVertices => "fewer than three distinct vertices",
            FaceDefect::ZeroArea => "zero area (collinear vertices)",
            FaceDefect::NonPlanar => "vertices not in one plane",
            FaceDefect::NonConvex => "not convex",
            FaceDefect::NotSimple => "not simple: its boundary touches or crosses itself",
            FaceDefect::OutOfRange => "a grid coordinate beyond ±MAX_COORD (2^26 - 1)",
        })
    }
}

impl std::error::Error for FaceDefect {}

/// Exclusive bound on the absolute value of a normal component: `2^55`.
pub const MAX_NORMAL_BITS: u32 = 55;
/// Exclusive bound on the absolute value of an offset: `2^83`.
pub const MAX_OFFSET_BITS: u32 = 83;

/// An oriented plane `n · x + d = 0` with integer coefficients, reduced so
/// that `gcd(n.x, n.y, n.z, d) = 1`.
///
/// Points with `n · x + d > 0` are in [`Side::Front`]. Because the
/// coefficients are reduced, two planes describe the same oriented plane if
/// and only if they are equal, and opposite planes are exact negations.
///
/// Every plane satisfies `|n_i| < 2^55` and `|d| < 2^83` (the budget of a
/// plane through three grid points); see `docs/architecture.md`.
#[derive(Clone, Copy)]
pub struct Plane {
    n: [i64; 3],
    /// `d` rounded to `f64`, cached for the floating-point filter.
    d_approx: f64,
    /// `d` as its low and high 64 bits: an `i128` field would align the
    /// plane, and every polygon and face holding one, to 16 bytes (a
    /// face slot took 16 bytes of padding for it).
    d: [u64; 2],
}

/// The halves [`Plane`] keeps an offset in.
#[inline]
fn halves(d: i128) -> [u64; 2] {
    [d as u64, (d >> 64) as u64]
}

impl PartialEq for Plane {
    fn eq(&self, o: &Plane) -> bool {
        self.n == o.n && self.d == o.d
    }
}
impl Eq for Plane {}
impl std::hash::Hash for Plane {
    fn hash<H: std::hash::Hasher>(&self, h: &mut H) {
        self.n.hash(h);
        self.offset().hash(h);
    }
}
impl std::fmt::Debug for Plane {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Plane")
            .field("n", &self.n)
            .field("d_approx", &self.d_approx)
            .field("d", &self.offset())
            .finish()
    }
}

/// Binary gcd of two `u64`s (`gcd(0, b) = b`).
#[inline]
fn gcd64(a: u64, b: u64) -> u64 {
    if a == 0 {
        return b;
    }
    if b == 0 {
        return a;
    }
    // one hardware remainder first where one is over 2^8 times the other
    // (`gcd(a, b) = gcd(a, b mod a)`): the binary steps take about one bit
    // each, and the normal's gcd with its last coordinate, or a
    // coordinate near an axis with the others, is often such a pair (the
    // three-coordinate gcd of random shadow and support normals in 0.8 and
    // 0.86 of the time)
    let (a, b) = (a.min(b), a.max(b));
    let b = if b >> 8 > a { b % a } else { b };
    if b == 0 {
        return a;
    }
    let shift = (a | b).trailing_zeros();
    let (mut a, mut b) = (a >> a.trailing_zeros(), b >> b.trailing_zeros());
    while a != b {
        // both odd. The shift of the difference is counted from `a - b`
        // wrapped (the same trailing zeros as `b - a`), beside the min and
        // max (conditional moves), not after them: a shorter chain of
        // dependent instructions a step
        let s = a.wrapping_sub(b).trailing_zeros();
        let (lo, hi) = (a.min(b), a.max(b));
        a = lo;
        b = (hi - lo) >> s;
    }
    a << shift
}

/// Binary gcd of two `u128`s (`gcd(0, b) = b`): shifts and subtractions,
/// in 64 bits (the binary `gcd64`) once both fit (Euclid's steps in 128 bits are
/// each a library call for the remainder).
pub fn gcd128(a: u128, b: u128) -> u128 {
    if a == 0 || b == 0 {
        return a | b;
    }
    let shift = (a | b).trailing_zeros();
    let (mut a, mut b) = (a >> a.trailing_zeros(), b >> b.trailing_zeros());
    // both odd from here on
    while a != b {
        if let (Ok(x), Ok(y)) = (u64::try_from(a), u64::try_from(b)) {
            return u128::from(gcd64(x, y)) << shift;
        }
        let (lo, hi) = (a.min(b), a.max(b));
        a = lo;
        b = (hi - lo) >> (hi - lo).trailing_zeros();
    }
    a << shift
}

/// Euclid's gcd in 128 bits: the reference the tests hold the binary one
/// and [`Plane::new`] to.
#[cfg(test)]
fn gcd(mut a: u128, mut b: u128) -> u128 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

impl Plane {
    /// A plane from raw coefficients, reduced by their GCD.
    ///
    /// Returns `None` if the normal is zero or the reduced coefficients
    /// exceed the budget (`|n_i| < 2^55`, `|d| < 2^83`).
    ///
    /// ```
    /// use bsp_core::Plane;
    /// let p = Plane::new([0, 0, 4], -8).unwrap();
    /// assert_eq!((p.normal(), p.offset()), ([0, 0, 1], -2));
    /// assert!(Plane::new([0, 0, 0], 1).is_none());
    /// ```
    pub fn new(n: [i64; 3], d: i128) -> Option<Plane> {
        if n == [0, 0, 0] {
            return None;
        }
        // the normal's gcd first (binary, in 64 bits): usually 1, and then
        // the offset need not be looked at
        let mut g = gcd64(n[0].unsigned_abs(), n[1].unsigned_abs());
        if g != 1 {
            g = gcd64(g, n[2].unsigned_abs());
        }
        // (the offset in 64 bits where it fits: `i128` division and
        // conversion are library calls, several times slower)
        let small = i64::try_from(d).ok();
        if g > 1 {
            let rest = match small {
                Some(d) => d.unsigned_abs() % g,
                None => (d.unsigned_abs() % g as u128) as u64,
            };
            // (`rest < g`: the binary gcd in 64 bits, not Euclid's in
            // 128, whose every step was a library call)
            g = gcd64(g, rest);
        }
        let (n, d, small) = if g > 1 {
            // (a divisor of 2^63, from a normal of `i64::MIN`s and
            // zeros, takes the wide path)
            let small = small.filter(|_| g <= i64::MAX as u64).map(|d| d / g as i64);
            let d = small.map_or(d / g as i128, i128::from);
            // (2^63 divides only `i64::MIN`: dividing by it as an `i64`
            // would turn the normal around)
            let n = if g <= i64::MAX as u64 {
                n.map(|c| c / g as i64)
            } else {
                n.map(|c| (c as i128 / g as i128) as i64)
            };
            (n, d, small)
        } else {
            (n, d, small)
        };
        let fits = n.iter().all(|c| c.unsigned_abs() < 1u64 << MAX_NORMAL_BITS)
            && d.unsigned_abs() < 1u128 << MAX_OFFSET_BITS;
        fits.then_some(Plane {
            n,
            // (both conversions round to nearest: the same value)
            d_approx: small.map_or(d as f64, |d| d as f64),
            d: halves(d),
        })
    }

    /// The plane through three grid points, oriented so that `a, b, c` run
    /// counter-clockwise seen from the front (right-hand normal).
    /// [`FaceDefect::ZeroArea`] if they are collinear,
    /// [`FaceDefect::OutOfRange`] if a coordinate exceeds
    /// [`MAX_COORD`](crate::kernel::MAX_COORD) (the arithmetic's budget: beyond
    /// it the normal could overflow).
    ///
    /// ```
    /// use bsp_core::{FaceDefect, MAX_COORD, Plane, Side};
    /// let p = Plane::through([0, 0, 0], [1, 0, 0], [0, 1, 0]).unwrap();
    /// assert_eq!(p.classify_grid([5, 5, 1]), Side::Front);
    /// assert_eq!(p.classify_grid([5, 5, 0]), Side::On);
    /// let far = [MAX_COORD + 1, 0, 0];
    /// assert_eq!(Plane::through([0, 0, 0], far, [0, 1, 0]), Err(FaceDefect::OutOfRange));
    /// ```
    pub fn through(a: GridPoint, b: GridPoint, c: GridPoint) -> Result<Plane, FaceDefect> {
        if !in_range(&[a, b, c]) {
            return Err(FaceDefect::OutOfRange);
        }
        Plane::through_in_range(a, b, c).ok_or(FaceDefect::ZeroArea)
    }

    /// [`Plane::through`] for points the caller knows to be within
    /// [`MAX_COORD`](crate::kernel::MAX_COORD); `None` if they are collinear.
    pub(crate) fn through_in_range(a: GridPoint, b: GridPoint, c: GridPoint) -> Option<Plane> {
        debug_assert!(in_range(&[a, b, c]), "{a:?} {b:?} {c:?}");
        let u = sub(b, a);
        let v = sub(c, a);
        let n = cross(u, v);
        let d = -dot_wide(n, a);
        Plane::new(n, d)
    }

    /// The plane through the edge `a → b` of a polygon with support `support`
    /// that contains the axis direction along which `support`'s normal is
    /// largest, oriented so that the polygon's interior is on its back.
    ///
    /// Its coefficients are small: `|n_i| < 2^27`, `|d| < 2^54`.
    pub(crate) fn edge(a: GridPoint, b: GridPoint, support: &Plane) -> Option<Plane> {
        let k = support.dominant_axis();
        let e = sub(b, a);
        // e × axis_k
        let mut n = match k {
            0 => [0, e[2], -e[1]],
            1 => [-e[2], 0, e[0]],
            _ => [e[1], -e[0], 0],
        };
        if support.n[k] < 0 {
            n = n.map(|c| -c);
        }
        let d = -dot_wide(n, a);
        Plane::new(n, d)
    }

    /// `n1 · (n2 × n3)` of the three planes' normals, exactly: zero when
    /// they do not meet in one point.
    pub fn normals_det(p1: &Plane, p2: &Plane, p3: &Plane) -> bnum::types::I256 {
        let (n1, n2, n3) = (p1.normal(), p2.normal(), p3.normal());
        let m = |x: i64, y: i64| x as i128 * y as i128;
        let c = [
            m(n2[1], n3[2]) - m(n2[2], n3[1]),
            m(n2[2], n3[0]) - m(n2[0], n3[2]),
            m(n2[0], n3[1]) - m(n2[1], n3[0]),
        ];
        use crate::kernel::exact::Wide;
        (0..3)
            .fold(Wide::ZERO, |s, i| s.add(Wide::product(n1[i] as i128, c[i])))
            .to_i256()
    }

    /// Index of the normal's component of largest magnitude.
    pub fn dominant_axis(&self) -> usize {
        let a = self.n.map(|c| c.unsigned_abs());
        if a[0] >= a[1] && a[0] >= a[2] {
            0
        } else if a[1] >= a[2] {
            1
        } else {
            2
        }
    }

    /// The same plane with the opposite orientation.
    pub fn flip(&self) -> Plane {
        Plane {
            n: self.n.map(|c| -c),
            d_approx: -self.d_approx,
            d: halves(-self.offset()),
        }
    }

    /// The integer normal.
    pub fn normal(&self) -> [i64; 3] {
        self.n
    }

    /// The integer offset `d`.
    #[inline]
    pub fn offset(&self) -> i128 {
        (self.d[1] as i64 as i128) << 64 | self.d[0] as i128
    }

    /// The normal and offset rounded to `f64`.
    pub fn approx(&self) -> [f64; 4] {
        [
            self.n[0] as f64,
            self.n[1] as f64,
            self.n[2] as f64,
            self.d_approx,
        ]
    }

    /// `true` if both planes are the same plane with either orientation.
    pub fn is_coincident(&self, o: &Plane) -> bool {
        self == o || (self.n == o.n.map(|c| -c) && self.offset() == -o.offset())
    }

    /// `true` if the normals point the same way (positive dot product).
    pub fn same_direction(&self, o: &Plane) -> bool {
        let s: i128 = (0..3).map(|i| self.n[i] as i128 * o.n[i] as i128).sum();
        s > 0
    }

    /// Exact side of a grid point. Uses 128-bit integers: `|n·p + d| < 2^84`.
    #[inline]
    pub fn classify_grid(&self, p: GridPoint) -> Side {
        let v = self.n[0] as i128 * p[0] as i128
            + self.n[1] as i128 * p[1] as i128
            + self.n[2] as i128 * p[2] as i128
            + self.offset();
        Side::from_sign(v.signum() as i32)
    }

    /// Exact side of a viewpoint. `|n·p + d| < 2^120` for viewpoints within
    /// [`crate::MAX_VIEW_COORD`].
    #[inline]
    pub fn classify_viewpoint(&self, p: ViewPoint) -> Side {
        let p = p.0;
        let v = self.n[0] as i128 * p[0] as i128
            + self.n[1] as i128 * p[1] as i128
            + self.n[2] as i128 * p[2] as i128
            + self.offset();
        Side::from_sign(v.signum() as i32)
    }
}

pub(crate) fn sub(a: GridPoint, b: GridPoint) -> [i64; 3] {
    [
        a[0] as i64 - b[0] as i64,
        a[1] as i64 - b[1] as i64,
        a[2] as i64 - b[2] as i64,
    ]
}

/// Cross product of grid differences (`|u_i|, |v_i| < 2^27`): `< 2^55`.
/// `true` if every coordinate is within `±MAX_COORD`.
pub(crate) fn in_range(points: &[GridPoint]) -> bool {
    let m = crate::kernel::MAX_COORD;
    points.iter().flatten().all(|c| (-m..=m).contains(c))
}

pub(crate) fn cross(u: [i64; 3], v: [i64; 3]) -> [i64; 3] {
    [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ]
}

/// Cross product of `i64` vectors in `i128` (exact for components below
/// `2^63`: each product is below `2^126`, each difference below `2^127`).
pub(crate) fn cross_wide(a: [i64; 3], b: [i64; 3]) -> [i128; 3] {
    let m = |x: i64, y: i64| x as i128 * y as i128;
    [
        m(a[1], b[2]) - m(a[2], b[1]),
        m(a[2], b[0]) - m(a[0], b[2]),
        m(a[0], b[1]) - m(a[1], b[0]),
    ]
}

fn dot_wide(n: [i64; 3], p: GridPoint) -> i128 {
    n[0] as i128 * p[0] as i128 + n[1] as i128 * p[1] as i128 + n[2] as i128 * p[2] as i128
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::MAX_COORD;

    /// Near `2^31` the normal's cross product overflows `i64` (a panic in
    /// the test build, a wrong plane in a release build): points beyond
    /// `MAX_COORD` are refused where a library caller hands them in.
    #[test]
    fn regress_grid_range_is_checked_at_the_api() {
        let m = MAX_COORD;
        let big = [i32::MAX, i32::MIN + 1, i32::MAX];
        assert_eq!(
            Plane::through([0, 0, 0], big, [i32::MIN + 1, i32::MAX, 5]),
            Err(FaceDefect::OutOfRange)
        );
        assert_eq!(
            Plane::through([m + 1, 0, 0], [0, 1, 0], [0, 0, 1]),
            Err(FaceDefect::OutOfRange)
        );
        assert!(Plane::through([m, 0, 0], [0, -m, 0], [0, 0, m]).is_ok());
        for poly in [
            vec![[0, 0, 0], [m + 1, 0, 0], [0, 1, 0]],
            vec![[0, 0, -m - 1], [1, 0, 0], [0, 1, 0], [0, 0, 1]],
            vec![[0, 0, 0], big, [1, 1, 1]],
        ] {
            assert_eq!(
                crate::kernel::Polygon::from_grid_points(&poly, 0).unwrap_err(),
                FaceDefect::OutOfRange
            );
        }
        assert!(
            crate::kernel::Polygon::from_grid_points(&[[-m, -m, 0], [m, -m, 0], [m, m, 0]], 0)
                .is_ok()
        );
    }

    #[test]
    fn extreme_grid_points_stay_in_budget() {
        let m = MAX_COORD;
        let p = Plane::through([-m, -m, -m], [m, -m, m], [-m, m, m]).unwrap();
        assert!(p.normal().iter().all(|c| c.unsigned_abs() < 1 << 55));
        // a plane whose gcd is 1 with near-maximal coefficients
        let p = Plane::through([-m, -m + 1, m], [m, -m, -m + 2], [m - 3, m, -m]).unwrap();
        for v in [[-m, -m + 1, m], [m, -m, -m + 2], [m - 3, m, -m]] {
            assert_eq!(p.classify_grid(v), Side::On);
        }
        let e = Plane::edge([-m, -m + 1, m], [m, -m, -m + 2], &p).unwrap();
        assert_eq!(e.classify_grid([m - 3, m, -m]), Side::Back);
    }

    /// The offset kept in two halves reads back as given, at the ends of
    /// the budget and around the halves' seam; the plane stays 8-byte
    /// aligned (a polygon or face holding one is not padded to 16).
    #[test]
    fn offsets_read_back_from_their_halves() {
        let big = (1i128 << MAX_OFFSET_BITS) - 1;
        for d in [
            0,
            1,
            -1,
            big,
            -big,
            1 << 64,
            -(1 << 64),
            (1 << 64) - 1,
            i64::MIN as i128,
        ] {
            let p = Plane::new([1, 0, 0], d).unwrap();
            assert_eq!(p.offset(), d);
            assert_eq!(p.flip().offset(), -d);
            assert_eq!(p.approx()[3], d as f64);
            assert!(p.is_coincident(&p.flip()));
        }
        assert_eq!(std::mem::align_of::<Plane>(), 8);
        assert_eq!(std::mem::size_of::<Plane>(), 48);
    }

    /// The binary gcd is Euclid's, on both sides of 64 bits and at the
    /// edges of 128.
    #[test]
    fn binary_gcd_is_euclids() {
        let mut x: u128 = 0x9e37_79b9_7f4a_7c15_f39c_c060_5ced_c834;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let edges = [
            0,
            1,
            2,
            3,
            6,
            1 << 64,
            (1 << 64) - 1,
            u128::MAX,
            u128::MAX - 1,
            1 << 127,
        ];
        for &a in &edges {
            for &b in &edges {
                assert_eq!(gcd128(a, b), gcd(a, b), "{a} {b}");
            }
        }
        for k in 0..20_000 {
            // sizes from a few bits to 128, with shared factors
            let (r, s, t) = (next(), next(), next());
            let f = (t >> (t % 128) as u32).max(1) >> (k % 40);
            let a = (r >> (r % 128) as u32).wrapping_mul(f.max(1));
            let b = (s >> (s % 128) as u32).wrapping_mul(f.max(1));
            assert_eq!(gcd128(a, b), gcd(a, b), "{a} {b}");
        }
    }

    #[test]
    fn gcds_agree() {
        for (a, b) in [
            (0u64, 0u64),
            (0, 7),
            (12, 18),
            (1 << 40, 3 << 38),
            (97, 89),
            (u64::MAX, 3),
        ] {
            assert_eq!(gcd64(a, b) as u128, gcd(a as u128, b as u128), "{a} {b}");
        }
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..10_000 {
            // xorshift pairs, and pairs with a large common factor
            crate::xorshift(&mut x);
            let (a, b) = (x >> (x % 40), x.rotate_left(17) >> (x % 23));
            assert_eq!(gcd64(a, b) as u128, gcd(a as u128, b as u128), "{a} {b}");
            let (a, b) = ((a >> 40) * 1_000_003, (b >> 40) * 1_000_003);
            assert_eq!(gcd64(a, b) as u128, gcd(a as u128, b as u128), "{a} {b}");
        }
        // the offset's 64-bit path gives what the 128-bit one gives:
        // random planes, small and large offsets, common factors
        let wide = |n: [i64; 3], d: i128| -> Option<([i64; 3], i128, f64)> {
            let g = n
                .iter()
                .fold(d.unsigned_abs(), |g, c| gcd(g, c.unsigned_abs() as u128));
            let (n, d) = (n.map(|c| (c as i128 / g as i128) as i64), d / g as i128);
            let fits = n.iter().all(|c| c.unsigned_abs() < 1u64 << MAX_NORMAL_BITS)
                && d.unsigned_abs() < 1u128 << MAX_OFFSET_BITS;
            fits.then_some((n, d, d as f64))
        };
        for i in 0..20_000u64 {
            crate::xorshift(&mut x);
            let f = [1i64, 2, 6, 1 << 20, 1_000_003][(i % 5) as usize];
            let c = |s: u32| ((x.rotate_left(s) >> 44) as i64 - (1 << 19)) * f;
            let n = [c(0), c(21), c(42)];
            if n == [0; 3] {
                continue;
            }
            let d = match i % 4 {
                0 => c(7) as i128,
                1 => (c(7) as i128) << 40,
                2 => i64::MIN as i128 + (x % 7) as i128 * f as i128,
                _ => (x as i128) * f as i128,
            };
            let got = Plane::new(n, d).map(|p| (p.normal(), p.offset(), p.approx()[3]));
            let want = wide(n, d);
            assert_eq!(got, want, "{n:?} {d}");
        }
        let p = Plane::new([i64::MIN, 0, 0], (i64::MIN as i128) * 3).unwrap();
        assert_eq!((p.normal(), p.offset()), ([-1, 0, 0], -3));
        // the third component counts when the first two share a factor
        let p = Plane::new([6, 10, 15], 30).unwrap();
        assert_eq!((p.normal(), p.offset()), ([6, 10, 15], 30));
        let p = Plane::new([6, 10, 14], 30).unwrap();
        assert_eq!((p.normal(), p.offset()), ([3, 5, 7], 15));
        // the offset takes part in the reduction
        let p = Plane::new([6, 12, 18], 9).unwrap();
        assert_eq!((p.normal(), p.offset()), ([2, 4, 6], 3));
        let p = Plane::new([6, 12, 18], 7).unwrap();
        assert_eq!((p.normal(), p.offset()), ([6, 12, 18], 7));
        let p = Plane::new([-4, 0, 0], -(1i128 << 80)).unwrap();
        assert_eq!((p.normal(), p.offset()), ([-1, 0, 0], -(1i128 << 78)));
    }

    #[test]
    fn reduced_planes_compare_exactly() {
        let a = Plane::through([0, 0, 0], [2, 0, 0], [0, 2, 0]).unwrap();
        let b = Plane::through([5, 5, 0], [1, 7, 0], [9, 9, 0]).unwrap();
        assert!(a.is_coincident(&b));
        assert_eq!(a.flip().flip(), a);
        assert_eq!(
            Plane::through([0, 0, 0], [1, 1, 1], [2, 2, 2]),
            Err(FaceDefect::ZeroArea)
        );
    }
}
