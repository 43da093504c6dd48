//! A picture of a sun study: every face coloured by its exact sun-hours
//! (the heat map of `shadow sunhours -o hours.png`), framed on the scene,
//! lit from the eye so the forms read, with the ramp along the bottom.
//!
//! ```sh
//! cargo run --release -p bsp-shadows --example sun_heatmap -- bunny-11k 51.5 -0.1 2026-06-21 10 heat.png
//! ```
//! (SCENE is a built-in scene's name, viewed and turned as the CLI stages
//! it: the bunnies stand with `y` up; or a mesh file, `z` up.)

use bsp_shadows::DVec3;
use bsp_shadows::sun::{HeatView, SunSite, Up, hours_png, study_suns, sun_hours_mean};

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
    let up = match staging.and_then(|s| s.up) {
        Some(DVec3::Y) => Up::Y,
        _ => Up::Z,
    };
    let site = SunSite::new(lat.parse()?, lon.parse()?).with_axes(0.0, up);
    let step: f64 = step.parse()?;
    let suns: Vec<DVec3> = study_suns(&site, &[date.parse()?], step, 0.0)?
        .iter()
        .map(|s| s.direction)
        .collect();
    let hours = sun_hours_mean(&mesh, &suns, step / 60.0)?;
    let png = hours_png(&mesh, &hours, suns.len(), HeatView { staging, up })?;
    std::fs::write(out, png)?;
    eprintln!(
        "wrote {out}: {} faces, {} suns on {date}",
        hours.len(),
        suns.len()
    );
    Ok(())
}
