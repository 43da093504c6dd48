//! Mesh → grid → exact polygons → BSP tree.

use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use bsp_core::{BspTree, BuildOptions, Grid, ImportReport, import_faces};
use shadow_scene::Mesh;

/// A mesh with its grid and BSP tree.
pub(crate) struct Prepared {
    pub(crate) mesh: Mesh,
    pub(crate) grid: Grid,
    pub(crate) report: ImportReport,
    pub(crate) tree: BspTree,
    /// Wall time of snapping and importing the faces.
    pub(crate) import_time: Duration,
    /// Wall time of the BSP build.
    pub(crate) build_time: Duration,
}

impl Prepared {
    /// Snaps `mesh` to a fitted grid, imports its faces (printing the
    /// import summary to stderr when faces were changed) and builds the
    /// tree. `name` names the mesh in messages.
    pub(crate) fn new(mesh: Mesh, name: &str) -> Result<Prepared> {
        let grid = Grid::fit_points(&mesh.positions)
            .with_context(|| format!("{name}: cannot fit a grid to the positions"))?;
        Prepared::on_grid(mesh, name, grid)
    }

    /// As [`Prepared::new`], on a given grid (one shared with other
    /// operands, such as lights). Faces are tagged with their index.
    pub(crate) fn on_grid(mesh: Mesh, name: &str, grid: Grid) -> Result<Prepared> {
        let start = Instant::now();
        let loops = mesh.face_loops();
        let (polys, report) = import_faces(&grid, loops.iter().map(Vec::as_slice))
            .with_context(|| format!("{name}: cannot import the faces"))?;
        let summary = report.summary();
        if !summary.is_empty() {
            eprint!("{name}: {summary}");
        }
        let import_time = start.elapsed();
        let start = Instant::now();
        let tree = BspTree::build(polys, &BuildOptions::default());
        let build_time = start.elapsed();
        Ok(Prepared {
            mesh,
            grid,
            report,
            tree,
            import_time,
            build_time,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn room_imports_without_changes() {
        let p = Prepared::new(shadow_scene::room(), "room").unwrap();
        assert!(p.report.triangulated.is_empty() && p.report.dropped.is_empty());
        assert_eq!(p.report.polygons, p.mesh.faces.len());
        p.tree.sanity_check().unwrap();
        assert!(p.tree.stats().polygons >= p.report.polygons);
    }

    #[test]
    fn empty_mesh_gives_an_empty_tree() {
        let p = Prepared::new(Mesh::default(), "empty").unwrap();
        assert_eq!(p.tree.stats().nodes, 0);
    }
}
