//! A face's loop of grid points cleaned before it becomes a polygon:
//! repeated corners merged, straight-through corners and spikes removed.

use smallvec::SmallVec;

use crate::kernel::grid::GridPoint;
use crate::kernel::plane::{cross, sub};

/// A face's loop of grid points, on the stack for up to eight corners.
pub(super) type GridLoop = SmallVec<[GridPoint; 8]>;

pub(super) fn dedupe_cyclic(points: &[GridPoint]) -> GridLoop {
    let mut v = GridLoop::with_capacity(points.len());
    for p in points {
        if v.last() != Some(p) {
            v.push(*p);
        }
    }
    while v.len() > 1 && v.first() == v.last() {
        v.pop();
    }
    v
}

/// Loops of at least this many corners are cleaned and checked convex
/// through linked corners and one turn each (linear), smaller ones by the
/// plain passes (quadratic) that define the answers.
pub(super) const LINKED: usize = 64;

/// Removes vertices whose two edges are collinear (straight-through points
/// and zero-area spikes); they do not change the enclosed region. The
/// first such corner goes, neighbours made equal by it are merged (as
/// [`dedupe_cyclic`] merges them), and so on from the start.
pub(super) fn remove_collinear(v: &mut GridLoop) {
    match v.len() >= LINKED {
        true => remove_collinear_linked(v),
        false => remove_collinear_passes(v),
    }
}

/// [`remove_collinear`] pass by pass, each from the start.
fn remove_collinear_passes(v: &mut GridLoop) {
    let mut changed = true;
    while changed && v.len() >= 3 {
        changed = false;
        let k = v.len();
        for i in 0..k {
            let prev = v[(i + k - 1) % k];
            let next = v[(i + 1) % k];
            if cross(sub(v[i], prev), sub(next, v[i])) == [0, 0, 0] {
                v.remove(i);
                changed = true;
                break;
            }
        }
        // removing a spike can make two neighbours equal
        let d = dedupe_cyclic(v);
        if d.len() != v.len() {
            *v = d;
            changed = true;
        }
    }
}

/// [`remove_collinear`]'s passes on a ring of linked corners: a removal
/// changes only its neighbours, so the next pass starts at the first of
/// them (the corners before it were straight-through in no pass), and a
/// loop of many collinear corners (a fine circle snapped to the grid) is
/// cleaned in linear time.
fn remove_collinear_linked(v: &mut GridLoop) {
    let pts: Vec<GridPoint> = v.to_vec();
    let mut r = Ring::new(pts.len());
    let mut from = r.head;
    while r.len >= 3 {
        let straight = |r: &Ring, i: usize| {
            cross(sub(pts[i], pts[r.prev[i]]), sub(pts[r.next[i]], pts[i])) == [0, 0, 0]
        };
        let mut i = from;
        let found = loop {
            if straight(&r, i) {
                break Some(i);
            }
            if i == r.tail {
                break None;
            }
            i = r.next[i];
        };
        let Some(x) = found else {
            break;
        };
        r.touched.clear();
        let (a, at_end) = (r.prev[x], x == r.head || x == r.tail);
        r.unlink(x);
        // equal neighbours in the loop's order keep the first of them (an
        // end's neighbours are the two ends: no new neighbours in order)
        while !at_end && a != r.tail && pts[r.next[a]] == pts[a] {
            r.unlink(r.next[a]);
        }
        // and an end equal to the start goes
        while r.len > 1 && pts[r.head] == pts[r.tail] {
            r.unlink(r.tail);
        }
        // the next pass from the first corner whose neighbours changed:
        // the corners before it stay as they were, none straight-through
        match r.touched.iter().copied().filter(|&i| !r.gone[i]).min() {
            Some(i) => from = i,
            None => break,
        }
    }
    *v = std::iter::successors(Some(r.head), |&i| Some(r.next[i]))
        .take(r.len)
        .map(|i| pts[i])
        .collect();
}

/// A loop's corners linked in a ring, some unlinked: the loop's order is
/// the corners' from `head` to `tail`, and an index grows along it.
struct Ring {
    next: Vec<usize>,
    prev: Vec<usize>,
    gone: Vec<bool>,
    head: usize,
    tail: usize,
    len: usize,
    /// The corners whose neighbours the unlinking changed.
    touched: Vec<usize>,
}

impl Ring {
    fn new(n: usize) -> Ring {
        Ring {
            next: (1..=n).map(|i| i % n).collect(),
            prev: (0..n).map(|i| (i + n - 1) % n).collect(),
            gone: vec![false; n],
            head: 0,
            tail: n - 1,
            len: n,
            touched: Vec::new(),
        }
    }

    fn unlink(&mut self, i: usize) {
        let (a, b) = (self.prev[i], self.next[i]);
        (self.next[a], self.prev[b], self.gone[i]) = (b, a, true);
        if i == self.head {
            self.head = b;
        }
        if i == self.tail {
            self.tail = a;
        }
        self.len -= 1;
        self.touched.extend([a, b]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Loops of 64 to 400 corners on small lattices (straight-through
    /// corners, spikes, corners met again, ends equal to starts): the
    /// linked cleaning leaves what the passes from the start leave.
    #[test]
    fn linked_cleaning_leaves_what_the_passes_leave() {
        let mut seed = 0xbb67_ae85_84ca_a73bu64;
        let mut next = |m: u64| crate::xorshift(&mut seed) % m;
        let mut removed = 0;
        for round in 0..2_000 {
            let n = LINKED + next(340) as usize;
            let spread = [2, 3, 8][round % 3];
            let mut v: GridLoop = (0..n)
                .map(|k| match next(4) {
                    // a lattice point, or a walk along one line
                    0 => [next(spread) as i32, next(spread) as i32, 0],
                    _ => [(k as i32 / 3) % 7, 0, 0],
                })
                .collect();
            v = dedupe_cyclic(&v);
            if v.len() < LINKED {
                continue;
            }
            let (mut passes, mut linked) = (v.clone(), v.clone());
            remove_collinear_passes(&mut passes);
            remove_collinear_linked(&mut linked);
            assert_eq!(linked, passes, "round {round}");
            removed += v.len() - linked.len();
        }
        assert!(removed > 10_000, "{removed}");
    }
}
