//! A software rasterizer for the exact BSP shadow toolkit: PNG images of a
//! scene and its shadows, and the classic image-space shadow and
//! visibility methods measured against the exact shadows of `svbsp`.
//!
//! - [`Camera`]: the perspective camera contract (right-handed look-at,
//!   pixel rays from the top-left corner).
//! - [`RasterScene`]: the scene's exact convex polygons, in input units.
//! - [`visible_surfaces`]: the visible polygon of every pixel by z-buffer,
//!   scan-line, Warnock, ray casting or BSP traversal ([`Hsr`]), all
//!   agreeing pixel for pixel (one coverage rule, the top-left rule in
//!   fixed point, and one tie rule).
//! - [`render`]: visibility, then shadows by one [`Method`] — the exact
//!   fragments, shadow rays, shadow maps, stencil shadow volumes (z-pass and
//!   z-fail), planar projection or a shadow texture — then Lambert shading
//!   into an [`Image`] (PNG) and a mask of the first light (PGM).
//! - [`render_fragments`]: the same image from exact fragments computed
//!   elsewhere (a [`svbsp::Batch`]), e.g. one frame of an animation.
//! - [`compare()`]: every method on one camera, with the share of pixels
//!   where each disagrees with `exact`, and its time.
//! - [`hidden_lines`]: Roberts' hidden-line algorithm for convex polyhedra.
//! - [`svg`]: SVG pictures by the painter's algorithm in a BSP tree's
//!   exact order, of a scene's polygons or of their exact fragments.
//! - [`shading`]: the one lighting model of every picture, PNG or SVG.
//!
//! Everything here is `f64` image-space arithmetic on the exact geometry;
//! its tolerances (the shadow rays' self-intersection margin
//! [`RAY_EPSILON`], the shadow map's bias, Roberts' [`LINE_EPSILON`]) are
//! named and documented. Parallel work is split by bands of rows (rayon)
//! and never changes a pixel.
//!
//! # Example
//!
//! ```
//! use glam::DVec3;
//! use shadow_raster::{Camera, Method, RasterScene, RenderOptions, render};
//! use svbsp::{LightSpec, place_lights};
//!
//! // a floor and a floating square, a light above
//! let faces = vec![
//!     vec![DVec3::new(-4.0, -4.0, 0.0), DVec3::new(4.0, -4.0, 0.0), DVec3::new(4.0, 4.0, 0.0), DVec3::new(-4.0, 4.0, 0.0)],
//!     vec![DVec3::new(-1.0, -1.0, 2.0), DVec3::new(1.0, -1.0, 2.0), DVec3::new(1.0, 1.0, 2.0), DVec3::new(-1.0, 1.0, 2.0)],
//! ];
//! let specs = [LightSpec::Point(DVec3::new(0.0, 0.0, 5.0))];
//! let grid = svbsp::shared_grid(&faces.concat(), &specs).unwrap();
//! let lights = place_lights(&grid, &specs).unwrap();
//! let (polys, _) = bsp_core::import_faces(&grid, faces.iter().map(Vec::as_slice)).unwrap();
//! let scene = RasterScene::new(&grid, polys)?;
//! let cam = Camera::look_at(DVec3::new(0.0, -8.0, 6.0), DVec3::ZERO, DVec3::Z, 50.0, 64, 48)?;
//! let out = render(&scene, &lights, &cam, &[], &RenderOptions::default().with_method(Method::Exact))?;
//! let mask = out.mask();
//! assert!(mask.contains(&255) && mask.contains(&128)); // lit floor, and its shadow
//! # Ok::<(), shadow_raster::RasterError>(())
//! ```
//!
//! # Feature flags
//!
//! None.

mod bvh;
mod compare;
mod error;
mod exact;
mod hsr;
mod image;
mod lines;
mod lit;
mod maps;
mod planar;
mod raster;
mod sampled;
mod scene;
pub mod shading;
mod shadow;
mod stencil;
pub mod svg;
#[cfg(test)]
mod testing;
mod view;

use std::time::{Duration, Instant};

use glam::DVec3;
use svbsp::{PlacedLight, SoftLight};

pub use bvh::TriangleBvh;
pub use compare::{Comparison, MethodReport, compare, compare_soft};
pub use error::{RasterError, UnknownName};
pub use hsr::{Hsr, NONE, VisibilityBuffer, visible_surfaces};
pub use image::{BACKGROUND, Image, composite, encode_pgm, mask, mask_counts, write_pgm};
pub use lines::{HiddenLines, LINE_EPSILON, LineCheck, hidden_lines};
pub use lit::{LitBuffer, Method, RAY_EPSILON, ShadowFigures, ShadowOptions};
pub use maps::PCSS_MAX_RADIUS;
pub use planar::{PLANAR_MARGIN, planar_matrix};
pub use scene::RasterScene;
use scene::SceneLight;
pub use view::{
    Camera, CameraError, MAX_PIXELS, MAX_SIZE, default_up, parse_fov, parse_size, parse_up,
};

/// Options of [`render`].
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct RenderOptions {
    /// The visible-surface method.
    pub hsr: Hsr,
    /// Leave out prims whose back faces the eye.
    pub cull_back_faces: bool,
    /// The shadow method.
    pub method: Method,
    /// Options of the image-space shadow methods.
    pub shadow: ShadowOptions,
}

impl Default for RenderOptions {
    fn default() -> RenderOptions {
        RenderOptions {
            hsr: Hsr::ZBuffer,
            cull_back_faces: false,
            method: Method::Exact,
            shadow: ShadowOptions::default(),
        }
    }
}

impl RenderOptions {
    /// Sets [`RenderOptions::hsr`].
    pub fn with_hsr(mut self, hsr: Hsr) -> Self {
        self.hsr = hsr;
        self
    }
    /// Sets [`RenderOptions::cull_back_faces`].
    pub fn with_culling(mut self, cull: bool) -> Self {
        self.cull_back_faces = cull;
        self
    }
    /// Sets [`RenderOptions::method`].
    pub fn with_method(mut self, m: Method) -> Self {
        self.method = m;
        self
    }
    /// Sets [`RenderOptions::shadow`].
    pub fn with_shadow(mut self, s: ShadowOptions) -> Self {
        self.shadow = s;
        self
    }
}

/// A rendered image and what it was made of.
#[derive(Clone, Debug)]
pub struct Rendered {
    /// The visible prim of every pixel.
    pub visibility: VisibilityBuffer,
    /// How much of each light reaches every pixel.
    pub lit: LitBuffer,
    /// The shaded image.
    pub image: Image,
    /// Figures of the shadow method.
    pub figures: ShadowFigures,
    /// Time of the visibility pass.
    pub visibility_time: Duration,
    /// Time of the shading pass.
    pub shading_time: Duration,
}

impl Rendered {
    /// The mask of the first light (see [`mask`]).
    pub fn mask(&self) -> Vec<u8> {
        mask(&self.visibility, &self.lit)
    }

    /// The passes' times for people, one line each: visibility, shadows
    /// (with the method's primitive count, and the pixels a point test
    /// settled) and shading.
    pub fn timings(&self) -> String {
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        let f = &self.figures;
        let fallback = match f.fallback_pixels {
            0 => String::new(),
            n => format!(", {n} pixels settled by a point test"),
        };
        format!(
            "visibility:     {:.1} ms\nshadows:        {:.1} ms ({} primitives{fallback})\n\
             shading:        {:.1} ms\n",
            ms(self.visibility_time),
            ms(f.time),
            f.primitives,
            ms(self.shading_time)
        )
    }
}

/// The lights in the forms the image-space methods use, at most
/// [`svbsp::MAX_LIGHTS`] of them.
fn scene_lights(lights: &[PlacedLight]) -> Result<Vec<SceneLight>, RasterError> {
    if lights.len() > svbsp::MAX_LIGHTS {
        return Err(RasterError::Option(format!(
            "{} lights: at most {} are supported",
            lights.len(),
            svbsp::MAX_LIGHTS
        )));
    }
    Ok(lights.iter().map(SceneLight::from_placed).collect())
}

/// [`scene_lights`] of the lights of a soft-shadow run.
fn soft_scene_lights(lights: &[SoftLight]) -> Result<Vec<SceneLight>, RasterError> {
    if lights.len() > svbsp::MAX_LIGHTS {
        return Err(RasterError::Option(format!(
            "{} lights: at most {} are supported",
            lights.len(),
            svbsp::MAX_LIGHTS
        )));
    }
    lights.iter().map(SceneLight::from_soft).collect()
}

/// Renders `scene` from `camera` with `lights`: visibility, shadows and
/// Lambert shading. `colors` gives each face's base colour (RGB in
/// `[0, 1]`, by face index; faces beyond it are grey).
///
/// Each call allocates its buffers; a [`Renderer`] keeps them from frame
/// to frame.
pub fn render(
    scene: &RasterScene,
    lights: &[PlacedLight],
    camera: &Camera,
    colors: &[DVec3],
    opts: &RenderOptions,
) -> Result<Rendered, RasterError> {
    let mut r = Renderer::new();
    r.render(scene, lights, camera, colors, opts)?;
    Ok(r.into_rendered().expect("a frame was rendered"))
}

/// [`render`] with lights of any kind, from [`svbsp::place_soft_lights`]:
/// area lights and sun discs as well as points and suns. With
/// [`Method::Exact`] a pixel gets all of a light it sees whole, none of
/// one it does not see, and in penumbra the share of the light's
/// irradiance that reaches it (interpolated over its exact fragment);
/// [`Method::Sampled`] spreads exact point lights over each light,
/// [`Method::Pcss`] blurs a shadow map; the other methods take each
/// light as its centre. With points and suns only, the image is
/// [`render`]'s.
///
/// ```
/// use glam::DVec3;
/// use shadow_raster::{Camera, Method, RasterScene, RenderOptions, render_soft};
/// use svbsp::{SoftSpec, place_soft_lights, shared_soft_grid};
///
/// let faces = vec![
///     vec![DVec3::new(-4.0, -4.0, 0.0), DVec3::new(4.0, -4.0, 0.0), DVec3::new(4.0, 4.0, 0.0), DVec3::new(-4.0, 4.0, 0.0)],
///     vec![DVec3::new(-1.0, -1.0, 2.0), DVec3::new(1.0, -1.0, 2.0), DVec3::new(1.0, 1.0, 2.0), DVec3::new(-1.0, 1.0, 2.0)],
/// ];
/// // a square light above, shining down (its corners turn clockwise seen from above)
/// let light = SoftSpec::Area(vec![DVec3::new(-1.0, -1.0, 5.0), DVec3::new(-1.0, 1.0, 5.0), DVec3::new(1.0, 1.0, 5.0), DVec3::new(1.0, -1.0, 5.0)]);
/// let grid = shared_soft_grid(&faces.concat(), &[], std::slice::from_ref(&light)).unwrap();
/// let lights = place_soft_lights(&grid, &[], &[light]).unwrap();
/// let (polys, _) = bsp_core::import_faces(&grid, faces.iter().map(Vec::as_slice)).unwrap();
/// let scene = RasterScene::new(&grid, polys)?;
/// let cam = Camera::look_at(DVec3::new(0.0, -8.0, 6.0), DVec3::ZERO, DVec3::Z, 50.0, 64, 48)?;
/// let out = render_soft(&scene, &lights, &cam, &[], &RenderOptions::default())?;
/// // lit floor, umbra under the square, and penumbra between
/// let amounts = &out.lit.amount;
/// assert!(amounts.contains(&1.0) && amounts.iter().any(|&a| a > 0.05 && a < 0.95));
/// # Ok::<(), shadow_raster::RasterError>(())
/// ```
pub fn render_soft(
    scene: &RasterScene,
    lights: &[SoftLight],
    camera: &Camera,
    colors: &[DVec3],
    opts: &RenderOptions,
) -> Result<Rendered, RasterError> {
    let mut r = Renderer::new();
    r.render_soft(scene, lights, camera, colors, opts)?;
    Ok(r.into_rendered().expect("a frame was rendered"))
}

/// Renders `scene` with the exact fragments of `batch` (from
/// [`svbsp::LightVolumes`] over the same polygons, every face a receiver with
/// its front side; a face seen from the back is drawn in attached shadow
/// unless the batch has fragments for its flipped plane). The hook for
/// animations: one frame's polygons and fragments in, one image out.
///
/// `lights` are the batch's lights, in order.
pub fn render_fragments(
    scene: &RasterScene,
    batch: &svbsp::Batch,
    lights: &[PlacedLight],
    camera: &Camera,
    colors: &[DVec3],
) -> Result<Rendered, RasterError> {
    let mut r = Renderer::new();
    r.render_fragments(scene, batch, lights, camera, colors)?;
    Ok(r.into_rendered().expect("a frame was rendered"))
}

/// A renderer that keeps its buffers from frame to frame: the depth and
/// prim buffers, the prims' projection, the light maps' texels, the lit
/// amounts and the image. An animation or a bench keeps one and calls
/// [`Renderer::render`] for every frame; the result is the same as
/// [`render`]'s, bit for bit, without the cost of fresh memory (a fresh
/// buffer's pages fault on first write, in every phase).
///
/// ```
/// use glam::DVec3;
/// use shadow_raster::{Camera, Method, RasterScene, RenderOptions, Renderer};
/// let grid = bsp_core::Grid::new(DVec3::ZERO, 0).unwrap();
/// let quad = bsp_core::Polygon::from_grid_points(&[[-4, -4, 0], [4, -4, 0], [4, 4, 0], [-4, 4, 0]], 0).unwrap();
/// let scene = RasterScene::new(&grid, vec![quad])?;
/// let mut renderer = Renderer::new();
/// for k in 0..3 {
///     let eye = DVec3::new(k as f64, -6.0, 6.0);
///     let cam = Camera::look_at(eye, DVec3::ZERO, DVec3::Z, 50.0, 32, 24)?;
///     let opts = RenderOptions::default().with_method(Method::ShadowMap);
///     let frame = renderer.render(&scene, &[], &cam, &[], &opts)?;
///     assert_eq!(frame.visibility.prim[12 * 32 + 16], 0);
/// }
/// # Ok::<(), shadow_raster::RasterError>(())
/// ```
#[derive(Default)]
pub struct Renderer {
    frame: hsr::FrameBuffers,
    shadow: shadow::ShadowBuffers,
    shade: image::ShadeBuffers,
    last: Option<Rendered>,
}

impl std::fmt::Debug for Renderer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Renderer")
            .field(
                "last",
                &self.last.as_ref().map(|r| (r.image.width, r.image.height)),
            )
            .finish_non_exhaustive()
    }
}

impl Renderer {
    /// A renderer with no buffers yet.
    pub fn new() -> Renderer {
        Renderer::default()
    }

    /// [`render`] in this renderer's buffers: the frame is the renderer's
    /// until the next call.
    pub fn render(
        &mut self,
        scene: &RasterScene,
        lights: &[PlacedLight],
        camera: &Camera,
        colors: &[DVec3],
        opts: &RenderOptions,
    ) -> Result<&Rendered, RasterError> {
        let lights = &scene_lights(lights)?;
        self.render_lights(scene, lights, camera, colors, opts)
    }

    /// [`render_soft`] in this renderer's buffers.
    pub fn render_soft(
        &mut self,
        scene: &RasterScene,
        lights: &[SoftLight],
        camera: &Camera,
        colors: &[DVec3],
        opts: &RenderOptions,
    ) -> Result<&Rendered, RasterError> {
        let lights = &soft_scene_lights(lights)?;
        self.render_lights(scene, lights, camera, colors, opts)
    }

    fn render_lights(
        &mut self,
        scene: &RasterScene,
        lights: &[SceneLight],
        camera: &Camera,
        colors: &[DVec3],
        opts: &RenderOptions,
    ) -> Result<&Rendered, RasterError> {
        opts.shadow.validate()?;
        let (method, shadow) = (opts.method, &opts.shadow);
        self.frame_with(
            scene,
            camera,
            (opts.cull_back_faces, opts.hsr),
            lights,
            colors,
            |frame, vis, bufs| shadow::shadows_in(frame, vis, lights, method, shadow, bufs),
        )
    }

    /// [`render_fragments`] in this renderer's buffers.
    pub fn render_fragments(
        &mut self,
        scene: &RasterScene,
        batch: &svbsp::Batch,
        lights: &[PlacedLight],
        camera: &Camera,
        colors: &[DVec3],
    ) -> Result<&Rendered, RasterError> {
        let lights = &scene_lights(lights)?;
        self.frame_with(
            scene,
            camera,
            (false, Hsr::ZBuffer),
            lights,
            colors,
            |frame, vis, _| {
                let t = Instant::now();
                let (lit, mut figures) = exact::draw_fragments(frame, vis, lights.len(), batch);
                figures.time = t.elapsed();
                Ok((lit, figures))
            },
        )
    }

    /// One frame in this renderer's buffers: visibility by `hsr` (back
    /// faces culled with `cull`), the lit amounts by `shadows`, shading.
    /// The previous frame's buffers are handed on for reuse.
    fn frame_with(
        &mut self,
        scene: &RasterScene,
        camera: &Camera,
        (cull, hsr): (bool, Hsr),
        lights: &[SceneLight],
        colors: &[DVec3],
        shadows: impl FnOnce(
            &hsr::Frame<'_>,
            &hsr::VisibilityBuffer,
            &mut shadow::ShadowBuffers,
        ) -> Result<(LitBuffer, ShadowFigures), RasterError>,
    ) -> Result<&Rendered, RasterError> {
        let t = Instant::now();
        let last = self.last.take();
        let frame = hsr::Frame::with_buffers(scene, camera, cull, std::mem::take(&mut self.frame))?;
        let (spare_vis, spare_img) = match last {
            Some(r) => {
                self.shadow.lit = Some(r.lit);
                (Some(r.visibility), Some(r.image))
            }
            None => (None, None),
        };
        let visibility = hsr::visibility_in(&frame, hsr, spare_vis);
        let visibility_time = t.elapsed();
        let (lit, figures) = shadows(&frame, &visibility, &mut self.shadow)?;
        let out = self.shaded(
            &frame,
            (visibility, visibility_time),
            lit,
            figures,
            lights,
            colors,
            spare_img,
        );
        self.frame = frame.into_buffers();
        Ok(self.last.insert(out))
    }

    /// The last frame rendered, if any.
    pub fn rendered(&self) -> Option<&Rendered> {
        self.last.as_ref()
    }

    /// The last frame rendered, the buffers given up.
    pub fn into_rendered(self) -> Option<Rendered> {
        self.last
    }

    /// Shades a frame's visibility and lit amounts into a [`Rendered`].
    #[allow(clippy::too_many_arguments)]
    fn shaded(
        &mut self,
        frame: &hsr::Frame<'_>,
        (visibility, visibility_time): (VisibilityBuffer, Duration),
        lit: LitBuffer,
        figures: ShadowFigures,
        lights: &[SceneLight],
        colors: &[DVec3],
        spare: Option<Image>,
    ) -> Rendered {
        let t = Instant::now();
        let image = image::shade_in(
            frame,
            &visibility,
            &lit,
            lights,
            colors,
            spare,
            &mut self.shade,
        );
        Rendered {
            visibility,
            lit,
            image,
            figures,
            visibility_time,
            shading_time: t.elapsed(),
        }
    }
}

/// The README's example, compiled and run as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
