//! Lights with extent: a planar convex polygon on the grid, and exactly
//! what of it a point sees.
//!
//! A point `x` sees the light point `l` if `l` is strictly in front of the
//! light's plane's emitting side as seen from `x` (the side its corners
//! turn counter-clockwise about), `l` is strictly in front of the plane of
//! the face `x` lies on (if one is given), and the open segment `(x, l)`
//! meets no occluder. What `x` sees of the light is then the light polygon
//! less, for every occluder `O` with `x` off its plane, the part of the
//! light inside `O`'s cone from `x` (behind the planes through `x` and
//! `O`'s edges, on the far side of `O`'s plane): convex pieces whose
//! corners are exact points, cut by planes through grid points only, so
//! every decision is an exact sign ([`AreaLight::view`]). Visibility is
//! counted by area: light points hidden only on a set of zero area (along
//! a line grazing an occluder's edge) count as seen, so [`Visibility::All`]
//! means the whole light's irradiance arrives.
//!
//! The share of the light's irradiance that arrives ([`LightView::fraction`])
//! is the point-to-polygon form factor of the pieces over the light's own,
//! in closed form (Lambert), in `f64`.
//!
//! A whole face is cut into fragments of one class each by
//! [`AreaLight::classify_face`]. The points an occluder `O` keeps from
//! seeing all of the light, `PV(O) = {x : conv(x, L) ∩ O ≠ ∅}`, form a
//! convex set (a convex combination of two witnesses is one) bounded by
//! the planes through a light corner and an occluder edge, or through a
//! light edge and an occluder corner, that separate the light from the
//! occluder, and, where the light lies on one side of the occluder's
//! plane, by that plane. All pass through grid points, so a face cut by
//! them is classified piece by piece by exact signs alone: lit is exact.
//! A piece inside one occluder's umbra (behind it from every light corner:
//! the light is convex, so it is then hidden whole) is umbra; a piece from
//! which some light corner is seen is penumbra; a piece whose every light
//! corner is hidden, by different occluders, is undecided: its umbra may
//! end on a quadric (EEE) surface, or on a plane of occluders that only
//! together hide the light. Under a closed mesh, convex polygons certified
//! inside its solid decide much of it ([`crate::cores`]), and a light
//! sealed inside one leaves everything outside in umbra
//! ([`crate::sealed`]).

use bsp_core::internals::GridPolygon;
use bsp_core::{FaceDefect, GridPoint, MAX_COORD, Plane, Polygon, PolygonSide, Side, Split};
use glam::DVec3;
use rayon::prelude::*;

use crate::boxes::{Box3, EMPTY, Near, Reach, ReachIndex, Scan, Scans, grid_box, polygon_box};
use crate::light::{
    AreaLightError, Light, MAX_DISC_RADIUS, cross, plane_along, quantize_direction,
};
use crate::merging::{Keyed, merge_convex, merge_keyed, merge_keyed_parts, vertex_keys};

/// A light with extent, or its limit, as a convex set of light points
/// given by its corners ([`Light`]s, all of one kind):
///
/// - a planar convex polygon on the grid that emits on the side its
///   corners turn counter-clockwise about ([`AreaLight::new`]);
/// - a convex polygon of directions, a disc of the sky bounded by a
///   regular polygon ([`AreaLight::sun_disc`]);
/// - one point or one direction, the limits of both
///   ([`AreaLight::point`], [`AreaLight::sun`]): classified as an area
///   light of no extent, lit or umbra, never penumbra.
#[derive(Clone, Debug)]
pub struct AreaLight {
    corners: Vec<Light>,
    /// The polygon of a light with area at finite distance.
    polygon: Option<GridPolygon>,
}

/// How many directions bound a sun disc ([`AreaLight::sun_disc`]): the
/// polygon's area is `8 tan(π/8) / π ≈ 1.055` times the disc's.
pub const DISC_SIDES: usize = 8;

/// An upper bound of `sin² r`: `sin r` rounded up by one unit in the last
/// place (the platform's `sin` is within one), squared and rounded up.
fn upper_sin2(r: f64) -> f64 {
    let s = r.sin().next_up();
    (s * s).next_up()
}

/// Whether the polygon of directions `corners` turns counter-clockwise
/// about `q`, strictly convex, and holds every direction within the angle
/// whose squared sine is at most `sin2` of `q`: for each edge's normal
/// `n = c_i × c_(i+1)`, `n · q > 0` and `(n · q)² ≥ sin2 · |n|² |q|²`,
/// decided exactly (`sin2` is a dyadic rational).
fn holds_disc(corners: &[[i32; 3]], q: [i32; 3], sin2: f64) -> bool {
    use bnum::types::U512;
    let k = corners.len();
    let wide = |p: [i32; 3]| p.map(i128::from);
    let dot = |a: [i128; 3], b: [i128; 3]| (0..3).map(|i| a[i] * b[i]).sum::<i128>();
    let cross = |a: [i128; 3], b: [i128; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let q = wide(q);
    // sin2 = m · 2^-e, m < 2^53
    let bits = sin2.to_bits();
    let (exp, frac) = ((bits >> 52) as i64, bits & ((1 << 52) - 1));
    let (m, e) = if exp == 0 {
        (frac, 1074)
    } else {
        (frac | 1 << 52, 1075 - exp)
    };
    (0..k).all(|i| {
        let (a, b, c) = (
            wide(corners[i]),
            wide(corners[(i + 1) % k]),
            wide(corners[(i + 2) % k]),
        );
        let n = cross(a, b);
        let nq = dot(n, q);
        // convex, turning one way, and q inside
        if dot(n, c) <= 0 || nq <= 0 {
            return false;
        }
        // (n·q)² < 2^164, |n|²|q|² < 2^164: A · 2^e ≥ m · B
        if e >= 240 {
            return true;
        }
        let big = |x: i128| U512::from(x.unsigned_abs());
        let lhs = (big(nq) * big(nq)) << (e as u32);
        let rhs = U512::from(m) * big(dot(n, n)) * big(dot(q, q));
        lhs >= rhs
    })
}

/// A face of the scene as area lights meet it, as an occluder or a
/// receiver: a planar, strictly convex polygon with corners on the grid
/// (counter-clockwise about its front; every face blocks light whichever
/// way it faces).
#[derive(Clone, Debug)]
pub struct Occluder {
    polygon: GridPolygon,
}

impl Occluder {
    /// The occluder with these corners (see [`AreaLight::new`] for what
    /// they must be).
    pub fn new(corners: &[GridPoint]) -> Result<Occluder, AreaLightError> {
        convex(corners).map(|polygon| Occluder { polygon })
    }

    /// The occluder of a polygon with grid corners (an imported face);
    /// `None` where a corner is not a grid point or the corners make no
    /// occluder.
    pub fn of_polygon(p: &Polygon) -> Option<Occluder> {
        let corners: Option<Vec<GridPoint>> =
            p.vertices().iter().map(|v| v.as_ref().as_grid()).collect();
        Occluder::new(&corners?).ok()
    }

    /// Its plane.
    pub fn plane(&self) -> &Plane {
        self.polygon.support()
    }

    /// The occluder as a polygon (tag 0).
    pub(crate) fn to_polygon(&self) -> Polygon {
        self.polygon.to_polygon(0)
    }

    /// Its corners, in order (without repeated or collinear ones).
    pub fn corners(&self) -> &[GridPoint] {
        self.polygon.vertices()
    }
}

/// The planar, strictly convex polygon with these corners (see
/// [`AreaLight::new`]).
fn convex(corners: &[GridPoint]) -> Result<GridPolygon, AreaLightError> {
    if corners.len() < 3 {
        return Err(AreaLightError::TooFewCorners(corners.len()));
    }
    GridPolygon::from_grid_points(corners).map_err(|d| {
        // corners not on one line whose loop has no area cross each other
        // (a bow tie): say so, not "collinear"
        let spread = || {
            (1..corners.len()).any(|i| {
                (i + 1..corners.len())
                    .any(|j| Plane::through(corners[0], corners[i], corners[j]).is_ok())
            })
        };
        match d {
            FaceDefect::ZeroArea if spread() => AreaLightError::Shape(FaceDefect::NotSimple),
            d => AreaLightError::Shape(d),
        }
    })
}

/// How much of a light a point sees, exactly (up to sets of zero area).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Visibility {
    /// All of it: fully lit.
    All,
    /// Some of it, not all: penumbra.
    Part,
    /// None of it: umbra (or the light is behind the point's face, or
    /// the point is not on the light's emitting side).
    None,
}

/// What a point sees of an area light ([`AreaLight::view`]).
#[derive(Clone, Debug)]
pub struct LightView {
    /// The light's part in front of the point's face (all of the light if
    /// no face is given), as convex pieces: what arrives unoccluded.
    pub reachable: Vec<Polygon>,
    /// The pieces of the light the point sees: the reachable part less
    /// every occluder's cone. Convex, disjoint, with exact corners.
    pub seen: Vec<Polygon>,
    /// Exactly how much.
    pub visibility: Visibility,
}

impl AreaLight {
    /// The light with these corners, in order; they must be a planar,
    /// strictly convex polygon with area (repeated and collinear corners
    /// are dropped first), with every coordinate within the grid.
    ///
    /// ```
    /// use svbsp::AreaLight;
    /// // a square at height 8 that shines down (clockwise seen from above)
    /// let light = AreaLight::new(&[[0, 0, 8], [0, 2, 8], [2, 2, 8], [2, 0, 8]]).unwrap();
    /// assert_eq!(light.corners().len(), 4);
    /// // a bow tie is no light
    /// assert!(AreaLight::new(&[[0, 0, 8], [2, 2, 8], [0, 2, 8], [2, 0, 8]]).is_err());
    /// ```
    pub fn new(corners: &[GridPoint]) -> Result<AreaLight, AreaLightError> {
        let polygon = convex(corners)?;
        if polygon.len() > 64 {
            return Err(AreaLightError::TooManyCorners(polygon.len()));
        }
        Ok(AreaLight {
            corners: polygon
                .vertices()
                .iter()
                .map(|&c| Light::Point(c))
                .collect(),
            polygon: Some(polygon),
        })
    }

    /// A point light as the limit of area lights: its fragments are lit
    /// or umbra, exactly where [`Light::Point`]'s are lit or shadowed.
    pub fn point(at: GridPoint) -> Result<AreaLight, AreaLightError> {
        Self::one(Light::Point(at))
    }

    /// A sun as the limit of sun discs (see [`AreaLight::point`]).
    pub fn sun(direction: [i32; 3]) -> Result<AreaLight, AreaLightError> {
        Self::one(Light::Directional(direction))
    }

    fn one(light: Light) -> Result<AreaLight, AreaLightError> {
        light.validate().map_err(|_| AreaLightError::Corner)?;
        Ok(AreaLight {
            corners: vec![light],
            polygon: None,
        })
    }

    /// The sun as a disc of the sky: the directions within the angular
    /// `radius` (radians) of `direction` (from the scene toward the sun)
    /// once quantized ([`quantize_direction`], as for a sun: within
    /// a ten-millionth of a degree of the given one), bounded by a regular polygon of
    /// [`DISC_SIDES`] quantized directions that contains the disc: each
    /// edge's plane is checked exactly to leave the whole disc inside (with
    /// `sin r` rounded up), and a polygon that fails is widened by one
    /// quantization step and built again. What is classified lit
    /// therefore sees all of the disc, and what is umbra sees none of it;
    /// the penumbra is a little wider than the disc's. A radius of 0 is
    /// [`AreaLight::sun`] of the quantized direction.
    ///
    /// ```
    /// use glam::DVec3;
    /// use svbsp::{AreaLight, DISC_SIDES};
    /// let sun = AreaLight::sun_disc(DVec3::new(1.0, 2.0, 5.0), 0.2666f64.to_radians()).unwrap();
    /// assert_eq!(sun.corners().len(), DISC_SIDES);
    /// assert!(AreaLight::sun_disc(DVec3::ZERO, 0.01).is_err());
    /// ```
    pub fn sun_disc(direction: DVec3, radius: f64) -> Result<AreaLight, AreaLightError> {
        let bad = AreaLightError::Disc { direction, radius };
        if !(0.0..=MAX_DISC_RADIUS).contains(&radius) {
            return Err(bad);
        }
        let q = quantize_direction(direction).ok_or(bad.clone())?;
        if radius == 0.0 {
            return Self::sun(q);
        }
        // an orthonormal frame about the quantized centre, and the
        // circumscribed polygon in the tangent plane at distance 1
        let d = DVec3::from_array(q.map(f64::from)).normalize();
        let u = d.any_orthonormal_vector();
        let v = d.cross(u);
        let step = std::f64::consts::TAU / DISC_SIDES as f64;
        let mut reach = radius.tan() / (step / 2.0).cos();
        let sin2 = upper_sin2(radius);
        for _ in 0..64 {
            let corners: Option<Vec<[i32; 3]>> = (0..DISC_SIDES)
                .map(|i| {
                    let a = step * i as f64;
                    quantize_direction(d + (u * a.cos() + v * a.sin()) * reach)
                })
                .collect();
            let corners = corners.ok_or(bad.clone())?;
            if holds_disc(&corners, q, sin2) {
                return Ok(AreaLight {
                    corners: corners.into_iter().map(Light::Directional).collect(),
                    polygon: None,
                });
            }
            reach += 1.0 / f64::from(MAX_COORD);
        }
        Err(bad)
    }

    /// The corners, in order (without repeated or collinear ones): grid
    /// points, or directions for a sun.
    pub fn corners(&self) -> &[Light] {
        &self.corners
    }

    /// The corners of a polygon light at finite distance.
    pub(crate) fn grid_corners(&self) -> Option<&[GridPoint]> {
        self.polygon.as_ref().map(GridPolygon::vertices)
    }

    /// The light's plane, for a polygon at finite distance; it emits on
    /// the front side.
    pub fn plane(&self) -> Option<&Plane> {
        self.polygon.as_ref().map(GridPolygon::support)
    }

    /// What the grid point `x` sees of the light: `face`, the plane of the
    /// face `x` lies on (light behind it does not arrive), and the
    /// occluders, each a convex polygon on the grid (a face `x` lies on
    /// hides nothing from it, and may be among them). `None` for a light
    /// without a polygon at finite distance (a point, a sun, a sun disc).
    ///
    /// ```
    /// use svbsp::{AreaLight, Occluder, Visibility};
    /// let light = AreaLight::new(&[[0, 0, 80], [0, 40, 80], [40, 40, 80], [40, 0, 80]]).unwrap();
    /// // a square half-way up, a quarter of the light's side, seen from
    /// // below its centre: it hides the light's middle quarter
    /// let roof = Occluder::new(&[[15, 15, 40], [25, 15, 40], [25, 25, 40], [15, 25, 40]]).unwrap();
    /// let view = light.view([20, 20, 0], None, &[roof]).unwrap();
    /// assert_eq!(view.visibility, Visibility::Part);
    /// let area: f64 = view.seen.iter().map(|p| svbsp::polygon_area(&p.vertices_f64()
    ///     .iter().map(|&v| glam::DVec3::from_array(v)).collect::<Vec<_>>())).sum();
    /// assert_eq!(area, 1200.0);
    /// ```
    pub fn view(
        &self,
        x: GridPoint,
        face: Option<&Plane>,
        occluders: &[Occluder],
    ) -> Option<LightView> {
        self.view_among(x, face, occluders.iter())
    }

    /// [`AreaLight::view`] with the occluders as an iterator.
    pub(crate) fn view_among<'o>(
        &self,
        x: GridPoint,
        face: Option<&Plane>,
        occluders: impl Iterator<Item = &'o Occluder>,
    ) -> Option<LightView> {
        let nothing = || LightView {
            reachable: Vec::new(),
            seen: Vec::new(),
            visibility: Visibility::None,
        };
        let polygon = self.polygon.as_ref()?;
        if polygon.support().classify_grid(x) != Side::Front {
            return Some(nothing());
        }
        let mut light = polygon.to_polygon(0);
        if let Some(face) = face
            && !light.clip(face, Side::Front)
        {
            return Some(nothing());
        }
        let reachable = vec![light];
        let mut seen = reachable.clone();
        let (mut hidden, mut merged) = (false, 0);
        for o in occluders {
            let Some(cone) = shadow_volume(Light::Point(x), &o.polygon) else {
                continue;
            };
            let mut next = Vec::with_capacity(seen.len());
            for piece in seen {
                hidden |= subtract_unmerged(&cone, piece, &mut next).is_some();
            }
            seen = next;
            if seen.is_empty() {
                break;
            }
            // merged as they pile up (later cones then meet fewer)
            if seen.len() > 16 && seen.len() > 2 * merged {
                merge_run(&mut seen, 0);
                merged = seen.len();
            }
        }
        let visibility = match (seen.is_empty(), hidden) {
            (true, _) => Visibility::None,
            (false, true) => Visibility::Part,
            (false, false) => Visibility::All,
        };
        Some(LightView {
            reachable,
            seen,
            visibility,
        })
    }
}

impl LightView {
    /// The share of the reachable light's irradiance that arrives at `x`
    /// (in grid units, as the view was taken) on a surface with normal
    /// `normal`: the form factor of the seen pieces over the reachable
    /// part's, in `f64`; `None` where nothing is reachable.
    ///
    /// ```
    /// use glam::DVec3;
    /// use svbsp::AreaLight;
    /// let light = AreaLight::new(&[[0, 0, 80], [0, 40, 80], [40, 40, 80], [40, 0, 80]]).unwrap();
    /// let view = light.view([20, 20, 0], None, &[]).unwrap();
    /// assert_eq!(view.fraction(DVec3::new(20.0, 20.0, 0.0), DVec3::Z), Some(1.0));
    /// ```
    pub fn fraction(&self, x: DVec3, normal: DVec3) -> Option<f64> {
        let of = |pieces: &[Polygon]| -> f64 {
            pieces
                .iter()
                .map(|p| form_factor(x, normal, &p.vertices_f64()))
                .sum()
        };
        let all = of(&self.reachable);
        if self.reachable.is_empty() || all <= 0.0 {
            return None;
        }
        if self.visibility == Visibility::All {
            return Some(1.0);
        }
        Some((of(&self.seen) / all).clamp(0.0, 1.0))
    }
}

/// The form factor from a point `x` with unit `normal` to a planar
/// polygon in front of it (Lambert's closed form: the sum over the edges
/// of the angle each subtends times the normal's component along the
/// edge's plane normal, over 2π), whichever way the polygon turns.
///
/// ```
/// use glam::DVec3;
/// let square = |s: f64| [[-s, -s, 1.0], [s, -s, 1.0], [s, s, 1.0], [-s, s, 1.0]];
/// let f = |s: f64| svbsp::form_factor(DVec3::ZERO, DVec3::Z, &square(s));
/// // a wider square right above sends more, and all of the hemisphere
/// // sends 1: a huge one nearly that
/// assert!(0.0 < f(0.5) && f(0.5) < f(1.0) && f(1.0) < f(1e6) && f(1e6) <= 1.0);
/// // seen from beside the square's plane, nothing
/// assert_eq!(svbsp::form_factor(DVec3::new(0.0, 0.0, 1.0), DVec3::X, &square(1.0)), 0.0);
/// ```
pub fn form_factor(x: DVec3, normal: DVec3, polygon: &[[f64; 3]]) -> f64 {
    let n = polygon.len();
    let mut sum = 0.0;
    for i in 0..n {
        let a = DVec3::from_array(polygon[i]) - x;
        let b = DVec3::from_array(polygon[(i + 1) % n]) - x;
        let c = a.cross(b);
        let len = c.length();
        if len == 0.0 {
            continue;
        }
        let angle = len.atan2(a.dot(b));
        sum += angle * normal.dot(c / len);
    }
    (sum / (2.0 * std::f64::consts::PI)).abs()
}

/// The shadow volume of occluder `o` from the grid point `from` (the
/// cone behind it): behind the planes through `from` and its edges, on
/// the far side of its plane. `None` where `from` lies in its plane (it
/// hides no area from there).
fn shadow_volume(from: Light, o: &GridPolygon) -> Option<HalfSpaces> {
    let far = beyond(sign(from.eval(o.support())))?;
    let v = o.vertices();
    let n = v.len();
    let mut hs = Vec::with_capacity(n + 1);
    hs.push((*o.support(), far));
    // (its edge planes oriented by the side of its plane `from` is on)
    let facing = far == Side::Back;
    for i in 0..n {
        // `from` is off the occluder's plane: never on a line of its edges
        let h = from.edge_plane_facing(v[i], v[(i + 1) % n], facing)?;
        debug_assert_eq!(
            Some(h),
            from.edge_plane(v[i], v[(i + 1) % n], v[(i + 2) % n])
        );
        hs.push((h, Side::Back));
    }
    Some(hs)
}

/// The side of a plane a value of it stands for.
fn sign(value: i128) -> Side {
    match value.signum() {
        1 => Side::Front,
        -1 => Side::Back,
        _ => Side::On,
    }
}

/// The side opposite `side`; `None` for [`Side::On`].
fn beyond(side: Side) -> Option<Side> {
    match side {
        Side::Front => Some(Side::Back),
        Side::Back => Some(Side::Front),
        Side::On => None,
    }
}

/// Whether a polygon on `side` of a plane lies wholly outside the
/// half-space `inside` of it (in the plane counts as outside: no area
/// inside).
fn wholly_outside(side: PolygonSide, inside: Side) -> bool {
    !matches!(
        (side, inside),
        (PolygonSide::Spanning, _)
            | (PolygonSide::Front, Side::Front)
            | (PolygonSide::Back, Side::Back)
    )
}

/// Pushes onto `out` the parts of `piece` outside the convex region
/// `halfspaces`, and returns the part inside, if it has area. Where no
/// part lies inside, `piece` is pushed whole (the cuts are undone); else
/// the parts outside, each cut off by one plane, are merged where their
/// union is convex.
fn subtract(
    halfspaces: &[(Plane, Side)],
    piece: Polygon,
    out: &mut Vec<Polygon>,
) -> Option<Polygon> {
    let start = out.len();
    let inside = subtract_unmerged(halfspaces, piece, out);
    if inside.is_some() {
        merge_run(out, start);
    }
    inside
}

/// [`subtract`] without merging the parts outside.
fn subtract_unmerged(
    halfspaces: &[(Plane, Side)],
    piece: Polygon,
    out: &mut Vec<Polygon>,
) -> Option<Polygon> {
    // wholly outside one half-space: nothing to cut (the common case)
    let outside_one = halfspaces
        .iter()
        .any(|(h, inside)| wholly_outside(piece.classify(h), *inside));
    if outside_one {
        out.push(piece);
        return None;
    }
    let start = out.len();
    let original = piece.clone();
    let mut rest = piece;
    for (plane, inside) in halfspaces {
        let (within, outside) = match rest.split(plane) {
            Split::Spanning { front, back } => match inside {
                Side::Front => (front, Some(back)),
                _ => (back, Some(front)),
            },
            Split::Front(p) if *inside == Side::Front => (p, None),
            Split::Back(p) if *inside == Side::Back => (p, None),
            Split::Front(_) | Split::Back(_) | Split::Coplanar { .. } => {
                out.truncate(start);
                out.push(original);
                return None;
            }
        };
        out.extend(outside);
        rest = within;
    }
    Some(rest)
}

/// Merges the polygons of `v[start..]` pairwise where their union is
/// convex, until none do.
fn merge_run(v: &mut Vec<Polygon>, start: usize) {
    let tail: Vec<Polygon> = v.drain(start..).collect();
    let merged = merge_convex(tail.into_iter().map(|p| (p, ())).collect());
    v.extend(merged.into_iter().map(|(p, ())| p));
}

/// What part of an area light the points of a fragment see.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AreaClass {
    /// All of it.
    Lit,
    /// Part of it: some light corner is seen, not all of the light.
    Penumbra,
    /// None of it.
    Umbra,
    /// Every light corner is hidden, by different occluders, and no one
    /// occluder hides the light: umbra or penumbra, not decided here.
    Undecided,
}

/// A piece of a face with one [`AreaClass`].
#[derive(Clone, Debug)]
pub struct AreaFragment {
    /// The piece: convex, with exact corners.
    pub polygon: Polygon,
    /// What its points see.
    pub class: AreaClass,
}

/// Half-spaces as planes and the side that is inside.
pub(crate) type HalfSpaces = Vec<(Plane, Side)>;

/// An occluder's regions for an area light: its penumbra volume (the
/// points it keeps from seeing all of the light) and, per light corner,
/// its shadow volume from that corner (`None` where the corner lies in
/// its plane and it hides nothing from there).
pub(crate) struct Regions {
    pub(crate) penumbra: HalfSpaces,
    pub(crate) from_corner: Vec<Option<HalfSpaces>>,
    /// Its umbra: the points inside its shadow volume from every corner
    /// (`None` where that is empty: a corner in its plane, or corners on
    /// both sides of it).
    pub(crate) umbra: Option<HalfSpaces>,
}

impl AreaLight {
    /// [`AreaLight::classify_face`] with the occluders' regions given.
    pub(crate) fn classify_with<'r>(
        &self,
        face: &Occluder,
        occluders: impl Iterator<Item = (&'r Regions, Reach)>,
        corners: Option<&mut SeenCorners<'_>>,
    ) -> Vec<AreaFragment> {
        let whole = face.polygon.to_polygon(0);
        let cut = self.cut(face, vec![(whole, ())], occluders, corners);
        merge_convex(cut.into_iter().map(|(p, (), c)| (p, c)).collect())
            .into_iter()
            .map(|(polygon, class)| AreaFragment { polygon, class })
            .collect()
    }

    /// Convex `pieces` of `face`, each with a label, cut where this
    /// light's class changes (see the module docs); each part keeps its
    /// piece's label. Not merged. `occluders` are those whose penumbra
    /// volume may meet the face (one that does not costs time, not
    /// correctness: [`crate::near`] leaves them out).
    ///
    /// `corners`, where given, cuts a piece where the light's corners it
    /// sees change (bit `i` of each part's mask: corner `i` seen, as the
    /// point lights' shadow volumes of the corners say); the pieces are
    /// then cut only by the occluders' penumbra and umbra volumes.
    /// Without it (or where it answers `None`), by every occluder's
    /// shadow volume from each corner too.
    pub(crate) fn cut<'r, K: Copy + PartialEq + Send + Sync>(
        &self,
        face: &Occluder,
        pieces: Vec<(Polygon, K)>,
        occluders: impl Iterator<Item = (&'r Regions, Reach)>,
        mut corners: Option<&mut SeenCorners<'_>>,
    ) -> Vec<(Polygon, K, AreaClass)> {
        let behind_face: Vec<bool> = self
            .corners()
            .iter()
            .map(|l| !l.faces(face.plane()))
            .collect();
        if behind_face.iter().all(|&b| b) {
            return pieces
                .into_iter()
                .map(|(p, k)| (p, k, AreaClass::Umbra))
                .collect();
        }
        let partly_behind = behind_face.iter().any(|&b| b);
        // points not strictly in front of a polygon light see none of it
        let mut out = Vec::new();
        let mut front = Vec::with_capacity(pieces.len());
        for (piece, label) in pieces {
            let split = match self.plane() {
                Some(plane) => piece.split(plane),
                None => Split::Front(piece),
            };
            match split {
                Split::Front(p) => front.push((p, label)),
                Split::Spanning { front: f, back } => {
                    out.push((back, label, AreaClass::Umbra));
                    front.push((f, label));
                }
                Split::Back(p) | Split::Coplanar { polygon: p, .. } => {
                    out.push((p, label, AreaClass::Umbra));
                }
            }
        }
        let mut regions: Vec<(&Regions, Reach)> = occluders.collect();
        // with no occluder having a corner in its plane, a cell that sees
        // one corner and not another is penumbra whatever the others: the
        // corners' cells need not say which (`ShadowSet::cells_known` settling)
        let flat = regions.iter().any(|(r, _)| flat_corners(r) != 0);
        let n = self.corners().len();
        let all = u64::MAX >> (64 - n);
        let behind = (0..n).fold(0u64, |m, i| m | u64::from(behind_face[i]) << i);
        let mut pieces = Vec::with_capacity(front.len());
        let mut known = corners.is_some();
        for (polygon, label) in front {
            let Some(cells) = corners.as_mut().and_then(|c| c(&polygon, !flat)) else {
                known = false;
                pieces.push(Piece::new(polygon, label, behind, false));
                continue;
            };
            let piece = |(polygon, seen): (Polygon, u64)| {
                let hidden = behind | (all & !seen);
                let mut piece = Piece::new(polygon, label, hidden, hidden != 0);
                // a point (or a sun) hidden is umbra
                piece.umbra = n == 1 && hidden == all;
                piece
            };
            // (a ground's many cells: their boxes in parallel, in order)
            match cells.len() > PARALLEL_PIECES {
                true => pieces.par_extend(cells.into_par_iter().map(piece)),
                false => pieces.extend(cells.into_iter().map(piece)),
            }
        }
        if known {
            // (a face's whole: its other work waits for this merge)
            pieces = merge_pieces(pieces, true);
            // occluders with a corner in their plane first: they hide that
            // corner (for lack of a seen neighbourhood of it), and every
            // piece that ends up hiding all corners must meet every umbra;
            // then those that cut by their umbra only (the inner occluders,
            // whose penumbra box is empty): under a closed mesh one of them
            // takes at once what the faces' small umbrae would cut into
            // thousands of pieces
            regions.sort_by_key(|(r, reach)| {
                (r.from_corner.iter().all(Option::is_some), reach[0] != EMPTY)
            });
        }
        // pieces whose class no occluder can change stay as they are (with
        // their corners known: umbra, or seeing some corners and hiding
        // others while no occluder has a corner in its plane)
        let (active, done): (Vec<Piece<K>>, Vec<Piece<K>>) = pieces
            .into_iter()
            .partition(|p| !known || !p.umbra && (p.hidden == 0 || p.hidden == all || flat));
        // many pieces, each cut by many occluders: an index of the
        // occluders' boxes spares each piece passing over all of them
        let index = (active.len() > 1 && regions.len() > 128)
            .then(|| ReachIndex::new(grid_box(face.corners()), regions.iter().map(|(_, r)| r)));
        let how = Cutting {
            regions: &regions,
            index,
            all,
            known,
        };
        // each piece and its parts on their own, in parallel where there
        // are several (in order: the same for every thread count)
        let pieces = how.families(active);
        for piece in pieces.into_iter().chain(done) {
            let class = match piece {
                Piece { not_lit: false, .. } if partly_behind => AreaClass::Penumbra,
                Piece { not_lit: false, .. } => AreaClass::Lit,
                Piece { umbra: true, .. } => AreaClass::Umbra,
                Piece { hidden, .. } if hidden == all => AreaClass::Undecided,
                _ => AreaClass::Penumbra,
            };
            out.push((piece.polygon, piece.label, class));
        }
        out
    }

    /// The occluder's regions (see [`Regions`]); `None` where it hides
    /// none of the light: where it lies in the light's plane, or has no
    /// point strictly on the side a polygon light emits to. (A point that
    /// sees any of the light lies strictly on that side, so its open
    /// segment to a light point does too, and cannot meet such an
    /// occluder; the volumes' separating planes alone would not say so
    /// where the occluder touches the light's plane.)
    pub(crate) fn regions(&self, o: &Occluder) -> Option<Regions> {
        let lv = self.corners();
        let light_sides: Vec<Side> = lv.iter().map(|l| sign(l.eval(o.plane()))).collect();
        if light_sides.iter().all(|&s| s == Side::On) {
            return None;
        }
        if let Some(plane) = self.plane()
            && (o.corners().iter()).all(|&c| plane.classify_grid(c) != Side::Front)
        {
            return None;
        }
        let from_corner: Vec<Option<HalfSpaces>> =
            lv.iter().map(|&l| shadow_volume(l, &o.polygon)).collect();
        let penumbra = if let [one] = &from_corner[..] {
            // a light of one point: the volume is its shadow volume
            one.clone()?
        } else {
            self.penumbra_volume(&light_sides, o, &from_corner)
        };
        Some(Regions {
            penumbra,
            umbra: umbra_volume(lv, &from_corner),
            from_corner,
        })
    }

    /// The half-spaces of an occluder's penumbra volume (see the module
    /// docs), for a light of several corners, whose shadow volumes from
    /// each corner are `from_corner` ([`shadow_volume`]: their edge planes
    /// are the planes through a corner and an edge, made once).
    fn penumbra_volume(
        &self,
        light_sides: &[Side],
        o: &Occluder,
        from_corner: &[Option<HalfSpaces>],
    ) -> HalfSpaces {
        let (lv, ov) = (self.corners(), o.polygon.vertices());
        let mut penumbra = HalfSpaces::new();
        // the occluder's plane bounds the volume where the light is on one side
        let light_front = light_sides.contains(&Side::Front);
        let light_back = light_sides.contains(&Side::Back);
        if light_front != light_back {
            penumbra.push((
                *o.plane(),
                if light_front { Side::Back } else { Side::Front },
            ));
        }
        let (nl, no) = (lv.len(), ov.len());
        for i in 0..nl {
            for j in 0..no {
                // the corner's shadow plane of edge `j` as made, unoriented
                // (`shadow_volume` flips it where the corner is behind the
                // occluder's plane)
                let through = match &from_corner[i] {
                    Some(hs) => Some(match light_sides[i] {
                        Side::Front => hs[j + 1].0,
                        _ => hs[j + 1].0.flip(),
                    }),
                    None => lv[i].plane_with(ov[j], ov[(j + 1) % no]),
                };
                debug_assert_eq!(through, lv[i].plane_with(ov[j], ov[(j + 1) % no]));
                let planes = [through, edge_corner_plane(lv[i], lv[(i + 1) % nl], ov[j])];
                for h in planes.into_iter().flatten() {
                    if let Some(inside) = separating(&h, lv, ov) {
                        penumbra.push((h, inside));
                    }
                }
            }
        }
        penumbra
    }
}

/// The intersection of the corners' shadow volumes (each the occluder's
/// plane, far side first, then its edges' planes): the occluder's plane
/// and, per edge, the plane through it and the light corner no other
/// corner lies outside of; `None` where it is empty.
///
/// On the far side of the occluder's plane (every corner on the near
/// side), the half-spaces through one edge `e` are, across `e`, wedges
/// right of the rays from `e` away from each corner: they are nested, and
/// the one through the outermost corner (every other corner inside it or
/// on it) is their intersection. So the other planes through `e` are
/// left out, exactly: the volume is the same set.
fn umbra_volume(lights: &[Light], from_corner: &[Option<HalfSpaces>]) -> Option<HalfSpaces> {
    let volumes: Vec<&HalfSpaces> = from_corner
        .iter()
        .map(Option::as_ref)
        .collect::<Option<_>>()?;
    let far = volumes.first()?.first()?.1;
    if volumes.iter().any(|v| v[0].1 != far) {
        return None;
    }
    let mut u = vec![volumes[0][0]];
    for e in 1..volumes[0].len() {
        let outermost = volumes.iter().find(|v| {
            let (h, inside) = v[e];
            lights.iter().all(|l| {
                let side = sign(l.eval(&h));
                side == Side::On || side == inside
            })
        });
        match outermost {
            Some(v) => u.push(v[e]),
            None => u.extend(volumes.iter().map(|v| v[e])),
        }
    }
    Some(u)
}

/// The plane through the light edge `l1, l2` and the occluder corner `o`
/// (for two directions, through `o` and parallel to both); `None` where
/// they are collinear (or parallel).
fn edge_corner_plane(l1: Light, l2: Light, o: GridPoint) -> Option<Plane> {
    match (l1, l2) {
        (Light::Point(a), Light::Point(b)) => Plane::through(a, b, o).ok(),
        (Light::Directional(a), Light::Directional(b)) => {
            plane_along(cross(a.map(i64::from), b.map(i64::from)), o)
        }
        _ => None,
    }
}

/// A piece of a face being cut for one light, and its state: inside some
/// penumbra volume (not lit), the light corners hidden from it (or behind
/// the face), inside one occluder's umbra.
struct Piece<K> {
    polygon: Polygon,
    /// The smallest box of integers holding it.
    bbox: Box3,
    label: K,
    not_lit: bool,
    hidden: u64,
    umbra: bool,
    /// Its vertex keys ([`vertex_keys`]), once a merge has made them.
    keys: Option<Vec<[u64; 3]>>,
}

/// How [`AreaLight::cut`] cuts one piece: by these occluders' regions,
/// with `all` the bits of every light corner, and whether the corners each
/// piece sees are known.
struct Cutting<'a, 'r> {
    regions: &'a [(&'r Regions, Reach)],
    /// Where a face has many pieces and occluders: which occluders may
    /// meet the pieces within a box.
    index: Option<ReachIndex>,
    all: u64,
    known: bool,
}

impl Cutting<'_, '_> {
    /// Every piece of `active` cut as its family ([`Cutting::family`]),
    /// the families one after the other in `active`'s order: in parallel
    /// where there are several (the same for every thread count), those
    /// with the most occluders near them first where the index tells, so
    /// that no large one is left to one thread at the end.
    fn families<K: Copy + PartialEq + Send + Sync>(&self, active: Vec<Piece<K>>) -> Vec<Piece<K>> {
        match (active.len(), &self.index) {
            (0 | 1, _) => active.into_iter().flat_map(|p| self.family(p)).collect(),
            (_, None) => active
                .into_par_iter()
                .flat_map_iter(|p| self.family(p))
                .collect::<Vec<_>>(),
            (_, Some(index)) => {
                // (each family's near occluders found once: they order
                // the families, then the family is cut by them)
                let mut jobs: Vec<(Vec<u32>, usize, Piece<K>)> = (active.into_iter().enumerate())
                    .map(|(i, p)| (index.near(&p.bbox), i, p))
                    .collect();
                jobs.sort_by_key(|(near, i, _)| (std::cmp::Reverse(near.len()), *i));
                // one a task; then back in their order
                let mut done: Vec<(usize, Vec<Piece<K>>)> = jobs
                    .into_par_iter()
                    .with_max_len(1)
                    .map(|(near, i, p)| (i, self.family_among(p, Some(&near))))
                    .collect();
                done.sort_unstable_by_key(|&(i, _)| i);
                done.into_iter().flat_map(|(_, f)| f).collect()
            }
        }
    }

    /// `first` cut by every occluder in turn, its parts alike after an
    /// occluder merged again as they pile up (so later occluders meet few).
    fn family<K: Copy + PartialEq + Send + Sync>(&self, first: Piece<K>) -> Vec<Piece<K>> {
        let near = self.index.as_ref().map(|index| index.near(&first.bbox));
        self.family_among(first, near.as_deref())
    }

    /// [`Cutting::family`], with the index's answer for `first`'s box
    /// (`near`) where there is an index.
    fn family_among<K: Copy + PartialEq + Send + Sync>(
        &self,
        first: Piece<K>,
        near: Option<&[u32]>,
    ) -> Vec<Piece<K>> {
        let (all, known) = (self.all, self.known);
        let scan = |p: &Piece<K>| scan_of(p, known && p.hidden == all);
        // every part of `first` lies in its box: the occluders whose boxes
        // miss it are passed over (in order: the parts are the same)
        let picked: Vec<(&Regions, Reach)>;
        let regions = match near {
            Some(near) => {
                picked = near.iter().map(|&i| self.regions[i as usize]).collect();
                &picked[..]
            }
            None => self.regions,
        };
        let mut pieces = vec![first];
        // beside the pieces, in step, what an occluder's boxes are tested
        // against: a face's pieces times its occluders are the most
        // pairs, and most are apart
        let mut scans = Scans::new(pieces.iter().map(scan));
        let mut merged = 0;
        for &(r, reach) in regions {
            // pieces this occluder leaves as they are stay in place; the
            // others are cut and their parts appended
            let mut parts = Vec::new();
            let mut i = 0;
            while i < pieces.len() {
                // a run of pieces none of which meets the occluder's boxes
                // is passed over whole
                if let Some(next) = scans.apart_until(i, &reach) {
                    i = next;
                    continue;
                }
                // a piece that hides every corner can only enter the umbra
                if !scans.items[i].near(&reach)
                    || match known {
                        true => untouched_known(r, &pieces[i], all),
                        false => untouched(r, &pieces[i]),
                    }
                {
                    i += 1;
                    continue;
                }
                scans.swap_remove(i);
                let piece = pieces.swap_remove(i);
                match known {
                    true => cut_piece_known(r, piece, all, &mut parts),
                    false => cut_piece(r, piece, all, &mut parts),
                }
            }
            parts.iter().for_each(|p| scans.push(scan(p)));
            pieces.append(&mut parts);
            if pieces.len() > 16 && pieces.len() > 2 * merged {
                pieces = merge_pieces(pieces, false);
                scans = Scans::new(pieces.iter().map(scan));
                merged = pieces.len();
            }
        }
        pieces
    }
}

/// A piece's [`Scan`]: its box, and which of an occluder's boxes it must
/// meet to be cut (a piece in an umbra is never cut again; one that
/// already hides every corner is cut only by an occluder's umbra).
fn scan_of<K>(p: &Piece<K>, deep: bool) -> Scan {
    Scan {
        bbox: p.bbox,
        kind: match (p.umbra, deep) {
            (true, _) => Near::Never,
            (false, true) => Near::Umbra,
            (false, false) => Near::Penumbra,
        },
    }
}

impl<K> Piece<K> {
    fn new(polygon: Polygon, label: K, hidden: u64, not_lit: bool) -> Piece<K> {
        Piece {
            bbox: polygon_box(&polygon),
            polygon,
            label,
            not_lit,
            hidden,
            umbra: false,
            keys: None,
        }
    }

    /// A maker of parts of this piece, in its state.
    fn parts(&self) -> impl Fn(Polygon) -> Piece<K> + use<K>
    where
        K: Copy,
    {
        let (label, hidden, not_lit, umbra) = (self.label, self.hidden, self.not_lit, self.umbra);
        move |polygon| Piece {
            umbra,
            ..Piece::new(polygon, label, hidden, not_lit)
        }
    }
}

/// The light corners in occluder `r`'s plane (from which it casts no
/// shadow volume).
fn flat_corners(r: &Regions) -> u64 {
    r.from_corner
        .iter()
        .enumerate()
        .fold(0, |m, (i, v)| m | u64::from(v.is_none()) << i)
}

/// Whether a piece lies wholly outside one of the half-spaces `hs`: its
/// box first (exact integers, cheap), then its corners.
fn outside<K>(piece: &Piece<K>, hs: &HalfSpaces) -> bool {
    hs.iter().any(|(h, s)| box_outside(&piece.bbox, h, *s))
        || hs
            .iter()
            .any(|(h, s)| wholly_outside(piece.polygon.classify(h), *s))
}

/// A piece cut into more cells than this by the corners' trees has them
/// made into pieces in parallel ([`AreaLight::cut`]). Higher than
/// [`crate::schedule::PARALLEL_CELLS`]: a cell becomes a piece for the
/// price of its box, and at 256 the area light took 1.04x the time.
const PARALLEL_PIECES: usize = 1024;

/// Whether box `b` lies in the closed half-space opposite `inside` of
/// `h`: the extreme value of `n · x + d` over its corners, in `i128`
/// (`false` where that would overflow).
fn box_outside(b: &Box3, h: &Plane, inside: Side) -> bool {
    let n = h.normal();
    let toward = match inside {
        Side::Front => 1,
        Side::Back => -1,
        Side::On => return false,
    };
    // the corner furthest into the inside
    let mut v = Some(h.offset());
    for k in 0..3 {
        let c = if (n[k] >= 0) == (toward > 0) {
            b[k][1]
        } else {
            b[k][0]
        };
        v = v.and_then(|v| v.checked_add(i128::from(n[k]).checked_mul(i128::from(c))?));
    }
    v.is_some_and(|v| v * toward <= 0)
}

/// [`untouched`] for pieces whose seen corners are known: a piece that
/// hides every corner can only become umbra, one that sees every corner
/// only penumbra, and one that sees some corners and hides others is
/// penumbra already (but for a corner in the occluder's plane, which the
/// occluder then hides where it hides part of the light).
fn untouched_known<K>(r: &Regions, piece: &Piece<K>, all: u64) -> bool {
    if piece.umbra {
        return true;
    }
    if piece.hidden == all {
        return r.umbra.as_ref().is_none_or(|u| outside(piece, u));
    }
    if !piece.not_lit || flat_corners(r) & !piece.hidden != 0 {
        return outside(piece, &r.penumbra);
    }
    true
}

/// [`cut_piece`] for pieces whose seen corners are known (see
/// [`untouched_known`]).
fn cut_piece_known<K: Copy>(r: &Regions, piece: Piece<K>, all: u64, next: &mut Vec<Piece<K>>) {
    let (volume, inside) = match (&r.umbra, piece.hidden == all) {
        (Some(u), true) => (u, (all, true)),
        (None, true) => {
            next.push(piece);
            return;
        }
        (_, false) => (&r.penumbra, (piece.hidden | flat_corners(r), false)),
    };
    let mut outside = Vec::new();
    let within = subtract(volume, piece.polygon, &mut outside);
    next.extend(
        outside
            .into_iter()
            .map(|polygon| Piece::new(polygon, piece.label, piece.hidden, piece.not_lit)),
    );
    next.extend(within.map(|polygon| Piece {
        umbra: inside.1,
        ..Piece::new(polygon, piece.label, inside.0, true)
    }));
}

/// Whether occluder regions `r` leave `piece` as it is ([`cut_piece`]
/// would give it back whole): it is umbra already, or it lies wholly
/// outside every volume that could change its state.
fn untouched<K>(r: &Regions, piece: &Piece<K>) -> bool {
    let outside = |hs: &HalfSpaces| {
        hs.iter()
            .any(|(h, s)| wholly_outside(piece.polygon.classify(h), *s))
    };
    if piece.umbra {
        return true;
    }
    if !piece.not_lit || r.from_corner.iter().any(Option::is_none) {
        return outside(&r.penumbra);
    }
    r.umbra.as_ref().is_none_or(outside)
        && r.from_corner
            .iter()
            .enumerate()
            .filter(|(i, _)| piece.hidden >> i & 1 == 0)
            .all(|(_, hs)| hs.as_ref().is_none_or(outside))
}

/// `piece` cut by occluder regions `r` (`all`: the bits of every light
/// corner), the parts pushed onto `next`.
fn cut_piece<K: Copy>(r: &Regions, piece: Piece<K>, all: u64, next: &mut Vec<Piece<K>>) {
    if piece.umbra {
        next.push(piece);
        return;
    }
    let part = piece.parts();
    if piece.not_lit && r.from_corner.iter().all(Option::is_some) {
        // not lit already: only this occluder's umbra and the corners not
        // hidden yet can change its class
        let mut parts = Vec::new();
        let umbra = match &r.umbra {
            Some(u) => subtract(u, piece.polygon, &mut parts),
            None => {
                parts.push(piece.polygon);
                None
            }
        };
        next.extend(umbra.map(|polygon| Piece {
            hidden: all,
            umbra: true,
            ..part(polygon)
        }));
        let mut parts: Vec<(Polygon, u64)> = parts.into_iter().map(|p| (p, 0)).collect();
        for (i, hs) in r.from_corner.iter().enumerate() {
            if let Some(hs) = hs.as_ref().filter(|_| piece.hidden >> i & 1 == 0) {
                parts = hide_corner(hs, i, parts);
            }
        }
        next.extend(parts.into_iter().map(|(polygon, m)| Piece {
            hidden: piece.hidden | m,
            ..part(polygon)
        }));
        return;
    }
    let mut outside = Vec::new();
    let inside = subtract(&r.penumbra, piece.polygon, &mut outside);
    next.extend(outside.into_iter().map(&part));
    let Some(inside) = inside else {
        return;
    };
    // inside the penumbra volume: cut by each corner's shadow volume,
    // noting the corners it hides (a corner in the occluder's plane may be
    // hidden but for itself: not seen)
    let mut parts = vec![(inside, 0u64)];
    for (i, volume) in r.from_corner.iter().enumerate() {
        let Some(hs) = volume else {
            parts.iter_mut().for_each(|(_, m)| *m |= 1 << i);
            continue;
        };
        parts = hide_corner(hs, i, parts);
    }
    let whole = r.from_corner.iter().all(Option::is_some);
    next.extend(parts.into_iter().map(|(polygon, m)| Piece {
        umbra: whole && m == all,
        ..Piece::new(polygon, piece.label, piece.hidden | m, true)
    }));
}

/// Pieces of equal label and state merged where their union is convex
/// (their keys kept; a merged piece's box is its parts' boxes' union);
/// with `parts`, many in parts in parallel ([`merge_keyed_parts`]: the
/// same pieces).
fn merge_pieces<K: Copy + PartialEq + Send + Sync>(
    pieces: Vec<Piece<K>>,
    parts: bool,
) -> Vec<Piece<K>> {
    let items = pieces
        .into_iter()
        .map(|p| Keyed {
            keys: p.keys.unwrap_or_else(|| vertex_keys(&p.polygon)),
            polygon: p.polygon,
            label: (p.label, p.not_lit, p.hidden, p.umbra),
            extra: p.bbox,
        })
        .collect();
    let join = |a: &Box3, b: &Box3| crate::boxes::union(*a, *b);
    match parts {
        true => merge_keyed_parts(items, join),
        false => merge_keyed(items, join),
    }
    .into_iter()
    .map(|m| {
        let (label, not_lit, hidden, umbra) = m.label;
        Piece {
            polygon: m.polygon,
            bbox: m.extra,
            label,
            not_lit,
            hidden,
            umbra,
            keys: Some(m.keys),
        }
    })
    .collect()
}

/// `parts` cut by the shadow volume `hs` of light corner `i`, the parts
/// inside it marked with bit `i`.
fn hide_corner(hs: &[(Plane, Side)], i: usize, parts: Vec<(Polygon, u64)>) -> Vec<(Polygon, u64)> {
    let mut cut = Vec::with_capacity(parts.len());
    for (p, m) in parts {
        let mut out = Vec::new();
        let within = subtract(hs, p, &mut out);
        cut.extend(out.into_iter().map(|q| (q, m)));
        cut.extend(within.map(|q| (q, m | 1 << i)));
    }
    cut
}

/// The occluder's side of `h` if `h` separates the light's corners `lv`
/// from the occluder's `ov` (each on one closed side, opposite, neither
/// wholly in `h`).
fn separating(h: &Plane, lv: &[Light], ov: &[GridPoint]) -> Option<Side> {
    let side_of = |sides: &mut dyn Iterator<Item = Side>| {
        let (mut front, mut back) = (false, false);
        for side in sides {
            match side {
                Side::Front => front = true,
                Side::Back => back = true,
                Side::On => {}
            }
        }
        match (front, back) {
            (true, false) => Some(Side::Front),
            (false, true) => Some(Side::Back),
            _ => None,
        }
    };
    let light = &mut lv.iter().map(|l| sign(l.eval(h)));
    let occluder = &mut ov.iter().map(|&p| h.classify_grid(p));
    match (side_of(light)?, side_of(occluder)?) {
        (l, o) if l != o => Some(o),
        _ => None,
    }
}

/// The convex parts of a polygon with the light corners each sees (bit
/// `i`: corner `i`), where that is known.
pub(crate) type SeenCorners<'a> = dyn FnMut(&Polygon, bool) -> Option<Vec<(Polygon, u64)>> + 'a;

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether grid point `x` lies in the closed intersection of `hs`.
    fn within(hs: &HalfSpaces, x: GridPoint) -> bool {
        hs.iter().all(|(h, s)| {
            let side = h.classify_grid(x);
            side == *s || side == Side::On
        })
    }

    /// A ground cut in a row of squares under many small triangles,
    /// crowded towards one end: the families, scheduled by how many
    /// occluders lie near them, come back as cut one after the other, in
    /// their order.
    #[test]
    fn families_come_back_in_their_order_whatever_runs_first() {
        let light = AreaLight::new(&[[-8, -8, 90], [-8, 8, 90], [8, 8, 90], [8, -8, 90]]).unwrap();
        let mut occluders = Vec::new();
        for i in 0..200 {
            // more of them over the row's far end
            let x = i * i / 200;
            let y = i * 7 % 11 - 5;
            let tri = [[x, y, 30], [x + 3, y, 30], [x, y + 3, 31]];
            occluders.push(Occluder::new(&tri).unwrap());
        }
        let regions: Vec<(Regions, Reach)> = (occluders.iter())
            .filter_map(|o| {
                let b = grid_box(o.corners());
                let wide: Box3 = [
                    [b[0][0] - 12, b[0][1] + 12],
                    [b[1][0] - 12, b[1][1] + 12],
                    [-1, 1],
                ];
                Some((light.regions(o)?, [wide, wide]))
            })
            .collect();
        assert!(regions.len() > 128);
        let refs: Vec<(&Regions, Reach)> = regions.iter().map(|(r, b)| (r, *b)).collect();
        let squares: Vec<Polygon> = (0..12)
            .map(|i| {
                let x = -20 + 20 * i;
                let q = [[x, -20, 0], [x + 20, -20, 0], [x + 20, 20, 0], [x, 20, 0]];
                Polygon::from_grid_points(&q, 0).unwrap()
            })
            .collect();
        let ground = grid_box(&[[-20, -20, 0], [220, 20, 0]]);
        let how = Cutting {
            regions: &refs,
            index: Some(ReachIndex::new(ground, refs.iter().map(|(_, r)| r))),
            all: 0b1111,
            known: false,
        };
        let pieces = || squares.iter().map(|q| Piece::new(q.clone(), (), 0, false));
        let want: Vec<Piece<()>> = pieces().flat_map(|p| how.family(p)).collect();
        let got = how.families(pieces().collect());
        assert!(want.len() > 2 * squares.len(), "{} pieces", want.len());
        assert_eq!(got.len(), want.len());
        for (g, w) in got.iter().zip(&want) {
            assert_eq!(g.polygon.vertices_f64(), w.polygon.vertices_f64());
            assert_eq!(
                (g.not_lit, g.hidden, g.umbra),
                (w.not_lit, w.hidden, w.umbra)
            );
        }
    }

    /// The occluders that cut by their umbra only (inner occluders: an
    /// empty penumbra box) cut a face's pieces before the others, wherever
    /// they stand in the list: under a large one, the small umbrae of the
    /// others meet nothing left to cut, and the pieces are those of the
    /// list with it first.
    #[test]
    fn umbra_only_occluders_cut_first() {
        let light = AreaLight::new(&[[-8, -8, 90], [-8, 8, 90], [8, 8, 90], [8, -8, 90]]).unwrap();
        let ground =
            Occluder::new(&[[-60, -60, 0], [60, -60, 0], [60, 60, 0], [-60, 60, 0]]).unwrap();
        let wide = grid_box(&[[-100, -100, -1], [100, 100, 100]]);
        // sixteen squares each with an umbra of its own on the ground
        let mut occluders: Vec<(Regions, Reach)> = Vec::new();
        for i in 0..4 {
            for j in 0..4 {
                let (x, y) = (-18 + 9 * i, -18 + 9 * j);
                let q = [
                    [x, y, 10],
                    [x + 8, y, 10],
                    [x + 8, y + 8, 10],
                    [x, y + 8, 10],
                ];
                let o = Occluder::new(&q).unwrap();
                occluders.push((light.regions(&o).unwrap(), [wide, wide]));
            }
        }
        let core =
            Occluder::new(&[[-40, -40, 30], [40, -40, 30], [40, 40, 30], [-40, 40, 30]]).unwrap();
        let core = (light.regions(&core).unwrap(), [EMPTY, wide]);
        let cut = |list: Vec<&(Regions, Reach)>| {
            // (the corners' trees say the whole ground hides every corner)
            let mut hidden = |p: &Polygon, _: bool| Some(vec![(p.clone(), 0u64)]);
            let pieces = vec![(ground.to_polygon(), ())];
            let list = list.into_iter().map(|(r, b)| (r, *b));
            light.cut(&ground, pieces, list, Some(&mut hidden))
        };
        let last = cut(occluders.iter().chain([&core]).collect());
        let first = cut([&core].into_iter().chain(occluders.iter()).collect());
        assert_eq!(last.len(), first.len());
        for (a, b) in last.iter().zip(&first) {
            assert_eq!(a.0.vertices_f64(), b.0.vertices_f64());
            assert_eq!(a.2, b.2);
        }
        // the core's umbra whole, the rest of the ground in a few pieces
        let umbra = last.iter().filter(|p| p.2 == AreaClass::Umbra).count();
        assert!(umbra < occluders.len(), "{umbra} umbra pieces");
        assert!(umbra >= 1 && last.iter().any(|p| p.2 == AreaClass::Undecided));
    }

    /// The umbra volume with one plane per occluder edge holds exactly
    /// the points in every corner's shadow volume: random triangles and
    /// quads under a square light and a sun disc, at random grid points.
    #[test]
    fn the_umbra_keeps_one_plane_per_edge_and_the_same_points() {
        let mut state = 0x0dd_ba11_u64;
        let mut draw = |n: i32| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % (2 * n as u64 + 1)) as i32 - n
        };
        let square = AreaLight::new(&[[-8, -8, 90], [-8, 8, 90], [8, 8, 90], [8, -8, 90]]).unwrap();
        let disc = AreaLight::sun_disc(DVec3::new(0.2, -0.1, 1.0), 0.05).unwrap();
        let (mut kept, mut inside) = (0, 0);
        for light in [square, disc] {
            for _ in 0..60 {
                let z = 30 + draw(10);
                let c = [draw(20), draw(20)];
                let tri: Vec<GridPoint> = (0..3)
                    .map(|_| [c[0] + draw(15), c[1] + draw(15), z + draw(3)])
                    .collect();
                let Ok(o) = Occluder::new(&tri) else { continue };
                let Some(r) = light.regions(&o) else { continue };
                let Some(umbra) = &r.umbra else { continue };
                let every: Vec<&HalfSpaces> = r.from_corner.iter().flatten().collect();
                assert_eq!(umbra.len(), 1 + o.corners().len());
                kept += 1;
                for _ in 0..400 {
                    let x = [c[0] + draw(30), c[1] + draw(30), draw(40)];
                    let want = every.iter().all(|hs| within(hs, x));
                    assert_eq!(within(umbra, x), want, "{x:?} under {tri:?}");
                    inside += usize::from(want);
                }
            }
        }
        assert!(
            kept > 20 && inside > 100,
            "{kept} occluders with an umbra, {inside} points in one"
        );
    }
}
