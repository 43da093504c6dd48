//! The volume a closed mesh encloses, exactly for its `f64` positions and
//! rounded once.

use num_bigint::{BigInt, BigUint, Sign};
use rayon::prelude::*;

use crate::Mesh;

/// The signed volume `mesh` encloses (positive for outward-facing faces),
/// each polygon fanned from its first corner: the exact sum of the fan
/// triangles' tetrahedra with the origin for the `f64` positions as given,
/// rounded once to the nearest `f64` (ties to even). Infinite if it is
/// beyond `f64`'s range; NaN if a position used by a face is not finite.
///
/// ```
/// use bsp_shadows::{DVec3, Mesh};
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../data/meshes/pyvista_sphere.obj");
/// let sphere = bsp_shadows::read_mesh(path)?;
/// let far = bsp_shadows::translated(&sphere, DVec3::splat(1e9));
/// // the same shape far away: the same volume, to the last bit
/// assert_eq!(bsp_shadows::volume(&sphere), bsp_shadows::volume(&far));
/// # Ok::<(), bsp_shadows::Error>(())
/// ```
pub fn volume(mesh: &Mesh) -> f64 {
    let used = mesh.faces.iter().flat_map(|f| &f.vertices);
    let mut least = i32::MAX;
    for &v in used {
        for x in mesh.positions[v as usize].to_array() {
            if !x.is_finite() {
                return f64::NAN;
            }
            if x != 0.0 {
                least = least.min(parts(x).1);
            }
        }
    }
    if least == i32::MAX {
        return 0.0;
    }
    // every coordinate an integer multiple of 2^least
    let whole = |x: f64| -> BigInt {
        let (m, e) = parts(x);
        BigInt::from(m) << (e - least) as usize
    };
    let six_volume: BigInt = (mesh.faces.par_iter())
        .map(|face| {
            let p: Vec<[BigInt; 3]> = (face.vertices.iter())
                .map(|&v| mesh.positions[v as usize].to_array().map(whole))
                .collect();
            let mut sum = BigInt::ZERO;
            for k in 1..p.len().saturating_sub(1) {
                sum += det(&p[0], &p[k], &p[k + 1]);
            }
            sum
        })
        .sum();
    let (sign, n) = six_volume.into_parts();
    let magnitude = round_ratio(&n, 6, 3 * i64::from(least));
    if sign == Sign::Minus {
        -magnitude
    } else {
        magnitude
    }
}

/// `x = m · 2^e` with `m` an integer.
fn parts(x: f64) -> (i64, i32) {
    let bits = x.to_bits();
    let exp = ((bits >> 52) & 0x7ff) as i32;
    let frac = (bits & ((1 << 52) - 1)) as i64;
    let m = if exp == 0 { frac } else { frac | 1 << 52 };
    let e = if exp == 0 { -1074 } else { exp - 1075 };
    (if x < 0.0 { -m } else { m }, e)
}

fn det(a: &[BigInt; 3], b: &[BigInt; 3], c: &[BigInt; 3]) -> BigInt {
    &a[0] * (&b[1] * &c[2] - &b[2] * &c[1]) - &a[1] * (&b[0] * &c[2] - &b[2] * &c[0])
        + &a[2] * (&b[0] * &c[1] - &b[1] * &c[0])
}

/// `n / d · 2^e` rounded to the nearest `f64`, ties to even.
fn round_ratio(n: &BigUint, d: u32, e: i64) -> f64 {
    if n.bits() == 0 {
        return 0.0;
    }
    // a quotient of at least 56 bits, and whether anything was left over
    let t = 58 + i64::from(d.ilog2()) - n.bits() as i64;
    let num = n << t.max(0) as usize;
    let den = BigUint::from(d) << (-t).max(0) as usize;
    let (q, sticky) = (&num / &den, &num % &den != BigUint::ZERO);
    let len = q.bits() as i64;
    // the value's binary exponent, and the bits to drop for 53 (fewer
    // below the normal range)
    let top = len - 1 + e - t;
    let drop = (len - 53 + (-1022 - top).max(0)).min(len + 1);
    let (mut m, rest_half, rest_more) = if drop <= 0 {
        (q.clone(), false, false)
    } else {
        let d = drop as u64;
        let low = &q & ((BigUint::from(1u8) << d) - 1u8);
        let half = BigUint::from(1u8) << (d - 1);
        (&q >> d, low >= half, low > half || (low == half && sticky))
    };
    let odd = m.bit(0);
    if rest_more || (rest_half && odd) {
        m += 1u8;
    }
    let m = u64::try_from(&m).expect("at most 54 bits") as f64;
    let k = e - t + drop.max(0);
    if k > 2100 {
        return f64::INFINITY;
    }
    let k = k.max(-2200) as i32;
    // m · 2^k in two exact steps
    m * 2f64.powi(k / 2) * 2f64.powi(k - k / 2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;
    use num_traits::ToPrimitive;

    fn cube(lo: DVec3, size: f64) -> Mesh {
        crate::art::cone::cuboid([lo, lo + DVec3::splat(size)])
    }

    #[test]
    fn cubes_far_and_tiny() {
        assert_eq!(volume(&cube(DVec3::ZERO, 1.0)), 1.0);
        assert_eq!(volume(&cube(DVec3::splat(-0.5), 3.0)), 27.0);
        // far from the origin, where the f64 sum of tetrahedra is off
        let lo = DVec3::new(1e12, -3e11, 7e10);
        let far = cube(lo, 0.1);
        // the sides as stored (exact differences of few bits each)
        let side = far.positions[7] - lo;
        assert_eq!(volume(&far), side.x * side.y * side.z);
        assert_ne!(far.signed_volume(), volume(&far));
        // inside out: the negative
        let mut inside = cube(DVec3::ZERO, 2.0);
        inside.faces.iter_mut().for_each(|f| f.vertices.reverse());
        assert_eq!(volume(&inside), -8.0);
        // tiny: below f64's normal range, rounded once
        let tiny = cube(DVec3::ZERO, 2f64.powi(-400));
        assert_eq!(volume(&tiny), 0.0); // 2^-1200 rounds to zero
        let small = cube(DVec3::ZERO, 2f64.powi(-358));
        assert_eq!(volume(&small), 2f64.powi(-1074));
        let big = cube(DVec3::ZERO, 1e200);
        assert_eq!(volume(&big), f64::INFINITY);
        let mut bad = cube(DVec3::ZERO, 1.0);
        bad.positions[3].x = f64::NAN;
        assert!(volume(&bad).is_nan());
        assert_eq!(volume(&Mesh::default()), 0.0);
    }

    /// Against the rational `n / 6` rounded by num-rational, on thirds
    /// (whose volumes are not `f64`s) and ties.
    #[test]
    fn rounds_once_to_nearest() {
        use num_rational::BigRational;
        for n in [
            1u64,
            2,
            3,
            5,
            7,
            9,
            11,
            (1 << 53) + 1,
            (1 << 54) + 3,
            u64::MAX,
        ] {
            for e in [-60i64, 0, 33] {
                let exact = BigRational::new(BigInt::from(n), BigInt::from(6))
                    * BigRational::from_integer(BigInt::from(2)).pow(e as i32);
                let want = exact.to_f64().unwrap();
                assert_eq!(round_ratio(&BigUint::from(n), 6, e), want, "{n} {e}");
            }
        }
        // a tie between two f64s goes to the even one
        let tie = (BigUint::from(1u64 << 53) + 1u8) * 6u8;
        assert_eq!(round_ratio(&tie, 6, 0), (1u64 << 53) as f64);
        let tie = (BigUint::from(1u64 << 53) + 3u8) * 6u8;
        assert_eq!(round_ratio(&tie, 6, 0), ((1u64 << 53) + 4) as f64);
    }
}
