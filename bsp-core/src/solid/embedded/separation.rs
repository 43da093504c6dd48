//! Whether two of the certificate's triangles, or the corners around one
//! vertex, certainly meet only where they should: exact tests on grid
//! points in 64- and 128-bit integers (see the parent module's docs).

use smallvec::SmallVec;

use super::Tri;
use crate::kernel::GridPoint;
use crate::kernel::plane::{cross, cross_wide};

pub(super) type V = [i64; 3];

#[inline]
pub(super) fn sub(a: GridPoint, b: GridPoint) -> V {
    [0, 1, 2].map(|k| a[k] as i64 - b[k] as i64)
}

#[inline]
pub(super) fn dot(u: V, v: V) -> i128 {
    (0..3).map(|k| u[k] as i128 * v[k] as i128).sum()
}

pub(super) type W = [i128; 3];

#[inline]
pub(super) fn wide(u: V) -> W {
    u.map(|c| c as i128)
}

/// `w · p` for `|w| < 2^89`, `|p| < 2^28` (below `2^119`).
#[inline]
pub(super) fn dot_w(w: W, p: V) -> i128 {
    (0..3).map(|k| w[k] * p[k] as i128).sum()
}

/// `true` if the corners `order` around the vertex `v` (each corner's
/// wedge from its next vertex to its previous one, counter-clockwise about
/// its polygon's normal, successive corners sharing a ray) are certified
/// to meet only along their shared rays: seen along `d`, the sum of the
/// wedges' normals, every wedge turns counter-clockwise by less than a
/// half turn, and the wedges go around exactly once. The star is then a
/// graph over the plane across `d`, so the polygons at `v` meet only in
/// the edges and vertex they share (each is convex, so two of them meet
/// elsewhere only if their wedges at `v` do). Stars of more than 512
/// corners, or with a ray seen along the first one's, are not certified.
pub(super) fn star_embedded(
    v: GridPoint,
    order: &[u32],
    ends: impl Fn(u32) -> (GridPoint, GridPoint),
) -> bool {
    let k = order.len();
    if !(3..=512).contains(&k) {
        return false;
    }
    let mut rays: SmallVec<[V; 8]> = SmallVec::with_capacity(k);
    let mut normals: SmallVec<[V; 8]> = SmallVec::with_capacity(k);
    // |n| < 2^55 each, so |d| < 2^64
    let mut d: W = [0; 3];
    for &g in order {
        let (next, prev) = ends(g);
        let (e, p) = (sub(next, v), sub(prev, v));
        let n = cross(e, p);
        for k in 0..3 {
            d[k] += n[k] as i128;
        }
        rays.push(e);
        normals.push(n);
    }
    // |n · d| < 3 · 2^119
    let along = |n: V| dot_w(d, n);
    if normals.iter().any(|&n| along(n) <= 0) {
        return false;
    }
    // wedge i runs from ray i to ray i - 1 (ray -1: the last); seen along
    // d, count those whose half-open [start, end) holds ray 0: wedge 0
    // does, wedge 1 ends there, no other may
    let e0 = rays[0];
    let orient = |x: V, y: V| along(cross(x, y));
    let side: SmallVec<[i128; 8]> = rays.iter().map(|&e| orient(e, e0)).collect();
    if side[1..].contains(&0) {
        return false;
    }
    (2..k).all(|i| !(side[i] > 0 && side[i - 1] < 0))
}

/// `true` if the closed triangles `s` and `t` (each with area) meet at
/// most in the vertices and the edge they share; `false` when they meet
/// elsewhere or the test cannot tell.
pub(super) fn apart(s: &Tri, t: &Tri) -> bool {
    let mut shared = [(0usize, 0usize); 3];
    let mut n = 0;
    for i in 0..3 {
        for j in 0..3 {
            if s.id[i] == t.id[j] {
                shared[n] = (i, j);
                n += 1;
            }
        }
    }
    match n {
        0 => disjoint(&s.v, &t.v),
        1 => {
            let (s, t) = (&s.v, &t.v);
            let (i, j) = shared[0];
            let v = s[i];
            let g = [
                sub(s[(i + 1) % 3], v),
                sub(s[(i + 2) % 3], v),
                sub(t[(j + 1) % 3], v),
                sub(t[(j + 2) % 3], v),
            ];
            cones_apart(g)
        }
        2 => {
            // the shared pair must be an edge of both polygons: a diagonal
            // (or a run of collinear edges) lies inside its polygon, or
            // along a line other polygons share, where two polygons can
            // cross along `ab` with every pair of triangles touching only
            // there (and the stars at a and b refused)
            let edge = |tri: &Tri, i: usize, j: usize| {
                let k = if (i + 1) % 3 == j { i } else { j };
                tri.edges & (1 << k) != 0
            };
            if !edge(s, shared[0].0, shared[1].0) || !edge(t, shared[0].1, shared[1].1) {
                return false;
            }
            let (s, t) = (&s.v, &t.v);
            let (a, b) = (s[shared[0].0], s[shared[1].0]);
            let c = s[3 - shared[0].0 - shared[1].0];
            let d = t[3 - shared[0].1 - shared[1].1];
            let e = sub(b, a);
            let n = cross(e, sub(c, a));
            // not coplanar, or coplanar on opposite sides of the edge
            dot(n, sub(d, a)) != 0 || dot(n, cross(e, sub(d, a))) < 0
        }
        _ => false,
    }
}

/// Whether the closed triangles `s` and `t` (grid corners) certainly do
/// not meet: a plane strictly separates them (the separating-axis test
/// over every candidate axis, exact). `false` where they meet, and may
/// be `false` for a triangle of no area that does not meet the other.
pub fn triangles_disjoint(s: &[GridPoint; 3], t: &[GridPoint; 3]) -> bool {
    disjoint(s, t)
}

/// Strict separation of two triangles without a shared vertex, by the
/// separating-axis test over every candidate axis.
pub(super) fn disjoint(s: &[GridPoint; 3], t: &[GridPoint; 3]) -> bool {
    let ps = s.map(|p| sub(p, [0; 3]));
    let pt = t.map(|p| sub(p, [0; 3]));
    let es = [0, 1, 2].map(|k| sub(s[(k + 1) % 3], s[k]));
    let et = [0, 1, 2].map(|k| sub(t[(k + 1) % 3], t[k]));
    let ns = cross(es[0], es[1]);
    let nt = cross(et[0], et[1]);
    let separates = |w: W| {
        let (mut a0, mut a1) = (i128::MAX, i128::MIN);
        let (mut b0, mut b1) = (i128::MAX, i128::MIN);
        for k in 0..3 {
            let x = dot_w(w, ps[k]);
            a0 = a0.min(x);
            a1 = a1.max(x);
            let y = dot_w(w, pt[k]);
            b0 = b0.min(y);
            b1 = b1.max(y);
        }
        a1 < b0 || b1 < a0
    };
    // the planes first, in 64 × 64-bit products: they settle most pairs
    let off = |n: V, p: &[V; 3], q: &[V; 3]| {
        let d = dot(n, p[0]);
        let x = q.map(|q| dot(n, q) - d);
        x.iter().all(|&x| x > 0) || x.iter().all(|&x| x < 0)
    };
    if off(ns, &ps, &pt) || off(nt, &pt, &ps) {
        return true;
    }
    for a in es {
        for b in et {
            let w = cross(a, b);
            if w != [0; 3] && separates(wide(w)) {
                return true;
            }
        }
    }
    // a normal (`< 2^56`) across an edge (`< 2^28`): below `2^85`
    es.iter().any(|&e| separates(cross_wide(ns, e)))
        || et.iter().any(|&e| separates(cross_wide(nt, e)))
}

/// `true` if the cones `{α g0 + β g1}` and `{γ g2 + δ g3}` (α, β, γ, δ ≥ 0)
/// meet only at the origin, certified by a plane strictly between them.
pub(super) fn cones_apart(g: [V; 4]) -> bool {
    let sign = [1i128, 1, -1, -1];
    let valid = |w: W, strict: bool| {
        (0..4).all(|i| {
            let x = sign[i] * dot_w(w, g[i]);
            if strict { x > 0 } else { x >= 0 }
        })
    };
    let n0 = cross(g[0], g[1]);
    let n1 = cross(g[2], g[3]);
    // each triangle's plane first: the other strictly on one side
    let quick = |n: V, a: V, b: V| {
        let (x, y) = (dot(n, a), dot(n, b));
        (x > 0 && y > 0) || (x < 0 && y < 0)
    };
    if quick(n0, g[2], g[3]) || quick(n1, g[0], g[1]) {
        return true;
    }
    // the sum of every weakly separating candidate
    let mut sum: W = [0; 3];
    let mut add = |w: W| {
        for s in [1, -1] {
            let w = w.map(|c| c * s);
            if valid(w, false) {
                for k in 0..3 {
                    sum[k] += w[k];
                }
            }
        }
    };
    for i in 0..4 {
        for j in i + 1..4 {
            add(wide(cross(g[i], g[j])));
        }
    }
    // normals (`< 2^56`) across edges (`< 2^28`): below `2^85`
    for (n, a, b) in [(n0, g[0], g[1]), (n1, g[2], g[3])] {
        add(cross_wide(n, a));
        add(cross_wide(n, b));
    }
    valid(sum, true)
}
