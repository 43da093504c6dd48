//! The lit parts of the occluders, found while their volumes are inserted
//! ([`super::ShadowVolumes::build_lit`]).
//!
//! An occluder's part that reaches a lit leaf as it is inserted is lit by
//! every volume in the tree so far. The finished tree is the tree of that
//! moment with some lit leaves replaced by subtrees (a graft only ever
//! replaces a lit leaf), so the walk a receiver would take through the
//! finished tree is the insertion's walk continued into whatever replaced
//! the leaf it reached. So each part rests at its lit leaf, and when a
//! graft replaces that leaf, the parts resting there walk on into the new
//! nodes, as [`crate::engine`]'s filter walks a receiver (behind a cap is
//! shadow; in a cap's plane is not). Inserted nearest first, a later
//! occluder rarely reaches a leaf an earlier part rests at (it would have
//! to lie between the light and that part), so the rests mostly stay where
//! they first came to: the lit parts of every occluder come with the tree,
//! without a second walk of every face through it.
//!
//! The part that brings its own volume to a leaf rests in front of that
//! volume's cap at once (it lies behind its own edge planes and in its
//! cap's plane: the walk would take it there). An occluder part wholly in
//! the plane of a cap it meets adds no volume (it hides nothing the cap's
//! occluder does not), but as a receiver it is lit there: it walks on as a
//! receiver only, resting without a graft. Which occluders had a part end
//! in shadow is noted too, so that the building can tell the occluders the
//! light reaches all over, not at all, or in part
//! ([`super::ShadowVolumes::build_reached`]).

use std::collections::hash_map::Entry;

use bsp_core::{Polygon, Side};
use rustc_hash::FxHashMap;
use smallvec::SmallVec;

use super::{LIT, SHADOW, ShadowVolumes, Subtree};
use crate::arena::pieces::{Piece, PieceArena, Vertex};

/// Where a leaf hangs: the node whose child it is and the side (`None`:
/// the root).
type Slot = Option<(u32, Side)>;

/// A lit leaf's slot as one key.
fn key(slot: Slot) -> u64 {
    match slot {
        None => u64::MAX,
        Some((id, Side::Front)) => 2 * id as u64,
        Some((id, _)) => 2 * id as u64 + 1,
    }
}

/// A part at rest: the piece, its occluder (sorted index) and its
/// support plane in the arena.
struct Rest {
    piece: Piece,
    occ: u32,
    sup: u32,
}

/// The end of a leaf's list of parts at rest.
const END: u32 = u32::MAX;

/// The parts resting at each lit leaf of one region's subtree: one list
/// of every part, each leaf's parts chained through it in the order they
/// came to rest (no list of its own a leaf: most leaves get one part, and
/// a list each was an allocation each).
#[derive(Default)]
pub(super) struct Rests {
    /// Per leaf with parts at rest, its first and last in `parts`.
    at: FxHashMap<u64, (u32, u32)>,
    /// The parts, each with the next of its leaf's (`END`: none); a part
    /// that walked on from its leaf is left behind empty.
    parts: Vec<(Rest, u32)>,
    /// Counts every part put at rest with a vertex or an edge plane an
    /// insertion made, and every cut of a part at rest, so that an
    /// insertion that kept none of its arena's new vertices and planes can
    /// roll them back.
    pub(super) changes: u64,
    stack: Vec<(Piece, u32, Slot)>,
    /// The occluders (sorted indices) a part of which ended in shadow,
    /// once or more.
    dark: Vec<u32>,
}

impl Rests {
    /// Puts `piece` of occluder `occ` (support plane `sup`) at rest at the
    /// lit leaf of `slot`; `new`: it has a vertex or an edge plane the
    /// arena must keep.
    pub(super) fn rest(&mut self, slot: Slot, piece: Piece, occ: u32, sup: u32, new: bool) {
        self.push(key(slot), Rest { piece, occ, sup });
        self.changes += new as u64;
    }

    /// Chains `r` to the end of the parts at rest at leaf `key`.
    fn push(&mut self, key: u64, r: Rest) {
        let i = self.parts.len() as u32;
        self.parts.push((r, END));
        match self.at.entry(key) {
            Entry::Occupied(mut e) => {
                let (_, last) = e.get_mut();
                self.parts[*last as usize].1 = i;
                *last = i;
            }
            Entry::Vacant(e) => {
                e.insert((i, i));
            }
        }
    }

    /// The parts at rest at leaf `key`, first to last, as indices.
    fn chain(&self, key: u64) -> impl Iterator<Item = u32> + '_ {
        let first = self.at.get(&key).map_or(END, |&(f, _)| f);
        std::iter::successors(Some(first).filter(|&i| i != END), move |&i| {
            Some(self.parts[i as usize].1).filter(|&n| n != END)
        })
    }

    /// Notes that a part of occluder `occ` ended in shadow.
    pub(super) fn dark(&mut self, occ: u32) {
        self.dark.push(occ);
    }

    /// After a graft at `slot`: the parts resting there walk on into the
    /// new nodes, to the lit leaves they reach (the parts in shadow are
    /// dropped).
    pub(super) fn settle(
        &mut self,
        tree: &Subtree,
        root: u32,
        slot: Slot,
        arena: &mut PieceArena,
        sides: &mut SmallVec<[Side; 8]>,
    ) {
        let Some((mut next, _)) = self.at.remove(&key(slot)) else {
            return;
        };
        let start = tree.link(slot, root);
        let mut stack = std::mem::take(&mut self.stack);
        while next != END {
            let (rest, after) = &mut self.parts[next as usize];
            let (piece, occ, sup) = (std::mem::take(&mut rest.piece), rest.occ, rest.sup);
            next = *after;
            stack.push((piece, start, slot));
            while let Some((mut p, mut link, mut at)) = stack.pop() {
                loop {
                    if link == LIT {
                        self.push(key(at), Rest { piece: p, occ, sup });
                        break;
                    }
                    if link == SHADOW {
                        self.dark.push(occ);
                        break;
                    }
                    let n = tree.nodes[link as usize];
                    let sd = arena.classify_into(&p, &n.plane, sides);
                    let next = match (n.cap, sd.front, sd.back) {
                        // a cap: in its plane or in front is lit by it
                        (true, _, false) => Side::Front,
                        (true, false, true) => {
                            self.dark.push(occ);
                            break;
                        }
                        (true, true, true) => {
                            let cut = arena.add_plane(n.plane);
                            p = arena.split(sup, &p, cut, sides).0;
                            self.dark.push(occ);
                            self.changes += 1;
                            Side::Front
                        }
                        (false, true, false) | (false, false, false) => Side::Front,
                        (false, false, true) => Side::Back,
                        (false, true, true) => {
                            let cut = arena.add_plane(n.plane);
                            let (f, b) = arena.split(sup, &p, cut, sides);
                            self.changes += 1;
                            stack.push((b, n.back, Some((link, Side::Back))));
                            p = f;
                            Side::Front
                        }
                    };
                    at = Some((link, next));
                    link = match next {
                        Side::Front => n.front,
                        _ => n.back,
                    };
                }
            }
        }
        self.stack = stack;
    }

    /// The area of every part at rest (grid units squared, from `f64`
    /// approximations of its corners), with its occluder: leaf by leaf in
    /// the order of their slots, so the same for every thread count.
    pub(super) fn areas(self, arena: &PieceArena) -> Vec<(u32, f64)> {
        let mut pts: Vec<[f64; 3]> = Vec::new();
        self.each(|r| {
            pts.clear();
            pts.extend(r.piece.verts.iter().map(|&v| arena.vertex(v).approx()));
            area(&pts)
        })
    }

    /// Every part at rest with exact corners, with its occluder, in the
    /// order of [`Rests::areas`].
    pub(super) fn parts(self, arena: &PieceArena) -> Vec<(u32, Vec<Vertex>)> {
        self.each(|r| {
            r.piece
                .verts
                .iter()
                .map(|&v| arena.vertex(v).to_owned())
                .collect()
        })
    }

    /// Per occluder (sorted indices) with a part at rest or in shadow:
    /// `Some(true)` if all of it rests lit, `Some(false)` if all of it
    /// ended in shadow, `None` for both; in the order of the occluders.
    pub(super) fn reached(self, _: &PieceArena) -> Vec<(u32, Option<bool>)> {
        let mut marks: Vec<(u32, bool)> = (self.at.keys())
            .flat_map(|&k| self.chain(k))
            .map(|i| (self.parts[i as usize].0.occ, true))
            .chain(self.dark.iter().map(|&o| (o, false)))
            .collect();
        marks.sort_unstable();
        marks.dedup();
        let mut out: Vec<(u32, Option<bool>)> = Vec::with_capacity(marks.len());
        for (o, lit) in marks {
            match out.last_mut() {
                Some(last) if last.0 == o => last.1 = None,
                _ => out.push((o, Some(lit))),
            }
        }
        out
    }

    /// `f` of every part at rest, with its occluder, leaf by leaf in the
    /// order of their slots.
    fn each<T>(self, mut f: impl FnMut(&Rest) -> T) -> Vec<(u32, T)> {
        let mut slots: Vec<u64> = self.at.keys().copied().collect();
        slots.sort_unstable();
        (slots.iter().flat_map(|&k| self.chain(k)))
            .map(|i| &self.parts[i as usize].0)
            .map(|r| (r.occ, f(r)))
            .collect()
    }
}

impl ShadowVolumes {
    /// The area of a receiver that the light reaches, in grid units
    /// squared: `polys` are convex polygons of one plane with grid
    /// vertices (one face, as [`crate::receivers`] groups them), each
    /// filtered through the tree as [`crate::ShadowSet`] filters it, its
    /// lit pieces measured as [`ShadowVolumes::build_lit`] measures
    /// (unmerged, from `f64` approximations of their cut corners). 0 if
    /// the light does not face their plane (attached shadow).
    pub fn lit_area(&self, polys: &[Polygon]) -> f64 {
        let Some(first) = polys.first() else {
            return 0.0;
        };
        if !self.light().faces(first.support()) {
            return 0.0;
        }
        let mut arena = PieceArena::default();
        let support = arena.add_plane(*first.support());
        let (mut out, mut stack, mut links) = (Vec::new(), Vec::new(), Vec::new());
        let mut sides = SmallVec::new();
        let mut pts: Vec<[f64; 3]> = Vec::new();
        let mut total = 0.0;
        for p in polys {
            let piece = arena.add_polygon(p);
            out.clear();
            super::filter::filter(
                self, &mut arena, support, piece, &mut out, &mut stack, &mut links, &mut sides,
            );
            for (piece, _) in out.iter().filter(|o| o.1) {
                pts.clear();
                pts.extend(piece.verts.iter().map(|&v| arena.vertex(v).approx()));
                total += area(&pts);
            }
        }
        total
    }
}

/// The area of a planar convex polygon (its corners turned either way):
/// half the length of the sum of the cross products of its corners taken
/// from the first.
fn area(pts: &[[f64; 3]]) -> f64 {
    let Some(&o) = pts.first() else {
        return 0.0;
    };
    let d = |p: [f64; 3]| [p[0] - o[0], p[1] - o[1], p[2] - o[2]];
    let mut n = [0.0; 3];
    for w in pts[1..].windows(2) {
        let (a, b) = (d(w[0]), d(w[1]));
        n[0] += a[1] * b[2] - a[2] * b[1];
        n[1] += a[2] * b[0] - a[0] * b[2];
        n[2] += a[0] * b[1] - a[1] * b[0];
    }
    0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt()
}
