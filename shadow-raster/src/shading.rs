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
}
