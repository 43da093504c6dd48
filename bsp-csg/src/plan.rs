//! Operations on solids, and planning them: everything `a ∘ b` decides
//! before a face is added to `a` ([`Solid::carry_out`]) or the result is
//! meshed. [`Solid::plan`] runs the phases of the crate docs in turn:
//!
//! 1. the octree over the box where the two surfaces may meet, each leaf
//!    listing its faces of each operand ([`Cells::build`], `octree`);
//! 2. the regions of leaves free of each surface, labelled by winding
//!    numbers ([`FreeRegions`]);
//! 3. each face sorted: in free leaves only, or with pieces in mixed
//!    leaves ([`sort_faces`]);
//! 4. the faces the other surface may meet ([`Touched`]), and each mixed
//!    cell run: easy, or its local partitions built (`mixed_cell`,
//!    `local`);
//! 5. the labels of the untouched faces and of the easy cells' pieces
//!    ([`Labeller`]); an easy cell that a label does not reach is run
//!    again and builds its partitions;
//! 6. the faces settled: those in free leaves kept or dropped whole, the
//!    others kept whole, dropped, or replaced by what stays of them
//!    ([`settle`](fn@settle)); and the faces away from the shared box.

mod labelling;
mod local;
mod mixed_cell;
mod octree;
mod operands;
mod resolve;
mod settle;
mod twins;

use bsp_core::internals::ConvexFace;
use bsp_core::par;
use bsp_core::{BoolOp, Plane, TriMesh};
use rustc_hash::{FxHashMap, FxHashSet};
use smallvec::SmallVec;

use crate::index::{IBox, SmallBox, intersect, union};
use crate::solid::{AddedFace, Additions, OtherFaces, drop_aside};
use crate::{CsgError, Options, Solid, Stats};
use labelling::{FreeRegions, Labeller};
use mixed_cell::{CellOutcome, CellRun, CellWork, EasyPieces, PieceFate, Touched, WallCrossings};
use octree::{Leaf, walls};
use operands::{Both, Keep, Operand};
use settle::{
    FacePiece, PiecedFace, Remains, SettledFace, SortedFaces, meeting_leaf, settle, sort_faces,
};

/// The most faces [`Solid::resolved`] takes for a solid made by an
/// operation (faces with corners off the grid): one partition of every face
/// of a smooth closed surface of 20,000 faces takes about 2 s on the
/// machine of `docs/bench-csg.md`, and it grows faster than the faces.
pub const RESOLVE_LIMIT: usize = 20_000;

/// An operation on two solids, decided ([`Solid::plan_owned`]).
pub struct Planned {
    solid: Solid,
    other: Solid,
    additions: Additions,
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
            additions,
            ..
        } = self;
        solid.carry_out(additions, OtherFaces::Moved(&mut other));
        drop_aside(other);
        solid
    }

    /// The result's watertight mesh, the one [`Planned::into_solid`]'s
    /// [`Solid::into_watertight_mesh`] gives (the same triangles in the
    /// same order), made from the faces where they are: the result's
    /// faces are not moved into one solid, and no index is made for them.
    pub fn into_watertight_mesh(self) -> Result<TriMesh, CsgError> {
        let Planned {
            solid,
            other,
            additions,
            ..
        } = self;
        solid.into_watertight_mesh_with(additions, other)
    }
}

impl Solid {
    /// The solid of the points where this surface's winding number is
    /// positive: for a surface whose shells cross, overlap or nest (two
    /// copies of a part, a part inside another turned the same way, a
    /// cavity outside any part), the solid those shells bound by the
    /// rule of mesh-arrangement Booleans; for a clean solid, the same
    /// solid. Exact.
    ///
    /// A surface of faces with grid corners (as snapped from a mesh) is
    /// resolved cell by cell: partitions only where faces meet, one small
    /// partition per edge-connected part elsewhere (`plan/resolve.rs`),
    /// and the faces that meet nothing kept whole. A solid made by an
    /// operation (corners off the grid) takes one partition of every
    /// face, which can grow much faster than the faces; such a surface of
    /// more than [`RESOLVE_LIMIT`] faces is refused
    /// ([`CsgError::TooLargeToResolve`]).
    pub fn resolved(mut self) -> Result<Solid, CsgError> {
        if self.resolved {
            return Ok(self);
        }
        let mut out = match resolve::resolve_locally(&self)? {
            resolve::Resolved::Unchanged => {
                self.resolved = true;
                return Ok(self);
            }
            resolve::Resolved::Faces(faces) => {
                drop_aside(self);
                Solid::from_polygons(faces)
            }
            resolve::Resolved::OffGrid if self.len() > RESOLVE_LIMIT => {
                return Err(CsgError::TooLargeToResolve { faces: self.len() });
            }
            resolve::Resolved::OffGrid => {
                let faces: Vec<bsp_core::Polygon> =
                    self.polygons().map(|p| p.into_owned()).collect();
                drop_aside(self);
                Solid::from_polygons(local::positive_region(faces)?)
            }
        };
        out.resolved = true;
        Ok(out)
    }

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
        let (stats, additions) = self.plan(other, op, opts)?;
        self.carry_out(additions, OtherFaces::Copied(other));
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
        let (stats, additions) = self.plan(&other, op, opts)?;
        self.carry_out(additions, OtherFaces::Moved(&mut other));
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
    ///
    /// Where a surface turns out to cross itself (the local winding
    /// numbers disagree), `other` is [resolved](Solid::resolved) and the
    /// operation planned again, and if that still fails, this solid too: what it decides then is the
    /// operation on the solids where the winding numbers are positive.
    pub fn plan_owned(mut self, mut other: Solid, op: BoolOp) -> Result<Planned, CsgError> {
        let opts = Options::default();
        // (a failed plan changed neither solid)
        let (stats, additions) = match self.plan(&other, op, &opts) {
            Err(CsgError::NotASolid) => {
                // the operand coming in first (it is usually fresh from a
                // file; a solid made by operations on resolved solids is
                // resolved already, and one that is not may be too large
                // to resolve whole)
                other = other.resolved()?;
                match self.plan(&other, op, &opts) {
                    Err(CsgError::NotASolid) => {
                        self = self.resolved()?;
                        self.plan(&other, op, &opts)?
                    }
                    planned => planned?,
                }
            }
            planned => planned?,
        };
        Ok(Planned {
            solid: self,
            other,
            additions,
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
    ) -> Result<(Stats, Additions), CsgError> {
        let Some(root) = self.octree_root(other) else {
            return Ok(self.apart(other, op));
        };
        let solids = Both {
            a: &*self,
            b: other,
        };
        let decided = Planning::new(solids, op, opts, root).decide()?;
        self.remove_all(&decided.remove);
        // the octree and its lists go on the pool (freeing them here, as
        // the function returns, held up what follows)
        let Decided {
            stats,
            add,
            remove,
            leftovers,
        } = decided;
        drop_aside((leftovers, remove));
        let flip = op == BoolOp::Difference;
        Ok((stats, Additions { faces: add, flip }))
    }

    /// The box the octree covers: where the two solids' bounds overlap,
    /// the faces of either there may meet the other surface, and the box
    /// they span holds every face of either in it (the octree's cells
    /// must know all the faces in them to tell which cells are free of a
    /// surface). `None` if no face of either may meet the other surface.
    fn octree_root(&self, other: &Solid) -> Option<IBox> {
        let domain = match (self.bounds(), other.bounds()) {
            (Some(a), Some(b)) => intersect(&a, &b),
            _ => None,
        }?;
        match (self.near_span(&domain), other.near_span(&domain)) {
            (Some(a), Some(b)) => Some(union(&a, &b)),
            (Some(x), None) | (None, Some(x)) => Some(x),
            (None, None) => None,
        }
    }

    /// `self op other` for solids whose faces cannot meet.
    fn apart(&mut self, other: &Solid, op: BoolOp) -> (Stats, Additions) {
        let faces = match op {
            BoolOp::Union => other.face_ids().map(AddedFace::Theirs).collect(),
            BoolOp::Intersection => {
                *self = Solid::empty();
                Vec::new()
            }
            BoolOp::Difference => Vec::new(),
        };
        let additions = Additions { faces, flip: false };
        (Stats::default(), additions)
    }
}

/// The octree's leaves over the box where the two surfaces may meet, and
/// each operand's faces in that box.
struct Cells {
    /// The octree's box.
    root: IBox,
    /// The leaves, each listing its faces of each operand by id.
    leaves: Vec<Leaf>,
    /// The pairs of leaves that share a piece of wall.
    adjacent: Vec<(u32, u32)>,
    /// Each operand's faces whose box overlaps the root (ascending ids).
    near: Both<Vec<u32>>,
    /// The leaves of each of those faces, by its place in `near`.
    leaves_of: Both<Vec<SmallVec<[u32; 4]>>>,
    /// The faces (by id) that are the same polygon as one of the other
    /// operand's ([`twins`]).
    twinned: Both<FxHashSet<u32>>,
}

impl Cells {
    /// The octree over `root` for the two solids' faces there.
    fn build(solids: Both<&Solid>, root: IBox, opts: &Options) -> Cells {
        let near = Both {
            a: solids.a.faces_near(&root),
            b: solids.b.faces_near(&root),
        };
        let twin = twins::twins(solids, &near);
        // a cell where the two surfaces are one is not split
        let settled = |l: &Leaf| {
            let (ta, tb) = (&twin.a, &twin.b);
            let twin_a = |f: u32| ta[f as usize] != twins::NONE;
            let twin_b = |f: u32| tb[f as usize] != twins::NONE;
            twins::one_set(solids, &l.bx, (&l.a, &l.b), twin_a, twin_b)
        };
        let mut leaves = grow_octree(solids, &near, root, opts.leaf_size, &settled);
        let twinned = twins::twinned(&twin, &near);
        if opts.exact_cells {
            // the lists of the leaves holding both, by the exact test
            par::for_each_mut(&mut leaves, |_, l| {
                if !l.mixed() {
                    return;
                }
                let bx = l.bx;
                l.a.retain(|&f| octree::polygon_meets(solids.a.face(near.a[f as usize]), &bx));
                l.b.retain(|&f| octree::polygon_meets(solids.b.face(near.b[f as usize]), &bx));
            });
        }
        // each face's leaves, by its place in `near` (each operand's on
        // its own thread)
        let leaves_of = Both::join(|o| {
            let mut of: Vec<SmallVec<[u32; 4]>> = vec![SmallVec::new(); near.get(o).len()];
            for (li, l) in leaves.iter().enumerate() {
                for &f in l.faces(o) {
                    of[f as usize].push(li as u32);
                }
            }
            of
        });
        // the leaves' lists by face id
        par::for_each_mut(&mut leaves, |_, l| {
            l.a.iter_mut().for_each(|f| *f = near.a[*f as usize]);
            l.b.iter_mut().for_each(|f| *f = near.b[*f as usize]);
        });
        let adjacent = octree::adjacent(&leaves);
        Cells {
            root,
            leaves,
            adjacent,
            near,
            leaves_of,
            twinned,
        }
    }
}

/// The octree's leaves over `root` for each solid's faces `near` it,
/// listed by their place in `near`.
fn grow_octree(
    solids: Both<&Solid>,
    near: &Both<Vec<u32>>,
    root: IBox,
    leaf_size: usize,
    settled: &(dyn Fn(&Leaf) -> bool + Sync),
) -> Vec<Leaf> {
    // the faces' boxes and planes side by side, by their place in `near`
    // (a face slot is large: the build reads these often)
    let geometry = |s: &Solid, fs: &[u32]| -> (Vec<SmallBox>, Vec<Plane>) {
        par::map_slice(fs, |&f| (s.face(f).small_box(), *s.face(f).support()))
            .into_iter()
            .unzip()
    };
    let (boxes_a, planes_a) = geometry(solids.a, &near.a);
    let (boxes_b, planes_b) = geometry(solids.b, &near.b);
    octree::build(
        root,
        &octree::Faces {
            boxes: &boxes_a,
            plane_meets: |f: u32, c: &IBox| octree::plane_meets(&planes_a[f as usize], c),
        },
        &octree::Faces {
            boxes: &boxes_b,
            plane_meets: |f: u32, c: &IBox| octree::plane_meets(&planes_b[f as usize], c),
        },
        leaf_size,
        settled,
    )
}

/// What the mixed cells decided, gathered cell by cell.
struct MixedCells {
    /// What became of each operand's listed faces, per cell that sorted
    /// its pieces (built or easy).
    fates: Both<FxHashMap<u32, Vec<PieceFate>>>,
    /// The walls each isolated piece crosses, per cell that sorted its
    /// pieces on its first run and per easy cell.
    crossings: Both<FxHashMap<u32, WallCrossings>>,
    /// The easy cells not settled yet, in order, and their pieces.
    easy: Vec<u32>,
    easy_pieces: Both<FxHashMap<u32, EasyPieces>>,
    /// The faces to add so far: the merged cells' boundaries.
    add: Vec<AddedFace>,
    stats: Stats,
}

impl MixedCells {
    /// Records cell `l`'s first run.
    fn record(&mut self, l: u32, run: CellRun) {
        match run {
            CellRun::Easy { crossings, pieces } => {
                self.easy.push(l);
                self.crossings.a.insert(l, crossings.a);
                self.crossings.b.insert(l, crossings.b);
                self.easy_pieces.a.insert(l, pieces.a);
                self.easy_pieces.b.insert(l, pieces.b);
            }
            CellRun::Built { outcome, crossings } => {
                if matches!(outcome, CellOutcome::Sorted(_) | CellOutcome::OneSet(_)) {
                    self.crossings.a.insert(l, crossings.a);
                    self.crossings.b.insert(l, crossings.b);
                }
                self.built(l, outcome);
            }
        }
    }

    /// Records what cell `l`'s partitions decided: its fates, or its
    /// merged boundary to add.
    fn built(&mut self, l: u32, outcome: CellOutcome) {
        match outcome {
            CellOutcome::Merged(ps) => {
                self.stats.merged_cells += 1;
                self.add
                    .extend(ps.into_iter().map(|p| AddedFace::New(Box::new(p))));
            }
            CellOutcome::OneSet(fates) => {
                self.stats.one_set_cells += 1;
                self.fates.a.insert(l, fates.a);
                self.fates.b.insert(l, fates.b);
            }
            CellOutcome::Sorted(fates) => {
                self.fates.a.insert(l, fates.a);
                self.fates.b.insert(l, fates.b);
            }
        }
    }
}

/// The new faces of an operation (cut faces' kept parts of both
/// operands, merged cells' boundaries) put back together where two of one
/// plane share a whole edge and their union is convex, across faces
/// ([`settle::rejoined`]); in their order, faces kept whole untouched.
fn rejoin_new_faces(add: &mut Vec<AddedFace>) {
    // the new faces' polygons, and a gap in the list where each was
    let (mut polygons, mut slots) = (Vec::new(), Vec::with_capacity(add.len()));
    for f in std::mem::take(add) {
        match f {
            AddedFace::New(p) => {
                polygons.push(*p);
                slots.push(None);
            }
            theirs => slots.push(Some(theirs)),
        }
    }
    // each gap filled with what its polygon grew into, or closed
    let mut joined = settle::rejoined(polygons).into_iter();
    add.extend(slots.into_iter().filter_map(|slot| match slot {
        Some(f) => Some(f),
        None => (joined.next().expect("one per new face")).map(|p| AddedFace::New(Box::new(p))),
    }));
}

/// What an operation decided for the first solid.
struct Decided {
    stats: Stats,
    /// The faces to add, in order.
    add: Vec<AddedFace>,
    /// The faces to remove, in order.
    remove: Vec<u32>,
    /// What the decision was made with, to free on the pool.
    leftovers: (
        Cells,
        Both<FreeRegions>,
        Both<FxHashMap<u32, WallCrossings>>,
    ),
}

/// An operation being decided: the two solids, the operation, and the
/// octree over the box where their surfaces may meet.
struct Planning<'s> {
    solids: Both<&'s Solid>,
    op: BoolOp,
    keep: Keep,
    easy_cells: bool,
    cells: Cells,
}

impl<'s> Planning<'s> {
    /// The operation `a op b` over the octree of `root`.
    fn new(solids: Both<&'s Solid>, op: BoolOp, opts: &Options, root: IBox) -> Planning<'s> {
        Planning {
            solids,
            op,
            keep: Keep(op),
            easy_cells: opts.easy_cells,
            cells: Cells::build(solids, root, opts),
        }
    }

    /// Every phase after the octree's, in turn.
    fn decide(self) -> Result<Decided, CsgError> {
        let leaves = &self.cells.leaves;
        // the regions free of each surface, and their labels
        let regions =
            Both::join(|o| FreeRegions::new(leaves, &self.cells.adjacent, o, self.solids.get(o)));
        // the faces wholly in free leaves, and the pieces of the others
        let sorted = Both::join(|o| self.sort(o));
        let mixed: Vec<u32> = (0..leaves.len() as u32)
            .filter(|&l| leaves[l as usize].mixed())
            .collect();
        let touched = Touched::find(&mixed, leaves, self.solids, self.easy_cells);
        let work = CellWork {
            solids: self.solids,
            touched: &touched,
            twinned: &self.cells.twinned,
            op: self.op,
        };
        let mut done = self.run_mixed_cells(&work, &mixed, &touched)?;
        let untouched = Both::join(|o| {
            self.labeller(o, &regions, &done.fates)
                .untouched_faces(&sorted.get(o).pieced, &touched)
        })
        .transpose()?;
        let easy = Both::join(|o| {
            self.labeller(o, &regions, &done.fates).easy_cells(
                &self.cells.adjacent,
                done.crossings.get(o),
                done.easy_pieces.get(o),
                untouched.get(o),
            )
        })
        .transpose()?;
        drop_aside(std::mem::take(&mut done.easy_pieces));
        self.settle_easy_cells(&work, &mut done, easy)?;
        let remove = self.changes(&mut done, &regions, sorted, &untouched, &touched)?;
        Ok(Decided {
            stats: done.stats,
            add: done.add,
            remove,
            leftovers: (self.cells, regions, done.crossings),
        })
    }

    /// Operand `o`'s faces in the octree's box, sorted.
    fn sort(&self, o: Operand) -> SortedFaces {
        let solid = self.solids.get(o);
        sort_faces(
            self.cells.near.get(o),
            self.cells.leaves_of.get(o),
            &self.cells.leaves,
            &self.cells.root,
            |f| solid.face(f).bx(),
            o,
        )
    }

    /// The first run of each mixed cell that is not clean, in parallel,
    /// recorded in order.
    fn run_mixed_cells(
        &self,
        work: &CellWork<'_>,
        mixed: &[u32],
        touched: &Touched,
    ) -> Result<MixedCells, CsgError> {
        let leaves = &self.cells.leaves;
        let unclean: Vec<u32> = mixed
            .iter()
            .copied()
            .filter(|&l| !touched.clean(l))
            .collect();
        let first: Vec<(u32, CellRun)> = par::try_map(unclean.len(), |i| {
            let l = unclean[i];
            work.run(&leaves[l as usize], self.easy_cells)
                .map(|r| (l, r))
        })?;
        let mut done = MixedCells {
            fates: Both::default(),
            crossings: Both::default(),
            easy: Vec::new(),
            easy_pieces: Both::default(),
            add: Vec::new(),
            stats: Stats {
                cells: leaves.len(),
                mixed_cells: mixed.len(),
                clean_cells: mixed.iter().filter(|&&l| touched.clean(l)).count(),
                ..Stats::default()
            },
        };
        for (l, run) in first {
            done.record(l, run);
        }
        Ok(done)
    }

    /// The labelling of operand `o`'s pieces.
    fn labeller<'p>(
        &'p self,
        o: Operand,
        regions: &'p Both<FreeRegions>,
        fates: &'p Both<FxHashMap<u32, Vec<PieceFate>>>,
    ) -> Labeller<'p> {
        Labeller {
            operand: o,
            solid: self.solids.get(o),
            other: self.solids.get(o.other()),
            leaves: &self.cells.leaves,
            other_regions: regions.get(o.other()),
            fates: fates.get(o),
            keep_inside: self.keep.piece(o, true),
        }
    }

    /// The easy cells settled by their pieces' labels `labels`: an easy
    /// cell with a piece no label reached does the full work.
    fn settle_easy_cells(
        &self,
        work: &CellWork<'_>,
        done: &mut MixedCells,
        mut labels: Both<FxHashMap<u32, Vec<Option<bool>>>>,
    ) -> Result<(), CsgError> {
        let mut again: Vec<u32> = Vec::new();
        for l in std::mem::take(&mut done.easy) {
            let la = labels.a.remove(&l).expect("an easy cell");
            let lb = labels.b.remove(&l).expect("an easy cell");
            let fa = easy_fates(&done.crossings.a[&l], &la, |x| {
                self.keep.piece(Operand::A, x)
            });
            let fb = easy_fates(&done.crossings.b[&l], &lb, |x| {
                self.keep.piece(Operand::B, x)
            });
            match (fa, fb) {
                (Some(fa), Some(fb)) => {
                    done.stats.easy_cells += 1;
                    done.fates.a.insert(l, fa);
                    done.fates.b.insert(l, fb);
                }
                _ => again.push(l),
            }
        }
        let leaves = &self.cells.leaves;
        let redone: Vec<(u32, CellRun)> = par::try_map(again.len(), |i| {
            let l = again[i];
            work.run(&leaves[l as usize], false).map(|r| (l, r))
        })?;
        for (l, run) in redone {
            match run {
                CellRun::Built { outcome, .. } => done.built(l, outcome),
                CellRun::Easy { .. } => unreachable!("a second run does the full work"),
            }
        }
        Ok(())
    }
}

impl Planning<'_> {
    /// The changes to the first solid, now that everything is known
    /// (decided in parallel, applied in order): the faces to remove, and
    /// those to add after the merged cells' boundaries in `done.add`;
    /// `labels` are the untouched faces'.
    fn changes(
        &self,
        done: &mut MixedCells,
        regions: &Both<FreeRegions>,
        sorted: Both<SortedFaces>,
        labels: &Both<Vec<Option<bool>>>,
        touched: &Touched,
    ) -> Result<Vec<u32>, CsgError> {
        let mut remove = self.whole_faces(Operand::A, &sorted.a, regions, false);
        // the two operands' faces at once (each in parallel, but each
        // with sequential tails)
        let settle_faces = |o: Operand| {
            let pieced = &sorted.get(o).pieced;
            self.settle_faces(
                o,
                pieced,
                regions,
                done.fates.get(o),
                labels.get(o),
                touched,
            )
        };
        let (settled_a, (kept_b, settled_b)) = par::join(
            || settle_faces(Operand::A),
            || {
                par::join(
                    // the other solid's faces kept whole are listed, to be
                    // copied or moved over (turned around for a difference)
                    || self.whole_faces(Operand::B, &sorted.b, regions, true),
                    || settle_faces(Operand::B),
                )
            },
        );
        drop_aside((sorted, std::mem::take(&mut done.fates)));
        let (settled_a, settled_b) = (settled_a?, settled_b?);
        let (stats, add) = (&mut done.stats, &mut done.add);
        for s in settled_a {
            if let Remains::Parts(kept) = s.remains {
                remove.push(s.face);
                count_cut(stats, &kept);
                add.extend(kept.into_iter().map(|p| AddedFace::New(Box::new(p))));
            }
        }
        add.extend(kept_b.into_iter().map(AddedFace::Theirs));
        let flip = self.op == BoolOp::Difference;
        for s in settled_b {
            match s.remains {
                Remains::Whole => add.push(AddedFace::Theirs(s.face)),
                Remains::Parts(kept) => {
                    count_cut(stats, &kept);
                    add.extend(
                        kept.into_iter()
                            .map(|p| AddedFace::New(Box::new(if flip { p.flipped() } else { p }))),
                    );
                }
            }
        }
        rejoin_new_faces(add);
        // the faces away from the shared box: outside the other solid
        match self.op {
            BoolOp::Union => {
                let far = far_faces(self.solids.b, &self.cells.near.b);
                add.extend(far.into_iter().map(AddedFace::Theirs));
            }
            BoolOp::Intersection => remove.extend(far_faces(self.solids.a, &self.cells.near.a)),
            BoolOp::Difference => {}
        }
        Ok(remove)
    }

    /// Operand `o`'s faces in leaves free of the other surface only
    /// (`sorted.whole`) that the operation keeps (`kept`) or drops (not
    /// `kept`), by id: each lies wholly inside or outside the other solid,
    /// as the region of a leaf it meets says (a face meeting none lies
    /// beyond the octree's box, so outside the other solid).
    fn whole_faces(
        &self,
        o: Operand,
        sorted: &SortedFaces,
        regions: &Both<FreeRegions>,
        kept: bool,
    ) -> Vec<u32> {
        let (solid, other_regions) = (self.solids.get(o), regions.get(o.other()));
        let (near, leaves_of) = (self.cells.near.get(o), self.cells.leaves_of.get(o));
        let whole = &sorted.whole;
        par::filter_map(whole.len(), |k| {
            let i = whole[k] as usize;
            let face = solid.face(near[i]);
            let inside = meeting_leaf(face, &leaves_of[i], &self.cells.leaves)
                .is_some_and(|l| other_regions.inside(l));
            (self.keep.piece(o, inside) == kept).then_some(near[i])
        })
    }

    /// What stays of each of operand `o`'s faces with pieces: by its
    /// label for an untouched face (`labels`), else piece by piece
    /// ([`settle`](fn@settle); a piece beyond the octree's box is beyond the other
    /// solid's box, so outside it).
    fn settle_faces(
        &self,
        o: Operand,
        pieced: &[PiecedFace],
        regions: &Both<FreeRegions>,
        fates: &FxHashMap<u32, Vec<PieceFate>>,
        labels: &[Option<bool>],
        touched: &Touched,
    ) -> Result<Vec<SettledFace>, CsgError> {
        let (solid, other_regions) = (self.solids.get(o), regions.get(o.other()));
        let keep = |inside: bool| self.keep.piece(o, inside);
        let free_stays = |p: &FacePiece| match *p {
            FacePiece::InFreeLeaf(l) => keep(other_regions.inside(l)),
            _ => keep(false),
        };
        let root_walls = walls(&self.cells.root);
        par::try_map(pieced.len(), |i| {
            let p = &pieced[i];
            if let Some(inside) = labels[p.face as usize] {
                let remains = if keep(inside) {
                    Remains::Whole
                } else {
                    Remains::Parts(Vec::new())
                };
                return Ok(SettledFace {
                    face: p.face,
                    remains,
                });
            }
            // (an untouched face stays or goes whole by its label; a
            // face the other surface may meet has no piece in a clean
            // cell)
            let in_clean_cell = |q: &FacePiece| matches!(*q, FacePiece::InMixedLeaf { leaf, .. } if touched.clean(leaf));
            if p.pieces.iter().any(in_clean_cell) {
                return Err(CsgError::Internal(
                    "a face the other surface may meet has a piece in a clean cell".into(),
                ));
            }
            let remains = settle(
                solid.face(p.face),
                &p.pieces,
                &free_stays,
                fates,
                &self.cells.leaves,
                &root_walls,
            );
            Ok(SettledFace {
                face: p.face,
                remains,
            })
        })
    }
}

/// Counts a face the other surface cuts, into the pieces `kept` (none:
/// the face is dropped, not cut).
fn count_cut(stats: &mut Stats, kept: &[bsp_core::Polygon]) {
    if !kept.is_empty() {
        stats.cut_faces += 1;
        stats.pieces += kept.len();
    }
}

/// The live faces of `solid` not in `near` (ascending ids), in order.
fn far_faces(solid: &Solid, near: &[u32]) -> Vec<u32> {
    let mut is_near = vec![false; solid.slot_count()];
    near.iter().for_each(|&f| is_near[f as usize] = true);
    solid.face_ids().filter(|&i| !is_near[i as usize]).collect()
}

/// The fates of an easy cell's listed faces of one operand, from the
/// walls their pieces cross (`None`: no piece) and the pieces' labels,
/// `keep(inside)` saying which stay; `None` if a piece got no label.
fn easy_fates(
    crossings: &[Option<u8>],
    labels: &[Option<bool>],
    keep: impl Fn(bool) -> bool,
) -> Option<Vec<PieceFate>> {
    crossings
        .iter()
        .zip(labels)
        .map(|(m, label)| match (m, label) {
            (None, _) => Some(PieceFate::Missing),
            (Some(_), Some(inside)) => Some(if keep(*inside) {
                PieceFate::Keep
            } else {
                PieceFate::Drop
            }),
            (Some(_), None) => None,
        })
        .collect()
}
