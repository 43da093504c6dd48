//! A picture of a sun study: every face coloured by its exact sun-hours
//! (the heat map of `shadow sunhours -o hours.obj`), framed on the scene,
//! lit from the eye so the forms read, with the ramp's range written on it.
//!
//! ```sh
//! cargo run --release -p bsp-shadows --example sun_heatmap -- bunny-11k 51.5 -0.1 2026-06-21 10 heat.png
//! ```
//! (SCENE is a built-in scene's name, viewed and turned as the CLI stages
//! it: the bunnies stand with `y` up; or a mesh file, `z` up.)

use bsp_shadows::DVec3;
use bsp_shadows::sun::{SunSite, Up, heat_colors, study_suns, sun_hours_mean};
use shadow_raster::svg::{SvgViewpoint, ViewRequest};
use shadow_raster::{RasterScene, RenderOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let [scene, lat, lon, date, step, out] = &a[..] else {
        return Err("usage: sun_heatmap SCENE LAT LON YYYY-MM-DD STEP_MINUTES OUT.png".into());
    };
    let mesh = match shadow_scene::scene_named(scene) {
        Ok(m) => m,
        Err(_) => bsp_shadows::read_mesh(scene)?,
    };
    let staging = shadow_scene::Staging::of_scene(scene, mesh.bounds().ok_or("no faces")?);
    let y_up = staging.is_some_and(|s| s.up == Some(DVec3::Y));
    let site =
        SunSite::new(lat.parse()?, lon.parse()?).with_axes(0.0, if y_up { Up::Y } else { Up::Z });
    let step: f64 = step.parse()?;
    let suns: Vec<DVec3> = study_suns(&site, &[date.parse()?], step, 0.0)?
        .iter()
        .map(|s| s.direction)
        .collect();
    let hours = sun_hours_mean(&mesh, &suns, step / 60.0)?;
    let most = hours.iter().map(|h| h.sun_hours).fold(0.0, f64::max);
    // the picture: framed on the scene, one point light at the eye
    let (at, _) = SvgViewpoint::choose(
        ViewRequest::default(),
        &mesh.positions,
        staging,
        (720, 405),
        40.0,
    );
    let light = [svbsp::LightSpec::Point(at.eye)];
    let grid = svbsp::shared_grid(&mesh.positions, &light)?;
    let lights = svbsp::place_lights(&grid, &light)?;
    let (polys, _) = bsp_core::import_faces_par(&grid, &mesh.face_loops())?;
    let scene = RasterScene::new(&grid, polys)?;
    let camera = at.camera(mesh.bounds().ok_or("no faces")?)?;
    let colors = heat_colors(&hours, most);
    let mut picture =
        shadow_raster::render(&scene, &lights, &camera, &colors, &RenderOptions::default())?.image;
    let legend = format!(
        "{date}: 0 h (blue) to {most:.1} h (yellow) of sun, {} suns",
        suns.len()
    );
    picture.text(&legend, 10, 405 - 24, 2, [255, 255, 255]);
    std::fs::write(out, picture.encode_png())?;
    eprintln!("wrote {out}: {} faces, {} suns", hours.len(), suns.len());
    Ok(())
}
