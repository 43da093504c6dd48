//! Self-checking drivers shared by the fuzz targets and the test suite of
//! `bsp-core`; a `publish = false` crate, so that a user of `bsp-core`
//! compiles only geometry.
//!
//! [`split_case`] and [`build_case`] turn arbitrary bytes into a geometric
//! input ([`SplitInput`], [`BuildInput`]) and run the kernel on it,
//! asserting its invariants exactly. The decoding never rejects: bytes that
//! run out read as zero, and every byte string decodes to some input. The
//! decoders favour the hard cases — shared and repeated vertices, coplanar
//! and touching polygons, cuts through vertices and along edges,
//! coordinates at the limits of the grid.
//!
//! A failed check panics with a message naming the invariant, followed by
//! the decoded input printed as a Rust expression, so that it pastes
//! straight into a regression test:
//!
//! ```
//! use bsp_testkit::SplitInput;
//! let input = SplitInput {
//!     polygon: vec![[0, 0, 0], [4, 0, 0], [4, 4, 0], [0, 4, 0]],
//!     cuts: vec![[[1, 0, 0], [1, 1, 0], [1, 0, 1]], [[0, 0, 0], [4, 4, 0], [0, 0, 1]]],
//! };
//! let report = input.check();
//! assert_eq!((report.spanning, report.pieces), (3, 4));
//! ```
//!
//! The same inputs are produced from bytes by [`SplitInput::decode`]; the
//! inverse, [`SplitInput::encode`], writes the seed corpus of `fuzz/`.

use std::collections::HashMap;
use std::fmt::{self, Debug};

mod merge;
pub use merge::{MergeInput, merge_case};

use bsp_core::{
    BspTree, BuildOptions, FlatBsp, GridPoint, Link, MAX_COORD, MAX_VIEW_COORD, Membership, NodeId,
    Order, Plane, Point, Polygon, PolygonSide, Side, Split, ViewPoint,
};

const M: i64 = MAX_COORD as i64;

/// Decodes `data` as a [`SplitInput`] and checks it (see
/// [`SplitInput::check`]). Panics, with the input printed as a Rust
/// expression, if an invariant fails.
///
/// ```
/// bsp_testkit::split_case(b"any bytes at all");
/// bsp_testkit::split_case(&[]);
/// ```
pub fn split_case(data: &[u8]) {
    SplitInput::decode(data).check();
}

/// Decodes `data` as a [`BuildInput`] and checks it (see
/// [`BuildInput::check`]). Panics, with the input printed as a Rust
/// expression, if an invariant fails.
///
/// ```
/// bsp_testkit::build_case(b"any bytes at all");
/// bsp_testkit::build_case(&[]);
/// ```
pub fn build_case(data: &[u8]) {
    BuildInput::decode(data).check();
}

// ---------------------------------------------------------------------------
// failure reporting

/// Panics with `msg` and the input as a Rust expression.
#[cold]
#[track_caller]
fn fail(input: &dyn Debug, msg: fmt::Arguments<'_>) -> ! {
    panic!("check failed: {msg}\ninput (paste into a regression test):\n{input:?}")
}

macro_rules! ensure {
    ($input:expr, $cond:expr, $($msg:tt)+) => {
        if !$cond {
            fail($input, format_args!($($msg)+))
        }
    };
}

/// Prints a slice as `vec![a, b, c]`.
struct VecLit<'a, T>(&'a [T]);

impl<T: Debug> Debug for VecLit<'_, T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("vec!")?;
        f.debug_list().entries(self.0).finish()
    }
}

/// Prints a slice of vectors as `vec![vec![..], ..]`.
struct NestedVecLit<'a, T>(&'a [Vec<T>]);

impl<T: Debug> Debug for NestedVecLit<'_, T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("vec!")?;
        f.debug_list()
            .entries(self.0.iter().map(|v| VecLit(v)))
            .finish()
    }
}

// ---------------------------------------------------------------------------
// byte decoding

/// A byte reader that reads zeros once the data runs out.
struct Bytes<'a> {
    data: &'a [u8],
}

impl Bytes<'_> {
    fn u8(&mut self) -> u8 {
        match self.data.split_first() {
            Some((&b, rest)) => {
                self.data = rest;
                b
            }
            None => 0,
        }
    }
    fn u16(&mut self) -> u16 {
        u16::from_le_bytes([self.u8(), self.u8()])
    }
    fn u32(&mut self) -> u32 {
        u32::from_le_bytes([self.u8(), self.u8(), self.u8(), self.u8()])
    }
    fn u64(&mut self) -> u64 {
        let lo = self.u32() as u64;
        lo | (self.u32() as u64) << 32
    }
    /// A value in `0..n`, `1 <= n <= 256`.
    fn below(&mut self, n: usize) -> usize {
        self.u8() as usize % n
    }
    /// A grid coordinate, biased to small values, powers of two and the
    /// limits of the grid.
    fn coord(&mut self) -> i32 {
        let v: i64 = match self.u8() % 8 {
            0 | 1 => self.u8() as i8 as i64,
            2 => (self.u8() % 8) as i64,
            3 => self.u16() as i16 as i64,
            4 => {
                let s = (self.u8() % 64) as i64;
                if self.u8() & 1 == 0 { M - s } else { s - M }
            }
            5 => (self.u32() as i64).rem_euclid(2 * M + 1) - M,
            6 => {
                let e = self.u8() % 26;
                let d = (self.u8() as i8 % 4) as i64;
                let v = (1i64 << e) + d;
                if self.u8() & 1 == 0 { v } else { -v }
            }
            _ => 0,
        };
        clamp_coord(v)
    }
    /// A grid point: fresh, or a repeat, a neighbour or a collinear
    /// extension of points in `pool`.
    fn point(&mut self, pool: &[GridPoint]) -> GridPoint {
        let mode = self.u8() % 8;
        if !pool.is_empty() && (4..=6).contains(&mode) {
            let a = pool[self.below(pool.len())];
            match mode {
                4 => return a,
                5 => {
                    let d = [self.u8(), self.u8(), self.u8()];
                    return [0, 1, 2].map(|k| clamp_coord(a[k] as i64 + (d[k] % 3) as i64 - 1));
                }
                _ => {
                    let b = pool[self.below(pool.len())];
                    return if self.u8() & 1 == 0 {
                        // floor of the midpoint: on the segment when the sum is even
                        [0, 1, 2].map(|k| clamp_coord((a[k] as i64 + b[k] as i64).div_euclid(2)))
                    } else {
                        // beyond b on the line through a and b
                        [0, 1, 2].map(|k| clamp_coord(2 * b[k] as i64 - a[k] as i64))
                    };
                }
            }
        }
        [self.coord(), self.coord(), self.coord()]
    }
    /// A small vector for templates and translations.
    fn vector(&mut self) -> [i64; 3] {
        match self.u8() % 4 {
            0 => [0, 1, 2].map(|_| self.u8() as i8 as i64),
            1 => [0, 1, 2].map(|_| self.u16() as i16 as i64),
            2 => {
                let axis = self.below(3);
                let len = self.u32() as i64 % (2 * M) - M;
                let mut v = [0; 3];
                v[axis] = len;
                v
            }
            _ => [0, 1, 2].map(|_| (self.u32() as i64).rem_euclid(2 * M + 1) - M),
        }
    }
}

fn clamp_coord(v: i64) -> i32 {
    v.clamp(-M, M) as i32
}

fn in_grid(p: [i64; 3]) -> Option<GridPoint> {
    p.iter().all(|c| c.abs() <= M).then(|| p.map(|c| c as i32))
}

/// Convex (and a few deliberately degenerate) outlines in 2D template
/// coordinates, counter-clockwise.
const TEMPLATES: &[&[(i64, i64)]] = &[
    &[(0, 0), (1, 0), (0, 1)],
    &[(0, 0), (1, 0), (1, 1), (0, 1)],
    &[(1, 0), (2, 0), (3, 1), (2, 2), (1, 2), (0, 1)],
    // a collinear vertex
    &[(0, 0), (1, 0), (2, 0), (2, 1), (0, 1)],
    // repeated vertices
    &[(0, 0), (1, 0), (1, 0), (1, 1), (0, 1), (0, 0)],
    // a sliver of area 1/2
    &[(0, 0), (1000, 1), (999, 1)],
    // a spike folding back on itself
    &[(0, 0), (2, 0), (1, 0), (1, 1)],
    // not convex
    &[(0, 0), (2, 0), (1, 1), (2, 2), (0, 2)],
];

/// A planar outline `o + a u + b v` from a template, translated to fit the
/// grid; `None` if it cannot fit.
fn template_polygon(b: &mut Bytes<'_>, pool: &[GridPoint]) -> Option<Vec<GridPoint>> {
    let t = TEMPLATES[b.below(TEMPLATES.len())];
    let reverse = b.u8() & 1 == 1;
    let o = b.point(pool).map(|c| c as i64);
    let (u, v) = (b.vector(), b.vector());
    let offs: Vec<[i64; 3]> = t
        .iter()
        .map(|&(x, y)| [0, 1, 2].map(|k| x * u[k] + y * v[k]))
        .collect();
    let mut o2 = o;
    for k in 0..3 {
        let lo = offs.iter().map(|p| p[k]).min().unwrap_or(0);
        let hi = offs.iter().map(|p| p[k]).max().unwrap_or(0);
        if hi - lo > 2 * M {
            return None;
        }
        o2[k] = o[k].clamp(-M - lo, M - hi);
    }
    let mut pts: Vec<GridPoint> = offs
        .iter()
        .map(|p| in_grid([0, 1, 2].map(|k| o2[k] + p[k])))
        .collect::<Option<_>>()?;
    if reverse {
        pts.reverse();
    }
    Some(pts)
}

/// Encoding of a fresh point with full-range coordinates (the inverse of
/// [`Bytes::point`] for any grid point).
fn enc_point(out: &mut Vec<u8>, p: GridPoint) {
    out.push(0);
    for c in p {
        out.push(5);
        out.extend(((c as i64 + M) as u32).to_le_bytes());
    }
}

// ---------------------------------------------------------------------------
// exact helpers

/// Filter and exact path must agree whenever the filter answers.
fn check_point_side(input: &dyn Debug, p: &Point, plane: &Plane) -> Side {
    let s = p.classify(plane);
    if let Point::Implicit(i) = p {
        let exact = i.classify_exact(plane);
        ensure!(
            input,
            exact == s,
            "Point::classify ({s:?}) differs from the exact path ({exact:?}) for {p:?} and {plane:?}"
        );
        if let Some(f) = i.classify_filtered(plane) {
            ensure!(
                input,
                f == exact,
                "the filter certified {f:?} but the exact side is {exact:?} for {p:?} and {plane:?}"
            );
        }
    }
    s
}

/// `true` if `p` lies in the closed polygon `poly` (exact).
fn inside_polygon(input: &dyn Debug, p: &Point, poly: &Polygon) -> Result<(), String> {
    if check_point_side(input, p, poly.support()) != Side::On {
        return Err("is off the support plane".into());
    }
    for (j, e) in poly.edge_planes().iter().enumerate() {
        if check_point_side(input, p, e) == Side::Front {
            return Err(format!("is outside edge plane {j}"));
        }
    }
    Ok(())
}

fn same_polygon(a: &Polygon, b: &Polygon) -> bool {
    a.tag() == b.tag()
        && a.support() == b.support()
        && a.edge_planes() == b.edge_planes()
        && a.len() == b.len()
        && a.vertices()
            .iter()
            .zip(b.vertices())
            .all(|(u, v)| u.same_point(v))
}

/// Twice the area vector of `verts` about `o`, and a bound on its
/// floating-point error per component (`m` bounds the coordinates).
fn area2(verts: &[[f64; 3]], o: [f64; 3], m: f64) -> ([f64; 3], f64) {
    let k = verts.len();
    let mut a = [0.0; 3];
    let mut err = 0.0;
    for i in 0..k {
        let p = [0, 1, 2].map(|c| verts[i][c] - o[c]);
        let q = [0, 1, 2].map(|c| verts[(i + 1) % k][c] - o[c]);
        let x = [
            p[1] * q[2] - p[2] * q[1],
            p[2] * q[0] - p[0] * q[2],
            p[0] * q[1] - p[1] * q[0],
        ];
        for c in 0..3 {
            a[c] += x[c];
        }
        let (np, nq) = (max_abs(p), max_abs(q));
        err += np * nq + m * (np + nq);
    }
    (a, err)
}

fn max_abs(v: [f64; 3]) -> f64 {
    v.iter().fold(0.0, |m, c| m.max(c.abs()))
}

/// The pieces cover `whole`: each lies inside it (exact), and their areas
/// add up to its area (in `f64`, with a rounding-error bound: the exact
/// containment is the real test, this one catches lost or doubled pieces).
fn check_cover(input: &dyn Debug, whole: &Polygon, pieces: &[&Polygon], what: &str) {
    for (i, p) in pieces.iter().enumerate() {
        ensure!(
            input,
            p.support() == whole.support(),
            "{what}: piece {i} has support {:?}, not the original's {:?}",
            p.support(),
            whole.support()
        );
        for (k, v) in p.vertices().iter().enumerate() {
            if let Err(e) = inside_polygon(input, v, whole) {
                fail(
                    input,
                    format_args!("{what}: vertex {k} of piece {i} ({v:?}) {e} of the original"),
                );
            }
        }
    }
    let wv = whole.vertices_f64();
    let o = wv[0];
    let pv: Vec<Vec<[f64; 3]>> = pieces.iter().map(|p| p.vertices_f64()).collect();
    let m = pv
        .iter()
        .flatten()
        .chain(&wv)
        .fold(0.0f64, |m, v| m.max(max_abs(*v)));
    let (aw, mut err) = area2(&wv, o, m);
    let mut sum = [0.0; 3];
    for v in &pv {
        let (a, e) = area2(v, o, m);
        err += e;
        for c in 0..3 {
            sum[c] += a[c];
        }
    }
    let tol = err * 2f64.powi(-40);
    for c in 0..3 {
        let close = (sum[c] - aw[c]).abs() <= tol;
        ensure!(
            input,
            close,
            "{what}: the pieces' area vector {sum:?} differs from the original's {aw:?} \
             by more than the rounding bound {tol:e}"
        );
    }
}

// ---------------------------------------------------------------------------
// split

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
    fn expected_side(&self, p: &Polygon, plane: &Plane, what: &str) -> (PolygonSide, Vec<Side>) {
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

    fn check_one_sided(
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
    fn check_spanning(
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
fn corner_polygon(b: &mut Bytes<'_>) -> Vec<GridPoint> {
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
fn decode_cut(b: &mut Bytes<'_>, verts: &[GridPoint], pool: &mut Vec<GridPoint>) -> [GridPoint; 3] {
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

// ---------------------------------------------------------------------------
// build

/// An input scene for [`BuildInput`].
#[derive(Clone, PartialEq, Eq)]
pub enum Scene {
    /// An open polygon soup: each entry is one polygon's vertices (invalid
    /// ones are left out of the tree; the tag is the index).
    Soup(Vec<Vec<GridPoint>>),
    /// A closed box, whose membership is known exactly.
    Box(BoxSolid),
}

impl Debug for Scene {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Scene::Soup(p) => f
                .debug_tuple("Scene::Soup")
                .field(&NestedVecLit(p))
                .finish(),
            Scene::Box(b) => f.debug_tuple("Scene::Box").field(b).finish(),
        }
    }
}

/// The box `lo <= p <= hi`, its faces optionally subdivided at `splits`
/// and triangulated, mapped to the grid by an integer shear (and mirror)
/// plus `offset`: world point `q = mirror(shears(p)) + offset`.
///
/// The map has an integer inverse, so membership of a probe is decided
/// exactly in box coordinates, independently of any plane.
#[derive(Clone, PartialEq, Eq)]
pub struct BoxSolid {
    /// Lower corner (box coordinates).
    pub lo: [i32; 3],
    /// Upper corner; `lo < hi` on every axis.
    pub hi: [i32; 3],
    /// Per axis, a coordinate at which the faces along that axis are
    /// subdivided (ignored unless strictly between `lo` and `hi`).
    pub splits: [i32; 3],
    /// Bit `f` (face `f = 2 axis + (0 low, 1 high)`) splits that face's
    /// quads into triangles; bit 6 picks the diagonal.
    pub triangulate: u8,
    /// Elementary shears `(i, j, s)`: `p[i] += s p[j]`, applied in order
    /// (skipped when `i == j`).
    pub shears: [(usize, usize, i32); 3],
    /// Negate x after the shears (faces are then reversed).
    pub mirror: bool,
    /// Translation.
    pub offset: [i32; 3],
    /// Probe points, box coordinates.
    pub probes: Vec<[i32; 3]>,
    /// Rational probe points `num / den` (box coordinates), built as the
    /// intersection of three planes so they are implicit points.
    pub rational_probes: Vec<([i64; 3], i64)>,
}

impl Debug for BoxSolid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("BoxSolid")
            .field("lo", &self.lo)
            .field("hi", &self.hi)
            .field("splits", &self.splits)
            .field("triangulate", &self.triangulate)
            .field("shears", &self.shears)
            .field("mirror", &self.mirror)
            .field("offset", &self.offset)
            .field("probes", &VecLit(&self.probes))
            .field("rational_probes", &VecLit(&self.rational_probes))
            .finish()
    }
}

/// A scene, build options, viewpoints.
#[derive(Clone, PartialEq, Eq)]
pub struct BuildInput {
    /// The polygons.
    pub scene: Scene,
    /// [`BuildOptions::candidates`].
    pub candidates: usize,
    /// [`BuildOptions::sample`].
    pub sample: usize,
    /// [`BuildOptions::split_weight`].
    pub split_weight: u32,
    /// [`BuildOptions::seed`].
    pub seed: u64,
    /// Viewpoints for the traversals (out-of-range ones are skipped).
    pub eyes: Vec<[i64; 3]>,
}

impl Debug for BuildInput {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("BuildInput")
            .field("scene", &self.scene)
            .field("candidates", &self.candidates)
            .field("sample", &self.sample)
            .field("split_weight", &self.split_weight)
            .field("seed", &self.seed)
            .field("eyes", &VecLit(&self.eyes))
            .finish()
    }
}

/// What a [`BuildInput::check`] exercised.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BuildReport {
    /// Valid input polygons.
    pub polygons: usize,
    /// Fragments in the tree.
    pub fragments: usize,
    /// Inner nodes.
    pub nodes: usize,
    /// Traversals checked (eyes × orders).
    pub traversals: usize,
    /// Membership probes checked, by expected answer: inside, outside,
    /// boundary.
    pub membership: [usize; 3],
    /// Of those, implicit (rational) probes.
    pub implicit_probes: usize,
}

impl BuildInput {
    /// Decodes bytes (any bytes) into an input.
    ///
    /// ```
    /// use bsp_testkit::{BuildInput, Scene};
    /// assert!(matches!(BuildInput::decode(&[]).scene, Scene::Box(_)));
    /// ```
    pub fn decode(data: &[u8]) -> BuildInput {
        let mut b = Bytes { data };
        let kind = b.u8();
        let candidates = 1 + b.below(16);
        let sample = 1 + b.below(64);
        let split_weight = (b.u8() % 9) as u32;
        let seed = b.u64();
        let scene = if kind.is_multiple_of(4) {
            Scene::Box(decode_box(&mut b))
        } else {
            Scene::Soup(decode_soup(&mut b))
        };
        let verts: Vec<GridPoint> = match &scene {
            Scene::Soup(s) => s.iter().flatten().copied().collect(),
            Scene::Box(bx) => bx.world_corners().unwrap_or_default(),
        };
        let n = 1 + b.below(3);
        let eyes = (0..n)
            .map(|_| match b.u8() % 4 {
                1 => {
                    let v = MAX_VIEW_COORD as u64;
                    [0, 1, 2].map(|_| (b.u64() % (2 * v + 1)) as i64 - MAX_VIEW_COORD)
                }
                2 if !verts.is_empty() => verts[b.below(verts.len())].map(|c| c as i64),
                _ => [b.coord(), b.coord(), b.coord()].map(|c| c as i64),
            })
            .collect();
        BuildInput {
            scene,
            candidates,
            sample,
            split_weight,
            seed,
            eyes,
        }
    }

    /// Bytes that [`BuildInput::decode`] turns back into `self`, within
    /// the decoder's ranges (at most 12 polygons of 3 to 5 vertices or a
    /// box with at most 8 + 4 probes; `candidates` 1..=16, `sample`
    /// 1..=64, `split_weight` 0..=8, shears within -8..=8, offsets within
    /// ±2^24, 1 to 3 eyes).
    ///
    /// ```
    /// use bsp_testkit::{BuildInput, Scene};
    /// let i = BuildInput {
    ///     scene: Scene::Soup(vec![vec![[0, 0, 0], [4, 0, 0], [0, 4, 0]]]),
    ///     candidates: 8, sample: 48, split_weight: 4, seed: 1,
    ///     eyes: vec![[1, 1, 1]],
    /// };
    /// assert_eq!(BuildInput::decode(&i.encode()), i);
    /// ```
    pub fn encode(&self) -> Vec<u8> {
        let mut out = vec![
            if matches!(self.scene, Scene::Box(_)) {
                0
            } else {
                1
            },
            (self.candidates.clamp(1, 16) - 1) as u8,
            (self.sample.clamp(1, 64) - 1) as u8,
            self.split_weight.min(8) as u8,
        ];
        out.extend(self.seed.to_le_bytes());
        match &self.scene {
            Scene::Soup(polys) => {
                out.push(0); // empty pool
                out.push((polys.len().clamp(1, 12) - 1) as u8);
                for p in polys {
                    out.push(0);
                    out.push((p.len().clamp(3, 5) - 3) as u8);
                    for v in p {
                        enc_point(&mut out, *v);
                    }
                }
            }
            Scene::Box(bx) => {
                for k in 0..3 {
                    let c = |out: &mut Vec<u8>, v: i32| {
                        out.push(5);
                        out.extend(((v as i64 + M) as u32).to_le_bytes());
                    };
                    c(&mut out, bx.lo[k]);
                    c(&mut out, bx.hi[k]);
                    c(&mut out, bx.splits[k]);
                }
                out.push(bx.triangulate);
                for (i, j, s) in bx.shears {
                    out.extend([i as u8, j as u8, s as i8 as u8]);
                }
                out.push(u8::from(bx.mirror));
                for c in bx.offset {
                    out.push(2);
                    out.extend(((c as i64 + (1 << 24)) as u32).to_le_bytes());
                }
                out.push(bx.probes.len().min(8) as u8);
                for p in &bx.probes {
                    for c in p {
                        out.push(7);
                        out.push(5);
                        out.extend(((*c as i64 + M) as u32).to_le_bytes());
                    }
                }
                out.push(bx.rational_probes.len().min(4) as u8);
                for (num, den) in &bx.rational_probes {
                    out.push(4);
                    out.extend(((den - 1) as u32).to_le_bytes());
                    for c in num {
                        out.extend([0, 4]);
                        out.extend(c.to_le_bytes());
                    }
                }
            }
        }
        out.push((self.eyes.len().clamp(1, 3) - 1) as u8);
        for e in &self.eyes {
            out.push(1);
            for c in e {
                out.extend(((c + MAX_VIEW_COORD) as u64).to_le_bytes());
            }
        }
        out
    }

    /// Builds the tree and checks it exactly:
    ///
    /// - [`BspTree::sanity_check`], and the statistics agree with the
    ///   nodes;
    /// - every fragment lies inside the input polygon of its tag, the
    ///   fragments of a polygon add up to its area, and every valid input
    ///   polygon has a fragment;
    /// - from every eye, in both orders, [`BspTree::traverse`] visits every
    ///   fragment exactly once, [`BspTree::traverse_recursive`] and
    ///   [`FlatBsp::traverse`] give the same sequence, and every pair of
    ///   fragments in different nodes is separated by the plane where their
    ///   paths part, with the eye on the side drawn last (back to front) or
    ///   first (front to back);
    /// - for a box, [`BspTree::classify_point`] of every probe, grid or
    ///   implicit, agrees with exact membership computed in box
    ///   coordinates.
    pub fn check(&self) -> BuildReport {
        let mut report = BuildReport::default();
        let opts = BuildOptions::default()
            .with_candidates(self.candidates)
            .with_sample(self.sample)
            .with_split_weight(self.split_weight)
            .with_seed(self.seed);
        let faces: Vec<Vec<GridPoint>> = match &self.scene {
            Scene::Soup(s) => s.clone(),
            Scene::Box(bx) => match bx.world_faces() {
                Some(f) => f,
                None => return report,
            },
        };
        let inputs: Vec<Option<Polygon>> = faces
            .iter()
            .enumerate()
            .map(|(i, f)| {
                if f.iter().flatten().any(|c| c.abs() > MAX_COORD) {
                    return None;
                }
                Polygon::from_grid_points(f, i as u32).ok()
            })
            .collect();
        if let Scene::Box(_) = self.scene
            && let Some(i) = inputs.iter().position(Option::is_none)
        {
            fail(
                self,
                format_args!("box face {i} ({:?}) is not a valid polygon", faces[i]),
            );
        }
        let polys: Vec<Polygon> = inputs.iter().flatten().cloned().collect();
        report.polygons = polys.len();
        let tree = BspTree::build(polys, &opts);
        if let Err(e) = tree.sanity_check() {
            fail(self, format_args!("BspTree::sanity_check: {e}"));
        }
        let stats = tree.stats();
        let frags: Vec<&Polygon> = tree.polygons().collect();
        report.fragments = frags.len();
        report.nodes = tree.nodes().len();
        ensure!(
            self,
            stats.nodes == tree.nodes().len() && stats.polygons == frags.len(),
            "stats {stats:?} disagree with {} nodes and {} fragments",
            tree.nodes().len(),
            frags.len()
        );
        ensure!(
            self,
            stats.in_cells + stats.out_cells == stats.nodes + 1,
            "stats {stats:?}: a binary tree has one more leaf than inner nodes"
        );
        self.check_fragments(&inputs, &frags);
        report.traversals = self.check_traversals(&tree, &frags);
        if let Scene::Box(bx) = &self.scene {
            self.check_membership(bx, &tree, &mut report);
        }
        report
    }

    fn check_fragments(&self, inputs: &[Option<Polygon>], frags: &[&Polygon]) {
        let mut by_tag: Vec<Vec<&Polygon>> = vec![Vec::new(); inputs.len()];
        for (i, f) in frags.iter().enumerate() {
            let t = f.tag() as usize;
            ensure!(
                self,
                inputs.get(t).is_some_and(Option::is_some),
                "fragment {i} has tag {t}, which is no valid input polygon"
            );
            by_tag[t].push(f);
        }
        for (t, (input, pieces)) in inputs.iter().zip(&by_tag).enumerate() {
            let Some(input) = input else { continue };
            ensure!(
                self,
                !pieces.is_empty(),
                "input polygon {t} has no fragment"
            );
            check_cover(self, input, pieces, &format!("fragments of polygon {t}"));
        }
    }

    fn check_traversals(&self, tree: &BspTree, frags: &[&Polygon]) -> usize {
        let map = FragmentMap::new(tree, frags);
        let flat = FlatBsp::new(tree);
        ensure!(
            self,
            flat.len() == tree.nodes().len() && flat.polygons().len() == frags.len(),
            "FlatBsp has {} nodes and {} polygons, the tree {} and {}",
            flat.len(),
            flat.polygons().len(),
            tree.nodes().len(),
            frags.len()
        );
        let mut count = 0;
        for (ei, e) in self.eyes.iter().enumerate() {
            let Some(eye) = ViewPoint::new(*e) else {
                continue;
            };
            for order in [Order::BackToFront, Order::FrontToBack] {
                count += 1;
                let what = format!("eye {ei} {e:?}, {order:?}");
                let seq = self.check_visits(&map, &flat, eye, order, &what);
                // painter's order, checked on the first eye only (quadratic)
                if ei > 0 {
                    continue;
                }
                self.check_painter(&map, &seq, eye, order, &what);
            }
        }
        count
    }

    /// Checks that [`BspTree::traverse`] from `eye` in `order` visits
    /// every fragment of `map` exactly once, and that
    /// [`BspTree::traverse_recursive`] and [`FlatBsp::traverse`] (`flat`)
    /// give the same sequence. Returns it (fragment indices).
    fn check_visits(
        &self,
        map: &FragmentMap<'_>,
        flat: &FlatBsp,
        eye: ViewPoint,
        order: Order,
        what: &str,
    ) -> Vec<usize> {
        let (tree, frags, index) = (map.tree, map.frags, &map.index);
        let mut seq = Vec::with_capacity(frags.len());
        tree.traverse(eye, order, |p| {
            seq.push(index.get(&(p as *const Polygon)).copied())
        });
        let mut seen = vec![false; frags.len()];
        for (k, i) in seq.iter().enumerate() {
            let Some(i) = *i else {
                fail(
                    self,
                    format_args!("{what}: visit {k} is not a fragment of the tree"),
                )
            };
            ensure!(
                self,
                !std::mem::replace(&mut seen[i], true),
                "{what}: fragment {i} visited twice"
            );
        }
        ensure!(
            self,
            seq.len() == frags.len(),
            "{what}: {} visits for {} fragments",
            seq.len(),
            frags.len()
        );
        let seq: Vec<usize> = seq.into_iter().flatten().collect();
        let mut rec = Vec::with_capacity(frags.len());
        tree.traverse_recursive(eye, order, |p| {
            rec.push(index.get(&(p as *const Polygon)).copied())
        });
        ensure!(
            self,
            rec.iter().copied().eq(seq.iter().map(|i| Some(*i))),
            "{what}: traverse_recursive gives {rec:?}, traverse {seq:?}"
        );
        let mut k = 0;
        let mut mismatch = None;
        flat.traverse(eye, order, |p| {
            if mismatch.is_none() && seq.get(k).is_none_or(|&i| !same_polygon(p, frags[i])) {
                mismatch = Some(k);
            }
            k += 1;
        });
        ensure!(
            self,
            mismatch.is_none() && k == seq.len(),
            "{what}: FlatBsp::traverse differs from the tree at visit {mismatch:?} \
             ({k} visits, {} fragments)",
            seq.len()
        );
        seq
    }

    /// Checks the painter's order of the visits `seq` from `eye` in
    /// `order`: every pair of fragments in different nodes is separated
    /// by the plane where their paths part, with the eye on the side drawn
    /// last (back to front) or first (front to back).
    fn check_painter(
        &self,
        map: &FragmentMap<'_>,
        seq: &[usize],
        eye: ViewPoint,
        order: Order,
        what: &str,
    ) {
        let (tree, frags) = (map.tree, map.frags);
        for x in 0..seq.len() {
            for y in x + 1..seq.len() {
                let (a, b) = (seq[x], seq[y]);
                let (na, nb) = (map.node_of[a], map.node_of[b]);
                if na == nb {
                    continue;
                }
                let plane = tree.node(map.lca(na, nb)).plane;
                // drawn first: `far`; drawn later: `near`
                let (far, near) = match order {
                    Order::BackToFront => (frags[a], frags[b]),
                    Order::FrontToBack => (frags[b], frags[a]),
                };
                let separated = [plane, plane.flip()].iter().any(|p| {
                    p.classify_viewpoint(eye) != Side::Back
                        && matches!(
                            far.classify(p),
                            PolygonSide::Back | PolygonSide::Coplanar { .. }
                        )
                        && matches!(
                            near.classify(p),
                            PolygonSide::Front | PolygonSide::Coplanar { .. }
                        )
                });
                ensure!(
                    self,
                    separated,
                    "{what}: fragments {a} (visit {x}) and {b} (visit {y}) are not \
                     separated from the eye by {plane:?}"
                );
            }
        }
    }

    fn check_membership(&self, bx: &BoxSolid, tree: &BspTree, report: &mut BuildReport) {
        let oracle = |p: [i128; 3], den: i128| {
            let mut boundary = false;
            for (k, &c) in p.iter().enumerate() {
                let (lo, hi) = (bx.lo[k] as i128 * den, bx.hi[k] as i128 * den);
                if c < lo || c > hi {
                    return Membership::Outside;
                }
                boundary |= c == lo || c == hi;
            }
            if boundary {
                Membership::Boundary
            } else {
                Membership::Inside
            }
        };
        let tally = |m: Membership, report: &mut BuildReport| {
            report.membership[match m {
                Membership::Inside => 0,
                Membership::Outside => 1,
                Membership::Boundary => 2,
            }] += 1;
        };
        let mut probes: Vec<[i64; 3]> = bx.probes.iter().map(|p| p.map(|c| c as i64)).collect();
        // the corners, the centre and a point outside
        for i in 0..8 {
            probes.push([0, 1, 2].map(|k| {
                if i >> k & 1 == 1 {
                    bx.hi[k] as i64
                } else {
                    bx.lo[k] as i64
                }
            }));
        }
        probes.push([0, 1, 2].map(|k| (bx.lo[k] as i64 + bx.hi[k] as i64).div_euclid(2)));
        probes.push([0, 1, 2].map(|k| bx.hi[k] as i64 + 1));
        for (i, p) in probes.iter().enumerate() {
            let Some(q) = bx.to_world(*p) else { continue };
            let want = oracle(p.map(|c| c as i128), 1);
            let got = tree.classify_point(&Point::Grid(q));
            ensure!(
                self,
                got == want,
                "probe {i}: box point {p:?} (grid {q:?}) is {want:?}, classify_point says {got:?}"
            );
            tally(want, report);
        }
        let minv = bx.inverse_rows();
        for (i, (num, den)) in bx.rational_probes.iter().enumerate() {
            if *den <= 0 {
                continue;
            }
            // plane k: den * (minv_k · (q - offset)) - num_k = 0
            let planes: Option<Vec<Plane>> = (0..3)
                .map(|k| {
                    let n = minv[k].map(|c| c as i128 * *den as i128);
                    let d: i128 =
                        -(0..3).map(|j| n[j] * bx.offset[j] as i128).sum::<i128>() - num[k] as i128;
                    let n: Option<[i64; 3]> = n
                        .iter()
                        .map(|c| i64::try_from(*c).ok())
                        .collect::<Option<Vec<_>>>()
                        .map(|v| [v[0], v[1], v[2]]);
                    Plane::new(n?, d)
                })
                .collect();
            let Some(planes) = planes else { continue };
            let Some(q) = Point::from_planes(&planes[0], &planes[1], &planes[2]) else {
                fail(
                    self,
                    format_args!("rational probe {i}: the three planes {planes:?} do not meet"),
                );
            };
            let want = oracle(num.map(|c| c as i128), *den as i128);
            let got = tree.classify_point(&q);
            ensure!(
                self,
                got == want,
                "rational probe {i}: box point {num:?}/{den} ({q:?}) is {want:?}, \
                 classify_point says {got:?}"
            );
            tally(want, report);
            report.implicit_probes += 1;
        }
    }
}

/// A built tree's fragments and where they sit in it: what the traversal
/// checks of [`BuildInput::check`] compare visits with.
struct FragmentMap<'a> {
    tree: &'a BspTree,
    frags: &'a [&'a Polygon],
    /// Each fragment's index, by address.
    index: HashMap<*const Polygon, usize>,
    /// The node holding each fragment.
    node_of: Vec<NodeId>,
    /// Each node's parent.
    parent: Vec<Option<NodeId>>,
    /// Each node's depth.
    depth: Vec<usize>,
}

impl<'a> FragmentMap<'a> {
    /// The index, node, and each node's parent and depth of `tree`'s
    /// fragments `frags`.
    fn new(tree: &'a BspTree, frags: &'a [&'a Polygon]) -> Self {
        let index: HashMap<*const Polygon, usize> = frags
            .iter()
            .enumerate()
            .map(|(i, p)| (*p as *const Polygon, i))
            .collect();
        // the node holding each fragment, and each node's parent and depth
        let mut node_of = vec![0 as NodeId; frags.len()];
        let mut parent: Vec<Option<NodeId>> = vec![None; tree.nodes().len()];
        let mut depth = vec![0usize; tree.nodes().len()];
        for (id, n) in tree.nodes().iter().enumerate() {
            for p in &n.polygons {
                node_of[index[&(p as *const Polygon)]] = id as NodeId;
            }
        }
        let mut stack = vec![(tree.root(), None, 0)];
        while let Some((link, up, d)) = stack.pop() {
            if let Link::Node(id) = link {
                parent[id as usize] = up;
                depth[id as usize] = d;
                let n = tree.node(id);
                stack.push((n.front, Some(id), d + 1));
                stack.push((n.back, Some(id), d + 1));
            }
        }
        FragmentMap {
            tree,
            frags,
            index,
            node_of,
            parent,
            depth,
        }
    }

    /// The lowest common ancestor of nodes `a` and `b`: the node where
    /// their paths from the root part.
    fn lca(&self, mut a: NodeId, mut b: NodeId) -> NodeId {
        while a != b {
            if self.depth[a as usize] >= self.depth[b as usize] {
                a = self.parent[a as usize].expect("a deeper node has a parent");
            } else {
                b = self.parent[b as usize].expect("a deeper node has a parent");
            }
        }
        a
    }
}

impl BoxSolid {
    /// Box coordinates to world grid coordinates, `None` outside the grid.
    fn to_world(&self, p: [i64; 3]) -> Option<GridPoint> {
        let mut q = p;
        for &(i, j, s) in &self.shears {
            if i % 3 != j % 3 {
                q[i % 3] += s as i64 * q[j % 3];
            }
        }
        if self.mirror {
            q[0] = -q[0];
        }
        in_grid([0, 1, 2].map(|k| q[k] + self.offset[k] as i64))
    }

    /// The rows of the inverse of the linear part.
    fn inverse_rows(&self) -> [[i64; 3]; 3] {
        let inv = |mut q: [i64; 3]| {
            if self.mirror {
                q[0] = -q[0];
            }
            for &(i, j, s) in self.shears.iter().rev() {
                if i % 3 != j % 3 {
                    q[i % 3] -= s as i64 * q[j % 3];
                }
            }
            q
        };
        let cols = [inv([1, 0, 0]), inv([0, 1, 0]), inv([0, 0, 1])];
        [0, 1, 2].map(|r| [cols[0][r], cols[1][r], cols[2][r]])
    }

    fn valid(&self) -> bool {
        (0..3).all(|k| self.lo[k] < self.hi[k])
            && self.shears.iter().all(|&(_, _, s)| (-8..=8).contains(&s))
    }

    fn world_corners(&self) -> Option<Vec<GridPoint>> {
        if !self.valid() {
            return None;
        }
        (0..8)
            .map(|i: usize| {
                self.to_world([0, 1, 2].map(|k| {
                    if i >> k & 1 == 1 {
                        self.hi[k] as i64
                    } else {
                        self.lo[k] as i64
                    }
                }))
            })
            .collect()
    }

    /// The faces in world coordinates, outward and counter-clockwise;
    /// `None` if the box is invalid or leaves the grid.
    fn world_faces(&self) -> Option<Vec<Vec<GridPoint>>> {
        self.world_corners()?;
        let xs: Vec<Vec<i64>> = (0..3)
            .map(|k| {
                let (lo, hi, s) = (self.lo[k], self.hi[k], self.splits[k]);
                if lo < s && s < hi {
                    vec![lo as i64, s as i64, hi as i64]
                } else {
                    vec![lo as i64, hi as i64]
                }
            })
            .collect();
        let mut faces = Vec::new();
        for a in 0..3 {
            let (b, c) = ((a + 1) % 3, (a + 2) % 3);
            for high in [false, true] {
                let val = if high { self.hi[a] } else { self.lo[a] } as i64;
                let tri = self.triangulate >> (2 * a + usize::from(high)) & 1 == 1;
                for ib in 0..xs[b].len() - 1 {
                    for ic in 0..xs[c].len() - 1 {
                        let corner = |ub: usize, uc: usize| {
                            let mut p = [0; 3];
                            p[a] = val;
                            p[b] = xs[b][ub];
                            p[c] = xs[c][uc];
                            self.to_world(p)
                        };
                        let mut q = [
                            corner(ib, ic)?,
                            corner(ib + 1, ic)?,
                            corner(ib + 1, ic + 1)?,
                            corner(ib, ic + 1)?,
                        ];
                        if !high {
                            q.reverse();
                        }
                        let mut polys: Vec<Vec<GridPoint>> = if !tri {
                            vec![q.to_vec()]
                        } else if self.triangulate & 64 == 0 {
                            vec![vec![q[0], q[1], q[2]], vec![q[0], q[2], q[3]]]
                        } else {
                            vec![vec![q[1], q[2], q[3]], vec![q[1], q[3], q[0]]]
                        };
                        if self.mirror {
                            polys.iter_mut().for_each(|p| p.reverse());
                        }
                        faces.extend(polys);
                    }
                }
            }
        }
        Some(faces)
    }
}

fn decode_box(b: &mut Bytes<'_>) -> BoxSolid {
    let mut lo = [0; 3];
    let mut hi = [0; 3];
    let mut splits = [0; 3];
    for k in 0..3 {
        let (mut l, mut h) = (b.coord(), b.coord());
        if l > h {
            (l, h) = (h, l);
        }
        if l == h {
            if h < MAX_COORD {
                h += 1;
            } else {
                l -= 1;
            }
        }
        lo[k] = l;
        hi[k] = h;
        splits[k] = b.coord();
    }
    let triangulate = b.u8();
    let shears = [0, 1, 2].map(|_| (b.below(3), b.below(3), (b.u8() as i8 % 9) as i32));
    let mirror = b.u8() & 1 == 1;
    let offset = [0, 1, 2].map(|_| match b.u8() % 3 {
        0 => 0,
        1 => b.u16() as i16 as i32,
        _ => ((b.u32() as i64).rem_euclid((1 << 25) + 1) - (1 << 24)) as i32,
    });
    let axis_value = |b: &mut Bytes<'_>, k: usize| -> i32 {
        let (l, h, s) = (lo[k] as i64, hi[k] as i64, splits[k] as i64);
        clamp_coord(match b.u8() % 8 {
            0 => l - 1,
            1 => l,
            2 => l + 1,
            3 => s,
            4 => h - 1,
            5 => h,
            6 => h + 1,
            _ => b.coord() as i64,
        })
    };
    let n = b.below(9);
    let probes = (0..n)
        .map(|_| [axis_value(b, 0), axis_value(b, 1), axis_value(b, 2)])
        .collect();
    let n = b.below(5);
    let rational_probes = (0..n)
        .map(|_| {
            let den: i64 = match b.u8() % 5 {
                0 => 1,
                1 => 2,
                2 => 3,
                3 => 1 << (b.u8() % 25),
                _ => b.u32() as i64 % (1 << 24) + 1,
            };
            let num = [0, 1, 2].map(|k| {
                let r = (b.u8() % 3) as i64 - 1;
                let base = |v: i32| v as i64 * den;
                match b.u8() % 5 {
                    0 => base(lo[k]) + r,
                    1 => base(hi[k]) + r,
                    2 => base(splits[k]) + r,
                    3 => (base(lo[k]) + base(hi[k])) / 2 + r,
                    _ => b.u64() as i64,
                }
            });
            (num, den)
        })
        .collect();
    BoxSolid {
        lo,
        hi,
        splits,
        triangulate,
        shears,
        mirror,
        offset,
        probes,
        rational_probes,
    }
}

fn decode_soup(b: &mut Bytes<'_>) -> Vec<Vec<GridPoint>> {
    let mut pool: Vec<GridPoint> = Vec::new();
    for _ in 0..b.below(9) {
        let p = b.point(&pool);
        pool.push(p);
    }
    let n = 1 + b.below(12);
    let mut polys: Vec<Vec<GridPoint>> = Vec::with_capacity(n);
    for _ in 0..n {
        let mode = b.u8() % 7;
        let earlier = if polys.is_empty() || !(1..=4).contains(&mode) {
            None
        } else {
            Some(polys[b.below(polys.len())].clone())
        };
        let p = match (mode, earlier) {
            // a triangle on an edge of an earlier polygon, on the other side
            (1, Some(e)) if !e.is_empty() => {
                let i = b.below(e.len());
                let (u, v) = (e[i], e[(i + 1) % e.len()]);
                vec![v, u, b.point(&pool)]
            }
            // the same polygon reversed, or repeated
            (2, Some(e)) => e.into_iter().rev().collect(),
            (3, Some(e)) => e,
            // translated
            (4, Some(e)) => {
                let d = [0, 1, 2].map(|_| b.u8() as i8 as i64);
                e.iter()
                    .map(|p| [0, 1, 2].map(|k| clamp_coord(p[k] as i64 + d[k])))
                    .collect()
            }
            (5, _) => template_polygon(b, &pool).unwrap_or_default(),
            // vertices from the pool
            (6, _) if pool.len() >= 3 => {
                let k = 3 + b.below(2);
                (0..k).map(|_| pool[b.below(pool.len())]).collect()
            }
            _ => {
                let k = 3 + b.below(3);
                (0..k).map(|_| b.point(&pool)).collect()
            }
        };
        pool.extend(p.iter().take(4));
        pool.truncate(16);
        polys.push(p);
    }
    polys
}

/// The README's example, compiled and run as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::{Path, PathBuf};

    const M32: i32 = MAX_COORD;

    fn corpus_dir(target: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../fuzz/corpus")
            .join(target)
    }

    /// Deterministic pseudo-random bytes.
    fn random_bytes(seed: u64, len: usize) -> Vec<u8> {
        let mut s = seed;
        (0..len)
            .map(|_| {
                s = s.wrapping_add(0x9e37_79b9_7f4a_7c15);
                let mut z = s;
                z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
                z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
                (z ^ (z >> 31)) as u8
            })
            .collect()
    }

    fn split_seeds() -> Vec<SplitInput> {
        let m = M32;
        let s = |polygon: &[GridPoint], cuts: &[[GridPoint; 3]]| SplitInput {
            polygon: polygon.to_vec(),
            cuts: cuts.to_vec(),
        };
        let square = [[0, 0, 0], [4, 0, 0], [4, 4, 0], [0, 4, 0]];
        let x1 = [[1, 0, 0], [1, 1, 0], [1, 0, 1]];
        let diag = [[0, 0, 0], [4, 4, 0], [0, 0, 1]];
        vec![
            // across two edges, then through two vertices
            s(&square, &[x1, diag]),
            // through a vertex and across the opposite edge
            s(
                &[[0, 0, 0], [6, 0, 0], [0, 6, 0]],
                &[[[0, 0, 0], [3, 3, 0], [0, 0, 5]]],
            ),
            // touching a vertex, along an edge, and in the plane (both ways)
            s(
                &[[0, 0, 0], [6, 0, 0], [0, 6, 0]],
                &[
                    [[6, 0, 0], [6, 1, 0], [6, 0, 1]],
                    [[0, 0, 0], [6, 0, 0], [0, 0, 1]],
                    [[0, 0, 0], [1, 0, 0], [0, 1, 0]],
                    [[0, 0, 0], [0, 1, 0], [1, 0, 0]],
                ],
            ),
            // four cuts: pieces with implicit vertices cut again
            s(
                &[
                    [1, 0, 0],
                    [2, 0, 0],
                    [3, 1, 0],
                    [2, 2, 0],
                    [1, 2, 0],
                    [0, 1, 0],
                ],
                &[
                    [[0, 0, 0], [3, 2, 0], [0, 0, 1]],
                    [[0, 2, 0], [3, 0, 0], [0, 2, 7]],
                    [[1, 0, -1], [2, 2, 1], [1, 3, 5]],
                    [[0, 1, 0], [3, 1, 0], [0, 1, 1]],
                ],
            ),
            // repeated and collinear vertices
            s(
                &[
                    [0, 0, 0],
                    [3, 0, 0],
                    [3, 0, 0],
                    [6, 0, 0],
                    [6, 6, 0],
                    [0, 6, 0],
                    [0, 0, 0],
                ],
                &[[[3, 0, 0], [3, 6, 0], [3, 0, 1]]],
            ),
            // the whole grid: a slanted triangle on the cube's corners
            s(
                &[[-m, -m, -m], [m, -m, m], [-m, m, m]],
                &[
                    [[m, m, -m], [-m, -m, m - 1], [m - 2, -m, 0]],
                    [[0, 0, 0], [1, 2, 3], [-m, m, -m]],
                ],
            ),
            // a face of the grid's cube, cut diagonally and near-parallel to an edge
            s(
                &[[-m, -m, m], [m, -m, m], [m, m, m], [-m, m, m]],
                &[
                    [[-m, -m, 0], [m, m, 0], [m, m, 1]],
                    [[-m, -m, 0], [m, -m + 1, 0], [0, 0, 1]],
                ],
            ),
            // a sliver of area 1/2 at the limit
            s(
                &[[-m, 0, 0], [m, 1, 0], [m - 2, 1, 0]],
                &[
                    [[0, -5, 0], [0, 5, 0], [0, 0, 1]],
                    [[m - 1, 0, 0], [m - 1, 1, 0], [m - 1, 0, 1]],
                ],
            ),
            // a tilted quad and a plane through three far points
            s(
                &[[0, 0, 0], [1000, 0, 1], [1000, 1000, 2], [0, 1000, 1]],
                &[
                    [[500, -m, 7], [499, m, -3], [501, 17, m]],
                    [[0, 0, 0], [1000, 1000, 2], [0, 0, 1]],
                ],
            ),
            // invalid polygons: a point, collinear, non-planar, a bow tie
            s(&[[5, 5, 5], [5, 5, 5], [5, 5, 5]], &[x1]),
            s(&[[0, 0, 0], [1, 1, 1], [2, 2, 2]], &[x1]),
            s(&[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 1]], &[x1]),
            s(&[[0, 0, 0], [2, 2, 0], [2, 0, 0], [0, 2, 0]], &[x1]),
            // collinear cut points are skipped
            s(&square, &[[[0, 0, 0], [1, 1, 1], [2, 2, 2]], x1]),
        ]
    }

    fn build_seeds() -> Vec<BuildInput> {
        let m = M32;
        let bi = |scene: Scene, eyes: &[[i64; 3]]| BuildInput {
            scene,
            candidates: 8,
            sample: 48,
            split_weight: 4,
            seed: 0x5eed,
            eyes: eyes.to_vec(),
        };
        let [unit, sheared, limit, flat] = seed_boxes();
        let [soup_shared, fan, crossing, invalid] = seed_soups();
        let far = MAX_VIEW_COORD;
        let mut worst = bi(Scene::Box(sheared.clone()), &[[0, 0, 0]]);
        worst.candidates = 1;
        worst.sample = 1;
        worst.split_weight = 0;
        vec![
            bi(Scene::Box(unit), &[[5, 5, 5], [0, 0, 0], [1, 0, 2]]),
            bi(Scene::Box(sheared), &[[1000, -77, 5], [-far, far, -far]]),
            bi(
                Scene::Box(limit),
                &[[far, far, far], [0, 0, 0], [m as i64, 0, 0]],
            ),
            bi(Scene::Box(flat), &[[50, 1, 50]]),
            worst,
            bi(soup_shared, &[[1, 1, 1], [2, 2, 0], [2, 2, -9]]),
            bi(fan, &[[0, 0, 0], [9, -9, 9]]),
            bi(crossing, &[[1, 2, 3], [-far, 0, 0], [0, 0, 0]]),
            bi(invalid, &[[0, 0, 0]]),
        ]
    }

    /// The boxes of the build seeds: a unit cube, a sheared, mirrored and
    /// moved box, one at the limits of the grid, and a flat one.
    fn seed_boxes() -> [BoxSolid; 4] {
        let m = M32;
        let unit = BoxSolid {
            lo: [0, 0, 0],
            hi: [1, 1, 1],
            splits: [0, 0, 0],
            triangulate: 0,
            shears: [(0, 0, 0); 3],
            mirror: false,
            offset: [0, 0, 0],
            probes: vec![],
            rational_probes: vec![([1, 1, 1], 2), ([2, 1, 1], 2), ([3, 1, 1], 2)],
        };
        let sheared = BoxSolid {
            lo: [-10, -3, 0],
            hi: [10, 7, 4],
            splits: [0, 2, 1],
            triangulate: 0b0110_1101,
            shears: [(0, 1, 3), (2, 0, -2), (1, 2, 5)],
            mirror: true,
            offset: [1000, -77, 5],
            probes: vec![
                [-10, 0, 2],
                [-11, 0, 2],
                [0, 2, 1],
                [10, 7, 4],
                [9, 6, 3],
                [0, 8, 0],
            ],
            rational_probes: vec![
                ([-10 * 4096 + 1, 1, 1], 4096),
                ([-10 * 4096 - 1, 1, 1], 4096),
                ([0, 2 * 3, 3], 3),
                ([1, 1, 1], 1 << 24),
            ],
        };
        let limit = BoxSolid {
            lo: [-m, -m, -m],
            hi: [m, m, m],
            splits: [0, 0, 0],
            triangulate: 0b0011_1111,
            shears: [(0, 0, 0); 3],
            mirror: false,
            offset: [0, 0, 0],
            probes: vec![[m, 0, 0], [m - 1, m - 1, m - 1], [0, 0, 0], [-m, -m, 5]],
            rational_probes: vec![
                ([m as i64 * 3 - 1, 0, 0], 3),
                ([m as i64 * 3 + 1, 0, 0], 3),
                ([m as i64 * (1 << 20), 1, -1], 1 << 20),
            ],
        };
        let flat = BoxSolid {
            lo: [0, 0, 0],
            hi: [100, 1, 100],
            splits: [50, 0, 50],
            triangulate: 0,
            shears: [(1, 0, 1), (0, 0, 0), (0, 0, 0)],
            mirror: false,
            offset: [0, 0, 0],
            probes: vec![[50, 0, 50], [50, 1, 50], [50, 2, 50], [1, 1, 1]],
            rational_probes: vec![([100, 1, 100], 2)],
        };
        [unit, sheared, limit, flat]
    }

    /// The polygon soups of the build seeds: triangles sharing edges with
    /// two quads (and a repeated triangle), a fan over six points, three
    /// planes and a triangle at the limits of the grid, and invalid
    /// polygons.
    fn seed_soups() -> [Scene; 4] {
        let m = M32;
        let tri = |a: GridPoint, b: GridPoint, c: GridPoint| vec![a, b, c];
        let soup_shared = Scene::Soup(vec![
            tri([0, 0, 0], [4, 0, 0], [0, 4, 0]),
            tri([4, 0, 0], [4, 4, 0], [0, 4, 0]),
            tri([0, 4, 0], [4, 0, 0], [0, 0, 0]),
            vec![[2, -1, -2], [2, 5, -2], [2, 5, 2], [2, -1, 2]],
            vec![[-1, 2, -2], [-1, 2, 2], [5, 2, 2], [5, 2, -2]],
            tri([0, 0, 0], [4, 0, 0], [0, 4, 0]),
        ]);
        let pool = [
            [0, 0, 0],
            [3, 0, 1],
            [0, 3, 2],
            [3, 3, -1],
            [1, 1, 5],
            [2, 2, -4],
        ];
        let fan = Scene::Soup(
            (0..12)
                .map(|i| tri(pool[i % 6], pool[(i + 1) % 6], pool[(i * 5 + 3) % 6]))
                .collect(),
        );
        let crossing = Scene::Soup(vec![
            vec![[-m, -m, 0], [m, -m, 0], [m, m, 0], [-m, m, 0]],
            vec![[-m, 0, -m], [-m, 0, m], [m, 0, m], [m, 0, -m]],
            vec![[0, -m, -m], [0, m, -m], [0, m, m], [0, -m, m]],
            tri([-m, -m, -m], [m, -m + 1, m], [m - 3, m, -m]),
        ]);
        let invalid = Scene::Soup(vec![
            tri([0, 0, 0], [1, 1, 1], [2, 2, 2]),
            tri([3, 3, 3], [3, 3, 3], [3, 3, 3]),
            vec![[0, 0, 0], [2, 2, 0], [2, 0, 0], [0, 2, 0]],
        ]);
        [soup_shared, fan, crossing, invalid]
    }

    /// Raw byte strings for the corpus: empty, constant, and random ones
    /// with each leading mode byte.
    fn raw_seeds(n: usize, modes: u8) -> Vec<Vec<u8>> {
        let mut v = vec![vec![], vec![0xff; 64], (0..=255).collect()];
        for i in 0..n {
            let mut b = random_bytes(i as u64 + 1, 24 + 16 * i);
            b[0] = (i % modes as usize) as u8;
            v.push(b);
        }
        v
    }

    fn seed_files(target: &str) -> Vec<(String, Vec<u8>)> {
        let (named, raw): (Vec<Vec<u8>>, Vec<Vec<u8>>) = match target {
            "split" => (
                split_seeds().iter().map(SplitInput::encode).collect(),
                raw_seeds(8, 4),
            ),
            _ => (
                build_seeds().iter().map(BuildInput::encode).collect(),
                raw_seeds(8, 4),
            ),
        };
        let named = named
            .into_iter()
            .enumerate()
            .map(|(i, b)| (format!("seed-{i:02}"), b));
        let raw = raw
            .into_iter()
            .enumerate()
            .map(|(i, b)| (format!("seed-raw-{i:02}"), b));
        named.chain(raw).collect()
    }

    /// Rewrites the `seed-*` files of `fuzz/corpus/` from the seeds above:
    /// `cargo test -p bsp-testkit --lib tests::write_seed_corpus -- --ignored`.
    #[test]
    #[ignore = "writes fuzz/corpus; run by hand after changing the seeds or the decoders"]
    fn write_seed_corpus() {
        for target in ["split", "build_tree"] {
            let dir = corpus_dir(target);
            std::fs::create_dir_all(&dir).unwrap();
            for e in std::fs::read_dir(&dir).unwrap() {
                let p = e.unwrap().path();
                if p.file_name()
                    .unwrap()
                    .to_string_lossy()
                    .starts_with("seed-")
                {
                    std::fs::remove_file(p).unwrap();
                }
            }
            for (name, bytes) in seed_files(target) {
                std::fs::write(dir.join(name), bytes).unwrap();
            }
        }
    }

    #[test]
    fn seed_corpus_is_up_to_date() {
        for target in ["split", "build_tree"] {
            for (name, bytes) in seed_files(target) {
                let path = corpus_dir(target).join(&name);
                let on_disk = std::fs::read(&path)
                    .unwrap_or_else(|e| panic!("{}: {e} (run write_seed_corpus)", path.display()));
                assert!(
                    on_disk == bytes,
                    "{} is stale (run write_seed_corpus)",
                    path.display()
                );
            }
        }
    }

    #[test]
    fn seeds_round_trip_through_bytes() {
        for s in split_seeds() {
            assert_eq!(SplitInput::decode(&s.encode()), s);
        }
        for s in build_seeds() {
            assert_eq!(BuildInput::decode(&s.encode()), s);
        }
    }

    /// Runs `check` on the input, printing it as a Rust expression if the
    /// kernel panics (the checks themselves already print it).
    fn run_reporting<T: Debug, R>(name: &str, input: &T, check: impl FnOnce(&T) -> R) -> R {
        match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| check(input))) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("{name} failed; decoded input:\n{input:?}");
                std::panic::resume_unwind(e)
            }
        }
    }

    fn corpus_files(target: &str) -> Vec<PathBuf> {
        let mut files: Vec<PathBuf> = std::fs::read_dir(corpus_dir(target))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.is_file() && !p.file_name().unwrap().to_string_lossy().starts_with('.'))
            .collect();
        // BSP_CHECK_REPLAY=<file or directory>: also run those (e.g. a crash artifact)
        if let Some(extra) = std::env::var_os(format!("BSP_CHECK_REPLAY_{}", target.to_uppercase()))
        {
            let extra = PathBuf::from(extra);
            if extra.is_dir() {
                files.extend(std::fs::read_dir(extra).unwrap().map(|e| e.unwrap().path()));
            } else {
                files.push(extra);
            }
        }
        files.sort();
        files
    }

    #[test]
    fn split_corpus_passes_and_covers_the_cases() {
        let mut total = SplitReport::default();
        let mut valid = 0;
        let files = corpus_files("split");
        assert!(
            files.len() >= 10,
            "fuzz/corpus/split has {} files",
            files.len()
        );
        for f in &files {
            let input = SplitInput::decode(&std::fs::read(f).unwrap());
            let r = run_reporting(&f.display().to_string(), &input, SplitInput::check);
            valid += usize::from(r.valid);
            total.spanning += r.spanning;
            total.one_sided += r.one_sided;
            total.coplanar += r.coplanar;
            total.through_vertex += r.through_vertex;
        }
        eprintln!(
            "split corpus: {} files, {valid} valid polygons, {total:?}",
            files.len()
        );
        assert!(valid >= files.len() / 2, "only {valid} valid polygons");
        assert!(total.spanning >= 10, "{total:?}");
        assert!(total.through_vertex >= 3, "{total:?}");
        assert!(total.one_sided >= 3 && total.coplanar >= 2, "{total:?}");
    }

    #[test]
    fn build_corpus_passes_and_covers_the_cases() {
        let mut total = BuildReport::default();
        let files = corpus_files("build_tree");
        assert!(
            files.len() >= 10,
            "fuzz/corpus/build_tree has {} files",
            files.len()
        );
        for f in &files {
            let input = BuildInput::decode(&std::fs::read(f).unwrap());
            let r = run_reporting(&f.display().to_string(), &input, BuildInput::check);
            total.fragments += r.fragments;
            total.traversals += r.traversals;
            total.implicit_probes += r.implicit_probes;
            for k in 0..3 {
                total.membership[k] += r.membership[k];
            }
        }
        eprintln!("build corpus: {} files, {total:?}", files.len());
        assert!(
            total.fragments >= 100 && total.traversals >= 20,
            "{total:?}"
        );
        assert!(total.membership.iter().all(|&n| n >= 10), "{total:?}");
        assert!(total.implicit_probes >= 10, "{total:?}");
    }

    #[test]
    fn random_bytes_pass() {
        let mut spanning = 0;
        let mut membership = 0;
        for i in 0..400u64 {
            let b = random_bytes(0xabcd + i, (i as usize * 7) % 300);
            let s = SplitInput::decode(&b);
            spanning += run_reporting("split", &s, SplitInput::check).spanning;
            let t = BuildInput::decode(&b);
            membership += run_reporting("build", &t, BuildInput::check)
                .membership
                .iter()
                .sum::<usize>();
        }
        eprintln!("random bytes: {spanning} spans, {membership} probes");
        // random bytes reach the interesting paths, not only early returns
        assert!(
            spanning >= 50 && membership >= 50,
            "{spanning} spans, {membership} probes"
        );
    }

    #[test]
    fn splits_of_a_square() {
        let r = split_seeds()[0].check();
        assert!(r.valid);
        // x = 1 cuts the square; the diagonal cuts both pieces, through a vertex each
        assert_eq!((r.spanning, r.through_vertex, r.pieces), (3, 2, 4));
    }

    fn panic_message(f: impl FnOnce()) -> String {
        let e = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_err();
        *e.downcast::<String>().unwrap()
    }

    #[test]
    fn cover_check_catches_lost_and_stray_pieces() {
        let sq =
            Polygon::from_grid_points(&[[0, 0, 0], [4, 0, 0], [4, 4, 0], [0, 4, 0]], 0).unwrap();
        let Split::Spanning { front, back } = sq.clone().split(&Plane::new([1, 0, 0], -1).unwrap())
        else {
            panic!("x = 1 spans the square")
        };
        check_cover(&"demo", &sq, &[&front, &back], "both pieces");
        let msg = panic_message(|| check_cover(&"demo", &sq, &[&front], "one piece"));
        assert!(msg.contains("one piece: the pieces' area vector"), "{msg}");
        let big =
            Polygon::from_grid_points(&[[0, 0, 0], [5, 0, 0], [5, 4, 0], [0, 4, 0]], 0).unwrap();
        let msg = panic_message(|| check_cover(&"demo", &sq, &[&big], "stray"));
        assert!(msg.contains("is outside edge plane"), "{msg}");
        let tilted = Polygon::from_grid_points(&[[0, 0, 0], [4, 0, 1], [0, 4, 0]], 0).unwrap();
        let msg = panic_message(|| check_cover(&"demo", &sq, &[&tilted], "tilted"));
        assert!(msg.contains("has support"), "{msg}");
    }

    #[test]
    fn failures_print_the_input_as_rust() {
        let input = SplitInput {
            polygon: vec![[0, 0, 0], [1, 0, 0], [0, 1, 0]],
            cuts: vec![[[0, 0, 0], [0, 1, 0], [0, 0, 1]]],
        };
        let msg = panic_message(|| fail(&input, format_args!("demo")));
        assert!(msg.starts_with("check failed: demo"), "{msg}");
        assert!(
            msg.contains(
                "SplitInput { polygon: vec![[0, 0, 0], [1, 0, 0], [0, 1, 0]], \
                 cuts: vec![[[0, 0, 0], [0, 1, 0], [0, 0, 1]]] }"
            ),
            "{msg}"
        );
        let b = format!("{:?}", build_seeds()[1]);
        assert!(
            b.starts_with("BuildInput { scene: Scene::Box(BoxSolid { lo: [-10, -3, 0]"),
            "{b}"
        );
        assert!(b.contains("probes: vec![[-10, 0, 2]"), "{b}");
        let soup = format!("{:?}", build_seeds()[5].scene);
        assert!(
            soup.starts_with("Scene::Soup(vec![vec![[0, 0, 0]"),
            "{soup}"
        );
    }
}
