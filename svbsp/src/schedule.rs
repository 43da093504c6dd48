//! The order of the receivers' shading: large faces first, the rest in
//! runs. Only the order of the work changes, never its result.

use std::ops::Range;

use bsp_core::Polygon;
use rayon::prelude::*;
use smallvec::SmallVec;

/// A face's cells, pieces or fragments from this many on (a ground under
/// a mesh, cut by its lights) are worked on in parallel, in order: the
/// lights after the first pass over runs of them, and they are made into
/// polygons, pieces, probe points and shares.
pub(crate) const PARALLEL_CELLS: usize = 256;

/// A receiver of this many times the median receiver's area counts as
/// large.
const LARGE_AREA: f64 = 64.0;

/// At most this many receivers are started early as large.
const MAX_LARGE: usize = 64;

/// The receivers (indices into `ranges`) to shade first: those of more
/// than [`LARGE_AREA`] times the median area, largest first (at most
/// [`MAX_LARGE`]). A large face, such as a ground under a scanned mesh,
/// is cut into many fragments by one thread: shaded last, as its place
/// in the receiver order would have it, it keeps one core busy after the
/// other has run out of work. Only the order of the work changes, never
/// its result.
pub(crate) fn large_receivers(polys: &[Polygon], ranges: &[Range<usize>]) -> Vec<usize> {
    let area: Vec<f64> = ranges
        .par_iter()
        .map(|r| polys[r.clone()].iter().map(approx_area).sum())
        .collect();
    large_first(&area)
}

/// Of receivers of areas `area`, those [`large_receivers`] starts first.
pub(crate) fn large_first(area: &[f64]) -> Vec<usize> {
    let mut sorted = area.to_vec();
    let Some((_, &mut median, _)) =
        (!sorted.is_empty()).then(|| sorted.select_nth_unstable_by(area.len() / 2, f64::total_cmp))
    else {
        return Vec::new();
    };
    let mut large: Vec<usize> = (0..area.len())
        .filter(|&i| area[i] > LARGE_AREA * median)
        .collect();
    large.sort_by(|&a, &b| area[b].total_cmp(&area[a]).then(a.cmp(&b)));
    large.truncate(MAX_LARGE);
    large
}

/// `p`'s area in grid units², from its vertices' approximations (for
/// scheduling only).
fn approx_area(p: &Polygon) -> f64 {
    let v: SmallVec<[glam::DVec3; 8]> = (p.vertices().iter())
        .map(|x| glam::DVec3::from(x.approx_f64()))
        .collect();
    crate::polygon_area(&v)
}

/// Receivers `all` in order, cut into runs of at most `chunk`, each of
/// `large` a run of its own.
pub(crate) fn runs(all: Range<usize>, large: &[usize], chunk: usize) -> Vec<Range<usize>> {
    let mut cuts: Vec<usize> = (large.iter())
        .filter(|i| all.contains(i))
        .flat_map(|&i| [i, i + 1])
        .collect();
    cuts.sort_unstable();
    let mut out = Vec::new();
    let mut start = all.start;
    for end in cuts.into_iter().chain([all.end]) {
        while start < end {
            let e = end.min(start + chunk);
            out.push(start..e);
            start = e;
        }
    }
    out
}

/// Whether run `r` is one of the `large` receivers alone.
pub(crate) fn is_one_of(r: &Range<usize>, large: &[usize]) -> bool {
    r.len() == 1 && large.contains(&r.start)
}
