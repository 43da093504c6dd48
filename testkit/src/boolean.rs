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
//!
//! A byte after the shear may make the case curved ([`Curved`]): the
//! first operand is then a UV sphere, and the second another sphere, a
//! copy of the first moved by a power of two (down to below the grid
//! step, and not at all), a half-size copy nested inside, or the boxes.
//! No set of cells is the answer then; the check runs all three
//! operations and asks, exactly, that each result be watertight, that
//! the volumes obey `V(A ∪ B) + V(A ∩ B) = V(A) + V(B)` and
//! `V(A − B) = V(A) − V(A ∩ B)` (the operands snapped to the same grid),
//! and that at every vertex of both operands and at pseudo-random grid
//! points, each result's winding number is the operation on the
//! operands' (all symbolically displaced alike, so points on a surface
//! are decided too). A last byte may join both operands into one mesh,
//! which crosses itself where they meet; resolved alone it must be their
//! union, and less the first, the second less the first: the same
//! windings at the same probes, the same exact volumes.

use bsp_core::BoolOp;
use bsp_core::GridPoint;
use bsp_csg::snap;
use bsp_csg::{CsgError, MeshBuf, MeshIn, mesh_sequence};
use glam::{DMat3, DVec3};
use num_bigint::BigInt;

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
    /// A curved case: spheres in place of the first operand's boxes
    /// (and of the second's, unless [`Partner::Boxes`]); `op` and the
    /// shear are then not used.
    pub curved: Option<Curved>,
}

/// A UV sphere: `4s(s − 1)` triangles for `stacks = s`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Ball {
    /// Stacks, `3..=8`.
    pub stacks: u8,
    /// The radius, `1..=4`.
    pub radius: u8,
    /// The centre in half units, each `0..=8`.
    pub centre: [u8; 3],
    /// A turn about `(1, 2, 3)` by `0.37·turn` radians.
    pub turn: u8,
}

/// The second operand of a curved case.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Partner {
    /// Another sphere.
    Ball(Ball),
    /// The first sphere moved by `2^−shift · (1, 1/2, 1/4)`, `shift` in
    /// `1..=47`, or not moved for `shift = 0`.
    Copy {
        /// The power of two.
        shift: u8,
    },
    /// The first sphere at half its size, about its centre.
    Nested,
    /// The decoded boxes of [`BooleanInput::b`].
    Boxes,
}

/// The spheres of a curved case (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Curved {
    /// The first operand.
    pub a: Ball,
    /// The second.
    pub b: Partner,
    /// Seeds the pseudo-random probes.
    pub probes: u8,
    /// Also both operands joined into one mesh, which crosses itself
    /// wherever they meet (a coarse sphere's faces across a fine one's,
    /// the boxes' large faces across a sphere): resolved alone, it must
    /// be their union, and less the first operand, the second less it.
    pub joined: bool,
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
    let each: Vec<(Vec<DVec3>, Vec<Vec<u32>>)> = boxes
        .iter()
        .map(|bx| {
            let corner = |c: [i32; 3]| DVec3::from_array(c.map(f64::from));
            let hi = [0, 1, 2].map(|k| bx.lo[k] + bx.size[k]);
            let (points, mut faces) = bsp_fixtures::indexed_box(corner(bx.lo), corner(hi));
            if bx.inward {
                faces.iter_mut().for_each(|f| f.reverse());
            }
            (
                points.into_iter().map(|p| sheared(shear, p)).collect(),
                faces,
            )
        })
        .collect();
    let parts: Vec<(&[DVec3], &[Vec<u32>])> = each
        .iter()
        .map(|(p, f)| (p.as_slice(), f.as_slice()))
        .collect();
    let (positions, faces) = bsp_fixtures::joined(&parts);
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
        let curved = (b.below(4) != 0).then(|| {
            let a = Ball::decode(&mut b);
            let partner = match b.below(4) {
                0 => Partner::Ball(Ball::decode(&mut b)),
                1 => Partner::Copy {
                    shift: b.below(48) as u8,
                },
                2 => Partner::Nested,
                _ => Partner::Boxes,
            };
            let probes = b.u8();
            Curved {
                a,
                b: partner,
                probes,
                joined: b.below(2) == 1,
            }
        });
        BooleanInput {
            op,
            a,
            b: bb,
            shear,
            curved,
        }
    }

    /// Runs the operation and checks it (see the module docs). Returns
    /// the number of unit cells inside the result, or `None` for an
    /// operand whose snapped volume is negative (refused as inward).
    pub fn check(&self) -> Option<usize> {
        if let Some(c) = self.curved {
            return self.check_curved(c);
        }
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
        let byte = |v: i32| [0, 1, -1, 2, -2].iter().position(|&x| x == v).unwrap_or(0) as u8;
        match self.curved {
            None if self.shear == [0; 3] => {}
            None => out.extend(self.shear.map(byte)),
            Some(c) => {
                out.extend(self.shear.map(byte));
                out.push(1);
                c.a.encode(&mut out);
                match c.b {
                    Partner::Ball(ball) => {
                        out.push(0);
                        ball.encode(&mut out);
                    }
                    Partner::Copy { shift } => out.extend([1, shift]),
                    Partner::Nested => out.push(2),
                    Partner::Boxes => out.push(3),
                }
                out.push(c.probes);
                if c.joined {
                    out.push(1);
                }
            }
        }
        out
    }

    /// The check of a curved case (see the module docs); returns the
    /// number of probes inside the union, or `None` if the boxes of
    /// [`Partner::Boxes`] are refused as inward.
    fn check_curved(&self, c: Curved) -> Option<usize> {
        let (pa, fa) = c.a.mesh();
        let (pb, fb) = match c.b {
            Partner::Ball(ball) => ball.mesh(),
            Partner::Copy { shift } => {
                let d = if shift == 0 {
                    DVec3::ZERO
                } else {
                    DVec3::new(1.0, 0.5, 0.25) * 2f64.powi(-i32::from(shift))
                };
                (pa.iter().map(|&p| p + d).collect(), fa.clone())
            }
            Partner::Nested => {
                let o = c.a.centre();
                (pa.iter().map(|&p| o + 0.5 * (p - o)).collect(), fa.clone())
            }
            Partner::Boxes => {
                let m = mesh(&self.b, [0; 3]);
                (m.positions, m.faces)
            }
        };
        let (va, vb) = (MeshIn::new(&pa, &fa), MeshIn::new(&pb, &fb));
        let snapped = match snap(&[va, vb]) {
            Ok(s) => s,
            Err(CsgError::Inward { .. }) => return None,
            Err(e) => fail(self, format_args!("snapping failed: {e}")),
        };
        let [sa, sb] = [0, 1].map(|i| &snapped.solids[i]);
        let grid = &snapped.grid;
        // probes: every vertex of both, and grid points in their box
        let mut probes: Vec<GridPoint> = pa
            .iter()
            .chain(&pb)
            .filter_map(|&p| grid.snap(p).ok())
            .collect();
        let (lo, hi) = pa.iter().chain(&pb).fold(
            (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        let mut state = u64::from(c.probes);
        let mut next = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..64 {
            let t = DVec3::new(next(), next(), next());
            if let Ok(g) = grid.snap(lo + t * (hi - lo)) {
                probes.push(g);
            }
        }
        let wa: Vec<bool> = probes.iter().map(|&q| sa.winding(q) > 0).collect();
        let wb: Vec<bool> = probes.iter().map(|&q| sb.winding(q) > 0).collect();
        let mut volumes = Vec::new();
        let mut inside = 0;
        for op in [BoolOp::Union, BoolOp::Intersection, BoolOp::Difference] {
            let out = match mesh_sequence(&va, &[(op, vb)]) {
                Ok(out) => out,
                Err(e) => fail(self, format_args!("{op:?} failed: {e}")),
            };
            if let Err(e) = out.mesh.check_watertight() {
                fail(self, format_args!("the {op:?} is not watertight: {e}"));
            }
            let want = |k: usize| match op {
                BoolOp::Union => wa[k] || wb[k],
                BoolOp::Intersection => wa[k] && wb[k],
                BoolOp::Difference => wa[k] && !wb[k],
            };
            self.check_windings(&out.solid, &probes, want, &format!("{op:?}"));
            if op == BoolOp::Union {
                inside += (0..probes.len()).filter(|&k| want(k)).count();
            }
            volumes.push(out.mesh.six_volume());
        }
        // six times the volumes as fractions with positive denominators,
        // compared by cross-multiplication (`Ratio` comparisons of such
        // long unreduced values recurse deeply)
        let [(na, da), (nb, db)] = [sa, sb].map(|s| s.to_mesh().six_volume());
        let [(nu, du), (ni, di), (nd, dd)] = [0, 1, 2].map(|k| volumes[k].clone());
        let union_and_meet = (&nu * &di + &ni * &du) * (&da * &db);
        let operands = (&na * &db + &nb * &da) * (&du * &di);
        if union_and_meet != operands {
            fail(self, format_args!("V(A ∪ B) + V(A ∩ B) ≠ V(A) + V(B)"));
        }
        if &nd * &da * &di != (&na * &di - &ni * &da) * &dd {
            fail(self, format_args!("V(A − B) ≠ V(A) − V(A ∩ B)"));
        }
        let outward = c.b != Partner::Boxes || self.b.iter().all(|bx| !bx.inward);
        if c.joined && outward {
            let operands = [
                (pa.as_slice(), fa.as_slice()),
                (pb.as_slice(), fb.as_slice()),
            ];
            self.check_joined(
                operands,
                grid,
                &probes,
                [&wa, &wb],
                [(&nu, &du), (&na, &da)],
            );
        }
        Some(inside)
    }

    /// Fails unless `solid`'s winding number at every probe `k` is 1
    /// where `want(k)` and 0 elsewhere; `what` names the result.
    fn check_windings(
        &self,
        solid: &bsp_csg::Solid,
        probes: &[GridPoint],
        want: impl Fn(usize) -> bool,
        what: &str,
    ) {
        for (k, &q) in probes.iter().enumerate() {
            let (got, want) = (solid.winding(q), i32::from(want(k)));
            if got != want {
                fail(
                    self,
                    format_args!("{what}: winding {got} at grid point {q:?}, want {want}"),
                );
            }
        }
    }

    /// The check of a case's operands joined into one mesh (see
    /// [`Curved::joined`]): resolved alone it is `A ∪ B`, less `A` it is
    /// `B − A`, at the probes and by exact volume (`union` and `a`: six
    /// times the volumes as numerators and denominators).
    fn check_joined(
        &self,
        [(pa, fa), (pb, fb)]: [(&[DVec3], &[Vec<u32>]); 2],
        grid: &bsp_core::Grid,
        probes: &[GridPoint],
        [wa, wb]: [&[bool]; 2],
        [(nu, du), (na, da)]: [(&BigInt, &BigInt); 2],
    ) {
        let va = MeshIn::new(pa, fa);
        let (pj, fj) = bsp_fixtures::joined(&[(pa, fa), (pb, fb)]);
        let vj = MeshIn::new(&pj, &fj);
        for less_a in [false, true] {
            let name = if less_a { "less A" } else { "resolved" };
            let ops = if less_a {
                vec![(BoolOp::Difference, va)]
            } else {
                vec![]
            };
            let out = match mesh_sequence(&vj, &ops) {
                Ok(out) => out,
                Err(e) => fail(self, format_args!("the joined operands {name} failed: {e}")),
            };
            if out.grid != *grid {
                fail(
                    self,
                    format_args!("the joined operands {name}: another grid"),
                );
            }
            if let Err(e) = out.mesh.check_watertight() {
                fail(
                    self,
                    format_args!("the joined operands {name}: not watertight: {e}"),
                );
            }
            let want = |k: usize| {
                if less_a {
                    wb[k] && !wa[k]
                } else {
                    wa[k] || wb[k]
                }
            };
            self.check_windings(
                &out.solid,
                probes,
                want,
                &format!("the joined operands {name}"),
            );
            // resolved: V(A ∪ B); less A: V(A ∪ B) − V(A)
            let (nj, dj) = out.mesh.six_volume();
            let ok = if less_a {
                &nj * du * da == (nu * da - na * du) * &dj
            } else {
                &nj * du == nu * &dj
            };
            if !ok {
                fail(
                    self,
                    format_args!("the joined operands {name}: wrong volume"),
                );
            }
        }
    }
}

impl Ball {
    fn decode(b: &mut Bytes<'_>) -> Ball {
        Ball {
            stacks: 3 + b.below(6) as u8,
            radius: 1 + b.below(4) as u8,
            centre: [(); 3].map(|()| b.below(9) as u8),
            turn: b.u8(),
        }
    }

    fn encode(&self, out: &mut Vec<u8>) {
        out.extend([self.stacks - 3, self.radius - 1]);
        out.extend(self.centre);
        out.push(self.turn);
    }

    fn centre(&self) -> DVec3 {
        DVec3::from_array(self.centre.map(|c| f64::from(c) / 2.0))
    }

    /// The sphere's positions and triangles.
    fn mesh(&self) -> (Vec<DVec3>, Vec<Vec<u32>>) {
        let s = usize::from(self.stacks);
        let (v, f) = bsp_fixtures::shapes::uv_sphere(4 * s * (s - 1));
        let turn = DMat3::from_axis_angle(
            DVec3::new(1.0, 2.0, 3.0).normalize(),
            0.37 * f64::from(self.turn),
        );
        let (r, o) = (f64::from(self.radius), self.centre());
        (v.iter().map(|&p| o + r * (turn * p)).collect(), f)
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
