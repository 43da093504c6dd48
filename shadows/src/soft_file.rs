//! Soft shadows written as a file, the job of `shadow shadows` with an
//! area light or a sun disc: every face cut where any light's class
//! changes (lit, penumbra, umbra; [`svbsp::soft_shadows`]), every light,
//! point lights and suns included, as an [`svbsp::AreaLight`], and the
//! fragments written as JSON or OBJ ([`svbsp::export::write_soft`]).

use std::io::Write;
use std::time::{Duration, Instant};

use bsp_core::{BspTree, BuildOptions, Grid, Polygon};
use glam::DVec3;
use shadow_raster::shading::affine_fit;
use shadow_raster::svg::{SvgFragment, SvgView, SvgViewpoint, unit_normal};
use shadow_scene::Mesh;
use svbsp::export::{FragmentFormat, SoftWritten, soft_areas, write_soft};
use svbsp::{
    AreaClass, AreaLight, LightSpec, Occluder, PlacedLight, Share, SoftFragment, SoftLight,
    SoftShape, SoftSpec,
};

use crate::Error;
use crate::shadow_file::Progress;

/// A scene snapped to its grid, with its lights: what the job shades.
#[derive(Clone, Copy, Debug)]
pub struct SoftScene<'a> {
    /// The scene's name, for the OBJ's comments.
    pub name: &'a str,
    /// How many faces the scene has.
    pub faces: usize,
    /// The grid the faces and lights are on.
    pub grid: &'a Grid,
    /// The lights, in order.
    pub lights: &'a [SoftLight],
    /// The faces on the grid, each tagged with its index in the mesh
    /// (convex, as imported).
    pub polys: &'a [Polygon],
}

/// What a soft-shadow job wrote, and what it took.
#[derive(Debug)]
pub struct SoftFile {
    /// The fragments, their areas per light, the OBJ's positions.
    pub written: SoftWritten,
    /// The wall time of each phase, in order.
    pub phases: Vec<(&'static str, Duration)>,
    /// For a picture: the pieces drawn, and the eye (input units).
    pub drawn: Option<(usize, DVec3)>,
}

impl SoftFile {
    /// The `--stats` lines: fragments (per face) and the phases' times.
    pub fn stats_text(&self, faces: usize) -> String {
        let n = self.written.fragments;
        let times: Vec<String> = self
            .phases
            .iter()
            .map(|(name, d)| format!("{name} {:.2} ms", d.as_secs_f64() * 1e3))
            .collect();
        format!(
            "fragments:       {n} ({:.3} per face)\ntime:            {}\n",
            n as f64 / faces.max(1) as f64,
            times.join(", ")
        )
    }

    /// The line saying what was written to `output`: the fragments of
    /// `scene` (and for a picture the pieces drawn and the eye) under
    /// `lights` (e.g. "2 lights").
    pub fn wrote(&self, output: &std::path::Path, scene: &SoftScene, lights: &str) -> String {
        let drawn = match self.drawn {
            Some((n, e)) => format!(", {n} drawn, eye {:.3},{:.3},{:.3}", e.x, e.y, e.z),
            None => String::new(),
        };
        format!(
            "wrote {}: {} fragments of {} faces of {}{drawn} under {lights}\n",
            output.display(),
            self.written.fragments,
            scene.faces,
            scene.name,
        )
    }

    /// One line per light: the shares of the area lit, in penumbra (and
    /// of it undecided) and in umbra.
    ///
    /// A light that reaches no part of any face gets a second line saying
    /// why that may be (an area light turned away from the scene).
    pub fn report(&self) -> String {
        let a = &self.written.areas;
        let pc = |x: f64| svbsp::percent(x, a.total);
        (0..a.lit.len())
            .map(|i| {
                let dark = a.total > 0.0 && a.lit[i] + a.penumbra[i] == 0.0;
                format!(
                    "light {i}: lit {:.1}%, penumbra {:.1}% (undecided {:.1}%), umbra {:.1}% \
                     of the area\n{}",
                    pc(a.lit[i]),
                    pc(a.penumbra[i]),
                    pc(a.undecided[i]),
                    pc(a.umbra[i]),
                    if dark {
                        format!(
                            "  light {i} reaches no face: is it behind them all? (an area \
                             light shines on the side its corners turn counter-clockwise \
                             about: list them the other way round to turn it over; a sun \
                             shines from the direction given, toward the scene)\n"
                        )
                    } else {
                        String::new()
                    }
                )
            })
            .collect()
    }
}

/// Every face of `scene` cut for its lights: the phases' times so far,
/// each occluder's face, and the fragments per occluder.
type Shaded = (
    Vec<(&'static str, Duration)>,
    Vec<u32>,
    Vec<Vec<SoftFragment>>,
);

/// Every face of `scene` cut for its lights, timed ([`Shaded`]); with
/// `pieces`, each fragment's convex pieces get their own shares (what a
/// picture is shaded by), else only the fragments (what the files hold).
fn shade(scene: &SoftScene, progress: &dyn Progress, pieces: bool) -> Result<Shaded, Error> {
    let (occluders, faces_of): (Vec<Occluder>, Vec<u32>) = scene
        .polys
        .iter()
        .filter_map(|p| Some((Occluder::of_polygon(p)?, p.tag())))
        .unzip();
    progress.phase("soft shadows", occluders.len() as u64);
    let start = Instant::now();
    let lights: Vec<AreaLight> = scene.lights.iter().map(|l| l.light.clone()).collect();
    let on_face = |n: usize| progress.advance(n as u64);
    let fragments = match pieces {
        true => svbsp::soft_shadows_with(&lights, &occluders, &on_face),
        false => svbsp::soft_regions_with(&lights, &occluders, &on_face),
    }
    .map_err(Error::Light)?;
    Ok((vec![("shadows", start.elapsed())], faces_of, fragments))
}

/// Soft shadows drawn as an SVG view of `mesh` (the mesh `scene` was
/// snapped from) seen from `at`, written to `out`: every face cut as for
/// the files, and each fragment shaded by what reaches it of each light
/// (all of a light it sees whole, none of one it does not see, and in
/// penumbra the visible share at its centroid, [`svbsp::Share`]), under
/// the one lighting model of the point lights' pictures.
pub fn draw_soft_shadows(
    scene: &SoftScene,
    mesh: &Mesh,
    at: &SvgViewpoint,
    out: &mut dyn Write,
    progress: &dyn Progress,
) -> Result<SoftFile, Error> {
    let (mut phases, faces_of, fragments) = shade(scene, progress, true)?;
    progress.phase("drawing", 1);
    let start = Instant::now();
    let grid = scene.grid;
    let mut of_faces = Vec::new();
    for (frags, &face) in fragments.iter().zip(&faces_of) {
        // (each convex piece shaded by its own shares)
        for (f, p) in frags
            .iter()
            .flat_map(|f| f.pieces.iter().map(move |p| (f, p)))
        {
            let soft: Vec<(usize, &Share)> = (0..scene.lights.len())
                .filter(|&j| matches!(f.class(j), AreaClass::Penumbra | AreaClass::Undecided))
                .filter_map(|j| Some((j, p.visible[j].as_ref()?)))
                .collect();
            let piece: Vec<DVec3> = (p.polygon.vertices_f64().into_iter())
                .map(|c| grid.to_world(c))
                .collect();
            let ramps = soft
                .iter()
                .filter_map(|&(j, s)| Some((j, affine_fit(&piece, &s.corners)?)))
                .collect();
            of_faces.push(SvgFragment {
                polygon: 0,
                face: face as usize,
                lit: f.lit,
                shares: soft.iter().map(|&(j, s)| (j, s.centroid)).collect(),
                ramps,
                normal: unit_normal(p.polygon.support()),
                pieces: vec![piece],
            });
        }
    }
    let tree = BspTree::build(scene.polys.to_vec(), &BuildOptions::default());
    let drawn = SvgFragment::cut_to_tree(&tree, grid, &of_faces, scene.faces);
    let lights: Vec<PlacedLight> = scene.lights.iter().map(shading_light).collect();
    let what = "shadow shadows (soft)";
    let picture = SvgView::mesh_fragments(grid, mesh, at, &tree, &lights, &drawn, what)
        .map_err(Error::Raster)?;
    out.write_all(picture.svg.as_bytes()).map_err(Error::Io)?;
    phases.push(("draw", start.elapsed()));
    let written = SoftWritten {
        areas: soft_areas(&fragments, scene.lights.len(), grid),
        fragments: fragments.iter().map(Vec::len).sum(),
        vertices: None,
        degenerate: 0,
    };
    Ok(SoftFile {
        written,
        phases,
        drawn: Some((picture.drawn, picture.eye)),
    })
}

/// A light of a soft-shadow run as the pictures' shading takes it: a
/// point or a direction (an area light from its corners' centre, a disc
/// from its centre's direction).
fn shading_light(l: &SoftLight) -> PlacedLight {
    let (spec, world) = match &l.shape {
        SoftShape::Point(p) => (LightSpec::Point(*p), *p),
        SoftShape::Area(c) => {
            let centre = c.iter().sum::<DVec3>() / c.len().max(1) as f64;
            (LightSpec::Point(centre), centre)
        }
        SoftShape::Sun(d) | SoftShape::SunDisc { direction: d, .. } => (LightSpec::Sun(*d), *d),
    };
    PlacedLight {
        spec,
        light: l.light.corners()[0],
        world,
        angle: 0.0,
    }
}

/// Cuts every face of `scene` for its lights and writes the fragments to
/// `out` as `format`.
pub fn write_soft_shadows(
    scene: &SoftScene,
    format: FragmentFormat,
    out: &mut dyn Write,
    progress: &dyn Progress,
) -> Result<SoftFile, Error> {
    let (mut phases, faces_of, fragments) = shade(scene, progress, false)?;
    progress.phase("writing", 1);
    let start = Instant::now();
    let notes: Vec<String> = scene.lights.iter().map(|l| l.shape.to_string()).collect();
    let head = (scene.name, &notes[..], scene.faces);
    let written = write_soft(
        out,
        format,
        scene.lights,
        head,
        (&fragments, &faces_of),
        scene.grid,
    )
    .map_err(Error::Io)?;
    phases.push(("write", start.elapsed()));
    // (freed by the pool: a caller about to exit need not wait for it)
    rayon::spawn(move || drop(fragments));
    Ok(SoftFile {
        written,
        phases,
        drawn: None,
    })
}

/// Parses `X,Y,Z;X,Y,Z;X,Y,Z[;...]`, an area light's corners.
pub fn parse_area_light(s: &str) -> Result<SoftSpec, String> {
    let corners = s
        .split(';')
        .map(shadow_scene::parse_vec3)
        .collect::<Result<Vec<_>, _>>();
    let corners = corners.map_err(|e| format!("{e}; corners go as X,Y,Z;X,Y,Z;X,Y,Z"))?;
    if corners.len() < 3 {
        return Err(format!(
            "{} corner(s): an area light takes at least three",
            corners.len()
        ));
    }
    Ok(SoftSpec::Area(corners))
}

/// Parses `DX,DY,DZ[:DEG]`, a sun disc.
pub fn parse_sun_disc(s: &str) -> Result<SoftSpec, String> {
    let (d, deg) = s.split_once(':').unwrap_or((s, ""));
    let radius_deg = match deg.trim() {
        "" => svbsp::SUN_RADIUS_DEG,
        r => r
            .parse()
            .map_err(|_| format!("`{r}` is not an angle in degrees"))?,
    };
    Ok(SoftSpec::SunDisc {
        direction: shadow_scene::parse_vec3(d)?,
        radius_deg,
    })
}

/// What reaches every face of a mesh from lights of extent: each face cut
/// into fragments that see all of a light (lit), part of it (penumbra),
/// none of it (umbra), or are undecided between the last two; see
/// [`soft_shadows`].
#[derive(Debug)]
pub struct SoftShadows {
    grid: Grid,
    lights: Vec<SoftLight>,
    faces: usize,
    /// The face of each occluder's fragments.
    faces_of: Vec<u32>,
    fragments: Vec<Vec<SoftFragment>>,
    /// `faces × lights`: lit, penumbra (undecided included), umbra and
    /// undecided areas, and the area weighted by the share of the light
    /// seen ([`SoftShadows::seen_area`]).
    classes: Vec<[f64; 5]>,
    area: Vec<f64>,
}

/// One fragment of a [`SoftShadows`] ([`SoftShadows::fragments`]): a
/// maximal region of one face with one class per light, as the JSON file
/// has it.
#[derive(Clone, Debug, PartialEq)]
pub struct SoftRegion {
    /// The face (its index in the mesh).
    pub face: usize,
    /// Bit `i` set: light `i` is seen whole.
    pub lit: u64,
    /// Bit `i` set: none of light `i` is seen.
    pub umbra: u64,
    /// Bit `i` set: penumbra of light `i` that may be umbra (undecided).
    pub undecided: u64,
    /// Per light, for penumbra of a polygon light or a sun disc, the share
    /// of its irradiance that arrives at the fragment's centroid (of its
    /// largest convex piece, [`svbsp::Share`]); `None` otherwise.
    pub visible: Vec<Option<f64>>,
    /// The outer boundary, counter-clockwise seen from the face's front,
    /// then the holes; in the mesh's units.
    pub rings: Vec<Vec<DVec3>>,
}

/// A face's area in one class of a light ([`SoftShadows::area_of`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SoftClass {
    /// Sees all of the light.
    Lit,
    /// Sees part of it (the undecided area included).
    Penumbra,
    /// Sees none of it.
    Umbra,
    /// Penumbra or umbra, not decided: where an umbra boundary may be a
    /// quadric surface of three occluders' edges.
    Undecided,
}

/// Shades every face of `mesh` for point lights and suns (`lights`) and
/// lights of extent (`soft`: area lights and sun discs), numbered in that
/// order (at most [`crate::MAX_LIGHTS`] in all). Faces are receivers and
/// occluders alike, lit on their front side only, as with
/// [`crate::shadows`].
///
/// ```
/// use bsp_shadows::{DVec3, SoftSpec, soft_file::SoftClass};
/// let room = shadow_scene::room();
/// let lamp = [(-0.2, -0.2), (0.2, -0.2), (0.2, 0.2), (-0.2, 0.2)]
///     .map(|(x, y)| DVec3::new(x, y, 2.9));
/// // (turned to face down: it shines on the side its corners turn
/// // counter-clockwise about)
/// let lamp = SoftSpec::Area(lamp.into_iter().rev().collect());
/// let s = bsp_shadows::soft_file::soft_shadows(&room, &[], &[lamp])?;
/// let total = |c| (0..s.faces()).map(|f| s.area_of(f, 0, c)).sum::<f64>();
/// assert!(total(SoftClass::Penumbra) > 0.0 && total(SoftClass::Umbra) > 0.0);
/// # Ok::<(), bsp_shadows::Error>(())
/// ```
pub fn soft_shadows(
    mesh: &Mesh,
    lights: &[LightSpec],
    soft: &[SoftSpec],
) -> Result<SoftShadows, Error> {
    let grid = svbsp::shared_soft_grid(&mesh.positions, lights, soft).map_err(Error::Light)?;
    let (polys, _) = crate::import_mesh(&grid, mesh).map_err(Error::Import)?;
    soft_shadows_on(grid, &polys, mesh.faces.len(), lights, soft)
}

/// [`soft_shadows`] of the `faces` faces of a mesh already snapped to
/// `grid` (which must hold the lights' points) and imported as `polys`:
/// what a study of sun discs shares between its suns.
pub(crate) fn soft_shadows_on(
    grid: Grid,
    polys: &[Polygon],
    faces: usize,
    lights: &[LightSpec],
    soft: &[SoftSpec],
) -> Result<SoftShadows, Error> {
    let placed = svbsp::place_lights(&grid, lights).map_err(Error::Light)?;
    let all = svbsp::place_soft_lights(&grid, &placed, soft).map_err(Error::Light)?;
    let scene = SoftScene {
        name: "",
        faces,
        grid: &grid,
        lights: &all,
        polys,
    };
    let (_, faces_of, fragments) = shade(&scene, &crate::shadow_file::NoProgress, true)?;
    let n = all.len();
    let (mut classes, mut area) = (vec![[0.0; 5]; faces * n], vec![0.0; faces]);
    for (frags, &face) in fragments.iter().zip(&faces_of) {
        let face = face as usize;
        let a = soft_areas(std::slice::from_ref(frags), n, &grid);
        area[face] += a.total;
        for (j, c) in classes[face * n..(face + 1) * n].iter_mut().enumerate() {
            let add = [a.lit[j], a.penumbra[j], a.umbra[j], a.undecided[j]];
            c.iter_mut().zip(add).for_each(|(x, y)| *x += y);
            c[4] += seen_area(frags, j, &grid);
        }
    }
    Ok(SoftShadows {
        grid,
        lights: all,
        faces,
        faces_of,
        fragments,
        classes,
        area,
    })
}

/// The area of `fragments` weighted by the share of light `j` each sees:
/// a lit one whole, each convex piece of a penumbra (or undecided) one by
/// the share at the piece's centroid, an umbra one not at all.
fn seen_area(fragments: &[SoftFragment], j: usize, grid: &Grid) -> f64 {
    let mut seen = 0.0;
    for f in fragments {
        let class = f.class(j);
        for p in &f.pieces {
            let share = match class {
                AreaClass::Lit => 1.0,
                AreaClass::Umbra => continue,
                AreaClass::Penumbra | AreaClass::Undecided => {
                    p.visible[j].as_ref().map_or(0.0, |s| s.centroid)
                }
            };
            let world: Vec<DVec3> = (p.polygon.vertices_f64().iter())
                .map(|&c| grid.to_world(c))
                .collect();
            seen += share * svbsp::polygon_area(&world);
        }
    }
    seen
}

impl SoftShadows {
    /// How many faces the mesh has.
    pub fn faces(&self) -> usize {
        self.faces
    }

    /// How many lights there are.
    pub fn lights(&self) -> usize {
        self.lights.len()
    }

    /// The area of `face` in `class` of light `light` (in the mesh's
    /// units squared).
    pub fn area_of(&self, face: usize, light: usize, class: SoftClass) -> f64 {
        let c = &self.classes[face * self.lights.len() + light];
        match class {
            SoftClass::Lit => c[0],
            SoftClass::Penumbra => c[1],
            SoftClass::Umbra => c[2],
            SoftClass::Undecided => c[3],
        }
    }

    /// The area of `face` weighted by the share of light `light` it sees:
    /// its lit area, and each convex piece of its penumbra fragments
    /// times the share of the light seen at the piece's centroid (the
    /// irradiance's share for an area
    /// light, the disc's for a sun disc; exact back-projection, `f64`).
    pub fn seen_area(&self, face: usize, light: usize) -> f64 {
        self.classes[face * self.lights.len() + light][4]
    }

    /// The area of `face`.
    pub fn face_area(&self, face: usize) -> f64 {
        self.area[face]
    }

    /// Every fragment, in the file's order, its lights numbered as in the
    /// file (points and suns first, then those with extent).
    pub fn fragments(&self) -> impl Iterator<Item = SoftRegion> + '_ {
        (self.fragments.iter().zip(&self.faces_of)).flat_map(move |(frags, &face)| {
            frags.iter().map(move |f| SoftRegion {
                face: face as usize,
                lit: f.lit,
                umbra: f.umbra,
                undecided: f.undecided,
                visible: (f.visible.iter())
                    .map(|v| v.as_ref().map(|s| s.centroid))
                    .collect(),
                rings: f.rings_in(&self.grid),
            })
        })
    }

    /// How many fragments the faces were cut into.
    pub fn fragment_count(&self) -> usize {
        self.fragments.iter().map(Vec::len).sum()
    }

    /// Writes the fragments as JSON or OBJ (groups `lit`, `penumbra`,
    /// `umbra`), by the extension (another is an error), as `shadow shadows`
    /// does, through a
    /// temporary file renamed into place when complete.
    pub fn write(&self, path: impl AsRef<std::path::Path>) -> Result<(), Error> {
        let path = path.as_ref();
        let format = crate::fragment_format(path)?;
        let io = |source| {
            Error::File(shadow_scene::SceneError::Io {
                path: path.display().to_string(),
                source,
            })
        };
        let mut out = shadow_scene::AtomicFile::create(path).map_err(io)?;
        let notes: Vec<String> = self.lights.iter().map(|l| l.shape.to_string()).collect();
        let head = ("", &notes[..], self.faces);
        let frags = (&self.fragments[..], &self.faces_of[..]);
        write_soft(&mut out, format, &self.lights, head, frags, &self.grid).map_err(io)?;
        out.commit().map_err(io)
    }
}
