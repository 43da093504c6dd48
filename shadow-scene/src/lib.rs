//! Scenes for the exact BSP shadow toolkit: mesh files and built-in
//! generated scenes.
//!
//! A [`Mesh`] is a list of positions and faces (vertex loops of any
//! length, in file order) with named groups. It is read from
//!
//! - Wavefront OBJ by a hand-written reader ([`read_obj`], [`parse_obj`])
//!   that keeps quads and n-gons whole and names the file and 1-based line
//!   of every error (`bunny.obj:12: face index 9999 out of range
//!   (1..=1839)`); no maintained crate does both,
//! - binary or ASCII STL through `stl_io` ([`read_stl`], [`parse_stl`]),
//!   welding exactly equal positions so triangles share vertices,
//! - either, chosen by extension ([`load`]),
//!
//! or generated in code ([`scene`], [`room`]): the test room of Liu & Wu's
//! real-time shadow paper, with a movable coordinate-axis object. Meshes
//! are written back with [`write_obj`].
//!
//! This crate does not depend on the exact kernel; it hands `f64` face
//! loops ([`Mesh::face_loops`]) to whoever snaps them.
//!
//! # Example
//!
//! ```
//! use shadow_scene::{parse_obj, room, SceneError};
//!
//! let mesh = parse_obj("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n", "quad.obj")?;
//! assert_eq!(mesh.faces[0].vertices.len(), 4);
//!
//! let err = parse_obj("v 0 0 0\nv nan 0 0\n", "bad.obj").unwrap_err();
//! assert_eq!(err.to_string(), "bad.obj:2: coordinate `nan` is not finite");
//!
//! let room = room();
//! let axes = room.group_index("axes").unwrap();
//! assert!(room.faces.iter().any(|f| f.group == axes));
//! # Ok::<(), SceneError>(())
//! ```
//!
//! # Feature flags
//!
//! None.

use std::path::Path;

mod error;
mod mesh;
mod obj;
mod prim;
mod scenes;
mod stl;

pub use error::SceneError;
pub use mesh::{Face, Mesh};
pub use obj::{parse_obj, read_obj, write_obj};
pub use scenes::{SCENE_NAMES, room, scene};
pub use stl::{parse_stl, read_stl};

/// Reads an OBJ or STL file, chosen by its extension (`.obj` or `.stl`,
/// in any case); other extensions give [`SceneError::UnknownFormat`].
///
/// ```
/// use std::path::Path;
/// use shadow_scene::{load, SceneError};
/// let err = load(Path::new("model.ply")).unwrap_err();
/// assert!(matches!(err, SceneError::UnknownFormat { .. }));
/// ```
pub fn load(path: &Path) -> Result<Mesh, SceneError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("obj") => read_obj(path),
        Some("stl") => read_stl(path),
        _ => Err(SceneError::UnknownFormat {
            path: path.display().to_string(),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str, contents: &[u8]) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("shadow-scene-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join(name);
        std::fs::write(&p, contents).unwrap();
        p
    }

    #[test]
    fn load_chooses_by_extension_in_any_case() {
        let obj = temp("tri.OBJ", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
        assert_eq!(load(&obj).unwrap().faces.len(), 1);
        let stl = temp(
            "tri.Stl",
            b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n",
        );
        assert_eq!(load(&stl).unwrap().faces.len(), 1);
        let none = temp("tri", b"");
        assert!(matches!(load(&none), Err(SceneError::UnknownFormat { .. })));
    }

    #[test]
    fn errors_name_the_file_on_disk() {
        let bad = temp("broken.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
        let e = load(&bad).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!("{}:4: face index 4 out of range (1..=3)", bad.display())
        );
        let missing = bad.with_file_name("missing.obj");
        let e = load(&missing).unwrap_err();
        assert!(matches!(e, SceneError::Io { .. }));
        assert!(e.to_string().starts_with(&missing.display().to_string()));
    }

    #[test]
    fn the_shipped_meshes_load() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/meshes");
        let teapot = load(&dir.join("teapot.obj")).unwrap();
        assert_eq!((teapot.positions.len(), teapot.faces.len()), (792, 992));
        let bunny = load(&dir.join("bunny.obj")).unwrap();
        assert_eq!((bunny.positions.len(), bunny.faces.len()), (1839, 3674));
        assert!(bunny.is_closed_oriented());
    }
}
