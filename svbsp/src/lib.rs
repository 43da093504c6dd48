//! Exact shadows with shadow-volume BSP trees (Chin & Feiner 1989).
//!
//! Given a scene's BSP tree ([`bsp_core::BspTree`]) and lights on the same
//! grid, [`shadow_fragments`] cuts every polygon into convex fragments, each
//! exactly lit or in shadow for every light. Every decision is the exact sign
//! of the true value: shadow planes (through a light and a fragment edge)
//! have their own exact tier, 140-bit normals and 168-bit offsets, and their
//! intersections with scene polygons are classified in 512-bit integers
//! behind an `f64` filter (see `docs/architecture.md`, "The shadow tier").
//!
//! # Example
//!
//! ```
//! use bsp_core::{BspTree, BuildOptions, Polygon};
//! use svbsp::{shadow_fragments, Light};
//!
//! let floor = Polygon::from_grid_points(&[[0, 0, 0], [8, 0, 0], [8, 8, 0], [0, 8, 0]], 0).unwrap();
//! let roof = Polygon::from_grid_points(&[[2, 2, 4], [4, 2, 4], [4, 4, 4], [2, 4, 4]], 1).unwrap();
//! let tree = BspTree::build(vec![floor, roof], &BuildOptions::default());
//! let (fragments, _stats) = shadow_fragments(&tree, &[Light::Point([3, 3, 8])]).unwrap();
//! let shadowed = fragments.iter().filter(|f| f.face() == 0 && !f.lit()[0]).count();
//! assert_eq!(shadowed, 1);
//! ```
//!
//! # Feature flags
//!
//! None.

mod fragment;
mod shadows;
mod wide;

pub use fragment::{Edge, Fragment};
pub use shadows::{Light, LightError, ShadowStats, shadow_fragments};
pub use wide::{WPoint, WidePlane};
