//! Receivers whose shadows the trees' building already found.
//!
//! Building a light's tree inserts every occluder, and each part of it
//! that its insertion brings to a lit leaf is lit by every volume in the
//! tree so far; kept there and walked on where a later volume is grafted,
//! those parts are exactly what the occluder's receiver would find lit
//! filtered through the finished tree ([`ShadowVolumes::build_reached`],
//! `psv/rests.rs`). Most faces of a scene come out lit all over or dark
//! all over: shading the occluders themselves, such a receiver takes its
//! flag for that light as it is, and only the lights that light part of
//! it are filtered. Its fragments are the ones the filter makes (for a
//! receiver one light reaches all over, the filter's quick test keeps it
//! whole too), so the output is the same, for less work. The same holds
//! for the cells an area light's corner trees cut a whole face into
//! ([`ShadowSet::cells_known`]), which is why those live here too.

use std::ops::Range;

use bsp_core::{Plane, Polygon};
use rayon::prelude::*;
use smallvec::SmallVec;

use super::{Batch, LightVolumes, ShadeOptions, ShadowError, ShadowSet, Start};
use crate::engine::Scratch;
use crate::light::Light;
use crate::psv::ShadowVolumes;
use crate::schedule::PARALLEL_CELLS;

impl LightVolumes {
    /// [`LightVolumes::new_with`] with the occluders taken in the order of
    /// the indices `order` (each tree is built in that order), keeping
    /// what each tree's building found of the occluders, for
    /// [`LightVolumes::set_for_occluders`].
    pub(crate) fn new_ordered_reaching(
        occluders: &[Polygon],
        order: &[usize],
        lights: &[Light],
        solids: &bsp_core::SolidParts,
    ) -> Result<LightVolumes, ShadowError> {
        LightVolumes::new_built(occluders, order, lights, Some(solids), true)
    }

    /// [`LightVolumes::new`], keeping what each tree's building found of
    /// the occluders it holds, for [`LightVolumes::set_for_occluders`].
    pub fn new_reaching(
        occluders: &[Polygon],
        lights: &[Light],
    ) -> Result<LightVolumes, ShadowError> {
        let order: Vec<usize> = (0..occluders.len()).collect();
        LightVolumes::new_built(occluders, &order, lights, None, true)
    }

    /// [`LightVolumes::from_volumes`] with what each tree's building found
    /// of the occluders: `reached[j][i]` for light `j` and polygon `i` of
    /// the receivers to be shaded by [`LightVolumes::set_for_occluders`]
    /// (`Some(true)`: the tree lets the light reach all of it, as
    /// [`ShadowVolumes::build_reached`] finds it; `Some(false)`: none of
    /// it; `None`: not known). Errors as `from_volumes` does, or if
    /// `reached` has not one list per light.
    pub fn from_volumes_reached(
        lights: &[Light],
        volumes: Vec<ShadowVolumes>,
        reached: Vec<Vec<Option<bool>>>,
    ) -> Result<LightVolumes, ShadowError> {
        if reached.len() != lights.len() {
            return Err(ShadowError::Mismatch);
        }
        let mut v = LightVolumes::from_volumes(lights, volumes)?;
        v.reached = reached;
        Ok(v)
    }

    /// The trees as a [`ShadowSet`] for shading the occluders they were
    /// built over, in their order (the same polygons, whole or as
    /// [`crate::receivers`] groups them): a receiver the trees' building
    /// found lit or dark all over for a light is not filtered through
    /// that light's tree again. With other receivers it shades as
    /// [`LightVolumes::set`] does but for a list of another length (not
    /// checked beyond that: the caller's to keep).
    pub fn set_for_occluders(&self) -> ShadowSet<'_> {
        let mut set = self.set();
        set.reached = &self.reached;
        set
    }
}

impl ShadowSet<'_> {
    /// The convex cells of receiver polygon `poly` with their flags (bit
    /// `j`: lit by light `j`), as polygons: the cells [`ShadowSet::shade`]
    /// merges into fragments. `None` where a cell's vertices cannot be
    /// made from its planes.
    pub(crate) fn cells(
        &self,
        poly: &Polygon,
        scratch: &mut Scratch,
    ) -> Option<Vec<(Polygon, u64)>> {
        let start = Start::Uniform(self.facing(poly.support()));
        self.cells_from(poly, &start, u64::MAX, scratch)
    }

    /// [`ShadowSet::cells`] from `start`, filtered through the trees of
    /// the lights in `mask` only.
    fn cells_from(
        &self,
        poly: &Polygon,
        start: &Start<'_>,
        mask: u64,
        scratch: &mut Scratch,
    ) -> Option<Vec<(Polygon, u64)>> {
        self.filter_lights_of(std::slice::from_ref(poly), start, scratch, mask);
        let s = &*scratch;
        let cell = |(c, flags): &(crate::arena::pieces::Piece, u64)| {
            let edges: SmallVec<[Plane; 6]> = c.edges.iter().map(|&e| s.arena.plane(e)).collect();
            Some((
                Polygon::from_planes(*poly.support(), &edges, poly.tag())?,
                *flags,
            ))
        };
        // (a ground's many cells in parallel, in order)
        match s.cur.len() >= PARALLEL_CELLS {
            true => s.cur.par_iter().map(cell).collect(),
            false => s.cur.iter().map(cell).collect(),
        }
    }

    /// Whether this set knows the receivers of `polys` (what its trees'
    /// building found, for a list of that length).
    pub(super) fn knows(&self, polys: &[Polygon]) -> bool {
        !self.reached.is_empty() && self.reached.iter().all(|r| r.len() == polys.len())
    }

    /// [`ShadowSet::shade`] of the receiver `polys[range]`, taking from
    /// what the trees' building found each light that reaches all of it
    /// or none of it.
    pub(super) fn shade_known(
        &self,
        polys: &[Polygon],
        range: Range<usize>,
        receiver: u32,
        opts: &ShadeOptions,
        scratch: &mut Scratch,
        out: &mut Batch,
    ) {
        let Some(first) = polys.get(range.start) else {
            return;
        };
        let (flags, filter) = self.known_flags(first, range.clone());
        let polys = &polys[range];
        self.filter_lights_of(polys, &Start::Uniform(flags), scratch, filter);
        self.finish(polys, receiver, opts, scratch, out);
    }

    /// [`ShadowSet::cells`] of `poly`, which is occluder `index` of those
    /// the trees were built over, whole, where given and this set knows
    /// them ([`LightVolumes::set_for_occluders`] over `occluders`
    /// polygons): the same cells, filtered only through the trees of the
    /// lights that reach part of it.
    ///
    /// With `settle` (an area light's corner cells, where a cell that sees
    /// one corner and not another is penumbra whatever the others), such a
    /// cell goes through no more corners' trees, and its flags for those
    /// stay as they began (set where the light faces the receiver); the
    /// other cells are exactly those without, flags and all.
    pub(crate) fn cells_known(
        &self,
        poly: &Polygon,
        (index, occluders): (Option<usize>, usize),
        settle: bool,
        scratch: &mut Scratch,
    ) -> Option<Vec<(Polygon, u64)>> {
        scratch.settle_mixed = settle;
        let known = !self.reached.is_empty() && self.reached.iter().all(|r| r.len() == occluders);
        let cells = match index.filter(|_| known) {
            None => self.cells(poly, scratch),
            Some(i) => {
                let (flags, filter) = self.known_flags(poly, i..i + 1);
                self.cells_from(poly, &Start::Uniform(flags), filter, scratch)
            }
        };
        scratch.settle_mixed = false;
        cells
    }

    /// For a receiver of the polygons `range` (the first `first`): the
    /// flags of the lights facing it, less those its trees' building found
    /// reach none of it, and the lights to filter it through (those that
    /// reach part of it, or are not known).
    fn known_flags(&self, first: &Polygon, range: Range<usize>) -> (u64, u64) {
        let facing = self.facing(first.support());
        let (mut flags, mut filter) = (facing, 0u64);
        for (j, reached) in self.reached.iter().enumerate() {
            let bit = 1u64 << j;
            if facing & bit == 0 {
                continue;
            }
            let all = |lit: bool| range.clone().all(|i| reached[i] == Some(lit));
            if all(false) {
                flags &= !bit;
            } else if !all(true) {
                filter |= bit;
            }
        }
        (flags, filter)
    }
}
