//! The crate's error type.

use bsp_core::SnapError;
use svbsp::ShadowError;

use crate::CameraError;

/// Why an image cannot be rendered.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum RasterError {
    /// The image size is zero, larger than [`crate::MAX_SIZE`] on a side
    /// or than [`crate::MAX_PIXELS`] in all.
    Size {
        /// Width asked for.
        width: u32,
        /// Height asked for.
        height: u32,
    },
    /// The camera cannot be set up.
    Camera(CameraError),
    /// A vertex of the scene is not finite in input units.
    NonFiniteVertex,
    /// The scene has nothing to draw.
    EmptyScene,
    /// The eye cannot be snapped to the scene's grid: it is too far from
    /// the scene.
    EyeOffGrid {
        /// The eye, in input units.
        eye: glam::DVec3,
        /// Why it cannot be snapped.
        cause: SnapError,
    },
    /// A fragment to draw names a polygon the tree does not have.
    FragmentPolygon {
        /// The fragment's index.
        fragment: usize,
        /// The polygon it names.
        polygon: usize,
    },
    /// An option is out of range; the message names it.
    Option(String),
    /// The exact shadows could not be computed.
    Shadows(ShadowError),
    /// Roberts' algorithm needs closed polyhedra; the message names the
    /// part that is not one.
    NotConvex(String),
    /// Roberts' algorithm needs the scene in front of the eye; the
    /// message names the part that reaches behind it.
    BehindEye(String),
    /// Writing a file failed.
    Io {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
}

impl std::fmt::Display for RasterError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RasterError::Size { width, height } => write!(
                f,
                "image size {width}x{height}: each side must be between 1 and {} pixels, and the \
                 image at most {} pixels",
                crate::MAX_SIZE,
                crate::MAX_PIXELS
            ),
            RasterError::Camera(e) => e.fmt(f),
            RasterError::NonFiniteVertex => f.write_str("a vertex is not finite in input units"),
            RasterError::Option(m) => f.write_str(m),
            RasterError::EmptyScene => f.write_str("nothing to draw: the scene has no faces"),
            RasterError::EyeOffGrid { eye, cause } => write!(
                f,
                "eye {},{},{}: {cause} (too far from the scene)",
                eye.x, eye.y, eye.z
            ),
            RasterError::FragmentPolygon { fragment, polygon } => write!(
                f,
                "internal error: fragment {fragment} names BSP polygon {polygon}"
            ),
            RasterError::Shadows(e) => write!(f, "exact shadows: {e}"),
            RasterError::NotConvex(m) | RasterError::BehindEye(m) => f.write_str(m),
            RasterError::Io { path, message } => write!(f, "{path}: {message}"),
        }
    }
}

impl std::error::Error for RasterError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            RasterError::Camera(e) => Some(e),
            RasterError::Shadows(e) => Some(e),
            RasterError::EyeOffGrid { cause, .. } => Some(cause),
            _ => None,
        }
    }
}

/// A name that [`Method`](crate::Method) or [`Hsr`](crate::Hsr) does not
/// know (their `FromStr`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnknownName {
    /// What was named: "method" or "visibility method".
    pub what: &'static str,
    /// The name given.
    pub name: String,
    /// The names there are, joined by ", ".
    pub available: String,
}

impl std::fmt::Display for UnknownName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let UnknownName {
            what,
            name,
            available,
        } = self;
        write!(f, "unknown {what} `{name}` (available: {available})")
    }
}

impl std::error::Error for UnknownName {}
