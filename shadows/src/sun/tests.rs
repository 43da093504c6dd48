//! The sun studies' tests: positions, a yard's hours, files, regions.

use super::*;

/// NREL's reference case (Reda & Andreas 2004, table A4.1): Golden,
/// Colorado, 17 October 2003 12:30:30 local standard time (UTC−7),
/// 1830.14 m, 820 hPa, 11 °C, ΔT 67 s: topocentric zenith 50.11162°,
/// azimuth 194.34024°.
#[test]
fn nrels_reference_case() {
    let site = SunSite {
        height: 1830.14,
        air: Some((820.0, 11.0)),
        delta_t: Some(67.0),
        ..SunSite::new(39.742476, -105.1786)
    };
    let time = parse_time("2003-10-17T12:30:30-07:00").unwrap();
    let p = sun_position(&site, &time).unwrap();
    assert!((p.azimuth_deg - 194.34024).abs() < 1e-4, "{p:?}");
    assert!((90.0 - p.elevation_deg - 50.11162).abs() < 1e-4, "{p:?}");
    // south-south-west and up, in the default axes
    let d = p.direction;
    assert!(d.y < 0.0 && d.x < 0.0 && d.z > 0.0 && (d.length() - 1.0).abs() < 1e-12);
}

#[test]
fn axes_and_north() {
    let time = parse_time("2026-03-21T12:00:00Z").unwrap();
    // at noon on the equinox at Greenwich, the sun stands south, high
    let p = sun_position(&SunSite::new(51.48, 0.0), &time).unwrap();
    // (the equation of time: solar noon is at about 12:07)
    assert!((p.azimuth_deg - 180.0).abs() < 3.0, "{p:?}");
    assert!(p.direction.y < -0.5 && p.direction.x.abs() < 0.05, "{p:?}");
    // y up: north is -z, so the southern sun is toward +z
    let y_up = SunSite {
        up: Up::Y,
        ..SunSite::new(51.48, 0.0)
    };
    let q = sun_position(&y_up, &time).unwrap();
    assert!(q.direction.z > 0.5 && q.direction.y > 0.5, "{q:?}");
    // north turned by 90 degrees: south lies along -x
    let turned = SunSite {
        north_deg: 90.0,
        ..SunSite::new(51.48, 0.0)
    };
    let r = sun_position(&turned, &time).unwrap();
    assert!(r.direction.x < -0.5, "{r:?}");
    assert!(parse_time("2026-03-21 12:00").is_err());
    let far = SunSite::new(95.0, 0.0);
    assert!(
        sun_position(&far, &time)
            .unwrap_err()
            .to_string()
            .contains("atitude")
    );
}

/// A ground with a box on it (the box's faces after the ground's).
pub(super) fn yard() -> crate::Mesh {
    let (b, h) = (1.0, 2.0);
    let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    let positions = vec![
        p(-10.0, -10.0, 0.0),
        p(10.0, -10.0, 0.0),
        p(10.0, 10.0, 0.0),
        p(-10.0, 10.0, 0.0),
        p(-b, -b, 0.0),
        p(b, -b, 0.0),
        p(b, b, 0.0),
        p(-b, b, 0.0),
        p(-b, -b, h),
        p(b, -b, h),
        p(b, b, h),
        p(-b, b, h),
    ];
    let faces = [
        vec![0, 1, 2, 3],
        vec![8, 9, 10, 11],
        vec![4, 5, 9, 8],
        vec![5, 6, 10, 9],
        vec![6, 7, 11, 10],
        vec![7, 4, 8, 11],
    ];
    crate::Mesh {
        positions,
        faces: faces
            .into_iter()
            .map(|vertices| crate::Face {
                vertices,
                line: 0,
                group: 0,
            })
            .collect(),
        groups: vec!["default".into()],
    }
}

/// Whether the ray from `p` toward `d` meets the box `[-1, 1]² × [0, 2]`
/// (slab test; `p` on the ground outside the box).
pub(super) fn blocked(p: DVec3, d: DVec3) -> bool {
    let (lo, hi) = (DVec3::new(-1.0, -1.0, 0.0), DVec3::new(1.0, 1.0, 2.0));
    let (mut t0, mut t1) = (1e-9f64, f64::INFINITY);
    for k in 0..3 {
        if d[k] == 0.0 {
            if p[k] < lo[k] || p[k] > hi[k] {
                return false;
            }
            continue;
        }
        let (a, b) = ((lo[k] - p[k]) / d[k], (hi[k] - p[k]) / d[k]);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    t0 < t1
}

/// Points on the yard's ground off the shadows' edges, then one above
/// the roof's middle.
pub(super) fn yard_sensors() -> Vec<DVec3> {
    [
        (0.0, -1.5),
        (1.5, 1.5),
        (-3.0, 2.0),
        (0.2, 2.5),
        (-1.2, -1.2),
    ]
    .iter()
    .map(|&(x, y)| DVec3::new(x, y, 0.0))
    .chain([DVec3::new(0.0, 0.0, 2.5)])
    .collect()
}

/// The yard on the equinox at Greenwich, a sun every 8 minutes (more
/// than one run takes): the mesh, the suns, the step, all suns' hours.
fn equinox_study() -> (crate::Mesh, Vec<DVec3>, f64, f64) {
    let site = SunSite::new(51.48, 0.0);
    let day = [chrono::NaiveDate::from_ymd_opt(2026, 3, 21).unwrap()];
    let suns: Vec<DVec3> = study_suns(&site, &day, 8.0, 0.0)
        .unwrap()
        .iter()
        .map(|s| s.direction)
        .collect();
    assert!(suns.len() > svbsp::MAX_LIGHTS, "{}", suns.len());
    let step = 8.0 / 60.0;
    let full = suns.len() as f64 * step;
    (yard(), suns, step, full)
}

#[test]
fn a_day_of_suns_and_the_hours_of_a_yard() {
    let site = SunSite::new(51.48, 0.0);
    let day = [chrono::NaiveDate::from_ymd_opt(2026, 3, 21).unwrap()];
    let hourly = study_suns(&site, &day, 60.0, 0.0).unwrap();
    assert!((11..=13).contains(&hourly.len()), "{}", hourly.len());
    assert!(study_suns(&site, &day, 0.0, 0.0).is_err());
    // a step under a second is refused at once (1e-9 minutes hung,
    // making 1.4e12 suns)
    for tiny in [1e-9, 0.0166, -5.0, f64::NAN, 1441.0] {
        let e = study_suns(&site, &day, tiny, 0.0).unwrap_err().to_string();
        assert!(e.contains("from one second (0.0167) to 1440"), "{e}");
    }
    let offset = study_suns(&site, &day, 60.0, 30.0).unwrap_err().to_string();
    assert!(
        offset.contains("30 hours: it must lie strictly between -24 and 24"),
        "{offset}"
    );
    // (NaN was taken for 0)
    let nan = study_suns(&site, &day, 60.0, f64::NAN)
        .unwrap_err()
        .to_string();
    assert!(nan.contains("NaN hours: it must lie strictly"), "{nan}");
    // true north must be an angle (NaN said "the sun direction is zero")
    for north in [f64::NAN, 1e300, -361.0] {
        let turned = site.with_axes(north, Up::Z);
        let e = study_suns(&turned, &day, 60.0, 0.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("give an angle from -360 to 360"), "{e}");
    }
    // a last day the sun's model does not reach fails at once, naming it
    let far = [day[0], chrono::NaiveDate::from_ymd_opt(3001, 1, 1).unwrap()];
    let e = study_suns(&site, &far, 60.0, 0.0).unwrap_err().to_string();
    assert!(e.starts_with("3001-01-01T12:00:00+00:00: "), "{e}");
    let (mesh, suns, step, full) = equinox_study();
    let hours = sun_hours(&mesh, &suns, step).unwrap();
    // the roof sees every sun
    let roof = &hours[1];
    assert!(
        (roof.sun_hours - full).abs() < 1e-9 && roof.min_hours == full,
        "{roof:?}"
    );
    assert_eq!(roof.max_hours, full);
    // the ground: its far corners see every sun, points by the box fewer
    let g = &hours[0];
    assert_eq!(g.max_hours, full);
    assert!(g.min_hours < g.sun_hours && g.sun_hours < full, "{g:?}");
    // every point's own count lies between the least and the most
    for &p in &yard_sensors()[..5] {
        let own = suns.iter().filter(|&&d| !blocked(p, d)).count() as f64 * step;
        assert!(
            g.min_hours - 1e-9 <= own && own <= g.max_hours + 1e-9,
            "{own} at {p}"
        );
    }
    // how much of the ground gets how many hours: all of it at least
    // none, less and less as the hours grow, none beyond the day
    let a = |h: f64| g.area_with_at_least(h);
    assert!(
        (a(0.0) - g.area).abs() < 1e-9 * g.area,
        "{} {}",
        a(0.0),
        g.area
    );
    assert!(a(0.0) >= a(3.0) && a(3.0) >= a(full) && a(full) > 0.0 && a(full + 1.0) == 0.0);
    assert!((roof.area_with_at_least(full) - roof.area).abs() < 1e-9);
    let groups = groups_in_sun(&mesh, &hours, full);
    assert_eq!(groups.len(), 1); // one group: the yard and the box
    // sensors: a point's own count, exactly (points off the shadows'
    // edges), and the roof's middle sees every sun
    let points = yard_sensors();
    let at = sensor_hours(&mesh, &points, &suns, step).unwrap();
    for (p, h) in points.iter().zip(&at) {
        let own = suns.iter().filter(|&&d| !blocked(*p, d)).count() as f64 * step;
        assert_eq!(*h, own, "at {p}");
    }
    assert_eq!(at[5], full);
}

/// A sensor given its surface's normal counts only the suns strictly in
/// front of it: each its own count, exactly, over several runs of suns;
/// facing up, every sun (each is above the horizon), as a sensor with
/// no normal; facing down, none. From a file of six columns too.
#[test]
fn sensors_with_a_normal_count_the_suns_in_front_of_them() {
    let (mesh, suns, step, _) = equinox_study();
    let points = yard_sensors();
    let plain = sensor_hours(&mesh, &points, &suns, step).unwrap();
    let normals = [
        DVec3::Z,
        DVec3::NEG_Z,
        DVec3::X,
        DVec3::new(0.3, -1.0, 0.2),
        DVec3::Y,
    ];
    for n in normals {
        let sensors: Vec<Sensor> = (points.iter())
            .map(|&position| Sensor {
                position,
                normal: Some(n),
            })
            .collect();
        let at = sensor_hours_facing(&mesh, &sensors, &suns, step).unwrap();
        for (p, h) in points.iter().zip(&at) {
            let own = (suns.iter())
                .filter(|&&d| !blocked(*p, d) && n.dot(d) > 0.0)
                .count() as f64
                * step;
            assert_eq!(*h, own, "at {p} facing {n}");
        }
        match n {
            DVec3::Z => assert_eq!(at, plain),
            DVec3::NEG_Z => assert!(at.iter().all(|&h| h == 0.0)),
            // the south-east wall of a sensor sees part of the day, an
            // east one its morning only
            _ => assert!(at[5] > 0.0 && at[5] < plain[5], "{n}: {at:?}"),
        }
    }
    let file = std::env::temp_dir().join(format!("facing-{}.csv", std::process::id()));
    let text: String = (points.iter())
        .map(|p| format!("{},{},{},1,0,0\n", p.x, p.y, p.z))
        .collect();
    std::fs::write(&file, format!("x,y,z,nx,ny,nz\n{text}")).unwrap();
    let (csv, n) = sensor_hours_file(&mesh, &file, &suns, step, HoursFormat::Csv).unwrap();
    std::fs::remove_file(&file).unwrap();
    let east: Vec<Sensor> = (points.iter())
        .map(|&position| Sensor {
            position,
            normal: Some(DVec3::X),
        })
        .collect();
    let want = sensor_hours_facing(&mesh, &east, &suns, step).unwrap();
    assert_eq!(n, points.len());
    let got: Vec<f64> = (csv.lines().skip(1))
        .map(|l| l.rsplit(',').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(got, want);
}

/// A day without sun (a polar night) still gives every face its area,
/// and no hours: the same areas as a day of suns.
#[test]
fn a_day_without_sun_keeps_the_faces_areas() {
    let (mesh, suns, step, _) = equinox_study();
    let lit = sun_hours(&mesh, &suns, step).unwrap();
    for hours in [
        sun_hours(&mesh, &[], step).unwrap(),
        sun_hours_mean(&mesh, &[], step).unwrap(),
        sun_hours_in_tiles(&mesh, &[], step, 2, true).unwrap(),
    ] {
        for (night, day) in hours.iter().zip(&lit) {
            assert!(day.area > 0.0 && (night.area - day.area).abs() < 1e-12 * day.area);
            assert_eq!(night.sun_hours, 0.0);
            assert!(
                night.min_hours == 0.0 || night.min_hours.is_nan(),
                "{night:?}"
            );
        }
    }
}

#[test]
fn runs_files_and_heat_maps_of_a_yard() {
    let (mesh, suns, step, full) = equinox_study();
    let hours = sun_hours(&mesh, &suns, step).unwrap();
    let points = yard_sensors();
    // the same points from a file, as CSV
    let file = std::env::temp_dir().join(format!("sensors-{}.csv", std::process::id()));
    let text: String = points
        .iter()
        .map(|p| format!("{} {} {}\n", p.x, p.y, p.z))
        .collect();
    std::fs::write(&file, format!("x y z\n{text}")).unwrap();
    let (csv, n) = sensor_hours_file(&mesh, &file, &suns, step, HoursFormat::Csv).unwrap();
    assert_eq!((n, csv.lines().count()), (6, 7));
    let last: f64 = csv
        .lines()
        .last()
        .unwrap()
        .rsplit(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(last, full);
    std::fs::write(&file, "1 2\n").unwrap();
    let e = sensor_hours_file(&mesh, &file, &suns, step, HoursFormat::Json).unwrap_err();
    assert!(
        e.to_string()
            .ends_with(".csv:1: `1 2` has 2 numbers; a sensor is x,y,z or x,y,z,nx,ny,nz"),
        "{e}"
    );
    std::fs::remove_file(&file).unwrap();
    // the heat map: a coloured corner per face corner, the roof yellow
    let obj = HoursFormat::Obj.bytes(&mesh, &hours, suns.len(), HeatView::default());
    let obj = String::from_utf8(obj.unwrap()).unwrap();
    let corners: usize = mesh.faces.iter().map(|f| f.vertices.len()).sum();
    assert_eq!(obj.lines().filter(|l| l.starts_with("v ")).count(), corners);
    let read = shadow_scene::parse_obj(&obj, "heat.obj").unwrap();
    assert_eq!(read.faces.len(), mesh.faces.len());
    let roof = obj.lines().filter(|l| l.starts_with("v ")).nth(4).unwrap();
    assert!(roof.ends_with(" 0.9922 0.9059 0.1451"), "{roof}");
    assert_eq!(viridis(0.0), [68.0 / 255.0, 1.0 / 255.0, 84.0 / 255.0]);
    // its picture, by the file's name; no picture of sensors
    let png = std::path::Path::new("study.PNG");
    assert_eq!(HoursFormat::for_path(png).unwrap(), HoursFormat::Png);
    let e = HoursFormat::for_path(std::path::Path::new("study.txt")).unwrap_err();
    assert_eq!(
        e.to_string(),
        "study.txt: a sun study is written as .csv, .json, .obj, .ply or .png"
    );
    let bytes = hours_png(&mesh, &hours, suns.len(), HeatView::default()).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    let of = HoursOf::Sensors(&file);
    let quiet = &crate::shadow_file::NoProgress;
    let e = hours_report(
        &mesh,
        &suns,
        step,
        png,
        of,
        None,
        HeatView::default(),
        quiet,
    );
    let e = e.unwrap_err().to_string();
    assert!(
        e.starts_with("study.PNG: a picture shows faces' hours"),
        "{e}"
    );
    // the suns in another order make other runs: the same hours
    let back: Vec<DVec3> = suns.iter().rev().copied().collect();
    for (a, b) in hours.iter().zip(sun_hours(&mesh, &back, step).unwrap()) {
        assert!((a.sun_hours - b.sun_hours).abs() < 1e-9, "{a:?} {b:?}");
        assert!((a.min_hours - b.min_hours).abs() < 1e-9, "{a:?} {b:?}");
        assert!((a.max_hours - b.max_hours).abs() < 1e-9, "{a:?} {b:?}");
    }
    // runs made apart, sent as bytes and folded in order: the same bits
    let runs: Vec<Vec<u8>> = (suns.chunks(SUNS_A_RUN))
        .map(|c| HoursRun::new(&mesh, c, step).unwrap().to_bytes())
        .collect();
    let back = runs.iter().map(|b| Ok(HoursRun::from_bytes(b).unwrap()));
    assert_eq!(HoursRun::fold(mesh.faces.len(), back).unwrap(), hours);
    let cut = &runs[0][..runs[0].len() - 8];
    assert!(HoursRun::from_bytes(cut).is_none());
    assert!(HoursRun::from_bytes(&[runs[0].clone(), vec![0; 8]].concat()).is_none());
    // the mean alone (its lit areas found as the trees are built, not
    // from fragments: the same to rounding), no extremes
    let mean = sun_hours_mean(&mesh, &suns, step).unwrap();
    for (a, b) in hours.iter().zip(&mean) {
        assert!((a.area - b.area).abs() <= 1e-12 * a.area, "{a:?} {b:?}");
        assert!((a.sun_hours - b.sun_hours).abs() < 1e-9, "{a:?} {b:?}");
        assert!(b.min_hours.is_nan() && b.max_hours.is_nan() && b.hours_area.is_empty());
    }
    let run = HoursRun::mean_only(&mesh, &suns[..10], step).unwrap();
    assert_eq!(HoursRun::from_bytes(&run.to_bytes()), Some(run));
    let none = HoursRun::fold(mesh.faces.len(), []).unwrap();
    assert!(
        none.iter()
            .all(|h| h.sun_hours == 0.0 && h.max_hours == 0.0)
    );
}

#[test]
fn regions_of_a_yard() {
    let (mesh, suns, step, _) = equinox_study();
    let hours = sun_hours(&mesh, &suns, step).unwrap();
    // the ground's cells: their areas add up to the ground's, and the
    // area in sun at least so long is the face's own
    let ground: RegionFaces = "0".parse().unwrap();
    let cells = region_hours(&mesh, &suns, step, &ground.faces(&mesh).unwrap()).unwrap();
    assert!(cells.len() > 10 && cells.iter().all(|c| c.face == 0));
    // merged: cells of equal hours are maximal, so no two of them share
    // a piece of boundary (an edge of one whose corners lie on an edge of
    // the other, at least one strictly inside it or both its ends: the
    // corners are correctly rounded from exact points, equal to the bit
    // where the points are equal); no corner repeats in a ring
    let edges = |c: &RegionCell| -> Vec<(DVec3, DVec3)> {
        c.rings()
            .flat_map(|r| (0..r.len()).map(move |k| (r[k], r[(k + 1) % r.len()])))
            .collect()
    };
    for (i, p) in cells.iter().enumerate() {
        for r in p.rings() {
            let n = r.len();
            assert!((0..n).all(|k| r[k] != r[(k + 1) % n]), "{p:?}");
        }
        let mine = edges(p);
        for q in cells
            .iter()
            .skip(i + 1)
            .filter(|q| q.hours == p.hours && q.face == p.face)
        {
            for (a, b) in edges(q) {
                assert!(!mine.contains(&(b, a)), "{p:?} and {q:?} share an edge");
            }
        }
    }
    // each cell's outer ring turns counter-clockwise from above, its
    // holes clockwise, and its area is the rings' signed sum
    let signed = |r: &[DVec3]| -> f64 {
        (0..r.len())
            .map(|i| r[i].truncate().perp_dot(r[(i + 1) % r.len()].truncate()))
            .sum::<f64>()
            / 2.0
    };
    for c in &cells {
        assert!(signed(&c.ring) > 0.0, "{c:?}");
        assert!(c.holes.iter().all(|h| signed(h) < 0.0), "{c:?}");
        let sum: f64 = c.rings().map(signed).sum();
        assert!((sum - c.area).abs() < 1e-9 * c.area.max(1.0), "{c:?}");
    }
    let g = &hours[0];
    let (total, sunny) = area_in_sun(&cells, 6.0);
    assert!((total - g.area).abs() < 1e-9 * g.area, "{total} {}", g.area);
    assert!((sunny - g.area_with_at_least(6.0)).abs() < 1e-9 * g.area);
    let (lo, hi) =
        (cells.iter().map(|c| c.hours)).fold((f64::MAX, 0.0_f64), |(a, b), h| (a.min(h), b.max(h)));
    assert_eq!((lo, hi), (g.min_hours, g.max_hours));
    for c in &cells {
        // each cell lies on the ground
        assert!(
            c.rings().flatten().all(|p| p.z == 0.0 || p.z.abs() < 1e-12),
            "{c:?}"
        );
        // its triangles cover its area
        let tri: f64 = (c.triangles().iter())
            .map(|t| (t[1] - t[0]).truncate().perp_dot((t[2] - t[0]).truncate()) / 2.0)
            .sum();
        assert!((tri - c.area).abs() < 1e-9 * c.area.max(1.0), "{c:?}");
    }
    let json: serde_json::Value = serde_json::from_str(&regions_json(&cells, suns.len())).unwrap();
    assert_eq!(json["cells"].as_array().unwrap().len(), cells.len());
    let holes: usize = cells.iter().map(|c| c.holes.len()).sum();
    let listed: usize = (json["cells"].as_array().unwrap().iter())
        .map(|c| c["holes"].as_array().unwrap().len())
        .sum();
    assert_eq!(listed, holes);
    let obj = regions_obj(&cells);
    assert_eq!(
        obj.lines().filter(|l| l.starts_with("g ")).count(),
        cells.len()
    );
    let triangles: usize = cells.iter().map(|c| c.triangles().len()).sum();
    assert_eq!(
        obj.lines().filter(|l| l.starts_with("f ")).count(),
        triangles
    );
    assert!(bre209_text(&cells).starts_with("BRE 209: the region passes: "));
    let png = regions_png(&mesh, &[0], &cells, suns.len(), HeatView::default()).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let march = chrono::NaiveDate::from_ymd_opt(2026, 3, 21).unwrap();
    assert!(check_bre209(true, &[march]).is_ok());
    let next = [march.succ_opt().unwrap()];
    assert!(check_bre209(true, &next).is_err() && check_bre209(false, &next).is_ok());
    // faces by ids and ranges; unknown ones are errors that say why
    assert_eq!(
        "1,3-5,3"
            .parse::<RegionFaces>()
            .unwrap()
            .faces(&mesh)
            .unwrap(),
        [1, 3, 4, 5]
    );
    assert!("3-1".parse::<RegionFaces>().is_err());
    // a range far past the mesh is an error before it is listed (it was
    // a failed allocation of 34 GB, or a panic)
    for huge in [
        "0-4294967295",
        "0-18446744073709551615",
        "5,2-18446744073709551615",
    ] {
        let e = huge
            .parse::<RegionFaces>()
            .unwrap()
            .faces(&mesh)
            .unwrap_err();
        assert!(e.to_string().contains("faces (ids from 0)"), "{e}");
    }
    let e = "99"
        .parse::<RegionFaces>()
        .unwrap()
        .faces(&mesh)
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        format!(
            "face 99: the mesh has {} faces (ids from 0)",
            mesh.faces.len()
        )
    );
    let e = RegionFaces::Group("garden".into())
        .faces(&mesh)
        .unwrap_err();
    assert!(
        e.to_string()
            .starts_with("no face is in a group `garden`; the groups: "),
        "{e}"
    );
}

#[test]
fn a_sun_disc_study_agrees_with_point_suns_and_blurs_the_edges() {
    let site = SunSite::new(51.48, 0.0);
    let day = [chrono::NaiveDate::from_ymd_opt(2026, 3, 21).unwrap()];
    let suns: Vec<DVec3> = study_suns(&site, &day, 60.0, 0.0)
        .unwrap()
        .iter()
        .map(|s| s.direction)
        .collect();
    let mesh = yard();
    let point = sun_hours_mean(&mesh, &suns, 1.0).unwrap();
    // a disc of no size is the point sun
    let none = sun_hours_disc(&mesh, &suns, 1.0, 0.0).unwrap();
    for (p, d) in point.iter().zip(&none) {
        assert!((p.sun_hours - d.sun_hours).abs() < 1e-9, "{p:?} {d:?}");
        assert!(d.min_hours.is_nan() && d.max_hours.is_nan());
    }
    // the real sun: the roof sees all of it, the ground loses a little of
    // the penumbra's light on one side of each edge and gains it on the other
    let real = sun_hours_disc(&mesh, &suns, 1.0, crate::SUN_RADIUS_DEG).unwrap();
    assert_eq!(real[1].sun_hours, point[1].sun_hours);
    let ground = (real[0].sun_hours - point[0].sun_hours).abs();
    assert!(
        ground > 0.0 && ground < 1e-3 * point[0].sun_hours,
        "{ground}"
    );
    // a wide disc blurs more, and the hours stay within a day's suns
    let wide = sun_hours_disc(&mesh, &suns, 1.0, 3.0).unwrap();
    let blur = (wide[0].sun_hours - point[0].sun_hours).abs();
    assert!(blur > ground, "{blur} against {ground}");
    for f in &wide {
        assert!(
            f.sun_hours >= 0.0 && f.sun_hours <= suns.len() as f64 + 1e-9,
            "{f:?}"
        );
    }
}

#[test]
fn a_disc_straddling_a_plane_is_counted_by_its_part_in_front() {
    let r = 0.5;
    assert_eq!(disc_in_front(0.01, r), 1.0);
    assert_eq!(disc_in_front(-0.01, r), 0.0);
    assert!((disc_in_front(0.0, r) - 0.5).abs() < 1e-15);
    // the segment beyond a chord at half the radius: 1/3 - √3/(4π)
    let sliver = 1.0 / 3.0 - 3f64.sqrt() / (4.0 * std::f64::consts::PI);
    let half_r = r.to_radians() / 2.0;
    assert!((disc_in_front(-half_r, r) - sliver).abs() < 1e-12);
    assert!((disc_in_front(half_r, r) - (1.0 - sliver)).abs() < 1e-12);
}

#[test]
fn a_sensor_under_the_ground_keeps_the_ground_as_an_occluder() {
    // the tiles hide nothing from the faces, all above them, but they do
    // hide the sun from a point below
    let city = shadow_scene::city_block(4);
    let suns = [DVec3::new(0.2, -0.3, 1.0), DVec3::new(-0.4, -0.2, 0.8)];
    let below = DVec3::new(2.0, 2.0, -1.0);
    let open = DVec3::new(2.0, 2.0, 0.5);
    let h = sensor_hours(&city, &[below, open], &suns, 1.0).unwrap();
    assert_eq!(h, [0.0, 2.0]);
}

#[test]
fn a_region_cut_to_an_outline_keeps_its_hours_and_its_area() {
    let (mesh, suns, step, _) = equinox_study();
    let cells = region_hours(&mesh, &suns, step, &[0]).unwrap();
    // an L-shaped garden north-east of the box, seen from above
    let p = |x: f64, y: f64| DVec3::new(x, y, 7.0); // (its height is left out)
    let garden = [
        p(1.5, 1.5),
        p(6.0, 1.5),
        p(6.0, 3.0),
        p(3.0, 3.0),
        p(3.0, 6.0),
        p(1.5, 6.0),
    ];
    let cut = clip_to_outline(&cells, &garden, Up::Z).unwrap();
    let area: f64 = cut.iter().map(|c| c.area).sum();
    assert!((area - (4.5 * 1.5 + 1.5 * 3.0)).abs() < 1e-9, "{area}");
    // a point of the garden has its cell's hours: the exact count there
    // (cells need not be convex, and may have holes: an even-odd test over
    // all their rings)
    let inside = |c: &RegionCell, q: DVec3| {
        let crossings = c.rings().flat_map(|r| {
            let n = r.len();
            (0..n).filter(move |&i| {
                let (a, b) = (r[i], r[(i + 1) % n]);
                (a.y > q.y) != (b.y > q.y) && q.x < a.x + (q.y - a.y) / (b.y - a.y) * (b.x - a.x)
            })
        });
        crossings.count() % 2 == 1
    };
    let points = [
        DVec3::new(1.7, 1.7, 0.0),
        DVec3::new(5.5, 2.2, 0.0),
        DVec3::new(2.1, 5.3, 0.0),
    ];
    let exact = sensor_hours(&mesh, &points, &suns, step).unwrap();
    for (q, h) in points.iter().zip(exact) {
        let c = cut
            .iter()
            .find(|c| inside(c, *q))
            .expect("a cell holds the point");
        assert!((c.hours - h).abs() < 1e-9, "{q}: {} against {h}", c.hours);
        assert_eq!(c.face, 0);
    }
    // y up: a ground cell of 4 × 4 in x and -z, a garden of 2 × 2 on it
    let ground = RegionCell {
        face: 0,
        hours: 3.0,
        area: 16.0,
        ring: [(0.0, 0.0), (4.0, 0.0), (4.0, 4.0), (0.0, 4.0)]
            .map(|(x, n)| DVec3::new(x, 0.0, -n))
            .to_vec(),
        holes: Vec::new(),
    };
    let square =
        [(1.0, 1.0), (3.0, 1.0), (3.0, 3.0), (1.0, 3.0)].map(|(x, n)| DVec3::new(x, 5.0, -n));
    let part = clip_to_outline(&[ground], &square, Up::Y).unwrap();
    assert_eq!(part.iter().map(|c| c.area).sum::<f64>(), 4.0);
    assert!(part.iter().all(|c| c.hours == 3.0));
    let flat = [p(0.0, 0.0), p(1.0, 1.0), p(2.0, 2.0)];
    assert!(clip_to_outline(&cells, &flat, Up::Z).is_err());
    // an outline beside the region is an error, not a region of no area
    let away = [p(100.0, 100.0), p(101.0, 100.0), p(101.0, 101.0)];
    let e = clip_to_outline(&cells, &away, Up::Z)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("from 100, 100 to 101, 101) meets none of the region's"),
        "{e}"
    );
}

#[test]
fn a_study_writes_ply_with_each_faces_hours() {
    let (mesh, suns, step, _) = equinox_study();
    let hours = sun_hours_mean(&mesh, &suns, step).unwrap();
    let ply = String::from_utf8(
        HoursFormat::Ply
            .bytes(&mesh, &hours, suns.len(), HeatView::default())
            .unwrap(),
    )
    .unwrap();
    let (head, body) = ply.split_once("end_header\n").unwrap();
    let corners: usize = mesh.faces.iter().map(|f| f.vertices.len()).sum();
    assert!(head.starts_with("ply\nformat ascii 1.0\n"));
    assert!(head.contains(&format!("element vertex {corners}\n")));
    assert!(head.contains(&format!("element face {}\n", mesh.faces.len())));
    let lines: Vec<&str> = body.lines().collect();
    assert_eq!(lines.len(), corners + mesh.faces.len());
    for (face, (line, h)) in lines[corners..].iter().zip(&hours).enumerate() {
        let v: Vec<&str> = line.split(' ').collect();
        let n = mesh.faces[face].vertices.len();
        assert_eq!(v[0].parse::<usize>().unwrap(), n);
        assert_eq!(v.last().unwrap().parse::<f64>().unwrap(), h.sun_hours);
    }
    // sensors as coloured points, regions as cells
    let points = yard_sensors();
    let s = sensors_ply(&points, &[1.0; 6]);
    assert!(s.contains("element vertex 6\n") && !s.contains("element face"));
    let cells = region_hours(&mesh, &suns, step, &[0]).unwrap();
    let triangles: usize = cells.iter().map(|c| c.triangles().len()).sum();
    assert!(triangles > cells.len());
    assert!(regions_ply(&cells).contains(&format!("element face {triangles}\n")));
}

/// A study cut into tiles: every face's hours the uncut study's up to the
/// last bits (each tile's trees hold every occluder that may hide the sun
/// from it), the extremes too; its runs made apart and folded in order
/// give the same bits; a tile that is not one is an error.
#[test]
fn a_study_cut_into_tiles_keeps_every_faces_hours() {
    let (mesh, suns, step, _) = equinox_study();
    let whole = sun_hours(&mesh, &suns, step).unwrap();
    let cut = sun_hours_in_tiles(&mesh, &suns, step, 2, true).unwrap();
    for (a, b) in whole.iter().zip(&cut) {
        assert!((a.area - b.area).abs() <= 1e-12 * a.area, "{a:?} {b:?}");
        for (x, y) in [
            (a.sun_hours, b.sun_hours),
            (a.min_hours, b.min_hours),
            (a.max_hours, b.max_hours),
        ] {
            assert!((x - y).abs() < 1e-9, "{a:?} {b:?}");
        }
    }
    let runs: Vec<Vec<u8>> = (suns.chunks(SUNS_A_RUN))
        .flat_map(|c| Tile::all(2).map(move |t| (c, t)))
        .map(|(c, t)| {
            HoursRun::of_tile(&mesh, c, step, true, t)
                .unwrap()
                .to_bytes()
        })
        .collect();
    let back = runs.iter().map(|b| Ok(HoursRun::from_bytes(b).unwrap()));
    assert_eq!(HoursRun::fold(mesh.faces.len(), back).unwrap(), cut);
    // a tile's face list must be ascending faces of the mesh
    let mut words: Vec<f64> = (runs[0].chunks_exact(8))
        .map(|w| f64::from_le_bytes(w.try_into().unwrap()))
        .collect();
    assert!(words[2] >= 2.0 && words[3] >= 1.0, "{:?}", &words[..4]);
    words[4] = mesh.faces.len() as f64;
    let bad: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    assert!(HoursRun::from_bytes(&bad).is_none());
    let e = HoursRun::of_tile(
        &mesh,
        &suns[..3],
        step,
        true,
        Tile {
            index: 9,
            per_side: 3,
        },
    );
    assert_eq!(
        e.unwrap_err().to_string(),
        "tile 9 of a study cut into 3 × 3 tiles (0 to 8)"
    );
    assert!(sun_hours_in_tiles(&mesh, &suns, step, 0, false).is_err());
    // the study tells its progress: a step a run of suns and tile
    #[derive(Default)]
    struct Heard(std::sync::Mutex<(Vec<(&'static str, u64)>, u64)>);
    impl crate::shadow_file::Progress for Heard {
        fn phase(&self, name: &'static str, steps: u64) {
            self.0.lock().unwrap().0.push((name, steps));
        }
        fn advance(&self, steps: u64) {
            self.0.lock().unwrap().1 += steps;
        }
    }
    let heard = Heard::default();
    let again = faces_study(&mesh, &suns, step, true, 2, &heard).unwrap();
    assert_eq!(again, cut);
    let runs = suns.len().div_ceil(SUNS_A_RUN) as u64 * 4;
    assert_eq!(*heard.0.lock().unwrap(), (vec![("sun runs", runs)], runs));

    // a city block's mean hours in 3 × 3 tiles: the same to the last bits
    let city = shadow_scene::city_block(6);
    let suns = &suns[..40];
    let whole = sun_hours_mean(&city, suns, step).unwrap();
    let cut = sun_hours_in_tiles(&city, suns, step, 3, false).unwrap();
    let most = whole.iter().map(|h| h.sun_hours).fold(0.0, f64::max);
    assert!(most > 1.0, "{most}");
    for (a, b) in whole.iter().zip(&cut) {
        assert!((a.area - b.area).abs() <= 1e-12 * a.area, "{a:?} {b:?}");
        assert!((a.sun_hours - b.sun_hours).abs() < 1e-9, "{a:?} {b:?}");
    }
}

/// A face's mean hours lie between its least and its most: the mean is a
/// sum of rounded areas, the extremes exact counts, and on the bunny the
/// mean fell an ulp outside them on 272 of its 3,675 faces.
#[test]
fn the_mean_lies_between_the_extremes() {
    let mesh = shadow_scene::scene("bunny").unwrap();
    let site = SunSite::new(51.5, 0.0).with_axes(0.0, Up::Y);
    let day = [chrono::NaiveDate::from_ymd_opt(2026, 3, 21).unwrap()];
    let suns: Vec<DVec3> = (study_suns(&site, &day, 30.0, 0.0).unwrap().iter())
        .map(|s| s.direction)
        .collect();
    let hours = sun_hours(&mesh, &suns, 0.5).unwrap();
    let outside = (hours.iter())
        .filter(|h| !(h.min_hours <= h.sun_hours && h.sun_hours <= h.max_hours))
        .count();
    assert_eq!(outside, 0);
    assert!(hours.iter().any(|h| h.min_hours < h.max_hours));
}

/// Runs of two meshes whose faces lie in other planes do not fold: an
/// error that names the face, not cells overlaid across planes.
#[test]
fn runs_of_different_meshes_do_not_fold() {
    let (mesh, suns, step, _) = equinox_study();
    let mut tilted = mesh.clone();
    for p in &mut tilted.positions {
        p.z += 0.1 * p.x;
    }
    let runs = [
        HoursRun::new(&mesh, &suns[..4], step),
        HoursRun::new(&tilted, &suns[4..8], step),
    ];
    let e = HoursRun::fold(mesh.faces.len(), runs).unwrap_err();
    assert!(matches!(e, crate::Error::Runs { face: 0 }), "{e}");
    assert!(
        e.to_string().contains("face 0's parts lie in other planes"),
        "{e}"
    );
}

/// A part whole in one run and cut in another: its count goes to each of
/// the other's cells, in either order; two whole parts add up; parts of
/// other planes do not fold.
#[test]
fn whole_parts_add_their_count_to_cut_ones() {
    use super::Part;
    use bsp_core::{Plane, Polygon, Split};
    let square =
        Polygon::from_grid_points(&[[0, 0, 0], [8, 0, 0], [8, 8, 0], [0, 8, 0]], 0).unwrap();
    let cut = Plane::through([3, 0, 0], [3, 8, 0], [3, 0, 1]).unwrap();
    let Split::Spanning { front, back } = square.clone().split(&cut) else {
        panic!("the cut spans the square")
    };
    let planes = |p: &Polygon| -> smallvec::SmallVec<[Plane; 6]> {
        p.edge_planes().iter().copied().collect()
    };
    let support = *square.support();
    let whole = |n| Part::new(support, vec![(planes(&square), n)]).unwrap();
    let cells = Part::new(support, vec![(planes(&front), 1), (planes(&back), 4)]).unwrap();
    assert!(matches!(whole(3), Part::Whole(..)) && matches!(cells, Part::Cells(_)));
    for sum in [
        whole(3).plus(&cells).unwrap(),
        cells.clone().plus(&whole(3)).unwrap(),
    ] {
        let mut counts = sum.counts();
        counts.sort_unstable();
        assert_eq!(counts, [4, 7]);
    }
    assert_eq!(whole(3).plus(&whole(5)).unwrap().counts(), [8]);
    let up = Polygon::from_grid_points(&[[0, 0, 1], [8, 0, 1], [8, 8, 1], [0, 8, 1]], 0).unwrap();
    let other = Part::new(*up.support(), vec![(planes(&up), 1)]).unwrap();
    assert!(whole(3).plus(&other).is_none() && cells.plus(&other).is_none());
}
