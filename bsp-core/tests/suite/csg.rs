//! Set operations on solid partitions (`docs/csg.md`).
//!
//! Identities of ∪ ∩ −, the complement and the overlay "+" on random
//! solids (boxes, rotated boxes and parallelepipeds, tetrahedra, convex
//! hulls, height fields) and on real meshes, checked against ray-parity
//! membership (`crate::oracle::Solid`) and exact volumes; then adversarial
//! configurations — coplanar, glued, touching, nested, one step apart,
//! slivers, chains and iterated subtractions — each with its exact
//! expected volume, computed independently (by hand, by counting unit
//! voxels, or from the input faces).
//!
//! Sample points are grid points and half-grid points: a point with
//! doubled coordinates `d` is `Point::from_planes` of the axis planes
//! `2x = d_x`, `2y = d_y`, `2z = d_z`, and the oracle classifies `d` in the
//! solid scaled by two, so it never sees a non-integer point.

use std::path::Path;

use bsp_core::internals::{PLink, merge_smaller_into_larger};
use bsp_core::{
    BoolOp, Cell, Grid, GridPoint, MAX_COORD, Membership, Overlay, Partition, Plane, Point,
    Polygon, Side, TriMesh, check_closed_manifold, import_faces,
};
use glam::DVec3;
use proptest::collection::vec;
use proptest::prelude::*;

use crate::oracle::{Q, Solid, det3, grid_z, q};
use crate::strategies::{Rng, SolidCase, hull_2d, solid as big_solid};

/// The three Boolean operations.
const OPS: [BoolOp; 3] = [BoolOp::Union, BoolOp::Intersection, BoolOp::Difference];

/// A closed solid as face loops on the grid: convex, planar,
/// counter-clockwise seen from outside.
#[derive(Clone, PartialEq)]
struct Shape {
    faces: Vec<Vec<GridPoint>>,
}

/// Rust constructor syntax, so that a failing case pastes straight into a
/// regression test.
impl std::fmt::Debug for Shape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Shape {{ faces: vec![")?;
        for (i, face) in self.faces.iter().enumerate() {
            let sep = if i == 0 { "" } else { ", " };
            write!(f, "{sep}vec!{face:?}")?;
        }
        write!(f, "] }}")
    }
}

impl Shape {
    fn translated(&self, t: [i64; 3]) -> Option<Shape> {
        let faces = self
            .faces
            .iter()
            .map(|f| {
                f.iter()
                    .map(|p| {
                        let v = [0, 1, 2].map(|k| p[k] as i64 + t[k]);
                        v.iter()
                            .all(|c| c.unsigned_abs() <= MAX_COORD as u64)
                            .then(|| v.map(|c| c as i32))
                    })
                    .collect::<Option<Vec<_>>>()
            })
            .collect::<Option<Vec<_>>>()?;
        Some(Shape { faces })
    }

    fn vertices(&self) -> impl Iterator<Item = GridPoint> + '_ {
        self.faces.iter().flatten().copied()
    }

    /// Lowest and highest corner of the bounding box.
    fn bounds(&self) -> (GridPoint, GridPoint) {
        let lo = [0, 1, 2].map(|k| self.vertices().map(|p| p[k]).min().expect("faces"));
        let hi = [0, 1, 2].map(|k| self.vertices().map(|p| p[k]).max().expect("faces"));
        (lo, hi)
    }

    /// The exact volume from the faces (fan triangles of each loop against
    /// the origin), independent of the kernel.
    fn volume(&self) -> Q {
        let mut six = num_bigint::BigInt::from(0);
        for f in &self.faces {
            for i in 1..f.len() - 1 {
                six += det3(&grid_z(f[0]), &grid_z(f[i]), &grid_z(f[i + 1]));
            }
        }
        Q::new(six, 6.into())
    }

    /// The faces scaled by `unit`, for the ray-parity oracle.
    fn oracle(&self, unit: i32) -> Solid {
        let scaled: Vec<Vec<GridPoint>> = self
            .faces
            .iter()
            .map(|f| f.iter().map(|p| p.map(|c| c * unit)).collect())
            .collect();
        Solid::new(&scaled)
    }

    fn polygons(&self) -> Vec<Polygon> {
        self.faces
            .iter()
            .enumerate()
            .map(|(i, f)| {
                Polygon::from_grid_points(f, i as u32)
                    .unwrap_or_else(|e| panic!("face {i} {f:?}: {e}"))
            })
            .collect()
    }

    fn partition(&self) -> Partition<Cell> {
        let p = Partition::solid(self.polygons());
        p.sanity_check()
            .unwrap_or_else(|e| panic!("input partition: {e}"));
        p
    }
}

/// An axis-aligned box, faces counter-clockwise seen from outside.
fn cuboid(lo: GridPoint, hi: GridPoint) -> Shape {
    assert!((0..3).all(|k| lo[k] < hi[k]), "{lo:?} {hi:?}");
    Shape {
        faces: bsp_fixtures::grid_cuboid(lo, hi),
    }
}

/// The exact convex hull of grid points (brute force over triples, for a
/// handful of points): one strictly convex loop per facet, counter-clockwise
/// seen from outside. `None` if the points are coplanar.
fn hull(points: &[GridPoint]) -> Option<Shape> {
    let mut pts = points.to_vec();
    pts.sort_unstable();
    pts.dedup();
    let mut planes: Vec<Plane> = Vec::new();
    for i in 0..pts.len() {
        for j in i + 1..pts.len() {
            for k in j + 1..pts.len() {
                let Ok(pl) = Plane::through(pts[i], pts[j], pts[k]) else {
                    continue;
                };
                let sides: Vec<Side> = pts.iter().map(|p| pl.classify_grid(*p)).collect();
                let outward = match (sides.contains(&Side::Front), sides.contains(&Side::Back)) {
                    (false, true) => pl,
                    (true, false) => pl.flip(),
                    _ => continue, // spanning, or every point on it
                };
                if !planes.contains(&outward) {
                    planes.push(outward);
                }
            }
        }
    }
    if planes.len() < 4 {
        return None;
    }
    let faces = planes
        .iter()
        .map(|pl| {
            let k = pl.dominant_axis();
            let (a, b) = ((k + 1) % 3, (k + 2) % 3);
            let on: Vec<GridPoint> = pts
                .iter()
                .copied()
                .filter(|p| pl.classify_grid(*p) == Side::On)
                .collect();
            let flat = hull_2d(on.iter().map(|p| [p[a] as i64, p[b] as i64]).collect());
            // the projection along the dominant axis is one-to-one on the plane
            let mut face: Vec<GridPoint> = flat
                .iter()
                .map(|f| {
                    *on.iter()
                        .find(|p| [p[a] as i64, p[b] as i64] == *f)
                        .expect("hull points are input points")
                })
                .collect();
            // counter-clockwise in (a, b) is counter-clockwise about +e_k
            if pl.normal()[k] < 0 {
                face.reverse();
            }
            face
        })
        .collect();
    let s = Shape { faces };
    for (f, pl) in s.faces.iter().zip(&planes) {
        let poly = Polygon::from_grid_points(f, 0).expect("a hull facet is convex");
        assert_eq!(poly.support(), pl, "hull facet {f:?} is misoriented");
    }
    Some(s)
}

/// The grid or half-grid point with doubled coordinates `d`.
fn half_point(d: GridPoint) -> Point {
    if d.iter().all(|c| c % 2 == 0) {
        return Point::Grid(d.map(|c| c / 2));
    }
    let axis = |k: usize| {
        let mut n = [0; 3];
        n[k] = 2;
        Plane::new(n, -(d[k] as i128)).expect("axis plane")
    };
    Point::from_planes(&axis(0), &axis(1), &axis(2)).expect("axis planes meet")
}

/// A sample point: the kernel's point and its coordinates in the oracle's
/// scaled frame.
struct Sample {
    point: Point,
    scaled: GridPoint,
}

fn sample(scaled: GridPoint, unit: i32) -> Sample {
    let point = match unit {
        1 => Point::Grid(scaled),
        2 => half_point(scaled),
        _ => unreachable!("units are 1 and 2"),
    };
    Sample { point, scaled }
}

/// One operand: its shape, partition, oracle and exact volume.
struct Operand {
    shape: Shape,
    part: Partition<Cell>,
    oracle: Solid,
    volume: Q,
}

impl Operand {
    fn new(shape: Shape, unit: i32) -> Operand {
        Operand::with_partition(shape.partition(), shape, unit)
    }

    fn with_partition(part: Partition<Cell>, shape: Shape, unit: i32) -> Operand {
        let volume = shape.volume();
        assert!(volume > q(0), "the shape is oriented outward");
        let oracle = shape.oracle(unit);
        let mesh = checked_mesh("input", &part);
        assert_q(&mesh.volume_exact(), &volume, "input partition volume");
        Operand {
            shape,
            part,
            oracle,
            volume,
        }
    }
}

/// Sanity check, watertight mesh, closed 2-manifold; the mesh is empty
/// exactly when the partition is a single cell.
fn checked_mesh(what: &str, p: &Partition<Cell>) -> TriMesh {
    p.sanity_check()
        .unwrap_or_else(|e| panic!("{what}: sanity_check: {e}"));
    let m = p.to_mesh();
    m.check_watertight()
        .unwrap_or_else(|e| panic!("{what}: not watertight: {e}"));
    check_closed_manifold(m.triangles.iter().map(|t| &t[..]))
        .unwrap_or_else(|e| panic!("{what}: not a closed manifold: {e}"));
    assert_eq!(
        m.triangles.is_empty(),
        matches!(p.root(), PLink::Leaf(_)),
        "{what}: an empty boundary means a single cell"
    );
    m
}

/// `a + b` without reducing (`Ratio`'s `+` reduces by a gcd of long
/// integers).
fn add(a: &Q, b: &Q) -> Q {
    Q::new_raw(
        a.numer() * b.denom() + b.numer() * a.denom(),
        a.denom() * b.denom(),
    )
}

/// The sign of a fraction whose denominator may be negative.
fn sign(a: &Q) -> i32 {
    let s = |x: &num_bigint::BigInt| match x.sign() {
        num_bigint::Sign::Minus => -1,
        num_bigint::Sign::NoSign => 0,
        num_bigint::Sign::Plus => 1,
    };
    s(a.numer()) * s(a.denom())
}

/// Exact equality by cross-multiplication. (`Ratio`'s `==` compares
/// continued-fraction expansions, one recursion level and one long
/// division per term: on the unreduced volumes of real meshes that
/// overflows a test thread's stack.)
fn assert_q(got: &Q, want: &Q, what: &str) {
    assert!(
        got.numer() * want.denom() == want.numer() * got.denom(),
        "{what}: about {} instead of {}",
        approx(got),
        approx(want)
    );
}

/// A fraction as `f64`, for messages.
fn approx(x: &Q) -> f64 {
    num_traits::ToPrimitive::to_f64(x).unwrap_or(f64::NAN)
}

fn volume(what: &str, p: &Partition<Cell>) -> Q {
    checked_mesh(what, p).volume_exact()
}

/// Checks an unbounded result (a complement, or built from one) like any
/// other; its exact volume is `want` (negative) when `full`.
fn check_unbounded(what: &str, p: &Partition<Cell>, want: &Q, full: bool) {
    let m = checked_mesh(what, p);
    if full {
        assert_q(&m.volume_exact(), want, what);
    }
}

fn inside(m: Membership) -> Option<bool> {
    match m {
        Membership::Inside => Some(true),
        Membership::Outside => Some(false),
        Membership::Boundary => None,
    }
}

fn cell(m: Membership) -> Cell {
    match m {
        Membership::Inside => Cell::In,
        Membership::Outside => Cell::Out,
        Membership::Boundary => panic!("a point on the boundary has no single cell"),
    }
}

fn apply(op: BoolOp, a: bool, b: bool) -> bool {
    match op {
        BoolOp::Union => a || b,
        BoolOp::Intersection => a && b,
        BoolOp::Difference => a && !b,
    }
}

/// Every sample classified the same by two partitions of one set.
fn same_membership(what: &str, x: &Partition<Cell>, y: &Partition<Cell>, samples: &[Sample]) {
    for s in samples {
        assert_eq!(
            x.classify_point(&s.point),
            y.classify_point(&s.point),
            "{what} at {:?} (scaled)",
            s.scaled
        );
    }
}

/// What `check_pair` looked at, for tests that want to know the samples
/// were not all degenerate.
#[derive(Debug, Default)]
struct Seen {
    /// Samples strictly inside or outside both operands.
    generic: usize,
    /// Samples on either boundary.
    boundary: usize,
    /// Samples off every plane, checked against the overlay.
    overlay: usize,
}

/// How much of [`check_pair`] to run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Depth {
    /// Everything.
    Full,
    /// For real meshes, whose exact volumes have millions of bits: the
    /// volumes of `A ∪ B`, `A ∩ B` and `A − B` only (every other result
    /// is still checked for membership and a watertight manifold mesh),
    /// and one of the two De Morgan laws.
    Mesh,
}

/// All the identities of the brief on one pair of operands.
fn check_pair(a: &Operand, b: &Operand, samples: &[Sample], depth: Depth) -> Seen {
    let full = depth == Depth::Full;
    let mut seen = Seen::default();
    let memb = sample_memberships(a, b, samples);
    let results = check_operations(a, b, samples, &memb);
    for &(ma, mb) in &memb {
        if ma == Membership::Boundary || mb == Membership::Boundary {
            seen.boundary += 1;
        } else {
            seen.generic += 1;
        }
    }
    let [(u, vu), (i, vi), (d, vd)] =
        <[_; 3]>::try_from(results).unwrap_or_else(|_| unreachable!());

    // exact volumes: inclusion-exclusion, and A − B = A − (A ∩ B)
    assert_q(
        &add(&vu, &vi),
        &add(&a.volume, &b.volume),
        "vol(A∪B) + vol(A∩B)",
    );
    assert_q(&add(&vd, &vi), &a.volume, "vol(A−B) + vol(A∩B)");
    assert!(sign(&vi) >= 0 && sign(&vd) >= 0);

    check_commutes(a, b, samples, full, [(&u, &vu), (&i, &vi)]);
    check_same_twice(a, samples, full);
    check_complements(a, b, samples, full, [(&u, &vu), (&i, &vi), (&d, &vd)]);
    seen.overlay += check_overlay(a, b, samples, &memb);
    seen
}

/// The exact volume of a result when `full`, else `want` after checking
/// the result's mesh.
fn volume_or(full: bool, what: &str, p: &Partition<Cell>, want: &Q) -> Q {
    if full {
        volume(what, p)
    } else {
        checked_mesh(what, p);
        want.clone()
    }
}

/// The oracle's membership of each sample in A and B, which the input
/// partitions must reproduce.
fn sample_memberships(
    a: &Operand,
    b: &Operand,
    samples: &[Sample],
) -> Vec<(Membership, Membership)> {
    samples
        .iter()
        .map(|s| {
            let (ma, mb) = (a.oracle.classify(s.scaled), b.oracle.classify(s.scaled));
            assert_eq!(a.part.classify_point(&s.point), ma, "A at {:?}", s.scaled);
            assert_eq!(b.part.classify_point(&s.point), mb, "B at {:?}", s.scaled);
            (ma, mb)
        })
        .collect()
}

/// `A ∪ B`, `A ∩ B` and `A − B` with their exact volumes, each checked
/// at the samples (memberships `memb`): inside(A op B) = op(inside A,
/// inside B) off both boundaries, and a result point is on the boundary
/// only where an input point is.
fn check_operations(
    a: &Operand,
    b: &Operand,
    samples: &[Sample],
    memb: &[(Membership, Membership)],
) -> Vec<(Partition<Cell>, Q)> {
    let mut results = Vec::new();
    for op in OPS {
        let r = a.part.boolean(&b.part, op);
        let v = volume(&format!("{op:?}"), &r);
        for (s, &(ma, mb)) in samples.iter().zip(memb) {
            let got = r.classify_point(&s.point);
            if let (Some(x), Some(y)) = (inside(ma), inside(mb)) {
                let want = if apply(op, x, y) {
                    Membership::Inside
                } else {
                    Membership::Outside
                };
                assert_eq!(got, want, "{op:?} at {:?} (scaled)", s.scaled);
            }
            if got == Membership::Boundary {
                assert!(
                    ma == Membership::Boundary || mb == Membership::Boundary,
                    "{op:?}: boundary at {:?} (scaled) off both inputs' boundaries",
                    s.scaled
                );
            }
        }
        results.push((r, v));
    }
    results
}

/// Commutativity: `B ∪ A` and `B ∩ A` against `A ∪ B` and `A ∩ B`
/// (`results`, with their volumes).
fn check_commutes(
    a: &Operand,
    b: &Operand,
    samples: &[Sample],
    full: bool,
    [(u, vu), (i, vi)]: [(&Partition<Cell>, &Q); 2],
) {
    for (op, r, v) in [(BoolOp::Union, u, vu), (BoolOp::Intersection, i, vi)] {
        let c = b.part.boolean(&a.part, op);
        assert_q(
            &volume_or(full, &format!("B {op:?} A"), &c, v),
            v,
            &format!("{op:?} commutes"),
        );
        same_membership(&format!("{op:?} commutes"), r, &c, samples);
    }
}

/// The same solid twice: `A − A` is a single Out cell, `A ∪ A` and
/// `A ∩ A` are `A`.
fn check_same_twice(a: &Operand, samples: &[Sample], full: bool) {
    let empty = a.part.boolean(&a.part, BoolOp::Difference);
    assert!(
        matches!(empty.root(), PLink::Leaf(Cell::Out)),
        "A − A is a single Out cell"
    );
    assert!(checked_mesh("A − A", &empty).triangles.is_empty());
    for op in [BoolOp::Union, BoolOp::Intersection] {
        let r = a.part.boolean(&a.part, op);
        assert_q(
            &volume_or(full, &format!("A {op:?} A"), &r, &a.volume),
            &a.volume,
            &format!("A {op:?} A"),
        );
        same_membership(&format!("A {op:?} A = A"), &r, &a.part, samples);
    }
}

/// De Morgan through the complement, and `A − B = A ∩ ¬B`, against
/// `A ∪ B`, `A ∩ B` and `A − B` (`results`, with their volumes).
fn check_complements(
    a: &Operand,
    b: &Operand,
    samples: &[Sample],
    full: bool,
    [(u, vu), (i, vi), (d, vd)]: [(&Partition<Cell>, &Q); 3],
) {
    let (na, nb) = (a.part.complement(), b.part.complement());
    check_unbounded("¬A", &na, &-a.volume.clone(), full);
    let nu = u.complement();
    let na_nb = na.boolean(&nb, BoolOp::Intersection);
    same_membership("¬(A∪B) = ¬A∩¬B", &nu, &na_nb, samples);
    check_unbounded("¬A∩¬B", &na_nb, &-vu.clone(), full);
    if full {
        let ni = i.complement();
        let na_or_nb = na.boolean(&nb, BoolOp::Union);
        same_membership("¬(A∩B) = ¬A∪¬B", &ni, &na_or_nb, samples);
        check_unbounded("¬A∪¬B", &na_or_nb, &-vi.clone(), full);
    }
    let a_nb = a.part.boolean(&nb, BoolOp::Intersection);
    same_membership("A−B = A∩¬B", d, &a_nb, samples);
    assert_q(&volume_or(full, "A∩¬B", &a_nb, vd), vd, "vol(A∩¬B)");
}

/// The overlay: a sample (memberships `memb`) off every plane of either
/// partition lies in exactly one cell, labelled with its membership in A
/// and in B. Returns how many samples were off every plane.
fn check_overlay(
    a: &Operand,
    b: &Operand,
    samples: &[Sample],
    memb: &[(Membership, Membership)],
) -> usize {
    let o = merge_smaller_into_larger(&a.part, &b.part, &Overlay);
    o.sanity_check()
        .unwrap_or_else(|e| panic!("overlay: sanity_check: {e}"));
    let planes: Vec<Plane> = a
        .part
        .nodes()
        .iter()
        .chain(b.part.nodes())
        .map(|n| n.plane)
        .collect();
    let mut checked = 0;
    for (s, &(ma, mb)) in samples.iter().zip(memb) {
        if planes.iter().any(|p| s.point.classify(p) == Side::On) {
            continue;
        }
        let cells = o.locate(&s.point);
        assert_eq!(
            cells,
            vec![(cell(ma), cell(mb))],
            "overlay at {:?} (scaled)",
            s.scaled
        );
        checked += 1;
    }
    checked
}

/// Samples for a pair of shapes, in the oracle's frame scaled by `unit`:
/// random points of the joint bounding box (enlarged by two steps), every
/// vertex and edge midpoint (where it is on the scaled grid) of one face
/// in `every`, and the axis neighbours of some vertices.
fn samples_for(
    (a, b): (&Shape, &Shape),
    extra: &[GridPoint],
    unit: i32,
    (n, every): (usize, usize),
    seed: u64,
) -> Vec<Sample> {
    let mut rng = Rng(seed);
    let scale = |p: GridPoint| p.map(|c| c * unit);
    let (la, ha) = a.bounds();
    let (lb, hb) = b.bounds();
    let m = MAX_COORD as i64;
    let lo = [0, 1, 2].map(|k| ((la[k].min(lb[k]) as i64 - 2) * unit as i64).max(-m));
    let hi = [0, 1, 2].map(|k| ((ha[k].max(hb[k]) as i64 + 2) * unit as i64).min(m));
    let mut pts: Vec<GridPoint> = Vec::new();
    for _ in 0..n {
        pts.push(
            [0, 1, 2].map(|k| (lo[k] + (rng.next() % (hi[k] - lo[k] + 1) as u64) as i64) as i32),
        );
    }
    for s in [a, b] {
        for f in &s.faces {
            if rng.below(every) != 0 {
                continue;
            }
            for (i, &p) in f.iter().enumerate() {
                pts.push(scale(p));
                let r = f[(i + 1) % f.len()];
                let mid = [0, 1, 2].map(|k| (p[k] as i64 + r[k] as i64) * unit as i64);
                if mid.iter().all(|c| c % 2 == 0) {
                    pts.push(mid.map(|c| (c / 2) as i32));
                }
                if rng.below(4) == 0 {
                    let mut q = scale(p);
                    q[rng.below(3)] += if rng.below(2) == 0 { 1 } else { -1 };
                    pts.push(q);
                }
            }
        }
    }
    pts.extend(extra.iter().map(|p| scale(*p)));
    pts.retain(|p| p.iter().all(|c| c.abs() <= MAX_COORD));
    pts.sort_unstable();
    pts.dedup();
    pts.into_iter().map(|p| sample(p, unit)).collect()
}

// ---------------------------------------------------------------------
// Random solids
// ---------------------------------------------------------------------

/// Coordinates of the small solids: within ±`R` before shapes are
/// translated, so that two random solids often meet.
const R: i32 = 10;

fn small_point() -> BoxedStrategy<GridPoint> {
    [-R..=R, -R..=R, -R..=R].boxed()
}

fn small_box() -> BoxedStrategy<Shape> {
    (small_point(), [1..=8, 1..=8, 1..=8])
        .prop_map(|(lo, s)| cuboid(lo, [lo[0] + s[0], lo[1] + s[1], lo[2] + s[2]]))
        .boxed()
}

fn permute(v: [i64; 3], axis: usize) -> [i64; 3] {
    [v[axis % 3], v[(axis + 1) % 3], v[(axis + 2) % 3]]
}

/// Parallelepipeds `o + i u + j v + k w`: general integer frames, boxes
/// rotated about a coordinate axis by an integer rotation-like shear
/// (`u = s (a, b, 0)`, `v = t (−b, a, 0)`), and rectangular boxes in a
/// rotated orthogonal integer frame `u, u × r, u × (u × r)`.
fn small_parallelepiped() -> BoxedStrategy<Shape> {
    let c = || -3i64..=3;
    let general = [[c(), c(), c()], [c(), c(), c()], [c(), c(), c()]].boxed();
    let about_axis = (c(), c(), 1i64..=2, 1i64..=2, 1i64..=5, 0usize..3)
        .prop_map(|(a, b, s, t, h, axis)| {
            [[s * a, s * b, 0], [-t * b, t * a, 0], [0, 0, h]].map(|v| permute(v, axis))
        })
        .boxed();
    let frame = (
        [-2i64..=2, -2i64..=2, -2i64..=2],
        [-2i64..=2, -2i64..=2, -2i64..=2],
    )
        .prop_map(|(u, r)| {
            let cr = |a: [i64; 3], b: [i64; 3]| {
                [
                    a[1] * b[2] - a[2] * b[1],
                    a[2] * b[0] - a[0] * b[2],
                    a[0] * b[1] - a[1] * b[0],
                ]
            };
            let v = cr(u, r);
            [u, v, cr(u, v)]
        })
        .boxed();
    (
        small_point(),
        prop_oneof![2 => general, 2 => about_axis, 1 => frame],
    )
        .prop_filter_map("degenerate frame", |(o, [u, v, w])| {
            let mut corners = Vec::new();
            for i in 0..2 {
                for j in 0..2 {
                    for k in 0..2 {
                        let p = [0, 1, 2].map(|x| o[x] as i64 + i * u[x] + j * v[x] + k * w[x]);
                        corners.push(p.map(|c| c as i32));
                    }
                }
            }
            let s = hull(&corners)?;
            let det = det3(&u.map(Into::into), &v.map(Into::into), &w.map(Into::into));
            assert_eq!(s.volume(), Q::from_integer(num_traits::Signed::abs(&det)));
            Some(s)
        })
        .boxed()
}

fn small_tetrahedron() -> BoxedStrategy<Shape> {
    [small_point(), small_point(), small_point(), small_point()]
        .prop_filter_map("coplanar", |p| {
            let s = hull(&p)?;
            assert_eq!(s.faces.len(), 4);
            Some(s)
        })
        .boxed()
}

fn small_hull() -> BoxedStrategy<Shape> {
    vec(small_point(), 5..9)
        .prop_filter_map("coplanar", |p| hull(&p))
        .boxed()
}

fn small_shape() -> BoxedStrategy<Shape> {
    prop_oneof![
        small_box(),
        small_parallelepiped(),
        small_tetrahedron(),
        small_hull()
    ]
    .boxed()
}

/// How the second operand relates to the first.
#[derive(Clone, Debug)]
enum Second {
    /// Another random solid.
    Other(Shape),
    /// The first moved by a few grid steps (zero included).
    Steps([i64; 3]),
    /// The first moved by a fraction (in quarters) of its size.
    Quarters([i64; 3]),
    /// The hull of the first's vertices with one of them moved by a grid
    /// step: slivers and nearly coincident planes.
    Nudged(usize, [i64; 3]),
}

fn second() -> BoxedStrategy<Second> {
    let s = || -2i64..=2;
    let f = || -4i64..=4;
    prop_oneof![
        3 => small_shape().prop_map(Second::Other),
        1 => small_box().prop_map(Second::Other),
        2 => [s(), s(), s()].prop_map(Second::Steps),
        1 => Just(Second::Steps([0, 0, 0])),
        2 => [f(), f(), f()].prop_map(Second::Quarters),
        2 => (any::<usize>(), [-1i64..=1, -1i64..=1, -1i64..=1])
            .prop_map(|(i, d)| Second::Nudged(i, d)),
    ]
    .boxed()
}

fn resolve(a: &Shape, second: &Second) -> Option<Shape> {
    match second {
        Second::Other(s) => Some(s.clone()),
        Second::Steps(t) => a.translated(*t),
        Second::Quarters(f) => {
            let (lo, hi) = a.bounds();
            let t = [0, 1, 2].map(|k| (hi[k] as i64 - lo[k] as i64) * f[k] / 4);
            a.translated(t)
        }
        Second::Nudged(i, d) => {
            let mut v: Vec<GridPoint> = a.vertices().collect();
            v.sort_unstable();
            v.dedup();
            let n = v.len();
            let p = &mut v[i % n];
            *p = [0, 1, 2].map(|k| p[k] + d[k] as i32);
            hull(&v)
        }
    }
}

/// How far the copy of a large solid is moved.
#[derive(Clone, Copy, Debug)]
enum Shift {
    /// By a few grid steps.
    Steps([i64; 3]),
    /// By a fraction of the solid's size, in eighths.
    Eighths([i64; 3]),
}

impl Shift {
    /// The translation for a solid with bounding box `lo..hi`, clamped so
    /// that the copy stays in the grid.
    fn resolve(self, (lo, hi): (GridPoint, GridPoint)) -> [i64; 3] {
        [0, 1, 2].map(|k| {
            let t = match self {
                Shift::Steps(t) => t[k],
                Shift::Eighths(f) => (hi[k] as i64 - lo[k] as i64) * f[k] / 8,
            };
            let m = MAX_COORD as i64;
            t.clamp(-m - lo[k] as i64, m - hi[k] as i64)
        })
    }
}

/// Large solids from the shared strategies (coordinates up to the grid
/// limits) and how to move their copy.
fn big_pair() -> BoxedStrategy<(SolidCase, Shift)> {
    let shift = prop_oneof![
        [-3i64..=3, -3i64..=3, -3i64..=3].prop_map(Shift::Steps),
        [-8i64..=8, -8i64..=8, -8i64..=8].prop_map(Shift::Eighths),
    ];
    (big_solid(), shift).boxed()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    /// Every identity of the brief on two small random solids, sampled at
    /// grid and half-grid points.
    #[test]
    fn identities_on_small_solids(a in small_shape(), second in second(), seed in any::<u64>()) {
        let Some(b) = resolve(&a, &second) else {
            return Err(TestCaseError::reject("does not fit"));
        };
        let samples = samples_for((&a, &b), &[], 2, (120, 1), seed);
        let (a, b) = (Operand::new(a, 2), Operand::new(b, 2));
        let seen = check_pair(&a, &b, &samples, Depth::Full);
        prop_assert!(seen.generic > 0 && seen.boundary > 0, "{seen:?}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(192))]

    /// The identities on large solids (parallelepipeds, tetrahedra and
    /// height fields up to the grid limits) and a translated copy, sampled
    /// at grid points.
    #[test]
    fn identities_on_large_solids((a, shift) in big_pair(), seed in any::<u64>()) {
        let shape = Shape { faces: a.faces.clone() };
        let t = shift.resolve(shape.bounds());
        let b = shape.translated(t).expect("clamped into the grid");
        let moved = Shape { faces: vec![a.special.clone()] }.translated(t).expect("in the grid");
        let special: Vec<GridPoint> = a.special.iter().chain(&moved.faces[0]).copied().collect();
        let samples = samples_for((&shape, &b), &special, 1, (60, 1), seed);
        let (a, b) = (Operand::new(shape, 1), Operand::new(b, 1));
        let seen = check_pair(&a, &b, &samples, Depth::Full);
        prop_assert!(seen.boundary > 0, "{seen:?}");
    }
}

// ---------------------------------------------------------------------
// Real meshes
// ---------------------------------------------------------------------

const MESHES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../data/meshes/");

fn mesh_loops(name: &str) -> Vec<Vec<DVec3>> {
    let path = format!("{MESHES}{name}.obj");
    shadow_scene::read_obj(Path::new(&path))
        .unwrap_or_else(|e| panic!("{path}: {e:?}"))
        .face_loops()
}

/// The faces of an axis-aligned box in input units.
fn box_loops(lo: DVec3, hi: DVec3) -> Vec<Vec<DVec3>> {
    let g = cuboid([0; 3], [1; 3]);
    g.faces
        .iter()
        .map(|f| {
            f.iter()
                .map(|p| {
                    DVec3::new(
                        if p[0] == 0 { lo.x } else { hi.x },
                        if p[1] == 0 { lo.y } else { hi.y },
                        if p[2] == 0 { lo.z } else { hi.z },
                    )
                })
                .collect()
        })
        .collect()
}

/// Snaps both operands with one grid fitted over both, imports them, and
/// builds their partitions.
fn mesh_operands(a: &[Vec<DVec3>], b: &[Vec<DVec3>]) -> (Operand, Operand) {
    let grid = Grid::fit_points(a.iter().chain(b).flatten()).expect("finite meshes");
    let operand = |loops: &[Vec<DVec3>]| {
        let (polys, report) =
            import_faces(&grid, loops.iter().map(|l| &l[..])).expect("the grid holds both");
        assert!(report.dropped.is_empty(), "{}", report.summary());
        let faces = loops
            .iter()
            .map(|l| {
                l.iter()
                    .map(|p| grid.snap(*p).expect("on the grid"))
                    .collect()
            })
            .collect();
        let part = Partition::solid(polys);
        part.sanity_check()
            .unwrap_or_else(|e| panic!("input partition: {e}"));
        Operand::with_partition(part, Shape { faces }, 1)
    };
    (operand(a), operand(b))
}

fn translate(loops: &[Vec<DVec3>], t: DVec3) -> Vec<Vec<DVec3>> {
    loops
        .iter()
        .map(|l| l.iter().map(|p| *p + t).collect())
        .collect()
}

fn bounds(loops: &[Vec<DVec3>]) -> (DVec3, DVec3) {
    let pts = loops.iter().flatten();
    let lo = pts.clone().fold(DVec3::INFINITY, |a, p| a.min(*p));
    let hi = pts.fold(DVec3::NEG_INFINITY, |a, p| a.max(*p));
    (lo, hi)
}

/// The second operand of a real mesh's checks.
#[derive(Clone, Copy, Debug)]
enum MeshSecond {
    /// The mesh moved by about a quarter of its size.
    Fraction,
    /// The mesh moved by `(3, −2, 1)` grid steps: nearly coincident faces.
    Steps,
    /// A box over part of the mesh.
    Box,
}

/// The identities on a real mesh against each second operand in turn
/// (the identities are costly on meshes; each mesh gets a share).
fn check_mesh(name: &str, seconds: &[MeshSecond], samples: usize) {
    let a = mesh_loops(name);
    let (lo, hi) = bounds(&a);
    let ext = hi - lo;
    let step = Grid::fit_points(a.iter().flatten()).expect("finite").step();
    for (i, what) in seconds.iter().enumerate() {
        let b = match what {
            MeshSecond::Fraction => translate(&a, ext * DVec3::new(0.31, -0.17, 0.23)),
            MeshSecond::Steps => translate(&a, DVec3::new(3.0, -2.0, 1.0) * step),
            MeshSecond::Box => box_loops(lo + ext * 0.2, hi - ext * DVec3::new(0.4, 0.1, 0.45)),
        };
        let (oa, ob) = mesh_operands(&a, &b);
        let ss = samples_for((&oa.shape, &ob.shape), &[], 1, (samples, 25), i as u64);
        let seen = check_pair(&oa, &ob, &ss, Depth::Mesh);
        assert!(
            seen.generic > 0 && seen.boundary > 0 && seen.overlay > 0,
            "{name} vs {what:?}: {seen:?}"
        );
    }
}

#[test]
fn identities_on_pyvista_sphere() {
    use MeshSecond::*;
    check_mesh("pyvista_sphere", &[Fraction, Steps, Box], 40);
}

#[test]
fn identities_on_cgal_eight() {
    use MeshSecond::*;
    check_mesh("cgal_eight", &[Steps, Box], 40);
}

#[test]
fn identities_on_pyvista_nut() {
    use MeshSecond::*;
    check_mesh("pyvista_nut", &[Fraction, Box], 40);
}

// ---------------------------------------------------------------------
// Adversarial configurations, with exact expected volumes
// ---------------------------------------------------------------------

/// `lo..hi` as an axis-aligned box with integer corners.
type Cube = (GridPoint, GridPoint);

/// Whether the point with doubled coordinates `c` is strictly inside the box.
fn in_cube((lo, hi): Cube, c: GridPoint) -> bool {
    (0..3).all(|k| 2 * lo[k] < c[k] && c[k] < 2 * hi[k])
}

/// The volume of the unit voxels of `region` whose centre (in doubled
/// coordinates) satisfies `pred`: exact for any Boolean combination of
/// boxes with integer corners.
fn voxel_volume((lo, hi): Cube, pred: impl Fn(GridPoint) -> bool) -> Q {
    let mut n = 0i64;
    for x in lo[0]..hi[0] {
        for y in lo[1]..hi[1] {
            for z in lo[2]..hi[2] {
                if pred([2 * x + 1, 2 * y + 1, 2 * z + 1]) {
                    n += 1;
                }
            }
        }
    }
    q(n)
}

/// Checks a result: sanity, watertight closed 2-manifold mesh, exact
/// volume; and membership at every half-grid point of the operands'
/// bounding box (enlarged by a step; a coarser lattice for large boxes)
/// against `expr` of the operands' ray-parity memberships, where no operand's boundary passes. Returns
/// the mesh.
fn check_result(
    what: &str,
    r: &Partition<Cell>,
    want: &Q,
    shapes: &[&Shape],
    expr: impl Fn(&[bool]) -> bool,
) -> TriMesh {
    let m = checked_mesh(what, r);
    assert_q(&m.volume_exact(), want, &format!("{what}: volume"));
    if *want == q(0) {
        assert!(
            matches!(r.root(), PLink::Leaf(Cell::Out)),
            "{what}: an empty result is a single Out cell"
        );
    }
    let oracles: Vec<Solid> = shapes.iter().map(|s| s.oracle(2)).collect();
    let lo = [0, 1, 2].map(|k| {
        shapes
            .iter()
            .map(|s| s.bounds().0[k])
            .min()
            .expect("shapes")
    });
    let hi = [0, 1, 2].map(|k| {
        shapes
            .iter()
            .map(|s| s.bounds().1[k])
            .max()
            .expect("shapes")
    });
    // every half-grid point of small regions; a lattice of about 40
    // points per axis (odd strides, through the lowest corner) of larger
    // ones
    let axis = |k: usize| {
        let (a, b) = (2 * lo[k] - 2, 2 * hi[k] + 2);
        let stride = ((b - a) / 40) | 1;
        (a..=b).step_by(stride as usize)
    };
    let mut checked = 0;
    for x in axis(0) {
        for y in axis(1) {
            for z in axis(2) {
                let d = [x, y, z];
                let ms: Vec<Membership> = oracles.iter().map(|o| o.classify(d)).collect();
                let got = r.classify_point(&half_point(d));
                if ms.contains(&Membership::Boundary) {
                    continue;
                }
                let ins: Vec<bool> = ms.iter().map(|m| *m == Membership::Inside).collect();
                let want = if expr(&ins) {
                    Membership::Inside
                } else {
                    Membership::Outside
                };
                assert_eq!(got, want, "{what} at {d:?} (doubled)");
                checked += 1;
            }
        }
    }
    assert!(checked > 0, "{what}: no point off every boundary");
    m
}

/// `a op b` checked against its expected volume and the oracle.
fn check_op(what: &str, a: &Shape, b: &Shape, op: BoolOp, want: &Q) -> Partition<Cell> {
    let r = a.partition().boolean(&b.partition(), op);
    check_result(&format!("{what} {op:?}"), &r, want, &[a, b], |m| {
        apply(op, m[0], m[1])
    });
    r
}

/// All three operations on two boxes, each volume given by hand and
/// counted in voxels.
fn check_boxes(what: &str, a: Cube, b: Cube, [u, i, d]: [i64; 3]) {
    let (sa, sb) = (cuboid(a.0, a.1), cuboid(b.0, b.1));
    let lo = [0, 1, 2].map(|k| a.0[k].min(b.0[k]));
    let hi = [0, 1, 2].map(|k| a.1[k].max(b.1[k]));
    for (op, want) in [
        (BoolOp::Union, u),
        (BoolOp::Intersection, i),
        (BoolOp::Difference, d),
    ] {
        let voxels = voxel_volume((lo, hi), |c| apply(op, in_cube(a, c), in_cube(b, c)));
        assert_eq!(voxels, q(want), "{what} {op:?}: the hand value");
        check_op(what, &sa, &sb, op, &q(want));
    }
}

/// Boxes whose faces lie in common planes without sharing area, or share
/// part of a plane while overlapping.
#[test]
fn coplanar_faces() {
    let a = ([0, 0, 0], [4, 4, 4]);
    // both z planes shared, overlapping in a column
    check_boxes("column", a, ([2, 2, 0], [6, 6, 4]), [112, 16, 48]);
    // one x and both z planes shared, the overlap is a slab against a face
    check_boxes("slab", a, ([2, -1, 0], [4, 6, 4]), [88, 32, 32]);
    // b is the lower half of a: five of its six planes are a's
    check_boxes("same planes", a, ([0, 0, 0], [4, 4, 2]), [64, 32, 32]);
    // a box straddling a's top face, its sides in a's side planes
    check_boxes("through the lid", a, ([0, 0, 2], [4, 4, 6]), [96, 32, 32]);
}

/// Boxes glued face to face: the union is one box without the glued face,
/// the intersection empty, the difference the first box.
#[test]
fn glued_faces() {
    let a = ([0, 0, 0], [2, 2, 2]);
    check_boxes("whole face", a, ([2, 0, 0], [4, 2, 2]), [16, 0, 8]);
    check_boxes("part of a face", a, ([2, 1, 1], [4, 3, 3]), [16, 0, 8]);
    check_boxes(
        "inside a face",
        ([0, 0, 0], [4, 4, 4]),
        ([1, 1, 4], [3, 3, 6]),
        [72, 0, 64],
    );
    // the glued face leaves no trace in the union of the whole-face pair
    let u = cuboid([0, 0, 0], [2, 2, 2])
        .partition()
        .boolean(&cuboid([2, 0, 0], [4, 2, 2]).partition(), BoolOp::Union);
    let glue = Plane::new([1, 0, 0], -2).expect("x = 2");
    let m = checked_mesh("glued union", &u);
    assert!(
        m.planes.iter().all(|p| !p.is_coincident(&glue)),
        "the glued face is inside the union"
    );
}

/// Boxes touching along an edge (all of it or part) or at a vertex only:
/// the union is a closed 2-manifold (the touching edge and vertex are
/// split), the intersection empty.
#[test]
fn touching_edges_and_vertices() {
    let a = ([0, 0, 0], [2, 2, 2]);
    check_boxes("edge", a, ([2, 2, 0], [4, 4, 2]), [16, 0, 8]);
    check_boxes("part of an edge", a, ([2, 2, 1], [4, 4, 3]), [16, 0, 8]);
    check_boxes(
        "edge inside an edge",
        a,
        ([2, -1, 2], [3, 3, 3]),
        [12, 0, 8],
    );
    check_boxes("vertex", a, ([2, 2, 2], [4, 4, 4]), [16, 0, 8]);
    check_boxes(
        "vertex on an edge",
        ([0, 0, 0], [4, 2, 2]),
        ([1, 2, 2], [3, 4, 4]),
        [24, 0, 16],
    );
}

/// Solids one grid step apart, and overlapping by one step: axis boxes,
/// and prisms cut by the tilted planes `x + y = 10` and `x + y = 11`
/// (or `9`).
#[test]
fn one_step_apart_and_overlapping() {
    let a = ([0, 0, 0], [8, 8, 8]);
    check_boxes("one apart", a, ([9, 0, 0], [17, 8, 8]), [1024, 0, 512]);
    check_boxes(
        "one apart diagonally",
        a,
        ([9, 9, 9], [17, 17, 17]),
        [1024, 0, 512],
    );
    check_boxes(
        "one overlapping",
        a,
        ([7, 0, 0], [15, 8, 8]),
        [960, 64, 448],
    );
    check_boxes(
        "one cube overlapping",
        a,
        ([7, 7, 7], [15, 15, 15]),
        [1023, 1, 511],
    );

    let prism = |xy: &[[i32; 2]]| {
        let pts: Vec<GridPoint> = xy
            .iter()
            .flat_map(|p| [[p[0], p[1], 0], [p[0], p[1], 8]])
            .collect();
        hull(&pts).expect("a prism")
    };
    // x + y <= 10 within the square [0, 8]²: area 64 − 18 = 46
    let low = prism(&[[0, 0], [8, 0], [8, 2], [2, 8], [0, 8]]);
    assert_eq!(low.volume(), q(46 * 8));
    // x + y >= 11 within [0, 16] × [0, 8]: a trapezoid of parallel sides 5 and 13
    let gap = prism(&[[11, 0], [16, 0], [16, 8], [3, 8]]);
    assert_eq!(gap.volume(), q((5 + 13) * 8 / 2 * 8));
    let va = low.volume();
    let vb = gap.volume();
    check_op("tilted, one apart", &low, &gap, BoolOp::Union, &(&va + &vb));
    check_op("tilted, one apart", &low, &gap, BoolOp::Intersection, &q(0));
    check_op("tilted, one apart", &low, &gap, BoolOp::Difference, &va);
    // x + y >= 9: the overlap is the strip 9 <= x + y <= 10 in the square,
    // the quadrilateral (1, 8) (2, 8) (8, 2) (8, 1): area 13/2
    let over = prism(&[[9, 0], [16, 0], [16, 8], [1, 8]]);
    let strip = prism(&[[1, 8], [2, 8], [8, 2], [8, 1]]);
    assert_eq!(strip.volume(), q(52));
    let vo = over.volume();
    check_op(
        "tilted, one overlapping",
        &low,
        &over,
        BoolOp::Intersection,
        &q(52),
    );
    check_op(
        "tilted, one overlapping",
        &low,
        &over,
        BoolOp::Union,
        &(&va + &vo - q(52)),
    );
    check_op(
        "tilted, one overlapping",
        &low,
        &over,
        BoolOp::Difference,
        &(&va - q(52)),
    );
}

/// The cube `[0, n]³` with its corner `(n, n, n)` moved to `corner`
/// (one step along x): the face `x = n` is no longer planar and is split
/// along its diagonal from `(n, n, 0)` to `(n, 0, n)`.
fn cube_with_corner(n: i32, corner: GridPoint) -> Shape {
    let mut s = cuboid([0; 3], [n; 3]);
    for f in &mut s.faces {
        for p in f.iter_mut() {
            if *p == [n, n, n] {
                *p = corner;
            }
        }
    }
    let x_face = s
        .faces
        .iter()
        .position(|f| f.contains(&corner) && f.iter().filter(|p| p[0] == n).count() == 3)
        .expect("the face x = n");
    s.faces.remove(x_face);
    s.faces.push(vec![[n, 0, 0], [n, n, 0], [n, 0, n]]);
    s.faces.push(vec![[n, n, 0], corner, [n, 0, n]]);
    s
}

/// A box against the same box with one vertex moved by one grid step: the
/// differences are tetrahedral slivers one step thick, of volume `n² / 6`.
#[test]
fn sliver_from_one_moved_vertex() {
    let n = 1001;
    let cube = cuboid([0; 3], [n; 3]);
    let vol = q(n as i64 * n as i64 * n as i64);
    let sliver = Q::new((n as i64 * n as i64).into(), 6.into());
    // moved outward: the cube plus a sliver
    let out = cube_with_corner(n, [n + 1, n, n]);
    assert_eq!(out.volume(), &vol + &sliver);
    check_op("bulge", &out, &cube, BoolOp::Difference, &sliver);
    check_op("bulge", &cube, &out, BoolOp::Difference, &q(0));
    check_op("bulge", &cube, &out, BoolOp::Intersection, &vol);
    check_op("bulge", &cube, &out, BoolOp::Union, &(&vol + &sliver));
    // moved inward: the cube minus a sliver
    let dent = cube_with_corner(n, [n - 1, n, n]);
    assert_eq!(dent.volume(), &vol - &sliver);
    check_op("dent", &cube, &dent, BoolOp::Difference, &sliver);
    check_op("dent", &dent, &cube, BoolOp::Difference, &q(0));
    check_op("dent", &cube, &dent, BoolOp::Union, &vol);
    // the bulge and the dent differ by both slivers
    check_op(
        "bulge − dent",
        &out,
        &dent,
        BoolOp::Difference,
        &(&sliver + &sliver),
    );
}

/// The triangles of `m` with every vertex on the closed box `c` face
/// toward the box's centre (the inner boundary of a hollow solid runs
/// inward); returns how many there are.
fn faces_inward(m: &TriMesh, (lo, hi): Cube) -> usize {
    let on_box = |p: &Point| {
        let g = p.as_grid().expect("box corners are grid points");
        (0..3).all(|k| lo[k] <= g[k] && g[k] <= hi[k])
    };
    let centre2 = [0, 1, 2].map(|k| lo[k] as i128 + hi[k] as i128);
    let mut n = 0;
    for (t, pl) in m.triangles.iter().zip(&m.planes) {
        if t.iter().all(|&v| on_box(&m.vertices[v as usize])) {
            let nn = pl.normal();
            let s: i128 =
                (0..3).map(|k| nn[k] as i128 * centre2[k]).sum::<i128>() + 2 * pl.offset();
            assert!(
                s > 0,
                "a triangle of the inner boundary faces away from the hole"
            );
            n += 1;
        }
    }
    n
}

/// A box strictly inside a box: the union is the outer box, the
/// intersection the inner one, the difference a hollow shell whose inner
/// boundary is oriented inward.
#[test]
fn nested_solids() {
    let (outer, inner) = (([0, 0, 0], [10, 10, 10]), ([3, 3, 3], [6, 6, 6]));
    check_boxes("nested", outer, inner, [1000, 27, 973]);
    check_boxes("nested, reversed", inner, outer, [1000, 27, 0]);
    let shell = check_op(
        "hollow",
        &cuboid(outer.0, outer.1),
        &cuboid(inner.0, inner.1),
        BoolOp::Difference,
        &q(973),
    );
    let m = checked_mesh("hollow", &shell);
    assert!(faces_inward(&m, inner) >= 12, "the cavity has six faces");
    assert_eq!(
        shell.classify_point(&Point::Grid([4, 4, 4])),
        Membership::Outside
    );
    assert_eq!(
        shell.classify_point(&Point::Grid([6, 4, 4])),
        Membership::Boundary
    );
    assert_eq!(
        shell.classify_point(&Point::Grid([7, 4, 4])),
        Membership::Inside
    );
    // a tetrahedron nested in a tetrahedron
    let big = hull(&[[0, 0, 0], [24, 0, 0], [0, 24, 0], [0, 0, 24]]).expect("tetrahedron");
    let small = hull(&[[2, 2, 2], [8, 2, 2], [2, 8, 2], [2, 2, 8]]).expect("tetrahedron");
    let (vb, vs) = (big.volume(), small.volume());
    check_op("tetrahedra", &big, &small, BoolOp::Difference, &(&vb - &vs));
    check_op("tetrahedra", &big, &small, BoolOp::Union, &vb);
    check_op("tetrahedra", &big, &small, BoolOp::Intersection, &vs);
}

/// A box inside a box touching the outer's boundary from inside: on a
/// face, along an edge (two faces), at a corner (three faces).
#[test]
fn touching_nested() {
    let outer = ([0, 0, 0], [10, 10, 10]);
    check_boxes("on a face", outer, ([0, 3, 3], [3, 6, 6]), [1000, 27, 973]);
    check_boxes("in an edge", outer, ([0, 0, 3], [3, 3, 6]), [1000, 27, 973]);
    check_boxes(
        "in a corner",
        outer,
        ([0, 0, 0], [3, 3, 3]),
        [1000, 27, 973],
    );
    check_boxes(
        "through a face",
        outer,
        ([0, 3, 3], [10, 6, 6]),
        [1000, 90, 910],
    );
    // an edge of a prism inside in a face of the box: the difference is a
    // groove touching the face along a segment
    let diamond = diamond();
    let o = cuboid(outer.0, outer.1);
    check_op(
        "edge on a face",
        &o,
        &diamond,
        BoolOp::Difference,
        &q(1000 - 48),
    );
    check_op("edge on a face", &o, &diamond, BoolOp::Union, &q(1000));
    check_op("edge on a face", &o, &diamond, BoolOp::Intersection, &q(48));
}

/// A square prism standing on its edge `x = 0, y = 5`, `z` from 2 to 8.
fn diamond() -> Shape {
    let d = hull(&[
        [0, 5, 2],
        [2, 3, 2],
        [2, 7, 2],
        [4, 5, 2],
        [0, 5, 8],
        [2, 3, 8],
        [2, 7, 8],
        [4, 5, 8],
    ])
    .expect("a square prism standing on its edge");
    assert_eq!(d.volume(), q(8 * 6));
    d
}

/// The same face loops started at another vertex and listed in another
/// order: a different tree for the same solid.
fn reordered(s: &Shape) -> Shape {
    let mut faces: Vec<Vec<GridPoint>> = s
        .faces
        .iter()
        .map(|f| {
            let mut f = f.clone();
            f.rotate_left(1);
            f
        })
        .collect();
    faces.reverse();
    Shape { faces }
}

/// A solid with itself (the same partition, another build of it, and a
/// copy translated by zero): union and intersection are the solid, the
/// difference empty.
#[test]
fn the_same_solid_twice() {
    let solids = [
        cuboid([-3, 0, 2], [4, 5, 9]),
        hull(&[
            [0, 0, 0],
            [7, 1, 2],
            [1, 8, -3],
            [-2, 3, 6],
            [5, 5, 5],
            [3, -4, 1],
        ])
        .expect("hull"),
        cube_with_corner(9, [10, 9, 9]),
    ];
    for s in &solids {
        let v = s.volume();
        let p = s.partition();
        for (what, other) in [
            ("itself", p.clone()),
            ("rebuilt", reordered(s).partition()),
            (
                "moved by zero",
                s.translated([0, 0, 0]).expect("fits").partition(),
            ),
        ] {
            for (op, want) in [
                (BoolOp::Union, v.clone()),
                (BoolOp::Intersection, v.clone()),
                (BoolOp::Difference, q(0)),
            ] {
                let r = p.boolean(&other, op);
                check_result(&format!("{what} {op:?}"), &r, &want, &[s], |m| {
                    apply(op, m[0], m[0])
                });
            }
            let o = merge_smaller_into_larger(&p, &other, &Overlay);
            o.sanity_check()
                .unwrap_or_else(|e| panic!("{what}: overlay: {e}"));
            assert!(
                o.locate(&half_point([1, 1, 1])).iter().all(|(x, y)| x == y),
                "{what}: both labels agree"
            );
        }
    }
}

/// A set expression over the operands' memberships.
type Expr = fn(&[bool]) -> bool;

/// `((A ∪ B) − C) ∩ D` with checks after every step, against voxel
/// counts and the oracle.
#[test]
fn chained_operations() {
    let a = ([0, 0, 0], [6, 6, 6]);
    let b = ([3, 1, 1], [9, 5, 5]);
    let c = ([2, -1, 2], [4, 10, 3]);
    let d = ([1, 1, 0], [8, 8, 4]);
    let shapes = [a, b, c, d].map(|x| cuboid(x.0, x.1));
    let refs: Vec<&Shape> = shapes.iter().collect();
    let parts: Vec<Partition<Cell>> = shapes.iter().map(Shape::partition).collect();
    let region = ([-1, -1, -1], [10, 11, 7]);
    let steps: [(&str, BoolOp, Expr); 3] = [
        ("A ∪ B", BoolOp::Union, |m| m[0] || m[1]),
        ("(A ∪ B) − C", BoolOp::Difference, |m| {
            (m[0] || m[1]) && !m[2]
        }),
        ("((A ∪ B) − C) ∩ D", BoolOp::Intersection, |m| {
            (m[0] || m[1]) && !m[2] && m[3]
        }),
    ];
    let mut acc = parts[0].clone();
    for (i, (what, op, expr)) in steps.iter().enumerate() {
        acc = acc.boolean(&parts[i + 1], *op);
        let cubes = [a, b, c, d];
        let want = voxel_volume(region, |p| expr(&cubes.map(|x| in_cube(x, p))));
        check_result(what, &acc, &want, &refs, expr);
    }
    // the same chain, associated the other way where the identities allow
    let other = parts[3]
        .boolean(
            &parts[0].boolean(&parts[1], BoolOp::Union),
            BoolOp::Intersection,
        )
        .boolean(
            &parts[2].boolean(&parts[3], BoolOp::Intersection),
            BoolOp::Difference,
        );
    let want = volume("final", &acc);
    check_result("D ∩ (A ∪ B) − (C ∩ D)", &other, &want, &refs, steps[2].2);
}

/// Twenty small boxes subtracted one after the other from a big box
/// (some crossing its boundary, some overlapping each other): the volume
/// is exact after every step and the reduced tree grows at most linearly.
#[test]
fn iterated_subtractions() {
    let big = ([0, 0, 0], [64, 64, 64]);
    let mut acc = cuboid(big.0, big.1).partition();
    let mut rng = Rng(0xc5_9001);
    // voxels still in the solid
    let side = 64usize;
    let mut solid = vec![true; side * side * side];
    let mut holes: Vec<Cube> = Vec::new();
    let mut sizes = vec![acc.nodes().len()];
    for step in 0..20 {
        let lo = [0; 3].map(|_| rng.below(72) as i32 - 4);
        let hi = [0, 1, 2].map(|k| lo[k] + 2 + rng.below(7) as i32);
        let hole = (lo, hi);
        holes.push(hole);
        acc = acc.boolean(&cuboid(lo, hi).partition(), BoolOp::Difference);
        for x in lo[0].max(0)..hi[0].min(64) {
            for y in lo[1].max(0)..hi[1].min(64) {
                for z in lo[2].max(0)..hi[2].min(64) {
                    solid[(x as usize * side + y as usize) * side + z as usize] = false;
                }
            }
        }
        let want = q(solid.iter().filter(|v| **v).count() as i64);
        let m = checked_mesh(&format!("step {step}"), &acc);
        assert_q(&m.volume_exact(), &want, &format!("step {step}: volume"));
        sizes.push(acc.nodes().len());
        // a point inside each hole is outside, unless the hole is outside the box anyway
        for h in &holes {
            let c = [0, 1, 2].map(|k| h.0[k] + h.1[k]);
            assert_ne!(
                acc.classify_point(&half_point(c)),
                Membership::Inside,
                "step {step}: the centre of {h:?}"
            );
        }
    }
    // each box brings six planes, cut into a few pieces by the planes
    // around it: at most twelve new nodes per step (about seven are seen)
    for (i, n) in sizes.iter().enumerate() {
        assert!(*n <= 6 + 12 * i, "step {i}: {n} nodes ({sizes:?})");
    }
}

/// Found by `touching_nested` and `identities_on_small_solids`: solids
/// whose boundary touches itself along an edge where the two wedges of
/// the solid around the edge are joined around its endpoints —
///
/// - the box `[0, 10]³` minus a square prism lying against its face
///   `x = 0` along the prism's edge `x = 0, y = 5, 2 <= z <= 8` (a groove
///   touching the face along a segment),
/// - the box `[-1, 3] × [-1, 3] × [-1, 2]` minus two unit cubes touching
///   along the edge `x = y = 1` (two cavities touching along an edge),
/// - the complement of those two cubes, `¬A ∩ ¬B` (= `¬(A ∪ B)`).
///
/// Each result was a valid partition with the right volume, but its mesh
/// used the touching edge twice in each direction: the triangles around
/// the edge were always paired across the solid's interior, which here
/// joins the two sheets into a single fan at each endpoint, so no vertex
/// copy could separate the two uses of the edge. Pairing across the
/// exterior gives two fans per endpoint.
#[test]
fn regress_mesh_pinched_edge_with_joined_wedges() {
    let o = cuboid([0, 0, 0], [10, 10, 10]);
    let groove = o
        .partition()
        .boolean(&diamond().partition(), BoolOp::Difference);
    groove.sanity_check().expect("a valid partition");
    assert_q(
        &groove.to_mesh().volume_exact(),
        &q(1000 - 48),
        "box − prism",
    );

    let a = cuboid([0, 0, 0], [1, 1, 1]);
    let b = cuboid([1, 1, 0], [2, 2, 1]);
    let u = a.partition().boolean(&b.partition(), BoolOp::Union);
    let hollow = cuboid([-1, -1, -1], [3, 3, 2])
        .partition()
        .boolean(&u, BoolOp::Difference);
    hollow.sanity_check().expect("a valid partition");
    assert_q(&hollow.to_mesh().volume_exact(), &q(46), "C − (A ∪ B)");

    let not_u = a
        .partition()
        .complement()
        .boolean(&b.partition().complement(), BoolOp::Intersection);
    not_u.sanity_check().expect("a valid partition");
    assert_q(
        &not_u.to_mesh().volume_exact(),
        &q(-2),
        "¬A ∩ ¬B inside out",
    );

    checked_mesh("box − prism", &groove);
    checked_mesh("C − (A ∪ B)", &hollow);
    checked_mesh("¬A ∩ ¬B", &not_u);
}
