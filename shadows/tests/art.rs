//! Shadow art: known hulls by their exact volumes, the hull's shadows
//! against the images, and bad input.

use std::path::PathBuf;

use bsp_shadows::DVec3;
use bsp_shadows::art::{ArtError, ArtLight, ArtSpec, ArtView, Mask, ViewPlane, shadow_hull};

/// A `n × n` mask wanting the pixels where `want(c, r)`.
fn mask(n: u32, want: impl Fn(u32, u32) -> bool) -> Mask {
    Mask {
        width: n,
        height: n,
        wanted: (0..n * n).map(|p| want(p % n, p / n)).collect(),
    }
}

/// A 4 × 4 image with its middle 2 × 2 wanted.
fn square() -> Mask {
    mask(4, |c, r| (1..3).contains(&c) && (1..3).contains(&r))
}

fn view(light: ArtLight, origin: DVec3, u: DVec3, v: DVec3, mask: Mask) -> ArtView {
    ArtView {
        image: PathBuf::from("test.pgm"),
        light,
        plane: ViewPlane { origin, u, v },
        mask,
    }
}

/// The floor `z = 0`, pixels of unit size along x and y.
fn floor(light: ArtLight, mask: Mask) -> ArtView {
    view(light, DVec3::ZERO, DVec3::X, DVec3::Y, mask)
}

fn spec(views: Vec<ArtView>, hi: DVec3) -> ArtSpec {
    ArtSpec {
        views,
        bounds: [DVec3::ZERO, hi],
        simplify: None,
    }
}

#[test]
fn a_square_under_a_sun_is_a_prism() {
    let s = spec(
        vec![floor(ArtLight::Sun(DVec3::Z), square())],
        DVec3::new(4.0, 4.0, 2.0),
    );
    let hull = shadow_hull(&s).unwrap();
    assert_eq!(hull.hull.volume(), 8.0);
    // its shadow is the wanted square, exactly where it is wanted
    let check = &hull.check(&s).unwrap()[0];
    assert_eq!(check.wanted_area, 4.0);
    assert!((check.shadow_area - 4.0).abs() < 1e-9, "{check:?}");
    assert!(
        check.missing_area < 1e-9 && check.extra_area < 1e-9,
        "{check:?}"
    );
}

#[test]
fn two_orthogonal_squares_give_a_box() {
    // the floor under a sun overhead, and the wall x = 0 under a sun
    // along +x
    let wall = view(
        ArtLight::Sun(DVec3::X),
        DVec3::ZERO,
        DVec3::Y,
        DVec3::Z,
        mask(4, |c, r| (1..3).contains(&c) && r < 1),
    );
    let s = spec(
        vec![floor(ArtLight::Sun(DVec3::Z), square()), wall],
        DVec3::new(4.0, 4.0, 4.0),
    );
    let hull = shadow_hull(&s).unwrap();
    // x in [1, 3] (floor), y in [1, 3] (both), z in [0, 1] (wall)
    assert_eq!(hull.hull.volume(), 4.0);
    for c in hull.check(&s).unwrap() {
        assert!(c.missing_area < 1e-9 && c.extra_area < 1e-9, "{c:?}");
    }
}

#[test]
fn a_point_light_gives_a_pyramid_frustum() {
    let light = ArtLight::Point(DVec3::new(2.0, 2.0, 4.0));
    let s = spec(vec![floor(light, square())], DVec3::new(4.0, 4.0, 2.0));
    let hull = shadow_hull(&s).unwrap();
    // from the side-2 square at z = 0 to the side-1 square at z = 2
    let v = hull.hull.volume();
    assert!((v - 14.0 / 3.0).abs() < 1e-12, "{v}");
    let c = &hull.check(&s).unwrap()[0];
    assert!(c.missing_area < 1e-9 && c.extra_area < 1e-9, "{c:?}");
}

#[test]
fn a_point_light_in_the_bounds_is_the_apex() {
    // the cone ends at the light: a pyramid on the square, 1 high
    let light = ArtLight::Point(DVec3::new(2.0, 2.0, 1.0));
    let s = spec(vec![floor(light, square())], DVec3::new(4.0, 4.0, 2.0));
    let hull = shadow_hull(&s).unwrap();
    assert_eq!(hull.hull.volume(), 4.0 / 3.0);
    // the hull touches the light, and still gives the square back whole
    let c = &hull.check(&s).unwrap()[0];
    assert!(c.missing_area < 1e-9 && c.extra_area < 1e-9, "{c:?}");
    assert_eq!(c.wanted_area, 4.0);
    // a ring (a hole: two loops meeting at the light) and a second view
    // whose sun cuts the pyramid at half its height: a frustum of a
    // square ring
    let ring = mask(8, |c, r| {
        (2..6).contains(&c) && (2..6).contains(&r) && !((3..5).contains(&c) && (3..5).contains(&r))
    });
    let light = ArtLight::Point(DVec3::new(4.0, 4.0, 2.0));
    let half = view(
        ArtLight::Sun(DVec3::X),
        DVec3::ZERO,
        DVec3::Y,
        DVec3::Z,
        mask(8, |c, r| r < 1 && (2..6).contains(&c)),
    );
    let s = spec(vec![floor(light, ring), half], DVec3::new(8.0, 8.0, 4.0));
    let hull = shadow_hull(&s).unwrap();
    // the ring pyramid (outer 4 × 4, hole 2 × 2, 2 high) below z = 1:
    // (16 − 4)·(2/3)·(1 − (1/2)³)
    let v = hull.hull.volume();
    assert!((v - 12.0 * 2.0 / 3.0 * 7.0 / 8.0).abs() < 1e-12, "{v}");
    // the ring whole; on the wall a trapezoid, 4 wide at the bottom and
    // 2 at the top, missing half of each end pixel
    let c = hull.check(&s).unwrap();
    assert!(
        c[0].missing_area < 1e-9 && c[0].extra_area < 1e-9,
        "{:?}",
        c[0]
    );
    assert!(
        (c[1].missing_area - 1.0).abs() < 1e-9 && c[1].extra_area < 1e-9,
        "{:?}",
        c[1]
    );
}

/// The floor wants a ring, the wall (x = 0, sun along +x) a bar along its
/// bottom row, wider than the ring.
fn ring_and_bar() -> (Mask, ArtSpec) {
    let ring = mask(6, |c, r| {
        let hole = (2..4).contains(&c) && (2..4).contains(&r);
        (1..5).contains(&c) && (1..5).contains(&r) && !hole
    });
    let bar = mask(6, |_, r| r == 0);
    let wall = view(
        ArtLight::Sun(DVec3::X),
        DVec3::ZERO,
        DVec3::Y,
        DVec3::Z,
        bar,
    );
    let floor = floor(ArtLight::Sun(DVec3::Z), ring.clone());
    (ring, spec(vec![floor, wall], DVec3::new(6.0, 6.0, 3.0)))
}

#[test]
fn conflicting_views_miss_shadow_and_never_cast_extra() {
    // the ring's hole cannot give the bar: the hull casts less than
    // the wall wants
    let (_, s) = ring_and_bar();
    let hull = shadow_hull(&s).unwrap();
    let checks = hull.check(&s).unwrap();
    for c in &checks {
        assert!(c.extra_area < 1e-9, "{c:?}");
    }
    // the wall's bar is wanted at rows y in [0, 1) and [5, 6) too, where
    // the ring has nothing: missed
    assert!(checks[1].missing_area > 1.0, "{:?}", checks[1]);
    // the floor's ring is all there
    assert!(checks[0].missing_area < 1e-9, "{:?}", checks[0]);
}

#[test]
fn a_letter_shaped_region_with_holes_and_touching_corners() {
    // a ring with an island, pixels touching at corners, a C whose tips
    // touch: every cone is closed, and the prism's volume is the pixels'
    let m = mask(9, |c, r| {
        let ring = (1..8).contains(&c)
            && (1..8).contains(&r)
            && !((2..7).contains(&c) && (2..7).contains(&r));
        let island = c == 4 && r == 4;
        let diagonal = (c, r) == (0, 0) || (c, r) == (8, 8);
        ring || island || diagonal || (c, r) == (3, 3)
    });
    let n = m.count() as f64;
    let s = spec(
        vec![floor(ArtLight::Sun(DVec3::Z), m)],
        DVec3::new(9.0, 9.0, 1.0),
    );
    let hull = shadow_hull(&s).unwrap();
    assert_eq!(hull.hull.volume(), n);
}

#[test]
fn a_dithered_image_makes_a_closed_cone() {
    // pixels touching at corners all over (where earcut's triangles met
    // the walls in T-junctions, and the Booleans refused the open cone)
    let rows = [
        ".#.#.#..", "..##.###", "...#.###", "##.#...#", "..#.###.", "..##.###", "#..###.#",
        "##.#.###",
    ];
    let m = mask(8, |c, r| rows[r as usize].as_bytes()[c as usize] == b'#');
    let n = m.count() as f64;
    let s = spec(
        vec![floor(ArtLight::Sun(DVec3::Z), m)],
        DVec3::new(8.0, 8.0, 1.0),
    );
    assert_eq!(shadow_hull(&s).unwrap().hull.volume(), n);
}

#[test]
fn bad_views_are_named() {
    let hi = DVec3::new(4.0, 4.0, 2.0);
    let err = |s: ArtSpec| shadow_hull(&s).unwrap_err().to_string();
    // a light on the receiving plane, and a sun along it
    let e = err(spec(
        vec![floor(ArtLight::Point(DVec3::new(9.0, 9.0, 0.0)), square())],
        hi,
    ));
    assert!(
        e.contains("view 0") && e.contains("lies on the receiving plane"),
        "{e}"
    );
    let e = err(spec(vec![floor(ArtLight::Sun(DVec3::X), square())], hi));
    assert!(e.contains("along the receiving plane"), "{e}");
    // a point light behind the plane (a light inside the bounds is fine:
    // `a_point_light_in_the_bounds_is_the_apex`)
    let e = err(spec(
        vec![floor(ArtLight::Point(DVec3::new(2.0, 2.0, -3.0)), square())],
        hi,
    ));
    assert!(
        e.contains("view 0") && e.contains("behind the receiving plane"),
        "{e}"
    );
    // degenerate u, v
    let flat = view(
        ArtLight::Sun(DVec3::Z),
        DVec3::ZERO,
        DVec3::X,
        DVec3::X * 2.0,
        square(),
    );
    let e = err(spec(vec![flat], hi));
    assert!(e.contains("parallel"), "{e}");
    // no wanted shadow
    let e = err(spec(
        vec![floor(ArtLight::Sun(DVec3::Z), mask(4, |_, _| false))],
        hi,
    ));
    assert!(e.contains("no wanted shadow"), "{e}");
    // cones that miss each other
    let a = floor(ArtLight::Sun(DVec3::Z), mask(4, |c, _| c == 0));
    let b = floor(ArtLight::Sun(DVec3::Z), mask(4, |c, _| c == 3));
    let e = shadow_hull(&spec(vec![a, b], hi)).unwrap_err();
    assert!(matches!(e, ArtError::Empty), "{e}");
}

#[test]
fn specs_and_images_are_read_with_clear_errors() {
    let dir = std::env::temp_dir().join(format!("bsp_art_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // a 4 × 4 P2 image with its middle dark
    let pgm =
        "P2\n# a square\n4 4\n255\n255 255 255 255\n255 0 0 255\n255 0 0 255\n255 255 255 255\n";
    std::fs::write(dir.join("sq.pgm"), pgm).unwrap();
    let text = r#"{"views": [{"image": "sq.pgm", "light": {"sun": [0, 0, 1]},
        "plane": {"origin": [0, 0, 0], "u": [1, 0, 0], "v": [0, 1, 0]}}],
        "bounds": [[0, 0, 0], [4, 4, 2]]}"#;
    std::fs::write(dir.join("spec.json"), text).unwrap();
    let s = ArtSpec::load(&dir.join("spec.json")).unwrap();
    assert_eq!(s.views[0].mask, square());
    assert_eq!(shadow_hull(&s).unwrap().hull.volume(), 8.0);
    // a byte-order mark before the JSON is read past
    std::fs::write(dir.join("bom.json"), format!("\u{feff}{text}")).unwrap();
    let b = ArtSpec::load(&dir.join("bom.json")).unwrap();
    assert_eq!(b.views[0].mask, square());
    // a missing image names the file
    std::fs::write(dir.join("bad.json"), text.replace("sq.pgm", "gone.pgm")).unwrap();
    let e = ArtSpec::load(&dir.join("bad.json"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("gone.pgm"), "{e}");
    // a spec without bounds
    std::fs::write(dir.join("nb.json"), r#"{"views": []}"#).unwrap();
    let e = ArtSpec::load(&dir.join("nb.json")).unwrap_err().to_string();
    assert!(e.contains("nb.json") && e.contains("views"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The repository's UV sphere (a closed mesh).
fn sphere() -> bsp_shadows::Mesh {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../data/meshes/pyvista_sphere.obj"
    );
    bsp_shadows::read_mesh(path).unwrap()
}

#[test]
fn silhouettes_of_a_closed_mesh_come_back_but_for_boundary_pixels() {
    let sphere = sphere();
    let s = bsp_shadows::art::axis_silhouettes(&sphere, 96).unwrap();
    let views = s.views.clone();
    let hull = shadow_hull(&s).unwrap();
    for (v, c) in views.iter().zip(hull.check(&s).unwrap()) {
        let areas = (c.wanted_area, c.shadow_area, c.missing_area, c.extra_area);
        // (the cones' corners, a non-dyadic pixel apart, round to the
        // Booleans' grid, and the hull's to the shadows' grid)
        assert!(c.extra_area < 1e-6 * c.wanted_area, "{areas:?}");
        assert!(c.missing_area <= 0.02 * c.wanted_area, "{areas:?}");
        // every pixel it misses lies on the wanted region's boundary
        for (x, y) in c.missing_pixels(v, 1e-6) {
            let (x, y) = (i64::from(x), i64::from(y));
            let boundary = [(1, 0), (-1, 0), (0, 1), (0, -1)]
                .iter()
                .any(|&(dx, dy)| !v.mask.at(x + dx, y + dy));
            assert!(boundary, "pixel ({x}, {y}) missed inside the region");
        }
    }
}

#[test]
fn simplified_silhouettes_give_a_smaller_hull_whose_shadows_are_the_simplified_images() {
    let sphere = sphere();
    let mut s = bsp_shadows::art::axis_silhouettes(&sphere, 96).unwrap();
    let pixels = shadow_hull(&s).unwrap();
    s.simplify = Some(1.5);
    let simple = shadow_hull(&s).unwrap();
    let (before, after) = (
        pixels.hull.exact.triangles.len(),
        simple.hull.exact.triangles.len(),
    );
    assert!(3 * after < before, "{after} triangles against {before}");
    for (v, c) in s.views.iter().zip(simple.check(&s).unwrap()) {
        let areas = (c.wanted_area, c.shadow_area, c.missing_area, c.extra_area);
        // the wanted region moved by at most 1.5 pixels along its
        // boundary (about 3.5 · 96 pixels long here)
        let px = v.plane.normal().length();
        let image = v.mask.count() as f64 * px;
        assert!(
            (c.wanted_area - image).abs() < 1.5 * 400.0 * px,
            "{areas:?} {image}"
        );
        assert!(c.wanted_area != image, "{areas:?}");
        // the hull lies in every (simplified) cone: no extra shadow
        assert!(c.extra_area < 1e-6 * c.wanted_area, "{areas:?}");
        assert!(c.missing_area <= 0.02 * c.wanted_area, "{areas:?}");
        // partly wanted pixels are the simplified region's boundary
        assert!(c.wanted.iter().any(|&w| w > 0.0 && w < 1.0));
    }
}

#[test]
fn simplifying_keeps_holes_and_islands() {
    // a ring (radii 12 and 18) around an island (radius 4), and a pixel
    // touching the ring's outside at a corner: simplified by 3 pixels,
    // every cone stays closed and the components and the hole stay
    let m = mask(40, |c, r| {
        let d2 = (f64::from(c) - 19.5).powi(2) + (f64::from(r) - 19.5).powi(2);
        (144.0..=324.0).contains(&d2) || d2 <= 16.0 || (c, r) == (15, 1)
    });
    let pixels = m.count() as f64;
    let mut s = spec(
        vec![floor(ArtLight::Sun(DVec3::Z), m)],
        DVec3::new(40.0, 40.0, 1.0),
    );
    s.simplify = Some(3.0);
    let hull = shadow_hull(&s).unwrap();
    let c = &hull.check(&s).unwrap()[0];
    // a prism of height 1: its volume and its shadow are the simplified
    // region's area, which is not the pixels'
    let areas = (c.wanted_area, c.shadow_area, c.missing_area, c.extra_area);
    assert!(
        (hull.hull.volume() - c.wanted_area).abs() < 1e-9,
        "{areas:?}"
    );
    // (the hull's corners round to the shadows' grid)
    let tiny = 1e-6 * c.wanted_area;
    assert!(c.missing_area < tiny && c.extra_area < tiny, "{areas:?}");
    assert!(c.wanted_area != pixels && (c.wanted_area - pixels).abs() < 0.1 * pixels);
    // the island, the gap around it, the ring, and the corner pixel
    let at = |x: usize, y: usize| c.wanted[y * 40 + x];
    assert_eq!(at(19, 19), 1.0);
    assert_eq!(at(19 + 8, 19), 0.0);
    assert_eq!(at(19 + 15, 19), 1.0);
    assert_eq!(at(15, 1), 1.0);
}

#[test]
fn conflicting_views_are_grown_until_they_agree() {
    use bsp_shadows::art::optimize;
    let (ring, s) = ring_and_bar();
    let o = optimize(&s, 0.005, 8).unwrap();
    let grown = o.grown.as_ref().unwrap();
    assert!(grown.missing_before[1] > 1.0, "{:?}", grown.missing_before);
    for c in &o.checks {
        assert!(
            c.missing_area <= 0.005 * c.wanted_area,
            "{:?}",
            (c.wanted_area, c.missing_area)
        );
        assert!(c.extra_area < 1e-9);
    }
    // the floor's ring gained the pixels next to it that the bar needs,
    // one pixel away; the wall's bar did not change
    let g = &grown.growth;
    assert!(g[0].pixels >= 2 && g[0].max_displacement == 1.0, "{g:?}");
    assert_eq!(g[1].pixels, 0);
    assert!(
        ring.wanted
            .iter()
            .zip(&o.spec.views[0].mask.wanted)
            .all(|(a, b)| !a || *b)
    );
    // views that agree are left alone
    let calm = spec(
        vec![floor(ArtLight::Sun(DVec3::Z), square())],
        DVec3::new(4.0, 4.0, 2.0),
    );
    let o = optimize(&calm, 0.005, 8).unwrap().grown.unwrap();
    assert_eq!((o.rounds, o.growth[0].pixels), (0, 0));
}

#[test]
fn png_images_are_read_as_grey_over_white() {
    let dir = std::env::temp_dir().join(format!("bsp_art_png_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // white, with a black pixel, a dark red one (luma 30: dark) and a
    // light yellow one (luma 226: light)
    let mut img = shadow_raster::Image::new(3, 2, [255, 255, 255]);
    img.rgb[0..3].copy_from_slice(&[0, 0, 0]);
    img.rgb[3..6].copy_from_slice(&[100, 0, 0]);
    img.rgb[6..9].copy_from_slice(&[255, 255, 80]);
    let path = dir.join("img.png");
    std::fs::write(&path, img.encode_png()).unwrap();
    let m = bsp_shadows::art::read_mask(&path, 128.0).unwrap();
    assert_eq!((m.width, m.height), (3, 2));
    assert_eq!(m.wanted, [true, true, false, false, false, false]);
    // not an image
    std::fs::write(&path, b"hello").unwrap();
    let e = bsp_shadows::art::read_mask(&path, 128.0)
        .unwrap_err()
        .to_string();
    assert!(e.contains("img.png") && e.contains("not a PGM"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn deforming_moves_a_shifted_view_back_instead_of_growing_the_others() {
    use bsp_shadows::art::{Optimize, optimize_with};
    // three views of a 16-cube in a 32-box, the third (on the wall y = 0)
    // shifted by 4 pixels along x: the floor and it each miss a quarter
    let sq = |c0: u32| {
        mask(32, move |c, r| {
            (c0..c0 + 16).contains(&c) && (8..24).contains(&r)
        })
    };
    // (each wall through the origin, under a sun along its normal)
    let wall =
        |sun: DVec3, u: DVec3, v: DVec3, c0| view(ArtLight::Sun(sun), DVec3::ZERO, u, v, sq(c0));
    let views = vec![
        wall(DVec3::Z, DVec3::X, DVec3::Y, 8),
        wall(DVec3::X, DVec3::Y, DVec3::Z, 8),
        wall(DVec3::Y, DVec3::X, DVec3::Z, 12),
    ];
    let s = spec(views, DVec3::splat(32.0));
    let how = |deform_rounds| Optimize {
        target: 0.005,
        rounds: 16,
        deform_rounds,
    };
    let grown = optimize_with(&s, how(0)).unwrap();
    let moved = optimize_with(&s, how(8)).unwrap();
    for run in [&grown, &moved] {
        let g = run.grown.as_ref().unwrap();
        assert!(
            (g.missing_before[0] - 64.0).abs() < 1e-9,
            "{:?}",
            g.missing_before
        );
        for c in &run.checks {
            assert!(c.missing_area <= 0.005 * c.wanted_area, "{c:?}");
            assert!(c.extra_area < 1e-9, "{c:?}");
        }
    }
    let pixels = |run: &bsp_shadows::art::ArtRun| -> usize {
        let g = run.grown.as_ref().unwrap();
        g.growth.iter().map(|g| g.pixels).sum()
    };
    let g = moved.grown.as_ref().unwrap();
    let d = g.deformed.as_ref().unwrap();
    // the two views that missed moved, by at most the shift and a pixel;
    // the one that did not stayed; fewer pixels were added
    assert!(d.rounds >= 1, "{d:?}");
    for k in [0, 2] {
        let v = &d.views[k];
        assert!(
            v.max_displacement > 0.0 && v.max_displacement <= 5.0,
            "{d:?}"
        );
    }
    assert_eq!(d.views[1].max_displacement, 0.0);
    assert!(
        pixels(&moved) < pixels(&grown),
        "{} {}",
        pixels(&moved),
        pixels(&grown)
    );
    assert!(grown.grown.as_ref().unwrap().deformed.is_none());
}
