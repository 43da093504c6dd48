//! The crate's error type.

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
    /// A camera or light parameter is unusable (not finite, zero, out of
    /// range); the message names it.
    Camera(String),
    /// The scene has nothing to draw.
    EmptyScene,
    /// An option is out of range; the message names it.
    Option(String),
    /// The exact shadows could not be computed.
    Shadows(String),
    /// Roberts' algorithm needs closed polyhedra; the message names the
    /// part that is not one.
    NotConvex(String),
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
            RasterError::Camera(m) | RasterError::Option(m) => f.write_str(m),
            RasterError::EmptyScene => f.write_str("nothing to draw: the scene has no faces"),
            RasterError::Shadows(m) => write!(f, "exact shadows: {m}"),
            RasterError::NotConvex(m) => f.write_str(m),
            RasterError::Io { path, message } => write!(f, "{path}: {message}"),
        }
    }
}

impl std::error::Error for RasterError {}
