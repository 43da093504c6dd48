//! The crate's error: why an operation cannot be done.

use bsp_core::TopologyError;

/// Why an operation cannot be done.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum CsgError {
    /// Operand `operand` (0 for the first) is not a closed, consistently
    /// oriented 2-manifold.
    Topology {
        /// The operand.
        operand: usize,
        /// What is wrong, with face and edge.
        error: TopologyError,
    },
    /// Operand `operand`'s faces face inward: the solid they bound is
    /// unbounded.
    Inward {
        /// The operand.
        operand: usize,
    },
    /// A coordinate does not fit the grid (or is not finite).
    Grid(bsp_core::InputError),
    /// A surface is closed and oriented as a mesh, but its winding
    /// numbers disagree within a cell (it crosses itself after snapping).
    /// [`Solid::plan_owned`](crate::Solid::plan_owned) meets it by
    /// resolving the solids ([`Solid::resolved`](crate::Solid::resolved));
    /// from there, it means the winding numbers disagree around a loop of
    /// the partition (the surface is not closed after all).
    NotASolid,
    /// A solid made by operations (its corners off the grid) of `faces`
    /// faces is too large for [`Solid::resolved`](crate::Solid::resolved),
    /// which resolves such a solid by one partition of all its faces (at
    /// most [`RESOLVE_LIMIT`](crate::RESOLVE_LIMIT)).
    TooLargeToResolve {
        /// The surface's faces.
        faces: usize,
    },
    /// Every face of operand `operand` has no area on the grid the
    /// operands share (fitted to all of them together): the solid is
    /// smaller than a step, and would be taken for the empty set.
    Collapsed {
        /// The operand.
        operand: usize,
        /// Its faces.
        faces: usize,
        /// The grid's step is `2^step_log2` input units.
        step_log2: i32,
    },
    /// The result is not watertight: a bug, not a problem of the input.
    Internal(String),
}

impl std::fmt::Display for CsgError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CsgError::Topology { operand, error } => write!(f, "operand {operand}: {error}"),
            CsgError::Inward { operand } => write!(
                f,
                "operand {operand}: the faces are oriented inward (clockwise seen from outside): \
                 the solid they bound is unbounded; reverse every face's vertex order"
            ),
            CsgError::Grid(e) => write!(f, "{e}"),
            CsgError::NotASolid => f.write_str(
                "a surface crosses itself (after snapping to the grid) and bounds no solid",
            ),
            CsgError::TooLargeToResolve { faces } => write!(
                f,
                "a result of {faces} faces made by the operations so far is too large to resolve \
                 where it crosses, overlaps or nests in itself (one partition of every face, \
                 done for at most {} faces)",
                crate::RESOLVE_LIMIT
            ),
            CsgError::Collapsed {
                operand,
                faces,
                step_log2,
            } => write!(
                f,
                "operand {operand}: {}",
                collapsed_text(*faces, *step_log2)
            ),
            CsgError::Internal(e) => write!(f, "internal error: {e}"),
        }
    }
}

impl std::error::Error for CsgError {}

/// Why a collapsed operand ([`CsgError::Collapsed`]) cannot be used.
pub(crate) fn collapsed_text(faces: usize, step_log2: i32) -> String {
    format!(
        "all {faces} faces have no area on the grid the operands share (step 2^{step_log2} \
         units, fitted to all of them together): the solid is smaller than a step, and would be \
         taken for nothing; operate on operands closer in size and place"
    )
}
