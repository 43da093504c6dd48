//! The merge driver: two decoded solids and a set operation.

use super::{BoxSolid, Bytes, decode_box, fail};
use bsp_core::{
    BoolOp, Cell, Membership, Overlay, Partition, Plane, Point, Polygon, check_closed_manifold,
};

/// A decoded merge case: two (sheared, subdivided, possibly triangulated)
/// boxes and an operation.
#[derive(Clone, PartialEq, Eq)]
pub struct MergeInput {
    /// The first operand.
    pub a: BoxSolid,
    /// The second operand.
    pub b: BoxSolid,
    /// 0 union, 1 intersection, 2 difference, 3 the overlay "+".
    pub op: u8,
}

impl std::fmt::Debug for MergeInput {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "MergeInput {{ a: {:?}, b: {:?}, op: {} }}",
            self.a, self.b, self.op
        )
    }
}

/// Decodes `data` as a [`MergeInput`] and checks it (see
/// [`MergeInput::check`]). Panics, with the input printed as a Rust
/// expression, if an invariant fails.
///
/// ```
/// bsp_testkit::merge_case(b"any bytes at all");
/// bsp_testkit::merge_case(&[]);
/// ```
pub fn merge_case(data: &[u8]) {
    MergeInput::decode(data).check();
}

fn solid(input: &MergeInput, bx: &BoxSolid, which: &str) -> Option<Partition<Cell>> {
    let faces = bx.world_faces()?;
    let polys: Option<Vec<Polygon>> = faces
        .iter()
        .map(|f| Polygon::from_grid_points(f, 0).ok())
        .collect();
    let p = Partition::solid(polys?);
    if let Err(e) = p.sanity_check() {
        fail(input, format_args!("operand {which}: {e}"));
    }
    Some(p)
}

fn cell(m: Membership) -> Option<Cell> {
    match m {
        Membership::Inside => Some(Cell::In),
        Membership::Outside => Some(Cell::Out),
        Membership::Boundary => None,
    }
}

impl MergeInput {
    /// Decodes two boxes and an operation from bytes; never rejects.
    pub fn decode(data: &[u8]) -> MergeInput {
        let mut b = Bytes { data };
        let op = b.u8() % 4;
        let a = decode_box(&mut b);
        let c = decode_box(&mut b);
        MergeInput { a, b: c, op }
    }

    /// Builds both solids, merges them, and checks exactly: the result's
    /// invariants (`sanity_check`); for every probe (both boxes' corners and
    /// probe points, and half-integer points between them, off every
    /// plane) that is not on an operand's boundary, the result's membership
    /// is the operation applied to the operands' (for "+": exactly one cell,
    /// labelled with both memberships); for ∪ ∩ −, a watertight 2-manifold
    /// mesh, and vol(A ∪ B) + vol(A ∩ B) = vol(A) + vol(B) exactly.
    pub fn check(&self) {
        let (Some(pa), Some(pb)) = (solid(self, &self.a, "a"), solid(self, &self.b, "b")) else {
            return; // a box left the grid: nothing to merge
        };
        let mut probes: Vec<Point> = Vec::new();
        for bx in [&self.a, &self.b] {
            for p in bx.world_corners().into_iter().flatten() {
                probes.push(Point::Grid(p));
            }
            for q in &bx.probes {
                if let Some(p) = bx.to_world(q.map(|c| c as i64)) {
                    probes.push(Point::Grid(p));
                }
            }
        }
        // half-integer points next to the grid probes avoid every plane of
        // axis-aligned boxes and most of sheared ones
        let half: Vec<Point> = probes
            .iter()
            .filter_map(|p| p.as_grid())
            .filter_map(|g| {
                let plane = |k: usize| {
                    let mut n = [0i64; 3];
                    n[k] = 2;
                    Plane::new(n, -(2 * g[k] as i128 + 1))
                };
                Point::from_planes(&plane(0)?, &plane(1)?, &plane(2)?)
            })
            .collect();
        probes.extend(half);
        if self.op == 3 {
            let o = bsp_core::internals::merge_smaller_into_larger(&pa, &pb, &Overlay);
            if let Err(e) = o.sanity_check() {
                fail(self, format_args!("overlay: {e}"));
            }
            for p in &probes {
                let (Some(x), Some(y)) = (cell(pa.classify_point(p)), cell(pb.classify_point(p)))
                else {
                    continue;
                };
                let cells = o.locate(p);
                if cells.iter().any(|&c| c != (x, y)) {
                    fail(
                        self,
                        format_args!("overlay: {p:?} has cells {cells:?}, expected ({x:?}, {y:?})"),
                    );
                }
            }
            return;
        }
        let ops = [BoolOp::Union, BoolOp::Intersection, BoolOp::Difference];
        let op = ops[self.op as usize];
        let r = pa.boolean(&pb, op);
        if let Err(e) = r.sanity_check() {
            fail(self, format_args!("{op:?}: {e}"));
        }
        for p in &probes {
            let (Some(x), Some(y)) = (cell(pa.classify_point(p)), cell(pb.classify_point(p)))
            else {
                continue;
            };
            let expected = bsp_core::CellOp::apply(&op, x, y);
            let got = r.classify_point(p);
            if cell(got) != Some(expected) {
                fail(
                    self,
                    format_args!("{op:?}: {p:?} is {got:?}, expected {expected:?}"),
                );
            }
        }
        let mesh = r.to_mesh();
        if let Err(e) = mesh.check_watertight() {
            fail(self, format_args!("{op:?}: mesh not watertight: {e}"));
        }
        if let Err(e) = check_closed_manifold(mesh.triangles.iter().map(|t| &t[..])) {
            fail(
                self,
                format_args!("{op:?}: mesh not a closed manifold: {e}"),
            );
        }
        let vol = |p: &Partition<Cell>| p.to_mesh().volume_exact();
        let (u, i) = (
            pa.boolean(&pb, BoolOp::Union),
            pa.boolean(&pb, BoolOp::Intersection),
        );
        if vol(&u) + vol(&i) != vol(&pa) + vol(&pb) {
            fail(
                self,
                format_args!("vol(A ∪ B) + vol(A ∩ B) != vol(A) + vol(B)"),
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn boxed(lo: [i32; 3], hi: [i32; 3]) -> BoxSolid {
        BoxSolid {
            lo,
            hi,
            splits: [0; 3],
            triangulate: 0,
            shears: [(0, 0, 0); 3],
            mirror: false,
            offset: [0; 3],
            probes: vec![],
            rational_probes: vec![],
        }
    }

    #[test]
    fn touching_and_overlapping_boxes() {
        for (lo, hi) in [
            ([2, 2, 2], [6, 6, 6]),
            ([4, 0, 0], [8, 4, 4]),
            ([4, 4, 0], [8, 8, 4]),
            ([4, 4, 4], [8, 8, 8]),
            ([0, 0, 0], [4, 4, 4]),
            ([1, 1, 1], [3, 3, 3]),
        ] {
            for op in 0..4 {
                MergeInput {
                    a: boxed([0, 0, 0], [4, 4, 4]),
                    b: boxed(lo, hi),
                    op,
                }
                .check();
            }
        }
    }

    #[test]
    fn merge_corpus_passes() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz/corpus/merge");
        let mut n = 0;
        for entry in std::fs::read_dir(&dir).expect("fuzz/corpus/merge exists") {
            let path = entry.expect("a corpus entry").path();
            merge_case(&std::fs::read(&path).expect("a readable seed"));
            n += 1;
        }
        assert!(n >= 10, "{n} seeds in {}", dir.display());
    }

    #[test]
    fn random_bytes_pass() {
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        for len in 0..64 {
            let bytes: Vec<u8> = (0..len * 3)
                .map(|_| {
                    s ^= s << 13;
                    s ^= s >> 7;
                    s ^= s << 17;
                    s as u8
                })
                .collect();
            merge_case(&bytes);
        }
    }
}
