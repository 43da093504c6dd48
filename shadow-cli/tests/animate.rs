//! `animate`: frames, the Table 2 report, exported scenes that `shadows`
//! answers the same way from scratch, strategies, errors.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::{assert_failed_with, scratch, shadow, stderr, stdout};

/// A fresh, empty directory.
fn dir(name: &str) -> PathBuf {
    let d = scratch(name);
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn run(args: &[&str]) -> String {
    let o = shadow(args);
    assert!(o.status.success(), "{}", stderr(&o));
    stdout(&o)
}

fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).expect("valid JSON")
}

/// Per (face, lit flags): the area, summed.
fn areas(doc: &Value) -> BTreeMap<(u64, String), f64> {
    let mut m = BTreeMap::new();
    for f in doc["fragments"].as_array().unwrap() {
        let key = (f["face"].as_u64().unwrap(), f["lit"].to_string());
        *m.entry(key).or_insert(0.0) += f["area"].as_f64().unwrap();
    }
    m
}

fn same_areas(a: &Value, b: &Value, what: &str) {
    let (x, y) = (areas(a), areas(b));
    let keys: std::collections::BTreeSet<_> = x.keys().chain(y.keys()).collect();
    for k in keys {
        let (p, q) = (
            x.get(k).copied().unwrap_or(0.0),
            y.get(k).copied().unwrap_or(0.0),
        );
        assert!(
            (p - q).abs() <= 1e-9 * (1.0 + p.abs().max(q.abs())),
            "{what}: face {} lit {}: {p} against {q}",
            k.0,
            k.1
        );
    }
}

#[test]
fn room_frames_report_and_scenes() {
    let out = dir("anim_room");
    let report = out.join("table2.csv");
    let text = run(&[
        "animate",
        "--scene",
        "room",
        "--frames",
        "3",
        "--light",
        "0.5,0.25,2.5",
        "--format",
        "json",
        "--export-scene",
        "--report",
        report.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(
        text.starts_with("3 frames of scene room: 445 static faces, 51 moving"),
        "{text}"
    );
    // the report: the paper's Table 2 columns, one row per frame
    let csv = std::fs::read_to_string(&report).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(
        lines[0],
        "frame,static_polygons,dynamic_polygons,dynamic_after_bsp,static_after_bsp,\
         static_after_shadow,dynamic_shadow_polygons,total_drawn,t_tiling_s,t_merge_s,\
         t_dynamic_shadows_s,t_frame_s"
    );
    assert_eq!(lines.len(), 4);
    for (k, row) in lines[1..].iter().enumerate() {
        let cells: Vec<&str> = row.split(',').collect();
        assert_eq!(cells.len(), 12, "{row}");
        assert_eq!(cells[0], k.to_string());
        assert_eq!(cells[1], "445");
        assert_eq!(cells[2], "51");
        let t: f64 = cells[11].parse().unwrap();
        assert!(t > 0.0 && t < 10.0, "{row}");
    }
    for k in 0..3 {
        let frame = json(&out.join(format!("frame_{k:04}.json")));
        assert_eq!(frame["faces"].as_u64(), Some(496));
        // every face has fragments, static faces first in file order
        let faces: Vec<u64> = frame["fragments"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f["face"].as_u64().unwrap())
            .collect();
        assert!(faces.windows(2).all(|w| w[0] <= w[1]));
        assert_eq!(faces.first(), Some(&0));
        assert_eq!(faces.last(), Some(&495));
        // the exported scene, shaded from scratch, gives the same areas
        let obj = out.join(format!("frame_{k:04}.obj"));
        let scratch_json = out.join(format!("scratch_{k}.json"));
        run(&[
            "shadows",
            obj.to_str().unwrap(),
            "--light",
            "0.5,0.25,2.5",
            "--quiet",
            "-o",
            scratch_json.to_str().unwrap(),
        ]);
        let again = json(&scratch_json);
        assert_eq!(again["faces"].as_u64(), Some(496));
        same_areas(&frame, &again, &format!("frame {k} against shadows"));
        assert_eq!(
            frame["fragments"].as_array().unwrap().len(),
            again["fragments"].as_array().unwrap().len(),
            "the same maximal fragments"
        );
    }
}

#[test]
fn both_strategies_agree_and_none_writes_no_frames() {
    let fast = dir("anim_fast");
    let paper = dir("anim_paper");
    let common = [
        "animate",
        "--scene",
        "room",
        "--frames",
        "2",
        "--spin",
        "0,0,1:40",
        "--step",
        "-0.3,0.1,0",
        "--format",
        "json",
        "--quiet",
    ];
    let mut a = common.to_vec();
    a.extend(["-o", fast.to_str().unwrap()]);
    run(&a);
    let mut b = common.to_vec();
    b.extend(["--strategy", "paper", "-o", paper.to_str().unwrap()]);
    run(&b);
    for k in 0..2 {
        let name = format!("frame_{k:04}.json");
        same_areas(
            &json(&fast.join(&name)),
            &json(&paper.join(&name)),
            "paper against fast",
        );
    }
    let none = dir("anim_none");
    let text = run(&[
        "animate",
        "--scene",
        "room",
        "--frames",
        "2",
        "--format",
        "none",
        "-o",
        none.to_str().unwrap(),
    ]);
    assert!(text.contains("frame time median"), "{text}");
    assert_eq!(std::fs::read_dir(&none).unwrap().count(), 0);
}

#[test]
fn png_frames_are_rasterized() {
    let out = dir("anim_png");
    run(&[
        "animate",
        "--scene",
        "room",
        "--frames",
        "2",
        "--format",
        "png",
        "--width",
        "160",
        "--height",
        "120",
        "-o",
        out.to_str().unwrap(),
    ]);
    for k in 0..2 {
        let png = std::fs::read(out.join(format!("frame_{k:04}.png"))).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
        // width and height in the IHDR chunk
        assert_eq!(u32::from_be_bytes(png[16..20].try_into().unwrap()), 160);
        assert_eq!(u32::from_be_bytes(png[20..24].try_into().unwrap()), 120);
    }
}

#[test]
fn svg_frames_are_drawn() {
    let out = dir("anim_svg");
    run(&[
        "animate",
        "--scene",
        "room",
        "--frames",
        "2",
        "--width",
        "200",
        "--height",
        "150",
        "-o",
        out.to_str().unwrap(),
    ]);
    for k in 0..2 {
        let svg = std::fs::read_to_string(out.join(format!("frame_{k:04}.svg"))).unwrap();
        assert!(svg.starts_with("<?xml") && svg.contains("<svg") && svg.contains("<path"));
    }
}

#[test]
fn files_need_a_moving_object_a_light_and_a_good_spin() {
    let stat = scratch("anim_static.obj");
    std::fs::write(&stat, "v -4 -4 0\nv 4 -4 0\nv 4 4 0\nv -4 4 0\nf 1 2 3 4\n").unwrap();
    let tet = scratch("anim_tet.obj");
    std::fs::write(
        &tet,
        "v 0 0 1\nv 1 0 1\nv 0 1 1\nv 0 0 2\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    )
    .unwrap();
    let empty = scratch("anim_empty.obj");
    std::fs::write(&empty, "v 0 0 0\n").unwrap();
    let out = dir("anim_err");
    let o = out.to_str().unwrap();
    let s = stat.to_str().unwrap();
    assert_failed_with(
        &shadow(&["animate", s, "--light", "0,0,5", "-o", o]),
        &["--dynamic"],
    );
    let t = tet.to_str().unwrap();
    assert_failed_with(
        &shadow(&["animate", s, "--dynamic", t, "-o", o]),
        &["no light"],
    );
    assert_failed_with(
        &shadow(&[
            "animate",
            s,
            "--dynamic",
            empty.to_str().unwrap(),
            "--light",
            "0,0,5",
            "-o",
            o,
        ]),
        &["no faces"],
    );
    // a path so long that the shared grid would lose the scene's detail
    // (a step of 2^5 under a scene of 8): an error, not frames of nothing;
    // a path of 200 times the scene is fine
    let far = [
        "animate",
        s,
        "--dynamic",
        t,
        "--light",
        "0,0,5",
        "--frames",
        "3",
    ];
    assert_failed_with(
        &shadow(
            &[
                &far[..],
                &["--step", "1e9,0,0", "-o", o, "--format", "none"],
            ]
            .concat(),
        ),
        &[
            "the moving object's path over 3 frames",
            "anim_static.obj)",
            "2^27 times coarser",
            "--step",
        ],
    );
    let o2 = dir("anim_far_ok");
    let o2 = o2.to_str().unwrap();
    let fine = shadow(
        &[
            &far[..],
            &["--step", "800,0,0", "-o", o2, "--format", "json"],
        ]
        .concat(),
    );
    assert!(fine.status.success(), "{}", stderr(&fine));
    let frame0 = json(&Path::new(o2).join("frame_0000.json"));
    let area = frame0["summary"]["area"].as_f64().unwrap();
    assert!(
        (area - (64.0 + 1.5 + 3f64.sqrt() / 2.0)).abs() < 1e-12,
        "{area}"
    );
    assert_failed_with(
        &shadow(&["animate", "--scene", "kitchen", "-o", o]),
        &["unknown animation `kitchen`", "room"],
    );
    let bad = shadow(&["animate", "--scene", "room", "--spin", "0,0,1", "-o", o]);
    assert_eq!(bad.status.code(), Some(1), "a usage error");
    assert!(
        stderr(&bad).contains("AX,AY,AZ:DEGREES"),
        "{}",
        stderr(&bad)
    );
    // a tetrahedron sliding over the quad: a working run of a file pair
    let text = run(&[
        "animate",
        s,
        "--dynamic",
        t,
        "--light",
        "0.25,0.25,6",
        "--step",
        "0.5,0,0",
        "--frames",
        "4",
        "--format",
        "json",
        "-o",
        o,
    ]);
    assert!(text.starts_with("4 frames of "), "{text}");
    // a closed outward tetrahedron under the light: every frame leaves
    // out its faces turned away from it
    assert!(
        text.contains("faces turned away from a light left out in 4 of the frames"),
        "{text}"
    );
    let last = json(&out.join("frame_0003.json"));
    // the tetrahedron's shadow is a hole in the quad's lit fragment
    let quad: Vec<&Value> = last["fragments"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|f| f["face"] == 0)
        .collect();
    assert!(quad.iter().any(|f| f["lit"][0] == false));
    assert!(
        quad.iter()
            .any(|f| f["lit"][0] == true && f.get("holes").is_some())
    );
}

/// A report that cannot be written stops the run before anything is
/// made: no frames folder is left behind.
#[test]
fn an_unwritable_report_leaves_no_folder() {
    let dir = scratch("never_frames");
    let _ = std::fs::remove_dir_all(&dir);
    let report = scratch("no_such_dir").join("deeper").join("rep.csv");
    let o = shadow(&[
        "animate",
        "--scene",
        "room",
        "--frames",
        "1",
        "--format",
        "none",
        "--report",
        report.to_str().unwrap(),
        "-o",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("rep.csv"), "{}", stderr(&o));
    assert!(!dir.exists());
}
