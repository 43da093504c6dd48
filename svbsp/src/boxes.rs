//! Boxes of exact integers: of grid points, of exact polygons, of an
//! occluder's volumes ([`Reach`]), and the pieces' boxes a face's cutting
//! tests each occluder's against ([`Scans`]). Boxes only ever let through
//! more than the exact tests keep.

use bsp_core::{GridPoint, Polygon};

/// The box of grid points, per axis `[lo, hi]`.
pub(crate) fn grid_box(points: &[GridPoint]) -> [[i64; 2]; 3] {
    [0, 1, 2].map(|k| {
        let c = points.iter().map(|p| i64::from(p[k]));
        [c.clone().min().unwrap_or(0), c.max().unwrap_or(0)]
    })
}

/// Boxes of an occluder's penumbra volume and of its umbra volume (empty
/// where some `lo > hi`), within the scene.
pub(crate) type Reach = [Box3; 2];

/// A box per axis, `[lo, hi]`, in grid units (exact integers).
pub(crate) type Box3 = [[i64; 2]; 3];

/// The least box holding both.
pub(crate) fn union(a: Box3, b: Box3) -> Box3 {
    [0, 1, 2].map(|k| [a[k][0].min(b[k][0]), a[k][1].max(b[k][1])])
}

/// Whether two boxes meet (touching counts).
pub(crate) fn overlap(a: &Box3, b: &Box3) -> bool {
    (0..3).all(|k| a[k][0] <= b[k][1] && b[k][0] <= a[k][1])
}

/// A box holding every point.
pub(crate) const EVERYWHERE: Box3 = [[i64::MIN, i64::MAX]; 3];

/// A box holding no point.
pub(crate) const EMPTY: Box3 = [[i64::MAX, i64::MIN]; 3];

/// The smallest box of integers holding a polygon: each exact corner's
/// coordinates rounded down and up (`Homogeneous::floor_ceil`).
pub(crate) fn polygon_box(p: &Polygon) -> Box3 {
    let mut b = [[i64::MAX, i64::MIN]; 3];
    for v in p.vertices() {
        let (lo, hi) = match v {
            bsp_core::Point::Grid(g) => (g.map(i64::from), g.map(i64::from)),
            bsp_core::Point::Implicit(i) => {
                let c = [0, 1, 2].map(|k| i.floor_ceil(k));
                (c.map(|c| c.0), c.map(|c| c.1))
            }
        };
        for k in 0..3 {
            b[k] = [b[k][0].min(lo[k]), b[k][1].max(hi[k])];
        }
    }
    b
}

/// What the cutting of a face's pieces (`area::Cutting::family`) tests a
/// piece against each occluder's boxes with: its box, and which box of
/// the occluder's may meet it.
pub(crate) struct Scan {
    pub(crate) bbox: Box3,
    pub(crate) kind: Near,
}

/// Which of an occluder's boxes ([`Reach`]) a piece must meet to be cut.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Near {
    /// None: a piece in an umbra is never cut again.
    Never,
    /// The penumbra volume's.
    Penumbra,
    /// The umbra's (a piece that hides every corner already).
    Umbra,
}

impl Scan {
    /// Whether the piece's box meets the occluder's box it must meet.
    pub(crate) fn near(&self, reach: &Reach) -> bool {
        let r = match self.kind {
            Near::Never => return false,
            Near::Penumbra => &reach[0],
            Near::Umbra => &reach[1],
        };
        overlap(&self.bbox, r)
    }
}

/// The pieces' [`Scan`]s in their order, and per run of [`Scans::RUN`]
/// of them a box holding the boxes of those that may be cut (it may be
/// larger: a piece that moves away leaves it as it was).
pub(crate) struct Scans {
    pub(crate) items: Vec<Scan>,
    runs: Vec<Box3>,
}

impl Scans {
    const RUN: usize = 32;

    pub(crate) fn new(items: impl Iterator<Item = Scan>) -> Scans {
        let mut s = Scans {
            items: Vec::new(),
            runs: Vec::new(),
        };
        items.for_each(|x| s.push(x));
        s
    }

    /// Widens the box of the run holding position `i` by its piece's.
    fn cover(&mut self, i: usize) {
        let x = &self.items[i];
        if x.kind != Near::Never {
            let b = &mut self.runs[i / Self::RUN];
            *b = union(*b, x.bbox);
        }
    }

    pub(crate) fn push(&mut self, x: Scan) {
        if self.items.len().is_multiple_of(Self::RUN) {
            self.runs.push(EMPTY);
        }
        self.items.push(x);
        self.cover(self.items.len() - 1);
    }

    /// As `Vec::swap_remove`: the last moves to `i`, and its run's box
    /// takes it in.
    pub(crate) fn swap_remove(&mut self, i: usize) {
        self.items.swap_remove(i);
        if i < self.items.len() {
            self.cover(i);
        }
        if self.items.len().is_multiple_of(Self::RUN) {
            self.runs.truncate(self.items.len() / Self::RUN);
        }
    }

    /// Where the next run starts, if no piece from `i` to its end meets
    /// either of the occluder's boxes.
    pub(crate) fn apart_until(&self, i: usize, reach: &Reach) -> Option<usize> {
        let run = i / Self::RUN;
        let b = &self.runs[run];
        (!overlap(b, &reach[0]) && !overlap(b, &reach[1])).then_some((run + 1) * Self::RUN)
    }
}

/// A uniform grid of cells over the scene, each listing the faces whose
/// box meets it. A coordinate's cell is `(v − lo)·n / extent`, rounded
/// down, in integers: it never decreases as `v` grows, so a box meets
/// every cell of every face box it meets.
pub(crate) struct CellGrid {
    lo: [i64; 3],
    extent: [i64; 3],
    n: [usize; 3],
    cells: Vec<Vec<u32>>,
}

impl CellGrid {
    /// About one cell per face, cubes as far as the scene's shape allows.
    pub(crate) fn new(scene: Box3, boxes: &[Box3]) -> CellGrid {
        let mut grid = CellGrid::empty(scene, boxes.len());
        for (i, b) in boxes.iter().enumerate() {
            grid.insert(i as u32, *b);
        }
        grid
    }

    /// A grid of about one cell per face for `faces` faces, none listed.
    fn empty(scene: Box3, faces: usize) -> CellGrid {
        let extent = scene.map(|[lo, hi]| hi - lo + 1);
        let volume: f64 = extent.iter().map(|&e| e as f64).product();
        let side = (volume / faces.max(1) as f64).cbrt();
        CellGrid::of_side(scene, [side; 3], faces)
    }

    /// [`CellGrid::new`] over the boxes `items` (each with its index) only,
    /// within `scene`, which holds them.
    pub(crate) fn of_items(scene: Box3, items: &[(u32, Box3)]) -> CellGrid {
        let mut grid = CellGrid::empty(scene, items.len());
        for &(i, b) in items {
            grid.insert(i, b);
        }
        grid
    }

    /// A grid of cells about `side` long per axis (longer where that
    /// would make more than about two cells per face), none listed.
    fn of_side(scene: Box3, mut side: [f64; 3], faces: usize) -> CellGrid {
        let extent = scene.map(|[lo, hi]| hi - lo + 1);
        let target = faces.max(1) as f64;
        // a flat scene (one face's box) would get too many thin cells
        let n = loop {
            let n = [0, 1, 2].map(|k| ((extent[k] as f64 / side[k]).ceil() as usize).clamp(1, 512));
            if (n[0] * n[1] * n[2]) as f64 <= 2.0 * target + 8.0 {
                break n;
            }
            side = side.map(|s| s * 1.25);
        };
        CellGrid {
            lo: scene.map(|[lo, _]| lo),
            extent,
            n,
            cells: vec![Vec::new(); n[0] * n[1] * n[2]],
        }
    }

    /// Lists face `i` in every cell its box `b` meets.
    fn insert(&mut self, i: u32, b: Box3) {
        let (lo, hi) = self.range(b);
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    let c = self.cell([x, y, z]);
                    self.cells[c].push(i);
                }
            }
        }
    }

    fn cell(&self, c: [usize; 3]) -> usize {
        (c[0] * self.n[1] + c[1]) * self.n[2] + c[2]
    }

    /// The cells a box meets, per axis from and to (inclusive).
    fn range(&self, b: Box3) -> ([usize; 3], [usize; 3]) {
        let at = |k: usize, v: i64| {
            let off = (v.clamp(self.lo[k], self.lo[k] + self.extent[k] - 1) - self.lo[k]) as u64;
            // (in 64 bits where the product fits, a hardware division; `i128`
            // division is a library call)
            match off.checked_mul(self.n[k] as u64) {
                Some(p) => (p / self.extent[k] as u64) as usize,
                None => (u128::from(off) * self.n[k] as u128 / self.extent[k] as u128) as usize,
            }
        };
        (
            [0, 1, 2].map(|k| at(k, b[k][0])),
            [0, 1, 2].map(|k| at(k, b[k][1])),
        )
    }

    /// How many cells box `b` meets.
    fn cells_met(&self, b: Box3) -> usize {
        let (lo, hi) = self.range(b);
        (0..3).map(|k| hi[k] + 1 - lo[k]).product()
    }

    /// Calls `f` with every face listed in a cell that `b` meets (a face
    /// may come more than once).
    pub(crate) fn visit(&self, b: Box3, mut f: impl FnMut(u32)) {
        let (lo, hi) = self.range(b);
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    self.cells[self.cell([x, y, z])].iter().for_each(|&i| f(i));
                }
            }
        }
    }

    /// The grid with every cell's list packed into one list, in cell
    /// order, each entry `item` of the listed index: a visit then reads
    /// one run of memory per row of cells, the entries' data inline.
    pub(crate) fn packed<T>(self, item: impl Fn(u32) -> T) -> PackedGrid<T> {
        let mut starts = Vec::with_capacity(self.cells.len() + 1);
        let mut items = Vec::with_capacity(self.cells.iter().map(Vec::len).sum());
        starts.push(0);
        for cell in &self.cells {
            items.extend(cell.iter().map(|&i| item(i)));
            starts.push(items.len() as u32);
        }
        PackedGrid {
            grid: CellGrid {
                cells: Vec::new(),
                ..self
            },
            starts,
            items,
        }
    }
}

/// A [`CellGrid`] whose cells' entries lie in one list ([`CellGrid::packed`]).
pub(crate) struct PackedGrid<T> {
    /// The cells' layout (its lists left empty).
    grid: CellGrid,
    /// Where each cell's entries start in `items`, and the end.
    starts: Vec<u32>,
    items: Vec<T>,
}

impl<T> PackedGrid<T> {
    /// Calls `f` with every entry of a cell that `b` meets (an entry may
    /// come more than once).
    pub(crate) fn visit(&self, b: Box3, mut f: impl FnMut(&T)) {
        let (lo, hi) = self.grid.range(b);
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                // a row's cells are adjacent: one run of entries
                let (first, last) = (self.grid.cell([x, y, lo[2]]), self.grid.cell([x, y, hi[2]]));
                let run = self.starts[first] as usize..self.starts[last + 1] as usize;
                self.items[run].iter().for_each(&mut f);
            }
        }
    }
}

/// The occluders' [`Reach`]es near one face, indexed by a [`CellGrid`]
/// over the face's box: for a box within the face, the occluders whose
/// boxes may meet it, in their order (a superset of those that do). A
/// face's pieces lie in its box, so an occluder whose boxes miss the
/// face's box meets none of them.
pub(crate) struct ReachIndex {
    grid: CellGrid,
    /// The occluder of each box in the grid.
    of: Vec<u32>,
    /// Occluders whose boxes span more than a quarter of the cells: met
    /// by every box asked about.
    wide: Vec<u32>,
}

impl ReachIndex {
    pub(crate) fn new<'a>(face: Box3, reaches: impl Iterator<Item = &'a Reach>) -> ReachIndex {
        let (mut boxes, mut of, mut wide) = (Vec::new(), Vec::new(), Vec::new());
        for (i, reach) in reaches.enumerate() {
            // both boxes as one, within the face's (an empty box adds nothing)
            let within = reach.iter().filter_map(|&r| meet(r, face));
            if let Some(b) = within.reduce(union) {
                boxes.push(b);
                of.push(i as u32);
            }
        }
        // cells about as long as the boxes' median, per axis: a box meets a
        // few cells, not thousands
        let side = [0, 1, 2].map(|k| {
            let mut e: Vec<i64> = boxes.iter().map(|b| b[k][1] - b[k][0] + 1).collect();
            let mid = e.len() / 2;
            if mid < e.len() {
                e.select_nth_unstable(mid);
            }
            e.get(mid).map_or(1.0, |&m| m as f64)
        });
        let mut grid = CellGrid::of_side(face, side, boxes.len());
        let cells = grid.cells.len();
        let mut kept = Vec::with_capacity(boxes.len());
        for (b, i) in boxes.into_iter().zip(of) {
            if 4 * grid.cells_met(b) > cells {
                wide.push(i);
            } else {
                grid.insert(kept.len() as u32, b);
                kept.push(i);
            }
        }
        ReachIndex {
            grid,
            of: kept,
            wide,
        }
    }

    /// The occluders whose boxes may meet `b`, ascending, each once.
    pub(crate) fn near(&self, b: &Box3) -> Vec<u32> {
        let mut ids = self.wide.clone();
        self.grid.visit(*b, |g| ids.push(self.of[g as usize]));
        ids.sort_unstable();
        ids.dedup();
        ids
    }
}

/// The box two boxes share; `None` where they do not meet (or either is
/// empty).
pub(crate) fn meet(a: Box3, b: Box3) -> Option<Box3> {
    let m = [0, 1, 2].map(|k| [a[k][0].max(b[k][0]), a[k][1].min(b[k][1])]);
    m.iter().all(|[lo, hi]| lo <= hi).then_some(m)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn a_box() -> impl Strategy<Value = Box3> {
        prop::array::uniform3((-50i64..50, 0i64..20).prop_map(|(lo, w)| [lo, lo + w]))
    }

    /// A box along the first axis at `at`, so pieces pushed in order lie
    /// in runs that are apart.
    fn placed(b: Box3, at: i64) -> Box3 {
        [[b[0][0] + 40 * at, b[0][1] + 40 * at], b[1], b[2]]
    }

    fn kind() -> impl Strategy<Value = Near> {
        prop_oneof![Just(Near::Never), Just(Near::Penumbra), Just(Near::Umbra)]
    }

    proptest! {
        /// Whatever was pushed and swapped out, a run passed over holds no
        /// piece near the occluder's boxes.
        #[test]
        fn a_run_passed_over_holds_nothing_near(
            ops in prop::collection::vec((prop::bool::weighted(0.8), a_box(), kind(), any::<prop::sample::Index>()), 1..300),
            reaches in prop::collection::vec((a_box(), a_box(), 0i64..300), 8),
        ) {
            let mut scans = Scans::new(std::iter::empty());
            for (n, (push, bbox, kind, at)) in ops.into_iter().enumerate() {
                if push || scans.items.is_empty() {
                    scans.push(Scan { bbox: placed(bbox, n as i64), kind });
                } else {
                    scans.swap_remove(at.index(scans.items.len()));
                }
                prop_assert_eq!(scans.runs.len(), scans.items.len().div_ceil(Scans::RUN));
                for &(penumbra, umbra, at) in &reaches {
                    let reach = [placed(penumbra, at), placed(umbra, at)];
                    let mut i = 0;
                    while i < scans.items.len() {
                        match scans.apart_until(i, &reach) {
                            Some(next) => {
                                for x in &scans.items[i..next.min(scans.items.len())] {
                                    prop_assert!(!x.near(&reach));
                                }
                                i = next;
                            }
                            None => i += 1,
                        }
                    }
                }
            }
        }

        /// For any box within a face's box, the index lists every
        /// occluder one of whose boxes (possibly empty, or unbounded)
        /// meets it, ascending and each once.
        #[test]
        fn the_index_lists_every_occluder_near_a_box(
            reaches in prop::collection::vec((a_box(), a_box(), 0u8..8), 0..200),
            face in a_box(),
            asked in prop::collection::vec(a_box(), 1..20),
        ) {
            // some boxes empty (lo > hi), some everywhere, the rest as drawn
            let reaches: Vec<Reach> = reaches
                .into_iter()
                .map(|(a, b, kind)| match kind {
                    0 => [[[5, 4], [0, 0], [0, 0]], b],
                    1 => [EVERYWHERE, a],
                    _ => [a, b],
                })
                .collect();
            // a flat face, as most are
            let face = [face[0], [face[1][0], face[1][0]], face[2]];
            let index = ReachIndex::new(face, reaches.iter());
            for b in asked {
                let Some(b) = meet(b, face) else { continue };
                let listed = index.near(&b);
                prop_assert!(listed.windows(2).all(|w| w[0] < w[1]));
                for (i, r) in reaches.iter().enumerate() {
                    if overlap(&r[0], &b) || overlap(&r[1], &b) {
                        prop_assert!(listed.contains(&(i as u32)), "occluder {} missed", i);
                    }
                }
            }
        }
    }
}
