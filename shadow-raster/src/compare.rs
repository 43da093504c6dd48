//! Every shadow method on one scene and camera, against `exact`.

use std::time::Duration;

use glam::DVec3;

use crate::hsr::{Frame, Hsr, NONE, visibility};
use crate::image::{Image, composite, mask, shade};
use svbsp::PlacedLight;

use crate::lit::{Method, ShadowOptions};
use crate::scene::RasterScene;
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
                let label = format!("{}  {:.2}%", r.method.name(), r.disagree_percent());
                (label, img)
            })
            .collect();
        composite(&panels, columns)
    }

    /// The report as a table for people: method, the share of visible
    /// pixels that disagree with the exact shadows, and the time.
    pub fn table(&self) -> String {
        let mut s = format!("{:<15} {:>12} {:>10}\n", "method", "disagree", "time");
        for r in &self.reports {
            s += &format!(
                "{:<15} {:>11.3}% {:>7.1} ms\n",
                r.method.name(),
                r.disagree_percent(),
                r.time.as_secs_f64() * 1e3
            );
        }
        s
    }

    /// The report as CSV: `method,disagree_pixels,visible_pixels,disagree_percent,ms`.
    pub fn csv(&self) -> String {
        let mut s = String::from("method,disagree_pixels,visible_pixels,disagree_percent,ms\n");
        for r in &self.reports {
            s += &format!(
                "{},{},{},{:.4},{:.1}\n",
                r.method.name(),
                r.disagree,
                r.visible,
                r.disagree_percent(),
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
    opts.validate()?;
    let t = std::time::Instant::now();
    let frame = Frame::new(scene, camera, false)?;
    let vis = visibility(&frame, Hsr::ZBuffer);
    let visibility_time = t.elapsed();
    let visible = vis.prim.iter().filter(|&&p| p != NONE).count();
    let mut list = vec![Method::Exact];
    list.extend(methods.iter().copied().filter(|&m| m != Method::Exact));
    let mut reports: Vec<MethodReport> = Vec::new();
    for m in list {
        let (lit, fig) = shadows(&frame, &vis, lights, m, opts)?;
        let image = shade(&frame, &vis, &lit, lights, colors);
        let mk = mask(&vis, &lit);
        let disagree = match reports.first() {
            Some(e) => e.mask.iter().zip(&mk).filter(|(a, b)| a != b).count(),
            None => 0,
        };
        reports.push(MethodReport {
            method: m,
            disagree,
            visible,
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
