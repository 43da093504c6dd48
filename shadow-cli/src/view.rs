//! `shadow view`, `shadow stats` and `shadow demo`: a scene drawn by the
//! painter's algorithm in its BSP tree's exact order, and the tree's
//! figures.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::Args;
use shadow_raster::svg::SvgViewpoint;
use shadow_scene::ROOM_STAGING;

use crate::args::{CameraArgs, ImageArgs, SourceArgs};
use crate::facade_error;
use crate::input::{load_source_quiet, prepare};
use crate::output::{emit, write_file};

#[derive(Args, Debug)]
pub(crate) struct ViewArgs {
    #[command(flatten)]
    pub(crate) source: SourceArgs,
    #[command(flatten)]
    pub(crate) camera: CameraArgs,
    /// Output SVG file.
    #[arg(short, long, value_name = "OUT.svg")]
    pub(crate) output: PathBuf,
    #[command(flatten)]
    pub(crate) image: ImageArgs,
    /// No notes on stderr (errors still go there).
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

/// `shadow stats`.
#[derive(Args, Debug)]
pub(crate) struct StatsArgs {
    #[command(flatten)]
    pub(crate) source: SourceArgs,
    /// No notes on stderr (errors still go there).
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

#[derive(Args, Debug)]
pub(crate) struct DemoArgs {
    /// Output SVG file.
    #[arg(short, long, value_name = "OUT.svg")]
    pub(crate) output: PathBuf,
    #[command(flatten)]
    pub(crate) image: ImageArgs,
    /// No notes on stderr (errors still go there).
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

/// `shadow view`.
pub(crate) fn view(args: &ViewArgs) -> Result<()> {
    let (mesh, name) = load_source_quiet(&args.source, args.quiet)?;
    let prepared = prepare(mesh, &name, args.quiet)?;
    let bounds = prepared
        .mesh
        .bounds()
        .context("nothing to draw: the mesh has no vertices")?;
    let staging = args.source.staging(bounds);
    let image = (args.image.size(), args.image.fov);
    let at = args.camera.pick(&prepared.mesh, staging, image, args.quiet);
    if !at.eye.is_finite() {
        bail!(
            "{name}: the scene spans {:.3e} units, so a camera that frames it would stand beyond \
             f64's range; give --eye and --target, or scale the scene below about 1e150",
            (bounds.1 - bounds.0).max_element()
        );
    }
    let out = prepared.draw(&at).map_err(facade_error)?;
    write_file(&args.output, out.svg.as_bytes())?;
    emit(&format!(
        "wrote {}: {} polygons of {} ({} faces), eye {}\n",
        args.output.display(),
        out.drawn,
        name,
        prepared.mesh.faces.len(),
        fmt_vec(out.eye)
    ))
}

/// `shadow stats`.
pub(crate) fn stats(args: &StatsArgs) -> Result<()> {
    let (mesh, name) = load_source_quiet(&args.source, args.quiet)?;
    let p = prepare(mesh, &name, args.quiet)?;
    emit(&p.stats_text(&name))
}

/// `shadow demo`.
pub(crate) fn demo(args: &DemoArgs) -> Result<()> {
    let prepared = prepare(shadow_scene::room(), "scene room", args.quiet)?;
    let at = SvgViewpoint::of_staging(ROOM_STAGING, args.image.size(), args.image.fov);
    let out = prepared.draw(&at).map_err(facade_error)?;
    write_file(&args.output, out.svg.as_bytes())?;
    emit(&format!(
        "wrote {}: the built-in room, {} polygons ({} faces, {} BSP fragments), eye {}\n",
        args.output.display(),
        out.drawn,
        prepared.mesh.faces.len(),
        prepared.tree.stats().polygons,
        fmt_vec(out.eye)
    ))
}

/// A vector with three decimals, as the reports print eyes.
pub(crate) fn fmt_vec(v: glam::DVec3) -> String {
    format!("{:.3},{:.3},{:.3}", v.x, v.y, v.z)
}
