//! An image's wanted pixels as exact polygons: the boundary loops of each
//! 4-connected component (its outer loop and its holes), with corners at
//! pixel corners, and the component's triangulation over those corners.
//!
//! Pixel `(c, r)` is the unit square `[c, c+1] × [r, r+1]` of the plane's
//! `(a, b)` coordinates. Every loop keeps its component on its left (outer
//! loops turn counter-clockwise, holes clockwise). Where two wanted pixels
//! touch only at a corner, they are apart (4-connectivity): the boundary
//! turns left there, so each loop passes such a corner on its own, and a
//! mesh made from the loops gives each passage its own vertex.

use earcut::int::EarcutI32;

/// The largest image side: the triangulation's exact integer range.
pub(crate) const MAX_SIDE: u32 = 1 << 19;

/// Which pixels are wanted shadow, row by row (row 0 first).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Mask {
    /// Pixels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// `wanted[r * width + c]`.
    pub wanted: Vec<bool>,
}

impl Mask {
    /// Whether pixel `(c, r)` is wanted (`false` outside the image).
    pub fn at(&self, c: i64, r: i64) -> bool {
        (0..self.width as i64).contains(&c)
            && (0..self.height as i64).contains(&r)
            && self.wanted[(r * self.width as i64 + c) as usize]
    }

    /// How many pixels are wanted.
    pub fn count(&self) -> usize {
        self.wanted.iter().filter(|&&w| w).count()
    }
}

/// One component of a mask: its corners (outer loop first, then each
/// hole), where each loop starts, and triangles over the corners
/// (counter-clockwise), which tile the component exactly.
#[derive(Clone, Debug)]
pub(crate) struct Component {
    pub(crate) corners: Vec<[i32; 2]>,
    /// Start of each loop in `corners` (the first is 0).
    pub(crate) loops: Vec<usize>,
    pub(crate) triangles: Vec<[u32; 3]>,
}

impl Component {
    /// The loops' corner index ranges.
    pub(crate) fn loop_ranges(&self) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
        let ends = self.loops[1..].iter().copied().chain([self.corners.len()]);
        self.loops.iter().copied().zip(ends).map(|(s, e)| s..e)
    }
}

/// Unit steps: `+a`, `+b`, `−a`, `−b` (counter-clockwise order).
const STEP: [(i64, i64); 4] = [(1, 0), (0, 1), (-1, 0), (0, -1)];

/// The boundary loops of `mask` (corners only, region on the left).
fn loops(mask: &Mask) -> Vec<Vec<[i32; 2]>> {
    let (w, h) = (mask.width as i64, mask.height as i64);
    let id = |x: i64, y: i64| (y * (w + 1) + x) as usize;
    // per vertex, the directions of the boundary edges leaving it
    let mut out = vec![0u8; ((w + 1) * (h + 1)) as usize];
    for r in 0..h {
        for c in 0..w {
            if !mask.at(c, r) {
                continue;
            }
            if !mask.at(c, r - 1) {
                out[id(c, r)] |= 1 << 0;
            }
            if !mask.at(c + 1, r) {
                out[id(c + 1, r)] |= 1 << 1;
            }
            if !mask.at(c, r + 1) {
                out[id(c + 1, r + 1)] |= 1 << 2;
            }
            if !mask.at(c - 1, r) {
                out[id(c, r + 1)] |= 1 << 3;
            }
        }
    }
    let mut all = Vec::new();
    for start in 0..out.len() {
        while out[start] != 0 {
            let (sx, sy) = ((start as i64) % (w + 1), (start as i64) / (w + 1));
            let first = out[start].trailing_zeros() as usize;
            out[start] &= !(1 << first);
            let (mut x, mut y, mut dir) = (sx, sy, first);
            let mut corners: Vec<[i32; 2]> = Vec::new();
            loop {
                x += STEP[dir].0;
                y += STEP[dir].1;
                let here = id(x, y);
                let mut choices = out[here];
                if here == start {
                    choices |= 1 << first;
                }
                // two ways on: turn left (the same pixel stays on the left)
                let next = if choices.count_ones() >= 2 {
                    (dir + 1) % 4
                } else {
                    choices.trailing_zeros() as usize
                };
                if next != dir {
                    corners.push([x as i32, y as i32]);
                }
                if here == start && next == first {
                    break;
                }
                out[here] &= !(1 << next);
                dir = next;
            }
            all.push(corners);
        }
    }
    all
}

/// Twice the signed area of a loop.
fn area2(corners: &[[i32; 2]]) -> i64 {
    let n = corners.len();
    (0..n)
        .map(|i| {
            let ([x0, y0], [x1, y1]) = (corners[i], corners[(i + 1) % n]);
            i64::from(x0) * i64::from(y1) - i64::from(x1) * i64::from(y0)
        })
        .sum()
}

/// The pixel on the left of a loop's first edge (from its last corner to
/// its first).
fn left_pixel(corners: &[[i32; 2]]) -> (i64, i64) {
    let [x0, y0] = corners[corners.len() - 1].map(i64::from);
    let [x1, y1] = corners[0].map(i64::from);
    let (dx, dy) = ((x1 - x0).signum(), (y1 - y0).signum());
    // the unit edge ending at the first corner
    let (x, y) = (x1 - dx, y1 - dy);
    match (dx, dy) {
        (1, 0) => (x, y),
        (0, 1) => (x - 1, y),
        (-1, 0) => (x - 1, y - 1),
        _ => (x, y - 1),
    }
}

/// The 4-connected components of `mask`: per pixel its component, or
/// `u32::MAX`.
fn components(mask: &Mask) -> Vec<u32> {
    let (w, h) = (mask.width as i64, mask.height as i64);
    let mut label = vec![u32::MAX; mask.wanted.len()];
    let mut next = 0;
    let mut stack = Vec::new();
    for start in 0..mask.wanted.len() {
        if !mask.wanted[start] || label[start] != u32::MAX {
            continue;
        }
        label[start] = next;
        stack.push(start);
        while let Some(p) = stack.pop() {
            let (c, r) = ((p as i64) % w, (p as i64) / w);
            for (dc, dr) in STEP {
                let (nc, nr) = (c + dc, r + dr);
                if nc < 0 || nr < 0 || nc >= w || nr >= h {
                    continue;
                }
                let q = (nr * w + nc) as usize;
                if mask.wanted[q] && label[q] == u32::MAX {
                    label[q] = next;
                    stack.push(q);
                }
            }
        }
        next += 1;
    }
    label
}

/// Why a mask's region cannot be made polygons.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum RegionError {
    /// An image side above [`MAX_SIDE`].
    TooLarge,
    /// The triangulation of the component holding this pixel does not
    /// tile it.
    Triangulation((i64, i64)),
}

/// The components of `mask`'s wanted region, each triangulated and
/// checked: its triangles turn counter-clockwise and their areas add up
/// to its pixels exactly. With `simplify`, the loops are first simplified
/// within that many pixels ([`super::simplify`]), and the triangles add
/// up to the simplified loops' area.
pub(crate) fn region(mask: &Mask, simplify: Option<f64>) -> Result<Vec<Component>, RegionError> {
    if mask.width > MAX_SIDE || mask.height > MAX_SIDE {
        return Err(RegionError::TooLarge);
    }
    let label = components(mask);
    let count = label
        .iter()
        .filter(|&&l| l != u32::MAX)
        .max()
        .map_or(0, |&m| m as usize + 1);
    let mut pixels = vec![0i64; count];
    for &l in label.iter().filter(|&&l| l != u32::MAX) {
        pixels[l as usize] += 1;
    }
    // per component: its outer loop, then its holes
    let mut outer: Vec<Option<Vec<[i32; 2]>>> = vec![None; count];
    let mut holes: Vec<Vec<Vec<[i32; 2]>>> = vec![Vec::new(); count];
    let mut all = loops(mask);
    // each loop's component, from its pixels before any simplification
    let of: Vec<usize> = (all.iter())
        .map(|l| {
            let (c, r) = left_pixel(l);
            label[(r * mask.width as i64 + c) as usize] as usize
        })
        .collect();
    if let Some(tolerance) = simplify {
        super::simplify::simplify(&mut all, tolerance);
    }
    for (l, k) in all.into_iter().zip(of) {
        if area2(&l) > 0 {
            outer[k] = Some(l);
        } else {
            holes[k].push(l);
        }
    }
    let mut earcut = EarcutI32::new();
    let mut out = Vec::with_capacity(count);
    for (k, (o, hs)) in outer.into_iter().zip(holes).enumerate() {
        let o = o.expect("every component has an outer loop");
        let pixel = left_pixel(&o);
        let mut corners = o;
        let mut loops = vec![0];
        for h in hs {
            loops.push(corners.len());
            corners.extend(h);
        }
        let mut tri: Vec<u32> = Vec::new();
        let holes: Vec<u32> = loops[1..].iter().map(|&s| s as u32).collect();
        earcut.earcut(corners.iter().copied(), &holes, &mut tri);
        let triangles: Vec<[u32; 3]> = tri.chunks(3).map(|t| [t[0], t[1], t[2]]).collect();
        // earcut's triangles may turn either way: counter-clockwise here
        let mut ccw = Vec::with_capacity(triangles.len());
        for t in triangles {
            let a = area2(&t.map(|i| corners[i as usize]));
            match a.signum() {
                1 => ccw.push(t),
                -1 => ccw.push([t[0], t[2], t[1]]),
                _ => {} // no area: nothing to tile (its sides are mended)
            }
        }
        let ccw = mend_t_junctions(&corners, ccw);
        let sum: i64 = (ccw.iter())
            .map(|t| area2(&t.map(|i| corners[i as usize])))
            .sum();
        let loops_area2: i64 = loops
            .iter()
            .zip(loops[1..].iter().chain([&corners.len()]))
            .map(|(&s, &e)| area2(&corners[s..e]))
            .sum();
        if sum != loops_area2 || simplify.is_none() && sum != 2 * pixels[k] {
            return Err(RegionError::Triangulation(pixel));
        }
        out.push(Component {
            corners,
            loops,
            triangles: ccw,
        });
    }
    Ok(out)
}

/// Earcut's triangles tile the component, but where corners lie in a
/// line (a hole or another passage of the loop touching it, triangles of
/// no area) a triangle's side may pass through a corner, which the walls
/// along the loop have as a vertex (a T-junction: the cone would not be
/// closed). Each triangle with corners inside its sides is cut into
/// triangles between all its corners; those of no area are left out.
fn mend_t_junctions(corners: &[[i32; 2]], triangles: Vec<[u32; 3]>) -> Vec<[u32; 3]> {
    use std::collections::HashMap;
    let at = |i: u32| corners[i as usize];
    // (the first of corners at one place)
    let index: HashMap<[i32; 2], u32> = (corners.iter().enumerate().rev())
        .map(|(i, &c)| (c, i as u32))
        .collect();
    let mut out = Vec::with_capacity(triangles.len());
    for t in triangles {
        let mut polygon = Vec::with_capacity(3);
        for k in 0..3 {
            let (a, b) = (at(t[k]), at(t[(k + 1) % 3]));
            polygon.push(t[k]);
            // the side's grid points, in order from a to b
            let d = [b[0] - a[0], b[1] - a[1]];
            let g = gcd(d[0].unsigned_abs(), d[1].unsigned_abs()) as i32;
            let step = [d[0] / g.max(1), d[1] / g.max(1)];
            let on_side = (1..g).map(|s| [a[0] + s * step[0], a[1] + s * step[1]]);
            polygon.extend(on_side.filter_map(|p| index.get(&p).copied()));
        }
        if polygon.len() == 3 {
            if area2(&t.map(at)) > 0 {
                out.push(t);
            }
            continue;
        }
        // a convex polygon with corners along its sides: clip ears at
        // its turning corners whose chords hold no corner
        while polygon.len() > 3 {
            let n = polygon.len();
            let ear = (0..n).find(|&k| {
                let (u, v, w) = (polygon[(k + n - 1) % n], polygon[k], polygon[(k + 1) % n]);
                area2(&[at(u), at(v), at(w)]) > 0
                    && !(polygon.iter())
                        .any(|&x| x != u && x != w && on_segment(at(u), at(x), at(w)))
            });
            let Some(k) = ear else { break };
            out.push([polygon[(k + n - 1) % n], polygon[k], polygon[(k + 1) % n]]);
            polygon.remove(k);
        }
        if let [a, b, c] = polygon[..]
            && area2(&[at(a), at(b), at(c)]) > 0
        {
            out.push([a, b, c]);
        }
    }
    out
}

/// The greatest common divisor.
fn gcd(a: u32, b: u32) -> u32 {
    if b == 0 { a } else { gcd(b, a % b) }
}

/// Whether `m` lies on the closed segment `ab`.
fn on_segment(a: [i32; 2], m: [i32; 2], b: [i32; 2]) -> bool {
    use super::simplify::{orient, within};
    orient(a, m, b) == 0 && within(a, b, m)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mask(rows: &[&str]) -> Mask {
        Mask {
            width: rows[0].len() as u32,
            height: rows.len() as u32,
            wanted: rows
                .iter()
                .flat_map(|r| r.chars().map(|c| c == '#'))
                .collect(),
        }
    }

    #[test]
    fn a_ring_is_one_component_with_a_hole() {
        let m = mask(&["#####", "#...#", "#.#.#", "#...#", "#####"]);
        let r = region(&m, None).unwrap();
        assert_eq!(r.len(), 2); // the ring and the island in it
        let ring = r.iter().find(|c| c.loops.len() == 2).unwrap();
        assert_eq!(ring.corners.len(), 8);
        let island = r.iter().find(|c| c.loops.len() == 1).unwrap();
        assert_eq!(island.corners.len(), 4);
    }

    #[test]
    fn pixels_touching_at_a_corner_are_apart() {
        // a diagonal, and a C whose tips touch at a corner
        let m = mask(&["#..", ".#.", "..#"]);
        let r = region(&m, None).unwrap();
        assert_eq!(r.len(), 3);
        assert!(
            r.iter()
                .all(|c| c.loops.len() == 1 && c.triangles.len() == 2)
        );
        let c = mask(&["###.", "#...", "#..#", "####"]);
        let r = region(&c, None).unwrap();
        assert_eq!(r.len(), 1);
        // the tips touch the body at corners: one loop, no hole
        assert_eq!(r[0].loops.len(), 1);
    }

    #[test]
    fn no_triangle_side_passes_through_a_corner() {
        // earcut's triangles along y = 6 here spanned corners of the loop
        // and of the hole (T-junctions: the cone was not closed)
        let rows = [
            ".#.#.#..", "..##.###", "...#.###", "##.#...#", "..#.###.", "..##.###", "#..###.#",
            "##.#.###",
        ];
        let m = mask(&rows);
        for simplify in [None, Some(1.5)] {
            for c in region(&m, simplify).unwrap() {
                for t in &c.triangles {
                    for k in 0..3 {
                        let (a, b) = (c.corners[t[k] as usize], c.corners[t[(k + 1) % 3] as usize]);
                        let through =
                            (c.corners.iter()).any(|&p| p != a && p != b && on_segment(a, p, b));
                        assert!(!through, "{a:?}-{b:?} passes through a corner");
                    }
                }
            }
        }
    }

    #[test]
    fn every_pixel_is_covered_once() {
        // a pseudo-random mask: the triangulation's check passes
        let mut state = 12345u32;
        let rows: Vec<String> = (0..40)
            .map(|_| {
                (0..50)
                    .map(|_| {
                        state = state.wrapping_mul(1_103_515_245).wrapping_add(12_345);
                        if state >> 16 & 3 != 0 { '#' } else { '.' }
                    })
                    .collect()
            })
            .collect();
        let rows: Vec<&str> = rows.iter().map(String::as_str).collect();
        let m = mask(&rows);
        let r = region(&m, None).unwrap();
        let tiled: i64 = r
            .iter()
            .flat_map(|c| {
                c.triangles
                    .iter()
                    .map(|t| area2(&t.map(|i| c.corners[i as usize])))
            })
            .sum();
        assert_eq!(tiled, 2 * m.count() as i64);
    }
}
