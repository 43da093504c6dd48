//! Wavefront OBJ: a hand-written reader that keeps n-gons and reports the
//! line of every error, and a simple writer.

use std::io::Write;
use std::path::Path;

use glam::DVec3;
use rayon::prelude::*;
use rustc_hash::FxHashMap;

use crate::{Face, Mesh, MeshView, SceneError};

/// Reads a Wavefront OBJ file (see [`parse_obj`] for what is understood).
///
/// Bytes that are not UTF-8 are replaced, so they only matter where a
/// number or index is expected.
pub fn read_obj(path: &Path) -> Result<Mesh, SceneError> {
    read_obj_notes(path).map(|(m, _)| m)
}

/// [`read_obj`], with what the reader skipped. A file with a NUL byte is
/// binary, not OBJ: an error naming the line it is on.
pub fn read_obj_notes(path: &Path) -> Result<(Mesh, ObjNotes), SceneError> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| SceneError::Io {
        path: name.clone(),
        source,
    })?;
    // (`contains` on bytes is a fast scan; the place only on a find)
    if bytes.contains(&0)
        && let Some(at) = bytes.iter().position(|&b| b == 0)
    {
        let line = 1 + bytes[..at].iter().filter(|&&b| b == b'\n').count();
        return Err(SceneError::Parse {
            path: name,
            line,
            message: format!("binary data (a NUL byte at byte {at}): not an OBJ file"),
        });
    }
    // valid UTF-8 is read as it is (the strict check is the fast one)
    match std::str::from_utf8(&bytes) {
        Ok(text) => parse_obj_notes(text, &name),
        Err(_) => parse_obj_notes(&String::from_utf8_lossy(&bytes), &name),
    }
}

/// Statements an OBJ reader skipped because it does not know them (a typo
/// such as `V 1 2 3`, or text that is not OBJ). Standard statements it
/// does not use (`vt`, `vn`, `usemtl`, `s`, ...) are not counted.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ObjNotes {
    /// How many statements were unknown.
    pub unknown: usize,
    /// The first one: its 1-based line and its keyword.
    pub first_unknown: Option<(usize, String)>,
}

impl ObjNotes {
    /// A one-line note for the user, or `None` if nothing was skipped.
    ///
    /// ```
    /// use shadow_scene::parse_obj_notes;
    /// let (_, notes) = parse_obj_notes("v 0 0 0\nV 1 0 0\nV 0 1 0\n", "typo.obj").unwrap();
    /// assert_eq!(
    ///     notes.message("typo.obj").unwrap(),
    ///     "typo.obj: skipped 2 unknown statements, the first `V` on line 2"
    /// );
    /// ```
    pub fn message(&self, path: &str) -> Option<String> {
        let (line, keyword) = self.first_unknown.as_ref()?;
        let what = if self.unknown == 1 {
            "statement".to_string()
        } else {
            format!("{} unknown statements, the first", self.unknown)
        };
        Some(if self.unknown == 1 {
            format!("{path}: skipped an unknown {what} `{keyword}` on line {line}")
        } else {
            format!("{path}: skipped {what} `{keyword}` on line {line}")
        })
    }
}

/// Statements of the OBJ format this reader does not use: skipped quietly.
const UNUSED: &[&str] = &[
    "vt",
    "vn",
    "vp",
    "s",
    "usemtl",
    "mtllib",
    "usemap",
    "maplib",
    "l",
    "p",
    "curv",
    "curv2",
    "surf",
    "parm",
    "trim",
    "hole",
    "scrv",
    "sp",
    "end",
    "con",
    "cstype",
    "deg",
    "bmat",
    "step",
    "mg",
    "bevel",
    "c_interp",
    "d_interp",
    "lod",
    "shadow_obj",
    "trace_obj",
    "ctech",
    "stech",
    "call",
    "csh",
];

/// Parses the text of a Wavefront OBJ file; `path_for_messages` names the
/// file in errors.
///
/// Understood statements:
/// - `v x y z [w]` (a trailing `r g b` vertex colour is accepted too; `w`
///   and colours are ignored),
/// - `f` with `i`, `i/t`, `i//n` or `i/t/n` vertices, where negative
///   indices count back from the last vertex read so far; faces keep every
///   vertex (quads stay quads),
/// - `g` and `o`, which start a group (a bare `g` returns to `"default"`);
///   names reused later continue the same group,
/// - `#` comments, blank lines, and a `\` at the end of a line joining it
///   to the next.
///
/// The other statements of the format (`vt`, `vn`, `vp`, `s`, `usemtl`,
/// `mtllib`, `l`, `p`, curves and surfaces) are skipped; so are unknown
/// ones, which [`parse_obj_notes`] counts.
///
/// Errors ([`SceneError::Parse`], with the 1-based line where the
/// statement starts): a number that does not parse, a NaN or infinite
/// coordinate, a vertex index of 0 or out of range, a face with fewer than
/// three vertices.
///
/// ```
/// use shadow_scene::parse_obj;
/// let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\ng top\nf -4 -3 -2 -1\n";
/// let mesh = parse_obj(text, "quad.obj").unwrap();
/// assert_eq!(mesh.faces[0].vertices, vec![0, 1, 2, 3]);
/// assert_eq!(mesh.group_name(0), "top");
///
/// let err = parse_obj("v 0 0 0\nf 1 2 3\n", "bad.obj").unwrap_err();
/// assert_eq!(err.to_string(), "bad.obj:2: face index 2 out of range (1..=1)");
/// ```
pub fn parse_obj(text: &str, path_for_messages: &str) -> Result<Mesh, SceneError> {
    parse_obj_notes(text, path_for_messages).map(|(m, _)| m)
}

/// [`parse_obj`], with the unknown statements it skipped.
///
/// A large text is read in parallel: cut at line ends into pieces of
/// about 256 KiB (never inside a statement that a `\` continues),
/// each piece's words and numbers read on its own, then the pieces joined
/// in order. The mesh, the notes and the first error are those of reading
/// it line by line.
pub fn parse_obj_notes(
    text: &str,
    path_for_messages: &str,
) -> Result<(Mesh, ObjNotes), SceneError> {
    // (a byte-order mark some editors write is no statement)
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    parse_in_pieces(text, path_for_messages, PIECE_BYTES)
}

/// The size of the pieces a large OBJ text is read in, in parallel.
const PIECE_BYTES: usize = 1 << 18;

fn parse_in_pieces(
    text: &str,
    path_for_messages: &str,
    piece_bytes: usize,
) -> Result<(Mesh, ObjNotes), SceneError> {
    let spans = pieces(text, piece_bytes);
    let read: Vec<Piece> = match spans.len() {
        1 => vec![Piece::read(text)],
        _ => spans
            .par_iter()
            .map(|r| Piece::read(&text[r.clone()]))
            .collect(),
    };
    join_pieces(read, path_for_messages)
}

/// Byte ranges that cut `text` at line ends into pieces of about `size`
/// bytes; a piece never ends on a line that a `\` continues.
fn pieces(text: &str, size: usize) -> Vec<std::ops::Range<usize>> {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    let mut start = 0;
    while start < bytes.len() {
        let mut end = (start + size.max(1)).min(bytes.len());
        loop {
            // the end of the line the cut falls in
            end = match bytes[end.max(1) - 1..].iter().position(|&c| c == b'\n') {
                Some(at) => end.max(1) + at,
                None => bytes.len(),
            };
            let line_start = bytes[..end - 1]
                .iter()
                .rposition(|&c| c == b'\n')
                .map_or(0, |at| at + 1);
            let continued =
                end < bytes.len() && text[line_start..end - 1].trim_end().ends_with('\\');
            if !continued {
                break;
            }
            end += 1;
        }
        out.push(start..end);
        start = end;
    }
    if out.is_empty() {
        out.push(0..0);
    }
    out
}

/// A face as a piece reads it: its vertex indices as written (the
/// piece's list of them from the face before's `end` to its own),
/// resolved when the vertices before the piece are counted.
struct RawFace {
    /// One past its last index in [`Piece::indices`].
    end: usize,
    /// Its line, counted from the piece's first (1-based).
    line: usize,
    /// The piece's `g`/`o` statement it follows, if any.
    group: Option<u32>,
    /// The vertices the piece read before it.
    vertices_before: usize,
}

/// What one piece of an OBJ text holds, read on its own.
#[derive(Default)]
struct Piece {
    positions: Vec<DVec3>,
    indices: Vec<i64>,
    faces: Vec<RawFace>,
    /// The names of its `g` and `o` statements, in order.
    groups: Vec<String>,
    notes: ObjNotes,
    /// The first statement that could not be read: its line, the message,
    /// and for a face the indices read before it went wrong (resolved
    /// first: an index out of range before the error is reported first).
    error: Option<(usize, String, Option<RawFace>)>,
    /// The lines it spans.
    lines: usize,
}

impl Piece {
    fn read(text: &str) -> Piece {
        let mut piece = Piece {
            lines: text.bytes().filter(|&c| c == b'\n').count()
                + usize::from(!text.ends_with('\n')),
            ..Piece::default()
        };
        let mut group = None;
        let mut lines = Lines(text).enumerate();
        let mut statement = String::new();
        while let Some((i, first)) = lines.next() {
            let line = i + 1;
            // a line read as it is, unless it goes on to the next (copied then)
            let mut current = first.trim_end();
            let whole: &str = if current.ends_with('\\') {
                statement.clear();
                while let Some(head) = current.strip_suffix('\\') {
                    statement.push_str(head);
                    statement.push(' ');
                    match lines.next() {
                        Some((_, next)) => current = next.trim_end(),
                        None => {
                            current = "";
                            break;
                        }
                    }
                }
                statement.push_str(current);
                &statement
            } else {
                current
            };
            let mut tokens = Tokens::of(whole);
            let Some(keyword) = tokens.next() else {
                continue;
            };
            match keyword {
                "v" => match parse_vertex(tokens) {
                    Ok(p) => piece.positions.push(p),
                    Err(message) => {
                        piece.error = Some((line, message, None));
                        break;
                    }
                },
                "f" => {
                    let read = parse_face(tokens, &mut piece.indices);
                    let face = RawFace {
                        end: piece.indices.len(),
                        line,
                        group,
                        vertices_before: piece.positions.len(),
                    };
                    if let Err(message) = read {
                        piece.error = Some((line, message, Some(face)));
                        break;
                    }
                    piece.faces.push(face);
                }
                "g" | "o" => {
                    let name = tokens.collect::<Vec<_>>().join(" ");
                    group = Some(piece.groups.len() as u32);
                    piece.groups.push(if name.is_empty() {
                        "default".to_string()
                    } else {
                        name
                    });
                }
                k if UNUSED.contains(&k) => {}
                k => {
                    piece.notes.unknown += 1;
                    if piece.notes.first_unknown.is_none() {
                        let shown: String = k.chars().take(24).collect();
                        piece.notes.first_unknown = Some((line, shown));
                    }
                }
            }
        }
        piece
    }
}

/// The pieces joined in order: the vertices before each piece counted, its
/// faces' indices resolved (in parallel) and its groups numbered as the
/// file's `g` lines number them.
fn join_pieces(read: Vec<Piece>, path: &str) -> Result<(Mesh, ObjNotes), SceneError> {
    let mut mesh = Mesh {
        groups: vec!["default".to_string()],
        ..Mesh::default()
    };
    let mut notes = ObjNotes::default();
    // (a map from names: a file may have a group a face)
    let mut numbers: FxHashMap<String, u32> = FxHashMap::default();
    numbers.insert("default".to_string(), 0);
    let mut starts = Vec::with_capacity(read.len());
    let (mut vertices, mut lines, mut group) = (0usize, 0usize, 0u32);
    for piece in &read {
        let named: Vec<u32> = (piece.groups.iter())
            .map(|name| {
                *numbers.entry(name.clone()).or_insert_with(|| {
                    mesh.groups.push(name.clone());
                    (mesh.groups.len() - 1) as u32
                })
            })
            .collect();
        starts.push((vertices, lines, group, named));
        vertices += piece.positions.len();
        lines += piece.lines;
        group = starts
            .last()
            .and_then(|s| s.3.last().copied())
            .unwrap_or(group);
        notes.unknown += piece.notes.unknown;
        if notes.first_unknown.is_none()
            && let Some((line, keyword)) = &piece.notes.first_unknown
        {
            notes.first_unknown = Some((line + starts.last().map_or(0, |s| s.1), keyword.clone()));
        }
    }
    let err = |line: usize, message: String| SceneError::Parse {
        path: path.to_string(),
        line,
        message,
    };
    let faces: Vec<Result<Vec<Face>, SceneError>> = read
        .par_iter()
        .zip(&starts)
        .map(|(piece, &(base, lines, group, ref named))| {
            let mut faces = Vec::with_capacity(piece.faces.len());
            let mut begin = 0;
            let face_of = |raw: &RawFace, begin: usize| -> Result<Vec<u32>, String> {
                piece.indices[begin..raw.end]
                    .iter()
                    .map(|&i| resolve_index(i, base + raw.vertices_before))
                    .collect()
            };
            for raw in &piece.faces {
                let vertices = face_of(raw, begin).map_err(|m| err(lines + raw.line, m))?;
                begin = raw.end;
                if vertices.len() < 3 {
                    let message =
                        format!("face has {} vertex(es), needs at least 3", vertices.len());
                    return Err(err(lines + raw.line, message));
                }
                let group = raw.group.map_or(group, |g| named[g as usize]);
                faces.push(Face {
                    vertices,
                    line: lines + raw.line,
                    group,
                });
            }
            if let Some((line, message, raw)) = &piece.error {
                if let Some(raw) = raw {
                    face_of(raw, begin).map_err(|m| err(lines + raw.line, m))?;
                }
                return Err(err(lines + line, message.clone()));
            }
            Ok(faces)
        })
        .collect();
    mesh.positions.reserve_exact(vertices);
    for piece in &read {
        mesh.positions.extend_from_slice(&piece.positions);
    }
    mesh.faces
        .reserve_exact(read.iter().map(|p| p.faces.len()).sum());
    for f in faces {
        mesh.faces.extend(f?);
    }
    Ok((mesh, notes))
}

/// The lines of a text, as [`str::lines`] gives them but for a carriage
/// return before the newline, which is left on the line (the parser
/// trims it with the other trailing whitespace): the newline is found by
/// a plain scan of the bytes, where `str::lines` sets up a search for
/// each line, slow for the short lines of a mesh file.
struct Lines<'a>(&'a str);

impl<'a> Iterator for Lines<'a> {
    type Item = &'a str;

    fn next(&mut self) -> Option<&'a str> {
        if self.0.is_empty() {
            return None;
        }
        let end = self.0.bytes().position(|c| c == b'\n');
        let (line, rest) = match end {
            Some(at) => (&self.0[..at], &self.0[at + 1..]),
            None => (self.0, ""),
        };
        self.0 = rest;
        Some(line)
    }
}

/// The whitespace-separated words of a line before any `#`, as
/// [`str::split_whitespace`] gives them; a line of ASCII (nearly every
/// line of every file) is split by its bytes, without decoding
/// characters.
enum Tokens<'a> {
    Ascii(&'a str),
    Any(std::str::SplitWhitespace<'a>),
}

impl<'a> Tokens<'a> {
    fn of(line: &'a str) -> Tokens<'a> {
        if line.is_ascii() {
            let end = line.bytes().position(|c| c == b'#').unwrap_or(line.len());
            return Tokens::Ascii(&line[..end]);
        }
        let content = match line.find('#') {
            Some(at) => &line[..at],
            None => line,
        };
        Tokens::Any(content.split_whitespace())
    }
}

impl<'a> Iterator for Tokens<'a> {
    type Item = &'a str;

    fn next(&mut self) -> Option<&'a str> {
        match self {
            Tokens::Any(words) => words.next(),
            Tokens::Ascii(rest) => {
                // the ASCII characters `char::is_whitespace` accepts:
                // space, and tab through carriage return
                let space = |c: u8| matches!(c, b' ' | b'\t'..=b'\r');
                let b = rest.as_bytes();
                let mut start = 0;
                while start < b.len() && space(b[start]) {
                    start += 1;
                }
                if start == b.len() {
                    *rest = "";
                    return None;
                }
                let mut end = start + 1;
                while end < b.len() && !space(b[end]) {
                    end += 1;
                }
                let word = &rest[start..end];
                *rest = &rest[end..];
                Some(word)
            }
        }
    }
}

fn parse_number(token: &str) -> Result<f64, String> {
    token
        .parse::<f64>()
        .map_err(|_| format!("could not parse `{token}` as a number"))
}

fn parse_vertex<'a>(tokens: impl Iterator<Item = &'a str>) -> Result<DVec3, String> {
    // (no list per line: the numbers are parsed as they come, and the
    // messages are those of a check of all numbers, then their count,
    // then the first three's finiteness)
    let mut xyz = [0.0; 3];
    let mut count = 0usize;
    let mut not_finite: Option<&str> = None;
    for t in tokens {
        let x = parse_number(t)?;
        if count < 3 {
            xyz[count] = x;
            if !x.is_finite() && not_finite.is_none() {
                not_finite = Some(t);
            }
        }
        count += 1;
    }
    if !matches!(count, 3 | 4 | 6 | 7) {
        return Err(format!(
            "vertex has {count} number(s); expected `v x y z [w]`, optionally followed by `r g b`"
        ));
    }
    if let Some(t) = not_finite {
        return Err(format!("coordinate `{t}` is not finite"));
    }
    Ok(DVec3::from_array(xyz))
}

/// The most vertices a face may have: a bound on the memory one line of
/// a file can ask for (the geometry made from a face takes some 40 times
/// its text), far above any real face.
pub const MAX_FACE_VERTICES: usize = 1 << 20;

/// Reads a face's vertex indices as written onto `indices` (resolved, and
/// counted, when the vertices before them are known).
fn parse_face<'a>(
    tokens: impl Iterator<Item = &'a str>,
    indices: &mut Vec<i64>,
) -> Result<(), String> {
    for (count, token) in tokens.enumerate() {
        if count == MAX_FACE_VERTICES {
            return Err(format!(
                "face has more than {MAX_FACE_VERTICES} vertices (the most a face may have)"
            ));
        }
        // (most tokens are a bare index: no search set up for the slashes)
        let (index, rest) = match token.bytes().position(|c| c == b'/') {
            None => (token, [None, None]),
            Some(at) => {
                let mut parts = token[at + 1..].split('/');
                let rest = [parts.next(), parts.next()];
                if parts.next().is_some() {
                    return Err(format!("malformed face vertex `{token}`"));
                }
                (&token[..at], rest)
            }
        };
        for extra in rest.into_iter().flatten().filter(|s| !s.is_empty()) {
            extra.parse::<i64>().map_err(|_| {
                format!("could not parse `{extra}` as a texture or normal index in `{token}`")
            })?;
        }
        let i = index
            .parse::<i64>()
            .map_err(|_| format!("could not parse `{index}` as a vertex index in `{token}`"))?;
        indices.push(i);
    }
    Ok(())
}

/// The 0-based vertex of a 1-based or negative (relative) OBJ index.
fn resolve_index(i: i64, n: usize) -> Result<u32, String> {
    let n64 = n as i64;
    let resolved = match i {
        0 => return Err("face index 0 is invalid (OBJ indices start at 1)".to_string()),
        _ if n == 0 => {
            return Err(format!(
                "face index {i} out of range (no vertices defined yet)"
            ));
        }
        1.. if i <= n64 => i - 1,
        1.. => return Err(format!("face index {i} out of range (1..={n})")),
        _ if -i <= n64 => n64 + i,
        _ => return Err(format!("face index {i} out of range (-{n}..=-1)")),
    };
    u32::try_from(resolved)
        .map_err(|_| format!("face index {i} exceeds the supported vertex count"))
}

/// Writes `mesh` as Wavefront OBJ: every position as `v` (shortest
/// representation that reads back to the same `f64`), faces as 1-based
/// `f` lines, and a `g` line whenever the group changes.
///
/// ```
/// use shadow_scene::{parse_obj, write_obj};
/// let chair = shadow_scene::scene("chair").unwrap();
/// let mut text = Vec::new();
/// write_obj(&chair, &mut text).unwrap();
/// let back = parse_obj(std::str::from_utf8(&text).unwrap(), "chair.obj").unwrap();
/// assert_eq!(back.positions, chair.positions);
/// assert_eq!(back.faces.len(), chair.faces.len());
/// ```
pub fn write_obj<M: MeshView + ?Sized, W: Write>(mesh: &M, mut out: W) -> std::io::Result<()> {
    let positions = mesh.positions();
    writeln!(
        out,
        "# shadow-scene: {} vertices, {} faces",
        positions.len(),
        mesh.face_count()
    )?;
    write_in_runs(&mut out, positions.len(), 64, |text, run| {
        let mut number = zmij::Buffer::new();
        for p in &positions[run] {
            text.push('v');
            for x in [p.x, p.y, p.z] {
                text.push(' ');
                text.push_str(number.format(x));
            }
            text.push('\n');
        }
    })?;
    // a `g` line where the group changes from the face before
    let group_line = |g: u32| {
        let name = mesh
            .group_name(g)
            .map(|s| s.split_whitespace().collect::<Vec<_>>().join(" "))
            .filter(|s| !s.is_empty())
            .unwrap_or_else(|| "default".to_string());
        format!("g {name}\n")
    };
    write_in_runs(&mut out, mesh.face_count(), 24, |text, run| {
        let mut index = itoa::Buffer::new();
        let mut current = run.start.checked_sub(1).map(|i| mesh.group(i));
        for f in run {
            let group = mesh.group(f);
            if current != Some(group) {
                current = Some(group);
                text.push_str(&group_line(group));
            }
            text.push('f');
            for v in mesh.face(f) {
                text.push(' ');
                text.push_str(index.format(u64::from(*v) + 1));
            }
            text.push('\n');
        }
    })?;
    out.flush()
}

/// Writes the lines that `format(text, run)` appends for each run of the
/// items `0..n` (a range of indices), the runs formatted in parallel, a
/// window of runs at a time (so that only a window's text is held), and
/// written in order: the bytes one pass in order writes. `bytes` is a
/// guess at an item's line length.
fn write_in_runs<W: Write>(
    out: &mut W,
    n: usize,
    bytes: usize,
    format: impl Fn(&mut String, std::ops::Range<usize>) + Sync,
) -> std::io::Result<()> {
    use rayon::prelude::*;
    const RUN: usize = 4096;
    const WINDOW: usize = 32 * RUN;
    for window in (0..n).step_by(WINDOW) {
        let end = (window + WINDOW).min(n);
        let texts: Vec<String> = (window..end)
            .into_par_iter()
            .step_by(RUN)
            .map(|first| {
                let run = first..(first + RUN).min(end);
                let mut text = String::with_capacity(bytes * run.len());
                format(&mut text, run);
                text
            })
            .collect();
        texts.iter().try_for_each(|t| out.write_all(t.as_bytes()))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One step of the xorshift generator (13, 7, 17) the tests draw
    /// their cases from: the new state, which is also the number drawn.
    fn xorshift(state: &mut u64) -> u64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        *state
    }

    /// A byte-order mark before the first statement is not part of it
    /// (it made `v` an unknown statement and every index one off).
    #[test]
    fn a_byte_order_mark_is_no_statement() {
        let text = "v 0 0 0\nv 10 0 0\nv 10 10 0\nv 0 10 0\nf 1 2 3 4\n";
        let (plain, _) = parse_obj_notes(text, "a.obj").unwrap();
        let (bom, notes) = parse_obj_notes(&format!("\u{feff}{text}"), "a.obj").unwrap();
        assert_eq!((bom, notes), (plain, ObjNotes::default()));
    }

    /// The lines are `str::lines`' once trailing whitespace is trimmed
    /// (the parser trims every line), with or without a final newline,
    /// with `\r\n` endings, empty lines and lone carriage returns.
    #[test]
    fn lines_are_split_as_str_lines_splits_them() {
        let mut seed = 0x6a09_e667_f3bc_c909u64;
        let mut next = |m: u64| xorshift(&mut seed) % m;
        let pieces = ["\n", "\r\n", "\r", "v 1 2 3", " ", "f 1 2 3", "é"];
        for _ in 0..5_000 {
            let text: String = (0..next(12))
                .map(|_| pieces[next(pieces.len() as u64) as usize])
                .collect();
            let want: Vec<&str> = text.lines().map(str::trim_end).collect();
            let got: Vec<&str> = Lines(&text).map(str::trim_end).collect();
            assert_eq!(got, want, "{text:?}");
        }
    }

    /// A line's words are `split_whitespace`'s of the text before its
    /// first `#`, whatever characters separate them: every ASCII
    /// character, and a few others (no-break space, next line, an
    /// em space, letters beyond ASCII).
    #[test]
    fn words_are_split_as_split_whitespace_splits_them() {
        let mut seed = 0x853c_49e6_748f_ea9bu64;
        let mut next = |m: u64| xorshift(&mut seed) % m;
        let others = ['\u{a0}', '\u{85}', '\u{2003}', 'é', '\u{1680}'];
        for round in 0..20_000 {
            let line: String = (0..next(24))
                .map(|_| match next(4) {
                    0 if round % 3 == 0 => others[next(others.len() as u64) as usize],
                    0 | 1 => char::from(next(128) as u8),
                    _ => char::from(b'0' + next(10) as u8),
                })
                .collect();
            let content = line.find('#').map_or(line.as_str(), |at| &line[..at]);
            let want: Vec<&str> = content.split_whitespace().collect();
            let got: Vec<&str> = Tokens::of(&line).collect();
            assert_eq!(got, want, "{line:?}");
        }
    }

    fn parse(text: &str) -> Result<Mesh, SceneError> {
        parse_obj(text, "test.obj")
    }

    /// Read in pieces of any size (in parallel), a text gives the mesh,
    /// notes and first error of reading it whole: statements continued
    /// over lines, groups named in one piece and used in the next,
    /// relative indices reaching back into earlier pieces, and errors of
    /// every kind, in any piece.
    #[test]
    fn pieces_read_as_the_whole_text_reads() {
        let mut seed = 0x3c6e_f372_fe94_f82bu64;
        let mut next = |m: u64| xorshift(&mut seed) % m;
        let statements = [
            "v 0 0 0",
            "v 1 0 0",
            "v 0 1 0",
            "v 1 1 1",
            "f 1 2 3",
            "f -1 -2 -3",
            "f -3 -2 -1 -4",
            "f 1/1 2//2 3/3/3",
            "g a",
            "g b c",
            "g",
            "o a",
            "vt 0 0",
            "# note",
            "",
            "  ",
            "\r",
            "f 1 2 \\",
            "v 1 \\",
            "V 1 2 3",
            "foo",
            "g b c",
            "é 1",
        ];
        let wrong = [
            "f 9 1 2",
            "f 0 1 2",
            "f 1 2",
            "v 1 x 2",
            "v 1 2 inf",
            "f 1 2 -9",
            "f 1/2/3/4 1 2",
            "f -1 -2 z",
            "f 1 99 z",
        ];
        let (mut read, mut failed) = (0, 0);
        for round in 0..3_000 {
            let n = next(40) as usize;
            let mut text = "v 0 0 1\nv 0 1 1\nv 1 0 1\nv 1 1 2\n".to_string();
            for _ in 0..n {
                let s = match next(60) {
                    0 => wrong[next(wrong.len() as u64) as usize],
                    _ => statements[next(statements.len() as u64) as usize],
                };
                text.push_str(s);
                text.push_str(if next(5) == 0 { "\r\n" } else { "\n" });
            }
            if round % 7 == 0 {
                text.pop();
            }
            let whole = parse_in_pieces(&text, "t.obj", usize::MAX);
            match &whole {
                Ok(_) => read += 1,
                Err(_) => failed += 1,
            }
            for size in [1, 2, 5, 9, 17, 40] {
                let cut = parse_in_pieces(&text, "t.obj", size);
                match (&whole, &cut) {
                    (Ok(a), Ok(b)) => assert_eq!(a, b, "{text:?}, pieces of {size}"),
                    (Err(a), Err(b)) => {
                        assert_eq!(a.to_string(), b.to_string(), "{text:?}, pieces of {size}")
                    }
                    _ => panic!("{text:?}, pieces of {size}: {whole:?} against {cut:?}"),
                }
            }
        }
        // both kinds of outcome, often
        assert!(read > 500 && failed > 500, "{read} read, {failed} failed");
    }

    /// A face's indices are resolved in order before a later word fails
    /// to read: the first thing wrong on the line is reported.
    #[test]
    fn a_face_reports_its_first_fault() {
        let err = |text: &str| parse(text).unwrap_err().to_string();
        assert_eq!(
            err("v 0 0 0\nf 1 5 z\n"),
            "test.obj:2: face index 5 out of range (1..=1)"
        );
        assert_eq!(
            err("v 0 0 0\nf 1 1 z\n"),
            "test.obj:2: could not parse `z` as a vertex index in `z`"
        );
        assert_eq!(
            err("v 0 0 0\nf 1 1\nv x\n"),
            "test.obj:2: face has 2 vertex(es), needs at least 3"
        );
    }

    /// The pieces cover the text, end at line ends, and never end on a
    /// line that a backslash continues.
    #[test]
    fn pieces_end_at_statement_ends() {
        let text = "v 1 \\\n2 3\nf 1 \\  \r\n2 \\\n3\n\ng a\n";
        for size in 1..text.len() + 2 {
            let spans = pieces(text, size);
            assert_eq!(spans.first().unwrap().start, 0);
            assert_eq!(spans.last().unwrap().end, text.len());
            for w in spans.windows(2) {
                assert_eq!(w[0].end, w[1].start);
                let line = text[..w[0].end - 1].rsplit('\n').next().unwrap();
                assert!(text.as_bytes()[w[0].end - 1] == b'\n' && !line.trim_end().ends_with('\\'));
            }
        }
    }

    /// The line and message of a parse error.
    fn error(text: &str) -> (usize, String) {
        match parse(text).unwrap_err() {
            SceneError::Parse {
                path,
                line,
                message,
            } => {
                assert_eq!(path, "test.obj");
                (line, message)
            }
            e => panic!("expected a parse error, got {e:?}"),
        }
    }

    const CUBE: &str = "\
# a unit cube made of quads
mtllib cube.mtl
o cube
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
vt 0 0
vn 0 0 1
usemtl wood
s off
f 1 4 3 2
f 5 6 7 8
f 1/1 2/1 6/1 5/1
f 2//1 3//1 7//1 6//1
f 3/1/1 4/1/1 8/1/1 7/1/1
f 4 1 5 8
";

    #[test]
    fn cube_of_quads_keeps_quads() {
        let m = parse(CUBE).unwrap();
        assert_eq!(m.positions.len(), 8);
        assert_eq!(m.faces.len(), 6);
        assert!(m.faces.iter().all(|f| f.vertices.len() == 4));
        assert_eq!(m.faces[0].vertices, vec![0, 3, 2, 1]);
        assert_eq!(m.faces[0].line, 16);
        assert_eq!(m.groups, vec!["default", "cube"]);
        assert!(m.faces.iter().all(|f| f.group == 1));
        assert!(m.is_closed_oriented());
        assert_eq!(m.signed_volume(), 1.0);
    }

    #[test]
    fn n_gons_are_kept_whole() {
        let mut text = String::new();
        for k in 0..7 {
            let a = k as f64 * std::f64::consts::TAU / 7.0;
            text += &format!("v {} {} 0\n", a.cos(), a.sin());
        }
        text += "f 1 2 3 4 5 6 7\n";
        let m = parse(&text).unwrap();
        assert_eq!(m.faces[0].vertices, (0..7).collect::<Vec<u32>>());
    }

    #[test]
    fn negative_indices_are_relative_to_the_vertices_so_far() {
        let m = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 0 0 1\nf -4 -1 -3\n").unwrap();
        assert_eq!(m.faces[0].vertices, vec![0, 1, 2]);
        assert_eq!(m.faces[1].vertices, vec![0, 3, 1]);
        let (line, msg) = error("v 0 0 0\nv 1 0 0\nf -1 -2 -3\n");
        assert_eq!(
            (line, msg.as_str()),
            (3, "face index -3 out of range (-2..=-1)")
        );
    }

    #[test]
    fn groups_and_objects() {
        let m = parse(
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\ng legs\nf 1 2 3\no table top\nf 1 2 3\ng legs\nf 1 2 3\ng\nf 1 2 3\n",
        )
        .unwrap();
        assert_eq!(m.groups, vec!["default", "legs", "table top"]);
        let groups: Vec<u32> = m.faces.iter().map(|f| f.group).collect();
        assert_eq!(groups, vec![0, 1, 2, 1, 0]);
        assert_eq!(m.group_name(2), "table top");
    }

    #[test]
    fn comments_blank_lines_crlf_and_continuations() {
        let m = parse("# header\r\n\r\nv 0 0 0 # origin\r\nv 1 \\\r\n 0 0\r\nv 0 1 0\r\nf 1 2 \\\n3\n\nf 1 2 x\n")
            .unwrap_err();
        // the continued face starts on line 7; the bad face is on line 10
        assert_eq!(m.line(), Some(10));
        let m =
            parse("# header\r\n\r\nv 0 0 0 # origin\r\nv 1 \\\r\n 0 0\r\nv 0 1 0\r\nf 1 2 \\\n3\n")
                .unwrap();
        assert_eq!(m.positions[1], DVec3::X);
        assert_eq!(m.faces[0].vertices, vec![0, 1, 2]);
        assert_eq!(m.faces[0].line, 7);
    }

    #[test]
    fn ignored_statements() {
        let text = "v 0 0 0\nv 1 0 0 1\nv 0 1 0 0.5 0.5 0.5\nvt 0.5 0.5\nvn 0 0 1\nvp 0.1\nl 1 2\np 1\ncurv 0 1 1 2\nmtllib a.mtl\nusemtl red\ns 1\no thing\nf 1 2 3\n";
        let (m, notes) = parse_obj_notes(text, "ok.obj").unwrap();
        assert_eq!(m.positions.len(), 3);
        assert_eq!(m.faces.len(), 1);
        // standard statements are skipped quietly
        assert_eq!(notes, ObjNotes::default());
        assert_eq!(notes.message("ok.obj"), None);
    }

    #[test]
    fn unknown_statements_are_counted_with_the_first_line() {
        let (m, notes) = parse_obj_notes(
            "v 0 0 0\nV 1 0 0\nv 0 1 0\nfoo bar\nV 0 0 1\nf 1 2 1\n",
            "t.obj",
        )
        .unwrap();
        assert_eq!((m.positions.len(), m.faces.len()), (2, 1));
        assert_eq!(notes.unknown, 3);
        assert_eq!(notes.first_unknown, Some((2, "V".to_string())));
        let (_, one) = parse_obj_notes("hello world\n", "prose.txt").unwrap();
        assert_eq!(
            one.message("prose.txt").unwrap(),
            "prose.txt: skipped an unknown statement `hello` on line 1"
        );
    }

    #[test]
    fn unparsable_numbers_name_the_line() {
        let (line, msg) = error("v 0 0 0\nv 1 0 0\nv 0 1.0.0 0\n");
        assert_eq!(
            (line, msg.as_str()),
            (3, "could not parse `1.0.0` as a number")
        );
        let (line, msg) = error("v 0 0\n");
        assert_eq!(line, 1);
        assert!(msg.starts_with("vertex has 2 number(s)"), "{msg}");
        let (line, msg) = error("v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 three\n");
        assert_eq!(line, 5);
        assert!(msg.contains("`three`"), "{msg}");
        let (line, _) = error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/a 2 3\n");
        assert_eq!(line, 4);
        let (line, msg) = error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n");
        assert_eq!((line, msg.as_str()), (4, "malformed face vertex `1/1/1/1`"));
    }

    #[test]
    fn non_finite_coordinates_are_rejected() {
        for (bad, tok) in [
            ("nan", "nan"),
            ("inf", "inf"),
            ("-Infinity", "-Infinity"),
            ("1e999", "1e999"),
        ] {
            let (line, msg) = error(&format!("v 0 0 0\n# bad one next\nv 0 {bad} 0\n"));
            assert_eq!(line, 3);
            assert_eq!(msg, format!("coordinate `{tok}` is not finite"));
        }
    }

    #[test]
    fn a_face_of_too_many_vertices_is_refused() {
        let mut text = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\nf");
        for _ in 0..=MAX_FACE_VERTICES {
            text += " 1";
        }
        let (line, msg) = error(&(text + "\n"));
        assert_eq!(line, 4);
        assert!(
            msg.starts_with("face has more than 1048576 vertices"),
            "{msg}"
        );
    }

    #[test]
    fn index_zero_and_out_of_range() {
        let (line, msg) = error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
        assert_eq!(
            (line, msg.as_str()),
            (4, "face index 0 is invalid (OBJ indices start at 1)")
        );
        let (line, msg) = error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9999\n");
        assert_eq!(
            (line, msg.as_str()),
            (5, "face index 9999 out of range (1..=3)")
        );
        let (line, msg) = error("f 1 2 3\n");
        assert_eq!(
            (line, msg.as_str()),
            (1, "face index 1 out of range (no vertices defined yet)")
        );
        // a face may only use vertices defined before it
        let (line, _) = error("v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n");
        assert_eq!(line, 3);
        let (line, _) = error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999\n");
        assert_eq!(line, 4);
    }

    #[test]
    fn faces_need_three_vertices() {
        let (line, msg) = error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n\nf 1 2\n");
        assert_eq!(
            (line, msg.as_str()),
            (6, "face has 2 vertex(es), needs at least 3")
        );
        let (line, _) = error("v 0 0 0\nf\n");
        assert_eq!(line, 2);
    }

    #[test]
    fn write_then_read_round_trips() {
        let m = parse(CUBE).unwrap();
        let mut buf = Vec::new();
        write_obj(&m, &mut buf).unwrap();
        let text = String::from_utf8(buf).unwrap();
        assert!(text.contains("\ng cube\nf 1 4 3 2\n"), "{text}");
        let back = parse(&text).unwrap();
        assert_eq!(back.positions, m.positions);
        let loops = |m: &Mesh| {
            (0..m.faces.len())
                .map(|i| (m.faces[i].vertices.clone(), m.group_name(i).to_string()))
                .collect::<Vec<_>>()
        };
        assert_eq!(loops(&back), loops(&m));
    }

    /// A mesh larger than the writer's runs and windows, with groups that
    /// change within runs, at a run's first face and back, is written
    /// line for line as one pass in order writes it.
    #[test]
    fn a_large_mesh_is_written_as_one_pass_in_order_writes_it() {
        let mut m = Mesh::default();
        for i in 0..300_000u32 {
            let x = f64::from(i);
            m.positions.push(DVec3::new(x / 7.0, -x * 1e-9, x.sqrt()));
        }
        let (a, b) = (m.add_group("a"), m.add_group("b  c"));
        let faces = 200_000u32;
        for i in 0..faces {
            // a run of 4096 faces starts at 4096: group b there, then a
            // run boundary inside a group, and a change at every 1000th face
            let group = if i == 4096 || (i / 1000) % 2 == 1 {
                b
            } else {
                a
            };
            m.faces.push(Face {
                vertices: vec![i, i + 1, i + 2 + i % 5],
                line: 0,
                group,
            });
        }
        let mut buf = Vec::new();
        write_obj(&m, &mut buf).unwrap();
        let mut expected = format!(
            "# shadow-scene: {} vertices, {} faces\n",
            m.positions.len(),
            m.faces.len()
        );
        let mut number = zmij::Buffer::new();
        for p in &m.positions {
            expected += "v";
            for x in [p.x, p.y, p.z] {
                expected += " ";
                expected += number.format(x);
            }
            expected += "\n";
        }
        let mut current = None;
        for f in &m.faces {
            if current != Some(f.group) {
                current = Some(f.group);
                expected += if f.group == a { "g a\n" } else { "g b c\n" };
            }
            let [x, y, z] = [0, 1, 2].map(|k| f.vertices[k] + 1);
            expected += &format!("f {x} {y} {z}\n");
        }
        assert!(String::from_utf8(buf).unwrap() == expected);
    }

    /// Every finite `f64` is written so that it reads back as itself:
    /// random bit patterns (all magnitudes, subnormals, both zeros).
    #[test]
    fn written_numbers_read_back_exactly() {
        let mut seed = 0xbb67_ae85_84ca_a73bu64;
        let mut m = Mesh::default();
        while m.positions.len() < 30_000 {
            let mut c = [0.0; 3];
            for x in &mut c {
                xorshift(&mut seed);
                *x = match seed % 4 {
                    0 => f64::from_bits(seed >> 12),
                    1 => -0.0,
                    _ => f64::from_bits(seed),
                };
            }
            if c.iter().all(|x| x.is_finite()) {
                m.positions.push(DVec3::from_array(c));
            }
        }
        let n = m.positions.len() as u32;
        m.faces.push(Face {
            vertices: vec![1, 2, n - 1],
            line: 0,
            group: 0,
        });
        let mut buf = Vec::new();
        write_obj(&m, &mut buf).unwrap();
        let back = parse(std::str::from_utf8(&buf).unwrap()).unwrap();
        for (a, b) in back.positions.iter().zip(&m.positions) {
            assert_eq!(
                a.to_array().map(f64::to_bits),
                b.to_array().map(f64::to_bits)
            );
        }
        assert_eq!(back.positions.len(), m.positions.len());
    }

    #[test]
    fn write_keeps_awkward_coordinates_exact() {
        let mut m = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        m.positions[0] = DVec3::new(0.1 + 0.2, -1e-300, 1.7976931348623157e308);
        let mut buf = Vec::new();
        write_obj(&m, &mut buf).unwrap();
        let back = parse(std::str::from_utf8(&buf).unwrap()).unwrap();
        assert_eq!(back.positions[0], m.positions[0]);
    }
}
