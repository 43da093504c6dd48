//! From meshes to solids: the check, the grid, and the snap.

use bsp_core::internals::GridPolygon;
use bsp_core::par;
use bsp_core::{Grid, ImportReport, check_closed_manifold};
use glam::DVec3;

use crate::solid::SolidFace;
use crate::{CsgError, Solid};

/// An indexed mesh in input units: positions and faces (vertex index
/// loops, counter-clockwise seen from outside).
#[derive(Clone, Copy, Debug)]
pub struct MeshIn<'a> {
    /// The positions.
    pub positions: &'a [DVec3],
    /// The faces.
    pub faces: &'a [Vec<u32>],
}

impl<'a> MeshIn<'a> {
    /// A mesh from its parts.
    pub fn new(positions: &'a [DVec3], faces: &'a [Vec<u32>]) -> MeshIn<'a> {
        MeshIn { positions, faces }
    }
}

/// An indexed mesh in input units that owns its positions and faces: an
/// operand handed over to [`mesh_sequence_with`](crate::mesh_sequence_with)
/// this way is let go as soon as it is snapped.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshBuf {
    /// The positions.
    pub positions: Vec<DVec3>,
    /// The faces (vertex index loops, counter-clockwise seen from
    /// outside).
    pub faces: Vec<Vec<u32>>,
}

impl MeshBuf {
    /// A mesh from its parts.
    pub fn new(positions: Vec<DVec3>, faces: Vec<Vec<u32>>) -> MeshBuf {
        MeshBuf { positions, faces }
    }
}

/// A mesh an operand is read from: borrowed ([`MeshIn`]) or owned
/// ([`MeshBuf`]).
pub trait AsMeshIn {
    /// The mesh, borrowed.
    fn as_mesh_in(&self) -> MeshIn<'_>;
}

impl AsMeshIn for MeshIn<'_> {
    fn as_mesh_in(&self) -> MeshIn<'_> {
        *self
    }
}

impl AsMeshIn for MeshBuf {
    fn as_mesh_in(&self) -> MeshIn<'_> {
        MeshIn::new(&self.positions, &self.faces)
    }
}

/// Checks that operand `operand` is a closed, consistently oriented
/// 2-manifold ([`check_closed_manifold`]), or at least a closed cycle
/// ([`bsp_core::is_closed_cycle`]: every edge used as often each way, as
/// where a surface touches itself along an edge, folds, or a shell is
/// turned inside out), which [`snap_one`] resolves to where its winding
/// number is positive. The error is the manifold check's.
pub fn check_mesh(m: &MeshIn<'_>, operand: usize) -> Result<(), CsgError> {
    match check_closed_manifold(m.faces.iter().map(Vec::as_slice)) {
        Err(_) if bsp_core::is_closed_cycle(m.faces.iter().map(Vec::as_slice)) => Ok(()),
        checked => checked.map_err(|error| CsgError::Topology { operand, error }),
    }
}

/// The snapped operands: one grid for all, and per mesh its solid and what
/// snapping did to its faces.
#[derive(Clone, Debug)]
pub struct Snapped {
    /// The grid every operand is snapped to.
    pub grid: Grid,
    /// The solids, in the order of the meshes.
    pub solids: Vec<Solid>,
    /// What snapping did to each mesh's faces.
    pub reports: Vec<ImportReport>,
}

/// Snaps `meshes` (already checked with [`check_mesh`]) to one grid and
/// makes their solids. Fails with [`CsgError::Inward`] for a mesh whose
/// snapped faces bound a negative volume (exact).
///
/// For a long sequence of operands, [`fit_grid`] and [`snap_one`] make
/// each solid only when it is needed, so that the solids of operands not
/// yet used do not take memory.
pub fn snap(meshes: &[MeshIn<'_>]) -> Result<Snapped, CsgError> {
    let grid = fit_grid(meshes)?;
    let mut reports = Vec::with_capacity(meshes.len());
    let mut solids = Vec::with_capacity(meshes.len());
    for (i, m) in meshes.iter().enumerate() {
        let (solid, report) = snap_one(&grid, m, i)?;
        reports.push(report);
        solids.push(solid);
    }
    Ok(Snapped {
        grid,
        solids,
        reports,
    })
}

/// The grid [`snap`] puts `meshes` on: one that holds every position of
/// every mesh.
pub fn fit_grid(meshes: &[MeshIn<'_>]) -> Result<Grid, CsgError> {
    Grid::fit_points(meshes.iter().flat_map(|m| m.positions.iter())).map_err(CsgError::Grid)
}

/// The solid of one mesh (already checked with [`check_mesh`]) on `grid`
/// (from [`fit_grid`] over every mesh of the computation), and what
/// snapping did to its faces; `operand` is its position, for
/// [`CsgError::Inward`].
pub fn snap_one(
    grid: &Grid,
    mesh: &MeshIn<'_>,
    operand: usize,
) -> Result<(Solid, ImportReport), CsgError> {
    // each face's polygon goes straight into the face's slot, in
    // parallel: a solid's faces are most of its memory, and a list of
    // polygons moved into the slots after would be made and touched once
    // more; the rare extra polygons of triangulated faces go after
    const CHUNK: usize = 4096;
    let n = mesh.faces.len();
    let mut faces: Vec<Option<SolidFace>> = Vec::with_capacity(n);
    faces.resize_with(n, || None);
    // each vertex snapped once, not once per face around it
    let snapped = bsp_core::internals::snap_positions(grid, mesh.positions);
    type Run = (ImportReport, Vec<SolidFace>, i128, bool);
    let runs: Vec<Result<Run, bsp_core::InputError>> =
        par::map_chunks_mut(&mut faces, CHUNK, |c, slots| {
            let loops = &mesh.faces[c * CHUNK..];
            let mut imp = bsp_core::internals::FaceImporter::default();
            let (mut extra, mut six, mut turned) = (Vec::new(), 0i128, false);
            for (i, (slot, face)) in slots.iter_mut().zip(loops).enumerate() {
                imp.indexed_snapped(grid, mesh.positions, &snapped, face, c * CHUNK + i, |p| {
                    turned |= turned_over(mesh.positions, face, &p);
                    six += six_volume(&p);
                    let face = SolidFace::grid(p);
                    match slot {
                        None => *slot = Some(face),
                        Some(_) => extra.push(face),
                    }
                })?;
            }
            Ok((imp.finish(), extra, six, turned))
        });
    // the first error in face order, as a sequential import gives
    let mut report = ImportReport::default();
    let mut sign = 0i128;
    let (mut extra, mut turned) = (Vec::new(), false);
    for run in runs {
        let (r, e, six, t) = run.map_err(CsgError::Grid)?;
        report.add(r);
        extra.extend(e);
        sign += six;
        turned |= t;
    }
    if sign < 0 {
        return Err(CsgError::Inward { operand });
    }
    if n > 0 && report.polygons == 0 {
        return Err(CsgError::Collapsed {
            operand,
            faces: n,
            step_log2: grid.step_log2(),
        });
    }
    faces.extend(extra.into_iter().map(Some));
    // a dropped face left its slot empty (the lowest is reused first)
    let free = report
        .dropped
        .iter()
        .rev()
        .map(|&(f, _)| f as u32)
        .collect();
    // several shells may cross, overlap or nest, one shell may cross,
    // touch or fold over itself (as given, or where snapping turned a
    // sliver triangle over: a result read back on a coarser grid, say):
    // their solid is where the winding number is positive (see the crate
    // docs); a certified shell bounds it already
    let clean = !turned && shells(mesh) <= 1 && embedded(&faces);
    let solid = Solid::from_faces(faces, free);
    let solid = match clean {
        true => solid,
        false => solid.resolved()?,
    };
    Ok((solid, report))
}

/// Whether snapping turned the triangle `face` over: its snapped polygon
/// `p` (the whole triangle) faces the other way along its normal's largest
/// axis than the triangle's `f64` corners, or they have no area in that
/// projection (exact: Shewchuk's orientation of the corners as given, the
/// grid's integer normal). Faces of more corners are not checked.
fn turned_over(positions: &[DVec3], face: &[u32], p: &GridPolygon) -> bool {
    use bsp_core::internals::ConvexFace;
    if face.len() != 3 || p.corner_count() != 3 {
        return false;
    }
    let n = p.support().normal();
    let k = (0..3).max_by_key(|&k| n[k].unsigned_abs()).unwrap_or(0);
    let (u, v) = ((k + 1) % 3, (k + 2) % 3);
    let at = |i: usize| {
        let q = positions[face[i] as usize].to_array();
        robust::Coord { x: q[u], y: q[v] }
    };
    let o = robust::orient2d(at(0), at(1), at(2));
    o == 0.0 || (o > 0.0) != (n[k] > 0)
}

/// Whether the faces (all with grid corners, as snapped) of a surface
/// that is one shell by index bound the solid where its winding number
/// is positive as they are: certified closed, oriented, outward, and
/// meeting one another only in shared corners and edges (or touching at
/// corners, cones apart: [`bsp_core::certify_solid_boundary`]), in one
/// edge-connected part. Such a surface can be pulled apart at the corners
/// where it touches into an embedded connected surface, which bounds
/// winding number 1 inside and 0 outside. (Two parts would not do: a
/// sphere inside another, touching it at a shared corner, passes the
/// pair tests, and inside it the winding number is 2.) A shell that is a
/// 2-manifold by index may still cross itself, as given or once snapped;
/// then it is resolved.
fn embedded(faces: &[Option<SolidFace>]) -> bool {
    let polys: Option<Vec<&GridPolygon>> = faces.iter().flatten().map(SolidFace::as_grid).collect();
    polys
        .is_some_and(|p| bsp_core::internals::certify_grid_polygons(&p).is_ok_and(|c| c.parts <= 1))
}

/// The number of vertex-connected shells of `mesh`'s faces (by vertex
/// index).
fn shells(mesh: &MeshIn<'_>) -> usize {
    let mut uf = bsp_core::internals::UnionFind::new(mesh.positions.len());
    let mut used = vec![false; mesh.positions.len()];
    for f in mesh.faces {
        for w in f.windows(2) {
            uf.union(w[0], w[1]);
        }
        for &v in f {
            used[v as usize] = true;
        }
    }
    (0..used.len() as u32)
        .filter(|&v| used[v as usize] && uf.find(v) == v)
        .count()
}

/// Six times the signed volume of the cone from the origin over an
/// imported polygon (a fan of grid vertices); summed over a closed
/// surface, six times the volume it bounds. Coordinates below 2^26 keep
/// each cross product's coordinates below 2^53 (in `i64`) and each term
/// below 2^81 (in `i128`).
fn six_volume(p: &GridPolygon) -> i128 {
    let g = p.vertices();
    let a = g[0].map(i128::from);
    g[1..]
        .windows(2)
        .map(|w| {
            let (b, c) = (w[0].map(i64::from), w[1].map(i64::from));
            let n = [
                b[1] * c[2] - b[2] * c[1],
                b[2] * c[0] - b[0] * c[2],
                b[0] * c[1] - b[1] * c[0],
            ];
            a[0] * n[0] as i128 + a[1] * n[1] as i128 + a[2] * n[2] as i128
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh_boolean;
    use bsp_core::BoolOp;

    #[test]
    fn triangulated_and_dropped_faces_keep_their_slots_straight() {
        // an L-shaped prism (its top and bottom are non-convex hexagons,
        // imported as triangles after the other faces), with a vertex 12
        // on the edge 0-1 and a sliver face 0 12 1 without area (dropped,
        // its slot left empty), united with a unit cube in its notch
        let v = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        let mut positions = Vec::new();
        for z in [0.0, 1.0] {
            for (x, y) in [(0., 0.), (2., 0.), (2., 1.), (1., 1.), (1., 2.), (0., 2.)] {
                positions.push(v(x, y, z));
            }
        }
        positions.push(v(1.0, 0.0, 0.0));
        let mut faces: Vec<Vec<u32>> = vec![vec![5, 4, 3, 2, 1, 0]];
        faces.push(vec![6, 7, 8, 9, 10, 11]);
        for i in 0..6u32 {
            let j = (i + 1) % 6;
            faces.push(if i == 0 {
                vec![0, 12, 1, 7, 6]
            } else {
                vec![i, j, j + 6, i + 6]
            });
        }
        faces.push(vec![0, 1, 12]);
        let cube: Vec<DVec3> = (0..8)
            .map(|i| {
                v(
                    1.0 + (i & 1) as f64,
                    1.0 + (i >> 1 & 1) as f64,
                    (i >> 2) as f64,
                )
            })
            .collect();
        let cube_faces: Vec<Vec<u32>> = vec![
            vec![0, 2, 3, 1],
            vec![4, 5, 7, 6],
            vec![0, 1, 5, 4],
            vec![2, 6, 7, 3],
            vec![0, 4, 6, 2],
            vec![1, 3, 7, 5],
        ];
        let r = mesh_boolean(
            &MeshIn::new(&positions, &faces),
            &MeshIn::new(&cube, &cube_faces),
            BoolOp::Union,
        )
        .unwrap();
        let rep = &r.reports[0];
        assert_eq!(rep.faces, 9);
        assert_eq!(
            rep.triangulated.iter().map(|t| t.0).collect::<Vec<_>>(),
            [0, 1]
        );
        assert_eq!(rep.dropped.iter().map(|t| t.0).collect::<Vec<_>>(), [8]);
        // 8 faces' slots (one empty) and the triangles after them
        assert_eq!(rep.polygons, 6 + 2 * 4);
        assert_eq!(r.volume(), 4.0);
        r.mesh.check_watertight().unwrap();
        // the union's solid: the cube's faces took the empty slot and the
        // end; a point in each part is inside
        for q in [
            [0.5, 0.5, 0.5],
            [1.5, 0.5, 0.5],
            [0.5, 1.5, 0.5],
            [1.5, 1.5, 0.5],
        ] {
            let g = r.grid.snap(DVec3::from_array(q)).unwrap();
            assert_eq!(r.solid.winding(g), 1, "{q:?}");
        }
    }
}
