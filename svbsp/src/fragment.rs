//! Fragments: convex pieces of scene polygons bounded by input planes and
//! shadow planes.

use bsp_core::{Plane, Polygon, Side};
use smallvec::SmallVec;
use std::sync::Arc;

use crate::wide::{WPoint, WidePlane};

/// One edge plane of a fragment: an input plane (kept in its small form so
/// that shadow planes can be built from it) or a shadow plane (shared with
/// the shadow tree that made it).
#[derive(Clone, Debug)]
pub enum Edge {
    /// An input plane.
    Input(Plane),
    /// A shadow plane.
    Shadow(Arc<WidePlane>),
}

impl Edge {
    /// The plane in wide form.
    pub fn wide(&self) -> WidePlane {
        match self {
            Edge::Input(p) => WidePlane::from_plane(p),
            Edge::Shadow(w) => **w,
        }
    }

    /// The input plane, if this edge is one.
    pub fn input(&self) -> Option<&Plane> {
        match self {
            Edge::Input(p) => Some(p),
            Edge::Shadow(_) => None,
        }
    }
}

/// A convex piece of a scene polygon, with one lit flag per light.
///
/// Like [`bsp_core::Polygon`]: vertex `i` is the support plane ∩ edge
/// `i - 1` ∩ edge `i`; the interior is behind every edge plane; vertices run
/// counter-clockwise seen from the front of the support plane.
#[derive(Clone, Debug)]
pub struct Fragment {
    pub(crate) support: Plane,
    pub(crate) edges: SmallVec<[Edge; 4]>,
    pub(crate) verts: SmallVec<[Box<WPoint>; 4]>,
    pub(crate) face: u32,
    pub(crate) polygon: u32,
    pub(crate) lit: SmallVec<[bool; 2]>,
}

/// Where a fragment lies relative to a plane.
// Moved straight into the caller's stack; boxing would add an allocation.
#[allow(clippy::large_enum_variant)]
pub(crate) enum FragSplit {
    Front(Fragment),
    Back(Fragment),
    /// In the plane (only for planes containing the light and the fragment:
    /// an edge-on polygon).
    On(Fragment),
    Spanning(Fragment, Fragment),
}

impl Fragment {
    /// A whole scene polygon, tagged with its face index and its index in
    /// the scene tree's polygon order, no flags yet.
    pub fn from_polygon(p: &Polygon, polygon: u32) -> Fragment {
        Fragment {
            support: *p.support(),
            edges: p.edge_planes().iter().map(|e| Edge::Input(*e)).collect(),
            verts: p
                .vertices()
                .iter()
                .map(|v| Box::new(WPoint::from_point(v)))
                .collect(),
            face: p.tag(),
            polygon,
            lit: SmallVec::new(),
        }
    }

    /// The input face this fragment belongs to.
    pub fn face(&self) -> u32 {
        self.face
    }

    /// Index of the scene polygon this fragment is a piece of, in the
    /// node-major order of [`bsp_core::BspTree::polygons`] (node `i` holds
    /// polygons `polygon_offsets()[i]..polygon_offsets()[i + 1]`): draw
    /// fragments in painter's order by visiting nodes with
    /// [`bsp_core::BspTree::traverse_nodes`].
    pub fn polygon(&self) -> u32 {
        self.polygon
    }

    /// One flag per light, in the order the lights were given: `true` where
    /// the light reaches the fragment's front side unobstructed.
    pub fn lit(&self) -> &[bool] {
        &self.lit
    }

    /// The support plane (the face's plane).
    pub fn support(&self) -> &Plane {
        &self.support
    }

    /// The exact vertices.
    pub fn vertices(&self) -> impl Iterator<Item = &WPoint> {
        self.verts.iter().map(|b| &**b)
    }

    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.verts.len()
    }

    /// Always `false`: a fragment has at least three vertices.
    pub fn is_empty(&self) -> bool {
        self.verts.is_empty()
    }

    /// The edge planes (edge `i` runs from vertex `i` to `i + 1`).
    pub fn edges(&self) -> &[Edge] {
        &self.edges
    }

    /// Vertices in grid coordinates, correctly rounded.
    pub fn vertices_f64(&self) -> Vec<[f64; 3]> {
        self.verts.iter().map(|v| v.to_f64()).collect()
    }

    /// Splits by the shadow plane `h` (`h_flip` is its flip, shared).
    pub(crate) fn split(self, h: &Arc<WidePlane>, h_flip: &Arc<WidePlane>) -> FragSplit {
        let sides: SmallVec<[Side; 8]> = self.verts.iter().map(|v| v.classify(h)).collect();
        let front = sides.contains(&Side::Front);
        let back = sides.contains(&Side::Back);
        match (front, back) {
            (true, false) => FragSplit::Front(self),
            (false, true) => FragSplit::Back(self),
            (false, false) => FragSplit::On(self),
            (true, true) => {
                let (f, b) = self.split_with_sides(h, h_flip, &sides);
                FragSplit::Spanning(f, b)
            }
        }
    }

    fn split_with_sides(
        &self,
        h: &Arc<WidePlane>,
        h_flip: &Arc<WidePlane>,
        sides: &[Side],
    ) -> (Fragment, Fragment) {
        let support = WidePlane::from_plane(&self.support);
        let cut_front = Edge::Shadow(h_flip.clone());
        let cut_back = Edge::Shadow(h.clone());
        let k = self.verts.len();
        let mut f = self.empty_like();
        let mut b = self.empty_like();
        for i in 0..k {
            let j = if i + 1 == k { 0 } else { i + 1 };
            let (vi, ei) = (&self.verts[i], &self.edges[i]);
            match (sides[i], sides[j]) {
                (Side::Front, Side::Back) | (Side::Back, Side::Front) => {
                    let x = Box::new(
                        WPoint::from_support_planes(&support, &ei.wide(), h)
                            .expect("a spanning edge meets the cutting plane in one point"),
                    );
                    if sides[i] == Side::Front {
                        f.push(vi.clone(), ei.clone());
                        f.push(x.clone(), cut_front.clone());
                        b.push(x, ei.clone());
                    } else {
                        b.push(vi.clone(), ei.clone());
                        b.push(x.clone(), cut_back.clone());
                        f.push(x, ei.clone());
                    }
                }
                (Side::Front, _) => f.push(vi.clone(), ei.clone()),
                (Side::Back, _) => b.push(vi.clone(), ei.clone()),
                (Side::On, Side::Back) => {
                    f.push(vi.clone(), cut_front.clone());
                    b.push(vi.clone(), ei.clone());
                }
                (Side::On, _) => {
                    f.push(vi.clone(), ei.clone());
                    b.push(vi.clone(), cut_back.clone());
                }
            }
        }
        (f, b)
    }

    fn empty_like(&self) -> Fragment {
        Fragment {
            support: self.support,
            edges: SmallVec::new(),
            verts: SmallVec::new(),
            face: self.face,
            polygon: self.polygon,
            lit: self.lit.clone(),
        }
    }

    fn push(&mut self, v: Box<WPoint>, e: Edge) {
        self.verts.push(v);
        self.edges.push(e);
    }

    /// Checks the invariants exactly: every vertex on the support plane and
    /// on its two edge planes, strictly inside the others.
    pub fn sanity_check(&self) -> Result<(), String> {
        let k = self.verts.len();
        if k < 3 || self.edges.len() != k {
            return Err(format!("{k} vertices, {} edges", self.edges.len()));
        }
        let support = WidePlane::from_plane(&self.support);
        for (i, v) in self.verts.iter().enumerate() {
            if v.classify(&support) != Side::On {
                return Err(format!("vertex {i} is off the support plane"));
            }
            for (j, e) in self.edges.iter().enumerate() {
                let incident = j == i || (j + 1) % k == i;
                let s = v.classify(&e.wide());
                if incident && s != Side::On {
                    return Err(format!("vertex {i} is off its edge plane {j}"));
                }
                if !incident && s != Side::Back {
                    return Err(format!("vertex {i} is not strictly inside edge plane {j}"));
                }
            }
        }
        Ok(())
    }
}
