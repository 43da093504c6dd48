//! Byte decoding: a reader that reads zeros once the data runs out, and the decoders of points and polygons.

#[allow(unused_imports)]
use super::*;

/// A byte reader that reads zeros once the data runs out.
pub(crate) struct Bytes<'a> {
    pub(crate) data: &'a [u8],
}

impl Bytes<'_> {
    pub(crate) fn u8(&mut self) -> u8 {
        match self.data.split_first() {
            Some((&b, rest)) => {
                self.data = rest;
                b
            }
            None => 0,
        }
    }
    pub(crate) fn u16(&mut self) -> u16 {
        u16::from_le_bytes([self.u8(), self.u8()])
    }
    pub(crate) fn u32(&mut self) -> u32 {
        u32::from_le_bytes([self.u8(), self.u8(), self.u8(), self.u8()])
    }
    pub(crate) fn u64(&mut self) -> u64 {
        let lo = self.u32() as u64;
        lo | (self.u32() as u64) << 32
    }
    /// A value in `0..n`, `1 <= n <= 256`.
    pub(crate) fn below(&mut self, n: usize) -> usize {
        self.u8() as usize % n
    }
    /// A grid coordinate, biased to small values, powers of two and the
    /// limits of the grid.
    pub(crate) fn coord(&mut self) -> i32 {
        let v: i64 = match self.u8() % 8 {
            0 | 1 => self.u8() as i8 as i64,
            2 => (self.u8() % 8) as i64,
            3 => self.u16() as i16 as i64,
            4 => {
                let s = (self.u8() % 64) as i64;
                if self.u8() & 1 == 0 { M - s } else { s - M }
            }
            5 => (self.u32() as i64).rem_euclid(2 * M + 1) - M,
            6 => {
                let e = self.u8() % 26;
                let d = (self.u8() as i8 % 4) as i64;
                let v = (1i64 << e) + d;
                if self.u8() & 1 == 0 { v } else { -v }
            }
            _ => 0,
        };
        clamp_coord(v)
    }
    /// A grid point: fresh, or a repeat, a neighbour or a collinear
    /// extension of points in `pool`.
    pub(crate) fn point(&mut self, pool: &[GridPoint]) -> GridPoint {
        let mode = self.u8() % 8;
        if !pool.is_empty() && (4..=6).contains(&mode) {
            let a = pool[self.below(pool.len())];
            match mode {
                4 => return a,
                5 => {
                    let d = [self.u8(), self.u8(), self.u8()];
                    return [0, 1, 2].map(|k| clamp_coord(a[k] as i64 + (d[k] % 3) as i64 - 1));
                }
                _ => {
                    let b = pool[self.below(pool.len())];
                    return if self.u8() & 1 == 0 {
                        // floor of the midpoint: on the segment when the sum is even
                        [0, 1, 2].map(|k| clamp_coord((a[k] as i64 + b[k] as i64).div_euclid(2)))
                    } else {
                        // beyond b on the line through a and b
                        [0, 1, 2].map(|k| clamp_coord(2 * b[k] as i64 - a[k] as i64))
                    };
                }
            }
        }
        [self.coord(), self.coord(), self.coord()]
    }
    /// A small vector for templates and translations.
    pub(crate) fn vector(&mut self) -> [i64; 3] {
        match self.u8() % 4 {
            0 => [0, 1, 2].map(|_| self.u8() as i8 as i64),
            1 => [0, 1, 2].map(|_| self.u16() as i16 as i64),
            2 => {
                let axis = self.below(3);
                let len = self.u32() as i64 % (2 * M) - M;
                let mut v = [0; 3];
                v[axis] = len;
                v
            }
            _ => [0, 1, 2].map(|_| (self.u32() as i64).rem_euclid(2 * M + 1) - M),
        }
    }
}

pub(crate) fn clamp_coord(v: i64) -> i32 {
    v.clamp(-M, M) as i32
}

pub(crate) fn in_grid(p: [i64; 3]) -> Option<GridPoint> {
    p.iter().all(|c| c.abs() <= M).then(|| p.map(|c| c as i32))
}

/// Convex (and a few deliberately degenerate) outlines in 2D template
/// coordinates, counter-clockwise.
pub(crate) const TEMPLATES: &[&[(i64, i64)]] = &[
    &[(0, 0), (1, 0), (0, 1)],
    &[(0, 0), (1, 0), (1, 1), (0, 1)],
    &[(1, 0), (2, 0), (3, 1), (2, 2), (1, 2), (0, 1)],
    // a collinear vertex
    &[(0, 0), (1, 0), (2, 0), (2, 1), (0, 1)],
    // repeated vertices
    &[(0, 0), (1, 0), (1, 0), (1, 1), (0, 1), (0, 0)],
    // a sliver of area 1/2
    &[(0, 0), (1000, 1), (999, 1)],
    // a spike folding back on itself
    &[(0, 0), (2, 0), (1, 0), (1, 1)],
    // not convex
    &[(0, 0), (2, 0), (1, 1), (2, 2), (0, 2)],
];

/// A planar outline `o + a u + b v` from a template, translated to fit the
/// grid; `None` if it cannot fit.
pub(crate) fn template_polygon(b: &mut Bytes<'_>, pool: &[GridPoint]) -> Option<Vec<GridPoint>> {
    let t = TEMPLATES[b.below(TEMPLATES.len())];
    let reverse = b.u8() & 1 == 1;
    let o = b.point(pool).map(|c| c as i64);
    let (u, v) = (b.vector(), b.vector());
    let offs: Vec<[i64; 3]> = t
        .iter()
        .map(|&(x, y)| [0, 1, 2].map(|k| x * u[k] + y * v[k]))
        .collect();
    let mut o2 = o;
    for k in 0..3 {
        let lo = offs.iter().map(|p| p[k]).min().unwrap_or(0);
        let hi = offs.iter().map(|p| p[k]).max().unwrap_or(0);
        if hi - lo > 2 * M {
            return None;
        }
        o2[k] = o[k].clamp(-M - lo, M - hi);
    }
    let mut pts: Vec<GridPoint> = offs
        .iter()
        .map(|p| in_grid([0, 1, 2].map(|k| o2[k] + p[k])))
        .collect::<Option<_>>()?;
    if reverse {
        pts.reverse();
    }
    Some(pts)
}

/// Encoding of a fresh point with full-range coordinates (the inverse of
/// [`Bytes::point`] for any grid point).
pub(crate) fn enc_point(out: &mut Vec<u8>, p: GridPoint) {
    out.push(0);
    for c in p {
        out.push(5);
        out.extend(((c as i64 + M) as u32).to_le_bytes());
    }
}
