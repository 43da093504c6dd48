//! Exact shadows: every face of a scene cut into fragments, each exactly
//! lit or in shadow for every light (point lights and suns).
//!
//! [`LightVolumes`] builds one partitioned shadow-volume tree per light
//! (Gerhards et al. 2015: every occluder's volume, bounded by planes
//! through the light and its edges and capped by its own plane) and
//! filters every face through them. A face is cut only where a shadow
//! boundary crosses it: cuts that do not separate lit from shadowed parts
//! are undone, and the pieces left are merged into maximal regions, so a
//! uniformly lit face is one fragment — its own polygon — and a fragment
//! is a connected part of a face with one set of flags (an outer boundary
//! and possibly holes). All planes stay in the input tier of `bsp-core`
//! (the plane through a grid light and two grid vertices is one), so
//! every decision is the exact sign of a 256-bit value behind an `f64`
//! filter. Faces are independent and shaded in parallel (rayon); the
//! output does not depend on the thread count.
//!
//! [`chin_feiner()`] is Chin & Feiner's (1989) BSP-ordered algorithm, on
//! which the core paper's dynamic pipeline builds; its shadow planes pass
//! through split edges and need a wider tier (see `docs/architecture.md`).
//! The two agree exactly on every face's lit area (tested).
//!
//! # Example
//!
//! ```
//! use bsp_core::Polygon;
//! use svbsp::{shadow_fragments, Light};
//!
//! let floor = Polygon::from_grid_points(&[[0, 0, 0], [8, 0, 0], [8, 8, 0], [0, 8, 0]], 0).unwrap();
//! let roof = Polygon::from_grid_points(&[[2, 2, 4], [4, 2, 4], [4, 4, 4], [2, 4, 4]], 1).unwrap();
//! let (fragments, _stats) = shadow_fragments(&[floor, roof], &[Light::Point([3, 3, 8])]).unwrap();
//! // the floor: a lit square ring around one shadowed square; the roof: lit
//! let floor: Vec<_> = fragments.fragments().filter(|f| f.face() == 0).collect();
//! assert_eq!(floor.len(), 2);
//! assert_eq!(floor.iter().find(|f| f.lit(0)).unwrap().hole_count(), 1);
//! assert_eq!(fragments.len(), 3);
//! ```
//!
//! # Feature flags
//!
//! None.

mod area;
mod areas;
mod arena;
mod backs;
mod blockers;
mod boxes;
mod chin_feiner;
mod cones;
mod cores;
mod engine;
pub mod export;
mod light;
mod merging;
mod near;
mod overlay;
mod psv;
mod schedule;
mod sealed;
mod soft;
mod wide;

pub use area::{
    AreaClass, AreaFragment, AreaLight, DISC_SIDES, LightView, Occluder, Visibility, form_factor,
};
pub use areas::{Areas, fragment_area, percent, polygon_area};
pub use arena::pieces::Vertex;
pub use chin_feiner::{CfFragment, CfFragments, chin_feiner};
pub use engine::{
    Batch, CHUNK, Cells, FragmentRef, LightVolumes, Refined, Scratch, ShadeOptions, ShadowError,
    ShadowSet, ShadowStats, Start, receivers, shadow_fragments,
};
pub use light::{
    AreaLightError, LIGHT_RANGE_BITS, Light, LightError, LightSpec, MAX_DISC_RADIUS,
    MAX_DISC_RADIUS_DEG, MAX_LIGHTS, PlacedLight, SUN_RADIUS_DEG, SoftSpec, angle_between,
    input_number, input_triple, place_lights, quantize_direction, shared_grid,
};
pub use overlay::{FaceOverlay, OverlayRegion};
pub use psv::{LitParts, ShadowVolumes, VolumeError, VolumeSanity};
pub use soft::{
    Share, SoftFragment, SoftLight, SoftPiece, SoftShape, SoftVolumes, place_soft_lights,
    shared_soft_grid, soft_regions_with, soft_shadows, soft_shadows_with,
};
pub use wide::{WPoint, WidePlane};

/// The README's example, compiled and run as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
