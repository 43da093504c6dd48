//! `shadow shadows`: exact lit and shadowed fragments of a scene for
//! point lights and suns, written as JSON, OBJ or a rendered SVG.
//!
//! Load → one grid for the scene and its point lights → import (faces
//! tagged with their index in the input) → BSP tree → shadow-volume BSP
//! fragments (`svbsp`) → output. Every lit/shadowed decision is exact for
//! the snapped scene, the snapped point lights and the quantized sun
//! directions; the outputs round the exact fragment vertices once to `f64`
//! grid units and map them back to input units. Areas and the SVG's
//! projection and shading are plain `f64` on those vertices.

use std::fmt::Write as _;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, anyhow, bail};
use bsp_core::{BspTree, Plane, Polygon};
use clap::Args;
use glam::DVec3;
use serde::Serialize;
use shadow_scene::{Face, Mesh};
use svbsp::{Fragment, Light, ShadowStats, shadow_fragments};

use crate::color::{face_colors, hex};
use crate::csg::{Phases, emit, guarded};
use crate::lights::{LightArg, SceneLight, place_lights, shared_grid};
use crate::pipeline::Prepared;
use crate::render::{Canvas, Rendered, View, painter_order, unit_normal};
use crate::{DEMO_EYE, DEMO_TARGET, ImageArgs, SourceArgs, load_source, parse_vec3};

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
    /// Print counts, timings, the area in light and in shadow of each
    /// light, and the faces with the most shadow cast on them.
    #[arg(long)]
    pub(crate) stats: bool,
}

/// The point light used for `--scene room` when no light is given: just
/// below the top of the walls, right of the room's centre and a little
/// behind it, so that the chairs, the shelf, the plant and the axis
/// object all cast shadows on the floor, the rug and the walls where the
/// demo's viewpoint sees them (the axis object's to the left of it).
pub(crate) const ROOM_LIGHT: DVec3 = DVec3::new(0.9, 0.3, 2.45);

/// How many faces `--stats` lists.
const TOP_FACES: usize = 10;

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

/// A fragment in input units, with what the outputs need.
#[derive(Clone, Debug)]
struct Piece {
    face: u32,
    /// Vertices in input units, counter-clockwise seen from the front.
    world: Vec<DVec3>,
    lit: Vec<bool>,
    /// Per light: the light is strictly in front of the fragment's plane
    /// (an unlit fragment is then in cast shadow, else in attached shadow).
    facing: Vec<bool>,
    /// Area in input units².
    area: f64,
    support: Plane,
}

/// The area of a planar polygon.
fn polygon_area(pts: &[DVec3]) -> f64 {
    let Some(&o) = pts.first() else {
        return 0.0;
    };
    let mut n = DVec3::ZERO;
    for w in pts[1..].windows(2) {
        n += (w[0] - o).cross(w[1] - o);
    }
    0.5 * n.length()
}

fn pieces(p: &Prepared, frags: &[Fragment], lights: &[SceneLight]) -> Result<Vec<Piece>> {
    frags
        .iter()
        .map(|f| {
            let world: Vec<DVec3> = f
                .vertices_f64()
                .into_iter()
                .map(|g| p.grid.to_world(g))
                .collect();
            if world.iter().any(|v| !v.is_finite()) {
                bail!(
                    "a vertex of face {} is not finite in input units (grid step {:e}): the \
                     coordinates are too large for f64",
                    f.face(),
                    p.grid.step()
                );
            }
            Ok(Piece {
                face: f.face(),
                area: polygon_area(&world),
                world,
                lit: f.lit().to_vec(),
                facing: lights
                    .iter()
                    .map(|l| l.light.eval(f.support()) > 0)
                    .collect(),
                support: *f.support(),
            })
        })
        .collect()
}

/// Areas in input units², in total, per light and per input face.
#[derive(Clone, Debug, PartialEq)]
struct Areas {
    total: f64,
    /// Per light: lit by it.
    lit: Vec<f64>,
    /// Per light: facing it but blocked.
    cast: Vec<f64>,
    /// Per light: facing away from it (or edge-on).
    attached: Vec<f64>,
    /// Lit by no light.
    dark: f64,
    /// Per input face: its area and, per light, its area in cast shadow.
    faces: Vec<(f64, Vec<f64>)>,
}

impl Areas {
    fn new(pieces: &[Piece], lights: usize, faces: usize) -> Areas {
        let mut a = Areas {
            total: 0.0,
            lit: vec![0.0; lights],
            cast: vec![0.0; lights],
            attached: vec![0.0; lights],
            dark: 0.0,
            faces: vec![(0.0, vec![0.0; lights]); faces],
        };
        for p in pieces {
            a.total += p.area;
            let face = &mut a.faces[p.face as usize];
            face.0 += p.area;
            for i in 0..lights {
                if p.lit[i] {
                    a.lit[i] += p.area;
                } else if p.facing[i] {
                    a.cast[i] += p.area;
                    face.1[i] += p.area;
                } else {
                    a.attached[i] += p.area;
                }
            }
            if !p.lit.contains(&true) {
                a.dark += p.area;
            }
        }
        a
    }

    /// Per light: the area in shadow, cast or attached.
    fn shadow(&self) -> Vec<f64> {
        self.cast
            .iter()
            .zip(&self.attached)
            .map(|(c, a)| c + a)
            .collect()
    }

    /// Faces with cast shadow, most shadow (summed over the lights) first.
    fn most_shaded(&self, n: usize) -> Vec<usize> {
        let sum = |f: usize| self.faces[f].1.iter().sum::<f64>();
        let mut faces: Vec<usize> = (0..self.faces.len()).filter(|&f| sum(f) > 0.0).collect();
        faces.sort_by(|&a, &b| sum(b).total_cmp(&sum(a)).then(a.cmp(&b)));
        faces.truncate(n);
        faces
    }
}

fn percent(part: f64, whole: f64) -> f64 {
    if whole > 0.0 {
        100.0 * part / whole
    } else {
        0.0
    }
}

// ---------------------------------------------------------------- JSON

#[derive(Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
enum JsonLight {
    Point { position: [f64; 3] },
    Directional { direction: [f64; 3] },
}

#[derive(Serialize)]
struct JsonFragment<'a> {
    face: u32,
    vertices: Vec<[f64; 3]>,
    lit: &'a [bool],
    area: f64,
}

#[derive(Serialize)]
struct JsonSummary {
    area: f64,
    lit_area: Vec<f64>,
    shadow_area: Vec<f64>,
    cast_shadow_area: Vec<f64>,
    dark_area: f64,
}

/// `{"lights": [...], "faces": N, "fragments": [...], "summary": {...}}`,
/// one fragment per line.
fn write_json(
    out: &mut impl Write,
    lights: &[SceneLight],
    faces: usize,
    pieces: &[Piece],
    areas: &Areas,
) -> Result<()> {
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
    write!(out, "{{\"lights\":")?;
    serde_json::to_writer(&mut *out, &lights)?;
    write!(out, ",\"faces\":{faces},\"fragments\":[")?;
    for (i, p) in pieces.iter().enumerate() {
        out.write_all(if i == 0 { b"\n" } else { b",\n" })?;
        let f = JsonFragment {
            face: p.face,
            vertices: p.world.iter().map(|v| v.to_array()).collect(),
            lit: &p.lit,
            area: p.area,
        };
        serde_json::to_writer(&mut *out, &f)?;
    }
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

// ----------------------------------------------------------------- OBJ

/// The OBJ group of a fragment: `shadow` when no light reaches it, else
/// `lit`, and with several lights also `lit_I_J...` naming exactly the
/// lights that reach it (an OBJ `g` line with two names puts the faces in
/// both groups).
fn obj_group(lit: &[bool]) -> String {
    let on: Vec<String> = (0..lit.len())
        .filter(|&i| lit[i])
        .map(|i| i.to_string())
        .collect();
    match (on.is_empty(), lit.len()) {
        (true, _) => "shadow".to_string(),
        (false, 1) => "lit".to_string(),
        (false, _) => format!("lit lit_{}", on.join("_")),
    }
}

/// The fragments as an OBJ mesh: one polygon per fragment, vertices with
/// equal coordinates shared, faces grouped (lit combinations in order,
/// `shadow` last). Returns the mesh and how many of its faces repeat a
/// vertex (distinct exact vertices that round to one `f64` triple).
fn obj_mesh(pieces: &[Piece]) -> (Mesh, usize) {
    let mut order: Vec<usize> = (0..pieces.len()).collect();
    // lit-by sets in lexicographic order of their light lists, none last
    let key = |i: usize| {
        let on: Vec<usize> = (0..pieces[i].lit.len())
            .filter(|&k| pieces[i].lit[k])
            .collect();
        (on.is_empty(), on)
    };
    order.sort_by_key(|&i| key(i));
    let mut mesh = Mesh::default();
    for i in order {
        let p = &pieces[i];
        let name = obj_group(&p.lit);
        let group = mesh.add_group(&name);
        let first = mesh.positions.len() as u32;
        mesh.positions.extend(&p.world);
        mesh.faces.push(Face {
            vertices: (first..first + p.world.len() as u32).collect(),
            line: 0,
            group,
        });
    }
    mesh.weld();
    let degenerate = mesh
        .faces
        .iter()
        .filter(|f| {
            let mut v = f.vertices.clone();
            v.sort_unstable();
            v.windows(2).any(|w| w[0] == w[1])
        })
        .count();
    (mesh, degenerate)
}

fn write_obj_file(
    out: &mut impl Write,
    name: &str,
    lights: &[SceneLight],
    faces: usize,
    mesh: &Mesh,
) -> Result<()> {
    writeln!(
        out,
        "# shadow shadows: {} fragments of {faces} faces of {name}",
        mesh.faces.len()
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
    shadow_scene::write_obj(mesh, &mut *out)?;
    Ok(())
}

// ----------------------------------------------------------------- SVG

/// For every BSP polygon (node-major order, as [`BspTree::polygons`]),
/// the indices of its fragments ([`Fragment::polygon`]).
fn fragments_per_polygon(tree: &BspTree, frags: &[Fragment]) -> Result<Vec<Vec<usize>>> {
    let n = tree.polygons().count();
    let mut per = vec![Vec::new(); n];
    for (j, f) in frags.iter().enumerate() {
        let Some(slot) = per.get_mut(f.polygon() as usize) else {
            bail!(
                "internal error: fragment {j} names BSP polygon {} of {n}",
                f.polygon()
            );
        };
        slot.push(j);
    }
    Ok(per)
}

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
    p: &Piece,
    normal: DVec3,
    centre: DVec3,
    lights: &[SceneLight],
    forward: DVec3,
) -> f64 {
    let weight = DIFFUSE / lights.len().max(1) as f64;
    let mut b = AMBIENT + AMBIENT_FACING * (-normal.dot(forward)).max(0.0);
    for (l, &lit) in lights.iter().zip(&p.lit) {
        if !lit {
            continue;
        }
        let to_light = match l.light {
            Light::Point(_) => (l.world - centre).normalize_or_zero(),
            Light::Directional(_) => l.world,
        };
        b += weight * normal.dot(to_light).max(0.0);
    }
    b
}

fn render(
    p: &Prepared,
    view: &View,
    frags: &[Fragment],
    pieces: &[Piece],
    lights: &[SceneLight],
) -> Result<Rendered> {
    // fragments meet along many more edges than whole polygons: a wider
    // stroke keeps their seams closed
    let mut canvas = Canvas::new(p, view, "shadow shadows", 1.0)?;
    let per_polygon = fragments_per_polygon(&p.tree, frags)?;
    let colors = face_colors(&p.mesh);
    let centres: Vec<DVec3> = (0..p.mesh.faces.len())
        .map(|f| {
            let pts = p.mesh.face_points(f);
            pts.iter().sum::<DVec3>() / pts.len().max(1) as f64
        })
        .collect();
    let forward = canvas.cam.forward();
    let polys: Vec<&Polygon> = p.tree.polygons().collect();
    let order = painter_order(&p.tree, canvas.eye_vp);
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
                let piece = &pieces[j];
                let face = piece.face as usize;
                let b = if toward {
                    let normal = unit_normal(&piece.support);
                    brightness(piece, normal, centres[face], lights, forward)
                } else {
                    // the back of a surface: no light is in front of it
                    AMBIENT
                };
                let fill = hex(colors[face], b);
                match regions.iter_mut().find(|(f, _)| *f == fill) {
                    Some((_, members)) => members.push(j),
                    None => regions.push((fill, vec![j])),
                }
            }
        }
        for (fill, members) in &regions {
            let rings = members.iter().map(|&j| pieces[j].world.iter().copied());
            canvas.region(rings, fill);
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

/// A light in words: the flag that gave it and what became of it on the
/// grid (the outputs have the exact values).
fn describe(l: &SceneLight) -> String {
    match l.light {
        Light::Point(_) => {
            let moved = l.world.distance(l.arg.value());
            if moved == 0.0 {
                format!("point light {}, on the grid", l.arg.flag())
            } else {
                format!(
                    "point light {}, snapped to the grid {moved:.1e} units away",
                    l.arg.flag()
                )
            }
        }
        Light::Directional(q) => format!(
            "sun {}, integer direction {},{},{}",
            l.arg.flag(),
            q[0],
            q[1],
            q[2]
        ),
    }
}

/// `shadow shadows`.
pub(crate) fn run(args: &ShadowsArgs) -> Result<()> {
    let total = Instant::now();
    // fail on a bad output name or a missing viewpoint before doing any work
    let format = Format::from_path(&args.output)?;
    let is_room = args.source.input.is_none() && args.source.scene.as_deref() == Some("room");
    let view = match format {
        Format::Svg => Some(svg_view(args, is_room)?),
        _ => None,
    };
    if view.is_none() && (args.eye.is_some() || args.target.is_some() || args.up.is_some()) {
        eprintln!("note: --eye, --target and --up only apply to SVG output");
    }
    let mut specs: Vec<LightArg> = args.lights.iter().map(|&p| LightArg::Point(p)).collect();
    specs.extend(args.suns.iter().map(|&d| LightArg::Sun(d)));
    let default_light = specs.is_empty();
    if default_light {
        if !is_room {
            bail!(
                "no light: give at least one --light X,Y,Z (a point light) or --sun X,Y,Z \
                 (a light at infinity); both can be repeated"
            );
        }
        specs.push(LightArg::Point(ROOM_LIGHT));
    }

    let mut phases = Phases::default();
    let (mesh, name) = phases.run("load", || load_source(&args.source))?;
    let grid = shared_grid(&mesh.positions, &specs).with_context(|| name.clone())?;
    let lights = place_lights(&grid, &specs)?;
    let prepared = Prepared::on_grid(mesh, &name, grid)?;
    phases.0.push(("snap/import", prepared.import_time));
    phases.0.push(("build", prepared.build_time));
    let kernel: Vec<Light> = lights.iter().map(|l| l.light).collect();
    let report_with = "the input and the command line";
    let (frags, sv_stats) = guarded(report_with, || {
        phases.run("shadows", || {
            shadow_fragments(&prepared.tree, &kernel).map_err(|e| anyhow!("{e}"))
        })
    })?;
    let faces = prepared.mesh.faces.len();
    let (pieces, areas) = phases.run("areas", || -> Result<_> {
        let pieces = pieces(&prepared, &frags, &lights)?;
        let areas = Areas::new(&pieces, lights.len(), faces);
        Ok((pieces, areas))
    })?;

    let written = phases.run("write", || -> Result<String> {
        let create = || {
            std::fs::File::create(&args.output)
                .map(std::io::BufWriter::new)
                .with_context(|| format!("could not write {}", args.output.display()))
        };
        let write_err = || format!("could not write {}", args.output.display());
        Ok(match format {
            Format::Json => {
                let mut out = create()?;
                write_json(&mut out, &lights, faces, &pieces, &areas).with_context(write_err)?;
                out.flush().with_context(write_err)?;
                String::new()
            }
            Format::Obj => {
                let (mesh, degenerate) = obj_mesh(&pieces);
                let mut out = create()?;
                write_obj_file(&mut out, &name, &lights, faces, &mesh).with_context(write_err)?;
                if degenerate > 0 {
                    eprintln!(
                        "warning: {degenerate} fragment(s) have distinct exact vertices that \
                         coincide once rounded to f64 input units; they are degenerate in the file"
                    );
                }
                format!(", {} vertices", mesh.positions.len())
            }
            Format::Svg => {
                let view = view.as_ref().expect("SVG output has a view");
                let r = guarded(report_with, || {
                    render(&prepared, view, &frags, &pieces, &lights)
                })?;
                let mut out = create()?;
                out.write_all(r.svg.as_bytes())
                    .and_then(|()| out.flush())
                    .with_context(write_err)?;
                format!(
                    ", {} drawn, eye {:.3},{:.3},{:.3}",
                    r.drawn, r.eye.x, r.eye.y, r.eye.z
                )
            }
        })
    })?;
    let total = total.elapsed();

    let lit_share = percent(areas.total - areas.dark, areas.total);
    let light_count = match (lights.len(), default_light) {
        (_, true) => format!("the room's default light ({})", specs[0].flag()),
        (1, false) => "1 light".to_string(),
        (n, false) => format!("{n} lights"),
    };
    let mut report = format!(
        "wrote {}: {} fragments of {faces} faces of {name}{written}; {light_count}, \
         {lit_share:.1}% of the area lit\n",
        args.output.display(),
        pieces.len(),
    );
    if args.stats {
        report += &stats_text(&prepared, &lights, &sv_stats, &areas, &phases, total);
    }
    emit(&report)
}

/// The `--stats` report.
fn stats_text(
    p: &Prepared,
    lights: &[SceneLight],
    sv: &ShadowStats,
    areas: &Areas,
    phases: &Phases,
    total: std::time::Duration,
) -> String {
    let t = p.tree.stats();
    let mut s = String::new();
    let _ = writeln!(
        s,
        "faces:           {} ({} polygons after import: {} faces triangulated, {} dropped)",
        p.mesh.faces.len(),
        p.report.polygons,
        p.report.triangulated.len(),
        p.report.dropped.len()
    );
    let _ = writeln!(
        s,
        "grid step:       2^{} = {:.3e} units",
        -p.grid.scale().log2(),
        p.grid.step()
    );
    let _ = writeln!(
        s,
        "bsp:             {} polygons, {} nodes, depth {}",
        t.polygons, t.nodes, t.depth
    );
    let _ = writeln!(
        s,
        "fragments:       {} ({} shadow-tree nodes over {} light{})",
        sv.fragments,
        sv.shadow_nodes,
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
        "time:            {}; total {:.2} ms",
        times.join(", "),
        total.as_secs_f64() * 1e3
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
        let (area, cast) = &areas.faces[f];
        let mut line = format!("  {f:>7}  {:<12} {area:>12.6}", p.mesh.group_name(f));
        for c in cast {
            line += &format!("  {:>20}", format!("{c:.6} ({:.1}%)", percent(*c, *area)));
        }
        let _ = writeln!(s, "{line}");
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn piece(face: u32, lit: &[bool], facing: &[bool], area: f64) -> Piece {
        Piece {
            face,
            world: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            lit: lit.to_vec(),
            facing: facing.to_vec(),
            area,
            support: Plane::new([0, 0, 1], 0).unwrap(),
        }
    }

    #[test]
    fn fragments_are_found_in_their_bsp_polygons() {
        let specs = [
            LightArg::Point(ROOM_LIGHT),
            LightArg::Sun(DVec3::new(-1.0, 2.0, 4.0)),
        ];
        let mesh = shadow_scene::room();
        let grid = shared_grid(&mesh.positions, &specs).unwrap();
        let lights = place_lights(&grid, &specs).unwrap();
        let p = Prepared::on_grid(mesh, "room", grid).unwrap();
        let kernel: Vec<Light> = lights.iter().map(|l| l.light).collect();
        let (frags, _) = shadow_fragments(&p.tree, &kernel).unwrap();
        let per = fragments_per_polygon(&p.tree, &frags).unwrap();
        let pieces = pieces(&p, &frags, &lights).unwrap();
        // every polygon gets fragments, every fragment one polygon, and
        // the fragments of a polygon cover its area
        assert_eq!(per.iter().map(Vec::len).sum::<usize>(), frags.len());
        for (poly, members) in p.tree.polygons().zip(&per) {
            assert!(!members.is_empty());
            let world: Vec<DVec3> = poly
                .vertices_f64()
                .into_iter()
                .map(|g| p.grid.to_world(g))
                .collect();
            let area = polygon_area(&world);
            let covered: f64 = members.iter().map(|&j| pieces[j].area).sum();
            assert!(
                (covered - area).abs() <= 1e-9 * area.max(1.0),
                "{covered} vs {area}"
            );
        }
    }

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
    fn areas_split_lit_cast_and_attached() {
        let pieces = [
            piece(0, &[true, false], &[true, true], 2.0),
            piece(0, &[false, false], &[true, false], 3.0),
            piece(1, &[false, true], &[false, true], 5.0),
        ];
        let a = Areas::new(&pieces, 2, 3);
        assert_eq!(a.total, 10.0);
        assert_eq!(a.lit, vec![2.0, 5.0]);
        assert_eq!(a.cast, vec![3.0, 2.0]);
        assert_eq!(a.attached, vec![5.0, 3.0]);
        assert_eq!(a.shadow(), vec![8.0, 5.0]);
        assert_eq!(a.dark, 3.0);
        assert_eq!(a.faces[0], (5.0, vec![3.0, 2.0]));
        assert_eq!(a.faces[1], (5.0, vec![0.0, 0.0]));
        assert_eq!(a.faces[2], (0.0, vec![0.0, 0.0]));
        assert_eq!(a.most_shaded(10), vec![0]);
    }

    #[test]
    fn polygon_areas() {
        let sq = [
            DVec3::new(1.0, 1.0, 5.0),
            DVec3::new(3.0, 1.0, 5.0),
            DVec3::new(3.0, 4.0, 5.0),
            DVec3::new(1.0, 4.0, 5.0),
        ];
        assert_eq!(polygon_area(&sq), 6.0);
        assert_eq!(polygon_area(&sq[..2]), 0.0);
        assert_eq!(polygon_area(&[]), 0.0);
    }

    #[test]
    fn obj_groups_name_the_lights() {
        assert_eq!(obj_group(&[true]), "lit");
        assert_eq!(obj_group(&[false]), "shadow");
        assert_eq!(obj_group(&[true, false, true]), "lit lit_0_2");
        assert_eq!(obj_group(&[false, false]), "shadow");
        let pieces = [
            piece(0, &[false, false], &[true, true], 1.0),
            piece(0, &[false, true], &[true, true], 1.0),
            piece(1, &[true, true], &[true, true], 1.0),
        ];
        let (mesh, degenerate) = obj_mesh(&pieces);
        // the three triangles share their corners
        assert_eq!((mesh.positions.len(), degenerate), (3, 0));
        let names: Vec<&str> = (0..3).map(|f| mesh.group_name(f)).collect();
        assert_eq!(names, ["lit lit_0_1", "lit lit_1", "shadow"]);
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
    }
}
