//! The engine's unit tests.

use super::*;

fn quad(z: i32, lo: i32, hi: i32, tag: u32) -> Polygon {
    Polygon::from_grid_points(&[[lo, lo, z], [hi, lo, z], [hi, hi, z], [lo, hi, z]], tag).unwrap()
}

fn ring_coords(b: &Batch, ring: &[u32]) -> Vec<[f64; 3]> {
    let mut v: Vec<[f64; 3]> = ring.iter().map(|&i| b.rounded(i)).collect();
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v
}

#[test]
fn occluder_casts_an_exact_square_hole() {
    // floor 0..8 at z = 0, occluder 2..4 at z = 4, light above at z = 8
    let polys = [quad(0, 0, 8, 0), quad(4, 2, 4, 1)];
    let (b, stats) = shadow_fragments(&polys, &[Light::Point([3, 3, 8])]).unwrap();
    // the floor: one lit ring with a hole, one shadowed square; the
    // occluder: lit, whole
    assert_eq!((b.len(), stats.fragments), (3, 3));
    let floor: Vec<_> = b.fragments().filter(|f| f.face() == 0).collect();
    let lit = floor.iter().find(|f| f.lit(0)).unwrap();
    let dark = floor.iter().find(|f| !f.lit(0)).unwrap();
    assert_eq!(lit.hole_count(), 1);
    assert_eq!(dark.hole_count(), 0);
    // the shadow of [2,4]^2 at height 4 from (3,3,8) on z = 0 is [1,5]^2
    let sq = vec![
        [1.0, 1.0, 0.0],
        [1.0, 5.0, 0.0],
        [5.0, 1.0, 0.0],
        [5.0, 5.0, 0.0],
    ];
    assert_eq!(ring_coords(&b, dark.outer()), sq);
    assert_eq!(ring_coords(&b, lit.rings().nth(1).unwrap()), sq);
    let occ: Vec<_> = b.fragments().filter(|f| f.face() == 1).collect();
    assert_eq!(occ.len(), 1);
    assert!(occ[0].lit(0));
    assert_eq!(occ[0].outer().len(), 4);
}

#[test]
fn sun_and_back_faces() {
    let floor = quad(0, 0, 8, 0);
    let occ = quad(4, 2, 4, 1).flipped(); // faces down, still blocks
    let polys = [floor, occ];
    let (b, _) = shadow_fragments(
        &polys,
        &[Light::Directional([0, 0, 1]), Light::Point([3, 3, -8])],
    )
    .unwrap();
    let dark: Vec<_> = b
        .fragments()
        .filter(|f| f.face() == 0 && !f.lit(0))
        .collect();
    assert_eq!(dark.len(), 1);
    assert_eq!(
        ring_coords(&b, dark[0].outer()),
        vec![
            [2.0, 2.0, 0.0],
            [2.0, 4.0, 0.0],
            [4.0, 2.0, 0.0],
            [4.0, 4.0, 0.0]
        ]
    );
    // the occluder faces away from the sun and the light below is
    // blocked by the floor
    assert!(
        b.fragments()
            .filter(|f| f.face() == 1)
            .all(|f| !f.lit(0) && !f.lit(1))
    );
    // the floor faces up: the light below leaves it in attached shadow
    assert!(b.fragments().filter(|f| f.face() == 0).all(|f| !f.lit(1)));
    assert!(
        b.fragments()
            .filter(|f| f.face() == 0)
            .all(|f| f.facing_mask() == 1)
    );
}

#[test]
fn uniform_faces_stay_whole_and_pieces_cover_fragments() {
    let polys = [quad(0, 0, 8, 0), quad(4, 2, 4, 1), quad(6, -20, -10, 2)];
    let (b, _) = shadow_fragments(&polys, &[Light::Point([3, 3, 8])]).unwrap();
    let far: Vec<_> = b.fragments().filter(|f| f.face() == 2).collect();
    assert_eq!(far.len(), 1);
    for f in b.fragments() {
        assert!(f.pieces().count() >= 1);
    }
}

/// A floor, a square over it and a square far away, and the volumes of
/// two point lights above.
fn floor_square_far_two_lights() -> ([Polygon; 3], LightVolumes) {
    let polys = [quad(0, 0, 8, 0), quad(4, 2, 4, 1), quad(6, -20, -10, 2)];
    let lights = [Light::Point([3, 3, 8]), Light::Point([6, 1, 9])];
    let shadows = LightVolumes::new(&polys, &lights).unwrap();
    (polys, shadows)
}

/// With `planes`, each piece's edge planes make it again (the same
/// corners, in turn, as the support plane's meets with them), for
/// pieces that stayed whole and pieces of merged regions alike; and
/// appending batches keeps them. Without, there are none.
#[test]
fn piece_planes_make_the_pieces_again() {
    let (polys, shadows) = floor_square_far_two_lights();
    let opts = ShadeOptions::default().with_planes(true);
    let whole = shadows.set().shade_all(&polys, &opts);
    let mut b = Batch::new();
    b.append_range(&whole, 0..1);
    b.append_range(&whole, 1..whole.len());
    let mut pieces = 0;
    for f in b.fragments() {
        let planes: Vec<&[Plane]> = f.piece_planes().unwrap().collect();
        for (corners, planes) in f.pieces().zip(planes) {
            let p = Polygon::from_planes(*f.support(), planes, 0).unwrap();
            let made: Vec<[f64; 3]> = p.vertices_f64();
            let kept: Vec<[f64; 3]> = corners.iter().map(|&v| b.rounded(v)).collect();
            assert_eq!(made, kept);
            // turned as the engine's pieces are: inside behind each plane
            assert!(crate::FaceOverlay::new(*f.support(), [(planes, 0)]).is_some());
            pieces += 1;
        }
    }
    assert!(pieces > b.len(), "some fragment of several pieces");
    let plain = shadows.set().shade_all(&polys, &ShadeOptions::default());
    assert!(plain.fragments().all(|f| f.piece_planes().is_none()));
    let mut mixed = whole.clone();
    mixed.append(&plain);
    assert!(mixed.fragments().all(|f| f.piece_planes().is_none()));
}

/// Without [`ShadeOptions::merge`] each piece is a fragment of its own:
/// the same pieces with the same flags, corners and planes, each
/// fragment's ring its piece; a face whole stays one fragment.
#[test]
fn unmerged_fragments_are_the_pieces() {
    let (polys, shadows) = floor_square_far_two_lights();
    let opts = ShadeOptions::default().with_planes(true);
    let merged = shadows.set().shade_all(&polys, &opts);
    let apart = shadows
        .set()
        .shade_all(&polys, &opts.clone().with_merge(false));
    // (the floor is cut, in more pieces than regions)
    assert!(apart.len() > merged.len());
    type Piece = (u32, u64, Vec<[f64; 3]>, Vec<Plane>);
    let pieces = |b: &Batch| -> Vec<Piece> {
        let mut out = Vec::new();
        for f in b.fragments() {
            for (corners, planes) in f.pieces().zip(f.piece_planes().unwrap()) {
                let corners = corners.iter().map(|&v| b.rounded(v)).collect();
                out.push((f.face(), f.lit_mask(), corners, planes.to_vec()));
            }
        }
        out.sort_by(|a, b| (a.0, a.1, &a.2).partial_cmp(&(b.0, b.1, &b.2)).unwrap());
        out
    };
    assert_eq!(pieces(&merged), pieces(&apart));
    for f in apart.fragments() {
        assert_eq!(f.rings().count(), 1);
        assert_eq!(f.pieces().count(), 1);
        assert_eq!(f.outer(), f.pieces().next().unwrap());
    }
    assert_eq!(apart.fragments().filter(|f| f.face() == 2).count(), 1);
}

/// Without [`ShadeOptions::vertices`] a batch keeps no exact vertex, and
/// everything else the same: the fragments, their rings' vertex numbers,
/// the roundings; `Batch::concat` of its parts is its `append`s'.
#[test]
fn rounding_only_batches_drop_nothing_else() {
    let polys = [quad(0, 0, 8, 0), quad(4, 2, 4, 1), quad(6, 1, 3, 2)];
    let lights = [Light::Point([3, 3, 8]), Light::Point([6, 1, 9])];
    let shadows = LightVolumes::new(&polys, &lights).unwrap();
    let exact = shadows.set().shade_all(&polys, &ShadeOptions::default());
    let opts = ShadeOptions::default().with_vertices(false);
    let rounded = shadows.set().shade_all(&polys, &opts);
    assert!(exact.vertex_count() > 0);
    assert!((0..exact.vertex_count() as u32).all(|v| exact.vertex(v).is_some()));
    assert!(rounded.vertex(0).is_none());
    assert_eq!(exact.len(), rounded.len());
    assert_eq!(exact.vertex_count(), rounded.vertex_count());
    for (a, b) in exact.fragments().zip(rounded.fragments()) {
        assert_eq!((a.face(), a.lit_mask()), (b.face(), b.lit_mask()));
        let (ra, rb): (Vec<&[u32]>, Vec<&[u32]>) = (a.rings().collect(), b.rings().collect());
        assert_eq!(ra, rb);
    }
    for v in 0..exact.vertex_count() as u32 {
        assert_eq!(exact.rounded(v), rounded.rounded(v));
    }
    // joined in one go or batch by batch: the same lists
    let parts = [&exact, &rounded, &exact];
    let joined = Batch::concat(&parts);
    let mut appended = Batch::new();
    for b in parts {
        appended.append(b);
    }
    assert_eq!(joined.len(), 3 * exact.len());
    assert_eq!(format!("{joined:?}"), format!("{appended:?}"));
}

/// The trees built while the parts are certified (over the faces each
/// light faces and those of open parts, kept where the certified parts
/// leave out every other face) are the trees built after certifying:
/// where the guess holds (closed boxes lit from outside, an open floor
/// facing the lights, an open face turned away) and where it does not (a
/// light inside a box, with and without the open faces).
#[test]
fn trees_built_while_certifying_are_those_built_after() {
    let poly = |l: &Vec<[i32; 3]>, tag: u32| Polygon::from_grid_points(l, tag).unwrap();
    let mut closed: Vec<Polygon> = bsp_fixtures::grid_cuboid([2, 2, 2], [5, 5, 5])
        .iter()
        .chain(&bsp_fixtures::grid_cuboid([6, 1, 1], [7, 3, 4]))
        .enumerate()
        .map(|(i, l)| poly(l, i as u32))
        .collect();
    closed.push(quad(0, -4, 12, 12));
    let mut open = closed.clone();
    open.push(quad(9, 0, 3, 13).flipped()); // faces down, away from lights above
    let above = [
        Light::Point([3, 4, 20]),
        Light::Point([10, 9, 14]),
        Light::Directional([1, 2, 5]),
    ];
    let inside = [Light::Point([3, 3, 3]), Light::Directional([-1, 2, 7])];
    let solids_of = |p: &[Polygon]| bsp_core::certify_solid_parts(p);
    // whether the guess holds for a light: every face it does not face
    // is in an open part or left out
    let holds = |p: &[Polygon], l: &Light| {
        let (s, paired) = (solids_of(p), bsp_core::pair_solid_parts(p));
        (0..p.len()).all(|i| {
            l.faces(p[i].support()) || paired.open(i) || l.leaves_out(&s, i, p[i].support())
        })
    };
    assert!(holds(&closed, &above[0]) && holds(&closed, &above[1]));
    assert!(holds(&open, &above[0]) && holds(&open, &above[2]));
    assert!(!holds(&closed, &inside[0]) && !holds(&open, &inside[0]));
    for (polys, lights) in [
        (&closed, &above[..]),
        (&open, &above[..]),
        (&closed, &inside[..]),
        (&open, &inside[..]),
    ] {
        let solids = solids_of(polys);
        let order: Vec<usize> = (0..polys.len()).collect();
        let pairs = [
            (
                LightVolumes::new(polys, lights).unwrap(),
                LightVolumes::new_with(polys, lights, &solids).unwrap(),
            ),
            (
                LightVolumes::new_reaching(polys, lights).unwrap(),
                LightVolumes::new_ordered_reaching(polys, &order, lights, &solids).unwrap(),
            ),
        ];
        for (a, b) in pairs {
            assert_eq!(a.reached, b.reached);
            for (ta, tb) in a.volumes().iter().zip(b.volumes()) {
                assert_eq!(ta.node_count(), tb.node_count());
                assert_eq!(ta.occluder_count(), tb.occluder_count());
                for x in -4..=12 {
                    for y in -4..=12 {
                        for z in -1..=10 {
                            assert_eq!(ta.hides([x, y, z]), tb.hides([x, y, z]));
                        }
                    }
                }
            }
        }
    }
}

/// A ground (polygon 0) under a grid of 12 × 12 small roofs.
fn ground_under_roofs() -> Vec<Polygon> {
    let mut polys = vec![quad(0, -40, 104, 0)];
    for i in 0..12 {
        for j in 0..12 {
            let (x, y) = (i * 6, j * 6);
            let roof = [[x, y, 5], [x + 3, y, 5], [x + 3, y + 2, 5], [x, y + 2, 5]];
            polys.push(Polygon::from_grid_points(&roof, (1 + i * 12 + j) as u32).unwrap());
        }
    }
    polys
}

/// A ground under a grid of small roofs, lit by three lights: cut by the
/// first into more cells than [`passes::PARALLEL_CELLS`], its cells go
/// through the other two trees in parallel runs
/// ([`passes::pass_runs`]) and come out as the one-by-one passes make
/// them: the same cells in the same order, the same exact corners, the
/// same flags, on one thread and on three.
#[test]
fn a_large_face_passes_its_cells_in_runs_as_one_by_one() {
    let polys = ground_under_roofs();
    let lights = [
        Light::Point([31, 29, 40]),
        Light::Point([50, 10, 33]),
        Light::Directional([2, -1, 9]),
    ];
    let shadows = LightVolumes::new(&polys, &lights).unwrap();
    let set = shadows.set();
    let ground = &polys[..1];
    let first = |s: &mut Scratch| {
        set.filter_lights_of(ground, &Start::Uniform(0b111), s, 0b001);
    };
    let rest: Vec<_> = set.trees[1..].to_vec();
    let corners = |s: &Scratch| -> Vec<(Vec<Vertex>, u64)> {
        (s.cur.iter())
            .map(|(p, f)| {
                let v = p
                    .verts
                    .iter()
                    .map(|&v| s.arena.vertex(v).to_owned())
                    .collect();
                (v, *f)
            })
            .collect()
    };
    let mut one = Scratch::default();
    first(&mut one);
    assert!(
        one.cur.len() >= crate::schedule::PARALLEL_CELLS,
        "{} cells",
        one.cur.len()
    );
    let changed_one = rest
        .iter()
        .fold(false, |c, &t| passes::pass(&mut one, t, None) | c);
    let expected = corners(&one);
    for threads in [1, 3] {
        let mut runs = Scratch::default();
        let changed = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                first(&mut runs);
                passes::pass_runs(&mut runs, &rest, None)
            });
        assert_eq!(changed, changed_one);
        let got = corners(&runs);
        assert_eq!(got.len(), expected.len());
        for ((a, fa), (b, fb)) in got.iter().zip(&expected) {
            assert_eq!(fa, fb);
            assert_eq!(a.len(), b.len());
            assert!(a.iter().zip(b).all(|(x, y)| x.same_point(y)));
        }
        // the renumbered cells keep their planes: each edge's plane holds
        // both of its corners
        for (p, _) in &runs.cur {
            let k = p.verts.len();
            for i in 0..k {
                let e = runs.arena.plane(p.edges[i]);
                for v in [p.verts[i], p.verts[(i + 1) % k]] {
                    assert_eq!(runs.arena.vertex(v).classify(&e), Side::On);
                }
            }
        }
    }
}

/// A build whose stop is raised gives up (`None`), and one whose stop
/// stays down is the build without one.
#[test]
fn a_stopped_build_gives_up() {
    use crate::psv::Stop;
    let polys = [quad(0, 0, 8, 0), quad(4, 2, 4, 1)];
    let light = Light::Point([3, 3, 8]);
    let up = Stop::new(true);
    assert!(
        ShadowVolumes::build_until(light, &polys, Some(&up))
            .unwrap()
            .is_none()
    );
    let index = [0, 1];
    let stopped = ShadowVolumes::build_reached_among_until(light, &polys, &index, Some(&up));
    assert!(stopped.unwrap().is_none());
    let down = Stop::new(false);
    let (v, reached) = ShadowVolumes::build_reached_among_until(light, &polys, &index, Some(&down))
        .unwrap()
        .expect("not stopped");
    let (w, reached_w) = ShadowVolumes::build_reached_among(light, &polys, &index).unwrap();
    assert_eq!((v.node_count(), reached), (w.node_count(), reached_w));
}

/// The pairing of the certificate's first step finds the open parts:
/// an open floor and a box with a face missing, not a closed box.
#[test]
fn the_pairing_finds_open_parts() {
    let poly = |l: &Vec<[i32; 3]>| Polygon::from_grid_points(l, 0).unwrap();
    let closed: Vec<Polygon> = bsp_fixtures::grid_cuboid([2, 2, 2], [5, 5, 5])
        .iter()
        .map(poly)
        .collect();
    let holed: Vec<Polygon> = bsp_fixtures::grid_cuboid([7, 2, 2], [9, 5, 5])
        .iter()
        .skip(1)
        .map(poly)
        .collect();
    let mut scene = closed.clone();
    scene.extend(holed.iter().cloned());
    scene.push(quad(0, -4, 12, 0));
    let paired = bsp_core::pair_solid_parts(&scene);
    let open: Vec<bool> = (0..scene.len()).map(|i| paired.open(i)).collect();
    assert!(open[..6].iter().all(|o| !o));
    assert!(open[6..].iter().all(|&o| o));
    assert_eq!(paired.certify(), bsp_core::certify_solid_parts(&scene));
}

/// An area light's corner cells, settling (`ShadowSet::cells_known`):
/// a cell that sees one corner and not another goes through no more
/// trees, so a ground under a grid of roofs comes out in fewer cells, and
/// every grid point strictly inside a cell of both sees every corner,
/// none or some alike (exact sides of the cells' edge planes).
#[test]
fn settled_corner_cells_cover_what_the_full_cells_do() {
    let polys = ground_under_roofs();
    // the corners of a small square light above the roofs
    let lights = [
        Light::Point([30, 30, 40]),
        Light::Point([34, 30, 40]),
        Light::Point([34, 34, 40]),
        Light::Point([30, 34, 40]),
    ];
    let shadows = LightVolumes::new(&polys, &lights).unwrap();
    let set = shadows.set();
    // per grid point of the ground strictly inside a cell: whether the
    // cell sees every corner (0), none (1) or some (2); exact sides
    let inside = polys[0].edge_planes()[0].classify_grid([104, 104, 0]);
    let by_point = |cells: &[(Polygon, u64)]| {
        let mut class = std::collections::BTreeMap::new();
        for (p, flags) in cells {
            let v = p.vertices_f64();
            let lo = [0, 1].map(|k| v.iter().map(|c| c[k]).fold(f64::INFINITY, f64::min));
            let hi = [0, 1].map(|k| v.iter().map(|c| c[k]).fold(f64::NEG_INFINITY, f64::max));
            for x in (lo[0].floor() as i32)..=(hi[0].ceil() as i32) {
                for y in (lo[1].floor() as i32)..=(hi[1].ceil() as i32) {
                    let g = [x, y, 0];
                    if p.edge_planes().iter().all(|e| e.classify_grid(g) == inside) {
                        let c = match flags & 0b1111 {
                            0b1111 => 0,
                            0 => 1,
                            _ => 2,
                        };
                        assert!(class.insert(g, c).is_none(), "{g:?} in two cells");
                    }
                }
            }
        }
        class
    };
    let full = set.cells_known(
        &polys[0],
        (None, polys.len()),
        false,
        &mut Scratch::default(),
    );
    let settled = set.cells_known(
        &polys[0],
        (None, polys.len()),
        true,
        &mut Scratch::default(),
    );
    let (full, settled) = (full.unwrap(), settled.unwrap());
    assert!(
        settled.len() < full.len(),
        "{} against {}",
        settled.len(),
        full.len()
    );
    let (a, b) = (by_point(&full), by_point(&settled));
    let some = a.values().filter(|&&c| c == 2).count();
    assert!(some > 100, "some ground sees some corners: {some} points");
    let common: Vec<_> = a.iter().filter(|(g, _)| b.contains_key(*g)).collect();
    assert!(
        common.len() > a.len() / 2,
        "{} of {}",
        common.len(),
        a.len()
    );
    for (g, c) in common {
        assert_eq!(b[g], *c, "at {g:?}");
    }
}
