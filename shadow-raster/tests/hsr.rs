//! Visibility: the five methods agree pixel for pixel; the fill rule
//! leaves no crack and covers no pixel twice.

use glam::DVec3;
use shadow_raster::{Camera, Hsr, NONE, visible_surfaces};
use svbsp::LightSpec;

use crate::{bunny, cuboid, mesh, room, room_camera, setup};

fn all_agree(s: &shadow_raster::RasterScene, cam: &Camera, cull: bool) -> usize {
    let reference = visible_surfaces(s, cam, Hsr::ZBuffer, cull).unwrap();
    for h in Hsr::ALL {
        let v = visible_surfaces(s, cam, h, cull).unwrap();
        let bad = v.differences(&reference);
        assert_eq!(bad, 0, "{} differs from zbuffer on {bad} pixels", h.name());
        assert_eq!(v.w, reference.w, "{}: nearness", h.name());
    }
    reference.prim.iter().filter(|&&p| p != NONE).count()
}

#[test]
fn methods_agree_on_the_room() {
    let s = room();
    for cull in [false, true] {
        assert!(all_agree(&s.scene, &room_camera(160, 90), cull) > 3000);
    }
    // from inside, looking at a corner: polygons cross the near plane
    let inside = Camera::look_at(
        DVec3::new(-2.0, -1.2, 1.1),
        DVec3::new(1.5, 2.4, 0.4),
        DVec3::Z,
        80.0,
        120,
        90,
    )
    .unwrap();
    assert!(all_agree(&s.scene, &inside, false) > 120 * 90 / 2);
}

#[test]
fn methods_agree_on_the_bunny() {
    let (s, cam) = bunny("bunny", 128, 72);
    assert!(all_agree(&s.scene, &cam, false) > 3000);
}

#[test]
fn methods_agree_on_interpenetrating_and_touching_boxes() {
    // boxes that cut through each other, stand on each other and share
    // faces, seen from a generic and an axis-aligned viewpoint
    let mut faces = cuboid(DVec3::ZERO, DVec3::new(4.0, 4.0, 1.0));
    faces.extend(cuboid(DVec3::new(1.0, 1.0, 1.0), DVec3::new(2.0, 2.0, 3.0)));
    faces.extend(cuboid(DVec3::new(1.5, 0.5, 0.5), DVec3::new(3.5, 3.0, 2.0)));
    faces.extend(cuboid(DVec3::new(2.0, 1.0, 1.0), DVec3::new(3.0, 2.0, 2.5)));
    let s = setup(&mesh(&faces), &[LightSpec::Sun(DVec3::Z)]);
    for eye in [DVec3::new(7.0, -5.0, 6.0), DVec3::new(2.0, -8.0, 1.5)] {
        let cam = Camera::look_at(eye, DVec3::new(2.0, 2.0, 1.0), DVec3::Z, 45.0, 96, 72).unwrap();
        all_agree(&s.scene, &cam, false);
        all_agree(&s.scene, &cam, true);
    }
}

#[test]
fn a_tiling_of_triangles_leaves_no_crack_and_no_double_cover() {
    // a 12 × 12 grid of squares, each cut along a diagonal, filling the
    // whole view: every pixel sees exactly one of its triangles, and the
    // triangles cover exactly the pixels the whole square covers
    let mut faces = Vec::new();
    let n = 12;
    let at = |i: usize, j: usize| DVec3::new(i as f64 - 6.0, j as f64 - 6.0, 0.0);
    for i in 0..n {
        for j in 0..n {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            if (i + j) % 2 == 0 {
                faces.push(vec![a, b, c]);
                faces.push(vec![a, c, d]);
            } else {
                faces.push(vec![a, b, d]);
                faces.push(vec![b, c, d]);
            }
        }
    }
    let tiles = setup(&mesh(&faces), &[LightSpec::Sun(DVec3::Z)]);
    let whole = setup(
        &mesh(&[vec![at(0, 0), at(n, 0), at(n, n), at(0, n)]]),
        &[LightSpec::Sun(DVec3::Z)],
    );
    for (eye, fov) in [
        (DVec3::new(0.3, -4.0, 9.0), 60.0),
        (DVec3::new(0.0, 0.0, 10.0), 20.0),
    ] {
        let up = if eye.x == 0.0 { DVec3::Y } else { DVec3::Z };
        let cam = Camera::look_at(eye, DVec3::ZERO, up, fov, 200, 150).unwrap();
        let a = visible_surfaces(&tiles.scene, &cam, Hsr::ZBuffer, false).unwrap();
        let b = visible_surfaces(&whole.scene, &cam, Hsr::ZBuffer, false).unwrap();
        let covered = |v: &shadow_raster::VisibilityBuffer| {
            v.prim.iter().map(|&p| p != NONE).collect::<Vec<_>>()
        };
        assert_eq!(covered(&a), covered(&b));
        assert!(covered(&a).iter().filter(|&&c| c).count() > 5000);
    }
}
