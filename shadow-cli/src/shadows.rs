//! `shadow shadows`: exact lit and shadowed fragments of a scene for
//! point lights and suns, written as JSON, OBJ or a rendered SVG.
//!
//! Load → one grid for the scene and its point lights (`svbsp`) → import
//! (faces tagged with their index in the input) → one shadow-volume tree
//! per light → every face shaded and written, chunk by chunk: the chunks
//! are shaded and formatted in parallel and written in order, so the file
//! is the same for every thread count and memory stays bounded. Every
//! lit/shadowed decision is exact for the snapped scene, the snapped point
//! lights and the quantized sun directions; the outputs round the exact
//! fragment vertices once to `f64` grid units and map them back to input
//! units. Areas and the SVG's projection and shading are plain `f64` on
//! those vertices.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::io::Write;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, anyhow, bail};
use bsp_core::{BspTree, BuildOptions, Grid, ImportReport, Polygon, import_faces_par};
use clap::{Args, ValueEnum};
use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;
use shadow_scene::Mesh;
use svbsp::{
    Areas, Batch, CHUNK, LightSpec, PlacedLight, ShadeOptions, Shadows, chin_feiner, polygon_area,
    receivers,
};

use crate::color::{face_colors, hex};
use crate::csg::{Phases, emit, guarded};
use crate::lights::{describe, place_lights, shared_grid};
use crate::progress::{Output, Progress};
use crate::render::{Canvas, Rendered, View, painter_order, unit_normal};
use crate::{DEMO_EYE, DEMO_TARGET, ImageArgs, SourceArgs, load_source_quiet, parse_vec3};

/// Which algorithm computes the shadows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum Algorithm {
    /// Partitioned shadow volumes: every face cut only where a shadow
    /// boundary crosses it (the default).
    Psv,
    /// Chin & Feiner's shadow-volume BSP tree over the scene's BSP: the
    /// fragments are pieces of the BSP's polygons.
    ChinFeiner,
}

#[derive(Args, Debug)]
pub(crate) struct ShadowsArgs {
    #[command(flatten)]
    pub(crate) source: SourceArgs,
    /// A point light at X,Y,Z (input units). Repeat for several lights;
    /// lights are numbered in order, all --light first, then all --sun
    /// [default for --scene room without lights: 0.9,0.3,2.45].
    #[arg(long = "light", value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(crate) lights: Vec<DVec3>,
    /// A light at infinity in the direction X,Y,Z from the scene toward
    /// the light (0,0,1: straight overhead). Repeatable.
    #[arg(long = "sun", value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(crate) suns: Vec<DVec3>,
    /// Output file: .json (the fragments), .obj (groups `lit` and
    /// `shadow`) or .svg (a view of the shaded scene).
    #[arg(short, long, value_name = "OUT")]
    pub(crate) output: PathBuf,
    /// SVG eye position [default for --scene room: the demo's viewpoint;
    /// required otherwise].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(crate) eye: Option<DVec3>,
    /// SVG point looked at [default: the centre of the scene's bounding
    /// box; the demo's target for the room's default eye].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(crate) target: Option<DVec3>,
    /// SVG up direction [default: +Z, or +Y when looking along Z].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(crate) up: Option<DVec3>,
    #[command(flatten)]
    pub(crate) image: ImageArgs,
    /// The algorithm.
    #[arg(long, value_enum, default_value_t = Algorithm::Psv)]
    pub(crate) algorithm: Algorithm,
    /// Worker threads [default: one per core].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub(crate) threads: Option<u32>,
    /// Print counts, timings, the area in light and in shadow of each
    /// light, and the faces with the most shadow cast on them.
    #[arg(long)]
    pub(crate) stats: bool,
    /// No progress bar and no notes on stderr (errors still go there).
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

/// The point light used for `--scene room` when no light is given: just
/// below the top of the walls, right of the room's centre and a little
/// behind it, so that the chairs, the shelf, the plant and the axis
/// object all cast shadows on the floor, the rug and the walls where the
/// demo's viewpoint sees them (the axis object's to the left of it).
pub(crate) const ROOM_LIGHT: DVec3 = shadow_scene::ROOM_LIGHT;

/// How many faces `--stats` lists.
const TOP_FACES: usize = 10;

/// Receivers shaded per round: each round is shaded and formatted in
/// parallel (in chunks of [`CHUNK`]), then written.
const ROUND: usize = CHUNK * 32;

/// The output format, by the file's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Json,
    Obj,
    Svg,
}

impl Format {
    fn from_path(path: &Path) -> Result<Format> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("json") => Ok(Format::Json),
            Some("obj") => Ok(Format::Obj),
            Some("svg") => Ok(Format::Svg),
            _ => bail!(
                "{}: unknown output format (use .json, .obj or .svg)",
                path.display()
            ),
        }
    }
}

/// A scene ready to be shaded: its mesh, grid, lights and polygons.
struct Scene {
    mesh: Mesh,
    name: String,
    grid: Grid,
    lights: Vec<PlacedLight>,
    polys: Vec<Polygon>,
    report: ImportReport,
}

/// What a run reports.
#[derive(Default)]
struct Figures {
    fragments: usize,
    receivers: usize,
    shadow_nodes: usize,
    bsp_polygons: Option<usize>,
    extra: String,
}

// ------------------------------------------------------ vertices and area

/// The batch's vertices in input units, each converted once; an error
/// names a face whose vertex leaves `f64`'s range.
pub(crate) fn world_vertices(b: &Batch, grid: &Grid) -> Result<Vec<DVec3>> {
    let world: Vec<DVec3> = (0..b.vertex_count() as u32)
        .map(|v| grid.to_world(b.rounded(v)))
        .collect();
    if let Some(bad) = world.iter().position(|v| !v.is_finite()) {
        let face = b
            .fragments()
            .find(|f| f.rings().flatten().any(|&v| v as usize == bad))
            .map(|f| f.face())
            .unwrap_or(0);
        bail!(
            "a vertex of face {face} is not finite in input units (grid step {:e}): the \
             coordinates are too large for f64",
            grid.step()
        );
    }
    Ok(world)
}

/// Per fragment of a batch: its face, area, lit and facing flags.
pub(crate) type AreaRecord = (u32, f64, u64, u64);

pub(crate) fn area_records(b: &Batch, world: &[DVec3]) -> Vec<AreaRecord> {
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
            (f.face(), area, f.lit_mask(), f.facing_mask())
        })
        .collect()
}

// ---------------------------------------------------------------- JSON

#[derive(Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
enum JsonLight {
    Point { position: [f64; 3] },
    Directional { direction: [f64; 3] },
}

#[derive(Serialize)]
struct JsonSummary {
    area: f64,
    lit_area: Vec<f64>,
    shadow_area: Vec<f64>,
    cast_shadow_area: Vec<f64>,
    dark_area: f64,
}

pub(crate) fn json_header(
    out: &mut impl Write,
    lights: &[PlacedLight],
    faces: usize,
) -> Result<()> {
    let lights: Vec<JsonLight> = lights
        .iter()
        .map(|l| match l.light {
            svbsp::Light::Point(_) => JsonLight::Point {
                position: l.world.to_array(),
            },
            svbsp::Light::Directional(_) => JsonLight::Directional {
                direction: l.world.to_array(),
            },
        })
        .collect();
    write!(out, "{{\"lights\":")?;
    serde_json::to_writer(&mut *out, &lights)?;
    write!(out, ",\"faces\":{faces},\"fragments\":[")?;
    Ok(())
}

pub(crate) fn json_footer(out: &mut impl Write, areas: &Areas) -> Result<()> {
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

fn push_f64(s: &mut Vec<u8>, x: f64) {
    // serde_json writes floats the same way: shortest round trip
    let mut b = zmij::Buffer::new();
    s.extend_from_slice(b.format_finite(x).as_bytes());
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
    s.push(b'[');
    for (i, &v) in ring.iter().enumerate() {
        if i > 0 {
            s.push(b',');
        }
        push_point(s, world[v as usize]);
    }
    s.push(b']');
}

/// The fragments of a batch as JSON lines, each preceded by `,\n`.
pub(crate) fn json_fragments(
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
        s.extend_from_slice(b"],\"area\":");
        push_f64(&mut s, rec.1);
        s.push(b'}');
    }
    s
}

// ----------------------------------------------------------------- OBJ

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
/// group changes.
struct ObjWriter {
    index: HashMap<[u64; 3], u32>,
    group: Option<u64>,
    faces: usize,
    degenerate: usize,
}

impl ObjWriter {
    fn new() -> ObjWriter {
        ObjWriter {
            index: HashMap::new(),
            group: None,
            faces: 0,
            degenerate: 0,
        }
    }

    /// Writes every convex piece of the batch's fragments.
    fn batch(
        &mut self,
        out: &mut impl Write,
        b: &Batch,
        world: &[DVec3],
        lights: usize,
    ) -> Result<()> {
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
                    let p = world[v as usize];
                    let next = self.index.len() as u32 + 1;
                    let id = *self
                        .index
                        .entry(p.to_array().map(f64::to_bits))
                        .or_insert_with(|| {
                            text.extend_from_slice(b"v ");
                            for (k, c) in p.to_array().into_iter().enumerate() {
                                if k > 0 {
                                    text.push(b' ');
                                }
                                push_f64(&mut text, c);
                            }
                            text.push(b'\n');
                            next
                        });
                    ids.push(id);
                }
                let mut sorted = ids.clone();
                sorted.sort_unstable();
                if sorted.windows(2).any(|w| w[0] == w[1]) {
                    self.degenerate += 1;
                }
                text.push(b'f');
                for id in &ids {
                    text.push(b' ');
                    text.extend_from_slice(itoa::Buffer::new().format(*id).as_bytes());
                }
                text.push(b'\n');
                self.faces += 1;
            }
        }
        out.write_all(&text)?;
        Ok(())
    }
}

fn obj_header(
    out: &mut impl Write,
    name: &str,
    lights: &[PlacedLight],
    faces: usize,
) -> Result<()> {
    writeln!(
        out,
        "# shadow shadows: the fragments of {faces} faces of {name}"
    )?;
    for (i, l) in lights.iter().enumerate() {
        writeln!(out, "# light {i}: {}", describe(l))?;
    }
    if lights.len() > 1 {
        writeln!(
            out,
            "# groups: lit (lit by at least one light), lit_I_J... (lit by exactly lights I, J, ...), \
             shadow (lit by none)"
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

// ----------------------------------------------------------------- SVG

/// Light reaching every surface: no surface is darker than this.
const AMBIENT: f64 = 0.28;
/// A little more ambient on surfaces facing the viewer, so that unlit
/// objects keep their shape.
const AMBIENT_FACING: f64 = 0.12;
/// Total diffuse weight, shared among the lights.
const DIFFUSE: f64 = 0.72;

/// Brightness of a fragment of a face whose centre is `centre`, seen from
/// its front: ambient, plus Lambert's cosine of each light that reaches
/// it. The cosine is taken at the face's centre, so a face's lit
/// fragments share one shade and only the shadow boundaries show.
fn brightness(
    lit: u64,
    normal: DVec3,
    centre: DVec3,
    lights: &[PlacedLight],
    forward: DVec3,
) -> f64 {
    let weight = DIFFUSE / lights.len().max(1) as f64;
    let mut b = AMBIENT + AMBIENT_FACING * (-normal.dot(forward)).max(0.0);
    for (j, l) in lights.iter().enumerate() {
        if lit >> j & 1 == 0 {
            continue;
        }
        let to_light = match l.light {
            svbsp::Light::Point(_) => (l.world - centre).normalize_or_zero(),
            svbsp::Light::Directional(_) => l.world,
        };
        b += weight * normal.dot(to_light).max(0.0);
    }
    b
}

/// A fragment to draw: a part of BSP polygon `polygon` of face `face`,
/// lit by the lights of `lit`, as convex pieces in input units.
pub(crate) struct DrawFrag {
    pub(crate) polygon: usize,
    pub(crate) face: usize,
    pub(crate) lit: u64,
    pub(crate) normal: DVec3,
    pub(crate) pieces: Vec<Vec<DVec3>>,
}

/// Draws the fragments of the scene tree's polygons (`batch`, receiver =
/// polygon index) in the tree's painter's order.
fn render(
    scene: &Scene,
    tree: &BspTree,
    view: &View,
    batch: &Batch,
    world: &[DVec3],
) -> Result<Rendered> {
    let frags: Vec<DrawFrag> = batch
        .fragments()
        .map(|f| DrawFrag {
            polygon: f.receiver() as usize,
            face: f.face() as usize,
            lit: f.lit_mask(),
            normal: unit_normal(f.support()),
            pieces: f
                .pieces()
                .map(|p| p.iter().map(|&v| world[v as usize]).collect())
                .collect(),
        })
        .collect();
    render_frags(
        &scene.mesh,
        &scene.grid,
        &scene.lights,
        tree,
        view,
        &frags,
        "shadow shadows",
    )
}

/// Draws fragments of the tree's polygons in the tree's painter's order,
/// each shaded by the lights that reach it.
pub(crate) fn render_frags(
    mesh: &Mesh,
    grid: &Grid,
    lights: &[PlacedLight],
    tree: &BspTree,
    view: &View,
    frags: &[DrawFrag],
    what: &str,
) -> Result<Rendered> {
    // fragments meet along many more edges than whole polygons: a wider
    // stroke keeps their seams closed
    let mut canvas = Canvas::new(mesh, grid, view, what, 1.0)?;
    let polys: Vec<&Polygon> = tree.polygons().collect();
    let mut per_polygon: Vec<Vec<usize>> = vec![Vec::new(); polys.len()];
    for (j, f) in frags.iter().enumerate() {
        let slot = per_polygon.get_mut(f.polygon).ok_or_else(|| {
            anyhow!(
                "internal error: fragment {j} names BSP polygon {}",
                f.polygon
            )
        })?;
        slot.push(j);
    }
    let colors = face_colors(mesh);
    let centres: Vec<DVec3> = (0..mesh.faces.len())
        .map(|f| {
            let pts = mesh.face_points(f);
            pts.iter().sum::<DVec3>() / pts.len().max(1) as f64
        })
        .collect();
    let forward = canvas.cam.forward();
    let order = painter_order(tree, canvas.eye_vp);
    // runs of coplanar polygons facing the same way: their fragments tile
    // the plane without overlap, so each colour is drawn as one region
    let mut start = 0;
    while start < order.len() {
        let (first, toward) = order[start];
        let plane = polys[first].support();
        let mut end = start + 1;
        while end < order.len()
            && order[end].1 == toward
            && polys[order[end].0].support().is_coincident(plane)
        {
            end += 1;
        }
        let mut regions: Vec<(String, Vec<usize>)> = Vec::new();
        for &(poly, _) in &order[start..end] {
            for &j in &per_polygon[poly] {
                let f = &frags[j];
                let b = if toward {
                    brightness(f.lit, f.normal, centres[f.face], lights, forward)
                } else {
                    // the back of a surface: no light is in front of it
                    AMBIENT
                };
                let fill = hex(colors[f.face], b);
                match regions.iter_mut().find(|(c, _)| *c == fill) {
                    Some((_, members)) => members.push(j),
                    None => regions.push((fill, vec![j])),
                }
            }
        }
        for (fill, members) in &regions {
            let pieces = members
                .iter()
                .flat_map(|&j| frags[j].pieces.iter().map(|p| p.iter().copied()));
            canvas.region(pieces, fill);
        }
        start = end;
    }
    Ok(canvas.finish())
}

/// The SVG camera: the given eye, or for the room the demo's viewpoint.
fn svg_view(args: &ShadowsArgs, is_room: bool) -> Result<View> {
    let (eye, target) = match (args.eye, is_room) {
        (Some(eye), _) => (eye, args.target),
        (None, true) => (DEMO_EYE, Some(args.target.unwrap_or(DEMO_TARGET))),
        (None, false) => bail!(
            "SVG output needs a viewpoint: give --eye X,Y,Z (only --scene room has a default)"
        ),
    };
    Ok(View {
        eye,
        target,
        up: args.up,
        width: args.image.width,
        height: args.image.height,
        fov_deg: args.image.fov,
    })
}

// ------------------------------------------------------------- command

/// `shadow shadows`.
pub(crate) fn run(args: &ShadowsArgs) -> Result<()> {
    match args.threads {
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n as usize)
            .build()
            .context("cannot start the worker threads")?
            .install(|| run_here(args)),
        None => run_here(args),
    }
}

fn run_here(args: &ShadowsArgs) -> Result<()> {
    let total = Instant::now();
    // fail on a bad output name or a missing viewpoint before doing any work
    let format = Format::from_path(&args.output)?;
    let is_room = args.source.input.is_none() && args.source.scene.as_deref() == Some("room");
    let view = match format {
        Format::Svg => Some(svg_view(args, is_room)?),
        _ => None,
    };
    let note = |s: &str| {
        if !args.quiet {
            eprintln!("{s}");
        }
    };
    if view.is_none() && (args.eye.is_some() || args.target.is_some() || args.up.is_some()) {
        note("note: --eye, --target and --up only apply to SVG output");
    }
    let mut specs: Vec<LightSpec> = args.lights.iter().map(|&p| LightSpec::Point(p)).collect();
    specs.extend(args.suns.iter().map(|&d| LightSpec::Sun(d)));
    let default_light = specs.is_empty();
    if default_light {
        if !is_room {
            bail!(
                "no light: give at least one --light X,Y,Z (a point light) or --sun X,Y,Z \
                 (a light at infinity); both can be repeated"
            );
        }
        specs.push(LightSpec::Point(ROOM_LIGHT));
    }

    let progress = Progress::new(!args.quiet);
    let mut phases = Phases::default();
    progress.phase("loading", 1);
    let (mesh, name) = phases.run("load", || load_source_quiet(&args.source, args.quiet))?;
    progress.phase("snapping", 1);
    let scene = phases.run("snap/import", || -> Result<Scene> {
        let grid = shared_grid(&mesh.positions, &specs).with_context(|| name.clone())?;
        let lights = place_lights(&grid, &specs)?;
        let loops = mesh.face_loops();
        let (polys, report) = import_faces_par(&grid, &loops)
            .with_context(|| format!("{name}: cannot import the faces"))?;
        Ok(Scene {
            mesh,
            name,
            grid,
            lights,
            polys,
            report,
        })
    })?;
    let summary = scene.report.summary();
    if !summary.is_empty() {
        note(&format!("{}: {}", scene.name, summary.trim_end()));
    }
    let kernel: Vec<svbsp::Light> = scene.lights.iter().map(|l| l.light).collect();
    let faces = scene.mesh.faces.len();
    let report_with = "the input and the command line";
    let mut areas = Areas::new(kernel.len(), faces);
    let mut out = Output::create(&args.output)?;
    let write_err = || format!("could not write {}", args.output.display());

    let figures = guarded(report_with, || -> Result<Figures> {
        let mut fig = Figures::default();
        // the fragments of every face, or for the SVG of every BSP polygon
        let (batches, tree): (Option<Batch>, Option<BspTree>) = match (args.algorithm, format) {
            (Algorithm::Psv, Format::Json | Format::Obj) => {
                progress.phase("shadow trees", kernel.len() as u64);
                let shadows = phases
                    .run("trees", || Shadows::new(&scene.polys, &kernel))
                    .map_err(|e| anyhow!("{e}"))?;
                fig.shadow_nodes = shadows.volumes().iter().map(|v| v.node_count()).sum();
                let ranges = receivers(&scene.polys);
                fig.receivers = ranges.len();
                stream(
                    args,
                    format,
                    &scene,
                    &shadows,
                    &ranges,
                    &mut out,
                    &mut areas,
                    &mut fig,
                    &mut phases,
                    &progress,
                )
                .with_context(write_err)?;
                (None, None)
            }
            (Algorithm::Psv, Format::Svg) => {
                progress.phase("scene tree", 1);
                let tree = phases.run("bsp", || {
                    BspTree::build(scene.polys.clone(), &BuildOptions::default())
                });
                progress.phase("shadow trees", kernel.len() as u64);
                let shadows = phases
                    .run("trees", || Shadows::new(&scene.polys, &kernel))
                    .map_err(|e| anyhow!("{e}"))?;
                fig.shadow_nodes = shadows.volumes().iter().map(|v| v.node_count()).sum();
                let polys: Vec<Polygon> = tree.polygons().cloned().collect();
                fig.bsp_polygons = Some(polys.len());
                fig.receivers = polys.len();
                progress.phase("shading", polys.len() as u64);
                let batch = phases.run("shading", || {
                    let ranges: Vec<Range<usize>> = (0..polys.len()).map(|i| i..i + 1).collect();
                    let parts: Vec<Batch> = ranges
                        .par_chunks(CHUNK)
                        .enumerate()
                        .map(|(i, rs)| {
                            let b = shadows.shade_ranges(
                                &polys,
                                rs,
                                (i * CHUNK) as u32,
                                &ShadeOptions::default(),
                            );
                            progress.inc(rs.len() as u64);
                            b
                        })
                        .collect();
                    let mut all = Batch::new();
                    for b in &parts {
                        all.append(b);
                    }
                    all
                });
                (Some(batch), Some(tree))
            }
            (Algorithm::ChinFeiner, _) => {
                progress.phase("scene tree", 1);
                let tree = phases.run("bsp", || {
                    BspTree::build(scene.polys.clone(), &BuildOptions::default())
                });
                fig.bsp_polygons = Some(tree.polygons().count());
                fig.receivers = tree.polygons().count();
                progress.phase("Chin & Feiner", 1);
                let cf = phases
                    .run("shadows", || chin_feiner(&tree, &kernel))
                    .map_err(|e| anyhow!("{e}"))?;
                fig.shadow_nodes = cf.shadow_nodes;
                (Some(Batch::from_chin_feiner(&cf, &kernel)), Some(tree))
            }
        };
        if let Some(batch) = batches {
            progress.phase("writing", 1);
            let world = world_vertices(&batch, &scene.grid)?;
            let records = area_records(&batch, &world);
            for r in &records {
                areas.add(r.0, r.1, r.2, r.3);
            }
            fig.fragments = batch.len();
            phases
                .run("write", || -> Result<()> {
                    match format {
                        Format::Json => {
                            json_header(&mut out, &scene.lights, faces)?;
                            let text = json_fragments(&batch, &world, &records, kernel.len());
                            out.write_all(text.get(1..).unwrap_or_default())?;
                            json_footer(&mut out, &areas)?;
                        }
                        Format::Obj => {
                            obj_header(&mut out, &scene.name, &scene.lights, faces)?;
                            let mut w = ObjWriter::new();
                            w.batch(&mut out, &batch, &world, kernel.len())?;
                            fig.extra = format!(", {} vertices", w.index.len());
                            warn_degenerate(&w, args.quiet);
                        }
                        Format::Svg => {
                            let view = view.as_ref().expect("SVG output has a view");
                            let tree = tree.as_ref().expect("SVG is drawn over the scene tree");
                            let r = render(&scene, tree, view, &batch, &world)?;
                            out.write_all(r.svg.as_bytes())?;
                            fig.extra = format!(
                                ", {} drawn, eye {:.3},{:.3},{:.3}",
                                r.drawn, r.eye.x, r.eye.y, r.eye.z
                            );
                        }
                    }
                    Ok(())
                })
                .with_context(write_err)?;
        }
        Ok(fig)
    })?;
    out.commit()?;
    progress.finish();
    let total = total.elapsed();

    let lit_share = percent(areas.total - areas.dark, areas.total);
    let light_count = match (scene.lights.len(), default_light) {
        (_, true) => format!(
            "the room's default light ({})",
            crate::lights::flag(&specs[0])
        ),
        (1, false) => "1 light".to_string(),
        (n, false) => format!("{n} lights"),
    };
    let mut report = format!(
        "wrote {}: {} fragments of {faces} faces of {}{}; {light_count}, \
         {lit_share:.1}% of the area lit\n",
        args.output.display(),
        figures.fragments,
        scene.name,
        figures.extra,
    );
    if args.stats {
        report += &stats_text(&scene, &figures, &areas, &phases, total);
    }
    emit(&report)
}

fn warn_degenerate(w: &ObjWriter, quiet: bool) {
    if w.degenerate > 0 && !quiet {
        eprintln!(
            "warning: {} fragment piece(s) have distinct exact vertices that coincide once \
             rounded to f64 input units; they are degenerate in the file",
            w.degenerate
        );
    }
}

/// A chunk of receivers shaded: the fragments, their vertices in input
/// units, their areas and (for JSON) their text.
type Shaded = (Batch, Vec<DVec3>, Vec<AreaRecord>, Vec<u8>);

/// Shades the receivers round by round (each round in parallel) and
/// writes each round as soon as it is done.
#[allow(clippy::too_many_arguments)]
fn stream(
    args: &ShadowsArgs,
    format: Format,
    scene: &Scene,
    shadows: &Shadows,
    ranges: &[Range<usize>],
    out: &mut Output,
    areas: &mut Areas,
    fig: &mut Figures,
    phases: &mut Phases,
    progress: &Progress,
) -> Result<()> {
    let lights = scene.lights.len();
    let faces = scene.mesh.faces.len();
    let opts = ShadeOptions::default().with_pieces(format == Format::Obj);
    let mut obj = ObjWriter::new();
    match format {
        Format::Json => json_header(out, &scene.lights, faces)?,
        _ => obj_header(out, &scene.name, &scene.lights, faces)?,
    }
    let (mut shading, mut writing) = (Duration::ZERO, Duration::ZERO);
    let mut first = true;
    progress.phase("shading", ranges.len() as u64);
    for (r, round) in ranges.chunks(ROUND).enumerate() {
        let start = Instant::now();
        let parts: Vec<Result<Shaded>> = round
            .par_chunks(CHUNK)
            .enumerate()
            .map(|(i, rs)| {
                let first_receiver = (r * ROUND + i * CHUNK) as u32;
                let b = shadows.shade_ranges(&scene.polys, rs, first_receiver, &opts);
                let world = world_vertices(&b, &scene.grid)?;
                let records = area_records(&b, &world);
                let text = match format {
                    Format::Json => json_fragments(&b, &world, &records, lights),
                    _ => Vec::new(),
                };
                progress.inc(rs.len() as u64);
                Ok((b, world, records, text))
            })
            .collect();
        shading += start.elapsed();
        let start = Instant::now();
        for part in parts {
            let (b, world, records, text) = part?;
            fig.fragments += b.len();
            for rec in &records {
                areas.add(rec.0, rec.1, rec.2, rec.3);
            }
            match format {
                Format::Json => {
                    let body = if first && !text.is_empty() {
                        first = false;
                        &text[1..]
                    } else {
                        &text[..]
                    };
                    out.write_all(body)?;
                }
                _ => obj.batch(out, &b, &world, lights)?,
            }
        }
        writing += start.elapsed();
    }
    match format {
        Format::Json => json_footer(out, areas)?,
        _ => {
            fig.extra = format!(", {} vertices", obj.index.len());
            warn_degenerate(&obj, args.quiet);
        }
    }
    phases.0.push(("shading", shading));
    phases.0.push(("write", writing));
    Ok(())
}

fn percent(part: f64, whole: f64) -> f64 {
    if whole > 0.0 {
        100.0 * part / whole
    } else {
        0.0
    }
}

/// The `--stats` report.
fn stats_text(
    scene: &Scene,
    fig: &Figures,
    areas: &Areas,
    phases: &Phases,
    total: Duration,
) -> String {
    let faces = scene.mesh.faces.len();
    let lights = &scene.lights;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "faces:           {faces} ({} polygons after import: {} faces triangulated, {} dropped)",
        scene.report.polygons,
        scene.report.triangulated.len(),
        scene.report.dropped.len()
    );
    let _ = writeln!(
        s,
        "grid step:       2^{} = {:.3e} units",
        -scene.grid.scale().log2(),
        scene.grid.step()
    );
    if let Some(n) = fig.bsp_polygons {
        let _ = writeln!(s, "bsp:             {n} polygons");
    }
    let _ = writeln!(
        s,
        "fragments:       {} ({:.3} per face; {} receivers, {} shadow-tree nodes over {} light{})",
        fig.fragments,
        fig.fragments as f64 / faces.max(1) as f64,
        fig.receivers,
        fig.shadow_nodes,
        lights.len(),
        if lights.len() == 1 { "" } else { "s" }
    );
    for (i, l) in lights.iter().enumerate() {
        let _ = writeln!(s, "light {i}:         {}", describe(l));
        if l.angle > 0.0 {
            let _ = writeln!(
                s,
                "                 exact for the integer direction, {:.3e} degrees from the \
                 given one",
                l.angle.to_degrees()
            );
        }
    }
    let times: Vec<String> = phases
        .0
        .iter()
        .map(|(n, d)| format!("{n} {:.2} ms", d.as_secs_f64() * 1e3))
        .collect();
    let _ = writeln!(
        s,
        "time:            {}; total {:.2} ms ({} threads)",
        times.join(", "),
        total.as_secs_f64() * 1e3,
        rayon::current_num_threads()
    );
    let _ = writeln!(
        s,
        "area:            {:.6} units² (every face once, its front side)",
        areas.total
    );
    for i in 0..lights.len() {
        let _ = writeln!(
            s,
            "light {i} area:    lit {:.6} ({:.1}%), in shadow {:.6} ({:.1}%): cast {:.6} ({:.1}%), \
             facing away {:.6} ({:.1}%)",
            areas.lit[i],
            percent(areas.lit[i], areas.total),
            areas.total - areas.lit[i],
            percent(areas.total - areas.lit[i], areas.total),
            areas.cast[i],
            percent(areas.cast[i], areas.total),
            areas.attached[i],
            percent(areas.attached[i], areas.total),
        );
    }
    if lights.len() > 1 {
        let _ = writeln!(
            s,
            "no light:        {:.6} ({:.1}%)",
            areas.dark,
            percent(areas.dark, areas.total)
        );
    }
    let top = areas.most_shaded(TOP_FACES);
    if top.is_empty() {
        let _ = writeln!(s, "cast shadow:     none");
        return s;
    }
    let _ = writeln!(
        s,
        "faces with the most cast shadow (area in shadow while facing the light, % of the face):"
    );
    let mut header = format!("  {:>7}  {:<12} {:>12}", "face", "group", "area");
    for i in 0..lights.len() {
        header += &format!("  {:>20}", format!("light {i} shadow"));
    }
    let _ = writeln!(s, "{header}");
    for f in top {
        let area = areas.face_area(f);
        let mut line = format!("  {f:>7}  {:<12} {area:>12.6}", scene.mesh.group_name(f));
        for c in areas.face_cast(f) {
            line += &format!("  {:>20}", format!("{c:.6} ({:.1}%)", percent(*c, area)));
        }
        let _ = writeln!(s, "{line}");
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_by_extension() {
        assert_eq!(
            Format::from_path(Path::new("a.JSON")).unwrap(),
            Format::Json
        );
        assert_eq!(
            Format::from_path(Path::new("a/b.obj")).unwrap(),
            Format::Obj
        );
        assert_eq!(Format::from_path(Path::new("c.Svg")).unwrap(), Format::Svg);
        let e = Format::from_path(Path::new("out.png")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "out.png: unknown output format (use .json, .obj or .svg)"
        );
        assert!(Format::from_path(Path::new("json")).is_err());
    }

    #[test]
    fn obj_groups_name_the_lights() {
        assert_eq!(obj_group(0b1, 1), "lit");
        assert_eq!(obj_group(0b0, 1), "shadow");
        assert_eq!(obj_group(0b101, 3), "lit lit_0_2");
        assert_eq!(obj_group(0b00, 2), "shadow");
    }

    #[test]
    fn json_numbers_are_serde_jsons() {
        for x in [0.0, -0.5, 1.0, 1e-7, 123456.789, 2f64.powi(60), -3.25e-300] {
            let mut s = Vec::new();
            push_f64(&mut s, x);
            assert_eq!(
                String::from_utf8(s).unwrap(),
                serde_json::to_string(&x).unwrap()
            );
        }
    }

    #[test]
    fn svg_needs_an_eye_except_for_the_room() {
        use clap::Parser;
        let parse = |extra: &[&str]| {
            let mut argv = vec!["shadow", "shadows", "-o", "x.svg"];
            argv.extend(extra);
            match crate::Cli::try_parse_from(argv).unwrap().command {
                crate::Command::Shadows(a) => *a,
                _ => panic!("not a shadows command"),
            }
        };
        let room = parse(&["--scene", "room"]);
        let v = svg_view(&room, true).unwrap();
        assert_eq!((v.eye, v.target), (DEMO_EYE, Some(DEMO_TARGET)));
        let file = parse(&["a.obj", "--light", "0,0,-1"]);
        assert_eq!(file.lights, vec![DVec3::NEG_Z]);
        let e = svg_view(&file, false).unwrap_err().to_string();
        assert!(e.contains("--eye"), "{e}");
        let file = parse(&[
            "a.obj", "--eye", "1,2,3", "--sun", "0,0,1", "--sun", "1,0,1",
        ]);
        let v = svg_view(&file, false).unwrap();
        assert_eq!((v.eye, v.target), (DVec3::new(1.0, 2.0, 3.0), None));
        assert_eq!(file.suns.len(), 2);
        let file = parse(&[
            "a.obj",
            "--sun",
            "0,0,1",
            "--algorithm",
            "chin-feiner",
            "--threads",
            "3",
            "-q",
        ]);
        assert_eq!(file.algorithm, Algorithm::ChinFeiner);
        assert_eq!(file.threads, Some(3));
        assert!(file.quiet);
    }
}
