//! Integration tests of `shadow-raster`: one test binary, one module per
//! concern.

mod hsr;
mod shadows;

use bsp_core::import_faces;
use glam::DVec3;
use shadow_raster::{Camera, RasterScene};
use shadow_scene::Mesh;
use svbsp::{LightSpec, place_lights, shared_grid};

/// A mesh on one grid with its lights.
pub(crate) struct Setup {
    pub(crate) scene: RasterScene,
    pub(crate) lights: Vec<svbsp::PlacedLight>,
}

pub(crate) fn setup(mesh: &Mesh, specs: &[LightSpec]) -> Setup {
    let grid = shared_grid(&mesh.positions, specs).unwrap();
    let lights = place_lights(&grid, specs).unwrap();
    let loops = mesh.face_loops();
    let (polys, _) = import_faces(&grid, loops.iter().map(Vec::as_slice)).unwrap();
    Setup {
        scene: RasterScene::new(&grid, polys).unwrap(),
        lights,
    }
}

/// The room with its default light (as `shadow render --scene room`).
pub(crate) fn room() -> Setup {
    setup(
        &shadow_scene::room(),
        &[LightSpec::Point(DVec3::new(0.9, 0.3, 2.45))],
    )
}

pub(crate) fn room_camera(w: u32, h: u32) -> Camera {
    Camera::look_at(
        DVec3::new(3.3, -7.4, 4.3),
        DVec3::new(-0.15, 0.3, 0.45),
        DVec3::Z,
        50.0,
        w,
        h,
    )
    .unwrap()
}

/// The scanned bunny on its ground with the benches' key light, and a
/// camera that shows it (as `shadow render --scene bunny`).
pub(crate) fn bunny(name: &str, w: u32, h: u32) -> (Setup, Camera) {
    let mesh = shadow_scene::scene(name).unwrap();
    let (lo, hi) = mesh.bounds().unwrap();
    let (c, half) = ((lo + hi) * 0.5, (hi - lo).max_element() * 0.5);
    let light = c + DVec3::Y * 1.6 * half + DVec3::X * 0.4 * half + DVec3::Z * 0.6 * half;
    let s = setup(&mesh, &[LightSpec::Point(light)]);
    let cam = Camera::look_at(
        c + DVec3::new(0.75 * half, 0.6 * half, 1.7 * half),
        c - DVec3::Y * 0.25 * half,
        DVec3::Y,
        50.0,
        w,
        h,
    )
    .unwrap();
    (s, cam)
}

/// A face list as a mesh.
pub(crate) fn mesh(faces: &[Vec<DVec3>]) -> Mesh {
    let mut m = Mesh::default();
    m.groups.push("default".into());
    for f in faces {
        let first = m.positions.len() as u32;
        m.positions.extend_from_slice(f);
        m.faces.push(shadow_scene::Face {
            vertices: (first..first + f.len() as u32).collect(),
            line: 0,
            group: 0,
        });
    }
    m
}

/// A closed box `[lo, hi]`, faces counter-clockwise from outside.
pub(crate) fn cuboid(lo: DVec3, hi: DVec3) -> Vec<Vec<DVec3>> {
    bsp_fixtures::cuboid(lo, hi)
}

/// Share of pixels where two masks differ.
pub(crate) fn disagreement(a: &[u8], b: &[u8]) -> f64 {
    a.iter().zip(b).filter(|(x, y)| x != y).count() as f64 / a.len() as f64
}
