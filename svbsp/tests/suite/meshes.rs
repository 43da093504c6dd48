//! Real meshes: the teapot (an open triangle soup) and the Stanford bunny
//! (closed), snapped with the lights onto one grid. Every face's tiling is
//! checked; flags are checked by the ray oracle on a few hundred fragments
//! per light, spread over the lit, cast-shadow and attached-shadow ones.

use bsp_core::{BspTree, BuildOptions, Grid, Membership, Point, Polygon, import_faces};
use glam::DVec3;
use shadow_scene::read_obj;
use svbsp::Light;

use crate::harness::{Checked, Opts, Sample, check, hunt, rng};
use crate::oracle::Scene;

/// A light in input units (point) or a grid direction (sun).
enum WorldLight {
    Point(DVec3),
    Sun([i32; 3]),
}

/// A mesh snapped with its lights, and the checked shadows.
struct MeshRun {
    polys: Vec<Polygon>,
    lights: Vec<Light>,
    checked: Checked,
}

impl MeshRun {
    /// Every light lights part of the scene and leaves part of it dark.
    fn assert_each_light_lights_and_darkens(&self) {
        for j in 0..self.lights.len() {
            let (lit, dark) = self.checked.count(j);
            assert!(lit > 0 && dark > 0, "light {j}: {lit} lit, {dark} dark");
        }
    }
}

/// Loads `name`, keeps the faces `keep` accepts, snaps them and the point
/// lights onto one fitted grid, and checks the shadows.
fn check_mesh(
    name: &str,
    keep: impl Fn(&[DVec3]) -> bool,
    world: &[WorldLight],
    per_kind: usize,
) -> MeshRun {
    let loops = mesh_loops(name).into_iter().filter(|l| keep(l)).collect();
    check_loops(name, loops, world, per_kind)
}

/// The face loops of mesh `name` of `data/meshes`.
pub(crate) fn mesh_loops(name: &str) -> Vec<Vec<DVec3>> {
    let path = format!("{}/../data/meshes/{name}", env!("CARGO_MANIFEST_DIR"));
    let mesh = read_obj(std::path::Path::new(&path)).unwrap_or_else(|e| panic!("{e}"));
    mesh.face_loops()
}

/// [`check_mesh`] of the face loops given.
fn check_loops(
    name: &str,
    loops: Vec<Vec<DVec3>>,
    world: &[WorldLight],
    per_kind: usize,
) -> MeshRun {
    let mut pts: Vec<DVec3> = loops.iter().flatten().copied().collect();
    pts.extend(world.iter().filter_map(|l| match l {
        WorldLight::Point(p) => Some(*p),
        WorldLight::Sun(_) => None,
    }));
    let grid = Grid::fit_points(&pts).expect("finite mesh");
    let lights: Vec<Light> = world
        .iter()
        .map(|l| match l {
            WorldLight::Point(p) => Light::Point(grid.snap(*p).expect("light inside the grid")),
            WorldLight::Sun(d) => Light::Directional(*d),
        })
        .collect();
    let (polys, _report) = import_faces(&grid, loops.iter().map(|l| &l[..])).expect("snaps");
    // one tag per polygon, so that each is checked on its own
    let polys: Vec<Polygon> = polys
        .into_iter()
        .enumerate()
        .map(|(i, p)| p.with_tag(i as u32))
        .collect();
    assert!(polys.len() > 100, "{name}: only {} polygons", polys.len());
    let scene = Scene::from_polygons(&polys);
    let opts = Opts {
        seeds: vec![BuildOptions::default().seed],
        sample: Sample::PerKind(per_kind),
        disjoint: true,
        shuffled: true,
    };
    let checked = check(&polys, &scene, &lights, &opts)
        .unwrap_or_else(|e| panic!("{name}, lights {lights:?}: {e}"));
    eprintln!(
        "{name}: {} polygons, {:?}, oracle {:?}",
        polys.len(),
        checked.stats,
        checked.flags
    );
    MeshRun {
        polys,
        lights,
        checked,
    }
}

#[test]
fn teapot_open_soup() {
    let run = check_mesh(
        "teapot.obj",
        |_| true,
        &[
            // above and beside the spout, inside the body, and a sun
            WorldLight::Point(DVec3::new(12.0, 11.0, 4.0)),
            WorldLight::Point(DVec3::new(0.5, 0.0, 0.25)),
            WorldLight::Sun([2, 5, 1]),
        ],
        60,
    );
    run.assert_each_light_lights_and_darkens();
    let c = &run.checked;
    assert!(c.flags.cast > 0 && c.flags.lit > 0, "{:?}", c.flags);
}

#[test]
fn bunny_closed_mesh() {
    let run = check_mesh(
        "bunny.obj",
        |_| true,
        &[
            // above and behind, inside the body, and a sun
            WorldLight::Point(DVec3::new(-3.0, 12.0, -2.0)),
            WorldLight::Point(DVec3::new(-0.5, 3.0, 0.5)),
            WorldLight::Sun([-1, 3, 2]),
        ],
        40,
    );
    let c = &run.checked;
    // the second light is inside the closed surface (as the solid tree
    // says): it reaches no face's outer side
    let solid = BspTree::build(run.polys.clone(), &BuildOptions::default());
    let Light::Point(inside) = run.lights[1] else {
        unreachable!()
    };
    assert_eq!(
        solid.classify_point(&Point::Grid(inside)),
        Membership::Inside
    );
    assert!(c.frags.iter().all(|f| !f.lit()[1]));
    for j in [0, 2] {
        let (lit, dark) = c.count(j);
        assert!(lit > 0 && dark > 0, "light {j}: {lit} lit, {dark} dark");
    }
    assert!(c.flags.cast > 0 && c.flags.lit > 0, "{:?}", c.flags);
}

#[test]
fn bunny_front_half_open_shell() {
    // the front half of the bunny (z > 0): the cut leaves an open shell
    // whose inside a light behind it sees
    let run = check_mesh(
        "bunny.obj",
        |l| l.iter().all(|p| p.z > 0.0),
        &[WorldLight::Point(DVec3::new(-1.0, 4.0, -3.0))],
        60,
    );
    let (lit, dark) = run.checked.count(0);
    assert!(lit > 0 && dark > 0, "{lit} lit, {dark} dark");
}

#[test]
fn teapot_double_sided() {
    // every face and its reverse, as double-sided walls are modelled: of
    // each pair, the face turned away from a light goes into its tree
    // after the skeleton is made, in the plane of its twin's cap
    let loops: Vec<Vec<DVec3>> = mesh_loops("teapot.obj")
        .into_iter()
        .flat_map(|l| {
            let back: Vec<DVec3> = l.iter().rev().copied().collect();
            [l, back]
        })
        .collect();
    let run = check_loops(
        "teapot.obj, double-sided",
        loops,
        &[
            WorldLight::Point(DVec3::new(12.0, 11.0, 4.0)),
            WorldLight::Sun([2, 5, 1]),
        ],
        60,
    );
    run.assert_each_light_lights_and_darkens();
}

#[test]
fn terrain_half_flipped() {
    // the bench's terrain (a height field with boxes on it) with its
    // faces turned up or down at random: the faces turned away from the
    // light are about as many as those facing it and mostly not hidden,
    // so a region soon stops sending them whole to its leaves and cuts
    // them like the others
    let mut rng = bsp_fixtures::Rng::new(0x9e37_79b9_7f4a_7c15);
    let loops: Vec<Vec<DVec3>> = bsp_fixtures::scenes::terrain(4000)
        .faces
        .into_iter()
        .map(|mut f| {
            if rng.next_u64() >> 63 == 1 {
                f.reverse();
            }
            f
        })
        .collect();
    let run = check_loops(
        "terrain, half flipped",
        loops,
        &[
            WorldLight::Point(DVec3::new(-14.0, 9.0, 7.0)),
            WorldLight::Sun([3, -2, 1]),
        ],
        24,
    );
    run.assert_each_light_lights_and_darkens();
    let c = &run.checked;
    assert!(c.flags.cast > 0 && c.flags.lit > 0, "{:?}", c.flags);
}

/// Real meshes under lights placed at random: one anywhere in (or about)
/// the mesh's box, one exactly at a vertex of the mesh (on the planes of
/// every face around it), and a sun along a small integer direction;
/// every flag checked by the ray oracle. The default draws one set for
/// the teapot; a hunt (`SVBSP_SEED`) draws others for every mesh here.
#[test]
fn real_meshes_under_random_lights() {
    let meshes: &[&str] = match hunt() {
        None => &["teapot.obj"],
        Some(_) => &[
            "teapot.obj",
            "bunny.obj",
            "pyvista_ant.obj",
            "pyvista_nut.obj",
        ],
    };
    let mut rng = rng(0x7ea_9075);
    let mut unit = || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
    for name in meshes {
        let loops = mesh_loops(name);
        let pts: Vec<DVec3> = loops.iter().flatten().copied().collect();
        let (lo, hi) = pts
            .iter()
            .fold((pts[0], pts[0]), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        let (mid, half) = ((lo + hi) / 2.0, (hi - lo) * 0.75);
        let anywhere =
            mid + DVec3::new(2.0 * unit() - 1.0, 2.0 * unit() - 1.0, 2.0 * unit() - 1.0) * half;
        let vertex = pts[(unit() * pts.len() as f64) as usize % pts.len()];
        let mut small = || (unit() * 7.0) as i32 - 3;
        let mut sun = [small(), small(), small()];
        if sun == [0, 0, 0] {
            sun = [1, 2, 3];
        }
        let world = [
            WorldLight::Point(anywhere),
            WorldLight::Point(vertex),
            WorldLight::Sun(sun),
        ];
        // (the oracle's disagreements panic inside)
        check_loops(name, loops, &world, 24);
    }
}
