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
//! - CityJSON city models ([`read_cityjson`], [`parse_cityjson`]), one
//!   group per city object named by its id, errors placed by a JSON
//!   pointer into the file,
//! - any of them, chosen by extension ([`load`]),
//!
//! or generated in code ([`scene`], [`room`]), with a base colour for
//! every face ([`face_colors`]): the test room of Liu & Wu's
//! real-time shadow paper, with a movable coordinate-axis object. Meshes
//! are written back with [`write_obj`] or [`write_stl`] (binary), or
//! [`save`]d with the format chosen by extension.
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

mod animated;
mod atomic;
mod city;
mod cityjson;
mod error;
mod mesh;
mod obj;
mod palette;
mod points;
mod prim;
mod rings;
mod scan;
mod scenes;
mod stl;

pub use animated::{
    ANIMATED_NAMES, Animated, BUNNY_LIGHT, ROOM_EYE, ROOM_LIGHT, ROOM_TARGET, animated, torus,
};
pub use atomic::{AtomicFile, remove_unfinished};
pub use city::{CITY_SIDE, city_block};
pub use cityjson::{parse_cityjson, read_cityjson};
pub use error::SceneError;
pub use mesh::{
    Face, FlatFix, Mesh, MeshView, Rounding, Triangles, collinear, f32_step, f64_step, newell,
    to_f32, unit_or_zero,
};
pub use obj::{
    MAX_FACE_VERTICES, ObjNotes, parse_obj, parse_obj_notes, read_obj, read_obj_notes, write_obj,
};
pub use palette::{Rgb, face_colors};
pub use points::{Sensor, parse_points, parse_sensors, read_points, read_sensors};
pub use rings::triangulate_rings;
pub use scan::{MAX_SUBDIVISIONS, bunny, sqrt3_subdivide};
pub use scenes::{ROOM_STAGING, SCENE_NAMES, Staging, room, scene, scene_named};
pub use stl::{parse_stl, read_stl, stl_collisions, write_stl};

/// A mesh file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum MeshFormat {
    /// Wavefront OBJ (`.obj`).
    Obj,
    /// STL (`.stl`): read as binary or ASCII, written as binary.
    Stl,
}

impl MeshFormat {
    /// The format named by `path`'s extension (`.obj` or `.stl`, in any
    /// case); other extensions give [`SceneError::UnknownFormat`].
    ///
    /// ```
    /// use std::path::Path;
    /// use shadow_scene::MeshFormat;
    /// assert_eq!(MeshFormat::from_path(Path::new("a/b.STL")).unwrap(), MeshFormat::Stl);
    /// assert!(MeshFormat::from_path(Path::new("model.ply")).is_err());
    /// ```
    pub fn from_path(path: &Path) -> Result<MeshFormat, SceneError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("obj") => Ok(MeshFormat::Obj),
            Some("stl") => Ok(MeshFormat::Stl),
            _ => Err(SceneError::UnknownFormat {
                path: path.display().to_string(),
            }),
        }
    }
}

/// Reads an OBJ, STL or CityJSON file, chosen by its extension (`.obj`,
/// `.stl` or `.json`, in any case); other extensions give
/// [`SceneError::UnknownFormat`].
///
/// ```
/// use std::path::Path;
/// use shadow_scene::{load, SceneError};
/// let err = load(Path::new("model.ply")).unwrap_err();
/// assert!(matches!(err, SceneError::UnknownFormat { .. }));
/// ```
pub fn load(path: &Path) -> Result<Mesh, SceneError> {
    load_notes(path).map(|(m, _)| m)
}

/// [`load`], with what an OBJ reader skipped (see [`ObjNotes`]; STL and
/// CityJSON have nothing to skip).
pub fn load_notes(path: &Path) -> Result<(Mesh, ObjNotes), SceneError> {
    let json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    if json {
        return Ok((read_cityjson(path)?, ObjNotes::default()));
    }
    match MeshFormat::from_path(path)? {
        MeshFormat::Obj => read_obj_notes(path),
        MeshFormat::Stl => Ok((read_stl(path)?, ObjNotes::default())),
    }
}

/// Writes `mesh` as OBJ ([`write_obj`]) or binary STL ([`write_stl`]),
/// chosen by `path`'s extension as for [`load`], whole or not at all
/// ([`AtomicFile`]). Errors name the file.
///
/// ```
/// use std::path::Path;
/// use shadow_scene::{save, SceneError};
/// let cube = shadow_scene::scene("cube").unwrap();
/// let err = save(Path::new("cube.ply"), &cube).unwrap_err();
/// assert!(matches!(err, SceneError::UnknownFormat { .. }));
/// ```
pub fn save(path: &Path, mesh: &dyn MeshView) -> Result<(), SceneError> {
    let format = MeshFormat::from_path(path)?;
    let io = |source| SceneError::Io {
        path: path.display().to_string(),
        source,
    };
    let mut file = AtomicFile::create(path).map_err(io)?;
    match format {
        MeshFormat::Obj => write_obj(mesh, &mut file),
        MeshFormat::Stl => write_stl(mesh, &mut file),
    }
    .and_then(|()| file.commit())
    .map_err(io)
}

/// The README's example, compiled and run as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;

/// Parses `X,Y,Z` into a finite vector.
pub fn parse_vec3(s: &str) -> Result<glam::DVec3, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(format!(
            "expected three comma-separated numbers X,Y,Z, got {} value(s)",
            parts.len()
        ));
    }
    let mut v = [0.0; 3];
    for (out, p) in v.iter_mut().zip(&parts) {
        *out = p
            .parse::<f64>()
            .map_err(|_| format!("`{p}` is not a number (expected X,Y,Z)"))?;
        if !out.is_finite() {
            return Err(format!("`{p}` is not a finite number"));
        }
    }
    Ok(glam::DVec3::from_array(v))
}

/// Parses `AX,AY,AZ:DEGREES`: a rotation axis (not zero) and a finite
/// angle in degrees.
pub fn parse_spin(s: &str) -> Result<(glam::DVec3, f64), String> {
    let (axis, deg) = s
        .rsplit_once(':')
        .ok_or_else(|| format!("expected AX,AY,AZ:DEGREES, got `{s}`"))?;
    let axis = parse_vec3(axis)?;
    if axis.length_squared() == 0.0 {
        return Err("the spin axis is zero".into());
    }
    let deg: f64 = deg
        .trim()
        .parse()
        .map_err(|_| format!("`{deg}` is not a number of degrees"))?;
    if !deg.is_finite() {
        return Err(format!("`{deg}` is not a finite number of degrees"));
    }
    Ok((axis, deg))
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
    fn save_then_load_in_both_formats() {
        let chair = scene("chair").unwrap();
        let dir = temp("unused", b"").with_file_name("");
        for name in ["chair.obj", "chair.STL"] {
            let p = dir.join(name);
            save(&p, &chair).unwrap();
            let back = load(&p).unwrap();
            assert!(back.is_closed_oriented(), "{name}");
            assert_eq!(back.triangle_count(), chair.triangle_count(), "{name}");
            assert_eq!(back.signed_volume(), chair.signed_volume(), "{name}");
        }
        let e = save(&dir.join("no_such_dir").join("x.obj"), &chair).unwrap_err();
        assert!(matches!(e, SceneError::Io { .. }));
        assert!(e.to_string().contains("x.obj"), "{e}");
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
    fn binary_files_are_not_obj() {
        let bin = temp("image.obj", b"v 0 0 0\n\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR");
        let e = load(&bin).unwrap_err();
        assert_eq!(e.line(), Some(4));
        assert!(e.to_string().contains("binary data"), "{e}");
        assert!(e.to_string().contains("not an OBJ file"), "{e}");
        // random bytes named .stl are not STL either
        let junk: Vec<u8> = (0..1000u32).map(|i| (i * 7919 % 251) as u8).collect();
        let stl = temp("junk.stl", &junk);
        assert!(matches!(load(&stl), Err(SceneError::Parse { .. })));
    }

    #[test]
    fn bytes_that_are_not_utf8_are_replaced() {
        // a Latin-1 comment and group name: the geometry reads as it is
        let text = b"# caf\xe9\nv 0 0 0\nv 1 0 0\nv 0 1 0\ng t\xeate\nf 1 2 3\n";
        let m = load(&temp("latin1.obj", text)).unwrap();
        assert_eq!(m.positions.len(), 3);
        assert_eq!(m.faces[0].vertices, vec![0, 1, 2]);
        assert_eq!(m.group_name(0), "t\u{fffd}te");
        // where a number is expected, the replaced byte is an error there
        let e = load(&temp("latin1_bad.obj", b"v 0 0 0\nv 1 \xe9 0\n")).unwrap_err();
        assert_eq!(e.line(), Some(2));
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
