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

use rustc_hash::{FxHashMap, FxHashSet};

use bsp_core::GridPoint;
use bsp_core::{Plane, Side};
use glam::{DVec2, DVec3};
use rayon::prelude::*;
use svbsp::{
    AreaClass, AreaLight, Batch, Light, LightError, LightVolumes, Occluder, ShadeOptions,
    ShadowError, SoftFragment, SoftVolumes,
};

use crate::RasterError;
use crate::hsr::{Frame, NONE, VisibilityBuffer};
use crate::lit::{LitBuffer, ShadowFigures, pixel_point};
use crate::raster::{Bins, for_bands, project_all};
use crate::scene::SceneLight;

/// The fragments of the scene's prims for the side the eye sees of each:
/// every prim is an occluder; each receiver is a prim turned toward the
/// eye whose face, seen from that side, has a pixel in `vis` ([`drawn`]:
/// no other fragment can take a pixel).
pub(crate) fn visible_side_fragments(
    frame: &Frame<'_>,
    vis: &VisibilityBuffer,
    lights: &[SceneLight],
) -> Result<Batch, RasterError> {
    let scene = frame.scene;
    let exact: Vec<svbsp::Light> = lights.iter().map(|l| l.exact).collect();
    let shadows = LightVolumes::new(&scene.polys, &exact).map_err(RasterError::Shadows)?;
    let drawn = drawn(frame, vis);
    let receivers: Vec<bsp_core::Polygon> = (scene.polys.par_iter().zip(&frame.side))
        .zip(drawn)
        .filter_map(|((p, v), drawn)| match v {
            _ if !drawn => None,
            Side::Front => Some(p.clone()),
            Side::Back => Some(p.flipped()),
            Side::On => None,
        })
        .collect();
    Ok(shadows.set().shade_all(
        &receivers,
        &ShadeOptions::default()
            .with_pieces(false)
            .with_vertices(false),
    ))
}

pub(crate) fn exact(
    frame: &Frame<'_>,
    vis: &VisibilityBuffer,
    lights: &[SceneLight],
    batch: Option<&Batch>,
    _facing: &[u64],
) -> Result<(LitBuffer, ShadowFigures), RasterError> {
    if lights.iter().any(|l| l.extent.is_some()) {
        return soft(frame, vis, lights);
    }
    let own;
    let batch = match batch {
        Some(b) => b,
        None => {
            own = visible_side_fragments(frame, vis, lights)?;
            &own
        }
    };
    Ok(draw_fragments(frame, vis, lights.len(), batch))
}

/// The exact method with lights of extent: the visible side of every
/// prim cut where any light's class changes ([`svbsp::SoftVolumes`], every
/// prim an occluder), each pixel getting all of a light it sees whole,
/// none of one it does not see, and in penumbra the share of the light's
/// irradiance that reaches the grid point nearest its point
/// ([`svbsp::SoftVolumes::shares`]: exact visibility, the form factor in
/// `f64`).
fn soft(
    frame: &Frame<'_>,
    vis: &VisibilityBuffer,
    lights: &[SceneLight],
) -> Result<(LitBuffer, ShadowFigures), RasterError> {
    let scene = frame.scene;
    let light = |(index, l): (usize, &SceneLight)| {
        let made = match (&l.extent, l.exact) {
            (Some(s), _) => Ok(s.light.clone()),
            (None, Light::Point(p)) => AreaLight::point(p),
            (None, Light::Directional(d)) => AreaLight::sun(d),
        };
        made.map_err(|cause| LightError::Extent { index, cause })
    };
    let area: Result<Vec<AreaLight>, _> = lights.iter().enumerate().map(light).collect();
    let area = area.map_err(|e| RasterError::Shadows(ShadowError::Light(e)))?;
    let (prims, occluders): (Vec<usize>, Vec<Occluder>) = scene
        .polys
        .iter()
        .zip(&frame.side)
        .enumerate()
        .filter_map(|(i, (p, side))| {
            let seen = if *side == Side::Back {
                p.flipped()
            } else {
                p.clone()
            };
            Some((i, Occluder::of_polygon(&seen)?))
        })
        .unzip();
    // (a pixel reads its fragment's share, or its own: the pieces' are
    // not needed)
    let run = SoftVolumes::new(&area, &occluders)
        .map_err(|e| RasterError::Shadows(ShadowError::Light(e)))?
        .regions_only();
    let grid = scene.grid;
    let mut fragments = SoftFragments::default();
    for (r, frags) in run.fragments().into_iter().enumerate() {
        for f in frags {
            let rings = f.rings_in(&grid);
            fragments
                .side
                .push((scene.face[prims[r]], *occluders[r].plane()));
            fragments.receiver.push(r as u32);
            fragments.rings.push(rings);
            fragments.cut.push(f);
        }
    }
    let n = lights.len();
    let (mut lit, fig, taken) = draw(frame, vis, n, &fragments);
    // the penumbra pixels, by receiver and light
    let mut wanted: Vec<(u32, u32, u32, GridPoint)> = Vec::new();
    for (pix, &f) in taken.iter().enumerate() {
        if f == NONE {
            continue;
        }
        let frag = &fragments.cut[f as usize];
        let soft = !(frag.lit | frag.umbra) & ((1u128 << n) - 1) as u64;
        if soft == 0 {
            continue;
        }
        let Ok(at) = grid.snap(pixel_point(frame, vis, pix)) else {
            continue; // (a visible point lies on a face: in range)
        };
        for j in (0..n).filter(|&j| soft >> j & 1 == 1) {
            wanted.push((fragments.receiver[f as usize], j as u32, pix as u32, at));
        }
    }
    wanted.sort_unstable_by_key(|w| (w.0, w.1, w.2));
    let groups: Vec<&[(u32, u32, u32, GridPoint)]> =
        wanted.chunk_by(|a, b| (a.0, a.1) == (b.0, b.1)).collect();
    let shares: Vec<Vec<Option<f64>>> = groups
        .par_iter()
        .map(|g| {
            let points: Vec<GridPoint> = g.iter().map(|w| w.3).collect();
            run.shares(g[0].1 as usize, g[0].0 as usize, &points)
        })
        .collect();
    for (g, s) in groups.iter().zip(&shares) {
        for (&(_, j, pix, _), share) in g.iter().zip(s) {
            if let Some(v) = share {
                lit.amount[pix as usize * n + j as usize] = v.clamp(0.0, 1.0) as f32;
            }
        }
    }
    Ok((lit, fig))
}

/// The fragments of [`soft`]: per fragment its face's side, the receiver
/// it was cut from, its rings (outer first) in input units, and the
/// fragment.
#[derive(Default)]
struct SoftFragments {
    side: Vec<(u32, Plane)>,
    receiver: Vec<u32>,
    rings: Vec<Vec<Vec<DVec3>>>,
    cut: Vec<SoftFragment>,
}

impl Drawable for SoftFragments {
    fn count(&self) -> usize {
        self.cut.len()
    }

    fn side(&self, i: usize) -> (u32, Plane) {
        self.side[i]
    }

    fn rings(&self, i: usize) -> Vec<Vec<DVec3>> {
        self.rings[i].clone()
    }

    /// All of a light seen whole, none of one not seen, and in penumbra
    /// the share at the fragment's centroid (each penumbra pixel then gets
    /// its own).
    fn amounts(&self, i: usize, out: &mut [f32]) {
        let f = &self.cut[i];
        for (j, cell) in out.iter_mut().enumerate() {
            *cell = match f.class(j) {
                AreaClass::Lit => 1.0,
                AreaClass::Umbra => 0.0,
                AreaClass::Penumbra | AreaClass::Undecided => {
                    f.visible[j].as_ref().map_or(0.5, |s| s.centroid) as f32
                }
            };
        }
    }
}

/// Fragments of faces that can be scan-converted: each a region of one
/// face's side (rings in input units), with how much of each light it
/// gets at a point of it.
pub(crate) trait Drawable: Sync {
    /// How many fragments.
    fn count(&self) -> usize;
    /// The face of fragment `i` and the plane of the side it lies on.
    fn side(&self, i: usize) -> (u32, Plane);
    /// The rings of fragment `i` (outer first), in input units.
    fn rings(&self, i: usize) -> Vec<Vec<DVec3>>;
    /// How much of each light fragment `i` gets, into `out` (one cell per
    /// light).
    fn amounts(&self, i: usize, out: &mut [f32]);
}

/// The fragments of a [`Batch`], their vertices in input units.
struct BatchFragments<'b> {
    batch: &'b Batch,
    world: Vec<DVec3>,
    lights: usize,
}

impl Drawable for BatchFragments<'_> {
    fn count(&self) -> usize {
        self.batch.len()
    }

    fn side(&self, i: usize) -> (u32, Plane) {
        let f = self.batch.fragment(i);
        (f.face(), *f.support())
    }

    fn rings(&self, i: usize) -> Vec<Vec<DVec3>> {
        self.batch
            .fragment(i)
            .rings()
            .map(|r| r.iter().map(|&v| self.world[v as usize]).collect())
            .collect()
    }

    fn amounts(&self, i: usize, out: &mut [f32]) {
        let mask = self.batch.fragment(i).lit_mask();
        for (j, cell) in out.iter_mut().enumerate().take(self.lights) {
            if mask >> j & 1 == 1 {
                *cell = 1.0;
            }
        }
    }
}

/// Per prim: whether a prim of its face, seen from the same side (a group
/// of [`draw`]), is visible at some pixel of `vis`. A pixel takes only a
/// fragment of its visible prim's group, so the fragments of the other
/// prims are never drawn.
fn drawn(frame: &Frame<'_>, vis: &VisibilityBuffer) -> Vec<bool> {
    let scene = frame.scene;
    let mut seen = vec![false; scene.len()];
    for &p in &vis.prim {
        if p != NONE {
            seen[p as usize] = true;
        }
    }
    let groups: FxHashSet<(u32, Plane)> = (0..scene.len())
        .filter(|&i| seen[i])
        .filter_map(|i| group_of(frame, i))
        .collect();
    (0..scene.len())
        .into_par_iter()
        .map(|i| group_of(frame, i).is_some_and(|g| groups.contains(&g)))
        .collect()
}

/// The group of prim `i`: its face and the plane of the side the eye
/// sees (`None` for a prim seen edge-on).
fn group_of(frame: &Frame<'_>, i: usize) -> Option<(u32, Plane)> {
    Some((frame.scene.face[i], frame.vis_plane(i)?))
}

/// Scan-converts the fragments of `batch` over the visible prims of their
/// face and side.
pub(crate) fn draw_fragments(
    frame: &Frame<'_>,
    vis: &VisibilityBuffer,
    lights: usize,
    batch: &Batch,
) -> (LitBuffer, ShadowFigures) {
    let grid = frame.scene.grid;
    let world = (0..batch.vertex_count() as u32)
        .into_par_iter()
        .map(|v| grid.to_world(batch.rounded(v)))
        .collect();
    let fragments = BatchFragments {
        batch,
        world,
        lights,
    };
    let (lit, fig, _) = draw(frame, vis, lights, &fragments);
    (lit, fig)
}

/// Scan-converts `fragments` over the visible prims of their face and
/// side: each pixel takes the amounts of the fragment that covers it. Also returns that fragment per pixel ([`NONE`]: none).
pub(crate) fn draw(
    frame: &Frame<'_>,
    vis: &VisibilityBuffer,
    lights: usize,
    fragments: &impl Drawable,
) -> (LitBuffer, ShadowFigures, Vec<u32>) {
    let scene = frame.scene;
    // a group: one face seen from one side
    let mut groups: FxHashMap<(u32, Plane), u32> =
        FxHashMap::with_capacity_and_hasher(scene.len(), Default::default());
    let prim_group: Vec<u32> = (0..scene.len())
        .map(|i| match group_of(frame, i) {
            Some(g) => {
                let next = groups.len() as u32;
                *groups.entry(g).or_insert(next)
            }
            None => NONE,
        })
        .collect();
    let frag_group: Vec<u32> = (0..fragments.count())
        .into_par_iter()
        .map(|i| groups.get(&fragments.side(i)).copied().unwrap_or(NONE))
        .collect();
    let view = frame.view();
    let screen = project_all(view, fragments.count(), |i, proj, out, sc| {
        if frag_group[i] == NONE {
            return;
        }
        let rings = fragments.rings(i);
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
    for (pix, (&prim, took)) in vis.prim.iter().zip(&mut taken).enumerate() {
        if prim == NONE {
            continue;
        }
        let mut f = *took;
        if f == NONE {
            let g = prim_group[prim as usize];
            let frags = &by_group[g as usize];
            if frags.is_empty() {
                continue; // no fragment for this side: attached shadow
            }
            fallback += 1;
            let (n, p) = (scene.plane[prim as usize].0, pixel_point(frame, vis, pix));
            f = frags
                .iter()
                .copied()
                .find(|&f| inside_fragment(&fragments.rings(f as usize), n, p))
                .unwrap_or(frags[0]);
            *took = f;
        }
        fragments.amounts(
            f as usize,
            &mut lit.amount[pix * lights..(pix + 1) * lights],
        );
    }
    let fig = ShadowFigures {
        primitives: screen.len(),
        fallback_pixels: fallback,
        ..ShadowFigures::default()
    };
    (lit, fig, taken)
}

/// Even-odd test of `p` against a fragment's rings, in the coordinate
/// plane that drops the normal's dominant axis.
fn inside_fragment(rings: &[Vec<DVec3>], n: DVec3, p: DVec3) -> bool {
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
    for ring in rings {
        let k = ring.len();
        for i in 0..k {
            let (a, b) = (flat(ring[i]), flat(ring[(i + 1) % k]));
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hsr::{Hsr, visibility};
    use crate::{Camera, RasterScene};

    /// Shading only the prims whose face is seen at some pixel draws the
    /// same image as shading every prim: on the bunny over its ground,
    /// seen from low and close, where most faces are hidden.
    #[test]
    fn only_the_drawn_faces_are_shaded_and_the_image_is_the_same() {
        let mesh = shadow_scene::bunny(0).unwrap();
        let lights = [svbsp::LightSpec::Point(DVec3::new(3.9, 20.6, 5.9))];
        let grid = svbsp::shared_grid(&mesh.positions, &lights).unwrap();
        let placed = svbsp::place_lights(&grid, &lights).unwrap();
        let (polys, _) = bsp_core::import_faces_par(&grid, &mesh.face_loops()).unwrap();
        let scene = RasterScene::new(&grid, polys).unwrap();
        let (lo, hi) = mesh.bounds().unwrap();
        let centre = (lo + hi) * 0.5;
        let eye = centre + DVec3::new(0.3, 0.1, 1.0) * (hi - lo).length();
        let cam = Camera::look_at(eye, centre, DVec3::Y, 40.0, 160, 120).unwrap();
        let frame = Frame::new(&scene, &cam, false).unwrap();
        let vis = visibility(&frame, Hsr::ZBuffer);
        let sl: Vec<SceneLight> = placed.iter().map(SceneLight::from_placed).collect();
        // every prim turned toward the eye, shaded
        let exact_lights: Vec<svbsp::Light> = sl.iter().map(|l| l.exact).collect();
        let shadows = LightVolumes::new(&scene.polys, &exact_lights).unwrap();
        let every: Vec<bsp_core::Polygon> = (scene.polys.iter().zip(&frame.side))
            .filter_map(|(p, v)| match v {
                Side::Front => Some(p.clone()),
                Side::Back => Some(p.flipped()),
                Side::On => None,
            })
            .collect();
        let all = shadows.set().shade_all(
            &every,
            &ShadeOptions::default()
                .with_pieces(false)
                .with_vertices(false),
        );
        let (lit_all, _) = draw_fragments(&frame, &vis, sl.len(), &all);
        let (lit, _) = exact(&frame, &vis, &sl, None, &[]).unwrap();
        assert_eq!(lit.amount, lit_all.amount);
        // most faces are left out, and the image has light and shadow
        let drawn = drawn(&frame, &vis).iter().filter(|&&d| d).count();
        assert!(drawn * 2 < every.len(), "{drawn} of {}", every.len());
        let seen: Vec<f32> = (vis.prim.iter().zip(&lit.amount))
            .filter(|(p, _)| **p != NONE)
            .map(|(_, a)| *a)
            .collect();
        assert!(seen.contains(&1.0) && seen.contains(&0.0));
    }
}
