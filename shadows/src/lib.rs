//! The BSP shadow toolkit in one dependency, for the common jobs: read a
//! mesh, combine meshes exactly, find the lit and shadowed part of every
//! face for point lights and suns, and write the results. Each job is one
//! to three calls; the crates underneath (`bsp-core`, `bsp-csg`, `svbsp`,
//! `shadow-scene`) hold the rest.
//!
//! ```
//! use bsp_shadows::{DVec3, Light};
//! let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../data/meshes/pyvista_sphere.obj");
//! let sphere = bsp_shadows::read_mesh(path)?;
//! let moved = bsp_shadows::translated(&sphere, DVec3::new(40.0, 20.0, 10.0));
//! let both = bsp_shadows::union(&sphere, &moved)?;
//! let lit = bsp_shadows::shadows(&both, &[Light::Point(DVec3::new(500.0, 300.0, 900.0))])?;
//! let share = lit.lit_fraction(0);
//! assert!(share > 0.3 && share < 0.7, "{share}");
//! # Ok::<(), bsp_shadows::Error>(())
//! ```
//!
//! Every decision is exact for the input snapped to a grid fitted to it
//! (`bsp_core::Grid`): which parts of two meshes a Boolean keeps, which
//! parts of a face a light reaches. The results are rounded once to
//! `f64`.

pub mod art;
pub mod frames;
mod lit;
pub mod prepared;
pub mod shadow_file;
pub mod soft_file;
pub mod sun;
mod volume;

use std::path::Path;

use bsp_csg::files::{FileBoolean, FileError, Operand};
use shadow_scene::SceneError;
use svbsp::export::{ExportError, FragmentFile, FragmentFormat, area_records, world_vertices};
use svbsp::{Batch, LightError, PlacedLight, ShadeOptions, ShadowError};

pub use bsp_core::BoolOp;
pub use glam::DVec3;
pub use shadow_scene::{Face, Mesh, MeshView};
/// A point light at a position, or a sun in a direction (from the scene
/// toward it), in the mesh's units.
pub use svbsp::LightSpec as Light;
/// The most lights one shadow run takes.
pub use svbsp::MAX_LIGHTS;
/// The sun's angular radius, degrees: a sun disc's by default.
pub use svbsp::SUN_RADIUS_DEG;
/// A light of extent: an area light's corners, or a sun disc
/// ([`soft_file::soft_shadows`]).
pub use svbsp::SoftSpec;
pub use volume::volume;

/// Why a job failed; [`std::error::Error::source`] gives the cause.
#[derive(Debug)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be read or written, or is not a mesh.
    File(SceneError),
    /// An operand of a Boolean is not a closed, oriented surface (the
    /// message names the face and edge).
    Boolean(FileError),
    /// A light cannot be placed on the scene's grid.
    Light(LightError),
    /// A face does not fit the grid.
    Import(bsp_core::InputError),
    /// The shadow computation refused its input (too many lights).
    Shadow(ShadowError),
    /// A fragment's vertex leaves `f64` in the mesh's units.
    Export(ExportError),
    /// A picture cannot be drawn (no faces, or a camera that cannot be
    /// set up).
    Raster(shadow_raster::RasterError),
    /// An output could not be written.
    Io(std::io::Error),
    /// A sensor point does not fit the scene's grid.
    Sensor {
        /// Its index.
        index: usize,
        /// Why.
        cause: bsp_core::SnapError,
    },
    /// The faces of a region study cannot be found, or its dates are not
    /// the test's (the message says which).
    Region(String),
    /// A study's runs whose pieces of a face lie in other planes (runs of
    /// different meshes, folded together).
    Runs {
        /// The face.
        face: usize,
    },
    /// A study's tile that is not one of its tiles ([`sun::Tile`]).
    Tile {
        /// The tile asked for.
        index: usize,
        /// The study's tiles along each axis.
        per_side: usize,
    },
    /// An output file's name asks for a format the job cannot write.
    Format {
        /// The file.
        path: std::path::PathBuf,
        /// What the job writes.
        why: &'static str,
    },
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Error::File(e) => e.fmt(f),
            Error::Boolean(e) => e.fmt(f),
            Error::Light(e) => e.fmt(f),
            Error::Import(e) => write!(f, "cannot import the faces: {e}"),
            Error::Shadow(e) => e.fmt(f),
            Error::Export(e) => e.fmt(f),
            Error::Raster(e) => e.fmt(f),
            Error::Io(e) => e.fmt(f),
            Error::Sensor { index, cause } => write!(f, "sensor {index}: {cause}"),
            Error::Format { path, why } => write!(f, "{}: {why}", path.display()),
            Error::Region(why) => f.write_str(why),
            Error::Runs { face } => write!(
                f,
                "the study's runs do not fold together: face {face}'s parts lie in other planes \
                 in one run than in another (runs of different meshes?)"
            ),
            Error::Tile { index, per_side: 0 } => {
                write!(
                    f,
                    "tile {index} of a study cut into no tiles (tiles along each axis: at least 1)"
                )
            }
            Error::Tile { index, per_side } => write!(
                f,
                "tile {index} of a study cut into {per_side} × {per_side} tiles (0 to {})",
                per_side.saturating_mul(*per_side) - 1
            ),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(match self {
            Error::File(e) => e,
            Error::Boolean(e) => e,
            Error::Light(e) => e,
            Error::Import(e) => e,
            Error::Shadow(e) => e,
            Error::Export(e) => e,
            Error::Raster(e) => e,
            Error::Io(e) => e,
            Error::Sensor { cause, .. } => cause,
            Error::Format { .. } | Error::Region(_) | Error::Tile { .. } | Error::Runs { .. } => {
                return None;
            }
        })
    }
}

/// Reads an OBJ, STL or CityJSON file (by its extension: `.json` is
/// CityJSON, one group per city object).
pub fn read_mesh(path: impl AsRef<Path>) -> Result<Mesh, Error> {
    shadow_scene::load(path.as_ref()).map_err(Error::File)
}

/// The fragment file format `path`'s extension asks for: `.json` or
/// `.obj` (any other was written as OBJ text, whatever its name).
pub(crate) fn fragment_format(path: &Path) -> Result<FragmentFormat, Error> {
    match path.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case("json") => Ok(FragmentFormat::Json),
        Some(e) if e.eq_ignore_ascii_case("obj") => Ok(FragmentFormat::Obj),
        _ => Err(Error::Format {
            path: path.to_path_buf(),
            why: "fragments are written as .json or .obj",
        }),
    }
}

/// Writes `mesh` as OBJ or STL (by the extension), through a temporary
/// file renamed into place when complete. For STL the positions are
/// rounded to `f32` first and what that does to a closed surface is
/// mended ([`Mesh::round_closed`]): vertices made equal are welded,
/// the faces that collapse left out, triangles made flat split away, and
/// where that would pinch the surface, vertices are kept one `f32` step
/// apart instead.
pub fn write_mesh(path: impl AsRef<Path>, mesh: &Mesh) -> Result<(), Error> {
    let path = path.as_ref();
    let format = shadow_scene::MeshFormat::from_path(path).map_err(Error::File)?;
    if format == shadow_scene::MeshFormat::Stl {
        let mut rounded = mesh.clone();
        rounded.round_closed(shadow_scene::to_f32, shadow_scene::f32_step);
        if rounded.faces.is_empty() && !mesh.faces.is_empty() {
            return Err(Error::Format {
                path: path.to_path_buf(),
                why: STL_TOO_COARSE,
            });
        }
        return shadow_scene::save(path, &rounded).map_err(Error::File);
    }
    shadow_scene::save(path, mesh).map_err(Error::File)
}

/// Why a mesh is not written as STL when rounding to `f32` collapses
/// every one of its triangles.
pub const STL_TOO_COARSE: &str = "STL stores f32, and rounding to f32 collapses every triangle of \
    this mesh (it is smaller than an f32 step where it lies); nothing was written: write .obj, \
    which keeps f64";

/// `mesh` moved by `by`.
pub fn translated(mesh: &Mesh, by: DVec3) -> Mesh {
    let mut m = mesh.clone();
    m.positions.iter_mut().for_each(|p| *p += by);
    m
}

/// The exact union of two closed, consistently oriented meshes (each the
/// set where its winding number is positive), as a closed triangle mesh
/// whose vertices are the exact ones rounded to `f64` (vertices that
/// rounding makes equal are welded).
pub fn union(a: &Mesh, b: &Mesh) -> Result<Mesh, Error> {
    boolean(a, b, BoolOp::Union)
}

/// The exact intersection of two meshes; see [`union`].
pub fn intersection(a: &Mesh, b: &Mesh) -> Result<Mesh, Error> {
    boolean(a, b, BoolOp::Intersection)
}

/// The exact difference `a − b` of two meshes; see [`union`].
pub fn difference(a: &Mesh, b: &Mesh) -> Result<Mesh, Error> {
    boolean(a, b, BoolOp::Difference)
}

fn boolean(a: &Mesh, b: &Mesh, op: BoolOp) -> Result<Mesh, Error> {
    boolean_of(a.clone(), b.clone(), op)
}

/// [`union`], [`intersection`] or [`difference`] (by `op`) of meshes the
/// caller gives away: no copy of them is made.
pub fn boolean_of(a: Mesh, b: Mesh, op: BoolOp) -> Result<Mesh, Error> {
    let mut operands = [Operand::new("a", a), Operand::new("b", b)];
    let checked = Operand::check_all(&mut operands).map_err(Error::Boolean)?;
    let out = FileBoolean::apply(checked, op, |_, _| {}).map_err(Error::Boolean)?;
    Ok(match out.rounded(false) {
        Some(r) => r.mesh,
        None => out.mesh().to_mesh(),
    })
}

/// The lit and shadowed parts of every face of a mesh, for its lights.
#[derive(Debug)]
pub struct Shadows {
    lights: Vec<PlacedLight>,
    faces: usize,
    batch: Batch,
    world: Vec<DVec3>,
    /// `faces × lights`: the area each light reaches.
    lit: Vec<f64>,
    area: Vec<f64>,
}

/// One fragment of a face: a part that every light either reaches all
/// over or not at all.
#[derive(Clone, Debug, PartialEq)]
pub struct Fragment {
    /// The face (its index in the mesh).
    pub face: usize,
    /// Bit `i` set: light `i` reaches it.
    pub lit: u64,
    /// The outer boundary, counter-clockwise seen from the face's front,
    /// then the holes; in the mesh's units.
    pub rings: Vec<Vec<DVec3>>,
}

/// Shades every face of `mesh` for `lights` (at most 64): see
/// [`Shadows`]. Faces are receivers and occluders alike; a face is lit
/// on its front side only.
///
/// ```
/// use bsp_shadows::{DVec3, Light};
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../data/meshes/teapot.obj");
/// let teapot = bsp_shadows::read_mesh(path)?;
/// let s = bsp_shadows::shadows(&teapot, &[Light::Sun(DVec3::new(1.0, 2.0, 4.0))])?;
/// let face = 0;
/// assert!(s.lit_area(face, 0) <= s.face_area(face));
/// assert!(s.fragments().all(|f| f.rings[0].len() >= 3));
/// # Ok::<(), bsp_shadows::Error>(())
/// ```
pub fn shadows(mesh: &Mesh, lights: &[Light]) -> Result<Shadows, Error> {
    let grid = svbsp::shared_grid(&mesh.positions, lights).map_err(Error::Light)?;
    let (polys, _) = crate::import_mesh(&grid, mesh).map_err(Error::Import)?;
    let solids = bsp_core::certify_solid_parts(&polys);
    shadows_on(
        &grid,
        &polys,
        &solids,
        mesh.faces.len(),
        lights,
        None,
        &ShadeOptions::default(),
    )
}

/// The faces of `mesh` snapped to `grid` and imported, in parallel, as
/// exact convex polygons tagged with their face numbers
/// ([`bsp_core::import_mesh_par`]).
pub fn import_mesh(
    grid: &bsp_core::Grid,
    mesh: &Mesh,
) -> Result<(Vec<bsp_core::Polygon>, bsp_core::ImportReport), bsp_core::InputError> {
    bsp_core::import_mesh_par(grid, &mesh.positions, mesh.faces.len(), &|f| {
        &mesh.faces[f].vertices[..]
    })
}

/// A tile's part of a study's run ([`shadows_on`]): its polygons
/// (indices into the scene's), the grid box they lie in, and the grid box
/// of every polygon of the scene.
pub(crate) type TilePart<'a> = (
    &'a [usize],
    [bsp_core::GridPoint; 2],
    &'a [[bsp_core::GridPoint; 2]],
);

/// [`shadows`] of the `faces` faces of a mesh already snapped to `grid`
/// (which must hold the point lights) and imported as `polys`: what a sun
/// study shares between its runs. With `tile`, of that tile's polygons
/// only (indices into `polys`, within the box given), past the occluders
/// that may hide a light from that box, by the boxes of `polys` given
/// ([`sun::Tile`]); the other faces get no fragment.
pub(crate) fn shadows_on(
    grid: &bsp_core::Grid,
    polys: &[bsp_core::Polygon],
    solids: &bsp_core::SolidParts,
    faces: usize,
    lights: &[Light],
    tile: Option<TilePart<'_>>,
    opts: &ShadeOptions,
) -> Result<Shadows, Error> {
    let placed = svbsp::place_lights(grid, lights).map_err(Error::Light)?;
    let kernel: Vec<svbsp::Light> = placed.iter().map(|l| l.light).collect();
    let reach = tile.map(|(_, b, boxes)| (b, boxes));
    // (untiled, every face is shaded: what the trees' building found of
    // each is kept)
    let trees = face_trees_with(polys, &kernel, &[], solids, reach, tile.is_none())
        .map_err(Error::Shadow)?;
    // with convex pieces where asked (the OBJ writer draws them), and
    // their planes (a sun study's extremes overlay them)
    let batch = match tile {
        None => trees.set_for_occluders().shade_all(polys, opts),
        Some((own, _, _)) => {
            let own: Vec<bsp_core::Polygon> = own.iter().map(|&i| polys[i].clone()).collect();
            trees.set().shade_all(&own, opts)
        }
    };
    let world = world_vertices(&batch, grid).map_err(Error::Export)?;
    let (mut lit, mut area) = (vec![0.0; faces * placed.len()], vec![0.0; faces]);
    for r in area_records(&batch, &world) {
        let f = r.face as usize;
        area[f] += r.area;
        for (i, l) in lit[f * placed.len()..(f + 1) * placed.len()]
            .iter_mut()
            .enumerate()
        {
            if r.lit >> i & 1 == 1 {
                *l += r.area;
            }
        }
    }
    Ok(Shadows {
        lights: placed,
        faces,
        batch,
        world,
        lit,
        area,
    })
}

/// One shadow-volume tree per light over the faces `polys`, for shading
/// those faces and asking at the grid points `also`: each light's tree
/// holds only the faces that may hide it from some face or point
/// ([`may_hide`]; the others change no fragment's class and no point's
/// light).
///
/// Nor the faces turned away from a light of the parts `solids` certifies
/// to bound solids ([`svbsp::Light::leaves_out`]; `solids` is
/// [`bsp_core::certify_solid_parts`] of `polys`): their other faces hide
/// all they hide, from every face and point.
///
/// With `reach` (a grid box holding every face to be shaded and every
/// point to be asked, in place of all of `polys` and `also`, and the grid
/// box of each of `polys`), nor the faces whose box no way from the box
/// toward the light meets.
pub(crate) fn face_trees(
    polys: &[bsp_core::Polygon],
    kernel: &[svbsp::Light],
    also: &[bsp_core::GridPoint],
    solids: &bsp_core::SolidParts,
    reach: Option<([bsp_core::GridPoint; 2], &[[bsp_core::GridPoint; 2]])>,
) -> Result<svbsp::LightVolumes, ShadowError> {
    face_trees_with(polys, kernel, also, solids, reach, false)
}

/// [`face_trees`], with `reaching` keeping what each tree's building
/// found of the faces it holds, for shading `polys` themselves
/// ([`svbsp::LightVolumes::set_for_occluders`]).
fn face_trees_with(
    polys: &[bsp_core::Polygon],
    kernel: &[svbsp::Light],
    also: &[bsp_core::GridPoint],
    solids: &bsp_core::SolidParts,
    reach: Option<([bsp_core::GridPoint; 2], &[[bsp_core::GridPoint; 2]])>,
    reaching: bool,
) -> Result<svbsp::LightVolumes, ShadowError> {
    let bounds = (reach.map(|(b, _)| b))
        .or_else(|| sun::grid_bounds(polys))
        .map(|[mut lo, mut hi]| {
            for p in also {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            [lo, hi]
        });
    let built = bsp_core::par::try_map(kernel.len(), |j| {
        let index: Vec<usize> = hiding(polys, &kernel[j], bounds, solids, reach).collect();
        if reaching {
            return svbsp::ShadowVolumes::build_reached_among(kernel[j], polys, &index);
        }
        let tree: Vec<&bsp_core::Polygon> = index.iter().map(|&i| &polys[i]).collect();
        svbsp::ShadowVolumes::build(kernel[j], &tree).map(|v| (v, Vec::new()))
    })?;
    let (volumes, reached): (Vec<_>, Vec<_>) = built.into_iter().unzip();
    match reaching {
        true => svbsp::LightVolumes::from_volumes_reached(kernel, volumes, reached),
        false => svbsp::LightVolumes::from_volumes(kernel, volumes),
    }
}

/// The indices of the faces of `polys` that [`face_trees`] puts in the
/// tree of `light`, where `bounds` holds every face and point to be
/// shaded (see there).
fn hiding<'a>(
    polys: &'a [bsp_core::Polygon],
    light: &'a svbsp::Light,
    bounds: Option<[bsp_core::GridPoint; 2]>,
    solids: &'a bsp_core::SolidParts,
    reach: Option<([bsp_core::GridPoint; 2], &'a [[bsp_core::GridPoint; 2]])>,
) -> impl Iterator<Item = usize> + 'a {
    (polys.iter().enumerate())
        .filter(move |(i, p)| {
            // (the tile's sweep first: the cheapest test, and the one
            // that leaves most faces out)
            reach.is_none_or(|(b, boxes)| sun::may_shade(light, b, boxes[*i]))
                && bounds.is_none_or(|b| may_hide(light, p.support(), b))
                && !light.leaves_out(solids, *i, p.support())
        })
        .map(|(i, _)| i)
}

/// Whether a face of plane `support` may hide `light` from some point of
/// the box `[lo, hi]`: its shadow lies strictly behind its plane seen from
/// the light, so where no corner of the box is there (a ground under
/// everything, a room's walls), it hides nothing from the faces in the
/// box, and its volume can be left out of the light's tree with every
/// fragment's class unchanged. Exact (`i128` on grid coordinates).
fn may_hide(light: &svbsp::Light, support: &bsp_core::Plane, [lo, hi]: [[i32; 3]; 2]) -> bool {
    let side = light.eval(support).signum();
    if side == 0 {
        return true; // (edge-on: the engine skips it anyway)
    }
    let n = support.normal();
    // the corner farthest behind the plane, seen from the light
    let corner: [i32; 3] = std::array::from_fn(|k| {
        if (n[k] as i128) * side > 0 {
            lo[k]
        } else {
            hi[k]
        }
    });
    let at = (0..3)
        .map(|k| n[k] as i128 * corner[k] as i128)
        .sum::<i128>()
        + support.offset();
    at * side < 0
}

impl Shadows {
    /// The area of `face` that light `light` reaches (in the mesh's
    /// units squared; lights numbered as given).
    pub fn lit_area(&self, face: usize, light: usize) -> f64 {
        self.lit[face * self.lights.len() + light]
    }

    /// The area of `face`.
    pub fn face_area(&self, face: usize) -> f64 {
        self.area[face]
    }

    /// The share of the whole surface that light `light` reaches.
    pub fn lit_fraction(&self, light: usize) -> f64 {
        let total: f64 = self.area.iter().sum();
        let lit: f64 = (0..self.faces).map(|f| self.lit_area(f, light)).sum();
        if total > 0.0 { lit / total } else { 0.0 }
    }

    /// Every fragment, face by face.
    pub fn fragments(&self) -> impl Iterator<Item = Fragment> + '_ {
        self.batch.fragments().map(|f| Fragment {
            face: f.face() as usize,
            lit: f.lit_mask(),
            rings: f
                .rings()
                .map(|r| r.iter().map(|&v| self.world[v as usize]).collect())
                .collect(),
        })
    }

    /// Writes the fragments as JSON (the schema of `docs/shadows.md`) or
    /// OBJ (groups `lit` and `shadow`), by the extension (another is an
    /// error), through a temporary file renamed into place when complete.
    pub fn write(&self, path: impl AsRef<Path>) -> Result<(), Error> {
        let path = path.as_ref();
        let format = crate::fragment_format(path)?;
        let io = |source| {
            Error::File(SceneError::Io {
                path: path.display().to_string(),
                source,
            })
        };
        let mut out = shadow_scene::AtomicFile::create(path).map_err(io)?;
        let records = area_records(&self.batch, &self.world);
        let mut file = FragmentFile::begin(&mut out, format, &self.lights, self.faces, ("", &[]))
            .map_err(io)?;
        file.write(&mut out, (&self.batch, &self.world, &records), None)
            .map_err(io)?;
        file.finish(&mut out).map_err(io)?;
        out.commit().map_err(io)
    }
}

/// The README's examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;

/// The workspace README's library example, run as a doctest (from the
/// workspace root, where its paths are).
#[cfg(doctest)]
#[doc = include_str!("../../README.md")]
pub struct WorkspaceReadmeDoctests;

#[cfg(test)]
mod tests {
    use super::*;

    /// Leaving out the faces that hide nothing (here the city's ground
    /// tiles, and for a light below the ground nothing; and the closed
    /// buildings' faces turned away from a light) gives every face the
    /// lit area of the trees of all faces.
    #[test]
    fn faces_that_hide_nothing_change_no_lit_area() {
        let city = shadow_scene::city_block(6);
        let lights = [
            Light::Sun(DVec3::new(0.3, -0.5, 1.0)),
            Light::Point(DVec3::new(50.0, 70.0, 80.0)),
            Light::Sun(DVec3::new(0.2, 0.1, -1.0)),
        ];
        let grid = svbsp::shared_grid(&city.positions, &lights).unwrap();
        let (polys, _) = bsp_core::import_faces_par(&grid, &city.face_loops()).unwrap();
        let solids = bsp_core::certify_solid_parts(&polys);
        let culled = shadows_on(
            &grid,
            &polys,
            &solids,
            city.faces.len(),
            &lights,
            None,
            &ShadeOptions::default(),
        )
        .unwrap();
        let placed = svbsp::place_lights(&grid, &lights).unwrap();
        let kernel: Vec<svbsp::Light> = placed.iter().map(|l| l.light).collect();
        // the buildings are closed: their faces turned away from a light
        // are left out too
        for l in &kernel {
            let away = (polys.iter().enumerate())
                .filter(|(i, p)| l.leaves_out(&solids, *i, p.support()))
                .count();
            assert!(away > polys.len() / 10, "{away} of {}", polys.len());
        }
        // the trees of every face
        let volumes = (kernel.iter())
            .map(|&l| svbsp::ShadowVolumes::build(l, &polys).unwrap())
            .collect();
        let all = svbsp::LightVolumes::from_volumes(&kernel, volumes).unwrap();
        let batch = all.set().shade_all(&polys, &ShadeOptions::default());
        let world = world_vertices(&batch, &grid).unwrap();
        let mut lit = vec![0.0; city.faces.len() * 3];
        for r in area_records(&batch, &world) {
            for j in 0..3 {
                if r.lit >> j & 1 == 1 {
                    lit[r.face as usize * 3 + j] += r.area;
                }
            }
        }
        for f in 0..city.faces.len() {
            for j in 0..3 {
                let (a, b) = (culled.lit_area(f, j), lit[f * 3 + j]);
                assert!(
                    (a - b).abs() <= 1e-9 * culled.face_area(f).max(1.0),
                    "{f} {j}: {a} {b}"
                );
            }
        }
        // the ground's tiles hide nothing from the suns above; from below, all may
        let bounds = sun::grid_bounds(&polys).unwrap();
        let tile = polys.last().unwrap().support();
        assert!(!may_hide(&kernel[0], tile, bounds) && !may_hide(&kernel[1], tile, bounds));
        assert!(may_hide(&kernel[2], tile, bounds));
        // a building's wall may hide a sun from the ground around it
        assert!(may_hide(&kernel[0], polys[1].support(), bounds));
    }
}
