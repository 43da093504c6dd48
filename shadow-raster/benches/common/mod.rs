//! The bench's scene, shared with `examples/frame_dump.rs`: a built-in
//! scanned bunny at the default camera and light of `shadow render`.

use glam::DVec3;
use shadow_raster::RasterScene;
use svbsp::{LightSpec, place_lights, shared_grid};

pub(crate) struct Setup {
    pub(crate) scene: RasterScene,
    pub(crate) lights: Vec<svbsp::PlacedLight>,
    pub(crate) eye: DVec3,
    pub(crate) target: DVec3,
}

pub(crate) fn bunny(name: &str, sun: bool) -> Setup {
    let mesh = shadow_scene::scene(name).expect("a built-in scene");
    let (lo, hi) = mesh.bounds().unwrap();
    let (c, half) = ((lo + hi) * 0.5, (hi - lo).max_element() * 0.5);
    let spec = if sun {
        LightSpec::Sun(DVec3::new(3.0, 10.0, 2.0))
    } else {
        LightSpec::Point(c + DVec3::Y * 1.6 * half + DVec3::X * 0.4 * half + DVec3::Z * 0.6 * half)
    };
    let grid = shared_grid(&mesh.positions, &[spec]).unwrap();
    let lights = place_lights(&grid, &[spec]).unwrap();
    let (polys, _) = bsp_core::import_faces_par(&grid, &mesh.face_loops()).unwrap();
    Setup {
        scene: RasterScene::new(&grid, polys).unwrap(),
        lights,
        eye: c + DVec3::new(0.75 * half, 0.6 * half, 1.7 * half),
        target: c - DVec3::Y * 0.25 * half,
    }
}
