//! A flattened, array-stored BSP tree for fast traversal.
//!
//! Seed 003 stores the tree level by level in an array padded to a full
//! binary tree, which costs `2^depth` slots. Here the nodes are stored in
//! pre-order in parallel arrays — planes, child indices with their
//! subtrees' sizes, and one contiguous polygon array sliced by per-node
//! offsets — so storage is linear in the node count. Traversal needs
//! neither recursion nor a stack: one pass over the nodes in memory order
//! places each node in the walk's order (after the subtree it puts first,
//! which its size says how long is), and a second emits the polygons in
//! that order.

use crate::kernel::Side;
use crate::kernel::grid::ViewPoint;
use crate::kernel::plane::Plane;
use crate::kernel::polygon::Polygon;
use crate::tree::{BspTree, Cell, Link, Order};

const IN: u32 = u32::MAX;
const OUT: u32 = u32::MAX - 1;

/// A BSP tree in pre-order array layout (see the module docs).
#[derive(Clone, Debug)]
pub struct FlatBsp {
    planes: Vec<Plane>,
    /// `[front, back]`, node indices or the `IN` / `OUT` sentinels.
    children: Vec<[u32; 2]>,
    /// Node `i` holds `polygons[first[i]..first[i + 1]]`.
    first: Vec<u32>,
    /// The node counts of each node's `[front, back]` subtrees (0 for a
    /// cell), beside its children so that the walk reads them in order.
    child_size: Vec<[u32; 2]>,
    polygons: Vec<Polygon>,
}

impl FlatBsp {
    /// Flattens `tree` (explicit stack, any depth).
    pub fn new(tree: &BspTree) -> FlatBsp {
        let n = tree.nodes().len();
        let mut f = FlatBsp {
            planes: Vec::with_capacity(n),
            children: Vec::with_capacity(n),
            first: Vec::with_capacity(n + 1),
            child_size: Vec::new(),
            polygons: Vec::with_capacity(tree.polygons().count()),
        };
        // (link in `tree`, slot in `children` to patch: (index, 0 front / 1 back))
        let mut stack: Vec<(Link, Option<(usize, usize)>)> = vec![(tree.root(), None)];
        while let Some((link, slot)) = stack.pop() {
            let v = match link {
                Link::Cell(Cell::In) => IN,
                Link::Cell(Cell::Out) => OUT,
                Link::Node(id) => {
                    let node = tree.node(id);
                    let me = f.planes.len();
                    f.planes.push(node.plane);
                    f.children.push([OUT, IN]);
                    f.first.push(f.polygons.len() as u32);
                    f.polygons.extend(node.polygons.iter().cloned());
                    // back pushed first so that front is laid out right after
                    stack.push((node.back, Some((me, 1))));
                    stack.push((node.front, Some((me, 0))));
                    me as u32
                }
            };
            if let Some((i, c)) = slot {
                f.children[i][c] = v;
            }
        }
        f.first.push(f.polygons.len() as u32);
        // pre-order: a node's children come after it (the cells read as
        // index `len`, of size 0)
        let len = f.planes.len();
        let mut size = vec![0u32; len + 1];
        for i in (0..len).rev() {
            let [a, b] = f.children[i].map(|c| (c as usize).min(len));
            size[i] = 1 + size[a] + size[b];
        }
        f.child_size = (f.children.iter())
            .map(|c| c.map(|c| size[(c as usize).min(len)]))
            .collect();
        f
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.planes.len()
    }

    /// `true` for a tree without inner nodes.
    pub fn is_empty(&self) -> bool {
        self.planes.is_empty()
    }

    /// All polygons, node by node in pre-order.
    pub fn polygons(&self) -> &[Polygon] {
        &self.polygons
    }

    /// Visits every polygon in `order` from `eye`: the same sequence as
    /// [`BspTree::traverse`] on the tree this was made from.
    pub fn traverse(&self, eye: ViewPoint, order: Order, mut visit: impl FnMut(&Polygon)) {
        if self.planes.is_empty() {
            return;
        }
        // one pass over the nodes in memory order (pre-order: a node before
        // its children) places each node in the walk's order: it comes
        // after the whole subtree it puts first, and its second subtree
        // right after it; the cells stand for index `len`. Then the
        // polygons go out in that order. No stack, and no branch on the
        // eye's side of a plane (which is as good as random).
        let back_to_front = order == Order::BackToFront;
        let len = self.planes.len();
        let mut base = vec![0u32; len + 1];
        let mut at = vec![0u32; len + 1];
        for i in 0..len {
            let c = self.children[i].map(|c| (c as usize).min(len));
            let eye_in_front = self.planes[i].classify_viewpoint(eye) != Side::Back;
            let b = usize::from(eye_in_front == back_to_front);
            let (first, second) = (c[b], c[1 - b]);
            let place = base[i] + self.child_size[i][b];
            at[place as usize] = i as u32;
            base[first] = base[i];
            base[second] = place + 1;
        }
        for &i in &at[..len] {
            let (a, b) = (
                self.first[i as usize] as usize,
                self.first[i as usize + 1] as usize,
            );
            self.polygons[a..b].iter().for_each(&mut visit);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tree::BuildOptions;

    #[test]
    fn same_order_as_tree() {
        let mut polys = Vec::new();
        for i in 0..40i32 {
            let (x, z) = (i % 7 * 3, i / 7 * 2);
            polys.push(
                Polygon::from_grid_points(
                    &[[x, 0, z], [x + 5, 1, z + 1], [x, 6, z + i % 3]],
                    i as u32,
                )
                .unwrap(),
            );
        }
        let t = BspTree::build(polys, &BuildOptions::default());
        let f = FlatBsp::new(&t);
        assert_eq!(f.len(), t.nodes().len());
        for eye in [[-50, -50, -50], [100, 3, 7], [7, 7, 7]] {
            let eye = ViewPoint::new(eye).unwrap();
            for order in [Order::BackToFront, Order::FrontToBack] {
                let (mut a, mut b) = (vec![], vec![]);
                t.traverse(eye, order, |p| a.push(p.tag()));
                f.traverse(eye, order, |p| b.push(p.tag()));
                assert_eq!(a, b);
            }
        }
    }
}
