//! A scene's exact shadows written as a file, the job of `shadow
//! shadows`: the fragments as JSON or OBJ, shaded and written chunk by
//! chunk (the file is the same for every thread count, and memory stays
//! bounded), or an SVG view of the shaded scene drawn in the painter's
//! order of the scene's BSP tree; by partitioned shadow volumes or by
//! Chin & Feiner's shadow-volume BSP tree. The caller sees the phases and
//! their steps through [`Progress`], and gets the figures back.

use std::io::Write;
use std::ops::Range;
use std::time::{Duration, Instant};

use bsp_core::{BspTree, BuildOptions, Grid, Polygon};
use glam::DVec3;
use shadow_raster::svg::{SvgFragment, SvgView, SvgViewpoint};
use shadow_scene::Mesh;
use svbsp::export::{FragmentFile, FragmentFormat, area_records, world_vertices};
use svbsp::{Areas, Batch, PlacedLight, ShadeOptions, chin_feiner, receivers};

use crate::Error;

/// A scene snapped to its grid, with its lights: what the job shades.
#[derive(Clone, Copy, Debug)]
pub struct LitScene<'a> {
    /// The scene's name, for the OBJ's comments.
    pub name: &'a str,
    /// The mesh (its faces' colours and groups).
    pub mesh: &'a Mesh,
    /// The grid the faces and lights are snapped to.
    pub grid: &'a Grid,
    /// The lights on the grid.
    pub lights: &'a [PlacedLight],
    /// One line per light, for the OBJ's comments.
    pub light_notes: &'a [String],
    /// The faces on the grid, each tagged with its index in the mesh.
    pub polys: &'a [Polygon],
}

/// Which algorithm computes the shadows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Algorithm {
    /// Partitioned shadow volumes: every face cut only where a shadow
    /// boundary crosses it.
    Psv,
    /// Chin & Feiner's shadow-volume BSP tree over the scene's BSP tree:
    /// the fragments are pieces of the tree's polygons.
    ChinFeiner,
}

/// The format of a shadows file, by its extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputFormat {
    /// `.json`: the fragments.
    Json,
    /// `.obj`: the fragments as groups.
    Obj,
    /// `.svg`: a view of the shaded scene.
    Svg,
}

impl OutputFormat {
    /// The format of `path` by its extension (any case); `None` for
    /// another.
    pub fn from_path(path: &std::path::Path) -> Option<OutputFormat> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "json" => Some(OutputFormat::Json),
            "obj" => Some(OutputFormat::Obj),
            "svg" => Some(OutputFormat::Svg),
            _ => None,
        }
    }
}

/// What the file holds.
#[derive(Clone, Copy, Debug)]
pub enum FileKind<'a> {
    /// The fragments as JSON.
    Json,
    /// The fragments as OBJ (groups `lit` and `shadow`).
    Obj,
    /// A view of the shaded scene from a viewpoint, as SVG.
    Svg(&'a SvgViewpoint),
}

/// Hears about a long job's progress.
pub trait Progress: Sync {
    /// A phase starts that takes `steps` steps.
    fn phase(&self, name: &'static str, steps: u64);
    /// `steps` more steps are done.
    fn advance(&self, steps: u64);
}

/// No progress to hear of.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn phase(&self, _: &'static str, _: u64) {}
    fn advance(&self, _: u64) {}
}

/// What a job wrote, and what it took.
#[derive(Debug)]
pub struct ShadowFile {
    /// Fragments written (or for SVG, shaded).
    pub fragments: usize,
    /// Receivers shaded: faces, or the scene tree's polygons.
    pub receivers: usize,
    /// Nodes of the shadow-volume trees.
    pub shadow_nodes: usize,
    /// The occluders the trees were built from and those offered, summed
    /// over the lights (faces turned away from a light, of closed meshes,
    /// are left out), where the partitioned shadow volumes ran.
    pub occluders: Option<(usize, usize)>,
    /// Polygons of the scene's BSP tree, where one was built.
    pub bsp_polygons: Option<usize>,
    /// The fragments' areas, added up.
    pub areas: Areas,
    /// Positions of an OBJ file.
    pub vertices: Option<usize>,
    /// OBJ pieces whose distinct exact vertices coincide once rounded.
    pub degenerate: usize,
    /// For SVG: the pieces drawn and the eye, in input units.
    pub drawn: Option<(usize, DVec3)>,
    /// The wall time of each phase, in order.
    pub phases: Vec<(&'static str, Duration)>,
}

/// How many faces [`ShadowFile::stats_text`] lists.
const TOP_FACES: usize = 10;

impl ShadowFile {
    /// The `--stats` report for people: the faces, what importing them
    /// did (`import`: its counts) and the grid, the fragments, each
    /// light (`lights`: its description, and how far its integer
    /// direction is from the given one, radians), the phases' times and
    /// the total, the threads, and the faces with the most shadow (named
    /// by `group`).
    pub fn stats_text(
        &self,
        (faces, import, grid): (usize, &str, &bsp_core::Grid),
        lights: &[(String, f64)],
        (phases, total): (&[(&'static str, Duration)], Duration),
        group: impl Fn(usize) -> String,
    ) -> String {
        use std::fmt::Write as _;
        let mut s = String::new();
        let _ = writeln!(s, "faces:           {faces}; {import}");
        let _ = writeln!(s, "grid step:       {}", grid.step_text());
        if let Some(n) = self.bsp_polygons {
            let _ = writeln!(s, "bsp:             {n} polygons");
        }
        let _ = writeln!(
            s,
            "fragments:       {} ({:.3} per face; {} receivers, {} shadow-tree nodes over {} light{}{})",
            self.fragments,
            self.fragments as f64 / faces.max(1) as f64,
            self.receivers,
            self.shadow_nodes,
            lights.len(),
            if lights.len() == 1 { "" } else { "s" },
            self.occluders.map_or(String::new(), |(n, of)| format!(
                "; {n} of {of} occluders kept, faces of closed meshes turned away left out"
            ))
        );
        for (i, (what, angle)) in lights.iter().enumerate() {
            let _ = writeln!(s, "light {i}:         {what}");
            if *angle > 0.0 {
                let _ = writeln!(
                    s,
                    "                 exact for the integer direction, {:.3e} degrees from the \
                     given one",
                    angle.to_degrees()
                );
            }
        }
        let times: Vec<String> = phases
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
        s += &self.areas.report(TOP_FACES, group);
        s
    }
}

/// Shades every face of `scene` by `algorithm` and writes `kind` to `out`.
pub fn write_shadows(
    scene: &LitScene,
    algorithm: Algorithm,
    kind: FileKind,
    out: &mut dyn Write,
    progress: &dyn Progress,
) -> Result<ShadowFile, Error> {
    let mut job = Job {
        scene,
        kernel: scene.lights.iter().map(|l| l.light).collect(),
        progress,
        fig: ShadowFile {
            fragments: 0,
            receivers: 0,
            shadow_nodes: 0,
            occluders: None,
            bsp_polygons: None,
            areas: Areas::new(scene.lights.len(), scene.mesh.faces.len()),
            vertices: None,
            degenerate: 0,
            drawn: None,
            phases: Vec::new(),
        },
    };
    job.run(algorithm, kind, out)?;
    Ok(job.fig)
}

/// One run's shading and writing, and what it counts.
struct Job<'a> {
    scene: &'a LitScene<'a>,
    kernel: Vec<svbsp::Light>,
    progress: &'a dyn Progress,
    fig: ShadowFile,
}

/// Runs `f`, its time pushed to `phases` as phase `name`.
fn timed<T>(
    phases: &mut Vec<(&'static str, Duration)>,
    name: &'static str,
    f: impl FnOnce() -> T,
) -> T {
    let start = Instant::now();
    let out = f();
    phases.push((name, start.elapsed()));
    out
}

impl Job<'_> {
    fn run(
        &mut self,
        algorithm: Algorithm,
        kind: FileKind,
        out: &mut dyn Write,
    ) -> Result<(), Error> {
        let (batch, tree) = match (algorithm, kind) {
            (Algorithm::Psv, FileKind::Json | FileKind::Obj) => {
                let shadows = self.shadow_trees(true)?;
                return self.stream(&shadows, kind, out);
            }
            (Algorithm::Psv, FileKind::Svg(_)) => {
                let tree = self.scene_tree();
                let shadows = self.shadow_trees(false)?;
                (self.shade_each(&shadows, &tree), tree)
            }
            (Algorithm::ChinFeiner, _) => {
                let tree = self.scene_tree();
                self.fig.receivers = tree.polygons().count();
                self.progress.phase("Chin & Feiner", 1);
                let kernel = &self.kernel;
                let cf = timed(&mut self.fig.phases, "shadows", || {
                    chin_feiner(&tree, kernel)
                })
                .map_err(Error::Light)?;
                self.fig.shadow_nodes = cf.shadow_nodes;
                (Batch::from_chin_feiner(&cf, &self.kernel), tree)
            }
        };
        self.progress.phase("writing", 1);
        let world = world_vertices(&batch, self.scene.grid).map_err(Error::Export)?;
        self.fig.fragments = batch.len();
        let start = Instant::now();
        match kind {
            FileKind::Svg(view) => self.write_svg(out, &tree, view, &batch, &world)?,
            _ => {
                let records = area_records(&batch, &world);
                let mut file = self.begin(kind, out)?;
                file.write(out, (&batch, &world, &records), None)
                    .map_err(Error::Io)?;
                self.finish(file, kind, out)?;
            }
        }
        self.fig.phases.push(("write", start.elapsed()));
        Ok(())
    }

    /// One shadow-volume tree per light; with `reaching`, knowing which
    /// faces each light reaches all over or not at all, for shading the
    /// scene's own polygons ([`svbsp::LightVolumes::set_for_occluders`]).
    fn shadow_trees(&mut self, reaching: bool) -> Result<svbsp::LightVolumes, Error> {
        self.progress
            .phase("shadow trees", self.kernel.len() as u64);
        let (polys, kernel) = (self.scene.polys, &self.kernel);
        let shadows = timed(&mut self.fig.phases, "trees", || match reaching {
            true => svbsp::LightVolumes::new_reaching(polys, kernel),
            false => svbsp::LightVolumes::new(polys, kernel),
        })
        .map_err(Error::Shadow)?;
        self.fig.shadow_nodes = shadows.volumes().iter().map(|v| v.node_count()).sum();
        let kept = shadows.volumes().iter().map(|v| v.occluder_count()).sum();
        self.fig.occluders = Some((kept, polys.len() * kernel.len()));
        Ok(shadows)
    }

    /// The scene's BSP tree (the SVG's painter's order, and the polygons
    /// Chin & Feiner shade).
    fn scene_tree(&mut self) -> BspTree {
        self.progress.phase("scene tree", 1);
        let polys = self.scene.polys;
        let tree = timed(&mut self.fig.phases, "bsp", || {
            BspTree::build(polys.to_vec(), &BuildOptions::default())
        });
        self.fig.bsp_polygons = Some(tree.polygons().count());
        tree
    }

    /// Every polygon of `tree` shaded as its own receiver (receiver =
    /// polygon index), in parallel.
    fn shade_each(&mut self, shadows: &svbsp::LightVolumes, tree: &BspTree) -> Batch {
        let polys: Vec<Polygon> = tree.polygons().cloned().collect();
        self.fig.receivers = polys.len();
        self.progress.phase("shading", polys.len() as u64);
        let progress = self.progress;
        let ranges: Vec<Range<usize>> = (0..polys.len()).map(|i| i..i + 1).collect();
        timed(&mut self.fig.phases, "shading", || {
            let opts = ShadeOptions::default();
            shadows
                .set()
                .shade_par(&polys, &ranges, &opts, |n| progress.advance(n as u64))
        })
    }

    /// Starts the JSON or OBJ file.
    fn begin(&self, kind: FileKind, out: &mut dyn Write) -> Result<FragmentFile, Error> {
        let format = match kind {
            FileKind::Json => FragmentFormat::Json,
            _ => FragmentFormat::Obj,
        };
        let s = self.scene;
        let head = (s.name, s.light_notes);
        FragmentFile::begin(out, format, s.lights, s.mesh.faces.len(), head).map_err(Error::Io)
    }

    /// Ends the JSON or OBJ file and keeps its figures.
    fn finish(
        &mut self,
        file: FragmentFile,
        kind: FileKind,
        out: &mut dyn Write,
    ) -> Result<(), Error> {
        let w = file.finish(out).map_err(Error::Io)?;
        self.fig.areas = w.areas;
        if matches!(kind, FileKind::Obj) {
            self.fig.vertices = Some(w.vertices);
        }
        self.fig.degenerate = w.degenerate;
        Ok(())
    }

    /// Draws the fragments of the scene tree's polygons.
    fn write_svg(
        &mut self,
        out: &mut dyn Write,
        tree: &BspTree,
        view: &SvgViewpoint,
        batch: &Batch,
        world: &[DVec3],
    ) -> Result<(), Error> {
        for r in area_records(batch, world) {
            self.fig.areas.add(r.face, r.area, r.lit, r.facing);
        }
        let frags = SvgFragment::of_batch(batch, world);
        let s = self.scene;
        let what = "shadow shadows";
        let r = SvgView::mesh_fragments(s.grid, s.mesh, view, tree, s.lights, &frags, what)
            .map_err(Error::Raster)?;
        out.write_all(r.svg.as_bytes()).map_err(Error::Io)?;
        self.fig.drawn = Some((r.drawn, r.eye));
        Ok(())
    }

    /// Shades the receivers and writes them as they are done
    /// ([`FragmentFile::stream`]).
    fn stream(
        &mut self,
        shadows: &svbsp::LightVolumes,
        kind: FileKind,
        out: &mut dyn Write,
    ) -> Result<(), Error> {
        let scene = self.scene;
        // (a file holds the vertices' rounding only)
        let opts = ShadeOptions::default()
            .with_pieces(matches!(kind, FileKind::Obj))
            .with_vertices(false);
        let mut file = self.begin(kind, out)?;
        let progress = self.progress;
        let ranges = receivers(scene.polys);
        progress.phase("shading", ranges.len() as u64);
        let polys = (scene.polys, &ranges[..], scene.grid);
        let s = file
            .stream(out, shadows.set_for_occluders(), polys, &opts, |n| {
                progress.advance(n as u64)
            })
            .map_err(Error::Io)?;
        self.fig.receivers = s.receivers;
        self.fig.fragments = s.fragments;
        self.finish(file, kind, out)?;
        self.fig.phases.push(("shading", s.shading));
        self.fig.phases.push(("write", s.writing));
        Ok(())
    }
}
