//! Crow's shadow volumes counted per pixel, as a stencil buffer would.
//!
//! For each light, the prims facing it are the occluders. Their edges are
//! collected as directed edges (counter-clockwise seen from the light);
//! an edge whose two directions do not cancel is a *silhouette* edge (for
//! a closed mesh, between a face toward the light and one away from it;
//! for an open surface, also its border). Each silhouette edge is
//! extruded away from the light into a quadrilateral, oriented outward.
//! The occluders are the volumes' front caps and, moved away from the
//! light by the same distance, their back caps.
//!
//! - **z-pass** counts the volume faces *in front of* the visible surface:
//!   +1 for each one facing the eye, −1 for each one facing away. Caps are
//!   not needed. Volumes are clipped by the near plane like everything
//!   else, so when the eye is inside a volume the count starts wrong and
//!   the shadows come out inverted — the method's known failure.
//! - **z-fail** (Carmack's reverse) counts the faces *behind* the visible
//!   surface the other way round, with both caps; what the near plane
//!   clips is in front of every visible surface, so it stays right.
//!
//! A pixel is in shadow when its count is not zero. The visible prim and a
//! front cap on it have bit-identical nearness (the same plane): z-pass
//! counts strictly in front, so a surface never counts its own cap; z-fail
//! counts at or behind, so it counts the cap it lies on together with the
//! back face its ray leaves the volume by.

use std::collections::HashMap;

use glam::DVec3;

use crate::hsr::{Frame, NONE, VisibilityBuffer};
use crate::lit::{LitBuffer, ShadowFigures, facing_only};
use crate::raster::{Bins, for_bands, project_all, row_term};
use crate::scene::{EdgeKey, RasterLight, SceneLight, point_key as key};

/// The polygons of a light's shadow volumes, in input units, with a
/// weight (silhouette edges met more than once count more).
pub(crate) struct Volumes {
    pub(crate) polys: Vec<Vec<DVec3>>,
    pub(crate) weight: Vec<i32>,
    /// The plane of a front cap: its prim's (so that its nearness is the
    /// prim's, bit for bit); `None` for the others.
    pub(crate) plane: Vec<Option<(DVec3, f64)>>,
}

/// Builds the shadow volumes of `light` (`caps`: with front and back caps).
pub(crate) fn volumes(frame: &Frame<'_>, light: &SceneLight, caps: bool) -> Volumes {
    let scene = frame.scene;
    let centre = (scene.lo + scene.hi) * 0.5;
    // far enough to leave the scene and the eye behind
    let reach = 4.0 * scene.diagonal() + (frame.camera.eye() - centre).length();
    let extrude = |p: DVec3| match light.world {
        RasterLight::Point(l) => {
            let v = p - l;
            let len = v.length();
            if len == 0.0 {
                p
            } else {
                l + v * ((len + reach) / len)
            }
        }
        RasterLight::Sun(d) => p - d * reach,
    };
    let mut edges: HashMap<EdgeKey, (DVec3, DVec3, i32)> = HashMap::new();
    let mut out = Volumes {
        polys: Vec::new(),
        weight: Vec::new(),
        plane: Vec::new(),
    };
    for i in 0..scene.len() {
        if !light.exact.faces(&scene.support[i]) {
            continue;
        }
        let pts = scene.prim(i);
        let k = pts.len();
        for e in 0..k {
            let (a, b) = (pts[e], pts[(e + 1) % k]);
            let (ka, kb) = (key(a), key(b));
            if ka < kb {
                edges.entry((ka, kb)).or_insert((a, b, 0)).2 += 1;
            } else {
                edges.entry((kb, ka)).or_insert((b, a, 0)).2 -= 1;
            }
        }
        if caps {
            out.polys.push(pts.to_vec());
            out.weight.push(1);
            out.plane.push(Some(scene.plane[i]));
            out.polys
                .push(pts.iter().rev().map(|&p| extrude(p)).collect());
            out.weight.push(1);
            out.plane.push(None);
        }
    }
    let mut sides: Vec<_> = edges.into_values().filter(|e| e.2 != 0).collect();
    sides.sort_by(|x, y| {
        (x.0.to_array(), x.1.to_array())
            .partial_cmp(&(y.0.to_array(), y.1.to_array()))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    for (a, b, c) in sides {
        let (a, b) = if c > 0 { (a, b) } else { (b, a) };
        out.polys.push(vec![a, extrude(a), extrude(b), b]);
        out.weight.push(c.abs());
        out.plane.push(None);
    }
    out
}

/// The unit normal and offset of a planar polygon (Newell's method).
pub(crate) fn newell(pts: &[DVec3]) -> Option<(DVec3, f64)> {
    let mut n = DVec3::ZERO;
    let k = pts.len();
    for i in 0..k {
        let (a, b) = (pts[i], pts[(i + 1) % k]);
        n += DVec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    let n = n.try_normalize()?;
    let c = pts.iter().sum::<DVec3>() / k as f64;
    Some((n, -n.dot(c)))
}

pub(crate) fn stencil(
    frame: &Frame<'_>,
    vis: &VisibilityBuffer,
    lights: &[SceneLight],
    facing: &[u64],
    zfail: bool,
) -> (LitBuffer, ShadowFigures) {
    let n = lights.len();
    let mut lit = facing_only(vis, n, facing);
    let mut fig = ShadowFigures::default();
    let view = frame.view();
    let eye = frame.camera.eye();
    let (w, h) = (vis.width as usize, vis.height as usize);
    for (j, l) in lights.iter().enumerate() {
        let vol = volumes(frame, l, zfail);
        fig.primitives += vol.polys.len();
        // a front cap is the prim itself: take its exact plane
        let screen = project_all(view, vol.polys.len(), |i, proj, out, sc| {
            let pts = &vol.polys[i];
            let Some((nrm, d)) = vol.plane[i].or_else(|| newell(pts)) else {
                return;
            };
            let Some(k) = view.coeffs(nrm, d) else { return };
            let toward = nrm.dot(eye) + d > 0.0;
            let sign = if toward { 1 } else { -1 } * vol.weight[i];
            proj.add([pts.as_slice()], k, sign as u32, out, sc);
        });
        let bins = Bins::new(&screen, h as u32);
        let mut count = crate::raster::filled(w * h, 0i32);
        for_bands(&mut count, w as u32, &bins, |rows, polys, px| {
            let mut edges = Vec::new();
            for &s in polys {
                let s = s as usize;
                let k = screen.coeffs[s];
                let sign = screen.id[s] as i32;
                screen.spans(s, rows.clone(), w as i64, &mut edges, |y, xs| {
                    let base = (y - rows.start) as usize * w;
                    let vbase = y as usize * w;
                    let rt = row_term(&k, y);
                    for x in xs {
                        let v = vbase + x as usize;
                        if vis.prim[v] == NONE {
                            continue;
                        }
                        let wv = k[0] * (x as f64 + 0.5) + rt;
                        let c = &mut px[base + x as usize];
                        if zfail {
                            // at the surface's own depth counts as behind (a
                            // GL_LESS depth test fails there): a surface on a
                            // front cap sees the cap and leaves the volume
                            if wv <= vis.w[v] {
                                *c -= sign;
                            }
                        } else if wv > vis.w[v] {
                            *c += sign;
                        }
                    }
                });
            }
        });
        for (p, &c) in count.iter().enumerate() {
            if c != 0 {
                lit.amount[p * n + j] = 0.0;
            }
        }
    }
    (lit, fig)
}
