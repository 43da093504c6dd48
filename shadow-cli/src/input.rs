//! What every command reads: a mesh file or a built-in scene, and the
//! mesh snapped to a grid, imported and built into a BSP tree.

use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use bsp_core::{BspTree, BuildOptions, Grid, ImportReport, import_faces};
use shadow_scene::Mesh;

use crate::args::SourceArgs;

/// Reads a mesh file: an error if it has no faces; a note on stderr
/// (unless `quiet`) if the reader skipped unknown statements.
pub(crate) fn load_mesh(path: &Path, quiet: bool) -> Result<shadow_scene::Mesh> {
    let (mesh, note) = read_mesh(path)?;
    if let Some(m) = note
        && !quiet
    {
        eprintln!("note: {m}");
    }
    with_faces(path, mesh)
}

/// [`load_mesh`]'s reading, printing nothing: the mesh, faces or not, and
/// the reader's note on what it skipped.
pub(crate) fn read_mesh(path: &Path) -> Result<(shadow_scene::Mesh, Option<String>)> {
    let (mesh, notes) = shadow_scene::load_notes(path)?;
    Ok((mesh, notes.message(&path.display().to_string())))
}

/// `mesh` read from `path`, unless it has no faces.
pub(crate) fn with_faces(path: &Path, mesh: shadow_scene::Mesh) -> Result<shadow_scene::Mesh> {
    if mesh.faces.is_empty() {
        bail!("{}: no faces", path.display());
    }
    Ok(mesh)
}

pub(crate) fn load_source(src: &SourceArgs) -> Result<(shadow_scene::Mesh, String)> {
    load_source_quiet(src, false)
}

pub(crate) fn load_source_quiet(
    src: &SourceArgs,
    quiet: bool,
) -> Result<(shadow_scene::Mesh, String)> {
    match (&src.input, &src.scene) {
        (Some(path), None) => Ok((load_mesh(path, quiet)?, path.display().to_string())),
        (None, Some(name)) => {
            let mesh = shadow_scene::scene(name).with_context(|| {
                format!(
                    "unknown scene `{name}` (available: {})",
                    shadow_scene::SCENE_NAMES.join(", ")
                )
            })?;
            Ok((mesh, format!("scene {name}")))
        }
        (Some(_), Some(_)) => bail!("give either an INPUT file or --scene NAME, not both"),
        (None, None) => bail!("no input: give a mesh file (.obj or .stl) or --scene NAME"),
    }
}

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

    #[test]
    fn source_must_be_exactly_one() {
        let both = SourceArgs {
            input: Some("a.obj".into()),
            scene: Some("room".into()),
        };
        assert!(
            load_source(&both)
                .unwrap_err()
                .to_string()
                .contains("not both")
        );
        let none = SourceArgs {
            input: None,
            scene: None,
        };
        assert!(
            load_source(&none)
                .unwrap_err()
                .to_string()
                .starts_with("no input")
        );
        let unknown = SourceArgs {
            input: None,
            scene: Some("kitchen".into()),
        };
        assert_eq!(
            load_source(&unknown).unwrap_err().to_string(),
            "unknown scene `kitchen` (available: room, chair, cube, bunny, bunny-11k, bunny-33k, \
             bunny-99k, bunny-298k, bunny-893k)"
        );
    }
}
