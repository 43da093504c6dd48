//! Runs a scene through the tree build and `shadow_fragments`, then checks
//! the result with the oracle: exact tiling of every face, and every flag
//! against ray casting on interior samples.

use std::collections::BTreeSet;

use bsp_core::{BspTree, BuildOptions, Polygon};
use svbsp::{Fragment, Light, ShadowStats, shadow_fragments};

use crate::oracle::{Face, FlagStats, Scene, check_flags, check_pieces, check_tiling};

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
    /// Tree build seeds (each gives another tree for the same scene).
    pub(crate) seeds: Vec<u64>,
    pub(crate) sample: Sample,
    /// Check pairwise disjointness of each face's fragments.
    pub(crate) disjoint: bool,
}

impl Default for Opts {
    fn default() -> Opts {
        Opts {
            seeds: vec![BuildOptions::default().seed, 1, 0xdead_beef],
            sample: Sample::All,
            disjoint: true,
        }
    }
}

/// What a checked run produced (for the first seed), and the flag figures
/// summed over the seeds.
pub(crate) struct Checked {
    pub(crate) frags: Vec<Fragment>,
    pub(crate) stats: ShadowStats,
    pub(crate) flags: FlagStats,
}

impl Checked {
    /// Flags of light `j` on the fragments of face `face`.
    pub(crate) fn flags_of(&self, face: u32, j: usize) -> Vec<bool> {
        self.frags
            .iter()
            .filter(|f| f.face() == face)
            .map(|f| f.lit()[j])
            .collect()
    }

    /// Number of fragments lit by light `j`, and in shadow of it.
    pub(crate) fn count(&self, j: usize) -> (usize, usize) {
        let lit = self.frags.iter().filter(|f| f.lit()[j]).count();
        (lit, self.frags.len() - lit)
    }
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

/// Checks a scene given as loops, with every fragment sampled, on three
/// trees.
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

fn pick(frags: &[Fragment], scene: &Scene, lights: &[Light], n: usize) -> BTreeSet<usize> {
    let mut out = BTreeSet::new();
    for (j, light) in lights.iter().enumerate() {
        let mut kinds: [Vec<usize>; 3] = Default::default();
        for (i, f) in frags.iter().enumerate() {
            let k = if !scene.faces[f.face() as usize].faces_light(light) {
                2
            } else if f.lit()[j] {
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

/// Builds the tree for each seed, runs the shadows and checks the output:
/// tiling of every face, flags on the chosen fragments.
pub(crate) fn check(
    polys: &[Polygon],
    scene: &Scene,
    lights: &[Light],
    opts: &Opts,
) -> Result<Checked, String> {
    let mut first: Option<Checked> = None;
    let mut flags = FlagStats::default();
    for &seed in &opts.seeds {
        let tree = BspTree::build(polys.to_vec(), &BuildOptions::default().with_seed(seed));
        let (frags, stats) = shadow_fragments(&tree, lights).map_err(|e| e.to_string())?;
        let ctx = |e: String| format!("tree seed {seed}: {e}");
        if stats.fragments != frags.len() {
            return Err(ctx(format!(
                "stats say {} fragments, {} came out",
                stats.fragments,
                frags.len()
            )));
        }
        check_tiling(scene, &frags, opts.disjoint).map_err(ctx)?;
        let tree_polys: Vec<&Polygon> = tree.polygons().collect();
        check_pieces(scene, &tree_polys, &frags).map_err(ctx)?;
        let chosen: Box<dyn Iterator<Item = &Fragment>> = match opts.sample {
            Sample::All => Box::new(frags.iter()),
            Sample::PerKind(n) => Box::new(
                pick(&frags, scene, lights, n)
                    .into_iter()
                    .map(|i| &frags[i]),
            ),
        };
        for f in chosen {
            check_flags(scene, lights, f, &mut flags).map_err(ctx)?;
        }
        if first.is_none() {
            first = Some(Checked {
                frags,
                stats,
                flags: FlagStats::default(),
            });
        }
    }
    let mut out = first.ok_or("no seeds")?;
    out.flags = flags;
    Ok(out)
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
    let tree = BspTree::build(polygons(&loops).unwrap(), &BuildOptions::default());
    let here = [Light::Point([3, 3, 8])];
    let (frags, _) = shadow_fragments(&tree, &here).unwrap();
    let mut stats = FlagStats::default();
    for f in &frags {
        check_flags(&scene, &here, f, &mut stats).unwrap();
    }
    for other in [Light::Point([7, 7, 8]), Light::Directional([0, 0, 1])] {
        let errors = frags
            .iter()
            .filter(|f| check_flags(&scene, &[other], f, &mut stats).is_err())
            .count();
        assert!(errors > 0, "{other:?}");
    }
}

#[test]
fn the_tiling_check_rejects_a_missing_or_repeated_fragment() {
    let loops = floor_and_roof();
    let scene = scene_of(&loops);
    let tree = BspTree::build(polygons(&loops).unwrap(), &BuildOptions::default());
    let (frags, _) = shadow_fragments(&tree, &[Light::Point([3, 3, 8])]).unwrap();
    check_tiling(&scene, &frags, true).unwrap();
    let floor: Vec<usize> = (0..frags.len()).filter(|&i| frags[i].face() == 0).collect();
    assert!(floor.len() > 1);
    for &i in &floor {
        let mut fewer = frags.clone();
        fewer.remove(i);
        assert!(check_tiling(&scene, &fewer, false).is_err());
        let mut more = frags.clone();
        more.push(frags[i].clone());
        assert!(check_tiling(&scene, &more, false).is_err());
    }
    // a fragment swapped in from another scene: same area, wrong place
    let moved = vec![
        vec![[0, 0, 0], [8, 0, 0], [8, 8, 0], [0, 8, 0]],
        vec![[4, 4, 4], [6, 4, 4], [6, 6, 4], [4, 6, 4]],
    ];
    let tree2 = BspTree::build(polygons(&moved).unwrap(), &BuildOptions::default());
    let (frags2, _) = shadow_fragments(&tree2, &[Light::Point([5, 5, 8])]).unwrap();
    let dark = |fs: &[Fragment]| {
        fs.iter()
            .position(|f| f.face() == 0 && !f.lit()[0])
            .expect("a shadow on the floor")
    };
    let mut swapped = frags.clone();
    swapped[dark(&frags)] = frags2[dark(&frags2)].clone();
    assert!(check_tiling(&scene, &swapped, true).is_err());
}
