//! `shadow art`: the exact shadow hull of several images, and how well
//! its shadows give them back. The work is `bsp_shadows::art`'s.

use std::path::PathBuf;

use anyhow::{Context, Result};
use bsp_shadows::art::{ArtSpec, shadow_hull};
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
}

/// `shadow art`.
pub(crate) fn run(args: &ArtArgs) -> Result<()> {
    let stl = MeshFormat::from_path(&args.output)? == MeshFormat::Stl;
    let spec = ArtSpec::load(&args.spec)?;
    let hull = shadow_hull(&spec)?;
    let checks = hull.check(&spec)?;
    let mesh = hull.mesh(stl);
    shadow_scene::save(&args.output, &mesh)?;
    let mut text = format!(
        "wrote {}: the shadow hull of {} views, {} triangles, volume {}\n",
        args.output.display(),
        spec.views.len(),
        mesh.faces.len(),
        hull.hull.volume()
    );
    for (i, c) in checks.iter().enumerate() {
        text += &format!(
            "view {i}: wanted {:.6}, shadow {:.6}, missing {:.6} ({:.3}%), extra {:.3e}\n",
            c.wanted_area,
            c.shadow_area,
            c.missing_area,
            100.0 * c.missing_area / c.wanted_area,
            c.extra_area
        );
    }
    if let Some(r) = &args.report {
        write_file(r, hull.report_json(&checks).as_bytes())?;
        text += &format!("wrote {}\n", r.display());
    }
    if let Some(dir) = &args.images {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("could not make {}", dir.display()))?;
        for (i, (v, c)) in spec.views.iter().zip(&checks).enumerate() {
            write_file(
                &dir.join(format!("view{i}.png")),
                &c.picture(v).encode_png(),
            )?;
        }
        text += &format!("wrote {}/view*.png\n", dir.display());
    }
    emit(&text)
}
