//! Point lights: the cube around the light, exactly.
//!
//! A face of the cube is the chart `(u, w) = (y / x, z / x)` of the
//! directions `d` from the light with `x >= |y|` and `x >= |z|`, in the
//! face's own axes (`x` along the face's outward axis). Its `N × N` tiles
//! are the squares between `u, w = -1 + 2k / N`. Every boundary of a tile
//! or a face is a plane through the light with small integer
//! coefficients, so a polygon's projection is found by clipping the *cone*
//! of directions from the light to the polygon by such planes, without
//! ever dividing:
//!
//! - The cone of a convex polygon whose plane misses the light is pointed:
//!   its rays are the vertices' directions `d_k = v_k - L` (27-bit
//!   integers) and each edge lies in the plane through the light with
//!   normal `n_k = d_k × d_(k+1)` (55 bits).
//! - Clipping the cone by a plane `c` through the light (Sutherland and
//!   Hodgman on rays) keeps the rays with `c · r >= 0` and puts the ray
//!   `± n × c` where an edge crosses: the one on the edge's short arc,
//!   whose sign follows from the sign of `c · r` at the edge's first ray.
//!   The new edge along `c` has normal `c`. So a ray is a vertex
//!   direction, or an edge normal crossed with a small plane: at most
//!   about `2^72` after the frustum and one band of rows, and every dot
//!   product and tile coordinate fits `i128`.
//! - A ray's tile coordinate `N (r_y + r_x) / (2 r_x)` (and the same with
//!   `r_z`) is an exact quotient; the tiles met by a closed range of
//!   coordinates `[a, b]` are `ceil(a) - 1 ..= floor(b)`, so a projection
//!   that touches a tile's edge is listed in both tiles.
//!
//! The tiles a polygon meets are found row by row: the cone clipped to the
//! face, then to each row band it reaches, gives the exact column range.
//! A polygon in a plane through the light is seen edge-on: its projection
//! is part of the plane's trace on the cube, and the whole trace is
//! listed (a superset, rounded outward).

use smallvec::SmallVec;

/// An integer direction or plane normal.
pub(crate) type V3 = [i128; 3];

pub(crate) fn cross(a: &V3, b: &V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn dot(a: &V3, b: &V3) -> i128 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `floor(n / d)` for `d > 0`.
pub(crate) fn floor_div(n: i128, d: i128) -> i128 {
    n.div_euclid(d)
}

/// `ceil(n / d)` for `d > 0`.
pub(crate) fn ceil_div(n: i128, d: i128) -> i128 {
    -(-n).div_euclid(d)
}

/// The tiles `0..n` that the closed coordinate range `[a, b]` meets, for
/// the range's bounds given as `floor` and `ceil` of its ends: `None` when
/// the range misses `[0, n]`.
pub(crate) fn tile_range(ceil_lo: i128, floor_hi: i128, n: u32) -> Option<(u32, u32)> {
    let (lo, hi) = ((ceil_lo - 1).max(0), floor_hi.min(n as i128 - 1));
    // [a, b] meets [0, n] when b >= 0 and a <= n
    (floor_hi >= 0 && ceil_lo <= n as i128 && lo <= hi).then_some((lo as u32, hi as u32))
}

/// One row's run of tiles on a face: columns `lo..=hi` of row `row`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Span {
    pub(crate) face: u8,
    pub(crate) row: u32,
    pub(crate) lo: u32,
    pub(crate) hi: u32,
}

/// `d` in the axes of cube face `f` (faces `+x, -x, +y, -y, +z, -z`): the
/// face's outward axis first, then the next two axes in cyclic order.
/// An orthogonal map, so dot products (and plane sides) are kept.
pub(crate) fn local(f: usize, d: [i64; 3]) -> V3 {
    let a = f / 2;
    let s = if f.is_multiple_of(2) { 1 } else { -1 };
    [
        s * d[a] as i128,
        d[(a + 1) % 3] as i128,
        d[(a + 2) % 3] as i128,
    ]
}

/// A pointed convex cone: rays in order, `normals[i]` the plane of the
/// edge from ray `i` to ray `i + 1`, a positive multiple of
/// `rays[i] × rays[i + 1]` (the interior on its positive side).
#[derive(Clone, Debug, Default)]
pub(crate) struct Cone {
    pub(crate) rays: SmallVec<[V3; 12]>,
    pub(crate) normals: SmallVec<[V3; 12]>,
}

impl Cone {
    /// The part of the cone on the side `c · r >= 0` of a plane through
    /// the light (Sutherland and Hodgman on rays), into `out`.
    pub(crate) fn clip(&self, c: &V3, out: &mut Cone) {
        out.rays.clear();
        out.normals.clear();
        let k = self.rays.len();
        for i in 0..k {
            let (r1, n) = (&self.rays[i], &self.normals[i]);
            let r2 = &self.rays[(i + 1) % k];
            let (s1, s2) = (dot(c, r1).signum(), dot(c, r2).signum());
            if s1 >= 0 {
                // an exit at r1 itself leaves along c
                let leave = if s1 == 0 && s2 < 0 { *c } else { *n };
                out.rays.push(*r1);
                out.normals.push(leave);
            }
            if s1 * s2 < 0 {
                // the crossing on the short arc from r1 to r2 (see the
                // module docs): n × c when r1 is inside, its opposite when
                // r1 is outside
                let x = cross(n, c);
                if s1 > 0 {
                    out.rays.push(x);
                    out.normals.push(*c);
                } else {
                    out.rays.push(x.map(|v| -v));
                    out.normals.push(*n);
                }
            }
        }
    }
}

/// The four planes of face chart `[-1, 1]²` (in the face's axes):
/// `x >= y`, `x >= -y`, `x >= z`, `x >= -z`.
const FRUSTUM: [V3; 4] = [[1, -1, 0], [1, 1, 0], [1, 0, -1], [1, 0, 1]];

/// The planes of row band `j`: `w >= w_j` and `w <= w_(j+1)`.
fn band(j: u32, n: u32, z: usize) -> [V3; 2] {
    let (j, n) = (j as i128, n as i128);
    let mut lo = [-(2 * j - n), 0, 0];
    lo[z] = n;
    let mut hi = [2 * j + 2 - n, 0, 0];
    hi[z] = -n;
    [lo, hi]
}

/// `ceil` and `floor` of the tile coordinate of ray `r` along axis `k`
/// (1: columns, 2: rows) of a face chart; `r[0] > 0`.
fn coord(r: &V3, k: usize, n: u32) -> (i128, i128) {
    let num = n as i128 * (r[k] + r[0]);
    let den = 2 * r[0];
    (ceil_div(num, den), floor_div(num, den))
}

/// The tile range a cone (inside the face's frustum, so every ray has
/// `x > 0`) covers along axis `k`.
fn cone_range(c: &Cone, k: usize, n: u32) -> Option<(u32, u32)> {
    let (mut lo, mut hi) = (i128::MAX, i128::MIN);
    for r in &c.rays {
        let (cl, fl) = coord(r, k, n);
        lo = lo.min(cl);
        hi = hi.max(fl);
    }
    tile_range(lo, hi, n)
}

/// Work space of [`spans`].
#[derive(Clone, Debug, Default)]
pub(crate) struct Work {
    a: Cone,
    b: Cone,
    c: Cone,
}

/// The tiles of an `n × n` cube around `light` that polygon `verts` (grid
/// points, convex, in order) meets, as row spans appended to `out`.
pub(crate) fn spans(
    light: [i64; 3],
    verts: &[[i64; 3]],
    n: u32,
    w: &mut Work,
    out: &mut Vec<Span>,
) {
    let d: SmallVec<[[i64; 3]; 8]> = verts
        .iter()
        .map(|v| [v[0] - light[0], v[1] - light[1], v[2] - light[2]])
        .collect();
    if d.len() < 3 {
        return;
    }
    for f in 0..6 {
        let rays: SmallVec<[V3; 8]> = d.iter().map(|&v| local(f, v)).collect();
        // orientation from the fan at ray 0: every triangle of a convex
        // polygon turns the same way or is flat; all flat means the
        // polygon's plane holds the light
        let turn = (1..rays.len() - 1)
            .map(|k| dot(&rays[0], &cross(&rays[k], &rays[k + 1])).signum())
            .find(|&s| s != 0);
        let Some(turn) = turn else {
            trace_spans(f, &rays, n, out);
            continue;
        };
        let cone = &mut w.a;
        cone.rays.clear();
        cone.normals.clear();
        let k = rays.len();
        let order: SmallVec<[usize; 8]> = if turn > 0 {
            (0..k).collect()
        } else {
            (0..k).rev().collect()
        };
        for i in 0..k {
            let (r1, r2) = (&rays[order[i]], &rays[order[(i + 1) % k]]);
            cone.rays.push(*r1);
            cone.normals.push(cross(r1, r2));
        }
        // the face's frustum
        for c in &FRUSTUM {
            w.a.clip(c, &mut w.b);
            std::mem::swap(&mut w.a, &mut w.b);
            if w.a.rays.is_empty() {
                break;
            }
        }
        if w.a.rays.is_empty() {
            continue;
        }
        let Some((r0, r1)) = cone_range(&w.a, 2, n) else {
            continue;
        };
        for row in r0..=r1 {
            let [lo, hi] = band(row, n, 2);
            w.a.clip(&lo, &mut w.b);
            if w.b.rays.is_empty() {
                continue;
            }
            w.b.clip(&hi, &mut w.c);
            if w.c.rays.is_empty() {
                continue;
            }
            if let Some((c0, c1)) = cone_range(&w.c, 1, n) {
                out.push(Span {
                    face: f as u8,
                    row,
                    lo: c0,
                    hi: c1,
                });
            }
        }
    }
}

/// The spans of the trace on face `f` of the plane through the light that
/// holds `rays` (a polygon seen edge-on): every tile the plane meets.
fn trace_spans(f: usize, rays: &[V3], n: u32, out: &mut Vec<Span>) {
    // the plane's normal from two rays that are not parallel
    let normal = (1..rays.len())
        .flat_map(|i| (0..i).map(move |j| (i, j)))
        .map(|(i, j)| cross(&rays[i], &rays[j]))
        .find(|p| p.iter().any(|&c| c != 0));
    let Some(p) = normal else {
        return; // every vertex on one ray from the light: no area, no trace
    };
    let ni = n as i128;
    // in the chart: p0 + p1 u + p2 w = 0
    if p[1] != 0 {
        // u at the row boundary w = (2k - n) / n, as a tile coordinate:
        // t = (n p1 - n p0 - p2 (2k - n)) / (2 p1)
        let t = |k: u32| {
            let mut num = ni * p[1] - ni * p[0] - p[2] * (2 * k as i128 - ni);
            let mut den = 2 * p[1];
            if den < 0 {
                num = -num;
                den = -den;
            }
            (ceil_div(num, den), floor_div(num, den))
        };
        for row in 0..n {
            let (a, b) = (t(row), t(row + 1));
            if let Some((lo, hi)) = tile_range(a.0.min(b.0), a.1.max(b.1), n) {
                out.push(Span {
                    face: f as u8,
                    row,
                    lo,
                    hi,
                });
            }
        }
    } else if p[2] != 0 {
        // a line of constant w = -p0 / p2: t = n (p2 - p0) / (2 p2)
        let (mut num, mut den) = (ni * (p[2] - p[0]), 2 * p[2]);
        if den < 0 {
            num = -num;
            den = -den;
        }
        if let Some((r0, r1)) = tile_range(ceil_div(num, den), floor_div(num, den), n) {
            for row in r0..=r1 {
                out.push(Span {
                    face: f as u8,
                    row,
                    lo: 0,
                    hi: n - 1,
                });
            }
        }
    }
    // p = (p0, 0, 0): the plane x = 0 holds no direction of this face
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tiles(light: [i64; 3], verts: &[[i64; 3]], n: u32) -> Vec<(u8, u32, u32)> {
        let mut out = Vec::new();
        spans(light, verts, n, &mut Work::default(), &mut out);
        let mut t: Vec<(u8, u32, u32)> = out
            .iter()
            .flat_map(|s| (s.lo..=s.hi).map(move |c| (s.face, s.row, c)))
            .collect();
        t.sort_unstable();
        t
    }

    #[test]
    fn a_square_straight_above_covers_the_middle_tiles_of_the_top_face() {
        // the square [-1, 1]² at height 5 seen from the origin: u, w in
        // [-1/5, 1/5] on face +z, tile coordinates 4 (u + 1) in [3.2, 4.8]
        // with n = 8: tiles 3..=4 both ways
        let sq = [[-1, -1, 5], [1, -1, 5], [1, 1, 5], [-1, 1, 5]];
        let t = tiles([0, 0, 0], &sq, 8);
        assert_eq!(t, vec![(4, 3, 3), (4, 3, 4), (4, 4, 3), (4, 4, 4)], "{t:?}");
        // the other orientation gives the same tiles
        let mut rev = sq;
        rev.reverse();
        assert_eq!(tiles([0, 0, 0], &rev, 8), t);
    }

    #[test]
    fn touching_a_tile_edge_lists_both_tiles() {
        // u in [0, 1/5]: the left edge u = 0 is the boundary of tiles 3, 4
        let sq = [[0, -1, 5], [1, -1, 5], [1, 1, 5], [0, 1, 5]];
        let t = tiles([0, 0, 0], &sq, 8);
        let cols: Vec<u32> = t.iter().filter(|x| x.1 == 4).map(|x| x.2).collect();
        assert_eq!(cols, vec![3, 4]);
    }

    #[test]
    fn a_floor_under_the_light_spreads_over_five_faces() {
        // a huge floor below the light covers the whole bottom face and
        // the lower halves of the four side faces
        let f = 1 << 20;
        let floor = [[-f, -f, -1], [f, -f, -1], [f, f, -1], [-f, f, -1]];
        let t = tiles([0, 0, 0], &floor, 4);
        let faces: std::collections::BTreeSet<u8> = t.iter().map(|x| x.0).collect();
        assert_eq!(faces.into_iter().collect::<Vec<_>>(), vec![0, 1, 2, 3, 5]);
        assert_eq!(t.iter().filter(|x| x.0 == 5).count(), 16);
        // face +x: rows are z (the axis after y), the floor is below: w < 0,
        // and it reaches w = -1/2^20 < 0, so rows 0..=1 (row 1 ends at w = 0)
        assert!(t.iter().filter(|x| x.0 == 0).all(|x| x.1 <= 1));
    }

    #[test]
    fn a_polygon_through_the_light_lists_its_trace() {
        // the triangle in the plane z = 0 with the light inside it
        let tri = [[-8, -8, 0], [8, -8, 0], [0, 8, 0]];
        let t = tiles([0, 0, 0], &tri, 4);
        // the trace z = 0 on the four side faces touches the middle two
        // rows of faces ±x (whose rows run along z) and the middle two
        // columns of faces ±y (whose columns run along z)
        assert!(t.iter().all(|x| x.0 < 4));
        assert!(t.iter().filter(|x| x.0 < 2).all(|x| x.1 == 1 || x.1 == 2));
        assert!(t.iter().filter(|x| x.0 >= 2).all(|x| x.2 == 1 || x.2 == 2));
        assert_eq!(t.len(), 4 * 2 * 4);
    }
}
