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

use std::fmt::Write as _;
use std::io::Write;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use bsp_core::{BspTree, BuildOptions, Polygon};
use clap::{Args, ValueEnum};
use glam::DVec3;
use shadow_raster::svg::{SvgFragment, SvgView, SvgViewpoint};
use svbsp::export::{FragmentFile, FragmentFormat, area_records, world_vertices};
use svbsp::{Areas, Batch, LightSpec, ShadeOptions, Shadows, chin_feiner, percent, receivers};

use crate::args::{CameraArgs, ImageArgs, LightArgs, SourceArgs};
use crate::input::{NO_LIGHT, Scene};
use crate::lights::describe;
use crate::output::{Output, Phases, emit, guarded};
use crate::progress::Progress;
use crate::raster_error;

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

/// How many faces `--stats` lists.
const TOP_FACES: usize = 10;

/// The output format, by the file's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Json,
    Obj,
    Svg,
}

impl Format {
    fn from_path(path: &Path) -> Result<Format> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("json") => Ok(Format::Json),
            Some("obj") => Ok(Format::Obj),
            Some("svg") => Ok(Format::Svg),
            _ => bail!(
                "{}: unknown output format (use .json, .obj or .svg)",
                path.display()
            ),
        }
    }
}

/// What a run reports.
#[derive(Default)]
struct Figures {
    fragments: usize,
    receivers: usize,
    shadow_nodes: usize,
    bsp_polygons: Option<usize>,
    extra: String,
}

// ------------------------------------------------------------- command

/// What the command line asks for, checked before any work is done.
struct Request {
    format: Format,
    /// The lights given.
    specs: Vec<LightSpec>,
}

impl Request {
    /// Fails on a bad output name, or no light for a file (a built-in
    /// scene may have its own).
    fn of(args: &ShadowsArgs) -> Result<Request> {
        let format = Format::from_path(&args.output)?;
        if format != Format::Svg && (args.camera.any() || args.image.any()) {
            note(
                args,
                "note: --eye, --target, --up, --size and --fov only apply to SVG output",
            );
        }
        args.source.check()?;
        let specs = args.lights.specs();
        if specs.is_empty() && args.source.input.is_some() {
            bail!("{NO_LIGHT}");
        }
        Ok(Request { format, specs })
    }
}

/// A note on stderr, unless `--quiet`.
fn note(args: &ShadowsArgs, s: &str) {
    if !args.quiet {
        eprintln!("{s}");
    }
}

/// `shadow shadows`.
pub(crate) fn run(args: &ShadowsArgs) -> Result<()> {
    let total = Instant::now();
    let request = Request::of(args)?;
    let progress = Progress::new(!args.quiet);
    let mut phases = Phases::default();
    progress.phase("loading", 1);
    let scene = Scene::load(&args.source, request.specs, true, args.quiet, &mut phases)?;
    let view = (request.format == Format::Svg).then(|| {
        let size = args.image.size();
        let image = (size, args.image.fov);
        args.camera
            .pick(&scene.mesh, scene.staging, image, args.quiet)
    });
    let mut out = Output::create(&args.output)?;
    let mut job = Job {
        args,
        format: request.format,
        scene: &scene,
        kernel: scene.lights.iter().map(|l| l.light).collect(),
        progress: &progress,
        phases,
        areas: Areas::new(scene.lights.len(), scene.mesh.faces.len()),
        fig: Figures::default(),
    };
    guarded("the input and the command line", || {
        job.run(view.as_ref(), &mut out)
    })?;
    out.commit()?;
    progress.finish();
    let total = total.elapsed();

    let areas = &job.areas;
    let lit_share = percent(areas.total - areas.dark, areas.total);
    // the SVG's fragments are pieces of the scene tree's polygons, the
    // files' pieces of the faces: say which
    let of = match job.fig.bsp_polygons {
        Some(n) => format!(
            "the scene tree's {n} polygons ({} faces)",
            scene.mesh.faces.len()
        ),
        None => format!("{} faces", scene.mesh.faces.len()),
    };
    let mut report = format!(
        "wrote {}: {} fragments of {of} of {}{}; {}, {lit_share:.1}% of the area lit\n",
        args.output.display(),
        job.fig.fragments,
        scene.name,
        job.fig.extra,
        scene.light_count(),
    );
    if job.fig.fragments == 0 {
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
        report += &stats_text(&scene, &job.fig, areas, &job.phases, total);
    }
    emit(&report)
}

/// One run's shading and writing, and what it counts.
struct Job<'a> {
    args: &'a ShadowsArgs,
    format: Format,
    scene: &'a Scene,
    kernel: Vec<svbsp::Light>,
    progress: &'a Progress,
    phases: Phases,
    areas: Areas,
    fig: Figures,
}

impl Job<'_> {
    /// Shades every face (or for the SVG every polygon of the scene's
    /// BSP) and writes the file.
    fn run(&mut self, view: Option<&SvgViewpoint>, out: &mut Output) -> Result<()> {
        let write_err = || format!("could not write {}", self.args.output.display());
        let (batch, tree) = match (self.args.algorithm, self.format) {
            (Algorithm::Psv, Format::Json | Format::Obj) => {
                let shadows = self.shadow_trees()?;
                return self.stream(&shadows, out).with_context(write_err);
            }
            (Algorithm::Psv, Format::Svg) => {
                let tree = self.scene_tree();
                let shadows = self.shadow_trees()?;
                (self.shade_each(&shadows, &tree), tree)
            }
            (Algorithm::ChinFeiner, _) => {
                let tree = self.scene_tree();
                self.fig.receivers = tree.polygons().count();
                self.progress.phase("Chin & Feiner", 1);
                let cf = self
                    .phases
                    .run("shadows", || chin_feiner(&tree, &self.kernel))?;
                self.fig.shadow_nodes = cf.shadow_nodes;
                (Batch::from_chin_feiner(&cf, &self.kernel), tree)
            }
        };
        self.progress.phase("writing", 1);
        let world = world_vertices(&batch, &self.scene.grid)?;
        let records = area_records(&batch, &world);
        self.fig.fragments = batch.len();
        let mut phases = std::mem::take(&mut self.phases);
        phases
            .run("write", || match (self.format, view) {
                (Format::Svg, Some(view)) => self.write_svg(out, &tree, view, &batch, &world),
                _ => {
                    let mut file = self.begin(out)?;
                    file.write(out, (&batch, &world, &records), None)?;
                    self.finish(file, out)
                }
            })
            .with_context(write_err)?;
        self.phases = phases;
        Ok(())
    }

    /// One shadow-volume tree per light.
    fn shadow_trees(&mut self) -> Result<Shadows> {
        self.progress
            .phase("shadow trees", self.kernel.len() as u64);
        let shadows = self
            .phases
            .run("trees", || Shadows::new(&self.scene.polys, &self.kernel))?;
        self.fig.shadow_nodes = shadows.volumes().iter().map(|v| v.node_count()).sum();
        Ok(shadows)
    }

    /// The scene's BSP tree (the SVG's painter's order, and the polygons
    /// Chin & Feiner shade).
    fn scene_tree(&mut self) -> BspTree {
        self.progress.phase("scene tree", 1);
        let polys = &self.scene.polys;
        let tree = self.phases.run("bsp", || {
            BspTree::build(polys.clone(), &BuildOptions::default())
        });
        self.fig.bsp_polygons = Some(tree.polygons().count());
        tree
    }

    /// Every polygon of `tree` shaded as its own receiver (receiver =
    /// polygon index), in parallel.
    fn shade_each(&mut self, shadows: &Shadows, tree: &BspTree) -> Batch {
        let polys: Vec<Polygon> = tree.polygons().cloned().collect();
        self.fig.receivers = polys.len();
        self.progress.phase("shading", polys.len() as u64);
        let progress = self.progress;
        let ranges: Vec<Range<usize>> = (0..polys.len()).map(|i| i..i + 1).collect();
        self.phases.run("shading", || {
            let opts = ShadeOptions::default();
            shadows
                .set()
                .shade_par(&polys, &ranges, &opts, |n| progress.inc(n as u64))
        })
    }

    /// Starts the JSON or OBJ file.
    fn begin(&self, out: &mut Output) -> Result<FragmentFile> {
        let format = match self.format {
            Format::Json => FragmentFormat::Json,
            _ => FragmentFormat::Obj,
        };
        let scene = self.scene;
        let notes: Vec<String> = scene.lights.iter().map(describe).collect();
        let faces = scene.mesh.faces.len();
        let head = (scene.name.as_str(), &notes[..]);
        Ok(FragmentFile::begin(
            out,
            format,
            &scene.lights,
            faces,
            head,
        )?)
    }

    /// Ends the JSON or OBJ file, keeps its areas, notes the OBJ's vertex
    /// count and warns of pieces degenerate once rounded.
    fn finish(&mut self, file: FragmentFile, out: &mut Output) -> Result<()> {
        let w = file.finish(out)?;
        self.areas = w.areas;
        if self.format == Format::Obj {
            self.fig.extra = format!(", {} vertices", w.vertices);
        }
        if w.degenerate > 0 && !self.args.quiet {
            eprintln!(
                "warning: {} fragment piece(s) have distinct exact vertices that coincide once \
                 rounded to f64 input units; they are degenerate in the file",
                w.degenerate
            );
        }
        Ok(())
    }

    /// Draws the fragments of the scene tree's polygons.
    fn write_svg(
        &mut self,
        out: &mut Output,
        tree: &BspTree,
        view: &SvgViewpoint,
        batch: &Batch,
        world: &[DVec3],
    ) -> Result<()> {
        for r in area_records(batch, world) {
            self.areas.add(r.face, r.area, r.lit, r.facing);
        }
        let frags = SvgFragment::of_batch(batch, world);
        let (scene, what) = (self.scene, "shadow shadows");
        let r = SvgView::mesh_fragments(
            &scene.grid,
            &scene.mesh,
            view,
            tree,
            &scene.lights,
            &frags,
            what,
        )
        .map_err(raster_error)?;
        out.write_all(r.svg.as_bytes())?;
        self.fig.extra = format!(
            ", {} drawn, eye {:.3},{:.3},{:.3}",
            r.drawn, r.eye.x, r.eye.y, r.eye.z
        );
        Ok(())
    }

    /// Shades the receivers and writes them as they are done
    /// ([`FragmentFile::stream`]).
    fn stream(&mut self, shadows: &Shadows, out: &mut Output) -> Result<()> {
        let scene = self.scene;
        let opts = ShadeOptions::default().with_pieces(self.format == Format::Obj);
        let mut file = self.begin(out)?;
        let progress = self.progress;
        let ranges = receivers(&scene.polys);
        progress.phase("shading", ranges.len() as u64);
        let polys = (&scene.polys[..], &ranges[..], &scene.grid);
        let s = file.stream(out, shadows.set(), polys, &opts, |n| {
            progress.inc(n as u64);
        })?;
        self.fig.receivers = s.receivers;
        self.fig.fragments = s.fragments;
        self.finish(file, out)?;
        self.phases.0.push(("shading", s.shading));
        self.phases.0.push(("write", s.writing));
        Ok(())
    }
}

/// The `--stats` report.
fn stats_text(
    scene: &Scene,
    fig: &Figures,
    areas: &Areas,
    phases: &Phases,
    total: Duration,
) -> String {
    let faces = scene.mesh.faces.len();
    let lights = &scene.lights;
    let mut s = String::new();
    let _ = writeln!(s, "faces:           {faces}; {}", scene.report.counts());
    let _ = writeln!(s, "grid step:       {}", scene.grid.step_text());
    if let Some(n) = fig.bsp_polygons {
        let _ = writeln!(s, "bsp:             {n} polygons");
    }
    let _ = writeln!(
        s,
        "fragments:       {} ({:.3} per face; {} receivers, {} shadow-tree nodes over {} light{})",
        fig.fragments,
        fig.fragments as f64 / faces.max(1) as f64,
        fig.receivers,
        fig.shadow_nodes,
        lights.len(),
        if lights.len() == 1 { "" } else { "s" }
    );
    for (i, l) in lights.iter().enumerate() {
        let _ = writeln!(s, "light {i}:         {}", describe(l));
        if l.angle > 0.0 {
            let _ = writeln!(
                s,
                "                 exact for the integer direction, {:.3e} degrees from the \
                 given one",
                l.angle.to_degrees()
            );
        }
    }
    let times: Vec<String> = phases
        .0
        .iter()
        .map(|(n, d)| format!("{n} {:.2} ms", d.as_secs_f64() * 1e3))
        .collect();
    let _ = writeln!(
        s,
        "time:            {}; total {:.2} ms ({} threads)",
        times.join(", "),
        total.as_secs_f64() * 1e3,
        rayon::current_num_threads()
    );
    s += &areas.report(TOP_FACES, |f| scene.mesh.group_name(f).to_string());
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use shadow_scene::{ROOM_EYE, ROOM_TARGET};

    #[test]
    fn formats_by_extension() {
        assert_eq!(
            Format::from_path(Path::new("a.JSON")).unwrap(),
            Format::Json
        );
        assert_eq!(
            Format::from_path(Path::new("a/b.obj")).unwrap(),
            Format::Obj
        );
        assert_eq!(Format::from_path(Path::new("c.Svg")).unwrap(), Format::Svg);
        let e = Format::from_path(Path::new("out.png")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "out.png: unknown output format (use .json, .obj or .svg)"
        );
        assert!(Format::from_path(Path::new("json")).is_err());
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
