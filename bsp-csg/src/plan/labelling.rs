//! Labelling: which cells, regions and pieces lie inside the other solid.

use bsp_core::internals::ConvexFace;
use bsp_core::{GridPoint, Polygon};
use rayon::prelude::*;
use rustc_hash::FxHashMap;
use smallvec::SmallVec;

use super::local;
use super::octree::{Leaf, walls};
use super::settle::Piece;
use crate::index::{IBox, holds};
use crate::solid::Face;
use crate::{CsgError, Solid};

/// The wall of the cell `s` that faces the cell `l`, if they are
/// neighbours across it and the wall's rectangle of `s` lies within `l`'s
/// (index into [`walls`]).
pub(crate) fn facing(s: &IBox, l: &IBox) -> Option<usize> {
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

/// One operand's listed faces in an easy cell: a grid vertex of each
/// piece, and the pairs of pieces sharing a grid vertex.
pub(crate) struct Listed {
    grid: Vec<Option<GridPoint>>,
    touch: Vec<(u32, u32)>,
}

impl Listed {
    /// From the grid vertices of each listed face's piece in the cell:
    /// its clipped piece's (`index` into `pieces`), or for a face not
    /// clipped, its grid corners in the cell's box `bx` (the same points:
    /// the walls hold no grid point).
    pub(crate) fn new<'p>(
        fs: &[u32],
        face: impl Fn(u32) -> &'p Face,
        pieces: &[Polygon],
        index: &[Option<u32>],
        clipped: impl Fn(u32) -> bool,
        bx: &IBox,
    ) -> Listed {
        let grid_of = |p: &Polygon| -> SmallVec<[GridPoint; 4]> {
            p.vertices()
                .iter()
                .filter_map(|v| match v {
                    bsp_core::Point::Grid(g) => Some(*g),
                    _ => None,
                })
                .collect()
        };
        let verts: Vec<SmallVec<[GridPoint; 4]>> = fs
            .iter()
            .zip(index)
            .map(|(&f, i)| {
                if clipped(f) {
                    return i.map_or_else(SmallVec::new, |i| grid_of(&pieces[i as usize]));
                }
                let face = face(f);
                (0..face.corner_count())
                    .filter_map(|k| face.corner(k).as_grid())
                    .filter(|g| holds(bx, g))
                    .collect()
            })
            .collect();
        let mut touch = Vec::new();
        for i in 0..verts.len() {
            for j in i + 1..verts.len() {
                if verts[i].iter().any(|g| verts[j].contains(g)) {
                    touch.push((i as u32, j as u32));
                }
            }
        }
        Listed {
            grid: verts.iter().map(|v| v.first().copied()).collect(),
            touch,
        }
    }
}

/// Labels (inside the other solid or not) for one operand's pieces in
/// the easy cells (`listed`), per cell and listed face; `None` where no
/// label reached a piece.
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
/// number), an isolated piece of a cell that built its partitions
/// (`known`), a piece of a face labelled as a whole (`face_label`: an
/// untouched face, which an easy cell does not clip), and, for a group no
/// known label reaches, the winding number `inside` of a grid vertex of
/// one of its pieces.
#[allow(clippy::too_many_arguments)]
pub(crate) fn label_easy<'p>(
    side_a: bool,
    face: impl Fn(u32) -> &'p Face + Sync,
    leaves: &[Leaf],
    adjacent: &[(u32, u32)],
    masks: &FxHashMap<u32, Vec<Option<u8>>>,
    listed: &FxHashMap<u32, Listed>,
    known: &(dyn Fn(u32, u32) -> Option<bool> + Sync),
    face_label: &(dyn Fn(u32) -> Option<bool> + Sync),
    free_inside: &(dyn Fn(u32) -> bool + Sync),
    inside: &(dyn Fn(GridPoint) -> bool + Sync),
) -> Result<FxHashMap<u32, Vec<Option<bool>>>, CsgError> {
    // a leaf's faces of this operand (ascending ids; in a mixed leaf, in
    // the order of its listed faces), and whether it is free of the other
    let list = |l: u32| -> &[u32] {
        let leaf = &leaves[l as usize];
        if side_a { &leaf.a } else { &leaf.b }
    };
    let free = |l: u32| {
        let leaf = &leaves[l as usize];
        if side_a {
            leaf.b.is_empty()
        } else {
            leaf.a.is_empty()
        }
    };
    // nodes: 0 and 1 stand for the labels outside and inside, then the
    // listed faces of each easy cell from its base
    let mut base: FxHashMap<u32, u32> = FxHashMap::default();
    let mut cells: Vec<u32> = listed.keys().copied().collect();
    cells.sort_unstable();
    let mut n = 2u32;
    for &l in &cells {
        base.insert(l, n);
        n += listed[&l].grid.len() as u32;
    }
    // the node of the `i`-th listed face of a mixed cell, if it has one
    let node = |l: u32, i: u32| -> Option<u32> {
        masks.get(&l).and_then(|v| v[i as usize])?;
        match base.get(&l) {
            Some(b) => Some(b + i),
            None => known(l, i).map(u32::from),
        }
    };
    // the easy cells' neighbours
    let mut around: FxHashMap<u32, Vec<u32>> = FxHashMap::default();
    for &(x, y) in adjacent {
        for (p, q) in [(x, y), (y, x)] {
            if base.contains_key(&p) {
                around.entry(p).or_default().push(q);
            }
        }
    }
    // each easy cell's pieces joined with the same face's pieces in the
    // cells around, across the walls the smaller of the two crosses
    let mut joins: Vec<(u32, u32)> = cells
        .par_iter()
        .flat_map_iter(|&l| {
            let (b, fs) = (base[&l], list(l));
            let ml = &masks[&l];
            let mut out = Vec::new();
            for &m in around.get(&l).map_or(&[][..], |v| &v[..]) {
                let (bl, bm) = (&leaves[l as usize].bx, &leaves[m as usize].bx);
                let (here, there) = (facing(bl, bm), facing(bm, bl));
                if here.is_none() && there.is_none() {
                    continue;
                }
                let others = list(m);
                for (i, &f) in fs.iter().enumerate() {
                    let Some(mask) = ml[i] else { continue };
                    let Ok(j) = others.binary_search(&f) else {
                        continue;
                    };
                    // the face's piece in `m`: its node, and the walls it
                    // crosses (a free cell's piece is clipped when needed)
                    let (other, other_mask) = if free(m) {
                        (free_inside(m) as u32, None)
                    } else {
                        let Some(node) = node(m, j as u32) else {
                            continue;
                        };
                        (node, masks[&m][j])
                    };
                    let linked = match (here, there) {
                        (Some(w), _) => mask & (1 << w) != 0,
                        (None, Some(w)) => {
                            let mm = other_mask.unwrap_or_else(|| {
                                let (wm, g) = (walls(bm), face(f));
                                local::clip_face(g, bm, &wm)
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
            out
        })
        .collect();
    for &l in &cells {
        let b = base[&l];
        joins.extend(listed[&l].touch.iter().map(|&(i, j)| (b + i, b + j)));
        // a face whose label is known as a whole (untouched)
        joins.extend(
            list(l)
                .iter()
                .enumerate()
                .filter_map(|(i, &f)| face_label(f).map(|x| (b + i as u32, u32::from(x)))),
        );
    }
    let mut groups = UnionFind::new(n as usize);
    for (a, b) in joins {
        groups.join(a, b);
    }
    if groups.find(1) == 0 {
        return Err(CsgError::Internal(
            "an easy cell's pieces got both labels".into(),
        ));
    }
    // groups no known label reached: the winding number at a grid vertex
    let mut asked: FxHashMap<u32, GridPoint> = FxHashMap::default();
    for &l in &cells {
        let b = base[&l];
        for (i, g) in listed[&l].grid.iter().enumerate() {
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
    groups.answer(&asked, inside);
    let mut out = FxHashMap::default();
    for &l in &cells {
        let b = base[&l];
        let labels = (0..listed[&l].grid.len() as u32)
            .map(|i| groups.label(b + i))
            .collect();
        out.insert(l, labels);
    }
    Ok(out)
}

/// For each face of `a` and of `b` (by id; `false` for faces in no
/// mixed cell), whether it may meet the other surface: it is not apart
/// ([`local::apart`], whole faces) from some face of the other in some
/// mixed cell of `mixed`, or it has no grid corner (where its label could
/// be asked), or it is listed in a mixed cell where faces of the two
/// share a plane (which may be merged whole, pieces and all); and per
/// leaf, whether it is a clean mixed cell: one whose faces all are
/// untouched.
///
/// An untouched face meets the other surface nowhere: a common point
/// would lie in some leaf's closed cell, whose lists hold every face
/// meeting it (box and plane), so that leaf would be mixed and the two
/// faces tested there, and faces with a common point are never apart.
pub(crate) fn touched(
    mixed: &[u32],
    leaves: &[Leaf],
    a: &Solid,
    b: &Solid,
) -> (Vec<bool>, Vec<bool>, Vec<bool>) {
    let no_grid_corner = |f: &Face| (0..f.corner_count()).all(|i| f.corner(i).as_grid().is_none());
    let per_cell: Vec<(Vec<u32>, Vec<u32>)> = mixed
        .par_iter()
        .map(|&l| {
            let leaf = &leaves[l as usize];
            let fa: Vec<&Face> = leaf.a.iter().map(|&f| a.face(f)).collect();
            let fb: Vec<&Face> = leaf.b.iter().map(|&f| b.face(f)).collect();
            // a cell where faces of the two share a plane may be merged
            // as a whole (`local::boolean_pieces`): all its faces settle
            // piece by piece
            let shared = fa
                .iter()
                .any(|p| fb.iter().any(|q| p.support().is_coincident(q.support())));
            if shared {
                return (leaf.a.clone(), leaf.b.clone());
            }
            let mut ta: Vec<bool> = fa.iter().map(|f| no_grid_corner(f)).collect();
            let mut tb: Vec<bool> = fb.iter().map(|f| no_grid_corner(f)).collect();
            for (i, p) in fa.iter().enumerate() {
                for (j, q) in fb.iter().enumerate() {
                    if ta[i] && tb[j] {
                        continue; // both known already
                    }
                    if !local::apart(*p, *q) {
                        ta[i] = true;
                        tb[j] = true;
                    }
                }
            }
            let pick = |fs: &[u32], t: &[bool]| -> Vec<u32> {
                fs.iter()
                    .zip(t)
                    .filter(|(_, t)| **t)
                    .map(|(f, _)| *f)
                    .collect()
            };
            (pick(&leaf.a, &ta), pick(&leaf.b, &tb))
        })
        .collect();
    let (mut ta, mut tb) = (vec![false; a.faces.len()], vec![false; b.faces.len()]);
    for (xa, xb) in &per_cell {
        xa.iter().for_each(|&f| ta[f as usize] = true);
        xb.iter().for_each(|&f| tb[f as usize] = true);
    }
    let mut clean = vec![false; leaves.len()];
    for &l in mixed {
        let leaf = &leaves[l as usize];
        clean[l as usize] =
            leaf.a.iter().all(|&f| !ta[f as usize]) && leaf.b.iter().all(|&f| !tb[f as usize]);
    }
    (ta, tb, clean)
}

/// The labels (inside the other solid or not) of the untouched faces
/// among `pieces`, by face id (`n` ids; `None` for the others), each one
/// label for the whole face, which meets the other surface nowhere:
///
/// - a grid corner of it in a free cell of its own: that cell's region's
///   label;
/// - a piece of it whose fate in a mixed cell is known (`known`);
/// - another untouched face of this operand with a common grid corner
///   (a small ball around the corner is free of the other surface);
/// - for a group none of these reach, the winding number `inside` at a
///   grid corner of its first face (every untouched face has one).
#[allow(clippy::too_many_arguments)]
pub(crate) fn label_untouched<'p>(
    pieces: &[(u32, Vec<Piece>)],
    n: usize,
    untouched: &(dyn Fn(u32) -> bool + Sync),
    face: impl Fn(u32) -> &'p Face + Sync,
    leaves: &[Leaf],
    known: &(dyn Fn(u32, u32) -> Option<bool> + Sync),
    free_inside: &(dyn Fn(u32) -> bool + Sync),
    inside: &(dyn Fn(GridPoint) -> bool + Sync),
) -> Result<Vec<Option<bool>>, CsgError> {
    let corners = |f: u32| -> SmallVec<[GridPoint; 4]> {
        let face = face(f);
        (0..face.corner_count())
            .filter_map(|i| face.corner(i).as_grid())
            .collect()
    };
    // `None`: touched; `Some(None)`: untouched, no label of its own yet
    let own: Vec<Option<Option<bool>>> = pieces
        .par_iter()
        .map(|(f, ps)| {
            if !untouched(*f) {
                return None;
            }
            let cs = corners(*f);
            let corner_in = |l: u32| cs.iter().any(|g| holds(&leaves[l as usize].bx, g));
            let label = ps.iter().find_map(|p| match *p {
                Piece::Free(Some(l)) if corner_in(l) => Some(free_inside(l)),
                Piece::Mixed(l, i) => known(l, i),
                _ => None,
            });
            Some(label)
        })
        .collect();
    let by_id = |label: &dyn Fn(usize) -> Result<Option<bool>, CsgError>| {
        let mut out: Vec<Option<bool>> = vec![None; n];
        for (i, (f, _)) in pieces.iter().enumerate() {
            out[*f as usize] = label(i)?;
        }
        Ok(out)
    };
    if own.iter().all(|x| !matches!(x, Some(None))) {
        return by_id(&|i| Ok(own[i].flatten()));
    }
    // nodes: the two labels, then the faces by place
    let mut groups = UnionFind::new(pieces.len() + 2);
    let mut first: FxHashMap<GridPoint, u32> = FxHashMap::default();
    for (i, x) in own.iter().enumerate() {
        let Some(label) = x else { continue };
        let node = i as u32 + 2;
        if let Some(inside) = label {
            groups.join(node, u32::from(*inside));
        }
        for g in corners(pieces[i].0) {
            let at = *first.entry(g).or_insert(node);
            groups.join(node, at);
        }
    }
    if groups.find(1) == 0 {
        return Err(CsgError::Internal(
            "an untouched face got both labels".into(),
        ));
    }
    // groups no label reached: the winding number at a grid corner
    let mut asked: Vec<(u32, GridPoint)> = Vec::new();
    let mut seen: rustc_hash::FxHashSet<u32> = Default::default();
    for (i, x) in own.iter().enumerate() {
        if x.is_some() {
            let r = groups.find(i as u32 + 2);
            if r >= 2 && seen.insert(r) {
                asked.push((r, corners(pieces[i].0)[0]));
            }
        }
    }
    groups.answer(&asked, inside);
    let labels: Vec<Option<bool>> = (0..pieces.len())
        .map(|i| groups.label(i as u32 + 2))
        .collect();
    by_id(&|i| match own[i] {
        None => Ok(None),
        Some(_) => labels[i]
            .map(Some)
            .ok_or_else(|| CsgError::Internal("an untouched face got no label".into())),
    })
}

/// Groups of nodes `0..n` by union and find; a group's root is its
/// smallest node, so where nodes 0 and 1 stand for the labels outside and
/// inside, they stay roots and name their groups' label.
pub(crate) struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    pub(crate) fn new(n: usize) -> UnionFind {
        UnionFind {
            parent: (0..n as u32).collect(),
        }
    }

    pub(crate) fn find(&mut self, mut x: u32) -> u32 {
        let p = &mut self.parent;
        while p[x as usize] != x {
            p[x as usize] = p[p[x as usize] as usize];
            x = p[x as usize];
        }
        x
    }

    pub(crate) fn join(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.parent[ra.max(rb) as usize] = ra.min(rb);
        }
    }

    /// Joins each group `(root, g)` of `asked` to the label `inside(g)`
    /// (asked in parallel).
    pub(crate) fn answer(
        &mut self,
        asked: &[(u32, GridPoint)],
        inside: &(dyn Fn(GridPoint) -> bool + Sync),
    ) {
        let answers: Vec<(u32, bool)> = asked.par_iter().map(|&(r, g)| (r, inside(g))).collect();
        for (r, x) in answers {
            self.join(r, u32::from(x));
        }
    }

    /// The label of node `x`'s group: `Some(inside)`, or `None` if no
    /// label reached it.
    pub(crate) fn label(&mut self, x: u32) -> Option<bool> {
        match self.find(x) {
            0 => Some(false),
            1 => Some(true),
            _ => None,
        }
    }
}

/// Connected regions of octree cells free of one surface, each wholly
/// inside or outside that surface's solid.
pub(crate) struct Regions {
    root: Vec<u32>,
    inside: FxHashMap<u32, bool>,
}

impl Regions {
    pub(crate) fn new(
        leaves: &[Leaf],
        adjacent: &[(u32, u32)],
        free: impl Fn(&Leaf) -> bool,
        solid: &Solid,
    ) -> Regions {
        let n = leaves.len();
        let mut groups = UnionFind::new(n);
        for &(a, b) in adjacent {
            if free(&leaves[a as usize]) && free(&leaves[b as usize]) {
                groups.join(a, b);
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
        Regions { root, inside }
    }

    pub(crate) fn inside(&self, leaf: u32) -> bool {
        self.inside[&self.root[leaf as usize]]
    }
}
