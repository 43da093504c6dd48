//! Maximal regions from labelled convex cells: the cells of one support
//! plane that touch along an edge and carry the same label are merged,
//! and each region's boundary is traced as an outer loop and its holes.
//!
//! A cut survives only where it separates different labels (or bounds the
//! cells' union): this is how `svbsp` turns the pieces a shadow tree cut a
//! face into back into one fragment per connected lit or shadowed part.
//!
//! Everything is exact. Vertices made twice for the same point are
//! identified by exact comparison; edges are grouped by the exact line
//! they lie on (two different planes may cut the support plane in the same
//! line), and along each line the cells on either side are matched
//! interval by interval, so a vertex of one cell in the middle of a
//! neighbour's edge (a T-junction) is handled. Only vertices where the
//! boundary turns are kept.

use std::cmp::Ordering;

use bnum::cast::As;
use num_bigint::BigInt;
use num_rational::BigRational;
use rustc_hash::FxHashMap;
use smallvec::SmallVec;

use crate::I256;
use crate::pieces::{Piece, PieceArena, Vertex};
use crate::plane::Plane;

/// A maximal connected region of equally labelled cells.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Region {
    /// The cells' common label.
    pub label: u64,
    /// The outer boundary: vertex indices into the arena, counter-clockwise
    /// seen from the front of the support plane. Only corners are listed:
    /// no two consecutive edges are collinear.
    pub outer: Vec<u32>,
    /// The holes, each clockwise.
    pub holes: Vec<Vec<u32>>,
    /// The cells whose union the region is (indices into the input), in
    /// increasing order.
    pub cells: Vec<u32>,
}

/// The line a cell edge lies on, within the support plane: the equation
/// `a u + b v + c = 0` in the two coordinates other than the support
/// plane's dominant axis, reduced and with `(a, b)` lexicographically
/// positive, so that equal lines have equal keys.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct LineKey {
    a: i128,
    b: i128,
    c: I256,
}

fn gcd(mut a: u128, mut b: u128) -> u128 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

/// The coordinate axes `(u, v)` of the support plane's projection, and its
/// dominant axis `k`: `(u, v, k)` is a cyclic permutation of `(0, 1, 2)`.
fn axes(support: &Plane) -> (usize, usize, usize) {
    let k = support.dominant_axis();
    ((k + 1) % 3, (k + 2) % 3, k)
}

fn line_key(support: &Plane, e: &Plane) -> LineKey {
    let (u, v, k) = axes(support);
    let (n, m) = (support.normal(), e.normal());
    // eliminate x_k with the support's equation: |a|, |b| < 2^111
    let a = n[k] as i128 * m[u] as i128 - m[k] as i128 * n[u] as i128;
    let b = n[k] as i128 * m[v] as i128 - m[k] as i128 * n[v] as i128;
    let c =
        I256::from(n[k]) * I256::from(e.offset()) - I256::from(m[k]) * I256::from(support.offset());
    assert!(
        a != 0 || b != 0,
        "an edge plane parallel to its support plane"
    );
    let g = gcd(a.unsigned_abs(), b.unsigned_abs());
    let cm = (c.unsigned_abs() % bnum::types::U256::from(g)).as_::<u128>();
    let g = gcd(g, cm) as i128;
    let (mut a, mut b, mut c) = (a / g, b / g, c / I256::from(g));
    if a < 0 || (a == 0 && b < 0) {
        (a, b, c) = (-a, -b, -c);
    }
    LineKey { a, b, c }
}

/// One line with the cell edges on it.
struct Line {
    /// The 3D axis that parametrizes the line.
    t_axis: usize,
    /// Direction of increasing `t` in `(u, v)` coordinates.
    dir: [i128; 2],
    /// (cell, from, to) in canonical vertex ids.
    edges: Vec<(u32, u32, u32)>,
}

struct UnionFind(Vec<u32>);
impl UnionFind {
    fn find(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            let p = self.0[x as usize];
            self.0[x as usize] = self.0[p as usize];
            x = p;
        }
        x
    }
    fn union(&mut self, a: u32, b: u32) {
        let (a, b) = (self.find(a), self.find(b));
        if a != b {
            // the smaller root stays: regions are named by their first cell
            let (lo, hi) = if a < b { (a, b) } else { (b, a) };
            self.0[hi as usize] = lo;
        }
    }
}

/// The cells on the left and on the right of one interval of a line.
type Sides = (Option<u32>, Option<u32>);

/// A directed boundary piece with its region on the left.
#[derive(Clone, Copy, Debug)]
struct Seg {
    from: u32,
    to: u32,
    line: u32,
    forward: bool,
    region: u32,
}

fn cross2(a: [i128; 2], b: [i128; 2]) -> I256 {
    I256::from(a[0]) * I256::from(b[1]) - I256::from(a[1]) * I256::from(b[0])
}

fn dot2(a: [i128; 2], b: [i128; 2]) -> I256 {
    I256::from(a[0]) * I256::from(b[0]) + I256::from(a[1]) * I256::from(b[1])
}

/// Canonical vertex ids: equal points get the id of their first
/// occurrence, in `canon` (indexed by [`PieceArena::dense`], `u32::MAX`
/// for vertices no cell uses); `exact` (the same indexing) receives every
/// used vertex's exact coordinates and `rounded` its correctly rounded
/// ones.
fn canonical_ids(
    arena: &PieceArena,
    cells: &[Piece],
    rounded: &mut Vec<Option<[f64; 3]>>,
    exact: &mut Vec<Option<Vertex>>,
    canon: &mut Vec<u32>,
) {
    rounded.resize(arena.len(), None);
    exact.clear();
    exact.resize(arena.len(), None);
    canon.clear();
    canon.resize(arena.len(), u32::MAX);
    let mut seen: FxHashMap<[u64; 3], SmallVec<[u32; 2]>> = FxHashMap::default();
    for c in cells {
        for &v in &c.verts {
            let d = arena.dense(v);
            if canon[d] != u32::MAX {
                continue;
            }
            // each vertex's exact coordinates once
            let vert = arena.vertex(v).to_owned();
            let r = *rounded[d].get_or_insert_with(|| vert.to_f64());
            let key = r.map(f64::to_bits);
            let bucket = seen.entry(key).or_default();
            let found = bucket.iter().copied().find(|&w| {
                exact[arena.dense(w)]
                    .as_ref()
                    .is_some_and(|x| x.same_point(&vert))
            });
            canon[d] = match found {
                Some(w) => w,
                None => {
                    bucket.push(v);
                    v
                }
            };
            exact[d] = Some(vert);
        }
    }
}

/// Merges `cells` (tiling a region of the `support` plane without overlap,
/// vertices and planes in `arena`) into maximal connected regions of equal
/// `labels`, with their boundary loops.
///
/// `rounded` is a cache of correctly rounded vertex coordinates, indexed
/// by [`PieceArena::dense`]; it is filled for every vertex the cells use (the
/// caller's output conversion can reuse it). Regions come in the order of
/// their first cell.
///
/// Panics (an internal error) if two cells overlap along an edge.
pub fn merge_cells(
    arena: &PieceArena,
    support: &Plane,
    cells: &[Piece],
    labels: &[u64],
    rounded: &mut Vec<Option<[f64; 3]>>,
) -> Vec<Region> {
    merge_cells_adjacent(arena, support, cells, labels, rounded, &mut Vec::new())
}

/// [`merge_cells`], also listing in `adjacent` every pair of cells
/// `[a, b]` (`a < b`, each pair once, in increasing order) that share a
/// piece of edge: what a later, local re-merge needs to know.
pub fn merge_cells_adjacent(
    arena: &PieceArena,
    support: &Plane,
    cells: &[Piece],
    labels: &[u64],
    rounded: &mut Vec<Option<[f64; 3]>>,
    adjacent: &mut Vec<[u32; 2]>,
) -> Vec<Region> {
    assert_eq!(cells.len(), labels.len(), "one label per cell");
    adjacent.clear();
    let (mut exact, mut canon_ids) = (Vec::new(), Vec::new());
    canonical_ids(arena, cells, rounded, &mut exact, &mut canon_ids);
    let canon = |v: u32| canon_ids[arena.dense(v)];
    let (u_ax, v_ax, k_ax) = axes(support);
    let sigma: i32 = if support.normal()[k_ax] > 0 { 1 } else { -1 };
    let vx = |i: u32| exact[arena.dense(i)].as_ref().expect("a used vertex");

    // group the edges by line
    let mut lines: Vec<Line> = Vec::new();
    let mut line_of: FxHashMap<LineKey, u32> = FxHashMap::default();
    for (ci, c) in cells.iter().enumerate() {
        let k = c.verts.len();
        for j in 0..k {
            let (a, b) = (canon(c.verts[j]), canon(c.verts[(j + 1) % k]));
            if a == b {
                continue;
            }
            let key = line_key(support, &arena.plane(c.edges[j]));
            let id = *line_of.entry(key).or_insert_with(|| {
                let (t_axis, dir) = if key.b.unsigned_abs() >= key.a.unsigned_abs() {
                    // u varies along the line: parametrize by u
                    let s = key.b.signum();
                    (u_ax, [s * key.b, -s * key.a])
                } else {
                    let s = -key.a.signum();
                    (v_ax, [s * key.b, -s * key.a])
                };
                lines.push(Line {
                    t_axis,
                    dir,
                    edges: Vec::new(),
                });
                (lines.len() - 1) as u32
            });
            lines[id as usize].edges.push((ci as u32, a, b));
        }
    }

    // along each line, the cells on the left and on the right of every
    // elementary interval
    let mut uf = UnionFind((0..cells.len() as u32).collect());
    // per line: sorted points, and per interval (left cell, right cell)
    let mut sides_of: Vec<(Vec<u32>, Vec<Sides>)> = Vec::with_capacity(lines.len());
    for line in &lines {
        let t = line.t_axis;
        let mut pts: Vec<u32> = line.edges.iter().flat_map(|&(_, a, b)| [a, b]).collect();
        pts.sort_unstable();
        pts.dedup();
        pts.sort_by(|&a, &b| vx(a).cmp_axis(vx(b), t));
        let pos: FxHashMap<u32, usize> = pts.iter().enumerate().map(|(i, &p)| (p, i)).collect();
        let mut iv: Vec<(Option<u32>, Option<u32>)> =
            vec![(None, None); pts.len().saturating_sub(1)];
        for &(ci, a, b) in &line.edges {
            let (pa, pb) = (pos[&a], pos[&b]);
            let (lo, hi, left) = if pa < pb {
                (pa, pb, true)
            } else {
                (pb, pa, false)
            };
            for slot in &mut iv[lo..hi] {
                let s = if left { &mut slot.0 } else { &mut slot.1 };
                assert!(
                    s.is_none() || *s == Some(ci),
                    "merge_cells: two cells overlap along an edge"
                );
                *s = Some(ci);
            }
        }
        for &(l, r) in &iv {
            if let (Some(l), Some(r)) = (l, r) {
                adjacent.push([l.min(r), l.max(r)]);
                if labels[l as usize] == labels[r as usize] {
                    uf.union(l, r);
                }
            }
        }
        sides_of.push((pts, iv));
    }

    // boundary pieces, each with its region on the left
    let mut segs: Vec<Seg> = Vec::new();
    for (li, (pts, iv)) in sides_of.iter().enumerate() {
        for (i, &(l, r)) in iv.iter().enumerate() {
            let same =
                matches!((l, r), (Some(l), Some(r)) if labels[l as usize] == labels[r as usize]);
            if same {
                continue;
            }
            if let Some(l) = l {
                segs.push(Seg {
                    from: pts[i],
                    to: pts[i + 1],
                    line: li as u32,
                    forward: true,
                    region: uf.find(l),
                });
            }
            if let Some(r) = r {
                segs.push(Seg {
                    from: pts[i + 1],
                    to: pts[i],
                    line: li as u32,
                    forward: false,
                    region: uf.find(r),
                });
            }
        }
    }
    let dir_of = |s: &Seg| {
        let d = lines[s.line as usize].dir;
        if s.forward { d } else { [-d[0], -d[1]] }
    };

    // chain the pieces into loops
    let mut outgoing: FxHashMap<(u32, u32), SmallVec<[u32; 2]>> = FxHashMap::default();
    for (i, s) in segs.iter().enumerate() {
        outgoing
            .entry((s.region, s.from))
            .or_default()
            .push(i as u32);
    }
    let mut used = vec![false; segs.len()];
    // region root -> loops (as segment lists)
    let mut loops: Vec<(u32, Vec<u32>)> = Vec::new();
    for start in 0..segs.len() {
        if used[start] {
            continue;
        }
        let region = segs[start].region;
        let mut path = vec![start as u32];
        used[start] = true;
        let mut cur = start;
        loop {
            let s = segs[cur];
            let cands = &outgoing[&(region, s.to)];
            let next = if cands.len() == 1 {
                cands[0]
            } else {
                // a vertex where the region touches itself: the first
                // outgoing piece clockwise from the reversed incoming one
                let r = dir_of(&s).map(|c| -c);
                *cands
                    .iter()
                    .min_by(|&&a, &&b| {
                        cmp_clockwise(
                            r,
                            dir_of(&segs[a as usize]),
                            dir_of(&segs[b as usize]),
                            sigma,
                        )
                    })
                    .expect("a boundary piece continues")
            };
            if next as usize == start {
                break;
            }
            assert!(!used[next as usize], "merge_cells: inconsistent boundary");
            used[next as usize] = true;
            path.push(next);
            cur = next as usize;
        }
        loops.push((region, path));
    }

    // corners only, then outer loop and holes per region
    let mut by_region: FxHashMap<u32, usize> = FxHashMap::default();
    let mut regions: Vec<Region> = Vec::new();
    let mut first_cell: Vec<u32> = Vec::new();
    let mut loop_lists: Vec<Vec<Vec<u32>>> = Vec::new();
    for (region, path) in &loops {
        let m = path.len();
        let corners: Vec<u32> = (0..m)
            .filter(|&i| segs[path[(i + m - 1) % m] as usize].line != segs[path[i] as usize].line)
            .map(|i| segs[path[i] as usize].from)
            .collect();
        let idx = *by_region.entry(*region).or_insert_with(|| {
            regions.push(Region {
                label: labels[*region as usize],
                outer: Vec::new(),
                holes: Vec::new(),
                cells: Vec::new(),
            });
            first_cell.push(*region);
            loop_lists.push(Vec::new());
            regions.len() - 1
        });
        loop_lists[idx].push(corners);
    }
    for (ri, list) in loop_lists.into_iter().enumerate() {
        if list.len() == 1 {
            regions[ri].outer = list.into_iter().next().expect("one loop");
            continue;
        }
        for l in list {
            if signed_area_sign(arena, &exact, rounded, &l, u_ax, v_ax) * sigma > 0 {
                debug_assert!(regions[ri].outer.is_empty(), "a region has one outer loop");
                regions[ri].outer = l;
            } else {
                regions[ri].holes.push(l);
            }
        }
    }
    // the cells of each region, and regions in the order of their first cell
    for ci in 0..cells.len() as u32 {
        let root = uf.find(ci);
        if let Some(&ri) = by_region.get(&root) {
            regions[ri].cells.push(ci);
        }
    }
    adjacent.sort_unstable();
    adjacent.dedup();
    let mut order: Vec<usize> = (0..regions.len()).collect();
    order.sort_by_key(|&i| first_cell[i]);
    let mut out: Vec<Option<Region>> = regions.into_iter().map(Some).collect();
    order
        .into_iter()
        .map(|i| out[i].take().expect("each region once"))
        .collect()
}

/// Orders `a` and `b` by the clockwise angle from `r` (seen from the
/// front of the support plane: `sigma` is the sign that makes `cross2`
/// counter-clockwise-positive), in `(0, 2π]`.
fn cmp_clockwise(r: [i128; 2], a: [i128; 2], b: [i128; 2], sigma: i32) -> Ordering {
    // group: 0 = clockwise within (0, π), 1 = exactly π, 2 = (π, 2π), 3 = 2π
    let group = |c: [i128; 2]| {
        let x = cross2(r, c);
        let s = if sigma > 0 { x } else { -x };
        if s.is_negative() {
            0
        } else if s.is_zero() {
            if dot2(r, c).is_negative() { 1 } else { 3 }
        } else {
            2
        }
    };
    let (ga, gb) = (group(a), group(b));
    if ga != gb {
        return ga.cmp(&gb);
    }
    // same open half-turn: a first if b is clockwise of a
    let x = cross2(a, b);
    let s = if sigma > 0 { x } else { -x };
    if s.is_negative() {
        Ordering::Less
    } else if s.is_zero() {
        Ordering::Equal
    } else {
        Ordering::Greater
    }
}

/// The sign of a loop's signed area in `(u, v)` coordinates: the `f64`
/// shoelace sum when its error bound certifies it, else exact rationals.
fn signed_area_sign(
    arena: &PieceArena,
    exact: &[Option<Vertex>],
    rounded: &[Option<[f64; 3]>],
    l: &[u32],
    u: usize,
    v: usize,
) -> i32 {
    let m = l.len();
    let p = |i: usize| rounded[arena.dense(l[i % m])].expect("rounded above");
    let (mut s, mut t) = (0.0f64, 0.0f64);
    for i in 0..m {
        let (a, b) = (p(i), p(i + 1));
        let (x, y) = (a[u] * b[v], b[u] * a[v]);
        s += x - y;
        t += x.abs() + y.abs();
    }
    // each coordinate is within half an ulp of the exact value, each term
    // carries a few roundings and the sum m more
    let bound = t * (m as f64 + 8.0) * f64::EPSILON;
    if s > bound {
        return 1;
    }
    if s < -bound {
        return -1;
    }
    let q = |i: usize| -> [BigRational; 2] {
        match exact[arena.dense(l[i % m])]
            .as_ref()
            .expect("a used vertex")
        {
            Vertex::Grid(g) => [
                BigRational::from_integer(BigInt::from(g[u])),
                BigRational::from_integer(BigInt::from(g[v])),
            ],
            Vertex::Implicit(h) => {
                let c = h.coords();
                let big = |x: I256| {
                    BigInt::parse_bytes(x.to_str_radix(16).as_bytes(), 16)
                        .expect("I256 prints in hexadecimal")
                };
                let w = big(c[3]);
                [
                    BigRational::new(big(c[u]), w.clone()),
                    BigRational::new(big(c[v]), w),
                ]
            }
        }
    };
    let mut sum = BigRational::from_integer(BigInt::from(0));
    for i in 0..m {
        let (a, b) = (q(i), q(i + 1));
        sum += &a[0] * &b[1] - &b[0] * &a[1];
    }
    use num_traits::Signed;
    if sum.is_positive() {
        1
    } else if sum.is_negative() {
        -1
    } else {
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::polygon::Polygon;

    fn square_cells(
        n: i32,
        labels: impl Fn(i32, i32) -> u64,
    ) -> (PieceArena, Plane, Vec<Piece>, Vec<u64>) {
        // an n × n grid of unit squares, each a separate polygon
        let mut arena = PieceArena::new();
        let mut cells = Vec::new();
        let mut ls = Vec::new();
        let mut support = None;
        for i in 0..n {
            for j in 0..n {
                let p = Polygon::from_grid_points(
                    &[[i, j, 0], [i + 1, j, 0], [i + 1, j + 1, 0], [i, j + 1, 0]],
                    0,
                )
                .unwrap();
                support = Some(*p.support());
                cells.push(arena.add_polygon(&p));
                ls.push(labels(i, j));
            }
        }
        (arena, support.unwrap(), cells, ls)
    }

    fn coords(arena: &PieceArena, l: &[u32]) -> Vec<[f64; 3]> {
        l.iter().map(|&v| arena.vertex(v).to_f64()).collect()
    }

    #[test]
    fn uniform_grid_becomes_one_square() {
        let (a, s, c, l) = square_cells(3, |_, _| 0);
        let mut r = Vec::new();
        let regions = merge_cells(&a, &s, &c, &l, &mut r);
        assert_eq!(regions.len(), 1);
        assert_eq!(regions[0].outer.len(), 4);
        assert!(regions[0].holes.is_empty());
        assert_eq!(regions[0].cells.len(), 9);
        let mut v = coords(&a, &regions[0].outer);
        v.sort_by(|a, b| a.partial_cmp(b).unwrap());
        assert_eq!(
            v,
            vec![[0., 0., 0.], [0., 3., 0.], [3., 0., 0.], [3., 3., 0.]]
        );
    }

    #[test]
    fn ring_with_a_hole() {
        let (a, s, c, l) = square_cells(3, |i, j| (i == 1 && j == 1) as u64);
        let mut r = Vec::new();
        let regions = merge_cells(&a, &s, &c, &l, &mut r);
        assert_eq!(regions.len(), 2);
        let ring = regions.iter().find(|g| g.label == 0).unwrap();
        assert_eq!(ring.outer.len(), 4);
        assert_eq!(ring.holes.len(), 1);
        assert_eq!(ring.holes[0].len(), 4);
        let centre = regions.iter().find(|g| g.label == 1).unwrap();
        assert!(centre.holes.is_empty());
        assert_eq!(centre.cells, vec![4]);
    }

    #[test]
    fn checkerboard_touching_at_corners() {
        let (a, s, c, l) = square_cells(2, |i, j| ((i + j) % 2) as u64);
        let mut r = Vec::new();
        let regions = merge_cells(&a, &s, &c, &l, &mut r);
        // squares of one label touch only at the centre: four regions
        assert_eq!(regions.len(), 4);
        assert!(
            regions
                .iter()
                .all(|g| g.outer.len() == 4 && g.holes.is_empty())
        );
    }

    #[test]
    fn t_junctions_and_pinches() {
        // an L of label 0 around a corner square of label 1, plus a cell
        // split so that a vertex sits in the middle of a neighbour's edge
        let mut arena = PieceArena::new();
        let big =
            Polygon::from_grid_points(&[[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0]], 0).unwrap();
        let s = *big.support();
        let c0 = arena.add_polygon(&big);
        let right1 =
            Polygon::from_grid_points(&[[2, 0, 0], [4, 0, 0], [4, 1, 0], [2, 1, 0]], 0).unwrap();
        let right2 =
            Polygon::from_grid_points(&[[2, 1, 0], [4, 1, 0], [4, 2, 0], [2, 2, 0]], 0).unwrap();
        let c1 = arena.add_polygon(&right1);
        let c2 = arena.add_polygon(&right2);
        let mut r = Vec::new();
        let regions = merge_cells(
            &arena,
            &s,
            &[c0.clone(), c1.clone(), c2.clone()],
            &[0, 0, 0],
            &mut r,
        );
        assert_eq!(regions.len(), 1);
        let mut v = coords(&arena, &regions[0].outer);
        v.sort_by(|a, b| a.partial_cmp(b).unwrap());
        assert_eq!(
            v,
            vec![[0., 0., 0.], [0., 2., 0.], [4., 0., 0.], [4., 2., 0.]]
        );
        let regions = merge_cells(&arena, &s, &[c0, c1, c2], &[0, 1, 0], &mut r);
        assert_eq!(regions.len(), 2);
        let l0 = regions.iter().find(|g| g.label == 0).unwrap();
        // big square plus the upper right half: an L with 6 corners
        assert_eq!(l0.outer.len(), 6);
    }
}
