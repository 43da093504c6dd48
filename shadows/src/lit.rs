//! Each face's lit area per light, without its fragments: what a sun
//! study of mean hours needs from every sun.
//!
//! The faces in a light's tree get their lit areas as the tree is built
//! ([`svbsp::ShadowVolumes::build_lit`]: the parts of each face that its
//! own insertion brings to a lit leaf, walked on where a later volume is
//! grafted). Only the faces left out of the tree that face the light (a
//! ground under everything, which hides nothing; see `face_trees`) are
//! filtered through the finished trees as `shadows_on` filters every face.
//! Every decision is the same exact sign either way: the areas agree with
//! `shadows_on`'s to rounding (the parts are measured unmerged, from `f64`
//! approximations of their cut corners).

use bsp_core::{Grid, Point, Polygon, SolidParts};
use svbsp::ShadowVolumes;

use crate::sun::tiles::grid_bounds;
use crate::{Error, Light, hiding};

/// Per face the area each light reaches (`lit[face * lights + light]`),
/// and per face its area, in the mesh's units squared.
pub(crate) struct LitAreas {
    pub(crate) lit: Vec<f64>,
    pub(crate) area: Vec<f64>,
}

/// The lit area of every face of `polys` (tagged with their faces, below
/// `faces`) for each of `lights`, as [`crate::shadows_on`] would sum its
/// fragments' (untiled).
pub(crate) fn lit_areas_on(
    grid: &Grid,
    polys: &[Polygon],
    solids: &SolidParts,
    faces: usize,
    lights: &[Light],
) -> Result<LitAreas, Error> {
    let unit = grid.step() * grid.step();
    let placed = svbsp::place_lights(grid, lights).map_err(Error::Light)?;
    let kernel: Vec<svbsp::Light> = placed.iter().map(|l| l.light).collect();
    let bounds = grid_bounds(polys);
    let ranges = svbsp::receivers(polys);
    // per light (in parallel, each tree dropped when done), per receiver
    // the area it reaches
    let per_light = bsp_core::par::try_map(kernel.len(), |j| {
        let light = kernel[j];
        let index: Vec<usize> = hiding(polys, &light, bounds, solids, None).collect();
        let tree: Vec<&Polygon> = index.iter().map(|&i| &polys[i]).collect();
        let (volumes, lit) =
            ShadowVolumes::build_lit(light, &tree).map_err(|e| Error::Shadow(e.into()))?;
        let mut reached = vec![None; polys.len()];
        for (&i, a) in index.iter().zip(lit) {
            reached[i] = Some(a * unit);
        }
        // the receivers it faces that are not in its tree: filtered
        let out = (ranges.iter())
            .map(
                |r| match r.clone().map(|i| reached[i]).sum::<Option<f64>>() {
                    Some(a) => a,
                    None => volumes.lit_area(&polys[r.clone()]) * unit,
                },
            )
            .collect::<Vec<f64>>();
        Ok::<_, Error>(out)
    })?;
    let n = kernel.len();
    let (mut lit, mut area) = (vec![0.0; faces * n], vec![0.0; faces]);
    let mut corners = Vec::new();
    for (k, r) in ranges.iter().enumerate() {
        let f = polys[r.start].tag() as usize;
        for p in &polys[r.clone()] {
            corners.clear();
            corners.extend(p.vertices().iter().map(|v| match v {
                Point::Grid(g) => grid.to_world(g.map(f64::from)),
                Point::Implicit(i) => grid.to_world(i.to_f64()),
            }));
            area[f] += svbsp::polygon_area(&corners);
        }
        for (j, out) in per_light.iter().enumerate() {
            lit[f * n + j] += out[k];
        }
    }
    Ok(LitAreas { lit, area })
}
