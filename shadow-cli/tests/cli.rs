//! `view`, `stats` and `demo`.

use std::path::Path;

use crate::{assert_failed_with, scratch, shadow, stderr, stdout};

fn teapot() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../data/meshes/teapot.obj")
        .display()
        .to_string()
}

/// Checks the SVG's frame and returns its number of polygons.
fn svg_polygons(path: &Path) -> usize {
    let svg = std::fs::read_to_string(path).unwrap();
    assert!(svg.starts_with("<?xml"), "no XML declaration");
    assert!(svg.contains("<svg xmlns=\"http://www.w3.org/2000/svg\""));
    assert!(svg.trim_end().ends_with("</svg>"));
    assert_eq!(svg.matches("<g ").count(), svg.matches("</g>").count());
    let polys = svg.matches("<polygon points=\"").count();
    assert_eq!(
        polys,
        svg.matches("\"/>\n").count() - 1,
        "every polygon closed (plus the background rect)"
    );
    polys
}

#[test]
fn demo_writes_the_room() {
    let out = scratch("demo_room.svg");
    let o = shadow(&["demo", "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).starts_with(&format!("wrote {}", out.display())),
        "{}",
        stdout(&o)
    );
    assert!(svg_polygons(&out) > 500);
    // the room is imported whole: no import summary on stderr
    assert_eq!(stderr(&o), "");
}

#[test]
fn view_of_the_teapot() {
    let out = scratch("teapot.svg");
    let o = shadow(&[
        "view",
        &teapot(),
        "--eye",
        "12,9,14",
        "--up",
        "0,1,0",
        "-o",
        out.to_str().unwrap(),
        "--width",
        "400",
        "--height",
        "300",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let svg = std::fs::read_to_string(&out).unwrap();
    assert!(svg.contains(r#"width="400" height="300""#));
    assert!(svg_polygons(&out) > 900);
}

#[test]
fn view_from_inside_the_room_with_negative_coordinates() {
    let out = scratch("inside.svg");
    let o = shadow(&[
        "view",
        "--scene",
        "room",
        "--eye",
        "-2.5,-1.5,1.6",
        "--target",
        "1,2,0.8",
        "--fov",
        "70",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(svg_polygons(&out) > 100);
}

#[test]
fn stats_prints_the_tree_figures() {
    let o = shadow(&["stats", &teapot()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = stdout(&o);
    for key in [
        "faces:           992",
        "polygons:",
        "bsp polygons:",
        "nodes:",
        "depth:",
        "cells:",
        "build time:",
    ] {
        assert!(s.contains(key), "`{key}` not in {s}");
    }
    let nodes: usize = s
        .lines()
        .find_map(|l| l.strip_prefix("nodes:"))
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    assert!(nodes > 100);
    let o = shadow(&["stats", "--scene", "room"]);
    assert!(o.status.success());
    assert!(
        stdout(&o).contains("(0 faces triangulated, 0 dropped)"),
        "{}",
        stdout(&o)
    );
}

#[test]
fn malformed_obj_names_file_and_line() {
    let bad = scratch("malformed.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nv 0 1 0\n# a comment\nf 1 2 7\n").unwrap();
    for cmd in [
        vec!["stats"],
        vec!["view", "--eye", "1,1,1", "-o", "never.svg"],
    ] {
        let mut args = cmd.clone();
        args.insert(1, bad.to_str().unwrap());
        let o = shadow(&args);
        assert_failed_with(
            &o,
            &["malformed.obj:5:", "face index 7 out of range (1..=3)"],
        );
    }
    assert!(!Path::new("never.svg").exists());
}

#[test]
fn nan_coordinate_is_an_error() {
    let bad = scratch("nan.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nv 0 NaN 0\nf 1 2 3\n").unwrap();
    let o = shadow(&["stats", bad.to_str().unwrap()]);
    assert_failed_with(&o, &["nan.obj:3:", "coordinate `NaN` is not finite"]);
}

#[test]
fn missing_and_unknown_files() {
    let missing = scratch("does_not_exist.obj");
    let o = shadow(&["stats", missing.to_str().unwrap()]);
    assert_failed_with(&o, &["does_not_exist.obj"]);
    let ply = scratch("model.ply");
    std::fs::write(&ply, "ply\n").unwrap();
    let o = shadow(&["stats", ply.to_str().unwrap()]);
    assert_failed_with(&o, &["model.ply", "unknown mesh format"]);
}

#[test]
fn source_and_argument_errors() {
    let o = shadow(&["stats"]);
    assert_failed_with(&o, &["no input"]);
    let o = shadow(&["stats", &teapot(), "--scene", "room"]);
    assert_failed_with(&o, &["not both"]);
    let o = shadow(&["stats", "--scene", "kitchen"]);
    assert_failed_with(&o, &["unknown scene `kitchen`", "room"]);
    let o = shadow(&["view", "--scene", "cube", "--eye", "1,2", "-o", "x.svg"]);
    assert_failed_with(&o, &["--eye", "expected three comma-separated numbers"]);
    let o = shadow(&[
        "view",
        "--scene",
        "cube",
        "--eye",
        "0.5,0.5,0.5",
        "--target",
        "0.5,0.5,0.5",
        "-o",
        "x.svg",
    ]);
    assert_failed_with(&o, &["eye and the target coincide"]);
    let unwritable = scratch("no_such_dir").join("out.svg");
    let o = shadow(&[
        "view",
        "--scene",
        "cube",
        "--eye",
        "3,2,1",
        "-o",
        unwritable.to_str().unwrap(),
    ]);
    assert_failed_with(&o, &["could not write", "out.svg"]);
}

#[test]
fn help_succeeds() {
    let o = shadow(&["--help"]);
    assert!(o.status.success());
    for cmd in ["shadows", "view", "stats", "demo"] {
        assert!(stdout(&o).contains(cmd));
    }
}
