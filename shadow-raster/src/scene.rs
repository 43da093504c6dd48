//! The scene as the rasterizer sees it: convex polygons ("prims") in
//! input units with their exact support planes, and the lights.

use bsp_core::{Grid, Plane, Polygon, Side};
use glam::DVec3;
use svbsp::{Light, PlacedLight, SoftLight, SoftShape};

use crate::RasterError;

/// A light in input units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum RasterLight {
    /// A point light at this position.
    Point(DVec3),
    /// A light at infinity: the unit direction from the scene toward it.
    Sun(DVec3),
}

impl RasterLight {
    /// The unit direction from `p` toward the light.
    #[inline]
    pub(crate) fn toward(&self, p: DVec3) -> DVec3 {
        match *self {
            RasterLight::Point(l) => (l - p).normalize_or_zero(),
            RasterLight::Sun(d) => d,
        }
    }
}

/// One light as the image-space methods use it: its exact form (on the
/// scene's grid) and its form in input units (a sun's direction
/// normalized once more), and for a light with extent the light itself.
/// Made from the [`PlacedLight`]s or [`SoftLight`]s the public functions
/// take.
#[derive(Clone, Debug)]
pub(crate) struct SceneLight {
    /// On the grid, as the exact shadows use it; for a light with extent,
    /// its centre (the grid point nearest its corners' mean, or the
    /// quantized direction of a disc's centre), which the methods that
    /// take lights as points use.
    pub(crate) exact: Light,
    /// In input units, as the image-space methods use it: the centre of a
    /// light with extent.
    pub(crate) world: RasterLight,
    /// An area light or a sun disc; `None` for a point or a sun.
    pub(crate) extent: Option<SoftLight>,
}

impl SceneLight {
    /// From a light placed on the scene's grid by [`svbsp::place_lights`].
    pub(crate) fn from_placed(l: &PlacedLight) -> SceneLight {
        let world = match l.light {
            Light::Point(_) => RasterLight::Point(l.world),
            Light::Directional(_) => RasterLight::Sun(l.world.normalize()),
        };
        SceneLight {
            exact: l.light,
            world,
            extent: None,
        }
    }

    /// From a light of a soft-shadow run ([`svbsp::place_soft_lights`]):
    /// a point or a sun as [`SceneLight::from_placed`] makes it, a light
    /// with extent with its centre.
    pub(crate) fn from_soft(l: &SoftLight) -> Result<SceneLight, RasterError> {
        let corners = l.light.corners();
        let (exact, world) = match &l.shape {
            SoftShape::Point(p) => (corners[0], RasterLight::Point(*p)),
            SoftShape::Sun(d) => (corners[0], RasterLight::Sun(d.normalize())),
            SoftShape::Area(world) => {
                let mut sum = [0i64; 3];
                for c in corners {
                    if let Light::Point(g) = c {
                        (0..3).for_each(|k| sum[k] += i64::from(g[k]));
                    }
                }
                let n = corners.len() as f64;
                let g = sum.map(|s| (s as f64 / n).round() as i32);
                let centre = world.iter().sum::<DVec3>() / world.len() as f64;
                (Light::Point(g), RasterLight::Point(centre))
            }
            SoftShape::SunDisc { direction, .. } => {
                let q = svbsp::quantize_direction(*direction)
                    .ok_or_else(|| RasterError::Option(format!("{}: no direction", l.shape)))?;
                (
                    Light::Directional(q),
                    RasterLight::Sun(direction.normalize()),
                )
            }
        };
        let extended = matches!(l.shape, SoftShape::Area(_) | SoftShape::SunDisc { .. });
        Ok(SceneLight {
            exact,
            world,
            extent: extended.then(|| l.clone()),
        })
    }

    /// An area light's centre and the unit normal of the side it shines
    /// on (input units); `None` for other lights.
    pub(crate) fn emitter(&self) -> Option<(DVec3, DVec3)> {
        let Some(SoftShape::Area(c)) = self.extent.as_ref().map(|l| &l.shape) else {
            return None;
        };
        let normal = (1..c.len() - 1)
            .map(|i| (c[i] - c[0]).cross(c[i + 1] - c[0]))
            .sum::<DVec3>();
        let normal = shadow_scene::unit_or_zero(normal);
        Some((c.iter().sum::<DVec3>() / c.len() as f64, normal))
    }

    /// How far the light spreads, for the methods that blur by it
    /// (PCSS): an area light's largest distance from its centre to a
    /// corner (input units), the tangent of a disc's angular radius, 0
    /// for a point or a sun.
    pub(crate) fn spread(&self) -> f64 {
        match self.extent.as_ref().map(|l| &l.shape) {
            Some(SoftShape::Area(c)) => {
                let centre = c.iter().sum::<DVec3>() / c.len() as f64;
                c.iter().map(|&p| p.distance(centre)).fold(0.0, f64::max)
            }
            Some(SoftShape::SunDisc { radius_deg, .. }) => radius_deg.to_radians().tan(),
            _ => 0.0,
        }
    }
}

/// The polygons of a scene ready to be drawn: each imported convex
/// polygon ("prim") with its vertices in input units, its face, its exact
/// support plane and that plane in input units (unit normal).
///
/// Built from the exact polygons of [`bsp_core::import_faces`] (or any
/// polygons on the grid, such as a frame of a moving scene); the exact
/// shadows of those polygons ([`svbsp::LightVolumes`]) are drawn by
/// [`crate::render_fragments`].
#[derive(Clone, Debug)]
pub struct RasterScene {
    pub(crate) grid: Grid,
    pub(crate) polys: Vec<Polygon>,
    /// Prim `i`'s vertices: `pts[start[i]..start[i + 1]]`.
    pub(crate) start: Vec<u32>,
    pub(crate) pts: Vec<DVec3>,
    /// Prim `i`'s vertices as indices into `verts`, the distinct points
    /// (bit for bit) of `pts`: `corner[start[i]..start[i + 1]]`.
    pub(crate) corner: Vec<u32>,
    pub(crate) verts: Vec<DVec3>,
    pub(crate) face: Vec<u32>,
    /// Each prim's exact support plane (kept apart from the polygons for
    /// a compact per-frame pass).
    pub(crate) support: Vec<Plane>,
    /// Unit normal and offset in input units: `n · p + d = 0`.
    pub(crate) plane: Vec<(DVec3, f64)>,
    pub(crate) lo: DVec3,
    pub(crate) hi: DVec3,
}

impl RasterScene {
    /// The scene of `polys` (imported on `grid`, each tagged with its
    /// face).
    pub fn new(grid: &Grid, polys: Vec<Polygon>) -> Result<RasterScene, RasterError> {
        if polys.is_empty() {
            return Err(RasterError::EmptyScene);
        }
        let mut start = Vec::with_capacity(polys.len() + 1);
        let mut pts = Vec::with_capacity(polys.len() * 4);
        let mut face = Vec::with_capacity(polys.len());
        let mut plane = Vec::with_capacity(polys.len());
        let mut support = Vec::with_capacity(polys.len());
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        start.push(0);
        for p in &polys {
            for g in p.vertices_f64() {
                let w = grid.to_world(g);
                lo = lo.min(w);
                hi = hi.max(w);
                pts.push(w);
            }
            start.push(pts.len() as u32);
            face.push(p.tag());
            support.push(*p.support());
            plane.push(world_plane(grid, p.support()));
        }
        if !(lo.is_finite() && hi.is_finite()) {
            return Err(RasterError::NonFiniteVertex);
        }
        let (corner, verts) = shared_vertices(&pts);
        Ok(RasterScene {
            grid: *grid,
            polys,
            start,
            pts,
            corner,
            verts,
            face,
            support,
            plane,
            lo,
            hi,
        })
    }

    /// Number of prims.
    pub fn len(&self) -> usize {
        self.face.len()
    }

    /// `true` if there is nothing to draw.
    pub fn is_empty(&self) -> bool {
        self.face.is_empty()
    }

    /// The grid of the exact polygons.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The exact polygons.
    pub fn polygons(&self) -> &[Polygon] {
        &self.polys
    }

    /// The bounding box of every vertex, in input units.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        (self.lo, self.hi)
    }

    /// Prim `i`'s vertices in input units.
    #[inline]
    pub(crate) fn prim(&self, i: usize) -> &[DVec3] {
        &self.pts[self.start[i] as usize..self.start[i + 1] as usize]
    }

    /// Length of the bounding box's diagonal (at least 1e-300).
    pub(crate) fn diagonal(&self) -> f64 {
        (self.hi - self.lo).length().max(1e-300)
    }

    /// The side of prim `i`'s exact plane the point `eye` (input units)
    /// is on: the eye is snapped to the grid for an exact answer.
    pub(crate) fn eye_side(
        &self,
        i: usize,
        eye: Option<bsp_core::ViewPoint>,
        world: DVec3,
    ) -> Side {
        match eye {
            Some(vp) => self.support[i].classify_viewpoint(vp),
            None => {
                let (n, d) = self.plane[i];
                let s = n.dot(world) + d;
                if s > 0.0 {
                    Side::Front
                } else if s < 0.0 {
                    Side::Back
                } else {
                    Side::On
                }
            }
        }
    }
}

/// The distinct points of `pts`, bit for bit, and each point's index
/// among them (numbered in the order of their first use).
fn shared_vertices(pts: &[DVec3]) -> (Vec<u32>, Vec<DVec3>) {
    use rayon::prelude::*;
    let bits = |p: DVec3| p.to_array().map(f64::to_bits);
    let mut order: Vec<u32> = (0..pts.len() as u32).collect();
    order.par_sort_unstable_by_key(|&k| (bits(pts[k as usize]), k));
    // each point's first use, through its run of equal points
    let mut first = vec![0u32; pts.len()];
    let mut k = 0;
    while k < order.len() {
        let key = bits(pts[order[k] as usize]);
        let mut e = k;
        while e < order.len() && bits(pts[order[e] as usize]) == key {
            first[order[e] as usize] = order[k];
            e += 1;
        }
        k = e;
    }
    let (mut corner, mut verts) = (vec![0u32; pts.len()], Vec::new());
    for (c, &f) in first.iter().enumerate() {
        corner[c] = if f as usize == c {
            verts.push(pts[c]);
            (verts.len() - 1) as u32
        } else {
            corner[f as usize]
        };
    }
    (corner, verts)
}

/// The bits of a point's coordinates (`-0.0` read as `0.0`): equal points,
/// equal keys. Vertices shared by prims are equal bit for bit (each is one
/// exact vertex rounded once).
#[inline]
pub(crate) fn point_key(p: DVec3) -> [u64; 3] {
    p.to_array().map(|c| (c + 0.0).to_bits())
}

/// The connected components of `n` items joined by `pairs`, numbered in
/// the order of their first item: each item's component, and the count.
pub(crate) fn components(
    n: usize,
    pairs: impl IntoIterator<Item = (usize, usize)>,
) -> (Vec<u32>, usize) {
    let mut sets = bsp_core::internals::UnionFind::new(n);
    for (a, b) in pairs {
        sets.union(a as u32, b as u32);
    }
    sets.numbered()
}

/// An edge by its two endpoints' keys.
pub(crate) type EdgeKey = ([u64; 3], [u64; 3]);

/// A plane of the grid in input units, with a unit normal. Opposite
/// planes give exactly opposite results.
pub(crate) fn world_plane(grid: &Grid, p: &Plane) -> (DVec3, f64) {
    let [a, b, c, d] = p.approx();
    let n = DVec3::new(a, b, c);
    // n · g + d = 0 with g = (w - origin) * scale
    // n · (w − origin) · scale + d = 0, divided by scale and |n|
    let len = n.length();
    let dw = d / grid.scale() - n.dot(grid.origin());
    (n / len, dw / len)
}

/// The side of each prim's exact plane the point `eye` (input units) is
/// on, into `out`.
pub(crate) fn eye_sides(scene: &RasterScene, eye: DVec3, out: &mut Vec<Side>) {
    use rayon::prelude::*;
    let vp = scene.grid.snap_viewpoint(eye).ok();
    out.clear();
    out.par_extend(
        (0..scene.len())
            .into_par_iter()
            .with_min_len(4096)
            .map(|i| scene.eye_side(i, vp, eye)),
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shared_vertices_are_the_distinct_points() {
        let mut rng = bsp_core::internals::SplitMix(0x5_4a7e);
        let pool: Vec<DVec3> = (0..50)
            .map(|_| DVec3::new(rng.below(4) as f64, rng.below(3) as f64 - 1.0, 0.5))
            .chain([DVec3::new(0.0, 0.0, 0.5), DVec3::new(-0.0, 0.0, 0.5)])
            .collect();
        let pts: Vec<DVec3> = (0..2000).map(|_| pool[rng.below(pool.len())]).collect();
        let (corner, verts) = shared_vertices(&pts);
        let bits = |p: DVec3| p.to_array().map(f64::to_bits);
        for (c, p) in pts.iter().enumerate() {
            assert_eq!(bits(verts[corner[c] as usize]), bits(*p));
        }
        let mut keys: Vec<_> = verts.iter().map(|&p| bits(p)).collect();
        keys.sort_unstable();
        keys.dedup();
        assert_eq!(keys.len(), verts.len(), "distinct");
        // numbered by first use
        let mut seen = 0;
        for &c in &corner {
            assert!(c as usize <= seen);
            seen = seen.max(c as usize + 1);
        }
    }

    #[test]
    fn world_planes_contain_the_vertices() {
        let grid = Grid::new(DVec3::new(0.5, -1.0, 2.0), 10).unwrap();
        let p = Polygon::from_grid_points(&[[0, 0, 7], [1000, 0, 9], [0, 900, 1]], 3).unwrap();
        let (n, d) = world_plane(&grid, p.support());
        for g in p.vertices_f64() {
            let w = grid.to_world(g);
            assert!((n.dot(w) + d).abs() < 1e-12, "{}", n.dot(w) + d);
        }
        let (nf, df) = world_plane(&grid, &p.support().flip());
        assert_eq!((nf, df), (-n, -d));
    }
}
