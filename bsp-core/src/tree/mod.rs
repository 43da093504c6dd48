//! BSP trees: autopartition build, painter's-order traversal, solid
//! membership, invariants.
//!
//! Nothing here recurses without a bound: build, traversal, membership and
//! checks use explicit stacks, and the recursive traversal hands over to the
//! iterative one past [`RECURSION_LIMIT`] levels.

mod build;
mod check;
pub(crate) mod flat;
pub(crate) mod partition;
mod traverse;

pub(crate) use build::push_down_by;
pub(crate) use check::{Ancestor, check_ancestors, walk_checked};
pub use flat::FlatBsp;
pub use partition::{
    BoolOp, CellOp, Overlay, PLink, PNode, Partition, box_section, merge, merge_smaller_into_larger,
};

use crate::kernel::{Plane, Polygon};

/// Index of a node in [`BspTree::nodes`].
pub type NodeId = u32;

/// A leaf cell's solid label.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Cell {
    /// Inside the solid.
    In,
    /// Outside the solid.
    Out,
}

/// A child reference: an inner node or a leaf cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Link {
    /// An inner node.
    Node(NodeId),
    /// A leaf cell.
    Cell(Cell),
}

/// An inner node: a partitioning plane and the polygons lying in it.
#[derive(Clone, Debug)]
pub struct Node {
    /// The partitioning plane (the support plane of the polygon that chose it).
    pub plane: Plane,
    /// Polygons in the plane, of either orientation.
    pub polygons: Vec<Polygon>,
    /// Subtree in front of the plane.
    pub front: Link,
    /// Subtree behind the plane.
    pub back: Link,
}

/// Where a point lies relative to a solid.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Membership {
    /// Strictly inside.
    Inside,
    /// Strictly outside.
    Outside,
    /// On the boundary.
    Boundary,
}

/// Drawing order of a traversal.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Order {
    /// Farthest first (painter's algorithm).
    BackToFront,
    /// Nearest first (as from a light, for shadows).
    FrontToBack,
}

/// Levels the recursive traversal descends before it continues with an
/// explicit stack.
pub const RECURSION_LIMIT: usize = 2048;

/// Options of the tree build: an autopartition with balance cuts.
///
/// At every node, `candidates` polygons of the node's list are tried as
/// the partitioning plane; each is scored on a sample of `sample` polygons
/// as `split_weight * spanning + |front - back|`, and the lowest score wins.
/// More candidates and larger samples cost build time and save fragments.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct BuildOptions {
    /// Candidate planes tried per node.
    pub candidates: usize,
    /// Polygons each candidate is scored on.
    pub sample: usize,
    /// Cost of one split relative to one unit of imbalance.
    pub split_weight: u32,
    /// Seed of the deterministic sampling.
    pub seed: u64,
    /// Lists longer than this may be cut by an axis-aligned plane through
    /// the median polygon position (a *balance cut*) instead of a
    /// polygon's plane; 0 builds a pure autopartition. The default is 128.
    ///
    /// A convex mesh makes an autopartition a chain as deep as its face
    /// count (every face's plane has the others behind it), and the build
    /// quadratic; balance cuts bound the depth by about `log2(n /
    /// threshold)` plus the length of the chains inside cells of
    /// `threshold` polygons. A balance cut is tried only where the best
    /// polygon plane found is lopsided (its smaller side and the plane
    /// itself each hold under an eighth of the sampled polygons), and made
    /// only when both sides keep polygons and neither keeps more than
    /// three quarters of them (spanning polygons count twice); otherwise
    /// the node is an ordinary autopartition node. So a scene the
    /// autopartition splits well (a city's blocks, a room) keeps its tree,
    /// and every empty leaf still hangs below a polygon's plane: the solid
    /// labelling stays valid.
    pub cut_threshold: usize,
    /// Try a balance cut first on every list above the threshold, lopsided
    /// or not (`Partition::solid`'s builds: their set operations' results
    /// have fewer polygons so).
    pub(crate) cut_always: bool,
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions {
            candidates: 8,
            sample: 48,
            split_weight: 4,
            seed: 0x5eed_b5b7,
            cut_threshold: 128,
            cut_always: false,
        }
    }
}

impl BuildOptions {
    /// Sets [`BuildOptions::candidates`] (at least 1).
    pub fn with_candidates(mut self, n: usize) -> Self {
        self.candidates = n.max(1);
        self
    }
    /// Sets [`BuildOptions::sample`] (at least 1).
    pub fn with_sample(mut self, n: usize) -> Self {
        self.sample = n.max(1);
        self
    }
    /// Sets [`BuildOptions::split_weight`].
    pub fn with_split_weight(mut self, w: u32) -> Self {
        self.split_weight = w;
        self
    }
    /// Sets [`BuildOptions::cut_threshold`] (0 disables balance cuts).
    pub fn with_cut_threshold(mut self, n: usize) -> Self {
        self.cut_threshold = n;
        self
    }
    /// Sets [`BuildOptions::seed`].
    pub fn with_seed(mut self, s: u64) -> Self {
        self.seed = s;
        self
    }
}

/// Size figures of a tree.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TreeStats {
    /// Inner nodes.
    pub nodes: usize,
    /// Polygons stored (fragments after splitting).
    pub polygons: usize,
    /// Longest root-to-leaf path, counted in inner nodes.
    pub depth: usize,
    /// Leaf cells labelled [`Cell::In`].
    pub in_cells: usize,
    /// Leaf cells labelled [`Cell::Out`].
    pub out_cells: usize,
}

/// A BSP tree over convex polygons, stored as an arena of nodes.
///
/// Leaves carry solid labels: an empty list behind a plane is [`Cell::In`],
/// in front [`Cell::Out`] (Thibault & Naylor). For a closed, consistently
/// oriented mesh this makes the tree a solid and [`BspTree::classify_point`]
/// exact point membership; for an open polygon soup the labels carry no
/// meaning, and the tree is used for ordering only.
#[derive(Clone, Debug)]
pub struct BspTree {
    nodes: Vec<Node>,
    root: Link,
}

/// `SplitMix64`: the small deterministic generator behind the sampled
/// choices of the builders (the same seed gives the same tree).
#[derive(Clone, Debug)]
pub struct SplitMix(pub u64);

impl SplitMix {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// A number in `0..n` (`n < 2^32`).
    pub fn below(&mut self, n: usize) -> usize {
        (((self.next_u64() >> 32) * n as u64) >> 32) as usize
    }
}

impl BspTree {
    fn root_id(&self) -> Option<NodeId> {
        match self.root {
            Link::Node(i) => Some(i),
            Link::Cell(_) => None,
        }
    }

    /// The root link.
    pub fn root(&self) -> Link {
        self.root
    }

    /// All inner nodes (indexed by [`NodeId`]).
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// One node.
    pub fn node(&self, id: NodeId) -> &Node {
        &self.nodes[id as usize]
    }

    /// Every stored polygon, in node order.
    pub fn polygons(&self) -> impl Iterator<Item = &Polygon> {
        self.nodes.iter().flat_map(|n| n.polygons.iter())
    }

    /// Node count, fragment count, depth and leaf counts.
    pub fn stats(&self) -> TreeStats {
        let mut s = TreeStats {
            nodes: self.nodes.len(),
            polygons: self.nodes.iter().map(|n| n.polygons.len()).sum(),
            ..TreeStats::default()
        };
        let mut stack = vec![(self.root, 0usize)];
        while let Some((link, d)) = stack.pop() {
            match link {
                Link::Cell(c) => {
                    s.depth = s.depth.max(d);
                    match c {
                        Cell::In => s.in_cells += 1,
                        Cell::Out => s.out_cells += 1,
                    }
                }
                Link::Node(id) => {
                    let n = &self.nodes[id as usize];
                    stack.push((n.front, d + 1));
                    stack.push((n.back, d + 1));
                }
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::build::{grow, partition_list};
    use super::*;
    use crate::kernel::{Point, PolygonSide, ViewPoint};

    fn cube(lo: i32, hi: i32) -> Vec<Polygon> {
        bsp_fixtures::grid_cuboid([lo; 3], [hi; 3])
            .iter()
            .enumerate()
            .map(|(i, q)| Polygon::from_grid_points(q, i as u32).unwrap())
            .collect()
    }

    #[test]
    fn cube_membership() {
        let t = BspTree::build(cube(0, 4), &BuildOptions::default());
        t.sanity_check().unwrap();
        let m = |p: [i32; 3]| t.classify_point(&Point::Grid(p));
        assert_eq!(m([2, 2, 2]), Membership::Inside);
        assert_eq!(m([5, 2, 2]), Membership::Outside);
        assert_eq!(m([4, 2, 2]), Membership::Boundary);
        assert_eq!(m([4, 4, 4]), Membership::Boundary);
        assert_eq!(m([4, 5, 4]), Membership::Outside);
        assert_eq!(t.stats().nodes, 6);
    }

    #[test]
    fn push_down_splits_by_the_cube_and_labels_the_pieces() {
        let t = BspTree::build(cube(0, 4), &BuildOptions::default());
        assert!(t.faces_agree());
        // a square in z = 2 from -2 to 6 each way: its middle (0..4)² is
        // inside, the rest outside
        let sq = Polygon::from_grid_points(&[[-2, -2, 2], [6, -2, 2], [6, 6, 2], [-2, 6, 2]], 9)
            .unwrap();
        let parts = t.push_down(sq);
        let area = |p: &Polygon| -> f64 {
            let v: Vec<[f64; 3]> = p.vertices().iter().map(|q| q.approx_f64()).collect();
            (0..v.len())
                .map(|i| {
                    let (a, b) = (v[i], v[(i + 1) % v.len()]);
                    a[0] * b[1] - b[0] * a[1]
                })
                .sum::<f64>()
                / 2.0
        };
        let inside: f64 = parts
            .iter()
            .filter(|(_, c)| *c == Cell::In)
            .map(|(p, _)| area(p))
            .sum();
        let outside: f64 = parts
            .iter()
            .filter(|(_, c)| *c == Cell::Out)
            .map(|(p, _)| area(p))
            .sum();
        assert_eq!(inside, 16.0);
        assert_eq!(outside, 64.0 - 16.0);
        // a cube's face coplanar with the opposite orientation breaks the
        // agreement
        let mut faces = cube(0, 4);
        faces.push(faces[0].flipped());
        assert!(!BspTree::build(faces, &BuildOptions::default()).faces_agree());
    }

    /// The `2 n` side faces of a convex prism over the parabola `y = x²`:
    /// every face has all the others behind it.
    fn parabola_prism(n: i32) -> Vec<Polygon> {
        (-n..n)
            .map(|i: i32| {
                let (a, b) = ([i, i * i, 0], [i + 1, (i + 1) * (i + 1), 0]);
                let up = |p: [i32; 3]| [p[0], p[1], 1];
                Polygon::from_grid_points(&[a, b, up(b), up(a)], (i + n) as u32).unwrap()
            })
            .collect()
    }

    /// The default build of a convex patch, which an autopartition makes a
    /// chain as deep as its faces, is shallow: balance cuts keep at most
    /// three quarters a side, so about `log(n / 128) / log(4/3)` of them
    /// above chains of at most 128.
    #[test]
    fn default_build_of_a_convex_patch_is_shallow() {
        let n = 5_000;
        let polys = parabola_prism(n);
        let t = BspTree::build(polys, &BuildOptions::default());
        t.sanity_check().unwrap();
        let s = t.stats();
        let levels = ((2 * n) as f64 / 128.0).ln() / (4.0_f64 / 3.0).ln();
        assert!(s.depth <= 128 + levels.ceil() as usize + 2, "{s:?}");
        // fragment growth at most 2.5 over the 2n faces
        assert!(2 * s.polygons <= 5 * (2 * n as usize), "{s:?}");
    }

    #[test]
    fn deep_chain_does_not_overflow() {
        // the side faces of a convex prism over the parabola y = x^2: every
        // face has all others behind it, so an autopartition is a chain
        // as deep as the face count whatever the heuristic picks
        let n = 5_000;
        let polys = parabola_prism(n);
        // (a pure autopartition: balance cuts would make it shallow)
        let t = BspTree::build(polys, &BuildOptions::default().with_cut_threshold(0));
        assert_eq!(t.stats().depth, 2 * n as usize);
        let eye = ViewPoint::new([0, -10, 0]).unwrap();
        let (mut a, mut b) = (vec![], vec![]);
        t.traverse_recursive(eye, Order::FrontToBack, |p| a.push(p.tag()));
        t.traverse(eye, Order::FrontToBack, |p| b.push(p.tag()));
        assert_eq!(a.len(), 2 * n as usize);
        assert_eq!(a, b);
    }

    /// The build as it was before the scoring's sides were kept: each
    /// candidate scored afresh, each list split by classifying again.
    fn reference_build(polygons: Vec<Polygon>, opts: &BuildOptions) -> BspTree {
        fn choose(polys: &[Polygon], opts: &BuildOptions, rng: &mut SplitMix) -> Plane {
            let n = polys.len();
            if n <= 2 {
                return *polys[0].support();
            }
            let (k, s) = (opts.candidates.min(n), opts.sample.min(n));
            let sample: Vec<usize> = if s == n {
                (0..n).collect()
            } else {
                (0..s).map(|_| rng.below(n)).collect()
            };
            let mut best = (u64::MAX, *polys[0].support());
            for c in 0..k {
                let plane = if k == n {
                    *polys[c].support()
                } else {
                    *polys[rng.below(n)].support()
                };
                let (mut f, mut b, mut sp) = (0u64, 0u64, 0u64);
                for &i in &sample {
                    match polys[i].classify(&plane) {
                        PolygonSide::Front => f += 1,
                        PolygonSide::Back => b += 1,
                        PolygonSide::Spanning => sp += 1,
                        PolygonSide::Coplanar { .. } => {}
                    }
                }
                let score = opts.split_weight as u64 * sp + f.abs_diff(b);
                if score < best.0 {
                    best = (score, plane);
                }
            }
            best.1
        }
        let mut rng = SplitMix(opts.seed);
        grow(polygons, (), |polys, ()| {
            let plane = choose(&polys, opts, &mut rng);
            let (on, front, back) = partition_list(polys, &plane);
            ((plane, on, front, back), (), ())
        })
    }

    /// Keeping the scoring's sides for the split, and scoring a plane drawn
    /// twice once, builds the same tree: the same planes, polygons (exact
    /// corners, tags) and links, for small lists (every polygon sampled)
    /// and large ones (a random sample), with many spanning polygons.
    #[test]
    fn kept_sides_build_the_same_tree() {
        use bsp_fixtures::uv_sphere;
        // two overlapping spheres' triangles and a few large random ones
        let mut polys = Vec::new();
        for (shift, n) in [(0i32, 300usize), (700, 120)] {
            let (pos, faces) = uv_sphere(n);
            let g = |i: u32| {
                let p = pos[i as usize] * 1000.0;
                [p.x as i32 + shift, p.y as i32, p.z as i32 - shift / 3]
            };
            for f in &faces {
                let pts: Vec<crate::kernel::GridPoint> = f.iter().map(|&i| g(i)).collect();
                if let Ok(p) = Polygon::from_grid_points(&pts, polys.len() as u32) {
                    polys.push(p);
                }
            }
        }
        let mut rng = SplitMix(3);
        for _ in 0..40 {
            let mut c = || (rng.below(4000) as i32) - 2000;
            let t = [[c(), c(), c()], [c(), c(), c()], [c(), c(), c()]];
            if let Ok(p) = Polygon::from_grid_points(&t, polys.len() as u32) {
                polys.push(p);
            }
        }
        let shown = |t: &BspTree| format!("{:?} {:?}", t.root, t.nodes);
        // (the reference makes no balance cuts)
        let pure = BuildOptions::default().with_cut_threshold(0);
        for opts in [
            pure.clone(),
            pure.clone().with_candidates(4).with_sample(16),
            pure.with_candidates(3).with_sample(5000),
        ] {
            for part in [&polys[..25], &polys[300..340], &polys[..]] {
                let built = BspTree::build(part.to_vec(), &opts);
                assert_eq!(shown(&built), shown(&reference_build(part.to_vec(), &opts)));
                if part.len() == polys.len() {
                    assert!(
                        built.stats().polygons > part.len(),
                        "some polygons are split"
                    );
                }
            }
        }
    }
}
