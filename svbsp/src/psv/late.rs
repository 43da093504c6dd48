//! The occluders turned away from a light ("late" ones, module docs of
//! [`super`]): when they go down a skeleton whole, the leaves each
//! reaches, and a region's running judgement of whether they are hidden
//! often enough there to keep going in whole.

use bsp_core::Side;

use super::occluders::Occluders;
use super::{Entry, LIT, Node, Task};
use crate::arena::pieces::Sides;

/// Late occluders a region tests before it judges them: while at least
/// one in [`LATE_HIDDEN`] of those tested is found hidden, they go into
/// its leaves whole; past that, a leaf's are cut to it like the others
/// and the leaf split as the skeleton splits (the price of going in whole
/// is paid by those that are not hidden: a terrain with half its faces
/// flipped at random has one in ten hidden, an open scan's far side 98 in
/// a hundred, a soup one in three, a city's walls turned from the sun
/// about one in two).
const LATE_TRIAL: usize = 64;
/// The share of a region's tested late occluders, one in this many,
/// found hidden that keeps them going into its leaves whole
/// ([`LATE_TRIAL`]).
const LATE_HIDDEN: usize = 4;
/// How a region's late occluders fared so far: tested by the quick reach
/// test, and found hidden by it.
#[derive(Default)]
pub(super) struct LateTally {
    tested: usize,
    hidden: usize,
}

impl LateTally {
    /// One more tested, hidden or not.
    pub(super) fn count(&mut self, hidden: bool) {
        self.tested += 1;
        self.hidden += usize::from(hidden);
    }

    /// Whether, on what was seen so far, the late occluders are better cut
    /// to a leaf like the others ([`LATE_TRIAL`], [`LATE_HIDDEN`]).
    pub(super) fn cut(&self) -> bool {
        self.tested >= LATE_TRIAL && self.hidden * LATE_HIDDEN < self.tested
    }
}

/// Per task of `tasks` (the open slots of the skeleton `nodes` below
/// `root`), the occluders of `late` that reach it, in order: each goes
/// down the nodes, whole, to the sides its corners lie on.
pub(super) fn route_late(
    occ: &Occluders,
    nodes: &[Node],
    root: u32,
    tasks: &[Task],
    late: &[u32],
) -> Vec<Vec<u32>> {
    let mut lists = vec![Vec::new(); tasks.len()];
    if late.is_empty() {
        return lists;
    }
    // the task at each open slot of the nodes
    let mut task_at = vec![[usize::MAX; 2]; nodes.len()];
    for (t, task) in tasks.iter().enumerate() {
        match task.slot {
            None => {
                lists[t] = late.to_vec();
                return lists;
            }
            Some((id, side)) => task_at[id as usize][(side == Side::Back) as usize] = t,
        }
    }
    // runs of the late occluders in parallel (an open scan has tens of
    // thousands, and the other core waited), each run's lists then laid
    // end to end in order: the same lists for every thread count
    let runs = bsp_core::par::fold_runs(late.len(), |r| {
        let mut own = vec![Vec::new(); tasks.len()];
        let mut stack = Vec::new();
        for &o in &late[r] {
            let verts = occ.verts(o);
            stack.push(root);
            while let Some(id) = stack.pop() {
                let n = &nodes[id as usize];
                let sd = Sides::of_grid(verts, &n.plane);
                // (an occluder is not in a plane through the light)
                let front = sd.front || !sd.back;
                for (reached, link, side) in [(sd.back, n.back, 1), (front, n.front, 0)] {
                    match (reached, link == LIT) {
                        (true, true) => own[task_at[id as usize][side]].push(o),
                        (true, false) => stack.push(link),
                        _ => {}
                    }
                }
            }
        }
        own
    });
    for run in runs {
        for (list, part) in lists.iter_mut().zip(run) {
            list.extend_from_slice(&part);
        }
    }
    lists
}

/// Two lists of entries, each nearest first, as one.
pub(super) fn merged(a: &[Entry], b: &[Entry]) -> Vec<Entry> {
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() || j < b.len() {
        if j == b.len() || (i < a.len() && a[i].occ < b[j].occ) {
            out.push(a[i]);
            i += 1;
        } else {
            out.push(b[j]);
            j += 1;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn merged_keeps_nearest_first() {
        let a: Vec<Entry> = [0, 3, 4, 9].map(Entry::whole).to_vec();
        let b: Vec<Entry> = [1, 2, 5, 10, 11].map(Entry::whole).to_vec();
        let m: Vec<u32> = merged(&a, &b).iter().map(|e| e.occ).collect();
        assert_eq!(m, [0, 1, 2, 3, 4, 5, 9, 10, 11]);
        assert!(merged(&[], &[]).is_empty());
    }

    #[test]
    fn tally_judges_only_after_its_trial() {
        let mut t = LateTally::default();
        for _ in 0..LATE_TRIAL - 1 {
            t.count(false);
        }
        assert!(!t.cut(), "judged before the trial is over");
        t.count(false);
        assert!(t.cut(), "none hidden: cut");
        let mut t = LateTally::default();
        for i in 0..LATE_TRIAL * 2 {
            t.count(i % LATE_HIDDEN == 0);
        }
        assert!(!t.cut(), "one in {LATE_HIDDEN} hidden: still whole");
    }
}
