//! Regions of a sun study: chosen faces overlaid, every step's lit
//! fragments on them added up (the core paper's "+" overlay), so that
//! each cell of a face has one number of suns; and the BRE 209 test of a
//! garden.

use glam::DVec3;
use rayon::prelude::*;

use super::{
    Cell, HeatView, HoursRun, area2, colored_vertex, face_frame, heat, heat_header, heat_picture,
    study,
};
use crate::{Error, Mesh};

/// The faces a region study overlays: a group's name, or face ids.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RegionFaces {
    /// The faces of the group of this name.
    Group(String),
    /// These faces: inclusive ranges of ids (from 0, in the mesh's
    /// order; one face is a range of one). A range is checked against the
    /// mesh before it is listed, so `0-4294967295` is an error, not a
    /// list of four billion ids.
    Ids(Vec<(usize, usize)>),
}

impl std::str::FromStr for RegionFaces {
    type Err = String;

    /// Face ids and inclusive ranges (`1,4,7-9`), else a group's name.
    fn from_str(s: &str) -> Result<RegionFaces, String> {
        let s = s.trim();
        if s.is_empty() {
            return Err("no faces: name a group, or give face ids such as 1,4,7-9".into());
        }
        if !s.starts_with(|c: char| c.is_ascii_digit()) {
            return Ok(RegionFaces::Group(s.to_string()));
        }
        let mut ids = Vec::new();
        for part in s.split(',').map(str::trim) {
            let bad = || format!("`{part}` is not a face id or a range of them such as 7-9");
            let id = |t: &str| t.trim().parse::<usize>().map_err(|_| bad());
            match part.split_once('-') {
                Some((a, b)) if id(a)? <= id(b)? => ids.push((id(a)?, id(b)?)),
                Some(_) => return Err(bad()),
                None => ids.push((id(part)?, id(part)?)),
            }
        }
        Ok(RegionFaces::Ids(ids))
    }
}

impl RegionFaces {
    /// The ids of these faces of `mesh`, in order, each once.
    pub fn faces(&self, mesh: &Mesh) -> Result<Vec<usize>, Error> {
        let n = mesh.faces.len();
        let mut ids: Vec<usize> = match self {
            RegionFaces::Group(name) => (0..n).filter(|&f| mesh.group_name(f) == name).collect(),
            RegionFaces::Ids(ranges) => {
                if let Some(&(_, f)) = ranges.iter().max_by_key(|r| r.1)
                    && f >= n
                {
                    return Err(Error::Region(format!(
                        "face {f}: the mesh has {n} faces (ids from 0)"
                    )));
                }
                ranges.iter().flat_map(|&(a, b)| a..=b).collect()
            }
        };
        ids.sort_unstable();
        ids.dedup();
        if let RegionFaces::Group(name) = self
            && ids.is_empty()
        {
            let mut groups: Vec<&str> = (0..n).map(|f| mesh.group_name(f)).collect();
            groups.dedup();
            let why = format!(
                "no face is in a group `{name}`; the groups: {}",
                groups.join(", ")
            );
            return Err(Error::Region(why));
        }
        match ids.last() {
            Some(&f) if f >= n => Err(Error::Region(format!(
                "face {f}: the mesh has {n} faces (ids from 0)"
            ))),
            _ => Ok(ids),
        }
    }
}

/// A cell of a region: a convex part of a face whose points all see the
/// same number of the study's suns.
#[derive(Clone, Debug, PartialEq)]
pub struct RegionCell {
    /// The face.
    pub face: usize,
    /// The sun-hours of its points: its suns times the step, exact.
    pub hours: f64,
    /// Its area.
    pub area: f64,
    /// Its corners, counter-clockwise seen from the face's front, in the
    /// mesh's units.
    pub ring: Vec<DVec3>,
}

/// The cells of `faces` of `mesh` under `suns` (directions toward them),
/// each sun standing for `step_hours`: every run's exact lit fragments of
/// those faces, as pieces, overlaid (their suns added; the overlay's
/// clipping is `f64`, and a cell below 10⁻¹² of its face's area, a
/// rounding sliver where two runs' boundaries coincide, is left out). A
/// face under no sun is one cell of 0 hours. A face's cells of equal
/// hours that share an edge are then merged where their union is convex
/// (decided by exact turns of their corners).
/// Faces in the order given, each face's cells in the overlay's order;
/// the same bits for any thread count.
pub fn region_hours(
    mesh: &Mesh,
    suns: &[DVec3],
    step_hours: f64,
    faces: &[usize],
) -> Result<Vec<RegionCell>, Error> {
    region_study(
        mesh,
        suns,
        step_hours,
        faces,
        &crate::shadow_file::NoProgress,
    )
}

/// [`region_hours`], every run of suns done told to `progress`.
pub(crate) fn region_study(
    mesh: &Mesh,
    suns: &[DVec3],
    step_hours: f64,
    faces: &[usize],
    progress: &dyn crate::shadow_file::Progress,
) -> Result<Vec<RegionCell>, Error> {
    let n = mesh.faces.len();
    let mut keep = vec![false; n];
    faces
        .iter()
        .filter(|&&f| f < n)
        .for_each(|&f| keep[f] = true);
    let pieces = Some(Some(&keep[..]));
    let (_, _, cells, _) = study(mesh, suns, step_hours, pieces, 1, progress, |runs| {
        HoursRun::fold_cells(n, runs)
    })??;
    let mut cells = cells.unwrap_or_else(|| vec![None; n]);
    // (a face given twice gets a copy the first time)
    let mut uses = vec![0_usize; n];
    faces.iter().filter(|&&f| f < n).for_each(|&f| uses[f] += 1);
    let per_face: Vec<(usize, Option<Vec<Cell>>)> = (faces.iter())
        .filter(|&&f| f < n)
        .map(|&f| {
            uses[f] -= 1;
            let face_cells = if uses[f] == 0 {
                cells[f].take()
            } else {
                cells[f].clone()
            };
            (f, face_cells)
        })
        .collect();
    // the faces' cells made and merged in parallel, in the faces' order
    let out: Vec<Vec<RegionCell>> = per_face
        .into_par_iter()
        .map(|(f, face_cells)| {
            let (o, u, v) = face_frame(mesh, f);
            let whole = || {
                let ring = mesh.faces[f].vertices.iter().map(|&i| {
                    let p = mesh.positions[i as usize] - o;
                    glam::DVec2::new(p.dot(u), p.dot(v))
                });
                vec![(ring.collect(), 0)]
            };
            let face_cells =
                (face_cells.unwrap_or_else(whole).into_iter()).map(|(ring, seen)| RegionCell {
                    face: f,
                    hours: f64::from(seen) * step_hours,
                    area: area2(&ring).abs() / 2.0,
                    ring: ring.iter().map(|p| o + u * p.x + v * p.y).collect(),
                });
            merge_cells(face_cells.collect(), u.cross(v))
        })
        .collect();
    Ok(out.into_iter().flatten().collect())
}

/// The corner's coordinates as bits (`-0.0` as `0.0`): equal corners
/// have equal keys.
fn corner_key(p: DVec3) -> [u64; 3] {
    p.to_array().map(|x| (x + 0.0).to_bits())
}

/// The directed edges of a ring of corner ids, each as one key.
fn edges(ids: &[u32]) -> impl Iterator<Item = u64> + '_ {
    let n = ids.len();
    (0..n).map(move |k| edge_key(ids[k], ids[(k + 1) % n]))
}

/// The key of the directed edge from corner `a` to corner `b`.
fn edge_key(a: u32, b: u32) -> u64 {
    u64::from(a) << 32 | u64::from(b)
}

/// One face's cells (convex, counter-clockwise about `normal`) with those
/// of equal hours merged pairwise where they share an edge (its two
/// corners equal to the bit) and their union is convex, until none do.
/// Convexity is the exact sign of the turn at the two shared corners
/// (`robust::orient2d` of the corners as written, seen along the
/// normal's largest axis), and a corner where the union runs straight on
/// is dropped; a merged cell's area is its parts'. Corners repeated in a
/// row (edges of no length, from the clipping) are dropped first.
/// Deterministic: a merged cell takes the place of its first part.
pub(super) fn merge_cells(cells: Vec<RegionCell>, normal: DVec3) -> Vec<RegionCell> {
    let flat = flat_along(normal);
    // each corner an id, equal corners one
    let mut corners: rustc_hash::FxHashMap<[u64; 3], u32> = Default::default();
    corners.reserve(cells.len() * 2);
    let mut cells: Vec<Option<(RegionCell, Vec<u32>)>> = (cells.into_iter())
        .map(|mut c| {
            c.ring.dedup_by_key(|p| corner_key(*p));
            while c.ring.len() > 3 && corner_key(c.ring[0]) == corner_key(c.ring[c.ring.len() - 1])
            {
                c.ring.pop();
            }
            let ids = (c.ring.iter())
                .map(|p| {
                    let next = corners.len() as u32;
                    *corners.entry(corner_key(*p)).or_insert(next)
                })
                .collect();
            Some((c, ids))
        })
        .collect();
    // each directed edge's cell (stale entries are checked on use)
    let mut at: rustc_hash::FxHashMap<u64, usize> = Default::default();
    at.reserve(cells.len() * 5);
    for (i, c) in cells.iter().enumerate() {
        if let Some((_, ids)) = c {
            at.extend(edges(ids).map(|e| (e, i)));
        }
    }
    for i in 0..cells.len() {
        // grow cell i while a neighbour of equal hours keeps it convex
        while let Some((cell, ids)) = &cells[i] {
            let found = edges(ids).enumerate().find_map(|(k, e)| {
                // the reverse edge: its two ids swapped
                let &j = at.get(&e.rotate_right(32))?;
                match &cells[j] {
                    Some((other, other_ids)) if j != i && other.hours == cell.hours => {
                        let p = (&cell.ring[..], &ids[..]);
                        merge_pair(p, k, (&other.ring, other_ids), &flat).map(|m| (j, m))
                    }
                    _ => None,
                }
            });
            let Some((j, (ring, ids))) = found else {
                break;
            };
            // the partner's edges, and those new at the seams, are now i's
            for e in edges(&ids) {
                if at.get(&e) != Some(&i) {
                    at.insert(e, i);
                }
            }
            let part = cells[j].take().map_or(0.0, |(c, _)| c.area);
            if let Some((cell, old)) = &mut cells[i] {
                cell.ring = ring;
                cell.area += part;
                *old = ids;
            }
        }
    }
    cells.into_iter().flatten().map(|(c, _)| c).collect()
}

/// The projection along `normal`'s largest axis that keeps a ring
/// counter-clockwise about `normal` counter-clockwise (coordinates
/// dropped, not computed: exact).
fn flat_along(normal: DVec3) -> impl Fn(DVec3) -> robust::Coord<f64> {
    let a = normal.abs();
    let axis = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    let mirror = normal[axis] < 0.0;
    move |p: DVec3| {
        let (x, y) = (p[(axis + 1) % 3], p[(axis + 2) % 3]);
        if mirror {
            robust::Coord { x: y, y: x }
        } else {
            robust::Coord { x, y }
        }
    }
}

/// The union of convex counter-clockwise rings `p` and `q` (corners and
/// their ids) where `p`'s edge from corner `k` is `q`'s edge reversed, if
/// it is convex (seen through `flat`) and they share no other corner;
/// `None` otherwise.
#[allow(clippy::type_complexity)] // (a ring's corners and their ids)
fn merge_pair(
    (p, pi): (&[DVec3], &[u32]),
    k: usize,
    (q, qi): (&[DVec3], &[u32]),
    flat: &impl Fn(DVec3) -> robust::Coord<f64>,
) -> Option<(Vec<DVec3>, Vec<u32>)> {
    let (np, nq) = (p.len(), q.len());
    let (a, b) = (pi[k], pi[(k + 1) % np]);
    let m = (0..nq).find(|&m| qi[m] == b && qi[(m + 1) % nq] == a)?;
    let turn = |u: DVec3, v: DVec3, w: DVec3| robust::orient2d(flat(u), flat(v), flat(w));
    // p from b round to a, then q after a up to before b
    let at_a = turn(p[(k + np - 1) % np], p[k], q[(m + 2) % nq]);
    let at_b = turn(q[(m + nq - 1) % nq], q[m], p[(k + 2) % np]);
    if at_a < 0.0 || at_b < 0.0 {
        return None;
    }
    if qi.iter().filter(|c| pi.contains(c)).count() != 2 {
        return None;
    }
    let (mut ring, mut ids) = (
        Vec::with_capacity(np + nq - 2),
        Vec::with_capacity(np + nq - 2),
    );
    for t in 1..=np {
        let i = (k + t) % np;
        let straight = if i == k {
            at_a == 0.0
        } else {
            i == (k + 1) % np && at_b == 0.0
        };
        if !straight {
            ring.push(p[i]);
            ids.push(pi[i]);
        }
    }
    for t in 2..nq {
        ring.push(q[(m + t) % nq]);
        ids.push(qi[(m + t) % nq]);
    }
    Some((ring, ids))
}

/// `cells` cut to the upright prism over `outline` (a closed polygon,
/// such as a garden's boundary, given by points whose height along `up`
/// is left out): each cell's parts whose plumb line meets the outline's
/// inside, on the cell's own face, with their areas. A cell on a wall
/// inside the outline stays whole. The outline is triangulated (earcut)
/// and each cell clipped by each triangle's three upright planes, in
/// `f64` (the cells' corners are); the parts keep their cell's face,
/// hours and turning. An outline without area, or one that meets none of
/// the cells, is an error.
pub fn clip_to_outline(
    cells: &[RegionCell],
    outline: &[DVec3],
    up: super::Up,
) -> Result<Vec<RegionCell>, Error> {
    // plan coordinates, counter-clockwise seen from above
    let plan = |p: DVec3| match up {
        super::Up::Z => [p.x, p.y],
        super::Up::Y => [p.x, -p.z],
    };
    let flat: Vec<[f64; 2]> = outline.iter().map(|&p| plan(p)).collect();
    let mut tri: Vec<u32> = Vec::new();
    earcut::Earcut::new().earcut(flat.iter().copied(), &[] as &[u32], &mut tri);
    let cross = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    };
    let triangles: Vec<[[f64; 2]; 3]> = (tri.chunks(3))
        .map(|t| t.iter().map(|&i| flat[i as usize]).collect::<Vec<_>>())
        .filter_map(|t| match cross(t[0], t[1], t[2]) {
            a if a > 0.0 => Some([t[0], t[1], t[2]]),
            a if a < 0.0 => Some([t[0], t[2], t[1]]),
            _ => None,
        })
        .collect();
    if triangles.is_empty() {
        return Err(Error::Region(format!(
            "the outline of {} points encloses no area seen from above",
            outline.len()
        )));
    }
    let mut out = Vec::new();
    for c in cells {
        for t in &triangles {
            let mut ring = c.ring.clone();
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                ring = clip_ring(&ring, |p| cross(a, b, plan(p)));
                if ring.len() < 3 {
                    break;
                }
            }
            let area = svbsp::polygon_area(&ring);
            if ring.len() >= 3 && area > 0.0 {
                out.push(RegionCell {
                    face: c.face,
                    hours: c.hours,
                    area,
                    ring,
                });
            }
        }
    }
    if out.is_empty() && !cells.is_empty() {
        // (a region of no area would say "0 % of its -0 units²")
        let (lo, hi) =
            flat.iter()
                .fold(([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]), |(l, h), p| {
                    (
                        [l[0].min(p[0]), l[1].min(p[1])],
                        [h[0].max(p[0]), h[1].max(p[1])],
                    )
                });
        return Err(Error::Region(format!(
            "the outline (seen from above, from {}, {} to {}, {}) meets none of the region's \
             {} cells",
            lo[0],
            lo[1],
            hi[0],
            hi[1],
            cells.len()
        )));
    }
    Ok(out)
}

/// The part of the polygon `ring` where `side(p) >= 0` (Sutherland and
/// Hodgman's step).
fn clip_ring(ring: &[DVec3], side: impl Fn(DVec3) -> f64) -> Vec<DVec3> {
    let mut out = Vec::with_capacity(ring.len() + 1);
    for (i, &a) in ring.iter().enumerate() {
        let b = ring[(i + 1) % ring.len()];
        let (sa, sb) = (side(a), side(b));
        if sa >= 0.0 {
            out.push(a);
        }
        // (a corner on the line is kept once, not again as a crossing)
        if (sa > 0.0 && sb < 0.0) || (sa < 0.0 && sb > 0.0) {
            out.push(a + (b - a) * (sa / (sa - sb)));
        }
    }
    out
}

/// The area of `cells` and the area of those that see at least `hours`
/// (within 10⁻⁹ hours: the steps' sums in `f64`).
pub fn area_in_sun(cells: &[RegionCell], hours: f64) -> (f64, f64) {
    let total = cells.iter().map(|c| c.area).sum::<f64>();
    let sunny = (cells.iter())
        .filter(|c| c.hours >= hours - 1e-9)
        .map(|c| c.area)
        .sum::<f64>();
    // (`+ 0.0`: an empty sum is -0)
    (total + 0.0, sunny + 0.0)
}

/// The line that says how much of the region sees at least `hours`.
pub fn region_in_sun_text(cells: &[RegionCell], hours: f64) -> String {
    let (total, sunny) = area_in_sun(cells, hours);
    let share = if total > 0.0 {
        100.0 * sunny / total
    } else {
        0.0
    };
    format!("region: {share:.1}% of its {total:.6} units² sees at least {hours} hours of sun\n")
}

/// The BRE 209 test of a garden ("Site layout planning for daylight and
/// sunlight", BRE 2022, 3.3.17): at least half of its area should see at
/// least two hours of sun on 21 March; the verdict in a line.
pub fn bre209_text(cells: &[RegionCell]) -> String {
    let (total, sunny) = area_in_sun(cells, 2.0);
    let share = if total > 0.0 { sunny / total } else { 0.0 };
    let verdict = if share >= 0.5 { "passes" } else { "fails" };
    format!(
        "BRE 209: the region {verdict}: {:.1}% of it sees at least 2 hours of sun (at least 50% asked)\n",
        100.0 * share
    )
}

/// Fails if the BRE 209 test is `asked` for, and `dates` is not one 21
/// March: the day the test is about.
pub fn check_bre209(asked: bool, dates: &[chrono::NaiveDate]) -> Result<(), Error> {
    use chrono::Datelike;
    match dates {
        _ if !asked => Ok(()),
        [d] if d.month() == 3 && d.day() == 21 => Ok(()),
        _ => Err(Error::Region(
            "the BRE 209 test is of 21 March: study that one day (YYYY-03-21)".into(),
        )),
    }
}

/// The cells as CSV: `cell,face,group,hours,area`.
pub fn regions_csv(mesh: &Mesh, cells: &[RegionCell]) -> String {
    let mut s = String::from("cell,face,group,hours,area\n");
    for (i, c) in cells.iter().enumerate() {
        let group = mesh.group_name(c.face);
        s += &format!("{i},{},{group},{},{}\n", c.face, c.hours, c.area);
    }
    s
}

/// The cells as JSON: `{"suns": n, "area": total, "cells": [{"face",
/// "hours", "area", "ring": [[x, y, z], …]}, …]}`.
pub fn regions_json(cells: &[RegionCell], suns: usize) -> String {
    let list: Vec<serde_json::Value> = (cells.iter())
        .map(|c| {
            let ring: Vec<[f64; 3]> = c.ring.iter().map(|p| p.to_array()).collect();
            serde_json::json!({"face": c.face, "hours": c.hours, "area": c.area, "ring": ring})
        })
        .collect();
    let total: f64 = cells.iter().map(|c| c.area).sum();
    let v = serde_json::json!({"suns": suns, "area": total, "cells": list});
    format!("{v:#}\n")
}

/// The cells as an OBJ heat map: each cell its own face, its corners
/// coloured by its hours on the ramp of [`super::hours_obj`].
pub fn regions_obj(cells: &[RegionCell]) -> String {
    let most = cells.iter().map(|c| c.hours).fold(0.0, f64::max);
    let mut s = heat_header(most);
    let mut next = 1;
    for c in cells {
        let rgb = heat(c.hours, most);
        for &p in &c.ring {
            s += &colored_vertex(p, rgb);
        }
        let corners: Vec<String> = (next..next + c.ring.len()).map(|i| i.to_string()).collect();
        s += &format!("f {}\n", corners.join(" "));
        next += c.ring.len();
    }
    s
}

/// A picture of the region (PNG, [`super::HEAT_PNG_SIZE`]): its cells
/// (`cells` of the faces `region`) in the heat map's colours, the scene's
/// other faces grey, seen as `view` says, with the ramp along the bottom
/// ([`super::hours_png`]). Cells that snapping to the picture's grid makes
/// degenerate are not drawn.
pub fn regions_png(
    mesh: &Mesh,
    region: &[usize],
    cells: &[RegionCell],
    suns: usize,
    view: HeatView,
) -> Result<Vec<u8>, Error> {
    let n = mesh.faces.len();
    let mut in_region = vec![false; n];
    region
        .iter()
        .filter(|&&f| f < n)
        .for_each(|&f| in_region[f] = true);
    let mut scene = Mesh {
        positions: mesh.positions.clone(),
        faces: Vec::new(),
        groups: vec!["scene".to_string()],
    };
    let mut colors = Vec::new();
    for (face, _) in mesh
        .faces
        .iter()
        .zip(&in_region)
        .filter(|(_, inside)| !**inside)
    {
        scene.faces.push(shadow_scene::Face {
            vertices: face.vertices.clone(),
            line: 0,
            group: 0,
        });
        colors.push(DVec3::splat(0.72));
    }
    let most = cells.iter().map(|c| c.hours).fold(0.0, f64::max);
    for c in cells {
        let first = scene.positions.len() as u32;
        scene.positions.extend(&c.ring);
        scene.faces.push(shadow_scene::Face {
            vertices: (first..first + c.ring.len() as u32).collect(),
            line: 0,
            group: 0,
        });
        colors.push(DVec3::from_array(heat(c.hours, most)));
    }
    heat_picture(&scene, &colors, most, suns, view)
}
