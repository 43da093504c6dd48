//! A mixed cell (one holding faces of both operands) at work: its faces
//! clipped to it, and what becomes of each.

use bsp_core::Polygon;

use super::labelling::Listed;
use super::local::{self, CellResult, Fate};
use crate::index::IBox;
use crate::solid::Face;

/// What becomes of a face listed in a mixed cell.
pub(crate) enum PieceFate {
    /// Clipped to the cell, nothing is left of it.
    Missing,
    /// Its piece in the cell stays whole (the face is clipped again, to
    /// the cells it stays whole in joined, when it is settled).
    Keep,
    /// Its piece goes.
    Drop,
    /// The other surface cuts its piece: the fragments that stay.
    Cut(Vec<Polygon>),
}

/// A mixed cell's first run: done, or easy (every piece isolated, the
/// labels to come from the cells around); either way with, per listed
/// face of each operand, the walls an isolated piece crosses
/// ([`local::wall_edges`]; `None` for an untouched face in an easy cell,
/// which is not clipped).
pub(crate) enum First {
    Done(Made, Vec<Option<u8>>, Vec<Option<u8>>),
    Easy((Vec<Option<u8>>, Listed), (Vec<Option<u8>>, Listed)),
}

/// A mixed cell's outcome, per listed face of each operand, or the
/// cell's merged boundary.
pub(crate) enum Made {
    Fates(Vec<PieceFate>, Vec<PieceFate>),
    Merged(Vec<Polygon>),
}

impl Made {
    /// The outcome of a cell's result for its listed faces, `ia` and `ib`
    /// giving each listed face's piece among the result's.
    pub(crate) fn of(c: CellResult, ia: &[Option<u32>], ib: &[Option<u32>]) -> Made {
        let fates = |fates: Vec<Fate>, pieces: Vec<Polygon>, index: &[Option<u32>]| {
            let mut all: Vec<Option<(Fate, Polygon)>> =
                fates.into_iter().zip(pieces).map(Some).collect();
            index
                .iter()
                .map(|i| match i.and_then(|i| all[i as usize].take()) {
                    None => PieceFate::Missing,
                    Some((Fate::Keep, _)) => PieceFate::Keep,
                    Some((Fate::Drop, _)) => PieceFate::Drop,
                    Some((Fate::Cut(frags), _)) => PieceFate::Cut(frags),
                })
                .collect()
        };
        match c {
            CellResult::Merged(ps) => Made::Merged(ps),
            CellResult::Pieces(fa, fb, pa, pb) => Made::Fates(fates(fa, pa, ia), fates(fb, pb, ib)),
        }
    }
}

/// The faces `fs` clipped to the cell `cell` (walls `w`): the non-empty
/// pieces, in order, and each face's piece among them.
pub(crate) fn clip_all<'p>(
    fs: &[u32],
    face: impl Fn(u32) -> &'p Face,
    cell: &IBox,
    w: &[bsp_core::Plane; 6],
    which: &dyn Fn(u32) -> bool,
) -> (Vec<Polygon>, Vec<Option<u32>>) {
    let mut pieces = Vec::with_capacity(fs.len());
    let index = fs
        .iter()
        .map(|&f| {
            if !which(f) {
                return None;
            }
            let face = face(f);
            local::clip_face(face, cell, w).map(|q| {
                pieces.push(q);
                (pieces.len() - 1) as u32
            })
        })
        .collect();
    (pieces, index)
}

/// [`clip_all`] of every face, given `pieces` and `index` from
/// [`clip_all`] of the faces `done` accepts: those are taken over, the
/// others clipped now (the same pieces, in the same order).
pub(crate) fn clip_rest<'p>(
    fs: &[u32],
    face: impl Fn(u32) -> &'p Face,
    cell: &IBox,
    w: &[bsp_core::Plane; 6],
    done: &dyn Fn(u32) -> bool,
    pieces: Vec<Polygon>,
    index: &[Option<u32>],
) -> (Vec<Polygon>, Vec<Option<u32>>) {
    let mut got: Vec<Option<Polygon>> = pieces.into_iter().map(Some).collect();
    let mut out = Vec::with_capacity(fs.len());
    let index = fs
        .iter()
        .zip(index)
        .map(|(&f, i)| {
            let piece = if done(f) {
                i.and_then(|i| got[i as usize].take())
            } else {
                local::clip_face(face(f), cell, w)
            };
            piece.map(|q| {
                out.push(q);
                (out.len() - 1) as u32
            })
        })
        .collect();
    (out, index)
}
