//! Every shadow method on one scene and camera, against `exact`.

use std::time::Duration;

use glam::DVec3;

use crate::hsr::{Frame, Hsr, NONE, visibility};
use crate::image::{Image, composite, mask, shade};
use svbsp::{PlacedLight, SoftLight};

use crate::lit::{Method, ShadowOptions};
use crate::scene::{RasterScene, SceneLight};
use crate::shadow::shadows;
use crate::{Camera, RasterError};

/// One method's result in a [`Comparison`].
#[derive(Clone, Debug)]
pub struct MethodReport {
    /// The method.
    pub method: Method,
    /// Pixels whose mask (first light) differs from `exact`'s.
    pub disagree: usize,
    /// Pixels with a visible surface (the same for every method).
    pub visible: usize,
    /// The mean of `|amount − exact amount|` over the visible pixels and
    /// the lights: how far the method's light is from the exact one, as
    /// a share of a whole light.
    pub mean_error: f64,
    /// Time of the method's shadow pass (the visibility pass is shared).
    pub time: Duration,
    /// The shaded image.
    pub image: Image,
    /// The mask of the first light.
    pub mask: Vec<u8>,
}

impl MethodReport {
    /// Share of the visible pixels that disagree with `exact`, in percent.
    pub fn disagree_percent(&self) -> f64 {
        100.0 * self.disagree as f64 / self.visible.max(1) as f64
    }
}

/// Every method's report, and the images side by side.
#[derive(Clone, Debug)]
pub struct Comparison {
    /// One per method, `exact` first.
    pub reports: Vec<MethodReport>,
    /// Time of the shared visibility pass (z-buffer).
    pub visibility_time: Duration,
}

impl Comparison {
    /// The panels side by side, each labelled with its method and its
    /// share of disagreeing pixels (not its time, which the report has: the
    /// picture is the same on every run); disagreeing pixels are tinted
    /// magenta when `highlight` is set.
    pub fn image(&self, columns: usize, highlight: bool) -> Image {
        let exact = &self.reports[0].mask;
        let panels: Vec<(String, Image)> = self
            .reports
            .iter()
            .map(|r| {
                let mut img = r.image.clone();
                if highlight {
                    for (p, (a, b)) in r.mask.iter().zip(exact).enumerate() {
                        if a != b {
                            let px = &mut img.rgb[3 * p..3 * p + 3];
                            px.copy_from_slice(&[
                                ((px[0] as u16 + 255) / 2) as u8,
                                px[1] / 3,
                                ((px[2] as u16 + 255) / 2) as u8,
                            ]);
                        }
                    }
                }
                let label = format!(
                    "{}  {:.2}%  err {:.2}%",
                    r.method,
                    r.disagree_percent(),
                    100.0 * r.mean_error
                );
                (label, img)
            })
            .collect();
        composite(&panels, columns)
    }

    /// The report as a table for people: method, the share of visible
    /// pixels whose first light's mask disagrees with the exact one, the
    /// mean error of the light's amount ([`MethodReport::mean_error`]),
    /// and the time.
    pub fn table(&self) -> String {
        let mut s = format!(
            "{:<15} {:>12} {:>10} {:>10}\n",
            "method", "disagree", "error", "time"
        );
        for r in &self.reports {
            s += &format!(
                "{:<15} {:>11.3}% {:>9.3}% {:>7.1} ms\n",
                r.method.to_string(),
                r.disagree_percent(),
                100.0 * r.mean_error,
                r.time.as_secs_f64() * 1e3
            );
        }
        s
    }

    /// The report as CSV:
    /// `method,disagree_pixels,visible_pixels,disagree_percent,mean_error_percent,ms`.
    pub fn csv(&self) -> String {
        let mut s = String::from(
            "method,disagree_pixels,visible_pixels,disagree_percent,mean_error_percent,ms\n",
        );
        for r in &self.reports {
            s += &format!(
                "{},{},{},{:.4},{:.4},{:.1}\n",
                r.method,
                r.disagree,
                r.visible,
                r.disagree_percent(),
                100.0 * r.mean_error,
                r.time.as_secs_f64() * 1e3
            );
        }
        s
    }
}

/// Runs every method of `methods` (`exact` is always run, first) on one
/// z-buffer visibility of `scene` from `camera`.
pub fn compare(
    scene: &RasterScene,
    lights: &[PlacedLight],
    camera: &Camera,
    colors: &[DVec3],
    opts: &ShadowOptions,
    methods: &[Method],
) -> Result<Comparison, RasterError> {
    let lights = &crate::scene_lights(lights)?;
    compare_lights(scene, lights, camera, colors, opts, methods)
}

/// [`compare`] with lights of any kind (see [`crate::render_soft`]): for
/// lights with extent, e.g. `exact` against [`Method::SOFT`].
pub fn compare_soft(
    scene: &RasterScene,
    lights: &[SoftLight],
    camera: &Camera,
    colors: &[DVec3],
    opts: &ShadowOptions,
    methods: &[Method],
) -> Result<Comparison, RasterError> {
    let lights = &crate::soft_scene_lights(lights)?;
    compare_lights(scene, lights, camera, colors, opts, methods)
}

fn compare_lights(
    scene: &RasterScene,
    lights: &[SceneLight],
    camera: &Camera,
    colors: &[DVec3],
    opts: &ShadowOptions,
    methods: &[Method],
) -> Result<Comparison, RasterError> {
    opts.validate()?;
    let t = std::time::Instant::now();
    let frame = Frame::new(scene, camera, false)?;
    let vis = visibility(&frame, Hsr::ZBuffer);
    let visibility_time = t.elapsed();
    let visible = vis.prim.iter().filter(|&&p| p != NONE).count();
    let mut list = vec![Method::Exact];
    list.extend(methods.iter().copied().filter(|&m| m != Method::Exact));
    let mut reports: Vec<MethodReport> = Vec::new();
    let mut exact: Option<Vec<f32>> = None;
    for m in list {
        let (lit, fig) = shadows(&frame, &vis, lights, m, opts)?;
        let image = shade(&frame, &vis, &lit, lights, colors);
        let mk = mask(&vis, &lit);
        let disagree = match reports.first() {
            Some(e) => e.mask.iter().zip(&mk).filter(|(a, b)| a != b).count(),
            None => 0,
        };
        let e = exact.get_or_insert_with(|| lit.amount.clone());
        let off: f64 = (vis.prim.iter().zip(lit.amount.chunks(lights.len().max(1))))
            .zip(e.chunks(lights.len().max(1)))
            .filter(|((p, _), _)| **p != NONE)
            .flat_map(|((_, a), b)| a.iter().zip(b).map(|(&a, &b)| f64::from((a - b).abs())))
            .sum();
        reports.push(MethodReport {
            method: m,
            disagree,
            visible,
            mean_error: off / (visible * lights.len()).max(1) as f64,
            time: fig.time,
            image,
            mask: mk,
        });
    }
    Ok(Comparison {
        reports,
        visibility_time,
    })
}
