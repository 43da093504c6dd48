//! Exact plane-based geometry and BSP trees.
//!
//! Input coordinates (`f64`) are snapped to an integer [`Grid`] of
//! 26-bit coordinates. Planes have integer coefficients ([`Plane`]); convex
//! polygons are a support plane plus edge planes ([`Polygon`]); vertices are
//! exact [`Point`]s, either grid points or intersections of three planes.
//! Every geometric decision — which side of a plane a point lies on, whether
//! a polygon spans a plane — is the exact sign of the true value: a
//! floating-point filter answers the easy cases and fixed-width integer
//! arithmetic (128 and 256 bits) the rest. There is no tolerance anywhere.
//!
//! On top of the kernel, [`BspTree`] builds autopartitions (explicit
//! stacks, no recursion limit), traverses them in painter's order,
//! answers exact point membership for solids, and has a flattened
//! array layout ([`FlatBsp`]) for fast traversal.
//!
//! # Example
//!
//! ```
//! use bsp_core::{import_faces, BspTree, BuildOptions, Grid, Membership, Point};
//! use glam::DVec3;
//!
//! // a tetrahedron, counter-clockwise faces seen from outside
//! let v = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
//! let faces = [[v[0], v[2], v[1]], [v[0], v[1], v[3]], [v[0], v[3], v[2]], [v[1], v[2], v[3]]];
//! let grid = Grid::fit_points(&v).unwrap();
//! let (polys, _report) = import_faces(&grid, faces.iter().map(|f| &f[..])).unwrap();
//! let tree = BspTree::build(polys, &BuildOptions::default());
//! tree.sanity_check().unwrap();
//! let inside = grid.snap(DVec3::splat(0.1)).unwrap();
//! assert_eq!(tree.classify_point(&Point::Grid(inside)), Membership::Inside);
//! ```
//!
//! # Feature flags
//!
//! None.

mod embedded;
mod exact;
mod flat;
mod grid;
mod import;
mod mesh;
mod partition;
mod plane;
mod point;
mod polygon;
mod sanity;
mod topology;
mod tree;

pub use embedded::{SolidBoundary, SurfaceDefect, certify_solid_boundary};
pub use exact::{
    FILTER_REL, Homogeneous, approx, filter_ring_area, filter_side, filter_side_err,
    ratio_to_f64_exact,
};
pub use flat::FlatBsp;
pub use grid::{GRID_BITS, Grid, GridPoint, MAX_COORD, MAX_VIEW_COORD, SnapError, ViewPoint};
pub use import::{
    FaceImporter, ImportReport, all_planar, import_faces, import_faces_par, import_indexed_par,
    snap_positions,
};
pub use mesh::TriMesh;
pub use partition::{
    BOX_HALF, BoolOp, CellOp, Overlay, PLink, PNode, Partition, box_section, merge,
    merge_smaller_into_larger, solid_build_options,
};
pub use plane::{MAX_NORMAL_BITS, MAX_OFFSET_BITS, Plane};
pub use point::{Implicit, Point, PointRef, rational_to_f64};
pub use polygon::{
    ConvexFace, FaceDefect, GridPolygon, Parts, Polygon, PolygonSide, Side, Split, share_points,
    split_loop,
};
pub use sanity::{ConvexParts, SanityError, check_convex};
pub use topology::{TopologyError, check_closed_manifold};
pub use tree::{
    BspTree, BuildOptions, Cell, Link, Membership, Node, NodeId, Order, RECURSION_LIMIT, SplitMix,
    TreeStats,
};

/// Re-export of the wide integer type used for homogeneous coordinates.
pub use bnum::types::{I256, I512};

/// Errors of this crate.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Error {
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

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Error::Snap {
                face,
                vertex,
                value,
                reason,
            } => write!(f, "face {face}, vertex {vertex} {value:?}: {reason}"),
            Error::InvalidGrid(why) => write!(f, "invalid grid: {why}"),
            Error::VertexIndex {
                face,
                vertex,
                index,
            } => write!(f, "face {face}, vertex {vertex}: no vertex {index}"),
        }
    }
}

impl std::error::Error for Error {}

/// One step of the xorshift generator (13, 7, 17) the tests draw their
/// cases from: the new state, which is also the number drawn.
#[cfg(test)]
pub(crate) fn xorshift(state: &mut u64) -> u64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    *state
}
