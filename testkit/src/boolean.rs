//! Mesh Booleans (`bsp_csg::mesh_sequence`) of decoded unions of integer
//! boxes, checked exactly. Each operand is one to three boxes, which may
//! overlap, nest, touch, share faces or be turned inward, in one mesh: its
//! solid is where its winding number is positive. Every box corner is an
//! integer, so the exact answer is a set of unit cells: the result must
//! be watertight, its winding number at every unit cell's centre must be
//! the operation on the operands' (positive or not), and its exact volume
//! must be the number of cells inside. Both operands may be sheared by
//! one integer shear (`x += a·y + b·z`, `y += c·z`): it maps the integer
//! lattice onto itself and keeps volumes, so the answer is the same cells,
//! sheared, and the faces are no longer axis-aligned.

use bsp_core::BoolOp;
use bsp_csg::{CsgError, MeshBuf, MeshIn, mesh_sequence};
use glam::DVec3;

use crate::bytes::Bytes;
use crate::report::fail;

/// An integer box `[lo, lo + size]`, turned inward if `inward`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct IntBox {
    /// The lower corner.
    pub lo: [i32; 3],
    /// The side lengths, each at least 1.
    pub size: [i32; 3],
    /// Faces turned inward (the box counts −1 inside).
    pub inward: bool,
}

/// Two operands of boxes and an operation, decoded from bytes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BooleanInput {
    /// The operation: union, intersection or difference.
    pub op: BoolOp,
    /// The first operand's boxes, in one mesh.
    pub a: Vec<IntBox>,
    /// The second operand's boxes, in one mesh.
    pub b: Vec<IntBox>,
    /// The shear `[a, b, c]` of both operands: `x += a·y + b·z`,
    /// `y += c·z`; each in `-2..=2`.
    pub shear: [i32; 3],
}

/// A shear coefficient from a byte: 0, 1, −1, 2, −2 (so that missing
/// bytes, read as zeros, shear nothing).
fn shear_of(byte: usize) -> i32 {
    [0, 1, -1, 2, -2][byte % 5]
}

/// `[x, y, z]` sheared by `[a, b, c]`: `x += a·y + b·z`, `y += c·z`
/// (integer grid points, or for the cell centres `f64`).
pub(crate) fn shear<T>(s: [i32; 3], [x, y, z]: [T; 3]) -> [T; 3]
where
    T: Copy + From<i32> + std::ops::Add<Output = T> + std::ops::Mul<Output = T>,
{
    let [a, b, c] = s.map(T::from);
    [x + a * y + b * z, y + c * z, z]
}

/// `p` sheared by `s` (see [`BooleanInput::shear`]).
fn sheared(s: [i32; 3], p: DVec3) -> DVec3 {
    DVec3::from_array(shear(s, p.to_array()))
}

/// Cells `0..SPAN` along each axis hold every box.
const SPAN: i32 = 8;

fn decode_boxes(b: &mut Bytes<'_>) -> Vec<IntBox> {
    let n = 1 + b.below(3);
    (0..n)
        .map(|_| {
            let lo = [0; 3].map(|_| b.below(5) as i32);
            let size = lo.map(|l| 1 + b.below((SPAN - l).min(4) as usize) as i32);
            IntBox {
                lo,
                size,
                inward: b.below(8) == 0,
            }
        })
        .collect()
}

impl IntBox {
    /// `+1`, `−1` or 0: the box's part of the winding number at the
    /// centre of unit cell `c`.
    fn winding(&self, c: [i32; 3]) -> i32 {
        let inside = (0..3).all(|k| self.lo[k] <= c[k] && c[k] < self.lo[k] + self.size[k]);
        match (inside, self.inward) {
            (false, _) => 0,
            (true, false) => 1,
            (true, true) => -1,
        }
    }
}

/// The boxes as one mesh (eight corners and six quads each), sheared by
/// `shear`.
fn mesh(boxes: &[IntBox], shear: [i32; 3]) -> MeshBuf {
    let mut positions = Vec::new();
    let mut faces = Vec::new();
    for bx in boxes {
        let first = positions.len() as u32;
        for i in 0..8u32 {
            let c = |k: usize| f64::from(bx.lo[k] + if i >> k & 1 == 1 { bx.size[k] } else { 0 });
            positions.push(sheared(shear, DVec3::new(c(0), c(1), c(2))));
        }
        let quads: [[u32; 4]; 6] = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        for q in quads {
            let mut f: Vec<u32> = q.iter().map(|v| first + v).collect();
            if bx.inward {
                f.reverse();
            }
            faces.push(f);
        }
    }
    MeshBuf::new(positions, faces)
}

impl BooleanInput {
    /// Decodes an operation and two operands from bytes; never rejects.
    pub fn decode(data: &[u8]) -> BooleanInput {
        let mut b = Bytes { data };
        let op = [BoolOp::Union, BoolOp::Intersection, BoolOp::Difference][b.below(3)];
        let a = decode_boxes(&mut b);
        let bb = decode_boxes(&mut b);
        let shear = [(); 3].map(|()| shear_of(b.below(5)));
        BooleanInput {
            op,
            a,
            b: bb,
            shear,
        }
    }

    /// Runs the operation and checks it (see the module docs). Returns
    /// the number of unit cells inside the result, or `None` for an
    /// operand whose snapped volume is negative (refused as inward).
    pub fn check(&self) -> Option<usize> {
        let (ma, mb) = (mesh(&self.a, self.shear), mesh(&self.b, self.shear));
        let (va, vb) = (
            MeshIn::new(&ma.positions, &ma.faces),
            MeshIn::new(&mb.positions, &mb.faces),
        );
        let out = match mesh_sequence(&va, &[(self.op, vb)]) {
            Ok(out) => out,
            Err(CsgError::Inward { .. }) => return None,
            Err(e) => fail(self, format_args!("the operation failed: {e}")),
        };
        if let Err(e) = out.mesh.check_watertight() {
            fail(self, format_args!("the result is not watertight: {e}"));
        }
        // the cells of the boxes' box (the grid holds nothing far beyond)
        let all = self.a.iter().chain(&self.b);
        let lo = [0, 1, 2].map(|k| all.clone().map(|b| b.lo[k]).min().unwrap_or(0));
        let hi = [0, 1, 2].map(|k| all.clone().map(|b| b.lo[k] + b.size[k]).max().unwrap_or(0));
        let mut inside = 0;
        for x in lo[0]..hi[0] {
            for y in lo[1]..hi[1] {
                for z in lo[2]..hi[2] {
                    let c = [x, y, z];
                    let w = |boxes: &[IntBox]| boxes.iter().map(|b| b.winding(c)).sum::<i32>() > 0;
                    let (a, b) = (w(&self.a), w(&self.b));
                    let want = match self.op {
                        BoolOp::Union => a || b,
                        BoolOp::Intersection => a && b,
                        BoolOp::Difference => a && !b,
                    };
                    let centre = DVec3::new(f64::from(x), f64::from(y), f64::from(z)) + 0.5;
                    let centre = sheared(self.shear, centre);
                    let Ok(g) = out.grid.snap(centre) else {
                        fail(
                            self,
                            format_args!("the cell centre {centre} is not a grid point"),
                        );
                    };
                    let got = out.solid.winding(g);
                    if got != i32::from(want) {
                        fail(
                            self,
                            format_args!("winding {got} at {centre}, want {}", i32::from(want)),
                        );
                    }
                    inside += usize::from(want);
                }
            }
        }
        if out.volume() != inside as f64 {
            fail(
                self,
                format_args!("volume {} for {inside} unit cells", out.volume()),
            );
        }
        Some(inside)
    }

    /// Bytes that [`BooleanInput::decode`] reads back as `self` (for the
    /// seed corpus).
    pub fn encode(&self) -> Vec<u8> {
        let op = match self.op {
            BoolOp::Union => 0,
            BoolOp::Intersection => 1,
            BoolOp::Difference => 2,
        };
        let mut out = vec![op];
        for boxes in [&self.a, &self.b] {
            out.push((boxes.len() - 1) as u8);
            for bx in boxes.iter() {
                out.extend(bx.lo.map(|c| c as u8));
                out.extend(bx.size.map(|s| (s - 1) as u8));
                out.push(if bx.inward { 0 } else { 1 });
            }
        }
        if self.shear != [0; 3] {
            let byte = |v: i32| [0, 1, -1, 2, -2].iter().position(|&x| x == v).unwrap_or(0) as u8;
            out.extend(self.shear.map(byte));
        }
        out
    }
}

/// Decodes `data` as a [`BooleanInput`] and checks it (see
/// [`BooleanInput::check`]). Panics, with the input printed as a Rust
/// expression, if a check fails.
///
/// ```
/// bsp_testkit::mesh_boolean_case(b"any bytes at all");
/// bsp_testkit::mesh_boolean_case(&[]);
/// ```
pub fn mesh_boolean_case(data: &[u8]) {
    BooleanInput::decode(data).check();
}
