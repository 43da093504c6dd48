//! Polygons of one plane meshed as one region: pieces of a face that a
//! Boolean cut at the walls of its cells, where the kept part bends and
//! the pieces could not be put back together as one convex polygon.
//! Triangulated one by one they keep every point where a wall crossed
//! them, and a closed mesh has two triangles for every vertex.
//!
//! Adjacent polygons of one support plane, each with a corner made by
//! cutting (an implicit point), whose edges meet whole, are joined
//! where the joined region's boundary is one loop and its inner corners
//! are its own. Corners where the loop runs straight on (the edge planes
//! before and after are the same plane) are dropped, unless another
//! polygon still has them, and then they come back as points on the edge,
//! as every such point does. A region with no reflex corner is clipped as
//! a convex polygon is; one with reflex corners is fanned from the first
//! that sees the whole region (strictly inside every edge but its own
//! two: with a single reflex corner the region is two convex parts that
//! both have it as a corner); one with none such keeps its polygons.
//! Every decision is an exact side of a point, or exact equality.

use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

use rayon::prelude::*;
use smallvec::{SmallVec, smallvec};

use crate::kernel::Side;
use crate::kernel::plane::Plane;
use crate::kernel::point::Point;
use crate::kernel::polygon::ConvexFace;
use crate::union_find::UnionFind;

/// The regions found: which polygons a region's triangles replace, and
/// each region's triangles under its first polygon.
pub(super) struct FlatRegions {
    pub(super) replaced: Vec<bool>,
    pub(super) triangles: HashMap<u32, Vec<[u32; 3]>>,
}

/// What a triangulation reads of the welded polygons.
pub(super) struct Welded<'a> {
    pub(super) vertices: &'a [Point],
    /// Polygon `i`'s corners are `corners[start[i]..start[i + 1]]`.
    pub(super) corners: &'a [u32],
    pub(super) start: &'a [usize],
    /// Each polygon's welded points inside its edges, in order along
    /// each: (edge, point).
    pub(super) inside: &'a [Vec<(u32, u32)>],
}

impl Welded<'_> {
    fn of(&self, p: usize) -> &[u32] {
        &self.corners[self.start[p]..self.start[p + 1]]
    }
}

/// The regions of `polys` (see the module docs).
pub(super) fn flat_regions<P: ConvexFace + Sync>(polys: &[P], w: &Welded<'_>) -> FlatRegions {
    let n = polys.len();
    let mut out = FlatRegions {
        replaced: vec![false; n],
        triangles: HashMap::default(),
    };
    let made: Vec<usize> = (0..n)
        .into_par_iter()
        .filter(|&p| {
            (w.of(p).iter()).any(|&v| matches!(w.vertices[v as usize], Point::Implicit(_)))
        })
        .collect();
    if made.len() < 2 {
        return out;
    }
    // their loops with the points on their edges (other polygons'
    // corners: where cells of different sizes meet, a piece's edge holds
    // its neighbours' corners), each point with the edge it is on
    let rings: HashMap<u32, Vec<(u32, u32)>> = made
        .par_iter()
        .map(|&p| (p as u32, ring_of(p, w)))
        .collect();
    // their directed sub-edges; one used twice the same way joins nothing
    let mut edges: HashMap<(u32, u32), u32> =
        HashMap::with_capacity_and_hasher(made.len() * 6, Default::default());
    let mut twice: HashSet<(u32, u32)> = HashSet::default();
    for &p in &made {
        for (a, b, _) in sub_edges(&rings[&(p as u32)]) {
            if edges.insert((a, b), p as u32).is_some() {
                twice.insert((a, b));
            }
        }
    }
    let mut sets = UnionFind::new(n);
    for &p in &made {
        for (a, b, _) in sub_edges(&rings[&(p as u32)]) {
            if twice.contains(&(a, b)) || twice.contains(&(b, a)) {
                continue;
            }
            if let Some(&q) = edges.get(&(b, a))
                && q as usize != p
                && polys[q as usize].support() == polys[p].support()
            {
                sets.union(p as u32, q);
            }
        }
    }
    let mut groups: HashMap<u32, Vec<u32>> = HashMap::default();
    for &p in &made {
        groups
            .entry(sets.find(p as u32))
            .or_default()
            .push(p as u32);
    }
    let mut groups: Vec<Vec<u32>> = groups.into_values().filter(|g| g.len() > 1).collect();
    groups.sort_unstable_by_key(|g| g[0]);
    if groups.is_empty() {
        return out;
    }
    // each point's uses in every polygon's loop: as a corner, or inside an
    // edge
    let mut uses = vec![0u32; w.vertices.len()];
    for &v in w.corners {
        uses[v as usize] += 1;
    }
    for &(_, v) in w.inside.iter().flatten() {
        uses[v as usize] += 1;
    }
    let mut plans: Vec<Option<Plan>> = groups
        .par_iter()
        .map(|g| plan(polys, w, g, &rings, &uses))
        .collect();
    // a point goes where every loop that has it belongs to a planned
    // region: a straight corner of its loop, or a point inside it; a fan
    // whose corner's edges would keep a point is given up, and its points
    // counted again (each round gives up one region at least)
    let dropped = loop {
        let mut votes: HashMap<u32, u32> = HashMap::default();
        for plan in plans.iter().flatten() {
            let on_loop: HashSet<u32> = plan.lp.iter().map(|e| e.v).collect();
            for (&v, &k) in &plan.own {
                if !on_loop.contains(&v) {
                    *votes.entry(v).or_default() += k;
                }
            }
        }
        let dropped: HashSet<u32> = (votes.into_iter())
            .filter(|&(v, k)| k == uses[v as usize])
            .map(|(v, _)| v)
            .collect();
        let mut given_up = false;
        for slot in plans.iter_mut() {
            if slot.as_ref().is_some_and(|p| !fan_edges_clear(p, &dropped)) {
                *slot = None;
                given_up = true;
            }
        }
        if !given_up {
            break dropped;
        }
    };
    let done: Vec<Option<Vec<[u32; 3]>>> = plans
        .par_iter()
        .map(|p| p.as_ref().map(|p| finish(p, &dropped)))
        .collect();
    for (g, tris) in groups.iter().zip(done) {
        if let Some(tris) = tris {
            g.iter().for_each(|&p| out.replaced[p as usize] = true);
            out.triangles.insert(g[0], tris);
        }
    }
    out
}

/// Polygon `p`'s corners with the welded points inside its edges, in
/// order, each with the edge it lies on or starts.
fn ring_of(p: usize, w: &Welded<'_>) -> Vec<(u32, u32)> {
    let cs = w.of(p);
    let mut ring = Vec::with_capacity(cs.len() + w.inside[p].len());
    for (i, &c) in cs.iter().enumerate() {
        ring.push((c, i as u32));
        let on = w.inside[p].iter().filter(|(e, _)| *e == i as u32);
        ring.extend(on.map(|&(e, v)| (v, e)));
    }
    ring
}

/// A ring's pieces of edges: from, to, and the polygon's edge.
fn sub_edges(ring: &[(u32, u32)]) -> impl Iterator<Item = (u32, u32, u32)> + '_ {
    (0..ring.len()).map(|j| (ring[j].0, ring[(j + 1) % ring.len()].0, ring[j].1))
}

/// An edge of a region's loop: from corner `v`, along `plane` (the edge
/// plane of the polygons' edges it joins), through the corners `inside`
/// dropped on it.
struct LoopEdge {
    v: u32,
    plane: Plane,
    inside: SmallVec<[u32; 2]>,
}

/// A region that will be meshed whole: its loop (straight corners taken
/// out onto the edges), its reflex corner if it has one, and how often
/// each of its points is used by its polygons' loops.
struct Plan {
    lp: Vec<LoopEdge>,
    reflex: Option<usize>,
    own: HashMap<u32, u32>,
}

/// The plan of the region made of `group`, or `None` where it is not one
/// (see the module docs). Whether a region is meshed whole does not
/// depend on which points are dropped: that is decided after, for all of
/// them at once.
fn plan<P: ConvexFace>(
    polys: &[P],
    w: &Welded<'_>,
    group: &[u32],
    rings: &HashMap<u32, Vec<(u32, u32)>>,
    uses: &[u32],
) -> Option<Plan> {
    let mut all: HashMap<(u32, u32), (u32, u32)> = HashMap::default();
    let mut own: HashMap<u32, u32> = HashMap::default();
    for &p in group {
        for (a, b, e) in sub_edges(&rings[&p]) {
            all.insert((a, b), (p, e));
            *own.entry(a).or_default() += 1;
        }
    }
    // the boundary: edges without their reverse, one from each corner
    let mut next: HashMap<u32, (u32, u32, u32)> = HashMap::default();
    for (&(a, b), &(p, e)) in &all {
        if !all.contains_key(&(b, a)) && next.insert(a, (b, p, e)).is_some() {
            return None;
        }
    }
    let first = *next.keys().min()?;
    let mut lp: Vec<LoopEdge> = Vec::with_capacity(next.len());
    let mut v = first;
    loop {
        let &(b, p, e) = next.get(&v)?;
        lp.push(LoopEdge {
            v,
            plane: polys[p as usize].edge_plane(e as usize),
            inside: SmallVec::new(),
        });
        v = b;
        if v == first || lp.len() > next.len() {
            break;
        }
    }
    // one loop through every boundary edge, and no other polygon at a
    // point inside it
    if v != first || lp.len() != next.len() {
        return None;
    }
    let on_loop: HashSet<u32> = lp.iter().map(|e| e.v).collect();
    if own
        .iter()
        .any(|(v, &k)| !on_loop.contains(v) && uses[*v as usize] != k)
    {
        return None;
    }
    // straight corners: the edges before and after on one plane
    'straight: while lp.len() > 3 {
        let m = lp.len();
        for i in 0..m {
            let j = (i + 1) % m;
            if lp[i].plane == lp[j].plane {
                let gone = lp.remove(j);
                let i = if j == 0 { i - 1 } else { i };
                lp[i].inside.push(gone.v);
                lp[i].inside.extend(gone.inside);
                continue 'straight;
            }
        }
        break;
    }
    // each corner's turn: the next corner against the edge into it (a
    // straight corner left, its edges' planes written differently, means
    // falling back: the clipping takes corners as turns)
    let m = lp.len();
    let turns: Vec<Side> = (0..m)
        .map(|i| w.vertices[lp[(i + 1) % m].v as usize].classify(&lp[(i + m - 1) % m].plane))
        .collect();
    if turns.contains(&Side::On) {
        return None;
    }
    // a fan from a reflex corner that is strictly inside every edge but
    // its own two: each fan triangle then turns counter-clockwise, and
    // triangles that all turn the same way over a simple loop cover its
    // inside once, so they are its triangulation (with one reflex corner
    // the region is two convex parts that both have it: only an edge
    // running through it stops the fan); its own two edges must keep no
    // point, checked once the points to drop are known
    let reflex: Vec<usize> = (0..m).filter(|&i| turns[i] == Side::Front).collect();
    let sees_all = |r: usize| {
        let apex = &w.vertices[lp[r].v as usize];
        (0..m)
            .filter(|&k| k != r && k != (r + m - 1) % m)
            .all(|k| apex.classify(&lp[k].plane) == Side::Back)
    };
    let r = match reflex.first() {
        None => None,
        Some(_) => Some(reflex.into_iter().find(|&r| sees_all(r))?),
    };
    Some(Plan { lp, reflex: r, own })
}

/// Whether the two edges at a planned fan's corner keep no point once
/// the points `dropped` go (else its triangles there would be flat).
fn fan_edges_clear(plan: &Plan, dropped: &HashSet<u32>) -> bool {
    let m = plan.lp.len();
    plan.reflex.is_none_or(|r| {
        [r, (r + m - 1) % m]
            .iter()
            .all(|&k| plan.lp[k].inside.iter().all(|t| dropped.contains(t)))
    })
}

/// The triangles of a planned region, the points `dropped` left out of
/// its edges.
fn finish(plan: &Plan, dropped: &HashSet<u32>) -> Vec<[u32; 3]> {
    let (lp, m) = (&plan.lp, plan.lp.len());
    let mut ring: Vec<(u32, SmallVec<[u32; 3]>)> = Vec::new();
    for (k, e) in lp.iter().enumerate() {
        ring.push((e.v, smallvec![((k + m - 1) % m) as u32, k as u32]));
        let kept = e.inside.iter().filter(|t| !dropped.contains(t));
        ring.extend(kept.map(|&t| (t, smallvec![k as u32])));
    }
    let mut tris = Vec::new();
    match plan.reflex {
        None => clip_ears(ring, m as u32, &mut tris),
        Some(r) => {
            let at = ring
                .iter()
                .position(|(v, _)| *v == lp[r].v)
                .expect("the reflex corner is on the loop");
            ring.rotate_left(at);
            for i in 1..ring.len() - 1 {
                tris.push([ring[0].0, ring[i].0, ring[i + 1].0]);
            }
        }
    }
    tris
}

/// Triangulates a convex loop whose points may be collinear along edges.
/// Every point knows the edges (original sides and chords made so far) it
/// lies on. Three consecutive points `a, b, c` form an ear when `a` and `c`
/// share no edge: the chord `ac` then crosses the interior and contains no
/// other point of the loop, and `b` is not on it. A convex loop of positive
/// area always has such an ear (at a corner next to a corner of another
/// side). `next_edge` is the first free edge id for chords.
pub(super) fn clip_ears(
    mut ring: Vec<(u32, SmallVec<[u32; 3]>)>,
    mut next_edge: u32,
    out: &mut Vec<[u32; 3]>,
) {
    while ring.len() > 3 {
        let m = ring.len();
        let ear = (0..m).find(|&j| {
            let (a, c) = (&ring[(j + m - 1) % m].1, &ring[(j + 1) % m].1);
            !a.iter().any(|e| c.contains(e))
        });
        let Some(j) = ear else {
            debug_assert!(false, "a convex loop with positive area has an ear");
            return;
        };
        let (ia, ic) = ((j + m - 1) % m, (j + 1) % m);
        out.push([ring[ia].0, ring[j].0, ring[ic].0]);
        ring[ia].1.push(next_edge);
        ring[ic].1.push(next_edge);
        next_edge += 1;
        ring.remove(j);
    }
    if ring.len() == 3 {
        let all_on_one = ring[1]
            .1
            .iter()
            .any(|e| ring[0].1.contains(e) && ring[2].1.contains(e));
        if !all_on_one {
            out.push([ring[0].0, ring[1].0, ring[2].0]);
        }
    }
}
