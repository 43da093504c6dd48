//! Exact lit and shadowed fragments of every receiver, from the
//! partitioned shadow volumes of each light.
//!
//! A receiver is a face: one or more convex polygons on one support plane
//! (a non-convex face is imported as several). For each light that faces
//! it, each of its current pieces is filtered through that light's tree;
//! a cut made on the way is undone when both sides turn out alike, so a
//! piece comes back whole unless a shadow boundary crosses it. After the
//! last light, the pieces with equal flags that touch along an edge are
//! merged into maximal regions ([`merge_cells`]): a fragment is a
//! connected part of the face with one set of flags, an outer boundary
//! and possibly holes. A face lit (or shadowed) all over by every light
//! is one fragment: its own polygon.
//!
//! Faces are independent of one another once the trees exist, so they are
//! shaded in parallel; each face's result depends only on the face and the
//! trees, and results are concatenated in face order, so the output is the
//! same for every thread count.

use crate::schedule::{is_one_of, large_receivers, runs};
use std::ops::Range;

use bsp_core::{Plane, Polygon, Side};
use rayon::prelude::*;
use smallvec::SmallVec;

use crate::arena::pieces::{EdgeRef, Piece, PieceArena, Vertex};
use crate::arena::regions::{MergeCache, Region, Remerged, merge_cells};
use crate::light::{Light, LightError, MAX_LIGHTS};
use crate::psv::filter::Walk;
use crate::psv::{ShadowVolumes, VolumeError};

/// Why shadows cannot be computed.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum ShadowError {
    /// A light is unusable.
    Light(LightError),
    /// An occluder is unusable.
    Volume(VolumeError),
    /// Trees given for lights they were not built for.
    Mismatch,
}

impl std::fmt::Display for ShadowError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ShadowError::Light(e) => e.fmt(f),
            ShadowError::Volume(e) => e.fmt(f),
            ShadowError::Mismatch => {
                write!(f, "the shadow trees were not built for the lights given")
            }
        }
    }
}

impl std::error::Error for ShadowError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ShadowError::Light(e) => Some(e),
            ShadowError::Volume(e) => Some(e),
            ShadowError::Mismatch => None,
        }
    }
}

impl From<LightError> for ShadowError {
    fn from(e: LightError) -> ShadowError {
        ShadowError::Light(e)
    }
}

impl From<VolumeError> for ShadowError {
    fn from(e: VolumeError) -> ShadowError {
        ShadowError::Volume(e)
    }
}

/// Options of [`ShadowSet::shade`].
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct ShadeOptions {
    /// Also record each fragment's convex pieces (for formats that need
    /// convex polygons, such as OBJ).
    pub pieces: bool,
    /// Also record each convex piece's edge planes, so that the pieces
    /// can be cut again exactly ([`FragmentRef::piece_planes`]; not kept
    /// by [`ShadowSet::refine_cells`]).
    pub planes: bool,
    /// Keep each vertex's exact coordinates ([`Batch::vertex`]), not only
    /// their correct rounding ([`Batch::rounded`]); a picture needs only
    /// the rounding.
    pub vertices: bool,
    /// Merge a receiver's convex pieces of one set of flags into maximal
    /// fragments (rings with holes). Without, each piece is a fragment
    /// of its own (its ring the piece, its one piece itself): the same
    /// points with the same flags, in more fragments, for a caller that
    /// reads only the pieces and their areas (a sun study's run).
    pub merge: bool,
}

impl Default for ShadeOptions {
    fn default() -> ShadeOptions {
        ShadeOptions {
            pieces: true,
            planes: false,
            vertices: true,
            merge: true,
        }
    }
}

impl ShadeOptions {
    /// Sets [`ShadeOptions::pieces`].
    pub fn with_pieces(mut self, pieces: bool) -> ShadeOptions {
        self.pieces = pieces;
        self
    }

    /// Sets [`ShadeOptions::vertices`].
    pub fn with_vertices(mut self, vertices: bool) -> ShadeOptions {
        self.vertices = vertices;
        self
    }

    /// Sets [`ShadeOptions::merge`].
    pub fn with_merge(mut self, merge: bool) -> ShadeOptions {
        self.merge = merge;
        self
    }

    /// Sets [`ShadeOptions::planes`] (and [`ShadeOptions::pieces`] with it).
    pub fn with_planes(mut self, planes: bool) -> ShadeOptions {
        self.planes = planes;
        self.pieces |= planes;
        self
    }
}

/// The shadow volumes of a scene for a list of lights, ready to shade
/// receivers.
#[derive(Clone, Debug)]
pub struct LightVolumes {
    lights: Vec<Light>,
    volumes: Vec<ShadowVolumes>,
    /// Per light, per occluder, whether its tree's building found the
    /// light reaches all of it or none (see `engine/known.rs`); empty
    /// where not asked.
    reached: Vec<Vec<Option<bool>>>,
}

/// Consecutive polygons that form one receiver: the same face (tag) and
/// the same support plane. An imported face that was triangulated because
/// it is not convex is one receiver; one that was triangulated because it
/// is not planar is one per plane.
pub fn receivers(polys: &[Polygon]) -> Vec<Range<usize>> {
    let mut out: Vec<Range<usize>> = Vec::new();
    for (i, p) in polys.iter().enumerate() {
        match out.last_mut() {
            Some(r)
                if polys[r.start].tag() == p.tag() && polys[r.start].support() == p.support() =>
            {
                r.end = i + 1
            }
            _ => out.push(i..i + 1),
        }
    }
    out
}

impl LightVolumes {
    /// Bit `j` set: light `j` reaches grid point `x`, no occluder hiding
    /// it ([`ShadowVolumes::hides`]; a point on a shadow's boundary is
    /// reached). For points apart from the faces, such as sensors; whether
    /// a surface at `x` faces the light is the caller's to ask.
    ///
    /// ```
    /// use svbsp::{Light, LightVolumes};
    /// let roof = bsp_core::Polygon::from_grid_points(&[[0, 0, 10], [10, 0, 10], [10, 10, 10], [0, 10, 10]], 0).unwrap();
    /// let s = LightVolumes::new(&[roof], &[Light::Directional([0, 0, 1])]).unwrap();
    /// assert_eq!(s.reaching([5, 5, 0]), 0); // under the roof
    /// assert_eq!(s.reaching([15, 5, 0]), 1); // beside it
    /// assert_eq!(s.reaching([10, 5, 0]), 1); // on its shadow's edge
    /// ```
    pub fn reaching(&self, x: bsp_core::GridPoint) -> u64 {
        (self.volumes.iter().enumerate())
            .filter(|(_, v)| !v.hides(x))
            .fold(0, |m, (j, _)| m | 1 << j)
    }

    /// Builds one shadow-volume tree per light from `occluders` (polygons
    /// with grid vertices, e.g. from [`bsp_core::import_faces`]), each in
    /// parallel.
    ///
    /// The polygons of an edge-connected part certified to bound a solid
    /// ([`bsp_core::certify_solid_parts`]: closed, oriented, embedded,
    /// outward) that a light outside the part's box does not face are left
    /// out of that light's tree: the part's faces toward the light hide
    /// all they hide ([`Light::leaves_out`]). Every lit area is the same
    /// as with all of them; the fragments may come out cut or listed
    /// differently.
    pub fn new(occluders: &[Polygon], lights: &[Light]) -> Result<LightVolumes, ShadowError> {
        let order: Vec<usize> = (0..occluders.len()).collect();
        LightVolumes::new_built(occluders, &order, lights, None, false)
    }

    /// [`LightVolumes::new`] with the parts of `occluders` already certified
    /// (`solids` is [`bsp_core::certify_solid_parts`] of `occluders`), for
    /// callers that build several runs over the same polygons.
    pub fn new_with(
        occluders: &[Polygon],
        lights: &[Light],
        solids: &bsp_core::SolidParts,
    ) -> Result<LightVolumes, ShadowError> {
        let order: Vec<usize> = (0..occluders.len()).collect();
        LightVolumes::new_built(occluders, &order, lights, Some(solids), false)
    }

    /// The lights, in order: bit `i` of a fragment's flags is light `i`.
    pub fn lights(&self) -> &[Light] {
        &self.lights
    }

    /// The shadow-volume tree of each light.
    pub fn volumes(&self) -> &[ShadowVolumes] {
        &self.volumes
    }

    /// The volumes of trees built elsewhere, one per light in order (for
    /// example over different occluders per light). Errors if a tree's
    /// light is not the light given for it.
    pub fn from_volumes(
        lights: &[Light],
        volumes: Vec<ShadowVolumes>,
    ) -> Result<LightVolumes, ShadowError> {
        if lights.len() > MAX_LIGHTS {
            return Err(LightError::TooMany(lights.len()).into());
        }
        if volumes.len() != lights.len() || volumes.iter().zip(lights).any(|(v, l)| v.light() != *l)
        {
            return Err(ShadowError::Mismatch);
        }
        Ok(LightVolumes {
            lights: lights.to_vec(),
            volumes,
            reached: Vec::new(),
        })
    }

    /// Bit `j` set: light `j` is strictly in front of `support`.
    pub fn facing(&self, support: &Plane) -> u64 {
        facing(&self.lights, support)
    }

    /// The trees as a [`ShadowSet`], which shades receivers:
    /// `shadows.set().shade_all(&polys, &opts)`.
    pub fn set(&self) -> ShadowSet<'_> {
        ShadowSet {
            lights: &self.lights,
            trees: self
                .volumes
                .iter()
                .enumerate()
                .map(|(j, v)| (v, j))
                .collect(),
            reached: &[],
        }
    }

    /// This set's trees and `more`'s (built for the same lights, e.g. over
    /// other occluders) as one [`ShadowSet`]: a point is lit by a light
    /// when none of the light's trees blocks it. Errors if the lights
    /// differ.
    pub fn with<'a>(&'a self, more: &'a LightVolumes) -> Result<ShadowSet<'a>, ShadowError> {
        if more.lights != self.lights {
            return Err(ShadowError::Mismatch);
        }
        let mut set = self.set();
        set.trees
            .extend(more.volumes.iter().enumerate().map(|(j, v)| (v, j)));
        Ok(set)
    }
}

/// Bit `j` set: light `j` is strictly in front of `support`.
fn facing(lights: &[Light], support: &Plane) -> u64 {
    lights
        .iter()
        .enumerate()
        .fold(0, |m, (j, l)| m | (l.faces(support) as u64) << j)
}

/// Shadow trees, borrowed, with the light each one is for: every shading
/// method. Usually one tree per light ([`LightVolumes::set`]); a light's
/// occluders may also be split among several trees ([`LightVolumes::with`]),
/// and a point is then lit by the light when none of its trees blocks it.
#[derive(Clone, Debug)]
pub struct ShadowSet<'a> {
    lights: &'a [Light],
    trees: SmallVec<[(&'a ShadowVolumes, usize); 4]>,
    /// [`LightVolumes::set_for_occluders`]'s knowledge, per light and
    /// occluder (empty: none).
    reached: &'a [Vec<Option<bool>>],
}

impl<'a> ShadowSet<'a> {
    /// The lights.
    pub fn lights(&self) -> &'a [Light] {
        self.lights
    }

    /// Bit `j` set: light `j` is strictly in front of `support`.
    pub fn facing(&self, support: &Plane) -> u64 {
        facing(self.lights, support)
    }

    /// Shades one receiver (polygons on one support plane, all tagged with
    /// the same face), appending its fragments to `out`. `receiver` is
    /// recorded with each fragment (e.g. the receiver's index).
    pub fn shade(
        &self,
        polys: &[Polygon],
        receiver: u32,
        opts: &ShadeOptions,
        scratch: &mut Scratch,
        out: &mut Batch,
    ) {
        let Some(first) = polys.first() else { return };
        let start = Start::Uniform(self.facing(first.support()));
        self.refine(polys, &start, receiver, opts, scratch, out);
    }

    /// [`ShadowSet::shade`], also returning the receiver's cells with their
    /// flags when the flags are not the same all over (`None` when they
    /// are: the receiver is then [`Start::Uniform`] with its fragments'
    /// flags), for later refinement by other trees
    /// ([`ShadowSet::refine_cells`]).
    pub fn shade_keeping(
        &self,
        polys: &[Polygon],
        receiver: u32,
        opts: &ShadeOptions,
        scratch: &mut Scratch,
        out: &mut Batch,
    ) -> Option<Cells> {
        let first = polys.first()?;
        let start = Start::Uniform(self.facing(first.support()));
        self.filter_lights(polys, &start, scratch);
        let s = &mut *scratch;
        let uniform = s.cur.iter().all(|(_, l)| *l == s.cur[0].1);
        if uniform {
            self.finish(polys, receiver, opts, scratch, out);
            return None;
        }
        let support = *first.support();
        s.pieces.clear();
        s.labels.clear();
        for (p, l) in &s.cur {
            s.pieces.push(p.clone());
            s.labels.push(*l);
        }
        let (merge, regions) = MergeCache::new(&s.arena, &support, &s.pieces, &s.labels);
        let cells = Cells {
            arena: s.arena.clone(),
            cells: std::mem::take(&mut s.cur),
            support: s.support,
            merge,
        };
        s.rounded.clear();
        out.push_regions(
            first.tag(),
            receiver,
            self.facing(&support),
            &support,
            s,
            &regions,
            opts,
        );
        Some(cells)
    }

    /// Refines a receiver already shaded for the same lights by other
    /// occluders: each part still lit by light `j` is filtered through this
    /// light `j`'s tree, and stays lit only where this tree lets the light
    /// through; the result is regions as [`ShadowSet::shade`] makes them.
    /// With the static scene's flags as `start` and trees of the occluders
    /// that moved, this is a receiver's shadow from both.
    pub fn refine(
        &self,
        polys: &[Polygon],
        start: &Start<'_>,
        receiver: u32,
        opts: &ShadeOptions,
        scratch: &mut Scratch,
        out: &mut Batch,
    ) {
        if polys.is_empty() {
            return;
        }
        self.filter_lights(polys, start, scratch);
        self.finish(polys, receiver, opts, scratch, out);
    }

    /// [`ShadowSet::refine`] that redoes only what these trees change:
    /// nothing when every cell comes back whole with its flags
    /// ([`Refined::Unchanged`]); from [`Start::Cells`], only the cells the
    /// trees cut or shadow are filtered, the cached merge is redone only
    /// where they are (`MergeCache::remerge`), and the receiver's other
    /// starting fragments stand ([`Refined::Some`]). The receiver's
    /// fragments are then those [`ShadowSet::refine`] makes (the same
    /// regions, perhaps in another order).
    ///
    /// `may_change(cell, light)` may answer `false` for a cell (an index
    /// into the starting cells; 0 for a [`Start::Uniform`] receiver) that
    /// light `light`'s tree cannot shadow — a cheap culling test of the
    /// caller's; it must never answer `false` for a cell the tree does
    /// shadow.
    #[allow(clippy::too_many_arguments)]
    pub fn refine_cells(
        &self,
        polys: &[Polygon],
        start: &Start<'_>,
        receiver: u32,
        opts: &ShadeOptions,
        scratch: &mut Scratch,
        out: &mut Batch,
        may_change: impl Fn(u32, usize) -> bool,
    ) -> Refined {
        let Some(first) = polys.first() else {
            return Refined::Unchanged;
        };
        let cells = match start {
            Start::Cells(c) => *c,
            Start::Uniform(flags) => {
                let bits = self.facing(first.support()) & flags;
                if (0..self.lights.len()).all(|j| bits >> j & 1 == 0 || !may_change(0, j))
                    || !self.filter_lights(polys, start, scratch)
                {
                    return Refined::Unchanged;
                }
                self.finish(polys, receiver, opts, scratch, out);
                return Refined::All;
            }
        };
        let support = *first.support();
        let facing = self.facing(&support);
        let s = scratch;
        // the cells that change: a quick test on the cached arena first,
        // then the exact filter on a copy of the few it cannot settle
        s.arena.clear();
        s.support = s.arena.add_plane(support);
        s.pieces.clear();
        s.labels.clear();
        let (mut removed, mut relabel) = (Vec::new(), Vec::new());
        for (i, (piece, flags)) in cells.cells.iter().enumerate() {
            let live = flags & facing;
            let mut now = *flags;
            let mut cut = 0u64;
            for &(sv, j) in &self.trees {
                let bit = 1u64 << j;
                if live & bit == 0 || !may_change(i as u32, j) {
                    continue;
                }
                match crate::psv::reach(
                    &sv.nodes,
                    sv.root,
                    |p| cells.arena.sides_shared(piece, p),
                    crate::psv::REACH_BUDGET,
                    &mut s.links,
                    &mut 0,
                    None,
                ) {
                    Some((true, false)) => {}
                    Some((false, true)) => now &= !bit,
                    _ => cut |= bit,
                }
            }
            if cut == 0 {
                if now != *flags {
                    relabel.push((i as u32, now));
                }
                continue;
            }
            // the cell in the scratch arena, filtered by the lights that
            // may cut it
            let mut copy = Piece::default();
            for (&v, &e) in piece.verts.iter().zip(&piece.edges) {
                copy.verts.push(s.arena.copy_vertex(&cells.arena, v));
                copy.edges
                    .push(EdgeRef::new(s.arena.add_plane(cells.arena.plane(e)), false));
            }
            s.cur.clear();
            s.cur.push((copy, now));
            self.pass_lights(s, cut);
            if s.cur.len() == 1 {
                let f = s.cur[0].1;
                if f != *flags {
                    relabel.push((i as u32, f));
                }
                continue;
            }
            removed.push(i as u32);
            for (p, f) in s.cur.drain(..) {
                s.pieces.push(p);
                s.labels.push(f);
            }
        }
        if removed.is_empty() && relabel.is_empty() {
            return Refined::Unchanged;
        }
        let merged = cells
            .merge
            .remerge(&removed, &relabel, &s.arena, &s.pieces, &s.labels);
        out.push_remerged(
            first.tag(),
            receiver,
            facing,
            &support,
            &cells.merge,
            &merged,
            opts,
        );
        if merged.standing.is_empty() {
            Refined::All
        } else {
            Refined::Some(merged.standing)
        }
    }

    /// Sets the scratch up with the receiver's cells as `start` says, and
    /// filters every cell lit by a light through that light's tree.
    /// Returns whether a cell was cut or changed its flags.
    fn filter_lights(&self, polys: &[Polygon], start: &Start<'_>, s: &mut Scratch) -> bool {
        self.filter_lights_of(polys, start, s, u64::MAX)
    }

    /// [`ShadowSet::filter_lights`] through the trees of the lights in
    /// `mask` only.
    fn filter_lights_of(
        &self,
        polys: &[Polygon],
        start: &Start<'_>,
        s: &mut Scratch,
        mask: u64,
    ) -> bool {
        let support = *polys[0].support();
        let face = polys[0].tag();
        s.arena.clear();
        s.cur.clear();
        match start {
            Start::Uniform(flags) => {
                s.support = s.arena.add_plane(support);
                for p in polys {
                    debug_assert!(p.support() == &support && p.tag() == face);
                    let c = s.arena.add_polygon(p);
                    s.cur.push((c, *flags));
                }
                s.whole = s.cur[0].0.clone();
            }
            Start::Cells(cells) => {
                s.arena.clone_from(&cells.arena);
                s.cur.extend_from_slice(&cells.cells);
                s.support = cells.support;
                s.whole = s.arena.add_polygon(&polys[0]);
            }
        }
        // lights the face turns its back to: attached shadow, the flag
        // stays 0
        let facing = self.facing(&support);
        self.pass_lights(s, facing & mask)
    }

    /// Merges the scratch's cells into regions and appends them.
    fn finish(
        &self,
        polys: &[Polygon],
        receiver: u32,
        opts: &ShadeOptions,
        s: &mut Scratch,
        out: &mut Batch,
    ) {
        let support = *polys[0].support();
        let facing = self.facing(&support);
        out.push_receiver(
            polys[0].tag(),
            receiver,
            facing,
            &support,
            s,
            polys.len() == 1,
            opts,
        );
    }

    /// Shades the receivers `ranges` of `polys` (see [`receivers`]) into
    /// one batch, in order; receiver `i` of the list is recorded as
    /// `first_receiver + i`.
    pub fn shade_ranges(
        &self,
        polys: &[Polygon],
        ranges: &[Range<usize>],
        first_receiver: u32,
        opts: &ShadeOptions,
    ) -> Batch {
        let mut scratch = Scratch::default();
        let mut out = Batch::new();
        let known = self.knows(polys);
        for (i, r) in ranges.iter().enumerate() {
            let receiver = first_receiver + i as u32;
            match known {
                true => self.shade_known(polys, r.clone(), receiver, opts, &mut scratch, &mut out),
                false => self.shade(&polys[r.clone()], receiver, opts, &mut scratch, &mut out),
            }
        }
        out
    }

    /// Shades every receiver of `polys`, in parallel, into one batch in
    /// receiver order (the same for every thread count).
    pub fn shade_all(&self, polys: &[Polygon], opts: &ShadeOptions) -> Batch {
        self.shade_par(polys, &receivers(polys), opts, |_| {})
    }

    /// [`ShadowSet::shade_ranges`] of the receivers `ranges` (receiver
    /// `i`: `ranges[i]`), in parallel by [`CHUNK`] receivers (the large
    /// ones first and alone, see `large_receivers`), into one batch in
    /// receiver order (the same for every thread count);
    /// `done(n)` is told of every `n` receivers shaded (for a progress
    /// bar).
    pub fn shade_par(
        &self,
        polys: &[Polygon],
        ranges: &[Range<usize>],
        opts: &ShadeOptions,
        done: impl Fn(usize) + Sync,
    ) -> Batch {
        let large = large_receivers(polys, ranges);
        let runs = runs(0..ranges.len(), &large, CHUNK);
        // the large receivers first (see `large_receivers`), then the rest
        let order = large.iter().map(|&i| i..i + 1);
        let order: Vec<Range<usize>> = order
            .chain(runs.iter().filter(|&r| !is_one_of(r, &large)).cloned())
            .collect();
        let mut batches: Vec<(usize, Batch)> = order
            .par_iter()
            .map(|r| {
                let b = self.shade_ranges(polys, &ranges[r.clone()], r.start as u32, opts);
                done(r.len());
                (r.start, b)
            })
            .collect();
        // back in receiver order: the runs' order
        batches.sort_unstable_by_key(|b| b.0);
        let parts: Vec<&Batch> = batches.iter().map(|b| &b.1).collect();
        Batch::concat(&parts)
    }
}

/// Receivers per parallel task in [`ShadowSet::shade_all`].
pub const CHUNK: usize = 512;

/// Work space of [`ShadowSet::shade`], reused from receiver to receiver so
/// that shading allocates nothing once warm.
#[derive(Default)]
pub struct Scratch {
    arena: PieceArena,
    /// The support plane's index in the arena.
    support: u32,
    cur: Vec<(Piece, u64)>,
    next: Vec<(Piece, u64)>,
    out: Vec<(Piece, bool)>,
    stack: Vec<Walk>,
    links: Vec<u32>,
    /// The receiver's first polygon, as it was added.
    whole: Piece,
    sides: SmallVec<[Side; 8]>,
    rounded: Vec<Option<[f64; 3]>>,
    remap: Vec<u32>,
    pieces: Vec<Piece>,
    labels: Vec<u64>,
    /// Whether a cell that some light it was filtered through reaches and
    /// another does not (a light the receiver turns from counting as one
    /// that does not) goes through no more trees: an area light's corner
    /// cells, where such a cell is penumbra whatever the other corners
    /// ([`ShadowSet::cells_known`]).
    settle_mixed: bool,
}

/// A receiver's convex cells with their flags (bit `j`: lit by light
/// `j`), in their own arena: where [`ShadowSet::refine`] can start.
#[derive(Clone, Debug)]
pub struct Cells {
    arena: PieceArena,
    cells: Vec<(Piece, u64)>,
    support: u32,
    /// The cells' merge into the receiver's fragments, kept for redoing
    /// it where they change.
    merge: MergeCache,
}

/// What [`ShadowSet::refine_cells`] did.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Refined {
    /// Nothing changed and nothing was appended: the receiver's
    /// fragments are the ones it started from.
    Unchanged,
    /// All of the receiver's fragments were appended.
    All,
    /// The starting fragments listed (indices among the receiver's
    /// fragments, in order) stand; the fragments appended replace the
    /// others.
    Some(Vec<u32>),
}

impl Cells {
    /// Per cell, a box of grid points that holds it: the floor and ceiling
    /// of its vertices' correctly rounded coordinates widened by one step
    /// (a rounded coordinate is within half a step of the exact one), for
    /// culling tests such as [`ShadowSet::refine_cells`]'s.
    pub fn bounds(&self) -> Vec<([i32; 3], [i32; 3])> {
        self.cells
            .iter()
            .map(|(c, _)| {
                let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
                for &v in &c.verts {
                    let p = self.arena.vertex(v).to_f64();
                    for k in 0..3 {
                        lo[k] = lo[k].min(p[k]);
                        hi[k] = hi[k].max(p[k]);
                    }
                }
                let m = bsp_core::MAX_COORD as f64;
                (
                    lo.map(|x| (x.floor() - 1.0).clamp(-m, m) as i32),
                    hi.map(|x| (x.ceil() + 1.0).clamp(-m, m) as i32),
                )
            })
            .collect()
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.cells.len()
    }

    /// `true` if there is no cell.
    pub fn is_empty(&self) -> bool {
        self.cells.is_empty()
    }

    /// The flags of each cell.
    pub fn flags(&self) -> impl Iterator<Item = u64> + '_ {
        self.cells.iter().map(|c| c.1)
    }
}

/// Where [`ShadowSet::refine`] starts a receiver from.
#[derive(Clone, Copy, Debug)]
pub enum Start<'a> {
    /// The receiver's polygons, all with these flags.
    Uniform(u64),
    /// Cells kept by [`ShadowSet::shade_keeping`].
    Cells(&'a Cells),
}

/// Fragments of many receivers in flat arrays: per fragment its face,
/// receiver, flags and rings (the first ring is the outer boundary,
/// counter-clockwise seen from the face's front; the others are holes,
/// clockwise), and optionally its convex pieces; vertices exact and
/// correctly rounded to `f64` grid coordinates, each stored once per
/// receiver.
#[derive(Clone, Debug)]
pub struct Batch {
    face: Vec<u32>,
    receiver: Vec<u32>,
    lit: Vec<u64>,
    facing: Vec<u64>,
    support: Vec<Plane>,
    frag_ring: Vec<u32>,
    ring_start: Vec<u32>,
    ring_verts: Vec<u32>,
    frag_piece: Vec<u32>,
    piece_start: Vec<u32>,
    piece_verts: Vec<u32>,
    /// Per piece corner, the plane of the edge leaving it (the piece
    /// behind it); valid while it is as long as `piece_verts` (every
    /// piece recorded with [`ShadeOptions::planes`]).
    piece_planes: Vec<Plane>,
    vertices: Vec<Vertex>,
    rounded: Vec<[f64; 3]>,
}

impl Default for Batch {
    fn default() -> Batch {
        Batch::new()
    }
}

/// One fragment of a [`Batch`].
#[derive(Clone, Copy, Debug)]
pub struct FragmentRef<'a> {
    batch: &'a Batch,
    index: usize,
}

impl<'a> FragmentRef<'a> {
    /// The batch it belongs to (for its vertices).
    pub fn batch(&self) -> &'a Batch {
        self.batch
    }

    /// The input face (the polygons' tag).
    pub fn face(&self) -> u32 {
        self.batch.face[self.index]
    }

    /// The receiver it was shaded as (see [`ShadowSet::shade`]).
    pub fn receiver(&self) -> u32 {
        self.batch.receiver[self.index]
    }

    /// Bit `i` set: light `i` reaches the fragment's front side
    /// unobstructed.
    pub fn lit_mask(&self) -> u64 {
        self.batch.lit[self.index]
    }

    /// `true` if light `i` reaches it.
    pub fn lit(&self, i: usize) -> bool {
        self.lit_mask() >> i & 1 == 1
    }

    /// Bit `i` set: light `i` is strictly in front of the face's plane
    /// (an unlit fragment is then in cast shadow, else in attached shadow).
    pub fn facing_mask(&self) -> u64 {
        self.batch.facing[self.index]
    }

    /// The face's support plane.
    pub fn support(&self) -> &'a Plane {
        &self.batch.support[self.index]
    }

    /// The rings: the outer boundary first, then the holes; each a list of
    /// vertex indices into the batch ([`Batch::vertex`], [`Batch::rounded`]).
    pub fn rings(self) -> impl Iterator<Item = &'a [u32]> + 'a {
        let b = self.batch;
        let r = b.frag_ring[self.index] as usize..b.frag_ring[self.index + 1] as usize;
        r.map(move |k| &b.ring_verts[b.ring_start[k] as usize..b.ring_start[k + 1] as usize])
    }

    /// The outer boundary.
    pub fn outer(self) -> &'a [u32] {
        self.rings().next().expect("a fragment has an outer ring")
    }

    /// Number of holes.
    pub fn hole_count(&self) -> usize {
        (self.batch.frag_ring[self.index + 1] - self.batch.frag_ring[self.index]) as usize - 1
    }

    /// Convex pieces whose union is the fragment (empty unless shaded with
    /// [`ShadeOptions::pieces`]), counter-clockwise.
    pub fn pieces(self) -> impl Iterator<Item = &'a [u32]> + 'a {
        let b = self.batch;
        let r = b.frag_piece[self.index] as usize..b.frag_piece[self.index + 1] as usize;
        r.map(move |k| &b.piece_verts[b.piece_start[k] as usize..b.piece_start[k + 1] as usize])
    }

    /// Per convex piece (as [`FragmentRef::pieces`]), its edge planes in
    /// turn, exact: plane `i` bounds the edge from corner `i` to `i + 1`,
    /// the piece behind it, so that with the fragment's support plane
    /// they make the piece again ([`bsp_core::Polygon::from_planes`]).
    /// `None` unless the batch was shaded with [`ShadeOptions::planes`].
    pub fn piece_planes(self) -> Option<impl Iterator<Item = &'a [Plane]> + 'a> {
        let b = self.batch;
        (b.piece_planes.len() == b.piece_verts.len()).then(|| {
            let r = b.frag_piece[self.index] as usize..b.frag_piece[self.index + 1] as usize;
            r.map(move |k| {
                &b.piece_planes[b.piece_start[k] as usize..b.piece_start[k + 1] as usize]
            })
        })
    }
}

impl Batch {
    /// An empty batch.
    pub fn new() -> Batch {
        Batch {
            face: Vec::new(),
            receiver: Vec::new(),
            lit: Vec::new(),
            facing: Vec::new(),
            support: Vec::new(),
            frag_ring: vec![0],
            ring_start: vec![0],
            ring_verts: Vec::new(),
            frag_piece: vec![0],
            piece_start: vec![0],
            piece_verts: Vec::new(),
            piece_planes: Vec::new(),
            vertices: Vec::new(),
            rounded: Vec::new(),
        }
    }

    /// Number of fragments.
    pub fn len(&self) -> usize {
        self.face.len()
    }

    /// `true` if there are no fragments.
    pub fn is_empty(&self) -> bool {
        self.face.is_empty()
    }

    /// Fragment `i`.
    pub fn fragment(&self, i: usize) -> FragmentRef<'_> {
        assert!(i < self.len(), "fragment {i} of {}", self.len());
        FragmentRef {
            batch: self,
            index: i,
        }
    }

    /// Every fragment, in order.
    pub fn fragments(&self) -> impl ExactSizeIterator<Item = FragmentRef<'_>> + '_ {
        (0..self.len()).map(move |index| FragmentRef { batch: self, index })
    }

    /// The exact vertex `v`; `None` in a batch made from (or with) Chin &
    /// Feiner's fragments ([`Batch::from_chin_feiner`]), whose vertices are
    /// wider than [`Vertex`], or shaded without [`ShadeOptions::vertices`].
    pub fn vertex(&self, v: u32) -> Option<&Vertex> {
        self.vertices.get(v as usize)
    }

    /// Vertex `v` in grid coordinates, correctly rounded.
    pub fn rounded(&self, v: u32) -> [f64; 3] {
        self.rounded[v as usize]
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.rounded.len()
    }

    /// Chin & Feiner's fragments in a batch, for the same outputs: each
    /// fragment is one convex ring and one piece, its receiver the index of
    /// its scene polygon; `lights` give the facing flags. Only the rounded
    /// vertices are kept ([`Batch::vertex`] is `None`).
    pub fn from_chin_feiner(cf: &crate::CfFragments, lights: &[Light]) -> Batch {
        let mut b = Batch::new();
        for f in cf.iter() {
            b.push_chin_feiner(&f, lights);
        }
        b
    }

    /// Appends one of Chin & Feiner's fragments (see
    /// [`Batch::from_chin_feiner`]).
    pub fn push_chin_feiner(&mut self, f: &crate::CfFragment<'_>, lights: &[Light]) {
        let b = self;
        let support = *f.support();
        let facing = lights
            .iter()
            .enumerate()
            .fold(0u64, |m, (j, l)| m | (l.faces(&support) as u64) << j);
        b.face.push(f.face());
        b.receiver.push(f.polygon());
        b.lit.push(f.lit_mask());
        b.facing.push(facing);
        b.support.push(support);
        let first = b.rounded.len() as u32;
        b.rounded.extend(f.vertices_f64());
        let last = b.rounded.len() as u32;
        b.ring_verts.extend(first..last);
        b.ring_start.push(b.ring_verts.len() as u32);
        b.frag_ring.push((b.ring_start.len() - 1) as u32);
        b.piece_verts.extend(first..last);
        b.piece_start.push(b.piece_verts.len() as u32);
        b.frag_piece.push((b.piece_start.len() - 1) as u32);
    }

    /// The fragments of `parts` one after the other (as [`Batch::append`]
    /// of each in turn), every list allocated once at its final length
    /// rather than grown (and copied) batch by batch.
    pub fn concat(parts: &[&Batch]) -> Batch {
        let mut out = Batch::new();
        let total = |len: fn(&Batch) -> usize| parts.iter().map(|b| len(b)).sum::<usize>();
        out.face.reserve(total(|b| b.face.len()));
        out.receiver.reserve(total(|b| b.receiver.len()));
        out.lit.reserve(total(|b| b.lit.len()));
        out.facing.reserve(total(|b| b.facing.len()));
        out.support.reserve(total(|b| b.support.len()));
        out.frag_ring.reserve(total(|b| b.frag_ring.len()));
        out.ring_start.reserve(total(|b| b.ring_start.len()));
        out.ring_verts.reserve(total(|b| b.ring_verts.len()));
        out.frag_piece.reserve(total(|b| b.frag_piece.len()));
        out.piece_start.reserve(total(|b| b.piece_start.len()));
        out.piece_verts.reserve(total(|b| b.piece_verts.len()));
        out.piece_planes.reserve(total(|b| b.piece_planes.len()));
        out.vertices.reserve(total(|b| b.vertices.len()));
        out.rounded.reserve(total(|b| b.rounded.len()));
        for b in parts {
            out.append(b);
        }
        out
    }

    /// Appends another batch's fragments.
    pub fn append(&mut self, o: &Batch) {
        self.append_range(o, 0..o.len());
    }

    /// Appends fragments `frags` of another batch (with the vertices they
    /// use: the span of vertex indices from their lowest to their highest,
    /// which is exactly theirs when `frags` covers whole receivers).
    pub fn append_range(&mut self, o: &Batch, frags: Range<usize>) {
        if frags.is_empty() {
            return;
        }
        let rings = o.frag_ring[frags.start] as usize..o.frag_ring[frags.end] as usize;
        let pieces = o.frag_piece[frags.start] as usize..o.frag_piece[frags.end] as usize;
        let rv = o.ring_start[rings.start] as usize..o.ring_start[rings.end] as usize;
        let pv = o.piece_start[pieces.start] as usize..o.piece_start[pieces.end] as usize;
        let used = o.ring_verts[rv.clone()]
            .iter()
            .chain(&o.piece_verts[pv.clone()]);
        let (lo, hi) = used.fold((u32::MAX, 0), |(lo, hi), &v| (lo.min(v), hi.max(v + 1)));
        let v0 = self.rounded.len() as u32;
        let shift = |v: u32| v - lo + v0;
        let (r0, p0) = (
            (self.ring_start.len() - 1) as u32,
            (self.piece_start.len() - 1) as u32,
        );
        let (rv0, pv0) = (self.ring_verts.len() as u32, self.piece_verts.len() as u32);
        self.face.extend_from_slice(&o.face[frags.clone()]);
        self.receiver.extend_from_slice(&o.receiver[frags.clone()]);
        self.lit.extend_from_slice(&o.lit[frags.clone()]);
        self.facing.extend_from_slice(&o.facing[frags.clone()]);
        self.support.extend_from_slice(&o.support[frags.clone()]);
        let (fr, fp) = (o.frag_ring[frags.start], o.frag_piece[frags.start]);
        self.frag_ring.extend(
            o.frag_ring[frags.start + 1..=frags.end]
                .iter()
                .map(|r| r - fr + r0),
        );
        self.frag_piece.extend(
            o.frag_piece[frags.start + 1..=frags.end]
                .iter()
                .map(|r| r - fp + p0),
        );
        let (rs, ps) = (o.ring_start[rings.start], o.piece_start[pieces.start]);
        self.ring_start.extend(
            o.ring_start[rings.start + 1..=rings.end]
                .iter()
                .map(|s| s - rs + rv0),
        );
        self.piece_start.extend(
            o.piece_start[pieces.start + 1..=pieces.end]
                .iter()
                .map(|s| s - ps + pv0),
        );
        self.ring_verts
            .extend(o.ring_verts[rv].iter().map(|&v| shift(v)));
        let planes = self.piece_planes.len() == self.piece_verts.len()
            && o.piece_planes.len() == o.piece_verts.len();
        if planes {
            self.piece_planes
                .extend_from_slice(&o.piece_planes[pv.clone()]);
        }
        self.piece_verts
            .extend(o.piece_verts[pv].iter().map(|&v| shift(v)));
        if lo < hi {
            let span = lo as usize..hi as usize;
            // exact vertices only while every part has them
            if self.vertices.len() == self.rounded.len() && o.vertices.len() == o.rounded.len() {
                self.vertices.extend_from_slice(&o.vertices[span.clone()]);
            } else {
                self.vertices.clear();
            }
            self.rounded.extend_from_slice(&o.rounded[span]);
        }
    }

    /// Per receiver, in order, its range of fragments: consecutive
    /// fragments with the same receiver number.
    pub fn receiver_ranges(&self) -> Vec<(u32, Range<usize>)> {
        let mut out: Vec<(u32, Range<usize>)> = Vec::new();
        for (i, &r) in self.receiver.iter().enumerate() {
            match out.last_mut() {
                Some((last, range)) if *last == r => range.end = i + 1,
                _ => out.push((r, i..i + 1)),
            }
        }
        out
    }

    /// A vertex of the scratch arena, added once per receiver (with
    /// `exact`, its exact coordinates kept too).
    fn take_vertex(&mut self, s: &mut Scratch, v: u32, exact: bool) -> u32 {
        let d = s.arena.dense(v);
        let slot = &mut s.remap[d];
        if *slot == u32::MAX {
            let vert = s.arena.vertex(v);
            let r = s
                .rounded
                .get(d)
                .copied()
                .flatten()
                .unwrap_or_else(|| vert.to_f64());
            if exact {
                self.vertices.push(vert.to_owned());
            }
            self.rounded.push(r);
            *slot = (self.rounded.len() - 1) as u32;
        }
        *slot
    }

    fn push_meta(&mut self, face: u32, receiver: u32, lit: u64, facing: u64, support: &Plane) {
        self.face.push(face);
        self.receiver.push(receiver);
        self.lit.push(lit);
        self.facing.push(facing);
        self.support.push(*support);
    }

    /// Closes the fragment's rings (each already pushed and closed) and
    /// pieces.
    fn close_fragment(&mut self) {
        self.frag_ring.push((self.ring_start.len() - 1) as u32);
        self.frag_piece.push((self.piece_start.len() - 1) as u32);
    }

    #[allow(clippy::too_many_arguments)]
    fn push_receiver(
        &mut self,
        face: u32,
        receiver: u32,
        facing: u64,
        support: &Plane,
        s: &mut Scratch,
        single_polygon: bool,
        opts: &ShadeOptions,
    ) {
        let uniform = s.cur.iter().all(|(_, l)| *l == s.cur[0].1);
        let whole = single_polygon && uniform;
        if whole || !opts.merge {
            s.remap.clear();
            s.remap.resize(s.arena.len(), u32::MAX);
            s.rounded.clear();
            if whole {
                // one set of flags all over: the receiver's own polygon,
                // whole
                let lit = s.cur[0].1;
                s.cur.clear();
                let piece = std::mem::take(&mut s.whole);
                self.push_meta(face, receiver, lit, facing, support);
                self.push_convex(s, &piece, opts);
            } else {
                // each piece a fragment of its own ([`ShadeOptions::merge`]
                // off)
                let cur = std::mem::take(&mut s.cur);
                for (piece, lit) in &cur {
                    self.push_meta(face, receiver, *lit, facing, support);
                    self.push_convex(s, piece, opts);
                }
                s.cur = cur;
                s.cur.clear();
            }
            return;
        }
        s.pieces.clear();
        s.labels.clear();
        for (p, l) in s.cur.drain(..) {
            s.pieces.push(p);
            s.labels.push(l);
        }
        s.rounded.clear();
        let regions = merge_cells(&s.arena, support, &s.pieces, &s.labels, &mut s.rounded);
        self.push_regions(face, receiver, facing, support, s, &regions, opts);
    }

    /// Closes the fragment begun by [`Batch::push_meta`] with one convex
    /// piece of the scratch's arena: its ring, and (as `opts` asks) the
    /// piece itself and its edge planes.
    fn push_convex(&mut self, s: &mut Scratch, piece: &Piece, opts: &ShadeOptions) {
        let start = self.ring_verts.len();
        for &v in &piece.verts {
            let id = self.take_vertex(s, v, opts.vertices);
            self.ring_verts.push(id);
        }
        self.ring_start.push(self.ring_verts.len() as u32);
        if opts.pieces {
            let copy: SmallVec<[u32; 8]> = self.ring_verts[start..].iter().copied().collect();
            self.piece_verts.extend(copy);
            self.piece_start.push(self.piece_verts.len() as u32);
            if opts.planes {
                (self.piece_planes).extend(piece.edges.iter().map(|&e| s.arena.plane(e)));
            }
        }
        self.close_fragment();
    }

    /// Appends merged regions of the scratch's cells (`s.pieces`, vertices
    /// in `s.arena`).
    #[allow(clippy::too_many_arguments)]
    fn push_regions(
        &mut self,
        face: u32,
        receiver: u32,
        facing: u64,
        support: &Plane,
        s: &mut Scratch,
        regions: &[Region],
        opts: &ShadeOptions,
    ) {
        s.remap.clear();
        s.remap.resize(s.arena.len(), u32::MAX);
        s.rounded.resize(s.arena.len(), None);
        for r in regions {
            self.push_meta(face, receiver, r.label, facing, support);
            for ring in std::iter::once(&r.outer).chain(&r.holes) {
                for &v in ring {
                    let id = self.take_vertex(s, v, opts.vertices);
                    self.ring_verts.push(id);
                }
                self.ring_start.push(self.ring_verts.len() as u32);
            }
            if opts.pieces {
                for &c in &r.cells {
                    let verts = s.pieces[c as usize].verts.clone();
                    for v in verts {
                        let id = self.take_vertex(s, v, opts.vertices);
                        self.piece_verts.push(id);
                    }
                    self.piece_start.push(self.piece_verts.len() as u32);
                    if opts.planes {
                        let edges = &s.pieces[c as usize].edges;
                        (self.piece_planes).extend(edges.iter().map(|&e| s.arena.plane(e)));
                    }
                }
            }
            self.close_fragment();
        }
    }

    /// Appends the regions of a re-merge (their points exact in the cache
    /// or the re-merge).
    #[allow(clippy::too_many_arguments)]
    fn push_remerged(
        &mut self,
        face: u32,
        receiver: u32,
        facing: u64,
        support: &Plane,
        cache: &MergeCache,
        m: &Remerged,
        opts: &ShadeOptions,
    ) {
        let mut ids: rustc_hash::FxHashMap<u32, u32> = rustc_hash::FxHashMap::default();
        let mut take = |b: &mut Batch, p: u32| {
            *ids.entry(p).or_insert_with(|| {
                let (v, r) = m.point(cache, p);
                if opts.vertices {
                    b.vertices.push(v.clone());
                }
                b.rounded.push(r);
                (b.rounded.len() - 1) as u32
            })
        };
        for r in &m.regions {
            self.push_meta(face, receiver, r.label, facing, support);
            for ring in std::iter::once(&r.outer).chain(&r.holes) {
                for &p in ring {
                    let id = take(self, p);
                    self.ring_verts.push(id);
                }
                self.ring_start.push(self.ring_verts.len() as u32);
            }
            if opts.pieces {
                for &c in &r.cells {
                    for &p in m.cell_points(cache, c) {
                        let id = take(self, p);
                        self.piece_verts.push(id);
                    }
                    self.piece_start.push(self.piece_verts.len() as u32);
                }
            }
            self.close_fragment();
        }
    }
}

/// Figures of one run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ShadowStats {
    /// Receivers shaded (faces, or face parts in different planes).
    pub receivers: usize,
    /// Fragments produced.
    pub fragments: usize,
    /// Shadow-volume tree nodes, summed over the lights.
    pub shadow_nodes: usize,
}

/// Exact lit and shadowed fragments of every face of `polys` (imported
/// polygons with grid vertices, tagged with their face) for each of
/// `lights`: every face is both occluder and receiver. A convenience over
/// [`LightVolumes`]; receivers are shaded in parallel.
pub fn shadow_fragments(
    polys: &[Polygon],
    lights: &[Light],
) -> Result<(Batch, ShadowStats), ShadowError> {
    let shadows = LightVolumes::new_reaching(polys, lights)?;
    let batch = (shadows.set_for_occluders()).shade_all(polys, &ShadeOptions::default());
    let stats = ShadowStats {
        receivers: receivers(polys).len(),
        fragments: batch.len(),
        shadow_nodes: shadows.volumes.iter().map(ShadowVolumes::node_count).sum(),
    };
    Ok((batch, stats))
}

#[cfg(test)]
mod tests;

mod building;
mod known;
mod passes;
