//! Iterated subtractions of small spheres from a larger one, on the faces
//! of the part's pole fan (slivers whose boxes and planes reach far beyond
//! them): every step must stay watertight, and the result must not depend
//! on how exactly the octree's cells list their faces.
//!
//! Regression: a face kept or dropped whole took its label from the first
//! cell its box and plane tests listed it in, which it may not reach — a
//! cell across the other surface. With exact cell lists the wrong label
//! left holes (the 2 000-triangle part minus 20 tools, from step 2 on).

use bsp_core::BoolOp;
use bsp_csg::shapes::{drill_tools, uv_sphere};
use bsp_csg::{MeshIn, Options, Snapped, snap};

fn drill(tools: usize, opts: &Options) -> (f64, usize) {
    let (pv, pf) = uv_sphere(2000);
    let (placed, tf) = drill_tools(tools, 1000);
    let mut meshes = vec![MeshIn::new(&pv, &pf)];
    meshes.extend(placed.iter().map(|v| MeshIn::new(v, &tf)));
    let Snapped { solids, .. } = snap(&meshes).unwrap();
    let mut it = solids.into_iter();
    let mut part = it.next().unwrap();
    for (i, tool) in it.enumerate() {
        part.apply_with(&tool, BoolOp::Difference, opts).unwrap();
        let mesh = part.to_mesh();
        if let Err(e) = mesh.check_watertight() {
            panic!("step {i}: {e}");
        }
    }
    let mesh = part.to_mesh();
    (mesh.volume_rounded(), mesh.triangles.len())
}

#[test]
fn twenty_tools_through_a_pole_fan() {
    let (box_lists, _) = drill(20, &Options::default());
    let (exact_lists, _) = drill(20, &Options::default().with_exact_cells(true));
    assert_eq!(box_lists, exact_lists, "the exact volume (grid units)");
    assert!(box_lists > 0.0);
}
