//! Partitioned shadow volumes (Gerhards, Mora, Aveneau & Ghazanfarpour
//! 2015), exactly: one BSP tree per light over the shadow volumes of every
//! occluder.
//!
//! An occluder's volume is bounded by one plane through the light and
//! each of its edges (for a sun, parallel to the direction) and capped by
//! the occluder's own plane, oriented so that the light is in front: the
//! points behind the cap and inside every edge plane are exactly the
//! points the occluder hides. Because of the cap, volumes can be inserted
//! in any order and a receiver can be filtered through the finished tree
//! whatever its position: the lit region is the complement of the union
//! of the volumes, which the tree's leaves partition.
//!
//! An occluder descends the tree clipped to the region of each node it
//! reaches (its part on each side of a plane through the light; its part
//! in front of a cap, since everything it hides behind the cap is hidden
//! already), so it reaches exactly the leaves its volume meets. At a lit
//! leaf its volume is grafted: its cap, and those of its edge planes that
//! bound its clipped part there and that the path does not already
//! enforce (a neighbour's shared edge, a plane of the skeleton). The parts
//! of the volume outside the leaf's region are cut off by the region
//! itself.
//!
//! The tree is built in two phases. First a *skeleton*: planes through the
//! light, chosen top-down among the occluders' edge planes so that each
//! splits its occluders evenly and cuts few (sampled, like
//! [`bsp_core::BspTree::build`]), the occluders clipped along, until at
//! most about a hundred reach each leaf. Then below each leaf the occluders
//! that reach it are inserted nearest first, so that far ones mostly stop
//! at the caps of near ones. Inserting a whole scene nearest first from
//! the root would instead let the first occluders' planes run across
//! everything behind them and cut every later occluder: the balanced
//! skeleton keeps the tree near linear in the scene size. Below the first
//! few skeleton levels the subtrees are independent and built in
//! parallel; each is a function of its occluders alone, so the tree is
//! the same for every thread count.
//!
//! The skeleton is made of the occluders that face the light only. Those
//! turned away from it (the far side of an open scan, which no
//! certificate lets the engine leave out) are mostly hidden by the ones
//! that face it, so they are sent down the skeleton whole, by their grid
//! corners' sides, to every leaf they reach, and go in there in their
//! nearest-first turn: one hidden all over below the leaf by then is
//! passed over without being cut, the others are first cut to the leaf's
//! region as the skeleton would have cut them. Making the skeleton cut
//! them all cost an open 150k-face bust a third of its tree's time. The
//! price is paid where the faces turned away are not hidden (a terrain
//! with half its triangles flipped at random built its tree in 1.2 times
//! the time), so each region keeps count ([`late`]): once it has seen
//! that few of them are hidden, a leaf's are cut to it like the others
//! and the leaf split further as the skeleton would have split it; and
//! where they are most of the occluders (`occluders::LATE_PER_FRONT`) the skeleton
//! is made of all of them, as before.
//!
//! Every plane is an input-tier plane (an occluder's support plane, or the
//! plane through the light and two grid vertices), so occluders and
//! receivers are cut in the input tier: 256-bit vertices behind the `f64`
//! filter.

use std::borrow::Borrow;

use bsp_core::internals::SplitMix;
use bsp_core::{Plane, Polygon, SanityError, Side};
use rayon::prelude::*;
use smallvec::SmallVec;
use std::sync::atomic::Ordering;

use crate::arena::pieces::{EdgeRef, Piece, PieceArena, Sides, Vertex};
use crate::light::Light;

pub(crate) mod filter;
mod late;
mod occluders;
mod rests;
use late::{LateTally, merged, route_late};
use occluders::Occluders;
use rests::Rests;

/// A leaf: lit.
pub(crate) const LIT: u32 = u32::MAX;
/// A leaf: in shadow (behind a cap).
pub(crate) const SHADOW: u32 = u32::MAX - 1;

/// A node of a shadow-volume tree.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Node {
    pub(crate) plane: Plane,
    /// Child in front of the plane: a node index, [`LIT`] or [`SHADOW`].
    pub(crate) front: u32,
    /// Child behind the plane.
    pub(crate) back: u32,
    /// A cap (an occluder's plane, light in front; behind is shadow)
    /// rather than a plane through the light.
    pub(crate) cap: bool,
}

/// Why shadow volumes cannot be built.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum VolumeError {
    /// An occluder has a vertex that is not a grid point (a piece cut by
    /// another plane): shadow planes through it would leave the input tier.
    ImplicitOccluder {
        /// The occluder's index in the input.
        index: usize,
    },
}

impl std::fmt::Display for VolumeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            VolumeError::ImplicitOccluder { index } => write!(
                f,
                "occluder {index} has a vertex off the grid: occluders must be imported \
                 polygons, not pieces of a split"
            ),
        }
    }
}

impl std::error::Error for VolumeError {}

/// A plane on a path from the root, with its side and an
/// orientation-free key for quick comparison.
#[derive(Clone, Copy, Debug)]
struct Step {
    key: u64,
    plane: Plane,
    side: Side,
}

impl Step {
    fn new(plane: Plane, side: Side) -> Step {
        Step {
            key: plane_key(&plane),
            plane,
            side,
        }
    }
}

/// A hash of a plane that is the same for both orientations.
#[inline]
fn plane_key(p: &Plane) -> u64 {
    let n = p.normal();
    let first = n.iter().copied().find(|&c| c != 0).unwrap_or(0);
    let s: i64 = if first < 0 { -1 } else { 1 };
    let d = p.offset() * s as i128;
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for x in [
        (n[0] * s) as u64,
        (n[1] * s) as u64,
        (n[2] * s) as u64,
        d as u64,
        (d >> 64) as u64,
    ] {
        h = (h ^ x).wrapping_mul(0x0100_0000_01b3).rotate_left(29);
    }
    h
}

/// `true` if `path` already keeps its region behind `e`: the path went
/// behind `e`, or in front of `e` flipped.
fn enforced(path: &[Step], e: &Plane) -> bool {
    let key = plane_key(e);
    path.iter().any(|st| {
        st.key == key
            && ((st.side == Side::Back && st.plane == *e)
                || (st.side == Side::Front && st.plane == e.flip()))
    })
}

/// `true` if `e` (either orientation) is on `path`.
fn on_path(path: &[Step], e: &Plane) -> bool {
    let key = plane_key(e);
    path.iter()
        .any(|st| st.key == key && st.plane.is_coincident(e))
}

/// Occluders per skeleton leaf: lists longer than this are split further
/// when a balanced plane is found. (96 rather than 192: bunny-99k's one
/// light 0.95×, its area light 0.94×, bunny-11k's day with extremes
/// 0.91×, bunny-99k's day of mean hours 0.90×, paired on 2026-11-30; 64
/// no different from 96. An insertion walks the chains its leaf's
/// earlier occluders grafted, so a leaf's cost grows faster than its
/// size; the skeleton's cuts are what a smaller leaf pays.)
const LEAF_SIZE: usize = 96;
/// Occluders drawn per skeleton node, each offering its edge planes.
const CANDIDATES: usize = 4;
/// Occluders each candidate plane is scored on.
const SAMPLE: usize = 32;
/// Weight of an occluder straddling a candidate against one unit of
/// imbalance.
const STRADDLE_WEIGHT: u64 = 3;
/// Depth at which the skeleton stops splitting whatever the lists.
const MAX_SKELETON_DEPTH: usize = 48;
/// Skeleton subtrees made one after the other before the rest is built in
/// parallel.
const PARALLEL_TASKS: usize = 32;
/// Lists at least this long are classified in parallel while the first
/// skeleton levels are made.
const PARALLEL_LIST: usize = 8192;

/// An occluder's part in a region: the occluder, the part (a piece of the
/// pool), and where the occluder's edge planes start in the pool's arena
/// (its support plane follows them); or, with `piece` [`WHOLE`], the
/// occluder whole, not yet in the pool (the skeleton's first levels cut
/// few occluders, so only those are added to its pool, and the regions'
/// pools, filled in parallel, add the others from [`Occluders`]).
#[derive(Clone, Copy, Debug)]
struct Entry {
    occ: u32,
    piece: u32,
    base: u32,
}

/// [`Entry::piece`] of an occluder whole, not in the pool.
const WHOLE: u32 = u32::MAX;

impl Entry {
    /// Occluder `o` whole, not in any pool.
    fn whole(o: u32) -> Entry {
        Entry {
            occ: o,
            piece: WHOLE,
            base: WHOLE,
        }
    }
}

/// Pieces of occluders and their vertices and planes.
#[derive(Default)]
struct Pool {
    arena: PieceArena,
    pieces: Vec<Piece>,
}

impl Pool {
    /// Adds occluder `o` whole.
    fn add_occluder(&mut self, occ: &Occluders, o: u32) -> Entry {
        let base = self.arena.planes.len() as u32;
        let verts = occ.verts(o);
        let k = verts.len();
        let mut piece = Piece::default();
        for (j, (&v, e)) in verts.iter().zip(occ.edges(o).iter()).enumerate() {
            piece.verts.push(self.arena.add_grid(v));
            let plane = self.arena.add_edge_plane(*e, v, verts[(j + 1) % k]);
            piece.edges.push(EdgeRef::new(plane, false));
        }
        self.arena.add_plane(*occ.support(o));
        self.pieces.push(piece);
        Entry {
            occ: o,
            piece: (self.pieces.len() - 1) as u32,
            base,
        }
    }

    /// The sides of entry `e`'s part relative to `plane` (an occluder
    /// whole by its grid points).
    fn sides_shared(&self, occ: &Occluders, e: Entry, plane: &Plane) -> Sides {
        if e.piece == WHOLE {
            Sides::of_grid(occ.verts(e.occ), plane)
        } else {
            self.arena
                .sides_shared(&self.pieces[e.piece as usize], plane)
        }
    }

    /// [`Pool::sides_shared`], keeping what a lazy vertex computes.
    fn sides(&mut self, occ: &Occluders, e: Entry, plane: &Plane) -> Sides {
        if e.piece == WHOLE {
            Sides::of_grid(occ.verts(e.occ), plane)
        } else {
            self.arena.sides(&self.pieces[e.piece as usize], plane)
        }
    }

    /// [`Pool::sides`] from every vertex's side, written to `out`: a lazy
    /// vertex keeps the exact coordinates this computes, and its measures
    /// then use them, so a skeleton's scoring classifies every vertex
    /// (an occluder whole leaves `out` as it was: its grid points keep
    /// nothing).
    fn classify_into(
        &mut self,
        occ: &Occluders,
        e: Entry,
        plane: &Plane,
        out: &mut SmallVec<[Side; 8]>,
    ) -> Sides {
        if e.piece == WHOLE {
            Sides::of_grid(occ.verts(e.occ), plane)
        } else {
            self.arena
                .classify_into(&self.pieces[e.piece as usize], plane, out)
        }
    }

    /// Entry `e` in this pool: an occluder whole is added.
    fn own(&mut self, occ: &Occluders, e: Entry) -> Entry {
        if e.piece == WHOLE {
            self.add_occluder(occ, e.occ)
        } else {
            e
        }
    }

    /// Copies an entry of another pool: the occluder's planes, then the
    /// part's vertices and cut planes; an occluder whole is added.
    fn copy_entry(&mut self, from: &Pool, occ: &Occluders, e: Entry) -> Entry {
        if e.piece == WHOLE {
            return self.add_occluder(occ, e.occ);
        }
        let k = occ.corners(e.occ) as u32;
        let base = self.arena.planes.len() as u32;
        for i in 0..=k {
            let plane = from.arena.planes[(e.base + i) as usize];
            match from.arena.anchors(e.base + i) {
                Some([a, b]) => self.arena.add_edge_plane(plane, a, b),
                None => self.arena.add_plane(plane),
            };
        }
        let src = &from.pieces[e.piece as usize];
        let mut piece = Piece::default();
        for &v in &src.verts {
            piece.verts.push(self.arena.copy_vertex(&from.arena, v));
        }
        for &r in &src.edges {
            let gi = r.index();
            let local = if (e.base..e.base + k).contains(&gi) {
                base + gi - e.base
            } else {
                self.arena.add_plane(from.arena.planes[gi as usize])
            };
            piece.edges.push(EdgeRef::new(local, r.flipped()));
        }
        self.pieces.push(piece);
        Entry {
            occ: e.occ,
            piece: (self.pieces.len() - 1) as u32,
            base,
        }
    }
}

/// A region still to be partitioned: where it hangs, the planes above it,
/// and the occluders whose volumes reach it, nearest first.
struct Task {
    slot: Option<(u32, Side)>,
    path: Vec<Step>,
    list: Vec<Entry>,
}

/// Nodes with local indices (links to other nodes of the same list).
struct Subtree {
    nodes: Vec<Node>,
    grafted: usize,
}

impl Subtree {
    fn link(&self, slot: Option<(u32, Side)>, root: u32) -> u32 {
        match slot {
            None => root,
            Some((id, Side::Front)) => self.nodes[id as usize].front,
            Some((id, _)) => self.nodes[id as usize].back,
        }
    }

    fn set_link(&mut self, slot: Option<(u32, Side)>, root: &mut u32, to: u32) {
        match slot {
            None => *root = to,
            Some((id, Side::Front)) => self.nodes[id as usize].front = to,
            Some((id, _)) => self.nodes[id as usize].back = to,
        }
    }
}

/// Nodes the quick test of [`reach`] may visit before the exact descent
/// takes over.
pub(crate) const REACH_BUDGET: usize = 1024;

/// The kinds of leaves a piece may reach below `root`, found without
/// cutting it: at every node it goes to each side some vertex is on
/// (behind a cap counts as shadow). A superset of the leaves its points
/// reach, so one kind alone is the exact answer for all of it. `None` when
/// more than `budget` nodes would be visited.
///
/// `fork` is set to the first node with vertices strictly on both sides
/// of its plane (left at `root` where there is none): above it the piece
/// goes one way only, so an exact descent may start there. With `trail`,
/// the nodes passed one way before the fork and the side taken at each
/// are written there (up to a cap the piece lies in or is behind, where
/// an insertion does more than pass).
pub(crate) fn reach(
    nodes: &[Node],
    root: u32,
    mut sides: impl FnMut(&Plane) -> Sides,
    budget: usize,
    stack: &mut Vec<u32>,
    fork: &mut u32,
    mut trail: Option<&mut Vec<(u32, Side)>>,
) -> Option<(bool, bool)> {
    let (mut lit, mut shadow) = (false, false);
    let mut visits = 0;
    let (mut forked, mut trailed) = (false, false);
    *fork = root;
    stack.clear();
    stack.push(root);
    while let Some(mut link) = stack.pop() {
        loop {
            if link == LIT {
                lit = true;
                break;
            }
            if link == SHADOW {
                shadow = true;
                break;
            }
            visits += 1;
            if visits > budget {
                return None;
            }
            let n = &nodes[link as usize];
            let s = sides(&n.plane);
            if s.front && s.back && !forked {
                (*fork, forked) = (link, true);
            }
            if let Some(t) = trail.as_deref_mut()
                && !forked
                && !trailed
            {
                match (n.cap, s.front, s.back) {
                    (true, false, _) => trailed = true,
                    (_, true, true) => {}
                    (false, false, true) => t.push((link, Side::Back)),
                    _ => t.push((link, Side::Front)),
                }
            }
            match (n.cap, s.front, s.back) {
                // a cap: behind it is hidden, in it or in front is not
                (true, false, true) => {
                    shadow = true;
                    break;
                }
                (true, front, back) => {
                    shadow |= front && back;
                    link = n.front;
                }
                (false, true, true) => {
                    stack.push(n.back);
                    link = n.front;
                }
                (false, false, true) => link = n.back,
                (false, _, false) => link = n.front,
            }
        }
        if lit && shadow {
            break;
        }
    }
    Some((lit, shadow))
}

/// The partitioned shadow volumes of one light.
#[derive(Clone, Debug)]
pub struct ShadowVolumes {
    light: Light,
    pub(crate) nodes: Vec<Node>,
    pub(crate) root: u32,
    grafted: usize,
    skeleton: usize,
    occluders: usize,
}

impl ShadowVolumes {
    /// The shadow volumes of `occluders` (polygons with grid vertices,
    /// whichever way they face) for `light`. Occluders in a plane through
    /// the light hide no area and are left out. See the module docs for
    /// how the tree is built.
    ///
    /// `occluders` may be polygons or references to them.
    pub fn build<P: Borrow<Polygon> + Sync>(
        light: Light,
        occluders: &[P],
    ) -> Result<ShadowVolumes, VolumeError> {
        Ok(ShadowVolumes::build_until(light, occluders, None)?.expect("no stop"))
    }

    /// [`ShadowVolumes::build`], given up (`None`) once `stop` is raised.
    pub(crate) fn build_until<P: Borrow<Polygon> + Sync>(
        light: Light,
        occluders: &[P],
        stop: Option<&Stop>,
    ) -> Result<Option<ShadowVolumes>, VolumeError> {
        let built = ShadowVolumes::build_inner::<P, ()>(light, occluders, None, stop)?;
        Ok(built.map(|b| b.0))
    }

    /// [`ShadowVolumes::build`], and the area of each occluder that the
    /// light reaches, as its receiver would find it filtered through the
    /// finished tree ([`crate::ShadowSet`]): the area of its parts that
    /// are in front of no other occluder's volume, where it faces the
    /// light (0 for an occluder turned away or edge-on), in grid units
    /// squared, in the order of `occluders`.
    ///
    /// Found while the tree is built, without a second walk (each part
    /// the insertion brings to a lit leaf is lit by the volumes so far,
    /// and walks on when a later volume is grafted where it rests; see
    /// `psv/rests.rs`). Every decision is the filter's exact sign; the
    /// areas are measured in `f64` from the parts' corners (a cut corner
    /// within `2^-20` grid units), so they agree with the filter's
    /// fragments' areas to rounding.
    ///
    /// ```
    /// use svbsp::{Light, ShadowVolumes};
    /// let quad = |z: i32, lo: i32, hi: i32| {
    ///     bsp_core::Polygon::from_grid_points(&[[lo, lo, z], [hi, lo, z], [hi, hi, z], [lo, hi, z]], 0).unwrap()
    /// };
    /// // a 2 x 2 roof over a 4 x 4 floor, the sun straight above
    /// let (_, lit) = ShadowVolumes::build_lit(Light::Directional([0, 0, 1]), &[quad(10, 1, 3), quad(0, 0, 4)]).unwrap();
    /// assert_eq!(lit, vec![4.0, 12.0]);
    /// ```
    pub fn build_lit<P: Borrow<Polygon> + Sync>(
        light: Light,
        occluders: &[P],
    ) -> Result<(ShadowVolumes, Vec<f64>), VolumeError> {
        let (v, parts) = ShadowVolumes::build_inner(light, occluders, Some(&Rests::areas), None)?
            .expect("no stop");
        let mut lit = vec![0.0; occluders.len()];
        for (i, a) in parts {
            lit[i as usize] += a;
        }
        Ok((v, lit))
    }

    /// [`ShadowVolumes::build_lit`] with the lit parts themselves: each a
    /// convex polygon with exact corners (counter-clockwise seen from the
    /// light's side) and the index of its occluder in `occluders`. The
    /// parts of one occluder tile what of it the light reaches, but are
    /// not merged (see [`crate::ShadowSet`] for maximal fragments).
    pub fn lit_parts<P: Borrow<Polygon> + Sync>(
        light: Light,
        occluders: &[P],
    ) -> Result<(ShadowVolumes, LitParts), VolumeError> {
        let (v, parts) = ShadowVolumes::build_inner(light, occluders, Some(&Rests::parts), None)?
            .expect("no stop");
        Ok((v, parts.into_iter().map(|(i, p)| (i as usize, p)).collect()))
    }

    /// [`ShadowVolumes::build`], and per occluder that faces the light
    /// whether the light reaches all of it (`Some(true)`), none of it
    /// (`Some(false)`) or a part (`None`; also for an occluder turned away
    /// or edge-on), as its receiver would find it filtered through the
    /// finished tree, in the order of `occluders`: found as the tree is
    /// built ([`ShadowVolumes::build_lit`]), so that a receiver known lit
    /// or dark all over need not be filtered ([`crate::LightVolumes`]).
    pub fn build_reached<P: Borrow<Polygon> + Sync>(
        light: Light,
        occluders: &[P],
    ) -> Result<(ShadowVolumes, Vec<Option<bool>>), VolumeError> {
        Ok(ShadowVolumes::build_reached_until(light, occluders, None)?.expect("no stop"))
    }

    /// [`ShadowVolumes::build_reached`], given up (`None`) once `stop` is
    /// raised.
    fn build_reached_until<P: Borrow<Polygon> + Sync>(
        light: Light,
        occluders: &[P],
        stop: Option<&Stop>,
    ) -> Result<Option<Reached>, VolumeError> {
        let built = ShadowVolumes::build_inner(light, occluders, Some(&Rests::reached), stop)?;
        let Some((v, found)) = built else {
            return Ok(None);
        };
        // (an occluder the skeleton cut has parts in several regions)
        let mut reached: Vec<Option<Option<bool>>> = vec![None; occluders.len()];
        for (i, r) in found {
            let at = &mut reached[i as usize];
            *at = Some(match *at {
                None => r,
                Some(was) if was == r => r,
                Some(_) => None,
            });
        }
        Ok(Some((
            v,
            reached.into_iter().map(Option::flatten).collect(),
        )))
    }

    /// [`ShadowVolumes::build_reached`] of the polygons `index` picks from
    /// `polys` (in that order), what it found given per polygon of
    /// `polys` (`None` for those not picked).
    pub fn build_reached_among(
        light: Light,
        polys: &[Polygon],
        index: &[usize],
    ) -> Result<(ShadowVolumes, Vec<Option<bool>>), VolumeError> {
        let built = ShadowVolumes::build_reached_among_until(light, polys, index, None)?;
        Ok(built.expect("no stop"))
    }

    /// [`ShadowVolumes::build_reached_among`], given up (`None`) once
    /// `stop` is raised.
    pub(crate) fn build_reached_among_until(
        light: Light,
        polys: &[Polygon],
        index: &[usize],
        stop: Option<&Stop>,
    ) -> Result<Option<Reached>, VolumeError> {
        let picked: Vec<&Polygon> = index.iter().map(|&i| &polys[i]).collect();
        let Some((v, found)) = ShadowVolumes::build_reached_until(light, &picked, stop)? else {
            return Ok(None);
        };
        let mut reached = vec![None; polys.len()];
        for (&i, r) in index.iter().zip(found) {
            reached[i] = r;
        }
        Ok(Some((v, reached)))
    }

    /// [`ShadowVolumes::build`], and with `record` what it makes of each
    /// region's lit parts, with their occluders' input indices (those
    /// facing the light only), region by region in order.
    fn build_inner<P: Borrow<Polygon> + Sync, T: Send>(
        light: Light,
        occluders: &[P],
        record: Option<&Record<T>>,
        stop: Option<&Stop>,
    ) -> Result<Option<Built<T>>, VolumeError> {
        let stopped = || stop.is_some_and(|s| s.load(Ordering::Relaxed));
        let occ = Occluders::new(&light, occluders)?;
        let mut pool = Pool::default();
        // the skeleton is made of the occluders that face the light; those
        // turned away are sent down it whole and go into its leaves in
        // their turn ([`route_late`])
        // (unless those turned away are most of them: then they are what
        // hides, and the skeleton cuts them all, as it cuts the others)
        let (list, late): (Vec<u32>, Vec<u32>) =
            (0..occ.len() as u32).partition(|&o| occ.faces[o as usize] || !occ.defer);
        let list: Vec<Entry> = list.into_iter().map(Entry::whole).collect();
        // the first levels one after the other, on one pool
        let mut top = Subtree {
            nodes: Vec::new(),
            grafted: 0,
        };
        let mut root = LIT;
        let mut rng = SplitMix(0x5eed_5a0d);
        let mut sides = SmallVec::new();
        // breadth first, so that the regions left for the parallel phase
        // are of similar sizes
        let mut ready: Vec<Task> = Vec::new();
        let mut queue = std::collections::VecDeque::from([Task {
            slot: None,
            path: Vec::new(),
            list,
        }]);
        while let Some(task) = queue.pop_front() {
            if stopped() {
                return Ok(None);
            }
            if queue.len() + ready.len() + 1 >= PARALLEL_TASKS {
                ready.push(task);
                continue;
            }
            match split_task(
                &occ, &mut pool, task, &mut rng, &mut sides, &mut top, &mut root,
            ) {
                Ok((front, back)) => {
                    queue.push_back(front);
                    queue.push_back(back);
                }
                Err(task) => ready.push(task),
            }
        }
        let skeleton_top = top.nodes.len();
        let late = route_late(&occ, &top.nodes, root, &ready, &late);
        // each pending region on its own pool, in parallel
        // the regions' sizes vary several times over (the open 150k bust:
        // 300 to 7,500 occluders): the largest start first, so that no
        // large one is left for the end on one thread
        let sizes: Vec<u64> = (ready.iter().zip(&late))
            .map(|(task, late)| (task.list.len() + late.len()) as u64)
            .collect();
        let parts: Vec<Region<T>> = bsp_core::par::map_largest_first(&sizes, |i| {
            let (task, late) = (&ready[i], &late[i]);
            let mut own = Pool::default();
            let list = task
                .list
                .iter()
                .map(|&e| own.copy_entry(&pool, &occ, e))
                .collect();
            let local = Task {
                slot: None,
                path: task.path.clone(),
                list,
            };
            let seed = 0x5eed_5a0d ^ (i as u64 + 1);
            build_region(&occ, &mut own, local, late, seed, record, stop)
        });
        drop(pool);
        if stopped() {
            return Ok(None);
        }
        // region by region in order: the same for every thread count
        let mut lit = Vec::new();
        let mut grafted = top.grafted;
        let mut skeleton = skeleton_top;
        let mut starts = vec![0, top.nodes.len()];
        let mut subs = vec![top.nodes];
        let mut roots = Vec::with_capacity(parts.len());
        for (sub, sub_root, sub_skeleton, found) in parts {
            for (o, a) in found {
                // (turned away: a receiver in attached shadow)
                if occ.cap(o) == occ.support(o) {
                    lit.push((occ.index[o as usize], a));
                }
            }
            let off = *starts.last().expect("the skeleton's top first");
            roots.push(shift(sub_root, off as u32));
            starts.push(off + sub.nodes.len());
            subs.push(sub.nodes);
            grafted += sub.grafted;
            skeleton += sub_skeleton;
        }
        let mut nodes = joined(&subs, &starts);
        drop(subs);
        for (task, r) in ready.iter().zip(roots) {
            match task.slot {
                None => root = r,
                Some((id, Side::Front)) => nodes[id as usize].front = r,
                Some((id, _)) => nodes[id as usize].back = r,
            }
        }
        let volumes = ShadowVolumes {
            light,
            nodes,
            root,
            grafted,
            skeleton,
            occluders: occ.len(),
        };
        Ok(Some((volumes, lit)))
    }

    /// The number of occluders the volumes were built from (those given,
    /// less those in a plane through the light).
    pub fn occluder_count(&self) -> usize {
        self.occluders
    }

    /// Whether the occluders hide the light from grid point `x`: `x` lies
    /// strictly inside a shadow volume (a point on a volume's boundary,
    /// e.g. on an occluder's own face or on a shadow's edge, is reached).
    /// The tree is walked without recursion.
    pub fn hides(&self, x: bsp_core::GridPoint) -> bool {
        let mut todo = vec![self.root];
        while let Some(link) = todo.pop() {
            match link {
                LIT => return false,
                SHADOW => continue,
                n => {
                    let node = &self.nodes[n as usize];
                    match node.plane.classify_grid(x) {
                        Side::Front => todo.push(node.front),
                        Side::Back => todo.push(node.back),
                        // on a plane: hidden only if both sides are
                        Side::On => todo.extend([node.front, node.back]),
                    }
                }
            }
        }
        true
    }

    /// The light.
    pub fn light(&self) -> Light {
        self.light
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Number of nodes of the skeleton (planes through the light chosen
    /// for balance, above the volumes).
    pub fn skeleton_count(&self) -> usize {
        self.skeleton
    }

    /// Number of volumes grafted (an occluder spanning several leaves
    /// counts once per leaf).
    pub fn grafted(&self) -> usize {
        self.grafted
    }

    /// Longest root-to-leaf path, in nodes.
    pub fn depth(&self) -> usize {
        let mut best = 0;
        let mut stack = vec![(self.root, 0usize)];
        while let Some((link, d)) = stack.pop() {
            if link >= SHADOW {
                best = best.max(d);
                continue;
            }
            let n = &self.nodes[link as usize];
            stack.push((n.front, d + 1));
            stack.push((n.back, d + 1));
        }
        best
    }

    /// Checks the tree exactly: every link is a node or a leaf, each node
    /// reached once, every plane through the light passes through it and
    /// every cap has it strictly in front with nothing behind.
    pub fn sanity_check(&self) -> Result<(), VolumeSanity> {
        let mut seen = vec![false; self.nodes.len()];
        let mut stack = vec![self.root];
        while let Some(link) = stack.pop() {
            if link >= SHADOW {
                continue;
            }
            let Some(n) = self.nodes.get(link as usize) else {
                return Err(VolumeSanity::Tree(SanityError::MissingNode { node: link }));
            };
            if std::mem::replace(&mut seen[link as usize], true) {
                return Err(VolumeSanity::Tree(SanityError::NodeReachedTwice {
                    node: link,
                }));
            }
            let at = self.light.eval(&n.plane);
            if n.cap && at <= 0 {
                return Err(VolumeSanity::CapMissesLight { node: link });
            }
            if !n.cap && at != 0 {
                return Err(VolumeSanity::PlaneMissesLight { node: link });
            }
            if n.cap && n.back != SHADOW {
                return Err(VolumeSanity::SomethingBehindCap { node: link });
            }
            stack.push(n.front);
            stack.push(n.back);
        }
        match seen.iter().position(|s| !s) {
            Some(i) => Err(VolumeSanity::Tree(SanityError::Unreachable {
                node: i as u32,
            })),
            None => Ok(()),
        }
    }
}

/// Which invariant a shadow-volume tree breaks
/// ([`ShadowVolumes::sanity_check`]).
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum VolumeSanity {
    /// The links do not form a tree over the nodes (a missing node, one
    /// reached twice or one unreachable).
    Tree(SanityError),
    /// A cap does not have the light strictly in front.
    CapMissesLight {
        /// The node.
        node: u32,
    },
    /// A shadow plane does not pass through the light.
    PlaneMissesLight {
        /// The node.
        node: u32,
    },
    /// A cap's back is not a shadow leaf.
    SomethingBehindCap {
        /// The node.
        node: u32,
    },
}

impl std::fmt::Display for VolumeSanity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            VolumeSanity::Tree(e) => e.fmt(f),
            VolumeSanity::CapMissesLight { node } => {
                write!(f, "cap {node} does not have the light strictly in front")
            }
            VolumeSanity::PlaneMissesLight { node } => {
                write!(f, "shadow plane {node} misses the light")
            }
            VolumeSanity::SomethingBehindCap { node } => {
                write!(f, "cap {node} has something behind it")
            }
        }
    }
}

impl std::error::Error for VolumeSanity {}

/// Splits `task` by a balanced plane through the light (a new node of
/// `tree` at the task's slot), clipping its occluders' parts: the front and
/// back tasks; or the task back if it is small enough or no plane splits it.
#[allow(clippy::too_many_arguments)]
fn split_task(
    occ: &Occluders,
    pool: &mut Pool,
    task: Task,
    rng: &mut SplitMix,
    sides: &mut SmallVec<[Side; 8]>,
    tree: &mut Subtree,
    root: &mut u32,
) -> Result<(Task, Task), Task> {
    if task.list.len() <= LEAF_SIZE || task.path.len() >= MAX_SKELETON_DEPTH {
        return Err(task);
    }
    let Some(plane) = choose_split(occ, pool, &task, rng, sides) else {
        return Err(task);
    };
    // the sides of every part, in parallel for long lists
    let reached: Vec<Sides> = if task.list.len() >= PARALLEL_LIST {
        let pool = &*pool;
        task.list
            .par_iter()
            .map(|&e| pool.sides_shared(occ, e, &plane))
            .collect()
    } else {
        task.list
            .iter()
            .map(|&e| pool.sides(occ, e, &plane))
            .collect()
    };
    let cut = pool.arena.add_plane(plane);
    let (mut front, mut back) = (Vec::new(), Vec::new());
    for (e, sd) in task.list.into_iter().zip(reached) {
        match (sd.front, sd.back) {
            (false, true) => back.push(e),
            (true, true) => {
                let e = pool.own(occ, e);
                pool.arena
                    .classify_into(&pool.pieces[e.piece as usize], &plane, sides);
                let sup = e.base + occ.corners(e.occ) as u32;
                let (f, b) = pool
                    .arena
                    .split(sup, &pool.pieces[e.piece as usize], cut, sides);
                pool.pieces.push(f);
                front.push(Entry {
                    piece: (pool.pieces.len() - 1) as u32,
                    ..e
                });
                pool.pieces.push(b);
                back.push(Entry {
                    piece: (pool.pieces.len() - 1) as u32,
                    ..e
                });
            }
            // an occluder part in a plane through the light is edge-on:
            // it cannot happen, and would hide nothing
            _ => front.push(e),
        }
    }
    let id = tree.nodes.len() as u32;
    tree.nodes.push(Node {
        plane,
        front: LIT,
        back: LIT,
        cap: false,
    });
    tree.set_link(task.slot, root, id);
    let child = |side: Side, list: Vec<Entry>| {
        let mut path = task.path.clone();
        path.push(Step::new(plane, side));
        Task {
            slot: Some((id, side)),
            path,
            list,
        }
    };
    Ok((child(Side::Front, front), child(Side::Back, back)))
}

/// Link `l` of a subtree whose nodes start at `off` in the whole tree.
#[inline]
fn shift(l: u32, off: u32) -> u32 {
    if l >= SHADOW { l } else { l + off }
}

/// The subtrees' nodes one after the other, each subtree's links shifted
/// to where it starts (`starts[i]`, and the end last), each node written
/// by its thread in its place (`bsp_core::par::map_placed`: the copy was
/// one thread's work at the end of every build, with the other core
/// idle).
fn joined(subs: &[Vec<Node>], starts: &[usize]) -> Vec<Node> {
    let total = *starts.last().expect("an end");
    bsp_core::par::map_placed(total, |i| {
        // the last subtree starting at or before node `i`
        let k = starts.partition_point(|&s| s <= i) - 1;
        let off = starts[k];
        let mut n = subs[k][i - off];
        n.front = shift(n.front, off as u32);
        n.back = shift(n.back, off as u32);
        n
    })
}

/// Lit parts of occluders: each a convex polygon's exact corners, with its
/// occluder's index ([`ShadowVolumes::lit_parts`]).
pub type LitParts = Vec<(usize, Vec<Vertex>)>;

/// A flag another thread raises to give up a build whose tree is no
/// longer wanted.
pub(crate) type Stop = std::sync::atomic::AtomicBool;

/// What a build makes: the tree, and what its `record` made of the lit
/// parts, with their occluders.
type Built<T> = (ShadowVolumes, Vec<(u32, T)>);

/// A tree, and per occluder whether the light reaches all of it
/// (`Some(true)`), none (`Some(false)`) or part ([`ShadowVolumes::build_reached`]).
pub(crate) type Reached = (ShadowVolumes, Vec<Option<bool>>);

/// What [`build_region`] makes: the nodes, the root link, the number of
/// skeleton nodes, and what its `record` makes of the lit parts, with
/// their occluders.
type Region<T> = (Subtree, u32, usize, Vec<(u32, T)>);

/// What a build makes of a region's lit parts: [`Rests::areas`],
/// [`Rests::parts`] or [`Rests::reached`].
type Record<T> = dyn Fn(Rests, &PieceArena) -> Vec<(u32, T)> + Sync;

/// The whole tree below one region, on its own pool: the rest of the
/// skeleton, then each leaf's occluders inserted nearest first, with
/// those of `late` (turned away from the light, not in the skeleton) that
/// reach the leaf whole among them; with `record`, the lit parts of the
/// occluders too (see [`rests`]).
fn build_region<T>(
    occ: &Occluders,
    pool: &mut Pool,
    task: Task,
    late: &[u32],
    seed: u64,
    record: Option<&Record<T>>,
    stop: Option<&Stop>,
) -> Region<T> {
    let mut tree = Subtree {
        nodes: Vec::new(),
        grafted: 0,
    };
    let mut root = LIT;
    let mut rng = SplitMix(seed);
    let mut sides = SmallVec::new();
    let (leaves, mut skeleton) =
        split_down(occ, pool, task, &mut rng, &mut sides, &mut tree, &mut root);
    let entries: usize = leaves.iter().map(|l| l.list.len()).sum();
    tree.nodes.reserve(entries * 3);
    let mut scratch = InsertScratch::default();
    let mut rests = record.map(|_| Rests::default());
    let late = route_late(occ, &tree.nodes, root, &leaves, late);
    // the leaves in order, each with the late occluders that reach it
    let mut todo: Vec<(Task, Vec<u32>)> = leaves.into_iter().zip(late).collect();
    todo.reverse();
    let mut tally = LateTally::default();
    while let Some((leaf, late)) = todo.pop() {
        // (a stopped build's regions are thrown away whole)
        if stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
            break;
        }
        if !late.is_empty() && tally.cut() {
            // mostly not hidden in this region: cut like the others, the
            // leaf split as the skeleton splits
            let cut: Vec<Entry> = (late.iter())
                .filter_map(|&o| clip_to(occ, pool, o, &leaf.path, &mut sides))
                .collect();
            let list = merged(&leaf.list, &cut);
            let task = Task { list, ..leaf };
            let (done, splits) =
                split_down(occ, pool, task, &mut rng, &mut sides, &mut tree, &mut root);
            skeleton += splits;
            todo.extend(done.into_iter().rev().map(|t| (t, Vec::new())));
            continue;
        }
        let leaf = &leaf;
        // the leaf's parts and the late occluders, nearest first
        let mut late = late.into_iter().peekable();
        let mut next = leaf.list.iter().peekable();
        loop {
            let e = match (next.peek(), late.peek()) {
                (Some(e), Some(&o)) if o < e.occ => late.next().map(Err),
                (Some(_), _) => next.next().map(|&e| Ok(e)),
                (None, _) => late.next().map(Err),
            };
            let e = match e {
                None => break,
                Some(Ok(e)) => e,
                Some(Err(o)) => {
                    let start = tree.link(leaf.slot, root);
                    let sides = |p: &Plane| Sides::of_grid(occ.verts(o), p);
                    let hidden = reach(
                        &tree.nodes,
                        start,
                        sides,
                        REACH_BUDGET,
                        &mut scratch.links,
                        &mut 0,
                        None,
                    );
                    tally.count(matches!(hidden, Some((false, _))));
                    let clipped = match hidden {
                        Some((false, _)) => None,
                        _ => clip_to(occ, pool, o, &leaf.path, &mut scratch.sides),
                    };
                    match clipped {
                        Some(e) => e,
                        None => {
                            if let Some(r) = rests.as_mut() {
                                r.dark(o);
                            }
                            continue;
                        }
                    }
                }
            };
            let r = rests.as_mut();
            insert(&mut tree, &mut root, occ, pool, e, leaf, &mut scratch, r);
        }
    }
    let found = match (rests, record) {
        (Some(r), Some(make)) => make(r, &pool.arena),
        _ => Vec::new(),
    };
    (tree, root, skeleton, found)
}

/// `task` split as the skeleton splits ([`split_task`]) down to its
/// leaves, front first, the nodes added to `tree`; and how many splits
/// that took.
fn split_down(
    occ: &Occluders,
    pool: &mut Pool,
    task: Task,
    rng: &mut SplitMix,
    sides: &mut SmallVec<[Side; 8]>,
    tree: &mut Subtree,
    root: &mut u32,
) -> (Vec<Task>, usize) {
    let (mut leaves, mut splits) = (Vec::new(), 0);
    let mut stack = vec![task];
    while let Some(task) = stack.pop() {
        match split_task(occ, pool, task, rng, sides, tree, root) {
            Ok((front, back)) => {
                splits += 1;
                stack.push(back);
                stack.push(front);
            }
            Err(task) => leaves.push(task),
        }
    }
    (leaves, splits)
}

/// Occluder `o` added whole to the pool and cut to the region of `path`
/// (the sides of its planes the steps name), as the skeleton would have
/// cut it; `None` where nothing of it is left.
fn clip_to(
    occ: &Occluders,
    pool: &mut Pool,
    o: u32,
    path: &[Step],
    sides: &mut SmallVec<[Side; 8]>,
) -> Option<Entry> {
    let mut e = pool.add_occluder(occ, o);
    let sup = e.base + occ.corners(o) as u32;
    for step in path {
        let piece = &pool.pieces[e.piece as usize];
        let sd = pool.arena.classify_into(piece, &step.plane, sides);
        match (sd.front, sd.back, step.side) {
            (true, true, side) => {
                let cut = pool.arena.add_plane(step.plane);
                let (f, b) = pool.arena.split(sup, piece, cut, sides);
                pool.pieces.push(if side == Side::Front { f } else { b });
                e.piece = (pool.pieces.len() - 1) as u32;
            }
            (false, true, Side::Front) | (true, false, Side::Back) => return None,
            _ => {}
        }
    }
    Some(e)
}

/// A plane through the light among the edge planes of a few occluders of
/// `task`, splitting a sample of its occluders most evenly with the
/// fewest straddling; `None` if none leaves occluders wholly on each side.
fn choose_split(
    occ: &Occluders,
    pool: &mut Pool,
    task: &Task,
    rng: &mut SplitMix,
    sides: &mut SmallVec<[Side; 8]>,
) -> Option<Plane> {
    let n = task.list.len();
    let sample: SmallVec<[usize; SAMPLE]> = if n <= SAMPLE {
        (0..n).collect()
    } else {
        (0..SAMPLE).map(|_| rng.below(n)).collect()
    };
    let mut best: Option<(u64, Plane)> = None;
    for _ in 0..CANDIDATES {
        let o = task.list[rng.below(n)].occ;
        for e in occ.edges(o).iter() {
            if on_path(&task.path, e) {
                continue;
            }
            let (mut f, mut b, mut both) = (0u64, 0u64, 0u64);
            for &i in &sample {
                let sd = pool.classify_into(occ, task.list[i], e, sides);
                match (sd.front, sd.back) {
                    (true, true) => both += 1,
                    (true, false) => f += 1,
                    (false, true) => b += 1,
                    (false, false) => {}
                }
            }
            if f == 0 || b == 0 {
                continue;
            }
            let score = STRADDLE_WEIGHT * both + f.abs_diff(b);
            if best.is_none_or(|(s, _)| score < s) {
                best = Some((score, *e));
            }
        }
    }
    best.map(|(_, p)| p)
}

/// Where a piece goes next: the piece, the link it reaches, the depth of
/// its path, the slot it came through, and whether it goes on as a
/// receiver only (see [`rests`]).
type Visit = (Piece, u32, usize, Option<(u32, Side)>, bool);

/// Work space of [`insert`].
#[derive(Default)]
struct InsertScratch {
    stack: Vec<Visit>,
    links: Vec<u32>,
    /// The nodes [`reach`] saw a piece pass one way, and its sides there.
    trail: Vec<(u32, Side)>,
    path: Vec<Step>,
    sides: SmallVec<[Side; 8]>,
}

/// Inserts entry `e` (an occluder clipped to the region of `leaf`) below
/// the leaf: it descends to the lit leaves its volume meets. The pieces it
/// is cut into live in the pool's arena until it is grafted, then the
/// arena is rolled back. With `rests`, its parts that reach lit leaves are
/// kept there as lit (and the arena kept while they are; see [`rests`]).
#[allow(clippy::too_many_arguments)]
fn insert(
    tree: &mut Subtree,
    root: &mut u32,
    occ: &Occluders,
    pool: &mut Pool,
    e: Entry,
    leaf: &Task,
    s: &mut InsertScratch,
    mut rests: Option<&mut Rests>,
) {
    let start_link = tree.link(leaf.slot, *root);
    let piece = pool.pieces[e.piece as usize].clone();
    // an occluder hidden all over below the leaf adds nothing: found
    // without cutting it
    s.trail.clear();
    if let Some((false, _)) = reach(
        &tree.nodes,
        start_link,
        |p| pool.arena.sides(&piece, p),
        REACH_BUDGET,
        &mut s.links,
        &mut 0,
        Some(&mut s.trail),
    ) {
        if let Some(r) = rests {
            r.dark(e.occ);
        }
        return;
    }
    let mark = pool.arena.mark();
    let k = occ.corners(e.occ) as u32;
    let sup = e.base + k;
    s.stack.clear();
    s.path.clear();
    s.path.extend_from_slice(&leaf.path);
    // the walk starts below the nodes the quick test saw it pass one way
    let (mut link, mut edge) = (start_link, leaf.slot);
    for &(id, side) in &s.trail {
        let n = &tree.nodes[id as usize];
        s.path.push(Step::new(n.plane, side));
        edge = Some((id, side));
        link = if side == Side::Front { n.front } else { n.back };
    }
    s.stack.push((piece, link, s.path.len(), edge, false));
    let arena = &mut pool.arena;
    let changes = rests.as_ref().map(|r| r.changes);
    let mut first = true;
    while let Some((mut p, mut link, depth, mut edge, receiver)) = s.stack.pop() {
        s.path.truncate(depth);
        if !first && let Some((id, side)) = edge {
            s.path.push(Step::new(tree.nodes[id as usize].plane, side));
        }
        first = false;
        loop {
            if link == SHADOW {
                if let Some(r) = rests.as_deref_mut() {
                    r.dark(e.occ);
                }
                break;
            }
            if link == LIT {
                // (the part rests where its own volume leaves it: behind
                // its edge planes, in its cap's plane, so in front of the
                // cap; what rested at the leaf walks on into the volume)
                let mut at = edge;
                if !receiver {
                    let cap = graft(tree, root, occ, e, &p, edge, &s.path);
                    if let Some(r) = rests.as_deref_mut() {
                        r.settle(tree, *root, edge, arena, &mut s.sides);
                    }
                    at = Some((cap, Side::Front));
                }
                if let Some(r) = rests.as_deref_mut() {
                    let new = arena.uses_since(&p, mark);
                    r.rest(at, p, e.occ, sup, new);
                }
                break;
            }
            let n = tree.nodes[link as usize];
            // every vertex's side, kept for a split (classified once)
            let sd = arena.classify_into(&p, &n.plane, &mut s.sides);
            let next = match (n.cap, sd.front, sd.back) {
                // in a cap's plane: its volume is hidden already, but as a
                // receiver the part is not
                (true, false, false) if rests.is_some() => {
                    let slot = Some((link, Side::Front));
                    s.stack.push((p, n.front, s.path.len(), slot, true));
                    break;
                }
                // behind a cap (or in its plane): hidden already
                (true, false, _) => {
                    if let Some(r) = rests.as_deref_mut() {
                        r.dark(e.occ);
                    }
                    break;
                }
                (true, true, false) | (false, true, false) | (false, false, false) => Side::Front,
                (false, false, true) => Side::Back,
                (true, true, true) => {
                    let cut = arena.add_plane(n.plane);
                    p = arena.split(sup, &p, cut, &s.sides).0;
                    if let Some(r) = rests.as_deref_mut() {
                        r.dark(e.occ);
                    }
                    Side::Front
                }
                (false, true, true) => {
                    let cut = arena.add_plane(n.plane);
                    let (f, b) = arena.split(sup, &p, cut, &s.sides);
                    s.stack
                        .push((b, n.back, s.path.len(), Some((link, Side::Back)), receiver));
                    p = f;
                    Side::Front
                }
            };
            s.path.push(Step::new(n.plane, next));
            edge = Some((link, next));
            link = if next == Side::Front { n.front } else { n.back };
        }
    }
    // (pieces at rest keep what they were cut from)
    if rests.map(|r| r.changes) == changes {
        arena.rollback(mark);
    }
}

/// Replaces the lit leaf below `slot` by the volume of `entry`'s
/// occluder, where `part` is what of it reaches the leaf: the occluder's
/// edge planes that bound `part` and that the path does not already
/// enforce, then the cap. Returns the cap's node.
fn graft(
    tree: &mut Subtree,
    root: &mut u32,
    occ: &Occluders,
    entry: Entry,
    part: &Piece,
    slot: Option<(u32, Side)>,
    path: &[Step],
) -> u32 {
    let o = entry.occ;
    let mut keep: SmallVec<[Plane; 4]> = SmallVec::new();
    for (i, e) in occ.edges(o).iter().enumerate() {
        let plane = entry.base + i as u32;
        let bounds = part.edges.iter().any(|r| r.index() == plane);
        if bounds && !enforced(path, e) {
            keep.push(*e);
        }
    }
    let first = tree.nodes.len() as u32;
    for (i, e) in keep.iter().enumerate() {
        tree.nodes.push(Node {
            plane: *e,
            front: LIT,
            back: first + i as u32 + 1,
            cap: false,
        });
    }
    tree.nodes.push(Node {
        plane: *occ.cap(o),
        front: LIT,
        back: SHADOW,
        cap: true,
    });
    tree.grafted += 1;
    tree.set_link(slot, root, first);
    first + keep.len() as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad(z: i32, lo: i32, hi: i32) -> Polygon {
        Polygon::from_grid_points(&[[lo, lo, z], [hi, lo, z], [hi, hi, z], [lo, hi, z]], 0).unwrap()
    }

    #[test]
    fn volumes_are_sane_and_share_edges() {
        // a 4 x 4 field of unit squares at height 4, light above: a shared
        // edge's plane is not added again below its neighbour's
        let mut polys = Vec::new();
        for i in 0..4 {
            for j in 0..4 {
                polys.push(
                    Polygon::from_grid_points(
                        &[[i, j, 4], [i + 1, j, 4], [i + 1, j + 1, 4], [i, j + 1, 4]],
                        0,
                    )
                    .unwrap(),
                );
            }
        }
        for light in [Light::Point([2, 2, 9]), Light::Directional([1, 1, 5])] {
            let sv = ShadowVolumes::build(light, &polys).unwrap();
            sv.sanity_check().unwrap();
            assert_eq!(sv.grafted(), 16);
            assert!(sv.node_count() < 16 * 5, "{}", sv.node_count());
            // with a ground below, which the squares partly hide
            let mut more = polys.clone();
            more.push(quad(0, -10, 10));
            let sv = ShadowVolumes::build(light, &more).unwrap();
            sv.sanity_check().unwrap();
            assert!(sv.grafted() > 16);
        }
    }

    #[test]
    fn implicit_occluders_are_rejected() {
        let mut q = quad(0, 0, 4);
        assert!(q.clip(&Plane::new([1, 0, 0], -1).unwrap(), Side::Back));
        let e = ShadowVolumes::build(Light::Point([0, 0, 9]), &[q]).unwrap_err();
        assert_eq!(e, VolumeError::ImplicitOccluder { index: 0 });
    }
}
