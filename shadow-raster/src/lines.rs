//! Roberts' hidden-line algorithm for convex polyhedra (seed 004), with a
//! cross-check against the z-buffer.
//!
//! The scene's polyhedra (prims joined across edges that exactly two of
//! them share, in opposite directions) must be closed. Every edge between two faces of different
//! planes is a candidate; an edge whose two faces both turn their back to
//! the eye is self-hidden. The scene is mapped to *perspective space*,
//! `(x/z, y/z, 1/z)` in camera coordinates, a projective map that keeps
//! planes and convexity and makes every line of sight parallel to the
//! third axis. There a point `P` is hidden by a polyhedron `B` when the
//! ray `P + α e₃` (`α > 0`, toward the eye) enters `B`'s interior:
//! `Nᵢ · (P(t) + α e₃) + Dᵢ < 0` for all of `B`'s faces `i`. For an edge
//! `P(t)`, `t ∈ [0, 1]`, these are linear inequalities in `(t, α)` (the
//! volume matrix of Roberts), and the hidden part of the edge is the
//! projection on `t` of the convex polygon they cut from
//! `[0, 1] × [0, ∞)`. The visible parts are what is left after every other
//! polyhedron.
//!
//! A closed polyhedron that is not convex (the room's flower pot) is cut
//! into convex cells, the inside cells of its own BSP tree, and tested
//! cell by cell, against its own edges too.

use std::collections::HashMap;
use std::fmt::Write;

use bsp_core::Plane;
use glam::{DVec2, DVec3};

use crate::hsr::{Frame, Hsr, NONE, visibility};
use crate::scene::{EdgeKey, RasterScene, point_key as key};
use crate::{Camera, RasterError};

/// Relative margin of Roberts' inequalities: a point must be inside a
/// polyhedron by this much (relative to the inequality's size) to be
/// hidden, so edges lying on another object's surface stay visible.
pub const LINE_EPSILON: f64 = 1e-9;

/// An edge's parts, in pixel coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct HiddenLines {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Visible parts of edges.
    pub visible: Vec<[DVec2; 2]>,
    /// Hidden parts of edges (self-hidden edges included).
    pub hidden: Vec<[DVec2; 2]>,
    /// Candidate edges (between faces of different planes).
    pub edges: usize,
    /// Closed polyhedra.
    pub polyhedra: usize,
    /// How many of them are convex (the others are cut into the convex
    /// cells of their BSP tree).
    pub convex: usize,
    /// The cross-check against the z-buffer.
    pub check: LineCheck,
}

/// Points of the result checked against the z-buffer: the midpoint of every
/// part at least a few pixels long, visible when the z-buffer's surface
/// there is not nearer than the edge (or is one of the edge's own
/// polyhedron), hidden when it is clearly nearer and belongs to another.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LineCheck {
    /// Points checked.
    pub checked: usize,
    /// Points where Roberts and the z-buffer agree.
    pub agree: usize,
}

impl HiddenLines {
    /// One line: the polyhedra, edges and parts drawn, and how many of the
    /// points checked against a z-buffer agree.
    pub fn summary(&self) -> String {
        format!(
            "{} polyhedra ({} convex), {} edges, {} visible and {} hidden parts; z-buffer \
             check: {} of {} points agree",
            self.polyhedra,
            self.convex,
            self.edges,
            self.visible.len(),
            self.hidden.len(),
            self.check.agree,
            self.check.checked
        )
    }

    /// The drawing as SVG: visible lines black, hidden ones (if `hidden`)
    /// dashed grey.
    pub fn svg(&self, hidden: bool) -> String {
        let (w, h) = (self.width, self.height);
        let mut s = String::new();
        let _ = writeln!(s, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
        let _ = writeln!(
            s,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}">"#
        );
        let _ = writeln!(
            s,
            "<!-- shadow lines: Roberts' hidden-line algorithm, {} polyhedra, {} edges -->",
            self.polyhedra, self.edges
        );
        let _ = writeln!(s, r##"<rect width="{w}" height="{h}" fill="#ffffff"/>"##);
        let path = |segs: &[[DVec2; 2]]| {
            let mut d = String::new();
            for [a, b] in segs {
                let _ = write!(d, "M{:.2},{:.2}L{:.2},{:.2}", a.x, a.y, b.x, b.y);
            }
            d
        };
        if hidden && !self.hidden.is_empty() {
            let _ = writeln!(
                s,
                r##"<path d="{}" stroke="#b0b4ba" stroke-width="0.8" stroke-dasharray="3,3" fill="none"/>"##,
                path(&self.hidden)
            );
        }
        let _ = writeln!(
            s,
            r##"<path d="{}" stroke="#1a1c20" stroke-width="1.2" stroke-linecap="round" fill="none"/>"##,
            path(&self.visible)
        );
        s.push_str("</svg>\n");
        s
    }
}

/// A polyhedron in perspective space: convex cells, each the points with
/// `N · Q + D < 0` for all its planes, whose union is the solid (one cell,
/// its faces, for a convex polyhedron; the inside cells of its BSP tree
/// otherwise), and its bounding box.
struct Solid {
    cells: Vec<Vec<(DVec3, f64)>>,
    convex: bool,
    lo: DVec3,
    hi: DVec3,
}

/// The inside cells of a closed polyhedron's BSP tree, each as the planes
/// (oriented with the cell behind) along its path.
fn bsp_cells(polys: Vec<bsp_core::Polygon>) -> Vec<Vec<Plane>> {
    use bsp_core::{BspTree, BuildOptions, Cell, Link};
    let tree = BspTree::build(polys, &BuildOptions::default());
    let mut out = Vec::new();
    let mut stack: Vec<(Link, Vec<Plane>)> = vec![(tree.root(), Vec::new())];
    while let Some((link, path)) = stack.pop() {
        match link {
            Link::Cell(Cell::In) => out.push(path),
            Link::Cell(_) => {}
            Link::Node(id) => {
                let n = tree.node(id);
                let mut front = path.clone();
                front.push(n.plane.flip());
                let mut back = path;
                back.push(n.plane);
                stack.push((n.front, front));
                stack.push((n.back, back));
            }
        }
    }
    out
}

/// Roberts' hidden lines of `scene` from `camera`.
pub fn hidden_lines(scene: &RasterScene, camera: &Camera) -> Result<HiddenLines, RasterError> {
    let frame = Frame::new(scene, camera, false)?;
    let view = frame.view();
    let (kx, ky) = match view.kind {
        crate::view::Kind::Perspective { kx, ky } => (kx, ky),
        crate::view::Kind::Orthographic { .. } => unreachable!("the camera is perspective"),
    };
    let (w, h) = (view.width as f64, view.height as f64);
    let (obj, count) = polyhedra(scene);
    let diag = scene.diagonal();
    let eye = camera.eye();
    // camera and perspective-space coordinates
    let space = Perspective {
        view,
        eye,
        diag,
        kx,
        ky,
        w,
        h,
    };
    // the prims of each object
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); count];
    for (i, &o) in obj.iter().enumerate() {
        members[o as usize].push(i);
    }
    let mut solids = Vec::with_capacity(count);
    let mut edges: Vec<Candidate> = Vec::new();
    for (o, prims) in members.iter().enumerate() {
        candidate_edges(scene, o, prims, &mut edges)?;
        solids.push(perspective_solid(scene, o, prims, &space)?);
    }
    edges.sort_by(|x, y| {
        (x.1.to_array(), x.2.to_array())
            .partial_cmp(&(y.1.to_array(), y.2.to_array()))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    let back = |i: usize| {
        let (n, d) = scene.plane[i];
        n.dot(eye) + d <= 0.0
    };
    let mut out = HiddenLines {
        width: view.width,
        height: view.height,
        visible: Vec::new(),
        hidden: Vec::new(),
        edges: edges.len(),
        polyhedra: count,
        convex: solids.iter().filter(|s| s.convex).count(),
        check: LineCheck::default(),
    };
    let vis = visibility(&frame, Hsr::ZBuffer);
    let zbuffer = ZBufferCheck {
        space: &space,
        vis: &vis,
        obj: &obj,
        solids: &solids,
    };
    for &(o, a, b, i, j) in &edges {
        let (qa, qb) = (
            space.to_q(a).expect("checked"),
            space.to_q(b).expect("checked"),
        );
        if back(i) && back(j) {
            out.hidden.push([space.to_px(qa), space.to_px(qb)]);
            continue;
        }
        let hidden = hidden_by(&solids, o, qa, qb);
        let parts = subtract(&hidden);
        let hidden = merge(hidden);
        let at = |t: f64| qa + (qb - qa) * t;
        for &(t0, t1) in &parts {
            out.visible.push([space.to_px(at(t0)), space.to_px(at(t1))]);
        }
        for &(t0, t1) in &hidden {
            out.hidden.push([space.to_px(at(t0)), space.to_px(at(t1))]);
        }
        // the cross-check at the midpoints of long enough parts
        zbuffer.check(&mut out.check, o, (qa, qb), &parts, true);
        zbuffer.check(&mut out.check, o, (qa, qb), &hidden, false);
    }
    Ok(out)
}

/// A candidate edge: its polyhedron, its ends `a`, `b` and its two prims.
type Candidate = (usize, DVec3, DVec3, usize, usize);

/// Perspective space of a camera: a point `(x/z, y/z, 1/z)` for camera
/// coordinates `(x, y, z)`, and the image's pixels.
struct Perspective<'a> {
    view: &'a crate::view::View,
    eye: DVec3,
    /// The scene's diagonal: a point must be farther than a billionth of
    /// it in front of the eye.
    diag: f64,
    /// `tan` of half the horizontal and vertical fields of view.
    kx: f64,
    ky: f64,
    /// The image's size in pixels.
    w: f64,
    h: f64,
}

impl Perspective<'_> {
    /// World point `p` in perspective space (`None` when not in front of
    /// the eye).
    fn to_q(&self, p: DVec3) -> Option<DVec3> {
        let c = self.view.frame(p);
        (c.z > 1e-9 * self.diag).then(|| DVec3::new(c.x / c.z, c.y / c.z, 1.0 / c.z))
    }

    /// The pixel coordinates of perspective-space point `q`.
    fn to_px(&self, q: DVec3) -> DVec2 {
        DVec2::new(
            0.5 * self.w * (1.0 + q.x / self.kx),
            0.5 * self.h * (1.0 - q.y / self.ky),
        )
    }
}

/// Polyhedron `o` (prims `prims`) named for an error message.
fn describe(scene: &RasterScene, o: usize, prims: &[usize]) -> String {
    format!(
        "polyhedron {o} (faces {}..={} of the input)",
        prims.iter().map(|&i| scene.face[i]).min().unwrap_or(0),
        prims.iter().map(|&i| scene.face[i]).max().unwrap_or(0)
    )
}

/// Checks that polyhedron `o` (prims `prims`) is closed, every directed
/// edge meeting its reverse once, and adds its candidate edges (between
/// faces of different planes) to `edges`.
fn candidate_edges(
    scene: &RasterScene,
    o: usize,
    prims: &[usize],
    edges: &mut Vec<Candidate>,
) -> Result<(), RasterError> {
    // closed: every directed edge meets its reverse once
    let mut directed: HashMap<EdgeKey, (usize, DVec3, DVec3)> = HashMap::new();
    for &i in prims {
        let pts = scene.prim(i);
        for k in 0..pts.len() {
            let (a, b) = (pts[k], pts[(k + 1) % pts.len()]);
            if directed.insert((key(a), key(b)), (i, a, b)).is_some() {
                return Err(RasterError::NotConvex(format!(
                    "{}: an edge is used twice the same way; Roberts' hidden lines need closed, \
                     consistently oriented polyhedra",
                    describe(scene, o, prims)
                )));
            }
        }
    }
    for (&(ka, kb), &(i, a, b)) in &directed {
        let Some(&(j, _, _)) = directed.get(&(kb, ka)) else {
            return Err(RasterError::NotConvex(format!(
                "{}: it is not closed (a border edge); Roberts' hidden lines need closed \
                 polyhedra",
                describe(scene, o, prims)
            )));
        };
        if ka < kb && !scene.support[i].is_coincident(&scene.support[j]) {
            edges.push((o, a, b, i, j));
        }
    }
    Ok(())
}

/// Polyhedron `o` (prims `prims`) as a [`Solid`] in perspective space:
/// one cell of its face planes when it is convex, else the inside cells
/// of its BSP tree. Errors if it reaches behind the eye.
fn perspective_solid(
    scene: &RasterScene,
    o: usize,
    prims: &[usize],
    space: &Perspective<'_>,
) -> Result<Solid, RasterError> {
    let (view, eye, diag) = (space.view, space.eye, space.diag);
    // convex when every vertex is behind or on every face plane
    let mut planes: Vec<Plane> = prims.iter().map(|&i| scene.support[i]).collect();
    planes.sort_by_key(|p| (p.normal(), p.offset()));
    planes.dedup();
    let convex = planes.iter().all(|p| {
        let (n, d) = crate::scene::world_plane(&scene.grid, p);
        prims
            .iter()
            .all(|&i| scene.prim(i).iter().all(|v| n.dot(*v) + d <= 1e-9 * diag))
    });
    let cells = if convex {
        vec![planes]
    } else {
        bsp_cells(prims.iter().map(|&i| scene.polys[i].clone()).collect())
    };
    // perspective space
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for &i in prims {
        for v in scene.prim(i) {
            let Some(q) = space.to_q(*v) else {
                return Err(RasterError::BehindEye(format!(
                    "{} reaches behind the eye; Roberts' algorithm needs the scene in front \
                     of it",
                    describe(scene, o, prims)
                )));
            };
            lo = lo.min(q);
            hi = hi.max(q);
        }
    }
    let to_qplane = |p: &Plane| {
        let (n, d) = crate::scene::world_plane(&scene.grid, p);
        // n · (eye + c.x r + c.y u + c.z f) + d = 0, times 1/c.z > 0
        let (nr, nu, nf) = (n.dot(view.r), n.dot(view.u), n.dot(view.f));
        let s = n.dot(eye) + d;
        (DVec3::new(nr, nu, s), nf)
    };
    let cells = cells
        .iter()
        .map(|c| c.iter().map(to_qplane).collect())
        .collect();
    Ok(Solid {
        cells,
        convex,
        lo,
        hi,
    })
}

/// The `t`-ranges of edge `qa → qb` (of polyhedron `o`) that the cells of
/// `solids` hide, unsorted and possibly overlapping. Only a solid nearer
/// than some of the edge and overlapping it on screen is tried, and the
/// edge's own polyhedron only when it is not convex.
fn hidden_by(solids: &[Solid], o: usize, qa: DVec3, qb: DVec3) -> Vec<(f64, f64)> {
    let mut hidden: Vec<(f64, f64)> = Vec::new();
    let (elo, ehi) = (qa.min(qb), qa.max(qb));
    for (k, s) in solids.iter().enumerate() {
        // only a solid nearer than some of the edge, overlapping it on screen
        if (k == o && s.convex)
            || s.hi.z <= elo.z
            || s.hi.x < elo.x
            || s.lo.x > ehi.x
            || s.hi.y < elo.y
            || s.lo.y > ehi.y
        {
            continue;
        }
        for cell in &s.cells {
            if let Some(iv) = hidden_interval(cell, s.hi.z, qa, qb) {
                hidden.push(iv);
            }
        }
    }
    hidden
}

/// What the cross-check against the z-buffer looks at (see
/// [`LineCheck`]).
struct ZBufferCheck<'a> {
    space: &'a Perspective<'a>,
    vis: &'a crate::hsr::VisibilityBuffer,
    /// Each prim's polyhedron.
    obj: &'a [u32],
    solids: &'a [Solid],
}

impl ZBufferCheck<'_> {
    /// Checks the `parts` of edge `qa → qb` (of polyhedron `o`), all
    /// `visible` or all hidden, against the z-buffer at their midpoints,
    /// those at least a few pixels long and on the image, and counts them
    /// in `check`.
    fn check(
        &self,
        check: &mut LineCheck,
        o: usize,
        (qa, qb): (DVec3, DVec3),
        parts: &[(f64, f64)],
        visible: bool,
    ) {
        let (space, vis) = (self.space, self.vis);
        let (w, h) = (space.w, space.h);
        let at = |t: f64| qa + (qb - qa) * t;
        for &(t0, t1) in parts {
            let (p0, p1) = (space.to_px(at(t0)), space.to_px(at(t1)));
            if p0.distance(p1) < 6.0 {
                continue;
            }
            let q = at(0.5 * (t0 + t1));
            let px = space.to_px(q);
            if !(0.0..w).contains(&px.x) || !(0.0..h).contains(&px.y) {
                continue;
            }
            let pix = px.y as usize * space.view.width as usize + px.x as usize;
            let z = 1.0 / q.z;
            let (prim, zb) = (vis.prim[pix], 1.0 / vis.w[pix]);
            let own = prim != NONE && self.obj[prim as usize] as usize == o;
            let ok = if visible {
                prim == NONE || own || zb >= z * (1.0 - 1e-3)
            } else {
                prim != NONE && (!own || !self.solids[o].convex) && zb < z
            };
            check.checked += 1;
            check.agree += ok as usize;
        }
    }
}

/// The scene's polyhedra: prims joined across every edge that exactly two
/// prims use, once in each direction (so solids touching along an edge or
/// at a vertex stay apart). Returns each prim's polyhedron.
fn polyhedra(scene: &RasterScene) -> (Vec<u32>, usize) {
    let mut uses: HashMap<EdgeKey, Vec<(usize, bool)>> = HashMap::new();
    for i in 0..scene.len() {
        let pts = scene.prim(i);
        for k in 0..pts.len() {
            let (a, b) = (key(pts[k]), key(pts[(k + 1) % pts.len()]));
            let (e, fwd) = if a < b {
                ((a, b), true)
            } else {
                ((b, a), false)
            };
            uses.entry(e).or_default().push((i, fwd));
        }
    }
    let mut pairs: Vec<(usize, usize)> = uses
        .values()
        .filter(|u| u.len() == 2 && u[0].1 != u[1].1)
        .map(|u| (u[0].0.min(u[1].0), u[0].0.max(u[1].0)))
        .collect();
    pairs.sort_unstable();
    crate::scene::components(scene.len(), pairs)
}

/// The `t`-range of edge `qa → qb` hidden by solid `s`: the projection on
/// `t` of `{(t, α) ∈ [0,1] × [0, A] : Nᵢ · (P(t) + α e₃) + Dᵢ < 0 ∀ i}`.
fn hidden_interval(cell: &[(DVec3, f64)], top: f64, qa: DVec3, qb: DVec3) -> Option<(f64, f64)> {
    let depth = (top - qa.z.min(qb.z)).max(0.0) * 2.0 + 1.0;
    let mut poly = vec![
        DVec2::new(0.0, 0.0),
        DVec2::new(1.0, 0.0),
        DVec2::new(1.0, depth),
        DVec2::new(0.0, depth),
    ];
    let d = qb - qa;
    for &(n, off) in cell {
        // a t + b α + c < 0
        let (a, b, c) = (n.dot(d), n.z, n.dot(qa) + off);
        let margin = LINE_EPSILON * (a.abs() + b.abs() * depth + c.abs()).max(1e-300);
        let mut next = Vec::with_capacity(poly.len() + 1);
        let k = poly.len();
        for i in 0..k {
            let (p, q) = (poly[i], poly[(i + 1) % k]);
            let (fp, fq) = (
                -(a * p.x + b * p.y + c) - margin,
                -(a * q.x + b * q.y + c) - margin,
            );
            if fp >= 0.0 {
                next.push(p);
            }
            if (fp >= 0.0) != (fq >= 0.0) {
                next.push(p + (q - p) * (fp / (fp - fq)));
            }
        }
        poly = next;
        if poly.len() < 3 {
            return None;
        }
    }
    let t0 = poly
        .iter()
        .map(|p| p.x)
        .fold(f64::INFINITY, f64::min)
        .max(0.0);
    let t1 = poly
        .iter()
        .map(|p| p.x)
        .fold(f64::NEG_INFINITY, f64::max)
        .min(1.0);
    (t1 > t0).then_some((t0, t1))
}

/// Sorted union of intervals.
fn merge(mut v: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out: Vec<(f64, f64)> = Vec::new();
    for (a, b) in v {
        match out.last_mut() {
            Some(last) if a <= last.1 => last.1 = last.1.max(b),
            _ => out.push((a, b)),
        }
    }
    out
}

/// `[0, 1]` less the union of `hidden`.
fn subtract(hidden: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let mut t = 0.0;
    for (a, b) in merge(hidden.to_vec()) {
        if a > t {
            out.push((t, a));
        }
        t = t.max(b);
    }
    if t < 1.0 {
        out.push((t, 1.0));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interval_arithmetic() {
        assert_eq!(
            subtract(&[(0.2, 0.4), (0.3, 0.5)]),
            vec![(0.0, 0.2), (0.5, 1.0)]
        );
        assert_eq!(subtract(&[(0.0, 1.0)]), Vec::<(f64, f64)>::new());
        assert_eq!(
            merge(vec![(0.5, 0.6), (0.1, 0.2)]),
            vec![(0.1, 0.2), (0.5, 0.6)]
        );
    }
}
