//! A planned operation carried out: the faces it adds written into the
//! solid's slots.

use bsp_core::Polygon;
use bsp_core::internals::share_points;
use rayon::prelude::*;

use super::face::Shape;
use super::{Face, Solid};
use crate::index::IBox;
use crate::plan::{Added, Plan};

impl Solid {
    /// Carries a plan out: its new faces, then the other solid's faces it
    /// keeps whole, from `other`.
    ///
    /// The faces are made in parallel and written straight into their
    /// slots (freed slots first, in order, then the end of the array),
    /// each moved or copied once; the index takes them while the new
    /// faces' equal new vertices are made one.
    pub(crate) fn carry_out(&mut self, plan: Plan, other: Other<'_>) {
        // where each face comes from: a kept face of an owned solid is
        // taken from its slot (distinct slots: one borrow each)
        enum Source<'s> {
            New(Box<Polygon>),
            Slot(&'s mut Option<Face>),
            Copy(&'s Face),
        }
        let (mut slots, borrowed): (Vec<Option<&mut Option<Face>>>, Option<&Solid>) = match other {
            Other::Owned(o) => (o.faces.iter_mut().map(Some).collect(), None),
            Other::Borrowed(o) => (Vec::new(), Some(o)),
        };
        let mut from: Vec<Source<'_>> = plan
            .add
            .into_iter()
            .map(|a| match a {
                Added::New(p) => Source::New(p),
                Added::Whole(f) => match borrowed {
                    Some(o) => Source::Copy(o.face(f)),
                    None => Source::Slot(slots[f as usize].take().expect("a face kept once")),
                },
            })
            .collect();
        drop(slots);
        let flip = plan.flip;
        let make = |f: Source<'_>| -> Face {
            match f {
                Source::New(p) => Face::made(p),
                Source::Slot(slot) => {
                    let face = slot.take().expect("a live face");
                    if flip { face.flipped() } else { face }
                }
                Source::Copy(face) if flip => face.flipped(),
                Source::Copy(face) => face.clone(),
            }
        };
        // freed slots first, in the order they are popped, then the end of
        // the array, in place: room for all at once (growing by doubling
        // would hold the old and a twice larger array)
        let n = from.len();
        let reused = reused_slots(&mut self.free, n);
        let rest = from.split_off(reused.len());
        let first_new = self.faces.len();
        // the slots of the new faces
        let mut new_slots: Vec<u32> = reused
            .iter()
            .copied()
            .zip(&from)
            .chain((first_new as u32..).zip(&rest))
            .filter(|(_, f)| matches!(f, Source::New(_)))
            .map(|(id, _)| id)
            .collect();
        // the freed slots filled in parallel, each borrowed once
        let mut refill: Vec<(u32, Source<'_>)> = reused.iter().copied().zip(from).collect();
        refill.sort_unstable_by_key(|r| r.0);
        let (slots, sources): (Vec<u32>, Vec<Source<'_>>) = refill.into_iter().unzip();
        borrow_sorted(&mut self.faces, &slots)
            .into_par_iter()
            .zip(sources)
            .for_each(|(slot, f)| *slot = Some(make(f)));
        self.faces.reserve_exact(rest.len());
        self.faces
            .par_extend(rest.into_par_iter().map(|f| Some(make(f))));
        // the index takes the faces while their equal new vertices become
        // one each (pieces cut along a shared edge computed them each for
        // itself); the boxes stay as they are
        let ids: Vec<u32> = reused
            .into_iter()
            .chain(first_new as u32..self.faces.len() as u32)
            .collect();
        let boxes: Vec<IBox> = ids.par_iter().map(|&f| self.face(f).bx()).collect();
        let Solid {
            faces,
            index,
            bounds,
            ..
        } = self;
        rayon::join(
            || {
                // one borrow each, by slot (not a pass over all slots: a
                // long sequence of operations adds few faces to many)
                new_slots.sort_unstable();
                let mut new: Vec<&mut Polygon> = borrow_sorted(faces, &new_slots)
                    .into_iter()
                    .filter_map(|slot| match slot {
                        Some(Face {
                            shape: Shape::Made(p, _),
                        }) => Some(&mut **p),
                        _ => None,
                    })
                    .collect();
                share_points(&mut new);
            },
            || Solid::index_boxes(index.get_mut(), bounds, &ids, &boxes),
        );
        self.live += n;
        if self.live > 4 * self.indexed + 1024 {
            self.reindex();
        } else if self.index.get().is_none() {
            // a solid changed in place is likely to be changed again
            self.make_index();
        }
    }
}

/// The freed slots the first `n` faces an operation adds go to, in the
/// order they take them (popped from the end of `free`); the rest go at
/// the end of the array. One rule for [`Solid::carry_out`] and for
/// [`Planned::into_watertight_mesh`](crate::Planned::into_watertight_mesh), which meshes the faces in the
/// order the slots would hold them.
pub(crate) fn reused_slots(free: &mut Vec<u32>, n: usize) -> Vec<u32> {
    let k = n.min(free.len());
    free.drain(free.len() - k..).rev().collect()
}

/// The items at `ids` (strictly increasing), each borrowed once.
pub(crate) fn borrow_sorted<'a, T>(items: &'a mut [T], ids: &[u32]) -> Vec<&'a mut T> {
    let mut out = Vec::with_capacity(ids.len());
    let (mut tail, mut at) = (items, 0);
    for &id in ids {
        let (item, rest) = std::mem::take(&mut tail)[id as usize - at..]
            .split_first_mut()
            .expect("ids within the items, increasing");
        out.push(item);
        (tail, at) = (rest, id as usize + 1);
    }
    out
}

/// The solid an operation takes kept faces from.
pub(crate) enum Other<'s> {
    /// Its faces are copied.
    Borrowed(&'s Solid),
    /// Its faces move over.
    Owned(&'s mut Solid),
}
