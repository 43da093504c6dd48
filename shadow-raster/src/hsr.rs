//! Visibility: the visible prim and its nearness at every pixel, by five
//! methods of seed 004 that agree pixel for pixel.
//!
//! They share one definition of the answer, so that they can agree
//! exactly: a prim *covers* a pixel when the pixel's centre is inside its
//! fixed-point projection by the top-left rule (see the `raster` module);
//! its nearness there is `a·xc + (b·yc + c)` from its plane (perspective-
//! correct, the same bits in every method); the visible prim is the
//! covering prim of greatest nearness, the lower prim index on a tie
//! (coplanar prims get bit-identical nearness from their exact plane).
//! The methods differ in how they find it:
//!
//! - `zbuffer`: every prim scan-converted into a depth buffer, bands of rows
//!   in parallel;
//! - `scanline`: Watkins-style scan-line z-buffer, top to bottom with an
//!   active-polygon list and a one-row depth buffer;
//! - `warnock`: area subdivision; a window is empty, filled by its only
//!   polygon, filled by a polygon surrounding it and nearer than all others
//!   at its corners, or split in four, down to single pixels;
//! - `raycast`: one ray per pixel through a BVH, nearest hit first, the
//!   ray-polygon test done on the polygon's projection;
//! - `bsp`: the scene's BSP tree walked front to back from the eye, each
//!   pixel taken by the first piece that covers it (a piece covers what its
//!   prim covers, cut exactly by its splitting planes).
//!
//! Back-face culling (prims whose back faces the eye are left out) is an
//! option of all five.

use bsp_core::{BspTree, BuildOptions, Order, Plane, Side};
use glam::DVec3;
use rayon::prelude::*;

use crate::bvh::Bvh;
use crate::raster::{
    Bins, Corners, Projector, Screen, for_bands2, nearness, project_all_into, row_term,
};
use crate::scene::RasterScene;
use crate::view::View;
use crate::{Camera, RasterError};

/// No prim at this pixel.
pub const NONE: u32 = u32::MAX;

/// A visible-surface method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Hsr {
    /// Depth buffer.
    ZBuffer,
    /// Scan-line z-buffer.
    Scanline,
    /// Warnock's area subdivision.
    Warnock,
    /// Ray casting through a BVH.
    Raycast,
    /// Front-to-back traversal of the scene's BSP tree.
    Bsp,
}

impl Hsr {
    /// Every method, in the order of the docs.
    pub const ALL: [Hsr; 5] = [
        Hsr::ZBuffer,
        Hsr::Scanline,
        Hsr::Warnock,
        Hsr::Raycast,
        Hsr::Bsp,
    ];

    /// The method's name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Hsr::ZBuffer => "zbuffer",
            Hsr::Scanline => "scanline",
            Hsr::Warnock => "warnock",
            Hsr::Raycast => "raycast",
            Hsr::Bsp => "bsp",
        }
    }
}

impl std::str::FromStr for Hsr {
    type Err = crate::error::UnknownName;

    /// The method of a name (see [`Hsr::name`]), spaces around it ignored.
    fn from_str(s: &str) -> Result<Hsr, Self::Err> {
        let s = s.trim();
        Hsr::ALL
            .into_iter()
            .find(|h| h.name() == s)
            .ok_or_else(|| crate::error::UnknownName {
                what: "visibility method",
                name: s.to_string(),
                available: Hsr::ALL.map(Hsr::name).join(", "),
            })
    }
}

/// The visible prim and its nearness per pixel, row-major from the
/// top-left corner.
#[derive(Clone, Debug, PartialEq)]
pub struct VisibilityBuffer {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// The visible prim of every pixel, [`NONE`] for the background.
    pub prim: Vec<u32>,
    /// Nearness (`1/z`, `z` the depth along the view direction) of the
    /// visible prim at the pixel's centre; 0 for the background.
    pub w: Vec<f64>,
}

impl VisibilityBuffer {
    /// Number of pixels where `self` and `o` see different prims.
    pub fn differences(&self, o: &VisibilityBuffer) -> usize {
        self.prim
            .iter()
            .zip(&o.prim)
            .filter(|(a, b)| a != b)
            .count()
    }
}

/// A camera and a scene made ready for drawing: the camera with its near
/// plane, the visible side of every prim, the prims projected.
pub(crate) struct Frame<'a> {
    pub(crate) scene: &'a RasterScene,
    pub(crate) camera: Camera,
    /// The side of each prim's exact support plane the eye is on.
    pub(crate) side: Vec<Side>,
    /// The drawn prims (ids are prim indices).
    pub(crate) screen: Screen,
    /// For each prim, its index in `screen`, or [`NONE`].
    pub(crate) slot: Vec<u32>,
    /// The drawn prims by bands of rows.
    pub(crate) bins: Bins,
    /// Spare per-chunk screens of the projection.
    parts: Vec<Screen>,
    /// The screen points of the scene's shared vertices.
    corners: Corners,
}

/// The buffers of a [`Frame`], kept from frame to frame by a
/// [`crate::Renderer`].
#[derive(Default)]
pub(crate) struct FrameBuffers {
    side: Vec<Side>,
    screen: Screen,
    slot: Vec<u32>,
    bins: Bins,
    parts: Vec<Screen>,
    corners: Corners,
}

impl<'a> Frame<'a> {
    pub(crate) fn new(
        scene: &'a RasterScene,
        camera: &Camera,
        cull: bool,
    ) -> Result<Frame<'a>, RasterError> {
        Frame::with_buffers(scene, camera, cull, FrameBuffers::default())
    }

    /// [`Frame::new`] in the buffers of an earlier frame.
    pub(crate) fn with_buffers(
        scene: &'a RasterScene,
        camera: &Camera,
        cull: bool,
        bufs: FrameBuffers,
    ) -> Result<Frame<'a>, RasterError> {
        if scene.is_empty() {
            return Err(RasterError::EmptyScene);
        }
        let FrameBuffers {
            mut side,
            mut screen,
            mut slot,
            mut bins,
            mut parts,
            mut corners,
        } = bufs;
        let eye = camera.eye();
        let centre = (scene.lo + scene.hi) * 0.5;
        let near = 1e-6 * scene.diagonal().max((eye - centre).length());
        let camera = camera.with_near(near);
        crate::scene::eye_sides(scene, eye, &mut side);
        let view = &camera.view;
        corners.compute(scene, &Projector::new(view));
        project_all_into(
            view,
            scene.len(),
            |i, proj, out, sc| {
                let s = side[i];
                if s == Side::On || (cull && s == Side::Back) {
                    return;
                }
                let (n, d) = scene.plane[i];
                if let Some(k) = view.coeffs(n, d) {
                    proj.add_prim(scene, i, &corners, k, out, sc);
                }
            },
            &mut parts,
            &mut screen,
        );
        slot.clear();
        slot.resize(scene.len(), NONE);
        for (s, &id) in screen.id.iter().enumerate() {
            slot[id as usize] = s as u32;
        }
        bins.rebuild(&screen, camera.height());
        Ok(Frame {
            scene,
            camera,
            side,
            screen,
            slot,
            bins,
            parts,
            corners,
        })
    }

    /// The buffers, for the next frame.
    pub(crate) fn into_buffers(self) -> FrameBuffers {
        FrameBuffers {
            side: self.side,
            screen: self.screen,
            slot: self.slot,
            bins: self.bins,
            parts: self.parts,
            corners: self.corners,
        }
    }

    /// The exact plane of the side of prim `i` the eye sees (`None` when
    /// the eye is in its plane).
    #[inline]
    pub(crate) fn vis_plane(&self, i: usize) -> Option<Plane> {
        match self.side[i] {
            Side::Front => Some(self.scene.support[i]),
            Side::Back => Some(self.scene.support[i].flip()),
            Side::On => None,
        }
    }

    /// The unit normal (input units) of the side of prim `i` the eye sees.
    #[inline]
    pub(crate) fn vis_normal(&self, i: usize) -> DVec3 {
        match self.side[i] {
            Side::Front => self.scene.plane[i].0,
            _ => -self.scene.plane[i].0,
        }
    }

    pub(crate) fn view(&self) -> &View {
        &self.camera.view
    }

    fn size(&self) -> (usize, usize) {
        (self.camera.width() as usize, self.camera.height() as usize)
    }
}

#[inline]
fn better(w: f64, id: u32, cur: (f64, u32)) -> bool {
    w > cur.0 || (w == cur.0 && id < cur.1)
}

fn finish(width: usize, height: usize, buf: Vec<(f64, u32)>) -> VisibilityBuffer {
    let (w, prim) = buf
        .into_par_iter()
        .with_min_len(1 << 14)
        .map(|(w, p)| if p == NONE { (0.0, NONE) } else { (w, p) })
        .unzip();
    VisibilityBuffer {
        width: width as u32,
        height: height as u32,
        prim,
        w,
    }
}

const EMPTY: (f64, u32) = (f64::NEG_INFINITY, NONE);

/// Computes the visibility of `frame` by `method`.
pub(crate) fn visibility(frame: &Frame<'_>, method: Hsr) -> VisibilityBuffer {
    visibility_in(frame, method, None)
}

/// [`visibility`], the z-buffer in the buffers of an earlier visibility.
pub(crate) fn visibility_in(
    frame: &Frame<'_>,
    method: Hsr,
    spare: Option<VisibilityBuffer>,
) -> VisibilityBuffer {
    match method {
        Hsr::ZBuffer => zbuffer(frame, spare),
        Hsr::Scanline => scanline(frame),
        Hsr::Warnock => warnock(frame),
        Hsr::Raycast => raycast(frame),
        Hsr::Bsp => bsp(frame),
    }
}

fn zbuffer(frame: &Frame<'_>, spare: Option<VisibilityBuffer>) -> VisibilityBuffer {
    let (w, h) = frame.size();
    let s = &frame.screen;
    let (mut near, mut prim) = spare.map(|v| (v.w, v.prim)).unwrap_or_default();
    // nearness is positive in front of the eye: 0 is "nothing"; each
    // band is cleared by the job that draws it (then it is in cache)
    crate::raster::reserve_len(&mut near, w * h, 0.0f64);
    crate::raster::reserve_len(&mut prim, w * h, NONE);
    for_bands2(
        &mut near,
        &mut prim,
        w as u32,
        &frame.bins,
        |rows, polys, nb, pb| {
            nb.fill(0.0);
            pb.fill(NONE);
            let mut edges = Vec::new();
            for &i in polys {
                let i = i as usize;
                let (k, id) = (s.coeffs[i], s.id[i]);
                s.spans(i, rows.clone(), w as i64, &mut edges, |y, xs| {
                    let base = (y - rows.start) as usize * w;
                    let rt = row_term(&k, y);
                    let cells = base + xs.start as usize..base + xs.end as usize;
                    // `x as f64` through i32: the same value, and a
                    // conversion the compiler can do two at a time
                    for ((n, p), x) in nb[cells.clone()]
                        .iter_mut()
                        .zip(&mut pb[cells])
                        .zip(xs.start as i32..)
                    {
                        let wv = k[0] * (x as f64 + 0.5) + rt;
                        let take = better(wv, id, (*n, *p));
                        *n = if take { wv } else { *n };
                        *p = if take { id } else { *p };
                    }
                });
            }
        },
    );
    VisibilityBuffer {
        width: w as u32,
        height: h as u32,
        prim,
        w: near,
    }
}

fn scanline(frame: &Frame<'_>) -> VisibilityBuffer {
    let (w, h) = frame.size();
    let s = &frame.screen;
    // the polygon table: polygons by their first row
    let mut table: Vec<Vec<u32>> = vec![Vec::new(); h];
    for (i, &(r0, _)) in s.rows.iter().enumerate() {
        table[r0 as usize].push(i as u32);
    }
    let mut active: Vec<u32> = Vec::new();
    let mut line = vec![EMPTY; w];
    let mut buf = Vec::with_capacity(w * h);
    let mut edges = Vec::new();
    for (y, starting) in table.iter().enumerate() {
        let y = y as i64;
        active.retain(|&i| s.rows[i as usize].1 as i64 > y);
        active.extend_from_slice(starting);
        line.fill(EMPTY);
        for &i in &active {
            let i = i as usize;
            let (k, id) = (s.coeffs[i], s.id[i]);
            s.spans(i, y..y + 1, w as i64, &mut edges, |_, xs| {
                let rt = row_term(&k, y);
                for x in xs {
                    let wv = k[0] * (x as f64 + 0.5) + rt;
                    let cell = &mut line[x as usize];
                    if better(wv, id, *cell) {
                        *cell = (wv, id);
                    }
                }
            });
        }
        buf.extend_from_slice(&line);
    }
    finish(w, h, buf)
}

/// A window of Warnock's subdivision: pixels `x0..x1 × y0..y1`.
struct Window {
    x0: i64,
    y0: i64,
    x1: i64,
    y1: i64,
    list: Vec<u32>,
}

fn warnock(frame: &Frame<'_>) -> VisibilityBuffer {
    let (w, h) = frame.size();
    let s = &frame.screen;
    let mut buf = crate::raster::filled(w * h, EMPTY);
    let mut edges = Vec::new();
    let mut stack = vec![Window {
        x0: 0,
        y0: 0,
        x1: w as i64,
        y1: h as i64,
        list: (0..s.len() as u32).collect(),
    }];
    while let Some(win) = stack.pop() {
        let list: Vec<u32> = win
            .list
            .into_iter()
            .filter(|&i| {
                let ((r0, r1), (c0, c1)) = (s.rows[i as usize], s.cols[i as usize]);
                (r0 as i64) < win.y1
                    && (r1 as i64) > win.y0
                    && (c0 as i64) < win.x1
                    && (c1 as i64) > win.x0
            })
            .collect();
        let (x0, y0, x1, y1) = (win.x0, win.y0, win.x1, win.y1);
        if list.is_empty() {
            continue; // disjoint from everything: background
        }
        if x1 - x0 == 1 && y1 - y0 == 1 {
            let mut best = EMPTY;
            for &i in &list {
                let i = i as usize;
                if s.covers(i, x0, y0, &mut edges) {
                    let wv = s.nearness(i, x0, y0);
                    if better(wv, s.id[i], best) {
                        best = (wv, s.id[i]);
                    }
                }
            }
            buf[y0 as usize * w + x0 as usize] = best;
            continue;
        }
        // one polygon, or a surrounding polygon in front of all others
        let fill_with = if list.len() == 1 {
            Some(list[0] as usize)
        } else {
            surrounder(s, &list, (x0, y0, x1, y1), &mut edges)
        };
        if let Some(i) = fill_with {
            let (k, id) = (s.coeffs[i], s.id[i]);
            s.spans(i, y0..y1, x1, &mut edges, |y, xs| {
                for x in xs.start.max(x0)..xs.end {
                    buf[y as usize * w + x as usize] = (nearness(&k, x, y), id);
                }
            });
            continue;
        }
        let (xm, ym) = ((x0 + x1) / 2, (y0 + y1) / 2);
        let quads = [
            (x0, y0, xm, ym),
            (xm, y0, x1, ym),
            (x0, ym, xm, y1),
            (xm, ym, x1, y1),
        ];
        for (a, b, c, d) in quads {
            if a < c && b < d {
                stack.push(Window {
                    x0: a,
                    y0: b,
                    x1: c,
                    y1: d,
                    list: list.clone(),
                });
            }
        }
    }
    finish(w, h, buf)
}

/// A polygon of `list` that covers every pixel of the window and is
/// nearer than every other polygon of the list at all four corners (so
/// everywhere in it, nearness being affine), by a margin far above
/// rounding.
fn surrounder(
    s: &Screen,
    list: &[u32],
    (x0, y0, x1, y1): (i64, i64, i64, i64),
    edges: &mut Vec<crate::raster::Edge>,
) -> Option<usize> {
    let corners = [(x0, y0), (x1 - 1, y0), (x0, y1 - 1), (x1 - 1, y1 - 1)];
    let range = |i: usize| {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for &(x, y) in &corners {
            let v = s.nearness(i, x, y);
            lo = lo.min(v);
            hi = hi.max(v);
        }
        (lo, hi)
    };
    for &c in list {
        let c = c as usize;
        let (lo, _) = range(c);
        let ((r0, r1), (c0, c1)) = (s.rows[c], s.cols[c]);
        if (r0 as i64) > y0 || (r1 as i64) < y1 || (c0 as i64) > x0 || (c1 as i64) < x1 {
            continue;
        }
        // nearer than the others by a margin
        let others = list
            .iter()
            .filter(|&&i| i as usize != c)
            .map(|&i| range(i as usize).1)
            .fold(f64::NEG_INFINITY, f64::max);
        let margin = 1e-9 * others.abs().max(lo.abs());
        if others.is_finite()
            && lo.partial_cmp(&(others + margin)) != Some(std::cmp::Ordering::Greater)
        {
            continue;
        }
        let mut rows_covered = 0;
        let mut whole = true;
        s.spans(c, y0..y1, x1, edges, |_, xs| {
            rows_covered += 1;
            whole &= xs.start <= x0 && xs.end >= x1;
        });
        if whole && rows_covered == y1 - y0 {
            return Some(c);
        }
    }
    None
}

fn raycast(frame: &Frame<'_>) -> VisibilityBuffer {
    let (w, h) = frame.size();
    let s = &frame.screen;
    let scene = frame.scene;
    let view = frame.view();
    let bvh = Bvh::new(scene);
    let eye = view.origin;
    let (centre, half) = ((scene.lo + scene.hi) * 0.5, 0.5 * scene.diagonal());
    // boxes widened by a hundredth of a pixel at their depth, beyond the
    // 1/512 pixel by which fixed point may move an edge
    let far = (eye - centre).length() + half;
    let pad = view.pixel_size(far) * 0.01 + 1e-12 * far;
    let mut buf = crate::raster::filled(w * h, EMPTY);
    buf.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        let y = y as i64;
        let mut edges = Vec::new();
        for (x, cell) in row.iter_mut().enumerate() {
            let x = x as i64;
            let d = view.dir(x as f64 + 0.5, y as f64 + 0.5);
            let mut best = EMPTY;
            bvh.walk(
                eye,
                d,
                f64::INFINITY,
                |_| pad,
                |items| {
                    for &p in items {
                        let si = frame.slot[p as usize];
                        if si == NONE || !s.covers(si as usize, x, y, &mut edges) {
                            continue;
                        }
                        let wv = s.nearness(si as usize, x, y);
                        if better(wv, p, best) {
                            best = (wv, p);
                        }
                    }
                    // depth along d (whose f component is 1) of the best hit
                    if best.1 == NONE {
                        f64::INFINITY
                    } else {
                        1.0 / best.0 * (1.0 + 1e-9) + pad
                    }
                },
            );
            *cell = best;
        }
    });
    finish(w, h, buf)
}

/// `true` if the cut plane keeps points on it (one of a plane and its
/// negation does: the one whose first non-zero coefficient is positive).
fn keeps_on(p: &Plane) -> bool {
    let n = p.normal();
    match n.iter().find(|&&c| c != 0) {
        Some(&c) => c > 0,
        None => p.offset() > 0,
    }
}

/// A splitting plane that bounds a BSP piece inside its prim: normal and
/// offset in grid units, and whether points on it are kept.
type Cut = (DVec3, f64, bool);

fn bsp(frame: &Frame<'_>) -> VisibilityBuffer {
    let (w, h) = frame.size();
    let s = &frame.screen;
    let scene = frame.scene;
    let view = frame.view();
    let grid = scene.grid;
    let polys: Vec<_> = scene
        .polys
        .iter()
        .enumerate()
        .filter(|(i, _)| frame.slot[*i] != NONE)
        .map(|(i, p)| p.clone().with_tag(i as u32))
        .collect();
    let tree = BspTree::build(polys, &BuildOptions::default());
    // pieces front to back; within a node, by prim
    let mut order: Vec<(u32, Vec<Cut>)> = Vec::new();
    let eye = grid.snap_viewpoint(view.origin).ok();
    let visit = |_: u32, node: &bsp_core::Node, order: &mut Vec<(u32, Vec<Cut>)>| {
        let mut pieces: Vec<&bsp_core::Polygon> = node.polygons.iter().collect();
        pieces.sort_by_key(|p| p.tag());
        for piece in pieces {
            let prim = piece.tag();
            let own = scene.polys[prim as usize].edge_planes();
            let cuts = piece
                .edge_planes()
                .iter()
                .filter(|e| !own.contains(e))
                .map(|e| {
                    let [a, b, c, d] = e.approx();
                    (DVec3::new(a, b, c), d, keeps_on(e))
                })
                .collect();
            order.push((prim, cuts));
        }
    };
    match eye {
        Some(vp) => tree.traverse_nodes(vp, Order::FrontToBack, |id, n| visit(id, n, &mut order)),
        None => {
            let o = view.origin;
            tree.traverse_nodes_by(
                |p| {
                    let [a, b, c, d] = p.approx();
                    let g = (o - grid.origin()) * grid.scale();
                    a * g.x + b * g.y + c * g.z + d >= 0.0
                },
                Order::FrontToBack,
                |id, n| visit(id, n, &mut order),
            )
        }
    }
    let mut buf = crate::raster::filled(w * h, EMPTY);
    let rows_all: Vec<(i32, i32)> = order
        .iter()
        .map(|(p, _)| s.rows[frame.slot[*p as usize] as usize])
        .collect();
    buf.par_chunks_mut(crate::raster::BAND * w)
        .enumerate()
        .for_each(|(b, chunk)| {
            let y0 = (b * crate::raster::BAND) as i64;
            let rows = y0..y0 + (chunk.len() / w) as i64;
            let mut edges = Vec::new();
            for ((prim, cuts), &(r0, r1)) in order.iter().zip(&rows_all) {
                if r1 as i64 <= rows.start || r0 as i64 >= rows.end {
                    continue;
                }
                let si = frame.slot[*prim as usize] as usize;
                let k = s.coeffs[si];
                s.spans(si, rows.clone(), w as i64, &mut edges, |y, xs| {
                    for x in xs {
                        let cell = &mut chunk[(y - rows.start) as usize * w + x as usize];
                        if cell.1 != NONE {
                            continue;
                        }
                        let wv = nearness(&k, x, y);
                        if !cuts.is_empty() {
                            let p = view.point(x as f64 + 0.5, y as f64 + 0.5, wv);
                            let g = (p - grid.origin()) * grid.scale();
                            let inside = cuts.iter().all(|&(n, d, on)| {
                                let v = n.dot(g) + d;
                                v < 0.0 || (v == 0.0 && on)
                            });
                            if !inside {
                                continue;
                            }
                        }
                        *cell = (wv, *prim);
                    }
                });
            }
        });
    finish(w, h, buf)
}

/// The visible prim of every pixel of `camera`'s image of `scene`.
///
/// ```
/// use glam::DVec3;
/// use shadow_raster::{Camera, Hsr, RasterScene, visible_surfaces};
/// let grid = bsp_core::Grid::new(DVec3::ZERO, 0).unwrap();
/// let quad = bsp_core::Polygon::from_grid_points(&[[-4, -4, 0], [4, -4, 0], [4, 4, 0], [-4, 4, 0]], 0).unwrap();
/// let scene = RasterScene::new(&grid, vec![quad])?;
/// let cam = Camera::look_at(DVec3::new(0.0, -6.0, 6.0), DVec3::ZERO, DVec3::Z, 50.0, 32, 24)?;
/// let vis = visible_surfaces(&scene, &cam, Hsr::ZBuffer, false)?;
/// assert_eq!(vis.prim[12 * 32 + 16], 0); // the centre sees the quad
/// # Ok::<(), shadow_raster::RasterError>(())
/// ```
pub fn visible_surfaces(
    scene: &RasterScene,
    camera: &Camera,
    method: Hsr,
    cull_back_faces: bool,
) -> Result<VisibilityBuffer, RasterError> {
    let frame = Frame::new(scene, camera, cull_back_faces)?;
    Ok(visibility(&frame, method))
}
