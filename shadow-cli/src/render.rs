//! Painter's-algorithm SVG rendering in the BSP tree's exact
//! back-to-front order.
//!
//! The order is exact for the snapped eye; everything after it —
//! projection, near-plane and frustum clipping, shading — is plain `f64`
//! display arithmetic.

use std::fmt::Write;

use anyhow::{Result, bail};
use bsp_core::{BspTree, Grid, Order, Plane, Polygon, Side, ViewPoint};
use glam::DVec3;
use shadow_scene::Mesh;

use crate::color::{face_colors, hex};
use crate::pipeline::Prepared;

/// Camera parameters of a view.
#[derive(Clone, Debug)]
pub(crate) struct View {
    pub(crate) eye: DVec3,
    pub(crate) target: Option<DVec3>,
    pub(crate) up: Option<DVec3>,
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) fov_deg: f64,
}

/// A rendered image.
#[derive(Debug)]
pub(crate) struct Rendered {
    pub(crate) svg: String,
    /// Polygons (BSP fragments) drawn after clipping.
    pub(crate) drawn: usize,
    /// The camera position used: the eye snapped to the grid.
    pub(crate) eye: DVec3,
}

/// A perspective look-at camera. Camera space: `x` right, `y` up, `z`
/// forward (depth).
#[derive(Clone, Debug)]
pub(crate) struct Camera {
    eye: DVec3,
    right: DVec3,
    up: DVec3,
    forward: DVec3,
    /// Focal length in pixels.
    focal: f64,
    width: f64,
    height: f64,
}

/// Sine of the smallest angle between the view direction and the up
/// vector that still defines a camera roll.
const MIN_UP_SINE: f64 = 1e-6;

impl Camera {
    pub(crate) fn look_at(
        eye: DVec3,
        target: DVec3,
        up: Option<DVec3>,
        width: u32,
        height: u32,
        fov_deg: f64,
    ) -> Result<Camera> {
        let Some(forward) = (target - eye).try_normalize() else {
            bail!("the eye and the target coincide; give a different --eye or --target");
        };
        let up_hint = match up {
            Some(u) => match u.try_normalize() {
                Some(u) if forward.cross(u).length() > MIN_UP_SINE => u,
                Some(_) => bail!("--up is parallel to the view direction"),
                None => bail!("--up must not be the zero vector"),
            },
            None if forward.cross(DVec3::Z).length() > MIN_UP_SINE => DVec3::Z,
            None => DVec3::Y,
        };
        let right = forward.cross(up_hint).normalize();
        let up = right.cross(forward);
        let (w, h) = (width as f64, height as f64);
        let focal = 0.5 * h / (0.5 * fov_deg.to_radians()).tan();
        Ok(Camera {
            eye,
            right,
            up,
            forward,
            focal,
            width: w,
            height: h,
        })
    }

    /// The unit viewing direction.
    pub(crate) fn forward(&self) -> DVec3 {
        self.forward
    }

    /// World point to camera space.
    pub(crate) fn to_camera(&self, p: DVec3) -> DVec3 {
        let d = p - self.eye;
        DVec3::new(d.dot(self.right), d.dot(self.up), d.dot(self.forward))
    }

    /// Camera-space point (in front of the eye) to pixel coordinates.
    pub(crate) fn project(&self, c: DVec3) -> (f64, f64) {
        (
            0.5 * self.width + self.focal * c.x / c.z,
            0.5 * self.height - self.focal * c.y / c.z,
        )
    }

    /// The planes `a · p >= 0` bounding what is drawn: near plane at
    /// `near`, and the four sides of the view frustum widened by a few
    /// pixels so that clipped edges stay off the image.
    fn clip_planes(&self, near: f64) -> [(DVec3, f64); 5] {
        let kx = (0.5 * self.width + 4.0) / self.focal;
        let ky = (0.5 * self.height + 4.0) / self.focal;
        [
            (DVec3::Z, -near),
            (DVec3::new(1.0, 0.0, kx), 0.0),
            (DVec3::new(-1.0, 0.0, kx), 0.0),
            (DVec3::new(0.0, 1.0, ky), 0.0),
            (DVec3::new(0.0, -1.0, ky), 0.0),
        ]
    }
}

/// Clips a convex polygon to the half-space `n · p + d >= 0`
/// (Sutherland–Hodgman for one plane).
pub(crate) fn clip(poly: &[DVec3], n: DVec3, d: f64) -> Vec<DVec3> {
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

/// Direction toward the key light in camera space: from the upper left,
/// somewhat behind the viewer.
const KEY: DVec3 = DVec3::new(-0.45, 0.75, -0.5);
const AMBIENT: f64 = 0.38;
const KEY_WEIGHT: f64 = 0.58;
/// A weak light at the eye, so that faces turned from the key light keep
/// some modelling.
const HEAD_WEIGHT: f64 = 0.25;

/// The exact painter's order of the tree's polygons from `eye`: indices
/// into the node-major sequence of [`bsp_core::BspTree::polygons`], each
/// with `true` when the polygon's front faces the eye. Polygons seen
/// edge-on are left out; within one plane, polygons turned away from the
/// eye come first so that touching solids do not bleed.
pub(crate) fn painter_order(tree: &BspTree, eye: ViewPoint) -> Vec<(usize, bool)> {
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

/// An SVG being drawn from a camera: polygons in input units go in one
/// after the other (painter's order is the caller's), clipped to the
/// near plane and the widened view frustum.
pub(crate) struct Canvas {
    pub(crate) cam: Camera,
    planes: [(DVec3, f64); 5],
    /// The eye snapped to the grid, and in input units.
    pub(crate) eye_vp: ViewPoint,
    pub(crate) eye: DVec3,
    svg: String,
    drawn: usize,
}

impl Canvas {
    /// Sets up the camera of `view` for the scene `p` (the eye snapped to
    /// the grid) and writes the SVG header; `what` names the drawing in a
    /// comment. Polygons are stroked `stroke` pixels wide in their fill
    /// colour, which closes anti-aliasing seams between neighbours.
    pub(crate) fn new(
        mesh: &Mesh,
        grid: &Grid,
        view: &View,
        what: &str,
        stroke: f64,
    ) -> Result<Canvas> {
        let Some((lo, hi)) = mesh.bounds() else {
            bail!("nothing to draw: the mesh has no vertices");
        };
        if mesh.faces.is_empty() {
            bail!("nothing to draw: the mesh has no faces");
        }
        let eye_vp = grid.snap_viewpoint(view.eye).map_err(|e| {
            anyhow::anyhow!(
                "eye {},{},{}: {e} (too far from the scene)",
                view.eye.x,
                view.eye.y,
                view.eye.z
            )
        })?;
        let eye = grid.viewpoint_to_world(eye_vp);
        let target = view.target.unwrap_or((lo + hi) * 0.5);
        let cam = Camera::look_at(eye, target, view.up, view.width, view.height, view.fov_deg)?;
        let diagonal = (hi - lo).length().max(grid.step());
        let planes = cam.clip_planes(1e-4 * diagonal.max((eye - target).length()));
        let (w, h) = (view.width, view.height);
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
        let _ = writeln!(svg, r##"<rect width="{w}" height="{h}" fill="#e9ecf0"/>"##);
        let _ = writeln!(
            svg,
            r#"<g stroke-width="{stroke}" stroke-linejoin="round">"#
        );
        Ok(Canvas {
            cam,
            planes,
            eye_vp,
            eye,
            svg,
            drawn: 0,
        })
    }

    /// A convex polygon given in input units, clipped and projected to
    /// pixels; `None` if nothing of it is in view.
    fn project(&self, world: impl IntoIterator<Item = DVec3>) -> Option<Vec<(f64, f64)>> {
        let mut pts: Vec<DVec3> = world.into_iter().map(|w| self.cam.to_camera(w)).collect();
        for (n, d) in self.planes {
            if pts.len() < 3 {
                return None;
            }
            pts = clip(&pts, n, d);
        }
        (pts.len() >= 3).then(|| pts.iter().map(|c| self.cam.project(*c)).collect())
    }

    /// Draws a convex polygon given in input units, filled and stroked
    /// with `fill` (the stroke hides anti-aliasing seams between pieces).
    /// Nothing is drawn if it lies outside the view.
    pub(crate) fn polygon(&mut self, world: impl IntoIterator<Item = DVec3>, fill: &str) {
        let Some(pts) = self.project(world) else {
            return;
        };
        self.svg.push_str("<polygon points=\"");
        for (i, (x, y)) in pts.iter().enumerate() {
            let _ = write!(self.svg, "{}{x:.2},{y:.2}", if i > 0 { " " } else { "" });
        }
        let _ = writeln!(self.svg, "\" fill=\"{fill}\" stroke=\"{fill}\"/>");
        self.drawn += 1;
    }

    /// Draws convex polygons that tile a region of one plane (given in
    /// input units) as one path of one colour, so that the edges they share
    /// leave no anti-aliasing seam. Returns how many pieces were in view.
    pub(crate) fn region<I>(&mut self, pieces: impl IntoIterator<Item = I>, fill: &str) -> usize
    where
        I: IntoIterator<Item = DVec3>,
    {
        let mut d = String::new();
        let mut drawn = 0;
        for piece in pieces {
            let Some(pts) = self.project(piece) else {
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
    pub(crate) fn finish(mut self) -> Rendered {
        self.svg.push_str("</g>\n</svg>\n");
        Rendered {
            svg: self.svg,
            drawn: self.drawn,
            eye: self.eye,
        }
    }
}

/// Draws every polygon of the tree back to front as seen from the view's
/// eye snapped to the grid.
pub(crate) fn render_svg(p: &Prepared, view: &View) -> Result<Rendered> {
    let mut canvas = Canvas::new(&p.mesh, &p.grid, view, "shadow view", 0.7)?;
    let colors = face_colors(&p.mesh);
    let cam = &canvas.cam;
    let key = (cam.right * KEY.x + cam.up * KEY.y + cam.forward * KEY.z).normalize();
    let forward = cam.forward;
    let polys: Vec<&Polygon> = p.tree.polygons().collect();
    for (i, toward) in painter_order(&p.tree, canvas.eye_vp) {
        let poly = polys[i];
        let mut normal = unit_normal(poly.support());
        if !toward {
            normal = -normal;
        }
        // one light value per plane: the head light shines along the view
        let light = AMBIENT
            + KEY_WEIGHT * normal.dot(key).max(0.0)
            + HEAD_WEIGHT * (-normal.dot(forward)).max(0.0);
        let fill = hex(colors[poly.tag() as usize], light);
        let world = poly.vertices_f64().into_iter().map(|g| p.grid.to_world(g));
        canvas.polygon(world, &fill);
    }
    Ok(canvas.finish())
}

/// The unit normal of a plane, in `f64`.
pub(crate) fn unit_normal(plane: &Plane) -> DVec3 {
    DVec3::from_array(plane.normal().map(|c| c as f64)).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camera_looks_down_forward() {
        let cam = Camera::look_at(
            DVec3::new(0.0, -5.0, 0.0),
            DVec3::ZERO,
            None,
            200,
            100,
            90.0,
        )
        .unwrap();
        // the target projects to the image centre, +z is up on screen
        let (x, y) = cam.project(cam.to_camera(DVec3::ZERO));
        assert_eq!((x, y), (100.0, 50.0));
        let (x, y) = cam.project(cam.to_camera(DVec3::new(1.0, 0.0, 1.0)));
        assert!(x > 100.0 && y < 50.0);
        // looking straight down falls back to +Y as up
        let cam = Camera::look_at(DVec3::Z * 3.0, DVec3::ZERO, None, 10, 10, 60.0).unwrap();
        assert!(cam.up.abs_diff_eq(DVec3::Y, 1e-12));
        assert!(Camera::look_at(DVec3::ONE, DVec3::ONE, None, 10, 10, 60.0).is_err());
        assert!(Camera::look_at(DVec3::ZERO, DVec3::X, Some(DVec3::X), 10, 10, 60.0).is_err());
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
        let p = Prepared::new(mesh, "floor").unwrap();
        let view = View {
            eye: DVec3::new(0.0, 0.0, 1.0),
            target: Some(DVec3::new(0.0, 5.0, 0.0)),
            up: None,
            width: 100,
            height: 100,
            fov_deg: 60.0,
        };
        let r = render_svg(&p, &view).unwrap();
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
        let p = Prepared::new(mesh, "two").unwrap();
        let mut order = Vec::new();
        let vp = p.grid.snap_viewpoint(DVec3::new(10.0, 0.5, 0.5)).unwrap();
        p.tree
            .traverse(vp, Order::BackToFront, |poly| order.push(poly.tag()));
        let near_face = order.iter().position(|&t| t == 9).unwrap(); // x = 4 face of the near cube
        let far_face = order.iter().position(|&t| t == 3).unwrap(); // x = 1 face of the far cube
        assert!(far_face < near_face);
        let view = View {
            eye: DVec3::new(10.0, 0.5, 0.5),
            target: None,
            up: None,
            width: 64,
            height: 48,
            fov_deg: 40.0,
        };
        let r = render_svg(&p, &view).unwrap();
        assert_eq!(r.drawn, 12);
        assert!(r.svg.starts_with("<?xml") && r.svg.ends_with("</svg>\n"));
    }

    #[test]
    fn bad_views_are_errors() {
        let p = Prepared::new(shadow_scene::scene("cube").unwrap(), "cube").unwrap();
        let mut view = View {
            eye: DVec3::splat(0.5),
            target: Some(DVec3::splat(0.5)),
            up: None,
            width: 10,
            height: 10,
            fov_deg: 50.0,
        };
        assert!(render_svg(&p, &view).is_err());
        view.eye = DVec3::splat(1e300);
        let e = render_svg(&p, &view).unwrap_err().to_string();
        assert!(e.contains("too far"), "{e}");
        let empty = Prepared::new(shadow_scene::Mesh::default(), "empty").unwrap();
        view.eye = DVec3::ONE;
        assert!(render_svg(&empty, &view).is_err());
    }
}
