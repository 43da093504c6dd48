//! A solid's face slot: an imported face as its grid corners, or a face
//! an operation made, with its edge planes.

use bsp_core::internals::{ConvexFace, GridPolygon, PointRef};
use bsp_core::{Plane, Polygon};
use std::borrow::Cow;

use crate::index::{IBox, SmallBox, polygon_box};

/// A face's polygon. An imported face keeps its grid corners only, and
/// its edge planes are computed when it is cut or tested: most faces of a
/// large solid are never cut, and the edge planes are most of a
/// polygon's room.
#[derive(Clone, Debug)]
enum Shape {
    /// An imported face (or one kept whole from one); its box is read off
    /// its corners.
    Grid(GridPolygon),
    /// A face an operation made, with its edge planes, and its box in 32
    /// bits (rounded outward where a coordinate does not fit).
    Made(Box<Polygon>, SmallBox),
}

/// A face slot's content (a face slot is most of a solid's memory: an
/// imported triangle takes 112 bytes, and a box stored beside its
/// corners would take 24 more).
#[derive(Clone, Debug)]
pub(crate) struct SolidFace {
    shape: Shape,
}

impl SolidFace {
    /// An imported face (its polygon made with tag 0).
    pub(crate) fn grid(g: GridPolygon) -> SolidFace {
        SolidFace {
            shape: Shape::Grid(g),
        }
    }

    /// A face an operation made (tag 0).
    pub(crate) fn made(mut p: Box<Polygon>) -> SolidFace {
        p.set_tag(0);
        let bx = polygon_box(&*p);
        let narrow = |v: i64| v.clamp(i32::MIN as i64, i32::MAX as i64) as i32;
        let small = (bx.0.map(narrow), bx.1.map(narrow));
        SolidFace {
            shape: Shape::Made(p, small),
        }
    }

    /// An imported face's grid polygon.
    pub(crate) fn as_grid(&self) -> Option<&GridPolygon> {
        match &self.shape {
            Shape::Grid(g) => Some(g),
            Shape::Made(..) => None,
        }
    }

    /// A made face's polygon, to change in place (an imported face's
    /// vertices are its grid corners, shared already).
    pub(crate) fn made_polygon_mut(&mut self) -> Option<&mut Polygon> {
        match &mut self.shape {
            Shape::Grid(_) => None,
            Shape::Made(p, _) => Some(&mut **p),
        }
    }

    /// The polygon, with its edge planes (made for an imported face).
    pub(crate) fn polygon(&self) -> Cow<'_, Polygon> {
        match &self.shape {
            Shape::Grid(g) => Cow::Owned(g.to_polygon(0)),
            Shape::Made(p, _) => Cow::Borrowed(p),
        }
    }

    /// The same face seen from the other side (the same box).
    pub(crate) fn flipped(&self) -> SolidFace {
        SolidFace {
            shape: match &self.shape {
                Shape::Grid(g) => Shape::Grid(g.flipped()),
                Shape::Made(p, b) => Shape::Made(Box::new(p.flipped()), *b),
            },
        }
    }

    /// A box holding the polygon, in 32 bits: an imported face's corners'
    /// (exact), a made face's stored one.
    #[inline]
    pub(crate) fn small_box(&self) -> SmallBox {
        match &self.shape {
            Shape::Grid(g) => match *g.vertices() {
                // (most imported faces)
                [a, b, c] => (
                    [0, 1, 2].map(|k| a[k].min(b[k]).min(c[k])),
                    [0, 1, 2].map(|k| a[k].max(b[k]).max(c[k])),
                ),
                // (a grid polygon's box is its corners' own: it fits)
                _ => {
                    let (lo, hi) = polygon_box(g);
                    (lo.map(|v| v as i32), hi.map(|v| v as i32))
                }
            },
            Shape::Made(_, b) => *b,
        }
    }

    /// A box holding the polygon.
    #[inline]
    pub(crate) fn bx(&self) -> IBox {
        let (lo, hi) = self.small_box();
        (lo.map(i64::from), hi.map(i64::from))
    }
}

impl ConvexFace for SolidFace {
    #[inline]
    fn support(&self) -> &Plane {
        match &self.shape {
            Shape::Grid(g) => g.support(),
            Shape::Made(p, _) => p.support(),
        }
    }
    #[inline]
    fn corner_count(&self) -> usize {
        match &self.shape {
            Shape::Grid(g) => g.len(),
            Shape::Made(p, _) => p.len(),
        }
    }
    #[inline]
    fn corner(&self, i: usize) -> PointRef<'_> {
        match &self.shape {
            Shape::Grid(g) => PointRef::Grid(g.vertices()[i]),
            Shape::Made(p, _) => p.vertices()[i].as_ref(),
        }
    }
    #[inline]
    fn edge_plane(&self, i: usize) -> Plane {
        match &self.shape {
            Shape::Grid(g) => g.edge_plane(i),
            Shape::Made(p, _) => p.edge_planes()[i],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A face slot stays small (it is most of a solid's memory), and an
    /// imported face's box read off its corners is the box of its
    /// polygon, as a made face's stored one is.
    #[test]
    fn face_slots_are_small_and_know_their_boxes() {
        assert!(std::mem::size_of::<SolidFace>() <= 112);
        let g = GridPolygon::from_grid_points(&[[5, -7, 1], [9, 2, -3], [-4, 0, 8]]).unwrap();
        let want = polygon_box(&g);
        let grid = SolidFace::grid(g.clone());
        assert_eq!(grid.bx(), want);
        assert_eq!(grid.flipped().bx(), want);
        let made = SolidFace::made(Box::new(g.to_polygon(0)));
        assert_eq!(made.bx(), want);
        assert_eq!(made.flipped().bx(), want);
    }
}
