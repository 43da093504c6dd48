//! The core paper's real-time pipeline: a static scene whose shadows are
//! computed once, and a moving object whose shadows, on itself and on the
//! static polygons near it, are recomputed every frame.
//!
//! **Preprocess** ([`Dynamic::new`]): the static faces are imported on the
//! grid, their shadows computed once for every light, and one
//! [`TileIndex`] built per light; the dynamic object's faces are kept in
//! input units, with (for the paper's strategy) its BSP tree `Bsp2`.
//!
//! **Per frame** ([`Dynamic::frame`]): the object's *original* coordinates
//! are transformed by the frame's 4×4 matrix and snapped to the scene's
//! grid; transforms are never composed on snapped coordinates, so frame
//! `k` is the same whether or not frames `0..k` were computed, and
//! rounding never accumulates. The snapped object's box, projected
//! through each light's tiling, gives the *related* static polygons: the
//! only ones that can shadow the object or be shadowed by it. Then:
//!
//! - [`Strategy::Paper`], as Liu & Wu give it: `Bsp2` replayed on the
//!   moved faces ([`bsp_core::BspTree::replay`]), `Bsp3` built from the
//!   related static polygons, `Bsp4 = Bsp2 + Bsp3` by the overlay merge,
//!   and Chin & Feiner's shadows of `Bsp4`. A related static face's
//!   fragments are those of `Bsp4` overlaid with its static fragments
//!   (lit where both are lit); every other static face keeps its static
//!   fragments.
//! - [`Strategy::Fast`]: no `Bsp3` or `Bsp4`. Per light, one partitioned
//!   shadow-volume tree over the moved faces and the related static
//!   polygons (the tree does not depend on an order), through which the
//!   moved faces are shaded; each related static face's static cells are
//!   refined through the same tree ([`svbsp::ShadowSet::refine`]).
//!
//! Either way the frame's fragments are exact, and every face's lit area
//! is exactly what [`svbsp::shadow_fragments`] computes from scratch on
//! the frame's whole scene (tested over random motions).

use std::ops::Range;
use std::time::{Duration, Instant};

use bsp_core::internals::merge_smaller_into_larger;
use bsp_core::{
    BspTree, BuildOptions, Grid, GridPoint, Overlay, Partition, Point, Polygon, import_faces_par,
};
use glam::{DMat4, DVec3};
use rayon::prelude::*;
use rustc_hash::FxHashMap;
use svbsp::{
    Batch, CHUNK, Cells, CfFragments, Light, LightVolumes, Refined, Scratch, ShadeOptions,
    ShadowError, ShadowVolumes, Start, chin_feiner, receivers,
};

use crate::{Query, TileIndex, TilingError};

/// How each frame's shadows are computed (see the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Strategy {
    /// Liu & Wu's pipeline: `Bsp4 = Bsp2 + Bsp3` and Chin & Feiner's
    /// shadow-volume BSP tree.
    Paper,
    /// Partitioned shadow volumes of the moved and related polygons, no
    /// per-frame BSP.
    #[default]
    Fast,
}

/// Options of [`Dynamic::new`].
#[derive(Clone, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct PipelineOptions {
    /// The per-frame strategy.
    pub strategy: Strategy,
    /// Tiles per side of every light's index; `None` for [`crate::tiles_for`].
    pub tiles: Option<u32>,
    /// Record each fragment's convex pieces (for OBJ output).
    pub pieces: bool,
    /// Keep only the rounding of the fragments' vertices, not their exact
    /// coordinates ([`svbsp::Batch::vertex`]): a picture or a file needs
    /// only the rounding, and a frame is then about 7% quicker.
    pub rounded_only: bool,
}

impl PipelineOptions {
    /// Sets [`PipelineOptions::strategy`].
    pub fn with_strategy(mut self, s: Strategy) -> Self {
        self.strategy = s;
        self
    }
    /// Sets [`PipelineOptions::tiles`].
    pub fn with_tiles(mut self, n: Option<u32>) -> Self {
        self.tiles = n;
        self
    }
    /// Sets [`PipelineOptions::pieces`].
    pub fn with_pieces(mut self, p: bool) -> Self {
        self.pieces = p;
        self
    }
    /// Sets [`PipelineOptions::rounded_only`].
    pub fn with_rounded_only(mut self, r: bool) -> Self {
        self.rounded_only = r;
        self
    }
    /// The shading options these ask for.
    fn shading(&self) -> ShadeOptions {
        ShadeOptions::default()
            .with_pieces(self.pieces)
            .with_vertices(!self.rounded_only)
    }
}

/// Why the pipeline cannot run.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum PipelineError {
    /// A static face does not fit the grid.
    Static(bsp_core::InputError),
    /// A face of the moved object does not fit the grid in this frame
    /// (the error names the dynamic face).
    Moved(bsp_core::InputError),
    /// The tiling of a light cannot be built.
    Tiling(TilingError),
    /// The shadows cannot be computed (a light or an occluder is unusable).
    Shadow(ShadowError),
}

impl std::fmt::Display for PipelineError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PipelineError::Static(e) => write!(f, "static scene: {e}"),
            PipelineError::Moved(e) => write!(f, "moved object: {e}"),
            PipelineError::Tiling(e) => write!(f, "tiling: {e}"),
            PipelineError::Shadow(e) => write!(f, "shadows: {e}"),
        }
    }
}

impl std::error::Error for PipelineError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            PipelineError::Static(e) | PipelineError::Moved(e) => Some(e),
            PipelineError::Tiling(e) => Some(e),
            PipelineError::Shadow(e) => Some(e),
        }
    }
}

/// A motion: frame `k` rotates the original coordinates by `k × degrees`
/// about `axis` through `centre`, then translates them by `k × step`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    /// The rotation axis (any length; zero means no rotation).
    pub axis: DVec3,
    /// Degrees per frame, counter-clockwise about `axis`.
    pub degrees: f64,
    /// A point on the rotation axis.
    pub centre: DVec3,
    /// Translation per frame.
    pub step: DVec3,
}

impl Motion {
    /// The transform of frame `k` (frame 0 is the identity).
    ///
    /// ```
    /// use glam::DVec3;
    /// use tiling::Motion;
    /// let m = Motion { axis: DVec3::Z, degrees: 90.0, centre: DVec3::X, step: DVec3::ZERO };
    /// let p = m.matrix(1).transform_point3(DVec3::new(2.0, 0.0, 0.0));
    /// assert!((p - DVec3::new(1.0, 1.0, 0.0)).length() < 1e-12);
    /// ```
    pub fn matrix(&self, k: u32) -> DMat4 {
        let k = k as f64;
        let rot = if self.axis.length_squared() > 0.0 && self.degrees != 0.0 {
            DMat4::from_axis_angle(self.axis.normalize(), (k * self.degrees).to_radians())
        } else {
            DMat4::IDENTITY
        };
        DMat4::from_translation(k * self.step + self.centre)
            * rot
            * DMat4::from_translation(-self.centre)
    }

    /// The box of `points` over frames `0..frames`: the corners of the
    /// box of every position they take.
    pub fn swept_bounds(&self, points: &[DVec3], frames: u32) -> (DVec3, DVec3) {
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for k in 0..frames {
            let m = self.matrix(k);
            for p in points {
                let q = m.transform_point3(*p);
                lo = lo.min(q);
                hi = hi.max(q);
            }
        }
        (lo, hi)
    }
}

/// Figures of the preprocessing.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PrepStats {
    /// Static faces.
    pub static_faces: usize,
    /// Static polygons (convex, as imported).
    pub static_polygons: usize,
    /// Static polygons after the static BSP's splits (`Bsp1`; the imported
    /// count with the fast strategy, which builds none).
    pub static_after_bsp: usize,
    /// Static fragments of the static shadows.
    pub static_after_shadow: usize,
    /// Time to import the static faces.
    pub t_import: Duration,
    /// Time of the static shadows (and `Bsp1`).
    pub t_shadows: Duration,
    /// Time to build the tilings.
    pub t_tiling: Duration,
}

/// Per-strategy static data (one per scene: its size does not matter).
#[allow(clippy::large_enum_variant)]
enum StaticShadows {
    Fast(FastStatics),
    Paper(PaperStatics),
}

/// The fast strategy's static data.
struct FastStatics {
    /// The static scene's shadow trees.
    shadows: LightVolumes,
    batch: Batch,
    /// Per static receiver, its fragments in `batch`.
    frags: Vec<Range<usize>>,
    /// Per static receiver, its cells when its flags vary.
    cells: Vec<Option<Box<Cells>>>,
    /// Per static receiver with cells, per light, per cell: the tiles
    /// of the cell's box (a frame leaves a cell alone when its box
    /// meets none of the tiles of the moved object's box).
    footprints: FxHashMap<u32, Vec<Vec<Vec<u32>>>>,
}

/// The paper's strategy's static data.
struct PaperStatics {
    cf: CfFragments,
    /// Per static face, its fragments in `cf`.
    of_face: Vec<Vec<u32>>,
    /// `Bsp2`, built on the object as given.
    bsp2: BspTree,
}

/// A static scene prepared once, and a moving object (see the module
/// docs).
pub struct Dynamic {
    grid: Grid,
    lights: Vec<Light>,
    opts: PipelineOptions,
    statics: Vec<Polygon>,
    static_faces: usize,
    receivers: Vec<Range<usize>>,
    /// Static polygon → its receiver.
    receiver_of: Vec<u32>,
    /// Per static face, its polygons.
    face_polys: Vec<Range<usize>>,
    tilings: Vec<TileIndex>,
    moving: Vec<Vec<DVec3>>,
    shadows: StaticShadows,
    prepared: PrepStats,
}

/// One frame's figures: the columns of the core paper's Table 2.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameStats {
    /// Static input faces.
    pub static_polygons: usize,
    /// Dynamic input faces.
    pub dynamic_polygons: usize,
    /// Dynamic polygons after the BSP's splits (`Bsp2`; the imported
    /// convex polygons with the fast strategy).
    pub dynamic_after_bsp: usize,
    /// Static polygons after the static BSP's splits (see [`PrepStats`]).
    pub static_after_bsp: usize,
    /// Static fragments of the static shadows.
    pub static_after_shadow: usize,
    /// Fragments made by this frame's shadow computation (the moved
    /// object's and the related static faces').
    pub dynamic_shadow_polygons: usize,
    /// Fragments of the whole frame: the untouched static faces' and this
    /// frame's.
    pub total_drawn: usize,
    /// Related static polygons (the union over the lights).
    pub related: usize,
    /// Fast strategy: the object's faces were shaded through the static
    /// trees and a tree of the object alone (many related polygons may
    /// block light on its way to the object), rather than through one tree
    /// of the object and those polygons.
    pub layered: bool,
    /// Fast strategy: the lights for which the object's faces turned away
    /// were left out of the shadow trees (its snapped surface certified to
    /// bound solids, see [`bsp_core::certify_solid_boundary`], and the
    /// light outside them).
    pub culled: usize,
    /// Time of the tiling queries.
    pub t_tiling: Duration,
    /// Time of the merge: `Bsp2` replayed, `Bsp3` built and merged (paper);
    /// the shadow trees built (fast).
    pub t_merge: Duration,
    /// Time of the dynamic shadows.
    pub t_dynamic_shadows: Duration,
    /// Time of the whole frame, from transform to fragments.
    pub t_frame: Duration,
}

/// What the frames of a run report, added up.
#[derive(Clone, Debug, Default)]
pub struct FrameTally {
    /// Each frame's time, in order.
    pub frame_times: Vec<Duration>,
    /// Related static polygons, over all frames.
    pub related: usize,
    /// Frames in which a light left out the object's faces turned away.
    pub culled_frames: u32,
    /// The last frame's figures.
    pub last: FrameStats,
}

impl FrameTally {
    /// Adds a frame's figures.
    pub fn add(&mut self, stats: &FrameStats) {
        self.frame_times.push(stats.t_frame);
        self.related += stats.related;
        self.culled_frames += u32::from(stats.culled > 0);
        self.last = *stats;
    }

    /// Related static polygons a frame, on average.
    pub fn related_per_frame(&self) -> f64 {
        self.related as f64 / self.frame_times.len().max(1) as f64
    }

    /// The median, mean and largest frame time (zero without frames).
    ///
    /// ```
    /// use std::time::Duration;
    /// let mut t = tiling::FrameTally::default();
    /// for ms in [3, 1, 2, 10] {
    ///     t.add(&tiling::FrameStats { t_frame: Duration::from_millis(ms), ..Default::default() });
    /// }
    /// let ms = Duration::from_millis;
    /// assert_eq!(t.times(), (ms(3), ms(4), ms(10)));
    /// ```
    pub fn times(&self) -> (Duration, Duration, Duration) {
        let mut sorted = self.frame_times.clone();
        sorted.sort();
        let Some(&max) = sorted.last() else {
            return (Duration::ZERO, Duration::ZERO, Duration::ZERO);
        };
        let mean = sorted.iter().sum::<Duration>() / sorted.len() as u32;
        (sorted[sorted.len() / 2], mean, max)
    }

    /// The frames' figures for people: `frame time median … ms, mean …
    /// ms, max … ms; … related static polygons a frame; … fragments in the
    /// last frame; faces turned away from a light left out in … of the
    /// frames`.
    ///
    /// ```
    /// use std::time::Duration;
    /// let mut t = tiling::FrameTally::default();
    /// let frame = tiling::FrameStats {
    ///     t_frame: Duration::from_millis(2),
    ///     related: 10,
    ///     total_drawn: 7,
    ///     culled: 1,
    ///     ..Default::default()
    /// };
    /// t.add(&frame);
    /// assert_eq!(
    ///     t.summary(),
    ///     "frame time median 2.00 ms, mean 2.00 ms, max 2.00 ms; 10 related static polygons \
    ///      a frame; 7 fragments in the last frame; faces turned away from a light left out \
    ///      in 1 of the frames"
    /// );
    /// ```
    pub fn summary(&self) -> String {
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        let (median, mean, max) = self.times();
        format!(
            "frame time median {:.2} ms, mean {:.2} ms, max {:.2} ms; {:.0} related static \
             polygons a frame; {} fragments in the last frame; faces turned away from a light \
             left out in {} of the frames",
            ms(median),
            ms(mean),
            ms(max),
            self.related_per_frame(),
            self.last.total_drawn,
            self.culled_frames
        )
    }
}

impl FrameStats {
    /// The header of [`FrameStats::csv_row`]: the paper's Table 2
    /// columns, in order, times in seconds.
    pub const CSV_HEADER: &'static str = "frame,static_polygons,dynamic_polygons,\
dynamic_after_bsp,static_after_bsp,static_after_shadow,dynamic_shadow_polygons,total_drawn,\
t_tiling_s,t_merge_s,t_dynamic_shadows_s,t_frame_s";

    /// Frame `k`'s figures as a CSV row under [`FrameStats::CSV_HEADER`].
    ///
    /// ```
    /// let row = tiling::FrameStats::default().csv_row(3);
    /// assert!(row.starts_with("3,0,0,"));
    /// assert_eq!(row.split(',').count(), tiling::FrameStats::CSV_HEADER.split(',').count());
    /// ```
    pub fn csv_row(&self, k: u32) -> String {
        let secs = |d: Duration| format!("{:.6}", d.as_secs_f64());
        format!(
            "{k},{},{},{},{},{},{},{},{},{},{},{}",
            self.static_polygons,
            self.dynamic_polygons,
            self.dynamic_after_bsp,
            self.static_after_bsp,
            self.static_after_shadow,
            self.dynamic_shadow_polygons,
            self.total_drawn,
            secs(self.t_tiling),
            secs(self.t_merge),
            secs(self.t_dynamic_shadows),
            secs(self.t_frame)
        )
    }
}

/// One frame's result.
pub struct Frame {
    /// The moved object's polygons on the grid, tagged with their face's
    /// number in the frame (static faces first, then dynamic).
    pub moved: Vec<Polygon>,
    /// The related static faces, ascending.
    pub related_faces: Vec<u32>,
    fragments: FrameFragments,
    /// The Table 2 figures.
    pub stats: FrameStats,
}

// one per frame: its size does not matter
#[allow(clippy::large_enum_variant)]
enum FrameFragments {
    /// Per related static receiver (ascending) its fragments, then the
    /// moved object's.
    Fast {
        batch: Batch,
        related: Vec<(u32, Range<usize>, Option<Vec<u32>>)>,
        moved: Range<usize>,
    },
    Paper(CfFragments),
}

/// `true` if every corner of the box `[lo, hi]` lies strictly on the other
/// side of `plane` than `light`: no segment from the light to the plane
/// reaches the box.
fn box_behind(light: &Light, plane: &bsp_core::Plane, lo: GridPoint, hi: GridPoint) -> bool {
    box_side(light, plane, lo, hi, false)
}

/// `true` if every corner of the box `[lo, hi]` lies strictly on the same
/// side of `plane` as `light` (for a sun: the side its direction points
/// to): no segment from the light to the box crosses the plane.
fn box_before(light: &Light, plane: &bsp_core::Plane, lo: GridPoint, hi: GridPoint) -> bool {
    box_side(light, plane, lo, hi, true)
}

fn box_side(
    light: &Light,
    plane: &bsp_core::Plane,
    lo: GridPoint,
    hi: GridPoint,
    same: bool,
) -> bool {
    let want = match (light.eval(plane).signum(), same) {
        (1, true) | (-1, false) => bsp_core::Side::Front,
        (-1, true) | (1, false) => bsp_core::Side::Back,
        _ => return false,
    };
    (0..8).all(|m: u32| {
        let c = [0, 1, 2].map(|k| if m >> k & 1 == 1 { hi[k] } else { lo[k] });
        plane.classify_grid(c) == want
    })
}

fn grid_points(polys: &[Polygon]) -> impl Iterator<Item = GridPoint> + '_ {
    polys
        .iter()
        .flat_map(|p| p.vertices().iter())
        .filter_map(Point::as_grid)
}

/// Per static polygon, the receiver whose polygons `ranges` it is in.
fn receiver_index(ranges: &[Range<usize>], polygons: usize) -> Vec<u32> {
    let mut receiver_of = vec![0u32; polygons];
    for (i, r) in ranges.iter().enumerate() {
        receiver_of[r.clone()]
            .iter_mut()
            .for_each(|x| *x = i as u32);
    }
    receiver_of
}

/// Per face of `faces`, the range of its polygons in `polys` (a face's
/// polygons are consecutive).
fn face_ranges(polys: &[Polygon], faces: usize) -> Vec<Range<usize>> {
    let mut face_polys = vec![0..0; faces];
    for (i, p) in polys.iter().enumerate() {
        let r = &mut face_polys[p.tag() as usize];
        if r.start == r.end {
            *r = i..i + 1;
        } else {
            r.end = i + 1;
        }
    }
    face_polys
}

impl FastStatics {
    /// The static shadows of `polys` (receivers `ranges`) for `lights`:
    /// every receiver shaded once, keeping the cells of those whose flags
    /// vary. The footprints are left empty ([`FastStatics::add_footprints`]
    /// fills them once the tilings exist).
    fn new(
        polys: &[Polygon],
        ranges: &[Range<usize>],
        lights: &[Light],
        opts: &PipelineOptions,
        prepared: &mut PrepStats,
    ) -> Result<FastStatics, PipelineError> {
        let sh = LightVolumes::new(polys, lights).map_err(PipelineError::Shadow)?;
        let sopts = opts.shading();
        let parts: Vec<(Batch, Vec<Option<Box<Cells>>>)> = ranges
            .par_chunks(CHUNK)
            .enumerate()
            .map(|(c, chunk)| {
                let (mut s, mut b) = (Scratch::default(), Batch::new());
                let cells = chunk
                    .iter()
                    .enumerate()
                    .map(|(i, r)| {
                        let rec = (c * CHUNK + i) as u32;
                        sh.set()
                            .shade_keeping(&polys[r.clone()], rec, &sopts, &mut s, &mut b)
                            .map(Box::new)
                    })
                    .collect();
                (b, cells)
            })
            .collect();
        let batch = Batch::concat(&parts.iter().map(|(b, _)| b).collect::<Vec<_>>());
        let cells: Vec<_> = parts.into_iter().flat_map(|(_, c)| c).collect();
        let mut frags = vec![0..0; ranges.len()];
        for (r, range) in batch.receiver_ranges() {
            frags[r as usize] = range;
        }
        prepared.static_after_bsp = polys.len();
        prepared.static_after_shadow = batch.len();
        Ok(FastStatics {
            shadows: sh,
            batch,
            frags,
            cells,
            footprints: FxHashMap::default(),
        })
    }

    /// Records the tiles of every kept cell's box, per light of
    /// `tilings`.
    fn add_footprints(&mut self, tilings: &[TileIndex]) {
        let kept: Vec<(u32, &Cells)> = self
            .cells
            .iter()
            .enumerate()
            .filter_map(|(r, c)| c.as_deref().map(|c| (r as u32, c)))
            .collect();
        let prints: Vec<(u32, Vec<Vec<Vec<u32>>>)> = kept
            .par_iter()
            .map(|&(r, c)| {
                let bounds = c.bounds();
                let mut q = Query::default();
                let per_light = tilings
                    .iter()
                    .map(|ix| {
                        bounds
                            .iter()
                            .map(|&(lo, hi)| {
                                let mut t = Vec::new();
                                if !ix.box_tiles(lo, hi, &mut q, &mut t) {
                                    t = vec![u32::MAX]; // every tile
                                }
                                t
                            })
                            .collect()
                    })
                    .collect();
                (r, per_light)
            })
            .collect();
        self.footprints.extend(prints);
    }
}

impl PaperStatics {
    /// `Bsp1` of `polys` and its Chin & Feiner shadows for `lights`, and
    /// `Bsp2` of `moving` (tagged after the `faces` static faces) as given.
    fn new(
        grid: &Grid,
        polys: &[Polygon],
        faces: usize,
        moving: &[Vec<DVec3>],
        lights: &[Light],
        prepared: &mut PrepStats,
    ) -> Result<PaperStatics, PipelineError> {
        let bsp1 = BspTree::build(polys.to_vec(), &BuildOptions::default());
        let cf = chin_feiner(&bsp1, lights).map_err(|e| PipelineError::Shadow(e.into()))?;
        let mut of_face = vec![Vec::new(); faces];
        for (i, f) in cf.iter().enumerate() {
            of_face[f.face() as usize].push(i as u32);
        }
        prepared.static_after_bsp = bsp1.stats().polygons;
        prepared.static_after_shadow = cf.len();
        let first = Dynamic::snap_moving(grid, moving, &DMat4::IDENTITY, faces)?;
        let bsp2 = BspTree::build(first, &BuildOptions::default());
        Ok(PaperStatics { cf, of_face, bsp2 })
    }
}

/// What a frame's tiling queries find: the moved object's box, and per
/// light the related static polygons and the tiles of the box.
struct Related {
    /// The moved object's box on the grid.
    lo: GridPoint,
    hi: GridPoint,
    /// Per light, the related static polygons.
    polygons: Vec<Vec<u32>>,
    /// Per light, the tiles of the moved object's box (`None`: every
    /// tile).
    box_tiles: Vec<Option<Vec<u32>>>,
}

/// A chunk of refined related receivers: its fragments, and per receiver
/// the range of its new fragments and the static fragments it keeps
/// (`None`: all replaced).
type RefinedChunk = (Batch, Vec<(u32, Range<usize>, Option<Vec<u32>>)>);

impl Dynamic {
    /// Prepares `statics` (face loops in input units) on `grid` for
    /// `lights`, and keeps `moving` (the object's face loops in input
    /// units, as given: frame 0). The grid must hold every position the
    /// object takes.
    pub fn new(
        statics: &[Vec<DVec3>],
        moving: &[Vec<DVec3>],
        grid: Grid,
        lights: &[Light],
        opts: PipelineOptions,
    ) -> Result<Dynamic, PipelineError> {
        let mut prepared = PrepStats {
            static_faces: statics.len(),
            ..PrepStats::default()
        };
        let t = Instant::now();
        let (polys, _) = import_faces_par(&grid, statics).map_err(PipelineError::Static)?;
        prepared.static_polygons = polys.len();
        prepared.t_import = t.elapsed();
        let ranges = receivers(&polys);
        let receiver_of = receiver_index(&ranges, polys.len());
        let face_polys = face_ranges(&polys, statics.len());
        let t = Instant::now();
        let shadows = match opts.strategy {
            Strategy::Fast => StaticShadows::Fast(FastStatics::new(
                &polys,
                &ranges,
                lights,
                &opts,
                &mut prepared,
            )?),
            Strategy::Paper => StaticShadows::Paper(PaperStatics::new(
                &grid,
                &polys,
                statics.len(),
                moving,
                lights,
                &mut prepared,
            )?),
        };
        prepared.t_shadows = t.elapsed();
        let t = Instant::now();
        let tilings = lights
            .iter()
            .map(|l| TileIndex::build(l, &polys, opts.tiles))
            .collect::<Result<Vec<_>, _>>()
            .map_err(PipelineError::Tiling)?;
        // the tiles of every kept cell's box, per light
        let mut shadows = shadows;
        if let StaticShadows::Fast(fast) = &mut shadows {
            fast.add_footprints(&tilings);
        }
        prepared.t_tiling = t.elapsed();
        Ok(Dynamic {
            grid,
            lights: lights.to_vec(),
            opts,
            statics: polys,
            static_faces: statics.len(),
            receivers: ranges,
            receiver_of,
            face_polys,
            tilings,
            moving: moving.to_vec(),
            shadows,
            prepared,
        })
    }

    /// The preprocessing figures.
    pub fn prepared(&self) -> &PrepStats {
        &self.prepared
    }

    /// The grid.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The lights.
    pub fn lights(&self) -> &[Light] {
        &self.lights
    }

    /// The static polygons, tagged with their face.
    pub fn static_polygons(&self) -> &[Polygon] {
        &self.statics
    }

    /// Number of static faces (the moved object's faces follow them).
    pub fn static_faces(&self) -> usize {
        self.static_faces
    }

    /// Number of faces of a frame: the static ones, then the object's.
    pub fn faces(&self) -> usize {
        self.static_faces + self.moving.len()
    }

    /// A frame's polygons: the static ones ([`Dynamic::static_polygons`])
    /// followed by the moved object's ([`Frame::moved`]).
    pub fn frame_polygons(&self, frame: &Frame) -> Vec<Polygon> {
        let mut polys = Vec::with_capacity(self.statics.len() + frame.moved.len());
        polys.extend_from_slice(&self.statics);
        polys.extend(frame.moved.iter().cloned());
        polys
    }

    /// The box of the static polygons' vertices in input units.
    pub fn static_bounds(&self) -> (DVec3, DVec3) {
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for p in &self.statics {
            for v in p.vertices_f64() {
                let w = self.grid.to_world(v);
                lo = lo.min(w);
                hi = hi.max(w);
            }
        }
        (lo, hi)
    }

    /// The tiling of each light.
    pub fn tilings(&self) -> &[TileIndex] {
        &self.tilings
    }

    /// The moved object's face loops in input units, as given.
    pub fn moving(&self) -> &[Vec<DVec3>] {
        &self.moving
    }

    /// The object's faces transformed by `m` and snapped to the grid,
    /// tagged `first + face`.
    fn snap_moving(
        grid: &Grid,
        moving: &[Vec<DVec3>],
        m: &DMat4,
        first: usize,
    ) -> Result<Vec<Polygon>, PipelineError> {
        let loops: Vec<Vec<DVec3>> = moving
            .iter()
            .map(|l| l.iter().map(|&p| m.transform_point3(p)).collect())
            .collect();
        let (polys, _) = import_faces_par(grid, &loops).map_err(PipelineError::Moved)?;
        Ok(polys
            .into_iter()
            .map(|p| {
                let t = p.tag() as usize + first;
                p.with_tag(t as u32)
            })
            .collect())
    }

    /// The object moved by `m` (applied to its original coordinates) and
    /// snapped: its polygons as [`Frame::moved`] has them.
    pub fn moved(&self, m: &DMat4) -> Result<Vec<Polygon>, PipelineError> {
        Self::snap_moving(&self.grid, &self.moving, m, self.static_faces)
    }

    /// The frame in which the object's original coordinates are
    /// transformed by `m`.
    pub fn frame(&self, m: &DMat4) -> Result<Frame, PipelineError> {
        let start = Instant::now();
        let moved = self.moved(m)?;
        let mut stats = FrameStats {
            static_polygons: self.static_faces,
            dynamic_polygons: self.moving.len(),
            static_after_bsp: self.prepared.static_after_bsp,
            static_after_shadow: self.prepared.static_after_shadow,
            ..FrameStats::default()
        };
        // the related static polygons, per light
        let t = Instant::now();
        let related = self.related(&moved);
        let mut all: Vec<u32> = related.polygons.iter().flatten().copied().collect();
        all.sort_unstable();
        all.dedup();
        stats.related = all.len();
        let mut related_faces: Vec<u32> = all
            .iter()
            .map(|&p| self.statics[p as usize].tag())
            .collect();
        related_faces.dedup();
        stats.t_tiling = t.elapsed();

        let fragments = match &self.shadows {
            StaticShadows::Fast(fast) => self.frame_fast(fast, &moved, &related, &mut stats)?,
            StaticShadows::Paper(paper) => {
                self.frame_paper(paper, &moved, &related_faces, &mut stats)?
            }
        };
        stats.t_frame = start.elapsed();
        Ok(Frame {
            moved,
            related_faces,
            fragments,
            stats,
        })
    }

    /// The moved object's box, and each light's tiling queried with it
    /// (see [`Related`]).
    fn related(&self, moved: &[Polygon]) -> Related {
        let mut lo = [i32::MAX; 3];
        let mut hi = [i32::MIN; 3];
        for g in grid_points(moved) {
            for k in 0..3 {
                lo[k] = lo[k].min(g[k]);
                hi[k] = hi[k].max(g[k]);
            }
        }
        // per light: the related static polygons, and the tiles of the
        // moved object's box (`None`: every tile)
        let (polygons, box_tiles): (Vec<Vec<u32>>, Vec<Option<Vec<u32>>>) = if moved.is_empty() {
            (
                vec![Vec::new(); self.lights.len()],
                vec![Some(Vec::new()); self.lights.len()],
            )
        } else {
            self.tilings
                .par_iter()
                .map(|ix| {
                    let mut q = Query::default();
                    let mut tiles = Vec::new();
                    let some = ix.box_tiles(lo, hi, &mut q, &mut tiles);
                    (ix.query_box(lo, hi, &mut q).to_vec(), some.then_some(tiles))
                })
                .unzip()
        };
        Related {
            lo,
            hi,
            polygons,
            box_tiles,
        }
    }

    /// The fast strategy's frame: the frame's shadow trees
    /// ([`Dynamic::frame_trees`]), then the related static receivers
    /// refined through them and the moved object shaded, side by side.
    fn frame_fast(
        &self,
        fast: &FastStatics,
        moved: &[Polygon],
        related: &Related,
        stats: &mut FrameStats,
    ) -> Result<FrameFragments, PipelineError> {
        let FastStatics {
            shadows: statics,
            batch,
            frags,
            cells,
            footprints,
        } = fast;
        let t = Instant::now();
        let (sh, layered) = self.frame_trees(moved, related, stats)?;
        let for_moved = if layered {
            statics.with(&sh).map_err(PipelineError::Shadow)?
        } else {
            sh.set()
        };
        stats.t_merge = t.elapsed();
        let t = Instant::now();
        let sopts = self.opts.shading();
        let (lights_of, recs) = self.changing_receivers(fast, related);
        let starts: Vec<Start<'_>> = recs
            .iter()
            .map(|&r| match &cells[r as usize] {
                Some(c) => Start::Cells(c),
                None => Start::Uniform(batch.fragment(frags[r as usize].start).lit_mask()),
            })
            .collect();
        // a cell may change only if its box's tiles meet the moved
        // object's box's tiles
        let meets = |r: u32, cell: u32, j: usize| -> bool {
            if lights_of[&r] >> j & 1 == 0 {
                return false;
            }
            let Some(bt) = &related.box_tiles[j] else {
                return true;
            };
            let Some(fp) = footprints.get(&r) else {
                return true;
            };
            let ct = &fp[j][cell as usize];
            ct.first() == Some(&u32::MAX) || ct.iter().any(|t| bt.binary_search(t).is_ok())
        };
        // the related static faces and the moved object side by side
        let (parts, dynamic) = rayon::join(
            || self.refine_receivers(&sh, &recs, &starts, &sopts, &meets),
            || for_moved.shade_all(moved, &sopts),
        );
        let mut all: Vec<&Batch> = parts.iter().map(|(b, _)| b).collect();
        all.push(&dynamic);
        let out = Batch::concat(&all);
        let mut related_ranges = Vec::new();
        let mut off = 0;
        for (b, done) in parts {
            related_ranges.extend(
                done.into_iter()
                    .map(|(r, range, kept)| (r, range.start + off..range.end + off, kept)),
            );
            off += b.len();
        }
        let m0 = off;
        stats.t_dynamic_shadows = t.elapsed();
        stats.dynamic_after_bsp = moved.len();
        stats.dynamic_shadow_polygons = out.len();
        let replaced: usize = related_ranges
            .iter()
            .map(|(r, _, kept)| frags[*r as usize].len() - kept.as_ref().map_or(0, Vec::len))
            .sum();
        stats.total_drawn = batch.len() - replaced + out.len();
        let len = out.len();
        Ok(FrameFragments::Fast {
            batch: out,
            related: related_ranges,
            moved: m0..len,
        })
    }

    /// The fast strategy's shadow trees of a frame, one per light: the
    /// moved object's faces (less, for a light outside its certified
    /// solids, those turned away from it) and the related polygons that
    /// may block light on its way to the object. When those are many, the
    /// trees hold the object alone and its faces are shaded through the
    /// static trees too (*layered*). Returns the trees and whether they
    /// are layered; records `culled` and `layered` in `stats`.
    fn frame_trees(
        &self,
        moved: &[Polygon],
        related: &Related,
        stats: &mut FrameStats,
    ) -> Result<(LightVolumes, bool), PipelineError> {
        let (lo, hi) = (related.lo, related.hi);
        // per light, the related static polygons that may block
        // light on its way to the object: a polygon whose plane has
        // the object's whole box on the light's side only receives
        // its shadow
        let blockers: Vec<Vec<&Polygon>> = self
            .lights
            .iter()
            .zip(&related.polygons)
            .map(|(l, rel)| {
                rel.iter()
                    .map(|&p| &self.statics[p as usize])
                    .filter(|p| !box_before(l, p.support(), lo, hi))
                    .collect()
            })
            .collect();
        // the object's faces turned away from a light hide nothing
        // more when its snapped surface is certified to bound
        // solids and the light is outside them (not certified
        // when no light could use it)
        let solid = self
            .lights
            .iter()
            .any(|l| l.outside_box(lo, hi))
            .then(|| bsp_core::certify_solid_boundary(moved).ok())
            .flatten();
        let culls: Vec<bool> = self
            .lights
            .iter()
            .map(|l| solid.as_ref().is_some_and(|s| l.culls_back_faces(s)))
            .collect();
        stats.culled = culls.iter().filter(|&&c| c).count();
        // few of them: one tree of the object and those; many: a
        // tree of the object alone, and for the object's own faces
        // the static trees too (a point is lit where neither blocks)
        let layered =
            blockers.iter().map(Vec::len).sum::<usize>() * 4 > moved.len() * self.lights.len();
        stats.layered = layered;
        let volumes = self
            .lights
            .iter()
            .zip(&blockers)
            .zip(&culls)
            .map(|((l, b), &cull)| {
                let own = moved.iter().filter(|p| !cull || l.faces(p.support()));
                let occ: Vec<&Polygon> = if layered {
                    own.collect()
                } else {
                    own.chain(b.iter().copied()).collect()
                };
                ShadowVolumes::build(*l, &occ)
            })
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| PipelineError::Shadow(e.into()))?;
        let sh =
            LightVolumes::from_volumes(&self.lights, volumes).map_err(PipelineError::Shadow)?;
        Ok((sh, layered))
    }

    /// The related static receivers (ascending) a frame may change, with
    /// the lights for which they may (a bit per light): related for that
    /// light, still lit somewhere, and not with the whole box of the
    /// moved object behind their plane (a segment from the light to them
    /// then stays on the light's side).
    fn changing_receivers(
        &self,
        fast: &FastStatics,
        related: &Related,
    ) -> (FxHashMap<u32, u64>, Vec<u32>) {
        let (lo, hi) = (related.lo, related.hi);
        let mut lights_of: FxHashMap<u32, u64> = FxHashMap::default();
        for (j, rel) in related.polygons.iter().enumerate() {
            for &p in rel {
                let poly = &self.statics[p as usize];
                if !box_behind(&self.lights[j], poly.support(), lo, hi) {
                    *lights_of.entry(self.receiver_of[p as usize]).or_default() |= 1 << j;
                }
            }
        }
        let mut recs: Vec<u32> = lights_of.keys().copied().collect();
        recs.sort_unstable();
        recs.retain(|&r| {
            let range = &fast.frags[r as usize];
            fast.cells[r as usize].is_some()
                || (range.start..range.end).any(|i| fast.batch.fragment(i).lit_mask() != 0)
        });
        (lights_of, recs)
    }

    /// The related static receivers `recs` (from `starts`) refined
    /// through the frame's trees `sh`, in parallel chunks. What the moved
    /// object leaves alone (`meets(receiver, cell, light)` is `false`)
    /// keeps its static fragments.
    fn refine_receivers(
        &self,
        sh: &LightVolumes,
        recs: &[u32],
        starts: &[Start<'_>],
        sopts: &ShadeOptions,
        meets: &(impl Fn(u32, u32, usize) -> bool + Sync),
    ) -> Vec<RefinedChunk> {
        recs.par_chunks(16)
            .zip(starts.par_chunks(16))
            .map(|(rs, ss)| {
                let (mut s, mut b) = (Scratch::default(), Batch::new());
                let mut done = Vec::new();
                for (&r, st) in rs.iter().zip(ss) {
                    let polys = &self.statics[self.receivers[r as usize].clone()];
                    let first = b.len();
                    // what the moved object leaves alone keeps
                    // its static fragments
                    let may = |c: u32, j: usize| meets(r, c, j);
                    match sh
                        .set()
                        .refine_cells(polys, st, r, sopts, &mut s, &mut b, may)
                    {
                        Refined::Unchanged => {}
                        Refined::All => done.push((r, first..b.len(), None)),
                        Refined::Some(kept) => done.push((r, first..b.len(), Some(kept))),
                    }
                }
                (b, done)
            })
            .collect()
    }

    /// The paper's strategy's frame: `Bsp2` replayed on the moved faces,
    /// `Bsp3` built from the related static faces, `Bsp4 = Bsp2 + Bsp3`
    /// and its Chin & Feiner shadows, overlaid with the static fragments.
    fn frame_paper(
        &self,
        paper: &PaperStatics,
        moved: &[Polygon],
        related_faces: &[u32],
        stats: &mut FrameStats,
    ) -> Result<FrameFragments, PipelineError> {
        let PaperStatics { cf, of_face, bsp2 } = paper;
        let t = Instant::now();
        let b2 = bsp2.replay(moved.to_vec(), &BuildOptions::default());
        stats.dynamic_after_bsp = b2.stats().polygons;
        // whole faces: a related face's fragments all come from Bsp4
        let near: Vec<Polygon> = related_faces
            .iter()
            .flat_map(|&f| self.statics[self.face_polys[f as usize].clone()].iter())
            .cloned()
            .collect();
        let b3 = BspTree::build(near, &BuildOptions::default());
        let b4 = merge_smaller_into_larger(
            &Partition::from_tree(&b2),
            &Partition::from_tree(&b3),
            &Overlay,
        )
        .polygon_tree(|(a, _)| a);
        stats.t_merge = t.elapsed();
        let t = Instant::now();
        let shaded = chin_feiner(&b4, &self.lights).map_err(|e| PipelineError::Shadow(e.into()))?;
        let statics = self.static_faces as u32;
        let out = shaded.overlay(cf, |face| {
            (face < statics).then(|| &of_face[face as usize][..])
        });
        stats.t_dynamic_shadows = t.elapsed();
        stats.dynamic_shadow_polygons = out.len();
        let replaced: usize = related_faces
            .iter()
            .map(|&f| of_face[f as usize].len())
            .sum();
        stats.total_drawn = cf.len() - replaced + out.len();
        Ok(FrameFragments::Paper(out))
    }

    /// The whole frame's fragments in face order (static faces, then the
    /// moved object's): the static fragments of the faces the frame left
    /// alone and the frame's own.
    pub fn fragments(&self, frame: &Frame) -> Batch {
        let mut out = Batch::new();
        self.walk(frame, |part| match part {
            Part::Batch(b, range) => out.append_range(b, range),
            Part::Cf(cf, list) => {
                for &i in list {
                    out.push_chin_feiner(&cf.get(i as usize), &self.lights);
                }
            }
        });
        out
    }

    /// Visits every fragment of the frame with its exact vertices, in the
    /// order of [`Dynamic::fragments`].
    pub fn each_fragment(&self, frame: &Frame, mut visit: impl FnMut(FragmentView<'_>)) {
        self.walk(frame, |part| match part {
            Part::Batch(b, range) => range.for_each(|i| visit(FragmentView::Region(b.fragment(i)))),
            Part::Cf(cf, list) => list
                .iter()
                .for_each(|&i| visit(FragmentView::Convex(cf.get(i as usize)))),
        });
    }

    /// The frame's fragments part by part, in face order.
    fn walk(&self, frame: &Frame, mut emit: impl FnMut(Part<'_>)) {
        match (&self.shadows, &frame.fragments) {
            (
                StaticShadows::Fast(FastStatics { batch, frags, .. }),
                FrameFragments::Fast {
                    batch: fb,
                    related,
                    moved,
                },
            ) => {
                let mut next = related.iter().peekable();
                let mut r = 0;
                while r < frags.len() {
                    if let Some((rr, range, kept)) = next.peek()
                        && *rr as usize == r
                    {
                        for &k in kept.iter().flatten() {
                            let f = frags[r].start + k as usize;
                            emit(Part::Batch(batch, f..f + 1));
                        }
                        emit(Part::Batch(fb, range.clone()));
                        next.next();
                        r += 1;
                        continue;
                    }
                    // a run of untouched receivers in one piece
                    let stop = next.peek().map_or(frags.len(), |(rr, _, _)| *rr as usize);
                    emit(Part::Batch(batch, frags[r].start..frags[stop - 1].end));
                    r = stop;
                }
                emit(Part::Batch(fb, moved.clone()));
            }
            (StaticShadows::Paper(PaperStatics { cf, of_face, .. }), FrameFragments::Paper(fc)) => {
                let mut mine: Vec<Vec<u32>> =
                    vec![Vec::new(); self.static_faces + self.moving.len()];
                for (i, f) in fc.iter().enumerate() {
                    mine[f.face() as usize].push(i as u32);
                }
                for (face, list) in mine.iter().enumerate() {
                    let untouched = face < self.static_faces
                        && frame.related_faces.binary_search(&(face as u32)).is_err();
                    if untouched {
                        emit(Part::Cf(cf, &of_face[face]));
                    } else {
                        emit(Part::Cf(fc, list));
                    }
                }
            }
            _ => unreachable!("a frame comes from its scene's strategy"),
        }
    }
}

/// A run of fragments of one source.
enum Part<'a> {
    Batch(&'a Batch, Range<usize>),
    Cf(&'a CfFragments, &'a [u32]),
}

/// One fragment of a frame, with its exact vertices.
#[derive(Clone, Copy)]
pub enum FragmentView<'a> {
    /// A region of the fast strategy (rings of exact [`svbsp::Vertex`]
    /// values, through [`Batch::vertex`]).
    Region(svbsp::FragmentRef<'a>),
    /// A convex fragment of the paper's strategy.
    Convex(svbsp::CfFragment<'a>),
}
