//! Shadow methods against the exact shadows.

use glam::DVec3;
use shadow_raster::{Camera, Hsr, Method, RenderOptions, ShadowOptions, render, render_fragments};
use svbsp::LightSpec;

use crate::{bunny, cuboid, disagreement, mesh, room, room_camera, setup};

fn mask_of(s: &crate::Setup, cam: &Camera, opts: RenderOptions) -> Vec<u8> {
    render(&s.scene, &s.lights, cam, &[], &opts).unwrap().mask()
}

fn with(m: Method) -> RenderOptions {
    RenderOptions::default().with_method(m)
}

#[test]
fn exact_and_raycast_agree_on_the_room_and_the_bunny() {
    let s = room();
    let cam = room_camera(480, 270);
    let exact = mask_of(&s, &cam, with(Method::Exact));
    let rays = mask_of(&s, &cam, with(Method::Raycast));
    assert!(exact.contains(&128) && exact.contains(&255) && exact.contains(&0));
    let d = disagreement(&exact, &rays);
    assert!(d <= 0.001, "room: {:.4}% of pixels differ", 100.0 * d);
    let (b, cam) = bunny("bunny-11k", 480, 270);
    let exact = mask_of(&b, &cam, with(Method::Exact));
    let rays = mask_of(&b, &cam, with(Method::Raycast));
    let d = disagreement(&exact, &rays);
    assert!(d <= 0.001, "bunny: {:.4}% of pixels differ", 100.0 * d);
    assert!(
        exact.iter().filter(|&&m| m == 128).count() > 2000,
        "the bunny casts a shadow"
    );
}

#[test]
fn stencil_zfail_is_right_where_zpass_fails() {
    // a roof over a floor, the eye under the roof in its shadow volume,
    // looking out at the lit floor
    let mut faces = cuboid(DVec3::new(-10.0, -10.0, -0.5), DVec3::new(10.0, 10.0, 0.0));
    faces.extend(cuboid(
        DVec3::new(-2.0, -2.0, 3.0),
        DVec3::new(2.0, 2.0, 3.2),
    ));
    let s = setup(
        &mesh(&faces),
        &[LightSpec::Point(DVec3::new(0.0, 0.0, 8.0))],
    );
    let cam = Camera::look_at(
        DVec3::new(0.0, -0.5, 1.5),
        DVec3::new(0.0, -8.0, 0.0),
        DVec3::Z,
        70.0,
        160,
        120,
    )
    .unwrap();
    let exact = mask_of(&s, &cam, with(Method::Exact));
    let zfail = mask_of(&s, &cam, with(Method::StencilZfail));
    let zpass = mask_of(&s, &cam, with(Method::StencilZpass));
    assert!(
        disagreement(&exact, &zfail) < 0.002,
        "{}",
        disagreement(&exact, &zfail)
    );
    assert!(
        disagreement(&exact, &zpass) > 0.2,
        "{}",
        disagreement(&exact, &zpass)
    );
    // from outside every volume both are right
    let out = room_camera(200, 112);
    let r = room();
    let exact = mask_of(&r, &out, with(Method::Exact));
    for m in [Method::StencilZpass, Method::StencilZfail] {
        let d = disagreement(&exact, &mask_of(&r, &out, with(m)));
        assert!(d < 0.002, "{}: {d}", m.name());
    }
}

#[test]
fn shadow_map_bias_trades_acne_for_peter_panning() {
    let (b, cam) = bunny("bunny", 320, 180);
    let exact = mask_of(&b, &cam, with(Method::Exact));
    let map = |c: f64, k: f64, size: u32| {
        let o = with(Method::ShadowMap)
            .with_shadow(ShadowOptions::default().with_bias(c, k).with_map_size(size));
        disagreement(&exact, &mask_of(&b, &cam, o))
    };
    let good = map(0.0, 1.5, 2048);
    let acne = map(0.0, 0.0, 2048);
    let (lo, hi) = b.scene.bounds();
    let panning = map(0.05 * (hi - lo).max_element(), 0.0, 2048);
    let coarse = map(0.0, 1.5, 64);
    eprintln!("good {good} acne {acne} panning {panning} coarse {coarse}");
    assert!(good < 0.01, "{good}");
    assert!(acne > 2.0 * good, "acne {acne} vs {good}");
    assert!(panning > 2.0 * good, "peter-panning {panning} vs {good}");
    assert!(coarse > 2.0 * good, "aliasing {coarse} vs {good}");
    // PCF blurs the boundary but keeps the shadow
    let pcf = with(Method::ShadowMap).with_shadow(ShadowOptions::default().with_pcf(3));
    assert!(disagreement(&exact, &mask_of(&b, &cam, pcf)) < 0.02);
}

#[test]
fn planar_clipping_removes_anti_and_false_shadows() {
    // a ground, a post taller than the light beside it (anti-shadow) and a
    // box under the ground (false shadow)
    let mut faces = vec![vec![
        DVec3::new(-10.0, -10.0, 0.0),
        DVec3::new(10.0, -10.0, 0.0),
        DVec3::new(10.0, 10.0, 0.0),
        DVec3::new(-10.0, 10.0, 0.0),
    ]];
    faces.extend(cuboid(
        DVec3::new(1.0, -0.5, 0.0),
        DVec3::new(2.0, 0.5, 5.0),
    ));
    faces.extend(cuboid(
        DVec3::new(-4.0, -4.0, -3.0),
        DVec3::new(-2.0, -2.0, -1.0),
    ));
    let s = setup(
        &mesh(&faces),
        &[LightSpec::Point(DVec3::new(0.0, 0.0, 3.0))],
    );
    let cam = Camera::look_at(
        DVec3::new(0.0, -14.0, 12.0),
        DVec3::ZERO,
        DVec3::Z,
        60.0,
        200,
        150,
    )
    .unwrap();
    let exact = mask_of(&s, &cam, with(Method::Exact));
    let planar = |clip: bool| {
        let o = with(Method::Planar).with_shadow(ShadowOptions::default().with_planar_clip(clip));
        disagreement(&exact, &mask_of(&s, &cam, o))
    };
    let (clipped, naive) = (planar(true), planar(false));
    assert!(clipped < 0.01, "{clipped}");
    assert!(naive > clipped + 0.01, "{naive} vs {clipped}");
}

#[test]
fn the_shadow_texture_misses_self_shadows() {
    // one closed, non-convex object: an L whose upper arm shades its foot
    let p = |x: f64, z: f64, y: f64| DVec3::new(x, y, z);
    let l = [
        (0.0, 0.0),
        (4.0, 0.0),
        (4.0, 1.0),
        (1.0, 1.0),
        (1.0, 4.0),
        (0.0, 4.0),
    ];
    let mut faces = vec![
        l.iter().map(|&(x, z)| p(x, z, 0.0)).collect::<Vec<_>>(),
        l.iter().rev().map(|&(x, z)| p(x, z, 2.0)).collect(),
    ];
    for k in 0..l.len() {
        let (a, b) = (l[k], l[(k + 1) % l.len()]);
        faces.push(vec![
            p(a.0, a.1, 0.0),
            p(a.0, a.1, 2.0),
            p(b.0, b.1, 2.0),
            p(b.0, b.1, 0.0),
        ]);
    }
    // the L's front faces -y: reverse everything if it came out inside-out
    let m = mesh(&faces);
    let m = if m.signed_volume() < 0.0 {
        mesh(
            &faces
                .iter()
                .map(|f| f.iter().rev().copied().collect())
                .collect::<Vec<_>>(),
        )
    } else {
        m
    };
    let s = setup(&m, &[LightSpec::Sun(DVec3::new(-1.0, 0.3, 1.2))]);
    let cam = Camera::look_at(
        DVec3::new(8.0, 7.0, 6.0),
        DVec3::new(2.0, 1.0, 1.0),
        DVec3::Z,
        50.0,
        160,
        120,
    )
    .unwrap();
    let exact = mask_of(&s, &cam, with(Method::Exact));
    let tex = mask_of(&s, &cam, with(Method::Texture));
    let shadowed = |m: &[u8]| m.iter().filter(|&&v| v == 128).count();
    assert!(
        shadowed(&tex) < shadowed(&exact),
        "{} vs {}",
        shadowed(&tex),
        shadowed(&exact)
    );
    assert!(disagreement(&exact, &tex) > 0.01);
}

#[test]
fn every_method_and_visibility_runs_on_the_room() {
    let s = room();
    let cam = room_camera(128, 72);
    for m in Method::ALL {
        for h in [Hsr::ZBuffer, Hsr::Bsp] {
            let out = render(&s.scene, &s.lights, &cam, &[], &with(m).with_hsr(h)).unwrap();
            assert_eq!(out.image.rgb.len(), 3 * 128 * 72);
            assert_eq!(out.mask().len(), 128 * 72);
        }
    }
}

#[test]
fn a_comparison_and_a_render_report_for_people() {
    let s = room();
    let cam = room_camera(128, 72);
    let opts = ShadowOptions::default();
    let cmp = shadow_raster::compare(&s.scene, &s.lights, &cam, &[], &opts, &[Method::ShadowMap])
        .unwrap();
    let methods: Vec<&str> = cmp.reports.iter().map(|r| r.method.name()).collect();
    assert_eq!(methods, ["exact", "shadow-map"]);
    assert_eq!(cmp.reports[0].disagree, 0);
    let table = cmp.table();
    let table: Vec<&str> = table.lines().collect();
    assert_eq!(table.len(), 3);
    assert!(table[0].starts_with("method") && table[0].contains("disagree"));
    assert!(table[1].starts_with("exact") && table[1].contains(" 0.000% "));
    let shown = format!("{:.3}%", cmp.reports[1].disagree_percent());
    assert!(table[2].starts_with("shadow-map") && table[2].contains(&shown));
    assert_eq!(cmp.csv().lines().count(), 3);

    let out = render(&s.scene, &s.lights, &cam, &[], &with(Method::ShadowMap)).unwrap();
    let t = out.timings();
    let names: Vec<&str> = t.lines().map(|l| l.split(':').next().unwrap()).collect();
    assert_eq!(names, ["visibility", "shadows", "shading"]);
    let primitives = format!("({} primitives", out.figures.primitives);
    assert!(t.contains(&primitives), "{t}");
}

#[test]
fn images_do_not_depend_on_the_thread_count() {
    let s = room();
    let cam = room_camera(200, 120);
    for m in [Method::Exact, Method::ShadowMap, Method::StencilZfail] {
        let run = |n| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .unwrap()
                .install(|| {
                    render(&s.scene, &s.lights, &cam, &[], &with(m))
                        .unwrap()
                        .image
                })
        };
        assert_eq!(run(1), run(3), "{}", m.name());
    }
}

#[test]
fn a_kept_renderer_draws_every_frame_as_a_fresh_one() {
    // one Renderer frame after frame (its buffers are not cleared between
    // frames: each pass must write or clear every cell it reads), the
    // camera and the light moving and the size changing, against fresh
    // renders
    let setups = [
        room(),
        setup(
            &shadow_scene::room(),
            &[LightSpec::Point(DVec3::new(-1.2, 0.8, 1.9))],
        ),
    ];
    let mut r = shadow_raster::Renderer::new();
    let eyes = [
        DVec3::new(3.3, -7.4, 4.3),
        DVec3::new(-4.0, 5.0, 1.2),
        DVec3::new(0.2, 0.4, 9.0),
        DVec3::new(3.3, -7.4, 4.3),
    ];
    let mut frames = 0;
    for (k, eye) in eyes.into_iter().enumerate() {
        let s = &setups[k % 2];
        let (w, h) = if k == 2 { (96, 96) } else { (160, 90) };
        let cam = Camera::look_at(eye, DVec3::new(-0.15, 0.3, 0.45), DVec3::Z, 50.0, w, h).unwrap();
        for m in [Method::ShadowMap, Method::Raycast, Method::Exact] {
            let o = with(m);
            let fresh = render(&s.scene, &s.lights, &cam, &[], &o).unwrap();
            let kept = r.render(&s.scene, &s.lights, &cam, &[], &o).unwrap();
            assert!(kept.image == fresh.image, "{} at eye {eye}", m.name());
            assert_eq!(kept.visibility.prim, fresh.visibility.prim);
            assert_eq!(kept.mask(), fresh.mask());
            frames += 1;
        }
    }
    assert_eq!(frames, 12);
}

#[test]
fn fragments_from_elsewhere_draw_the_same_image() {
    // the animation hook: fragments of every face's front side
    let s = room();
    let cam = room_camera(240, 135);
    let exact: Vec<svbsp::Light> = s.lights.iter().map(|l| l.light).collect();
    let (batch, _) = svbsp::shadow_fragments(s.scene.polygons(), &exact).unwrap();
    let hook = render_fragments(&s.scene, &batch, &s.lights, &cam, &[]).unwrap();
    let direct = render(&s.scene, &s.lights, &cam, &[], &with(Method::Exact)).unwrap();
    // the room is seen from outside its solids: every visible face shows
    // its front, so the two agree except where rounding differs
    assert!(disagreement(&hook.mask(), &direct.mask()) < 0.0005);
}

#[test]
fn bad_options_are_errors() {
    let s = room();
    let cam = room_camera(32, 18);
    for o in [
        ShadowOptions::default().with_map_size(8),
        ShadowOptions::default().with_pcf(2),
        ShadowOptions::default().with_bias(-1.0, 0.0),
        ShadowOptions::default().with_bias(f64::NAN, 0.0),
    ] {
        let e = render(
            &s.scene,
            &s.lights,
            &cam,
            &[],
            &with(Method::ShadowMap).with_shadow(o),
        )
        .unwrap_err()
        .to_string();
        assert!(!e.is_empty());
    }
}

#[test]
fn odd_cameras_and_lights_never_panic() {
    let s = room();
    let eyes = [
        (DVec3::new(1e9, -2e9, 5e8), DVec3::ZERO, 50.0), // very far
        (DVec3::new(0.0, 0.0, 0.01), DVec3::new(1.0, 0.0, 0.01), 50.0), // on the floor
        (DVec3::new(-3.5, 0.0, 1.0), DVec3::new(3.0, 0.0, 1.0), 50.0), // in a wall's plane
        (DVec3::new(1.0, 2.45, 1.0), DVec3::new(1.0, 0.0, 1.0), 0.01), // in the bookshelf, tiny fov
        (DVec3::new(0.0, -1.0, 1.5), DVec3::new(0.0, 1.0, 1.5), 179.0), // very wide
    ];
    for (eye, target, fov) in eyes {
        let cam = Camera::look_at(eye, target, DVec3::Z, fov, 40, 24).unwrap();
        for m in Method::ALL {
            for h in [Hsr::ZBuffer, Hsr::Warnock] {
                let o = with(m)
                    .with_hsr(h)
                    .with_shadow(ShadowOptions::default().with_map_size(64));
                let out = render(&s.scene, &s.lights, &cam, &[], &o).unwrap();
                assert_eq!(out.mask().len(), 40 * 24);
            }
        }
        let _ = shadow_raster::hidden_lines(&s.scene, &cam);
    }
    // no light at all, and a grazing sun
    let cam = room_camera(40, 24);
    for m in Method::ALL {
        let out = render(&s.scene, &[], &cam, &[], &with(m)).unwrap();
        assert!(out.mask().iter().all(|&v| v != 255));
    }
    let grazing = setup(
        &shadow_scene::room(),
        &[LightSpec::Sun(DVec3::new(1.0, 0.2, 0.0))],
    );
    for m in Method::ALL {
        render(&grazing.scene, &grazing.lights, &cam, &[], &with(m)).unwrap();
    }
    // sizes
    for (w, h) in [(0, 10), (20000, 10), (16384, 16384)] {
        assert!(Camera::look_at(DVec3::ONE, DVec3::ZERO, DVec3::Z, 50.0, w, h).is_err());
    }
}

/// The room under a point light and a sun, as the lights of a soft run.
fn room_soft(
    extra: &[svbsp::SoftSpec],
) -> (
    shadow_raster::RasterScene,
    Vec<svbsp::PlacedLight>,
    Vec<svbsp::SoftLight>,
) {
    let mesh = shadow_scene::room();
    let specs = [
        LightSpec::Point(DVec3::new(0.9, 0.3, 2.45)),
        LightSpec::Sun(DVec3::new(0.3, -0.2, 1.0)),
    ];
    let grid = svbsp::shared_soft_grid(&mesh.positions, &specs, extra).unwrap();
    let placed = svbsp::place_lights(&grid, &specs).unwrap();
    let soft = svbsp::place_soft_lights(&grid, &placed, extra).unwrap();
    let loops = mesh.face_loops();
    let (polys, _) = bsp_core::import_faces(&grid, loops.iter().map(Vec::as_slice)).unwrap();
    (
        shadow_raster::RasterScene::new(&grid, polys).unwrap(),
        placed,
        soft,
    )
}

#[test]
fn soft_methods_with_points_and_suns_only_are_the_hard_ones() {
    let (scene, placed, soft) = room_soft(&[]);
    let cam = room_camera(240, 135);
    for (soft_method, hard) in [
        (Method::Exact, Method::Exact),
        (Method::Sampled(4), Method::Exact),
        (Method::Pcss, Method::ShadowMap),
    ] {
        let a = shadow_raster::render_soft(&scene, &soft, &cam, &[], &with(soft_method)).unwrap();
        let b = render(&scene, &placed, &cam, &[], &with(hard)).unwrap();
        assert_eq!(a.lit, b.lit, "{soft_method}");
        assert_eq!(a.image.rgb, b.image.rgb, "{soft_method}");
    }
}

#[test]
fn soft_pictures_do_not_depend_on_the_thread_count() {
    let light = svbsp::SoftSpec::Area(
        [[0.7, 0.1], [0.7, 0.5], [1.1, 0.5], [1.1, 0.1]]
            .map(|[x, y]| DVec3::new(x, y, 2.45))
            .to_vec(),
    );
    let disc = svbsp::SoftSpec::SunDisc {
        direction: DVec3::new(0.3, -0.2, 1.0),
        radius_deg: 3.0,
    };
    let (scene, _, soft) = room_soft(&[light, disc]);
    let cam = room_camera(200, 112);
    for m in [Method::Exact, Method::Sampled(8), Method::Pcss] {
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| shadow_raster::render_soft(&scene, &soft, &cam, &[], &with(m)).unwrap())
        };
        let (one, three) = (run(1), run(3));
        assert_eq!(one.lit, three.lit, "{m}");
        // the area light and the disc leave penumbra
        let soft_px = |j: usize| {
            (one.lit.amount.iter().skip(j).step_by(4))
                .filter(|&&a| a > 0.0 && a < 1.0)
                .count()
        };
        assert!(
            soft_px(2) > 50 && soft_px(3) > 50,
            "{m}: {} {}",
            soft_px(2),
            soft_px(3)
        );
    }
}
