//! Chin & Feiner's shadow-volume BSP tree, exactly, for several lights.

use bsp_core::{BspTree, Link, MAX_COORD, Plane, Polygon};

use std::sync::Arc;

use crate::fragment::{Edge, FragSplit, Fragment};
use crate::wide::WidePlane;

/// A light source, on the scene's grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Light {
    /// A point light at grid coordinates (each `|c| <= MAX_COORD`).
    Point([i32; 3]),
    /// A light at infinity ("sun"): an integer direction from the scene
    /// toward the light, non-zero, each `|c| <= MAX_COORD`.
    Directional([i32; 3]),
}

/// Why a light is unusable.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum LightError {
    /// A coordinate exceeds the grid.
    OutOfGrid,
    /// A directional light with a zero direction.
    ZeroDirection,
}

impl std::fmt::Display for LightError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LightError::OutOfGrid => f.write_str("light coordinate outside the grid"),
            LightError::ZeroDirection => f.write_str("sun direction is zero"),
        }
    }
}

impl std::error::Error for LightError {}

impl Light {
    /// Checks the coordinate bounds the arithmetic budget relies on.
    pub fn validate(&self) -> Result<(), LightError> {
        let c = match self {
            Light::Point(c) | Light::Directional(c) => c,
        };
        if c.iter().any(|v| v.unsigned_abs() > MAX_COORD as u32) {
            return Err(LightError::OutOfGrid);
        }
        if matches!(self, Light::Directional([0, 0, 0])) {
            return Err(LightError::ZeroDirection);
        }
        Ok(())
    }

    /// The plane's value at the light in homogeneous form: `n · L + d` for a
    /// point light, `n · D` for a directional one. Positive when the light
    /// is in front. `|value| < 2^84`.
    pub fn eval(&self, p: &Plane) -> i128 {
        let n = p.normal();
        let dot = |c: &[i32; 3]| (0..3).map(|k| n[k] as i128 * c[k] as i128).sum::<i128>();
        match self {
            Light::Point(c) => dot(c) + p.offset(),
            Light::Directional(c) => dot(c),
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
    plane: Arc<WidePlane>,
    flipped: Arc<WidePlane>,
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
    fn new() -> ShadowTree {
        ShadowTree {
            nodes: Vec::new(),
            root: SvLink::Out,
        }
    }

    /// Splits `frag` down the tree: the pieces that reach `In` leaves, and
    /// the pieces that reach `Out` leaves with the leaf's slot.
    fn filter(
        &self,
        frag: Fragment,
        inside: &mut Vec<Fragment>,
        outside: &mut Vec<(Fragment, Slot)>,
    ) {
        let mut stack = vec![(frag, self.root, Slot::Root)];
        while let Some((f, link, slot)) = stack.pop() {
            match link {
                SvLink::In => inside.push(f),
                SvLink::Out => outside.push((f, slot)),
                SvLink::Node(i) => {
                    let n = &self.nodes[i as usize];
                    match f.split(&n.plane, &n.flipped) {
                        FragSplit::Front(f) => stack.push((f, n.front, Slot::Front(i))),
                        FragSplit::Back(f) => stack.push((f, n.back, Slot::Back(i))),
                        // a fragment in a shadow plane contains the light in
                        // its plane: it is edge-on and lit nowhere; send it
                        // anywhere
                        FragSplit::On(f) => stack.push((f, n.front, Slot::Front(i))),
                        FragSplit::Spanning(a, b) => {
                            stack.push((a, n.front, Slot::Front(i)));
                            stack.push((b, n.back, Slot::Back(i)));
                        }
                    }
                }
            }
        }
    }

    /// Replaces the `Out` leaf at `slot` by the shadow volume bounded by
    /// `planes` (interior behind each).
    fn graft(&mut self, slot: Slot, planes: &[Arc<WidePlane>]) {
        let mut link = SvLink::In;
        for p in planes.iter().rev() {
            self.nodes.push(SvNode {
                plane: p.clone(),
                flipped: Arc::new(p.flip()),
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
fn shadow_planes(f: &Fragment, light: &Light, a: i128) -> Vec<Arc<WidePlane>> {
    f.edges()
        .iter()
        .filter_map(|e| match e {
            Edge::Shadow(_) => None,
            Edge::Input(ep) => {
                let s = WidePlane::pencil(a, ep, light.eval(ep), f.support(), a < 0);
                (!s.is_degenerate()).then(|| Arc::new(s))
            }
        })
        .collect()
}

/// The scene's nodes in front-to-back order as seen from `light`.
fn order_from(tree: &BspTree, light: &Light) -> Vec<u32> {
    enum Item {
        Visit(Link),
        Emit(u32),
    }
    let mut out = Vec::with_capacity(tree.nodes().len());
    let mut stack = vec![Item::Visit(tree.root())];
    while let Some(item) = stack.pop() {
        match item {
            Item::Visit(Link::Cell(_)) => {}
            Item::Visit(Link::Node(id)) => {
                let n = tree.node(id);
                let (near, far) = if light.eval(&n.plane) >= 0 {
                    (n.front, n.back)
                } else {
                    (n.back, n.front)
                };
                stack.push(Item::Visit(far));
                stack.push(Item::Emit(id));
                stack.push(Item::Visit(near));
            }
            Item::Emit(id) => out.push(id),
        }
    }
    out
}

/// Figures of one run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ShadowStats {
    /// Scene polygons (after BSP splitting).
    pub polygons: usize,
    /// Fragments produced.
    pub fragments: usize,
    /// Shadow-tree nodes, summed over the lights.
    pub shadow_nodes: usize,
}

/// Exact lit and shadowed fragments of every polygon of `tree` for each of
/// `lights`.
///
/// For each light in turn, the scene's BSP is traversed front to back as
/// seen from the light (a polygon later in that order never occludes an
/// earlier one). Each polygon's current fragments are filtered through the
/// light's shadow tree: pieces reaching `In` are in cast shadow; pieces
/// reaching `Out` are lit when the light is strictly in front of the
/// polygon's plane, else in attached shadow. Then the polygon's parts
/// visible from the light — whichever way it faces, since every face blocks
/// light — graft their shadow volumes onto the `Out` leaves they reached.
/// Polygons of one node are coplanar and cannot shadow one another, so all
/// of a node's flags are settled before its volumes are grafted.
///
/// With several lights, each light refines the previous fragments, so the
/// result is the overlay of the per-light partitions of every face: each
/// fragment is entirely lit or entirely shadowed for every light.
///
/// Fragments come out grouped by scene polygon, in the node-major polygon
/// order of the tree ([`Fragment::polygon`]).
pub fn shadow_fragments(
    tree: &BspTree,
    lights: &[Light],
) -> Result<(Vec<Fragment>, ShadowStats), LightError> {
    for l in lights {
        l.validate()?;
    }
    // per scene polygon: its current fragments
    let polys: Vec<&Polygon> = tree.polygons().collect();
    let first = tree.polygon_offsets();
    let mut frags: Vec<Vec<Fragment>> = polys
        .iter()
        .enumerate()
        .map(|(i, p)| vec![Fragment::from_polygon(p, i as u32)])
        .collect();
    let mut stats = ShadowStats {
        polygons: polys.len(),
        ..ShadowStats::default()
    };
    let (mut inside, mut outside) = (Vec::new(), Vec::new());
    for light in lights {
        let mut sv = ShadowTree::new();
        for node in order_from(tree, light) {
            let range = first[node as usize]..first[node as usize + 1];
            // flags first: coplanar polygons do not shadow one another
            for pi in range.clone() {
                let a = light.eval(polys[pi].support());
                let current = std::mem::take(&mut frags[pi]);
                let mut next = Vec::with_capacity(current.len());
                for f in current {
                    if a <= 0 {
                        let mut f = f;
                        f.lit.push(false);
                        next.push(f);
                        continue;
                    }
                    inside.clear();
                    outside.clear();
                    sv.filter(f, &mut inside, &mut outside);
                    for mut f in inside.drain(..) {
                        f.lit.push(false);
                        next.push(f);
                    }
                    for (mut f, _) in outside.drain(..) {
                        f.lit.push(true);
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
                sv.filter(
                    Fragment::from_polygon(polys[pi], pi as u32),
                    &mut inside,
                    &mut outside,
                );
                for (f, slot) in outside.drain(..) {
                    let planes = shadow_planes(&f, light, a);
                    sv.graft(slot, &planes);
                }
            }
        }
        stats.shadow_nodes += sv.nodes.len();
    }
    let out: Vec<Fragment> = frags.into_iter().flatten().collect();
    stats.fragments = out.len();
    Ok((out, stats))
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
        // floor 0..8 at z = 0, occluder 2..4 at z = 4, light above at z = 8
        let floor = quad(0, 0, 8, 0);
        let occ = quad(4, 2, 4, 1);
        let tree = BspTree::build(vec![floor, occ], &BuildOptions::default());
        let (frags, _) = shadow_fragments(&tree, &[Light::Point([3, 3, 8])]).unwrap();
        for f in &frags {
            f.sanity_check().unwrap();
        }
        let shadowed: Vec<_> = frags.iter().filter(|f| f.face == 0 && !f.lit[0]).collect();
        assert_eq!(shadowed.len(), 1);
        // the shadow of [2,4]^2 at height 4 from (3,3,8) on z = 0 is [1,5]^2
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
        assert!(frags.iter().filter(|f| f.face == 1).all(|f| f.lit[0]));
    }

    #[test]
    fn sun_and_back_faces() {
        let floor = quad(0, 0, 8, 0);
        let occ = quad(4, 2, 4, 1).flipped(); // faces down, still blocks
        let tree = BspTree::build(vec![floor, occ], &BuildOptions::default());
        let (frags, _) = shadow_fragments(
            &tree,
            &[Light::Directional([0, 0, 1]), Light::Point([3, 3, -8])],
        )
        .unwrap();
        let shadowed: Vec<_> = frags.iter().filter(|f| f.face == 0 && !f.lit[0]).collect();
        let mut v: Vec<[f64; 3]> = shadowed.iter().flat_map(|f| f.vertices_f64()).collect();
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
        // the occluder faces away from the sun: attached shadow; the light
        // below faces its front but the floor, facing away, still blocks it
        assert!(
            frags
                .iter()
                .filter(|f| f.face == 1)
                .all(|f| !f.lit[0] && !f.lit[1])
        );
        // the floor faces up: the light below leaves it in attached shadow
        assert!(frags.iter().filter(|f| f.face == 0).all(|f| !f.lit[1]));
    }
}
