//! Exact triangles of a non-convex planar face: its loop of grid points
//! split where it meets itself at a corner, each part checked simple and
//! ear-clipped, every decision an exact `i128` orientation in the face's
//! projection along its dominant axis.
//!
//! A loop of [`BUCKETED`] corners or more is not searched pair by pair:
//! whether two of its edges meet is found by a sweep (Shamos and Hoey:
//! the first place where two edges meet lies between edges next to each
//! other along the sweep line, so each edge is tested against its
//! neighbours there, `O(n log n)` whatever the edges' lengths), and its
//! ears through buckets (a uniform grid of cells over the loop's box, each
//! listing the corners that may lie in it). Both answer as the pairwise
//! searches do, triangle for triangle.

use std::cell::Cell;
use std::cmp::Ordering;
use std::collections::BTreeSet;
use std::ops::Bound;

use rustc_hash::FxHashMap;

use crate::kernel::grid::GridPoint;
use crate::kernel::plane::Plane;

/// Loops of at least this many corners are searched through buckets;
/// smaller ones pair by pair.
const BUCKETED: usize = 64;

/// The most cells an item of [`Buckets`] may fill on average.
const MAX_CELLS_AN_ITEM: usize = 16;

/// Triangles that tile the planar loop `v` exactly, counter-clockwise in
/// `proj`: the loop split at a corner it meets twice and each part tiled
/// (a part turning the other way, a hole pinched off, cannot be); a loop
/// of distinct corners only if it is simple (no two edges but neighbours
/// meet), by ear clipping, checked (every triangle turns the loop's way
/// and their areas add up to its area). The parts must not overlap (a
/// loop that goes round twice, or a lobe inside another, covers some
/// points twice: no triangles tile it once). The parts wait on a list,
/// not on the stack: a loop may meet itself at thousands of corners.
pub(super) fn tile(v: &[GridPoint], proj: &Projection) -> Option<Vec<[GridPoint; 3]>> {
    let mut out = Vec::new();
    // where each part's triangles start in `out`
    let mut starts = Vec::new();
    let mut parts = vec![v.to_vec()];
    while let Some(v) = parts.pop() {
        if let Some((i, j)) = first_repeat(&v) {
            // the part inside the repeated corner first, then the rest
            parts.push(v[j..].iter().chain(&v[..i]).copied().collect());
            parts.push(v[i..j].to_vec());
            continue;
        }
        // corners all distinct: simple unless two edges not next to each
        // other meet
        let area = proj.area2(&v);
        if area <= 0 || !proj.simple(&v) {
            return None;
        }
        let t = ear_clip(&v, proj)?;
        if t.iter().map(|t| proj.area2(t)).sum::<i128>() != area {
            return None;
        }
        starts.push(out.len());
        out.extend(t);
    }
    if starts.len() > 1 && parts_overlap(&out, &starts, proj) {
        return None;
    }
    Some(out)
}

/// Whether triangles of different parts (`starts`: where each part's
/// triangles begin in `tris`) share an inner point: exactly, two triangles with area
/// are apart when the line of an edge of one has the other on its outer
/// side or on it (convex sets are apart when some edge's line separates
/// them). Triangles are visited in order of their least `x`, each against
/// those that begin before it ends.
fn parts_overlap(tris: &[[GridPoint; 3]], starts: &[usize], proj: &Projection) -> bool {
    let part_of = |i: usize| starts.partition_point(|&s| s <= i);
    let xy: Vec<[Xy; 3]> = tris.iter().map(|t| t.map(|p| proj.xy(p))).collect();
    let mut order: Vec<usize> = (0..tris.len())
        .filter(|&i| turn(xy[i][0], xy[i][1], xy[i][2]) != 0)
        .collect();
    // each triangle's box, once: (least x, most x, least y, most y)
    let boxes: Vec<[i128; 4]> = (xy.iter())
        .map(|t| {
            let (xs, ys) = (t.map(|p| p.0), t.map(|p| p.1));
            let lo = |v: [i128; 3]| v[0].min(v[1]).min(v[2]);
            let hi = |v: [i128; 3]| v[0].max(v[1]).max(v[2]);
            [lo(xs), hi(xs), lo(ys), hi(ys)]
        })
        .collect();
    order.sort_unstable_by_key(|&i| boxes[i][0]);
    // (a triangle kept counter-clockwise; an edge's line separates when
    // every corner of the other lies on it or to its right)
    let ccw = |i: usize| match turn(xy[i][0], xy[i][1], xy[i][2]) > 0 {
        true => xy[i],
        false => [xy[i][0], xy[i][2], xy[i][1]],
    };
    let separates = |a: [Xy; 3], b: [Xy; 3]| {
        (0..3).any(|k| b.iter().all(|&p| turn(a[k], a[(k + 1) % 3], p) <= 0))
    };
    order.iter().enumerate().any(|(k, &i)| {
        let [_, x1, y0, y1] = boxes[i];
        order[k + 1..]
            .iter()
            .take_while(|&&j| boxes[j][0] < x1)
            .any(|&j| {
                let [_, _, b0, b1] = boxes[j];
                part_of(i) != part_of(j) && b0 < y1 && y0 < b1 && {
                    let (a, b) = (ccw(i), ccw(j));
                    !separates(a, b) && !separates(b, a)
                }
            })
    })
}

/// The first corner of `v` that it meets again, and where it first does.
fn first_repeat(v: &[GridPoint]) -> Option<(usize, usize)> {
    if v.len() < BUCKETED {
        return (0..v.len()).find_map(|i| Some((i, (i + 1..v.len()).find(|&j| v[j] == v[i])?)));
    }
    // the first repeated corner is a first occurrence, and its first
    // repeat the first one met after it
    let mut first: FxHashMap<GridPoint, usize> = FxHashMap::default();
    first.reserve(v.len());
    let mut found: Option<(usize, usize)> = None;
    for (k, p) in v.iter().enumerate() {
        match first.get(p) {
            Some(&i) => {
                if found.is_none_or(|(f, _)| i < f) {
                    found = Some((i, k));
                }
            }
            None => {
                first.insert(*p, k);
            }
        }
    }
    found
}

/// A plane's loops seen along its dominant axis, counter-clockwise about
/// its normal: exact `i128` orientation and area.
pub(super) struct Projection {
    a: usize,
    b: usize,
}

/// A point of a projected loop.
type Xy = (i128, i128);

impl Projection {
    pub(super) fn of(plane: &Plane) -> Projection {
        let ax = plane.dominant_axis();
        let (a, b) = if plane.normal()[ax] > 0 {
            ((ax + 1) % 3, (ax + 2) % 3)
        } else {
            ((ax + 2) % 3, (ax + 1) % 3)
        };
        Projection { a, b }
    }

    fn xy(&self, p: GridPoint) -> Xy {
        (i128::from(p[self.a]), i128::from(p[self.b]))
    }

    /// The sign of the turn `p, q, r`.
    fn orient(&self, p: GridPoint, q: GridPoint, r: GridPoint) -> i128 {
        turn(self.xy(p), self.xy(q), self.xy(r))
    }

    /// Whether segments `p`–`q` and `r`–`s` share a point.
    fn meet(&self, (p, q): (GridPoint, GridPoint), (r, s): (GridPoint, GridPoint)) -> bool {
        meet((self.xy(p), self.xy(q)), (self.xy(r), self.xy(s)))
    }

    /// Whether the loop's edges meet only their neighbours, at their
    /// shared corners.
    fn simple(&self, v: &[GridPoint]) -> bool {
        let n = v.len();
        let edge = |i: usize| (v[i], v[(i + 1) % n]);
        // (edges `i < j` next to each other: `j = i + 1`, and the last
        // with the first)
        let apart = |i: usize, j: usize| j > i + 1 && !(i == 0 && j == n - 1);
        if n < BUCKETED {
            return (0..n)
                .all(|i| (i + 2..n).all(|j| !apart(i, j) || !self.meet(edge(i), edge(j))));
        }
        let xy: Vec<Xy> = v.iter().map(|&p| self.xy(p)).collect();
        !Sweep::new(&xy).meets()
    }

    /// Twice the loop's signed area (positive: counter-clockwise).
    fn area2(&self, v: &[GridPoint]) -> i128 {
        (0..v.len())
            .map(|i| {
                let (p, q) = (self.xy(v[i]), self.xy(v[(i + 1) % v.len()]));
                p.0 * q.1 - q.0 * p.1
            })
            .sum()
    }
}

/// The sign of the turn `p, q, r`.
fn turn(p: Xy, q: Xy, r: Xy) -> i128 {
    ((q.0 - p.0) * (r.1 - p.1) - (q.1 - p.1) * (r.0 - p.0)).signum()
}

/// Whether segments `p`–`q` and `r`–`s` share a point.
fn meet((p, q): (Xy, Xy), (r, s): (Xy, Xy)) -> bool {
    let (d1, d2) = (turn(p, q, r), turn(p, q, s));
    let (d3, d4) = (turn(r, s, p), turn(r, s, q));
    if d1 == 0 && d2 == 0 {
        // on one line: do their extents overlap?
        let within =
            |lo: i128, hi: i128, a: i128, b: i128| lo.min(hi) <= a.max(b) && a.min(b) <= lo.max(hi);
        return within(p.0, q.0, r.0, s.0) && within(p.1, q.1, r.1, s.1);
    }
    d1 * d2 <= 0 && d3 * d4 <= 0
}

/// The sweep over a loop's edges (Shamos and Hoey): a line sweeps the
/// plane in the order of points by `x`, then `y` (a vertical edge is met
/// from its lower end up), holding the edges it crosses in their order
/// along it, below to above; two edges are tested when they become
/// neighbours there. Until the first place where two edges meet, the order
/// does not change between events (the edges' ends), so the ordered set
/// stays valid; and the two edges that meet first are neighbours just
/// before that place, so they are tested.
struct Sweep {
    /// Each edge's ends, the lower first (by `x`, then `y`).
    edges: Vec<(Xy, Xy)>,
    loop_len: usize,
    /// The event being handled, and whether the order asked for is the
    /// one just after it (edges starting there) or just before (edges
    /// ending there).
    at: Cell<(Xy, bool)>,
}

/// An edge in the sweep's ordered set: compared along the sweep line.
struct Crossing<'s> {
    edge: u32,
    sweep: &'s Sweep,
}

impl Sweep {
    /// The sweep of the loop `xy`: distinct corners, at least three.
    fn new(xy: &[Xy]) -> Sweep {
        let n = xy.len();
        let edges = (0..n)
            .map(|i| {
                let (p, q) = (xy[i], xy[(i + 1) % n]);
                if p <= q { (p, q) } else { (q, p) }
            })
            .collect();
        Sweep {
            edges,
            loop_len: n,
            at: Cell::new(((0, 0), false)),
        }
    }

    /// Where edge `e` crosses the sweep line through the event: its `y`
    /// as a fraction (positive denominator); a vertical edge at the event
    /// itself, kept within its ends.
    fn y_at(&self, e: u32) -> (i128, i128) {
        let ((lo, hi), (x, y)) = (self.edges[e as usize], self.at.get().0);
        let dx = hi.0 - lo.0;
        if dx == 0 {
            return (y.clamp(lo.1, hi.1), 1);
        }
        (lo.1 * dx + (hi.1 - lo.1) * (x - lo.0), dx)
    }

    /// Edge `e`'s direction, from its lower end (`dx >= 0`, and `dy > 0`
    /// where `dx = 0`).
    fn slope(&self, e: u32) -> Xy {
        let (lo, hi) = self.edges[e as usize];
        (hi.0 - lo.0, hi.1 - lo.1)
    }

    /// The order of edges `a` and `b` along the sweep line, below first:
    /// where they cross it, then (crossing it at one point, the event)
    /// by their slopes just after the event or just before it, then by
    /// their numbers (edges on one line).
    fn order(&self, a: u32, b: u32) -> Ordering {
        if a == b {
            return Ordering::Equal;
        }
        let ((ya, da), (yb, db)) = (self.y_at(a), self.y_at(b));
        let ((ax, ay), (bx, by)) = (self.slope(a), self.slope(b));
        // (a vertical edge, `dx = 0` and `dy > 0`, is steeper than all)
        let slopes = (ay * bx).cmp(&(by * ax));
        // where they cross the sweep line at one point, their order is the
        // one just after it if the sweep has passed it (below the event,
        // on its vertical), just before it if not (above), and at the
        // event as asked
        let ((_, y), after) = self.at.get();
        let after = match ya.cmp(&(y * da)) {
            Ordering::Less => true,
            Ordering::Greater => false,
            Ordering::Equal => after,
        };
        (ya * db)
            .cmp(&(yb * da))
            .then(if after { slopes } else { slopes.reverse() })
            .then(a.cmp(&b))
    }

    /// Whether edges `a` and `b` lie on one line where the sweep line
    /// crosses them: they overlap there (for a corner's two edges, one
    /// holds the other: a spike).
    fn tied(&self, a: u32, b: u32) -> bool {
        let ((ya, da), (yb, db)) = (self.y_at(a), self.y_at(b));
        let ((ax, ay), (bx, by)) = (self.slope(a), self.slope(b));
        ya * db == yb * da && ay * bx == by * ax
    }

    /// The edges one way along the sweep line from edge `e` that `e`
    /// must be tested against: the next one, and after it, while an edge
    /// lies on one line with the one before it, the edges of that run and
    /// the first one past it (overlapping edges, such as a spike's two,
    /// must not hide what lies beyond them).
    fn run(&self, e: u32, edges: impl Iterator<Item = u32>) -> Vec<u32> {
        let mut out = Vec::new();
        let (mut last, mut last_tied) = (e, false);
        for o in edges {
            let tied = self.tied(last, o);
            if !out.is_empty() && !last_tied && !tied {
                break;
            }
            out.push(o);
            (last, last_tied) = (o, tied);
        }
        out
    }

    /// Whether edges `a` and `b` meet, unless they are the loop's
    /// neighbours (which share a corner).
    fn meet(&self, a: u32, b: u32) -> bool {
        let n = self.loop_len as u32;
        let neighbours = a.abs_diff(b) == 1 || a.abs_diff(b) == n - 1;
        !neighbours && meet(self.edges[a as usize], self.edges[b as usize])
    }

    /// Whether any two edges of the loop that are not neighbours meet.
    fn meets(&self) -> bool {
        // the events: each edge's lower end (it enters) and upper end (it
        // leaves); at one point, the edges that leave first
        let mut events: Vec<(Xy, bool, u32)> = (0..self.edges.len() as u32)
            .flat_map(|e| {
                let (lo, hi) = self.edges[e as usize];
                [(lo, true, e), (hi, false, e)]
            })
            .collect();
        events.sort_unstable();
        let key = |edge: u32| Crossing { edge, sweep: self };
        // (the keys compare by the sweep's position, which moves; the
        // order of the edges on the line does not, until two meet)
        #[allow(clippy::mutable_key_type)]
        let mut line: BTreeSet<Crossing<'_>> = BTreeSet::new();
        for &(p, enters, e) in &events {
            self.at.set((p, enters));
            // the neighbours on each side, with the edges that overlap
            // them (a spike's shorter edge must not hide its longer one)
            let below = self.run(e, line.range(..key(e)).rev().map(|c| c.edge));
            let after = line.range((Bound::Excluded(key(e)), Bound::Unbounded));
            let above = self.run(e, after.map(|c| c.edge));
            if enters {
                line.insert(key(e));
                if below.iter().chain(&above).any(|&o| self.meet(e, o)) {
                    return true;
                }
            } else {
                line.remove(&key(e));
                if below
                    .iter()
                    .any(|&b| above.iter().any(|&a| self.meet(b, a)))
                {
                    return true;
                }
            }
        }
        false
    }
}

impl PartialEq for Crossing<'_> {
    fn eq(&self, o: &Self) -> bool {
        self.edge == o.edge
    }
}

impl Eq for Crossing<'_> {}

impl PartialOrd for Crossing<'_> {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

impl Ord for Crossing<'_> {
    fn cmp(&self, o: &Self) -> Ordering {
        self.sweep.order(self.edge, o.edge)
    }
}

/// A uniform grid of about as many square-ish cells as items over the
/// items' boxes, each cell listing (in order) the items whose box meets
/// it; none where the boxes would fill more than [`MAX_CELLS_AN_ITEM`]
/// cells an item on average (long edges across the loop: the pairs are
/// then searched pairwise).
struct Buckets {
    lo: Xy,
    size: Xy,
    side: usize,
    /// Where each cell's items start in `items` (one more: the end).
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Buckets {
    fn new(boxes: Vec<(Xy, Xy)>) -> Option<Buckets> {
        let lo = boxes.iter().fold((i128::MAX, i128::MAX), |l, b| {
            (l.0.min(b.0.0), l.1.min(b.0.1))
        });
        let hi = boxes.iter().fold((i128::MIN, i128::MIN), |h, b| {
            (h.0.max(b.1.0), h.1.max(b.1.1))
        });
        let side = ((boxes.len() as f64).sqrt().ceil() as usize).max(1);
        let size = (
            (hi.0 - lo.0) / side as i128 + 1,
            (hi.1 - lo.1) / side as i128 + 1,
        );
        let mut cells = Buckets {
            lo,
            size,
            side,
            start: vec![0; side * side + 1],
            items: Vec::new(),
        };
        // a counting sort: how many a cell, where each starts, the items
        for &(l, h) in &boxes {
            let (xs, ys) = cells.span(l, h);
            for y in ys {
                for x in xs.clone() {
                    cells.start[y * side + x + 1] += 1;
                }
            }
        }
        for c in 0..side * side {
            cells.start[c + 1] += cells.start[c];
        }
        if cells.start[side * side] as usize > MAX_CELLS_AN_ITEM * boxes.len() {
            return None;
        }
        let mut at: Vec<u32> = cells.start[..side * side].to_vec();
        cells.items = vec![0; cells.start[side * side] as usize];
        for (i, &(l, h)) in boxes.iter().enumerate() {
            let (xs, ys) = cells.span(l, h);
            for y in ys {
                for x in xs.clone() {
                    let c = &mut at[y * side + x];
                    cells.items[*c as usize] = i as u32;
                    *c += 1;
                }
            }
        }
        Some(cells)
    }

    /// The columns and rows of the cells that the box `l`–`h` meets.
    fn span(
        &self,
        l: Xy,
        h: Xy,
    ) -> (
        std::ops::RangeInclusive<usize>,
        std::ops::RangeInclusive<usize>,
    ) {
        let col = |t: i128| (((t - self.lo.0).max(0) / self.size.0) as usize).min(self.side - 1);
        let row = |t: i128| (((t - self.lo.1).max(0) / self.size.1) as usize).min(self.side - 1);
        (col(l.0)..=col(h.0), row(l.1)..=row(h.1))
    }

    fn cell(&self, c: usize) -> &[u32] {
        &self.items[self.start[c] as usize..self.start[c + 1] as usize]
    }

    /// The cells that may hold a lattice point of triangle `t`: row by
    /// row, the columns of the triangle's extent in the row's band, its
    /// ends rounded inward to the lattice exactly (the integer ceiling and
    /// floor of where the edges cross the band's lines).
    fn under_triangle(&self, t: [Xy; 3], mut each: impl FnMut(usize) -> bool) -> bool {
        let l = (
            t.iter().map(|p| p.0).min().unwrap_or(0),
            t.iter().map(|p| p.1).min().unwrap_or(0),
        );
        let h = (
            t.iter().map(|p| p.0).max().unwrap_or(0),
            t.iter().map(|p| p.1).max().unwrap_or(0),
        );
        let (xs, ys) = self.span(l, h);
        for y in ys {
            // the band's rows of points, within the triangle's
            let y0 = (self.lo.1 + y as i128 * self.size.1).max(l.1);
            let y1 = (self.lo.1 + (y as i128 + 1) * self.size.1 - 1).min(h.1);
            // (the band's part of the triangle has its corners where the
            // edges cross the band's lines, or at the triangle's own)
            let (mut x0, mut x1) = (i128::MAX, i128::MIN);
            for k in 0..3 {
                let (p, q) = (t[k], t[(k + 1) % 3]);
                let (ylo, yhi) = (p.1.min(q.1), p.1.max(q.1));
                if yhi < y0 || ylo > y1 {
                    continue;
                }
                if q.1 == p.1 {
                    (x0, x1) = (x0.min(p.0.min(q.0)), x1.max(p.0.max(q.0)));
                    continue;
                }
                for y in [y0.max(ylo), y1.min(yhi)] {
                    // x = p.x + (y - p.y)(q.x - p.x) / (q.y - p.y): the
                    // lattice points on the band's side of it lie from its
                    // ceiling (at the left end) to its floor (at the right)
                    let (num, den) = ((y - p.1) * (q.0 - p.0), q.1 - p.1);
                    let (num, den) = if den < 0 { (-num, -den) } else { (num, den) };
                    let floor = p.0 + num.div_euclid(den);
                    let ceil = floor + i128::from(num.rem_euclid(den) != 0);
                    (x0, x1) = (x0.min(ceil), x1.max(floor));
                }
            }
            if x0 > x1 {
                continue;
            }
            let (first, last) = (self.span((x0, y0), (x1, y0)).0).into_inner();
            let (first, last) = (first.max(*xs.start()), last.min(*xs.end()));
            for x in first..=last {
                if !each(y * self.side + x) {
                    return false;
                }
            }
        }
        true
    }
}

/// Exact ear clipping of a planar loop, counter-clockwise in `proj`: the
/// first corner (in the loop's order, from its first remaining corner)
/// that turns the loop's way and whose triangle holds no other remaining
/// corner, again and again.
fn ear_clip(v: &[GridPoint], proj: &Projection) -> Option<Vec<[GridPoint; 3]>> {
    let orient = |p, q, r| proj.orient(p, q, r);
    let n = v.len();
    if n < 3 {
        return None;
    }
    let xy: Vec<Xy> = v.iter().map(|&p| proj.xy(p)).collect();
    // (a point fills one cell)
    let cells = (n >= BUCKETED)
        .then(|| Buckets::new(xy.iter().map(|&p| (p, p)).collect()))
        .flatten();
    // the remaining corners, a ring
    let mut next: Vec<usize> = (1..=n).map(|i| i % n).collect();
    let mut prev: Vec<usize> = (0..n).map(|i| (i + n - 1) % n).collect();
    let mut gone = vec![false; n];
    let (mut head, mut m) = (0, n);
    let mut tris = Vec::with_capacity(n);
    let inside = |gone: &[bool], j: usize, (pa, pb, pc): (GridPoint, GridPoint, GridPoint)| {
        let p = v[j];
        !gone[j]
            && p != pa
            && p != pb
            && p != pc
            && orient(pa, pb, p) >= 0
            && orient(pb, pc, p) >= 0
            && orient(pc, pa, p) >= 0
    };
    while m > 3 {
        let mut i = head;
        let mut found = None;
        for _ in 0..m {
            let (a, c) = (prev[i], next[i]);
            let ear = (v[a], v[i], v[c]);
            if orient(ear.0, ear.1, ear.2) > 0 {
                let clear = match &cells {
                    None => (0..n).all(|j| !inside(&gone, j, ear)),
                    Some(cells) => cells.under_triangle([xy[a], xy[i], xy[c]], |cell| {
                        cells
                            .cell(cell)
                            .iter()
                            .all(|&j| !inside(&gone, j as usize, ear))
                    }),
                };
                if clear {
                    found = Some(i);
                    break;
                }
            }
            i = next[i];
        }
        let i = found?;
        let (a, c) = (prev[i], next[i]);
        tris.push([v[a], v[i], v[c]]);
        (next[a], prev[c], gone[i]) = (c, a, true);
        if head == i {
            head = c;
        }
        m -= 1;
    }
    tris.push([v[head], v[next[head]], v[next[next[head]]]]);
    // every triangle must keep the loop's orientation
    tris.iter()
        .all(|t| orient(t[0], t[1], t[2]) >= 0)
        .then_some(tris)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The pairwise searches, as they were before the buckets: the
    /// oracle of the bucketed ones.
    fn simple_pairwise(proj: &Projection, v: &[GridPoint]) -> bool {
        let n = v.len();
        let edge = |i: usize| (v[i], v[(i + 1) % n]);
        (0..n).all(|i| {
            (i + 2..n)
                .filter(|&j| (j + 1) % n != i)
                .all(|j| !proj.meet(edge(i), edge(j)))
        })
    }

    fn ear_clip_pairwise(v: &[GridPoint], proj: &Projection) -> Option<Vec<[GridPoint; 3]>> {
        let orient = |p, q, r| proj.orient(p, q, r);
        let mut idx: Vec<usize> = (0..v.len()).collect();
        let mut tris = Vec::new();
        while idx.len() > 3 {
            let m = idx.len();
            let i = (0..m).find(|&i| {
                let (pa, pb, pc) = (v[idx[(i + m - 1) % m]], v[idx[i]], v[idx[(i + 1) % m]]);
                orient(pa, pb, pc) > 0
                    && !idx.iter().any(|&j| {
                        let p = v[j];
                        p != pa
                            && p != pb
                            && p != pc
                            && orient(pa, pb, p) >= 0
                            && orient(pb, pc, p) >= 0
                            && orient(pc, pa, p) >= 0
                    })
            })?;
            tris.push([v[idx[(i + m - 1) % m]], v[idx[i]], v[idx[(i + 1) % m]]]);
            idx.remove(i);
        }
        tris.push([v[idx[0]], v[idx[1]], v[idx[2]]]);
        tris.iter()
            .all(|t| orient(t[0], t[1], t[2]) >= 0)
            .then_some(tris)
    }

    const XY: Projection = Projection { a: 0, b: 1 };

    /// Loops of 64 to 300 corners on small lattices (collinear corners,
    /// touching and crossing edges, spikes, long and short edges), star
    /// shaped ones (mostly simple), and random walks (mostly not): the
    /// bucketed searches answer as the pairwise ones, triangle for
    /// triangle.
    #[test]
    fn buckets_answer_as_the_pairwise_search() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = |m: u64| crate::xorshift(&mut seed) % m;
        let (mut simple, mut clipped, mut crossed) = (0, 0, 0);
        for round in 0..1_200 {
            let n = 64 + next(240) as usize;
            let spread = [4, 50, 1 << 20][round % 3];
            let star = |next: &mut dyn FnMut(u64) -> u64| -> Vec<GridPoint> {
                (0..n)
                    .map(|k| {
                        let a = std::f64::consts::TAU * k as f64 / n as f64;
                        let r = (spread + next(spread)) as f64;
                        [
                            (r * a.cos()).round() as i32,
                            (r * a.sin()).round() as i32,
                            0,
                        ]
                    })
                    .collect()
            };
            let mut v: Vec<GridPoint> = match round % 4 {
                // a star: corners in angle order at random radii
                0 | 1 => star(&mut next),
                // the same with two neighbours swapped: one crossing
                // (mostly), anywhere
                2 => {
                    let mut v = star(&mut next);
                    let k = next(n as u64 - 1) as usize;
                    v.swap(k, k + 1);
                    v
                }
                // a random walk
                _ => (0..n)
                    .map(|_| [next(spread) as i32, next(spread) as i32, 0])
                    .collect(),
            };
            v.dedup();
            if v.len() < BUCKETED || first_repeat(&v).is_some() {
                assert_eq!(
                    first_repeat(&v),
                    (0..v.len()).find_map(|i| Some((i, (i + 1..v.len()).find(|&j| v[j] == v[i])?)))
                );
                continue;
            }
            let s = XY.simple(&v);
            assert_eq!(s, simple_pairwise(&XY, &v), "round {round}");
            crossed += usize::from(!s && round % 4 == 2);
            if s && XY.area2(&v) > 0 {
                simple += 1;
                let t = ear_clip(&v, &XY);
                assert_eq!(t, ear_clip_pairwise(&v, &XY), "round {round}");
                clipped += usize::from(t.is_some());
            }
        }
        assert!(
            simple > 100 && clipped > 100 && crossed > 40,
            "{simple} simple, {clipped} clipped, {crossed} crossed once"
        );
    }

    /// The sweep answers as the pairwise search on loops of distinct
    /// corners of tiny lattices, where edges are vertical, collinear,
    /// overlapping and touching everywhere: random corners in random order
    /// (mostly crossing) and in the order of their angle about their
    /// centre (mostly simple), some with a corner moved; on lattices
    /// spread to the grid's range too.
    #[test]
    fn the_sweep_answers_as_the_pairwise_search() {
        let mut seed = 0x6a09_e667_f3bc_c908u64;
        let mut next = |m: u64| crate::xorshift(&mut seed) % m;
        let (mut simple, mut not) = (0, 0);
        for round in 0..20_000 {
            let spread = 2 + next(6) as i32;
            let mut lattice: Vec<GridPoint> = (0..spread * spread)
                .map(|k| [k % spread, k / spread, 0])
                .collect();
            for i in (1..lattice.len()).rev() {
                lattice.swap(i, next(i as u64 + 1) as usize);
            }
            let k = 4 + next((lattice.len() as u64 - 3).min(40)) as usize;
            let mut v = lattice[..k].to_vec();
            if round % 2 == 0 {
                let c = v
                    .iter()
                    .fold([0.0, 0.0], |c, p| [c[0] + p[0] as f64, c[1] + p[1] as f64]);
                let angle = |p: &GridPoint| {
                    (p[1] as f64 - c[1] / k as f64).atan2(p[0] as f64 - c[0] / k as f64)
                };
                v.sort_by(|a, b| angle(a).total_cmp(&angle(b)));
                if round % 4 == 2 {
                    // a corner moved to a free lattice point
                    let i = next(k as u64) as usize;
                    v[i] = lattice[k + next((lattice.len() - k).max(1) as u64) as usize
                        % (lattice.len() - k).max(1)..]
                        .first()
                        .copied()
                        .unwrap_or(v[i]);
                }
            }
            if round % 3 == 0 {
                let s = 1 << (next(20) as i32);
                v.iter_mut()
                    .for_each(|p| *p = [p[0] * s - (1 << 25), p[1] * s + 7, 0]);
            }
            if first_repeat(&v).is_some() {
                continue;
            }
            let xy: Vec<Xy> = v.iter().map(|&p| XY.xy(p)).collect();
            let swept = !Sweep::new(&xy).meets();
            assert_eq!(swept, simple_pairwise(&XY, &v), "round {round}: {v:?}");
            (simple, not) = (simple + usize::from(swept), not + usize::from(!swept));
        }
        assert!(simple > 3_000 && not > 3_000, "{simple} simple, {not} not");
    }

    /// A loop pinched at a corner into lobes side by side is tiled; one
    /// that goes round twice, or has a lobe inside another, covers points
    /// twice and is not (a face `1 2 3 1 2 3` made the shadows' merge
    /// meet overlapping cells; a lobe inside counted its area twice).
    #[test]
    fn overlapping_lobes_are_not_tiled() {
        let (a, b, c) = ([0, 0, 0], [4, 0, 0], [0, 4, 0]);
        assert!(tile(&[a, b, c, a, b, c], &XY).is_none());
        assert!(tile(&[a, b, c, a, [2, 1, 0], [1, 2, 0]], &XY).is_none());
        // a lobe beside, touching at the corner, and one touching along
        // part of an edge from outside (apart inside: tiled)
        let beside = tile(&[a, b, c, a, [-1, -2, 0], [1, -3, 0]], &XY).unwrap();
        assert_eq!(beside.len(), 2);
        let below = tile(&[a, b, c, a, [1, -2, 0], [4, -2, 0], [2, 0, 0]], &XY).unwrap();
        assert_eq!(below.len(), 3);
        let apart = tile(&[a, b, c, a, [-1, -1, 0], [0, -4, 0], [1, -1, 0]], &XY).unwrap();
        assert_eq!(apart.len(), 3);
        // pinched many times: a row of lobes along a line
        let mut row = Vec::new();
        for k in 0..50 {
            row.extend([[4 * k, 0, 0], [4 * k + 2, -1, 0]]);
        }
        row.push([200, 0, 0]);
        for k in (0..50).rev() {
            row.extend([[4 * k + 2, 1, 0]]);
            if k > 0 {
                row.push([4 * k, 0, 0]);
            }
        }
        assert_eq!(tile(&row, &XY).map(|t| t.len()), Some(100));
    }

    /// `n` corners about the origin in angle order, corner `k` at radius
    /// `radius(k)`, snapped to the grid.
    fn ring(n: usize, radius: impl Fn(usize) -> f64) -> Vec<GridPoint> {
        (0..n)
            .map(|k| {
                let (a, r) = (std::f64::consts::TAU * k as f64 / n as f64, radius(k));
                [
                    (r * a.cos()).round() as i32,
                    (r * a.sin()).round() as i32,
                    0,
                ]
            })
            .collect()
    }

    /// A star of 200,000 corners (long edges close together, which
    /// buckets cannot tell apart) is tiled; its simplicity by the sweep.
    #[test]
    fn a_star_of_many_corners_is_tiled() {
        let n = 200_000;
        let v = ring(n, |k| if k % 2 == 0 { 4e6 } else { 2e6 });
        let t = tile(&v, &XY).unwrap();
        assert_eq!(t.len(), n - 2);
    }

    /// Every point of a triangle (its edges included) lies in a cell that
    /// [`Buckets::under_triangle`] visits: small lattices, so that the
    /// edges' crossings of the bands' lines fall between lattice points.
    #[test]
    fn a_triangle_s_cells_hold_all_its_points() {
        let mut seed = 0x510e_527f_ade6_82d1u64;
        let mut next = |m: u64| crate::xorshift(&mut seed) % m;
        let mut inside = 0;
        for _ in 0..400 {
            let spread = 2 + next(40);
            let pts: Vec<Xy> = (0..64 + next(200))
                .map(|_| (next(spread) as i128, next(spread) as i128))
                .collect();
            let cells = Buckets::new(pts.iter().map(|&p| (p, p)).collect()).unwrap();
            for _ in 0..20 {
                let t = [0, 1, 2].map(|_| pts[next(pts.len() as u64) as usize]);
                // (an ear turns the loop's way: no flat triangle)
                let t = match turn(t[0], t[1], t[2]) {
                    0 => continue,
                    -1 => [t[0], t[2], t[1]],
                    _ => t,
                };
                let mut seen = vec![false; pts.len()];
                cells.under_triangle(t, |c| {
                    cells.cell(c).iter().for_each(|&j| seen[j as usize] = true);
                    true
                });
                for (j, &p) in pts.iter().enumerate() {
                    let holds = (0..3).all(|k| turn(t[k], t[(k + 1) % 3], p) >= 0);
                    assert!(!holds || seen[j], "{p:?} in {t:?}");
                    inside += usize::from(holds);
                }
            }
        }
        assert!(inside > 10_000, "{inside}");
    }

    /// A circle of 30,000 corners snapped to the grid (not convex any
    /// more) is tiled, in much less than the pairwise search's seconds.
    #[test]
    fn a_face_of_many_corners_is_tiled() {
        let n = 30_000;
        let v = ring(n, |_| 1e6);
        let t = tile(&v, &XY).unwrap();
        assert_eq!(t.len(), n - 2);
    }
}
