//! Shadow art (Mitra & Pauly, SIGGRAPH Asia 2009): the shadow hull of
//! several images, exactly.
//!
//! Each view pairs a binary image (the pixels darker than a threshold are
//! wanted shadow) with a light (a point, or a sun) and a receiving plane
//! (`origin + a·u + b·v`: pixel `(c, r)` covers `a ∈ [c, c+1]`,
//! `b ∈ [r, r+1]`). Its cone is the solid of the points between the light
//! and the plane whose projection from the light falls in the wanted
//! region; the hull is the intersection of every view's cone and the
//! `bounds` box, made by `bsp-csg`'s exact Booleans ([`shadow_hull`]).
//! Its shadows are then cast on each view's plane by `svbsp`'s exact
//! engine and measured against the wanted region ([`ShadowHull::check`]):
//! the hull lies in every cone, so it casts no shadow outside a wanted
//! region; where the images disagree it casts less than they want.
//!
//! The wanted region of an image is exact: the union of its pixel squares,
//! as the boundary loops of each 4-connected component (pixels that touch
//! only at a corner are apart), triangulated over their corners with exact
//! integer predicates and checked to tile the region (`region`).

mod check;
pub(crate) mod cone;
mod deform;
mod grow;
mod region;
mod simplify;
mod spec;

use std::path::PathBuf;

use bsp_core::BoolOp;
use bsp_csg::files::{FileBoolean, FileError, Operand};
use glam::DVec3;

pub use check::{ViewCheck, axis_silhouettes, shadow_coverage};
pub use deform::Deformation;
pub use grow::{ArtRun, Deformed, Grown, Growth, Optimize, optimize, optimize_with, run};
pub use region::Mask;
pub use spec::read_mask;

/// A view's light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ArtLight {
    /// A sun: the direction from the scene toward it.
    Sun(DVec3),
    /// A point light at this position.
    Point(DVec3),
}

/// A view's receiving plane: pixel `(c, r)` covers
/// `origin + [c, c+1]·u + [r, r+1]·v`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewPlane {
    /// Where pixel `(0, 0)`'s corner lies.
    pub origin: DVec3,
    /// One pixel along a row.
    pub u: DVec3,
    /// One pixel down a column.
    pub v: DVec3,
}

impl ViewPlane {
    /// The point of pixel coordinates `(a, b)`.
    pub fn at(&self, a: f64, b: f64) -> DVec3 {
        self.origin + self.u * a + self.v * b
    }

    /// `u × v`: the plane's normal, its length a pixel's area.
    pub fn normal(&self) -> DVec3 {
        self.u.cross(self.v)
    }

    /// The pixel coordinates `(a, b)` of a point of the plane.
    pub fn coords(&self, p: DVec3) -> (f64, f64) {
        let n = self.normal();
        let d = p - self.origin;
        let a = d.dot(self.v.cross(n)) / self.u.dot(self.v.cross(n));
        let b = d.dot(n.cross(self.u)) / self.v.dot(n.cross(self.u));
        (a, b)
    }
}

/// One view: an image's mask, its light and its plane.
#[derive(Clone, Debug)]
pub struct ArtView {
    /// The image file.
    pub image: PathBuf,
    /// The light.
    pub light: ArtLight,
    /// The receiving plane.
    pub plane: ViewPlane,
    /// The wanted shadow.
    pub mask: Mask,
}

/// A shadow-art job: the views, and the box every cone is clipped to.
#[derive(Clone, Debug)]
pub struct ArtSpec {
    /// The views, in order.
    pub views: Vec<ArtView>,
    /// The box's least and greatest corners.
    pub bounds: [DVec3; 2],
    /// Simplify each image's wanted region within this many pixels
    /// (`shadow art --simplify PX`): fewer corners and a smaller hull,
    /// the region kept in shape but no longer the pixels' (see
    /// `docs/shadow-art.md`). `None`: the pixels as they are.
    pub simplify: Option<f64>,
}

/// Why a shadow-art job failed; each names the view (from 0) or file.
#[derive(Debug)]
#[non_exhaustive]
pub enum ArtError {
    /// The SPEC is not what it should be; the message says where.
    Spec(String),
    /// A file could not be read.
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        cause: std::io::Error,
    },
    /// An image could not be decoded.
    Image {
        /// The file.
        path: PathBuf,
        /// Why.
        message: String,
    },
    /// A view cannot make a cone; the message says why.
    View {
        /// The view.
        view: usize,
        /// Why.
        message: String,
    },
    /// The cones have no point in common inside the bounds.
    Empty,
    /// The Booleans refused the cones (a bug: they are closed).
    Boolean(FileError),
    /// The hull's shadows could not be computed.
    Shadows(crate::Error),
}

impl ArtError {
    /// A spec error placed in view `i`.
    fn in_view(self, i: usize) -> ArtError {
        match self {
            ArtError::Spec(m) => ArtError::Spec(format!("view {i}: {m}")),
            e => e,
        }
    }
}

impl std::fmt::Display for ArtError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ArtError::Spec(m) => f.write_str(m),
            ArtError::Read { path, cause } => write!(f, "{}: {cause}", path.display()),
            ArtError::Image { path, message } => write!(f, "{}: {message}", path.display()),
            ArtError::View { view, message } => write!(f, "view {view}: {message}"),
            ArtError::Empty => write!(
                f,
                "the hull is empty: the views' cones have no point in common inside the bounds"
            ),
            ArtError::Boolean(e) => write!(f, "the cones' intersection: {e}"),
            ArtError::Shadows(e) => write!(f, "the hull's shadows: {e}"),
        }
    }
}

impl std::error::Error for ArtError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ArtError::Read { cause, .. } => Some(cause),
            ArtError::Boolean(e) => Some(e),
            ArtError::Shadows(e) => Some(e),
            _ => None,
        }
    }
}

/// The exact shadow hull of a spec's views.
#[derive(Debug)]
pub struct ShadowHull {
    /// The intersection of the cones and the bounds (exact, with its
    /// vertices in input units).
    pub hull: FileBoolean,
    /// Each view's cone: its triangles.
    pub cone_triangles: Vec<usize>,
}

/// The intersection of every view's cone with the `bounds` box: a closed,
/// oriented, watertight mesh, exactly ([`ArtError::Empty`] when it has no
/// volume).
pub fn shadow_hull(spec: &ArtSpec) -> Result<ShadowHull, ArtError> {
    // (NaN is not above 0 either)
    if let Some(px) = spec.simplify
        && px.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
    {
        return Err(ArtError::Spec(format!(
            "simplify within {px} pixels: the tolerance must be a positive number"
        )));
    }
    let mut operands = vec![Operand::new("bounds", cone::cuboid(spec.bounds))];
    let mut cone_triangles = Vec::new();
    for (i, v) in spec.views.iter().enumerate() {
        let mesh = cone::cone(v, spec.bounds, spec.simplify)
            .map_err(|message| ArtError::View { view: i, message })?;
        cone_triangles.push(mesh.faces.len());
        operands.push(Operand::new(format!("cone {i}"), mesh));
    }
    let checked = Operand::check_all(&mut operands).map_err(ArtError::Boolean)?;
    let hull =
        FileBoolean::apply(checked, BoolOp::Intersection, |_, _| {}).map_err(ArtError::Boolean)?;
    if hull.exact.triangles.is_empty() {
        return Err(ArtError::Empty);
    }
    Ok(ShadowHull {
        hull,
        cone_triangles,
    })
}

impl ShadowHull {
    /// The hull as a file holds it (rounded to `f64`, or for `stl` to
    /// `f32`, welded where rounding would pinch it; see
    /// [`FileBoolean::rounded`]).
    pub fn mesh(&self, stl: bool) -> shadow_scene::Mesh {
        match self.hull.rounded(stl) {
            Some(r) => r.mesh,
            None => self.hull.mesh().to_mesh(),
        }
    }
}

impl ArtRun {
    /// The report as JSON: per view (in the spec's order) its areas
    /// ([`ViewCheck`]) and, after [`optimize`], how its image grew
    /// ([`Growth`]) and what it missed before, and with deforming how far
    /// its image moved ([`Deformation`]); the hull's exact volume
    /// and its triangles.
    pub fn report_json(&self) -> String {
        let grown = self
            .grown
            .as_ref()
            .map(|g| (&g.growth[..], &g.missing_before[..]));
        let views: Vec<serde_json::Value> = self
            .checks
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let mut v = serde_json::json!({
                    "wanted_area": c.wanted_area,
                    "shadow_area": c.shadow_area,
                    "missing_area": c.missing_area,
                    "extra_area": c.extra_area,
                });
                if let Some((growth, before)) = grown {
                    let g = &growth[i];
                    v["missing_area_before"] = before[i].into();
                    v["pixels_added"] = g.pixels.into();
                    v["max_displacement_px"] = g.max_displacement.into();
                    v["mean_displacement_px"] = g.mean_displacement.into();
                }
                if let Some(d) = self.grown.as_ref().and_then(|g| g.deformed.as_ref()) {
                    v["max_deformation_px"] = d.views[i].max_displacement.into();
                    v["mean_deformation_px"] = d.views[i].mean_displacement.into();
                }
                v
            })
            .collect();
        let report = serde_json::json!({
            "views": views,
            "hull": {
                "volume": self.hull.hull.volume(),
                "triangles": self.hull.hull.exact.triangles.len(),
            },
        });
        format!("{report:#}\n")
    }
}
