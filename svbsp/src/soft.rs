//! Several lights, some with extent, over one scene: every face cut where
//! the class of any light changes ([`soft_shadows`]), each fragment with
//! one [`AreaClass`] per light, and for a penumbra fragment of a polygon
//! light or a sun disc the share of its irradiance that arrives.
//!
//! Each light cuts the pieces the lights before it left
//! ([`AreaLight::classify_face`]'s cuts, by planes through grid points
//! only), so the classes are exact for every light at once; pieces of one
//! face with the same classes are then merged where their union is
//! convex, and these convex pieces into maximal connected regions (with
//! holes), the fragments: a face is cut only where a class changes.
//! Points and suns take part as the limits of area lights
//! ([`AreaLight::point`], [`AreaLight::sun`]): lit or umbra.

use bsp_core::{Grid, GridPoint, MAX_COORD, Point, Polygon};
use glam::{DVec2, DVec3};
use rayon::prelude::*;

use crate::area::{AreaClass, AreaFragment, AreaLight, Occluder, Regions};
use crate::backs::SolidBacks;
use crate::blockers::{coplanar_blockers, coplanar_blockers_of, plane_key};
use crate::boxes::{Box3, EMPTY, EVERYWHERE, Reach, meet};
use crate::engine::{LightVolumes, Scratch, ShadowSet};
use crate::light::{Light, LightError, LightSpec, MAX_LIGHTS, PlacedLight, SoftSpec};
use crate::merging::{LabelledRegion, merge_convex_parts, merge_regions};
use crate::near::{InSlab, near_lists, slab_box};

mod hiders;
use hiders::{Hiders, MAX_PROBED_CORNERS, Probing};

/// The share of a polygon light's irradiance that arrives on a penumbra
/// fragment ([`crate::LightView::fraction`]): at the grid point nearest a
/// point of it, and at the grid points nearest its corners (each, and the
/// least and most).
///
/// For a convex piece ([`SoftPiece`]) the point is its centroid (the mean
/// of its corners). A fragment is a maximal region that may not be convex
/// (its centroid may lie outside it): its point is that of its largest
/// piece, and its corners are those of its rings, in ring order.
#[derive(Clone, Debug, PartialEq)]
pub struct Share {
    /// At the centroid (of a fragment: of its largest piece).
    pub centroid: f64,
    /// The least at a corner.
    pub min: f64,
    /// The most at a corner.
    pub max: f64,
    /// At each corner, in vertex order (of a fragment: its outer ring's
    /// corners, then each hole's).
    pub corners: Vec<f64>,
}

/// A convex piece of a [`SoftFragment`]: what its shading is interpolated
/// over.
#[derive(Clone, Debug)]
pub struct SoftPiece {
    /// The piece: convex, with exact corners.
    pub polygon: Polygon,
    /// Per light, as [`SoftFragment::visible`], for this piece.
    pub visible: Vec<Option<Share>>,
}

/// A piece of a face with one class per light: a maximal connected region
/// of the face where every light's class is the same (the face is cut
/// only where a class changes), which need not be convex and may have
/// holes.
#[derive(Clone, Debug)]
pub struct SoftFragment {
    /// The boundary: the outer ring, counter-clockwise seen from the
    /// front of the face, then the holes, each clockwise; exact corners
    /// only (no two consecutive edges collinear).
    pub rings: Vec<Vec<Point>>,
    /// Convex pieces whose union the fragment is (one, when it is
    /// convex), each with its own shares: what a picture's shading is
    /// interpolated over.
    pub pieces: Vec<SoftPiece>,
    /// Bit `i`: light `i` is wholly seen ([`AreaClass::Lit`]).
    pub lit: u64,
    /// Bit `i`: none of light `i` is seen ([`AreaClass::Umbra`]).
    pub umbra: u64,
    /// Bit `i`: light `i`'s class is [`AreaClass::Undecided`].
    pub undecided: u64,
    /// Per light, for a penumbra (or undecided) fragment of a polygon
    /// light or a sun disc, the share of its irradiance that arrives;
    /// `None` otherwise.
    pub visible: Vec<Option<Share>>,
}

impl SoftFragment {
    /// The class for light `i`.
    pub fn class(&self, i: usize) -> AreaClass {
        let bit = |m: u64| m >> i & 1 == 1;
        if bit(self.lit) {
            AreaClass::Lit
        } else if bit(self.umbra) {
            AreaClass::Umbra
        } else if bit(self.undecided) {
            AreaClass::Undecided
        } else {
            AreaClass::Penumbra
        }
    }

    /// Its [`SoftFragment::rings`] in input units (`grid`'s), each corner
    /// correctly rounded once.
    pub fn rings_in(&self, grid: &Grid) -> Vec<Vec<DVec3>> {
        (self.rings.iter())
            .map(|r| r.iter().map(|p| grid.to_world(p.to_f64())).collect())
            .collect()
    }
}

/// Per light, the classes as bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
struct Classes {
    lit: u64,
    umbra: u64,
    undecided: u64,
}

impl Classes {
    fn with(mut self, i: usize, class: AreaClass) -> Classes {
        match class {
            AreaClass::Lit => self.lit |= 1 << i,
            AreaClass::Umbra => self.umbra |= 1 << i,
            AreaClass::Undecided => self.undecided |= 1 << i,
            AreaClass::Penumbra => {}
        }
        self
    }
}

/// Every face of `faces` cut into fragments of one class per light, with
/// all the other faces as occluders (see the module docs), in face order;
/// the faces in parallel, the same result for every thread count. At most
/// [`MAX_LIGHTS`] lights (the classes are bits of a `u64`): more are
/// [`LightError::TooMany`].
///
/// ```
/// use svbsp::{AreaClass, AreaLight, Occluder, soft_shadows};
/// let lights = [
///     AreaLight::new(&[[0, 0, 80], [0, 40, 80], [40, 40, 80], [40, 0, 80]]).unwrap(),
///     AreaLight::point([20, 20, 80]).unwrap(),
/// ];
/// let faces = [
///     Occluder::new(&[[-200, -200, 0], [200, -200, 0], [200, 200, 0], [-200, 200, 0]]).unwrap(),
///     Occluder::new(&[[0, 0, 40], [40, 0, 40], [40, 40, 40], [0, 40, 40]]).unwrap(),
/// ];
/// let all = soft_shadows(&lights, &faces).unwrap();
/// let ground = &all[0];
/// // under the roof's middle: umbra of both
/// assert!(ground.iter().any(|f| f.class(0) == AreaClass::Umbra && f.class(1) == AreaClass::Umbra));
/// // the square light's penumbra, lit by the point
/// let soft = ground.iter().find(|f| f.class(0) == AreaClass::Penumbra && f.class(1) == AreaClass::Lit);
/// let share = soft.unwrap().visible[0].as_ref().unwrap();
/// assert!(0.0 <= share.min && share.min <= share.max && share.max <= 1.0);
/// assert!(share.centroid > 0.0 && share.centroid < 1.0);
/// ```
pub fn soft_shadows(
    lights: &[AreaLight],
    faces: &[Occluder],
) -> Result<Vec<Vec<SoftFragment>>, LightError> {
    soft_shadows_with(lights, faces, &|_| {})
}

/// [`soft_shadows`], calling `on_faces(n)` as each `n` more faces are done
/// (from the worker threads: a progress bar's tick).
pub fn soft_shadows_with(
    lights: &[AreaLight],
    faces: &[Occluder],
    on_faces: &(dyn Fn(usize) + Sync),
) -> Result<Vec<Vec<SoftFragment>>, LightError> {
    let run = SoftVolumes::new(lights, faces)?;
    let fragments = run.fragments_with(on_faces);
    run.free_later();
    Ok(fragments)
}

/// [`soft_shadows_with`] for what reads each fragment's shares only: the
/// fragments' pieces carry none ([`SoftVolumes::regions_only`]), and
/// everything else is the same.
pub fn soft_regions_with(
    lights: &[AreaLight],
    faces: &[Occluder],
    on_faces: &(dyn Fn(usize) + Sync),
) -> Result<Vec<Vec<SoftFragment>>, LightError> {
    let run = SoftVolumes::new(lights, faces)?.regions_only();
    let fragments = run.fragments_with(on_faces);
    run.free_later();
    Ok(fragments)
}

/// A soft-shadow run of `lights` over `faces`, every face an occluder
/// and a receiver (see [`soft_shadows`]): what it builds once (each
/// occluder's volumes, the occluders near each face, the lights' corner
/// trees), then the fragments of every face, and the share of a light
/// at any point of a face.
///
/// ```
/// use svbsp::{AreaClass, AreaLight, Occluder, SoftVolumes};
/// let lights = [AreaLight::new(&[[0, 0, 80], [0, 40, 80], [40, 40, 80], [40, 0, 80]]).unwrap()];
/// let faces = [
///     Occluder::new(&[[-200, -200, 0], [200, -200, 0], [200, 200, 0], [-200, 200, 0]]).unwrap(),
///     Occluder::new(&[[0, 0, 40], [40, 0, 40], [40, 40, 40], [0, 40, 40]]).unwrap(),
/// ];
/// let run = SoftVolumes::new(&lights, &faces).unwrap();
/// let ground = &run.fragments()[0];
/// assert!(ground.iter().any(|f| f.class(0) == AreaClass::Penumbra));
/// // on the ground: under the roof's middle none, far away all; where
/// // the roof hides the light's far half, more than half (the near half
/// // shines stronger)
/// let shares = run.shares(0, 0, &[[20, 20, 0], [190, 190, 0], [60, 20, 0]]);
/// assert_eq!(&shares[..2], &[Some(0.0), Some(1.0)]);
/// assert!(shares[2].unwrap() > 0.5 && shares[2].unwrap() < 1.0);
/// ```
pub struct SoftVolumes<'a> {
    lights: &'a [AreaLight],
    faces: &'a [Occluder],
    blockers: Vec<Occluder>,
    /// Per light, per blocker: its volumes.
    regions: Vec<Vec<Option<Regions>>>,
    /// Per light, per face: the blockers that may hide some of the light.
    near: Vec<Vec<Vec<u32>>>,
    /// Per light, per blocker: the boxes its volumes reach.
    reach: Vec<Vec<Reach>>,
    corners: Vec<Option<LightVolumes>>,
    /// The blockers a point outside their solid may pass over.
    backs: SolidBacks,
    /// Per light, the inner occluders that decide joint umbra
    /// ([`crate::cores`]).
    cores: Vec<crate::cores::LightCores>,
    /// Per light, per face: strictly outside a closed part that holds the
    /// light (umbra, whole; [`crate::sealed`]); empty for none.
    sealed: Vec<Vec<bool>>,
    /// Whether each convex piece of a fragment gets its own shares
    /// ([`SoftVolumes::regions_only`]).
    piece_shares: bool,
}

impl std::fmt::Debug for SoftVolumes<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SoftVolumes")
            .field("lights", &self.lights.len())
            .field("faces", &self.faces.len())
            .finish_non_exhaustive()
    }
}

impl<'a> SoftVolumes<'a> {
    /// The run's shared parts. At most [`MAX_LIGHTS`] lights (the classes
    /// are bits of a `u64`): more are [`LightError::TooMany`].
    pub fn new(lights: &'a [AreaLight], faces: &'a [Occluder]) -> Result<Self, LightError> {
        if lights.len() > MAX_LIGHTS {
            return Err(LightError::TooMany(lights.len()));
        }
        Ok(SoftVolumes::build(lights, faces))
    }

    /// [`SoftVolumes::new`] for at most [`MAX_LIGHTS`] lights.
    fn build(lights: &'a [AreaLight], faces: &'a [Occluder]) -> Self {
        // the occluders' volumes and near lists beside the certificate
        // and what hangs on it (both sides use every core in parts)
        let ((blockers, sources, regions, (near, reach)), (solids, cores, sealed, corners)) =
            rayon::join(
                || {
                    let (blockers, sources) = coplanar_blockers_of(faces);
                    let regions: Vec<Vec<Option<Regions>>> = lights
                        .iter()
                        .map(|l| blockers.par_iter().map(|o| l.regions(o)).collect())
                        .collect();
                    let near: (Vec<_>, Vec<_>) = lights
                        .iter()
                        .zip(&regions)
                        .map(|(l, r)| near_lists(l.corners(), faces, (&blockers, r)))
                        .unzip();
                    (blockers, sources, regions, near)
                },
                || {
                    let (polygons, solids) = certified(faces);
                    let cores = crate::cores::cores_per_light(lights, faces, &solids);
                    let sealed: Vec<Vec<bool>> = lights
                        .iter()
                        .map(|l| crate::sealed::sealed_faces(l, faces, &solids))
                        .collect();
                    let corners = corner_shadows(lights, (faces, &polygons), &solids);
                    (solids, cores, sealed, corners)
                },
            );
        SoftVolumes {
            cores,
            sealed,
            piece_shares: true,
            corners,
            backs: SolidBacks::new(faces, &sources, &solids),
            lights,
            faces,
            blockers,
            regions,
            near,
            reach,
        }
    }

    /// Hands what the run built to the thread pool to free, so that the
    /// caller goes on (to write the fragments, on one thread) while its
    /// millions of small lists are given back.
    fn free_later(self) {
        let SoftVolumes {
            blockers,
            regions,
            near,
            reach,
            corners,
            backs,
            cores,
            sealed,
            ..
        } = self;
        rayon::spawn(move || {
            drop((
                blockers, regions, near, reach, corners, backs, cores, sealed,
            ))
        });
    }

    /// The run with fragments whose convex pieces carry no shares of
    /// their own (every [`SoftPiece::visible`] `None`); each fragment's
    /// [`SoftFragment::visible`] is the same as without. For what reads
    /// the fragments' shares only (the files): the probe points inside a
    /// fragment of many pieces are never viewed, and on a ground under a
    /// mesh those are most of them.
    pub fn regions_only(mut self) -> Self {
        self.piece_shares = false;
        self
    }

    /// Every face cut into fragments of one class per light, in face
    /// order: [`soft_shadows`].
    pub fn fragments(&self) -> Vec<Vec<SoftFragment>> {
        self.fragments_with(&|_| {})
    }

    /// [`SoftVolumes::fragments`], calling `on_faces(n)` as each `n` more
    /// faces are done.
    pub fn fragments_with(&self, on_faces: &(dyn Fn(usize) + Sync)) -> Vec<Vec<SoftFragment>> {
        // the large faces first (a ground under a mesh: its pieces are
        // cut on one thread, which must not be the last work left; see
        // `large_receivers`), then the others in order; each face's
        // fragments go back to its place
        let area: Vec<f64> = self.faces.iter().map(|f| grid_area(f.corners())).collect();
        let large = crate::schedule::large_first(&area);
        let mut order = large.clone();
        order.extend((0..self.faces.len()).filter(|i| !large.contains(i)));
        let done: Vec<Vec<SoftFragment>> = order
            .par_iter()
            .map_init(Scratch::default, |scratch, &i| {
                let fragments = soft_face(self, (i, large.contains(&i)), &self.faces[i], scratch);
                on_faces(1);
                fragments
            })
            .collect();
        let mut out: Vec<Vec<SoftFragment>> = vec![Vec::new(); self.faces.len()];
        for (i, fragments) in order.into_iter().zip(done) {
            out[i] = fragments;
        }
        out
    }

    /// The share of light `light`'s irradiance arriving at each grid
    /// point of `points`, taken as points of face `face` (on its front
    /// side; see [`Share`]): `None` where nothing of the light is
    /// reachable, and everywhere for a point light or a sun. The points
    /// in parallel.
    pub fn shares(&self, light: usize, face: usize, points: &[GridPoint]) -> Vec<Option<f64>> {
        let l = &self.lights[light];
        if !has_share(l) {
            return vec![None; points.len()];
        }
        let f = &self.faces[face];
        let hiders = self.hiders(light, face, (Probing::Anywhere, points.len()), None);
        // (one point a task when stolen: neighbouring points cost alike,
        // and the dear ones, deep in a mesh's penumbra, lie together)
        points
            .par_iter()
            .with_max_len(1)
            .map(|&x| fraction_at(l, f, &hiders, x))
            .collect()
    }

    /// The occluders near face `face` that may hide some of light
    /// `light`, found by point, for `points` points `probing` says where.
    ///
    /// Where the face's cut `narrowed` its near occluders' boxes to the
    /// slab round its plane, and the hiders would narrow them to that
    /// slab too (points near the face, many of them), they take those
    /// boxes and occluders instead of finding them again.
    fn hiders(
        &self,
        light: usize,
        face: usize,
        (probing, points): (Probing, usize),
        narrowed: Option<&[(u32, Box3)]>,
    ) -> Hiders<'_> {
        let hider = |(j, b): (u32, Box3)| {
            let j = j as usize;
            let r = self.regions[light][j].as_ref()?;
            Some((&self.blockers[j], r, b, self.backs.of(j)))
        };
        let (probing, near) = match (probing, narrowed) {
            (Probing::NearFace { slab: true }, Some(n)) if Hiders::narrows(points) => (
                Probing::NearFace { slab: false },
                n.iter().copied().filter_map(hider).collect(),
            ),
            _ => (
                probing,
                (self.near[light][face].iter())
                    .filter_map(|&j| hider((j, self.reach[light][j as usize][0])))
                    .collect(),
            ),
        };
        Hiders::new(
            &self.faces[face],
            self.lights[light].corners(),
            (near, &self.backs),
            (probing, points),
        )
    }
}

/// The faces as polygons, and their parts certified to bound solids
/// ([`bsp_core::certify_solid_parts`]).
fn certified(faces: &[Occluder]) -> (Vec<Polygon>, bsp_core::SolidParts) {
    let polygons: Vec<Polygon> = faces.iter().map(Occluder::to_polygon).collect();
    let solids = bsp_core::certify_solid_parts(&polygons);
    (polygons, solids)
}

/// Per light, the point lights' shadow volumes of its corners over
/// `faces` (which corners each point of a face sees); `None` for a light
/// of more corners than the trees take (its pieces are then cut by each
/// occluder's shadow volume from each corner instead). Each tree is built
/// with the faces in the order of their corners, so the cells, and with
/// them the fragments, do not depend on the faces' order.
fn corner_shadows(
    lights: &[AreaLight],
    (faces, polygons): (&[Occluder], &[Polygon]),
    solids: &bsp_core::SolidParts,
) -> Vec<Option<LightVolumes>> {
    let mut order: Vec<usize> = (0..faces.len()).collect();
    order.sort_by(|&a, &b| faces[a].corners().cmp(faces[b].corners()));
    lights
        .iter()
        .map(|l| LightVolumes::new_ordered_reaching(polygons, &order, l.corners(), solids).ok())
        .collect()
}

impl AreaLight {
    /// `face` cut into fragments of one class each (see the module docs),
    /// with the faces of `occluders` not in its plane as occluders (`face`
    /// may be among them: it hides nothing from its own points), those of
    /// one plane that share an edge merged where their union is convex. Adjacent pieces
    /// of one class are merged where their union is convex. Where the
    /// light lies wholly behind the face's plane, the face is umbra
    /// (attached shadow); where it lies partly behind, no point of the
    /// face sees all of it.
    ///
    /// ```
    /// use svbsp::{AreaClass, AreaLight, Occluder};
    /// let light = AreaLight::new(&[[0, 0, 80], [0, 40, 80], [40, 40, 80], [40, 0, 80]]).unwrap();
    /// let ground = Occluder::new(&[[-200, -200, 0], [200, -200, 0], [200, 200, 0], [-200, 200, 0]]).unwrap();
    /// let roof = Occluder::new(&[[0, 0, 40], [40, 0, 40], [40, 40, 40], [0, 40, 40]]).unwrap();
    /// let fragments = light.classify_face(&ground, &[ground.clone(), roof]);
    /// let has = |c| fragments.iter().any(|f| f.class == c);
    /// assert!(has(AreaClass::Lit) && has(AreaClass::Penumbra) && has(AreaClass::Umbra));
    /// assert!(!has(AreaClass::Undecided));
    /// ```
    pub fn classify_face(&self, face: &Occluder, occluders: &[Occluder]) -> Vec<AreaFragment> {
        let own = plane_key(face.plane());
        let blockers = coplanar_blockers(occluders);
        // those whose penumbra volume may meet the face
        let regions: Vec<Regions> = blockers
            .iter()
            .filter(|o| plane_key(o.plane()) != own)
            .filter_map(|o| self.regions(o))
            .filter(|r| !crate::near::outside(face.corners(), &r.penumbra))
            .collect();
        self.classify_with(face, regions.iter().map(|r| (r, [EVERYWHERE; 2])), None)
    }

    /// Every face of `faces` cut into fragments of one class each, with
    /// all the others as occluders: [`AreaLight::classify_face`] for each,
    /// each occluder's volumes built once and met only by the faces near
    /// it, the faces in parallel (the result is in face order, the same
    /// for every thread count).
    ///
    /// ```
    /// use svbsp::{AreaClass, AreaLight, Occluder};
    /// let light = AreaLight::new(&[[0, 0, 80], [0, 40, 80], [40, 40, 80], [40, 0, 80]]).unwrap();
    /// let faces = [
    ///     Occluder::new(&[[-200, -200, 0], [200, -200, 0], [200, 200, 0], [-200, 200, 0]]).unwrap(),
    ///     Occluder::new(&[[0, 0, 40], [40, 0, 40], [40, 40, 40], [0, 40, 40]]).unwrap(),
    /// ];
    /// let all = light.classify_faces(&faces);
    /// assert!(all[1].iter().all(|f| f.class == AreaClass::Lit)); // the roof
    /// ```
    pub fn classify_faces(&self, faces: &[Occluder]) -> Vec<Vec<AreaFragment>> {
        // the run's shared parts for this one light, built as for several
        let run = SoftVolumes::build(std::slice::from_ref(self), faces);
        // (only the large faces' occluder boxes are narrowed, as in
        // `SoftVolumes::fragments_with`: the narrowing only prunes)
        let area: Vec<f64> = faces.iter().map(|f| grid_area(f.corners())).collect();
        let large = crate::schedule::large_first(&area);
        let set = run.corners[0].as_ref().map(LightVolumes::set_for_occluders);
        let (regions, reach, cores, sealed) = (
            &run.regions[0],
            &run.reach[0],
            &run.cores[0],
            &run.sealed[0],
        );
        let fragments = faces
            .par_iter()
            .zip(&run.near[0])
            .enumerate()
            .map_init(Scratch::default, |scratch, (i, (face, near))| {
                if sealed.get(i) == Some(&true) {
                    let polygon = face.to_polygon();
                    return vec![AreaFragment {
                        polygon,
                        class: AreaClass::Umbra,
                    }];
                }
                let others = near_occluders(
                    near,
                    (regions, reach, &run.blockers),
                    self.corners(),
                    (face, large.contains(&i)),
                )
                .0
                .into_iter()
                .chain(crate::cores::cores_at(cores, face));
                let mut seen = corner_cells(set.as_ref(), (face, i, faces.len()), scratch);
                self.classify_with(face, others, Some(&mut seen))
            })
            .collect();
        drop(set);
        run.free_later();
        fragments
    }
}

/// The cells of a piece of `face` (face `i` of `faces`) by the corners'
/// trees `set` (see [`ShadowSet::cells`]): the face whole is occluder
/// `i` of those trees, so what their building found of it spares
/// filtering it where they light all of it or none
/// ([`ShadowSet::cells_known`]).
fn corner_cells<'a, 't: 'a>(
    set: Option<&'a ShadowSet<'t>>,
    (face, i, faces): (&'a Occluder, usize, usize),
    scratch: &'a mut Scratch,
) -> impl FnMut(&Polygon, bool) -> Option<Vec<(Polygon, u64)>> + 'a {
    move |p: &Polygon, settle: bool| {
        let c = face.corners();
        let whole = p.vertices().len() == c.len()
            && (p.vertices().iter().zip(c))
                .all(|(v, g)| matches!(v, bsp_core::Point::Grid(v) if v == g));
        set?.cells_known(p, (whole.then_some(i), faces), settle, scratch)
    }
}

/// The fragments of face `i` of `run`, `face`.
fn soft_face(
    run: &SoftVolumes<'_>,
    (i, large): (usize, bool),
    face: &Occluder,
    scratch: &mut Scratch,
) -> Vec<SoftFragment> {
    let (pieces, narrowed) = cut_face(run, (i, large), face, scratch);
    let fragments = merge_convex_parts(pieces);
    let shading = Shading {
        run,
        i,
        face,
        narrowed,
        // (a face of many fragments, such as a ground, rounds their
        // corners on every thread)
        many: fragments.len() >= crate::schedule::PARALLEL_CELLS,
        // (a probe point lies near the face when its fragment is not huge)
        near_face: fragments.iter().all(|(p, _)| p.len() < MAX_PROBED_CORNERS),
    };
    match run.piece_shares {
        true => shading.with_pieces(fragments),
        false => shading.regions_only(fragments),
    }
}

/// Face `i` of `run`, `face`, cut into convex pieces of one class per
/// light.
fn cut_face(
    run: &SoftVolumes<'_>,
    (i, large): (usize, bool),
    face: &Occluder,
    scratch: &mut Scratch,
) -> (Vec<(Polygon, Classes)>, Vec<Option<Narrowed>>) {
    let SoftVolumes {
        lights,
        regions,
        reach,
        corners,
        ..
    } = run;
    let near: Vec<&[u32]> = run.near.iter().map(|n| &n[i][..]).collect();
    let mut pieces = vec![(face.to_polygon(), Classes::default())];
    let mut narrowed = vec![None; lights.len()];
    for (k, light) in lights.iter().enumerate() {
        if run.sealed[k].get(i) == Some(&true) {
            pieces = pieces
                .into_iter()
                .map(|(p, c)| (p, c.with(k, AreaClass::Umbra)))
                .collect();
            continue;
        }
        // the inner occluders last: they cut only what stays undecided
        let (occluders, narrow) = near_occluders(
            near[k],
            (&regions[k], &reach[k], &run.blockers),
            light.corners(),
            (face, large),
        );
        narrowed[k] = narrow;
        let occluders = occluders
            .into_iter()
            .chain(crate::cores::cores_at(&run.cores[k], face));
        let set = corners[k].as_ref().map(LightVolumes::set_for_occluders);
        let mut seen = corner_cells(set.as_ref(), (face, i, run.faces.len()), scratch);
        pieces = light
            .cut(face, pieces, occluders, Some(&mut seen))
            .into_iter()
            .map(|(p, c, class)| (p, c.with(k, class)))
            .collect();
    }
    (pieces, narrowed)
}

/// The shares of one face's convex pieces (merged where their union is
/// convex): per light, the grid points nearest the penumbra fragments'
/// centroids and corners (neighbours share corners), each viewed once, in
/// parallel; then each fragment's share from its points.
struct Shading<'r, 'a> {
    run: &'r SoftVolumes<'a>,
    i: usize,
    face: &'r Occluder,
    /// Per light, the near occluders' boxes the cut narrowed, if it did.
    narrowed: Vec<Option<Narrowed>>,
    many: bool,
    near_face: bool,
}

impl Shading<'_, '_> {
    /// Whether pieces of classes `c` have a share of light `k`.
    fn wanted(&self, c: &Classes, k: usize) -> bool {
        (c.lit | c.umbra) >> k & 1 == 0 && has_share(&self.run.lights[k])
    }

    /// Per light, the share at every point of `probes` (the probes per
    /// piece or region, per light).
    fn view(&self, probes: &[Vec<Option<Probes>>]) -> Vec<Option<Viewed>> {
        let lights = self.run.lights;
        (0..lights.len())
            .map(|k| {
                let mut points: Vec<GridPoint> = probes
                    .iter()
                    .filter_map(|p| p[k].as_ref())
                    .flat_map(|p| std::iter::once(p.centroid).chain(p.corners.iter().copied()))
                    .collect();
                if points.is_empty() {
                    return None;
                }
                points.sort_unstable();
                points.dedup();
                // (a box of what each volume holds of the face's slab costs a
                // few hundred operations; it pays where many points look)
                let slab = points.len() >= 32;
                let probing = match self.near_face {
                    true => Probing::NearFace { slab },
                    false => Probing::Anywhere,
                };
                let hiders = self.run.hiders(
                    k,
                    self.i,
                    (probing, points.len()),
                    self.narrowed[k].as_deref(),
                );
                // (one point a task when stolen: the points are sorted, so the
                // dear ones, deep in a mesh's penumbra, lie together, and a
                // run of them must not be left to one thread)
                let fractions = points
                    .par_iter()
                    .with_max_len(1)
                    .map(|&x| fraction_at(&lights[k], self.face, &hiders, x))
                    .collect();
                Some(Viewed { points, fractions })
            })
            .collect()
    }

    /// The fragments with every piece's shares.
    fn with_pieces(&self, fragments: Vec<(Polygon, Classes)>) -> Vec<SoftFragment> {
        let n = self.run.lights.len();
        let probes_of = |(polygon, c): &(Polygon, Classes)| -> Vec<Option<Probes>> {
            (0..n)
                .map(|k| self.wanted(c, k).then(|| Probes::of(polygon)))
                .collect()
        };
        let probes: Vec<Vec<Option<Probes>>> = match self.many {
            true => fragments.par_iter().map(probes_of).collect(),
            false => fragments.iter().map(probes_of).collect(),
        };
        // the convex pieces merged into maximal regions, the fragments (a
        // face of many, such as a ground, merges them on one thread: beside
        // its shares, which need no regions)
        let (values, regions) = match self.many {
            true => rayon::join(|| self.view(&probes), || merge_regions(&fragments)),
            false => (self.view(&probes), merge_regions(&fragments)),
        };
        let piece = |(polygon, probes): (Polygon, Vec<Option<Probes>>)| SoftPiece {
            visible: shares(&probes, &values),
            polygon,
        };
        let pieces: Vec<(Polygon, Vec<Option<Probes>>)> =
            fragments.into_iter().map(|(p, _)| p).zip(probes).collect();
        let mut pieces: Vec<Option<SoftPiece>> = match self.many {
            true => pieces.into_par_iter().map(piece).map(Some).collect(),
            false => pieces.into_iter().map(piece).map(Some).collect(),
        };
        regions
            .into_iter()
            .map(|r| {
                let pieces: Vec<SoftPiece> = (r.cells.iter())
                    .map(|&c| pieces[c as usize].take().expect("a piece is in one region"))
                    .collect();
                let visible = match pieces.len() {
                    1 => pieces[0].visible.clone(),
                    _ => region_shares(&r.rings, &pieces, &values),
                };
                fragment(r, pieces, visible)
            })
            .collect()
    }

    /// The fragments with only their own shares
    /// ([`SoftVolumes::regions_only`]): each region's points are the
    /// centroid of its largest piece and its rings' corners (a piece's own
    /// corners where it is the region), as [`Shading::with_pieces`] takes
    /// them; the points inside a region of many pieces are never viewed.
    fn regions_only(&self, fragments: Vec<(Polygon, Classes)>) -> Vec<SoftFragment> {
        let n = self.run.lights.len();
        let regions = merge_regions(&fragments);
        let region_probes = |r: &LabelledRegion<Classes>| -> Vec<Option<Probes>> {
            if !(0..n).any(|k| self.wanted(&r.label, k)) {
                return vec![None; n];
            }
            let probes = match &r.cells[..] {
                &[one] => Probes::of(&fragments[one as usize].0),
                cells => {
                    let largest = largest(cells.iter().map(|&c| &fragments[c as usize].0));
                    Probes {
                        centroid: Probes::of(&fragments[cells[largest] as usize].0).centroid,
                        corners: ring_corners(&r.rings),
                    }
                }
            };
            (0..n)
                .map(|k| self.wanted(&r.label, k).then(|| probes.clone()))
                .collect()
        };
        let probes: Vec<Vec<Option<Probes>>> = match self.many {
            true => regions.par_iter().map(region_probes).collect(),
            false => regions.iter().map(region_probes).collect(),
        };
        let values = self.view(&probes);
        let mut polygons: Vec<Option<Polygon>> =
            fragments.into_iter().map(|(p, _)| Some(p)).collect();
        (regions.into_iter().zip(&probes))
            .map(|(r, probes)| {
                let pieces = (r.cells.iter())
                    .map(|&c| SoftPiece {
                        polygon: polygons[c as usize]
                            .take()
                            .expect("a piece is in one region"),
                        visible: vec![None; n],
                    })
                    .collect();
                let visible = shares(probes, &values);
                fragment(r, pieces, visible)
            })
            .collect()
    }
}

/// Per light, the [`Share`] of the values at `probes`.
fn shares(probes: &[Option<Probes>], values: &[Option<Viewed>]) -> Vec<Option<Share>> {
    (probes.iter().zip(values))
        .map(|(p, v)| Some(p.as_ref()?.share(v.as_ref()?)))
        .collect()
}

/// The fragment of region `r` of convex `pieces`, with shares `visible`.
fn fragment(
    r: LabelledRegion<Classes>,
    pieces: Vec<SoftPiece>,
    visible: Vec<Option<Share>>,
) -> SoftFragment {
    SoftFragment {
        rings: r.rings,
        pieces,
        lit: r.label.lit,
        umbra: r.label.umbra,
        undecided: r.label.undecided,
        visible,
    }
}

/// The index of the largest of `pieces` by area (the first of equal
/// ones), in `f64`: the piece whose centroid a region's share is taken at.
fn largest<'p>(pieces: impl Iterator<Item = &'p Polygon>) -> usize {
    let area = |p: &Polygon| {
        let v: Vec<DVec3> = (p.vertices_f64().iter())
            .map(|&c| DVec3::from_array(c))
            .collect();
        crate::polygon_area(&v)
    };
    let mut largest = 0;
    let mut most = f64::NEG_INFINITY;
    for (i, p) in pieces.enumerate() {
        let a = area(p);
        if a > most {
            (largest, most) = (i, a);
        }
    }
    largest
}

/// The grid points nearest a region's ring corners, in ring order.
fn ring_corners(rings: &[Vec<Point>]) -> Vec<GridPoint> {
    (rings.iter().flatten())
        .map(|p| nearest(p.to_f64()))
        .collect()
}

/// A region's [`Share`] per light, of its `pieces` (several, convex) and
/// the values at their probe points: at the centroid of its largest piece
/// (a non-convex region's centroid may lie outside it), and at the
/// corners of its `rings` (corners of its pieces, so probed).
fn region_shares(
    rings: &[Vec<Point>],
    pieces: &[SoftPiece],
    values: &[Option<Viewed>],
) -> Vec<Option<Share>> {
    let largest = largest(pieces.iter().map(|p| &p.polygon));
    let corners = ring_corners(rings);
    (0..values.len())
        .map(|k| {
            let viewed = values[k].as_ref()?;
            let centroid = pieces[largest].visible[k].as_ref()?.centroid;
            Some(Probes::share_at(viewed, centroid, &corners))
        })
        .collect()
}

/// The occluders near `face` (numbers `near` into `regions`, `reach` and
/// `blockers`) with their volumes and boxes: for a `large` face (one
/// scheduled first, of many pieces) with many, the boxes narrowed to
/// what the volumes hold of the slab round its plane ([`in_slab`]; one
/// that holds none is left out: a small face of one piece would pay more
/// for the narrowing than its cutting saves), in parallel for a face
/// with very many (a ground under a mesh). In `near`'s order.
fn near_occluders<'r>(
    near: &[u32],
    (regions, reach, blockers): (&'r [Option<Regions>], &[Reach], &[Occluder]),
    light: &[Light],
    (face, large): (&Occluder, bool),
) -> (Vec<(&'r Regions, Reach)>, Option<Narrowed>) {
    let narrow = large && near.len() > TIGHTENED;
    let occluder = |&j: &u32| {
        let r = regions[j as usize].as_ref()?;
        let reach = reach[j as usize];
        match narrow {
            true => Some((j, r, in_slab(reach, light, &blockers[j as usize], face)?)),
            false => Some((j, r, reach)),
        }
    };
    let kept: Vec<(u32, &Regions, Reach)> = match near.len() > PARALLEL_OCCLUDERS {
        true => near.par_iter().filter_map(occluder).collect(),
        false => near.iter().filter_map(occluder).collect(),
    };
    let narrowed = narrow.then(|| kept.iter().map(|&(j, _, reach)| (j, reach[0])).collect());
    (
        kept.into_iter().map(|(_, r, reach)| (r, reach)).collect(),
        narrowed,
    )
}

/// A face's near occluders (by number) that [`near_occluders`] kept when
/// it narrowed their boxes to the slab round the face's plane, each with
/// its penumbra volume's box so narrowed: what [`Hiders`] would find
/// again for points near the face ([`SoftVolumes::hiders`]).
type Narrowed = Vec<(u32, Box3)>;

/// A face with more occluders near it than this has them prepared in
/// parallel (their boxes narrowed, their tests for its points).
const PARALLEL_OCCLUDERS: usize = 1024;

/// A large face with more occluders near it than this has their boxes
/// ([`Reach`]) narrowed to what their volumes hold of the slab round its
/// plane before its pieces are cut.
const TIGHTENED: usize = 128;

/// An occluder's boxes narrowed to what its penumbra volume holds of the
/// slab round `face`'s plane (its umbra volume lies in that one), where
/// its pieces lie; `None` where the volume holds none of it.
fn in_slab(reach: Reach, lights: &[Light], o: &Occluder, face: &Occluder) -> Option<Reach> {
    match slab_box(lights, o.corners(), face.plane()) {
        InSlab::Nothing => None,
        InSlab::Unbounded => Some(reach),
        // (the penumbra's box missing the slab's: the volume misses it)
        InSlab::Within(b) => Some([meet(reach[0], b)?, meet(reach[1], b).unwrap_or(EMPTY)]),
    }
}

/// The grid points nearest a fragment's centroid and corners, where its
/// visible share is taken.
#[derive(Clone)]
struct Probes {
    centroid: GridPoint,
    corners: Vec<GridPoint>,
}

/// The share of one light at sorted grid points.
struct Viewed {
    points: Vec<GridPoint>,
    fractions: Vec<Option<f64>>,
}

impl Probes {
    fn of(piece: &Polygon) -> Probes {
        let corners = piece.vertices_f64();
        let centroid = corners
            .iter()
            .fold(DVec3::ZERO, |s, &c| s + DVec3::from_array(c))
            / corners.len() as f64;
        Probes {
            centroid: nearest(centroid.to_array()),
            corners: corners.into_iter().map(nearest).collect(),
        }
    }

    /// The fragment's [`Share`] from the values at its points (nothing
    /// reachable counts as 0).
    fn share(&self, viewed: &Viewed) -> Share {
        let centroid = viewed.at(&self.centroid).unwrap_or(0.0);
        Probes::share_at(viewed, centroid, &self.corners)
    }

    /// The [`Share`] of value `centroid` at the centroid and the values
    /// of `viewed` at `corners` (nothing reachable counts as 0).
    fn share_at(viewed: &Viewed, centroid: f64, corners: &[GridPoint]) -> Share {
        let corners: Vec<f64> = corners
            .iter()
            .map(|x| viewed.at(x).unwrap_or(0.0))
            .collect();
        let (min, max) = corners
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &f| {
                (lo.min(f), hi.max(f))
            });
        Share {
            centroid,
            min,
            max,
            corners,
        }
    }
}

impl Viewed {
    /// The value at probe point `x`, if it was viewed and reaches the
    /// light.
    fn at(&self, x: &GridPoint) -> Option<f64> {
        let i = self.points.binary_search(x).ok()?;
        self.fractions[i]
    }
}

/// Whether `light` has a share to report: a polygon, or a disc of the sky
/// (not a point or a sun).
fn has_share(light: &AreaLight) -> bool {
    light.plane().is_some() || light.corners().len() >= 3
}

/// The grid point nearest `p` (grid units).
fn nearest(p: [f64; 3]) -> GridPoint {
    p.map(|c| c.round() as i32)
}

/// A planar polygon's area from its grid corners, in `f64` (for
/// scheduling only).
fn grid_area(corners: &[GridPoint]) -> f64 {
    let v: Vec<DVec3> = corners
        .iter()
        .map(|c| DVec3::from_array(c.map(f64::from)))
        .collect();
    crate::polygon_area(&v)
}

/// The share of `light` (a polygon or a disc: [`has_share`]) arriving at
/// grid point `x` near `face` (see [`Share`]); `None` where nothing of it
/// is reachable.
fn fraction_at(
    light: &AreaLight,
    face: &Occluder,
    hiders: &Hiders<'_>,
    x: GridPoint,
) -> Option<f64> {
    let n = face.plane().normal().map(|c| c as f64);
    let normal = DVec3::from_array(n).normalize();
    let mut near = hiders.at(x);
    // nearest first: they hide the most, and the cones of those behind
    // them then often meet only what is hidden already
    near.sort_by_cached_key(|o| {
        (o.corners().iter())
            .map(|c| {
                (0..3)
                    .map(|k| (i64::from(c[k]) - i64::from(x[k])).pow(2))
                    .sum::<i64>()
            })
            .min()
    });
    let hiding = near.into_iter();
    let xf = DVec3::from_array(x.map(f64::from));
    if light.plane().is_none() {
        let quantized: Vec<[i32; 3]> = (light.corners().iter())
            .filter_map(|l| match l {
                Light::Directional(d) => Some(*d),
                Light::Point(_) => None,
            })
            .collect();
        if let Some(share) =
            crate::cones::sky_seen_share(&quantized, face.plane(), x, hiding.clone())
        {
            return share;
        }
        let sky: Vec<DVec3> = (quantized.iter())
            .map(|d| DVec3::from_array(d.map(f64::from)))
            .collect();
        return sky_share(&sky, xf, normal, hiding);
    }
    if let (Some(corners), Some(plane)) = (light.grid_corners(), light.plane())
        && let Some(share) =
            crate::cones::seen_share(corners, plane, face.plane(), x, normal, hiding.clone())
    {
        return share;
    }
    let view = light.view_among(x, Some(face.plane()), hiding)?;
    view.fraction(xf, normal)
}

/// The share of a sun disc's polygon of directions `sky` that `x` (on a
/// face with unit `normal`) sees, in `f64`: the directions drawn in the
/// plane tangent to the sky at their centre (`d ↦ d / (d · c)`), less each
/// occluder's part beyond `x` drawn alike, over the part in front of the
/// face; the cosine at the face is taken as constant over the disc (it
/// varies by less than its radius). `None` where no direction is in
/// front of the face.
pub(crate) fn sky_share<'o>(
    sky: &[DVec3],
    x: DVec3,
    normal: DVec3,
    occluders: impl Iterator<Item = &'o Occluder>,
) -> Option<f64> {
    let c = sky.iter().sum::<DVec3>().normalize();
    let u = c.any_orthonormal_vector();
    let v = c.cross(u);
    let chart = |d: DVec3| DVec2::new(d.dot(u), d.dot(v)) / d.dot(c);
    let disc: Vec<DVec2> = sky.iter().map(|&d| chart(d)).collect();
    // in front of the face: n · (c + a u + b v) > 0
    let front = [normal.dot(u), normal.dot(v), normal.dot(c)];
    let reachable = clip2(&ccw(disc), front);
    let all = area2(&reachable);
    if all <= 0.0 {
        return None;
    }
    // the planes through x bounding the light's cone, inward
    let n = sky.len();
    let cone: Vec<DVec3> = (0..n)
        .map(|i| {
            let h = sky[i].cross(sky[(i + 1) % n]);
            if h.dot(c) < 0.0 { -h } else { h }
        })
        .collect();
    let mut seen = vec![reachable];
    for o in occluders {
        // the occluder's part inside the light's cone from x (where the
        // chart is defined: every direction there is within the disc's
        // bounding polygon, so `r · c > 0` unless `r` is x itself)
        let mut ahead: Vec<DVec3> = o
            .corners()
            .iter()
            .map(|p| DVec3::from_array(p.map(f64::from)) - x)
            .collect();
        for h in &cone {
            ahead = clip3(&ahead, *h);
        }
        ahead.retain(|r| *r != DVec3::ZERO);
        if ahead.len() < 3 {
            continue;
        }
        let shadow = ccw(ahead.iter().map(|&r| chart(r)).collect());
        if area2(&shadow) <= 0.0 {
            continue;
        }
        seen = seen
            .into_iter()
            .flat_map(|piece| subtract2(piece, &shadow))
            .collect();
    }
    let left: f64 = seen.iter().map(|p| area2(p)).sum();
    Some((left / all).clamp(0.0, 1.0))
}

/// The part of a 3D polygon where `r · h >= 0`.
fn clip3(poly: &[DVec3], h: DVec3) -> Vec<DVec3> {
    let mut out = Vec::new();
    for (i, &a) in poly.iter().enumerate() {
        let b = poly[(i + 1) % poly.len()];
        let (da, db) = (a.dot(h), b.dot(h));
        if da >= 0.0 {
            out.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            out.push(a + (b - a) * (da / (da - db)));
        }
    }
    out
}

/// The part of a 2D polygon where `h[0] a + h[1] b + h[2] >= 0`.
fn clip2(poly: &[DVec2], h: [f64; 3]) -> Vec<DVec2> {
    let f = |p: DVec2| h[0] * p.x + h[1] * p.y + h[2];
    let mut out = Vec::new();
    for (i, &a) in poly.iter().enumerate() {
        let b = poly[(i + 1) % poly.len()];
        let (fa, fb) = (f(a), f(b));
        if fa >= 0.0 {
            out.push(a);
        }
        if (fa >= 0.0) != (fb >= 0.0) {
            out.push(a + (b - a) * (fa / (fa - fb)));
        }
    }
    out
}

fn area2(p: &[DVec2]) -> f64 {
    let n = p.len();
    (0..n).map(|i| p[i].perp_dot(p[(i + 1) % n])).sum::<f64>() / 2.0
}

/// The polygon turned counter-clockwise.
fn ccw(mut p: Vec<DVec2>) -> Vec<DVec2> {
    if area2(&p) < 0.0 {
        p.reverse();
    }
    p
}

/// The convex `piece` less the convex `hole` (both counter-clockwise), as
/// convex parts.
fn subtract2(mut piece: Vec<DVec2>, hole: &[DVec2]) -> Vec<Vec<DVec2>> {
    let mut out = Vec::new();
    for (i, &a) in hole.iter().enumerate() {
        let b = hole[(i + 1) % hole.len()];
        // outside the edge a→b: to its right
        let e = b - a;
        if e == DVec2::ZERO {
            continue;
        }
        let right = [e.y, -e.x, -(e.y * a.x - e.x * a.y)];
        let outside = clip2(&piece, right);
        if area2(&outside) > 0.0 {
            out.push(outside);
        }
        piece = clip2(&piece, right.map(|k| -k));
        if piece.len() < 3 {
            return out;
        }
    }
    out
}

/// A light of a soft-shadow run ([`crate::soft_shadows`]): any light as an
/// [`AreaLight`] on the grid, and what the outputs say of it.
#[derive(Clone, Debug)]
pub struct SoftLight {
    /// The exact light.
    pub light: AreaLight,
    /// What it is, in input units.
    pub shape: SoftShape,
}

/// A [`SoftLight`] in input units, as the outputs name it.
#[derive(Clone, Debug, PartialEq)]
pub enum SoftShape {
    /// A point light, at its snapped position.
    Point(DVec3),
    /// A sun, its quantized direction normalized.
    Sun(DVec3),
    /// An area light, its snapped corners.
    Area(Vec<DVec3>),
    /// A sun disc as given (its bounding polygon is
    /// [`AreaLight::sun_disc`]'s).
    SunDisc {
        /// Toward the centre, normalized.
        direction: DVec3,
        /// The angular radius, degrees.
        radius_deg: f64,
    },
}

/// The grid of a soft-shadow run: [`crate::shared_grid`] with the corners
/// of the area lights among `soft` counted as point lights.
pub fn shared_soft_grid(
    positions: &[DVec3],
    lights: &[LightSpec],
    soft: &[SoftSpec],
) -> Result<Grid, LightError> {
    let mut all = lights.to_vec();
    all.extend(
        soft.iter()
            .flat_map(SoftSpec::points)
            .map(|&c| LightSpec::Point(c)),
    );
    crate::light::shared_grid(positions, &all)
}

/// Every light of a soft-shadow run on `grid`, numbered in order: the
/// placed point lights and suns (`placed`, from [`crate::place_lights`]), then
/// `specs`. Errors name the light by its number.
pub fn place_soft_lights(
    grid: &Grid,
    placed: &[PlacedLight],
    specs: &[SoftSpec],
) -> Result<Vec<SoftLight>, LightError> {
    let total = placed.len() + specs.len();
    if total > MAX_LIGHTS {
        return Err(LightError::TooMany(total));
    }
    let mut out = Vec::with_capacity(total);
    for p in placed {
        let (light, shape) = match p.light {
            Light::Point(at) => (AreaLight::point(at), SoftShape::Point(p.world)),
            Light::Directional(d) => (AreaLight::sun(d), SoftShape::Sun(p.world)),
        };
        let index = out.len();
        let light = light.map_err(|cause| LightError::Extent { index, cause })?;
        out.push(SoftLight { light, shape });
    }
    for spec in specs {
        let index = out.len();
        let extent = |cause| LightError::Extent { index, cause };
        let (light, shape) = match spec {
            SoftSpec::Area(corners) if corners.iter().any(|c| !c.is_finite()) => {
                return Err(LightError::NotFinite { index });
            }
            SoftSpec::SunDisc { direction, .. } if !direction.is_finite() => {
                return Err(LightError::NotFinite { index });
            }
            SoftSpec::Area(corners) => {
                let far = |_| LightError::FarPoint {
                    index,
                    reach: MAX_COORD as f64 / grid.scale(),
                    centre: grid.origin(),
                };
                let g: Vec<GridPoint> = corners
                    .iter()
                    .map(|&c| grid.snap(c).map_err(far))
                    .collect::<Result<_, _>>()?;
                let world = g.iter().map(|c| grid.to_world(c.map(f64::from))).collect();
                (AreaLight::new(&g).map_err(extent)?, SoftShape::Area(world))
            }
            &SoftSpec::SunDisc {
                direction,
                radius_deg,
            } => {
                let light = AreaLight::sun_disc(direction, radius_deg.to_radians());
                let direction = direction.normalize_or_zero();
                let shape = SoftShape::SunDisc {
                    direction,
                    radius_deg,
                };
                (light.map_err(extent)?, shape)
            }
        };
        out.push(SoftLight { light, shape });
    }
    Ok(out)
}

impl std::fmt::Display for SoftShape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v = |p: &DVec3| crate::input_triple(*p);
        match self {
            SoftShape::Point(p) => write!(f, "point light at {}", v(p)),
            SoftShape::Sun(d) => write!(f, "sun toward {}", v(d)),
            SoftShape::Area(c) => {
                let c: Vec<String> = c.iter().map(v).collect();
                write!(f, "area light {}", c.join(";"))
            }
            SoftShape::SunDisc {
                direction,
                radius_deg,
            } => write!(
                f,
                "sun disc toward {}, radius {} degrees",
                v(direction),
                crate::input_number(*radius_deg)
            ),
        }
    }
}

impl std::fmt::Display for SoftSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SoftSpec::Area(c) => SoftShape::Area(c.clone()).fmt(f),
            &SoftSpec::SunDisc {
                direction,
                radius_deg,
            } => SoftShape::SunDisc {
                direction,
                radius_deg,
            }
            .fmt(f),
        }
    }
}
