//! Fragments written to files, batch by batch: JSON (the schema of
//! `shadow shadows`, documented in `docs/shadows.md`) and Wavefront OBJ
//! (groups `lit` and `shadow`). A batch's vertices are rounded once to
//! `f64` grid units and mapped to input units ([`world_vertices`]); each
//! fragment's area is measured on those ([`area_records`]).
//!
//! A caller that shades many batches in parallel formats each one's JSON
//! text where it is shaded ([`json_fragments`]) and writes the texts in
//! order between [`json_header`] and [`json_footer`]; OBJ goes through one
//! [`ObjWriter`], which welds equal positions over the whole file.
//! [`FragmentFile`] does either, batch by batch, and adds up the areas.

use std::collections::HashMap;
use std::io::{self, Write};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use bsp_core::{Grid, Polygon};
use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;

use crate::schedule::{is_one_of, large_receivers, runs};
use crate::{
    AreaClass, Areas, Batch, CHUNK, Light, PlacedLight, ShadeOptions, ShadowSet, SoftFragment,
    SoftLight, SoftShape, polygon_area,
};

/// Why a batch cannot be written.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum ExportError {
    /// A vertex of `face` is not finite in input units: the grid's
    /// coordinates, scaled back, leave `f64`'s range.
    NonFiniteVertex {
        /// The face.
        face: u32,
        /// The grid step in input units.
        step: f64,
    },
}

impl std::fmt::Display for ExportError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ExportError::NonFiniteVertex { face, step } => write!(
                f,
                "a vertex of face {face} is not finite in input units (grid step {step:e}): the \
                 coordinates are too large for f64"
            ),
        }
    }
}

impl std::error::Error for ExportError {}

/// The batch's vertices in input units, each converted once.
pub fn world_vertices(b: &Batch, grid: &Grid) -> Result<Vec<DVec3>, ExportError> {
    let world: Vec<DVec3> = (0..b.vertex_count() as u32)
        .map(|v| grid.to_world(b.rounded(v)))
        .collect();
    if let Some(bad) = world.iter().position(|v| !v.is_finite()) {
        let face = b
            .fragments()
            .find(|f| f.rings().flatten().any(|&v| v as usize == bad))
            .map(|f| f.face())
            .unwrap_or(0);
        return Err(ExportError::NonFiniteVertex {
            face,
            step: grid.step(),
        });
    }
    Ok(world)
}

/// A fragment's face, area and flags, as [`Areas::add`] takes them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AreaRecord {
    /// The fragment's face.
    pub face: u32,
    /// Its area in input units (holes subtracted).
    pub area: f64,
    /// The lights that reach it.
    pub lit: u64,
    /// The lights its face turns toward.
    pub facing: u64,
}

/// Every fragment's [`AreaRecord`], measured on `world` (the batch's
/// vertices in input units).
pub fn area_records(b: &Batch, world: &[DVec3]) -> Vec<AreaRecord> {
    let mut buf = Vec::new();
    b.fragments()
        .map(|f| {
            let mut area = 0.0;
            for (k, ring) in f.rings().enumerate() {
                buf.clear();
                buf.extend(ring.iter().map(|&v| world[v as usize]));
                let a = polygon_area(&buf);
                area += if k == 0 { a } else { -a };
            }
            AreaRecord {
                face: f.face(),
                area,
                lit: f.lit_mask(),
                facing: f.facing_mask(),
            }
        })
        .collect()
}

#[derive(Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
enum JsonLight {
    Point {
        position: [f64; 3],
    },
    Directional {
        direction: [f64; 3],
    },
    Area {
        corners: Vec<[f64; 3]>,
    },
    SunDisc {
        direction: [f64; 3],
        radius_deg: f64,
    },
}

#[derive(Serialize)]
struct JsonSummary {
    area: f64,
    lit_area: Vec<f64>,
    shadow_area: Vec<f64>,
    cast_shadow_area: Vec<f64>,
    dark_area: f64,
}

/// The JSON document's head: the lights, the face count, and the
/// opening of the fragment list.
pub fn json_header(
    out: &mut (impl Write + ?Sized),
    lights: &[PlacedLight],
    faces: usize,
) -> io::Result<()> {
    let lights: Vec<JsonLight> = lights
        .iter()
        .map(|l| match l.light {
            Light::Point(_) => JsonLight::Point {
                position: l.world.to_array(),
            },
            Light::Directional(_) => JsonLight::Directional {
                direction: l.world.to_array(),
            },
        })
        .collect();
    json_head(out, &lights, faces)
}

/// `{"lights":[...],"faces":N,"fragments":[`.
fn json_head(
    out: &mut (impl Write + ?Sized),
    lights: &[JsonLight],
    faces: usize,
) -> io::Result<()> {
    write!(out, "{{\"lights\":")?;
    serde_json::to_writer(&mut *out, lights)?;
    write!(out, ",\"faces\":{faces},\"fragments\":[")
}

/// An OBJ file's first comments: what it holds, and one line per light.
fn obj_head(
    out: &mut (impl Write + ?Sized),
    name: &str,
    lights: &[String],
    faces: usize,
) -> io::Result<()> {
    writeln!(
        out,
        "# shadow shadows: the fragments of {faces} faces of {name}"
    )?;
    for (i, l) in lights.iter().enumerate() {
        writeln!(out, "# light {i}: {l}")?;
    }
    Ok(())
}

/// The JSON document's tail: the fragment list closed, and the summary
/// of `areas`.
pub fn json_footer(out: &mut (impl Write + ?Sized), areas: &Areas) -> io::Result<()> {
    write!(out, "\n],\"summary\":")?;
    let summary = JsonSummary {
        area: areas.total,
        lit_area: areas.lit.clone(),
        shadow_area: areas.shadow(),
        cast_shadow_area: areas.cast.clone(),
        dark_area: areas.dark,
    };
    serde_json::to_writer(&mut *out, &summary)?;
    writeln!(out, "}}")?;
    Ok(())
}

/// Shortest round-trip decimal of a finite `f64`, as `serde_json` writes
/// it.
fn push_f64(s: &mut Vec<u8>, x: f64) {
    let mut b = zmij::Buffer::new();
    // (`+ 0.0` writes a negative zero, such as an empty sum's, as 0)
    s.extend_from_slice(b.format_finite(x + 0.0).as_bytes());
}

fn push_point(s: &mut Vec<u8>, p: DVec3) {
    s.push(b'[');
    push_f64(s, p.x);
    s.push(b',');
    push_f64(s, p.y);
    s.push(b',');
    push_f64(s, p.z);
    s.push(b']');
}

fn push_ring(s: &mut Vec<u8>, ring: &[u32], world: &[DVec3]) {
    push_points(s, ring.iter().map(|&v| world[v as usize]));
}

/// Points as a JSON array of `[x, y, z]`.
fn push_points(s: &mut Vec<u8>, points: impl Iterator<Item = DVec3>) {
    s.push(b'[');
    for (i, p) in points.enumerate() {
        if i > 0 {
            s.push(b',');
        }
        push_point(s, p);
    }
    s.push(b']');
}

/// The fragments of a batch as JSON lines, each preceded by `,\n` (the
/// first fragment of a document drops its comma).
pub fn json_fragments(
    b: &Batch,
    world: &[DVec3],
    records: &[AreaRecord],
    lights: usize,
) -> Vec<u8> {
    let mut s = Vec::with_capacity(b.len() * 160);
    for (f, rec) in b.fragments().zip(records) {
        s.extend_from_slice(b",\n{\"face\":");
        s.extend_from_slice(itoa::Buffer::new().format(f.face()).as_bytes());
        s.extend_from_slice(b",\"vertices\":");
        push_ring(&mut s, f.outer(), world);
        if f.hole_count() > 0 {
            s.extend_from_slice(b",\"holes\":[");
            for (k, ring) in f.rings().skip(1).enumerate() {
                if k > 0 {
                    s.push(b',');
                }
                push_ring(&mut s, ring, world);
            }
            s.push(b']');
        }
        s.extend_from_slice(b",\"lit\":[");
        for j in 0..lights {
            if j > 0 {
                s.push(b',');
            }
            s.extend_from_slice(if f.lit(j) { b"true" } else { b"false" });
        }
        // a point light or a sun has no penumbra: umbra where not lit
        s.extend_from_slice(b"],\"umbra\":[");
        for j in 0..lights {
            if j > 0 {
                s.push(b',');
            }
            s.extend_from_slice(if f.lit(j) { b"false" } else { b"true" });
        }
        s.extend_from_slice(b"],\"area\":");
        push_f64(&mut s, rec.area);
        s.push(b'}');
    }
    s
}

/// The OBJ group of a fragment: `shadow` when no light reaches it, else
/// `lit`, and with several lights also `lit_I_J...` naming exactly the
/// lights that reach it (an OBJ `g` line with two names puts the faces in
/// both groups).
fn obj_group(lit: u64, lights: usize) -> String {
    let on: Vec<String> = (0..lights)
        .filter(|&i| lit >> i & 1 == 1)
        .map(|i| i.to_string())
        .collect();
    match (on.is_empty(), lights) {
        (true, _) => "shadow".to_string(),
        (false, 1) => "lit".to_string(),
        (false, _) => format!("lit lit_{}", on.join("_")),
    }
}

/// Writes OBJ text incrementally: positions welded by exact equality of
/// their `f64` coordinates over the whole file, a `g` line whenever the
/// group changes, each fragment as its convex pieces.
#[derive(Debug, Default)]
pub struct ObjWriter {
    index: HashMap<[u64; 3], u32>,
    group: Option<u64>,
    faces: usize,
    degenerate: usize,
}

impl ObjWriter {
    /// A writer that has written nothing.
    pub fn new() -> ObjWriter {
        ObjWriter::default()
    }

    /// The file's head: what it holds, one comment line per light
    /// (`lights`, described by the caller), and the groups.
    pub fn header(
        &self,
        out: &mut (impl Write + ?Sized),
        name: &str,
        lights: &[String],
        faces: usize,
    ) -> io::Result<()> {
        obj_head(out, name, lights, faces)?;
        if lights.len() > 1 {
            writeln!(
                out,
                "# groups: lit (lit by at least one light), lit_I_J... (lit by exactly lights I, \
                 J, ...), shadow (lit by none)"
            )?;
        } else {
            writeln!(out, "# groups: lit, shadow")?;
        }
        writeln!(
            out,
            "# each fragment as its convex pieces, faces in input order, vertices welded"
        )?;
        Ok(())
    }

    /// Writes every convex piece of the batch's fragments (`world`: its
    /// vertices in input units).
    pub fn batch(
        &mut self,
        out: &mut (impl Write + ?Sized),
        b: &Batch,
        world: &[DVec3],
        lights: usize,
    ) -> io::Result<()> {
        let mut text = Vec::with_capacity(b.len() * 64);
        let mut ids: Vec<u32> = Vec::new();
        for f in b.fragments() {
            if self.group != Some(f.lit_mask()) {
                self.group = Some(f.lit_mask());
                writeln!(text, "g {}", obj_group(f.lit_mask(), lights))?;
            }
            for piece in f.pieces() {
                ids.clear();
                for &v in piece {
                    ids.push(self.vertex(&mut text, world[v as usize]));
                }
                self.face(&mut text, &ids);
            }
        }
        out.write_all(&text)
    }

    /// An `f` line of the positions `ids` (1-based) into `text`.
    fn face(&mut self, text: &mut Vec<u8>, ids: &[u32]) {
        let mut sorted = ids.to_vec();
        sorted.sort_unstable();
        if sorted.windows(2).any(|w| w[0] == w[1]) {
            self.degenerate += 1;
        }
        text.push(b'f');
        for id in ids {
            text.push(b' ');
            text.extend_from_slice(itoa::Buffer::new().format(*id).as_bytes());
        }
        text.push(b'\n');
        self.faces += 1;
    }

    /// The 1-based index of position `p`, written as a `v` line into
    /// `text` the first time.
    fn vertex(&mut self, text: &mut Vec<u8>, p: DVec3) -> u32 {
        let next = self.index.len() as u32 + 1;
        *self
            .index
            .entry(p.to_array().map(f64::to_bits))
            .or_insert_with(|| {
                text.extend_from_slice(b"v ");
                for (k, c) in p.to_array().into_iter().enumerate() {
                    if k > 0 {
                        text.push(b' ');
                    }
                    push_f64(text, c);
                }
                text.push(b'\n');
                next
            })
    }

    /// Positions written so far.
    pub fn vertex_count(&self) -> usize {
        self.index.len()
    }

    /// Pieces written so far whose distinct exact vertices coincide once
    /// rounded to `f64` input units: they are degenerate in the file.
    pub fn degenerate(&self) -> usize {
        self.degenerate
    }
}

/// Receivers shaded per round of [`FragmentFile::stream`]: each round is
/// shaded and formatted in parallel (in chunks of [`CHUNK`]; the large
/// receivers of every round from the start), then written while the next
/// round is shaded (so two rounds are held at once).
const ROUND: usize = CHUNK * 32;

/// What [`FragmentFile::stream`] did.
#[derive(Clone, Copy, Debug, Default)]
pub struct Streamed {
    /// Fragments written.
    pub fragments: usize,
    /// Receivers shaded.
    pub receivers: usize,
    /// Time not spent writing: shading and formatting (in parallel, a
    /// round's beside the writing of the one before).
    pub shading: Duration,
    /// Time spent writing.
    pub writing: Duration,
}

/// A chunk of receivers shaded: the fragments, their vertices in input
/// units, their areas and (for JSON) their text.
type Shaded = (Batch, Vec<DVec3>, Vec<AreaRecord>, Vec<u8>);

/// The format of a [`FragmentFile`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FragmentFormat {
    /// The JSON document of `docs/shadows.md`.
    Json,
    /// Wavefront OBJ, groups `lit` and `shadow`.
    Obj,
}

/// A JSON or OBJ file of fragments, written batch by batch in receiver
/// order; it adds up the fragments' areas, which the JSON's summary
/// reports.
#[derive(Debug)]
pub struct FragmentFile {
    kind: FileKind,
    lights: usize,
    areas: Areas,
}

#[derive(Debug)]
enum FileKind {
    /// Whether the next fragment is the document's first (written without
    /// its separating comma).
    Json {
        first: bool,
    },
    Obj(ObjWriter),
}

/// What a [`FragmentFile`] wrote.
#[derive(Debug)]
pub struct Written {
    /// The fragments' areas, added up.
    pub areas: Areas,
    /// Positions in an OBJ file (0 for JSON).
    pub vertices: usize,
    /// OBJ pieces degenerate once rounded (see [`ObjWriter::degenerate`]).
    pub degenerate: usize,
}

impl FragmentFile {
    /// Writes the file's head for the fragments of `faces` faces lit by
    /// `lights`. `name` (the scene) and `notes` (one line per light) are
    /// the OBJ's comments.
    pub fn begin(
        out: &mut (impl Write + ?Sized),
        format: FragmentFormat,
        lights: &[PlacedLight],
        faces: usize,
        (name, notes): (&str, &[String]),
    ) -> io::Result<FragmentFile> {
        let kind = match format {
            FragmentFormat::Json => {
                json_header(out, lights, faces)?;
                FileKind::Json { first: true }
            }
            FragmentFormat::Obj => {
                let w = ObjWriter::new();
                w.header(out, name, notes, faces)?;
                FileKind::Obj(w)
            }
        };
        Ok(FragmentFile {
            kind,
            lights: lights.len(),
            areas: Areas::new(lights.len(), faces),
        })
    }

    /// Writes batch `b` (`world`: its vertices in input units, `records`:
    /// its areas). `json` is the batch's text from [`json_fragments`] when
    /// the caller formatted it already (in parallel, say); else it is
    /// formatted here.
    pub fn write(
        &mut self,
        out: &mut (impl Write + ?Sized),
        (b, world, records): (&Batch, &[DVec3], &[AreaRecord]),
        json: Option<&[u8]>,
    ) -> io::Result<()> {
        for r in records {
            self.areas.add(r.face, r.area, r.lit, r.facing);
        }
        match &mut self.kind {
            FileKind::Json { first } => {
                let own;
                let text = match json {
                    Some(t) => t,
                    None => {
                        own = json_fragments(b, world, records, self.lights);
                        &own[..]
                    }
                };
                let body = match text.split_first() {
                    Some((_, rest)) if *first => {
                        *first = false;
                        rest
                    }
                    _ => text,
                };
                out.write_all(body)
            }
            FileKind::Obj(w) => w.batch(out, b, world, self.lights),
        }
    }

    /// The whole file of one batch `b` on `grid` in one call: [`begin`],
    /// [`write`], [`finish`]. A vertex that is not finite in input units
    /// is an [`io::ErrorKind::InvalidData`] error carrying the
    /// [`ExportError`].
    ///
    /// [`begin`]: FragmentFile::begin
    /// [`write`]: FragmentFile::write
    /// [`finish`]: FragmentFile::finish
    pub fn of_batch(
        out: &mut (impl Write + ?Sized),
        format: FragmentFormat,
        lights: &[PlacedLight],
        faces: usize,
        (b, grid): (&Batch, &Grid),
    ) -> io::Result<Written> {
        let world =
            world_vertices(b, grid).map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))?;
        let records = area_records(b, &world);
        let mut file = FragmentFile::begin(out, format, lights, faces, ("", &[]))?;
        file.write(out, (b, &world, &records), None)?;
        file.finish(out)
    }

    /// Shades the receivers `ranges` of `polys` (see [`crate::receivers`]) on
    /// `grid` by `shadows` and writes
    /// its fragments, round by round: each round's chunks are shaded and
    /// formatted in parallel, then written in order while the next round
    /// is shaded, so the file is the same for every thread count and
    /// memory stays bounded (two rounds at most). `done(n)` is
    /// told of every `n` receivers shaded (for a progress bar). A vertex
    /// that is not finite in input units is an
    /// [`io::ErrorKind::InvalidData`] error carrying the [`ExportError`].
    pub fn stream(
        &mut self,
        out: &mut (impl Write + ?Sized),
        shadows: ShadowSet<'_>,
        scene: (&[Polygon], &[std::ops::Range<usize>], &Grid),
        opts: &ShadeOptions,
        done: impl Fn(usize) + Sync,
    ) -> io::Result<Streamed> {
        self.stream_by(out, shadows, scene, opts, done, (ROUND, CHUNK))
    }

    /// [`FragmentFile::stream`] in rounds of `round` receivers, each
    /// shaded in parallel in runs of at most `chunk`.
    fn stream_by(
        &mut self,
        out: &mut (impl Write + ?Sized),
        shadows: ShadowSet<'_>,
        (polys, ranges, grid): (&[Polygon], &[std::ops::Range<usize>], &Grid),
        opts: &ShadeOptions,
        done: impl Fn(usize) + Sync,
        (round, chunk): (usize, usize),
    ) -> io::Result<Streamed> {
        let json = matches!(self.kind, FileKind::Json { .. });
        let lights = self.lights;
        let mut s = Streamed {
            receivers: ranges.len(),
            ..Streamed::default()
        };
        // the large receivers (see `large_receivers`) are shaded from the
        // start, beside the rounds, and kept until their round writes them;
        // a round that comes to one not yet begun shades it itself
        let large = large_receivers(polys, ranges);
        let slots: Vec<OnceLock<Result<Shaded, ExportError>>> =
            large.iter().map(|_| OnceLock::new()).collect();
        let shade = |r: std::ops::Range<usize>| -> Result<Shaded, ExportError> {
            let b = shadows.shade_ranges(polys, &ranges[r.clone()], r.start as u32, opts);
            let world = world_vertices(&b, grid)?;
            let records = area_records(&b, &world);
            let text = match json {
                true => json_fragments(&b, &world, &records, lights),
                false => Vec::new(),
            };
            done(r.len());
            Ok((b, world, records, text))
        };
        let large_part = |k: usize| slots[k].get_or_init(|| shade(large[k]..large[k] + 1));
        // a round's runs, and the parts of those not large, shaded
        let shade_round = |start: usize| {
            let runs = runs(start..(start + round).min(ranges.len()), &large, chunk);
            let todo: Vec<&std::ops::Range<usize>> =
                runs.iter().filter(|r| !is_one_of(r, &large)).collect();
            let parts: Vec<Result<Shaded, ExportError>> =
                todo.par_iter().map(|r| shade((*r).clone())).collect();
            (runs, parts)
        };
        let t0 = Instant::now();
        rayon::in_place_scope(|scope| {
            scope.spawn(|_| {
                (0..large.len()).into_par_iter().for_each(|k| {
                    large_part(k);
                })
            });
            // each round written on this thread while the next is shaded
            // beside it (the writing alone had left a core idle)
            let starts: Vec<usize> = (0..ranges.len()).step_by(round).collect();
            let mut pending = starts.first().map(|&start| shade_round(start));
            for k in 1..=starts.len() {
                let (runs, parts) = pending.take().expect("a round shaded");
                let mut next = None;
                let (next_at, shade_round) = (&mut next, &shade_round);
                rayon::in_place_scope(|sc| {
                    if let Some(&start) = starts.get(k) {
                        sc.spawn(move |_| *next_at = Some(shade_round(start)));
                    }
                    let t = Instant::now();
                    let mut parts = parts.into_iter();
                    for r in &runs {
                        let own;
                        let part = match large.iter().position(|&i| r.len() == 1 && r.start == i) {
                            Some(k) => large_part(k).as_ref(),
                            None => {
                                own = parts.next().expect("a part a run");
                                own.as_ref()
                            }
                        };
                        let (b, world, records, text) =
                            part.map_err(|e| io::Error::new(io::ErrorKind::InvalidData, *e))?;
                        s.fragments += b.len();
                        self.write(out, (b, world, records), json.then_some(&text[..]))?;
                    }
                    s.writing += t.elapsed();
                    Ok::<(), io::Error>(())
                })?;
                pending = next;
            }
            Ok::<(), io::Error>(())
        })?;
        s.shading = t0.elapsed().saturating_sub(s.writing);
        Ok(s)
    }

    /// Writes the file's tail (JSON: the summary of the areas).
    pub fn finish(self, out: &mut (impl Write + ?Sized)) -> io::Result<Written> {
        let (vertices, degenerate) = match &self.kind {
            FileKind::Json { .. } => {
                json_footer(out, &self.areas)?;
                (0, 0)
            }
            FileKind::Obj(w) => (w.vertex_count(), w.degenerate()),
        };
        Ok(Written {
            areas: self.areas,
            vertices,
            degenerate,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A negative zero (an empty sum's, a share's) is written as 0.
    #[test]
    fn negative_zero_is_written_as_zero() {
        let (mut neg, mut pos) = (Vec::new(), Vec::new());
        push_f64(&mut neg, -0.0);
        push_f64(&mut pos, 0.0);
        assert_eq!(neg, pos);
        assert!(!neg.starts_with(b"-"));
    }

    /// The floor `[0, 8]²` under the roof `[2, 4]²` at height 4, lit from
    /// above by one point light and one sun, shaded in two batches.
    fn floor_and_roof() -> (Grid, Vec<PlacedLight>, Batch, Batch) {
        let (grid, lights, polys, shadows) = floor_and_roof_scene();
        let opts = crate::ShadeOptions::default().with_pieces(true);
        let ranges = crate::receivers(&polys);
        let first = shadows.set().shade_ranges(&polys, &ranges[..1], 0, &opts);
        let second = shadows.set().shade_ranges(&polys, &ranges[1..], 1, &opts);
        (grid, lights, first, second)
    }

    /// The scene of [`floor_and_roof`]: its grid, lights, polygons and
    /// shadow trees.
    fn floor_and_roof_scene() -> (Grid, Vec<PlacedLight>, Vec<Polygon>, crate::LightVolumes) {
        let loops: [[[f64; 3]; 4]; 2] = [
            [[0., 0., 0.], [8., 0., 0.], [8., 8., 0.], [0., 8., 0.]],
            [[2., 2., 4.], [4., 2., 4.], [4., 4., 4.], [2., 4., 4.]],
        ];
        let specs = [
            crate::LightSpec::Point(DVec3::new(3.0, 3.0, 8.0)),
            crate::LightSpec::Sun(DVec3::new(0.0, 0.0, 1.0)),
        ];
        scene_of(&loops, &specs)
    }

    /// The quads `loops` (face `i`: `loops[i]`) snapped to a grid fitted
    /// to them and `specs`: the grid, the lights placed on it, the
    /// polygons and their shadow trees.
    fn scene_of(
        loops: &[[[f64; 3]; 4]],
        specs: &[crate::LightSpec],
    ) -> (Grid, Vec<PlacedLight>, Vec<Polygon>, crate::LightVolumes) {
        let positions: Vec<DVec3> = loops.iter().flatten().map(|&p| DVec3::from(p)).collect();
        let grid = crate::shared_grid(&positions, specs).unwrap();
        let lights = crate::place_lights(&grid, specs).unwrap();
        let polys: Vec<bsp_core::Polygon> = (loops.iter().enumerate())
            .map(|(i, l)| {
                let pts: Vec<_> = l.iter().map(|&p| grid.snap(p.into()).unwrap()).collect();
                bsp_core::Polygon::from_grid_points(&pts, i as u32).unwrap()
            })
            .collect();
        let kernel: Vec<Light> = lights.iter().map(|l| l.light).collect();
        let shadows = crate::LightVolumes::new(&polys, &kernel).unwrap();
        (grid, lights, polys, shadows)
    }

    #[test]
    fn a_streamed_file_is_the_file_of_its_batches() {
        let (grid, lights, polys, shadows) = floor_and_roof_scene();
        let (_, _, first, second) = floor_and_roof();
        let opts = crate::ShadeOptions::default().with_pieces(true);
        for format in [FragmentFormat::Json, FragmentFormat::Obj] {
            let (whole, w) = file_of(format, &grid, &lights, &[&first, &second], false);
            let mut out = Vec::new();
            let notes = ["a".to_string(), "b".to_string()];
            let head = ("test", &notes[..]);
            let mut file = FragmentFile::begin(&mut out, format, &lights, 2, head).unwrap();
            let done = std::sync::atomic::AtomicUsize::new(0);
            let s = file
                .stream(
                    &mut out,
                    shadows.set(),
                    (&polys, &crate::receivers(&polys), &grid),
                    &opts,
                    |n| {
                        done.fetch_add(n, std::sync::atomic::Ordering::Relaxed);
                    },
                )
                .unwrap();
            let streamed = file.finish(&mut out).unwrap();
            assert_eq!(
                String::from_utf8(out).unwrap(),
                String::from_utf8(whole).unwrap()
            );
            assert_eq!(streamed.areas, w.areas);
            assert_eq!((s.receivers, done.into_inner()), (2, 2));
            assert_eq!(s.fragments, first.len() + second.len());
        }
    }

    /// A row of `n` small tiles at height 1 over three large faces at
    /// heights 0, -1 and -2 (receivers 0, 21 and `n + 2`), under a point
    /// light: its grid, light, polygons and shadow trees.
    fn tiles_scene(n: usize) -> (Grid, Vec<PlacedLight>, Vec<Polygon>, crate::LightVolumes) {
        let large = |z: f64| {
            [
                [-9., -9., z],
                [n as f64 + 9., -9., z],
                [n as f64 + 9., 9., z],
                [-9., 9., z],
            ]
        };
        let tile = |i: usize| {
            let x = i as f64;
            [
                [x + 0.2, 0.2, 1.],
                [x + 0.8, 0.2, 1.],
                [x + 0.8, 0.8, 1.],
                [x + 0.2, 0.8, 1.],
            ]
        };
        let mut loops: Vec<[[f64; 3]; 4]> = (0..n).map(tile).collect();
        loops.insert(0, large(0.0));
        loops.insert(21, large(-1.0));
        loops.push(large(-2.0));
        let specs = [crate::LightSpec::Point(DVec3::new(
            n as f64 / 2.0,
            3.0,
            9.0,
        ))];
        scene_of(&loops, &specs)
    }

    /// The large receivers are shaded first, beside the rounds, and the
    /// file is still the receivers' in order: the same bytes as one batch
    /// shaded receiver by receiver, for rounds and runs of every size and
    /// on one thread or two.
    #[test]
    fn large_receivers_shaded_first_keep_the_file_in_order() {
        let n = 40;
        let (grid, lights, polys, shadows) = tiles_scene(n);
        let ranges = crate::receivers(&polys);
        let mut large = crate::schedule::large_receivers(&polys, &ranges);
        large.sort_unstable();
        assert_eq!(large, [0, 21, n + 2]);
        let opts = crate::ShadeOptions::default().with_pieces(true);
        let whole = shadows.set().shade_ranges(&polys, &ranges, 0, &opts);
        assert!(whole.len() > ranges.len(), "the large faces are cut");
        for format in [FragmentFormat::Json, FragmentFormat::Obj] {
            let (expected, _) =
                file_of_faces(format, &grid, &lights, &[&whole], false, polys.len());
            for (threads, round, chunk) in [(1, 8, 3), (2, 8, 3), (2, 64, 5), (2, 1, 1)] {
                let pool = pool_of(threads);
                let mut out = Vec::new();
                let notes = ["a".to_string(), "b".to_string()];
                let head = ("test", &notes[..]);
                let faces = polys.len();
                let mut file = FragmentFile::begin(&mut out, format, &lights, faces, head).unwrap();
                let done = std::sync::atomic::AtomicUsize::new(0);
                let count = |k: usize| {
                    done.fetch_add(k, std::sync::atomic::Ordering::Relaxed);
                };
                let scene = (&polys[..], &ranges[..], &grid);
                let s = pool
                    .install(|| {
                        file.stream_by(&mut out, shadows.set(), scene, &opts, count, (round, chunk))
                    })
                    .unwrap();
                file.finish(&mut out).unwrap();
                let why =
                    format!("{format:?}, {threads} threads, rounds of {round}, runs of {chunk}");
                assert!(out == expected, "{why}");
                assert_eq!(
                    (s.fragments, done.into_inner()),
                    (whole.len(), ranges.len()),
                    "{why}"
                );
            }
            let all = shadows.set().shade_all(&polys, &opts);
            let (by_chunks, _) = file_of_faces(format, &grid, &lights, &[&all], false, polys.len());
            assert!(by_chunks == expected, "shade_all, {format:?}");
        }
    }

    /// A pool of `threads` threads for one test's runs.
    fn pool_of(threads: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
    }

    /// A vertex that leaves `f64` in input units is an error, however the
    /// rounds fall: the write that meets it returns while the next round
    /// is being shaded, and nothing is left waiting.
    #[test]
    fn a_vertex_beyond_f64_stops_the_stream_with_its_error() {
        let (_, lights, polys, shadows) = tiles_scene(24);
        let ranges = crate::receivers(&polys);
        // a step of 2^1000 input units: every grid coordinate but 0 is
        // beyond f64 once scaled back
        let huge = Grid::new(DVec3::ZERO, -1000).unwrap();
        let opts = crate::ShadeOptions::default();
        for (threads, round, chunk) in [(1, 4, 2), (2, 1, 1), (2, 4, 2), (2, 64, 8)] {
            let pool = pool_of(threads);
            let mut out = Vec::new();
            let format = FragmentFormat::Json;
            let faces = polys.len();
            let mut file =
                FragmentFile::begin(&mut out, format, &lights, faces, ("", &[])).unwrap();
            let scene = (&polys[..], &ranges[..], &huge);
            let e = pool
                .install(|| {
                    file.stream_by(
                        &mut out,
                        shadows.set(),
                        scene,
                        &opts,
                        |_| {},
                        (round, chunk),
                    )
                })
                .unwrap_err();
            assert_eq!(e.kind(), io::ErrorKind::InvalidData);
            let inner = e.into_inner().unwrap().downcast::<ExportError>().unwrap();
            assert!(matches!(
                *inner,
                ExportError::NonFiniteVertex { face: 0, .. }
            ));
        }
    }

    #[test]
    fn runs_cover_the_receivers_in_order_with_each_large_one_alone() {
        use crate::schedule::runs;
        assert_eq!(runs(0..10, &[], 4), [0..4, 4..8, 8..10]);
        assert_eq!(
            runs(0..10, &[9, 2, 3], 4),
            [0..2, 2..3, 3..4, 4..8, 8..9, 9..10]
        );
        // large receivers of other rounds are not this round's
        assert_eq!(runs(5..9, &[0, 6, 12], 8), [5..6, 6..7, 7..9]);
        assert!(runs(3..3, &[3], 4).is_empty());
    }

    /// The file written in `batches`, and what was written.
    fn file_of(
        format: FragmentFormat,
        grid: &Grid,
        lights: &[PlacedLight],
        batches: &[&Batch],
        preformat: bool,
    ) -> (Vec<u8>, Written) {
        file_of_faces(format, grid, lights, batches, preformat, 2)
    }

    /// [`file_of`] for a scene of `faces` faces.
    fn file_of_faces(
        format: FragmentFormat,
        grid: &Grid,
        lights: &[PlacedLight],
        batches: &[&Batch],
        preformat: bool,
        faces: usize,
    ) -> (Vec<u8>, Written) {
        let mut out = Vec::new();
        let notes = ["a".to_string(), "b".to_string()];
        let mut file =
            FragmentFile::begin(&mut out, format, lights, faces, ("test", &notes[..])).unwrap();
        for b in batches {
            let world = world_vertices(b, grid).unwrap();
            let records = area_records(b, &world);
            let text = json_fragments(b, &world, &records, lights.len());
            let json = preformat.then_some(&text[..]);
            file.write(&mut out, (b, &world, &records), json).unwrap();
        }
        let written = file.finish(&mut out).unwrap();
        (out, written)
    }

    #[test]
    fn a_fragment_file_is_the_same_in_one_batch_or_several() {
        let (grid, lights, first, second) = floor_and_roof();
        let mut both = first.clone();
        both.append(&second);
        assert!(!first.is_empty() && !second.is_empty());
        for format in [FragmentFormat::Json, FragmentFormat::Obj] {
            let (whole, w) = file_of(format, &grid, &lights, &[&both], false);
            for preformat in [false, true] {
                let (parts, p) = file_of(format, &grid, &lights, &[&first, &second], preformat);
                assert_eq!(
                    String::from_utf8(parts).unwrap(),
                    String::from_utf8(whole.clone()).unwrap()
                );
                assert_eq!(p.areas, w.areas);
                assert_eq!((p.vertices, p.degenerate), (w.vertices, w.degenerate));
            }
            // the floor is 64 units², the roof 4, both facing up; the
            // point light, 4 above the roof and 8 above the floor, casts the
            // roof twice its size, onto [1, 5]²; the sun straight overhead
            // (a direction the quantization keeps exactly) casts it onto
            // [2, 4]². Every corner is an integer in input units, so every
            // area is exact in f64
            let a = &w.areas;
            assert_eq!(a.total, 68.0);
            assert_eq!(a.cast[0], 16.0);
            assert_eq!(a.lit[0], 68.0 - 16.0);
            assert_eq!(a.cast[1], 4.0);
            if format == FragmentFormat::Obj {
                assert!(w.vertices > 8);
            }
        }
        let (json, _) = file_of(
            FragmentFormat::Json,
            &grid,
            &lights,
            &[&first, &second],
            true,
        );
        let doc: serde_json::Value = serde_json::from_slice(&json).unwrap();
        assert_eq!(doc["faces"], 2);
        assert_eq!(doc["fragments"].as_array().unwrap().len(), both.len());
        assert_eq!(doc["lights"][1]["kind"], "directional");
    }

    #[test]
    fn obj_groups_name_the_lights() {
        assert_eq!(obj_group(0b1, 1), "lit");
        assert_eq!(obj_group(0b0, 1), "shadow");
        assert_eq!(obj_group(0b101, 3), "lit lit_0_2");
        assert_eq!(obj_group(0b00, 2), "shadow");
    }

    /// Numbers to print, each compared as text with `serde_json`'s
    /// printing of it: zero, a fraction, an integer, a small and a tiny
    /// value that print in exponent form, a long decimal and 2^60.
    fn printed() -> [f64; 7] {
        [
            0.0,
            -0.5,
            1.0,
            10f64.powi(-7),
            123_456.789,
            2f64.powi(60),
            -3.25 * 10f64.powi(-300),
        ]
    }

    #[test]
    fn json_numbers_are_serde_jsons() {
        for x in printed() {
            let mut s = Vec::new();
            push_f64(&mut s, x);
            assert_eq!(
                String::from_utf8(s).unwrap(),
                serde_json::to_string(&x).unwrap()
            );
        }
    }
}

// ------------------------------------------------------- soft shadows

/// A soft-shadow run's areas, per light (input units).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SoftAreas {
    /// Every fragment's area (each face once).
    #[serde(rename = "area")]
    pub total: f64,
    /// Per light: seeing all of it.
    #[serde(rename = "lit_area")]
    pub lit: Vec<f64>,
    /// Per light: seeing part of it (the undecided area included).
    #[serde(rename = "penumbra_area")]
    pub penumbra: Vec<f64>,
    /// Per light: seeing none of it.
    #[serde(rename = "umbra_area")]
    pub umbra: Vec<f64>,
    /// Per light: penumbra or umbra, not decided (where an umbra boundary
    /// may be a quadric surface of three occluders' edges).
    #[serde(rename = "undecided_area")]
    pub undecided: Vec<f64>,
}

impl SoftAreas {
    fn new(lights: usize) -> SoftAreas {
        SoftAreas {
            total: 0.0,
            lit: vec![0.0; lights],
            penumbra: vec![0.0; lights],
            umbra: vec![0.0; lights],
            undecided: vec![0.0; lights],
        }
    }

    fn add(&mut self, f: &SoftFragment, area: f64) {
        self.total += area;
        for i in 0..self.lit.len() {
            match f.class(i) {
                AreaClass::Lit => self.lit[i] += area,
                AreaClass::Umbra => self.umbra[i] += area,
                AreaClass::Penumbra => self.penumbra[i] += area,
                AreaClass::Undecided => {
                    self.penumbra[i] += area;
                    self.undecided[i] += area;
                }
            }
        }
    }
}

/// What [`write_soft`] wrote.
#[derive(Clone, Debug)]
pub struct SoftWritten {
    /// The areas, per light.
    pub areas: SoftAreas,
    /// Fragments written.
    pub fragments: usize,
    /// Positions of an OBJ file.
    pub vertices: Option<usize>,
    /// OBJ pieces degenerate once rounded (see [`ObjWriter::degenerate`]).
    pub degenerate: usize,
}

/// The areas of soft fragments (`fragments`, per face) per light, in
/// input units: what [`write_soft`] sums into its summary.
pub fn soft_areas(fragments: &[Vec<SoftFragment>], lights: usize, grid: &Grid) -> SoftAreas {
    let mut areas = SoftAreas::new(lights);
    for f in fragments.iter().flatten() {
        areas.add(f, soft_area(f, grid));
    }
    areas
}

/// A soft fragment's area in input units: the sum of its convex pieces'.
pub fn soft_area(f: &SoftFragment, grid: &Grid) -> f64 {
    (f.pieces.iter())
        .map(|p| polygon_area(&in_world(&p.polygon, grid)))
        .sum()
}

/// A polygon's corners in input units.
fn in_world(p: &Polygon, grid: &Grid) -> Vec<DVec3> {
    p.vertices_f64().iter().map(|&c| grid.to_world(c)).collect()
}

fn json_light(l: &SoftLight) -> JsonLight {
    match &l.shape {
        SoftShape::Point(p) => JsonLight::Point {
            position: p.to_array(),
        },
        SoftShape::Sun(d) => JsonLight::Directional {
            direction: d.to_array(),
        },
        SoftShape::Area(c) => JsonLight::Area {
            corners: c.iter().map(|p| p.to_array()).collect(),
        },
        SoftShape::SunDisc {
            direction,
            radius_deg,
        } => JsonLight::SunDisc {
            direction: direction.to_array(),
            radius_deg: *radius_deg,
        },
    }
}

/// The OBJ groups of a soft fragment: `lit` where some light is wholly
/// seen, `penumbra` where some is partly seen, `umbra` where none is
/// seen at all; with several lights also `lit_I_J...` and
/// `penumbra_I_J...` naming the lights.
fn soft_group(f: &SoftFragment, lights: usize) -> String {
    let of = |want: &dyn Fn(AreaClass) -> bool| -> Vec<String> {
        (0..lights)
            .filter(|&i| want(f.class(i)))
            .map(|i| i.to_string())
            .collect()
    };
    let lit = of(&|c| c == AreaClass::Lit);
    let part = of(&|c| matches!(c, AreaClass::Penumbra | AreaClass::Undecided));
    let mut names = Vec::new();
    for (name, on) in [("lit", &lit), ("penumbra", &part)] {
        if !on.is_empty() {
            names.push(name.to_string());
            if lights > 1 {
                names.push(format!("{name}_{}", on.join("_")));
            }
        }
    }
    if names.is_empty() {
        names.push("umbra".to_string());
    }
    names.join(" ")
}

/// The bits of a fragment's classes, for telling groups apart.
fn soft_key(f: &SoftFragment) -> u64 {
    f.lit.wrapping_mul(0x9e37_79b9_7f4a_7c15)
        ^ f.umbra.rotate_left(21)
        ^ f.undecided.rotate_left(42)
}

/// Writes a soft-shadow run's fragments (`fragments[k]`: those of
/// polygon `k`, which belongs to face `faces_of[k]`) as JSON (the schema
/// of `docs/shadows.md`, with per light `umbra` flags and the `visible`
/// share of penumbra fragments) or OBJ (groups by class, see
/// [`FragmentFormat`]). Vertices are rounded once to `f64` grid units and
/// mapped to input units by `grid`.
pub fn write_soft(
    out: &mut (impl Write + ?Sized),
    format: FragmentFormat,
    lights: &[SoftLight],
    (name, notes, faces): (&str, &[String], usize),
    (fragments, faces_of): (&[Vec<SoftFragment>], &[u32]),
    grid: &Grid,
) -> io::Result<SoftWritten> {
    let n = lights.len();
    let mut areas = SoftAreas::new(n);
    let mut obj = ObjWriter::new();
    let mut group = None;
    let mut count = 0;
    match format {
        FragmentFormat::Json => {
            let lights: Vec<JsonLight> = lights.iter().map(json_light).collect();
            json_head(out, &lights, faces)?;
        }
        FragmentFormat::Obj => {
            obj_head(out, name, notes, faces)?;
            writeln!(
                out,
                "# groups: lit (sees all of a light), penumbra (part of one), umbra (none of any){}",
                if n > 1 {
                    "; lit_I_J..., penumbra_I_J... name the lights"
                } else {
                    ""
                }
            )?;
            writeln!(
                out,
                "# each fragment as its convex pieces, faces in input order, vertices welded"
            )?;
        }
    }
    let mut text = Vec::new();
    let mut ids = Vec::new();
    let mut piece = Vec::new();
    for (k, frags) in fragments.iter().enumerate() {
        for f in frags {
            text.clear();
            if format == FragmentFormat::Obj && group != Some(soft_key(f)) {
                group = Some(soft_key(f));
                writeln!(text, "g {}", soft_group(f, n))?;
            }
            // (the rings' corners are corners of the pieces: finite with them)
            let mut area = 0.0;
            for p in &f.pieces {
                piece.clear();
                piece.extend(p.polygon.vertices_f64().iter().map(|&c| grid.to_world(c)));
                if piece.iter().any(|v| !v.is_finite()) {
                    return Err(io::Error::other(ExportError::NonFiniteVertex {
                        face: faces_of[k],
                        step: grid.step(),
                    }));
                }
                area += polygon_area(&piece);
                if format == FragmentFormat::Obj {
                    ids.clear();
                    for &v in &piece {
                        ids.push(obj.vertex(&mut text, v));
                    }
                    obj.face(&mut text, &ids);
                }
            }
            areas.add(f, area);
            if format == FragmentFormat::Json {
                let rings = f.rings_in(grid);
                soft_json(&mut text, f, faces_of[k], &rings, area, n, count == 0);
            }
            out.write_all(&text)?;
            count += 1;
        }
    }
    if format == FragmentFormat::Json {
        write!(out, "\n],\"summary\":")?;
        serde_json::to_writer(&mut *out, &areas)?;
        writeln!(out, "}}")?;
    }
    Ok(SoftWritten {
        areas,
        fragments: count,
        vertices: (format == FragmentFormat::Obj).then(|| obj.vertex_count()),
        degenerate: obj.degenerate(),
    })
}

/// One soft fragment as a JSON object, preceded by `,\n` unless `first`:
/// its outer ring (`vertices`) and holes in input units (`rings`).
fn soft_json(
    s: &mut Vec<u8>,
    f: &SoftFragment,
    face: u32,
    rings: &[Vec<DVec3>],
    area: f64,
    lights: usize,
    first: bool,
) {
    s.extend_from_slice(if first { b"\n" } else { b",\n" });
    s.extend_from_slice(b"{\"face\":");
    s.extend_from_slice(itoa::Buffer::new().format(face).as_bytes());
    let ring = |s: &mut Vec<u8>, r: &[DVec3]| push_points(s, r.iter().copied());
    s.extend_from_slice(b",\"vertices\":");
    ring(s, &rings[0]);
    if rings.len() > 1 {
        s.extend_from_slice(b",\"holes\":[");
        for (k, r) in rings[1..].iter().enumerate() {
            if k > 0 {
                s.push(b',');
            }
            ring(s, r);
        }
        s.push(b']');
    }
    let flags = |s: &mut Vec<u8>, key: &[u8], mask: u64| {
        s.extend_from_slice(key);
        for j in 0..lights {
            if j > 0 {
                s.push(b',');
            }
            s.extend_from_slice(if mask >> j & 1 == 1 {
                b"true"
            } else {
                b"false"
            });
        }
        s.push(b']');
    };
    flags(s, b",\"lit\":[", f.lit);
    flags(s, b",\"umbra\":[", f.umbra);
    flags(s, b",\"undecided\":[", f.undecided);
    let shares = |s: &mut Vec<u8>, key: &[u8], pick: fn(&crate::Share) -> f64| {
        s.extend_from_slice(key);
        for (j, v) in f.visible.iter().enumerate() {
            if j > 0 {
                s.push(b',');
            }
            match v {
                Some(v) => push_f64(s, pick(v)),
                None => s.extend_from_slice(b"null"),
            }
        }
        s.push(b']');
    };
    shares(s, b",\"visible\":[", |v| v.centroid);
    shares(s, b",\"visible_min\":[", |v| v.min);
    shares(s, b",\"visible_max\":[", |v| v.max);
    s.extend_from_slice(b",\"area\":");
    push_f64(s, area);
    s.push(b'}');
}
