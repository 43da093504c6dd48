//! Watertight triangle meshes from exact convex polygons.
//!
//! [`TriMesh::from_polygons`] welds exactly equal vertices, inserts into
//! every polygon edge each vertex that lies exactly on it (so that no
//! T-junction remains), and triangulates each polygon without new vertices.
//! When the polygons tile the boundary of a solid, every edge of the result
//! is shared by exactly two triangles with opposite directions.

use std::cmp::Ordering;
use std::collections::HashMap;

use bnum::cast::As;
use bnum::types::I512;
use num_bigint::BigInt;
use num_rational::BigRational;
use smallvec::SmallVec;

use crate::Side;
use crate::point::Point;
use crate::polygon::Polygon;

/// A triangle mesh over exact, welded vertices.
#[derive(Clone, Debug, Default)]
pub struct TriMesh {
    /// Distinct exact vertices.
    pub vertices: Vec<Point>,
    /// Counter-clockwise triangles (indices into `vertices`).
    pub triangles: Vec<[u32; 3]>,
}

/// An exact conversion of a wide integer.
pub(crate) fn to_bigint(x: &crate::I256) -> BigInt {
    let neg = x.is_negative();
    let mag = x.unsigned_abs();
    let mut bytes = Vec::with_capacity(32);
    for d in mag.digits() {
        bytes.extend_from_slice(&d.to_le_bytes());
    }
    let m = BigInt::from_bytes_le(num_bigint::Sign::Plus, &bytes);
    if neg { -m } else { m }
}

fn key(p: &Point) -> [u64; 3] {
    p.to_f64().map(|c| (c + 0.0).to_bits())
}

/// Exact comparison of two points' coordinate `k`.
fn cmp_axis(p: &Point, q: &Point, k: usize) -> Ordering {
    if let (Point::Grid(a), Point::Grid(b)) = (p, q) {
        return a[k].cmp(&b[k]);
    }
    let (a, b) = (p.homogeneous(), q.homogeneous());
    let big = |x: crate::I256| x.as_::<I512>();
    // a_k / a_w vs b_k / b_w with positive w
    (big(a[k]) * big(b[3])).cmp(&(big(b[k]) * big(a[3])))
}

struct Welder {
    vertices: Vec<Point>,
    by_key: HashMap<[u64; 3], SmallVec<[u32; 1]>>,
}

impl Welder {
    fn id(&mut self, p: &Point) -> u32 {
        let bucket = self.by_key.entry(key(p)).or_default();
        for &i in bucket.iter() {
            if self.vertices[i as usize].same_point(p) {
                return i;
            }
        }
        let i = self.vertices.len() as u32;
        self.vertices.push(p.clone());
        bucket.push(i);
        i
    }
}

impl TriMesh {
    /// The conforming triangulation of `polys` (see the module docs).
    pub fn from_polygons(polys: &[Polygon]) -> TriMesh {
        let mut w = Welder {
            vertices: Vec::new(),
            by_key: HashMap::new(),
        };
        let corners: Vec<Vec<u32>> = polys
            .iter()
            .map(|p| p.vertices().iter().map(|v| w.id(v)).collect())
            .collect();
        let vertices = w.vertices;
        // vertices sorted by rounded x, for candidate look-up
        let coords: Vec<[f64; 3]> = vertices.iter().map(Point::to_f64).collect();
        let mut by_x: Vec<u32> = (0..vertices.len() as u32).collect();
        by_x.sort_by(|&a, &b| coords[a as usize][0].total_cmp(&coords[b as usize][0]));
        let xs: Vec<f64> = by_x.iter().map(|&i| coords[i as usize][0]).collect();

        let mut triangles = Vec::new();
        for (poly, cs) in polys.iter().zip(&corners) {
            let k = cs.len();
            // boundary loop: (vertex, edge ids it lies on)
            let mut ring: Vec<(u32, SmallVec<[u32; 3]>)> = Vec::with_capacity(k);
            for i in 0..k {
                let (a, b) = (cs[i], cs[(i + 1) % k]);
                ring.push((
                    a,
                    SmallVec::from_slice(&[((i + k - 1) % k) as u32, i as u32]),
                ));
                let mut on_edge = edge_points(poly, i, a, b, &vertices, &coords, &by_x, &xs);
                if on_edge.len() > 1 {
                    let (pa, pb) = (&vertices[a as usize], &vertices[b as usize]);
                    let axis = (0..3)
                        .max_by(|&x, &y| {
                            let d =
                                |c: usize| (coords[b as usize][c] - coords[a as usize][c]).abs();
                            d(x).total_cmp(&d(y))
                        })
                        .filter(|&ax| cmp_axis(pa, pb, ax) != Ordering::Equal)
                        .or_else(|| (0..3).find(|&ax| cmp_axis(pa, pb, ax) != Ordering::Equal))
                        .expect("edge endpoints are distinct points");
                    let rising = cmp_axis(pa, pb, axis) == Ordering::Less;
                    on_edge.sort_by(|&x, &y| {
                        let o = cmp_axis(&vertices[x as usize], &vertices[y as usize], axis);
                        if rising { o } else { o.reverse() }
                    });
                }
                ring.extend(
                    on_edge
                        .into_iter()
                        .map(|v| (v, SmallVec::from_slice(&[i as u32]))),
                );
            }
            clip_ears(ring, k as u32, &mut triangles);
        }
        TriMesh {
            vertices,
            triangles,
        }
    }

    /// Vertex coordinates (grid units), correctly rounded.
    pub fn vertices_f64(&self) -> Vec<[f64; 3]> {
        self.vertices.iter().map(Point::to_f64).collect()
    }

    /// Checks that every directed edge appears once and its reverse once
    /// (closed, consistently oriented, no T-junctions), and that no
    /// triangle repeats a vertex. Names the first bad edge.
    pub fn check_watertight(&self) -> Result<(), String> {
        let mut count: HashMap<(u32, u32), u32> = HashMap::new();
        for (t, tri) in self.triangles.iter().enumerate() {
            if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
                return Err(format!("triangle {t} repeats a vertex: {tri:?}"));
            }
            for i in 0..3 {
                *count.entry((tri[i], tri[(i + 1) % 3])).or_default() += 1;
            }
        }
        let mut bad: Vec<_> = count
            .iter()
            .filter(|&(&(a, b), &c)| c != 1 || count.get(&(b, a)) != Some(&1))
            .map(|(&e, &c)| (e, c))
            .collect();
        bad.sort();
        match bad.first() {
            None => Ok(()),
            Some(((a, b), c)) => Err(format!(
                "edge {a}->{b} is used {c} time(s), its reverse {} time(s) ({} bad edges)",
                count.get(&(*b, *a)).copied().unwrap_or(0),
                bad.len()
            )),
        }
    }

    /// Signed volume in grid units³, in `f64` from the rounded vertices.
    pub fn volume_f64(&self) -> f64 {
        let v = self.vertices_f64();
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| glam::DVec3::from_array(v[i as usize]));
                a.dot(b.cross(c))
            })
            .sum::<f64>()
            / 6.0
    }

    /// The exact signed volume in grid units³ (divide by `scale³` of the
    /// grid for input units; the scale is a power of two, so that is exact
    /// too), as an unreduced fraction (reducing it costs a gcd of very long
    /// integers; `Ratio`'s comparisons do not need it).
    ///
    /// Triangles whose vertices share a denominator are summed in integers;
    /// the groups are then added pairwise in a balanced tree without
    /// reduction, so the cost grows with the total size of the
    /// denominators, not quadratically.
    pub fn volume_exact(&self) -> BigRational {
        let (num, den) = self.six_volume();
        BigRational::new_raw(num, den * BigInt::from(6))
    }

    /// Six times the exact volume as `(numerator, denominator)`,
    /// denominator positive and not reduced.
    pub fn six_volume(&self) -> (BigInt, BigInt) {
        let hom: Vec<[BigInt; 4]> = self
            .vertices
            .iter()
            .map(|p| p.homogeneous().map(|c| to_bigint(&c)))
            .collect();
        let mut groups: HashMap<BigInt, BigInt> = HashMap::new();
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| &hom[i as usize]);
            let det = &a[0] * (&b[1] * &c[2] - &b[2] * &c[1])
                - &a[1] * (&b[0] * &c[2] - &b[2] * &c[0])
                + &a[2] * (&b[0] * &c[1] - &b[1] * &c[0]);
            *groups.entry(&a[3] * &b[3] * &c[3]).or_default() += det;
        }
        let mut terms: Vec<(BigInt, BigInt)> = groups.into_iter().map(|(d, n)| (n, d)).collect();
        // deterministic order, whatever the hash map did
        terms.sort_by(|x, y| x.1.cmp(&y.1));
        while terms.len() > 1 {
            let mut next = Vec::with_capacity(terms.len().div_ceil(2));
            let mut it = terms.into_iter();
            while let Some((n1, d1)) = it.next() {
                next.push(match it.next() {
                    Some((n2, d2)) if d1 == d2 => (n1 + n2, d1),
                    Some((n2, d2)) => (n1 * &d2 + n2 * &d1, d1 * d2),
                    None => (n1, d1),
                });
            }
            terms = next;
        }
        terms
            .pop()
            .unwrap_or_else(|| (BigInt::from(0), BigInt::from(1)))
    }

    /// Surface area in grid units², in `f64`.
    pub fn area_f64(&self) -> f64 {
        let v = self.vertices_f64();
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| glam::DVec3::from_array(v[i as usize]));
                (b - a).cross(c - a).length() * 0.5
            })
            .sum()
    }
}

/// Welded vertices lying strictly inside edge `i` (from `a` to `b`) of `poly`.
#[allow(clippy::too_many_arguments)]
fn edge_points(
    poly: &Polygon,
    i: usize,
    a: u32,
    b: u32,
    vertices: &[Point],
    coords: &[[f64; 3]],
    by_x: &[u32],
    xs: &[f64],
) -> Vec<u32> {
    let k = poly.len();
    let (ca, cb) = (coords[a as usize], coords[b as usize]);
    let lo = [ca[0].min(cb[0]), ca[1].min(cb[1]), ca[2].min(cb[2])];
    let hi = [ca[0].max(cb[0]), ca[1].max(cb[1]), ca[2].max(cb[2])];
    let start = xs.partition_point(|&x| x < lo[0]);
    let end = xs.partition_point(|&x| x <= hi[0]);
    let edges = poly.edge_planes();
    let (e, prev, next) = (&edges[i], &edges[(i + k - 1) % k], &edges[(i + 1) % k]);
    let mut out = Vec::new();
    for &v in &by_x[start..end] {
        if v == a || v == b {
            continue;
        }
        let c = coords[v as usize];
        // rounding is monotone, so a point on the segment has its rounded
        // coordinates inside the rounded box: a conservative filter
        if (1..3).any(|j| c[j] < lo[j] || c[j] > hi[j]) {
            continue;
        }
        let p = &vertices[v as usize];
        if p.classify(poly.support()) == Side::On
            && p.classify(e) == Side::On
            && p.classify(prev) == Side::Back
            && p.classify(next) == Side::Back
        {
            out.push(v);
        }
    }
    out
}

/// Triangulates a convex loop whose points may be collinear along edges.
/// Every point knows the edges (original sides and chords made so far) it
/// lies on. Three consecutive points `a, b, c` form an ear when `a` and `c`
/// share no edge: the chord `ac` then crosses the interior and contains no
/// other point of the loop, and `b` is not on it. A convex loop of positive
/// area always has such an ear (at a corner next to a corner of another
/// side). `next_edge` is the first free edge id for chords.
fn clip_ears(
    mut ring: Vec<(u32, SmallVec<[u32; 3]>)>,
    mut next_edge: u32,
    out: &mut Vec<[u32; 3]>,
) {
    while ring.len() > 3 {
        let m = ring.len();
        let ear = (0..m).find(|&j| {
            let (a, c) = (&ring[(j + m - 1) % m].1, &ring[(j + 1) % m].1);
            !a.iter().any(|e| c.contains(e))
        });
        let Some(j) = ear else {
            debug_assert!(false, "a convex loop with positive area has an ear");
            return;
        };
        let (ia, ic) = ((j + m - 1) % m, (j + 1) % m);
        out.push([ring[ia].0, ring[j].0, ring[ic].0]);
        ring[ia].1.push(next_edge);
        ring[ic].1.push(next_edge);
        next_edge += 1;
        ring.remove(j);
    }
    if ring.len() == 3 {
        let all_on_one = ring[1]
            .1
            .iter()
            .any(|e| ring[0].1.contains(e) && ring[2].1.contains(e));
        if !all_on_one {
            out.push([ring[0].0, ring[1].0, ring[2].0]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn t_junction_is_resolved() {
        // a 2x1 rectangle next to two unit squares: the middle vertex of the
        // squares' shared side lies on the rectangle's edge
        let sq = |x0: i32, x1: i32, y0: i32, y1: i32| {
            Polygon::from_grid_points(&[[x0, y0, 0], [x1, y0, 0], [x1, y1, 0], [x0, y1, 0]], 0)
                .unwrap()
        };
        let polys = vec![sq(0, 2, 0, 1), sq(0, 1, 1, 2), sq(1, 2, 1, 2)];
        let m = TriMesh::from_polygons(&polys);
        assert_eq!(m.vertices.len(), 8);
        // the rectangle gets the vertex (1, 1): 5 boundary points, 3 triangles
        assert_eq!(m.triangles.len(), 3 + 2 + 2);
        let area: f64 = m.area_f64();
        assert_eq!(area, 4.0);
        assert_eq!(m.volume_exact(), BigRational::from_integer(0.into()));
    }
}
