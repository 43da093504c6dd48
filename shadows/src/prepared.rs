//! A mesh ready to be looked at: snapped to a grid fitted to it, its
//! faces imported and built into a BSP tree, and its picture drawn in the
//! tree's painter's order (what `shadow view`, `stats` and `demo` do).

use std::time::{Duration, Instant};

use bsp_core::{BspTree, BuildOptions, Grid, ImportReport, import_faces};
use shadow_raster::RasterError;
use shadow_raster::svg::{SvgPicture, SvgView, SvgViewpoint};
use shadow_scene::Mesh;

use crate::Error;

/// A mesh with its grid, its import report and its BSP tree.
#[derive(Debug)]
pub struct Prepared {
    /// The mesh.
    pub mesh: Mesh,
    /// The grid fitted to its positions.
    pub grid: Grid,
    /// What snapping did to the faces.
    pub report: ImportReport,
    /// The tree of the faces (each polygon tagged with its face).
    pub tree: BspTree,
    /// Wall time of snapping and importing the faces.
    pub import_time: Duration,
    /// Wall time of the tree's build.
    pub build_time: Duration,
}

impl Prepared {
    /// Snaps `mesh` to a grid fitted to its positions, imports its faces
    /// (each tagged with its index) and builds the tree.
    pub fn new(mesh: Mesh) -> Result<Prepared, Error> {
        let grid = Grid::fit_points(&mesh.positions).map_err(Error::Import)?;
        let start = Instant::now();
        let loops = mesh.face_loops();
        let (polys, report) =
            import_faces(&grid, loops.iter().map(Vec::as_slice)).map_err(Error::Import)?;
        let import_time = start.elapsed();
        let start = Instant::now();
        let tree = BspTree::build(polys, &BuildOptions::default());
        Ok(Prepared {
            mesh,
            grid,
            report,
            tree,
            import_time,
            build_time: start.elapsed(),
        })
    }

    /// The figures of `shadow stats`: the input `name`, its faces and
    /// polygons, the tree's size and depth, the grid step and the times.
    pub fn stats_text(&self, name: &str) -> String {
        let t = self.tree.stats();
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        format!(
            "input:           {name}\n\
             faces:           {}; {}\n\
             bsp polygons:    {} after splitting\n\
             nodes:           {}\n\
             depth:           {}\n\
             cells:           {} in, {} out\n\
             grid step:       {}\n\
             import time:     {:.2} ms\n\
             build time:      {:.2} ms\n",
            self.mesh.faces.len(),
            self.report.counts(),
            t.polygons,
            t.nodes,
            t.depth,
            t.in_cells,
            t.out_cells,
            self.grid.step_text(),
            ms(self.import_time),
            ms(self.build_time)
        )
    }

    /// The tree's polygons drawn back to front from `at`, in the faces'
    /// colours; [`RasterError::EmptyScene`] for a mesh without faces.
    pub fn draw(&self, at: &SvgViewpoint) -> Result<SvgPicture, Error> {
        let bounds = self.mesh.bounds();
        let bounds = bounds
            .filter(|_| !self.mesh.faces.is_empty())
            .ok_or(Error::Raster(RasterError::EmptyScene))?;
        let view = SvgView::new(&self.grid, bounds, at).map_err(Error::Raster)?;
        let colors = shadow_scene::face_colors(&self.mesh);
        Ok(view.polygons(&self.tree, &self.grid, &colors))
    }
}
