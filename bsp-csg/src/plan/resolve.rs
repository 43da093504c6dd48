//! Resolving a surface that crosses, overlaps or nests in itself, cell by
//! cell: the solid where its winding number is positive, with a
//! partition only where faces meet.
//!
//! 1. **Where faces meet.** The pairs of faces that meet other than in
//!    shared vertices and edges ([`bsp_core::meeting_pairs`], exact and
//!    conservative) mark the cells of a uniform grid that hold the common
//!    box of each pair: the *dirty* cells. Cells are integer boxes whose
//!    walls lie half-way between grid planes, so no face with grid
//!    corners lies in a wall.
//! 2. **Dirty cells.** In each, the faces near it, clipped to it, are
//!    partitioned, and the winding number is carried from the cell's low
//!    corner (displaced as [`Solid::winding`] displaces it, and found by
//!    a ray through the whole surface) across every piece; what stays is
//!    the boundary of the leaves with a positive number.
//! 3. **Clean parts.** What lies outside every dirty cell meets nothing:
//!    each piece of a face there keeps one winding number in front and one
//!    behind, the same as the piece of the next face across an edge shared
//!    once each way, at an end outside the dirty cells. (Two pieces of one
//!    face may differ: the face may cross the surface in a dirty cell.)
//!    Each part so connected gets its numbers from one small partition
//!    around one of its pieces, and is kept where they are 0 in front and
//!    1 behind, dropped otherwise.
//!
//! Every decision is exact, and the cost grows with the faces near the
//! places where the surface meets itself, not with the whole surface.

use bsp_core::internals::UnionFind;
use bsp_core::par;
use bsp_core::{GridPoint, Partition, Polygon, Split, meeting_pairs};
use rustc_hash::{FxHashMap, FxHashSet};

use super::local::{cell_windings, positive_boundary, side_windings};
use super::octree::walls;
use crate::index::{IBox, overlaps, polygon_box};
use crate::{CsgError, Solid};

/// A cell of the uniform grid: its integer position.
type CellKey = [i64; 3];

/// The uniform grid of cells: cell `k` along an axis holds the grid
/// coordinates `origin + k·size ..= origin + (k + 1)·size − 1`.
struct Cells {
    origin: [i64; 3],
    size: i64,
    dirty: FxHashSet<CellKey>,
}

impl Cells {
    fn key(&self, p: [i64; 3]) -> CellKey {
        [0, 1, 2].map(|k| (p[k] - self.origin[k]).div_euclid(self.size))
    }

    fn cell_box(&self, c: CellKey) -> IBox {
        let lo = [0, 1, 2].map(|k| self.origin[k] + c[k] * self.size);
        (lo, lo.map(|x| x + self.size - 1))
    }

    /// The cells whose real extent meets the integer box `b`.
    fn keys_of(&self, b: &IBox) -> impl Iterator<Item = CellKey> {
        let (lo, hi) = (self.key(b.0), self.key(b.1));
        (lo[2]..=hi[2]).flat_map(move |z| {
            (lo[1]..=hi[1]).flat_map(move |y| (lo[0]..=hi[0]).map(move |x| [x, y, z]))
        })
    }

    /// The dirty cells meeting the box `b`.
    fn dirty_near(&self, b: &IBox) -> Vec<CellKey> {
        let (lo, hi) = (self.key(b.0), self.key(b.1));
        let span: i64 = (0..3).map(|k| hi[k] - lo[k] + 1).product();
        let mut out: Vec<CellKey> = if span as usize <= self.dirty.len() {
            self.keys_of(b).filter(|c| self.dirty.contains(c)).collect()
        } else {
            self.dirty
                .iter()
                .filter(|c| (0..3).all(|k| lo[k] <= c[k] && c[k] <= hi[k]))
                .copied()
                .collect()
        };
        out.sort_unstable();
        out
    }
}

/// The faces of `solid` near `bx`, clipped to the cell (its closed real
/// extent).
fn clipped_to(solid: &Solid, bx: &IBox) -> Vec<Polygon> {
    let w = walls(bx);
    solid
        .faces_near(bx)
        .into_iter()
        .filter_map(|i| {
            let mut p = solid.face(i).polygon().into_owned();
            w.iter()
                .all(|wall| p.clip(wall, bsp_core::Side::Back))
                .then_some(p)
        })
        .collect()
}

/// The partition of the faces of `solid` near the box `bx`, clipped to
/// it, and the winding number of each leaf, carried from the box's low
/// corner (displaced; its number by a ray through the whole surface).
fn windings_in(solid: &Solid, bx: &IBox) -> Result<(Partition<u32>, Vec<i32>), CsgError> {
    let corner = bx.0.map(|x| x as i32);
    cell_windings(bx, clipped_to(solid, bx), corner, solid.winding(corner))
}

/// The parts of `p` outside the cells `cells` (convex pieces).
fn outside(p: Polygon, cells: &Cells, near: &[CellKey]) -> Vec<Polygon> {
    let mut pieces = vec![p];
    for &c in near {
        let bx = cells.cell_box(c);
        let mut next = Vec::with_capacity(pieces.len());
        for piece in pieces {
            if !overlaps(&polygon_box(&piece), &bx) {
                next.push(piece);
                continue;
            }
            // peel the parts in front of each wall off; what is left
            // after the six is inside the cell
            let mut rest = Some(piece);
            for wall in walls(&bx) {
                let Some(r) = rest.take() else { break };
                match r.split(&wall) {
                    Split::Front(f) => next.push(f),
                    Split::Back(b) => rest = Some(b),
                    Split::Spanning { front, back } => {
                        next.push(front);
                        rest = Some(back);
                    }
                    // a face with grid corners never lies in a wall
                    Split::Coplanar { polygon, .. } => next.push(polygon),
                }
            }
        }
        pieces = next;
    }
    pieces
}

/// What [`resolve_locally`] finds.
pub(crate) enum Resolved {
    /// A face has a corner off the grid (a solid made by an operation):
    /// only the partition of every face resolves it.
    OffGrid,
    /// No two faces meet, and every face bounds the positive region
    /// already: the solid as it is.
    Unchanged,
    /// The boundary of the positive region.
    Faces(Vec<Polygon>),
}

/// The boundary of the points where the winding number of `solid`'s
/// surface is positive (see the module docs).
pub(crate) fn resolve_locally(solid: &Solid) -> Result<Resolved, CsgError> {
    let ids: Vec<u32> = solid.face_ids().collect();
    let owned: Vec<Polygon> = ids
        .iter()
        .map(|&i| solid.face(i).polygon().into_owned())
        .collect();
    let Ok(pairs) = meeting_pairs(&owned) else {
        return Ok(Resolved::OffGrid);
    };
    let boxes: Vec<IBox> = owned.iter().map(polygon_box).collect();
    let Some(bounds) = boxes
        .iter()
        .copied()
        .reduce(|a, b| crate::index::union(&a, &b))
    else {
        return Ok(Resolved::Unchanged);
    };
    // cells of the median face extent: a few faces each (larger cells
    // cut fewer faces at their walls, but partition more faces together)
    let mut ext: Vec<i64> = boxes
        .iter()
        .map(|b| (0..3).map(|k| b.1[k] - b.0[k]).max().unwrap_or(0))
        .collect();
    let mid = ext.len() / 2;
    let size = (*ext.select_nth_unstable(mid).1).max(2);
    let mut cells = Cells {
        origin: bounds.0,
        size,
        dirty: FxHashSet::default(),
    };
    for &[i, j] in &pairs {
        if let Some(common) = crate::index::intersect(&boxes[i], &boxes[j]) {
            let keys: Vec<CellKey> = cells.keys_of(&common).collect();
            cells.dirty.extend(keys);
        }
    }
    let mut dirty: Vec<CellKey> = cells.dirty.iter().copied().collect();
    dirty.sort_unstable();
    // 2. the dirty cells, each on its own
    let inside: Vec<Vec<Polygon>> = par::try_map(dirty.len(), |i| {
        let (part, w) = windings_in(solid, &cells.cell_box(dirty[i]))?;
        Ok::<_, CsgError>(positive_boundary(&part, &w))
    })?;
    // 3. the clean parts: each face's pieces outside the dirty cells
    let loops: Vec<Vec<GridPoint>> = owned
        .iter()
        .map(|p| p.vertices().iter().filter_map(|v| v.as_grid()).collect())
        .collect();
    let rest: Vec<Vec<Polygon>> =
        par::map_vec(owned.into_iter().zip(&boxes).collect(), |(p, b)| {
            let near = cells.dirty_near(b);
            if near.is_empty() {
                vec![p]
            } else {
                outside(p, &cells, &near)
            }
        });
    // the pieces numbered in face order
    let mut first_piece = Vec::with_capacity(rest.len() + 1);
    first_piece.push(0u32);
    for r in &rest {
        first_piece.push(first_piece.last().copied().unwrap_or(0) + r.len() as u32);
    }
    let parts = clean_parts(&loops, &rest, &first_piece, &cells);
    // one probe per part: its first piece
    let mut first: FxHashMap<u32, (usize, usize)> = FxHashMap::default();
    for (f, r) in rest.iter().enumerate() {
        for k in 0..r.len() {
            let n = first_piece[f] as usize + k;
            first.entry(parts[n]).or_insert((f, k));
        }
    }
    let mut probes: Vec<(u32, (usize, usize))> = first.into_iter().collect();
    probes.sort_unstable();
    let keep: FxHashMap<u32, bool> = par::try_map(probes.len(), |i| {
        let (part, (f, k)) = probes[i];
        Ok::<_, CsgError>((part, probe(solid, &rest[f][k])?))
    })?
    .into_iter()
    .collect();
    if pairs.is_empty() && keep.values().all(|&k| k) {
        return Ok(Resolved::Unchanged);
    }
    let mut out: Vec<Polygon> = inside.into_iter().flatten().collect();
    for (f, pieces) in rest.into_iter().enumerate() {
        for (k, piece) in pieces.into_iter().enumerate() {
            let n = first_piece[f] as usize + k;
            if keep.get(&parts[n]).copied().unwrap_or(false) {
                out.push(piece);
            }
        }
    }
    Ok(Resolved::Faces(out))
}

/// The edge-connected parts of the faces' pieces outside the dirty cells
/// (`rest[f]`, numbered from `first_piece[f]`). Two pieces of different
/// faces are joined across an edge of the faces (`loops`) that the one
/// uses one way and the other the other way, that nothing else uses,
/// and that has an end outside every dirty cell: the pieces holding that
/// end. There nothing else meets the faces, so the winding numbers in
/// front of the two pieces are one. (Two pieces of one face are not
/// joined as such: a face may cross the surface inside a dirty cell, and
/// its pieces lie on both sides.) Returns each piece's part.
fn clean_parts(
    loops: &[Vec<GridPoint>],
    rest: &[Vec<Polygon>],
    first_piece: &[u32],
    cells: &Cells,
) -> Vec<u32> {
    let clean = |g: &GridPoint| !cells.dirty.contains(&cells.key(g.map(i64::from)));
    // the piece of face `f` with the corner `g` (a corner of the face
    // outside the dirty cells is a corner of exactly one piece)
    let holding = |f: usize, g: GridPoint| -> Option<u32> {
        rest[f]
            .iter()
            .position(|p| p.vertices().iter().any(|v| v.as_grid() == Some(g)))
            .map(|k| first_piece[f] + k as u32)
    };
    // each directed edge with a clean end: how many faces use it, and the
    // piece holding its clean end (the smaller end if both are clean)
    let mut edges: FxHashMap<(GridPoint, GridPoint), (u32, u32)> = FxHashMap::default();
    edges.reserve(3 * loops.len());
    for (f, v) in loops.iter().enumerate() {
        if rest[f].is_empty() {
            continue;
        }
        for k in 0..v.len() {
            let (a, b) = (v[k], v[(k + 1) % v.len()]);
            let end = match (clean(&a.min(b)), clean(&a.max(b))) {
                (true, _) => a.min(b),
                (false, true) => a.max(b),
                (false, false) => continue,
            };
            let Some(piece) = holding(f, end) else {
                continue;
            };
            let e = edges.entry((a, b)).or_insert((0, 0));
            e.0 += 1;
            e.1 = piece;
        }
    }
    let n = first_piece.last().copied().unwrap_or(0) as usize;
    let mut uf = UnionFind::new(n);
    for (&(a, b), &(count, p)) in &edges {
        if count != 1 {
            continue;
        }
        if let Some(&(1, q)) = edges.get(&(b, a)) {
            uf.union(p, q);
        }
    }
    (0..n as u32).map(|p| uf.find(p)).collect()
}

/// Whether the clean piece `piece` (and so its whole part) is kept: the
/// winding numbers in front of it and behind it, from a partition of the
/// faces near it, are 0 and 1.
fn probe(solid: &Solid, piece: &Polygon) -> Result<bool, CsgError> {
    let b = polygon_box(piece);
    let (part, w) = windings_in(solid, &(b.0.map(|x| x - 1), b.1.map(|x| x + 1)))?;
    match side_windings(&part, &w, piece) {
        Some((front, back)) if back == front + 1 => Ok(front == 0),
        _ => Err(CsgError::NotASolid),
    }
}
