//! `shadow art`: the exact shadow hull of several images, and how well
//! its shadows give them back. The work is `bsp_shadows::art`'s.

use std::path::PathBuf;

use anyhow::{Context, Result};
use bsp_shadows::art::{ArtSpec, optimize, shadow_hull};
use clap::Args;
use shadow_scene::MeshFormat;

use crate::output::{emit, note, write_file};

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
    /// No notes on stderr (errors still go there).
    #[arg(long, short)]
    quiet: bool,
}

/// `shadow art`.
pub(crate) fn run(args: &ArtArgs) -> Result<()> {
    let stl = MeshFormat::from_path(&args.output)? == MeshFormat::Stl;
    let given = ArtSpec::load(&args.spec)?;
    let (spec, hull, checks, grown) = if args.optimize {
        let o = optimize(&given, 0.005, 16)?;
        (
            o.spec,
            o.hull,
            o.checks,
            Some((o.growth, o.missing_before, o.rounds)),
        )
    } else {
        let hull = shadow_hull(&given)?;
        let checks = hull.check(&given)?;
        (given, hull, checks, None)
    };
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
        if grown.is_none() && c.missing_area > 0.005 * c.wanted_area {
            let why = "the views conflict (--optimize grows the images until they agree)";
            note(
                args.quiet,
                &format!("note: view {i} misses part of its wanted shadow: {why}"),
            );
        }
        if let Some((g, before, _)) = &grown {
            let g = &g[i];
            text += &format!(
                "  grown by {} pixels, {:.2} px on average and {:.2} at most; missing before {:.6}\n",
                g.pixels, g.mean_displacement, g.max_displacement, before[i]
            );
        }
    }
    if let Some((_, _, rounds)) = &grown {
        text += &format!("{rounds} rounds of growing\n");
    }
    if let Some(r) = &args.report {
        let grown = grown.as_ref().map(|(g, b, _)| (&g[..], &b[..]));
        write_file(r, hull.report_json(&checks, grown).as_bytes())?;
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
