//! A view's cone as a closed mesh: the wanted region's triangles on the
//! receiving plane, the same triangles where the cone leaves the bounds
//! toward the light, and a wall along every boundary segment between.

use glam::DVec3;
use shadow_scene::{Face, Mesh};

use super::region::{Component, RegionError, region};
use super::{ArtLight, ArtView};

/// A mesh of triangles and quads, one group.
fn mesh(positions: Vec<DVec3>, faces: Vec<Vec<u32>>) -> Mesh {
    Mesh {
        positions,
        faces: faces
            .into_iter()
            .map(|vertices| Face {
                vertices,
                line: 0,
                group: 0,
            })
            .collect(),
        groups: vec!["default".into()],
    }
}

/// The box `[lo, hi]`, its faces turned outward.
pub(crate) fn cuboid(bounds: [DVec3; 2]) -> Mesh {
    let faces = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    mesh(corners(bounds).to_vec(), faces.map(|f| f.to_vec()).to_vec())
}

/// The corners of the box `[lo, hi]` (corner `i` takes `hi` along axis
/// `k` where bit `k` of `i` is set).
fn corners([lo, hi]: [DVec3; 2]) -> [DVec3; 8] {
    std::array::from_fn(|i| {
        DVec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    })
}

/// Where the cone of `view` ends toward the light.
enum End {
    /// Just beyond `bounds`: the map from a point of the plane to its end.
    Cap(Box<dyn Fn(DVec3) -> DVec3>),
    /// At the point light itself, which the bounds reach.
    Apex(DVec3),
}

/// Whether `view`'s light is a point light that `bounds` reach (a corner
/// of the box as far from the plane as the light, or farther): its cone
/// then ends at the light, and the hull may touch it.
pub(crate) fn reaches_light(view: &ArtView, bounds: [DVec3; 2]) -> bool {
    let ArtLight::Point(l) = view.light else {
        return false;
    };
    let n = view.plane.normal();
    let h = (view.plane.origin - l).dot(n);
    h != 0.0 && corners(bounds).iter().any(|&c| (c - l).dot(n) / h <= 0.0)
}

/// Where the cone of `view` ends toward the light: just beyond `bounds`,
/// or at a point light the bounds reach.
fn far_end(view: &ArtView, bounds: [DVec3; 2]) -> Result<End, String> {
    let pl = view.plane;
    let n = pl.normal();
    if n.length_squared() == 0.0 || !n.is_finite() {
        return Err("the plane's u and v are parallel (or zero): no pixel has an area".into());
    }
    let size = (bounds[1] - bounds[0]).length();
    match view.light {
        ArtLight::Sun(d) => {
            let dn = d.dot(n);
            if dn == 0.0 {
                return Err("the sun shines along the receiving plane".into());
            }
            // each box corner is `p + t·d` for a point p of the plane
            let t = corners(bounds)
                .iter()
                .map(|&c| (c - pl.origin).dot(n) / dn)
                .fold(f64::NEG_INFINITY, f64::max);
            if t <= 0.0 {
                return Err("the bounds lie behind the receiving plane, away from the sun".into());
            }
            let t = t + 0.01 * size / d.length();
            Ok(End::Cap(Box::new(move |p| p + d * t)))
        }
        ArtLight::Point(l) => {
            let h = (pl.origin - l).dot(n);
            if h == 0.0 {
                return Err("the point light lies on the receiving plane".into());
            }
            // each box corner at the fraction s of the way from the light
            // to the plane
            let s: Vec<f64> = corners(bounds)
                .iter()
                .map(|&c| (c - l).dot(n) / h)
                .collect();
            let (lo, hi) = s
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                    (a.min(x), b.max(x))
                });
            if hi <= 0.0 || lo >= 1.0 {
                return Err(
                    "the bounds lie behind the receiving plane, away from the light, or \
                     behind the light"
                        .into(),
                );
            }
            if lo <= 0.0 {
                return Ok(End::Apex(l));
            }
            let s = lo * 0.99;
            Ok(End::Cap(Box::new(move |p| l + (p - l) * s)))
        }
    }
}

/// The components of `view`'s wanted region, simplified within
/// `simplify` pixels if given; an error names the image.
pub(crate) fn wanted_region(
    view: &ArtView,
    simplify: Option<f64>,
) -> Result<Vec<Component>, String> {
    let parts = region(&view.mask, simplify).map_err(|e| match e {
        RegionError::TooLarge => format!(
            "{}: an image side above {} pixels",
            super::spec::name(&view.image),
            super::region::MAX_SIDE
        ),
        RegionError::Triangulation((c, r)) => format!(
            "{}: the wanted region at pixel ({c}, {r}) could not be triangulated",
            super::spec::name(&view.image)
        ),
    })?;
    if parts.is_empty() {
        return Err(format!(
            "{}: no pixel is darker than the threshold (no wanted shadow)",
            super::spec::name(&view.image)
        ));
    }
    Ok(parts)
}

/// The cone of `view` up to just beyond `bounds` (or up to a point light
/// the bounds reach), as a closed mesh (each component of the wanted
/// region a closed part; its faces turned outward), its region
/// simplified within `simplify` pixels if given.
pub(crate) fn cone(
    view: &ArtView,
    bounds: [DVec3; 2],
    simplify: Option<f64>,
) -> Result<Mesh, String> {
    let end = far_end(view, bounds)?;
    let parts = wanted_region(view, simplify)?;
    let (mut positions, mut faces) = (Vec::new(), Vec::new());
    for part in &parts {
        let base = positions.len() as u32;
        let n = part.corners.len() as u32;
        let near: Vec<DVec3> = (part.corners.iter())
            .map(|&[a, b]| view.plane.at(f64::from(a), f64::from(b)))
            .collect();
        match &end {
            End::Cap(end) => {
                // the ends toward the light, then the plane's corners
                positions.extend(near.iter().map(|&p| end(p)));
                positions.extend(near);
                let (far, near) = (|i: u32| base + i, |i: u32| base + n + i);
                for t in &part.triangles {
                    // (counter-clockwise in the plane's (a, b) coordinates)
                    faces.push(vec![near(t[0]), near(t[2]), near(t[1])]);
                    faces.push(vec![far(t[0]), far(t[1]), far(t[2])]);
                }
                for (i, j) in loop_edges(part) {
                    faces.push(vec![near(i), near(j), far(j)]);
                    faces.push(vec![near(i), far(j), far(i)]);
                }
            }
            End::Apex(light) => {
                positions.extend(near);
                let near = |i: u32| base + i;
                for t in &part.triangles {
                    faces.push(vec![near(t[0]), near(t[2]), near(t[1])]);
                }
                // each loop's walls meet at a copy of the light of their
                // own, so the mesh stays a manifold where they touch
                for range in part.loop_ranges() {
                    let apex = positions.len() as u32;
                    positions.push(*light);
                    let (s, e) = (range.start as u32, range.end as u32);
                    for i in s..e {
                        let j = if i + 1 == e { s } else { i + 1 };
                        faces.push(vec![near(i), near(j), apex]);
                    }
                }
            }
        }
    }
    let mut m = mesh(positions, faces);
    // turned outward: the plane's normal may face the light or away
    if signed_volume(&m) < 0.0 {
        for f in &mut m.faces {
            f.vertices.reverse();
        }
    }
    Ok(m)
}

/// The boundary segments `(i, j)` of a component's loops, as corner
/// indices.
fn loop_edges(part: &Component) -> impl Iterator<Item = (u32, u32)> + '_ {
    part.loop_ranges().flat_map(|range| {
        let (s, e) = (range.start as u32, range.end as u32);
        (s..e).map(move |i| (i, if i + 1 == e { s } else { i + 1 }))
    })
}

/// The signed volume of a closed triangle mesh (`f64`: only its sign is
/// read, and a cone is far from flat).
fn signed_volume(m: &Mesh) -> f64 {
    m.faces
        .iter()
        .map(|f| {
            let [a, b, c] = [0, 1, 2].map(|k| m.positions[f.vertices[k] as usize]);
            a.dot(b.cross(c))
        })
        .sum::<f64>()
        / 6.0
}
