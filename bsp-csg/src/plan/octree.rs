//! An adaptive octree over the region where two surfaces may meet.
//!
//! A cell is a box of grid coordinates `[lo, hi]` (inclusive, per axis);
//! its walls lie half a step outside, at `lo − ½` and `hi + ½`, on planes
//! that hold no grid point — so no input vertex and no input face lies on a
//! wall, and no face edge lies in one. A cell is split (at the middle of
//! every axis it spans more than one coordinate of) while it holds faces of
//! both operands, more than `leaf_size` faces in all, and can be split.
//! Faces are sent to every child their box overlaps.

use bsp_core::Plane;
use bsp_core::internals::ConvexFace;
use bsp_core::par;
use smallvec::SmallVec;

use super::operands::Operand;
use crate::index::{IBox, SmallBox};

/// A leaf of the octree: its box and the faces of each operand whose box
/// overlaps it.
#[derive(Clone, Debug)]
pub(crate) struct Leaf {
    pub(crate) bx: IBox,
    pub(crate) a: Vec<u32>,
    pub(crate) b: Vec<u32>,
    /// The build's `settled` said so: the cell was left whole because its
    /// two surfaces are one (a leaf without it was not asked).
    pub(crate) settled: bool,
}

impl Leaf {
    /// Whether the leaf holds faces of both operands.
    pub(crate) fn mixed(&self) -> bool {
        !self.a.is_empty() && !self.b.is_empty()
    }

    /// The leaf's faces of operand `o`.
    pub(crate) fn faces(&self, o: Operand) -> &Vec<u32> {
        match o {
            Operand::A => &self.a,
            Operand::B => &self.b,
        }
    }

    /// Whether the leaf holds no face of operand `o`: it is free of that
    /// operand's surface.
    pub(crate) fn free_of(&self, o: Operand) -> bool {
        self.faces(o).is_empty()
    }
}

/// The six wall planes of a cell, interior behind each.
pub(crate) fn walls(bx: &IBox) -> [Plane; 6] {
    let wall = |k: usize, sign: i64, c: i64| {
        let mut n = [0i64; 3];
        n[k] = 2 * sign;
        // sign · 2x − (2c ± 1) = 0
        Plane::new(n, -(sign as i128) * (2 * c as i128 + sign as i128))
            .expect("a wall plane is within the budget")
    };
    let (lo, hi) = bx;
    [
        wall(0, -1, lo[0]),
        wall(0, 1, hi[0]),
        wall(1, -1, lo[1]),
        wall(1, 1, hi[1]),
        wall(2, -1, lo[2]),
        wall(2, 1, hi[2]),
    ]
}

/// Whether the plane meets the closed box of a cell, walls included: the
/// exact signs of the plane at the box's extreme corners (half-integers,
/// so everything is doubled; the products stay within `i128`).
pub(crate) fn plane_meets(pl: &Plane, bx: &IBox) -> bool {
    let n = pl.normal();
    let (mut lo, mut hi) = (2 * pl.offset(), 2 * pl.offset());
    for ((&n, &l), &h) in n.iter().zip(&bx.0).zip(&bx.1) {
        // (a cell's coordinates are grid coordinates, far inside `i64`:
        // each product is one 64 × 64 → 128-bit multiplication)
        debug_assert!(l.unsigned_abs() < 1 << 61 && h.unsigned_abs() < 1 << 61);
        let (a, b) = (
            n as i128 * (2 * l - 1) as i128,
            n as i128 * (2 * h + 1) as i128,
        );
        // the lower end is at the low wall where the normal is positive
        if n >= 0 {
            lo += a;
            hi += b;
        } else {
            lo += b;
            hi += a;
        }
    }
    lo <= 0 && 0 <= hi
}

/// Whether the polygon meets the closed box of a cell (walls included).
/// Exact for polygons with grid vertices (separating axes: the box's, the
/// polygon's normal, and its edges crossed with the box's axes, all in
/// doubled integer coordinates); for others the support plane's test
/// ([`plane_meets`]), which may say yes where the polygon does not reach.
pub(crate) fn polygon_meets(poly: &impl ConvexFace, bx: &IBox) -> bool {
    if !plane_meets(poly.support(), bx) {
        return false;
    }
    let g: Option<SmallVec<[[i128; 3]; 8]>> = (0..poly.corner_count())
        .map(|i| poly.corner(i).as_grid().map(|c| c.map(|x| 2 * x as i128)))
        .collect();
    let Some(g) = g else {
        return true;
    };
    // the box in doubled coordinates: centre lo + hi, half extent hi − lo + 1
    let c = [0, 1, 2].map(|k| (bx.0[k] + bx.1[k]) as i128);
    let h = [0, 1, 2].map(|k| (bx.1[k] - bx.0[k] + 1) as i128);
    let dot = |l: &[i128; 3], p: &[i128; 3]| l[0] * p[0] + l[1] * p[1] + l[2] * p[2];
    for (i, &p) in g.iter().enumerate() {
        let q = g[(i + 1) % g.len()];
        let e = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
        for k in 0..3 {
            // e × unit axis k
            let mut l = [0i128; 3];
            let (u, v) = ((k + 1) % 3, (k + 2) % 3);
            l[u] = e[v];
            l[v] = -e[u];
            if l == [0; 3] {
                continue;
            }
            let (mut lo, mut hi) = (i128::MAX, i128::MIN);
            for w in &g {
                let d = dot(&l, w);
                lo = lo.min(d);
                hi = hi.max(d);
            }
            let mid = dot(&l, &c);
            let r = l[0].abs() * h[0] + l[1].abs() * h[1] + l[2].abs() * h[2];
            if hi < mid - r || lo > mid + r {
                return false;
            }
        }
    }
    true
}

/// A test of a face's plane against a cell, for [`Faces`].
pub(crate) trait PlaneTest: Fn(u32, &IBox) -> bool + Sync {}

impl<T: Fn(u32, &IBox) -> bool + Sync> PlaneTest for T {}

/// One operand's faces for [`build`]: each face's box, and a test of its
/// plane against a cell (`true` whenever the face meets the cell; it may
/// be `true` more often).
pub(crate) struct Faces<'a, P> {
    pub(crate) boxes: &'a [SmallBox],
    pub(crate) plane_meets: P,
}

/// The leaves of the octree over `domain` for the faces `0..` of `a` and
/// of `b` (by their index in each), in a fixed order. A face goes to each
/// child of a cell that its box overlaps and whose box its plane meets.
///
/// A cell holding faces of both operands is split while it holds more
/// than `leaf_size` faces, can be split, and the last split made progress:
/// a split after which some child holds every face of its parent gains
/// nothing when faces pile up at one point (a vertex of high degree on the
/// other surface), so the depth stays bounded there. Large cells' subtrees
/// are built in parallel (the same leaves, in the same order).
///
/// `settled(cell)` says that a cell need not be split whatever it holds
/// (its two surfaces are one there: see `plan::twins`).
pub(crate) fn build<P: PlaneTest, Q: PlaneTest>(
    domain: IBox,
    a: &Faces<'_, P>,
    b: &Faces<'_, Q>,
    leaf_size: usize,
    settled: &(dyn Fn(&Leaf) -> bool + Sync),
) -> Vec<Leaf> {
    let root = Leaf {
        bx: domain,
        a: (0..a.boxes.len() as u32).collect(),
        b: (0..b.boxes.len() as u32).collect(),
        settled: false,
    };
    grow(
        root,
        0,
        &Build {
            a,
            b,
            leaf_size,
            settled,
        },
    )
}

/// What the build works from.
struct Build<'f, 'a, P, Q> {
    a: &'f Faces<'a, P>,
    b: &'f Faces<'a, Q>,
    leaf_size: usize,
    settled: &'f (dyn Fn(&Leaf) -> bool + Sync),
}

/// Cells with more faces than this build their children's subtrees in
/// parallel.
const PARALLEL_FACES: usize = 2048;

/// The leaves under `cell`, in order; `stalled` counts the splits in a row
/// that made no progress.
fn grow<P: PlaneTest, Q: PlaneTest>(cell: Leaf, stalled: u8, o: &Build<'_, '_, P, Q>) -> Vec<Leaf> {
    let mut leaves = Vec::new();
    let mut stack = vec![(cell, stalled)];
    while let Some((mut cell, stalled)) = stack.pop() {
        let Some((kids, stalled)) = split(&mut cell, stalled, o) else {
            leaves.push(cell);
            continue;
        };
        if cell.a.len() + cell.b.len() > PARALLEL_FACES {
            let parts: Vec<Vec<Leaf>> =
                par::map_vec(kids.into_iter().collect(), |k| grow(k, stalled, o));
            leaves.extend(parts.into_iter().flatten());
        } else {
            // children pushed in reverse so that they come out in order
            for k in kids.into_iter().rev() {
                stack.push((k, stalled));
            }
        }
    }
    leaves
}

/// The children of `cell` with their faces, and their count of stalled
/// splits; `None` if the cell is a leaf (marked `settled` if that is why).
fn split<P: PlaneTest, Q: PlaneTest>(
    cell: &mut Leaf,
    stalled: u8,
    o: &Build<'_, '_, P, Q>,
) -> Option<(Vec<Leaf>, u8)> {
    let (a, b, leaf_size) = (o.a, o.b, o.leaf_size);
    let (lo, hi) = cell.bx;
    let axes: SmallVec<[usize; 3]> = (0..3).filter(|&k| hi[k] > lo[k]).collect();
    if !cell.mixed()
        || cell.a.len() + cell.b.len() <= leaf_size
        || axes.is_empty()
        || stalled >= MAX_STALLED
    {
        return None;
    }
    if (o.settled)(cell) {
        cell.settled = true;
        return None;
    }
    let mid = [0, 1, 2].map(|k| lo[k] + (hi[k] - lo[k]) / 2);
    // child `c` lies on the upper side of axis `axes[j]` when bit
    // `axes.len() - 1 - j` of `c` is set (the first axis varies slowest)
    let m = axes.len();
    let boxes: SmallVec<[IBox; 8]> = (0..1usize << m)
        .map(|c| {
            let (mut l, mut h) = (lo, hi);
            for (j, &k) in axes.iter().enumerate() {
                if c >> (m - 1 - j) & 1 == 0 {
                    h[k] = mid[k];
                } else {
                    l[k] = mid[k] + 1;
                }
            }
            (l, h)
        })
        .collect();
    let mut kids: Vec<Leaf> = boxes
        .iter()
        .map(|&bx| Leaf {
            bx,
            a: Vec::new(),
            b: Vec::new(),
            settled: false,
        })
        .collect();
    // a face's box overlaps the cell, so along each split axis it
    // overlaps the lower child if it starts at or below the middle, the
    // upper if it ends above it
    let deal_run = |fs: &[u32],
                    bxs: &[SmallBox],
                    meets: &(dyn Fn(u32, &IBox) -> bool + Sync),
                    kids: &mut [Vec<u32>]| {
        for &f in fs {
            let (fl, fh) = bxs[f as usize];
            let (fl, fh) = (fl.map(i64::from), fh.map(i64::from));
            let (mut any, mut all) = (0usize, 0usize);
            for (j, &k) in axes.iter().enumerate() {
                let bit = 1 << (m - 1 - j);
                let (low, high) = (fl[k] <= mid[k], fh[k] > mid[k]);
                if high {
                    any |= bit;
                    if !low {
                        all |= bit;
                    }
                }
            }
            // the children c with all ⊆ c ⊆ any; a face whose box lies
            // within the child's meets it, so its plane needs no test
            let spread = any & !all;
            let mut s = spread;
            loop {
                let c = all | s;
                let (cl, ch) = &boxes[c];
                let within = (0..3).all(|k| cl[k] <= fl[k] && fh[k] <= ch[k]);
                if within || meets(f, &boxes[c]) {
                    kids[c].push(f);
                }
                if s == 0 {
                    break;
                }
                s = (s - 1) & spread;
            }
        }
    };
    // a large cell's faces are dealt in runs in parallel, each run's
    // lists joined in order (the same lists)
    let deal = |fs: &[u32], bxs: &[SmallBox], meets: &(dyn Fn(u32, &IBox) -> bool + Sync)| {
        const RUN: usize = 1 << 13;
        // (each child's list starts with room for a share of the faces:
        // a surface crosses about half the children of a cell)
        let room = |n: usize| n.div_ceil(boxes.len()) * 2;
        if fs.len() <= 2 * RUN {
            let mut lists: Vec<Vec<u32>> = (0..boxes.len())
                .map(|_| Vec::with_capacity(room(fs.len())))
                .collect();
            deal_run(fs, bxs, meets, &mut lists);
            return lists;
        }
        let runs: Vec<Vec<Vec<u32>>> = par::map(fs.len().div_ceil(RUN), |k| {
            let run = &fs[k * RUN..((k + 1) * RUN).min(fs.len())];
            let mut lists: Vec<Vec<u32>> = (0..boxes.len())
                .map(|_| Vec::with_capacity(room(run.len())))
                .collect();
            deal_run(run, bxs, meets, &mut lists);
            lists
        });
        (0..boxes.len())
            .map(|c| runs.iter().flat_map(|r| r[c].iter().copied()).collect())
            .collect()
    };
    let (la, lb) = if cell.a.len() + cell.b.len() > PARALLEL_FACES {
        par::join(
            || deal(&cell.a, a.boxes, &a.plane_meets),
            || deal(&cell.b, b.boxes, &b.plane_meets),
        )
    } else {
        (
            deal(&cell.a, a.boxes, &a.plane_meets),
            deal(&cell.b, b.boxes, &b.plane_meets),
        )
    };
    for ((kid, fa), fb) in kids.iter_mut().zip(la).zip(lb) {
        kid.a = fa;
        kid.b = fb;
    }
    // faces larger than the cell land in several children each: the
    // split cuts them without sorting them apart
    let n = cell.a.len() + cell.b.len();
    let total: usize = kids.iter().map(|k| k.a.len() + k.b.len()).sum();
    let stuck = total >= STALL_SHARE * n || kids.iter().any(|k| k.a.len() + k.b.len() == n);
    Some((kids, if stuck { stalled + 1 } else { 0 }))
}

/// Splits in a row after which a child still holds all its parent's faces
/// before a cell is left as it is.
const MAX_STALLED: u8 = 2;

/// A split after which the children hold this many times their parent's
/// faces in all made no progress.
const STALL_SHARE: usize = 3;

/// Pairs of leaves that share a piece of wall with an area: their boxes
/// touch along one axis (`hi + 1 == lo`) and their ranges overlap along the
/// two others. The leaves tile space without overlap, so for each wall
/// coordinate a sweep finds the pairs in `O(n log n)` plus their number.
pub(crate) fn adjacent(leaves: &[Leaf]) -> Vec<(u32, u32)> {
    // the boxes side by side (a leaf is large), read at random below
    let boxes: Vec<IBox> = leaves.iter().map(|l| l.bx).collect();
    // (coordinate, a small field, leaf) packed in one integer that sorts
    // as the tuple would (the coordinate's sign bit flipped)
    let key = |c: i64, small: u64, i: usize| -> u128 {
        (((c as u64) ^ (1 << 63)) as u128) << 64 | (small << 32 | i as u64) as u128
    };
    let coordinate = |key: u128| (key >> 64) as u64;
    let side = |key: u128| (key >> 32) as u8 & 1;
    let leaf = |key: u128| key as u32;
    // the three axes in parallel, joined in order
    let per_axis: Vec<Vec<(u32, u32)>> = par::map(3, |k| {
        let mut out = Vec::new();
        let (u, v) = ((k + 1) % 3, (k + 2) % 3);
        // (wall coordinate, side, leaf): side 0 below the wall, 1 above
        let mut by_wall: Vec<u128> = Vec::with_capacity(2 * boxes.len());
        for (i, b) in boxes.iter().enumerate() {
            by_wall.push(key(b.1[k], 0, i));
            by_wall.push(key(b.0[k] - 1, 1, i));
        }
        by_wall.sort_unstable();
        // (u coordinate, kind, side, leaf): removals (kind 0) before
        // insertions (1) at a coordinate
        let mut events: Vec<u128> = Vec::new();
        // the leaves of each side the sweep line crosses, by their
        // lower v: (lower v, upper v, leaf); their v ranges are
        // disjoint (few at a time: sorted lists)
        let mut active: [Vec<(i64, i64, u32)>; 2] = [Vec::new(), Vec::new()];
        for group in by_wall.chunk_by(|x, y| coordinate(*x) == coordinate(*y)) {
            if side(group[0]) == side(group[group.len() - 1]) {
                continue; // leaves on one side of this wall only
            }
            // sweep along u
            events.clear();
            for &g in group {
                let (i, s) = (leaf(g) as usize, side(g) as u64);
                let b = &boxes[i];
                events.push(key(b.0[u], 2 | s, i));
                events.push(key(b.1[u] + 1, s, i));
            }
            events.sort_unstable();
            for &e in &events {
                let i = leaf(e);
                let b = &boxes[i as usize];
                let (s, insert) = (side(e) as usize, (e >> 33) & 1 == 1);
                let at = active[s].partition_point(|x| x.0 < b.0[v]);
                if !insert {
                    active[s].remove(at);
                    continue;
                }
                let other = &active[1 - s];
                // the other side's leaves whose v range meets [lo, hi]:
                // the last starting below lo (if it reaches lo), then
                // those starting in [lo, hi]
                let from = other.partition_point(|x| x.0 < b.0[v]);
                let to = from + other[from..].partition_point(|x| x.0 <= b.1[v]);
                let before = from.checked_sub(1).filter(|&p| other[p].1 >= b.0[v]);
                for p in before.into_iter().chain(from..to) {
                    let j = other[p].2;
                    out.push(if s == 0 { (i, j) } else { (j, i) });
                }
                active[s].insert(at, (b.0[v], b.1[v], i));
            }
        }
        out
    });
    per_axis.concat()
}

#[cfg(test)]
mod tests {
    use super::*;
    use bsp_core::Side;

    #[test]
    fn walls_hold_no_grid_point_and_bound_the_cell() {
        let bx = ([0, -3, 5], [2, 4, 5]);
        for w in walls(&bx) {
            for p in [[0, -3, 5], [2, 4, 5], [1, 0, 5]] {
                assert_eq!(w.classify_grid(p), Side::Back, "{w:?} {p:?}");
            }
            for p in [[3, 0, 5], [-1, 0, 5], [0, 5, 5], [0, 0, 6], [0, 0, 4]] {
                let s = w.classify_grid(p);
                assert_ne!(s, Side::On);
            }
        }
        assert!(
            walls(&bx)
                .iter()
                .any(|w| w.classify_grid([3, 0, 5]) == Side::Front)
        );
    }

    /// The plane meets the closed box exactly when its value at the
    /// box's eight corners (half a step outside the grid points, doubled
    /// here) is not of one strict sign: random planes near and through
    /// random boxes, large coefficients, both orientations.
    #[test]
    fn plane_meets_the_box_as_its_corners_say() {
        let mut x = 0x2545_f491_4f6c_dd1du64;
        let mut next = move |m: i64| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 2) as i64 % m
        };
        let mut seen = [0usize; 2];
        for i in 0..20_000 {
            let lo = [0, 1, 2].map(|_| next(1 << 30) - (1 << 29));
            let hi = [0, 1, 2].map(|k| lo[k] + next(1 << (4 + i % 20)));
            let scale = 1i64 << (i % 30);
            let n = [0, 1, 2].map(|_| (next(2001) - 1000) * scale);
            if n == [0; 3] {
                continue;
            }
            // through a point near the box, moved off by a little
            let p = [0, 1, 2].map(|k| (lo[k] + hi[k]) / 2 + next(1 << (4 + i % 20)));
            let d =
                -(0..3).map(|k| n[k] as i128 * p[k] as i128).sum::<i128>() + next(3) as i128 - 1;
            let Some(pl) = Plane::new(n, d) else {
                continue;
            };
            let (pn, pd) = (pl.normal(), pl.offset());
            let values = (0..8).map(|c: usize| {
                let v = |k: usize| {
                    if c >> k & 1 == 0 {
                        2 * lo[k] as i128 - 1
                    } else {
                        2 * hi[k] as i128 + 1
                    }
                };
                2 * pd + (0..3).map(|k| pn[k] as i128 * v(k)).sum::<i128>()
            });
            let want = values.clone().any(|v| v <= 0) && values.clone().any(|v| v >= 0);
            assert_eq!(plane_meets(&pl, &(lo, hi)), want, "{pl:?} {lo:?} {hi:?}");
            seen[want as usize] += 1;
        }
        assert!(seen[0] > 1000 && seen[1] > 1000, "{seen:?}");
    }

    #[test]
    fn leaves_tile_the_domain_and_adjacency_is_found() {
        // eight faces of each operand packed in one corner: the cell splits
        let boxes: Vec<SmallBox> = (0..8).map(|i| ([i, 0, 0], [i, 1, 1])).collect();
        let faces = Faces {
            boxes: &boxes,
            plane_meets: |_, _: &IBox| true,
        };
        let leaves = build(([0, 0, 0], [15, 15, 15]), &faces, &faces, 4, &|_| false);
        let volume: i64 = leaves
            .iter()
            .map(|l| (0..3).map(|k| l.bx.1[k] - l.bx.0[k] + 1).product::<i64>())
            .sum();
        assert_eq!(volume, 16 * 16 * 16);
        assert!(leaves.len() > 8);
        let adj = adjacent(&leaves);
        // every leaf touches another
        for i in 0..leaves.len() as u32 {
            assert!(adj.iter().any(|&(p, q)| p == i || q == i));
        }
    }
}
