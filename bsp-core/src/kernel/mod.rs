//! The exact kernel: the integer grid, the `f64` filters and wide
//! integers behind every decision, planes, points and convex polygons.
//! Nothing here knows of trees or solids.

pub(crate) mod convex;
pub(crate) mod error;
pub(crate) mod exact;
pub(crate) mod grid;
mod grid_loop;
pub(crate) mod plane;
pub(crate) mod point;
pub(crate) mod polygon;
mod side;

pub use convex::{ConvexParts, SanityError, check_convex};
pub use error::{InputError, SnapError};
pub use exact::{Homogeneous, approx, filter_ring_area, filter_side, filter_side_err};
pub use grid::{GRID_BITS, Grid, GridPoint, MAX_COORD, MAX_VIEW_COORD, ViewPoint};
pub use plane::{FaceDefect, MAX_NORMAL_BITS, MAX_OFFSET_BITS, Plane};
pub use point::{Implicit, Point, PointRef};
pub use polygon::{
    ConvexFace, GridPolygon, Parts, Polygon, PolygonSide, Split, share_points, split_loop,
};
pub use side::Side;
