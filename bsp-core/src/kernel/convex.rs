//! Exact invariant checks shared by every polygon and tree type of the
//! workspace, and the error they report.

use crate::kernel::Side;

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
/// One implementation for every tier: `bsp-core`'s [`crate::kernel::Polygon`] and
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
