//! The pair grid of the certificate's step 2: triangles listed in the
//! cells of a uniform grid their boxes meet, so that the pairs whose
//! boxes overlap are visited once each.

use std::ops::ControlFlow;

use super::Tri;
use crate::kernel::GridPoint;

/// The triangles listed in a uniform grid of cubic cells, of a typical
/// triangle's size: each triangle in the cells its box meets, a pair of
/// triangles whose boxes overlap visited in the cell that holds the low
/// corner of the boxes' common part (so once). Only the cells that hold
/// triangles are listed, in the order of their keys.
pub(super) struct PairGrid {
    /// The listed triangles of the `k`-th cell that holds any:
    /// `listed[first[k]..first[k + 1]]`, each with what the pair test
    /// reads (so that a cell's are contiguous).
    first: Vec<u32>,
    listed: Vec<Listed>,
    /// The grid's cells along x and y.
    nx: u64,
    ny: u64,
}

/// A triangle as listed in a cell: the cell's key, the triangle's box,
/// the cell of its box's low corner, and its index.
#[derive(Clone, Copy)]
struct Listed {
    key: u64,
    lo: [i32; 3],
    hi: [i32; 3],
    low: [u32; 3],
    tri: u32,
}

impl PairGrid {
    /// The triangles of `tris` that `keep` keeps, in cells fitted to all
    /// of `tris`; `None` for fewer than two triangles.
    pub(super) fn new(
        tris: &[Tri],
        lo: GridPoint,
        hi: GridPoint,
        keep: impl Fn(&Tri) -> bool + Sync,
    ) -> Option<PairGrid> {
        if tris.len() < 2 {
            return None;
        }
        // cells of the median of the triangles' largest box extents, grown
        // until there are at most 8 cells a triangle
        let mut ext: Vec<i64> = tris
            .iter()
            .map(|t| {
                (0..3)
                    .map(|k| t.hi[k] as i64 - t.lo[k] as i64)
                    .max()
                    .unwrap_or(0)
            })
            .collect();
        let mid = ext.len() / 2;
        let mut size = (*ext.select_nth_unstable(mid).1).max(1);
        let span = [0, 1, 2].map(|k| hi[k] as i64 - lo[k] as i64);
        let dims = |size: i64| span.map(|s| (s / size + 1) as u64);
        // (saturating: tiny triangles in a large scene would overflow)
        let cells = |size: i64| dims(size).iter().fold(1u64, |n, &d| n.saturating_mul(d));
        while cells(size) > 8 * tris.len() as u64 {
            size *= 2;
        }
        let [nx, ny, _] = dims(size);
        let cell = |p: GridPoint| [0, 1, 2].map(|k| ((p[k] as i64 - lo[k] as i64) / size) as u64);
        let key = |c: [u64; 3]| (c[2] * ny + c[1]) * nx + c[0];
        // each triangle in every cell its box meets, sorted by cell (a
        // counting sort: the cells are at most 8 a triangle; within a
        // cell the triangles keep their order)
        let cells_of = |t: &Tri| {
            let (a, b) = (cell(t.lo), cell(t.hi));
            (a[2]..=b[2]).flat_map(move |z| {
                (a[1]..=b[1]).flat_map(move |y| (a[0]..=b[0]).map(move |x| key([x, y, z])))
            })
        };
        let n_cells = cells(size) as usize;
        let mut at = vec![0u32; n_cells + 1];
        for t in tris.iter().filter(|t| keep(t)) {
            for k in cells_of(t) {
                at[k as usize + 1] += 1;
            }
        }
        for k in 1..at.len() {
            at[k] += at[k - 1];
        }
        let mut first: Vec<u32> = (0..n_cells)
            .filter(|&k| at[k + 1] > at[k])
            .map(|k| at[k])
            .collect();
        first.push(at[n_cells]);
        let blank = Listed {
            key: 0,
            lo: [0; 3],
            hi: [0; 3],
            low: [0; 3],
            tri: 0,
        };
        let mut listed = vec![blank; at[n_cells] as usize];
        for (i, t) in tris.iter().enumerate().filter(|(_, t)| keep(t)) {
            let low = cell(t.lo).map(|c| c as u32);
            for k in cells_of(t) {
                let slot = &mut at[k as usize];
                listed[*slot as usize] = Listed {
                    key: k,
                    lo: t.lo,
                    hi: t.hi,
                    low,
                    tri: i as u32,
                };
                *slot += 1;
            }
        }
        Some(PairGrid {
            first,
            listed,
            nx,
            ny,
        })
    }

    /// The number of cells that hold triangles.
    fn cell_count(&self) -> usize {
        self.first.len() - 1
    }

    /// [`PairGrid::visit`] over runs of the listed cells, in parallel
    /// when the listings are many: each run's value, filled by `visit`
    /// from `A::default()` until it breaks, in the runs' order.
    pub(super) fn visit_runs<A: Default + Send>(
        &self,
        tris: &[Tri],
        visit: impl Fn(&mut A, &Tri, &Tri) -> ControlFlow<()> + Sync,
    ) -> Vec<A> {
        super::runs(self.cell_count(), self.listed.len(), |cells| {
            let mut a = A::default();
            self.visit(tris, cells, |s, t| visit(&mut a, s, t));
            a
        })
    }

    /// Calls `visit` on each pair of triangles of `tris` (those the grid
    /// was made of) whose boxes overlap and that is visited in one of the
    /// listed cells `range`, until it breaks.
    fn visit(
        &self,
        tris: &[Tri],
        range: std::ops::Range<usize>,
        mut visit: impl FnMut(&Tri, &Tri) -> ControlFlow<()>,
    ) {
        for k in range {
            let here = &self.listed[self.first[k] as usize..self.first[k + 1] as usize];
            for (i, s) in here.iter().enumerate() {
                for t in &here[i + 1..] {
                    // without branches: most pairs are near misses
                    let mut miss = false;
                    for k in 0..3 {
                        miss |= (t.lo[k] > s.hi[k]) | (s.lo[k] > t.hi[k]);
                    }
                    if miss {
                        continue;
                    }
                    // the cell of the common part's low corner (the larger
                    // of the two low cells on each axis) must be this one
                    let c = [0, 1, 2].map(|k| u64::from(s.low[k].max(t.low[k])));
                    if (c[2] * self.ny + c[1]) * self.nx + c[0] != s.key {
                        continue;
                    }
                    let (s, t) = (&tris[s.tri as usize], &tris[t.tri as usize]);
                    if visit(s, t).is_break() {
                        return;
                    }
                }
            }
        }
    }
}
