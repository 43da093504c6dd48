//! The boolean inside one octree cell where both surfaces are: a BSP
//! partition of each operand's faces within the cell, labelled exactly,
//! merged.
//!
//! **Labels.** A partition of one operand's face pieces (an
//! autopartition: every face lies on a node plane) has leaves that no face
//! crosses, so each leaf is all inside or all outside the operand. Two
//! leaves that meet across a piece `σ` of a node's sub-hyperplane differ by
//! the surface on `σ`: `w(back) − w(front)` is 1 where the node's polygons
//! facing the node plane's front (outward, so inside behind) cover `σ`,
//! minus 1 where those facing back do. The surface covers a piece all over
//! or not at all (the two leaves have one label each), so one exact
//! overlap test with one face decides it. A covered piece fixes both labels (the
//! winding numbers of a solid are 0 and 1); the others carry them across.
//! Only a cell whose pieces cover nothing with a net orientation needs a
//! reference: the winding number of a grid point in it, by a ray. Labels
//! that disagree (a surface crossing itself) are an error here, which the
//! operation meets by resolving the solids: [`positive_region`] carries the
//! winding number from a box corner through one partition of every face,
//! whatever its values.
//!
//! **Labels without regions.** Where every node's pieces face its plane's
//! way (no two coplanar pieces face opposite ways), each leaf is the
//! child of a node with a piece on the leaf's side of it and nothing
//! between: for a solid, the labels [`BspTree::build`] gives (front leaves
//! outside, back leaves inside) are the winding numbers, and sorting the
//! other operand's pieces needs only the tree ([`Labelled`]). Each piece
//! is checked against the leaves right in front of it and right behind it
//! (`faces_bound`), which a surface crossing itself (two overlapping
//! shells in one file) fails where a leaf lies against two of its pieces
//! from opposite sides. The regions and their links are built where
//! pieces face both ways (a solid touching itself in a plane), where that
//! check fails (the links then find the crossing and fail the operation),
//! and for the merged cells.

use bsp_core::internals::{ConvexFace, PLink, Parts, merge_smaller_into_larger};
use bsp_core::{
    BoolOp, BspTree, BuildOptions, Cell, Link, Partition, Plane, Polygon, PolygonSide, Side, Split,
};

use super::octree::walls;
use crate::CsgError;
use crate::index::{IBox, overlaps};

/// `true` if `piece` and `face` (convex, in the same plane) overlap with
/// an area: no edge line of either has the other wholly on its outer side
/// (separating axes; nothing is built).
fn overlap(piece: &Polygon, face: &Polygon) -> bool {
    let separates =
        |e: &Plane, other: &Polygon| other.vertices().iter().all(|v| v.classify(e) != Side::Back);
    !face.edge_planes().iter().any(|e| separates(e, piece))
        && !piece.edge_planes().iter().any(|e| separates(e, face))
}

/// The solid partition of `pieces` (faces of one operand clipped to the
/// cell `bx`); `reference` gives the operand's winding number at a point
/// of the cell when no piece decides it.
pub(crate) fn solid(
    bx: &IBox,
    pieces: Vec<Polygon>,
    reference: impl FnOnce() -> i32,
) -> Result<Partition<Cell>, CsgError> {
    solid_of(bx, &BspTree::build(pieces, &local_build()), reference)
}

/// How a cell's trees choose their planes: 4 candidate planes, each
/// scored on 16 of the pieces. The defaults (8 on 48) are for large
/// trees; a cell holds a few dozen pieces a side, where a cheaper choice
/// saves more time than its slightly larger trees cost
/// (`docs/bench-csg.md`).
fn local_build() -> BuildOptions {
    BuildOptions::default()
        .with_candidates(4)
        .with_sample(16)
        .with_cut_threshold(0)
}

/// [`solid`] from the autopartition `tree` of the pieces.
fn solid_of(
    bx: &IBox,
    tree: &BspTree,
    reference: impl FnOnce() -> i32,
) -> Result<Partition<Cell>, CsgError> {
    let w = walls(bx);
    let (part, leaves) = Partition::from_tree_in(tree, &w);
    let links = links(&part, sheet);
    let mut w: Vec<Option<i32>> = vec![None; leaves as usize];
    let mut adj: Vec<Vec<(u32, i32)>> = vec![Vec::new(); leaves as usize];
    for &(f, b, c) in &links {
        adj[f as usize].push((b, c));
        adj[b as usize].push((f, -c));
        match c {
            0 => {}
            1 | -1 => {
                let (wf, wb) = if c == 1 { (0, 1) } else { (1, 0) };
                for (leaf, v) in [(f, wf), (b, wb)] {
                    match w[leaf as usize] {
                        None => w[leaf as usize] = Some(v),
                        Some(x) if x == v => {}
                        Some(_) => return Err(CsgError::NotASolid),
                    }
                }
            }
            _ => return Err(CsgError::NotASolid),
        }
    }
    let mut queue: Vec<u32> = (0..leaves).filter(|&l| w[l as usize].is_some()).collect();
    if queue.is_empty() {
        // no piece decides: the whole cell is on one side
        let r = reference();
        w.iter_mut().for_each(|x| *x = Some(r));
        queue.clear();
    }
    while let Some(l) = queue.pop() {
        let v = w[l as usize].expect("queued leaves are labelled");
        for &(m, c) in &adj[l as usize] {
            let want = v + c;
            match w[m as usize] {
                None => {
                    w[m as usize] = Some(want);
                    queue.push(m);
                }
                Some(x) if x == want => {}
                Some(_) => return Err(CsgError::NotASolid),
            }
        }
    }
    let mut cells = Vec::with_capacity(w.len());
    for v in w {
        cells.push(match v {
            Some(0) => Cell::Out,
            Some(1) => Cell::In,
            _ => return Err(CsgError::NotASolid),
        });
    }
    Ok(part.map_labels(|l| cells[l as usize]))
}

/// `(front leaf, back leaf, w(back) − w(front))` across every piece of
/// every sub-hyperplane of `part`, the difference `cover(piece, node's
/// polygons, node's plane)`: [`sheet`] for a solid, [`layers`] where
/// faces may lie on each other.
fn links(
    part: &Partition<u32>,
    cover: impl Fn(&Polygon, &[Polygon], &Plane) -> i32,
) -> Vec<(u32, u32, i32)> {
    let mut links: Vec<(u32, u32, i32)> = Vec::new();
    for n in part.nodes() {
        for (pf, lf) in part.push_down(n.shp.clone(), n.front) {
            for (pb, lb) in part.push_down(pf, n.back) {
                links.push((lf, lb, cover(&pb, &n.polygons, &n.plane)));
            }
        }
    }
    links
}

/// `w(back) − w(front)` across `piece` for a solid: the surface on the
/// plane covers a piece all over or not at all (it may be cut into several
/// faces), so one overlapping face of each orientation tells.
fn sheet(piece: &Polygon, faces: &[Polygon], plane: &Plane) -> i32 {
    let (mut up, mut down) = (false, false);
    for g in faces {
        let same = g.support() == plane;
        if (same && up) || (!same && down) {
            continue;
        }
        if overlap(piece, g) {
            if same {
                up = true;
            } else {
                down = true;
            }
        }
    }
    i32::from(up) - i32::from(down)
}

/// `w(back) − w(front)` across `piece` (in the plane `plane`, which
/// `faces` lie in): the layers of faces covering it, those facing the
/// plane's front counted `+1`, the others `−1`. The faces of one layer
/// tile the piece without overlapping, and each layer covers it all over
/// or not at all; so the piece, shrunk to the inside of each face that
/// still overlaps it in turn, meets each layer once.
fn layers(piece: &Polygon, faces: &[Polygon], plane: &Plane) -> i32 {
    let mut region: Option<Polygon> = None;
    let mut count = 0;
    for g in faces {
        let r = region.as_ref().unwrap_or(piece);
        if !overlap(r, g) {
            continue;
        }
        let mut inside = r.clone();
        if g.edge_planes().iter().all(|e| inside.clip(e, Side::Back)) {
            region = Some(inside);
            count += if g.support() == plane { 1 } else { -1 };
        }
    }
    count
}

/// The boundary of the points where the winding number of the closed,
/// oriented surface `faces` is positive (the rule of mesh-arrangement
/// Booleans): faces may cross, overlap, nest or touch one another; what
/// comes out bounds a solid, outward. One partition of all the faces (an
/// autopartition in a box around them) carries the winding number from a
/// corner of the box, where it is 0, across every piece of every
/// sub-hyperplane ([`layers`]: faces of several shells lying on each other
/// count once each); every decision is exact. `Err(NotASolid)` if the
/// surface is not closed (the numbers disagree around a loop).
pub(crate) fn positive_region(faces: Vec<Polygon>) -> Result<Vec<Polygon>, CsgError> {
    let Some(bx) = faces
        .iter()
        .map(crate::index::polygon_box)
        .reduce(|a, b| crate::index::union(&a, &b))
    else {
        return Ok(Vec::new());
    };
    let corner = bx.0.map(|c| c - 1);
    let bx: IBox = (bx.0.map(|c| c - 2), bx.1.map(|c| c + 2));
    let tree = BspTree::build(faces, &BuildOptions::default().with_cut_threshold(0));
    let (part, leaves) = Partition::from_tree_in(&tree, &walls(&bx));
    let corner = bsp_core::Point::Grid(corner.map(|c| c as i32));
    let start = part.locate(&corner);
    let w = carry_windings(&part, leaves, &start, 0)?;
    Ok(positive_boundary(&part, &w))
}

/// The boundary, outward, of the leaves of `part` whose winding number
/// `w[leaf]` is positive.
pub(crate) fn positive_boundary(part: &Partition<u32>, w: &[i32]) -> Vec<Polygon> {
    let region = part.map_labels(|l| {
        if w[l as usize] > 0 {
            Cell::In
        } else {
            Cell::Out
        }
    });
    match region.root() {
        PLink::Leaf(_) => Vec::new(),
        PLink::Node(_) => region.boundary(),
    }
}

/// The winding numbers of the `leaves` leaves of `part` (an
/// autopartition of faces that may cross, overlap or nest: [`layers`]),
/// carried from `start`, the leaves where it is `w0`, across every piece
/// of every sub-hyperplane. `Err(NotASolid)` where they disagree around
/// a loop (a surface that is not closed).
fn carry_windings(
    part: &Partition<u32>,
    leaves: u32,
    start: &[u32],
    w0: i32,
) -> Result<Vec<i32>, CsgError> {
    let mut adj: Vec<Vec<(u32, i32)>> = vec![Vec::new(); leaves as usize];
    for (f, b, c) in links(part, layers) {
        adj[f as usize].push((b, c));
        adj[b as usize].push((f, -c));
    }
    let mut w: Vec<Option<i32>> = vec![None; leaves as usize];
    let mut queue = start.to_vec();
    for &l in &queue {
        w[l as usize] = Some(w0);
    }
    while let Some(l) = queue.pop() {
        let v = w[l as usize].expect("queued leaves are labelled");
        for &(m, c) in &adj[l as usize] {
            match w[m as usize] {
                None => {
                    w[m as usize] = Some(v + c);
                    queue.push(m);
                }
                Some(x) if x == v + c => {}
                Some(_) => return Err(CsgError::NotASolid),
            }
        }
    }
    // every leaf is reached: the partition's cells are connected
    Ok(w.into_iter().map(|v| v.unwrap_or(0)).collect())
}

/// The partition of `pieces` (faces that may cross, overlap or nest,
/// clipped to the cell `bx`) in the cell, and the winding number of every
/// leaf, carried from `wc`, the surface's winding number at the grid
/// point `c` of the cell displaced by `(ε³, ε, ε²)` (as
/// [`Solid::winding`](crate::Solid::winding) gives it).
pub(crate) fn cell_windings(
    bx: &IBox,
    pieces: Vec<Polygon>,
    c: bsp_core::GridPoint,
    wc: i32,
) -> Result<(Partition<u32>, Vec<i32>), CsgError> {
    let tree = BspTree::build(pieces, &local_build());
    let (part, leaves) = Partition::from_tree_in(&tree, &walls(bx));
    let start = [locate_displaced(&part, c)];
    let w = carry_windings(&part, leaves, &start, wc)?;
    Ok((part, w))
}

/// The leaf of `part` holding the grid point `c` displaced by
/// `(ε³, ε, ε²)`: on a node's plane, the side of the displacement, the
/// sign of the first non-zero of the normal's `y`, `z`, `x`.
fn locate_displaced(part: &Partition<u32>, c: bsp_core::GridPoint) -> u32 {
    let mut link = part.root();
    loop {
        match link {
            PLink::Leaf(l) => return l,
            PLink::Node(i) => {
                let n = &part.nodes()[i as usize];
                let side = match n.plane.classify_grid(c) {
                    Side::On => {
                        let [x, y, z] = n.plane.normal();
                        let first = [y, z, x].into_iter().find(|&v| v != 0).unwrap_or(0);
                        if first > 0 { Side::Front } else { Side::Back }
                    }
                    s => s,
                };
                link = if side == Side::Front { n.front } else { n.back };
            }
        }
    }
}

/// The winding numbers in front of and behind `piece` (part of a face
/// among the pieces `part` was built from, that no other face meets):
/// the leaf it lies against on its front side, and its back side.
pub(crate) fn side_windings(
    part: &Partition<u32>,
    w: &[i32],
    piece: &Polygon,
) -> Option<(i32, i32)> {
    let mut link = part.root();
    let mut piece = piece.clone();
    // whether the node whose plane holds the piece faces the piece's way
    let mut facing: Option<bool> = None;
    loop {
        match link {
            PLink::Leaf(l) => {
                let wl = w[l as usize];
                return match facing? {
                    true => Some((wl, wl + 1)),
                    false => Some((wl - 1, wl)),
                };
            }
            PLink::Node(i) => {
                let n = &part.nodes()[i as usize];
                link = match piece.clone().split(&n.plane) {
                    Split::Front(_) => n.front,
                    Split::Back(_) => n.back,
                    Split::Spanning { front, .. } => {
                        piece = front;
                        n.front
                    }
                    Split::Coplanar {
                        same_orientation, ..
                    } => {
                        facing = Some(same_orientation);
                        n.front
                    }
                };
            }
        }
    }
}

/// The boundary of `a op b` inside the cell `bx`, from the two operands'
/// pieces in it.
pub(crate) fn boolean(
    bx: &IBox,
    a: Vec<Polygon>,
    b: Vec<Polygon>,
    op: BoolOp,
    ref_a: impl FnOnce() -> i32,
    ref_b: impl FnOnce() -> i32,
) -> Result<Vec<Polygon>, CsgError> {
    let pa = solid(bx, a, ref_a)?;
    let pb = solid(bx, b, ref_b)?;
    let r = merge_smaller_into_larger(&pa, &pb, &op);
    Ok(match r.root() {
        PLink::Leaf(_) => Vec::new(),
        PLink::Node(_) => r.boundary(),
    })
}

/// What becomes of one face piece in a mixed cell.
#[derive(Clone, Debug)]
pub(crate) enum Fate {
    /// The piece lies wholly on the kept side of the other surface.
    Keep,
    /// The piece lies wholly on the dropped side.
    Drop,
    /// The other surface crosses the piece: its kept fragments.
    Cut(Vec<Polygon>),
}

/// The result of one mixed cell: a fate per piece of each operand, or —
/// where faces of the two operands share a plane, so the pieces alone
/// cannot tell which copy of a shared area stays — the merged boundary of
/// the whole cell.
pub(crate) enum CellResult {
    /// The fates, with the pieces given back (`a`'s, then `b`'s).
    Pieces(Vec<Fate>, Vec<Fate>, Vec<Polygon>, Vec<Polygon>),
    Merged(Vec<Polygon>),
}

/// One operand's pieces in a cell with every region labelled, to sort the
/// other operand's pieces by.
pub(crate) enum Labelled {
    /// The autopartition as built, when every node's pieces face its
    /// plane's way ([`BspTree::faces_agree`]): each leaf then lies beside
    /// a piece of its parent node, on that piece's outer side (a front
    /// leaf) or inner side (a back leaf), and no piece crosses the leaf's
    /// part of the cell, so the built labels are the winding numbers and
    /// no region needs to be made.
    Tree(BspTree),
    /// The labelled partition ([`solid`]): where coplanar pieces face
    /// both ways (a solid touching itself), or there are no pieces.
    Partition(Partition<Cell>),
}

impl Labelled {
    /// The labelled regions of `pieces` (faces of one operand clipped to
    /// the cell `bx`), `reference` as for [`solid`].
    pub(crate) fn new(
        bx: &IBox,
        pieces: Vec<Polygon>,
        reference: impl FnOnce() -> i32,
    ) -> Result<Labelled, CsgError> {
        if pieces.is_empty() {
            return solid(bx, pieces, reference).map(Labelled::Partition);
        }
        let tree = BspTree::build(pieces, &local_build());
        if tree.faces_agree() && faces_bound(&tree) {
            Ok(Labelled::Tree(tree))
        } else {
            solid_of(bx, &tree, reference).map(Labelled::Partition)
        }
    }

    /// `poly` split by the regions, each fragment with its region's label.
    #[cfg(test)]
    fn push_down(&self, poly: Polygon) -> Vec<(Polygon, Cell)> {
        match self {
            Labelled::Tree(t) => t.push_down(poly),
            Labelled::Partition(p) => p.push_down(poly, p.root()),
        }
    }

    /// The root.
    fn at_root(&self) -> At {
        match self {
            Labelled::Tree(t) => At::of_tree(t.root()),
            Labelled::Partition(p) => At::of_partition(p.root()),
        }
    }

    /// A node's plane and its front and back children.
    fn node(&self, i: u32) -> (&Plane, At, At) {
        match self {
            Labelled::Tree(t) => {
                let n = t.node(i);
                (&n.plane, At::of_tree(n.front), At::of_tree(n.back))
            }
            Labelled::Partition(p) => {
                let n = &p.nodes()[i as usize];
                (
                    &n.plane,
                    At::of_partition(n.front),
                    At::of_partition(n.back),
                )
            }
        }
    }
}

/// `true` if every piece of every node (all facing the node plane's way)
/// has only outside leaves right in front of it and only inside leaves
/// right behind it: each piece is pushed down the node's front subtree and
/// its back subtree, and every leaf a part of it lands in must be labelled
/// so. A solid's faces always pass (just in front of a face is outside,
/// just behind it inside); a surface that crosses itself in the cell, two
/// overlapping shells say, fails wherever a leaf lies against a piece of
/// each shell from opposite sides, and the cell is then labelled through
/// its regions, which finds it out.
fn faces_bound(tree: &BspTree) -> bool {
    use std::borrow::Cow;
    let lands_in = |poly: &Polygon, start: Link, want: Cell| {
        let mut stack: Vec<(Cow<'_, Polygon>, Link)> = vec![(Cow::Borrowed(poly), start)];
        while let Some((p, link)) = stack.pop() {
            match link {
                Link::Cell(c) if c != want => return false,
                Link::Cell(_) => {}
                Link::Node(i) => {
                    let n = tree.node(i);
                    match p.parts(&n.plane) {
                        Parts::Whole(PolygonSide::Back) => stack.push((p, n.back)),
                        Parts::Whole(_) => stack.push((p, n.front)),
                        Parts::Split { front, back } => {
                            stack.push((Cow::Owned(front), n.front));
                            stack.push((Cow::Owned(back), n.back));
                        }
                    }
                }
            }
        }
        true
    };
    tree.nodes().iter().all(|n| {
        n.polygons
            .iter()
            .all(|g| lands_in(g, n.front, Cell::Out) && lands_in(g, n.back, Cell::In))
    })
}

/// A place in a labelled tree: a node or a labelled leaf.
#[derive(Clone, Copy)]
enum At {
    Node(u32),
    Leaf(Cell),
}

impl At {
    fn of_tree(l: Link) -> At {
        match l {
            Link::Node(i) => At::Node(i),
            Link::Cell(c) => At::Leaf(c),
        }
    }

    fn of_partition(l: PLink<Cell>) -> At {
        match l {
            PLink::Node(i) => At::Node(i),
            PLink::Leaf(c) => At::Leaf(c),
        }
    }
}

/// The fate of `piece` against the labelled regions `other` of the other
/// operand in the cell. `keep(c)` says whether a fragment strictly inside
/// a region labelled `c` stays; a part that lies in one of `other`'s
/// planes is cut by the regions on both sides, and `coplanar(plane,
/// ahead, behind)` says whether a fragment in `plane` with those labels
/// just ahead of it and just behind it stays.
///
/// The piece is split down the tree; where both parts of a split stay
/// whole, the part they were cut from stays instead (it is their union),
/// so a kept fragment is cut only by planes with something dropped on
/// one side. The mesh puts into its edges the vertices its neighbours
/// have there.
fn fate(
    piece: &Polygon,
    other: &Labelled,
    keep: impl Fn(Cell) -> bool,
    coplanar: impl Fn(&Plane, Cell, Cell) -> bool,
) -> Fate {
    /// A part: the piece itself (borrowed: most go down whole), or a
    /// part cut from it (boxed, so that the records stay small).
    enum Cow<'p> {
        Borrowed(&'p Polygon),
        Owned(Box<Polygon>),
    }
    impl Cow<'_> {
        fn get(&self) -> &Polygon {
            match self {
                Cow::Borrowed(p) => p,
                Cow::Owned(p) => p,
            }
        }
        fn into_owned(self) -> Polygon {
            match self {
                Cow::Borrowed(p) => p.clone(),
                Cow::Owned(p) => *p,
            }
        }
    }
    #[derive(Clone, Copy, PartialEq)]
    enum State {
        Kept,
        Dropped,
        Mixed,
    }
    /// A part met on the way down: a fragment in a leaf, or a part that a
    /// node's plane splits, with its two pieces' records.
    struct Rec<'p> {
        poly: Option<Cow<'p>>,
        pieces: Option<[u32; 2]>,
        state: State,
    }
    /// Where a part in one of `other`'s planes is on its way: first down
    /// the regions just ahead of it (then on to `behind`), then down those
    /// just behind it with the label ahead found.
    #[derive(Clone, Copy)]
    enum Beside {
        No,
        Ahead { behind: At, node: u32 },
        Behind { ahead: Cell, node: u32 },
    }
    /// A part on its way down: where it goes, its parent's record and
    /// side, and whether it lies in a plane of `other`.
    /// (The piece itself is only borrowed: most go down whole.)
    type Going<'p> = (Cow<'p>, At, Option<(u32, usize)>, Beside);
    // (small records in place: most pieces make one, and no allocation)
    let mut recs: smallvec::SmallVec<[Rec<'_>; 8]> = smallvec::SmallVec::new();
    let mut stack: smallvec::SmallVec<[Going<'_>; 8]> =
        smallvec::smallvec![(Cow::Borrowed(piece), other.at_root(), None, Beside::No)];
    while let Some((p, mut at, parent, mut beside)) = stack.pop() {
        let me = recs.len() as u32;
        if let Some((r, k)) = parent {
            recs[r as usize].pieces.as_mut().expect("a split record")[k] = me;
        }
        loop {
            match (at, beside) {
                (At::Leaf(c), Beside::Ahead { behind, node }) => {
                    (at, beside) = (behind, Beside::Behind { ahead: c, node });
                }
                (At::Leaf(c), _) => {
                    let kept = match beside {
                        Beside::Behind { ahead, node } => coplanar(other.node(node).0, ahead, c),
                        _ => keep(c),
                    };
                    let state = if kept { State::Kept } else { State::Dropped };
                    recs.push(Rec {
                        poly: Some(p),
                        pieces: None,
                        state,
                    });
                    break;
                }
                (At::Node(i), _) => {
                    let (plane, front, back) = other.node(i);
                    match p.get().parts(plane) {
                        Parts::Whole(PolygonSide::Back) => at = back,
                        Parts::Whole(PolygonSide::Coplanar { same_orientation }) => {
                            // the side the part's normal points to is the
                            // plane's front if they agree
                            let (ahead, behind) = match same_orientation {
                                true => (front, back),
                                false => (back, front),
                            };
                            (at, beside) = match beside {
                                Beside::No => (ahead, Beside::Ahead { behind, node: i }),
                                Beside::Ahead { .. } => (ahead, beside),
                                Beside::Behind { .. } => (behind, beside),
                            };
                        }
                        Parts::Whole(_) => at = front,
                        Parts::Split { front: f, back: b } => {
                            recs.push(Rec {
                                poly: Some(p),
                                pieces: Some([u32::MAX; 2]),
                                state: State::Mixed,
                            });
                            stack.push((Cow::Owned(Box::new(b)), back, Some((me, 1)), beside));
                            stack.push((Cow::Owned(Box::new(f)), front, Some((me, 0)), beside));
                            break;
                        }
                    }
                }
            }
        }
    }
    // a split part's pieces are recorded after it
    for j in (0..recs.len()).rev() {
        if let Some([f, b]) = recs[j].pieces {
            let (sf, sb) = (recs[f as usize].state, recs[b as usize].state);
            recs[j].state = if sf == sb { sf } else { State::Mixed };
        }
    }
    match recs[0].state {
        State::Kept => Fate::Keep,
        State::Dropped => Fate::Drop,
        State::Mixed => {
            // (room for every leaf record at once: a polygon is large)
            let mut kept = Vec::with_capacity(recs.len().div_ceil(2));
            let mut todo = vec![0u32];
            while let Some(j) = todo.pop() {
                let r = &mut recs[j as usize];
                match r.state {
                    State::Kept => kept.push(r.poly.take().expect("each record once").into_owned()),
                    State::Dropped => {}
                    State::Mixed => {
                        let [f, b] = r.pieces.expect("a mixed record is split");
                        todo.push(b);
                        todo.push(f);
                    }
                }
            }
            Fate::Cut(kept)
        }
    }
}

/// The boolean inside the cell `bx` piece by piece: each operand's pieces
/// are sorted against the other's labelled partition, so a piece no
/// surface crosses stays whole and its face can be put back together.
/// `keep_a(inside_b)` and `keep_b(inside_a)` say which pieces stay.
pub(crate) fn boolean_pieces(
    bx: &IBox,
    a: Vec<Polygon>,
    b: Vec<Polygon>,
    op: BoolOp,
    keep: (impl Fn(bool) -> bool, impl Fn(bool) -> bool),
    ref_a: impl FnOnce() -> i32,
    ref_b: impl FnOnce() -> i32,
) -> Result<CellResult, CsgError> {
    let shared = a
        .iter()
        .any(|p| b.iter().any(|q| p.support().is_coincident(q.support())));
    let (pa, pb) = if shared {
        // pieces in a plane of the other surface are sorted by the labels
        // on both sides of it, where each surface is simple there (see
        // [`coplanar_keeps`]); else the cell is merged as a whole
        match (simple_tree(&a), simple_tree(&b)) {
            (Some(ta), Some(tb)) => (Labelled::Tree(ta), Labelled::Tree(tb)),
            _ => return boolean(bx, a, b, op, ref_a, ref_b).map(CellResult::Merged),
        }
    } else {
        (
            Labelled::new(bx, a.clone(), ref_a)?,
            Labelled::new(bx, b.clone(), ref_b)?,
        )
    };
    let b_kept = if shared {
        b_copies_kept(op, &a, &b)
    } else {
        Vec::new()
    };
    let on = |of_a: bool| {
        let b_kept = &b_kept;
        move |plane: &Plane, ahead: Cell, behind: Cell| {
            let b_copy = b_kept
                .iter()
                .any(|(p, kept)| *kept && p.is_coincident(plane));
            coplanar_keeps(op, of_a, b_copy, (ahead == Cell::In, behind == Cell::In))
        }
    };
    let (on_a, on_b) = (on(true), on(false));
    let fa = a
        .iter()
        .map(|p| fate(p, &pb, |c| keep.0(c == Cell::In), on_a))
        .collect();
    let fb = b
        .iter()
        .map(|p| fate(p, &pa, |c| keep.1(c == Cell::In), on_b))
        .collect();
    Ok(CellResult::Pieces(fa, fb, a, b))
}

/// The autopartition of one operand's pieces in a cell where it is a
/// simple surface: its tree's own labels are the winding numbers (as for
/// [`Labelled::Tree`]), and no two of its pieces in one plane overlap (an
/// area covered twice, where the labels on its two sides would not tell
/// that two pieces lie there). `None` otherwise.
fn simple_tree(pieces: &[Polygon]) -> Option<BspTree> {
    let twice = pieces.iter().enumerate().any(|(i, p)| {
        pieces[i + 1..]
            .iter()
            .any(|q| p.support().is_coincident(q.support()) && !apart_in_plane(p, q))
    });
    if twice {
        return None;
    }
    let tree = BspTree::build(pieces.to_vec(), &local_build());
    (tree.faces_agree() && faces_bound(&tree)).then_some(tree)
}

/// `true` if two convex polygons of one plane have no interior point in
/// common: an edge line of one has the other wholly on its outer side or
/// on it (for convex polygons in a plane, a separating line can be taken
/// along an edge of one of them).
fn apart_in_plane(p: &Polygon, q: &Polygon) -> bool {
    let outside = |a: &Polygon, b: &Polygon| {
        a.edge_planes()
            .iter()
            .any(|e| b.vertices().iter().all(|v| v.classify(e) != Side::Back))
    };
    outside(p, q) || outside(q, p)
}

/// Whether a fragment of a piece of operand A (`of_a`) or B that lies in
/// a plane of the other operand's surface stays, from the other's labels
/// just ahead of the piece (on the side its normal points to) and just
/// behind it. Both surfaces are simple in the cell ([`simple_tree`]): the
/// piece's own solid is outside ahead of it and inside behind it, and the
/// other's labels differ across the plane exactly where one piece of the
/// other's lies there, facing the way its labels change.
///
/// The result's boundary runs through the fragment, facing the way the
/// kept piece is written (a piece of B turned around for `a − b`), where
/// the result holds the point just behind that way and not the one ahead.
/// Where a piece of the other operand would be written there facing the
/// same way (a shared area), one copy is kept: B's where `b_copy` (see
/// [`b_copies_kept`]), else A's.
fn coplanar_keeps(op: BoolOp, of_a: bool, b_copy: bool, (ahead, behind): (bool, bool)) -> bool {
    let holds = |own: bool, other: bool| {
        let (a, b) = if of_a { (own, other) } else { (other, own) };
        match op {
            BoolOp::Union => a || b,
            BoolOp::Intersection => a && b,
            BoolOp::Difference => a && !b,
        }
    };
    let (front, back) = (holds(false, ahead), holds(true, behind));
    // whether the other's piece there is written facing the same way
    let turned = op == BoolOp::Difference;
    let twin = match turned {
        true => ahead && !behind,
        false => !ahead && behind,
    };
    // the result's boundary there, facing the way this piece is written
    // (a piece of B turned around for a difference faces the other way)
    let bounds = match !of_a && turned {
        true => front && !back,
        false => back && !front,
    };
    // the other operand's copy of it, where that is the one kept
    let theirs = twin && b_copy == of_a;
    bounds && !theirs
}

/// The planes where pieces of the two operands lie in a cell, each with
/// whether B's copy of an area both cover is the one kept: the copy that
/// can stay whole. For `a ∪ b` the result there covers both pieces, so
/// B's where every piece of A in that plane lies within one of B's; for
/// `a ∩ b` it covers what both do, so B's where every piece of B lies
/// within one of A's (a box with a prism standing in it keeps the prism's
/// faces whole and drops the box's); for `a − b`, where a piece of B
/// would be written turned around onto one of A's, A's.
fn b_copies_kept<'p>(op: BoolOp, a: &'p [Polygon], b: &'p [Polygon]) -> Vec<(&'p Plane, bool)> {
    let (inner, outer) = match op {
        BoolOp::Union => (a, b),
        BoolOp::Intersection => (b, a),
        BoolOp::Difference => return Vec::new(),
    };
    let mut planes: Vec<(&Plane, bool)> = Vec::new();
    for q in inner {
        let mut twins = (outer.iter())
            .filter(|p| p.support().is_coincident(q.support()))
            .peekable();
        if twins.peek().is_none() {
            continue;
        }
        let within = twins.any(|p| contains_in_plane(p, q));
        match planes
            .iter_mut()
            .find(|(h, _)| h.is_coincident(q.support()))
        {
            Some((_, all)) => *all &= within,
            None => planes.push((q.support(), within)),
        }
    }
    planes
}

/// `true` if the convex polygon `q` lies within `p`, of the same plane:
/// every corner of `q` on or behind every edge plane of `p`.
fn contains_in_plane(p: &Polygon, q: &Polygon) -> bool {
    p.edge_planes()
        .iter()
        .all(|e| q.vertices().iter().all(|v| v.classify(e) != Side::Front))
}

/// `true` if every vertex of `p` lies strictly on one side of `plane`.
fn strictly_one_side(p: &impl ConvexFace, plane: &Plane) -> bool {
    let mut sides = (0..p.corner_count()).map(|i| p.corner(i).classify(plane));
    let first = sides.next().unwrap_or(Side::On);
    first != Side::On && sides.all(|s| s == first)
}

/// `true` if the closed polygons `p` and `q` are apart by a support plane:
/// one lies strictly on one side of the other's. Polygons that meet are
/// never apart; some that do not meet are not found apart (a sufficient
/// test only).
pub(crate) fn apart(p: &impl ConvexFace, q: &impl ConvexFace) -> bool {
    strictly_one_side(q, p.support()) || strictly_one_side(p, q.support())
}

/// For each piece of `a`, whether it is apart from every piece of `b`
/// ([`apart`]), and the same for `b`'s pieces: an isolated piece meets
/// no piece of the other surface in the cell, closed sets as they are.
pub(crate) fn isolated(a: &[Polygon], b: &[Polygon]) -> (Vec<bool>, Vec<bool>) {
    let mut ia = vec![true; a.len()];
    let mut ib = vec![true; b.len()];
    for (i, p) in a.iter().enumerate() {
        for (j, q) in b.iter().enumerate() {
            if !apart(p, q) {
                ia[i] = false;
                ib[j] = false;
            }
        }
    }
    (ia, ib)
}

/// The walls `w[k]` of its cell that the piece `p` (a face clipped to the
/// cell) crosses into the next cell, as bits `1 << k`: the piece has an
/// edge on the wall, and that edge does not lie along a border of the
/// wall (both ends on one perpendicular wall), so every point inside the
/// edge lies inside the wall's rectangle, where the face goes on into the
/// cells beyond.
pub(crate) fn wall_edges(p: &Polygon, w: &[Plane; 6]) -> u8 {
    let (edges, verts) = (p.edge_planes(), p.vertices());
    let n = verts.len();
    let mut mask = 0u8;
    for (k, wall) in w.iter().enumerate() {
        let Some(e) = edges.iter().position(|e| e == wall) else {
            continue;
        };
        let (v0, v1) = (&verts[e], &verts[(e + 1) % n]);
        let along_border = w.iter().enumerate().any(|(j, other)| {
            j / 2 != k / 2 && v0.classify(other) == Side::On && v1.classify(other) == Side::On
        });
        if !along_border {
            mask |= 1 << k;
        }
    }
    mask
}

/// `face` clipped to the cell whose walls are `w`, by every wall: the
/// reference [`clip_in`] is tested against.
#[cfg(test)]
pub(crate) fn clip_to(face: &Polygon, w: &[Plane; 6]) -> Option<Polygon> {
    let mut p = face.clone();
    for wall in w {
        if !p.clip(wall, Side::Back) {
            return None;
        }
    }
    Some(p)
}

/// The piece of `face` in the cell `cell` (walls `w`, interior behind),
/// `None` if no area is left; `fb` is a box holding the face. A wall the
/// box lies behind is not tried, and a box apart from the cell gives
/// nothing at once: the piece that clipping by all six walls gives, with
/// fewer vertices classified.
pub(crate) fn clip_in(face: &Polygon, fb: &IBox, cell: &IBox, w: &[Plane; 6]) -> Option<Polygon> {
    if !overlaps(fb, cell) {
        return None;
    }
    clip_owned(face.clone(), fb, cell, w)
}

/// [`clip_in`] of a polygon the caller gives up, whose box `fb` meets the
/// cell.
fn clip_owned(mut p: Polygon, fb: &IBox, cell: &IBox, w: &[Plane; 6]) -> Option<Polygon> {
    for wall in walls_crossed(fb, cell, w) {
        if !p.clip(wall, Side::Back) {
            return None;
        }
    }
    Some(p)
}

/// The walls `w` of the cell `cell` that a face whose box is `fb` may
/// reach beyond (those its box does not lie behind), in order.
fn walls_crossed<'w>(fb: &IBox, cell: &IBox, w: &'w [Plane; 6]) -> impl Iterator<Item = &'w Plane> {
    let (fb, cell) = (*fb, *cell);
    w.iter().enumerate().filter_map(move |(i, wall)| {
        let k = i / 2;
        let behind = if i % 2 == 0 {
            fb.0[k] >= cell.0[k]
        } else {
            fb.1[k] <= cell.1[k]
        };
        (!behind).then_some(wall)
    })
}

/// [`clip_in`] for a solid's face: an imported face is clipped from its
/// grid corners ([`GridPolygon::clipped`](bsp_core::internals::GridPolygon::clipped):
/// the same piece, made more cheaply), only when its box meets the cell.
pub(crate) fn clip_face(
    face: &crate::solid::SolidFace,
    cell: &IBox,
    w: &[Plane; 6],
) -> Option<Polygon> {
    let fb = face.bx();
    if !overlaps(&fb, cell) {
        return None;
    }
    match face.as_grid() {
        Some(g) => g.clipped(walls_crossed(&fb, cell, w), 0),
        None => clip_owned(face.polygon().into_owned(), &fb, cell, w),
    }
}

/// The parts of `face` outside the box whose walls are `w`: convex
/// pieces, one per wall it crosses.
pub(crate) fn outside(face: &Polygon, w: &[Plane; 6]) -> Vec<Polygon> {
    let mut out = Vec::new();
    let mut rest = face.clone();
    for wall in w {
        let mut beyond = rest.clone();
        if beyond.clip(wall, Side::Front) {
            out.push(beyond);
        }
        if !rest.clip(wall, Side::Back) {
            break;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use bsp_core::GridPoint;

    /// The faces of the box `lo..hi` (grid corners), outward.
    fn cuboid(lo: GridPoint, hi: GridPoint) -> Vec<Polygon> {
        bsp_fixtures::grid_cuboid(lo, hi)
            .iter()
            .map(|g| Polygon::from_grid_points(g, 0).expect("a proper face"))
            .collect()
    }

    /// A tetrahedron's faces, outward (corners counter-clockwise from
    /// outside for `a, b, c` seen against `d` behind).
    fn tetra(a: GridPoint, b: GridPoint, c: GridPoint, d: GridPoint) -> Vec<Polygon> {
        [[a, b, c], [a, d, b], [b, d, c], [a, c, d]]
            .iter()
            .map(|f| Polygon::from_grid_points(f, 1).expect("a proper face"))
            .collect()
    }

    fn pieces(faces: &[Polygon], bx: &IBox) -> Vec<Polygon> {
        faces
            .iter()
            .filter_map(|f| clip_to(f, &walls(bx)))
            .collect()
    }

    /// The fragments and labels of `probe` in both labellings, which must
    /// agree fragment for fragment.
    fn agree(tree: &Labelled, part: &Partition<Cell>, probe: &Polygon) -> Vec<Cell> {
        let t = tree.push_down(probe.clone());
        let p = part.push_down(probe.clone(), part.root());
        assert_eq!(t.len(), p.len(), "fragment count of {probe:?}");
        for ((a, la), (b, lb)) in t.iter().zip(&p) {
            assert_eq!(la, lb, "label of a fragment of {probe:?}");
            assert_eq!(a.vertices().len(), b.vertices().len());
            assert!(
                a.vertices()
                    .iter()
                    .zip(b.vertices())
                    .all(|(x, y)| x.same_point(y))
            );
        }
        t.into_iter().map(|(_, c)| c).collect()
    }

    #[test]
    fn the_built_labels_are_the_winding_numbers_when_faces_agree() {
        // a box and a tetrahedron, cut by cells through them; probes are a
        // slanted tetrahedron's faces (no plane in common with either)
        let solids = [
            cuboid([0, 0, 0], [6, 5, 4]),
            tetra([0, 0, 0], [9, 1, 0], [2, 8, 1], [3, 2, 7]),
        ];
        let probes = tetra([-3, -2, -1], [11, 2, 3], [1, 12, -2], [4, 3, 13]);
        let cells: [IBox; 4] = [
            ([-5, -5, -5], [20, 20, 20]),
            ([1, 1, 1], [3, 3, 9]),
            ([-2, 2, -2], [4, 9, 2]),
            ([3, -1, 2], [9, 9, 9]),
        ];
        let mut seen = [false; 2];
        for s in &solids {
            for bx in &cells {
                let ps = pieces(s, bx);
                if ps.is_empty() {
                    continue;
                }
                let l = Labelled::new(bx, ps.clone(), || panic!("pieces decide")).unwrap();
                assert!(matches!(l, Labelled::Tree(_)), "one solid's faces agree");
                let part = solid(bx, ps, || panic!("pieces decide")).unwrap();
                for probe in pieces(&probes, bx) {
                    for c in agree(&l, &part, &probe) {
                        seen[(c == Cell::In) as usize] = true;
                    }
                }
            }
        }
        assert_eq!(seen, [true, true], "probes reach inside and outside");
    }

    #[test]
    fn faces_of_both_orientations_in_one_plane_take_the_partition() {
        // a block above z = 0 and another below it, side by side: the
        // plane z = 0 holds a face facing down and one facing up
        let mut faces = cuboid([0, 0, 0], [2, 2, 2]);
        faces.extend(cuboid([4, 0, -2], [6, 2, 0]));
        let bx: IBox = ([-1, -1, -1], [7, 3, 1]);
        let ps = pieces(&faces, &bx);
        let l = Labelled::new(&bx, ps.clone(), || panic!("pieces decide")).unwrap();
        let Labelled::Partition(part) = &l else {
            panic!("opposite faces in one plane need the regions");
        };
        // a horizontal probe just above z = 0 is inside the first block
        // only, one just below inside the second only
        let strip = |z2: i32| {
            // the plane 2z = z2 (half-integer z) through a strip x ∈ [-1, 7]
            let n = [0, 0, 2];
            let support = bsp_core::Plane::new(n, -(z2 as i128)).unwrap();
            let mut p = bsp_core::internals::box_section(&support).unwrap();
            for w in walls(&bx) {
                assert!(p.clip(&w, Side::Back));
            }
            p
        };
        let inside = |p: &Polygon| -> Vec<(i64, Cell)> {
            let mut v: Vec<(i64, Cell)> = part
                .push_down(p.clone(), part.root())
                .into_iter()
                .map(|(q, c)| {
                    let x = q.vertices().iter().map(|v| v.approx_f64()[0]).sum::<f64>()
                        / q.vertices().len() as f64;
                    (x.floor() as i64, c)
                })
                .filter(|&(_, c)| c == Cell::In)
                .collect();
            v.sort_unstable_by_key(|&(x, _)| x);
            v
        };
        let above = inside(&strip(1));
        let below = inside(&strip(-1));
        assert!(!above.is_empty() && above.iter().all(|&(x, _)| (0..2).contains(&x)));
        assert!(!below.is_empty() && below.iter().all(|&(x, _)| (4..6).contains(&x)));
    }

    fn area(p: &Polygon) -> f64 {
        let v: Vec<[f64; 3]> = p.vertices().iter().map(|q| q.approx_f64()).collect();
        let n = p.support().normal().map(|c| c as f64);
        let mut a = [0.0; 3];
        for i in 1..v.len() - 1 {
            let (e, f) = (
                [0, 1, 2].map(|k| v[i][k] - v[0][k]),
                [0, 1, 2].map(|k| v[i + 1][k] - v[0][k]),
            );
            a[0] += e[1] * f[2] - e[2] * f[1];
            a[1] += e[2] * f[0] - e[0] * f[2];
            a[2] += e[0] * f[1] - e[1] * f[0];
        }
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        (a[0] * n[0] + a[1] * n[1] + a[2] * n[2]) / len / 2.0
    }

    #[test]
    fn kept_fragments_of_one_split_are_put_back_together() {
        // two blocks as one operand, the second moved about; a square
        // through the first at z = 1 (in no face's plane) and beside the
        // second, of which the part outside the blocks stays: the planes of
        // the second block's faces cut the square where nothing is dropped
        let sq = Polygon::from_grid_points(&[[-4, -1, 1], [4, -1, 1], [4, 8, 1], [-4, 8, 1]], 7)
            .unwrap();
        let bx: IBox = ([-5, -5, -5], [13, 9, 7]);
        let out = |c: Cell| c == Cell::Out;
        let (mut fewer, mut cases) = (0, 0);
        for dx in 5..8 {
            for h in 3..7 {
                for dz in [-1, 0] {
                    let mut faces = cuboid([0, 0, 0], [2, 2, 2]);
                    faces.extend(cuboid([dx, -1, dz], [dx + 2, h, dz + 3]));
                    let l = Labelled::new(&bx, pieces(&faces, &bx), || panic!("pieces decide"))
                        .unwrap();
                    let in_plane = |_: &Plane, _: Cell, _: Cell| panic!("no plane shared");
                    let Fate::Cut(kept) = fate(&sq, &l, out, in_plane) else {
                        panic!("the first block cuts the square");
                    };
                    let leaves = l.push_down(sq.clone());
                    let kept_leaves = leaves.iter().filter(|(_, c)| out(*c)).count();
                    let total: f64 = kept.iter().map(area).sum();
                    assert_eq!(total, 8.0 * 9.0 - 4.0, "the kept area");
                    assert!(kept.len() <= kept_leaves);
                    fewer += (kept.len() < kept_leaves) as u32;
                    cases += 1;
                    // everything kept, or everything dropped: the piece
                    assert!(matches!(fate(&sq, &l, |_| true, in_plane), Fate::Keep));
                    assert!(matches!(fate(&sq, &l, |_| false, in_plane), Fate::Drop));
                }
            }
        }
        assert!(fewer > 0, "no split put back in {cases} cases");
    }

    #[test]
    fn clipping_by_the_box_gives_the_clipped_piece() {
        // faces with grid and implicit vertices (a tetrahedron's faces cut
        // by a slanted plane) against cells around and across them
        let cut = bsp_core::Plane::new([1, 2, 3], -20).unwrap();
        let mut faces = tetra([0, 0, 0], [9, 1, 0], [2, 8, 1], [3, 2, 7]);
        let halves: Vec<Polygon> = faces
            .iter()
            .filter_map(|f| {
                let mut h = f.clone();
                h.clip(&cut, Side::Back).then_some(h)
            })
            .collect();
        faces.extend(halves);
        let (mut same, mut some) = (0, 0);
        for lo in [-2, 0, 1, 3] {
            for size in [1, 2, 4, 12] {
                for shift in [[0, 0, 0], [1, -1, 2], [3, 2, 0]] {
                    let cell: IBox = (
                        [0, 1, 2].map(|k| (lo + shift[k]) as i64),
                        [0, 1, 2].map(|k| (lo + shift[k] + size) as i64),
                    );
                    let w = walls(&cell);
                    for f in &faces {
                        let a = clip_to(f, &w);
                        let b = clip_in(f, &crate::index::polygon_box(f), &cell, &w);
                        match (&a, &b) {
                            (None, None) => {}
                            (Some(p), Some(q)) => {
                                assert_eq!(p.vertices().len(), q.vertices().len());
                                assert!(
                                    p.vertices()
                                        .iter()
                                        .zip(q.vertices())
                                        .all(|(x, y)| x.same_point(y))
                                );
                                some += 1;
                            }
                            _ => panic!("{f:?} in {cell:?}: {a:?} against {b:?}"),
                        }
                        same += 1;
                    }
                }
            }
        }
        assert!(some > 20 && some < same, "{some} pieces of {same}");
    }

    #[test]
    fn overlapping_shells_are_not_a_solid() {
        // two boxes overlapping in [1, 2]³ as one operand: inside both the
        // winding number is 2; the pieces face their planes' ways, but a
        // leaf lies in front of one box's face and behind the other's
        let mut faces = cuboid([0, 0, 0], [2, 2, 2]);
        faces.extend(cuboid([1, 1, 1], [3, 3, 3]));
        let bx: IBox = ([-1, -1, -1], [4, 4, 4]);
        let ps = pieces(&faces, &bx);
        let tree = BspTree::build(ps.clone(), &BuildOptions::default());
        assert!(tree.faces_agree());
        assert!(!faces_bound(&tree));
        assert!(matches!(
            Labelled::new(&bx, ps, || panic!("pieces decide")),
            Err(CsgError::NotASolid)
        ));
        // one box alone bounds
        let one = BspTree::build(cuboid([0, 0, 0], [2, 2, 2]), &BuildOptions::default());
        assert!(faces_bound(&one));
    }
}
