//! Iterated CSG: subtracts `TOOLS` small spheres (about `TOOL_TRIS`
//! triangles each) from a sphere of about `PART_TRIS` triangles, one after
//! the other, on one grid; each tool is centred on the part's surface, on
//! a Fibonacci spiral. Each tool is snapped when its turn comes (the grid
//! is fitted to every mesh first), so that only the part and one tool are
//! solids at a time. Prints the time of the snaps, of the subtractions and
//! of the final mesh, and checks that the result is watertight.
//!
//! ```sh
//! cargo run --release -p bsp-csg --example drill [TOOLS] [PART_TRIS] [TOOL_TRIS]
//! ```
//!
//! `LEAF_SIZE=N` sets the octree's leaf size.

use std::time::Instant;

use bsp_core::BoolOp;
use bsp_csg::{MeshIn, fit_grid, snap_one};
use bsp_fixtures::{drill_tools, uv_sphere};

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
    let grid = fit_grid(&meshes).unwrap();
    let mut part = snap_one(&grid, &meshes[0], 0).unwrap().0;
    let mut t_snap = t.elapsed();
    let (mut cut, mut mixed, mut easy, mut clean, mut cells) = (0, 0, 0, 0, 0);
    let leaf = std::env::var("LEAF_SIZE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(bsp_csg::LEAF_SIZE);
    let opts = bsp_csg::Options::default().with_leaf_size(leaf);
    let mut t_ops = std::time::Duration::ZERO;
    for (i, m) in meshes.iter().enumerate().skip(1) {
        let t = Instant::now();
        let tool = snap_one(&grid, m, i).unwrap().0;
        t_snap += t.elapsed();
        let t = Instant::now();
        let s = part
            .apply_owned_with(tool, BoolOp::Difference, &opts)
            .unwrap();
        t_ops += t.elapsed();
        cut += s.cut_faces;
        mixed += s.mixed_cells;
        easy += s.easy_cells;
        clean += s.clean_cells;
        cells += s.cells;
    }
    let t = Instant::now();
    let faces_out = part.len();
    let mesh = part.into_watertight_mesh().unwrap();
    let t_mesh = t.elapsed();
    println!(
        "{} - {tools} x {} triangles: snap {:.0} ms, subtractions {:.0} ms ({:.2} ms each, \
         {cut} faces cut, {cells} cells, {mixed} mixed, {clean} clean, {easy} easy), mesh+check {:.0} ms; {} faces, {} triangles out",
        pf.len(),
        tf.len(),
        t_snap.as_secs_f64() * 1e3,
        t_ops.as_secs_f64() * 1e3,
        t_ops.as_secs_f64() * 1e3 / tools as f64,
        t_mesh.as_secs_f64() * 1e3,
        faces_out,
        mesh.triangles.len()
    );
}
