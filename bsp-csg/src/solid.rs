//! The [`Solid`]: its face slots and the spatial index of their boxes.
//! What a solid answers is in `query`, how a planned operation's faces
//! go into its slots in `carry_out`, its mesh in `mesh_out`.

mod carry_out;
mod face;
mod mesh_out;
mod query;
mod winding;

use bsp_core::Polygon;
use bsp_core::par;
use std::borrow::Cow;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicU32, Ordering};

pub(crate) use carry_out::{AddedFace, Additions, OtherFaces};
pub(crate) use face::SolidFace;

use crate::index::{FaceIndex, IBox, span, union};

/// Faces removed or added at once from which the index is updated in
/// parallel passes rather than face by face.
const BULK: usize = 4096;

/// The boundary of a closed, outward-oriented polyhedron: plane-based
/// convex polygons on the grid, with a spatial index of their boxes (see
/// the crate docs).
#[derive(Clone, Debug)]
pub struct Solid {
    /// The face slots (`None`: a free slot).
    faces: Vec<Option<SolidFace>>,
    /// The free slots; the last one is reused first.
    free: Vec<u32>,
    /// The spatial index of the faces' boxes, once made: by an operation
    /// carried out on the solid (a solid changed in place is likely to
    /// be changed again), or by a solid's queries once it has been asked
    /// [`SCANS_BEFORE_INDEX`] times; until then a query reads every face
    /// (an operation on two new solids asks each a few times, and making
    /// the index costs more than those reads).
    index: OnceLock<FaceIndex>,
    /// The index's design size, to know when to rebuild it.
    indexed: usize,
    /// Queries answered by reading every face.
    scans: Scans,
    /// The box of the live faces' boxes.
    bounds: Option<IBox>,
    /// The number of live faces.
    live: usize,
    /// The faces are known to bound where their winding number is
    /// positive ([`Solid::resolved`] made them, or found them so).
    pub(crate) resolved: bool,
}

impl Solid {
    /// The solid bounded by `polys`, which must tile the boundary of a
    /// closed, outward-oriented polyhedron (not checked; see
    /// [`mesh_boolean`](crate::mesh_boolean) for checked input).
    pub fn from_polygons(polys: Vec<Polygon>) -> Solid {
        let faces = par::map_vec(polys, |p| Some(SolidFace::made(Box::new(p))));
        Solid::from_faces(faces, Vec::new())
    }

    /// The solid of these face slots, indexed; the empty ones are `free`
    /// (each once).
    pub(crate) fn from_faces(faces: Vec<Option<SolidFace>>, free: Vec<u32>) -> Solid {
        debug_assert!(free.iter().all(|&f| faces[f as usize].is_none()));
        let live = faces.len() - free.len();
        let mut s = Solid {
            live,
            faces,
            free,
            index: OnceLock::new(),
            indexed: live.max(1),
            scans: Scans::default(),
            bounds: None,
            resolved: false,
        };
        s.bounds = s.faces_bounds();
        s
    }

    /// The box of the live faces' boxes.
    fn faces_bounds(&self) -> Option<IBox> {
        let faces = &self.faces;
        let spans = par::fold_runs(faces.len(), |r| {
            span(
                faces[r]
                    .iter()
                    .filter_map(|f| f.as_ref().map(SolidFace::bx)),
            )
        });
        span(spans.into_iter().flatten())
    }

    /// An empty solid.
    pub fn empty() -> Solid {
        Solid::from_polygons(Vec::new())
    }

    /// The bounds found again and the index made anew, sized for the
    /// live faces.
    fn reindex(&mut self) {
        self.bounds = self.faces_bounds();
        self.indexed = self.live.max(1);
        self.make_index();
    }

    /// The index of the faces over the bounds, sized for `indexed`, made
    /// now (in parallel).
    fn make_index(&mut self) {
        self.index = OnceLock::from(FaceIndex::filled(
            self.bounds.unwrap_or(([0; 3], [0; 3])),
            self.indexed,
            self.faces.len(),
            |i| self.faces[i].as_ref().map(SolidFace::bx),
        ));
    }

    /// The index for a query: `None` while the solid has been asked fewer
    /// than [`SCANS_BEFORE_INDEX`] times without one (the query reads
    /// every face), then made. (Made on one thread: a query may run on
    /// the thread pool, and a thread making it with the pool's help could
    /// be handed another query that waits for it.)
    fn query_index(&self) -> Option<&FaceIndex> {
        if let Some(index) = self.index.get() {
            return Some(index);
        }
        if self.scans.0.fetch_add(1, Ordering::Relaxed) < SCANS_BEFORE_INDEX {
            return None;
        }
        Some(self.index.get_or_init(|| {
            let mut index = FaceIndex::new(self.bounds.unwrap_or(([0; 3], [0; 3])), self.indexed);
            for (i, f) in self.faces.iter().enumerate() {
                if let Some(f) = f {
                    index.insert(i as u32, &f.bx());
                }
            }
            index
        }))
    }

    /// The number of face slots, live or free: every face id is below it.
    pub(crate) fn slot_count(&self) -> usize {
        self.faces.len()
    }

    /// The ids of the live faces, in order.
    pub(crate) fn face_ids(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.faces.len() as u32).filter(|&i| self.faces[i as usize].is_some())
    }

    /// The box of the live faces' boxes (`None` for an empty solid).
    pub(crate) fn bounds(&self) -> Option<IBox> {
        self.bounds
    }

    /// Number of faces.
    pub fn len(&self) -> usize {
        self.live
    }

    /// `true` if the solid has no face (it is empty).
    pub fn is_empty(&self) -> bool {
        self.live == 0
    }

    /// The faces, each with its edge planes (made for a face kept as
    /// imported, which does not store them).
    pub fn polygons(&self) -> impl Iterator<Item = Cow<'_, Polygon>> + '_ {
        self.faces.iter().flatten().map(SolidFace::polygon)
    }

    /// The face in slot `i`, which must be live.
    pub(crate) fn face(&self, i: u32) -> &SolidFace {
        self.faces[i as usize].as_ref().expect("a live face")
    }

    /// The face in slot `id` taken out, if it is live: its slot is
    /// free, and the index forgets it.
    fn remove(&mut self, id: u32) {
        if let Some(f) = self.faces[id as usize].take() {
            if let Some(index) = self.index.get_mut() {
                index.remove(id, &f.bx());
            }
            self.free.push(id);
            self.live -= 1;
        }
    }

    /// [`Solid::remove`] of each of `ids` in turn (the same free list);
    /// many at once are taken out of the slots and the index in parallel
    /// passes (the index's lists keep their other ids in order, which no
    /// query depends on).
    pub(crate) fn remove_all(&mut self, ids: &[u32]) {
        if ids.len() < BULK.max(self.faces.len() / 16) {
            ids.iter().for_each(|&f| self.remove(f));
            return;
        }
        let mut gone = vec![false; self.faces.len()];
        for &f in ids {
            if self.faces[f as usize].is_some() && !gone[f as usize] {
                gone[f as usize] = true;
                self.free.push(f);
                self.live -= 1;
            }
        }
        par::for_each_mut(&mut self.faces, |i, f| {
            if gone[i] {
                *f = None;
            }
        });
        if let Some(index) = self.index.get_mut() {
            index.retain(|f| !gone[f as usize]);
        }
    }

    /// Adds the faces `ids` (live, not yet indexed) with their `boxes` to
    /// the bounds, and to the index if there is one, in order.
    fn index_boxes(
        index: Option<&mut FaceIndex>,
        bounds: &mut Option<IBox>,
        ids: &[u32],
        boxes: &[IBox],
    ) {
        let Some(all) = boxes.iter().copied().reduce(|a, b| union(&a, &b)) else {
            return;
        };
        *bounds = Some(bounds.map_or(all, |b| union(&b, &all)));
        if let Some(index) = index {
            for (&f, bx) in ids.iter().zip(boxes) {
                index.insert(f, bx);
            }
        }
    }
}

/// Queries a solid answers by reading every face before it makes its
/// index ([`Solid::query_index`]).
const SCANS_BEFORE_INDEX: u32 = 8;

/// A count of queries, shared by the threads asking (a copy starts with
/// the count so far).
#[derive(Debug, Default)]
struct Scans(AtomicU32);

impl Clone for Scans {
    fn clone(&self) -> Scans {
        Scans(AtomicU32::new(self.0.load(Ordering::Relaxed)))
    }
}

/// Frees `x` on the thread pool: large temporaries (a cell's fates, the
/// other operand's remains) are many small allocations, and freeing them
/// where they fall due would hold up the sequential steps after while the
/// other threads idle.
pub(crate) fn drop_aside<T: Send + 'static>(x: T) {
    rayon::spawn(move || drop(x));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{MeshIn, snap};

    /// Many faces removed at once (slots and index in parallel passes)
    /// leave the solid as removing them one by one does: the same free
    /// list, slots, bounds of the remaining queries and index answers.
    #[test]
    fn removing_many_faces_at_once_is_removing_them_in_turn() {
        let (pos, faces) = bsp_fixtures::uv_sphere(12_000);
        let snapped = snap(&[MeshIn::new(&pos, &faces)]).unwrap();
        // with the index made (it is updated) and without (a new solid's)
        let mut indexed = snapped.solids[0].clone();
        indexed.reindex();
        for solid in [&snapped.solids[0], &indexed] {
            removing_many_at_once(solid);
        }
    }

    fn removing_many_at_once(solid: &Solid) {
        let n = solid.faces.len() as u32;
        // every other face, some named twice, ending with one already gone
        let mut ids: Vec<u32> = (0..n).filter(|i| i % 2 == 0).rev().collect();
        ids.extend([2, 4, 6]);
        assert!(ids.len() >= BULK && ids.len() >= solid.faces.len() / 16);
        let mut one = solid.clone();
        let mut all = solid.clone();
        one.remove(8);
        all.remove(8);
        ids.iter().for_each(|&f| one.remove(f));
        all.remove_all(&ids);
        assert_eq!(one.free, all.free);
        assert_eq!(one.live, all.live);
        assert_eq!(one.live, (n / 2) as usize);
        let live = |s: &Solid| -> Vec<bool> { s.faces.iter().map(Option::is_some).collect() };
        assert_eq!(live(&one), live(&all));
        let (lo, hi) = solid.bounds.unwrap();
        let mid = [0, 1, 2].map(|k| (lo[k] + hi[k]) / 2);
        for bx in [(lo, hi), (lo, mid), (mid, hi), (mid, mid)] {
            let near = all.faces_near(&bx);
            assert_eq!(one.faces_near(&bx), near);
            assert!(near.iter().all(|&f| f % 2 == 1));
        }
        for q in [lo, mid].map(|p| p.map(|c| c as i32)) {
            assert_eq!(one.winding(q), all.winding(q));
        }
    }
}
