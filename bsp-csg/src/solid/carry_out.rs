//! An operation's additions carried out: the faces it adds written into
//! the solid's slots, and the index told of them.

use bsp_core::Polygon;
use bsp_core::internals::share_points;
use bsp_core::par;

use super::{Solid, SolidFace};
use crate::index::IBox;

/// What an operation adds to the first solid, in order: new faces, and
/// the other solid's faces kept whole (turned around if `flip`, for a
/// difference).
pub(crate) struct Additions {
    pub(crate) faces: Vec<AddedFace>,
    pub(crate) flip: bool,
}

/// A face an operation adds: a new one (boxed, so that the many faces
/// kept whole cost a few bytes each), or the other solid's face kept
/// whole, by its id there.
pub(crate) enum AddedFace {
    New(Box<Polygon>),
    Theirs(u32),
}

/// The solid an operation takes the faces it keeps whole from.
pub(crate) enum OtherFaces<'s> {
    /// Its faces are copied.
    Copied(&'s Solid),
    /// Its faces move over (the solid is given up).
    Moved(&'s mut Solid),
}

/// Where an added face comes from: a face kept whole from a solid given
/// up is taken from its slot (distinct slots: one borrow each).
enum Source<'s> {
    New(Box<Polygon>),
    Slot(&'s mut Option<SolidFace>),
    Copy(&'s SolidFace),
}

impl Source<'_> {
    /// The face, the other solid's turned around if `flip`.
    fn make(self, flip: bool) -> SolidFace {
        match self {
            Source::New(p) => SolidFace::made(p),
            Source::Slot(slot) => {
                let face = slot.take().expect("a live face");
                if flip { face.flipped() } else { face }
            }
            Source::Copy(face) if flip => face.flipped(),
            Source::Copy(face) => face.clone(),
        }
    }
}

/// Where each of `faces` comes from, in order.
fn sources<'s>(faces: Vec<AddedFace>, other: OtherFaces<'s>) -> Vec<Source<'s>> {
    let (mut slots, borrowed): (Vec<Option<&mut Option<SolidFace>>>, Option<&Solid>) = match other {
        OtherFaces::Moved(o) => (o.faces.iter_mut().map(Some).collect(), None),
        OtherFaces::Copied(o) => (Vec::new(), Some(o)),
    };
    faces
        .into_iter()
        .map(|a| match a {
            AddedFace::New(p) => Source::New(p),
            AddedFace::Theirs(f) => match borrowed {
                Some(o) => Source::Copy(o.face(f)),
                None => Source::Slot(slots[f as usize].take().expect("a face kept once")),
            },
        })
        .collect()
}

impl Solid {
    /// Carries an operation's additions out: its new faces, then the
    /// other solid's faces it keeps whole, from `other`.
    ///
    /// The faces are made in parallel and written straight into their
    /// slots (freed slots first, in order, then the end of the array),
    /// each moved or copied once; the index takes them while the new
    /// faces' equal new vertices are made one.
    pub(crate) fn carry_out(&mut self, additions: Additions, other: OtherFaces<'_>) {
        // an operation on two resolved solids gives one
        self.resolved &= match &other {
            OtherFaces::Copied(o) => o.resolved,
            OtherFaces::Moved(o) => o.resolved,
        };
        let from = sources(additions.faces, other);
        let n = from.len();
        let (ids, new_slots) = self.write_faces(from, additions.flip);
        self.index_added(&ids, new_slots);
        self.live += n;
        if self.live > 4 * self.indexed + 1024 {
            self.reindex();
        } else if self.index.get().is_none() {
            // a solid changed in place is likely to be changed again
            self.make_index();
        }
    }

    /// Writes the faces `from` into the freed slots, in the order they
    /// are popped, then at the end of the array, in place: room for all
    /// at once (growing by doubling would hold the old and a twice larger
    /// array). The ids the faces went to, in order, and those of the new
    /// faces.
    fn write_faces(&mut self, mut from: Vec<Source<'_>>, flip: bool) -> (Vec<u32>, Vec<u32>) {
        let reused = reused_slots(&mut self.free, from.len());
        let rest = from.split_off(reused.len());
        let first_new = self.faces.len();
        // the slots of the new faces
        let new_slots: Vec<u32> = reused
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
        let refills = borrow_sorted(&mut self.faces, &slots)
            .into_iter()
            .zip(sources)
            .collect();
        par::map_vec(refills, |(slot, f)| *slot = Some(f.make(flip)));
        let rest = par::map_vec(rest, |f| Some(f.make(flip)));
        self.faces.reserve_exact(rest.len());
        self.faces.extend(rest);
        let ids = reused
            .into_iter()
            .chain(first_new as u32..self.faces.len() as u32)
            .collect();
        (ids, new_slots)
    }

    /// The index (if made) and the bounds take the faces `ids` just
    /// written, while the equal new vertices of the new faces among them
    /// (`new_slots`) become one each: pieces cut along a shared edge
    /// computed them each for itself. The boxes stay as they are.
    fn index_added(&mut self, ids: &[u32], mut new_slots: Vec<u32>) {
        let boxes: Vec<IBox> = par::map_slice(ids, |&f| self.face(f).bx());
        let Solid {
            faces,
            index,
            bounds,
            ..
        } = self;
        par::join(
            || {
                // one borrow each, by slot (not a pass over all slots: a
                // long sequence of operations adds few faces to many)
                new_slots.sort_unstable();
                let mut new: Vec<&mut Polygon> = borrow_sorted(faces, &new_slots)
                    .into_iter()
                    .filter_map(|slot| slot.as_mut().and_then(SolidFace::made_polygon_mut))
                    .collect();
                share_points(&mut new);
            },
            || Solid::index_boxes(index.get_mut(), bounds, ids, &boxes),
        );
    }
}

/// The freed slots the first `n` faces an operation adds go to, in the
/// order they take them (popped from the end of `free`); the rest go at
/// the end of the array. One rule for [`Solid::carry_out`] and for
/// [`Solid::into_watertight_mesh_with`], which meshes the faces in the
/// order the slots would hold them.
pub(super) fn reused_slots(free: &mut Vec<u32>, n: usize) -> Vec<u32> {
    let k = n.min(free.len());
    free.drain(free.len() - k..).rev().collect()
}

/// The items at `ids` (strictly increasing), each borrowed once.
pub(super) fn borrow_sorted<'a, T>(items: &'a mut [T], ids: &[u32]) -> Vec<&'a mut T> {
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
