//! Building the trees of several lights: which occluders each keeps,
//! two lights at a time, and the first two built while the occluders'
//! closed parts are certified.

use bsp_core::Polygon;

use super::LightVolumes;
use crate::engine::ShadowError;
use crate::light::{Light, LightError, MAX_LIGHTS};
use crate::psv::{ShadowVolumes, VolumeError};

/// A light's tree, and per occluder what its building found of it (empty
/// where not asked).
type Built = (ShadowVolumes, Vec<Option<bool>>);

/// Per light, the faces a tree was built over while certifying, and the
/// tree.
type Guessed = Vec<(Vec<usize>, Result<Built, VolumeError>)>;

/// How a light's tree is built over the occluders of the given indices.
type Build<'a> = dyn Fn(Light, Vec<usize>) -> Result<Built, VolumeError> + Sync + 'a;

impl LightVolumes {
    /// [`LightVolumes::new_ordered`], and with `reach` what each tree's
    /// building found of the occluders it holds
    /// ([`ShadowVolumes::build_reached`]). With `solids` `None`, the
    /// occluders' parts are certified here, while the first two lights'
    /// trees are built over the faces they face (see
    /// [`LightVolumes::new_certifying`]).
    pub(super) fn new_built(
        occluders: &[Polygon],
        order: &[usize],
        lights: &[Light],
        solids: Option<&bsp_core::SolidParts>,
        reach: bool,
    ) -> Result<LightVolumes, ShadowError> {
        if lights.len() > MAX_LIGHTS {
            return Err(LightError::TooMany(lights.len()).into());
        }
        for l in lights {
            l.validate()?;
        }
        // (polygons off the grid leave no part certified, so nothing is
        // left out and an error's index is the caller's)
        let build = |l: Light, index: Vec<usize>| match reach {
            true => ShadowVolumes::build_reached_among(l, occluders, &index),
            false => {
                let kept: Vec<&Polygon> = index.iter().map(|&i| &occluders[i]).collect();
                ShadowVolumes::build(l, &kept).map(|v| (v, Vec::new()))
            }
        };
        let kept = |l: Light, solids: &bsp_core::SolidParts| -> Vec<usize> {
            (order.iter().copied())
                .filter(|&i| !l.leaves_out(solids, i, occluders[i].support()))
                .collect()
        };
        let (owned, first) = match solids {
            Some(_) => (None, Vec::new()),
            None => {
                let (solids, first) =
                    LightVolumes::new_certifying(occluders, order, lights, &build);
                (Some(solids), first)
            }
        };
        let solids = solids.or(owned.as_ref()).expect("given or certified");
        let mut built = Vec::with_capacity(lights.len());
        // the speculated trees that hold: built over the very occluders
        // the certified parts keep
        for (l, (faced, tree)) in lights.iter().zip(first) {
            let index = kept(*l, solids);
            match tree {
                Ok(t) if index == faced => built.push(t),
                _ => built.push(build(*l, index)?),
            }
        }
        // two lights at a time: each build is parallel inside but has
        // parts on one thread (its start, and its last regions), which the
        // other build fills; only two builds' working memory is alive at
        // once
        for pair in lights[built.len()..].chunks(2) {
            match *pair {
                [a, b] => {
                    let (a, b) =
                        rayon::join(|| build(a, kept(a, solids)), || build(b, kept(b, solids)));
                    built.push(a?);
                    built.push(b?);
                }
                [a] => built.push(build(a, kept(a, solids))?),
                _ => unreachable!("chunks of one or two"),
            }
        }
        let (volumes, reached): (Vec<ShadowVolumes>, Vec<Vec<Option<bool>>>) =
            built.into_iter().unzip();
        Ok(LightVolumes {
            lights: lights.to_vec(),
            volumes,
            reached: if reach { reached } else { Vec::new() },
        })
    }

    /// Certifies the parts of `occluders` ([`bsp_core::certify_solid_parts`],
    /// which has steps on one thread) while the first two lights' trees
    /// are built over the occluders they face, in `order`: the faces a
    /// light's tree keeps whatever the parts are. Where the certified
    /// parts leave out every other face (a scene of closed meshes lit
    /// from outside, and open faces toward the light), such a tree is the
    /// one the parts ask for, and is kept; otherwise it is built again.
    /// The parts, and per light the faces its tree was built over with
    /// the tree.
    fn new_certifying(
        occluders: &[Polygon],
        order: &[usize],
        lights: &[Light],
        build: &Build,
    ) -> (bsp_core::SolidParts, Guessed) {
        let faced = |l: &Light| -> Vec<usize> {
            (order.iter().copied())
                .filter(|&i| l.faces(occluders[i].support()))
                .collect()
        };
        let first = &lights[..lights.len().min(2)];
        rayon::join(
            || bsp_core::certify_solid_parts(occluders),
            || match *first {
                [a, b] => {
                    let (fa, fb) = (faced(&a), faced(&b));
                    let (ta, tb) = rayon::join(|| build(a, fa.clone()), || build(b, fb.clone()));
                    vec![(fa, ta), (fb, tb)]
                }
                [a] => {
                    let fa = faced(&a);
                    let ta = build(a, fa.clone());
                    vec![(fa, ta)]
                }
                _ => Vec::new(),
            },
        )
    }
}
