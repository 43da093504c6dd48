//! A receiver's cells through the lights' trees, light after light; the
//! cells of a large receiver in runs, in parallel.
//!
//! A ground under a scanned mesh is cut by its first light into
//! thousands of cells, and with several lights each of them goes through
//! every other tree: one face's work, on one thread, while the rest of
//! the scene is done. Past the first light, each cell's walk through a
//! tree is its own: runs of cells go through the remaining trees on
//! copies of the arena, whose additions are then appended in the runs'
//! order ([`PieceArena::append_since`](crate::arena::pieces::PieceArena::append_since)). The cells come out in the same
//! order, each the same polygon with the same flags, for any number of
//! threads.

use rayon::prelude::*;
use smallvec::SmallVec;

use super::{Scratch, ShadowSet};
use crate::psv::ShadowVolumes;
use crate::psv::filter::filter;
use crate::schedule::PARALLEL_CELLS;

/// At most this many runs (each copies the arena).
const MAX_RUNS: usize = 8;

/// Cells a run holds at least.
const MIN_RUN: usize = 64;

impl ShadowSet<'_> {
    /// Filters every cell of `s.cur` through the tree of each light in
    /// `mask` for which the cell's flag is set, light after light; a cell
    /// may come back cut, or shadowed for that light. Returns whether a
    /// cell was cut or lost a light. Once the cells are many (a large
    /// face, such as a ground, cut by its first light), the rest of the
    /// lights pass over runs of them in parallel (`engine/passes.rs`).
    pub(super) fn pass_lights(&self, s: &mut Scratch, mask: u64) -> bool {
        let trees: SmallVec<[(&ShadowVolumes, usize); 4]> = (self.trees.iter())
            .filter(|(_, j)| mask & 1 << j != 0)
            .copied()
            .collect();
        let all = u64::MAX >> (64 - self.lights.len().clamp(1, 64));
        let mut pending = trees.iter().fold(0u64, |m, &(_, j)| m | 1 << j);
        let mut changed = false;
        for (k, &tree) in trees.iter().enumerate() {
            let settle = s.settle_mixed.then_some((all, pending));
            if k > 0 && s.cur.len() >= PARALLEL_CELLS {
                return pass_runs(s, &trees[k..], settle) | changed;
            }
            changed |= pass(s, tree, settle);
            pending &= !(1 << tree.1);
        }
        changed
    }
}

/// Whether `flags` has, among the lights of `all` not `pending` (their
/// bits final), one set and one clear.
fn mixed(flags: u64, (all, pending): (u64, u64)) -> bool {
    let known = all & !pending;
    flags & known != 0 && !flags & known != 0
}

/// The cells of `s.cur` whose flag for light `j` is set through `sv`,
/// the tree of light `j`; whether a cell was cut or lost the light. With
/// `settle` (the lights of the set, and those whose trees are still to
/// come, `j`'s among them), a cell already [`mixed`] stays as it is.
pub(super) fn pass(
    s: &mut Scratch,
    (sv, j): (&ShadowVolumes, usize),
    settle: Option<(u64, u64)>,
) -> bool {
    let bit = 1u64 << j;
    let mut changed = false;
    s.next.clear();
    for (piece, flags) in s.cur.drain(..) {
        if flags & bit == 0 || settle.is_some_and(|m| mixed(flags, m)) {
            s.next.push((piece, flags));
            continue;
        }
        s.out.clear();
        filter(
            sv,
            &mut s.arena,
            s.support,
            piece,
            &mut s.out,
            &mut s.stack,
            &mut s.links,
            &mut s.sides,
        );
        // one piece back, still lit: the cell as it was
        changed |= s.out.len() != 1 || !s.out[0].1;
        for (p, lit) in s.out.drain(..) {
            s.next.push((p, flags & !bit | (lit as u64) << j));
        }
    }
    std::mem::swap(&mut s.cur, &mut s.next);
    changed
}

/// [`pass`] of every tree of `trees` in turn, over runs of `s.cur` in
/// parallel, each on its own copy of the arena; the cells and the
/// arena's additions put back in the runs' order.
pub(super) fn pass_runs(
    s: &mut Scratch,
    trees: &[(&ShadowVolumes, usize)],
    settle: Option<(u64, u64)>,
) -> bool {
    let n = s.cur.len();
    let runs = (n / MIN_RUN).clamp(1, MAX_RUNS);
    let size = n.div_ceil(runs);
    let mark = s.arena.mark();
    let (arena, support) = (&s.arena, s.support);
    let done: Vec<(Scratch, bool)> = s
        .cur
        .par_chunks(size)
        .map(|cells| {
            let mut own = Scratch {
                arena: arena.clone(),
                support,
                cur: cells.to_vec(),
                ..Scratch::default()
            };
            let mut changed = false;
            let mut at = settle;
            for &t in trees {
                changed |= pass(&mut own, t, at);
                at = at.map(|(all, pending)| (all, pending & !(1 << t.1)));
            }
            (own, changed)
        })
        .collect();
    s.cur.clear();
    let mut changed = false;
    for (mut own, c) in done {
        let (mut pieces, flags): (Vec<_>, Vec<_>) = own.cur.drain(..).unzip();
        s.arena.append_since(&own.arena, mark, &mut pieces);
        s.cur.extend(pieces.into_iter().zip(flags));
        changed |= c;
    }
    changed
}
