//! `shadow art`: the exact shadow hull of several images, and how well
//! its shadows give them back. The work is `bsp_shadows::art`'s.

use std::path::PathBuf;

use anyhow::{Context, Result};
use bsp_shadows::art::{self, ArtSpec, Optimize, optimize_with};
use clap::Args;
use shadow_scene::MeshFormat;

use crate::output::{emit, write_file};

#[derive(Args, Debug)]
pub(crate) struct ArtArgs {
    /// The SPEC (JSON): views, each an image (PGM or PNG; dark is wanted
    /// shadow), a light and a receiving plane; and the bounds.
    spec: PathBuf,
    /// The hull: OBJ or STL.
    #[arg(short, long, value_name = "HULL.obj|HULL.stl")]
    output: PathBuf,
    /// Also write each view's areas and the hull's volume as JSON.
    #[arg(long, value_name = "REPORT.json")]
    report: Option<PathBuf>,
    /// Also write per view a PNG of the wanted shadow against the hull's
    /// (missed in red, extra in blue) into DIR.
    #[arg(long, value_name = "DIR")]
    images: Option<PathBuf>,
    /// Grow the images where the views conflict until each misses at
    /// most 0.5% of its wanted shadow (the paper's inner loop).
    #[arg(long)]
    optimize: bool,
    /// With --optimize: first deform the images that miss shadow as
    /// rigidly as possible (the paper's outer loop), then grow them.
    #[arg(long, requires = "optimize")]
    deform: bool,
    /// Simplify each image's wanted region within PX pixels: fewer
    /// corners and a smaller hull, the region then no longer the pixels'.
    #[arg(long, value_name = "PX")]
    simplify: Option<f64>,
    /// (Nothing to quiet: the report is on stdout.)
    #[arg(long, short)]
    quiet: bool,
}

/// `shadow art`.
pub(crate) fn run(args: &ArtArgs) -> Result<()> {
    let stl = MeshFormat::from_path(&args.output)? == MeshFormat::Stl;
    let mut given = ArtSpec::load(&args.spec)?;
    given.simplify = args.simplify;
    let run = match args.optimize {
        true => optimize_with(
            &given,
            Optimize {
                target: 0.005,
                rounds: 16,
                deform_rounds: if args.deform { 8 } else { 0 },
            },
        )?,
        false => art::run(given)?,
    };
    let mesh = run.hull.mesh(stl);
    shadow_scene::save(&args.output, &mesh)?;
    let mut text = run.said(&args.output, mesh.faces.len());
    if let Some(r) = &args.report {
        write_file(r, run.report_json().as_bytes())?;
        text += &format!("wrote {}\n", r.display());
    }
    if let Some(dir) = &args.images {
        (run.write_pictures(dir)).with_context(|| format!("could not write {}", dir.display()))?;
        text += &format!("wrote {}/view*.png\n", dir.display());
    }
    emit(&text)
}
