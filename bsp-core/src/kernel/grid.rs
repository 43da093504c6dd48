//! The integer grid that every input coordinate is snapped to.
//!
//! All exact reasoning in this crate happens on integers. An input `f64`
//! coordinate `x` becomes the grid coordinate `round((x - origin) * scale)`,
//! where `scale` is a power of two, and must satisfy `|g| <= MAX_COORD`.
//! See `docs/architecture.md` for why 26 bits is the budget.

use glam::DVec3;

use crate::kernel::error::{InputError, SnapError};

/// Number of bits of an input grid coordinate: `|g| < 2^GRID_BITS`.
pub const GRID_BITS: u32 = 26;

/// Largest absolute value of an input grid coordinate (`2^26 - 1`).
pub const MAX_COORD: i32 = (1 << GRID_BITS) - 1;

/// Largest absolute value of a viewpoint (eye or light) grid coordinate.
///
/// Viewpoints only ever meet planes in a single dot product, which stays
/// below `2^120` for coordinates up to `2^60`, so they may lie far outside
/// the scene's box.
pub const MAX_VIEW_COORD: i64 = 1 << 60;

/// A point with integer grid coordinates, `|c| <= MAX_COORD` on each axis.
pub type GridPoint = [i32; 3];

/// A viewpoint (eye or light position) snapped to the grid; coordinates may
/// reach [`MAX_VIEW_COORD`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ViewPoint(pub(crate) [i64; 3]);

impl ViewPoint {
    /// A viewpoint from grid coordinates, or `None` if one exceeds
    /// [`MAX_VIEW_COORD`].
    ///
    /// ```
    /// use bsp_core::ViewPoint;
    /// assert!(ViewPoint::new([1, 2, 3]).is_some());
    /// assert!(ViewPoint::new([i64::MAX, 0, 0]).is_none());
    /// ```
    pub fn new(c: [i64; 3]) -> Option<ViewPoint> {
        c.iter()
            .all(|v| v.unsigned_abs() <= MAX_VIEW_COORD as u64)
            .then_some(ViewPoint(c))
    }

    /// The grid coordinates.
    pub fn coords(&self) -> [i64; 3] {
        self.0
    }
}

impl From<GridPoint> for ViewPoint {
    fn from(p: GridPoint) -> ViewPoint {
        ViewPoint([p[0] as i64, p[1] as i64, p[2] as i64])
    }
}

/// The mapping between input units and grid coordinates.
///
/// `scale` is a power of two, so the mapping back to input units is a
/// multiplication by an exact power of two followed by one addition.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    origin: DVec3,
    scale: f64,
}

/// How much of the grid's range the fitted box may use: one half, so that a
/// second operand, a light or a moved object near the scene still fits.
const FIT_FRACTION: f64 = 0.5;

impl Grid {
    /// A grid with the given origin and power-of-two `log2_scale`
    /// (grid units per input unit is `2^log2_scale`). The origin is rounded
    /// to the nearest multiple of the grid step, so that it is itself a
    /// grid point and snapping is an exact nearest-point rounding.
    ///
    /// ```
    /// use bsp_core::Grid;
    /// use glam::DVec3;
    /// let g = Grid::new(DVec3::new(0.25, 0.0, 0.0), 0).unwrap();
    /// assert_eq!(g.origin(), DVec3::ZERO);
    /// ```
    pub fn new(origin: DVec3, log2_scale: i32) -> Result<Grid, InputError> {
        if !origin.is_finite() {
            return Err(InputError::InvalidGrid("origin is not finite"));
        }
        if !(-1000..=1000).contains(&log2_scale) {
            return Err(InputError::InvalidGrid("log2_scale outside -1000..=1000"));
        }
        let scale = 2f64.powi(log2_scale);
        let origin = (origin * scale).round() / scale;
        if !origin.is_finite() {
            return Err(InputError::InvalidGrid("origin too large for the scale"));
        }
        Ok(Grid { origin, scale })
    }

    /// The finest grid on which the box `[min, max]` takes at most half of
    /// the coordinate range, with its origin at the box centre (rounded to
    /// the grid).
    ///
    /// ```
    /// use bsp_core::Grid;
    /// use glam::DVec3;
    /// let g = Grid::fit(DVec3::splat(-1.0), DVec3::splat(1.0)).unwrap();
    /// let p = g.snap(DVec3::new(0.5, -1.0, 1.0)).unwrap();
    /// assert_eq!(g.to_world([p[0] as f64, p[1] as f64, p[2] as f64]), DVec3::new(0.5, -1.0, 1.0));
    /// ```
    pub fn fit(min: DVec3, max: DVec3) -> Result<Grid, InputError> {
        if !min.is_finite() || !max.is_finite() {
            return Err(InputError::InvalidGrid("bounding box is not finite"));
        }
        let half = ((max - min) * 0.5).abs().max_element();
        let centre = (min + max) * 0.5;
        let target = MAX_COORD as f64 * FIT_FRACTION;
        let log2 = if half > 0.0 {
            // largest k with half * 2^k <= target
            let mut k = (target / half).log2().floor() as i32;
            if k > 1000 {
                // the finest grid would still give the box only a few
                // steps: snapping would move its points by a good part of
                // its size
                return Err(InputError::InvalidGrid(
                    "bounding box too small (under about 2^-975 units across)",
                ));
            }
            k = k.max(-1000);
            while k > -1000 && half * 2f64.powi(k) > target {
                k -= 1;
            }
            k
        } else {
            0
        };
        let scale = 2f64.powi(log2);
        let origin = (centre * scale).round() / scale;
        if !origin.is_finite() {
            return Err(InputError::InvalidGrid("bounding box too large"));
        }
        Ok(Grid { origin, scale })
    }

    /// The grid that fits the bounding box of `points` (see [`Grid::fit`]).
    pub fn fit_points<'a>(points: impl IntoIterator<Item = &'a DVec3>) -> Result<Grid, InputError> {
        let mut min = DVec3::splat(f64::INFINITY);
        let mut max = DVec3::splat(f64::NEG_INFINITY);
        for p in points {
            if !p.is_finite() {
                return Err(InputError::InvalidGrid("a point is not finite"));
            }
            min = min.min(*p);
            max = max.max(*p);
        }
        if min.x > max.x {
            min = DVec3::ZERO;
            max = DVec3::ZERO;
        }
        Grid::fit(min, max)
    }

    /// Grid units per input unit (a power of two).
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// The input-space position of grid coordinate zero.
    pub fn origin(&self) -> DVec3 {
        self.origin
    }

    /// Size of one grid step in input units.
    pub fn step(&self) -> f64 {
        1.0 / self.scale
    }

    /// The grid step as a power of two: the step is `2^step_log2()` input
    /// units.
    ///
    /// ```
    /// let g = bsp_core::Grid::new(glam::DVec3::ZERO, 23).unwrap();
    /// assert_eq!(g.step_log2(), -23);
    /// assert_eq!(g.step(), 2f64.powi(-23));
    /// ```
    pub fn step_log2(&self) -> i32 {
        -(self.scale.log2() as i32)
    }

    /// The step for people: `2^-7 = 7.812e-3 units`.
    pub fn step_text(&self) -> String {
        format!("2^{} = {:.3e} units", self.step_log2(), self.step())
    }

    fn snap_f64(&self, p: DVec3) -> Result<DVec3, SnapError> {
        if !p.is_finite() {
            return Err(SnapError::NonFinite);
        }
        // `origin * scale` is an integer and `p * scale` is exact (a power of
        // two), so rounding `p * scale` first and subtracting after gives the
        // nearest grid point: `(p - origin) * scale` would round the
        // difference before scaling and could land on the wrong side of a
        // midpoint. The subtraction of two integer-valued doubles is exact
        // here: either both are small, or they are within 2^27 of each other.
        let g = (p * self.scale).round() - self.origin * self.scale;
        if !g.is_finite() {
            return Err(SnapError::OutOfRange);
        }
        Ok(g)
    }

    /// Snaps an input point to the grid.
    pub fn snap(&self, p: DVec3) -> Result<GridPoint, SnapError> {
        let g = self.snap_f64(p)?;
        if g.abs().max_element() > MAX_COORD as f64 {
            return Err(SnapError::OutOfRange);
        }
        Ok([g.x as i32, g.y as i32, g.z as i32])
    }

    /// Snaps a viewpoint (eye or light) to the grid; it may lie outside the
    /// scene's range, up to [`MAX_VIEW_COORD`].
    pub fn snap_viewpoint(&self, p: DVec3) -> Result<ViewPoint, SnapError> {
        let g = self.snap_f64(p)?;
        if g.abs().max_element() > MAX_VIEW_COORD as f64 {
            return Err(SnapError::OutOfRange);
        }
        Ok(ViewPoint([g.x as i64, g.y as i64, g.z as i64]))
    }

    /// Maps grid coordinates (possibly fractional) back to input units.
    pub fn to_world(&self, g: [f64; 3]) -> DVec3 {
        DVec3::from_array(g) / self.scale + self.origin
    }

    /// Maps a viewpoint back to input units.
    pub fn viewpoint_to_world(&self, v: ViewPoint) -> DVec3 {
        self.to_world(v.0.map(|c| c as f64))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_keeps_box_inside_half_range() {
        let g = Grid::fit(DVec3::new(-3.0, 0.0, 1.0), DVec3::new(5.0, 2.0, 1.5)).unwrap();
        for p in [DVec3::new(-3.0, 0.0, 1.0), DVec3::new(5.0, 2.0, 1.5)] {
            let s = g.snap(p).unwrap();
            assert!(s.iter().all(|c| c.abs() <= MAX_COORD / 2 + 1));
        }
        assert_eq!(g.scale().log2().fract(), 0.0);
    }

    #[test]
    fn the_step_reads_as_a_power_of_two() {
        let g = Grid::fit(DVec3::ZERO, DVec3::splat(1000.0)).unwrap();
        let k = g.step_log2();
        assert_eq!(2f64.powi(k), g.step());
        assert_eq!(g.step_text(), format!("2^{k} = {:.3e} units", g.step()));
        let g = Grid::fit(DVec3::ZERO, DVec3::splat(2f64.powi(20))).unwrap();
        assert_eq!(
            g.step_text(),
            format!("2^{} = {:.3e} units", g.step_log2(), g.step())
        );
    }

    #[test]
    fn fit_refuses_a_box_too_small_for_the_finest_grid() {
        let tiny = DVec3::splat(2f64.powi(-1000));
        assert!(matches!(
            Grid::fit(DVec3::ZERO, tiny),
            Err(InputError::InvalidGrid(why)) if why.contains("too small")
        ));
        // a box a little larger still spans 2^24 steps and more (powers of
        // two: the product is exact)
        let small = DVec3::splat(2f64.powi(-960));
        let g = Grid::fit(DVec3::ZERO, small).unwrap();
        assert!(small.x * g.scale() >= 2f64.powi(24), "{}", g.scale());
        // a single point (no extent) is fine
        assert!(Grid::fit(tiny, tiny).is_ok());
    }

    #[test]
    fn snap_rejects_nan_and_far_points() {
        let g = Grid::fit(DVec3::ZERO, DVec3::ONE).unwrap();
        assert_eq!(
            g.snap(DVec3::new(f64::NAN, 0.0, 0.0)),
            Err(SnapError::NonFinite)
        );
        assert_eq!(
            g.snap(DVec3::new(f64::INFINITY, 0.0, 0.0)),
            Err(SnapError::NonFinite)
        );
        assert_eq!(
            g.snap(DVec3::new(1e9, 0.0, 0.0)),
            Err(SnapError::OutOfRange)
        );
        assert!(g.snap_viewpoint(DVec3::new(1e9, 0.0, 0.0)).is_ok());
        assert_eq!(
            g.snap_viewpoint(DVec3::new(1e300, 0.0, 0.0)),
            Err(SnapError::OutOfRange)
        );
    }

    #[test]
    fn degenerate_and_huge_boxes() {
        let g = Grid::fit(DVec3::splat(7.0), DVec3::splat(7.0)).unwrap();
        assert_eq!(g.snap(DVec3::splat(7.0)).unwrap(), [0, 0, 0]);
        let g = Grid::fit(DVec3::splat(-1e300), DVec3::splat(1e300)).unwrap();
        assert!(g.snap(DVec3::splat(1e300)).is_ok());
        // so small a box that even the finest grid (2^1000) would give it
        // eight steps: refused, rather than snapped coarsely
        let tiny = DVec3::splat(2f64.powi(-997));
        assert!(Grid::fit(-tiny, tiny).is_err());
        assert!(Grid::fit(DVec3::splat(f64::NAN), DVec3::ONE).is_err());
    }
}
