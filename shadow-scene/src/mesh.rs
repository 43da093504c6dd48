//! The mesh type and its geometric helpers.

use std::collections::{HashMap, HashSet};

use glam::DVec3;

/// One face of a mesh: a loop of vertex indices.
#[derive(Clone, Debug, PartialEq)]
pub struct Face {
    /// Indices into [`Mesh::positions`], in the file's order.
    pub vertices: Vec<u32>,
    /// 1-based source line of the face, 0 for generated faces.
    pub line: usize,
    /// Index into [`Mesh::groups`].
    pub group: u32,
}

/// A polygon mesh or soup in input units.
///
/// Faces keep their vertex count: quads stay quads and n-gons stay n-gons.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Faces, in the file's order.
    pub faces: Vec<Face>,
    /// Group / object names (at least one, "default", in meshes made by
    /// this crate's readers).
    pub groups: Vec<String>,
}

/// What the writers ([`crate::write_obj`], [`crate::write_stl`],
/// [`crate::save`]) read of a mesh: its positions and its faces, each a
/// loop of vertex indices in a group. A [`Mesh`] is one; [`Triangles`], a
/// triangle list beside its positions, is another that needs no list per
/// face.
pub trait MeshView: Sync {
    /// Vertex positions.
    fn positions(&self) -> &[DVec3];
    /// Number of faces.
    fn face_count(&self) -> usize;
    /// Face `i`'s vertex loop (indices into [`MeshView::positions`]).
    fn face(&self, i: usize) -> &[u32];
    /// Face `i`'s group, named by [`MeshView::group_name`].
    fn group(&self, i: usize) -> u32;
    /// The name of group `g`, if it has one.
    fn group_name(&self, g: u32) -> Option<&str>;

    /// How many of the vertices used by faces repeat the position of
    /// another used vertex (`-0.0` equals `0.0`): the number of vertices
    /// [`Mesh::weld`] would merge away. Non-zero for files that store the
    /// corners of every face separately.
    ///
    /// ```
    /// use shadow_scene::{MeshView, parse_obj};
    /// let soup = parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 4 6 5\n", "s.obj").unwrap();
    /// assert_eq!(soup.repeated_positions(), 2);
    /// ```
    fn repeated_positions(&self) -> usize {
        let mut seen: rustc_hash::FxHashSet<[u64; 3]> = Default::default();
        used_positions(self)
            .filter(|p| !seen.insert(key(**p)))
            .count()
    }

    /// How many triangles have three distinct corners that lie exactly on
    /// one line once each position is mapped by `round` (the identity for
    /// `f64` files, a rounding to `f32` for STL): the faces a reader would
    /// find flat ([`Mesh::split_flat_triangles`] takes them out).
    fn flat_triangles(&self, round: fn(DVec3) -> DVec3) -> usize {
        use rayon::prelude::*;
        let positions = self.positions();
        (0..self.face_count())
            .into_par_iter()
            .filter(|&f| flat(self.face(f), |v| round(positions[v as usize])))
            .count()
    }
}

/// Items grouped by vertex, by a counting sort: `each` calls `emit(v,
/// item)` for every item, the same calls each time it runs (twice: to
/// count, then to place); vertex `v`'s items are
/// `items[start[v]..start[v + 1]]`, in the order they were emitted.
pub(crate) fn by_vertex<T: Copy + Default>(
    vertices: usize,
    each: impl Fn(&mut dyn FnMut(u32, T)),
) -> (Vec<usize>, Vec<T>) {
    let mut start = vec![0usize; vertices + 1];
    each(&mut |v, _| start[v as usize + 1] += 1);
    for k in 1..start.len() {
        start[k] += start[k - 1];
    }
    let mut next = start.clone();
    let mut items = vec![T::default(); start[vertices]];
    each(&mut |v, item| {
        items[next[v as usize]] = item;
        next[v as usize] += 1;
    });
    (start, items)
}

/// The positions some face uses, in order (each once).
pub(crate) fn used_positions<M: MeshView + ?Sized>(mesh: &M) -> impl Iterator<Item = &DVec3> {
    let positions = mesh.positions();
    let mut used = vec![false; positions.len()];
    for v in (0..mesh.face_count()).flat_map(|f| mesh.face(f)) {
        used[*v as usize] = true;
    }
    positions
        .iter()
        .zip(used)
        .filter(|(_, u)| *u)
        .map(|(p, _)| p)
}

impl MeshView for Mesh {
    fn positions(&self) -> &[DVec3] {
        &self.positions
    }

    fn face_count(&self) -> usize {
        self.faces.len()
    }

    fn face(&self, i: usize) -> &[u32] {
        &self.faces[i].vertices
    }

    fn group(&self, i: usize) -> u32 {
        self.faces[i].group
    }

    fn group_name(&self, g: u32) -> Option<&str> {
        self.groups.get(g as usize).map(String::as_str)
    }
}

/// Triangles beside their positions, all in one group: a mesh to write
/// ([`MeshView`]) with no list per face, as a large result is made.
///
/// ```
/// use glam::DVec3;
/// use shadow_scene::{MeshView, Triangles};
/// let positions = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
/// let triangles = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
/// let tet = Triangles { positions: &positions, triangles: &triangles, group: "tet" };
/// assert_eq!(tet.face(3), &[1, 2, 3]);
/// assert!(tet.to_mesh().is_closed_oriented());
/// ```
#[derive(Clone, Copy, Debug)]
pub struct Triangles<'a> {
    /// Vertex positions.
    pub positions: &'a [DVec3],
    /// Counter-clockwise triangles (indices into `positions`).
    pub triangles: &'a [[u32; 3]],
    /// The one group's name.
    pub group: &'a str,
}

impl Triangles<'_> {
    /// The same faces as a [`Mesh`] (one [`Face`] per triangle).
    pub fn to_mesh(&self) -> Mesh {
        Mesh {
            positions: self.positions.to_vec(),
            faces: self
                .triangles
                .iter()
                .map(|t| Face {
                    vertices: t.to_vec(),
                    line: 0,
                    group: 0,
                })
                .collect(),
            groups: vec![self.group.to_string()],
        }
    }
}

impl MeshView for Triangles<'_> {
    fn positions(&self) -> &[DVec3] {
        self.positions
    }

    fn face_count(&self) -> usize {
        self.triangles.len()
    }

    fn face(&self, i: usize) -> &[u32] {
        &self.triangles[i]
    }

    fn group(&self, _: usize) -> u32 {
        0
    }

    fn group_name(&self, g: u32) -> Option<&str> {
        (g == 0).then_some(self.group)
    }
}

/// Bit pattern of a position, with `-0.0` read as `0.0`, so that equal
/// values get equal keys.
pub(crate) fn key(p: DVec3) -> [u64; 3] {
    // adding +0.0 turns -0.0 into +0.0 and leaves every other value alone
    [p.x, p.y, p.z].map(|c| (c + 0.0).to_bits())
}

/// `true` if `a`, `b` and `c` lie exactly on one line: the three
/// components of `(b − a) × (c − a)` are the orientations of the points'
/// projections on the three coordinate planes, each of whose signs
/// `robust` computes exactly.
pub fn collinear(a: DVec3, b: DVec3, c: DVec3) -> bool {
    let o = |i: usize, j: usize| {
        let q = |p: DVec3| robust::Coord { x: p[i], y: p[j] };
        robust::orient2d(q(a), q(b), q(c))
    };
    o(0, 1) == 0.0 && o(1, 2) == 0.0 && o(2, 0) == 0.0
}

/// `true` if `face` is a triangle whose three corners (positions by
/// `at`) are distinct and lie exactly on one line.
fn flat(face: &[u32], at: impl Fn(u32) -> DVec3) -> bool {
    let &[a, b, c] = face else {
        return false;
    };
    let [pa, pb, pc] = [a, b, c].map(at);
    key(pa) != key(pb) && key(pb) != key(pc) && key(pc) != key(pa) && collinear(pa, pb, pc)
}

/// The 26 positions one `step` from `at` along one, two or three axes,
/// the nearest to `to` first (ties in a fixed order).
fn neighbours(at: DVec3, to: DVec3, step: fn(f64, bool) -> f64) -> Vec<DVec3> {
    let mut near: Vec<(f64, DVec3)> = (0..27u32)
        .filter(|&d| d != 13)
        .map(|d| {
            let c = |x: f64, k: u32| match (d / 3u32.pow(k)) % 3 {
                0 => step(x, false),
                1 => x,
                _ => step(x, true),
            };
            let q = DVec3::new(c(at.x, 0), c(at.y, 1), c(at.z, 2));
            (q.distance_squared(to), q)
        })
        .collect();
    near.sort_by(|a, b| a.0.total_cmp(&b.0));
    near.into_iter().map(|(_, q)| q).collect()
}

/// The directed edges of a vertex loop, in order.
fn ring(v: &[u32]) -> impl Iterator<Item = (u32, u32)> + '_ {
    (0..v.len()).map(move |i| (v[i], v[(i + 1) % v.len()]))
}

/// `true` if `m` lies between `p` and `q` along every axis (for collinear
/// points: on the segment `pq`).
fn between(m: DVec3, p: DVec3, q: DVec3) -> bool {
    (0..3).all(|i| p[i].min(q[i]) <= m[i] && m[i] <= p[i].max(q[i]))
}

/// What [`Mesh::round_positions`] mended.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Rounding {
    /// Faces left out because rounding made their corners one position.
    pub collapsed: usize,
    /// Flat triangles split away.
    pub flattened: usize,
    /// Flat triangles that stay ([`FlatFix::left`]).
    pub left_flat: usize,
    /// Vertices moved one step of the rounded format off their rounded
    /// position, to keep them apart from another vertex rounded there
    /// ([`Mesh::round_positions_apart`]).
    pub moved: usize,
}

/// `p` rounded to `f32` and back: the positions an STL file holds.
pub fn to_f32(p: DVec3) -> DVec3 {
    p.as_vec3().as_dvec3()
}

/// The `f32` next to `x` (itself an `f32` value), above it if `up`.
pub fn f32_step(x: f64, up: bool) -> f64 {
    let x = x as f32;
    f64::from(if up { x.next_up() } else { x.next_down() })
}

/// The `f64` next to `x`, above it if `up`.
pub fn f64_step(x: f64, up: bool) -> f64 {
    if up { x.next_up() } else { x.next_down() }
}

/// What [`Mesh::split_flat_triangles`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FlatFix {
    /// Flat triangles taken out (of those there were at the start).
    pub removed: usize,
    /// Flat triangles that stay (no single face across the long edge).
    pub left: usize,
}

impl Mesh {
    /// The positions of face `i`'s vertices.
    pub fn face_points(&self, i: usize) -> Vec<DVec3> {
        self.faces[i]
            .vertices
            .iter()
            .map(|&v| self.positions[v as usize])
            .collect()
    }

    /// Every face as a loop of positions.
    pub fn face_loops(&self) -> Vec<Vec<DVec3>> {
        (0..self.faces.len()).map(|i| self.face_points(i)).collect()
    }

    /// The axis-aligned bounding box `(min, max)` of all positions, `None`
    /// for a mesh without positions.
    ///
    /// ```
    /// use shadow_scene::parse_obj;
    /// use glam::DVec3;
    /// let m = parse_obj("v 0 0 0\nv 2 1 0\nv 0 1 -3\nf 1 2 3\n", "t.obj").unwrap();
    /// assert_eq!(m.bounds(), Some((DVec3::new(0., 0., -3.), DVec3::new(2., 1., 0.))));
    /// ```
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        let first = *self.positions.first()?;
        Some(
            self.positions
                .iter()
                .fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p))),
        )
    }

    /// Number of triangles a fan triangulation of every face would give
    /// (`n - 2` per face of `n` vertices).
    ///
    /// ```
    /// let room = shadow_scene::room();
    /// assert!(room.triangle_count() > room.faces.len());
    /// ```
    pub fn triangle_count(&self) -> usize {
        self.faces
            .iter()
            .map(|f| f.vertices.len().saturating_sub(2))
            .sum()
    }

    /// The index of the group called `name`.
    ///
    /// ```
    /// let room = shadow_scene::room();
    /// let axes = room.group_index("axes").unwrap();
    /// assert!(room.faces.iter().any(|f| f.group == axes));
    /// assert_eq!(room.group_index("no such group"), None);
    /// ```
    pub fn group_index(&self, name: &str) -> Option<u32> {
        self.groups.iter().position(|g| g == name).map(|i| i as u32)
    }

    /// The index of the group called `name`, appended if it is new.
    pub fn add_group(&mut self, name: &str) -> u32 {
        self.group_index(name).unwrap_or_else(|| {
            self.groups.push(name.to_string());
            (self.groups.len() - 1) as u32
        })
    }

    /// The name of face `i`'s group (`""` if the group index is out of
    /// range).
    ///
    /// ```
    /// let room = shadow_scene::room();
    /// assert_eq!(room.group_name(0), "floor");
    /// ```
    pub fn group_name(&self, i: usize) -> &str {
        self.groups
            .get(self.faces[i].group as usize)
            .map_or("", String::as_str)
    }

    /// The centre (the mean of the corners) of every face.
    ///
    /// ```
    /// let cube = shadow_scene::scene("cube").unwrap();
    /// let centres = cube.face_centres();
    /// assert_eq!(centres.len(), cube.faces.len());
    /// ```
    pub fn face_centres(&self) -> Vec<DVec3> {
        (0..self.faces.len())
            .map(|f| {
                let pts = self.face_points(f);
                pts.iter().sum::<DVec3>() / pts.len().max(1) as f64
            })
            .collect()
    }

    /// Each face's unit normal by Newell's sum over its loop (zero for a
    /// face without area), turned as its loop turns counter-clockwise.
    ///
    /// ```
    /// let cube = shadow_scene::scene("cube").unwrap();
    /// let up = cube.face_normals().into_iter().filter(|n| n.z == 1.0).count();
    /// assert_eq!(up, 1);
    /// ```
    pub fn face_normals(&self) -> Vec<DVec3> {
        (0..self.faces.len())
            .map(|f| unit_or_zero(newell(&self.face_points(f))))
            .collect()
    }

    /// The connected parts of the faces (faces sharing a vertex are in one
    /// part), numbered in the order of their first face: each face's part.
    ///
    /// ```
    /// use shadow_scene::{Face, Mesh};
    /// use glam::DVec3;
    /// let f = |vertices: Vec<u32>| Face { vertices, line: 0, group: 0 };
    /// let m = Mesh {
    ///     positions: vec![DVec3::ZERO; 7],
    ///     faces: vec![f(vec![4, 5, 6]), f(vec![0, 1, 2]), f(vec![2, 3, 1])],
    ///     groups: vec!["default".into()],
    /// };
    /// assert_eq!(m.parts(), vec![0, 1, 1]);
    /// ```
    pub fn parts(&self) -> Vec<usize> {
        // the faces around each vertex
        let (first, around) = by_vertex(self.positions.len(), |emit| {
            for (i, f) in self.faces.iter().enumerate() {
                for &v in &f.vertices {
                    emit(v, i as u32);
                }
            }
        });
        // each part by a walk from its first face
        const UNSEEN: usize = usize::MAX;
        let mut part = vec![UNSEEN; self.faces.len()];
        let mut count = 0;
        let mut stack = Vec::new();
        for start in 0..self.faces.len() {
            if part[start] != UNSEEN {
                continue;
            }
            part[start] = count;
            stack.push(start);
            while let Some(f) = stack.pop() {
                for &v in &self.faces[f].vertices {
                    for &g in &around[first[v as usize]..first[v as usize + 1]] {
                        if part[g as usize] == UNSEEN {
                            part[g as usize] = count;
                            stack.push(g as usize);
                        }
                    }
                }
            }
            count += 1;
        }
        part
    }

    /// Merges vertices with exactly equal positions (`-0.0` equals `0.0`)
    /// and drops positions no face uses; faces keep their order and
    /// vertex loops.
    ///
    /// ```
    /// use shadow_scene::{Face, Mesh};
    /// use glam::DVec3;
    /// let mut m = Mesh {
    ///     positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::X, DVec3::Y, DVec3::ONE],
    ///     faces: vec![
    ///         Face { vertices: vec![0, 1, 2], line: 0, group: 0 },
    ///         Face { vertices: vec![3, 5, 4], line: 0, group: 0 },
    ///     ],
    ///     groups: vec!["default".into()],
    /// };
    /// m.weld();
    /// assert_eq!(m.positions.len(), 4);
    /// assert_eq!(m.faces[1].vertices, vec![1, 3, 2]);
    /// ```
    pub fn weld(&mut self) {
        let mut index: rustc_hash::FxHashMap<[u64; 3], u32> = Default::default();
        let mut positions = Vec::new();
        let mut map = vec![u32::MAX; self.positions.len()];
        for f in &mut self.faces {
            for v in &mut f.vertices {
                let old = *v as usize;
                if map[old] == u32::MAX {
                    let p = self.positions[old];
                    map[old] = *index.entry(key(p)).or_insert_with(|| {
                        positions.push(p);
                        (positions.len() - 1) as u32
                    });
                }
                *v = map[old];
            }
        }
        self.positions = positions;
    }

    /// Takes out of each face the corners that repeat the one before
    /// (around the loop), as [`Mesh::weld`] makes them where distinct
    /// vertices share a position, and drops the faces left with fewer
    /// than three: on a closed surface this collapses the edges between
    /// equal positions (the surface stays closed where each collapsed
    /// edge's ends have only its two faces' third corners as common
    /// neighbours; [`Mesh::is_closed_oriented`] tells). Returns the
    /// indices of the faces dropped, in order.
    ///
    /// ```
    /// use shadow_scene::{Face, Mesh};
    /// let face = |v: Vec<u32>| Face { vertices: v, line: 0, group: 0 };
    /// let mut m = Mesh {
    ///     positions: vec![glam::DVec3::ZERO; 4],
    ///     faces: vec![face(vec![0, 1, 1]), face(vec![0, 1, 1, 2, 3, 0])],
    ///     groups: vec!["default".into()],
    /// };
    /// assert_eq!(m.collapse_repeats(), vec![0]);
    /// assert_eq!(m.faces[0].vertices, vec![0, 1, 2, 3]);
    /// ```
    pub fn collapse_repeats(&mut self) -> Vec<usize> {
        let mut dropped = Vec::new();
        let mut i = 0;
        self.faces.retain_mut(|f| {
            f.vertices.dedup();
            while f.vertices.len() > 1 && f.vertices.first() == f.vertices.last() {
                f.vertices.pop();
            }
            let keep = f.vertices.len() >= 3;
            if !keep {
                dropped.push(i);
            }
            i += 1;
            keep
        });
        dropped
    }

    /// Rounds every position with `round` (to `f32` for STL, say) and
    /// mends what rounding did to a closed surface: vertices that became
    /// equal are welded ([`Mesh::weld`]), the faces that collapse are left
    /// out ([`Mesh::collapse_repeats`]) and triangles that became flat are
    /// split away ([`Mesh::split_flat_triangles`]).
    pub fn round_positions(&mut self, round: fn(DVec3) -> DVec3) -> Rounding {
        for p in &mut self.positions {
            *p = round(*p);
        }
        self.mend(0)
    }

    /// Welds, leaves out what collapses and splits flat triangles away,
    /// after rounding that moved `moved` vertices apart.
    fn mend(&mut self, moved: usize) -> Rounding {
        self.weld();
        let collapsed = self.collapse_repeats().len();
        let flat = self.split_flat_triangles();
        Rounding {
            collapsed,
            flattened: flat.removed,
            left_flat: flat.left,
            moved,
        }
    }

    /// Rounds every position with `round` as a file holds it, keeping a
    /// closed, oriented surface so as read back where it can: as
    /// [`Mesh::round_positions`] does (weld, leave out what collapses,
    /// split flat triangles away), and where that pinches the surface or
    /// leaves a flat triangle, as [`Mesh::round_positions_apart`] does
    /// instead, if that keeps it closed. Returns what it did and whether
    /// the mesh is closed and oriented with no flat triangle
    /// ([`Mesh::is_closed_oriented`]).
    pub fn round_closed(
        &mut self,
        round: fn(DVec3) -> DVec3,
        step: fn(f64, bool) -> f64,
    ) -> (Rounding, bool) {
        let before = self.clone();
        let r = self.round_positions(round);
        if r.left_flat == 0 && self.is_closed_oriented() {
            return (r, true);
        }
        let mut apart = before;
        let a = apart.round_positions_apart(round, step);
        if a.left_flat == 0 && apart.is_closed_oriented() {
            *self = apart;
            return (a, true);
        }
        (r, false)
    }

    /// Rounds every position with `round` like [`Mesh::round_positions`],
    /// but keeps distinct positions distinct and triangles off one line
    /// where it can, by moving vertices one step of the rounded format
    /// (`step` moves one coordinate one value up or down, e.g.
    /// [`f32_step`]) to one of the 26 neighbouring positions, the nearest
    /// to the vertex's position before rounding first:
    /// - a vertex that rounds onto a position an earlier vertex (by
    ///   index) took moves to a free neighbour;
    /// - a triangle that rounding made flat has one of its corners, the
    ///   middle one first, moved to a free neighbour where none of that
    ///   corner's triangles is flat.
    ///
    /// So where welding would pinch a closed surface (two sheets closer
    /// than the format resolves, made one), the surface stays closed as
    /// read back; each coordinate then lies within one and a half steps,
    /// not half a step, of its value before rounding. What finds no free
    /// neighbour is welded and split away as [`Mesh::round_positions`]
    /// does. The result does not depend on hashing: vertices go in index
    /// order, candidates by distance with ties in a fixed order.
    ///
    /// ```
    /// use glam::DVec3;
    /// use shadow_scene::{Face, Mesh, f32_step, to_f32};
    /// let face = |v: [u32; 3]| Face { vertices: v.to_vec(), line: 0, group: 0 };
    /// // a flat double pyramid: apexes 2^-30 above and below its base at
    /// // z = 1, where f32 steps are 2^-24 and 2^-23
    /// let h = 2f64.powi(-30);
    /// let mut m = Mesh {
    ///     positions: vec![
    ///         DVec3::Z, DVec3::new(1.0, 0.0, 1.0), DVec3::new(0.0, 1.0, 1.0),
    ///         DVec3::new(0.25, 0.25, 1.0 + h), DVec3::new(0.25, 0.25, 1.0 - h),
    ///     ],
    ///     faces: [[0, 1, 3], [1, 2, 3], [2, 0, 3], [1, 0, 4], [2, 1, 4], [0, 2, 4]]
    ///         .map(face).to_vec(),
    ///     groups: vec!["default".into()],
    /// };
    /// let mut welded = m.clone();
    /// welded.round_positions(to_f32);
    /// assert!(!welded.is_closed_oriented()); // the apexes became one
    /// let r = m.round_positions_apart(to_f32, f32_step);
    /// assert_eq!(r.moved, 1); // the lower apex, one step (2^-26) along y
    /// assert_eq!(m.positions[4], DVec3::new(0.25, 0.25 - 2f64.powi(-26), 1.0));
    /// assert!(m.is_closed_oriented());
    /// ```
    pub fn round_positions_apart(
        &mut self,
        round: fn(DVec3) -> DVec3,
        step: fn(f64, bool) -> f64,
    ) -> Rounding {
        let before = std::mem::take(&mut self.positions);
        self.positions = before.iter().map(|&p| round(p)).collect();
        let mut taken: rustc_hash::FxHashMap<[u64; 3], u32> = Default::default();
        let mut moved = vec![false; before.len()];
        for i in 0..before.len() {
            if taken.insert(key(self.positions[i]), i as u32).is_some() {
                let at = self.positions[i];
                if let Some(q) = neighbours(at, before[i], step)
                    .into_iter()
                    .find(|q| !taken.contains_key(&key(*q)))
                {
                    taken.insert(key(q), i as u32);
                    self.positions[i] = q;
                    moved[i] = true;
                }
            }
        }
        self.nudge_flat(&before, &mut taken, &mut moved, step);
        self.mend(moved.iter().filter(|&&m| m).count())
    }

    /// Moves a corner of each flat triangle one step off the line (see
    /// [`Mesh::round_positions_apart`]).
    fn nudge_flat(
        &mut self,
        before: &[DVec3],
        taken: &mut rustc_hash::FxHashMap<[u64; 3], u32>,
        moved: &mut [bool],
        step: fn(f64, bool) -> f64,
    ) {
        let flat_at = |positions: &[DVec3], f: &Face| flat(&f.vertices, |v| positions[v as usize]);
        let queue: Vec<usize> = (0..self.faces.len())
            .filter(|&i| flat_at(&self.positions, &self.faces[i]))
            .collect();
        if queue.is_empty() {
            return;
        }
        let mut around: Vec<Vec<u32>> = vec![Vec::new(); self.positions.len()];
        for (i, f) in self.faces.iter().enumerate() {
            for &v in &f.vertices {
                around[v as usize].push(i as u32);
            }
        }
        for t in queue {
            let positions = &self.positions;
            if !flat_at(positions, &self.faces[t]) {
                continue;
            }
            let v: [u32; 3] = [0, 1, 2].map(|k| self.faces[t].vertices[k]);
            let at = |k: usize| positions[v[k] as usize];
            let middle = (0..3)
                .find(|&k| between(at(k), at((k + 1) % 3), at((k + 2) % 3)))
                .unwrap_or(0);
            'corners: for k in [middle, (middle + 1) % 3, (middle + 2) % 3] {
                let c = v[k] as usize;
                let here = self.positions[c];
                for q in neighbours(here, before[c], step) {
                    if taken.contains_key(&key(q)) {
                        continue;
                    }
                    self.positions[c] = q;
                    let faces = &self.faces;
                    if around[c]
                        .iter()
                        .all(|&f| !flat_at(&self.positions, &faces[f as usize]))
                    {
                        if taken.get(&key(here)) == Some(&(c as u32)) {
                            taken.remove(&key(here));
                        }
                        taken.insert(key(q), c as u32);
                        moved[c] = true;
                        break 'corners;
                    }
                    self.positions[c] = here;
                }
            }
        }
    }

    /// Takes out the triangles whose three distinct corners lie exactly
    /// on one line (zero-area faces, as rounding a closed surface's
    /// vertices can make them) without opening the surface: the middle
    /// corner lies on the triangle's long edge, so the face across that
    /// edge is split there in two (or, where that face is the same flat
    /// triangle turned over, both go). The surface's points are unchanged,
    /// so it stays closed and oriented, and its volume is the same.
    /// Collinearity is decided exactly ([`collinear`]). A flat triangle
    /// whose long edge has no single face across it (an open or
    /// non-manifold surface) stays, and is counted in
    /// [`FlatFix::left`].
    ///
    /// ```
    /// use glam::DVec3;
    /// use shadow_scene::{Face, Mesh};
    /// let face = |v: Vec<u32>| Face { vertices: v, line: 0, group: 0 };
    /// // a tetrahedron whose edge 0-1 carries its midpoint 4, with the flat
    /// // triangle (1, 4, 0) filling the notch
    /// let mut m = Mesh {
    ///     positions: vec![
    ///         DVec3::ZERO, DVec3::new(2.0, 0.0, 0.0), DVec3::new(0.0, 2.0, 0.0),
    ///         DVec3::new(0.0, 0.0, 2.0), DVec3::new(1.0, 0.0, 0.0),
    ///     ],
    ///     faces: [[0, 4, 3], [4, 1, 3], [1, 4, 0], [1, 0, 2], [1, 2, 3], [0, 3, 2]]
    ///         .map(|f| face(f.to_vec())).to_vec(),
    ///     groups: vec!["default".into()],
    /// };
    /// assert!(m.is_closed_oriented());
    /// let fix = m.split_flat_triangles();
    /// assert_eq!((fix.removed, fix.left), (1, 0));
    /// assert!(m.is_closed_oriented() && m.faces.len() == 6);
    /// assert_eq!(m.signed_volume(), 8.0 / 6.0);
    /// ```
    pub fn split_flat_triangles(&mut self) -> FlatFix {
        let positions = &self.positions;
        let is_flat = |f: &Face| flat(&f.vertices, |v| positions[v as usize]);
        let mut queue: Vec<usize> = (0..self.faces.len())
            .filter(|&i| is_flat(&self.faces[i]))
            .collect();
        if queue.is_empty() {
            return FlatFix::default();
        }
        // directed edge → its face; `usize::MAX` where several faces use it
        const SHARED: usize = usize::MAX;
        let mut edges: rustc_hash::FxHashMap<(u32, u32), usize> = Default::default();
        for (i, f) in self.faces.iter().enumerate() {
            for e in ring(&f.vertices) {
                edges.entry(e).and_modify(|x| *x = SHARED).or_insert(i);
            }
        }
        let mut alive = vec![true; self.faces.len()];
        let at_start = queue.len();
        // each step takes one flat triangle out and may make two: bounded
        let mut budget = 8 * queue.len() + 64;
        while let Some(t) = queue.pop() {
            if budget == 0 {
                break;
            }
            budget -= 1;
            if !alive[t] || !is_flat(&self.faces[t]) {
                continue;
            }
            let v: [u32; 3] = self.faces[t].vertices[..]
                .try_into()
                .expect("a flat face is a triangle");
            let at = |i: usize| self.positions[v[i] as usize];
            let i = (0..3)
                .find(|&i| between(at(i), at((i + 1) % 3), at((i + 2) % 3)))
                .expect("one of three distinct collinear points lies between the others");
            let (m, p, q) = (v[i], v[(i + 1) % 3], v[(i + 2) % 3]);
            let n = match edges.get(&(q, p)) {
                Some(&n) if n != SHARED && alive[n] && self.faces[n].vertices.len() == 3 => n,
                _ => continue,
            };
            let nv = &self.faces[n].vertices;
            let k = nv
                .iter()
                .position(|&x| x == q)
                .expect("the edge's face has it");
            let d = nv[(k + 2) % 3];
            let unlink = |f: &Face, i: usize, edges: &mut rustc_hash::FxHashMap<_, _>| {
                for e in ring(&f.vertices) {
                    if edges.get(&e) == Some(&i) {
                        edges.remove(&e);
                    }
                }
            };
            unlink(&self.faces[t], t, &mut edges);
            unlink(&self.faces[n], n, &mut edges);
            alive[t] = false;
            if d == m {
                // the same flat triangle turned over: the two close each other
                alive[n] = false;
                continue;
            }
            let (line, group) = (self.faces[n].line, self.faces[n].group);
            self.faces[n].vertices = vec![q, m, d];
            self.faces.push(Face {
                vertices: vec![m, p, d],
                line,
                group,
            });
            alive.push(true);
            for j in [n, self.faces.len() - 1] {
                for e in ring(&self.faces[j].vertices) {
                    edges.entry(e).and_modify(|x| *x = SHARED).or_insert(j);
                }
                if is_flat(&self.faces[j]) {
                    queue.push(j);
                }
            }
        }
        let mut alive = alive.into_iter();
        self.faces.retain(|_| alive.next().unwrap_or(true));
        let left = self.faces.iter().filter(|f| is_flat(f)).count();
        FlatFix {
            removed: at_start.saturating_sub(left),
            left,
        }
    }

    /// `true` if every directed edge `a → b` of every face appears exactly
    /// once and its reverse `b → a` exactly once: the faces (compared by
    /// vertex index, so weld first) bound closed, consistently oriented
    /// surfaces without T-junctions.
    ///
    /// ```
    /// let chair = shadow_scene::scene("chair").unwrap();
    /// assert!(chair.is_closed_oriented());
    /// ```
    pub fn is_closed_oriented(&self) -> bool {
        let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
        for f in &self.faces {
            let n = f.vertices.len();
            for i in 0..n {
                *edges
                    .entry((f.vertices[i], f.vertices[(i + 1) % n]))
                    .or_default() += 1;
            }
        }
        edges
            .iter()
            .all(|(&(a, b), &c)| c == 1 && edges.get(&(b, a)) == Some(&1))
    }

    /// The signed volume enclosed by the faces (positive for closed
    /// surfaces whose faces are counter-clockwise seen from outside), in
    /// `f64`.
    ///
    /// ```
    /// let cube = shadow_scene::scene("cube").unwrap();
    /// assert_eq!(cube.signed_volume(), 1.0);
    /// ```
    pub fn signed_volume(&self) -> f64 {
        let mut six_v = 0.0;
        for f in &self.faces {
            let p = |i: usize| self.positions[f.vertices[i] as usize];
            for i in 1..f.vertices.len().saturating_sub(1) {
                six_v += p(0).dot(p(i).cross(p(i + 1)));
            }
        }
        six_v / 6.0
    }

    /// The mesh split in two: the faces of every other group, and the
    /// faces of group `name`, each with only the positions it uses (in
    /// their order) and the same group list. `None` if there is no such
    /// group.
    ///
    /// ```
    /// let room = shadow_scene::room();
    /// let (rest, axes) = room.split_off_group("axes").unwrap();
    /// assert_eq!(rest.faces.len() + axes.faces.len(), room.faces.len());
    /// assert!(axes.is_closed_oriented());
    /// ```
    pub fn split_off_group(&self, name: &str) -> Option<(Mesh, Mesh)> {
        let g = self.group_index(name)?;
        let part = |keep: &dyn Fn(&Face) -> bool| {
            let mut map: HashMap<u32, u32> = HashMap::new();
            let mut out = Mesh {
                positions: Vec::new(),
                faces: Vec::new(),
                groups: self.groups.clone(),
            };
            for f in self.faces.iter().filter(|f| keep(f)) {
                let vertices = f
                    .vertices
                    .iter()
                    .map(|&v| {
                        *map.entry(v).or_insert_with(|| {
                            out.positions.push(self.positions[v as usize]);
                            (out.positions.len() - 1) as u32
                        })
                    })
                    .collect();
                out.faces.push(Face {
                    vertices,
                    line: f.line,
                    group: f.group,
                });
            }
            out
        };
        Some((part(&|f| f.group != g), part(&|f| f.group == g)))
    }

    /// Moves every face of group `name` by `offset`; vertices the group
    /// shares with other groups are duplicated first, so other groups stay
    /// where they are. Returns the number of faces moved, `None` if there
    /// is no such group.
    ///
    /// ```
    /// use glam::DVec3;
    /// let mut room = shadow_scene::room();
    /// let (lo, _) = room.bounds().unwrap();
    /// let moved = room.translate_group("axes", DVec3::new(0.5, 0.0, 0.0)).unwrap();
    /// assert!(moved > 0);
    /// assert_eq!(room.bounds().unwrap().0, lo);
    /// ```
    pub fn translate_group(&mut self, name: &str, offset: DVec3) -> Option<usize> {
        let g = self.group_index(name)?;
        let others: HashSet<u32> = self
            .faces
            .iter()
            .filter(|f| f.group != g)
            .flat_map(|f| f.vertices.iter().copied())
            .collect();
        let mut moved: HashMap<u32, u32> = HashMap::new();
        let mut count = 0;
        for f in self.faces.iter_mut().filter(|f| f.group == g) {
            count += 1;
            for v in &mut f.vertices {
                *v = *moved.entry(*v).or_insert_with(|| {
                    let p = self.positions[*v as usize] + offset;
                    if others.contains(v) {
                        self.positions.push(p);
                        (self.positions.len() - 1) as u32
                    } else {
                        self.positions[*v as usize] = p;
                        *v
                    }
                });
            }
        }
        Some(count)
    }

    /// Appends `other`'s faces, each vertex at `at(position)`, its groups
    /// named `prefix` + their name (the faces keep no line: they are not
    /// in this mesh's file).
    ///
    /// ```
    /// use glam::DVec3;
    /// let mut two = shadow_scene::scene("cube").unwrap();
    /// let cube = two.clone();
    /// two.append(&cube, "moved_", |p| p + DVec3::X * 2.0);
    /// assert_eq!(two.faces.len(), 12);
    /// assert_eq!(two.signed_volume(), 2.0);
    /// assert_eq!(two.group_name(6), "moved_cube");
    /// ```
    pub fn append(&mut self, other: &Mesh, prefix: &str, at: impl Fn(DVec3) -> DVec3) {
        let first = self.positions.len() as u32;
        let groups = self.groups.len() as u32;
        self.positions
            .extend(other.positions.iter().map(|&p| at(p)));
        self.groups
            .extend(other.groups.iter().map(|g| format!("{prefix}{g}")));
        self.faces.extend(other.faces.iter().map(|f| Face {
            vertices: f.vertices.iter().map(|&v| v + first).collect(),
            line: 0,
            group: f.group + groups,
        }));
    }
}

/// `v` scaled to unit length, or zero where it has none (as glam's
/// `normalize_or_zero`), at any size: `v` is first scaled by a power of
/// two that brings its largest component to about 1, so that squaring
/// it neither overflows nor underflows (a face's normal from cross
/// products is the square of its size: a face of size 1e77 has a normal
/// whose squared length is not an `f64`). A power of two scales exactly,
/// so the result is `normalize_or_zero`'s, bit for bit, wherever that one
/// did not overflow or underflow.
///
/// ```
/// use glam::DVec3;
/// let n = shadow_scene::unit_or_zero(DVec3::new(3e160, 0.0, 4e160));
/// assert_eq!(n, DVec3::new(0.6, 0.0, 0.8));
/// assert_eq!(shadow_scene::unit_or_zero(DVec3::ZERO), DVec3::ZERO);
/// ```
pub fn unit_or_zero(v: DVec3) -> DVec3 {
    // (near unit scale, as it stands: the same bits)
    if v.length_squared().is_normal() {
        return v.normalize_or_zero();
    }
    let largest = v.abs().max_element();
    if !(largest > 0.0 && largest.is_finite()) {
        return v.normalize_or_zero();
    }
    // in two factors, each a normal number, to reach subnormal sizes too
    let e = largest.log2().floor() as i32;
    let (a, b) = (-e / 2, -e - (-e / 2));
    (v * 2f64.powi(a) * 2f64.powi(b)).normalize_or_zero()
}

/// Newell normal of a loop (twice its vector area; zero for a loop
/// without area).
///
/// ```
/// use glam::DVec3;
/// let square = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
/// assert_eq!(shadow_scene::newell(&square), DVec3::new(0.0, 0.0, 2.0));
/// ```
pub fn newell(ring: &[DVec3]) -> DVec3 {
    let n = ring.len();
    (0..n).fold(DVec3::ZERO, |acc, i| acc + ring[i].cross(ring[(i + 1) % n]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetra() -> Mesh {
        Mesh {
            positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            faces: [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]
                .iter()
                .map(|v| Face {
                    vertices: v.to_vec(),
                    line: 0,
                    group: 0,
                })
                .collect(),
            groups: vec!["default".into()],
        }
    }

    fn faces(list: &[[u32; 3]]) -> Vec<Face> {
        list.iter()
            .map(|v| Face {
                vertices: v.to_vec(),
                line: 0,
                group: 0,
            })
            .collect()
    }

    #[test]
    fn flat_triangles_are_split_away_and_the_surface_stays_closed() {
        // a tetrahedron three units large whose edge 0-1 carries the points
        // 4 and 5, the notch filled by two flat triangles in a fan: fixing
        // one makes others flat before the face across 0-1 takes them
        let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        let positions = vec![
            p(0.0, 0.0, 0.0),
            p(3.0, 0.0, 0.0),
            p(0.0, 3.0, 0.0),
            p(0.0, 0.0, 3.0),
            p(1.0, 0.0, 0.0),
            p(2.0, 0.0, 0.0),
        ];
        let solid = [
            [0, 4, 3],
            [4, 5, 3],
            [5, 1, 3],
            [1, 0, 2],
            [1, 2, 3],
            [0, 3, 2],
        ];
        for notch in [
            [[1, 5, 4], [1, 4, 0]],
            [[1, 4, 0], [1, 5, 4]],
            [[0, 1, 5], [5, 4, 0]],
        ] {
            let mut m = Mesh {
                positions: positions.clone(),
                faces: faces(&[&solid[..], &notch[..]].concat()),
                groups: vec!["default".into()],
            };
            assert!(m.is_closed_oriented(), "{notch:?}");
            assert_eq!(m.flat_triangles(|p| p), 2);
            let fix = m.split_flat_triangles();
            assert_eq!(
                fix,
                FlatFix {
                    removed: 2,
                    left: 0
                },
                "{notch:?}"
            );
            assert!(m.is_closed_oriented(), "{notch:?}");
            assert_eq!(m.flat_triangles(|p| p), 0);
            assert_eq!(m.signed_volume(), 27.0 / 6.0);
        }
    }

    #[test]
    fn a_flat_pair_turned_over_goes_and_an_open_one_stays() {
        let mut m = tetra();
        m.positions
            .extend([DVec3::new(5.0, 0.0, 0.0), DVec3::new(7.0, 1.0, 0.0)]);
        m.positions.push(DVec3::new(6.0, 0.5, 0.0));
        m.faces.extend(faces(&[[4, 5, 6], [5, 4, 6]]));
        assert!(m.is_closed_oriented());
        assert_eq!(
            m.split_flat_triangles(),
            FlatFix {
                removed: 2,
                left: 0
            }
        );
        assert_eq!(m.faces.len(), 4);
        assert!(m.is_closed_oriented());
        // alone, a flat triangle has no face across its long edge
        let mut open = tetra();
        open.positions
            .extend([DVec3::new(5.0, 0.0, 0.0), DVec3::new(7.0, 1.0, 0.0)]);
        open.positions.push(DVec3::new(6.0, 0.5, 0.0));
        open.faces.extend(faces(&[[4, 5, 6]]));
        assert_eq!(
            open.split_flat_triangles(),
            FlatFix {
                removed: 0,
                left: 1
            }
        );
        assert_eq!(open.faces.len(), 5);
    }

    #[test]
    fn collinearity_is_exact() {
        let a = DVec3::new(0.1, 0.2, 0.3);
        let b = DVec3::new(0.7, 1.4, 2.1);
        // the midpoint rounded: on the line only if it rounds onto it
        assert!(collinear(DVec3::ZERO, a, a * 2.0));
        assert!(!collinear(
            DVec3::ZERO,
            a,
            DVec3::new(0.2, 0.4, 0.6000000000000001)
        ));
        assert!(!collinear(
            a,
            b,
            (a + b) * 0.5 + DVec3::new(0.0, 0.0, 1e-300)
        ));
        assert!(collinear(DVec3::X, DVec3::X * 2.0, DVec3::X * -1e300));
    }

    #[test]
    fn tetra_is_closed_with_positive_volume() {
        let t = tetra();
        assert!(t.is_closed_oriented());
        assert_eq!(t.signed_volume(), 1.0 / 6.0);
        assert_eq!(t.triangle_count(), 4);
    }

    #[test]
    fn flipped_or_open_mesh_is_detected() {
        let mut t = tetra();
        t.faces[0].vertices.reverse();
        assert!(!t.is_closed_oriented());
        let mut t = tetra();
        t.faces.pop();
        assert!(!t.is_closed_oriented());
    }

    #[test]
    fn weld_treats_negative_zero_as_zero_and_drops_unused() {
        let mut t = tetra();
        t.positions.push(DVec3::new(-0.0, 0.0, -0.0));
        t.positions.push(DVec3::splat(9.0));
        t.faces[0].vertices[0] = 4;
        t.weld();
        assert_eq!(t.positions.len(), 4);
        assert!(t.is_closed_oriented());
    }

    #[test]
    fn repeated_positions_counts_what_weld_merges() {
        let mut t = tetra();
        assert_eq!(t.repeated_positions(), 0);
        // face 3 gets its own copies of all three corners, plus an unused
        // position equal to a used one (which does not count)
        let n = t.positions.len() as u32;
        for v in t.faces[3].vertices.clone() {
            t.positions.push(t.positions[v as usize]);
        }
        t.faces[3].vertices = vec![n, n + 1, n + 2];
        t.positions.push(DVec3::ZERO);
        assert_eq!(t.repeated_positions(), 3);
        let before = t.positions.len();
        t.weld();
        assert_eq!(before - t.positions.len(), 3 + 1);
        assert_eq!(t.repeated_positions(), 0);
        assert!(t.is_closed_oriented());
    }

    /// A triangle list written through its view gives the bytes its
    /// [`Mesh`] gives, OBJ and STL, and the same counts of repeats (a
    /// soup of 3 000 triangles: more than one run of the OBJ writer).
    #[test]
    fn triangles_write_as_their_mesh() {
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for i in 0..3000u32 {
            let x = f64::from(i % 97) * 0.25;
            let y = f64::from(i / 97) * -0.5;
            positions.extend([
                DVec3::new(x, y, 0.0),
                DVec3::new(x + 0.25, y, 0.125),
                DVec3::new(x, y + 0.5, 0.0),
            ]);
            triangles.push([3 * i, 3 * i + 1, 3 * i + 2]);
        }
        let view = Triangles {
            positions: &positions,
            triangles: &triangles,
            group: "a group",
        };
        let mesh = view.to_mesh();
        assert_eq!(mesh.faces.len(), 3000);
        let (mut a, mut b) = (Vec::new(), Vec::new());
        crate::write_obj(&view, &mut a).unwrap();
        crate::write_obj(&mesh, &mut b).unwrap();
        assert!(a == b, "OBJ bytes differ");
        assert!(
            String::from_utf8(a)
                .unwrap()
                .contains("\ng a group\nf 1 2 3\n")
        );
        let (mut a, mut b) = (Vec::new(), Vec::new());
        crate::write_stl(&view, &mut a).unwrap();
        crate::write_stl(&mesh, &mut b).unwrap();
        assert!(a == b, "STL bytes differ");
        assert_eq!(view.repeated_positions(), mesh.repeated_positions());
        assert!(mesh.repeated_positions() > 0);
        assert_eq!(crate::stl_collisions(&view), crate::stl_collisions(&mesh));
    }

    #[test]
    fn translate_group_splits_shared_vertices() {
        let mut t = tetra();
        let g = t.add_group("lid");
        t.faces[3].group = g;
        assert_eq!(t.translate_group("lid", DVec3::Z), Some(1));
        // the three vertices of the lid were shared, so they were copied
        assert_eq!(t.positions.len(), 7);
        assert_eq!(
            t.face_points(3),
            vec![
                DVec3::new(1., 0., 1.),
                DVec3::new(0., 1., 1.),
                DVec3::new(0., 0., 2.)
            ]
        );
        assert_eq!(t.face_points(0), vec![DVec3::ZERO, DVec3::Y, DVec3::X]);
        assert_eq!(t.translate_group("nothing", DVec3::Z), None);
    }

    #[test]
    fn bounds_of_empty_mesh_is_none() {
        assert_eq!(Mesh::default().bounds(), None);
    }
}
