//! Light maps: Williams' shadow map and the shadow texture.
//!
//! A point light gets a cube map (six 90° perspective faces; only the
//! faces that some visible pixel looks up are rendered), a sun an
//! orthographic map covering the scene's bounding sphere. Maps are drawn
//! with the same rasterizer as the image.
//!
//! - **Shadow map:** each texel keeps the nearness of the nearest surface
//!   (as `f32`, like a GPU depth buffer). A visible point at depth `z` along
//!   the face's axis is lit when `z − bias ≤ z_map`, with
//!   `bias = constant + slope · texel footprint · tan θ` (θ between the
//!   normal and the light). Zero bias shows acne, a large one
//!   peter-panning, a small map aliasing. PCF averages `k × k` such tests.
//! - **Shadow texture:** the scene's objects (connected parts) are drawn
//!   from the light, each texel keeping the first object in the light's
//!   order (by its nearest vertex). A point is shadowed when an object
//!   earlier than its own covers its texel: objects are drawn "black on
//!   white" over the ones behind them, and never over themselves, so there
//!   is no self-shadowing.

use glam::DVec3;
use rayon::prelude::*;

use crate::hsr::{Frame, NONE, VisibilityBuffer};
use crate::lit::{LitBuffer, ShadowFigures, ShadowOptions, set_amounts, visible_normal};
use crate::raster::{Bins, Corners, Projector, Screen, for_bands, project_all_into, row_term};
use crate::scene::{RasterLight, RasterScene, SceneLight};
use crate::view::{Kind, Rays, View};

/// The views of a light's map: six cube faces (`+x, −x, +y, −y, +z, −z`)
/// for a point light, one orthographic view for a sun.
fn light_views(scene: &RasterScene, light: RasterLight, size: u32) -> Vec<View> {
    let frame_of = |f: DVec3| {
        let up = if f.z.abs() < 0.5 { DVec3::Z } else { DVec3::Y };
        let r = f.cross(up).normalize();
        (r, r.cross(f))
    };
    let near = 1e-6 * scene.diagonal();
    match light {
        RasterLight::Point(l) => [
            DVec3::X,
            -DVec3::X,
            DVec3::Y,
            -DVec3::Y,
            DVec3::Z,
            -DVec3::Z,
        ]
        .into_iter()
        .map(|f| {
            let (r, u) = frame_of(f);
            View {
                kind: Kind::Perspective { kx: 1.0, ky: 1.0 },
                origin: l,
                r,
                u,
                f,
                width: size,
                height: size,
                near,
                scale: (0.0, 0.0),
            }
            .ready()
        })
        .collect(),
        RasterLight::Sun(d) => {
            let centre = (scene.lo + scene.hi) * 0.5;
            let radius = 0.5 * scene.diagonal();
            let f = -d;
            let (r, u) = frame_of(f);
            vec![
                View {
                    kind: Kind::Orthographic {
                        scale: 2.0 * radius / size as f64,
                    },
                    origin: centre + d * (2.0 * radius),
                    r,
                    u,
                    f,
                    width: size,
                    height: size,
                    near: 0.0,
                    scale: (0.0, 0.0),
                }
                .ready(),
            ]
        }
    }
}

/// The map view a point looks up.
#[inline]
fn face_of(light: RasterLight, p: DVec3) -> usize {
    match light {
        RasterLight::Sun(_) => 0,
        RasterLight::Point(l) => cube_face(p - l),
    }
}

/// The cube face the direction `v` from a point light falls in.
#[inline]
fn cube_face(v: DVec3) -> usize {
    let a = v.abs();
    if a.x >= a.y && a.x >= a.z {
        (v.x < 0.0) as usize
    } else if a.y >= a.z {
        2 + (v.y < 0.0) as usize
    } else {
        4 + (v.z < 0.0) as usize
    }
}

/// The faces some visible pixel facing light `j` looks up.
fn needed_faces(
    frame: &Frame<'_>,
    vis: &VisibilityBuffer,
    light: RasterLight,
    j: usize,
    facing: &[u64],
) -> [bool; 6] {
    let w = vis.width as usize;
    let faces = |prim: u32| prim != NONE && facing[prim as usize] >> j & 1 == 1;
    if matches!(light, RasterLight::Sun(_)) {
        // one view
        return [
            vis.prim.par_iter().any(|&p| faces(p)),
            false,
            false,
            false,
            false,
            false,
        ];
    }
    let rays = Rays::new(frame.view());
    vis.prim
        .par_chunks(w)
        .enumerate()
        .map(|(y, row)| {
            let mut need = [false; 6];
            let rt = rays.row(y);
            for (x, &prim) in row.iter().enumerate() {
                if faces(prim) {
                    let p = rays.point(x, y, rt, vis.w[y * w + x]);
                    need[face_of(light, p)] = true;
                }
            }
            need
        })
        .reduce(|| [false; 6], |a, b| std::array::from_fn(|k| a[k] || b[k]))
}

/// Projected polygons and their bins, kept from frame to frame.
#[derive(Default)]
pub(crate) struct Projected {
    parts: Vec<Screen>,
    screen: Screen,
    bins: Bins,
    corners: Corners,
}

/// The buffers of the shadow maps kept from frame to frame: the texels of
/// each view, and the projected prims.
#[derive(Default)]
pub(crate) struct MapBuffers {
    texels: Vec<Vec<f32>>,
    proj: Projected,
    look: Lookups,
}

/// Draws every prim into `buf`, a `size²` map of view `view`:
/// `update(texel, nearness, prim)` for each covered texel, bands in
/// parallel.
fn draw_map<T: Copy + Send + Sync>(
    scene: &RasterScene,
    view: &View,
    region: Region,
    init: T,
    update: impl Fn(&mut T, f64, u32) + Sync,
    buf: &mut Vec<T>,
    proj: &mut Projected,
) {
    let size = view.width;
    let Projected {
        parts,
        screen,
        bins,
        corners,
    } = proj;
    corners.compute(scene, &Projector::new(view));
    let corners = &*corners;
    project_all_into(
        view,
        scene.len(),
        |i, proj, out, sc| {
            let (n, d) = scene.plane[i];
            if let Some(k) = view.coeffs(n, d) {
                proj.add_prim(scene, i, corners, k, out, sc);
            }
        },
        parts,
        screen,
    );
    bins.rebuild(screen, size);
    let w = size as usize;
    let Region { x0, y0, x1, y1 } = region;
    crate::raster::reserve_len(buf, w * w, init);
    let screen = &*screen;
    let (x0, x1) = (x0 as i64, x1 as i64);
    for_bands(buf, size, bins, |rows, polys, px| {
        let band = rows.start as usize;
        let rows = rows.start.max(y0 as i64)..rows.end.min(y1 as i64);
        if rows.is_empty() {
            return;
        }
        // the region's rows, cleared by the job that draws them (then
        // they are in cache when drawn)
        px[(rows.start as usize - band) * w..(rows.end as usize - band) * w].fill(init);
        let mut edges = Vec::new();
        for &s in polys {
            let s = s as usize;
            let (c0, c1) = screen.cols[s];
            if c1 as i64 <= x0 || c0 as i64 >= x1 {
                continue;
            }
            let (k, id) = (screen.coeffs[s], screen.id[s]);
            screen.spans(s, rows.clone(), x1, &mut edges, |y, xs| {
                let row = (y as usize - band) * w;
                let rt = row_term(&k, y);
                let start = xs.start.max(x0);
                let texels = &mut px[row + start as usize..row + xs.end.max(start) as usize];
                // `x as f64` through i32: the same value, and a conversion
                // the compiler can do two at a time
                for (t, x) in texels.iter_mut().zip(start as i32..) {
                    update(t, k[0] * (x as f64 + 0.5) + rt, id);
                }
            });
        }
    });
}

/// `⌊v⌋` without a library call (this runs for every pixel).
#[inline]
fn floor(v: f64) -> i64 {
    let i = v as i64;
    i - ((i as f64) > v) as i64
}

/// A rendered light map: per view its texels (`None` for faces not drawn).
struct LightMap<'m, T> {
    views: Vec<View>,
    data: Vec<Option<&'m [T]>>,
}

impl<T: Copy> LightMap<'_, T> {
    /// The texel (clamped into the map) of `p`, and `p`'s frame coordinates.
    #[inline]
    fn texel(&self, light: RasterLight, p: DVec3) -> Option<(usize, i64, i64, DVec3)> {
        let f = face_of(light, p);
        let view = &self.views[f];
        let c = view.frame(p);
        if matches!(view.kind, Kind::Perspective { .. }) && c.z <= 0.0 {
            return None;
        }
        let (x, y) = view.screen(c);
        let n = view.width as i64;
        let (x, y) = (floor(x).clamp(0, n - 1), floor(y).clamp(0, n - 1));
        Some((f, x, y, c))
    }
}

/// A rectangle of texels, `x0..x1` by `y0..y1` (empty when `x0 >= x1`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Region {
    x0: u32,
    y0: u32,
    x1: u32,
    y1: u32,
}

impl Region {
    const EMPTY: Region = Region {
        x0: u32::MAX,
        y0: u32::MAX,
        x1: 0,
        y1: 0,
    };

    fn whole(size: u32) -> Region {
        Region {
            x0: 0,
            y0: 0,
            x1: size,
            y1: size,
        }
    }

    fn is_empty(self) -> bool {
        self.x0 >= self.x1 || self.y0 >= self.y1
    }

    /// The smallest rectangle holding both.
    fn union(self, o: Region) -> Region {
        Region {
            x0: self.x0.min(o.x0),
            y0: self.y0.min(o.y0),
            x1: self.x1.max(o.x1),
            y1: self.y1.max(o.y1),
        }
    }

    /// Widened by `k` texels on every side, within a `size²` map.
    fn grown(self, k: u32, size: u32) -> Region {
        Region {
            x0: self.x0.saturating_sub(k),
            y0: self.y0.saturating_sub(k),
            x1: (self.x1 + k).min(size),
            y1: (self.y1 + k).min(size),
        }
    }
}

/// Draws the views of a light's map that some pixel looks up into `store`
/// (one buffer per view), each only over the texels some pixel looks up
/// (`need`, empty for a view not drawn; the other texels are left as
/// they were): the number of texels drawn.
fn build_map<T: Copy + Send + Sync>(
    scene: &RasterScene,
    views: &[View],
    need: [Region; 6],
    init: T,
    update: impl Fn(&mut T, f64, u32) + Sync,
    store: &mut Vec<Vec<T>>,
    proj: &mut Projected,
) -> usize {
    store.resize_with(views.len(), Vec::new);
    let mut texels = 0;
    for (f, v) in views.iter().enumerate() {
        let r = need[f];
        if !r.is_empty() {
            texels += (r.x1 - r.x0) as usize * (r.y1 - r.y0) as usize;
            draw_map(scene, v, r, init, &update, &mut store[f], proj);
        }
    }
    texels
}

impl<'m, T> LightMap<'m, T> {
    fn new(views: Vec<View>, need: [bool; 6], store: &'m [Vec<T>]) -> LightMap<'m, T> {
        let data = store
            .iter()
            .zip(need)
            .map(|(t, n)| n.then_some(t.as_slice()))
            .collect();
        LightMap { views, data }
    }
}

/// A pixel that looks nothing up (its visible side does not face the
/// light, or it lies at a point light): its amount is 0.
const NO_LOOKUP: u32 = u32::MAX;

/// Bits of a texel coordinate in a [`Lookups`] entry (map sizes are at most
/// 8192 = 2^13).
const TEXEL_BITS: u32 = 13;

/// Where each pixel looks a light's map up, found in one pass before the
/// map is drawn (which also tells which cube faces to draw), and read
/// back after it: the view and texel (`face << 26 | y << 13 | x`, or
/// [`NO_LOOKUP`]) and the biased depth `z − bias` to test.
#[derive(Default)]
struct Lookups {
    at: Vec<u32>,
    depth: Vec<f64>,
}

/// Fills `look` for light `j`: per pixel whose visible side faces the
/// light, the view and texel its point falls in (clamped into the map)
/// and its depth there less the bias. Returns per view the texels some
/// pixel looks up.
fn locate(
    frame: &Frame<'_>,
    vis: &VisibilityBuffer,
    (light, j): (RasterLight, usize),
    facing: &[u64],
    views: &[View],
    opts: &ShadowOptions,
    look: &mut Lookups,
) -> [Region; 6] {
    let (w, n) = (vis.width as usize, vis.prim.len());
    let Lookups { at, depth } = look;
    crate::raster::reserve_len(at, n, NO_LOOKUP);
    crate::raster::reserve_len(depth, n, 0.0);
    let rays = Rays::new(frame.view());
    // the slope-scaled bias per unit of tan θ and of depth: a texel's
    // footprint (`View::pixel_size`) is `z · k` at depth `z` for a
    // perspective view, `k` for an orthographic one
    let slope: Vec<f64> = views
        .iter()
        .map(|v| opts.bias_slope * v.pixel_size(1.0))
        .collect();
    at.par_chunks_mut(w)
        .zip(depth.par_chunks_mut(w))
        .enumerate()
        .map_init(Row::default, |row, (y, (at, depth))| {
            // the row in simple passes over its facing pixels (each pass
            // many independent iterations: the divisions and the square
            // root of neighbouring pixels overlap), the same arithmetic as
            // one pixel at a time
            let mut need = [Region::EMPTY; 6];
            let rt = rays.row(y);
            let base = y * w;
            row.clear();
            for (x, a) in at.iter_mut().enumerate() {
                *a = NO_LOOKUP;
                let prim = vis.prim[base + x];
                if prim != NONE && facing[prim as usize] >> j & 1 == 1 {
                    row.x.push(x as u32);
                    row.prim.push(prim);
                }
            }
            row.p.extend(
                row.x
                    .iter()
                    .map(|&x| rays.point(x as usize, y, rt, vis.w[base + x as usize])),
            );
            match light {
                RasterLight::Point(l) => {
                    // the cube faces share their origin, the light
                    row.fc.extend(row.p.iter().map(|&p| {
                        let v = p - l;
                        let f = cube_face(v);
                        let view = &views[f];
                        (
                            f as u8,
                            DVec3::new(v.dot(view.r), v.dot(view.u), v.dot(view.f)),
                        )
                    }));
                }
                RasterLight::Sun(_) => {
                    row.fc.extend(row.p.iter().map(|&p| (0, views[0].frame(p))));
                }
            }
            let view = &views[row.fc.first().map_or(0, |fc| fc.0 as usize)];
            let persp = matches!(view.kind, Kind::Perspective { .. });
            let top = (view.width - 1) as f64;
            // every view of a light has the same size and projection;
            // `⌊s⌋` clamped into the map is `s` clamped, then truncated
            // (`as` saturates, and NaN, behind the light, is 0)
            row.texel.extend(row.fc.iter().map(|&(_, c)| {
                let (sx, sy) = view.screen(c);
                let (tx, ty) = (sx.clamp(0.0, top) as u32, sy.clamp(0.0, top) as u32);
                if persp && c.z <= 0.0 {
                    NO_LOOKUP
                } else {
                    ty << TEXEL_BITS | tx
                }
            }));
            row.depth
                .extend(
                    row.p
                        .iter()
                        .zip(&row.fc)
                        .zip(&row.prim)
                        .map(|((&p, &(f, c)), &prim)| {
                            // tan θ from the normal and the (unnormalized) way to the light
                            let v = match light {
                                RasterLight::Point(lp) => lp - p,
                                RasterLight::Sun(d) => d,
                            };
                            let nv = visible_normal(frame, prim as usize).dot(v);
                            let vv = v.length_squared();
                            let tan = ((vv - nv * nv).max(0.0).sqrt() / nv).clamp(0.0, 50.0);
                            let bias = opts.bias_constant
                                + slope[f as usize] * if persp { c.z } else { 1.0 } * tan;
                            c.z - bias
                        }),
                );
            // the region of the current run of one view in locals (in
            // `need[f]` every update waited on the one before through
            // memory), merged into `need` where the view changes
            let (mut cur, mut r) = (0, Region::EMPTY);
            for k in 0..row.x.len() {
                let t = row.texel[k];
                if t == NO_LOOKUP {
                    continue;
                }
                let (tx, ty) = (t & ((1 << TEXEL_BITS) - 1), t >> TEXEL_BITS);
                let (x, f) = (row.x[k] as usize, row.fc[k].0 as usize);
                at[x] = (f as u32) << (2 * TEXEL_BITS) | t;
                depth[x] = row.depth[k];
                if f != cur {
                    need[cur] = need[cur].union(r);
                    (cur, r) = (f, Region::EMPTY);
                }
                r.x0 = r.x0.min(tx);
                r.y0 = r.y0.min(ty);
                r.x1 = r.x1.max(tx + 1);
                r.y1 = r.y1.max(ty + 1);
            }
            need[cur] = need[cur].union(r);
            need
        })
        .reduce(
            || [Region::EMPTY; 6],
            |a, b| std::array::from_fn(|k| a[k].union(b[k])),
        )
}

/// One row's facing pixels in [`locate`], pass by pass.
#[derive(Default)]
struct Row {
    x: Vec<u32>,
    prim: Vec<u32>,
    /// World points.
    p: Vec<DVec3>,
    /// View and frame coordinates in it.
    fc: Vec<(u8, DVec3)>,
    /// Texel, `y << TEXEL_BITS | x`, or [`NO_LOOKUP`] behind a point
    /// light.
    texel: Vec<u32>,
    /// Depth less the bias.
    depth: Vec<f64>,
}

impl Row {
    fn clear(&mut self) {
        self.x.clear();
        self.prim.clear();
        self.p.clear();
        self.fc.clear();
        self.texel.clear();
        self.depth.clear();
    }
}

/// Locates every pixel's lookup of light `j` (`l`), then draws the
/// nearness of the light's map over each view's lookups as `widen` widens
/// them (an empty view stays empty): the views and the texels drawn.
fn depth_map(
    frame: &Frame<'_>,
    vis: &VisibilityBuffer,
    (l, j): (&SceneLight, usize),
    facing: &[u64],
    opts: &ShadowOptions,
    bufs: &mut MapBuffers,
    widen: impl Fn(Region) -> Region,
) -> (Vec<View>, usize) {
    let views = light_views(frame.scene, l.world, opts.map_size);
    let need = locate(
        frame,
        vis,
        (l.world, j),
        facing,
        &views,
        opts,
        &mut bufs.look,
    )
    .map(|r| if r.is_empty() { r } else { widen(r) });
    let texels = build_map(
        frame.scene,
        &views,
        need,
        f32::NEG_INFINITY,
        |t, w, _| {
            let w = w as f32;
            *t = if w > *t { w } else { *t };
        },
        &mut bufs.texels,
        &mut bufs.proj,
    );
    (views, texels)
}

/// Williams' shadow map.
pub(crate) fn shadow_map(
    frame: &Frame<'_>,
    vis: &VisibilityBuffer,
    lights: &[SceneLight],
    facing: &[u64],
    opts: &ShadowOptions,
    spare: Option<LitBuffer>,
    bufs: &mut MapBuffers,
) -> (LitBuffer, ShadowFigures) {
    shadow_map_in(frame, vis, (lights, facing), opts, spare, bufs, true)
}

/// [`shadow_map`], each view drawn only over the texels some pixel looks
/// up (`scissor`) or whole.
fn shadow_map_in(
    frame: &Frame<'_>,
    vis: &VisibilityBuffer,
    (lights, facing): (&[SceneLight], &[u64]),
    opts: &ShadowOptions,
    spare: Option<LitBuffer>,
    bufs: &mut MapBuffers,
    scissor: bool,
) -> (LitBuffer, ShadowFigures) {
    let n = lights.len();
    let mut lit = LitBuffer::reuse(spare, vis.prim.len(), n);
    let mut fig = ShadowFigures::default();
    let half = (opts.pcf / 2) as i64;
    let taps = (opts.pcf * opts.pcf) as f32;
    let w = vis.width as usize;
    for (j, l) in lights.iter().enumerate() {
        let (_, texels) = depth_map(frame, vis, (l, j), facing, opts, bufs, |r| {
            if scissor {
                // the texels of the lookups and of their PCF kernels
                r.grown(half as u32, opts.map_size)
            } else {
                Region::whole(opts.map_size)
            }
        });
        fig.primitives += texels;
        let persp = matches!(l.world, RasterLight::Point(_));
        let size = opts.map_size as i64;
        let data: Vec<&[f32]> = bufs.texels.iter().map(Vec::as_slice).collect();
        let (at, depth) = (&bufs.look.at, &bufs.look.depth);
        // lit when z − bias <= z_map, with z_map = 1/wm (perspective) or
        // −wm, and nothing drawn (wm = −∞) lit
        let passes = |wm: f64, t: f64| {
            wm == f64::NEG_INFINITY || if persp { wm * t <= 1.0 } else { t <= -wm }
        };
        lit.amount
            .par_chunks_mut(n * w)
            .zip(at.par_chunks(w).zip(depth.par_chunks(w)))
            .for_each(|(cells, (at, depth))| {
                for (x, cell) in cells.chunks_mut(n).enumerate() {
                    let a = at[x];
                    cell[j] = if a == NO_LOOKUP {
                        0.0
                    } else {
                        let texels = data[(a >> (2 * TEXEL_BITS)) as usize];
                        let mask = (1 << TEXEL_BITS) - 1;
                        let (tx, ty) = ((a & mask) as i64, (a >> TEXEL_BITS & mask) as i64);
                        let t = depth[x];
                        if half == 0 {
                            passes(texels[(ty * size + tx) as usize] as f64, t) as u8 as f32
                        } else {
                            let mut pass = 0.0f32;
                            for dy in -half..=half {
                                for dx in -half..=half {
                                    let (sx, sy) = (
                                        (tx + dx).clamp(0, size - 1),
                                        (ty + dy).clamp(0, size - 1),
                                    );
                                    let wm = texels[(sy * size + sx) as usize] as f64;
                                    pass += passes(wm, t) as u8 as f32;
                                }
                            }
                            pass / taps
                        }
                    };
                }
            });
    }
    (lit, fig)
}

/// The widest PCSS kernel, in texels from its centre (blocker search and
/// filter alike): wider penumbrae are cut to it.
pub const PCSS_MAX_RADIUS: f64 = 24.0;

/// Taps of the PCSS blocker search and of its filter.
const PCSS_SEARCH_TAPS: usize = 16;
const PCSS_FILTER_TAPS: usize = 32;

/// Tap `i` of `m` of a Vogel (golden-angle) disc of unit radius, turned
/// by `turn` radians.
#[inline]
fn vogel(i: usize, m: usize, turn: f64) -> (f64, f64) {
    let r = ((i as f64 + 0.5) / m as f64).sqrt();
    let a = i as f64 * 2.399_963_229_728_653 + turn;
    (r * a.cos(), r * a.sin())
}

/// A pixel's turn of the PCSS disc (interleaved gradient noise: the same
/// on every run, and without the bands of one fixed pattern).
#[inline]
fn turn(x: usize, y: usize) -> f64 {
    let f = |v: f64| v - v.floor();
    std::f64::consts::TAU * f(52.982_918_9 * f(0.067_110_56 * x as f64 + 0.005_837_15 * y as f64))
}

/// Percentage-closer soft shadows (Fernando 2005) on the shadow map of
/// each light's centre, with the light's spread
/// ([`SceneLight::spread`]): a blocker search over the texels where the
/// cone from the pixel to the light crosses the map half-way to it, the
/// penumbra's half-width from the blockers' mean depth by similar
/// triangles (`spread · (z − z_b) / z_b` for a point light at depth `z`,
/// `(z − z_b) · tan r` for a disc), and the share of a Vogel disc of taps
/// that pass the biased depth test within it. A point behind an area
/// light's plane gets none of it. A point light or a sun is one tap, as
/// [`shadow_map`] without PCF.
pub(crate) fn pcss(
    frame: &Frame<'_>,
    vis: &VisibilityBuffer,
    (lights, facing): (&[SceneLight], &[u64]),
    opts: &ShadowOptions,
    spare: Option<LitBuffer>,
    bufs: &mut MapBuffers,
) -> (LitBuffer, ShadowFigures) {
    let n = lights.len();
    let mut lit = LitBuffer::reuse(spare, vis.prim.len(), n);
    let mut fig = ShadowFigures::default();
    let w = vis.width as usize;
    // a sun's map starts this deep (see `light_views`)
    let top = 0.5 * frame.scene.diagonal();
    for (j, l) in lights.iter().enumerate() {
        let spread = l.spread();
        let grow = if spread > 0.0 {
            PCSS_MAX_RADIUS as u32 + 1
        } else {
            0
        };
        let (views, texels) = depth_map(frame, vis, (l, j), facing, opts, bufs, |r| {
            r.grown(grow, opts.map_size)
        });
        fig.primitives += texels;
        let blur = Blur {
            persp: matches!(l.world, RasterLight::Point(_)),
            // a texel's footprint per unit of depth (perspective) or in all
            k: views[0].pixel_size(1.0),
            size: opts.map_size as i64,
            spread,
            top,
        };
        let data: Vec<&[f32]> = bufs.texels.iter().map(Vec::as_slice).collect();
        let (at, depth) = (&bufs.look.at, &bufs.look.depth);
        // an area light shines on one side of its plane only
        let emitter = l.emitter();
        let rays = Rays::new(frame.view());
        lit.amount
            .par_chunks_mut(n * w)
            .zip(at.par_chunks(w).zip(depth.par_chunks(w)))
            .enumerate()
            .for_each(|(y, (cells, (at, depth)))| {
                let rt = rays.row(y);
                for (x, cell) in cells.chunks_mut(n).enumerate() {
                    let a = at[x];
                    let behind = |(c, m): (DVec3, DVec3)| {
                        m.dot(rays.point(x, y, rt, vis.w[y * w + x]) - c) <= 0.0
                    };
                    cell[j] = if a == NO_LOOKUP || emitter.is_some_and(behind) {
                        0.0
                    } else {
                        let texels = data[(a >> (2 * TEXEL_BITS)) as usize];
                        let mask = (1 << TEXEL_BITS) - 1;
                        let texel = ((a & mask) as i64, (a >> TEXEL_BITS & mask) as i64);
                        blur.amount(texels, texel, depth[x], turn(x, y))
                    };
                }
            });
    }
    (lit, fig)
}

/// One light's map as PCSS reads it.
struct Blur {
    /// A point light's cube map (else a sun's orthographic map).
    persp: bool,
    /// A texel's footprint per unit of depth (perspective) or in all.
    k: f64,
    /// Texels on a side.
    size: i64,
    /// [`SceneLight::spread`].
    spread: f64,
    /// The depth where a sun's map meets the scene.
    top: f64,
}

impl Blur {
    /// Lit when `t − bias <= z_map`, with `z_map = 1/wm` (perspective)
    /// or `−wm`, and nothing drawn (`wm = −∞`) lit.
    #[inline]
    fn passes(&self, wm: f64, t: f64) -> bool {
        wm == f64::NEG_INFINITY || if self.persp { wm * t <= 1.0 } else { t <= -wm }
    }

    /// The light reaching a point that looks up `texel` of `texels` at
    /// biased depth `t`, the disc turned by `rot`.
    fn amount(&self, texels: &[f32], (tx, ty): (i64, i64), t: f64, rot: f64) -> f32 {
        let (size, spread, k) = (self.size, self.spread, self.k);
        let tap = |dx: f64, dy: f64| {
            let sx = (tx + dx.round() as i64).clamp(0, size - 1);
            let sy = (ty + dy.round() as i64).clamp(0, size - 1);
            texels[(sy * size + sx) as usize] as f64
        };
        let hard = self.passes(tap(0.0, 0.0), t) as u8 as f32;
        if spread == 0.0 {
            return hard;
        }
        // the blockers: where the cone to the light is half-way there
        let search = if self.persp {
            spread / (k * t)
        } else {
            0.5 * (t - self.top).max(0.0) * spread / k
        }
        .min(PCSS_MAX_RADIUS);
        let (mut sum, mut count) = (0.0, 0);
        for i in 0..PCSS_SEARCH_TAPS {
            let (dx, dy) = vogel(i, PCSS_SEARCH_TAPS, rot);
            let wm = tap(dx * search, dy * search);
            if !self.passes(wm, t) {
                sum += if self.persp { 1.0 / wm } else { -wm };
                count += 1;
            }
        }
        if count == 0 {
            return hard;
        }
        // the penumbra's half-width by similar triangles
        let zb = sum / count as f64;
        let radius = if self.persp {
            spread * (t - zb) / (zb * k * t)
        } else {
            (t - zb) * spread / k
        }
        .clamp(0.0, PCSS_MAX_RADIUS);
        if radius < 0.5 {
            return hard;
        }
        let pass = (0..PCSS_FILTER_TAPS)
            .filter(|&i| {
                let (dx, dy) = vogel(i, PCSS_FILTER_TAPS, rot);
                self.passes(tap(dx * radius, dy * radius), t)
            })
            .count();
        pass as f32 / PCSS_FILTER_TAPS as f32
    }
}

/// The scene's objects: prims connected through shared vertices. Returns
/// each prim's object.
pub(crate) fn objects(scene: &RasterScene) -> (Vec<u32>, usize) {
    use std::collections::HashMap;
    let mut first: HashMap<[u64; 3], usize> = HashMap::with_capacity(scene.pts.len());
    let mut pairs = Vec::with_capacity(scene.pts.len());
    for i in 0..scene.len() {
        for p in scene.prim(i) {
            pairs.push((i, *first.entry(crate::scene::point_key(*p)).or_insert(i)));
        }
    }
    crate::scene::components(scene.len(), pairs)
}

/// The shadow texture.
pub(crate) fn texture(
    frame: &Frame<'_>,
    vis: &VisibilityBuffer,
    lights: &[SceneLight],
    facing: &[u64],
    opts: &ShadowOptions,
    spare: Option<LitBuffer>,
) -> (LitBuffer, ShadowFigures) {
    let scene = frame.scene;
    let (obj, count) = objects(scene);
    let n = lights.len();
    let mut lit = LitBuffer::reuse(spare, vis.prim.len(), n);
    let (mut store, mut proj) = (Vec::new(), Projected::default());
    let mut fig = ShadowFigures::default();
    for (j, l) in lights.iter().enumerate() {
        // objects in the light's order, by their nearest vertex
        let mut key = vec![f64::INFINITY; count];
        for (i, &o) in obj.iter().enumerate() {
            for p in scene.prim(i) {
                let k = match l.world {
                    RasterLight::Point(lp) => (*p - lp).length(),
                    RasterLight::Sun(d) => -p.dot(d),
                };
                key[o as usize] = key[o as usize].min(k);
            }
        }
        let mut order: Vec<u32> = (0..count as u32).collect();
        order.sort_by(|&a, &b| key[a as usize].total_cmp(&key[b as usize]).then(a.cmp(&b)));
        let mut rank = vec![0u32; count];
        for (r, &o) in order.iter().enumerate() {
            rank[o as usize] = r as u32;
        }
        let prim_rank: Vec<u32> = obj.iter().map(|&o| rank[o as usize]).collect();
        let views = light_views(scene, l.world, opts.map_size);
        let need = needed_faces(frame, vis, l.world, j, facing);
        let whole = need.map(|n| {
            if n {
                Region::whole(opts.map_size)
            } else {
                Region::EMPTY
            }
        });
        let texels = build_map(
            scene,
            &views,
            whole,
            NONE,
            |t, _, prim| {
                *t = (*t).min(prim_rank[prim as usize]);
            },
            &mut store,
            &mut proj,
        );
        let map = LightMap::new(views, need, &store);
        fig.primitives += texels;
        set_amounts(frame, vis, &mut lit, j, facing, |_, prim, p| {
            let Some((f, x, y, _)) = map.texel(l.world, p) else {
                return 1.0;
            };
            let data = map.data[f].expect("needed faces are drawn");
            let first = data[(y * map.views[f].width as i64 + x) as usize];
            (first >= prim_rank[prim as usize]) as u8 as f32
        });
    }
    (lit, fig)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::scenes;

    #[test]
    fn maps_drawn_only_where_looked_up_give_the_same_shadows() {
        // the scissored views against whole ones, frame after frame in the
        // same buffers (texels outside the lookups are left from earlier
        // frames and must never be read), with and without PCF
        let mut bufs = MapBuffers::default();
        let mut drawn = (0, 0);
        for (scene, lights, cams) in scenes() {
            for cam in &cams {
                let frame = Frame::new(&scene, cam, false).unwrap();
                let vis = crate::hsr::visibility(&frame, crate::Hsr::ZBuffer);
                let facing = crate::lit::facing_bits(&frame, &lights);
                for (pcf, size) in [(1, 256), (3, 64), (1, 16)] {
                    let opts = ShadowOptions::default().with_pcf(pcf).with_map_size(size);
                    let args = (lights.as_slice(), facing.as_slice());
                    let (part, pf) =
                        shadow_map_in(&frame, &vis, args, &opts, None, &mut bufs, true);
                    let mut fresh = MapBuffers::default();
                    let (whole, wf) =
                        shadow_map_in(&frame, &vis, args, &opts, None, &mut fresh, false);
                    assert_eq!(part, whole, "pcf {pcf}, map {size}");
                    assert!(pf.primitives <= wf.primitives);
                    drawn.0 += pf.primitives;
                    drawn.1 += wf.primitives;
                    assert!(part.amount.contains(&1.0));
                    assert!(part.amount.contains(&0.0));
                }
            }
        }
        // the scissor saves texels
        assert!(drawn.0 < drawn.1, "{drawn:?}");
    }
}
