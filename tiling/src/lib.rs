//! The light-cube tiling of Liu & Wu, and the real-time pipeline it drives:
//! exact shadows of a moving object in a static scene, frame by frame.
//!
//! [`TileIndex`] projects every static polygon from a light onto the six
//! faces of a cube around it (for a sun, onto a plane across its
//! direction), divided into `n × n` tiles, and lists per tile the polygons
//! that meet it, in compressed sparse rows. A moving object's bounding box
//! projected the same way gives, through the tiles it meets, the static
//! polygons that may shadow the object or be shadowed by it. The
//! projection is exact integer arithmetic (no division), and a projection
//! that touches a tile counts for it, so the query never misses a polygon
//! whose projection meets the box's.
//!
//! # Example
//!
//! ```
//! use bsp_core::Polygon;
//! use svbsp::Light;
//! use tiling::{Query, TileIndex};
//!
//! // a floor, a light above its middle and a small roof off to one side
//! let floor = Polygon::from_grid_points(&[[0, 0, 0], [64, 0, 0], [64, 64, 0], [0, 64, 0]], 0).unwrap();
//! let roof = Polygon::from_grid_points(&[[20, 20, 24], [28, 20, 24], [28, 28, 24], [20, 28, 24]], 1).unwrap();
//! let light = Light::Point([32, 32, 48]);
//! let index = TileIndex::build(&light, &[floor, roof], Some(16)).unwrap();
//! // a box right under the light: only the floor is related to it
//! let mut q = Query::default();
//! assert_eq!(index.query_box([28, 28, 4], [36, 36, 12], &mut q), &[0]);
//! // a box in the roof's shadow: the roof may shadow it
//! assert_eq!(index.query_box([14, 14, 4], [18, 18, 8], &mut q), &[0, 1]);
//! ```
//!
//! # Feature flags
//!
//! None.

mod cube;
mod index;
mod ortho;
mod pipeline;

pub use index::{
    MAX_CUBE_TILES, MAX_PLANE_TILES, Query, TileIndex, TilingError, TilingStats, tiles_for,
};
pub use pipeline::{
    Dynamic, FragmentView, Frame, FrameStats, FrameTally, Motion, PipelineError, PipelineOptions,
    PrepStats, Strategy,
};

/// The README's example, compiled and run as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
