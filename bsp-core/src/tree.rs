//! BSP trees: autopartition build, painter's-order traversal, solid
//! membership, invariants.
//!
//! Nothing here recurses without a bound: build, traversal, membership and
//! checks use explicit stacks, and the recursive traversal hands over to the
//! iterative one past [`RECURSION_LIMIT`] levels.

use crate::Side;
use crate::grid::ViewPoint;
use crate::plane::Plane;
use crate::point::Point;
use crate::polygon::{Polygon, PolygonSide, Split};
use crate::sanity::{Ancestor, SanityError, walk_checked};

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

/// Options of the autopartition build.
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
    /// Lists longer than this are first cut by an axis-aligned plane
    /// through the median polygon position (a *balance cut*) instead of a
    /// polygon's plane; 0 (the default) builds a pure autopartition.
    ///
    /// A convex mesh makes an autopartition a chain as deep as its face
    /// count; balance cuts bound the depth by about `log2(n / threshold)`
    /// plus the length of the chains inside cells of `threshold` polygons,
    /// at the price of some extra fragments. A cut is only made when both
    /// sides keep polygons and neither keeps more than three quarters of
    /// them (spanning polygons count twice); otherwise the node is an
    /// ordinary autopartition node. So every empty leaf still hangs below a
    /// polygon's plane and the solid labelling stays valid.
    pub cut_threshold: usize,
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions {
            candidates: 8,
            sample: 48,
            split_weight: 4,
            seed: 0x5eed_b5b7,
            cut_threshold: 0,
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

#[derive(Clone, Copy)]
enum Slot {
    Root,
    Front(NodeId),
    Back(NodeId),
}

/// Splits a list by `plane` into (coplanar, front, back).
fn partition_list(
    polys: Vec<Polygon>,
    plane: &Plane,
) -> (Vec<Polygon>, Vec<Polygon>, Vec<Polygon>) {
    let (mut on, mut front, mut back) = (Vec::new(), Vec::new(), Vec::new());
    for p in polys {
        match p.split(plane) {
            Split::Front(p) => front.push(p),
            Split::Back(p) => back.push(p),
            Split::Coplanar { polygon, .. } => on.push(polygon),
            Split::Spanning { front: f, back: b } => {
                front.push(f);
                back.push(b);
            }
        }
    }
    (on, front, back)
}

/// [`partition_list`] of polygons whose sides of `plane` are known
/// (`sides`, [`Polygon::classify`]'s): only the spanning ones are looked
/// at again, to be split, and each list is made at its size.
fn partition_known(
    polys: Vec<Polygon>,
    plane: &Plane,
    sides: &[PolygonSide],
) -> (Vec<Polygon>, Vec<Polygon>, Vec<Polygon>) {
    let (mut n_on, mut n_front, mut n_back) = (0, 0, 0);
    for s in sides {
        match s {
            PolygonSide::Front => n_front += 1,
            PolygonSide::Back => n_back += 1,
            PolygonSide::Coplanar { .. } => n_on += 1,
            PolygonSide::Spanning => {
                n_front += 1;
                n_back += 1;
            }
        }
    }
    let (mut on, mut front, mut back) = (
        Vec::with_capacity(n_on),
        Vec::with_capacity(n_front),
        Vec::with_capacity(n_back),
    );
    for (p, side) in polys.into_iter().zip(sides) {
        match side {
            PolygonSide::Front => front.push(p),
            PolygonSide::Back => back.push(p),
            PolygonSide::Coplanar { .. } => on.push(p),
            PolygonSide::Spanning => match p.split(plane) {
                Split::Spanning { front: f, back: b } => {
                    front.push(f);
                    back.push(b);
                }
                _ => unreachable!("a spanning polygon spans the plane"),
            },
        }
    }
    (on, front, back)
}

/// `true` if cutting by `plane` leaves each side with at most three
/// quarters of the polygons (spanning ones count on both sides) and neither
/// side empty. Decided before anything is split, so a rejected cut costs no
/// fragments; without it, long parallel slivers would be cut again and
/// again next to the previous cut.
fn cut_balances(polys: &[Polygon], plane: &Plane) -> bool {
    let (mut front, mut back) = (0usize, 0usize);
    for p in polys {
        match p.classify(plane) {
            PolygonSide::Front => front += 1,
            PolygonSide::Back => back += 1,
            PolygonSide::Spanning => {
                front += 1;
                back += 1;
            }
            PolygonSide::Coplanar { .. } => {}
        }
    }
    let limit = polys.len() * 3 / 4;
    front > 0 && back > 0 && front <= limit && back <= limit
}

/// An axis-aligned plane `x_k = m` through the median of the polygons'
/// first-vertex coordinate along the longest axis of their bounding box.
/// How the plane is chosen does not affect exactness, so `f64` is fine here.
fn balance_cut(polys: &[Polygon]) -> Option<Plane> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut firsts: Vec<[f64; 3]> = Vec::with_capacity(polys.len());
    for p in polys {
        let v = p.vertices()[0].approx_f64();
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
        firsts.push(v);
    }
    let k = (0..3).max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))?;
    let mid = firsts.len() / 2;
    firsts.select_nth_unstable_by(mid, |a, b| a[k].total_cmp(&b[k]));
    let m = firsts[mid][k].round() as i128;
    let mut n = [0i64; 3];
    n[k] = 1;
    Plane::new(n, -m)
}

fn choose_plane(polys: &[Polygon], opts: &BuildOptions, rng: &mut SplitMix) -> Plane {
    choose_plane_sides(polys, opts, rng, &mut Vec::new()).0
}

/// [`choose_plane`], and whether `sides` holds every polygon's side of
/// the chosen plane ([`Polygon::classify`]): so when the sample is the
/// whole list, which the scoring classified against each candidate.
fn choose_plane_sides(
    polys: &[Polygon],
    opts: &BuildOptions,
    rng: &mut SplitMix,
    sides: &mut Vec<PolygonSide>,
) -> (Plane, bool) {
    let n = polys.len();
    if n <= 2 {
        return (*polys[0].support(), false);
    }
    let k = opts.candidates.min(n);
    let s = opts.sample.min(n);
    let sample: Vec<usize> = if s == n {
        (0..n).collect()
    } else {
        (0..s).map(|_| rng.below(n)).collect()
    };
    // the best candidate's sides, and the current one's
    let mut these: Vec<PolygonSide> = Vec::with_capacity(s);
    sides.clear();
    let mut best = (u64::MAX, *polys[0].support());
    let mut tried: smallvec::SmallVec<[Plane; 8]> = smallvec::SmallVec::new();
    for c in 0..k {
        let plane = if k == n {
            *polys[c].support()
        } else {
            *polys[rng.below(n)].support()
        };
        // a plane drawn again scores as it did, which does not beat itself
        if tried.contains(&plane) {
            continue;
        }
        tried.push(plane);
        let (mut f, mut b, mut sp) = (0u64, 0u64, 0u64);
        these.clear();
        for &i in &sample {
            let side = polys[i].classify(&plane);
            match side {
                PolygonSide::Front => f += 1,
                PolygonSide::Back => b += 1,
                PolygonSide::Spanning => sp += 1,
                PolygonSide::Coplanar { .. } => {}
            }
            these.push(side);
        }
        let score = opts.split_weight as u64 * sp + f.abs_diff(b);
        if score < best.0 {
            best = (score, plane);
            std::mem::swap(sides, &mut these);
        }
    }
    (best.1, s == n)
}

/// A node's cut: its plane, the polygons in the plane, and the lists in
/// front of it and behind it.
type Cut = (Plane, Vec<Polygon>, Vec<Polygon>, Vec<Polygon>);

/// The tree `split` grows from `polygons`: a non-empty list becomes a node
/// by the cut `split` makes of it (given what the caller keeps with the
/// list, `at`, and giving that of the front and back lists); an empty one
/// is a leaf, inside behind its parent's plane and outside elsewhere.
/// Nodes are numbered in the order they are made, front subtree first;
/// an explicit stack, so any depth is fine.
fn grow<A>(
    polygons: Vec<Polygon>,
    at: A,
    mut split: impl FnMut(Vec<Polygon>, A) -> (Cut, A, A),
) -> BspTree {
    let mut tree = BspTree {
        nodes: Vec::new(),
        root: Link::Cell(Cell::Out),
    };
    let mut stack: Vec<(Vec<Polygon>, A, Slot)> = vec![(polygons, at, Slot::Root)];
    while let Some((polys, at, slot)) = stack.pop() {
        let link = if polys.is_empty() {
            Link::Cell(match slot {
                Slot::Back(_) => Cell::In,
                Slot::Front(_) | Slot::Root => Cell::Out,
            })
        } else {
            let ((plane, on, front, back), at_front, at_back) = split(polys, at);
            let id = tree.nodes.len() as NodeId;
            tree.nodes.push(Node {
                plane,
                polygons: on,
                front: Link::Cell(Cell::Out),
                back: Link::Cell(Cell::In),
            });
            stack.push((back, at_back, Slot::Back(id)));
            stack.push((front, at_front, Slot::Front(id)));
            Link::Node(id)
        };
        match slot {
            Slot::Root => tree.root = link,
            Slot::Front(id) => tree.nodes[id as usize].front = link,
            Slot::Back(id) => tree.nodes[id as usize].back = link,
        }
    }
    tree
}

impl BspTree {
    /// An autopartition of `polygons`: every partitioning plane is the
    /// support plane of an input polygon; coplanar polygons of both
    /// orientations stay at their node. Uses an explicit stack, so any
    /// depth is fine.
    pub fn build(polygons: Vec<Polygon>, opts: &BuildOptions) -> BspTree {
        let mut rng = SplitMix(opts.seed);
        let mut sides = Vec::new();
        grow(polygons, (), |polys, ()| {
            let cut = if opts.cut_threshold > 0 && polys.len() > opts.cut_threshold {
                balance_cut(&polys)
            } else {
                None
            };
            if let Some(plane) = cut.filter(|c| cut_balances(&polys, c)) {
                let (on, front, back) = partition_list(polys, &plane);
                return ((plane, on, front, back), (), ());
            }
            let (plane, known) = choose_plane_sides(&polys, opts, &mut rng, &mut sides);
            let (on, front, back) = if known {
                partition_known(polys, &plane, &sides)
            } else {
                partition_list(polys, &plane)
            };
            ((plane, on, front, back), (), ())
        })
    }

    /// A tree from its nodes and root (indices into `nodes`; every node
    /// reached once).
    pub(crate) fn from_parts(nodes: Vec<Node>, root: Link) -> BspTree {
        BspTree { nodes, root }
    }

    /// This tree's splitting choices replayed on other copies of its
    /// polygons (moved, or snapped again after a motion), tagged as this
    /// tree's polygons are: where this tree split by the plane of face
    /// `t`, the replay splits by the plane of `t`'s new copy, without a
    /// candidate search. Where a copy is missing from its node's list, or
    /// polygons reach what was a leaf here, the replay chooses as
    /// [`BspTree::build`] does with `fallback`. The result is the same
    /// tree wherever the new coordinates keep every polygon on the same
    /// side of every plane, and a valid autopartition in any case.
    pub fn replay(&self, polygons: Vec<Polygon>, fallback: &BuildOptions) -> BspTree {
        let mut rng = SplitMix(fallback.seed);
        // each list with the node of this tree it stands at
        grow(polygons, self.root_id(), |polys, at| {
            let old = at.map(|i| &self.nodes[i as usize]);
            // the face whose plane this tree chose here
            let chosen = old.and_then(|n| {
                let t = n.polygons.iter().find(|p| p.support() == &n.plane)?.tag();
                polys.iter().find(|p| p.tag() == t).map(|p| *p.support())
            });
            let plane = chosen.unwrap_or_else(|| choose_plane(&polys, fallback, &mut rng));
            let (on, front, back) = partition_list(polys, &plane);
            let child = |l: Link| match l {
                Link::Node(j) => Some(j),
                Link::Cell(_) => None,
            };
            let (f, b) = old.map_or((None, None), |n| (child(n.front), child(n.back)));
            ((plane, on, front, back), f, b)
        })
    }

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

    fn children_in_order(n: &Node, eye_in_front: bool, order: Order) -> (Link, Link) {
        if eye_in_front == (order == Order::BackToFront) {
            (n.back, n.front)
        } else {
            (n.front, n.back)
        }
    }

    /// Visits every polygon in `order` as seen from `eye`, with an explicit
    /// stack. Polygons in the same node (coplanar) come out together.
    ///
    /// ```
    /// use bsp_core::{BspTree, BuildOptions, Order, Polygon, ViewPoint};
    /// let near = Polygon::from_grid_points(&[[0, 0, 1], [4, 0, 1], [0, 4, 1]], 0).unwrap();
    /// let far = Polygon::from_grid_points(&[[0, 0, 0], [4, 0, 0], [0, 4, 0]], 1).unwrap();
    /// let tree = BspTree::build(vec![near, far], &BuildOptions::default());
    /// let mut tags = vec![];
    /// tree.traverse(ViewPoint::new([1, 1, 10]).unwrap(), Order::BackToFront, |p| tags.push(p.tag()));
    /// assert_eq!(tags, vec![1, 0]);
    /// ```
    pub fn traverse(&self, eye: ViewPoint, order: Order, mut visit: impl FnMut(&Polygon)) {
        self.traverse_nodes(eye, order, |_, n| n.polygons.iter().for_each(&mut visit));
    }

    /// Visits every node in `order` from `eye` (explicit stack): the
    /// node's id and the node, whose `polygons` are its coplanar polygons.
    /// The polygon sequence is the one [`BspTree::traverse`] produces.
    pub fn traverse_nodes(
        &self,
        eye: ViewPoint,
        order: Order,
        mut visit: impl FnMut(NodeId, &Node),
    ) {
        let front = |p: &Plane| p.classify_viewpoint(eye) != Side::Back;
        self.traverse_nodes_from(self.root, &front, order, &mut visit);
    }

    /// [`BspTree::traverse_nodes`] for a viewpoint given by the side it
    /// takes of each plane: `in_front(plane)` is `true` when the viewpoint
    /// is in front of `plane` (or on it). A point at infinity, such as a
    /// sun's direction `D`, is in front when `n · D >= 0`.
    pub fn traverse_nodes_by(
        &self,
        in_front: impl Fn(&Plane) -> bool,
        order: Order,
        mut visit: impl FnMut(NodeId, &Node),
    ) {
        self.traverse_nodes_from(self.root, &in_front, order, &mut visit);
    }

    /// The node traversal of the subtree at `start`, with an explicit
    /// stack: the one implementation behind every traversal order.
    fn traverse_nodes_from(
        &self,
        start: Link,
        in_front: &impl Fn(&Plane) -> bool,
        order: Order,
        visit: &mut impl FnMut(NodeId, &Node),
    ) {
        enum Item {
            Visit(Link),
            Emit(NodeId),
        }
        let mut stack = vec![Item::Visit(start)];
        while let Some(item) = stack.pop() {
            match item {
                Item::Visit(Link::Cell(_)) => {}
                Item::Visit(Link::Node(id)) => {
                    let n = &self.nodes[id as usize];
                    let (first, second) = Self::children_in_order(n, in_front(&n.plane), order);
                    stack.push(Item::Visit(second));
                    stack.push(Item::Emit(id));
                    stack.push(Item::Visit(first));
                }
                Item::Emit(id) => visit(id, &self.nodes[id as usize]),
            }
        }
    }

    /// Index of the first polygon of every node in the node-major order of
    /// [`BspTree::polygons`], plus the total at the end: node `i` holds
    /// polygons `first[i]..first[i + 1]`.
    pub fn polygon_offsets(&self) -> Vec<usize> {
        let mut first = Vec::with_capacity(self.nodes.len() + 1);
        let mut k = 0;
        for n in &self.nodes {
            first.push(k);
            k += n.polygons.len();
        }
        first.push(k);
        first
    }

    fn traverse_from(
        &self,
        start: Link,
        eye: ViewPoint,
        order: Order,
        visit: &mut impl FnMut(&Polygon),
    ) {
        let front = |p: &Plane| p.classify_viewpoint(eye) != Side::Back;
        self.traverse_nodes_from(start, &front, order, &mut |_, n: &Node| {
            n.polygons.iter().for_each(&mut *visit)
        });
    }

    /// The same order as [`BspTree::traverse`], by recursion; past
    /// [`RECURSION_LIMIT`] levels it continues with an explicit stack, so
    /// a degenerate chain cannot overflow the call stack.
    pub fn traverse_recursive(
        &self,
        eye: ViewPoint,
        order: Order,
        mut visit: impl FnMut(&Polygon),
    ) {
        self.recurse(self.root, eye, order, &mut visit, 0);
    }

    fn recurse(
        &self,
        link: Link,
        eye: ViewPoint,
        order: Order,
        visit: &mut impl FnMut(&Polygon),
        depth: usize,
    ) {
        let Link::Node(id) = link else { return };
        if depth >= RECURSION_LIMIT {
            return self.traverse_from(link, eye, order, visit);
        }
        let n = &self.nodes[id as usize];
        let in_front = n.plane.classify_viewpoint(eye) != Side::Back;
        let (first, second) = Self::children_in_order(n, in_front, order);
        self.recurse(first, eye, order, visit, depth + 1);
        n.polygons.iter().for_each(&mut *visit);
        self.recurse(second, eye, order, visit, depth + 1);
    }

    /// Exact point membership for a solid tree (see the type's docs).
    ///
    /// A point on a partitioning plane is looked up on both sides; it is on
    /// the boundary exactly when the cells around it disagree. Every
    /// subtree is entered at most once, so the cost is bounded by the tree
    /// size.
    pub fn classify_point(&self, p: &Point) -> Membership {
        let (mut saw_in, mut saw_out) = (false, false);
        let mut stack = vec![self.root];
        while let Some(link) = stack.pop() {
            match link {
                Link::Cell(Cell::In) => saw_in = true,
                Link::Cell(Cell::Out) => saw_out = true,
                Link::Node(id) => {
                    let n = &self.nodes[id as usize];
                    match p.classify(&n.plane) {
                        Side::Front => stack.push(n.front),
                        Side::Back => stack.push(n.back),
                        Side::On => {
                            stack.push(n.front);
                            stack.push(n.back);
                        }
                    }
                }
            }
            if saw_in && saw_out {
                return Membership::Boundary;
            }
        }
        if saw_in {
            Membership::Inside
        } else {
            Membership::Outside
        }
    }

    /// Splits `poly` down the tree by the node planes: the pieces, each with
    /// the cell it lands in. A piece lying in a node's plane goes to the
    /// front (as [`crate::Partition::push_down`]).
    pub fn push_down(&self, poly: Polygon) -> Vec<(Polygon, Cell)> {
        crate::partition::push_down_by(poly, self.root, |l| match l {
            Link::Cell(c) => Err(c),
            Link::Node(id) => {
                let n = &self.nodes[id as usize];
                Ok((&n.plane, n.front, n.back))
            }
        })
    }

    /// `true` if every node's polygons face the way of its plane (none is
    /// coplanar with the opposite orientation). Then, for the faces of a
    /// solid, each empty leaf of an autopartition lies on one side of a
    /// face of its parent node, across nothing else: the leaves that
    /// [`BspTree::build`] makes are labelled as the solid is (a front leaf
    /// outside, a back leaf inside) without any other test.
    pub fn faces_agree(&self) -> bool {
        self.nodes
            .iter()
            .all(|n| !n.polygons.is_empty() && n.polygons.iter().all(|p| p.support() == &n.plane))
    }

    /// Checks the tree invariants exactly: the links form a tree reaching
    /// every node once; every stored polygon is valid and lies in its
    /// node's plane; every polygon of a subtree lies on that subtree's
    /// side of each ancestor plane (touching it at most).
    ///
    /// Costs `O(polygons × depth)`; meant for tests and fuzzing.
    pub fn sanity_check(&self) -> Result<(), SanityError> {
        let link = |l: Link| match l {
            Link::Node(id) => Some(id),
            Link::Cell(_) => None,
        };
        walk_checked(
            self.nodes.len(),
            link(self.root),
            |id| {
                let n = &self.nodes[id as usize];
                (n.plane, link(n.front), link(n.back))
            },
            |id, path| {
                let n = &self.nodes[id as usize];
                // a node without polygons is a balance cut: both sides hold
                // polygons, so neither child is a leaf
                if n.polygons.is_empty()
                    && (matches!(n.front, Link::Cell(_)) || matches!(n.back, Link::Cell(_)))
                {
                    return Err(SanityError::BareCut { node: id });
                }
                for (k, p) in n.polygons.iter().enumerate() {
                    p.sanity_check().map_err(|e| SanityError::Polygon {
                        node: id,
                        polygon: Some(k),
                        error: Box::new(e),
                    })?;
                    if !p.support().is_coincident(&n.plane) {
                        return Err(SanityError::OffNodePlane { node: id });
                    }
                    check_ancestors(id, p, path)?;
                }
                Ok(())
            },
        )
    }
}

/// Checks that `poly`, held by node `node`, lies on the recorded side of
/// every ancestor plane (touching it at most).
pub(crate) fn check_ancestors(
    node: NodeId,
    poly: &Polygon,
    path: &[Ancestor],
) -> Result<(), SanityError> {
    for (a, (plane, side)) in path.iter().enumerate() {
        let ok = matches!(
            (poly.classify(plane), side),
            (PolygonSide::Front, Side::Front) | (PolygonSide::Back, Side::Back)
        );
        if !ok {
            return Err(SanityError::WrongSide {
                node,
                ancestor: a,
                side: *side,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(lo: i32, hi: i32) -> Vec<Polygon> {
        let c = |x, y, z| [x, y, z];
        let (l, h) = (lo, hi);
        let quads = [
            [c(l, l, l), c(l, h, l), c(h, h, l), c(h, l, l)],
            [c(l, l, h), c(h, l, h), c(h, h, h), c(l, h, h)],
            [c(l, l, l), c(h, l, l), c(h, l, h), c(l, l, h)],
            [c(l, h, l), c(l, h, h), c(h, h, h), c(h, h, l)],
            [c(l, l, l), c(l, l, h), c(l, h, h), c(l, h, l)],
            [c(h, l, l), c(h, h, l), c(h, h, h), c(h, l, h)],
        ];
        quads
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

    #[test]
    fn deep_chain_does_not_overflow() {
        // the side faces of a convex prism over the parabola y = x^2: every
        // face has all others behind it, so the tree is a chain as deep as
        // the face count whatever the heuristic picks
        let n = 5_000;
        let polys: Vec<Polygon> = (-n..n)
            .map(|i: i32| {
                let (a, b) = ([i, i * i, 0], [i + 1, (i + 1) * (i + 1), 0]);
                let up = |p: [i32; 3]| [p[0], p[1], 1];
                Polygon::from_grid_points(&[a, b, up(b), up(a)], (i + n) as u32).unwrap()
            })
            .collect();
        let t = BspTree::build(polys, &BuildOptions::default());
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
                let pts: Vec<crate::GridPoint> = f.iter().map(|&i| g(i)).collect();
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
        for opts in [
            BuildOptions::default(),
            BuildOptions::default().with_candidates(4).with_sample(16),
            BuildOptions::default().with_candidates(3).with_sample(5000),
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
