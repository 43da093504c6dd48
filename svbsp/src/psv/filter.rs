//! A piece's walk through a shadow-volume tree: its lit and shadowed
//! parts, cut only where they differ ([`filter`]). Shading walks every
//! receiver so (`crate::engine`), and the tree's building walks the
//! parts that rest at a leaf where a volume is grafted (`rests.rs`).

use bsp_core::Side;
use smallvec::SmallVec;

use super::{LIT, SHADOW, ShadowVolumes};
use crate::arena::pieces::{ArenaMark, Piece, PieceArena};

/// What is left of a piece's walk through a tree: a piece to take on
/// from a link, or a cut to undo where its two sides came back alike.
pub(crate) enum Walk {
    Visit(Piece, u32),
    /// Both pieces of `parent`'s cut start at `out[mark]`; the arena held
    /// `arena` before the cut.
    Merge {
        parent: Piece,
        mark: usize,
        arena: ArenaMark,
    },
}

/// Filters `piece` through a shadow-volume tree: the lit and shadowed
/// pieces go to `out`.
///
/// First a quick test without cuts ([`super::reach`]): a piece that
/// can only reach leaves of one kind is all lit or all in shadow, and
/// stays whole. Otherwise the piece descends cut by every plane it
/// straddles; a cut whose two sides come back as single pieces with the
/// same flag is undone (the parent piece is kept, the arena rolled back),
/// so only cuts that separate lit from shadow survive.
#[allow(clippy::too_many_arguments)]
pub(crate) fn filter(
    sv: &ShadowVolumes,
    arena: &mut PieceArena,
    support: u32,
    piece: Piece,
    out: &mut Vec<(Piece, bool)>,
    stack: &mut Vec<Walk>,
    links: &mut Vec<u32>,
    sides: &mut SmallVec<[Side; 8]>,
) {
    // (where the quick test cannot tell, the exact descent starts at the
    // first node the piece straddles: the same walk, less its first part)
    let mut fork = sv.root;
    match super::reach(
        &sv.nodes,
        sv.root,
        |p| arena.sides(&piece, p),
        super::REACH_BUDGET,
        links,
        &mut fork,
        None,
    ) {
        Some((true, false)) => return out.push((piece, true)),
        Some((false, true)) => return out.push((piece, false)),
        _ => {}
    }
    stack.clear();
    stack.push(Walk::Visit(piece, fork));
    while let Some(t) = stack.pop() {
        match t {
            Walk::Visit(mut p, mut link) => loop {
                if link == LIT {
                    out.push((p, true));
                    break;
                }
                if link == SHADOW {
                    out.push((p, false));
                    break;
                }
                let n = &sv.nodes[link as usize];
                // every vertex's side, kept for a split (classified once)
                let s = arena.classify_into(&p, &n.plane, sides);
                let (front, back) = match (n.cap, s.front, s.back) {
                    // a cap: the part behind it is hidden
                    (true, _, false) => {
                        link = n.front;
                        continue;
                    }
                    (true, false, true) => {
                        out.push((p, false));
                        break;
                    }
                    (true, true, true) => (n.front, SHADOW),
                    // a plane through the light
                    (false, true, false) | (false, false, false) => {
                        link = n.front;
                        continue;
                    }
                    (false, false, true) => {
                        link = n.back;
                        continue;
                    }
                    (false, true, true) => (n.front, n.back),
                };
                let mark = arena.mark();
                let cut = arena.add_plane(n.plane);
                let (f, b) = arena.split(support, &p, cut, sides);
                stack.push(Walk::Merge {
                    parent: p,
                    mark: out.len(),
                    arena: mark,
                });
                stack.push(Walk::Visit(b, back));
                p = f;
                link = front;
            },
            Walk::Merge {
                parent,
                mark,
                arena: am,
            } => {
                if out.len() == mark + 2 && out[mark].1 == out[mark + 1].1 {
                    let lit = out[mark].1;
                    out.truncate(mark);
                    arena.rollback(am);
                    out.push((parent, lit));
                }
            }
        }
    }
}
