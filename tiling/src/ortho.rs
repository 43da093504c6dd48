//! Suns: the same index on a plane across the light's direction.
//!
//! Points are projected along the sun's integer direction `s` onto the
//! coordinate plane most nearly across it (axis `a`, the largest `|s_a|`):
//! `(U, W) = (p_b s_a - s_b p_a, p_c s_a - s_c p_a)` with `b, c` the next
//! axes. That is an oblique parallel projection scaled by `s_a`: two
//! points share a projection exactly when the line along `s` through one
//! passes through the other, as with an orthographic view along `s`, and
//! every coordinate is an integer below `2^54`. The `N × N` tiles are
//! integer squares over the static scene's projected bounding box; a
//! projection beyond the box falls in the border tiles. A convex polygon's
//! projection is rasterized row by row from its edges' exact crossings of
//! the row lines (quotients below `2^110`), with a closed range of
//! coordinates meeting every tile it touches.

use crate::cube::{Span, ceil_div, floor_div};

/// The projection plane and its tiles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Frame {
    /// The sun's direction.
    s: [i128; 3],
    /// The axis projected away.
    a: usize,
    /// Lower corner of the tiled box, and the tile sizes.
    u0: i128,
    w0: i128,
    tu: i128,
    tw: i128,
    n: u32,
}

impl Frame {
    /// The frame of `dir` whose `n × n` tiles cover the projections of
    /// `points`.
    pub(crate) fn new(dir: [i32; 3], points: impl Iterator<Item = [i64; 3]>, n: u32) -> Frame {
        let s = dir.map(i128::from);
        let a = (0..3).max_by_key(|&k| s[k].abs()).unwrap_or(2);
        let mut f = Frame {
            s,
            a,
            u0: 0,
            w0: 0,
            tu: 1,
            tw: 1,
            n,
        };
        let (mut lo, mut hi) = ([i128::MAX; 2], [i128::MIN; 2]);
        for p in points {
            let q = f.project(p);
            for k in 0..2 {
                lo[k] = lo[k].min(q[k]);
                hi[k] = hi[k].max(q[k]);
            }
        }
        if lo[0] > hi[0] {
            lo = [0, 0];
            hi = [0, 0];
        }
        let ni = n as i128;
        f.u0 = lo[0];
        f.w0 = lo[1];
        // tiles at least one unit wide, covering [lo, hi] whole
        f.tu = ((hi[0] - lo[0]) / ni + 1).max(1);
        f.tw = ((hi[1] - lo[1]) / ni + 1).max(1);
        f
    }

    /// The projection of a grid point.
    pub(crate) fn project(&self, p: [i64; 3]) -> [i128; 2] {
        let (a, b, c) = (self.a, (self.a + 1) % 3, (self.a + 2) % 3);
        let p = p.map(i128::from);
        [
            p[b] * self.s[a] - self.s[b] * p[a],
            p[c] * self.s[a] - self.s[c] * p[a],
        ]
    }

    /// `ceil` and `floor` of the tile coordinate of `num / den` (`den > 0`)
    /// along axis `k` (0: columns, 1: rows).
    fn coord(&self, num: i128, den: i128, k: usize) -> (i128, i128) {
        let (o, t) = if k == 0 {
            (self.u0, self.tu)
        } else {
            (self.w0, self.tw)
        };
        let (num, den) = (num - o * den, den * t);
        (ceil_div(num, den), floor_div(num, den))
    }

    /// The tiles polygon `verts` (grid points in order, convex) meets, as
    /// row spans appended to `out`. Beyond the tiled box a projection is
    /// clamped to the border tiles.
    pub(crate) fn spans(&self, verts: &[[i64; 3]], out: &mut Vec<Span>) {
        let pts: Vec<[i128; 2]> = verts.iter().map(|&v| self.project(v)).collect();
        let Some(&first) = pts.first() else { return };
        let n = self.n;
        let clamp = |(lo, hi): (i128, i128)| {
            // a range beyond the box is clamped to its border tiles
            let (lo, hi) = ((lo - 1).clamp(0, n as i128 - 1), hi.clamp(0, n as i128 - 1));
            (lo as u32, hi.max(lo) as u32)
        };
        let (mut wl, mut wh) = (first[1], first[1]);
        for p in &pts {
            wl = wl.min(p[1]);
            wh = wh.max(p[1]);
        }
        let (r0, r1) = clamp((self.coord(wl, 1, 1).0, self.coord(wh, 1, 1).1));
        let k = pts.len();
        for row in r0..=r1 {
            // the row's band of W, extended to infinity at the border rows
            let b0 = if row == 0 {
                i128::MIN
            } else {
                self.w0 + row as i128 * self.tw
            };
            let b1 = if row == n - 1 {
                i128::MAX
            } else {
                self.w0 + (row as i128 + 1) * self.tw
            };
            let (mut lo, mut hi) = (i128::MAX, i128::MIN);
            let mut seen = false;
            let mut take = |num: i128, den: i128| {
                let (c, f) = self.coord(num, den, 0);
                lo = lo.min(c);
                hi = hi.max(f);
                seen = true;
            };
            for i in 0..k {
                let (p, q) = (pts[i], pts[(i + 1) % k]);
                if p[1] == q[1] {
                    if b0 <= p[1] && p[1] <= b1 {
                        take(p[0], 1);
                        take(q[0], 1);
                    }
                    continue;
                }
                let (wlo, whi) = (p[1].min(q[1]).max(b0), p[1].max(q[1]).min(b1));
                if wlo > whi {
                    continue;
                }
                // U at W on the edge: p_u + (W - p_w)(q_u - p_u) / (q_w - p_w)
                let (den0, du0) = (q[1] - p[1], q[0] - p[0]);
                for w in [wlo, whi] {
                    let (mut num, mut den) = (p[0] * den0 + (w - p[1]) * du0, den0);
                    if den < 0 {
                        num = -num;
                        den = -den;
                    }
                    take(num, den);
                }
            }
            if seen {
                let (c0, c1) = clamp((lo, hi));
                out.push(Span {
                    face: 0,
                    row,
                    lo: c0,
                    hi: c1,
                });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tiles(f: &Frame, verts: &[[i64; 3]]) -> Vec<(u32, u32)> {
        let mut out = Vec::new();
        f.spans(verts, &mut out);
        out.iter()
            .flat_map(|s| (s.lo..=s.hi).map(move |c| (s.row, c)))
            .collect()
    }

    #[test]
    fn straight_down_tiles_follow_x_and_y() {
        let box_pts = [[0, 0, 0], [8, 8, 0]];
        let f = Frame::new([0, 0, 1], box_pts.into_iter(), 4);
        // (U, W) = (x, y): tiles of width 8/4 + 1 = 3
        assert_eq!((f.tu, f.tw), (3, 3));
        let t = tiles(&f, &[[0, 0, 5], [2, 0, 5], [2, 2, 5], [0, 2, 5]]);
        assert_eq!(t, vec![(0, 0)]);
        // touching the line x = 3 lists both columns
        let t = tiles(&f, &[[1, 1, 0], [3, 1, 0], [3, 2, 0]]);
        assert_eq!(t, vec![(0, 0), (0, 1)]);
    }

    #[test]
    fn oblique_sun_projects_along_its_direction() {
        // a sun along (1, 0, 1): (U, W) = (x - z, y) (a = z, b = x, c = y)
        let f = Frame::new([1, 0, 1], [[0, 0, 0], [16, 16, 0]].into_iter(), 4);
        assert_eq!(f.project([5, 3, 2]), [3, 3]);
        assert_eq!(f.project([7, 3, 4]), [3, 3]);
    }
}
