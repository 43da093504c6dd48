//! Occluders as area lights meet them: faces of one plane that share an
//! edge merged into one convex polygon wherever their union is convex.
//! A merged polygon blocks exactly the light its parts block, but as one
//! occluder its umbra is exact where the parts' umbra would only be
//! joint (undecided): a wall or a floor split into triangles hides the
//! light as the wall does.

use std::collections::HashMap;

use bsp_core::{GridPoint, Plane};
use rayon::prelude::*;

use crate::area::Occluder;

/// The faces' plane up to orientation: the same key for both sides.
pub(crate) fn plane_key(p: &Plane) -> PlaneKey {
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
    // each face by its plane's key, in the key's orientation (one per
    // plane), then by its corners and number: each plane's faces are one
    // run, in the order of their corners
    let mut keyed: Vec<(PlaneKey, Vec<GridPoint>, u32)> = faces
        .par_iter()
        .enumerate()
        .map(|(i, f)| {
            let key = plane_key(f.plane());
            let mut corners = f.corners().to_vec();
            if f.plane().normal() != key.0 {
                corners.reverse();
            }
            (key, corners, i as u32)
        })
        .collect();
    keyed.par_sort_unstable();
    let runs: Vec<_> = keyed.chunk_by_mut(|a, b| a.0 == b.0).collect();
    let mut out: Vec<(Occluder, Vec<u32>)> = runs
        .into_par_iter()
        .flat_map_iter(|run| {
            let polys = run
                .iter_mut()
                .map(|(_, corners, i)| (std::mem::take(corners), vec![*i]))
                .collect();
            merge_group(polys)
        })
        .collect();
    // in the order of their corners: every face meets its occluders in
    // that order (index order), whatever order the faces came in
    out.par_sort_by(|a, b| a.0.corners().cmp(b.0.corners()));
    out.into_iter().unzip()
}

/// A plane up to orientation ([`plane_key`]).
pub(crate) type PlaneKey = ([i64; 3], i128);

/// One plane's polygons merged until no two that share an edge have a
/// convex union.
fn merge_group(mut polys: Vec<(Vec<GridPoint>, Vec<u32>)>) -> Vec<(Occluder, Vec<u32>)> {
    if let [(p, from)] = &mut polys[..] {
        let from = std::mem::take(from);
        return Occluder::new(p)
            .ok()
            .map(|o| (o, from))
            .into_iter()
            .collect();
    }
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
