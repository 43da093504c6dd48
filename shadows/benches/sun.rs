//! Sun studies: every face's exact sun-hours over one day (the built-in
//! room at 51.5° N on the equinox, a sun every 10 minutes: 73 suns above
//! the horizon, the runs' pieces overlaid), the sun positions alone, and
//! the built-in city block's mean hours (3,703 faces: sixteen buildings on
//! 2 m ground tiles) for the same day, uncut and in 2 × 2 tiles
//! (`--tiles 2`), and its day at 100 sensors in closed form
//! (`--exact-time`).

use std::hint::black_box;
use std::time::Duration;

use bsp_shadows::sun::{
    SunSite, day_paths, sensor_intervals, study_suns, sun_hours, sun_hours_in_tiles, sun_hours_mean,
};
use criterion::{Criterion, criterion_group, criterion_main};

fn sun(cr: &mut Criterion) {
    let mesh = shadow_scene::scene("room").expect("a built-in scene");
    let site = SunSite::new(51.5, -0.12);
    let day = [chrono::NaiveDate::from_ymd_opt(2026, 3, 21).unwrap()];
    let suns: Vec<_> = study_suns(&site, &day, 10.0, 0.0)
        .unwrap()
        .iter()
        .map(|s| s.direction)
        .collect();
    let mut g = cr.benchmark_group("sun/room equinox 10 min");
    g.sample_size(10).measurement_time(Duration::from_secs(8));
    g.bench_function("positions", |b| {
        b.iter(|| black_box(study_suns(&site, &day, 10.0, 0.0).unwrap().len()))
    });
    g.bench_function("sun-hours", |b| {
        b.iter(|| black_box(sun_hours(&mesh, &suns, 1.0 / 6.0).unwrap().len()))
    });
    g.finish();
    let city = shadow_scene::scene("city").expect("a built-in scene");
    let mut g = cr.benchmark_group("sun/city block equinox 10 min");
    g.sample_size(10).measurement_time(Duration::from_secs(10));
    g.bench_function("mean sun-hours", |b| {
        b.iter(|| black_box(sun_hours_mean(&city, &suns, 1.0 / 6.0).unwrap().len()))
    });
    // the same cut into 2 x 2 tiles, a run a tile (less memory a run)
    g.bench_function("mean sun-hours, 2 x 2 tiles", |b| {
        b.iter(|| {
            let h = sun_hours_in_tiles(&city, &suns, 1.0 / 6.0, 2, false).unwrap();
            black_box(h.len())
        })
    });
    // 100 sensors on a 10 m lattice of the ground, the day in closed form
    let sensors: Vec<glam::DVec3> = (0..100)
        .map(|i| {
            glam::DVec3::new(
                5.0 + 10.0 * f64::from(i % 10),
                5.0 + 10.0 * f64::from(i / 10),
                0.0,
            )
        })
        .collect();
    let paths = day_paths(&site, &day, 0.0).unwrap();
    g.bench_function("exact time, 100 sensors", |b| {
        b.iter(|| black_box(sensor_intervals(&city, &sensors, &paths).len()))
    });
    g.finish();
}

criterion_group!(benches, sun);
criterion_main!(benches);
