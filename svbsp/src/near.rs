//! Which occluders may hide part of a light from which faces: a box of
//! each occluder's penumbra volume within the scene, and a uniform grid of
//! the faces' boxes to find the faces it meets (the faces as wide as the
//! scene, a ground, tested apart), so a scene of `n` faces is not `n²`
//! pairs. Boxes only ever let through more pairs than the exact tests
//! keep: the exact signs decide (see [`crate::area`]).

use bsp_core::{GridPoint, Plane};
use rayon::prelude::*;

use crate::area::{HalfSpaces, Occluder, Regions};
use crate::blockers::{PlaneKey, plane_key};
use crate::boxes::{Box3, CellGrid, Reach, grid_box, overlap, union};
use crate::light::Light;

/// Per receiving face, the indices of the occluders not in its plane whose
/// penumbra volume (`regions`, per occluder; `None`: it hides nothing) may
/// meet it, in index order; and per occluder, boxes of its penumbra and
/// umbra volumes within the scene ([`Reach`]).
pub(crate) fn near_lists(
    lights: &[Light],
    faces: &[Occluder],
    (occluders, regions): (&[Occluder], &[Option<Regions>]),
) -> (Vec<Vec<u32>>, Vec<Reach>) {
    let boxes: Vec<Box3> = faces.iter().map(|f| grid_box(f.corners())).collect();
    let planes: Vec<_> = faces.iter().map(|f| plane_key(f.plane())).collect();
    // (a hash of each face's plane inline in the grid: most faces met are
    // in another plane than the occluder's, told without reading theirs)
    let hashes: Vec<u32> = planes.iter().map(plane_hash).collect();
    let Some(scene) = boxes.iter().copied().reduce(union) else {
        return (Vec::new(), Vec::new());
    };
    // the faces as wide as the scene on two axes (a ground) apart, the
    // others in a grid over their own box: cells of about one face each
    // where the faces are (a grid over the ground's box would put the
    // whole mesh in a few of its cells, each visited by every occluder)
    let wide_face = |b: &Box3| {
        (0..3)
            .filter(|&k| 4 * (b[k][1] - b[k][0]) > scene[k][1] - scene[k][0])
            .count()
            >= 2
    };
    let (wide, small): (Vec<_>, Vec<_>) = (boxes.iter().enumerate())
        .map(|(i, b)| (i as u32, *b))
        .partition(|(_, b)| wide_face(b));
    let small_box = small.iter().map(|(_, b)| *b).reduce(union).unwrap_or(scene);
    // (each face's box inline, in 32 bits: grid points are)
    let grid = CellGrid::of_items(small_box, &small)
        .packed(|i| (i, narrow(&boxes[i as usize]), hashes[i as usize]));
    let reaches: Vec<Reach> = occluders
        .par_iter()
        .map(|f| {
            [
                penumbra_box(lights, f.corners(), scene),
                umbra_box(lights, f.corners(), scene),
            ]
        })
        .collect();
    // per occluder the faces it may reach, then turned into per face the
    // occluders (in index order): four bytes a pair in each form, and each
    // occluder's list freed as it is turned. A face met by several parts'
    // boxes (or cells) is tested once: `seen` holds, per face, the last
    // occluder that tested it (one list per run of occluders a thread
    // takes), and a face's exact test does not depend on the part.
    let hits: Vec<Vec<u32>> = regions
        .par_iter()
        .enumerate()
        .map_init(
            || vec![u32::MAX; faces.len()],
            |seen, (j, r)| {
                let mut hit = Vec::new();
                if let Some(r) = r {
                    let reach = reaches[j][0];
                    let plane = plane_key(occluders[j].plane());
                    let hash = plane_hash(&plane);
                    let mut test = |i: u32, b: &Box3, h: u32| {
                        let last = &mut seen[i as usize];
                        if *last == j as u32 {
                            return;
                        }
                        *last = j as u32;
                        let f = i as usize;
                        // (the inline box first: the others read the face)
                        if overlap(b, &reach)
                            && (h != hash || planes[f] != plane)
                            && !outside(faces[f].corners(), &r.penumbra)
                        {
                            hit.push(i);
                        }
                    };
                    // the sweep in a few boxes: most faces in the whole box
                    // lie beside the volume where it is still narrow
                    let parts = penumbra_boxes(lights, occluders[j].corners(), scene, SWEEP_PARTS);
                    // the cells of the parts only (not of their whole box)
                    for part in &parts {
                        if overlap(part, &small_box) {
                            grid.visit(*part, |&(i, b, h)| {
                                let b = widen(&b);
                                if overlap(&b, part) {
                                    test(i, &b, h);
                                }
                            });
                        }
                        for (i, b) in &wide {
                            if overlap(b, part) {
                                test(*i, b, hashes[*i as usize]);
                            }
                        }
                    }
                    hit.shrink_to_fit();
                }
                hit
            },
        )
        .collect();
    let mut counts = vec![0usize; faces.len()];
    for &i in hits.iter().flatten() {
        counts[i as usize] += 1;
    }
    let mut near: Vec<Vec<u32>> = counts.into_iter().map(Vec::with_capacity).collect();
    for (j, hit) in hits.into_iter().enumerate() {
        for i in hit {
            near[i as usize].push(j as u32);
        }
    }
    (near, reaches)
}

/// A hash of a plane's key, in 32 bits: keys with other hashes differ.
fn plane_hash(key: &PlaneKey) -> u32 {
    use std::hash::{Hash, Hasher};
    let mut h = rustc_hash::FxHasher::default();
    key.hash(&mut h);
    h.finish() as u32
}

/// A box of grid points in 32 bits a coordinate.
type NarrowBox = [[i32; 2]; 3];

/// `b`, a box of grid points, in 32 bits a coordinate.
fn narrow(b: &Box3) -> NarrowBox {
    b.map(|r| r.map(|v| v as i32))
}

/// A box of [`narrow`] in 64 bits again.
fn widen(b: &NarrowBox) -> Box3 {
    b.map(|r| r.map(i64::from))
}

/// A box holding the part of occluder `o`'s umbra volume inside `scene`:
/// the umbra lies in the shadow volume from every light corner.
pub(crate) fn umbra_box(lights: &[Light], o: &[GridPoint], scene: Box3) -> Box3 {
    lights
        .iter()
        .map(|l| penumbra_box(std::slice::from_ref(l), o, scene))
        .fold(scene, |a, b| {
            [0, 1, 2].map(|k| [a[k][0].max(b[k][0]), a[k][1].min(b[k][1])])
        })
}

/// The box of every face's corners; `None` for no faces.
pub(crate) fn scene_box(faces: &[Occluder]) -> Option<Box3> {
    faces.iter().map(|f| grid_box(f.corners())).reduce(union)
}

/// Into how many boxes [`near_lists`] cuts an occluder's sweep. A slanted
/// sweep's box is as wide as its slope times its length: at bunny-99k
/// under a 1 × 1 light, 4 boxes let 28.1M face boxes through to the
/// exact test for 3.4M pairs kept, 16 boxes 10.2M (12, 16 and 24 gave
/// the same time; more boxes cost more cell visits than they save).
const SWEEP_PARTS: usize = 16;

/// Whether grid points `corners` lie in the closed outside of one of the
/// half-spaces `hs` (a face there has no area inside the volume).
pub(crate) fn outside(corners: &[GridPoint], hs: &HalfSpaces) -> bool {
    hs.iter()
        .any(|(h, inside)| corners.iter().all(|&c| h.classify_grid(c) != *inside))
}

/// A box holding the part of occluder `o`'s penumbra volume inside
/// `scene`, in exact integers. Every point of the volume is `o + t(o − l)`
/// for an occluder point `o`, a light point `l` and `t ≥ 0` (for a
/// direction `d`, `o − t d`), unless the light touches the occluder (then
/// it may be anywhere). With `D` the box of the vectors `o − l`, along an
/// axis on which `D` has one sign the point leaves the scene once `t`
/// passes a bound `T = num / den` (the least over such axes), and the
/// volume lies in `box(O) + [0, T]·D`, its bounds rounded outward.
fn penumbra_box(lights: &[Light], o: &[GridPoint], scene: Box3) -> Box3 {
    penumbra_boxes(lights, o, scene, 1)[0]
}

/// [`penumbra_box`] in `parts` boxes, one for each `t` in
/// `[T·k/parts, T·(k+1)/parts]`: near the occluder the volume is narrow,
/// and one box of the whole sweep is as wide there as the volume is where
/// it leaves the scene. Over such a range the point lies in
/// `box(O) + [t0, t1]·D`, whose bounds per axis are the least and most of
/// `t·d` at the range's ends and `D`'s (`t ≥ 0`).
fn penumbra_boxes(lights: &[Light], o: &[GridPoint], scene: Box3, parts: usize) -> Vec<Box3> {
    let ob = grid_box(o);
    let points: Vec<GridPoint> = lights.iter().filter_map(Light::point).collect();
    // a light point on the occluder's box: the volume may be anywhere
    if !points.is_empty() && overlap(&grid_box(&points), &ob) {
        return vec![scene];
    }
    let mut d = [[i64::MAX, i64::MIN]; 3];
    for l in lights {
        for k in 0..3 {
            let (a, b) = match l {
                Light::Point(p) => (ob[k][0] - i64::from(p[k]), ob[k][1] - i64::from(p[k])),
                Light::Directional(v) => (-i64::from(v[k]), -i64::from(v[k])),
            };
            d[k] = [d[k][0].min(a), d[k][1].max(b)];
        }
    }
    // T = num / den, den > 0; None: no bound
    let mut t: Option<(i128, i128)> = None;
    for k in 0..3 {
        let bound = if d[k][0] > 0 {
            Some((scene[k][1] - ob[k][0], d[k][0]))
        } else if d[k][1] < 0 {
            Some((ob[k][1] - scene[k][0], -d[k][1]))
        } else {
            None
        };
        if let Some((num, den)) = bound {
            let c = (i128::from(num.max(0)), i128::from(den));
            if t.is_none_or(|(n, m)| c.0 * m < n * c.1) {
                t = Some(c);
            }
        }
    }
    let Some((num, den)) = t else {
        return vec![scene];
    };
    // t from num·j / q to num·(j + 1) / q, q = den·parts
    let q = den * parts as i128;
    (0..parts as i128)
        .map(|j| {
            let b = [0, 1, 2].map(|k| {
                let ends = [num * j, num * (j + 1)];
                let lo = ends
                    .map(|e| e * i128::from(d[k][0]))
                    .into_iter()
                    .min()
                    .unwrap_or(0);
                let hi = ends
                    .map(|e| e * i128::from(d[k][1]))
                    .into_iter()
                    .max()
                    .unwrap_or(0);
                [
                    ob[k][0] + floor_ceil(lo, q).0 as i64,
                    ob[k][1] + floor_ceil(hi, q).1 as i64,
                ]
            });
            [0, 1, 2].map(|k| [b[k][0].max(scene[k][0]), b[k][1].min(scene[k][1])])
        })
        .collect()
}

/// What a slab holds of an occluder's penumbra volume ([`slab_box`]).
pub(crate) enum InSlab {
    /// None of it.
    Nothing,
    /// Its points there lie in this box.
    Within(Box3),
    /// It may hold points of the slab without bound (or the bound did
    /// not fit the arithmetic): no box.
    Unbounded,
}

/// A box holding the points of occluder `o`'s penumbra volume (see
/// [`penumbra_box`]) in the slab `|n·x + d| ≤ |n|_1` around `plane`, in
/// exact integers. The volume is `O + cone{o_i − l_j}` (occluder corners
/// `o_i`, light corners `l_j`; a direction `v` gives `−v`): a midpoint of
/// two of its points is one again, and `o' + t(o − l)` is
/// `(1 + t)·(o' + t o)/(1 + t) − t l`. Where `n` has one strict sign on
/// every `o_i − l_j`, the slab holds a bounded part of it, whose corners
/// are corners `o_i` in the slab and points where the rays
/// `o_i + t(o_i − l_j)` and the occluder's edges cross the slab's two
/// planes: the box of those, rounded outward.
pub(crate) fn slab_box(lights: &[Light], o: &[GridPoint], plane: &Plane) -> InSlab {
    let wide = |p: &GridPoint| p.map(i128::from);
    let n = plane.normal().map(i128::from);
    let d = plane.offset();
    let m: i128 = n.iter().map(|c| c.abs()).sum();
    let dot = |v: [i128; 3]| -> Option<i128> {
        n[0].checked_mul(v[0])?
            .checked_add(n[1].checked_mul(v[1])?)?
            .checked_add(n[2].checked_mul(v[2])?)
    };
    let mut rays = Vec::with_capacity(o.len() * lights.len());
    let mut sign = 0;
    for c in o {
        let c = wide(c);
        for l in lights {
            let r = match l {
                Light::Point(p) => [0, 1, 2].map(|k| c[k] - i128::from(p[k])),
                Light::Directional(v) => v.map(|x| -i128::from(x)),
            };
            let Some(nr) = dot(r) else {
                return InSlab::Unbounded;
            };
            if nr == 0 || (sign != 0 && nr.signum() != sign) {
                return InSlab::Unbounded;
            }
            sign = nr.signum();
            rays.push((c, r, nr));
        }
    }
    let mut b = [[i64::MAX, i64::MIN]; 3];
    let mut any = false;
    // the point c + r·num/den (den ≠ 0), its coordinates rounded outward
    let mut add = |c: [i128; 3], r: [i128; 3], num: i128, den: i128| -> Option<()> {
        let (num, den) = if den < 0 { (-num, -den) } else { (num, den) };
        for k in 0..3 {
            let x = c[k].checked_mul(den)?.checked_add(r[k].checked_mul(num)?)?;
            let (lo, hi) = floor_ceil(x, den);
            let (lo, hi) = (i64::try_from(lo).ok()?, i64::try_from(hi).ok()?);
            b[k] = [b[k][0].min(lo), b[k][1].max(hi)];
        }
        any = true;
        Some(())
    };
    let value = |c: [i128; 3]| dot(c).and_then(|v| v.checked_add(d));
    for (i, c) in o.iter().enumerate() {
        let c = wide(c);
        let Some(vc) = value(c) else {
            return InSlab::Unbounded;
        };
        if vc.abs() <= m && add(c, [0; 3], 0, 1).is_none() {
            return InSlab::Unbounded;
        }
        let e = [0, 1, 2].map(|k| i128::from(o[(i + 1) % o.len()][k]) - c[k]);
        for level in [-m, m] {
            // the edge c + s·e, 0 ≤ s ≤ 1, and the level's plane
            let (Some(ne), num) = (dot(e), level - vc) else {
                return InSlab::Unbounded;
            };
            let on_edge = ne != 0 && num.signum() * ne.signum() >= 0 && num.abs() <= ne.abs();
            if on_edge && add(c, e, num, ne).is_none() {
                return InSlab::Unbounded;
            }
        }
    }
    for &(c, r, nr) in &rays {
        let Some(vc) = value(c) else {
            return InSlab::Unbounded;
        };
        for level in [-m, m] {
            // the ray c + t·r, t ≥ 0, and the level's plane
            let num = level - vc;
            if num.signum() * nr.signum() >= 0 && add(c, r, num, nr).is_none() {
                return InSlab::Unbounded;
            }
        }
    }
    if any {
        InSlab::Within(b)
    } else {
        InSlab::Nothing
    }
}

/// `⌊x / den⌋` and `⌈x / den⌉` for `den > 0`, by one division (a
/// hardware one where both fit in 64 bits; `i128`'s `div_euclid` pairs
/// are library calls, two for each rounding).
#[inline]
fn floor_ceil(x: i128, den: i128) -> (i128, i128) {
    debug_assert!(den > 0);
    let (q, r) = match (i64::try_from(x), i64::try_from(den)) {
        (Ok(x), Ok(den)) => (i128::from(x / den), i128::from(x % den)),
        _ => {
            let q = x / den;
            (q, x - q * den)
        }
    };
    (q - i128::from(r < 0), q + i128::from(r > 0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn plane_z(z: i32) -> Plane {
        Plane::through([0, 0, z], [1, 0, z], [0, 1, z]).unwrap()
    }

    proptest! {
        #[test]
        fn floor_and_ceil_by_one_division_round_as_div_euclid(
            x in (i128::MIN + 1)..=i128::MAX,
            den in 1..i128::MAX,
            small in any::<i64>(),
            small_den in 1..i64::MAX,
        ) {
            for (x, den) in [(x, den), (i128::from(small), i128::from(small_den)), (x, i128::from(small_den))] {
                prop_assert_eq!(floor_ceil(x, den), (x.div_euclid(den), -(-x).div_euclid(den)));
            }
        }
    }

    #[test]
    fn a_slab_under_a_square_holds_its_shadow() {
        let square = [[-1, -1, 10], [1, -1, 10], [1, 1, 10], [-1, 1, 10]];
        // the slab |z| <= 1: the shadow spreads from 2 (z = 0) to 2.1
        // (z = -1) half-widths, rounded outward
        let InSlab::Within(b) = slab_box(&[Light::Point([0, 0, 20])], &square, &plane_z(0)) else {
            panic!("bounded");
        };
        assert_eq!(b, [[-3, 3], [-3, 3], [-1, 1]]);
        // above the light's height nothing; a light level with the
        // occluder's corners gives rays along the slab: no bound
        let high = slab_box(&[Light::Point([0, 0, 20])], &square, &plane_z(30));
        assert!(matches!(high, InSlab::Nothing));
        let level = slab_box(&[Light::Point([5, 0, 10])], &square, &plane_z(0));
        assert!(matches!(level, InSlab::Unbounded));
        // a sun straight above: the square's prism
        let InSlab::Within(b) = slab_box(&[Light::Directional([0, 0, 1])], &square, &plane_z(0))
        else {
            panic!("bounded");
        };
        assert_eq!(b, [[-1, 1], [-1, 1], [-1, 1]]);
    }

    fn point() -> impl Strategy<Value = GridPoint> {
        prop::array::uniform3(-60i32..60)
    }

    /// The points `light` as point lights, or (`sun`) as directions toward
    /// suns; `None` where a direction is zero.
    fn lights_of(light: &[GridPoint], sun: bool) -> Option<Vec<Light>> {
        if sun && light.contains(&[0, 0, 0]) {
            return None;
        }
        let kind = |p| {
            if sun {
                Light::Directional(p)
            } else {
                Light::Point(p)
            }
        };
        Some(light.iter().map(|&p| kind(p)).collect())
    }

    /// A sample `(a, b, t1, t2)` of the volume of `occluder` under the
    /// light points (or, `sun`, directions toward the light) `light`, as
    /// `num / den`: `o = Σa·o_i / Σa` and `l = Σb·l_j / Σb`; for a point
    /// light `p = ((t2 + t1)·o − t1·l) / t2`, for a sun `p = o − (t1 / t2)·l`.
    /// `None` for zero weights.
    fn volume_point(
        occluder: &[GridPoint; 3],
        light: &[GridPoint],
        sun: bool,
        (a, b, t1, t2): &([i128; 3], Vec<i128>, i128, i128),
    ) -> Option<([i128; 3], i128)> {
        let b = &b[..light.len()];
        let (sa, sb): (i128, i128) = (a.iter().sum(), b.iter().sum());
        if sa == 0 || sb == 0 {
            return None;
        }
        let num = [0, 1, 2].map(|k| {
            let o: i128 = (0..3).map(|i| a[i] * i128::from(occluder[i][k])).sum();
            let l: i128 = (0..light.len())
                .map(|j| b[j] * i128::from(light[j][k]))
                .sum();
            if sun {
                t2 * sb * o - t1 * sa * l
            } else {
                (t2 + t1) * sb * o - t1 * sa * l
            }
        });
        Some((num, t2 * sa * sb))
    }

    proptest! {
        /// Every point `o + t(o − l)` of the volume inside the scene lies
        /// in one of the sweep's boxes, and they all in the whole sweep's.
        #[test]
        fn the_sweep_boxes_hold_the_volume(
            occluder in prop::array::uniform3(point()),
            light in prop::collection::vec(point(), 1..4),
            sun in any::<bool>(),
            parts in 1usize..6,
            samples in prop::collection::vec(
                (prop::array::uniform3(0i128..4), prop::collection::vec(0i128..4, 4), 0i128..400, 1i128..8),
                64,
            ),
        ) {
            let Some(lights) = lights_of(&light, sun) else {
                return Ok(());
            };
            let scene = [[-100, 100]; 3];
            let boxes = penumbra_boxes(&lights, &occluder, scene, parts);
            let whole = penumbra_box(&lights, &occluder, scene);
            for b in &boxes {
                for k in 0..3 {
                    prop_assert!(b[k][0] > b[k][1] || (whole[k][0] <= b[k][0] && b[k][1] <= whole[k][1]));
                }
            }
            for sample in &samples {
                let Some((num, den)) = volume_point(&occluder, &light, sun, sample) else {
                    continue;
                };
                let inside = |bx: &Box3| {
                    (0..3).all(|k| {
                        i128::from(bx[k][0]) * den <= num[k] && num[k] <= i128::from(bx[k][1]) * den
                    })
                };
                if !inside(&scene) {
                    continue;
                }
                prop_assert!(boxes.iter().any(inside), "{num:?} / {den} in none of {boxes:?}");
            }
        }

        /// Every point `o + t(o − l)` of the volume (rational `o`, `l`,
        /// `t`) within the slab lies in its box.
        #[test]
        fn the_box_holds_the_volume_in_the_slab(
            occluder in prop::array::uniform3(point()),
            light in prop::collection::vec(point(), 1..4),
            sun in any::<bool>(),
            plane in prop::array::uniform3(point()),
            samples in prop::collection::vec(
                (prop::array::uniform3(0i128..4), prop::collection::vec(0i128..4, 4), 0i128..40, 1i128..8),
                64,
            ),
        ) {
            let Ok(plane) = Plane::through(plane[0], plane[1], plane[2]) else {
                return Ok(());
            };
            let Some(lights) = lights_of(&light, sun) else {
                return Ok(());
            };
            let found = slab_box(&lights, &occluder, &plane);
            let n = plane.normal().map(i128::from);
            let m: i128 = n.iter().map(|c| c.abs()).sum();
            for sample in &samples {
                let Some((num, den)) = volume_point(&occluder, &light, sun, sample) else {
                    continue;
                };
                let value = (0..3).map(|k| n[k] * num[k]).sum::<i128>() + plane.offset() * den;
                if value.abs() > m * den {
                    continue;
                }
                match &found {
                    InSlab::Nothing => prop_assert!(false, "a point in the slab, none found"),
                    InSlab::Unbounded => {}
                    InSlab::Within(bx) => {
                        for k in 0..3 {
                            prop_assert!(i128::from(bx[k][0]) * den <= num[k]);
                            prop_assert!(num[k] <= i128::from(bx[k][1]) * den);
                        }
                    }
                }
            }
        }
    }
}
