//! Polygons of one plane meshed as one region: pieces of a face that a
//! Boolean cut at the walls of its cells, where the kept part bends and
//! the pieces could not be put back together as one convex polygon.
//! Triangulated one by one they keep every point where a wall crossed
//! them, and a closed mesh has two triangles for every vertex.
//!
//! Adjacent polygons of one support plane, each with a corner made by
//! cutting (an implicit point), whose edges meet whole, are joined
//! where the joined region's boundary is one loop and its inner corners
//! are its own. A point goes where every loop that has it agrees: a
//! region's loop, where the point is a straight corner (the edge planes
//! before and after are the same plane) or lies inside an edge, and any
//! other polygon's, where the point lies inside one of its edges (a
//! convex polygon is clipped as well without it); a point that stays is
//! a point on the edges of every loop that has it. A region with no
//! reflex corner is clipped as a convex polygon is; one with reflex
//! corners is fanned from the first that sees the whole region (strictly
//! inside every edge but its own two: with a single reflex corner the
//! region is two convex parts that both have it as a corner), and where
//! none does, or the fan's corner would keep a point on its edges, its
//! corners are cut into ears by exact turns (`point::turn`) and each ear
//! clipped with the points kept on its edges. Every decision is an exact
//! side of a point, an exact turn, or exact equality.

use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

use smallvec::{SmallVec, smallvec};

use crate::kernel::Side;
use crate::kernel::plane::Plane;
use crate::kernel::point::{Point, turn};
use crate::kernel::polygon::ConvexFace;
use crate::union_find::UnionFind;

/// The regions found: which polygons a region's triangles replace, and
/// each region's triangles under its first polygon.
pub(super) struct FlatRegions {
    pub(super) replaced: Vec<bool>,
    pub(super) triangles: HashMap<u32, Vec<[u32; 3]>>,
    /// Points left out of every loop: the other polygons leave them out
    /// of their edges too.
    pub(super) dropped: HashSet<u32>,
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
        dropped: HashSet::default(),
    };
    let made: Vec<usize> = crate::par::filter_map(n, |p| {
        (w.of(p).iter())
            .any(|&v| matches!(w.vertices[v as usize], Point::Implicit(_)))
            .then_some(p)
    });
    if made.len() < 2 {
        return out;
    }
    // their loops with the points on their edges (other polygons'
    // corners: where cells of different sizes meet, a piece's edge holds
    // its neighbours' corners), each point with the edge it is on
    let rings: HashMap<u32, Vec<(u32, u32)>> =
        crate::par::map_slice(&made, |&p| (p as u32, ring_of(p, w)))
            .into_iter()
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
    let mut plans: Vec<Option<Plan>> =
        crate::par::map_slice(&groups, |g| plan(polys, w, g, &rings, &uses));
    // a point goes where every loop that has it agrees: a planned
    // region's, where it is a straight corner or a point inside an edge,
    // or another polygon's, where it is a point inside an edge (a convex
    // polygon is clipped as well without it). A fan whose corner's edges
    // would keep a point is cut into ears instead, and given up where it
    // cannot be (then its points are counted again: each round gives up
    // one region at least)
    let dropped = loop {
        let mut votes: HashMap<u32, u32> = HashMap::default();
        let mut planned = vec![false; n];
        for (g, plan) in groups.iter().zip(&plans) {
            let Some(plan) = plan else { continue };
            g.iter().for_each(|&p| planned[p as usize] = true);
            let on_loop: HashSet<u32> = plan.lp.iter().map(|e| e.v).collect();
            for (&v, &k) in &plan.own {
                if !on_loop.contains(&v) {
                    *votes.entry(v).or_default() += k;
                }
            }
        }
        for (p, inside) in w.inside.iter().enumerate() {
            if !planned[p] {
                for &(_, v) in inside {
                    *votes.entry(v).or_default() += 1;
                }
            }
        }
        let dropped: HashSet<u32> = (votes.into_iter())
            .filter(|&(v, k)| k == uses[v as usize])
            .map(|(v, _)| v)
            .collect();
        let mut given_up = false;
        for (g, slot) in groups.iter().zip(plans.iter_mut()) {
            if slot.as_ref().is_some_and(|p| !fan_edges_clear(p, &dropped)) {
                let mut plan = slot.take().expect("a plan");
                let support = polys[g[0] as usize].support();
                match ears(w, &plan.lp, support) {
                    Some(e) => {
                        (plan.reflex, plan.ears) = (None, Some(e));
                        *slot = Some(plan);
                    }
                    None => given_up = true,
                }
            }
        }
        if !given_up {
            break dropped;
        }
    };
    let done: Vec<Option<Vec<[u32; 3]>>> =
        crate::par::map_slice(&plans, |p| p.as_ref().map(|p| finish(p, &dropped)));
    for (g, tris) in groups.iter().zip(done) {
        if let Some(tris) = tris {
            g.iter().for_each(|&p| out.replaced[p as usize] = true);
            out.triangles.insert(g[0], tris);
        }
    }
    out.dropped = dropped;
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
    /// Where no reflex corner sees the whole region: its loop's corners
    /// cut into triangles (ears, as indices into `lp`).
    ears: Option<Vec<[u32; 3]>>,
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
    let (r, ears) = match reflex.first() {
        None => (None, None),
        Some(_) => match reflex.into_iter().find(|&r| sees_all(r)) {
            Some(r) => (Some(r), None),
            None => (
                None,
                Some(ears(w, &lp, polys[group[0] as usize].support())?),
            ),
        },
    };
    Some(Plan {
        lp,
        reflex: r,
        ears,
        own,
    })
}

/// The most corners a loop is cut into ears at (each ear is tested
/// against every corner left: cubic in the worst case).
const MAX_EAR_CORNERS: usize = 256;

/// A simple loop's corners (counter-clockwise on `support`, no straight
/// corner) cut into triangles by clipping ears: a corner that turns
/// counter-clockwise and whose triangle with its two neighbours holds no
/// other corner left, on its edges included. Such a triangle's new side
/// crosses the inside only, so the triangles tile the loop. Every turn is
/// exact (`point::turn`, seen along the support normal's largest axis).
/// `None` where no ear is found (the loop is not simple) or the loop has
/// more than [`MAX_EAR_CORNERS`] corners.
fn ears(w: &Welded<'_>, lp: &[LoopEdge], support: &Plane) -> Option<Vec<[u32; 3]>> {
    let m = lp.len();
    if m > MAX_EAR_CORNERS {
        return None;
    }
    let n = support.normal();
    let k = (0..3).max_by_key(|&k| n[k].unsigned_abs())?;
    let sign = if n[k] > 0 { 1 } else { -1 };
    let ccw = |a: u32, b: u32, c: u32| {
        let at = |i: u32| &w.vertices[lp[i as usize].v as usize];
        turn(at(a), at(b), at(c), k) * sign
    };
    let mut ring: Vec<u32> = (0..m as u32).collect();
    let mut tris = Vec::with_capacity(m - 2);
    while ring.len() > 3 {
        let l = ring.len();
        let j = (0..l).find(|&j| {
            let (a, b, c) = (ring[(j + l - 1) % l], ring[j], ring[(j + 1) % l]);
            ccw(a, b, c) > 0
                && ring.iter().all(|&p| {
                    p == a
                        || p == b
                        || p == c
                        || ccw(a, b, p) < 0
                        || ccw(b, c, p) < 0
                        || ccw(c, a, p) < 0
                })
        })?;
        tris.push([ring[(j + l - 1) % l], ring[j], ring[(j + 1) % l]]);
        ring.remove(j);
    }
    (ccw(ring[0], ring[1], ring[2]) > 0).then_some(())?;
    tris.push([ring[0], ring[1], ring[2]]);
    Some(tris)
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
    if let Some(ears) = &plan.ears {
        // each ear with the points kept on the loop's edges it has
        for &[a, b, c] in ears {
            let mut ring: Vec<(u32, SmallVec<[u32; 3]>)> = Vec::new();
            for (e, (x, y)) in [(a, b), (b, c), (c, a)].into_iter().enumerate() {
                let e = e as u32;
                ring.push((lp[x as usize].v, smallvec![(e + 2) % 3, e]));
                if y as usize == (x as usize + 1) % m {
                    let kept = lp[x as usize]
                        .inside
                        .iter()
                        .filter(|t| !dropped.contains(t));
                    ring.extend(kept.map(|&t| (t, smallvec![e])));
                }
            }
            clip_ears(ring, 3, &mut tris);
        }
        return tris;
    }
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
