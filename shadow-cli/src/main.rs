//! `shadow`: the command-line front end of the exact BSP shadow toolkit.
//!
//! ```text
//! shadow shadows [INPUT | --scene NAME] [--light X,Y,Z]... [--sun X,Y,Z]...
//!                -o OUT.json|OUT.obj|OUT.svg [--eye X,Y,Z] [--target X,Y,Z]
//!                [--up X,Y,Z] [--width W] [--height H] [--fov DEG] [--stats]
//! shadow view    [INPUT | --scene NAME] --eye X,Y,Z [--target X,Y,Z] [--up X,Y,Z]
//!                -o OUT.svg [--width W] [--height H] [--fov DEG]
//! shadow stats   [INPUT | --scene NAME]
//! shadow demo    [-o room.svg]
//! shadow csg     union|intersection|difference A B -o OUT [--weld] [--stats]
//! shadow animate (--scene room | STATIC --dynamic DYNAMIC) [--light X,Y,Z]... [--sun X,Y,Z]...
//!                [--frames N] [--spin AX,AY,AZ:DEG] [--spin-center X,Y,Z] [--step DX,DY,DZ]
//!                -o DIR [--format svg|png|json|none] [--report FILE.csv] [--export-scene]
//!                [--strategy paper|fast] [--tiles N]
//! shadow render  [INPUT | --scene NAME] [lights] [camera] [--method M] [--hsr H]
//!                [--mask MASK.pgm] -o OUT.png
//! shadow compare [INPUT | --scene NAME] [lights] [camera] -o OUT.png [--report OUT.csv]
//! shadow lines   [INPUT | --scene NAME] [camera] [--hidden] -o OUT.svg
//! ```
//!
//! Every command loads a mesh (OBJ or STL) or a built-in scene, snaps it
//! to an exact integer grid, builds a BSP tree, and uses it: `shadows`
//! cuts every face into exactly lit and shadowed fragments for point
//! lights and suns (see `docs/shadows.md`), `view` draws the scene with
//! the painter's algorithm in the tree's exact back-to-front order,
//! `stats` reports the tree's figures, `demo` renders the built-in room,
//! `csg` computes an exact Boolean operation of two closed meshes and
//! writes the watertight result (OBJ or binary STL), `animate` runs the
//! core paper's real-time pipeline on a moving object (see `tiling`);
//! `render`, `compare` and `lines` draw PNG images and hidden-line SVG
//! with `shadow-raster` (see `docs/raster.md`).
//! Errors go to stderr as `error: ...` with exit code 1.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Args, Parser, Subcommand};
use glam::DVec3;

mod animate;
mod color;
mod csg;
mod lights;
mod pipeline;
mod progress;
mod raster_cmd;
mod render;
mod shadows;

use pipeline::Prepared;
use render::View;

#[derive(Parser, Debug)]
#[command(
    name = "shadow",
    version,
    about = "Exact BSP shadows, hidden-surface rendering, Boolean operations and statistics for \
             polygon scenes"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Exact lit and shadowed fragments for point lights and suns, as
    /// JSON, OBJ or an SVG view.
    Shadows(Box<shadows::ShadowsArgs>),
    /// Render a mesh or built-in scene to SVG in exact BSP back-to-front order.
    View(ViewArgs),
    /// Print import and BSP tree statistics of a mesh or built-in scene.
    Stats(SourceArgs),
    /// Render the built-in room from a viewpoint that shows all of it.
    Demo(DemoArgs),
    /// Exact union, intersection or difference of two closed meshes.
    Csg(csg::CsgArgs),
    /// The core paper's real-time pipeline: a moving object's exact
    /// shadows in a static scene, frame by frame, with Table 2's figures.
    Animate(Box<animate::AnimateArgs>),
    /// Render a scene and its shadows to PNG by the exact method or a
    /// classic image-space one (shadow map, stencil volumes, ...).
    Render(Box<raster_cmd::RenderArgs>),
    /// Every shadow method side by side, with the share of pixels where
    /// each disagrees with the exact shadows.
    Compare(Box<raster_cmd::CompareArgs>),
    /// Hidden-line drawing of convex polyhedra (Roberts' algorithm) to SVG.
    Lines(Box<raster_cmd::LinesArgs>),
}

/// Where the mesh comes from: a file or a built-in scene (exactly one).
#[derive(Args, Debug)]
struct SourceArgs {
    /// Mesh file (.obj or .stl).
    input: Option<PathBuf>,
    /// Built-in scene instead of a file (room, chair, cube, bunny, or the
    /// bunny refined to bunny-11k ... bunny-893k faces).
    #[arg(long, value_name = "NAME")]
    scene: Option<String>,
}

#[derive(Args, Debug)]
struct ViewArgs {
    #[command(flatten)]
    source: SourceArgs,
    /// Eye position.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    eye: DVec3,
    /// Point looked at [default: centre of the scene's bounding box].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    target: Option<DVec3>,
    /// Up direction [default: +Z, or +Y when looking along Z].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    up: Option<DVec3>,
    /// Output SVG file.
    #[arg(short, long, value_name = "OUT.svg")]
    output: PathBuf,
    #[command(flatten)]
    image: ImageArgs,
}

#[derive(Args, Debug)]
struct ImageArgs {
    /// Image width in pixels.
    #[arg(long, default_value_t = 1200, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 900, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    height: u32,
    /// Vertical field of view in degrees (between 1 and 170).
    #[arg(long, value_name = "DEG", default_value_t = 50.0, value_parser = parse_fov)]
    fov: f64,
}

#[derive(Args, Debug)]
struct DemoArgs {
    /// Output SVG file.
    #[arg(short, long, value_name = "OUT.svg", default_value = "room.svg")]
    output: PathBuf,
    #[command(flatten)]
    image: ImageArgs,
}

/// Parses `X,Y,Z` into a finite vector.
fn parse_vec3(s: &str) -> Result<DVec3, String> {
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
    Ok(DVec3::from_array(v))
}

fn parse_fov(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    if (1.0..=170.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("{v} is outside 1..=170 degrees"))
    }
}

/// The default demo viewpoint: from the open front side of the room,
/// slightly above, looking at its middle.
const DEMO_EYE: DVec3 = DVec3::new(3.3, -7.4, 4.3);
const DEMO_TARGET: DVec3 = DVec3::new(-0.15, 0.3, 0.45);

/// Reads a mesh file: an error if it has no faces; a note on stderr
/// (unless `quiet`) if the reader skipped unknown statements.
fn load_mesh(path: &Path, quiet: bool) -> Result<shadow_scene::Mesh> {
    let (mesh, note) = read_mesh(path)?;
    if let Some(m) = note
        && !quiet
    {
        eprintln!("note: {m}");
    }
    with_faces(path, mesh)
}

/// [`load_mesh`]'s reading, printing nothing: the mesh, faces or not, and
/// the reader's note on what it skipped.
fn read_mesh(path: &Path) -> Result<(shadow_scene::Mesh, Option<String>)> {
    let (mesh, notes) = shadow_scene::load_notes(path)?;
    Ok((mesh, notes.message(&path.display().to_string())))
}

/// `mesh` read from `path`, unless it has no faces.
fn with_faces(path: &Path, mesh: shadow_scene::Mesh) -> Result<shadow_scene::Mesh> {
    if mesh.faces.is_empty() {
        bail!("{}: no faces", path.display());
    }
    Ok(mesh)
}

fn load_source(src: &SourceArgs) -> Result<(shadow_scene::Mesh, String)> {
    load_source_quiet(src, false)
}

fn load_source_quiet(src: &SourceArgs, quiet: bool) -> Result<(shadow_scene::Mesh, String)> {
    match (&src.input, &src.scene) {
        (Some(path), None) => Ok((load_mesh(path, quiet)?, path.display().to_string())),
        (None, Some(name)) => {
            let mesh = shadow_scene::scene(name).with_context(|| {
                format!(
                    "unknown scene `{name}` (available: {})",
                    shadow_scene::SCENE_NAMES.join(", ")
                )
            })?;
            Ok((mesh, format!("scene {name}")))
        }
        (Some(_), Some(_)) => bail!("give either an INPUT file or --scene NAME, not both"),
        (None, None) => bail!("no input: give a mesh file (.obj or .stl) or --scene NAME"),
    }
}

fn write_file(path: &Path, contents: &str) -> Result<()> {
    std::fs::write(path, contents).with_context(|| format!("could not write {}", path.display()))
}

fn view(args: &ViewArgs) -> Result<()> {
    let (mesh, name) = load_source(&args.source)?;
    let prepared = Prepared::new(mesh, &name)?;
    let view = View {
        eye: args.eye,
        target: args.target,
        up: args.up,
        width: args.image.width,
        height: args.image.height,
        fov_deg: args.image.fov,
    };
    let out = render::render_svg(&prepared, &view)?;
    write_file(&args.output, &out.svg)?;
    println!(
        "wrote {}: {} polygons of {} ({} faces), eye {}",
        args.output.display(),
        out.drawn,
        name,
        prepared.mesh.faces.len(),
        fmt_vec(out.eye)
    );
    Ok(())
}

fn stats(args: &SourceArgs) -> Result<()> {
    let (mesh, name) = load_source(args)?;
    let p = Prepared::new(mesh, &name)?;
    let t = p.tree.stats();
    println!("input:           {name}");
    println!("faces:           {}", p.mesh.faces.len());
    println!(
        "polygons:        {} after import ({} faces triangulated, {} dropped)",
        p.report.polygons,
        p.report.triangulated.len(),
        p.report.dropped.len()
    );
    println!("bsp polygons:    {} after splitting", t.polygons);
    println!("nodes:           {}", t.nodes);
    println!("depth:           {}", t.depth);
    println!("cells:           {} in, {} out", t.in_cells, t.out_cells);
    println!(
        "grid step:       2^{} = {:.3e} units",
        -p.grid.scale().log2(),
        p.grid.step()
    );
    println!(
        "import time:     {:.2} ms",
        p.import_time.as_secs_f64() * 1e3
    );
    println!(
        "build time:      {:.2} ms",
        p.build_time.as_secs_f64() * 1e3
    );
    Ok(())
}

fn demo(args: &DemoArgs) -> Result<()> {
    let prepared = Prepared::new(shadow_scene::room(), "scene room")?;
    let view = View {
        eye: DEMO_EYE,
        target: Some(DEMO_TARGET),
        up: None,
        width: args.image.width,
        height: args.image.height,
        fov_deg: args.image.fov,
    };
    let out = render::render_svg(&prepared, &view)?;
    write_file(&args.output, &out.svg)?;
    println!(
        "wrote {}: the built-in room, {} polygons ({} faces, {} BSP fragments), eye {}",
        args.output.display(),
        out.drawn,
        prepared.mesh.faces.len(),
        prepared.tree.stats().polygons,
        fmt_vec(out.eye)
    );
    Ok(())
}

fn fmt_vec(v: DVec3) -> String {
    format!("{:.3},{:.3},{:.3}", v.x, v.y, v.z)
}

fn main() -> ExitCode {
    progress::clean_up_on_interrupt();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => {
            // --help and --version
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            let _ = e.print();
            return ExitCode::FAILURE;
        }
    };
    let result = match &cli.command {
        Command::Shadows(a) => shadows::run(a),
        Command::View(a) => view(a),
        Command::Stats(a) => stats(a),
        Command::Demo(a) => demo(a),
        Command::Csg(a) => csg::run(a),
        Command::Animate(a) => animate::run(a),
        Command::Render(a) => raster_cmd::run_render(a),
        Command::Compare(a) => raster_cmd::run_compare(a),
        Command::Lines(a) => raster_cmd::run_lines(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vectors_parse_with_clear_errors() {
        assert_eq!(
            parse_vec3("1,-2.5, 3e1").unwrap(),
            DVec3::new(1.0, -2.5, 30.0)
        );
        assert_eq!(
            parse_vec3("1,2").unwrap_err(),
            "expected three comma-separated numbers X,Y,Z, got 2 value(s)"
        );
        assert_eq!(
            parse_vec3("1,y,3").unwrap_err(),
            "`y` is not a number (expected X,Y,Z)"
        );
        assert_eq!(
            parse_vec3("1,nan,3").unwrap_err(),
            "`nan` is not a finite number"
        );
        assert!(parse_vec3("").is_err());
    }

    #[test]
    fn fov_range() {
        assert_eq!(parse_fov("60").unwrap(), 60.0);
        assert!(parse_fov("0").is_err());
        assert!(parse_fov("180").is_err());
        assert!(parse_fov("wide").is_err());
    }

    #[test]
    fn command_line_shapes() {
        let cli = Cli::try_parse_from([
            "shadow", "view", "--scene", "room", "--eye", "-3,2,1", "-o", "x.svg",
        ])
        .unwrap();
        let Command::View(v) = cli.command else {
            panic!("not a view command")
        };
        assert_eq!(v.eye, DVec3::new(-3.0, 2.0, 1.0));
        assert_eq!(
            (v.image.width, v.image.height, v.image.fov),
            (1200, 900, 50.0)
        );
        assert!(Cli::try_parse_from(["shadow", "view", "--scene", "room", "-o", "x.svg"]).is_err());
        assert!(
            Cli::try_parse_from([
                "shadow", "view", "--scene", "room", "--eye", "1,2", "-o", "x"
            ])
            .is_err()
        );
        assert!(Cli::try_parse_from(["shadow", "demo", "--width", "0"]).is_err());
    }

    #[test]
    fn source_must_be_exactly_one() {
        let both = SourceArgs {
            input: Some("a.obj".into()),
            scene: Some("room".into()),
        };
        assert!(
            load_source(&both)
                .unwrap_err()
                .to_string()
                .contains("not both")
        );
        let none = SourceArgs {
            input: None,
            scene: None,
        };
        assert!(
            load_source(&none)
                .unwrap_err()
                .to_string()
                .starts_with("no input")
        );
        let unknown = SourceArgs {
            input: None,
            scene: Some("kitchen".into()),
        };
        assert_eq!(
            load_source(&unknown).unwrap_err().to_string(),
            "unknown scene `kitchen` (available: room, chair, cube, bunny, bunny-11k, bunny-33k, \
             bunny-99k, bunny-298k, bunny-893k)"
        );
    }
}
