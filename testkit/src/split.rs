//! The split driver: a convex polygon cut by planes.

#[allow(unused_imports)]
use super::*;

/// A convex polygon and cutting planes, each through three grid points.
///
/// [`SplitInput::check`] splits the polygon by the first plane, every
/// piece by the second, and so on.
#[derive(Clone, PartialEq, Eq)]
pub struct SplitInput {
    /// The polygon's vertices, counter-clockwise (it may be invalid: then
    /// the check only confirms that [`Polygon::from_grid_points`] refuses
    /// it without panicking).
    pub polygon: Vec<GridPoint>,
    /// Cutting planes, each given by three points (collinear ones are
    /// skipped).
    pub cuts: Vec<[GridPoint; 3]>,
}

impl Debug for SplitInput {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SplitInput")
            .field("polygon", &VecLit(&self.polygon))
            .field("cuts", &VecLit(&self.cuts))
            .finish()
    }
}

/// What a [`SplitInput::check`] exercised.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SplitReport {
    /// The polygon was valid.
    pub valid: bool,
    /// Splits that cut a piece in two.
    pub spanning: usize,
    /// Splits that left a piece on one side (possibly touching the plane).
    pub one_sided: usize,
    /// Splits with the piece in the cutting plane.
    pub coplanar: usize,
    /// Splits where the plane passed through a vertex of a spanning piece.
    pub through_vertex: usize,
    /// Pieces at the end.
    pub pieces: usize,
}

impl SplitInput {
    /// Decodes bytes (any bytes) into an input.
    ///
    /// ```
    /// use bsp_testkit::SplitInput;
    /// let i = SplitInput::decode(&[]);
    /// assert_eq!(i.polygon.len(), 3);
    /// assert_eq!(i.cuts.len(), 1);
    /// ```
    pub fn decode(data: &[u8]) -> SplitInput {
        let mut b = Bytes { data };
        let mut pool: Vec<GridPoint> = Vec::new();
        let polygon = match b.u8() % 4 {
            0 => {
                for _ in 0..3 {
                    let p = b.point(&pool);
                    pool.push(p);
                }
                pool.clone()
            }
            1 => {
                let n = 3 + b.below(6);
                for _ in 0..n {
                    let p = b.point(&pool);
                    pool.push(p);
                }
                pool.clone()
            }
            2 => template_polygon(&mut b, &pool).unwrap_or_default(),
            _ => corner_polygon(&mut b),
        };
        pool.clone_from(&polygon);
        let n = 1 + b.below(4);
        let cuts = (0..n)
            .map(|_| decode_cut(&mut b, &polygon, &mut pool))
            .collect();
        SplitInput { polygon, cuts }
    }

    /// Bytes that [`SplitInput::decode`] turns back into `self` (for
    /// polygons of 3 to 8 vertices and 1 to 4 cuts, coordinates within the
    /// grid).
    ///
    /// ```
    /// use bsp_testkit::SplitInput;
    /// let i = SplitInput { polygon: vec![[0, 0, 0], [9, 0, 0], [0, 9, 0]], cuts: vec![[[1, 0, 0], [1, 1, 0], [1, 0, 1]]] };
    /// assert_eq!(SplitInput::decode(&i.encode()), i);
    /// ```
    pub fn encode(&self) -> Vec<u8> {
        let mut out = vec![1, (self.polygon.len().clamp(3, 8) - 3) as u8];
        for p in &self.polygon {
            enc_point(&mut out, *p);
        }
        out.push((self.cuts.len().clamp(1, 4) - 1) as u8);
        for c in &self.cuts {
            out.push(0);
            for p in c {
                enc_point(&mut out, *p);
            }
        }
        out
    }

    /// Runs the splits and checks every result exactly:
    ///
    /// - pieces pass [`Polygon::sanity_check`] and keep the support plane
    ///   and tag;
    /// - the kind of split matches the exact sides of the vertices;
    /// - a front piece has its vertices in front of or on the plane, a
    ///   back piece behind or on, and the two share exactly two vertices,
    ///   both on the plane; every other vertex is an original one, on the
    ///   side it came from, and every original vertex is kept;
    /// - the cut edge is the plane (flipped for the front piece) and every
    ///   other edge plane an original one;
    /// - every piece lies inside the original polygon (on its support,
    ///   behind or on each edge plane), and the areas add up;
    /// - the floating-point filter never contradicts the exact path.
    pub fn check(&self) -> SplitReport {
        let mut report = SplitReport::default();
        if self.polygon.iter().flatten().any(|c| c.abs() > MAX_COORD) {
            return report;
        }
        let root = match Polygon::from_grid_points(&self.polygon, 7) {
            Ok(p) => p,
            Err(_) => return report,
        };
        report.valid = true;
        if let Err(e) = root.sanity_check() {
            fail(
                self,
                format_args!("from_grid_points built an invalid polygon: {e}"),
            );
        }
        for (i, v) in root.vertices().iter().enumerate() {
            ensure!(
                self,
                v.as_grid().is_some_and(|g| self.polygon.contains(&g)),
                "vertex {i} ({v:?}) of the built polygon is not an input point"
            );
        }
        let mut pieces = vec![root.clone()];
        for (ci, c) in self.cuts.iter().enumerate() {
            if c.iter().flatten().any(|c| c.abs() > MAX_COORD) {
                continue;
            }
            let Ok(plane) = Plane::through(c[0], c[1], c[2]) else {
                continue;
            };
            let mut next = Vec::with_capacity(2 * pieces.len());
            for (pi, p) in pieces.into_iter().enumerate() {
                let parent = p.clone();
                let what = format!("cut {ci} of piece {pi}");
                match p.split(&plane) {
                    Split::Front(q) => {
                        self.check_one_sided(&parent, &plane, &q, PolygonSide::Front, &what);
                        report.one_sided += 1;
                        next.push(q);
                    }
                    Split::Back(q) => {
                        self.check_one_sided(&parent, &plane, &q, PolygonSide::Back, &what);
                        report.one_sided += 1;
                        next.push(q);
                    }
                    Split::Coplanar {
                        polygon,
                        same_orientation,
                    } => {
                        let kind = PolygonSide::Coplanar { same_orientation };
                        self.check_one_sided(&parent, &plane, &polygon, kind, &what);
                        report.coplanar += 1;
                        next.push(polygon);
                    }
                    Split::Spanning { front, back } => {
                        if self.check_spanning(&parent, &plane, &front, &back, &what) {
                            report.through_vertex += 1;
                        }
                        report.spanning += 1;
                        next.push(front);
                        next.push(back);
                    }
                }
            }
            pieces = next;
            let refs: Vec<&Polygon> = pieces.iter().collect();
            check_cover(self, &root, &refs, &format!("after cut {ci}"));
        }
        report.pieces = pieces.len();
        report
    }

    /// The kind of split `plane` must cause on `p`, from the exact sides of
    /// its vertices.
    pub(crate) fn expected_side(
        &self,
        p: &Polygon,
        plane: &Plane,
        what: &str,
    ) -> (PolygonSide, Vec<Side>) {
        let sides: Vec<Side> = p
            .vertices()
            .iter()
            .map(|v| check_point_side(self, v, plane))
            .collect();
        let kind = if p.support() == plane {
            PolygonSide::Coplanar {
                same_orientation: true,
            }
        } else if *p.support() == plane.flip() {
            PolygonSide::Coplanar {
                same_orientation: false,
            }
        } else {
            let front = sides.contains(&Side::Front);
            let back = sides.contains(&Side::Back);
            match (front, back) {
                (true, true) => PolygonSide::Spanning,
                (true, false) => PolygonSide::Front,
                (false, true) => PolygonSide::Back,
                (false, false) => fail(
                    self,
                    format_args!("{what}: every vertex is on {plane:?} but it is not the support"),
                ),
            }
        };
        let got = p.classify(plane);
        ensure!(
            self,
            got == kind,
            "{what}: Polygon::classify says {got:?}, the vertex sides {sides:?} say {kind:?}"
        );
        (kind, sides)
    }

    pub(crate) fn check_one_sided(
        &self,
        parent: &Polygon,
        plane: &Plane,
        got: &Polygon,
        kind: PolygonSide,
        what: &str,
    ) {
        let (expected, _) = self.expected_side(parent, plane, what);
        ensure!(
            self,
            expected == kind,
            "{what}: split returned {kind:?}, expected {expected:?}"
        );
        ensure!(
            self,
            same_polygon(parent, got),
            "{what}: a {kind:?} split changed the polygon"
        );
    }

    /// Checks a spanning split; returns whether the plane passed through a
    /// vertex.
    pub(crate) fn check_spanning(
        &self,
        parent: &Polygon,
        plane: &Plane,
        front: &Polygon,
        back: &Polygon,
        what: &str,
    ) -> bool {
        let (expected, sides) = self.expected_side(parent, plane, what);
        ensure!(
            self,
            expected == PolygonSide::Spanning,
            "{what}: split returned Spanning, expected {expected:?}"
        );
        for (name, piece, keep, cut) in [
            ("front", front, Side::Front, plane.flip()),
            ("back", back, Side::Back, *plane),
        ] {
            if let Err(e) = piece.sanity_check() {
                fail(self, format_args!("{what}: {name} piece is invalid: {e}"));
            }
            ensure!(
                self,
                piece.support() == parent.support() && piece.tag() == parent.tag(),
                "{what}: {name} piece lost its support plane or tag"
            );
            let wrong = if keep == Side::Front {
                Side::Back
            } else {
                Side::Front
            };
            let vs: Vec<Side> = piece
                .vertices()
                .iter()
                .map(|v| check_point_side(self, v, plane))
                .collect();
            ensure!(
                self,
                !vs.contains(&wrong) && vs.contains(&keep),
                "{what}: {name} piece has vertex sides {vs:?}"
            );
            let cuts = piece.edge_planes().iter().filter(|e| **e == cut).count();
            ensure!(
                self,
                cuts == 1,
                "{what}: {name} piece has the cut plane as {cuts} edges"
            );
            for (j, e) in piece.edge_planes().iter().enumerate() {
                ensure!(
                    self,
                    *e == cut || parent.edge_planes().contains(e),
                    "{what}: {name} piece edge {j} ({e:?}) is neither the cut nor an original edge"
                );
            }
            // every vertex is an original one or lies on the plane
            for (k, (v, s)) in piece.vertices().iter().zip(&vs).enumerate() {
                let original = parent.vertices().iter().any(|w| w.same_point(v));
                ensure!(
                    self,
                    original || *s == Side::On,
                    "{what}: {name} vertex {k} ({v:?}) is new but off the cutting plane"
                );
            }
            // every original vertex on this side (or on the plane) is kept once
            for (k, (v, s)) in parent.vertices().iter().zip(&sides).enumerate() {
                let n = piece.vertices().iter().filter(|w| w.same_point(v)).count();
                let want = usize::from(*s != wrong);
                ensure!(
                    self,
                    n == want,
                    "{what}: original vertex {k} ({s:?}) appears {n} times in the {name} piece"
                );
            }
        }
        let shared: Vec<&Point> = front
            .vertices()
            .iter()
            .filter(|v| back.vertices().iter().any(|w| w.same_point(v)))
            .collect();
        ensure!(
            self,
            shared.len() == 2,
            "{what}: the pieces share {} vertices, not 2",
            shared.len()
        );
        for v in &shared {
            ensure!(
                self,
                check_point_side(self, v, plane) == Side::On,
                "{what}: shared vertex {v:?} is off the cutting plane"
            );
        }
        let on = sides.iter().filter(|s| **s == Side::On).count();
        ensure!(
            self,
            front.len() + back.len() == parent.len() + 4 - on,
            "{what}: pieces of {} and {} vertices from {} with {on} on the plane",
            front.len(),
            back.len(),
            parent.len()
        );
        check_cover(self, parent, &[front, back], what);
        on > 0
    }
}

/// A triangle or rectangle on the corners of the grid's cube, possibly
/// pulled inwards a little.
pub(crate) fn corner_polygon(b: &mut Bytes<'_>) -> Vec<GridPoint> {
    let corner = |i: usize| {
        [0, 1, 2].map(|k| {
            if i >> k & 1 == 1 {
                MAX_COORD
            } else {
                -MAX_COORD
            }
        })
    };
    let mut pts: Vec<GridPoint> = match b.u8() % 3 {
        0 => (0..3).map(|_| corner(b.below(8))).collect(),
        1 => {
            // a face of the cube
            let axis = b.below(3);
            let hi = b.u8() & 1 == 1;
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let c = |du: bool, dv: bool| {
                let mut i = 0;
                i |= usize::from(hi) << axis;
                i |= usize::from(du) << u;
                i |= usize::from(dv) << v;
                corner(i)
            };
            let q = vec![
                c(false, false),
                c(true, false),
                c(true, true),
                c(false, true),
            ];
            if hi { q } else { q.into_iter().rev().collect() }
        }
        _ => {
            // a diagonal rectangle, e.g. the plane y = z
            let axis = b.below(3);
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let c = |a: bool, d: bool| {
                corner(usize::from(a) << axis | usize::from(d) << u | usize::from(d) << v)
            };
            vec![
                c(false, false),
                c(true, false),
                c(true, true),
                c(false, true),
            ]
        }
    };
    for p in &mut pts {
        let pull = b.u8();
        if pull & 0xc0 == 0xc0 {
            let k = (pull % 3) as usize;
            p[k] -= p[k].signum() * (1 + (pull >> 2 & 7) as i32);
        }
    }
    pts
}

/// A cutting plane, biased to pass through the polygon.
pub(crate) fn decode_cut(
    b: &mut Bytes<'_>,
    verts: &[GridPoint],
    pool: &mut Vec<GridPoint>,
) -> [GridPoint; 3] {
    let mode = b.u8() % 4;
    if verts.is_empty() || mode == 0 {
        let p = [b.point(pool), b.point(pool), b.point(pool)];
        pool.extend(p);
        p
    } else {
        let axis = b.below(3);
        let along = |p: GridPoint| {
            let mut q = p;
            q[axis] = if p[axis] < MAX_COORD {
                p[axis] + 1
            } else {
                p[axis] - 1
            };
            q
        };
        let n = verts.len();
        let a = verts[b.below(n)];
        match mode {
            // through two vertices (a diagonal, an edge or a touching line)
            1 => [a, verts[b.below(n)], along(a)],
            // through a point near the middle, in a decoded direction
            2 => {
                let mut c = [0i64; 3];
                for v in verts {
                    for k in 0..3 {
                        c[k] += v[k] as i64;
                    }
                }
                let m = c.map(|s| clamp_coord(s.div_euclid(n as i64) + (b.u8() as i8 % 3) as i64));
                let d = b.vector();
                let other = [0, 1, 2].map(|k| clamp_coord(m[k] as i64 + d[k]));
                [m, other, along(m)]
            }
            // through a vertex and (near) the midpoint of an edge
            _ => {
                let i = b.below(n);
                let (p, q) = (verts[i], verts[(i + 1) % n]);
                let mid = [0, 1, 2].map(|k| clamp_coord((p[k] as i64 + q[k] as i64).div_euclid(2)));
                [a, mid, along(a)]
            }
        }
    }
}
