//! A solid's boundary as a watertight triangle mesh, and the result of an
//! operation meshed straight from the two solids' faces.

use bsp_core::internals::share_points;
use bsp_core::par;
use bsp_core::{Polygon, TriMesh};

use super::carry_out::{borrow_sorted, reused_slots};
use super::{AddedFace, Additions, Solid, SolidFace, drop_aside};
use crate::CsgError;

impl Solid {
    /// The watertight triangle mesh of the boundary (see
    /// [`TriMesh::from_polygons`]).
    pub fn to_mesh(&self) -> TriMesh {
        let faces: Vec<&SolidFace> = self.faces.iter().flatten().collect();
        TriMesh::from_polygons(&faces)
    }

    /// [`Solid::to_mesh`], checked watertight
    /// ([`TriMesh::from_polygons_watertight`]: one check, most often made
    /// while the mesh is made). A failure is a bug in this crate
    /// ([`CsgError::Internal`]).
    pub fn to_watertight_mesh(&self) -> Result<TriMesh, CsgError> {
        let faces: Vec<&SolidFace> = self.faces.iter().flatten().collect();
        TriMesh::from_polygons_watertight(&faces).map_err(CsgError::Internal)
    }

    /// [`Solid::to_mesh`] for a solid no longer needed: the index goes
    /// first, and the faces go on the thread pool once the triangles are
    /// made (the same mesh).
    pub fn into_mesh(self) -> TriMesh {
        self.into_mesh_with(|polys| TriMesh::from_polygons(polys))
    }

    /// [`Solid::to_watertight_mesh`] for a solid no longer needed, as
    /// [`Solid::into_mesh`] makes it.
    pub fn into_watertight_mesh(self) -> Result<TriMesh, CsgError> {
        self.into_mesh_with(|polys| {
            TriMesh::from_polygons_watertight(polys).map_err(CsgError::Internal)
        })
    }

    /// `make` of the faces, the index and the faces let go as
    /// [`Solid::into_mesh`] says.
    fn into_mesh_with<T>(self, make: impl FnOnce(&[&SolidFace]) -> T) -> T {
        // the index goes now (`..` would keep it to the end)
        let Solid { faces, index, .. } = self;
        drop_aside(index);
        // the polygons are read where they are (moving them out of their
        // slots into a list cost a pass over all of them)
        let polys: Vec<&SolidFace> = faces.iter().flatten().collect();
        let mesh = make(&polys);
        drop(polys);
        drop_aside(faces);
        mesh
    }
}

/// A face of an operation's result that is not in the first solid's
/// slots: a new face, by its place among the new ones, or the other
/// solid's face kept whole, read in its slot.
enum AddedAt {
    New(u32),
    Theirs(u32),
}

impl Solid {
    /// The watertight mesh of this solid with `additions` from `other`
    /// carried out: the one [`Solid::carry_out`] then
    /// [`Solid::into_watertight_mesh`] give (the same triangles in the
    /// same order), made from the faces where they are: the result's
    /// faces are not moved into one solid, and no index is made for them.
    pub(crate) fn into_watertight_mesh_with(
        self,
        additions: Additions,
        other: Solid,
    ) -> Result<TriMesh, CsgError> {
        let Solid {
            faces,
            mut free,
            index,
            ..
        } = self;
        let Solid {
            faces: mut theirs,
            index: their_index,
            ..
        } = other;
        drop_aside((index, their_index));
        let (news, turned, added) = read_where_they_are(additions);
        // (in place, in parallel: no second copy of the faces kept)
        par::for_each_mut(&mut borrow_sorted(&mut theirs, &turned), |_, slot| {
            let f = slot.as_mut().expect("a live face");
            *f = f.flipped();
        });
        let face = |a: &AddedAt| -> &SolidFace {
            match *a {
                AddedAt::New(i) => &news[i as usize],
                AddedAt::Theirs(f) => theirs[f as usize].as_ref().expect("a live face"),
            }
        };
        // in the order of the slots `carry_out` would put them in: the
        // freed slots first, then the end of the array
        let reused = reused_slots(&mut free, added.len());
        let k = reused.len();
        let mut polys: Vec<Option<&SolidFace>> = faces.iter().map(Option::as_ref).collect();
        for (&slot, a) in reused.iter().zip(&added) {
            polys[slot as usize] = Some(face(a));
        }
        let polys: Vec<&SolidFace> = polys
            .into_iter()
            .flatten()
            .chain(added[k..].iter().map(face))
            .collect();
        let mesh = TriMesh::from_polygons_watertight(&polys).map_err(CsgError::Internal);
        drop(polys);
        drop_aside((faces, theirs, news));
        mesh
    }
}

/// The faces `additions` adds that are not read where they are: the new
/// ones, made (the other solid's kept whole are read in its slots); the
/// other solid's faces to turn around there first (for a difference;
/// sorted, each once); and where each added face is read, in order.
fn read_where_they_are(additions: Additions) -> (Vec<SolidFace>, Vec<u32>, Vec<AddedAt>) {
    let (mut news, mut turned) = (Vec::new(), Vec::new());
    let added = additions
        .faces
        .into_iter()
        .map(|a| match a {
            AddedFace::New(p) => {
                news.push(p);
                AddedAt::New((news.len() - 1) as u32)
            }
            AddedFace::Theirs(f) => {
                if additions.flip {
                    turned.push(f);
                }
                AddedAt::Theirs(f)
            }
        })
        .collect();
    turned.sort_unstable();
    turned.dedup();
    // equal new vertices made one, as `carry_out` makes them: the welder
    // then knows them equal at once
    let mut refs: Vec<&mut Polygon> = news.iter_mut().map(|p| &mut **p).collect();
    share_points(&mut refs);
    let news = par::map_vec(news, SolidFace::made);
    (news, turned, added)
}
