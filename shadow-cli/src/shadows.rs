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

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use bsp_shadows::shadow_file::{self, FileKind, LitScene, OutputFormat as Format, write_shadows};
use bsp_shadows::soft_file::{SoftScene, draw_soft_shadows, write_soft_shadows};
use clap::{Args, ValueEnum};
use shadow_raster::svg::SvgViewpoint;
use svbsp::export::FragmentFormat;
use svbsp::{LightSpec, SoftSpec, percent};

use crate::args::{CameraArgs, ImageArgs, LightArgs, SourceArgs};
use crate::facade_error;
use crate::input::{NO_LIGHT, Scene};
use crate::lights::describe;
use crate::output::{Output, Phases, emit, guarded};
use crate::progress::Progress;

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
    #[command(flatten)]
    pub(crate) lights: LightArgs,
    /// Output file: .json (the fragments), .obj (groups `lit` and
    /// `shadow`) or .svg (a view of the shaded scene).
    #[arg(short, long, value_name = "OUT")]
    pub(crate) output: PathBuf,
    /// The SVG's viewpoint.
    #[command(flatten)]
    pub(crate) camera: CameraArgs,
    #[command(flatten)]
    pub(crate) image: ImageArgs,
    /// The algorithm.
    #[arg(long, value_enum, default_value_t = Algorithm::Psv)]
    pub(crate) algorithm: Algorithm,
    /// Print counts, timings, the area in light and in shadow of each
    /// light, and the faces with the most shadow cast on them.
    #[arg(long)]
    pub(crate) stats: bool,
    /// No progress bar and no notes on stderr (errors still go there).
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

/// The output format, by the file's extension.
fn format_of(path: &Path) -> Result<Format> {
    let known = Format::from_path(path);
    known.with_context(|| {
        format!(
            "{}: unknown output format (use .json, .obj or .svg)",
            path.display()
        )
    })
}

// ------------------------------------------------------------- command

/// The output format and the lights given, checked before any work is
/// done: fails on a bad output name, or no light for a file (a built-in
/// scene may have its own).
fn request(args: &ShadowsArgs) -> Result<(Format, Vec<LightSpec>, Vec<SoftSpec>)> {
    let format = format_of(&args.output)?;
    if format != Format::Svg && (args.camera.any() || args.image.any()) {
        note(
            args,
            "note: --eye, --target, --up, --size and --fov only apply to SVG output",
        );
    }
    args.source.check()?;
    let specs = args.lights.specs();
    let soft = args.lights.soft();
    if specs.is_empty() && soft.is_empty() && args.source.input.is_some() {
        bail!("{NO_LIGHT}");
    }
    if !soft.is_empty() && args.algorithm != Algorithm::Psv {
        bail!("soft shadows (--area-light, --sun-disc) are made with --algorithm psv only");
    }
    Ok((format, specs, soft))
}

/// A note on stderr, unless `--quiet`.
fn note(args: &ShadowsArgs, s: &str) {
    crate::output::note(args.quiet, s);
}

/// `shadow shadows`.
pub(crate) fn run(args: &ShadowsArgs) -> Result<()> {
    let total = Instant::now();
    let (format, specs, soft) = request(args)?;
    let progress = Progress::new(!args.quiet);
    let mut phases = Phases::default();
    progress.phase("loading", 1);
    let scene = Scene::load(&args.source, (specs, &soft), true, args.quiet, &mut phases)?;
    let view = (format == Format::Svg).then(|| {
        let size = args.image.size();
        let image = (size, args.image.fov);
        args.camera
            .pick(&scene.mesh, scene.staging, image, args.quiet)
    });
    if !scene.soft.is_empty() {
        return soft_shadows(args, &scene, (format, view.as_ref()), progress);
    }
    let mut out = Output::create(&args.output)?;
    let kind = match (format, &view) {
        (Format::Svg, Some(v)) => FileKind::Svg(v),
        (Format::Obj, _) => FileKind::Obj,
        _ => FileKind::Json,
    };
    let algorithm = match args.algorithm {
        Algorithm::Psv => shadow_file::Algorithm::Psv,
        Algorithm::ChinFeiner => shadow_file::Algorithm::ChinFeiner,
    };
    let notes: Vec<String> = scene.lights.iter().map(describe).collect();
    let lit = LitScene {
        name: &scene.name,
        mesh: &scene.mesh,
        grid: &scene.grid,
        lights: &scene.lights,
        light_notes: &notes,
        polys: &scene.polys,
    };
    let fig = guarded("the input and the command line", || {
        write_shadows(&lit, algorithm, kind, &mut out, &progress).map_err(|e| match e {
            bsp_shadows::Error::Io(_)
            | bsp_shadows::Error::Export(_)
            | bsp_shadows::Error::Raster(_) => {
                facade_error(e).context(format!("could not write {}", args.output.display()))
            }
            e => facade_error(e),
        })
    })?;
    out.commit()?;
    drop(progress);
    let total = total.elapsed();
    phases.0.extend(fig.phases.iter().copied());
    if fig.degenerate > 0 {
        let n = fig.degenerate;
        note(
            args,
            &format!(
                "warning: {n} fragment piece(s) have distinct exact vertices that \
             coincide once rounded to f64 input units; they are degenerate in the file"
            ),
        );
    }

    let areas = &fig.areas;
    let lit_share = percent(areas.total - areas.dark, areas.total);
    // the SVG's fragments are pieces of the scene tree's polygons, the
    // files' pieces of the faces: say which
    let of = match fig.bsp_polygons {
        Some(n) => format!(
            "the scene tree's {n} polygons ({} faces)",
            scene.mesh.faces.len()
        ),
        None => format!("{} faces", scene.mesh.faces.len()),
    };
    let extra = match (fig.vertices, fig.drawn) {
        (_, Some((drawn, eye))) => format!(
            ", {drawn} drawn, eye {:.3},{:.3},{:.3}",
            eye.x, eye.y, eye.z
        ),
        (Some(v), None) => format!(", {v} vertices"),
        (None, None) => String::new(),
    };
    let mut report = format!(
        "wrote {}: {} fragments of {of} of {}{extra}; {}, {lit_share:.1}% of the area lit\n",
        args.output.display(),
        fig.fragments,
        scene.name,
        scene.light_count(),
    );
    if fig.fragments == 0 {
        note(
            args,
            "note: no face has an area on the grid, so nothing was shaded (are the faces \
             collinear or repeated?)",
        );
    } else if areas.total > 0.0 && areas.dark >= areas.total {
        note(
            args,
            "note: nothing is lit (is a point light inside a closed mesh, or behind every face?)",
        );
    }
    if args.stats {
        let lights: Vec<(String, f64)> = scene
            .lights
            .iter()
            .map(|l| (describe(l), l.angle))
            .collect();
        let import = scene.report.counts();
        let group = |f| scene.mesh.group_name(f).to_string();
        let faces = scene.mesh.faces.len();
        let import = (faces, import.as_str(), &scene.grid);
        report += &fig.stats_text(import, &lights, (&phases.0, total), group);
    }
    crate::output::drop_in_background(scene);
    emit(&report)
}

/// `shadow shadows` with lights of extent: every light's lit, penumbra
/// and umbra fragments as JSON or OBJ, or drawn as SVG.
fn soft_shadows(
    args: &ShadowsArgs,
    scene: &Scene,
    (format, view): (Format, Option<&SvgViewpoint>),
    progress: Progress,
) -> Result<()> {
    let (name, faces, grid) = (&scene.name, scene.mesh.faces.len(), &scene.grid);
    let (lights, polys) = (&scene.soft, &scene.polys);
    let job = SoftScene {
        name,
        faces,
        grid,
        lights,
        polys,
    };
    let mut out = Output::create(&args.output)?;
    let fig = guarded("the input and the command line", || {
        match view {
            Some(at) => draw_soft_shadows(&job, &scene.mesh, at, &mut out, &progress),
            None if format == Format::Obj => {
                write_soft_shadows(&job, FragmentFormat::Obj, &mut out, &progress)
            }
            None => write_soft_shadows(&job, FragmentFormat::Json, &mut out, &progress),
        }
        .map_err(facade_error)
    })?;
    out.commit()?;
    drop(progress);
    let mut report = fig.wrote(&args.output, &job, &scene.light_count());
    report += &fig.report();
    if args.stats {
        report += &fig.stats_text(job.faces);
    }
    emit(&report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;
    use shadow_scene::{ROOM_EYE, ROOM_TARGET};

    #[test]
    fn formats_by_extension() {
        assert_eq!(format_of(Path::new("a.JSON")).unwrap(), Format::Json);
        assert_eq!(format_of(Path::new("a/b.obj")).unwrap(), Format::Obj);
        assert_eq!(format_of(Path::new("c.Svg")).unwrap(), Format::Svg);
        let e = format_of(Path::new("out.png")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "out.png: unknown output format (use .json, .obj or .svg)"
        );
        assert!(format_of(Path::new("json")).is_err());
    }

    #[test]
    fn svg_viewpoints_from_flags_staging_or_framing() {
        use clap::Parser;
        let parse = |extra: &[&str]| {
            let mut argv = vec!["shadow", "shadows", "-o", "x.svg"];
            argv.extend(extra);
            let cli = crate::Cli::try_parse_from(argv).unwrap();
            match cli.command {
                crate::Command::Shadows(a) => (*a, cli.threads),
                _ => panic!("not a shadows command"),
            }
        };
        let cube = shadow_scene::scene("cube").unwrap();
        let view = |a: &ShadowsArgs, staging| {
            a.camera
                .viewpoint(&cube, staging, a.image.size(), a.image.fov)
        };
        let (room, _) = parse(&["--scene", "room"]);
        let room_box = shadow_scene::room().bounds().unwrap();
        let (v, framed) = view(&room, room.source.staging(room_box));
        assert_eq!(
            (v.eye, v.target, framed),
            (ROOM_EYE, Some(ROOM_TARGET), false)
        );
        let (file, _) = parse(&["a.obj", "--light", "0,0,-1", "--up", "y"]);
        assert_eq!(file.lights.lights, vec![DVec3::NEG_Z]);
        let (v, framed) = view(&file, None);
        assert!(framed);
        assert_eq!(v.up, Some(DVec3::Y));
        // the target centres the picture: within the box, near its centre
        let t = v.target.unwrap();
        assert!(
            t.cmpge(DVec3::ZERO).all() && t.cmple(DVec3::ONE).all(),
            "{t:?}"
        );
        assert!(v.eye.y > 1.0 && v.eye.z > 1.0, "{:?}", v.eye);
        let (file, _) = parse(&[
            "a.obj", "--eye", "1,2,3", "--sun", "0,0,1", "--sun", "1,0,1",
        ]);
        let (v, framed) = view(&file, None);
        assert_eq!(
            (v.eye, v.target, framed),
            (DVec3::new(1.0, 2.0, 3.0), None, false)
        );
        assert_eq!(file.lights.suns.len(), 2);
        let (file, threads) = parse(&[
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
        assert_eq!(threads, Some(3));
        assert!(file.quiet);
    }
}
