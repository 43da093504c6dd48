//! The shadow tier of exact arithmetic: shadow planes and the points where
//! they cut scene polygons.
//!
//! Bounds (see `docs/architecture.md`, "The shadow tier"): a shadow plane through a light `L` with
//! `|L_i| < 2^26` (or a sun direction with `|D_i| < 2^26`) and the edge
//! `P ∩ E` of an input-budget polygon is `P(L)·E − E(L)·P`, with
//! `|P(L)|, |E(L)| < 2^84`, so its normal is below `2^140` and its offset
//! below `2^168`. Every fragment vertex is its polygon's support plane
//! (`2^55`, `2^83`) cut by two edge planes of either tier: `|w| < 2^338`,
//! `|x_i| < 2^366`, and a classification against a shadow plane is below
//! `2^509` — inside a signed 512-bit integer.

use bnum::cast::As;
use bsp_core::internals::{Homogeneous, I512, approx};
use bsp_core::{I256, Plane, Side};

/// A plane with wide integer coefficients: an input plane, or a shadow
/// plane through the light.
#[derive(Clone, Copy, Debug)]
pub struct WidePlane {
    n: [I256; 3],
    d: I256,
    approx: [f64; 4],
    form: Form,
}

/// How a plane was made, kept for cheap exact evaluation at grid points.
#[derive(Clone, Copy, Debug)]
enum Form {
    /// An input plane.
    Input(Plane),
    /// `s (a e − b p)` with `s = ±1`.
    Pencil {
        a: i128,
        e: Plane,
        b: i128,
        p: Plane,
        negate: bool,
    },
}

fn value_at_grid(p: &Plane, g: [i32; 3]) -> i128 {
    let n = p.normal();
    n[0] as i128 * g[0] as i128
        + n[1] as i128 * g[1] as i128
        + n[2] as i128 * g[2] as i128
        + p.offset()
}

fn side_of(v: I512) -> Side {
    if v.is_negative() {
        Side::Back
    } else if v.is_zero() {
        Side::On
    } else {
        Side::Front
    }
}

impl PartialEq for WidePlane {
    fn eq(&self, o: &WidePlane) -> bool {
        self.n == o.n && self.d == o.d
    }
}

impl WidePlane {
    fn new(n: [I256; 3], d: I256, form: Form) -> WidePlane {
        WidePlane {
            approx: [approx(&n[0]), approx(&n[1]), approx(&n[2]), approx(&d)],
            n,
            d,
            form,
        }
    }

    /// An input plane, widened.
    pub fn from_plane(p: &Plane) -> WidePlane {
        let n = p.normal().map(|c| I256::from(c as i128));
        WidePlane::new(n, I256::from(p.offset()), Form::Input(*p))
    }

    /// The exact side of a grid point, in at most 256 bits.
    fn classify_grid(&self, g: [i32; 3]) -> Side {
        match &self.form {
            Form::Input(p) => p.classify_grid(g),
            Form::Pencil { a, e, b, p, negate } => {
                // |a|, |b|, |e(g)|, |p(g)| < 2^84: products below 2^168
                let v = I256::from(*a) * I256::from(value_at_grid(e, g))
                    - I256::from(*b) * I256::from(value_at_grid(p, g));
                let v = if *negate { -v } else { v };
                if v.is_negative() {
                    Side::Back
                } else if v.is_zero() {
                    Side::On
                } else {
                    Side::Front
                }
            }
        }
    }

    /// The normal.
    pub fn normal(&self) -> &[I256; 3] {
        &self.n
    }

    /// The offset.
    pub fn offset(&self) -> I256 {
        self.d
    }

    /// The plane `a · e − b · p` of the pencil through the line `p ∩ e`,
    /// negated when `negate`.
    pub(crate) fn pencil(a: i128, e: &Plane, b: i128, p: &Plane, negate: bool) -> WidePlane {
        let (a, b) = (I256::from(a), I256::from(b));
        let (ne, np) = (e.normal(), p.normal());
        let mut n = [I256::ZERO; 3];
        for k in 0..3 {
            n[k] = a * I256::from(ne[k] as i128) - b * I256::from(np[k] as i128);
        }
        let mut d = a * I256::from(e.offset()) - b * I256::from(p.offset());
        if negate {
            n = n.map(|c| -c);
            d = -d;
        }
        let form = Form::Pencil {
            a: a.as_::<i128>(),
            e: *e,
            b: b.as_::<i128>(),
            p: *p,
            negate,
        };
        WidePlane::new(n, d, form)
    }

    /// The same plane, opposite orientation.
    pub fn flip(&self) -> WidePlane {
        let form = match self.form {
            Form::Input(p) => Form::Input(p.flip()),
            Form::Pencil { a, e, b, p, negate } => Form::Pencil {
                a,
                e,
                b,
                p,
                negate: !negate,
            },
        };
        WidePlane::new(self.n.map(|c| -c), -self.d, form)
    }

    /// `true` if the normal is zero (a degenerate pencil member).
    pub fn is_degenerate(&self) -> bool {
        self.n.iter().all(|c| c.is_zero())
    }
}

/// An exact point of the shadow tier: homogeneous coordinates `(x, y, z,
/// w)`, `w > 0`, in 512-bit integers ([`bsp_core::internals::Homogeneous`]), and its
/// grid coordinates when it is a grid point (classified in at most 256
/// bits then).
#[derive(Clone, Debug)]
pub struct WPoint {
    h: Homogeneous<8>,
    grid: Option<[i32; 3]>,
}

fn wide(x: I256) -> I512 {
    x.as_::<I512>()
}

/// The full 512-bit product of two 256-bit integers (16 limb products,
/// where a 512-bit multiplication takes 64).
fn wmul(a: I256, b: I256) -> I512 {
    let neg = a.is_negative() != b.is_negative();
    let (lo, hi) = a.unsigned_abs().widening_mul(b.unsigned_abs());
    let mut digits = [0u64; 8];
    digits[..4].copy_from_slice(lo.digits());
    digits[4..].copy_from_slice(hi.digits());
    let m = bnum::types::U512::from_digits(digits).as_::<I512>();
    if neg { -m } else { m }
}

fn narrow(x: I512) -> I256 {
    x.as_::<I256>()
}

fn cross(a: &[I512; 3], b: &[I512; 3]) -> [I512; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

impl WPoint {
    /// A scene point (grid or implicit), widened.
    pub fn from_point(p: &bsp_core::Point) -> WPoint {
        let h = Homogeneous::new(p.homogeneous().map(wide)).expect("a scene point is finite");
        let grid = match p {
            bsp_core::Point::Grid(g) => Some(*g),
            bsp_core::Point::Implicit(_) => None,
        };
        WPoint { h, grid }
    }

    fn from_h(h: [I512; 4]) -> Option<WPoint> {
        Some(WPoint {
            h: Homogeneous::new(h)?,
            grid: None,
        })
    }

    /// The intersection of three planes, `None` if they do not meet in one
    /// point.
    pub fn from_planes(p1: &WidePlane, p2: &WidePlane, p3: &WidePlane) -> Option<WPoint> {
        let n = |p: &WidePlane| p.n.map(wide);
        let (n1, n2, n3) = (n(p1), n(p2), n(p3));
        let (c23, c31, c12) = (cross(&n2, &n3), cross(&n3, &n1), cross(&n1, &n2));
        let w = n1[0] * c23[0] + n1[1] * c23[1] + n1[2] * c23[2];
        let (d1, d2, d3) = (wide(p1.d), wide(p2.d), wide(p3.d));
        let mut h = [I512::ZERO; 4];
        for k in 0..3 {
            h[k] = -(c23[k] * d1 + c31[k] * d2 + c12[k] * d3);
        }
        h[3] = w;
        WPoint::from_h(h)
    }

    /// The intersection of an input plane `p` (normal below `2^55`, offset
    /// below `2^83`: a fragment's support plane) with two planes of either
    /// tier: the same point as [`WPoint::from_planes`], computed from
    /// 256 × 256-bit products only.
    pub fn from_support_planes(p: &WidePlane, e: &WidePlane, h: &WidePlane) -> Option<WPoint> {
        let (n1, n2, n3) = (&p.n, &e.n, &h.n);
        let cross_small = |a: &[I256; 3], b: &[I256; 3]| {
            // one factor is the support normal: |component| < 2^196
            [
                narrow(wmul(a[1], b[2]) - wmul(a[2], b[1])),
                narrow(wmul(a[2], b[0]) - wmul(a[0], b[2])),
                narrow(wmul(a[0], b[1]) - wmul(a[1], b[0])),
            ]
        };
        let c12 = cross_small(n1, n2);
        let c31 = cross_small(n3, n1);
        let w = wmul(n3[0], c12[0]) + wmul(n3[1], c12[1]) + wmul(n3[2], c12[2]);
        // c23_k d1 with c23 = n2 × n3, as (n2_i d1) n3_j − (n2_j d1) n3_i:
        // |n2_i d1| < 2^223 fits 256 bits
        let d1 = p.d;
        let n2d = [n2[0] * d1, n2[1] * d1, n2[2] * d1];
        let c23d1 = [
            wmul(n2d[1], n3[2]) - wmul(n2d[2], n3[1]),
            wmul(n2d[2], n3[0]) - wmul(n2d[0], n3[2]),
            wmul(n2d[0], n3[1]) - wmul(n2d[1], n3[0]),
        ];
        let mut out = [I512::ZERO; 4];
        for k in 0..3 {
            out[k] = -(c23d1[k] + wmul(c31[k], e.d) + wmul(c12[k], h.d));
        }
        out[3] = w;
        WPoint::from_h(out)
    }

    /// Exact side of `plane`: the shared filter, then the exact path.
    #[inline]
    pub fn classify(&self, plane: &WidePlane) -> Side {
        match self.h.filter(&plane.approx) {
            Some(s) => s,
            None => self.classify_exact(plane),
        }
    }

    /// The exact path alone: grid points against input planes and shadow
    /// planes in at most 256 bits (a shadow plane's value at a grid point is
    /// `a e(g) − b p(g)`), everything else in 512 bits.
    pub fn classify_exact(&self, plane: &WidePlane) -> Side {
        if let Some(g) = self.grid {
            return plane.classify_grid(g);
        }
        let h = self.h.coords();
        let v = wide(plane.n[0]) * h[0]
            + wide(plane.n[1]) * h[1]
            + wide(plane.n[2]) * h[2]
            + wide(plane.d) * h[3];
        side_of(v)
    }

    /// Homogeneous coordinates, `w > 0`.
    pub fn homogeneous(&self) -> &[I512; 4] {
        self.h.coords()
    }

    /// Grid coordinates, each correctly rounded (equal points give equal
    /// results).
    pub fn to_f64(&self) -> [f64; 3] {
        match self.grid {
            Some(g) => g.map(f64::from),
            None => self.h.round_with::<17>(),
        }
    }

    /// Exact equality of the represented points.
    pub fn same_point(&self, o: &WPoint) -> bool {
        self.h.same(&o.h)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_intersection_matches_general() {
        let p = WidePlane::from_plane(&Plane::through([0, 0, 0], [7, 1, 0], [2, 9, 1]).unwrap());
        let e = WidePlane::from_plane(&Plane::through([1, 2, 3], [5, -4, 2], [0, 0, 9]).unwrap());
        let a = Plane::new([3, -1, 2], 11).unwrap();
        let b = Plane::new([1, 4, -5], -2).unwrap();
        let h = WidePlane::pencil(123_456_789, &a, -987_654_321, &b, false);
        for (x, y) in [(&e, &h), (&h, &e), (&h, &h.flip())] {
            let fast = WPoint::from_support_planes(&p, x, y);
            let slow = WPoint::from_planes(&p, x, y);
            match (fast, slow) {
                (Some(f), Some(s)) => assert_eq!(f.homogeneous(), s.homogeneous()),
                (None, None) => {}
                _ => panic!("one found a point, the other not"),
            }
        }
    }

    #[test]
    fn pencil_contains_line_and_light() {
        let p = Plane::new([0, 0, 1], 0).unwrap(); // z = 0
        let e = Plane::new([1, 0, 0], -2).unwrap(); // x = 2
        let light = [0i128, 0, 5];
        let a = p.offset() + p.normal()[2] as i128 * light[2]; // p(L) = 5
        let b = e.offset(); // e(L) = -2
        let s = WidePlane::pencil(a, &e, b, &p, false);
        let on = |x: [i32; 3]| WPoint::from_point(&bsp_core::Point::Grid(x)).classify(&s);
        assert_eq!(on([0, 0, 5]), Side::On);
        assert_eq!(on([2, 7, 0]), Side::On);
        assert_eq!(on([1, 0, 0]), Side::Back); // interior side of e, on p
    }
}
