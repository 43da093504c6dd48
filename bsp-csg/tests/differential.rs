//! The octree path against the global BSP merge of `bsp-core`: the same
//! exact membership of every grid point of the scene's box (inside,
//! outside, on the boundary) and the same exact volume, for random
//! polyhedra on a small lattice (so that faces are often coplanar, edges
//! collinear and vertices shared), for every operation, and for
//! sequences of operations; the result is watertight every time.

use bsp_core::{BoolOp, GridPoint, Partition, Polygon};
use bsp_csg::{Options, Solid};
use proptest::prelude::*;

type Face = Vec<GridPoint>;

use bsp_fixtures::grid_cuboid as cuboid;

fn det(a: GridPoint, b: GridPoint, c: GridPoint, d: GridPoint) -> i64 {
    let s = |p: GridPoint, q: GridPoint| [0, 1, 2].map(|k| (p[k] - q[k]) as i64);
    let (u, v, w) = (s(b, a), s(c, a), s(d, a));
    u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
        + u[2] * (v[0] * w[1] - v[1] * w[0])
}

/// A tetrahedron with outward faces, or `None` if flat.
fn tetra(p: [GridPoint; 4]) -> Option<Vec<Face>> {
    let d = det(p[0], p[1], p[2], p[3]);
    if d == 0 {
        return None;
    }
    let [a, b, c, e] = if d > 0 { p } else { [p[1], p[0], p[2], p[3]] };
    Some(vec![
        vec![a, c, b],
        vec![a, b, e],
        vec![a, e, c],
        vec![b, c, e],
    ])
}

fn polys(faces: &[Face]) -> Vec<Polygon> {
    faces
        .iter()
        .map(|f| Polygon::from_grid_points(f, 0).expect("a proper face"))
        .collect()
}

fn shape() -> impl Strategy<Value = Vec<Face>> {
    let p = || prop::array::uniform3(0i32..7);
    prop_oneof![
        (p(), p()).prop_filter_map("a box with a volume", |(a, b)| {
            let lo = [0, 1, 2].map(|k| a[k].min(b[k]));
            let hi = [0, 1, 2].map(|k| a[k].max(b[k]));
            (0..3).all(|k| lo[k] < hi[k]).then(|| cuboid(lo, hi))
        }),
        prop::array::uniform4(p()).prop_filter_map("a tetrahedron with a volume", tetra),
    ]
}

fn op() -> impl Strategy<Value = BoolOp> {
    prop::sample::select(vec![
        BoolOp::Union,
        BoolOp::Intersection,
        BoolOp::Difference,
    ])
}

/// The same mesh, vertex for vertex and triangle for triangle.
fn identical(a: &Solid, b: &Solid) -> Result<(), TestCaseError> {
    same_mesh(&a.to_mesh(), &b.to_mesh())
}

/// The same mesh, vertex for vertex and triangle for triangle.
fn same_mesh(ma: &bsp_core::TriMesh, mb: &bsp_core::TriMesh) -> Result<(), TestCaseError> {
    prop_assert_eq!(ma.vertices.len(), mb.vertices.len(), "vertices");
    for (p, q) in ma.vertices.iter().zip(&mb.vertices) {
        prop_assert!(p.same_point(q), "vertex {:?} against {:?}", p, q);
    }
    prop_assert_eq!(&ma.triangles, &mb.triangles, "triangles");
    prop_assert_eq!(&ma.planes, &mb.planes, "planes");
    Ok(())
}

/// Checks the octree result against the global merge of the same inputs.
fn same(octree: &Solid, global: &Partition<bsp_core::Cell>) -> Result<(), TestCaseError> {
    let mesh = octree.to_mesh();
    if let Err(e) = mesh.check_watertight() {
        return Err(TestCaseError::fail(format!("not watertight: {e}")));
    }
    let gm = global.to_mesh();
    let exact = mesh.volume_exact();
    prop_assert_eq!(&exact, &gm.volume_exact(), "exact volume");
    // the cheap correctly rounded volume is the exact one, rounded
    use num_traits::ToPrimitive;
    prop_assert_eq!(
        mesh.volume_rounded(),
        exact.to_f64().unwrap(),
        "rounded volume"
    );
    for x in -1..8 {
        for y in -1..8 {
            for z in -1..8 {
                let p = [x, y, z];
                prop_assert_eq!(
                    octree.classify_point(p),
                    global.classify_point(&bsp_core::Point::Grid(p)),
                    "membership of {:?}",
                    p
                );
            }
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn one_operation_matches_the_global_merge(
        a in shape(),
        b in shape(),
        op in op(),
        leaf in prop::sample::select(vec![1usize, 2, 3, 24]),
        exact in any::<bool>(),
    ) {
        let (pa, pb) = (polys(&a), polys(&b));
        let mut octree = Solid::from_polygons(pa.clone());
        let opts = Options::default().with_leaf_size(leaf).with_exact_cells(exact);
        octree
            .apply_with(&Solid::from_polygons(pb.clone()), op, &opts)
            .unwrap();
        let global = Partition::solid(pa.clone()).boolean(&Partition::solid(pb.clone()), op);
        same(&octree, &global)?;
        // labelling the cells where the surfaces do not meet along the
        // faces gives what their local trees give
        let mut full = Solid::from_polygons(pa);
        full.apply_with(&Solid::from_polygons(pb), op, &opts.with_easy_cells(false))
            .unwrap();
        identical(&octree, &full)?;
    }

    #[test]
    fn the_last_result_meshed_from_its_plan_is_the_solid_s_mesh(
        first in shape(),
        rest in prop::collection::vec((shape(), op()), 1..4),
    ) {
        // the operations before the last leave free slots in the first
        // solid, which the last one's faces fill first
        let mut acc = Solid::from_polygons(polys(&first));
        let (last, op) = rest.last().unwrap();
        for (s, op) in &rest[..rest.len() - 1] {
            acc.apply(&Solid::from_polygons(polys(s)), *op).unwrap();
        }
        let other = Solid::from_polygons(polys(last));
        let mut applied = acc.clone();
        applied.apply(&other, *op).unwrap();
        let solid = acc.clone().plan_owned(other.clone(), *op).unwrap().into_solid();
        identical(&solid, &applied)?;
        let planned = acc.plan_owned(other, *op).unwrap();
        match (planned.into_watertight_mesh(), solid.into_watertight_mesh()) {
            (Ok(direct), Ok(via_solid)) => same_mesh(&direct, &via_solid)?,
            (direct, via_solid) => prop_assert_eq!(
                direct.map(|m| m.triangles).map_err(|e| e.to_string()),
                via_solid.map(|m| m.triangles).map_err(|e| e.to_string())
            ),
        }
    }

    #[test]
    fn sequences_match_the_global_merge(
        first in shape(),
        rest in prop::collection::vec((shape(), op()), 1..5),
        leaf in prop::sample::select(vec![1usize, 2, 5, 24]),
        exact in any::<bool>(),
    ) {
        let opts = Options::default().with_leaf_size(leaf).with_exact_cells(exact);
        let full_opts = opts.clone().with_easy_cells(false);
        let mut octree = Solid::from_polygons(polys(&first));
        let mut full = octree.clone();
        let mut global = Partition::solid(polys(&first));
        for (s, op) in &rest {
            octree.apply_with(&Solid::from_polygons(polys(s)), *op, &opts).unwrap();
            full.apply_with(&Solid::from_polygons(polys(s)), *op, &full_opts).unwrap();
            global = global.boolean(&Partition::solid(polys(s)), *op);
            same(&octree, &global)?;
            identical(&octree, &full)?;
        }
    }
}
