//! An exact oracle written from scratch on `num-bigint` / `num-rational`.
//!
//! Nothing here calls into `bsp_core`'s arithmetic: kernel values are only
//! read out (plane coefficients, homogeneous coordinates) and every answer
//! is recomputed with arbitrary-precision integers and rationals.
//!
//! The ray-parity solid test is the one exception to "big numbers
//! everywhere": it runs on `i128` with checked operations, because its
//! inputs are bounded grid points (see [`Solid`]) and it has to stay fast
//! on meshes with thousands of triangles.

use std::ops::{Add, Mul, Sub};

use bsp_core::{GridPoint, I256, MAX_COORD, Membership, Plane, Point, PolygonSide, Side};
use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{One, Signed, Zero};

/// An exact rational.
pub(crate) type Q = BigRational;
/// A rational point or vector.
pub(crate) type Q3 = [Q; 3];
/// An integer point or vector.
pub(crate) type Z3 = [BigInt; 3];

/// A bnum integer as a `BigInt`, through its decimal representation.
pub(crate) fn big(x: I256) -> BigInt {
    x.to_string()
        .parse()
        .expect("an I256 prints as a decimal integer")
}

/// An integer as a rational.
pub(crate) fn q(x: impl Into<BigInt>) -> Q {
    Q::from_integer(x.into())
}

/// A grid point as an integer vector.
pub(crate) fn grid_z(g: GridPoint) -> Z3 {
    g.map(BigInt::from)
}

/// A grid point as a rational point.
pub(crate) fn grid_q(g: GridPoint) -> Q3 {
    g.map(q)
}

/// The exact rational coordinates of a kernel point, from its homogeneous
/// coordinates (checking `w > 0`).
pub(crate) fn point_q(p: &Point) -> Q3 {
    let h = p.homogeneous();
    let w = big(h[3]);
    assert!(w.is_positive(), "homogeneous w must be positive: {p:?}");
    [0, 1, 2].map(|k| Q::new(big(h[k]), w.clone()))
}

/// Sign of a signed number as a [`Side`].
pub(crate) fn side_of<T: Signed>(v: &T) -> Side {
    if v.is_positive() {
        Side::Front
    } else if v.is_negative() {
        Side::Back
    } else {
        Side::On
    }
}

pub(crate) fn add3<T>(a: &[T; 3], b: &[T; 3]) -> [T; 3]
where
    for<'x> &'x T: Add<&'x T, Output = T>,
{
    [&a[0] + &b[0], &a[1] + &b[1], &a[2] + &b[2]]
}

pub(crate) fn sub3<T>(a: &[T; 3], b: &[T; 3]) -> [T; 3]
where
    for<'x> &'x T: Sub<&'x T, Output = T>,
{
    [&a[0] - &b[0], &a[1] - &b[1], &a[2] - &b[2]]
}

pub(crate) fn scale3<T>(a: &[T; 3], s: &T) -> [T; 3]
where
    for<'x> &'x T: Mul<&'x T, Output = T>,
{
    [&a[0] * s, &a[1] * s, &a[2] * s]
}

pub(crate) fn dot3<T>(a: &[T; 3], b: &[T; 3]) -> T
where
    for<'x> &'x T: Mul<&'x T, Output = T>,
    T: Add<Output = T>,
{
    &a[0] * &b[0] + &a[1] * &b[1] + &a[2] * &b[2]
}

pub(crate) fn cross3<T>(a: &[T; 3], b: &[T; 3]) -> [T; 3]
where
    for<'x> &'x T: Mul<&'x T, Output = T>,
    T: Sub<Output = T>,
{
    [
        &a[1] * &b[2] - &a[2] * &b[1],
        &a[2] * &b[0] - &a[0] * &b[2],
        &a[0] * &b[1] - &a[1] * &b[0],
    ]
}

/// `det[a; b; c]` (rows).
pub(crate) fn det3<T>(a: &[T; 3], b: &[T; 3], c: &[T; 3]) -> T
where
    for<'x> &'x T: Mul<&'x T, Output = T>,
    T: Add<Output = T> + Sub<Output = T>,
{
    dot3(a, &cross3(b, c))
}

fn gcd(a: &BigInt, b: &BigInt) -> BigInt {
    let (mut a, mut b) = (a.abs(), b.abs());
    while !b.is_zero() {
        let r = &a % &b;
        a = b;
        b = r;
    }
    a
}

/// A plane `n · x + d = 0` with big-integer coefficients (not necessarily
/// reduced). Its front is where `n · x + d > 0`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct OPlane {
    pub(crate) n: Z3,
    pub(crate) d: BigInt,
}

impl OPlane {
    /// The coefficients of a kernel plane.
    pub(crate) fn of(p: &Plane) -> OPlane {
        OPlane {
            n: p.normal().map(BigInt::from),
            d: BigInt::from(p.offset()),
        }
    }

    /// The plane through three integer points, normal `(b - a) × (c - a)`;
    /// `None` if they are collinear.
    pub(crate) fn through(a: &Z3, b: &Z3, c: &Z3) -> Option<OPlane> {
        let n = cross3(&sub3(b, a), &sub3(c, a));
        if n.iter().all(Zero::is_zero) {
            return None;
        }
        let d = -dot3(&n, a);
        Some(OPlane { n, d })
    }

    /// The plane through three grid points.
    pub(crate) fn through_grid(a: GridPoint, b: GridPoint, c: GridPoint) -> Option<OPlane> {
        OPlane::through(&grid_z(a), &grid_z(b), &grid_z(c))
    }

    /// Divided by the gcd of all coefficients (orientation kept).
    pub(crate) fn reduced(&self) -> OPlane {
        let g = self.n.iter().fold(self.d.abs(), |g, c| gcd(&g, c));
        OPlane {
            n: self.n.clone().map(|c| c / &g),
            d: &self.d / &g,
        }
    }

    /// The opposite orientation.
    pub(crate) fn flip(&self) -> OPlane {
        OPlane {
            n: self.n.clone().map(|c| -c),
            d: -self.d.clone(),
        }
    }

    /// `n · x + d` at a rational point.
    pub(crate) fn eval(&self, x: &Q3) -> Q {
        let n = self.n.clone().map(Q::from_integer);
        dot3(&n, x) + Q::from_integer(self.d.clone())
    }

    /// `n · x + d w` for homogeneous `(x, w)`; its sign is the side when `w > 0`.
    pub(crate) fn eval_h(&self, x: &Z3, w: &BigInt) -> BigInt {
        dot3(&self.n, x) + &self.d * w
    }

    /// Exact side of a rational point.
    pub(crate) fn side(&self, x: &Q3) -> Side {
        side_of(&self.eval(x))
    }

    /// Exact side of a homogeneous point.
    pub(crate) fn side_h(&self, p: &HPoint) -> Side {
        side_of(&self.eval_h(&p.x, &p.w))
    }

    /// Exact side of an integer point.
    pub(crate) fn side_z(&self, x: &Z3) -> Side {
        side_of(&self.eval_h(x, &BigInt::one()))
    }
}

/// The single intersection point of three planes by Cramer's rule, or
/// `None` if their normals are linearly dependent.
pub(crate) fn meet3(p1: &OPlane, p2: &OPlane, p3: &OPlane) -> Option<Q3> {
    let det = det3(&p1.n, &p2.n, &p3.n);
    if det.is_zero() {
        return None;
    }
    // rows n_i, right-hand side -d_i; x_k = det(N with column k := -d) / det
    let rhs = [-p1.d.clone(), -p2.d.clone(), -p3.d.clone()];
    let rows = [&p1.n, &p2.n, &p3.n];
    let col_replaced = |k: usize| -> [Z3; 3] {
        [0, 1, 2].map(|r| {
            let mut row = rows[r].clone();
            row[k] = rhs[r].clone();
            row
        })
    };
    Some([0, 1, 2].map(|k| {
        let m = col_replaced(k);
        Q::new(det3(&m[0], &m[1], &m[2]), det.clone())
    }))
}

/// The area vector of a planar polygon: the sum of the cross products of
/// its fan triangles, `2 · area · unit normal`, exact (its length is
/// irrational in general; the vector is not).
pub(crate) fn area_vector(v: &[Q3]) -> Q3 {
    let mut s = [Q::zero(), Q::zero(), Q::zero()];
    for i in 1..v.len().saturating_sub(1) {
        let c = cross3(&sub3(&v[i], &v[0]), &sub3(&v[i + 1], &v[0]));
        s = add3(&s, &c);
    }
    s
}

/// `true` if `v` is a strictly convex polygon lying in a plane and running
/// counter-clockwise about `normal`: every vertex other than an edge's
/// endpoints is strictly to the left of that edge.
pub(crate) fn is_strictly_convex(v: &[Q3], normal: &Q3) -> Result<(), String> {
    let k = v.len();
    if k < 3 {
        return Err(format!("{k} vertices"));
    }
    let a = area_vector(v);
    if a.iter().all(Zero::is_zero) {
        return Err("zero area".into());
    }
    if !dot3(&a, normal).is_positive() {
        return Err("orientation does not match the normal".into());
    }
    for (j, p) in v.iter().enumerate() {
        if !dot3(&sub3(p, &v[0]), &a).is_zero() {
            return Err(format!("vertex {j} off the polygon's plane"));
        }
    }
    for i in 0..k {
        let (p, r) = (&v[i], &v[(i + 1) % k]);
        let e = sub3(r, p);
        for (j, x) in v.iter().enumerate() {
            if j == i || j == (i + 1) % k {
                continue;
            }
            if !dot3(&cross3(&e, &sub3(x, p)), &a).is_positive() {
                return Err(format!("vertex {j} not strictly left of edge {i}"));
            }
        }
    }
    Ok(())
}

/// The expected [`PolygonSide`] of a polygon with vertices `v` against
/// `plane`, from the vertices' exact signs alone.
pub(crate) fn polygon_side(v: &[Q3], plane: &OPlane) -> PolygonSide {
    let sides: Vec<Side> = v.iter().map(|x| plane.side(x)).collect();
    let front = sides.contains(&Side::Front);
    let back = sides.contains(&Side::Back);
    match (front, back) {
        (true, true) => PolygonSide::Spanning,
        (true, false) => PolygonSide::Front,
        (false, true) => PolygonSide::Back,
        (false, false) => {
            let n = plane.n.clone().map(Q::from_integer);
            PolygonSide::Coplanar {
                same_orientation: dot3(&area_vector(v), &n).is_positive(),
            }
        }
    }
}

/// Exact `f64` → rational.
pub(crate) fn f64_q(f: f64) -> Q {
    assert!(f.is_finite(), "{f} is not finite");
    let bits = f.to_bits();
    let neg = bits >> 63 == 1;
    let exp = ((bits >> 52) & 0x7ff) as i64;
    let frac = bits & ((1u64 << 52) - 1);
    let (m, e) = if exp == 0 {
        (frac, -1074)
    } else {
        (frac | 1u64 << 52, exp - 1075)
    };
    let m = if neg {
        -BigInt::from(m)
    } else {
        BigInt::from(m)
    };
    if e >= 0 {
        Q::from_integer(m << e as usize)
    } else {
        Q::new(m, BigInt::one() << (-e) as usize)
    }
}

/// `Ok` if `f` is the round-to-nearest-even value of `exact`; `Ok(true)`
/// when `exact` is a tie between two `f64`s.
pub(crate) fn check_correctly_rounded(f: f64, exact: &Q) -> Result<bool, String> {
    let dist = |g: f64| (f64_q(g) - exact).abs();
    let (d0, up, down) = (dist(f), dist(f.next_up()), dist(f.next_down()));
    if d0 > up || d0 > down {
        return Err(format!("{f:e} is not nearest to {exact}"));
    }
    let tie = d0 == up || d0 == down;
    if tie && f.to_bits() & 1 == 1 {
        return Err(format!("{f:e} is a tie for {exact} but not even"));
    }
    Ok(tie)
}

/// A point in homogeneous big-integer coordinates `x / w`, `w > 0`.
#[derive(Clone, Debug)]
pub(crate) struct HPoint {
    pub(crate) x: Z3,
    pub(crate) w: BigInt,
}

impl HPoint {
    pub(crate) fn of(p: &Point) -> HPoint {
        let h = p.homogeneous();
        let w = big(h[3]);
        assert!(w.is_positive());
        HPoint {
            x: [big(h[0]), big(h[1]), big(h[2])],
            w,
        }
    }

    pub(crate) fn from_q(p: &Q3) -> HPoint {
        let w = p.iter().fold(BigInt::one(), |w, c| w * c.denom());
        HPoint {
            x: p.clone().map(|c| c.numer() * (&w / c.denom())),
            w,
        }
    }
}

/// A ray from an integer eye through a point `s`, parametrised so that
/// the eye is at `t = 0` and `s` at `t = 1`; `dir` is `w (s - eye)`.
#[derive(Clone, Debug)]
pub(crate) struct Ray {
    eye: Z3,
    dir: Z3,
    w: BigInt,
}

impl Ray {
    /// The ray from `eye` through `s` (`None` if `s` is the eye).
    pub(crate) fn through(eye: [i64; 3], s: &HPoint) -> Option<Ray> {
        let eye = eye.map(BigInt::from);
        let dir = sub3(&s.x, &scale3(&eye, &s.w));
        (!dir.iter().all(Zero::is_zero)).then_some(Ray {
            eye,
            dir,
            w: s.w.clone(),
        })
    }

    /// The parameter `t > 0` at which the ray crosses the relative interior
    /// of the convex polygon `v` lying in `plane`, transversally; `None`
    /// if it misses, grazes its boundary, or runs inside its plane.
    ///
    /// The line meets the interior iff every `det[v_i - eye, v_i+1 - eye,
    /// dir]` has the same strict sign.
    pub(crate) fn hit(&self, v: &[HPoint], plane: &OPlane) -> Option<Q> {
        let rel: Vec<Z3> = v
            .iter()
            .map(|p| sub3(&p.x, &scale3(&self.eye, &p.w)))
            .collect();
        let k = rel.len();
        let mut sign = 0;
        for i in 0..k {
            let s = det3(&rel[i], &rel[(i + 1) % k], &self.dir);
            let s = if s.is_positive() {
                1
            } else if s.is_negative() {
                -1
            } else {
                return None;
            };
            if sign != 0 && s != sign {
                return None;
            }
            sign = s;
        }
        let num = -plane.eval_h(&self.eye, &BigInt::one());
        let den = dot3(&plane.n, &self.dir);
        assert!(!den.is_zero(), "an interior crossing is transversal");
        // eye + (num / den) dir = eye + (num w / den) (s - eye)
        let t = Q::new(num * &self.w, den);
        t.is_positive().then_some(t)
    }
}

/// Generic ray directions for the parity test (`|r_i| < 2^20`), tried in
/// turn until one misses every edge and vertex.
const RAY_DIRS: [[i128; 3]; 10] = [
    [1_000_003, 314_159, 271_828],
    [-271_829, 999_983, 141_421],
    [173_207, -223_607, 1_000_033],
    [-577_215, -662_607, 299_792],
    [618_034, 161_803, -987_654],
    [-31_337, 786_433, -524_287],
    [917_503, -65_537, -131_071],
    [3, 1_048_573, -7],
    [-1_048_571, 5, 11],
    [13, -17, 1_048_559],
];

type V = [i128; 3];

fn vsub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn vdot(a: V, b: V) -> i128 {
    // |a|, |b| stay below 2^83 and 2^27 (or 2^55 and 2^56), see `Solid`
    a[0].checked_mul(b[0])
        .and_then(|x| a[1].checked_mul(b[1]).and_then(|y| x.checked_add(y)))
        .and_then(|x| a[2].checked_mul(b[2]).and_then(|y| x.checked_add(y)))
        .expect("the parity oracle's i128 budget")
}

fn vcross(a: V, b: V) -> V {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[derive(Clone, Debug)]
struct Tri {
    a: V,
    b: V,
    c: V,
    n: V,
    lo: V,
    hi: V,
}

enum Crossing {
    Miss,
    Hit,
    Degenerate,
}

/// A closed triangle mesh on the grid, for exact ray-parity membership.
///
/// Bounds that keep everything in `i128`: grid coordinates `|c| <=
/// MAX_COORD < 2^26`, so differences `< 2^27`, triangle normals `< 2^55`,
/// ray directions `< 2^20`; the largest quantities are `n · (p - a) <
/// 3 · 2^82` and `n · ((b - a) × (p - a)) < 3 · 2^110`.
#[derive(Clone, Debug)]
pub(crate) struct Solid {
    tris: Vec<Tri>,
}

impl Solid {
    /// Fan-triangulates every face loop; triangles without area are left
    /// out (they do not change the surface).
    pub(crate) fn new(faces: &[Vec<GridPoint>]) -> Solid {
        let v = |g: GridPoint| g.map(|c| c as i128);
        let mut tris = Vec::new();
        for f in faces {
            for i in 1..f.len().saturating_sub(1) {
                let (a, b, c) = (v(f[0]), v(f[i]), v(f[i + 1]));
                let n = vcross(vsub(b, a), vsub(c, a));
                if n == [0, 0, 0] {
                    continue;
                }
                let lo = [0, 1, 2].map(|k| a[k].min(b[k]).min(c[k]));
                let hi = [0, 1, 2].map(|k| a[k].max(b[k]).max(c[k]));
                tris.push(Tri { a, b, c, n, lo, hi });
            }
        }
        Solid { tris }
    }

    /// Number of triangles with area.
    pub(crate) fn len(&self) -> usize {
        self.tris.len()
    }

    /// The sign of the enclosed signed volume: positive when the
    /// triangles run counter-clockwise seen from outside.
    pub(crate) fn volume_sign(&self) -> i32 {
        let mut s = BigInt::zero();
        for t in &self.tris {
            let z = |p: V| p.map(BigInt::from);
            s += det3(&z(t.a), &z(t.b), &z(t.c));
        }
        if s.is_positive() {
            1
        } else if s.is_negative() {
            -1
        } else {
            0
        }
    }

    fn on_triangle(t: &Tri, p: V) -> bool {
        if (0..3).any(|k| p[k] < t.lo[k] || p[k] > t.hi[k]) {
            return false;
        }
        if vdot(t.n, vsub(p, t.a)) != 0 {
            return false;
        }
        [(t.a, t.b), (t.b, t.c), (t.c, t.a)]
            .iter()
            .all(|&(u, w)| vdot(t.n, vcross(vsub(w, u), vsub(p, u))) >= 0)
    }

    fn crossing(t: &Tri, p: V, r: V) -> Crossing {
        let den = vdot(t.n, r);
        let num = vdot(t.n, vsub(t.a, p));
        if den == 0 {
            return if num == 0 {
                Crossing::Degenerate
            } else {
                Crossing::Miss
            };
        }
        if num == 0 || (num > 0) != (den > 0) {
            return Crossing::Miss;
        }
        let (a, b, c) = (vsub(t.a, p), vsub(t.b, p), vsub(t.c, p));
        let s = [
            vdot(vcross(a, b), r).signum(),
            vdot(vcross(b, c), r).signum(),
            vdot(vcross(c, a), r).signum(),
        ];
        if s.contains(&1) && s.contains(&-1) {
            Crossing::Miss
        } else if s.contains(&0) {
            Crossing::Degenerate
        } else {
            Crossing::Hit
        }
    }

    /// Membership of a grid point: `Boundary` if it lies on a triangle,
    /// otherwise the parity of the crossings of a ray that meets no edge
    /// or vertex.
    pub(crate) fn classify(&self, p: GridPoint) -> Membership {
        assert!(p.iter().all(|c| c.abs() <= MAX_COORD));
        let p = p.map(|c| c as i128);
        if self.tris.iter().any(|t| Solid::on_triangle(t, p)) {
            return Membership::Boundary;
        }
        'dirs: for r in RAY_DIRS {
            let mut odd = false;
            for t in &self.tris {
                match Solid::crossing(t, p, r) {
                    Crossing::Miss => {}
                    Crossing::Hit => odd = !odd,
                    Crossing::Degenerate => continue 'dirs,
                }
            }
            return if odd {
                Membership::Inside
            } else {
                Membership::Outside
            };
        }
        panic!("every ray direction from {p:?} hits an edge or vertex");
    }
}

#[cfg(test)]
mod tests {
    //! The oracle checked on values known by hand.
    use super::*;

    #[test]
    fn oracle_meet_and_area_by_hand() {
        let x = OPlane::of(&Plane::new([1, 0, 0], -3).unwrap());
        let y = OPlane::of(&Plane::new([0, 2, 0], 1).unwrap());
        let z = OPlane::of(&Plane::new([1, 1, 1], 0).unwrap());
        let p = meet3(&x, &y, &z).unwrap();
        assert_eq!(
            p,
            [
                q(3),
                Q::new((-1).into(), 2.into()),
                Q::new((-5).into(), 2.into())
            ]
        );
        assert!(meet3(&x, &x.flip(), &z).is_none());
        let sq = [[0, 0, 0], [2, 0, 0], [2, 3, 0], [0, 3, 0]].map(grid_q);
        assert_eq!(area_vector(&sq), [q(0), q(0), q(12)]);
        let t = OPlane::through_grid([0, 0, 0], [2, 0, 0], [0, 2, 0]).unwrap();
        assert_eq!(
            t.reduced(),
            OPlane {
                n: grid_z([0, 0, 1]),
                d: 0.into()
            }
        );
        assert!(is_strictly_convex(&sq, &[q(0), q(0), q(1)]).is_ok());
        assert!(is_strictly_convex(&sq, &[q(0), q(0), q(-1)]).is_err());
    }

    #[test]
    fn oracle_rounding_and_bignum_conversion() {
        assert_eq!(f64_q(0.75), Q::new(3.into(), 4.into()));
        assert_eq!(f64_q(-6.0), q(-6));
        assert!(check_correctly_rounded(1.0 / 3.0, &Q::new(1.into(), 3.into())).is_ok());
        assert!(check_correctly_rounded(0.3333, &Q::new(1.into(), 3.into())).is_err());
        let big_i = I256::from(-7i128) * I256::from(1i128 << 100) * I256::from(1i128 << 100);
        assert_eq!(big(big_i), BigInt::from(-7) << 200usize);
    }

    #[test]
    fn oracle_parity_on_a_unit_cube() {
        let c = |x, y, z| [x, y, z];
        let faces = vec![
            vec![c(0, 0, 0), c(0, 2, 0), c(2, 2, 0), c(2, 0, 0)],
            vec![c(0, 0, 2), c(2, 0, 2), c(2, 2, 2), c(0, 2, 2)],
            vec![c(0, 0, 0), c(2, 0, 0), c(2, 0, 2), c(0, 0, 2)],
            vec![c(0, 2, 0), c(0, 2, 2), c(2, 2, 2), c(2, 2, 0)],
            vec![c(0, 0, 0), c(0, 0, 2), c(0, 2, 2), c(0, 2, 0)],
            vec![c(2, 0, 0), c(2, 2, 0), c(2, 2, 2), c(2, 0, 2)],
        ];
        let s = Solid::new(&faces);
        assert_eq!(s.volume_sign(), 1);
        assert_eq!(s.classify([1, 1, 1]), Membership::Inside);
        assert_eq!(s.classify([3, 1, 1]), Membership::Outside);
        assert_eq!(s.classify([2, 1, 1]), Membership::Boundary);
        assert_eq!(s.classify([2, 2, 2]), Membership::Boundary);
        assert_eq!(s.classify([-1, -1, -1]), Membership::Outside);
    }
}
