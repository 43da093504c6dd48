//! Walking a tree: painter's order from a viewpoint (explicit stack, or
//! recursion up to [`super::RECURSION_LIMIT`] levels),
//! and exact point membership.

use crate::kernel::{Plane, Point, Polygon, Side, ViewPoint};

use super::{BspTree, Cell, Link, Membership, Node, NodeId, Order, RECURSION_LIMIT};

impl BspTree {
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
        // the nodes whose first subtree is being walked, each with its
        // second subtree: a node is emitted when popped, then its second
        // subtree walked (in order, no entry for a leaf)
        let mut stack: Vec<(NodeId, Link)> = Vec::new();
        let mut at = start;
        loop {
            while let Link::Node(id) = at {
                let n = &self.nodes[id as usize];
                let (first, second) = Self::children_in_order(n, in_front(&n.plane), order);
                stack.push((id, second));
                at = first;
            }
            let Some((id, second)) = stack.pop() else {
                return;
            };
            visit(id, &self.nodes[id as usize]);
            at = second;
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
}
