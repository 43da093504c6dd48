//! Exact winding numbers of grid points, by a ray along `+x` with
//! simulation of simplicity.
//!
//! The point `q` is displaced symbolically to `q_ε = q + (ε³, ε, ε²)` for
//! an infinitesimal `ε > 0`, so that it lies on no plane and the ray from
//! it along `+x` meets no edge or vertex: every decision below is the sign
//! of a polynomial in `ε`, that is, of its first non-zero coefficient, and
//! none of those polynomials is zero. Only the faces' planes are used (the
//! support plane and the edge planes of a plane-based convex polygon), so
//! faces with implicit vertices — the pieces of earlier operations — are
//! handled the same way. With the `i128` values below `2^86` and their
//! products in 256 bits, everything is exact.
//!
//! For a face with support `P` (normal `n`, `n · p + d`) and the ray
//! `q_ε + t x̂`:
//!
//! - if `n_x = 0` the ray is parallel to `P` and, `q_ε` being off every
//!   plane, never meets it;
//! - `P(q_ε) = P(q) + n_y ε + n_z ε² + n_x ε³`, and the ray meets the plane
//!   ahead (`t = −P(q_ε) / n_x > 0`) when `P(q_ε)` and `n_x` have opposite
//!   signs;
//! - the meeting point `h` is inside the face when every edge plane `E` has
//!   `E(h) < 0`; `n_x E(h) = [n_x E(q) − e_x P(q)] + ε [n_x e_y − e_x n_y] +
//!   ε² [n_x e_z − e_x n_z]` (the `ε³` terms cancel), whose coefficients
//!   vanish together only for an edge plane parallel to the support, which
//!   a face does not have.
//!
//! A crossing counts `+1` where the ray leaves the solid (`n_x > 0`: from
//! behind the outward face to its front) and `−1` where it enters, so the
//! winding number of a point inside a closed, outward-oriented surface is
//! 1 and outside 0.

use bsp_core::internals::ConvexFace;
use bsp_core::{I256, Plane};

/// The sign of the first non-zero value.
fn first_sign(values: &[i128]) -> i32 {
    values
        .iter()
        .find(|&&v| v != 0)
        .map_or(0, |v| v.signum() as i32)
}

fn eval(p: &Plane, q: [i64; 3]) -> i128 {
    let n = p.normal();
    n[0] as i128 * q[0] as i128
        + n[1] as i128 * q[1] as i128
        + n[2] as i128 * q[2] as i128
        + p.offset()
}

/// `+1`, `−1` or `0`: how the ray from `q_ε` along `+x` crosses `face`.
pub(super) fn crossing(q: [i64; 3], face: &impl ConvexFace) -> i32 {
    let s = face.support();
    let n = s.normal();
    if n[0] == 0 {
        return 0;
    }
    let ps = eval(s, q);
    let side = first_sign(&[ps, n[1] as i128, n[2] as i128, n[0] as i128]);
    let nx = n[0].signum() as i32;
    if side == nx {
        return 0; // the plane is behind the ray's start
    }
    for i in 0..face.corner_count() {
        let e = &face.edge_plane(i);
        let m = e.normal();
        // n_x E(q) − e_x P(q), in 256 bits
        let c0 = I256::from(n[0]) * I256::from(eval(e, q)) - I256::from(m[0]) * I256::from(ps);
        let s0 = if c0.is_zero() {
            let c1 = n[0] as i128 * m[1] as i128 - m[0] as i128 * n[1] as i128;
            let c2 = n[0] as i128 * m[2] as i128 - m[0] as i128 * n[2] as i128;
            first_sign(&[c1, c2])
        } else if c0.is_negative() {
            -1
        } else {
            1
        };
        debug_assert!(s0 != 0, "an edge plane parallel to its support");
        // E(h) = (n_x E(h)) / n_x: outside this edge when positive
        if s0 * nx > 0 {
            return 0;
        }
    }
    nx
}

#[cfg(test)]
mod tests {
    use super::*;
    use bsp_core::Polygon;

    fn winding<'a>(q: [i64; 3], faces: impl IntoIterator<Item = &'a Polygon>) -> i32 {
        faces.into_iter().map(|f| crossing(q, f)).sum()
    }

    fn cube(lo: i32, hi: i32) -> Vec<Polygon> {
        bsp_fixtures::grid_cuboid([lo; 3], [hi; 3])
            .iter()
            .map(|q| Polygon::from_grid_points(q, 0).unwrap())
            .collect()
    }

    #[test]
    fn inside_outside_and_on_the_surface() {
        let c = cube(0, 4);
        assert_eq!(winding([1, 2, 3], &c), 1);
        assert_eq!(winding([5, 2, 3], &c), 0);
        assert_eq!(winding([-1, 2, 3], &c), 0);
        // on faces, edges and corners the displaced point decides, and
        // consistently: it lies just beyond (x, y, z) by (ε³, ε, ε²)
        assert_eq!(winding([0, 2, 2], &c), 1); // on the face x = 0
        assert_eq!(winding([4, 2, 2], &c), 0); // on the face x = 4
        assert_eq!(winding([2, 4, 2], &c), 0); // y = 4: beyond
        assert_eq!(winding([2, 0, 2], &c), 1); // y = 0: inside
        assert_eq!(winding([0, 0, 0], &c), 1); // the corner, displaced inward
        assert_eq!(winding([4, 4, 4], &c), 0);
        // lined up with edges of the far faces
        assert_eq!(winding([-3, 0, 0], &c), 0);
        assert_eq!(winding([-3, 0, 4], &c), 0);
        assert_eq!(winding([-3, 3, 4], &c), 0);
        assert_eq!(winding([-3, 3, 3], &c), 0);
        assert_eq!(winding([2, 3, 3], &c), 1);
    }
}
