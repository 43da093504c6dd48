//! The tile index: per tile, the polygons whose projection meets it, in
//! compressed sparse rows; and the query by a moving object's box.

use bsp_core::{GridPoint, Point, Polygon};
use rayon::prelude::*;
use svbsp::Light;

use crate::cube::{self, Span};
use crate::ortho;

/// Most tiles per cube edge for a point light: six faces of `1024²`
/// tiles, 25 MB of row offsets. (Every exact quantity of the projection
/// stays within `i128` up to `2^12` per edge; see the `cube` module.)
pub const MAX_CUBE_TILES: u32 = 1024;

/// Most tiles per side of a sun's plane: `4096²` tiles, 64 MB of offsets.
pub const MAX_PLANE_TILES: u32 = 4096;

/// Why an index cannot be built.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum TilingError {
    /// Polygon `index` has a vertex that is not a grid point (it was cut
    /// from a larger polygon): index the input polygons instead.
    NotGrid {
        /// The polygon's index in the list.
        index: usize,
    },
    /// The number of tiles per side is 0 or above [`MAX_CUBE_TILES`] (a
    /// point light) or [`MAX_PLANE_TILES`] (a sun).
    Tiles(u32),
    /// The light is unusable (a zero sun direction, a point light off the
    /// grid).
    Light,
}

impl std::fmt::Display for TilingError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TilingError::NotGrid { index } => write!(
                f,
                "polygon {index} has a vertex that is not a grid point; index input polygons"
            ),
            TilingError::Tiles(n) => write!(
                f,
                "{n} tiles per side: give 1 to {MAX_CUBE_TILES} for a point light, 1 to \
                 {MAX_PLANE_TILES} for a sun"
            ),
            TilingError::Light => f.write_str("the light is unusable"),
        }
    }
}

impl std::error::Error for TilingError {}

/// The documented rule for the number of tiles per side when none is
/// given: about four tiles per polygon's share of a face, so that a
/// polygon of typical size meets a few tiles, and a query box's tiles
/// list few polygons that do not meet it.
///
/// - point light: `clamp(ceil(2 sqrt(P / 6)), 4, 1024)` per cube edge
///   (six faces);
/// - sun: `clamp(ceil(2 sqrt(P)), 4, 4096)` per side of its plane.
///
/// ```
/// use tiling::tiles_for;
/// use svbsp::Light;
/// assert_eq!(tiles_for(&Light::Point([0, 0, 0]), 255), 14);
/// assert_eq!(tiles_for(&Light::Point([0, 0, 0]), 100_000), 259);
/// assert_eq!(tiles_for(&Light::Directional([0, 0, 1]), 100_000), 633);
/// ```
pub fn tiles_for(light: &Light, polygons: usize) -> u32 {
    let p = polygons as f64;
    match light {
        Light::Point(_) => ((2.0 * (p / 6.0).sqrt()).ceil() as u32).clamp(4, MAX_CUBE_TILES),
        Light::Directional(_) => ((2.0 * p.sqrt()).ceil() as u32).clamp(4, MAX_PLANE_TILES),
    }
}

#[derive(Clone, Debug, PartialEq, Eq)]
enum Projection {
    Cube([i64; 3]),
    Plane(ortho::Frame),
}

/// The light-cube tiling of a static scene for one light (Liu & Wu's
/// "tiling"): the polygons met by each tile of the projection from the
/// light, for finding the static polygons a moving object may shadow or
/// be shadowed by.
///
/// For a point light the projection is onto a cube around the light (six
/// faces of `n × n` tiles); for a sun it is along the sun's direction onto
/// a plane across it (`n × n` tiles over the scene's extent). Every
/// decision is exact integer arithmetic, and a projection touching a
/// tile's edge counts for both tiles, so a query never misses a polygon
/// whose projection meets the queried one's (see [`TileIndex::query_box`]).
#[derive(Clone, Debug)]
pub struct TileIndex {
    projection: Projection,
    n: u32,
    /// Per tile, the start of its list in `items`, plus the end.
    offsets: Vec<u32>,
    items: Vec<u32>,
    polygons: usize,
}

/// Figures of an index.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TilingStats {
    /// Tiles per side.
    pub n: u32,
    /// Tiles in all.
    pub tiles: usize,
    /// Polygons indexed.
    pub polygons: usize,
    /// Entries (a polygon listed in a tile).
    pub entries: usize,
    /// Tiles listing at least one polygon.
    pub used_tiles: usize,
    /// Bytes of the two arrays.
    pub bytes: usize,
}

/// Work space of queries, reused from query to query.
#[derive(Clone, Debug, Default)]
pub struct Query {
    stamp: Vec<u32>,
    epoch: u32,
    spans: Vec<Span>,
    work: cube::Work,
    /// The polygons found by the last query, ascending.
    pub found: Vec<u32>,
}

fn grid_verts(p: &Polygon) -> Option<Vec<[i64; 3]>> {
    p.vertices()
        .iter()
        .map(|v| match v {
            Point::Grid(g) => Some(g.map(i64::from)),
            Point::Implicit(_) => None,
        })
        .collect()
}

impl TileIndex {
    /// Indexes `polygons` (with grid vertices, as imported) for `light`,
    /// with `tiles` per side or the [`tiles_for`] rule. Polygons are
    /// projected in parallel; the index does not depend on the thread
    /// count.
    pub fn build(
        light: &Light,
        polygons: &[Polygon],
        tiles: Option<u32>,
    ) -> Result<TileIndex, TilingError> {
        light.validate().map_err(|_| TilingError::Light)?;
        let n = tiles.unwrap_or_else(|| tiles_for(light, polygons.len()));
        let max = match light {
            Light::Point(_) => MAX_CUBE_TILES,
            Light::Directional(_) => MAX_PLANE_TILES,
        };
        if n == 0 || n > max {
            return Err(TilingError::Tiles(n));
        }
        let verts: Vec<Vec<[i64; 3]>> = polygons
            .par_iter()
            .enumerate()
            .map(|(index, p)| grid_verts(p).ok_or(TilingError::NotGrid { index }))
            .collect::<Result<_, _>>()?;
        let projection = match light {
            Light::Point(l) => Projection::Cube(l.map(i64::from)),
            Light::Directional(d) => {
                Projection::Plane(ortho::Frame::new(*d, verts.iter().flatten().copied(), n))
            }
        };
        let mut index = TileIndex {
            projection,
            n,
            offsets: Vec::new(),
            items: Vec::new(),
            polygons: polygons.len(),
        };
        // each polygon's tiles, chunk by chunk in parallel, in order
        let parts: Vec<(Vec<u32>, Vec<u32>)> = verts
            .par_chunks(1024)
            .enumerate()
            .map(|(c, chunk)| {
                let mut w = cube::Work::default();
                let mut spans = Vec::new();
                let (mut tiles, mut owner) = (Vec::new(), Vec::new());
                for (i, v) in chunk.iter().enumerate() {
                    spans.clear();
                    index.spans_into(v, &mut w, &mut spans);
                    let id = (c * 1024 + i) as u32;
                    for s in &spans {
                        for col in s.lo..=s.hi {
                            tiles.push(index.tile(s, col));
                            owner.push(id);
                        }
                    }
                }
                (tiles, owner)
            })
            .collect();
        // counting sort by tile: lists in polygon order
        let count = index.tile_count();
        let mut offsets = vec![0u32; count + 1];
        for (tiles, _) in &parts {
            for &t in tiles {
                offsets[t as usize + 1] += 1;
            }
        }
        for i in 0..count {
            offsets[i + 1] += offsets[i];
        }
        let mut fill = offsets.clone();
        let mut items = vec![0u32; offsets[count] as usize];
        for (tiles, owner) in &parts {
            for (&t, &o) in tiles.iter().zip(owner) {
                let slot = &mut fill[t as usize];
                items[*slot as usize] = o;
                *slot += 1;
            }
        }
        index.offsets = offsets;
        index.items = items;
        Ok(index)
    }

    fn spans_into(&self, verts: &[[i64; 3]], w: &mut cube::Work, out: &mut Vec<Span>) {
        match &self.projection {
            Projection::Cube(l) => cube::spans(*l, verts, self.n, w, out),
            Projection::Plane(f) => f.spans(verts, out),
        }
    }

    fn tile(&self, s: &Span, col: u32) -> u32 {
        (s.face as u32 * self.n + s.row) * self.n + col
    }

    /// Tiles per side.
    pub fn n(&self) -> u32 {
        self.n
    }

    /// Tiles in all: `6 n²` for a point light, `n²` for a sun.
    pub fn tile_count(&self) -> usize {
        let faces = match self.projection {
            Projection::Cube(_) => 6,
            Projection::Plane(_) => 1,
        };
        faces * self.n as usize * self.n as usize
    }

    /// The polygons listed in tile `t`, ascending.
    pub fn tile_polygons(&self, t: usize) -> &[u32] {
        &self.items[self.offsets[t] as usize..self.offsets[t + 1] as usize]
    }

    /// The tiles a polygon (grid points in order, convex) meets: tile
    /// numbers `(face n + row) n + column`, ascending.
    pub fn tiles_of(&self, verts: &[GridPoint]) -> Vec<u32> {
        let v: Vec<[i64; 3]> = verts.iter().map(|g| g.map(i64::from)).collect();
        let mut spans = Vec::new();
        self.spans_into(&v, &mut cube::Work::default(), &mut spans);
        let mut t: Vec<u32> = spans
            .iter()
            .flat_map(|s| (s.lo..=s.hi).map(|c| self.tile(s, c)))
            .collect();
        t.sort_unstable();
        t.dedup();
        t
    }

    /// Figures of the index.
    pub fn stats(&self) -> TilingStats {
        TilingStats {
            n: self.n,
            tiles: self.tile_count(),
            polygons: self.polygons,
            entries: self.items.len(),
            used_tiles: self.offsets.windows(2).filter(|w| w[1] > w[0]).count(),
            bytes: 4 * (self.offsets.len() + self.items.len()),
        }
    }

    /// The tiles the closed box `[lo, hi]` (grid points) meets, ascending
    /// and without repeats, into `out`; `false` (and `out` empty) when it
    /// meets every tile: a point light inside the box, or a box flat along
    /// two axes.
    pub fn box_tiles(
        &self,
        lo: GridPoint,
        hi: GridPoint,
        q: &mut Query,
        out: &mut Vec<u32>,
    ) -> bool {
        out.clear();
        if !self.box_spans(lo, hi, q) {
            return false;
        }
        for s in &q.spans {
            out.extend((s.lo..=s.hi).map(|c| self.tile(s, c)));
        }
        out.sort_unstable();
        out.dedup();
        true
    }

    /// The spans of the box's faces into `q.spans`; `false` when the box
    /// meets every tile.
    fn box_spans(&self, lo: GridPoint, hi: GridPoint, q: &mut Query) -> bool {
        let (lo, hi) = (lo.map(i64::from), hi.map(i64::from));
        q.spans.clear();
        let inside = match self.projection {
            Projection::Cube(l) => (0..3).all(|k| lo[k] <= l[k] && l[k] <= hi[k]),
            Projection::Plane(_) => false,
        };
        // a box flat along two axes (a segment or a point) has no face
        // with area: take every tile rather than risk a miss
        let flat = (0..3).filter(|&k| lo[k] >= hi[k]).count();
        if inside || flat >= 2 {
            return false;
        }
        let c = |x: bool, y: bool, z: bool| {
            [
                if x { hi[0] } else { lo[0] },
                if y { hi[1] } else { lo[1] },
                if z { hi[2] } else { lo[2] },
            ]
        };
        let (f, t) = (false, true);
        let faces = [
            [c(f, f, f), c(f, t, f), c(f, t, t), c(f, f, t)],
            [c(t, f, f), c(t, f, t), c(t, t, t), c(t, t, f)],
            [c(f, f, f), c(f, f, t), c(t, f, t), c(t, f, f)],
            [c(f, t, f), c(t, t, f), c(t, t, t), c(f, t, t)],
            [c(f, f, f), c(t, f, f), c(t, t, f), c(f, t, f)],
            [c(f, f, t), c(f, t, t), c(t, t, t), c(t, f, t)],
        ];
        for face in &faces {
            // a box flat along one axis: its four side faces are segments,
            // and its two big faces (the same quad) carry its projection
            let mut v: Vec<[i64; 3]> = Vec::with_capacity(4);
            for p in face {
                if !v.contains(p) {
                    v.push(*p);
                }
            }
            if v.len() >= 3 {
                self.spans_into(&v, &mut q.work, &mut q.spans);
            }
        }
        true
    }

    /// The polygons whose projection may meet the projection of the
    /// closed box `[lo, hi]` (grid points): every polygon whose projection
    /// meets the box's, and some more (those sharing a tile with it). The
    /// box is projected by its six faces, as the core paper does; a point
    /// light inside the box sees it all around, and every polygon is
    /// returned. The result, ascending, is in `q.found`.
    pub fn query_box<'q>(&self, lo: GridPoint, hi: GridPoint, q: &'q mut Query) -> &'q [u32] {
        q.found.clear();
        if !self.box_spans(lo, hi, q) {
            q.found.extend(0..self.polygons as u32);
            return &q.found;
        }
        self.collect(q);
        &q.found
    }

    /// The polygons listed in the tiles of `q.spans`, ascending, into
    /// `q.found`.
    fn collect(&self, q: &mut Query) {
        if q.stamp.len() != self.polygons {
            q.stamp = vec![0; self.polygons];
            q.epoch = 0;
        }
        q.epoch = q.epoch.wrapping_add(1);
        if q.epoch == 0 {
            q.stamp.iter_mut().for_each(|s| *s = 0);
            q.epoch = 1;
        }
        let Query {
            stamp,
            epoch,
            spans,
            found,
            ..
        } = q;
        for s in spans.iter() {
            let first = self.tile(s, s.lo) as usize;
            let last = self.tile(s, s.hi) as usize;
            let items = &self.items[self.offsets[first] as usize..self.offsets[last + 1] as usize];
            for &p in items {
                let st = &mut stamp[p as usize];
                if *st != *epoch {
                    *st = *epoch;
                    found.push(p);
                }
            }
        }
        found.sort_unstable();
    }
}
