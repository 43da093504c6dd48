//! Closed convex-faced primitives for the built-in scenes.
//!
//! Every input coordinate is first rounded to the design grid (multiples
//! of [`DESIGN_STEP`]), and vertices are then formed only by sums of such
//! values and products of two of them. Those are exact in `f64`, so the
//! faces are exactly planar (parallelograms, trapezoids, flat rings) and
//! stay planar when a toolkit grid of `2^20` or more steps per unit snaps
//! them. The rounding is a property of the generated scenes, not a
//! tolerance anywhere in a computation.

use std::collections::HashMap;
use std::ops::Range;

use glam::DVec3;

use crate::mesh::newell;
use crate::{Face, Mesh};

/// The design grid of generated scenes: `2^-10` input units (about a
/// millimetre when units are metres).
pub(crate) const DESIGN_STEP: f64 = 1.0 / 1024.0;

/// Rounds to the design grid.
pub(crate) fn q(x: f64) -> f64 {
    (x / DESIGN_STEP).round() * DESIGN_STEP
}

/// Rounds each coordinate to the design grid.
pub(crate) fn q3(v: DVec3) -> DVec3 {
    DVec3::new(q(v.x), q(v.y), q(v.z))
}

/// A coordinate axis (the direction of a [`Builder::lathe`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Axis {
    X,
    Y,
    Z,
}

impl Axis {
    /// `(d, u, v)`: the axis and two perpendicular unit vectors with
    /// `u × v = d`.
    fn frame(self) -> (DVec3, DVec3, DVec3) {
        match self {
            Axis::X => (DVec3::X, DVec3::Y, DVec3::Z),
            Axis::Y => (DVec3::Y, DVec3::Z, DVec3::X),
            Axis::Z => (DVec3::Z, DVec3::X, DVec3::Y),
        }
    }
}

/// A square cross-section for [`Builder::lathe`]: radius `r` gives a square
/// of half-width `r`.
pub(crate) const SQUARE: [[f64; 2]; 4] = [[1.0, -1.0], [1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0]];

/// A regular `n`-gon cross-section of circumradius 1 (rounded to the
/// design grid), the first corner at `phase_deg` degrees.
pub(crate) fn regular(n: usize, phase_deg: f64) -> Vec<[f64; 2]> {
    (0..n)
        .map(|k| {
            let a = phase_deg.to_radians() + k as f64 * std::f64::consts::TAU / n as f64;
            [q(a.cos()), q(a.sin())]
        })
        .collect()
}

/// Six times the signed volume bounded by `faces`.
fn six_volume(faces: &[Vec<DVec3>]) -> f64 {
    faces
        .iter()
        .flat_map(|f| (1..f.len() - 1).map(move |i| f[0].dot(f[i].cross(f[i + 1]))))
        .sum()
}

/// Collects closed solids into a [`Mesh`], welding equal positions within
/// each group (never across groups, so a group can be moved on its own).
#[derive(Debug)]
pub(crate) struct Builder {
    mesh: Mesh,
    group: u32,
    weld: HashMap<(u32, [u64; 3]), u32>,
    parts: Vec<Range<usize>>,
}

impl Builder {
    pub(crate) fn new() -> Builder {
        Builder {
            mesh: Mesh::default(),
            group: 0,
            weld: HashMap::new(),
            parts: Vec::new(),
        }
    }

    /// Continues in group `name` (created if new).
    pub(crate) fn group(&mut self, name: &str) -> &mut Builder {
        self.group = self.mesh.add_group(name);
        self
    }

    /// The face ranges of the solids added so far, one per primitive.
    #[cfg(test)]
    pub(crate) fn parts(&self) -> &[Range<usize>] {
        &self.parts
    }

    pub(crate) fn finish(self) -> Mesh {
        self.mesh
    }

    fn vertex(&mut self, p: DVec3) -> u32 {
        let key = (self.group, [p.x, p.y, p.z].map(|c| (c + 0.0).to_bits()));
        let positions = &mut self.mesh.positions;
        *self.weld.entry(key).or_insert_with(|| {
            positions.push(p);
            (positions.len() - 1) as u32
        })
    }

    /// Adds one closed solid given as outward, counter-clockwise faces.
    ///
    /// Panics if the faces enclose no positive volume: the primitives below
    /// guarantee it, so a failure is a bug in a generator.
    fn solid(&mut self, faces: Vec<Vec<DVec3>>) -> &mut Builder {
        assert!(
            six_volume(&faces) > 0.0,
            "generated solid is inside out or flat: {faces:?}"
        );
        let start = self.mesh.faces.len();
        for f in faces {
            let vertices = f.into_iter().map(|p| self.vertex(p)).collect();
            self.mesh.faces.push(Face {
                vertices,
                line: 0,
                group: self.group,
            });
        }
        self.parts.push(start..self.mesh.faces.len());
        self
    }

    /// The axis-aligned box `[min, max]`.
    pub(crate) fn cuboid(&mut self, min: DVec3, max: DVec3) -> &mut Builder {
        let (min, max) = (q3(min), q3(max));
        let d = max - min;
        self.parallelepiped(min, d * DVec3::X, d * DVec3::Y, d * DVec3::Z)
    }

    /// The parallelepiped `o + s a + t b + u c`, `s, t, u ∈ [0, 1]` (an
    /// oriented box when the edges are perpendicular). Either handedness
    /// of `(a, b, c)` is accepted.
    pub(crate) fn parallelepiped(
        &mut self,
        o: DVec3,
        a: DVec3,
        b: DVec3,
        c: DVec3,
    ) -> &mut Builder {
        let (o, a, mut b, mut c) = (q3(o), q3(a), q3(b), q3(c));
        if a.dot(b.cross(c)) < 0.0 {
            std::mem::swap(&mut b, &mut c);
        }
        self.solid(vec![
            vec![o, o + c, o + b + c, o + b],
            vec![o + a, o + a + b, o + a + b + c, o + a + c],
            vec![o, o + a, o + a + c, o + c],
            vec![o + b, o + b + c, o + a + b + c, o + a + b],
            vec![o, o + b, o + a + b, o + a],
            vec![o + c, o + a + c, o + a + b + c, o + b + c],
        ])
    }

    /// The prism swept by the convex planar loop `base` along `h`.
    pub(crate) fn prism(&mut self, base: &[DVec3], h: DVec3) -> &mut Builder {
        self.frustum(base, h, 1.0)
    }

    /// The frustum between the convex planar loop `base` and its copy
    /// scaled by `top_scale` about the base's (rounded) centroid and moved
    /// by `h`.
    pub(crate) fn frustum(&mut self, base: &[DVec3], h: DVec3, top_scale: f64) -> &mut Builder {
        let mut ring: Vec<DVec3> = base.iter().map(|p| q3(*p)).collect();
        let (h, s) = (q3(h), q(top_scale));
        if newell(&ring).dot(h) < 0.0 {
            ring.reverse();
        }
        let c = q3(ring.iter().sum::<DVec3>() / ring.len() as f64);
        let top: Vec<DVec3> = ring.iter().map(|p| c + h + (*p - c) * s).collect();
        let n = ring.len();
        let mut faces = vec![ring.iter().rev().copied().collect(), top.clone()];
        for i in 0..n {
            let j = (i + 1) % n;
            faces.push(vec![ring[i], ring[j], top[j], top[i]]);
        }
        self.solid(faces)
    }

    /// The pyramid over the convex planar loop `base` with tip `apex`.
    pub(crate) fn pyramid(&mut self, base: &[DVec3], apex: DVec3) -> &mut Builder {
        let mut ring: Vec<DVec3> = base.iter().map(|p| q3(*p)).collect();
        let apex = q3(apex);
        if newell(&ring).dot(apex - ring[0]) < 0.0 {
            ring.reverse();
        }
        let n = ring.len();
        let mut faces = vec![ring.iter().rev().copied().collect::<Vec<_>>()];
        faces.extend((0..n).map(|i| vec![ring[i], ring[(i + 1) % n], apex]));
        self.solid(faces)
    }

    /// Two pyramids glued at their base loop `ring` (only triangles, so any
    /// orientation stays planar): tips `top` and `bottom` on either side.
    pub(crate) fn bipyramid(&mut self, ring: &[DVec3], top: DVec3, bottom: DVec3) -> &mut Builder {
        let mut ring: Vec<DVec3> = ring.iter().map(|p| q3(*p)).collect();
        let (top, bottom) = (q3(top), q3(bottom));
        if newell(&ring).dot(top - ring[0]) < 0.0 {
            ring.reverse();
        }
        let n = ring.len();
        let mut faces = Vec::with_capacity(2 * n);
        for i in 0..n {
            let j = (i + 1) % n;
            faces.push(vec![ring[i], ring[j], top]);
            faces.push(vec![ring[j], ring[i], bottom]);
        }
        self.solid(faces)
    }

    /// A solid of revolution with a polygonal cross-section: the
    /// `profile` of `(radius, height)` pairs, read from the bottom up along
    /// the outside, swept around `axis` through `base`. The cross-section
    /// `ring` (counter-clockwise, around the origin) is scaled by each
    /// radius; a profile starting or ending off the axis gets a cap, a
    /// radius of 0 a tip.
    pub(crate) fn lathe(
        &mut self,
        base: DVec3,
        axis: Axis,
        profile: &[(f64, f64)],
        ring: &[[f64; 2]],
    ) -> &mut Builder {
        let (d, u, v) = axis.frame();
        let base = q3(base);
        let dirs: Vec<DVec3> = ring.iter().map(|c| u * q(c[0]) + v * q(c[1])).collect();
        let rings: Vec<(f64, Vec<DVec3>)> = profile
            .iter()
            .map(|&(r, h)| {
                let (r, h) = (q(r), q(h));
                (r, dirs.iter().map(|e| base + d * h + *e * r).collect())
            })
            .collect();
        let n = dirs.len();
        let mut faces = Vec::new();
        if let Some((r, first)) = rings.first()
            && *r > 0.0
        {
            faces.push(first.iter().rev().copied().collect());
        }
        for w in rings.windows(2) {
            let ((r0, a), (r1, b)) = (&w[0], &w[1]);
            for i in 0..n {
                let j = (i + 1) % n;
                let face = match (*r0 > 0.0, *r1 > 0.0) {
                    (true, true) => vec![a[i], a[j], b[j], b[i]],
                    (true, false) => vec![a[i], a[j], b[0]],
                    (false, true) => vec![a[0], b[j], b[i]],
                    (false, false) => continue,
                };
                faces.push(face);
            }
        }
        if let Some((r, last)) = rings.last()
            && *r > 0.0
        {
            faces.push(last.clone());
        }
        self.solid(faces)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Exact checks of a generated solid: every directed edge appears once
    /// and its reverse once, the volume is positive, every face is exactly
    /// planar and strictly convex, counter-clockwise from outside.
    ///
    /// Coordinates of generated scenes are multiples of `2^-20`, so they
    /// become integers exactly and the checks run in `i128`.
    pub(crate) fn check_part(mesh: &Mesh, faces: Range<usize>) -> Result<(), String> {
        let part = Mesh {
            positions: mesh.positions.clone(),
            faces: mesh.faces[faces.clone()].to_vec(),
            groups: mesh.groups.clone(),
        };
        if !part.is_closed_oriented() {
            return Err(format!(
                "faces {faces:?} are not closed and consistently oriented"
            ));
        }
        if part.signed_volume() <= 0.0 {
            return Err(format!("faces {faces:?} enclose no positive volume"));
        }
        let int = |p: DVec3| -> Result<[i128; 3], String> {
            let s = p * (1u64 << 20) as f64;
            if s.fract() != DVec3::ZERO || s.abs().max_element() >= 2f64.powi(40) {
                return Err(format!("{p} is not on the 2^-20 grid"));
            }
            Ok([s.x as i128, s.y as i128, s.z as i128])
        };
        let sub = |a: [i128; 3], b: [i128; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let cross = |a: [i128; 3], b: [i128; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let dot = |a: [i128; 3], b: [i128; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        for fi in faces {
            let pts = mesh
                .face_points(fi)
                .into_iter()
                .map(int)
                .collect::<Result<Vec<_>, _>>()?;
            let k = pts.len();
            let normal = cross(sub(pts[1], pts[0]), sub(pts[2], pts[0]));
            for i in 0..k {
                let (a, b, c) = (pts[i], pts[(i + 1) % k], pts[(i + 2) % k]);
                if dot(sub(c, pts[0]), normal) != 0 {
                    return Err(format!("face {fi} is not planar"));
                }
                if dot(cross(sub(b, a), sub(c, b)), normal) <= 0 {
                    return Err(format!("face {fi} is not strictly convex"));
                }
            }
        }
        Ok(())
    }

    fn single(build: impl FnOnce(&mut Builder)) -> Mesh {
        let mut b = Builder::new();
        b.group("test");
        build(&mut b);
        assert_eq!(b.parts().len(), 1);
        let part = b.parts()[0].clone();
        let m = b.finish();
        check_part(&m, part).unwrap();
        m
    }

    fn hexagon() -> Vec<DVec3> {
        regular(6, 10.0)
            .iter()
            .map(|c| DVec3::new(c[0] * 0.3 + 1.0, c[1] * 0.3, 0.5))
            .collect()
    }

    #[test]
    fn cuboid_is_closed_outward() {
        let m = single(|b| {
            b.cuboid(DVec3::new(-1.0, 0.1, 0.2), DVec3::new(0.5, 0.7, 2.0));
        });
        assert_eq!(m.faces.len(), 6);
        assert_eq!(m.positions.len(), 8);
    }

    #[test]
    fn oriented_box_of_either_handedness() {
        let (s, c) = 30f64.to_radians().sin_cos();
        let a = DVec3::new(c, s, 0.0) * 0.8;
        let b = DVec3::new(-s, c, 0.1) * 0.3;
        let h = DVec3::new(0.05, 0.0, 0.4);
        for (b2, h2) in [(b, h), (h, b)] {
            let m = single(|bld| {
                bld.parallelepiped(DVec3::new(0.3, -0.2, 0.1), a, b2, h2);
            });
            assert!(m.signed_volume() > 0.0);
        }
    }

    #[test]
    fn prism_and_frustum_either_way_round() {
        for h in [DVec3::new(0.0, 0.1, 0.7), DVec3::new(0.0, 0.0, -0.4)] {
            let mut base = hexagon();
            let m = single(|b| {
                b.prism(&base, h);
            });
            assert_eq!(m.faces.len(), 8);
            base.reverse();
            single(|b| {
                b.frustum(&base, h, 0.625);
            });
        }
    }

    #[test]
    fn pyramid_and_bipyramid() {
        let m = single(|b| {
            b.pyramid(&hexagon(), DVec3::new(1.0, 0.0, -0.3));
        });
        assert_eq!(m.faces.len(), 7);
        // a planar diamond with normal (1, 0, -2) and tips on either side
        let diamond = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.3, -0.05, 0.15),
            DVec3::new(0.5, 0.0, 0.25),
            DVec3::new(0.3, 0.05, 0.15),
        ];
        let top = DVec3::new(0.3, 0.0, 0.15) + DVec3::new(-1.0, 0.0, 2.0) * 0.01;
        let bottom = DVec3::new(0.3, 0.0, 0.15) - DVec3::new(-1.0, 0.0, 2.0) * 0.01;
        let m = single(|b| {
            b.bipyramid(&diamond, top, bottom);
        });
        assert_eq!(m.faces.len(), 8);
        // swapping the tips is fixed up by reversing the ring
        single(|b| {
            b.bipyramid(&diamond, bottom, top);
        });
    }

    #[test]
    fn lathe_with_caps_tips_and_steps() {
        // an arrow: cap, shaft, step out, tip
        for axis in [Axis::X, Axis::Y, Axis::Z] {
            let m = single(|b| {
                b.lathe(
                    DVec3::new(0.1, 0.2, 0.3),
                    axis,
                    &[(0.02, 0.0), (0.02, 0.6), (0.05, 0.6), (0.0, 0.75)],
                    &SQUARE,
                );
            });
            assert_eq!(m.faces.len(), 13);
        }
        // a pot with a rim, octagonal, and a double cone
        single(|b| {
            b.lathe(
                DVec3::ZERO,
                Axis::Z,
                &[(0.12, 0.0), (0.16, 0.3), (0.18, 0.3), (0.18, 0.35)],
                &regular(8, 22.5),
            );
        });
        single(|b| {
            b.lathe(
                DVec3::ZERO,
                Axis::Z,
                &[(0.0, 0.0), (0.1, 0.1), (0.0, 0.3)],
                &regular(5, 0.0),
            );
        });
    }

    #[test]
    fn welding_stays_inside_a_group() {
        let mut b = Builder::new();
        b.group("a").cuboid(DVec3::ZERO, DVec3::ONE);
        b.group("b").cuboid(DVec3::ZERO, DVec3::ONE);
        b.group("a").cuboid(DVec3::X, DVec3::new(2.0, 1.0, 1.0));
        let m = b.finish();
        // the second box has its own 8 vertices, the third shares 4 with the first
        assert_eq!(m.positions.len(), 8 + 8 + 4);
        assert_eq!(m.groups, vec!["a", "b"]);
    }

    #[test]
    #[should_panic(expected = "inside out or flat")]
    fn flat_solid_is_a_bug() {
        let mut b = Builder::new();
        b.group("a").cuboid(DVec3::ZERO, DVec3::new(1.0, 1.0, 0.0));
    }
}
