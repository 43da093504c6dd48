//! An adaptive octree over the region where two surfaces may meet.
//!
//! A cell is a box of grid coordinates `[lo, hi]` (inclusive, per axis);
//! its walls lie half a step outside, at `lo − ½` and `hi + ½`, on planes
//! that hold no grid point — so no input vertex and no input face lies on a
//! wall, and no face edge lies in one. A cell is split (at the middle of
//! every axis it spans more than one coordinate of) while it holds faces of
//! both operands, more than `leaf_size` faces in all, and can be split.
//! Faces are sent to every child their box overlaps.

use bsp_core::Plane;

use crate::index::{IBox, overlaps};

/// A leaf of the octree: its box and the faces of each operand whose box
/// overlaps it.
#[derive(Clone, Debug)]
pub(crate) struct Leaf {
    pub(crate) bx: IBox,
    pub(crate) a: Vec<u32>,
    pub(crate) b: Vec<u32>,
}

impl Leaf {
    pub(crate) fn mixed(&self) -> bool {
        !self.a.is_empty() && !self.b.is_empty()
    }
}

/// The six wall planes of a cell, interior behind each.
pub(crate) fn walls(bx: &IBox) -> [Plane; 6] {
    let wall = |k: usize, sign: i64, c: i64| {
        let mut n = [0i64; 3];
        n[k] = 2 * sign;
        // sign · 2x − (2c ± 1) = 0
        Plane::new(n, -(sign as i128) * (2 * c as i128 + sign as i128))
            .expect("a wall plane is within the budget")
    };
    let (lo, hi) = bx;
    [
        wall(0, -1, lo[0]),
        wall(0, 1, hi[0]),
        wall(1, -1, lo[1]),
        wall(1, 1, hi[1]),
        wall(2, -1, lo[2]),
        wall(2, 1, hi[2]),
    ]
}

/// The leaves of the octree over `domain` for the faces of `a` and `b`
/// (ids with their boxes), in a fixed order.
pub(crate) fn build(
    domain: IBox,
    a: Vec<u32>,
    b: Vec<u32>,
    box_a: &impl Fn(u32) -> IBox,
    box_b: &impl Fn(u32) -> IBox,
    leaf_size: usize,
) -> Vec<Leaf> {
    let mut leaves = Vec::new();
    let mut stack = vec![Leaf { bx: domain, a, b }];
    while let Some(cell) = stack.pop() {
        let (lo, hi) = cell.bx;
        let split: Vec<usize> = (0..3).filter(|&k| hi[k] > lo[k]).collect();
        if !cell.mixed() || cell.a.len() + cell.b.len() <= leaf_size || split.is_empty() {
            leaves.push(cell);
            continue;
        }
        let mid = [0, 1, 2].map(|k| lo[k] + (hi[k] - lo[k]) / 2);
        let mut children: Vec<IBox> = vec![(lo, hi)];
        for &k in &split {
            children = children
                .into_iter()
                .flat_map(|(l, h)| {
                    let (mut h1, mut l2) = (h, l);
                    h1[k] = mid[k];
                    l2[k] = mid[k] + 1;
                    [(l, h1), (l2, h)]
                })
                .collect();
        }
        // children pushed in reverse so that they come out in order
        for bx in children.into_iter().rev() {
            let a = cell
                .a
                .iter()
                .copied()
                .filter(|&f| overlaps(&box_a(f), &bx))
                .collect();
            let b = cell
                .b
                .iter()
                .copied()
                .filter(|&f| overlaps(&box_b(f), &bx))
                .collect();
            stack.push(Leaf { bx, a, b });
        }
    }
    leaves
}

/// Pairs of leaves that share a piece of wall with an area: their boxes
/// touch along one axis (`hi + 1 == lo`) and their ranges overlap along the
/// two others.
pub(crate) fn adjacent(leaves: &[Leaf]) -> Vec<(u32, u32)> {
    let mut out = Vec::new();
    for k in 0..3 {
        let (u, v) = ((k + 1) % 3, (k + 2) % 3);
        // leaves by the coordinate of their upper and of their lower wall
        let mut upper: Vec<(i64, u32)> = leaves
            .iter()
            .enumerate()
            .map(|(i, l)| (l.bx.1[k], i as u32))
            .collect();
        let mut lower: Vec<(i64, u32)> = leaves
            .iter()
            .enumerate()
            .map(|(i, l)| (l.bx.0[k] - 1, i as u32))
            .collect();
        upper.sort_unstable();
        lower.sort_unstable();
        let (mut i, mut j) = (0, 0);
        while i < upper.len() && j < lower.len() {
            let c = upper[i].0.min(lower[j].0);
            let i1 = i + upper[i..].iter().take_while(|x| x.0 == c).count();
            let j1 = j + lower[j..].iter().take_while(|x| x.0 == c).count();
            for &(_, p) in &upper[i..i1] {
                for &(_, q) in &lower[j..j1] {
                    let (bp, bq) = (&leaves[p as usize].bx, &leaves[q as usize].bx);
                    let meet = |a: usize| bp.0[a] <= bq.1[a] && bq.0[a] <= bp.1[a];
                    if meet(u) && meet(v) {
                        out.push((p, q));
                    }
                }
            }
            (i, j) = (i1, j1);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use bsp_core::Side;

    #[test]
    fn walls_hold_no_grid_point_and_bound_the_cell() {
        let bx = ([0, -3, 5], [2, 4, 5]);
        for w in walls(&bx) {
            for p in [[0, -3, 5], [2, 4, 5], [1, 0, 5]] {
                assert_eq!(w.classify_grid(p), Side::Back, "{w:?} {p:?}");
            }
            for p in [[3, 0, 5], [-1, 0, 5], [0, 5, 5], [0, 0, 6], [0, 0, 4]] {
                let s = w.classify_grid(p);
                assert_ne!(s, Side::On);
            }
        }
        assert!(
            walls(&bx)
                .iter()
                .any(|w| w.classify_grid([3, 0, 5]) == Side::Front)
        );
    }

    #[test]
    fn leaves_tile_the_domain_and_adjacency_is_found() {
        // eight faces of each operand packed in one corner: the cell splits
        let boxes: Vec<IBox> = (0..8).map(|i| ([i, 0, 0], [i, 1, 1])).collect();
        let bx = |f: u32| boxes[f as usize];
        let leaves = build(
            ([0, 0, 0], [15, 15, 15]),
            (0..8).collect(),
            (0..8).collect(),
            &bx,
            &bx,
            4,
        );
        let volume: i64 = leaves
            .iter()
            .map(|l| (0..3).map(|k| l.bx.1[k] - l.bx.0[k] + 1).product::<i64>())
            .sum();
        assert_eq!(volume, 16 * 16 * 16);
        assert!(leaves.len() > 8);
        let adj = adjacent(&leaves);
        // every leaf touches another
        for i in 0..leaves.len() as u32 {
            assert!(adj.iter().any(|&(p, q)| p == i || q == i));
        }
    }
}
