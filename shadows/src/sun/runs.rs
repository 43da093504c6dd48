//! A study's runs: [`HoursRun`], one run of suns' share of the hours
//! (made here or on another process, sent as bytes, folded in order), and
//! the mesh snapped once for all of them ([`StudyScene`]).

use std::sync::{Arc, Mutex};

use glam::DVec3;
use rayon::prelude::*;
use smallvec::SmallVec;

use super::tiles::{Tile, TileIndex};
use super::{FaceCells, FaceHours, Part, face_hours};

/// A study's mesh snapped and imported once for all its runs: suns add
/// no point to the grid ([`svbsp::shared_grid`]), so each run's own grid
/// and faces would be these.
pub(super) struct Snapped {
    grid: bsp_core::Grid,
    polys: Vec<bsp_core::Polygon>,
    /// The parts of `polys` certified to bound solids.
    solids: bsp_core::SolidParts,
    /// `polys` cut into tiles, for the last number of tiles asked.
    tiles: Mutex<Option<Arc<TileIndex>>>,
}

/// A study's mesh snapped to its grid and imported once, for any number
/// of runs ([`HoursRun::on`]): what the tasks of a distributed study on
/// one worker can share.
pub struct StudyScene(Snapped);

impl StudyScene {
    /// `mesh` snapped and imported.
    pub fn new(mesh: &crate::Mesh) -> Result<StudyScene, crate::Error> {
        Snapped::new(mesh).map(StudyScene)
    }
}

impl Snapped {
    /// `mesh` snapped and imported.
    pub(super) fn new(mesh: &crate::Mesh) -> Result<Snapped, crate::Error> {
        let grid = svbsp::shared_grid(&mesh.positions, &[]).map_err(crate::Error::Light)?;
        let (polys, _) = crate::import_mesh(&grid, mesh).map_err(crate::Error::Import)?;
        let solids = bsp_core::certify_solid_parts(&polys);
        Ok(Snapped {
            grid,
            polys,
            solids,
            tiles: Mutex::new(None),
        })
    }

    /// The polygons cut into `per_side × per_side` tiles, made once for
    /// as many runs as ask for that many; `None` where they cannot be
    /// ([`TileIndex::new`]).
    fn tile_index(&self, per_side: usize) -> Option<Arc<TileIndex>> {
        let mut last = self.tiles.lock().expect("the tiles' lock");
        if let Some(t) = last.as_ref().filter(|t| t.per_side == per_side) {
            return Some(t.clone());
        }
        let index = Arc::new(TileIndex::new(&self.polys, per_side)?);
        *last = Some(index.clone());
        Some(index)
    }
}

/// One run's share of a study's sun-hours: for at most
/// [`svbsp::MAX_LIGHTS`] suns, every face's area, its lit area summed
/// over the suns times the step, and (for the extremes) its pieces with
/// the number of suns each sees.
#[derive(Clone, Debug, PartialEq)]
pub struct HoursRun {
    step_hours: f64,
    /// The mesh's face count.
    faces: usize,
    /// The faces the run shades, ascending (a tile's), or `None` for all;
    /// `area`, `lit` and `cells` are theirs, in this order.
    ids: Option<Vec<u32>>,
    area: Vec<f64>,
    lit: Vec<f64>,
    cells: Option<Vec<FaceCells>>,
    /// The grid the cells' corners are on.
    grid: bsp_core::Grid,
}

impl HoursRun {
    /// The run of `suns` (at most [`svbsp::MAX_LIGHTS`]) over `mesh`, with
    /// its pieces (for [`sun_hours`](super::sun_hours)).
    pub fn new(
        mesh: &crate::Mesh,
        suns: &[DVec3],
        step_hours: f64,
    ) -> Result<HoursRun, crate::Error> {
        HoursRun::make(
            mesh,
            suns,
            step_hours,
            Some(None),
            &Snapped::new(mesh)?,
            None,
        )
    }

    /// The run without its pieces (for [`sun_hours_mean`](super::sun_hours_mean)).
    pub fn mean_only(
        mesh: &crate::Mesh,
        suns: &[DVec3],
        step_hours: f64,
    ) -> Result<HoursRun, crate::Error> {
        HoursRun::make(mesh, suns, step_hours, None, &Snapped::new(mesh)?, None)
    }

    /// The run of `suns` over the faces of `tile` only (see [`Tile`]),
    /// with their pieces if `extremes`: the runs of every tile, folded in
    /// order with [`HoursRun::fold`], are [`sun_hours_in_tiles`](super::sun_hours_in_tiles)'s study.
    pub fn of_tile(
        mesh: &crate::Mesh,
        suns: &[DVec3],
        step_hours: f64,
        extremes: bool,
        tile: Tile,
    ) -> Result<HoursRun, crate::Error> {
        let scene = StudyScene::new(mesh)?;
        HoursRun::on(&scene, mesh, suns, step_hours, extremes, Some(tile))
    }

    /// The run of `suns` over `mesh` snapped once as `scene` (of this
    /// mesh): [`HoursRun::new`] (or [`HoursRun::mean_only`] without
    /// `extremes`), or [`HoursRun::of_tile`] with a tile, the same bits,
    /// without snapping and importing the mesh again for every run.
    pub fn on(
        scene: &StudyScene,
        mesh: &crate::Mesh,
        suns: &[DVec3],
        step_hours: f64,
        extremes: bool,
        tile: Option<Tile>,
    ) -> Result<HoursRun, crate::Error> {
        let pieces = extremes.then_some(None);
        HoursRun::make(mesh, suns, step_hours, pieces, &scene.0, tile)
    }

    /// The run of `lights` (suns) over every face, mean hours alone: the
    /// lit areas, no fragments (`crate::lit`).
    fn mean_of(
        faces: usize,
        lights: &[crate::Light],
        step_hours: f64,
        s: &Snapped,
    ) -> Result<HoursRun, crate::Error> {
        let got = crate::lit::lit_areas_on(&s.grid, &s.polys, &s.solids, faces, lights)?;
        let n = lights.len();
        let lit = (0..faces)
            .map(|f| got.lit[f * n..(f + 1) * n].iter().sum::<f64>() * step_hours)
            .collect();
        Ok(HoursRun {
            step_hours,
            faces,
            ids: None,
            area: got.area,
            lit,
            cells: None,
            grid: s.grid,
        })
    }

    /// The run on the study's `snapped` mesh; with `pieces`, the pieces
    /// of every face, or with `Some(Some(keep))` of the faces `keep`
    /// marks; of `tile`'s faces only if given.
    pub(super) fn make(
        mesh: &crate::Mesh,
        suns: &[DVec3],
        step_hours: f64,
        pieces: Option<Option<&[bool]>>,
        snapped: &Snapped,
        tile: Option<Tile>,
    ) -> Result<HoursRun, crate::Error> {
        let faces = mesh.faces.len();
        let lights: Vec<crate::Light> = suns.iter().map(|&d| crate::Light::Sun(d)).collect();
        // the tile's polygons, the box they lie in, and every polygon's box
        let index = tile.map(|t| (t, snapped.tile_index(t.per_side)));
        let part = match &index {
            None => None,
            Some((t, index)) => Some(
                (index
                    .as_deref()
                    .and_then(|i| Some((i.get(*t)?, &i.boxes[..]))))
                .ok_or(crate::Error::Tile {
                    index: t.index,
                    per_side: t.per_side,
                })?,
            ),
        };
        let shaded = match part {
            None => None,
            Some((own, boxes)) => match own.bounds {
                Some(b) => Some((&own.polys[..], b, boxes)),
                None => {
                    return Ok(HoursRun::empty(
                        faces,
                        step_hours,
                        pieces,
                        &own.faces,
                        snapped.grid,
                    ));
                }
            },
        };
        let s = snapped;
        if pieces.is_none() && part.is_none() {
            return HoursRun::mean_of(faces, &lights, step_hours, s);
        }
        let run = crate::shadows_on(
            &s.grid,
            &s.polys,
            &s.solids,
            faces,
            &lights,
            shaded,
            &svbsp::ShadeOptions::default()
                .with_pieces(pieces.is_some())
                .with_planes(pieces.is_some())
                .with_merge(pieces.is_none())
                .with_vertices(false),
        )?;
        let ids = part.map(|(own, _)| own.faces.clone());
        let order: Vec<usize> = match &ids {
            Some(ids) => ids.iter().map(|&f| f as usize).collect(),
            None => (0..faces).collect(),
        };
        let area: Vec<f64> = order.iter().map(|&f| run.face_area(f)).collect();
        let lit = (order.iter())
            .map(|&f| (0..suns.len()).map(|l| run.lit_area(f, l)).sum::<f64>() * step_hours)
            .collect();
        let mut out = HoursRun {
            step_hours,
            faces,
            ids,
            area,
            lit,
            cells: None,
            grid: s.grid,
        };
        let Some(keep) = pieces else {
            return Ok(out);
        };
        // each face's place in the run's lists
        let mut slot = vec![usize::MAX; faces];
        for (k, &f) in order.iter().enumerate() {
            slot[f] = k;
        }
        let kept = |f: usize| keep.is_none_or(|k| k[f]);
        let cells = run_cells(&run.batch, &slot, order.len(), kept);
        out.cells = Some(cells);
        Ok(out)
    }

    /// The run of a tile with no face (`ids`: none, but kept as given),
    /// with pieces if asked.
    fn empty(
        faces: usize,
        step_hours: f64,
        pieces: Option<Option<&[bool]>>,
        ids: &[u32],
        grid: bsp_core::Grid,
    ) -> HoursRun {
        let n = ids.len();
        HoursRun {
            step_hours,
            faces,
            ids: Some(ids.to_vec()),
            area: vec![0.0; n],
            lit: vec![0.0; n],
            cells: pieces.map(|_| vec![Vec::new(); n]),
            grid,
        }
    }

    /// The number of faces of the run's mesh.
    pub fn faces(&self) -> usize {
        self.faces
    }

    /// The runs' faces' hours, the runs taken in order (`faces`: the
    /// mesh's face count, for no runs at all; every run must be of a mesh
    /// of as many faces, see [`HoursRun::faces`]). The extremes are NaN if a
    /// run has no pieces. Faces are overlaid in parallel, each the same
    /// whatever the thread count.
    pub fn fold<I>(faces: usize, runs: I) -> Result<Vec<FaceHours>, crate::Error>
    where
        I: IntoIterator<Item = Result<HoursRun, crate::Error>>,
        I::IntoIter: Send,
    {
        let (area, lit, cells, step_hours) = HoursRun::fold_cells(faces, runs)?;
        Ok((0..faces)
            .into_par_iter()
            .map(|f| match &cells {
                Some((cells, grid)) => face_hours(
                    area[f],
                    lit[f],
                    cells[f].as_deref().map(|c| (c, grid)),
                    step_hours,
                ),
                None => FaceHours {
                    min_hours: f64::NAN,
                    max_hours: f64::NAN,
                    ..face_hours(area[f], lit[f], None, step_hours)
                },
            })
            .collect())
    }

    /// The runs folded in order: every face's area, its lit area times
    /// hours, its overlaid cells and their grid (`None` if a run has no
    /// pieces; a face `None` for no runs), and the step. Each face's
    /// parts (one a support plane) are overlaid exactly
    /// ([`svbsp::FaceOverlay::plus`]), faces in parallel.
    #[allow(clippy::type_complexity)] // (the fold's four results, named above)
    pub(super) fn fold_cells<I>(
        faces: usize,
        runs: I,
    ) -> Result<
        (
            Vec<f64>,
            Vec<f64>,
            Option<(Vec<Option<FaceCells>>, bsp_core::Grid)>,
            f64,
        ),
        crate::Error,
    >
    where
        I: IntoIterator<Item = Result<HoursRun, crate::Error>>,
        I::IntoIter: Send,
    {
        let mut area = vec![0.0; faces];
        let mut lit = vec![0.0; faces];
        let mut cells: Vec<Option<FaceCells>> = vec![None; faces];
        let (mut step_hours, mut pieces, mut grid) = (0.0, true, None);
        let mut add = |run: HoursRun| -> Result<(), crate::Error> {
            step_hours = run.step_hours;
            grid = Some(run.grid);
            // the run's faces, in its lists' order, within the mesh's
            let ids: Vec<usize> = match &run.ids {
                Some(ids) => ids.iter().map(|&f| f as usize).collect(),
                None => (0..run.area.len()).collect(),
            };
            let ids = &ids[..ids.partition_point(|&f| f < faces).min(run.area.len())];
            for (k, &f) in ids.iter().enumerate() {
                area[f] = run.area[k];
                lit[f] += run.lit[k];
            }
            match run.cells {
                Some(new) if pieces => {
                    let mut both: Vec<_> = (ids.iter().zip(new))
                        .map(|(&f, new)| (f, cells[f].take().map(Ok), new))
                        .collect();
                    bsp_core::par::for_each_mut(&mut both, |_, (_, old, new)| {
                        let new = std::mem::take(new);
                        *old = Some(match old.take() {
                            None => Ok(new),
                            Some(old) => old.and_then(|old| overlay_parts(old, new)),
                        });
                    });
                    for (f, c, _) in both {
                        cells[f] = match c {
                            Some(Err(())) => return Err(crate::Error::Runs { face: f }),
                            Some(Ok(c)) => Some(c),
                            None => None,
                        };
                    }
                }
                _ => {
                    pieces = false;
                    cells = vec![None; faces];
                }
            }
            Ok(())
        };
        // a run with pieces folded while the next is made (a large face's
        // overlay is one task, which would leave the other threads idle);
        // one without, first (made inside a join, the next run's shading
        // took 1.09 times as long, for a fold of no work)
        let mut runs = runs.into_iter();
        let mut pending = runs.next();
        while let Some(run) = pending {
            let run = run?;
            let (done, next) = match run.cells {
                Some(_) => rayon::join(|| add(run), || runs.next()),
                None => (add(run), runs.next()),
            };
            done?;
            pending = next;
        }
        let cells = match (pieces, grid) {
            (true, Some(grid)) => Some((cells, grid)),
            (true, None) => Some((
                cells,
                bsp_core::Grid::new(DVec3::ZERO, 0).expect("a unit grid"),
            )),
            (false, _) => None,
        };
        Ok((area, lit, cells, step_hours))
    }

    /// The run as bytes (little-endian words of 64 bits: numbers as
    /// `f64`, a plane's integers as their bits), for sending to another
    /// process.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::new();
        let mut word = |x: u64| out.extend_from_slice(&x.to_le_bytes());
        let mut put = |x: f64| word(x.to_bits());
        put(self.step_hours);
        put(self.faces as f64);
        let pieces = if self.cells.is_some() { 1.0 } else { 0.0 };
        match &self.ids {
            None => put(pieces),
            Some(ids) => {
                put(pieces + 2.0);
                put(ids.len() as f64);
                ids.iter().for_each(|&f| put(f64::from(f)));
            }
        }
        let o = self.grid.origin();
        [o.x, o.y, o.z, f64::from(self.grid.step_log2())]
            .into_iter()
            .for_each(&mut put);
        let plane = |p: &bsp_core::Plane, put: &mut dyn FnMut(f64)| {
            let (n, d) = (p.normal(), p.offset());
            n.iter().for_each(|&c| put(f64::from_bits(c as u64)));
            put(f64::from_bits(d as u64));
            put(f64::from_bits((d >> 64) as u64));
        };
        for f in 0..self.area.len() {
            put(self.area[f]);
            put(self.lit[f]);
            let Some(cells) = &self.cells else {
                continue;
            };
            put(cells[f].len() as f64);
            for part in &cells[f] {
                let part = part.overlay();
                plane(part.support(), &mut put);
                put(part.len() as f64);
                for i in 0..part.len() {
                    put(f64::from(part.count(i)));
                    let planes = part.planes(i);
                    put(planes.len() as f64);
                    planes.iter().for_each(|p| plane(p, &mut put));
                }
            }
        }
        out
    }

    /// A run from [`HoursRun::to_bytes`]; `None` if `bytes` is not one
    /// (a cell that is not a strictly convex polygon included).
    pub fn from_bytes(bytes: &[u8]) -> Option<HoursRun> {
        let mut words = bytes
            .chunks_exact(8)
            .map(|w| u64::from_le_bytes(w.try_into().expect("eight bytes")));
        let mut bits = || words.next();
        let mut next = || bits().map(f64::from_bits);
        let count = |x: f64| (x >= 0.0 && x.fract() == 0.0 && x < 1e15).then_some(x as usize);
        let step_hours = next()?;
        let faces = count(next()?)?;
        let (pieces, tiled) = match next()? {
            0.0 => (false, false),
            1.0 => (true, false),
            2.0 => (false, true),
            3.0 => (true, true),
            _ => return None,
        };
        let ids = match tiled {
            false => None,
            true => {
                let n = count(next()?)?;
                let ids = (0..n)
                    .map(|_| u32::try_from(count(next()?)?).ok())
                    .collect::<Option<Vec<u32>>>()?;
                // ascending, each once, faces of the mesh
                let fits = ids.last().is_none_or(|&f| (f as usize) < faces);
                (fits && ids.is_sorted_by(|a, b| a < b))
                    .then_some(ids)?
                    .into()
            }
        };
        let origin = DVec3::new(next()?, next()?, next()?);
        let step = next()?;
        let log2 = (step.fract() == 0.0 && step.abs() <= 1000.0).then_some(-step as i32)?;
        let grid = bsp_core::Grid::new(origin, log2).ok()?;
        let listed = ids.as_ref().map_or(faces, Vec::len);
        let mut run = HoursRun {
            step_hours,
            faces,
            ids,
            area: Vec::new(),
            lit: Vec::new(),
            cells: pieces.then(Vec::new),
            grid,
        };
        let plane = |next: &mut dyn FnMut() -> Option<f64>| {
            let mut w = || next().map(|x| x.to_bits());
            let n = [w()? as i64, w()? as i64, w()? as i64];
            let d = i128::from(w()?) | i128::from(w()? as i64) << 64;
            bsp_core::Plane::new(n, d)
        };
        for _ in 0..listed {
            run.area.push(next()?);
            run.lit.push(next()?);
            let Some(cells) = &mut run.cells else {
                continue;
            };
            let parts = count(next()?)?;
            let mut face = Vec::new();
            for _ in 0..parts {
                let support = plane(&mut next)?;
                let n = count(next()?)?;
                let mut part = Vec::new();
                for _ in 0..n {
                    let seen = u32::try_from(count(next()?)?).ok()?;
                    let len = count(next()?)?;
                    let planes = (0..len)
                        .map(|_| plane(&mut next))
                        .collect::<Option<SmallVec<[bsp_core::Plane; 6]>>>()?;
                    part.push((planes, seen));
                }
                face.push(Part::new(support, part)?);
            }
            cells.push(face);
        }
        (bytes.len().is_multiple_of(8) && next().is_none()).then_some(run)
    }
}

/// Per place in a run's lists (`slot[f]`: face `f`'s place, of
/// `places`), the face's parts from the run's pieces, for the faces
/// `kept` says: a counting sort of the batch's fragments by place, then
/// each face's parts made on its own, faces in parallel.
fn run_cells(
    batch: &svbsp::Batch,
    slot: &[usize],
    places: usize,
    kept: impl Fn(usize) -> bool,
) -> Vec<FaceCells> {
    let mut first = vec![0u32; places + 1];
    for frag in batch.fragments() {
        let f = frag.face() as usize;
        if kept(f) {
            first[slot[f] + 1] += 1;
        }
    }
    for k in 0..places {
        first[k + 1] += first[k];
    }
    let mut at = first.clone();
    let mut frags = vec![0u32; first[places] as usize];
    for (i, frag) in batch.fragments().enumerate() {
        let f = frag.face() as usize;
        if kept(f) {
            frags[at[slot[f]] as usize] = i as u32;
            at[slot[f]] += 1;
        }
    }
    (0..places)
        .into_par_iter()
        .map(|k| face_parts(batch, &frags[first[k] as usize..first[k + 1] as usize]))
        .collect()
}

/// A face's parts from its fragments `frags` of `batch`: per support
/// plane, its pieces' planes (read in the batch, not copied) and the
/// suns each sees.
fn face_parts(batch: &svbsp::Batch, frags: &[u32]) -> FaceCells {
    type Pieces<'a> = Vec<(&'a [bsp_core::Plane], u32)>;
    let mut face: Vec<(bsp_core::Plane, Pieces<'_>)> = Vec::new();
    for &i in frags {
        let frag = batch.fragment(i as usize);
        let seen = frag.lit_mask().count_ones();
        let support = *frag.support();
        let at = match face.iter().position(|(s, _)| *s == support) {
            Some(at) => at,
            None => {
                face.push((support, Vec::new()));
                face.len() - 1
            }
        };
        let planes = frag
            .piece_planes()
            .expect("a study's run is shaded with its pieces' planes");
        face[at].1.extend(planes.map(|p| (p, seen)));
    }
    (face.into_iter())
        .map(|(support, cells)| {
            Part::of_pieces(support, cells).expect("the engine's pieces are strictly convex")
        })
        .collect()
}

/// A face's parts (one overlay a support plane) overlaid with a later
/// run's: part by part, in order; `Err` where the two runs' parts lie in
/// other planes (runs of different meshes).
fn overlay_parts(old: FaceCells, new: FaceCells) -> Result<FaceCells, ()> {
    if old.len() != new.len() {
        return Err(());
    }
    (old.into_iter().zip(&new))
        .map(|(a, b)| a.plus(b).ok_or(()))
        .collect()
}
