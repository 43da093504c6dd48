//! Booleans of meshes read from files, with messages that point into the
//! files: the file, line, face and vertex of a topology error, and the
//! file whose surface bounds no solid.
//!
//! A reader's [`Mesh`] goes in as an [`Operand`]; [`Operand::check_all`]
//! checks them; [`FileBoolean::apply`] snaps every operand to one grid, applies the operation to
//! the first with each of the others in turn ([`mesh_sequence_with`]) and
//! gives the exact result with its vertices in input units, ready for a
//! writer ([`FileBoolean::mesh`]).
//!
//! ```
//! use bsp_core::BoolOp;
//! use bsp_csg::files::{FileBoolean, Operand};
//! let cube = shadow_scene::scene("cube").unwrap();
//! let mut moved = cube.clone();
//! moved.positions.iter_mut().for_each(|p| *p += 0.5);
//! let mut operands = [Operand::new("a.obj", cube), Operand::new("b.obj", moved)];
//! let checked = Operand::check_all(&mut operands).unwrap();
//! let union = FileBoolean::apply(checked, BoolOp::Union, |_, _| {}).unwrap();
//! assert_eq!(union.volume(), 2.0 - 0.125);
//! ```

use std::time::{Duration, Instant};

use bsp_core::par;
use bsp_core::{BoolOp, Grid, ImportReport, TopologyError, TriMesh};
use glam::DVec3;
use shadow_scene::{Mesh, MeshView, Triangles};

use crate::{CsgError, MeshBuf, MeshIn, SequenceError, Stage, Step, mesh_sequence_with};

/// A mesh read from a file, with what messages need to point into it.
#[derive(Clone, Debug)]
pub struct Operand {
    /// The file, as given: messages name it.
    pub name: String,
    /// The mesh; [`FileBoolean::apply`] takes it when its turn comes.
    pub mesh: Mesh,
    /// Triangles and faces as read.
    pub counts: (usize, usize),
    /// The faces' vertex loops as in the file, kept when
    /// [`Operand::welded`] renumbered them, so that messages quote the
    /// file's indices.
    file_loops: Option<Vec<Vec<u32>>>,
    /// Faces that welding collapsed and left out (see
    /// [`Operand::welded`]).
    pub collapsed: usize,
}

/// An operand's or the operation's error, worded to point into the files.
#[derive(Clone, Debug, PartialEq)]
pub struct FileError {
    /// The message: `file:line: what`, or `file: what`.
    pub message: String,
    /// A topology error of a mesh that was not welded and repeats
    /// positions: merging equal positions first may mend it.
    pub weld_may_help: bool,
    /// A surface crosses itself once snapped: the operands it may be
    /// (their indices) and the grid, for [`find_crossing`] to say where.
    pub crossing: Option<(Vec<usize>, Grid)>,
}

impl std::fmt::Display for FileError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for FileError {}

impl FileError {
    /// Where a surface crosses itself, for an error that says one does
    /// ([`FileError::crossing`]): the operands it may be are read again
    /// from their `names` (the paths they were read from) and searched
    /// ([`find_crossing`]); `name: faces … cross near …`.
    pub fn locate_crossing(&self, names: &[String]) -> Option<String> {
        let (operands, grid) = self.crossing.as_ref()?;
        operands.iter().find_map(|&i| {
            let mesh = shadow_scene::load(std::path::Path::new(names.get(i)?)).ok()?;
            find_crossing(&mesh, grid).map(|c| format!("{}: {c}", names[i]))
        })
    }

    fn new(message: String) -> FileError {
        FileError {
            message,
            weld_may_help: false,
            crossing: None,
        }
    }
}

impl Operand {
    /// The operands named in words: "a alone", "a and b", "a and 2 more".
    pub fn names(operands: &[Operand]) -> String {
        match operands {
            [a] => format!("{} alone", a.name),
            [a, b] => format!("{} and {}", a.name, b.name),
            [first, rest @ ..] => format!("{} and {} more", first.name, rest.len()),
            [] => String::new(),
        }
    }

    /// `mesh`, read from file `name`.
    pub fn new(name: impl Into<String>, mesh: Mesh) -> Operand {
        Operand {
            name: name.into(),
            counts: (mesh.triangle_count(), mesh.faces.len()),
            mesh,
            file_loops: None,
            collapsed: 0,
        }
    }

    /// `mesh` with vertices at exactly equal positions merged (for files
    /// that repeat the vertices of every face); messages still quote the
    /// file's vertex indices.
    ///
    /// A face whose corners merge ([`Mesh::collapse_repeats`]: a sliver
    /// whose vertices a writer rounded to one position) loses the corners
    /// that repeat, and is left out if fewer than three remain; their
    /// number is [`Operand::collapsed`]. The check that follows tells
    /// whether the surface is still closed.
    pub fn welded(name: impl Into<String>, mesh: Mesh) -> Operand {
        Operand::welded_named(name.into(), mesh)
    }

    /// [`Operand::welded`], compiled here (a generic body would be
    /// compiled, with its loops, in the caller's crate and build settings).
    fn welded_named(name: String, mut mesh: Mesh) -> Operand {
        let counts = (mesh.triangle_count(), mesh.faces.len());
        let mut loops: Vec<Vec<u32>> = mesh.faces.iter().map(|f| f.vertices.clone()).collect();
        mesh.weld();
        let dropped = mesh.collapse_repeats();
        for &f in dropped.iter().rev() {
            loops.remove(f);
        }
        Operand {
            name,
            counts,
            mesh,
            file_loops: Some(loops),
            collapsed: dropped.len(),
        }
    }

    /// Checks that the faces form a closed, consistently oriented
    /// 2-manifold, or at least a closed cycle (resolved when snapped); the
    /// error names the file, line, face and edge (the check of
    /// [`crate::check_mesh`], on the faces as they are).
    ///
    /// A mesh so large that its volume overflows `f64` is an error too. A
    /// mesh with no faces is the empty solid (a Boolean's empty result,
    /// written and read back, is an operand again).
    pub fn check(&self) -> Result<(), FileError> {
        self.check_faces()?;
        let loops = || self.mesh.faces.iter().map(|f| f.vertices.as_slice());
        match bsp_core::check_closed_manifold(loops()) {
            // resolved when snapped (see `crate::check_mesh`)
            Err(_) if bsp_core::is_closed_cycle(loops()) => Ok(()),
            checked => checked,
        }
        .map_err(|e| FileError {
            message: self.topology_message(&e),
            weld_may_help: self.file_loops.is_none() && self.mesh.repeated_positions() > 0,
            crossing: None,
        })
    }

    /// The part of [`Operand::check`] that needs no topology: the mesh's
    /// volume fits in `f64` (a mesh with no faces, the empty solid, has
    /// none).
    pub fn check_faces(&self) -> Result<(), FileError> {
        let Some((lo, hi)) = self.mesh.bounds().filter(|_| !self.mesh.faces.is_empty()) else {
            return Ok(());
        };
        let extent = (hi - lo).max_element();
        if !(extent * extent * extent).is_finite() {
            return Err(FileError::new(format!(
                "{}: the mesh spans {extent:.3e} units, so its volume does not fit in f64; \
                 scale it below about 1e100",
                self.name
            )));
        }
        Ok(())
    }

    /// [`Operand::check`] of each operand, in parallel; the first error
    /// in their order. The operands checked are what
    /// [`FileBoolean::apply`] takes.
    pub fn check_all(operands: &mut [Operand]) -> Result<Checked<'_>, FileError> {
        let checked: Vec<Result<(), FileError>> = par::map_slice(operands, Operand::check);
        checked.into_iter().collect::<Result<(), FileError>>()?;
        Ok(Checked(operands))
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
                let (a, b) = (v(face, a), v(face, b));
                let what = format!(
                    "face {face} uses edge {a}->{b} in the same direction as face \
                     {first}{first_at} (the faces are not consistently oriented)"
                );
                (Some(face), what)
            }
            TopologyError::NonManifoldEdge { a, b, face, .. } => (
                Some(face),
                format!(
                    "edge {}-{} of face {face} is shared by more than two faces (the mesh is \
                     not a 2-manifold)",
                    v(face, a),
                    v(face, b)
                ),
            ),
            TopologyError::DegenerateFace { face } => {
                let f = &self.mesh.faces[face];
                // without a line to look at, show the corners
                let corners: String = match f.line {
                    0 => f
                        .vertices
                        .iter()
                        .map(|&x| format!(" {}", v(face, x)))
                        .collect(),
                    _ => String::new(),
                };
                let welded = match self.file_loops {
                    Some(_) => " (after welding merged equal positions)",
                    None => "",
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
                        "vertex {} of face {face} joins separate fans of faces (a pinch: the \
                         mesh is not a 2-manifold there)",
                        v(face, vertex)
                    ),
                    None => e.to_string(),
                };
                (face, what)
            }
            _ => (None, e.to_string()),
        };
        let at = face.map_or_else(|| self.name.clone(), |f| self.locate(f));
        format!("{at}: {what}")
    }

    /// The mesh as the library takes it: the positions and the face lists
    /// moved out (not copied), the rest of the mesh let go.
    fn hand_over(&mut self) -> MeshBuf {
        self.file_loops = None;
        let mesh = std::mem::take(&mut self.mesh);
        let faces = mesh.faces.into_iter().map(|f| f.vertices).collect();
        MeshBuf::new(mesh.positions, faces)
    }
}

/// Operands that passed [`Operand::check_all`]: closed, consistently
/// oriented 2-manifolds.
#[derive(Debug)]
pub struct Checked<'a>(&'a mut [Operand]);

/// A Boolean operation of files: the exact result, its vertices in input
/// units, and what each step reported.
#[derive(Clone, Debug)]
pub struct FileBoolean {
    /// The result's vertices in input units (its triangles are `exact`'s).
    pub positions: Vec<DVec3>,
    /// The exact result (grid units).
    pub exact: TriMesh,
    /// The grid every operand was snapped to.
    pub grid: Grid,
    /// What snapping did to each operand's faces.
    pub reports: Vec<ImportReport>,
    /// What each operation did.
    pub stats: Vec<crate::Stats>,
    /// The operation's name, the result's one group.
    pub group: &'static str,
    /// The wall time of each kind of stage.
    pub times: StageTimes,
}

/// The wall time of each kind of stage of a [`FileBoolean::apply`],
/// summed over the operands; `None` for a stage that did not run.
#[derive(Clone, Copy, Debug, Default)]
pub struct StageTimes {
    /// Snapping the operands to the grid (their solids).
    pub snap: Option<Duration>,
    /// The operations.
    pub operations: Option<Duration>,
    /// The result's mesh, to its positions in input units.
    pub mesh: Option<Duration>,
    /// The stage running, and since when.
    running: Option<(Stage, Instant)>,
}

impl StageTimes {
    /// Stage `stage` starts (the one running, if any, is over).
    fn start(&mut self, stage: Stage) {
        self.stop();
        self.running = Some((stage, Instant::now()));
    }

    /// The running stage is over: its time is added to its kind's.
    fn stop(&mut self) {
        let Some((stage, since)) = self.running.take() else {
            return;
        };
        let kind = match stage {
            Stage::Snap(_) => &mut self.snap,
            Stage::Operation(_) => &mut self.operations,
            Stage::Mesh => &mut self.mesh,
        };
        *kind = Some(kind.unwrap_or_default() + since.elapsed());
    }
}

impl FileBoolean {
    /// `op` applied to the first operand with each of the others in turn
    /// ([`mesh_sequence_with`]), all snapped to one grid. Each operand's
    /// mesh is handed over when its turn comes and let go once snapped;
    /// `on_step` sees every step as the library reports it, with the grid
    /// (to time the stages or to print an import summary).
    pub fn apply(
        operands: Checked<'_>,
        op: BoolOp,
        mut on_step: impl FnMut(&Step, &Grid),
    ) -> Result<FileBoolean, FileError> {
        FileBoolean::apply_dyn(operands, op, &mut on_step)
    }

    /// [`FileBoolean::apply`], compiled here, optimised, whatever crate
    /// calls it (a generic body is compiled in the caller's crate).
    fn apply_dyn(
        operands: Checked<'_>,
        op: BoolOp,
        on_step: &mut dyn FnMut(&Step, &Grid),
    ) -> Result<FileBoolean, FileError> {
        let operands = operands.0;
        let grid = {
            let meshes: Vec<MeshIn<'_>> = operands
                .iter()
                // (an empty solid's stray vertices are no part of it)
                .map(|o| match o.mesh.faces.is_empty() {
                    true => MeshIn::new(&[], &[]),
                    false => MeshIn::new(&o.mesh.positions, &[]),
                })
                .collect();
            crate::fit_grid(&meshes)
                .map_err(|e| FileError::new(format!("cannot snap the faces to one grid: {e}")))?
        };
        let names: Vec<String> = operands.iter().map(|o| o.name.clone()).collect();
        let mut meshes = operands.iter_mut().map(Operand::hand_over);
        let Some(first) = meshes.next() else {
            return Err(FileError::new("no operand".to_string()));
        };
        let rest = meshes.map(|m| (op, m));
        let (mut reports, mut stats) = (Vec::new(), Vec::new());
        let mut times = StageTimes::default();
        let exact = mesh_sequence_with(&grid, first, rest, |step| {
            on_step(&step, &grid);
            match step {
                Step::Started(stage) => times.start(stage),
                // (the mesh's stage goes on through the positions below)
                Step::Finished(Stage::Mesh) => {}
                Step::Finished(_) => times.stop(),
                Step::Snapped { report, .. } => reports.push(report),
                Step::Planned { stats: s, .. } => stats.push(s),
            }
        })
        .map_err(|e| sequence_error(e, &names, op, &grid))?;
        let positions = par::map_vec(exact.vertices_f64(), |v| grid.to_world(v));
        times.stop();
        Ok(FileBoolean {
            times,
            positions,
            exact,
            grid,
            reports,
            stats,
            group: op_name(op),
        })
    }

    /// The result in input units, as a writer takes it: its triangles
    /// beside their positions, one group named after the operation.
    pub fn mesh(&self) -> Triangles<'_> {
        Triangles {
            positions: &self.positions,
            triangles: &self.exact.triangles,
            group: self.group,
        }
    }

    /// The figures for people, one per line: each operand as read and
    /// imported, the grid step, the octree, the result and its `volume`
    /// (exact, rounded once; [`FileBoolean::volume`], which the caller may
    /// want to time) beside the plain `f64` sum.
    pub fn report(&self, operands: &[Operand], volume: f64) -> String {
        let mut s = String::new();
        for (i, (o, r)) in operands.iter().zip(&self.reports).enumerate() {
            let label = match i {
                0 => "A".to_string(),
                1 if operands.len() == 2 => "B".to_string(),
                i => format!("{}", i + 1),
            };
            s += &format!(
                "input {label}:{:pad$}{}: {} triangles ({} faces), {}\n",
                "",
                o.name,
                o.counts.0,
                o.counts.1,
                r.counts(),
                pad = 9usize.saturating_sub(label.len())
            );
        }
        let k = self.grid.scale();
        let sum: crate::Stats = self.stats.iter().sum();
        s += &format!("grid step:      {}\n", self.grid.step_text());
        s += &format!("octree:         {sum}\n");
        s += &format!(
            "output:         {} triangles, {} vertices\n",
            self.exact.triangles.len(),
            self.positions.len()
        );
        s += &format!(
            "volume:         {volume} (exact, rounded once); {} (f64 sum)\n",
            self.exact.volume_f64() / (k * k * k)
        );
        s
    }

    /// The result as a file holds it where rounding its exact vertices
    /// to `f64` (or for `stl`, to `f32`) makes distinct ones equal or
    /// puts three corners of a triangle on one line: welded, with the
    /// faces that collapse left out ([`Mesh::collapse_repeats`]) and the
    /// flat triangles split away ([`Mesh::split_flat_triangles`]), so
    /// that a reader that welds by position finds no face repeating a
    /// vertex and no face without area. Where welding would pinch the
    /// surface (two sheets closer than the format resolves), vertices are
    /// kept apart and off one line instead, one step of the format off
    /// their rounded position ([`Mesh::round_closed`]). `None`
    /// where rounding does nothing of this (the file is
    /// [`FileBoolean::mesh`] as it is).
    pub fn rounded(&self, stl: bool) -> Option<Rounded> {
        let view = self.mesh();
        let coincide = match stl {
            true => shadow_scene::stl_collisions(&view),
            false => view.repeated_positions(),
        };
        let round: fn(DVec3) -> DVec3 = match stl {
            true => shadow_scene::to_f32,
            false => |p| p,
        };
        if coincide == 0 && view.flat_triangles(round) == 0 {
            return None;
        }
        let step = match stl {
            true => shadow_scene::f32_step,
            false => shadow_scene::f64_step,
        };
        let mut mesh = view.to_mesh();
        let (r, closed) = mesh.round_closed(round, step);
        Some(Rounded {
            mesh,
            collapsed: r.collapsed,
            flattened: r.flattened,
            moved: r.moved,
            closed,
            shared: coincide,
        })
    }

    /// The exact volume in input units, rounded once to `f64`.
    pub fn volume(&self) -> f64 {
        // the scale is a power of two: the division is exact
        self.exact.volume_rounded() / self.grid.scale().powi(3)
    }
}

/// A result as a file holds it once rounded ([`FileBoolean::rounded`]).
#[derive(Clone, Debug)]
pub struct Rounded {
    /// The mesh to write.
    pub mesh: Mesh,
    /// Faces that rounding collapsed, left out.
    pub collapsed: usize,
    /// Triangles that rounding made flat (three corners on one line),
    /// split away: the face across each one's long edge is cut at its
    /// middle corner, so the surface stays closed.
    pub flattened: usize,
    /// Vertices moved one step of the format off their rounded position
    /// to keep the surface from pinching or a triangle from going flat.
    pub moved: usize,
    /// Whether the mesh is still closed and oriented by vertex index,
    /// with no flat triangle (where a collapsed edge's ends had other
    /// neighbours in common and no vertex could be kept apart, it is not).
    pub closed: bool,
    /// Vertices of the result that shared their rounded position with
    /// another before anything was done (where the solid touches itself,
    /// as two cubes meeting at a corner, they share it exactly).
    pub shared: usize,
}

impl Rounded {
    /// What rounding did, as a note (the file is closed as read back) or
    /// a warning (it is not); `stl`: rounded to `f32`.
    pub fn message(&self, stl: bool) -> String {
        let to = if stl { "f32 for STL" } else { "f64" };
        let mut did = Vec::new();
        if self.collapsed > 0 {
            did.push(format!(
                "made distinct vertices equal ({} collapsed triangle(s) left out)",
                self.collapsed
            ));
        }
        if self.flattened > 0 {
            did.push(format!(
                "put the corners of {} triangle(s) on one line (split away: the face across \
                 each long edge is cut at the middle corner)",
                self.flattened
            ));
        }
        if self.moved > 0 {
            did.push(format!(
                "would have pinched the surface or flattened triangles at {} vertex(es) (each \
                 kept apart, one {} step off)",
                self.moved,
                if stl { "f32" } else { "f64" }
            ));
        }
        if did.is_empty() {
            // (only positions shared where the solid touches itself)
            did.push(format!(
                "keeps {} vertex(es) that share a position with another (where the solid \
                 touches itself), each a vertex of its own",
                self.shared
            ));
        }
        let did = did.join(" and ");
        match (self.closed, stl) {
            (true, _) => format!("note: rounding to {to} {did}; the file is closed as read back"),
            (false, true) => format!(
                "warning: rounding to {to} {did}; the file is not closed as read back (write \
                 .obj to keep full precision)"
            ),
            (false, false) => {
                format!("warning: rounding to {to} {did}; the file is not closed as read back")
            }
        }
    }
}

/// Has glibc keep the large blocks a run frees, to be used again, instead
/// of unmapping each one and faulting the next one in page by page: freeing
/// one untouched block just under 32 MiB raises glibc's dynamic mmap
/// threshold at once (mallopt(3)). `docs/bench-csg.md` has the
/// measurement; other allocators see one allocation made and freed. A
/// program that runs a large Boolean calls it once, first.
pub fn keep_freed_blocks() {
    // (two pages under 32 MiB: with glibc's header the mapped block is one
    // page under, within the largest threshold glibc raises to; where even
    // that much address space is refused, nothing is done)
    let mut block: Vec<u8> = Vec::new();
    if block.try_reserve_exact((32 << 20) - 8192).is_ok() {
        // (kept from being optimized away: the allocation is the point)
        drop(std::hint::black_box(block));
    }
}

/// "union", "intersection" or "difference".
pub fn op_name(op: BoolOp) -> &'static str {
    match op {
        BoolOp::Union => "union",
        BoolOp::Intersection => "intersection",
        BoolOp::Difference => "difference",
    }
}

/// The message for an operation that failed at `e.stage`, naming the
/// file it comes from.
fn sequence_error(e: SequenceError, names: &[String], op: BoolOp, grid: &Grid) -> FileError {
    let crossing = match (e.stage, &e.error) {
        (Stage::Operation(1), CsgError::NotASolid) => Some(vec![1, 0]),
        (Stage::Operation(i), CsgError::NotASolid) => Some(vec![i]),
        // the result of the operands before `i`, made by operations
        (Stage::Operation(i), CsgError::TooLargeToResolve { .. }) => Some((0..i).collect()),
        (Stage::Snap(i), CsgError::TooLargeToResolve { .. }) => Some(vec![i]),
        _ => None,
    };
    let message = match (e.stage, e.error) {
        (Stage::Snap(i), CsgError::Inward { .. }) => format!(
            "{}: the faces are oriented inward (clockwise seen from outside): the solid they \
             bound is unbounded; reverse every face's vertex order",
            names[i]
        ),
        (Stage::Snap(_), CsgError::Grid(e)) => format!("cannot snap the faces to one grid: {e}"),
        (
            Stage::Snap(i),
            CsgError::Collapsed {
                faces, step_log2, ..
            },
        ) => {
            format!(
                "{}: {}",
                names[i],
                crate::error::collapsed_text(faces, step_log2)
            )
        }
        (Stage::Operation(i), CsgError::NotASolid) => format!(
            "{} or the result before it: a surface crosses itself after snapping to the \
             grid (step 2^{}) and bounds no solid",
            names[i],
            grid.step_log2()
        ),
        // the mesh is checked watertight as it is made (one check, the
        // one that tells whether it needs mending where the solid touches
        // itself)
        (Stage::Mesh, e) => {
            let e = match e {
                CsgError::Internal(why) => why,
                e => e.to_string(),
            };
            format!(
                "internal error: the {} of {} is not watertight ({e}); this is a bug in the \
                 exact kernel, not a problem with the input, and nothing was written — please \
                 report it with the input files",
                op_name(op),
                names.join(", ")
            )
        }
        (_, e) => e.to_string(),
    };
    FileError {
        crossing: crossing.map(|c| (c, *grid)),
        ..FileError::new(message)
    }
}

/// Two faces of a mesh that cross once snapped to a grid (or touch in a
/// way the certificate cannot settle), and a point near where they meet.
#[derive(Clone, Debug, PartialEq)]
pub struct Crossing {
    /// The faces (indices into the mesh's faces).
    pub faces: [usize; 2],
    /// Their lines in the file (0 for generated faces).
    pub lines: [usize; 2],
    /// A point where they meet, in input units (rounded: for a message).
    pub point: DVec3,
}

impl std::fmt::Display for Crossing {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [a, b] = self.faces;
        let [la, lb] = self.lines;
        let p = self.point;
        write!(
            f,
            "faces {a} (line {la}) and {b} (line {lb}) cross near {:.6},{:.6},{:.6}",
            p.x, p.y, p.z
        )
    }
}

/// Where `mesh`, snapped to `grid`, crosses itself: two faces that the
/// culling certificate ([`bsp_core::certify_solid_boundary`]) finds
/// meeting other than in shared vertices and edges, and a point near
/// their meeting. `None` if it finds no such pair (or the faces do not
/// fit the grid).
pub fn find_crossing(mesh: &Mesh, grid: &Grid) -> Option<Crossing> {
    let loops = mesh.face_loops();
    let (polys, _) = bsp_core::import_faces_par(grid, &loops).ok()?;
    let Err(bsp_core::SurfaceDefect::Intersecting { polygons: [i, j] }) =
        bsp_core::certify_solid_boundary(&polys)
    else {
        return None;
    };
    let faces = [polys[i].tag() as usize, polys[j].tag() as usize];
    let ring = |p: &bsp_core::Polygon| -> Vec<DVec3> {
        p.vertices_f64()
            .into_iter()
            .map(|v| grid.to_world(v))
            .collect()
    };
    let (a, b) = (ring(&polys[i]), ring(&polys[j]));
    let point = meeting_point(&a, &b)
        .or_else(|| meeting_point(&b, &a))
        .unwrap_or_else(|| (centre(&a) + centre(&b)) * 0.5);
    Some(Crossing {
        faces,
        lines: faces.map(|f| mesh.faces[f].line),
        point,
    })
}

fn centre(ring: &[DVec3]) -> DVec3 {
    ring.iter().sum::<DVec3>() / ring.len().max(1) as f64
}

/// A point where an edge of convex polygon `a` passes through convex
/// polygon `b` (`f64`, for a message).
fn meeting_point(a: &[DVec3], b: &[DVec3]) -> Option<DVec3> {
    let normal = (1..b.len().saturating_sub(1))
        .map(|k| (b[k] - b[0]).cross(b[k + 1] - b[0]))
        .sum::<DVec3>();
    let side = |p: DVec3| normal.dot(p - b[0]);
    (0..a.len()).find_map(|k| {
        let (p, q) = (a[k], a[(k + 1) % a.len()]);
        let (sp, sq) = (side(p), side(q));
        if sp * sq > 0.0 || sp == sq {
            return None;
        }
        let x = p + (q - p) * (sp / (sp - sq));
        // inside b: on the inner side of every edge, seen along the normal
        let inside = (0..b.len()).all(|m| {
            let (u, v) = (b[m], b[(m + 1) % b.len()]);
            (v - u).cross(x - u).dot(normal) >= 0.0
        });
        inside.then_some(x)
    })
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
        let mesh = parse_obj(text, name).unwrap();
        match weld {
            true => Operand::welded(name, mesh),
            false => Operand::new(name, mesh),
        }
    }

    /// The operation of `operands` after their check, and the stages it
    /// went through in order (each once).
    fn apply_staged(
        operands: &mut [Operand],
        op: BoolOp,
    ) -> Result<(FileBoolean, Vec<&'static str>), FileError> {
        let mut stages: Vec<&'static str> = Vec::new();
        let out = FileBoolean::apply(Operand::check_all(operands)?, op, |step, _| {
            if let Step::Started(stage) = step {
                let name = match stage {
                    Stage::Snap(_) => "snap/import",
                    Stage::Operation(_) => "boolean",
                    Stage::Mesh => "boundary+mesh",
                };
                if !stages.contains(&name) {
                    stages.push(name);
                }
            }
        })?;
        Ok((out, stages))
    }

    fn apply(operands: &mut [Operand], op: BoolOp) -> Result<FileBoolean, FileError> {
        apply_staged(operands, op).map(|(out, _)| out)
    }

    const STAGES: [&str; 3] = ["snap/import", "boolean", "boundary+mesh"];

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

    /// A solid smaller than a step of the grid all the operands share is
    /// an error, not the empty set (a unit cube beside one 10^15 away
    /// gave an empty union).
    #[test]
    fn an_operand_the_grid_cannot_hold_is_an_error() {
        let mut operands = [
            operand(&cube(1.0, [0.0; 3]), "near.obj", false),
            operand(&cube(1.0, [1e15; 3]), "far.obj", false),
        ];
        let e = apply(&mut operands, BoolOp::Union)
            .err()
            .unwrap()
            .to_string();
        assert!(
            e.starts_with("near.obj: all 6 faces have no area on the grid the operands share"),
            "{e}"
        );
    }

    #[test]
    fn open_mesh_names_line_face_and_file_indices() {
        // drop the top face (line 10)
        let text: String = CUBE
            .lines()
            .filter(|l| *l != "f 5 6 7 8")
            .map(|l| format!("{l}\n"))
            .collect();
        let e = operand(&text, "open.obj", false).check().unwrap_err();
        assert_eq!(
            e.to_string(),
            "open.obj:10: edge 6-5 of face 1 is a boundary edge (the mesh is not closed)"
        );
    }

    #[test]
    fn misoriented_face_names_both_faces() {
        let text = CUBE.replace("f 2 3 7 6", "f 6 7 3 2");
        let e = operand(&text, "flip.obj", false).check().unwrap_err();
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
        let e = operand(&text, "soup.obj", false).check().unwrap_err();
        assert_eq!(
            e.to_string(),
            "soup.obj:25: edge 1-2 of face 0 is a boundary edge (the mesh is not closed)"
        );
        assert!(e.weld_may_help);
        operand(&text, "soup.obj", true).check().unwrap();
        // with --weld, a defect is still reported with the file's indices
        let broken = text.replace("f 5 6 7 8\n", "");
        let e = operand(&broken, "soup.obj", true).check().unwrap_err();
        assert_eq!(
            e.to_string(),
            "soup.obj:26: edge 11-12 of face 1 is a boundary edge (the mesh is not closed)"
        );
    }

    #[test]
    fn pinch_and_degenerate_faces() {
        // two cubes sharing only the corner (1, 1, 1), which --weld merges
        let two = cube(1.0, [0.0; 3]) + &cube(1.0, [1.0; 3]);
        operand(&two, "two.obj", false).check().unwrap();
        // welded, a closed cycle but no manifold: accepted, and resolved
        // to the two cubes (the union of one; its mesh keeps the corner
        // apart, one vertex for each cube)
        let pinch = operand(&two, "pinch.obj", true);
        pinch.check().unwrap();
        let out = apply(&mut [pinch], BoolOp::Union).unwrap();
        assert_eq!(out.volume(), 2.0);
        assert!(out.mesh().to_mesh().is_closed_oriented());
        // a face turned the other way is no closed cycle: still an error
        let turned = CUBE.replace("f 1 4 3 2", "f 1 2 3 4");
        let e = operand(&turned, "turned.obj", false).check().unwrap_err();
        assert!(e.to_string().contains("not consistently oriented"), "{e}");
        let e = operand(&CUBE.replace("f 1 4 3 2", "f 1 4 3 1"), "d.obj", false)
            .check()
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
        let o = Operand::new("open.stl", mesh);
        assert_eq!(
            o.check().unwrap_err().to_string(),
            "open.stl: edge (1, 0, 1)-(0, 0, 1) of face 1 is a boundary edge (the mesh is not closed)"
        );
        let mut mesh = o.mesh;
        mesh.faces[0].vertices = vec![0, 3, 0];
        let o = Operand::new("sliver.stl", mesh);
        assert_eq!(
            o.check().unwrap_err().to_string(),
            "sliver.stl: face 0 (0, 0, 0) (0, 1, 0) (0, 0, 0) repeats a vertex"
        );
    }

    /// Cubes meeting at one corner: the union's two corners there share
    /// their position, and rounding has nothing else to do: the note says
    /// so (it said "rounding to f64 ;" before).
    #[test]
    fn cubes_meeting_at_a_corner_note_their_shared_position() {
        let a = operand(&cube(1.0, [0.0; 3]), "a.obj", false);
        let b = operand(&cube(1.0, [1.0; 3]), "b.obj", false);
        let out = apply(&mut [a, b], BoolOp::Union).unwrap();
        let r = out.rounded(false).unwrap();
        assert_eq!((r.collapsed, r.flattened, r.moved, r.shared), (0, 0, 0, 1));
        assert_eq!(
            r.message(false),
            "note: rounding to f64 keeps 1 vertex(es) that share a position with another \
             (where the solid touches itself), each a vertex of its own; the file is closed as \
             read back"
        );
    }

    #[test]
    fn overlapping_cubes_exactly() {
        let a = operand(&cube(4.0, [0.0; 3]), "a.obj", false);
        let b = operand(&cube(4.0, [2.0; 3]), "b.obj", false);
        for (op, vol) in [
            (BoolOp::Union, 120.0),
            (BoolOp::Intersection, 8.0),
            (BoolOp::Difference, 56.0),
        ] {
            let (out, stages) = apply_staged(&mut [a.clone(), b.clone()], op).unwrap();
            assert_eq!(stages, STAGES);
            assert_eq!(out.volume(), vol, "{op:?}");
            let mesh = out.mesh().to_mesh();
            assert_eq!(mesh.signed_volume(), vol, "{op:?}");
            assert!(mesh.is_closed_oriented());
            assert_eq!(mesh.groups, vec![op_name(op)]);
        }
        // disjoint: empty intersection
        let far = operand(&cube(1.0, [10.0; 3]), "far.obj", false);
        let out = apply(&mut [a, far], BoolOp::Intersection).unwrap();
        assert!(out.exact.triangles.is_empty() && out.positions.is_empty());
        assert_eq!(out.stats[0].cells, 0);
    }

    /// A mesh with no faces is the empty solid: the union is the others',
    /// the intersection empty, a difference takes nothing away or leaves
    /// nothing; stray vertices of it do not widen the grid; the empty
    /// result written and read back is an operand again.
    #[test]
    fn no_faces_is_the_empty_solid() {
        let a = operand(&cube(4.0, [0.0; 3]), "a.obj", false);
        let none = Operand::new("e.obj", Mesh::default());
        let stray = operand("v 1e200 0 0\n", "stray.obj", false);
        let alone = apply(&mut [a.clone()], BoolOp::Union).unwrap();
        for empty in [none, stray] {
            for (mut operands, op, vol) in [
                (vec![empty.clone(), a.clone()], BoolOp::Union, 64.0),
                (vec![a.clone(), empty.clone()], BoolOp::Union, 64.0),
                (vec![a.clone(), empty.clone()], BoolOp::Intersection, 0.0),
                (vec![empty.clone(), a.clone()], BoolOp::Intersection, 0.0),
                (vec![a.clone(), empty.clone()], BoolOp::Difference, 64.0),
                (vec![empty.clone(), a.clone()], BoolOp::Difference, 0.0),
                (vec![empty.clone(), empty.clone()], BoolOp::Union, 0.0),
            ] {
                let out = apply(&mut operands, op).unwrap();
                assert_eq!(out.volume(), vol, "{op:?} of {}", Operand::names(&operands));
                if vol > 0.0 {
                    assert_eq!(out.grid, alone.grid);
                    assert_eq!(out.exact.triangles.len(), alone.exact.triangles.len());
                }
            }
        }
        let empty = apply(&mut [a.clone(), a.clone()], BoolOp::Difference).unwrap();
        let mut text = Vec::new();
        shadow_scene::write_obj(&empty.mesh(), &mut text).unwrap();
        let back = operand(std::str::from_utf8(&text).unwrap(), "back.obj", false);
        let out = apply(&mut [back, a], BoolOp::Union).unwrap();
        assert_eq!(out.volume(), 64.0);
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
        let (out, stages) = apply_staged(&mut operands, BoolOp::Difference).unwrap();
        assert_eq!(stages, STAGES);
        // 64 − 8 − (the part of c in a but not in b: 1·3·3 − 1·2·1)
        assert_eq!(out.volume(), 49.0);
        assert_eq!(out.reports.len(), 3);
        assert!(out.reports.iter().all(|r| r.polygons == 6));
        assert_eq!(out.stats.len(), 2);
        assert!(out.stats.iter().all(|s| s.mixed_cells > 0));
        for o in &operands {
            assert!(o.mesh.positions.is_empty() && o.mesh.faces.is_empty());
            assert!(o.file_loops.is_none());
            assert_eq!(o.counts, (12, 6));
        }
    }

    /// The report, the rounding warnings and the checks that need no
    /// topology, as a person reads them.
    #[test]
    fn the_report_and_the_warnings_read_as_documented() {
        let mut operands = [
            operand(&cube(4.0, [0.0; 3]), "a.obj", false),
            operand(&cube(4.0, [2.0; 3]), "b.obj", false),
        ];
        let out = apply(&mut operands, BoolOp::Union).unwrap();
        let r = out.report(&operands, out.volume());
        let lines: Vec<&str> = r.lines().collect();
        assert_eq!(lines.len(), 6, "{r}");
        assert!(lines[0].starts_with("input A:        a.obj: 12 triangles (6 faces), 6 polygons"));
        assert!(lines[1].starts_with("input B:        b.obj: "));
        assert_eq!(
            lines[2],
            format!("grid step:      {}", out.grid.step_text())
        );
        assert!(lines[3].starts_with(&format!("octree:         {} cells,", out.stats[0].cells)));
        assert_eq!(
            lines[4],
            format!(
                "output:         {} triangles, {} vertices",
                out.exact.triangles.len(),
                out.positions.len()
            )
        );
        assert_eq!(
            lines[5],
            "volume:         120 (exact, rounded once); 120 (f64 sum)"
        );
        // integer vertices: nothing coincides once rounded, even in f32
        assert!(out.rounded(true).is_none() && out.rounded(false).is_none());
        // every kind of stage ran, and was timed
        let t = out.times;
        assert!(t.snap.is_some() && t.operations.is_some() && t.mesh.is_some());

        // the empty solid: an operand like any other
        let empty = Operand::new("e.obj", Mesh::default());
        assert!(empty.check().is_ok());
        let huge = operand(&cube(1e120, [0.0; 3]), "h.obj", false);
        let e = huge.check_faces().unwrap_err().message;
        assert!(
            e.starts_with("h.obj: the mesh spans 1.000e120 units"),
            "{e}"
        );
    }

    #[test]
    fn exact_volume_scales_by_the_grid() {
        // a 3/4-unit cube at 1/8 offsets: the grid is finer than 1, so the
        // exact volume is divided by a power of two
        let a = operand(&cube(0.75, [0.125; 3]), "a.obj", false);
        let b = operand(&cube(0.75, [0.5; 3]), "b.obj", false);
        let out = apply(&mut [a, b], BoolOp::Union).unwrap();
        assert!(out.grid.scale() > 1.0);
        assert_eq!(out.volume(), 2.0 * 0.421875 - 0.052734375);
        // a coarse grid (scale < 1) multiplies instead
        let a = operand(&cube(4e9, [0.0; 3]), "a.obj", false);
        let b = operand(&cube(4e9, [2e9; 3]), "b.obj", false);
        let out = apply(&mut [a, b], BoolOp::Intersection).unwrap();
        assert!(out.grid.scale() < 1.0);
        assert_eq!(out.volume(), 8e27);
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
        a.check().unwrap();
        for (x, y, op) in [
            (&a, &b, BoolOp::Union),
            (&a, &b, BoolOp::Intersection),
            (&a, &b, BoolOp::Difference),
            (&a, &c, BoolOp::Difference),
            (&c, &b, BoolOp::Union),
        ] {
            let out = apply(&mut [x.clone(), y.clone()], op).unwrap();
            assert!(out.exact.vertices.iter().any(|p| p.as_grid().is_none()));
            // the cheap rounding is the exact fraction's, rounded once
            let exact = out.exact.volume_exact();
            let k = out.grid.scale().log2() as i32;
            let scaled = if k >= 0 {
                exact / BigRational::from_integer(BigInt::one() << (3 * k) as usize)
            } else {
                exact * BigRational::from_integer(BigInt::one() << (-3 * k) as usize)
            };
            assert_eq!(out.volume(), scaled.to_f64().unwrap(), "{op:?}");
            assert!(out.volume() > 0.0);
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
        a.check().unwrap();
        let b = operand(CUBE, "b.obj", false);
        let e = apply(&mut [a, b], BoolOp::Union).err().unwrap();
        assert!(
            e.to_string()
                .starts_with("inv.obj: the faces are oriented inward"),
            "{e}"
        );
    }

    #[test]
    fn overlapping_shells_in_one_file_count_once() {
        // two closed cubes that overlap, in one file: each is a closed
        // manifold, and together they bound their union (the points where
        // the winding number is positive; it is 2 where they overlap)
        let shells = cube(4.0, [0.0; 3]) + &cube(4.0, [2.0; 3]);
        let a = operand(&shells, "shells.obj", false);
        a.check().unwrap();
        let b = operand(&cube(3.0, [2.5, -0.5, 1.5]), "b.obj", false);
        // A ∪ B = 120; C = 27; (A ∪ B) ∩ C = 9.375 + 3.75 − 1.5
        for (op, volume) in [
            (BoolOp::Union, 135.375),
            (BoolOp::Intersection, 11.625),
            (BoolOp::Difference, 108.375),
        ] {
            let out = apply(&mut [a.clone(), b.clone()], op).unwrap();
            assert_eq!(out.volume(), volume, "{op:?}");
        }
    }
}
