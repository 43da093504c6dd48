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

/// A closed surface that crosses itself along a segment `ab` which is a
/// diagonal of two of its faces, with its two solids on their own and
/// points of known winding number (see [`crossing_along_diagonal`]).
#[derive(Clone, Debug)]
pub struct DiagonalCrossing {
    /// The surface: one edge-connected part, every edge used once each
    /// way, positive volume, yet winding number `-1` at `negative`.
    pub surface: Vec<crate::Polygon>,
    /// The two convex solids it is made of, each on its own and outward.
    pub solids: [Vec<crate::Polygon>; 2],
    /// A point inside the inverted solid: winding number `-1`.
    pub negative: crate::GridPoint,
    /// A point inside the other solid: winding number `+1`.
    pub positive: crate::GridPoint,
}

/// Two convex solids lying in opposite dihedral wedges about a segment
/// `ab`, so that they touch only along it; the small one turned inside
/// out, and each solid's two faces through `ab` merged with the other's
/// into one convex polygon (of 4 to 10 corners) with `ab` as a diagonal.
/// The two merged polygons cross along `ab`. Every edge is used once each
/// way and the volume is positive, so only a test of how the faces meet
/// along `ab` can tell that the winding number is `-1` inside the small
/// solid. Drawn at random: the wedges, the solids' profiles (1 to 3
/// corners a side) and an orientation-preserving integer map with a
/// translation.
pub fn crossing_along_diagonal(rng: &mut crate::SplitMix) -> DiagonalCrossing {
    type P = [i64; 3];
    let mut pick = |lo: i64, hi: i64| lo + (rng.next_u64() % (hi - lo + 1) as u64) as i64;
    // two wedge directions across the z axis, not parallel
    let (u, v) = loop {
        let u = [pick(-4, 4), pick(-4, 4), 0];
        let v = [pick(-4, 4), pick(-4, 4), 0];
        if u[0] * v[1] - u[1] * v[0] != 0 {
            break (u, v);
        }
    };
    let h = 12 * pick(1, 2);
    // a strictly concave profile of `k` radii at equal heights
    let profile = |pick: &mut dyn FnMut(i64, i64) -> i64, r: i64| -> Vec<(i64, i64)> {
        let k = pick(1, 3);
        let radii = match k {
            1 => vec![r],
            2 => vec![r, r],
            _ => {
                let d = pick(1, r - 1);
                vec![r, r + d, r]
            }
        };
        (1..=k)
            .zip(radii)
            .map(|(i, r)| (i * h / (k + 1), r))
            .collect()
    };
    // the small solid's radii stay below 2r, the large one's start at 4r:
    // the large one holds more than twice the volume
    let r = pick(2, 3);
    let small = profile(&mut pick, r);
    let big = pick(4 * r, 4 * r + 3);
    let large = profile(&mut pick, big);
    let at = |w: P, s: i64, (z, r): (i64, i64)| [s * r * w[0], s * r * w[1], z];
    let (a, b): (P, P) = ([0; 3], [0, 0, h]);
    // the small solid in the wedge of +u and +v, the large one in -u, -v
    let chain = |prof: &[(i64, i64)], w: P, s: i64| -> Vec<P> {
        std::iter::once(a)
            .chain(prof.iter().map(|&q| at(w, s, q)))
            .chain(std::iter::once(b))
            .collect()
    };
    let (sp, sq) = (chain(&small, u, 1), chain(&small, v, 1));
    let (lp, lq) = (chain(&large, u, -1), chain(&large, v, -1));
    // each solid: the strips between its two chains, and its two faces
    // through `ab` (one in the plane of u, one in the plane of v)
    let strips = |p: &[P], q: &[P]| -> Vec<Vec<P>> {
        (0..p.len() - 1)
            .map(|i| {
                let mut f = vec![p[i], p[i + 1], q[i + 1], q[i]];
                f.dedup();
                if f.first() == f.last() {
                    f.pop();
                }
                f
            })
            .collect()
    };
    let inner = |c: &[P]| c[1..c.len() - 1].to_vec();
    let centroid = |c: &[&[P]]| {
        let pts: Vec<P> = c.iter().flat_map(|c| inner(c)).chain([a, b]).collect();
        (
            pts.iter()
                .fold([0; 3], |s, p| [0, 1, 2].map(|k| s[k] + p[k])),
            pts.len() as i64,
        )
    };
    let (cs, ns) = centroid(&[&sp, &sq]);
    let (cl, nl) = centroid(&[&lp, &lq]);
    // everything scaled by ns · nl: both centroids become grid points
    let scale = ns * nl;
    let sub = |p: P, q: P| [0, 1, 2].map(|k| p[k] - q[k]);
    // a face turned so that its normal points away from `c / n` (or
    // towards it when `inward`)
    let orient = |mut f: Vec<P>, (c, n): (P, i64), inward: bool| -> Vec<P> {
        let (e, g) = (sub(f[1], f[0]), sub(f[2], f[0]));
        let nrm = [
            e[1] * g[2] - e[2] * g[1],
            e[2] * g[0] - e[0] * g[2],
            e[0] * g[1] - e[1] * g[0],
        ];
        let to_c = sub(c, f[0].map(|x| x * n));
        let towards = (0..3).map(|k| nrm[k] * to_c[k]).sum::<i64>() > 0;
        if towards != inward {
            f.reverse();
        }
        f
    };
    let solid = |p: &[P], q: &[P], c: (P, i64), inward: bool| -> Vec<Vec<P>> {
        strips(p, q)
            .into_iter()
            .chain([p.to_vec(), q.to_vec()])
            .map(|f| orient(f, c, inward))
            .collect()
    };
    // the merged faces: a, one side's chain, b, the other side's back
    let merged = |s: &[P], l: &[P]| -> Vec<P> {
        s.iter()
            .copied()
            .chain(l[1..l.len() - 1].iter().rev().copied())
            .collect()
    };
    let mut surface: Vec<Vec<P>> = strips(&sp, &sq)
        .into_iter()
        .map(|f| orient(f, (cs, ns), true))
        .chain(
            strips(&lp, &lq)
                .into_iter()
                .map(|f| orient(f, (cl, nl), false)),
        )
        .collect();
    // each merged face starts at `a` or `b`, so that `ab` is a diagonal
    // of its triangle fan too (a certificate that works on fan triangles
    // sees the crossing only as two triangles sharing `ab`)
    for (s, l) in [(&sp, &lp), (&sq, &lq)] {
        let mut f = orient(merged(s, l), (cl, nl), false);
        let end = if pick(0, 1) == 0 { a } else { b };
        let at = f.iter().position(|&p| p == end).expect("a corner");
        f.rotate_left(at);
        surface.push(f);
    }
    let solids = [
        solid(&sp, &sq, (cs, ns), false),
        solid(&lp, &lq, (cl, nl), false),
    ];
    // an integer map of positive determinant and a translation
    let m = loop {
        let m: [[i64; 3]; 3] = [(); 3].map(|_| [(); 3].map(|_| pick(-2, 2)));
        let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
        if det > 0 {
            break m;
        }
    };
    let t = [(); 3].map(|_| pick(-1000, 1000));
    let map = |p: P, s: i64| -> crate::GridPoint {
        [0, 1, 2].map(|r| ((0..3).map(|k| m[r][k] * p[k]).sum::<i64>() * s + t[r] * scale) as i32)
    };
    let polys = |faces: Vec<Vec<P>>| -> Vec<crate::Polygon> {
        faces
            .iter()
            .map(|f| {
                let l: Vec<crate::GridPoint> = f.iter().map(|&p| map(p, scale)).collect();
                crate::Polygon::from_grid_points(&l, 0).expect("a convex face")
            })
            .collect()
    };
    let [s0, s1] = solids;
    DiagonalCrossing {
        surface: polys(surface),
        solids: [polys(s0), polys(s1)],
        negative: map(cs, nl),
        positive: map(cl, ns),
    }
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
