//! The `sampled:N` method: each light with extent as `N` exact point
//! lights spread over it (or `N` suns over a sun disc), each pixel
//! getting the share of their irradiance that reaches it.
//!
//! The samples are a Hammersley set: sample `k` of `N` takes
//! `u = (k + ½)/N` and the base-2 radical inverse of `k` as `v`. Over a
//! polygon, `u` picks a triangle of its fan by area (and a place in it)
//! and `(u', v)` a point of that triangle with uniform density; over a
//! disc of angular radius `r`, the direction at angle `r·√u` from the
//! centre, turned `2π·v` about it. Each is then snapped to the scene's
//! grid (a point) or quantized (a direction), and its shadows are the
//! exact method's. A pixel at `p` with normal `n` weighs a point sample
//! at `q` on a light of normal `m` by `max(0, n·(q−p)) · max(0, m·(p−q)) /
//! |q−p|⁴` (the light's irradiance kernel; every sample stands for the
//! same area) and a sun sample `d` by `max(0, n·d)`: as N grows the share
//! tends to the visible fraction that `exact` reports.

use glam::DVec3;
use rayon::prelude::*;
use svbsp::{Light, SoftShape};

use crate::RasterError;
use crate::hsr::{Frame, NONE, VisibilityBuffer};
use crate::lit::{LitBuffer, ShadowFigures, pixel_point, visible_normal};
use crate::scene::{RasterLight, SceneLight};

/// Samples whose shadows are computed together (each run of the exact
/// method cuts the faces for all its lights at once).
const BATCH: usize = 8;

/// One sample of a light, and how a pixel weighs it.
struct Sample {
    light: SceneLight,
    weight: Weight,
}

/// How a pixel weighs a sample.
#[derive(Clone, Copy)]
enum Weight {
    /// A point light or a sun: the light itself.
    One,
    /// A point on an area light whose unit normal (the side it shines
    /// on) is `normal`.
    Area { at: DVec3, normal: DVec3 },
    /// A direction toward a sun disc.
    Sky { toward: DVec3 },
}

impl Weight {
    #[inline]
    fn at(self, p: DVec3, n: DVec3) -> f64 {
        match self {
            Weight::One => 1.0,
            Weight::Area { at, normal } => {
                let v = at - p;
                let d2 = v.length_squared();
                if d2 == 0.0 {
                    return 0.0;
                }
                n.dot(v).max(0.0) * normal.dot(-v).max(0.0) / (d2 * d2)
            }
            Weight::Sky { toward } => n.dot(toward).max(0.0),
        }
    }
}

/// The base-2 radical inverse of `k`: its bits mirrored behind the point.
fn radical_inverse(k: u32) -> f64 {
    f64::from(k.reverse_bits()) / 4_294_967_296.0
}

/// The `n` samples of `light` on `grid` (see the module docs); a point
/// light or a sun is its one sample.
fn samples(light: &SceneLight, grid: &bsp_core::Grid, n: u32) -> Result<Vec<Sample>, RasterError> {
    let one = |l: SceneLight, weight| Sample { light: l, weight };
    let Some(soft) = &light.extent else {
        return Ok(vec![one(light.clone(), Weight::One)]);
    };
    let hammersley = (0..n).map(|k| ((f64::from(k) + 0.5) / f64::from(n), radical_inverse(k)));
    match &soft.shape {
        SoftShape::Area(c) => {
            let normal = light.emitter().map_or(DVec3::ZERO, |e| e.1);
            let areas: Vec<f64> = (1..c.len() - 1)
                .map(|i| svbsp::polygon_area(&[c[0], c[i], c[i + 1]]))
                .collect();
            let total: f64 = areas.iter().sum();
            hammersley
                .map(|(u, v)| {
                    // the fan triangle at `u` of the area, and where in it
                    let mut left = u * total;
                    let mut t = 0;
                    while t + 1 < areas.len() && left >= areas[t] {
                        left -= areas[t];
                        t += 1;
                    }
                    let u = (left / areas[t]).clamp(0.0, 1.0);
                    let s = u.sqrt();
                    let q = c[0] * (1.0 - s) + c[t + 1] * (s * (1.0 - v)) + c[t + 2] * (s * v);
                    let g = grid.snap(q).map_err(|e| {
                        RasterError::Option(format!("a sample of {}: {e}", soft.shape))
                    })?;
                    let world = grid.to_world(g.map(f64::from));
                    let light = SceneLight {
                        exact: Light::Point(g),
                        world: RasterLight::Point(world),
                        extent: None,
                    };
                    Ok(one(light, Weight::Area { at: world, normal }))
                })
                .collect()
        }
        SoftShape::SunDisc {
            direction,
            radius_deg,
        } => {
            let d = direction.normalize();
            let e1 = d.any_orthonormal_vector();
            let e2 = d.cross(e1);
            let r = radius_deg.to_radians();
            hammersley
                .map(|(u, v)| {
                    let (a, phi) = (r * u.sqrt(), std::f64::consts::TAU * v);
                    let dir = d * a.cos() + (e1 * phi.cos() + e2 * phi.sin()) * a.sin();
                    let q = svbsp::quantize_direction(dir).ok_or_else(|| {
                        RasterError::Option(format!("a sample of {}: no direction", soft.shape))
                    })?;
                    let toward = DVec3::from_array(q.map(f64::from)).normalize();
                    let light = SceneLight {
                        exact: Light::Directional(q),
                        world: RasterLight::Sun(toward),
                        extent: None,
                    };
                    Ok(one(light, Weight::Sky { toward }))
                })
                .collect()
        }
        SoftShape::Point(_) | SoftShape::Sun(_) => Ok(vec![one(light.clone(), Weight::One)]),
    }
}

/// The lit amounts of `lights` with `n` samples of each light with
/// extent (see the module docs).
pub(crate) fn sampled(
    frame: &Frame<'_>,
    vis: &VisibilityBuffer,
    lights: &[SceneLight],
    n: u32,
) -> Result<(LitBuffer, ShadowFigures), RasterError> {
    let grid = &frame.scene.grid;
    let mut all: Vec<(usize, Sample)> = Vec::new();
    for (j, l) in lights.iter().enumerate() {
        all.extend(samples(l, grid, n)?.into_iter().map(|s| (j, s)));
    }
    let (w, count) = (vis.width as usize, lights.len());
    let pixels = vis.prim.len();
    // per pixel and light: Σ weight · lit, and Σ weight
    let mut sums = vec![(0.0f64, 0.0f64); pixels * count];
    let mut fig = ShadowFigures::default();
    for batch in all.chunks(BATCH) {
        let batch_lights: Vec<SceneLight> = batch.iter().map(|(_, s)| s.light.clone()).collect();
        let (lit, f) = crate::exact::exact(frame, vis, &batch_lights, None, &[])?;
        fig.primitives += f.primitives;
        fig.fallback_pixels += f.fallback_pixels;
        let k = batch.len();
        sums.par_chunks_mut(w * count)
            .enumerate()
            .for_each(|(y, row)| {
                for (x, cells) in row.chunks_mut(count).enumerate() {
                    let pix = y * w + x;
                    let prim = vis.prim[pix];
                    if prim == NONE {
                        continue;
                    }
                    let p = pixel_point(frame, vis, pix);
                    let normal = visible_normal(frame, prim as usize);
                    for (s, (j, sample)) in batch.iter().enumerate() {
                        let wt = sample.weight.at(p, normal);
                        let cell = &mut cells[*j];
                        cell.0 += wt * f64::from(lit.amount[pix * k + s]);
                        cell.1 += wt;
                    }
                }
            });
    }
    let mut lit = LitBuffer::new(pixels, count);
    for (a, &(num, den)) in lit.amount.iter_mut().zip(&sums) {
        *a = if den > 0.0 { (num / den) as f32 } else { 0.0 };
    }
    Ok((lit, fig))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radical_inverses_halve_and_quarter() {
        assert_eq!(radical_inverse(0), 0.0);
        assert_eq!(radical_inverse(1), 0.5);
        assert_eq!(radical_inverse(2), 0.25);
        assert_eq!(radical_inverse(3), 0.75);
    }

    #[test]
    fn a_pixel_weighs_what_it_can_see() {
        let up = DVec3::Z;
        let light = Weight::Area {
            at: DVec3::new(0.0, 0.0, 2.0),
            normal: -DVec3::Z,
        };
        // right under it: cos · cos / r²
        assert_eq!(light.at(DVec3::ZERO, up), 0.25);
        // behind the receiver, or with the light turned away: nothing
        assert_eq!(light.at(DVec3::ZERO, -up), 0.0);
        assert_eq!(light.at(DVec3::new(0.0, 0.0, 3.0), -up), 0.0);
        let sun = Weight::Sky { toward: up };
        assert_eq!(sun.at(DVec3::ZERO, up), 1.0);
        assert_eq!(sun.at(DVec3::ZERO, -up), 0.0);
    }
}

#[cfg(test)]
mod against_exact {
    use super::*;
    use crate::hsr::{Hsr, visibility};
    use crate::{Camera, RasterScene};
    use svbsp::{Occluder, SoftSpec, place_soft_lights, shared_soft_grid};

    /// A floor and a square above it under `light`, seen from above: the
    /// exact method's amounts, `sampled:n`'s for each `n`, and per pixel
    /// the share that the light's own view of the point gives (every face
    /// an occluder; `None` off the floor and square).
    #[allow(clippy::type_complexity)]
    fn amounts(light: SoftSpec, ns: &[u32]) -> (Vec<f32>, Vec<Vec<f32>>, Vec<Option<f64>>) {
        let q = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        let faces = [
            vec![
                q(-4.0, -4.0, 0.0),
                q(4.0, -4.0, 0.0),
                q(4.0, 4.0, 0.0),
                q(-4.0, 4.0, 0.0),
            ],
            vec![
                q(-1.0, -1.0, 2.0),
                q(1.0, -1.0, 2.0),
                q(1.0, 1.0, 2.0),
                q(-1.0, 1.0, 2.0),
            ],
        ];
        let grid = shared_soft_grid(&faces.concat(), &[], std::slice::from_ref(&light)).unwrap();
        let lights = place_soft_lights(&grid, &[], &[light]).unwrap();
        let (polys, _) = bsp_core::import_faces(&grid, faces.iter().map(Vec::as_slice)).unwrap();
        let occluders: Vec<Occluder> = polys.iter().filter_map(Occluder::of_polygon).collect();
        let scene = RasterScene::new(&grid, polys).unwrap();
        let cam = Camera::look_at(q(0.3, -0.4, 12.0), DVec3::ZERO, DVec3::Z, 50.0, 96, 72).unwrap();
        let sl: Vec<SceneLight> = lights
            .iter()
            .map(|l| SceneLight::from_soft(l).unwrap())
            .collect();
        let frame = Frame::new(&scene, &cam, false).unwrap();
        let vis = visibility(&frame, Hsr::ZBuffer);
        let (exact, _) = crate::exact::exact(&frame, &vis, &sl, None, &[]).unwrap();
        let sampled = ns
            .iter()
            .map(|&n| sampled(&frame, &vis, &sl, n).unwrap().0.amount)
            .collect();
        let truth = (0..vis.prim.len())
            .map(|pix| {
                let prim = *vis.prim.get(pix).filter(|&&p| p != NONE)? as usize;
                let g = grid.snap(pixel_point(&frame, &vis, pix)).unwrap();
                let plane = frame.vis_plane(prim).unwrap();
                let normal = visible_normal(&frame, prim);
                match lights[0].light.view(g, Some(&plane), &occluders) {
                    Some(v) => Some(
                        v.fraction(DVec3::from_array(g.map(f64::from)), normal)
                            .unwrap_or(0.0),
                    ),
                    None => Some(f64::NAN), // a sun disc: no polygon
                }
            })
            .collect();
        (exact.amount, sampled, truth)
    }

    fn mean_off(a: &[f32], b: &[f32], seen: &[Option<f64>]) -> f64 {
        let (sum, n) = a
            .iter()
            .zip(b)
            .zip(seen)
            .filter(|(_, s)| s.is_some())
            .fold((0.0, 0), |(s, n), ((x, y), _)| {
                (s + f64::from((x - y).abs()), n + 1)
            });
        sum / f64::from(n)
    }

    #[test]
    fn an_area_light_sampled_tends_to_the_exact_share() {
        let q = |x: f64, y: f64| DVec3::new(x, y, 5.0);
        let light = SoftSpec::Area(vec![q(-1.0, -1.0), q(-1.0, 1.0), q(1.0, 1.0), q(1.0, -1.0)]);
        let (exact, sampled, truth) = amounts(light, &[4, 64, 256]);
        // exact: every pixel's amount is the light's own view of its point
        let mut soft = 0;
        for (a, t) in exact.iter().zip(&truth) {
            if let Some(t) = t {
                assert!((f64::from(*a) - t).abs() < 1e-6, "{a} against {t}");
                soft += (0.01..0.99).contains(t) as usize;
            }
        }
        assert!(soft > 300, "{soft} penumbra pixels");
        // the samples close in on it
        let off: Vec<f64> = sampled
            .iter()
            .map(|s| mean_off(s, &exact, &truth))
            .collect();
        assert!(off[0] > off[1] && off[1] > off[2], "{off:?}");
        assert!(off[2] < 0.002, "{off:?}");
    }

    #[test]
    fn a_sun_disc_sampled_tends_to_the_exact_share() {
        let light = SoftSpec::SunDisc {
            direction: DVec3::new(0.2, 0.1, 1.0),
            radius_deg: 8.0,
        };
        let (exact, sampled, truth) = amounts(light, &[4, 256]);
        let soft = exact.iter().filter(|a| (0.01..0.99).contains(*a)).count();
        assert!(soft > 50, "{soft} penumbra pixels");
        let off: Vec<f64> = sampled
            .iter()
            .map(|s| mean_off(s, &exact, &truth))
            .collect();
        assert!(off[0] > off[1], "{off:?}");
        // (with the bounding polygon's extra share of the sky, and the
        // cosine taken as constant over the disc)
        assert!(off[1] < 0.002, "{off:?}");
    }
}
