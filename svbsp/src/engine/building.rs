//! Building the trees of several lights: which occluders each keeps,
//! two lights at a time, and the first two built while the occluders'
//! closed parts are certified.

use bsp_core::Polygon;
use rayon::prelude::*;

use super::LightVolumes;
use crate::engine::ShadowError;
use crate::light::{Light, LightError, MAX_LIGHTS};
use crate::psv::{Reached, ShadowVolumes, Stop, VolumeError};

/// Per light, the faces a tree was built over while certifying, and the
/// tree (`None`: given up).
type Guessed = Vec<(Vec<usize>, Result<Option<Reached>, VolumeError>)>;

/// How a light's tree is built over the occluders of the given indices,
/// given up (`None`) once the stop is raised.
type Build<'a> =
    dyn Fn(Light, Vec<usize>, Option<&Stop>) -> Result<Option<Reached>, VolumeError> + Sync + 'a;

impl LightVolumes {
    /// The trees of `lights` over `occluders` taken in the order of the
    /// indices `order` ([`LightVolumes::new_with`]), and with `reach`
    /// what each tree's building found of the occluders it holds
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
        let build_until = |l: Light, index: Vec<usize>, stop: Option<&Stop>| match reach {
            true => ShadowVolumes::build_reached_among_until(l, occluders, &index, stop),
            false => {
                let kept: Vec<&Polygon> = index.iter().map(|&i| &occluders[i]).collect();
                let built = ShadowVolumes::build_until(l, &kept, stop)?;
                Ok(built.map(|v| (v, Vec::new())))
            }
        };
        let build = |l: Light, index: Vec<usize>| -> Result<Reached, VolumeError> {
            Ok(build_until(l, index, None)?.expect("no stop"))
        };
        let kept =
            |l: Light, solids: &bsp_core::SolidParts| kept(occluders, order, &l, solids).collect();
        let (owned, first) = match solids {
            Some(_) => (None, Vec::new()),
            None => {
                let (solids, first) =
                    LightVolumes::new_certifying(occluders, order, lights, &build_until);
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
                Ok(Some(t)) if index == faced => built.push(t),
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
    /// are built over the occluders no certificate can leave out, in
    /// `order`: the faces toward the light, and those of the parts the
    /// pairing of the edges (the certificate's first step) finds open.
    /// Where the certified parts leave out every other face (closed
    /// meshes lit from outside, open scans, and both), such a tree is the
    /// one the parts ask for, and is kept; otherwise it is built again,
    /// and a guess is given up as soon as the parts say it fails. (An
    /// open scan was not guessed for, and waited for the certificate's
    /// serial steps with the other core idle.) The parts, and per light
    /// the faces its tree was built over with the tree.
    fn new_certifying(
        occluders: &[Polygon],
        order: &[usize],
        lights: &[Light],
        build: &Build,
    ) -> (bsp_core::SolidParts, Guessed) {
        let paired = bsp_core::pair_solid_parts(occluders);
        // per light: the faces it faces, and those of open parts (in
        // parallel: the trees wait for it)
        let guess = |l: &Light| -> Vec<usize> {
            (order.par_iter().copied())
                .filter(|&i| l.faces(occluders[i].support()) || paired.open(i))
                .collect()
        };
        let first: Vec<(Light, Vec<usize>)> =
            (lights.iter().take(2)).map(|l| (*l, guess(l))).collect();
        if first.is_empty() {
            return (paired.certify(), Vec::new());
        }
        let stops = [Stop::new(false), Stop::new(false)];
        let certify = || {
            let solids = paired.certify();
            for ((l, faced), stop) in first.iter().zip(&stops) {
                let holds = kept(occluders, order, l, &solids).eq(faced.iter().copied());
                if !holds {
                    stop.store(true, std::sync::atomic::Ordering::Relaxed);
                }
            }
            solids
        };
        let guessed = || match &first[..] {
            [(a, fa), (b, fb)] => {
                let (ta, tb) = rayon::join(
                    || build(*a, fa.clone(), Some(&stops[0])),
                    || build(*b, fb.clone(), Some(&stops[1])),
                );
                vec![(fa.clone(), ta), (fb.clone(), tb)]
            }
            [(a, fa)] => vec![(fa.clone(), build(*a, fa.clone(), Some(&stops[0])))],
            _ => unreachable!("one or two lights"),
        };
        rayon::join(certify, guessed)
    }
}

/// The faces of `order` (in that order) that light `l`'s tree keeps: all
/// but those the certified parts `solids` leave out.
fn kept<'a>(
    occluders: &'a [Polygon],
    order: &'a [usize],
    l: &'a Light,
    solids: &'a bsp_core::SolidParts,
) -> impl Iterator<Item = usize> + 'a {
    (order.iter().copied()).filter(move |&i| !l.leaves_out(solids, i, occluders[i].support()))
}
