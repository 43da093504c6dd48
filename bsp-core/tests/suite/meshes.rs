//! Real meshes: OBJ → `Grid::fit_points` → `import_faces` → BSP tree,
//! checked for dropped faces, planarity, tree invariants, exact face
//! coverage by fragments, membership against ray parity, and painter's
//! order against exact ray casting.

use std::collections::HashMap;
use std::path::Path;

use bsp_core::internals::all_planar;
use bsp_core::{
    BspTree, BuildOptions, Grid, GridPoint, ImportReport, Point, Polygon, import_faces,
};
use glam::DVec3;
use num_traits::Zero;

use crate::oracle::{Q, Q3, Solid, add3, area_vector, point_q};
use crate::strategies::{Rng, box_point};
use crate::tree::check_scene;

const MESHES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../data/meshes/");

/// A mesh read from `data/meshes`, its grid and its faces snapped.
struct Loaded {
    name: &'static str,
    grid: Grid,
    loops: Vec<Vec<DVec3>>,
    snapped: Vec<Vec<GridPoint>>,
}

fn load(name: &'static str) -> Loaded {
    let path = format!("{MESHES}{name}.obj");
    let mesh = shadow_scene::read_obj(Path::new(&path)).unwrap_or_else(|e| panic!("{path}: {e:?}"));
    let grid = Grid::fit_points(&mesh.positions).expect("finite mesh");
    let loops = mesh.face_loops();
    let snapped = loops
        .iter()
        .map(|l| {
            l.iter()
                .map(|p| grid.snap(*p).expect("fitted grid holds the mesh"))
                .collect()
        })
        .collect();
    Loaded {
        name,
        grid,
        loops,
        snapped,
    }
}

fn import(m: &Loaded) -> (Vec<Polygon>, ImportReport) {
    import_faces(&m.grid, m.loops.iter().map(|l| &l[..]))
        .unwrap_or_else(|e| panic!("{}: {e}", m.name))
}

/// Sum of the area vectors of polygons per tag.
fn areas_by_tag<'a>(polys: impl Iterator<Item = &'a Polygon>) -> HashMap<u32, Q3> {
    let mut m: HashMap<u32, Q3> = HashMap::new();
    for p in polys {
        let a = area_vector(&p.vertices().iter().map(point_q).collect::<Vec<_>>());
        let e = m
            .entry(p.tag())
            .or_insert_with(|| [Q::zero(), Q::zero(), Q::zero()]);
        *e = add3(e, &a);
    }
    m
}

/// Imports a closed mesh whole, builds trees with and without balance
/// cuts, and checks them; returns the default tree and the oracle solid.
fn closed_mesh(name: &'static str) -> (Loaded, BspTree, Solid) {
    let m = load(name);
    let (polys, report) = import(&m);
    assert!(report.dropped.is_empty(), "{name}: {}", report.summary());
    assert_eq!(report.faces, m.loops.len());
    assert_eq!(report.polygons, polys.len());
    assert!(polys.len() >= m.loops.len());
    assert!(
        all_planar(&polys),
        "{name}: a vertex is off its support plane"
    );
    for (i, p) in polys.iter().enumerate() {
        p.sanity_check()
            .unwrap_or_else(|e| panic!("{name}: polygon {i}: {e}"));
        // import creates no vertices: each one is a snapped vertex of its face
        let face = &m.snapped[p.tag() as usize];
        for v in p.vertices() {
            let g = v.as_grid().expect("imported vertices are grid points");
            assert!(
                face.contains(&g),
                "{name}: vertex {g:?} not in face {}",
                p.tag()
            );
        }
    }
    let solid = Solid::new(&m.snapped);
    assert_eq!(solid.volume_sign(), 1, "{name} is not oriented outwards");
    let imported = areas_by_tag(polys.iter());
    let mut default_tree = None;
    for opts in [
        BuildOptions::default(),
        BuildOptions::default().with_cut_threshold(64).with_seed(3),
    ] {
        let tree = BspTree::build(polys.clone(), &opts);
        tree.sanity_check()
            .unwrap_or_else(|e| panic!("{name} {opts:?}: {e}"));
        // the fragments of every face cover it exactly (checked on the
        // first tree: exact areas of thousands of fragments are costly)
        if default_tree.is_none() {
            let fragments = areas_by_tag(tree.polygons());
            assert_eq!(fragments.len(), imported.len());
            for (tag, a) in &imported {
                assert_eq!(
                    fragments.get(tag),
                    Some(a),
                    "{name}: face {tag} area changed"
                );
            }
        }
        default_tree.get_or_insert(tree);
    }
    (m, default_tree.expect("built"), solid)
}

/// Membership of sampled points against ray parity: random points in the
/// bounding box, mesh vertices, edge midpoints that are grid points, and
/// the axis neighbours of vertices.
fn check_membership(m: &Loaded, tree: &BspTree, solid: &Solid, samples: usize, seed: u64) {
    let mut rng = Rng(seed);
    let all: Vec<GridPoint> = m.snapped.iter().flatten().copied().collect();
    let (lo, hi) = crate::strategies::bbox(&all);
    let mut points: Vec<GridPoint> = Vec::new();
    for _ in 0..samples {
        let f = [0; 3].map(|_| rng.next() as u16);
        points.push(box_point(lo, hi, f));
        let face = &m.snapped[rng.below(m.snapped.len())];
        let i = rng.below(face.len());
        let (a, b) = (face[i], face[(i + 1) % face.len()]);
        points.push(a);
        let s = [0, 1, 2].map(|k| a[k] as i64 + b[k] as i64);
        if s.iter().all(|c| c % 2 == 0) {
            points.push(s.map(|c| (c / 2) as i32));
        }
        let mut n = a;
        n[rng.below(3)] += if rng.next().is_multiple_of(2) { 1 } else { -1 };
        points.push(n);
    }
    let mut seen = [0usize; 3];
    for p in points {
        let want = solid.classify(p);
        seen[want as usize] += 1;
        assert_eq!(
            tree.classify_point(&Point::Grid(p)),
            want,
            "{} at {p:?}",
            m.name
        );
    }
    assert!(
        seen.iter().all(|&s| s > 0),
        "{}: inside/outside/boundary all sampled: {seen:?}",
        m.name
    );
}

#[test]
fn bunny_imports_whole_and_membership_matches_ray_parity() {
    let (m, tree, solid) = closed_mesh("bunny");
    assert_eq!(
        solid.len(),
        m.loops.len(),
        "bunny is all triangles with area"
    );
    check_membership(&m, &tree, &solid, 60, 1);
}

#[test]
fn cgal_eight_imports_whole_and_membership_matches_ray_parity() {
    let (m, tree, solid) = closed_mesh("cgal_eight");
    check_membership(&m, &tree, &solid, 150, 2);
}

#[test]
fn pyvista_sphere_imports_whole() {
    let (m, tree, solid) = closed_mesh("pyvista_sphere");
    check_membership(&m, &tree, &solid, 20, 3);
}

#[test]
fn pyvista_nut_imports_whole() {
    let (m, tree, solid) = closed_mesh("pyvista_nut");
    check_membership(&m, &tree, &solid, 20, 4);
}

#[test]
fn pyvista_ant_imports_whole() {
    let (m, tree, solid) = closed_mesh("pyvista_ant");
    check_membership(&m, &tree, &solid, 20, 5);
}

/// The teapot is an open soup: the tree is for ordering only. Painter's
/// order from a few viewpoints, against exact ray casting.
#[test]
fn teapot_soup_painter_order() {
    let m = load("teapot");
    let (polys, report) = import(&m);
    assert_eq!(report.polygons, polys.len());
    assert!(all_planar(&polys));
    let all: Vec<GridPoint> = m.snapped.iter().flatten().copied().collect();
    let (lo, hi) = crate::strategies::bbox(&all);
    let centre = [0, 1, 2].map(|k| (lo[k] as i64 + hi[k] as i64) / 2);
    let ext = (0..3)
        .map(|k| hi[k] as i64 - lo[k] as i64)
        .max()
        .expect("3 axes");
    let eyes = [
        [centre[0] + 2 * ext, centre[1] + ext, centre[2] + 3 * ext],
        [centre[0] - 1, centre[1] + 2, centre[2] - 3],
        [centre[0], centre[1] - (1 << 50), centre[2] + (1 << 49)],
    ];
    let opts = BuildOptions::default().with_cut_threshold(128);
    let occluding = check_scene(&m.snapped, &opts, &eyes, 6, &mut Rng(11))
        .unwrap_or_else(|e| panic!("teapot: {e}"));
    assert!(occluding > 0, "the rays must cross several fragments");
    // only faces without area are dropped
    for (f, defect) in &report.dropped {
        let l: Vec<Q3> = m.snapped[*f]
            .iter()
            .map(|g| crate::oracle::grid_q(*g))
            .collect();
        assert!(
            l.len() == 3 && area_vector(&l).iter().all(Zero::is_zero),
            "teapot face {f} dropped ({defect}) but has area"
        );
    }
}

/// A closed mesh seen from outside and from inside its bounding box.
#[test]
fn cgal_eight_painter_order() {
    let m = load("cgal_eight");
    let all: Vec<GridPoint> = m.snapped.iter().flatten().copied().collect();
    let (lo, hi) = crate::strategies::bbox(&all);
    let eyes = [
        [hi[0] as i64 * 3, lo[1] as i64 * 2, hi[2] as i64 + 5],
        [0, 0, 0],
        [lo[0] as i64 - 7, 1 << 45, -(1 << 44)],
    ];
    let occluding = check_scene(&m.snapped, &BuildOptions::default(), &eyes, 6, &mut Rng(12))
        .unwrap_or_else(|e| panic!("cgal_eight: {e}"));
    assert!(occluding > 0, "the rays must cross several fragments");
}
