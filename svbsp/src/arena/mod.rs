//! The cell arena of the shadow computations: the pieces of a face in the
//! cells of a shadow-volume tree, with shared lazily computed vertices
//! ([`pieces`]), and their merge back into maximal regions of one set of
//! lit flags ([`regions`]).

pub(crate) mod pieces;
pub(crate) mod regions;
