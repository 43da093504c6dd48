//! Booleans of meshes: snap, operate and mesh in one call, for two
//! meshes ([`mesh_boolean`]), a list of them ([`mesh_sequence`]), or
//! operands handed over one at a time with each step reported
//! ([`mesh_sequence_with`]).

use bsp_core::{BoolOp, Grid, ImportReport, TriMesh};

use crate::{AsMeshIn, CsgError, MeshIn, Planned, Solid, Stats, check_mesh, fit_grid, snap_one};

/// The result of [`mesh_boolean`] and [`mesh_sequence`].
#[derive(Clone, Debug)]
pub struct Boolean {
    /// The watertight result in grid units (`grid.to_world` for input
    /// units).
    pub mesh: TriMesh,
    /// The grid every operand was snapped to.
    pub grid: Grid,
    /// The result as a solid, ready for further operations.
    pub solid: Solid,
    /// What snapping did to each operand's faces.
    pub reports: Vec<ImportReport>,
}

impl Boolean {
    /// The result's exact volume in input units, correctly rounded to
    /// `f64` ([`TriMesh::volume_rounded`]; the grid's scale is a power of
    /// two).
    pub fn volume(&self) -> f64 {
        self.mesh.volume_rounded() / self.grid.scale().powi(3)
    }
}

/// A stage of [`mesh_sequence_with`]: what [`Step::Started`] announces,
/// and where a [`SequenceError`] stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Snapping operand `i` (0 for the first) to the grid: its solid.
    Snap(usize),
    /// The operation with operand `i` (from 1): decided, and carried out
    /// unless it is the last.
    Operation(usize),
    /// The last result's mesh.
    Mesh,
}

impl std::fmt::Display for Stage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Stage::Snap(i) => write!(f, "snapping operand {i}"),
            Stage::Operation(i) => write!(f, "the operation with operand {i}"),
            Stage::Mesh => f.write_str("meshing the result"),
        }
    }
}

/// What [`mesh_sequence_with`] tells its caller as it goes. Each stage
/// is told when it starts and when it is over (a stage that fails is
/// not: the error names it), so that a caller can time the stages; for
/// an operand `i ≥ 1`, the steps are `Started(Snap(i))`,
/// `Finished(Snap(i))`, `Snapped { i, .. }`, `Started(Operation(i))`,
/// `Planned { i, .. }`, `Finished(Operation(i))`, and after the last,
/// `Started(Mesh)` and `Finished(Mesh)`.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Step {
    /// A stage begins.
    Started(Stage),
    /// A stage is over (for [`Stage::Mesh`], the mesh is returned next).
    Finished(Stage),
    /// Operand `operand` is snapped (after its [`Stage::Snap`] is over):
    /// what snapping did to its faces. Its mesh is let go after this step.
    Snapped {
        /// The operand.
        operand: usize,
        /// What snapping did to its faces.
        report: ImportReport,
    },
    /// The operation with operand `operand` is decided: what it found.
    /// Its [`Stage::Operation`] goes on (the result is carried out)
    /// unless it is the last.
    Planned {
        /// The operand.
        operand: usize,
        /// What the operation found.
        stats: Stats,
    },
}

/// Why [`mesh_sequence_with`] stopped: the stage it was at, and the
/// error.
#[derive(Clone, Debug, PartialEq)]
pub struct SequenceError {
    /// The stage that failed: a [`CsgError::NotASolid`] in
    /// [`Stage::Operation`]`(i)` means that operand `i`'s surface or the
    /// result's before it crosses itself; a [`CsgError::Internal`] in
    /// [`Stage::Mesh`], that the result is not watertight.
    pub stage: Stage,
    /// The error.
    pub error: CsgError,
}

impl std::fmt::Display for SequenceError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.error {
            // (these name their operand)
            CsgError::Inward { .. } | CsgError::Topology { .. } => write!(f, "{}", self.error),
            _ => write!(f, "{}: {}", self.stage, self.error),
        }
    }
}

impl std::error::Error for SequenceError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(&self.error)
    }
}

/// Snaps both meshes to one grid, checks them, and computes `a op b`.
pub fn mesh_boolean(a: &MeshIn<'_>, b: &MeshIn<'_>, op: BoolOp) -> Result<Boolean, CsgError> {
    mesh_sequence(a, &[(op, *b)])
}

/// `((first op₁ m₁) op₂ m₂) ...` on one grid: every operand is checked
/// and snapped once, its solid made only when its turn comes, and each
/// operation works on the previous result in place (so a long sequence
/// holds the result and one operand's solid at a time).
pub fn mesh_sequence(
    first: &MeshIn<'_>,
    ops: &[(BoolOp, MeshIn<'_>)],
) -> Result<Boolean, CsgError> {
    let all: Vec<MeshIn<'_>> = std::iter::once(*first)
        .chain(ops.iter().map(|(_, m)| *m))
        .collect();
    for (i, m) in all.iter().enumerate() {
        check_mesh(m, i)?;
    }
    let grid = fit_grid(&all)?;
    let mut reports = Vec::with_capacity(all.len());
    let mut on_step = |step: Step| {
        if let Step::Snapped { report, .. } = step {
            reports.push(report);
        }
    };
    let last = operate(&grid, *first, ops.iter().copied(), &mut on_step);
    let solid = match last.map_err(|e| e.error)? {
        Last::Solid(solid) => *solid,
        Last::Planned(planned) => planned.into_solid(),
    };
    let mesh = solid.to_watertight_mesh()?;
    Ok(Boolean {
        mesh,
        grid,
        solid,
        reports,
    })
}

/// `((first op₁ m₁) op₂ m₂) ...` on `grid`, the last result made as a
/// mesh only ([`Planned::into_watertight_mesh`]: no solid of its own),
/// with each operand handed over when its turn comes (the first two at
/// once: they are snapped side by side) and let go once snapped, and
/// each step told to `on_step`.
///
/// The meshes must be checked already ([`check_mesh`]), and `grid` must
/// hold every position of every mesh ([`fit_grid`]). `rest` is read one
/// operand at a time, each when the operation before is carried out:
/// an iterator that moves each operand out of the caller's storage (a
/// [`MeshBuf`](crate::MeshBuf) each, say) holds only the result, the
/// operand at work and the operands not reached yet. `on_step` hears
/// each snapped operand's [`ImportReport`] and each operation's
/// [`Stats`], and when each [`Stage`] starts and ends ([`Step`]). An
/// error says the stage that failed.
///
/// ```
/// use bsp_core::BoolOp;
/// use bsp_csg::{MeshBuf, MeshIn, Step, fit_grid, mesh_sequence_with};
/// use glam::DVec3;
///
/// // a unit cube at `at`, as an owned mesh
/// fn cube(at: f64) -> MeshBuf {
///     let p = |i: u32| DVec3::new(f64::from(i & 1), f64::from(i >> 1 & 1), f64::from(i >> 2)) + at;
///     let faces = vec![vec![0, 2, 3, 1], vec![4, 5, 7, 6], vec![0, 1, 5, 4],
///                      vec![2, 6, 7, 3], vec![0, 4, 6, 2], vec![1, 3, 7, 5]];
///     MeshBuf::new((0..8).map(p).collect(), faces)
/// }
/// let cubes: Vec<MeshBuf> = [0.0, 0.5, 1.25].map(cube).into();
/// let views: Vec<MeshIn<'_>> = cubes.iter().map(|m| MeshIn::new(&m.positions, &m.faces)).collect();
/// let grid = fit_grid(&views).unwrap();
/// let mut cubes = cubes.into_iter();
/// let first = cubes.next().unwrap();
/// let (mut snapped, mut cut) = (0, 0);
/// let mesh = mesh_sequence_with(&grid, first, cubes.map(|m| (BoolOp::Union, m)), |step| {
///     match step {
///         Step::Snapped { report, .. } => snapped += report.polygons,
///         Step::Planned { stats, .. } => cut += stats.cut_faces,
///         _ => {}
///     }
/// })
/// .unwrap();
/// assert_eq!((snapped, cut > 0), (18, true));
/// // three unit cubes, less the overlaps of the first two (1/8) and of
/// // the last two (1/64), exactly
/// assert_eq!(mesh.volume_rounded() / grid.scale().powi(3), 2.859375);
/// ```
pub fn mesh_sequence_with<M, I>(
    grid: &Grid,
    first: M,
    rest: I,
    mut on_step: impl FnMut(Step),
) -> Result<TriMesh, SequenceError>
where
    M: AsMeshIn,
    I: IntoIterator<Item = (BoolOp, M)>,
    I::IntoIter: ExactSizeIterator,
{
    let last = operate(grid, first, rest.into_iter(), &mut on_step)?;
    on_step(Step::Started(Stage::Mesh));
    let mesh = match last {
        Last::Solid(solid) => solid.into_watertight_mesh(),
        Last::Planned(planned) => planned.into_watertight_mesh(),
    };
    let mesh = mesh.map_err(|error| SequenceError {
        stage: Stage::Mesh,
        error,
    })?;
    on_step(Step::Finished(Stage::Mesh));
    Ok(mesh)
}

/// The last result of a sequence: the first operand's solid if there was
/// no operation, else the last operation, decided (boxed: the two differ
/// in size).
enum Last {
    Solid(Box<Solid>),
    Planned(Box<Planned>),
}

/// The operations of a sequence, each carried out but the last, which
/// is only decided.
fn operate<M: AsMeshIn>(
    grid: &Grid,
    first: M,
    mut rest: impl ExactSizeIterator<Item = (BoolOp, M)>,
    on_step: &mut dyn FnMut(Step),
) -> Result<Last, SequenceError> {
    let Some((mut op, second)) = rest.next() else {
        // a sequence of one: its solid, cleaned (a shell that crosses
        // itself bounds where its winding number is positive)
        let solid = snap_operand(grid, first, 0, on_step)?;
        let stage = Stage::Snap(0);
        let solid = solid
            .resolved()
            .map_err(|error| SequenceError { stage, error })?;
        return Ok(Last::Solid(Box::new(solid)));
    };
    let (mut solid, mut other) = snap_two(grid, (first, second), on_step)?;
    let mut operand = 1;
    loop {
        let stage = Stage::Operation(operand);
        on_step(Step::Started(stage));
        let planned = solid
            .plan_owned(other, op)
            .map_err(|error| SequenceError { stage, error })?;
        on_step(Step::Planned {
            operand,
            stats: *planned.stats(),
        });
        if rest.len() == 0 {
            on_step(Step::Finished(stage));
            return Ok(Last::Planned(Box::new(planned)));
        }
        solid = planned.into_solid();
        on_step(Step::Finished(stage));
        let Some((next, mesh)) = rest.next() else {
            return Ok(Last::Solid(Box::new(solid)));
        };
        operand += 1;
        op = next;
        other = snap_operand(grid, mesh, operand, on_step)?;
    }
}

/// The solids of the first two operands, snapped side by side (each
/// snap has parts on one thread: counting its shells, numbering the
/// certificate's points, making the solid), their steps told in order as
/// [`snap_operand`] tells them, and the first error in operand order.
fn snap_two<M: AsMeshIn>(
    grid: &Grid,
    (first, second): (M, M),
    on_step: &mut dyn FnMut(Step),
) -> Result<(Solid, Solid), SequenceError> {
    let (a, b) = (first.as_mesh_in(), second.as_mesh_in());
    on_step(Step::Started(Stage::Snap(0)));
    let (snapped_a, snapped_b) =
        bsp_core::par::join(|| snap_one(grid, &a, 0), || snap_one(grid, &b, 1));
    let told = |operand: usize,
                snapped: Result<(Solid, ImportReport), CsgError>,
                on_step: &mut dyn FnMut(Step)| {
        let stage = Stage::Snap(operand);
        let (solid, report) = snapped.map_err(|error| SequenceError { stage, error })?;
        on_step(Step::Finished(stage));
        on_step(Step::Snapped { operand, report });
        Ok::<Solid, SequenceError>(solid)
    };
    let solid_a = told(0, snapped_a, on_step)?;
    drop(first);
    on_step(Step::Started(Stage::Snap(1)));
    let solid_b = told(1, snapped_b, on_step)?;
    drop(second);
    Ok((solid_a, solid_b))
}

/// The solid of operand `operand`'s mesh, which is let go once the step
/// that says it is snapped is told.
fn snap_operand<M: AsMeshIn>(
    grid: &Grid,
    mesh: M,
    operand: usize,
    on_step: &mut dyn FnMut(Step),
) -> Result<Solid, SequenceError> {
    let stage = Stage::Snap(operand);
    on_step(Step::Started(stage));
    let (solid, report) = snap_one(grid, &mesh.as_mesh_in(), operand)
        .map_err(|error| SequenceError { stage, error })?;
    on_step(Step::Finished(stage));
    on_step(Step::Snapped { operand, report });
    drop(mesh);
    Ok(solid)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::MeshBuf;
    use bsp_fixtures::sphere_pair;
    use glam::DVec3;
    use std::cell::RefCell;
    use std::rc::Rc;

    /// The cube `[lo, lo + s]` (per axis), outward.
    fn cube(lo: [f64; 3], s: f64) -> MeshBuf {
        let p = |i: u32| {
            DVec3::from_array(lo)
                + s * DVec3::new(f64::from(i & 1), f64::from(i >> 1 & 1), f64::from(i >> 2))
        };
        let faces = vec![
            vec![0, 2, 3, 1],
            vec![4, 5, 7, 6],
            vec![0, 1, 5, 4],
            vec![2, 6, 7, 3],
            vec![0, 4, 6, 2],
            vec![1, 3, 7, 5],
        ];
        MeshBuf::new((0..8).map(p).collect(), faces)
    }

    /// Two overlapping spheres and a cube across both.
    fn three() -> Vec<MeshBuf> {
        let (va, vb, faces) = sphere_pair(2000);
        vec![
            MeshBuf::new(va, faces.clone()),
            MeshBuf::new(vb, faces),
            cube([0.4, -0.4, -0.3], 1.0),
        ]
    }

    fn grid_of(meshes: &[MeshBuf]) -> Grid {
        let views: Vec<MeshIn<'_>> = meshes.iter().map(AsMeshIn::as_mesh_in).collect();
        fit_grid(&views).unwrap()
    }

    /// The steps of `first op₁ m₁ op₂ m₂ ...`, and its mesh or error.
    fn run(meshes: Vec<MeshBuf>, ops: &[BoolOp]) -> (Vec<Step>, Result<TriMesh, SequenceError>) {
        let grid = grid_of(&meshes);
        let mut meshes = meshes.into_iter();
        let first = meshes.next().unwrap();
        let mut steps = Vec::new();
        let rest = ops.iter().copied().zip(meshes);
        let r = mesh_sequence_with(&grid, first, rest, |s| steps.push(s));
        (steps, r)
    }

    #[test]
    fn the_last_result_meshed_alone_is_the_mesh_of_mesh_sequence() {
        use BoolOp::{Difference, Intersection, Union};
        for ops in [
            [Union, Difference],
            [Intersection, Union],
            [Difference, Union],
            [Union, Intersection],
        ] {
            let meshes = three();
            let views: Vec<MeshIn<'_>> = meshes.iter().map(AsMeshIn::as_mesh_in).collect();
            let want = mesh_sequence(&views[0], &[(ops[0], views[1]), (ops[1], views[2])]).unwrap();
            assert_eq!(grid_of(&meshes), want.grid);
            let (_, got) = run(meshes.clone(), &ops);
            let got = got.unwrap();
            assert!(!got.triangles.is_empty(), "{ops:?}");
            assert_eq!(got.triangles, want.mesh.triangles, "{ops:?}");
            assert_eq!(got.vertices_f64(), want.mesh.vertices_f64(), "{ops:?}");
            // two operands, and one (no operation)
            let two = mesh_sequence(&views[0], &[(ops[0], views[1])]).unwrap();
            let (_, got) = run(meshes[..2].to_vec(), &ops[..1]);
            assert_eq!(got.unwrap().triangles, two.mesh.triangles, "{ops:?}");
            let one = mesh_sequence(&views[2], &[]).unwrap();
            let (_, got) = run(meshes[2..].to_vec(), &[]);
            assert_eq!(got.unwrap().volume_rounded(), one.mesh.volume_rounded());
        }
    }

    /// The steps come in order, with each operand's import report and
    /// each operation's stats as snapping and applying them give.
    #[test]
    fn each_step_is_told_with_its_report_and_stats() {
        let meshes = three();
        let grid = grid_of(&meshes);
        let ops = [BoolOp::Union, BoolOp::Difference];
        let snapped: Vec<(Solid, ImportReport)> = meshes
            .iter()
            .enumerate()
            .map(|(i, m)| snap_one(&grid, &m.as_mesh_in(), i).unwrap())
            .collect();
        let mut it = snapped.iter().cloned();
        let mut solid = it.next().unwrap().0;
        let stats: Vec<Stats> = it
            .zip(ops)
            .map(|((other, _), op)| solid.apply_owned(other, op).unwrap())
            .collect();
        assert!(stats.iter().all(|s| s.cut_faces > 0));
        let snapped = |i: usize| {
            let (stage, report) = (Stage::Snap(i), snapped[i].1.clone());
            [
                Step::Started(stage),
                Step::Finished(stage),
                Step::Snapped { operand: i, report },
            ]
        };
        let operation = |i: usize| {
            let (stage, stats) = (Stage::Operation(i), stats[i - 1]);
            [
                Step::Started(stage),
                Step::Planned { operand: i, stats },
                Step::Finished(stage),
            ]
        };
        let mesh = [Step::Started(Stage::Mesh), Step::Finished(Stage::Mesh)];
        let want: Vec<Step> = [
            snapped(0),
            snapped(1),
            operation(1),
            snapped(2),
            operation(2),
        ]
        .into_iter()
        .flatten()
        .chain(mesh)
        .collect();
        let (steps, mesh) = run(meshes, &ops);
        assert_eq!(steps, want);
        assert_eq!(mesh.unwrap().triangles, solid.to_mesh().triangles);
    }

    /// An operand that notes when it is let go.
    struct Noted {
        mesh: MeshBuf,
        operand: usize,
        log: Rc<RefCell<Vec<String>>>,
    }

    impl AsMeshIn for Noted {
        fn as_mesh_in(&self) -> MeshIn<'_> {
            self.mesh.as_mesh_in()
        }
    }

    impl Drop for Noted {
        fn drop(&mut self) {
            self.log.borrow_mut().push(format!("drop {}", self.operand));
        }
    }

    /// The first two operands are taken at once (they are snapped side by
    /// side), each later one when its turn comes (after the operation
    /// before is decided), and each is let go right after the step that
    /// says it is snapped: a long sequence holds one or two operands'
    /// meshes.
    #[test]
    fn operands_are_taken_in_turn_and_let_go_once_snapped() {
        let meshes = three();
        let grid = grid_of(&meshes);
        let log = Rc::new(RefCell::new(Vec::new()));
        let noted = |(operand, mesh): (usize, MeshBuf)| Noted {
            mesh,
            operand,
            log: log.clone(),
        };
        let mut all = meshes.into_iter().enumerate().map(noted);
        let first = all.next().unwrap();
        let rest: Vec<Noted> = all.collect();
        // handed over lazily: each moved out of `rest` when asked for
        let taken = rest.into_iter().map(|m| {
            log.borrow_mut().push(format!("take {}", m.operand));
            (BoolOp::Union, m)
        });
        mesh_sequence_with(&grid, first, taken, |s| {
            let note = match s {
                Step::Started(stage) => format!("{stage}"),
                Step::Finished(stage) => format!("end of {stage}"),
                Step::Snapped { operand, .. } => format!("snapped {operand}"),
                Step::Planned { operand, .. } => format!("planned {operand}"),
            };
            log.borrow_mut().push(note);
        })
        .unwrap();
        assert_eq!(
            *log.borrow(),
            [
                "take 1",
                "snapping operand 0",
                "end of snapping operand 0",
                "snapped 0",
                "drop 0",
                "snapping operand 1",
                "end of snapping operand 1",
                "snapped 1",
                "drop 1",
                "the operation with operand 1",
                "planned 1",
                "end of the operation with operand 1",
                "take 2",
                "snapping operand 2",
                "end of snapping operand 2",
                "snapped 2",
                "drop 2",
                "the operation with operand 2",
                "planned 2",
                "end of the operation with operand 2",
                "meshing the result",
                "end of meshing the result",
            ]
        );
    }

    /// An error says the stage it stopped at: an operand's snap (an
    /// inward mesh, a grid too small), an operation (a surface crossing
    /// itself), with messages that say where.
    #[test]
    fn errors_name_their_stage() {
        let mut inward = cube([0.5; 3], 1.0);
        inward.faces.iter_mut().for_each(|f| f.reverse());
        let (steps, r) = run(
            vec![cube([0.0; 3], 1.0), cube([0.2; 3], 1.0), inward],
            &[BoolOp::Union; 2],
        );
        let e = r.unwrap_err();
        assert_eq!(e.stage, Stage::Snap(2));
        assert_eq!(e.error, CsgError::Inward { operand: 2 });
        assert_eq!(e.to_string(), e.error.to_string());
        assert_eq!(steps.last(), Some(&Step::Started(Stage::Snap(2))));
        let source = std::error::Error::source(&e).unwrap().to_string();
        assert_eq!(source, e.error.to_string());
        // two overlapping cubes in one mesh: their solid is where the
        // winding number is positive, A ∪ B (120); with C: 120 + 27 −
        // (A∩C + B∩C − A∩B∩C = 9.375 + 3.75 − 1.5)
        let mut shells = cube([0.0; 3], 4.0);
        let more = cube([2.0; 3], 4.0);
        shells.faces.extend(
            more.faces
                .iter()
                .map(|f| f.iter().map(|&v| v + 8).collect()),
        );
        shells.positions.extend(more.positions);
        let meshes = vec![shells, cube([2.5, -0.5, 1.5], 3.0)];
        let grid = grid_of(&meshes);
        let (_, r) = run(meshes, &[BoolOp::Union]);
        let volume = r.unwrap().volume_rounded() / grid.scale().powi(3);
        assert_eq!(volume, 135.375);
        // a surface that still bounds no solid names the operation
        let e = SequenceError {
            stage: Stage::Operation(1),
            error: CsgError::NotASolid,
        };
        assert_eq!(
            e.to_string(),
            "the operation with operand 1: a surface crosses itself (after snapping to the grid) \
             and bounds no solid"
        );
        // an operand the grid does not hold
        let near = [cube([0.0; 3], 1.0), cube([0.5; 3], 1.0)];
        let grid = grid_of(&near);
        let [a, b] = near;
        let far = cube([1e12; 3], 1.0);
        let e = mesh_sequence_with(&grid, a, [(BoolOp::Union, b), (BoolOp::Union, far)], |_| {})
            .unwrap_err();
        assert_eq!(e.stage, Stage::Snap(2));
        assert!(matches!(e.error, CsgError::Grid(_)), "{e:?}");
        assert!(e.to_string().starts_with("snapping operand 2: "), "{e}");
    }
}
