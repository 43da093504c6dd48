//! The crate's error: input that cannot become geometry.

/// Errors of this crate.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum InputError {
    /// An input coordinate could not be snapped to the grid.
    Snap {
        /// Index of the face.
        face: usize,
        /// Index of the vertex within the face.
        vertex: usize,
        /// The offending coordinates.
        value: [f64; 3],
        /// Why.
        reason: SnapError,
    },
    /// Grid parameters are unusable.
    InvalidGrid(&'static str),
    /// A face names a vertex the mesh does not have.
    VertexIndex {
        /// Index of the face.
        face: usize,
        /// Position of the index within the face.
        vertex: usize,
        /// The index.
        index: u32,
    },
}

impl std::fmt::Display for InputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            InputError::Snap {
                face,
                vertex,
                value,
                reason,
            } => write!(f, "face {face}, vertex {vertex} {value:?}: {reason}"),
            InputError::InvalidGrid(why) => write!(f, "invalid grid: {why}"),
            InputError::VertexIndex {
                face,
                vertex,
                index,
            } => write!(f, "face {face}, vertex {vertex}: no vertex {index}"),
        }
    }
}

impl std::error::Error for InputError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            InputError::Snap { reason, .. } => Some(reason),
            _ => None,
        }
    }
}

/// Why a single coordinate could not be snapped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SnapError {
    /// NaN or infinite.
    NonFinite,
    /// Outside the grid's range.
    OutOfRange,
}

impl std::fmt::Display for SnapError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SnapError::NonFinite => f.write_str("coordinate is NaN or infinite"),
            SnapError::OutOfRange => f.write_str("coordinate is outside the grid's range"),
        }
    }
}

impl std::error::Error for SnapError {}
