//! Scanned-mesh scenes of any size: the Stanford bunny (a real scan,
//! kept in the repository), refined by √3-subdivision (Kobbelt 2000) and
//! standing on a ground quad.
//!
//! Each √3 step puts a vertex at the centre of every triangle, flips every
//! old edge and smooths the old vertices, so the face count triples while
//! the surface stays a smooth closed scan, not a faceted one: 3 674
//! triangles become 11 022, 33 066, 99 198, 297 594 and 892 782 after one
//! to five steps. The ground is one quad under the mesh, perpendicular to
//! `+y` (the bunny's up), twice as wide as the mesh.

use glam::DVec3;

use crate::mesh::{Face, Mesh};

/// The Stanford bunny (3 674 triangles; see `data/README.md`).
const BUNNY_OBJ: &str = include_str!("../../data/meshes/bunny.obj");

/// The largest number of √3 steps [`bunny`] takes.
pub const MAX_SUBDIVISIONS: u32 = 6;

/// One √3-subdivision step of a triangle mesh (triangles only; faces that
/// are not triangles are kept as they are). Edges with one face (a
/// boundary) are split to the new centre without a flip.
pub fn sqrt3_subdivide(mesh: &Mesh) -> Mesh {
    let n = mesh.positions.len();
    let (tris, groups): (Vec<[u32; 3]>, Vec<u32>) = mesh
        .faces
        .iter()
        .filter(|f| f.vertices.len() == 3)
        .map(|f| ([f.vertices[0], f.vertices[1], f.vertices[2]], f.group))
        .unzip();
    // neighbours of each old vertex, for the smoothing: each edge adds
    // its ends once, when it is first seen from either side
    let edges = Edges::new(n, &tris);
    let mut sum = vec![DVec3::ZERO; n];
    let mut count = vec![0u32; n];
    for (fi, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let e = (3 * fi + k) as u32;
            if edges.between(b, a).next().is_none_or(|f| f > e) {
                sum[a as usize] += mesh.positions[b as usize];
                sum[b as usize] += mesh.positions[a as usize];
                count[a as usize] += 1;
                count[b as usize] += 1;
            }
        }
    }
    let mut out = Mesh {
        positions: Vec::with_capacity(n + tris.len()),
        faces: Vec::with_capacity(tris.len() * 3),
        groups: mesh.groups.clone(),
    };
    for (i, p) in mesh.positions.iter().enumerate() {
        let k = count[i] as f64;
        out.positions.push(if k > 0.0 {
            let a = (4.0 - 2.0 * (2.0 * std::f64::consts::PI / k).cos()) / 9.0;
            *p * (1.0 - a) + sum[i] * (a / k)
        } else {
            *p
        });
    }
    let centre: Vec<u32> = tris
        .iter()
        .map(|t| {
            let c = t.iter().map(|&v| mesh.positions[v as usize]).sum::<DVec3>() / 3.0;
            out.positions.push(c);
            (out.positions.len() - 1) as u32
        })
        .collect();
    let mut push = |v: [u32; 3], g: u32| {
        out.faces.push(Face {
            vertices: v.to_vec(),
            line: 0,
            group: g,
        })
    };
    for (fi, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            // (the last triangle with the opposite edge, where several have it)
            match edges.between(b, a).last().map(|e| e as usize / 3) {
                // each interior edge once: the two triangles of the flip
                Some(g) if a < b => {
                    let (c, d) = (centre[fi], centre[g]);
                    push([a, d, c], groups[fi]);
                    push([b, c, d], groups[g]);
                }
                Some(_) => {}
                None => push([a, b, centre[fi]], groups[fi]),
            }
        }
    }
    for f in mesh.faces.iter().filter(|f| f.vertices.len() != 3) {
        out.faces.push(f.clone());
    }
    out
}

/// A triangle list's directed edges `a → b`, edge `k` of triangle `t`
/// numbered `3 t + k`, listed by their first vertex in their numbers'
/// order (each vertex's few edges side by side: a lookup of an edge reads
/// a handful of neighbours where a hash map's read its table at random).
struct Edges {
    /// Vertex `a`'s edges are `to[start[a]..start[a + 1]]`.
    start: Vec<usize>,
    /// Each edge's second vertex and number.
    to: Vec<(u32, u32)>,
}

impl Edges {
    fn new(vertices: usize, tris: &[[u32; 3]]) -> Edges {
        let (start, to) = crate::mesh::by_vertex(vertices, |emit| {
            for (fi, t) in tris.iter().enumerate() {
                for k in 0..3 {
                    emit(t[k], (t[(k + 1) % 3], (3 * fi + k) as u32));
                }
            }
        });
        Edges { start, to }
    }

    /// The numbers of the edges `a → b`, in increasing order.
    fn between(&self, a: u32, b: u32) -> impl Iterator<Item = u32> + '_ {
        self.to[self.start[a as usize]..self.start[a as usize + 1]]
            .iter()
            .filter(move |&&(to, _)| to == b)
            .map(|&(_, e)| e)
    }
}

/// The Stanford bunny after `subdivisions` √3 steps (at most
/// [`MAX_SUBDIVISIONS`]), standing on a ground quad (the last face, group
/// `ground`); the bunny is group `bunny`. `None` above the maximum.
///
/// ```
/// let m = shadow_scene::bunny(1).unwrap();
/// assert_eq!(m.faces.len(), 3 * 3674 + 1);
/// assert!(shadow_scene::bunny(7).is_none());
/// ```
pub fn bunny(subdivisions: u32) -> Option<Mesh> {
    if subdivisions > MAX_SUBDIVISIONS {
        return None;
    }
    let mut m = crate::parse_obj(BUNNY_OBJ, "bunny.obj").expect("the bundled bunny parses");
    m.groups = vec!["bunny".to_string()];
    for f in &mut m.faces {
        f.group = 0;
    }
    for _ in 0..subdivisions {
        m = sqrt3_subdivide(&m);
    }
    let (lo, hi) = m.bounds().expect("the bunny has vertices");
    let (c, half) = ((lo + hi) * 0.5, (hi - lo).max_element());
    let g = m.add_group("ground");
    let first = m.positions.len() as u32;
    for (dx, dz) in [(-1.0, 1.0), (1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)] {
        m.positions
            .push(DVec3::new(c.x + dx * half, lo.y, c.z + dz * half));
    }
    m.faces.push(Face {
        vertices: (first..first + 4).collect(),
        line: 0,
        group: g,
    });
    Some(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn subdivision_triples_faces_and_keeps_the_surface_closed() {
        let m = bunny(0).unwrap();
        assert_eq!(m.faces.len(), 3674 + 1);
        let one = bunny(1).unwrap();
        assert_eq!(one.faces.len(), 3 * 3674 + 1);
        assert_eq!(one.positions.len(), 1839 + 3674 + 4);
        // without the ground the refined bunny is still closed and
        // consistently oriented, with about the same volume
        let strip = |mut m: Mesh| {
            m.faces.pop();
            m
        };
        let (a, b) = (strip(m), strip(one));
        assert!(a.is_closed_oriented() && b.is_closed_oriented());
        let (va, vb) = (a.signed_volume(), b.signed_volume());
        assert!(va > 0.0 && (vb - va).abs() < 0.05 * va, "{va} {vb}");
        // the ground faces up, under the bunny
        let g = bunny(0).unwrap();
        let q = g.face_points(g.faces.len() - 1);
        let n = (q[1] - q[0]).cross(q[2] - q[0]);
        assert!(n.y > 0.0 && n.x == 0.0 && n.z == 0.0, "{n}");
        let (lo, _) = g.bounds().unwrap();
        assert!(q.iter().all(|p| p.y == lo.y));
        assert_eq!(g.group_name(g.faces.len() - 1), "ground");
    }
}
