//! Planar projection shadows (seed 001): every occluder projected from the
//! light onto each receiving plane by the 4×4 matrix
//! `M = (P·L) I − L Pᵀ`, with `P = (n, d)` the plane and `L` the light in
//! homogeneous coordinates (`(l, 1)` for a point light, `(D, 0)` for a
//! sun). For a point light and `y = 0` this is the lecture's simple form.
//!
//! Receivers are the largest planes of the scene (by the area of their
//! faces, oriented). A projected polygon darkens the pixels where the
//! receiving plane itself is visible (as the stencil test of the classic
//! method does); every other surface only gets attached shadow.
//!
//! Two failures of the naive projection, removed by clipping each
//! occluder to the slab between the receiving plane and the light before
//! projecting it (`planar_clip`, on by default):
//! - *anti-shadows*: a part of an occluder farther from the plane than the
//!   light projects through the light onto the wrong side;
//! - *false shadows*: an occluder behind the receiving plane projects onto
//!   it although it cannot block the light.

use std::collections::HashMap;

use bsp_core::Plane;
use glam::{DVec3, DVec4};

use crate::hsr::{Frame, NONE, VisibilityBuffer};
use crate::lit::{LitBuffer, ShadowFigures, ShadowOptions, facing_only};
use crate::raster::{Bins, for_bands, project_all};
use crate::scene::{RasterLight, SceneLight};

/// Planar shadows clip occluders this fraction of the light's height
/// below the light: a point at the light's height would project to
/// infinity.
pub const PLANAR_MARGIN: f64 = 1e-6;

/// The 4×4 planar projection matrix `M = (P·L) I − L Pᵀ` (rows).
pub fn planar_matrix(n: DVec3, d: f64, light: DVec4) -> [DVec4; 4] {
    let p = DVec4::new(n.x, n.y, n.z, d);
    let dot = p.dot(light);
    std::array::from_fn(|i| {
        let mut row = -light[i] * p;
        row[i] += dot;
        row
    })
}

fn apply(m: &[DVec4; 4], v: DVec3) -> DVec4 {
    let h = DVec4::new(v.x, v.y, v.z, 1.0);
    DVec4::new(m[0].dot(h), m[1].dot(h), m[2].dot(h), m[3].dot(h))
}

/// Keeps the part of a polygon with `n · p + d >= 0`.
fn clip(poly: &[DVec3], n: DVec3, d: f64) -> Vec<DVec3> {
    let mut out = Vec::with_capacity(poly.len() + 1);
    crate::raster::clip_ring(poly, (n, d), &mut out);
    out
}

/// The receiving planes: the `max` largest oriented planes by face area,
/// each holding at least 1% of the scene's area.
pub(crate) fn receivers(frame: &Frame<'_>, max: usize) -> Vec<Plane> {
    let scene = frame.scene;
    let mut area: HashMap<Plane, f64> = HashMap::new();
    let mut total = 0.0;
    for i in 0..scene.len() {
        let a = svbsp::polygon_area(scene.prim(i));
        total += a;
        *area.entry(scene.support[i]).or_insert(0.0) += a;
    }
    let mut planes: Vec<(Plane, f64)> = area
        .into_iter()
        .filter(|(_, a)| *a >= 0.01 * total)
        .collect();
    planes.sort_by(|a, b| {
        b.1.total_cmp(&a.1)
            .then_with(|| (a.0.normal(), a.0.offset()).cmp(&(b.0.normal(), b.0.offset())))
    });
    planes.truncate(max);
    planes.into_iter().map(|(p, _)| p).collect()
}

pub(crate) fn planar(
    frame: &Frame<'_>,
    vis: &VisibilityBuffer,
    lights: &[SceneLight],
    facing: &[u64],
    opts: &ShadowOptions,
) -> (LitBuffer, ShadowFigures) {
    let scene = frame.scene;
    let n = lights.len();
    let mut lit = facing_only(vis, n, facing);
    let mut fig = ShadowFigures::default();
    let planes = receivers(frame, opts.planar_receivers);
    let view = frame.view();
    let (w, h) = (vis.width as usize, vis.height as usize);
    for (j, l) in lights.iter().enumerate() {
        for plane in &planes {
            if !l.exact.faces(plane) {
                continue; // the plane faces away: attached shadow already
            }
            // the prims of this receiver that the eye sees from the front
            let on: Vec<bool> = (0..scene.len())
                .map(|i| frame.vis_plane(i) == Some(*plane))
                .collect();
            if !vis.prim.iter().any(|&p| p != NONE && on[p as usize]) {
                continue;
            }
            let (nw, dw) = crate::scene::world_plane(&scene.grid, plane);
            let lh = match l.world {
                RasterLight::Point(p) => DVec4::new(p.x, p.y, p.z, 1.0),
                RasterLight::Sun(d) => DVec4::new(d.x, d.y, d.z, 0.0),
            };
            let m = planar_matrix(nw, dw, lh);
            let shadows: Vec<Vec<DVec3>> = (0..scene.len())
                .filter(|&i| !scene.support[i].is_coincident(plane))
                .filter_map(|i| {
                    let mut poly = scene.prim(i).to_vec();
                    if opts.planar_clip {
                        poly = clip(&poly, nw, dw);
                        if let RasterLight::Point(p) = l.world {
                            // below the plane through the light parallel to
                            // the receiver (a hair below: a point at the
                            // light's height projects to infinity)
                            let h = nw.dot(p) + dw;
                            poly = clip(&poly, -nw, h * (1.0 - PLANAR_MARGIN) - dw);
                        }
                        if poly.len() < 3 {
                            return None;
                        }
                    }
                    let out: Option<Vec<DVec3>> = poly
                        .iter()
                        .map(|&v| {
                            let q = apply(&m, v);
                            (q.w != 0.0).then(|| q.truncate() / q.w)
                        })
                        .collect();
                    out.filter(|o| o.iter().all(|p| p.is_finite()))
                })
                .collect();
            fig.primitives += shadows.len();
            let screen = project_all(view, shadows.len(), |i, proj, out, sc| {
                proj.add([shadows[i].as_slice()], [0.0; 3], i as u32, out, sc);
            });
            let bins = Bins::new(&screen, h as u32);
            let mut dark = crate::raster::filled(w * h, false);
            for_bands(&mut dark, w as u32, &bins, |rows, polys, px| {
                let mut edges = Vec::new();
                for &s in polys {
                    screen.spans(s as usize, rows.clone(), w as i64, &mut edges, |y, xs| {
                        let base = (y - rows.start) as usize * w;
                        for x in xs {
                            let prim = vis.prim[y as usize * w + x as usize];
                            if prim != NONE && on[prim as usize] {
                                px[base + x as usize] = true;
                            }
                        }
                    });
                }
            });
            for (p, &d) in dark.iter().enumerate() {
                if d {
                    lit.amount[p * n + j] = 0.0;
                }
            }
        }
    }
    (lit, fig)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_matrix_projects_onto_the_plane_through_the_light() {
        // the ground y = 0 (the lecture's case), light at (1, 4, 2)
        let m = planar_matrix(DVec3::Y, 0.0, DVec4::new(1.0, 4.0, 2.0, 1.0));
        let q = apply(&m, DVec3::new(2.0, 2.0, 3.0));
        let p = q.truncate() / q.w;
        // halfway down from the light: twice as far out
        assert!((p - DVec3::new(3.0, 0.0, 4.0)).length() < 1e-12, "{p}");
        // a sun straight down projects vertically
        let m = planar_matrix(DVec3::Y, 0.0, DVec4::new(0.0, 1.0, 0.0, 0.0));
        let q = apply(&m, DVec3::new(2.0, 5.0, 3.0));
        assert!((q.truncate() / q.w - DVec3::new(2.0, 0.0, 3.0)).length() < 1e-12);
    }
}
