//! An exact ray-casting oracle and exact tiling checks, written from scratch
//! on `num-bigint` / `num-rational`.
//!
//! Nothing here calls into `svbsp`'s or `bsp-core`'s arithmetic: the scene
//! is read as integer vertex loops, fragments as homogeneous integer
//! vertices, and every answer is recomputed exactly. Points are rationals
//! held in homogeneous form `(x, y, z) / w` with big integers and `w > 0`
//! (no gcd on the hot paths, which keeps the real-mesh tests fast);
//! parameters along lines are `BigRational`s.
//!
//! Semantics (the issue's): every face blocks light whichever way it faces;
//! a point `X` of face `G` is lit by a point light `L` iff `L` is strictly
//! in front of `G`'s plane (counter-clockwise loop, right-hand normal) and
//! the open segment `(L, X)` touches no closed face; for a sun with
//! direction `D` (toward the light), the open ray `X + tD, t > 0`.
//!
//! A sample point can sit where the answer changes over a set of zero
//! area: on the shadow of an edge, in the plane of an edge-on face, on
//! another face. The oracle says so ([`Verdict::Degenerate`]) instead of
//! guessing; a fragment's flag must equal every non-degenerate verdict on
//! its samples, and every fragment must have at least one.

use std::collections::HashMap;

use bsp_core::internals::I512;
use bsp_core::{I256, Polygon};
use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{One, Signed, ToPrimitive, Zero};
use svbsp::Vertex;
use svbsp::{Light, WPoint};

/// An exact rational.
pub(crate) type Q = BigRational;
/// An integer vector.
pub(crate) type Z3 = [BigInt; 3];

/// A 512-bit integer as a `BigInt`, through its hexadecimal digits.
pub(crate) fn big(x: I512) -> BigInt {
    BigInt::parse_bytes(x.to_str_radix(16).as_bytes(), 16).expect("I512 prints in hexadecimal")
}

/// A 256-bit integer as a `BigInt`.
pub(crate) fn big256(x: I256) -> BigInt {
    BigInt::parse_bytes(x.to_str_radix(16).as_bytes(), 16).expect("I256 prints in hexadecimal")
}

fn z3(p: [i64; 3]) -> Z3 {
    p.map(BigInt::from)
}

fn zsub(a: &Z3, b: &Z3) -> Z3 {
    [&a[0] - &b[0], &a[1] - &b[1], &a[2] - &b[2]]
}

fn zdot(a: &Z3, b: &Z3) -> BigInt {
    &a[0] * &b[0] + &a[1] * &b[1] + &a[2] * &b[2]
}

fn zcross(a: &Z3, b: &Z3) -> Z3 {
    [
        &a[1] * &b[2] - &a[2] * &b[1],
        &a[2] * &b[0] - &a[0] * &b[2],
        &a[0] * &b[1] - &a[1] * &b[0],
    ]
}

fn zscale(a: &Z3, s: &BigInt) -> Z3 {
    [&a[0] * s, &a[1] * s, &a[2] * s]
}

/// `n / d` as an `f64` with a relative error near `2^-58` (for display
/// and for filters with a wide margin), also for numbers past `f64`'s
/// range as long as the quotient is not.
fn ratio_f64(n: &BigInt, d: &BigInt) -> f64 {
    let shift = n.bits().max(d.bits()).saturating_sub(62);
    let (n, d) = (n >> shift, d >> shift);
    n.to_f64().expect("fits") / d.to_f64().expect("fits")
}

/// `floor(n / d)` for `d > 0`.
fn div_floor(n: &BigInt, d: &BigInt) -> BigInt {
    let q = n / d;
    if n.is_negative() && &q * d != *n {
        q - 1
    } else {
        q
    }
}

/// An exact rational point `x / w`, `w > 0`.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct HPoint {
    x: Z3,
    w: BigInt,
}

impl HPoint {
    fn new(x: Z3, w: BigInt) -> HPoint {
        assert!(!w.is_zero(), "a point at infinity");
        if w.is_negative() {
            HPoint {
                x: x.map(|c| -c),
                w: -w,
            }
        } else {
            HPoint { x, w }
        }
    }

    pub(crate) fn grid(p: [i64; 3]) -> HPoint {
        HPoint::new(z3(p), BigInt::one())
    }

    /// The exact point of a fragment vertex.
    pub(crate) fn of(p: &WPoint) -> HPoint {
        let h = p.homogeneous();
        let w = big(h[3]);
        assert!(w.is_positive(), "homogeneous w must be positive: {h:?}");
        HPoint {
            x: [0, 1, 2].map(|k| big(h[k])),
            w,
        }
    }

    /// The exact point of a fragment vertex of the fast path.
    pub(crate) fn of_vertex(v: &Vertex) -> HPoint {
        match v {
            Vertex::Grid(g) => HPoint::grid(g.map(i64::from)),
            Vertex::Implicit(i) => {
                let h = i.coords();
                let w = big256(h[3]);
                assert!(w.is_positive(), "homogeneous w must be positive: {h:?}");
                HPoint {
                    x: [0, 1, 2].map(|k| big256(h[k])),
                    w,
                }
            }
        }
    }

    fn q(&self) -> [Q; 3] {
        self.x.clone().map(|c| Q::new(c, self.w.clone()))
    }

    pub(crate) fn f64(&self) -> [f64; 3] {
        [0, 1, 2].map(|k| ratio_f64(&self.x[k], &self.w))
    }

    /// Integer bounds `[floor, ceil]` per axis.
    fn int_box(&self) -> [(i64, i64); 3] {
        [0, 1, 2].map(|k| {
            let f = div_floor(&self.x[k], &self.w);
            let c = -div_floor(&-&self.x[k], &self.w);
            (f.to_i64().expect("fits"), c.to_i64().expect("fits"))
        })
    }

    /// `Σ λ_i p_i / Σ λ_i` for positive integer weights.
    fn combine(pts: &[HPoint], lambda: &[i64]) -> HPoint {
        let mut x = z3([0, 0, 0]);
        for (i, (p, l)) in pts.iter().zip(lambda).enumerate() {
            let mut f = BigInt::from(*l);
            for (j, o) in pts.iter().enumerate() {
                if j != i {
                    f *= &o.w;
                }
            }
            let t = zscale(&p.x, &f);
            x = [&x[0] + &t[0], &x[1] + &t[1], &x[2] + &t[2]];
        }
        let mut w = BigInt::from(lambda.iter().sum::<i64>());
        for p in pts {
            w *= &p.w;
        }
        HPoint::new(x, w)
    }
}

/// Where a point of a face's plane lies relative to the closed face.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Loc {
    Inside,
    Boundary,
    Outside,
}

/// One input face: a convex planar loop of grid points.
#[derive(Clone, Debug)]
pub(crate) struct Face {
    /// Newell normal `Σ v_i × v_{i+1}`: twice the area vector.
    n: Z3,
    d: BigInt,
    /// Inward edge lines `m · x - c >= 0` (within the plane).
    edges: Vec<(Z3, BigInt)>,
    lo: [i64; 3],
    hi: [i64; 3],
    /// The plane up to a positive factor: coefficients over the first
    /// non-zero normal component, and that component's sign.
    key: ([Q; 4], bool),
}

impl Face {
    /// A face from a convex planar loop (counter-clockwise about its
    /// right-hand normal); repeated consecutive vertices are ignored.
    pub(crate) fn new(pts: &[[i64; 3]]) -> Face {
        let mut v: Vec<[i64; 3]> = Vec::new();
        for p in pts {
            if v.last() != Some(p) {
                v.push(*p);
            }
        }
        while v.len() > 1 && v.first() == v.last() {
            v.pop();
        }
        assert!(v.len() >= 3, "face with fewer than three vertices: {pts:?}");
        let verts: Vec<Z3> = v.iter().map(|p| z3(*p)).collect();
        let k = verts.len();
        let mut n = z3([0, 0, 0]);
        for i in 0..k {
            let c = zcross(&verts[i], &verts[(i + 1) % k]);
            n = [&n[0] + &c[0], &n[1] + &c[1], &n[2] + &c[2]];
        }
        assert!(n.iter().any(|c| !c.is_zero()), "face without area: {pts:?}");
        let d = -zdot(&n, &verts[0]);
        for p in &verts {
            assert!((zdot(&n, p) + &d).is_zero(), "face is not planar: {pts:?}");
        }
        let edges: Vec<(Z3, BigInt)> = (0..k)
            .map(|i| {
                let m = zcross(&n, &zsub(&verts[(i + 1) % k], &verts[i]));
                let c = zdot(&m, &verts[i]);
                (m, c)
            })
            .collect();
        for (i, (m, c)) in edges.iter().enumerate() {
            for p in &verts {
                assert!(
                    !(zdot(m, p) - c).is_negative(),
                    "face is not convex at edge {i}: {pts:?}"
                );
            }
        }
        let mut lo = [i64::MAX; 3];
        let mut hi = [i64::MIN; 3];
        for p in &v {
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        let key = plane_key(&n, &d);
        Face {
            n,
            d,
            edges,
            lo,
            hi,
            key,
        }
    }

    /// A face from a kernel polygon with grid vertices.
    pub(crate) fn from_polygon(p: &Polygon) -> Face {
        let pts: Vec<[i64; 3]> = p
            .vertices()
            .iter()
            .map(|v| {
                v.as_grid()
                    .expect("input polygons have grid vertices")
                    .map(i64::from)
            })
            .collect();
        Face::new(&pts)
    }

    /// The plane's value at `p`, times `p.w > 0`.
    fn eval(&self, p: &HPoint) -> BigInt {
        zdot(&self.n, &p.x) + &self.d * &p.w
    }

    fn locate(&self, p: &HPoint) -> Loc {
        let mut on = false;
        for (m, c) in &self.edges {
            let s = zdot(m, &p.x) - c * &p.w;
            if s.is_negative() {
                return Loc::Outside;
            }
            on |= s.is_zero();
        }
        if on { Loc::Boundary } else { Loc::Inside }
    }

    /// The closed parameter interval of the line `a + t b` (which lies in
    /// the face's plane) inside the face, intersected with `[t0, t1]`
    /// (`None` bounds are infinite); `None` if empty.
    fn clip(
        &self,
        a: &[Q; 3],
        b: &[Q; 3],
        t0: Option<Q>,
        t1: Option<Q>,
    ) -> Option<(Option<Q>, Option<Q>)> {
        let qdot = |m: &Z3, v: &[Q; 3]| -> Q {
            (0..3)
                .map(|k| &v[k] * Q::from_integer(m[k].clone()))
                .fold(Q::zero(), |s, t| s + t)
        };
        let (mut lo, mut hi) = (t0, t1);
        for (m, c) in &self.edges {
            // m · (a + t b) - c >= 0
            let s0 = qdot(m, a) - Q::from_integer(c.clone());
            let s1 = qdot(m, b);
            if s1.is_zero() {
                if s0.is_negative() {
                    return None;
                }
                continue;
            }
            let t = -s0 / &s1;
            if s1.is_positive() {
                if lo.as_ref().is_none_or(|l| t > *l) {
                    lo = Some(t);
                }
            } else if hi.as_ref().is_none_or(|h| t < *h) {
                hi = Some(t);
            }
        }
        match (&lo, &hi) {
            (Some(l), Some(h)) if l > h => None,
            _ => Some((lo, hi)),
        }
    }

    /// The plane's value at a point light, or its normal's product with a
    /// sun direction: positive iff the light is strictly in front.
    fn light_value(&self, light: &Light) -> BigInt {
        match light {
            Light::Point(l) => zdot(&self.n, &z3(l.map(i64::from))) + &self.d,
            Light::Directional(dir) => zdot(&self.n, &z3(dir.map(i64::from))),
        }
    }

    /// `true` if the light is strictly in front of the face's plane.
    pub(crate) fn faces_light(&self, light: &Light) -> bool {
        self.light_value(light).is_positive()
    }

    /// Conservative float test: can the segment `x + t dir`, `t` in
    /// `[0, tmax]`, come within one grid step of the face's bounding box?
    /// Coordinates stay below `2^28` and the floats are within `2^-50` of
    /// the true values, so the errors are far below the one-step margin.
    fn near(&self, x: &[f64; 3], dir: &[f64; 3], tmax: f64) -> bool {
        let (mut t0, mut t1) = (0.0f64, tmax);
        for k in 0..3 {
            let (lo, hi) = (self.lo[k] as f64 - 1.0, self.hi[k] as f64 + 1.0);
            if dir[k] == 0.0 {
                if x[k] < lo || x[k] > hi {
                    return false;
                }
                continue;
            }
            let (a, b) = ((lo - x[k]) / dir[k], (hi - x[k]) / dir[k]);
            let (a, b) = if a < b { (a, b) } else { (b, a) };
            t0 = t0.max(a);
            t1 = t1.min(b);
            if t0 > t1 {
                return false;
            }
        }
        true
    }
}

fn plane_key(n: &Z3, d: &BigInt) -> ([Q; 4], bool) {
    let k = n.iter().find(|c| !c.is_zero()).expect("non-zero normal");
    let r = |c: &BigInt| Q::new(c.clone(), k.clone());
    ([r(&n[0]), r(&n[1]), r(&n[2]), r(d)], k.is_positive())
}

/// A scene: faces indexed by the polygon tags given to the tree.
pub(crate) struct Scene {
    pub(crate) faces: Vec<Face>,
}

/// What the ray oracle says about one sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Verdict {
    /// Lit, and so is every point of the face near the sample.
    Lit,
    /// Shadowed (attached or cast), and so is a neighbourhood.
    Shadowed,
    /// The sample sits on a set of zero area where the answer may change
    /// (shadow of an edge, plane of an edge-on face, another face);
    /// `lit` is the answer at the point itself.
    Degenerate { lit: bool },
}

impl Scene {
    pub(crate) fn new(faces: Vec<Face>) -> Scene {
        Scene { faces }
    }

    pub(crate) fn from_polygons(polys: &[Polygon]) -> Scene {
        Scene::new(polys.iter().map(Face::from_polygon).collect())
    }

    /// The oracle: is the point `x` of face `own` lit by `light`?
    pub(crate) fn verdict(&self, light: &Light, own: usize, x: &HPoint) -> Verdict {
        let g = &self.faces[own];
        if !g.faces_light(light) {
            return Verdict::Shadowed;
        }
        let xb = x.int_box();
        let xf = x.f64();
        // the segment or ray as x + t dir, t in [0, tmax], for the filters
        let (dir, tmax, lo, hi) = match light {
            Light::Point(l) => (
                [0, 1, 2].map(|k| l[k] as f64 - xf[k]),
                1.0,
                [0, 1, 2].map(|k| Some(xb[k].0.min(l[k] as i64))),
                [0, 1, 2].map(|k| Some(xb[k].1.max(l[k] as i64))),
            ),
            Light::Directional(d) => (
                d.map(f64::from),
                f64::INFINITY,
                [0, 1, 2].map(|k| (d[k] >= 0).then_some(xb[k].0)),
                [0, 1, 2].map(|k| (d[k] <= 0).then_some(xb[k].1)),
            ),
        };
        let mut hit = false;
        let mut degenerate = false;
        for (fi, f) in self.faces.iter().enumerate() {
            if fi == own {
                continue;
            }
            let apart = (0..3)
                .any(|a| hi[a].is_some_and(|h| f.lo[a] > h) || lo[a].is_some_and(|l| f.hi[a] < l));
            // (the planes' keys compared last: rationals compare by
            // division, far dearer than the filters that pass over most
            // faces)
            if apart || !f.near(&xf, &dir, tmax) || f.key.0 == g.key.0 {
                // the segment or ray leaves the plane of `own` at once, or
                // cannot come near the face
                continue;
            }
            let ex = f.eval(x);
            let sl = f.light_value(light);
            let crossing =
                if sl.is_positive() && ex.is_negative() || sl.is_negative() && ex.is_positive() {
                    Some(match light {
                        // Y = (sl X - sx L) / (sl - sx), sx = ex / w
                        Light::Point(l) => HPoint::new(
                            zsub(&zscale(&x.x, &sl), &zscale(&z3(l.map(i64::from)), &ex)),
                            &sl * &x.w - &ex,
                        ),
                        // Y = X + t D, t = -sx / sd
                        Light::Directional(d) => HPoint::new(
                            zsub(&zscale(&x.x, &sl), &zscale(&z3(d.map(i64::from)), &ex)),
                            &sl * &x.w,
                        ),
                    })
                } else {
                    if sl.is_zero() && ex.is_zero() {
                        // the segment or ray lies in the face's plane
                        let xq = x.q();
                        let touch = match light {
                            Light::Point(l) => {
                                // L + t (X - L), t in [0, 1]; open: (0, 1)
                                let lq = l.map(|c| Q::from_integer(c.into()));
                                let dq = [0, 1, 2].map(|k| &xq[k] - &lq[k]);
                                f.clip(&lq, &dq, Some(Q::zero()), Some(Q::one()))
                                    .map(|(a, b)| {
                                        let (a, b) = (a.expect("bounded"), b.expect("bounded"));
                                        a < Q::one() && b.is_positive()
                                    })
                            }
                            Light::Directional(d) => {
                                // X + t D, t in [0, inf); open: (0, inf)
                                let dq = d.map(|c| Q::from_integer(c.into()));
                                f.clip(&xq, &dq, Some(Q::zero()), None)
                                    .map(|(_, b)| b.is_none_or(|b| b.is_positive()))
                            }
                        };
                        if let Some(open_hit) = touch {
                            degenerate = true;
                            hit |= open_hit;
                        }
                    }
                    None
                };
            match crossing {
                Some(y) => match f.locate(&y) {
                    Loc::Inside => return Verdict::Shadowed,
                    Loc::Boundary => {
                        hit = true;
                        degenerate = true;
                    }
                    Loc::Outside => {}
                },
                None => {
                    // X on another face: points beside X may be behind it
                    if ex.is_zero() && f.locate(x) != Loc::Outside {
                        degenerate = true;
                    }
                }
            }
        }
        match (degenerate, hit) {
            (true, hit) => Verdict::Degenerate { lit: !hit },
            (false, false) => Verdict::Lit,
            (false, true) => unreachable!("every hit is robust or degenerate"),
        }
    }
}

/// Strictly interior sample points of a convex polygon: the vertex
/// centroid, the midpoints between it and each vertex, then `generic`
/// points with unrelated prime weights.
pub(crate) fn samples(verts: &[HPoint], generic: usize) -> Vec<HPoint> {
    const PRIMES: [i64; 12] = [
        7919,
        104_729,
        1_299_709,
        15_485_863,
        3,
        61,
        997,
        65_537,
        2_147_483_647,
        131,
        17,
        524_287,
    ];
    let k = verts.len();
    let mut out = vec![HPoint::combine(verts, &vec![1; k])];
    for i in 0..k {
        // (centroid + v_i) / 2
        let mut w = vec![1; k];
        w[i] += k as i64;
        out.push(HPoint::combine(verts, &w));
    }
    for s in 0..generic {
        let w: Vec<i64> = (0..k)
            .map(|i| PRIMES[(i * 5 + s * 7 + 1) % PRIMES.len()])
            .collect();
        out.push(HPoint::combine(verts, &w));
    }
    out
}

/// Figures of the flag checks.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct FlagStats {
    /// Fragment-light pairs checked.
    pub(crate) pairs: usize,
    /// Samples that decided a flag.
    pub(crate) decisive: usize,
    /// Samples on a degenerate set (not compared themselves).
    pub(crate) degenerate: usize,
    /// Decisive points probed beside degenerate samples.
    pub(crate) probes: usize,
    /// Pairs whose face does not have the light strictly in front.
    pub(crate) attached: usize,
    /// Pairs lit.
    pub(crate) lit: usize,
    /// Pairs in cast shadow (face facing the light).
    pub(crate) cast: usize,
}

/// A convex piece to check: its face, its flags and its exact vertices.
pub(crate) struct PieceRef<'a> {
    pub(crate) face: usize,
    pub(crate) lit: &'a [bool],
    pub(crate) verts: &'a [HPoint],
}

impl PieceRef<'_> {
    fn f64s(&self) -> Vec<[f64; 3]> {
        self.verts.iter().map(HPoint::f64).collect()
    }
}

/// Checks every flag of a convex piece against the oracle on interior
/// samples.
pub(crate) fn check_flags(
    scene: &Scene,
    lights: &[Light],
    frag: &PieceRef<'_>,
    stats: &mut FlagStats,
) -> Result<(), String> {
    let own = frag.face;
    let verts = frag.verts;
    let g = &scene.faces[own];
    if frag.lit.len() != lights.len() {
        return Err(format!(
            "fragment of face {own} has {} flags for {} lights",
            frag.lit.len(),
            lights.len()
        ));
    }
    let mut pts = samples(verts, 1);
    for (j, light) in lights.iter().enumerate() {
        let flag = frag.lit[j];
        stats.pairs += 1;
        if !g.faces_light(light) {
            stats.attached += 1;
            if flag {
                return Err(format!(
                    "face {own} does not have light {j} ({light:?}) strictly in front, \
                     yet a fragment is lit: {:?}",
                    frag.f64s()
                ));
            }
            continue;
        }
        if flag {
            stats.lit += 1;
        } else {
            stats.cast += 1;
        }
        let mut decided = false;
        let mut next = 0;
        while next < pts.len() || !decided {
            if next == pts.len() {
                // every sample so far is degenerate: more generic ones
                let generic = pts.len() - verts.len();
                if generic > 4 {
                    return Err(format!(
                        "light {j} ({light:?}): every sample of a fragment of face {own} is \
                         degenerate; fragment {:?}",
                        frag.f64s()
                    ));
                }
                pts.push(samples(verts, generic + 1).pop().expect("one more"));
            }
            let x = &pts[next];
            next += 1;
            match scene.verdict(light, own, x) {
                Verdict::Degenerate { .. } => {
                    // on a set of zero area: the points just beside it,
                    // toward each vertex, must agree with the flag (a
                    // shadow boundary through the sample would put some
                    // vertex, and the point toward it, on its far side)
                    stats.degenerate += 1;
                    for v in verts {
                        let probe = HPoint::combine(&[x.clone(), v.clone()], &[(1 << 30) - 1, 1]);
                        match scene.verdict(light, own, &probe) {
                            Verdict::Degenerate { .. } => {}
                            p if (p == Verdict::Lit) != flag => {
                                return Err(format!(
                                    "light {j} ({light:?}): a sample of a {} fragment of face \
                                     {own} is on a shadow boundary: at {:?} the oracle says \
                                     {p:?}; fragment {:?}",
                                    if flag { "lit" } else { "shadowed" },
                                    probe.f64(),
                                    frag.f64s()
                                ));
                            }
                            _ => stats.probes += 1,
                        }
                    }
                }
                v => {
                    stats.decisive += 1;
                    decided = true;
                    if (v == Verdict::Lit) != flag {
                        return Err(format!(
                            "light {j} ({light:?}): fragment of face {own} is {}, but the \
                             ray oracle says {v:?} at {:?}; fragment {:?}",
                            if flag { "lit" } else { "shadowed" },
                            x.f64(),
                            frag.f64s()
                        ));
                    }
                }
            }
        }
    }
    Ok(())
}

/// Twice a polygon's area vector, exactly: the sum of its edges' cross
/// products (pointing where the polygon turns counter-clockwise).
pub(crate) fn twice_area_vector(verts: &[HPoint]) -> [Q; 3] {
    let (a, den) = area2(verts);
    a.map(|c| Q::new(c, den.clone()))
}

/// Twice the area vector of a polygon, `Σ v_i × v_{i+1}`, as an integer
/// vector over the positive denominator `Π w_i`.
fn area2(verts: &[HPoint]) -> (Z3, BigInt) {
    let k = verts.len();
    let mut a = z3([0, 0, 0]);
    for i in 0..k {
        let j = (i + 1) % k;
        let mut f = BigInt::one();
        for (m, v) in verts.iter().enumerate() {
            if m != i && m != j {
                f *= &v.w;
            }
        }
        let c = zscale(&zcross(&verts[i].x, &verts[j].x), &f);
        a = [&a[0] + &c[0], &a[1] + &c[1], &a[2] + &c[2]];
    }
    let den = verts.iter().fold(BigInt::one(), |d, v| d * &v.w);
    (a, den)
}

/// Sign of the 2D orientation of `(p, q, r)` projected along axis `ax`
/// (a 3×3 determinant of homogeneous coordinates; every `w > 0`).
fn orient2(p: &HPoint, q: &HPoint, r: &HPoint, ax: usize) -> BigInt {
    let (a, b) = ((ax + 1) % 3, (ax + 2) % 3);
    let row = |v: &HPoint| [v.x[a].clone(), v.x[b].clone(), v.w.clone()];
    zdot(&row(p), &zcross(&row(q), &row(r)))
}

/// Whether some edge line of the convex polygon `a` has all of `b` on or
/// outside it (`ccw`: `a` runs counter-clockwise in the projection).
fn separated(a: &[HPoint], b: &[HPoint], ax: usize, ccw: bool) -> bool {
    let k = a.len();
    (0..k).any(|i| {
        b.iter().all(|v| {
            let o = orient2(&a[i], &a[(i + 1) % k], v, ax);
            if ccw {
                !o.is_positive()
            } else {
                !o.is_negative()
            }
        })
    })
}

/// A fragment's exact vertices and an integer box around them, stored as
/// `[min; -max]`.
type Boxed = (Vec<HPoint>, [i64; 6]);

/// The least integer box holding the exact vertices (to skip exact tests
/// on pairs whose boxes are apart).
fn boxed(verts: &[HPoint]) -> [i64; 6] {
    let mut bb = [i64::MAX; 6];
    for v in verts {
        for (k, (lo, hi)) in v.int_box().into_iter().enumerate() {
            bb[k] = bb[k].min(lo);
            bb[k + 3] = bb[k + 3].min(-hi);
        }
    }
    bb
}

fn boxes_apart(a: &[i64; 6], b: &[i64; 6]) -> bool {
    (0..3).any(|k| -a[k + 3] < b[k] || -b[k + 3] < a[k])
}

/// The dominant axis of face `g`'s normal, and whether loops that run
/// counter-clockwise about the normal run counter-clockwise in the
/// projection along it.
fn projection(g: &Face) -> (usize, bool) {
    let ax = (0..3)
        .max_by(|&a, &b| g.n[a].abs().cmp(&g.n[b].abs()))
        .expect("three axes");
    (ax, g.n[ax].is_positive())
}

/// A polygon's area as a multiple of its face's (signed: positive when it
/// runs counter-clockwise about the face's normal).
pub(crate) fn area_of(g: &Face, verts: &[HPoint]) -> Q {
    let (a, den) = area2(verts);
    // (unreduced: a sum of areas reduces once per term, not twice)
    Q::new_raw(zdot(&a, &g.n), den * zdot(&g.n, &g.n))
}

/// Checks that convex pieces tile their faces exactly: each piece is
/// strictly convex (recomputed here), lies in its face's plane and inside
/// the face, runs counter-clockwise about the face's normal; per face the
/// areas add up to exactly the face's, and (with `disjoint`) no two pieces
/// overlap. Together these say each face is covered exactly once.
pub(crate) fn check_tiling(
    scene: &Scene,
    pieces: &[(usize, Vec<HPoint>)],
    disjoint: bool,
) -> Result<(), String> {
    let mut sums: Vec<Q> = vec![Q::zero(); scene.faces.len()];
    let mut per_face: HashMap<usize, Vec<Boxed>> = HashMap::new();
    for (i, (fi, verts)) in pieces.iter().enumerate() {
        let fi = *fi;
        let ctx = || {
            format!(
                "piece {i} of face {fi} {:?}",
                verts.iter().map(HPoint::f64).collect::<Vec<_>>()
            )
        };
        let g = scene
            .faces
            .get(fi)
            .ok_or_else(|| format!("piece {i} has unknown face {fi}"))?;
        let k = verts.len();
        if k < 3 {
            return Err(format!("{}: fewer than three vertices", ctx()));
        }
        for (m, v) in verts.iter().enumerate() {
            if !g.eval(v).is_zero() {
                return Err(format!("{}: vertex {m} is off the face's plane", ctx()));
            }
            if g.locate(v) == Loc::Outside {
                return Err(format!("{}: vertex {m} is outside the face", ctx()));
            }
        }
        let (ax, ccw) = projection(g);
        for m in 0..k {
            let o = orient2(&verts[m], &verts[(m + 1) % k], &verts[(m + 2) % k], ax);
            let wrong = if ccw {
                !o.is_positive()
            } else {
                !o.is_negative()
            };
            if wrong {
                return Err(format!(
                    "{}: not strictly convex counter-clockwise at vertex {}",
                    ctx(),
                    (m + 1) % k
                ));
            }
        }
        let a = area_of(g, verts);
        if !a.is_positive() {
            return Err(format!("{}: area is not positive", ctx()));
        }
        sums[fi] += a;
        if disjoint {
            per_face
                .entry(fi)
                .or_default()
                .push((verts.clone(), boxed(verts)));
        }
    }
    for (fi, s) in sums.iter().enumerate() {
        if !s.is_one() {
            return Err(format!(
                "face {fi}: piece areas add up to {} times the face's area",
                s.to_f64().unwrap_or(f64::NAN)
            ));
        }
    }
    for (fi, list) in &per_face {
        let (ax, ccw) = projection(&scene.faces[*fi]);
        for i in 0..list.len() {
            for j in i + 1..list.len() {
                let (a, ba) = &list[i];
                let (b, bb) = &list[j];
                if boxes_apart(ba, bb) || separated(a, b, ax, ccw) || separated(b, a, ax, ccw) {
                    continue;
                }
                return Err(format!(
                    "face {fi}: two pieces overlap: {:?} and {:?}",
                    a.iter().map(HPoint::f64).collect::<Vec<_>>(),
                    b.iter().map(HPoint::f64).collect::<Vec<_>>()
                ));
            }
        }
    }
    Ok(())
}

/// A fragment of the fast path, as the checks see it.
pub(crate) struct Region {
    pub(crate) face: usize,
    pub(crate) lit: Vec<bool>,
    /// The outer ring first, then the holes.
    pub(crate) rings: Vec<Vec<HPoint>>,
    /// Convex pieces whose union the fragment is.
    pub(crate) pieces: Vec<Vec<HPoint>>,
}

/// Checks fragments that are regions: the outer ring runs
/// counter-clockwise and each hole clockwise, every ring vertex lies in
/// the face; the rings' signed areas add up to exactly the pieces' (so the
/// rings bound the pieces' union); no ring has a vertex where it runs
/// straight on; and the regions are as large as they can be: no two
/// fragments of a face with the same flags share a stretch of boundary.
pub(crate) fn check_regions(scene: &Scene, regions: &[Region]) -> Result<(), String> {
    let mut by_face: HashMap<usize, Vec<usize>> = HashMap::new();
    for (i, r) in regions.iter().enumerate() {
        let g = &scene.faces[r.face];
        let ctx = || format!("fragment {i} of face {}", r.face);
        let (ax, ccw) = projection(g);
        let mut ring_area = Q::zero();
        for (k, ring) in r.rings.iter().enumerate() {
            if ring.len() < 3 {
                return Err(format!("{}: ring {k} has {} vertices", ctx(), ring.len()));
            }
            for v in ring {
                if !g.eval(v).is_zero() || g.locate(v) == Loc::Outside {
                    return Err(format!("{}: ring {k} leaves the face", ctx()));
                }
            }
            let m = ring.len();
            for j in 0..m {
                if orient2(&ring[j], &ring[(j + 1) % m], &ring[(j + 2) % m], ax).is_zero() {
                    let (a, c) = (&ring[j], &ring[(j + 2) % m]);
                    // straight on, not a spike back
                    let dot: Q = (0..3)
                        .map(|d| {
                            (&ring[(j + 1) % m].q()[d] - &a.q()[d])
                                * (&c.q()[d] - &ring[(j + 1) % m].q()[d])
                        })
                        .fold(Q::zero(), |s, t| s + t);
                    if dot.is_positive() {
                        return Err(format!(
                            "{}: ring {k} runs straight on at vertex {}",
                            ctx(),
                            (j + 1) % m
                        ));
                    }
                }
            }
            let a = area_of(g, ring);
            if (k == 0) != a.is_positive() {
                return Err(format!(
                    "{}: ring {k} runs the wrong way ({})",
                    ctx(),
                    if k == 0 { "outer" } else { "hole" }
                ));
            }
            ring_area += a;
        }
        let piece_area = r
            .pieces
            .iter()
            .map(|p| area_of(g, p))
            .fold(Q::zero(), |s, t| s + t);
        if ring_area != piece_area {
            return Err(format!(
                "{}: rings enclose {} of the face, pieces {}",
                ctx(),
                ring_area.to_f64().unwrap_or(f64::NAN),
                piece_area.to_f64().unwrap_or(f64::NAN)
            ));
        }
        let _ = ccw;
        by_face.entry(r.face).or_default().push(i);
    }
    // maximality: pieces of different fragments with the same flags never
    // share a stretch of edge
    for (face, list) in &by_face {
        let (ax, _) = projection(&scene.faces[*face]);
        let items: Vec<(usize, &Vec<HPoint>, [i64; 6])> = list
            .iter()
            .flat_map(|&i| regions[i].pieces.iter().map(move |p| (i, p, boxed(p))))
            .collect();
        for a in 0..items.len() {
            for b in a + 1..items.len() {
                let (ia, pa, ba) = &items[a];
                let (ib, pb, bb) = &items[b];
                if ia == ib || regions[*ia].lit != regions[*ib].lit || boxes_apart(ba, bb) {
                    continue;
                }
                if share_edge(pa, pb, ax) {
                    return Err(format!(
                        "face {face}: fragments {ia} and {ib} have the same flags {:?} but \
                         touch along an edge: a cut that separates nothing survived",
                        regions[*ia].lit
                    ));
                }
            }
        }
    }
    Ok(())
}

/// `true` if some edge of `a` and some edge of `b` overlap along a
/// stretch of positive length (projected along axis `ax`).
fn share_edge(a: &[HPoint], b: &[HPoint], ax: usize) -> bool {
    let (u, v) = ((ax + 1) % 3, (ax + 2) % 3);
    let (ka, kb) = (a.len(), b.len());
    for i in 0..ka {
        let (p, q) = (&a[i], &a[(i + 1) % ka]);
        for j in 0..kb {
            let (r, s) = (&b[j], &b[(j + 1) % kb]);
            if !orient2(p, q, r, ax).is_zero() || !orient2(p, q, s, ax).is_zero() {
                continue;
            }
            // collinear: compare the parameters along the longer axis
            let (pq, qq, rq, sq) = (p.q(), q.q(), r.q(), s.q());
            let t = if (&qq[u] - &pq[u]).abs() >= (&qq[v] - &pq[v]).abs() {
                u
            } else {
                v
            };
            let (lo1, hi1) = if pq[t] < qq[t] {
                (&pq[t], &qq[t])
            } else {
                (&qq[t], &pq[t])
            };
            let (lo2, hi2) = if rq[t] < sq[t] {
                (&rq[t], &sq[t])
            } else {
                (&sq[t], &rq[t])
            };
            let lo = if lo1 > lo2 { lo1 } else { lo2 };
            let hi = if hi1 < hi2 { hi1 } else { hi2 };
            if lo < hi {
                return true;
            }
        }
    }
    false
}

#[test]
fn i512_converts_exactly() {
    for c in [0i128, 1, -1, i128::MAX, i128::MIN] {
        assert_eq!(big(I512::from(c)), BigInt::from(c));
    }
    let huge = I512::from(-3i128) << 400u32;
    assert_eq!(big(huge), BigInt::from(-3) << 400);
}

#[test]
fn floats_and_floors_of_huge_rationals() {
    let n = (BigInt::from(7) << 1500) + 1;
    let d = BigInt::from(2) << 1500;
    assert_eq!(ratio_f64(&n, &d), 3.5);
    assert_eq!(ratio_f64(&-n.clone(), &d), -3.5);
    assert_eq!(div_floor(&n, &d), BigInt::from(3));
    assert_eq!(div_floor(&-n, &d), BigInt::from(-4));
    assert_eq!(
        div_floor(&BigInt::from(-8), &BigInt::from(4)),
        BigInt::from(-2)
    );
    let p = HPoint::new(z3([-7, 8, 0]), BigInt::from(-2));
    assert_eq!(p.int_box(), [(3, 4), (-4, -4), (0, 0)]);
}

#[cfg(test)]
fn at(x: i64, y: i64, z: i64) -> HPoint {
    HPoint::grid([x, y, z])
}

#[test]
fn oracle_sees_a_square_shadow() {
    // floor [0,8]^2 at z = 0 and a roof [2,4]^2 at z = 4, light at (3,3,8):
    // the shadow on the floor is [1,5]^2 — probed inside, outside, and on
    // its edge (degenerate)
    let floor = Face::new(&[[0, 0, 0], [8, 0, 0], [8, 8, 0], [0, 8, 0]]);
    let roof = Face::new(&[[2, 2, 4], [4, 2, 4], [4, 4, 4], [2, 4, 4]]);
    let scene = Scene::new(vec![floor, roof]);
    let l = Light::Point([3, 3, 8]);
    assert_eq!(scene.verdict(&l, 0, &at(3, 3, 0)), Verdict::Shadowed);
    assert_eq!(scene.verdict(&l, 0, &at(6, 3, 0)), Verdict::Lit);
    assert_eq!(
        scene.verdict(&l, 0, &at(5, 3, 0)),
        Verdict::Degenerate { lit: false }
    );
    // the roof is lit from above, in attached shadow from below
    assert_eq!(scene.verdict(&l, 1, &at(3, 3, 4)), Verdict::Lit);
    let below = Light::Point([3, 3, -1]);
    assert_eq!(scene.verdict(&below, 1, &at(3, 3, 4)), Verdict::Shadowed);
    // a sun straight up: the shadow is the roof's footprint
    let sun = Light::Directional([0, 0, 1]);
    assert_eq!(scene.verdict(&sun, 0, &at(3, 3, 0)), Verdict::Shadowed);
    assert_eq!(scene.verdict(&sun, 0, &at(5, 3, 0)), Verdict::Lit);
    assert_eq!(
        scene.verdict(&sun, 0, &at(4, 3, 0)),
        Verdict::Degenerate { lit: false }
    );
    // a slanted sun moves the shadow: (1, 0, 2) puts it at x in [0, 2]
    let slant = Light::Directional([1, 0, 2]);
    assert_eq!(scene.verdict(&slant, 0, &at(1, 3, 0)), Verdict::Shadowed);
    assert_eq!(scene.verdict(&slant, 0, &at(3, 3, 0)), Verdict::Lit);
    // a sun parallel to the floor: not strictly in front of it
    let flat = Light::Directional([1, 0, 0]);
    assert_eq!(scene.verdict(&flat, 0, &at(3, 3, 0)), Verdict::Shadowed);
}

#[test]
fn oracle_edge_on_face_is_degenerate() {
    // a wall in the plane x = 4, which holds the light: a zero-width shadow
    let floor = Face::new(&[[0, 0, 0], [8, 0, 0], [8, 8, 0], [0, 8, 0]]);
    let wall = Face::new(&[[4, 2, 1], [4, 6, 1], [4, 6, 3], [4, 2, 3]]);
    let scene = Scene::new(vec![floor, wall]);
    let l = Light::Point([4, 4, 8]);
    assert_eq!(
        scene.verdict(&l, 0, &at(4, 3, 0)),
        Verdict::Degenerate { lit: false }
    );
    assert_eq!(scene.verdict(&l, 0, &at(3, 3, 0)), Verdict::Lit);
    assert_eq!(
        scene.verdict(&l, 0, &at(4, 7, 0)),
        Verdict::Degenerate { lit: false }
    );
    // further along the wall's plane the segment passes beside the wall
    assert_eq!(scene.verdict(&l, 0, &at(4, 8, 0)), Verdict::Lit);
    // a sun in the wall's plane: the ray from (4, 3, 0) runs up the wall
    let sun = Light::Directional([0, 1, 2]);
    assert_eq!(
        scene.verdict(&sun, 0, &at(4, 3, 0)),
        Verdict::Degenerate { lit: false }
    );
    assert_eq!(scene.verdict(&sun, 0, &at(4, 7, 0)), Verdict::Lit);
}

#[test]
fn oracle_point_on_another_face_is_degenerate() {
    // a wall standing on the floor along y = 4, light in front of it
    let floor = Face::new(&[[0, 0, 0], [8, 0, 0], [8, 8, 0], [0, 8, 0]]);
    let wall = Face::new(&[[2, 4, 0], [6, 4, 0], [6, 4, 3], [2, 4, 3]]);
    let scene = Scene::new(vec![floor, wall]);
    let l = Light::Point([4, 0, 2]);
    assert_eq!(
        scene.verdict(&l, 0, &at(4, 4, 0)),
        Verdict::Degenerate { lit: true }
    );
    assert_eq!(scene.verdict(&l, 0, &at(4, 5, 0)), Verdict::Shadowed);
    assert_eq!(scene.verdict(&l, 0, &at(4, 3, 0)), Verdict::Lit);
}
