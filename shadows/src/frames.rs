//! The frames of the real-time pipeline ([`tiling::Dynamic`]) as files:
//! the frame's whole scene as OBJ, its fragments as JSON (the schema of
//! the exact shadows' files), and pictures of the shaded frame as SVG (the
//! painter's order of a BSP tree of the frame's polygons) and PNG
//! (rasterized from the exact fragments).

use std::io::{self, Write};

use bsp_core::{BspTree, BuildOptions};
use glam::{DMat4, DVec3};
use shadow_raster::svg::{SvgFragment, SvgView, SvgViewpoint};
use shadow_raster::{RasterScene, Renderer};
use shadow_scene::Mesh;
use svbsp::PlacedLight;
use svbsp::export::{FragmentFile, FragmentFormat, world_vertices};
use tiling::{Dynamic, Frame};

use crate::Error;

/// The frame's whole scene in input units, faces numbered as the frame's
/// fragments are (`statics` first, then `moving` moved by `m`, its groups
/// prefixed `moving_`): every vertex is the frame's grid point mapped
/// back to input units, so the mesh is exactly the scene the frame's
/// shadows were computed for.
pub fn frame_mesh(d: &Dynamic, statics: &Mesh, moving: &Mesh, m: &DMat4) -> Mesh {
    let grid = d.grid();
    let snap = |p: DVec3| {
        grid.snap(p)
            .map(|g| grid.to_world(g.map(f64::from)))
            .unwrap_or(p)
    };
    let mut mesh = Mesh {
        positions: statics.positions.iter().map(|&p| snap(p)).collect(),
        faces: statics.faces.clone(),
        groups: statics.groups.clone(),
    };
    mesh.append(moving, "moving_", |p| snap(m.transform_point3(p)));
    mesh
}

/// Writes frame `k`'s scene ([`frame_mesh`]) as OBJ, after comments that
/// say which faces are static and where the lights are.
pub fn write_frame_obj(
    out: &mut dyn Write,
    d: &Dynamic,
    scene: &Mesh,
    k: u32,
    lights: &[PlacedLight],
) -> io::Result<()> {
    writeln!(
        out,
        "# shadow animate: frame {k}, {} static faces then {} moving ones; vertices are the \
         frame's grid points",
        d.static_faces(),
        scene.faces.len() - d.static_faces()
    )?;
    for (i, l) in lights.iter().enumerate() {
        let kind = match l.light {
            svbsp::Light::Point(_) => "point light at",
            svbsp::Light::Directional(_) => "sun toward",
        };
        let p = l.world;
        writeln!(out, "# light {i}: {kind} {},{},{}", p.x, p.y, p.z)?;
    }
    shadow_scene::write_obj(scene, out)
}

/// Writes the frame's fragments as a JSON document.
pub fn write_frame_json(
    out: &mut dyn Write,
    d: &Dynamic,
    frame: &Frame,
    lights: &[PlacedLight],
) -> io::Result<()> {
    let batch = d.fragments(frame);
    let (format, faces) = (FragmentFormat::Json, d.faces());
    FragmentFile::of_batch(out, format, lights, faces, (&batch, d.grid()))?;
    Ok(())
}

/// The frame rasterized from its exact fragments, as PNG bytes, seen
/// from `view` (framed on the static scene's bounds), one colour per face
/// (static faces, then the moving object's). `renderer` keeps its buffers
/// from frame to frame.
pub fn frame_png(
    renderer: &mut Renderer,
    (d, frame): (&Dynamic, &Frame),
    colors: &[DVec3],
    lights: &[PlacedLight],
    view: &SvgViewpoint,
) -> Result<Vec<u8>, Error> {
    let scene = RasterScene::new(d.grid(), d.frame_polygons(frame)).map_err(Error::Raster)?;
    let camera = view.camera(d.static_bounds()).map_err(Error::Raster)?;
    let batch = d.fragments(frame);
    let out = renderer
        .render_fragments(&scene, &batch, lights, &camera, colors)
        .map_err(Error::Raster)?;
    Ok(out.image.encode_png())
}

/// The frame drawn as SVG: a BSP tree of the frame's polygons gives the
/// painter's order, and each face's fragments are cut to the tree's
/// pieces of the face. `scene` is the frame's [`frame_mesh`].
pub fn frame_svg(
    (d, frame): (&Dynamic, &Frame),
    scene: &Mesh,
    lights: &[PlacedLight],
    at: &SvgViewpoint,
) -> Result<String, Error> {
    let grid = d.grid();
    let tree = BspTree::build(d.frame_polygons(frame), &BuildOptions::default());
    let batch = d.fragments(frame);
    let world = world_vertices(&batch, grid).map_err(Error::Export)?;
    let frags = SvgFragment::of_faces_in_tree(&tree, grid, &batch, &world, d.faces());
    let what = "shadow animate";
    let r = SvgView::mesh_fragments(grid, scene, at, &tree, lights, &frags, what)
        .map_err(Error::Raster)?;
    Ok(r.svg)
}
