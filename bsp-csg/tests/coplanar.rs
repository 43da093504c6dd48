//! Operands whose faces share planes: a mesh with itself, a pocket flush
//! with a face, a prism standing in a box. The result is exact (the
//! differential tests check that on random boxes and tetrahedra); these
//! check that it is also no finer than the inputs make it.

use bsp_core::BoolOp;
use bsp_csg::files::{FileBoolean, Operand};
use bsp_csg::{MeshBuf, MeshIn, mesh_boolean, mesh_sequence};

use crate::view;
use bsp_fixtures as shapes;
use glam::DVec3;

/// The box `[lo, hi]` as one mesh (quads).
fn cuboid(lo: [f64; 3], hi: [f64; 3]) -> MeshBuf {
    let mut positions: Vec<DVec3> = Vec::new();
    let mut faces = Vec::new();
    for face in shapes::cuboid(DVec3::from(lo), DVec3::from(hi)) {
        let ids = face.into_iter().map(|p| {
            let i = positions.iter().position(|&q| q == p).unwrap_or_else(|| {
                positions.push(p);
                positions.len() - 1
            });
            i as u32
        });
        faces.push(ids.collect());
    }
    MeshBuf::new(positions, faces)
}

/// A real mesh united with itself, intersected with itself and taken
/// from itself: the same triangles, the same triangles, nothing, and no
/// cell split or face cut. (Every face of one lies on a face of the
/// other: before, each cell where they met was merged as a whole and the
/// nut came back with 4,410 triangles instead of 1,046, the bunny with
/// 27,944 instead of 3,674.)
#[test]
fn a_mesh_with_itself_comes_back_as_it_was() {
    for name in ["pyvista_nut.obj", "bunny.obj"] {
        let mesh = crate::repo_mesh(name);
        let triangles: usize = mesh.faces.iter().map(|f| f.vertices.len() - 2).sum();
        let alone = {
            let mut one = [Operand::new(name, mesh.clone())];
            let checked = Operand::check_all(&mut one).unwrap();
            FileBoolean::apply(checked, BoolOp::Union, |_, _| {}).unwrap()
        };
        for op in [BoolOp::Union, BoolOp::Intersection, BoolOp::Difference] {
            let mut twice = [
                Operand::new(name, mesh.clone()),
                Operand::new(name, mesh.clone()),
            ];
            let checked = Operand::check_all(&mut twice).unwrap();
            let out = FileBoolean::apply(checked, op, |_, _| {}).unwrap();
            let got = out.exact.triangles.len();
            if op == BoolOp::Difference {
                assert_eq!(got, 0, "{name} less itself");
                continue;
            }
            assert_eq!(got, triangles, "{name} {op:?} itself");
            assert_eq!(out.volume(), alone.volume(), "{name} {op:?} itself");
            out.exact.check_watertight().unwrap();
            // the two surfaces are one everywhere: the octree's first cell
            // is settled whole, nothing is cut (before, 179,460 cells for
            // the 99k sphere)
            let stats = out.stats[0];
            let counts = (stats.cells, stats.one_set_cells, stats.cut_faces);
            assert_eq!(counts, (1, 1, 0), "{name} {op:?} itself");
        }
    }
}

/// A pocket whose opening lies in the part's top face comes out as lean
/// as a pocket cut through it: the top face with a hole, the pocket's
/// walls and floor (before, the cells where the two tops met were merged
/// whole: 58 triangles instead of 36).
#[test]
fn a_pocket_flush_with_a_face_is_as_lean_as_one_cut_through_it() {
    let part = cuboid([0.0; 3], [4.0, 4.0, 2.0]);
    let flush = cuboid([1.0, 1.0, 1.0], [3.0, 3.0, 2.0]);
    let through = cuboid([1.0, 1.0, 1.0], [3.0, 3.0, 3.0]);
    let a = mesh_boolean(&view(&part), &view(&flush), BoolOp::Difference).unwrap();
    let b = mesh_boolean(&view(&part), &view(&through), BoolOp::Difference).unwrap();
    assert_eq!(a.volume(), 28.0);
    assert_eq!(b.volume(), 28.0);
    a.mesh.check_watertight().unwrap();
    assert!(
        a.mesh.triangles.len() <= b.mesh.triangles.len(),
        "flush {} against through {}",
        a.mesh.triangles.len(),
        b.mesh.triangles.len()
    );
}

/// A box and a box standing inside it on its floor, sharing the floor's
/// plane and two walls': the union is the outer box, the intersection
/// the inner one, each with the triangles of its own faces only (the copy
/// of a shared area that stays is the one that stays whole).
#[test]
fn of_two_faces_in_one_plane_the_one_that_stays_whole_is_kept() {
    let outer = cuboid([0.0; 3], [4.0, 4.0, 3.0]);
    let inner = cuboid([0.0, 1.0, 0.0], [2.0, 4.0, 2.0]);
    for (op, volume) in [(BoolOp::Union, 48.0), (BoolOp::Intersection, 12.0)] {
        for (a, b) in [(&outer, &inner), (&inner, &outer)] {
            let r = mesh_boolean(&view(a), &view(b), op).unwrap();
            assert_eq!(r.volume(), volume, "{op:?}");
            r.mesh.check_watertight().unwrap();
            assert_eq!(r.mesh.triangles.len(), 12, "{op:?}: a box");
        }
    }
}

/// A mesh and an edited copy of it (the nut with a box added, as one
/// sequence): where their faces are the same polygons the cells are
/// settled without cutting, near the edit they are cut as usual. The
/// union is the copy exactly, and no finer than the copy by much (before,
/// 5,240 triangles for the copy's 1,146).
#[test]
fn a_mesh_with_an_edited_copy_of_itself_is_the_copy() {
    let nut = crate::repo_mesh("pyvista_nut.obj");
    let (lo, hi) = nut.bounds().unwrap();
    let (c, s) = ((lo + hi) / 2.0, hi - lo);
    let at = |x: f64, y: f64, z: f64| [x, c.y + y * s.y, c.z + z * s.z];
    let b = cuboid(
        at(hi.x - 0.2 * s.x, -0.1, -0.1),
        at(hi.x + 0.2 * s.x, 0.1, 0.1),
    );
    let faces: Vec<Vec<u32>> = nut.faces.iter().map(|f| f.vertices.clone()).collect();
    let n = MeshIn::new(&nut.positions, &faces);
    let copy = mesh_sequence(&n, &[(BoolOp::Union, view(&b))]).unwrap();
    for op in [BoolOp::Union, BoolOp::Intersection] {
        let again = mesh_sequence(&n, &[(BoolOp::Union, view(&b)), (op, n)]).unwrap();
        let want = match op {
            BoolOp::Union => copy.volume(),
            _ => mesh_boolean(&n, &n, op).unwrap().volume(),
        };
        assert_eq!(again.volume(), want, "{op:?}");
        again.mesh.check_watertight().unwrap();
        let (got, of) = (again.mesh.triangles.len(), copy.mesh.triangles.len());
        assert!(4 * got <= 5 * of, "{op:?}: {got} triangles, the copy {of}");
    }
}
