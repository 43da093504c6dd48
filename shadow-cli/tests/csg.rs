//! `csg`: every result is read back from the file it was written to and
//! checked to be closed and consistently oriented, with the volume it must
//! have.

use std::path::{Path, PathBuf};
use std::process::Output;

use bsp_core::check_closed_manifold;
use glam::DVec3;
use shadow_scene::Mesh;

use crate::{assert_failed_with, scratch, shadow, stderr, stdout};

/// The axis-aligned cube `[lo, lo + size]³` as OBJ quads, counter-clockwise
/// seen from outside; faces on lines 9 to 14.
fn cube_obj(lo: [f64; 3], size: f64) -> String {
    let mut s = String::new();
    for i in 0..8 {
        let bit = |b: usize| if i >> b & 1 == 1 { size } else { 0.0 };
        // vertex order: 1 (0,0,0) 2 (1,0,0) 3 (1,1,0) 4 (0,1,0), then z = 1
        let (x, y) = [(0.0, 0.0), (size, 0.0), (size, size), (0.0, size)][i % 4];
        s += &format!("v {} {} {}\n", lo[0] + x, lo[1] + y, lo[2] + bit(2));
    }
    s + "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n"
}

fn write(name: &str, text: &str) -> PathBuf {
    let p = scratch(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../data/meshes")
        .join(name)
}

/// Runs `shadow csg op a b -o out extra...`.
fn csg(op: &str, a: &Path, b: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "csg",
        op,
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend(extra);
    shadow(&args)
}

/// Reads `path` back, checks that it is a closed, consistently oriented
/// triangle mesh, and returns it.
fn closed_result(path: &Path) -> Mesh {
    let m = shadow_scene::load(path).unwrap();
    assert!(m.faces.iter().all(|f| f.vertices.len() == 3));
    check_closed_manifold(m.faces.iter().map(|f| f.vertices.as_slice()))
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    m
}

fn assert_ok(o: &Output) {
    assert!(o.status.success(), "stderr: {}", stderr(o));
}

/// The value after `key` on the `--stats` line starting with it.
fn stat<'a>(out: &'a str, key: &str) -> &'a str {
    out.lines()
        .find_map(|l| l.strip_prefix(key))
        .unwrap_or_else(|| panic!("no `{key}` in {out}"))
        .trim()
}

#[test]
fn two_cubes_all_operations_exact_volume() {
    let a = write("cube_a.obj", &cube_obj([0.0; 3], 4.0));
    let b = write("cube_b.obj", &cube_obj([2.0; 3], 4.0));
    for (op, vol, a, b) in [
        ("union", 120.0, &a, &b),
        ("intersection", 8.0, &a, &b),
        ("difference", 56.0, &a, &b),
        ("difference", 56.0, &b, &a),
    ] {
        let out = scratch(&format!("cubes_{op}.obj"));
        let o = csg(op, a, b, &out, &[]);
        assert_ok(&o);
        assert!(
            stdout(&o).starts_with(&format!("wrote {}: {op} of ", out.display())),
            "{}",
            stdout(&o)
        );
        assert_eq!(stderr(&o), "", "no warnings for clean input");
        let m = closed_result(&out);
        assert_eq!(m.signed_volume(), vol, "{op}");
        assert_eq!(m.groups, vec!["default", op]);
        // every output vertex is a cube corner or a crossing of cube
        // planes: integers here
        assert!(m.positions.iter().all(|p| *p == p.round()));
    }
}

#[test]
fn stats_report_counts_volume_and_phases() {
    let a = write("stats_a.obj", &cube_obj([0.0; 3], 4.0));
    let b = write("stats_b.obj", &cube_obj([2.0; 3], 4.0));
    let out = scratch("stats_union.obj");
    let o = csg("union", &a, &b, &out, &["--stats"]);
    assert_ok(&o);
    let s = stdout(&o);
    assert!(stat(&s, "input A:").contains("12 triangles (6 faces), 6 polygons"));
    assert_eq!(
        stat(&s, "volume:"),
        "120 (exact, rounded once); 120 (f64 sum)"
    );
    // one cell holds both cubes' faces: three faces of each are cut by
    // the other surface
    assert_eq!(
        stat(&s, "octree:"),
        "1 cells, 1 with both surfaces (0 where they are one, 0 with shared planes merged whole, \
         0 where they do not meet: 0 with every face apart from the other surface, 0 labelled \
         from the cells around); 6 faces cut into 12 pieces"
    );
    let m = closed_result(&out);
    assert_eq!(
        stat(&s, "output:"),
        format!(
            "{} triangles, {} vertices",
            m.faces.len(),
            m.positions.len()
        )
    );
    for phase in [
        "load",
        "validate",
        "snap/import",
        "boolean",
        "boundary+mesh",
        "write",
        "total",
    ] {
        let ms: f64 = stat(&s, &format!("  {phase} ")).parse().unwrap();
        assert!(ms >= 0.0, "{phase}");
    }
}

/// A result that STL's f32 cannot hold (every triangle collapses) is an
/// error and no file, not an empty file and "the union is empty"; so is
/// an operand smaller than a step of the grid the operands share.
#[test]
fn what_the_formats_or_the_grid_cannot_hold_is_an_error() {
    let a = write("tiny_a.obj", &cube_obj([1e6; 3], 0.01));
    let b = write("tiny_b.obj", &cube_obj([1e6 + 0.005; 3], 0.01));
    let out = scratch("tiny_union.stl");
    std::fs::remove_file(&out).ok();
    let o = csg("union", &a, &b, &out, &[]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(
        e.contains("rounding to f32 collapses every triangle"),
        "{e}"
    );
    assert!(!out.exists());
    // as OBJ the same union is written
    let obj = scratch("tiny_union.obj");
    assert_ok(&csg("union", &a, &b, &obj, &[]));
    assert!(closed_result(&obj).faces.len() >= 12);
    // a unit cube beside one 10^15 away
    let far = write("far_cube.obj", &cube_obj([1e15; 3], 1.0));
    let near = write("near_cube.obj", &cube_obj([0.0; 3], 1.0));
    let o = csg("union", &near, &far, &scratch("far_union.obj"), &[]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("all 6 faces have no area on the grid"),
        "{}",
        stderr(&o)
    );
    // 10^8 away, the grid's step is 2: the cubes come out coarsened, and
    // the command warns (it said nothing of a volume of 16 for 2)
    let far8 = write("far8_cube.obj", &cube_obj([1e8, 0.0, 0.0], 1.0));
    let o = csg("union", &near, &far8, &scratch("far8_union.obj"), &[]);
    assert_ok(&o);
    let e = stderr(&o);
    assert!(
        e.contains("near_cube.obj spans 0.500 steps of the grid"),
        "{e}"
    );
    // operands of like size and place: no such warning
    let near2 = write("near2_cube.obj", &cube_obj([0.5; 3], 1.0));
    let o = csg("union", &near, &near2, &scratch("near2_union.obj"), &[]);
    assert!(!stderr(&o).contains("steps of the grid"), "{}", stderr(&o));
}

#[test]
fn stl_in_and_out_round_trip() {
    let cube = |lo, size| shadow_scene::parse_obj(&cube_obj(lo, size), "cube.obj").unwrap();
    let a = scratch("cube_a.stl");
    let b = scratch("cube_b.stl");
    shadow_scene::save(&a, &cube([0.0; 3], 4.0)).unwrap();
    shadow_scene::save(&b, &cube([2.0; 3], 4.0)).unwrap();
    let out = scratch("cubes_union.stl");
    assert_ok(&csg("union", &a, &b, &out, &[]));
    let m = closed_result(&out);
    assert_eq!(m.signed_volume(), 120.0);
    let bytes = std::fs::metadata(&out).unwrap().len();
    assert_eq!(bytes, 84 + 50 * m.faces.len() as u64, "binary STL");
    // STL output back in as an operand, with an OBJ, to OBJ
    let c = write("cube_c.obj", &cube_obj([3.0, 3.0, -1.0], 2.0));
    let out2 = scratch("stl_minus_obj.obj");
    assert_ok(&csg("difference", &out, &c, &out2, &[]));
    // the part of [3,5]x[3,5]x[-1,1] inside the union is [3,4]^2 x [0,1]
    assert_eq!(closed_result(&out2).signed_volume(), 120.0 - 1.0);
}

#[test]
fn sphere_minus_translated_copy() {
    let sphere_path = data("pyvista_sphere.obj");
    let sphere = shadow_scene::load(&sphere_path).unwrap();
    let mut moved = sphere.clone();
    for p in &mut moved.positions {
        *p += DVec3::new(37.5, 21.25, 10.0);
    }
    let moved_path = scratch("sphere_moved.obj");
    shadow_scene::save(&moved_path, &moved).unwrap();
    let volume = |op: &str| {
        let out = scratch(&format!("sphere_{op}.obj"));
        let o = csg(op, &sphere_path, &moved_path, &out, &["--stats"]);
        assert_ok(&o);
        let m = closed_result(&out);
        let v = m.signed_volume();
        // the exact volume printed by --stats agrees with the file's
        let exact: f64 = stat(&stdout(&o), "volume:")
            .split(' ')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        assert!((exact - v).abs() <= 1e-9 * v, "{op}: {exact} vs {v}");
        v
    };
    let (diff, inter, union) = (
        volume("difference"),
        volume("intersection"),
        volume("union"),
    );
    let whole = sphere.signed_volume();
    assert!(diff > 0.1 * whole && inter > 0.1 * whole, "they overlap");
    assert!((diff + inter - whole).abs() <= 1e-9 * whole);
    assert!((union - (2.0 * whole - inter)).abs() <= 1e-9 * whole);
}

#[test]
fn eight_union_box() {
    let eight = data("cgal_eight.obj");
    // a bar through one of the eight's holes and out of its side, with
    // coordinates on every grid (so that its volume is exact)
    let bar = cube_obj([0.0; 3], 1.0)
        .lines()
        .map(|l| match l.strip_prefix("v ") {
            Some(v) => {
                let c: Vec<f64> = v.split(' ').map(|x| x.parse().unwrap()).collect();
                let (x, y, z) = (c[0] * 0.5, c[1] * 0.125 - 0.0625, c[2] * 0.625 - 0.3125);
                format!("v {x} {y} {z}\n")
            }
            None => format!("{l}\n"),
        })
        .collect::<String>();
    let bar_path = write("bar.obj", &bar);
    let bar_volume = 0.5 * 0.125 * 0.625;
    let volume = |op: &str, b: &Path| {
        let out = scratch(&format!("eight_{op}.obj"));
        assert_ok(&csg(op, &eight, b, &out, &[]));
        closed_result(&out).signed_volume()
    };
    let union = volume("union", &bar_path);
    let inter = volume("intersection", &bar_path);
    let diff = volume("difference", &bar_path);
    assert!(inter > 0.0 && inter < bar_volume);
    assert!((union - (diff + bar_volume)).abs() <= 1e-12 * union);
    // A ∪ A is A as snapped to the grid: the two parts add up to it
    let snapped = volume("union", &eight);
    assert!((diff + inter - snapped).abs() <= 1e-12 * snapped);
    // and snapping moves the volume very little
    let whole = shadow_scene::load(&eight).unwrap().signed_volume();
    assert!((snapped - whole).abs() <= 1e-6 * whole);
}

#[test]
fn open_mesh_names_edge_face_and_line() {
    let open = write(
        "open.obj",
        &cube_obj([0.0; 3], 1.0).replace("f 5 6 7 8\n", ""),
    );
    let b = write("open_b.obj", &cube_obj([0.5; 3], 1.0));
    let out = scratch("open_out.obj");
    let o = csg("union", &open, &b, &out, &[]);
    assert_failed_with(
        &o,
        &[&format!(
            "error: {}:10: edge 6-5 of face 1 is a boundary edge (the mesh is not closed)\n",
            open.display()
        )],
    );
    assert!(!stderr(&o).contains("--weld"), "the file is welded");
    assert!(!out.exists());
    // as the second operand too
    let o = csg("union", &b, &open, &out, &[]);
    assert_failed_with(&o, &["open.obj:10: edge 6-5 of face 1"]);
}

#[test]
fn misoriented_face_names_both_faces_and_lines() {
    let flipped = write(
        "flipped.obj",
        &cube_obj([0.0; 3], 1.0).replace("f 2 3 7 6", "f 6 7 3 2"),
    );
    let b = write("flipped_b.obj", &cube_obj([0.5; 3], 1.0));
    let o = csg("difference", &b, &flipped, &scratch("flipped_out.obj"), &[]);
    assert_failed_with(
        &o,
        &[&format!(
            "{}:12: face 3 uses edge 6->7 in the same direction as face 1 (line 10) \
             (the faces are not consistently oriented)",
            flipped.display()
        )],
    );
}

#[test]
fn unwelded_input_needs_weld() {
    // every face with its own copies of its corners (as many exporters do)
    let cube = shadow_scene::parse_obj(&cube_obj([0.0; 3], 4.0), "c.obj").unwrap();
    let (mut verts, mut faces) = (String::new(), String::new());
    for f in &cube.faces {
        let base = verts.lines().count() + 1;
        for v in &f.vertices {
            let p = cube.positions[*v as usize];
            verts += &format!("v {} {} {}\n", p.x, p.y, p.z);
        }
        faces += &format!("f {} {} {} {}\n", base, base + 1, base + 2, base + 3);
    }
    let soup = write("soup.obj", &(verts + &faces));
    let b = write("soup_b.obj", &cube_obj([2.0; 3], 4.0));
    let out = scratch("soup_union.obj");
    let o = csg("union", &soup, &b, &out, &[]);
    assert_failed_with(
        &o,
        &[
            &format!(
                "{}:25: edge 1-2 of face 0 is a boundary edge",
                soup.display()
            ),
            "; if the file repeats vertices per face, try --weld",
        ],
    );
    assert!(!out.exists());
    let o = csg("union", &soup, &b, &out, &["--weld"]);
    assert_ok(&o);
    assert_eq!(closed_result(&out).signed_volume(), 120.0);
}

#[test]
fn inward_facing_input_is_refused() {
    let mut text = cube_obj([0.0; 3], 1.0);
    for (l, r) in [
        ("f 1 4 3 2", "f 2 3 4 1"),
        ("f 5 6 7 8", "f 8 7 6 5"),
        ("f 1 2 6 5", "f 5 6 2 1"),
        ("f 2 3 7 6", "f 6 7 3 2"),
        ("f 3 4 8 7", "f 7 8 4 3"),
        ("f 4 1 5 8", "f 8 5 1 4"),
    ] {
        text = text.replace(l, r);
    }
    let inv = write("inside_out.obj", &text);
    let b = write("inside_out_b.obj", &cube_obj([0.5; 3], 1.0));
    let o = csg("union", &b, &inv, &scratch("inside_out_result.obj"), &[]);
    assert_failed_with(
        &o,
        &["inside_out.obj: the faces are oriented inward", "reverse"],
    );
}

#[test]
fn argument_and_file_errors() {
    let a = write("args_a.obj", &cube_obj([0.0; 3], 1.0));
    let out = scratch("args_out.obj");
    let o = csg("xor", &a, &a, &out, &[]);
    assert_failed_with(
        &o,
        &["invalid value 'xor'", "union", "intersection", "difference"],
    );
    let missing = scratch("no_such_mesh.obj");
    let o = csg("union", &a, &missing, &out, &[]);
    assert_failed_with(&o, &["no_such_mesh.obj"]);
    let o = csg("union", &a, &a, &scratch("result.ply"), &[]);
    assert_failed_with(&o, &["result.ply", "unknown mesh format"]);
    let o = csg(
        "union",
        &a,
        &a,
        &scratch("no_such_dir").join("out.obj"),
        &[],
    );
    assert_failed_with(&o, &["out.obj"]);
    let o = shadow(&["csg", "union"]);
    assert_failed_with(&o, &["required", "<MESH>"]);
    let one = scratch("one.obj");
    let o = shadow(&[
        "csg",
        "difference",
        a.to_str().unwrap(),
        "-o",
        one.to_str().unwrap(),
    ]);
    assert_failed_with(&o, &["the difference of one mesh: give two or more"]);
    assert!(!one.exists());
    assert!(!out.exists());
}

#[test]
fn disjoint_intersection_is_empty_but_written() {
    let a = write("apart_a.obj", &cube_obj([0.0; 3], 1.0));
    let b = write("apart_b.obj", &cube_obj([5.0; 3], 1.0));
    let out = scratch("apart.obj");
    let o = csg("intersection", &a, &b, &out, &[]);
    assert_ok(&o);
    assert!(stderr(&o).contains("the intersection is empty"));
    assert!(closed_result(&out).faces.is_empty());
    let o = csg("union", &a, &b, &out, &[]);
    assert_ok(&o);
    assert_eq!(closed_result(&out).signed_volume(), 2.0);
}

#[test]
fn dropped_faces_are_reported() {
    // a unit cube whose top edge 5-6 carries an extra vertex 9, and a
    // closing sliver face 5 9 6 without area
    let text = cube_obj([0.0; 3], 1.0)
        .replace("f 1 4 3 2\n", "v 0.5 0 1\nf 1 4 3 2\n")
        .replace("f 1 2 6 5\n", "f 1 2 6 9 5\n")
        + "f 5 9 6\n";
    let sliver = write("sliver.obj", &text);
    let b = write("sliver_b.obj", &cube_obj([0.5; 3], 1.0));
    let out = scratch("sliver_union.obj");
    let o = csg("union", &sliver, &b, &out, &["--stats"]);
    assert_ok(&o);
    let err = stderr(&o);
    assert!(
        err.contains("sliver.obj: 1 degenerate face(s) dropped: face 6 (line 16: zero area"),
        "{err}"
    );
    assert!(
        err.contains("the seams they leave have no area either"),
        "{err}"
    );
    assert!(stat(&stdout(&o), "input A:").ends_with("(0 faces triangulated, 1 dropped)"));
    assert_eq!(closed_result(&out).signed_volume(), 2.0 - 0.125);
    // --quiet: the same file, and nothing on stderr
    let quiet = scratch("sliver_union_quiet.obj");
    let o = csg("union", &sliver, &b, &quiet, &["-q"]);
    assert_ok(&o);
    assert_eq!(stderr(&o), "");
    assert_eq!(std::fs::read(&quiet).unwrap(), std::fs::read(&out).unwrap());
    let svg = quiet.with_extension("svg");
    for args in [
        vec!["stats", sliver.to_str().unwrap(), "-q"],
        vec![
            "view",
            sliver.to_str().unwrap(),
            "-q",
            "-o",
            svg.to_str().unwrap(),
        ],
    ] {
        let o = shadow(&args);
        assert_ok(&o);
        assert_eq!(stderr(&o), "", "{args:?}");
    }
}

#[test]
fn several_tools_in_turn() {
    // a 4-cube; unit cubes bite into two of its corners, a third one
    // overlaps the second by half, and a fourth lies apart
    let part = write("part.obj", &cube_obj([0.0; 3], 4.0));
    let t1 = write("tool1.obj", &cube_obj([-0.5; 3], 1.0));
    let t2 = write("tool2.obj", &cube_obj([3.5, 3.5, -0.5], 1.0));
    let t3 = write("tool3.obj", &cube_obj([3.0, 3.5, -0.5], 1.0));
    let t4 = write("tool4.obj", &cube_obj([9.0; 3], 1.0));
    let out = scratch("part_minus_tools.obj");
    let paths = [&part, &t1, &t2, &t3, &t4];
    let run = |op: &str, paths: &[&PathBuf], out: &Path| {
        let mut args = vec!["csg", op];
        args.extend(paths.iter().map(|p| p.to_str().unwrap()));
        args.extend(["-o", out.to_str().unwrap(), "--stats"]);
        let o = shadow(&args);
        assert_ok(&o);
        o
    };
    // each corner bite is 1/8; the third tool bites 1/4, half of it
    // already taken by the second
    let o = run("difference", &paths, &out);
    assert_eq!(
        closed_result(&out).signed_volume(),
        64.0 - 0.125 - 0.125 - 0.125
    );
    let s = stdout(&o);
    assert!(
        s.contains("difference of ") && s.contains(" and 4 more"),
        "{s}"
    );
    assert!(
        stat(&s, "input 5:").contains("12 triangles (6 faces)"),
        "{s}"
    );
    assert_eq!(stat(&s, "volume:").split(' ').next(), Some("63.625"));
    // the union of the tools; their intersection is the second and third's
    // overlap, and nothing once the part-free fourth joins
    let u = scratch("tools_union.obj");
    run("union", &[&t1, &t2, &t3, &t4], &u);
    assert_eq!(closed_result(&u).signed_volume(), 4.0 - 0.5);
    let i = scratch("tools_intersection.obj");
    run("intersection", &[&part, &t2, &t3], &i);
    assert_eq!(closed_result(&i).signed_volume(), 0.125);
    run("intersection", &[&part, &t2, &t3, &t4], &i);
    assert!(closed_result(&i).faces.is_empty());
}

#[test]
fn a_union_of_one_cleans_shells_that_overlap_or_nest() {
    // two overlapping cubes and a third inside the first, all outward, in
    // one file: the solid where the winding number is positive is the
    // union of the two overlapping ones (8 + 8 − 1)
    let shells = [([0.0; 3], 2.0), ([1.0; 3], 2.0), ([0.25; 3], 0.5)];
    let mut text = String::new();
    for (k, (lo, size)) in shells.iter().enumerate() {
        let cube = cube_obj(*lo, *size);
        for line in cube.lines() {
            match line.strip_prefix("f ") {
                Some(f) => {
                    let ids: Vec<String> = f
                        .split(' ')
                        .map(|i| (i.parse::<usize>().unwrap() + 8 * k).to_string())
                        .collect();
                    text += &format!("f {}\n", ids.join(" "));
                }
                None => text += &format!("{line}\n"),
            }
        }
    }
    let dirty = write("shells.obj", &text);
    let out = scratch("shells_clean.obj");
    let o = shadow(&[
        "csg",
        "union",
        dirty.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--stats",
    ]);
    assert_ok(&o);
    let s = stdout(&o);
    assert!(
        s.starts_with(&format!(
            "wrote {}: union of {} alone",
            out.display(),
            dirty.display()
        )),
        "{s}"
    );
    assert_eq!(stat(&s, "volume:").split(' ').next(), Some("15"));
    closed_result(&out);
    // as an operand of a Boolean: the same solid
    let far = write("far_cube.obj", &cube_obj([5.0; 3], 1.0));
    let o = csg(
        "union",
        &dirty,
        &far,
        &scratch("shells_far.obj"),
        &["--stats"],
    );
    assert_ok(&o);
    assert_eq!(stat(&stdout(&o), "volume:").split(' ').next(), Some("16"));
}

/// The second sphere's centre of [`spheres_obj`]'s overlapping pair.
const SECOND: DVec3 = DVec3::new(0.9, 0.2, 0.1);

/// Unit UV spheres of 12,100 triangles each around `centres`, in one OBJ
/// text.
fn spheres_obj(centres: &[DVec3]) -> String {
    let (nu, nv) = (110, 56);
    let mut s = String::new();
    let mut faces = Vec::new();
    for (k, c) in centres.iter().enumerate() {
        let first = 1 + k * (2 + (nv - 1) * nu);
        let ring = |i: usize, j: usize| first + 1 + (i - 1) * nu + j % nu;
        let top = first + 1 + (nv - 1) * nu;
        s += &format!("v {} {} {}\n", c.x, c.y, c.z - 1.0);
        for i in 1..nv {
            let th = std::f64::consts::PI * (i as f64 / nv as f64 - 0.5);
            for j in 0..nu {
                let ph = std::f64::consts::TAU * j as f64 / nu as f64;
                let p = *c + DVec3::new(th.cos() * ph.cos(), th.cos() * ph.sin(), th.sin());
                s += &format!("v {} {} {}\n", p.x, p.y, p.z);
            }
        }
        s += &format!("v {} {} {}\n", c.x, c.y, c.z + 1.0);
        for j in 0..nu {
            faces.push([first, ring(1, j + 1), ring(1, j)]);
            faces.push([top, ring(nv - 1, j), ring(nv - 1, j + 1)]);
            for i in 1..nv - 1 {
                faces.push([ring(i, j), ring(i, j + 1), ring(i + 1, j + 1)]);
                faces.push([ring(i, j), ring(i + 1, j + 1), ring(i + 1, j)]);
            }
        }
    }
    for f in faces {
        s += &format!("f {} {} {}\n", f[0], f[1], f[2]);
    }
    s
}

/// Two overlapping spheres in one file, more faces than one partition
/// of every face takes: resolved cell by cell, the union of one is the
/// union of the two spheres as two files, to the exact volume.
#[test]
fn two_large_crossing_shells_in_one_file_resolve_to_their_union() {
    let two = write("two_spheres.obj", &spheres_obj(&[DVec3::ZERO, SECOND]));
    let a = write("sphere_a.obj", &spheres_obj(&[DVec3::ZERO]));
    let b = write("sphere_b.obj", &spheres_obj(&[SECOND]));
    let out = scratch("two_spheres_u.obj");
    let o = shadow(&[
        "csg",
        "union",
        two.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--stats",
    ]);
    assert_ok(&o);
    closed_result(&out);
    let o2 = csg("union", &a, &b, &scratch("spheres_ab.obj"), &["--stats"]);
    assert_ok(&o2);
    let volume = |o: &Output| {
        stat(&stdout(o), "volume:")
            .split(' ')
            .next()
            .map(String::from)
    };
    assert_eq!(volume(&o), volume(&o2));
    assert!(volume(&o).is_some());
}

/// Two cubes touching along an edge, united and written as STL: read back
/// (STL is welded by position), four faces share that edge, two each
/// way. Such a closed cycle is no 2-manifold, yet a valid input again: it
/// is resolved to where its winding number is positive, the two cubes.
#[test]
fn solids_touching_along_an_edge_written_as_stl_are_inputs_again() {
    let a = write("edge_a.obj", &cube_obj([0.0; 3], 1.0));
    let b = write("edge_b.obj", &cube_obj([1.0, 1.0, 0.0], 1.0));
    let stl = scratch("edge_ab.stl");
    assert_ok(&csg("union", &a, &b, &stl, &[]));
    let back = scratch("edge_ab_back.obj");
    let o = shadow(&[
        "csg",
        "union",
        stl.to_str().unwrap(),
        "-o",
        back.to_str().unwrap(),
        "--stats",
    ]);
    assert_ok(&o);
    assert_eq!(stat(&stdout(&o), "volume:").split(' ').next(), Some("2"));
    // and united with itself
    let twice = scratch("edge_ab_twice.obj");
    let o = csg("union", &stl, &stl, &twice, &["--stats"]);
    assert_ok(&o);
    assert_eq!(stat(&stdout(&o), "volume:").split(' ').next(), Some("2"));
}
