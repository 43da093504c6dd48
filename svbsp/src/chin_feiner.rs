//! Chin & Feiner's (1989) shadow-volume BSP tree, exactly, for several
//! lights: the algorithm the core paper's dynamic pipeline builds on.
//!
//! The scene's BSP tree is traversed front to back as seen from the light
//! (a polygon later in that order never occludes an earlier one). Each
//! polygon's current fragments are filtered through the light's shadow
//! tree: pieces reaching `In` are in cast shadow; pieces reaching `Out`
//! are lit when the light is strictly in front of the polygon's plane,
//! else in attached shadow. Then the parts of the polygon the light sees —
//! whichever way it faces, since every face blocks light — graft their
//! shadow volumes onto the `Out` leaves they reached. Polygons of one node
//! are coplanar and cannot shadow one another, so all of a node's flags
//! are settled before its volumes are grafted.
//!
//! The fragments are pieces of the BSP's polygons, whose edges may lie on
//! other scene planes, so shadow planes through them leave the input tier:
//! they are `sign(P(L)) (P(L) E − E(L) P)` for support plane `P` and edge
//! plane `E`, with 140-bit normals and 168-bit offsets, and fragment
//! vertices are 512-bit points (see `docs/architecture.md`, "The shadow
//! tier"). Fragments live in one arena of points and refer to them by
//! index; a split makes each new vertex once. The split itself, the
//! filter and the invariant check are `bsp-core`'s, shared with every
//! other tier. [`crate::LightVolumes`] (partitioned shadow volumes) is the fast
//! path; this one is kept for the paper's pipeline and as an independent
//! cross-check.

use bsp_core::internals::{ConvexParts, check_convex, split_loop};
use bsp_core::{BspTree, Order, Plane, Polygon, SanityError, Side};
use smallvec::SmallVec;

use crate::light::{Light, LightError, MAX_LIGHTS};
use crate::wide::{WPoint, WidePlane};

/// An edge plane of a C&F fragment: an input plane, or a shadow plane of
/// the run's table (index, orientation bit).
#[derive(Clone, Copy, Debug)]
enum Edge {
    Input(Plane),
    Shadow(u32),
}

#[derive(Clone, Debug)]
struct Frag {
    support: Plane,
    edges: SmallVec<[Edge; 4]>,
    verts: SmallVec<[u32; 4]>,
    face: u32,
    polygon: u32,
    lit: u64,
}

/// The planes and points of one run.
struct Tables {
    points: Vec<WPoint>,
    /// Shadow planes; index `2 i` is plane `i`, `2 i + 1` its flip.
    shadow: Vec<WidePlane>,
}

impl Tables {
    fn add_shadow(&mut self, p: WidePlane) -> u32 {
        self.shadow.push(p);
        self.shadow.push(p.flip());
        (self.shadow.len() - 2) as u32
    }

    fn add_polygon(&mut self, p: &Polygon, polygon: u32) -> Frag {
        Frag {
            support: *p.support(),
            edges: p.edge_planes().iter().map(|e| Edge::Input(*e)).collect(),
            verts: p
                .vertices()
                .iter()
                .map(|v| {
                    self.points.push(WPoint::from_point(v));
                    (self.points.len() - 1) as u32
                })
                .collect(),
            face: p.tag(),
            polygon,
            lit: 0,
        }
    }

    /// Splits by shadow plane `h` (table index, even): front, back, or
    /// both pieces; a fragment in the plane (edge-on) counts as front.
    fn split(&mut self, f: Frag, h: u32) -> (Option<Frag>, Option<Frag>) {
        let plane = self.shadow[h as usize];
        let sides: SmallVec<[Side; 8]> = f
            .verts
            .iter()
            .map(|&v| self.points[v as usize].classify(&plane))
            .collect();
        let front = sides.contains(&Side::Front);
        let back = sides.contains(&Side::Back);
        match (front, back) {
            (_, false) => (Some(f), None),
            (false, true) => (None, Some(f)),
            (true, true) => {
                let support = WidePlane::from_plane(&f.support);
                let empty = || Frag {
                    support: f.support,
                    edges: SmallVec::new(),
                    verts: SmallVec::new(),
                    face: f.face,
                    polygon: f.polygon,
                    lit: f.lit,
                };
                let (mut a, mut b) = (empty(), empty());
                let (points, shadow) = (&mut self.points, &self.shadow);
                split_loop(
                    &f.verts,
                    &f.edges,
                    &sides,
                    Edge::Shadow(h + 1),
                    Edge::Shadow(h),
                    |i| {
                        let e = match &f.edges[i] {
                            Edge::Input(p) => WidePlane::from_plane(p),
                            Edge::Shadow(j) => shadow[*j as usize],
                        };
                        let x = WPoint::from_support_planes(&support, &e, &plane)
                            .expect("a spanning edge meets the cutting plane in one point");
                        points.push(x);
                        (points.len() - 1) as u32
                    },
                    |v, e| {
                        a.verts.push(v);
                        a.edges.push(e);
                    },
                    |v, e| {
                        b.verts.push(v);
                        b.edges.push(e);
                    },
                );
                (Some(a), Some(b))
            }
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum SvLink {
    Node(u32),
    In,
    Out,
}

#[derive(Clone, Copy, Debug)]
enum Slot {
    Root,
    Front(u32),
    Back(u32),
}

struct SvNode {
    /// Shadow-table index of the plane (even).
    plane: u32,
    front: SvLink,
    back: SvLink,
}

/// The shadow-volume tree of one light: inner nodes are shadow planes,
/// leaves are `In` (in shadow) or `Out` (lit).
struct ShadowTree {
    nodes: Vec<SvNode>,
    root: SvLink,
}

impl ShadowTree {
    /// Splits `frag` down the tree: the pieces that reach `In` leaves, and
    /// the pieces that reach `Out` leaves with the leaf's slot.
    fn filter(
        &self,
        t: &mut Tables,
        frag: Frag,
        inside: &mut Vec<Frag>,
        outside: &mut Vec<(Frag, Slot)>,
    ) {
        let mut stack = vec![(frag, self.root, Slot::Root)];
        while let Some((f, link, slot)) = stack.pop() {
            match link {
                SvLink::In => inside.push(f),
                SvLink::Out => outside.push((f, slot)),
                SvLink::Node(i) => {
                    let n = &self.nodes[i as usize];
                    // a fragment in a shadow plane contains the light in its
                    // plane: it is edge-on and lit nowhere; it goes in front
                    let (a, b) = t.split(f, n.plane);
                    if let Some(b) = b {
                        stack.push((b, n.back, Slot::Back(i)));
                    }
                    if let Some(a) = a {
                        stack.push((a, n.front, Slot::Front(i)));
                    }
                }
            }
        }
    }

    /// Replaces the `Out` leaf at `slot` by the shadow volume bounded by
    /// `planes` (interior behind each).
    fn graft(&mut self, slot: Slot, planes: &[u32]) {
        let mut link = SvLink::In;
        for &p in planes.iter().rev() {
            self.nodes.push(SvNode {
                plane: p,
                front: SvLink::Out,
                back: link,
            });
            link = SvLink::Node((self.nodes.len() - 1) as u32);
        }
        match slot {
            Slot::Root => self.root = link,
            Slot::Front(i) => self.nodes[i as usize].front = link,
            Slot::Back(i) => self.nodes[i as usize].back = link,
        }
    }
}

/// The shadow planes of a fragment that faces or backs onto `light`
/// (`a = light.eval(support) != 0`), oriented with the volume behind them.
///
/// An input edge `E` gives `sign(a) (a E − E(L) P)`. An edge that is
/// already a shadow plane was made by a split on the way to the fragment's
/// leaf, so the leaf's region already lies on the fragment's side of it:
/// it would add nothing, and is left out. No plane grows beyond the shadow
/// tier.
fn shadow_planes(t: &mut Tables, f: &Frag, light: &Light, a: i128) -> SmallVec<[u32; 4]> {
    f.edges
        .iter()
        .filter_map(|e| match e {
            Edge::Shadow(_) => None,
            Edge::Input(ep) => {
                let s = WidePlane::pencil(a, ep, light.eval(ep), &f.support, a < 0);
                (!s.is_degenerate()).then(|| t.add_shadow(s))
            }
        })
        .collect()
}

/// The fragments of a Chin & Feiner run: convex pieces of the scene BSP's
/// polygons, each exactly lit or in shadow for every light.
pub struct CfFragments {
    points: Vec<WPoint>,
    shadow: Vec<WidePlane>,
    frags: Vec<Frag>,
    /// Shadow-tree nodes, summed over the lights.
    pub shadow_nodes: usize,
}

/// One fragment of a [`CfFragments`].
#[derive(Clone, Copy)]
pub struct CfFragment<'a> {
    set: &'a CfFragments,
    f: &'a Frag,
}

impl<'a> CfFragment<'a> {
    /// The input face this fragment belongs to.
    pub fn face(&self) -> u32 {
        self.f.face
    }

    /// Index of the scene polygon this fragment is a piece of, in the
    /// node-major order of [`BspTree::polygons`].
    pub fn polygon(&self) -> u32 {
        self.f.polygon
    }

    /// Bit `i`: light `i` reaches the fragment's front side unobstructed.
    pub fn lit_mask(&self) -> u64 {
        self.f.lit
    }

    /// `true` if light `i` reaches it.
    pub fn lit(&self, i: usize) -> bool {
        self.f.lit >> i & 1 == 1
    }

    /// The support plane (the face's plane).
    pub fn support(&self) -> &'a Plane {
        &self.f.support
    }

    /// The exact vertices, counter-clockwise seen from the front.
    pub fn vertices(&self) -> impl Iterator<Item = &'a WPoint> + 'a {
        let set = self.set;
        self.f.verts.iter().map(move |&v| &set.points[v as usize])
    }

    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.f.verts.len()
    }

    /// Always `false`: a fragment has at least three vertices.
    pub fn is_empty(&self) -> bool {
        self.f.verts.is_empty()
    }

    /// Vertices in grid coordinates, correctly rounded.
    pub fn vertices_f64(&self) -> Vec<[f64; 3]> {
        self.vertices().map(WPoint::to_f64).collect()
    }

    /// Checks the invariants exactly (see [`check_convex`]).
    pub fn sanity_check(&self) -> Result<(), SanityError> {
        check_convex(self)
    }

    fn plane(&self, j: usize) -> WidePlane {
        match &self.f.edges[j] {
            Edge::Input(p) => WidePlane::from_plane(p),
            Edge::Shadow(i) => self.set.shadow[*i as usize],
        }
    }
}

impl ConvexParts for CfFragment<'_> {
    fn vertex_count(&self) -> usize {
        self.f.verts.len()
    }
    fn edge_count(&self) -> usize {
        self.f.edges.len()
    }
    fn support_side(&self, i: usize) -> Side {
        self.set.points[self.f.verts[i] as usize].classify(&WidePlane::from_plane(&self.f.support))
    }
    fn edge_side(&self, i: usize, j: usize) -> Side {
        self.set.points[self.f.verts[i] as usize].classify(&self.plane(j))
    }
    fn edge_is_support(&self, j: usize) -> bool {
        let s = WidePlane::from_plane(&self.f.support);
        let p = self.plane(j);
        p == s || p == s.flip()
    }
}

impl CfFragments {
    /// The fragments with some faces overlaid by another run's fragments:
    /// each fragment `q` of a face for which `base_of` lists fragments of
    /// `base` (by index) is replaced by its non-empty intersections with
    /// them, each lit by the lights that light both. With `base` the
    /// static scene's fragments and `self` a run over the polygons that
    /// moved and those near them, a face's flags become those of the whole
    /// scene (a point is lit when neither run's occluders block it). The
    /// intersections are exact: `q` is cut by the planes of each base
    /// fragment's edges.
    pub fn overlay<'b>(
        self,
        base: &CfFragments,
        base_of: impl Fn(u32) -> Option<&'b [u32]>,
    ) -> CfFragments {
        // boxes around the exact fragments: a correctly rounded coordinate
        // is within half an ulp of the exact one, so the neighbouring
        // doubles bound it on both sides; fragments whose boxes are apart
        // do not overlap, and are not cut against each other
        let bounds = |pts: &mut dyn Iterator<Item = [f64; 3]>| {
            let mut b = [
                f64::INFINITY,
                f64::INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::NEG_INFINITY,
                f64::NEG_INFINITY,
            ];
            for p in pts {
                for k in 0..3 {
                    b[k] = b[k].min(p[k].next_down());
                    b[k + 3] = b[k + 3].max(p[k].next_up());
                }
            }
            b
        };
        let apart = |a: &[f64; 6], b: &[f64; 6]| (0..3).any(|k| a[k + 3] < b[k] || b[k + 3] < a[k]);
        let mut base_box: Vec<Option<[f64; 6]>> = vec![None; base.frags.len()];
        let mut t = Tables {
            points: self.points,
            shadow: self.shadow,
        };
        let mut frags = Vec::with_capacity(self.frags.len());
        for q in self.frags {
            let Some(list) = base_of(q.face) else {
                frags.push(q);
                continue;
            };
            let qb = bounds(&mut q.verts.iter().map(|&v| t.points[v as usize].to_f64()));
            for &si in list {
                let sf = base.get(si as usize);
                let sb = *base_box[si as usize]
                    .get_or_insert_with(|| bounds(&mut sf.vertices().map(WPoint::to_f64)));
                if apart(&qb, &sb) {
                    continue;
                }
                let mut piece = Some(q.clone());
                for j in 0..sf.f.edges.len() {
                    let Some(r) = piece.take() else { break };
                    let h = t.add_shadow(sf.plane(j));
                    // the fragment lies behind its edge planes
                    piece = t.split(r, h).1;
                }
                if let Some(mut r) = piece {
                    r.lit &= sf.f.lit;
                    frags.push(r);
                }
            }
        }
        CfFragments {
            points: t.points,
            shadow: t.shadow,
            frags,
            shadow_nodes: self.shadow_nodes,
        }
    }

    /// Number of fragments.
    pub fn len(&self) -> usize {
        self.frags.len()
    }

    /// `true` if there are none.
    pub fn is_empty(&self) -> bool {
        self.frags.is_empty()
    }

    /// Fragment `i`.
    pub fn get(&self, i: usize) -> CfFragment<'_> {
        CfFragment {
            set: self,
            f: &self.frags[i],
        }
    }

    /// Every fragment, grouped by scene polygon in the node-major polygon
    /// order of the tree.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = CfFragment<'_>> + '_ {
        self.frags.iter().map(move |f| CfFragment { set: self, f })
    }
}

/// Exact lit and shadowed fragments of every polygon of `tree` for each of
/// `lights`, by Chin & Feiner's algorithm (see the module docs).
///
/// With several lights, each light refines the previous fragments, so the
/// result is the overlay of the per-light partitions of every polygon.
pub fn chin_feiner(tree: &BspTree, lights: &[Light]) -> Result<CfFragments, LightError> {
    if lights.len() > MAX_LIGHTS {
        return Err(LightError::TooMany(lights.len()));
    }
    for l in lights {
        l.validate()?;
    }
    let polys: Vec<&Polygon> = tree.polygons().collect();
    let first = tree.polygon_offsets();
    let mut t = Tables {
        points: Vec::new(),
        shadow: Vec::new(),
    };
    let mut frags: Vec<Vec<Frag>> = polys
        .iter()
        .enumerate()
        .map(|(i, p)| vec![t.add_polygon(p, i as u32)])
        .collect();
    let mut shadow_nodes = 0;
    let (mut inside, mut outside) = (Vec::new(), Vec::new());
    for (j, light) in lights.iter().enumerate() {
        let mut sv = ShadowTree {
            nodes: Vec::new(),
            root: SvLink::Out,
        };
        let mut order = Vec::with_capacity(tree.nodes().len());
        tree.traverse_nodes_by(
            |p| light.eval(p) >= 0,
            Order::FrontToBack,
            |id, _| order.push(id),
        );
        for node in order {
            let range = first[node as usize]..first[node as usize + 1];
            // flags first: coplanar polygons do not shadow one another
            for pi in range.clone() {
                let a = light.eval(polys[pi].support());
                let current = std::mem::take(&mut frags[pi]);
                let mut next = Vec::with_capacity(current.len());
                for f in current {
                    if a <= 0 {
                        next.push(f);
                        continue;
                    }
                    inside.clear();
                    outside.clear();
                    sv.filter(&mut t, f, &mut inside, &mut outside);
                    next.append(&mut inside);
                    for (mut f, _) in outside.drain(..) {
                        f.lit |= 1 << j;
                        next.push(f);
                    }
                }
                frags[pi] = next;
            }
            // then the volumes of what the light sees of each polygon
            for pi in range {
                let a = light.eval(polys[pi].support());
                if a == 0 {
                    continue; // edge-on: no volume
                }
                inside.clear();
                outside.clear();
                // the pieces of this pass only give their edges' planes:
                // their points are dropped after the graft
                let mark = t.points.len();
                let whole = t.add_polygon(polys[pi], pi as u32);
                sv.filter(&mut t, whole, &mut inside, &mut outside);
                for (f, slot) in outside.drain(..) {
                    let planes = shadow_planes(&mut t, &f, light, a);
                    sv.graft(slot, &planes);
                }
                inside.clear();
                t.points.truncate(mark);
            }
        }
        shadow_nodes += sv.nodes.len();
    }
    Ok(CfFragments {
        points: t.points,
        shadow: t.shadow,
        frags: frags.into_iter().flatten().collect(),
        shadow_nodes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use bsp_core::BuildOptions;

    fn quad(z: i32, lo: i32, hi: i32, tag: u32) -> Polygon {
        Polygon::from_grid_points(&[[lo, lo, z], [hi, lo, z], [hi, hi, z], [lo, hi, z]], tag)
            .unwrap()
    }

    #[test]
    fn occluder_casts_exact_shadow() {
        let tree = BspTree::build(
            vec![quad(0, 0, 8, 0), quad(4, 2, 4, 1)],
            &BuildOptions::default(),
        );
        let out = chin_feiner(&tree, &[Light::Point([3, 3, 8])]).unwrap();
        for f in out.iter() {
            f.sanity_check().unwrap();
        }
        let shadowed: Vec<_> = out.iter().filter(|f| f.face() == 0 && !f.lit(0)).collect();
        assert_eq!(shadowed.len(), 1);
        let mut v = shadowed[0].vertices_f64();
        v.sort_by(|a, b| a.partial_cmp(b).unwrap());
        assert_eq!(
            v,
            vec![
                [1.0, 1.0, 0.0],
                [1.0, 5.0, 0.0],
                [5.0, 1.0, 0.0],
                [5.0, 5.0, 0.0]
            ]
        );
        assert!(out.iter().filter(|f| f.face() == 1).all(|f| f.lit(0)));
    }

    #[test]
    fn sun_and_back_faces() {
        let occ = quad(4, 2, 4, 1).flipped();
        let tree = BspTree::build(vec![quad(0, 0, 8, 0), occ], &BuildOptions::default());
        let out = chin_feiner(
            &tree,
            &[Light::Directional([0, 0, 1]), Light::Point([3, 3, -8])],
        )
        .unwrap();
        let mut v: Vec<[f64; 3]> = out
            .iter()
            .filter(|f| f.face() == 0 && !f.lit(0))
            .flat_map(|f| f.vertices_f64())
            .collect();
        v.sort_by(|a, b| a.partial_cmp(b).unwrap());
        v.dedup();
        assert_eq!(
            v,
            vec![
                [2.0, 2.0, 0.0],
                [2.0, 4.0, 0.0],
                [4.0, 2.0, 0.0],
                [4.0, 4.0, 0.0]
            ]
        );
        assert!(
            out.iter()
                .filter(|f| f.face() == 1)
                .all(|f| !f.lit(0) && !f.lit(1))
        );
        assert!(out.iter().filter(|f| f.face() == 0).all(|f| !f.lit(1)));
    }

    #[test]
    fn node_traversal_is_the_tree_order() {
        // the traversal by plane sides is the tree's own front-to-back
        // order from a grid viewpoint
        let tree = BspTree::build(
            vec![quad(0, 0, 8, 0), quad(4, 2, 4, 1), quad(2, 1, 3, 2)],
            &BuildOptions::default(),
        );
        let eye = bsp_core::ViewPoint::new([3, 3, 8]).unwrap();
        let (mut a, mut b) = (vec![], vec![]);
        tree.traverse_nodes(eye, Order::FrontToBack, |id, _| a.push(id));
        let light = Light::Point([3, 3, 8]);
        tree.traverse_nodes_by(
            |p| light.eval(p) >= 0,
            Order::FrontToBack,
            |id, _| b.push(id),
        );
        assert_eq!(a, b);
    }
}
