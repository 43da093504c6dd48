use super::*;
use crate::sun::tests::{blocked, yard, yard_sensors};
use crate::sun::{parse_time, sensor_hours, sun_position};

fn day(y: i32, m: u32, d: u32) -> NaiveDate {
    NaiveDate::from_ymd_opt(y, m, d).unwrap()
}

/// The angle between two unit vectors, degrees.
fn degrees(a: DVec3, b: DVec3) -> f64 {
    a.dot(b).clamp(-1.0, 1.0).acos().to_degrees()
}

#[test]
fn the_path_follows_spa_through_the_day() {
    let turned = SunSite {
        up: Up::Y,
        ..SunSite::new(51.48, 0.0).with_axes(30.0, Up::Y)
    };
    let cases = [
        (SunSite::new(51.48, 0.0), day(2026, 3, 21), 0.0),
        (turned, day(2026, 3, 21), 1.0),
        (SunSite::new(-33.9, 18.4), day(2026, 6, 21), 2.0),
        (SunSite::new(40.4, -3.7), day(2026, 12, 21), 1.0),
    ];
    for (site, date, offset) in cases {
        let path = SunPath::of_day(&site, date, offset).unwrap();
        for hour in 0..24 {
            let time = format!("{date}T{hour:02}:00:00+0{offset}:00");
            let spa = sun_position(&site, &parse_time(&time).unwrap()).unwrap();
            if spa.elevation_deg < 10.0 {
                continue; // refraction apart, the model holds down to the horizon
            }
            let d = path.direction(f64::from(hour));
            // the declination's and the equation of time's drift in half a day
            assert!(
                degrees(d, spa.direction) < 0.3,
                "{date} {hour}h: {d} {spa:?}"
            );
            assert!(path.is_up(f64::from(hour)));
        }
    }
}

#[test]
fn intervals_agree_with_one_second_sampling_of_the_model() {
    let mesh = yard();
    let tris = triangles(&mesh);
    assert_eq!(tris.len(), 12);
    let path = SunPath::of_day(&SunSite::new(51.48, 0.0), day(2026, 3, 21), 0.0).unwrap();
    let sensors = yard_sensors();
    let exact = sensor_intervals(&mesh, &sensors, std::slice::from_ref(&path));
    for (x, on) in sensors.iter().zip(&exact) {
        let on = &on[0];
        let mut seconds = 0;
        for s in 0..86_400 {
            let hour = (f64::from(s) + 0.5) / 3600.0;
            let d = path.direction(hour);
            let (up, hidden) = (path.is_up(hour), tris.iter().any(|t| hides(*x, d, t)));
            // the triangles' test against the box's slab test (for suns up)
            assert!(!up || hidden == blocked(*x, d), "{x} at {hour}h");
            let lit = up && !hidden;
            seconds += u32::from(lit);
            let inside = on.iter().any(|&(a, b)| a < hour && hour < b);
            let near_an_end = on
                .iter()
                .any(|&(a, b)| (hour - a).abs() < 1.0 / 3600.0 || (hour - b).abs() < 1.0 / 3600.0);
            assert!(
                inside == lit || near_an_end,
                "{x} at {hour}h: {on:?} {lit} {up}"
            );
        }
        let hours: f64 = on.iter().map(|(a, b)| b - a).sum();
        let sampled = f64::from(seconds) / 3600.0;
        let ends = 2.0 * on.len() as f64 / 3600.0;
        assert!(
            (hours - sampled).abs() <= ends,
            "{x}: {hours} against {sampled}"
        );
    }
    // the ground north of the box is shaded some of the day, the roof never
    let hours = interval_hours(&exact);
    let roof = hours[5];
    assert!(
        hours[1] < roof - 2.0 && hours.iter().all(|&h| h <= roof),
        "{hours:?}"
    );
    assert!((11.5..12.5).contains(&roof), "{roof}");
}

/// The geometric suns (no refraction, as the model) at the middles of a
/// day's minutes, above the horizon, in the scene's axes.
fn minute_suns(site: &SunSite, date: NaiveDate) -> Vec<DVec3> {
    let midnight = parse_time(&format!("{date}T00:00:00Z")).unwrap();
    (0..1440)
        .filter_map(|m| {
            let t = midnight + chrono::Duration::seconds(60 * m + 30);
            let (az, el) = geometric_position(site, &t).unwrap();
            let (az, el) = (az.to_radians(), el.to_radians());
            let d = DVec3::new(az.sin() * el.cos(), az.cos() * el.cos(), el.sin());
            (el > 0.0).then_some(d)
        })
        .collect()
}

/// The yard at Greenwich on the equinox and the solstice: the mesh, the
/// suns of every minute, the days' paths.
fn two_days_of_minutes() -> (crate::Mesh, Vec<DVec3>, Vec<SunPath>) {
    let site = SunSite::new(51.48, 0.0);
    let days = [day(2026, 3, 21), day(2026, 6, 21)];
    let suns: Vec<DVec3> = days.iter().flat_map(|&d| minute_suns(&site, d)).collect();
    (yard(), suns, day_paths(&site, &days, 0.0).unwrap())
}

/// Each sensor's exact hours within the minute steps' bound of its
/// sampled ones: half a step at each end of each interval, and the
/// model's seconds.
fn assert_near_minutes(exact: &[Vec<Vec<Interval>>], sampled: &[f64], what: &str) {
    for ((on, e), s) in exact.iter().zip(interval_hours(exact)).zip(sampled) {
        let ends: usize = on.iter().map(Vec::len).sum();
        let bound = ends as f64 * (0.5 + 0.1) / 60.0;
        assert!(
            (e - s).abs() <= bound,
            "{what}: {e} against {s} ({ends} ends)"
        );
    }
}

#[test]
fn exact_hours_agree_with_the_engine_sampled_every_minute() {
    let (mesh, suns, paths) = two_days_of_minutes();
    // (sensors on the ground, as the engine snaps them)
    let sensors = yard_sensors();
    let sampled = sensor_hours(&mesh, &sensors, &suns, 1.0 / 60.0).unwrap();
    let exact = sensor_intervals(&mesh, &sensors, &paths);
    assert_near_minutes(&exact, &sampled, "no normal");
}

/// Sensors facing a way: the exact intervals hold only the suns in
/// front of the surface, as the engine's minute-by-minute count of the
/// same sensors says (within the ends' half steps); facing up, the same
/// intervals as with no normal, facing down none.
#[test]
fn exact_hours_of_sensors_facing_a_way_agree_with_the_engine() {
    let (mesh, suns, paths) = two_days_of_minutes();
    let points = yard_sensors();
    let plain = sensor_intervals(&mesh, &points, &paths);
    for n in [DVec3::Z, DVec3::NEG_Z, DVec3::X, DVec3::new(-0.2, 1.0, 0.5)] {
        let sensors: Vec<Sensor> = (points.iter())
            .map(|&position| Sensor {
                position,
                normal: Some(n),
            })
            .collect();
        let sampled = crate::sun::sensor_hours_facing(&mesh, &sensors, &suns, 1.0 / 60.0).unwrap();
        let exact = sensor_intervals_facing(&mesh, &sensors, &paths);
        assert_near_minutes(&exact, &sampled, &format!("facing {n}"));
        match n {
            DVec3::Z => assert_eq!(exact, plain),
            DVec3::NEG_Z => assert!(exact.iter().flatten().all(Vec::is_empty), "{exact:?}"),
            _ => {
                let (e, p) = (interval_hours(&exact), interval_hours(&plain));
                assert!(e[5] > 1.0 && e[5] < p[5] - 1.0, "{n}: {e:?} {p:?}");
            }
        }
    }
}

#[test]
fn polar_day_and_polar_night() {
    let ground = crate::Mesh {
        positions: vec![
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(1.0, -1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(-1.0, 1.0, 0.0),
        ],
        faces: vec![shadow_scene::Face {
            vertices: vec![0, 1, 2, 3],
            line: 0,
            group: 0,
        }],
        groups: vec!["ground".into()],
    };
    let site = SunSite::new(80.0, 15.0);
    let paths = day_paths(&site, &[day(2026, 6, 21), day(2026, 12, 21)], 1.0).unwrap();
    let on = sensor_intervals(&ground, &[DVec3::new(0.0, 0.0, 0.0)], &paths);
    assert_eq!(on[0][0], [(0.0, 24.0)]);
    assert_eq!(on[0][1], []);
    assert_eq!(interval_hours(&on), [24.0]);
}

#[test]
fn interval_lists() {
    let p = [(0.0, 2.0), (3.0, 5.0)];
    assert_eq!(intersect(&p, &[(1.0, 4.0)]), [(1.0, 2.0), (3.0, 4.0)]);
    assert_eq!(
        merged(vec![(0.0, 1.0), (0.5, 2.0), (2.0, 3.0), (4.0, 5.0)]),
        [(0.0, 3.0), (4.0, 5.0)]
    );
    assert_eq!(
        subtract(&p, &[(1.0, 3.5), (4.0, 4.5)]),
        [(0.0, 1.0), (3.5, 4.0), (4.5, 5.0)]
    );
    assert_eq!(subtract(&p, &[]), p);
}
