//! The facade's jobs on a real mesh: Booleans that are closed and add up,
//! shadows whose areas agree with their fragments, files written whole,
//! errors with their causes.

use bsp_shadows::{DVec3, Error, Light, Mesh};

fn sphere() -> Mesh {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../data/meshes/pyvista_sphere.obj"
    );
    bsp_shadows::read_mesh(path).unwrap()
}

/// Twice the area of a planar ring (its normal's length).
fn ring_area(r: &[DVec3]) -> f64 {
    let mut n = DVec3::ZERO;
    for i in 1..r.len().saturating_sub(1) {
        n += (r[i] - r[0]).cross(r[i + 1] - r[0]);
    }
    n.length() / 2.0
}

#[test]
fn booleans_are_closed_and_add_up() {
    let a = sphere();
    let b = bsp_shadows::translated(&a, DVec3::new(60.0, 30.0, 15.0));
    let u = bsp_shadows::union(&a, &b).unwrap();
    let i = bsp_shadows::intersection(&a, &b).unwrap();
    let d = bsp_shadows::difference(&a, &b).unwrap();
    for m in [&u, &i, &d] {
        assert!(m.is_closed_oriented());
    }
    let (va, vb) = (a.signed_volume(), b.signed_volume());
    let (vu, vi, vd) = (u.signed_volume(), i.signed_volume(), d.signed_volume());
    // exact results rounded once: the identities hold to rounding
    let tol = 1e-9 * va;
    assert!(
        (vu + vi - va - vb).abs() < tol,
        "{vu} + {vi} vs {va} + {vb}"
    );
    assert!((vd + vi - va).abs() < tol, "{vd} + {vi} vs {va}");
    assert!(vi > 0.0 && vd > 0.0);
}

/// A result written as STL is closed and has no flat face as read back,
/// although rounding to `f32` makes vertices equal and puts the corners
/// of some triangles on one line (the nut and a moved copy do both).
#[test]
fn results_written_as_stl_are_closed_as_read_back() {
    let nut = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../data/meshes/pyvista_nut.obj"
    );
    let a = bsp_shadows::read_mesh(nut).unwrap();
    let (lo, hi) = a.bounds().unwrap();
    let b = bsp_shadows::translated(&a, (hi - lo) * DVec3::new(0.31, 0.17, 0.23));
    let u = bsp_shadows::union(&a, &b).unwrap();
    let path = std::env::temp_dir().join(format!("facade-stl-{}.stl", std::process::id()));
    bsp_shadows::write_mesh(&path, &u).unwrap();
    let mut back = bsp_shadows::read_mesh(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    back.weld();
    use bsp_shadows::MeshView;
    assert_eq!(back.flat_triangles(|p| p), 0);
    assert!(back.is_closed_oriented());
    assert!((back.signed_volume() - u.signed_volume()).abs() < 1e-5 * u.signed_volume());
    // a mesh smaller than an f32 step where it lies is not written as STL
    let tiny = bsp_shadows::translated(&sphere(), DVec3::splat(1e9));
    let tiny = bsp_shadows::Mesh {
        positions: (tiny.positions.iter())
            .map(|&p| DVec3::splat(1e9) + (p - DVec3::splat(1e9)) * 1e-3)
            .collect(),
        ..tiny
    };
    let e = bsp_shadows::write_mesh(&path, &tiny).unwrap_err();
    assert!(
        e.to_string()
            .contains("rounding to f32 collapses every triangle"),
        "{e}"
    );
    assert!(!path.exists());
}

#[test]
fn shadow_areas_agree_with_the_fragments_and_files() {
    let a = sphere();
    let b = bsp_shadows::translated(&a, DVec3::new(100.0, 50.0, 200.0));
    let both = bsp_shadows::union(&a, &b).unwrap();
    let lights = [
        Light::Point(DVec3::new(300.0, 200.0, 900.0)),
        Light::Sun(DVec3::new(-1.0, 0.5, 1.0)),
    ];
    let s = bsp_shadows::shadows(&both, &lights).unwrap();
    let faces = both.faces.len();
    let mut lit = vec![[0.0; 2]; faces];
    let mut area = vec![0.0; faces];
    for f in s.fragments() {
        let a = ring_area(&f.rings[0]) - f.rings[1..].iter().map(|r| ring_area(r)).sum::<f64>();
        area[f.face] += a;
        for (l, x) in lit[f.face].iter_mut().enumerate() {
            if f.lit >> l & 1 == 1 {
                *x += a;
            }
        }
    }
    for f in 0..faces {
        assert!(
            (s.face_area(f) - area[f]).abs() <= 1e-9 * area[f].max(1.0),
            "face {f}"
        );
        for (l, want) in lit[f].iter().enumerate() {
            assert!((s.lit_area(f, l) - want).abs() <= 1e-9 * area[f].max(1.0));
            assert!(s.lit_area(f, l) <= s.face_area(f) * (1.0 + 1e-12));
        }
    }
    // the upper sphere shadows the lower one from the point light above
    assert!(
        s.lit_fraction(0) > 0.2 && s.lit_fraction(0) < 0.5,
        "{}",
        s.lit_fraction(0)
    );
    let dir = std::env::temp_dir().join(format!("bsp-shadows-facade-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    s.write(dir.join("s.json")).unwrap();
    s.write(dir.join("s.obj")).unwrap();
    // another name is an error, not OBJ text under it
    let e = s.write(dir.join("s.svg")).unwrap_err().to_string();
    assert!(
        e.ends_with("s.svg: fragments are written as .json or .obj"),
        "{e}"
    );
    assert!(!dir.join("s.svg").exists());
    let json = std::fs::read_to_string(dir.join("s.json")).unwrap();
    assert!(json.starts_with('{') && json.trim_end().ends_with('}'));
    let obj = std::fs::read_to_string(dir.join("s.obj")).unwrap();
    assert!(obj.contains("\ng lit") && obj.contains("\ng shadow"));
    bsp_shadows::write_mesh(dir.join("both.stl"), &both).unwrap();
    let back = bsp_shadows::read_mesh(dir.join("both.stl")).unwrap();
    assert_eq!(back.faces.len(), both.faces.len());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn errors_keep_their_causes() {
    let e = bsp_shadows::read_mesh("/no/such/mesh.obj").unwrap_err();
    assert!(matches!(e, Error::File(_)));
    assert!(std::error::Error::source(&e).is_some());
    assert!(e.to_string().contains("/no/such/mesh.obj"), "{e}");
    let mut open = sphere();
    open.faces.pop();
    let e = bsp_shadows::union(&open, &sphere()).unwrap_err();
    assert!(matches!(e, Error::Boolean(_)));
    assert!(e.to_string().contains("boundary edge"), "{e}");
    let e = bsp_shadows::shadows(&sphere(), &[Light::Sun(DVec3::ZERO)]).unwrap_err();
    assert!(matches!(e, Error::Light(_)), "{e}");
}

/// A light with a NaN or infinite coordinate is named as such, whatever
/// kind it is (not "outside the grid", nor "a zero direction").
#[test]
fn lights_not_finite_are_named() {
    use bsp_shadows::SoftSpec;
    let not_finite = |index: usize| format!("light {index}: a coordinate is not finite");
    for bad in [f64::NAN, f64::INFINITY] {
        let lights = [
            Light::Point(DVec3::new(0.0, 0.0, 3.0)),
            Light::Sun(DVec3::new(0.0, bad, 1.0)),
        ];
        let e = bsp_shadows::shadows(&sphere(), &lights).unwrap_err();
        assert!(e.to_string().contains(&not_finite(1)), "{e}");
        let e = bsp_shadows::shadows(&sphere(), &[Light::Point(DVec3::new(bad, 0.0, 3.0))])
            .unwrap_err();
        assert!(e.to_string().contains(&not_finite(0)), "{e}");
        let area = |z: f64| {
            SoftSpec::Area(
                [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5)]
                    .map(|(x, y)| DVec3::new(x, y, z))
                    .to_vec(),
            )
        };
        let disc = |d: DVec3| SoftSpec::SunDisc {
            direction: d,
            radius_deg: 0.2666,
        };
        let cases = [
            vec![area(3.0), area(bad)],
            vec![area(3.0), disc(DVec3::new(bad, 0.0, 1.0))],
        ];
        for soft in cases {
            let e = bsp_shadows::soft_file::soft_shadows(&sphere(), &[], &soft).unwrap_err();
            assert!(e.to_string().contains(&not_finite(1)), "{e}");
        }
    }
}

/// Counts the phases and steps a job reports.
#[derive(Default)]
struct Heard {
    phases: std::sync::Mutex<Vec<&'static str>>,
    steps: std::sync::atomic::AtomicU64,
}

impl bsp_shadows::shadow_file::Progress for Heard {
    fn phase(&self, name: &'static str, _: u64) {
        self.phases.lock().unwrap().push(name);
    }
    fn advance(&self, steps: u64) {
        self.steps
            .fetch_add(steps, std::sync::atomic::Ordering::Relaxed);
    }
}

/// The shadow file job: JSON, OBJ and SVG by both algorithms agree on
/// the lit area, report their phases and steps, and the JSON holds one
/// record per fragment.
#[test]
fn shadow_files_by_both_algorithms_agree() {
    use bsp_shadows::shadow_file::{Algorithm, FileKind, LitScene, write_shadows};
    let mesh = shadow_scene::scene("chair").unwrap();
    let specs = [Light::Point(DVec3::new(1.0, -2.0, 3.0))];
    let grid = svbsp::shared_grid(&mesh.positions, &specs).unwrap();
    let lights = svbsp::place_lights(&grid, &specs).unwrap();
    let (polys, _) = bsp_core::import_faces_par(&grid, &mesh.face_loops()).unwrap();
    let notes = vec!["a point light".to_string()];
    let scene = LitScene {
        name: "chair",
        mesh: &mesh,
        grid: &grid,
        lights: &lights,
        light_notes: &notes,
        polys: &polys,
    };
    let view = shadow_raster::svg::SvgViewpoint::choose(
        Default::default(),
        &mesh.positions,
        None,
        (320, 180),
        50.0,
    )
    .0;
    let mut lit = Vec::new();
    for algorithm in [Algorithm::Psv, Algorithm::ChinFeiner] {
        for kind in [FileKind::Json, FileKind::Obj, FileKind::Svg(&view)] {
            let heard = Heard::default();
            let mut out = Vec::new();
            let f = write_shadows(&scene, algorithm, kind, &mut out, &heard).unwrap();
            assert!(f.fragments > 0 && !out.is_empty());
            assert!(heard.steps.into_inner() > 0 || algorithm == Algorithm::ChinFeiner);
            assert!(!heard.phases.into_inner().unwrap().is_empty() && !f.phases.is_empty());
            assert_eq!(
                f.bsp_polygons.is_some(),
                algorithm == Algorithm::ChinFeiner || matches!(kind, FileKind::Svg(_))
            );
            assert_eq!(f.drawn.is_some(), matches!(kind, FileKind::Svg(_)));
            assert_eq!(f.vertices.is_some(), matches!(kind, FileKind::Obj));
            if matches!(kind, FileKind::Json) {
                let v: serde_json::Value = serde_json::from_slice(&out).unwrap();
                assert_eq!(v["fragments"].as_array().unwrap().len(), f.fragments);
            }
            lit.push(f.areas.total - f.areas.dark);
        }
    }
    for l in &lit {
        assert!((l - lit[0]).abs() <= 1e-9 * lit[0], "{lit:?}");
    }
}

/// Soft shadows' fragments through the facade: a ground under a square
/// roof and a square area light is three regions (lit with the penumbra
/// as its hole, penumbra with the umbra as its hole, umbra), the roof one
/// lit region; per face and class the rings' areas are the face's areas,
/// and only penumbra has a share.
#[test]
fn soft_fragments_are_regions_with_the_faces_areas() {
    // a ground of side 10 and a roof of side 2 at height 1
    let square =
        |r: f64, z: f64| [(-r, -r), (r, -r), (r, r), (-r, r)].map(|(x, y)| DVec3::new(x, y, z));
    let face = |first: u32| bsp_shadows::Face {
        vertices: (first..first + 4).collect(),
        line: 0,
        group: 0,
    };
    let mesh = Mesh {
        positions: [square(5.0, 0.0), square(1.0, 1.0)].concat(),
        faces: vec![face(0), face(4)],
        groups: vec!["default".to_string()],
    };
    let lamp = [(-0.5, -0.5), (-0.5, 0.5), (0.5, 0.5), (0.5, -0.5)];
    let soft = [bsp_shadows::SoftSpec::Area(
        lamp.iter().map(|&(x, y)| DVec3::new(x, y, 3.0)).collect(),
    )];
    let s = bsp_shadows::soft_file::soft_shadows(&mesh, &[], &soft).unwrap();
    let frags: Vec<_> = s.fragments().collect();
    assert_eq!(frags.len(), s.fragment_count());
    let ground: Vec<_> = frags.iter().filter(|f| f.face == 0).collect();
    let holes = |lit: u64, umbra: u64| -> Vec<usize> {
        (ground.iter())
            .filter(|f| (f.lit, f.umbra) == (lit, umbra))
            .map(|f| f.rings.len() - 1)
            .collect()
    };
    assert_eq!(ground.len(), 3);
    assert_eq!(holes(1, 0), [1]);
    assert_eq!(holes(0, 0), [1]);
    assert_eq!(holes(0, 1), [0]);
    let roof: Vec<_> = frags.iter().filter(|f| f.face == 1).collect();
    assert!(roof.len() == 1 && roof[0].lit == 1);
    use bsp_shadows::soft_file::SoftClass;
    for face in 0..2 {
        for (class, lit, umbra) in [
            (SoftClass::Lit, 1, 0),
            (SoftClass::Penumbra, 0, 0),
            (SoftClass::Umbra, 0, 1),
        ] {
            let got: f64 = (frags.iter())
                .filter(|f| f.face == face && (f.lit, f.umbra) == (lit, umbra))
                .map(|f| {
                    ring_area(&f.rings[0]) - f.rings[1..].iter().map(|r| ring_area(r)).sum::<f64>()
                })
                .sum();
            let want = s.area_of(face, 0, class);
            assert!(
                (got - want).abs() <= 1e-9 * (1.0 + want),
                "{face} {class:?}: {got} {want}"
            );
        }
    }
    for f in &frags {
        let penumbra = f.lit == 0 && f.umbra == 0;
        assert_eq!(f.visible[0].is_some(), penumbra);
        if let Some(v) = f.visible[0] {
            assert!(v > 0.0 && v < 1.0, "{v}");
        }
    }
}
