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

use bsp_core::internals::{UnionFind, filter_ring_area, gcd128};
use bsp_core::{I256, Plane};

use super::pieces::{EdgeRef, Piece, PieceArena, Vertex};

/// A maximal connected region of equally labelled cells.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Region {
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

/// The coordinate axes `(u, v)` of the support plane's projection, and its
/// dominant axis `k`: `(u, v, k)` is a cyclic permutation of `(0, 1, 2)`.
fn axes(support: &Plane) -> (usize, usize, usize) {
    let k = support.dominant_axis();
    ((k + 1) % 3, (k + 2) % 3, k)
}

/// [`line_key`] of the arena's edge plane `e`, computed once per plane
/// (the key does not depend on the plane's orientation).
fn line_key_cached(
    keys: &mut FxHashMap<u32, LineKey>,
    support: &Plane,
    arena: &PieceArena,
    e: EdgeRef,
) -> LineKey {
    *keys
        .entry(e.index())
        .or_insert_with(|| line_key(support, &arena.plane(e)))
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
    let g = gcd128(a.unsigned_abs(), b.unsigned_abs());
    // (a gcd of 1, the usual one, divides nothing: the 256-bit remainder
    // and divisions are left out)
    let (mut a, mut b, mut c) = if g == 1 {
        (a, b, c)
    } else {
        let cm = (c.unsigned_abs() % bnum::types::U256::from(g)).as_::<u128>();
        let g = gcd128(g, cm) as i128;
        (a / g, b / g, c / I256::from(g))
    };
    if a < 0 || (a == 0 && b < 0) {
        (a, b, c) = (-a, -b, -c);
    }
    LineKey { a, b, c }
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

/// A point of a merge: its exact value, its correctly rounded
/// coordinates, and the arena id it was first seen with.
#[derive(Clone, Debug)]
struct MPoint {
    vertex: Vertex,
    rounded: [f64; 3],
    id: u32,
}

/// One line of a merge: the cell edges on it (cell, from, to, as point
/// indices), its points in order along it, and per interval between
/// consecutive points the cells on its left and on its right.
#[derive(Clone, Debug)]
struct MLine {
    /// The 3D axis that parametrizes the line.
    t_axis: usize,
    /// Direction of increasing `t` in `(u, v)` coordinates.
    dir: [i128; 2],
    edges: Vec<(u32, u32, u32)>,
    pts: Vec<u32>,
    iv: Vec<Sides>,
}

/// Points by exact identity: a base table (a cache's, shared) and the
/// points added for one merge, found by their rounded coordinates first.
struct Points<'a> {
    base: &'a [MPoint],
    base_bits: Option<&'a FxHashMap<[u64; 3], SmallVec<[u32; 2]>>>,
    extra: Vec<MPoint>,
    extra_bits: FxHashMap<[u64; 3], SmallVec<[u32; 2]>>,
}

impl<'a> Points<'a> {
    fn get(&self, i: u32) -> &MPoint {
        let i = i as usize;
        if i < self.base.len() {
            &self.base[i]
        } else {
            &self.extra[i - self.base.len()]
        }
    }

    /// The index of the point equal to `vertex`, added if new.
    fn add(&mut self, vertex: Vertex, rounded: [f64; 3], id: u32) -> u32 {
        let key = rounded.map(f64::to_bits);
        if let Some(b) = self.base_bits.and_then(|m| m.get(&key))
            && let Some(&i) = b
                .iter()
                .find(|&&i| self.base[i as usize].vertex.same_point(&vertex))
        {
            return i;
        }
        let n = self.base.len() as u32;
        let bucket = self.extra_bits.entry(key).or_default();
        if let Some(&i) = bucket
            .iter()
            .find(|&&i| self.extra[(i - n) as usize].vertex.same_point(&vertex))
        {
            return i;
        }
        let i = n + self.extra.len() as u32;
        bucket.push(i);
        self.extra.push(MPoint {
            vertex,
            rounded,
            id,
        });
        i
    }
}

/// The merge's frame: the support plane's projection axes and the sign
/// that makes `cross2` counter-clockwise-positive seen from its front.
#[derive(Clone, Copy, Debug)]
struct Frame {
    u: usize,
    v: usize,
    sigma: i32,
}

impl Frame {
    fn of(support: &Plane) -> Frame {
        let (u, v, k) = axes(support);
        Frame {
            u,
            v,
            sigma: if support.normal()[k] > 0 { 1 } else { -1 },
        }
    }
}

/// A new line for `key`.
fn new_line(key: &LineKey, f: &Frame) -> MLine {
    let (t_axis, dir) = if key.b.unsigned_abs() >= key.a.unsigned_abs() {
        // u varies along the line: parametrize by u
        let s = key.b.signum();
        (f.u, [s * key.b, -s * key.a])
    } else {
        let s = -key.a.signum();
        (f.v, [s * key.b, -s * key.a])
    };
    MLine {
        t_axis,
        dir,
        edges: Vec::new(),
        pts: Vec::new(),
        iv: Vec::new(),
    }
}

/// Sorts the line's points (its edges' ends, plus any already in `pts`)
/// along it and finds the cells on each side of every interval.
fn settle(line: &mut MLine, points: &Points<'_>) {
    let t = line.t_axis;
    line.pts
        .extend(line.edges.iter().flat_map(|&(_, a, b)| [a, b]));
    line.pts.sort_unstable();
    line.pts.dedup();
    line.pts
        .sort_by(|&a, &b| points.get(a).vertex.cmp_axis(&points.get(b).vertex, t));
    let pos: FxHashMap<u32, usize> = line.pts.iter().enumerate().map(|(i, &p)| (p, i)).collect();
    line.iv.clear();
    line.iv
        .resize(line.pts.len().saturating_sub(1), (None, None));
    for &(ci, a, b) in &line.edges {
        let (pa, pb) = (pos[&a], pos[&b]);
        let (lo, hi, left) = if pa < pb {
            (pa, pb, true)
        } else {
            (pb, pa, false)
        };
        for slot in &mut line.iv[lo..hi] {
            let s = if left { &mut slot.0 } else { &mut slot.1 };
            assert!(
                s.is_none() || *s == Some(ci),
                "merge_cells: two cells overlap along an edge"
            );
            *s = Some(ci);
        }
    }
}

/// A region as point indices.
#[derive(Clone, Debug, Default)]
struct PRegion {
    label: u64,
    outer: Vec<u32>,
    holes: Vec<Vec<u32>>,
    cells: Vec<u32>,
}

/// The union-find of `labels.len()` cells whose edges lie on `lines`:
/// cells that share a piece of edge and a label are united (the root of a
/// set is its smallest cell). `adjacent` receives every pair of cells
/// that share a piece of edge.
fn unite(lines: &[&MLine], labels: &[u64], adjacent: Option<&mut Vec<[u32; 2]>>) -> UnionFind {
    let mut uf = UnionFind::new(labels.len());
    let mut adj = adjacent;
    for line in lines {
        for &(l, r) in &line.iv {
            if let (Some(l), Some(r)) = (l, r) {
                if let Some(a) = adj.as_deref_mut() {
                    a.push([l.min(r), l.max(r)]);
                }
                if labels[l as usize] == labels[r as usize] {
                    uf.union(l, r);
                }
            }
        }
    }
    if let Some(a) = adj {
        a.sort_unstable();
        a.dedup();
    }
    uf
}

/// The regions of the cells labelled `labels` whose edges lie on `lines`
/// (united in `uf`). Regions whose root `skip` names are neither traced
/// nor returned.
fn trace(
    lines: &[&MLine],
    labels: &[u64],
    points: &Points<'_>,
    f: Frame,
    uf: &mut UnionFind,
    skip: impl Fn(u32) -> bool,
) -> Vec<PRegion> {
    let n = labels.len();
    let segs = boundary_pieces(lines, labels, uf, skip);
    let loops = chain_loops(lines, &segs, f.sigma);
    let (mut regions, by_region) = outline_regions(&segs, &loops, labels, points, f);
    // the cells of each region, and regions in the order of their first cell
    for ci in 0..n as u32 {
        let root = uf.find(ci);
        if let Some(&ri) = by_region.get(&root) {
            regions[ri].cells.push(ci);
        }
    }
    regions.sort_by_key(|r| r.cells.first().copied().unwrap_or(u32::MAX));
    regions
}

/// The boundary pieces of the regions (the intervals of `lines` between
/// cells of different labels, or with a cell on one side only), each
/// directed with its region on the left; none of the regions whose root
/// `skip` names.
fn boundary_pieces(
    lines: &[&MLine],
    labels: &[u64],
    uf: &mut UnionFind,
    skip: impl Fn(u32) -> bool,
) -> Vec<Seg> {
    let mut segs: Vec<Seg> = Vec::new();
    for (li, line) in lines.iter().enumerate() {
        for (i, &(l, r)) in line.iv.iter().enumerate() {
            let same =
                matches!((l, r), (Some(l), Some(r)) if labels[l as usize] == labels[r as usize]);
            if same {
                continue;
            }
            if let Some(l) = l {
                let region = uf.find(l);
                if !skip(region) {
                    segs.push(Seg {
                        from: line.pts[i],
                        to: line.pts[i + 1],
                        line: li as u32,
                        forward: true,
                        region,
                    });
                }
            }
            if let Some(r) = r {
                let region = uf.find(r);
                if !skip(region) {
                    segs.push(Seg {
                        from: line.pts[i + 1],
                        to: line.pts[i],
                        line: li as u32,
                        forward: false,
                        region,
                    });
                }
            }
        }
    }
    segs
}

/// The boundary pieces `segs` chained into closed loops, each with its
/// region: where a region touches itself at a vertex, a loop turns to
/// the first outgoing piece clockwise (`sigma` as in [`Frame`]).
fn chain_loops(lines: &[&MLine], segs: &[Seg], sigma: i32) -> Vec<(u32, Vec<u32>)> {
    let dir_of = |s: &Seg| {
        let d = lines[s.line as usize].dir;
        if s.forward { d } else { [-d[0], -d[1]] }
    };
    let mut outgoing: FxHashMap<(u32, u32), SmallVec<[u32; 2]>> = FxHashMap::default();
    for (i, s) in segs.iter().enumerate() {
        outgoing
            .entry((s.region, s.from))
            .or_default()
            .push(i as u32);
    }
    let mut used = vec![false; segs.len()];
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
    loops
}

/// The regions of `loops` (in the order of their first loop), each with
/// its label, its outer loop and its holes, corners only (no cells yet);
/// and each region's index by its root.
fn outline_regions(
    segs: &[Seg],
    loops: &[(u32, Vec<u32>)],
    labels: &[u64],
    points: &Points<'_>,
    f: Frame,
) -> (Vec<PRegion>, FxHashMap<u32, usize>) {
    let mut by_region: FxHashMap<u32, usize> = FxHashMap::default();
    let mut regions: Vec<PRegion> = Vec::new();
    let mut loop_lists: Vec<Vec<Vec<u32>>> = Vec::new();
    for (region, path) in loops {
        let m = path.len();
        let corners: Vec<u32> = (0..m)
            .filter(|&i| segs[path[(i + m - 1) % m] as usize].line != segs[path[i] as usize].line)
            .map(|i| segs[path[i] as usize].from)
            .collect();
        let idx = *by_region.entry(*region).or_insert_with(|| {
            regions.push(PRegion {
                label: labels[*region as usize],
                ..PRegion::default()
            });
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
            if signed_area_sign(points, &l, f.u, f.v) * f.sigma > 0 {
                debug_assert!(regions[ri].outer.is_empty(), "a region has one outer loop");
                regions[ri].outer = l;
            } else {
                regions[ri].holes.push(l);
            }
        }
    }
    (regions, by_region)
}

/// The points, lines and per-cell indices of `cells`.
struct Built<'a> {
    points: Points<'a>,
    lines: Vec<MLine>,
    line_of: FxHashMap<LineKey, u32>,
    cell_points: Vec<SmallVec<[u32; 6]>>,
    cell_lines: Vec<SmallVec<[u32; 6]>>,
}

/// The points of `cells`' corners, each arena vertex added to `points`
/// once (its exact coordinates and their rounding computed once).
fn add_points(
    points: &mut Points<'_>,
    arena: &PieceArena,
    cells: &[Piece],
) -> Vec<SmallVec<[u32; 6]>> {
    let mut seen: FxHashMap<u32, u32> = FxHashMap::default();
    cells
        .iter()
        .map(|c| {
            c.verts
                .iter()
                .map(|&v| {
                    *seen.entry(v).or_insert_with(|| {
                        let vert = arena.vertex(v).to_owned();
                        let r = vert.to_f64();
                        points.add(vert, r, v)
                    })
                })
                .collect()
        })
        .collect()
}

fn build<'a>(arena: &PieceArena, support: &Plane, cells: &[Piece], f: &Frame) -> Built<'a> {
    let mut points = Points {
        base: &[],
        base_bits: None,
        extra: Vec::new(),
        extra_bits: FxHashMap::default(),
    };
    let cell_points = add_points(&mut points, arena, cells);
    let mut lines: Vec<MLine> = Vec::new();
    let mut line_of: FxHashMap<LineKey, u32> = FxHashMap::default();
    let mut cell_lines: Vec<SmallVec<[u32; 6]>> = Vec::with_capacity(cells.len());
    let mut keys = FxHashMap::default();
    for (ci, c) in cells.iter().enumerate() {
        let pts = &cell_points[ci];
        let k = pts.len();
        let mut ls = SmallVec::new();
        for j in 0..k {
            let (a, b) = (pts[j], pts[(j + 1) % k]);
            let key = line_key_cached(&mut keys, support, arena, c.edges[j]);
            let id = *line_of.entry(key).or_insert_with(|| {
                lines.push(new_line(&key, f));
                (lines.len() - 1) as u32
            });
            if a != b {
                lines[id as usize].edges.push((ci as u32, a, b));
            }
            ls.push(id);
        }
        cell_lines.push(ls);
    }
    for line in &mut lines {
        settle(line, &points);
    }
    Built {
        points,
        lines,
        line_of,
        cell_points,
        cell_lines,
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
pub(crate) fn merge_cells(
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
/// piece of edge.
pub(crate) fn merge_cells_adjacent(
    arena: &PieceArena,
    support: &Plane,
    cells: &[Piece],
    labels: &[u64],
    rounded: &mut Vec<Option<[f64; 3]>>,
    adjacent: &mut Vec<[u32; 2]>,
) -> Vec<Region> {
    assert_eq!(cells.len(), labels.len(), "one label per cell");
    adjacent.clear();
    let f = Frame::of(support);
    let b = build(arena, support, cells, &f);
    rounded.resize(arena.len(), None);
    for (c, pts) in cells.iter().zip(&b.cell_points) {
        for (&v, &p) in c.verts.iter().zip(pts) {
            rounded[arena.dense(v)] = Some(b.points.get(p).rounded);
        }
    }
    let lines: Vec<&MLine> = b.lines.iter().collect();
    let mut uf = unite(&lines, labels, Some(adjacent));
    let regions = trace(&lines, labels, &b.points, f, &mut uf, |_| false);
    let id = |p: &u32| b.points.get(*p).id;
    regions
        .into_iter()
        .map(|r| Region {
            label: r.label,
            outer: r.outer.iter().map(id).collect(),
            holes: r.holes.iter().map(|h| h.iter().map(id).collect()).collect(),
            cells: r.cells,
        })
        .collect()
}

/// A region merge kept for merging the same cells again after some of them
/// change (the static shadows of a face under a moving object's).
///
/// It holds what a merge computes once: the cells' exact points, each
/// edge's line, every line's points in order and the cells on both sides
/// of each interval, and the regions. [`MergeCache::remerge`] then works
/// only on the lines the changed cells touch and traces only the regions
/// that change; the regions are the same as a full [`merge_cells`] of the
/// new cells would make.
#[derive(Clone, Debug)]
pub(crate) struct MergeCache {
    frame: Frame,
    support: Plane,
    points: Vec<MPoint>,
    bits: FxHashMap<[u64; 3], SmallVec<[u32; 2]>>,
    lines: Vec<MLine>,
    line_of: FxHashMap<LineKey, u32>,
    cell_points: Vec<SmallVec<[u32; 6]>>,
    cell_lines: Vec<SmallVec<[u32; 6]>>,
    labels: Vec<u64>,
    /// Per cell, its region.
    region_of: Vec<u32>,
    /// Per region, its cell count.
    region_size: Vec<u32>,
}

/// A merged region of a [`MergeCache::remerge`]: its label, its rings and
/// cells as indices into the [`Remerged`] it belongs to.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct MergedRegion {
    /// The cells' label.
    pub label: u64,
    /// The outer boundary (point indices), counter-clockwise seen from
    /// the front of the support plane; corners only.
    pub outer: Vec<u32>,
    /// The holes, each clockwise.
    pub holes: Vec<Vec<u32>>,
    /// The cells: cached cells `0..n`, then the new pieces `n..`.
    pub cells: Vec<u32>,
}

/// The result of [`MergeCache::remerge`].
#[derive(Clone, Debug)]
pub(crate) struct Remerged {
    base: usize,
    extra: Vec<MPoint>,
    piece_points: Vec<SmallVec<[u32; 6]>>,
    /// The regions that differ from the cache's, in the order of their
    /// first cell.
    pub regions: Vec<MergedRegion>,
    /// The cache's regions that stand as they were (indices, ascending).
    pub standing: Vec<u32>,
}

impl Remerged {
    /// Point `i`'s exact value and correctly rounded coordinates.
    pub(crate) fn point<'c>(&'c self, cache: &'c MergeCache, i: u32) -> (&'c Vertex, [f64; 3]) {
        let p = if (i as usize) < self.base {
            &cache.points[i as usize]
        } else {
            &self.extra[i as usize - self.base]
        };
        (&p.vertex, p.rounded)
    }

    /// The points of cell `c` (a cached cell below the cache's cell count,
    /// else a new piece).
    pub(crate) fn cell_points<'c>(&'c self, cache: &'c MergeCache, c: u32) -> &'c [u32] {
        let n = cache.cell_points.len();
        if (c as usize) < n {
            &cache.cell_points[c as usize]
        } else {
            &self.piece_points[c as usize - n]
        }
    }
}

impl MergeCache {
    /// Merges `cells` as [`merge_cells`] does and keeps what a re-merge
    /// needs. Returns the regions too, in the cache's region order.
    pub(crate) fn new(
        arena: &PieceArena,
        support: &Plane,
        cells: &[Piece],
        labels: &[u64],
    ) -> (MergeCache, Vec<Region>) {
        assert_eq!(cells.len(), labels.len(), "one label per cell");
        let f = Frame::of(support);
        let b = build(arena, support, cells, &f);
        let lines: Vec<&MLine> = b.lines.iter().collect();
        let mut uf = unite(&lines, labels, None);
        let regions = trace(&lines, labels, &b.points, f, &mut uf, |_| false);
        let mut region_of = vec![0u32; cells.len()];
        let mut region_size = Vec::with_capacity(regions.len());
        for (ri, r) in regions.iter().enumerate() {
            for &c in &r.cells {
                region_of[c as usize] = ri as u32;
            }
            region_size.push(r.cells.len() as u32);
        }
        let id = |p: &u32| b.points.get(*p).id;
        let out = regions
            .into_iter()
            .map(|r| Region {
                label: r.label,
                outer: r.outer.iter().map(id).collect(),
                holes: r.holes.iter().map(|h| h.iter().map(id).collect()).collect(),
                cells: r.cells,
            })
            .collect();
        let cache = MergeCache {
            frame: f,
            support: *support,
            points: b.points.extra,
            bits: b.points.extra_bits,
            lines: b.lines,
            line_of: b.line_of,
            cell_points: b.cell_points,
            cell_lines: b.cell_lines,
            labels: labels.to_vec(),
            region_of,
            region_size,
        };
        (cache, out)
    }

    /// The regions after a change: the cached cells listed in `removed`
    /// are replaced by `pieces` (in `arena`, labelled `piece_labels`, on
    /// the same support plane, covering exactly the removed cells), and
    /// the cached cells in `relabel` take new labels. Only the lines the
    /// change touches are redone, and only the regions that change are
    /// traced: [`Remerged::standing`] lists the cached regions that stand.
    pub(crate) fn remerge(
        &self,
        removed: &[u32],
        relabel: &[(u32, u64)],
        arena: &PieceArena,
        pieces: &[Piece],
        piece_labels: &[u64],
    ) -> Remerged {
        assert_eq!(pieces.len(), piece_labels.len(), "one label per piece");
        let n = self.cell_points.len();
        let f = self.frame;
        let mut points = Points {
            base: &self.points,
            base_bits: Some(&self.bits),
            extra: Vec::new(),
            extra_bits: FxHashMap::default(),
        };
        let (labels, changed, gone) = self.changed_cells(removed, relabel, piece_labels);
        // the new pieces' points and lines
        let piece_points = add_points(&mut points, arena, pieces);
        let (touched, fresh) =
            self.touched_lines(removed, &gone, arena, pieces, &piece_points, &points);
        let mut all: Vec<&MLine> = Vec::with_capacity(self.lines.len() + fresh.len());
        for (i, line) in self.lines.iter().enumerate() {
            all.push(touched.get(&(i as u32)).unwrap_or(line));
        }
        all.extend(fresh.iter());
        let (mut uf, standing_root, standing) = self.unite_standing(&all, &labels, &changed, &gone);
        let traced = trace(&all, &labels, &points, f, &mut uf, |root| {
            standing_root[root as usize]
        });
        // removed cells have no edges left: they are not regions
        let regions = traced
            .into_iter()
            .filter(|r| {
                r.cells
                    .iter()
                    .any(|&c| (c as usize) >= n || !gone[c as usize])
            })
            .map(|mut r| {
                r.cells.retain(|&c| (c as usize) >= n || !gone[c as usize]);
                MergedRegion {
                    label: r.label,
                    outer: r.outer,
                    holes: r.holes,
                    cells: r.cells,
                }
            })
            .collect();
        Remerged {
            base: self.points.len(),
            extra: points.extra,
            piece_points,
            regions,
            standing,
        }
    }

    /// The labels after a change (the cached cells', with `relabel`
    /// applied, then `piece_labels`), and per cached cell whether it
    /// changed (relabelled or removed) and whether it is `removed`.
    fn changed_cells(
        &self,
        removed: &[u32],
        relabel: &[(u32, u64)],
        piece_labels: &[u64],
    ) -> (Vec<u64>, Vec<bool>, Vec<bool>) {
        let n = self.cell_points.len();
        let mut labels = self.labels.clone();
        let mut changed = vec![false; n];
        for &(c, l) in relabel {
            labels[c as usize] = l;
            changed[c as usize] = true;
        }
        let mut gone = vec![false; n];
        for &c in removed {
            gone[c as usize] = true;
            changed[c as usize] = true;
        }
        labels.extend_from_slice(piece_labels);
        (labels, changed, gone)
    }

    /// The lines a change touches, settled on `points`: copies of the
    /// cached lines that the `removed` cells or the new `pieces` (with
    /// points `piece_points`) lie on, without the removed cells' edges and
    /// with the pieces', by cached line; and the new lines only pieces lie
    /// on, numbered after the cached ones.
    fn touched_lines(
        &self,
        removed: &[u32],
        gone: &[bool],
        arena: &PieceArena,
        pieces: &[Piece],
        piece_points: &[SmallVec<[u32; 6]>],
        points: &Points<'_>,
    ) -> (FxHashMap<u32, MLine>, Vec<MLine>) {
        let n = self.cell_points.len();
        let f = self.frame;
        // touched lines: copies of the cached ones, and new ones
        let mut touched: FxHashMap<u32, MLine> = FxHashMap::default();
        let mut fresh: Vec<MLine> = Vec::new();
        let mut fresh_of: FxHashMap<LineKey, u32> = FxHashMap::default();
        for &c in removed {
            for &l in &self.cell_lines[c as usize] {
                touched.entry(l).or_insert_with(|| {
                    let mut line = self.lines[l as usize].clone();
                    line.edges.retain(|e| !gone[e.0 as usize]);
                    line
                });
            }
        }
        let nl = self.lines.len() as u32;
        let mut keys = FxHashMap::default();
        for (k, (c, pts)) in pieces.iter().zip(piece_points).enumerate() {
            let m = pts.len();
            for j in 0..m {
                let (a, b) = (pts[j], pts[(j + 1) % m]);
                let key = line_key_cached(&mut keys, &self.support, arena, c.edges[j]);
                let line = match self.line_of.get(&key) {
                    Some(&l) => touched.entry(l).or_insert_with(|| {
                        let mut line = self.lines[l as usize].clone();
                        line.edges.retain(|e| !gone[e.0 as usize]);
                        line
                    }),
                    None => {
                        let i = *fresh_of.entry(key).or_insert_with(|| {
                            fresh.push(new_line(&key, &f));
                            nl + fresh.len() as u32 - 1
                        });
                        &mut fresh[(i - nl) as usize]
                    }
                };
                if a != b {
                    line.edges.push(((n + k) as u32, a, b));
                }
            }
        }
        for line in touched.values_mut().chain(fresh.iter_mut()) {
            settle(line, points);
        }
        (touched, fresh)
    }

    /// The union-find of the changed cells (`labels`, on `all` lines),
    /// and the cached regions that stand: none of their cells changed and
    /// their cells make up a whole new region (nothing joined it). Returns
    /// the union-find, per root whether its region stands, and the
    /// standing regions (ascending).
    fn unite_standing(
        &self,
        all: &[&MLine],
        labels: &[u64],
        changed: &[bool],
        gone: &[bool],
    ) -> (UnionFind, Vec<bool>, Vec<u32>) {
        let n = self.cell_points.len();
        // a cached region stands when none of its cells changed and its
        // cells make up a whole new region (nothing joined it)
        let regions = self.region_size.len();
        let mut intact = vec![true; regions];
        for c in 0..n {
            if changed[c] {
                intact[self.region_of[c] as usize] = false;
            }
        }
        let mut uf = unite(all, labels, None);
        let mut size = vec![0u32; labels.len()];
        for c in 0..labels.len() as u32 {
            if (c as usize) < n && gone[c as usize] {
                continue;
            }
            size[uf.find(c) as usize] += 1;
        }
        let mut standing_root = vec![false; labels.len()];
        let mut standing = Vec::new();
        let mut first = vec![u32::MAX; regions];
        for c in (0..n).rev() {
            first[self.region_of[c] as usize] = c as u32;
        }
        for r in 0..regions {
            if !intact[r] {
                continue;
            }
            let root = uf.find(first[r]);
            if size[root as usize] == self.region_size[r] {
                standing_root[root as usize] = true;
                standing.push(r as u32);
            }
        }
        (uf, standing_root, standing)
    }
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
/// shoelace sum when the kernel's filter certifies it
/// ([`bsp_core::internals::filter_ring_area`]: the points' coordinates are
/// correctly rounded), else exact rationals.
fn signed_area_sign(points: &Points<'_>, l: &[u32], u: usize, v: usize) -> i32 {
    let m = l.len();
    let ring = l.iter().map(|&i| {
        let r = points.get(i).rounded;
        [r[u], r[v]]
    });
    if let Some(sign) = filter_ring_area(ring) {
        return sign;
    }
    let q = |i: usize| -> [BigRational; 2] {
        match &points.get(l[i % m]).vertex {
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
    use bsp_core::Polygon;

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
