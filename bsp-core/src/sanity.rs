//! Exact invariant checks shared by every polygon and tree type of the
//! workspace, and the error they report.

use crate::Side;
use crate::plane::Plane;

/// Which exact invariant a polygon, tree or partition breaks.
///
/// Polygon indices count from 0 in the polygon's vertex and edge-plane
/// order (vertex `i` lies between edges `i - 1` and `i`); node ids are
/// those of the tree's arena.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum SanityError {
    /// Fewer than three vertices, or not as many edge planes as vertices.
    Shape {
        /// Vertices.
        vertices: usize,
        /// Edge planes.
        edges: usize,
    },
    /// A vertex is off the support plane.
    OffSupport {
        /// The vertex.
        vertex: usize,
    },
    /// A vertex is off one of its two edge planes.
    OffEdge {
        /// The vertex.
        vertex: usize,
        /// The edge plane.
        edge: usize,
    },
    /// A vertex is not strictly behind an edge plane it is not on (the
    /// polygon is not strictly convex).
    NotInside {
        /// The vertex.
        vertex: usize,
        /// The edge plane.
        edge: usize,
    },
    /// An edge plane coincides with the support plane.
    EdgeIsSupport {
        /// The edge plane.
        edge: usize,
    },
    /// A link names a node that does not exist.
    MissingNode {
        /// The link's target.
        node: u32,
    },
    /// Two links lead to the same node.
    NodeReachedTwice {
        /// The node.
        node: u32,
    },
    /// A node no link leads to.
    Unreachable {
        /// The node.
        node: u32,
    },
    /// A node without polygons (a balance cut) has a leaf child.
    BareCut {
        /// The node.
        node: u32,
    },
    /// A polygon of a node is not in the node's plane (either orientation),
    /// or a sub-hyperplane is not in it with the same orientation.
    OffNodePlane {
        /// The node.
        node: u32,
    },
    /// A polygon of a subtree is not on that subtree's side of an ancestor
    /// plane (touching it is allowed).
    WrongSide {
        /// The node holding the polygon.
        node: u32,
        /// The ancestor, counted from the root (0).
        ancestor: usize,
        /// The side the polygon should be on.
        side: Side,
    },
    /// A polygon of a node breaks a polygon invariant.
    Polygon {
        /// The node.
        node: u32,
        /// The polygon's index in the node, or `None` for a partition's
        /// sub-hyperplane.
        polygon: Option<usize>,
        /// What is wrong with it.
        error: Box<SanityError>,
    },
}

impl std::fmt::Display for SanityError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SanityError::Shape { vertices, edges } => {
                write!(f, "{vertices} vertices, {edges} edge planes")
            }
            SanityError::OffSupport { vertex } => {
                write!(f, "vertex {vertex} is off the support plane")
            }
            SanityError::OffEdge { vertex, edge } => {
                write!(f, "vertex {vertex} is off its edge plane {edge}")
            }
            SanityError::NotInside { vertex, edge } => {
                write!(
                    f,
                    "vertex {vertex} is not strictly inside edge plane {edge}"
                )
            }
            SanityError::EdgeIsSupport { edge } => {
                write!(f, "edge plane {edge} is the support plane")
            }
            SanityError::MissingNode { node } => write!(f, "link to missing node {node}"),
            SanityError::NodeReachedTwice { node } => write!(f, "node {node} is reached twice"),
            SanityError::Unreachable { node } => write!(f, "node {node} is unreachable"),
            SanityError::BareCut { node } => {
                write!(f, "node {node} holds no polygon but has a leaf child")
            }
            SanityError::OffNodePlane { node } => {
                write!(f, "node {node}: a polygon is not in the node plane")
            }
            SanityError::WrongSide {
                node,
                ancestor,
                side,
            } => write!(
                f,
                "node {node}: a polygon is not on the {side:?} side of ancestor {ancestor}"
            ),
            SanityError::Polygon {
                node,
                polygon,
                error,
            } => match polygon {
                Some(k) => write!(f, "node {node} polygon {k}: {error}"),
                None => write!(f, "node {node} sub-hyperplane: {error}"),
            },
        }
    }
}

impl std::error::Error for SanityError {}

/// What [`check_convex`] needs to know about a plane-based convex polygon:
/// the exact side of each vertex relative to the support plane and to each
/// edge plane.
pub trait ConvexParts {
    /// Number of vertices.
    fn vertex_count(&self) -> usize;
    /// Number of edge planes.
    fn edge_count(&self) -> usize;
    /// Exact side of vertex `i` relative to the support plane.
    fn support_side(&self, i: usize) -> Side;
    /// Exact side of vertex `i` relative to edge plane `j`.
    fn edge_side(&self, i: usize, j: usize) -> Side;
    /// `true` if edge plane `j` coincides with the support plane.
    fn edge_is_support(&self, j: usize) -> bool;
}

/// Checks a convex polygon's invariants exactly: at least three vertices
/// and as many edge planes; every vertex on the support plane and on its
/// two edge planes, and strictly behind every other edge plane (strict
/// convexity); no edge plane equal to the support plane.
///
/// One implementation for every tier: `bsp-core`'s [`crate::Polygon`] and
/// the fragments and cells of `svbsp` implement [`ConvexParts`].
pub fn check_convex(p: &impl ConvexParts) -> Result<(), SanityError> {
    let k = p.vertex_count();
    if k < 3 || p.edge_count() != k {
        return Err(SanityError::Shape {
            vertices: k,
            edges: p.edge_count(),
        });
    }
    for i in 0..k {
        if p.support_side(i) != Side::On {
            return Err(SanityError::OffSupport { vertex: i });
        }
        for j in 0..k {
            let incident = j == i || (j + 1) % k == i;
            let s = p.edge_side(i, j);
            if incident && s != Side::On {
                return Err(SanityError::OffEdge { vertex: i, edge: j });
            }
            if !incident && s != Side::Back {
                return Err(SanityError::NotInside { vertex: i, edge: j });
            }
        }
        if p.edge_is_support(i) {
            return Err(SanityError::EdgeIsSupport { edge: i });
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
