//! `shadows`: JSON schema, exact shadow polygons, OBJ groups, SVG, errors.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::{assert_failed_with, scratch, shadow, stderr, stdout};

/// A 2 × 2 floor at z = 0 (face 0, facing up) and a 0.5 × 0.5 occluder
/// at z = 1 (face 1, facing up) over `[0.5, 1]²`, in a file of its own
/// for each caller (tests run at once: one must not read the file while
/// another rewrites it).
fn floor_and_occluder() -> PathBuf {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static CALLS: AtomicUsize = AtomicUsize::new(0);
    let n = CALLS.fetch_add(1, Ordering::Relaxed);
    let path = scratch(&format!("floor_and_occluder_{n}.obj"));
    std::fs::write(
        &path,
        "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\n\
         v 0.5 0.5 1\nv 1 0.5 1\nv 1 1 1\nv 0.5 1 1\n\
         f 1 2 3 4\nf 5 6 7 8\n",
    )
    .unwrap();
    path
}

/// Runs `shadow shadows INPUT ARGS... -o OUT.json` and parses the output.
fn shadows_json(input: &Path, args: &[&str], name: &str) -> Value {
    let out = scratch(name);
    let mut argv = vec!["shadows", input.to_str().unwrap()];
    argv.extend(args);
    argv.extend(["-o", out.to_str().unwrap()]);
    let o = shadow(&argv);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).starts_with(&format!("wrote {}", out.display())),
        "{}",
        stdout(&o)
    );
    serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).expect("valid JSON")
}

fn point(v: &Value) -> [f64; 3] {
    let a = v.as_array().expect("a point is an array");
    assert_eq!(a.len(), 3, "{v}");
    [0, 1, 2].map(|k| {
        let c = a[k].as_f64().expect("a coordinate is a number");
        assert!(c.is_finite());
        c
    })
}

/// Checks the required schema; returns the number of lights.
fn check_schema(doc: &Value) -> usize {
    let lights = doc["lights"].as_array().expect("lights");
    for l in lights {
        match l["kind"].as_str() {
            Some("point") => {
                point(&l["position"]);
            }
            Some("directional") => {
                let d = point(&l["direction"]);
                let len = d.iter().map(|c| c * c).sum::<f64>().sqrt();
                assert!((len - 1.0).abs() < 1e-15, "normalized: {len}");
            }
            _ => panic!("bad light {l}"),
        }
    }
    let faces = doc["faces"].as_u64().expect("faces") as usize;
    let frags = doc["fragments"].as_array().expect("fragments");
    for f in frags {
        let face = f["face"].as_u64().expect("face index") as usize;
        assert!(face < faces, "{f}");
        let vs = f["vertices"].as_array().expect("vertices");
        assert!(vs.len() >= 3, "{f}");
        vs.iter().for_each(|v| {
            point(v);
        });
        let lit = f["lit"].as_array().expect("lit");
        assert_eq!(lit.len(), lights.len(), "{f}");
        assert!(lit.iter().all(Value::is_boolean), "{f}");
    }
    lights.len()
}

fn vertices(f: &Value) -> Vec<[f64; 3]> {
    f["vertices"]
        .as_array()
        .unwrap()
        .iter()
        .map(point)
        .collect()
}

/// The fragments of `face` with `lit` flags.
fn fragments<'a>(doc: &'a Value, face: u64, lit: &[bool]) -> Vec<&'a Value> {
    let lit: Vec<Value> = lit.iter().map(|&b| Value::Bool(b)).collect();
    doc["fragments"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|f| f["face"] == face && f["lit"].as_array().unwrap() == &lit)
        .collect()
}

/// Twice the signed area of the polygon's projection on the xy plane.
fn xy_area2(v: &[[f64; 3]]) -> f64 {
    (0..v.len())
        .map(|i| {
            let (a, b) = (v[i], v[(i + 1) % v.len()]);
            a[0] * b[1] - a[1] * b[0]
        })
        .sum()
}

fn sorted(mut v: Vec<[f64; 3]>) -> Vec<[f64; 3]> {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v
}

#[test]
fn a_point_light_casts_the_exact_shadow_in_input_units() {
    let doc = shadows_json(
        &floor_and_occluder(),
        &["--light", "0.75,0.75,2"],
        "point.json",
    );
    assert_eq!(check_schema(&doc), 1);
    assert_eq!(doc["faces"], 2);
    assert_eq!(
        doc["lights"][0],
        serde_json::json!({"kind": "point", "position": [0.75, 0.75, 2.0]})
    );
    // from height 2 through height 1 the occluder's shadow doubles in
    // size about the light's foot: [0.25, 1.25]²
    let shadow = fragments(&doc, 0, &[false]);
    assert_eq!(shadow.len(), 1, "{shadow:?}");
    let v = vertices(shadow[0]);
    assert_eq!(
        sorted(v.clone()),
        vec![
            [0.25, 0.25, 0.0],
            [0.25, 1.25, 0.0],
            [1.25, 0.25, 0.0],
            [1.25, 1.25, 0.0]
        ]
    );
    assert!(xy_area2(&v) > 0.0, "counter-clockwise seen from above");
    assert_eq!(shadow[0]["area"], 1.0);
    // the rest of the floor and the whole occluder are lit
    let lit_floor: f64 = fragments(&doc, 0, &[true])
        .iter()
        .map(|f| f["area"].as_f64().unwrap())
        .sum();
    assert!((lit_floor - 3.0).abs() < 1e-12, "{lit_floor}");
    assert_eq!(fragments(&doc, 1, &[false]).len(), 0);
    let s = &doc["summary"];
    assert!((s["area"].as_f64().unwrap() - 4.25).abs() < 1e-12, "{s}");
    assert!((s["cast_shadow_area"][0].as_f64().unwrap() - 1.0).abs() < 1e-12);
    assert!((s["lit_area"][0].as_f64().unwrap() - 3.25).abs() < 1e-12);
}

#[test]
fn lights_come_first_then_suns_and_suns_are_normalized() {
    // the sun is given first on the command line but numbered after the
    // point light; straight overhead it casts the occluder's own outline
    let doc = shadows_json(
        &floor_and_occluder(),
        &["--sun", "0,0,5", "--light", "0.75,0.75,2"],
        "order.json",
    );
    assert_eq!(check_schema(&doc), 2);
    assert_eq!(doc["lights"][0]["kind"], "point");
    assert_eq!(
        doc["lights"][1],
        serde_json::json!({"kind": "directional", "direction": [0.0, 0.0, 1.0]})
    );
    // in both shadows: the occluder's outline [0.5, 1]²
    let both = fragments(&doc, 0, &[false, false]);
    assert_eq!(both.len(), 1);
    assert_eq!(
        sorted(vertices(both[0])),
        vec![
            [0.5, 0.5, 0.0],
            [0.5, 1.0, 0.0],
            [1.0, 0.5, 0.0],
            [1.0, 1.0, 0.0]
        ]
    );
    // the ring around it is in the point light's shadow only
    let ring: f64 = fragments(&doc, 0, &[false, true])
        .iter()
        .map(|f| f["area"].as_f64().unwrap())
        .sum();
    assert!((ring - 0.75).abs() < 1e-12, "{ring}");
    assert!(fragments(&doc, 0, &[true, false]).is_empty());
}

#[test]
fn every_face_of_a_closed_scene_appears() {
    let doc = shadows_json(
        Path::new(&unit_cube()),
        &["--light", "3,2,5", "--sun", "-1,0.5,2"],
        "cube.json",
    );
    assert_eq!(check_schema(&doc), 2);
    assert_eq!(doc["faces"], 6);
    let seen: BTreeSet<u64> = doc["fragments"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["face"].as_u64().unwrap())
        .collect();
    assert_eq!(seen, (0..6).collect());
    // a convex solid does not shadow itself: a face is lit exactly when
    // it faces the light (top, +x and +y faces for the point light)
    for f in doc["fragments"].as_array().unwrap() {
        let face = f["face"].as_u64().unwrap();
        assert_eq!(f["lit"][0], matches!(face, 1 | 3 | 4), "{f}");
    }
}

/// A unit cube as an OBJ file.
fn unit_cube() -> String {
    let path = scratch("unit_cube.obj");
    std::fs::write(
        &path,
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
         f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n",
    )
    .unwrap();
    path.display().to_string()
}

#[test]
fn room_json_covers_every_face_with_its_default_light() {
    let out = scratch("room.json");
    let o = shadow(&["shadows", "--scene", "room", "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("the room's default light (--light "),
        "{}",
        stdout(&o)
    );
    let doc: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    assert_eq!(check_schema(&doc), 1);
    let faces = doc["faces"].as_u64().unwrap();
    let seen: BTreeSet<u64> = doc["fragments"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["face"].as_u64().unwrap())
        .collect();
    assert_eq!(seen, (0..faces).collect());
    // some of the floor (face 5, facing the light) is in cast shadow
    assert!(!fragments(&doc, 5, &[false]).is_empty());
    assert!(!fragments(&doc, 5, &[true]).is_empty());
}

/// A face of an OBJ file: its `g` line's names and its vertex indices
/// (0-based).
type ObjFace = (String, Vec<usize>);

/// Parses an OBJ written by `shadows`: positions and faces.
fn read_obj(path: &Path) -> (Vec<[f64; 3]>, Vec<ObjFace>) {
    let text = std::fs::read_to_string(path).unwrap();
    let (mut pos, mut faces, mut group) = (Vec::new(), Vec::new(), String::new());
    for line in text.lines() {
        let mut t = line.split_whitespace();
        match t.next() {
            Some("v") => {
                let c: Vec<f64> = t.map(|x| x.parse().unwrap()).collect();
                pos.push([c[0], c[1], c[2]]);
            }
            Some("g") => group = t.collect::<Vec<_>>().join(" "),
            Some("f") => faces.push((
                group.clone(),
                t.map(|x| x.parse::<usize>().unwrap() - 1).collect(),
            )),
            _ => {}
        }
    }
    (pos, faces)
}

#[test]
fn obj_has_lit_and_shadow_groups_and_shared_vertices() {
    let out = scratch("shadows.obj");
    let input = floor_and_occluder();
    let o = shadow(&[
        "shadows",
        input.to_str().unwrap(),
        "--light",
        "0.75,0.75,2",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (pos, faces) = read_obj(&out);
    let groups: BTreeSet<&str> = faces.iter().map(|(g, _)| g.as_str()).collect();
    assert_eq!(groups, BTreeSet::from(["lit", "shadow"]));
    let shadow_faces: Vec<&Vec<usize>> = faces
        .iter()
        .filter(|(g, _)| g == "shadow")
        .map(|(_, f)| f)
        .collect();
    assert_eq!(shadow_faces.len(), 1);
    let square: Vec<[f64; 3]> = shadow_faces[0].iter().map(|&i| pos[i]).collect();
    assert_eq!(sorted(square)[0], [0.25, 0.25, 0.0]);
    // welded: no position twice, and every corner of the shadow square is
    // shared with a lit fragment around it
    let distinct: BTreeSet<[u64; 3]> = pos.iter().map(|p| p.map(f64::to_bits)).collect();
    assert_eq!(distinct.len(), pos.len());
    for &v in shadow_faces[0] {
        assert!(faces.iter().any(|(g, f)| g == "lit" && f.contains(&v)));
    }

    // two lights: combination groups beside `lit`
    let o = shadow(&[
        "shadows",
        input.to_str().unwrap(),
        "--light",
        "0.75,0.75,2",
        "--sun",
        "0,0,1",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (_, faces) = read_obj(&out);
    let groups: BTreeSet<&str> = faces.iter().map(|(g, _)| g.as_str()).collect();
    assert_eq!(
        groups,
        BTreeSet::from(["lit lit_0_1", "lit lit_1", "shadow"])
    );
}

#[test]
fn svg_of_the_room_and_of_a_file() {
    let out = scratch("room_shadows.svg");
    let o = shadow(&["shadows", "--scene", "room", "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stderr(&o), "");
    let svg = std::fs::read_to_string(&out).unwrap();
    assert!(svg.starts_with("<?xml") && svg.trim_end().ends_with("</svg>"));
    assert!(svg.matches("<path d=\"M").count() > 300);

    let input = floor_and_occluder();
    let o = shadow(&[
        "shadows",
        input.to_str().unwrap(),
        "--light",
        "0.75,0.75,2",
        "--eye",
        "1,-3,3",
        "-o",
        out.to_str().unwrap(),
        "--width",
        "320",
        "--height",
        "240",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let svg = std::fs::read_to_string(&out).unwrap();
    assert!(svg.contains(r#"width="320" height="240""#));
    // the lit floor, its shadow and the occluder: three colours
    let fills: BTreeSet<&str> = svg
        .split("fill=\"")
        .skip(2) // the background
        .map(|s| &s[..7])
        .collect();
    assert_eq!(fills.len(), 3, "{fills:?}");
}

#[test]
fn stats_report_areas_and_the_quantized_sun() {
    let out = scratch("stats.json");
    let o = shadow(&[
        "shadows",
        floor_and_occluder().to_str().unwrap(),
        "--light",
        "0.75,0.75,2",
        "--sun",
        "1,2,7",
        "-o",
        out.to_str().unwrap(),
        "--stats",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = stdout(&o);
    for key in [
        "fragments:",
        "light 0:         point light --light 0.75,0.75,2, on the grid",
        "light 1:         sun --sun 1,2,7, integer direction 9586980,19173961,67108863",
        "degrees from the given one",
        "time:",
        "area:            4.250000",
        "light 0 area:    lit 3.250000 (76.5%), in shadow 1.000000 (23.5%): cast 1.000000",
        "faces with the most cast shadow",
    ] {
        assert!(s.contains(key), "`{key}` not in {s}");
    }
}

#[test]
fn shadows_errors() {
    let input = floor_and_occluder();
    let input = input.to_str().unwrap();
    let never = scratch("never.json");
    let out = never.to_str().unwrap();

    let o = shadow(&["shadows", input, "-o", out]);
    assert_failed_with(&o, &["no light", "--light X,Y,Z", "--sun X,Y,Z"]);

    let o = shadow(&["shadows", input, "--light", "0,0,1e9", "-o", out]);
    assert_failed_with(
        &o,
        &[
            "light 0 (--light 0,0,1000000000): outside the grid",
            "--sun",
        ],
    );

    let o = shadow(&[
        "shadows", input, "--sun", "0,0,0", "--light", "1,1,3", "-o", out,
    ]);
    assert_failed_with(&o, &["light 1 (--sun 0,0,0): the sun direction is zero"]);

    let png = scratch("out.png");
    let o = shadow(&[
        "shadows",
        input,
        "--light",
        "1,1,3",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert_failed_with(
        &o,
        &["out.png: unknown output format (use .json, .obj or .svg)"],
    );
    assert!(!png.exists());

    let svg = scratch("no_eye.svg");
    let o = shadow(&[
        "shadows",
        input,
        "--light",
        "1,1,3",
        "-o",
        svg.to_str().unwrap(),
    ]);
    // no --eye: the mesh is framed, and the camera printed
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("note: camera --eye "), "{}", stderr(&o));
    assert!(svg.exists());

    let o = shadow(&["shadows", "--scene", "cube", "-o", out]);
    assert_failed_with(&o, &["no light"]);
    let o = shadow(&["shadows", input, "--light", "1,nan,3", "-o", out]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("not a finite number"));
    assert!(!never.exists());
}

#[test]
fn output_is_the_same_for_every_thread_count() {
    // the 33k-face bunny spans several rounds of chunks; two point lights
    // and a sun
    for ext in ["json", "obj"] {
        let mut outputs = Vec::new();
        for threads in ["1", "2", "3"] {
            let out = scratch(&format!("threads_{threads}.{ext}"));
            let o = shadow(&[
                "shadows",
                "--scene",
                "bunny-33k",
                "--light",
                "4,16,6",
                "--light",
                "-6,12,2",
                "--sun",
                "0.3,1,0.2",
                "--threads",
                threads,
                "-o",
                out.to_str().unwrap(),
            ]);
            assert!(o.status.success(), "{}", stderr(&o));
            outputs.push(std::fs::read(&out).unwrap());
        }
        assert!(outputs[0].len() > 1_000_000, "{ext}: {}", outputs[0].len());
        assert!(outputs.iter().all(|o| *o == outputs[0]), "{ext} differs");
    }
}

#[test]
fn uniformly_lit_faces_are_single_fragments_of_their_own_polygon() {
    // a unit cube lit from one side: every face is uniformly lit or in
    // attached shadow, so every face is exactly one fragment, its own
    // square with its own corners
    let doc = shadows_json(
        Path::new(&unit_cube()),
        &["--light", "3,2,5"],
        "one_each.json",
    );
    let frags = doc["fragments"].as_array().unwrap();
    assert_eq!(frags.len(), 6);
    for f in frags {
        let v = vertices(f);
        assert_eq!(v.len(), 4, "{f}");
        assert!(
            v.iter().all(|p| p.iter().all(|c| *c == 0.0 || *c == 1.0)),
            "{f}"
        );
        assert!(f.get("holes").is_none(), "{f}");
    }
}

#[test]
fn a_shadow_inside_a_face_is_a_hole_in_its_lit_fragment() {
    // the occluder's shadow [0.25, 1.25]² lies inside the 2 × 2 floor: the
    // lit floor is one fragment with one hole, the shadow's square
    let doc = shadows_json(
        &floor_and_occluder(),
        &["--light", "0.75,0.75,2"],
        "hole.json",
    );
    let lit = fragments(&doc, 0, &[true]);
    assert_eq!(lit.len(), 1);
    assert_eq!(sorted(vertices(lit[0]))[0], [0.0, 0.0, 0.0]);
    let holes = lit[0]["holes"].as_array().expect("a hole");
    assert_eq!(holes.len(), 1);
    let hole: Vec<[f64; 3]> = holes[0].as_array().unwrap().iter().map(point).collect();
    assert!(
        xy_area2(&hole) < 0.0,
        "holes run clockwise seen from the front"
    );
    assert_eq!(
        sorted(hole),
        vec![
            [0.25, 0.25, 0.0],
            [0.25, 1.25, 0.0],
            [1.25, 0.25, 0.0],
            [1.25, 1.25, 0.0]
        ]
    );
    assert_eq!(lit[0]["area"], 3.0);
}

#[test]
fn chin_feiner_gives_the_same_areas() {
    let a = shadows_json(
        &floor_and_occluder(),
        &["--light", "0.75,0.75,2"],
        "psv.json",
    );
    let b = shadows_json(
        &floor_and_occluder(),
        &["--light", "0.75,0.75,2", "--algorithm", "chin-feiner"],
        "cf.json",
    );
    assert_eq!(a["summary"], b["summary"]);
    // Chin & Feiner's fragments are convex pieces of the BSP's polygons:
    // never fewer than the fast path's
    let n = |d: &Value| d["fragments"].as_array().unwrap().len();
    assert!(n(&b) >= n(&a), "{} {}", n(&a), n(&b));
}

/// A file and `--scene` together is named as the conflict it is, before
/// anything about lights.
#[test]
fn a_file_and_a_scene_conflict() {
    let o = shadow(&["shadows", "a.obj", "--scene", "room", "-o", "x.json"]);
    assert_failed_with(&o, &["not both"]);
}

/// `shadow shadows INPUT --light LIGHT -o OUT EXTRA...`, its output.
fn lit_by(input: &str, light: &str, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "shadows",
        input,
        "--light",
        light,
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend(extra);
    let o = shadow(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    o
}

/// Outcomes that usually mean a mistake get a note: a light inside a
/// closed mesh lights nothing; faces without area shade nothing.
#[test]
fn nothing_lit_and_nothing_shaded_are_noted() {
    let (cube, out) = (unit_cube(), scratch("inside.json"));
    let o = lit_by(&cube, "0.5,0.5,0.5", &out, &[]);
    assert!(
        stdout(&o).contains("0.0% of the area lit"),
        "{}",
        stdout(&o)
    );
    let note = "note: nothing is lit (is a point light inside a closed mesh";
    assert!(stderr(&o).contains(note), "{}", stderr(&o));
    let o = lit_by(&cube, "3,2,5", &out, &[]);
    assert!(!stderr(&o).contains("nothing is lit"), "{}", stderr(&o));

    let flat = scratch("collinear.obj");
    std::fs::write(&flat, "v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\n").unwrap();
    let o = lit_by(flat.to_str().unwrap(), "3,2,5", &out, &[]);
    let note = "note: no face has an area on the grid";
    assert!(stderr(&o).contains(note), "{}", stderr(&o));
    // the SVG counts pieces of the scene tree's polygons, and says so
    let o = lit_by(&cube, "3,2,5", &scratch("cube_counts.svg"), &[]);
    let counts = "fragments of the scene tree's 6 polygons (6 faces)";
    assert!(stdout(&o).contains(counts), "{}", stdout(&o));
}

/// Flags that do not apply to the chosen output get a note, and the
/// output is what it is without them.
#[test]
fn flags_that_do_not_apply_are_noted() {
    let (cube, out) = (unit_cube(), scratch("flags.json"));
    let plain = lit_by(&cube, "3,2,5", &out, &[]);
    assert!(!stderr(&plain).contains("only apply"));
    let first = std::fs::read(&out).unwrap();
    for extra in [["--fov", "30"], ["--size", "64x48"], ["--eye", "5,5,5"]] {
        let o = lit_by(&cube, "3,2,5", &out, &extra);
        assert!(
            stderr(&o).contains("only apply to SVG output"),
            "{extra:?}: {}",
            stderr(&o)
        );
        assert_eq!(std::fs::read(&out).unwrap(), first);
    }
    let png = scratch("flags.png");
    let render = |extra: &[&str]| {
        let mut args = vec![
            "render", &cube, "--light", "3,2,5", "--size", "64x48", "--pcf", "3",
        ];
        args.extend(extra);
        args.extend(["-o", png.to_str().unwrap()]);
        let o = shadow(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        stderr(&o)
    };
    let err = render(&[]);
    assert!(
        err.contains("note: --method exact does not use --pcf"),
        "{err}"
    );
    let err = render(&["--method", "shadow-map"]);
    assert!(!err.contains("does not use"), "{err}");
}

/// Runs `shadow shadows` on the floor and occluder with an area light
/// (0.2 × 0.2 at height 2 over the occluder's centre) and more flags.
fn soft_json(extra: &[&str], name: &str) -> Value {
    soft_json_of(&floor_and_occluder(), extra, name)
}

/// [`soft_json`] of the scene `input`.
fn soft_json_of(input: &Path, extra: &[&str], name: &str) -> Value {
    let mut args = vec![
        "--area-light",
        "0.65,0.65,2;0.65,0.85,2;0.85,0.85,2;0.85,0.65,2",
    ];
    args.extend(extra);
    shadows_json(input, &args, name)
}

/// The area light's regions in closed form: from height 2 through the
/// occluder at height 1, the umbra on the floor is `[0.35, 1.15]²`, the
/// penumbra reaches `[0.15, 1.35]²`; the occluder's top is lit. Every
/// fragment has one flag per light, penumbra fragments the share of the
/// light they see, and the areas add up. The floor is cut only where a
/// class changes: one lit fragment with the penumbra as its hole, one
/// penumbra fragment round the umbra (its share from about 0 at its
/// hole's corners to about 1 at its outer ones), one umbra fragment.
#[test]
fn an_area_light_gives_umbra_and_penumbra_in_closed_form() {
    let doc = soft_json(&[], "soft_area.json");
    assert_eq!(doc["lights"][0]["kind"], "area");
    let s = &doc["summary"];
    let first = |key: &str| s[key][0].as_f64().unwrap();
    let near = |a: f64, b: f64| (a - b).abs() < 1e-6;
    assert!(near(first("umbra_area"), 0.64), "{s}");
    assert!(near(first("penumbra_area"), 0.80), "{s}");
    assert!(near(first("lit_area"), 2.56 + 0.25), "{s}");
    assert_eq!(first("undecided_area"), 0.0);
    let mut shares = 0;
    let holes = |f: &Value| f.get("holes").map_or(0, |h| h.as_array().unwrap().len());
    let mut floor_holes = Vec::new();
    for f in doc["fragments"].as_array().unwrap() {
        if f["face"] == 0 {
            floor_holes.push(holes(f));
        }
        let (lit, umbra) = (
            f["lit"][0].as_bool().unwrap(),
            f["umbra"][0].as_bool().unwrap(),
        );
        assert!(!(lit && umbra), "{f}");
        let visible = &f["visible"][0];
        if lit || umbra {
            assert!(visible.is_null(), "{f}");
            continue;
        }
        let (v, lo, hi) = (
            visible.as_f64().unwrap(),
            f["visible_min"][0].as_f64().unwrap(),
            f["visible_max"][0].as_f64().unwrap(),
        );
        assert!(
            (0.0..=1.0).contains(&v) && 0.0 <= lo && lo <= hi && hi <= 1.0,
            "{f}"
        );
        assert!(lo < 0.05 && hi > 0.95 && lo < v && v < hi, "{f}");
        assert_eq!(holes(f), 1, "{f}");
        shares += 1;
    }
    assert_eq!(shares, 1, "{shares} penumbra fragments");
    floor_holes.sort_unstable();
    assert_eq!(floor_holes, [0, 1, 1], "the floor's fragments' holes");
}

/// Two occluders at two heights that only together hide the area light
/// from a strip of the floor: that strip is one fragment flagged
/// `undecided` (penumbra that may be umbra), its area the summary's
/// `undecided_area`, apart from the decided penumbra beside it.
#[test]
fn undecided_fragments_are_flagged_and_counted() {
    let input = scratch("joint.obj");
    std::fs::write(
        &input,
        "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\n\
         v 0.5 0.5 1\nv 0.76 0.5 1\nv 0.76 1 1\nv 0.5 1 1\n\
         v 0.74 0.5 1.1\nv 1 0.5 1.1\nv 1 1 1.1\nv 0.74 1 1.1\n\
         f 1 2 3 4\nf 5 6 7 8\nf 9 10 11 12\n",
    )
    .unwrap();
    let doc = soft_json_of(&input, &[], "joint.json");
    let want = doc["summary"]["undecided_area"][0].as_f64().unwrap();
    assert!(want > 0.1, "{}", doc["summary"]);
    let mut got = Vec::new();
    for f in doc["fragments"].as_array().unwrap() {
        if f["undecided"][0].as_bool().unwrap() {
            assert_eq!(
                (&f["lit"][0], &f["umbra"][0]),
                (&false.into(), &false.into()),
                "{f}"
            );
            got.push(f["area"].as_f64().unwrap());
        }
    }
    assert_eq!(got.len(), 1, "{got:?}");
    assert!((got[0] - want).abs() < 1e-12, "{got:?} against {want}");
}

/// A point light among soft lights is classified exactly as alone: lit
/// or umbra, with the lit area the partitioned shadow volumes give; a sun
/// disc of radius 0 likewise equals the sun. The OBJ has the classes'
/// groups.
#[test]
fn point_lights_and_suns_among_soft_lights_keep_their_shadows() {
    let input = floor_and_occluder();
    let hard = shadows_json(
        &input,
        &["--light", "0.75,0.75,2", "--sun", "1,2,5"],
        "hard.json",
    );
    let doc = soft_json(
        &[
            "--light",
            "0.75,0.75,2",
            "--sun-disc",
            "1,2,5:0",
            "--sun-disc",
            "1,2,5",
        ],
        "soft_mixed.json",
    );
    let kinds: Vec<&str> = doc["lights"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["kind"].as_str().unwrap())
        .collect();
    assert_eq!(kinds, ["point", "area", "sun_disc", "sun_disc"]);
    let (s, h) = (&doc["summary"], &hard["summary"]);
    for (soft, hard) in [(0, 0), (2, 1)] {
        let lit = s["lit_area"][soft].as_f64().unwrap();
        let want = h["lit_area"][hard].as_f64().unwrap();
        assert!(
            (lit - want).abs() < 1e-9,
            "light {soft}: {lit} against {want}"
        );
        assert_eq!(s["penumbra_area"][soft].as_f64(), Some(0.0));
    }
    // the real sun's disc blurs the occluder's shadow a little
    let disc = s["penumbra_area"][3].as_f64().unwrap();
    assert!(disc > 0.0 && disc < 0.05, "{disc}");
    let out = scratch("soft.obj");
    let o = shadow(&[
        "shadows",
        input.to_str().unwrap(),
        "--area-light",
        "0.65,0.65,2;0.65,0.85,2;0.85,0.85,2;0.85,0.65,2",
        "--stats",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = stdout(&o);
    assert!(report.contains("light 0: lit "), "{report}");
    assert!(
        report.contains("per face)") && report.contains("time: "),
        "{report}"
    );
    let text = std::fs::read_to_string(&out).unwrap();
    for g in ["g lit", "g penumbra", "g umbra"] {
        assert!(text.lines().any(|l| l == g), "no `{g}` in\n{text}");
    }
}

/// Lights with extent that are no light, or outputs they cannot go to,
/// are errors naming the light.
#[test]
fn bad_soft_lights_are_errors() {
    let input = floor_and_occluder();
    let run = |args: &[&str], out: &str| {
        let out = scratch(out);
        let mut argv = vec!["shadows", input.to_str().unwrap()];
        argv.extend(args);
        argv.extend(["-o", out.to_str().unwrap()]);
        shadow(&argv)
    };
    let bent = run(&["--area-light", "0,0,3;1,0,3;1,1,3.5;0,1,3"], "bent.json");
    assert_failed_with(
        &bent,
        &[
            "light 0 (area light",
            "not in one plane",
            "up to 1.179e-1 units off",
        ],
    );
    // a tilted square whose corners are decimals: nearly flat, and said so
    let tilted = "0.7,0.1,2.45;0.7,0.5,2.5333333;1.1,0.5,2.6166667;1.1,0.1,2.5333333";
    let nearly = run(&["--area-light", tilted], "tilted.json");
    assert_failed_with(
        &nearly,
        &["not in one plane", "e-8 units off their plane as given"],
    );
    let two = run(&["--area-light", "0,0,3;1,0,3"], "two.json");
    assert_failed_with(&two, &["at least three"]);
    let wide = run(&["--sun", "0,0,1", "--sun-disc", "0,0,1:45"], "wide.json");
    assert_failed_with(
        &wide,
        &["light 1 (sun disc", "between 0° and 30° (given 45°)"],
    );
    let cf = run(
        &[
            "--area-light",
            "0,0,3;0,1,3;1,1,3",
            "--algorithm",
            "chin-feiner",
        ],
        "soft_cf.json",
    );
    assert_failed_with(&cf, &["--algorithm psv only"]);
}

/// An area light turned away from every face lights nothing, and the
/// report says which light and why that may be.
#[test]
fn an_area_light_turned_away_is_named() {
    let input = floor_and_occluder();
    // counter-clockwise seen from above: it shines up, away from both
    let up = "0.65,0.65,2;0.85,0.65,2;0.85,0.85,2;0.65,0.85,2";
    let out = scratch("turned_away.json");
    let o = shadow(&[
        "shadows",
        input.to_str().unwrap(),
        "--area-light",
        up,
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = stdout(&o);
    assert!(report.contains("umbra 100.0%"), "{report}");
    assert!(report.contains("light 0 reaches no face"), "{report}");
    let down = "0.65,0.65,2;0.65,0.85,2;0.85,0.85,2;0.85,0.65,2";
    let o = shadow(&[
        "shadows",
        input.to_str().unwrap(),
        "--area-light",
        down,
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(!stdout(&o).contains("reaches no face"), "{}", stdout(&o));
}

/// Soft shadows drawn: under a small square light, the floor's lit and
/// umbra parts have the colours of the point light at its centre, lit
/// and in shadow, and its penumbra is drawn with gradients whose colours
/// run between them.
#[test]
fn soft_shadows_are_drawn_between_lit_and_shadow() {
    let input = floor_and_occluder();
    // the colours after `key` (`fill="` or `stop-color="`), but the
    // background's and gradients' references
    let colours = |args: &[&str], name: &str, key: &str| -> BTreeSet<String> {
        let out = scratch(name);
        let mut argv = vec!["shadows", input.to_str().unwrap(), "--eye", "1,-3,3"];
        argv.extend(args);
        argv.extend(["-o", out.to_str().unwrap()]);
        let o = shadow(&argv);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(stdout(&o).contains(" drawn, eye "), "{}", stdout(&o));
        let svg = std::fs::read_to_string(&out).unwrap();
        assert!(svg.trim_end().ends_with("</svg>"));
        svg.split(key)
            .skip(1)
            .map(|s| s[..7].to_string())
            .filter(|c| c.starts_with('#') && c != "#e9ecf0")
            .collect()
    };
    let hard = colours(&["--light", "0.75,0.75,2"], "hard_floor.svg", "fill=\"");
    let light = "0.65,0.65,2;0.65,0.85,2;0.85,0.85,2;0.85,0.65,2";
    let soft = colours(&["--area-light", light], "soft_floor.svg", "fill=\"");
    assert!(hard.is_subset(&soft), "{hard:?} not in {soft:?}");
    let rgb = |f: &str| [1, 3, 5].map(|i| u8::from_str_radix(&f[i..i + 2], 16).unwrap());
    // the floor's lit and shadowed colours: the two of one hue
    let floor: Vec<[u8; 3]> = hard.iter().map(|f| rgb(f)).collect();
    let pair = floor
        .iter()
        .flat_map(|a| floor.iter().map(move |b| (*a, *b)));
    let (lit, dark) = pair
        .filter(|(a, b)| (0..3).all(|k| a[k] > b[k]))
        .max_by_key(|(a, b)| (0..3).map(|k| a[k] - b[k]).min())
        .unwrap();
    let stops = colours(&["--area-light", light], "soft_floor.svg", "stop-color=\"");
    assert!(!stops.is_empty(), "no gradient in the penumbra");
    let within = |c: &[u8; 3]| (0..3).all(|k| dark[k] <= c[k] && c[k] <= lit[k]);
    for s in &stops {
        assert!(within(&rgb(s)), "{s} is not between {dark:?} and {lit:?}");
    }
    let strictly = |c: &[u8; 3]| (0..3).all(|k| dark[k] < c[k] && c[k] < lit[k]);
    assert!(stops.iter().any(|s| strictly(&rgb(s))), "{stops:?}");
}

#[test]
fn art_deform_moves_a_shifted_view() {
    let dir = scratch("art_deform");
    std::fs::create_dir_all(&dir).unwrap();
    // three 16 × 16 views of an 8-cube, the third shifted by 2 pixels
    let pgm = |c0: usize| {
        let px: Vec<&str> = (0..256)
            .map(|p| {
                let (c, r) = (p % 16, p / 16);
                if (c0..c0 + 8).contains(&c) && (4..12).contains(&r) {
                    "0"
                } else {
                    "255"
                }
            })
            .collect();
        format!("P2\n16 16\n255\n{}\n", px.join(" "))
    };
    std::fs::write(dir.join("a.pgm"), pgm(4)).unwrap();
    std::fs::write(dir.join("b.pgm"), pgm(6)).unwrap();
    let spec = r#"{"views": [
        {"image": "a.pgm", "light": {"sun": [0, 0, 1]},
         "plane": {"origin": [0, 0, 0], "u": [1, 0, 0], "v": [0, 1, 0]}},
        {"image": "a.pgm", "light": {"sun": [1, 0, 0]},
         "plane": {"origin": [0, 0, 0], "u": [0, 1, 0], "v": [0, 0, 1]}},
        {"image": "b.pgm", "light": {"sun": [0, 1, 0]},
         "plane": {"origin": [0, 0, 0], "u": [1, 0, 0], "v": [0, 0, 1]}}],
        "bounds": [[0, 0, 0], [16, 16, 16]]}"#;
    let spec_path = dir.join("spec.json");
    std::fs::write(&spec_path, spec).unwrap();
    let (hull, report) = (dir.join("hull.obj"), dir.join("report.json"));
    let args = [
        "art",
        spec_path.to_str().unwrap(),
        "-o",
        hull.to_str().unwrap(),
    ];
    let o = shadow(
        &[
            &args[..],
            &[
                "--optimize",
                "--deform",
                "--report",
                report.to_str().unwrap(),
            ],
        ]
        .concat(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("rounds of deforming"), "{}", stdout(&o));
    let r: Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    for (k, v) in r["views"].as_array().unwrap().iter().enumerate() {
        let moved = v["max_deformation_px"].as_f64().unwrap();
        // the floor and the shifted wall moved, by about the shift
        assert_eq!(moved > 0.0, k != 1, "{r}");
        assert!(
            moved <= 3.0 && v["mean_deformation_px"].as_f64().unwrap() <= moved,
            "{r}"
        );
        let (missing, wanted) = (
            v["missing_area"].as_f64().unwrap(),
            v["wanted_area"].as_f64().unwrap(),
        );
        assert!(missing <= 0.005 * wanted, "{r}");
    }
    // --deform belongs to --optimize
    let o = shadow(&[&args[..], &["--deform"]].concat());
    assert!(!o.status.success());
    assert!(stderr(&o).contains("--optimize"), "{}", stderr(&o));
}

#[test]
fn art_makes_the_hull_its_report_and_pictures() {
    let dir = scratch("art");
    std::fs::create_dir_all(&dir).unwrap();
    // a 4 × 4 P2 image with its middle dark, under a sun straight down
    let pgm = "P2\n4 4\n255\n255 255 255 255\n255 0 0 255\n255 0 0 255\n255 255 255 255\n";
    std::fs::write(dir.join("sq.pgm"), pgm).unwrap();
    let spec = r#"{"views": [{"image": "sq.pgm", "light": {"sun": [0, 0, 1]},
        "plane": {"origin": [0, 0, 0], "u": [1, 0, 0], "v": [0, 1, 0]}}],
        "bounds": [[0, 0, 0], [4, 4, 2]]}"#;
    std::fs::write(dir.join("spec.json"), spec).unwrap();
    let (hull, report, views) = (
        dir.join("hull.stl"),
        dir.join("report.json"),
        dir.join("views"),
    );
    let o = shadow(&[
        "art",
        dir.join("spec.json").to_str().unwrap(),
        "-o",
        hull.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
        "--images",
        views.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("volume 8"), "{}", stdout(&o));
    let r: Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(r["hull"]["volume"], 8.0);
    assert_eq!(r["views"][0]["wanted_area"], 4.0);
    assert_eq!(r["views"][0]["missing_area"], 0.0);
    // the hull reads back as a closed mesh
    let back = bsp_shadows::read_mesh(&hull).unwrap();
    let loops: Vec<&[u32]> = back.faces.iter().map(|f| f.vertices.as_slice()).collect();
    assert!(bsp_core::check_closed_manifold(loops).is_ok());
    assert!(views.join("view0.png").exists());
    // views that agree need no growing
    let o = shadow(&[
        "art",
        dir.join("spec.json").to_str().unwrap(),
        "-o",
        hull.to_str().unwrap(),
        "--optimize",
        "--report",
        report.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("0 rounds of growing"), "{}", stdout(&o));
    let r: Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(r["views"][0]["pixels_added"], 0);
    assert!(r["views"][0].get("mean_deformation_px").is_none());
    // a staircase triangle simplified: fewer triangles, no extra shadow
    let stairs: String = (0..12)
        .flat_map(|r| (0..12).map(move |c| if c + r < 12 { "0 " } else { "255 " }))
        .collect();
    std::fs::write(dir.join("sq.pgm"), format!("P2\n12 12\n255\n{stairs}")).unwrap();
    let spec = spec.replace("[4, 4, 2]", "[12, 12, 2]");
    std::fs::write(dir.join("spec.json"), spec).unwrap();
    let spec_path = dir.join("spec.json");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "art",
            spec_path.to_str().unwrap(),
            "-o",
            hull.to_str().unwrap(),
        ];
        args.extend(["--report", report.to_str().unwrap()]);
        args.extend(extra);
        shadow(&args)
    };
    let triangles = |extra: &[&str]| {
        let o = run(extra);
        assert!(o.status.success(), "{}", stderr(&o));
        let r: Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
        (
            r["hull"]["triangles"].as_u64().unwrap(),
            r["views"][0].clone(),
            stdout(&o),
        )
    };
    let (pixels, _, _) = triangles(&[]);
    let (fewer, view, said) = triangles(&["--simplify", "1.5"]);
    assert!(fewer < pixels, "{fewer} against {pixels} triangles");
    assert!(said.contains("simplified within 1.5 px"), "{said}");
    // (78 pixels; within 1.5 px of the steps, between their two chords)
    let wanted = view["wanted_area"].as_f64().unwrap();
    assert!((72.0..=84.0).contains(&wanted), "{view}");
    assert!(view["extra_area"].as_f64().unwrap() < 1e-9, "{view}");
    assert!(view["missing_area"].as_f64().unwrap() < 1e-9, "{view}");
    let o = run(&["--simplify", "0"]);
    crate::assert_failed_with(&o, &["simplify within 0 pixels", "positive"]);
    // an all-white image is a clear error naming it
    std::fs::write(
        dir.join("sq.pgm"),
        "P2\n4 4\n255\n".to_string() + &"255 ".repeat(16),
    )
    .unwrap();
    let o = shadow(&[
        "art",
        dir.join("spec.json").to_str().unwrap(),
        "-o",
        hull.to_str().unwrap(),
    ]);
    crate::assert_failed_with(&o, &["view 0", "sq.pgm", "no wanted shadow"]);
}

#[test]
fn sun_prints_where_the_sun_is() {
    let o = shadow(&[
        "sun",
        "--lat",
        "51.48",
        "--lon",
        "0",
        "--time",
        "2026-03-21T12:00:00Z",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_str(&stdout(&o)).unwrap();
    let az = v["azimuth_deg"].as_f64().unwrap();
    let el = v["elevation_deg"].as_f64().unwrap();
    assert!((az - 180.0).abs() < 3.0 && (el - 38.9).abs() < 0.5, "{v}");
    // south in the default axes (+y north), and with y up (-z north)
    assert!(v["direction"][1].as_f64().unwrap() < -0.5, "{v}");
    let o = shadow(&[
        "sun",
        "--lat",
        "51.48",
        "--lon",
        "0",
        "--time",
        "2026-03-21T12:00:00+00:00",
        "--up",
        "y",
    ]);
    assert!(stdout(&o).starts_with("azimuth 177."), "{}", stdout(&o));
    // a time without its offset is refused, naming the form
    let o = shadow(&[
        "sun",
        "--lat",
        "51.48",
        "--lon",
        "0",
        "--time",
        "2026-03-21 12:00",
    ]);
    crate::assert_failed_with(&o, &["2026-03-21 12:00", "offset"]);
}

/// `shadow sunhours` of the cube on the equator at `date`, with `extra`.
fn equator_cube_sunhours(date: &str, extra: &[&str]) -> std::process::Output {
    let at = [
        "sunhours", "--scene", "cube", "--lat", "0", "--lon", "0", "--date", date,
    ];
    shadow(&[&at[..], extra].concat())
}

/// `shadow sunhours` of the cube on the equinox at Greenwich, hourly, to
/// `out`, with `extra` flags.
fn cube_sunhours(out: &Path, extra: &[&str]) -> std::process::Output {
    let mut argv = vec![
        "sunhours",
        "--scene",
        "cube",
        "--lat",
        "51.48",
        "--lon",
        "0",
        "--date",
        "2026-03-21",
        "--step",
        "60",
        "-o",
        out.to_str().unwrap(),
    ];
    argv.extend(extra);
    shadow(&argv)
}

#[test]
fn sunhours_writes_every_faces_hours() {
    let (csv, json) = (scratch("hours.csv"), scratch("hours.json"));
    let run = cube_sunhours;
    let o = run(&csv, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains(", 1 days"), "{}", stdout(&o));
    // an hour a sun is a study's usual step; a day a sun is said to be coarse
    assert!(
        !stderr(&o).contains("each sun stands for"),
        "{}",
        stderr(&o)
    );
    let day_csv = scratch("day_step.csv");
    let day = equator_cube_sunhours(
        "2026-03-21",
        &["--step", "1440", "-o", day_csv.to_str().unwrap()],
    );
    assert!(
        stderr(&day).contains("each sun stands for 1440 minutes"),
        "{}",
        stderr(&day)
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    let rows: Vec<Vec<&str>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(
        text.lines().next(),
        Some("face,group,area,sun_hours,min_hours,max_hours")
    );
    assert_eq!(rows.len(), 6);
    // the cube's top sees every sun above the horizon (about 12 hours)
    let top = rows
        .iter()
        .map(|r| r[3].parse::<f64>().unwrap())
        .fold(0.0, f64::max);
    assert!((11.0..=13.0).contains(&top), "{text}");
    for r in &rows {
        let h: Vec<f64> = r[3..].iter().map(|v| v.parse().unwrap()).collect();
        assert!(h[1] <= h[0] + 1e-9 && h[0] <= h[2] + 1e-9, "{r:?}");
    }
    let o = run(&json, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["faces"].as_array().unwrap().len(), 6);
    // how much of each group sees at least 11 hours: the cube's top (a
    // sixth of its area) sees every sun, its sides fewer
    let o = run(&csv, &["--min-hours", "11"]);
    let line = stdout(&o).lines().nth(1).unwrap_or_default().to_string();
    assert!(
        line.starts_with("cube: ") && line.ends_with("sees at least 11 hours of sun"),
        "{line}"
    );
    let share: f64 = line["cube: ".len()..line.find('%').unwrap()]
        .parse()
        .unwrap();
    assert!((16.0..50.0).contains(&share), "{line}");
    // hours at sensors: above the cube every sun, inside it none; a bad
    // sensors file names its line
    let points = scratch("sensors.csv");
    std::fs::write(&points, "x,y,z\n0.5,0.5,2\n0.5,0.5,0.5\n").unwrap();
    let o = run(&csv, &["--sensors", points.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("sun-hours of 2 sensors among the faces of"),
        "{}",
        stdout(&o)
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    let hours: Vec<f64> = (text.lines().skip(1))
        .map(|l| l.rsplit(',').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(text.lines().next(), Some("sensor,x,y,z,sun_hours"));
    assert!(hours[0] == top && hours[1] == 0.0, "{text}");
    // a sensor given its surface's normal counts the suns in front of it:
    // above the cube facing up, every sun; facing down, none
    std::fs::write(
        &points,
        "x,y,z,nx,ny,nz\n0.5,0.5,2,0,0,1\n0.5,0.5,2,0,0,-1\n",
    )
    .unwrap();
    let o = run(&csv, &["--sensors", points.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&csv).unwrap();
    let facing: Vec<f64> = (text.lines().skip(1))
        .map(|l| l.rsplit(',').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(facing, [top, 0.0], "{text}");
    std::fs::write(&points, "0.5,0.5\n").unwrap();
    let o = run(&json, &["--sensors", points.to_str().unwrap()]);
    crate::assert_failed_with(
        &o,
        &["sensors.csv:1:", "a sensor is x,y,z or x,y,z,nx,ny,nz"],
    );
    // a heat map to look at: every face, its corners coloured
    let heat = scratch("hours.obj");
    let o = run(&heat, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&heat).unwrap();
    assert!(text.starts_with("# sun-hours: viridis from 0"), "{text}");
    assert_eq!(text.lines().filter(|l| l.starts_with("f ")).count(), 6);
    // the mean alone: the same hours, the extremes' fields empty
    let mean = scratch("mean.csv");
    let o = run(&mean, &["--no-extremes"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&mean).unwrap();
    for (r, l) in rows.iter().zip(text.lines().skip(1)) {
        let m: Vec<&str> = l.split(',').collect();
        assert_eq!((&m[..4], &m[4..]), (&r[..4], &["", ""][..]), "{l}");
    }
    let o = run(&mean, &["--no-extremes", "--min-hours", "2"]);
    crate::assert_failed_with(&o, &["--no-extremes", "--min-hours"]);
    let o = run(&mean, &["--min-hours", "nan"]);
    crate::assert_failed_with(&o, &["--min-hours NaN: give a number of hours"]);
    // bad names and dates are clear errors
    let o = run(&scratch("hours.txt"), &[]);
    crate::assert_failed_with(&o, &["hours.txt", ".csv, .json, .obj, .ply or .png"]);
    let o = run(&csv, &["--to", "2026-02-30"]);
    crate::assert_failed_with(&o, &["2026-02-30", "not a date"]);
}
#[test]
fn sunhours_draws_pictures_and_overlays_regions() {
    let run = cube_sunhours;
    let points = scratch("sensors_for_png.csv");
    std::fs::write(&points, "0.5,0.5,2\n").unwrap();
    // the most hours a face gets, from the faces' study
    let faces = scratch("faces_for_regions.csv");
    assert!(run(&faces, &[]).status.success());
    let top = (std::fs::read_to_string(&faces).unwrap().lines().skip(1))
        .map(|l| l.split(',').nth(3).unwrap().parse::<f64>().unwrap())
        .fold(0.0, f64::max);
    // its picture: the cube framed, its faces in the ramp's colours (the
    // top, in every sun, yellow), the ramp itself along the bottom
    let png = scratch("hours.png");
    let o = run(&png, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(crate::raster::png_size(&png), (1280, 720));
    let (px, w) = crate::raster::rgb_of(&png);
    let at = |x: u32, y: u32| px[(y * w + x) as usize];
    assert_eq!((at(52, 699), at(307, 699)), ([68, 1, 84], [253, 231, 37]));
    let yellow = (px[..w as usize * 680].iter())
        .filter(|p| p[0] > 100 && p[0] > 2 * p[2] && p[1] > 2 * p[2])
        .count();
    assert!(yellow > 5000, "{yellow} yellow pixels");
    let o = run(&png, &["--sensors", points.to_str().unwrap()]);
    crate::assert_failed_with(&o, &["hours.png", "a picture shows faces' hours"]);
    // regions: the cube's faces as cells of exact hours, adding up to
    // the faces' area; the BRE 209 verdict on 21 March only
    let cells = scratch("cells.csv");
    let o = run(
        &cells,
        &["--regions", "cube", "--min-hours", "11", "--bre209"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let said = stdout(&o);
    assert!(said.contains("cells of 6 faces of scene cube"), "{said}");
    assert!(
        said.contains("region: ") && said.contains("sees at least 11 hours"),
        "{said}"
    );
    assert!(said.contains("BRE 209: the region passes: "), "{said}");
    let text = std::fs::read_to_string(&cells).unwrap();
    assert_eq!(text.lines().next(), Some("cell,face,group,hours,area"));
    // (a lone cube shades none of its own faces: a cell each, its area 1)
    let rows: Vec<Vec<&str>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 6, "{text}");
    assert!(rows.iter().all(|r| r[4] == "1"), "{text}");
    let most = rows
        .iter()
        .map(|r| r[3].parse::<f64>().unwrap())
        .fold(0.0, f64::max);
    assert_eq!(most, top, "{text}");
    let o = run(
        &cells,
        &["--regions", "cube", "--bre209", "--to", "2026-03-22"],
    );
    crate::assert_failed_with(&o, &["BRE 209 test is of 21 March"]);
    let o = run(&cells, &["--regions", "garden"]);
    crate::assert_failed_with(&o, &["no face is in a group `garden`; the groups: cube"]);
    let o = run(&cells, &["--regions", "0,9"]);
    crate::assert_failed_with(&o, &["face 9: the mesh has 6 faces"]);
    // the region's picture: its cells coloured, the other faces grey
    let o = run(&png, &["--regions", "0-2"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(crate::raster::png_size(&png), (1280, 720));
}

#[test]
fn sunhours_reads_a_cityjson_block_and_keeps_the_objects_ids() {
    let block = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/city/block.city.json");
    let csv = scratch("block_hours.csv");
    let (block, out) = (block.to_str().unwrap(), csv.to_str().unwrap());
    let site = ["--lat", "52.01", "--lon", "4.36", "--date", "2026-06-21"];
    let mut argv = vec!["sunhours", block, "--step", "60", "-o", out];
    argv.extend(site);
    let o = shadow(&argv);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut groups: Vec<&str> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap())
        .collect();
    groups.dedup();
    assert_eq!(groups, ["house", "tower-part", "tree-1", "yard"]);
    // the yard with its pond cut out, through the triangulation and the import
    let yard: f64 = text
        .lines()
        .filter(|l| l.split(',').nth(1) == Some("yard"))
        .map(|l| l.split(',').nth(2).unwrap().parse::<f64>().unwrap())
        .sum();
    assert!((yard - 3500.0).abs() < 1e-6, "{yard}");
    // cut into 2 × 2 tiles: the same rows, ids and hours to the last bits
    let tiled = scratch("block_hours_tiled.csv");
    let mut cut = argv.clone();
    cut[5] = tiled.to_str().unwrap();
    cut.extend(["--tiles", "2"]);
    let o = shadow(&cut);
    assert!(o.status.success(), "{}", stderr(&o));
    let again = std::fs::read_to_string(&tiled).unwrap();
    assert_eq!(again.lines().count(), text.lines().count());
    for (a, b) in text.lines().zip(again.lines()).skip(1) {
        let (a, b): (Vec<&str>, Vec<&str>) = (a.split(',').collect(), b.split(',').collect());
        assert_eq!(a[..2], b[..2]);
        for k in 2..6 {
            let (x, y) = (a[k].parse::<f64>().unwrap(), b[k].parse::<f64>().unwrap());
            assert!((x - y).abs() <= 1e-9 * x.abs().max(1.0), "{a:?} {b:?}");
        }
    }
    *cut.last_mut().unwrap() = "0";
    let o = shadow(&cut);
    crate::assert_failed_with(&o, &["invalid value '0' for '--tiles <N>'"]);
    // a broken file: the place in it named
    let bad = scratch("bad.city.json");
    let text = std::fs::read_to_string(block).unwrap();
    std::fs::write(&bad, text.replacen("[0,1,2,3]", "[0,1,2,40]", 1)).unwrap();
    argv[1] = bad.to_str().unwrap();
    let o = shadow(&argv);
    crate::assert_failed_with(
        &o,
        &["/CityObjects/yard/geometry/0/boundaries/0/0/3: vertex 40 out of range (0..=39)"],
    );
}

#[test]
fn sunhours_exact_time_gives_sensors_intervals_in_closed_form() {
    let block = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/city/block.city.json");
    let sensors = scratch("yard_sensors.csv");
    // in the yard: west of the house, just north of the tower, the open
    // north-west corner
    let points = "x,y,z\n85005,446015,0\n85034,446021,0\n85005,446055,0\n";
    std::fs::write(&sensors, points).unwrap();
    let (json, csv, sampled) = (
        scratch("exact.json"),
        scratch("exact.csv"),
        scratch("sampled.csv"),
    );
    let run = |out: &Path, exact: bool| {
        let mut argv = vec![
            "sunhours",
            block.to_str().unwrap(),
            "--lat",
            "52.01",
            "--lon",
            "4.36",
            "--date",
            "2026-06-21",
            "--sensors",
            sensors.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ];
        if exact {
            argv.push("--exact-time");
        }
        let o = shadow(&argv);
        assert!(o.status.success(), "{}", stderr(&o));
        std::fs::read_to_string(out).unwrap()
    };
    let v: Value = serde_json::from_str(&run(&json, true)).unwrap();
    let column = |text: &str| -> Vec<f64> {
        text.lines()
            .skip(1)
            .map(|l| l.rsplit(',').next().unwrap().parse().unwrap())
            .collect()
    };
    let (exact, sampled) = (column(&run(&csv, true)), column(&run(&sampled, false)));
    for (i, s) in v["sensors"].as_array().unwrap().iter().enumerate() {
        let on = s["days"][0]["sun"].as_array().unwrap();
        let mut total = 0.0;
        let mut last = 0.0;
        for pair in on {
            let (a, b) = (pair[0].as_f64().unwrap(), pair[1].as_f64().unwrap());
            assert!(last <= a && a < b && b <= 24.0, "{on:?}");
            (total, last) = (total + b - a, b);
        }
        assert!((s["sun_hours"].as_f64().unwrap() - total).abs() < 1e-12);
        assert!((exact[i] - total).abs() < 1e-9, "{exact:?}");
        // the refraction the model leaves out (about 10 minutes a day in
        // June at 52°) and the 10-minute steps' error at each shadow edge
        // (the library's tests hold the model to a minute's sampling)
        assert!(
            (exact[i] - sampled[i]).abs() < 0.5,
            "{exact:?} against {sampled:?}"
        );
    }
    // the one by the tower's north face loses the midday sun
    assert!(exact[1] < exact[2] - 2.0, "{exact:?}");
    let o = equator_cube_sunhours("2026-01-01", &["--exact-time", "-o", "x.csv"]);
    crate::assert_failed_with(&o, &["--sensors"]);
}

#[test]
fn sunhours_with_a_sun_disc_counts_the_penumbras_share() {
    let (point, disc) = (scratch("point_hours.csv"), scratch("disc_hours.csv"));
    let hours = |out: &Path, extra: &[&str]| -> Vec<Vec<String>> {
        let o = cube_sunhours(out, extra);
        assert!(o.status.success(), "{}", stderr(&o));
        let text = std::fs::read_to_string(out).unwrap();
        text.lines()
            .skip(1)
            .map(|l| l.split(',').map(String::from).collect())
            .collect()
    };
    let p = hours(&point, &["--no-extremes"]);
    for extra in [&["--sun-disc"][..], &["--sun-disc", "2"]] {
        let d = hours(&disc, extra);
        assert_eq!(d.len(), p.len());
        for (a, b) in p.iter().zip(&d) {
            // a lone cube casts nothing on itself: a disc changes no face
            let (x, y): (f64, f64) = (a[3].parse().unwrap(), b[3].parse().unwrap());
            assert!((x - y).abs() < 1e-9, "{a:?} {b:?}");
            assert_eq!((b[4].as_str(), b[5].as_str()), ("", ""), "no extremes");
        }
    }
    let o = cube_sunhours(&disc, &["--sun-disc", "--regions", "0"]);
    crate::assert_failed_with(&o, &["--sun-disc", "--regions"]);
}

#[test]
fn sunhours_regions_cut_to_a_garden_outline() {
    let block = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/city/block.city.json");
    let (garden, csv) = (scratch("garden.csv"), scratch("garden_cells.csv"));
    // a 6 m square in the yard's south-west corner, heights left out
    let corners = "x,y,z\n85002,446002,0\n85008,446002,0\n85008,446008,3\n85002,446008,0\n";
    std::fs::write(&garden, corners).unwrap();
    let argv = [
        "sunhours",
        block.to_str().unwrap(),
        "--lat",
        "52.01",
        "--lon",
        "4.36",
        "--date",
        "2026-03-21",
        "--step",
        "30",
        "--regions",
        "yard",
        "--outline",
        garden.to_str().unwrap(),
        "--bre209",
        "-o",
        csv.to_str().unwrap(),
    ];
    let o = shadow(&argv);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("BRE 209"), "{}", stdout(&o));
    let text = std::fs::read_to_string(&csv).unwrap();
    let area: f64 = text
        .lines()
        .skip(1)
        .map(|l| l.rsplit(',').next().unwrap().parse::<f64>().unwrap())
        .sum();
    assert!((area - 36.0).abs() < 1e-6, "{area}");
    // an outline without regions is refused
    let o = shadow(&[&argv[..10], &argv[12..]].concat());
    crate::assert_failed_with(&o, &["--outline", "--regions"]);
}

#[test]
fn a_face_that_touches_itself_is_tiled_not_fanned() {
    // two triangles meeting at (5, 1), one face whose loop passes there
    // twice: area 2 (a fan over the loop covered 4, lit 3 of it)
    let obj = scratch("pinched.obj");
    let text = "v 4 0 0\nv 6 0 0\nv 5 1 0\nv 6 2 0\nv 4 2 0\nf 1 2 3 4 5 3\n";
    std::fs::write(&obj, text).unwrap();
    let v = shadows_json(&obj, &["--sun", "0.3,-0.2,1"], "pinched.json");
    assert_eq!(v["summary"]["area"], 2.0);
    assert_eq!(v["summary"]["lit_area"][0], 2.0);
}
