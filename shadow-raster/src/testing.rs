//! Scenes for the unit tests.

use glam::DVec3;
use svbsp::{LightSpec, place_lights, shared_grid};

use crate::{Camera, RasterScene, SceneLight};

/// Boxes standing on a ground, seen from a few places, lit by a point
/// light and a sun.
pub(crate) fn scenes() -> Vec<(RasterScene, Vec<SceneLight>, Vec<Camera>)> {
    use bsp_fixtures::cuboid;
    let mut faces = vec![vec![
        DVec3::new(-8.0, -8.0, 0.0),
        DVec3::new(8.0, -8.0, 0.0),
        DVec3::new(8.0, 8.0, 0.0),
        DVec3::new(-8.0, 8.0, 0.0),
    ]];
    faces.extend(cuboid(
        DVec3::new(-1.0, -1.0, 0.0),
        DVec3::new(1.0, 1.5, 2.0),
    ));
    faces.extend(cuboid(DVec3::new(2.0, 0.5, 1.0), DVec3::new(3.0, 1.0, 4.0)));
    faces.extend(cuboid(
        DVec3::new(-4.0, 2.0, 0.0),
        DVec3::new(-3.0, 5.0, 0.5),
    ));
    let pts: Vec<DVec3> = faces.concat();
    [
        LightSpec::Point(DVec3::new(0.5, -1.5, 6.0)),
        LightSpec::Point(DVec3::new(1.0, 0.2, 1.5)),
        LightSpec::Sun(DVec3::new(1.0, -2.0, 3.0)),
    ]
    .into_iter()
    .map(|spec| {
        let grid = shared_grid(&pts, &[spec]).unwrap();
        let lights = place_lights(&grid, &[spec])
            .unwrap()
            .iter()
            .map(SceneLight::from_placed)
            .collect();
        let (polys, _) = bsp_core::import_faces(&grid, faces.iter().map(Vec::as_slice)).unwrap();
        let cams = [
            DVec3::new(6.0, -9.0, 7.0),
            DVec3::new(-7.0, 3.0, 2.0),
            DVec3::new(0.5, 0.0, 9.0),
        ]
        .into_iter()
        .map(|eye| Camera::look_at(eye, DVec3::ZERO, DVec3::Z, 55.0, 96, 64).unwrap())
        .collect();
        (RasterScene::new(&grid, polys).unwrap(), lights, cams)
    })
    .collect()
}
