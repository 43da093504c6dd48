//! `shadow render`, `shadow compare` and `shadow lines`: PNG images of a
//! scene and its shadows by the exact method or a classic image-space one,
//! every method side by side against the exact shadows, and Roberts'
//! hidden-line drawing. The work is `shadow-raster`'s; this module parses
//! the flags, prepares the scene and reports.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{Result, bail};
use clap::Args;
use glam::DVec3;
use shadow_raster::{
    Camera, Hsr, Method, RasterScene, RenderOptions, ShadowOptions, compare, compare_soft,
    encode_pgm, hidden_lines, mask_counts, render, render_soft,
};
use shadow_scene::face_colors;
use svbsp::{PlacedLight, SoftLight};

use crate::args::{CameraArgs, LightArgs, SourceArgs, parse_fov, parse_size};
use crate::input::Scene;
use crate::lights::describe;
use crate::output::{Phases, emit, ms, note, write_file, write_files};
use crate::raster_error;

/// Where the scene and camera come from.
#[derive(Args, Debug)]
pub(crate) struct SceneArgs {
    #[command(flatten)]
    pub(crate) source: SourceArgs,
    #[command(flatten)]
    pub(crate) camera: CameraArgs,
    /// Vertical field of view in degrees.
    #[arg(long, value_name = "DEG", default_value_t = 50.0, value_parser = parse_fov)]
    pub(crate) fov: f64,
    /// No notes on stderr (errors still go there).
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

/// Options of the image-space shadow methods.
#[derive(Args, Debug)]
pub(crate) struct MethodArgs {
    /// Shadow-map (and shadow-texture) size: texels on a side of a sun's
    /// map or of each cube face of a point light.
    #[arg(long, value_name = "N", default_value_t = 2048, value_parser = clap::value_parser!(u32).range(16..=8192))]
    pub(crate) map_size: u32,
    /// Shadow-map bias: C (input units) or C,S (S texel footprints times
    /// the tangent of the light's angle) [default: 0,1.5].
    #[arg(long, value_name = "C[,S]", value_parser = ShadowOptions::parse_bias, allow_hyphen_values = true)]
    pub(crate) bias: Option<(f64, f64)>,
    /// Percentage-closer filtering over K×K texels (odd K; 1: off).
    #[arg(long, value_name = "K", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=15))]
    pub(crate) pcf: u32,
    /// Planar shadows: project occluders without clipping them to the slab
    /// between the receiving plane and the light (shows anti-shadows and
    /// false shadows).
    #[arg(long)]
    pub(crate) no_clip: bool,
    /// Planar shadows: the number of receiving planes (the largest).
    #[arg(long, value_name = "N", default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub(crate) receivers: u32,
}

impl MethodArgs {
    /// The flags given that `method` does not use, as a note.
    fn unused_by(&self, method: Method) -> Option<String> {
        let opts = self.options().ok()?;
        let flags: Vec<&str> = (opts.unused_by(method).into_iter())
            .map(|o| match o {
                "map_size" => "--map-size (shadow maps and textures)",
                "bias" => "--bias (shadow maps)",
                "pcf" => "--pcf (shadow maps without pcss)",
                _ => "--no-clip and --receivers (planar shadows)",
            })
            .collect();
        (!flags.is_empty())
            .then(|| format!("note: --method {method} does not use {}", flags.join(", ")))
    }

    fn options(&self) -> Result<ShadowOptions> {
        if self.pcf.is_multiple_of(2) {
            bail!("--pcf {}: the kernel must be odd (1, 3, 5, ...)", self.pcf);
        }
        let d = ShadowOptions::default();
        let (c, s) = self.bias.unwrap_or((d.bias_constant, d.bias_slope));
        Ok(ShadowOptions::default()
            .with_map_size(self.map_size)
            .with_bias(c, s)
            .with_pcf(self.pcf)
            .with_planar_clip(!self.no_clip)
            .with_planar_receivers(self.receivers as usize))
    }
}

#[derive(Args, Debug)]
pub(crate) struct RenderArgs {
    #[command(flatten)]
    pub(crate) scene: SceneArgs,
    /// The lights; the mask is the first's.
    #[command(flatten)]
    pub(crate) lights: LightArgs,
    /// Image size.
    #[arg(long, value_name = "WxH", default_value = "1280x720", value_parser = parse_size)]
    pub(crate) size: (u32, u32),
    /// Shadow method: exact, raycast, shadow-map, stencil-zpass,
    /// stencil-zfail, planar, texture, sampled:N (N exact point lights
    /// over each light with extent) or pcss (soft shadow maps).
    #[arg(long, value_name = "M", default_value = "exact")]
    pub(crate) method: Method,
    /// Visible-surface method: zbuffer, scanline, warnock, raycast or bsp
    /// (all give the same image).
    #[arg(long, value_name = "H", default_value = "zbuffer")]
    pub(crate) hsr: Hsr,
    /// Back-face culling: leave out faces whose back faces the eye.
    #[arg(long)]
    pub(crate) cull: bool,
    #[command(flatten)]
    pub(crate) opts: MethodArgs,
    /// Also write the first light's mask as binary PGM: 0 nothing seen,
    /// 255 lit, 128 not lit.
    #[arg(long, value_name = "MASK.pgm")]
    pub(crate) mask: Option<PathBuf>,
    /// Output PNG.
    #[arg(short, long, value_name = "OUT.png")]
    pub(crate) output: PathBuf,
    /// Print the time of each phase.
    #[arg(long)]
    pub(crate) stats: bool,
}

#[derive(Args, Debug)]
pub(crate) struct CompareArgs {
    #[command(flatten)]
    pub(crate) scene: SceneArgs,
    /// The lights.
    #[command(flatten)]
    pub(crate) lights: LightArgs,
    /// Size of each method's panel (`--size` is a hidden alias).
    #[arg(long = "panel", alias = "size", value_name = "WxH", default_value = "640x360", value_parser = parse_size)]
    pub(crate) size: (u32, u32),
    /// The methods to compare with exact, comma-separated [default: all;
    /// with an area light or a sun disc, sampled:16,64,256 and pcss].
    #[arg(long, value_name = "M,M...", value_delimiter = ',')]
    pub(crate) methods: Vec<Method>,
    #[command(flatten)]
    pub(crate) opts: MethodArgs,
    /// Panels per row.
    #[arg(long, value_name = "N", default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub(crate) columns: u32,
    /// Tint the pixels that disagree with exact.
    #[arg(long)]
    pub(crate) highlight: bool,
    /// Output PNG: the panels side by side.
    #[arg(short, long, value_name = "OUT.png")]
    pub(crate) output: PathBuf,
    /// Also write the report as CSV.
    #[arg(long, value_name = "OUT.csv")]
    pub(crate) report: Option<PathBuf>,
}

#[derive(Args, Debug)]
pub(crate) struct LinesArgs {
    #[command(flatten)]
    pub(crate) scene: SceneArgs,
    /// Image size.
    #[arg(long, value_name = "WxH", default_value = "1280x720", value_parser = parse_size)]
    pub(crate) size: (u32, u32),
    /// Also draw the hidden lines, dashed.
    #[arg(long)]
    pub(crate) hidden: bool,
    /// Output SVG.
    #[arg(short, long, value_name = "OUT.svg")]
    pub(crate) output: PathBuf,
}

/// A scene ready to render.
pub(crate) struct Prepared {
    pub(crate) name: String,
    pub(crate) faces: usize,
    pub(crate) scene: RasterScene,
    pub(crate) lights: Vec<PlacedLight>,
    /// Every light, where some has extent.
    pub(crate) soft: Vec<SoftLight>,
    pub(crate) light_notes: Vec<String>,
    pub(crate) camera: Camera,
    pub(crate) colors: Vec<DVec3>,
    pub(crate) load_time: Duration,
}

fn check_ext(path: &std::path::Path, ext: &str, flag: &str) -> Result<()> {
    let ok = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case(ext));
    if !ok {
        bail!("{}: {flag} must name a .{ext} file", path.display());
    }
    Ok(())
}

/// Loads the scene, places the lights (`None`: a drawing without
/// shadows) and sets up the camera.
pub(crate) fn prepare(
    args: &SceneArgs,
    lights: Option<&LightArgs>,
    size: (u32, u32),
) -> Result<Prepared> {
    let start = Instant::now();
    let specs = lights.map(LightArgs::specs).unwrap_or_default();
    let soft = lights.map(LightArgs::soft).unwrap_or_default();
    let s = Scene::load(
        &args.source,
        (specs, &soft),
        lights.is_some(),
        args.quiet,
        &mut Phases::default(),
    )?;
    let at = args
        .camera
        .pick(&s.mesh, s.staging, (size, args.fov), args.quiet);
    let camera = at.camera(s.bounds).map_err(raster_error)?;
    if s.polys.is_empty() {
        bail!("{}: nothing to draw: no face has an area", s.name);
    }
    // (the colours walk the mesh's parts on one thread, beside the prims;
    // the mesh, a list a face, is freed there too)
    let faces = s.mesh.faces.len();
    let mesh = s.mesh;
    let (colors, scene) = rayon::join(
        move || face_colors(&mesh),
        || RasterScene::new(&s.grid, s.polys),
    );
    Ok(Prepared {
        faces,
        colors,
        scene: scene?,
        light_notes: (s.lights.iter().map(describe))
            .chain(
                s.soft[s.lights.len().min(s.soft.len())..]
                    .iter()
                    .map(|l| l.shape.to_string()),
            )
            .collect(),
        lights: s.lights,
        soft: s.soft,
        name: s.name,
        camera,
        load_time: start.elapsed(),
    })
}

/// `shadow render`.
pub(crate) fn run_render(args: &RenderArgs) -> Result<()> {
    check_ext(&args.output, "png", "-o")?;
    if let Some(m) = &args.mask {
        check_ext(m, "pgm", "--mask")?;
    }
    let shadow = args.opts.options()?;
    if let Some(n) = args.opts.unused_by(args.method) {
        note(args.scene.quiet, &n);
    }
    let total = Instant::now();
    let p = prepare(&args.scene, Some(&args.lights), args.size)?;
    let opts = RenderOptions::default()
        .with_hsr(args.hsr)
        .with_culling(args.cull)
        .with_method(args.method)
        .with_shadow(shadow);
    let out = match &p.soft[..] {
        [] => render(&p.scene, &p.lights, &p.camera, &p.colors, &opts)?,
        soft => render_soft(&p.scene, soft, &p.camera, &p.colors, &opts)?,
    };
    let t = Instant::now();
    let mask = out.mask();
    let png = out.image.encode_png();
    let pgm = encode_pgm(args.size.0, args.size.1, &mask);
    let mut files = vec![(args.output.as_path(), &png[..])];
    files.extend(args.mask.as_deref().map(|m| (m, &pgm[..])));
    write_files(&files)?;
    let write = t.elapsed();
    let (seen, lit) = mask_counts(&mask);
    let lit = match seen {
        0 => "nothing of the scene in view (look at --eye, --target and --fov)".to_string(),
        _ => format!(
            "{:.1}% of the visible pixels lit by light 0",
            100.0 * lit as f64 / seen as f64
        ),
    };
    let mut text = format!(
        "wrote {}: {}x{} of {} ({} faces), {} shadows, {} visibility; {lit}\n",
        args.output.display(),
        args.size.0,
        args.size.1,
        p.name,
        p.faces,
        args.method,
        args.hsr.name(),
    );
    if let Some(m) = &args.mask {
        text += &format!("wrote {}: the mask of light 0\n", m.display());
    }
    if args.stats {
        for (i, n) in p.light_notes.iter().enumerate() {
            text += &format!("light {i}:        {n}\n");
        }
        text += &format!("load/import:    {:.1} ms\n", ms(p.load_time));
        text += &out.timings();
        text += &format!("write:          {:.1} ms\n", ms(write));
        text += &format!("total:          {:.1} ms\n", ms(total.elapsed()));
    }
    emit(&text)
}

/// `shadow compare`.
pub(crate) fn run_compare(args: &CompareArgs) -> Result<()> {
    check_ext(&args.output, "png", "-o")?;
    if let Some(r) = &args.report {
        check_ext(r, "csv", "--report")?;
    }
    let shadow = args.opts.options()?;
    let p = prepare(&args.scene, Some(&args.lights), args.size)?;
    let methods = match (args.methods.is_empty(), p.soft.is_empty()) {
        (false, _) => args.methods.clone(),
        (true, true) => Method::ALL.to_vec(),
        (true, false) => Method::SOFT.to_vec(),
    };
    let (scene, cam, colors) = (&p.scene, &p.camera, &p.colors);
    let cmp = match &p.soft[..] {
        [] => compare(scene, &p.lights, cam, colors, &shadow, &methods)?,
        soft => compare_soft(scene, soft, cam, colors, &shadow, &methods)?,
    };
    let png = cmp
        .image(args.columns as usize, args.highlight)
        .encode_png();
    let csv = cmp.csv();
    let mut files = vec![(args.output.as_path(), &png[..])];
    files.extend(args.report.as_deref().map(|r| (r, csv.as_bytes())));
    write_files(&files)?;
    let mut text = format!(
        "wrote {}: {} methods on {} ({} faces), {}x{} each; visibility {:.1} ms\n",
        args.output.display(),
        cmp.reports.len(),
        p.name,
        p.faces,
        args.size.0,
        args.size.1,
        ms(cmp.visibility_time)
    );
    text += &cmp.table();
    if let Some(r) = &args.report {
        text += &format!("wrote {}\n", r.display());
    }
    emit(&text)
}

/// `shadow lines`.
pub(crate) fn run_lines(args: &LinesArgs) -> Result<()> {
    check_ext(&args.output, "svg", "-o")?;
    let p = prepare(&args.scene, None, args.size)?;
    let lines = hidden_lines(&p.scene, &p.camera)?;
    write_file(&args.output, lines.svg(args.hidden).as_bytes())?;
    let what = lines.summary();
    emit(&format!("wrote {}: {what}\n", args.output.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn methods_and_biases_parse() {
        assert_eq!(" shadow-map".parse(), Ok(Method::ShadowMap));
        let e = "phong".parse::<Method>().unwrap_err().to_string();
        assert!(e.contains("available: exact, raycast"), "{e}");
        assert_eq!("warnock".parse(), Ok(Hsr::Warnock));
        assert!("painter".parse::<Hsr>().is_err());
    }
}
