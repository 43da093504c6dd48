//! A bounding-volume hierarchy over the scene's prims, for per-pixel rays:
//! the visibility ray caster and the shadow rays.
//!
//! Axis-aligned boxes split at the median centroid along the longest axis
//! of the centroids' box, up to [`LEAF`] items per leaf. A prim is tested
//! as the fan of its triangles, by Möller–Trumbore in `f64`. The same
//! hierarchy over plain triangles ([`TriangleBvh`]) is the ray-pass
//! baseline of the `svbsp` benches.

use glam::DVec3;

use crate::RasterScene;

/// Prims per leaf at most.
const LEAF: usize = 4;

#[derive(Clone, Copy, Debug)]
struct Node {
    lo: DVec3,
    hi: DVec3,
    /// Leaf: first item; inner node: left child (right is `start + 1`).
    start: u32,
    /// Leaf: item count; inner node: 0.
    count: u32,
}

/// The hierarchy over items given by their boxes; leaves list item
/// indices.
pub(crate) struct Bvh {
    nodes: Vec<Node>,
    items: Vec<u32>,
}

impl Bvh {
    /// Builds the hierarchy over every prim of `scene`.
    pub(crate) fn new(scene: &RasterScene) -> Bvh {
        let (lo, hi): (Vec<DVec3>, Vec<DVec3>) = (0..scene.len())
            .map(|i| {
                scene
                    .prim(i)
                    .iter()
                    .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(l, h), p| {
                        (l.min(*p), h.max(*p))
                    })
            })
            .unzip();
        Bvh::from_boxes(&lo, &hi)
    }

    /// Builds the hierarchy over items with boxes `lo[i]..hi[i]`.
    fn from_boxes(lo: &[DVec3], hi: &[DVec3]) -> Bvh {
        let n = lo.len();
        let cen: Vec<DVec3> = (0..n).map(|i| (lo[i] + hi[i]) * 0.5).collect();
        let mut idx: Vec<u32> = (0..n as u32).collect();
        let empty = Node {
            lo: DVec3::ZERO,
            hi: DVec3::ZERO,
            start: 0,
            count: 0,
        };
        let mut nodes = vec![empty];
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
            nodes.push(empty);
            nodes.push(empty);
            nodes[ni].start = left as u32;
            nodes[ni].count = 0;
            stack.push((left, a, mid));
            stack.push((left + 1, mid, b));
        }
        Bvh { nodes, items: idx }
    }

    /// `true` if `hit(item)` holds for an item of a leaf whose box the
    /// ray `o + t d`, `t` in `(tmin, tmax)`, meets (any hit: boxes in no
    /// particular order).
    fn any(
        &self,
        o: DVec3,
        d: DVec3,
        tmin: f64,
        tmax: f64,
        mut hit: impl FnMut(u32) -> bool,
    ) -> bool {
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
            if self.items[s..s + node.count as usize]
                .iter()
                .any(|&i| hit(i))
            {
                return true;
            }
        }
        false
    }

    /// Visits the leaves the ray `o + t d` may reach for `t` in
    /// `[0, tmax())`, nearer boxes first; boxes are widened by `pad(t)` at
    /// ray parameter `t`. `visit` gets the leaf's items and returns the
    /// new `tmax` (to stop early, return a value below every box).
    pub(crate) fn walk(
        &self,
        o: DVec3,
        d: DVec3,
        mut tmax: f64,
        pad: impl Fn(f64) -> f64,
        mut visit: impl FnMut(&[u32]) -> f64,
    ) {
        let inv = d.recip();
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        stack.push(0);
        let enter = |n: &Node, tmax: f64| -> Option<f64> {
            let p = DVec3::splat(pad(tmax.min(1e300)));
            let t1 = (n.lo - p - o) * inv;
            let t2 = (n.hi + p - o) * inv;
            let tn = t1.min(t2).max_element().max(0.0);
            let tf = t1.max(t2).min_element().min(tmax);
            // NaN (a zero direction component on a slab's plane) keeps the box
            if tn > tf { None } else { Some(tn) }
        };
        while let Some(ni) = stack.pop() {
            let n = &self.nodes[ni as usize];
            if enter(n, tmax).is_none() {
                continue;
            }
            if n.count > 0 {
                let s = n.start as usize;
                tmax = visit(&self.items[s..s + n.count as usize]);
                continue;
            }
            let (a, b) = (n.start, n.start + 1);
            let ta = enter(&self.nodes[a as usize], tmax);
            let tb = enter(&self.nodes[b as usize], tmax);
            match (ta, tb) {
                (Some(x), Some(y)) => {
                    if x <= y {
                        stack.push(b);
                        stack.push(a);
                    } else {
                        stack.push(a);
                        stack.push(b);
                    }
                }
                (Some(_), None) => stack.push(a),
                (None, Some(_)) => stack.push(b),
                (None, None) => {}
            }
        }
    }

    /// `true` if some prim other than `skip` meets the segment `o + t d`,
    /// `t` in `(tmin, tmax)` (any hit).
    pub(crate) fn occluded(
        &self,
        scene: &RasterScene,
        o: DVec3,
        d: DVec3,
        tmin: f64,
        tmax: f64,
        skip: u32,
    ) -> bool {
        self.any(o, d, tmin, tmax, |i| {
            i != skip && prim_hit(scene.prim(i as usize), o, d, tmin, tmax)
        })
    }
}

/// A BVH over triangles for any-hit shadow rays: the renderer's
/// alternative to exact shadows, also the baseline of the `svbsp` benches.
///
/// ```
/// use glam::DVec3;
/// use shadow_raster::TriangleBvh;
/// let roof = [DVec3::new(-1.0, -1.0, 1.0), DVec3::new(1.0, -1.0, 1.0), DVec3::new(0.0, 1.0, 1.0)];
/// let bvh = TriangleBvh::build(&[roof]);
/// assert!(bvh.occluded(DVec3::ZERO, DVec3::Z, 0.0, 2.0));
/// assert!(!bvh.occluded(DVec3::ZERO, DVec3::Z, 0.0, 0.5));
/// ```
pub struct TriangleBvh {
    bvh: Bvh,
    tris: Vec<[DVec3; 3]>,
}

impl TriangleBvh {
    /// Median-split hierarchy over `tris`.
    pub fn build(tris: &[[DVec3; 3]]) -> TriangleBvh {
        let lo: Vec<DVec3> = tris.iter().map(|t| t[0].min(t[1]).min(t[2])).collect();
        let hi: Vec<DVec3> = tris.iter().map(|t| t[0].max(t[1]).max(t[2])).collect();
        TriangleBvh {
            bvh: Bvh::from_boxes(&lo, &hi),
            tris: tris.to_vec(),
        }
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.bvh.nodes.len()
    }

    /// `true` if the hierarchy has no triangle.
    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// `true` if some triangle meets the ray `o + t d` for `t` in
    /// `(tmin, tmax)` (edges included; any hit, no ordering).
    pub fn occluded(&self, o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> bool {
        self.bvh.any(o, d, tmin, tmax, |i| {
            let [a, b, c] = self.tris[i as usize];
            tri_hit(a, b, c, o, d, tmin, tmax)
        })
    }
}

/// Does the ray meet the convex polygon `pts` (its triangle fan, edges
/// included) at a parameter in `(tmin, tmax)`?
#[inline]
pub(crate) fn prim_hit(pts: &[DVec3], o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> bool {
    (1..pts.len() - 1).any(|k| tri_hit(pts[0], pts[k], pts[k + 1], o, d, tmin, tmax))
}

/// Möller–Trumbore in `f64`.
#[inline]
fn tri_hit(v0: DVec3, v1: DVec3, v2: DVec3, o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> bool {
    let (e1, e2) = (v1 - v0, v2 - v0);
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 {
        return false;
    }
    let inv = 1.0 / det;
    let s = o - v0;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let q = s.cross(e1);
    let v = d.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    let t = e2.dot(q) * inv;
    t > tmin && t < tmax
}
