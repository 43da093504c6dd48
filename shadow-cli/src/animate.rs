//! `shadow animate`: the core paper's real-time pipeline, frame by frame.
//!
//! A static scene (a file or a built-in scene) and a moving object (a
//! file, or the built-in scene's own: the room's coordinate-axis object,
//! a torus around the bunny) → one grid for the scene, the lights and
//! every position the object takes → the static shadows and the tiling of
//! each light, once (`tiling::Dynamic`) → per frame, the object's original
//! coordinates moved by the frame's transform and snapped, and the
//! frame's shadows (see `tiling`'s docs) → per frame an SVG or JSON file,
//! optionally the frame's scene as OBJ, and a row of the paper's Table 2
//! in the CSV report.

use std::fmt::Write as _;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, anyhow, bail};
use bsp_core::Grid;
use bsp_shadows::frames;
use clap::{Args, ValueEnum};
use glam::{DMat4, DVec3};
use rayon::prelude::*;
use shadow_raster::svg::SvgViewpoint;
use shadow_scene::{Mesh, Staging};
use svbsp::{Light, LightSpec, PlacedLight};
use tiling::{Dynamic, FrameStats, FrameTally, Motion, PipelineOptions, Strategy};

use crate::args::{CameraArgs, ImageArgs, LightArgs, parse_vec3};
use crate::facade_error;
use crate::input::{NO_LIGHT, load_mesh};
use crate::lights::{place_lights, shared_grid};
use crate::output::{Output, emit, ms, note};
use crate::progress::Progress;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum FrameFormat {
    /// A view of the shaded frame (`frame_0000.svg`).
    Svg,
    /// The fragments, in the schema of `shadow shadows` (`frame_0000.json`).
    Json,
    /// An image of the shaded frame (`frame_0000.png`), rasterized from the
    /// exact fragments.
    Png,
    /// Nothing: for timing.
    None,
}

/// The per-frame strategy.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum StrategyArg {
    /// Liu & Wu's pipeline: Bsp4 = Bsp2 + Bsp3 and Chin & Feiner's shadows.
    Paper,
    /// Partitioned shadow volumes of the moved and related polygons.
    Fast,
}

#[derive(Args, Debug)]
pub(crate) struct AnimateArgs {
    /// The static scene (.obj, .stl or CityJSON .json).
    pub(crate) input: Option<PathBuf>,
    /// A built-in animation instead of a file: room (the axis object
    /// spins) or bunny, bunny-11k ... bunny-893k (a torus circles the
    /// bunny).
    #[arg(long, value_name = "NAME")]
    pub(crate) scene: Option<String>,
    /// The moving object (.obj or .stl) [default for --scene: the scene's
    /// own].
    #[arg(long, value_name = "FILE")]
    pub(crate) dynamic: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) lights: LightArgs,
    /// Number of frames.
    #[arg(long, default_value_t = 24, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub(crate) frames: u32,
    /// Rotation per frame: axis and degrees, AX,AY,AZ:DEGREES [default for
    /// --scene: the scene's; none for files].
    #[arg(long, value_name = "AX,AY,AZ:DEG", value_parser = shadow_scene::parse_spin, allow_hyphen_values = true)]
    pub(crate) spin: Option<(DVec3, f64)>,
    /// A point on the rotation axis [default: the centre of the moving
    /// object's bounding box, or the scene's].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(crate) spin_center: Option<DVec3>,
    /// Translation per frame, applied after the rotation.
    #[arg(long, value_name = "DX,DY,DZ", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(crate) step: Option<DVec3>,
    /// Output directory (created if missing).
    #[arg(short, long, value_name = "DIR")]
    pub(crate) output: PathBuf,
    /// What each frame writes.
    #[arg(long, value_enum, default_value_t = FrameFormat::Svg)]
    pub(crate) format: FrameFormat,
    /// One CSV row per frame: the columns of the paper's Table 2.
    #[arg(long, value_name = "FILE.csv")]
    pub(crate) report: Option<PathBuf>,
    /// Also write each frame's whole scene as an OBJ file beside the frame's
    /// own (the same name, .obj).
    #[arg(long)]
    pub(crate) export_scene: bool,
    /// The per-frame strategy.
    #[arg(long, value_enum, default_value_t = StrategyArg::Fast)]
    pub(crate) strategy: StrategyArg,
    /// Tiles per side of each light's tiling [default: the tiling crate's
    /// rule].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub(crate) tiles: Option<u32>,
    /// The frames' viewpoint [default for the room: its built-in one;
    /// for other scenes: in front of and above the scene].
    #[command(flatten)]
    pub(crate) camera: CameraArgs,
    #[command(flatten)]
    pub(crate) image: ImageArgs,
    /// Frames computed at the same time: 1 gives each frame every core
    /// (the lowest latency); 2 keeps every core busy (the highest frame
    /// rate, each frame a little later). The output is the same.
    #[arg(long, value_name = "N", default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub(crate) in_flight: u32,
    /// No progress bar and no notes on stderr (errors still go there).
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

/// The static scene, the moving object and the defaults that come with a
/// built-in animation.
struct Setup {
    statics: Mesh,
    moving: Mesh,
    name: String,
    spin: Option<(DVec3, f64)>,
    centre: Option<DVec3>,
    light: Option<DVec3>,
    /// A built-in scene's default camera.
    staging: Option<Staging>,
}

fn setup(args: &AnimateArgs) -> Result<Setup> {
    let dynamic = |required: bool| -> Result<Option<Mesh>> {
        match &args.dynamic {
            Some(p) => Ok(Some(load_mesh(p, args.quiet)?)),
            None if required => bail!(
                "no moving object: give --dynamic FILE (the object that moves; STATIC is what \
                 stays put)"
            ),
            None => Ok(None),
        }
    };
    match (&args.input, &args.scene) {
        (Some(path), None) => Ok(Setup {
            statics: load_mesh(path, args.quiet)?,
            moving: dynamic(true)?.unwrap_or_default(),
            name: path.display().to_string(),
            spin: None,
            centre: None,
            light: None,
            staging: None,
        }),
        (None, Some(name)) => {
            let a = shadow_scene::animated(name).with_context(|| {
                format!(
                    "unknown animation `{name}` (available: {})",
                    shadow_scene::ANIMATED_NAMES.join(", ")
                )
            })?;
            let staging = a.statics.bounds().and_then(|b| Staging::of_scene(name, b));
            Ok(Setup {
                moving: dynamic(false)?.unwrap_or(a.moving),
                statics: a.statics,
                name: format!("scene {name}"),
                spin: Some((a.axis, a.degrees)),
                centre: a.centre,
                light: Some(a.light),
                staging,
            })
        }
        (Some(_), Some(_)) => bail!("give either a STATIC file or --scene NAME, not both"),
        (None, None) => bail!(
            "no input: give a static scene file and --dynamic FILE, or --scene NAME (available: {})",
            shadow_scene::ANIMATED_NAMES.join(", ")
        ),
    }
}

/// What the command line asks for, checked before any work is done.
struct Plan {
    setup: Setup,
    specs: Vec<LightSpec>,
    motion: Motion,
    strategy: Strategy,
    /// The report, its header written by [`FrameFiles::new`].
    report: Option<Output>,
}

impl Plan {
    /// Loads the scene and fails on a missing object or light; creates
    /// the output folder.
    fn of(args: &AnimateArgs) -> Result<Plan> {
        let s = setup(args)?;
        if s.moving.faces.is_empty() {
            bail!("the moving object has no faces");
        }
        if s.statics.faces.is_empty() {
            bail!("{}: no faces", s.name);
        }
        if !args.lights.soft().is_empty() {
            bail!("--area-light and --sun-disc are for `shadow shadows` so far");
        }
        let mut specs = args.lights.specs();
        if specs.is_empty() {
            match s.light {
                Some(l) => specs.push(LightSpec::Point(l)),
                None => bail!("{NO_LIGHT}"),
            }
        }
        let (axis, degrees) = args.spin.or(s.spin).unwrap_or((DVec3::Z, 0.0));
        let step = args.step.unwrap_or(DVec3::ZERO);
        let (mlo, mhi) = s.moving.bounds().expect("the moving object has faces");
        let centre = args.spin_center.or(s.centre).unwrap_or((mlo + mhi) * 0.5);
        let motion = Motion {
            axis,
            degrees,
            centre,
            step,
        };
        if degrees == 0.0 && step == DVec3::ZERO && args.frames > 1 {
            note(
                args.quiet,
                "note: no motion given (--spin, --step): every frame is the same",
            );
        }
        if !has_view(args) && (args.camera.any() || args.image.any()) {
            note(
                args.quiet,
                "note: --eye, --target, --up, --size and --fov only apply to SVG and PNG frames",
            );
        }
        // the folder first (the report may be in it); a report that cannot
        // be written then takes back a folder this run made
        let made = !args.output.exists();
        std::fs::create_dir_all(&args.output)
            .with_context(|| format!("could not create {}", args.output.display()))?;
        let report = args.report.as_deref().map(Output::create).transpose();
        let report = match report {
            Ok(r) => r,
            Err(e) => {
                if made {
                    let _ = std::fs::remove_dir(&args.output);
                }
                return Err(e);
            }
        };
        let strategy = match args.strategy {
            StrategyArg::Paper => Strategy::Paper,
            StrategyArg::Fast => Strategy::Fast,
        };
        Ok(Plan {
            setup: s,
            specs,
            motion,
            strategy,
            report,
        })
    }

    /// One grid for every frame: the static scene, the lights and the box
    /// of every position the object takes. A path that would make it more
    /// than `2^LIGHT_RANGE_BITS` times coarser than the grid of the scene
    /// and the object as given is an error, as a point light that far
    /// away is: the scene would lose its detail (a path of 10^9 over a
    /// scene of 10 snaps the scene to a grid of step 32).
    fn grid(&self, frames: u32) -> Result<Grid> {
        let s = &self.setup;
        let (lo, hi) = self.motion.swept_bounds(&s.moving.positions, frames);
        let mut pts = s.statics.positions.clone();
        pts.extend_from_slice(&s.moving.positions);
        let own = shared_grid(&pts, &self.specs, &[]).with_context(|| s.name.clone())?;
        pts.push(lo);
        pts.push(hi);
        let grid = shared_grid(&pts, &self.specs, &[]).with_context(|| s.name.clone())?;
        let coarser = grid.step_log2() - own.step_log2();
        if coarser > svbsp::LIGHT_RANGE_BITS {
            bail!(
                "the moving object's path over {frames} frames spans {:.3e} units (from {lo} to \
                 {hi}), which would snap the scene ({}) to a grid 2^{coarser} times coarser \
                 than its own (a step of {} instead of {}) and cost it its detail; at most 2^{} \
                 is allowed: give fewer frames, or a smaller --step or --spin",
                (hi - lo).max_element(),
                s.name,
                grid.step_text(),
                own.step_text(),
                svbsp::LIGHT_RANGE_BITS,
            );
        }
        Ok(grid)
    }
}

/// Whether the frames are pictures (and need a viewpoint).
fn has_view(args: &AnimateArgs) -> bool {
    matches!(args.format, FrameFormat::Svg | FrameFormat::Png)
}

/// `shadow animate`.
pub(crate) fn run(args: &AnimateArgs) -> Result<()> {
    let total = Instant::now();
    let mut plan = Plan::of(args)?;
    let grid = plan.grid(args.frames)?;
    let (placed, _) = place_lights(&grid, &plan.specs, &[])?;
    let kernel: Vec<Light> = placed.iter().map(|l| l.light).collect();
    let opts = PipelineOptions::default()
        .with_strategy(plan.strategy)
        .with_tiles(args.tiles)
        .with_pieces(args.format == FrameFormat::Svg)
        .with_rounded_only(true);

    let progress = Progress::new(!args.quiet);
    progress.phase("preprocessing", 1);
    let report = plan.report.take();
    let s = &plan.setup;
    let start = Instant::now();
    let d = Dynamic::new(
        &s.statics.face_loops(),
        &s.moving.face_loops(),
        grid,
        &kernel,
        opts,
    )?;
    let t_pre = start.elapsed();
    let mut files = FrameFiles::new(args, s, (&d, &placed), report)?;
    progress.phase("frames", args.frames as u64);
    let mut tally = FrameTally::default();
    let loop_start = Instant::now();
    let in_flight = args.in_flight.max(1);
    for k0 in (0..args.frames).step_by(in_flight as usize) {
        let k1 = (k0 + in_flight).min(args.frames);
        // frames are independent: several at a time keep every core busy
        let batch: Vec<Result<tiling::Frame>> = (k0..k1)
            .into_par_iter()
            .map(|k| {
                d.frame(&plan.motion.matrix(k)).map_err(|e| {
                    anyhow!(
                        "frame {k}: {e} (the grid holds every position the object takes; is a \
                         vertex not finite?)"
                    )
                })
            })
            .collect();
        for (k, frame) in (k0..k1).zip(batch) {
            let frame = frame?;
            files.write(k, &frame, &plan.motion.matrix(k))?;
            tally.add(&frame.stats);
            progress.inc(1);
        }
    }
    let wall = loop_start.elapsed() / args.frames;
    files.finish()?;
    drop(progress);
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{} frames of {}: {} static faces, {} moving; {:?} strategy, {} light(s); {}; wall time \
         a frame {:.2} ms ({in_flight} in flight); preprocessing {:.1} ms, total {:.2} s",
        args.frames,
        s.name,
        s.statics.faces.len(),
        s.moving.faces.len(),
        plan.strategy,
        kernel.len(),
        tally.summary(),
        ms(wall),
        ms(t_pre),
        total.elapsed().as_secs_f64()
    );
    if args.format != FrameFormat::None || args.export_scene {
        let _ = writeln!(out, "frames in {}", args.output.display());
    }
    emit(&out)
}

/// The files each frame writes, and the Table 2 report.
struct FrameFiles<'a> {
    args: &'a AnimateArgs,
    setup: &'a Setup,
    d: &'a Dynamic,
    lights: &'a [PlacedLight],
    view: Option<SvgViewpoint>,
    /// One colour per face, static faces then the moving object's.
    colors: Vec<DVec3>,
    /// PNG frames are drawn one after the other in one renderer, which
    /// keeps its buffers from frame to frame.
    renderer: shadow_raster::Renderer,
    report: Option<Output>,
}

impl<'a> FrameFiles<'a> {
    fn new(
        args: &'a AnimateArgs,
        setup: &'a Setup,
        (d, lights): (&'a Dynamic, &'a [PlacedLight]),
        mut report: Option<Output>,
    ) -> Result<FrameFiles<'a>> {
        let view = has_view(args).then(|| frame_view(args, setup));
        let still = frames::frame_mesh(d, &setup.statics, &setup.moving, &DMat4::IDENTITY);
        let colors = shadow_scene::face_colors(&still);
        if let Some(o) = &mut report {
            writeln!(o, "{}", FrameStats::CSV_HEADER)?;
        }
        Ok(FrameFiles {
            args,
            setup,
            d,
            lights,
            view,
            colors,
            renderer: shadow_raster::Renderer::new(),
            report,
        })
    }

    /// Writes frame `k` (the object moved by `m`): its report row and its
    /// files.
    fn write(&mut self, k: u32, frame: &tiling::Frame, m: &DMat4) -> Result<()> {
        let (args, d, lights) = (self.args, self.d, self.lights);
        if let Some(r) = &mut self.report {
            writeln!(r, "{}", frame.stats.csv_row(k))?;
        }
        let stem = args.output.join(format!("frame_{k:04}"));
        if args.export_scene || args.format == FrameFormat::Svg {
            let scene = frames::frame_mesh(d, &self.setup.statics, &self.setup.moving, m);
            if args.export_scene {
                write_file(&stem.with_extension("obj"), |o| {
                    Ok(frames::write_frame_obj(o, d, &scene, k, lights)?)
                })?;
            }
            if let Some(view) = &self.view {
                let svg =
                    frames::frame_svg((d, frame), &scene, lights, view).map_err(facade_error)?;
                write_file(&stem.with_extension("svg"), |o| {
                    Ok(o.write_all(svg.as_bytes())?)
                })?;
            }
        }
        match (args.format, &self.view) {
            (FrameFormat::Png, Some(view)) => {
                let png =
                    frames::frame_png(&mut self.renderer, (d, frame), &self.colors, lights, view)
                        .map_err(facade_error)?;
                write_file(&stem.with_extension("png"), |o| Ok(o.write_all(&png)?))?;
            }
            (FrameFormat::Json, _) => {
                write_file(&stem.with_extension("json"), |o| {
                    Ok(frames::write_frame_json(o, d, frame, lights)?)
                })?;
            }
            _ => {}
        }
        Ok(())
    }

    /// Puts the report in place.
    fn finish(self) -> Result<()> {
        match self.report {
            Some(r) => r.commit(),
            None => Ok(()),
        }
    }
}

/// Writes `path` with `f`, renamed into place when complete.
fn write_file(path: &Path, f: impl FnOnce(&mut Output) -> Result<()>) -> Result<()> {
    let mut o = Output::create(path)?;
    f(&mut o).with_context(|| format!("could not write {}", path.display()))?;
    o.commit()
}

/// The viewpoint of SVG and PNG frames.
fn frame_view(args: &AnimateArgs, s: &Setup) -> SvgViewpoint {
    let image = (args.image.size(), args.image.fov);
    args.camera.pick(&s.statics, s.staging, image, args.quiet)
}

#[cfg(test)]
mod tests {
    use super::*;
    use shadow_scene::parse_spin;

    #[test]
    fn spins_parse_with_clear_errors() {
        assert_eq!(
            parse_spin("0,0,1:15").unwrap(),
            (DVec3::new(0.0, 0.0, 1.0), 15.0)
        );
        assert_eq!(
            parse_spin("1,-1,0:-7.5").unwrap(),
            (DVec3::new(1.0, -1.0, 0.0), -7.5)
        );
        assert_eq!(
            parse_spin("0,0,1").unwrap_err(),
            "expected AX,AY,AZ:DEGREES, got `0,0,1`"
        );
        assert_eq!(parse_spin("0,0,0:5").unwrap_err(), "the spin axis is zero");
        assert_eq!(
            parse_spin("0,0,1:x").unwrap_err(),
            "`x` is not a number of degrees"
        );
    }

    #[test]
    fn frame_paths_are_numbered() {
        use std::path::Path;
        let p = Path::new("out").join(format!("frame_{:04}", 7));
        assert_eq!(p.with_extension("svg"), Path::new("out/frame_0007.svg"));
    }
}
