//! Iterated CSG: subtracts `TOOLS` small spheres (about `TOOL_TRIS`
//! triangles each) from a sphere of about `PART_TRIS` triangles, one after
//! the other, on one grid; each tool is centred on the part's surface, on
//! a Fibonacci spiral. Prints the time of the snap, of the subtractions
//! and of the final mesh, and checks that the result is watertight.
//!
//! ```sh
//! cargo run --release -p bsp-csg --example drill [TOOLS] [PART_TRIS] [TOOL_TRIS]
//! ```
//!
//! `LEAF_SIZE=N` sets the octree's leaf size.

use std::time::Instant;

use bsp_core::BoolOp;
use bsp_csg::shapes::{drill_tools, uv_sphere};
use bsp_csg::{MeshIn, Snapped, snap};

fn main() {
    let mut args = std::env::args().skip(1).map(|a| a.parse::<usize>().ok());
    let tools = args.next().flatten().unwrap_or(1000);
    let part_tris = args.next().flatten().unwrap_or(100_000);
    let tool_tris = args.next().flatten().unwrap_or(1000);
    let (pv, pf) = uv_sphere(part_tris);
    let (tool_meshes, tf) = drill_tools(tools, tool_tris);
    let mut meshes = vec![MeshIn::new(&pv, &pf)];
    meshes.extend(tool_meshes.iter().map(|v| MeshIn::new(v, &tf)));
    let t = Instant::now();
    let Snapped { solids, .. } = snap(&meshes).unwrap();
    let t_snap = t.elapsed();
    let mut it = solids.into_iter();
    let mut part = it.next().unwrap();
    let t = Instant::now();
    let (mut cut, mut mixed, mut cells) = (0, 0, 0);
    let leaf = std::env::var("LEAF_SIZE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(bsp_csg::LEAF_SIZE);
    let opts = bsp_csg::Options::default().with_leaf_size(leaf);
    for tool in it {
        let s = part.apply_with(&tool, BoolOp::Difference, &opts).unwrap();
        cut += s.cut_faces;
        mixed += s.mixed_cells;
        cells += s.cells;
    }
    let t_ops = t.elapsed();
    let t = Instant::now();
    let mesh = part.to_mesh();
    mesh.check_watertight().unwrap();
    let t_mesh = t.elapsed();
    println!(
        "{} - {tools} x {} triangles: snap {:.0} ms, subtractions {:.0} ms ({:.2} ms each, \
         {cut} faces cut, {cells} cells, {mixed} mixed), mesh+check {:.0} ms; {} faces, {} triangles out",
        pf.len(),
        tf.len(),
        t_snap.as_secs_f64() * 1e3,
        t_ops.as_secs_f64() * 1e3,
        t_ops.as_secs_f64() * 1e3 / tools as f64,
        t_mesh.as_secs_f64() * 1e3,
        part.len(),
        mesh.triangles.len()
    );
}
