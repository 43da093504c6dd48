//! Lights on the scene's grid: exact point lights and suns, and how lights
//! given in input units are placed on the grid.

use bsp_core::{FaceDefect, Grid, GridPoint, MAX_COORD, Plane, Side};
use glam::DVec3;

/// A light source, on the scene's grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Light {
    /// A point light at grid coordinates (each `|c| <= MAX_COORD`).
    Point([i32; 3]),
    /// A light at infinity ("sun"): an integer direction from the scene
    /// toward the light, non-zero, each `|c| <= MAX_COORD`.
    Directional([i32; 3]),
}

/// Most lights one computation takes: the lit flags of a fragment are the
/// bits of a `u64`.
pub const MAX_LIGHTS: usize = 64;

/// Why a light is unusable.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum LightError {
    /// A coordinate exceeds the grid.
    OutOfGrid,
    /// A directional light with a zero direction.
    ZeroDirection,
    /// More than [`MAX_LIGHTS`] lights.
    TooMany(usize),
    /// Placing lights given in input units: point light `index` lies
    /// outside the grid shared with the scene.
    FarPoint {
        /// The light's number (all point lights first, then the suns, in
        /// the order given).
        index: usize,
        /// How far from `centre` along each axis a point light may lie,
        /// in input units.
        reach: f64,
        /// The grid's origin, in input units.
        centre: DVec3,
    },
    /// Placing lights given in input units: a coordinate of light `index`
    /// (a position, a direction or an area light's corner) is NaN or
    /// infinite.
    NotFinite {
        /// The light's number.
        index: usize,
    },
    /// Placing lights given in input units: sun `index` has no direction.
    ZeroSun {
        /// The light's number.
        index: usize,
    },
    /// No grid fits the scene and its lights.
    Grid(bsp_core::InputError),
    /// Placing lights given in input units: light `index`, an area light
    /// or a sun disc, is no light once on the grid.
    Extent {
        /// The light's number.
        index: usize,
        /// Why.
        cause: AreaLightError,
    },
}

impl std::fmt::Display for LightError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LightError::OutOfGrid => f.write_str("light coordinate outside the grid"),
            LightError::ZeroDirection => f.write_str("sun direction is zero"),
            LightError::TooMany(n) => write!(f, "{n} lights: at most {MAX_LIGHTS} are supported"),
            LightError::FarPoint {
                index,
                reach,
                centre,
            } => write!(
                f,
                "light {index}: outside the grid shared with the scene: a point light may lie at \
                 most {reach:.3e} units from {},{},{} along each axis; give a distant light as a \
                 sun",
                centre.x, centre.y, centre.z
            ),
            LightError::NotFinite { index } => {
                write!(
                    f,
                    "light {index}: a coordinate is not finite (NaN or infinite)"
                )
            }
            LightError::ZeroSun { index } => write!(f, "light {index}: the sun direction is zero"),
            LightError::Grid(e) => write!(f, "cannot fit a grid to the scene and its lights: {e}"),
            LightError::Extent { index, cause } => write!(f, "light {index}: {cause}"),
        }
    }
}

impl std::error::Error for LightError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            LightError::Grid(e) => Some(e),
            LightError::Extent { cause, .. } => Some(cause),
            _ => None,
        }
    }
}

/// The plane with normal `n` through the grid point `a`.
pub(crate) fn plane_along(n: [i64; 3], a: GridPoint) -> Option<Plane> {
    let offset = -(0..3).map(|k| n[k] as i128 * a[k] as i128).sum::<i128>();
    Plane::new(n, offset)
}

pub(crate) fn sub(a: [i32; 3], b: [i32; 3]) -> [i64; 3] {
    [0, 1, 2].map(|k| a[k] as i64 - b[k] as i64)
}

pub(crate) fn cross(u: [i64; 3], v: [i64; 3]) -> [i64; 3] {
    [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ]
}

impl Light {
    /// The point of a point light; `None` for a sun.
    pub(crate) fn point(&self) -> Option<[i32; 3]> {
        match self {
            Light::Point(p) => Some(*p),
            Light::Directional(_) => None,
        }
    }

    /// Checks the coordinate bounds the arithmetic budget relies on.
    pub fn validate(&self) -> Result<(), LightError> {
        let c = match self {
            Light::Point(c) | Light::Directional(c) => c,
        };
        if c.iter().any(|v| v.unsigned_abs() > MAX_COORD as u32) {
            return Err(LightError::OutOfGrid);
        }
        if matches!(self, Light::Directional([0, 0, 0])) {
            return Err(LightError::ZeroDirection);
        }
        Ok(())
    }

    /// The plane's value at the light in homogeneous form: `n · L + d` for a
    /// point light, `n · D` for a directional one. Positive when the light
    /// is in front. `|value| < 2^84`.
    #[inline]
    pub fn eval(&self, p: &Plane) -> i128 {
        let n = p.normal();
        let dot = |c: &[i32; 3]| (0..3).map(|k| n[k] as i128 * c[k] as i128).sum::<i128>();
        match self {
            Light::Point(c) => dot(c) + p.offset(),
            Light::Directional(c) => dot(c),
        }
    }

    /// `true` if the light is strictly in front of `p`.
    #[inline]
    pub fn faces(&self, p: &Plane) -> bool {
        self.eval(p) > 0
    }

    /// `true` if, among occluders certified to bound solids
    /// ([`bsp_core::certify_solid_boundary`], or one part of them by
    /// [`bsp_core::certify_solid_parts`]), those this light does not
    /// face ([`Light::faces`]) may be left out of its shadow volumes: the
    /// light is a sun, or a point outside the solids' box, so its winding
    /// number is 0. The others' volumes then cover theirs, except where a
    /// segment to the light only grazes the surface: a set of no area on
    /// every receiver not edge-on to the light, so every lit area stays the
    /// same exactly.
    pub fn culls_back_faces(&self, solid: &bsp_core::SolidBoundary) -> bool {
        self.outside_box(solid.lo, solid.hi)
    }

    /// `true` if polygon `i` of a list, whose plane is `support`, can be
    /// left out of this light's shadow volumes: its edge-connected part is
    /// certified to bound a solid (`solids`, from
    /// [`bsp_core::certify_solid_parts`] of the list), the light is
    /// outside the part's box ([`Light::culls_back_faces`]) and does not
    /// face it. The part's faces toward the light hide all it hides.
    pub fn leaves_out(&self, solids: &bsp_core::SolidParts, i: usize, support: &Plane) -> bool {
        solids.boundary(i).is_some_and(|b| self.culls_back_faces(b)) && !self.faces(support)
    }

    /// `true` for a sun, or a point light strictly outside the box `[lo,
    /// hi]`: where [`Light::culls_back_faces`] may answer `true` for
    /// solids with that box (so a caller can skip certifying them).
    pub fn outside_box(&self, lo: GridPoint, hi: GridPoint) -> bool {
        match self {
            Light::Point(c) => (0..3).any(|k| c[k] < lo[k] || c[k] > hi[k]),
            Light::Directional(_) => true,
        }
    }

    /// The plane through the light and the points `a`, `b` (for a sun,
    /// through them and parallel to its direction), unoriented; `None`
    /// where the light lies on their line.
    pub(crate) fn plane_with(&self, a: GridPoint, b: GridPoint) -> Option<Plane> {
        match self {
            Light::Point(l) => Plane::through(*l, a, b).ok(),
            Light::Directional(d) => plane_along(cross(sub(b, a), d.map(i64::from)), a),
        }
    }

    /// The shadow plane of the edge `a → b` of a polygon with grid
    /// vertices: the plane through the light and the edge (for a sun, the
    /// plane through the edge parallel to the direction), oriented so that
    /// `inside`, a vertex of the polygon off the edge's line, is behind it.
    /// `None` if the light lies on the edge's line.
    ///
    /// An input-tier plane: through three grid points it has `|n_i| <
    /// 2^55` and `|d| < 2^83`, and for a sun `n = (b - a) × D` has
    /// `|n_i| < 2^54`, `|d| < 2^82` (see `docs/architecture.md`).
    pub fn edge_plane(&self, a: GridPoint, b: GridPoint, inside: GridPoint) -> Option<Plane> {
        let p = self.plane_with(a, b)?;
        match p.classify_grid(inside) {
            Side::Back => Some(p),
            Side::Front => Some(p.flip()),
            Side::On => None,
        }
    }

    /// [`Light::edge_plane`] of the edge `a → b` of a convex polygon whose
    /// vertices run counter-clockwise about its support plane, where
    /// `facing` says whether the light is strictly in front of that plane
    /// ([`Light::faces`]; the light must not lie in it): no vertex is
    /// classified. For a vertex `c` of the polygon off the edge's line,
    /// the plane through the light `L`, `a` and `b` has at `c` the sign of
    /// `det(a − L, b − L, c − L) = (a − L) · ((b − a) × (c − a))`, and
    /// `(b − a) × (c − a)` is a positive multiple of the support's
    /// normal `N`: the sign of `−(N · L + d)`, the same for every edge (for
    /// a sun `D`, `((b − a) × D) · (c − a) = −((b − a) × (c − a)) · D`).
    /// So the inside is behind the plane as made exactly when the light
    /// faces the polygon.
    #[inline]
    pub fn edge_plane_facing(&self, a: GridPoint, b: GridPoint, facing: bool) -> Option<Plane> {
        let p = self.plane_with(a, b)?;
        Some(if facing { p } else { p.flip() })
    }
}

/// A light as given in input units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightSpec {
    /// A point light at this position.
    Point(DVec3),
    /// A light at infinity, in this direction from the scene toward it.
    Sun(DVec3),
}

impl LightSpec {
    /// The position or direction given.
    pub fn value(&self) -> DVec3 {
        match *self {
            LightSpec::Point(v) | LightSpec::Sun(v) => v,
        }
    }
}

/// A light placed on the grid, with what reports say about it.
#[derive(Clone, Debug, PartialEq)]
pub struct PlacedLight {
    /// As given.
    pub spec: LightSpec,
    /// The exact light.
    pub light: Light,
    /// A point light's snapped position in input units; a sun's quantized
    /// direction, normalized.
    pub world: DVec3,
    /// For a sun, the angle in radians between the given and the
    /// quantized direction; zero for a point light.
    pub angle: f64,
}

/// A number as a person types it, for messages: Rust's `{:?}` form
/// (plain decimals, the exponent form for very large and very small
/// magnitudes, which std chooses) without its `.0` on whole numbers, so
/// that an echo of `1e300` is not 301 digits long and `3` stays `3`.
///
/// ```
/// assert_eq!(svbsp::input_number(2.5), "2.5");
/// assert_eq!(svbsp::input_number(-3.0), "-3");
/// assert_eq!(svbsp::input_number(1e300), "1e300");
/// assert_eq!(svbsp::input_number(1e-300), "1e-300");
/// ```
pub fn input_number(x: f64) -> String {
    let s = format!("{x:?}");
    match s.strip_suffix(".0") {
        Some(whole) => whole.to_string(),
        None => s,
    }
}

/// The three numbers of a point or direction, comma-separated, each as
/// [`input_number`] gives it.
pub fn input_triple(v: DVec3) -> String {
    format!(
        "{},{},{}",
        input_number(v.x),
        input_number(v.y),
        input_number(v.z)
    )
}

/// How many times coarser (as a power of two) than the scene's own grid
/// the shared grid may become to take in the point lights. Beyond that, a
/// light far away would cost the scene its resolution: such a light is
/// outside the grid and should be a sun.
pub const LIGHT_RANGE_BITS: i32 = 8;

/// The grid shared by a scene (its vertex positions) and its point
/// lights: the grid fitted to the positions and every point light, but at
/// most `2^LIGHT_RANGE_BITS` times coarser than the scene's own grid (a
/// light farther away then lies outside it, and [`place_lights`] says so).
/// Suns do not affect the grid.
pub fn shared_grid(positions: &[DVec3], lights: &[LightSpec]) -> Result<Grid, LightError> {
    let scene = Grid::fit_points(positions).map_err(LightError::Grid)?;
    let points: Vec<DVec3> = lights
        .iter()
        .filter_map(|l| match l {
            LightSpec::Point(p) => Some(*p),
            LightSpec::Sun(_) => None,
        })
        .collect();
    let coarsest = scene.scale().log2() as i32 - LIGHT_RANGE_BITS;
    match Grid::fit_points(positions.iter().chain(&points)) {
        Ok(g) if g.scale().log2() as i32 >= coarsest => Ok(g),
        _ => Grid::new(scene.origin(), coarsest).map_err(LightError::Grid),
    }
}

/// Snaps every point light to `grid` and quantizes every sun, in order.
/// Errors name the light by its index.
pub fn place_lights(grid: &Grid, lights: &[LightSpec]) -> Result<Vec<PlacedLight>, LightError> {
    if lights.len() > MAX_LIGHTS {
        return Err(LightError::TooMany(lights.len()));
    }
    lights
        .iter()
        .enumerate()
        .map(|(index, spec)| match *spec {
            LightSpec::Point(p) | LightSpec::Sun(p) if !p.is_finite() => {
                Err(LightError::NotFinite { index })
            }
            LightSpec::Point(p) => {
                let g = grid.snap(p).map_err(|_| LightError::FarPoint {
                    index,
                    reach: MAX_COORD as f64 / grid.scale(),
                    centre: grid.origin(),
                })?;
                Ok(PlacedLight {
                    spec: *spec,
                    light: Light::Point(g),
                    world: grid.to_world(g.map(f64::from)),
                    angle: 0.0,
                })
            }
            LightSpec::Sun(d) => {
                let q = quantize_direction(d).ok_or(LightError::ZeroSun { index })?;
                let qd = DVec3::from_array(q.map(f64::from));
                Ok(PlacedLight {
                    spec: *spec,
                    light: Light::Directional(q),
                    world: qd.normalize(),
                    angle: angle_between(d, qd),
                })
            }
        })
        .collect()
}

/// The largest angular radius of a sun disc, in radians (30°: the real
/// sun's is 0.2666°).
pub const MAX_DISC_RADIUS: f64 = MAX_DISC_RADIUS_DEG.to_radians();

/// [`MAX_DISC_RADIUS`] in degrees.
pub const MAX_DISC_RADIUS_DEG: f64 = 30.0;

/// Why corners make no area light (or occluder).
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum AreaLightError {
    /// Fewer than three corners.
    TooFewCorners(usize),
    /// An area light of more than 64 corners.
    TooManyCorners(usize),
    /// The corners are not a planar, strictly convex polygon with area
    /// (collinear, not planar, not convex, turning twice, or out of the
    /// grid); the cause as the kernel found it.
    Shape(FaceDefect),
    /// A point or direction outside the grid, or a zero direction.
    Corner,
    /// A sun disc's direction is zero or not finite, or its angular
    /// radius (radians) is not in `[0, MAX_DISC_RADIUS]`.
    Disc {
        /// The direction given.
        direction: DVec3,
        /// The angular radius given, in radians.
        radius: f64,
    },
}

impl std::fmt::Display for AreaLightError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            AreaLightError::TooFewCorners(n) => {
                write!(
                    f,
                    "a polygon of {n} corners: it takes at least three corners"
                )
            }
            AreaLightError::TooManyCorners(n) => {
                write!(f, "an area light of {n} corners: at most 64 are supported")
            }
            AreaLightError::Shape(d) => {
                write!(f, "not a planar convex polygon with area: {d}")
            }
            AreaLightError::Corner => {
                f.write_str("a point or direction outside the grid, or a zero direction")
            }
            AreaLightError::Disc { direction, radius } => write!(
                f,
                "a sun disc needs a non-zero direction (given {},{},{}) and an angular radius \
                 between 0° and {}° (given {}°)",
                direction.x,
                direction.y,
                direction.z,
                MAX_DISC_RADIUS_DEG,
                radius.to_degrees()
            ),
        }
    }
}

impl std::error::Error for AreaLightError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            AreaLightError::Shape(d) => Some(d),
            AreaLightError::TooFewCorners(_)
            | AreaLightError::TooManyCorners(_)
            | AreaLightError::Corner
            | AreaLightError::Disc { .. } => None,
        }
    }
}

/// A light with extent as given in input units.
#[derive(Clone, Debug, PartialEq)]
pub enum SoftSpec {
    /// A planar convex polygon, its corners in order; it emits on the
    /// side they turn counter-clockwise about.
    Area(Vec<DVec3>),
    /// The sun as a disc of the sky: the direction from the scene toward
    /// its centre and its angular radius in degrees.
    SunDisc {
        /// Toward the centre.
        direction: DVec3,
        /// The angular radius, degrees.
        radius_deg: f64,
    },
}

/// The real sun's mean angular radius, in degrees.
pub const SUN_RADIUS_DEG: f64 = 0.2666;

impl SoftSpec {
    /// The points that must lie on the grid (an area light's corners).
    pub fn points(&self) -> &[DVec3] {
        match self {
            SoftSpec::Area(c) => c,
            SoftSpec::SunDisc { .. } => &[],
        }
    }
}

/// The integer direction of `d`: scaled so that its largest component is
/// `±MAX_COORD`, then rounded. `None` for a zero or non-finite `d`.
pub fn quantize_direction(d: DVec3) -> Option<[i32; 3]> {
    let m = d.abs().max_element();
    if !d.is_finite() || m == 0.0 {
        return None;
    }
    // d / m has components in [-1, 1], the largest exactly ±1
    let q = (d / m * MAX_COORD as f64).round();
    Some([q.x as i32, q.y as i32, q.z as i32])
}

/// The angle between two non-zero directions, in radians (accurate for
/// tiny angles).
pub fn angle_between(a: DVec3, b: DVec3) -> f64 {
    let (a, b) = (
        (a / a.abs().max_element()).normalize(),
        (b / b.abs().max_element()).normalize(),
    );
    a.cross(b).length().atan2(a.dot(b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sun_directions_are_quantized_to_the_grid_range() {
        let m = MAX_COORD;
        assert_eq!(quantize_direction(DVec3::Z), Some([0, 0, m]));
        assert_eq!(
            quantize_direction(DVec3::new(-2.0, 1.0, 0.0)),
            Some([-m, (m + 1) / 2, 0])
        );
        // subnormal and huge directions scale alike (the scaling divides
        // by the largest component, which is exact)
        let subnormal = f64::MIN_POSITIVE * 2f64.powi(-40);
        assert_eq!(
            quantize_direction(DVec3::new(subnormal, 0.0, -subnormal)),
            Some([m, 0, -m])
        );
        let huge = f64::MAX / 4.0;
        assert_eq!(
            quantize_direction(DVec3::new(huge, huge, 0.0)),
            Some([m, m, 0])
        );
        assert_eq!(quantize_direction(DVec3::ZERO), None);
        assert_eq!(quantize_direction(DVec3::new(f64::NAN, 1.0, 0.0)), None);
    }

    #[test]
    fn quantization_error_is_tiny_and_measured() {
        let d = DVec3::new(1.0, 2.0, 7.0);
        let q = quantize_direction(d).unwrap();
        let a = angle_between(d, DVec3::from_array(q.map(f64::from)));
        // each component rounds by at most ½ on a vector at least
        // MAX_COORD long: the angle is below 1 / MAX_COORD
        assert!(a > 0.0 && a < 1.0 / MAX_COORD as f64, "{a}");
        // MAX_COORD = 3 · 22369621: thirds are exact
        let q = quantize_direction(DVec3::new(1.0, 2.0, 3.0)).unwrap();
        assert_eq!(q, [22369621, 44739242, MAX_COORD]);
        assert_eq!(angle_between(DVec3::X, DVec3::X * 7.0), 0.0);
        // atan2(1, 0): π/2 correctly rounded
        assert_eq!(
            angle_between(DVec3::X, DVec3::Y),
            std::f64::consts::FRAC_PI_2
        );
    }

    #[test]
    fn lights_share_the_scene_grid() {
        let scene = [DVec3::ZERO, DVec3::ONE];
        let near = [LightSpec::Point(DVec3::new(0.5, 0.5, 3.0))];
        let g = shared_grid(&scene, &near).unwrap();
        // the light is inside the fitted box, so it snaps exactly
        let placed = place_lights(&g, &near).unwrap();
        assert_eq!(placed[0].world, DVec3::new(0.5, 0.5, 3.0));
        assert!(matches!(placed[0].light, Light::Point(_)));
        // suns do not move the grid
        let sun = [LightSpec::Sun(DVec3::new(0.0, 0.0, -1e9))];
        assert_eq!(
            shared_grid(&scene, &sun).unwrap(),
            shared_grid(&scene, &[]).unwrap()
        );
        let placed = place_lights(&g, &sun).unwrap();
        assert_eq!(placed[0].light, Light::Directional([0, 0, -MAX_COORD]));
        assert_eq!(placed[0].world, DVec3::NEG_Z);
    }

    #[test]
    fn far_lights_and_zero_suns_are_errors_naming_the_light() {
        let scene = [DVec3::ZERO, DVec3::ONE];
        let lights = [
            LightSpec::Point(DVec3::new(0.5, 0.5, 2.0)),
            LightSpec::Point(DVec3::new(0.5, 0.5, 1e6)),
        ];
        let g = shared_grid(&scene, &lights).unwrap();
        // the grid stays at most 2^8 times coarser than the scene's own
        let own = shared_grid(&scene, &[]).unwrap();
        assert_eq!(g.scale(), own.scale() / 256.0);
        let e = place_lights(&g, &lights).unwrap_err();
        assert!(matches!(e, LightError::FarPoint { index: 1, .. }), "{e}");
        assert!(
            e.to_string().starts_with("light 1: outside the grid"),
            "{e}"
        );
        let e = place_lights(&g, &[LightSpec::Sun(DVec3::ZERO)]).unwrap_err();
        assert_eq!(e, LightError::ZeroSun { index: 0 });
        // not "outside the grid" or "zero": what is wrong, and where
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let lights = [
                LightSpec::Point(DVec3::new(0.5, 0.5, 2.0)),
                LightSpec::Point(DVec3::new(0.5, bad, 2.0)),
                LightSpec::Sun(DVec3::new(bad, 0.0, 1.0)),
            ];
            let g = shared_grid(&scene, &lights).unwrap();
            let e = place_lights(&g, &lights).unwrap_err();
            assert_eq!(e, LightError::NotFinite { index: 1 });
            assert_eq!(
                e.to_string(),
                "light 1: a coordinate is not finite (NaN or infinite)"
            );
            let e = place_lights(&g, &lights[2..]).unwrap_err();
            assert_eq!(e, LightError::NotFinite { index: 0 });
        }
        let many = vec![LightSpec::Sun(DVec3::Z); MAX_LIGHTS + 1];
        assert_eq!(
            place_lights(&g, &many).unwrap_err(),
            LightError::TooMany(MAX_LIGHTS + 1)
        );
    }

    proptest::proptest! {
        /// The orientation from the light's side of the support plane is
        /// the one the classified vertex gives, for lights on both sides,
        /// points and suns, triangles turned either way.
        #[test]
        fn edge_planes_facing_agree_with_the_classified_ones(
            t in proptest::array::uniform3(proptest::array::uniform3(-1000i32..1000)),
            l in proptest::array::uniform3(-2000i32..2000),
            sun in proptest::bool::ANY,
        ) {
            let Ok(support) = Plane::through(t[0], t[1], t[2]) else {
                return Ok(());
            };
            let light = match sun {
                true => Light::Directional(l),
                false => Light::Point(l),
            };
            if light.eval(&support) == 0 {
                return Ok(());
            }
            let facing = light.faces(&support);
            for j in 0..3 {
                let (a, b, c) = (t[j], t[(j + 1) % 3], t[(j + 2) % 3]);
                proptest::prop_assert_eq!(
                    light.edge_plane_facing(a, b, facing),
                    light.edge_plane(a, b, c)
                );
            }
        }
    }

    #[test]
    fn edge_planes_contain_the_light_and_the_edge() {
        let (a, b, c) = ([0, 0, 0], [4, 0, 0], [0, 4, 0]);
        for light in [Light::Point([1, 1, 5]), Light::Directional([1, -2, 7])] {
            let p = light.edge_plane(a, b, c).unwrap();
            assert_eq!(p.classify_grid(a), Side::On);
            assert_eq!(p.classify_grid(b), Side::On);
            assert_eq!(p.classify_grid(c), Side::Back);
            assert_eq!(light.eval(&p), 0);
        }
        // a light on the edge's line has no shadow plane for it
        assert!(Light::Point([9, 0, 0]).edge_plane(a, b, c).is_none());
        assert!(Light::Directional([1, 0, 0]).edge_plane(a, b, c).is_none());
    }
}
