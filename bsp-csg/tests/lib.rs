//! bsp-csg's integration tests, one binary: each module is one subject.

mod certify;
mod coplanar;
mod differential;
mod drill;
mod resolve;

use bsp_csg::{MeshBuf, MeshIn};

/// A mesh as an operand.
fn view(m: &MeshBuf) -> MeshIn<'_> {
    MeshIn::new(&m.positions, &m.faces)
}

/// One of the repository's meshes (`data/meshes/NAME`), read.
fn repo_mesh(name: &str) -> shadow_scene::Mesh {
    let path = format!("{}/../data/meshes/{name}", env!("CARGO_MANIFEST_DIR"));
    shadow_scene::load(std::path::Path::new(&path)).unwrap()
}
