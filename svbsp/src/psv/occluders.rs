//! The occluders of one light's tree, prepared in parallel: their grid
//! corners, edge planes, support and cap, in insertion order.

use std::borrow::{Borrow, Cow};

use bsp_core::{GridPoint, Plane, Point, Polygon};
use rayon::prelude::*;

use super::VolumeError;
use crate::light::Light;

/// The occluders that face or back onto the light, nearest first, as
/// flat arrays in chunks of [`OCCLUDER_CHUNK`] occluders (each chunk made
/// on its own thread; joining them into one list took a serial pass over
/// a scene's every plane).
///
/// The edge planes of the occluders turned away from the light are not
/// made where those go down the skeleton whole ([`Occluders::defer`]):
/// most of them are found hidden by their corners alone (on an open scan
/// about 96 % of its far side, half of all its occluders), so their
/// planes are made when asked for ([`Occluders::edges`]), the same planes.
pub(super) struct Occluders {
    light: Light,
    chunks: Vec<OccluderChunk>,
    /// Each occluder's index in the input.
    pub(super) index: Vec<u32>,
    /// Per occluder: it faces the light (else it is turned away).
    pub(super) faces: Vec<bool>,
    /// Those turned away go down the skeleton whole, in their turn (at
    /// most [`LATE_PER_FRONT`] of them per occluder facing the light);
    /// else the skeleton is made of all.
    pub(super) defer: bool,
}

/// At most this many occluders turned away from the light per occluder
/// that faces it, for those turned away to go down the skeleton whole
/// (`psv`'s module docs): a scene turned away from its light (a terrain whose
/// faces point down, lit from above, 2.9 times as long without this)
/// needs them in the skeleton.
pub(super) const LATE_PER_FRONT: usize = 2;

/// Occluders per chunk of [`Occluders`] (a power of two).
const OCCLUDER_CHUNK: usize = 1 << OCCLUDER_CHUNK_BITS;
const OCCLUDER_CHUNK_BITS: u32 = 12;

/// [`OCCLUDER_CHUNK`] consecutive occluders (fewer in the last chunk).
struct OccluderChunk {
    /// Vertices of the chunk's occluder `i`: `verts[start[i]..start[i + 1]]`.
    verts: Vec<GridPoint>,
    /// The shadow plane of each edge (edge `j` from vertex `j` to `j + 1`),
    /// interior behind: also the occluder's edge planes as a polygon.
    /// Occluder `i`'s are `edges[edge_start[i]..edge_start[i + 1]]`, none
    /// for one whose planes are made when asked for.
    edges: Vec<Plane>,
    edge_start: Vec<u32>,
    start: Vec<u32>,
    support: Vec<Plane>,
    cap: Vec<Plane>,
}

impl Occluders {
    pub(super) fn len(&self) -> usize {
        self.index.len()
    }

    /// Occluder `i`'s chunk and its index there.
    #[inline]
    fn at(&self, i: u32) -> (&OccluderChunk, usize) {
        (
            &self.chunks[(i >> OCCLUDER_CHUNK_BITS) as usize],
            i as usize & (OCCLUDER_CHUNK - 1),
        )
    }

    fn range(&self, i: u32) -> (&OccluderChunk, std::ops::Range<usize>) {
        let (c, j) = self.at(i);
        (c, c.start[j] as usize..c.start[j + 1] as usize)
    }

    /// The number of occluder `i`'s corners (and edges).
    pub(super) fn corners(&self, i: u32) -> usize {
        self.range(i).1.len()
    }

    pub(super) fn verts(&self, i: u32) -> &[GridPoint] {
        let (c, r) = self.range(i);
        &c.verts[r]
    }

    /// Occluder `i`'s edge planes, made now for one turned away whose
    /// planes were deferred.
    pub(super) fn edges(&self, i: u32) -> Cow<'_, [Plane]> {
        let (c, j) = self.at(i);
        let r = c.edge_start[j] as usize..c.edge_start[j + 1] as usize;
        if r.is_empty() {
            Cow::Owned(edge_planes(&self.light, self.verts(i), false).collect())
        } else {
            Cow::Borrowed(&c.edges[r])
        }
    }

    pub(super) fn support(&self, i: u32) -> &Plane {
        let (c, j) = self.at(i);
        &c.support[j]
    }

    pub(super) fn cap(&self, i: u32) -> &Plane {
        let (c, j) = self.at(i);
        &c.cap[j]
    }

    /// Prepares every polygon (in parallel) and orders them nearest
    /// first, ties by input order.
    pub(super) fn new<P: Borrow<Polygon> + Sync>(
        light: &Light,
        polys: &[P],
    ) -> Result<Occluders, VolumeError> {
        // the order first: keys of the polygons not edge-on
        let keyed: Vec<Option<(bool, f64, u32)>> = polys
            .par_iter()
            .enumerate()
            .map(|(index, p)| {
                let p = p.borrow();
                if p.vertices().iter().any(|v| matches!(v, Point::Implicit(_))) {
                    return Err(VolumeError::ImplicitOccluder { index });
                }
                let side = light.eval(p.support());
                if side == 0 {
                    return Ok(None);
                }
                Ok(Some((
                    side > 0,
                    sort_key(light, grid_points(p)),
                    index as u32,
                )))
            })
            .collect::<Result<_, _>>()?;
        let mut order: Vec<(bool, f64, u32)> = keyed.into_iter().flatten().collect();
        order.par_sort_unstable_by(|a, b| a.1.total_cmp(&b.1).then(a.2.cmp(&b.2)));
        let fronts = order.iter().filter(|o| o.0).count();
        let defer = order.len() - fronts <= LATE_PER_FRONT * fronts;
        // then the planes, chunk by chunk in parallel
        let chunks: Vec<OccluderChunk> = order
            .par_chunks(OCCLUDER_CHUNK)
            .map(|part| {
                let mut c = OccluderChunk {
                    verts: Vec::with_capacity(part.len() * 3),
                    edges: Vec::with_capacity(part.len() * 3),
                    edge_start: Vec::with_capacity(part.len() + 1),
                    start: Vec::with_capacity(part.len() + 1),
                    support: Vec::with_capacity(part.len()),
                    cap: Vec::with_capacity(part.len()),
                };
                c.start.push(0);
                c.edge_start.push(0);
                // (whether it faces the light, as its key found it)
                for &(facing, _, i) in part {
                    let p = polys[i as usize].borrow();
                    let first = c.verts.len();
                    c.verts.extend(grid_points(p));
                    let support = *p.support();
                    if facing || !defer {
                        c.edges
                            .extend(edge_planes(light, &c.verts[first..], facing));
                    }
                    c.start.push(c.verts.len() as u32);
                    c.edge_start.push(c.edges.len() as u32);
                    c.support.push(support);
                    c.cap.push(if facing { support } else { support.flip() });
                }
                c
            })
            .collect();
        Ok(Occluders {
            light: *light,
            chunks,
            index: order.iter().map(|o| o.2).collect(),
            faces: order.iter().map(|o| o.0).collect(),
            defer,
        })
    }
}

/// The shadow planes of a polygon's edges (edge `j` from `verts[j]` to
/// `verts[j + 1]`), its interior behind each: the plane through the light
/// and the edge, turned by whether the polygon faces the light.
fn edge_planes<'a>(
    light: &'a Light,
    verts: &'a [GridPoint],
    facing: bool,
) -> impl Iterator<Item = Plane> + 'a {
    let k = verts.len();
    (0..k).map(move |j| {
        let e = light
            .edge_plane_facing(verts[j], verts[(j + 1) % k], facing)
            .expect("a light off the plane is off every edge line");
        debug_assert_eq!(
            Some(e),
            light.edge_plane(verts[j], verts[(j + 1) % k], verts[(j + 2) % k])
        );
        e
    })
}

/// The grid vertices of a polygon checked to have no other kind.
fn grid_points(p: &Polygon) -> impl Iterator<Item = GridPoint> + '_ {
    p.vertices().iter().map(|v| match v {
        Point::Grid(g) => *g,
        Point::Implicit(_) => unreachable!("checked"),
    })
}

/// The insertion order's key of a polygon with grid vertices: its
/// distance from the light (for a sun, its position along the direction),
/// nearest first.
fn sort_key(light: &Light, verts: impl Iterator<Item = GridPoint>) -> f64 {
    match light {
        Light::Point(l) => verts
            .map(|v| {
                (0..3)
                    .map(|j| (v[j] as f64 - l[j] as f64).powi(2))
                    .sum::<f64>()
            })
            .fold(f64::INFINITY, f64::min),
        Light::Directional(d) => -verts
            .map(|v| (0..3).map(|j| v[j] as f64 * d[j] as f64).sum::<f64>())
            .fold(f64::NEG_INFINITY, f64::max),
    }
}
