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
//! together hide the light, which this first version does not resolve.

use bsp_core::internals::GridPolygon;
use bsp_core::{FaceDefect, GridPoint, Plane, Polygon, PolygonSide, Side, Split};
use glam::DVec3;

/// A planar convex polygon that emits light on the side its corners turn
/// counter-clockwise about, with corners on the scene's grid.
#[derive(Clone, Debug)]
pub struct AreaLight {
    polygon: GridPolygon,
}

/// Why corners make no area light (or occluder).
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum AreaLightError {
    /// Fewer than three corners.
    TooFewCorners(usize),
    /// The corners are not a planar, strictly convex polygon with area
    /// (collinear, not planar, not convex, turning twice, or out of the
    /// grid); the cause as the kernel found it.
    Shape(FaceDefect),
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
            AreaLightError::Shape(d) => {
                write!(f, "not a planar convex polygon with area: {d}")
            }
        }
    }
}

impl std::error::Error for AreaLightError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            AreaLightError::Shape(d) => Some(d),
            AreaLightError::TooFewCorners(_) => None,
        }
    }
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
        if corners.len() < 3 {
            return Err(AreaLightError::TooFewCorners(corners.len()));
        }
        let polygon = GridPolygon::from_grid_points(corners).map_err(AreaLightError::Shape)?;
        Ok(Occluder { polygon })
    }

    /// Its plane.
    pub fn plane(&self) -> &Plane {
        self.polygon.support()
    }
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
        if corners.len() < 3 {
            return Err(AreaLightError::TooFewCorners(corners.len()));
        }
        let polygon = GridPolygon::from_grid_points(corners).map_err(AreaLightError::Shape)?;
        Ok(AreaLight { polygon })
    }

    /// The corners, in order (without repeated or collinear ones).
    pub fn corners(&self) -> &[GridPoint] {
        self.polygon.vertices()
    }

    /// The light's plane; it emits on the front side.
    pub fn plane(&self) -> &Plane {
        self.polygon.support()
    }

    /// What the grid point `x` sees of the light: `face`, the plane of the
    /// face `x` lies on (light behind it does not arrive), and the
    /// occluders, each a convex polygon on the grid (a face `x` lies on
    /// hides nothing from it, and may be among them).
    ///
    /// ```
    /// use svbsp::{AreaLight, Occluder, Visibility};
    /// let light = AreaLight::new(&[[0, 0, 80], [0, 40, 80], [40, 40, 80], [40, 0, 80]]).unwrap();
    /// // a square half-way up, a quarter of the light's side, seen from
    /// // below its centre: it hides the light's middle quarter
    /// let roof = Occluder::new(&[[15, 15, 40], [25, 15, 40], [25, 25, 40], [15, 25, 40]]).unwrap();
    /// let view = light.view([20, 20, 0], None, &[roof]);
    /// assert_eq!(view.visibility, Visibility::Part);
    /// let area: f64 = view.seen.iter().map(|p| svbsp::polygon_area(&p.vertices_f64()
    ///     .iter().map(|&v| glam::DVec3::from_array(v)).collect::<Vec<_>>())).sum();
    /// assert_eq!(area, 1200.0);
    /// ```
    pub fn view(&self, x: GridPoint, face: Option<&Plane>, occluders: &[Occluder]) -> LightView {
        let nothing = || LightView {
            reachable: Vec::new(),
            seen: Vec::new(),
            visibility: Visibility::None,
        };
        if self.plane().classify_grid(x) != Side::Front {
            return nothing();
        }
        let mut light = self.polygon.to_polygon(0);
        if let Some(face) = face
            && !light.clip(face, Side::Front)
        {
            return nothing();
        }
        let reachable = vec![light];
        let mut seen = reachable.clone();
        let mut hidden = false;
        for o in occluders {
            let Some(cone) = Cone::of(x, &o.polygon) else {
                continue;
            };
            let mut next = Vec::with_capacity(seen.len());
            for piece in seen {
                hidden |= cone.subtract(piece, &mut next);
            }
            seen = next;
            if seen.is_empty() {
                break;
            }
        }
        let visibility = match (seen.is_empty(), hidden) {
            (true, _) => Visibility::None,
            (false, true) => Visibility::Part,
            (false, false) => Visibility::All,
        };
        LightView {
            reachable,
            seen,
            visibility,
        }
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
    /// let view = light.view([20, 20, 0], None, &[]);
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
/// // a huge square right above: the whole hemisphere
/// let big = [[-1e6, -1e6, 1.0], [1e6, -1e6, 1.0], [1e6, 1e6, 1.0], [-1e6, 1e6, 1.0]];
/// assert!((svbsp::form_factor(DVec3::ZERO, DVec3::Z, &big) - 1.0).abs() < 1e-5);
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

/// An occluder's cone from a point: the planes through the point and its
/// edges, each with the side its interior is on, and its own plane with
/// the side away from the point.
struct Cone {
    planes: Vec<(Plane, Side)>,
}

impl Cone {
    /// `None` where `x` lies in the occluder's plane (it hides no area).
    fn of(x: GridPoint, o: &GridPolygon) -> Option<Cone> {
        let far = match o.support().classify_grid(x) {
            Side::Front => Side::Back,
            Side::Back => Side::Front,
            Side::On => return None,
        };
        let v = o.vertices();
        let n = v.len();
        let mut planes = Vec::with_capacity(n + 1);
        planes.push((*o.support(), far));
        for i in 0..n {
            // x is off the occluder's plane: never on a line of its edges
            let plane = Plane::through(x, v[i], v[(i + 1) % n]).ok()?;
            let inside = plane.classify_grid(v[(i + 2) % n]);
            planes.push((plane, inside));
        }
        Some(Cone { planes })
    }

    /// Pushes onto `out` the parts of `piece` outside the cone; returns
    /// whether a part with area lay inside (hidden).
    fn subtract(&self, piece: Polygon, out: &mut Vec<Polygon>) -> bool {
        let mut rest = piece;
        for (plane, inside) in &self.planes {
            let (within, outside) = match rest.split(plane) {
                Split::Spanning { front, back } => match inside {
                    Side::Front => (front, Some(back)),
                    _ => (back, Some(front)),
                },
                Split::Front(p) if *inside == Side::Front => (p, None),
                Split::Back(p) if *inside == Side::Back => (p, None),
                Split::Front(p) | Split::Back(p) | Split::Coplanar { polygon: p, .. } => {
                    out.push(p);
                    return false;
                }
            };
            if let Some(o) = outside {
                out.push(o);
            }
            rest = within;
        }
        true
    }
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
type HalfSpaces = Vec<(Plane, Side)>;

/// An occluder's regions for an area light: its penumbra volume (the
/// points it keeps from seeing all of the light) and, per light corner,
/// its shadow volume from that corner (`None` where the corner lies in
/// its plane and it hides nothing from there).
struct Regions {
    penumbra: HalfSpaces,
    from_corner: Vec<Option<HalfSpaces>>,
}

impl AreaLight {
    /// `face` cut into fragments of one class each (see the module docs),
    /// with every other face of `occluders` as an occluder (`face` may be
    /// among them: it hides nothing from its own points). Adjacent pieces
    /// of one class are merged where their union is convex. Where the
    /// light lies wholly behind the face's plane, the face is umbra
    /// (attached shadow); where it lies partly behind, no point of the
    /// face sees all of it.
    ///
    /// ```
    /// use svbsp::{AreaClass, AreaLight, Occluder};
    /// let light = AreaLight::new(&[[0, 0, 80], [0, 40, 80], [40, 40, 80], [40, 0, 80]]).unwrap();
    /// let ground = Occluder::new(&[[-200, -200, 0], [200, -200, 0], [200, 200, 0], [-200, 200, 0]]).unwrap();
    /// let roof = Occluder::new(&[[0, 0, 40], [40, 0, 40], [40, 40, 40], [0, 40, 40]]).unwrap();
    /// let fragments = light.classify_face(&ground, &[ground.clone(), roof]);
    /// let has = |c| fragments.iter().any(|f| f.class == c);
    /// assert!(has(AreaClass::Lit) && has(AreaClass::Penumbra) && has(AreaClass::Umbra));
    /// assert!(!has(AreaClass::Undecided));
    /// ```
    pub fn classify_face(&self, face: &Occluder, occluders: &[Occluder]) -> Vec<AreaFragment> {
        let fragment = |polygon, class| AreaFragment { polygon, class };
        let whole = face.polygon.to_polygon(0);
        let behind_face: Vec<bool> = self
            .corners()
            .iter()
            .map(|&v| face.plane().classify_grid(v) != Side::Front)
            .collect();
        if behind_face.iter().all(|&b| b) {
            return vec![fragment(whole, AreaClass::Umbra)];
        }
        let partly_behind = behind_face.iter().any(|&b| b);
        // points not strictly in front of the light see none of it
        let mut out = Vec::new();
        let front = match whole.split(self.plane()) {
            Split::Front(p) => p,
            Split::Spanning { front, back } => {
                out.push(fragment(back, AreaClass::Umbra));
                front
            }
            Split::Back(p) | Split::Coplanar { polygon: p, .. } => {
                return vec![fragment(p, AreaClass::Umbra)];
            }
        };
        let regions: Vec<Regions> = occluders
            .iter()
            .filter(|o| o.polygon.vertices() != face.polygon.vertices())
            .filter_map(|o| self.regions(o))
            .filter(|r| {
                let mut probe = front.clone();
                r.penumbra.iter().all(|(h, s)| probe.clip(h, *s))
            })
            .collect();
        let mut pieces = vec![front];
        for r in &regions {
            let planes = r
                .penumbra
                .iter()
                .chain(r.from_corner.iter().flatten().flatten());
            for (h, _) in planes {
                pieces = pieces
                    .into_iter()
                    .flat_map(|p| match p.split(h) {
                        Split::Spanning { front, back } => vec![front, back],
                        Split::Front(p) | Split::Back(p) | Split::Coplanar { polygon: p, .. } => {
                            vec![p]
                        }
                    })
                    .collect();
            }
        }
        let corners = self.corners().len();
        for piece in pieces {
            let within = |hs: &HalfSpaces| {
                hs.iter().all(|(h, s)| match piece.classify(h) {
                    PolygonSide::Front => *s == Side::Front,
                    PolygonSide::Back => *s == Side::Back,
                    _ => false,
                })
            };
            let class = if !regions.iter().any(|r| within(&r.penumbra)) {
                if partly_behind {
                    AreaClass::Penumbra
                } else {
                    AreaClass::Lit
                }
            } else if regions
                .iter()
                .any(|r| r.from_corner.iter().all(|c| c.as_ref().is_some_and(within)))
            {
                AreaClass::Umbra
            } else if (0..corners).all(|i| {
                // a corner in an occluder's plane may be hidden but for
                // itself: not taken as seen
                behind_face[i]
                    || regions.iter().any(|r| match &r.from_corner[i] {
                        Some(hs) => within(hs),
                        None => true,
                    })
            }) {
                AreaClass::Undecided
            } else {
                AreaClass::Penumbra
            };
            out.push(fragment(piece, class));
        }
        merge_alike(out)
    }

    /// The occluder's regions (see [`Regions`]); `None` where it lies in
    /// the light's plane and hides none of it.
    fn regions(&self, o: &Occluder) -> Option<Regions> {
        let (lv, ov) = (self.corners(), o.polygon.vertices());
        let light_sides: Vec<Side> = lv.iter().map(|&v| o.plane().classify_grid(v)).collect();
        if light_sides.iter().all(|&s| s == Side::On) {
            return None;
        }
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
        let candidates = (0..nl).flat_map(|i| {
            (0..no).flat_map(move |j| {
                [
                    (lv[i], ov[j], ov[(j + 1) % no]),
                    (lv[i], lv[(i + 1) % nl], ov[j]),
                ]
            })
        });
        for (a, b, c) in candidates {
            let Ok(h) = Plane::through(a, b, c) else {
                continue;
            };
            if let Some(inside) = separating(&h, lv, ov) {
                penumbra.push((h, inside));
            }
        }
        let from_corner = lv
            .iter()
            .zip(&light_sides)
            .map(|(&l, &side)| {
                let far = match side {
                    Side::Front => Side::Back,
                    Side::Back => Side::Front,
                    Side::On => return None,
                };
                let mut hs = vec![(*o.plane(), far)];
                for j in 0..no {
                    let h = Plane::through(l, ov[j], ov[(j + 1) % no]).ok()?;
                    hs.push((h, h.classify_grid(ov[(j + 2) % no])));
                }
                Some(hs)
            })
            .collect();
        Some(Regions {
            penumbra,
            from_corner,
        })
    }
}

/// The occluder's side of `h` if `h` separates the light's corners `lv`
/// from the occluder's `ov` (each on one closed side, opposite, neither
/// wholly in `h`).
fn separating(h: &Plane, lv: &[GridPoint], ov: &[GridPoint]) -> Option<Side> {
    let side_of = |pts: &[GridPoint]| {
        let (mut front, mut back) = (false, false);
        for &p in pts {
            match h.classify_grid(p) {
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
    match (side_of(lv)?, side_of(ov)?) {
        (l, o) if l != o => Some(o),
        _ => None,
    }
}

/// Merges fragments of one class whose union is convex, until none do.
fn merge_alike(mut fragments: Vec<AreaFragment>) -> Vec<AreaFragment> {
    let mut i = 0;
    while i < fragments.len() {
        let mut j = i + 1;
        let mut merged = false;
        while j < fragments.len() {
            if fragments[j].class == fragments[i].class
                && let Some(m) = fragments[i].polygon.merge(&fragments[j].polygon)
            {
                fragments[i].polygon = m;
                fragments.swap_remove(j);
                merged = true;
            } else {
                j += 1;
            }
        }
        if !merged {
            i += 1;
        }
    }
    fragments
}
