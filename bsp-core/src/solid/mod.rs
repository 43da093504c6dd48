//! Solids given by their boundary: faces snapped to polygons, the
//! boundary back to a watertight triangle mesh, and the exact checks that
//! a surface is closed, oriented and embedded.

pub(crate) mod embedded;
mod flat_regions;
pub(crate) mod import;
mod loops;
pub(crate) mod mesh;
pub(crate) mod topology;

pub use embedded::{
    PairedParts, SolidBoundary, SolidParts, SurfaceDefect, certify_grid_polygons,
    certify_solid_boundary, certify_solid_parts, meeting_pairs, pair_solid_parts,
    triangles_disjoint,
};
pub use import::{
    FaceImporter, ImportReport, all_planar, import_faces, import_faces_par, import_indexed_par,
    import_mesh_par, snap_positions,
};
pub use mesh::TriMesh;
pub use topology::{TopologyError, check_closed_manifold, is_closed_cycle};
