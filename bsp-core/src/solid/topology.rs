//! Combinatorial checks of indexed meshes: closed, consistently oriented
//! 2-manifolds.

use rustc_hash::FxHashMap as HashMap;

/// Why an indexed mesh is not a closed, consistently oriented 2-manifold.
/// Faces are 0-based indices into the list given; edges are vertex indices.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum TopologyError {
    /// A face repeats a vertex or has fewer than three.
    DegenerateFace {
        /// The face.
        face: usize,
    },
    /// The edge `a → b` of `face` has no face using `b → a`: the surface is
    /// open there.
    OpenEdge {
        /// Start vertex.
        a: u32,
        /// End vertex.
        b: u32,
        /// The face using `a → b`.
        face: usize,
    },
    /// Two faces use the edge `a → b` in the same direction: their
    /// orientations disagree.
    Misoriented {
        /// Start vertex.
        a: u32,
        /// End vertex.
        b: u32,
        /// The two faces.
        faces: [usize; 2],
    },
    /// More than two faces share the edge `{a, b}`.
    NonManifoldEdge {
        /// One end.
        a: u32,
        /// The other end.
        b: u32,
        /// How many faces use it.
        count: usize,
        /// The first face using it.
        face: usize,
    },
    /// The faces around a vertex form more than one fan (a pinch).
    NonManifoldVertex {
        /// The vertex.
        vertex: u32,
    },
}

impl std::fmt::Display for TopologyError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TopologyError::DegenerateFace { face } => {
                write!(f, "face {face} repeats a vertex or has fewer than three")
            }
            TopologyError::OpenEdge { a, b, face } => {
                write!(
                    f,
                    "edge {a}-{b} of face {face} is a boundary edge (the mesh is not closed)"
                )
            }
            TopologyError::Misoriented { a, b, faces } => write!(
                f,
                "faces {} and {} both use edge {a}->{b} in the same direction (inconsistent orientation)",
                faces[0], faces[1]
            ),
            TopologyError::NonManifoldEdge { a, b, count, face } => {
                write!(f, "edge {a}-{b} (face {face}) is shared by {count} faces")
            }
            TopologyError::NonManifoldVertex { vertex } => {
                write!(f, "vertex {vertex} joins separate fans of faces (a pinch)")
            }
        }
    }
}

impl std::error::Error for TopologyError {}

/// Whether `faces` (vertex index loops) form a closed cycle: no face
/// repeats a vertex or has fewer than three, and every edge `{a, b}` is
/// used as often from `a` to `b` as from `b` to `a`. That is what a
/// winding number needs to be defined everywhere off the surface; a
/// closed, consistently oriented 2-manifold is one, and so is a surface
/// that touches itself along an edge or at a vertex, folds, or holds a
/// shell turned inside out.
///
/// ```
/// use bsp_core::is_closed_cycle;
/// let tet = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
/// assert!(is_closed_cycle(tet.iter().map(|f| &f[..])));
/// // one face turned: its edges are used twice one way
/// let turned = [[0, 1, 2], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
/// assert!(!is_closed_cycle(turned.iter().map(|f| &f[..])));
/// ```
pub fn is_closed_cycle<'a>(faces: impl IntoIterator<Item = &'a [u32]>) -> bool {
    let mut net: rustc_hash::FxHashMap<(u32, u32), i64> = rustc_hash::FxHashMap::default();
    for f in faces {
        let mut v: smallvec::SmallVec<[u32; 8]> = f.iter().copied().collect();
        v.sort_unstable();
        if f.len() < 3 || v.windows(2).any(|w| w[0] == w[1]) {
            return false;
        }
        for (k, &a) in f.iter().enumerate() {
            let b = f[(k + 1) % f.len()];
            *net.entry((a.min(b), a.max(b))).or_default() += if a < b { 1 } else { -1 };
        }
    }
    net.values().all(|&n| n == 0)
}

/// Checks that `faces` (vertex index loops) form a closed, consistently
/// oriented 2-manifold: every directed edge is used once and its reverse
/// once, and the faces around every vertex form a single fan. Reports the
/// first problem in face order.
///
/// ```
/// use bsp_core::check_closed_manifold;
/// let tet = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
/// assert!(check_closed_manifold(tet.iter().map(|f| &f[..])).is_ok());
/// assert!(check_closed_manifold(tet[..3].iter().map(|f| &f[..])).is_err());
/// ```
pub fn check_closed_manifold<'a>(
    faces: impl IntoIterator<Item = &'a [u32]>,
) -> Result<(), TopologyError> {
    let faces: Vec<&[u32]> = faces.into_iter().collect();
    if is_closed_manifold(&faces) {
        return Ok(());
    }
    first_defect(&faces)
}

/// The verdict of [`check_closed_manifold`], without naming a defect: no
/// face repeats a vertex, and the corners around every vertex close up
/// ([`corners_close`], with the link cycles).
fn is_closed_manifold(faces: &[&[u32]]) -> bool {
    let ok_face = |f: &&[u32]| match **f {
        // (most faces: three comparisons, no copy)
        [a, b, c] => a != b && b != c && c != a,
        _ => {
            let mut v: smallvec::SmallVec<[u32; 8]> = f.iter().copied().collect();
            v.sort_unstable();
            f.len() >= 3 && v.windows(2).all(|w| w[0] != w[1])
        }
    };
    let ok_faces = crate::par::fold_runs(faces.len(), |r| faces[r].iter().all(ok_face))
        .into_iter()
        .all(|ok| ok);
    ok_faces && corners_close(faces, true)
}

/// `true` if around every vertex `v` the corners `u → v → w` of the faces
/// (no face repeating a vertex) close up: the `u`s are distinct and are
/// the `w`s. That is every directed edge used once and its reverse once:
/// `v → w` is used by one corner at `v` (the `w`s are distinct), and
/// `w → v` by one (`w` is one of the distinct `u`s). With `cycles`, the
/// corners also form one cycle `u ↦ w` (the vertex's link is one loop, so
/// no two sheets of the surface meet there).
///
/// The corners are put in buckets by vertex (one count, one pass), and
/// each vertex's few corners are checked on their own, in parallel: no
/// sort of all edges.
pub(crate) fn corners_close<F: AsRef<[u32]> + Sync>(faces: &[F], cycles: bool) -> bool {
    use rayon::prelude::*;
    // (the largest id and the number of corners, run by run)
    let runs = crate::par::fold_runs(faces.len(), |r| {
        let faces = &faces[r];
        let last = (faces.iter())
            .filter_map(|f| f.as_ref().iter().max().copied())
            .max();
        (last, faces.iter().map(|f| f.as_ref().len()).sum::<usize>())
    });
    let Some(last) = runs.iter().filter_map(|r| r.0).max() else {
        return true;
    };
    let corners: usize = runs.iter().map(|r| r.1).sum();
    // ids far beyond the corner count are numbered densely first, so that
    // the buckets stay as small as the faces
    let (n, dense): (usize, Option<Vec<u32>>) = if last as usize > 4 * corners + 1024 {
        let mut ids: Vec<u32> = faces
            .iter()
            .flat_map(|f| f.as_ref().iter().copied())
            .collect();
        ids.par_sort_unstable();
        ids.dedup();
        (ids.len(), Some(ids))
    } else {
        (last as usize + 1, None)
    };
    let id = |v: u32| match &dense {
        Some(ids) => ids.binary_search(&v).expect("every id is listed"),
        None => v as usize,
    };
    // the corners of vertex `v` are `link[start[v]..start[v + 1]]`
    let (start, link) = bucket(n, |emit| {
        for f in faces {
            let f = f.as_ref();
            let k = f.len();
            for i in 0..k {
                emit(id(f[i]), (f[(i + k - 1) % k], f[(i + 1) % k]));
            }
        }
    });
    crate::par::fold_runs(n, |vs| {
        vs.into_iter()
            .all(|v| corners_close_at(&link[start[v]..start[v + 1]], cycles))
    })
    .into_iter()
    .all(|ok| ok)
}

/// Items grouped by key: `each(emit)` calls `emit(key, item)` for every
/// item (keys below `n`), twice, the same way each time; key `k`'s items
/// come out in `items[start[k]..start[k + 1]]`, in the order emitted. One
/// count and one pass: a counting sort, no comparison.
pub(crate) fn bucket<T: Copy + Default>(
    n: usize,
    each: impl Fn(&mut dyn FnMut(usize, T)),
) -> (Vec<usize>, Vec<T>) {
    let mut start = vec![0usize; n + 1];
    each(&mut |k, _| start[k + 1] += 1);
    for k in 0..n {
        start[k + 1] += start[k];
    }
    let mut items = vec![T::default(); start[n]];
    let mut fill = start.clone();
    each(&mut |k, t| {
        items[fill[k]] = t;
        fill[k] += 1;
    });
    (start, items)
}

/// `n` default items, written in parallel (a large array's pages are
/// first touched by both threads).
fn zeroed_par<T: Copy + Default + Send + Sync>(n: usize) -> Vec<T> {
    use rayon::prelude::*;
    let mut v = Vec::with_capacity(n);
    v.par_extend(rayon::iter::repeat_n(T::default(), n));
    v
}

/// [`bucket`] of every corner `i` of every face `f` (face `f`'s corners
/// being `start[f]..start[f + 1]`), item `make(c, f, i)` for corner number
/// `c` under key `key(f, i)` (below `n`; called twice per corner), in
/// parallel, for few keys (shards): each run of faces counts its corners
/// per key, then fills its own ranges (a count per key per run, which for
/// keys as many as the vertices would be larger than the items). No list
/// of the corners is made first.
pub(crate) fn bucket_par_corners<'f, F: Sync, T: Copy + Default + Send + Sync>(
    n: usize,
    faces: &'f [F],
    start: &[usize],
    key: impl Fn(&'f F, usize) -> usize + Sync,
    make: impl Fn(usize, &'f F, usize) -> T + Sync,
) -> (Vec<usize>, Vec<T>) {
    const RUN: usize = 4096;
    let corners = |r: usize, j: usize| start[r * RUN + j]..start[r * RUN + j + 1];
    let run_of = |r: usize| &faces[r * RUN..faces.len().min((r + 1) * RUN)];
    let counts: Vec<Vec<usize>> = crate::par::map(faces.len().div_ceil(RUN), |r| {
        let run = run_of(r);
        let mut c = vec![0usize; n];
        for (j, f) in run.iter().enumerate() {
            for i in 0..corners(r, j).len() {
                c[key(f, i)] += 1;
            }
        }
        c
    });
    let mut at = vec![0usize; n + 1];
    for k in 0..n {
        at[k + 1] = at[k] + counts.iter().map(|c| c[k]).sum::<usize>();
    }
    let mut items = zeroed_par(at[n]);
    // each run's range of each key, key by key, run by run
    let mut ranges: Vec<Vec<&mut [T]>> = counts.iter().map(|_| Vec::with_capacity(n)).collect();
    let mut rest = &mut items[..];
    for k in 0..n {
        for (r, c) in counts.iter().enumerate() {
            let (here, tail) = std::mem::take(&mut rest).split_at_mut(c[k]);
            ranges[r].push(here);
            rest = tail;
        }
    }
    crate::par::for_each_mut(&mut ranges, |r, out| {
        let run = run_of(r);
        let mut fill = vec![0usize; n];
        for (j, f) in run.iter().enumerate() {
            for (i, c) in corners(r, j).enumerate() {
                let k = key(f, i);
                out[k][fill[k]] = make(c, f, i);
                fill[k] += 1;
            }
        }
    });
    (at, items)
}

/// [`corners_close`] at one vertex, its corners `(u, w)`.
fn corners_close_at(g: &[(u32, u32)], cycles: bool) -> bool {
    if g.len() <= SMALL_LINK {
        corners_close_small(g, cycles)
    } else {
        corners_close_sorted(g, cycles)
    }
}

/// A vertex with at most this many corners (most of them: a closed
/// triangle mesh has six on average) is checked by comparing its corners
/// pairwise, with no copy and no sort.
const SMALL_LINK: usize = 12;

/// [`corners_close_at`] by pairwise comparisons: the `u`s distinct, and
/// then either the walk `u ↦ w` from the first corner comes back to it
/// after exactly as many steps as there are corners (`cycles`), or each
/// `w` is the `u` of exactly one corner.
fn corners_close_small(g: &[(u32, u32)], cycles: bool) -> bool {
    for (i, a) in g.iter().enumerate() {
        if g[i + 1..].iter().any(|b| b.0 == a.0) {
            return false;
        }
    }
    if !cycles {
        // with the `u`s distinct, every `w` a `u` and the `w`s distinct
        // make the `w`s the `u`s
        return g
            .iter()
            .enumerate()
            .all(|(i, a)| g.iter().any(|b| b.0 == a.1) && !g[i + 1..].iter().any(|b| b.1 == a.1));
    }
    let Some(&(first, mut u)) = g.first() else {
        return true;
    };
    // (the walk as in `corners_close_sorted`, the next corner found by a
    // scan)
    for step in 1..=g.len() {
        if u == first {
            return step == g.len();
        }
        match g.iter().find(|c| c.0 == u) {
            Some(c) => u = c.1,
            None => return false,
        }
    }
    false
}

/// [`corners_close_at`] by sorting the corners by `u`.
fn corners_close_sorted(g: &[(u32, u32)], cycles: bool) -> bool {
    let mut by_u: smallvec::SmallVec<[(u32, u32); 16]> = g.iter().copied().collect();
    by_u.sort_unstable();
    if by_u.windows(2).any(|x| x[0].0 == x[1].0) {
        return false;
    }
    if !cycles {
        let mut ws: smallvec::SmallVec<[u32; 16]> = g.iter().map(|c| c.1).collect();
        ws.sort_unstable();
        return by_u.iter().map(|c| c.0).eq(ws);
    }
    if by_u.is_empty() {
        return true;
    }
    // the walk u ↦ w from the first u: with the u's distinct, it comes
    // back to its start after exactly as many steps as there are corners
    // only if it met every u once, so the w's are the u's
    let first = by_u[0].0;
    let mut u = first;
    for step in 1..=by_u.len() {
        match by_u.binary_search_by_key(&u, |c| c.0) {
            Ok(i) => u = by_u[i].1,
            Err(_) => return false,
        }
        if u == first {
            return step == by_u.len();
        }
    }
    false
}

/// The edge `a → b` as its two ends in order and its direction (0 when
/// `a < b`).
#[inline]
pub(crate) fn undirected(a: u32, b: u32) -> (u32, u32, u32) {
    if a < b { (a, b, 0) } else { (b, a, 1) }
}

/// [`check_closed_manifold`] face by face, naming the first defect.
fn first_defect(faces: &[&[u32]]) -> Result<(), TopologyError> {
    // directed edge -> first face using it
    let edges: usize = faces.iter().map(|f| f.len()).sum();
    let mut directed: HashMap<(u32, u32), usize> =
        HashMap::with_capacity_and_hasher(edges, Default::default());
    let mut undirected: HashMap<(u32, u32), (usize, usize)> =
        HashMap::with_capacity_and_hasher(edges / 2 + 1, Default::default());
    for (fi, f) in faces.iter().enumerate() {
        let k = f.len();
        let mut sorted: smallvec::SmallVec<[u32; 8]> = f.iter().copied().collect();
        sorted.sort_unstable();
        sorted.dedup();
        if k < 3 || sorted.len() != k {
            return Err(TopologyError::DegenerateFace { face: fi });
        }
        for i in 0..k {
            let (a, b) = (f[i], f[(i + 1) % k]);
            if let Some(&other) = directed.get(&(a, b)) {
                return Err(TopologyError::Misoriented {
                    a,
                    b,
                    faces: [other, fi],
                });
            }
            directed.insert((a, b), fi);
            let e = undirected.entry((a.min(b), a.max(b))).or_insert((0, fi));
            e.0 += 1;
            if e.0 > 2 {
                return Err(TopologyError::NonManifoldEdge {
                    a: a.min(b),
                    b: a.max(b),
                    count: e.0,
                    face: e.1,
                });
            }
        }
    }
    for (fi, f) in faces.iter().enumerate() {
        let k = f.len();
        for i in 0..k {
            let (a, b) = (f[i], f[(i + 1) % k]);
            if !directed.contains_key(&(b, a)) {
                return Err(TopologyError::OpenEdge { a, b, face: fi });
            }
        }
    }
    // vertex links: around each vertex v, face f with ... u -> v -> w ...
    // maps u to w; a single fan means one cycle covering all incident faces
    let mut next: HashMap<(u32, u32), u32> = HashMap::default();
    let mut incident: HashMap<u32, usize> = HashMap::default();
    for f in faces {
        let k = f.len();
        for i in 0..k {
            let (u, v, w) = (f[(i + k - 1) % k], f[i], f[(i + 1) % k]);
            next.insert((v, u), w);
            *incident.entry(v).or_default() += 1;
        }
    }
    let mut start_of: HashMap<u32, u32> = HashMap::default();
    for &(v, u) in next.keys() {
        start_of.entry(v).or_insert(u);
    }
    let mut verts: Vec<u32> = start_of.keys().copied().collect();
    verts.sort_unstable();
    for v in verts {
        let start = start_of[&v];
        let mut u = start;
        let mut steps = 0usize;
        loop {
            u = next[&(v, u)];
            steps += 1;
            if u == start || steps > incident[&v] {
                break;
            }
        }
        if steps != incident[&v] {
            return Err(TopologyError::NonManifoldVertex { vertex: v });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(f: &[&[u32]]) -> Result<(), TopologyError> {
        check_closed_manifold(f.iter().copied())
    }

    #[test]
    fn corners_close_only_once_each_way() {
        let close = |f: &[[u32; 3]], cycles| corners_close(f, cycles);
        let tet = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        assert!(close(&tet, true));
        assert!(close(&[] as &[[u32; 3]], true));
        assert!(!close(&tet[..3], false), "one way only");
        let mut twice = tet.to_vec();
        twice.extend(tet);
        assert!(!close(&twice, false), "twice each way");
        let mut one_way = tet.to_vec();
        one_way.push(tet[0]);
        assert!(!close(&one_way, false), "a face twice");
        // two tetrahedra sharing vertex 0: every edge pairs up, but the
        // link of 0 is two loops
        let mut pinch = tet.to_vec();
        pinch.extend([[0, 5, 4], [0, 4, 6], [0, 6, 5], [4, 5, 6]]);
        assert!(close(&pinch, false));
        assert!(!close(&pinch, true));
        // the largest ids
        let m = u32::MAX - 1;
        let big = tet.map(|t| t.map(|v| m - v));
        assert!(close(&big, true));
    }

    /// The pairwise check of a vertex's corners says what the sorting
    /// one says: random small links, closed (one loop or several),
    /// broken, and with repeats.
    #[test]
    fn small_links_are_checked_as_sorted_ones() {
        let mut rng = crate::tree::SplitMix(9);
        let mut seen = [0usize; 2];
        for _ in 0..20_000 {
            let k = 1 + rng.below(SMALL_LINK);
            // a permutation of k ids as the link's loop(s) ...
            let mut ids: Vec<u32> = (0..k as u32).map(|i| i * 3 + 1).collect();
            for i in (1..k).rev() {
                ids.swap(i, rng.below(i + 1));
            }
            let split = rng.below(k + 1);
            let mut g: Vec<(u32, u32)> = Vec::new();
            for part in [&ids[..split], &ids[split..]] {
                for (i, &u) in part.iter().enumerate() {
                    g.push((u, part[(i + 1) % part.len()]));
                }
            }
            // ... broken now and then
            match rng.below(4) {
                0 => {
                    let i = rng.below(k);
                    g[i].1 = ids[rng.below(k)];
                }
                1 => {
                    let i = rng.below(k);
                    g[i].0 = ids[rng.below(k)];
                }
                2 => g.swap(0, k - 1),
                _ => {}
            }
            for cycles in [false, true] {
                let want = corners_close_sorted(&g, cycles);
                assert_eq!(corners_close_small(&g, cycles), want, "{g:?} {cycles}");
                seen[want as usize] += 1;
            }
        }
        assert!(seen[0] > 1000 && seen[1] > 1000, "{seen:?}");
    }

    /// The parallel bucketing of corners gives what one pass in order
    /// gives: faces of 3 to 7 corners, enough for several runs.
    #[test]
    fn corners_bucket_in_parallel_as_in_order() {
        let mut rng = crate::tree::SplitMix(5);
        let faces: Vec<Vec<u32>> = (0..20_000)
            .map(|_| {
                (0..3 + rng.below(5))
                    .map(|_| rng.below(1 << 20) as u32)
                    .collect()
            })
            .collect();
        let mut start = vec![0usize];
        for f in &faces {
            start.push(start[start.len() - 1] + f.len());
        }
        let key = |f: &Vec<u32>, i: usize| (f[i] % 13) as usize;
        let got = bucket_par_corners(13, &faces, &start, key, |c, f, i| (c as u32, f[i]));
        let want = bucket(13, |emit| {
            for (fi, f) in faces.iter().enumerate() {
                for i in 0..f.len() {
                    emit(key(f, i), ((start[fi] + i) as u32, f[i]));
                }
            }
        });
        assert_eq!(got, want);
    }

    #[test]
    fn finds_each_defect() {
        let tet: [&[u32]; 4] = [&[0, 2, 1], &[0, 1, 3], &[0, 3, 2], &[1, 2, 3]];
        assert_eq!(check(&tet), Ok(()));
        assert!(matches!(
            check(&tet[..3]),
            Err(TopologyError::OpenEdge { .. })
        ));
        let flipped: [&[u32]; 4] = [&[0, 1, 2], &[0, 1, 3], &[0, 3, 2], &[1, 2, 3]];
        assert!(matches!(
            check(&flipped),
            Err(TopologyError::Misoriented { .. })
        ));
        assert!(matches!(
            check(&[&[0, 1, 1]]),
            Err(TopologyError::DegenerateFace { face: 0 })
        ));
        // two tetrahedra sharing only vertex 0: a pinch
        let pinch: [&[u32]; 8] = [
            &[0, 2, 1],
            &[0, 1, 3],
            &[0, 3, 2],
            &[1, 2, 3],
            &[0, 5, 4],
            &[0, 4, 6],
            &[0, 6, 5],
            &[4, 5, 6],
        ];
        assert_eq!(
            check(&pinch),
            Err(TopologyError::NonManifoldVertex { vertex: 0 })
        );
        // three faces on one edge
        let fin: [&[u32]; 3] = [&[0, 1, 2], &[1, 0, 3], &[0, 1, 4]];
        assert!(matches!(
            check(&fin),
            Err(TopologyError::Misoriented { .. } | TopologyError::NonManifoldEdge { .. })
        ));
    }
}
