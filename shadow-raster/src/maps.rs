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

use crate::hsr::{Frame, NONE, Visibility};
use crate::raster::{Bins, Screen, for_bands, project_all_into, row_term};
use crate::scene::{RasterLight, RasterScene, SceneLight};
use crate::shadow::{LitBuffer, ShadowFigures, ShadowOptions, set_amounts, visible_normal};
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
        RasterLight::Point(l) => {
            let v = p - l;
            let a = v.abs();
            if a.x >= a.y && a.x >= a.z {
                (v.x < 0.0) as usize
            } else if a.y >= a.z {
                2 + (v.y < 0.0) as usize
            } else {
                4 + (v.z < 0.0) as usize
            }
        }
    }
}

/// The faces some visible pixel facing light `j` looks up.
fn needed_faces(
    frame: &Frame<'_>,
    vis: &Visibility,
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
}

/// The buffers of the shadow maps kept from frame to frame: the texels of
/// each view, and the projected prims.
#[derive(Default)]
pub(crate) struct MapBuffers {
    texels: Vec<Vec<f32>>,
    proj: Projected,
}

/// Draws every prim into `buf`, a `size²` map of view `view`:
/// `update(texel, nearness, prim)` for each covered texel, bands in
/// parallel.
fn draw_map<T: Copy + Send + Sync>(
    scene: &RasterScene,
    view: &View,
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
    } = proj;
    project_all_into(
        view,
        scene.len(),
        |i, proj, out, sc| {
            let (n, d) = scene.plane[i];
            if let Some(k) = view.coeffs(n, d) {
                proj.add([scene.prim(i)], k, i as u32, out, sc);
            }
        },
        parts,
        screen,
    );
    bins.rebuild(screen, size);
    crate::raster::refill(buf, size as usize * size as usize, init);
    let w = size as usize;
    let screen = &*screen;
    for_bands(buf, size, bins, |rows, polys, px| {
        let mut edges = Vec::new();
        for &s in polys {
            let s = s as usize;
            let (k, id) = (screen.coeffs[s], screen.id[s]);
            screen.spans(s, rows.clone(), w as i64, &mut edges, |y, xs| {
                let row = &mut px[(y - rows.start) as usize * w..];
                let rt = row_term(&k, y);
                for x in xs {
                    update(&mut row[x as usize], k[0] * (x as f64 + 0.5) + rt, id);
                }
            });
        }
    });
}

/// `⌊v⌋` without a library call (this runs for every pixel).
#[inline]
fn floor(v: f64) -> i64 {
    let i = v as i64;
    if (i as f64) > v { i - 1 } else { i }
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

/// Draws the views of light `j`'s map that some pixel looks up into
/// `store` (one buffer per view): the views, which were drawn, and the
/// number of texels drawn.
#[allow(clippy::too_many_arguments)]
fn build_map<T: Copy + Send + Sync>(
    frame: &Frame<'_>,
    vis: &Visibility,
    light: RasterLight,
    j: usize,
    facing: &[u64],
    size: u32,
    init: T,
    update: impl Fn(&mut T, f64, u32) + Sync,
    store: &mut Vec<Vec<T>>,
    proj: &mut Projected,
) -> (Vec<View>, [bool; 6], usize) {
    let views = light_views(frame.scene, light, size);
    let need = needed_faces(frame, vis, light, j, facing);
    store.resize_with(views.len(), Vec::new);
    let mut texels = 0;
    for (f, v) in views.iter().enumerate() {
        if need[f] {
            texels += (size as usize).pow(2);
            draw_map(frame.scene, v, init, &update, &mut store[f], proj);
        }
    }
    (views, need, texels)
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

/// Williams' shadow map.
pub(crate) fn shadow_map(
    frame: &Frame<'_>,
    vis: &Visibility,
    lights: &[SceneLight],
    facing: &[u64],
    opts: &ShadowOptions,
    spare: Option<LitBuffer>,
    bufs: &mut MapBuffers,
) -> (LitBuffer, ShadowFigures) {
    let n = lights.len();
    let mut lit = LitBuffer::reuse(spare, vis.prim.len(), n);
    let mut fig = ShadowFigures::default();
    let half = (opts.pcf / 2) as i64;
    let taps = (opts.pcf * opts.pcf) as f32;
    for (j, l) in lights.iter().enumerate() {
        let (views, need, texels) = build_map(
            frame,
            vis,
            l.world,
            j,
            facing,
            opts.map_size,
            f32::NEG_INFINITY,
            |t, w, _| {
                let w = w as f32;
                if w > *t {
                    *t = w;
                }
            },
            &mut bufs.texels,
            &mut bufs.proj,
        );
        let map = LightMap::new(views, need, &bufs.texels);
        fig.primitives += texels;
        set_amounts(frame, vis, &mut lit, j, facing, |_, prim, p| {
            let Some((f, x, y, cf)) = map.texel(l.world, p) else {
                return 0.0;
            };
            let view = &map.views[f];
            let data = map.data[f].expect("needed faces are drawn");
            let z = cf.z;
            // tan θ from the normal and the (unnormalized) way to the light
            let v = match l.world {
                RasterLight::Point(lp) => lp - p,
                RasterLight::Sun(d) => d,
            };
            let nv = visible_normal(frame, prim as usize).dot(v);
            let vv = v.length_squared();
            let tan = ((vv - nv * nv).max(0.0).sqrt() / nv).clamp(0.0, 50.0);
            let bias = opts.bias_constant + opts.bias_slope * view.pixel_size(z) * tan;
            let (t, persp) = (z - bias, matches!(view.kind, Kind::Perspective { .. }));
            let size = view.width as i64;
            let mut pass = 0.0f32;
            for dy in -half..=half {
                for dx in -half..=half {
                    let (tx, ty) = ((x + dx).clamp(0, size - 1), (y + dy).clamp(0, size - 1));
                    let wm = data[(ty * size + tx) as usize] as f64;
                    // t <= z_map, with z_map = 1/wm (perspective) or −wm
                    let lit_here =
                        wm == f64::NEG_INFINITY || if persp { wm * t <= 1.0 } else { t <= -wm };
                    pass += lit_here as u8 as f32;
                }
            }
            pass / taps
        });
    }
    (lit, fig)
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
    vis: &Visibility,
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
        let (views, need, texels) = build_map(
            frame,
            vis,
            l.world,
            j,
            facing,
            opts.map_size,
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
