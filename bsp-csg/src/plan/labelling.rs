//! Labelling: whether leaves, regions and pieces lie inside the other
//! operand's solid.
//!
//! - [`FreeRegions`]: the leaves free of one surface, joined with their
//!   free neighbours into regions, each labelled by one exact winding
//!   number.
//! - [`Labeller::untouched_faces`]: each face the other surface meets
//!   nowhere gets one label for the whole face.
//! - [`Labeller::easy_cells`]: the pieces of the easy cells are labelled
//!   along their faces from the cells around.
//!
//! Pieces known to share a label are joined in the workspace's union-find
//! ([`UnionFind`]: a set's root is its smallest member), whose nodes
//! 0 and 1 stand for the labels outside and inside; a group no known
//! label reaches asks the winding number at a grid vertex of a member.

use bsp_core::GridPoint;
use bsp_core::internals::{ConvexFace, UnionFind};
use bsp_core::par;
use rustc_hash::{FxHashMap, FxHashSet};
use smallvec::SmallVec;

use super::local;
use super::mixed_cell::{EasyPieces, PieceFate, Touched, WallCrossings};
use super::octree::{Leaf, walls};
use super::operands::Operand;
use super::settle::{FacePiece, PiecedFace};
use crate::index::{IBox, holds};
use crate::{CsgError, Solid};

/// Connected regions of octree leaves free of one surface, each wholly
/// inside or outside that surface's solid.
pub(super) struct FreeRegions {
    /// Each leaf's region, by its first leaf.
    root: Vec<u32>,
    /// Each region that holds faces to label: whether it is inside.
    inside: FxHashMap<u32, bool>,
}

impl FreeRegions {
    /// The regions of the leaves free of operand `of`'s surface, labelled
    /// by the winding numbers of `solid`, its solid.
    pub(super) fn new(
        leaves: &[Leaf],
        adjacent: &[(u32, u32)],
        of: Operand,
        solid: &Solid,
    ) -> FreeRegions {
        let free = |l: &Leaf| l.free_of(of);
        let n = leaves.len();
        let mut groups = UnionFind::new(n);
        for &(a, b) in adjacent {
            if free(&leaves[a as usize]) && free(&leaves[b as usize]) {
                groups.union(a, b);
            }
        }
        let root: Vec<u32> = (0..n as u32).map(|x| groups.find(x)).collect();
        // one winding number per region that holds faces to label
        let mut wanted: Vec<u32> = (0..n)
            .filter(|&l| free(&leaves[l]) && !(leaves[l].a.is_empty() && leaves[l].b.is_empty()))
            .map(|l| root[l])
            .collect();
        wanted.sort_unstable();
        wanted.dedup();
        let qs: Vec<GridPoint> = wanted
            .iter()
            .map(|&r| leaves[r as usize].bx.0.map(|c| c as i32))
            .collect();
        let inside: FxHashMap<u32, bool> = wanted
            .iter()
            .zip(solid.windings(&qs))
            .map(|(&r, w)| (r, w != 0))
            .collect();
        FreeRegions { root, inside }
    }

    /// Whether the free leaf `leaf` (one holding faces) lies inside.
    pub(super) fn inside(&self, leaf: u32) -> bool {
        self.inside[&self.root[leaf as usize]]
    }
}

/// One operand's faces and pieces labelled: inside the other operand's
/// solid or not.
pub(super) struct Labeller<'p> {
    /// The operand whose pieces are labelled.
    pub(super) operand: Operand,
    /// Its solid, and the other operand's (whose winding numbers are
    /// the labels).
    pub(super) solid: &'p Solid,
    pub(super) other: &'p Solid,
    pub(super) leaves: &'p [Leaf],
    /// The regions free of the other surface.
    pub(super) other_regions: &'p FreeRegions,
    /// What became of this operand's listed faces in the cells that
    /// built their partitions, by leaf.
    pub(super) fates: &'p FxHashMap<u32, Vec<PieceFate>>,
    /// Whether this operand's pieces inside the other solid are kept.
    pub(super) keep_inside: bool,
}

/// A face with pieces, as [`Labeller::untouched_faces`] first finds it.
#[derive(Clone, Copy)]
enum OwnLabel {
    /// The other surface may meet it: it has no label as a whole.
    Touched,
    /// An untouched face whose label one of its own pieces tells.
    Known(bool),
    /// An untouched face whose pieces tell nothing.
    Unknown,
}

impl Labeller<'_> {
    /// The label of the `listed`-th face of this operand in the mixed
    /// leaf `leaf`, known from the fate of its piece there, if that cell
    /// built its partitions: a piece kept whole is inside when pieces
    /// inside are kept.
    fn known(&self, leaf: u32, listed: u32) -> Option<bool> {
        match self.fates.get(&leaf).map(|v| &v[listed as usize]) {
            Some(PieceFate::Keep) => Some(self.keep_inside),
            Some(PieceFate::Drop) => Some(!self.keep_inside),
            _ => None,
        }
    }

    /// Whether the grid point `g` (not on the other surface) lies inside
    /// the other solid: its winding number.
    fn inside(&self, g: GridPoint) -> bool {
        self.other.winding(g) != 0
    }

    /// This operand's faces in the leaf `l` (ascending ids; in a mixed
    /// leaf, in the order of its listed faces).
    fn listed(&self, l: u32) -> &[u32] {
        self.leaves[l as usize].faces(self.operand)
    }

    /// Whether the leaf `l` is free of the other surface.
    fn free(&self, l: u32) -> bool {
        self.leaves[l as usize].free_of(self.operand.other())
    }

    /// A face's grid corners.
    fn corners(&self, f: u32) -> SmallVec<[GridPoint; 4]> {
        let face = self.solid.face(f);
        (0..face.corner_count())
            .filter_map(|i| face.corner(i).as_grid())
            .collect()
    }

    /// The labels (inside the other solid or not) of the untouched faces
    /// among `pieced` (those `touched` says the other surface cannot
    /// meet), by face id (`None` for the others), each one label for the
    /// whole face, which meets the other surface nowhere:
    ///
    /// - a grid corner of it in a free leaf of its own: that leaf's
    ///   region's label;
    /// - a piece of it whose fate in a mixed cell is known;
    /// - another untouched face of this operand with a common grid corner
    ///   (a small ball around the corner is free of the other surface);
    /// - for a group none of these reach, the winding number at a grid
    ///   corner of its first face (every untouched face has one).
    pub(super) fn untouched_faces(
        &self,
        pieced: &[PiecedFace],
        touched: &Touched,
    ) -> Result<Vec<Option<bool>>, CsgError> {
        let own: Vec<OwnLabel> = par::map_slice(pieced, |p| self.own_label(p, touched));
        let by_id = |label: &dyn Fn(usize) -> Result<Option<bool>, CsgError>| {
            let mut out: Vec<Option<bool>> = vec![None; self.solid.slot_count()];
            for (i, p) in pieced.iter().enumerate() {
                out[p.face as usize] = label(i)?;
            }
            Ok(out)
        };
        if own.iter().all(|x| !matches!(x, OwnLabel::Unknown)) {
            return by_id(&|i| match own[i] {
                OwnLabel::Known(inside) => Ok(Some(inside)),
                OwnLabel::Touched | OwnLabel::Unknown => Ok(None),
            });
        }
        let labels = self.join_untouched(pieced, &own)?;
        by_id(&|i| match own[i] {
            OwnLabel::Touched => Ok(None),
            OwnLabel::Known(_) | OwnLabel::Unknown => labels[i]
                .map(Some)
                .ok_or_else(|| CsgError::Internal("an untouched face got no label".into())),
        })
    }

    /// A face's label as its own pieces tell it: a grid corner of it in a
    /// free leaf, or a piece with a known fate.
    fn own_label(&self, p: &PiecedFace, touched: &Touched) -> OwnLabel {
        if touched.face(self.operand, p.face) {
            return OwnLabel::Touched;
        }
        let cs = self.corners(p.face);
        let corner_in = |l: u32| cs.iter().any(|g| holds(&self.leaves[l as usize].bx, g));
        let label = p.pieces.iter().find_map(|piece| match *piece {
            FacePiece::InFreeLeaf(l) if corner_in(l) => Some(self.other_regions.inside(l)),
            FacePiece::InMixedLeaf { leaf, listed } => self.known(leaf, listed),
            _ => None,
        });
        label.map_or(OwnLabel::Unknown, OwnLabel::Known)
    }

    /// The labels of the untouched faces among `pieced` (by place),
    /// joined through their common grid corners, the groups no label
    /// reaches asked at a corner.
    fn join_untouched(
        &self,
        pieced: &[PiecedFace],
        own: &[OwnLabel],
    ) -> Result<Vec<Option<bool>>, CsgError> {
        // nodes: the two labels, then the faces by place
        let mut groups = UnionFind::new(pieced.len() + 2);
        let mut first: FxHashMap<GridPoint, u32> = FxHashMap::default();
        for (i, x) in own.iter().enumerate() {
            let node = i as u32 + 2;
            match *x {
                OwnLabel::Touched => continue,
                OwnLabel::Known(inside) => {
                    groups.union(node, u32::from(inside));
                }
                OwnLabel::Unknown => {}
            }
            for g in self.corners(pieced[i].face) {
                let at = *first.entry(g).or_insert(node);
                groups.union(node, at);
            }
        }
        if groups.find(1) == 0 {
            return Err(CsgError::Internal(
                "an untouched face got both labels".into(),
            ));
        }
        // groups no label reached: the winding number at a grid corner
        let mut asked: Vec<(u32, GridPoint)> = Vec::new();
        let mut seen: FxHashSet<u32> = FxHashSet::default();
        for (i, x) in own.iter().enumerate() {
            if !matches!(x, OwnLabel::Touched) {
                let r = groups.find(i as u32 + 2);
                if r >= 2 && seen.insert(r) {
                    asked.push((r, self.corners(pieced[i].face)[0]));
                }
            }
        }
        answer(&mut groups, &asked, &|g| self.inside(g));
        Ok((0..pieced.len())
            .map(|i| label(&mut groups, i as u32 + 2))
            .collect())
    }

    /// Labels (inside the other solid or not) for this operand's pieces
    /// in the easy cells (`easy`), per cell and listed face; `None` where
    /// no label reached a piece. `crossings` are the walls each isolated
    /// piece of a mixed cell crosses (easy cells' and built cells'), and
    /// `face_label` the labels of the untouched faces, by id.
    ///
    /// A piece meeting no piece of the other surface in its cell (isolated)
    /// has one label: the other surface does not meet its inside, which lies
    /// in the open cell. Pieces with the same label are joined, and the
    /// groups take their label from a member whose label is known:
    ///
    /// - Two pieces of one face in neighbouring cells `s` and `l`, when `s`'s
    ///   piece crosses the wall into `l` ([`local::wall_edges`]: an edge on
    ///   `s`'s wall facing `l`, with a point `y` inside the wall's rectangle,
    ///   which lies within `l`'s) and each is isolated or in a cell free of
    ///   the other surface. A face of the other surface through `y` would have
    ///   a piece in `s` or `l` (no face lies in a wall) meeting one of them,
    ///   so a small disc of the face around `y` is free of it and joins the
    ///   two pieces.
    /// - Two isolated pieces of one cell sharing a grid vertex: a small ball
    ///   around it is free of the other surface.
    ///
    /// Known labels: a face's piece in a free cell (its region's winding
    /// number), an isolated piece of a cell that built its partitions, a
    /// piece of a face labelled as a whole (an untouched face, which an
    /// easy cell does not clip), and, for a group no known label reaches,
    /// the winding number of a grid vertex of one of its pieces.
    pub(super) fn easy_cells(
        &self,
        adjacent: &[(u32, u32)],
        crossings: &FxHashMap<u32, WallCrossings>,
        easy: &FxHashMap<u32, EasyPieces>,
        face_label: &[Option<bool>],
    ) -> Result<FxHashMap<u32, Vec<Option<bool>>>, CsgError> {
        let nodes = EasyNodes::new(easy, adjacent);
        let mut joins = self.joins_across_walls(&nodes, crossings);
        for &l in &nodes.cells {
            let b = nodes.base[&l];
            joins.extend(easy[&l].touching.iter().map(|&(i, j)| (b + i, b + j)));
            // a face whose label is known as a whole (untouched)
            joins.extend(self.listed(l).iter().enumerate().filter_map(|(i, &f)| {
                face_label[f as usize].map(|x| (b + i as u32, u32::from(x)))
            }));
        }
        let mut groups = UnionFind::new(nodes.count as usize);
        for (a, b) in joins {
            groups.union(a, b);
        }
        if groups.find(1) == 0 {
            return Err(CsgError::Internal(
                "an easy cell's pieces got both labels".into(),
            ));
        }
        // groups no known label reached: the winding number at a grid vertex
        let mut asked: FxHashMap<u32, GridPoint> = FxHashMap::default();
        for &l in &nodes.cells {
            let b = nodes.base[&l];
            for (i, g) in easy[&l].grid_vertex.iter().enumerate() {
                if let Some(g) = g {
                    let r = groups.find(b + i as u32);
                    if r >= 2 {
                        asked.entry(r).or_insert(*g);
                    }
                }
            }
        }
        let mut asked: Vec<(u32, GridPoint)> = asked.into_iter().collect();
        asked.sort_unstable();
        answer(&mut groups, &asked, &|g| self.inside(g));
        let mut out = FxHashMap::default();
        for &l in &nodes.cells {
            let b = nodes.base[&l];
            let labels = (0..easy[&l].grid_vertex.len() as u32)
                .map(|i| label(&mut groups, b + i))
                .collect();
            out.insert(l, labels);
        }
        Ok(out)
    }

    /// The node of the `listed`-th face of this operand in the mixed leaf
    /// `leaf`, if its piece is isolated: its own in an easy cell, else the
    /// label its fate tells.
    fn node(
        &self,
        nodes: &EasyNodes,
        crossings: &FxHashMap<u32, WallCrossings>,
        leaf: u32,
        listed: u32,
    ) -> Option<u32> {
        crossings.get(&leaf).and_then(|v| v[listed as usize])?;
        match nodes.base.get(&leaf) {
            Some(b) => Some(b + listed),
            None => self.known(leaf, listed).map(u32::from),
        }
    }

    /// The pairs of nodes joined across walls: each easy cell's pieces
    /// with the same face's pieces in the cells around, across the walls
    /// the smaller of the two cells crosses.
    fn joins_across_walls(
        &self,
        nodes: &EasyNodes,
        crossings: &FxHashMap<u32, WallCrossings>,
    ) -> Vec<(u32, u32)> {
        par::flat_map(nodes.cells.len(), |i| {
            let l = nodes.cells[i];
            let mut out = Vec::new();
            for &m in nodes.around.get(&l).map_or(&[][..], |v| &v[..]) {
                self.join_neighbours(nodes, crossings, l, m, &mut out);
            }
            out
        })
    }

    /// The joins of the easy cell `l`'s pieces with the same faces'
    /// pieces in its neighbour `m`, into `out`.
    fn join_neighbours(
        &self,
        nodes: &EasyNodes,
        crossings: &FxHashMap<u32, WallCrossings>,
        l: u32,
        m: u32,
        out: &mut Vec<(u32, u32)>,
    ) {
        let (bl, bm) = (&self.leaves[l as usize].bx, &self.leaves[m as usize].bx);
        let (here, there) = (facing(bl, bm), facing(bm, bl));
        if here.is_none() && there.is_none() {
            return;
        }
        let (b, others) = (nodes.base[&l], self.listed(m));
        let crossed = &crossings[&l];
        for (i, &f) in self.listed(l).iter().enumerate() {
            let Some(mask) = crossed[i] else { continue };
            let Ok(j) = others.binary_search(&f) else {
                continue;
            };
            // the face's piece in `m`: its node, and the walls it
            // crosses (a free cell's piece is clipped when needed)
            let (other, other_mask) = if self.free(m) {
                (self.other_regions.inside(m) as u32, None)
            } else {
                let Some(node) = self.node(nodes, crossings, m, j as u32) else {
                    continue;
                };
                (node, crossings[&m][j])
            };
            let linked = match (here, there) {
                (Some(w), _) => mask & (1 << w) != 0,
                (None, Some(w)) => {
                    let mm = other_mask.unwrap_or_else(|| {
                        let wm = walls(bm);
                        local::clip_face(self.solid.face(f), bm, &wm)
                            .map_or(0, |q| local::wall_edges(&q, &wm))
                    });
                    mm & (1 << w) != 0
                }
                (None, None) => false,
            };
            if linked {
                out.push((b + i as u32, other));
            }
        }
    }
}

/// The easy cells' pieces as the nodes of one union-find: 0 and 1 stand
/// for the labels outside and inside, then come the listed faces of each
/// easy cell from its base.
struct EasyNodes {
    /// The easy cells, in order.
    cells: Vec<u32>,
    /// Each easy cell's first node.
    base: FxHashMap<u32, u32>,
    /// The number of nodes.
    count: u32,
    /// Each easy cell's neighbours.
    around: FxHashMap<u32, Vec<u32>>,
}

impl EasyNodes {
    /// The nodes of the easy cells `easy`, and their neighbours among the
    /// pairs `adjacent`.
    fn new(easy: &FxHashMap<u32, EasyPieces>, adjacent: &[(u32, u32)]) -> EasyNodes {
        let mut base: FxHashMap<u32, u32> = FxHashMap::default();
        let mut cells: Vec<u32> = easy.keys().copied().collect();
        cells.sort_unstable();
        let mut count = 2u32;
        for &l in &cells {
            base.insert(l, count);
            count += easy[&l].grid_vertex.len() as u32;
        }
        let mut around: FxHashMap<u32, Vec<u32>> = FxHashMap::default();
        for &(x, y) in adjacent {
            for (p, q) in [(x, y), (y, x)] {
                if base.contains_key(&p) {
                    around.entry(p).or_default().push(q);
                }
            }
        }
        EasyNodes {
            cells,
            base,
            count,
            around,
        }
    }
}

/// The wall of the cell `s` that faces the cell `l`, if they are
/// neighbours across it and the wall's rectangle of `s` lies within `l`'s
/// (index into [`walls`]).
fn facing(s: &IBox, l: &IBox) -> Option<usize> {
    for k in 0..3 {
        let wall = if s.1[k] + 1 == l.0[k] {
            2 * k + 1
        } else if l.1[k] + 1 == s.0[k] {
            2 * k
        } else {
            continue;
        };
        let within = (0..3)
            .filter(|&j| j != k)
            .all(|j| l.0[j] <= s.0[j] && s.1[j] <= l.1[j]);
        return within.then_some(wall);
    }
    None
}

/// Joins each group `(root, g)` of `asked` to the label `inside(g)`
/// (asked in parallel). Nodes 0 and 1 stand for the labels outside and
/// inside: a group's root is its smallest node, so they stay roots and
/// name their groups' label.
fn answer(
    groups: &mut UnionFind,
    asked: &[(u32, GridPoint)],
    inside: &(dyn Fn(GridPoint) -> bool + Sync),
) {
    let answers: Vec<(u32, bool)> = par::map_slice(asked, |&(r, g)| (r, inside(g)));
    for (r, x) in answers {
        groups.union(r, u32::from(x));
    }
}

/// The label of node `x`'s group: `Some(inside)`, or `None` if no label
/// reached it.
fn label(groups: &mut UnionFind, x: u32) -> Option<bool> {
    match groups.find(x) {
        0 => Some(false),
        1 => Some(true),
        _ => None,
    }
}
