//! Shadow methods: for every pixel with a visible surface, how much of
//! each light reaches it (0 or 1, or a fraction with PCF), by the method
//! asked for (the methods are in `exact`, `maps`, `stencil`, `planar`;
//! ray casting is here).

use crate::RasterError;
use crate::hsr::{Frame, VisibilityBuffer};
use crate::lit::{
    LitBuffer, Method, RAY_EPSILON, ShadowFigures, ShadowOptions, facing_bits, set_amounts,
};
use crate::scene::{RasterLight, SceneLight};

/// Buffers of the shadow methods kept from frame to frame by a
/// [`crate::Renderer`].
#[derive(Default)]
pub(crate) struct ShadowBuffers {
    /// The lit buffer of an earlier frame.
    pub(crate) lit: Option<LitBuffer>,
    /// Light maps.
    pub(crate) maps: crate::maps::MapBuffers,
}

/// Computes the lit buffer of `method`.
pub(crate) fn shadows(
    frame: &Frame<'_>,
    vis: &VisibilityBuffer,
    lights: &[SceneLight],
    method: Method,
    opts: &ShadowOptions,
) -> Result<(LitBuffer, ShadowFigures), RasterError> {
    shadows_in(
        frame,
        vis,
        lights,
        method,
        opts,
        &mut ShadowBuffers::default(),
    )
}

/// [`shadows`] in the buffers of earlier frames.
pub(crate) fn shadows_in(
    frame: &Frame<'_>,
    vis: &VisibilityBuffer,
    lights: &[SceneLight],
    method: Method,
    opts: &ShadowOptions,
    bufs: &mut ShadowBuffers,
) -> Result<(LitBuffer, ShadowFigures), RasterError> {
    opts.validate()?;
    let start = std::time::Instant::now();
    let facing = facing_bits(frame, lights);
    let spare = bufs.lit.take();
    let (lit, mut fig) = match method {
        Method::Exact => crate::exact::exact(frame, vis, lights, None, &facing)?,
        Method::Raycast => raycast(frame, vis, lights, &facing, spare),
        Method::ShadowMap => {
            crate::maps::shadow_map(frame, vis, lights, &facing, opts, spare, &mut bufs.maps)
        }
        Method::Texture => crate::maps::texture(frame, vis, lights, &facing, opts, spare),
        Method::StencilZpass => crate::stencil::stencil(frame, vis, lights, &facing, false),
        Method::StencilZfail => crate::stencil::stencil(frame, vis, lights, &facing, true),
        Method::Planar => crate::planar::planar(frame, vis, lights, &facing, opts),
        Method::Sampled(n) => crate::sampled::sampled(frame, vis, lights, n)?,
        Method::Pcss => {
            let with = (lights, &facing[..]);
            crate::maps::pcss(frame, vis, with, opts, spare, &mut bufs.maps)
        }
    };
    fig.time = start.elapsed();
    Ok((lit, fig))
}

fn raycast(
    frame: &Frame<'_>,
    vis: &VisibilityBuffer,
    lights: &[SceneLight],
    facing: &[u64],
    spare: Option<LitBuffer>,
) -> (LitBuffer, ShadowFigures) {
    let scene = frame.scene;
    let bvh = crate::bvh::Bvh::new(scene);
    let eps = RAY_EPSILON * scene.diagonal();
    let mut lit = LitBuffer::reuse(spare, vis.prim.len(), lights.len());
    for (j, l) in lights.iter().enumerate() {
        set_amounts(frame, vis, &mut lit, j, facing, |_, prim, p| {
            let (d, tmax) = match l.world {
                RasterLight::Point(lp) => (lp - p, 1.0),
                RasterLight::Sun(dir) => (dir, f64::INFINITY),
            };
            let tmin = eps / d.length();
            (!bvh.occluded(scene, p, d, tmin, tmax, prim)) as u8 as f32
        });
    }
    (lit, ShadowFigures::default())
}
