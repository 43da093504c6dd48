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
        "polygons after import",
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
fn completions_and_man_page_cover_the_commands() {
    for shell in ["bash", "zsh", "fish"] {
        let o = shadow(&["completions", shell]);
        assert!(o.status.success(), "{}", stderr(&o));
        let s = stdout(&o);
        assert!(s.contains("--scene") && s.contains("csg"), "{shell}");
    }
    let o = shadow(&["man"]);
    assert!(o.status.success());
    let s = stdout(&o);
    assert!(s.starts_with(".ie") && s.contains(".TH shadow 1"), "{s}");
    assert!(s.contains("shadows") && s.contains("animate"));
    let o = shadow(&["completions", "tcsh"]);
    assert!(!o.status.success());
}

#[test]
fn help_succeeds() {
    let o = shadow(&["--help"]);
    assert!(o.status.success());
    for cmd in ["shadows", "view", "stats", "demo"] {
        assert!(stdout(&o).contains(cmd));
    }
}

/// Writes `bytes` to a scratch file named `name`.
fn file(name: &str, bytes: &[u8]) -> String {
    let p = scratch(name);
    std::fs::write(&p, bytes).unwrap();
    p.display().to_string()
}

#[test]
fn files_without_faces_are_errors_but_empty_solids_for_csg() {
    let empty = file(
        "no_faces.obj",
        b"# just vertices\nv 0 0 0\nv 1 0 0\nv 0 1 0\n",
    );
    let other = file(
        "other.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    );
    let out = scratch("never.out");
    let out_svg = out.with_extension("svg");
    let out_json = out.with_extension("json");
    let out_obj = out.with_extension("obj");
    let runs: [Vec<&str>; 3] = [
        vec![
            "shadows",
            &empty,
            "--light",
            "0,0,5",
            "-o",
            out_json.to_str().unwrap(),
        ],
        vec![
            "view",
            &empty,
            "--eye",
            "3,3,3",
            "-o",
            out_svg.to_str().unwrap(),
        ],
        vec!["stats", &empty],
    ];
    for argv in runs {
        let o = shadow(&argv);
        assert_failed_with(&o, &[&format!("{empty}: no faces")]);
    }
    for p in [&out_svg, &out_json] {
        assert!(!p.exists(), "{}", p.display());
    }
    // a Boolean's operand without faces is the empty solid (an empty
    // result, written and read back, is an operand again), with a note
    for pair in [[&empty, &other], [&other, &empty]] {
        let o = shadow(&[
            "csg",
            "union",
            pair[0],
            pair[1],
            "-o",
            out_obj.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(stderr(&o).contains(&format!("note: {empty}: no faces: the empty solid")));
        assert!(
            stdout(&o).contains("4 triangles, 4 vertices"),
            "{}",
            stdout(&o)
        );
    }
}

/// A face that snapping changed is named with its line in the file, by
/// `stats`, `shadows` and the other commands that import a scene.
#[test]
fn changed_faces_are_named_with_their_line() {
    let l = file(
        "l_shape.obj",
        b"# an L\nv 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\n\nf 1 2 3 4 5 6\n",
    );
    let want = "1 face(s) triangulated: face 0 (line 9: not convex)";
    let o = shadow(&["stats", &l]);
    assert!(
        o.status.success() && stderr(&o).contains(want),
        "{}",
        stderr(&o)
    );
    let out = scratch("l_shape.json");
    let o = shadow(&[
        "shadows",
        &l,
        "--light",
        "0,0,5",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(
        o.status.success() && stderr(&o).contains(want),
        "{}",
        stderr(&o)
    );
}

#[test]
fn binary_files_are_errors_naming_the_file() {
    let png = file(
        "picture.obj",
        b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\x00\x00",
    );
    let o = shadow(&["stats", &png]);
    assert_failed_with(&o, &[&format!("{png}:3: binary data"), "not an OBJ file"]);
    let junk: Vec<u8> = (0..600u32).map(|i| (i * 7919 % 251) as u8).collect();
    let stl = file("junk.stl", &junk);
    let o = shadow(&["stats", &stl]);
    assert_failed_with(&o, &[&stl, "invalid STL"]);
}

#[test]
fn unknown_statements_are_reported_once_with_the_first_line() {
    // a typo (`V` for `v`) and a stray line; standard statements the
    // reader does not use pass quietly
    let typo = file(
        "typo.obj",
        b"mtllib a.mtl\nv 0 0 0\nv 1 0 0\nvt 0 0\nvn 0 0 1\nV 0 1 0\nv 0 1 0\nusemtl red\ns off\nhello there\nf 1 2 3\n",
    );
    let o = shadow(&["stats", &typo]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        stderr(&o),
        format!("note: {typo}: skipped 2 unknown statements, the first `V` on line 6\n")
    );
    let clean = file(
        "clean.obj",
        b"mtllib a.mtl\no thing\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\ns 1\nf 1 2 3\n",
    );
    let o = shadow(&["stats", &clean]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stderr(&o), "");
    // --quiet silences the note for shadows
    let out = scratch("typo.json");
    let o = shadow(&[
        "shadows",
        &typo,
        "--light",
        "0,0,5",
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stderr(&o), "");
}

#[test]
fn csg_operands_read_in_parallel_report_in_the_order_of_the_files() {
    // the files are read at once; their notes come out in order, and the
    // error is the first file's in order (not the missing last one's)
    let first = file(
        "order_first.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nW 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n",
    );
    let second = file("order_second.obj", b"v 0 0 0\nQ 2\nQ 3\n");
    let missing = scratch("order_missing.obj");
    let missing = missing.to_str().unwrap();
    let out = scratch("order_out.obj");
    let o = shadow(&[
        "csg",
        "union",
        &first,
        &second,
        missing,
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert_eq!(
        stderr(&o),
        format!(
            "note: {first}: skipped an unknown statement `W` on line 5\n\
             note: {second}: skipped 2 unknown statements, the first `Q` on line 2\n\
             note: {second}: no faces: the empty solid\n\
             error: {missing}: No such file or directory (os error 2)\n"
        )
    );
    assert!(!out.exists());
}

/// Every command writes the same bytes on 1, 2 and 8 worker threads
/// (`shadows` has its own test on a scene of many rounds).
#[test]
fn every_command_writes_the_same_for_every_thread_count() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/meshes");
    let sphere = data.join("pyvista_sphere.obj");
    let moved = scratch("threads_moved_sphere.obj");
    let text = std::fs::read_to_string(&sphere).unwrap();
    let shifted: String = text
        .lines()
        .map(|l| match l.strip_prefix("v ") {
            Some(v) => {
                let c: Vec<f64> = v.split_whitespace().map(|x| x.parse().unwrap()).collect();
                format!("v {} {} {}\n", c[0] + 0.1, c[1] + 0.05, c[2] + 0.02)
            }
            None => format!("{l}\n"),
        })
        .collect();
    std::fs::write(&moved, shifted).unwrap();
    let (a, b) = (sphere.to_str().unwrap(), moved.to_str().unwrap());
    // each command and the files it writes (under the name OUT)
    let runs: [(&[&str], &[&str]); 6] = [
        (&["csg", "union", a, b, "-o", "OUT.obj"], &["OUT.obj"]),
        (
            &[
                "render",
                "--scene",
                "room",
                "--size",
                "160x90",
                "--method",
                "shadow-map",
                "-o",
                "OUT.png",
                "--mask",
                "OUT.pgm",
            ],
            &["OUT.png", "OUT.pgm"],
        ),
        (
            &[
                "compare", "--scene", "room", "--size", "96x54", "-o", "OUT.png", "--report",
                "OUT.csv",
            ],
            &["OUT.png"],
        ),
        (&["view", "--scene", "room", "-o", "OUT.svg"], &["OUT.svg"]),
        (
            &["lines", "--scene", "chair", "-o", "OUT.svg"],
            &["OUT.svg"],
        ),
        (
            &[
                "animate", "--scene", "room", "--frames", "2", "--format", "json", "-o", "OUT",
            ],
            &["OUT/frame_0000.json", "OUT/frame_0001.json"],
        ),
    ];
    for (k, (args, files)) in runs.iter().enumerate() {
        let mut outputs: Vec<Vec<Vec<u8>>> = Vec::new();
        for threads in ["1", "2", "8"] {
            let out = scratch(&format!("threads_{k}_{threads}"));
            let out = out.to_str().unwrap();
            let argv: Vec<String> = args.iter().map(|a| a.replace("OUT", out)).collect();
            let mut argv: Vec<&str> = argv.iter().map(String::as_str).collect();
            argv.extend(["--threads", threads]);
            let o = shadow(&argv);
            assert!(o.status.success(), "{argv:?}: {}", stderr(&o));
            let bytes = files
                .iter()
                .map(|f| std::fs::read(f.replace("OUT", out)).unwrap())
                .collect();
            outputs.push(bytes);
        }
        assert!(outputs[0].iter().all(|f| !f.is_empty()), "{args:?}");
        assert!(
            outputs.iter().all(|o| *o == outputs[0]),
            "{args:?} differs with the thread count"
        );
    }
}

/// Coordinates whose areas or volumes leave `f64`'s range, or a scene too
/// small for the finest grid: a clear error, not a NaN or a coarse snap;
/// and every scale the checks let through gives the areas and sun-hours
/// of a sane scale.
#[test]
fn huge_and_tiny_coordinates_are_clear_errors_or_exact() {
    let write = |name: &str, s: f64| {
        let p = scratch(name);
        let text = format!(
            "v 0 0 0\nv {s:e} 0 0\nv 0 {s:e} 0\nv 0 0 {s:e}\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
        );
        std::fs::write(&p, text).unwrap();
        p
    };
    let huge = write("huge_tetra.obj", 1e300);
    let tiny = write("tiny_tetra.obj", 1e-300);
    let (h, t) = (huge.to_str().unwrap(), tiny.to_str().unwrap());
    let out = scratch("hostile_coordinates.json");
    let out = out.to_str().unwrap();
    let o = shadow(&["shadows", h, "--sun", "0,0,1", "-o", out]);
    assert_failed_with(&o, &["huge_tetra.obj", "areas do not fit in f64"]);
    let never = scratch("hostile_coordinates.obj");
    let never = never.to_str().unwrap();
    let o = shadow(&["csg", "union", h, h, "-o", never]);
    assert_failed_with(&o, &["huge_tetra.obj", "volume does not fit in f64"]);
    // a view frames the scene: its eye would stand beyond f64's range
    let svg = scratch("hostile_coordinates.svg");
    let o = shadow(&["view", h, "-o", svg.to_str().unwrap()]);
    assert_failed_with(&o, &["huge_tetra.obj", "spans 1.000e300 units", "--eye"]);
    assert!(!stderr(&o).contains("NaN"), "{}", stderr(&o));
    assert!(!svg.exists());
    let o = shadow(&["shadows", t, "--sun", "0,0,1", "-o", out]);
    assert_failed_with(&o, &["too small"]);
    let o = shadow(&["csg", "union", t, t, "-o", never]);
    assert_failed_with(&o, &["too small"]);
    // a sane scale of the same tetrahedron works
    let fine = write("fine_tetra.obj", 2.0);
    // a number echoed in a message keeps its exponent
    let f = fine.to_str().unwrap();
    let o = shadow(&["shadows", f, "--light", "1e300,0,0", "-o", out]);
    assert!(
        !o.status.success() && stderr(&o).contains("--light 1e300,0,0"),
        "{}",
        stderr(&o)
    );
    assert!(stderr(&o).len() < 600, "{}", stderr(&o));
    let o = shadow(&[
        "shadows",
        fine.to_str().unwrap(),
        "--sun",
        "1,2,3",
        "-o",
        out,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    // and so does every scale the checks let through: the areas are those
    // of the tetrahedron, not an overflow to infinity or an underflow to 0
    // (the normal's length is the fourth power of the size)
    let csv = scratch("scaled_tetra.csv");
    let csv = csv.to_str().unwrap();
    let day = [
        "--lat",
        "50",
        "--lon",
        "0",
        "--date",
        "2026-06-21",
        "--step",
        "60",
        "-o",
        csv,
    ];
    let hours = |p: &str| {
        let o = shadow(&[&["sunhours", p][..], &day[..]].concat());
        assert!(o.status.success(), "{p}: {}", stderr(&o));
        let text = std::fs::read_to_string(csv).unwrap();
        // each face's area, and its hours (mean, fewest, most)
        let rows: Vec<(f64, String)> = (text.lines().skip(1))
            .map(|l| {
                let cells: Vec<&str> = l.split(',').collect();
                let hours: Vec<f64> = cells[3..6].iter().map(|c| c.parse().unwrap()).collect();
                let rounded: Vec<String> = hours.iter().map(|h| format!("{h:.9}")).collect();
                (cells[2].parse().unwrap(), rounded.join(","))
            })
            .collect();
        rows
    };
    let unit = hours(fine.to_str().unwrap());
    for s in [1e-150, 1e-81, 1e77, 1e150] {
        let p = write("scaled_tetra.obj", s);
        // the sun-hours of each face are the same at every scale
        let scaled = hours(p.to_str().unwrap());
        for ((a, h), (b, g)) in scaled.iter().zip(&unit) {
            assert_eq!(h, g, "{s:e}");
            assert!(
                (a / (b * s * s / 4.0) - 1.0).abs() < 1e-6,
                "{s:e}: area {a:e}"
            );
        }
        let o = shadow(&["shadows", p.to_str().unwrap(), "--sun", "1,2,3", "-o", out]);
        assert!(o.status.success(), "{s:e}: {}", stderr(&o));
        assert!(
            stdout(&o).contains("36.6% of the area lit"),
            "{s:e}: {}",
            stdout(&o)
        );
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out).unwrap()).unwrap();
        let area = json["summary"]["area"].as_f64().unwrap();
        let want = (3.0 + 3f64.sqrt()) / 2.0 * s * s;
        assert!(
            (area / want - 1.0).abs() < 1e-6,
            "{s:e}: area {area:e}, want {want:e}"
        );
    }
}
