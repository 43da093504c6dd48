//! `--simplify PX`: fewer corners for an image's wanted region.
//!
//! Each boundary loop keeps a subset of its own corners (pixel corners,
//! so every test below is exact in integers), chosen as Douglas and
//! Peucker do: a run of corners within `PX` pixels of the segment between
//! its ends becomes that segment. A shortcut is taken only where it
//! leaves the region's shape intact: it touches no other segment of any
//! loop (its own loop's neighbours only at its ends, without folding back
//! on them), and no corner or edge midpoint of any loop lies inside the
//! sliver between it and the run it replaces. Corners that two passages
//! share (pixels touching at a corner) stay. So every loop stays simple,
//! no two loops meet, and each keeps its side of every other: components
//! and holes are those of the image. This changes the image: the wanted
//! region is the simplified polygons, up to `PX` pixels from the pixels'.

use std::collections::HashMap;

/// A pixel corner.
type Corner = [i32; 2];

/// Simplifies every loop of `loops` (closed loops of pixel corners, each
/// simple, no two crossing) within `tolerance` pixels, in order; a loop
/// keeps at least four corners, or all of them.
pub(crate) fn simplify(loops: &mut [Vec<Corner>], tolerance: f64) {
    let mut seen: HashMap<Corner, u32> = HashMap::new();
    for c in loops.iter().flatten() {
        *seen.entry(*c).or_default() += 1;
    }
    let removed = {
        let mut state = State::new(loops);
        for i in 0..loops.len() {
            simplify_loop(&mut state, i, tolerance, &|c| seen[c] > 1);
        }
        state.removed
    };
    for (l, removed) in loops.iter_mut().zip(removed) {
        *l = (0..l.len())
            .filter(|&k| !removed[k])
            .map(|k| l[k])
            .collect();
    }
}

/// Simplifies loop `i` (the others as they are now).
fn simplify_loop(state: &mut State, i: usize, tolerance: f64, pinned: &dyn Fn(&Corner) -> bool) {
    let l = state.loops[i].as_slice();
    let n = l.len();
    if n <= 4 {
        return;
    }
    let far = (1..n)
        .max_by_key(|&k| dist2(l[0], l[k]))
        .expect("a loop of more than four corners");
    // the two runs between corner 0 and the corner farthest from it,
    // each keeping its corner farthest from their segment
    for (s, e) in [(0, far), (far, n)] {
        let Some(m) = farthest(l, s, e).map(|(m, _)| m) else {
            continue;
        };
        let mut stack = vec![(m, e), (s, m)];
        while let Some((s, e)) = stack.pop() {
            let Some((m, d)) = farthest(l, s, e) else {
                continue;
            };
            let movable = (s + 1..e).all(|k| !pinned(&l[k % n]));
            if d <= tolerance && movable && state.shortcut_fits(i, s, e) {
                state.take(i, s, e);
            } else {
                stack.extend([(m, e), (s, m)]);
            }
        }
    }
}

/// Of the corners strictly between indices `s` and `e` (taken modulo the
/// loop's length), the one farthest from the segment between them, and
/// its distance in pixels; `None` where there is none.
fn farthest(l: &[Corner], s: usize, e: usize) -> Option<(usize, f64)> {
    let n = l.len();
    let (a, b) = (l[s % n], l[e % n]);
    (s + 1..e)
        .map(|k| (k, segment_distance(l[k % n], a, b)))
        .fold(None, |best: Option<(usize, f64)>, (k, d)| match best {
            Some((_, bd)) if bd >= d => best,
            _ => Some((k, d)),
        })
}

/// The distance from `p` to the segment `ab`, in pixels (`f64`: it only
/// compares with the user's tolerance).
fn segment_distance(p: Corner, a: Corner, b: Corner) -> f64 {
    let f = |c: Corner| [f64::from(c[0]), f64::from(c[1])];
    let ([px, py], [ax, ay], [bx, by]) = (f(p), f(a), f(b));
    let (dx, dy) = (bx - ax, by - ay);
    let len2 = dx * dx + dy * dy;
    let t = match len2 > 0.0 {
        true => (((px - ax) * dx + (py - ay) * dy) / len2).clamp(0.0, 1.0),
        false => 0.0,
    };
    ((px - ax - t * dx).powi(2) + (py - ay - t * dy).powi(2)).sqrt()
}

/// Every loop as simplified so far: its corners, those removed, each
/// kept corner's neighbours, and a grid of cells holding every segment
/// there is or was (a segment is there while its start is kept and its
/// end is the start's next).
struct State<'a> {
    loops: &'a [Vec<Corner>],
    removed: Vec<Vec<bool>>,
    next: Vec<Vec<u32>>,
    prev: Vec<Vec<u32>>,
    /// Loop, start, end.
    segments: Vec<[u32; 3]>,
    grid: Grid,
}

/// Square cells of `CELL` pixels over the loops' box, each listing the
/// segments whose boxes meet it.
struct Grid {
    lo: Corner,
    n: [usize; 2],
    cells: Vec<Vec<u32>>,
}

/// A grid cell's side, in pixels.
const CELL: i32 = 8;

impl Grid {
    /// The cells the box of `a` and `b` meets.
    fn cells(&self, a: Corner, b: Corner) -> impl Iterator<Item = usize> + '_ {
        let at = |k: usize, v: i32| ((v - self.lo[k]) / CELL) as usize;
        let (x0, x1) = (at(0, a[0].min(b[0])), at(0, a[0].max(b[0])));
        let (y0, y1) = (at(1, a[1].min(b[1])), at(1, a[1].max(b[1])));
        (y0..=y1).flat_map(move |y| (x0..=x1).map(move |x| y * self.n[0] + x))
    }
}

impl<'a> State<'a> {
    fn new(loops: &'a [Vec<Corner>]) -> State<'a> {
        let (mut lo, mut hi) = ([i32::MAX; 2], [i32::MIN; 2]);
        for c in loops.iter().flatten() {
            lo = [lo[0].min(c[0]), lo[1].min(c[1])];
            hi = [hi[0].max(c[0]), hi[1].max(c[1])];
        }
        let n = [0, 1].map(|k| ((hi[k] - lo[k]).max(0) / CELL) as usize + 1);
        let ring = |l: &Vec<Corner>, step: usize| -> Vec<u32> {
            (0..l.len())
                .map(|k| ((k + step) % l.len()) as u32)
                .collect()
        };
        let mut state = State {
            loops,
            removed: loops.iter().map(|l| vec![false; l.len()]).collect(),
            next: loops.iter().map(|l| ring(l, 1)).collect(),
            prev: loops.iter().map(|l| ring(l, l.len() - 1)).collect(),
            segments: Vec::new(),
            grid: Grid {
                lo,
                n,
                cells: vec![Vec::new(); n[0] * n[1]],
            },
        };
        for (i, l) in loops.iter().enumerate() {
            for k in 0..l.len() {
                state.add(i, k, (k + 1) % l.len());
            }
        }
        state
    }

    fn add(&mut self, i: usize, s: usize, e: usize) {
        let id = self.segments.len() as u32;
        self.segments.push([i, s, e].map(|x| x as u32));
        let (a, b) = (self.loops[i][s], self.loops[i][e]);
        let cells: Vec<usize> = self.grid.cells(a, b).collect();
        for c in cells {
            self.grid.cells[c].push(id);
        }
    }

    /// The run of loop `i` from `s` to `e` replaced by its shortcut.
    fn take(&mut self, i: usize, s: usize, e: usize) {
        let n = self.loops[i].len();
        (s + 1..e).for_each(|k| self.removed[i][k % n] = true);
        self.next[i][s % n] = (e % n) as u32;
        self.prev[i][e % n] = (s % n) as u32;
        self.add(i, s % n, e % n);
    }

    /// Calls `f` with every segment there is now whose box meets the box
    /// of `a` and `b` (some more than once): its loop, start and end.
    fn near(&self, a: Corner, b: Corner, mut f: impl FnMut(usize, usize, usize)) {
        for c in self.grid.cells(a, b) {
            for &id in &self.grid.cells[c] {
                let [j, s, e] = self.segments[id as usize].map(|x| x as usize);
                if !self.removed[j][s] && self.next[j][s] as usize == e {
                    f(j, s, e);
                }
            }
        }
    }

    /// Whether the segment from corner `s` to corner `e` of loop `i`
    /// (indices modulo its length, `s < e`, none between them removed)
    /// may replace the run between them (see the module docs).
    fn shortcut_fits(&self, i: usize, s: usize, e: usize) -> bool {
        let l = &self.loops[i];
        let n = l.len();
        let (a, b) = (l[s % n], l[e % n]);
        if a == b {
            return false;
        }
        let in_run = |k: usize| (k + n - s % n) % n < e - s;
        // the run's ends' neighbours on the loop as it is now
        let (before, after) = (self.prev[i][s % n] as usize, self.next[i][e % n] as usize);
        let mut fits = true;
        self.near(a, b, |j, k, m| {
            let (p, q) = (self.loops[j][k], self.loops[j][m]);
            fits = fits
                && match (j == i, k, m) {
                    // the run itself, replaced
                    (true, k, _) if in_run(k) => true,
                    // the segment into `a`, and the one out of `b`
                    (true, k, m) if k == before && m == s % n => !folds(a, b, p),
                    (true, k, m) if k == e % n && m == after => !folds(b, a, q),
                    _ => !meet(a, b, p, q),
                };
        });
        fits && self.sliver_is_empty(i, s, e)
    }

    /// Whether no corner and no edge midpoint of any loop (but the run's
    /// own) lies strictly inside the polygon of the run of loop `i` from
    /// `s` to `e` closed by the shortcut.
    fn sliver_is_empty(&self, i: usize, s: usize, e: usize) -> bool {
        let l = &self.loops[i];
        let n = l.len();
        let in_run = |k: usize| (k + n - s % n) % n < e - s;
        let (mut lo, mut hi) = ([i32::MAX; 2], [i32::MIN; 2]);
        for k in s..=e {
            let p = l[k % n];
            lo = [lo[0].min(p[0]), lo[1].min(p[1])];
            hi = [hi[0].max(p[0]), hi[1].max(p[1])];
        }
        // doubled coordinates: edge midpoints are integers too
        let run: Vec<[i64; 2]> = (s..=e).map(|k| double(l[k % n])).collect();
        let (lo2, hi2) = (double(lo), double(hi));
        let in_box = |p: [i64; 2]| (0..2).all(|k| lo2[k] < p[k] && p[k] < hi2[k]);
        let mut empty = true;
        self.near(lo, hi, |j, k, m| {
            // (the run's own corners and midpoints lie on its boundary)
            if !empty || j == i && in_run(k) {
                return;
            }
            let (p2, q2) = (double(self.loops[j][k]), double(self.loops[j][m]));
            let mid = [(p2[0] + q2[0]) / 2, (p2[1] + q2[1]) / 2];
            empty = ![mid, p2]
                .iter()
                .any(|&x| in_box(x) && strictly_inside(x, &run));
        });
        empty
    }
}

/// The squared distance between two corners.
fn dist2(a: Corner, b: Corner) -> i64 {
    let d = [0, 1].map(|k| i64::from(a[k]) - i64::from(b[k]));
    d[0] * d[0] + d[1] * d[1]
}

fn double(c: Corner) -> [i64; 2] {
    [2 * i64::from(c[0]), 2 * i64::from(c[1])]
}

/// Twice the signed area of the triangle `abc` (positive: counter-clockwise).
pub(super) fn orient(a: Corner, b: Corner, c: Corner) -> i64 {
    let [ax, ay] = a.map(i64::from);
    let [bx, by] = b.map(i64::from);
    let [cx, cy] = c.map(i64::from);
    (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
}

/// Whether `p` lies on the closed segment `ab` (given it is on its line).
pub(super) fn within(a: Corner, b: Corner, p: Corner) -> bool {
    (0..2).all(|k| a[k].min(b[k]) <= p[k] && p[k] <= a[k].max(b[k]))
}

/// Whether the closed segments `ab` and `cd` have a point in common.
fn meet(a: Corner, b: Corner, c: Corner, d: Corner) -> bool {
    let (d1, d2) = (orient(a, b, c), orient(a, b, d));
    let (d3, d4) = (orient(c, d, a), orient(c, d, b));
    if d1.signum() * d2.signum() < 0 && d3.signum() * d4.signum() < 0 {
        return true;
    }
    (d1 == 0 && within(a, b, c))
        || (d2 == 0 && within(a, b, d))
        || (d3 == 0 && within(c, d, a))
        || (d4 == 0 && within(c, d, b))
}

/// Whether the segments `ab` and `ac`, which share `a`, overlap beyond
/// it (one folds back along the other).
fn folds(a: Corner, b: Corner, c: Corner) -> bool {
    let dot = i64::from(b[0] - a[0]) * i64::from(c[0] - a[0])
        + i64::from(b[1] - a[1]) * i64::from(c[1] - a[1]);
    orient(a, b, c) == 0 && dot > 0
}

/// Whether `x` lies strictly inside the simple polygon `poly` (not on its
/// boundary), by its crossings to the right, exactly.
fn strictly_inside(x: [i64; 2], poly: &[[i64; 2]]) -> bool {
    let mut inside = false;
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        let cross = (b[0] - a[0]) * (x[1] - a[1]) - (b[1] - a[1]) * (x[0] - a[0]);
        let on_line = cross == 0
            && a[0].min(b[0]) <= x[0]
            && x[0] <= a[0].max(b[0])
            && a[1].min(b[1]) <= x[1]
            && x[1] <= a[1].max(b[1]);
        if on_line {
            return false;
        }
        // the edge spans x's row (half-open), and crosses it right of x
        if (a[1] > x[1]) != (b[1] > x[1]) && (cross > 0) == (b[1] > a[1]) {
            inside = !inside;
        }
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area2(l: &[Corner]) -> i64 {
        (0..l.len())
            .map(|k| orient([0, 0], l[k], l[(k + 1) % l.len()]))
            .sum()
    }

    /// A staircase triangle: its diagonal of 20 steps.
    fn staircase(steps: i32) -> Vec<Corner> {
        let mut l = vec![[0, 0], [steps, 0]];
        for k in (0..steps).rev() {
            l.push([k + 1, steps - k]);
            l.push([k, steps - k]);
        }
        l.pop();
        l.push([0, steps]);
        l
    }

    #[test]
    fn a_staircase_becomes_a_triangle() {
        let mut loops = vec![staircase(20)];
        let before = area2(&loops[0]);
        simplify(&mut loops, 1.0);
        assert!(loops[0].len() <= 5, "{:?}", loops[0]);
        let after = area2(&loops[0]);
        assert!(
            after > 0 && (after - before).abs() <= 2 * 20,
            "{before} {after}"
        );
        // every shortcut passes a corner at 1/√5 pixels or more
        let mut same = vec![staircase(20)];
        simplify(&mut same, 0.44);
        assert_eq!(same[0], staircase(20));
    }

    #[test]
    fn an_island_in_a_notch_keeps_the_notch_open_around_it() {
        // a notch 3 deep that a tolerance of 3.5 would fill, and a pixel
        // (another component) in it
        let notched = vec![
            [0, 0],
            [10, 0],
            [10, 5],
            [8, 5],
            [8, 2],
            [2, 2],
            [2, 5],
            [0, 5],
        ];
        let island = vec![[4, 3], [5, 3], [5, 4], [4, 4]];
        let mut alone = vec![notched.clone()];
        simplify(&mut alone, 3.5);
        assert_eq!(alone[0].len(), 4, "filled: {:?}", alone[0]);
        let mut loops = vec![notched.clone(), island.clone()];
        simplify(&mut loops, 3.5);
        assert_eq!(loops[1], island);
        let l = &loops[0];
        assert!(l.len() < notched.len() && area2(l) > 0, "{l:?}");
        let outer: Vec<[i64; 2]> = l.iter().map(|&c| double(c)).collect();
        for j in 0..4 {
            assert!(!strictly_inside(double(island[j]), &outer));
            for k in 0..l.len() {
                let (a, b) = (l[k], l[(k + 1) % l.len()]);
                assert!(!meet(a, b, island[j], island[(j + 1) % 4]), "{l:?}");
            }
        }
    }

    #[test]
    fn exact_predicates() {
        assert!(meet([0, 0], [2, 2], [0, 2], [2, 0]));
        assert!(meet([0, 0], [2, 2], [1, 1], [3, 0])); // touching
        assert!(meet([0, 0], [2, 0], [1, 0], [3, 0])); // overlapping
        assert!(!meet([0, 0], [2, 0], [3, 0], [4, 0]));
        assert!(folds([0, 0], [2, 0], [1, 0]));
        assert!(!folds([0, 0], [2, 0], [-1, 0]));
        let sq = [[0, 0], [4, 0], [4, 4], [0, 4]];
        assert!(strictly_inside([2, 2], &sq));
        assert!(!strictly_inside([4, 2], &sq));
        assert!(!strictly_inside([5, 2], &sq));
    }
}
