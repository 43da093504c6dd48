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

/// Whether two boxes meet (touching counts).
pub(crate) fn overlap(a: &Box3, b: &Box3) -> bool {
    (0..3).all(|k| a[k][0] <= b[k][1] && b[k][0] <= a[k][1])
}

/// A box holding every point.
pub(crate) const EVERYWHERE: Box3 = [[i64::MIN, i64::MAX]; 3];

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
    const NONE: Box3 = [[i64::MAX, i64::MIN]; 3];

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
            *b = [0, 1, 2].map(|k| [b[k][0].min(x.bbox[k][0]), b[k][1].max(x.bbox[k][1])]);
        }
    }

    pub(crate) fn push(&mut self, x: Scan) {
        if self.items.len().is_multiple_of(Self::RUN) {
            self.runs.push(Self::NONE);
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
    }
}
