//! Merging convex polygons back where their union is convex: the pieces
//! a face was cut into, once their classes are known, and what of a
//! light a point sees ([`merge_convex`]).
//!
//! Two polygons that share an edge share two vertex keys (their
//! vertices' correctly rounded coordinates), so candidates are found by
//! hashing; whether they merge is decided exactly (`Polygon::merge`).
//!
//! Convex unions are not maximal: [`merge_regions`] then unites a face's
//! pieces of one label into maximal connected regions, with holes.

use bsp_core::{Point, Polygon};
use rayon::prelude::*;
use smallvec::SmallVec;

use crate::arena::pieces::PieceArena;
use crate::arena::regions::merge_cells;

/// A maximal connected region of equally labelled polygons
/// ([`merge_regions`]).
#[derive(Clone, Debug)]
pub(crate) struct LabelledRegion<T> {
    /// The polygons' label.
    pub(crate) label: T,
    /// The outer ring, counter-clockwise seen from the front of the
    /// polygons' plane, then the holes, each clockwise; corners only (no
    /// two consecutive edges collinear), exact.
    pub(crate) rings: Vec<Vec<Point>>,
    /// The polygons whose union it is (indices into the input), in
    /// increasing order.
    pub(crate) cells: Vec<u32>,
}

/// Merges convex polygons of one plane (with one orientation), which tile
/// a region without overlap, into maximal connected regions of equal
/// labels: the exact region merge of the point lights' fragments
/// (`arena::regions::merge_cells`), whose pieces may meet at T-junctions.
/// Regions come in the order of their first polygon.
pub(crate) fn merge_regions<T: Copy + PartialEq>(items: &[(Polygon, T)]) -> Vec<LabelledRegion<T>> {
    let Some((first, _)) = items.first() else {
        return Vec::new();
    };
    // each distinct label a number (a face has few)
    let mut distinct: Vec<T> = Vec::new();
    let labels: Vec<u64> = items
        .iter()
        .map(|(_, l)| match distinct.iter().position(|d| d == l) {
            Some(i) => i as u64,
            None => {
                distinct.push(*l);
                distinct.len() as u64 - 1
            }
        })
        .collect();
    if distinct.len() == items.len() {
        // no two polygons of one label: each is its own region
        return (items.iter().enumerate())
            .map(|(i, (p, l))| LabelledRegion {
                label: *l,
                rings: vec![p.vertices().to_vec()],
                cells: vec![i as u32],
            })
            .collect();
    }
    let mut arena = PieceArena::default();
    let support = *first.support();
    let mut shared = rustc_hash::FxHashMap::default();
    let cells: Vec<_> = (items.iter())
        .map(|(p, _)| arena.add_polygon_sharing(p, &mut shared))
        .collect();
    // each arena vertex's point as the polygons hold it (shared, not made
    // again from the arena's)
    let mut points: Vec<Option<&Point>> = vec![None; arena.len()];
    for ((p, _), c) in items.iter().zip(&cells) {
        for (v, &id) in p.vertices().iter().zip(&c.verts) {
            points[arena.dense(id)] = Some(v);
        }
    }
    let mut rounded = Vec::new();
    let point = |id: &u32| {
        (points[arena.dense(*id)].expect("every arena vertex is a polygon's corner")).clone()
    };
    merge_cells(&arena, &support, &cells, &labels, &mut rounded)
        .into_iter()
        .map(|r| LabelledRegion {
            label: distinct[r.label as usize],
            rings: std::iter::once(&r.outer)
                .chain(&r.holes)
                .map(|ring| ring.iter().map(point).collect())
                .collect(),
            cells: r.cells,
        })
        .collect()
}

/// The vertices' correctly rounded coordinates, as bits: equal exact
/// points have equal keys, so two polygons that share an edge share two.
pub(crate) fn vertex_keys(p: &Polygon) -> Vec<[u64; 3]> {
    p.vertices_f64()
        .iter()
        .map(|c| c.map(|x| (x + 0.0).to_bits()))
        .collect()
}

/// Merges polygons of equal labels pairwise where their union is convex
/// (`Polygon::merge`, exact), until none do; only pairs that share two
/// vertex keys are tried. Deterministic: the order of the input decides.
pub(crate) fn merge_convex<T: Copy + PartialEq>(items: Vec<(Polygon, T)>) -> Vec<(Polygon, T)> {
    let items = items.into_iter().map(keyed).collect();
    merge_keyed(items, |_, _| ())
        .into_iter()
        .map(|m| (m.polygon, m.label))
        .collect()
}

/// [`merge_convex`] of a face's pieces whose other work waits for it (a
/// ground under a mesh): their keys made on every thread, in order, and
/// many merged in parts in parallel ([`merge_keyed_parts`]); the same
/// polygons.
pub(crate) fn merge_convex_parts<T: Copy + PartialEq + Send + Sync>(
    items: Vec<(Polygon, T)>,
) -> Vec<(Polygon, T)> {
    let items = match items.len() >= crate::schedule::PARALLEL_CELLS {
        true => items.into_par_iter().map(keyed).collect(),
        false => items.into_iter().map(keyed).collect(),
    };
    merge_keyed_parts(items, |_, _| ())
        .into_iter()
        .map(|m| (m.polygon, m.label))
        .collect()
}

/// A polygon with its vertex keys, to merge.
fn keyed<T>((polygon, label): (Polygon, T)) -> Keyed<T, ()> {
    Keyed {
        keys: vertex_keys(&polygon),
        polygon,
        label,
        extra: (),
    }
}

/// A polygon to merge: its label, its vertex keys, and something that two
/// merged polygons join.
pub(crate) struct Keyed<T, X> {
    pub(crate) polygon: Polygon,
    pub(crate) label: T,
    pub(crate) keys: Vec<[u64; 3]>,
    pub(crate) extra: X,
}

/// [`merge_convex`] of polygons with their keys; `join` makes a merged
/// polygon's `extra` of its two parts'. A polygon's keys are made again
/// only when it grows.
///
/// In passes: each live polygon in turn tries, in index order, the later
/// live ones of its label that share two vertex keys with it (as the
/// pass found them) and takes the first it merges with; passes repeat
/// until one merges nothing. A pass after the first visits only the
/// polygons that grew in the one before and those sharing a key with
/// them: any other polygon and all its partners are as they were when
/// they last failed to merge, so it would fail again, and leaving it out
/// changes nothing (a polygon's partners are always later ones, looked
/// up as the pass began: the one that grows is never a partner of those
/// after it, and the one it takes is dead).
pub(crate) fn merge_keyed<T: Copy + PartialEq, X>(
    mut items: Vec<Keyed<T, X>>,
    join: impl Fn(&X, &X) -> X,
) -> Vec<Keyed<T, X>> {
    let dead = merge_in_place(&mut items, &join);
    let mut k = 0;
    items.retain(|_| {
        k += 1;
        !dead[k - 1]
    });
    items
}

/// [`merge_keyed`] for a caller that has both cores to itself (a face of
/// many pieces whose other work waits for the merge): many polygons
/// (from [`PARALLEL_MERGE`] on) are merged in parts, in parallel: the
/// polygons of one label linked by shared keys, each part in index order.
/// A merged polygon's corners are its two parts', so a polygon's
/// partners, then and later, are all in its part, and what happens in
/// one part never changes what happens in another: the same polygons as
/// merged all at once, in the same order. (Inside work that is parallel
/// already, finding the parts only costs.)
pub(crate) fn merge_keyed_parts<T: Copy + PartialEq + Send + Sync, X: Send>(
    items: Vec<Keyed<T, X>>,
    join: impl Fn(&X, &X) -> X + Sync,
) -> Vec<Keyed<T, X>> {
    if items.len() < PARALLEL_MERGE {
        return merge_keyed(items, &join);
    }
    // the parts: polygons of one label sharing a key
    let mut parts = bsp_core::internals::UnionFind::new(items.len());
    let mut at: rustc_hash::FxHashMap<[u64; 3], SmallVec<[u32; 4]>> = Default::default();
    at.reserve(items.len() * 2);
    for (i, item) in items.iter().enumerate() {
        for k in &item.keys {
            at.entry(*k).or_default().push(i as u32);
        }
    }
    for list in at.values() {
        for (n, &i) in list.iter().enumerate() {
            if let Some(&j) =
                (list[..n].iter()).find(|&&j| items[j as usize].label == items[i as usize].label)
            {
                parts.union(i, j);
            }
        }
    }
    drop(at);
    // each part's polygons in index order, the parts in order of their
    // first polygon
    let mut part_of: rustc_hash::FxHashMap<u32, usize> = Default::default();
    let mut members: Vec<Vec<(u32, Keyed<T, X>)>> = Vec::new();
    for (i, item) in items.into_iter().enumerate() {
        let root = parts.find(i as u32);
        let p = *part_of.entry(root).or_insert_with(|| {
            members.push(Vec::new());
            members.len() - 1
        });
        members[p].push((i as u32, item));
    }
    let merged: Vec<Vec<(u32, Keyed<T, X>)>> = members
        .into_par_iter()
        .map(|part| {
            let (index, mut items): (Vec<u32>, Vec<Keyed<T, X>>) = part.into_iter().unzip();
            let dead = merge_in_place(&mut items, &join);
            (index.into_iter().zip(items).zip(dead))
                .filter_map(|(item, d)| (!d).then_some(item))
                .collect()
        })
        .collect();
    let mut all: Vec<(u32, Keyed<T, X>)> = merged.into_iter().flatten().collect();
    all.sort_unstable_by_key(|&(i, _)| i);
    all.into_iter().map(|(_, item)| item).collect()
}

/// From this many polygons on, [`merge_keyed_parts`] merges its parts in
/// parallel.
const PARALLEL_MERGE: usize = 1024;

/// [`merge_keyed`] in place: each merged polygon at the place of its
/// first part, and whether each polygon was merged into an earlier one.
fn merge_in_place<T: Copy + PartialEq, X>(
    items: &mut [Keyed<T, X>],
    join: &impl Fn(&X, &X) -> X,
) -> Vec<bool> {
    // each key to the live polygons with it, once for each time it is one
    // of their keys (a vertex is a corner of a few polygons: no list
    // allocated for it)
    let mut at: rustc_hash::FxHashMap<[u64; 3], SmallVec<[u32; 4]>> = Default::default();
    at.reserve(items.len() * 2);
    for (i, item) in items.iter().enumerate() {
        for k in &item.keys {
            at.entry(*k).or_default().push(i as u32);
        }
    }
    let mut dead = vec![false; items.len()];
    let mut active: Vec<u32> = (0..items.len() as u32).collect();
    let mut seen: SmallVec<[u32; 32]> = SmallVec::new();
    while !active.is_empty() {
        let mut grown: Vec<u32> = Vec::new();
        for &i in &active {
            let i = i as usize;
            if dead[i] {
                continue;
            }
            seen.clear();
            seen.extend(items[i].keys.iter().flat_map(|k| at[k].iter().copied()));
            seen.sort_unstable();
            let shared = seen
                .windows(2)
                .filter(|w| w[0] == w[1] && w[0] as usize > i)
                .map(|w| w[0] as usize);
            let mut candidates: SmallVec<[usize; 8]> = shared.collect();
            candidates.dedup();
            for j in candidates {
                if dead[j] || items[j].label != items[i].label {
                    continue;
                }
                if let Some(m) = items[i].polygon.merge(&items[j].polygon) {
                    // (the lists change for `i`, earlier than every
                    // polygon after it in this pass, and for `j`, dead:
                    // the later ones' partners are as the pass found them)
                    let keys = vertex_keys(&m);
                    unlist(&mut at, &items[i].keys, i as u32);
                    unlist(&mut at, &items[j].keys, j as u32);
                    for k in &keys {
                        at.entry(*k).or_default().push(i as u32);
                    }
                    items[i].keys = keys;
                    items[i].polygon = m;
                    items[i].extra = join(&items[i].extra, &items[j].extra);
                    dead[j] = true;
                    grown.push(i as u32);
                    break;
                }
            }
        }
        // the next pass: the polygons that grew and those sharing a key
        // with them
        active = grown
            .iter()
            .flat_map(|&i| {
                items[i as usize]
                    .keys
                    .iter()
                    .flat_map(|k| at[k].iter().copied())
            })
            .collect();
        active.sort_unstable();
        active.dedup();
    }
    dead
}

/// Takes polygon `i` off the lists of `keys`, once for each time a key
/// is among them.
fn unlist(at: &mut rustc_hash::FxHashMap<[u64; 3], SmallVec<[u32; 4]>>, keys: &[[u64; 3]], i: u32) {
    for k in keys {
        if let Some(list) = at.get_mut(k)
            && let Some(p) = list.iter().position(|&x| x == i)
        {
            list.swap_remove(p);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The merge as it was before a pass visited only what the one before
    /// changed: every pass visits every live polygon, with the lists made
    /// again from all of them.
    fn every_pass<T: Copy + PartialEq>(mut items: Vec<(Polygon, T)>) -> Vec<(Polygon, T)> {
        loop {
            let keys: Vec<Vec<[u64; 3]>> = items.iter().map(|(p, _)| vertex_keys(p)).collect();
            let mut at: rustc_hash::FxHashMap<[u64; 3], Vec<usize>> = Default::default();
            for (i, ks) in keys.iter().enumerate() {
                for k in ks {
                    at.entry(*k).or_default().push(i);
                }
            }
            let mut dead = vec![false; items.len()];
            let mut any = false;
            for i in 0..items.len() {
                if dead[i] {
                    continue;
                }
                let mut seen: Vec<usize> = keys[i].iter().flat_map(|k| at[k].clone()).collect();
                seen.sort_unstable();
                let mut candidates: Vec<usize> = (seen.windows(2))
                    .filter(|w| w[0] == w[1] && w[0] > i)
                    .map(|w| w[0])
                    .collect();
                candidates.dedup();
                for j in candidates {
                    if dead[j] || items[j].1 != items[i].1 {
                        continue;
                    }
                    if let Some(m) = items[i].0.merge(&items[j].0) {
                        items[i].0 = m;
                        dead[j] = true;
                        any = true;
                        break;
                    }
                }
            }
            let mut k = 0;
            items.retain(|_| {
                k += 1;
                !dead[k - 1]
            });
            if !any {
                return items;
            }
        }
    }

    /// A grid of unit squares, each cut into two triangles along a
    /// random diagonal, with random labels of two kinds, in a random
    /// order: the merge gives what passes over everything give, polygon
    /// for polygon and label for label, in the same order; and so does
    /// the merge in parts.
    #[test]
    fn later_passes_visit_only_what_changed_and_give_the_same() {
        let mut state = 0x5eed_u64;
        let mut draw = |n: u64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state % n
        };
        let mut merged_some = 0;
        // (the last rounds have more triangles than one thread merges, so
        // `merge_convex_parts` merges them in parts)
        for round in 0..23 {
            let side = match round {
                0..20 => 4 + round % 9,
                _ => 24 + 6 * (round - 20),
            };
            let mut items: Vec<(Polygon, u8)> = Vec::new();
            for x in 0..side {
                for y in 0..side {
                    let c = |dx: i32, dy: i32| [x + dx, y + dy, 0];
                    let halves = match draw(2) {
                        0 => [[c(0, 0), c(1, 0), c(1, 1)], [c(0, 0), c(1, 1), c(0, 1)]],
                        _ => [[c(0, 0), c(1, 0), c(0, 1)], [c(1, 0), c(1, 1), c(0, 1)]],
                    };
                    // labels in patches, so that runs of equal ones merge
                    let label = u8::from((x / 3 + y / 2 + draw(4) as i32 / 3) % 2 == 0);
                    for t in halves {
                        items.push((Polygon::from_grid_points(&t, 0).unwrap(), label));
                    }
                }
            }
            for i in (1..items.len()).rev() {
                items.swap(i, draw(i as u64 + 1) as usize);
            }
            let want = every_pass(items.clone());
            for got in [
                merge_convex(items.clone()),
                merge_convex_parts(items.clone()),
            ] {
                assert_eq!(got.len(), want.len(), "round {round}");
                for ((p, a), (q, b)) in got.iter().zip(&want) {
                    assert_eq!(a, b);
                    assert_eq!(p.vertices_f64(), q.vertices_f64(), "round {round}");
                }
            }
            assert_eq!(items.len() >= PARALLEL_MERGE, round >= 20);
            merged_some += usize::from(want.len() < items.len() / 2);
        }
        assert!(
            merged_some > 10,
            "{merged_some} rounds merged most triangles"
        );
    }
}
