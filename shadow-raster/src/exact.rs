//! The `exact` method: the fragments of `svbsp` scan-converted over the
//! pixels where their face is visible.
//!
//! Each fragment is a region of one face (an outer ring and holes) with
//! one lit flag per light. Its rings are projected and filled even-odd
//! with the rasterizer's top-left rule, and a pixel takes the flags of the
//! fragment that covers it, if the pixel's visible prim belongs to the
//! fragment's face and side. Fragments of a face tile it exactly, so a
//! pixel is covered once, except where rounding to `f64` and to fixed
//! point opens a sliver between two fragments (a vertex of one lying on
//! the straight edge of the other): such a pixel is settled by testing its
//! surface point against the face's fragments (even-odd in the face's
//! plane).

use std::collections::HashMap;

use bsp_core::{Plane, Side};
use glam::{DVec2, DVec3};
use svbsp::{Batch, ShadeOptions, Shadows};

use crate::RasterError;
use crate::hsr::{Frame, NONE, Visibility};
use crate::lit::{LitBuffer, ShadowFigures, pixel_point};
use crate::raster::{Bins, for_bands, project_all};
use crate::scene::SceneLight;

/// The fragments of the scene's prims for the side the eye sees of each:
/// every prim is an occluder; each receiver is a prim turned toward the
/// eye.
pub(crate) fn visible_side_fragments(
    frame: &Frame<'_>,
    lights: &[SceneLight],
) -> Result<Batch, RasterError> {
    let scene = frame.scene;
    let exact: Vec<svbsp::Light> = lights.iter().map(|l| l.exact).collect();
    let shadows = Shadows::new(&scene.polys, &exact).map_err(RasterError::Shadows)?;
    let receivers: Vec<bsp_core::Polygon> = scene
        .polys
        .iter()
        .zip(&frame.side)
        .filter_map(|(p, v)| match v {
            Side::Front => Some(p.clone()),
            Side::Back => Some(p.flipped()),
            Side::On => None,
        })
        .collect();
    Ok(shadows
        .set()
        .shade_all(&receivers, &ShadeOptions::default().with_pieces(false)))
}

pub(crate) fn exact(
    frame: &Frame<'_>,
    vis: &Visibility,
    lights: &[SceneLight],
    batch: Option<&Batch>,
    _facing: &[u64],
) -> Result<(LitBuffer, ShadowFigures), RasterError> {
    let own;
    let batch = match batch {
        Some(b) => b,
        None => {
            own = visible_side_fragments(frame, lights)?;
            &own
        }
    };
    Ok(draw_fragments(frame, vis, lights.len(), batch))
}

/// Scan-converts the fragments of `batch` over the visible prims of their
/// face and side.
pub(crate) fn draw_fragments(
    frame: &Frame<'_>,
    vis: &Visibility,
    lights: usize,
    batch: &Batch,
) -> (LitBuffer, ShadowFigures) {
    let scene = frame.scene;
    let grid = scene.grid;
    // a group: one face seen from one side
    let mut groups: HashMap<(u32, Plane), u32> = HashMap::new();
    let prim_group: Vec<u32> = (0..scene.len())
        .map(|i| match frame.vis_plane(i) {
            Some(p) => {
                let next = groups.len() as u32;
                *groups.entry((scene.face[i], p)).or_insert(next)
            }
            None => NONE,
        })
        .collect();
    let frag_group: Vec<u32> = batch
        .fragments()
        .map(|f| {
            groups
                .get(&(f.face(), *f.support()))
                .copied()
                .unwrap_or(NONE)
        })
        .collect();
    let world: Vec<DVec3> = (0..batch.vertex_count() as u32)
        .map(|v| grid.to_world(batch.rounded(v)))
        .collect();
    let view = frame.view();
    let screen = project_all(view, batch.len(), |i, proj, out, sc| {
        if frag_group[i] == NONE {
            return;
        }
        let rings: Vec<Vec<DVec3>> = batch
            .fragment(i)
            .rings()
            .map(|r| r.iter().map(|&v| world[v as usize]).collect())
            .collect();
        proj.add(rings.iter().map(Vec::as_slice), [0.0; 3], i as u32, out, sc);
    });
    let (w, h) = (vis.width as usize, vis.height as usize);
    let bins = Bins::new(&screen, h as u32);
    // per pixel: the fragment that took it
    let mut taken = crate::raster::filled(w * h, NONE);
    for_bands(&mut taken, w as u32, &bins, |rows, polys, px| {
        let mut edges = Vec::new();
        for &s in polys {
            let f = screen.id[s as usize];
            let g = frag_group[f as usize];
            screen.spans(s as usize, rows.clone(), w as i64, &mut edges, |y, xs| {
                let base = (y - rows.start) as usize * w;
                let vbase = y as usize * w;
                for x in xs {
                    let prim = vis.prim[vbase + x as usize];
                    if prim != NONE && prim_group[prim as usize] == g {
                        px[base + x as usize] = f;
                    }
                }
            });
        }
    });
    // the fragments of each group, for the pixels left between them
    let mut by_group: Vec<Vec<u32>> = vec![Vec::new(); groups.len()];
    for (f, &g) in frag_group.iter().enumerate() {
        if g != NONE {
            by_group[g as usize].push(f as u32);
        }
    }
    let mut lit = LitBuffer::new(w * h, lights);
    let mut fallback = 0;
    for (pix, (&prim, &took)) in vis.prim.iter().zip(&taken).enumerate() {
        if prim == NONE {
            continue;
        }
        let mut f = took;
        if f == NONE {
            let g = prim_group[prim as usize];
            let frags = &by_group[g as usize];
            if frags.is_empty() {
                continue; // no fragment for this side: attached shadow
            }
            fallback += 1;
            let p = pixel_point(frame, vis, pix);
            let n = scene.plane[prim as usize].0;
            f = frags
                .iter()
                .copied()
                .find(|&f| inside_fragment(batch, f as usize, &world, n, p))
                .unwrap_or(frags[0]);
        }
        let mask = batch.fragment(f as usize).lit_mask();
        for j in 0..lights {
            if mask >> j & 1 == 1 {
                lit.amount[pix * lights + j] = 1.0;
            }
        }
    }
    let fig = ShadowFigures {
        primitives: screen.len(),
        fallback_pixels: fallback,
        ..ShadowFigures::default()
    };
    (lit, fig)
}

/// Even-odd test of `p` against fragment `f`'s rings, in the coordinate
/// plane that drops the normal's dominant axis.
fn inside_fragment(batch: &Batch, f: usize, world: &[DVec3], n: DVec3, p: DVec3) -> bool {
    let a = n.abs();
    let drop = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    let flat = |v: DVec3| match drop {
        0 => DVec2::new(v.y, v.z),
        1 => DVec2::new(v.z, v.x),
        _ => DVec2::new(v.x, v.y),
    };
    let q = flat(p);
    let mut inside = false;
    for ring in batch.fragment(f).rings() {
        let k = ring.len();
        for i in 0..k {
            let (a, b) = (
                flat(world[ring[i] as usize]),
                flat(world[ring[(i + 1) % k] as usize]),
            );
            if (a.y > q.y) != (b.y > q.y) {
                let x = a.x + (q.y - a.y) * (b.x - a.x) / (b.y - a.y);
                if q.x < x {
                    inside = !inside;
                }
            }
        }
    }
    inside
}
