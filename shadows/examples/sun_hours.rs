//! Sun-hours of every face of a mesh over one day, as CSV on stdout
//! (`face,area,sun_hours,min_hours,max_hours`), until `shadow sunhours`
//! lands: the suns at the midpoints of `STEP`-minute intervals
//! (`bsp_shadows::sun::study_suns`), each face's exact lit part for each
//! (`bsp_shadows::sun::sun_hours`). Scene axes: +z up, +y north.
//!
//! ```text
//! cargo run --release -p bsp-shadows --example sun_hours -- MESH LAT LON 2026-03-21 [STEP] [UTC_OFFSET]
//! ```

use bsp_shadows::sun::{SunSite, study_suns, sun_hours};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().skip(1).collect();
    if a.len() < 4 {
        return Err(
            "usage: sun_hours MESH LAT LON YYYY-MM-DD [STEP_MINUTES] [UTC_OFFSET_HOURS]".into(),
        );
    }
    let mesh = bsp_shadows::read_mesh(&a[0])?;
    let site = SunSite::new(a[1].parse()?, a[2].parse()?);
    let date: chrono::NaiveDate = a[3].parse()?;
    let step: f64 = a.get(4).map_or(Ok(10.0), |s| s.parse())?;
    let offset: f64 = a.get(5).map_or(Ok(0.0), |s| s.parse())?;
    let t = std::time::Instant::now();
    let suns: Vec<_> = study_suns(&site, &[date], step, offset)?
        .iter()
        .map(|s| s.direction)
        .collect();
    let hours = sun_hours(&mesh, &suns, step / 60.0)?;
    println!("face,area,sun_hours,min_hours,max_hours");
    for (f, h) in hours.iter().enumerate() {
        println!(
            "{f},{},{},{},{}",
            h.area, h.sun_hours, h.min_hours, h.max_hours
        );
    }
    eprintln!(
        "{} faces, {} suns above the horizon, {:.2} s",
        hours.len(),
        suns.len(),
        t.elapsed().as_secs_f64()
    );
    Ok(())
}
