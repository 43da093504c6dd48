//! Areas in input units: per light, the area lit, in cast shadow (facing
//! the light but blocked) and in attached shadow (facing away), and per
//! face its area in cast shadow.
//!
//! Areas are plain `f64`, from the correctly rounded fragment vertices
//! mapped to input units; the fragments themselves are exact.

use bsp_core::Grid;
use glam::DVec3;

use crate::engine::FragmentRef;

/// The area of a planar polygon (any orientation).
///
/// Half the length of the sum of the fan's cross products. Where that
/// length's square is not a normal `f64` (a polygon larger than about
/// 1e77 or smaller than about 1e-77: the square is the fourth power of the
/// size), it is computed at unit scale: the corners' offsets from the
/// first are scaled by a power of two that brings the largest to about 1,
/// and the area scaled back. A power of two scales every step exactly, so
/// both ways give the same bits wherever the plain one neither overflows
/// nor underflows.
///
/// ```
/// use glam::DVec3;
/// // (powers of two: every step exact; the tiny and huge ones at unit scale)
/// for e in [2f64.powi(-500), 1.0, 2f64.powi(500)] {
///     let tri = [DVec3::ZERO, DVec3::new(e, 0.0, 0.0), DVec3::new(0.0, e, 0.0)];
///     assert_eq!(svbsp::polygon_area(&tri), 0.5 * e * e);
/// }
/// ```
pub fn polygon_area(pts: &[DVec3]) -> f64 {
    let Some(&o) = pts.first() else {
        return 0.0;
    };
    // at unit scale or near it, the formula as it stands (the scaled one's
    // bits, for less): a normal squared length neither overflowed nor
    // lost its digits
    let mut n = DVec3::ZERO;
    for w in pts[1..].windows(2) {
        n += (w[0] - o).cross(w[1] - o);
    }
    let square = n.length_squared();
    if square.is_normal() {
        return 0.5 * square.sqrt();
    }
    let largest = pts
        .iter()
        .map(|&p| (p - o).abs().max_element())
        .fold(0.0, f64::max);
    // (no scale for no size, and none for a corner not finite)
    let e = match largest {
        0.0 => return 0.0,
        l if l.is_finite() => l.log2().floor() as i32,
        _ => 0,
    };
    // 2^-e brings the largest offset into [1/2, 4); applied in two halves,
    // each a normal number, so that it reaches subnormal sizes too
    let (a, b) = (-e / 2, -e - (-e / 2));
    let (sa, sb) = (2f64.powi(a), 2f64.powi(b));
    let mut n = DVec3::ZERO;
    for w in pts[1..].windows(2) {
        n += ((w[0] - o) * sa * sb).cross((w[1] - o) * sa * sb);
    }
    // the area scales back by 2^(2e), in four normal factors
    let back = [2f64.powi(-a), 2f64.powi(-b)];
    0.5 * n.length() * back[0] * back[0] * back[1] * back[1]
}

/// A fragment's area in input units: its outer ring's less its holes'.
pub fn fragment_area(f: &FragmentRef<'_>, grid: &Grid, buf: &mut Vec<DVec3>) -> f64 {
    let mut area = 0.0;
    for (k, ring) in f.rings().enumerate() {
        buf.clear();
        buf.extend(ring.iter().map(|&v| grid.to_world(f.batch().rounded(v))));
        let a = polygon_area(buf);
        area += if k == 0 { a } else { -a };
    }
    area
}

/// Area totals, per light and per face.
#[derive(Clone, Debug, PartialEq)]
pub struct Areas {
    lights: usize,
    /// Total area of every fragment (each face once).
    pub total: f64,
    /// Per light: lit by it.
    pub lit: Vec<f64>,
    /// Per light: facing it but blocked.
    pub cast: Vec<f64>,
    /// Per light: facing away from it (or edge-on).
    pub attached: Vec<f64>,
    /// Lit by no light.
    pub dark: f64,
    face_area: Vec<f64>,
    /// `faces × lights`: area in cast shadow.
    face_cast: Vec<f64>,
}

impl Areas {
    /// Zero areas for `lights` lights and `faces` faces.
    pub fn new(lights: usize, faces: usize) -> Areas {
        Areas {
            lights,
            total: 0.0,
            lit: vec![0.0; lights],
            cast: vec![0.0; lights],
            attached: vec![0.0; lights],
            dark: 0.0,
            face_area: vec![0.0; faces],
            face_cast: vec![0.0; faces * lights],
        }
    }

    /// Adds a fragment of `face` with area `area`, lit by the lights of
    /// `lit` (bit `i`: light `i`), whose face has the lights of `facing`
    /// strictly in front.
    pub fn add(&mut self, face: u32, area: f64, lit: u64, facing: u64) {
        let f = face as usize;
        self.total += area;
        self.face_area[f] += area;
        for i in 0..self.lights {
            if lit >> i & 1 == 1 {
                self.lit[i] += area;
            } else if facing >> i & 1 == 1 {
                self.cast[i] += area;
                self.face_cast[f * self.lights + i] += area;
            } else {
                self.attached[i] += area;
            }
        }
        if lit == 0 {
            self.dark += area;
        }
    }

    /// Per light: the area in shadow, cast or attached.
    pub fn shadow(&self) -> Vec<f64> {
        self.cast
            .iter()
            .zip(&self.attached)
            .map(|(c, a)| c + a)
            .collect()
    }

    /// The area of face `f`.
    pub fn face_area(&self, f: usize) -> f64 {
        self.face_area[f]
    }

    /// Face `f`'s area in cast shadow of each light.
    pub fn face_cast(&self, f: usize) -> &[f64] {
        &self.face_cast[f * self.lights..(f + 1) * self.lights]
    }

    /// Up to `n` faces with cast shadow, most shadow (summed over the
    /// lights) first, ties by index.
    pub fn most_shaded(&self, n: usize) -> Vec<usize> {
        let sum = |f: usize| self.face_cast(f).iter().sum::<f64>();
        let mut faces: Vec<usize> = (0..self.face_area.len())
            .filter(|&f| sum(f) > 0.0)
            .collect();
        faces.sort_by(|&a, &b| sum(b).total_cmp(&sum(a)).then(a.cmp(&b)));
        faces.truncate(n);
        faces
    }

    /// The area report: the total, each light's lit, cast and attached
    /// shares (and the area no light reaches, with several), then a table
    /// of the `top` faces with the most cast shadow, each face named by
    /// `group` (its group or material).
    pub fn report(&self, top: usize, group: impl Fn(usize) -> String) -> String {
        use std::fmt::Write;
        let total = self.total;
        let mut s =
            format!("area:            {total:.6} units² (every face once, its front side)\n");
        for i in 0..self.lights {
            let (lit, cast, att) = (self.lit[i], self.cast[i], self.attached[i]);
            let _ = writeln!(
                s,
                "light {i} area:    lit {lit:.6} ({:.1}%), in shadow {:.6} ({:.1}%): cast \
                 {cast:.6} ({:.1}%), facing away {att:.6} ({:.1}%)",
                percent(lit, total),
                total - lit,
                percent(total - lit, total),
                percent(cast, total),
                percent(att, total),
            );
        }
        if self.lights > 1 {
            let dark = self.dark;
            let _ = writeln!(
                s,
                "no light:        {dark:.6} ({:.1}%)",
                percent(dark, total)
            );
        }
        let faces = self.most_shaded(top);
        if faces.is_empty() {
            s += "cast shadow:     none\n";
            return s;
        }
        s += "faces with the most cast shadow (area in shadow while facing the light, % of the face):\n";
        let _ = write!(s, "  {:>7}  {:<12} {:>12}", "face", "group", "area");
        for i in 0..self.lights {
            let _ = write!(s, "  {:>20}", format!("light {i} shadow"));
        }
        s.push('\n');
        for f in faces {
            let area = self.face_area(f);
            let _ = write!(s, "  {f:>7}  {:<12} {area:>12.6}", group(f));
            for c in self.face_cast(f) {
                let _ = write!(s, "  {:>20}", format!("{c:.6} ({:.1}%)", percent(*c, area)));
            }
            s.push('\n');
        }
        s
    }
}

/// `part` as a percentage of `whole` (0 when `whole` is not positive).
pub fn percent(part: f64, whole: f64) -> f64 {
    if whole > 0.0 {
        100.0 * part / whole
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn areas_split_lit_cast_and_attached() {
        let mut a = Areas::new(2, 3);
        a.add(0, 2.0, 0b01, 0b11);
        a.add(0, 3.0, 0b00, 0b01);
        a.add(1, 5.0, 0b10, 0b10);
        assert_eq!(a.total, 10.0);
        assert_eq!(a.lit, vec![2.0, 5.0]);
        assert_eq!(a.cast, vec![3.0, 2.0]);
        assert_eq!(a.attached, vec![5.0, 3.0]);
        assert_eq!(a.shadow(), vec![8.0, 5.0]);
        assert_eq!(a.dark, 3.0);
        assert_eq!((a.face_area(0), a.face_cast(0)), (5.0, &[3.0, 2.0][..]));
        assert_eq!((a.face_area(1), a.face_cast(1)), (5.0, &[0.0, 0.0][..]));
        assert_eq!(a.face_area(2), 0.0);
        assert_eq!(a.most_shaded(10), vec![0]);
    }

    #[test]
    fn polygon_areas() {
        let sq = [
            DVec3::new(1.0, 1.0, 5.0),
            DVec3::new(3.0, 1.0, 5.0),
            DVec3::new(3.0, 4.0, 5.0),
            DVec3::new(1.0, 4.0, 5.0),
        ];
        assert_eq!(polygon_area(&sq), 6.0);
        assert_eq!(polygon_area(&sq[..2]), 0.0);
        assert_eq!(polygon_area(&[]), 0.0);
    }
}
