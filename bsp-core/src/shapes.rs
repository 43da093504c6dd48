//! Test shapes as closed, outward-oriented meshes (positions and faces),
//! for examples, benches and tests.

use glam::DVec3;

/// The unit UV sphere of about `n` triangles: `s` stacks (at least 3) of
/// `2s` slices, the poles as fans; `4s(s − 1)` triangles.
pub fn uv_sphere(n: usize) -> (Vec<DVec3>, Vec<Vec<u32>>) {
    let s = (((n as f64 / 4.0).sqrt() + 0.5).floor() as usize).max(3);
    let m = 2 * s;
    let mut v = vec![DVec3::Z];
    for i in 1..s {
        let th = std::f64::consts::PI * i as f64 / s as f64;
        for j in 0..m {
            let ph = std::f64::consts::TAU * j as f64 / m as f64;
            v.push(DVec3::new(
                th.sin() * ph.cos(),
                th.sin() * ph.sin(),
                th.cos(),
            ));
        }
    }
    v.push(-DVec3::Z);
    let south = (v.len() - 1) as u32;
    let ring = |i: usize, j: usize| (1 + (i - 1) * m + j % m) as u32;
    let mut t = Vec::new();
    for j in 0..m {
        t.push(vec![0, ring(1, j), ring(1, j + 1)]);
    }
    for i in 1..s - 1 {
        for j in 0..m {
            let (a, b, c, d) = (
                ring(i, j),
                ring(i, j + 1),
                ring(i + 1, j + 1),
                ring(i + 1, j),
            );
            t.push(vec![a, d, c]);
            t.push(vec![a, c, b]);
        }
    }
    for j in 0..m {
        t.push(vec![ring(s - 1, j), south, ring(s - 1, j + 1)]);
    }
    (v, t)
}

/// `n` points spread evenly over the unit sphere (a Fibonacci spiral from
/// the north pole to the south pole).
pub fn fibonacci_sphere(n: usize) -> Vec<DVec3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let a = golden * i as f64;
            DVec3::new(r * a.cos(), r * a.sin(), z)
        })
        .collect()
}

/// An axis-aligned box from `lo` to `hi` as six quads, counter-clockwise
/// seen from outside (bottom, top, then the sides at `y = lo`, `y = hi`,
/// `x = lo`, `x = hi`).
pub fn cuboid(lo: DVec3, hi: DVec3) -> Vec<Vec<DVec3>> {
    let c = |x: bool, y: bool, z: bool| {
        DVec3::new(
            if x { hi.x } else { lo.x },
            if y { hi.y } else { lo.y },
            if z { hi.z } else { lo.z },
        )
    };
    let (f, t) = (false, true);
    vec![
        vec![c(f, f, f), c(f, t, f), c(t, t, f), c(t, f, f)],
        vec![c(f, f, t), c(t, f, t), c(t, t, t), c(f, t, t)],
        vec![c(f, f, f), c(t, f, f), c(t, f, t), c(f, f, t)],
        vec![c(f, t, f), c(f, t, t), c(t, t, t), c(t, t, f)],
        vec![c(f, f, f), c(f, f, t), c(f, t, t), c(f, t, f)],
        vec![c(t, f, f), c(t, t, f), c(t, t, t), c(t, f, t)],
    ]
}

/// The CSG benches' pair: the unit UV sphere of about `n` triangles
/// ([`uv_sphere`]) and a copy of it rotated 5° about `(1, 2, 3)` and moved
/// by `(0.3, 0.1, 0.05)` (the inputs of `scripts/manifold_compare.py`).
/// Returns both vertex lists and their shared faces.
pub fn sphere_pair(n: usize) -> (Vec<DVec3>, Vec<DVec3>, Vec<Vec<u32>>) {
    let (a, f) = uv_sphere(n);
    let rot =
        glam::DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 5f64.to_radians());
    let b = a
        .iter()
        .map(|&p| rot * p + DVec3::new(0.3, 0.1, 0.05))
        .collect();
    (a, b, f)
}

/// The iterated-CSG benches' tools: `count` UV spheres of about `n`
/// triangles and radius 0.05, centred on the unit sphere along a
/// Fibonacci spiral ([`fibonacci_sphere`]). Returns each tool's vertices
/// and their shared faces.
pub fn drill_tools(count: usize, n: usize) -> (Vec<Vec<DVec3>>, Vec<Vec<u32>>) {
    let (v, f) = uv_sphere(n);
    let tools = fibonacci_sphere(count)
        .into_iter()
        .map(|c| v.iter().map(|&p| c + 0.05 * p).collect())
        .collect();
    (tools, f)
}

/// The UV sphere of about `n` triangles ([`uv_sphere`]) scaled by `radius`
/// on the integer grid, every vertex moved by a random amount in
/// `-jitter..=jitter` on each axis, and the faces that keep an area as
/// polygons: a closed surface that often folds over, passes through
/// itself or turns a part inside out, for tests of what is certified
/// about surfaces.
pub fn jittered_uv_sphere(
    n: usize,
    radius: f64,
    jitter: i32,
    rng: &mut crate::SplitMix,
) -> Vec<crate::Polygon> {
    let (v, f) = uv_sphere(n);
    let pts: Vec<crate::GridPoint> = v
        .iter()
        .map(|p| {
            let mut j = || (rng.next_u64() % (2 * jitter as u64 + 1)) as i32 - jitter;
            [
                (p.x * radius).round() as i32 + j(),
                (p.y * radius).round() as i32 + j(),
                (p.z * radius).round() as i32 + j(),
            ]
        })
        .collect();
    f.iter()
        .filter_map(|t| {
            let l: Vec<crate::GridPoint> = t.iter().map(|&i| pts[i as usize]).collect();
            crate::Polygon::from_grid_points(&l, 0).ok()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fibonacci_points_are_on_the_sphere_from_pole_to_pole() {
        let p = fibonacci_sphere(50);
        assert_eq!(p.len(), 50);
        // heights 1 − (2i + 1)/n, strictly falling from pole to pole
        for (i, q) in p.iter().enumerate() {
            assert_eq!(q.z, 1.0 - 2.0 * (i as f64 + 0.5) / 50.0);
        }
        assert!(p.windows(2).all(|w| w[0].z > w[1].z));
    }

    #[test]
    fn uv_sphere_is_closed_and_outward() {
        for n in [1, 100, 1000] {
            let (v, f) = uv_sphere(n);
            crate::check_closed_manifold(f.iter().map(Vec::as_slice)).unwrap();
            let s = ((n as f64 / 4.0).sqrt() + 0.5).floor().max(3.0) as usize;
            assert_eq!(f.len(), 4 * s * (s - 1));
            let vol: f64 = f
                .iter()
                .map(|t| v[t[0] as usize].dot(v[t[1] as usize].cross(v[t[2] as usize])))
                .sum::<f64>()
                / 6.0;
            assert!(vol > 0.0 && vol < 4.0 / 3.0 * std::f64::consts::PI, "{vol}");
        }
    }
}
