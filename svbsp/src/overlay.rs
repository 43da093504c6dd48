//! The exact overlay of partitions of one face (the core paper's "+"):
//! cells with counts, each cell of one partition met with each cell of
//! the other and their counts added, every cut an exact plane and every
//! corner an exact point (no rounding decides anything, and no sliver is
//! dropped for being small). A sun study overlays its runs' lit pieces
//! of a face this way, so that each cell's points all see the same number
//! of suns.

use bsp_core::{Plane, Side};
use rayon::prelude::*;
use rustc_hash::FxHashMap;
use smallvec::SmallVec;

use crate::arena::pieces::{EdgeRef, Piece, PieceArena, VertexRef};
use crate::arena::regions::merge_cells;
use crate::boxes::{Box3, CellGrid, meet, overlap, union};

/// How many cells [`FaceOverlay::plus`] tries in turn rather than through a
/// grid of their boxes.
const FEW: usize = 8;

/// Convex cells of one face with a count each, their corners exact.
#[derive(Clone, Debug)]
pub struct FaceOverlay {
    arena: PieceArena,
    /// The support plane's index in the arena.
    support: u32,
    plane: Plane,
    cells: Vec<(Piece, u32)>,
    /// Per cell, a box of grid points holding it.
    boxes: Vec<Box3>,
    /// How many cells there were after the last [`FaceOverlay::join`].
    joined_at: usize,
}

/// A region of an [`FaceOverlay`]: cells of one count merged, as rings of
/// correctly rounded grid coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct OverlayRegion {
    /// The cells' count.
    pub count: u32,
    /// The outer boundary, counter-clockwise seen from the front of the
    /// support plane; no two consecutive edges collinear.
    pub outer: Vec<[f64; 3]>,
    /// The holes, each clockwise.
    pub holes: Vec<Vec<[f64; 3]>>,
}

/// Equal where the support planes, and each cell's edge planes and
/// count in turn, are (the same cells, however their corners were made).
impl PartialEq for FaceOverlay {
    fn eq(&self, o: &FaceOverlay) -> bool {
        self.plane == o.plane
            && self.len() == o.len()
            && (0..self.len()).all(|i| self.count(i) == o.count(i) && self.planes(i) == o.planes(i))
    }
}

impl FaceOverlay {
    /// The cells on plane `support` given by their edge planes in turn
    /// (plane `i` bounds the edge from corner `i` to `i + 1`, the cell
    /// behind it, as [`crate::FragmentRef::piece_planes`] gives them) and
    /// their counts. `None` where a cell is not a strictly convex polygon
    /// of at least three corners on `support` (checked exactly).
    pub fn new<P: AsRef<[Plane]>>(
        support: Plane,
        cells: impl IntoIterator<Item = (P, u32)>,
    ) -> Option<FaceOverlay> {
        let mut arena = PieceArena::default();
        let s = arena.add_plane(support);
        let mut out = Vec::new();
        let mut sides = SmallVec::new();
        // one arena plane for a plane and its opposite, one vertex where
        // two of them meet: cells that share an edge share its corners
        // (and can be joined)
        let mut plane_at: FxHashMap<Plane, u32> = FxHashMap::default();
        let mut meet_at: FxHashMap<(u32, u32), u32> = FxHashMap::default();
        for (planes, count) in cells {
            let planes = planes.as_ref();
            let k = planes.len();
            if k < 3 {
                return None;
            }
            let idx: SmallVec<[EdgeRef; 6]> = (planes.iter())
                .map(|&p| {
                    let flipped = p.normal().into_iter().find(|&c| c != 0) < Some(0);
                    let key = if flipped { p.flip() } else { p };
                    let i = *plane_at.entry(key).or_insert_with(|| arena.add_plane(key));
                    EdgeRef::new(i, flipped)
                })
                .collect();
            let mut piece = Piece::default();
            for i in 0..k {
                let (a, b) = (idx[(i + k - 1) % k].index(), idx[i].index());
                let v = match meet_at.get(&(a.min(b), a.max(b))) {
                    Some(&v) => v,
                    None => {
                        let v = arena.add_meet([s, a, b])?;
                        meet_at.insert((a.min(b), a.max(b)), v);
                        v
                    }
                };
                piece.verts.push(v);
                piece.edges.push(idx[i]);
            }
            // strictly convex: every corner strictly behind the planes of
            // the edges it is not on
            for (i, plane) in planes.iter().enumerate() {
                arena.classify_into(&piece, plane, &mut sides);
                let apart = (0..k).all(|v| match v == i || v == (i + 1) % k {
                    true => sides[v] == Side::On,
                    false => sides[v] == Side::Back,
                });
                if !apart {
                    return None;
                }
            }
            out.push((piece, count));
        }
        let mut o = FaceOverlay {
            arena,
            support: s,
            plane: support,
            cells: out,
            boxes: Vec::new(),
            joined_at: 0,
        };
        o.boxes = (o.cells.iter()).map(|c| o.bounds_of(&c.0)).collect();
        Some(o)
    }

    /// The support plane.
    pub fn support(&self) -> &Plane {
        &self.plane
    }

    /// The number of cells.
    pub fn len(&self) -> usize {
        self.cells.len()
    }

    /// `true` if there is no cell.
    pub fn is_empty(&self) -> bool {
        self.cells.is_empty()
    }

    /// Cell `i`'s count.
    pub fn count(&self, i: usize) -> u32 {
        self.cells[i].1
    }

    /// Adds `n` to every cell's count.
    pub fn add_count(&mut self, n: u32) {
        self.cells.iter_mut().for_each(|c| c.1 += n);
    }

    /// Cell `i`'s edge planes in turn (what [`FaceOverlay::new`] takes).
    pub fn planes(&self, i: usize) -> SmallVec<[Plane; 6]> {
        let c = &self.cells[i].0;
        c.edges.iter().map(|&e| self.arena.plane(e)).collect()
    }

    /// Cell `i`'s corners, counter-clockwise seen from the front of the
    /// support plane, as correctly rounded grid coordinates (equal points
    /// give equal coordinates, however they were made).
    pub fn corners(&self, i: usize) -> Vec<[f64; 3]> {
        let c = &self.cells[i].0;
        c.verts
            .iter()
            .map(|&v| self.arena.vertex(v).to_f64())
            .collect()
    }

    /// Every cell's corners as [`FaceOverlay::corners`] gives them, each
    /// corner rounded once (in parallel for many) however many cells
    /// share it.
    pub fn all_corners(&self) -> Vec<Vec<[f64; 3]>> {
        self.corners_by(|v| v.to_f64())
    }

    /// Every cell's corners for measuring (its area, say): grid
    /// coordinates within `2^-20` grid units of the exact ones, found
    /// without exact arithmetic where the `f64` approximations of a cut
    /// corner are that close (the same bits however the overlay was
    /// made), each corner once however many cells share it.
    pub fn measured_corners(&self) -> Vec<Vec<[f64; 3]>> {
        self.corners_by(|v| v.measure())
    }

    /// Every cell's corners, each found once by `at`.
    fn corners_by(&self, at: impl Fn(VertexRef<'_>) -> [f64; 3] + Sync) -> Vec<Vec<[f64; 3]>> {
        let mut used: Vec<u32> = self
            .cells
            .iter()
            .flat_map(|c| c.0.verts.iter().copied())
            .collect();
        used.sort_unstable();
        used.dedup();
        let round = |&v: &u32| at(self.arena.vertex(v));
        let rounded: Vec<[f64; 3]> = match used.len() > 4096 {
            true => used.par_iter().map(round).collect(),
            false => used.iter().map(round).collect(),
        };
        let at = |v: u32| rounded[used.binary_search(&v).expect("a used corner")];
        (self.cells.iter())
            .map(|c| c.0.verts.iter().map(|&v| at(v)).collect())
            .collect()
    }

    /// Every cell of `self` met with every cell of `other` (on the same
    /// support plane; the cells of each must not overlap, as a face's
    /// partitions' do not), their counts added: the parts of a cell of
    /// `self` inside each cell of `other`, cut off by that cell's edge
    /// planes (exact sides, exact new corners). Where `other`'s cells
    /// leave part of a cell uncovered, that part keeps its count alone.
    /// A cell whose parts all come to one count is kept whole. In the
    /// order of `self`'s cells, then of the parts as they are cut. `None`
    /// where the two lie on different support planes.
    pub fn plus(self, other: &FaceOverlay) -> Option<FaceOverlay> {
        (self.plane == other.plane).then(|| self.meet(other, false))
    }

    /// [`FaceOverlay::plus`] where `other`'s cells cover every cell of
    /// `self` (two partitions of one face, as the runs of a sun study
    /// are), in fewer cells, found faster. The parts of a cell of `self`
    /// that share a whole edge, have one count and make a convex union are
    /// joined (the cuts between `other`'s cells of one count are undone
    /// where that leaves convex cells; the points keep their counts), and
    /// each time the cells have grown by a quarter, so are any two cells of one
    /// count that share a whole edge (cut apart once, of one count again
    /// after later overlays). A
    /// cell of `self` whose box meets the boxes of `other`'s cells of one
    /// count only lies in those (they cover it) and takes that count whole
    /// without a test of its corners; so does, found without listing the
    /// cells near it, a cell whose box meets no box of `other`'s cells of
    /// other counts than the one whose cells' boxes cover the most (the
    /// count of most of the face, as a rule); and so does a cell whose
    /// overlapping cells of `other` (found exactly) are all of one count.
    /// Where `other` does not
    /// cover `self`, such a cell takes that count where
    /// [`FaceOverlay::plus`] would keep a part of it uncounted.
    pub fn plus_covering(self, other: &FaceOverlay) -> Option<FaceOverlay> {
        (self.plane == other.plane).then(|| {
            let mut o = self.meet(other, true);
            // (cells that came to one count in later overlays joined,
            // each time the cells have grown by a quarter)
            if 4 * o.len() >= 5 * o.joined_at.max(JOIN_FROM) {
                o.join();
            }
            o
        })
    }

    /// Joins cells of one count that share a whole edge (its two corners
    /// the same vertices: [`FaceOverlay::new`] makes one vertex where two
    /// planes meet) and make a convex union, pass after pass while a pass
    /// joins more than a few. The points keep their counts; the cells
    /// still tile what they tiled.
    pub fn join(&mut self) {
        let mut near = None;
        loop {
            let n = self.len();
            near = self.join_cells_near(near.as_deref());
            if near.is_none() || JOIN_AGAIN * self.len() >= (JOIN_AGAIN - 1) * n {
                break;
            }
        }
        self.joined_at = self.len();
        // the arena keeps the corners and planes of cells cut since; once
        // it holds more vertices than the cells have corners, only what
        // the cells use is kept
        let corners: usize = self.cells.iter().map(|c| c.0.verts.len()).sum();
        if self.arena.len() > corners {
            let pieces = self.cells.iter_mut().map(|c| &mut c.0);
            self.support = self.arena.compact(self.support, pieces);
        }
    }

    /// Joins cells of one count that share a whole edge (its two corners
    /// the same vertices) and make a convex union ([`joined`]), in one
    /// pass over the shared edges in the order of their corners (those
    /// whose two corners `near` marks, by [`PieceArena::dense`]; all if
    /// `None`); a cell joins several in turn. The points keep their
    /// counts. Returns the marks of the corners of the cells that joined
    /// others (`None` if none did): a pass after this one, over the edges
    /// between those, joins what a pass over all edges would, as every
    /// other pair it tried and left stays as it was.
    fn join_cells_near(&mut self, near: Option<&[bool]>) -> Option<Vec<bool>> {
        // each edge listed at its lower corner (a counting sort by the
        // corners' dense numbers), then in each corner's list by its other
        // corner
        let n = self.arena.len();
        let mut start = vec![0u32; n + 1];
        let ends = |c: &Piece, e: usize| {
            let k = c.verts.len();
            let (u, v) = (c.verts[e], c.verts[(e + 1) % k]);
            let (u, v) = (self.arena.dense(u), self.arena.dense(v));
            let (lo, hi) = (u.min(v), u.max(v));
            near.is_none_or(|m| m[lo] && m[hi])
                .then_some((lo, hi as u32))
        };
        for (c, _) in &self.cells {
            for e in 0..c.verts.len() {
                if let Some((lo, _)) = ends(c, e) {
                    start[lo + 1] += 1;
                }
            }
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let mut at = start.clone();
        let mut edges = vec![(0u32, 0u32); start[n] as usize];
        for (i, (c, _)) in self.cells.iter().enumerate() {
            for e in 0..c.verts.len() {
                if let Some((lo, hi)) = ends(c, e) {
                    edges[at[lo] as usize] = (hi, i as u32);
                    at[lo] += 1;
                }
            }
        }
        let mut gone = vec![false; self.cells.len()];
        let mut grew = Vec::new();
        for b in start.windows(2) {
            let list = &mut edges[b[0] as usize..b[1] as usize];
            if list.len() > 2 {
                list.sort_unstable();
            }
            for w in list.windows(2) {
                let (i, j) = (w[0].1 as usize, w[1].1 as usize);
                if w[0].0 != w[1].0 || i == j || gone[i] || gone[j] {
                    continue;
                }
                if self.cells[i].1 != self.cells[j].1 {
                    continue;
                }
                if let Some(p) = joined(&mut self.arena, &self.cells[i].0, &self.cells[j].0) {
                    self.cells[i].0 = p;
                    self.boxes[i] = union(self.boxes[i], self.boxes[j]);
                    gone[j] = true;
                    grew.push(i);
                }
            }
        }
        let marks = (!grew.is_empty()).then(|| {
            let mut marks = vec![false; n];
            for &i in &grew {
                for &v in &self.cells[i].0.verts {
                    marks[self.arena.dense(v)] = true;
                }
            }
            marks
        });
        let mut k = 0;
        self.cells.retain(|_| {
            k += 1;
            !gone[k - 1]
        });
        let mut k = 0;
        self.boxes.retain(|_| {
            k += 1;
            !gone[k - 1]
        });
        marks
    }

    /// The count whose cells' boxes cover the most (their faces' areas
    /// summed, in `f64`: a choice, not a decision about a point), and an
    /// index of the boxes of the cells of other counts.
    fn common_count(&self) -> Option<(u32, Vec<u32>, Option<CellGrid>)> {
        let mut by: Vec<(u32, f64)> = Vec::new();
        for (c, b) in self.cells.iter().zip(&self.boxes) {
            let e = b.map(|[lo, hi]| (hi - lo) as f64);
            let area = e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
            match by.iter_mut().find(|(n, _)| *n == c.1) {
                Some(at) => at.1 += area,
                None => by.push((c.1, area)),
            }
        }
        let common = by.iter().max_by(|a, b| a.1.total_cmp(&b.1))?.0;
        let others: Vec<u32> = (0..self.len() as u32)
            .filter(|&j| self.cells[j as usize].1 != common)
            .collect();
        let boxes: Vec<Box3> = others.iter().map(|&j| self.boxes[j as usize]).collect();
        let scene = boxes.iter().copied().reduce(union);
        let grid = scene
            .filter(|_| boxes.len() > FEW)
            .map(|scene| CellGrid::new(scene, &boxes));
        Some((common, others, grid))
    }

    /// [`FaceOverlay::plus`] of two overlays on one plane; with
    /// `covering`, [`FaceOverlay::plus_covering`].
    fn meet(mut self, other: &FaceOverlay, covering: bool) -> FaceOverlay {
        // one cell holding all of `other` (a face still whole): `other`'s
        // cells, counted with it
        if let [(cell, count)] = &self.cells[..]
            && other.inside(cell, &self.arena)
        {
            let mut o = other.clone();
            o.cells.iter_mut().for_each(|c| c.1 += count);
            return o;
        }
        let boxes = &other.boxes;
        let Some(scene) = boxes.iter().copied().reduce(union) else {
            return self;
        };
        let mut look = Near::new(other, scene, covering);
        // each of `other`'s planes copied in once (as oriented), when
        // first needed
        let mut copied: Vec<Option<u32>> = vec![None; 2 * other.arena.planes.len()];
        // (and those copied while a cell is cut, forgotten if its cuts are
        // undone)
        let mut fresh = Vec::new();
        let mut hits = Vec::new();
        let (mut rest, mut next) = (Vec::new(), Vec::new());
        let mut sides = SmallVec::new();
        let mut out = Vec::with_capacity(self.cells.len());
        let mut out_boxes = Vec::with_capacity(self.cells.len());
        let cells = std::mem::take(&mut self.cells);
        let own = std::mem::take(&mut self.boxes);
        for (i, ((cell, count), bounds)) in cells.into_iter().zip(own).enumerate() {
            if let Some(n) = look.find(i, bounds) {
                out.push((cell, count + n));
                out_boxes.push(bounds);
                continue;
            }
            // inside one cell of `other` (whose cells do not overlap): whole,
            // with its count added; else the cells of `other` it overlaps
            // (apart where a plane of either has the other in front or on
            // it); each cell's planes against its corners once for both
            hits.clear();
            let mut holder = None;
            for &j in &look.list {
                let theirs = &other.cells[j as usize].0;
                match other.relate(theirs, &cell, &mut self.arena) {
                    Relation::Holds => {
                        holder = Some(j);
                        break;
                    }
                    Relation::Apart => {}
                    Relation::Unknown => {
                        if !self.apart_by_own(&cell, other, theirs) {
                            hits.push(j);
                        }
                    }
                }
            }
            if let Some(j) = holder {
                out.push((cell, count + other.cells[j as usize].1));
                out_boxes.push(meet(bounds, boxes[j as usize]).unwrap_or(bounds));
                continue;
            }
            // covered by the cells it overlaps (`other` covers it), all of
            // one count: that count, whole
            if covering && let Some(n) = other.one_count(&hits) {
                out.push((cell, count + n));
                out_boxes.push(bounds);
                continue;
            }
            let (first, mark) = (out.len(), self.arena.mark());
            fresh.clear();
            rest.clear();
            rest.push(cell.clone());
            for &j in &hits {
                let (theirs, more) = &other.cells[j as usize];
                next.clear();
                for piece in rest.drain(..) {
                    if self.apart(&piece, other, theirs) {
                        next.push(piece);
                        continue;
                    }
                    // they overlap: each cut leaves a part inside
                    let mut p = piece;
                    for &e in &theirs.edges {
                        let plane = other.arena.plane(e);
                        let s = self.arena.classify_into(&p, &plane, &mut sides);
                        if s.front && s.back {
                            let key = 2 * e.index() as usize + usize::from(e.flipped());
                            let at = *copied[key].get_or_insert_with(|| {
                                fresh.push(key);
                                self.arena.add_plane(plane)
                            });
                            let (outside, kept) = self.arena.split(self.support, &p, at, &sides);
                            next.push(outside);
                            p = kept;
                        }
                    }
                    // in both cells: in both boxes
                    out.push((p, count + more));
                    out_boxes.push(meet(bounds, boxes[j as usize]).unwrap_or(bounds));
                }
                std::mem::swap(&mut rest, &mut next);
                if rest.is_empty() {
                    break;
                }
            }
            out_boxes.extend(rest.iter().map(|_| bounds));
            out.extend(rest.drain(..).map(|p| (p, count)));
            // parts that all came to one count: the cell whole, its cuts
            // undone (the cuts made only other's cells, not other counts)
            let mine = &out[first..];
            if mine.len() > 1 && mine.iter().all(|c| c.1 == mine[0].1) {
                let n = mine[0].1;
                out.truncate(first);
                out_boxes.truncate(first);
                self.arena.rollback(mark);
                fresh.iter().for_each(|&k| copied[k] = None);
                out.push((cell, n));
                out_boxes.push(bounds);
            } else if covering {
                rejoin(&mut self.arena, &mut out, &mut out_boxes, first);
            }
        }
        self.cells = out;
        self.boxes = out_boxes;
        self
    }

    /// Whether `piece` (of this arena) and `theirs` (of `other`'s) are
    /// apart: a plane of either has all of the other in front of it or on
    /// it (two convex polygons that meet with area have no such plane).
    fn apart(&mut self, piece: &Piece, other: &FaceOverlay, theirs: &Piece) -> bool {
        matches!(
            other.relate(theirs, piece, &mut self.arena),
            Relation::Apart
        ) || self.apart_by_own(piece, other, theirs)
    }

    /// Whether cell `theirs` of this overlay holds `piece` of `arena`
    /// (every corner behind or on each of its edge planes), or is apart
    /// from it by one of its edge planes (every corner in front or on it).
    fn relate(&self, theirs: &Piece, piece: &Piece, arena: &mut PieceArena) -> Relation {
        let mut holds = true;
        for &e in &theirs.edges {
            let s = arena.sides(piece, &self.arena.plane(e));
            if !s.back {
                return Relation::Apart;
            }
            holds &= !s.front;
        }
        match holds {
            true => Relation::Holds,
            false => Relation::Unknown,
        }
    }

    /// The count of the listed cells if they all have one (`None` for no
    /// cell).
    fn one_count(&self, cells: &[u32]) -> Option<u32> {
        let (&j, more) = cells.split_first()?;
        let c = self.cells[j as usize].1;
        more.iter()
            .all(|&k| self.cells[k as usize].1 == c)
            .then_some(c)
    }

    /// Whether a plane of `piece` (of this arena) has all of `theirs` (of
    /// `other`'s) in front of it or on it: [`FaceOverlay::apart`] by
    /// `piece`'s planes alone.
    fn apart_by_own(&self, piece: &Piece, other: &FaceOverlay, theirs: &Piece) -> bool {
        (piece.edges.iter()).any(|&e| {
            let plane = self.arena.plane(e);
            (theirs.verts.iter()).all(|&v| other.arena.vertex(v).classify(&plane) != Side::Back)
        })
    }

    /// Whether every cell lies in `cell` of `arena` (its corners behind or
    /// on each of `cell`'s edge planes: the cells are convex).
    fn inside(&self, cell: &Piece, arena: &PieceArena) -> bool {
        cell.edges.iter().all(|&e| {
            let plane = arena.plane(e);
            (self.cells.iter()).all(|(c, _)| !self.arena.sides_shared(c, &plane).front)
        })
    }

    /// The cells of equal counts merged into regions (maximal and
    /// connected, with holes), in the order of their first cell.
    pub fn regions(&self) -> Vec<OverlayRegion> {
        let pieces: Vec<Piece> = self.cells.iter().map(|c| c.0.clone()).collect();
        let labels: Vec<u64> = self.cells.iter().map(|c| u64::from(c.1)).collect();
        let mut rounded = Vec::new();
        let regions = merge_cells(&self.arena, &self.plane, &pieces, &labels, &mut rounded);
        let at = |v: &u32| self.arena.vertex(*v).to_f64();
        regions
            .into_iter()
            .map(|r| OverlayRegion {
                count: r.label as u32,
                outer: r.outer.iter().map(at).collect(),
                holes: r.holes.iter().map(|h| h.iter().map(at).collect()).collect(),
            })
            .collect()
    }

    /// A box of grid points holding `cell`: the floor and ceiling of
    /// intervals holding its corners' coordinates (but for a few units in
    /// their last place, below `2^-20` of a grid step), widened by one.
    fn bounds_of(&self, cell: &Piece) -> Box3 {
        let mut b = [[i64::MAX, i64::MIN]; 3];
        for &v in &cell.verts {
            let p = self.arena.vertex(v).near_f64();
            for k in 0..3 {
                b[k][0] = b[k][0].min(p[k][0].floor() as i64 - 1);
                b[k][1] = b[k][1].max(p[k][1].ceil() as i64 + 1);
            }
        }
        b
    }
}

/// How [`FaceOverlay::meet`] finds the cells of `other` near a cell: a
/// few tried in turn, many through a grid of their boxes; with
/// `covering`, the common count's cells apart.
struct Near<'a> {
    other: &'a FaceOverlay,
    grid: Option<CellGrid>,
    covering: bool,
    /// The common count, the cells of other counts and a grid of their
    /// boxes ([`FaceOverlay::common_count`]).
    common: Option<(u32, Vec<u32>, Option<CellGrid>)>,
    /// Per cell of `other`, the last cell it was listed for.
    seen: Vec<usize>,
    /// The cells near the last cell asked about, in their order.
    list: Vec<u32>,
}

impl<'a> Near<'a> {
    /// The lookup of `other`'s cells, which lie in box `scene`.
    fn new(other: &'a FaceOverlay, scene: Box3, covering: bool) -> Near<'a> {
        Near {
            other,
            grid: (other.len() > FEW).then(|| CellGrid::new(scene, &other.boxes)),
            covering,
            common: covering.then(|| other.common_count()).flatten(),
            seen: vec![usize::MAX; other.len()],
            list: Vec::new(),
        }
    }

    /// For cell `i` of box `bounds`: with `covering`, the count it takes
    /// whole if the boxes alone tell (the cells of `other` whose boxes
    /// meet its box cover it: of one count, it lies in that count);
    /// else `None`, and [`Near::list`] holds those cells (the others are
    /// apart from it).
    fn find(&mut self, i: usize, bounds: Box3) -> Option<u32> {
        let (other, boxes) = (self.other, &self.other.boxes);
        // away from every cell of another count than the common one
        if let Some((n, others, grid)) = &self.common {
            let mut met = false;
            match grid {
                Some(grid) => grid.visit(bounds, |j| {
                    met |= overlap(&bounds, &boxes[others[j as usize] as usize]);
                }),
                None => met = (others.iter()).any(|&j| overlap(&bounds, &boxes[j as usize])),
            }
            if !met {
                return Some(*n);
            }
        }
        self.list.clear();
        match &self.grid {
            Some(grid) => {
                let (seen, list) = (&mut self.seen, &mut self.list);
                grid.visit(bounds, |j| {
                    if std::mem::replace(&mut seen[j as usize], i) != i
                        && overlap(&bounds, &boxes[j as usize])
                    {
                        list.push(j);
                    }
                });
                self.list.sort_unstable();
            }
            None => self
                .list
                .extend((0..other.len() as u32).filter(|&j| overlap(&bounds, &boxes[j as usize]))),
        }
        self.covering.then(|| other.one_count(&self.list)).flatten()
    }
}

/// How a cell of one overlay lies to a convex piece of another, by the
/// cell's edge planes ([`FaceOverlay::relate`]).
enum Relation {
    /// It holds the piece.
    Holds,
    /// One of its planes has the piece in front or on it.
    Apart,
    /// Neither, by its planes.
    Unknown,
}

/// How many cells [`FaceOverlay::plus_covering`] leaves before it first
/// joins cells across the whole overlay.
const JOIN_FROM: usize = 256;

/// [`FaceOverlay::join`] passes again while a pass joins more than one
/// cell in this many.
const JOIN_AGAIN: usize = 32;

/// At most how many parts of one cell [`rejoin`] tries to put together
/// (it tries every pair).
const REJOIN: usize = 24;

/// The parts of one cell from `first` on put back together where two of
/// one count share a whole edge (the same two corners) and their union
/// is convex: fewer cells for the overlays to come. The cuts of the other
/// partition between its cells of one count cut the cell where no count
/// changes; this undoes those that leave convex pieces.
fn rejoin(
    arena: &mut PieceArena,
    out: &mut Vec<(Piece, u32)>,
    boxes: &mut Vec<Box3>,
    first: usize,
) {
    if out.len() - first > REJOIN {
        return;
    }
    let mut a = first;
    while a < out.len() {
        let mut b = a + 1;
        while b < out.len() {
            let joined = (out[a].1 == out[b].1)
                .then(|| joined(arena, &out[a].0, &out[b].0))
                .flatten();
            match joined {
                Some(piece) => {
                    out[a].0 = piece;
                    boxes[a] = union(boxes[a], boxes[b]);
                    out.remove(b);
                    boxes.remove(b);
                    // (the larger piece may now join one tried before)
                    b = a + 1;
                }
                None => b += 1,
            }
        }
        a += 1;
    }
}

/// The union of convex pieces `p` and `q` of one arena, if they share a
/// whole edge (its two corners the same vertices) and the union is
/// convex: at each end of the edge, the corner after it strictly behind
/// the plane of the edge before it, or on it (the corner is then
/// straight and dropped, the edge before it going on).
fn joined(arena: &mut PieceArena, p: &Piece, q: &Piece) -> Option<Piece> {
    let (n, m) = (p.verts.len(), q.verts.len());
    // p's edge i runs from u to v, q's edge j from v to u
    let (i, j) = (0..n).find_map(|i| {
        let (u, v) = (p.verts[i], p.verts[(i + 1) % n]);
        (0..m)
            .find(|&j| q.verts[j] == v && q.verts[(j + 1) % m] == u)
            .map(|j| (i, j))
    })?;
    // at u: p's edge into it, then q's corner after it
    let into_u = arena.plane(p.edges[(i + n - 1) % n]);
    let at_u = arena.classify(q.verts[(j + 2) % m], &into_u);
    // at v: q's edge into it, then p's corner after it
    let into_v = arena.plane(q.edges[(j + m - 1) % m]);
    let at_v = arena.classify(p.verts[(i + 2) % n], &into_v);
    if at_u == Side::Front || at_v == Side::Front {
        return None;
    }
    // from v around p to u, then around q back to v
    let mut out = Piece::default();
    for k in 1..=n {
        out.verts.push(p.verts[(i + k) % n]);
    }
    for k in 2..m {
        out.verts.push(q.verts[(j + k) % m]);
    }
    for k in 1..n {
        out.edges.push(p.edges[(i + k) % n]);
    }
    for k in 1..m {
        out.edges.push(q.edges[(j + k) % m]);
    }
    // a straight corner at u (vertex n - 1): the edge into it goes on
    if at_u == Side::On {
        out.verts.remove(n - 1);
        out.edges.remove(n - 1);
    }
    // a straight corner at v (vertex 0): q's edge into it goes on
    if at_v == Side::On {
        out.verts.remove(0);
        out.edges.remove(0);
    }
    (out.verts.len() >= 3).then_some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::arena::pieces::MEASURE_UNITS;
    use bsp_core::{GridPoint, Polygon, Split};
    use proptest::prelude::*;

    /// The square `[0, s]²` on the plane z = 0, facing +z.
    fn square(s: i32) -> Polygon {
        Polygon::from_grid_points(&[[0, 0, 0], [s, 0, 0], [s, s, 0], [0, s, 0]], 0).unwrap()
    }

    /// The upright plane through `a` and `b` (on z = 0).
    fn upright(a: [i32; 2], b: [i32; 2]) -> Option<Plane> {
        Plane::through([a[0], a[1], 0], [b[0], b[1], 0], [a[0], a[1], 1]).ok()
    }

    /// `face` cut by each of `cuts` in turn, each piece with a count.
    fn partition(
        face: Polygon,
        cuts: &[Plane],
        count: impl Fn(usize) -> u32,
    ) -> Vec<(Polygon, u32)> {
        let mut pieces = vec![face];
        for c in cuts {
            pieces = pieces
                .into_iter()
                .flat_map(|p| match p.split(c) {
                    Split::Spanning { front, back } => vec![front, back],
                    Split::Front(p) | Split::Back(p) => vec![p],
                    Split::Coplanar { polygon, .. } => vec![polygon],
                })
                .collect();
        }
        pieces
            .into_iter()
            .enumerate()
            .map(|(i, p)| (p, count(i)))
            .collect()
    }

    fn overlay_of(cells: &[(Polygon, u32)]) -> FaceOverlay {
        let support = *cells[0].0.support();
        FaceOverlay::new(support, cells.iter().map(|(p, c)| (p.edge_planes(), *c))).unwrap()
    }

    /// The count of the cell of `o` that holds grid point `x` strictly
    /// inside (`None` if none does: `x` lies on an edge).
    fn count_at(o: &FaceOverlay, x: GridPoint) -> Option<u32> {
        let inside: Vec<u32> = (0..o.len())
            .filter(|&i| o.planes(i).iter().all(|p| p.classify_grid(x) == Side::Back))
            .map(|i| o.count(i))
            .collect();
        assert!(inside.len() <= 1, "cells overlap at {x:?}");
        inside.first().copied()
    }

    fn count_in(cells: &[(Polygon, u32)], x: GridPoint) -> Option<u32> {
        let inside: Vec<u32> = (cells.iter())
            .filter(|(p, _)| {
                p.edge_planes()
                    .iter()
                    .all(|e| e.classify_grid(x) == Side::Back)
            })
            .map(|c| c.1)
            .collect();
        inside.first().copied()
    }

    fn area(c: &[[f64; 3]]) -> f64 {
        let n = c.len();
        (0..n)
            .map(|i| c[i][0] * c[(i + 1) % n][1] - c[(i + 1) % n][0] * c[i][1])
            .sum::<f64>()
            / 2.0
    }

    #[test]
    fn two_crossing_cuts_give_four_cells_with_summed_counts() {
        let a = partition(square(12), &[upright([4, 0], [4, 12]).unwrap()], |i| {
            i as u32 + 1
        });
        let b = partition(square(12), &[upright([0, 3], [12, 9]).unwrap()], |i| {
            10 * i as u32
        });
        let o = overlay_of(&a).plus(&overlay_of(&b)).unwrap();
        assert_eq!(o.len(), 4);
        let total: f64 = (0..o.len()).map(|i| area(&o.corners(i))).sum();
        assert_eq!(total, 144.0);
        for (x, y) in [(1, 1), (1, 11), (11, 1), (11, 11), (5, 8), (2, 5)] {
            let want = count_in(&a, [x, y, 0]).unwrap() + count_in(&b, [x, y, 0]).unwrap();
            assert_eq!(count_at(&o, [x, y, 0]), Some(want), "at {x}, {y}");
        }
    }

    #[test]
    fn a_cell_inside_another_is_kept_whole_and_regions_have_holes() {
        // a square in the middle of the face, counted 1; around it 0
        let cuts = [
            upright([4, 0], [4, 12]).unwrap(),
            upright([8, 12], [8, 0]).unwrap(),
            upright([12, 4], [0, 4]).unwrap(),
            upright([0, 8], [12, 8]).unwrap(),
        ];
        let middle = |p: &Polygon| {
            p.vertices_f64()
                .iter()
                .all(|v| (4.0..=8.0).contains(&v[0]) && (4.0..=8.0).contains(&v[1]))
        };
        let a: Vec<(Polygon, u32)> = partition(square(12), &cuts, |_| 0)
            .into_iter()
            .map(|(p, _)| {
                let c = u32::from(middle(&p));
                (p, c)
            })
            .collect();
        let whole = vec![(square(12), 2)];
        let o = overlay_of(&whole).plus(&overlay_of(&a)).unwrap();
        assert_eq!(o.len(), 9);
        let r = o.regions();
        assert_eq!(r.len(), 2);
        let ring = r.iter().find(|r| r.count == 2).unwrap();
        assert_eq!(ring.holes.len(), 1);
        assert_eq!(area(&ring.outer), 144.0);
        assert_eq!(area(&ring.holes[0]), -16.0);
        let mid = r.iter().find(|r| r.count == 3).unwrap();
        assert_eq!((area(&mid.outer), mid.holes.len()), (16.0, 0));
    }

    #[test]
    fn one_cell_takes_the_others_cells_only_where_they_lie_in_it() {
        let b = partition(square(12), &[upright([0, 3], [12, 9]).unwrap()], |i| {
            10 * i as u32 + 1
        });
        // the whole face: b's cells as they are, counted with it
        let whole = overlay_of(&[(square(12), 5)])
            .plus(&overlay_of(&b))
            .unwrap();
        assert_eq!(
            whole,
            overlay_of(
                &b.iter()
                    .map(|(p, c)| (p.clone(), c + 5))
                    .collect::<Vec<_>>()
            )
        );
        // the face's left third only: b's cells cut to it
        let left = partition(square(12), &[upright([4, 12], [4, 0]).unwrap()], |_| 2);
        let third: Vec<(Polygon, u32)> = (left.into_iter())
            .filter(|(p, _)| p.vertices_f64().iter().all(|v| v[0] <= 4.0))
            .collect();
        let o = overlay_of(&third).plus(&overlay_of(&b)).unwrap();
        let total: f64 = (0..o.len()).map(|i| area(&o.corners(i))).sum();
        assert_eq!((o.len(), total), (2, 48.0));
        assert_eq!(
            count_at(&o, [1, 1, 0]),
            Some(2 + count_in(&b, [1, 1, 0]).unwrap())
        );
        assert_eq!(
            count_at(&o, [1, 11, 0]),
            Some(2 + count_in(&b, [1, 11, 0]).unwrap())
        );
    }

    #[test]
    fn cells_come_back_through_their_planes_and_bad_ones_are_refused() {
        let a = partition(square(9), &[upright([2, 0], [7, 9]).unwrap()], |i| i as u32);
        let o = overlay_of(&a);
        let again = FaceOverlay::new(
            *o.support(),
            (0..o.len()).map(|i| (o.planes(i), o.count(i))),
        )
        .unwrap();
        for i in 0..o.len() {
            assert_eq!(again.corners(i), o.corners(i));
        }
        // a cell whose planes make no convex polygon
        let mut planes = a[0].0.edge_planes().to_vec();
        planes.swap(0, 1);
        assert!(FaceOverlay::new(*o.support(), [(planes, 0)]).is_none());
        // two planes are no cell
        assert!(FaceOverlay::new(*o.support(), [(&a[0].0.edge_planes()[..2], 0)]).is_none());
        // overlays of two planes do not meet
        let up =
            Polygon::from_grid_points(&[[0, 0, 1], [9, 0, 1], [9, 9, 1], [0, 9, 1]], 0).unwrap();
        assert!(o.clone().plus(&overlay_of(&[(up, 1)])).is_none());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]

        /// Random partitions of a face by upright cuts through grid points:
        /// at every grid point inside a cell of the overlay, its count is the
        /// sum of the two partitions' counts there; the cells tile the face.
        /// For odd seeds the second partition is mostly of one count (as a
        /// run's lit pieces are mostly lit).
        #[test]
        fn the_overlay_counts_what_both_partitions_count(
            cuts_a in prop::collection::vec(([0..=40i32, 0..=40i32], [0..=40i32, 0..=40i32]), 1..10),
            cuts_b in prop::collection::vec(([0..=40i32, 0..=40i32], [0..=40i32, 0..=40i32]), 1..10),
            seed in 0u32..1000,
        ) {
            let a = cut_square(40, &cuts_a, |i| (i as u32 * 7 + seed) % 5);
            let b = cut_square(40, &cuts_b, |i| match seed % 2 {
                0 => (i as u32 * 3 + seed) % 4,
                _ => u32::from((i as u32 * 5 + seed).is_multiple_of(7)),
            });
            let o = overlay_of(&a).plus(&overlay_of(&b)).unwrap();
            tiles_with_summed_counts(&o, &a, &b, 40)?;
            // `b` covers `a`: the covering overlay, as exact, in no more cells
            let c = overlay_of(&a).plus_covering(&overlay_of(&b)).unwrap();
            tiles_with_summed_counts(&c, &a, &b, 40)?;
            prop_assert!(c.len() <= o.len());
            // overlaid again, its cells of one count joined across the
            // whole overlay: as exact, in no more cells
            let twice: Vec<(Polygon, u32)> = b.iter().map(|(p, n)| (p.clone(), 2 * n)).collect();
            let mut d = c.clone().plus_covering(&overlay_of(&b)).unwrap();
            let before = d.len();
            // (passes over the edges near the last pass's joins join as
            // passes over all edges do)
            let (mut all, mut near) = (d.clone(), d.clone());
            while all.join_cells_near(None).is_some() {}
            let mut marks = near.join_cells_near(None);
            while marks.is_some() {
                marks = near.join_cells_near(marks.as_deref());
            }
            prop_assert!(all == near);
            d.join();
            tiles_with_summed_counts(&d, &a, &twice, 40)?;
            prop_assert!(d.len() <= before);
            // (its arena kept to what the cells use, and overlaid again
            // from there)
            let corners: usize = d.cells.iter().map(|c| c.0.verts.len()).sum();
            prop_assert!(d.arena.len() <= corners);
            let thrice: Vec<(Polygon, u32)> = b.iter().map(|(p, n)| (p.clone(), 3 * n)).collect();
            let e = d.plus_covering(&overlay_of(&b)).unwrap();
            tiles_with_summed_counts(&e, &a, &thrice, 40)?;
            // corners for measuring: within 2^-20 grid units of the
            // correctly rounded ones, cell by cell
            let (exact, measured) = (c.all_corners(), c.measured_corners());
            prop_assert_eq!(exact.len(), measured.len());
            for (e, m) in exact.iter().zip(&measured) {
                prop_assert_eq!(e.len(), m.len());
                for (p, q) in e.iter().zip(m) {
                    prop_assert!((0..3).all(|k| (p[k] - q[k]).abs() <= MEASURE_UNITS), "{:?} {:?}", p, q);
                }
            }
        }
    }

    /// The square `[0, s]²` cut by the upright planes through each pair of
    /// points of `cuts` (those of two points), each piece with a count.
    fn cut_square(
        s: i32,
        cuts: &[([i32; 2], [i32; 2])],
        count: impl Fn(usize) -> u32,
    ) -> Vec<(Polygon, u32)> {
        let planes: Vec<Plane> = cuts.iter().filter_map(|&(a, b)| upright(a, b)).collect();
        partition(square(s), &planes, count)
    }

    /// Checks that `o`'s cells tile the square `[0, s]²` exactly (all
    /// given one count, they merge into one region, the square, with no
    /// hole), are strictly convex, and count at grid points what `a` and
    /// `b` count there together.
    fn tiles_with_summed_counts(
        o: &FaceOverlay,
        a: &[(Polygon, u32)],
        b: &[(Polygon, u32)],
        s: i32,
    ) -> Result<(), TestCaseError> {
        let one = FaceOverlay::new(*o.support(), (0..o.len()).map(|i| (o.planes(i), 0))).unwrap();
        let r = one.regions();
        prop_assert_eq!(r.len(), 1);
        prop_assert!(r[0].holes.is_empty());
        let mut outer = r[0].outer.clone();
        outer.sort_by(|a, b| a.partial_cmp(b).unwrap());
        let f = f64::from(s);
        prop_assert_eq!(
            outer,
            vec![[0.0, 0.0, 0.0], [0.0, f, 0.0], [f, 0.0, 0.0], [f, f, 0.0]]
        );
        for x in 0..=s {
            for y in (0..=s).step_by(3) {
                let p = [x, y, 0];
                // (a point on an edge of `a` or `b` lies in a cell of the
                // overlay where the two sides have one count)
                let (Some(ca), Some(cb)) = (count_in(a, p), count_in(b, p)) else {
                    continue;
                };
                match count_at(o, p) {
                    Some(c) => prop_assert_eq!(c, ca + cb, "at {:?}", p),
                    // on a cut through cells of one count: on a cell's edge
                    None => prop_assert!(
                        (0..o.len()).any(|i| o
                            .planes(i)
                            .iter()
                            .all(|e| e.classify_grid(p) != Side::Front)),
                        "{:?} in no cell",
                        p
                    ),
                }
            }
        }
        // and each cell is still a strictly convex polygon
        let cells = (0..o.len()).map(|i| (o.planes(i), o.count(i)));
        prop_assert!(FaceOverlay::new(*o.support(), cells).is_some());
        Ok(())
    }

    #[test]
    fn parts_of_one_count_are_not_joined_where_their_union_bends_in() {
        // b: counted 1 in a rectangle and a quadrilateral beside it that
        // share an edge, whose union bends in at one end of it; 0 above
        let b = [
            (vec![[0, 0], [10, 0], [10, 20], [0, 20]], 1),
            (vec![[10, 0], [60, 0], [60, 45], [10, 20]], 1),
            (vec![[0, 20], [10, 20], [60, 45], [60, 60], [0, 60]], 0),
        ];
        let halves = partition(square(60), &[upright([30, 0], [30, 60]).unwrap()], |i| {
            i as u32
        });
        // as drawn, and upside down (the bend at the edge's other end)
        for flip in [false, true] {
            let b: Vec<(Polygon, u32)> = (b.iter())
                .map(|(ring, count)| {
                    let mut points: Vec<GridPoint> = (ring.iter())
                        .map(|&[x, y]| [x, if flip { 60 - y } else { y }, 0])
                        .collect();
                    if flip {
                        points.reverse();
                    }
                    (Polygon::from_grid_points(&points, 0).unwrap(), *count)
                })
                .collect();
            let o = overlay_of(&halves).plus_covering(&overlay_of(&b)).unwrap();
            tiles_with_summed_counts(&o, &halves, &b, 60).unwrap();
            assert!(o.len() <= overlay_of(&halves).plus(&overlay_of(&b)).unwrap().len());
        }
    }

    #[test]
    fn cut_parts_of_one_count_are_joined_where_their_union_is_convex() {
        // a: the square's two halves; b: counted 0 above y = 20, 1 below,
        // where a cut at x = 10 splits it in two
        let a = partition(square(60), &[upright([30, 0], [30, 60]).unwrap()], |i| {
            i as u32
        });
        let cuts = [
            upright([0, 20], [60, 20]).unwrap(),
            upright([10, 0], [10, 60]).unwrap(),
        ];
        let b: Vec<(Polygon, u32)> = (partition(square(60), &cuts[..1], |_| 0).into_iter())
            .flat_map(|(p, _)| {
                let low = p.vertices_f64().iter().all(|v| v[1] <= 20.0);
                match low {
                    true => partition(p, &cuts[1..], |_| 1),
                    false => vec![(p, 0)],
                }
            })
            .collect();
        assert_eq!(b.len(), 3);
        let plain = overlay_of(&a).plus(&overlay_of(&b)).unwrap();
        let joined = overlay_of(&a).plus_covering(&overlay_of(&b)).unwrap();
        // the left half's two parts below y = 20 are one rectangle
        assert_eq!((plain.len(), joined.len()), (5, 4));
        let mut areas: Vec<f64> = (0..joined.len())
            .map(|i| area(&joined.corners(i)))
            .collect();
        areas.sort_by(f64::total_cmp);
        assert_eq!(areas, vec![600.0, 600.0, 1200.0, 1200.0]);
        for (x, y) in [(5, 5), (15, 5), (45, 5), (5, 45), (45, 45)] {
            let want = count_in(&a, [x, y, 0]).unwrap() + count_in(&b, [x, y, 0]).unwrap();
            assert_eq!(count_at(&joined, [x, y, 0]), Some(want), "at {x}, {y}");
        }
    }

    #[test]
    fn cells_that_come_to_one_count_later_are_joined() {
        // the halves cut at x = 20 by a partition counted 1 left of it,
        // then by one counted 1 right of it: every point counts 1 more
        let halves = partition(square(60), &[upright([30, 0], [30, 60]).unwrap()], |_| 0);
        let at = [upright([20, 0], [20, 60]).unwrap()];
        let left = |first: bool| {
            let cells = partition(square(60), &at, |_| 0);
            (cells.into_iter())
                .map(|(p, _)| {
                    let low = p.vertices_f64().iter().all(|v| v[0] <= 20.0);
                    (p, u32::from(low == first))
                })
                .collect::<Vec<_>>()
        };
        let o = (overlay_of(&halves).plus_covering(&overlay_of(&left(true))))
            .and_then(|o| o.plus_covering(&overlay_of(&left(false))))
            .unwrap();
        // the left half's two parts, of one count now, are not joined yet
        assert_eq!(o.len(), 3);
        // (the halves, given apart, share their corners on x = 30: a pass
        // joins one pair of the three, the next the last two)
        let mut joined = o.clone();
        joined.join_cells_near(None);
        assert_eq!(joined.len(), 2);
        tiles_with_summed_counts(&joined, &halves, &[(square(60), 1)], 60).unwrap();
        let areas: f64 = (0..2).map(|i| area(&joined.corners(i))).sum();
        assert_eq!(areas, 3600.0);
        joined.join();
        assert_eq!(joined.len(), 1);
        tiles_with_summed_counts(&joined, &halves, &[(square(60), 1)], 60).unwrap();
        assert_eq!(area(&joined.corners(0)), 3600.0);
    }

    #[test]
    fn cells_given_apart_share_corners_and_join_pass_after_pass() {
        // three upright strips of one count, given as three cells: the
        // cells share the corners where their planes meet, a first pass
        // joins two of them, a second the third
        let cuts = [
            upright([20, 0], [20, 60]).unwrap(),
            upright([40, 0], [40, 60]).unwrap(),
        ];
        let strips = partition(square(60), &cuts, |_| 1);
        let mut once = overlay_of(&strips);
        assert_eq!(once.len(), 3);
        once.join_cells_near(None);
        assert_eq!(once.len(), 2);
        let mut o = overlay_of(&strips);
        o.join();
        assert_eq!(o.len(), 1);
        assert_eq!(area(&o.corners(0)), 3600.0);
        assert_eq!(o.corners(0).len(), 4);
        tiles_with_summed_counts(&o, &strips, &[(square(60), 0)], 60).unwrap();
        // a grid of cells of two counts in checks: no two of one count
        // share an edge, none is joined; in stripes of two counts, each
        // stripe comes to one cell
        let grid: Vec<Plane> = [20, 40]
            .into_iter()
            .flat_map(|t| [upright([t, 0], [t, 60]), upright([0, t], [60, t])])
            .flatten()
            .collect();
        let cells = partition(square(60), &grid, |_| 0);
        let at = |p: &Polygon, k: usize| {
            let v = p.vertices_f64();
            (v.iter().map(|v| v[k]).sum::<f64>() / v.len() as f64 / 20.0) as u32
        };
        let checks: Vec<(Polygon, u32)> = (cells.iter())
            .map(|(p, _)| (p.clone(), (at(p, 0) + at(p, 1)) % 2))
            .collect();
        let mut o = overlay_of(&checks);
        o.join();
        assert_eq!(o.len(), 9);
        let stripes: Vec<(Polygon, u32)> = (cells.iter())
            .map(|(p, _)| (p.clone(), at(p, 0) % 2))
            .collect();
        let mut o = overlay_of(&stripes);
        o.join();
        assert_eq!(o.len(), 3);
        tiles_with_summed_counts(&o, &stripes, &[(square(60), 0)], 60).unwrap();
    }

    #[test]
    fn cells_away_from_the_others_counts_take_the_common_count_whole() {
        // a fine grid of cells, and a partition of the face counted 3 but
        // for one corner square, counted 1
        let lines = |k: i32| {
            (1..k).flat_map(move |i| {
                let t = 60 * i / k;
                [upright([t, 0], [t, 60]), upright([0, t], [60, t])]
            })
        };
        let fine: Vec<Plane> = lines(12).flatten().collect();
        let a = partition(square(60), &fine, |i| i as u32 % 3);
        let corner = [upright([12, 0], [12, 60]), upright([0, 12], [60, 12])];
        let b = partition(
            square(60),
            &corner.into_iter().flatten().collect::<Vec<_>>(),
            |_| 3,
        );
        let b: Vec<(Polygon, u32)> = (b.into_iter())
            .map(|(p, _)| {
                let low = p
                    .vertices_f64()
                    .iter()
                    .all(|v| v[0] <= 12.0 && v[1] <= 12.0);
                (p, if low { 1 } else { 3 })
            })
            .collect();
        let got = overlay_of(&a).plus_covering(&overlay_of(&b)).unwrap();
        tiles_with_summed_counts(&got, &a, &b, 60).unwrap();
        // (the cells the corner's edges cross are cut, the rest whole)
        assert!(got.len() > a.len() && got.len() < a.len() + 10);
        for (x, y) in [
            (1, 1),
            (9, 9),
            (11, 11),
            (11, 13),
            (13, 11),
            (31, 2),
            (59, 59),
        ] {
            let want = count_in(&a, [x, y, 0]).unwrap() + count_in(&b, [x, y, 0]).unwrap();
            assert_eq!(count_at(&got, [x, y, 0]), Some(want), "at {x}, {y}");
        }
    }
}
