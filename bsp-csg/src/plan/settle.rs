//! Sorting each face into the leaves it crosses ([`sort_faces`]), and
//! settling what stays of it once every cell is decided ([`settle`]):
//! a face none of whose pieces the other surface cuts stays exactly as
//! it was, however many cells it spans; the others are replaced by their
//! kept pieces and fragments, put back together where they can be.

use bsp_core::Polygon;
use bsp_core::internals::ConvexFace;
use rustc_hash::FxHashMap;
use smallvec::SmallVec;

use super::local;
use super::mixed_cell::PieceFate;
use super::octree::{Leaf, walls};
use super::operands::Operand;
use crate::index::{IBox, holds};
use crate::solid::SolidFace;

/// Where a piece of a face (the face cut by the octree's walls) lies; it
/// is not clipped until it must be.
pub(super) enum FacePiece {
    /// In a leaf free of the other surface.
    InFreeLeaf(u32),
    /// Beyond the octree's box, so beyond the other solid's.
    BeyondOctree,
    /// In a mixed leaf, as the `listed`-th face of its list of this
    /// operand.
    InMixedLeaf { leaf: u32, listed: u32 },
}

/// A face with pieces in mixed leaves, and all its pieces.
pub(super) struct PiecedFace {
    pub(super) face: u32,
    pub(super) pieces: Vec<FacePiece>,
}

/// One operand's faces in the octree's box, sorted.
pub(super) struct SortedFaces {
    /// The faces only in leaves free of the other surface, by their place
    /// in the list sorted.
    pub(super) whole: Vec<u32>,
    /// Every other face, by id, with its pieces.
    pub(super) pieced: Vec<PiecedFace>,
}

/// A face with pieces, settled.
pub(super) struct SettledFace {
    pub(super) face: u32,
    pub(super) remains: Remains,
}

/// What stays of a face with pieces.
pub(super) enum Remains {
    /// The whole face, as it is.
    Whole,
    /// These polygons instead (none: the face goes).
    Parts(Vec<Polygon>),
}

/// Sorts operand `o`'s `faces` (their leaves `leaves_of`, by place) into
/// those in leaves free of the other surface only and those with pieces
/// in mixed leaves. A face's piece in a mixed leaf is named by its place
/// in the leaf's list of `o`'s faces (the leaves list the faces in the
/// order of `faces`); `bx` gives a face's box.
pub(super) fn sort_faces(
    faces: &[u32],
    leaves_of: &[SmallVec<[u32; 4]>],
    leaves: &[Leaf],
    root: &IBox,
    bx: impl Fn(u32) -> IBox,
    o: Operand,
) -> SortedFaces {
    let mut whole = Vec::new();
    let mut pieced = Vec::new();
    // per leaf, the faces met so far
    let mut seen: Vec<u32> = vec![0; leaves.len()];
    let free = |l: u32| leaves[l as usize].free_of(o.other());
    for (i, (&f, ls)) in faces.iter().zip(leaves_of).enumerate() {
        // a face in no cell lies beyond the octree's box
        if ls.iter().all(|&l| free(l)) {
            whole.push(i as u32);
            continue;
        }
        let mut pieces: Vec<FacePiece> = ls
            .iter()
            .map(|&l| {
                if free(l) {
                    FacePiece::InFreeLeaf(l)
                } else {
                    let at = seen[l as usize];
                    seen[l as usize] += 1;
                    debug_assert_eq!(leaves[l as usize].faces(o)[at as usize], f);
                    FacePiece::InMixedLeaf {
                        leaf: l,
                        listed: at,
                    }
                }
            })
            .collect();
        let fb = bx(f);
        if (0..3).any(|k| fb.0[k] < root.0[k] || fb.1[k] > root.1[k]) {
            pieces.push(FacePiece::BeyondOctree);
        }
        pieced.push(PiecedFace { face: f, pieces });
    }
    SortedFaces { whole, pieced }
}

/// A leaf among `ls` (the leaves a face's box and plane tests put it in)
/// that the face really meets: the one holding a grid vertex of it,
/// else the first one its clipping leaves something in. The lists may
/// name leaves the face does not reach, whose region may lie on the other
/// side of the other surface; `None` if it meets none (it lies beyond the
/// octree's box, so beyond the other solid).
pub(super) fn meeting_leaf(face: &SolidFace, ls: &[u32], leaves: &[Leaf]) -> Option<u32> {
    for i in 0..face.corner_count() {
        if let Some(g) = face.corner(i).as_grid()
            && let Some(&l) = ls.iter().find(|&&l| holds(&leaves[l as usize].bx, &g))
        {
            return Some(l);
        }
    }
    let poly = face.polygon();
    let fb = face.bx();
    ls.iter().copied().find(|&l| {
        let bx = &leaves[l as usize].bx;
        local::clip_in(&poly, &fb, bx, &walls(bx)).is_some()
    })
}

/// What stays of a face cut into `pieces`. `free_stays(piece)` says
/// whether a piece in a free leaf or beyond the octree's box stays;
/// `fates` are the mixed cells' (the fragments kept are copied: faces
/// settle in parallel). The face is clipped anew to the leaves whose
/// piece stays whole, joined into larger boxes (`root` holds the walls
/// of the octree's box).
pub(super) fn settle(
    face: &SolidFace,
    pieces: &[FacePiece],
    free_stays: &dyn Fn(&FacePiece) -> bool,
    fates: &FxHashMap<u32, Vec<PieceFate>>,
    leaves: &[Leaf],
    root: &[bsp_core::Plane; 6],
) -> Remains {
    let fate = |leaf: u32, listed: u32| fates.get(&leaf).map(|v| &v[listed as usize]);
    // (a piece in a merged cell, with no fates, does not stay whole: the
    // cell's boundary replaces it)
    let stays_whole = |p: &FacePiece| match *p {
        FacePiece::InMixedLeaf { leaf, listed } => {
            matches!(
                fate(leaf, listed),
                Some(PieceFate::Missing | PieceFate::Keep)
            )
        }
        _ => free_stays(p),
    };
    if pieces.iter().all(stays_whole) {
        return Remains::Whole;
    }
    // the cells whose piece stays whole (the face clipped to the cell),
    // and the fragments of the cells that cut it
    let mut kept = Vec::new();
    let mut whole: Vec<IBox> = Vec::new();
    for p in pieces {
        match *p {
            FacePiece::InFreeLeaf(l) if free_stays(p) => whole.push(leaves[l as usize].bx),
            FacePiece::BeyondOctree if free_stays(p) => {
                kept.extend(local::outside(&face.polygon(), root))
            }
            FacePiece::InFreeLeaf(_) | FacePiece::BeyondOctree => {}
            FacePiece::InMixedLeaf { leaf, listed } => match fate(leaf, listed) {
                Some(PieceFate::Keep) => whole.push(leaves[leaf as usize].bx),
                Some(PieceFate::Cut(frags)) => kept.extend(frags.iter().cloned()),
                _ => {}
            },
        }
    }
    // the face clipped to the boxes those cells join into: the same
    // region in fewer pieces than a piece per cell (a face crossing many
    // small cells has dozens), so fewer clips and fewer to put together
    join_boxes(&mut whole);
    kept.extend(
        whole
            .iter()
            .filter_map(|bx| local::clip_face(face, bx, &walls(bx))),
    );
    Remains::Parts(rejoin(kept))
}

/// Joins boxes that tile space without overlap into fewer boxes covering
/// the same points: two boxes join where they share a whole wall (the
/// same extent along two axes, one just after the other along the
/// third), axis after axis, until none do. The result does not depend on
/// the boxes' order.
fn join_boxes(boxes: &mut Vec<IBox>) {
    loop {
        let before = boxes.len();
        for k in 0..3 {
            let (u, v) = ((k + 1) % 3, (k + 2) % 3);
            let rest = |b: &IBox| (b.0[u], b.1[u], b.0[v], b.1[v]);
            boxes.sort_unstable_by_key(|b| (rest(b), b.0[k]));
            let mut joined: Vec<IBox> = Vec::with_capacity(boxes.len());
            for b in boxes.drain(..) {
                match joined.last_mut() {
                    Some(last) if rest(last) == rest(&b) && last.1[k] + 1 == b.0[k] => {
                        last.1[k] = b.1[k]
                    }
                    _ => joined.push(b),
                }
            }
            *boxes = joined;
        }
        if boxes.len() == before {
            return;
        }
    }
}

/// The kept pieces of one face put back together where two share a whole
/// edge and their union is convex ([`Polygon::merge`]): the cells' walls
/// cut a face into pieces that the other surface does not separate, and
/// a piece per cell would be a polygon per cell in the result (more
/// vertices to weld, more triangles). The same region, exactly; pieces
/// whose edges meet partly (a T-junction) stay apart.
fn rejoin(pieces: Vec<Polygon>) -> Vec<Polygon> {
    if pieces.len() < 2 {
        return pieces;
    }
    rejoined(pieces).into_iter().flatten().collect()
}

/// [`rejoin`] in place: each polygon's slot holds what it grew into, or
/// `None` where it was merged into another (an earlier one, or a later
/// one that then holds the union). Polygons of different planes never
/// merge, so any polygons may be given: an operation passes every new
/// face of its result, and the pieces of faces that one plane held (a
/// quad written as two triangles, both cut) come together again.
pub(super) fn rejoined(pieces: Vec<Polygon>) -> Vec<Option<Polygon>> {
    // the endpoints' approximate keys: a pair of equal points that gets
    // two keys is only a merge missed, and a merge is decided exactly
    let keys_of = |p: &Polygon| -> SmallVec<[u64; 8]> {
        p.vertices()
            .iter()
            .map(bsp_core::Point::approx_key)
            .collect()
    };
    // each directed edge's latest polygon; an entry left by a polygon
    // merged since only costs a merge that fails
    let mut edges: FxHashMap<(u64, u64), u32> = FxHashMap::default();
    let add_edges = |edges: &mut FxHashMap<(u64, u64), u32>, ks: &[u64], i: usize| {
        for e in 0..ks.len() {
            edges.insert((ks[e], ks[(e + 1) % ks.len()]), i as u32);
        }
    };
    let mut keys: Vec<SmallVec<[u64; 8]>> = pieces.iter().map(keys_of).collect();
    for (i, ks) in keys.iter().enumerate() {
        add_edges(&mut edges, ks, i);
    }
    let mut live: Vec<Option<Polygon>> = pieces.into_iter().map(Some).collect();
    // each polygon looks for a partner across its edges; one that grew
    // looks again
    let mut work: Vec<usize> = (0..live.len()).rev().collect();
    while let Some(i) = work.pop() {
        let Some(p) = live[i].as_ref() else { continue };
        let ks = &keys[i];
        let partner = (0..ks.len()).find_map(|e| {
            let j = *edges.get(&(ks[(e + 1) % ks.len()], ks[e]))? as usize;
            if j == i {
                return None;
            }
            p.merge(live[j].as_ref()?).map(|m| (j, m))
        });
        if let Some((j, m)) = partner {
            keys[i] = keys_of(&m);
            add_edges(&mut edges, &keys[i], i);
            live[i] = Some(m);
            live[j] = None;
            work.push(i);
        }
    }
    live
}

#[cfg(test)]
mod tests {
    use super::*;
    use bsp_core::internals::Parts;
    use bsp_core::{Plane, Side};

    /// The same points in the same cyclic order.
    fn same_loop(a: &Polygon, b: &Polygon) -> bool {
        let (x, y) = (a.vertices(), b.vertices());
        let n = x.len();
        n == y.len() && (0..n).any(|r| (0..n).all(|i| x[i].same_point(&y[(i + r) % n])))
    }

    /// `p` cut by the walls `x = 4, 8, 12` and `y = 4, 8, 12`: up to 16
    /// pieces, one per cell, as the cells' clipping leaves them.
    fn cells_of(p: &Polygon) -> Vec<Polygon> {
        let mut pieces = vec![p.clone()];
        for k in 0..2 {
            for w in [4i128, 8, 12] {
                let mut n = [0; 3];
                n[k] = 1;
                let wall = Plane::new(n, -w).unwrap();
                pieces = pieces
                    .into_iter()
                    .flat_map(|q| match q.parts(&wall) {
                        Parts::Split { front, back } => vec![back, front],
                        Parts::Whole(_) => vec![q],
                    })
                    .collect();
            }
        }
        pieces
    }

    #[test]
    fn a_face_cut_by_walls_and_one_plane_is_put_back_whole() {
        let square =
            Polygon::from_grid_points(&[[1, 1, 0], [15, 1, 0], [15, 15, 0], [1, 15, 0]], 0)
                .unwrap();
        // no cut: the square itself
        let pieces = cells_of(&square);
        assert_eq!(pieces.len(), 16);
        let back = rejoin(pieces);
        assert_eq!(back.len(), 1);
        assert!(same_loop(&back[0], &square));
        // a cut 2x + 3y = 41 across many cells: what is behind it, whole
        let cut = Plane::new([2, 3, 0], -41).unwrap();
        let kept: Vec<Polygon> = cells_of(&square)
            .into_iter()
            .filter_map(|mut q| q.clip(&cut, Side::Back).then_some(q))
            .collect();
        assert!(kept.len() > 6, "{} pieces", kept.len());
        let mut whole = square.clone();
        assert!(whole.clip(&cut, Side::Back));
        let back = rejoin(kept);
        assert_eq!(back.len(), 1);
        assert!(back[0].sanity_check().is_ok());
        assert!(same_loop(&back[0], &whole));
    }

    #[test]
    fn pieces_a_bend_separates_stay_convex_and_fewer() {
        // the kept part is behind two cuts meeting at a reflex corner: not
        // convex, so it stays in several convex pieces, each valid
        let square =
            Polygon::from_grid_points(&[[1, 1, 0], [15, 1, 0], [15, 15, 0], [1, 15, 0]], 0)
                .unwrap();
        let (c1, c2) = (
            Plane::new([1, 0, 0], -10).unwrap(),
            Plane::new([0, 1, 0], -10).unwrap(),
        );
        // kept: x < 10 or y < 10 (an L)
        let kept: Vec<Polygon> = cells_of(&square)
            .into_iter()
            .flat_map(|q| {
                let mut a = q.clone();
                let left = a.clip(&c1, Side::Back).then_some(a);
                let mut b = q;
                let right = b.clip(&c1, Side::Front) && b.clip(&c2, Side::Back);
                left.into_iter().chain(right.then_some(b))
            })
            .collect();
        let n = kept.len();
        let back = rejoin(kept);
        assert!(back.len() >= 2 && back.len() < n, "{} of {n}", back.len());
        for p in &back {
            assert!(p.sanity_check().is_ok());
        }
        // the same region: a point off every wall and cut is in one piece
        // exactly when it is kept
        let odd = [2, 3, 5, 6, 7, 9, 11, 13, 14];
        for x in odd {
            for y in odd {
                let pt = bsp_core::Point::Grid([x, y, 0]);
                let holding = back
                    .iter()
                    .filter(|p| p.edge_planes().iter().all(|e| pt.classify(e) == Side::Back))
                    .count();
                assert_eq!(holding, usize::from(x < 10 || y < 10), "({x}, {y})");
            }
        }
    }

    /// Joined boxes cover exactly the points of the boxes joined: an
    /// octree cell's eight children become the cell, an L of three boxes
    /// stays two, and the order they come in does not matter.
    #[test]
    fn joined_boxes_cover_the_same_points() {
        let children: Vec<IBox> = (0..8)
            .map(|c: i64| {
                let lo = [0, 1, 2].map(|k| if c >> k & 1 == 0 { 0 } else { 4 });
                (lo, lo.map(|x| x + 3))
            })
            .collect();
        for turn in 0..8 {
            let mut bs = children.clone();
            bs.rotate_left(turn);
            join_boxes(&mut bs);
            assert_eq!(bs, vec![([0, 0, 0], [7, 7, 7])]);
        }
        // an L (and a box apart): a cell and two of its neighbours
        let l_shape = vec![
            ([0, 0, 0], [1, 1, 1]),
            ([2, 0, 0], [3, 1, 1]),
            ([0, 2, 0], [1, 3, 1]),
            ([9, 9, 9], [9, 9, 9]),
        ];
        let mut bs = l_shape.clone();
        join_boxes(&mut bs);
        assert_eq!(bs.len(), 3);
        let points = |bs: &[IBox]| -> Vec<[i64; 3]> {
            let mut ps: Vec<[i64; 3]> = bs
                .iter()
                .flat_map(|b| {
                    (b.0[0]..=b.1[0]).flat_map(move |x| {
                        (b.0[1]..=b.1[1])
                            .flat_map(move |y| (b.0[2]..=b.1[2]).map(move |z| [x, y, z]))
                    })
                })
                .collect();
            ps.sort_unstable();
            ps
        };
        assert_eq!(points(&bs), points(&l_shape));
        let mut reversed: Vec<IBox> = l_shape.into_iter().rev().collect();
        join_boxes(&mut reversed);
        assert_eq!(reversed, bs);
    }
}
