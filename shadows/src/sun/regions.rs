//! Regions of a sun study: chosen faces overlaid, every step's lit
//! fragments on them added up (the core paper's "+" overlay), so that
//! each cell of a face has one number of suns; and the BRE 209 test of a
//! garden.

use glam::DVec3;
use rayon::prelude::*;

use super::{HeatView, HoursRun, colored_vertex, heat, heat_header, heat_picture, study};
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

/// A cell of a region: a connected part of a face whose points all see
/// the same number of the study's suns, as large as it can be (its
/// neighbours see other numbers), with holes where it surrounds others.
#[derive(Clone, Debug, PartialEq)]
pub struct RegionCell {
    /// The face.
    pub face: usize,
    /// The sun-hours of its points: its suns times the step, exact.
    pub hours: f64,
    /// Its area (its holes' taken out).
    pub area: f64,
    /// Its outer boundary, counter-clockwise seen from the face's front,
    /// in the mesh's units.
    pub ring: Vec<DVec3>,
    /// Its holes, each clockwise seen from the face's front.
    pub holes: Vec<Vec<DVec3>>,
}

impl RegionCell {
    /// The cell's outer boundary, then its holes.
    pub fn rings(&self) -> impl Iterator<Item = &[DVec3]> {
        std::iter::once(&self.ring[..]).chain(self.holes.iter().map(|h| &h[..]))
    }

    /// Triangles covering the cell (its holes left out), counter-clockwise
    /// seen from the face's front as the cell is
    /// ([`shadow_scene::triangulate_rings`]); none for a cell of no area.
    pub fn triangles(&self) -> Vec<[DVec3; 3]> {
        let corners: Vec<DVec3> = self.rings().flatten().copied().collect();
        let points: Vec<[f64; 3]> = corners.iter().map(|p| p.to_array()).collect();
        let lens: Vec<usize> = self.rings().map(<[DVec3]>::len).collect();
        (shadow_scene::triangulate_rings(&points, &lens).into_iter())
            .map(|t| t.map(|i| corners[i]))
            .collect()
    }
}

/// The cells of `faces` of `mesh` under `suns` (directions toward them),
/// each sun standing for `step_hours`: every run's exact lit fragments of
/// those faces, as pieces, overlaid exactly ([`svbsp::FaceOverlay`]: their
/// suns added, every corner an exact point, nothing dropped), then the
/// pieces of equal hours merged into maximal connected cells with holes
/// (exactly: [`svbsp::FaceOverlay::regions`]), each corner correctly rounded
/// on the study's grid. A face under no sun is one cell of 0 hours.
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
    let (mut cells, grid) = match cells {
        Some((cells, grid)) => (cells, Some(grid)),
        None => (vec![None; n], None),
    };
    // (a face given twice gets a copy the first time)
    let mut uses = vec![0_usize; n];
    faces.iter().filter(|&&f| f < n).for_each(|&f| uses[f] += 1);
    let per_face: Vec<(usize, Option<super::FaceCells>)> = (faces.iter())
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
    // the faces' regions made in parallel, in the faces' order
    let out: Vec<Vec<RegionCell>> = per_face
        .into_par_iter()
        .map(|(f, parts)| match (parts, grid) {
            (Some(parts), Some(grid)) if !parts.is_empty() => (parts.iter())
                .flat_map(|p| p.overlay().regions())
                .map(|r| {
                    let world = |ring: &[[f64; 3]]| -> Vec<DVec3> {
                        ring.iter().map(|&c| grid.to_world(c)).collect()
                    };
                    let (ring, holes) = (world(&r.outer), r.holes.iter().map(|h| world(h)));
                    let holes: Vec<Vec<DVec3>> = holes.collect();
                    let area = svbsp::polygon_area(&ring)
                        - holes.iter().map(|h| svbsp::polygon_area(h)).sum::<f64>();
                    RegionCell {
                        face: f,
                        hours: f64::from(r.count) * step_hours,
                        area,
                        ring,
                        holes,
                    }
                })
                .collect(),
            _ => {
                let ring: Vec<DVec3> = (mesh.faces[f].vertices.iter())
                    .map(|&i| mesh.positions[i as usize])
                    .collect();
                vec![RegionCell {
                    face: f,
                    hours: 0.0,
                    area: svbsp::polygon_area(&ring),
                    ring,
                    holes: Vec::new(),
                }]
            }
        })
        .collect();
    Ok(out.into_iter().flatten().collect())
}

/// `cells` cut to the upright prism over `outline` (a closed polygon,
/// such as a garden's boundary, given by points whose height along `up`
/// is left out): each cell's parts whose plumb line meets the outline's
/// inside, on the cell's own face, with their areas. A cell on a wall
/// inside the outline stays whole. The outline is triangulated (earcut)
/// and each cell's rings (its boundary and holes) clipped by each
/// triangle's three upright planes, in `f64` (the cells' corners are, and
/// the outline is the user's); the parts keep their cell's face, hours
/// and turning (a part of a cell that is not convex may run along a
/// triangle's side and back: its area is still the part's). An outline without area, or one that meets none of
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
            let clip = |ring: &[DVec3]| {
                let mut ring = ring.to_vec();
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    ring = clip_ring(&ring, |p| cross(a, b, plan(p)));
                    if ring.len() < 3 {
                        return None;
                    }
                }
                Some(ring)
            };
            let Some(ring) = clip(&c.ring) else {
                continue;
            };
            let holes: Vec<Vec<DVec3>> = c.holes.iter().filter_map(|h| clip(h)).collect();
            let area = svbsp::polygon_area(&ring)
                - holes.iter().map(|h| svbsp::polygon_area(h)).sum::<f64>();
            if area > 0.0 {
                out.push(RegionCell {
                    face: c.face,
                    hours: c.hours,
                    area,
                    ring,
                    holes,
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
/// "hours", "area", "ring": [[x, y, z], …], "holes": [[[x, y, z], …],
/// …]}, …]}`.
pub fn regions_json(cells: &[RegionCell], suns: usize) -> String {
    let points = |r: &[DVec3]| -> Vec<[f64; 3]> { r.iter().map(|p| p.to_array()).collect() };
    let list: Vec<serde_json::Value> = (cells.iter())
        .map(|c| {
            let holes: Vec<Vec<[f64; 3]>> = c.holes.iter().map(|h| points(h)).collect();
            serde_json::json!({"face": c.face, "hours": c.hours, "area": c.area,
                "ring": points(&c.ring), "holes": holes})
        })
        .collect();
    let total: f64 = cells.iter().map(|c| c.area).sum();
    let v = serde_json::json!({"suns": suns, "area": total, "cells": list});
    format!("{v:#}\n")
}

/// The cells as an OBJ heat map: each cell a group `cell<i>` of
/// triangles ([`RegionCell::triangles`]: a cell need not be convex, and
/// may have holes), its corners coloured by its hours on the ramp of
/// [`super::hours_obj`].
pub fn regions_obj(cells: &[RegionCell]) -> String {
    let most = cells.iter().map(|c| c.hours).fold(0.0, f64::max);
    let mut s = heat_header(most);
    let mut next = 1;
    for (i, c) in cells.iter().enumerate() {
        let rgb = heat(c.hours, most);
        s += &format!("g cell{i}\n");
        for t in c.triangles() {
            t.iter().for_each(|&p| s += &colored_vertex(p, rgb));
            s += &format!("f {} {} {}\n", next, next + 1, next + 2);
            next += 3;
        }
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
        for t in c.triangles() {
            let first = scene.positions.len() as u32;
            scene.positions.extend(t);
            scene.faces.push(shadow_scene::Face {
                vertices: (first..first + 3).collect(),
                line: 0,
                group: 0,
            });
            colors.push(DVec3::from_array(heat(c.hours, most)));
        }
    }
    heat_picture(&scene, &colors, most, suns, view)
}
