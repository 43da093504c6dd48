//! The lighting model of every picture the workspace draws, PNG or SVG:
//! Lambert's cosine law over an ambient term that is a little stronger on
//! surfaces facing the viewer.
//!
//! A surface with unit normal `n`, seen along `v` (from the surface
//! toward the viewer), lit by lights in directions `lᵢ` (from the surface
//! toward each light) with weights `wᵢ`, has the brightness
//! `ambient + facing · max(0, n·v) + Σ wᵢ · max(0, n·lᵢ)`, the terms added
//! in that order; its colour is its base colour times the brightness.
//! Each term is one call here, so every picture computes it with the same
//! operations in the same order.

use glam::DVec3;

/// The ambient part of the model; the lights' part is [`Lambert::cosine`]
/// with weights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lambert {
    /// Light reaching every surface: nothing is darker.
    pub ambient: f64,
    /// More ambient light on surfaces facing the viewer, so that a surface
    /// no light reaches keeps its shape.
    pub facing: f64,
}

impl Lambert {
    /// Pictures of shadows: the lights share [`Lambert::DIFFUSE`]
    /// equally ([`Lambert::weight`]).
    pub const SHADOWS: Lambert = Lambert {
        ambient: 0.28,
        facing: 0.12,
    };

    /// Pictures without shadows (the painter's-algorithm views): a key
    /// light from the upper left behind the viewer and a weak light at
    /// the eye, in [`crate::svg`].
    pub const VIEW: Lambert = Lambert {
        ambient: 0.38,
        facing: 0.0,
    };

    /// The diffuse light shared by the lights of a picture of shadows.
    pub const DIFFUSE: f64 = 0.72;

    /// Each light's weight when `lights` share [`Lambert::DIFFUSE`].
    #[inline]
    pub fn weight(lights: usize) -> f64 {
        Lambert::DIFFUSE / lights.max(1) as f64
    }

    /// The ambient term of a surface with unit normal `normal` seen along
    /// `to_viewer` (unit, from the surface toward the viewer).
    #[inline]
    pub fn base(&self, normal: DVec3, to_viewer: DVec3) -> f64 {
        self.ambient + self.facing * normal.dot(to_viewer).max(0.0)
    }

    /// A light's term: `weight · max(0, n·l)`, `to_light` the unit
    /// direction from the surface toward the light.
    #[inline]
    pub fn cosine(weight: f64, normal: DVec3, to_light: DVec3) -> f64 {
        weight * normal.dot(to_light).max(0.0)
    }
}

/// The affine function `g · p + d` (`[g, d]`) of the points `p` of a
/// planar convex polygon (`corners`, input units) nearest, by least
/// squares, to `values` at its corners: the share of a light across a
/// penumbra fragment, for the picture (`f64`). `None` for fewer than three
/// corners, or corners that span no area.
pub fn affine_fit(corners: &[DVec3], values: &[f64]) -> Option<[f64; 4]> {
    if corners.len() < 3 || corners.len() != values.len() {
        return None;
    }
    let o = corners[0];
    let u = (corners[1] - o).normalize_or_zero();
    let normal = corners
        .windows(2)
        .map(|w| (w[0] - o).cross(w[1] - o))
        .sum::<DVec3>();
    let v = normal.cross(u).normalize_or_zero();
    // normal equations of s = a·u + b·v + c over the corners
    let mut m = [[0.0f64; 3]; 3];
    let mut r = [0.0f64; 3];
    for (&p, &s) in corners.iter().zip(values) {
        let x = [(p - o).dot(u), (p - o).dot(v), 1.0];
        for i in 0..3 {
            for k in 0..3 {
                m[i][k] += x[i] * x[k];
            }
            r[i] += x[i] * s;
        }
    }
    let m = glam::DMat3::from_cols_array_2d(&m);
    if m.determinant() == 0.0 {
        return None;
    }
    let [a, b, c] = (m.inverse() * DVec3::from_array(r)).to_array();
    let g = u * a + v * b;
    let out = [g.x, g.y, g.z, c - g.dot(o)];
    out.iter().all(|x| x.is_finite()).then_some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_terms_add_up() {
        let n = DVec3::Z;
        let m = Lambert::SHADOWS;
        assert_eq!(m.base(n, DVec3::Z), 0.28 + 0.12);
        assert_eq!(m.base(n, -DVec3::Z), 0.28);
        assert_eq!(Lambert::weight(0), 0.72);
        assert_eq!(Lambert::weight(2), 0.36);
        assert_eq!(Lambert::cosine(0.5, n, DVec3::Z), 0.5);
        assert_eq!(Lambert::cosine(0.5, n, -DVec3::Z), 0.0);
        // the view's ambient term is exactly its constant
        assert_eq!(Lambert::VIEW.base(n, DVec3::Z), 0.38);
    }

    /// Values of an affine function at a polygon's corners come back as
    /// that function; a triangle's three values are met exactly.
    #[test]
    fn ramps_fit_the_corners() {
        let f = |p: DVec3| 0.3 + 0.1 * p.x - 0.05 * p.y + 0.02 * p.z;
        let quad = [
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(2.0, 0.0, 1.5),
            DVec3::new(2.0, 1.0, 1.5),
            DVec3::new(0.0, 1.0, 1.0),
        ];
        let values: Vec<f64> = quad.iter().map(|&p| f(p)).collect();
        let [gx, gy, gz, d] = affine_fit(&quad, &values).unwrap();
        let g = |p: DVec3| gx * p.x + gy * p.y + gz * p.z + d;
        for &p in &quad {
            assert!((g(p) - f(p)).abs() < 1e-12, "{} against {}", g(p), f(p));
        }
        let tri = &quad[..3];
        let [gx, gy, gz, d] = affine_fit(tri, &[0.0, 1.0, 0.25]).unwrap();
        let got: Vec<f64> = tri
            .iter()
            .map(|p| gx * p.x + gy * p.y + gz * p.z + d)
            .collect();
        for (a, b) in got.iter().zip([0.0, 1.0, 0.25]) {
            assert!((a - b).abs() < 1e-12, "{got:?}");
        }
        assert!(affine_fit(&quad[..2], &[0.0, 1.0]).is_none());
    }
}
