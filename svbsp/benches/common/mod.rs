//! Scenes and the ray-casting baseline shared by the `shadows` bench and
//! the `shade` example: fixed seeds, everything built in code or from the
//! repository's bunny (no data files outside the repository).
//!
//! Scenes are made in input units (`f64`), snapped with one
//! `Grid::fit_points` over every vertex and every point light, and
//! imported with `import_faces`.
//!
//! The baseline is what a renderer does instead of exact shadows: a
//! median-split BVH over the scene's triangles (in `f64` grid units,
//! `shadow_raster::TriangleBvh`) and one any-hit shadow ray per sample
//! point toward each light, with a Möller–Trumbore test; the points are
//! spread over the faces by area, as the pixels of an image would be.

#![allow(dead_code, unreachable_pub, missing_docs)]

use bsp_core::{Grid, Polygon, import_faces};
use glam::DVec3;
use rayon::prelude::*;
use svbsp::Light;

/// The generator every bench draws from.
pub use bsp_fixtures::Rng;

/// A light in input units.
#[derive(Clone, Copy, Debug)]
pub enum WorldLight {
    /// A point light at this position.
    Point(DVec3),
    /// A sun: an integer direction from the scene toward the light (used
    /// as is, exactly).
    Sun([i32; 3]),
}

/// A scene in input units.
pub struct SceneSpec {
    pub name: String,
    pub faces: Vec<Vec<DVec3>>,
}

/// Rounds to a multiple of `2^-10`: such coordinates (below `2^10` in
/// magnitude) snap exactly to any grid finer than `2^-10`, so a
/// parallelogram made of them stays planar on the grid.
fn q(x: f64) -> f64 {
    (x * 1024.0).round() / 1024.0
}

fn qv(v: DVec3) -> DVec3 {
    DVec3::new(q(v.x), q(v.y), q(v.z))
}

/// A box with a square-ish footprint of `sx × sy` centred at `(cx, cy)`,
/// rotated by `angle` about the vertical, from height `z0` to `z1`: six
/// quads, counter-clockwise seen from outside. Rotating about the vertical
/// only keeps every face planar after snapping (the top and bottom are
/// horizontal, the sides vertical with equal `x, y` above and below).
fn boxed(c: (f64, f64), s: (f64, f64), angle: f64, z: (f64, f64)) -> [Vec<DVec3>; 6] {
    let (sin, cos) = angle.sin_cos();
    let corner = |u: f64, v: f64| {
        let (dx, dy) = (u * s.0 * 0.5, v * s.1 * 0.5);
        (c.0 + dx * cos - dy * sin, c.1 + dx * sin + dy * cos)
    };
    let xy = [
        corner(-1.0, -1.0),
        corner(1.0, -1.0),
        corner(1.0, 1.0),
        corner(-1.0, 1.0),
    ];
    let b = xy.map(|(x, y)| DVec3::new(x, y, z.0));
    let t = xy.map(|(x, y)| DVec3::new(x, y, z.1));
    [
        vec![b[0], b[3], b[2], b[1]], // bottom, facing down
        vec![t[0], t[1], t[2], t[3]], // top, facing up
        vec![b[0], b[1], t[1], t[0]],
        vec![b[1], b[2], t[2], t[1]],
        vec![b[2], b[3], t[3], t[2]],
        vec![b[3], b[0], t[0], t[3]],
    ]
}

/// A random tetrahedron of about `size` around `c`: four triangles,
/// counter-clockwise seen from outside.
fn tetra(rng: &mut Rng, c: DVec3, size: f64) -> [Vec<DVec3>; 4] {
    loop {
        let v: Vec<DVec3> = (0..4)
            .map(|_| c + rng.unit_vector() * size * rng.range(0.6, 1.0))
            .collect();
        let vol = (v[1] - v[0]).cross(v[2] - v[0]).dot(v[3] - v[0]);
        // reject flat ones: volume well above the degenerate case
        if vol.abs() < 0.1 * size * size * size {
            continue;
        }
        let (a, b) = if vol > 0.0 { (1, 2) } else { (2, 1) };
        // with (v0, va, vb, v3) positively oriented, these face outward
        return [
            vec![v[0], v[b], v[a]],
            vec![v[0], v[a], v[3]],
            vec![v[a], v[b], v[3]],
            vec![v[b], v[0], v[3]],
        ];
    }
}

/// A random parallelogram of about `size` around `c`, any orientation,
/// on the `2^-10` lattice (so it stays planar on the grid).
fn quad(rng: &mut Rng, c: DVec3, size: f64) -> Vec<DVec3> {
    loop {
        let a = qv(rng.unit_vector() * size * rng.range(0.5, 1.0));
        let b = qv(rng.unit_vector() * size * rng.range(0.5, 1.0));
        if a.cross(b).length() < 0.3 * size * size {
            continue;
        }
        let p = qv(c - (a + b) * 0.5);
        return vec![p, p + a, p + a + b, p + b];
    }
}

/// A Chin & Feiner-like scene of exactly `n` polygons: a 20 × 20 floor
/// (one quad) and `(n - 1) / 10` boxes (6 quads each), as many tetrahedra
/// (4 triangles each) and `(n - 1) % 10` parallelograms, floating at
/// random between heights 1 and 6 above it. Object sizes shrink with their
/// number, so that shadows overlap at every size.
pub fn chin_feiner(n: usize) -> SceneSpec {
    assert!(n >= 1);
    let mut rng = Rng::new(0x0c4f_1989 ^ n as u64);
    let k = (n - 1) / 10;
    let extra = (n - 1) % 10;
    let objects = (2 * k + extra).max(1) as f64;
    let size = (8.0 / objects.sqrt()).min(3.0);
    let h = 10.0;
    let mut faces: Vec<Vec<DVec3>> = vec![vec![
        DVec3::new(-h, -h, 0.0),
        DVec3::new(h, -h, 0.0),
        DVec3::new(h, h, 0.0),
        DVec3::new(-h, h, 0.0),
    ]];
    let centre = |rng: &mut Rng| {
        DVec3::new(
            rng.range(-h + size, h - size),
            rng.range(-h + size, h - size),
            rng.range(1.0 + size, 6.0),
        )
    };
    for _ in 0..k {
        let c = centre(&mut rng);
        let s = (size * rng.range(0.5, 1.2), size * rng.range(0.5, 1.2));
        let dz = size * rng.range(0.4, 1.0);
        faces.extend(boxed(
            (c.x, c.y),
            s,
            rng.range(0.0, std::f64::consts::PI),
            (c.z - dz, c.z + dz),
        ));
    }
    for _ in 0..k {
        let c = centre(&mut rng);
        faces.extend(tetra(&mut rng, c, size * 0.8));
    }
    for _ in 0..extra {
        let c = centre(&mut rng);
        faces.push(quad(&mut rng, c, size));
    }
    assert_eq!(faces.len(), n);
    SceneSpec {
        name: format!("cf{n}"),
        faces,
    }
}

/// Terrain height: gentle hills between about -0.8 and 0.8.
fn height(x: f64, y: f64) -> f64 {
    0.45 * (0.7 * x).sin() * (0.5 * y).cos()
        + 0.25 * (1.3 * x + 0.4 * y).sin()
        + 0.1 * (2.9 * y - 0.8 * x).cos()
}

/// A terrain-and-objects scene of exactly `n` polygons, `n` a multiple of
/// 100: a height field over `[-10, 10]²` of `0.35 n` cells (two triangles
/// each, 70% of the polygons) and `0.05 n` boxes (30%) standing on it or
/// floating up to 2 units above it, randomly rotated about the vertical.
pub fn terrain(n: usize) -> SceneSpec {
    assert!(n.is_multiple_of(100) && n > 0);
    let mut rng = Rng::new(0x07e5_5a1a ^ n as u64);
    let cells = n * 35 / 100;
    // nx × ny = cells with nx / ny close to 1
    let mut nx = (cells as f64).sqrt() as usize;
    while !cells.is_multiple_of(nx) {
        nx -= 1;
    }
    let ny = cells / nx;
    let h = 10.0;
    let at = |i: usize, j: usize| {
        let x = -h + 2.0 * h * i as f64 / nx as f64;
        let y = -h + 2.0 * h * j as f64 / ny as f64;
        DVec3::new(x, y, height(x, y))
    };
    let mut faces: Vec<Vec<DVec3>> = Vec::with_capacity(n);
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            // alternate the diagonal, as tessellators do
            if (i + j) % 2 == 0 {
                faces.push(vec![a, b, c]);
                faces.push(vec![a, c, d]);
            } else {
                faces.push(vec![a, b, d]);
                faces.push(vec![b, c, d]);
            }
        }
    }
    let boxes = (n - faces.len()) / 6;
    let size = 9.0 / (boxes as f64).sqrt();
    for _ in 0..boxes {
        let (cx, cy) = (
            rng.range(-h + size, h - size),
            rng.range(-h + size, h - size),
        );
        let s = (size * rng.range(0.4, 1.0), size * rng.range(0.4, 1.0));
        let ground = height(cx, cy) + 0.8 * size;
        let z0 = ground
            + if rng.f64() < 0.5 {
                0.0
            } else {
                rng.range(0.0, 2.0)
            };
        let dz = size * rng.range(0.5, 2.0);
        faces.extend(boxed(
            (cx, cy),
            s,
            rng.range(0.0, std::f64::consts::PI),
            (z0, z0 + dz),
        ));
    }
    assert_eq!(faces.len(), n);
    SceneSpec {
        name: format!("terrain{n}"),
        faces,
    }
}

/// The scenes of the bench by name: `cfN` (Chin & Feiner-like, `N`
/// polygons), `terrainN` (`N` a multiple of 100), `room`, and
/// `bunny-99k`, `bunny-893k` and the other refinements of the bunny on its
/// ground (see `shadow_scene::bunny`).
pub fn scene(name: &str) -> SceneSpec {
    if let Some(n) = name.strip_prefix("cf") {
        return chin_feiner(n.parse().expect("cfN"));
    }
    if let Some(n) = name.strip_prefix("terrain") {
        return terrain(n.parse().expect("terrainN"));
    }
    let mesh = shadow_scene::scene(name).unwrap_or_else(|| panic!("unknown scene {name}"));
    SceneSpec {
        name: name.to_string(),
        faces: mesh.face_loops(),
    }
}

/// The lights of a scene: one key point light above it, or four (three
/// point lights and a sun), placed relative to the scene's box.
pub fn lights(spec: &SceneSpec, n: usize) -> Vec<WorldLight> {
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for p in spec.faces.iter().flatten() {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let (c, s) = ((lo + hi) * 0.5, (hi - lo).max_element() * 0.5);
    // the bunny stands along +y, the other scenes along +z
    let up = if spec.name.starts_with("bunny") {
        DVec3::Y
    } else {
        DVec3::Z
    };
    let side = if up == DVec3::Y { DVec3::Z } else { DVec3::Y };
    let key = c + up * 1.6 * s + DVec3::X * 0.4 * s + side * 0.6 * s;
    let all = [
        WorldLight::Point(key),
        WorldLight::Point(c + up * 1.2 * s - DVec3::X * 1.1 * s + side * 0.2 * s),
        WorldLight::Point(c + up * 0.5 * s + DVec3::X * 1.8 * s - side * 0.9 * s),
        WorldLight::Sun(if up == DVec3::Y {
            [3, 10, 2]
        } else {
            [4, 3, 10]
        }),
    ];
    all[..n.min(4)].to_vec()
}

/// A scene on its grid, ready for the shadows and the baseline.
pub struct Prepared {
    pub name: String,
    pub grid: Grid,
    pub polys: Vec<Polygon>,
    pub lights: Vec<Light>,
    /// The lights in `f64` grid units: `true` and the point, or `false`
    /// and the sun's direction.
    pub lights_f64: Vec<(bool, DVec3)>,
}

/// Snaps the scene and its lights to one grid and imports it.
pub fn prepare(spec: &SceneSpec, world_lights: &[WorldLight]) -> Prepared {
    let mut pts: Vec<DVec3> = spec.faces.iter().flatten().copied().collect();
    for l in world_lights {
        if let WorldLight::Point(p) = l {
            pts.push(*p);
        }
    }
    let grid = Grid::fit_points(&pts).expect("scene fits a grid");
    let (polys, _report) =
        import_faces(&grid, spec.faces.iter().map(|f| &f[..])).expect("scene snaps");
    let mut lights = Vec::new();
    let mut lights_f64 = Vec::new();
    for l in world_lights {
        match l {
            WorldLight::Point(p) => {
                let g = grid.snap(*p).expect("light on the grid");
                lights.push(Light::Point(g));
                lights_f64.push((true, DVec3::new(g[0] as f64, g[1] as f64, g[2] as f64)));
            }
            WorldLight::Sun(d) => {
                lights.push(Light::Directional(*d));
                lights_f64.push((false, DVec3::new(d[0] as f64, d[1] as f64, d[2] as f64)));
            }
        }
    }
    Prepared {
        name: spec.name.clone(),
        grid,
        polys,
        lights,
        lights_f64,
    }
}

/// The scene's triangles in `f64` grid units (each convex polygon as a
/// fan), for the baseline.
pub fn triangles(polys: &[Polygon]) -> Vec<[DVec3; 3]> {
    let mut out = Vec::new();
    for p in polys {
        let v: Vec<DVec3> = p.vertices_f64().into_iter().map(DVec3::from).collect();
        for i in 1..v.len() - 1 {
            out.push([v[0], v[i], v[i + 1]]);
        }
    }
    out
}

// ---------------------------------------------------------------------------
// The baseline: a median-split BVH and any-hit shadow rays (the hierarchy
// is `shadow-raster`'s, the renderer's own).

pub use shadow_raster::TriangleBvh as Bvh;

/// `n` sample points spread over the triangles by area (as an image's
/// pixels land on the surfaces), each with its triangle's normal.
pub fn surface_samples(tris: &[[DVec3; 3]], n: usize, seed: u64) -> Vec<(DVec3, DVec3)> {
    let mut cum = Vec::with_capacity(tris.len());
    let mut total = 0.0;
    for t in tris {
        total += (t[1] - t[0]).cross(t[2] - t[0]).length();
        cum.push(total);
    }
    let mut rng = Rng::new(seed);
    (0..n)
        .map(|_| {
            let x = rng.f64() * total;
            let i = cum.partition_point(|&c| c < x).min(tris.len() - 1);
            let t = &tris[i];
            let (mut u, mut v) = (rng.f64(), rng.f64());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            let p = t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * v;
            let nrm = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
            (p, nrm)
        })
        .collect()
}

/// Self-intersection margin of the shadow rays, in grid units of distance
/// along the ray.
pub const RAY_EPS: f64 = 1.0;

/// One shadow-ray pass, as a renderer's: for every sample, a ray toward
/// each light in front of it (in `f64`), ignoring hits closer than
/// [`RAY_EPS`]; samples with the light behind are in attached shadow.
/// In parallel. Returns how many (sample, light) pairs are lit.
pub fn shadow_ray_pass(bvh: &Bvh, samples: &[(DVec3, DVec3)], lights: &[(bool, DVec3)]) -> usize {
    samples
        .par_chunks(4096)
        .map(|chunk| {
            let mut lit = 0;
            for (p, n) in chunk {
                for &(point, l) in lights {
                    let d = if point { l - *p } else { l };
                    if n.dot(d) <= 0.0 {
                        continue;
                    }
                    let tmin = RAY_EPS / d.length();
                    let tmax = if point { 1.0 } else { f64::INFINITY };
                    if !bvh.occluded(*p, d, tmin, tmax) {
                        lit += 1;
                    }
                }
            }
            lit
        })
        .sum()
}

/// The process's resident memory now and its peak since the last
/// [`reset_peak`], in bytes, from `/proc/self/status` (Linux).
pub fn memory() -> Option<(u64, u64)> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let field = |name: &str| -> Option<u64> {
        let line = s.lines().find(|l| l.starts_with(name))?;
        let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
        Some(kb * 1024)
    };
    Some((field("VmRSS:")?, field("VmHWM:")?))
}

/// Resets the peak resident memory to the current one (Linux 4.0+).
pub fn reset_peak() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}
