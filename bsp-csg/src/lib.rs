//! Exact Boolean operations on closed meshes: local BSP trees in an
//! adaptive octree.
//!
//! A [`Solid`] is the boundary of a closed, outward-oriented polyhedron as
//! plane-based convex polygons on `bsp-core`'s grid, with a spatial index
//! of their boxes made once it pays (by the first operation carried out on
//! the solid, or after a few queries).
//! [`Solid::apply`] computes `self ∘ other` for `∘` ∈ {∪, ∩, −}:
//!
//! 1. Faces outside the other solid's box are outside it: left as they
//!    are (or dropped, for ∩), at no cost.
//! 2. Over the box both solids share, an adaptive octree splits the cells
//!    that hold faces of both until they hold few
//!    (module `octree`: cell walls lie half a grid step off the
//!    grid, so no vertex or face of either solid is ever on one).
//! 3. In each cell that holds faces of both, the faces are clipped to the
//!    cell, each operand's pieces make a small BSP partition whose leaves
//!    are labelled exactly by the faces that cover their common boundaries
//!    (module `local`), and each piece of one operand is sorted
//!    against the other's labelled partition: kept whole, dropped whole, or
//!    cut by the other surface into kept fragments. Where faces of the two
//!    operands share a plane, the cell's two partitions are merged with
//!    `bsp-core`'s set operations instead (coplanar and touching faces
//!    included). Cells run in parallel. A cell where the two surfaces come
//!    near without meeting (each piece strictly on one side of the other
//!    surface's pieces' planes, or they of its) builds nothing: its pieces
//!    take their labels along their faces from the cells around
//!    ([`Options::easy_cells`]). A face apart from every face of the other
//!    surface in every mixed cell listing both meets that surface nowhere:
//!    it is kept or dropped whole by one label, without being clipped, and
//!    a cell holding only such faces does nothing ([`Stats::clean_cells`]).
//! 4. Every other face lies in cells the other surface does not enter: it
//!    is wholly inside or outside the other solid. Those cells form
//!    connected regions of space free of the other surface (adjacent cells
//!    share their label); each region's label is one exact winding number
//!    ([`Solid::winding`]: a ray along `+x` with simulation of simplicity),
//!    and a face keeps or loses its pieces by it.
//! 5. A face none of whose pieces the other surface cuts stays exactly as
//!    it was, however many cells it spans; only cut faces are replaced by
//!    pieces ([`Stats`]). An imported face is kept as its grid corners
//!    ([`bsp_core::internals::GridPolygon`]), and its edge planes are computed only
//!    when a cell clips it: most faces of a large solid never are, and the
//!    edge planes were most of a face's memory.
//!
//! Everything is exact: the planes are `bsp-core`'s input tier (planes of
//! the input faces, their edges, and the octree walls), vertices are
//! intersections of three of them, and the result is again such a solid —
//! the next operation takes it as it is ([`Solid::apply`] works in place
//! and touches only the faces near the other operand, so a sequence of
//! small operations on a large part never rebuilds anything global).
//!
//! From meshes: [`mesh_boolean`] and [`mesh_sequence`] check, snap, operate
//! and mesh in one call; [`snap`] makes every operand's solid on one grid
//! at once, and [`fit_grid`] with [`snap_one`] makes each when its turn
//! comes, so that a long sequence holds only the result and one operand.
//! Where only the mesh of the last result is wanted, [`Solid::plan_owned`]
//! decides the operation and [`Planned::into_watertight_mesh`] meshes the
//! result straight from the two solids' faces, with no solid of its own.
//! [`mesh_sequence_with`] does all of this for operands handed over one at
//! a time (each let go once snapped), and tells its caller each step: the
//! import reports, each operation's [`Stats`], when each [`Stage`] starts
//! (what the CLI does).
//!
//! # Example
//!
//! ```
//! use bsp_core::{BoolOp, Grid, Membership};
//! use bsp_csg::{MeshIn, mesh_boolean};
//! use glam::DVec3;
//!
//! fn cube(lo: f64, hi: f64) -> (Vec<DVec3>, Vec<Vec<u32>>) {
//!     let p = |i: u32| DVec3::new(
//!         if i & 1 == 0 { lo } else { hi },
//!         if i & 2 == 0 { lo } else { hi },
//!         if i & 4 == 0 { lo } else { hi },
//!     );
//!     let faces = vec![vec![0, 2, 3, 1], vec![4, 5, 7, 6], vec![0, 1, 5, 4],
//!                      vec![2, 6, 7, 3], vec![0, 4, 6, 2], vec![1, 3, 7, 5]];
//!     ((0..8).map(p).collect(), faces)
//! }
//! let (pa, fa) = cube(0.0, 2.0);
//! let (pb, fb) = cube(1.0, 3.0);
//! let r = mesh_boolean(&MeshIn::new(&pa, &fa), &MeshIn::new(&pb, &fb), BoolOp::Union).unwrap();
//! // 8 + 8 − 1 cubic units, exactly
//! assert_eq!(r.volume(), 15.0);
//! let inside = r.grid.snap(DVec3::splat(2.5)).unwrap();
//! assert_eq!(r.solid.classify_point(inside), Membership::Inside);
//! ```
//!
//! # Feature flags
//!
//! None.
mod error;
pub mod files;
mod import;
mod index;
mod options;
mod plan;
mod sequence;
mod solid;

pub use error::CsgError;
pub use import::{AsMeshIn, MeshBuf, MeshIn, Snapped, check_mesh, fit_grid, snap, snap_one};
pub use options::{LEAF_SIZE, Options, Stats};
pub use plan::{Planned, RESOLVE_LIMIT};
pub use sequence::{
    Boolean, SequenceError, Stage, Step, mesh_boolean, mesh_sequence, mesh_sequence_with,
};
pub use solid::Solid;

/// The README's example, compiled and run as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
