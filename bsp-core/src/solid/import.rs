//! Turning input faces (`f64` vertex loops) into exact convex polygons.

use glam::DVec3;

use crate::kernel::InputError;
use crate::kernel::Side;
use crate::kernel::grid::{Grid, GridPoint};
use crate::kernel::plane::FaceDefect;
use crate::kernel::polygon::{GridPolygon, Polygon, support_plane};

use super::loops::{Projection, tile};

/// What happened to the input faces on the way to convex polygons.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ImportReport {
    /// Number of input faces.
    pub faces: usize,
    /// Number of convex polygons produced.
    pub polygons: usize,
    /// Faces split into triangles, with the reason (non-planar after
    /// snapping, or non-convex).
    pub triangulated: Vec<(usize, FaceDefect)>,
    /// Faces that produced no polygon at all, with the reason.
    pub dropped: Vec<(usize, FaceDefect)>,
}

impl ImportReport {
    /// A one-paragraph human summary, empty when every face was kept whole.
    pub fn summary(&self) -> String {
        self.summary_at(&|_| 0)
    }

    /// [`ImportReport::summary`] with each face's line in its file
    /// (`line(face)`; 0 where the format has none), so that a person finds
    /// it: `face 6 (line 22: zero area (collinear vertices))`.
    pub fn summary_at(&self, line: &dyn Fn(usize) -> usize) -> String {
        let mut s = String::new();
        let list = |v: &[(usize, FaceDefect)]| {
            v.iter()
                .take(5)
                .map(|&(f, d)| match line(f) {
                    0 => format!("face {f} ({d})"),
                    l => format!("face {f} (line {l}: {d})"),
                })
                .collect::<Vec<_>>()
                .join(", ")
                + if v.len() > 5 { ", ..." } else { "" }
        };
        if !self.triangulated.is_empty() {
            s += &format!(
                "{} face(s) triangulated: {}\n",
                self.triangulated.len(),
                list(&self.triangulated)
            );
        }
        if !self.dropped.is_empty() {
            s += &format!(
                "{} degenerate face(s) dropped: {}\n",
                self.dropped.len(),
                list(&self.dropped)
            );
        }
        s
    }

    /// The summary of operand `name` ([`ImportReport::summary`], each line
    /// prefixed with the name) and, where faces were dropped, a warning
    /// that says so (`grid`: the grid they were snapped to): a face with
    /// no area on the grid leaves a seam of no area, where the other faces
    /// do not pair up edge for edge (a solid made of them is resolved; see
    /// `bsp-csg`). Empty when every face was kept whole.
    pub fn notes(&self, name: &str, grid: &Grid) -> String {
        self.notes_at(name, grid, &|_| 0)
    }

    /// [`ImportReport::notes`] with each face's line ([`ImportReport::summary_at`]).
    pub fn notes_at(&self, name: &str, grid: &Grid, line: &dyn Fn(usize) -> usize) -> String {
        let mut s = String::new();
        let summary = self.summary_at(line);
        if !summary.is_empty() {
            s += &format!("{name}: {summary}");
        }
        if !self.dropped.is_empty() {
            s += &format!(
                "warning: {name}: {} face(s) have no area on the grid (step 2^{}) and were \
                 dropped; the seams they leave have no area either\n",
                self.dropped.len(),
                grid.step_log2()
            );
        }
        s
    }

    /// `N polygons after import (T faces triangulated, D dropped)`.
    pub fn counts(&self) -> String {
        format!(
            "{} polygons after import ({} faces triangulated, {} dropped)",
            self.polygons,
            self.triangulated.len(),
            self.dropped.len()
        )
    }
}

/// Snaps `faces` to `grid` and turns each into convex polygons tagged with
/// the face's index.
///
/// Planar convex faces stay one polygon whatever their vertex count;
/// non-convex planar faces are triangulated by exact ear clipping;
/// non-planar faces (after snapping) are fan-triangulated; faces with no
/// area are dropped. The report says which faces were changed and why.
///
/// ```
/// use bsp_core::{Grid, import_faces};
/// use glam::DVec3;
/// let quad = [DVec3::new(0., 0., 0.), DVec3::new(1., 0., 0.), DVec3::new(1., 1., 0.), DVec3::new(0., 1., 0.)];
/// let grid = Grid::fit_points(&quad).unwrap();
/// let (polys, report) = import_faces(&grid, [&quad[..]]).unwrap();
/// assert_eq!((polys.len(), polys[0].len()), (1, 4));
/// assert!(report.dropped.is_empty() && report.triangulated.is_empty());
/// ```
pub fn import_faces<'a>(
    grid: &Grid,
    faces: impl IntoIterator<Item = &'a [DVec3]>,
) -> Result<(Vec<Polygon>, ImportReport), InputError> {
    import_from(grid, faces, 0)
}

/// [`import_faces`] of a slice of face loops, in parallel (rayon): the
/// same polygons, tags and report in the same order whatever the thread
/// count.
///
/// ```
/// use bsp_core::{Grid, import_faces, import_faces_par};
/// use glam::DVec3;
/// let tri = vec![DVec3::ZERO, DVec3::X, DVec3::Y];
/// let faces = vec![tri.clone(); 3];
/// let grid = Grid::fit_points(&tri).unwrap();
/// let (a, ra) = import_faces_par(&grid, &faces).unwrap();
/// let (b, rb) = import_faces(&grid, faces.iter().map(|f| &f[..])).unwrap();
/// assert_eq!((a.len(), ra), (b.len(), rb));
/// assert_eq!(a[2].tag(), 2);
/// ```
pub fn import_faces_par(
    grid: &Grid,
    faces: &[Vec<DVec3>],
) -> Result<(Vec<Polygon>, ImportReport), InputError> {
    import_placed(
        faces.len(),
        |fi| single_polygon(grid, faces[fi].iter().map(|&p| Some(p)), fi),
        |importer, fi, out| importer.face(grid, &faces[fi], fi, out),
    )
}

/// [`import_faces_par`] of an indexed mesh: `face(i)` is face `i`'s loop
/// of indices into `positions` (an index out of range is an error naming
/// the face and the corner). The same polygons and report as
/// [`import_faces_par`] of the loops of positions, without making them.
/// (`face` is a `dyn` closure so that the import is compiled here,
/// optimised, whatever the caller's build settings.)
///
/// ```
/// use bsp_core::{Grid, import_faces_par, import_mesh_par};
/// use glam::DVec3;
/// let p = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::ONE];
/// let faces = [vec![0, 1, 2], vec![1, 3, 2], vec![0, 0, 1]];
/// let grid = Grid::fit_points(&p).unwrap();
/// let (polys, report) = import_mesh_par(&grid, &p, faces.len(), &|i| &faces[i][..]).unwrap();
/// let loops: Vec<Vec<DVec3>> = faces.iter().map(|f| f.iter().map(|&v| p[v as usize]).collect()).collect();
/// let (by_loops, by_loops_report) = import_faces_par(&grid, &loops).unwrap();
/// assert_eq!(report, by_loops_report);
/// let corners = |q: &[bsp_core::Polygon]| -> Vec<(u32, Vec<[f64; 3]>)> {
///     q.iter().map(|q| (q.tag(), q.vertices_f64())).collect()
/// };
/// assert_eq!(corners(&polys), corners(&by_loops));
/// assert_eq!((polys.len(), report.dropped.len()), (2, 1));
/// assert!(import_mesh_par(&grid, &p, 1, &|_| &[0, 1, 7][..]).is_err());
/// ```
pub fn import_mesh_par<'a>(
    grid: &Grid,
    positions: &[DVec3],
    faces: usize,
    face: &(dyn Fn(usize) -> &'a [u32] + Sync),
) -> Result<(Vec<Polygon>, ImportReport), InputError> {
    import_placed(
        faces,
        |fi| {
            let corners = face(fi).iter().map(|&v| positions.get(v as usize).copied());
            single_polygon(grid, corners, fi)
        },
        |importer, fi, out| importer.indexed(grid, positions, face(fi), fi, out),
    )
}

/// The import of `n` faces in parallel: `single(i)` is face `i` as one
/// polygon where it is one as it stands (the rule), and `import` imports
/// any face with its notes and errors.
///
/// The rule's polygons go straight into their places in parallel (a
/// gather and copy of large polygons on one thread afterwards was a tenth
/// of a 100k-face scene's shadows), each other face holding its place
/// with a stand-in tagged [`u32::MAX`] (no face's number: tags are face
/// numbers, below `n`). Where there are stand-ins, the other faces
/// (triangulated, dropped, or in error) are imported again, in face order,
/// with their notes: the same polygons, report and first error as one
/// import of every face in order.
fn import_placed(
    n: usize,
    single: impl Fn(usize) -> Option<Polygon> + Sync,
    import: impl Fn(&mut FaceImporter, usize, &mut dyn FnMut(Polygon)) -> Result<(), InputError>,
) -> Result<(Vec<Polygon>, ImportReport), InputError> {
    const STAND_IN: u32 = u32::MAX;
    let stand_in = GridPolygon::from_grid_points(&[[0, 0, 0], [1, 0, 0], [0, 1, 0]])
        .map(|g| g.to_polygon(STAND_IN))
        .ok();
    let polys = match stand_in {
        Some(stand_in) if n < STAND_IN as usize => {
            crate::par::map_placed(n, |fi| single(fi).unwrap_or_else(|| stand_in.clone()))
        }
        // (no stand-in: every face again in order)
        _ => Vec::new(),
    };
    let singles = polys.iter().filter(|p| p.tag() != STAND_IN).count();
    if polys.len() == n && singles == n {
        let report = ImportReport {
            faces: n,
            polygons: n,
            ..ImportReport::default()
        };
        return Ok((polys, report));
    }
    let mut run = Importer::new(n);
    let mut placed = polys.into_iter();
    for fi in 0..n {
        match placed.next() {
            Some(p) if p.tag() != STAND_IN => run.out.push(p),
            _ => {
                let out = &mut run.out;
                import(&mut run.faces, fi, &mut |q| out.push(q))?;
            }
        }
    }
    let (polys, mut report) = run.finish();
    report.faces += singles;
    report.polygons += singles;
    Ok((polys, report))
}

/// Face `fi`, its corners' positions (`None` for a corner that does not
/// exist), as one polygon where it is one as it stands: every corner
/// snapped, and the loop planar, convex and with area on the grid (the
/// import's rule, with nothing to note). Else `None`.
fn single_polygon(
    grid: &Grid,
    corners: impl Iterator<Item = Option<DVec3>>,
    fi: usize,
) -> Option<Polygon> {
    let pts: smallvec::SmallVec<[GridPoint; 8]> =
        corners.map(|p| grid.snap(p?).ok()).collect::<Option<_>>()?;
    let polygon = GridPolygon::from_grid_points(&pts).ok()?;
    Some(polygon.to_polygon(fi as u32))
}

/// The runs of a parallel import in face order, with their report joined;
/// the first error in face order, as the sequential import gives.
#[allow(clippy::type_complexity)]
fn gather(
    parts: Vec<Result<(Vec<Polygon>, ImportReport), InputError>>,
) -> Result<(Vec<Vec<Polygon>>, ImportReport), InputError> {
    let mut runs = Vec::with_capacity(parts.len());
    let mut report = ImportReport::default();
    for part in parts {
        let (polys, r) = part?;
        runs.push(polys);
        report.add(r);
    }
    Ok((runs, report))
}

/// [`import_faces`] of an indexed mesh (positions and vertex-index
/// loops), in parallel (rayon): the polygons come in runs, in face order
/// (the faces of one run imported together), so that a caller can move
/// them on in parallel without gathering them first; the same polygons,
/// tags and report as [`import_faces`] of the loops.
///
/// ```
/// use bsp_core::{Grid, import_indexed_par};
/// use glam::DVec3;
/// let p = vec![DVec3::ZERO, DVec3::X, DVec3::Y];
/// let grid = Grid::fit_points(&p).unwrap();
/// let (runs, report) = import_indexed_par(&grid, &p, &[vec![0, 1, 2], vec![0, 2, 1]]).unwrap();
/// let polys: Vec<_> = runs.into_iter().flatten().collect();
/// assert_eq!((polys.len(), report.polygons), (2, 2));
/// assert_eq!(polys[1].tag(), 1);
/// assert!(import_indexed_par(&grid, &p, &[vec![0, 1, 7]]).is_err());
/// ```
pub fn import_indexed_par(
    grid: &Grid,
    positions: &[DVec3],
    faces: &[Vec<u32>],
) -> Result<(Vec<Vec<Polygon>>, ImportReport), InputError> {
    const CHUNK: usize = 4096;
    let parts = crate::par::map(faces.len().div_ceil(CHUNK), |c| {
        let chunk = &faces[c * CHUNK..faces.len().min((c + 1) * CHUNK)];
        let mut run = Importer::new(chunk.len());
        for (i, face) in chunk.iter().enumerate() {
            let out = &mut run.out;
            run.faces
                .indexed(grid, positions, face, c * CHUNK + i, |p| out.push(p))?;
        }
        Ok(run.finish())
    });
    gather(parts)
}

impl ImportReport {
    /// Adds the report of the faces after these (the reports of a
    /// parallel import's runs, joined in face order).
    pub fn add(&mut self, r: ImportReport) {
        self.faces += r.faces;
        self.polygons += r.polygons;
        self.triangulated.extend(r.triangulated);
        self.dropped.extend(r.dropped);
    }
}

/// [`import_faces`], numbering the faces from `first`.
fn import_from<'a>(
    grid: &Grid,
    faces: impl IntoIterator<Item = &'a [DVec3]>,
    first: usize,
) -> Result<(Vec<Polygon>, ImportReport), InputError> {
    let faces = faces.into_iter();
    let mut run = Importer::new(faces.size_hint().0);
    for (fi, face) in faces.enumerate() {
        let out = &mut run.out;
        run.faces.face(grid, face, fi + first, |p| out.push(p))?;
    }
    Ok(run.finish())
}

/// Faces imported one after the other into a list.
struct Importer {
    out: Vec<Polygon>,
    faces: FaceImporter,
}

impl Importer {
    /// Room for about `faces` polygons: one a face as a rule, so that the
    /// output (large polygons) is not regrown.
    fn new(faces: usize) -> Importer {
        Importer {
            out: Vec::with_capacity(faces),
            faces: FaceImporter::default(),
        }
    }

    fn finish(self) -> (Vec<Polygon>, ImportReport) {
        (self.out, self.faces.finish())
    }
}

/// The import of one face at a time, each face's polygons handed to the
/// caller as they are made (one as a rule; none for a dropped face,
/// several for a triangulated one), so that a caller can put them
/// straight where they are kept, with no list to gather and copy. The
/// same polygons, tags and report as [`import_faces`].
///
/// ```
/// use bsp_core::Grid;
/// use bsp_core::internals::FaceImporter;
/// use glam::DVec3;
/// let p = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)];
/// let grid = Grid::fit_points(&p).unwrap();
/// let mut imp = FaceImporter::default();
/// let mut polys = Vec::new();
/// imp.indexed(&grid, &p, &[0, 1, 3, 2], 0, |q| polys.push(q)).unwrap();
/// imp.indexed(&grid, &p, &[0, 1, 0], 1, |q| polys.push(q)).unwrap(); // no area
/// assert!(imp.indexed(&grid, &p, &[0, 1, 9], 2, |q| polys.push(q)).is_err());
/// let report = imp.finish();
/// assert_eq!((polys.len(), polys[0].len(), report.polygons), (1, 4, 1));
/// assert_eq!(report.dropped.len(), 1);
/// ```
#[derive(Debug, Default)]
pub struct FaceImporter {
    report: ImportReport,
    pts: Vec<GridPoint>,
    loop_: Vec<DVec3>,
}

impl FaceImporter {
    /// Imports face `fi` of an indexed mesh: the loop `face` of indices
    /// into `positions`. An index out of range is an error naming the face
    /// and the corner.
    pub fn indexed(
        &mut self,
        grid: &Grid,
        positions: &[DVec3],
        face: &[u32],
        fi: usize,
        mut out: impl FnMut(Polygon),
    ) -> Result<(), InputError> {
        self.indexed_grid(grid, positions, face, fi, |g| out(g.to_polygon(fi as u32)))
    }

    /// [`FaceImporter::indexed`], giving the polygons without their edge
    /// planes (see [`GridPolygon`]).
    pub fn indexed_grid(
        &mut self,
        grid: &Grid,
        positions: &[DVec3],
        face: &[u32],
        fi: usize,
        out: impl FnMut(GridPolygon),
    ) -> Result<(), InputError> {
        let mut loop_ = std::mem::take(&mut self.loop_);
        loop_.clear();
        for (vertex, &v) in face.iter().enumerate() {
            let p = positions.get(v as usize).ok_or(InputError::VertexIndex {
                face: fi,
                vertex,
                index: v,
            })?;
            loop_.push(*p);
        }
        let r = self.face_grid(grid, &loop_, fi, out);
        self.loop_ = loop_;
        r
    }

    /// Imports face `fi`, the loop `face`.
    pub fn face(
        &mut self,
        grid: &Grid,
        face: &[DVec3],
        fi: usize,
        mut out: impl FnMut(Polygon),
    ) -> Result<(), InputError> {
        self.face_grid(grid, face, fi, |g| out(g.to_polygon(fi as u32)))
    }

    /// [`FaceImporter::face`], giving the polygons without their edge
    /// planes (see [`GridPolygon`]).
    pub fn face_grid(
        &mut self,
        grid: &Grid,
        face: &[DVec3],
        fi: usize,
        out: impl FnMut(GridPolygon),
    ) -> Result<(), InputError> {
        self.report.faces += 1;
        let mut pts = std::mem::take(&mut self.pts);
        pts.clear();
        for (vi, p) in face.iter().enumerate() {
            let g = grid.snap(*p).map_err(|e| InputError::Snap {
                face: fi,
                vertex: vi,
                value: p.to_array(),
                reason: e,
            })?;
            pts.push(g);
        }
        self.grid_loop(&pts, fi, out);
        self.pts = pts;
        Ok(())
    }

    /// [`FaceImporter::indexed_grid`] with the positions snapped already:
    /// `snapped[v]` is `grid.snap(positions[v])` where that succeeds
    /// ([`snap_positions`]). The same polygons, report and errors, without
    /// snapping a vertex again for every face it is a corner of.
    pub fn indexed_snapped(
        &mut self,
        grid: &Grid,
        positions: &[DVec3],
        snapped: &[Option<GridPoint>],
        face: &[u32],
        fi: usize,
        out: impl FnMut(GridPolygon),
    ) -> Result<(), InputError> {
        let mut pts = std::mem::take(&mut self.pts);
        pts.clear();
        for &v in face {
            match snapped.get(v as usize) {
                Some(&Some(g)) => pts.push(g),
                // a bad index or a vertex off the grid: the error as
                // the face's own import names it
                _ => {
                    self.pts = pts;
                    return self.indexed_grid(grid, positions, face, fi, out);
                }
            }
        }
        self.report.faces += 1;
        self.grid_loop(&pts, fi, out);
        self.pts = pts;
        Ok(())
    }

    /// The polygons of face `fi`, the loop of grid points `pts`.
    fn grid_loop(&mut self, pts: &[GridPoint], fi: usize, mut out: impl FnMut(GridPolygon)) {
        let report = &mut self.report;
        match GridPolygon::from_grid_points(pts) {
            Ok(p) => {
                report.polygons += 1;
                out(p);
            }
            Err(defect @ (FaceDefect::NonConvex | FaceDefect::NonPlanar)) => {
                let Some(tris) = triangulate(pts, defect) else {
                    report.dropped.push((fi, FaceDefect::NotSimple));
                    return;
                };
                let before = report.polygons;
                for t in tris.iter() {
                    if let Ok(p) = GridPolygon::from_grid_points(t) {
                        report.polygons += 1;
                        out(p);
                    }
                }
                if report.polygons == before {
                    report.dropped.push((fi, defect));
                } else {
                    report.triangulated.push((fi, defect));
                }
            }
            Err(defect) => report.dropped.push((fi, defect)),
        }
    }

    /// What happened to the faces imported so far.
    pub fn finish(self) -> ImportReport {
        self.report
    }
}

/// Each position snapped to `grid` ([`Grid::snap`]), `None` where that
/// fails, in parallel: for [`FaceImporter::indexed_snapped`].
pub fn snap_positions(grid: &Grid, positions: &[DVec3]) -> Vec<Option<GridPoint>> {
    crate::par::map_slice(positions, |&p| grid.snap(p).ok())
}

/// Triangles covering the loop: for a planar loop, triangles that tile it
/// exactly (ear clipping, the loop split where a corner repeats if need
/// be), or `None` where it touches or crosses itself so that none do; a
/// fan for a loop out of one plane.
fn triangulate(pts: &[GridPoint], defect: FaceDefect) -> Option<Vec<[GridPoint; 3]>> {
    let mut v: Vec<GridPoint> = Vec::with_capacity(pts.len());
    for p in pts {
        if v.last() != Some(p) {
            v.push(*p);
        }
    }
    while v.len() > 1 && v.first() == v.last() {
        v.pop();
    }
    if defect == FaceDefect::NonConvex
        && let Ok(plane) = support_plane(&v)
    {
        return tile(&v, &Projection::of(&plane));
    }
    Some(
        (1..v.len().saturating_sub(1))
            .map(|i| [v[0], v[i], v[i + 1]])
            .collect(),
    )
}

/// `true` if every vertex of every polygon lies exactly on its support plane
/// (used by tests of importers).
pub fn all_planar(polys: &[Polygon]) -> bool {
    polys.iter().all(|p| {
        p.vertices()
            .iter()
            .all(|v| v.classify(p.support()) == Side::On)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn import(face: &[[f64; 3]]) -> (Vec<Polygon>, ImportReport) {
        let f: Vec<DVec3> = face.iter().map(|p| DVec3::from_array(*p)).collect();
        let grid = Grid::new(DVec3::ZERO, 0).unwrap();
        import_faces(&grid, [&f[..]]).unwrap()
    }

    #[test]
    fn snapped_positions_import_as_the_positions_do() {
        // triangles, an L (ear-clipped), a degenerate face, a bad index,
        // and a vertex beyond the grid's range and one not finite
        let grid = Grid::new(DVec3::ZERO, 0).unwrap();
        let mut positions: Vec<DVec3> = (0..6)
            .flat_map(|i| {
                L_SHAPE
                    .iter()
                    .map(move |p| DVec3::from_array(*p) + i as f64)
            })
            .collect();
        let far = positions.len() as u32;
        positions.push(DVec3::new(1e9, 0.0, 0.0));
        positions.push(DVec3::new(f64::NAN, 0.0, 0.0));
        let n = L_SHAPE.len() as u32;
        let mut faces: Vec<Vec<u32>> = (0..6).map(|i| (i * n..(i + 1) * n).collect()).collect();
        faces.push(vec![0, 1, 2]);
        faces.push(vec![0, 0, 1]);
        faces.push(vec![0, 1, far]);
        faces.push(vec![0, far + 1, 1]);
        faces.push(vec![0, 1, far + 7]);
        let snapped = snap_positions(&grid, &positions);
        assert_eq!(snapped[far as usize], None);
        let run = |pre: bool| {
            let mut imp = FaceImporter::default();
            let mut polys = Vec::new();
            let results: Vec<Result<(), InputError>> = faces
                .iter()
                .enumerate()
                .map(|(fi, f)| {
                    let out = |p: GridPolygon| polys.push((p.vertices().to_vec(), *p.support()));
                    if pre {
                        imp.indexed_snapped(&grid, &positions, &snapped, f, fi, out)
                    } else {
                        imp.indexed_grid(&grid, &positions, f, fi, out)
                    }
                })
                .collect();
            (results, polys, imp.finish())
        };
        let (r0, p0, rep0) = run(false);
        let (r1, p1, rep1) = run(true);
        // (as text: a NaN coordinate is not equal to itself)
        assert_eq!(format!("{r0:?}"), format!("{r1:?}"));
        assert_eq!(rep0, rep1);
        assert_eq!(p0, p1);
        assert!(r0.iter().filter(|r| r.is_err()).count() == 3, "{r0:?}");
        assert!(!rep0.triangulated.is_empty() && !rep0.dropped.is_empty());
    }

    #[test]
    fn indexed_import_matches_the_loops() {
        // many faces (several runs): triangles, a quad, an L (ear-clipped),
        // a non-planar quad (fanned) and a degenerate one (dropped)
        let mut positions = Vec::new();
        let mut faces: Vec<Vec<u32>> = Vec::new();
        for i in 0..10_000 {
            let b = positions.len() as u32;
            let x = (i % 100) as f64 * 3.0;
            let y = (i / 100) as f64 * 3.0;
            let shape: &[[f64; 3]] = match i % 5 {
                0 => &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]],
                1 => &[[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
                2 => L_SHAPE,
                3 => &[[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 1.]],
                _ => &[[0., 0., 0.], [1., 1., 1.], [2., 2., 2.]],
            };
            positions.extend(shape.iter().map(|p| DVec3::new(p[0] + x, p[1] + y, p[2])));
            faces.push((b..b + shape.len() as u32).collect());
        }
        let grid = Grid::fit_points(&positions).unwrap();
        let loops: Vec<Vec<DVec3>> = faces
            .iter()
            .map(|f| f.iter().map(|&v| positions[v as usize]).collect())
            .collect();
        let (want, want_report) = import_faces(&grid, loops.iter().map(|f| &f[..])).unwrap();
        let (runs, report) = import_indexed_par(&grid, &positions, &faces).unwrap();
        assert!(runs.len() > 1);
        let got: Vec<Polygon> = runs.into_iter().flatten().collect();
        let same = |got: &[Polygon], want: &[Polygon]| {
            assert_eq!(got.len(), want.len());
            for (g, w) in got.iter().zip(want) {
                assert_eq!(g.tag(), w.tag());
                assert_eq!(g.support(), w.support());
                assert_eq!(g.vertices_f64(), w.vertices_f64());
            }
        };
        assert_eq!(report, want_report);
        same(&got, &want);
        // the parallel imports that place each face's polygon: mixed faces
        // (the others imported again in order), and faces that are all one
        // polygon each (the triangles and quads alone)
        let by_index = |faces: &[Vec<u32>]| {
            import_mesh_par(&grid, &positions, faces.len(), &|f| &faces[f][..])
        };
        let (got, report) = import_faces_par(&grid, &loops).unwrap();
        assert_eq!(report, want_report);
        same(&got, &want);
        let (got, report) = by_index(&faces).unwrap();
        assert_eq!(report, want_report);
        same(&got, &want);
        let simple: Vec<Vec<u32>> = faces.iter().step_by(5).cloned().collect();
        let simple_loops: Vec<Vec<DVec3>> = loops.iter().step_by(5).cloned().collect();
        let (want, want_report) = import_faces(&grid, simple_loops.iter().map(|f| &f[..])).unwrap();
        assert_eq!(want_report.polygons, simple.len());
        let (got, report) = by_index(&simple).unwrap();
        assert_eq!(report, want_report);
        same(&got, &want);
        let (got, report) = import_faces_par(&grid, &simple_loops).unwrap();
        assert_eq!(report, want_report);
        same(&got, &want);
        // a face naming a vertex the mesh does not have is an error, not
        // a panic; the first such face in order is named
        faces[7_000].push(positions.len() as u32);
        faces[9_000].push(positions.len() as u32 + 1);
        let error = InputError::VertexIndex {
            face: 7_000,
            vertex: 3,
            index: positions.len() as u32,
        };
        assert_eq!(
            import_indexed_par(&grid, &positions, &faces).unwrap_err(),
            error
        );
        assert_eq!(by_index(&faces).unwrap_err(), error);
    }

    /// A non-convex planar face.
    const L_SHAPE: &[[f64; 3]] = &[
        [0., 0., 0.],
        [2., 0., 0.],
        [2., 1., 0.],
        [1., 1., 0.],
        [1., 2., 0.],
        [0., 2., 0.],
    ];

    #[test]
    fn l_shape_is_ear_clipped() {
        let (p, r) = import(L_SHAPE);
        assert_eq!(p.len(), 4);
        assert_eq!(r.triangulated, vec![(0, FaceDefect::NonConvex)]);
        assert!(p.iter().all(|q| q.support().normal() == [0, 0, 1]));
        assert_eq!(
            r.counts(),
            "4 polygons after import (1 faces triangulated, 0 dropped)"
        );
    }

    #[test]
    fn non_planar_quad_is_fanned_and_degenerate_dropped() {
        let (p, r) = import(&[[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 1.]]);
        assert_eq!(p.len(), 2);
        assert_eq!(r.triangulated, vec![(0, FaceDefect::NonPlanar)]);
        let (p, r) = import(&[[0., 0., 0.], [1., 1., 1.], [2., 2., 2.]]);
        assert!(p.is_empty());
        assert_eq!(r.dropped, vec![(0, FaceDefect::ZeroArea)]);
    }

    #[test]
    fn bad_coordinates_name_face_and_vertex() {
        let f = [DVec3::ZERO, DVec3::X, DVec3::new(f64::NAN, 0.0, 0.0)];
        let grid = Grid::new(DVec3::ZERO, 0).unwrap();
        let e = import_faces(&grid, [&f[..]]).unwrap_err();
        assert!(
            matches!(
                e,
                InputError::Snap {
                    face: 0,
                    vertex: 2,
                    ..
                }
            ),
            "{e}"
        );
        assert!(e.to_string().contains("face 0"));
    }

    /// Twice the area of polygons in the plane z = 0.
    fn area2(polys: &[Polygon]) -> f64 {
        polys
            .iter()
            .map(|p| {
                let v = p.vertices_f64();
                (1..v.len() - 1)
                    .map(|i| {
                        let (a, b, c) = (v[0], v[i], v[i + 1]);
                        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
                    })
                    .sum::<f64>()
            })
            .sum()
    }

    #[test]
    fn a_loop_that_touches_itself_is_tiled_part_by_part_or_dropped() {
        let at = |pts: &[(f64, f64)]| -> Vec<[f64; 3]> {
            pts.iter().map(|&(x, y)| [x, y, 0.0]).collect()
        };
        // two triangles meeting at one corner, the loop through it twice:
        // area 2, not the 4 that a fan over it covers (overlapping)
        let pinched = at(&[
            (4.0, 0.0),
            (6.0, 0.0),
            (5.0, 1.0),
            (6.0, 2.0),
            (4.0, 2.0),
            (5.0, 1.0),
        ]);
        let (polys, r) = import(&pinched);
        assert_eq!(area2(&polys), 4.0);
        assert_eq!(r.triangulated, vec![(0, FaceDefect::NonConvex)]);
        // a hole pinched off at a corner (its part turns the other way),
        // and a star whose edges cross: no triangles tile them
        let hole = at(&[
            (0.0, 0.0),
            (4.0, 0.0),
            (4.0, 4.0),
            (0.0, 4.0),
            (0.0, 0.0),
            (1.0, 2.0),
            (2.0, 2.0),
            (2.0, 1.0),
        ]);
        let star = at(&[
            (0.0, 10.0),
            (6.0, -8.0),
            (-10.0, 3.0),
            (10.0, 3.0),
            (-6.0, -8.0),
        ]);
        for face in [hole, star] {
            let (polys, r) = import(&face);
            assert!(polys.is_empty());
            assert_eq!(r.dropped, vec![(0, FaceDefect::NotSimple)]);
        }
        assert_eq!(
            FaceDefect::NotSimple.to_string(),
            "not simple: its boundary touches or crosses itself"
        );
    }
}
