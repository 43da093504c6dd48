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

/// The verdict of [`check_closed_manifold`] by parallel sorts, without
/// naming a defect: no face repeats a vertex, every directed edge is used
/// once and its reverse once (the sorted edges equal the sorted reversed
/// edges, without repeats), and around every vertex the corners
/// `u → v → w` form one cycle.
fn is_closed_manifold(faces: &[&[u32]]) -> bool {
    use rayon::prelude::*;
    let ok_faces = faces.par_iter().all(|f| {
        let mut v: smallvec::SmallVec<[u32; 8]> = f.iter().copied().collect();
        v.sort_unstable();
        f.len() >= 3 && v.windows(2).all(|w| w[0] != w[1])
    });
    if !ok_faces {
        return false;
    }
    let key = |a: u32, b: u32| (a as u64) << 32 | b as u64;
    // every directed edge used once and its reverse once
    let edges = per_corner(
        faces,
        |f| f.len(),
        |f, i| edge_key(f[i], f[(i + 1) % f.len()]),
    );
    if !edges_pair_up(edges) {
        return false;
    }
    // vertex links: (v, u) → w, sorted; each vertex's group is one cycle
    let mut link: Vec<(u64, u32)> = per_corner(
        faces,
        |f| f.len(),
        |f, i| {
            let k = f.len();
            (key(f[i], f[(i + k - 1) % k]), f[(i + 1) % k])
        },
    );
    link.par_sort_unstable();
    link.par_chunk_by(|x, y| x.0 >> 32 == y.0 >> 32).all(|g| {
        let v = g[0].0 >> 32;
        let next = |u: u32| {
            g.binary_search_by(|e| e.0.cmp(&(v << 32 | u as u64)))
                .ok()
                .map(|i| g[i].1)
        };
        let start = g[0].0 as u32;
        let mut u = start;
        let mut steps = 0usize;
        loop {
            match next(u) {
                Some(w) => u = w,
                None => return false,
            }
            steps += 1;
            if u == start || steps > g.len() {
                break;
            }
        }
        steps == g.len()
    })
}

/// The directed edge `a → b` (`a ≠ b`) as a sort key for
/// [`edges_pair_up`]: its undirected edge, then its direction.
#[inline]
pub(crate) fn edge_key(a: u32, b: u32) -> u128 {
    let (lo, hi, dir) = undirected(a, b);
    (lo as u128) << 64 | (hi as u128) << 1 | dir as u128
}

/// The edge `a → b` as its two ends in order and its direction (0 when
/// `a < b`).
#[inline]
pub(crate) fn undirected(a: u32, b: u32) -> (u32, u32, u32) {
    if a < b { (a, b, 0) } else { (b, a, 1) }
}

/// `true` if every directed edge of `edges` ([`edge_key`]s) is used once
/// and its reverse once: sorted, the keys come in pairs, both directions
/// of one edge, and no edge has a second pair. One parallel sort and one
/// scan.
pub(crate) fn edges_pair_up(mut edges: Vec<u128>) -> bool {
    use rayon::prelude::*;
    edges.par_sort_unstable();
    let n = edges.len();
    n.is_multiple_of(2)
        && (0..n / 2).into_par_iter().all(|i| {
            let (x, y) = (edges[2 * i], edges[2 * i + 1]);
            x >> 1 == y >> 1
                && x & 1 == 0
                && y & 1 == 1
                && edges.get(2 * i + 2).is_none_or(|z| z >> 1 != y >> 1)
        })
}

/// `item(face, i)` for every corner `i` of every face (`corners(face)` of
/// them), in order, in an array of exactly that size, filled in parallel
/// by runs of faces: no list per face, no growing.
pub(crate) fn per_corner<F: Sync, T: Copy + Default + Send + Sync>(
    faces: &[F],
    corners: impl Fn(&F) -> usize + Sync,
    item: impl Fn(&F, usize) -> T + Sync,
) -> Vec<T> {
    use rayon::prelude::*;
    const RUN: usize = 1024;
    let mut start = Vec::with_capacity(faces.len() / RUN + 2);
    let mut total = 0;
    for (k, f) in faces.iter().enumerate() {
        if k % RUN == 0 {
            start.push(total);
        }
        total += corners(f);
    }
    let mut out = vec![T::default(); total];
    let mut pieces = Vec::with_capacity(start.len());
    let mut rest = &mut out[..];
    for (r, &s) in start.iter().enumerate() {
        let end = start.get(r + 1).copied().unwrap_or(total);
        let (piece, tail) = rest.split_at_mut(end - s);
        pieces.push(piece);
        rest = tail;
    }
    pieces
        .into_par_iter()
        .zip(faces.par_chunks(RUN))
        .for_each(|(piece, fs)| {
            let mut o = piece.iter_mut();
            for f in fs {
                for (i, slot) in o.by_ref().take(corners(f)).enumerate() {
                    *slot = item(f, i);
                }
            }
        });
    out
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
    fn edges_pair_up_only_once_each_way() {
        let keys = |e: &[(u32, u32)]| e.iter().map(|&(a, b)| edge_key(a, b)).collect();
        assert!(edges_pair_up(keys(&[(0, 1), (1, 0), (2, 1), (1, 2)])));
        assert!(edges_pair_up(Vec::new()));
        assert!(!edges_pair_up(keys(&[(0, 1)])), "one way only");
        assert!(!edges_pair_up(keys(&[(0, 1), (0, 1)])), "twice one way");
        assert!(
            !edges_pair_up(keys(&[(0, 1), (1, 0), (0, 1), (1, 0)])),
            "twice each way"
        );
        assert!(!edges_pair_up(keys(&[(0, 1), (1, 2)])), "two one-way edges");
        // the largest ids keep their direction bit apart
        let m = u32::MAX;
        assert!(edges_pair_up(keys(&[(m, m - 1), (m - 1, m)])));
        assert!(!edges_pair_up(keys(&[(m, m - 1), (m, m - 1)])));
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
