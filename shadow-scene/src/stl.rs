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
/// Every facet becomes a face in group `"default"` (a triangle; an ASCII
/// facet of more vertices, which some writers make, one polygon); vertices
/// with exactly equal positions are welded, so neighbouring triangles share
/// them. Binary STL is read through `stl_io`, its `f32` coordinates widened
/// exactly to `f64`; ASCII STL by this crate, its decimal coordinates
/// rounded once to `f64` (a coordinate outside `f32`'s range is not read as
/// 0 or infinite). A binary file whose header happens to start with `solid`
/// is recognised by its size or its NUL bytes. A binary file's size must be
/// what its triangle count says: a shorter or longer one is an error, not a
/// guess. Errors in a binary file say which triangle is bad (line 0); in an
/// ASCII file, which line.
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
        Some(text)
            if !looks_binary(bytes)
                && text
                    .trim_ascii_start()
                    .get(..5)
                    .is_some_and(|w| w.eq_ignore_ascii_case(b"solid")) =>
        {
            text
        }
        _ => bytes,
    };
    if !bytes
        .trim_ascii_start()
        .get(..5)
        .is_some_and(|w| w.eq_ignore_ascii_case(b"solid"))
        && bytes.len() < 84
    {
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
        && (!bytes
            .trim_ascii_start()
            .get(..5)
            .is_some_and(|w| w.eq_ignore_ascii_case(b"solid"))
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
    if !binary {
        return parse_ascii(bytes, path_for_messages);
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
/// Reads ASCII STL: `solid [name]`, then facets (`facet normal NX NY NZ`,
/// `outer loop`, `vertex X Y Z` three or more times, `endloop`,
/// `endfacet`), then `endsolid [name]`; several solids may follow one
/// another. Keywords in any case, tokens split by any white space.
/// Coordinates are read as `f64` (correctly rounded from the decimal text),
/// so a coordinate below `f32`'s range is not read as 0, nor one beyond it
/// as infinite. A facet of more than three vertices is kept as one polygon
/// face. Errors name the line.
fn parse_ascii(bytes: &[u8], path: &str) -> Result<Mesh, SceneError> {
    let err = |line: usize, message: String| SceneError::Parse {
        path: path.to_string(),
        line,
        message,
    };
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let line = 1 + bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        err(
            line,
            "invalid ASCII STL: a byte that is not text".to_string(),
        )
    })?;
    let mut tokens = Tokens::new(text);
    let mut mesh = Mesh {
        groups: vec!["default".to_string()],
        ..Mesh::default()
    };
    let mut solids = 0;
    while let Some((word, line)) = tokens.next() {
        if !word.eq_ignore_ascii_case("solid") {
            return Err(err(line, format!("expected `solid`, found `{word}`")));
        }
        solids += 1;
        tokens.skip_name(line);
        loop {
            let (word, line) = tokens.expect("`facet` or `endsolid`", &err)?;
            if word.eq_ignore_ascii_case("endsolid") {
                tokens.skip_name(line);
                break;
            }
            if !word.eq_ignore_ascii_case("facet") {
                return Err(err(
                    line,
                    format!("expected `facet` or `endsolid`, found `{word}`"),
                ));
            }
            tokens.keyword("normal", &err)?;
            for _ in 0..3 {
                tokens.number("the facet's normal", &err)?;
            }
            tokens.keyword("outer", &err)?;
            tokens.keyword("loop", &err)?;
            let base = mesh.positions.len() as u32;
            let end = loop {
                let (word, at) = tokens.expect("`vertex` or `endloop`", &err)?;
                if word.eq_ignore_ascii_case("endloop") {
                    break at;
                }
                if !word.eq_ignore_ascii_case("vertex") {
                    return Err(err(
                        at,
                        format!("expected `vertex` or `endloop`, found `{word}`"),
                    ));
                }
                let mut p = [0.0; 3];
                for c in &mut p {
                    *c = tokens.number("a vertex", &err)?;
                }
                mesh.positions.push(DVec3::from_array(p));
            };
            let n = mesh.positions.len() as u32 - base;
            if n < 3 {
                return Err(err(
                    end,
                    format!("the facet of line {line} has {n} vertices (at least 3)"),
                ));
            }
            tokens.keyword("endfacet", &err)?;
            mesh.faces.push(Face {
                vertices: (base..base + n).collect(),
                line,
                group: 0,
            });
        }
    }
    if solids == 0 {
        return Err(err(1, "invalid ASCII STL: no `solid`".to_string()));
    }
    mesh.weld();
    Ok(mesh)
}

/// The white-space separated words of a text, with their 1-based lines.
struct Tokens<'a> {
    words: std::iter::Peekable<Box<dyn Iterator<Item = (&'a str, usize)> + 'a>>,
    /// The text, whose last line an error at its end names.
    text: &'a str,
}

impl<'a> Tokens<'a> {
    fn new(text: &'a str) -> Tokens<'a> {
        let words: Box<dyn Iterator<Item = (&'a str, usize)> + 'a> = Box::new(
            text.lines()
                .enumerate()
                .flat_map(|(i, l)| l.split_ascii_whitespace().map(move |w| (w, i + 1))),
        );
        Tokens {
            words: words.peekable(),
            text,
        }
    }

    fn next(&mut self) -> Option<(&'a str, usize)> {
        self.words.next()
    }

    /// Passes over a solid's name: the words after `solid` or `endsolid`
    /// on its line, up to a keyword that starts a facet or a solid.
    fn skip_name(&mut self, line: usize) {
        let keyword = |w: &str| {
            ["facet", "endsolid", "solid"]
                .iter()
                .any(|k| w.eq_ignore_ascii_case(k))
        };
        while self
            .words
            .next_if(|&(w, l)| l == line && !keyword(w))
            .is_some()
        {}
    }

    /// The next word, or an error naming `what` was expected.
    fn expect(
        &mut self,
        what: &str,
        err: &impl Fn(usize, String) -> SceneError,
    ) -> Result<(&'a str, usize), SceneError> {
        // (the lines counted only for the error)
        let text = self.text;
        self.next().ok_or_else(|| {
            err(
                text.lines().count().max(1),
                format!("the file ends where {what} was expected"),
            )
        })
    }

    /// The next word, which must be `keyword` (in any case).
    fn keyword(
        &mut self,
        keyword: &str,
        err: &impl Fn(usize, String) -> SceneError,
    ) -> Result<(), SceneError> {
        let (word, line) = self.expect(&format!("`{keyword}`"), err)?;
        match word.eq_ignore_ascii_case(keyword) {
            true => Ok(()),
            false => Err(err(line, format!("expected `{keyword}`, found `{word}`"))),
        }
    }

    /// The next word as a finite number, for `what`.
    fn number(
        &mut self,
        what: &str,
        err: &impl Fn(usize, String) -> SceneError,
    ) -> Result<f64, SceneError> {
        let (word, line) = self.expect(&format!("a number of {what}"), err)?;
        match word.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => Err(err(
                line,
                format!("{what} has a coordinate `{word}` that is not finite"),
            )),
            Err(_) => Err(err(
                line,
                format!("{what} has `{word}` where a number was expected"),
            )),
        }
    }
}

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
    fn ascii_coordinates_are_read_as_f64() {
        // below f32's least subnormal, and beyond its largest value
        let text = "solid tiny\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n\
                    vertex 1e-50 0 0\nvertex 0 3e-50 0\nendloop\nendfacet\n\
                    facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1e39 0 0\n\
                    vertex 0 0.1 0\nendloop\nendfacet\nendsolid tiny\n";
        let m = parse_stl(text.as_bytes(), "tiny.stl").unwrap();
        assert_eq!(m.positions.len(), 5);
        assert_eq!(m.positions[1], DVec3::new(1e-50, 0.0, 0.0));
        assert_eq!(m.positions[2], DVec3::new(0.0, 3e-50, 0.0));
        assert_eq!(m.positions[3], DVec3::new(1e39, 0.0, 0.0));
        // the decimal text rounded once to f64, not through f32
        assert_eq!(m.positions[4], DVec3::new(0.0, 0.1, 0.0));
        assert_eq!((m.faces[0].line, m.faces[1].line), (2, 9));
    }

    #[test]
    fn ascii_keywords_in_any_case_several_solids_and_polygons() {
        let text = "SOLID a\nFACET NORMAL 0 0 1\n OUTER LOOP\n  VERTEX 0 0 0\n  VERTEX 1 0 0\n\
                    VERTEX 1 1 0\n  VERTEX 0 1 0\n ENDLOOP\nENDFACET\nENDSOLID a\n\
                    solid b facet normal 0 0 1 outer loop vertex 0 0 0 vertex 0 1 0 vertex \
                    -1 0 0 endloop endfacet endsolid b";
        let m = parse_stl(text.as_bytes(), "two.stl").unwrap();
        assert_eq!(m.faces.len(), 2);
        assert_eq!(m.faces[0].vertices.len(), 4);
        assert_eq!(m.faces[1].vertices.len(), 3);
        // the shared corners welded
        assert_eq!(m.positions.len(), 5);
    }

    #[test]
    fn ascii_errors_name_the_line() {
        let good = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n\
                    vertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
        let cases: [(&str, &str, &str); 7] = [
            (
                "vertex 1 0 0",
                "vertex 1 x 0",
                "t.stl:5: a vertex has `x` where a number",
            ),
            (
                "vertex 1 0 0",
                "vertex 1 1e999 0",
                "t.stl:5: a vertex has a coordinate `1e999`",
            ),
            (
                "vertex 1 0 0",
                "vertex 1 inf 0",
                "t.stl:5: a vertex has a coordinate `inf`",
            ),
            (
                "outer loop",
                "outer lop",
                "t.stl:3: expected `loop`, found `lop`",
            ),
            (
                "vertex 0 1 0\n",
                "",
                "t.stl:6: the facet of line 2 has 2 vertices (at least 3)",
            ),
            (
                "endsolid t\n",
                "",
                "t.stl:8: the file ends where `facet` or `endsolid`",
            ),
            (
                "endfacet",
                "endfacet\nvertex",
                "t.stl:9: expected `facet` or `endsolid`",
            ),
        ];
        for (from, to, want) in cases {
            let text = good.replacen(from, to, 1);
            let e = parse_stl(text.as_bytes(), "t.stl").unwrap_err().to_string();
            assert!(e.starts_with(want), "{text}: {e}");
        }
        assert!(parse_stl(good.as_bytes(), "t.stl").is_ok());
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
        assert_eq!(
            e.to_string(),
            "a.stl:4: a vertex has `zero` where a number was expected"
        );
    }
}
