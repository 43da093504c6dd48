//! BSP trees: painter's order against exact ray casting, the traversal
//! variants against each other, solid membership against ray parity, and
//! `sanity_check` on every tree built.

use std::collections::HashMap;

use bsp_core::internals::merge_smaller_into_larger;
use bsp_core::{
    BspTree, BuildOptions, FlatBsp, GridPoint, MAX_COORD, Membership, Order, Overlay, Partition,
    Plane, Point, Polygon, RECURSION_LIMIT, Side, ViewPoint,
};
use num_traits::One;
use proptest::collection::vec;
use proptest::prelude::*;

use crate::oracle::{HPoint, OPlane, Q, Q3, Ray, Solid, point_q};
use crate::strategies::{
    Rng, SolidCase, box_point, eye, make_eye, options, options_with_cuts, scene, solid, wide,
};

/// The fragments of a tree, indexed in `tree.polygons()` order, with what
/// the oracle needs: exact vertices and the plane of the input face.
pub(crate) struct Frags<'a> {
    pub(crate) list: Vec<&'a Polygon>,
    index: HashMap<*const Polygon, usize>,
    verts: Vec<Vec<HPoint>>,
    planes: Vec<OPlane>,
}

/// The oracle's plane of an input loop (its first non-collinear triple).
pub(crate) fn loop_plane(l: &[GridPoint]) -> OPlane {
    for i in 1..l.len() {
        for j in i + 1..l.len() {
            if let Some(p) = OPlane::through_grid(l[0], l[i], l[j]) {
                return p;
            }
        }
    }
    panic!("a loop that became a polygon has a plane");
}

impl<'a> Frags<'a> {
    /// `input[tag]` is the grid loop that polygon `tag` came from.
    pub(crate) fn new(tree: &'a BspTree, input: &[Vec<GridPoint>]) -> Frags<'a> {
        let list: Vec<&Polygon> = tree.polygons().collect();
        let index = list
            .iter()
            .enumerate()
            .map(|(i, p)| (*p as *const Polygon, i))
            .collect();
        let verts = list
            .iter()
            .map(|p| p.vertices().iter().map(HPoint::of).collect())
            .collect();
        let planes = list
            .iter()
            .map(|p| loop_plane(&input[p.tag() as usize]))
            .collect();
        Frags {
            list,
            index,
            verts,
            planes,
        }
    }

    fn sequence(&self, visit: impl FnOnce(&mut dyn FnMut(&Polygon))) -> Vec<usize> {
        let mut seq = Vec::with_capacity(self.list.len());
        visit(&mut |p: &Polygon| seq.push(self.index[&(p as *const Polygon)]));
        seq
    }

    /// The exact hit parameters of a ray on every fragment.
    fn hits(&self, ray: &Ray) -> Vec<Option<Q>> {
        self.verts
            .iter()
            .zip(&self.planes)
            .map(|(v, pl)| ray.hit(v, pl))
            .collect()
    }
}

fn same_polygon(a: &Polygon, b: &Polygon) -> bool {
    a.tag() == b.tag()
        && a.support() == b.support()
        && a.edge_planes() == b.edge_planes()
        && a.len() == b.len()
        && a.vertices()
            .iter()
            .zip(b.vertices())
            .all(|(x, y)| x.same_point(y))
}

/// `traverse`, `traverse_recursive` and `FlatBsp::traverse` give the same
/// sequence, a permutation of all fragments; returns it.
pub(crate) fn check_traversals(
    tree: &BspTree,
    flat: &FlatBsp,
    frags: &Frags<'_>,
    eye: ViewPoint,
    order: Order,
) -> Result<Vec<usize>, TestCaseError> {
    let a = frags.sequence(|f| tree.traverse(eye, order, f));
    let b = frags.sequence(|f| tree.traverse_recursive(eye, order, f));
    prop_assert_eq!(&a, &b, "traverse and traverse_recursive differ");
    let mut sorted = a.clone();
    sorted.sort_unstable();
    prop_assert!(
        sorted.iter().copied().eq(0..frags.list.len()),
        "not a permutation"
    );
    let mut flat_seq = Vec::with_capacity(a.len());
    flat.traverse(eye, order, |p| flat_seq.push(p.clone()));
    prop_assert_eq!(flat_seq.len(), a.len());
    for (i, (p, &j)) in flat_seq.iter().zip(&a).enumerate() {
        prop_assert!(
            same_polygon(p, frags.list[j]),
            "FlatBsp differs at position {}",
            i
        );
    }
    Ok(a)
}

fn centroid(v: &[Q3], weights: &[u64]) -> Q3 {
    let total: u64 = weights.iter().sum();
    let mut s = [
        Q::from_integer(0.into()),
        Q::from_integer(0.into()),
        Q::from_integer(0.into()),
    ];
    for (p, &w) in v.iter().zip(weights) {
        let w = Q::from_integer(w.into());
        for k in 0..3 {
            s[k] += &p[k] * &w;
        }
    }
    let t = Q::from_integer(total.into());
    s.map(|c| c / &t)
}

/// Painter's order checked by exact ray casting: rays from the eye through
/// interior points of sampled fragments; along each ray, a fragment drawn
/// later (back-to-front) is never behind one drawn earlier. Returns the
/// number of rays that crossed two or more fragments.
pub(crate) fn check_painter(
    frags: &Frags<'_>,
    eye: [i64; 3],
    back_to_front: &[usize],
    front_to_back: &[usize],
    rays: usize,
    rng: &mut Rng,
) -> Result<usize, TestCaseError> {
    let mut occluding = 0;
    let eye_z = eye.map(num_bigint::BigInt::from);
    for r in 0..rays {
        let j = rng.below(frags.list.len());
        let v: Vec<Q3> = frags.list[j].vertices().iter().map(point_q).collect();
        let w: Vec<u64> = if r % 2 == 0 {
            vec![1; v.len()]
        } else {
            v.iter().map(|_| 1 + rng.below(5) as u64).collect()
        };
        let s = HPoint::from_q(&centroid(&v, &w));
        let Some(ray) = Ray::through(eye, &s) else {
            continue;
        };
        let hits = frags.hits(&ray);
        // the ray crosses its own fragment at t = 1 unless it runs in its plane
        let eye_on = frags.planes[j].eval_h(&eye_z, &num_bigint::BigInt::one()) == 0.into();
        prop_assert_eq!(hits[j].is_some(), !eye_on, "ray through fragment {}", j);
        if let Some(t) = &hits[j] {
            prop_assert!(t.is_one());
        }
        if hits.iter().filter(|h| h.is_some()).count() >= 2 {
            occluding += 1;
        }
        for (seq, name) in [
            (back_to_front, "BackToFront"),
            (front_to_back, "FrontToBack"),
        ] {
            let ts: Vec<(usize, &Q)> = seq
                .iter()
                .filter_map(|&i| hits[i].as_ref().map(|t| (i, t)))
                .collect();
            for w in ts.windows(2) {
                let ((a, ta), (b, tb)) = (w[0], w[1]);
                let ok = if name == "BackToFront" {
                    ta >= tb
                } else {
                    ta <= tb
                };
                prop_assert!(
                    ok,
                    "{}: fragment {} (t = {}) drawn before fragment {} (t = {}), eye {:?}",
                    name,
                    a,
                    ta,
                    b,
                    tb,
                    eye
                );
            }
        }
    }
    Ok(occluding)
}

/// Builds a tree over `input` (faces that are not convex polygons are
/// skipped), checks it, and runs the traversal and painter's checks for
/// every eye.
pub(crate) fn check_scene(
    input: &[Vec<GridPoint>],
    opts: &BuildOptions,
    eyes: &[[i64; 3]],
    rays: usize,
    rng: &mut Rng,
) -> Result<usize, TestCaseError> {
    let polys: Vec<Polygon> = input
        .iter()
        .enumerate()
        .filter_map(|(i, l)| Polygon::from_grid_points(l, i as u32).ok())
        .collect();
    let count = polys.len();
    let tree = BspTree::build(polys, opts);
    check_tree(&tree, input, count, eyes, rays, rng)
}

/// Checks a tree over the faces of `input` (tagged with their index;
/// `count` of them made it in): invariants, figures, traversals and the
/// painter's order from every eye.
pub(crate) fn check_tree(
    tree: &BspTree,
    input: &[Vec<GridPoint>],
    count: usize,
    eyes: &[[i64; 3]],
    rays: usize,
    rng: &mut Rng,
) -> Result<usize, TestCaseError> {
    if let Err(e) = tree.sanity_check() {
        return Err(TestCaseError::fail(format!("sanity_check: {e}")));
    }
    let stats = tree.stats();
    prop_assert_eq!(stats.polygons, tree.polygons().count());
    prop_assert_eq!(stats.nodes, tree.nodes().len());
    prop_assert_eq!(
        stats.in_cells + stats.out_cells,
        stats.nodes + 1,
        "leaves of a binary tree"
    );
    prop_assert!(stats.depth <= stats.nodes);
    prop_assert!(stats.polygons >= count);
    let flat = FlatBsp::new(tree);
    prop_assert_eq!(flat.len(), tree.nodes().len());
    prop_assert_eq!(flat.polygons().len(), stats.polygons);
    let frags = Frags::new(tree, input);
    let mut occluding = 0;
    for &e in eyes {
        let vp = ViewPoint::new(e).expect("viewpoint within range");
        let b2f = check_traversals(tree, &flat, &frags, vp, Order::BackToFront)?;
        let f2b = check_traversals(tree, &flat, &frags, vp, Order::FrontToBack)?;
        if !frags.list.is_empty() {
            occluding += check_painter(&frags, e, &b2f, &f2b, rays, rng)?;
        }
    }
    Ok(occluding)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    /// Random soups (intersecting, coplanar, edge-sharing, stacked) seen
    /// from random, far-away and on-plane eyes.
    #[test]
    fn painter_order_matches_exact_ray_casting(
        input in scene(),
        opts in options(),
        eyes in vec(eye(), 1..4),
        seed in any::<u64>(),
    ) {
        let eyes: Vec<[i64; 3]> = eyes.iter().map(|e| make_eye(e, &input)).collect();
        check_scene(&input, &opts, &eyes, 10, &mut Rng(seed))?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// The same with balance cuts (axis-aligned cuts that are not polygon
    /// planes), from the smallest cut threshold up.
    #[test]
    fn painter_order_with_balance_cuts(
        input in scene(),
        opts in options_with_cuts(),
        eyes in vec(eye(), 1..4),
        seed in any::<u64>(),
    ) {
        let eyes: Vec<[i64; 3]> = eyes.iter().map(|e| make_eye(e, &input)).collect();
        check_scene(&input, &opts, &eyes, 10, &mut Rng(seed))?;
    }
}

fn input_polygons(input: &[Vec<GridPoint>]) -> Vec<Polygon> {
    input
        .iter()
        .enumerate()
        .filter_map(|(i, l)| Polygon::from_grid_points(l, i as u32).ok())
        .collect()
}

fn same_tree(a: &BspTree, b: &BspTree) -> bool {
    a.root() == b.root()
        && a.nodes().len() == b.nodes().len()
        && a.nodes().iter().zip(b.nodes()).all(|(x, y)| {
            x.plane == y.plane
                && x.front == y.front
                && x.back == y.back
                && x.polygons.len() == y.polygons.len()
                && x.polygons
                    .iter()
                    .zip(&y.polygons)
                    .all(|(p, q)| same_polygon(p, q))
        })
}

/// The same links, and the same tags in every node.
fn same_shape(a: &BspTree, b: &BspTree) -> bool {
    let tags = |n: &bsp_core::Node| n.polygons.iter().map(|p| p.tag()).collect::<Vec<_>>();
    a.root() == b.root()
        && a.nodes().len() == b.nodes().len()
        && a.nodes()
            .iter()
            .zip(b.nodes())
            .all(|(x, y)| x.front == y.front && x.back == y.back && tags(x) == tags(y))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// A tree's choices replayed on its own polygons give the same tree,
    /// and on a copy moved by a grid vector (where every classification is
    /// the same) a tree of the same shape; a replay on polygons moved
    /// apart is still a correct painter's tree.
    #[test]
    fn replayed_trees_keep_their_shape_and_stay_correct(
        input in scene(),
        opts in options(),
        eyes in vec(eye(), 1..3),
        seed in any::<u64>(),
        shift in prop::array::uniform3(-64i32..64),
    ) {
        let eyes: Vec<[i64; 3]> = eyes.iter().map(|e| make_eye(e, &input)).collect();
        let polys = input_polygons(&input);
        let count = polys.len();
        let tree = BspTree::build(polys.clone(), &opts);
        let again = tree.replay(polys, &opts);
        prop_assert!(same_tree(&tree, &again), "replay differs from the tree");
        let moved_by = |f: &dyn Fn(usize) -> [i32; 3]| -> Option<Vec<Vec<GridPoint>>> {
            input
                .iter()
                .enumerate()
                .map(|(i, l)| {
                    let d = f(i);
                    l.iter()
                        .map(|p| {
                            let q = [p[0] + d[0], p[1] + d[1], p[2] + d[2]];
                            q.iter().all(|c| c.abs() <= MAX_COORD).then_some(q)
                        })
                        .collect()
                })
                .collect()
        };
        if let Some(moved) = moved_by(&|_| shift) {
            let replay = tree.replay(input_polygons(&moved), &opts);
            prop_assert!(same_shape(&replay, &tree), "a moved replay has another shape");
            check_tree(&replay, &moved, count, &eyes, 6, &mut Rng(seed))?;
        }
        // every face moved its own way: the old choices may no longer fit
        let mut rng = Rng(seed);
        let offsets: Vec<[i32; 3]> = (0..input.len())
            .map(|_| [0, 1, 2].map(|_| rng.below(129) as i32 - 64))
            .collect();
        if let Some(apart) = moved_by(&|i| offsets[i]) {
            let ap = input_polygons(&apart);
            let n = ap.len();
            let replay = tree.replay(ap, &opts);
            check_tree(&replay, &apart, n, &eyes, 6, &mut rng)?;
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// The overlay "+" of two polygon trees (the core paper's
    /// `Bsp4 = Bsp2 + Bsp3`) keeps every polygon of both, and as a tree
    /// orders them correctly for every eye.
    #[test]
    fn overlay_of_polygon_trees_is_a_painters_tree(
        input in scene(),
        opts in options(),
        eyes in vec(eye(), 1..3),
        seed in any::<u64>(),
        cut in 0usize..8,
    ) {
        let eyes: Vec<[i64; 3]> = eyes.iter().map(|e| make_eye(e, &input)).collect();
        let polys = input_polygons(&input);
        let count = polys.len();
        let k = cut.min(polys.len());
        let a = BspTree::build(polys[..k].to_vec(), &opts);
        let b = BspTree::build(polys[k..].to_vec(), &opts);
        let (pa, pb) = (Partition::from_tree(&a), Partition::from_tree(&b));
        let o = merge_smaller_into_larger(&pa, &pb, &Overlay);
        if let Err(e) = o.sanity_check() {
            return Err(TestCaseError::fail(format!("overlay: sanity_check: {e}")));
        }
        let tree = o.polygon_tree(|(x, _)| x);
        let mut tags: Vec<u32> = tree.polygons().map(|p| p.tag()).collect();
        tags.sort_unstable();
        tags.dedup();
        prop_assert_eq!(tags.len(), count, "every polygon is kept");
        check_tree(&tree, &input, count, &eyes, 6, &mut Rng(seed))?;
    }
}

/// Three quads that overlap cyclically (each lies over the next when seen
/// from above): no order of the whole quads is correct, so the tree has to
/// split, and its fragments must come out in a correct order.
#[test]
fn cyclic_overlap_is_split_and_ordered() {
    // long quads along three directions 120 degrees apart, tilted so that
    // each one is high where the next one is low
    let quads: Vec<Vec<GridPoint>> = vec![
        vec![[-60, -6, 10], [60, -6, 30], [60, 6, 30], [-60, 6, 10]],
        vec![[35, -46, 10], [-25, 58, 30], [-15, 64, 30], [45, -40, 10]],
        vec![[25, 58, 10], [-35, -46, 30], [-45, -40, 30], [15, 64, 10]],
    ];
    let mut rng = Rng(7);
    let mut occluding = 0;
    for seed in 0..8 {
        let opts = BuildOptions::default().with_seed(seed);
        let eyes = [
            [0, 0, 1000],
            [3, -5, 400],
            [1 << 40, 1 << 41, 1 << 50],
            [0, 0, -1000],
        ];
        occluding += check_scene(&quads, &opts, &eyes, 24, &mut rng)
            .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        let polys: Vec<Polygon> = quads
            .iter()
            .enumerate()
            .map(|(i, q)| Polygon::from_grid_points(q, i as u32).expect("planar convex quad"))
            .collect();
        let tree = BspTree::build(polys, &opts);
        assert!(tree.stats().polygons > 3, "a cyclic overlap needs a split");
    }
    assert!(occluding > 0, "the rays must see overlaps");
}

/// Points near the special ones: the six axis neighbours.
fn neighbours(p: GridPoint) -> impl Iterator<Item = GridPoint> {
    (0..6).filter_map(move |i| {
        let mut q = wide(p);
        q[i / 2] += if i % 2 == 0 { 1 } else { -1 };
        crate::strategies::to_grid(q)
    })
}

/// Builds the solid's tree and compares `classify_point` with the
/// ray-parity oracle on the special points, their neighbours, the given
/// box points, and every fragment vertex (on the surface: `Boundary`).
pub(crate) fn check_solid(
    name: &str,
    faces: &[Vec<GridPoint>],
    special: &[GridPoint],
    fractions: &[[u16; 3]],
    opts: &BuildOptions,
) -> Result<(), TestCaseError> {
    let polys = faces
        .iter()
        .enumerate()
        .map(|(i, f)| Polygon::from_grid_points(f, i as u32))
        .collect::<Result<Vec<_>, _>>();
    let polys = match polys {
        Ok(p) => p,
        Err(e) => return Err(TestCaseError::fail(format!("{name}: face refused: {e}"))),
    };
    let oracle = Solid::new(faces);
    prop_assert_eq!(oracle.volume_sign(), 1, "{} must be outward oriented", name);
    let tree = BspTree::build(polys, opts);
    if let Err(e) = tree.sanity_check() {
        return Err(TestCaseError::fail(format!("{name}: sanity_check: {e}")));
    }
    let all: Vec<GridPoint> = faces.iter().flatten().copied().collect();
    let (lo, hi) = crate::strategies::bbox(&all);
    let mut points: Vec<GridPoint> = Vec::new();
    for &s in special {
        points.push(s);
        points.extend(neighbours(s));
    }
    points.extend(fractions.iter().map(|f| box_point(lo, hi, *f)));
    let m = MAX_COORD;
    points.extend([[m, m, m], [-m, -m, -m], [m, -m, 0], [0, m, -m]]);
    let mut seen = [0usize; 3];
    for p in points {
        let want = oracle.classify(p);
        seen[want as usize] += 1;
        let got = tree.classify_point(&Point::Grid(p));
        prop_assert_eq!(got, want, "{} at {:?}", name, p);
    }
    prop_assert!(
        seen[Membership::Boundary as usize] > 0,
        "no boundary point sampled"
    );
    for frag in tree.polygons() {
        for v in frag.vertices() {
            prop_assert_eq!(
                tree.classify_point(v),
                Membership::Boundary,
                "{}: fragment vertex {:?} is not on the boundary",
                name,
                point_q(v)
            );
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(768))]

    /// Parallelepipeds (incl. boxes), tetrahedra and non-convex height
    /// fields: membership of points on vertices, edges and faces, next to
    /// them, and random, against ray parity.
    #[test]
    fn solid_membership_matches_ray_parity(
        case in solid(),
        opts in prop_oneof![options(), options_with_cuts()],
        fractions in vec([any::<u16>(), any::<u16>(), any::<u16>()], 16..40),
    ) {
        let SolidCase { name, faces, special } = &case;
        check_solid(name, faces, special, &fractions, &opts)?;
    }
}

/// A box spanning the whole grid and a tetrahedron with vertices at the
/// grid's corners, sampled on a lattice that includes the limits.
#[test]
fn grid_limit_solids() {
    let m = MAX_COORD;
    let c = |x, y, z| [x, y, z];
    let cube = vec![
        vec![c(-m, -m, -m), c(-m, m, -m), c(m, m, -m), c(m, -m, -m)],
        vec![c(-m, -m, m), c(m, -m, m), c(m, m, m), c(-m, m, m)],
        vec![c(-m, -m, -m), c(m, -m, -m), c(m, -m, m), c(-m, -m, m)],
        vec![c(-m, m, -m), c(-m, m, m), c(m, m, m), c(m, m, -m)],
        vec![c(-m, -m, -m), c(-m, -m, m), c(-m, m, m), c(-m, m, -m)],
        vec![c(m, -m, -m), c(m, m, -m), c(m, m, m), c(m, -m, m)],
    ];
    let (a, b, cc, d) = (c(-m, -m, -m), c(m, m, -m), c(m, -m, m), c(-m, m, m));
    let tetra = vec![
        vec![a, b, cc],
        vec![a, d, b],
        vec![a, cc, d],
        vec![b, d, cc],
    ];
    let lattice = [-m, 1 - m, -1, 0, 1, m - 1, m];
    let mut special = Vec::new();
    for x in lattice {
        for y in lattice {
            for z in lattice {
                special.push(c(x, y, z));
            }
        }
    }
    for (name, faces) in [("limit cube", cube), ("limit tetrahedron", tetra)] {
        for seed in 0..3 {
            let opts = BuildOptions::default()
                .with_seed(seed)
                .with_candidates(1 + seed as usize);
            check_solid(name, &faces, &special, &[], &opts).unwrap_or_else(|e| panic!("{e}"));
        }
    }
}

/// Eyes exactly on partitioning planes, seeing polygons edge-on or
/// standing on them, in a stack of three overlapping squares.
#[test]
fn eyes_on_partition_planes() {
    let square = |z: i32, d: i32| vec![[d, d, z], [4 + d, d, z], [4 + d, 4 + d, z], [d, 4 + d, z]];
    let input = vec![square(0, 0), square(2, 1), square(4, 2)];
    let plane = Plane::through(input[0][0], input[0][1], input[0][2]).unwrap();
    let eyes = [
        [9, 9, 0],
        [2, 2, 0],
        [3, 3, 2],
        [2, 2, 1],
        [0, 0, 0],
        [-7, 1, 4],
    ];
    assert_eq!(
        plane.classify_viewpoint(ViewPoint::new(eyes[0]).unwrap()),
        Side::On
    );
    for seed in 0..4 {
        let opts = BuildOptions::default().with_seed(seed).with_candidates(1);
        let occluding = check_scene(&input, &opts, &eyes, 16, &mut Rng(seed)).unwrap();
        assert!(occluding > 0);
    }
}

/// The side faces of a convex prism over the parabola `y = x^2`: every
/// face has all others behind it, so an autopartition is a chain deeper
/// than [`RECURSION_LIMIT`] whatever the heuristic picks. The recursive
/// traversal hands over to the explicit stack and still agrees with the
/// others, and the order is right along a few rays.
#[test]
fn chain_deeper_than_the_recursion_limit() {
    let n = RECURSION_LIMIT as i32 / 2 + 40;
    let input: Vec<Vec<GridPoint>> = (-n..n)
        .map(|i| {
            let (a, b) = ([i, i * i, 0], [i + 1, (i + 1) * (i + 1), 0]);
            vec![a, b, [b[0], b[1], 1], [a[0], a[1], 1]]
        })
        .collect();
    let polys: Vec<Polygon> = input
        .iter()
        .enumerate()
        .map(|(i, l)| Polygon::from_grid_points(l, i as u32).expect("planar convex quad"))
        .collect();
    // a pure autopartition (balance cuts would make the tree shallow)
    let opts = BuildOptions::default().with_cut_threshold(0);
    let depth = BspTree::build(polys, &opts).stats().depth;
    assert!(depth > RECURSION_LIMIT, "depth {depth}");
    let eyes = [[0, -10, 0], [3, 1 << 40, 1], [n as i64 + 5, 0, 7]];
    let occluding = check_scene(&input, &opts, &eyes, 3, &mut Rng(5)).unwrap();
    assert!(occluding > 0);
}

/// Balance cuts (`BuildOptions::cut_threshold`) are documented to bound
/// the depth by about `log2(n / threshold)` plus the chains inside cells.
/// Two parallel triangles one grid step apart defeat them: every region
/// that still holds both is cut again next to the previous cut, so the
/// tree grows linearly with the triangles' extent (`L = 4096` gives about
/// `2 L` fragments and depth `L`; at the grid's full scale, a build of a
/// handful of polygons exhausts memory).
#[test]
fn regress_balance_cuts_grow_with_extent() {
    let l = 4096;
    let t = [[0, 0, 0], [l, l / 8, l / 2], [l / 4, l, l / 3]];
    let polys: Vec<Polygon> = (0..2)
        .map(|i| {
            let moved: Vec<GridPoint> = t.iter().map(|p| [p[0] + i, p[1], p[2]]).collect();
            Polygon::from_grid_points(&moved, i as u32).expect("a triangle")
        })
        .collect();
    let n = polys.len();
    let tree = BspTree::build(polys, &BuildOptions::default().with_cut_threshold(1));
    tree.sanity_check().unwrap();
    let s = tree.stats();
    assert!(
        s.depth <= 32 && s.polygons <= 32 * n,
        "{n} polygons, cut threshold 1: {s:?}"
    );
}

/// A closed torus of `2 u v` triangles on the grid (radii `2^18` and
/// `0.4 · 2^18`), rounded to grid points; triangles that rounding makes
/// degenerate are left out.
fn grid_torus(u: usize, v: usize) -> Vec<Polygon> {
    let tris = bsp_fixtures::torus(u, v, 262_144.0, 104_857.6);
    (tris.iter().enumerate())
        .filter_map(|(i, t)| {
            let g = t.map(|p| p.to_array().map(|c| c.round() as i32));
            Polygon::from_grid_points(&g, i as u32).ok()
        })
        .collect()
}

/// Lists of more than 2^15 polygons are cut level by level and the
/// shorter lists left grown in parallel: on a torus of 35,200 triangles
/// (convex patches, so balance cuts at the top) and a random soup of
/// 40,000, the tree is valid, keeps a fragment of every polygon, stays
/// shallow, and is the same on one thread as on two.
#[test]
fn long_lists_grow_in_parallel_to_the_same_tree_on_any_thread_count() {
    let mut rng = Rng(11);
    let soup: Vec<Polygon> = (0..40_000)
        .filter_map(|i| {
            let c = [0; 3].map(|_| rng.below(1 << 20) as i32 - (1 << 19));
            let mut corner = || c.map(|x| x + rng.below(1 << 14) as i32 - (1 << 13));
            Polygon::from_grid_points(&[corner(), corner(), corner()], i).ok()
        })
        .collect();
    for (name, polys) in [("torus", grid_torus(160, 110)), ("soup", soup)] {
        assert!(polys.len() > 1 << 15, "{name}: {} polygons", polys.len());
        let opts = BuildOptions::default();
        let on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| BspTree::build(polys.clone(), &opts))
        };
        let (one, two) = (on(1), on(2));
        assert!(same_tree(&one, &two), "{name}: one thread and two differ");
        two.sanity_check().unwrap();
        let mut kept = vec![false; polys.len()];
        let index: HashMap<u32, usize> = (polys.iter().enumerate())
            .map(|(i, p)| (p.tag(), i))
            .collect();
        two.polygons().for_each(|f| kept[index[&f.tag()]] = true);
        assert!(kept.iter().all(|&k| k), "{name}: a polygon has no fragment");
        let s = two.stats();
        assert!(
            s.depth < 200 && s.polygons < 3 * polys.len(),
            "{name}: {s:?}"
        );
    }
}
