//! Scene generators and the ray-casting baseline shared by the `shadows`
//! bench and the `bench_100k` example: fixed seeds, everything built in
//! code (no data files).
//!
//! Scenes are made in input units (`f64`), snapped with one
//! `Grid::fit_points` over every vertex and every point light, imported with
//! `import_faces` and checked to give exactly the advertised number of
//! polygons (nothing triangulated, nothing dropped).
//!
//! The baseline is what a renderer would do instead of exact shadows: a
//! median-split BVH over the scene's triangles (in `f64` grid units) and
//! one any-hit shadow ray per fragment sample (the fragment's centroid)
//! toward each light, with a Möller–Trumbore test.

#![allow(dead_code, unreachable_pub, missing_docs)]

use std::time::{Duration, Instant};

use bsp_core::{BspTree, BuildOptions, Grid, Polygon, import_faces};
use glam::DVec3;
use svbsp::{Fragment, Light, ShadowStats, shadow_fragments};

/// `SplitMix64`: a small deterministic generator.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// Uniform in `[0, 1)`.
    pub fn f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.f64()
    }
    pub fn unit_vector(&mut self) -> DVec3 {
        loop {
            let v = DVec3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            let l = v.length();
            if l > 0.1 && l <= 1.0 {
                return v / l;
            }
        }
    }
}

/// A light in input units.
#[derive(Clone, Copy, Debug)]
pub enum WorldLight {
    /// A point light at this position.
    Point(DVec3),
    /// A sun: an integer direction from the scene toward the light (used
    /// as is, exactly).
    Sun([i32; 3]),
}

/// The scenes' lights: the key point light, a second point light, a sun.
pub const KEY_LIGHT: WorldLight = WorldLight::Point(DVec3::new(2.0, -3.0, 15.0));
pub const FILL_LIGHT: WorldLight = WorldLight::Point(DVec3::new(-8.0, 6.0, 10.0));
pub const SUN: WorldLight = WorldLight::Sun([4, 3, 10]);

/// One light (the key point light) or three (two points and the sun).
pub fn lights(n: usize) -> Vec<WorldLight> {
    match n {
        1 => vec![KEY_LIGHT],
        _ => vec![KEY_LIGHT, FILL_LIGHT, SUN],
    }
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

/// The scene for a benchmark size: Chin & Feiner-like below 10 000
/// polygons, terrain and boxes from 10 000 up.
pub fn scene(n: usize) -> SceneSpec {
    if n < 10_000 {
        chin_feiner(n)
    } else {
        terrain(n)
    }
}

/// A scene on its grid, ready for the BSP build and the baseline.
pub struct Prepared {
    pub name: String,
    pub grid: Grid,
    /// Imported polygons (as many as the scene's faces).
    pub polys: Vec<Polygon>,
    pub lights: Vec<Light>,
    /// The lights in `f64` grid units: the point, or the sun's direction.
    pub lights_f64: Vec<(bool, DVec3)>,
}

/// Snaps the scene and its lights to one grid and imports it; panics
/// (with a message) unless every face became exactly one polygon.
pub fn prepare(spec: &SceneSpec, world_lights: &[WorldLight]) -> Prepared {
    let mut pts: Vec<DVec3> = spec.faces.iter().flatten().copied().collect();
    for l in world_lights {
        if let WorldLight::Point(p) = l {
            pts.push(*p);
        }
    }
    let grid = Grid::fit_points(&pts).expect("scene fits a grid");
    let (polys, report) =
        import_faces(&grid, spec.faces.iter().map(|f| &f[..])).expect("scene snaps");
    assert!(
        report.dropped.is_empty() && report.triangulated.is_empty(),
        "{}: {}",
        spec.name,
        report.summary()
    );
    assert_eq!(polys.len(), spec.faces.len());
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

/// The BSP build options compared: the default autopartition and balance
/// cuts above 64 polygons.
pub fn build_options(cut: bool) -> BuildOptions {
    if cut {
        BuildOptions::default().with_cut_threshold(64)
    } else {
        BuildOptions::default()
    }
}

/// `"default"` or `"cut64"`.
pub fn options_name(cut: bool) -> &'static str {
    if cut { "cut64" } else { "default" }
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
// The baseline: a median-split BVH and any-hit shadow rays.

/// Triangles per leaf at most.
const LEAF: usize = 4;

#[derive(Clone, Copy, Debug)]
struct BvhNode {
    lo: DVec3,
    hi: DVec3,
    /// Leaf: first triangle; inner node: left child (right is `start + 1`).
    start: u32,
    /// Leaf: triangle count; inner node: 0.
    count: u32,
}

/// A triangle ready for Möller–Trumbore: a vertex and two edges.
#[derive(Clone, Copy, Debug)]
struct Tri {
    v0: DVec3,
    e1: DVec3,
    e2: DVec3,
}

/// A straightforward bounding-volume hierarchy: axis-aligned boxes, split
/// at the median centroid along the longest axis of the centroids' box,
/// up to [`LEAF`] triangles per leaf.
pub struct Bvh {
    nodes: Vec<BvhNode>,
    tris: Vec<Tri>,
}

impl Bvh {
    pub fn build(tris: &[[DVec3; 3]]) -> Bvh {
        let n = tris.len();
        let lo: Vec<DVec3> = tris.iter().map(|t| t[0].min(t[1]).min(t[2])).collect();
        let hi: Vec<DVec3> = tris.iter().map(|t| t[0].max(t[1]).max(t[2])).collect();
        let cen: Vec<DVec3> = (0..n).map(|i| (lo[i] + hi[i]) * 0.5).collect();
        let mut idx: Vec<u32> = (0..n as u32).collect();
        let mut nodes = vec![BvhNode {
            lo: DVec3::ZERO,
            hi: DVec3::ZERO,
            start: 0,
            count: 0,
        }];
        let mut stack = vec![(0usize, 0usize, n)];
        while let Some((ni, a, b)) = stack.pop() {
            let (mut bl, mut bh) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
            let (mut cl, mut ch) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
            for &i in &idx[a..b] {
                let i = i as usize;
                bl = bl.min(lo[i]);
                bh = bh.max(hi[i]);
                cl = cl.min(cen[i]);
                ch = ch.max(cen[i]);
            }
            nodes[ni].lo = bl;
            nodes[ni].hi = bh;
            if b - a <= LEAF {
                nodes[ni].start = a as u32;
                nodes[ni].count = (b - a) as u32;
                continue;
            }
            let ext = ch - cl;
            let axis = if ext.x >= ext.y && ext.x >= ext.z {
                0
            } else if ext.y >= ext.z {
                1
            } else {
                2
            };
            let mid = (a + b) / 2;
            idx[a..b].select_nth_unstable_by(mid - a, |&i, &j| {
                cen[i as usize][axis].total_cmp(&cen[j as usize][axis])
            });
            let left = nodes.len();
            let empty = nodes[ni];
            nodes.push(empty);
            nodes.push(empty);
            nodes[ni].start = left as u32;
            nodes[ni].count = 0;
            stack.push((left, a, mid));
            stack.push((left + 1, mid, b));
        }
        let tris = idx
            .iter()
            .map(|&i| {
                let t = &tris[i as usize];
                Tri {
                    v0: t[0],
                    e1: t[1] - t[0],
                    e2: t[2] - t[0],
                }
            })
            .collect();
        Bvh { nodes, tris }
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// `true` if some triangle meets the ray `o + t d` for `t` in
    /// `(tmin, tmax)` (any hit, no ordering).
    pub fn occluded(&self, o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> bool {
        let inv = d.recip();
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top] as usize];
            let t1 = (node.lo - o) * inv;
            let t2 = (node.hi - o) * inv;
            let tn = t1.min(t2).max_element().max(tmin);
            let tf = t1.max(t2).min_element().min(tmax);
            if tn > tf {
                continue;
            }
            if node.count == 0 {
                stack[top] = node.start;
                stack[top + 1] = node.start + 1;
                top += 2;
                continue;
            }
            let s = node.start as usize;
            for t in &self.tris[s..s + node.count as usize] {
                if hit(t, o, d, tmin, tmax) {
                    return true;
                }
            }
        }
        false
    }
}

/// Möller–Trumbore in `f64`: does the ray meet the triangle (edges
/// included) at a parameter in `(tmin, tmax)`?
#[inline]
fn hit(t: &Tri, o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> bool {
    let p = d.cross(t.e2);
    let det = t.e1.dot(p);
    if det == 0.0 {
        return false;
    }
    let inv = 1.0 / det;
    let s = o - t.v0;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let qv = s.cross(t.e1);
    let v = d.dot(qv) * inv;
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    let tt = t.e2.dot(qv) * inv;
    tt > tmin && tt < tmax
}

/// One shadow ray: from a fragment's sample toward a light.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub o: DVec3,
    pub d: DVec3,
    pub tmin: f64,
    pub tmax: f64,
    /// Fragment index and light index, to compare with the exact flag.
    pub fragment: u32,
    pub light: u32,
}

/// Self-intersection margin of the shadow rays, in grid units of distance
/// along the ray (one grid step: `2^-21` of a unit in these scenes,
/// `2.4e-8` of their width).
pub const RAY_EPS: f64 = 1.0;

/// The shadow rays of the baseline: for every fragment and light where the
/// light is in front of the fragment (in `f64`: `n · (L − c) > 0`, or
/// `n · D > 0` for the sun), a ray from the fragment's centroid `c` toward
/// the light, ignoring hits closer than `eps` grid units (see
/// [`RAY_EPS`]). Fragments with the light behind or edge-on are in
/// attached shadow and need no ray. Returns the rays and, per fragment and
/// light, whether the light is in front.
pub fn shadow_rays(
    frags: &[Fragment],
    lights: &[(bool, DVec3)],
    eps: f64,
) -> (Vec<Ray>, Vec<bool>) {
    let mut rays = Vec::new();
    let mut facing = Vec::with_capacity(frags.len() * lights.len());
    for (fi, f) in frags.iter().enumerate() {
        let v = f.vertices_f64();
        let c = v.iter().fold(DVec3::ZERO, |s, p| s + DVec3::from(*p)) / v.len() as f64;
        let n = f.support().normal().map(|x| x as f64);
        let n = DVec3::from(n);
        for (li, &(point, l)) in lights.iter().enumerate() {
            let d = if point { l - c } else { l };
            let front = n.dot(d) > 0.0;
            facing.push(front);
            if front {
                let len = d.length();
                rays.push(Ray {
                    o: c,
                    d,
                    tmin: eps / len,
                    tmax: if point { 1.0 } else { f64::INFINITY },
                    fragment: fi as u32,
                    light: li as u32,
                });
            }
        }
    }
    (rays, facing)
}

/// Casts every ray; `true` where the ray is blocked.
pub fn cast(bvh: &Bvh, rays: &[Ray]) -> Vec<bool> {
    rays.iter()
        .map(|r| bvh.occluded(r.o, r.d, r.tmin, r.tmax))
        .collect()
}

/// How the baseline's answers compare with the exact flags.
#[derive(Clone, Copy, Debug, Default)]
pub struct Disagreements {
    /// The baseline says lit, the exact answer shadow.
    pub false_lit: usize,
    /// The baseline says shadow, the exact answer lit.
    pub false_shadow: usize,
    /// Fragment-light pairs where the `f64` facing test (`n · (L − c) > 0`)
    /// differs from the exact one (`Light::eval` of the support plane
    /// `> 0`), whether or not the flag then differs.
    pub facing: usize,
}

impl Disagreements {
    pub fn total(&self) -> usize {
        self.false_lit + self.false_shadow
    }
}

/// Compares the baseline (`lit = facing && !blocked`) with every exact
/// flag, for the lights `lights` (the ones given to `shadow_fragments`).
/// Returns the counts and the disagreeing (fragment, light) pairs.
pub fn compare(
    frags: &[Fragment],
    lights: &[Light],
    rays: &[Ray],
    blocked: &[bool],
    facing: &[bool],
) -> (Disagreements, Vec<(u32, u32)>) {
    let nlights = lights.len();
    let mut lit: Vec<bool> = facing.to_vec();
    for (r, &b) in rays.iter().zip(blocked) {
        if b {
            lit[r.fragment as usize * nlights + r.light as usize] = false;
        }
    }
    let mut d = Disagreements::default();
    let mut which = Vec::new();
    for (fi, f) in frags.iter().enumerate() {
        for (li, light) in lights.iter().enumerate() {
            let k = fi * nlights + li;
            if facing[k] != (light.eval(f.support()) > 0) {
                d.facing += 1;
            }
            let (base, exact) = (lit[k], f.lit()[li]);
            if base != exact {
                if base {
                    d.false_lit += 1;
                } else {
                    d.false_shadow += 1;
                }
                which.push((fi as u32, li as u32));
            }
        }
    }
    (d, which)
}

// ---------------------------------------------------------------------------
// Clocks: the machine the figures come from is shared, so besides wall time
// we measure the time the benchmarking thread spent on a CPU.

/// Time on a CPU of the calling thread (user and kernel), from
/// `/proc/thread-self/schedstat` (Linux). Its resolution is the
/// scheduler tick (4 ms at `HZ = 250`). `None` where unavailable.
pub fn thread_cpu() -> Option<Duration> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: u64 = s.split_whitespace().next()?.parse().ok()?;
    Some(Duration::from_nanos(ns))
}

/// Wall and CPU time of one step.
#[derive(Clone, Copy, Debug, Default)]
pub struct Span {
    pub wall: Duration,
    pub cpu: Option<Duration>,
}

impl Span {
    /// Runs `f` once, timing it.
    pub fn time<T>(f: impl FnOnce() -> T) -> (T, Span) {
        let (c, t) = (thread_cpu(), Instant::now());
        let out = f();
        let wall = t.elapsed();
        let cpu = match (c, thread_cpu()) {
            (Some(a), Some(b)) => Some(b.saturating_sub(a)),
            _ => None,
        };
        (out, Span { wall, cpu })
    }

    /// The CPU time where known and long enough to be resolved (ten
    /// ticks), else the wall time.
    pub fn best(&self) -> Duration {
        match self.cpu {
            Some(c) if c >= Duration::from_millis(40) => c,
            _ => self.wall,
        }
    }
}

impl std::fmt::Display for Span {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:.4} s", self.wall.as_secs_f64())?;
        if let Some(c) = self.cpu {
            write!(f, " (cpu {:.4} s)", c.as_secs_f64())?;
        }
        Ok(())
    }
}

/// The criterion measurement of the `shadows` bench: the benchmarking
/// thread's CPU time ([`thread_cpu`]) when available, so that waiting for
/// a core on a loaded machine is not counted; wall time with
/// `SVBSP_BENCH_CLOCK=wall` or where `/proc/thread-self/schedstat` is
/// missing.
pub struct Clock {
    cpu: bool,
}

impl Clock {
    pub fn from_env() -> Clock {
        let wall = std::env::var("SVBSP_BENCH_CLOCK").is_ok_and(|v| v == "wall");
        Clock {
            cpu: !wall && thread_cpu().is_some(),
        }
    }

    pub fn name(&self) -> &'static str {
        if self.cpu {
            "thread CPU time"
        } else {
            "wall time"
        }
    }
}

impl criterion::measurement::Measurement for Clock {
    type Intermediate = (Instant, Duration);
    type Value = Duration;

    fn start(&self) -> (Instant, Duration) {
        let c = if self.cpu {
            thread_cpu().unwrap_or_default()
        } else {
            Duration::ZERO
        };
        (Instant::now(), c)
    }
    fn end(&self, (t, c): (Instant, Duration)) -> Duration {
        if self.cpu {
            thread_cpu().unwrap_or(c).saturating_sub(c)
        } else {
            t.elapsed()
        }
    }
    fn add(&self, a: &Duration, b: &Duration) -> Duration {
        *a + *b
    }
    fn zero(&self) -> Duration {
        Duration::ZERO
    }
    fn to_f64(&self, v: &Duration) -> f64 {
        v.as_nanos() as f64
    }
    fn formatter(&self) -> &dyn criterion::measurement::ValueFormatter {
        &NsFormatter
    }
}

/// Formats nanoseconds like criterion's wall-time formatter.
struct NsFormatter;

impl criterion::measurement::ValueFormatter for NsFormatter {
    fn scale_values(&self, ns: f64, values: &mut [f64]) -> &'static str {
        let (factor, unit) = if ns < 1e3 {
            (1.0, "ns")
        } else if ns < 1e6 {
            (1e-3, "µs")
        } else if ns < 1e9 {
            (1e-6, "ms")
        } else {
            (1e-9, "s")
        };
        for v in values {
            *v *= factor;
        }
        unit
    }

    fn scale_throughputs(
        &self,
        typical: f64,
        throughput: &criterion::Throughput,
        values: &mut [f64],
    ) -> &'static str {
        use criterion::Throughput as T;
        let n = match *throughput {
            T::Bits(n) | T::Bytes(n) | T::BytesDecimal(n) | T::Elements(n) => n,
            T::ElementsAndBytes { elements, .. } => elements,
        } as f64;
        let per_s = n * 1e9 / typical;
        let (div, unit) = if per_s < 1e3 {
            (1.0, " elem/s")
        } else if per_s < 1e6 {
            (1e3, "Kelem/s")
        } else if per_s < 1e9 {
            (1e6, "Melem/s")
        } else {
            (1e9, "Gelem/s")
        };
        for v in values {
            *v = n * 1e9 / *v / div;
        }
        unit
    }

    fn scale_for_machines(&self, _values: &mut [f64]) -> &'static str {
        "ns"
    }
}

// ---------------------------------------------------------------------------
// One-shot measurement of a whole row of the table.

/// Figures of one scene, one option set, one light set.
pub struct Row {
    pub name: String,
    pub input: usize,
    pub lights: usize,
    pub options: &'static str,
    pub build: Span,
    pub depth: usize,
    pub stats: ShadowStats,
    pub shadows: Span,
    pub bvh_build: Span,
    pub bvh_nodes: usize,
    pub rays: usize,
    pub eps: f64,
    pub cast: Span,
    pub disagree: Disagreements,
}

impl Row {
    pub fn print(&self) {
        eprintln!(
            "{} ({} lights, {}): {} input polygons, {} BSP polygons (depth {}), build {}; \
             {} fragments, {} shadow-tree nodes, shadow_fragments {}; \
             BVH {} nodes built in {}, {} rays (eps {}) in {} ({:.2} Mrays/s), \
             {} disagreements ({} false lit, {} false shadow), {} facing-test mismatches",
            self.name,
            self.lights,
            self.options,
            self.input,
            self.stats.polygons,
            self.depth,
            self.build,
            self.stats.fragments,
            self.stats.shadow_nodes,
            self.shadows,
            self.bvh_nodes,
            self.bvh_build,
            self.rays,
            self.eps,
            self.cast,
            self.rays as f64 / self.cast.best().as_secs_f64() / 1e6,
            self.disagree.total(),
            self.disagree.false_lit,
            self.disagree.false_shadow,
            self.disagree.facing,
        );
    }
}

/// Builds and shadows once, timing and printing each step (no baseline).
pub fn measure_shadows(p: &Prepared, cut: bool, nlights: usize) {
    let (tree, build) = Span::time(|| BspTree::build(p.polys.clone(), &build_options(cut)));
    let ((_, stats), shadows) =
        Span::time(|| shadow_fragments(&tree, &p.lights[..nlights]).expect("lights on the grid"));
    eprintln!(
        "{} ({nlights} lights, {}): {} input polygons, {} BSP polygons, build {build}; \
         {} fragments, {} shadow-tree nodes, shadow_fragments {shadows}",
        p.name,
        options_name(cut),
        p.polys.len(),
        stats.polygons,
        stats.fragments,
        stats.shadow_nodes,
    );
}

/// Builds, shadows and casts once, timing each step.
pub fn measure(p: &Prepared, cut: bool, nlights: usize, eps: f64) -> (Row, BspTree, Vec<Fragment>) {
    let lights = &p.lights[..nlights];
    let (tree, build) = Span::time(|| BspTree::build(p.polys.clone(), &build_options(cut)));
    let depth = tree.stats().depth;
    let ((frags, stats), shadows) =
        Span::time(|| shadow_fragments(&tree, lights).expect("lights on the grid"));
    let tris = triangles(&p.polys);
    let (bvh, bvh_build) = Span::time(|| Bvh::build(&tris));
    let (rays, facing) = shadow_rays(&frags, &p.lights_f64[..nlights], eps);
    let (blocked, cast_t) = Span::time(|| cast(&bvh, &rays));
    let (disagree, _) = compare(&frags, lights, &rays, &blocked, &facing);
    let row = Row {
        name: p.name.clone(),
        input: p.polys.len(),
        lights: nlights,
        options: options_name(cut),
        build,
        depth,
        stats,
        shadows,
        bvh_build,
        bvh_nodes: bvh.len(),
        rays: rays.len(),
        eps,
        cast: cast_t,
        disagree,
    };
    (row, tree, frags)
}
