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

use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{Result, anyhow, bail};
use bsp_core::BoolOp;
use bsp_csg::Step;
use bsp_csg::files::{FileBoolean, FileError, Operand};
use clap::{Args, ValueEnum};
use rayon::prelude::*;
use shadow_scene::MeshFormat;

use crate::output::{Phases, emit, guarded, ms, note};

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
        bsp_csg::files::op_name(self.kernel())
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
    /// The operands (.obj or .stl): closed, consistently oriented meshes,
    /// two or more; a union of one cleans it (shells that cross, overlap
    /// or nest become the solid where the winding number is positive).
    #[arg(value_name = "MESH", num_args = 1.., required = true)]
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
    /// No notes or warnings on stderr (errors still go there).
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

/// The operands from `paths`, read (and welded) in parallel; the
/// readers' notes are printed, and the first error returned, in the order
/// of the files, as reading them in turn would.
fn load_all(paths: &[PathBuf], weld: bool, quiet: bool) -> Result<Vec<Operand>> {
    let read: Vec<Result<(Operand, Option<String>)>> = paths
        .par_iter()
        .map(|p| {
            let (mesh, note) = crate::input::read_mesh(p)?;
            let name = p.display().to_string();
            let o = match weld {
                true => Operand::welded(name, mesh),
                false => Operand::new(name, mesh),
            };
            Ok((o, note))
        })
        .collect();
    let mut operands = Vec::with_capacity(paths.len());
    for r in read {
        let (o, skipped) = r?;
        if let Some(m) = skipped {
            note(quiet, &format!("note: {m}"));
        }
        if o.collapsed > 0 {
            let (name, n) = (&o.name, o.collapsed);
            let what =
                format!("{name}: welding left out {n} face(s) whose corners became one position");
            note(quiet, &format!("note: {what}"));
        }
        if o.mesh.faces.is_empty() {
            let name = &o.name;
            note(quiet, &format!("note: {name}: no faces: the empty solid"));
        }
        // (in the files' order, before a later file's read error)
        o.check_faces().map_err(file_error)?;
        operands.push(o);
    }
    Ok(operands)
}

/// An operand spanning fewer steps of the shared grid than this is warned
/// about: its vertices move by more than 0.05 % of its size.
const COARSE_STEPS: f64 = 1024.0;

/// The operation applied to the first operand with each of the others in
/// turn ([`FileBoolean::apply`]): each import summary is printed to stderr
/// as its operand is snapped, and the library's stages are timed as
/// "validate", "snap/import", "boolean" and "boundary+mesh".
fn apply(
    operands: &mut [Operand],
    op: Operation,
    phases: &mut Phases,
    quiet: bool,
) -> Result<FileBoolean> {
    let names: Vec<String> = operands.iter().map(|o| o.name.clone()).collect();
    // each face's line, for the notes on faces snapping changed
    let lines: Vec<Vec<usize>> = (operands.iter())
        .map(|o| o.mesh.faces.iter().map(|f| f.line).collect())
        .collect();
    // each operand's size, to say when the grid the operands share is
    // coarse for it (a unit cube beside one 10^8 away snaps to a grid of
    // step 2 and comes out 8 times its volume)
    let sizes: Vec<f64> = (operands.iter())
        .map(|o| {
            o.mesh
                .bounds()
                .map_or(0.0, |(lo, hi)| (hi - lo).max_element())
        })
        .collect();
    let checked = phases
        .run("validate", || Operand::check_all(operands))
        .map_err(file_error)?;
    let out = FileBoolean::apply(checked, op.kernel(), |step, grid| {
        if let Step::Snapped { operand, report } = step
            && !quiet
        {
            let line = |f: usize| lines[*operand].get(f).copied().unwrap_or(0);
            eprint!("{}", report.notes_at(&names[*operand], grid, &line));
            let steps = sizes[*operand] * grid.scale();
            if steps > 0.0 && steps < COARSE_STEPS {
                eprintln!(
                    "warning: {} spans {steps:.3} steps of the grid the operands share (step {}): \
                     snapping moves its vertices by up to half a step, {:.2}% of its size; \
                     operate on operands closer in size and place",
                    names[*operand],
                    grid.step_text(),
                    50.0 / steps
                );
            }
        }
    })
    .map_err(|e| match e.locate_crossing(&names) {
        Some(at) => anyhow!("{}; {at}", e.message),
        None => file_error(e),
    })?;
    let t = out.times;
    let stages = [
        ("snap/import", t.snap),
        ("boolean", t.operations),
        ("boundary+mesh", t.mesh),
    ];
    for (name, d) in stages {
        d.into_iter().for_each(|d| phases.add(name, d));
    }
    Ok(out)
}

/// An operand's error, with the hint of `--weld` where welding may mend it.
fn file_error(e: FileError) -> anyhow::Error {
    match e.weld_may_help {
        true => anyhow!(
            "{}; if the file repeats vertices per face, try --weld",
            e.message
        ),
        false => anyhow!(e.message),
    }
}

/// `shadow csg`.
pub(crate) fn run(args: &CsgArgs) -> Result<()> {
    let total = Instant::now();
    bsp_csg::files::keep_freed_blocks();
    // fail on a bad output name before doing any work
    MeshFormat::from_path(&args.output)?;
    if args.operands.len() == 1 && args.op != Operation::Union {
        bail!(
            "the {} of one mesh: give two or more (a union of one mesh cleans it)",
            args.op.name()
        );
    }
    let mut phases = Phases::default();
    let mut operands = phases.run("load", || load_all(&args.operands, args.weld, args.quiet))?;
    let out = guarded("the input files", || {
        apply(&mut operands, args.op, &mut phases, args.quiet)
    })?;
    let stl = MeshFormat::from_path(&args.output)? == MeshFormat::Stl;
    let rounded = out.rounded(stl);
    if let Some(r) = &rounded
        && r.mesh.faces.is_empty()
        && !out.exact.triangles.is_empty()
    {
        bail!(
            "{}: the {} has {} triangles, but {}",
            args.output.display(),
            args.op.name(),
            out.exact.triangles.len(),
            bsp_shadows::STL_TOO_COARSE
        );
    }
    phases.run("write", || match &rounded {
        Some(r) => shadow_scene::save(&args.output, &r.mesh),
        None => shadow_scene::save(&args.output, &out.mesh()),
    })?;
    let total = total.elapsed();

    let (tris, verts) = match &rounded {
        Some(r) => (r.mesh.faces.len(), r.mesh.positions.len()),
        None => (out.exact.triangles.len(), out.positions.len()),
    };
    let of = Operand::names(&operands);
    let mut report = format!(
        "wrote {}: {} of {of}, {tris} triangles, {verts} vertices\n",
        args.output.display(),
        args.op.name(),
    );
    if tris == 0 {
        note(
            args.quiet,
            &format!("note: the {} is empty", args.op.name()),
        );
    }
    if let Some(r) = &rounded {
        note(args.quiet, &r.message(stl));
    }
    if args.stats {
        report += &stats_text(args.op, &operands, &out, &phases, total);
    }
    emit(&report)
}

/// The `--stats` report. Computes the exact volume, which is timed on its
/// own (after "total", as only `--stats` pays for it).
fn stats_text(
    op: Operation,
    operands: &[Operand],
    out: &FileBoolean,
    phases: &Phases,
    total: Duration,
) -> String {
    let mut s = format!("operation:      {}\n", op.name());
    let start = Instant::now();
    let volume = out.volume();
    let exact_time = start.elapsed();
    s += &out.report(operands, volume);
    s += "time (ms):\n";
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

    /// The CLI's phases: validation, then the library's three stages.
    #[test]
    fn the_phases_are_timed_in_order() {
        let cube = shadow_scene::scene("cube").unwrap();
        let mut moved = cube.clone();
        moved.positions.iter_mut().for_each(|p| *p += 0.5);
        let mut operands = [Operand::new("a.obj", cube), Operand::new("b.obj", moved)];
        let mut phases = Phases::default();
        let out = apply(&mut operands, Operation::Union, &mut phases, false).unwrap();
        assert_eq!(out.volume(), 2.0 - 0.125);
        let names: Vec<&str> = phases.0.iter().map(|p| p.0).collect();
        assert_eq!(
            names,
            ["validate", "snap/import", "boolean", "boundary+mesh"]
        );
    }

    #[test]
    fn an_unwelded_soup_gets_the_weld_hint() {
        let e = FileError {
            crossing: None,
            message: "soup.obj:25: edge 1-2 of face 0 is a boundary edge".into(),
            weld_may_help: true,
        };
        assert!(
            file_error(e)
                .to_string()
                .ends_with("; if the file repeats vertices per face, try --weld")
        );
    }
}
