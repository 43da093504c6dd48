//! The [`Solid`]: its face slots, the spatial index of their boxes, and
//! the operations on it.

mod carry_out;
pub(crate) mod face;
mod mesh_out;
mod query;
mod winding;

use bsp_core::{BoolOp, Polygon};
use rayon::prelude::*;
use std::borrow::Cow;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicU32, Ordering};

pub(crate) use carry_out::Other;
pub(crate) use face::Face;

use crate::index::{FaceIndex, IBox, union};
use crate::plan::Planned;
use crate::{CsgError, Options, Stats};

/// Faces removed or added at once from which the index is updated in
/// parallel passes rather than face by face.
pub(crate) const BULK: usize = 4096;

/// The boundary of a closed, outward-oriented polyhedron: plane-based
/// convex polygons on the grid, with a spatial index of their boxes (see
/// the crate docs).
#[derive(Clone, Debug)]
pub struct Solid {
    pub(crate) faces: Vec<Option<Face>>,
    pub(crate) free: Vec<u32>,
    /// The spatial index of the faces' boxes, once made: by an operation
    /// carried out on the solid (a solid changed in place is likely to
    /// be changed again), or by a solid's queries once it has been asked
    /// [`SCANS_BEFORE_INDEX`] times; until then a query reads every face
    /// (an operation on two new solids asks each a few times, and making
    /// the index costs more than those reads).
    pub(crate) index: OnceLock<FaceIndex>,
    /// The index's design size, to know when to rebuild it.
    pub(crate) indexed: usize,
    /// Queries answered by reading every face.
    pub(crate) scans: Scans,
    pub(crate) bounds: Option<IBox>,
    pub(crate) live: usize,
}

impl Solid {
    /// The solid bounded by `polys`, which must tile the boundary of a
    /// closed, outward-oriented polyhedron (not checked; see
    /// [`mesh_boolean`](crate::mesh_boolean) for checked input).
    pub fn from_polygons(polys: Vec<Polygon>) -> Solid {
        let faces: Vec<Option<Face>> = polys
            .into_par_iter()
            .map(|p| Some(Face::made(Box::new(p))))
            .collect();
        Solid::from_faces(faces, Vec::new())
    }

    /// The solid of these face slots, indexed; the empty ones are `free`
    /// (each once).
    pub(crate) fn from_faces(faces: Vec<Option<Face>>, free: Vec<u32>) -> Solid {
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
        };
        s.bounds = s.faces_bounds();
        s
    }

    /// The box of the live faces' boxes.
    pub(crate) fn faces_bounds(&self) -> Option<IBox> {
        self.faces
            .par_iter()
            .filter_map(|f| f.as_ref().map(Face::bx))
            .reduce_with(|a, b| union(&a, &b))
    }

    /// An empty solid.
    pub fn empty() -> Solid {
        Solid::from_polygons(Vec::new())
    }

    /// The bounds found again and the index made anew, sized for the
    /// live faces.
    pub(crate) fn reindex(&mut self) {
        self.bounds = self.faces_bounds();
        self.indexed = self.live.max(1);
        self.make_index();
    }

    /// The index of the faces over the bounds, sized for `indexed`, made
    /// now (in parallel).
    pub(crate) fn make_index(&mut self) {
        self.index = OnceLock::from(FaceIndex::filled(
            self.bounds.unwrap_or(([0; 3], [0; 3])),
            self.indexed,
            self.faces.par_iter().map(|f| f.as_ref().map(Face::bx)),
        ));
    }

    /// The index for a query: `None` while the solid has been asked fewer
    /// than [`SCANS_BEFORE_INDEX`] times without one (the query reads
    /// every face), then made. (Made on one thread: a query may run on
    /// the thread pool, and a thread making it with the pool's help could
    /// be handed another query that waits for it.)
    pub(crate) fn query_index(&self) -> Option<&FaceIndex> {
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
        self.faces.iter().flatten().map(Face::polygon)
    }

    pub(crate) fn face(&self, i: u32) -> &Face {
        self.faces[i as usize].as_ref().expect("a live face")
    }

    pub(crate) fn remove(&mut self, id: u32) {
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
        self.faces
            .par_iter_mut()
            .zip(&gone)
            .filter(|(_, g)| **g)
            .for_each(|(f, _)| *f = None);
        if let Some(index) = self.index.get_mut() {
            index.retain(|f| !gone[f as usize]);
        }
    }

    /// Adds the faces `ids` (live, not yet indexed) with their `boxes` to
    /// the bounds, and to the index if there is one, in order.
    pub(crate) fn index_boxes(
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

impl Solid {
    /// `self op other`, as a new solid.
    pub fn boolean(&self, other: &Solid, op: BoolOp) -> Result<Solid, CsgError> {
        let mut s = self.clone();
        s.apply(other, op)?;
        Ok(s)
    }

    /// `self ← self op other`, touching only the faces near `other`.
    pub fn apply(&mut self, other: &Solid, op: BoolOp) -> Result<Stats, CsgError> {
        self.apply_with(other, op, &Options::default())
    }

    /// [`Solid::apply`] with options.
    pub fn apply_with(
        &mut self,
        other: &Solid,
        op: BoolOp,
        opts: &Options,
    ) -> Result<Stats, CsgError> {
        let (stats, plan) = self.plan(other, op, opts)?;
        self.carry_out(plan, Other::Borrowed(other));
        Ok(stats)
    }

    /// [`Solid::apply`], taking the other solid: the faces it keeps whole
    /// move over instead of being copied, so that the two are not held
    /// at once (the same result).
    pub fn apply_owned(&mut self, other: Solid, op: BoolOp) -> Result<Stats, CsgError> {
        self.apply_owned_with(other, op, &Options::default())
    }

    /// [`Solid::apply_owned`] with options.
    pub fn apply_owned_with(
        &mut self,
        mut other: Solid,
        op: BoolOp,
        opts: &Options,
    ) -> Result<Stats, CsgError> {
        let (stats, plan) = self.plan(&other, op, opts)?;
        self.carry_out(plan, Other::Owned(&mut other));
        drop_aside(other);
        Ok(stats)
    }

    /// `self op other`, decided but not yet carried out: the result is
    /// then made as a mesh ([`Planned::into_watertight_mesh`]) straight
    /// from the two solids' faces, with no solid of its own (the last
    /// operation of a sequence needs none), or as a solid
    /// ([`Planned::into_solid`], what [`Solid::apply_owned`] gives).
    ///
    /// ```
    /// use bsp_core::BoolOp;
    /// use bsp_csg::{MeshIn, fit_grid, snap_one};
    /// use bsp_fixtures::sphere_pair;
    ///
    /// let (va, vb, faces) = sphere_pair(1000);
    /// let (a, b) = (MeshIn::new(&va, &faces), MeshIn::new(&vb, &faces));
    /// let grid = fit_grid(&[a, b]).unwrap();
    /// let (sa, _) = snap_one(&grid, &a, 0).unwrap();
    /// let (sb, _) = snap_one(&grid, &b, 1).unwrap();
    /// let planned = sa.clone().plan_owned(sb.clone(), BoolOp::Union).unwrap();
    /// assert!(planned.stats().cut_faces > 0);
    /// let mesh = planned.into_watertight_mesh().unwrap();
    /// // the mesh of the solid `apply_owned` makes, triangle for triangle
    /// let mut solid = sa;
    /// solid.apply_owned(sb, BoolOp::Union).unwrap();
    /// assert_eq!(mesh.triangles, solid.into_watertight_mesh().unwrap().triangles);
    /// ```
    pub fn plan_owned(mut self, other: Solid, op: BoolOp) -> Result<Planned, CsgError> {
        let (stats, plan) = self.plan(&other, op, &Options::default())?;
        Ok(Planned {
            solid: self,
            other,
            plan,
            stats,
        })
    }
}

/// Queries a solid answers by reading every face before it makes its
/// index ([`Solid::query_index`]).
pub(crate) const SCANS_BEFORE_INDEX: u32 = 8;

/// A count of queries, shared by the threads asking (a copy starts with
/// the count so far).
#[derive(Debug, Default)]
pub(crate) struct Scans(AtomicU32);

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
