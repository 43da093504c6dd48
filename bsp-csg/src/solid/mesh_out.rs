//! A solid's boundary as a watertight triangle mesh, and the result of a
//! planned operation meshed straight from the two solids' faces.

use bsp_core::internals::share_points;
use bsp_core::{Polygon, TriMesh};
use rayon::prelude::*;

use super::carry_out::{borrow_sorted, reused_slots};
use super::{Face, Solid, drop_aside};
use crate::CsgError;
use crate::plan::{Added, Planned};

impl Solid {
    /// The watertight triangle mesh of the boundary (see
    /// [`TriMesh::from_polygons`]).
    pub fn to_mesh(&self) -> TriMesh {
        let faces: Vec<&Face> = self.faces.iter().flatten().collect();
        TriMesh::from_polygons(&faces)
    }

    /// [`Solid::to_mesh`], checked watertight
    /// ([`TriMesh::from_polygons_watertight`]: one check, most often made
    /// while the mesh is made). A failure is a bug in this crate
    /// ([`CsgError::Internal`]).
    pub fn to_watertight_mesh(&self) -> Result<TriMesh, CsgError> {
        let faces: Vec<&Face> = self.faces.iter().flatten().collect();
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
    pub(crate) fn into_mesh_with<T>(self, make: impl FnOnce(&[&Face]) -> T) -> T {
        // the index goes now (`..` would keep it to the end)
        let Solid { faces, index, .. } = self;
        drop_aside(index);
        // the polygons are read where they are (moving them out of their
        // slots into a list cost a pass over all of them)
        let polys: Vec<&Face> = faces.iter().flatten().collect();
        let mesh = make(&polys);
        drop(polys);
        drop_aside(faces);
        mesh
    }
}

impl Planned {
    /// The result's watertight mesh, the one [`Planned::into_solid`]'s
    /// [`Solid::into_watertight_mesh`] gives (the same triangles in the
    /// same order), made from the faces where they are: the result's
    /// faces are not moved into one solid, and no index is made for them.
    pub fn into_watertight_mesh(self) -> Result<TriMesh, CsgError> {
        let Planned {
            solid, other, plan, ..
        } = self;
        let Solid {
            faces,
            mut free,
            index,
            ..
        } = solid;
        let Solid {
            faces: mut theirs,
            index: their_index,
            ..
        } = other;
        drop_aside((index, their_index));
        // the faces the plan adds that are not read where they are: new
        // ones (the other solid's kept whole are read in its slots,
        // turned around there for a difference)
        let flip = plan.flip;
        enum Src {
            New(u32),
            Theirs(u32),
        }
        let (mut news, mut turned) = (Vec::new(), Vec::new());
        let srcs: Vec<Src> = plan
            .add
            .into_iter()
            .map(|a| match a {
                Added::New(p) => {
                    news.push(p);
                    Src::New((news.len() - 1) as u32)
                }
                Added::Whole(f) => {
                    if flip {
                        turned.push(f);
                    }
                    Src::Theirs(f)
                }
            })
            .collect();
        // (in place, in parallel: no second copy of the faces kept)
        turned.sort_unstable();
        turned.dedup();
        borrow_sorted(&mut theirs, &turned)
            .into_par_iter()
            .for_each(|slot| {
                let f = slot.as_mut().expect("a live face");
                *f = f.flipped();
            });
        let face = |f: u32| theirs[f as usize].as_ref().expect("a live face");
        {
            // equal new vertices made one, as `carry_out` makes them: the
            // welder then knows them equal at once
            let mut refs: Vec<&mut Polygon> = news.iter_mut().map(|p| &mut **p).collect();
            share_points(&mut refs);
        }
        let news: Vec<Face> = news.into_par_iter().map(Face::made).collect();
        let src = |s: &Src| -> &Face {
            match *s {
                Src::New(i) => &news[i as usize],
                Src::Theirs(f) => face(f),
            }
        };
        // in the order of the slots `carry_out` would put them in: the
        // freed slots first, then the end of the array
        let reused = reused_slots(&mut free, srcs.len());
        let k = reused.len();
        let mut polys: Vec<Option<&Face>> = faces.iter().map(Option::as_ref).collect();
        for (&slot, s) in reused.iter().zip(&srcs) {
            polys[slot as usize] = Some(src(s));
        }
        let polys: Vec<&Face> = polys
            .into_iter()
            .flatten()
            .chain(srcs[k..].iter().map(src))
            .collect();
        let mesh = TriMesh::from_polygons_watertight(&polys).map_err(CsgError::Internal);
        drop(polys);
        drop_aside((faces, theirs, news));
        mesh
    }
}
