//! The mesh readers on arbitrary bytes: OBJ (as text) and STL (binary or
//! ASCII). Neither may panic; a mesh read must index only its own
//! positions with faces of three or more corners, and an error must name
//! the file.

use shadow_scene::{Mesh, parse_obj, parse_stl};

/// What a reader gave: a mesh whose every face has three or more corners,
/// each a position of the mesh, or an error naming `name`.
fn check_read(r: Result<Mesh, shadow_scene::SceneError>, name: &str) -> Option<Mesh> {
    match r {
        Ok(m) => {
            for (i, f) in m.faces.iter().enumerate() {
                assert!(
                    f.vertices.len() >= 3,
                    "{name}: face {i} has {} corners",
                    f.vertices.len()
                );
                assert!(
                    f.vertices.iter().all(|&v| (v as usize) < m.positions.len()),
                    "{name}: face {i} indexes past the {} positions",
                    m.positions.len()
                );
                assert!(
                    (f.group as usize) < m.groups.len().max(1),
                    "{name}: face {i}'s group"
                );
            }
            // the checks a command runs next do not panic either
            let _ = m.is_closed_oriented();
            let _ = m.bounds();
            Some(m)
        }
        Err(e) => {
            let text = e.to_string();
            assert!(
                text.contains(name),
                "the error does not name the file: {text}"
            );
            None
        }
    }
}

/// `data` read as an OBJ file (lossily as UTF-8, as a file of any bytes
/// would be); see the module docs. Returns whether it read.
///
/// ```
/// assert!(bsp_testkit::obj_case(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"));
/// assert!(!bsp_testkit::obj_case(b"f 1 2 3\n"));
/// ```
pub fn obj_case(data: &[u8]) -> bool {
    let text = String::from_utf8_lossy(data);
    check_read(parse_obj(&text, "fuzz.obj"), "fuzz.obj").is_some()
}

/// `data` read as an STL file; see the module docs. Returns whether it
/// read.
///
/// ```
/// let ascii = b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n\
///               vertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
/// assert!(bsp_testkit::stl_case(ascii));
/// assert!(!bsp_testkit::stl_case(b"short"));
/// ```
pub fn stl_case(data: &[u8]) -> bool {
    check_read(parse_stl(data, "fuzz.stl"), "fuzz.stl").is_some()
}
