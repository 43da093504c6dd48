//! Runs a scene through both shadow algorithms and checks them with the
//! oracle: the fast path's fragments (maximal regions and their convex
//! pieces) tile every face exactly, are as large as they can be, and carry
//! the flags the ray oracle gives at interior samples; shuffling the input
//! changes no face's exact lit area; Chin & Feiner's fragments on scene
//! trees tile every face, carry the oracle's flags, and give exactly the
//! same area per face and set of flags as the fast path.

use std::collections::{BTreeSet, HashMap};

use bsp_core::{BspTree, BuildOptions, Polygon};
use num_traits::{ToPrimitive, Zero};
use svbsp::{
    Batch, CfFragments, Light, LightVolumes, ShadowStats, ShadowVolumes, chin_feiner,
    shadow_fragments,
};

use crate::oracle::{
    Face, FlagStats, HPoint, PieceRef, Q, Region, Scene, area_of, check_flags, check_regions,
    check_tiling,
};

/// Which fragments get their flags checked.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Sample {
    /// Every fragment.
    All,
    /// Per light, up to this many fragments of each kind (lit, cast
    /// shadow, attached shadow), evenly spread over the output.
    PerKind(usize),
}

/// How to check a scene.
#[derive(Clone, Debug)]
pub(crate) struct Opts {
    /// Scene tree seeds for Chin & Feiner (each gives another tree).
    pub(crate) seeds: Vec<u64>,
    pub(crate) sample: Sample,
    /// Check pairwise disjointness of each face's pieces.
    pub(crate) disjoint: bool,
    /// Rerun on the polygons in another order and compare.
    pub(crate) shuffled: bool,
}

impl Default for Opts {
    fn default() -> Opts {
        Opts {
            seeds: vec![BuildOptions::default().seed, 1],
            sample: Sample::All,
            disjoint: true,
            shuffled: true,
        }
    }
}

/// One fragment of the fast path, simplified for assertions.
pub(crate) struct Frag {
    face: u32,
    lit: Vec<bool>,
    holes: usize,
}

impl Frag {
    pub(crate) fn face(&self) -> u32 {
        self.face
    }
    pub(crate) fn lit(&self) -> &[bool] {
        &self.lit
    }
    pub(crate) fn holes(&self) -> usize {
        self.holes
    }
}

/// What a checked run produced, and the flag figures summed over the
/// checks.
pub(crate) struct Checked {
    pub(crate) frags: Vec<Frag>,
    pub(crate) stats: ShadowStats,
    pub(crate) flags: FlagStats,
}

impl Checked {
    /// Flags of light `j` on the fragments of face `face`.
    pub(crate) fn flags_of(&self, face: u32, j: usize) -> Vec<bool> {
        self.frags
            .iter()
            .filter(|f| f.face == face)
            .map(|f| f.lit[j])
            .collect()
    }

    /// Number of fragments lit by light `j`, and in shadow of it.
    pub(crate) fn count(&self, j: usize) -> (usize, usize) {
        let lit = self.frags.iter().filter(|f| f.lit[j]).count();
        (lit, self.frags.len() - lit)
    }

    /// Number of fragments of face `face`.
    pub(crate) fn fragments_of(&self, face: u32) -> usize {
        self.frags.iter().filter(|f| f.face == face).count()
    }
}

/// `SVBSP_SEED`, when a hunt sets it (for longer hunts, as `SVBSP_CASES`
/// for the properties). A hunt looks for wrong answers only: the checks
/// that the default scenes meet every class are left out.
pub(crate) fn hunt() -> Option<u64> {
    std::env::var("SVBSP_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
}

/// A random scenes' generator: `default`, or under a hunt another stream
/// for every test.
pub(crate) fn rng(default: u64) -> bsp_fixtures::Rng {
    let h = hunt().map_or(0, |h| h.wrapping_mul(0x9e37_79b9_7f4a_7c15));
    bsp_fixtures::Rng::new(default ^ h)
}

/// Input loops as convex polygons tagged with their index.
pub(crate) fn polygons(loops: &[Vec<[i32; 3]>]) -> Result<Vec<Polygon>, String> {
    loops
        .iter()
        .enumerate()
        .map(|(i, l)| {
            Polygon::from_grid_points(l, i as u32).map_err(|e| format!("face {i} {l:?}: {e}"))
        })
        .collect()
}

/// The oracle's scene, straight from the loops.
pub(crate) fn scene_of(loops: &[Vec<[i32; 3]>]) -> Scene {
    Scene::new(
        loops
            .iter()
            .map(|l| Face::new(&l.iter().map(|p| p.map(i64::from)).collect::<Vec<_>>()))
            .collect(),
    )
}

/// Checks a scene given as loops, with every fragment sampled.
pub(crate) fn check_loops(loops: &[Vec<[i32; 3]>], lights: &[Light]) -> Result<Checked, String> {
    let polys = polygons(loops)?;
    check(&polys, &scene_of(loops), lights, &Opts::default())
}

/// Panicking form of [`check_loops`] for fixed scenes.
pub(crate) fn assert_loops(loops: &[Vec<[i32; 3]>], lights: &[Light]) -> Checked {
    match check_loops(loops, lights) {
        Ok(c) => c,
        Err(e) => panic!("{e}\nscene: {loops:?}\nlights: {lights:?}"),
    }
}

fn flags(mask: u64, n: usize) -> Vec<bool> {
    (0..n).map(|i| mask >> i & 1 == 1).collect()
}

/// The fast path's fragments as regions with exact vertices.
pub(crate) fn regions_of(batch: &Batch, lights: usize) -> Vec<Region> {
    let pt = |v: u32| HPoint::of_vertex(batch.vertex(v).expect("exact vertices"));
    batch
        .fragments()
        .map(|f| Region {
            face: f.face() as usize,
            lit: flags(f.lit_mask(), lights),
            rings: f
                .rings()
                .map(|r| r.iter().map(|&v| pt(v)).collect())
                .collect(),
            pieces: f
                .pieces()
                .map(|p| p.iter().map(|&v| pt(v)).collect())
                .collect(),
        })
        .collect()
}

/// Exact area (as a multiple of the face's) per face and set of flags.
type Areas = HashMap<(usize, Vec<bool>), Q>;

fn areas_of<'a>(
    scene: &Scene,
    pieces: impl Iterator<Item = (usize, &'a [bool], &'a [HPoint])>,
) -> Areas {
    let mut out: Areas = HashMap::new();
    for (face, lit, verts) in pieces {
        *out.entry((face, lit.to_vec())).or_insert_with(Q::zero) +=
            area_of(&scene.faces[face], verts);
    }
    out
}

fn compare_areas(what: &str, a: &Areas, b: &Areas) -> Result<(), String> {
    let keys: BTreeSet<&(usize, Vec<bool>)> = a.keys().chain(b.keys()).collect();
    for k in keys {
        let (x, y) = (
            a.get(k).cloned().unwrap_or_else(Q::zero),
            b.get(k).cloned().unwrap_or_else(Q::zero),
        );
        if x != y {
            return Err(format!(
                "{what}: face {} with flags {:?} has {} of its area lit that way, not {}",
                k.0,
                k.1,
                y.to_f64().unwrap_or(f64::NAN),
                x.to_f64().unwrap_or(f64::NAN)
            ));
        }
    }
    Ok(())
}

/// The indices of the items to check: all, or per light up to `n` of each
/// kind (lit, cast shadow, attached shadow) spread over the list.
fn pick(
    items: &[(usize, Vec<bool>)],
    scene: &Scene,
    lights: &[Light],
    sample: Sample,
) -> BTreeSet<usize> {
    let n = match sample {
        Sample::All => return (0..items.len()).collect(),
        Sample::PerKind(n) => n,
    };
    let mut out = BTreeSet::new();
    for (j, light) in lights.iter().enumerate() {
        let mut kinds: [Vec<usize>; 3] = Default::default();
        for (i, (face, lit)) in items.iter().enumerate() {
            let k = if !scene.faces[*face].faces_light(light) {
                2
            } else if lit[j] {
                0
            } else {
                1
            };
            kinds[k].push(i);
        }
        for list in &kinds {
            let step = list.len().div_ceil(n.max(1)).max(1);
            out.extend(list.iter().step_by(step).copied());
        }
    }
    out
}

/// A fixed permutation of `n` items.
fn shuffle(n: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..n).collect();
    let mut s = 0x2545_f491_4f6c_dd1du64;
    for i in (1..n).rev() {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        order.swap(i, (s % (i as u64 + 1)) as usize);
    }
    order
}

/// Runs both algorithms and checks everything (see the module docs).
pub(crate) fn check(
    polys: &[Polygon],
    scene: &Scene,
    lights: &[Light],
    opts: &Opts,
) -> Result<Checked, String> {
    let n = lights.len();
    let shadows = LightVolumes::new(polys, lights).map_err(|e| e.to_string())?;
    for (j, v) in shadows.volumes().iter().enumerate() {
        v.sanity_check()
            .map_err(|e| format!("shadow volumes of light {j}: {e}"))?;
    }
    let (batch, stats) = shadow_fragments(polys, lights).map_err(|e| e.to_string())?;
    if stats.fragments != batch.len() {
        return Err(format!(
            "stats say {} fragments, {} came out",
            stats.fragments,
            batch.len()
        ));
    }
    let regions = regions_of(&batch, n);
    let pieces: Vec<(usize, Vec<HPoint>)> = regions
        .iter()
        .flat_map(|r| r.pieces.iter().map(move |p| (r.face, p.clone())))
        .collect();
    check_tiling(scene, &pieces, opts.disjoint).map_err(|e| format!("fast path: {e}"))?;
    check_regions(scene, &regions).map_err(|e| format!("fast path: {e}"))?;
    let mut flag_stats = FlagStats::default();
    let items: Vec<(usize, Vec<bool>)> = regions.iter().map(|r| (r.face, r.lit.clone())).collect();
    for i in pick(&items, scene, lights, opts.sample) {
        let r = &regions[i];
        for p in &r.pieces {
            let piece = PieceRef {
                face: r.face,
                lit: &r.lit,
                verts: p,
            };
            check_flags(scene, lights, &piece, &mut flag_stats)
                .map_err(|e| format!("fast path: {e}"))?;
        }
    }
    let areas = areas_of(
        scene,
        regions
            .iter()
            .flat_map(|r| r.pieces.iter().map(move |p| (r.face, &r.lit[..], &p[..]))),
    );
    check_lit_parts(polys, scene, lights, &areas)?;
    if opts.shuffled {
        let order = shuffle(polys.len());
        let moved: Vec<Polygon> = order.iter().map(|&i| polys[i].clone()).collect();
        let (b, _) = shadow_fragments(&moved, lights).map_err(|e| e.to_string())?;
        let r = regions_of(&b, n);
        let other = areas_of(
            scene,
            r.iter()
                .flat_map(|r| r.pieces.iter().map(move |p| (r.face, &r.lit[..], &p[..]))),
        );
        compare_areas("shuffled input", &areas, &other)?;
    }
    for &seed in &opts.seeds {
        let ctx = |e: String| format!("Chin & Feiner, tree seed {seed}: {e}");
        let tree = BspTree::build(polys.to_vec(), &BuildOptions::default().with_seed(seed));
        let cf = chin_feiner(&tree, lights).map_err(|e| e.to_string())?;
        check_chin_feiner(scene, lights, &cf, opts, &areas, &mut flag_stats).map_err(ctx)?;
    }
    let frags = batch
        .fragments()
        .map(|f| Frag {
            face: f.face(),
            lit: flags(f.lit_mask(), n),
            holes: f.hole_count(),
        })
        .collect();
    Ok(Checked {
        frags,
        stats,
        flags: flag_stats,
    })
}

/// The lit parts found while each light's tree is built
/// ([`ShadowVolumes::lit_parts`]) give every face exactly the fast path's
/// lit area for that light.
fn check_lit_parts(
    polys: &[Polygon],
    scene: &Scene,
    lights: &[Light],
    areas: &Areas,
) -> Result<(), String> {
    for (j, &light) in lights.iter().enumerate() {
        let mut want: HashMap<usize, Q> = HashMap::new();
        for ((face, lit), a) in areas {
            if lit[j] {
                *want.entry(*face).or_insert_with(Q::zero) += a;
            }
        }
        let (_, parts) = ShadowVolumes::lit_parts(light, polys).map_err(|e| e.to_string())?;
        let mut got: HashMap<usize, Q> = HashMap::new();
        let mut per_poly: HashMap<usize, Q> = HashMap::new();
        for (i, verts) in parts {
            let face = polys[i].tag() as usize;
            let pts: Vec<HPoint> = verts.iter().map(HPoint::of_vertex).collect();
            let a = area_of(&scene.faces[face], &pts);
            *per_poly.entry(i).or_insert_with(Q::zero) += a.clone();
            *got.entry(face).or_insert_with(Q::zero) += a;
        }
        // what the building says of each polygon: all of it, none, or part
        let (_, reached) = ShadowVolumes::build_reached(light, polys).map_err(|e| e.to_string())?;
        for (i, (p, r)) in polys.iter().zip(&reached).enumerate() {
            if !light.faces(p.support()) {
                continue;
            }
            let face = p.tag() as usize;
            let pts: Vec<HPoint> = (p.vertices().iter())
                .map(|v| match v {
                    bsp_core::Point::Grid(g) => Ok(HPoint::grid(g.map(i64::from))),
                    bsp_core::Point::Implicit(_) => Err("an occluder off the grid".to_string()),
                })
                .collect::<Result<_, _>>()?;
            let whole = area_of(&scene.faces[face], &pts);
            let lit = per_poly.get(&i).cloned().unwrap_or_else(Q::zero);
            let found = match (lit.is_zero(), lit == whole) {
                (true, _) => Some(false),
                (_, true) => Some(true),
                _ => None,
            };
            if *r != found {
                return Err(format!(
                    "light {j}: the building says {r:?} of polygon {i}, its lit parts {found:?}"
                ));
            }
        }
        let faces: BTreeSet<usize> = want.keys().chain(got.keys()).copied().collect();
        for f in faces {
            let (w, g) = (
                want.get(&f).cloned().unwrap_or_else(Q::zero),
                got.get(&f).cloned().unwrap_or_else(Q::zero),
            );
            if w != g {
                return Err(format!(
                    "light {j}: the parts lit as the tree was built give face {f} {} of its \
                     area, the filter {}",
                    g.to_f64().unwrap_or(f64::NAN),
                    w.to_f64().unwrap_or(f64::NAN)
                ));
            }
        }
    }
    Ok(())
}

/// Chin & Feiner's fragments: valid convex polygons that tile the faces,
/// with the oracle's flags (sampled as `opts` says), and the same exact
/// area per face and flags as the fast path.
fn check_chin_feiner(
    scene: &Scene,
    lights: &[Light],
    cf: &CfFragments,
    opts: &Opts,
    areas: &Areas,
    stats: &mut FlagStats,
) -> Result<(), String> {
    let n = lights.len();
    let mut pieces: Vec<(usize, Vec<HPoint>)> = Vec::with_capacity(cf.len());
    let mut items = Vec::with_capacity(cf.len());
    for f in cf.iter() {
        f.sanity_check()
            .map_err(|e| format!("fragment of face {}: sanity_check: {e}", f.face()))?;
        pieces.push((f.face() as usize, f.vertices().map(HPoint::of).collect()));
        items.push((f.face() as usize, flags(f.lit_mask(), n)));
    }
    check_tiling(scene, &pieces, opts.disjoint)?;
    for i in pick(&items, scene, lights, opts.sample) {
        let piece = PieceRef {
            face: items[i].0,
            lit: &items[i].1,
            verts: &pieces[i].1,
        };
        check_flags(scene, lights, &piece, stats)?;
    }
    let mine = areas_of(
        scene,
        items
            .iter()
            .zip(&pieces)
            .map(|((face, lit), (_, v))| (*face, &lit[..], &v[..])),
    );
    compare_areas("against the fast path", areas, &mine)
}

/// The floor `[0, 8]^2` with the roof `[2, 4]^2` at height 4 over it.
#[cfg(test)]
fn floor_and_roof() -> Vec<Vec<[i32; 3]>> {
    vec![
        vec![[0, 0, 0], [8, 0, 0], [8, 8, 0], [0, 8, 0]],
        vec![[2, 2, 4], [4, 2, 4], [4, 4, 4], [2, 4, 4]],
    ]
}

#[test]
fn the_flag_check_rejects_another_lights_flags() {
    // the checks have teeth: flags computed for one light fail against
    // the oracle for a light elsewhere
    let loops = floor_and_roof();
    let scene = scene_of(&loops);
    let here = [Light::Point([3, 3, 8])];
    let (b, _) = shadow_fragments(&polygons(&loops).unwrap(), &here).unwrap();
    let regions = regions_of(&b, 1);
    let mut stats = FlagStats::default();
    let check_all = |lights: &[Light], stats: &mut FlagStats| {
        regions
            .iter()
            .flat_map(|r| r.pieces.iter().map(move |p| (r, p)))
            .filter(|(r, p)| {
                let piece = PieceRef {
                    face: r.face,
                    lit: &r.lit,
                    verts: p,
                };
                check_flags(&scene, lights, &piece, stats).is_err()
            })
            .count()
    };
    assert_eq!(check_all(&here, &mut stats), 0);
    for other in [Light::Point([7, 7, 8]), Light::Directional([0, 0, 1])] {
        assert!(check_all(&[other], &mut stats) > 0, "{other:?}");
    }
}

#[test]
fn the_tiling_and_region_checks_reject_broken_output() {
    let loops = floor_and_roof();
    let scene = scene_of(&loops);
    let (b, _) = shadow_fragments(&polygons(&loops).unwrap(), &[Light::Point([3, 3, 8])]).unwrap();
    let regions = regions_of(&b, 1);
    let pieces: Vec<(usize, Vec<HPoint>)> = regions
        .iter()
        .flat_map(|r| r.pieces.iter().map(move |p| (r.face, p.clone())))
        .collect();
    check_tiling(&scene, &pieces, true).unwrap();
    check_regions(&scene, &regions).unwrap();
    let floor: Vec<usize> = (0..pieces.len()).filter(|&i| pieces[i].0 == 0).collect();
    assert!(floor.len() > 1);
    for &i in &floor {
        let mut fewer = pieces.clone();
        fewer.remove(i);
        assert!(check_tiling(&scene, &fewer, false).is_err());
        let mut more = pieces.clone();
        more.push(pieces[i].clone());
        assert!(check_tiling(&scene, &more, false).is_err());
    }
    // a region split in two along a cut with equal flags on both sides
    let lit = regions
        .iter()
        .position(|r| r.face == 0 && r.lit[0])
        .unwrap();
    assert!(regions[lit].pieces.len() > 1);
    let mut split: Vec<Region> = Vec::new();
    for (i, r) in regions.iter().enumerate() {
        if i == lit {
            for p in &r.pieces {
                split.push(Region {
                    face: r.face,
                    lit: r.lit.clone(),
                    rings: vec![p.clone()],
                    pieces: vec![p.clone()],
                });
            }
        } else {
            split.push(Region {
                face: r.face,
                lit: r.lit.clone(),
                rings: r.rings.clone(),
                pieces: r.pieces.clone(),
            });
        }
    }
    let e = check_regions(&scene, &split).unwrap_err();
    assert!(e.contains("touch along an edge"), "{e}");
    // a hole turned the wrong way
    let mut turned: Vec<Region> = regions
        .iter()
        .map(|r| Region {
            face: r.face,
            lit: r.lit.clone(),
            rings: r.rings.clone(),
            pieces: r.pieces.clone(),
        })
        .collect();
    assert_eq!(turned[lit].rings.len(), 2);
    turned[lit].rings[1].reverse();
    assert!(check_regions(&scene, &turned).is_err());
}
