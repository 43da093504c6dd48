//! What every shadow method shares: the methods and their options, the
//! lit buffer they fill, and the per-pixel helpers (the exact
//! attached-shadow test, the visible point and normal of a pixel).
//!
//! Every method first applies the same exact attached-shadow test: a light
//! can only reach the visible side of a prim when it lies strictly on that
//! side of the prim's exact plane. The methods differ in how they decide
//! cast shadows; see `docs/raster.md` for what each gets wrong.

use std::time::Duration;

use glam::DVec3;

use crate::RasterError;
use crate::hsr::{Frame, NONE, VisibilityBuffer};
use crate::scene::SceneLight;
use crate::view::Rays;

/// A shadow method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Method {
    /// The exact fragments of `svbsp`, scan-converted.
    Exact,
    /// One shadow ray per pixel and light through a BVH.
    Raycast,
    /// Williams' shadow map (cube map for a point light, orthographic for
    /// a sun), with constant and slope-scaled bias and optional PCF.
    ShadowMap,
    /// Crow's shadow volumes counted in front of the visible surface.
    StencilZpass,
    /// Crow's capped shadow volumes counted behind the visible surface.
    StencilZfail,
    /// Projection of every occluder onto the large receiving planes.
    Planar,
    /// Shadow texture: objects drawn from the light, projected on the
    /// objects behind them; no self-shadowing.
    Texture,
    /// Each light with extent as `N` exact point lights spread over it
    /// (suns over a sun disc), a pixel getting the share of their
    /// irradiance that reaches it; a point light or a sun is itself.
    Sampled(u32),
    /// Percentage-closer soft shadows (Fernando 2005) on the shadow map
    /// of each light's centre: a blocker search, then PCF over a kernel
    /// as wide as the penumbra that the blockers' mean depth predicts.
    Pcss,
}

impl Method {
    /// Every method, `exact` first.
    pub const ALL: [Method; 7] = [
        Method::Exact,
        Method::Raycast,
        Method::ShadowMap,
        Method::StencilZpass,
        Method::StencilZfail,
        Method::Planar,
        Method::Texture,
    ];

    /// The methods compared by default when a light has extent: `exact`,
    /// 16, 64 and 256 samples, and PCSS.
    pub const SOFT: [Method; 5] = [
        Method::Exact,
        Method::Sampled(16),
        Method::Sampled(64),
        Method::Sampled(256),
        Method::Pcss,
    ];

    /// The most samples [`Method::Sampled`] takes of a light.
    pub const MAX_SAMPLES: u32 = 4096;

    /// The name on the command line, without a sample count (see the
    /// `Display` form for that: `sampled:16`).
    pub fn name(self) -> &'static str {
        match self {
            Method::Exact => "exact",
            Method::Raycast => "raycast",
            Method::ShadowMap => "shadow-map",
            Method::StencilZpass => "stencil-zpass",
            Method::StencilZfail => "stencil-zfail",
            Method::Planar => "planar",
            Method::Texture => "texture",
            Method::Sampled(_) => "sampled",
            Method::Pcss => "pcss",
        }
    }
}

impl std::fmt::Display for Method {
    /// The name on the command line: [`Method::name`], and for
    /// [`Method::Sampled`] its count (`sampled:16`).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Method::Sampled(n) => write!(f, "sampled:{n}"),
            m => f.write_str(m.name()),
        }
    }
}

impl std::str::FromStr for Method {
    type Err = crate::error::UnknownName;

    /// The method of a name (its `Display` form: `sampled:N` with N from
    /// 1 to [`Method::MAX_SAMPLES`]), spaces around it ignored.
    fn from_str(s: &str) -> Result<Method, Self::Err> {
        let s = s.trim();
        let sampled = s
            .strip_prefix("sampled:")
            .and_then(|n| n.trim().parse::<u32>().ok())
            .filter(|n| (1..=Method::MAX_SAMPLES).contains(n))
            .map(Method::Sampled);
        let mut names = Method::ALL.map(Method::name).to_vec();
        names.extend(["sampled:N (N from 1 to 4096)", "pcss"]);
        sampled
            .or_else(|| {
                (Method::ALL.into_iter())
                    .chain([Method::Pcss])
                    .find(|m| m.name() == s)
            })
            .ok_or_else(|| crate::error::UnknownName {
                what: "method",
                name: s.to_string(),
                available: names.join(", "),
            })
    }
}

/// Options of the image-space shadow methods.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct ShadowOptions {
    /// Shadow-map and shadow-texture resolution: texels on a side of the
    /// orthographic map of a sun, or of each cube face of a point light.
    pub map_size: u32,
    /// Constant depth bias of the shadow map, in input units.
    pub bias_constant: f64,
    /// Slope-scaled bias of the shadow map: this many texel footprints
    /// times the tangent of the angle between the normal and the light.
    pub bias_slope: f64,
    /// Percentage-closer filtering: `pcf × pcf` texels (1: off).
    pub pcf: u32,
    /// Planar shadows: clip occluders to the slab between the receiving
    /// plane and the light (removes anti-shadows and false shadows).
    pub planar_clip: bool,
    /// Planar shadows: at most this many receiving planes, the largest.
    pub planar_receivers: usize,
}

impl Default for ShadowOptions {
    fn default() -> ShadowOptions {
        ShadowOptions {
            map_size: 2048,
            bias_constant: 0.0,
            bias_slope: 1.5,
            pcf: 1,
            planar_clip: true,
            planar_receivers: 8,
        }
    }
}

impl ShadowOptions {
    /// The biases of `C` or `C,S` (`(constant, slope)`; the default
    /// slope when only `C` is given), neither negative.
    ///
    /// ```
    /// use shadow_raster::ShadowOptions;
    /// assert_eq!(ShadowOptions::parse_bias("0.01"), Ok((0.01, 1.5)));
    /// assert_eq!(ShadowOptions::parse_bias("0,2"), Ok((0.0, 2.0)));
    /// assert!(ShadowOptions::parse_bias("-1").is_err());
    /// assert!(ShadowOptions::parse_bias("1,2,3").is_err());
    /// ```
    pub fn parse_bias(s: &str) -> Result<(f64, f64), String> {
        let parts: Vec<&str> = s.split(',').map(str::trim).collect();
        let num = |v: &str| -> Result<f64, String> {
            let x: f64 = v
                .parse()
                .map_err(|_| format!("`{v}` is not a number (expected C or C,S)"))?;
            if !x.is_finite() || x < 0.0 {
                return Err(format!("`{v}`: a bias must be finite and not negative"));
            }
            Ok(x)
        };
        match parts.as_slice() {
            [c] => Ok((num(c)?, ShadowOptions::default().bias_slope)),
            [c, k] => Ok((num(c)?, num(k)?)),
            _ => Err(format!("`{s}`: expected C or C,S")),
        }
    }

    /// The options set away from their defaults that `method` does not
    /// use, by name: `map_size` (shadow maps, PCSS and textures), `bias`
    /// (shadow maps and PCSS), `pcf` (shadow maps) and `planar` (the
    /// planar method's clipping and receivers).
    ///
    /// ```
    /// use shadow_raster::{Method, ShadowOptions};
    /// let o = ShadowOptions::default().with_pcf(3).with_map_size(512);
    /// assert_eq!(o.unused_by(Method::Exact), ["map_size", "pcf"]);
    /// assert!(o.unused_by(Method::ShadowMap).is_empty());
    /// assert_eq!(o.unused_by(Method::Pcss), ["pcf"]);
    /// ```
    pub fn unused_by(&self, method: Method) -> Vec<&'static str> {
        let d = ShadowOptions::default();
        let map = matches!(method, Method::ShadowMap | Method::Pcss);
        let mut out = Vec::new();
        if !map && method != Method::Texture && self.map_size != d.map_size {
            out.push("map_size");
        }
        if !map && (self.bias_constant, self.bias_slope) != (d.bias_constant, d.bias_slope) {
            out.push("bias");
        }
        if method != Method::ShadowMap && self.pcf != d.pcf {
            out.push("pcf");
        }
        let planar =
            (self.planar_clip, self.planar_receivers) != (d.planar_clip, d.planar_receivers);
        if method != Method::Planar && planar {
            out.push("planar");
        }
        out
    }

    /// Sets [`ShadowOptions::map_size`].
    pub fn with_map_size(mut self, n: u32) -> Self {
        self.map_size = n;
        self
    }
    /// Sets the constant and slope-scaled bias.
    pub fn with_bias(mut self, constant: f64, slope: f64) -> Self {
        self.bias_constant = constant;
        self.bias_slope = slope;
        self
    }
    /// Sets [`ShadowOptions::pcf`].
    pub fn with_pcf(mut self, k: u32) -> Self {
        self.pcf = k;
        self
    }
    /// Sets [`ShadowOptions::planar_clip`].
    pub fn with_planar_clip(mut self, clip: bool) -> Self {
        self.planar_clip = clip;
        self
    }
    /// Sets [`ShadowOptions::planar_receivers`].
    pub fn with_planar_receivers(mut self, n: usize) -> Self {
        self.planar_receivers = n;
        self
    }

    /// Checks the ranges.
    pub fn validate(&self) -> Result<(), RasterError> {
        if !(16..=8192).contains(&self.map_size) {
            return Err(RasterError::Option(format!(
                "map size {}: it must lie between 16 and 8192 texels",
                self.map_size
            )));
        }
        if !(self.bias_constant.is_finite() && self.bias_slope.is_finite())
            || self.bias_constant < 0.0
            || self.bias_slope < 0.0
        {
            return Err(RasterError::Option(format!(
                "bias {},{}: both parts must be finite and not negative",
                self.bias_constant, self.bias_slope
            )));
        }
        if self.pcf == 0 || self.pcf > 15 || self.pcf.is_multiple_of(2) {
            return Err(RasterError::Option(format!(
                "PCF kernel {}: it must be odd, between 1 and 15",
                self.pcf
            )));
        }
        if self.planar_receivers == 0 {
            return Err(RasterError::Option("planar receivers: at least one".into()));
        }
        Ok(())
    }
}

/// How much of each light reaches each pixel: `amount[pixel * lights + j]`
/// in `[0, 1]` (0 also for the background).
#[derive(Clone, Debug, PartialEq)]
pub struct LitBuffer {
    /// Number of lights.
    pub lights: usize,
    /// The amounts.
    pub amount: Vec<f32>,
}

impl LitBuffer {
    pub(crate) fn new(pixels: usize, lights: usize) -> LitBuffer {
        LitBuffer {
            lights,
            amount: crate::raster::filled(pixels * lights, 0.0),
        }
    }

    /// A buffer for `pixels × lights` amounts in the memory of `spare`,
    /// its values left as they were: for methods that write every cell
    /// (through [`set_amounts`]).
    pub(crate) fn reuse(spare: Option<LitBuffer>, pixels: usize, lights: usize) -> LitBuffer {
        match spare {
            Some(l) if l.amount.len() == pixels * lights => LitBuffer {
                lights,
                amount: l.amount,
            },
            _ => LitBuffer::new(pixels, lights),
        }
    }

    /// `true` if light `j` reaches pixel `p` (at least half of it, with
    /// PCF).
    #[inline]
    pub fn lit(&self, p: usize, j: usize) -> bool {
        self.amount[p * self.lights + j] >= 0.5
    }
}

/// Figures of a shadow computation.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ShadowFigures {
    /// Exact: fragments drawn; stencil: volume polygons; maps: texels
    /// rendered; planar: projected polygons.
    pub primitives: usize,
    /// Exact: pixels settled by a point-in-fragment test because rounding
    /// left them between the scan-converted fragments.
    pub fallback_pixels: usize,
    /// Time spent, for the report.
    pub time: Duration,
}

/// Per prim, bit `j` set when light `j` lies strictly on the side of the
/// prim's exact plane that the eye sees.
pub(crate) fn facing_bits(frame: &Frame<'_>, lights: &[SceneLight]) -> Vec<u64> {
    use rayon::prelude::*;
    (0..frame.scene.len())
        .into_par_iter()
        .with_min_len(4096)
        .map(|i| match frame.vis_plane(i) {
            None => 0,
            Some(p) => lights
                .iter()
                .enumerate()
                .fold(0u64, |m, (j, l)| m | (l.exact.faces(&p) as u64) << j),
        })
        .collect()
}

/// The unit normal of the side of prim `i` the eye sees.
#[inline]
pub(crate) fn visible_normal(frame: &Frame<'_>, i: usize) -> DVec3 {
    frame.vis_normal(i)
}

/// The world point of pixel `pix` (which has a visible prim).
#[inline]
pub(crate) fn pixel_point(frame: &Frame<'_>, vis: &VisibilityBuffer, pix: usize) -> DVec3 {
    let w = vis.width as usize;
    let (x, y) = ((pix % w) as f64 + 0.5, (pix / w) as f64 + 0.5);
    frame.view().point(x, y, vis.w[pix])
}

/// Sets the amount of every pixel to its facing bits alone (lit where the
/// visible side faces the light); the methods then remove cast shadows.
pub(crate) fn facing_only(vis: &VisibilityBuffer, lights: usize, facing: &[u64]) -> LitBuffer {
    let mut lit = LitBuffer::new(vis.prim.len(), lights);
    for (p, &prim) in vis.prim.iter().enumerate() {
        if prim == NONE {
            continue;
        }
        for j in 0..lights {
            if facing[prim as usize] >> j & 1 == 1 {
                lit.amount[p * lights + j] = 1.0;
            }
        }
    }
    lit
}

/// Self-intersection margin of the shadow rays, relative to the scene's
/// diagonal (the raster crate's only distance tolerance besides the
/// shadow-map bias).
pub const RAY_EPSILON: f64 = 1e-7;

/// Sets the amount of light `j` at every pixel whose visible side faces
/// it to `amount(pixel, prim, point)`, and at every other pixel to 0, in
/// parallel by rows.
pub(crate) fn set_amounts(
    frame: &Frame<'_>,
    vis: &VisibilityBuffer,
    lit: &mut LitBuffer,
    j: usize,
    facing: &[u64],
    amount: impl Fn(usize, u32, DVec3) -> f32 + Sync,
) {
    use rayon::prelude::*;
    let (n, w) = (lit.lights, vis.width as usize);
    let rays = Rays::new(frame.view());
    lit.amount
        .par_chunks_mut(n * w)
        .enumerate()
        .for_each(|(y, cells)| {
            let row = rays.row(y);
            for (x, cell) in cells.chunks_mut(n).enumerate() {
                let pix = y * w + x;
                let prim = vis.prim[pix];
                cell[j] = if prim != NONE && facing[prim as usize] >> j & 1 == 1 {
                    amount(pix, prim, rays.point(x, y, row, vis.w[pix]))
                } else {
                    0.0
                };
            }
        });
}
