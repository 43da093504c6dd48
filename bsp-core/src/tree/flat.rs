//! A flattened, array-stored BSP tree for fast traversal.
//!
//! Seed 003 stores the tree level by level in an array padded to a full
//! binary tree, which costs `2^depth` slots. Here the nodes are stored in
//! pre-order in parallel arrays — planes, child indices, and one contiguous
//! polygon array sliced by per-node offsets — so storage is linear in the
//! node count, and traversal is a loop over a small explicit stack of
//! `u32`s, without recursion.

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
    polygons: Vec<Polygon>,
    depth: usize,
}

impl FlatBsp {
    /// Flattens `tree` (explicit stack, any depth).
    pub fn new(tree: &BspTree) -> FlatBsp {
        let n = tree.nodes().len();
        let mut f = FlatBsp {
            planes: Vec::with_capacity(n),
            children: Vec::with_capacity(n),
            first: Vec::with_capacity(n + 1),
            polygons: Vec::with_capacity(tree.polygons().count()),
            depth: tree.stats().depth,
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
        // the eye's side of every plane first, in one pass over the planes
        // in memory order (exact, and free of the walk's branches); then
        // the walk reads one bit a node
        let back_to_front = order == Order::BackToFront;
        let mut near_back = vec![0u64; self.planes.len().div_ceil(64)];
        for (w, planes) in near_back.iter_mut().zip(self.planes.chunks(64)) {
            for (k, plane) in planes.iter().enumerate() {
                let eye_in_front = plane.classify_viewpoint(eye) != Side::Back;
                *w |= u64::from(eye_in_front == back_to_front) << k;
            }
        }
        // down each node's first subtree, keeping on the stack only the
        // nodes still to emit, each with its second subtree
        let mut stack: Vec<(u32, u32)> = Vec::with_capacity(self.depth + 1);
        let mut at = 0u32;
        loop {
            while at < OUT {
                let i = at as usize;
                let [front, back] = self.children[i];
                let (first, second) = match near_back[i / 64] >> (i % 64) & 1 == 1 {
                    true => (back, front),
                    false => (front, back),
                };
                stack.push((at, second));
                at = first;
            }
            let Some((i, second)) = stack.pop() else {
                break;
            };
            let (a, b) = (
                self.first[i as usize] as usize,
                self.first[i as usize + 1] as usize,
            );
            self.polygons[a..b].iter().for_each(&mut visit);
            at = second;
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
