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
//! array layout ([`FlatBsp`]) for fast traversal. [`merge`] combines two
//! partitions cell by cell: the set operations of solids ([`BoolOp`]) and
//! the overlay "+" ([`Overlay`]). For meshes, [`import_faces`] snaps faces
//! to polygons, [`TriMesh`] turns a solid's boundary back into a
//! watertight mesh, and [`certify_solid_boundary`] proves that polygons
//! bound solids.
//!
//! The layers, each in its folder: `kernel` (grid, exact arithmetic,
//! planes, points, polygons), `tree` (building, traversal, merging) and
//! `solid` (import, meshes, topology and embedding checks). The crate
//! root re-exports what a user needs; [`internals`] holds what the sibling
//! crates of this workspace use besides, and [`par`] the parallel loops
//! they share (rayon's scheduling compiled once, results in index order).
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

mod kernel;
pub mod par;
mod solid;
mod tree;
mod union_find;

pub use kernel::{
    FaceDefect, GRID_BITS, Grid, GridPoint, Implicit, InputError, MAX_COORD, MAX_VIEW_COORD, Plane,
    Point, Polygon, PolygonSide, SanityError, Side, SnapError, Split, ViewPoint,
};
pub use solid::{
    ImportReport, PairedParts, SolidBoundary, SolidParts, SurfaceDefect, TopologyError, TriMesh,
    certify_solid_boundary, certify_solid_parts, check_closed_manifold, import_faces,
    import_faces_par, import_indexed_par, import_mesh_par, is_closed_cycle, meeting_pairs,
    pair_solid_parts,
};
pub use tree::{
    BoolOp, BspTree, BuildOptions, Cell, CellOp, FlatBsp, Link, Membership, Node, NodeId, Order,
    Overlay, Partition, RECURSION_LIMIT, TreeStats, merge,
};

/// The 256-bit integer of implicit points' homogeneous coordinates.
pub use bnum::types::I256;

/// What the sibling crates of this workspace (`svbsp`, `bsp-csg`,
/// `tiling`, the test kit) use of the kernel besides the crate root: the
/// `f64` filters, wide integers, convex-polygon plumbing and the building
/// blocks of merging. Everything here is exact and tested, but shaped for
/// those crates' inner loops; it may change with them, without notice.
pub mod internals {
    pub use crate::kernel::plane::gcd128;
    pub use crate::kernel::{
        ConvexFace, ConvexParts, GridPolygon, Homogeneous, MAX_NORMAL_BITS, MAX_OFFSET_BITS, Parts,
        PointRef, approx, check_convex, filter_ring_area, filter_side, filter_side_err,
        share_points, split_loop,
    };
    pub use crate::solid::{
        FaceImporter, all_planar, certify_grid_polygons, snap_positions, triangles_disjoint,
    };
    pub use crate::tree::{PLink, PNode, SplitMix, box_section, merge_smaller_into_larger};
    pub use crate::union_find::UnionFind;
    pub use bnum::types::I512;
}

/// One step of the xorshift generator (13, 7, 17) the tests draw their
/// cases from: the new state, which is also the number drawn.
#[cfg(test)]
pub(crate) fn xorshift(state: &mut u64) -> u64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    *state
}

/// The README's example, compiled and run as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
