//! The mixed cells (leaves holding faces of both operands) at work.
//!
//! First, which faces the other surface may meet at all ([`Touched`]):
//! the others are kept or dropped whole by one label, and a mixed cell
//! holding only such faces (a clean one) does nothing. Each other mixed
//! cell clips its faces to its walls itself ([`CellWork::run`]), so that
//! only the cells at work hold their pieces, and finds the pieces that
//! meet no piece of the other surface (isolated). A cell whose pieces are
//! all isolated (an easy one) builds nothing: its pieces' labels are
//! carried along their faces from the cells around (`labelling`). The
//! others build their local partitions (`local`) and give back what
//! becomes of each listed face, or their merged boundary.

use bsp_core::internals::ConvexFace;
use bsp_core::par;
use bsp_core::{BoolOp, GridPoint, Plane, Polygon};
use rustc_hash::FxHashSet;
use smallvec::SmallVec;

use super::local::{self, CellResult, Fate};
use super::octree::{Leaf, walls};
use super::operands::{Both, Keep, Operand};
use super::twins;
use crate::index::{IBox, holds};
use crate::solid::SolidFace;
use crate::{CsgError, Solid};

/// What becomes of a face listed in a mixed cell.
pub(super) enum PieceFate {
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

/// Per listed face of one operand in a mixed cell, the walls its piece
/// crosses into the cells beyond ([`local::wall_edges`]: bit `1 << k`
/// for wall `k` of [`walls`]) where the piece is isolated; `None` where
/// it is not, where nothing of the face is left in the cell, or for an
/// untouched face in an easy cell (which is not clipped).
pub(super) type WallCrossings = Vec<Option<u8>>;

/// A mixed cell's run.
pub(super) enum CellRun {
    /// The cell built its local partitions.
    Built {
        outcome: CellOutcome,
        crossings: Both<WallCrossings>,
    },
    /// Every piece is isolated: the labels are to come from the cells
    /// around.
    Easy {
        crossings: Both<WallCrossings>,
        pieces: Both<EasyPieces>,
    },
}

/// What a cell that built its partitions decided.
pub(super) enum CellOutcome {
    /// What becomes of each listed face of each operand.
    Sorted(Both<Vec<PieceFate>>),
    /// Faces of the two operands share a plane: the cell's merged
    /// boundary, which replaces every listed face's piece.
    Merged(Vec<Polygon>),
    /// The two solids are one set in the cell ([`twins`]): each listed
    /// face kept or dropped whole, nothing clipped.
    OneSet(Both<Vec<PieceFate>>),
}

impl CellOutcome {
    /// The outcome of a cell's local result for its listed faces,
    /// `piece_of` giving each listed face's piece among the result's.
    fn new(result: CellResult, piece_of: Both<&[Option<u32>]>) -> CellOutcome {
        let fates = |fates: Vec<Fate>, pieces: Vec<Polygon>, piece_of: &[Option<u32>]| {
            let mut all: Vec<Option<(Fate, Polygon)>> =
                fates.into_iter().zip(pieces).map(Some).collect();
            piece_of
                .iter()
                .map(|i| match i.and_then(|i| all[i as usize].take()) {
                    None => PieceFate::Missing,
                    Some((Fate::Keep, _)) => PieceFate::Keep,
                    Some((Fate::Drop, _)) => PieceFate::Drop,
                    Some((Fate::Cut(frags), _)) => PieceFate::Cut(frags),
                })
                .collect()
        };
        match result {
            CellResult::Merged(ps) => CellOutcome::Merged(ps),
            CellResult::Pieces(fa, fb, pa, pb) => CellOutcome::Sorted(Both {
                a: fates(fa, pa, piece_of.a),
                b: fates(fb, pb, piece_of.b),
            }),
        }
    }
}

/// One operand's listed faces in an easy cell, as labelling reads them:
/// a grid vertex of each piece, and the pairs of pieces sharing a grid
/// vertex.
pub(super) struct EasyPieces {
    /// Per listed face, a grid vertex of its piece (`None`: none).
    pub(super) grid_vertex: Vec<Option<GridPoint>>,
    /// The pairs of listed faces whose pieces share a grid vertex.
    pub(super) touching: Vec<(u32, u32)>,
}

impl EasyPieces {
    /// From the grid vertices of each listed face's piece in the cell:
    /// its clipped piece's, or for a face not clipped, its grid corners
    /// in the cell's box `bx` (the same points: the walls hold no grid
    /// point).
    fn new<'p>(
        listed: &[u32],
        face: impl Fn(u32) -> &'p SolidFace,
        clipped: &CellPieces,
        was_clipped: impl Fn(u32) -> bool,
        bx: &IBox,
    ) -> EasyPieces {
        let grid_of = |p: &Polygon| -> SmallVec<[GridPoint; 4]> {
            p.vertices()
                .iter()
                .filter_map(|v| match v {
                    bsp_core::Point::Grid(g) => Some(*g),
                    _ => None,
                })
                .collect()
        };
        let verts: Vec<SmallVec<[GridPoint; 4]>> = listed
            .iter()
            .zip(&clipped.piece_of)
            .map(|(&f, i)| {
                if was_clipped(f) {
                    return i.map_or_else(SmallVec::new, |i| grid_of(&clipped.pieces[i as usize]));
                }
                let face = face(f);
                (0..face.corner_count())
                    .filter_map(|k| face.corner(k).as_grid())
                    .filter(|g| holds(bx, g))
                    .collect()
            })
            .collect();
        let mut touching = Vec::new();
        for i in 0..verts.len() {
            for j in i + 1..verts.len() {
                if verts[i].iter().any(|g| verts[j].contains(g)) {
                    touching.push((i as u32, j as u32));
                }
            }
        }
        EasyPieces {
            grid_vertex: verts.iter().map(|v| v.first().copied()).collect(),
            touching,
        }
    }
}

/// One operand's listed faces of a mixed cell clipped to it.
struct CellPieces {
    /// The non-empty pieces, in the order of the list.
    pieces: Vec<Polygon>,
    /// Per listed face, its piece among `pieces` (`None`: nothing left,
    /// or not clipped).
    piece_of: Vec<Option<u32>>,
}

impl CellPieces {
    /// The faces `listed` that `which` accepts clipped to the cell `cell`
    /// (walls `w`).
    fn clip<'p>(
        listed: &[u32],
        face: impl Fn(u32) -> &'p SolidFace,
        cell: &IBox,
        w: &[Plane; 6],
        which: impl Fn(u32) -> bool,
    ) -> CellPieces {
        let mut pieces = Vec::with_capacity(listed.len());
        let piece_of = listed
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
        CellPieces { pieces, piece_of }
    }

    /// These pieces, of the faces `done` accepts, completed with the
    /// other faces of `listed` clipped now: the pieces [`CellPieces::clip`]
    /// of every face gives, in the same order.
    fn clip_rest<'p>(
        self,
        listed: &[u32],
        face: impl Fn(u32) -> &'p SolidFace,
        cell: &IBox,
        w: &[Plane; 6],
        done: impl Fn(u32) -> bool,
    ) -> CellPieces {
        let mut got: Vec<Option<Polygon>> = self.pieces.into_iter().map(Some).collect();
        let mut pieces = Vec::with_capacity(listed.len());
        let piece_of = listed
            .iter()
            .zip(&self.piece_of)
            .map(|(&f, i)| {
                let piece = if done(f) {
                    i.and_then(|i| got[i as usize].take())
                } else {
                    local::clip_face(face(f), cell, w)
                };
                piece.map(|q| {
                    pieces.push(q);
                    (pieces.len() - 1) as u32
                })
            })
            .collect();
        CellPieces { pieces, piece_of }
    }

    /// Per listed face, the walls its piece crosses if `isolated` says
    /// the piece is.
    fn wall_crossings(&self, isolated: &[bool], w: &[Plane; 6]) -> WallCrossings {
        self.piece_of
            .iter()
            .map(|i| {
                i.filter(|&i| isolated[i as usize])
                    .map(|i| local::wall_edges(&self.pieces[i as usize], w))
            })
            .collect()
    }
}

/// Which faces of each operand the other surface may meet, and which
/// mixed cells are clean (all their faces untouched).
pub(super) struct Touched {
    /// By face id: whether the face may meet the other surface.
    faces: Both<Vec<bool>>,
    /// By leaf: whether it is a clean mixed cell.
    clean: Vec<bool>,
}

impl Touched {
    /// For each face of each solid (by id; `false` for faces in no mixed
    /// cell), whether it may meet the other surface: it is not apart
    /// ([`local::apart`], whole faces) from some face of the other in some
    /// mixed cell of `mixed`, or it has no grid corner (where its label
    /// could be asked), or it is listed in a mixed cell where faces of the
    /// two share a plane (which may be merged whole, pieces and all); and
    /// per leaf, whether it is a clean mixed cell: one whose faces all are
    /// untouched. Without `easy_cells`, no cell is clean (every mixed
    /// cell builds its trees, and the untouched faces take their labels
    /// from them: the same result).
    ///
    /// An untouched face meets the other surface nowhere: a common point
    /// would lie in some leaf's closed cell, whose lists hold every face
    /// meeting it (box and plane), so that leaf would be mixed and the two
    /// faces tested there, and faces with a common point are never apart.
    pub(super) fn find(
        mixed: &[u32],
        leaves: &[Leaf],
        solids: Both<&Solid>,
        easy_cells: bool,
    ) -> Touched {
        let per_cell: Vec<Both<Vec<u32>>> =
            par::map_slice(mixed, |&l| touched_in(&leaves[l as usize], solids));
        let mut faces = Both {
            a: vec![false; solids.a.slot_count()],
            b: vec![false; solids.b.slot_count()],
        };
        for cell in &per_cell {
            cell.a.iter().for_each(|&f| faces.a[f as usize] = true);
            cell.b.iter().for_each(|&f| faces.b[f as usize] = true);
        }
        let mut clean = vec![false; leaves.len()];
        if easy_cells {
            for &l in mixed {
                let leaf = &leaves[l as usize];
                clean[l as usize] = leaf.a.iter().all(|&f| !faces.a[f as usize])
                    && leaf.b.iter().all(|&f| !faces.b[f as usize]);
            }
        }
        Touched { faces, clean }
    }

    /// Whether the other surface may meet face `f` of operand `o`.
    pub(super) fn face(&self, o: Operand, f: u32) -> bool {
        self.faces.get(o).get(f as usize) != Some(&false)
    }

    /// Whether leaf `l` is a clean mixed cell.
    pub(super) fn clean(&self, l: u32) -> bool {
        self.clean[l as usize]
    }
}

/// The faces of each operand listed in the mixed leaf `leaf` that the
/// other surface may meet there ([`Touched::find`]).
fn touched_in(leaf: &Leaf, solids: Both<&Solid>) -> Both<Vec<u32>> {
    let no_grid_corner =
        |f: &SolidFace| (0..f.corner_count()).all(|i| f.corner(i).as_grid().is_none());
    let fa: Vec<&SolidFace> = leaf.a.iter().map(|&f| solids.a.face(f)).collect();
    let fb: Vec<&SolidFace> = leaf.b.iter().map(|&f| solids.b.face(f)).collect();
    // a cell where faces of the two share a plane may be merged as a
    // whole (`local::boolean_pieces`): all its faces settle piece by piece
    let shared = fa
        .iter()
        .any(|p| fb.iter().any(|q| p.support().is_coincident(q.support())));
    if shared {
        return Both {
            a: leaf.a.clone(),
            b: leaf.b.clone(),
        };
    }
    let mut ta: Vec<bool> = fa.iter().map(|f| no_grid_corner(f)).collect();
    let mut tb: Vec<bool> = fb.iter().map(|f| no_grid_corner(f)).collect();
    for (i, p) in fa.iter().enumerate() {
        for (j, q) in fb.iter().enumerate() {
            if ta[i] && tb[j] {
                continue; // both known already
            }
            if !local::apart(*p, *q) {
                ta[i] = true;
                tb[j] = true;
            }
        }
    }
    let pick = |fs: &[u32], t: &[bool]| -> Vec<u32> {
        fs.iter()
            .zip(t)
            .filter(|(_, t)| **t)
            .map(|(f, _)| *f)
            .collect()
    };
    Both {
        a: pick(&leaf.a, &ta),
        b: pick(&leaf.b, &tb),
    }
}

/// What a mixed cell's run reads: the two solids, the faces the other
/// surface may meet, and the operation.
pub(super) struct CellWork<'p> {
    pub(super) solids: Both<&'p Solid>,
    pub(super) touched: &'p Touched,
    /// The faces that are the same polygon as one of the other's.
    pub(super) twinned: &'p Both<FxHashSet<u32>>,
    pub(super) op: BoolOp,
}

impl CellWork<'_> {
    /// Runs the mixed cell `leaf`. With `allow_easy`, the cell first
    /// clips only the faces the other surface may meet (untouched faces
    /// are isolated, and their pieces need no labels of their own: their
    /// faces' are known) and is easy if every piece is isolated; else it
    /// clips every face and builds its partitions.
    pub(super) fn run(&self, leaf: &Leaf, allow_easy: bool) -> Result<CellRun, CsgError> {
        // (the octree's build asked already where it left the cell whole)
        let (ta, tb) = (&self.twinned.a, &self.twinned.b);
        let (twin_a, twin_b) = (|f| ta.contains(&f), |f| tb.contains(&f));
        if leaf.settled || twins::one_set(self.solids, &leaf.bx, (&leaf.a, &leaf.b), twin_a, twin_b)
        {
            return Ok(self.one_set(leaf));
        }
        let w = walls(&leaf.bx);
        let pieces = if allow_easy {
            let touched = Both {
                a: self.clip(Operand::A, leaf, &w, |f| self.touched.face(Operand::A, f)),
                b: self.clip(Operand::B, leaf, &w, |f| self.touched.face(Operand::B, f)),
            };
            let (isolated_a, isolated_b) = local::isolated(&touched.a.pieces, &touched.b.pieces);
            if isolated_a.iter().chain(&isolated_b).all(|&x| x) {
                let isolated = Both {
                    a: isolated_a,
                    b: isolated_b,
                };
                return Ok(self.easy(leaf, &touched, &isolated, &w));
            }
            // every face's piece (those clipped already reused)
            let Both { a, b } = touched;
            Both {
                a: self.clip_rest(Operand::A, a, leaf, &w),
                b: self.clip_rest(Operand::B, b, leaf, &w),
            }
        } else {
            Both {
                a: self.clip(Operand::A, leaf, &w, |_| true),
                b: self.clip(Operand::B, leaf, &w, |_| true),
            }
        };
        self.build(leaf, pieces, &w)
    }

    /// A cell where the two solids are one set ([`twins`]): `a ∪ b` and
    /// `a ∩ b` keep `a`'s faces and drop `b`'s, `a − b` drops both; no
    /// piece crosses a wall alone.
    fn one_set(&self, leaf: &Leaf) -> CellRun {
        let fate = |keep: bool| match keep {
            true => PieceFate::Keep,
            false => PieceFate::Drop,
        };
        let keep_a = self.op != BoolOp::Difference;
        CellRun::Built {
            outcome: CellOutcome::OneSet(Both {
                a: leaf.a.iter().map(|_| fate(keep_a)).collect(),
                b: leaf.b.iter().map(|_| fate(false)).collect(),
            }),
            crossings: Both {
                a: vec![None; leaf.a.len()],
                b: vec![None; leaf.b.len()],
            },
        }
    }

    /// Operand `o`'s listed faces of `leaf` that `which` accepts, clipped
    /// to the leaf's cell (walls `w`).
    fn clip(
        &self,
        o: Operand,
        leaf: &Leaf,
        w: &[Plane; 6],
        which: impl Fn(u32) -> bool,
    ) -> CellPieces {
        let solid = self.solids.get(o);
        CellPieces::clip(leaf.faces(o), |f| solid.face(f), &leaf.bx, w, which)
    }

    /// [`CellPieces::clip_rest`] of operand `o`'s pieces of its touched
    /// faces.
    fn clip_rest(
        &self,
        o: Operand,
        touched: CellPieces,
        leaf: &Leaf,
        w: &[Plane; 6],
    ) -> CellPieces {
        let solid = self.solids.get(o);
        touched.clip_rest(
            leaf.faces(o),
            |f| solid.face(f),
            &leaf.bx,
            w,
            |f| self.touched.face(o, f),
        )
    }

    /// An easy cell's run, from the pieces of its touched faces, all
    /// isolated: the walls they cross, and what labelling reads of them.
    /// (An untouched face stands there by its grid corners in the cell,
    /// with its face's label.)
    fn easy(
        &self,
        leaf: &Leaf,
        pieces: &Both<CellPieces>,
        isolated: &Both<Vec<bool>>,
        w: &[Plane; 6],
    ) -> CellRun {
        let easy_pieces = |o: Operand| {
            let solid = self.solids.get(o);
            EasyPieces::new(
                leaf.faces(o),
                |f| solid.face(f),
                pieces.get(o),
                |f| self.touched.face(o, f),
                &leaf.bx,
            )
        };
        CellRun::Easy {
            crossings: Both {
                a: pieces.a.wall_crossings(&isolated.a, w),
                b: pieces.b.wall_crossings(&isolated.b, w),
            },
            pieces: Both {
                a: easy_pieces(Operand::A),
                b: easy_pieces(Operand::B),
            },
        }
    }

    /// The cell's local partitions built from every listed face's piece:
    /// what becomes of each, or the merged boundary.
    fn build(
        &self,
        leaf: &Leaf,
        pieces: Both<CellPieces>,
        w: &[Plane; 6],
    ) -> Result<CellRun, CsgError> {
        let (isolated_a, isolated_b) = local::isolated(&pieces.a.pieces, &pieces.b.pieces);
        let crossings = Both {
            a: pieces.a.wall_crossings(&isolated_a, w),
            b: pieces.b.wall_crossings(&isolated_b, w),
        };
        let Both { a, b } = pieces;
        let (bx, keep, solids) = (leaf.bx, Keep(self.op), self.solids);
        let r = bx.0.map(|c| c as i32);
        let result = local::boolean_pieces(
            &bx,
            a.pieces,
            b.pieces,
            self.op,
            (
                |inside_b| keep.piece(Operand::A, inside_b),
                |inside_a| keep.piece(Operand::B, inside_a),
            ),
            || solids.a.winding(r),
            || solids.b.winding(r),
        )?;
        let piece_of = Both {
            a: &a.piece_of[..],
            b: &b.piece_of[..],
        };
        Ok(CellRun::Built {
            outcome: CellOutcome::new(result, piece_of),
            crossings,
        })
    }
}
