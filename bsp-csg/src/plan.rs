//! Planning an operation: everything `self ∘ other` decides, from the
//! octree over the shared box to the faces removed and added.

mod labelling;
pub(crate) mod local;
mod mixed_cell;
pub(crate) mod octree;
mod settle;

use bsp_core::internals::ConvexFace;
use bsp_core::{BoolOp, Polygon};
use rayon::prelude::*;
use rustc_hash::FxHashMap;
use smallvec::SmallVec;

use crate::index::{IBox, SmallBox, intersect, union};
use crate::solid::{Other, drop_aside};
use crate::{CsgError, Options, Solid, Stats};
use labelling::{Listed, Regions, label_easy, label_untouched, touched};
use mixed_cell::{First, Made, PieceFate, clip_all, clip_rest};
use octree::{Leaf, walls};
use settle::{Piece, Settled, meeting_leaf, settle, sort_faces};

/// An operation on two solids, decided ([`Solid::plan_owned`]).
pub struct Planned {
    pub(crate) solid: Solid,
    pub(crate) other: Solid,
    pub(crate) plan: Plan,
    pub(crate) stats: Stats,
}

impl Planned {
    /// What the operation found.
    pub fn stats(&self) -> &Stats {
        &self.stats
    }

    /// The result as a solid, ready for further operations.
    pub fn into_solid(self) -> Solid {
        let Planned {
            mut solid,
            mut other,
            plan,
            ..
        } = self;
        solid.carry_out(plan, Other::Owned(&mut other));
        drop_aside(other);
        solid
    }
}

impl Solid {
    /// `self op other` for solids whose faces cannot meet.
    pub(crate) fn apart(&mut self, other: &Solid, op: BoolOp) -> Result<(Stats, Plan), CsgError> {
        let mut plan = Plan {
            add: Vec::new(),
            flip: false,
        };
        match op {
            BoolOp::Union => {
                plan.add = (0..other.faces.len() as u32)
                    .filter(|&i| other.faces[i as usize].is_some())
                    .map(Added::Whole)
                    .collect()
            }
            BoolOp::Intersection => *self = Solid::empty(),
            BoolOp::Difference => {}
        }
        Ok((Stats::default(), plan))
    }

    /// Everything an operation decides; of the changes to this solid it
    /// makes the removals (and empties it for an intersection with a
    /// solid apart), and leaves the additions to [`Solid::carry_out`].
    pub(crate) fn plan(
        &mut self,
        other: &Solid,
        op: BoolOp,
        opts: &Options,
    ) -> Result<(Stats, Plan), CsgError> {
        let keep_a = |inside_b: bool| match op {
            BoolOp::Union | BoolOp::Difference => !inside_b,
            BoolOp::Intersection => inside_b,
        };
        let keep_b = |inside_a: bool| match op {
            BoolOp::Union => !inside_a,
            BoolOp::Intersection | BoolOp::Difference => inside_a,
        };
        let flip_b = op == BoolOp::Difference;
        let domain = match (self.bounds, other.bounds) {
            (Some(a), Some(b)) => intersect(&a, &b),
            _ => None,
        };
        let Some(domain) = domain else {
            return self.apart(other, op);
        };
        // the faces that may meet the other surface, and every face of
        // either in the box they span: the octree's cells must know all
        // the faces in them to tell which cells are free of a surface
        let root = match (self.near_span(&domain), other.near_span(&domain)) {
            (Some(a), Some(b)) => union(&a, &b),
            (Some(x), None) | (None, Some(x)) => x,
            (None, None) => return self.apart(other, op),
        };
        let a_c = self.faces_near(&root);
        let b_c = other.faces_near(&root);
        // the faces' boxes and planes side by side, by their place in
        // `a_c` and `b_c` (a face slot is large: the build reads these often)
        let geometry = |s: &Solid, fs: &[u32]| -> (Vec<SmallBox>, Vec<bsp_core::Plane>) {
            fs.par_iter()
                .map(|&f| (s.face(f).small_box(), *s.face(f).support()))
                .unzip()
        };
        let (boxes_a, planes_a) = geometry(self, &a_c);
        let (boxes_b, planes_b) = geometry(other, &b_c);
        let mut leaves = octree::build(
            root,
            &octree::Faces {
                boxes: &boxes_a,
                plane_meets: |f: u32, c: &IBox| octree::plane_meets(&planes_a[f as usize], c),
            },
            &octree::Faces {
                boxes: &boxes_b,
                plane_meets: |f: u32, c: &IBox| octree::plane_meets(&planes_b[f as usize], c),
            },
            opts.leaf_size,
        );
        drop((boxes_a, planes_a, boxes_b, planes_b));
        if opts.exact_cells {
            // the lists of the leaves holding both, by the exact test
            leaves.par_iter_mut().filter(|l| l.mixed()).for_each(|l| {
                let bx = l.bx;
                l.a.retain(|&f| octree::polygon_meets(self.face(a_c[f as usize]), &bx));
                l.b.retain(|&f| octree::polygon_meets(other.face(b_c[f as usize]), &bx));
            });
        }
        // each face's leaves, by its place in `a_c` and `b_c`
        // (each operand's on its own thread)
        let leaves_of = |n: usize, list: fn(&Leaf) -> &Vec<u32>| {
            let mut of: Vec<SmallVec<[u32; 4]>> = vec![SmallVec::new(); n];
            for (li, l) in leaves.iter().enumerate() {
                for &f in list(l) {
                    of[f as usize].push(li as u32);
                }
            }
            of
        };
        let (a_leaves, b_leaves) = rayon::join(
            || leaves_of(a_c.len(), |l| &l.a),
            || leaves_of(b_c.len(), |l| &l.b),
        );
        // the leaves' lists by face id
        leaves.par_iter_mut().for_each(|l| {
            l.a.iter_mut().for_each(|f| *f = a_c[*f as usize]);
            l.b.iter_mut().for_each(|f| *f = b_c[*f as usize]);
        });
        let adjacent = octree::adjacent(&leaves);
        // the regions free of each surface, and their labels
        let (inside_b, inside_a) = rayon::join(
            || Regions::new(&leaves, &adjacent, |l| l.b.is_empty(), other),
            || Regions::new(&leaves, &adjacent, |l| l.a.is_empty(), self),
        );

        // the faces wholly in free cells, and the pieces of the others
        let root_walls = walls(&root);
        let ((whole_a, pieces_a), (whole_b, pieces_b)) = rayon::join(
            || {
                sort_faces(
                    &a_c,
                    &a_leaves,
                    &leaves,
                    &root,
                    |f| self.face(f).bx(),
                    |l| (&l.a, l.b.is_empty()),
                )
            },
            || {
                sort_faces(
                    &b_c,
                    &b_leaves,
                    &leaves,
                    &root,
                    |f| other.face(f).bx(),
                    |l| (&l.b, l.a.is_empty()),
                )
            },
        );
        // the mixed cells, in parallel; a mixed leaf's lists are its
        // listed faces (`Piece::Mixed` indexes them)
        let mixed: Vec<u32> = (0..leaves.len() as u32)
            .filter(|&l| leaves[l as usize].mixed())
            .collect();
        // The faces that may meet the other surface: those not apart from
        // some face of it in some mixed cell (whole faces, by their
        // support planes). Every other face meets the other surface
        // nowhere (a common point would lie in a cell listing both), so it
        // is kept or dropped whole by one label (`label_untouched`); a
        // mixed cell all of whose faces are such ("clean") does nothing.
        // (without easy cells every mixed cell builds its trees, and the
        // untouched faces take their labels from them: the same result)
        let (meets_a, meets_b, mut clean) = touched(&mixed, &leaves, self, other);
        if !opts.easy_cells {
            clean.iter_mut().for_each(|c| *c = false);
        }
        let touched_a = |f: u32| meets_a.get(f as usize) != Some(&false);
        let touched_b = |f: u32| meets_b.get(f as usize) != Some(&false);
        let untouched_a = |f: u32| !touched_a(f);
        let untouched_b = |f: u32| !touched_b(f);
        // Each cell clips its faces to its walls itself, so that only the
        // cells at work hold their pieces, and finds the pieces that meet
        // no piece of the other surface (isolated). A cell whose pieces are
        // all isolated ("easy") builds nothing: its pieces' labels are
        // carried along their faces from the neighbouring cells
        // (`label_easy`). The others build their partitions and give
        // back what stays.
        let run = |l: u32, allow_easy: bool| -> Result<First, CsgError> {
            let leaf = &leaves[l as usize];
            let (bx, w) = (leaf.bx, walls(&leaf.bx));
            let masks = |pieces: &[Polygon], iso: &[bool], index: &[Option<u32>]| {
                index
                    .iter()
                    .map(|i| {
                        i.filter(|&i| iso[i as usize])
                            .map(|i| local::wall_edges(&pieces[i as usize], &w))
                    })
                    .collect::<Vec<Option<u8>>>()
            };
            // Untouched faces are isolated, and their pieces need no
            // labels of their own (their faces' are known): a cell tries
            // to be easy with only the other faces clipped. Their pieces
            // are the nodes of `label_easy`; an untouched face stands
            // there by its grid corners in the cell, with its label.
            let mut tried = None;
            if allow_easy {
                let (pa, ia) = clip_all(&leaf.a, |f| self.face(f), &bx, &w, &touched_a);
                let (pb, ib) = clip_all(&leaf.b, |f| other.face(f), &bx, &w, &touched_b);
                let (isa, isb) = local::isolated(&pa, &pb);
                if isa.iter().chain(&isb).all(|&x| x) {
                    let (ma, mb) = (masks(&pa, &isa, &ia), masks(&pb, &isb, &ib));
                    let la = Listed::new(&leaf.a, |f| self.face(f), &pa, &ia, touched_a, &bx);
                    let lb = Listed::new(&leaf.b, |f| other.face(f), &pb, &ib, touched_b, &bx);
                    return Ok(First::Easy((ma, la), (mb, lb)));
                }
                tried = Some(((pa, ia), (pb, ib)));
            }
            // every face's piece (those clipped already reused)
            let (pa, ia, pb, ib) = match tried {
                Some(((pa, ia), (pb, ib))) => {
                    let (pa, ia) =
                        clip_rest(&leaf.a, |f| self.face(f), &bx, &w, &touched_a, pa, &ia);
                    let (pb, ib) =
                        clip_rest(&leaf.b, |f| other.face(f), &bx, &w, &touched_b, pb, &ib);
                    (pa, ia, pb, ib)
                }
                None => {
                    let (pa, ia) = clip_all(&leaf.a, |f| self.face(f), &bx, &w, &|_| true);
                    let (pb, ib) = clip_all(&leaf.b, |f| other.face(f), &bx, &w, &|_| true);
                    (pa, ia, pb, ib)
                }
            };
            let (isa, isb) = local::isolated(&pa, &pb);
            let (ma, mb) = (masks(&pa, &isa, &ia), masks(&pb, &isb, &ib));
            let r = bx.0.map(|c| c as i32);
            let c = local::boolean_pieces(
                &bx,
                pa,
                pb,
                op,
                (keep_a, keep_b),
                || self.winding(r),
                || other.winding(r),
            )?;
            Ok(First::Done(Made::of(c, &ia, &ib), ma, mb))
        };
        let first: Vec<(u32, First)> = mixed
            .par_iter()
            .filter(|&&l| !clean[l as usize])
            .map(|&l| run(l, opts.easy_cells).map(|r| (l, r)))
            .collect::<Result<_, _>>()?;
        let mut stats = Stats {
            cells: leaves.len(),
            mixed_cells: mixed.len(),
            clean_cells: mixed.iter().filter(|&&l| clean[l as usize]).count(),
            ..Stats::default()
        };
        let mut add: Vec<Added> = Vec::new();
        let mut fates_a: FxHashMap<u32, Vec<PieceFate>> = FxHashMap::default();
        let mut fates_b: FxHashMap<u32, Vec<PieceFate>> = FxHashMap::default();
        let mut masks_a: FxHashMap<u32, Vec<Option<u8>>> = FxHashMap::default();
        let mut masks_b: FxHashMap<u32, Vec<Option<u8>>> = FxHashMap::default();
        let mut easy: Vec<u32> = Vec::new();
        let mut listed_a: FxHashMap<u32, Listed> = FxHashMap::default();
        let mut listed_b: FxHashMap<u32, Listed> = FxHashMap::default();
        // a cell done: its boundary (merged) or its fates
        let mut done = |l: u32,
                        made: Made,
                        fates_a: &mut FxHashMap<_, _>,
                        fates_b: &mut FxHashMap<_, _>| match made {
            Made::Merged(ps) => {
                stats.merged_cells += 1;
                add.extend(ps.into_iter().map(|p| Added::New(Box::new(p))))
            }
            Made::Fates(fa, fb) => {
                fates_a.insert(l, fa);
                fates_b.insert(l, fb);
            }
        };
        for (l, r) in first {
            match r {
                First::Easy((ma, la), (mb, lb)) => {
                    easy.push(l);
                    masks_a.insert(l, ma);
                    masks_b.insert(l, mb);
                    listed_a.insert(l, la);
                    listed_b.insert(l, lb);
                }
                First::Done(made, ma, mb) => {
                    if matches!(made, Made::Fates(..)) {
                        masks_a.insert(l, ma);
                        masks_b.insert(l, mb);
                    }
                    done(l, made, &mut fates_a, &mut fates_b);
                }
            }
        }
        // the easy cells' labels
        // a piece kept whole is inside when pieces inside are kept
        fn label_of(
            fates: &FxHashMap<u32, Vec<PieceFate>>,
            keep_inside: bool,
        ) -> impl Fn(u32, u32) -> Option<bool> + Sync + '_ {
            move |l: u32, i: u32| match fates.get(&l).map(|v| &v[i as usize]) {
                Some(PieceFate::Keep) => Some(keep_inside),
                Some(PieceFate::Drop) => Some(!keep_inside),
                _ => None,
            }
        }
        // the untouched faces' labels
        let (untouched_la, untouched_lb) = rayon::join(
            || {
                label_untouched(
                    &pieces_a,
                    self.faces.len(),
                    &untouched_a,
                    |f| self.face(f),
                    &leaves,
                    &label_of(&fates_a, keep_a(true)),
                    &|l| inside_b.inside(l),
                    &|g| other.winding(g) != 0,
                )
            },
            || {
                label_untouched(
                    &pieces_b,
                    other.faces.len(),
                    &untouched_b,
                    |f| other.face(f),
                    &leaves,
                    &label_of(&fates_b, keep_b(true)),
                    &|l| inside_a.inside(l),
                    &|g| self.winding(g) != 0,
                )
            },
        );
        // (from the cells that built their trees, free cells, each other
        // and winding numbers; by face id)
        let (face_la, face_lb) = (untouched_la?, untouched_lb?);
        let (labels_a, labels_b) = rayon::join(
            || {
                label_easy(
                    true,
                    |f| self.face(f),
                    &leaves,
                    &adjacent,
                    &masks_a,
                    &listed_a,
                    &label_of(&fates_a, keep_a(true)),
                    &|f| face_la[f as usize],
                    &|l| inside_b.inside(l),
                    &|g| other.winding(g) != 0,
                )
            },
            || {
                label_easy(
                    false,
                    |f| other.face(f),
                    &leaves,
                    &adjacent,
                    &masks_b,
                    &listed_b,
                    &label_of(&fates_b, keep_b(true)),
                    &|f| face_lb[f as usize],
                    &|l| inside_a.inside(l),
                    &|g| self.winding(g) != 0,
                )
            },
        );
        let (mut labels_a, mut labels_b) = (labels_a?, labels_b?);
        drop_aside((listed_a, listed_b));
        // an easy cell with a piece no label reached does the full work
        let mut again: Vec<u32> = Vec::new();
        for l in easy {
            let la = labels_a.remove(&l).expect("an easy cell");
            let lb = labels_b.remove(&l).expect("an easy cell");
            let settled =
                |masks: &[Option<u8>], labels: &[Option<bool>], keep: &dyn Fn(bool) -> bool| {
                    masks
                        .iter()
                        .zip(labels)
                        .map(|(m, lab)| match (m, lab) {
                            (None, _) => Some(PieceFate::Missing),
                            (Some(_), Some(inside)) => Some(if keep(*inside) {
                                PieceFate::Keep
                            } else {
                                PieceFate::Drop
                            }),
                            (Some(_), None) => None,
                        })
                        .collect::<Option<Vec<PieceFate>>>()
                };
            let sa = settled(&masks_a[&l], &la, &keep_a);
            let sb = settled(&masks_b[&l], &lb, &keep_b);
            match (sa, sb) {
                (Some(sa), Some(sb)) => {
                    stats.easy_cells += 1;
                    fates_a.insert(l, sa);
                    fates_b.insert(l, sb);
                }
                _ => again.push(l),
            }
        }
        let redone: Vec<(u32, First)> = again
            .into_par_iter()
            .map(|l| run(l, false).map(|r| (l, r)))
            .collect::<Result<_, _>>()?;
        for (l, r) in redone {
            match r {
                First::Done(made, _, _) => done(l, made, &mut fates_a, &mut fates_b),
                First::Easy(..) => unreachable!("a second run does the full work"),
            }
        }

        // the changes, now that everything is known
        // (decided in parallel, applied in order)
        let mut remove: Vec<u32> = whole_a
            .par_iter()
            .filter(|&&i| {
                let inside =
                    meeting_leaf(self.face(a_c[i as usize]), &a_leaves[i as usize], &leaves)
                        .is_some_and(|l| inside_b.inside(l));
                !keep_a(inside)
            })
            .map(|&i| a_c[i as usize])
            .collect();
        // a piece beyond the octree's box is beyond the other solid's box
        // (an untouched face stays or goes whole by its label; a face the
        // other surface may meet has no piece in a clean cell)
        let settle_all = |pieces: &[(u32, Vec<Piece>)],
                          solid: &Solid,
                          keep: &(dyn Fn(bool) -> bool + Sync),
                          other_side: &Regions,
                          fates: &FxHashMap<u32, Vec<PieceFate>>,
                          labels: &[Option<bool>]|
         -> Result<Settled, CsgError> {
            pieces
                .par_iter()
                .map(|(f, pieces)| {
                    if let Some(inside) = labels[*f as usize] {
                        return Ok((*f, (!keep(inside)).then(Vec::new)));
                    }
                    if pieces
                        .iter()
                        .any(|p| matches!(p, Piece::Mixed(l, _) if clean[*l as usize]))
                    {
                        return Err(CsgError::Internal(
                            "a face the other surface may meet has a piece in a clean cell".into(),
                        ));
                    }
                    let kept = settle(
                        solid.face(*f),
                        pieces,
                        &|l| keep(l.is_some_and(|l| other_side.inside(l))),
                        fates,
                        &leaves,
                        &root_walls,
                    );
                    Ok((*f, kept))
                })
                .collect()
        };
        // the two operands' faces at once (each in parallel, but each
        // with sequential tails)
        let (settled_a, (kept_b, settled_b)) = rayon::join(
            || settle_all(&pieces_a, self, &keep_a, &inside_b, &fates_a, &face_la),
            || {
                rayon::join(
                    // the other solid's faces kept whole are listed, to be
                    // copied or moved over (flipped for a difference)
                    || -> Vec<u32> {
                        whole_b
                            .par_iter()
                            .filter(|&&i| {
                                let inside = meeting_leaf(
                                    other.face(b_c[i as usize]),
                                    &b_leaves[i as usize],
                                    &leaves,
                                )
                                .is_some_and(|l| inside_a.inside(l));
                                keep_b(inside)
                            })
                            .map(|&i| b_c[i as usize])
                            .collect()
                    },
                    || settle_all(&pieces_b, other, &keep_b, &inside_a, &fates_b, &face_lb),
                )
            },
        );
        drop_aside((pieces_a, fates_a, pieces_b, fates_b));
        let (settled_a, settled_b) = (settled_a?, settled_b?);
        for (f, outcome) in settled_a {
            if let Some(kept) = outcome {
                remove.push(f);
                if !kept.is_empty() {
                    stats.cut_faces += 1;
                    stats.pieces += kept.len();
                }
                add.extend(kept.into_iter().map(|p| Added::New(Box::new(p))));
            }
        }
        add.extend(kept_b.into_iter().map(Added::Whole));
        for (f, outcome) in settled_b {
            match outcome {
                None => add.push(Added::Whole(f)),
                Some(kept) => {
                    if !kept.is_empty() {
                        stats.cut_faces += 1;
                        stats.pieces += kept.len();
                    }
                    add.extend(
                        kept.into_iter()
                            .map(|p| Added::New(Box::new(if flip_b { p.flipped() } else { p }))),
                    );
                }
            }
        }
        // the faces away from the shared box: outside the other solid
        if op == BoolOp::Union {
            let mut near = vec![false; other.faces.len()];
            b_c.iter().for_each(|&f| near[f as usize] = true);
            for (i, f) in other.faces.iter().enumerate() {
                if f.is_some() && !near[i] {
                    add.push(Added::Whole(i as u32));
                }
            }
        }
        if op == BoolOp::Intersection {
            let mut near = vec![false; self.faces.len()];
            a_c.iter().for_each(|&f| near[f as usize] = true);
            for i in 0..self.faces.len() as u32 {
                if self.faces[i as usize].is_some() && !near[i as usize] {
                    remove.push(i);
                }
            }
        }
        self.remove_all(&remove);
        // the octree and its lists go on the pool (freeing them here, as
        // the function returns, held up what follows)
        drop_aside((leaves, a_leaves, b_leaves, adjacent, a_c, b_c));
        drop_aside((inside_a, inside_b, masks_a, masks_b, remove));
        Ok((stats, Plan { add, flip: flip_b }))
    }
}

/// What an operation adds to the first solid, in order: new faces, and
/// the other solid's faces kept whole (flipped if `flip`).
pub(crate) struct Plan {
    pub(crate) add: Vec<Added>,
    pub(crate) flip: bool,
}

/// A new face, or (`Whole`) the other solid's face kept whole; new faces
/// are boxed so that the many whole ones cost a few bytes each.
pub(crate) enum Added {
    New(Box<Polygon>),
    Whole(u32),
}
