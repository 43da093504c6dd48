//! What every command reads: a mesh file or a built-in scene, and the
//! mesh snapped to a grid, imported and built into a BSP tree.

use std::path::Path;

use anyhow::{Context, Result, bail};
use bsp_core::{Grid, ImportReport, Polygon};
use bsp_shadows::prepared::Prepared;
use glam::DVec3;
use shadow_scene::{Mesh, Staging};
use svbsp::{LightSpec, PlacedLight, SoftLight, SoftSpec};

use crate::args::SourceArgs;
use crate::lights::{place_lights, shared_grid};
use crate::output::Phases;

/// Reads a mesh file: an error if it has no faces; a note on stderr
/// (unless `quiet`) if the reader skipped unknown statements.
pub(crate) fn load_mesh(path: &Path, quiet: bool) -> Result<shadow_scene::Mesh> {
    let (mesh, note) = read_mesh(path)?;
    if let Some(m) = note {
        crate::output::note(quiet, &format!("note: {m}"));
    }
    if mesh.faces.is_empty() {
        bail!("{}: no faces", path.display());
    }
    Ok(mesh)
}

/// [`load_mesh`]'s reading, printing nothing: the mesh, faces or not, and
/// the reader's note on what it skipped.
pub(crate) fn read_mesh(path: &Path) -> Result<(shadow_scene::Mesh, Option<String>)> {
    let (mesh, notes) = shadow_scene::load_notes(path)?;
    Ok((mesh, notes.message(&path.display().to_string())))
}

pub(crate) fn load_source_quiet(
    src: &SourceArgs,
    quiet: bool,
) -> Result<(shadow_scene::Mesh, String)> {
    src.check()?;
    if let Some(path) = &src.input {
        return Ok((load_mesh(path, quiet)?, path.display().to_string()));
    }
    let name = src.scene.as_deref().unwrap_or_default();
    let mesh = shadow_scene::scene_named(name).map_err(anyhow::Error::msg)?;
    Ok((mesh, format!("scene {name}")))
}

/// The message for a scene without a light.
pub(crate) const NO_LIGHT: &str = "no light: give at least one --light X,Y,Z (a point light) or \
     --sun X,Y,Z (a light at infinity); both can be repeated";

/// A scene ready to be shaded: its mesh, grid, lights and polygons.
pub(crate) struct Scene {
    pub(crate) mesh: Mesh,
    pub(crate) name: String,
    pub(crate) bounds: (DVec3, DVec3),
    /// A built-in scene's viewpoint and light.
    pub(crate) staging: Option<Staging>,
    /// No light was given: the scene's own stands in.
    pub(crate) default_light: bool,
    pub(crate) grid: Grid,
    pub(crate) lights: Vec<PlacedLight>,
    /// Where lights with extent are given: every light, for soft shadows.
    pub(crate) soft: Vec<SoftLight>,
    pub(crate) polys: Vec<Polygon>,
    pub(crate) report: ImportReport,
}

impl Scene {
    /// Loads the scene ("load"), snaps it and its point lights to one
    /// grid and imports its faces in parallel ("snap/import"). With no
    /// light given, a built-in scene's own light stands in; a scene
    /// without one is an error if `need_light`.
    pub(crate) fn load(
        source: &SourceArgs,
        (mut specs, soft): (Vec<LightSpec>, &[SoftSpec]),
        need_light: bool,
        quiet: bool,
        phases: &mut Phases,
    ) -> Result<Scene> {
        let (mesh, name) = phases.run("load", || load_source_quiet(source, quiet))?;
        let bounds = mesh
            .bounds()
            .with_context(|| format!("{name}: no vertices"))?;
        let extent = (bounds.1 - bounds.0).max_element();
        if !(extent * extent).is_finite() {
            bail!(
                "{name}: the scene spans {extent:.3e} units, so its areas do not fit in f64 (the \
                 fragments would be exact, their areas infinite); scale it below about 1e150"
            );
        }
        let staging = source.staging(bounds);
        let default_light = specs.is_empty() && soft.is_empty() && need_light;
        if default_light {
            let s = staging.with_context(|| format!("{name}: {NO_LIGHT}"))?;
            specs.push(LightSpec::Point(s.light));
        }
        let scene = phases.run("snap/import", || -> Result<Scene> {
            let grid = shared_grid(&mesh.positions, &specs, soft).with_context(|| name.clone())?;
            let (lights, soft) = place_lights(&grid, &specs, soft)?;
            let (polys, report) = bsp_shadows::import_mesh(&grid, &mesh)
                .with_context(|| format!("{name}: cannot import the faces"))?;
            Ok(Scene {
                mesh,
                name,
                bounds,
                staging,
                default_light,
                grid,
                lights,
                soft,
                polys,
                report,
            })
        })?;
        let summary = (scene.report).summary_at(&|f| line_of(&scene.mesh, f));
        if !summary.is_empty() && !quiet {
            eprintln!("note: {}: {}", scene.name, summary.trim_end());
        }
        Ok(scene)
    }

    /// The lights, as the report names them.
    pub(crate) fn light_count(&self) -> String {
        match (self.lights.len().max(self.soft.len()), self.default_light) {
            (_, true) => format!(
                "the {}'s default light ({})",
                self.name.trim_start_matches("scene "),
                crate::lights::flag(&self.lights[0].spec)
            ),
            (1, false) => "1 light".to_string(),
            (n, false) => format!("{n} lights"),
        }
    }
}

/// Snaps, imports and builds `mesh` ([`Prepared::new`]), printing the
/// import summary to stderr when faces were changed (unless `quiet`).
pub(crate) fn prepare(mesh: Mesh, name: &str, quiet: bool) -> Result<Prepared> {
    let p = Prepared::new(mesh).map_err(|e| anyhow::anyhow!(e).context(name.to_string()))?;
    let summary = p.report.summary_at(&|f| line_of(&p.mesh, f));
    if !summary.is_empty() && !quiet {
        eprint!("{name}: {summary}");
    }
    Ok(p)
}

/// The line of face `f` in its file (0: none, as in STL or a built-in
/// scene).
pub(crate) fn line_of(mesh: &Mesh, f: usize) -> usize {
    mesh.faces.get(f).map_or(0, |face| face.line)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn room_imports_without_changes() {
        let p = prepare(shadow_scene::room(), "room", false).unwrap();
        assert!(p.report.triangulated.is_empty() && p.report.dropped.is_empty());
        assert_eq!(p.report.polygons, p.mesh.faces.len());
        p.tree.sanity_check().unwrap();
        assert!(p.tree.stats().polygons >= p.report.polygons);
    }

    #[test]
    fn empty_mesh_gives_an_empty_tree() {
        let p = prepare(Mesh::default(), "empty", false).unwrap();
        assert_eq!(p.tree.stats().nodes, 0);
    }

    #[test]
    fn source_must_be_exactly_one() {
        let both = SourceArgs {
            input: Some("a.obj".into()),
            scene: Some("room".into()),
        };
        assert!(
            load_source_quiet(&both, false)
                .unwrap_err()
                .to_string()
                .contains("not both")
        );
        let none = SourceArgs {
            input: None,
            scene: None,
        };
        assert!(
            load_source_quiet(&none, false)
                .unwrap_err()
                .to_string()
                .starts_with("no input")
        );
        let unknown = SourceArgs {
            input: None,
            scene: Some("kitchen".into()),
        };
        assert_eq!(
            load_source_quiet(&unknown, false).unwrap_err().to_string(),
            "unknown scene `kitchen` (available: room, chair, cube, bunny, bunny-11k, bunny-33k, \
             bunny-99k, bunny-298k, bunny-893k, city, city-100k)"
        );
    }
}
