//! `shadow csg`: exact Boolean operations (∪ ∩ −) on closed meshes.
//!
//! Load the operands → validate each as a closed, consistently oriented
//! 2-manifold → snap all to one grid → `bsp-csg` applies each operation in
//! turn to the first operand (local BSPs in an adaptive octree) →
//! boundary as a watertight triangle mesh → write. Every decision after
//! snapping is exact; the only roundings are the input snap and the final
//! conversion of exact vertices to `f64` (and to `f32` for STL). This
//! module is the front end: loading, messages that point into the files,
//! and the report; the work is the library's.

use rayon::prelude::*;
use std::io::Write;
use std::panic;
use std::path::PathBuf;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, anyhow};
use bsp_core::{BoolOp, Grid, ImportReport, TopologyError, TriMesh};
use bsp_csg::{CsgError, MeshBuf, MeshIn, SequenceError, Stage, Step};
use clap::{Args, ValueEnum};
use glam::DVec3;
use shadow_scene::{Mesh, MeshFormat, MeshView, Triangles};

/// A Boolean operation as named on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum Operation {
    /// A ∪ B.
    Union,
    /// A ∩ B.
    Intersection,
    /// A − B.
    Difference,
}

impl Operation {
    fn name(self) -> &'static str {
        match self {
            Operation::Union => "union",
            Operation::Intersection => "intersection",
            Operation::Difference => "difference",
        }
    }

    fn kernel(self) -> BoolOp {
        match self {
            Operation::Union => BoolOp::Union,
            Operation::Intersection => BoolOp::Intersection,
            Operation::Difference => BoolOp::Difference,
        }
    }
}

#[derive(Args, Debug)]
pub(crate) struct CsgArgs {
    /// The operation, applied in turn: `difference PART TOOL...` subtracts
    /// every tool from the part; union and intersection combine all.
    #[arg(value_enum)]
    pub(crate) op: Operation,
    /// The operands (.obj or .stl), two or more: closed, consistently
    /// oriented meshes.
    #[arg(value_name = "MESH", num_args = 2.., required = true)]
    pub(crate) operands: Vec<PathBuf>,
    /// Output file: .obj, or .stl for binary STL.
    #[arg(short, long, value_name = "OUT")]
    pub(crate) output: PathBuf,
    /// Merge vertices with exactly equal positions first (for files that
    /// repeat the vertices of every face; STL input is always welded).
    #[arg(long)]
    pub(crate) weld: bool,
    /// Print counts, the exact volume and the time of each phase.
    #[arg(long)]
    pub(crate) stats: bool,
}

/// One input mesh with what messages need to point into its file.
#[derive(Clone)]
struct Operand {
    /// The file, as given.
    name: String,
    mesh: Mesh,
    /// The faces' vertex loops as in the file, kept when `--weld` renumbered
    /// them, so that messages quote the file's indices.
    file_loops: Option<Vec<Vec<u32>>>,
    /// Triangles and faces as read (the mesh itself is let go once
    /// snapped).
    counts: (usize, usize),
}

impl Operand {
    fn new(name: String, mesh: Mesh, file_loops: Option<Vec<Vec<u32>>>) -> Operand {
        Operand {
            name,
            counts: (mesh.triangle_count(), mesh.faces.len()),
            mesh,
            file_loops,
        }
    }

    /// The operands from `paths`, read (and welded) in parallel; the
    /// readers' notes are printed, and the first error returned, in the
    /// order of the files, as reading them in turn would.
    fn load_all(paths: &[PathBuf], weld: bool) -> Result<Vec<Operand>> {
        type Read = (Mesh, Option<Vec<Vec<u32>>>, Option<String>);
        let read: Vec<Result<Read>> = paths
            .par_iter()
            .map(|p| {
                let (mut mesh, note) = crate::input::read_mesh(p)?;
                let file_loops = weld.then(|| {
                    let loops = mesh.faces.iter().map(|f| f.vertices.clone()).collect();
                    mesh.weld();
                    loops
                });
                Ok((mesh, file_loops, note))
            })
            .collect();
        let mut operands = Vec::with_capacity(paths.len());
        for (path, r) in paths.iter().zip(read) {
            let (mesh, file_loops, note) = r?;
            if let Some(m) = note {
                eprintln!("note: {m}");
            }
            let mesh = crate::input::with_faces(path, mesh)?;
            operands.push(Operand::new(path.display().to_string(), mesh, file_loops));
        }
        Ok(operands)
    }

    /// `file:line` of face `face` for text formats, else `file`.
    fn locate(&self, face: usize) -> String {
        match self.mesh.faces.get(face).map(|f| f.line) {
            Some(line) if line > 0 => format!("{}:{line}", self.name),
            _ => self.name.clone(),
        }
    }

    /// Vertex `v` (a mesh index) of face `face` as the user can find it:
    /// its index as written in the file (1-based) when the format has
    /// indices, else its coordinates.
    fn vertex(&self, face: usize, v: u32) -> String {
        let f = &self.mesh.faces[face];
        if f.line == 0 {
            let p = self.mesh.positions[v as usize];
            return format!("({}, {}, {})", p.x, p.y, p.z);
        }
        let at = f.vertices.iter().position(|&x| x == v);
        let in_file = match (&self.file_loops, at) {
            (Some(loops), Some(i)) => loops[face][i],
            _ => v,
        };
        (in_file + 1).to_string()
    }

    /// Checks that the faces form a closed, consistently oriented
    /// 2-manifold; the error names the file, line, face and edge. (The
    /// check of [`bsp_csg::check_mesh`], on the faces as they are.)
    fn validate(&self) -> Result<()> {
        bsp_core::check_closed_manifold(self.mesh.faces.iter().map(|f| f.vertices.as_slice()))
            .map_err(|error| anyhow!(self.topology_message(&error)))
    }

    /// [`Operand::validate`] of each operand, in parallel; the first
    /// error in their order.
    fn validate_all(operands: &[Operand]) -> Result<()> {
        let checked: Vec<Result<()>> = operands.par_iter().map(Operand::validate).collect();
        checked.into_iter().collect()
    }

    fn topology_message(&self, e: &TopologyError) -> String {
        let v = |face, x| self.vertex(face, x);
        let (face, what) = match *e {
            TopologyError::OpenEdge { a, b, face } => (
                Some(face),
                format!(
                    "edge {}-{} of face {face} is a boundary edge (the mesh is not closed)",
                    v(face, a),
                    v(face, b)
                ),
            ),
            TopologyError::Misoriented {
                a,
                b,
                faces: [first, face],
            } => {
                let first_at = match self.mesh.faces[first].line {
                    0 => String::new(),
                    line => format!(" (line {line})"),
                };
                (
                    Some(face),
                    format!(
                        "face {face} uses edge {}->{} in the same direction as face {first}{first_at} \
                         (the faces are not consistently oriented)",
                        v(face, a),
                        v(face, b)
                    ),
                )
            }
            TopologyError::NonManifoldEdge { a, b, face, .. } => (
                Some(face),
                format!(
                    "edge {}-{} of face {face} is shared by more than two faces (the mesh is not a 2-manifold)",
                    v(face, a),
                    v(face, b)
                ),
            ),
            TopologyError::DegenerateFace { face } => {
                let f = &self.mesh.faces[face];
                // without a line to look at, show the corners
                let corners = if f.line == 0 {
                    let c: Vec<String> = f.vertices.iter().map(|&x| v(face, x)).collect();
                    format!(" {}", c.join(" "))
                } else {
                    String::new()
                };
                let welded = if self.file_loops.is_some() {
                    " (after --weld merged equal positions)"
                } else {
                    ""
                };
                (
                    Some(face),
                    format!("face {face}{corners} repeats a vertex{welded}"),
                )
            }
            TopologyError::NonManifoldVertex { vertex } => {
                let face = self
                    .mesh
                    .faces
                    .iter()
                    .position(|f| f.vertices.contains(&vertex));
                let what = match face {
                    Some(face) => format!(
                        "vertex {} of face {face} joins separate fans of faces (a pinch: the mesh is not a 2-manifold there)",
                        v(face, vertex)
                    ),
                    None => e.to_string(),
                };
                (face, what)
            }
            _ => (None, e.to_string()),
        };
        let at = face.map_or_else(|| self.name.clone(), |f| self.locate(f));
        let hint = if self.file_loops.is_none() && self.mesh.repeated_positions() > 0 {
            "; if the file repeats vertices per face, try --weld"
        } else {
            ""
        };
        format!("{at}: {what}{hint}")
    }
}

/// Wall time of each phase, in order.
#[derive(Default)]
pub(crate) struct Phases(pub(crate) Vec<(&'static str, Duration)>);

impl Phases {
    /// Runs `f`, its time added to phase `name` (a new phase the first
    /// time).
    pub(crate) fn run<T>(&mut self, name: &'static str, f: impl FnOnce() -> T) -> T {
        let start = Instant::now();
        let out = f();
        let t = start.elapsed();
        match self.0.iter_mut().find(|(n, _)| *n == name) {
            Some((_, d)) => *d += t,
            None => self.0.push((name, t)),
        }
        out
    }
}

/// A Boolean operation's result and the figures `--stats` prints.
struct Outcome {
    /// The result's vertices in input units (its triangles are `exact`'s).
    positions: Vec<DVec3>,
    /// The operation's name: the result's one group.
    group: &'static str,
    /// The exact result (grid units).
    exact: TriMesh,
    grid: Grid,
    reports: Vec<ImportReport>,
    /// What each operation did.
    stats: Vec<bsp_csg::Stats>,
}

impl Outcome {
    /// The operation applied to the first operand with each of the others
    /// in turn ([`bsp_csg::mesh_sequence_with`]): each operand's faces are
    /// handed over when its turn comes and its mesh is let go once snapped,
    /// each import summary is printed to stderr as its operand is snapped,
    /// and the library's stages are timed as "snap/import", "boolean" and
    /// "boundary+mesh".
    fn new(operands: &mut [Operand], op: Operation, phases: &mut Phases) -> Result<Outcome> {
        // the meshes are checked, and messages from here on name the files
        // only; one grid holds every operand
        let grid = {
            let meshes: Vec<MeshIn<'_>> = operands
                .iter()
                .map(|o| MeshIn::new(&o.mesh.positions, &[]))
                .collect();
            bsp_csg::fit_grid(&meshes)
                .map_err(|e| anyhow!(e).context("cannot snap the faces to one grid"))?
        };
        let names: Vec<String> = operands.iter().map(|o| o.name.clone()).collect();
        let mut meshes = operands.iter_mut().map(hand_over);
        let first = meshes.next().expect("at least two operands");
        let rest = meshes.map(|m| (op.kernel(), m));
        let (mut reports, mut stats) = (Vec::new(), Vec::new());
        let mut clock = StageClock {
            phases,
            running: None,
        };
        let exact = bsp_csg::mesh_sequence_with(&grid, first, rest, |step| {
            clock.step(&step);
            match step {
                Step::Snapped { operand, report } => {
                    print_import_summary(&names[operand], &report, &grid);
                    reports.push(report);
                }
                Step::Planned { stats: s, .. } => stats.push(s),
                _ => {}
            }
        })
        .map_err(|e| sequence_error(e, &names, op, &grid))?;
        let positions = exact
            .vertices_f64()
            .into_par_iter()
            .map(|v| grid.to_world(v))
            .collect();
        // (the positions in input units are part of "boundary+mesh")
        clock.stop();
        Ok(Outcome {
            positions,
            group: op.name(),
            exact,
            grid,
            reports,
            stats,
        })
    }

    /// The result in input units, as written: its triangles beside their
    /// positions (no list per triangle), one group named after the
    /// operation.
    fn mesh(&self) -> Triangles<'_> {
        Triangles {
            positions: &self.positions,
            triangles: &self.exact.triangles,
            group: self.group,
        }
    }
}

/// Operand `o`'s mesh as the library takes it: the positions and the
/// face lists moved out (not copied), the rest of the mesh let go.
fn hand_over(o: &mut Operand) -> MeshBuf {
    o.file_loops = None;
    let mesh = std::mem::take(&mut o.mesh);
    let faces = mesh.faces.into_iter().map(|f| f.vertices).collect();
    MeshBuf::new(mesh.positions, faces)
}

/// Prints what snapping did to operand `name`'s faces, if anything.
fn print_import_summary(name: &str, report: &ImportReport, grid: &Grid) {
    let summary = report.summary();
    if !summary.is_empty() {
        eprint!("{name}: {summary}");
    }
    if !report.dropped.is_empty() {
        eprintln!(
            "warning: {name}: {} face(s) have no area on the grid (step 2^{}) and were dropped; \
             the solid may not be closed",
            report.dropped.len(),
            -grid.scale().log2()
        );
    }
}

/// The message for an operation that failed at `e.stage`, naming the
/// file it comes from.
fn sequence_error(e: SequenceError, names: &[String], op: Operation, grid: &Grid) -> anyhow::Error {
    match (e.stage, e.error) {
        (Stage::Snap(i), CsgError::Inward { .. }) => anyhow!(
            "{}: the faces are oriented inward (clockwise seen from outside): the solid they \
             bound is unbounded; reverse every face's vertex order",
            names[i]
        ),
        (Stage::Snap(_), CsgError::Grid(e)) => {
            anyhow!(e).context("cannot snap the faces to one grid")
        }
        (Stage::Operation(i), CsgError::NotASolid) => anyhow!(
            "{} or the result before it: a surface crosses itself after snapping to the \
             grid (step 2^{}) and bounds no solid",
            names[i],
            -grid.scale().log2()
        ),
        // the mesh is checked watertight as it is made (one check, the
        // one that tells whether it needs mending where the solid touches
        // itself)
        (Stage::Mesh, e) => {
            let e = match e {
                CsgError::Internal(why) => why,
                e => e.to_string(),
            };
            anyhow!(
                "internal error: the {} of {} is not watertight ({e}); this is a bug in the \
                 exact kernel, not a problem with the input, and nothing was written — please \
                 report it with the input files",
                op.name(),
                names.join(", ")
            )
        }
        (_, e) => anyhow!(e),
    }
}

/// Times the library's stages into [`Phases`] from the steps it reports:
/// a stage runs from its start to its end (the mesh's, to
/// [`StageClock::stop`], after the positions are converted).
struct StageClock<'p> {
    phases: &'p mut Phases,
    /// The phase running, and since when.
    running: Option<(&'static str, Instant)>,
}

impl StageClock<'_> {
    fn step(&mut self, step: &Step) {
        match step {
            Step::Started(stage) => {
                let phase = match stage {
                    Stage::Snap(_) => "snap/import",
                    Stage::Operation(_) => "boolean",
                    Stage::Mesh => "boundary+mesh",
                };
                self.stop();
                self.running = Some((phase, Instant::now()));
            }
            Step::Finished(Stage::Mesh) => {}
            Step::Finished(_) => self.stop(),
            _ => {}
        }
    }

    /// The running phase's time added to it (a new phase the first time).
    fn stop(&mut self) {
        let Some((name, start)) = self.running.take() else {
            return;
        };
        let t = start.elapsed();
        match self.phases.0.iter_mut().find(|(n, _)| *n == name) {
            Some((_, d)) => *d += t,
            None => self.phases.0.push((name, t)),
        }
    }
}

/// The exact volume in input units, rounded once to `f64`.
fn exact_volume(mesh: &TriMesh, grid: &Grid) -> f64 {
    // the scale is a power of two: the division is exact
    mesh.volume_rounded() / grid.scale().powi(3)
}

/// Runs `f`, turning a panic into an error that says it is a bug (the
/// kernel panics only on broken internal invariants) and asks for a
/// report with `inputs`.
pub(crate) fn guarded<T>(inputs: &str, f: impl FnOnce() -> Result<T>) -> Result<T> {
    static LAST: Mutex<Option<String>> = Mutex::new(None);
    let previous = panic::take_hook();
    panic::set_hook(Box::new(|info| {
        let payload = info.payload();
        let message = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "(no message)".to_string());
        let at = info
            .location()
            .map(|l| format!(" ({}:{})", l.file(), l.line()))
            .unwrap_or_default();
        *LAST.lock().unwrap_or_else(|e| e.into_inner()) = Some(format!("{message}{at}"));
    }));
    let result = panic::catch_unwind(panic::AssertUnwindSafe(f));
    panic::set_hook(previous);
    result.unwrap_or_else(|_| {
        let detail = LAST
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .take()
            .unwrap_or_default();
        Err(anyhow!(
            "internal error: {detail}; this is a bug, not a problem with the input, and nothing \
             was written — please report it with {inputs}"
        ))
    })
}

/// Has glibc keep the large blocks a run frees, to be used again, instead
/// of unmapping each one and faulting the next one in page by page.
///
/// glibc maps each allocation above a threshold (128 KiB at start) on its
/// own, and unmaps it when it is freed; when such a block is freed, it
/// raises the threshold to that block's size (up to 32 MiB) and from then
/// on keeps up to twice that much free memory in its heaps (mallopt(3),
/// "dynamic mmap threshold"). The phases of a mesh Boolean make and free
/// buffers of megabytes one after the other, so the threshold would rise
/// only after many of them had been faulted in and given back. Freeing one
/// block of just under 32 MiB, never touched (no page of it is faulted in),
/// raises it at once: the 99k-triangle union makes a fifth fewer page
/// faults and runs about 7% faster, with the same peak. (Not for every
/// command: `shadow shadows` on the 99k bunny ran no faster, with a
/// quarter more peak memory.) Other allocators and C libraries see one
/// allocation made and freed.
fn keep_freed_blocks() {
    // (two pages under 32 MiB: with glibc's header the mapped block is one
    // page under, within the largest threshold glibc raises to; where even
    // that much address space is refused, nothing is done)
    let mut block: Vec<u8> = Vec::new();
    if block.try_reserve_exact((32 << 20) - 8192).is_ok() {
        // (kept from being optimized away: the allocation is the point)
        drop(std::hint::black_box(block));
    }
}

/// `shadow csg`.
pub(crate) fn run(args: &CsgArgs) -> Result<()> {
    let total = Instant::now();
    keep_freed_blocks();
    // fail on a bad output name before doing any work
    MeshFormat::from_path(&args.output)?;
    let mut phases = Phases::default();
    let mut operands = phases.run("load", || Operand::load_all(&args.operands, args.weld))?;
    phases.run("validate", || Operand::validate_all(&operands))?;
    let out = guarded("the input files", || {
        Outcome::new(&mut operands, args.op, &mut phases)
    })?;
    phases.run("write", || shadow_scene::save(&args.output, &out.mesh()))?;
    let total = total.elapsed();

    let (tris, verts) = (out.exact.triangles.len(), out.positions.len());
    let names: Vec<&str> = operands.iter().map(|o| o.name.as_str()).collect();
    let of = match names.as_slice() {
        [a, b] => format!("{a} and {b}"),
        [first, rest @ ..] => format!("{first} and {} more", rest.len()),
        [] => String::new(),
    };
    let mut report = format!(
        "wrote {}: {} of {of}, {tris} triangles, {verts} vertices\n",
        args.output.display(),
        args.op.name(),
    );
    if tris == 0 {
        eprintln!("note: the {} is empty", args.op.name());
    }
    let coincide = out.mesh().repeated_positions();
    if coincide > 0 {
        eprintln!(
            "warning: {coincide} distinct exact vertices coincide once rounded to f64 input units; \
             their triangles are degenerate in the file"
        );
    }
    if MeshFormat::from_path(&args.output)? == MeshFormat::Stl {
        let merged = shadow_scene::stl_collisions(&out.mesh());
        if merged > 0 {
            eprintln!(
                "warning: {merged} vertices coincide once rounded to f32 for STL; the file may \
                 not be closed when read back (write .obj to keep full precision)"
            );
        }
    }
    if args.stats {
        report += &stats_text(args.op, &operands, &out, &phases, total);
    }
    emit(&report)
}

/// Writes to stdout; a closed pipe (`shadow csg ... --stats | head`) is
/// not an error.
pub(crate) fn emit(text: &str) -> Result<()> {
    let mut stdout = std::io::stdout().lock();
    match stdout
        .write_all(text.as_bytes())
        .and_then(|()| stdout.flush())
    {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(e).context("could not write to stdout")
        }
        _ => Ok(()),
    }
}

/// The `--stats` report. Computes the exact volume, which is timed on its
/// own (after "total", as only `--stats` pays for it).
fn stats_text(
    op: Operation,
    operands: &[Operand],
    out: &Outcome,
    phases: &Phases,
    total: Duration,
) -> String {
    let mut s = format!("operation:      {}\n", op.name());
    for (i, (o, r)) in operands.iter().zip(&out.reports).enumerate() {
        let label = match i {
            0 => "A".to_string(),
            1 if operands.len() == 2 => "B".to_string(),
            i => format!("{}", i + 1),
        };
        s += &format!(
            "input {label}:{:pad$}{}: {} triangles ({} faces), {} polygons after import \
             ({} faces triangulated, {} dropped)\n",
            "",
            o.name,
            o.counts.0,
            o.counts.1,
            r.polygons,
            r.triangulated.len(),
            r.dropped.len(),
            pad = 9usize.saturating_sub(label.len())
        );
    }
    s += &format!(
        "grid step:      2^{} = {:.3e} units\n",
        -out.grid.scale().log2(),
        out.grid.step()
    );
    let sum = out
        .stats
        .iter()
        .fold(bsp_csg::Stats::default(), |a, b| bsp_csg::Stats {
            cells: a.cells + b.cells,
            mixed_cells: a.mixed_cells + b.mixed_cells,
            merged_cells: a.merged_cells + b.merged_cells,
            cut_faces: a.cut_faces + b.cut_faces,
            pieces: a.pieces + b.pieces,
            easy_cells: a.easy_cells + b.easy_cells,
            clean_cells: a.clean_cells + b.clean_cells,
        });
    s += &format!(
        "octree:         {} cells, {} with both surfaces ({} with shared planes, {} where \
         they do not meet: {} with every face apart from the other surface, {} labelled from \
         the cells around); {} faces cut into {} pieces\n",
        sum.cells,
        sum.mixed_cells,
        sum.merged_cells,
        sum.easy_cells + sum.clean_cells,
        sum.clean_cells,
        sum.easy_cells,
        sum.cut_faces,
        sum.pieces
    );
    s += &format!(
        "output:         {} triangles, {} vertices\n",
        out.exact.triangles.len(),
        out.positions.len()
    );
    let start = Instant::now();
    let exact = exact_volume(&out.exact, &out.grid);
    let exact_time = start.elapsed();
    let k = out.grid.scale();
    s += &format!(
        "volume:         {exact} (exact, rounded once); {} (f64 sum)\n",
        out.exact.volume_f64() / (k * k * k)
    );
    s += "time (ms):\n";
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    for (name, d) in &phases.0 {
        s += &format!("  {name:<15}{:10.3}\n", ms(*d));
    }
    s += &format!("  {:<15}{:10.3}\n", "total", ms(total));
    s += &format!("  {:<15}{:10.3}\n", "exact volume", ms(exact_time));
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_bigint::BigInt;
    use num_rational::BigRational;
    use num_traits::{One, ToPrimitive, Zero};
    use shadow_scene::parse_obj;

    const CUBE: &str = "\
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
";

    fn operand(text: &str, name: &str, weld: bool) -> Operand {
        let mut mesh = parse_obj(text, name).unwrap();
        let file_loops = weld.then(|| {
            let l = mesh.faces.iter().map(|f| f.vertices.clone()).collect();
            mesh.weld();
            l
        });
        Operand::new(name.to_string(), mesh, file_loops)
    }

    /// The cube scaled by `s` and moved by `d`, as OBJ text with relative
    /// face indices (so that such texts can be concatenated).
    fn cube(s: f64, d: [f64; 3]) -> String {
        CUBE.lines()
            .map(|l| {
                if let Some(v) = l.strip_prefix("v ") {
                    let c: Vec<f64> = v.split(' ').map(|x| x.parse().unwrap()).collect();
                    format!(
                        "v {} {} {}\n",
                        c[0] * s + d[0],
                        c[1] * s + d[1],
                        c[2] * s + d[2]
                    )
                } else {
                    let f = l.strip_prefix("f ").unwrap();
                    let rel: Vec<String> = f
                        .split(' ')
                        .map(|i| (i.parse::<i32>().unwrap() - 9).to_string())
                        .collect();
                    format!("f {}\n", rel.join(" "))
                }
            })
            .collect()
    }

    #[test]
    fn open_mesh_names_line_face_and_file_indices() {
        // drop the top face (line 10)
        let text: String = CUBE
            .lines()
            .filter(|l| *l != "f 5 6 7 8")
            .map(|l| format!("{l}\n"))
            .collect();
        let e = operand(&text, "open.obj", false).validate().unwrap_err();
        assert_eq!(
            e.to_string(),
            "open.obj:10: edge 6-5 of face 1 is a boundary edge (the mesh is not closed)"
        );
    }

    #[test]
    fn misoriented_face_names_both_faces() {
        let text = CUBE.replace("f 2 3 7 6", "f 6 7 3 2");
        let e = operand(&text, "flip.obj", false).validate().unwrap_err();
        assert_eq!(
            e.to_string(),
            "flip.obj:12: face 3 uses edge 6->7 in the same direction as face 1 (line 10) \
             (the faces are not consistently oriented)"
        );
    }

    #[test]
    fn unwelded_file_gets_the_hint_and_welded_indices_map_back() {
        // every face with its own four vertices: 24 positions
        let m = parse_obj(CUBE, "c.obj").unwrap();
        let mut text = String::new();
        let mut faces = String::new();
        for (i, f) in m.faces.iter().enumerate() {
            for v in &f.vertices {
                let p = m.positions[*v as usize];
                text += &format!("v {} {} {}\n", p.x, p.y, p.z);
            }
            let k = 4 * i + 1;
            faces += &format!("f {} {} {} {}\n", k, k + 1, k + 2, k + 3);
        }
        let text = text + &faces;
        let e = operand(&text, "soup.obj", false).validate().unwrap_err();
        assert_eq!(
            e.to_string(),
            "soup.obj:25: edge 1-2 of face 0 is a boundary edge (the mesh is not closed); \
             if the file repeats vertices per face, try --weld"
        );
        operand(&text, "soup.obj", true).validate().unwrap();
        // with --weld, a defect is still reported with the file's indices
        let broken = text.replace("f 5 6 7 8\n", "");
        let e = operand(&broken, "soup.obj", true).validate().unwrap_err();
        assert_eq!(
            e.to_string(),
            "soup.obj:26: edge 11-12 of face 1 is a boundary edge (the mesh is not closed)"
        );
    }

    #[test]
    fn pinch_and_degenerate_faces() {
        // two cubes sharing only the corner (1, 1, 1), which --weld merges
        let two = cube(1.0, [0.0; 3]) + &cube(1.0, [1.0; 3]);
        operand(&two, "two.obj", false).validate().unwrap();
        let e = operand(&two, "pinch.obj", true).validate().unwrap_err();
        assert_eq!(
            e.to_string(),
            "pinch.obj:10: vertex 7 of face 1 joins separate fans of faces \
             (a pinch: the mesh is not a 2-manifold there)"
        );
        let e = operand(&CUBE.replace("f 1 4 3 2", "f 1 4 3 1"), "d.obj", false)
            .validate()
            .unwrap_err();
        assert_eq!(e.to_string(), "d.obj:9: face 0 repeats a vertex");
    }

    #[test]
    fn stl_defects_name_coordinates() {
        let m = parse_obj(CUBE, "c.obj").unwrap();
        let mut mesh = m.clone();
        for f in &mut mesh.faces {
            f.line = 0;
        }
        mesh.faces.remove(1);
        let o = Operand::new("open.stl".into(), mesh, None);
        assert_eq!(
            o.validate().unwrap_err().to_string(),
            "open.stl: edge (1, 0, 1)-(0, 0, 1) of face 1 is a boundary edge (the mesh is not closed)"
        );
        let mut mesh = o.mesh;
        mesh.faces[0].vertices = vec![0, 3, 0];
        let o = Operand::new("sliver.stl".into(), mesh, None);
        assert_eq!(
            o.validate().unwrap_err().to_string(),
            "sliver.stl: face 0 (0, 0, 0) (0, 1, 0) (0, 0, 0) repeats a vertex"
        );
    }

    #[test]
    fn overlapping_cubes_exactly() {
        let a = operand(&cube(4.0, [0.0; 3]), "a.obj", false);
        let b = operand(&cube(4.0, [2.0; 3]), "b.obj", false);
        for (op, vol) in [
            (Operation::Union, 120.0),
            (Operation::Intersection, 8.0),
            (Operation::Difference, 56.0),
        ] {
            let mut phases = Phases::default();
            let out = Outcome::new(&mut [a.clone(), b.clone()], op, &mut phases).unwrap();
            assert_eq!(exact_volume(&out.exact, &out.grid), vol, "{op:?}");
            let mesh = out.mesh().to_mesh();
            assert_eq!(mesh.signed_volume(), vol, "{op:?}");
            assert!(mesh.is_closed_oriented());
            assert_eq!(mesh.groups, vec![op.name()]);
            let names: Vec<&str> = phases.0.iter().map(|p| p.0).collect();
            assert_eq!(names, ["snap/import", "boolean", "boundary+mesh"]);
        }
        // disjoint: empty intersection
        let far = operand(&cube(1.0, [10.0; 3]), "far.obj", false);
        let out = Outcome::new(
            &mut [a, far],
            Operation::Intersection,
            &mut Phases::default(),
        )
        .unwrap();
        assert!(out.exact.triangles.is_empty() && out.positions.is_empty());
        assert_eq!(out.stats[0].cells, 0);
    }

    /// Three operands: an import report for each, the stats of each
    /// operation, the library's three phases timed, and every operand's
    /// mesh let go (handed over to the library).
    #[test]
    fn three_operands_report_each_import_and_operation() {
        let mut operands = [
            operand(&cube(4.0, [0.0; 3]), "a.obj", false),
            operand(&cube(4.0, [2.0; 3]), "b.obj", true),
            operand(&cube(4.0, [3.0, 1.0, -1.0]), "c.obj", false),
        ];
        let mut phases = Phases::default();
        let out = Outcome::new(&mut operands, Operation::Difference, &mut phases).unwrap();
        // 64 − 8 − (the part of c in a but not in b: 1·3·3 − 1·2·1)
        assert_eq!(exact_volume(&out.exact, &out.grid), 49.0);
        assert_eq!(out.reports.len(), 3);
        assert!(out.reports.iter().all(|r| r.polygons == 6));
        assert_eq!(out.stats.len(), 2);
        assert!(out.stats.iter().all(|s| s.mixed_cells > 0));
        let names: Vec<&str> = phases.0.iter().map(|p| p.0).collect();
        assert_eq!(names, ["snap/import", "boolean", "boundary+mesh"]);
        for o in &operands {
            assert!(o.mesh.positions.is_empty() && o.mesh.faces.is_empty());
            assert!(o.file_loops.is_none());
            assert_eq!(o.counts, (12, 6));
        }
    }

    #[test]
    fn exact_volume_scales_by_the_grid() {
        // a 3/4-unit cube at 1/8 offsets: the grid is finer than 1, so the
        // exact volume is divided by a power of two
        let a = operand(&cube(0.75, [0.125; 3]), "a.obj", false);
        let b = operand(&cube(0.75, [0.5; 3]), "b.obj", false);
        let out = Outcome::new(&mut [a, b], Operation::Union, &mut Phases::default()).unwrap();
        assert!(out.grid.scale() > 1.0);
        assert_eq!(
            exact_volume(&out.exact, &out.grid),
            2.0 * 0.421875 - 0.052734375
        );
        // a coarse grid (scale < 1) multiplies instead
        let a = operand(&cube(4e9, [0.0; 3]), "a.obj", false);
        let b = operand(&cube(4e9, [2e9; 3]), "b.obj", false);
        let out =
            Outcome::new(&mut [a, b], Operation::Intersection, &mut Phases::default()).unwrap();
        assert!(out.grid.scale() < 1.0);
        assert_eq!(exact_volume(&out.exact, &out.grid), 8e27);
    }

    #[test]
    fn exact_volume_agrees_with_the_kernel() {
        // tilted planes make implicit vertices with many denominators
        let tet = |d: [f64; 3]| {
            let v = [
                [0.0, 0.0, 0.0],
                [3.0, 0.2, 0.1],
                [0.3, 2.9, 0.7],
                [0.4, 0.5, 3.1],
            ];
            let mut t = String::new();
            for p in v {
                t += &format!("v {} {} {}\n", p[0] + d[0], p[1] + d[1], p[2] + d[2]);
            }
            t + "f -4 -2 -3\nf -4 -3 -1\nf -4 -1 -2\nf -3 -2 -1\n"
        };
        let a = operand(&tet([0.0; 3]), "a.obj", false);
        let b = operand(&tet([0.7, 0.6, 0.5]), "b.obj", false);
        let c = operand(&cube(1.3, [0.45, 0.35, 0.25]), "c.obj", false);
        a.validate().unwrap();
        for (x, y, op) in [
            (&a, &b, Operation::Union),
            (&a, &b, Operation::Intersection),
            (&a, &b, Operation::Difference),
            (&a, &c, Operation::Difference),
            (&c, &b, Operation::Union),
        ] {
            let out =
                Outcome::new(&mut [x.clone(), y.clone()], op, &mut Phases::default()).unwrap();
            assert!(out.exact.vertices.iter().any(|p| p.as_grid().is_none()));
            // the cheap rounding is the exact fraction's, rounded once
            let exact = out.exact.volume_exact();
            let k = out.grid.scale().log2() as i32;
            let scaled = if k >= 0 {
                exact / BigRational::from_integer(BigInt::one() << (3 * k) as usize)
            } else {
                exact * BigRational::from_integer(BigInt::one() << (-3 * k) as usize)
            };
            assert_eq!(
                exact_volume(&out.exact, &out.grid),
                scaled.to_f64().unwrap(),
                "{op:?}"
            );
            assert!(exact_volume(&out.exact, &out.grid) > 0.0);
        }
        assert_eq!(
            TriMesh::default().six_volume(),
            (BigInt::zero(), BigInt::one())
        );
    }

    #[test]
    fn inward_faces_are_rejected() {
        let mut inside_out = String::new();
        for l in CUBE.lines() {
            match l.strip_prefix("f ") {
                Some(f) => {
                    let mut v: Vec<&str> = f.split(' ').collect();
                    v.reverse();
                    inside_out += &format!("f {}\n", v.join(" "));
                }
                None => inside_out += &format!("{l}\n"),
            }
        }
        let a = operand(&inside_out, "inv.obj", false);
        a.validate().unwrap();
        let b = operand(CUBE, "b.obj", false);
        let e = Outcome::new(&mut [a, b], Operation::Union, &mut Phases::default())
            .err()
            .unwrap();
        assert!(
            e.to_string()
                .starts_with("inv.obj: the faces are oriented inward"),
            "{e}"
        );
    }

    #[test]
    fn overlapping_shells_in_one_file_are_rejected() {
        // two closed cubes that overlap, in one file: each is a closed
        // manifold, but together they bound no solid (winding number 2
        // where they overlap); the other operand's surface crosses there
        let shells = cube(4.0, [0.0; 3]) + &cube(4.0, [2.0; 3]);
        let a = operand(&shells, "shells.obj", false);
        a.validate().unwrap();
        let b = operand(&cube(3.0, [2.5, -0.5, 1.5]), "b.obj", false);
        for op in [
            Operation::Union,
            Operation::Intersection,
            Operation::Difference,
        ] {
            let e = Outcome::new(&mut [a.clone(), b.clone()], op, &mut Phases::default())
                .err()
                .unwrap();
            assert!(e.to_string().contains("crosses itself"), "{op:?}: {e}");
        }
    }

    #[test]
    fn guarded_turns_a_panic_into_an_error() {
        let e = guarded("both input files", || -> Result<()> {
            panic!("inconsistent sub-hyperplanes")
        })
        .unwrap_err();
        let s = e.to_string();
        assert!(
            s.starts_with("internal error: inconsistent sub-hyperplanes ("),
            "{s}"
        );
        assert!(s.contains("csg.rs:"), "{s}");
        assert!(s.ends_with("please report it with both input files"), "{s}");
        assert_eq!(guarded("x", || Ok(7)).unwrap(), 7);
    }
}
