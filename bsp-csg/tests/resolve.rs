//! Surfaces whose shells cross, overlap, nest or turn inside out,
//! resolved to the solid where their winding number is positive
//! (`Solid::resolved`), checked against exact winding numbers of the
//! surface as given; and such surfaces as operands of Booleans.

use bsp_core::{BoolOp, Polygon};
use bsp_csg::files::{FileBoolean, FileError, Operand, find_crossing};
use bsp_csg::{MeshBuf, MeshIn, Solid, mesh_sequence};

use crate::view;
use bsp_fixtures::{self as shapes, GridPoint, Loop, Rng};
use glam::DVec3;
use shadow_scene::MeshView;

fn polys(loops: &[Loop]) -> Vec<Polygon> {
    loops
        .iter()
        .map(|l| Polygon::from_grid_points(l, 0).unwrap())
        .collect()
}

/// `surface` resolved: a closed mesh whose winding number is 1 where the
/// surface's is positive and 0 elsewhere, at `samples` random grid points
/// of the surface's box and at `extra`.
fn check_resolved(surface: &[Loop], samples: usize, extra: &[GridPoint], rng: &mut Rng) -> Solid {
    let before = Solid::from_polygons(polys(surface));
    let after = Solid::from_polygons(polys(surface)).resolved().unwrap();
    after.to_watertight_mesh().unwrap();
    let (mut lo, mut hi) = ([i32::MAX; 3], [i32::MIN; 3]);
    for p in surface.iter().flatten() {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k] - 1);
            hi[k] = hi[k].max(p[k] + 1);
        }
    }
    let random = (0..samples)
        .map(|_| [0, 1, 2].map(|k| lo[k] + (rng.next_u64() % (hi[k] - lo[k] + 1) as u64) as i32));
    for q in random.chain(extra.iter().copied()) {
        let w = before.winding(q);
        assert_eq!(after.winding(q), i32::from(w > 0), "at {q:?} (winding {w})");
    }
    after
}

#[test]
fn folded_and_overlapping_spheres_resolve_to_their_positive_winding() {
    let mut rng = Rng(0x5e50);
    for case in 0..16 {
        let jitter = 1 + case % 4;
        let mut surface = shapes::jittered_uv_sphere(24, 7.0, jitter, &mut rng);
        if case % 2 == 1 {
            // a second sphere, apart, overlapping or inside
            let off = (rng.next_u64() % 20) as i32 - 4;
            let other = shapes::jittered_uv_sphere(16, 3.0, 1, &mut rng);
            surface.extend(
                other
                    .iter()
                    .map(|l| l.iter().map(|g| [g[0] + off, g[1], g[2]]).collect()),
            );
        }
        check_resolved(&surface, 3000, &[], &mut rng);
    }
}

#[test]
fn a_crossing_along_a_diagonal_resolves_to_the_outward_solid() {
    let mut rng = Rng(0xd1a6);
    for _ in 0..12 {
        let c = shapes::crossing_along_diagonal(&mut rng);
        let extra = [c.negative, c.positive];
        let after = check_resolved(&c.surface, 1000, &extra, &mut rng);
        assert_eq!(after.winding(c.negative), 0);
        assert_eq!(after.winding(c.positive), 1);
    }
}

/// The boxes `[lo, hi]` (each turned inward if its flag says so) as one
/// mesh.
fn boxes(list: &[([f64; 3], [f64; 3], bool)]) -> MeshBuf {
    let mut positions: Vec<DVec3> = Vec::new();
    let mut faces = Vec::new();
    for &(lo, hi, inward) in list {
        let first = positions.len();
        for mut face in shapes::cuboid(DVec3::from(lo), DVec3::from(hi)) {
            if inward {
                face.reverse();
            }
            // each box's corners once (boxes share none)
            let index = |p: DVec3, positions: &mut Vec<DVec3>| match positions[first..]
                .iter()
                .position(|&q| q == p)
            {
                Some(i) => (first + i) as u32,
                None => {
                    positions.push(p);
                    (positions.len() - 1) as u32
                }
            };
            faces.push(face.into_iter().map(|p| index(p, &mut positions)).collect());
        }
    }
    MeshBuf::new(positions, faces)
}

#[test]
fn shells_that_nest_or_overlap_in_one_operand_count_once() {
    let far = boxes(&[([10.0; 3], [11.0; 3], false)]);
    let cases = [
        // a box in a box, both outward: the inner one is inside already
        (
            boxes(&[([0.0; 3], [4.0; 3], false), ([1.0; 3], [2.0; 3], false)]),
            64.0,
        ),
        // two overlapping boxes: 8 + 8 − 1
        (
            boxes(&[([0.0; 3], [2.0; 3], false), ([1.0; 3], [3.0; 3], false)]),
            15.0,
        ),
        // a box with a cavity: 64 − 1 (a clean solid, unchanged)
        (
            boxes(&[([0.0; 3], [4.0; 3], false), ([1.0; 3], [2.0; 3], true)]),
            63.0,
        ),
        // an inward box alone outside another: nothing
        (
            boxes(&[([0.0; 3], [4.0; 3], false), ([5.0; 3], [6.0; 3], true)]),
            64.0,
        ),
    ];
    for (i, (mesh, volume)) in cases.iter().enumerate() {
        let alone = mesh_sequence(&view(mesh), &[]).unwrap();
        assert_eq!(alone.volume(), *volume, "case {i} alone");
        let with_far = mesh_sequence(&view(mesh), &[(BoolOp::Union, view(&far))]).unwrap();
        assert_eq!(with_far.volume(), volume + 1.0, "case {i} and a box apart");
        // the box apart first: the shells are the second operand
        let far_first = mesh_sequence(&view(&far), &[(BoolOp::Union, view(mesh))]).unwrap();
        assert_eq!(
            far_first.volume(),
            volume + 1.0,
            "case {i} after a box apart"
        );
        let cut = boxes(&[([-1.0; 3], [1.5, 5.0, 5.0], false)]);
        let kept = mesh_sequence(&view(mesh), &[(BoolOp::Intersection, view(&cut))]).unwrap();
        // x ≤ 1.5: 1.5 · 16; 1.5 · 4 + 0.5 · 4 − 0.5 · 1; 24 − 0.5
        let expected = [24.0, 7.5, 23.5, 24.0][i];
        assert_eq!(kept.volume(), expected, "case {i} cut");
    }
}

/// `positions` and `faces` as OBJ text.
fn obj_text(positions: &[DVec3], faces: &[Vec<u32>]) -> String {
    let mut s = String::new();
    for p in positions {
        s += &format!("v {} {} {}\n", p.x, p.y, p.z);
    }
    for f in faces {
        let ids: Vec<String> = f.iter().map(|i| (i + 1).to_string()).collect();
        s += &format!("f {}\n", ids.join(" "));
    }
    s
}

/// The bench's sphere pair of about `n` triangles each, as OBJ files read.
fn sphere_pair_read(n: usize) -> [Operand; 2] {
    let (a, b, faces) = shapes::sphere_pair(n);
    let read = |p: &[DVec3], name: &str| {
        Operand::new(
            name,
            shadow_scene::parse_obj(&obj_text(p, &faces), name).unwrap(),
        )
    };
    [read(&a, "a.obj"), read(&b, "b.obj")]
}

/// `out` written as OBJ (`f64`) or STL (`f32`), read back and united
/// with itself: the volume moves at most by the surface's area times the
/// farthest a vertex moves, half a step of the new grid along each axis
/// plus the rounding to `f32` for STL.
fn round_trip(out: &FileBoolean, stl: bool) {
    let mut bytes = Vec::new();
    let rounded = out.rounded(stl);
    if let Some(r) = &rounded {
        assert!(r.closed, "{}: {} collapsed", out.group, r.collapsed);
    }
    match (&rounded, stl) {
        (Some(r), true) => shadow_scene::write_stl(&r.mesh, &mut bytes).unwrap(),
        (Some(r), false) => shadow_scene::write_obj(&r.mesh, &mut bytes).unwrap(),
        (None, true) => shadow_scene::write_stl(&out.mesh(), &mut bytes).unwrap(),
        (None, false) => shadow_scene::write_obj(&out.mesh(), &mut bytes).unwrap(),
    }
    let mesh = match stl {
        true => shadow_scene::parse_stl(&bytes, "r.stl").unwrap(),
        false => shadow_scene::parse_obj(std::str::from_utf8(&bytes).unwrap(), "r.obj").unwrap(),
    };
    // as read back: no face without area
    assert_eq!(
        mesh.flat_triangles(|p| p),
        0,
        "{}: flat triangles",
        out.group
    );
    let mut twice = [
        Operand::welded("r", mesh.clone()),
        Operand::welded("r", mesh),
    ];
    let checked = Operand::check_all(&mut twice).unwrap();
    let again = FileBoolean::apply(checked, BoolOp::Union, |_, _| {}).unwrap();
    let area: f64 = out
        .exact
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| out.positions[i as usize]);
            (b - a).cross(c - a).length() / 2.0
        })
        .sum();
    let reach = out
        .positions
        .iter()
        .map(|p| p.abs().max_element())
        .fold(0.0, f64::max);
    // rounding to f32 moves a coordinate by half a step, at most
    // reach·2^-24; one kept apart, by one and a half steps
    let apart = rounded.as_ref().is_some_and(|r| r.moved > 0);
    let f32_move = match (stl, apart) {
        (false, _) => 0.0,
        (true, false) => reach * 2f64.powi(-24),
        (true, true) => 3.0 * reach * 2f64.powi(-24),
    };
    let moved = 3f64.sqrt() * (again.grid.step() / 2.0 + f32_move);
    let (v0, v1) = (out.volume(), again.volume());
    assert!(
        (v1 - v0).abs() <= area * moved,
        "{} {}: {v0} then {v1}, more than {area} · {moved}",
        out.group,
        if stl { "STL" } else { "OBJ" }
    );
}

#[test]
fn results_written_and_read_back_are_inputs_again() {
    for op in [BoolOp::Union, BoolOp::Intersection, BoolOp::Difference] {
        let mut pair = sphere_pair_read(800);
        let checked = Operand::check_all(&mut pair).unwrap();
        let out = FileBoolean::apply(checked, op, |_, _| {}).unwrap();
        round_trip(&out, false);
        round_trip(&out, true);
    }
}

/// A sphere less a box over `x > 0.1`, written as OBJ and read back,
/// united with the sphere: on the new run's grid (finer: the box is gone)
/// some of the part's sliver triangles at the cut turn over, folding its
/// surface where it nearly coincides with the sphere's. Such an operand is
/// resolved (before, the union stopped with an internal error while it
/// was meshed); the volumes then add up: the union is the sphere and the
/// part less the sphere, exactly.
#[test]
fn a_part_read_back_with_turned_slivers_unites_with_its_whole() {
    let (positions, faces) = shapes::uv_sphere(1500);
    let read = |text: String, name: &str| {
        Operand::new(name, shadow_scene::parse_obj(&text, name).unwrap())
    };
    let cube = |lo: [f64; 3], hi: [f64; 3]| {
        let (v, f) = shapes::indexed_box(DVec3::from(lo), DVec3::from(hi));
        obj_text(&v, &f)
    };
    let sphere = obj_text(&positions, &faces);
    let run = |a: Operand, b: Operand, op| {
        let mut pair = [a, b];
        let checked = Operand::check_all(&mut pair).unwrap();
        FileBoolean::apply(checked, op, |_, _| {}).unwrap()
    };
    let part = run(
        read(sphere.clone(), "sphere.obj"),
        read(cube([0.1, -2.0, -2.0], [2.0, 2.0, 2.0]), "box.obj"),
        BoolOp::Difference,
    );
    let mut bytes = Vec::new();
    match part.rounded(false) {
        Some(r) => shadow_scene::write_obj(&r.mesh, &mut bytes),
        None => shadow_scene::write_obj(&part.mesh(), &mut bytes),
    }
    .unwrap();
    let part = String::from_utf8(bytes).unwrap();
    let with = |op| {
        run(
            read(sphere.clone(), "sphere.obj"),
            read(part.clone(), "part.obj"),
            op,
        )
    };
    let union = with(BoolOp::Union);
    let whole = run(
        read(sphere.clone(), "sphere.obj"),
        read(sphere.clone(), "sphere.obj"),
        BoolOp::Intersection,
    );
    let beyond = run(
        read(part.clone(), "part.obj"),
        read(sphere.clone(), "sphere.obj"),
        BoolOp::Difference,
    );
    // (each volume exact, rounded once: their sum within an ulp or two)
    let (u, sum) = (union.volume(), whole.volume() + beyond.volume());
    assert!(
        (u - sum).abs() <= 4.0 * f64::EPSILON * u,
        "{u} against {sum}"
    );
    assert!(
        beyond.volume() < 1e-6 * whole.volume(),
        "{}",
        beyond.volume()
    );
}

/// The nut and a copy moved by a skew fraction of its size: their
/// results rounded to `f32` put the three corners of some triangles on
/// one line (and make some vertices equal); as written they have no flat
/// face and are closed, and they are inputs again.
#[test]
fn results_that_round_flat_are_split_and_closed() {
    let nut = crate::repo_mesh("pyvista_nut.obj");
    let (lo, hi) = nut.bounds().unwrap();
    let moved = {
        let mut m = nut.clone();
        let by = (hi - lo) * DVec3::new(0.31, 0.17, 0.23);
        m.positions.iter_mut().for_each(|p| *p += by);
        m
    };
    let mut flattened = 0;
    for op in [BoolOp::Union, BoolOp::Intersection, BoolOp::Difference] {
        let mut pair = [
            Operand::new("nut", nut.clone()),
            Operand::new("moved", moved.clone()),
        ];
        let checked = Operand::check_all(&mut pair).unwrap();
        let out = FileBoolean::apply(checked, op, |_, _| {}).unwrap();
        // (`None`: rounding to f32 leaves every vertex apart and no
        // triangle flat, so the result is written as it is)
        if let Some(r) = out.rounded(true) {
            assert!(r.closed, "{op:?}");
            assert_eq!(r.mesh.flat_triangles(|p| p), 0, "{op:?}");
            flattened += r.flattened;
        }
        round_trip(&out, true);
        round_trip(&out, false);
    }
    // (the case this test is for happens: 1 and 8 triangles)
    assert!(flattened > 0);
}

/// An 8,000-triangle sphere minus itself moved by 10⁻⁷: rounded to
/// `f32`, the difference has vertices of two sheets closer than `f32`
/// resolves, which welding would make one (an edge used four times). They
/// are kept apart one step instead, and the file is closed as read back,
/// and an input again.
#[test]
fn results_that_would_pinch_in_f32_keep_their_vertices_apart() {
    let (a, _, faces) = shapes::sphere_pair(8_000);
    let b: Vec<DVec3> = (a.iter())
        .map(|p| *p + DVec3::new(1e-7, 0.5e-7, 0.0))
        .collect();
    let read = |p: &[DVec3], name: &str| {
        Operand::new(
            name,
            shadow_scene::parse_obj(&obj_text(p, &faces), name).unwrap(),
        )
    };
    let mut pair = [read(&a, "a.obj"), read(&b, "b.obj")];
    let checked = Operand::check_all(&mut pair).unwrap();
    let out = FileBoolean::apply(checked, BoolOp::Difference, |_, _| {}).unwrap();
    let mut welded = out.mesh().to_mesh();
    welded.round_positions(shadow_scene::to_f32);
    assert!(!welded.is_closed_oriented(), "the case this test is for");
    let r = out
        .rounded(true)
        .expect("f32 rounding makes vertices equal");
    assert!(r.closed && r.moved > 0 && r.collapsed == 0, "{r:?}");
    assert_eq!(r.mesh.flat_triangles(|p| p), 0);
    round_trip(&out, true);
}

/// A union of one large surface: a clean one is kept face for face; one
/// sphere inside another, both outward, is the outer sphere alone.
/// Resolved cell by cell (more than the 20,000 faces one partition of
/// every face takes).
#[test]
fn a_large_surface_alone_is_kept_or_resolved_cell_by_cell() {
    let (a, _, faces) = shapes::sphere_pair(2 * bsp_csg::RESOLVE_LIMIT);
    assert!(faces.len() > bsp_csg::RESOLVE_LIMIT);
    let alone = mesh_sequence(&MeshIn::new(&a, &faces), &[]).unwrap();
    assert_eq!(alone.mesh.triangles.len(), faces.len());
    let inner: Vec<DVec3> = a.iter().map(|&p| p * 0.5).collect();
    let (both, two) = shapes::joined(&[(&a, &faces), (&inner, &faces)]);
    let nested = mesh_sequence(&MeshIn::new(&both, &two), &[]).unwrap();
    nested.mesh.check_watertight().unwrap();
    assert_eq!(nested.mesh.triangles.len(), faces.len());
    // the same grid (the outer sphere holds every position), the same solid
    assert_eq!(nested.grid, alone.grid);
    let ((n1, d1), (n2, d2)) = (nested.mesh.six_volume(), alone.mesh.six_volume());
    assert_eq!(n1 * d2, n2 * d1);
}

/// One file holding two overlapping spheres of 12,000 triangles each,
/// more than one partition of every face takes: its union of one is the
/// union of the two spheres as two operands, to the exact volume; and
/// `find_crossing` names one face of each sphere and a point on both.
#[test]
fn two_large_crossing_shells_resolve_to_their_union() {
    let (a, b, faces) = shapes::sphere_pair(12_000);
    let (positions, both) = shapes::joined(&[(&a, &faces), (&b, &faces)]);
    assert!(both.len() > bsp_csg::RESOLVE_LIMIT);
    let one = mesh_sequence(&MeshIn::new(&positions, &both), &[]).unwrap();
    one.mesh.check_watertight().unwrap();
    let two = mesh_sequence(
        &MeshIn::new(&a, &faces),
        &[(BoolOp::Union, MeshIn::new(&b, &faces))],
    )
    .unwrap();
    assert_eq!(one.grid, two.grid);
    let ((n1, d1), (n2, d2)) = (one.mesh.six_volume(), two.mesh.six_volume());
    assert_eq!(n1 * d2, n2 * d1, "the resolved volume is the union's");
    // where the file crosses itself
    let mesh = shadow_scene::parse_obj(&obj_text(&positions, &both), "two.obj").unwrap();
    let grid = one.grid;
    let c = find_crossing(&mesh, &grid).expect("the certificate finds the pair");
    let half = faces.len();
    assert!((c.faces[0] < half) != (c.faces[1] < half), "{c}");
    assert_eq!(c.lines, c.faces.map(|f| mesh.faces[f].line));
    // on both unit spheres, to the faces' flatness
    let centre = |p: &[DVec3]| p.iter().sum::<DVec3>() / p.len() as f64;
    for sphere in [&a, &b] {
        let r = (c.point - centre(sphere)).length();
        assert!((r - 1.0).abs() < 0.01, "{c}: {r} from a centre");
    }
    // the same, read again from the file an operand came from
    let path = std::env::temp_dir().join(format!("two-{}.obj", std::process::id()));
    std::fs::write(&path, obj_text(&positions, &both)).unwrap();
    let e = FileError {
        message: String::new(),
        weld_may_help: false,
        crossing: Some((vec![0], grid)),
    };
    let at = e.locate_crossing(&[path.display().to_string()]);
    std::fs::remove_file(&path).unwrap();
    assert_eq!(at, Some(format!("{}: {c}", path.display())));
    // a clean surface has none
    let single = shadow_scene::parse_obj(&obj_text(&a, &faces), "a.obj").unwrap();
    assert_eq!(find_crossing(&single, &grid), None);
}

/// A surface of two overlapping shells in one mesh, resolved cell by
/// cell, is the union of the two as two operands, to the exact volume:
/// coarse faces that cross the other shell have pieces outside the cells
/// where it crosses on both of its sides (inside and outside the other
/// shell), which must be kept or dropped each on its own.
#[test]
fn coarse_faces_crossing_a_fine_shell_resolve_piece_by_piece() {
    let (fine, fine_faces) = shapes::uv_sphere(8_000);
    let (coarse, coarse_faces) = shapes::uv_sphere(60);
    let (cube_points, cube_faces) =
        shapes::indexed_box(DVec3::new(-0.3, -0.2, -0.25), DVec3::new(1.4, 0.5, 0.6));
    let moved: Vec<DVec3> = coarse
        .iter()
        .map(|&p| 0.9 * p + DVec3::new(0.7, 0.3, -0.2))
        .collect();
    for (other, other_faces) in [(&moved, &coarse_faces), (&cube_points, &cube_faces)] {
        let (positions, faces) = shapes::joined(&[
            (&fine, &fine_faces),
            (other.as_slice(), other_faces.as_slice()),
        ]);
        let one = mesh_sequence(&MeshIn::new(&positions, &faces), &[]).unwrap();
        one.mesh.check_watertight().unwrap();
        let two = mesh_sequence(
            &MeshIn::new(&fine, &fine_faces),
            &[(BoolOp::Union, MeshIn::new(other, other_faces))],
        )
        .unwrap();
        assert_eq!(one.grid, two.grid);
        let ((n1, d1), (n2, d2)) = (one.mesh.six_volume(), two.mesh.six_volume());
        assert_eq!(n1 * d2, n2 * d1, "the resolved volume is the union's");
    }
}

/// A single closed 2-manifold shell that crosses itself: a unit cube
/// (scaled by 4) whose corner (4, 4, 4) is pulled through the bottom to
/// (3, 3, −4). By index it is a clean solid, so only the certificate of
/// its snapped faces (`certify_grid_polygons` at import) finds the
/// crossing. As one of two operands it must count as the solid where its
/// winding number is positive, as it does alone (checked here against
/// exact winding numbers): before, `A ∪ A` and `A ∪ (a box apart)` kept
/// its faces as they were, with the signed volume.
#[test]
fn a_single_shell_crossing_itself_is_resolved_as_any_operand() {
    let corners: [[i32; 3]; 8] = [
        [0, 0, 0],
        [4, 0, 0],
        [0, 4, 0],
        [4, 4, 0],
        [0, 0, 4],
        [4, 0, 4],
        [0, 4, 4],
        [3, 3, -4],
    ];
    let tris: [[u32; 3]; 12] = [
        [0, 2, 3],
        [0, 3, 1],
        [4, 5, 7],
        [4, 7, 6],
        [0, 1, 5],
        [0, 5, 4],
        [2, 6, 7],
        [2, 7, 3],
        [0, 4, 6],
        [0, 6, 2],
        [1, 3, 7],
        [1, 7, 5],
    ];
    let loops: Vec<Loop> = tris
        .iter()
        .map(|t| t.iter().map(|&i| corners[i as usize]).collect())
        .collect();
    check_resolved(&loops, 4000, &[], &mut Rng::new(7));
    let positions: Vec<DVec3> = corners
        .iter()
        .map(|c| DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64))
        .collect();
    let faces: Vec<Vec<u32>> = tris.iter().map(|t| t.to_vec()).collect();
    let a = MeshBuf::new(positions, faces);
    bsp_core::check_closed_manifold(a.faces.iter().map(Vec::as_slice)).unwrap();
    let alone = mesh_sequence(&view(&a), &[]).unwrap().volume();
    // the signed volume is less: part of the inside is turned out
    let signed = six_volume(&a, &a.faces) / 6.0;
    assert!(signed < alone - 1.0, "signed {signed}, resolved {alone}");
    let far = boxes(&[([10.0; 3], [11.0; 3], false)]);
    let around = boxes(&[([-10.0; 3], [10.0; 3], false)]);
    let cases = [
        (view(&a), BoolOp::Union, view(&a), alone),
        (view(&a), BoolOp::Intersection, view(&a), alone),
        (view(&a), BoolOp::Union, view(&far), alone + 1.0),
        (view(&far), BoolOp::Union, view(&a), alone + 1.0),
        (view(&a), BoolOp::Difference, view(&far), alone),
        (view(&a), BoolOp::Intersection, view(&around), alone),
        (view(&around), BoolOp::Difference, view(&a), 8000.0 - alone),
    ];
    for (i, (x, op, y, volume)) in cases.into_iter().enumerate() {
        let out = mesh_sequence(&x, &[(op, y)]).unwrap();
        out.mesh.check_watertight().unwrap();
        assert_eq!(out.volume(), volume, "case {i}: {op:?}");
    }
}

/// A box with a tetrahedron inside it that touches it at one shared
/// corner (one shell by index, two edge-connected parts): every pair of
/// faces at the corner is apart but for the corner, yet the winding
/// number inside the tetrahedron is 2. The solid is the box alone, as an
/// operand alone and with a box apart.
#[test]
fn a_shell_nested_in_another_at_a_shared_corner_counts_once() {
    let mut mesh = boxes(&[([0.0; 3], [4.0; 3], false)]);
    let corner = mesh
        .positions
        .iter()
        .position(|&p| p == DVec3::ZERO)
        .unwrap() as u32;
    let first = mesh.positions.len() as u32;
    mesh.positions.extend([
        DVec3::new(1.0, 2.0, 2.0),
        DVec3::new(2.0, 1.0, 2.0),
        DVec3::new(2.0, 2.0, 1.0),
    ]);
    let [a, b, c] = [first, first + 1, first + 2];
    // outward: the far face (a, b, c) faces away from the corner
    mesh.faces.extend([
        vec![a, b, c],
        vec![corner, b, a],
        vec![corner, c, b],
        vec![corner, a, c],
    ]);
    assert!(
        six_volume(&mesh, &mesh.faces[6..]) > 0.0,
        "the tetrahedron is outward"
    );
    let far = boxes(&[([10.0; 3], [11.0; 3], false)]);
    assert_eq!(mesh_sequence(&view(&mesh), &[]).unwrap().volume(), 64.0);
    let with_far = mesh_sequence(&view(&mesh), &[(BoolOp::Union, view(&far))]).unwrap();
    assert_eq!(with_far.volume(), 65.0);
}

/// Six times the signed volume the triangles `faces` of `mesh` enclose
/// with the origin.
fn six_volume(mesh: &MeshBuf, faces: &[Vec<u32>]) -> f64 {
    faces
        .iter()
        .map(|f| {
            let [p, q, r] = [0, 1, 2].map(|k| mesh.positions[f[k] as usize]);
            p.dot(q.cross(r))
        })
        .sum()
}
