//! `shadow`: the command-line front end of the exact BSP shadow toolkit.
//!
//! `shadow --help` lists the commands, `shadow COMMAND --help` their flags.
//!
//! Every command takes `--threads N`. This crate parses the flags, reads
//! and writes the files, shows progress and words the messages; the work
//! is the libraries': `svbsp` (shadows, their JSON and OBJ files),
//! `bsp-csg` (Booleans), `tiling` (the real-time pipeline),
//! `shadow-raster` (PNG images, SVG pictures, the classic image-space
//! methods) and `shadow-scene` (meshes, built-in scenes, the palette).
//! Errors go to stderr as `error: ...` with exit code 1.

use std::process::ExitCode;

use anyhow::{Context, Result, anyhow};
use clap::{CommandFactory, Parser, Subcommand};
use shadow_raster::{CameraError, RasterError};

mod animate;
mod args;
mod art;
mod csg;
mod input;
mod lights;
mod output;
mod progress;
mod raster;
mod shadows;
mod sun;
mod view;

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
    /// Worker threads [default: one per core]; the output is the same for
    /// every count.
    #[arg(long, global = true, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1024))]
    threads: Option<u32>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Exact lit and shadowed fragments for point lights and suns, as
    /// JSON, OBJ or an SVG view.
    #[command(
        after_help = "Examples:\n  shadow shadows --scene room -o room.svg\n  shadow shadows part.obj --light 2,3,5 --sun 1,1,3 -o part.json --stats"
    )]
    Shadows(Box<shadows::ShadowsArgs>),
    /// Render a mesh or built-in scene to SVG in exact BSP back-to-front order.
    #[command(
        after_help = "Examples:\n  shadow view --scene bunny -o bunny.svg\n  shadow view scan.obj --up y -o scan.svg"
    )]
    View(view::ViewArgs),
    /// Print import and BSP tree statistics of a mesh or built-in scene.
    #[command(after_help = "Examples:\n  shadow stats part.obj")]
    Stats(view::StatsArgs),
    /// Render the built-in room from a viewpoint that shows all of it.
    #[command(after_help = "Examples:\n  shadow demo -o room.svg")]
    Demo(view::DemoArgs),
    /// Exact union, intersection or difference of two closed meshes.
    #[command(
        after_help = "Examples:\n  shadow csg union a.obj b.obj -o u.obj\n  shadow csg difference part.stl tool1.stl tool2.stl -o cut.stl --stats\n  shadow csg union dirty.obj -o clean.obj"
    )]
    Csg(csg::CsgArgs),
    /// The core paper's real-time pipeline: a moving object's exact
    /// shadows in a static scene, frame by frame, with Table 2's figures.
    #[command(
        after_help = "Examples:\n  shadow animate --scene room --frames 24 -o frames/ --report table2.csv\n  shadow animate ground.obj --dynamic cube.obj --light 0,0,9 --spin 0,0,1:15 -o frames/"
    )]
    Animate(Box<animate::AnimateArgs>),
    /// Render a scene and its shadows to PNG by the exact method or a
    /// classic image-space one (shadow map, stencil volumes, ...).
    #[command(
        after_help = "Examples:\n  shadow render --scene room --method shadow-map -o room.png\n  shadow render part.obj --light 2,3,5 --size 1920x1080 -o part.png --mask lit.pgm"
    )]
    Render(Box<raster::RenderArgs>),
    /// Every shadow method side by side, with the share of pixels where
    /// each disagrees with the exact shadows.
    #[command(
        after_help = "Examples:\n  shadow compare --scene room -o compare.png --report compare.csv"
    )]
    Compare(Box<raster::CompareArgs>),
    /// Hidden-line drawing of convex polyhedra (Roberts' algorithm) to SVG.
    #[command(after_help = "Examples:\n  shadow lines --scene room -o lines.svg --hidden")]
    Lines(Box<raster::LinesArgs>),
    /// Shadow art: the exact hull whose shadows make several images, and
    /// how much of each it gives.
    #[command(
        after_help = "Examples:\n  shadow art geb.json -o geb.obj --report geb.json --images views/\n  \
                      shadow art bunny/spec.json -o hull.stl --simplify 1.5\n  \
                      shadow art geb.json -o geb.obj --optimize --deform --images moved/"
    )]
    Art(art::ArtArgs),
    /// Where the sun is at a place and time (NREL's SPA), in the scene's
    /// axes: the light of a sun study.
    #[command(
        after_help = "Examples:\n  shadow sun --lat 51.5 --lon -0.12 --time 2026-03-21T12:00:00Z --json"
    )]
    Sun(sun::SunArgs),
    /// Every face's exact sun-hours over a day or days: the mean of its
    /// points', the fewest and the most.
    #[command(
        after_help = "Examples:\n  shadow sunhours --scene room --lat 51.5 --lon -0.12 --date 2026-03-21 -o hours.csv\n  shadow sunhours city.obj --lat 40.4 --lon -3.7 --date 2026-12-21 --sensors windows.csv -o w.csv\n  shadow sunhours --scene bunny-11k --lat 51.5 --lon -0.1 --date 2026-03-21 --up y -o heat.png\n  shadow sunhours site.obj --lat 51.5 --lon -0.1 --date 2026-03-21 --regions garden --bre209 -o garden.csv"
    )]
    Sunhours(Box<sun::SunHoursArgs>),
    /// Print a shell completion script (bash, zsh, fish, elvish or
    /// powershell).
    #[command(
        after_help = "Examples:\n  shadow completions bash > ~/.local/share/bash-completion/completions/shadow"
    )]
    Completions {
        /// The shell.
        shell: clap_complete::Shell,
    },
    /// Print the man page (roff).
    #[command(after_help = "Examples:\n  shadow man > shadow.1 && man ./shadow.1")]
    Man,
}

/// A rendering error worded for the command line: a camera that cannot
/// be set up names the flags that set it.
pub(crate) fn raster_error(e: RasterError) -> anyhow::Error {
    match e {
        RasterError::Camera(CameraError::EyeAtTarget) => {
            anyhow!("the eye and the target coincide; give a different --eye or --target")
        }
        RasterError::Camera(CameraError::TooFar(d)) => anyhow!(
            "the eye is {d:.3e} units from the target: too far for f64; give a nearer --eye"
        ),
        RasterError::Camera(CameraError::UpAlongView) => {
            anyhow!("the up vector is parallel to the view direction; give another --up")
        }
        RasterError::Camera(CameraError::ZeroUp) => {
            anyhow!("the up vector must not be zero; give another --up")
        }
        e => anyhow!(e),
    }
}

/// A facade error worded for the command line: a picture's error as
/// [`raster_error`] words it.
pub(crate) fn facade_error(e: bsp_shadows::Error) -> anyhow::Error {
    match e {
        bsp_shadows::Error::Raster(e) => raster_error(e),
        e => anyhow!(e),
    }
}

/// Runs the command, on `threads` worker threads if given.
fn run(cli: &Cli) -> Result<()> {
    if let Some(n) = cli.threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n as usize)
            .build_global()
            .context("cannot start the worker threads")?;
    }
    match &cli.command {
        Command::Shadows(a) => shadows::run(a),
        Command::View(a) => view::view(a),
        Command::Stats(a) => view::stats(a),
        Command::Demo(a) => view::demo(a),
        Command::Csg(a) => csg::run(a),
        Command::Animate(a) => animate::run(a),
        Command::Render(a) => raster::run_render(a),
        Command::Compare(a) => raster::run_compare(a),
        Command::Lines(a) => raster::run_lines(a),
        Command::Art(a) => art::run(a),
        Command::Sun(a) => sun::run(a),
        Command::Sunhours(a) => sun::run_hours(a),
        Command::Completions { shell } => {
            let mut out = Vec::new();
            clap_complete::generate(*shell, &mut Cli::command(), "shadow", &mut out);
            output::emit(&String::from_utf8_lossy(&out))
        }
        Command::Man => {
            let mut out = Vec::new();
            clap_mangen::Man::new(Cli::command()).render(&mut out)?;
            output::emit(&String::from_utf8_lossy(&out))
        }
    }
}

/// The whole command: parse the arguments, run the command, report an
/// error on stderr. The binary's `main` is only this (the code lives in
/// a library so that it compiles beside the libraries it calls, not
/// after them).
pub fn main() -> ExitCode {
    output::clean_up_on_interrupt();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let _ = e.print();
            // status 1 for a usage error; 0 for --help and --version (stdout)
            return ExitCode::from(u8::from(e.use_stderr()));
        }
    };
    // (every command: a panic of the libraries is reported as a bug)
    match output::guarded("the input and the command line", || run(&cli)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", message(&e));
            ExitCode::FAILURE
        }
    }
}

/// An error and its causes, each joined with `: ` unless its text is in
/// the message already (the libraries' errors name their causes in their
/// own text too, and keep them as their `source()`).
fn message(e: &anyhow::Error) -> String {
    let mut text = e.to_string();
    for cause in e.chain().skip(1) {
        let c = cause.to_string();
        if !text.contains(&c) {
            text.push_str(": ");
            text.push_str(&c);
        }
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn causes_are_named_once() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "not found");
        let e = anyhow::Error::new(shadow_scene::SceneError::Io {
            path: "gone.obj".into(),
            source: io,
        });
        assert_eq!(message(&e), "gone.obj: not found");
        let e = anyhow!("inner").context("outer");
        assert_eq!(message(&e), "outer: inner");
    }

    /// Every flag that several commands have has one default (or none)
    /// everywhere, and every command's help ends with an example.
    #[test]
    fn flags_of_one_name_share_their_default() {
        let cli = Cli::command();
        let mut seen: std::collections::HashMap<String, (String, Vec<String>)> = Default::default();
        for sub in cli.get_subcommands() {
            let help = sub
                .get_after_help()
                .map(|h| h.to_string())
                .unwrap_or_default();
            assert!(
                help.contains(&format!("shadow {}", sub.get_name())),
                "{}: no example",
                sub.get_name()
            );
            let quiet = sub.get_arguments().any(|a| a.get_long() == Some("quiet"));
            let tool = matches!(sub.get_name(), "completions" | "man");
            assert!(quiet || tool, "{}: no --quiet", sub.get_name());
            for arg in sub.get_arguments().filter(|a| !a.is_hide_set()) {
                let Some(long) = arg.get_long() else { continue };
                let default: Vec<String> = arg
                    .get_default_values()
                    .iter()
                    .map(|v| v.to_string_lossy().into_owned())
                    .collect();
                let e = seen
                    .entry(long.to_string())
                    .or_insert_with(|| (sub.get_name().to_string(), default.clone()));
                assert_eq!(
                    e.1,
                    default,
                    "--{long}: {} and {} differ",
                    e.0,
                    sub.get_name()
                );
            }
        }
        assert!(seen.len() > 20);
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
        assert_eq!(v.camera.eye, Some(DVec3::new(-3.0, 2.0, 1.0)));
        assert_eq!((v.image.size(), v.image.fov), ((1280, 720), 50.0));
        // no --eye: the scene's viewpoint, or the mesh framed
        assert!(Cli::try_parse_from(["shadow", "view", "--scene", "room", "-o", "x.svg"]).is_ok());
        assert!(Cli::try_parse_from(["shadow", "view", "--up", "0,0,0", "-o", "x.svg"]).is_err());
        assert!(
            Cli::try_parse_from([
                "shadow", "view", "--scene", "room", "--eye", "1,2", "-o", "x"
            ])
            .is_err()
        );
        assert!(Cli::try_parse_from(["shadow", "demo", "--width", "0"]).is_err());
        assert!(Cli::try_parse_from(["shadow", "demo", "--size", "0x10"]).is_err());
        let cli = Cli::try_parse_from([
            "shadow", "demo", "-o", "d.svg", "--size", "640x480", "--height", "400",
        ]);
        let Command::Demo(d) = cli.unwrap().command else {
            panic!("not a demo command")
        };
        assert_eq!(d.image.size(), (640, 400));
    }
}
