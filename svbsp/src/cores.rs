//! Inner occluders: convex polygons certified to lie strictly inside a
//! closed part of the scene, which decide its joint umbra.
//!
//! Under a closed mesh the light is hidden by many faces together, and
//! the per-occluder test of [`crate::area`] leaves such points undecided.
//! A convex polygon `Q` strictly inside the solid that a certified part
//! bounds ([`bsp_core::certify_solid_parts`]) hides nothing the part does
//! not: a segment from a light point outside the solid to a point `q` of
//! `Q` (inside it) crosses the part's boundary, so a segment through `Q`
//! between a receiver and the light meets one of the part's faces, but for
//! segments of zero area (grazing an edge). So `Q`'s umbra (behind it from
//! every light corner: the light is convex, so all of it is hidden) is
//! umbra of the scene, and an undecided piece inside it is umbra. These
//! are the "virtual occluders" of Koltun, Chrysanthou and Cohen-Or (2000);
//! here they are made exact.
//!
//! Where `Q` is put is a guess in `f64`: slices of the part across the
//! light's main axis, in each the corners of a convex polygon around the
//! point furthest inside the slice, rounded to the grid. Whether it lies
//! inside is decided exactly: no triangle of the part's faces meets it
//! (an exact separating-axis test), and the part winds once around one of
//! its corners (a ray along the axis, crossings counted by exact signs).
//! A guess that fails is shrunk, then dropped. Only undecided pieces are
//! cut by inner occluders, and only by their umbra volumes: lit and
//! penumbra are as before, and a light that may reach inside the part's
//! box gives the part no inner occluders.

use bsp_core::internals::triangles_disjoint;
use bsp_core::{GridPoint, SolidParts};
use rayon::prelude::*;

use crate::area::{AreaLight, Occluder, Regions};
use crate::boxes::{Box3, CellGrid, EMPTY, Reach, grid_box, overlap};
use crate::light::Light;

/// Slices of a part at most, evenly spaced across its box along the axis.
const SLICES: usize = 16;
/// Rays from a slice's centre to its boundary: the guessed polygon's
/// corners (an umbra volume has a plane per corner: few are cheap).
const RAYS: usize = 16;
/// Inner occluders a slice gives at most.
const PER_SLICE: usize = 3;
/// The raster a slice's centre is sought on.
const RASTER: usize = 24;
/// Parts of fewer faces get no inner occluders: a few convex faces cast
/// their umbra one by one already (a cost rule, not a correctness one).
const MIN_FACES: usize = 24;
/// A part gets at most one inner occluder per this many of its faces:
/// each cuts the pieces round its umbra into more fragments, which a
/// scene of many small closed parts pays for in time (a cost rule).
const FACES_PER_CORE: usize = 16;
/// Shares of the distance to the slice's boundary tried in turn.
const SCALES: [f64; 3] = [0.98, 0.8, 0.5];

/// The inner occluders of the certified parts of `faces` (`solids`, the
/// parts of the faces' polygons) in slices across axis `axis`, each with
/// its part's box of grid points.
pub(crate) fn inner_occluders(
    faces: &[Occluder],
    solids: &SolidParts,
    axis: usize,
) -> Vec<(Occluder, Box3)> {
    let parts = certified_parts(faces, solids, MIN_FACES);
    // per part: its slices, and how many inner occluders each may give
    let jobs: Vec<(usize, i64, usize)> = parts
        .iter()
        .enumerate()
        .flat_map(|(p, (members, b))| {
            let budget = (members.len() / FACES_PER_CORE).max(1);
            let slices = budget.min(SLICES) as i64;
            let each = (budget / slices as usize).clamp(1, PER_SLICE);
            let (lo, hi) = (b[axis][0], b[axis][1]);
            (1..=slices)
                .map(move |s| (p, lo + (hi - lo) * s / (slices + 1), each))
                .filter(move |&(_, k, _)| lo < k && k < hi)
        })
        .collect();
    // each part's faces, and its triangles indexed for the exact tests
    let indexed: Vec<(Vec<&[GridPoint]>, PartShadows)> = parts
        .par_iter()
        .map(|(members, _)| {
            let part: Vec<&[GridPoint]> = members.iter().map(|&i| faces[i].corners()).collect();
            let shadows = PartShadows::new(&part, axis);
            (part, shadows)
        })
        .collect();
    let mut cores: Vec<(Occluder, Box3)> = jobs
        .par_iter()
        .flat_map_iter(|&(p, k, each)| {
            let b = &parts[p].1;
            let (part, shadows) = &indexed[p];
            let found = inner_polygons((part, shadows), k, each);
            found
                .into_iter()
                .filter_map(move |q| Some((Occluder::new(&q).ok()?, *b)))
        })
        .collect();
    // the largest first: their umbrae take in whole pieces, which no
    // later one cuts again (a smaller one first would cut the pieces
    // round it into slivers the larger one then leaves apart); then in
    // the order of their corners, not of the parts' first faces: the
    // fragments do not depend on the faces' order
    let [u, v] = across(axis);
    let twice_area = |q: &Occluder| {
        let c = q.corners();
        (0..c.len())
            .map(|i| {
                let (a, b) = (c[i], c[(i + 1) % c.len()]);
                i64::from(a[u]) * i64::from(b[v]) - i64::from(a[v]) * i64::from(b[u])
            })
            .sum::<i64>()
            .abs()
    };
    cores.sort_by_cached_key(|(q, _)| (std::cmp::Reverse(twice_area(q)), q.corners().to_vec()));
    cores
}

/// Per light, the regions and reach of the inner occluders that can
/// decide its joint umbra ([`core_regions`]); the inner occluders of each
/// axis made once.
pub(crate) fn cores_per_light(
    lights: &[AreaLight],
    faces: &[Occluder],
    solids: &SolidParts,
) -> Vec<LightCores> {
    let Some(scene) = crate::near::scene_box(faces) else {
        return lights.iter().map(|_| LightCores::default()).collect();
    };
    let mut by_axis: [Option<Vec<(Occluder, Box3)>>; 3] = [None, None, None];
    lights
        .iter()
        .map(|l| {
            let Some(axis) = light_axis(l) else {
                return LightCores::default();
            };
            let cores = by_axis[axis].get_or_insert_with(|| inner_occluders(faces, solids, axis));
            let cores = core_regions(l, cores, scene);
            let boxes: Vec<Box3> = cores.iter().map(|(_, reach)| reach[1]).collect();
            let grid = (!cores.is_empty()).then(|| CellGrid::new(scene, &boxes));
            LightCores { cores, grid }
        })
        .collect()
}

/// One light's inner occluders ([`core_regions`]), and a grid of their
/// umbrae's boxes to find those near a face.
#[derive(Default)]
pub(crate) struct LightCores {
    cores: Vec<(Regions, Reach)>,
    grid: Option<CellGrid>,
}

/// The inner occluders of `cores` that may cut face `face`'s undecided
/// pieces: their umbra's box meets the face's, and the face is not
/// wholly outside their umbra.
pub(crate) fn cores_at<'r>(
    cores: &'r LightCores,
    face: &Occluder,
) -> impl Iterator<Item = (&'r Regions, Reach)> + use<'r> {
    let corners = face.corners();
    let b = grid_box(corners);
    // (in their order, whatever cells the face's box meets)
    let mut near = Vec::new();
    if let Some(grid) = &cores.grid {
        grid.visit(b, |i| near.push(i));
    }
    near.sort_unstable();
    near.dedup();
    near.retain(|&i| {
        let (r, reach) = &cores.cores[i as usize];
        overlap(&b, &reach[1])
            && r.umbra
                .as_ref()
                .is_some_and(|u| !crate::near::outside(corners, u))
    });
    near.into_iter().map(|i| {
        let (r, reach) = &cores.cores[i as usize];
        (r, *reach)
    })
}

/// The certified closed parts of `faces` of at least `min_faces` faces:
/// each its faces' indices and the box of their corners.
pub(crate) fn certified_parts(
    faces: &[Occluder],
    solids: &SolidParts,
    min_faces: usize,
) -> Vec<(Vec<usize>, Box3)> {
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); solids.len()];
    for i in 0..faces.len() {
        if solids.boundary(i).is_some() {
            members[solids.part(i)].push(i);
        }
    }
    members
        .into_iter()
        .filter(|m| !m.is_empty() && m.len() >= min_faces)
        .filter_map(|m| {
            // the certificate's box is the box of the part's corners
            let c = solids.boundary(m[0])?;
            let b = [0, 1, 2].map(|k| [i64::from(c.lo[k]), i64::from(c.hi[k])]);
            Some((m, b))
        })
        .collect()
}

/// The regions and reach of the inner occluders that can decide light
/// `light`'s joint umbra: the light lies outside the part's box, and the
/// occluder has an umbra. The reach's penumbra box is empty (they cut
/// only pieces that hide every light corner already).
pub(crate) fn core_regions(
    light: &AreaLight,
    cores: &[(Occluder, Box3)],
    scene: Box3,
) -> Vec<(Regions, Reach)> {
    let corners = light.corners();
    let points: Vec<GridPoint> = corners.iter().filter_map(Light::point).collect();
    cores
        .par_iter()
        .filter(|(_, part)| points.is_empty() || !overlap(&grid_box(&points), part))
        .filter_map(|(q, _)| {
            let r = light.regions(q)?;
            r.umbra.as_ref()?;
            let umbra = crate::near::umbra_box(corners, q.corners(), scene);
            Some((r, [EMPTY, umbra]))
        })
        .collect()
}

/// The axis along which light `light`'s inner occluders are sliced (the
/// largest component of its plane's normal, or of its first direction),
/// `None` for a light of one corner (a hidden point is umbra already).
pub(crate) fn light_axis(light: &AreaLight) -> Option<usize> {
    let corners = light.corners();
    if corners.len() < 2 {
        return None;
    }
    let d: [i64; 3] = match (light.plane(), corners[0]) {
        (Some(p), _) => p.normal(),
        (None, Light::Directional(d)) => d.map(i64::from),
        (None, Light::Point(_)) => return None,
    };
    (0..3).max_by_key(|&k| d[k].unsigned_abs())
}

/// The two axes across `axis`, in turn.
fn across(axis: usize) -> [usize; 2] {
    [(axis + 1) % 3, (axis + 2) % 3]
}

/// Convex polygons of grid corners in the plane `x[axis] = k`, each
/// certified to lie strictly inside the solid the closed part `part` (its
/// faces' corners) bounds: around the points furthest inside the slice,
/// each outside the polygons before it, at most `each`.
fn inner_polygons(
    (part, shadows): (&[&[GridPoint]], &PartShadows),
    k: i64,
    each: usize,
) -> Vec<Vec<GridPoint>> {
    let axis = shadows.axis;
    let segments = slice(part, axis, k);
    let mut out: Vec<Vec<GridPoint>> = Vec::new();
    let mut taken: Vec<Vec<[i32; 2]>> = Vec::new();
    if segments.len() < 3 {
        return out;
    }
    for centre in centres(&segments) {
        if out.len() == each {
            break;
        }
        if taken.iter().any(|h| holds(h, centre)) {
            continue;
        }
        if let Some((q, h)) = inner_polygon(shadows, k, &segments, centre) {
            out.push(q);
            taken.push(h);
        }
    }
    out
}

/// The convex polygon around `centre` (see [`inner_polygons`]), and its
/// corners in the slice's coordinates; `None` where no guess passes.
fn inner_polygon(
    shadows: &PartShadows,
    k: i64,
    segments: &[[[f64; 2]; 2]],
    centre: [f64; 2],
) -> Option<(Vec<GridPoint>, Vec<[i32; 2]>)> {
    let axis = shadows.axis;
    let reach: Vec<f64> = (0..RAYS)
        .map(|i| ray_reach(segments, centre, direction(i)))
        .collect::<Option<_>>()?;
    let [u, v] = across(axis);
    let k = i32::try_from(k).ok()?;
    SCALES.iter().find_map(|&s| {
        let r: Vec<f64> = reach.iter().map(|r| r * s).collect();
        let hull = hull(&convex_corners(centre, r))?;
        let q: Vec<GridPoint> = hull
            .iter()
            .map(|p| {
                let mut g = [0; 3];
                g[axis] = k;
                g[u] = p[0];
                g[v] = p[1];
                g
            })
            .collect();
        (shadows.placed(&q) == Some(1)).then_some((q, hull))
    })
}

/// Whether the convex counter-clockwise polygon `h` holds `x` (`f64`: a
/// guess only).
fn holds(h: &[[i32; 2]], x: [f64; 2]) -> bool {
    (0..h.len()).all(|i| {
        let (a, b) = (h[i].map(f64::from), h[(i + 1) % h.len()].map(f64::from));
        (b[0] - a[0]) * (x[1] - a[1]) - (b[1] - a[1]) * (x[0] - a[0]) >= 0.0
    })
}

/// The unit direction of ray `i` of [`RAYS`].
fn direction(i: usize) -> [f64; 2] {
    let t = std::f64::consts::TAU * i as f64 / RAYS as f64;
    [t.cos(), t.sin()]
}

/// The part's faces cut by the plane `x[axis] = k`, as segments in the
/// plane's two other coordinates (`f64`: a guess's material only).
fn slice(part: &[&[GridPoint]], axis: usize, k: i64) -> Vec<[[f64; 2]; 2]> {
    let [u, v] = across(axis);
    let mut out = Vec::new();
    for face in part {
        let mut points: Vec<[f64; 2]> = Vec::with_capacity(2);
        let n = face.len();
        for j in 0..n {
            let (a, b) = (face[j], face[(j + 1) % n]);
            let (ta, tb) = (i64::from(a[axis]) - k, i64::from(b[axis]) - k);
            if ta == 0 {
                points.push([f64::from(a[u]), f64::from(a[v])]);
            } else if (ta < 0) != (tb < 0) && tb != 0 {
                let t = ta as f64 / (ta - tb) as f64;
                let at = |c: usize| f64::from(a[c]) + t * f64::from(b[c] - a[c]);
                points.push([at(u), at(v)]);
            }
        }
        points.dedup();
        if let [p, q] = points[..] {
            out.push([p, q]);
        }
    }
    out
}

/// The raster points of the slice's box inside the slice (by even-odd
/// crossings of a ray along the first coordinate), furthest from its
/// boundary first.
fn centres(segments: &[[[f64; 2]; 2]]) -> Vec<[f64; 2]> {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in segments.iter().flatten() {
        for c in 0..2 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    let mut found: Vec<(f64, [f64; 2])> = Vec::new();
    for i in 0..RASTER {
        for j in 0..RASTER {
            let at =
                |c: usize, s: usize| lo[c] + (hi[c] - lo[c]) * (s as f64 + 0.5) / RASTER as f64;
            let x = [at(0, i), at(1, j)];
            let crossings = segments
                .iter()
                .filter(|[p, q]| {
                    (p[1] > x[1]) != (q[1] > x[1])
                        && p[0] + (x[1] - p[1]) * (q[0] - p[0]) / (q[1] - p[1]) > x[0]
                })
                .count();
            if crossings % 2 == 1 {
                let d = segments
                    .iter()
                    .map(|s| distance(x, s))
                    .fold(f64::INFINITY, f64::min);
                found.push((d, x));
            }
        }
    }
    found.sort_by(|a, b| b.0.total_cmp(&a.0));
    found.into_iter().map(|(_, x)| x).collect()
}

/// The distance from `x` to the segment `s`.
fn distance(x: [f64; 2], s: &[[f64; 2]; 2]) -> f64 {
    let [p, q] = s;
    let e = [q[0] - p[0], q[1] - p[1]];
    let w = [x[0] - p[0], x[1] - p[1]];
    let ee = e[0] * e[0] + e[1] * e[1];
    let t = if ee > 0.0 {
        ((w[0] * e[0] + w[1] * e[1]) / ee).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (w[0] - t * e[0]).hypot(w[1] - t * e[1])
}

/// How far the ray from `c` along `d` goes before it meets a segment;
/// `None` where it meets none.
fn ray_reach(segments: &[[[f64; 2]; 2]], c: [f64; 2], d: [f64; 2]) -> Option<f64> {
    let cross = |a: [f64; 2], b: [f64; 2]| a[0] * b[1] - a[1] * b[0];
    let mut best = f64::INFINITY;
    for [p, q] in segments {
        let e = [q[0] - p[0], q[1] - p[1]];
        let den = cross(d, e);
        if den == 0.0 {
            continue;
        }
        let w = [p[0] - c[0], p[1] - c[1]];
        let t = cross(w, e) / den;
        let s = cross(w, d) / den;
        if t > 0.0 && (0.0..=1.0).contains(&s) {
            best = best.min(t);
        }
    }
    best.is_finite().then_some(best)
}

/// The corners `c + r_i d_i`, each reflex one moved in along its ray onto
/// the chord of its neighbours until none is reflex.
fn convex_corners(c: [f64; 2], mut r: Vec<f64>) -> Vec<[f64; 2]> {
    let n = r.len();
    let at = |r: &[f64], i: usize| {
        let d = direction(i);
        [c[0] + r[i] * d[0], c[1] + r[i] * d[1]]
    };
    for _ in 0..4 * n {
        let mut moved = false;
        for i in 0..n {
            let (a, p, b) = (at(&r, (i + n - 1) % n), at(&r, i), at(&r, (i + 1) % n));
            let turn = (p[0] - a[0]) * (b[1] - p[1]) - (p[1] - a[1]) * (b[0] - p[0]);
            if turn >= 0.0 {
                continue;
            }
            // where the ray meets the chord a–b
            let d = direction(i);
            let e = [b[0] - a[0], b[1] - a[1]];
            let den = d[0] * e[1] - d[1] * e[0];
            let w = [a[0] - c[0], a[1] - c[1]];
            let t = (w[0] * e[1] - w[1] * e[0]) / den;
            if den != 0.0 && t.is_finite() && t >= 0.0 && t < r[i] {
                r[i] = t;
                moved = true;
            }
        }
        if !moved {
            break;
        }
    }
    (0..n).map(|i| at(&r, i)).collect()
}

/// The convex hull, counter-clockwise, of the points rounded to integers,
/// with no three corners on a line (exact); `None` where it has no area.
fn hull(points: &[[f64; 2]]) -> Option<Vec<[i32; 2]>> {
    let mut p: Vec<[i32; 2]> = points.iter().map(|q| q.map(|c| c.round() as i32)).collect();
    p.sort_unstable();
    p.dedup();
    let turn = |o: [i32; 2], a: [i32; 2], b: [i32; 2]| {
        let (o, a, b) = (o.map(i64::from), a.map(i64::from), b.map(i64::from));
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut h: Vec<[i32; 2]> = Vec::new();
    for pass in 0..2 {
        let start = h.len();
        let it: Box<dyn Iterator<Item = &[i32; 2]>> = match pass {
            0 => Box::new(p.iter()),
            _ => Box::new(p.iter().rev()),
        };
        for &q in it {
            while h.len() >= start + 2 && turn(h[h.len() - 2], h[h.len() - 1], q) <= 0 {
                h.pop();
            }
            h.push(q);
        }
        h.pop();
    }
    (h.len() >= 3).then_some(h)
}

/// How many times the closed, oriented, embedded part `part` (its faces'
/// grid corners) winds around the convex polygon `q` (grid corners, one
/// plane; or a segment or a point) where no triangle of `q` meets a
/// triangle of the part's faces: 1 strictly inside the solid it bounds, 0
/// strictly outside. `None` where they meet or may meet, or where every
/// corner of `q` is degenerate for the ray along `axis` ([`winding`]).
/// The reference [`PartShadows::placed`] is checked against: every face
/// of the part, one by one.
#[cfg(test)]
fn placed(part: &[&[GridPoint]], axis: usize, q: &[GridPoint]) -> Option<i64> {
    let qb = grid_box(q);
    let tris_q = fan(q)?;
    let apart = part.iter().filter(|f| overlap(&grid_box(f), &qb)).all(|f| {
        (1..f.len() - 1).all(|j| {
            let t = [f[0], f[j], f[j + 1]];
            tris_q.iter().all(|s| triangles_disjoint(s, &t))
        })
    });
    if !apart {
        return None;
    }
    q.iter().find_map(|&p| winding(part, axis, p))
}

/// The fan triangles of the convex polygon `q` (a segment or a point as
/// one triangle of no area); `None` for no corners.
fn fan(q: &[GridPoint]) -> Option<Vec<[GridPoint; 3]>> {
    Some(match q.len() {
        0 => return None,
        1 | 2 => vec![[q[0], q[q.len() - 1], q[0]]],
        _ => (1..q.len() - 1).map(|j| [q[0], q[j], q[j + 1]]).collect(),
    })
}

/// The number of times the closed, outward part `part` winds around grid
/// point `p`, counted along the ray from `p` in the `+axis` direction:
/// each fan triangle whose shadow on the plane across `axis` holds `p`'s
/// strictly, met past `p`, counts the sign of its normal's `axis`
/// component. `None` where the ray meets an edge, a corner or `p` lies
/// on a face (degenerate: another point is tried). The reference
/// [`PartShadows`]'s own is checked against.
#[cfg(test)]
fn winding(part: &[&[GridPoint]], axis: usize, p: GridPoint) -> Option<i64> {
    let mut w = 0;
    for f in part {
        for j in 1..f.len() - 1 {
            w += crossing(&[f[0], f[j], f[j + 1]], axis, p)?;
        }
    }
    Some(w)
}

/// What fan triangle `t` adds to the winding number (`winding`, the
/// tests' reference, and [`PartShadows`]' own) at `p`: the sign of its
/// normal's `axis` component where its shadow holds `p`'s strictly and
/// the ray from `p` meets it past `p`, else 0; `None` where `p`'s shadow
/// lies on its shadow's boundary (or the shadow has no area and `p`'s
/// lies on its line), or `p` on its plane.
fn crossing(t: &[GridPoint; 3], axis: usize, p: GridPoint) -> Option<i64> {
    let [u, v] = across(axis);
    let d = |a: GridPoint, b: GridPoint| [0, 1, 2].map(|c| i64::from(a[c]) - i64::from(b[c]));
    // the turns of p's shadow about the shadow's edges
    let turn = |a: GridPoint, b: GridPoint| {
        let (e, x) = (d(b, a), d(p, a));
        e[u] * x[v] - e[v] * x[u]
    };
    let s = [turn(t[0], t[1]), turn(t[1], t[2]), turn(t[2], t[0])];
    let strictly = s.iter().all(|&x| x > 0) || s.iter().all(|&x| x < 0);
    if !strictly {
        if s.iter().any(|&x| x > 0) && s.iter().any(|&x| x < 0) {
            return Some(0); // outside the shadow
        }
        return None; // on its boundary (or a shadow of no area)
    }
    let (e1, e2) = (d(t[1], t[0]), d(t[2], t[0]));
    let n = [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ];
    let x = d(p, t[0]);
    let side: i128 = (0..3).map(|c| i128::from(n[c]) * i128::from(x[c])).sum();
    // the ray meets the plane at `-side / n[axis]` past p
    if side == 0 {
        return None;
    }
    Some(match (side < 0) == (n[axis] > 0) {
        true => n[axis].signum(),
        false => 0,
    })
}

/// A closed part's fan triangles indexed across one axis: a grid over
/// their faces' boxes, and one over those boxes drawn across the axis
/// (the axis' extent left out), each triangle listed in the cells of its
/// face's box; the triangles whose shadow has no area apart from the
/// second, checked at every point. It answers as the tests' reference
/// `placed` over the whole part does:
/// - the triangles a polygon `q` in a plane across the axis is tested
///   against are those of the faces whose box meets `q`'s, as there;
/// - at a point `p`, a triangle whose shadow has area and whose face's
///   box (so its own) holds `p`'s shadow not even on its boundary adds
///   nothing: its three turns sum to twice its shadow's signed area, so
///   some turn has the area's sign and, `p` being outside, some the
///   other ([`crossing`] gives 0).
pub(crate) struct PartShadows {
    axis: usize,
    /// Each fan triangle and its face's box.
    tris: Vec<([GridPoint; 3], Box3)>,
    /// The triangles whose shadow has no area.
    flat: Vec<u32>,
    /// The other triangles by their faces' boxes drawn across the axis.
    grid: CellGrid,
    /// Every triangle by its face's box (a polygon across the axis meets
    /// the cells of one layer).
    boxes: CellGrid,
}

impl PartShadows {
    /// The fan triangles of the faces of `part` (grid corners), across
    /// `axis`.
    pub(crate) fn new(part: &[&[GridPoint]], axis: usize) -> PartShadows {
        let [u, v] = across(axis);
        let flatten = |mut b: Box3| {
            b[axis] = [0, 0];
            b
        };
        let mut tris = Vec::new();
        for f in part {
            let b = grid_box(f);
            for j in 1..f.len() - 1 {
                tris.push(([f[0], f[j], f[j + 1]], b));
            }
        }
        let area = |t: &[GridPoint; 3]| {
            let e = |a: GridPoint, b: GridPoint, k: usize| i64::from(b[k]) - i64::from(a[k]);
            e(t[0], t[1], u) * e(t[0], t[2], v) - e(t[0], t[1], v) * e(t[0], t[2], u)
        };
        let (flat, shadowed): (Vec<u32>, Vec<u32>) =
            (0..tris.len() as u32).partition(|&i| area(&tris[i as usize].0) == 0);
        // a grid over the boxes of `items`
        let index = |items: Vec<(u32, Box3)>| {
            let scene = items.iter().map(|(_, b)| *b).reduce(crate::boxes::union);
            CellGrid::of_items(scene.unwrap_or([[0, 0]; 3]), &items)
        };
        let grid = index(
            (shadowed.iter())
                .map(|&i| (i, flatten(tris[i as usize].1)))
                .collect(),
        );
        let boxes = index(
            (tris.iter().enumerate())
                .map(|(i, (_, b))| (i as u32, *b))
                .collect(),
        );
        PartShadows {
            axis,
            tris,
            flat,
            grid,
            boxes,
        }
    }

    /// Whether the convex polygon `q` lies strictly inside the solid the
    /// part bounds (1) or strictly outside it (0), as the tests' reference
    /// `placed` answers, over the part indexed.
    pub(crate) fn placed(&self, q: &[GridPoint]) -> Option<i64> {
        let qb = grid_box(q);
        let tris_q = fan(q)?;
        let mut apart = true;
        self.boxes.visit(qb, |i| {
            let (t, b) = &self.tris[i as usize];
            apart &= !overlap(b, &qb) || tris_q.iter().all(|s| triangles_disjoint(s, t));
        });
        if !apart {
            return None;
        }
        q.iter().find_map(|&p| self.winding(p))
    }

    /// The part's winding number round `p`, as the tests' reference
    /// `winding` counts it, over the part indexed.
    fn winding(&self, p: GridPoint) -> Option<i64> {
        let mut at = [
            [i64::from(p[0]); 2],
            [i64::from(p[1]); 2],
            [i64::from(p[2]); 2],
        ];
        at[self.axis] = [0, 0];
        let mut w = Some(0);
        let mut add = |i: u32| {
            w = w.and_then(|w| Some(w + crossing(&self.tris[i as usize].0, self.axis, p)?));
        };
        self.flat.iter().for_each(|&i| add(i));
        // (a point meets one cell: each triangle once)
        self.grid.visit(at, &mut add);
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed, outward faces of an octahedron of radius `r` about
    /// the origin, each split into `4^levels` triangles (a fine closed
    /// mesh with no face of the others' planes).
    fn octahedron(r: i32, levels: u32) -> Vec<Vec<GridPoint>> {
        let axes = |s: [i32; 3]| [[s[0] * r, 0, 0], [0, s[1] * r, 0], [0, 0, s[2] * r]];
        let mut tris = Vec::new();
        for s in 0..8 {
            let sg = [0, 1, 2].map(|k| if s >> k & 1 == 1 { -1 } else { 1 });
            let [a, b, c] = axes(sg);
            // outward: counter-clockwise seen from outside
            let t = if sg[0] * sg[1] * sg[2] > 0 {
                [a, b, c]
            } else {
                [a, c, b]
            };
            tris.push(t);
        }
        for _ in 0..levels {
            tris = tris
                .into_iter()
                .flat_map(|[a, b, c]| {
                    let m = |p: GridPoint, q: GridPoint| [0, 1, 2].map(|k| (p[k] + q[k]) / 2);
                    let (ab, bc, ca) = (m(a, b), m(b, c), m(c, a));
                    [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
                })
                .collect();
        }
        tris.into_iter().map(|t| t.to_vec()).collect()
    }

    #[test]
    fn inner_polygons_lie_inside() {
        let faces = octahedron(64, 2);
        let part: Vec<&[GridPoint]> = faces.iter().map(|f| &f[..]).collect();
        let inside = |part: &[&[GridPoint]], axis, q: &[GridPoint]| {
            let indexed = PartShadows::new(part, axis).placed(q);
            assert_eq!(indexed, placed(part, axis, q));
            indexed == Some(1)
        };
        let mut found = 0;
        for axis in 0..3 {
            let shadows = PartShadows::new(&part, axis);
            for k in [-40, -10, 0, 7, 33] {
                for q in inner_polygons((&part, &shadows), k, PER_SLICE) {
                    found += 1;
                    // every corner strictly inside |x| + |y| + |z| < 64
                    for c in &q {
                        assert_eq!(c[axis], k as i32);
                        assert!(c.iter().map(|x| x.abs()).sum::<i32>() < 64, "{c:?}");
                    }
                    let w = q.iter().find_map(|&p| winding(&part, axis, p));
                    assert_eq!(w, Some(1));
                }
            }
        }
        assert!(found >= 12, "{found} of 15 slices");
        // a polygon reaching out of the solid is refused, as is one outside
        let out = [[0, -70, -70], [0, 70, -70], [0, 70, 70], [0, -70, 70]];
        assert!(!inside(&part, 0, &out));
        let far = [[0, 100, 100], [0, 110, 100], [0, 110, 110]];
        assert!(!inside(&part, 0, &far));
        assert_eq!(winding(&part, 0, [0, 100, 100]), Some(0));
        // the solid turned inside out winds -1 round its inside
        let inverted: Vec<Vec<GridPoint>> = faces
            .iter()
            .map(|f| f.iter().rev().copied().collect())
            .collect();
        let part: Vec<&[GridPoint]> = inverted.iter().map(|f| &f[..]).collect();
        assert_eq!(winding(&part, 0, [3, 1, 2]), Some(-1));
        assert!(!inside(&part, 0, &[[3, 1, 2], [3, 5, 2], [3, 1, 6]]));
    }

    /// A closed octahedron and, beside it, a closed thin upright box, whose
    /// faces' shadows across the z axis have no area.
    fn two_parts() -> Vec<Vec<GridPoint>> {
        let mut faces = octahedron(16, 2);
        let b = |x: i32, y: i32, z: i32| [x, y, z];
        let (x0, x1, y0, y1, z0, z1) = (20, 28, 2, 3, -6, 6);
        let quad = |a, b, c, d| vec![a, b, c, d];
        faces.extend([
            quad(b(x0, y0, z0), b(x0, y1, z0), b(x1, y1, z0), b(x1, y0, z0)),
            quad(b(x0, y0, z1), b(x1, y0, z1), b(x1, y1, z1), b(x0, y1, z1)),
            quad(b(x0, y0, z0), b(x1, y0, z0), b(x1, y0, z1), b(x0, y0, z1)),
            quad(b(x0, y1, z0), b(x0, y1, z1), b(x1, y1, z1), b(x1, y1, z0)),
            quad(b(x0, y0, z0), b(x0, y0, z1), b(x0, y1, z1), b(x0, y1, z0)),
            quad(b(x1, y0, z0), b(x1, y1, z0), b(x1, y1, z1), b(x1, y0, z1)),
        ]);
        faces
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(1200))]
        /// The indexed part places every polygon and point as the whole
        /// part does: triangles, segments and points in a slice across each
        /// axis, on the grid of the solids' corners (so many lie on faces,
        /// edges and corners, and many shadows meet at theirs), small ones
        /// near the octahedron's centre (inside it).
        #[test]
        fn the_indexed_part_places_as_the_whole_part(
            axis in 0usize..3,
            k in -20i32..=20,
            small in proptest::prelude::any::<bool>(),
            q in proptest::collection::vec(proptest::array::uniform3(-30i32..=30), 1..4),
        ) {
            let faces = two_parts();
            let part: Vec<&[GridPoint]> = faces.iter().map(|f| &f[..]).collect();
            let q: Vec<GridPoint> = (q.into_iter())
                .map(|c| {
                    let mut c = if small { c.map(|x| x / 6) } else { c };
                    c[axis] = k;
                    c
                })
                .collect();
            proptest::prop_assert_eq!(PartShadows::new(&part, axis).placed(&q), placed(&part, axis, &q));
        }
    }

    /// The three answers, indexed as whole: inside the octahedron, outside
    /// both parts, and on the line of the upright box's shadow (no area),
    /// which no winding decides.
    #[test]
    fn the_indexed_part_gives_each_answer() {
        let faces = two_parts();
        let part: Vec<&[GridPoint]> = faces.iter().map(|f| &f[..]).collect();
        let shadows = PartShadows::new(&part, 2);
        for (q, answer) in [
            (vec![[1, 1, 3], [2, 1, 3], [1, 0, 3]], Some(1)),
            (vec![[40, 40, 0]], Some(0)),
            (vec![[24, 2, 9]], None),
        ] {
            assert_eq!(placed(&part, 2, &q), answer, "{q:?}");
            assert_eq!(shadows.placed(&q), answer, "{q:?}");
        }
    }

    /// A certified closed part gets inner occluders across the light's
    /// axis; a light that may reach inside the part's box keeps none of
    /// them (a segment between two points inside the solid need not
    /// cross its boundary), nor does a point light.
    #[test]
    fn lights_outside_the_part_use_its_inner_occluders() {
        let faces: Vec<Occluder> = octahedron(64, 2)
            .iter()
            .map(|f| Occluder::new(f).unwrap())
            .collect();
        let polygons: Vec<bsp_core::Polygon> = faces.iter().map(Occluder::to_polygon).collect();
        let solids = bsp_core::certify_solid_parts(&polygons);
        let above =
            AreaLight::new(&[[-8, -8, 200], [-8, 8, 200], [8, 8, 200], [8, -8, 200]]).unwrap();
        let within = AreaLight::new(&[[-8, -8, 50], [-8, 8, 50], [8, 8, 50], [8, -8, 50]]).unwrap();
        assert_eq!(light_axis(&above), Some(2));
        let cores = inner_occluders(&faces, &solids, 2);
        // one per 16 of its 128 faces at most (a slice or two may find none)
        assert!(
            (6..=8).contains(&cores.len()),
            "{} inner occluders",
            cores.len()
        );
        for (q, _) in &cores {
            let z = q.corners()[0][2];
            assert!(q.corners().iter().all(|c| c[2] == z));
        }
        let scene = crate::near::scene_box(&faces).unwrap();
        assert_eq!(core_regions(&above, &cores, scene).len(), cores.len());
        assert!(core_regions(&within, &cores, scene).is_empty());
        let per_light = cores_per_light(
            &[above, within, AreaLight::point([0, 0, 200]).unwrap()],
            &faces,
            &solids,
        );
        let counts: Vec<usize> = per_light.iter().map(|l| l.cores.len()).collect();
        assert_eq!(counts, [cores.len(), 0, 0]);
    }
}
