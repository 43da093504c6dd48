//! A tree's invariants, checked exactly.

use crate::kernel::{Plane, Polygon, PolygonSide, SanityError, Side};

use super::{BspTree, Link, NodeId};

impl BspTree {
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

/// An ancestor's plane and the side of it a subtree lies on.
pub(crate) type Ancestor = (Plane, Side);

/// Walks a tree of `count` nodes from `root` with an explicit stack,
/// checking that the links form a tree over all of them (no missing,
/// repeated or unreachable node), and calls `visit` with each node and its
/// ancestors (plane and the side the node lies on), root first. `node`
/// gives a node's plane and its front and back child nodes.
pub(crate) fn walk_checked(
    count: usize,
    root: Option<u32>,
    node: impl Fn(u32) -> (Plane, Option<u32>, Option<u32>),
    mut visit: impl FnMut(u32, &[Ancestor]) -> Result<(), SanityError>,
) -> Result<(), SanityError> {
    let mut seen = vec![false; count];
    let mut path: Vec<Ancestor> = Vec::new();
    // (node, number of ancestors above its parent, edge from its parent)
    let mut stack: Vec<(Option<u32>, usize, Option<Ancestor>)> = vec![(root, 0, None)];
    while let Some((id, depth, edge)) = stack.pop() {
        path.truncate(depth);
        if let Some(e) = edge {
            path.push(e);
        }
        let Some(id) = id else { continue };
        let Some(flag) = seen.get_mut(id as usize) else {
            return Err(SanityError::MissingNode { node: id });
        };
        if std::mem::replace(flag, true) {
            return Err(SanityError::NodeReachedTwice { node: id });
        }
        visit(id, &path)?;
        let (plane, front, back) = node(id);
        let d = path.len();
        stack.push((front, d, Some((plane, Side::Front))));
        stack.push((back, d, Some((plane, Side::Back))));
    }
    if let Some(i) = seen.iter().position(|s| !s) {
        return Err(SanityError::Unreachable { node: i as u32 });
    }
    Ok(())
}
