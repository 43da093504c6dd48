//! Soft shadows written as a file, the job of `shadow shadows` with an
//! area light or a sun disc: every face cut where any light's class
//! changes (lit, penumbra, umbra; [`svbsp::soft_shadows`]), every light,
//! point lights and suns included, as an [`svbsp::AreaLight`], and the
//! fragments written as JSON or OBJ ([`svbsp::export::write_soft`]).

use std::io::Write;
use std::time::{Duration, Instant};

use bsp_core::{Grid, Polygon};
use svbsp::export::{FragmentFormat, SoftWritten, write_soft};
use svbsp::{AreaLight, Occluder, SoftLight};

use crate::Error;
use crate::shadow_file::Progress;

/// A scene snapped to its grid, with its lights: what the job shades.
#[derive(Clone, Copy, Debug)]
pub struct SoftScene<'a> {
    /// The scene's name, for the OBJ's comments.
    pub name: &'a str,
    /// How many faces the scene has.
    pub faces: usize,
    /// The grid the faces and lights are on.
    pub grid: &'a Grid,
    /// The lights, in order.
    pub lights: &'a [SoftLight],
    /// The faces on the grid, each tagged with its index in the mesh
    /// (convex, as imported).
    pub polys: &'a [Polygon],
}

/// What a soft-shadow job wrote, and what it took.
#[derive(Debug)]
pub struct SoftFile {
    /// The fragments, their areas per light, the OBJ's positions.
    pub written: SoftWritten,
    /// The wall time of each phase, in order.
    pub phases: Vec<(&'static str, Duration)>,
}

impl SoftFile {
    /// The `--stats` lines: fragments (per face) and the phases' times.
    pub fn stats_text(&self, faces: usize) -> String {
        let n = self.written.fragments;
        let times: Vec<String> = self
            .phases
            .iter()
            .map(|(name, d)| format!("{name} {:.2} ms", d.as_secs_f64() * 1e3))
            .collect();
        format!(
            "fragments:       {n} ({:.3} per face)\ntime:            {}\n",
            n as f64 / faces.max(1) as f64,
            times.join(", ")
        )
    }

    /// One line per light: the shares of the area lit, in penumbra (and
    /// of it undecided) and in umbra.
    pub fn report(&self) -> String {
        let a = &self.written.areas;
        let pc = |x: f64| svbsp::percent(x, a.total);
        (0..a.lit.len())
            .map(|i| {
                format!(
                    "light {i}: lit {:.1}%, penumbra {:.1}% (undecided {:.1}%), umbra {:.1}% \
                     of the area\n",
                    pc(a.lit[i]),
                    pc(a.penumbra[i]),
                    pc(a.undecided[i]),
                    pc(a.umbra[i])
                )
            })
            .collect()
    }
}

/// Cuts every face of `scene` for its lights and writes the fragments to
/// `out` as `format`.
pub fn write_soft_shadows(
    scene: &SoftScene,
    format: FragmentFormat,
    out: &mut impl Write,
    progress: &dyn Progress,
) -> Result<SoftFile, Error> {
    let mut phases = Vec::new();
    progress.phase("soft shadows", 1);
    let start = Instant::now();
    let (occluders, faces_of): (Vec<Occluder>, Vec<u32>) = scene
        .polys
        .iter()
        .filter_map(|p| Some((Occluder::of_polygon(p)?, p.tag())))
        .unzip();
    let lights: Vec<AreaLight> = scene.lights.iter().map(|l| l.light.clone()).collect();
    let fragments = svbsp::soft_shadows(&lights, &occluders).map_err(Error::Light)?;
    phases.push(("shadows", start.elapsed()));
    progress.advance(1);
    progress.phase("writing", 1);
    let start = Instant::now();
    let notes: Vec<String> = scene.lights.iter().map(|l| l.shape.to_string()).collect();
    let head = (scene.name, &notes[..], scene.faces);
    let written = write_soft(
        out,
        format,
        scene.lights,
        head,
        (&fragments, &faces_of),
        scene.grid,
    )
    .map_err(Error::Io)?;
    phases.push(("write", start.elapsed()));
    Ok(SoftFile { written, phases })
}
