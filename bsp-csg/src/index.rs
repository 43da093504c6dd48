//! A uniform grid of face boxes: the faces overlapping a box, and the
//! faces a ray along `+x` may cross.

use bsp_core::internals::{ConvexFace, PointRef};

/// An integer box: inclusive grid coordinate ranges per axis.
pub(crate) type IBox = ([i64; 3], [i64; 3]);

/// A face's box in 32 bits (as a solid keeps it): the build reads one
/// per face at every level, so half the room is half the traffic.
pub(crate) type SmallBox = ([i32; 3], [i32; 3]);

/// The box of grid points that holds a polygon: exact for grid vertices,
/// the floor and ceiling of the approximate coordinates widened by one
/// step for implicit ones.
pub(crate) fn polygon_box(p: &impl ConvexFace) -> IBox {
    let (mut lo, mut hi) = ([i64::MAX; 3], [i64::MIN; 3]);
    for i in 0..p.corner_count() {
        let v = p.corner(i);
        match v {
            PointRef::Grid(g) => {
                for k in 0..3 {
                    lo[k] = lo[k].min(g[k] as i64);
                    hi[k] = hi[k].max(g[k] as i64);
                }
            }
            PointRef::Implicit(i) => {
                // the cached approximation is within a few ulps, far
                // below the margin of 1 for any coordinate under 2^40;
                // beyond that, the correctly rounded value (an exact
                // division) is used
                let a = i.approx_f64();
                let r = if a.iter().all(|c| c.abs() < (1u64 << 40) as f64) {
                    a
                } else {
                    v.to_f64()
                };
                for k in 0..3 {
                    lo[k] = lo[k].min(r[k].floor() as i64 - 1);
                    hi[k] = hi[k].max(r[k].ceil() as i64 + 1);
                }
            }
        }
    }
    (lo, hi)
}

/// Whether the box holds the grid point.
pub(crate) fn holds(b: &IBox, g: &bsp_core::GridPoint) -> bool {
    (0..3).all(|k| b.0[k] <= g[k] as i64 && g[k] as i64 <= b.1[k])
}

pub(crate) fn overlaps(a: &IBox, b: &IBox) -> bool {
    (0..3).all(|k| a.0[k] <= b.1[k] && b.0[k] <= a.1[k])
}

pub(crate) fn intersect(a: &IBox, b: &IBox) -> Option<IBox> {
    let lo = [0, 1, 2].map(|k| a.0[k].max(b.0[k]));
    let hi = [0, 1, 2].map(|k| a.1[k].min(b.1[k]));
    (0..3).all(|k| lo[k] <= hi[k]).then_some((lo, hi))
}

pub(crate) fn union(a: &IBox, b: &IBox) -> IBox {
    (
        [0, 1, 2].map(|k| a.0[k].min(b.0[k])),
        [0, 1, 2].map(|k| a.1[k].max(b.1[k])),
    )
}

/// The box spanning `boxes`; `None` for none.
pub(crate) fn span(boxes: impl IntoIterator<Item = IBox>) -> Option<IBox> {
    boxes.into_iter().reduce(|a, b| union(&a, &b))
}

/// Face ids bucketed by the grid cells their boxes overlap. Boxes beyond
/// the grid fall in its border cells, so every query stays conservative.
#[derive(Clone, Debug)]
pub(crate) struct FaceIndex {
    lo: [i64; 3],
    size: [i64; 3],
    dims: [usize; 3],
    cells: Vec<Vec<u32>>,
}

impl FaceIndex {
    /// An index over `bounds` sized for about `count` faces.
    pub(crate) fn new(bounds: IBox, count: usize) -> FaceIndex {
        let ext = [0, 1, 2].map(|k| (bounds.1[k] - bounds.0[k] + 1).max(1) as f64);
        let target = (count as f64 / 2.0).max(1.0);
        let scale = (target / (ext[0] * ext[1] * ext[2])).cbrt();
        let dims = [0, 1, 2].map(|k| ((ext[k] * scale).ceil() as usize).clamp(1, 256));
        let size = [0, 1, 2].map(|k| ((ext[k] / dims[k] as f64).ceil() as i64).max(1));
        FaceIndex {
            lo: bounds.0,
            size,
            dims,
            cells: vec![Vec::new(); dims[0] * dims[1] * dims[2]],
        }
    }

    fn coord(&self, k: usize, x: i64) -> usize {
        ((x - self.lo[k]).div_euclid(self.size[k])).clamp(0, self.dims[k] as i64 - 1) as usize
    }

    fn at(&self, c: [usize; 3]) -> usize {
        (c[0] * self.dims[1] + c[1]) * self.dims[2] + c[2]
    }

    fn cells_of(&self, b: &IBox) -> impl Iterator<Item = usize> + '_ {
        let lo = [0, 1, 2].map(|k| self.coord(k, b.0[k]));
        let hi = [0, 1, 2].map(|k| self.coord(k, b.1[k]));
        (lo[0]..=hi[0]).flat_map(move |x| {
            (lo[1]..=hi[1]).flat_map(move |y| (lo[2]..=hi[2]).map(move |z| self.at([x, y, z])))
        })
    }

    /// The index over `bounds` sized for about `count` faces, holding the
    /// faces `(id, box)` of `faces` (the same lists as inserting them in
    /// order of id): each face's range of cells is found in parallel,
    /// then the lists are counted, made to size and filled in order.
    pub(crate) fn filled(
        bounds: IBox,
        count: usize,
        faces: usize,
        face_box: impl Fn(usize) -> Option<IBox> + Sync,
    ) -> FaceIndex {
        let mut ix = FaceIndex::new(bounds, count);
        let this = &ix;
        // (cell coordinates are below 256: `new` makes at most 256 cells
        // along an axis)
        debug_assert!(ix.dims.iter().all(|&d| d <= 256));
        let ranges: Vec<Option<[u8; 6]>> = bsp_core::par::map(faces, |i| {
            face_box(i).map(|b| {
                let c = |k: usize, x: i64| this.coord(k, x) as u8;
                [
                    c(0, b.0[0]),
                    c(1, b.0[1]),
                    c(2, b.0[2]),
                    c(0, b.1[0]),
                    c(1, b.1[1]),
                    c(2, b.1[2]),
                ]
            })
        });
        let dims = ix.dims;
        let cells_in = move |r: [u8; 6]| {
            (r[0] as usize..=r[3] as usize).flat_map(move |x| {
                (r[1] as usize..=r[4] as usize).flat_map(move |y| {
                    (r[2] as usize..=r[5] as usize).map(move |z| (x * dims[1] + y) * dims[2] + z)
                })
            })
        };
        let mut counts = vec![0u32; ix.cells.len()];
        for &r in ranges.iter().flatten() {
            for c in cells_in(r) {
                counts[c] += 1;
            }
        }
        let mut cells: Vec<Vec<u32>> = counts
            .iter()
            .map(|&n| Vec::with_capacity(n as usize))
            .collect();
        for (i, r) in ranges.iter().enumerate() {
            if let &Some(r) = r {
                for c in cells_in(r) {
                    cells[c].push(i as u32);
                }
            }
        }
        ix.cells = cells;
        ix
    }

    /// Calls `f` with each cell's list that `b` overlaps.
    fn each_list(&mut self, b: &IBox, mut f: impl FnMut(&mut Vec<u32>)) {
        let lo = [0, 1, 2].map(|k| self.coord(k, b.0[k]));
        let hi = [0, 1, 2].map(|k| self.coord(k, b.1[k]));
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    let c = self.at([x, y, z]);
                    f(&mut self.cells[c]);
                }
            }
        }
    }

    pub(crate) fn insert(&mut self, id: u32, b: &IBox) {
        self.each_list(b, |list| list.push(id));
    }

    pub(crate) fn remove(&mut self, id: u32, b: &IBox) {
        self.each_list(b, |list| {
            if let Some(i) = list.iter().position(|&x| x == id) {
                list.swap_remove(i);
            }
        });
    }

    /// Keeps the ids `keep` accepts (every list in parallel, in order).
    pub(crate) fn retain(&mut self, keep: impl Fn(u32) -> bool + Sync) {
        bsp_core::par::for_each_mut(&mut self.cells, |_, list| list.retain(|&f| keep(f)));
    }

    /// How many ids [`FaceIndex::near`] would give (with repeats),
    /// without listing them.
    pub(crate) fn near_count(&self, b: &IBox) -> usize {
        self.cells_of(b).map(|c| self.cells[c].len()).sum()
    }

    /// The ids in the cells `b` overlaps (with repeats), into `out`.
    pub(crate) fn near(&self, b: &IBox, out: &mut Vec<u32>) {
        for c in self.cells_of(b) {
            out.extend_from_slice(&self.cells[c]);
        }
    }

    /// The ids in the cells a ray from `q` along `+x` passes (with
    /// repeats): the column of cells at `q`'s `y` and `z`, from `q`'s
    /// cell on.
    pub(crate) fn along_x(&self, q: [i64; 3], out: &mut Vec<u32>) {
        let (y, z) = (self.coord(1, q[1]), self.coord(2, q[2]));
        for x in self.coord(0, q[0])..self.dims[0] {
            out.extend_from_slice(&self.cells[self.at([x, y, z])]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_filled_index_is_the_faces_inserted_in_turn() {
        let bounds = ([-50, 0, 10], [149, 99, 59]);
        // small and large boxes, some beyond the bounds, some slots empty
        let mut state = 7u64;
        let mut next = |m: i64| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) as i64 % m
        };
        let boxes: Vec<Option<IBox>> = (0..3000)
            .map(|i| {
                if i % 17 == 0 {
                    return None;
                }
                let lo = [next(260) - 80, next(130) - 15, next(80)];
                let size = if i % 5 == 0 { 60 } else { 4 };
                Some((lo, [0, 1, 2].map(|k| lo[k] + next(size))))
            })
            .collect();
        let filled = FaceIndex::filled(bounds, 2000, boxes.len(), |i| boxes[i]);
        let mut inserted = FaceIndex::new(bounds, 2000);
        for (i, b) in boxes.iter().enumerate() {
            if let Some(b) = b {
                inserted.insert(i as u32, b);
            }
        }
        assert_eq!(filled.dims, inserted.dims);
        assert_eq!(filled.cells, inserted.cells);
        assert!(filled.cells.iter().filter(|c| !c.is_empty()).count() > 100);
    }
}
