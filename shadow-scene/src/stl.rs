//! STL (binary and ASCII) through the `stl_io` crate.

use std::borrow::Cow;
use std::io::{Cursor, Write};
use std::path::Path;

use glam::DVec3;

use crate::{Face, Mesh, MeshView, SceneError};

/// Reads a binary or ASCII STL file; see [`parse_stl`].
pub fn read_stl(path: &Path) -> Result<Mesh, SceneError> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| SceneError::Io {
        path: name.clone(),
        source,
    })?;
    parse_stl(&bytes, &name)
}

/// Parses the bytes of a binary or ASCII STL file; `path_for_messages`
/// names the file in errors.
///
/// Every facet becomes a triangle face in group `"default"`; vertices with
/// exactly equal positions (after the exact widening of `f32` to `f64`) are
/// welded, so neighbouring triangles share them. A binary file whose header
/// happens to start with `solid` is recognised by its size or its NUL
/// bytes. A binary file's size must be what its triangle count says: a
/// shorter or longer one is an error, not a guess. Errors say which
/// triangle is bad; the line is 0 as `stl_io` does not report lines.
///
/// ```
/// use shadow_scene::parse_stl;
/// let empty = parse_stl(b"", "e.stl").unwrap_err().to_string();
/// assert!(empty.contains("80-byte header"), "{empty}");
/// let text = b"solid t
/// facet normal 0 0 1
///   outer loop
///     vertex 0 0 0
///     vertex 1 0 0
///     vertex 0 1 0
///   endloop
/// endfacet
/// endsolid t
/// ";
/// let mesh = parse_stl(text, "t.stl").unwrap();
/// assert_eq!((mesh.positions.len(), mesh.faces.len()), (3, 1));
/// ```
pub fn parse_stl(bytes: &[u8], path_for_messages: &str) -> Result<Mesh, SceneError> {
    let err = |message: String| SceneError::Parse {
        path: path_for_messages.to_string(),
        line: 0,
        message,
    };
    // an ASCII file may start with a byte-order mark (a binary one's
    // header is free text, and its size tells it)
    let bytes = match bytes.strip_prefix(b"\xEF\xBB\xBF") {
        Some(text) if !looks_binary(bytes) && text.trim_ascii_start().starts_with(b"solid") => text,
        _ => bytes,
    };
    if !bytes.trim_ascii_start().starts_with(b"solid") && bytes.len() < 84 {
        return Err(err(format!(
            "invalid STL: a binary STL file has an 80-byte header and a 4-byte triangle count; this one \
             has {} byte(s) in all",
            bytes.len()
        )));
    }
    // A binary file's size must be what its count of triangles says:
    // shorter, it was cut short (stl_io says only "failed to fill whole
    // buffer"); longer, the count may be one a writer never filled in,
    // and reading only what it counts would drop triangles unsaid. A
    // NUL byte marks a binary file whose header starts with "solid":
    // ASCII STL has none.
    let binary = bytes.len() >= 84
        && (!bytes.trim_ascii_start().starts_with(b"solid")
            || looks_binary(bytes)
            || bytes.contains(&0));
    if binary {
        let n = u64::from(u32::from_le_bytes([
            bytes[80], bytes[81], bytes[82], bytes[83],
        ]));
        let (want, have) = (84 + 50 * n, bytes.len() as u64);
        if have < want {
            return Err(err(format!(
                "invalid STL at triangle {}: the file is cut short: its header counts {n} \
                 triangle(s), {want} bytes in all, and it has {have}",
                (have - 84) / 50 + 1
            )));
        }
        if have > want {
            let fits = match (have - 84) % 50 {
                0 => format!(" (its size fits {} triangles)", (have - 84) / 50),
                _ => String::new(),
            };
            return Err(err(format!(
                "invalid binary STL: its header counts {n} triangle(s), {want} bytes in all, \
                 but the file has {have}{fits}: {} byte(s) after the last counted triangle",
                have - want
            )));
        }
    }
    let mut data = Cow::Borrowed(bytes);
    if binary && bytes.starts_with(b"solid") {
        // stl_io takes any file starting with "solid " for ASCII; the
        // 80-byte header of a binary file is free text, so hide the word
        let mut owned = bytes.to_vec();
        owned[..5].copy_from_slice(b"SOLID");
        data = Cow::Owned(owned);
    }
    let mut cursor = Cursor::new(&data[..]);
    let reader =
        stl_io::create_stl_reader(&mut cursor).map_err(|e| err(format!("invalid STL: {e}")))?;
    let mut mesh = Mesh {
        groups: vec!["default".to_string()],
        ..Mesh::default()
    };
    for (i, triangle) in reader.enumerate() {
        let t = triangle.map_err(|e| err(format!("invalid STL at triangle {}: {e}", i + 1)))?;
        let base = mesh.positions.len() as u32;
        for v in t.vertices {
            let p = DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64);
            if !p.is_finite() {
                return Err(err(format!(
                    "triangle {} has a NaN or infinite coordinate",
                    i + 1
                )));
            }
            mesh.positions.push(p);
        }
        mesh.faces.push(Face {
            vertices: vec![base, base + 1, base + 2],
            line: 0,
            group: 0,
        });
    }
    mesh.weld();
    Ok(mesh)
}

/// Writes `mesh` as binary STL (through `stl_io`).
///
/// Faces with more than three vertices are fan-triangulated from their
/// first vertex, which is right for convex faces. Each facet's normal is
/// the unit normal of its triangle (zero for a triangle without area).
/// Binary STL stores `f32`: every coordinate is rounded to the nearest
/// `f32`, so positions that differ by less than an `f32` step may become
/// equal (see [`stl_collisions`]); groups are not stored.
///
/// ```
/// use shadow_scene::{parse_stl, write_stl};
/// let cube = shadow_scene::scene("cube").unwrap();
/// let mut bytes = Vec::new();
/// write_stl(&cube, &mut bytes).unwrap();
/// assert_eq!(bytes.len(), 84 + 50 * cube.triangle_count());
/// let back = parse_stl(&bytes, "cube.stl").unwrap();
/// assert!(back.is_closed_oriented());
/// assert_eq!(back.signed_volume(), cube.signed_volume());
/// ```
pub fn write_stl<M: MeshView + ?Sized, W: Write>(mesh: &M, mut out: W) -> std::io::Result<()> {
    let count = (0..mesh.face_count())
        .map(|f| mesh.face(f).len().saturating_sub(2))
        .sum();
    let mut triangles = Vec::with_capacity(count);
    let to32 = |p: DVec3| stl_io::Vector::new([p.x as f32, p.y as f32, p.z as f32]);
    let positions = mesh.positions();
    for f in (0..mesh.face_count()).map(|f| mesh.face(f)) {
        let p = |i: usize| positions[f[i] as usize];
        for i in 1..f.len().saturating_sub(1) {
            let (a, b, c) = (p(0), p(i), p(i + 1));
            let n = crate::unit_or_zero((b - a).cross(c - a));
            triangles.push(stl_io::Triangle {
                normal: to32(n),
                vertices: [to32(a), to32(b), to32(c)],
            });
        }
    }
    if u32::try_from(triangles.len()).is_err() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "binary STL holds at most 2^32 - 1 triangles",
        ));
    }
    stl_io::write_stl(&mut out, triangles.iter())?;
    out.flush()
}

/// How many of the vertices used by faces would share their `f32`
/// rounding with another used vertex of a different `f64` position: the
/// vertices that [`write_stl`] followed by [`parse_stl`] would merge.
/// When it is not zero the written surface may no longer be closed.
///
/// ```
/// use glam::DVec3;
/// use shadow_scene::{stl_collisions, Face, Mesh};
/// let mesh = Mesh {
///     positions: vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0 + 1e-12, 0.0, 0.0), DVec3::Y],
///     faces: vec![Face { vertices: vec![0, 1, 3], line: 0, group: 0 }, Face { vertices: vec![0, 3, 2], line: 0, group: 0 }],
///     groups: vec!["default".into()],
/// };
/// assert_eq!(stl_collisions(&mesh), 1);
/// ```
pub fn stl_collisions<M: MeshView + ?Sized>(mesh: &M) -> usize {
    let key64 = crate::mesh::key;
    let key32 = |p: DVec3| [p.x, p.y, p.z].map(|c| (c as f32 + 0.0).to_bits());
    let mut by32: rustc_hash::FxHashMap<[u32; 3], [u64; 3]> = Default::default();
    let mut distinct64: rustc_hash::FxHashSet<[u64; 3]> = Default::default();
    let mut collisions = 0;
    for p in crate::mesh::used_positions(mesh) {
        if !distinct64.insert(key64(*p)) {
            continue; // an exact repeat: merged by any reader, not by rounding
        }
        let first = *by32.entry(key32(*p)).or_insert(key64(*p));
        if first != key64(*p) {
            collisions += 1;
        }
    }
    collisions
}

/// `true` if the size matches the binary layout: an 80-byte header, a
/// triangle count, and 50 bytes per triangle.
fn looks_binary(bytes: &[u8]) -> bool {
    bytes.len() >= 84 && {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        84 + 50 * n == bytes.len() as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A binary STL of `triangles` with the given 80-byte header start.
    fn binary(header: &[u8], triangles: &[[[f32; 3]; 3]]) -> Vec<u8> {
        let mut out = vec![0u8; 80];
        out[..header.len()].copy_from_slice(header);
        out.extend((triangles.len() as u32).to_le_bytes());
        for t in triangles {
            out.extend([0f32; 3].iter().flat_map(|c| c.to_le_bytes()));
            for v in t {
                out.extend(v.iter().flat_map(|c| c.to_le_bytes()));
            }
            out.extend([0u8; 2]);
        }
        out
    }

    const TETRA: [[[f32; 3]; 3]; 4] = [
        [[0., 0., 0.], [0., 1., 0.], [1., 0., 0.]],
        [[0., 0., 0.], [1., 0., 0.], [0., 0., 1.]],
        [[0., 0., 0.], [0., 0., 1.], [0., 1., 0.]],
        [[1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
    ];

    #[test]
    fn binary_tetra_is_welded_and_closed() {
        let m = parse_stl(&binary(b"made by a test", &TETRA), "t.stl").unwrap();
        assert_eq!((m.positions.len(), m.faces.len()), (4, 4));
        assert!(m.is_closed_oriented());
        assert_eq!(m.signed_volume(), 1.0 / 6.0);
    }

    #[test]
    fn binary_with_solid_header_is_still_binary() {
        let m = parse_stl(&binary(b"solid but binary", &TETRA), "t.stl").unwrap();
        assert_eq!(m.faces.len(), 4);
    }

    #[test]
    fn ascii_tetra() {
        let mut text = String::from("solid tetra\n");
        for t in TETRA {
            text += "facet normal 0 0 0\nouter loop\n";
            for v in t {
                text += &format!("vertex {} {} {}\n", v[0], v[1], v[2]);
            }
            text += "endloop\nendfacet\n";
        }
        text += "endsolid tetra\n";
        let m = parse_stl(text.as_bytes(), "t.stl").unwrap();
        assert_eq!((m.positions.len(), m.faces.len()), (4, 4));
        assert!(m.is_closed_oriented());
        // a byte-order mark in front changes nothing
        let bom = [&b"\xEF\xBB\xBF"[..], text.as_bytes()].concat();
        assert_eq!(parse_stl(&bom, "bom.stl").unwrap(), m);
    }

    #[test]
    fn write_then_read_round_trips_and_fans_quads() {
        let mut m = parse_stl(&binary(b"", &TETRA), "t.stl").unwrap();
        let mut bytes = Vec::new();
        write_stl(&m, &mut bytes).unwrap();
        assert_eq!(bytes.len(), 84 + 50 * 4);
        let back = parse_stl(&bytes, "back.stl").unwrap();
        assert_eq!(back, m);
        // the stored normal of the slanted face is its unit normal
        let t = stl_io::create_stl_reader(&mut Cursor::new(&bytes))
            .unwrap()
            .nth(3)
            .unwrap()
            .unwrap();
        let s = (1.0 / 3f64.sqrt()) as f32;
        assert_eq!(t.normal.0, [s, s, s]);
        // a quad becomes two triangles, a pentagon three
        m.positions.push(DVec3::new(1., 1., 0.));
        m.faces = vec![Face {
            vertices: vec![0, 1, 4, 2],
            line: 0,
            group: 0,
        }];
        let mut bytes = Vec::new();
        write_stl(&m, &mut bytes).unwrap();
        let back = parse_stl(&bytes, "quad.stl").unwrap();
        assert_eq!(back.faces.len(), 2);
        assert_eq!(back.faces[0].vertices, vec![0, 1, 2]);
        assert_eq!(back.faces[1].vertices, vec![0, 2, 3]);
    }

    #[test]
    fn f32_rounding_collisions_are_counted() {
        let mut m = parse_stl(&binary(b"", &TETRA), "t.stl").unwrap();
        assert_eq!(stl_collisions(&m), 0);
        // a position a hair off a used one, used by a face
        let near = DVec3::new(1.0 + 1e-12, 0.0, 0.0);
        assert!(m.positions.contains(&DVec3::X));
        m.positions.push(near);
        m.faces[0].vertices[0] = 4;
        assert_eq!(stl_collisions(&m), 1);
        // exact repeats are not collisions
        m.positions.push(near);
        m.faces[1].vertices[0] = 5;
        assert_eq!(stl_collisions(&m), 1);
    }

    #[test]
    fn errors_name_the_file() {
        let e = parse_stl(b"", "empty.stl").unwrap_err();
        assert!(e.to_string().starts_with("empty.stl: invalid STL"), "{e}");
        let mut bytes = binary(b"", &TETRA);
        bytes.truncate(bytes.len() - 10);
        let e = parse_stl(&bytes, "cut.stl").unwrap_err();
        assert_eq!(
            e.to_string(),
            "cut.stl: invalid STL at triangle 4: the file is cut short: its header counts 4 \
             triangle(s), 284 bytes in all, and it has 274"
        );
        // bytes after the counted triangles: a count never filled in, or
        // a damaged file; with a "solid" header too
        for header in [&b""[..], b"solid but binary"] {
            let mut bytes = binary(header, &TETRA);
            bytes[80] = 2;
            let e = parse_stl(&bytes, "long.stl").unwrap_err();
            assert_eq!(
                e.to_string(),
                "long.stl: invalid binary STL: its header counts 2 triangle(s), 184 bytes in \
                 all, but the file has 284 (its size fits 4 triangles): 100 byte(s) after the \
                 last counted triangle"
            );
            let mut bytes = binary(header, &TETRA);
            bytes.extend(b"pad");
            let e = parse_stl(&bytes, "pad.stl").unwrap_err();
            assert!(
                e.to_string()
                    .ends_with("has 287: 3 byte(s) after the last counted triangle"),
                "{e}"
            );
        }
        let mut bad = TETRA;
        bad[2][1][0] = f32::NAN;
        let e = parse_stl(&binary(b"", &bad), "nan.stl").unwrap_err();
        assert_eq!(
            e.to_string(),
            "nan.stl: triangle 3 has a NaN or infinite coordinate"
        );
        let e = parse_stl(
            b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 zero\n",
            "a.stl",
        )
        .unwrap_err();
        assert!(
            e.to_string()
                .starts_with("a.stl: invalid STL at triangle 1"),
            "{e}"
        );
    }
}
