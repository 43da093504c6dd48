//! Convex cells over shared arrays: the compact form in which polygons are
//! cut again and again (shadow fragments, overlays).
//!
//! A [`PieceArena`] holds the vertices and planes of the cells that live on
//! one support plane. A [`Piece`] is two short index lists: its vertices and
//! the edge planes between them ([`EdgeRef`]: an index into the arena's
//! planes and an orientation bit). A split makes each new vertex once, in
//! the arena, and both pieces refer to it; nothing is deep-copied and no
//! vertex is boxed. The vertices are stored inline ([`Vertex`]), so an
//! arena that is cleared and refilled allocates nothing after warming up.
//!
//! The arena is a stack: [`PieceArena::mark`] and [`PieceArena::rollback`]
//! drop every vertex and plane made since a mark, which the shadow
//! filter uses to discard the pieces of a cut it undoes.

use std::cmp::Ordering;

use smallvec::SmallVec;

use bsp_core::internals::{filter_side_err, split_loop};
use bsp_core::{GridPoint, I256, Implicit, Plane, Point, Polygon, Side};
#[cfg(test)]
use {
    bsp_core::SanityError,
    bsp_core::internals::{ConvexParts, check_convex},
};

/// A vertex of a piece, stored inline in the arena of pieces.
#[derive(Clone, Debug)]
pub enum Vertex {
    /// An input grid point.
    Grid(GridPoint),
    /// The intersection of three input-tier planes.
    Implicit(Implicit),
}

impl Vertex {
    /// Exact side of `plane`: `i128` for grid points, the filter and then
    /// 256-bit arithmetic for implicit points.
    #[inline]
    pub fn classify(&self, plane: &Plane) -> Side {
        match self {
            Vertex::Grid(g) => plane.classify_grid(*g),
            Vertex::Implicit(i) => i.classify(plane),
        }
    }

    /// The correctly rounded grid coordinates (equal points give equal
    /// results however they were made).
    pub fn to_f64(&self) -> [f64; 3] {
        match self {
            Vertex::Grid(g) => g.map(f64::from),
            Vertex::Implicit(i) => i.to_f64(),
        }
    }

    /// Grid coordinates within a few ulps (fast, not canonical).
    #[inline]
    pub fn approx_f64(&self) -> [f64; 3] {
        match self {
            Vertex::Grid(g) => g.map(f64::from),
            Vertex::Implicit(i) => i.approx_f64(),
        }
    }

    /// Exact comparison of coordinate `k` (0, 1 or 2).
    pub fn cmp_axis(&self, o: &Vertex, k: usize) -> Ordering {
        match (self, o) {
            (Vertex::Grid(a), Vertex::Grid(b)) => a[k].cmp(&b[k]),
            (Vertex::Implicit(a), Vertex::Implicit(b)) => a.cmp_axis(b, k),
            (Vertex::Grid(g), Vertex::Implicit(i)) => cmp_grid_implicit(g[k], i, k),
            (Vertex::Implicit(i), Vertex::Grid(g)) => cmp_grid_implicit(g[k], i, k).reverse(),
        }
    }

    /// Exact equality of the represented points.
    pub fn same_point(&self, o: &Vertex) -> bool {
        (0..3).all(|k| self.cmp_axis(o, k) == Ordering::Equal)
    }

    /// The same point as a [`Point`].
    pub fn to_point(&self) -> Point {
        match self {
            Vertex::Grid(g) => Point::Grid(*g),
            Vertex::Implicit(i) => Point::Implicit(std::sync::Arc::new(i.clone())),
        }
    }

    /// The same point from a [`Point`].
    pub fn from_point(p: &Point) -> Vertex {
        match p {
            Point::Grid(g) => Vertex::Grid(*g),
            Point::Implicit(i) => Vertex::Implicit((**i).clone()),
        }
    }
}

/// `g` against coordinate `k` of `i`: `g w` against `x_k`.
fn cmp_grid_implicit(g: i32, i: &Implicit, k: usize) -> Ordering {
    let h = i.coords();
    (I256::from(g) * h[3]).cmp(&h[k])
}

/// An edge plane of a cell: an index into [`PieceArena::planes`] and an
/// orientation bit (the plane as stored, or flipped).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct EdgeRef(u32);

impl EdgeRef {
    /// Plane `index` of the arena, flipped if `flipped`.
    #[inline]
    pub(crate) fn new(index: u32, flipped: bool) -> EdgeRef {
        EdgeRef(index << 1 | flipped as u32)
    }

    /// The index of the plane in the arena.
    #[inline]
    pub(crate) fn index(self) -> u32 {
        self.0 >> 1
    }

    /// `true` if the edge is the stored plane flipped.
    #[inline]
    pub(crate) fn flipped(self) -> bool {
        self.0 & 1 == 1
    }
}

/// A convex cell: vertex `i` lies between edge planes `i - 1` and `i`; the
/// interior is behind every edge plane; vertices run counter-clockwise
/// seen from the front of the support plane, which the cells of one arena
/// share.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub(crate) struct Piece {
    /// Vertex indices into [`PieceArena::vertex`].
    pub verts: SmallVec<[u32; 6]>,
    /// Edge planes (edge `i` runs from vertex `i` to vertex `i + 1`).
    pub edges: SmallVec<[EdgeRef; 6]>,
}

/// Vertices and planes of pieces.
///
/// Vertices come in three kinds, stored apart: grid points (12 bytes),
/// exact implicit points copied in from elsewhere ([`Implicit`], 160
/// bytes), and *lazy* points made here by splits ([`Lazy`], 80 bytes): the
/// indices of their three planes in the arena and `f64` approximations of
/// their homogeneous coordinates with certified error bounds. A lazy point
/// is classified by the filter ([`bsp_core::internals::filter_side_err`]) and computes
/// its exact coordinates only when the filter cannot decide, or for
/// output. A vertex id is an index into one of the three lists, tagged in
/// its top two bits; [`PieceArena::dense`] maps ids to `0..len()` for
/// per-vertex tables.
#[derive(Clone, Debug, Default)]
pub(crate) struct PieceArena {
    grid: Vec<GridPoint>,
    exact: Vec<Implicit>,
    lazy: Vec<Lazy>,
    /// The planes: supports, edges and cuts.
    pub planes: Vec<Plane>,
    /// Per plane: two grid points on its line of intersection with the
    /// support plane it was added for (a polygon's edge), if known.
    anchors: Vec<Option<[GridPoint; 2]>>,
}

const TAG: u32 = 3 << 30;
const EXACT: u32 = 1 << 30;
const LAZY: u32 = 2 << 30;

/// [`PieceArena::dense`] in an arena of `grids` grid and `exacts` exact
/// vertices.
#[inline]
fn dense_of(id: u32, grids: usize, exacts: usize) -> usize {
    let i = (id & !TAG) as usize;
    match id & TAG {
        0 => i,
        EXACT => grids + i,
        _ => grids + exacts + i,
    }
}

/// An implicit vertex made by a split: the intersection of planes
/// `planes` of its arena, with `f64` approximations `approx` of its
/// homogeneous coordinates `(x, y, z, w)` (`w > 0`) and bounds `err` on
/// their absolute errors.
#[derive(Clone, Debug)]
pub(crate) struct Lazy {
    approx: [f64; 4],
    err: [f64; 4],
    planes: [u32; 3],
    /// The exact point, once computed.
    exact: Option<Box<Implicit>>,
}

/// `2^-49`: the bound, relative to the sum of the absolute values of its
/// terms, on the error of a coordinate computed in `f64` by
/// [`Lazy::new`] (at most `8.4 · 2^-53`; see `docs/architecture.md`).
const LAZY_REL: f64 = 1.0 / (1u64 << 49) as f64;

/// `2^-20`: how far from the exact coordinates [`VertexRef::approx`] may
/// measure a lazy point (a bound on a measurement's input, not a
/// tolerance any decision reads).
pub(crate) const MEASURE_UNITS: f64 = 1.0 / (1u64 << 20) as f64;

impl Lazy {
    /// The intersection of `planes[i]` for the three indices, or `None` if
    /// they do not meet in one point.
    fn new(planes: &[Plane], idx: [u32; 3]) -> Option<Lazy> {
        let [a, b, c] = idx.map(|i| planes[i as usize].approx());
        let n = |p: &[f64; 4]| [p[0], p[1], p[2]];
        let (n1, n2, n3) = (n(&a), n(&b), n(&c));
        let cross = |u: [f64; 3], v: [f64; 3]| {
            [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ]
        };
        // the absolute value of every expanded term, summed the same way
        let cross_abs = |u: [f64; 3], v: [f64; 3]| {
            [
                (u[1] * v[2]).abs() + (u[2] * v[1]).abs(),
                (u[2] * v[0]).abs() + (u[0] * v[2]).abs(),
                (u[0] * v[1]).abs() + (u[1] * v[0]).abs(),
            ]
        };
        let (c23, c31, c12) = (cross(n2, n3), cross(n3, n1), cross(n1, n2));
        let (t23, t31, t12) = (cross_abs(n2, n3), cross_abs(n3, n1), cross_abs(n1, n2));
        let mut w = n1[0] * c23[0] + n1[1] * c23[1] + n1[2] * c23[2];
        let tw = n1[0].abs() * t23[0] + n1[1].abs() * t23[1] + n1[2].abs() * t23[2];
        let ew = tw * LAZY_REL;
        let mut x = [0.0; 3];
        let mut err = [0.0; 4];
        for k in 0..3 {
            x[k] = -(c23[k] * a[3] + c31[k] * b[3] + c12[k] * c[3]);
            err[k] = (t23[k] * a[3].abs() + t31[k] * b[3].abs() + t12[k] * c[3].abs()) * LAZY_REL;
        }
        err[3] = ew;
        // the sign of w, exactly when the approximation cannot tell
        let negative = if w.abs() > ew {
            w < 0.0
        } else {
            let [p1, p2, p3] = idx.map(|i| &planes[i as usize]);
            let det = Plane::normals_det(p1, p2, p3);
            if det.is_zero() {
                return None;
            }
            det.is_negative()
        };
        if negative {
            x = x.map(|v| -v);
            w = -w;
        }
        Some(Lazy {
            approx: [x[0], x[1], x[2], w],
            err,
            planes: idx,
            exact: None,
        })
    }

    /// The exact point.
    pub(crate) fn exact(&self, planes: &[Plane]) -> Implicit {
        if let Some(e) = &self.exact {
            return (**e).clone();
        }
        let [a, b, c] = self.planes.map(|i| &planes[i as usize]);
        Implicit::from_planes(a, b, c).expect("a lazy point's planes meet in one point")
    }

    /// Exact side of `plane` where the filter on the approximations
    /// (`filter_side_err`, which the caller ran) could not tell: `On` if
    /// `plane` is one of the three planes the point was made from; then
    /// the exact coordinates, computed once and kept.
    fn classify_unfiltered(
        &mut self,
        planes: &[Plane],
        anchors: &[Option<[GridPoint; 2]>],
        plane: &Plane,
    ) -> Side {
        if self.on_by_construction(planes, anchors, plane) {
            return Side::On;
        }
        let [a, b, c] = self.planes.map(|i| &planes[i as usize]);
        let e = self.exact.get_or_insert_with(|| {
            Box::new(
                Implicit::from_planes(a, b, c).expect("a lazy point's planes meet in one point"),
            )
        });
        e.classify_exact(plane)
    }

    /// `true` if the point lies on `plane` because of how it was made:
    /// `plane` is one of its three planes, or contains the line where its
    /// support (the first plane) meets one of the other two, known by two
    /// grid points.
    #[inline]
    fn on_by_construction(
        &self,
        planes: &[Plane],
        anchors: &[Option<[GridPoint; 2]>],
        plane: &Plane,
    ) -> bool {
        self.planes
            .iter()
            .any(|&i| planes[i as usize].is_coincident(plane))
            || self.planes[1..].iter().any(|&i| {
                anchors
                    .get(i as usize)
                    .copied()
                    .flatten()
                    .is_some_and(|[a, b]| {
                        plane.classify_grid(a) == Side::On && plane.classify_grid(b) == Side::On
                    })
            })
    }

    /// Grid coordinates from the approximations, if they are within
    /// [`MEASURE_UNITS`] of the exact ones.
    fn measure(&self) -> Option<[f64; 3]> {
        let (w, ew) = (self.approx[3], self.err[3]);
        // |x/w - X/W| <= (ex + |x/w| ew) / (w - ew) for |x - X| <= ex,
        // |w - W| <= ew, w > ew
        let q = [0, 1, 2].map(|k| self.approx[k] / w);
        let room = (w - ew) * MEASURE_UNITS;
        (w > ew && (0..3).all(|k| self.err[k] + q[k].abs() * ew <= room)).then_some(q)
    }

    /// Exact side of `plane` without keeping the exact point: the filter,
    /// then `On` for one of the point's three planes, then the exact side.
    fn classify_shared(&self, planes: &[Plane], plane: &Plane) -> Side {
        if let Some(s) = filter_side_err(&plane.approx(), &self.approx, &self.err) {
            return s;
        }
        if self
            .planes
            .iter()
            .any(|&i| planes[i as usize].is_coincident(plane))
        {
            return Side::On;
        }
        match &self.exact {
            Some(e) => e.classify_exact(plane),
            None => self.exact(planes).classify_exact(plane),
        }
    }
}

/// A vertex of a [`PieceArena`], borrowed.
#[derive(Clone, Copy, Debug)]
pub(crate) enum VertexRef<'a> {
    /// A grid point.
    Grid(GridPoint),
    /// An exact implicit point.
    Exact(&'a Implicit),
    /// A lazy implicit point and the planes of its arena.
    Lazy(&'a Lazy, &'a [Plane]),
}

impl VertexRef<'_> {
    /// Exact side of `plane`.
    #[inline]
    pub(crate) fn classify(self, plane: &Plane) -> Side {
        match self {
            VertexRef::Grid(g) => plane.classify_grid(g),
            VertexRef::Exact(i) => i.classify(plane),
            VertexRef::Lazy(l, planes) => l.classify_shared(planes, plane),
        }
    }

    /// An owned exact copy.
    pub(crate) fn to_owned(self) -> Vertex {
        match self {
            VertexRef::Grid(g) => Vertex::Grid(g),
            VertexRef::Exact(i) => Vertex::Implicit(i.clone()),
            VertexRef::Lazy(l, planes) => Vertex::Implicit(l.exact(planes)),
        }
    }

    /// Per coordinate, an interval of `f64` values holding the exact one
    /// but for a few units in the last place (a lazy point's from its
    /// approximations and their error bounds, without its exact
    /// coordinates where the denominator's interval is clear of zero);
    /// for boxes that may be wider than the point, widened by the caller.
    pub(crate) fn near_f64(self) -> [[f64; 2]; 3] {
        match self {
            VertexRef::Lazy(l, _) if l.exact.is_none() && l.approx[3] > 2.0 * l.err[3] => {
                let (w, ew) = (l.approx[3], l.err[3]);
                [0, 1, 2].map(|k| {
                    let (x, ex) = (l.approx[k], l.err[k]);
                    let q = [
                        (x - ex) / (w - ew),
                        (x - ex) / (w + ew),
                        (x + ex) / (w - ew),
                        (x + ex) / (w + ew),
                    ];
                    [
                        q.iter().copied().fold(f64::INFINITY, f64::min),
                        q.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                    ]
                })
            }
            _ => self.to_f64().map(|c| [c, c]),
        }
    }

    /// Grid coordinates in `f64` for measuring, not deciding: a lazy
    /// point's approximations divided, without its exact coordinates,
    /// where their error bounds put every coordinate within
    /// [`MEASURE_UNITS`] grid units of the exact one; else, and for the
    /// others, correctly rounded.
    pub(crate) fn approx(self) -> [f64; 3] {
        if let VertexRef::Lazy(l, _) = self
            && l.exact.is_none()
            && let Some(q) = l.measure()
        {
            return q;
        }
        self.to_f64()
    }

    /// [`VertexRef::approx`] whether or not a lazy point's exact
    /// coordinates were found (so the same bits however it was
    /// classified before).
    pub(crate) fn measure(self) -> [f64; 3] {
        match self {
            VertexRef::Lazy(l, _) => l.measure().unwrap_or_else(|| self.to_f64()),
            _ => self.to_f64(),
        }
    }

    /// The correctly rounded grid coordinates.
    pub(crate) fn to_f64(self) -> [f64; 3] {
        match self {
            VertexRef::Grid(g) => g.map(f64::from),
            VertexRef::Exact(i) => i.to_f64(),
            VertexRef::Lazy(l, planes) => l.exact(planes).to_f64(),
        }
    }
}

/// Sizes of a [`PieceArena`] to go back to (see [`PieceArena::rollback`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct ArenaMark {
    grid: usize,
    exact: usize,
    lazy: usize,
    planes: usize,
}

/// Where a cell lies relative to a plane, by its vertices' exact sides.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Sides {
    /// Some vertex is strictly in front.
    pub front: bool,
    /// Some vertex is strictly behind.
    pub back: bool,
}

impl Sides {
    /// The sides some vertex of `c` is strictly on, given each vertex's
    /// side; stops at the first vertex that makes both.
    #[inline]
    fn of(c: &Piece, mut side: impl FnMut(u32) -> Side) -> Sides {
        Sides::first_both(c.verts.iter().map(|&v| side(v)))
    }

    /// The sides some grid point of `verts` is strictly on (a polygon not
    /// yet in an arena), as [`Sides::of`] gives for a piece of them.
    #[inline]
    pub(crate) fn of_grid(verts: &[GridPoint], plane: &Plane) -> Sides {
        Sides::first_both(verts.iter().map(|&g| plane.classify_grid(g)))
    }

    /// The sides some of `sides` is strictly on, taken no further than
    /// the first that makes both.
    #[inline]
    fn first_both(sides: impl Iterator<Item = Side>) -> Sides {
        let (mut front, mut back) = (false, false);
        for s in sides {
            match s {
                Side::Front => front = true,
                Side::Back => back = true,
                Side::On => {}
            }
            if front && back {
                break;
            }
        }
        Sides { front, back }
    }
}

impl PieceArena {
    /// An empty arena.
    #[cfg(test)]
    pub(crate) fn new() -> PieceArena {
        PieceArena::default()
    }

    /// Empties the arena, keeping its memory.
    pub(crate) fn clear(&mut self) {
        self.grid.clear();
        self.exact.clear();
        self.lazy.clear();
        self.planes.clear();
        self.anchors.clear();
    }

    /// The current sizes.
    #[inline]
    pub(crate) fn mark(&self) -> ArenaMark {
        ArenaMark {
            grid: self.grid.len(),
            exact: self.exact.len(),
            lazy: self.lazy.len(),
            planes: self.planes.len(),
        }
    }

    /// Appends what `other` (a copy of this arena when it was at `mark`,
    /// since grown on its own) added after `mark`, and renumbers `pieces`
    /// (of `other`) into this arena: the vertices and planes `other` had
    /// at `mark` keep their ids, the later ones follow this arena's own.
    /// With several copies appended in turn, each renumbered piece refers
    /// to the same points and planes as in its copy.
    pub(crate) fn append_since(
        &mut self,
        other: &PieceArena,
        mark: ArenaMark,
        pieces: &mut [Piece],
    ) {
        let shift = [
            self.grid.len() - mark.grid,
            self.exact.len() - mark.exact,
            self.lazy.len() - mark.lazy,
        ];
        let planes = self.planes.len() - mark.planes;
        let plane = |i: u32| match i as usize >= mark.planes {
            true => i + planes as u32,
            false => i,
        };
        let vertex = |id: u32| {
            let (tag, i) = (id & TAG, (id & !TAG) as usize);
            let (base, k) = match tag {
                EXACT => (mark.exact, 1),
                LAZY => (mark.lazy, 2),
                _ => (mark.grid, 0),
            };
            match i >= base {
                true => (i + shift[k]) as u32 | tag,
                false => id,
            }
        };
        self.grid.extend_from_slice(&other.grid[mark.grid..]);
        self.exact.extend_from_slice(&other.exact[mark.exact..]);
        self.lazy
            .extend(other.lazy[mark.lazy..].iter().map(|l| Lazy {
                planes: l.planes.map(plane),
                ..l.clone()
            }));
        self.planes.extend_from_slice(&other.planes[mark.planes..]);
        self.anchors
            .extend_from_slice(&other.anchors[mark.planes..]);
        for c in pieces {
            for v in &mut c.verts {
                *v = vertex(*v);
            }
            for e in &mut c.edges {
                *e = EdgeRef::new(plane(e.index()), e.flipped());
            }
        }
    }

    /// Drops every vertex and plane added since `mark`. Pieces that refer
    /// to them must be dropped too.
    #[inline]
    pub(crate) fn rollback(&mut self, mark: ArenaMark) {
        self.grid.truncate(mark.grid);
        self.exact.truncate(mark.exact);
        self.lazy.truncate(mark.lazy);
        self.planes.truncate(mark.planes);
        self.anchors.truncate(mark.planes);
    }

    /// Adds a plane, returning its index.
    #[inline]
    pub(crate) fn add_plane(&mut self, p: Plane) -> u32 {
        self.planes.push(p);
        self.anchors.push(None);
        (self.planes.len() - 1) as u32
    }

    /// Adds the plane of a polygon's edge from grid point `a` to `b`,
    /// returning its index. Knowing the edge lets a vertex on it be found
    /// on any plane through the edge without arithmetic.
    #[inline]
    pub(crate) fn add_edge_plane(&mut self, p: Plane, a: GridPoint, b: GridPoint) -> u32 {
        self.planes.push(p);
        self.anchors.push(Some([a, b]));
        (self.planes.len() - 1) as u32
    }

    /// The two grid points known on plane `i`'s line with the support (see
    /// [`PieceArena::add_edge_plane`]).
    #[inline]
    pub(crate) fn anchors(&self, i: u32) -> Option<[GridPoint; 2]> {
        self.anchors[i as usize]
    }

    /// Adds a grid vertex, returning its id.
    #[inline]
    pub(crate) fn add_grid(&mut self, g: GridPoint) -> u32 {
        self.grid.push(g);
        (self.grid.len() - 1) as u32
    }

    /// Adds an exact implicit vertex, returning its id.
    #[inline]
    pub(crate) fn add_exact(&mut self, i: Implicit) -> u32 {
        self.exact.push(i);
        (self.exact.len() - 1) as u32 | EXACT
    }

    /// Adds the intersection of planes `idx` of this arena as a lazy
    /// vertex, returning its id; `None` if they do not meet in one point.
    pub(crate) fn add_meet(&mut self, idx: [u32; 3]) -> Option<u32> {
        let l = Lazy::new(&self.planes, idx)?;
        self.lazy.push(l);
        Some((self.lazy.len() - 1) as u32 | LAZY)
    }

    /// Copies vertex `id` of another arena into this one (a lazy vertex
    /// with its three planes).
    pub(crate) fn copy_vertex(&mut self, from: &PieceArena, id: u32) -> u32 {
        match from.vertex(id) {
            VertexRef::Grid(g) => self.add_grid(g),
            VertexRef::Exact(i) => self.add_exact(i.clone()),
            VertexRef::Lazy(l, planes) => {
                let anchors = &from.anchors;
                let idx = l.planes.map(|i| {
                    self.planes.push(planes[i as usize]);
                    self.anchors.push(anchors[i as usize]);
                    (self.planes.len() - 1) as u32
                });
                self.lazy.push(Lazy {
                    planes: idx,
                    ..l.clone()
                });
                (self.lazy.len() - 1) as u32 | LAZY
            }
        }
    }

    /// Keeps only the vertices and planes `pieces` use, and plane `keep`,
    /// renumbering them (in the order first met: `keep` first, then each
    /// piece's corners and edges in turn, a lazy vertex's planes with it).
    /// Returns `keep`'s new index. The points and planes are the same
    /// values, a lazy point keeps its exact coordinates if it had them.
    pub(crate) fn compact<'a>(
        &mut self,
        keep: u32,
        pieces: impl IntoIterator<Item = &'a mut Piece>,
    ) -> u32 {
        let old = std::mem::take(self);
        let (grids, exacts) = (old.grid.len(), old.exact.len());
        let mut lazy: Vec<Option<Lazy>> = old.lazy.into_iter().map(Some).collect();
        let mut exact: Vec<Option<Implicit>> = old.exact.into_iter().map(Some).collect();
        let mut plane_at = vec![u32::MAX; old.planes.len()];
        let mut vertex_at = vec![u32::MAX; grids + exacts + lazy.len()];
        let mut plane = |i: u32, new: &mut PieceArena| -> u32 {
            let at = &mut plane_at[i as usize];
            if *at == u32::MAX {
                *at = new.planes.len() as u32;
                new.planes.push(old.planes[i as usize]);
                new.anchors.push(old.anchors[i as usize]);
            }
            *at
        };
        let keep = plane(keep, self);
        for p in pieces {
            for v in &mut p.verts {
                let (i, d) = ((*v & !TAG) as usize, dense_of(*v, grids, exacts));
                if vertex_at[d] == u32::MAX {
                    vertex_at[d] = match *v & TAG {
                        0 => self.add_grid(old.grid[i]),
                        EXACT => self.add_exact(exact[i].take().expect("each vertex once")),
                        _ => {
                            let mut l = lazy[i].take().expect("each vertex once");
                            l.planes = l.planes.map(|j| plane(j, self));
                            self.lazy.push(l);
                            (self.lazy.len() - 1) as u32 | LAZY
                        }
                    };
                }
                *v = vertex_at[d];
            }
            for e in &mut p.edges {
                *e = EdgeRef::new(plane(e.index(), self), e.flipped());
            }
        }
        keep
    }

    /// Vertex `id`.
    #[inline]
    pub(crate) fn vertex(&self, id: u32) -> VertexRef<'_> {
        let i = (id & !TAG) as usize;
        match id & TAG {
            0 => VertexRef::Grid(self.grid[i]),
            EXACT => VertexRef::Exact(&self.exact[i]),
            _ => VertexRef::Lazy(&self.lazy[i], &self.planes),
        }
    }

    /// Number of vertices.
    pub(crate) fn len(&self) -> usize {
        self.grid.len() + self.exact.len() + self.lazy.len()
    }

    /// Whether a vertex or an edge plane of `c` was added since `mark`
    /// (so that rolling back to `mark` would take it away; a cut through
    /// two of its corners makes a new edge and no new vertex).
    pub(crate) fn uses_since(&self, c: &Piece, mark: ArenaMark) -> bool {
        c.edges.iter().any(|e| e.index() as usize >= mark.planes)
            || c.verts.iter().any(|&id| {
                let i = (id & !TAG) as usize;
                match id & TAG {
                    0 => i >= mark.grid,
                    EXACT => i >= mark.exact,
                    _ => i >= mark.lazy,
                }
            })
    }

    /// A dense index in `0..len()` for vertex `id`, valid until the next
    /// vertex is added.
    #[inline]
    pub(crate) fn dense(&self, id: u32) -> usize {
        dense_of(id, self.grid.len(), self.exact.len())
    }

    /// The plane of an edge, oriented.
    #[inline]
    pub(crate) fn plane(&self, e: EdgeRef) -> Plane {
        let p = self.planes[e.index() as usize];
        if e.flipped() { p.flip() } else { p }
    }

    /// A piece from a polygon lying on this arena's support plane: its
    /// vertices and edge planes are copied into the arena.
    pub(crate) fn add_polygon(&mut self, p: &Polygon) -> Piece {
        self.add_polygon_with(p, |arena, a| arena.add_exact((**a).clone()))
    }

    /// [`PieceArena::add_polygon`], an implicit vertex added once for all
    /// the polygons that share it (one allocation, `shared` mapping it to
    /// its id): the pieces of a cut face share their split vertices.
    pub(crate) fn add_polygon_sharing(
        &mut self,
        p: &Polygon,
        shared: &mut rustc_hash::FxHashMap<*const Implicit, u32>,
    ) -> Piece {
        self.add_polygon_with(p, |arena, a| {
            *(shared.entry(std::sync::Arc::as_ptr(a)))
                .or_insert_with(|| arena.add_exact((**a).clone()))
        })
    }

    /// [`PieceArena::add_polygon`], each implicit vertex's id given by
    /// `implicit`.
    #[inline]
    fn add_polygon_with(
        &mut self,
        p: &Polygon,
        mut implicit: impl FnMut(&mut PieceArena, &std::sync::Arc<Implicit>) -> u32,
    ) -> Piece {
        let mut c = Piece::default();
        let vs = p.vertices();
        let k = vs.len();
        for (i, (v, e)) in vs.iter().zip(p.edge_planes()).enumerate() {
            let id = match v {
                Point::Grid(g) => self.add_grid(*g),
                Point::Implicit(a) => implicit(self, a),
            };
            c.verts.push(id);
            let plane = match (v, &vs[(i + 1) % k]) {
                (Point::Grid(a), Point::Grid(b)) => self.add_edge_plane(*e, *a, *b),
                _ => self.add_plane(*e),
            };
            c.edges.push(EdgeRef::new(plane, false));
        }
        c
    }

    /// The exact side of vertex `id` relative to `plane` (a lazy vertex
    /// keeps its exact coordinates if they had to be computed).
    ///
    /// A grid vertex is classified inline, and so is an implicit one
    /// the floating-point filter decides; the exact arithmetic the filter
    /// leaves is out of line, so that the callers' loops carry no frame
    /// for it.
    #[inline]
    pub(crate) fn classify(&mut self, id: u32, plane: &Plane) -> Side {
        match id & TAG {
            0 => plane.classify_grid(self.grid[id as usize]),
            _ => self.classify_implicit(id, plane),
        }
    }

    /// [`PieceArena::classify`] of an implicit vertex: the filter on its
    /// `f64` coordinates, which decides nearly every call, inline; the
    /// exact arithmetic (256-bit products and a kept exact point, whose
    /// frame is several hundred bytes) out of line, in
    /// [`PieceArena::classify_implicit_exactly`].
    #[inline]
    fn classify_implicit(&mut self, id: u32, plane: &Plane) -> Side {
        let i = (id & !TAG) as usize;
        let filtered = match id & TAG {
            EXACT => self.exact[i].classify_filtered(plane),
            _ => {
                let l = &self.lazy[i];
                filter_side_err(&plane.approx(), &l.approx, &l.err)
            }
        };
        match filtered {
            Some(s) => s,
            None => self.classify_implicit_exactly(id, plane),
        }
    }

    /// [`PieceArena::classify_implicit`] where the filter cannot tell.
    #[cold]
    #[inline(never)]
    fn classify_implicit_exactly(&mut self, id: u32, plane: &Plane) -> Side {
        let i = (id & !TAG) as usize;
        match id & TAG {
            EXACT => self.exact[i].classify_exact(plane),
            _ => self.lazy[i].classify_unfiltered(&self.planes, &self.anchors, plane),
        }
    }

    /// Which sides of `plane` some vertex of `c` is strictly on.
    #[inline]
    pub(crate) fn sides(&mut self, c: &Piece, plane: &Plane) -> Sides {
        Sides::of(c, |v| self.classify(v, plane))
    }

    /// [`PieceArena::sides`] through a shared reference (a lazy vertex
    /// that needs its exact coordinates computes them without keeping
    /// them), for classifying in parallel.
    pub(crate) fn sides_shared(&self, c: &Piece, plane: &Plane) -> Sides {
        Sides::of(c, |v| self.vertex(v).classify(plane))
    }

    /// The exact sides of `c`'s vertices relative to `plane`, written to
    /// `out` (cleared first).
    #[inline]
    pub(crate) fn classify_into(
        &mut self,
        c: &Piece,
        plane: &Plane,
        out: &mut SmallVec<[Side; 8]>,
    ) -> Sides {
        out.clear();
        let (mut front, mut back) = (false, false);
        for &v in &c.verts {
            let s = self.classify(v, plane);
            front |= s == Side::Front;
            back |= s == Side::Back;
            out.push(s);
        }
        Sides { front, back }
    }

    /// Splits `c` by plane `cut` given its vertices' sides, which must
    /// include both `Front` and `Back`: the front and back pieces. `support`
    /// and `cut` are indices into [`PieceArena::planes`]. Each crossing edge
    /// gets one new (lazy) vertex, shared by both pieces.
    pub(crate) fn split(
        &mut self,
        support: u32,
        c: &Piece,
        cut: u32,
        sides: &[Side],
    ) -> (Piece, Piece) {
        let mut f = Piece::default();
        let mut b = Piece::default();
        split_loop(
            &c.verts,
            &c.edges,
            sides,
            EdgeRef::new(cut, true),
            EdgeRef::new(cut, false),
            |i| {
                self.add_meet([support, c.edges[i].index(), cut])
                    .expect("a spanning edge meets the cutting plane in one point")
            },
            |v, e| {
                f.verts.push(v);
                f.edges.push(e);
            },
            |v, e| {
                b.verts.push(v);
                b.edges.push(e);
            },
        );
        (f, b)
    }

    /// Checks `c`'s invariants exactly (see [`check_convex`]).
    #[cfg(test)]
    pub(crate) fn sanity_check(&self, support: &Plane, c: &Piece) -> Result<(), SanityError> {
        check_convex(&PieceView {
            arena: self,
            support,
            cell: c,
        })
    }
}

#[cfg(test)]
struct PieceView<'a> {
    arena: &'a PieceArena,
    support: &'a Plane,
    cell: &'a Piece,
}

#[cfg(test)]
impl ConvexParts for PieceView<'_> {
    fn vertex_count(&self) -> usize {
        self.cell.verts.len()
    }
    fn edge_count(&self) -> usize {
        self.cell.edges.len()
    }
    fn support_side(&self, i: usize) -> Side {
        self.arena.vertex(self.cell.verts[i]).classify(self.support)
    }
    fn edge_side(&self, i: usize, j: usize) -> Side {
        let p = self.arena.plane(self.cell.edges[j]);
        self.arena.vertex(self.cell.verts[i]).classify(&p)
    }
    fn edge_is_support(&self, j: usize) -> bool {
        self.arena
            .plane(self.cell.edges[j])
            .is_coincident(self.support)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_shares_new_vertices_and_keeps_invariants() {
        let sq =
            Polygon::from_grid_points(&[[0, 0, 0], [4, 0, 0], [4, 4, 0], [0, 4, 0]], 0).unwrap();
        let mut a = PieceArena::new();
        let support = *sq.support();
        let sup = a.add_plane(support);
        let c = a.add_polygon(&sq);
        a.sanity_check(&support, &c).unwrap();
        let cut = a.add_plane(Plane::new([1, 0, 0], -1).unwrap());
        let mut sides = SmallVec::new();
        let s = a.classify_into(&c, &a.planes[cut as usize].clone(), &mut sides);
        assert!(s.front && s.back);
        let before = a.mark();
        let (f, b) = a.split(sup, &c, cut, &sides);
        assert_eq!(a.len(), 4 + 2);
        a.sanity_check(&support, &f).unwrap();
        a.sanity_check(&support, &b).unwrap();
        let shared = f.verts.iter().filter(|v| b.verts.contains(v)).count();
        assert_eq!(shared, 2);
        // rolling back removes the new vertices
        a.rollback(before);
        assert_eq!(a.len(), 4);
    }

    #[test]
    fn vertex_comparisons_are_exact_across_kinds() {
        let x = Plane::new([1, 0, 0], -3).unwrap();
        let y = Plane::new([0, 2, 0], 10).unwrap();
        let z = Plane::new([0, 0, -1], 7).unwrap();
        let i = Vertex::Implicit(Implicit::from_planes(&x, &y, &z).unwrap());
        let g = Vertex::Grid([3, -5, 7]);
        assert!(i.same_point(&g) && g.same_point(&i));
        assert_eq!(Vertex::Grid([4, 0, 0]).cmp_axis(&i, 0), Ordering::Greater);
        assert_eq!(i.cmp_axis(&Vertex::Grid([4, 0, 0]), 0), Ordering::Less);
        assert_eq!(i.to_f64(), [3.0, -5.0, 7.0]);
    }
}
