//! What a grid point sees of a polygon light or a sun disc, as cones of
//! directions from it: the quick path of the visible share
//! ([`seen_share`], [`sky_seen_share`]).
//!
//! Every plane the share needs passes through the point `x`: the planes
//! through `x` and a light edge bound the light's cone (for a sun, the
//! planes through two of its directions), and those through `x` and an
//! occluder edge bound the occluder's. So with `x` as origin each is a
//! normal vector alone, `(a − x) × (b − x)` of two grid points: below
//! `2^55` per coordinate. A piece of the light is a convex cone, its
//! boundary planes in turn (counter-clockwise seen from `x`, normals
//! inward); its corner `i` is the ray `n_i × n_{i+1}` (below `2^111`,
//! kept rounded to `f64`), and the side of a plane `m` it lies on is the
//! sign of `m · (n_i × n_{i+1})`, below `2^168`: from the rounded ray
//! where the error bound decides, else exactly in two `i128` limbs.
//! Cutting makes no new numbers, only new lists of planes.
//!
//! An occluder hides the light points `q` whose segment `x q` meets it.
//! Where it lies on `x`'s side of the light's plane (corners on the plane
//! allowed), those are exactly the light points in its cone: the ray to
//! `q` meets it before the light's plane. Where it lies on the light's
//! plane or beyond, it hides no area of the light; a sun is beyond every
//! occluder. What lies behind the point's face is cut off by the plane
//! through `x` parallel to the face's (its normal, below `2^55` too): the
//! face's own plane where `x` lies on it, and for a probe point rounded
//! off it, the half-space its irradiance is taken over. An occluder
//! crossing the light's plane is left to the general paths
//! (`AreaLight::view_among`, which cuts exact polygons in space, and the
//! sun's chart in `soft.rs`).

use bsp_core::internals::filter_side;
use bsp_core::{GridPoint, Plane, Side};
use glam::DVec3;
use rustc_hash::FxHashMap;
use smallvec::SmallVec;

use crate::area::Occluder;

/// A plane through the viewing point, by its normal; inside: `n · d > 0`.
type Line = [i64; 3];

/// The boundary planes of a convex cone of directions, in turn.
type Planes = SmallVec<[Line; 6]>;

/// An occluder's cone from the viewing point: its boundary planes, and
/// the directions to its corners (grid differences, below `2^27`), whose
/// positive hull it is.
struct Cone {
    planes: Planes,
    corners: SmallVec<[[i64; 3]; 4]>,
}

/// The ray `a × b` of two planes, exactly (below `2^111`) and rounded to
/// `f64`.
#[derive(Clone, Copy, Debug)]
struct Ray {
    exact: [i128; 3],
    approx: [f64; 3],
}

impl Ray {
    fn new(a: &Line, b: &Line) -> Ray {
        let m = |p: i64, q: i64| i128::from(p) * i128::from(q);
        let exact = [
            m(a[1], b[2]) - m(a[2], b[1]),
            m(a[2], b[0]) - m(a[0], b[2]),
            m(a[0], b[1]) - m(a[1], b[0]),
        ];
        Ray {
            exact,
            approx: exact.map(|v| v as f64),
        }
    }
}

/// The pieces of one point's view: every piece's planes in turn
/// (counter-clockwise seen from the point) and its corners' rays rounded
/// to `f64` (corner `i` between planes `i` and `i + 1`; the exact ray is
/// made again where the rounded one does not decide), a piece a range of
/// both lists. Cutting appends its parts' lists and moves no piece.
#[derive(Default)]
struct Pool {
    planes: Vec<Line>,
    rays: Vec<[f64; 3]>,
}

/// A convex piece of the light's cone: the range `at..at + len` of its
/// [`Pool`]'s lists.
#[derive(Clone, Copy, Debug)]
struct Piece {
    at: u32,
    len: u32,
}

impl Pool {
    /// A piece bounded by `planes`, its rays made from them.
    fn add(&mut self, planes: &[Line]) -> Piece {
        let n = planes.len();
        let at = self.planes.len() as u32;
        self.planes.extend_from_slice(planes);
        self.rays
            .extend((0..n).map(|i| Ray::new(&planes[i], &planes[(i + 1) % n]).approx));
        Piece { at, len: n as u32 }
    }

    /// The planes of `p`, in turn.
    fn planes(&self, p: Piece) -> &[Line] {
        &self.planes[p.at as usize..(p.at + p.len) as usize]
    }

    /// The rays of `p`'s corners, rounded.
    fn rays(&self, p: Piece) -> &[[f64; 3]] {
        &self.rays[p.at as usize..(p.at + p.len) as usize]
    }

    /// The side of plane `m` corner `i` of `p` lies on.
    fn side(&self, p: Piece, m: &Line, i: usize) -> i32 {
        let at = p.at as usize;
        match filtered(m, &self.rays[at + i]) {
            Some(s) => s,
            None => {
                let next = at + (i + 1) % p.len as usize;
                exact_side(m, &Ray::new(&self.planes[at + i], &self.planes[next]))
            }
        }
    }
}

/// The share of the light polygon with grid `corners` (strictly convex)
/// that grid point `x` on a face with plane `face` and unit `normal`
/// receives past `hiders` (in the order given), as
/// [`crate::LightView::fraction`] gives it: `None` where this path does
/// not apply (see the module docs), else that value (`Some(None)`:
/// nothing arrives).
pub(crate) fn seen_share<'o>(
    corners: &[GridPoint],
    light: &Plane,
    face: &Plane,
    x: GridPoint,
    normal: DVec3,
    hiders: impl Iterator<Item = &'o Occluder>,
) -> Option<Option<f64>> {
    if light.classify_grid(x) != Side::Front {
        return None;
    }
    // every occluder wholly on `x`'s side of the light's plane, or on it
    // or beyond (hiding nothing)
    let mut hiding: Vec<&Occluder> = Vec::new();
    for o in hiders {
        let sides = o.corners().iter().map(|&c| light.classify_grid(c));
        // (a corner on the light's plane hides an area of it from
        // neither side)
        let (near, far) = sides.fold((0, 0), |(n, f), s| match s {
            Side::Front => (n + 1, f),
            Side::Back => (n, f + 1),
            Side::On => (n, f),
        });
        if near > 0 && far > 0 {
            return None;
        }
        if near > 0 {
            hiding.push(o);
        }
    }
    let mut pool = Pool::default();
    let whole = pool.add(&light_cone(corners.iter().map(|&c| from(x, c)))?);
    let Some(light_cone) = in_front(&mut pool, whole, face) else {
        return Some(None);
    };
    let all = form_factor(normal, pool.rays(light_cone));
    if all <= 0.0 {
        return Some(None);
    }
    // (each cone made as it is reached: a point that sees nothing stops
    // early)
    let cones = hiding.iter().filter_map(|o| occluder_cone(o.corners(), x));
    let Some(seen) = visible(&mut pool, light_cone, cones) else {
        return Some(Some(1.0));
    };
    #[cfg(test)]
    tests::SEEN.with(|s| *s.borrow_mut() = cones_of(&pool, &seen));
    let part: f64 = seen
        .iter()
        .map(|&c| form_factor(normal, pool.rays(c)))
        .sum();
    Some(Some((part / all).clamp(0.0, 1.0)))
}

/// The planes of `pieces`, each in turn (for tests that measure them
/// exactly).
#[cfg(test)]
fn cones_of(pool: &Pool, pieces: &[Piece]) -> Vec<Planes> {
    (pieces.iter())
        .map(|&p| pool.planes(p).iter().copied().collect())
        .collect()
}

/// The share of a sun disc's polygon of directions `sky` (quantized, in
/// order) that grid point `x` on a face with plane `face` sees past
/// `hiders`, as `soft::sky_share` measures it: of its directions in front
/// of the face (`n · d > 0`, a plane through `x` too), the part no
/// occluder hides, by areas on the plane tangent to the sky at the
/// directions' centre. `None` where this path does not apply (the
/// quantized directions make no strictly convex cone); `Some(None)` where
/// no direction is in front of the face.
pub(crate) fn sky_seen_share<'o>(
    sky: &[[i32; 3]],
    face: &Plane,
    x: GridPoint,
    hiders: impl Iterator<Item = &'o Occluder>,
) -> Option<Option<f64>> {
    let dirs = || sky.iter().map(|d| d.map(i64::from));
    let mut pool = Pool::default();
    let whole = pool.add(&light_cone(dirs())?);
    let Some(light) = in_front(&mut pool, whole, face) else {
        return Some(None);
    };
    // a sun is beyond every occluder: each hides its whole cone
    let cones = hiders.filter_map(|o| occluder_cone(o.corners(), x));
    let c = dirs()
        .map(|d| DVec3::from_array(d.map(|v| v as f64)))
        .sum::<DVec3>()
        .normalize();
    let u = c.any_orthonormal_vector();
    let v = c.cross(u);
    let area = |rays: &[[f64; 3]]| {
        let q: SmallVec<[(f64, f64); 8]> = (rays.iter())
            .map(|r| {
                let r = DVec3::from_array(*r);
                (r.dot(u) / r.dot(c), r.dot(v) / r.dot(c))
            })
            .collect();
        let k = q.len();
        let twice: f64 = (0..k)
            .map(|i| q[i].0 * q[(i + 1) % k].1 - q[(i + 1) % k].0 * q[i].1)
            .sum();
        twice.abs() / 2.0
    };
    let all = area(pool.rays(light));
    if all <= 0.0 {
        return Some(None);
    }
    let Some(seen) = visible(&mut pool, light, cones) else {
        return Some(Some(1.0));
    };
    #[cfg(test)]
    tests::SEEN.with(|s| *s.borrow_mut() = cones_of(&pool, &seen));
    let left: f64 = seen.iter().map(|&p| area(pool.rays(p))).sum();
    Some(Some((left / all).clamp(0.0, 1.0)))
}

/// What of the cone `light` lies in front of the face of plane `face`,
/// seen from the apex: beyond the plane through it parallel to the
/// face's; `None` where nothing does.
fn in_front(pool: &mut Pool, light: Piece, face: &Plane) -> Option<Piece> {
    let front = face.normal();
    let s = sides(pool, light, &front);
    if s.iter().all(|&v| v <= 0) {
        return None;
    }
    Some(match s.contains(&-1) {
        true => keep(pool, light, &s, 1, front),
        false => light,
    })
}

/// What of `light` lies outside every cone of `cones` (in their order),
/// as convex pieces; `None` where no cone hid any of it.
fn visible(pool: &mut Pool, light: Piece, cones: impl Iterator<Item = Cone>) -> Option<Vec<Piece>> {
    let mut seen = vec![light];
    let (mut hidden, mut merged) = (false, 0);
    let mut parts = Vec::new();
    for cone in cones {
        // pieces the cone leaves whole stay in place; the parts of those
        // it cuts outside it are appended
        let mut i = 0;
        while i < seen.len() {
            if cut(pool, &cone, seen[i], &mut parts) {
                hidden = true;
                seen.swap_remove(i);
            } else {
                i += 1;
            }
        }
        seen.append(&mut parts);
        if seen.is_empty() {
            break;
        }
        // merged as they pile up (later cones then meet fewer)
        if seen.len() > 16 && seen.len() > 2 * merged {
            seen = merge(pool, seen);
            merged = seen.len();
        }
    }
    hidden.then_some(seen)
}

/// `a × b` of grid differences (below `2^27`): below `2^55`.
fn cross(a: [i64; 3], b: [i64; 3]) -> Line {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn from(x: GridPoint, p: GridPoint) -> [i64; 3] {
    [0, 1, 2].map(|k| i64::from(p[k]) - i64::from(x[k]))
}

/// The light's cone from a point, of the directions `d` to its corners
/// (a polygon's, the point off its plane; or a sun's directions):
/// counter-clockwise seen from the point, so that `n_i × n_{i+1}` points
/// along corner `i + 1`; `None` unless it is strictly convex (every three
/// corners in turn turn the same way).
fn light_cone(d: impl Iterator<Item = [i64; 3]>) -> Option<Planes> {
    let d: Vec<[i64; 3]> = d.collect();
    let n = d.len();
    if n < 3 {
        return None;
    }
    let turn = det_sign(&d[0], &d[1], &d[2]);
    let convex = (0..n).all(|i| det_sign(&d[i], &d[(i + 1) % n], &d[(i + 2) % n]) == turn);
    if turn == 0 || !convex {
        return None;
    }
    let planes = (0..n)
        .map(|i| match turn {
            1 => cross(d[i], d[(i + 1) % n]),
            _ => cross(d[(n - i) % n], d[(2 * n - i - 1) % n]),
        })
        .collect();
    Some(planes)
}

/// The cone of directions from `x` that meet occluder `corners` (a convex
/// polygon): inside the plane through `x` and each edge, on the side of
/// the next corner; `None` where `x` lies in the occluder's plane.
fn occluder_cone(corners: &[GridPoint], x: GridPoint) -> Option<Cone> {
    let n = corners.len();
    let d: SmallVec<[[i64; 3]; 4]> = corners.iter().map(|&c| from(x, c)).collect();
    let mut cone = Planes::new();
    for i in 0..n {
        let h = cross(d[i], d[(i + 1) % n]);
        match dot(&h, &d[(i + 2) % n]).signum() {
            1 => cone.push(h),
            -1 => cone.push(h.map(|v| -v)),
            _ => return None,
        }
    }
    Some(Cone {
        planes: cone,
        corners: d,
    })
}

/// `l · d` exactly, for `l` below `2^55` and `d` below `2^27`.
fn dot(l: &Line, d: &[i64; 3]) -> i128 {
    (0..3).map(|k| i128::from(l[k]) * i128::from(d[k])).sum()
}

/// The sign of `det(a, b, c) = a · (b × c)` for coordinates below `2^55`:
/// the side of `a` that the ray `b × c` lies on.
fn det_sign(a: &Line, b: &Line, c: &Line) -> i32 {
    side(a, &Ray::new(b, c))
}

/// The side of plane `m` (below `2^55`) ray `r` lies on: the sign of
/// `m · r`.
fn side(m: &Line, r: &Ray) -> i32 {
    filtered(m, &r.approx).unwrap_or_else(|| exact_side(m, r))
}

/// The sign of `m · r` from `r` correctly rounded, where the kernel's one
/// `f64` filter (`bsp_core::internals::filter_side`: both sides within
/// `3 · 2^-53` of exact integers, as one rounding each leaves them)
/// certifies it; `None` sends the caller to [`exact_side`].
fn filtered(m: &Line, r: &[f64; 3]) -> Option<i32> {
    let plane = [m[0] as f64, m[1] as f64, m[2] as f64, 0.0];
    filter_side(&plane, &[r[0], r[1], r[2], 0.0]).map(|s| match s {
        Side::Front => 1,
        Side::Back => -1,
        Side::On => 0,
    })
}

/// The sign of `m · r` exactly: each `r_k = h_k 2^64 + l_k` with
/// `0 ≤ l_k < 2^64`, so `m · r = A 2^64 + B` with `A = Σ m_k h_k` (below
/// `2^104`) and `B = Σ m_k l_k` (below `2^121`).
fn exact_side(m: &Line, r: &Ray) -> i32 {
    let (mut a, mut b) = (0i128, 0i128);
    for (&m, &c) in m.iter().zip(&r.exact) {
        a += i128::from(m) * (c >> 64);
        b += i128::from(m) * i128::from(c as u64);
    }
    // A 2^64 + B = (A + ⌊B / 2^64⌋) 2^64 + (B mod 2^64)
    let high = a + (b >> 64);
    match high.signum() {
        0 => i32::from(b as u64 != 0),
        s => s as i32,
    }
}

/// The side of `m` each corner of `piece` lies on.
fn sides(pool: &Pool, piece: Piece, m: &Line) -> SmallVec<[i32; 6]> {
    (0..piece.len as usize)
        .map(|i| pool.side(piece, m, i))
        .collect()
}

/// The planes of `piece` whose edge has a corner strictly on side `on` of
/// the cutting plane, then the cutting plane `m` (inward for that part).
/// Some corner is strictly on each side.
fn keep(pool: &mut Pool, piece: Piece, s: &[i32], on: i32, m: Line) -> Piece {
    let (at, n) = (piece.at as usize, piece.len as usize);
    // the corners on side `on` are a run (the cone is convex); edge i runs
    // from corner i − 1 to corner i, so the edges ending at the run's
    // first corner through the one leaving its last are kept
    let first = (0..n)
        .find(|&i| s[i] == on && s[(i + n - 1) % n] != on)
        .unwrap_or(0);
    let run = (0..n).take_while(|&k| s[(first + k) % n] == on).count();
    let start = pool.planes.len();
    for k in 0..=run {
        let l = pool.planes[at + (first + k) % n];
        pool.planes.push(l);
    }
    // the kept corners, then the two where `m` cuts
    for k in 0..run {
        let r = pool.rays[at + (first + k) % n];
        pool.rays.push(r);
    }
    let (last, head) = (pool.planes[start + run], pool.planes[start]);
    pool.rays.push(Ray::new(&last, &m).approx);
    pool.rays.push(Ray::new(&m, &head).approx);
    pool.planes.push(m);
    Piece {
        at: start as u32,
        len: (run + 2) as u32,
    }
}

/// Cuts `piece` by `cone`: where some of it lies inside, its parts
/// outside are pushed to `out` and `true` returned; a piece only touching
/// the cone is left whole (`false`).
fn cut(pool: &mut Pool, cone: &Cone, piece: Piece, out: &mut Vec<Piece>) -> bool {
    let n = piece.len as usize;
    // apart where a plane of either has the other wholly outside it
    // (the piece's planes against the cone's corner directions: exact
    // products of integers)
    if (pool.planes(piece).iter()).any(|l| cone.corners.iter().all(|c| dot(l, c) <= 0)) {
        return false;
    }
    let cone = &cone.planes;
    if cone
        .iter()
        .any(|m| (0..n).all(|i| pool.side(piece, m, i) <= 0))
    {
        return false;
    }
    let start = out.len();
    let mut rest = piece;
    for m in cone {
        let s = sides(pool, rest, m);
        if s.iter().all(|&v| v >= 0) {
            continue;
        }
        if s.iter().all(|&v| v <= 0) {
            // the cone's planes each cross the piece, and yet it misses
            // their meet: left whole
            out.truncate(start);
            return false;
        }
        let outside = keep(pool, rest, &s, -1, m.map(|v| -v));
        out.push(outside);
        rest = keep(pool, rest, &s, 1, *m);
    }
    true
}

/// Merges pieces pairwise where they share a whole edge and their union
/// is convex, until none do. Deterministic: the input order decides.
fn merge(pool: &mut Pool, mut pieces: Vec<Piece>) -> Vec<Piece> {
    // each plane, up to sign, to the pieces bounded by it
    let key = |l: &Line| match l.iter().find(|&&v| v != 0) {
        Some(&v) if v < 0 => l.map(|c| -c),
        _ => *l,
    };
    loop {
        let mut at: FxHashMap<Line, SmallVec<[u32; 4]>> = FxHashMap::default();
        for (i, &p) in pieces.iter().enumerate() {
            for l in pool.planes(p) {
                at.entry(key(l)).or_default().push(i as u32);
            }
        }
        let mut dead = vec![false; pieces.len()];
        let mut any = false;
        for i in 0..pieces.len() {
            if dead[i] {
                continue;
            }
            let mut partners: SmallVec<[u32; 8]> = (pool.planes(pieces[i]).iter())
                .flat_map(|l| at[&key(l)].iter().copied())
                .filter(|&j| j as usize > i)
                .collect();
            partners.sort_unstable();
            partners.dedup();
            for j in partners {
                let j = j as usize;
                if dead[j] {
                    continue;
                }
                if let Some(m) = union(pool, pieces[i], pieces[j]) {
                    pieces[i] = m;
                    dead[j] = true;
                    any = true;
                }
            }
        }
        if !any {
            return pieces;
        }
        pieces = pieces
            .into_iter()
            .zip(dead)
            .filter_map(|(p, d)| (!d).then_some(p))
            .collect();
    }
}

/// The union of two pieces that share a whole edge, where it is convex.
fn union(pool: &mut Pool, p: Piece, q: Piece) -> Option<Piece> {
    let (pl, ql): (Planes, Planes) = (
        pool.planes(p).iter().copied().collect(),
        pool.planes(q).iter().copied().collect(),
    );
    let (k, j) = (pl.len(), ql.len());
    let neg = |l: &Line| l.map(|v| -v);
    let (a, b) = (0..k).find_map(|a| Some((a, ql.iter().position(|l| *l == neg(&pl[a]))?)))?;
    let (pp, qp) = (&pl[(a + k - 1) % k], &ql[(b + j - 1) % j]);
    // the shared edge's ends: p's start (its corner a − 1) on q's plane
    // after the shared one, p's end (corner a) on q's plane before it
    if pool.side(p, &ql[(b + 1) % j], (a + k - 1) % k) != 0 || pool.side(p, qp, a) != 0 {
        return None;
    }
    // convex where the boundary passes from one to the other: the far
    // corner of the edge leaving each junction inside the edge entering it
    let one = pool.side(q, pp, (b + 1) % j);
    let two = pool.side(p, qp, (a + 1) % k);
    if one < 0 || two < 0 {
        return None;
    }
    let mut planes = Planes::new();
    // p from after the shared edge round to before it, then q likewise;
    // a straight junction keeps one of its two (equal) planes
    planes.extend((1..k).map(|t| pl[(a + t) % k]));
    planes.extend(
        (1..j)
            .map(|t| ql[(b + t) % j])
            .enumerate()
            .filter_map(|(t, l)| {
                let straight = (t == 0 && one == 0) || (t == j - 2 && two == 0);
                (!straight).then_some(l)
            }),
    );
    (planes.len() >= 3).then(|| pool.add(&planes))
}

/// The form factor from a point with unit `normal` to a piece's
/// directions, its corners' `rays` ([`crate::form_factor`] of the rays
/// from the origin: Lambert's closed form needs their directions only), in
/// `f64`.
fn form_factor(normal: DVec3, rays: &[[f64; 3]]) -> f64 {
    crate::form_factor(DVec3::ZERO, normal, rays)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{AreaLight, LightView, Visibility};
    use bnum::cast::As;
    use bnum::types::I256;
    use bsp_core::Polygon;
    use num_bigint::BigInt;
    use num_rational::BigRational;
    use num_traits::{Signed, Zero};
    use proptest::prelude::*;

    thread_local! {
        /// The seen pieces' planes of the last share taken on this
        /// thread (set by [`seen_share`] and [`sky_seen_share`] in tests).
        pub(super) static SEEN: std::cell::RefCell<Vec<Planes>> =
            const { std::cell::RefCell::new(Vec::new()) };
    }

    /// A disc's radius of one quantization step of a direction (`1 /
    /// MAX_COORD` radians): about the least a quantized octagon can hold,
    /// where it may be no strictly convex cone and the disc is left to
    /// the `f64` chart.
    const TINY_DISC: f64 = 1.0 / bsp_core::MAX_COORD as f64;

    /// An exact `BigInt` of an `I256`.
    fn big(v: I256) -> BigInt {
        BigInt::parse_bytes(v.to_str_radix(16).as_bytes(), 16).expect("I256 prints in hexadecimal")
    }

    /// Twice the area, exactly, of convex polygons (corners in turn, as
    /// exact points relative to one origin) drawn on the two coordinates
    /// other than `k`: each polygon's area taken unsigned, then summed.
    fn twice_area(rings: &[Vec<[BigRational; 3]>], k: usize) -> BigRational {
        let (u, v) = ((k + 1) % 3, (k + 2) % 3);
        let mut sum = BigRational::zero();
        for ring in rings {
            let n = ring.len();
            let mut a = BigRational::zero();
            for i in 0..n {
                let (p, q) = (&ring[i], &ring[(i + 1) % n]);
                a += &p[u] * &q[v] - &q[u] * &p[v];
            }
            sum += a.abs();
        }
        sum
    }

    /// Where the seen cones (their planes through `x`) meet the plane
    /// `plane`, relative to `x`, exactly: corner `i` on the ray of planes
    /// `i` and `i + 1`.
    fn cones_on(cones: &[Planes], plane: &Plane, x: GridPoint) -> Vec<Vec<[BigRational; 3]>> {
        let n = plane.normal().map(BigInt::from);
        let at_x = (0..3).fold(BigInt::from(plane.offset()), |a, k| {
            a + &n[k] * BigInt::from(x[k])
        });
        (cones.iter())
            .map(|planes| {
                let m = planes.len();
                (0..m)
                    .map(|i| {
                        let r = Ray::new(&planes[i], &planes[(i + 1) % m])
                            .exact
                            .map(BigInt::from);
                        let along = (0..3).fold(BigInt::zero(), |a, k| a + &n[k] * &r[k]);
                        // x + t r on the plane: t = -(n · x + d) / (n · r)
                        let t = BigRational::new(-at_x.clone(), along);
                        r.map(|c| &t * BigRational::from_integer(c))
                    })
                    .collect()
            })
            .collect()
    }

    /// Exact polygons, relative to `x`.
    fn polygons_at(polys: &[Polygon], x: GridPoint) -> Vec<Vec<[BigRational; 3]>> {
        (polys.iter())
            .map(|p| {
                (p.vertices().iter())
                    .map(|v| {
                        let h = v.homogeneous();
                        let w = big(h[3]);
                        [0, 1, 2].map(|k| {
                            BigRational::new(big(h[k]), w.clone())
                                - BigRational::from_integer(BigInt::from(x[k]))
                        })
                    })
                    .collect()
            })
            .collect()
    }

    /// Whether the cones [`SEEN`] last found from `x` cut the plane of the
    /// light `view` was taken of in exactly the area of `view.seen`.
    fn same_seen(view: &LightView, light: &Plane, x: GridPoint) -> bool {
        let k = light.dominant_axis();
        let cones = SEEN.with(|s| s.borrow().clone());
        twice_area(&cones_on(&cones, light, x), k) == twice_area(&polygons_at(&view.seen, x), k)
    }

    /// The general path's view (exact polygons in space) and share.
    fn general(
        light: &AreaLight,
        face: &Plane,
        x: GridPoint,
        normal: DVec3,
        hiders: &[Occluder],
    ) -> Option<(LightView, Option<f64>)> {
        let view = light.view(x, Some(face), hiders)?;
        let share = view.fraction(DVec3::from_array(x.map(f64::from)), normal);
        Some((view, share))
    }

    /// A height field of `k × k` cells at heights `z` (two triangles a
    /// cell: shared edges and corners, fans round every inner corner),
    /// then loose triangles.
    fn scene(
        scale: i32,
        (ox, oy, s, k): (i32, i32, i32, usize),
        z: &[i32],
        loose: &[[(i32, i32, i32); 3]],
    ) -> Vec<Occluder> {
        let at = |i: usize, j: usize| {
            let h = z[(i * 7 + j * 3) % z.len()];
            [ox + s * i as i32, oy + s * j as i32, h].map(|c| c * scale)
        };
        let mut out = Vec::new();
        for i in 0..k {
            for j in 0..k {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                out.extend(Occluder::new(&[a, b, c]));
                out.extend(Occluder::new(&[a, c, d]));
            }
        }
        for t in loose {
            out.extend(Occluder::new(
                &t.map(|(x, y, z)| [x, y, z].map(|c| c * scale)),
            ));
        }
        out
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(500))]
        /// Where it applies, the cones see what the general path sees:
        /// fully lit and nothing seen alike, else a seen part of exactly
        /// the same area on the light's plane (exact rationals; the two
        /// shares are `f64` sums over differently cut pieces), on the
        /// ground and on faces through `x` tilted so that their plane
        /// cuts the light, or leaves it all behind. It does not apply
        /// where an occluder crosses the light's plane.
        #[test]
        fn the_cones_see_what_the_general_path_sees(
            scale in prop_oneof![Just(1), Just(3), Just(1 << 19)],
            light in (-20i32..20, -20i32..20, 1i32..30, 90i32..100),
            x in (-30i32..30, -30i32..30),
            field in (-30i32..0, -30i32..0, 1i32..12, 1usize..6),
            z in prop::collection::vec(10i32..80, 1..6),
            loose in prop::collection::vec(prop::array::uniform3((-40i32..40, -40i32..40, 5i32..103)), 0..6),
            tilt in prop_oneof![Just((0, 1)), Just((8, 1)), Just((30, 1)), Just((-60, 1)), Just((1, 0)), Just((-8, -7))],
        ) {
            let (lx, ly, size, lz) = light;
            // clockwise seen from above: it shines down
            let corners = [[lx, ly, lz], [lx, ly + size, lz], [lx + size, ly + size, lz], [lx + size, ly, lz]]
                .map(|c| c.map(|v| v * scale));
            let light = AreaLight::new(&corners).unwrap();
            let x = [x.0 * scale, x.1 * scale, 0];
            // the face through `x`: the ground turned about the x axis
            let (p, q) = tilt;
            let ground = Plane::through(x, [x[0] + 1, x[1], x[2]], [x[0], x[1] + q, x[2] + p]).unwrap();
            let normal = DVec3::from_array(ground.normal().map(|c| c as f64)).normalize();
            let hiders = scene(scale, field, &z, &loose);
            let crosses = hiders.iter().any(|o| {
                let s = o.corners().iter().map(|&c| light.plane().unwrap().classify_grid(c));
                let s: Vec<Side> = s.collect();
                s.contains(&Side::Front) && s.contains(&Side::Back)
            });
            let quick = seen_share(light.grid_corners().unwrap(), light.plane().unwrap(), &ground, x, normal, hiders.iter());
            prop_assert_eq!(quick.is_none(), crosses);
            if let Some(quick) = quick {
                let (view, slow) = general(&light, &ground, x, normal, &hiders).unzip();
                let slow = slow.flatten();
                match (quick, slow) {
                    (Some(q), Some(s)) if q == 1.0 || s == 1.0 || q == 0.0 || s == 0.0 => prop_assert_eq!(q, s),
                    (Some(_), Some(_)) => prop_assert!(
                        same_seen(view.as_ref().unwrap(), light.plane().unwrap(), x),
                        "the cones' seen part has another area than the general path's"
                    ),
                    (q, s) => prop_assert_eq!(q, s),
                }
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]
        /// A sun's polygon of directions on the cones sees what the
        /// general path sees of the polygon light those directions reach
        /// far beyond every occluder (a sun is beyond every occluder; the
        /// light at height `2^20` is beyond these): nothing, all, or a
        /// part of exactly the same area on the light's plane, with the
        /// face cutting the directions or not.
        #[test]
        fn the_cones_see_a_sun_as_the_general_path_sees_a_far_light(
            toward in (-8i32..8, -8i32..8),
            size in prop_oneof![Just(3i32), Just(1000), Just(30000)],
            x in (-30i32..30, -30i32..30),
            field in (-30i32..0, -30i32..0, 1i32..12, 1usize..6),
            z in prop::collection::vec(10i32..80, 1..6),
            loose in prop::collection::vec(prop::array::uniform3((-40i32..40, -40i32..40, 5i32..103)), 0..6),
            tilt in prop_oneof![Just((0, 1)), Just((8, 7)), Just((8, 6)), Just((8, 8)), Just((1, 0)), Just((-8, -7))],
        ) {
            const H: i32 = 1 << 20;
            let x = [x.0, x.1, 0];
            // an octagon at height H round a point the directions lean
            // toward, clockwise seen from above: it shines down
            let (cx, cy) = (toward.0 * (H / 8), toward.1 * (H / 8));
            let (a, b) = (size, size / 2);
            let corners: Vec<GridPoint> = [(a, b), (b, a), (-b, a), (-a, b), (-a, -b), (-b, -a), (b, -a), (a, -b)]
                .iter()
                .rev()
                .map(|&(u, v)| [cx + u, cy + v, H])
                .collect();
            let light = AreaLight::new(&corners).unwrap();
            let sky: Vec<[i32; 3]> = (corners.iter())
                .map(|c| [c[0] - x[0], c[1] - x[1], c[2] - x[2]])
                .collect();
            let (p, q) = tilt;
            let face = Plane::through(x, [x[0] + 1, x[1], x[2]], [x[0], x[1] + q, x[2] + p]).unwrap();
            let hiders = scene(1, field, &z, &loose);
            let quick = sky_seen_share(&sky, &face, x, hiders.iter())
                .expect("a strictly convex octagon of directions");
            let view = light.view(x, Some(&face), &hiders);
            match (quick, view) {
                (None, view) => prop_assert!(
                    view.is_none_or(|v| v.reachable.is_empty()),
                    "no direction in front of the face, yet the light is"
                ),
                (Some(_), None) => prop_assert!(false, "directions in front of the face, but no light"),
                (Some(share), Some(view)) => match view.visibility {
                    Visibility::All => prop_assert_eq!(share, 1.0),
                    Visibility::None => prop_assert_eq!(share, 0.0),
                    Visibility::Part => prop_assert!(
                        share < 1.0 && same_seen(&view, light.plane().unwrap(), x),
                        "the cones' seen part has another area than the general path's"
                    ),
                },
            }
        }
    }

    /// The cones decline a sun disc (leaving it to the `f64` chart) where,
    /// and only where, its quantized octagon is no strictly convex cone;
    /// a disc of the sun's size they take.
    #[test]
    fn the_cones_decline_only_discs_that_are_no_cone() {
        let hiders = scene(1, (-10, -10, 4, 3), &[20, 30], &[]);
        let ground = Plane::through([0, 0, 0], [1, 0, 0], [0, 1, 0]).unwrap();
        for toward in [
            DVec3::new(0.1, -0.2, 1.0),
            DVec3::Z,
            DVec3::new(-0.7, 0.4, 1.0),
        ] {
            for radius in [TINY_DISC, 0.01, 0.2666] {
                let disc = AreaLight::sun_disc(toward, radius).unwrap();
                let sky: Vec<[i32; 3]> = (disc.corners().iter())
                    .map(|l| match l {
                        crate::Light::Directional(d) => *d,
                        crate::Light::Point(_) => unreachable!("a disc of directions"),
                    })
                    .collect();
                let quick = sky_seen_share(&sky, &ground, [0, 0, 0], hiders.iter());
                let octagon = light_cone(sky.iter().map(|d| d.map(i64::from)));
                assert_eq!(quick.is_none(), octagon.is_none(), "radius {radius}");
                assert!(radius < 0.01 || quick.is_some(), "radius {radius} declined");
            }
        }
    }

    /// The part of `cone` left of the line from `a` to `b` on the plane
    /// `z = 10`, seen from above (from the origin: inside its plane).
    fn left_of(pool: &mut Pool, cone: Piece, a: [i32; 2], b: [i32; 2]) -> Piece {
        let m = cross(
            from([0; 3], [a[0], a[1], 10]),
            from([0; 3], [b[0], b[1], 10]),
        );
        let s = sides(pool, cone, &m);
        assert!(
            s.contains(&1) && s.contains(&-1),
            "the line crosses the piece"
        );
        keep(pool, cone, &s, 1, m)
    }

    /// Two cones sharing a whole edge merge where their union is convex
    /// (a straight junction keeps one plane), not where it is not or
    /// where they share part of an edge.
    #[test]
    fn pieces_merge_where_their_union_is_convex() {
        let x = [0, 0, 0];
        let mut pool = Pool::default();
        let p = &mut pool;
        // the square light's cone cut in two along a diagonal, and merged
        // back: the same four planes
        let square = [[-2, -2, 10], [2, -2, 10], [2, 2, 10], [-2, 2, 10]];
        let whole = p.add(&light_cone(square.iter().map(|&c| from(x, c))).unwrap());
        let (a, b) = (
            left_of(p, whole, [-2, -2], [2, 2]),
            left_of(p, whole, [2, 2], [-2, -2]),
        );
        assert_eq!((a.len, b.len), (3, 3));
        let back = merge(p, vec![a, b]);
        assert_eq!(back.len(), 1);
        let (mut planes, mut want) = (p.planes(back[0]).to_vec(), p.planes(whole).to_vec());
        planes.sort_unstable();
        want.sort_unstable();
        assert_eq!(planes, want);
        // a band [-2, 0] x [-1, 1] and, right of it, the same band: one
        // rectangle of four planes (two straight junctions)
        let low = left_of(p, whole, [-2, -1], [2, -1]);
        let band = left_of(p, low, [2, 1], [-2, 1]);
        let (west, east) = (
            left_of(p, band, [0, -2], [0, 2]),
            left_of(p, band, [0, 2], [0, -2]),
        );
        let joined = union(p, west, east).expect("the halves make the band");
        assert_eq!(joined.len, 4);
        // the band's own four planes, exactly
        let (mut planes, mut want) = (p.planes(joined).to_vec(), p.planes(band).to_vec());
        planes.sort_unstable();
        want.sort_unstable();
        assert_eq!(planes, want);
        // right of the west half, a piece widening from its edge: the
        // union has reflex corners
        let right = left_of(p, whole, [0, 2], [0, -2]);
        let narrow = left_of(p, right, [0, -1], [2, -2]);
        let fan = left_of(p, narrow, [2, 2], [0, 1]);
        assert!(union(p, west, fan).is_none() && union(p, fan, west).is_none());
        // the east half and the west half of the whole square share part
        // of an edge only
        let tall_west = left_of(p, whole, [0, -2], [0, 2]);
        assert!(union(p, tall_west, east).is_none());
    }

    proptest! {
        /// The filtered sign of a determinant is the exact one, also
        /// where it is 0 or a unit from it at the largest coordinates.
        #[test]
        fn the_determinant_sign_is_exact(
            a in prop::array::uniform3(-(1i64 << 55)..(1i64 << 55)),
            b in prop::array::uniform3(-(1i64 << 55)..(1i64 << 55)),
            (p, q) in (-3i64..4, -3i64..4),
            nudge in prop::array::uniform3(-1i64..2),
            shift in prop_oneof![Just(0u32), Just(37), Just(45)],
        ) {
            let exact = |a: &Line, b: &Line, c: &Line| {
                let w = |v: i64| I256::from(v);
                let det = w(a[0]) * (w(b[1]) * w(c[2]) - w(b[2]) * w(c[1]))
                    + w(a[1]) * (w(b[2]) * w(c[0]) - w(b[0]) * w(c[2]))
                    + w(a[2]) * (w(b[0]) * w(c[1]) - w(b[1]) * w(c[0]));
                det.signum().as_::<i32>()
            };
            // c in the plane of a and b (within 2^55 after halving), then
            // nudged off it by a unit
            // (also small, where the product is below 2^64 and nonzero)
            let (a, b) = match shift {
                0 => (a, b),
                s => (a.map(|v| v >> s), b.map(|v| v >> s)),
            };
            let c: Line = [0, 1, 2].map(|k| (p * (a[k] / 4) + q * (b[k] / 4)) + nudge[k]);
            let a4 = a.map(|v| v / 4 * 4);
            let b4 = b.map(|v| v / 4 * 4);
            for (x, y, z) in [(&a, &b, &c), (&a4, &b4, &c), (&c, &a4, &b4)] {
                prop_assert_eq!(det_sign(x, y, z), exact(x, y, z));
                prop_assert_eq!(exact_side(x, &Ray::new(y, z)), exact(x, y, z));
            }
        }
    }
}
