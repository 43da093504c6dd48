//! Convex polygons in plane-based form, exact classification and splitting.

use smallvec::SmallVec;

use crate::kernel::grid::GridPoint;
use crate::kernel::plane::FaceDefect;
use crate::kernel::plane::{Plane, in_range};
use std::sync::Arc;

use crate::kernel::convex::{ConvexParts, SanityError, check_convex};
use crate::kernel::grid_loop::{LINKED, dedupe_cyclic, remove_collinear};
use crate::kernel::point::{Implicit, Point, PointRef, approx_key};

/// Exact position of a polygon relative to a plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PolygonSide {
    /// Every vertex is in front or on, at least one in front.
    Front,
    /// Every vertex is behind or on, at least one behind.
    Back,
    /// The polygon lies in the plane; `same_orientation` tells whether its
    /// normal points the same way as the plane's.
    Coplanar {
        /// Normals agree.
        same_orientation: bool,
    },
    /// Vertices strictly on both sides.
    Spanning,
}

/// The result of splitting a polygon by a plane.
// By value on purpose: the pieces move straight into the caller's lists.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
pub enum Split {
    /// Entirely in front (possibly touching the plane).
    Front(Polygon),
    /// Entirely behind (possibly touching the plane).
    Back(Polygon),
    /// In the plane.
    Coplanar {
        /// The polygon, unchanged.
        polygon: Polygon,
        /// Normals agree.
        same_orientation: bool,
    },
    /// Cut into two convex pieces sharing the cut edge's two vertices.
    Spanning {
        /// The piece in front.
        front: Polygon,
        /// The piece behind.
        back: Polygon,
    },
}

/// A polygon's parts on the two sides of a plane, the polygon itself kept
/// ([`Polygon::parts`]).
// By value on purpose, as [`Split`].
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
pub enum Parts {
    /// Not cut: the polygon's side of the plane (never `Spanning`).
    Whole(PolygonSide),
    /// Cut into two convex pieces sharing the cut edge's two vertices.
    Split {
        /// The piece in front.
        front: Polygon,
        /// The piece behind.
        back: Polygon,
    },
}

/// A convex polygon: a support plane and a cycle of edge planes.
///
/// Vertex `i` is the intersection of the support plane with edge planes
/// `i - 1` and `i`; edge plane `i` bounds the edge from vertex `i` to vertex
/// `i + 1`, with the polygon's interior behind it. Vertices run
/// counter-clockwise seen from the support plane's front. The vertices are
/// cached as exact [`Point`]s; new ones are created only where a split cuts
/// an edge, and both pieces share them.
#[derive(Clone, Debug)]
pub struct Polygon {
    support: Plane,
    edges: SmallVec<[Plane; 4]>,
    verts: SmallVec<[Point; 4]>,
    tag: u32,
}

/// The support plane of a planar loop, oriented by its winding; `None` if
/// the enclosed area is zero.
pub(crate) fn support_plane(v: &[GridPoint]) -> Result<Plane, FaceDefect> {
    let k = v.len();
    let mut plane = None;
    'outer: for i in 1..k {
        for j in i + 1..k {
            if let Some(p) = Plane::through_in_range(v[0], v[i], v[j]) {
                plane = Some(p);
                break 'outer;
            }
        }
    }
    let plane = plane.ok_or(FaceDefect::ZeroArea)?;
    // the plane through three points holds them exactly
    if k > 3
        && v.iter()
            .any(|p| plane.classify_grid(*p) != crate::kernel::Side::On)
    {
        return Err(FaceDefect::NonPlanar);
    }
    // orientation: twice the projected signed area along the dominant axis
    let ax = plane.dominant_axis();
    let (a, b) = ((ax + 1) % 3, (ax + 2) % 3);
    let mut area2: i128 = 0;
    for i in 0..k {
        let p = v[i];
        let q = v[(i + 1) % k];
        area2 += p[a] as i128 * q[b] as i128 - q[a] as i128 * p[b] as i128;
    }
    if area2 == 0 {
        return Err(FaceDefect::ZeroArea);
    }
    let n = plane.normal()[ax];
    Ok(if (area2 > 0) == (n > 0) {
        plane
    } else {
        plane.flip()
    })
}

/// A convex polygon with grid vertices, stored without its edge planes:
/// its support plane and its corners. Each edge plane is the one
/// [`Polygon::from_grid_points`] gives (through the edge, containing the
/// axis along which the support's normal is largest), computed when asked
/// for, so the form takes about a third of a [`Polygon`]'s room: a large
/// solid whose faces are mostly never cut keeps them in it. It carries no
/// tag, which would cost eight bytes on every face of a large solid: a
/// caller who tags its polygons tags the [`Polygon`] it makes of one.
#[derive(Clone, Debug)]
pub struct GridPolygon {
    support: Plane,
    verts: SmallVec<[GridPoint; 4]>,
}

impl GridPolygon {
    /// A polygon from grid points in counter-clockwise order, checked and
    /// cleaned as [`Polygon::from_grid_points`] does.
    pub fn from_grid_points(points: &[GridPoint]) -> Result<GridPolygon, FaceDefect> {
        if !in_range(points) {
            return Err(FaceDefect::OutOfRange);
        }
        // most faces are triangles of three distinct corners: what the
        // general path gives them, without its copies (the plane through
        // the corners in order is the one oriented by their winding, and
        // a triangle of nonzero area is convex)
        if let [a, b, c] = *points
            && a != b
            && b != c
            && c != a
        {
            let support = Plane::through_in_range(a, b, c).ok_or(FaceDefect::ZeroArea)?;
            return Ok(GridPolygon {
                support,
                verts: SmallVec::from_buf_and_len([a, b, c, [0; 3]], 3),
            });
        }
        let mut v = dedupe_cyclic(points);
        if v.len() < 3 {
            return Err(FaceDefect::TooFewVertices);
        }
        let support = support_plane(&v)?;
        // a triangle of nonzero area has no collinear corner and is
        // convex: the checks are for larger loops
        let triangle = v.len() == 3;
        if !triangle {
            remove_collinear(&mut v);
            if v.len() < 3 {
                return Err(FaceDefect::ZeroArea);
            }
        }
        let g = GridPolygon {
            support,
            verts: v.into_iter().collect(),
        };
        let convex = || match g.verts.len() >= LINKED {
            true => g.convex_by_turns(),
            false => g.convex_pairwise(),
        };
        if triangle {
            debug_assert!(convex(), "a triangle of nonzero area is convex");
        } else if !convex() {
            return Err(FaceDefect::NonConvex);
        }
        Ok(g)
    }

    /// The support plane.
    pub fn support(&self) -> &Plane {
        &self.support
    }

    /// Whether every corner but an edge's own lies strictly behind the
    /// edge's plane, edge by edge: strictly convex.
    fn convex_pairwise(&self) -> bool {
        let k = self.verts.len();
        (0..k).all(|i| {
            let e = self.edge_plane(i);
            self.verts.iter().enumerate().all(|(j, p)| {
                j == i || j == (i + 1) % k || e.classify_grid(*p) == crate::kernel::Side::Back
            })
        })
    }

    /// [`GridPolygon::convex_pairwise`]'s answer in linear time: strictly
    /// convex if and only if every corner turns the loop's way (the corner
    /// after the next lies strictly behind each edge's plane) and the loop
    /// turns around once (a loop turning one way all along may go around
    /// twice, as a pentagram does): its edges' directions, seen along the
    /// support's dominant axis, pass a fixed direction once.
    fn convex_by_turns(&self) -> bool {
        let k = self.verts.len();
        let v = &self.verts;
        let turns = (0..k)
            .all(|i| self.edge_plane(i).classify_grid(v[(i + 2) % k]) == crate::kernel::Side::Back);
        if !turns {
            return false;
        }
        let ax = self.support.dominant_axis();
        let (a, b) = ((ax + 1) % 3, (ax + 2) % 3);
        let d = |i: usize| {
            let (p, q) = (v[i], v[(i + 1) % k]);
            let c = |x: usize| i128::from(q[x]) - i128::from(p[x]);
            (c(a), c(b))
        };
        let cross = |u: (i128, i128), w: (i128, i128)| u.0 * w.1 - u.1 * w.0;
        // the way every edge turns into the next, seen so (none is straight)
        let s = cross(d(0), d(1)).signum();
        let r = (1, 0);
        // the edges turning past `r` (from before it to it or beyond)
        let passes = (0..k)
            .filter(|&i| {
                let (u, w) = (d(i), d((i + 1) % k));
                s * cross(u, r) > 0 && (s * cross(r, w) > 0 || (cross(r, w) == 0 && w.0 > 0))
            })
            .count();
        passes == 1
    }

    /// The corners, counter-clockwise.
    pub fn vertices(&self) -> &[GridPoint] {
        &self.verts
    }

    /// Number of corners.
    pub fn len(&self) -> usize {
        self.verts.len()
    }

    /// Always `false`: a polygon has at least three corners.
    pub fn is_empty(&self) -> bool {
        self.verts.is_empty()
    }

    /// Edge plane `i`, bounding the edge from corner `i` to `i + 1`
    /// (interior behind): the plane [`GridPolygon::to_polygon`] stores.
    #[inline]
    pub fn edge_plane(&self, i: usize) -> Plane {
        let k = self.verts.len();
        Plane::edge(self.verts[i], self.verts[(i + 1) % k], &self.support)
            .expect("edge plane of two distinct grid points fits the budget")
    }

    /// The same polygon seen from the other side: its edge planes are
    /// those of [`Polygon::flipped`] of the polygon.
    pub fn flipped(&self) -> GridPolygon {
        GridPolygon {
            support: self.support.flip(),
            verts: self.verts.iter().rev().copied().collect(),
        }
    }

    /// What [`Polygon::clip`] by each of `planes` in turn, keeping the
    /// back, gives [`GridPolygon::to_polygon`]: the same corners, edge
    /// planes and tag, or `None` where a clip leaves nothing. The same
    /// points, too, but computed more cheaply: a corner a plane cuts from
    /// an input edge is found from that edge's two grid ends
    /// ([`Implicit::on_segment`], native products) even where earlier
    /// planes have cut the edge shorter, and an input edge's plane is
    /// made only if part of the edge is left. No polygon is made between
    /// the planes.
    pub fn clipped<'a>(
        &self,
        planes: impl IntoIterator<Item = &'a Plane>,
        tag: u32,
    ) -> Option<Polygon> {
        use crate::kernel::Side::{Back, Front, On};
        /// An edge of the polygon being clipped: part of input edge `i`,
        /// or a piece of a cutting plane.
        #[derive(Clone, Copy)]
        enum Edge {
            Input(u8),
            Cut(Plane),
        }
        type Loop = SmallVec<[(Point, Edge); 8]>;
        let n = self.verts.len();
        let mut cur: Loop = (0..n)
            .map(|i| (Point::Grid(self.verts[i]), Edge::Input(i as u8)))
            .collect();
        let mut next = Loop::new();
        let mut sides: SmallVec<[crate::kernel::Side; 8]> = SmallVec::new();
        for plane in planes {
            if self.support == *plane || self.support == plane.flip() {
                return None;
            }
            sides.clear();
            sides.extend(cur.iter().map(|(v, _)| v.classify(plane)));
            match (sides.contains(&Back), sides.contains(&Front)) {
                (true, false) => continue,
                (false, _) => return None,
                (true, true) => {}
            }
            let crossing = |e: &Edge, a: &Point, b: &Point| -> Point {
                match *e {
                    Edge::Input(i) => {
                        let i = i as usize;
                        let (p, q) = (self.verts[i], self.verts[(i + 1) % n]);
                        Point::Implicit(Arc::new(Implicit::on_segment(&p, &q, plane)))
                    }
                    Edge::Cut(e) => Point::crossing(a, b, &self.support, &e, plane),
                }
            };
            // the back piece, as `split_loop` makes it
            next.clear();
            let k = cur.len();
            for i in 0..k {
                let j = if i + 1 == k { 0 } else { i + 1 };
                let (vi, ei) = &cur[i];
                match (sides[i], sides[j]) {
                    (Front, Back) => next.push((crossing(ei, vi, &cur[j].0), *ei)),
                    (Back, Front) => {
                        next.push((vi.clone(), *ei));
                        next.push((crossing(ei, vi, &cur[j].0), Edge::Cut(*plane)));
                    }
                    (Front, _) => {}
                    (Back, _) | (On, Back) => next.push((vi.clone(), *ei)),
                    (On, _) => next.push((vi.clone(), Edge::Cut(*plane))),
                }
            }
            std::mem::swap(&mut cur, &mut next);
        }
        let (verts, edges) = cur
            .into_iter()
            .map(|(v, e)| {
                let e = match e {
                    Edge::Input(i) => self.edge_plane(i as usize),
                    Edge::Cut(p) => p,
                };
                (v, e)
            })
            .unzip();
        Some(Polygon {
            support: self.support,
            edges,
            verts,
            tag,
        })
    }

    /// The polygon with its edge planes, tagged `tag`.
    pub fn to_polygon(&self, tag: u32) -> Polygon {
        Polygon {
            support: self.support,
            edges: (0..self.verts.len()).map(|i| self.edge_plane(i)).collect(),
            verts: self.verts.iter().map(|&g| Point::Grid(g)).collect(),
            tag,
        }
    }
}

/// A convex face as the mesh builder and the exact ray test read it: its
/// support plane, its corners counter-clockwise, and its edge planes (edge
/// `i` runs from corner `i` to `i + 1`, interior behind). [`Polygon`] and
/// [`GridPolygon`] are faces, and so is a reference to one.
pub trait ConvexFace {
    /// The support plane.
    fn support(&self) -> &Plane;
    /// Number of corners.
    fn corner_count(&self) -> usize;
    /// Corner `i`.
    fn corner(&self, i: usize) -> PointRef<'_>;
    /// Edge plane `i`.
    fn edge_plane(&self, i: usize) -> Plane;
}

impl ConvexFace for Polygon {
    #[inline]
    fn support(&self) -> &Plane {
        &self.support
    }
    #[inline]
    fn corner_count(&self) -> usize {
        self.verts.len()
    }
    #[inline]
    fn corner(&self, i: usize) -> PointRef<'_> {
        self.verts[i].as_ref()
    }
    #[inline]
    fn edge_plane(&self, i: usize) -> Plane {
        self.edges[i]
    }
}

impl ConvexFace for GridPolygon {
    #[inline]
    fn support(&self) -> &Plane {
        &self.support
    }
    #[inline]
    fn corner_count(&self) -> usize {
        self.verts.len()
    }
    #[inline]
    fn corner(&self, i: usize) -> PointRef<'_> {
        PointRef::Grid(self.verts[i])
    }
    #[inline]
    fn edge_plane(&self, i: usize) -> Plane {
        GridPolygon::edge_plane(self, i)
    }
}

impl<T: ConvexFace + ?Sized> ConvexFace for &T {
    #[inline]
    fn support(&self) -> &Plane {
        (**self).support()
    }
    #[inline]
    fn corner_count(&self) -> usize {
        (**self).corner_count()
    }
    #[inline]
    fn corner(&self, i: usize) -> PointRef<'_> {
        (**self).corner(i)
    }
    #[inline]
    fn edge_plane(&self, i: usize) -> Plane {
        (**self).edge_plane(i)
    }
}

impl Polygon {
    /// A polygon from grid points in counter-clockwise order.
    ///
    /// Repeated and collinear vertices are removed first; the rest must be
    /// planar and strictly convex, with every coordinate within
    /// `±`[`MAX_COORD`](crate::kernel::MAX_COORD) ([`FaceDefect::OutOfRange`]).
    ///
    /// ```
    /// use bsp_core::{Polygon, FaceDefect};
    /// let sq = Polygon::from_grid_points(&[[0, 0, 0], [2, 0, 0], [2, 2, 0], [1, 2, 0], [0, 2, 0]], 7).unwrap();
    /// assert_eq!(sq.len(), 4); // the collinear vertex is gone
    /// assert_eq!(sq.support().normal(), [0, 0, 1]);
    /// let bow = Polygon::from_grid_points(&[[0, 0, 0], [2, 2, 0], [2, 0, 0], [0, 2, 0]], 0);
    /// assert!(bow.is_err());
    /// ```
    pub fn from_grid_points(points: &[GridPoint], tag: u32) -> Result<Polygon, FaceDefect> {
        GridPolygon::from_grid_points(points).map(|g| g.to_polygon(tag))
    }

    /// A polygon from its support plane and cycle of edge planes (edge
    /// plane `i` bounds the edge from vertex `i` to `i + 1`, interior
    /// behind), computing the vertices. `None` if two consecutive planes do
    /// not meet the support plane in one point. The caller guarantees
    /// convexity (checked by [`Polygon::sanity_check`]).
    pub fn from_planes(support: Plane, edges: &[Plane], tag: u32) -> Option<Polygon> {
        let k = edges.len();
        if k < 3 {
            return None;
        }
        let verts = (0..k)
            .map(|i| Point::from_planes(&support, &edges[(i + k - 1) % k], &edges[i]))
            .collect::<Option<SmallVec<[Point; 4]>>>()?;
        Some(Polygon {
            support,
            edges: edges.iter().copied().collect(),
            verts,
            tag,
        })
    }

    /// The same polygon seen from the other side: flipped support plane,
    /// reversed vertex order, same edge planes.
    pub fn flipped(&self) -> Polygon {
        let k = self.verts.len();
        Polygon {
            support: self.support.flip(),
            edges: (0..k).map(|j| self.edges[(2 * k - 2 - j) % k]).collect(),
            verts: self.verts.iter().rev().cloned().collect(),
            tag: self.tag,
        }
    }

    /// The same polygon with another tag.
    pub fn with_tag(mut self, tag: u32) -> Polygon {
        self.tag = tag;
        self
    }

    /// Sets the tag in place.
    pub fn set_tag(&mut self, tag: u32) {
        self.tag = tag;
    }

    /// The support plane.
    pub fn support(&self) -> &Plane {
        &self.support
    }

    /// The edge planes; plane `i` bounds the edge from vertex `i` to `i + 1`.
    pub fn edge_planes(&self) -> &[Plane] {
        &self.edges
    }

    /// The exact vertices, counter-clockwise.
    pub fn vertices(&self) -> &[Point] {
        &self.verts
    }

    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.verts.len()
    }

    /// Always `false`: a polygon has at least three vertices.
    pub fn is_empty(&self) -> bool {
        self.verts.is_empty()
    }

    /// The caller's tag, carried unchanged into every fragment (e.g. the
    /// index of the input face).
    pub fn tag(&self) -> u32 {
        self.tag
    }

    /// Vertices in grid coordinates, correctly rounded to `f64`.
    pub fn vertices_f64(&self) -> Vec<[f64; 3]> {
        self.verts.iter().map(Point::to_f64).collect()
    }

    /// Exact position relative to `plane`.
    pub fn classify(&self, plane: &Plane) -> PolygonSide {
        if let Some(c) = self.coplanar_with(plane) {
            return c;
        }
        let (mut front, mut back) = (false, false);
        for v in &self.verts {
            match v.classify(plane) {
                crate::kernel::Side::Front => front = true,
                crate::kernel::Side::Back => back = true,
                crate::kernel::Side::On => {}
            }
            if front && back {
                return PolygonSide::Spanning;
            }
        }
        self.side_from(front, back, plane)
    }

    /// Coplanar answer from plane identity alone: reduced planes are equal
    /// exactly when they coincide.
    #[inline]
    fn coplanar_with(&self, plane: &Plane) -> Option<PolygonSide> {
        if self.support == *plane {
            Some(PolygonSide::Coplanar {
                same_orientation: true,
            })
        } else if self.support == plane.flip() {
            Some(PolygonSide::Coplanar {
                same_orientation: false,
            })
        } else {
            None
        }
    }

    fn side_from(&self, front: bool, back: bool, plane: &Plane) -> PolygonSide {
        match (front, back) {
            (true, true) => PolygonSide::Spanning,
            (true, false) => PolygonSide::Front,
            (false, true) => PolygonSide::Back,
            // a non-degenerate polygon with every vertex on `plane` lies in
            // it, and reduced planes are then equal up to sign: unreachable
            // for valid polygons, answered consistently anyway
            (false, false) => PolygonSide::Coplanar {
                same_orientation: self.support.same_direction(plane),
            },
        }
    }

    /// Splits by `plane`. The two pieces of a spanning polygon are convex,
    /// cover it exactly, and share the same two exact vertices on the cut.
    /// Each vertex is classified once.
    pub fn split(self, plane: &Plane) -> Split {
        match self.parts(plane) {
            Parts::Split { front, back } => Split::Spanning { front, back },
            Parts::Whole(PolygonSide::Front) => Split::Front(self),
            Parts::Whole(PolygonSide::Back) => Split::Back(self),
            Parts::Whole(PolygonSide::Coplanar { same_orientation }) => Split::Coplanar {
                polygon: self,
                same_orientation,
            },
            Parts::Whole(PolygonSide::Spanning) => unreachable!("a spanning polygon is split"),
        }
    }

    /// As [`Polygon::split`], keeping the polygon: its side of `plane`, or
    /// the two pieces when it spans the plane.
    pub fn parts(&self, plane: &Plane) -> Parts {
        if let Some(c) = self.coplanar_with(plane) {
            return Parts::Whole(c);
        }
        let sides: SmallVec<[crate::kernel::Side; 8]> =
            self.verts.iter().map(|v| v.classify(plane)).collect();
        let front = sides.contains(&crate::kernel::Side::Front);
        let back = sides.contains(&crate::kernel::Side::Back);
        if front && back {
            let (front, back) = self.split_with_sides(plane, &sides);
            return Parts::Split { front, back };
        }
        Parts::Whole(self.side_from(front, back, plane))
    }

    /// Keeps only the part on side `keep` (`Front` or `Back`) of `plane`,
    /// in place; returns `false` if no part with positive area is left (the
    /// polygon is then unchanged and should be dropped). Cheaper than
    /// [`Polygon::split`] when one piece is not wanted: nothing is moved
    /// unless the polygon spans the plane, and only the kept piece is built.
    pub fn clip(&mut self, plane: &Plane, keep: crate::kernel::Side) -> bool {
        use crate::kernel::Side::{Back, Front, On};
        debug_assert!(keep != On, "keep the front or the back");
        if self.coplanar_with(plane).is_some() {
            return false;
        }
        let sides: SmallVec<[crate::kernel::Side; 8]> =
            self.verts.iter().map(|v| v.classify(plane)).collect();
        let away = if keep == Front { Back } else { Front };
        let has_keep = sides.contains(&keep);
        let has_away = sides.contains(&away);
        match (has_keep, has_away) {
            (true, false) => return true,
            (false, _) => return false,
            (true, true) => {}
        }
        let out = std::cell::RefCell::new(Builder::new(self.support, self.tag));
        let (keep_front, keep_back) = (keep == Front, keep == Back);
        split_loop(
            &self.verts,
            &self.edges,
            &sides,
            plane.flip(),
            *plane,
            |i| self.crossing(i, plane),
            |v, e| {
                if keep_front {
                    out.borrow_mut().push(v, e)
                }
            },
            |v, e| {
                if keep_back {
                    out.borrow_mut().push(v, e)
                }
            },
        );
        let out = out.into_inner();
        *self = out.finish();
        true
    }

    /// The new vertex where `plane` cuts edge `i`, whose ends it has
    /// strictly on opposite sides ([`Point::crossing`]).
    fn crossing(&self, i: usize, plane: &Plane) -> Point {
        let j = if i + 1 == self.verts.len() { 0 } else { i + 1 };
        Point::crossing(
            &self.verts[i],
            &self.verts[j],
            &self.support,
            &self.edges[i],
            plane,
        )
    }

    fn split_with_sides(&self, plane: &Plane, sides: &[crate::kernel::Side]) -> (Polygon, Polygon) {
        let mut f = Builder::new(self.support, self.tag);
        let mut b = Builder::new(self.support, self.tag);
        split_loop(
            &self.verts,
            &self.edges,
            sides,
            plane.flip(),
            *plane,
            |i| self.crossing(i, plane),
            |v, e| f.push(v, e),
            |v, e| b.push(v, e),
        );
        (f.finish(), b.finish())
    }

    /// The union of two polygons on the same support plane that share an
    /// edge (this one's edge `u → v` is `other`'s edge `v → u`, with exactly
    /// equal endpoints), if it is convex; `None` if they share no edge or
    /// their union is not convex. Where the two meet in a straight line
    /// the shared endpoint is dropped (so the union is strictly convex
    /// again) and the first's edge plane spans both edges. Exact: the
    /// angles at the shared endpoints are read off by classifying the next
    /// vertex of one against the edge plane of the other. The tag is this
    /// polygon's.
    ///
    /// ```
    /// use bsp_core::Polygon;
    /// let a = Polygon::from_grid_points(&[[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0]], 1).unwrap();
    /// let b = Polygon::from_grid_points(&[[2, 0, 0], [5, 0, 0], [5, 2, 0], [2, 2, 0]], 2).unwrap();
    /// let m = a.merge(&b).unwrap();
    /// assert_eq!(m.len(), 4); // (2, 0, 0) and (2, 2, 0) lie on straight lines
    /// assert!(m.sanity_check().is_ok());
    /// let c = Polygon::from_grid_points(&[[2, 0, 0], [5, 1, 0], [2, 2, 0]], 3).unwrap();
    /// assert_eq!(a.merge(&c).unwrap().len(), 5);
    /// let d = Polygon::from_grid_points(&[[2, 0, 0], [3, 0, 0], [3, 3, 0], [2, 2, 0]], 4).unwrap();
    /// assert!(a.merge(&d).is_none()); // a reflex corner at (2, 2, 0)
    /// ```
    pub fn merge(&self, other: &Polygon) -> Option<Polygon> {
        if self.support != other.support {
            return None;
        }
        let (n, m) = (self.verts.len(), other.verts.len());
        for i in 0..n {
            let (u, v) = (&self.verts[i], &self.verts[(i + 1) % n]);
            for j in 0..m {
                if other.verts[j].same_point(v) && other.verts[(j + 1) % m].same_point(u) {
                    return self.merge_at(other, i, j);
                }
            }
        }
        None
    }

    /// [`Polygon::merge`] along this polygon's edge `i` (`u → v`) and
    /// `other`'s edge `j` (`v → u`).
    fn merge_at(&self, other: &Polygon, i: usize, j: usize) -> Option<Polygon> {
        use crate::kernel::Side::{Front, On};
        let (n, m) = (self.verts.len(), other.verts.len());
        // at u: this polygon's edge into u, against other's vertex after u
        let at_u = other.verts[(j + 2) % m].classify(&self.edges[(i + n - 1) % n]);
        // at v: other's edge into v, against this polygon's vertex after v
        let at_v = self.verts[(i + 2) % n].classify(&other.edges[(j + m - 1) % m]);
        if at_u == Front || at_v == Front {
            return None;
        }
        let mut out = Builder::new(self.support, self.tag);
        // this polygon from v round to u, then other from u round to v;
        // each vertex with its outgoing edge plane
        for t in 1..n {
            let k = (i + t) % n;
            if t == 1 && at_v == On {
                continue; // v lies between two parts of one straight edge
            }
            out.push(self.verts[k].clone(), self.edges[k]);
        }
        if at_u != On {
            out.push(self.verts[i].clone(), other.edges[(j + 1) % m]);
        }
        for t in 2..m {
            let k = (j + t) % m;
            out.push(other.verts[k].clone(), other.edges[k]);
        }
        Some(out.finish())
    }

    /// Checks the representation invariants exactly: every vertex lies on
    /// the support plane and on its two edge planes, and strictly behind
    /// every other edge plane (strict convexity).
    pub fn sanity_check(&self) -> Result<(), SanityError> {
        check_convex(self)
    }
}

impl ConvexParts for Polygon {
    fn vertex_count(&self) -> usize {
        self.verts.len()
    }
    fn edge_count(&self) -> usize {
        self.edges.len()
    }
    fn support_side(&self, i: usize) -> crate::kernel::Side {
        self.verts[i].classify(&self.support)
    }
    fn edge_side(&self, i: usize, j: usize) -> crate::kernel::Side {
        self.verts[i].classify(&self.edges[j])
    }
    fn edge_is_support(&self, j: usize) -> bool {
        self.edges[j].is_coincident(&self.support)
    }
}

/// The two pieces of a convex loop cut by a plane, from the exact side of
/// each vertex: the combinatorial part of every split in the workspace,
/// whatever the vertex type `V` (an exact point, or an index into an
/// arena) and edge type `E` (a plane, or a reference to one).
///
/// `verts[i]` lies between `edges[i - 1]` and `edges[i]`; `sides` holds
/// each vertex's side of the cutting plane, with at least one `Front` and
/// one `Back`. The pieces come out through `front` and `back` as (vertex,
/// outgoing edge) pairs in loop order: vertices on the plane go to both
/// pieces; each crossing edge `i` gets one new vertex, `crossing(i)`,
/// called once and given to both pieces; the front piece's cut edge is
/// `cut_front` (the cutting plane flipped, so that the piece lies behind
/// it) and the back piece's `cut_back`.
#[allow(clippy::too_many_arguments)]
pub fn split_loop<V: Clone, E: Clone>(
    verts: &[V],
    edges: &[E],
    sides: &[crate::kernel::Side],
    cut_front: E,
    cut_back: E,
    mut crossing: impl FnMut(usize) -> V,
    mut front: impl FnMut(V, E),
    mut back: impl FnMut(V, E),
) {
    use crate::kernel::Side::{Back, Front, On};
    let k = verts.len();
    for i in 0..k {
        let j = if i + 1 == k { 0 } else { i + 1 };
        let (vi, ei) = (&verts[i], &edges[i]);
        match (sides[i], sides[j]) {
            (Front, Back) => {
                let x = crossing(i);
                front(vi.clone(), ei.clone());
                front(x.clone(), cut_front.clone());
                back(x, ei.clone());
            }
            (Back, Front) => {
                let x = crossing(i);
                back(vi.clone(), ei.clone());
                back(x.clone(), cut_back.clone());
                front(x, ei.clone());
            }
            (Front, _) => front(vi.clone(), ei.clone()),
            (Back, _) => back(vi.clone(), ei.clone()),
            (On, Back) => {
                front(vi.clone(), cut_front.clone());
                back(vi.clone(), ei.clone());
            }
            (On, _) => {
                front(vi.clone(), ei.clone());
                back(vi.clone(), cut_back.clone());
            }
        }
    }
}

struct Builder {
    support: Plane,
    tag: u32,
    edges: SmallVec<[Plane; 4]>,
    verts: SmallVec<[Point; 4]>,
}

impl Builder {
    fn new(support: Plane, tag: u32) -> Builder {
        Builder {
            support,
            tag,
            edges: SmallVec::new(),
            verts: SmallVec::new(),
        }
    }
    fn push(&mut self, v: Point, outgoing: Plane) {
        self.verts.push(v);
        self.edges.push(outgoing);
    }
    fn finish(self) -> Polygon {
        debug_assert!(
            self.verts.len() >= 3,
            "a split piece has at least 3 vertices"
        );
        Polygon {
            support: self.support,
            edges: self.edges,
            verts: self.verts,
            tag: self.tag,
        }
    }
}

/// Makes equal implicit vertices of `polys` one shared allocation: each
/// is replaced by the first equal one (in the order of the polygons and
/// their vertices), but for rare pairs whose approximate keys differ (see
/// `point_key`).
///
/// Two pieces cut at the same time along a shared edge compute the same
/// new vertex each for itself: the point is exact and equal, but held
/// twice (an implicit point takes about 190 bytes). Points are compared
/// exactly, so no vertex moves. The work is parallel: the corners are
/// sharded by key.
pub fn share_points(polys: &mut [&mut Polygon]) {
    let keys: Vec<SmallVec<[(u64, u32); 6]>> = crate::par::map_slice(polys, |p| {
        p.verts
            .iter()
            .enumerate()
            .filter_map(|(v, pt)| match pt {
                Point::Implicit(i) => Some((point_key(i), v as u32)),
                Point::Grid(_) => None,
            })
            .collect()
    });
    // the corners by shard of their keys, each shard in order
    let shards = 4 * rayon::current_num_threads().max(1);
    let mut by_shard: Vec<Vec<(u64, u32, u32)>> = vec![Vec::new(); shards];
    for (p, ks) in keys.iter().enumerate() {
        for &(k, v) in ks {
            by_shard[(k >> 40) as usize % shards].push((k, p as u32, v));
        }
    }
    drop(keys);
    let view: &[&mut Polygon] = polys;
    // (corner, the first equal corner), shard by shard
    let moves: Vec<Vec<(u32, u32, u32, u32)>> = crate::par::map_slice(&by_shard, |corners| {
        let mut firsts: rustc_hash::FxHashMap<u64, SmallVec<[(u32, u32); 1]>> = Default::default();
        let mut moves = Vec::new();
        for &(k, p, v) in corners {
            let Some(i) = implicit_at(view, p, v) else {
                continue;
            };
            let bucket = firsts.entry(k).or_default();
            let first = bucket.iter().find_map(|&(q, w)| {
                implicit_at(view, q, w)
                    .filter(|j| j.same_point(i))
                    .map(|j| (q, w, j))
            });
            match first {
                Some((q, w, j)) => {
                    if !Arc::ptr_eq(j, i) {
                        moves.push((p, v, q, w));
                    }
                }
                None => bucket.push((p, v)),
            }
        }
        moves
    });
    // a first corner is never moved, so the order does not matter
    for (p, v, q, w) in moves.into_iter().flatten() {
        let first = implicit_at(polys, q, w).cloned();
        if let (Some(first), Some(Point::Implicit(i))) =
            (first, polys[p as usize].verts.get_mut(v as usize))
        {
            *i = first;
        }
    }
}

/// The implicit vertex `v` of polygon `p`, if it is one.
fn implicit_at<'a>(polys: &'a [&mut Polygon], p: u32, v: u32) -> Option<&'a Arc<Implicit>> {
    match polys.get(p as usize)?.verts.get(v as usize)? {
        Point::Implicit(i) => Some(i),
        Point::Grid(_) => None,
    }
}

/// [`Point::approx_key`] of an implicit point.
fn point_key(i: &Implicit) -> u64 {
    approx_key(i.approx_f64())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::grid_loop::GridLoop;

    /// A point of the plane `(x, y)` on one of a few integer planes of
    /// space (each projected along a different axis, either way round).
    fn embed(plane: usize, (x, y): (i32, i32)) -> GridPoint {
        match plane % 4 {
            0 => [x, y, 0],
            1 => [y, 3, x],
            2 => [x, y, x + 2 * y],
            _ => [-2 * y + x, y, -x],
        }
    }

    /// Regular polygons (convex), the same going round twice (turning one
    /// way all along, not convex), with two corners swapped, with a corner
    /// pushed in or out, each on a few planes of space and either way
    /// round: convex by turns exactly when convex pair by pair.
    #[test]
    fn convex_by_turns_as_pair_by_pair() {
        let mut seed = 0x3c6e_f372_fe94_f82bu64;
        let mut next = |m: u64| crate::xorshift(&mut seed) % m;
        let (mut convex, mut not) = (0, 0);
        for round in 0..800 {
            let n = LINKED + next(200) as usize;
            let turns = if round % 5 == 1 { 2.0 } else { 1.0 };
            let r = 1e5 + next(1_000) as f64;
            let mut xy: Vec<(i32, i32)> = (0..n)
                .map(|k| {
                    let a = turns * std::f64::consts::TAU * k as f64 / n as f64;
                    ((r * a.cos()).round() as i32, (r * a.sin()).round() as i32)
                })
                .collect();
            let k = next(n as u64 - 1) as usize;
            match round % 5 {
                2 => xy.swap(k, k + 1),
                3 => xy[k] = (xy[k].0 / 2, xy[k].1 / 2),
                4 => xy[k] = (xy[k].0 + xy[k].0 / 500, xy[k].1 + xy[k].1 / 500),
                _ => {}
            }
            if round % 2 == 1 {
                xy.reverse();
            }
            let mut v: GridLoop = xy.iter().map(|&p| embed(round / 2, p)).collect();
            v = dedupe_cyclic(&v);
            let Ok(support) = support_plane(&v) else {
                continue;
            };
            remove_collinear(&mut v);
            if v.len() < LINKED {
                continue;
            }
            let g = GridPolygon {
                support,
                verts: v.into_iter().collect(),
            };
            let pairwise = g.convex_pairwise();
            assert_eq!(g.convex_by_turns(), pairwise, "round {round}");
            if pairwise {
                convex += 1;
            } else {
                not += 1;
            }
        }
        assert!(convex > 100 && not > 200, "{convex} convex, {not} not");
    }

    proptest::proptest! {
        /// A triangle of three distinct corners takes a short path; it
        /// gives what the general path gives the same corners (reached
        /// through a repeated corner, which the general path drops):
        /// plane, orientation, corners, and the defect of a degenerate one.
        #[test]
        fn a_triangle_s_short_path_gives_the_general_result(
            c in proptest::array::uniform9(-6i32..6),
            big in proptest::prelude::any::<bool>(),
        ) {
            let k = if big { 1 << 25 } else { 1 };
            let p = |i: usize| [c[i] * k, c[i + 1] * k + 1, c[i + 2] * k];
            let (a, b, d) = (p(0), p(3), p(6));
            let short = GridPolygon::from_grid_points(&[a, b, d]);
            let general = GridPolygon::from_grid_points(&[a, b, d, d]);
            match (&short, &general) {
                (Ok(s), Ok(g)) => {
                    proptest::prop_assert_eq!(s.support(), g.support());
                    proptest::prop_assert_eq!(s.vertices(), g.vertices());
                }
                (Err(s), Err(g)) => proptest::prop_assert_eq!(s, g),
                _ => proptest::prop_assert!(false, "{:?} against {:?}", short, general),
            }
        }
    }

    /// Clipping a grid polygon from its corners gives what clipping its
    /// full polygon plane by plane gives: the same points, edge planes,
    /// support and tag, and nothing where that leaves nothing. Triangles
    /// and quads, large and small, by cell walls (half steps, holding no
    /// grid point) and by planes through grid points (corners on them).
    #[test]
    fn clipping_from_the_corners_gives_the_clipped_polygon() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = |m: i32| (crate::xorshift(&mut seed) >> 33) as i32 % m;
        let (mut kept, mut gone, mut cut) = (0, 0, 0);
        for round in 0..8000 {
            let k = if round % 2 == 0 { 1 } else { 1 << 20 };
            let o = [0; 3].map(|_| next(9) * k);
            let pt = |x: i32, y: i32, z: i32| [o[0] + x * k, o[1] + y * k, o[2] + z * k];
            let corners: Vec<GridPoint> = if round % 3 == 0 {
                // a quad in a tilted plane
                let (a, b) = (1 + next(6), 1 + next(6));
                vec![pt(0, 0, 0), pt(a, 0, 1), pt(a, b, 2), pt(0, b, 1)]
            } else {
                let r = |_| pt(next(9), next(9), next(9));
                (0..3).map(r).collect()
            };
            let Ok(g) = GridPolygon::from_grid_points(&corners) else {
                continue;
            };
            let planes: Vec<Plane> = (0..1 + next(4))
                .filter_map(|_| {
                    if next(2) == 0 {
                        // a wall: sign · 2 x_axis − (2c ± 1)
                        let axis = next(3) as usize;
                        let sign = if next(2) == 0 { 1 } else { -1 };
                        let mut n = [0i64; 3];
                        n[axis] = 2 * sign;
                        let c = o[axis] as i128 + (next(9) * k) as i128;
                        Plane::new(n, -(sign as i128) * (2 * c + 1))
                    } else {
                        // through a corner, in a random direction
                        let n = [0; 3].map(|_| (next(7) - 3) as i64);
                        let at = corners[next(corners.len() as i32) as usize];
                        Plane::new(
                            n,
                            -(0..3).map(|i| n[i] as i128 * at[i] as i128).sum::<i128>(),
                        )
                    }
                })
                .collect();
            let mut reference = Some(g.to_polygon(7));
            for plane in &planes {
                if let Some(p) = &mut reference
                    && !p.clip(plane, crate::kernel::Side::Back)
                {
                    reference = None;
                }
            }
            let got = g.clipped(&planes, 7);
            match (&reference, &got) {
                (None, None) => gone += 1,
                (Some(r), Some(p)) => {
                    assert_eq!(p.support(), r.support());
                    assert_eq!(p.edge_planes(), r.edge_planes(), "{corners:?} {planes:?}");
                    assert_eq!(p.len(), r.len());
                    for (a, b) in p.vertices().iter().zip(r.vertices()) {
                        assert!(a.same_point(b), "{corners:?} {planes:?}");
                    }
                    assert_eq!(p.tag(), 7);
                    if p.len() != g.vertices().len()
                        || p.vertices().iter().any(|v| matches!(v, Point::Implicit(_)))
                    {
                        cut += 1;
                    } else {
                        kept += 1;
                    }
                }
                _ => panic!("{corners:?} {planes:?}: {reference:?} against {got:?}"),
            }
        }
        assert!(
            kept > 300 && gone > 300 && cut > 2000,
            "{kept} {gone} {cut}"
        );
    }

    /// A grid polygon's computed edge planes are exact edge planes of it
    /// (each holds its edge's ends, every other corner strictly behind),
    /// the ones its full polygon stores, and flipping either form gives the
    /// same polygon; the defects are the full form's.
    #[test]
    fn grid_polygons_compute_the_stored_edge_planes() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = |m: i32| (crate::xorshift(&mut seed) % (2 * m as u64 + 1)) as i32 - m;
        let same = |p: &Polygon, q: &Polygon| {
            p.support() == q.support()
                && p.edge_planes() == q.edge_planes()
                && p.vertices().len() == q.vertices().len()
                && p.vertices()
                    .iter()
                    .zip(q.vertices())
                    .all(|(a, b)| a.same_point(b))
        };
        let mut loops: Vec<Vec<GridPoint>> = Vec::new();
        for _ in 0..400 {
            let m = if loops.len().is_multiple_of(2) {
                9
            } else {
                1 << 20
            };
            loops.push((0..3).map(|_| [next(m), next(m), next(m)]).collect());
        }
        // squares and pentagons in tilted planes, some with a collinear
        // corner, and a bow tie
        for t in 0..20 {
            let (u, v) = ([1, 0, t], [0, 1, 2 - t]);
            let at = |a: i32, b: i32| {
                [
                    a * u[0] + b * v[0],
                    a * u[1] + b * v[1],
                    a * u[2] + b * v[2],
                ]
            };
            loops.push(vec![at(0, 0), at(3, 0), at(3, 3), at(0, 3)]);
            loops.push(vec![at(0, 0), at(2, 0), at(4, 0), at(4, 4), at(0, 4)]);
            loops.push(vec![at(0, 0), at(4, 0), at(5, 2), at(2, 5), at(0, 3)]);
            loops.push(vec![at(0, 0), at(2, 2), at(2, 0), at(0, 2)]);
        }
        let mut made = 0;
        for l in &loops {
            let g = GridPolygon::from_grid_points(l);
            let p = Polygon::from_grid_points(l, 3);
            let (g, p) = match (g, p) {
                (Ok(g), Ok(p)) => (g, p),
                (Err(a), Err(b)) => {
                    assert_eq!(a, b);
                    continue;
                }
                (g, p) => panic!("{l:?}: {:?} against {:?}", g.err(), p.err()),
            };
            made += 1;
            let full = g.to_polygon(3);
            assert!(same(&full, &p), "{l:?}");
            assert!(full.sanity_check().is_ok());
            let k = g.len();
            for i in 0..k {
                let e = g.edge_plane(i);
                assert_eq!(e, ConvexFace::edge_plane(&p, i));
                for (j, &c) in g.vertices().iter().enumerate() {
                    let want = if j == i || j == (i + 1) % k {
                        Side::On
                    } else {
                        Side::Back
                    };
                    assert_eq!(e.classify_grid(c), want, "{l:?} edge {i} corner {j}");
                }
            }
            assert!(same(&g.flipped().to_polygon(3), &p.flipped()), "{l:?}");
            assert_eq!(full.tag(), 3);
        }
        assert!(made > 300, "only {made} polygons made");
    }

    #[test]
    fn equal_new_vertices_are_shared_and_none_moves() {
        use std::sync::Arc;
        // two squares sharing the edge x = 4, z = 0, cut by 2y + z = 3:
        // each cut makes the point (4, 1.5, 0) for itself
        let floor =
            Polygon::from_grid_points(&[[0, 0, 0], [4, 0, 0], [4, 4, 0], [0, 4, 0]], 0).unwrap();
        let wall =
            Polygon::from_grid_points(&[[4, 0, 0], [4, 4, 0], [4, 4, 4], [4, 0, 4]], 0).unwrap();
        let cut = Plane::new([0, 2, 1], -3).unwrap();
        let mut pieces = Vec::new();
        for p in [floor, wall] {
            match p.split(&cut) {
                Split::Spanning { front, back } => pieces.extend([front, back]),
                _ => panic!("the plane crosses both squares"),
            }
        }
        let implicit = |ps: &[Polygon]| -> Vec<Arc<Implicit>> {
            ps.iter()
                .flat_map(|p| p.vertices())
                .filter_map(|v| match v {
                    Point::Implicit(i) => Some(i.clone()),
                    Point::Grid(_) => None,
                })
                .collect()
        };
        let distinct_allocations = |is: &[Arc<Implicit>]| {
            let mut ptrs: Vec<usize> = is.iter().map(|i| Arc::as_ptr(i) as usize).collect();
            ptrs.sort_unstable();
            ptrs.dedup();
            ptrs.len()
        };
        let distinct_points = |is: &[Arc<Implicit>]| {
            let mut seen: Vec<&Arc<Implicit>> = Vec::new();
            for i in is {
                if !seen.iter().any(|s| s.same_point(i)) {
                    seen.push(i);
                }
            }
            seen.len()
        };
        let before = implicit(&pieces);
        assert!(distinct_allocations(&before) > distinct_points(&before));
        let originals: Vec<Vec<Point>> = pieces.iter().map(|p| p.vertices().to_vec()).collect();
        let mut refs: Vec<&mut Polygon> = pieces.iter_mut().collect();
        share_points(&mut refs);
        let after = implicit(&pieces);
        assert_eq!(distinct_allocations(&after), distinct_points(&after));
        assert_eq!(distinct_points(&after), distinct_points(&before));
        for (p, o) in pieces.iter().zip(&originals) {
            assert_eq!(p.vertices().len(), o.len());
            assert!(p.vertices().iter().zip(o).all(|(v, w)| v.same_point(w)));
        }
    }
    use crate::kernel::Side;

    fn square() -> Polygon {
        Polygon::from_grid_points(&[[0, 0, 0], [4, 0, 0], [4, 4, 0], [0, 4, 0]], 1).unwrap()
    }

    #[test]
    fn split_through_vertices_shares_them() {
        let diag = Plane::new([1, -1, 0], 0).unwrap();
        match square().split(&diag) {
            Split::Spanning { front, back } => {
                assert_eq!(front.len(), 3);
                assert_eq!(back.len(), 3);
                front.sanity_check().unwrap();
                back.sanity_check().unwrap();
                assert!(front.vertices().iter().all(|v| matches!(v, Point::Grid(_))));
            }
            other => panic!("expected a span, got {other:?}"),
        }
    }

    #[test]
    fn split_across_edges_creates_shared_implicit_vertices() {
        let cut = Plane::new([1, 0, 0], -1).unwrap(); // x = 1
        let Split::Spanning { front, back } = square().split(&cut) else {
            panic!("expected a span")
        };
        front.sanity_check().unwrap();
        back.sanity_check().unwrap();
        let shared: Vec<_> = front
            .vertices()
            .iter()
            .filter(|v| back.vertices().iter().any(|w| w.same_point(v)))
            .collect();
        assert_eq!(shared.len(), 2);
        assert_eq!(front.tag(), 1);
    }

    #[test]
    fn clip_keeps_the_same_piece_as_split() {
        let planes = [
            Plane::new([1, 0, 0], -1).unwrap(),
            Plane::new([1, -1, 0], 0).unwrap(),
            Plane::new([3, 1, 0], -7).unwrap(),
            Plane::new([1, 0, 0], 0).unwrap(),
        ];
        for plane in planes {
            for keep in [Side::Front, Side::Back] {
                let mut c = square();
                let kept = c.clip(&plane, keep);
                let expected = match (square().split(&plane), keep) {
                    (Split::Front(p), Side::Front) | (Split::Back(p), Side::Back) => Some(p),
                    (Split::Spanning { front, .. }, Side::Front) => Some(front),
                    (Split::Spanning { back, .. }, Side::Back) => Some(back),
                    _ => None,
                };
                assert_eq!(kept, expected.is_some());
                if let Some(e) = expected {
                    c.sanity_check().unwrap();
                    assert_eq!(c.len(), e.len());
                    for (a, b) in c.vertices().iter().zip(e.vertices()) {
                        assert!(a.same_point(b));
                    }
                    assert_eq!(c.edge_planes(), e.edge_planes());
                }
            }
        }
    }

    #[test]
    fn touching_and_coplanar() {
        let sq = square();
        let touch = Plane::new([1, 0, 0], 0).unwrap(); // x = 0, an edge
        assert_eq!(sq.classify(&touch), PolygonSide::Front);
        let z = Plane::new([0, 0, 1], 0).unwrap();
        assert_eq!(
            sq.classify(&z),
            PolygonSide::Coplanar {
                same_orientation: true
            }
        );
        assert_eq!(
            sq.classify(&z.flip()),
            PolygonSide::Coplanar {
                same_orientation: false
            }
        );
    }

    /// The same points in the same cyclic order.
    fn same_loop(a: &Polygon, b: &Polygon) -> bool {
        let (x, y) = (a.vertices(), b.vertices());
        let n = x.len();
        n == y.len() && (0..n).any(|r| (0..n).all(|i| x[i].same_point(&y[(i + r) % n])))
    }

    #[test]
    fn the_two_parts_of_a_split_merge_back_into_the_polygon() {
        let polys = [
            Polygon::from_grid_points(&[[0, 0, 0], [9, 0, 0], [9, 7, 0], [0, 7, 0]], 5).unwrap(),
            Polygon::from_grid_points(&[[1, 2, 3], [11, -4, 6], [5, 9, -2]], 5).unwrap(),
            Polygon::from_grid_points(
                &[[0, 0, 0], [6, 0, 6], [8, 5, 3], [3, 9, -6], [-2, 4, -6]],
                5,
            )
            .unwrap(),
        ];
        let mut splits = 0;
        for p in &polys {
            for a in -3i64..=3 {
                for b in -3i64..=3 {
                    for c in [-1i64, 0, 2] {
                        for d in (-20i128..=20).step_by(3) {
                            let Some(plane) = Plane::new([a, b, c], d) else {
                                continue;
                            };
                            let Parts::Split { front, back } = p.parts(&plane) else {
                                continue;
                            };
                            splits += 1;
                            for m in [front.merge(&back), back.merge(&front)] {
                                let m = m.expect("the parts share the cut edge");
                                assert!(m.sanity_check().is_ok());
                                assert!(same_loop(&m, p), "{m:?} is not {p:?}");
                                assert_eq!(m.edge_planes().len(), m.len());
                            }
                        }
                    }
                }
            }
        }
        assert!(splits > 500, "{splits} splits");
    }

    #[test]
    fn merges_need_a_whole_shared_edge_a_convex_union_and_one_plane() {
        let g = |p: &[GridPoint]| Polygon::from_grid_points(p, 0).unwrap();
        let a = g(&[[0, 0, 0], [4, 0, 0], [4, 4, 0], [0, 4, 0]]);
        // a convex corner at both ends: a pentagon, every vertex kept
        let roof = g(&[[0, 4, 0], [4, 4, 0], [2, 6, 0]]);
        let house = a.merge(&roof).unwrap();
        assert_eq!(house.len(), 5);
        assert!(house.sanity_check().is_ok());
        // only part of the edge shared (a T-junction): not merged
        let half = g(&[[0, 4, 0], [2, 4, 0], [1, 6, 0]]);
        assert!(a.merge(&half).is_none());
        // the same edge in the same direction: overlapping, not merged
        let under = g(&[[4, 4, 0], [0, 4, 0], [2, 2, 0]]);
        assert!(a.merge(&under).is_none());
        // another plane through the shared edge: not merged
        let fold = g(&[[0, 4, 0], [4, 4, 0], [2, 6, 1]]);
        assert!(a.merge(&fold).is_none());
        // a reflex corner at one end
        let wing = g(&[[4, 0, 0], [8, -1, 0], [4, 4, 0]]);
        assert!(a.merge(&wing).is_none());
        // straight at one end only
        let side = g(&[[4, 0, 0], [8, 0, 0], [4, 4, 0]]);
        let m = a.merge(&side).unwrap();
        assert_eq!(m.len(), 4);
        assert!(m.sanity_check().is_ok());
    }

    #[test]
    fn defects_are_named() {
        let e = |p: &[GridPoint]| Polygon::from_grid_points(p, 0).unwrap_err();
        assert_eq!(
            e(&[[0, 0, 0], [1, 0, 0], [0, 0, 0]]),
            FaceDefect::TooFewVertices
        );
        assert_eq!(e(&[[0, 0, 0], [1, 0, 0], [2, 0, 0]]), FaceDefect::ZeroArea);
        assert_eq!(
            e(&[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 1]]),
            FaceDefect::NonPlanar
        );
        assert_eq!(
            e(&[[0, 0, 0], [4, 0, 0], [4, 4, 0], [2, 1, 0], [0, 4, 0]]),
            FaceDefect::NonConvex
        );
    }
}
