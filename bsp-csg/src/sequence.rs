//! Booleans of meshes in one call: check, snap, operate and mesh.

use bsp_core::{BoolOp, Grid, ImportReport, TriMesh};

use crate::{CsgError, MeshIn, Solid, check_mesh, fit_grid, snap_one};

/// The result of [`mesh_boolean`].
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
    // each operand's solid is made when its turn comes
    let grid = fit_grid(&all)?;
    let (mut solid, report) = snap_one(&grid, first, 0)?;
    let mut reports = vec![report];
    for (i, (op, m)) in ops.iter().enumerate() {
        let (other, report) = snap_one(&grid, m, i + 1)?;
        reports.push(report);
        solid.apply_owned(other, *op)?;
    }
    let mesh = solid.to_watertight_mesh()?;
    Ok(Boolean {
        mesh,
        grid,
        solid,
        reports,
    })
}
