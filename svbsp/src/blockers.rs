//! Occluders as area lights meet them: faces of one plane that share an
//! edge merged into one convex polygon wherever their union is convex.
//! A merged polygon blocks exactly the light its parts block, but as one
//! occluder its umbra is exact where the parts' umbra would only be
//! joint (undecided): a wall or a floor split into triangles hides the
//! light as the wall does.

use std::collections::HashMap;

use bsp_core::{GridPoint, Plane};

use crate::area::Occluder;

/// The faces' plane up to orientation: the same key for both sides.
pub(crate) fn plane_key(p: &Plane) -> ([i64; 3], i128) {
    let (n, d) = (p.normal(), p.offset());
    let first = n.iter().find(|&&c| c != 0).copied().unwrap_or(0);
    if first < 0 {
        (n.map(|c| -c), -d)
    } else {
        (n, d)
    }
}

/// The union of two convex polygons of one plane and one orientation that
/// share the edge `p → q` of `a` (`q → p` of `b`), as a corner list; `None`
/// where they share no edge.
fn joined(a: &[GridPoint], b: &[GridPoint]) -> Option<Vec<GridPoint>> {
    let (na, nb) = (a.len(), b.len());
    for i in 0..na {
        let (p, q) = (a[i], a[(i + 1) % na]);
        if let Some(j) = (0..nb).find(|&j| b[j] == q && b[(j + 1) % nb] == p) {
            // a from q round to p, then b after p round to before q
            let mut v: Vec<GridPoint> = (0..na).map(|k| a[(i + 1 + k) % na]).collect();
            v.extend((2..nb).map(|k| b[(j + k) % nb]));
            return Some(v);
        }
    }
    None
}

/// The faces as occluders: those of one plane merged, pair by pair along
/// shared edges, wherever the union is a strictly convex polygon. The
/// result does not depend on the faces' order (each plane's faces are
/// taken in the order of their corners).
pub(crate) fn coplanar_blockers(faces: &[Occluder]) -> Vec<Occluder> {
    coplanar_blockers_of(faces).0
}

/// [`coplanar_blockers`], with each blocker's faces (their numbers in
/// `faces`, ascending).
pub(crate) fn coplanar_blockers_of(faces: &[Occluder]) -> (Vec<Occluder>, Vec<Vec<u32>>) {
    type Group = Vec<(Vec<GridPoint>, Vec<u32>)>;
    let mut groups: HashMap<([i64; 3], i128), Group> = HashMap::new();
    for (i, f) in faces.iter().enumerate() {
        let key = plane_key(f.plane());
        let mut corners = f.corners().to_vec();
        // one orientation per plane: the key's
        if f.plane().normal() != key.0 {
            corners.reverse();
        }
        groups
            .entry(key)
            .or_default()
            .push((corners, vec![i as u32]));
    }
    let mut keys: Vec<_> = groups.keys().copied().collect();
    keys.sort_unstable();
    let mut out = Vec::new();
    for key in keys {
        let mut polys = groups.remove(&key).unwrap_or_default();
        polys.sort();
        out.extend(merge_group(polys));
    }
    // in the order of their corners: every face meets its occluders in
    // that order (index order), whatever order the faces came in
    out.sort_by(|a, b| a.0.corners().cmp(b.0.corners()));
    out.into_iter().unzip()
}

/// One plane's polygons merged until no two that share an edge have a
/// convex union.
fn merge_group(mut polys: Vec<(Vec<GridPoint>, Vec<u32>)>) -> Vec<(Occluder, Vec<u32>)> {
    let mut alive = vec![true; polys.len()];
    loop {
        let mut edges: HashMap<(GridPoint, GridPoint), usize> = HashMap::new();
        for (i, (p, _)) in polys.iter().enumerate().filter(|(i, _)| alive[*i]) {
            for k in 0..p.len() {
                edges.insert((p[k], p[(k + 1) % p.len()]), i);
            }
        }
        let mut changed = false;
        for i in 0..polys.len() {
            if !alive[i] {
                continue;
            }
            let n = polys[i].0.len();
            let partner = (0..n).find_map(|k| {
                let (p, q) = (polys[i].0[k], polys[i].0[(k + 1) % n]);
                let j = *edges.get(&(q, p))?;
                let union = (j != i && alive[j]).then(|| joined(&polys[i].0, &polys[j].0))??;
                let o = Occluder::new(&union).ok()?;
                Some((j, o.corners().to_vec()))
            });
            if let Some((j, union)) = partner {
                let mut from = std::mem::take(&mut polys[j].1);
                from.extend_from_slice(&polys[i].1);
                from.sort_unstable();
                polys[i] = (union, from);
                alive[j] = false;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    polys
        .into_iter()
        .zip(alive)
        .filter(|(_, a)| *a)
        .filter_map(|((p, from), _)| Some((Occluder::new(&p).ok()?, from)))
        .collect()
}
