//! Exact Boolean operations on closed meshes: local BSP trees in an
//! adaptive octree.
//!
//! A [`Solid`] is the boundary of a closed, outward-oriented polyhedron as
//! plane-based convex polygons on `bsp-core`'s grid, with a spatial index
//! of their boxes made once it pays (by the first operation carried out on
//! the solid, or after a few queries).
//! [`Solid::apply`] computes `self ∘ other` for `∘` ∈ {∪, ∩, −}:
//!
//! 1. Faces outside the other solid's box are outside it: left as they
//!    are (or dropped, for ∩), at no cost.
//! 2. Over the box both solids share, an adaptive octree splits the cells
//!    that hold faces of both until they hold few
//!    (module `octree`: cell walls lie half a grid step off the
//!    grid, so no vertex or face of either solid is ever on one).
//! 3. In each cell that holds faces of both, the faces are clipped to the
//!    cell, each operand's pieces make a small BSP partition whose leaves
//!    are labelled exactly by the faces that cover their common boundaries
//!    (module `local`), and each piece of one operand is sorted
//!    against the other's labelled partition: kept whole, dropped whole, or
//!    cut by the other surface into kept fragments. Where faces of the two
//!    operands share a plane, the cell's two partitions are merged with
//!    `bsp-core`'s set operations instead (coplanar and touching faces
//!    included). Cells run in parallel. A cell where the two surfaces come
//!    near without meeting (each piece strictly on one side of the other
//!    surface's pieces' planes, or they of its) builds nothing: its pieces
//!    take their labels along their faces from the cells around
//!    ([`Options::easy_cells`]). A face apart from every face of the other
//!    surface in every mixed cell listing both meets that surface nowhere:
//!    it is kept or dropped whole by one label, without being clipped, and
//!    a cell holding only such faces does nothing ([`Stats::clean_cells`]).
//! 4. Every other face lies in cells the other surface does not enter: it
//!    is wholly inside or outside the other solid. Those cells form
//!    connected regions of space free of the other surface (adjacent cells
//!    share their label); each region's label is one exact winding number
//!    ([`Solid::winding`]: a ray along `+x` with simulation of simplicity),
//!    and a face keeps or loses its pieces by it.
//! 5. A face none of whose pieces the other surface cuts stays exactly as
//!    it was, however many cells it spans; only cut faces are replaced by
//!    pieces ([`Stats`]). An imported face is kept as its grid corners
//!    ([`bsp_core::internals::GridPolygon`]), and its edge planes are computed only
//!    when a cell clips it: most faces of a large solid never are, and the
//!    edge planes were most of a face's memory.
//!
//! Everything is exact: the planes are `bsp-core`'s input tier (planes of
//! the input faces, their edges, and the octree walls), vertices are
//! intersections of three of them, and the result is again such a solid —
//! the next operation takes it as it is ([`Solid::apply`] works in place
//! and touches only the faces near the other operand, so a sequence of
//! small operations on a large part never rebuilds anything global).
//!
//! From meshes: [`mesh_boolean`] and [`mesh_sequence`] check, snap, operate
//! and mesh in one call; [`snap`] makes every operand's solid on one grid
//! at once, and [`fit_grid`] with [`snap_one`] makes each when its turn
//! comes, so that a long sequence holds only the result and one operand.
//! Where only the mesh of the last result is wanted, [`Solid::plan_owned`]
//! decides the operation and [`Planned::into_watertight_mesh`] meshes the
//! result straight from the two solids' faces, with no solid of its own
//! (what the CLI does).
//!
//! # Example
//!
//! ```
//! use bsp_core::{BoolOp, Grid, Membership};
//! use bsp_csg::{MeshIn, mesh_boolean};
//! use glam::DVec3;
//!
//! fn cube(lo: f64, hi: f64) -> (Vec<DVec3>, Vec<Vec<u32>>) {
//!     let p = |i: u32| DVec3::new(
//!         if i & 1 == 0 { lo } else { hi },
//!         if i & 2 == 0 { lo } else { hi },
//!         if i & 4 == 0 { lo } else { hi },
//!     );
//!     let faces = vec![vec![0, 2, 3, 1], vec![4, 5, 7, 6], vec![0, 1, 5, 4],
//!                      vec![2, 6, 7, 3], vec![0, 4, 6, 2], vec![1, 3, 7, 5]];
//!     ((0..8).map(p).collect(), faces)
//! }
//! let (pa, fa) = cube(0.0, 2.0);
//! let (pb, fb) = cube(1.0, 3.0);
//! let r = mesh_boolean(&MeshIn::new(&pa, &fa), &MeshIn::new(&pb, &fb), BoolOp::Union).unwrap();
//! // 8 + 8 − 1 cubic units, exactly
//! assert_eq!(r.volume(), 15.0);
//! let inside = r.grid.snap(DVec3::splat(2.5)).unwrap();
//! assert_eq!(r.solid.classify_point(inside), Membership::Inside);
//! ```
//!
//! # Feature flags
//!
//! None.

mod index;
mod local;
mod octree;
mod winding;

use bsp_core::internals::{ConvexFace, GridPolygon, PointRef, share_points};
use bsp_core::{
    BoolOp, Grid, GridPoint, ImportReport, Membership, Plane, Polygon, Side, TopologyError,
    TriMesh, check_closed_manifold,
};
use glam::DVec3;
use rayon::prelude::*;
use rustc_hash::FxHashMap;
use smallvec::SmallVec;
use std::borrow::Cow;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicU32, Ordering};

use crate::index::{FaceIndex, IBox, holds, intersect, overlaps, polygon_box, union};
use crate::local::{CellResult, Fate};
use crate::octree::{Leaf, walls};

/// Faces a leaf of the octree may hold before it is split (when it holds
/// faces of both operands), by default.
pub const LEAF_SIZE: usize = 32;

/// Face ids a query near a box handles in parallel.
const MANY_NEAR: usize = 1 << 15;

/// Faces removed or added at once from which the index is updated in
/// parallel passes rather than face by face.
const BULK: usize = 4096;

/// Options of [`Solid::apply_with`].
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct Options {
    /// Faces an octree cell holding faces of both operands may have before
    /// it is split; smaller cells make smaller local trees, and more cells.
    pub leaf_size: usize,
    /// Test every face against each leaf holding both surfaces exactly
    /// (separating axes, for faces with grid vertices) instead of by its
    /// box and plane only: fewer cells hold both surfaces, at the cost of
    /// the tests. Off by default (slower on the benchmarks); the result is
    /// the same either way.
    pub exact_cells: bool,
    /// Let a mixed cell whose two surfaces do not meet label its pieces
    /// along their faces from the cells around instead of building local
    /// trees, and one whose faces all lie apart from the other surface
    /// do nothing (on by default; off, every mixed cell builds them). The
    /// result is the same either way.
    pub easy_cells: bool,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            leaf_size: LEAF_SIZE,
            exact_cells: false,
            easy_cells: true,
        }
    }
}

impl Options {
    /// Sets [`Options::exact_cells`].
    pub fn with_exact_cells(mut self, on: bool) -> Options {
        self.exact_cells = on;
        self
    }

    /// Sets [`Options::easy_cells`].
    pub fn with_easy_cells(mut self, on: bool) -> Options {
        self.easy_cells = on;
        self
    }

    /// Sets [`Options::leaf_size`] (at least 1).
    pub fn with_leaf_size(mut self, n: usize) -> Options {
        self.leaf_size = n.max(1);
        self
    }
}

/// What one [`Solid::apply`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Cells of the octree over the shared box.
    pub cells: usize,
    /// Cells that hold faces of both operands (a local boolean each).
    pub mixed_cells: usize,
    /// Mixed cells where faces of the two operands share a plane, merged
    /// as whole partitions.
    pub merged_cells: usize,
    /// Faces of either operand that the other surface cuts, so that only
    /// part of them stays (outside merged cells).
    pub cut_faces: usize,
    /// The pieces they left.
    pub pieces: usize,
    /// Mixed cells where the two surfaces do not meet: their pieces were
    /// labelled along their faces from the cells around, without local
    /// trees.
    pub easy_cells: usize,
    /// Mixed cells whose faces all lie apart from the other surface's
    /// (each whole face from each face of the other in every mixed cell
    /// that lists both): nothing was clipped or built there, and those
    /// faces were kept or dropped whole.
    pub clean_cells: usize,
}

/// Why an operation cannot be done.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum CsgError {
    /// Operand `operand` (0 for the first) is not a closed, consistently
    /// oriented 2-manifold.
    Topology {
        /// The operand.
        operand: usize,
        /// What is wrong, with face and edge.
        error: TopologyError,
    },
    /// Operand `operand`'s faces face inward: the solid they bound is
    /// unbounded.
    Inward {
        /// The operand.
        operand: usize,
    },
    /// A coordinate does not fit the grid (or is not finite).
    Grid(bsp_core::Error),
    /// Operand `operand` is closed and oriented as a mesh, but its snapped
    /// surface does not bound a solid (it crosses itself).
    NotASolid,
    /// The result is not watertight: a bug, not a problem of the input.
    Internal(String),
}

impl std::fmt::Display for CsgError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CsgError::Topology { operand, error } => write!(f, "operand {operand}: {error}"),
            CsgError::Inward { operand } => write!(
                f,
                "operand {operand}: the faces are oriented inward (clockwise seen from outside): \
                 the solid they bound is unbounded; reverse every face's vertex order"
            ),
            CsgError::Grid(e) => write!(f, "{e}"),
            CsgError::NotASolid => f.write_str(
                "a surface crosses itself (after snapping to the grid) and bounds no solid",
            ),
            CsgError::Internal(e) => write!(f, "internal error: {e}"),
        }
    }
}

impl std::error::Error for CsgError {}

/// A face's polygon. An imported face keeps its grid corners only, and
/// its edge planes are computed when it is cut or tested: most faces of a
/// large solid are never cut, and the edge planes are most of a
/// polygon's room.
#[derive(Clone, Debug)]
enum Shape {
    /// An imported face (or one kept whole from one); its box is read off
    /// its corners.
    Grid(GridPolygon),
    /// A face an operation made, with its edge planes, and its box in 32
    /// bits (rounded outward where a coordinate does not fit).
    Made(Box<Polygon>, octree::SmallBox),
}

/// A face slot's content (a face slot is most of a solid's memory: an
/// imported triangle takes 112 bytes, and a box stored beside its
/// corners would take 24 more).
#[derive(Clone, Debug)]
struct Face {
    shape: Shape,
}

impl Face {
    /// An imported face (its polygon made with tag 0).
    fn grid(g: GridPolygon) -> Face {
        Face {
            shape: Shape::Grid(g),
        }
    }

    /// A face an operation made (tag 0).
    fn made(mut p: Box<Polygon>) -> Face {
        p.set_tag(0);
        let bx = polygon_box(&*p);
        let narrow = |v: i64| v.clamp(i32::MIN as i64, i32::MAX as i64) as i32;
        let small = (bx.0.map(narrow), bx.1.map(narrow));
        Face {
            shape: Shape::Made(p, small),
        }
    }

    /// An imported face's grid polygon.
    fn as_grid(&self) -> Option<&GridPolygon> {
        match &self.shape {
            Shape::Grid(g) => Some(g),
            Shape::Made(..) => None,
        }
    }

    /// The polygon, with its edge planes (made for an imported face).
    fn polygon(&self) -> Cow<'_, Polygon> {
        match &self.shape {
            Shape::Grid(g) => Cow::Owned(g.to_polygon(0)),
            Shape::Made(p, _) => Cow::Borrowed(p),
        }
    }

    /// The same face seen from the other side (the same box).
    fn flipped(&self) -> Face {
        Face {
            shape: match &self.shape {
                Shape::Grid(g) => Shape::Grid(g.flipped()),
                Shape::Made(p, b) => Shape::Made(Box::new(p.flipped()), *b),
            },
        }
    }

    /// A box holding the polygon, in 32 bits: an imported face's corners'
    /// (exact), a made face's stored one.
    #[inline]
    fn small_box(&self) -> octree::SmallBox {
        match &self.shape {
            Shape::Grid(g) => match *g.vertices() {
                // (most imported faces)
                [a, b, c] => (
                    [0, 1, 2].map(|k| a[k].min(b[k]).min(c[k])),
                    [0, 1, 2].map(|k| a[k].max(b[k]).max(c[k])),
                ),
                // (a grid polygon's box is its corners' own: it fits)
                _ => {
                    let (lo, hi) = polygon_box(g);
                    (lo.map(|v| v as i32), hi.map(|v| v as i32))
                }
            },
            Shape::Made(_, b) => *b,
        }
    }

    /// A box holding the polygon.
    #[inline]
    fn bx(&self) -> IBox {
        let (lo, hi) = self.small_box();
        (lo.map(i64::from), hi.map(i64::from))
    }
}

impl ConvexFace for Face {
    #[inline]
    fn support(&self) -> &Plane {
        match &self.shape {
            Shape::Grid(g) => g.support(),
            Shape::Made(p, _) => p.support(),
        }
    }
    #[inline]
    fn corner_count(&self) -> usize {
        match &self.shape {
            Shape::Grid(g) => g.len(),
            Shape::Made(p, _) => p.len(),
        }
    }
    #[inline]
    fn corner(&self, i: usize) -> PointRef<'_> {
        match &self.shape {
            Shape::Grid(g) => PointRef::Grid(g.vertices()[i]),
            Shape::Made(p, _) => p.vertices()[i].as_ref(),
        }
    }
    #[inline]
    fn edge_plane(&self, i: usize) -> Plane {
        match &self.shape {
            Shape::Grid(g) => g.edge_plane(i),
            Shape::Made(p, _) => p.edge_planes()[i],
        }
    }
}

/// The boundary of a closed, outward-oriented polyhedron: plane-based
/// convex polygons on the grid, with a spatial index of their boxes (see
/// the crate docs).
#[derive(Clone, Debug)]
pub struct Solid {
    faces: Vec<Option<Face>>,
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
    bounds: Option<IBox>,
    live: usize,
}

/// An indexed mesh in input units: positions and faces (vertex index
/// loops, counter-clockwise seen from outside).
#[derive(Clone, Copy, Debug)]
pub struct MeshIn<'a> {
    /// The positions.
    pub positions: &'a [DVec3],
    /// The faces.
    pub faces: &'a [Vec<u32>],
}

impl<'a> MeshIn<'a> {
    /// A mesh from its parts.
    pub fn new(positions: &'a [DVec3], faces: &'a [Vec<u32>]) -> MeshIn<'a> {
        MeshIn { positions, faces }
    }
}

/// The result of [`mesh_boolean`].
#[derive(Clone, Debug)]
pub struct Boolean {
    /// The watertight result in grid units (`grid.to_world` for input
    /// units).
    pub mesh: TriMesh,
    /// The grid every operand was snapped to.
    pub grid: Grid,
    /// The result as a solid, ready for further operations.
    pub solid: Solid,
    /// What snapping did to each operand's faces.
    pub reports: Vec<ImportReport>,
}

impl Boolean {
    /// The result's exact volume in input units, correctly rounded to
    /// `f64` ([`TriMesh::volume_rounded`]; the grid's scale is a power of
    /// two).
    pub fn volume(&self) -> f64 {
        self.mesh.volume_rounded() / self.grid.scale().powi(3)
    }
}

impl Solid {
    /// The solid bounded by `polys`, which must tile the boundary of a
    /// closed, outward-oriented polyhedron (not checked; see
    /// [`mesh_boolean`] for checked input).
    pub fn from_polygons(polys: Vec<Polygon>) -> Solid {
        let faces: Vec<Option<Face>> = polys
            .into_par_iter()
            .map(|p| Some(Face::made(Box::new(p))))
            .collect();
        Solid::from_faces(faces, Vec::new())
    }

    /// The solid of these face slots, indexed; the empty ones are `free`
    /// (each once).
    fn from_faces(faces: Vec<Option<Face>>, free: Vec<u32>) -> Solid {
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
    fn faces_bounds(&self) -> Option<IBox> {
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
            self.faces.par_iter().map(|f| f.as_ref().map(Face::bx)),
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

    fn face(&self, i: u32) -> &Face {
        self.faces[i as usize].as_ref().expect("a live face")
    }

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
    fn remove_all(&mut self, ids: &[u32]) {
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

    /// The live faces whose box overlaps `b`.
    fn faces_near(&self, b: &IBox) -> Vec<u32> {
        match self.near_ids(b) {
            None => (0..self.faces.len() as u32)
                .into_par_iter()
                .filter(|&i| self.near_face(i, b).is_some())
                .collect(),
            Some(ids) if ids.len() > MANY_NEAR => ids
                .into_par_iter()
                .filter(|&i| self.near_face(i, b).is_some())
                .collect(),
            Some(mut ids) => {
                ids.retain(|&i| self.near_face(i, b).is_some());
                // the ids came with repeats: the lists of a large box are
                // kept while an operation runs
                ids.shrink_to_fit();
                ids
            }
        }
    }

    /// The box spanned by the live faces whose box overlaps `b`.
    fn near_span(&self, b: &IBox) -> Option<IBox> {
        let bx = |i: u32| self.near_face(i, b).map(Face::bx);
        match self.near_ids(b) {
            None => (0..self.faces.len() as u32)
                .into_par_iter()
                .filter_map(bx)
                .reduce_with(|x, y| union(&x, &y)),
            Some(ids) => ids
                .into_par_iter()
                .filter_map(bx)
                .reduce_with(|x, y| union(&x, &y)),
        }
    }

    /// Face `i` if it is live and its box overlaps `b`.
    #[inline]
    fn near_face(&self, i: u32, b: &IBox) -> Option<&Face> {
        self.faces[i as usize]
            .as_ref()
            .filter(|f| overlaps(&f.bx(), b))
    }

    /// The ids the index lists near `b`, sorted and without repeats;
    /// `None` where a scan of the slots is cheaper: many ids, as many as
    /// half the slots (each face is listed in several index cells), which
    /// a scan in order gives sorted without listing them first.
    fn near_ids(&self, b: &IBox) -> Option<Vec<u32>> {
        let index = self.query_index()?;
        let listed = index.near_count(b);
        if listed > MANY_NEAR && listed > self.faces.len() / 2 {
            return None;
        }
        let mut ids = Vec::with_capacity(listed);
        index.near(b, &mut ids);
        if ids.len() > MANY_NEAR {
            ids.par_sort_unstable();
        } else {
            ids.sort_unstable();
        }
        ids.dedup();
        Some(ids)
    }

    /// The winding number of the grid point `q` displaced by
    /// `(ε³, ε, ε²)` (see the crate docs): 1 inside, 0 outside; exact, and
    /// for a point not on the surface its own winding number.
    pub fn winding(&self, q: GridPoint) -> i32 {
        let q = q.map(i64::from);
        let Some(index) = self.query_index() else {
            return self
                .faces
                .par_iter()
                .filter_map(Option::as_ref)
                .map(|f| ray_crossing(q, f))
                .sum();
        };
        let mut ids = Vec::new();
        index.along_x(q, &mut ids);
        ids.sort_unstable();
        ids.dedup();
        ids.iter()
            .filter_map(|&i| self.faces[i as usize].as_ref())
            .map(|f| ray_crossing(q, f))
            .sum()
    }

    /// [`Solid::winding`] of each of `qs`: for a few points and no index,
    /// in one pass over the faces.
    fn windings(&self, qs: &[GridPoint]) -> Vec<i32> {
        if self.index.get().is_some() || qs.len() > FEW_WINDINGS {
            return qs.par_iter().map(|&q| self.winding(q)).collect();
        }
        let qs: Vec<[i64; 3]> = qs.iter().map(|q| q.map(i64::from)).collect();
        let zero = || vec![0i32; qs.len()];
        self.faces
            .par_iter()
            .filter_map(Option::as_ref)
            .fold(zero, |mut sums, f| {
                let bx = f.bx();
                for (s, &q) in sums.iter_mut().zip(&qs) {
                    if ray_reaches(q, &bx) {
                        *s += winding::crossing(q, f);
                    }
                }
                sums
            })
            .reduce(zero, |mut a, b| {
                a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
                a
            })
    }

    /// Exact membership of a grid point.
    pub fn classify_point(&self, q: GridPoint) -> Membership {
        let p = q.map(i64::from);
        for i in self.faces_near(&(p, p)) {
            let f = self.face(i);
            if f.support().classify_grid(q) == Side::On
                && (0..f.corner_count()).all(|e| f.edge_plane(e).classify_grid(q) != Side::Front)
            {
                return Membership::Boundary;
            }
        }
        if self.winding(q) == 0 {
            Membership::Outside
        } else {
            Membership::Inside
        }
    }

    /// The watertight triangle mesh of the boundary (see
    /// [`TriMesh::from_polygons`]).
    pub fn to_mesh(&self) -> TriMesh {
        let faces: Vec<&Face> = self.faces.iter().flatten().collect();
        TriMesh::from_polygons(&faces)
    }

    /// [`Solid::to_mesh`], checked watertight
    /// ([`TriMesh::from_polygons_watertight`]: one check, most often made
    /// while the mesh is made). A failure is a bug in this crate
    /// ([`CsgError::Internal`]).
    pub fn to_watertight_mesh(&self) -> Result<TriMesh, CsgError> {
        let faces: Vec<&Face> = self.faces.iter().flatten().collect();
        TriMesh::from_polygons_watertight(&faces).map_err(CsgError::Internal)
    }

    /// [`Solid::to_mesh`] for a solid no longer needed: the index goes
    /// first, and the faces go on the thread pool once the triangles are
    /// made (the same mesh).
    pub fn into_mesh(self) -> TriMesh {
        self.into_mesh_with(|polys| TriMesh::from_polygons(polys))
    }

    /// [`Solid::to_watertight_mesh`] for a solid no longer needed, as
    /// [`Solid::into_mesh`] makes it.
    pub fn into_watertight_mesh(self) -> Result<TriMesh, CsgError> {
        self.into_mesh_with(|polys| {
            TriMesh::from_polygons_watertight(polys).map_err(CsgError::Internal)
        })
    }

    /// `make` of the faces, the index and the faces let go as
    /// [`Solid::into_mesh`] says.
    fn into_mesh_with<T>(self, make: impl FnOnce(&[&Face]) -> T) -> T {
        // the index goes now (`..` would keep it to the end)
        let Solid { faces, index, .. } = self;
        drop_aside(index);
        // the polygons are read where they are (moving them out of their
        // slots into a list cost a pass over all of them)
        let polys: Vec<&Face> = faces.iter().flatten().collect();
        let mesh = make(&polys);
        drop(polys);
        drop_aside(faces);
        mesh
    }

    /// `self op other`, as a new solid.
    pub fn boolean(&self, other: &Solid, op: BoolOp) -> Result<Solid, CsgError> {
        let mut s = self.clone();
        s.apply(other, op)?;
        Ok(s)
    }

    /// `self op other` for solids whose faces cannot meet.
    fn apart(&mut self, other: &Solid, op: BoolOp) -> Result<(Stats, Plan), CsgError> {
        let mut plan = Plan {
            add: Vec::new(),
            flip: false,
        };
        match op {
            BoolOp::Union => {
                plan.add = (0..other.faces.len() as u32)
                    .filter(|&i| other.faces[i as usize].is_some())
                    .map(Added::Whole)
                    .collect()
            }
            BoolOp::Intersection => *self = Solid::empty(),
            BoolOp::Difference => {}
        }
        Ok((Stats::default(), plan))
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

    /// Everything an operation decides; of the changes to this solid it
    /// makes the removals (and empties it for an intersection with a
    /// solid apart), and leaves the additions to [`Solid::carry_out`].
    fn plan(
        &mut self,
        other: &Solid,
        op: BoolOp,
        opts: &Options,
    ) -> Result<(Stats, Plan), CsgError> {
        let keep_a = |inside_b: bool| match op {
            BoolOp::Union | BoolOp::Difference => !inside_b,
            BoolOp::Intersection => inside_b,
        };
        let keep_b = |inside_a: bool| match op {
            BoolOp::Union => !inside_a,
            BoolOp::Intersection | BoolOp::Difference => inside_a,
        };
        let flip_b = op == BoolOp::Difference;
        let domain = match (self.bounds, other.bounds) {
            (Some(a), Some(b)) => intersect(&a, &b),
            _ => None,
        };
        let Some(domain) = domain else {
            return self.apart(other, op);
        };
        // the faces that may meet the other surface, and every face of
        // either in the box they span: the octree's cells must know all
        // the faces in them to tell which cells are free of a surface
        let root = match (self.near_span(&domain), other.near_span(&domain)) {
            (Some(a), Some(b)) => union(&a, &b),
            (Some(x), None) | (None, Some(x)) => x,
            (None, None) => return self.apart(other, op),
        };
        let a_c = self.faces_near(&root);
        let b_c = other.faces_near(&root);
        // the faces' boxes and planes side by side, by their place in
        // `a_c` and `b_c` (a face slot is large: the build reads these often)
        let geometry = |s: &Solid, fs: &[u32]| -> (Vec<octree::SmallBox>, Vec<bsp_core::Plane>) {
            fs.par_iter()
                .map(|&f| (s.face(f).small_box(), *s.face(f).support()))
                .unzip()
        };
        let (boxes_a, planes_a) = geometry(self, &a_c);
        let (boxes_b, planes_b) = geometry(other, &b_c);
        let mut leaves = octree::build(
            root,
            &octree::Faces {
                boxes: &boxes_a,
                plane_meets: |f: u32, c: &IBox| octree::plane_meets(&planes_a[f as usize], c),
            },
            &octree::Faces {
                boxes: &boxes_b,
                plane_meets: |f: u32, c: &IBox| octree::plane_meets(&planes_b[f as usize], c),
            },
            opts.leaf_size,
        );
        drop((boxes_a, planes_a, boxes_b, planes_b));
        if opts.exact_cells {
            // the lists of the leaves holding both, by the exact test
            leaves.par_iter_mut().filter(|l| l.mixed()).for_each(|l| {
                let bx = l.bx;
                l.a.retain(|&f| octree::polygon_meets(self.face(a_c[f as usize]), &bx));
                l.b.retain(|&f| octree::polygon_meets(other.face(b_c[f as usize]), &bx));
            });
        }
        // each face's leaves, by its place in `a_c` and `b_c`
        // (each operand's on its own thread)
        let leaves_of = |n: usize, list: fn(&Leaf) -> &Vec<u32>| {
            let mut of: Vec<SmallVec<[u32; 4]>> = vec![SmallVec::new(); n];
            for (li, l) in leaves.iter().enumerate() {
                for &f in list(l) {
                    of[f as usize].push(li as u32);
                }
            }
            of
        };
        let (a_leaves, b_leaves) = rayon::join(
            || leaves_of(a_c.len(), |l| &l.a),
            || leaves_of(b_c.len(), |l| &l.b),
        );
        // the leaves' lists by face id
        leaves.par_iter_mut().for_each(|l| {
            l.a.iter_mut().for_each(|f| *f = a_c[*f as usize]);
            l.b.iter_mut().for_each(|f| *f = b_c[*f as usize]);
        });
        let adjacent = octree::adjacent(&leaves);
        // the regions free of each surface, and their labels
        let (inside_b, inside_a) = rayon::join(
            || Regions::new(&leaves, &adjacent, |l| l.b.is_empty(), other),
            || Regions::new(&leaves, &adjacent, |l| l.a.is_empty(), self),
        );

        // the faces wholly in free cells, and the pieces of the others
        let root_walls = walls(&root);
        let ((whole_a, pieces_a), (whole_b, pieces_b)) = rayon::join(
            || {
                sort_faces(
                    &a_c,
                    &a_leaves,
                    &leaves,
                    &root,
                    |f| self.face(f).bx(),
                    |l| (&l.a, l.b.is_empty()),
                )
            },
            || {
                sort_faces(
                    &b_c,
                    &b_leaves,
                    &leaves,
                    &root,
                    |f| other.face(f).bx(),
                    |l| (&l.b, l.a.is_empty()),
                )
            },
        );
        // the mixed cells, in parallel; a mixed leaf's lists are its
        // listed faces (`Piece::Mixed` indexes them)
        let mixed: Vec<u32> = (0..leaves.len() as u32)
            .filter(|&l| leaves[l as usize].mixed())
            .collect();
        // The faces that may meet the other surface: those not apart from
        // some face of it in some mixed cell (whole faces, by their
        // support planes). Every other face meets the other surface
        // nowhere (a common point would lie in a cell listing both), so it
        // is kept or dropped whole by one label (`label_untouched`); a
        // mixed cell all of whose faces are such ("clean") does nothing.
        // (without easy cells every mixed cell builds its trees, and the
        // untouched faces take their labels from them: the same result)
        let (meets_a, meets_b, mut clean) = touched(&mixed, &leaves, self, other);
        if !opts.easy_cells {
            clean.iter_mut().for_each(|c| *c = false);
        }
        let touched_a = |f: u32| meets_a.get(f as usize) != Some(&false);
        let touched_b = |f: u32| meets_b.get(f as usize) != Some(&false);
        let untouched_a = |f: u32| !touched_a(f);
        let untouched_b = |f: u32| !touched_b(f);
        // Each cell clips its faces to its walls itself, so that only the
        // cells at work hold their pieces, and finds the pieces that meet
        // no piece of the other surface (isolated). A cell whose pieces are
        // all isolated ("easy") builds nothing: its pieces' labels are
        // carried along their faces from the neighbouring cells
        // (`label_easy`). The others build their partitions and give
        // back what stays.
        let run = |l: u32, allow_easy: bool| -> Result<First, CsgError> {
            let leaf = &leaves[l as usize];
            let (bx, w) = (leaf.bx, walls(&leaf.bx));
            let masks = |pieces: &[Polygon], iso: &[bool], index: &[Option<u32>]| {
                index
                    .iter()
                    .map(|i| {
                        i.filter(|&i| iso[i as usize])
                            .map(|i| local::wall_edges(&pieces[i as usize], &w))
                    })
                    .collect::<Vec<Option<u8>>>()
            };
            // Untouched faces are isolated, and their pieces need no
            // labels of their own (their faces' are known): a cell tries
            // to be easy with only the other faces clipped. Their pieces
            // are the nodes of `label_easy`; an untouched face stands
            // there by its grid corners in the cell, with its label.
            let mut tried = None;
            if allow_easy {
                let (pa, ia) = clip_all(&leaf.a, |f| self.face(f), &bx, &w, &touched_a);
                let (pb, ib) = clip_all(&leaf.b, |f| other.face(f), &bx, &w, &touched_b);
                let (isa, isb) = local::isolated(&pa, &pb);
                if isa.iter().chain(&isb).all(|&x| x) {
                    let (ma, mb) = (masks(&pa, &isa, &ia), masks(&pb, &isb, &ib));
                    let la = Listed::new(&leaf.a, |f| self.face(f), &pa, &ia, touched_a, &bx);
                    let lb = Listed::new(&leaf.b, |f| other.face(f), &pb, &ib, touched_b, &bx);
                    return Ok(First::Easy((ma, la), (mb, lb)));
                }
                tried = Some(((pa, ia), (pb, ib)));
            }
            // every face's piece (those clipped already reused)
            let (pa, ia, pb, ib) = match tried {
                Some(((pa, ia), (pb, ib))) => {
                    let (pa, ia) =
                        clip_rest(&leaf.a, |f| self.face(f), &bx, &w, &touched_a, pa, &ia);
                    let (pb, ib) =
                        clip_rest(&leaf.b, |f| other.face(f), &bx, &w, &touched_b, pb, &ib);
                    (pa, ia, pb, ib)
                }
                None => {
                    let (pa, ia) = clip_all(&leaf.a, |f| self.face(f), &bx, &w, &|_| true);
                    let (pb, ib) = clip_all(&leaf.b, |f| other.face(f), &bx, &w, &|_| true);
                    (pa, ia, pb, ib)
                }
            };
            let (isa, isb) = local::isolated(&pa, &pb);
            let (ma, mb) = (masks(&pa, &isa, &ia), masks(&pb, &isb, &ib));
            let r = bx.0.map(|c| c as i32);
            let c = local::boolean_pieces(
                &bx,
                pa,
                pb,
                op,
                (keep_a, keep_b),
                || self.winding(r),
                || other.winding(r),
            )?;
            Ok(First::Done(Made::of(c, &ia, &ib), ma, mb))
        };
        let first: Vec<(u32, First)> = mixed
            .par_iter()
            .filter(|&&l| !clean[l as usize])
            .map(|&l| run(l, opts.easy_cells).map(|r| (l, r)))
            .collect::<Result<_, _>>()?;
        let mut stats = Stats {
            cells: leaves.len(),
            mixed_cells: mixed.len(),
            clean_cells: mixed.iter().filter(|&&l| clean[l as usize]).count(),
            ..Stats::default()
        };
        let mut add: Vec<Added> = Vec::new();
        let mut fates_a: FxHashMap<u32, Vec<PieceFate>> = FxHashMap::default();
        let mut fates_b: FxHashMap<u32, Vec<PieceFate>> = FxHashMap::default();
        let mut masks_a: FxHashMap<u32, Vec<Option<u8>>> = FxHashMap::default();
        let mut masks_b: FxHashMap<u32, Vec<Option<u8>>> = FxHashMap::default();
        let mut easy: Vec<u32> = Vec::new();
        let mut listed_a: FxHashMap<u32, Listed> = FxHashMap::default();
        let mut listed_b: FxHashMap<u32, Listed> = FxHashMap::default();
        // a cell done: its boundary (merged) or its fates
        let mut done = |l: u32,
                        made: Made,
                        fates_a: &mut FxHashMap<_, _>,
                        fates_b: &mut FxHashMap<_, _>| match made {
            Made::Merged(ps) => {
                stats.merged_cells += 1;
                add.extend(ps.into_iter().map(|p| Added::New(Box::new(p))))
            }
            Made::Fates(fa, fb) => {
                fates_a.insert(l, fa);
                fates_b.insert(l, fb);
            }
        };
        for (l, r) in first {
            match r {
                First::Easy((ma, la), (mb, lb)) => {
                    easy.push(l);
                    masks_a.insert(l, ma);
                    masks_b.insert(l, mb);
                    listed_a.insert(l, la);
                    listed_b.insert(l, lb);
                }
                First::Done(made, ma, mb) => {
                    if matches!(made, Made::Fates(..)) {
                        masks_a.insert(l, ma);
                        masks_b.insert(l, mb);
                    }
                    done(l, made, &mut fates_a, &mut fates_b);
                }
            }
        }
        // the easy cells' labels
        // a piece kept whole is inside when pieces inside are kept
        fn label_of(
            fates: &FxHashMap<u32, Vec<PieceFate>>,
            keep_inside: bool,
        ) -> impl Fn(u32, u32) -> Option<bool> + Sync + '_ {
            move |l: u32, i: u32| match fates.get(&l).map(|v| &v[i as usize]) {
                Some(PieceFate::Keep) => Some(keep_inside),
                Some(PieceFate::Drop) => Some(!keep_inside),
                _ => None,
            }
        }
        // the untouched faces' labels
        let (untouched_la, untouched_lb) = rayon::join(
            || {
                label_untouched(
                    &pieces_a,
                    self.faces.len(),
                    &untouched_a,
                    |f| self.face(f),
                    &leaves,
                    &label_of(&fates_a, keep_a(true)),
                    &|l| inside_b.inside(l),
                    &|g| other.winding(g) != 0,
                )
            },
            || {
                label_untouched(
                    &pieces_b,
                    other.faces.len(),
                    &untouched_b,
                    |f| other.face(f),
                    &leaves,
                    &label_of(&fates_b, keep_b(true)),
                    &|l| inside_a.inside(l),
                    &|g| self.winding(g) != 0,
                )
            },
        );
        // (from the cells that built their trees, free cells, each other
        // and winding numbers; by face id)
        let (face_la, face_lb) = (untouched_la?, untouched_lb?);
        let (labels_a, labels_b) = rayon::join(
            || {
                label_easy(
                    true,
                    |f| self.face(f),
                    &leaves,
                    &adjacent,
                    &masks_a,
                    &listed_a,
                    &label_of(&fates_a, keep_a(true)),
                    &|f| face_la[f as usize],
                    &|l| inside_b.inside(l),
                    &|g| other.winding(g) != 0,
                )
            },
            || {
                label_easy(
                    false,
                    |f| other.face(f),
                    &leaves,
                    &adjacent,
                    &masks_b,
                    &listed_b,
                    &label_of(&fates_b, keep_b(true)),
                    &|f| face_lb[f as usize],
                    &|l| inside_a.inside(l),
                    &|g| self.winding(g) != 0,
                )
            },
        );
        let (mut labels_a, mut labels_b) = (labels_a?, labels_b?);
        drop_aside((listed_a, listed_b));
        // an easy cell with a piece no label reached does the full work
        let mut again: Vec<u32> = Vec::new();
        for l in easy {
            let la = labels_a.remove(&l).expect("an easy cell");
            let lb = labels_b.remove(&l).expect("an easy cell");
            let settled =
                |masks: &[Option<u8>], labels: &[Option<bool>], keep: &dyn Fn(bool) -> bool| {
                    masks
                        .iter()
                        .zip(labels)
                        .map(|(m, lab)| match (m, lab) {
                            (None, _) => Some(PieceFate::Missing),
                            (Some(_), Some(inside)) => Some(if keep(*inside) {
                                PieceFate::Keep
                            } else {
                                PieceFate::Drop
                            }),
                            (Some(_), None) => None,
                        })
                        .collect::<Option<Vec<PieceFate>>>()
                };
            let sa = settled(&masks_a[&l], &la, &keep_a);
            let sb = settled(&masks_b[&l], &lb, &keep_b);
            match (sa, sb) {
                (Some(sa), Some(sb)) => {
                    stats.easy_cells += 1;
                    fates_a.insert(l, sa);
                    fates_b.insert(l, sb);
                }
                _ => again.push(l),
            }
        }
        let redone: Vec<(u32, First)> = again
            .into_par_iter()
            .map(|l| run(l, false).map(|r| (l, r)))
            .collect::<Result<_, _>>()?;
        for (l, r) in redone {
            match r {
                First::Done(made, _, _) => done(l, made, &mut fates_a, &mut fates_b),
                First::Easy(..) => unreachable!("a second run does the full work"),
            }
        }

        // the changes, now that everything is known
        // (decided in parallel, applied in order)
        let mut remove: Vec<u32> = whole_a
            .par_iter()
            .filter(|&&i| {
                let inside =
                    meeting_leaf(self.face(a_c[i as usize]), &a_leaves[i as usize], &leaves)
                        .is_some_and(|l| inside_b.inside(l));
                !keep_a(inside)
            })
            .map(|&i| a_c[i as usize])
            .collect();
        // a piece beyond the octree's box is beyond the other solid's box
        // (an untouched face stays or goes whole by its label; a face the
        // other surface may meet has no piece in a clean cell)
        let settle_all = |pieces: &[(u32, Vec<Piece>)],
                          solid: &Solid,
                          keep: &(dyn Fn(bool) -> bool + Sync),
                          other_side: &Regions,
                          fates: &FxHashMap<u32, Vec<PieceFate>>,
                          labels: &[Option<bool>]|
         -> Result<Settled, CsgError> {
            pieces
                .par_iter()
                .map(|(f, pieces)| {
                    if let Some(inside) = labels[*f as usize] {
                        return Ok((*f, (!keep(inside)).then(Vec::new)));
                    }
                    if pieces
                        .iter()
                        .any(|p| matches!(p, Piece::Mixed(l, _) if clean[*l as usize]))
                    {
                        return Err(CsgError::Internal(
                            "a face the other surface may meet has a piece in a clean cell".into(),
                        ));
                    }
                    let kept = settle(
                        solid.face(*f),
                        pieces,
                        &|l| keep(l.is_some_and(|l| other_side.inside(l))),
                        fates,
                        &leaves,
                        &root_walls,
                    );
                    Ok((*f, kept))
                })
                .collect()
        };
        // the two operands' faces at once (each in parallel, but each
        // with sequential tails)
        let (settled_a, (kept_b, settled_b)) = rayon::join(
            || settle_all(&pieces_a, self, &keep_a, &inside_b, &fates_a, &face_la),
            || {
                rayon::join(
                    // the other solid's faces kept whole are listed, to be
                    // copied or moved over (flipped for a difference)
                    || -> Vec<u32> {
                        whole_b
                            .par_iter()
                            .filter(|&&i| {
                                let inside = meeting_leaf(
                                    other.face(b_c[i as usize]),
                                    &b_leaves[i as usize],
                                    &leaves,
                                )
                                .is_some_and(|l| inside_a.inside(l));
                                keep_b(inside)
                            })
                            .map(|&i| b_c[i as usize])
                            .collect()
                    },
                    || settle_all(&pieces_b, other, &keep_b, &inside_a, &fates_b, &face_lb),
                )
            },
        );
        drop_aside((pieces_a, fates_a, pieces_b, fates_b));
        let (settled_a, settled_b) = (settled_a?, settled_b?);
        for (f, outcome) in settled_a {
            if let Some(kept) = outcome {
                remove.push(f);
                if !kept.is_empty() {
                    stats.cut_faces += 1;
                    stats.pieces += kept.len();
                }
                add.extend(kept.into_iter().map(|p| Added::New(Box::new(p))));
            }
        }
        add.extend(kept_b.into_iter().map(Added::Whole));
        for (f, outcome) in settled_b {
            match outcome {
                None => add.push(Added::Whole(f)),
                Some(kept) => {
                    if !kept.is_empty() {
                        stats.cut_faces += 1;
                        stats.pieces += kept.len();
                    }
                    add.extend(
                        kept.into_iter()
                            .map(|p| Added::New(Box::new(if flip_b { p.flipped() } else { p }))),
                    );
                }
            }
        }
        // the faces away from the shared box: outside the other solid
        if op == BoolOp::Union {
            let mut near = vec![false; other.faces.len()];
            b_c.iter().for_each(|&f| near[f as usize] = true);
            for (i, f) in other.faces.iter().enumerate() {
                if f.is_some() && !near[i] {
                    add.push(Added::Whole(i as u32));
                }
            }
        }
        if op == BoolOp::Intersection {
            let mut near = vec![false; self.faces.len()];
            a_c.iter().for_each(|&f| near[f as usize] = true);
            for i in 0..self.faces.len() as u32 {
                if self.faces[i as usize].is_some() && !near[i as usize] {
                    remove.push(i);
                }
            }
        }
        self.remove_all(&remove);
        // the octree and its lists go on the pool (freeing them here, as
        // the function returns, held up what follows)
        drop_aside((leaves, a_leaves, b_leaves, adjacent, a_c, b_c));
        drop_aside((inside_a, inside_b, masks_a, masks_b, remove));
        Ok((stats, Plan { add, flip: flip_b }))
    }

    /// Carries a plan out: its new faces, then the other solid's faces it
    /// keeps whole, from `other`.
    ///
    /// The faces are made in parallel and written straight into their
    /// slots (freed slots first, in order, then the end of the array),
    /// each moved or copied once; the index takes them while the new
    /// faces' equal new vertices are made one.
    fn carry_out(&mut self, plan: Plan, other: Other<'_>) {
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

/// An operation on two solids, decided ([`Solid::plan_owned`]).
pub struct Planned {
    solid: Solid,
    other: Solid,
    plan: Plan,
    stats: Stats,
}

impl Planned {
    /// What the operation found.
    pub fn stats(&self) -> &Stats {
        &self.stats
    }

    /// The result as a solid, ready for further operations.
    pub fn into_solid(self) -> Solid {
        let Planned {
            mut solid,
            mut other,
            plan,
            ..
        } = self;
        solid.carry_out(plan, Other::Owned(&mut other));
        drop_aside(other);
        solid
    }

    /// The result's watertight mesh, the one [`Planned::into_solid`]'s
    /// [`Solid::into_watertight_mesh`] gives (the same triangles in the
    /// same order), made from the faces where they are: the result's
    /// faces are not moved into one solid, and no index is made for them.
    pub fn into_watertight_mesh(self) -> Result<TriMesh, CsgError> {
        let Planned {
            solid, other, plan, ..
        } = self;
        let Solid {
            faces,
            mut free,
            index,
            ..
        } = solid;
        let Solid {
            faces: mut theirs,
            index: their_index,
            ..
        } = other;
        drop_aside((index, their_index));
        // the faces the plan adds that are not read where they are: new
        // ones (the other solid's kept whole are read in its slots,
        // turned around there for a difference)
        let flip = plan.flip;
        enum Src {
            New(u32),
            Theirs(u32),
        }
        let (mut news, mut turned) = (Vec::new(), Vec::new());
        let srcs: Vec<Src> = plan
            .add
            .into_iter()
            .map(|a| match a {
                Added::New(p) => {
                    news.push(p);
                    Src::New((news.len() - 1) as u32)
                }
                Added::Whole(f) => {
                    if flip {
                        turned.push(f);
                    }
                    Src::Theirs(f)
                }
            })
            .collect();
        // (in place, in parallel: no second copy of the faces kept)
        turned.sort_unstable();
        turned.dedup();
        borrow_sorted(&mut theirs, &turned)
            .into_par_iter()
            .for_each(|slot| {
                let f = slot.as_mut().expect("a live face");
                *f = f.flipped();
            });
        let face = |f: u32| theirs[f as usize].as_ref().expect("a live face");
        {
            // equal new vertices made one, as `carry_out` makes them: the
            // welder then knows them equal at once
            let mut refs: Vec<&mut Polygon> = news.iter_mut().map(|p| &mut **p).collect();
            share_points(&mut refs);
        }
        let news: Vec<Face> = news.into_par_iter().map(Face::made).collect();
        let src = |s: &Src| -> &Face {
            match *s {
                Src::New(i) => &news[i as usize],
                Src::Theirs(f) => face(f),
            }
        };
        // in the order of the slots `carry_out` would put them in: the
        // freed slots first, then the end of the array
        let reused = reused_slots(&mut free, srcs.len());
        let k = reused.len();
        let mut polys: Vec<Option<&Face>> = faces.iter().map(Option::as_ref).collect();
        for (&slot, s) in reused.iter().zip(&srcs) {
            polys[slot as usize] = Some(src(s));
        }
        let polys: Vec<&Face> = polys
            .into_iter()
            .flatten()
            .chain(srcs[k..].iter().map(src))
            .collect();
        let mesh = TriMesh::from_polygons_watertight(&polys).map_err(CsgError::Internal);
        drop(polys);
        drop_aside((faces, theirs, news));
        mesh
    }
}

/// The freed slots the first `n` faces an operation adds go to, in the
/// order they take them (popped from the end of `free`); the rest go at
/// the end of the array. One rule for [`Solid::carry_out`] and for
/// [`Planned::into_watertight_mesh`], which meshes the faces in the
/// order the slots would hold them.
fn reused_slots(free: &mut Vec<u32>, n: usize) -> Vec<u32> {
    let k = n.min(free.len());
    free.drain(free.len() - k..).rev().collect()
}

/// The items at `ids` (strictly increasing), each borrowed once.
fn borrow_sorted<'a, T>(items: &'a mut [T], ids: &[u32]) -> Vec<&'a mut T> {
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
enum Other<'s> {
    /// Its faces are copied.
    Borrowed(&'s Solid),
    /// Its faces move over.
    Owned(&'s mut Solid),
}

/// What an operation adds to the first solid, in order: new faces, and
/// the other solid's faces kept whole (flipped if `flip`).
struct Plan {
    add: Vec<Added>,
    flip: bool,
}

/// A new face, or (`Whole`) the other solid's face kept whole; new faces
/// are boxed so that the many whole ones cost a few bytes each.
enum Added {
    New(Box<Polygon>),
    Whole(u32),
}

/// A piece of a face cut by octree walls: in a cell free of the other
/// surface (or `None`: beyond the octree's box), or in a mixed cell as
/// the `i`-th face of the cell's list; neither is clipped until needed.
enum Piece {
    Free(Option<u32>),
    Mixed(u32, u32),
}

/// Faces wholly in cells free of the other surface (by their place in the
/// list sorted), and the pieces of every other face (by id).
type Sorted = (Vec<u32>, Vec<(u32, Vec<Piece>)>);

/// Faces with pieces, each with what stays of it ([`settle`]).
type Settled = Vec<(u32, Option<Vec<Polygon>>)>;

/// What becomes of a face listed in a mixed cell.
enum PieceFate {
    /// Clipped to the cell, nothing is left of it.
    Missing,
    /// Its piece in the cell stays whole (the face is clipped again, to
    /// the cells it stays whole in joined, when it is settled).
    Keep,
    /// Its piece goes.
    Drop,
    /// The other surface cuts its piece: the fragments that stay.
    Cut(Vec<Polygon>),
}

/// A mixed cell's first run: done, or easy (every piece isolated, the
/// labels to come from the cells around); either way with, per listed
/// face of each operand, the walls an isolated piece crosses
/// ([`local::wall_edges`]; `None` for an untouched face in an easy cell,
/// which is not clipped).
enum First {
    Done(Made, Vec<Option<u8>>, Vec<Option<u8>>),
    Easy((Vec<Option<u8>>, Listed), (Vec<Option<u8>>, Listed)),
}

/// A mixed cell's outcome, per listed face of each operand, or the
/// cell's merged boundary.
enum Made {
    Fates(Vec<PieceFate>, Vec<PieceFate>),
    Merged(Vec<Polygon>),
}

impl Made {
    /// The outcome of a cell's result for its listed faces, `ia` and `ib`
    /// giving each listed face's piece among the result's.
    fn of(c: CellResult, ia: &[Option<u32>], ib: &[Option<u32>]) -> Made {
        let fates = |fates: Vec<Fate>, pieces: Vec<Polygon>, index: &[Option<u32>]| {
            let mut all: Vec<Option<(Fate, Polygon)>> =
                fates.into_iter().zip(pieces).map(Some).collect();
            index
                .iter()
                .map(|i| match i.and_then(|i| all[i as usize].take()) {
                    None => PieceFate::Missing,
                    Some((Fate::Keep, _)) => PieceFate::Keep,
                    Some((Fate::Drop, _)) => PieceFate::Drop,
                    Some((Fate::Cut(frags), _)) => PieceFate::Cut(frags),
                })
                .collect()
        };
        match c {
            CellResult::Merged(ps) => Made::Merged(ps),
            CellResult::Pieces(fa, fb, pa, pb) => Made::Fates(fates(fa, pa, ia), fates(fb, pb, ib)),
        }
    }
}

/// The crossing number of the ray from `q` along `+x` (displaced as
/// [`Solid::winding`] says) with the face `f`: 0 where the face's box is
/// beyond the ray's reach.
fn ray_crossing(q: [i64; 3], f: &Face) -> i32 {
    if ray_reaches(q, &f.bx()) {
        winding::crossing(q, f)
    } else {
        0
    }
}

/// Whether the ray from `q` along `+x` may meet a face in the box `bx`.
#[inline]
fn ray_reaches(q: [i64; 3], bx: &IBox) -> bool {
    bx.1[0] >= q[0] && bx.0[1] <= q[1] && q[1] <= bx.1[1] && bx.0[2] <= q[2] && q[2] <= bx.1[2]
}

/// Queries a solid answers by reading every face before it makes its
/// index ([`Solid::query_index`]).
const SCANS_BEFORE_INDEX: u32 = 8;

/// At most this many winding numbers are found in one pass over a
/// solid's faces that has no index ([`Solid::windings`]).
const FEW_WINDINGS: usize = 64;

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
fn drop_aside<T: Send + 'static>(x: T) {
    rayon::spawn(move || drop(x));
}

/// The faces `fs` clipped to the cell `cell` (walls `w`): the non-empty
/// pieces, in order, and each face's piece among them.
fn clip_all<'p>(
    fs: &[u32],
    face: impl Fn(u32) -> &'p Face,
    cell: &IBox,
    w: &[bsp_core::Plane; 6],
    which: &dyn Fn(u32) -> bool,
) -> (Vec<Polygon>, Vec<Option<u32>>) {
    let mut pieces = Vec::with_capacity(fs.len());
    let index = fs
        .iter()
        .map(|&f| {
            if !which(f) {
                return None;
            }
            let face = face(f);
            local::clip_face(face, cell, w).map(|q| {
                pieces.push(q);
                (pieces.len() - 1) as u32
            })
        })
        .collect();
    (pieces, index)
}

/// [`clip_all`] of every face, given `pieces` and `index` from
/// [`clip_all`] of the faces `done` accepts: those are taken over, the
/// others clipped now (the same pieces, in the same order).
fn clip_rest<'p>(
    fs: &[u32],
    face: impl Fn(u32) -> &'p Face,
    cell: &IBox,
    w: &[bsp_core::Plane; 6],
    done: &dyn Fn(u32) -> bool,
    pieces: Vec<Polygon>,
    index: &[Option<u32>],
) -> (Vec<Polygon>, Vec<Option<u32>>) {
    let mut got: Vec<Option<Polygon>> = pieces.into_iter().map(Some).collect();
    let mut out = Vec::with_capacity(fs.len());
    let index = fs
        .iter()
        .zip(index)
        .map(|(&f, i)| {
            let piece = if done(f) {
                i.and_then(|i| got[i as usize].take())
            } else {
                local::clip_face(face(f), cell, w)
            };
            piece.map(|q| {
                out.push(q);
                (out.len() - 1) as u32
            })
        })
        .collect();
    (out, index)
}

/// Sorts `faces` (their leaves `leaves_of`, by place) into those in free
/// cells only and those with pieces in mixed cells. `side(leaf)` gives the
/// leaf's list of this operand's faces and whether it is free of the
/// other surface; a face's piece in a mixed leaf is named by its place in
/// that list (the leaves list the faces in the order of `faces`).
fn sort_faces<'l>(
    faces: &[u32],
    leaves_of: &[SmallVec<[u32; 4]>],
    leaves: &'l [Leaf],
    root: &IBox,
    bx: impl Fn(u32) -> IBox,
    side: impl Fn(&'l Leaf) -> (&'l Vec<u32>, bool),
) -> Sorted {
    let mut whole = Vec::new();
    let mut pieces = Vec::new();
    // per leaf, the faces met so far
    let mut seen: Vec<u32> = vec![0; leaves.len()];
    let free = |l: u32| side(&leaves[l as usize]).1;
    for (i, (&f, ls)) in faces.iter().zip(leaves_of).enumerate() {
        // a face in no cell lies beyond the octree's box
        if ls.iter().all(|&l| free(l)) {
            whole.push(i as u32);
            continue;
        }
        let mut mine: Vec<Piece> = ls
            .iter()
            .map(|&l| {
                if free(l) {
                    Piece::Free(Some(l))
                } else {
                    let at = seen[l as usize];
                    seen[l as usize] += 1;
                    debug_assert_eq!(side(&leaves[l as usize]).0[at as usize], f);
                    Piece::Mixed(l, at)
                }
            })
            .collect();
        let fb = bx(f);
        if (0..3).any(|k| fb.0[k] < root.0[k] || fb.1[k] > root.1[k]) {
            mine.push(Piece::Free(None));
        }
        pieces.push((f, mine));
    }
    (whole, pieces)
}

/// A leaf among `ls` (the leaves a face's box and plane tests put it in)
/// that the face really meets: the one holding a grid vertex of it,
/// else the first one its clipping leaves something in. The lists may
/// name leaves the face does not reach, whose region may lie on the other
/// side of the other surface; `None` if it meets none (it lies beyond the
/// octree's box, so beyond the other solid).
fn meeting_leaf(face: &Face, ls: &[u32], leaves: &[Leaf]) -> Option<u32> {
    for i in 0..face.corner_count() {
        if let Some(g) = face.corner(i).as_grid()
            && let Some(&l) = ls.iter().find(|&&l| holds(&leaves[l as usize].bx, &g))
        {
            return Some(l);
        }
    }
    let poly = face.polygon();
    let fb = face.bx();
    ls.iter().copied().find(|&l| {
        let bx = &leaves[l as usize].bx;
        local::clip_in(&poly, &fb, bx, &walls(bx)).is_some()
    })
}

/// What stays of a face cut into `pieces`: `None` if every piece stays
/// (the face stays as it is), else the kept pieces and fragments.
/// `keep_free(cell)` says whether a piece in a free cell (`None`: beyond
/// the octree's box) stays; `fates` are the mixed cells' (the fragments
/// kept are copied: faces settle in parallel). The face is clipped anew
/// to the cells whose piece stays whole, joined into larger boxes.
fn settle(
    face: &Face,
    pieces: &[Piece],
    keep_free: &dyn Fn(Option<u32>) -> bool,
    fates: &FxHashMap<u32, Vec<PieceFate>>,
    leaves: &[Leaf],
    root: &[bsp_core::Plane; 6],
) -> Option<Vec<Polygon>> {
    // `None`: the piece is in a merged cell's output
    let fate = |p: &Piece| match p {
        Piece::Free(l) if keep_free(*l) => Some(Ok(())),
        Piece::Free(_) => Some(Err(())),
        Piece::Mixed(l, i) => fates.get(l).map(|v| match &v[*i as usize] {
            PieceFate::Missing | PieceFate::Keep => Ok(()),
            PieceFate::Drop | PieceFate::Cut(_) => Err(()),
        }),
    };
    if pieces.iter().all(|p| fate(p) == Some(Ok(()))) {
        return None;
    }
    // the cells whose piece stays whole (the face clipped to the cell),
    // and the fragments of the cells that cut it
    let mut kept = Vec::new();
    let mut whole: Vec<IBox> = Vec::new();
    for p in pieces {
        match p {
            Piece::Free(Some(l)) if keep_free(Some(*l)) => whole.push(leaves[*l as usize].bx),
            Piece::Free(None) if keep_free(None) => {
                kept.extend(local::outside(&face.polygon(), root))
            }
            Piece::Free(_) => {}
            Piece::Mixed(l, i) => match fates.get(l).map(|v| &v[*i as usize]) {
                Some(PieceFate::Keep) => whole.push(leaves[*l as usize].bx),
                Some(PieceFate::Cut(frags)) => kept.extend(frags.iter().cloned()),
                _ => {}
            },
        }
    }
    // the face clipped to the boxes those cells join into: the same
    // region in fewer pieces than a piece per cell (a face crossing many
    // small cells has dozens), so fewer clips and fewer to put together
    join_boxes(&mut whole);
    kept.extend(
        whole
            .iter()
            .filter_map(|bx| local::clip_face(face, bx, &walls(bx))),
    );
    Some(rejoin(kept))
}

/// Joins boxes that tile space without overlap into fewer boxes covering
/// the same points: two boxes join where they share a whole wall (the
/// same extent along two axes, one just after the other along the
/// third), axis after axis, until none do. The result does not depend on
/// the boxes' order.
fn join_boxes(boxes: &mut Vec<IBox>) {
    loop {
        let before = boxes.len();
        for k in 0..3 {
            let (u, v) = ((k + 1) % 3, (k + 2) % 3);
            let rest = |b: &IBox| (b.0[u], b.1[u], b.0[v], b.1[v]);
            boxes.sort_unstable_by_key(|b| (rest(b), b.0[k]));
            let mut joined: Vec<IBox> = Vec::with_capacity(boxes.len());
            for b in boxes.drain(..) {
                match joined.last_mut() {
                    Some(last) if rest(last) == rest(&b) && last.1[k] + 1 == b.0[k] => {
                        last.1[k] = b.1[k]
                    }
                    _ => joined.push(b),
                }
            }
            *boxes = joined;
        }
        if boxes.len() == before {
            return;
        }
    }
}

/// The kept pieces of one face put back together where two share a whole
/// edge and their union is convex ([`Polygon::merge`]): the cells' walls
/// cut a face into pieces that the other surface does not separate, and
/// a piece per cell would be a polygon per cell in the result (more
/// vertices to weld, more triangles). The same region, exactly; pieces
/// whose edges meet partly (a T-junction) stay apart.
fn rejoin(pieces: Vec<Polygon>) -> Vec<Polygon> {
    if pieces.len() < 2 {
        return pieces;
    }
    // the endpoints' approximate keys: a pair of equal points that gets
    // two keys is only a merge missed, and a merge is decided exactly
    let keys_of = |p: &Polygon| -> SmallVec<[u64; 8]> {
        p.vertices()
            .iter()
            .map(bsp_core::Point::approx_key)
            .collect()
    };
    // each directed edge's latest polygon; an entry left by a polygon
    // merged since only costs a merge that fails
    let mut edges: FxHashMap<(u64, u64), u32> = FxHashMap::default();
    let add_edges = |edges: &mut FxHashMap<(u64, u64), u32>, ks: &[u64], i: usize| {
        for e in 0..ks.len() {
            edges.insert((ks[e], ks[(e + 1) % ks.len()]), i as u32);
        }
    };
    let mut keys: Vec<SmallVec<[u64; 8]>> = pieces.iter().map(keys_of).collect();
    for (i, ks) in keys.iter().enumerate() {
        add_edges(&mut edges, ks, i);
    }
    let mut live: Vec<Option<Polygon>> = pieces.into_iter().map(Some).collect();
    // each polygon looks for a partner across its edges; one that grew
    // looks again
    let mut work: Vec<usize> = (0..live.len()).rev().collect();
    while let Some(i) = work.pop() {
        let Some(p) = live[i].as_ref() else { continue };
        let ks = &keys[i];
        let partner = (0..ks.len()).find_map(|e| {
            let j = *edges.get(&(ks[(e + 1) % ks.len()], ks[e]))? as usize;
            if j == i {
                return None;
            }
            p.merge(live[j].as_ref()?).map(|m| (j, m))
        });
        if let Some((j, m)) = partner {
            keys[i] = keys_of(&m);
            add_edges(&mut edges, &keys[i], i);
            live[i] = Some(m);
            live[j] = None;
            work.push(i);
        }
    }
    live.into_iter().flatten().collect()
}

/// The wall of the cell `s` that faces the cell `l`, if they are
/// neighbours across it and the wall's rectangle of `s` lies within `l`'s
/// (index into [`walls`]).
fn facing(s: &IBox, l: &IBox) -> Option<usize> {
    for k in 0..3 {
        let wall = if s.1[k] + 1 == l.0[k] {
            2 * k + 1
        } else if l.1[k] + 1 == s.0[k] {
            2 * k
        } else {
            continue;
        };
        let within = (0..3)
            .filter(|&j| j != k)
            .all(|j| l.0[j] <= s.0[j] && s.1[j] <= l.1[j]);
        return within.then_some(wall);
    }
    None
}

/// One operand's listed faces in an easy cell: a grid vertex of each
/// piece, and the pairs of pieces sharing a grid vertex.
struct Listed {
    grid: Vec<Option<GridPoint>>,
    touch: Vec<(u32, u32)>,
}

impl Listed {
    /// From the grid vertices of each listed face's piece in the cell:
    /// its clipped piece's (`index` into `pieces`), or for a face not
    /// clipped, its grid corners in the cell's box `bx` (the same points:
    /// the walls hold no grid point).
    fn new<'p>(
        fs: &[u32],
        face: impl Fn(u32) -> &'p Face,
        pieces: &[Polygon],
        index: &[Option<u32>],
        clipped: impl Fn(u32) -> bool,
        bx: &IBox,
    ) -> Listed {
        let grid_of = |p: &Polygon| -> SmallVec<[GridPoint; 4]> {
            p.vertices()
                .iter()
                .filter_map(|v| match v {
                    bsp_core::Point::Grid(g) => Some(*g),
                    _ => None,
                })
                .collect()
        };
        let verts: Vec<SmallVec<[GridPoint; 4]>> = fs
            .iter()
            .zip(index)
            .map(|(&f, i)| {
                if clipped(f) {
                    return i.map_or_else(SmallVec::new, |i| grid_of(&pieces[i as usize]));
                }
                let face = face(f);
                (0..face.corner_count())
                    .filter_map(|k| face.corner(k).as_grid())
                    .filter(|g| holds(bx, g))
                    .collect()
            })
            .collect();
        let mut touch = Vec::new();
        for i in 0..verts.len() {
            for j in i + 1..verts.len() {
                if verts[i].iter().any(|g| verts[j].contains(g)) {
                    touch.push((i as u32, j as u32));
                }
            }
        }
        Listed {
            grid: verts.iter().map(|v| v.first().copied()).collect(),
            touch,
        }
    }
}

/// Labels (inside the other solid or not) for one operand's pieces in
/// the easy cells (`listed`), per cell and listed face; `None` where no
/// label reached a piece.
///
/// A piece meeting no piece of the other surface in its cell (isolated)
/// has one label: the other surface does not meet its inside, which lies
/// in the open cell. Pieces with the same label are joined, and the
/// groups take their label from a member whose label is known:
///
/// - Two pieces of one face in neighbouring cells `s` and `l`, when `s`'s
///   piece crosses the wall into `l` ([`local::wall_edges`]: an edge on
///   `s`'s wall facing `l`, with a point `y` inside the wall's rectangle,
///   which lies within `l`'s) and each is isolated or in a cell free of
///   the other surface. A face of the other surface through `y` would have
///   a piece in `s` or `l` (no face lies in a wall) meeting one of them,
///   so a small disc of the face around `y` is free of it and joins the
///   two pieces.
/// - Two isolated pieces of one cell sharing a grid vertex: a small ball
///   around it is free of the other surface.
///
/// Known labels: a face's piece in a free cell (its region's winding
/// number), an isolated piece of a cell that built its partitions
/// (`known`), a piece of a face labelled as a whole (`face_label`: an
/// untouched face, which an easy cell does not clip), and, for a group no
/// known label reaches, the winding number `inside` of a grid vertex of
/// one of its pieces.
#[allow(clippy::too_many_arguments)]
fn label_easy<'p>(
    side_a: bool,
    face: impl Fn(u32) -> &'p Face + Sync,
    leaves: &[Leaf],
    adjacent: &[(u32, u32)],
    masks: &FxHashMap<u32, Vec<Option<u8>>>,
    listed: &FxHashMap<u32, Listed>,
    known: &(dyn Fn(u32, u32) -> Option<bool> + Sync),
    face_label: &(dyn Fn(u32) -> Option<bool> + Sync),
    free_inside: &(dyn Fn(u32) -> bool + Sync),
    inside: &(dyn Fn(GridPoint) -> bool + Sync),
) -> Result<FxHashMap<u32, Vec<Option<bool>>>, CsgError> {
    // a leaf's faces of this operand (ascending ids; in a mixed leaf, in
    // the order of its listed faces), and whether it is free of the other
    let list = |l: u32| -> &[u32] {
        let leaf = &leaves[l as usize];
        if side_a { &leaf.a } else { &leaf.b }
    };
    let free = |l: u32| {
        let leaf = &leaves[l as usize];
        if side_a {
            leaf.b.is_empty()
        } else {
            leaf.a.is_empty()
        }
    };
    // nodes: 0 and 1 stand for the labels outside and inside, then the
    // listed faces of each easy cell from its base
    let mut base: FxHashMap<u32, u32> = FxHashMap::default();
    let mut cells: Vec<u32> = listed.keys().copied().collect();
    cells.sort_unstable();
    let mut n = 2u32;
    for &l in &cells {
        base.insert(l, n);
        n += listed[&l].grid.len() as u32;
    }
    // the node of the `i`-th listed face of a mixed cell, if it has one
    let node = |l: u32, i: u32| -> Option<u32> {
        masks.get(&l).and_then(|v| v[i as usize])?;
        match base.get(&l) {
            Some(b) => Some(b + i),
            None => known(l, i).map(u32::from),
        }
    };
    // the easy cells' neighbours
    let mut around: FxHashMap<u32, Vec<u32>> = FxHashMap::default();
    for &(x, y) in adjacent {
        for (p, q) in [(x, y), (y, x)] {
            if base.contains_key(&p) {
                around.entry(p).or_default().push(q);
            }
        }
    }
    // each easy cell's pieces joined with the same face's pieces in the
    // cells around, across the walls the smaller of the two crosses
    let mut joins: Vec<(u32, u32)> = cells
        .par_iter()
        .flat_map_iter(|&l| {
            let (b, fs) = (base[&l], list(l));
            let ml = &masks[&l];
            let mut out = Vec::new();
            for &m in around.get(&l).map_or(&[][..], |v| &v[..]) {
                let (bl, bm) = (&leaves[l as usize].bx, &leaves[m as usize].bx);
                let (here, there) = (facing(bl, bm), facing(bm, bl));
                if here.is_none() && there.is_none() {
                    continue;
                }
                let others = list(m);
                for (i, &f) in fs.iter().enumerate() {
                    let Some(mask) = ml[i] else { continue };
                    let Ok(j) = others.binary_search(&f) else {
                        continue;
                    };
                    // the face's piece in `m`: its node, and the walls it
                    // crosses (a free cell's piece is clipped when needed)
                    let (other, other_mask) = if free(m) {
                        (free_inside(m) as u32, None)
                    } else {
                        let Some(node) = node(m, j as u32) else {
                            continue;
                        };
                        (node, masks[&m][j])
                    };
                    let linked = match (here, there) {
                        (Some(w), _) => mask & (1 << w) != 0,
                        (None, Some(w)) => {
                            let mm = other_mask.unwrap_or_else(|| {
                                let (wm, g) = (walls(bm), face(f));
                                local::clip_face(g, bm, &wm)
                                    .map_or(0, |q| local::wall_edges(&q, &wm))
                            });
                            mm & (1 << w) != 0
                        }
                        (None, None) => false,
                    };
                    if linked {
                        out.push((b + i as u32, other));
                    }
                }
            }
            out
        })
        .collect();
    for &l in &cells {
        let b = base[&l];
        joins.extend(listed[&l].touch.iter().map(|&(i, j)| (b + i, b + j)));
        // a face whose label is known as a whole (untouched)
        joins.extend(
            list(l)
                .iter()
                .enumerate()
                .filter_map(|(i, &f)| face_label(f).map(|x| (b + i as u32, u32::from(x)))),
        );
    }
    let mut groups = UnionFind::new(n as usize);
    for (a, b) in joins {
        groups.join(a, b);
    }
    if groups.find(1) == 0 {
        return Err(CsgError::Internal(
            "an easy cell's pieces got both labels".into(),
        ));
    }
    // groups no known label reached: the winding number at a grid vertex
    let mut asked: FxHashMap<u32, GridPoint> = FxHashMap::default();
    for &l in &cells {
        let b = base[&l];
        for (i, g) in listed[&l].grid.iter().enumerate() {
            if let Some(g) = g {
                let r = groups.find(b + i as u32);
                if r >= 2 {
                    asked.entry(r).or_insert(*g);
                }
            }
        }
    }
    let mut asked: Vec<(u32, GridPoint)> = asked.into_iter().collect();
    asked.sort_unstable();
    groups.answer(&asked, inside);
    let mut out = FxHashMap::default();
    for &l in &cells {
        let b = base[&l];
        let labels = (0..listed[&l].grid.len() as u32)
            .map(|i| groups.label(b + i))
            .collect();
        out.insert(l, labels);
    }
    Ok(out)
}

/// For each face of `a` and of `b` (by id; `false` for faces in no
/// mixed cell), whether it may meet the other surface: it is not apart
/// ([`local::apart`], whole faces) from some face of the other in some
/// mixed cell of `mixed`, or it has no grid corner (where its label could
/// be asked), or it is listed in a mixed cell where faces of the two
/// share a plane (which may be merged whole, pieces and all); and per
/// leaf, whether it is a clean mixed cell: one whose faces all are
/// untouched.
///
/// An untouched face meets the other surface nowhere: a common point
/// would lie in some leaf's closed cell, whose lists hold every face
/// meeting it (box and plane), so that leaf would be mixed and the two
/// faces tested there, and faces with a common point are never apart.
fn touched(
    mixed: &[u32],
    leaves: &[Leaf],
    a: &Solid,
    b: &Solid,
) -> (Vec<bool>, Vec<bool>, Vec<bool>) {
    let no_grid_corner = |f: &Face| (0..f.corner_count()).all(|i| f.corner(i).as_grid().is_none());
    let per_cell: Vec<(Vec<u32>, Vec<u32>)> = mixed
        .par_iter()
        .map(|&l| {
            let leaf = &leaves[l as usize];
            let fa: Vec<&Face> = leaf.a.iter().map(|&f| a.face(f)).collect();
            let fb: Vec<&Face> = leaf.b.iter().map(|&f| b.face(f)).collect();
            // a cell where faces of the two share a plane may be merged
            // as a whole (`local::boolean_pieces`): all its faces settle
            // piece by piece
            let shared = fa
                .iter()
                .any(|p| fb.iter().any(|q| p.support().is_coincident(q.support())));
            if shared {
                return (leaf.a.clone(), leaf.b.clone());
            }
            let mut ta: Vec<bool> = fa.iter().map(|f| no_grid_corner(f)).collect();
            let mut tb: Vec<bool> = fb.iter().map(|f| no_grid_corner(f)).collect();
            for (i, p) in fa.iter().enumerate() {
                for (j, q) in fb.iter().enumerate() {
                    if ta[i] && tb[j] {
                        continue; // both known already
                    }
                    if !local::apart(*p, *q) {
                        ta[i] = true;
                        tb[j] = true;
                    }
                }
            }
            let pick = |fs: &[u32], t: &[bool]| -> Vec<u32> {
                fs.iter()
                    .zip(t)
                    .filter(|(_, t)| **t)
                    .map(|(f, _)| *f)
                    .collect()
            };
            (pick(&leaf.a, &ta), pick(&leaf.b, &tb))
        })
        .collect();
    let (mut ta, mut tb) = (vec![false; a.faces.len()], vec![false; b.faces.len()]);
    for (xa, xb) in &per_cell {
        xa.iter().for_each(|&f| ta[f as usize] = true);
        xb.iter().for_each(|&f| tb[f as usize] = true);
    }
    let mut clean = vec![false; leaves.len()];
    for &l in mixed {
        let leaf = &leaves[l as usize];
        clean[l as usize] =
            leaf.a.iter().all(|&f| !ta[f as usize]) && leaf.b.iter().all(|&f| !tb[f as usize]);
    }
    (ta, tb, clean)
}

/// The labels (inside the other solid or not) of the untouched faces
/// among `pieces`, by face id (`n` ids; `None` for the others), each one
/// label for the whole face, which meets the other surface nowhere:
///
/// - a grid corner of it in a free cell of its own: that cell's region's
///   label;
/// - a piece of it whose fate in a mixed cell is known (`known`);
/// - another untouched face of this operand with a common grid corner
///   (a small ball around the corner is free of the other surface);
/// - for a group none of these reach, the winding number `inside` at a
///   grid corner of its first face (every untouched face has one).
#[allow(clippy::too_many_arguments)]
fn label_untouched<'p>(
    pieces: &[(u32, Vec<Piece>)],
    n: usize,
    untouched: &(dyn Fn(u32) -> bool + Sync),
    face: impl Fn(u32) -> &'p Face + Sync,
    leaves: &[Leaf],
    known: &(dyn Fn(u32, u32) -> Option<bool> + Sync),
    free_inside: &(dyn Fn(u32) -> bool + Sync),
    inside: &(dyn Fn(GridPoint) -> bool + Sync),
) -> Result<Vec<Option<bool>>, CsgError> {
    let corners = |f: u32| -> SmallVec<[GridPoint; 4]> {
        let face = face(f);
        (0..face.corner_count())
            .filter_map(|i| face.corner(i).as_grid())
            .collect()
    };
    // `None`: touched; `Some(None)`: untouched, no label of its own yet
    let own: Vec<Option<Option<bool>>> = pieces
        .par_iter()
        .map(|(f, ps)| {
            if !untouched(*f) {
                return None;
            }
            let cs = corners(*f);
            let corner_in = |l: u32| cs.iter().any(|g| holds(&leaves[l as usize].bx, g));
            let label = ps.iter().find_map(|p| match *p {
                Piece::Free(Some(l)) if corner_in(l) => Some(free_inside(l)),
                Piece::Mixed(l, i) => known(l, i),
                _ => None,
            });
            Some(label)
        })
        .collect();
    let by_id = |label: &dyn Fn(usize) -> Result<Option<bool>, CsgError>| {
        let mut out: Vec<Option<bool>> = vec![None; n];
        for (i, (f, _)) in pieces.iter().enumerate() {
            out[*f as usize] = label(i)?;
        }
        Ok(out)
    };
    if own.iter().all(|x| !matches!(x, Some(None))) {
        return by_id(&|i| Ok(own[i].flatten()));
    }
    // nodes: the two labels, then the faces by place
    let mut groups = UnionFind::new(pieces.len() + 2);
    let mut first: FxHashMap<GridPoint, u32> = FxHashMap::default();
    for (i, x) in own.iter().enumerate() {
        let Some(label) = x else { continue };
        let node = i as u32 + 2;
        if let Some(inside) = label {
            groups.join(node, u32::from(*inside));
        }
        for g in corners(pieces[i].0) {
            let at = *first.entry(g).or_insert(node);
            groups.join(node, at);
        }
    }
    if groups.find(1) == 0 {
        return Err(CsgError::Internal(
            "an untouched face got both labels".into(),
        ));
    }
    // groups no label reached: the winding number at a grid corner
    let mut asked: Vec<(u32, GridPoint)> = Vec::new();
    let mut seen: rustc_hash::FxHashSet<u32> = Default::default();
    for (i, x) in own.iter().enumerate() {
        if x.is_some() {
            let r = groups.find(i as u32 + 2);
            if r >= 2 && seen.insert(r) {
                asked.push((r, corners(pieces[i].0)[0]));
            }
        }
    }
    groups.answer(&asked, inside);
    let labels: Vec<Option<bool>> = (0..pieces.len())
        .map(|i| groups.label(i as u32 + 2))
        .collect();
    by_id(&|i| match own[i] {
        None => Ok(None),
        Some(_) => labels[i]
            .map(Some)
            .ok_or_else(|| CsgError::Internal("an untouched face got no label".into())),
    })
}

/// Groups of nodes `0..n` by union and find; a group's root is its
/// smallest node, so where nodes 0 and 1 stand for the labels outside and
/// inside, they stay roots and name their groups' label.
struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    fn new(n: usize) -> UnionFind {
        UnionFind {
            parent: (0..n as u32).collect(),
        }
    }

    fn find(&mut self, mut x: u32) -> u32 {
        let p = &mut self.parent;
        while p[x as usize] != x {
            p[x as usize] = p[p[x as usize] as usize];
            x = p[x as usize];
        }
        x
    }

    fn join(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.parent[ra.max(rb) as usize] = ra.min(rb);
        }
    }

    /// Joins each group `(root, g)` of `asked` to the label `inside(g)`
    /// (asked in parallel).
    fn answer(&mut self, asked: &[(u32, GridPoint)], inside: &(dyn Fn(GridPoint) -> bool + Sync)) {
        let answers: Vec<(u32, bool)> = asked.par_iter().map(|&(r, g)| (r, inside(g))).collect();
        for (r, x) in answers {
            self.join(r, u32::from(x));
        }
    }

    /// The label of node `x`'s group: `Some(inside)`, or `None` if no
    /// label reached it.
    fn label(&mut self, x: u32) -> Option<bool> {
        match self.find(x) {
            0 => Some(false),
            1 => Some(true),
            _ => None,
        }
    }
}

/// Connected regions of octree cells free of one surface, each wholly
/// inside or outside that surface's solid.
struct Regions {
    root: Vec<u32>,
    inside: FxHashMap<u32, bool>,
}

impl Regions {
    fn new(
        leaves: &[Leaf],
        adjacent: &[(u32, u32)],
        free: impl Fn(&Leaf) -> bool,
        solid: &Solid,
    ) -> Regions {
        let n = leaves.len();
        let mut groups = UnionFind::new(n);
        for &(a, b) in adjacent {
            if free(&leaves[a as usize]) && free(&leaves[b as usize]) {
                groups.join(a, b);
            }
        }
        let root: Vec<u32> = (0..n as u32).map(|x| groups.find(x)).collect();
        // one winding number per region that holds faces to label
        let mut wanted: Vec<u32> = (0..n)
            .filter(|&l| free(&leaves[l]) && !(leaves[l].a.is_empty() && leaves[l].b.is_empty()))
            .map(|l| root[l])
            .collect();
        wanted.sort_unstable();
        wanted.dedup();
        let qs: Vec<GridPoint> = wanted
            .iter()
            .map(|&r| leaves[r as usize].bx.0.map(|c| c as i32))
            .collect();
        let inside: FxHashMap<u32, bool> = wanted
            .iter()
            .zip(solid.windings(&qs))
            .map(|(&r, w)| (r, w != 0))
            .collect();
        Regions { root, inside }
    }

    fn inside(&self, leaf: u32) -> bool {
        self.inside[&self.root[leaf as usize]]
    }
}

/// Snaps both meshes to one grid, checks them, and computes `a op b`.
pub fn mesh_boolean(a: &MeshIn<'_>, b: &MeshIn<'_>, op: BoolOp) -> Result<Boolean, CsgError> {
    mesh_sequence(a, &[(op, *b)])
}

/// Checks that operand `operand` is a closed, consistently oriented
/// 2-manifold ([`check_closed_manifold`]).
pub fn check_mesh(m: &MeshIn<'_>, operand: usize) -> Result<(), CsgError> {
    check_closed_manifold(m.faces.iter().map(Vec::as_slice))
        .map_err(|error| CsgError::Topology { operand, error })
}

/// The snapped operands: one grid for all, and per mesh its solid and what
/// snapping did to its faces.
#[derive(Clone, Debug)]
pub struct Snapped {
    /// The grid every operand is snapped to.
    pub grid: Grid,
    /// The solids, in the order of the meshes.
    pub solids: Vec<Solid>,
    /// What snapping did to each mesh's faces.
    pub reports: Vec<ImportReport>,
}

/// Snaps `meshes` (already checked with [`check_mesh`]) to one grid and
/// makes their solids. Fails with [`CsgError::Inward`] for a mesh whose
/// snapped faces bound a negative volume (exact).
///
/// For a long sequence of operands, [`fit_grid`] and [`snap_one`] make
/// each solid only when it is needed, so that the solids of operands not
/// yet used do not take memory.
pub fn snap(meshes: &[MeshIn<'_>]) -> Result<Snapped, CsgError> {
    let grid = fit_grid(meshes)?;
    let mut reports = Vec::with_capacity(meshes.len());
    let mut solids = Vec::with_capacity(meshes.len());
    for (i, m) in meshes.iter().enumerate() {
        let (solid, report) = snap_one(&grid, m, i)?;
        reports.push(report);
        solids.push(solid);
    }
    Ok(Snapped {
        grid,
        solids,
        reports,
    })
}

/// The grid [`snap`] puts `meshes` on: one that holds every position of
/// every mesh.
pub fn fit_grid(meshes: &[MeshIn<'_>]) -> Result<Grid, CsgError> {
    Grid::fit_points(meshes.iter().flat_map(|m| m.positions.iter())).map_err(CsgError::Grid)
}

/// The solid of one mesh (already checked with [`check_mesh`]) on `grid`
/// (from [`fit_grid`] over every mesh of the computation), and what
/// snapping did to its faces; `operand` is its position, for
/// [`CsgError::Inward`].
pub fn snap_one(
    grid: &Grid,
    mesh: &MeshIn<'_>,
    operand: usize,
) -> Result<(Solid, ImportReport), CsgError> {
    // each face's polygon goes straight into the face's slot, in
    // parallel: a solid's faces are most of its memory, and a list of
    // polygons moved into the slots after would be made and touched once
    // more; the rare extra polygons of triangulated faces go after
    const CHUNK: usize = 4096;
    let n = mesh.faces.len();
    let mut faces: Vec<Option<Face>> = Vec::with_capacity(n);
    faces.par_extend((0..n).into_par_iter().map(|_| None));
    // each vertex snapped once, not once per face around it
    let snapped = bsp_core::internals::snap_positions(grid, mesh.positions);
    type Run = (ImportReport, Vec<Face>, i128);
    let runs: Vec<Result<Run, bsp_core::Error>> = faces
        .par_chunks_mut(CHUNK)
        .zip(mesh.faces.par_chunks(CHUNK))
        .enumerate()
        .map(|(c, (slots, loops))| {
            let mut imp = bsp_core::internals::FaceImporter::default();
            let (mut extra, mut six) = (Vec::new(), 0i128);
            for (i, (slot, face)) in slots.iter_mut().zip(loops).enumerate() {
                imp.indexed_snapped(grid, mesh.positions, &snapped, face, c * CHUNK + i, |p| {
                    six += six_volume(&p);
                    let face = Face::grid(p);
                    match slot {
                        None => *slot = Some(face),
                        Some(_) => extra.push(face),
                    }
                })?;
            }
            Ok((imp.finish(), extra, six))
        })
        .collect();
    // the first error in face order, as a sequential import gives
    let mut report = ImportReport::default();
    let mut sign = 0i128;
    let mut extra = Vec::new();
    for run in runs {
        let (r, e, six) = run.map_err(CsgError::Grid)?;
        report.add(r);
        extra.extend(e);
        sign += six;
    }
    if sign < 0 {
        return Err(CsgError::Inward { operand });
    }
    faces.extend(extra.into_iter().map(Some));
    // a dropped face left its slot empty (the lowest is reused first)
    let free = report
        .dropped
        .iter()
        .rev()
        .map(|&(f, _)| f as u32)
        .collect();
    Ok((Solid::from_faces(faces, free), report))
}

/// `((first op₁ m₁) op₂ m₂) ...` on one grid: every operand is checked
/// and snapped once, its solid made only when its turn comes, and each
/// operation works on the previous result in place (so a long sequence
/// holds the result and one operand's solid at a time).
pub fn mesh_sequence(
    first: &MeshIn<'_>,
    ops: &[(BoolOp, MeshIn<'_>)],
) -> Result<Boolean, CsgError> {
    let all: Vec<MeshIn<'_>> = std::iter::once(*first)
        .chain(ops.iter().map(|(_, m)| *m))
        .collect();
    for (i, m) in all.iter().enumerate() {
        check_mesh(m, i)?;
    }
    // each operand's solid is made when its turn comes
    let grid = fit_grid(&all)?;
    let (mut solid, report) = snap_one(&grid, first, 0)?;
    let mut reports = vec![report];
    for (i, (op, m)) in ops.iter().enumerate() {
        let (other, report) = snap_one(&grid, m, i + 1)?;
        reports.push(report);
        solid.apply_owned(other, *op)?;
    }
    let mesh = solid.to_watertight_mesh()?;
    Ok(Boolean {
        mesh,
        grid,
        solid,
        reports,
    })
}

/// Six times the signed volume of the cone from the origin over an
/// imported polygon (a fan of grid vertices); summed over a closed
/// surface, six times the volume it bounds. Coordinates below 2^26 keep
/// each cross product's coordinates below 2^53 (in `i64`) and each term
/// below 2^81 (in `i128`).
fn six_volume(p: &GridPolygon) -> i128 {
    let g = p.vertices();
    let a = g[0].map(i128::from);
    g[1..]
        .windows(2)
        .map(|w| {
            let (b, c) = (w[0].map(i64::from), w[1].map(i64::from));
            let n = [
                b[1] * c[2] - b[2] * c[1],
                b[2] * c[0] - b[0] * c[2],
                b[0] * c[1] - b[1] * c[0],
            ];
            a[0] * n[0] as i128 + a[1] * n[1] as i128 + a[2] * n[2] as i128
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use bsp_core::Plane;
    use bsp_core::internals::Parts;

    /// The same points in the same cyclic order.
    fn same_loop(a: &Polygon, b: &Polygon) -> bool {
        let (x, y) = (a.vertices(), b.vertices());
        let n = x.len();
        n == y.len() && (0..n).any(|r| (0..n).all(|i| x[i].same_point(&y[(i + r) % n])))
    }

    /// `p` cut by the walls `x = 4, 8, 12` and `y = 4, 8, 12`: up to 16
    /// pieces, one per cell, as the cells' clipping leaves them.
    fn cells_of(p: &Polygon) -> Vec<Polygon> {
        let mut pieces = vec![p.clone()];
        for k in 0..2 {
            for w in [4i128, 8, 12] {
                let mut n = [0; 3];
                n[k] = 1;
                let wall = Plane::new(n, -w).unwrap();
                pieces = pieces
                    .into_iter()
                    .flat_map(|q| match q.parts(&wall) {
                        Parts::Split { front, back } => vec![back, front],
                        Parts::Whole(_) => vec![q],
                    })
                    .collect();
            }
        }
        pieces
    }

    /// A face slot stays small (it is most of a solid's memory), and an
    /// imported face's box read off its corners is the box of its
    /// polygon, as a made face's stored one is.
    #[test]
    fn face_slots_are_small_and_know_their_boxes() {
        assert!(std::mem::size_of::<Face>() <= 112);
        let g = GridPolygon::from_grid_points(&[[5, -7, 1], [9, 2, -3], [-4, 0, 8]]).unwrap();
        let want = polygon_box(&g);
        let grid = Face::grid(g.clone());
        assert_eq!(grid.bx(), want);
        assert_eq!(grid.flipped().bx(), want);
        let made = Face::made(Box::new(g.to_polygon(0)));
        assert_eq!(made.bx(), want);
        assert_eq!(made.flipped().bx(), want);
    }

    #[test]
    fn triangulated_and_dropped_faces_keep_their_slots_straight() {
        // an L-shaped prism (its top and bottom are non-convex hexagons,
        // imported as triangles after the other faces), with a vertex 12
        // on the edge 0-1 and a sliver face 0 12 1 without area (dropped,
        // its slot left empty), united with a unit cube in its notch
        let v = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        let mut positions = Vec::new();
        for z in [0.0, 1.0] {
            for (x, y) in [(0., 0.), (2., 0.), (2., 1.), (1., 1.), (1., 2.), (0., 2.)] {
                positions.push(v(x, y, z));
            }
        }
        positions.push(v(1.0, 0.0, 0.0));
        let mut faces: Vec<Vec<u32>> = vec![vec![5, 4, 3, 2, 1, 0]];
        faces.push(vec![6, 7, 8, 9, 10, 11]);
        for i in 0..6u32 {
            let j = (i + 1) % 6;
            faces.push(if i == 0 {
                vec![0, 12, 1, 7, 6]
            } else {
                vec![i, j, j + 6, i + 6]
            });
        }
        faces.push(vec![0, 1, 12]);
        let cube: Vec<DVec3> = (0..8)
            .map(|i| {
                v(
                    1.0 + (i & 1) as f64,
                    1.0 + (i >> 1 & 1) as f64,
                    (i >> 2) as f64,
                )
            })
            .collect();
        let cube_faces: Vec<Vec<u32>> = vec![
            vec![0, 2, 3, 1],
            vec![4, 5, 7, 6],
            vec![0, 1, 5, 4],
            vec![2, 6, 7, 3],
            vec![0, 4, 6, 2],
            vec![1, 3, 7, 5],
        ];
        let r = mesh_boolean(
            &MeshIn::new(&positions, &faces),
            &MeshIn::new(&cube, &cube_faces),
            BoolOp::Union,
        )
        .unwrap();
        let rep = &r.reports[0];
        assert_eq!(rep.faces, 9);
        assert_eq!(
            rep.triangulated.iter().map(|t| t.0).collect::<Vec<_>>(),
            [0, 1]
        );
        assert_eq!(rep.dropped.iter().map(|t| t.0).collect::<Vec<_>>(), [8]);
        // 8 faces' slots (one empty) and the triangles after them
        assert_eq!(rep.polygons, 6 + 2 * 4);
        assert_eq!(r.volume(), 4.0);
        r.mesh.check_watertight().unwrap();
        // the union's solid: the cube's faces took the empty slot and the
        // end; a point in each part is inside
        for q in [
            [0.5, 0.5, 0.5],
            [1.5, 0.5, 0.5],
            [0.5, 1.5, 0.5],
            [1.5, 1.5, 0.5],
        ] {
            let g = r.grid.snap(DVec3::from_array(q)).unwrap();
            assert_eq!(r.solid.winding(g), 1, "{q:?}");
        }
    }

    #[test]
    fn a_face_cut_by_walls_and_one_plane_is_put_back_whole() {
        let square =
            Polygon::from_grid_points(&[[1, 1, 0], [15, 1, 0], [15, 15, 0], [1, 15, 0]], 0)
                .unwrap();
        // no cut: the square itself
        let pieces = cells_of(&square);
        assert_eq!(pieces.len(), 16);
        let back = rejoin(pieces);
        assert_eq!(back.len(), 1);
        assert!(same_loop(&back[0], &square));
        // a cut 2x + 3y = 41 across many cells: what is behind it, whole
        let cut = Plane::new([2, 3, 0], -41).unwrap();
        let kept: Vec<Polygon> = cells_of(&square)
            .into_iter()
            .filter_map(|mut q| q.clip(&cut, Side::Back).then_some(q))
            .collect();
        assert!(kept.len() > 6, "{} pieces", kept.len());
        let mut whole = square.clone();
        assert!(whole.clip(&cut, Side::Back));
        let back = rejoin(kept);
        assert_eq!(back.len(), 1);
        assert!(back[0].sanity_check().is_ok());
        assert!(same_loop(&back[0], &whole));
    }

    #[test]
    fn pieces_a_bend_separates_stay_convex_and_fewer() {
        // the kept part is behind two cuts meeting at a reflex corner: not
        // convex, so it stays in several convex pieces, each valid
        let square =
            Polygon::from_grid_points(&[[1, 1, 0], [15, 1, 0], [15, 15, 0], [1, 15, 0]], 0)
                .unwrap();
        let (c1, c2) = (
            Plane::new([1, 0, 0], -10).unwrap(),
            Plane::new([0, 1, 0], -10).unwrap(),
        );
        // kept: x < 10 or y < 10 (an L)
        let kept: Vec<Polygon> = cells_of(&square)
            .into_iter()
            .flat_map(|q| {
                let mut a = q.clone();
                let left = a.clip(&c1, Side::Back).then_some(a);
                let mut b = q;
                let right = b.clip(&c1, Side::Front) && b.clip(&c2, Side::Back);
                left.into_iter().chain(right.then_some(b))
            })
            .collect();
        let n = kept.len();
        let back = rejoin(kept);
        assert!(back.len() >= 2 && back.len() < n, "{} of {n}", back.len());
        for p in &back {
            assert!(p.sanity_check().is_ok());
        }
        // the same region: a point off every wall and cut is in one piece
        // exactly when it is kept
        let odd = [2, 3, 5, 6, 7, 9, 11, 13, 14];
        for x in odd {
            for y in odd {
                let pt = bsp_core::Point::Grid([x, y, 0]);
                let holding = back
                    .iter()
                    .filter(|p| p.edge_planes().iter().all(|e| pt.classify(e) == Side::Back))
                    .count();
                assert_eq!(holding, usize::from(x < 10 || y < 10), "({x}, {y})");
            }
        }
    }

    /// Joined boxes cover exactly the points of the boxes joined: an
    /// octree cell's eight children become the cell, an L of three boxes
    /// stays two, and the order they come in does not matter.
    #[test]
    fn joined_boxes_cover_the_same_points() {
        let children: Vec<IBox> = (0..8)
            .map(|c: i64| {
                let lo = [0, 1, 2].map(|k| if c >> k & 1 == 0 { 0 } else { 4 });
                (lo, lo.map(|x| x + 3))
            })
            .collect();
        for turn in 0..8 {
            let mut bs = children.clone();
            bs.rotate_left(turn);
            join_boxes(&mut bs);
            assert_eq!(bs, vec![([0, 0, 0], [7, 7, 7])]);
        }
        // an L (and a box apart): a cell and two of its neighbours
        let l_shape = vec![
            ([0, 0, 0], [1, 1, 1]),
            ([2, 0, 0], [3, 1, 1]),
            ([0, 2, 0], [1, 3, 1]),
            ([9, 9, 9], [9, 9, 9]),
        ];
        let mut bs = l_shape.clone();
        join_boxes(&mut bs);
        assert_eq!(bs.len(), 3);
        let points = |bs: &[IBox]| -> Vec<[i64; 3]> {
            let mut ps: Vec<[i64; 3]> = bs
                .iter()
                .flat_map(|b| {
                    (b.0[0]..=b.1[0]).flat_map(move |x| {
                        (b.0[1]..=b.1[1])
                            .flat_map(move |y| (b.0[2]..=b.1[2]).map(move |z| [x, y, z]))
                    })
                })
                .collect();
            ps.sort_unstable();
            ps
        };
        assert_eq!(points(&bs), points(&l_shape));
        let mut reversed: Vec<IBox> = l_shape.into_iter().rev().collect();
        join_boxes(&mut reversed);
        assert_eq!(reversed, bs);
    }

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

    /// A solid answers its queries the same before it has an index (by
    /// reading every face), while the index is made after a few queries,
    /// and with it: the faces near boxes, winding numbers one by one and
    /// in one pass, and membership. A solid an operation changed in place
    /// has its index.
    #[test]
    fn queries_agree_with_and_without_the_index() {
        let (pos, faces) = bsp_fixtures::uv_sphere(6_000);
        let snapped = snap(&[MeshIn::new(&pos, &faces)]).unwrap();
        let fresh = snapped.solids[0].clone();
        assert!(fresh.index.get().is_none());
        let mut indexed = fresh.clone();
        indexed.reindex();
        let (lo, hi) = fresh.bounds.unwrap();
        let at = |t: [i64; 3]| [0, 1, 2].map(|k| (lo[k] + (hi[k] - lo[k]) * t[k] / 8) as i32);
        let points: Vec<GridPoint> = (0..9 * 9 * 9)
            .map(|i| at([i % 9, i / 9 % 9, i / 81]))
            .collect();
        let boxes: Vec<IBox> = points
            .iter()
            .zip(points.iter().rev())
            .map(|(p, q)| {
                let lo = [0, 1, 2].map(|k| p[k].min(q[k]) as i64);
                let hi = [0, 1, 2].map(|k| p[k].max(q[k]) as i64);
                (lo, hi)
            })
            .step_by(37)
            .collect();
        // one pass, then point by point (which makes the index as it goes)
        let lazy = fresh.clone();
        let few: Vec<GridPoint> = points.iter().copied().step_by(12).collect();
        assert!(few.len() <= FEW_WINDINGS);
        let want = indexed.windings(&few);
        assert!(want.iter().any(|&w| w != 0) && want.contains(&0));
        assert_eq!(lazy.windings(&few), want);
        let mut inside = 0;
        for &q in &points {
            let w = indexed.winding(q);
            assert_eq!(lazy.winding(q), w, "{q:?}");
            assert_eq!(fresh.clone().classify_point(q), indexed.classify_point(q));
            inside += (w != 0) as usize;
        }
        assert!(inside > 50 && inside < points.len() - 50, "{inside}");
        assert!(lazy.index.get().is_some());
        for bx in &boxes {
            assert_eq!(fresh.clone().faces_near(bx), indexed.faces_near(bx));
            assert_eq!(fresh.clone().near_span(bx), indexed.near_span(bx));
        }
        // an operation carried out leaves an index
        let mut a = fresh.clone();
        let mut b = fresh.clone();
        b.apply(&a.clone(), BoolOp::Union).unwrap();
        a.apply(&indexed, BoolOp::Intersection).unwrap();
        assert!(a.index.get().is_some() && b.index.get().is_some());
    }
}
