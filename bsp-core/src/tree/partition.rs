//! Labelled BSP partitions and their merging (Naylor, Amanatides &
//! Thibault 1990): set operations ∪ ∩ − and the overlay "+".
//!
//! A [`Partition`] is a BSP tree whose leaves carry a label (a [`Cell`] for
//! solids, a pair of labels for an overlay) and whose nodes know their
//! *sub-hyperplane*: the convex polygon where the node's plane meets the
//! node's region, bounded by the grid's box. Sub-hyperplanes are ordinary
//! plane-based [`Polygon`]s whose edge planes are ancestor planes and box
//! planes, so they stay inside the arithmetic budget however often they are
//! split.
//!
//! Merging partitions the second tree by the first tree's sub-hyperplanes
//! and combines the labels of coinciding cells with a [`CellOp`]. Every
//! operation here runs on explicit work stacks.

use crate::kernel::{MAX_COORD, Plane, Point, Polygon, PolygonSide, SanityError, Side, Split};

use super::{
    Ancestor, BspTree, BuildOptions, Cell, Link, Membership, Node, NodeId, check_ancestors,
    push_down_by, walk_checked,
};

/// Half-width of the box that bounds every sub-hyperplane: `2^26`, just
/// outside every grid coordinate.
pub(crate) const BOX_HALF: i64 = MAX_COORD as i64 + 1;

/// A child reference of a [`Partition`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PLink<L> {
    /// An inner node (index into [`Partition::nodes`]).
    Node(u32),
    /// A leaf with its label.
    Leaf(L),
}

/// An inner node of a [`Partition`].
#[derive(Clone, Debug)]
pub struct PNode<L> {
    /// The partitioning plane.
    pub plane: Plane,
    /// The sub-hyperplane: `plane` ∩ this node's region (within the box).
    pub shp: Polygon,
    /// Input polygons lying in `plane` within this node's region.
    pub polygons: Vec<Polygon>,
    /// Subtree in front.
    pub front: PLink<L>,
    /// Subtree behind.
    pub back: PLink<L>,
}

/// A BSP partition of the grid's box with labelled cells.
#[derive(Clone, Debug)]
pub struct Partition<L> {
    nodes: Vec<PNode<L>>,
    root: PLink<L>,
}

/// How merging combines the labels of two coinciding cells.
pub trait CellOp<A, B> {
    /// The label of the result.
    type Out;
    /// The label of `c1 ∩ c2`.
    fn apply(&self, a: A, b: B) -> Self::Out;
    /// The result when the first cell has label `a`, if it does not depend
    /// on the second (e.g. `In ∪ anything = In`); saves visiting a subtree.
    fn left(&self, a: A) -> Option<Self::Out> {
        let _ = a;
        None
    }
    /// As [`CellOp::left`], for the second cell.
    fn right(&self, b: B) -> Option<Self::Out> {
        let _ = b;
        None
    }
    /// `true` if a node that carries input polygons must stay even when
    /// its two sides end up as one cell: the overlay of polygon trees
    /// keeps every polygon, a set operation drops the ones that no longer
    /// bound anything.
    fn keeps_polygons(&self) -> bool {
        false
    }
}

/// The Boolean set operations on solid partitions (Table 1 of the core
/// paper).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BoolOp {
    /// A ∪ B.
    Union,
    /// A ∩ B.
    Intersection,
    /// A − B.
    Difference,
}

impl CellOp<Cell, Cell> for BoolOp {
    type Out = Cell;
    fn apply(&self, a: Cell, b: Cell) -> Cell {
        let (a, b) = (a == Cell::In, b == Cell::In);
        let r = match self {
            BoolOp::Union => a || b,
            BoolOp::Intersection => a && b,
            BoolOp::Difference => a && !b,
        };
        if r { Cell::In } else { Cell::Out }
    }
    fn left(&self, a: Cell) -> Option<Cell> {
        match (self, a) {
            (BoolOp::Union, Cell::In) => Some(Cell::In),
            (BoolOp::Intersection | BoolOp::Difference, Cell::Out) => Some(Cell::Out),
            _ => None,
        }
    }
    fn right(&self, b: Cell) -> Option<Cell> {
        match (self, b) {
            (BoolOp::Union, Cell::In) => Some(Cell::In),
            (BoolOp::Intersection, Cell::Out) | (BoolOp::Difference, Cell::In) => Some(Cell::Out),
            _ => None,
        }
    }
}

/// The overlay "+": every cell of the result is a non-empty `c1 ∩ c2`
/// labelled with both labels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Overlay;

impl<A, B> CellOp<A, B> for Overlay {
    type Out = (A, B);
    fn apply(&self, a: A, b: B) -> (A, B) {
        (a, b)
    }
    fn keeps_polygons(&self) -> bool {
        true
    }
}

/// An operation with its arguments swapped (to insert the smaller tree).
struct Swapped<'a, O>(&'a O);

impl<A, B, O: CellOp<A, B>> CellOp<B, A> for Swapped<'_, O> {
    type Out = O::Out;
    fn apply(&self, b: B, a: A) -> O::Out {
        self.0.apply(a, b)
    }
    fn left(&self, b: B) -> Option<O::Out> {
        self.0.right(b)
    }
    fn right(&self, a: A) -> Option<O::Out> {
        self.0.left(a)
    }
    fn keeps_polygons(&self) -> bool {
        self.0.keeps_polygons()
    }
}

/// The box plane `sign · x_axis - BOX_HALF = 0` (interior behind).
fn box_plane(axis: usize, sign: i64) -> Plane {
    let mut n = [0i64; 3];
    n[axis] = sign;
    Plane::new(n, -(BOX_HALF as i128)).expect("box planes are in budget")
}

/// `plane` ∩ the grid's box, as a convex polygon whose edge planes are box
/// planes. Every plane through grid points meets the box.
pub fn box_section(plane: &Plane) -> Option<Polygon> {
    let k = plane.dominant_axis();
    let (a, b) = ((k + 1) % 3, (k + 2) % 3);
    // counter-clockwise in (a, b) seen along +k: the sides b = -B, a = +B,
    // b = +B, a = -B
    let mut edges = vec![
        box_plane(b, -1),
        box_plane(a, 1),
        box_plane(b, 1),
        box_plane(a, -1),
    ];
    if plane.normal()[k] < 0 {
        edges.reverse();
    }
    let mut poly = Polygon::from_planes(*plane, &edges, 0)?;
    for sign in [1, -1] {
        poly = match poly.split(&box_plane(k, sign)) {
            Split::Back(p) => p,
            Split::Spanning { back, .. } => back,
            Split::Front(_) | Split::Coplanar { .. } => return None,
        };
    }
    Some(poly)
}

/// `plane` ∩ an axis-aligned box given by its six faces in the order
/// `−x, +x, −y, +y, −z, +z` (interior behind each), built like
/// [`box_section`] from the box's own faces rather than clipped down from
/// the grid's box: fewer intersection points to construct. `None` if
/// `walls` is not such a box or the plane misses it.
fn section_in(plane: &Plane, walls: &[Plane]) -> Option<Polygon> {
    let aligned = walls.len() == 6
        && walls.iter().enumerate().all(|(i, w)| {
            let (k, up) = (i / 2, i % 2 == 1);
            let n = w.normal();
            (0..3).all(|j| {
                if j == k {
                    (n[j] > 0) == up && n[j] != 0
                } else {
                    n[j] == 0
                }
            })
        });
    if !aligned {
        return None;
    }
    let k = plane.dominant_axis();
    let (a, b) = ((k + 1) % 3, (k + 2) % 3);
    let w = |axis: usize, up: bool| walls[2 * axis + up as usize];
    let mut edges = vec![w(b, false), w(a, true), w(b, true), w(a, false)];
    if plane.normal()[k] < 0 {
        edges.reverse();
    }
    let mut poly = Polygon::from_planes(*plane, &edges, 0)?;
    for up in [true, false] {
        poly = match poly.split(&w(k, up)) {
            Split::Back(p) => p,
            Split::Spanning { back, .. } => back,
            Split::Front(_) | Split::Coplanar { .. } => return None,
        };
    }
    Some(poly)
}

/// Options of [`Partition::solid`]: the BSP build with a balance cut
/// tried first on every list above 64 polygons, which keeps convex meshes
/// from turning into chains.
pub(crate) fn solid_build_options() -> BuildOptions {
    BuildOptions {
        cut_always: true,
        ..BuildOptions::default().with_cut_threshold(64)
    }
}

impl Partition<Cell> {
    /// The solid bounded by `polygons`, which must tile the boundary of a
    /// closed, consistently oriented solid (outward normals). Node polygons
    /// are not kept: set operations only need cells and sub-hyperplanes.
    pub fn solid(polygons: Vec<Polygon>) -> Partition<Cell> {
        let tree = BspTree::build(polygons, &solid_build_options());
        let mut p = Partition::from_tree(&tree);
        p.clear_polygons();
        p
    }

    /// The solid partition of a solid BSP tree (see [`BspTree`]): the same
    /// planes, polygons and cells, with each node's sub-hyperplane computed
    /// by clipping its plane's box section by the ancestors' half-spaces.
    pub fn from_tree(tree: &BspTree) -> Partition<Cell> {
        Partition::from_tree_with(tree, &[], |c| c)
    }
}

impl Partition<u32> {
    /// The partition of a BSP tree within a convex region: every
    /// sub-hyperplane is clipped to the back of each plane of `walls` (the
    /// region's faces, interior behind), and leaves are numbered `0..n` in
    /// the order they are made, for labels found later (returned with
    /// `n`). Every node's polygons must lie inside the region.
    pub fn from_tree_in(tree: &BspTree, walls: &[Plane]) -> (Partition<u32>, u32) {
        let mut n = 0;
        let p = Partition::from_tree_with(tree, walls, |_| {
            n += 1;
            n - 1
        });
        (p, n)
    }
}

impl<L: Copy> Partition<L> {
    fn from_tree_with(
        tree: &BspTree,
        walls: &[Plane],
        mut leaf: impl FnMut(Cell) -> L,
    ) -> Partition<L> {
        let mut out: Partition<L> = Partition {
            nodes: Vec::with_capacity(tree.nodes().len()),
            root: PLink::Node(0),
        };
        // (tree link, depth, edge to parent, slot to patch)
        let mut path: Vec<(Plane, Side)> = Vec::new();
        type Item = (Link, usize, Option<Ancestor>, Option<(u32, Side)>);
        let mut stack: Vec<Item> = vec![(tree.root(), 0, None, None)];
        while let Some((link, depth, edge, slot)) = stack.pop() {
            path.truncate(depth);
            if let Some(e) = edge {
                path.push(e);
            }
            let v = match link {
                Link::Cell(c) => PLink::Leaf(leaf(c)),
                Link::Node(id) => {
                    let n = tree.node(id);
                    // an axis-aligned region's section directly, else the
                    // grid box's section clipped to the walls
                    let (mut shp, rest) = match section_in(&n.plane, walls) {
                        Some(p) => (p, &[][..]),
                        None => (
                            box_section(&n.plane)
                                .expect("a plane through grid points meets the box"),
                            walls,
                        ),
                    };
                    // nearest ancestors first: they cut the box section
                    // down early, and the far ones then rarely split it;
                    // the region's walls last
                    let ancestors = path.iter().rev().map(|(p, s)| (p, *s));
                    for (p, s) in ancestors.chain(rest.iter().map(|w| (w, Side::Back))) {
                        let kept = shp.clip(p, s);
                        assert!(
                            kept,
                            "a node's plane meets its region (its polygons lie there)"
                        );
                    }
                    let me = out.nodes.len() as u32;
                    out.nodes.push(PNode {
                        plane: n.plane,
                        shp,
                        polygons: n.polygons.clone(),
                        front: PLink::Node(u32::MAX), // patched below
                        back: PLink::Node(u32::MAX),
                    });
                    let d = path.len();
                    stack.push((
                        n.back,
                        d,
                        Some((n.plane, Side::Back)),
                        Some((me, Side::Back)),
                    ));
                    stack.push((
                        n.front,
                        d,
                        Some((n.plane, Side::Front)),
                        Some((me, Side::Front)),
                    ));
                    PLink::Node(me)
                }
            };
            match slot {
                None => out.root = v,
                Some((p, Side::Front)) => out.nodes[p as usize].front = v,
                Some((p, _)) => out.nodes[p as usize].back = v,
            }
        }
        out
    }
}

impl Partition<Cell> {
    /// Exact point membership (see [`BspTree::classify_point`]).
    pub fn classify_point(&self, p: &Point) -> Membership {
        let labels = self.locate(p);
        let has_in = labels.contains(&Cell::In);
        let has_out = labels.contains(&Cell::Out);
        match (has_in, has_out) {
            (true, true) => Membership::Boundary,
            (true, false) => Membership::Inside,
            _ => Membership::Outside,
        }
    }

    /// The complement: every label flipped.
    pub fn complement(&self) -> Partition<Cell> {
        self.map_labels(|c| match c {
            Cell::In => Cell::Out,
            Cell::Out => Cell::In,
        })
    }

    /// `self op other`, inserting the smaller tree into the larger.
    pub fn boolean(&self, other: &Partition<Cell>, op: BoolOp) -> Partition<Cell> {
        merge_smaller_into_larger(self, other, &op)
    }

    /// The boundary of the solid: the pieces of every sub-hyperplane that
    /// separate an `In` cell from an `Out` cell, oriented outward (front
    /// toward `Out`). Tags are 0.
    pub fn boundary(&self) -> Vec<Polygon> {
        let mut out = Vec::new();
        for n in &self.nodes {
            for (piece, front) in self.push_down(n.shp.clone(), n.front) {
                for (piece, back) in self.push_down(piece, n.back) {
                    match (front, back) {
                        (Cell::Out, Cell::In) => out.push(piece),
                        (Cell::In, Cell::Out) => out.push(piece.flipped()),
                        _ => {}
                    }
                }
            }
        }
        out
    }
}

/// Merges, choosing which tree to partition by the other's planes so that
/// the smaller one is inserted.
pub fn merge_smaller_into_larger<A, B, O>(
    a: &Partition<A>,
    b: &Partition<B>,
    op: &O,
) -> Partition<O::Out>
where
    A: Copy,
    B: Copy,
    O: CellOp<A, B>,
    O::Out: Copy + PartialEq,
{
    if a.nodes.len() >= b.nodes.len() {
        merge(a, b, op)
    } else {
        merge(b, a, &Swapped(op))
    }
}

#[derive(Clone, Copy)]
enum BSlot {
    Front(u32),
    Back(u32),
    Temp(usize),
}

#[derive(Clone, Copy)]
enum OSlot {
    Root,
    Front(u32),
    Back(u32),
}

#[derive(Clone, Copy)]
enum BSource<B> {
    Link(PLink<B>),
    Temp(usize),
}

// Tasks live briefly on the work stack; boxing the polygon would cost an
// allocation per task for no gain.
#[allow(clippy::large_enum_variant)]
enum Task<A, B> {
    Partition {
        t: PLink<B>,
        h: Polygon,
        plus: BSlot,
        minus: BSlot,
        collect: u32,
    },
    Merge {
        a: PLink<A>,
        b: BSource<B>,
        out: OSlot,
    },
    CopyA {
        a: PLink<A>,
        b: B,
        out: OSlot,
    },
    CopyB {
        a: A,
        b: PLink<B>,
        out: OSlot,
    },
}

/// Merges two partitions of the same box: `a`'s structure is kept and `b`
/// is partitioned by `a`'s sub-hyperplanes (so `b` should be the smaller;
/// see [`merge_smaller_into_larger`]). Each cell of the result is a
/// non-empty intersection of a cell of each input, labelled
/// `op.apply(label_a, label_b)`; polygons of both inputs are carried to the
/// result's nodes. The result is reduced (nodes whose two children are
/// leaves with equal labels collapse).
pub fn merge<A, B, O>(a: &Partition<A>, b: &Partition<B>, op: &O) -> Partition<O::Out>
where
    A: Copy,
    B: Copy,
    O: CellOp<A, B>,
    O::Out: Copy + PartialEq,
{
    let mut m = Merger {
        a,
        op,
        bn: b.nodes.clone(),
        temps: Vec::new(),
        out: Partition {
            nodes: Vec::new(),
            root: PLink::Leaf(op.apply(first_leaf(a), first_leaf(b))),
        },
        stack: vec![Task::Merge {
            a: a.root,
            b: BSource::Link(b.root),
            out: OSlot::Root,
        }],
    };
    while let Some(task) = m.stack.pop() {
        match task {
            Task::Merge { a, b, out } => m.merge_links(a, b, out),
            Task::CopyA { a, b, out } => m.copy_a(a, b, out),
            Task::CopyB { a, b, out } => m.copy_b(a, b, out),
            Task::Partition {
                t,
                h,
                plus,
                minus,
                collect,
            } => m.partition(t, h, (plus, minus), collect),
        }
    }
    let mut out = m.out;
    out.reduce_nodes(op.keeps_polygons());
    out
}

/// The state of a [`merge`]: `a`, the nodes of `b` as they are cut by
/// `a`'s sub-hyperplanes, the pieces of `b` waiting to be merged, the
/// result so far and the work stack (no recursion: any depth is fine).
struct Merger<'p, A, B, O: CellOp<A, B>> {
    a: &'p Partition<A>,
    op: &'p O,
    bn: Vec<PNode<B>>,
    temps: Vec<Option<PLink<B>>>,
    out: Partition<O::Out>,
    stack: Vec<Task<A, B>>,
}

impl<A, B, O> Merger<'_, A, B, O>
where
    A: Copy,
    B: Copy,
    O: CellOp<A, B>,
    O::Out: Copy + PartialEq,
{
    /// Hangs `v` at slot `s` of `b`'s nodes or of the waiting pieces.
    fn put_b(&mut self, s: BSlot, v: PLink<B>) {
        match s {
            BSlot::Front(i) => self.bn[i as usize].front = v,
            BSlot::Back(i) => self.bn[i as usize].back = v,
            BSlot::Temp(i) => self.temps[i] = Some(v),
        }
    }

    /// Hangs `v` at slot `s` of the result.
    fn put_o(&mut self, s: OSlot, v: PLink<O::Out>) {
        match s {
            OSlot::Root => self.out.root = v,
            OSlot::Front(i) => self.out.nodes[i as usize].front = v,
            OSlot::Back(i) => self.out.nodes[i as usize].back = v,
        }
    }

    /// Merges a subtree of `a` with a subtree of `b` (or a piece of `b`
    /// partitioned earlier) into result slot `slot`: a leaf that decides
    /// the operation alone ends it, a leaf of either side copies the
    /// other subtree, and a node of `a` over a node of `b` partitions
    /// `b`'s subtree by `a`'s sub-hyperplane first.
    fn merge_links(&mut self, la: PLink<A>, sb: BSource<B>, slot: OSlot) {
        let lb = match sb {
            BSource::Link(l) => l,
            BSource::Temp(i) => self.temps[i].take().expect("partition result is ready"),
        };
        let op = self.op;
        match (la, lb) {
            (PLink::Leaf(x), _) if op.left(x).is_some() => self.put_o(
                slot,
                PLink::Leaf(op.left(x).unwrap_or_else(|| unreachable!())),
            ),
            (_, PLink::Leaf(y)) if op.right(y).is_some() => self.put_o(
                slot,
                PLink::Leaf(op.right(y).unwrap_or_else(|| unreachable!())),
            ),
            (PLink::Leaf(x), _) => self.stack.push(Task::CopyB {
                a: x,
                b: lb,
                out: slot,
            }),
            (_, PLink::Leaf(y)) => self.stack.push(Task::CopyA {
                a: la,
                b: y,
                out: slot,
            }),
            (PLink::Node(ia), PLink::Node(_)) => {
                let na = &self.a.nodes[ia as usize];
                let me = self.out.nodes.len() as u32;
                let label = self.out.root_label();
                self.out.nodes.push(PNode {
                    plane: na.plane,
                    shp: na.shp.clone(),
                    polygons: na.polygons.clone(),
                    front: PLink::Leaf(label),
                    back: PLink::Leaf(label),
                });
                self.put_o(slot, PLink::Node(me));
                let (tp, tm) = (self.temps.len(), self.temps.len() + 1);
                self.temps.push(None);
                self.temps.push(None);
                self.stack.push(Task::Merge {
                    a: na.back,
                    b: BSource::Temp(tm),
                    out: OSlot::Back(me),
                });
                self.stack.push(Task::Merge {
                    a: na.front,
                    b: BSource::Temp(tp),
                    out: OSlot::Front(me),
                });
                self.stack.push(Task::Partition {
                    t: lb,
                    h: na.shp.clone(),
                    plus: BSlot::Temp(tp),
                    minus: BSlot::Temp(tm),
                    collect: me,
                });
            }
        }
    }

    /// Copies a subtree of `a` whose every cell meets one cell of `b`,
    /// labelled `y`.
    fn copy_a(&mut self, la: PLink<A>, y: B, slot: OSlot) {
        match la {
            PLink::Leaf(x) => self.put_o(slot, PLink::Leaf(self.op.apply(x, y))),
            PLink::Node(ia) => {
                let na = &self.a.nodes[ia as usize];
                let me = self.out.push_copy(na.plane, &na.shp, &na.polygons);
                self.put_o(slot, PLink::Node(me));
                self.stack.push(Task::CopyA {
                    a: na.back,
                    b: y,
                    out: OSlot::Back(me),
                });
                self.stack.push(Task::CopyA {
                    a: na.front,
                    b: y,
                    out: OSlot::Front(me),
                });
            }
        }
    }

    /// Copies a subtree of `b` whose every cell meets one cell of `a`,
    /// labelled `x`.
    fn copy_b(&mut self, x: A, lb: PLink<B>, slot: OSlot) {
        match lb {
            PLink::Leaf(y) => self.put_o(slot, PLink::Leaf(self.op.apply(x, y))),
            PLink::Node(ib) => {
                let nb = &self.bn[ib as usize];
                let me = self.out.push_copy(nb.plane, &nb.shp, &nb.polygons);
                let (f, bk) = (nb.front, nb.back);
                self.put_o(slot, PLink::Node(me));
                self.stack.push(Task::CopyB {
                    a: x,
                    b: bk,
                    out: OSlot::Back(me),
                });
                self.stack.push(Task::CopyB {
                    a: x,
                    b: f,
                    out: OSlot::Front(me),
                });
            }
        }
    }

    /// Partitions `b`'s subtree `t` by the sub-hyperplane `h` of result
    /// node `collect`: the part in front goes to `plus`, the part behind
    /// to `minus`; polygons of `b` lying in `h`'s plane go to `collect`.
    fn partition(&mut self, t: PLink<B>, h: Polygon, (plus, minus): (BSlot, BSlot), collect: u32) {
        let PLink::Node(it) = t else {
            self.put_b(plus, t);
            self.put_b(minus, t);
            return;
        };
        let hp = *h.support();
        let (s, front, back) = {
            let n = &self.bn[it as usize];
            (n.plane, n.front, n.back)
        };
        if s == hp || s == hp.flip() {
            let polys = std::mem::take(&mut self.bn[it as usize].polygons);
            self.out.nodes[collect as usize].polygons.extend(polys);
            let (p, m) = if s == hp {
                (front, back)
            } else {
                (back, front)
            };
            self.put_b(plus, p);
            self.put_b(minus, m);
            return;
        }
        let side_of_s = self.bn[it as usize].shp.classify(&hp);
        match h.split(&s) {
            Split::Spanning {
                front: h_plus,
                back: h_minus,
            } => self.split_node(it, (h_plus, h_minus), (plus, minus), collect),
            Split::Front(h) => self.pass_by(it, (h, true), side_of_s, (plus, minus), collect),
            Split::Back(h) => self.pass_by(it, (h, false), side_of_s, (plus, minus), collect),
            Split::Coplanar { .. } => unreachable!("coincident planes handled above"),
        }
    }

    /// `h` spans node `it`'s plane: the node is cut in two by `h`'s plane
    /// (its sub-hyperplane and polygons), the front copy going to `plus`
    /// and the back one to `minus`, and both children are partitioned by
    /// the matching piece of `h`.
    fn split_node(
        &mut self,
        it: u32,
        (h_plus, h_minus): (Polygon, Polygon),
        (plus, minus): (BSlot, BSlot),
        collect: u32,
    ) {
        let hp = *h_plus.support();
        let node = &mut self.bn[it as usize];
        let (s, front, back) = (node.plane, node.front, node.back);
        let shp = node.shp.clone();
        let Split::Spanning {
            front: s_plus,
            back: s_minus,
        } = shp.split(&hp)
        else {
            panic!("sub-hyperplanes of one region span each other symmetrically");
        };
        let (mut pp, mut pm) = (Vec::new(), Vec::new());
        for poly in std::mem::take(&mut node.polygons) {
            match poly.split(&hp) {
                Split::Front(q) => pp.push(q),
                Split::Back(q) => pm.push(q),
                Split::Spanning { front: f, back: b } => {
                    pp.push(f);
                    pm.push(b);
                }
                Split::Coplanar { .. } => {
                    unreachable!("a node polygon lies in the node plane, not in h")
                }
            }
        }
        node.shp = s_plus;
        node.polygons = pp;
        let m = self.bn.len() as u32;
        self.bn.push(PNode {
            plane: s,
            shp: s_minus,
            polygons: pm,
            front,
            back,
        });
        self.put_b(plus, PLink::Node(it));
        self.put_b(minus, PLink::Node(m));
        self.stack.push(Task::Partition {
            t: back,
            h: h_minus,
            plus: BSlot::Back(it),
            minus: BSlot::Back(m),
            collect,
        });
        self.stack.push(Task::Partition {
            t: front,
            h: h_plus,
            plus: BSlot::Front(it),
            minus: BSlot::Front(m),
            collect,
        });
    }

    /// `h` lies on one side of node `it`'s plane (in front when
    /// `h_in_front`): the subtree on the other side does not meet `h`, so
    /// it lies on the side of `h` where the node's sub-hyperplane is
    /// (`side_of_s`); only the subtree on `h`'s side is partitioned
    /// further.
    fn pass_by(
        &mut self,
        it: u32,
        (h, h_in_front): (Polygon, bool),
        side_of_s: PolygonSide,
        (plus, minus): (BSlot, BSlot),
        collect: u32,
    ) {
        let (front, back) = {
            let n = &self.bn[it as usize];
            (n.front, n.back)
        };
        let s_in_front = match side_of_s {
            PolygonSide::Front => true,
            PolygonSide::Back => false,
            other => panic!("inconsistent sub-hyperplanes: {other:?}"),
        };
        let (keep, pass) = if s_in_front {
            (plus, minus)
        } else {
            (minus, plus)
        };
        self.put_b(keep, PLink::Node(it));
        let (child, slot) = if h_in_front {
            (front, BSlot::Front(it))
        } else {
            (back, BSlot::Back(it))
        };
        let (p, m) = if s_in_front {
            (slot, pass)
        } else {
            (pass, slot)
        };
        self.stack.push(Task::Partition {
            t: child,
            h,
            plus: p,
            minus: m,
            collect,
        });
    }
}

fn first_leaf<L: Copy>(p: &Partition<L>) -> L {
    let mut l = p.root;
    loop {
        match l {
            PLink::Leaf(x) => return x,
            PLink::Node(i) => l = p.nodes[i as usize].front,
        }
    }
}

impl<L: Copy> Partition<L> {
    /// A partition with a single cell.
    pub fn leaf(label: L) -> Partition<L> {
        Partition {
            nodes: Vec::new(),
            root: PLink::Leaf(label),
        }
    }

    /// Drops the input polygons carried by the nodes.
    pub fn clear_polygons(&mut self) {
        for n in &mut self.nodes {
            n.polygons = Vec::new();
        }
    }

    /// The root link.
    pub fn root(&self) -> PLink<L> {
        self.root
    }

    /// All inner nodes.
    pub fn nodes(&self) -> &[PNode<L>] {
        &self.nodes
    }

    fn root_label(&self) -> L {
        first_leaf(self)
    }

    fn push_copy(&mut self, plane: Plane, shp: &Polygon, polygons: &[Polygon]) -> u32 {
        let l = self.root_label();
        self.nodes.push(PNode {
            plane,
            shp: shp.clone(),
            polygons: polygons.to_vec(),
            front: PLink::Leaf(l),
            back: PLink::Leaf(l),
        });
        (self.nodes.len() - 1) as u32
    }

    /// The polygon BSP tree of this partition: the same planes, node
    /// polygons and order, with each leaf's label mapped to a [`Cell`].
    /// The overlay of two polygon trees (`merge(&a, &b, &Overlay)` of
    /// [`Partition::from_tree`]s) turned back into a tree is the core
    /// paper's `Bsp4 = Bsp2 + Bsp3`, ready for painter's-order traversal
    /// and shadows. A node without polygons whose child is a leaf orders
    /// nothing, and is replaced by its other child.
    pub fn polygon_tree(&self, cell: impl Fn(L) -> Cell) -> BspTree {
        // post-order: what each node becomes (a leaf or a kept node)
        let mut order = Vec::with_capacity(self.nodes.len());
        if let PLink::Node(r) = self.root {
            let mut stack = vec![r];
            while let Some(i) = stack.pop() {
                order.push(i);
                let n = &self.nodes[i as usize];
                for c in [n.front, n.back] {
                    if let PLink::Node(j) = c {
                        stack.push(j);
                    }
                }
            }
        }
        let mut repl: Vec<Option<PLink<L>>> = vec![None; self.nodes.len()];
        let resolve = |repl: &[Option<PLink<L>>], l: PLink<L>| match l {
            PLink::Node(j) => repl[j as usize].unwrap_or(l),
            leaf => leaf,
        };
        for &i in order.iter().rev() {
            let n = &self.nodes[i as usize];
            if !n.polygons.is_empty() {
                continue;
            }
            let (f, b) = (resolve(&repl, n.front), resolve(&repl, n.back));
            repl[i as usize] = match (f, b) {
                (PLink::Leaf(_), other) => Some(other),
                (other, PLink::Leaf(_)) => Some(other),
                _ => None,
            };
        }
        // the kept nodes in pre-order
        let mut nodes: Vec<Node> = Vec::new();
        let root = resolve(&repl, self.root);
        type Item<L> = (PLink<L>, Option<(NodeId, Side)>);
        let mut stack: Vec<Item<L>> = vec![(root, None)];
        let mut root_link = Link::Cell(Cell::Out);
        while let Some((l, slot)) = stack.pop() {
            let link = match l {
                PLink::Leaf(x) => Link::Cell(cell(x)),
                PLink::Node(i) => {
                    let n = &self.nodes[i as usize];
                    let id = nodes.len() as NodeId;
                    nodes.push(Node {
                        plane: n.plane,
                        polygons: n.polygons.clone(),
                        front: Link::Cell(Cell::Out),
                        back: Link::Cell(Cell::In),
                    });
                    stack.push((resolve(&repl, n.back), Some((id, Side::Back))));
                    stack.push((resolve(&repl, n.front), Some((id, Side::Front))));
                    Link::Node(id)
                }
            };
            match slot {
                None => root_link = link,
                Some((p, Side::Front)) => nodes[p as usize].front = link,
                Some((p, _)) => nodes[p as usize].back = link,
            }
        }
        BspTree::from_parts(nodes, root_link)
    }

    /// The same partition with every label mapped.
    pub fn map_labels<M: Copy>(&self, f: impl Fn(L) -> M) -> Partition<M> {
        let m = |l: PLink<L>| match l {
            PLink::Node(i) => PLink::Node(i),
            PLink::Leaf(x) => PLink::Leaf(f(x)),
        };
        Partition {
            nodes: self
                .nodes
                .iter()
                .map(|n| PNode {
                    plane: n.plane,
                    shp: n.shp.clone(),
                    polygons: n.polygons.clone(),
                    front: m(n.front),
                    back: m(n.back),
                })
                .collect(),
            root: m(self.root),
        }
    }

    /// Labels of every cell whose closure contains `p` (one label for a
    /// point inside a cell; several for a point on sub-hyperplanes).
    pub fn locate(&self, p: &Point) -> Vec<L> {
        let mut out = Vec::new();
        let mut stack = vec![self.root];
        while let Some(l) = stack.pop() {
            match l {
                PLink::Leaf(x) => out.push(x),
                PLink::Node(i) => {
                    let n = &self.nodes[i as usize];
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
        }
        out
    }

    /// Splits `poly` down the subtree at `link`: the pieces with the label
    /// of the cell each lands in. A piece lying in a node's plane goes to
    /// the front.
    pub fn push_down(&self, poly: Polygon, link: PLink<L>) -> Vec<(Polygon, L)> {
        push_down_by(poly, link, |l| match l {
            PLink::Leaf(x) => Err(x),
            PLink::Node(i) => {
                let n = &self.nodes[i as usize];
                Ok((&n.plane, n.front, n.back))
            }
        })
    }

    /// Collapses nodes whose children are leaves with equal labels, and
    /// drops the nodes no longer reachable.
    pub fn reduce(&mut self)
    where
        L: PartialEq,
    {
        self.reduce_nodes(false);
    }

    /// [`Partition::reduce`]; with `keep_polygons`, nodes that carry input
    /// polygons stay.
    fn reduce_nodes(&mut self, keep_polygons: bool)
    where
        L: PartialEq,
    {
        if let PLink::Node(r) = self.root {
            // post-order: children are final before their parent is looked at
            let mut order = Vec::with_capacity(self.nodes.len());
            let mut stack = vec![r];
            while let Some(i) = stack.pop() {
                order.push(i);
                let n = &self.nodes[i as usize];
                for c in [n.front, n.back] {
                    if let PLink::Node(j) = c {
                        stack.push(j);
                    }
                }
            }
            let mut collapsed: Vec<Option<L>> = vec![None; self.nodes.len()];
            for &i in order.iter().rev() {
                let n = &self.nodes[i as usize];
                let get = |l: PLink<L>| match l {
                    PLink::Leaf(x) => Some(x),
                    PLink::Node(j) => collapsed[j as usize],
                };
                let (f, b) = (get(n.front), get(n.back));
                let newf = f.map_or(n.front, PLink::Leaf);
                let newb = b.map_or(n.back, PLink::Leaf);
                let n = &mut self.nodes[i as usize];
                n.front = newf;
                n.back = newb;
                // the overlay of polygon trees ("+") keeps every polygon
                if let (Some(x), Some(y)) = (f, b)
                    && x == y
                    && (!keep_polygons || n.polygons.is_empty())
                {
                    collapsed[i as usize] = Some(x);
                }
            }
            if let Some(x) = collapsed[r as usize] {
                self.root = PLink::Leaf(x);
            }
        }
        self.compact();
    }

    /// Renumbers the reachable nodes in pre-order and drops the rest.
    fn compact(&mut self) {
        let PLink::Node(r) = self.root else {
            self.nodes.clear();
            return;
        };
        let mut new_id = vec![u32::MAX; self.nodes.len()];
        let mut order = Vec::new();
        let mut stack = vec![r];
        while let Some(i) = stack.pop() {
            new_id[i as usize] = order.len() as u32;
            order.push(i);
            let n = &self.nodes[i as usize];
            for c in [n.back, n.front] {
                if let PLink::Node(j) = c {
                    stack.push(j);
                }
            }
        }
        let remap = |l: PLink<L>| match l {
            PLink::Node(j) => PLink::Node(new_id[j as usize]),
            leaf => leaf,
        };
        let mut old: Vec<Option<PNode<L>>> = std::mem::take(&mut self.nodes)
            .into_iter()
            .map(Some)
            .collect();
        self.nodes = order
            .iter()
            .map(|&i| {
                let mut n = old[i as usize].take().expect("each node is reached once");
                n.front = remap(n.front);
                n.back = remap(n.back);
                n
            })
            .collect();
        self.root = PLink::Node(0);
    }

    /// Checks the invariants exactly: a tree over all nodes; every node's
    /// sub-hyperplane is a valid polygon in its plane, and lies on the
    /// correct side of every ancestor (touching at most); node polygons lie
    /// in the plane and inside the sub-hyperplane's region side of ancestors.
    pub fn sanity_check(&self) -> Result<(), SanityError> {
        let link = |l: PLink<L>| match l {
            PLink::Node(id) => Some(id),
            PLink::Leaf(_) => None,
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
                n.shp.sanity_check().map_err(|e| SanityError::Polygon {
                    node: id,
                    polygon: None,
                    error: Box::new(e),
                })?;
                if *n.shp.support() != n.plane {
                    return Err(SanityError::OffNodePlane { node: id });
                }
                for poly in std::iter::once(&n.shp).chain(n.polygons.iter()) {
                    if !poly.support().is_coincident(&n.plane) {
                        return Err(SanityError::OffNodePlane { node: id });
                    }
                    check_ancestors(id, poly, path)?;
                }
                Ok(())
            },
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(lo: [i32; 3], hi: [i32; 3]) -> Vec<Polygon> {
        bsp_fixtures::grid_cuboid(lo, hi)
            .iter()
            .map(|q| Polygon::from_grid_points(q, 0).unwrap())
            .collect()
    }

    fn solid(lo: [i32; 3], hi: [i32; 3]) -> Partition<Cell> {
        let t = BspTree::build(cube(lo, hi), &BuildOptions::default());
        let p = Partition::from_tree(&t);
        p.sanity_check().unwrap();
        p
    }

    #[test]
    fn touching_solids_give_manifold_meshes() {
        let a = solid([0, 0, 0], [2, 2, 2]);
        for (lo, hi, vol) in [
            ([2, 2, 0], [4, 4, 2], 16), // shares an edge
            ([2, 2, 2], [4, 4, 4], 16), // shares a vertex
            ([2, 0, 0], [4, 2, 2], 16), // shares a face
            ([1, 1, 2], [3, 3, 4], 16), // overlapping face region
            ([0, 0, 0], [2, 2, 2], 8),  // the same solid
        ] {
            let b = solid(lo, hi);
            let u = a.boolean(&b, BoolOp::Union);
            u.sanity_check().unwrap();
            let m = u.to_mesh();
            m.check_watertight()
                .unwrap_or_else(|e| panic!("{lo:?}: {e}"));
            crate::check_closed_manifold(m.triangles.iter().map(|t| &t[..]))
                .unwrap_or_else(|e| panic!("{lo:?}: {e}"));
            assert_eq!(
                m.volume_exact(),
                num_rational::BigRational::from_integer(vol.into())
            );
        }
        // a cube minus one touching it along an edge is the cube itself
        let b = solid([2, 2, 0], [4, 4, 2]);
        let d = a.boolean(&b, BoolOp::Difference).to_mesh();
        d.check_watertight().unwrap();
        assert_eq!(
            d.volume_exact(),
            num_rational::BigRational::from_integer(8.into())
        );
    }

    #[test]
    fn section_in_a_box_is_the_clipped_grid_section() {
        // walls of [lo, hi] half a step out, as bsp-csg's octree makes them
        let walls = |lo: [i64; 3], hi: [i64; 3]| -> Vec<Plane> {
            let mut w = Vec::new();
            for k in 0..3 {
                for (sign, c) in [(-1i64, lo[k]), (1, hi[k])] {
                    let mut n = [0i64; 3];
                    n[k] = 2 * sign;
                    w.push(
                        Plane::new(n, -(sign as i128) * (2 * c as i128 + sign as i128)).unwrap(),
                    );
                }
            }
            w
        };
        let planes = [
            Plane::through([0, 0, 0], [1, 0, 1], [0, 1, 3]).unwrap(),
            Plane::through([2, 1, 0], [0, 3, 1], [1, 1, 4]).unwrap(),
            Plane::through([0, 0, 2], [5, 0, 2], [0, 5, 2]).unwrap(),
            Plane::through([1, 1, 1], [2, 3, 1], [1, 1, 7])
                .unwrap()
                .flip(),
        ];
        let mut met = 0;
        for pl in &planes {
            for (lo, hi) in [
                ([0, 0, 0], [3, 3, 3]),
                ([-2, 1, 0], [4, 2, 5]),
                ([1, 1, 1], [1, 1, 1]),
            ] {
                let w = walls(lo, hi);
                let mut clipped = box_section(pl);
                for wall in &w {
                    clipped = clipped.and_then(|mut c| c.clip(wall, Side::Back).then_some(c));
                }
                let direct = section_in(pl, &w);
                match (clipped, direct) {
                    (None, None) => {}
                    (Some(c), Some(d)) => {
                        met += 1;
                        d.sanity_check().unwrap();
                        assert_eq!(d.support(), pl);
                        assert_eq!(c.len(), d.len(), "{pl:?} {lo:?} {hi:?}");
                        for v in d.vertices() {
                            assert!(c.vertices().iter().any(|u| u.same_point(v)));
                        }
                    }
                    (c, d) => panic!("{pl:?} {lo:?} {hi:?}: {c:?} vs {d:?}"),
                }
            }
        }
        assert!(met >= 6, "{met}");
        // not an axis-aligned box: no shortcut
        assert!(section_in(&planes[0], &walls([0; 3], [1; 3])[..5]).is_none());
    }

    #[test]
    fn box_section_of_tilted_plane() {
        let p = Plane::through([0, 0, 0], [1, 0, 1], [0, 1, 3]).unwrap();
        let s = box_section(&p).unwrap();
        s.sanity_check().unwrap();
        assert_eq!(*s.support(), p);
    }

    #[test]
    fn two_boxes_all_operations() {
        let a = solid([0, 0, 0], [4, 4, 4]);
        let b = solid([2, 2, 2], [6, 6, 6]);
        let grid_pts =
            (-1..8).flat_map(|x| (-1..8).flat_map(move |y| (-1..8).map(move |z| [x, y, z])));
        for op in [BoolOp::Union, BoolOp::Intersection, BoolOp::Difference] {
            let r = a.boolean(&b, op);
            r.sanity_check().unwrap();
            let r2 = merge(&b, &a, &Swapped(&op));
            r2.sanity_check().unwrap();
            for p in grid_pts.clone() {
                let pt = Point::Grid(p);
                let (ma, mb) = (a.classify_point(&pt), b.classify_point(&pt));
                let m = r.classify_point(&pt);
                assert_eq!(m, r2.classify_point(&pt));
                if ma != Membership::Boundary && mb != Membership::Boundary {
                    let exp = op.apply(
                        if ma == Membership::Inside {
                            Cell::In
                        } else {
                            Cell::Out
                        },
                        if mb == Membership::Inside {
                            Cell::In
                        } else {
                            Cell::Out
                        },
                    );
                    let got = match m {
                        Membership::Inside => Cell::In,
                        Membership::Outside => Cell::Out,
                        Membership::Boundary => panic!("{p:?} {op:?}: boundary"),
                    };
                    assert_eq!(got, exp, "{p:?} {op:?}");
                }
            }
            assert!(!r.boundary().is_empty());
        }
        for (op, vol) in [
            (BoolOp::Union, 120.0),
            (BoolOp::Intersection, 8.0),
            (BoolOp::Difference, 56.0),
        ] {
            let m = crate::solid::TriMesh::from_polygons(&a.boolean(&b, op).boundary());
            m.check_watertight().unwrap();
            assert_eq!(m.volume_f64(), vol, "{op:?}");
            assert_eq!(
                m.volume_exact(),
                num_rational::BigRational::from_integer((vol as i64).into())
            );
        }
        let empty = a.boolean(&a, BoolOp::Difference);
        assert!(
            matches!(empty.root(), PLink::Leaf(Cell::Out)),
            "A - A is empty"
        );
        let same = a.boolean(&a, BoolOp::Union);
        assert_eq!(same.boundary().len(), 6);
    }

    #[test]
    fn overlay_labels_every_cell() {
        let a = solid([0, 0, 0], [4, 4, 4]);
        let b = solid([1, 2, 3], [6, 5, 7]);
        let o = merge_smaller_into_larger(&a, &b, &Overlay);
        o.sanity_check().unwrap();
        for x in -1..8 {
            for y in -1..8 {
                for z in -1..9 {
                    // points at half-integers avoid every plane: use doubled coordinates
                    let p = Point::from_planes(
                        &Plane::new([2, 0, 0], -(2 * x as i128 + 1)).unwrap(),
                        &Plane::new([0, 2, 0], -(2 * y as i128 + 1)).unwrap(),
                        &Plane::new([0, 0, 2], -(2 * z as i128 + 1)).unwrap(),
                    )
                    .unwrap();
                    let cells = o.locate(&p);
                    assert_eq!(cells.len(), 1);
                    let to = |m| {
                        if m == Membership::Inside {
                            Cell::In
                        } else {
                            Cell::Out
                        }
                    };
                    assert_eq!(
                        cells[0],
                        (to(a.classify_point(&p)), to(b.classify_point(&p)))
                    );
                }
            }
        }
    }
}
