//! SVG pictures by the painter's algorithm in a BSP tree's exact
//! back-to-front order: a scene's polygons ([`SvgView::polygons`]), or
//! the exact lit and shadowed fragments of them ([`SvgView::fragments`]).
//!
//! The order is exact for the eye snapped to the scene's grid; everything
//! after it — projection through the [`Camera`], near-plane and frustum
//! clipping, shading by the [`Lambert`] model — is plain `f64` display
//! arithmetic. A picture's polygons are clipped to the view widened by a
//! few pixels, so that clipped edges stay off the picture.

use std::fmt::Write;

use bsp_core::{BspTree, Grid, Order, Plane, Polygon, Side, ViewPoint};
use glam::{DVec2, DVec3};
use shadow_scene::Staging;
use svbsp::{Light, PlacedLight};

use crate::shading::Lambert;
use crate::{Camera, RasterError, default_up};

/// The background of pictures (as [`crate::BACKGROUND`]).
const BACKGROUND: &str = "#e9ecf0";

/// The key light of [`SvgView::polygons`], in camera space (`x` right,
/// `y` up, `z` forward): from the upper left, somewhat behind the viewer.
const KEY: DVec3 = DVec3::new(-0.45, 0.75, -0.5);
/// The key light's weight.
const KEY_WEIGHT: f64 = 0.58;
/// The weight of a weak light at the eye, so that faces turned from the
/// key light keep some modelling.
const HEAD_WEIGHT: f64 = 0.25;

/// `#rrggbb` of a colour (RGB in `[0, 1]`) scaled by `intensity`.
///
/// ```
/// use glam::DVec3;
/// assert_eq!(shadow_raster::svg::hex(DVec3::new(1.0, 0.5, 0.0), 1.0), "#ff8000");
/// ```
pub fn hex(c: DVec3, intensity: f64) -> String {
    let v = (c * intensity).clamp(DVec3::ZERO, DVec3::ONE) * 255.0;
    format!(
        "#{:02x}{:02x}{:02x}",
        v.x.round() as u8,
        v.y.round() as u8,
        v.z.round() as u8
    )
}

/// The unit normal of a plane, in `f64`.
pub fn unit_normal(plane: &Plane) -> DVec3 {
    DVec3::from_array(plane.normal().map(|c| c as f64)).normalize()
}

/// The exact painter's order of the tree's polygons from `eye`: indices
/// into the node-major sequence of [`BspTree::polygons`], each with
/// `true` when the polygon's front faces the eye. Polygons seen edge-on
/// are left out; within one plane, polygons turned away from the eye come
/// first so that touching solids do not bleed.
pub fn painter_order(tree: &BspTree, eye: ViewPoint) -> Vec<(usize, bool)> {
    let first = tree.polygon_offsets();
    let mut items: Vec<(usize, bool, Plane)> = Vec::new();
    tree.traverse_nodes(eye, Order::BackToFront, |id, node| {
        for (k, poly) in node.polygons.iter().enumerate() {
            let facing = poly.support().classify_viewpoint(eye);
            if facing != Side::On {
                items.push((
                    first[id as usize] + k,
                    facing == Side::Front,
                    *poly.support(),
                ));
            }
        }
    });
    let mut start = 0;
    while start < items.len() {
        let plane = items[start].2;
        let mut end = start + 1;
        while end < items.len() && items[end].2.is_coincident(&plane) {
            end += 1;
        }
        items[start..end].sort_by_key(|&(_, toward, _)| toward);
        start = end;
    }
    items
        .into_iter()
        .map(|(i, toward, _)| (i, toward))
        .collect()
}

/// Where an SVG picture is seen from: a [`Camera`] at the eye snapped to
/// the scene's grid (the painter's order is exact for that point), and
/// the scene's size, which sets the near plane.
#[derive(Clone, Debug)]
pub struct SvgView {
    camera: Camera,
    eye: ViewPoint,
    /// Focal length in pixels.
    focal: f64,
    /// The near plane and the four sides of the widened view frustum,
    /// each `n · c + d >= 0` in camera space.
    planes: [(DVec3, f64); 5],
}

/// Where an [`SvgView`] looks from and at, and the picture's size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SvgViewpoint {
    /// The eye, in input units (snapped to the grid).
    pub eye: DVec3,
    /// The point looked at [`None`]: the centre of the scene's box].
    pub target: Option<DVec3>,
    /// The up direction [`None`]: [`default_up`]].
    pub up: Option<DVec3>,
    /// Picture width in pixels.
    pub width: u32,
    /// Picture height in pixels.
    pub height: u32,
    /// Vertical field of view in degrees.
    pub fov_deg: f64,
}

/// What a user gave of a viewpoint: any of the eye, the target and the
/// up direction.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ViewRequest {
    /// The eye.
    pub eye: Option<DVec3>,
    /// The point looked at.
    pub target: Option<DVec3>,
    /// The up direction.
    pub up: Option<DVec3>,
}

impl SvgViewpoint {
    /// The viewpoint of a `width`×`height` picture from `staging`'s eye
    /// toward its target, with its up, and a vertical field of view of
    /// `fov_deg`.
    pub fn of_staging(staging: Staging, (width, height): (u32, u32), fov_deg: f64) -> SvgViewpoint {
        SvgViewpoint {
            eye: staging.eye,
            target: Some(staging.target),
            up: staging.up,
            width,
            height,
            fov_deg,
        }
    }

    /// The viewpoint of a `width`×`height` picture of `positions` with a
    /// vertical field of view of `fov_deg`, completing what was `given`:
    /// an eye given is kept (its up from `staging` unless given); else a
    /// built-in scene's `staging` is used; else the camera frames every
    /// vertex ([`Staging::framing`], with `given.up`, default +z, as up).
    /// The flag says whether the camera was framed, which is worth
    /// telling the user.
    pub fn choose(
        given: ViewRequest,
        positions: &[DVec3],
        staging: Option<Staging>,
        (width, height): (u32, u32),
        fov_deg: f64,
    ) -> (SvgViewpoint, bool) {
        let aspect = width as f64 / height as f64;
        let up_axis = given.up.unwrap_or(DVec3::Z);
        let ((eye, target, up), framed) = match (given.eye, staging) {
            (Some(e), s) => ((e, given.target, given.up.or(s.and_then(|s| s.up))), false),
            (None, Some(s)) => {
                let target = Some(given.target.unwrap_or(s.target));
                ((s.eye, target, given.up.or(s.up)), false)
            }
            (None, None) => match Staging::framing(positions, up_axis, fov_deg, aspect) {
                Some(s) => ((s.eye, Some(given.target.unwrap_or(s.target)), s.up), true),
                // no vertex: nothing to frame (drawing it fails later)
                None => ((DVec3::ONE, given.target, given.up), false),
            },
        };
        let at = SvgViewpoint {
            eye,
            target,
            up,
            width,
            height,
            fov_deg,
        };
        (at, framed)
    }

    /// The raster camera of this viewpoint (the eye as given) for a scene
    /// spanning `bounds`: the target defaults to the box's centre, the up
    /// direction to [`default_up`].
    pub fn camera(&self, bounds: (DVec3, DVec3)) -> Result<Camera, RasterError> {
        let target = self.target.unwrap_or((bounds.0 + bounds.1) * 0.5);
        let up = self.up.unwrap_or_else(|| default_up(self.eye, target));
        Camera::look_at(self.eye, target, up, self.fov_deg, self.width, self.height)
    }
}

impl SvgView {
    /// The view of a scene on `grid` whose vertices span `bounds`, from
    /// `at.eye` snapped to the grid.
    pub fn new(
        grid: &Grid,
        bounds: (DVec3, DVec3),
        at: &SvgViewpoint,
    ) -> Result<SvgView, RasterError> {
        let (lo, hi) = bounds;
        let eye = grid
            .snap_viewpoint(at.eye)
            .map_err(|cause| RasterError::EyeOffGrid { eye: at.eye, cause })?;
        let eye_world = grid.viewpoint_to_world(eye);
        let target = at.target.unwrap_or((lo + hi) * 0.5);
        let up = match at.up {
            Some(u) => u.try_normalize().unwrap_or(u),
            None => default_up(eye_world, target),
        };
        let camera =
            Camera::look_at_any_size(eye_world, target, up, at.fov_deg, at.width, at.height)?;
        let focal = 0.5 * at.height as f64 / (0.5 * at.fov_deg.to_radians()).tan();
        let diagonal = (hi - lo).length().max(grid.step());
        let near = 1e-4 * diagonal.max((eye_world - target).length());
        let kx = (0.5 * at.width as f64 + 4.0) / focal;
        let ky = (0.5 * at.height as f64 + 4.0) / focal;
        let planes = [
            (DVec3::Z, -near),
            (DVec3::new(1.0, 0.0, kx), 0.0),
            (DVec3::new(-1.0, 0.0, kx), 0.0),
            (DVec3::new(0.0, 1.0, ky), 0.0),
            (DVec3::new(0.0, -1.0, ky), 0.0),
        ];
        Ok(SvgView {
            camera,
            eye,
            focal,
            planes,
        })
    }

    /// The camera (at the snapped eye).
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// The snapped eye.
    pub fn eye(&self) -> ViewPoint {
        self.eye
    }

    /// World point to camera space: `x` right, `y` up, `z` forward.
    fn to_camera(&self, p: DVec3) -> DVec3 {
        let d = p - self.camera.eye();
        DVec3::new(
            d.dot(self.camera.right()),
            d.dot(self.camera.up()),
            d.dot(self.camera.forward()),
        )
    }

    /// Camera-space point (in front of the eye) to pixel coordinates.
    fn project(&self, c: DVec3) -> (f64, f64) {
        (
            0.5 * self.camera.width() as f64 + self.focal * c.x / c.z,
            0.5 * self.camera.height() as f64 - self.focal * c.y / c.z,
        )
    }

    /// A convex polygon given in input units, clipped and projected to
    /// pixels; `None` if nothing of it is in view.
    fn clip_project(&self, world: impl IntoIterator<Item = DVec3>) -> Option<Vec<(f64, f64)>> {
        let mut pts: Vec<DVec3> = world.into_iter().map(|w| self.to_camera(w)).collect();
        for (n, d) in self.planes {
            if pts.len() < 3 {
                return None;
            }
            pts = clip(&pts, n, d);
        }
        (pts.len() >= 3).then(|| pts.iter().map(|c| self.project(*c)).collect())
    }

    /// Every polygon of `tree` back to front, each filled with its face's
    /// colour (`colors`, by the polygons' tags) under the [`Lambert::VIEW`]
    /// lighting: a key light and a light at the eye.
    pub fn polygons(&self, tree: &BspTree, grid: &Grid, colors: &[DVec3]) -> SvgPicture {
        let mut canvas = Canvas::new(self, "shadow view", 0.7);
        let cam = &self.camera;
        let key = (cam.right() * KEY.x + cam.up() * KEY.y + cam.forward() * KEY.z).normalize();
        let to_viewer = -cam.forward();
        let polys: Vec<&Polygon> = tree.polygons().collect();
        for (i, toward) in painter_order(tree, self.eye) {
            let poly = polys[i];
            let mut normal = unit_normal(poly.support());
            if !toward {
                normal = -normal;
            }
            // one light value per plane: the head light shines along the view
            let light = Lambert::VIEW.base(normal, to_viewer)
                + Lambert::cosine(KEY_WEIGHT, normal, key)
                + Lambert::cosine(HEAD_WEIGHT, normal, to_viewer);
            let fill = hex(colors[poly.tag() as usize], light);
            let world = poly.vertices_f64().into_iter().map(|g| grid.to_world(g));
            canvas.polygon(world, &fill);
        }
        canvas.finish()
    }

    /// [`SvgView::fragments`] of the faces of `mesh` (snapped to `grid`,
    /// its polygons in `tree`) seen from `at`: the mesh gives the view's
    /// box, each face's colour ([`shadow_scene::face_colors`]) and the
    /// centres its shading is taken at.
    pub fn mesh_fragments(
        grid: &Grid,
        mesh: &shadow_scene::Mesh,
        at: &SvgViewpoint,
        tree: &BspTree,
        lights: &[PlacedLight],
        frags: &[SvgFragment],
        what: &str,
    ) -> Result<SvgPicture, RasterError> {
        let bounds = mesh.bounds().ok_or(RasterError::EmptyScene)?;
        let view = SvgView::new(grid, bounds, at)?;
        let colors = shadow_scene::face_colors(mesh);
        let centres = mesh.face_centres();
        view.fragments(tree, lights, frags, (&colors, &centres), what)
    }

    /// Exact fragments of `tree`'s polygons drawn in the tree's painter's
    /// order, each shaded by the lights that reach it under the
    /// [`Lambert::SHADOWS`] lighting, the cosines taken at its face's
    /// centre (`centres`, by face) so that a face's lit fragments share
    /// one shade and only the shadow boundaries show. `colors` gives each
    /// face's base colour; `what` names the picture in a comment.
    pub fn fragments(
        &self,
        tree: &BspTree,
        lights: &[PlacedLight],
        frags: &[SvgFragment],
        (colors, centres): (&[DVec3], &[DVec3]),
        what: &str,
    ) -> Result<SvgPicture, RasterError> {
        // fragments meet along many more edges than whole polygons: a
        // wider stroke keeps their seams closed
        let mut canvas = Canvas::new(self, what, 1.0);
        let polys: Vec<&Polygon> = tree.polygons().collect();
        let mut per_polygon: Vec<Vec<usize>> = vec![Vec::new(); polys.len()];
        for (j, f) in frags.iter().enumerate() {
            let slot = per_polygon
                .get_mut(f.polygon)
                .ok_or(RasterError::FragmentPolygon {
                    fragment: j,
                    polygon: f.polygon,
                })?;
            slot.push(j);
        }
        let to_viewer = -self.camera.forward();
        let order = painter_order(tree, self.eye);
        // runs of coplanar polygons facing the same way: their fragments
        // tile the plane without overlap, so each colour is one region
        let mut start = 0;
        while start < order.len() {
            let (first, toward) = order[start];
            let plane = polys[first].support();
            let mut end = start + 1;
            while end < order.len()
                && order[end].1 == toward
                && polys[order[end].0].support().is_coincident(plane)
            {
                end += 1;
            }
            let mut regions: Vec<(String, Vec<usize>)> = Vec::new();
            for &(poly, _) in &order[start..end] {
                for &j in &per_polygon[poly] {
                    let f = &frags[j];
                    if toward && !f.ramps.is_empty() {
                        // a soft shade: each piece with its own gradient
                        let at = |p| brightness_at(f, Some(p), centres[f.face], lights, to_viewer);
                        for piece in &f.pieces {
                            canvas.ramp(piece, colors[f.face], &at);
                        }
                        continue;
                    }
                    let b = if toward {
                        brightness(f, centres[f.face], lights, to_viewer)
                    } else {
                        // the back of a surface: no light is in front of it
                        Lambert::SHADOWS.ambient
                    };
                    let fill = hex(colors[f.face], b);
                    match regions.iter_mut().find(|(c, _)| *c == fill) {
                        Some((_, members)) => members.push(j),
                        None => regions.push((fill, vec![j])),
                    }
                }
            }
            for (fill, members) in &regions {
                let pieces = members
                    .iter()
                    .flat_map(|&j| frags[j].pieces.iter().map(|p| p.iter().copied()));
                canvas.region(pieces, fill);
            }
            start = end;
        }
        Ok(canvas.finish())
    }
}

/// Brightness of a fragment seen from its front at point `p`, lit by the
/// lights of its mask and by its lights of extent in the shares at `p`
/// (a light's ramp where it has one, else its flat share):
/// [`Lambert::SHADOWS`] at its face's centre `centre`.
fn brightness_at(
    f: &SvgFragment,
    p: Option<DVec3>,
    centre: DVec3,
    lights: &[PlacedLight],
    to_viewer: DVec3,
) -> f64 {
    let weight = Lambert::weight(lights.len());
    let mut b = Lambert::SHADOWS.base(f.normal, to_viewer);
    let full = (0..lights.len())
        .filter(|j| f.lit >> j & 1 == 1)
        .map(|j| (j, 1.0));
    let share = |&(j, flat): &(usize, f64)| {
        let ramp = p.and_then(|p| Some((p, f.ramps.iter().find(|r| r.0 == j)?.1)));
        let at =
            ramp.map(|(p, [gx, gy, gz, d])| (gx * p.x + gy * p.y + gz * p.z + d).clamp(0.0, 1.0));
        (j, at.unwrap_or(flat))
    };
    for (j, share) in full.chain(f.shares.iter().map(share)) {
        let Some(l) = lights.get(j) else { continue };
        let to_light = match l.light {
            Light::Point(_) => (l.world - centre).normalize_or_zero(),
            Light::Directional(_) => l.world,
        };
        b += share * Lambert::cosine(weight, f.normal, to_light);
    }
    b
}

/// [`brightness_at`] with every share flat.
fn brightness(f: &SvgFragment, centre: DVec3, lights: &[PlacedLight], to_viewer: DVec3) -> f64 {
    brightness_at(f, None, centre, lights, to_viewer)
}

/// A fragment to draw: a part of BSP polygon `polygon` (an index into
/// [`BspTree::polygons`]) of face `face`, lit by the lights of the mask
/// `lit`, as convex pieces in input units.
#[derive(Clone, Debug)]
pub struct SvgFragment {
    /// The BSP polygon it is a part of.
    pub polygon: usize,
    /// Its face.
    pub face: usize,
    /// The lights that reach all of it (bit `j`: light `j`).
    pub lit: u64,
    /// Lights of extent that reach part of it: the light's index and the
    /// share of its irradiance that arrives (soft shadows' penumbra).
    pub shares: Vec<(usize, f64)>,
    /// Where given, the shares vary over it: for a light of `shares`,
    /// the share at a point `p` (input units) is `g · p + d` (`[g, d]`),
    /// clamped to `[0, 1]` (a light of `shares` without one keeps its
    /// flat share); the fragment is then drawn with a gradient.
    pub ramps: Vec<(usize, [f64; 4])>,
    /// The unit normal of its front.
    pub normal: DVec3,
    /// Its convex pieces, in input units.
    pub pieces: Vec<Vec<DVec3>>,
}

impl SvgFragment {
    /// The fragments of `batch` whose receivers are the polygons of a
    /// tree (receiver `i`: polygon `i`), with `world` the batch's vertices
    /// in input units.
    pub fn of_batch(batch: &svbsp::Batch, world: &[DVec3]) -> Vec<SvgFragment> {
        batch
            .fragments()
            .map(|f| SvgFragment {
                polygon: f.receiver() as usize,
                face: f.face() as usize,
                lit: f.lit_mask(),
                shares: Vec::new(),
                ramps: Vec::new(),
                normal: unit_normal(f.support()),
                pieces: f
                    .pieces()
                    .map(|p| p.iter().map(|&v| world[v as usize]).collect())
                    .collect(),
            })
            .collect()
    }
}

impl SvgFragment {
    /// The fragments of `batch` (fragments of `faces` faces, `world` its
    /// vertices in input units) cut to the polygons of `tree`, a BSP tree
    /// of the same faces (each polygon tagged with its face): each
    /// fragment's pieces clipped, in `f64` and for the picture only, to
    /// every polygon of its face in turn.
    pub fn of_faces_in_tree(
        tree: &BspTree,
        grid: &Grid,
        batch: &svbsp::Batch,
        world: &[DVec3],
        faces: usize,
    ) -> Vec<SvgFragment> {
        let of_faces = SvgFragment::of_batch(batch, world);
        SvgFragment::cut_to_tree(tree, grid, &of_faces, faces)
    }

    /// Fragments of faces (`face` set, `polygon` ignored; `faces` faces)
    /// cut to the polygons of `tree`, a BSP tree of the same faces (each
    /// polygon tagged with its face): each fragment's pieces clipped, in
    /// `f64` and for the picture only, to every polygon of its face in
    /// turn.
    pub fn cut_to_tree(
        tree: &BspTree,
        grid: &Grid,
        of_faces: &[SvgFragment],
        faces: usize,
    ) -> Vec<SvgFragment> {
        let mut of_face: Vec<Vec<&SvgFragment>> = vec![Vec::new(); faces];
        for f in of_faces {
            if let Some(list) = of_face.get_mut(f.face) {
                list.push(f);
            }
        }
        let mut frags = Vec::new();
        for (pi, p) in tree.polygons().enumerate() {
            let outline: Vec<DVec3> = p
                .vertices_f64()
                .into_iter()
                .map(|v| grid.to_world(v))
                .collect();
            let n = unit_normal(p.support());
            let Some(list) = of_face.get(p.tag() as usize) else {
                continue;
            };
            for f in list {
                let pieces: Vec<Vec<DVec3>> = f
                    .pieces
                    .iter()
                    .filter_map(|piece| clip_to_outline(piece.clone(), &outline, n))
                    .collect();
                if !pieces.is_empty() {
                    frags.push(SvgFragment {
                        polygon: pi,
                        pieces,
                        ..(*f).clone()
                    });
                }
            }
        }
        frags
    }
}

/// `poly` clipped to the convex `outline` (counter-clockwise about `n`),
/// if anything is left.
fn clip_to_outline(mut poly: Vec<DVec3>, outline: &[DVec3], n: DVec3) -> Option<Vec<DVec3>> {
    for e in 0..outline.len() {
        let (a, b) = (outline[e], outline[(e + 1) % outline.len()]);
        // inside: to the left of a → b seen from the normal
        let m = n.cross(b - a);
        poly = clip(&poly, m, -m.dot(a));
        if poly.len() < 3 {
            return None;
        }
    }
    (poly.len() >= 3).then_some(poly)
}

/// The linear gradient of values `b` at points `pts` (pixels): the
/// affine function through the first corner and the two that span the
/// largest triangle with it, from where it is least to where it is most
/// over the corners, with those values; `None` where it is flat or the
/// polygon covers less than a pixel.
#[allow(clippy::type_complexity)]
fn gradient(pts: &[(f64, f64)], b: &[f64]) -> Option<((f64, f64), (f64, f64), f64, f64)> {
    let p = |i: usize| DVec2::new(pts[i].0, pts[i].1);
    let n = pts.len();
    let (mut best, mut pick) = (0.0, (1, 2));
    for i in 1..n {
        for k in i + 1..n {
            let a = (p(i) - p(0)).perp_dot(p(k) - p(0)).abs();
            if a > best {
                (best, pick) = (a, (i, k));
            }
        }
    }
    let (e1, e2) = (p(pick.0) - p(0), p(pick.1) - p(0));
    let det = e1.perp_dot(e2);
    // under a square pixel: too small to show a gradient
    if best < 1.0 {
        return None;
    }
    // g · e1 = b1 − b0, g · e2 = b2 − b0
    let (d1, d2) = (b[pick.0] - b[0], b[pick.1] - b[0]);
    let g = DVec2::new(d1 * e2.y - d2 * e1.y, e1.x * d2 - e2.x * d1) / det;
    let (lo, hi) = b
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
            (l.min(v), h.max(v))
        });
    let g2 = g.length_squared();
    if hi <= lo || g2 == 0.0 {
        return None;
    }
    let from = p(0) + g * ((lo - b[0]) / g2);
    let to = p(0) + g * ((hi - b[0]) / g2);
    Some(((from.x, from.y), (to.x, to.y), lo, hi))
}

/// A finished SVG picture.
#[derive(Clone, Debug)]
pub struct SvgPicture {
    /// The SVG document.
    pub svg: String,
    /// Polygons (pieces) drawn after clipping.
    pub drawn: usize,
    /// The eye used, in input units (snapped to the grid).
    pub eye: DVec3,
}

/// An SVG being drawn: polygons in input units go in one after the other
/// (painter's order is the caller's), clipped and projected.
struct Canvas<'v> {
    view: &'v SvgView,
    svg: String,
    drawn: usize,
}

impl<'v> Canvas<'v> {
    /// Writes the SVG header; `what` names the drawing in a comment.
    /// Polygons are stroked `stroke` pixels wide in their fill colour,
    /// which closes anti-aliasing seams between neighbours.
    fn new(view: &'v SvgView, what: &str, stroke: f64) -> Canvas<'v> {
        let (w, h) = (view.camera.width(), view.camera.height());
        let eye = view.camera.eye();
        let mut svg = String::new();
        let _ = writeln!(svg, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
        let _ = writeln!(
            svg,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}">"#
        );
        let _ = writeln!(
            svg,
            "<!-- {what}: BSP back-to-front order from eye {:.4},{:.4},{:.4} -->",
            eye.x, eye.y, eye.z
        );
        let _ = writeln!(
            svg,
            r##"<rect width="{w}" height="{h}" fill="{BACKGROUND}"/>"##
        );
        let _ = writeln!(
            svg,
            r#"<g stroke-width="{stroke}" stroke-linejoin="round">"#
        );
        Canvas {
            view,
            svg,
            drawn: 0,
        }
    }

    /// Draws a convex polygon given in input units, filled and stroked
    /// with `fill`; nothing if it lies outside the view.
    fn polygon(&mut self, world: impl IntoIterator<Item = DVec3>, fill: &str) {
        let Some(pts) = self.view.clip_project(world) else {
            return;
        };
        self.svg.push_str("<polygon points=\"");
        for (i, (x, y)) in pts.iter().enumerate() {
            let _ = write!(self.svg, "{}{x:.2},{y:.2}", if i > 0 { " " } else { "" });
        }
        let _ = writeln!(self.svg, "\" fill=\"{fill}\" stroke=\"{fill}\"/>");
        self.drawn += 1;
    }

    /// Draws a convex polygon given in input units shaded from colour `c`
    /// by the brightness `at` its points: a linear gradient through the
    /// brightness at three of its corners as projected (exact for a
    /// brightness affine in the picture's plane; a polygon cut by the
    /// view's edges gets its corners' mean, flat).
    fn ramp(&mut self, world: &[DVec3], c: DVec3, at: &dyn Fn(DVec3) -> f64) {
        let Some(pts) = self.view.clip_project(world.iter().copied()) else {
            return;
        };
        let b: Vec<f64> = world.iter().map(|&p| at(p)).collect();
        let mean = b.iter().sum::<f64>() / b.len().max(1) as f64;
        let fill = match (pts.len() == world.len())
            .then(|| gradient(&pts, &b))
            .flatten()
        {
            Some(((x1, y1), (x2, y2), lo, hi)) => {
                let id = self.drawn;
                let _ = writeln!(
                    self.svg,
                    r#"<linearGradient id="r{id}" gradientUnits="userSpaceOnUse" x1="{x1:.2}" y1="{y1:.2}" x2="{x2:.2}" y2="{y2:.2}"><stop offset="0" stop-color="{}"/><stop offset="1" stop-color="{}"/></linearGradient>"#,
                    hex(c, lo),
                    hex(c, hi)
                );
                format!("url(#r{id})")
            }
            None => hex(c, mean),
        };
        self.svg.push_str("<polygon points=\"");
        for (i, (x, y)) in pts.iter().enumerate() {
            let _ = write!(self.svg, "{}{x:.2},{y:.2}", if i > 0 { " " } else { "" });
        }
        let _ = writeln!(self.svg, "\" fill=\"{fill}\" stroke=\"{fill}\"/>");
        self.drawn += 1;
    }

    /// Draws convex polygons that tile a region of one plane (in input
    /// units) as one path of one colour, so that the edges they share
    /// leave no anti-aliasing seam. Returns how many pieces were in view.
    fn region<I>(&mut self, pieces: impl IntoIterator<Item = I>, fill: &str) -> usize
    where
        I: IntoIterator<Item = DVec3>,
    {
        let mut d = String::new();
        let mut drawn = 0;
        for piece in pieces {
            let Some(pts) = self.view.clip_project(piece) else {
                continue;
            };
            for (i, (x, y)) in pts.iter().enumerate() {
                let _ = write!(d, "{}{x:.2},{y:.2}", if i == 0 { "M" } else { "L" });
            }
            d.push('Z');
            drawn += 1;
        }
        if drawn > 0 {
            let _ = writeln!(
                self.svg,
                "<path d=\"{d}\" fill=\"{fill}\" stroke=\"{fill}\"/>"
            );
            self.drawn += drawn;
        }
        drawn
    }

    /// Closes the SVG.
    fn finish(mut self) -> SvgPicture {
        self.svg.push_str("</g>\n</svg>\n");
        SvgPicture {
            svg: self.svg,
            drawn: self.drawn,
            eye: self.view.camera.eye(),
        }
    }
}

/// Clips a convex polygon to the half-space `n · p + d >= 0`
/// (Sutherland–Hodgman for one plane).
fn clip(poly: &[DVec3], n: DVec3, d: f64) -> Vec<DVec3> {
    let mut out = Vec::with_capacity(poly.len() + 1);
    let k = poly.len();
    for i in 0..k {
        let (a, b) = (poly[i], poly[(i + 1) % k]);
        let (da, db) = (n.dot(a) + d, n.dot(b) + d);
        if da >= 0.0 {
            out.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            out.push(a + (b - a) * (da / (da - db)));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use bsp_core::{BuildOptions, import_faces};

    /// A gradient runs from the least value to the most, and the affine
    /// function it draws takes the given values at the corners; flat or
    /// sub-pixel polygons get none.
    #[test]
    fn gradients_reproduce_affine_values() {
        let pts = [(10.0, 10.0), (110.0, 20.0), (90.0, 80.0), (20.0, 70.0)];
        let f = |(x, y): (f64, f64)| 0.2 + 0.004 * x - 0.003 * y;
        let b: Vec<f64> = pts.iter().map(|&p| f(p)).collect();
        let ((x1, y1), (x2, y2), lo, hi) = gradient(&pts, &b).unwrap();
        assert!((f((x1, y1)) - lo).abs() < 1e-12 && (f((x2, y2)) - hi).abs() < 1e-12);
        let (min, max) = b
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
                (l.min(v), h.max(v))
            });
        assert_eq!((lo, hi), (min, max));
        assert!(gradient(&pts, &[0.5; 4]).is_none());
        let tiny = [(0.0, 0.0), (0.5, 0.0), (0.0, 0.5)];
        assert!(gradient(&tiny, &[0.0, 1.0, 0.5]).is_none());
    }

    /// A mesh snapped to its own grid and built into a tree.
    fn prepared(mesh: &shadow_scene::Mesh) -> (Grid, BspTree) {
        let grid = Grid::fit_points(&mesh.positions).unwrap();
        let loops = mesh.face_loops();
        let (polys, _) = import_faces(&grid, loops.iter().map(Vec::as_slice)).unwrap();
        (grid, BspTree::build(polys, &BuildOptions::default()))
    }

    /// The mesh's polygons drawn from `at`, as `shadow view` draws them.
    fn render_svg(
        mesh: &shadow_scene::Mesh,
        at: SvgViewpoint,
    ) -> Result<SvgPicture, Box<dyn std::error::Error>> {
        let (grid, tree) = prepared(mesh);
        let bounds = mesh.bounds().ok_or("nothing to draw")?;
        let view = SvgView::new(&grid, bounds, &at)?;
        let colors = shadow_scene::face_colors(mesh);
        Ok(view.polygons(&tree, &grid, &colors))
    }

    fn at(
        eye: DVec3,
        target: Option<DVec3>,
        (width, height): (u32, u32),
        fov: f64,
    ) -> SvgViewpoint {
        SvgViewpoint {
            eye,
            target,
            up: None,
            width,
            height,
            fov_deg: fov,
        }
    }

    #[test]
    fn camera_looks_down_forward() {
        let grid = Grid::new(DVec3::ZERO, 10).unwrap();
        let cube = (DVec3::splat(-1.0), DVec3::ONE);
        let v = |eye, up| SvgViewpoint {
            up,
            ..at(eye, Some(DVec3::ZERO), (200, 100), 90.0)
        };
        let view = SvgView::new(&grid, cube, &v(DVec3::new(0.0, -5.0, 0.0), None)).unwrap();
        // the target projects to the image centre, +z is up on screen
        let (x, y) = view.project(view.to_camera(DVec3::ZERO));
        assert_eq!((x, y), (100.0, 50.0));
        let (x, y) = view.project(view.to_camera(DVec3::new(1.0, 0.0, 1.0)));
        assert!(x > 100.0 && y < 50.0);
        // looking straight down falls back to +Y as up
        let view = SvgView::new(&grid, cube, &v(DVec3::Z * 3.0, None)).unwrap();
        assert!(view.camera().up().abs_diff_eq(DVec3::Y, 1e-12));
        let eye_at_target = SvgViewpoint {
            target: Some(DVec3::ONE),
            ..v(DVec3::ONE, None)
        };
        assert!(SvgView::new(&grid, cube, &eye_at_target).is_err());
        let up_along_view = SvgViewpoint {
            target: Some(DVec3::X),
            ..v(DVec3::ZERO, Some(DVec3::X))
        };
        assert!(SvgView::new(&grid, cube, &up_along_view).is_err());
    }

    #[test]
    fn clipping_a_square_by_a_plane() {
        let sq = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(2.0, 2.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
        ];
        // keep x <= 1
        let c = clip(&sq, DVec3::new(-1.0, 0.0, 0.0), 1.0);
        assert_eq!(
            c,
            vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(1.0, 2.0, 0.0),
                DVec3::new(0.0, 2.0, 0.0),
            ]
        );
        assert!(clip(&sq, DVec3::X, -5.0).is_empty());
        assert_eq!(clip(&sq, DVec3::X, 5.0).len(), 4);
    }

    #[test]
    fn near_polygons_are_clipped_not_flipped() {
        // a floor under an eye standing on it: only the part ahead is drawn
        let mesh = shadow_scene::parse_obj(
            "v -10 -10 0\nv 10 -10 0\nv 10 10 0\nv -10 10 0\nf 1 2 3 4\n",
            "floor.obj",
        )
        .unwrap();
        let view = at(
            DVec3::new(0.0, 0.0, 1.0),
            Some(DVec3::new(0.0, 5.0, 0.0)),
            (100, 100),
            60.0,
        );
        let r = render_svg(&mesh, view).unwrap();
        assert_eq!(r.drawn, 1);
        let pts = r
            .svg
            .split("points=\"")
            .nth(1)
            .unwrap()
            .split('"')
            .next()
            .unwrap();
        for xy in pts.split(' ') {
            let (x, y) = xy.split_once(',').unwrap();
            let (x, y): (f64, f64) = (x.parse().unwrap(), y.parse().unwrap());
            assert!(
                (-5.0..=105.0).contains(&x) && (-5.0..=105.0).contains(&y),
                "{x},{y}"
            );
        }
    }

    #[test]
    fn painter_order_puts_the_near_box_last() {
        // two cubes on the x axis; from +x the near one is drawn last
        let mesh = shadow_scene::parse_obj(
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
             f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n\
             g near\nv 3 0 0\nv 4 0 0\nv 4 1 0\nv 3 1 0\nv 3 0 1\nv 4 0 1\nv 4 1 1\nv 3 1 1\n\
             f -8 -5 -6 -7\nf -4 -3 -2 -1\nf -8 -7 -3 -4\nf -7 -6 -2 -3\nf -6 -5 -1 -2\nf -5 -8 -4 -1\n",
            "two.obj",
        )
        .unwrap();
        let (grid, tree) = prepared(&mesh);
        let mut order = Vec::new();
        let vp = grid.snap_viewpoint(DVec3::new(10.0, 0.5, 0.5)).unwrap();
        tree.traverse(vp, Order::BackToFront, |poly| order.push(poly.tag()));
        let near_face = order.iter().position(|&t| t == 9).unwrap(); // x = 4 face of the near cube
        let far_face = order.iter().position(|&t| t == 3).unwrap(); // x = 1 face of the far cube
        assert!(far_face < near_face);
        let r = render_svg(&mesh, at(DVec3::new(10.0, 0.5, 0.5), None, (64, 48), 40.0)).unwrap();
        assert_eq!(r.drawn, 12);
        assert!(r.svg.starts_with("<?xml") && r.svg.ends_with("</svg>\n"));
    }

    #[test]
    fn bad_views_are_errors() {
        let cube = shadow_scene::scene("cube").unwrap();
        let mut view = at(DVec3::splat(0.5), Some(DVec3::splat(0.5)), (10, 10), 50.0);
        assert!(render_svg(&cube, view).is_err());
        view.eye = DVec3::splat(1e300);
        let e = render_svg(&cube, view).unwrap_err().to_string();
        assert!(e.contains("too far"), "{e}");
        view.eye = DVec3::ONE;
        assert!(render_svg(&shadow_scene::Mesh::default(), view).is_err());
    }

    #[test]
    fn hex_clamps() {
        assert_eq!(hex(DVec3::new(1.0, 0.5, 0.0), 1.0), "#ff8000");
        assert_eq!(hex(DVec3::new(1.0, 0.5, 0.0), 4.0), "#ffff00");
        assert_eq!(hex(DVec3::new(0.2, 0.2, 0.2), -1.0), "#000000");
    }
}
