//! Degenerate configurations, each checked by the ray oracle (every flag)
//! and the exact tiling check, on three different scene trees.

use bsp_core::{BspTree, BuildOptions, MAX_COORD, Polygon};
use svbsp::{Light, LightError, ShadowError, chin_feiner, shadow_fragments};

use crate::harness::assert_loops;

type Loop = Vec<[i32; 3]>;

/// The rectangle `[x0, x1] × [y0, y1]` at height `z`, facing up.
fn up(x0: i32, y0: i32, x1: i32, y1: i32, z: i32) -> Loop {
    vec![[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]]
}

/// The same loop, facing the other way.
fn flip(l: &Loop) -> Loop {
    l.iter().rev().copied().collect()
}

/// The six faces of the box `[a, b]`, facing outward.
fn cube(a: [i32; 3], b: [i32; 3]) -> Vec<Loop> {
    bsp_fixtures::grid_cuboid(a, b)
}

#[test]
fn cube_helper_faces_outward() {
    // every face has the box centre strictly behind it
    let faces = cube([0, 0, 0], [2, 2, 2]);
    let centre = Light::Point([1, 1, 1]);
    let scene = crate::harness::scene_of(&faces);
    assert!(scene.faces.iter().all(|f| !f.faces_light(&centre)));
    let outside = Light::Point([1, 1, 5]);
    assert_eq!(
        scene
            .faces
            .iter()
            .filter(|f| f.faces_light(&outside))
            .count(),
        1
    );
}

#[test]
fn uniform_faces_are_one_fragment_and_shadows_make_holes() {
    // the floor: a lit ring around the roof's shadow; the roof and a
    // tile far away are lit all over, each one fragment; a lit tile and a
    // tile wholly in shadow stay whole too
    let floor = up(0, 0, 8, 8, 0);
    let roof = up(2, 2, 4, 4, 4);
    let far = up(20, 20, 22, 22, 0);
    let dark = up(3, 3, 4, 4, 1);
    let c = assert_loops(&[floor, roof, far, dark], &[Light::Point([3, 3, 8])]);
    assert_eq!(c.fragments_of(0), 2);
    let lit: Vec<_> = c
        .frags
        .iter()
        .filter(|f| f.face() == 0 && f.lit()[0])
        .collect();
    assert_eq!((lit.len(), lit[0].holes()), (1, 1));
    for face in [1, 2, 3] {
        assert_eq!(c.fragments_of(face), 1, "face {face}");
    }
    assert_eq!(c.flags_of(3, 0), [false]);
    // two lights: the floor's fragments are the overlay of both shadows,
    // still one per connected part with equal flags
    let c = assert_loops(
        &[up(0, 0, 8, 8, 0), up(2, 2, 4, 4, 4)],
        &[Light::Point([3, 3, 8]), Light::Point([3, 3, 9])],
    );
    // both shadows are squares about (3, 3): [1, 5]^2 and [1.4, 4.6]^2
    assert_eq!(c.fragments_of(0), 3);
    assert_eq!(c.fragments_of(1), 1);
}

#[test]
fn light_in_a_face_plane() {
    let floor = up(0, 0, 8, 8, 0);
    // a wall in the plane x = 4, which holds light 0 (edge-on, both ways)
    let wall = vec![[4, 2, 1], [4, 6, 1], [4, 6, 3], [4, 2, 3]];
    let roof = up(1, 1, 3, 3, 3);
    let scene = vec![floor, wall.clone(), flip(&wall), roof];
    // light 1 lies in the floor's plane, light 2 in the roof's
    let lights = [
        Light::Point([4, 4, 6]),
        Light::Point([10, 4, 0]),
        Light::Point([-3, 2, 3]),
    ];
    let c = assert_loops(&scene, &lights);
    assert!(c.flags_of(1, 0).iter().chain(&c.flags_of(2, 0)).all(|l| !l));
    assert!(c.flags_of(0, 1).iter().all(|l| !l));
    assert!(c.flags_of(3, 2).iter().all(|l| !l));
    // the roof does cast a shadow on the floor from light 0
    let floor0 = c.flags_of(0, 0);
    assert!(floor0.contains(&true) && floor0.contains(&false));
}

#[test]
fn light_on_the_extension_of_edges() {
    // a tilted triangle whose edge (2,2,2)-(3,3,3) points at the light,
    // and a second one sharing that edge (a fold along the light's line)
    let a = vec![[2, 2, 2], [3, 3, 3], [2, 5, 2]];
    let b = vec![[3, 3, 3], [2, 2, 2], [5, 2, 2]];
    // a quad whose edge line y = 1, z = 4 passes through light 1
    let c = up(-1, 1, 3, 4, 4);
    let floor = up(-4, -4, 9, 9, 0);
    let lights = [Light::Point([6, 6, 6]), Light::Point([7, 1, 4])];
    let r = assert_loops(&[a, b, c, floor], &lights);
    for j in 0..2 {
        let (lit, dark) = r.count(j);
        assert!(lit > 0 && dark > 0, "light {j}: {lit} lit, {dark} dark");
    }
}

#[test]
fn shadow_planes_that_coincide() {
    // seen from (4,4,8), the roof [3,5]^2 at z = 6 covers the roof [2,6]^2
    // at z = 4 exactly: their shadow planes are the same planes, and the
    // lower roof is entirely in shadow
    let lower = up(2, 2, 6, 6, 4);
    let upper = up(3, 3, 5, 5, 6);
    let floor = up(-4, -4, 12, 12, 0);
    // a second occluder whose shadow edge meets the first's on the floor
    let side = up(6, 2, 8, 6, 4);
    let lights = [Light::Point([4, 4, 8]), Light::Directional([0, 0, 1])];
    let c = assert_loops(&[lower, upper, floor, side], &lights);
    assert!(c.flags_of(0, 0).iter().all(|l| !l));
    assert!(c.flags_of(1, 0).iter().all(|l| *l));
}

#[test]
fn coincident_and_coplanar_faces() {
    let floor = up(0, 0, 10, 10, 0);
    let a = up(2, 2, 5, 5, 4);
    let lights = [
        Light::Point([4, 4, 9]),
        Light::Point([6, 3, -5]),
        Light::Directional([1, 2, 5]),
    ];
    let scene = vec![
        floor.clone(),
        a.clone(),
        a.clone(),                // an identical face
        flip(&a),                 // and its flipped copy
        up(4, 3, 7, 6, 4),        // overlapping, coplanar
        flip(&up(3, 4, 6, 8, 4)), // overlapping, coplanar, flipped
        flip(&floor),             // the floor seen from below
        up(8, 8, 9, 9, 0),        // coplanar with the floor, inside it
    ];
    let c = assert_loops(&scene, &lights);
    // duplicates get the same flags, as areas: coplanar faces do not
    // shadow one another
    for j in 0..lights.len() {
        let lit_area = |face: u32| c.flags_of(face, j).iter().filter(|l| **l).count() > 0;
        assert_eq!(lit_area(1), lit_area(2), "light {j}");
    }
    let (lit, dark) = c.count(0);
    assert!(lit > 0 && dark > 0);
}

#[test]
fn light_touching_a_face() {
    let floor = up(-2, -2, 10, 10, 0);
    let roof = up(2, 2, 6, 6, 4);
    // a closed tetrahedron, faces outward, apex (3,7,5)
    let (p, q, r, apex) = ([1, 6, 2], [5, 6, 2], [3, 9, 2], [3, 7, 5]);
    let tet = vec![
        vec![p, r, q],
        vec![p, q, apex],
        vec![q, r, apex],
        vec![r, p, apex],
    ];
    let mut scene = vec![floor, roof];
    scene.extend(tet);
    let lights = [
        Light::Point([2, 2, 4]), // a vertex of the roof
        Light::Point([4, 2, 4]), // on an edge of the roof
        Light::Point([3, 4, 4]), // inside the roof
        Light::Point(apex),      // the tetrahedron's apex
        Light::Point([3, 6, 2]), // on the tetrahedron's edge p-q
    ];
    let c = assert_loops(&scene, &lights);
    // the roof is edge-on to the first three lights
    for j in 0..3 {
        assert!(c.flags_of(1, j).iter().all(|l| !l), "light {j}");
    }
    // from its apex, the tetrahedron is dark and shadows the floor below
    // it; the floor is still lit elsewhere
    for face in 2..6 {
        assert!(c.flags_of(face, 3).iter().all(|l| !l));
    }
    let floor3 = c.flags_of(0, 3);
    assert!(floor3.contains(&true) && floor3.contains(&false));
}

#[test]
fn sun_parallel_to_faces() {
    let floor = up(0, 0, 12, 12, 0);
    // walls in planes y = const, facing both ways, and a slanted face
    // whose plane x = z + 2 holds the direction (1, 0, 1)
    let wall = |y: i32| vec![[2, y, 0], [9, y, 0], [9, y, 4], [2, y, 4]];
    let slant = vec![[4, 7, 2], [5, 7, 3], [5, 10, 3], [4, 10, 2]];
    let scene = vec![floor, wall(3), flip(&wall(6)), slant, up(3, 4, 6, 5, 5)];
    let lights = [
        Light::Directional([1, 0, 1]), // in the walls' and the slant's planes
        Light::Directional([0, 0, 1]), // in the walls' planes
        Light::Directional([1, 1, 0]), // in the floor's plane
        Light::Directional([0, -3, 2]),
    ];
    let c = assert_loops(&scene, &lights);
    for j in 0..2 {
        for face in [1, 2] {
            assert!(c.flags_of(face, j).iter().all(|l| !l), "light {j}");
        }
    }
    assert!(c.flags_of(3, 0).iter().all(|l| !l));
    assert!(c.flags_of(0, 2).iter().all(|l| !l));
    let floor0 = c.flags_of(0, 0);
    assert!(floor0.contains(&true) && floor0.contains(&false));
}

#[test]
fn light_inside_a_closed_box() {
    let floor = up(-4, -4, 12, 12, 0);
    let outside = up(0, 8, 3, 10, 2);
    let bx = cube([2, 2, 2], [6, 6, 6]);
    let inner: Vec<Loop> = bx.iter().map(flip).collect();
    // an inside light at the centre and one off-centre on the grid; a
    // third light outside the box
    let lights = [
        Light::Point([4, 4, 4]),
        Light::Point([3, 5, 4]),
        Light::Point([4, 4, 12]),
    ];
    // the box faces outward: every box face backs onto the inside lights
    let mut scene = vec![floor.clone(), outside.clone()];
    scene.extend(bx.iter().cloned());
    let c = assert_loops(&scene, &lights);
    for j in 0..2 {
        assert!(c.frags.iter().all(|f| !f.lit()[j]), "light {j}");
    }
    let (lit, dark) = c.count(2);
    assert!(lit > 0 && dark > 0);
    // the box faces inward: its faces are lit from inside, nothing outside
    let mut scene = vec![floor, outside];
    scene.extend(inner);
    let c = assert_loops(&scene, &lights);
    for j in 0..2 {
        for f in &c.frags {
            assert_eq!(f.lit()[j], f.face() >= 2, "light {j}, face {}", f.face());
        }
    }
}

#[test]
fn several_lights_at_once() {
    let floor = up(0, 0, 12, 12, 0);
    let wall = vec![[0, 0, 0], [0, 0, 6], [0, 12, 6], [0, 12, 0]];
    let table = up(3, 3, 7, 6, 3);
    let tilted = vec![[6, 8, 2], [9, 8, 4], [9, 11, 4], [6, 11, 2]];
    let lights = [
        Light::Point([5, 5, 9]),
        Light::Directional([2, 1, 3]),
        Light::Point([10, 2, 5]),
    ];
    let c = assert_loops(&[floor, flip(&wall), table, tilted], &lights);
    // each light leaves some of the floor lit and some in shadow, at
    // different places: the flags are not all equal
    for j in 0..3 {
        let f = c.flags_of(0, j);
        assert!(f.contains(&true) && f.contains(&false), "light {j}");
    }
    let mixed = c.frags.iter().any(|f| f.lit() == [true, false, true]);
    assert!(mixed, "no fragment lit by lights 0 and 2 but not the sun");
}

#[test]
fn coordinates_at_the_grid_limits() {
    let m = MAX_COORD;
    let floor = up(-m, -m, m, m, -m);
    // a parallelogram spanning most of the grid, tilted a little
    let (p, a, b) = (
        [-m / 2, -m / 2, 3],
        [m / 2 + m / 3, 1000, 7],
        [-1000, m / 2 + m / 4, -5],
    );
    let add = |u: [i32; 3], v: [i32; 3]| [u[0] + v[0], u[1] + v[1], u[2] + v[2]];
    let roof = vec![p, add(p, a), add(add(p, a), b), add(p, b)];
    let lights = [
        Light::Point([m - 1, -m, m]),
        Light::Directional([m, m - 1, m - 2]),
        Light::Point([1, 0, m]),
    ];
    let c = assert_loops(&[floor, roof], &lights);
    let (lit, dark) = c.count(0);
    assert!(lit > 0 && dark > 0);
}

#[test]
fn no_lights_and_bad_lights() {
    let polys = vec![
        Polygon::from_grid_points(&up(0, 0, 4, 4, 0), 0).unwrap(),
        Polygon::from_grid_points(&up(1, 1, 2, 2, 2), 1).unwrap(),
    ];
    let (frags, stats) = shadow_fragments(&polys, &[]).unwrap();
    assert_eq!((frags.len(), stats.receivers), (2, 2));
    assert!(frags.fragments().all(|f| f.lit_mask() == 0));
    let bad = |lights: &[Light]| match shadow_fragments(&polys, lights).unwrap_err() {
        ShadowError::Light(e) => e,
        e => panic!("{e}"),
    };
    assert_eq!(
        bad(&[Light::Point([MAX_COORD + 1, 0, 0])]),
        LightError::OutOfGrid
    );
    assert_eq!(
        bad(&[Light::Directional([0, 0, -MAX_COORD - 1])]),
        LightError::OutOfGrid
    );
    assert_eq!(
        bad(&[Light::Point([0, 0, 1]), Light::Directional([0, 0, 0])]),
        LightError::ZeroDirection
    );
    let (frags, _) = shadow_fragments(&[], &[Light::Point([0, 0, 1])]).unwrap();
    assert!(frags.is_empty());
    // the same for Chin & Feiner
    let tree = BspTree::build(polys, &BuildOptions::default());
    assert_eq!(
        chin_feiner(&tree, &[Light::Directional([0, 0, 0])]).err(),
        Some(LightError::ZeroDirection)
    );
}

/// `LightVolumes::new` leaves out the faces that a light does not face of an
/// edge-connected part certified to bound a solid, and only of such a
/// part: two closed boxes crossing each other over an open ground lose
/// the faces turned away; an inverted box keeps all of them (left out,
/// its floor would come out lit under its own roof). The oracle checks
/// every fragment's flags, and the exact areas against Chin & Feiner's
/// (which keeps every face), either way.
#[test]
fn back_faces_of_certified_solids_are_left_out() {
    let light = Light::Point([3, 2, 40]);
    let kept = |scene: &[Loop]| {
        assert_loops(scene, &[light]);
        let polys = crate::harness::polygons(scene).unwrap();
        let s = svbsp::LightVolumes::new(&polys, &[light]).unwrap();
        let facing = polys.iter().filter(|p| light.faces(p.support())).count();
        (s.volumes()[0].occluder_count(), facing, polys.len())
    };
    let mut scene = vec![up(-30, -30, 30, 30, 0)];
    scene.extend(cube([0, 0, 4], [4, 4, 8]));
    scene.extend(cube([2, 1, 6], [7, 3, 10]));
    let (count, facing, all) = kept(&scene);
    assert_eq!((count, all), (facing, 13));
    assert!(facing < 8, "{facing}");
    let mut scene = vec![up(-30, -30, 30, 30, 0)];
    scene.extend(cube([0, 0, 4], [4, 4, 8]).iter().map(flip));
    let (count, _, all) = kept(&scene);
    assert_eq!(count, all);
}
