//! What a solid answers: the faces near a box, winding numbers and
//! membership.

use bsp_core::internals::ConvexFace;
use bsp_core::par;
use bsp_core::{GridPoint, Membership, Side};

use super::{Solid, SolidFace, winding};
use crate::index::{IBox, overlaps, span};

/// Face ids a query near a box handles in parallel.
const MANY_NEAR: usize = 1 << 15;

impl Solid {
    /// The live faces whose box overlaps `b`.
    pub(crate) fn faces_near(&self, b: &IBox) -> Vec<u32> {
        match self.near_ids(b) {
            None => par::filter_map(self.faces.len(), |i| {
                let i = i as u32;
                self.near_face(i, b).map(|_| i)
            }),
            Some(ids) if ids.len() > MANY_NEAR => {
                par::filter_map(ids.len(), |k| self.near_face(ids[k], b).map(|_| ids[k]))
            }
            Some(mut ids) => {
                ids.retain(|&i| self.near_face(i, b).is_some());
                // the ids came with repeats: the lists of a large box are
                // kept while an operation runs
                ids.shrink_to_fit();
                ids
            }
        }
    }

    /// The box spanned by the live faces whose box overlaps `b`.
    pub(crate) fn near_span(&self, b: &IBox) -> Option<IBox> {
        let bx = |i: u32| self.near_face(i, b).map(SolidFace::bx);
        let spans = match self.near_ids(b) {
            None => par::fold_runs(self.faces.len(), |r| span(r.filter_map(|i| bx(i as u32)))),
            Some(ids) => par::fold_runs(ids.len(), |r| span(ids[r].iter().filter_map(|&i| bx(i)))),
        };
        span(spans.into_iter().flatten())
    }

    /// Face `i` if it is live and its box overlaps `b`.
    #[inline]
    fn near_face(&self, i: u32, b: &IBox) -> Option<&SolidFace> {
        self.faces[i as usize]
            .as_ref()
            .filter(|f| overlaps(&f.bx(), b))
    }

    /// The ids the index lists near `b`, sorted and without repeats;
    /// `None` where a scan of the slots is cheaper: many ids, as many as
    /// half the slots (each face is listed in several index cells), which
    /// a scan in order gives sorted without listing them first.
    fn near_ids(&self, b: &IBox) -> Option<Vec<u32>> {
        let index = self.query_index()?;
        let listed = index.near_count(b);
        if listed > MANY_NEAR && listed > self.faces.len() / 2 {
            return None;
        }
        let mut ids = Vec::with_capacity(listed);
        index.near(b, &mut ids);
        if ids.len() > MANY_NEAR {
            rayon::slice::ParallelSliceMut::par_sort_unstable(&mut ids[..]);
        } else {
            ids.sort_unstable();
        }
        ids.dedup();
        Some(ids)
    }

    /// The winding number of the grid point `q` displaced by
    /// `(ε³, ε, ε²)` (see the crate docs): 1 inside, 0 outside; exact, and
    /// for a point not on the surface its own winding number.
    pub fn winding(&self, q: GridPoint) -> i32 {
        let q = q.map(i64::from);
        let Some(index) = self.query_index() else {
            let faces = &self.faces;
            let sums = par::fold_runs(faces.len(), |r| {
                faces[r]
                    .iter()
                    .filter_map(Option::as_ref)
                    .map(|f| ray_crossing(q, f))
                    .sum::<i32>()
            });
            return sums.into_iter().sum();
        };
        let mut ids = Vec::new();
        index.along_x(q, &mut ids);
        ids.sort_unstable();
        ids.dedup();
        ids.iter()
            .filter_map(|&i| self.faces[i as usize].as_ref())
            .map(|f| ray_crossing(q, f))
            .sum()
    }

    /// [`Solid::winding`] of each of `qs`: for a few points and no index,
    /// in one pass over the faces.
    pub(crate) fn windings(&self, qs: &[GridPoint]) -> Vec<i32> {
        if self.index.get().is_some() || qs.len() > FEW_WINDINGS {
            return par::map_slice(qs, |&q| self.winding(q));
        }
        let qs: Vec<[i64; 3]> = qs.iter().map(|q| q.map(i64::from)).collect();
        let faces = &self.faces;
        let parts = par::fold_runs(faces.len(), |r| {
            let mut sums = vec![0i32; qs.len()];
            for f in faces[r].iter().filter_map(Option::as_ref) {
                let bx = f.bx();
                for (s, &q) in sums.iter_mut().zip(&qs) {
                    if ray_reaches(q, &bx) {
                        *s += winding::crossing(q, f);
                    }
                }
            }
            sums
        });
        let mut total = vec![0i32; qs.len()];
        for p in parts {
            total.iter_mut().zip(p).for_each(|(x, y)| *x += y);
        }
        total
    }

    /// Exact membership of a grid point.
    pub fn classify_point(&self, q: GridPoint) -> Membership {
        let p = q.map(i64::from);
        for i in self.faces_near(&(p, p)) {
            let f = self.face(i);
            if f.support().classify_grid(q) == Side::On
                && (0..f.corner_count()).all(|e| f.edge_plane(e).classify_grid(q) != Side::Front)
            {
                return Membership::Boundary;
            }
        }
        if self.winding(q) == 0 {
            Membership::Outside
        } else {
            Membership::Inside
        }
    }
}

/// The crossing number of the ray from `q` along `+x` (displaced as
/// [`Solid::winding`] says) with the face `f`: 0 where the face's box is
/// beyond the ray's reach.
fn ray_crossing(q: [i64; 3], f: &SolidFace) -> i32 {
    if ray_reaches(q, &f.bx()) {
        winding::crossing(q, f)
    } else {
        0
    }
}

/// Whether the ray from `q` along `+x` may meet a face in the box `bx`.
#[inline]
fn ray_reaches(q: [i64; 3], bx: &IBox) -> bool {
    bx.1[0] >= q[0] && bx.0[1] <= q[1] && q[1] <= bx.1[1] && bx.0[2] <= q[2] && q[2] <= bx.1[2]
}

/// At most this many winding numbers are found in one pass over a
/// solid's faces that has no index ([`Solid::windings`]).
const FEW_WINDINGS: usize = 64;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{MeshIn, snap};
    use bsp_core::BoolOp;

    /// A solid answers its queries the same before it has an index (by
    /// reading every face), while the index is made after a few queries,
    /// and with it: the faces near boxes, winding numbers one by one and
    /// in one pass, and membership. A solid an operation changed in place
    /// has its index.
    #[test]
    fn queries_agree_with_and_without_the_index() {
        let (pos, faces) = bsp_fixtures::uv_sphere(6_000);
        let snapped = snap(&[MeshIn::new(&pos, &faces)]).unwrap();
        let fresh = snapped.solids[0].clone();
        assert!(fresh.index.get().is_none());
        let mut indexed = fresh.clone();
        indexed.reindex();
        let (lo, hi) = fresh.bounds.unwrap();
        let at = |t: [i64; 3]| [0, 1, 2].map(|k| (lo[k] + (hi[k] - lo[k]) * t[k] / 8) as i32);
        let points: Vec<GridPoint> = (0..9 * 9 * 9)
            .map(|i| at([i % 9, i / 9 % 9, i / 81]))
            .collect();
        let boxes: Vec<IBox> = points
            .iter()
            .zip(points.iter().rev())
            .map(|(p, q)| {
                let lo = [0, 1, 2].map(|k| p[k].min(q[k]) as i64);
                let hi = [0, 1, 2].map(|k| p[k].max(q[k]) as i64);
                (lo, hi)
            })
            .step_by(37)
            .collect();
        // one pass, then point by point (which makes the index as it goes)
        let lazy = fresh.clone();
        let few: Vec<GridPoint> = points.iter().copied().step_by(12).collect();
        assert!(few.len() <= FEW_WINDINGS);
        let want = indexed.windings(&few);
        assert!(want.iter().any(|&w| w != 0) && want.contains(&0));
        assert_eq!(lazy.windings(&few), want);
        let mut inside = 0;
        for &q in &points {
            let w = indexed.winding(q);
            assert_eq!(lazy.winding(q), w, "{q:?}");
            assert_eq!(fresh.clone().classify_point(q), indexed.classify_point(q));
            inside += (w != 0) as usize;
        }
        assert!(inside > 50 && inside < points.len() - 50, "{inside}");
        assert!(lazy.index.get().is_some());
        for bx in &boxes {
            assert_eq!(fresh.clone().faces_near(bx), indexed.faces_near(bx));
            assert_eq!(fresh.clone().near_span(bx), indexed.near_span(bx));
        }
        // an operation carried out leaves an index
        let mut a = fresh.clone();
        let mut b = fresh.clone();
        b.apply(&a.clone(), BoolOp::Union).unwrap();
        a.apply(&indexed, BoolOp::Intersection).unwrap();
        assert!(a.index.get().is_some() && b.index.get().is_some());
    }
}
