//! Built-in scenes generated in code.
//!
//! All scenes are z-up, in metres, and made of closed solids whose faces
//! are convex and counter-clockwise seen from outside (quads stay quads,
//! n-gons stay n-gons). Coordinates lie on a `2^-10` m design grid, so the
//! faces are exactly planar; see the `prim` module.

use glam::DVec3;

use crate::prim::{Axis, Builder, SQUARE, q, regular};
use crate::{Mesh, ROOM_EYE, ROOM_LIGHT, ROOM_TARGET};

/// Names accepted by [`scene`].
pub const SCENE_NAMES: &[&str] = &[
    "room",
    "chair",
    "cube",
    "bunny",
    "bunny-11k",
    "bunny-33k",
    "bunny-99k",
    "bunny-298k",
    "bunny-893k",
    "city",
    "city-100k",
];

/// The built-in scene `name`, or an error naming the scenes there are.
pub fn scene_named(name: &str) -> Result<Mesh, String> {
    scene(name).ok_or_else(|| {
        format!(
            "unknown scene `{name}` (available: {})",
            SCENE_NAMES.join(", ")
        )
    })
}

/// A built-in scene by name (see [`SCENE_NAMES`]): `"room"` is [`room`],
/// `"chair"` one swivel chair of the room standing at the origin, `"cube"`
/// the unit cube `[0, 1]³`, `"bunny"` the Stanford bunny (3 674 faces) on
/// a ground quad, and `"bunny-11k"` to `"bunny-893k"` the same refined by
/// one to five √3-subdivisions ([`crate::bunny`]) to 11 022 to 892 782
/// faces; `"city"` a block of sixteen buildings on a ground of 2 m tiles
/// ([`crate::city_block`], 3,703 faces) and `"city-100k"` the same on
/// 0.38 m tiles (99,959 faces), for sun studies.
///
/// ```
/// for name in ["room", "chair", "cube", "bunny"] {
///     let mesh = shadow_scene::scene(name).unwrap();
///     assert!(!mesh.faces.is_empty());
/// }
/// assert!(shadow_scene::scene("kitchen").is_none());
/// ```
pub fn scene(name: &str) -> Option<Mesh> {
    match name {
        "room" => Some(room()),
        "chair" => {
            let mut b = Builder::new();
            swivel_chair(&mut b, DVec3::ZERO, 0.0);
            Some(b.finish())
        }
        "cube" => {
            let mut b = Builder::new();
            b.group("cube").cuboid(DVec3::ZERO, DVec3::ONE);
            Some(b.finish())
        }
        "bunny" => crate::bunny(0),
        "bunny-11k" => crate::bunny(1),
        "bunny-33k" => crate::bunny(2),
        "bunny-99k" => crate::bunny(3),
        "bunny-298k" => crate::bunny(4),
        "bunny-893k" => crate::bunny(5),
        "city" => Some(crate::city_block(60)),
        "city-100k" => Some(crate::city_block(316)),
        _ => None,
    }
}

/// Where a built-in scene is seen from and lit from by default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Staging {
    /// The default eye.
    pub eye: DVec3,
    /// The point the default eye looks at.
    pub target: DVec3,
    /// The default up direction; `None`: the camera's own default (`+z`).
    pub up: Option<DVec3>,
    /// The default point light.
    pub light: DVec3,
}

/// The room's staging: [`ROOM_EYE`] looking at [`ROOM_TARGET`], `+z` up,
/// under [`ROOM_LIGHT`].
pub const ROOM_STAGING: Staging = Staging {
    eye: ROOM_EYE,
    target: ROOM_TARGET,
    up: None,
    light: ROOM_LIGHT,
};

impl Staging {
    /// The staging of built-in scene `name` (see [`SCENE_NAMES`]) whose
    /// mesh spans `bounds` (`lo`, `hi`): for the room [`ROOM_EYE`] looking
    /// at [`ROOM_TARGET`] under [`ROOM_LIGHT`]; for the bunnies (`y` up) a
    /// three-quarter view from the front, above and to the side, and a
    /// light above and in front; `None` for the other scenes.
    ///
    /// ```
    /// let room = shadow_scene::room();
    /// let s = shadow_scene::Staging::of_scene("room", room.bounds().unwrap()).unwrap();
    /// assert_eq!(s.eye, shadow_scene::ROOM_EYE);
    /// assert!(shadow_scene::Staging::of_scene("cube", (glam::DVec3::ZERO, glam::DVec3::ONE)).is_none());
    /// ```
    pub fn of_scene(name: &str, (lo, hi): (DVec3, DVec3)) -> Option<Staging> {
        let (c, half) = ((lo + hi) * 0.5, (hi - lo).max_element() * 0.5);
        match name {
            "room" => Some(ROOM_STAGING),
            _ if name.starts_with("bunny") => Some(Staging {
                eye: c + DVec3::new(0.75, 0.6, 1.7) * half,
                target: c - DVec3::Y * 0.25 * half,
                up: Some(DVec3::Y),
                light: c + DVec3::new(0.4, 1.6, 0.6) * half,
            }),
            _ => None,
        }
    }

    /// A view of `points` (a mesh's positions) with `up` (a unit axis,
    /// such as `+z`, or `+y` for most scans) pointing up: a three-quarter
    /// view from the front, to the right and above, from the nearest
    /// distance at which every point lies inside a picture of vertical
    /// field of view `fov_deg` and width / height `aspect` (with a 4%
    /// margin), the points centred in it; and a light above, in front and
    /// to the left, three bounding-sphere radii from the centre of their
    /// box (outside every face). "Front" is `-y` for `z` up, `+z` for `y`
    /// up and `+y` for `x` up (the way scans usually face). `None` without
    /// points.
    ///
    /// ```
    /// use glam::DVec3;
    /// let cube = shadow_scene::scene("cube").unwrap();
    /// let s = shadow_scene::Staging::framing(&cube.positions, DVec3::Z, 50.0, 4.0 / 3.0).unwrap();
    /// assert!(s.target.cmpge(DVec3::ZERO).all() && s.target.cmple(DVec3::ONE).all());
    /// assert!(s.eye.z > 1.0 && s.eye.y < 0.0 && s.light.z > 1.0);
    /// assert_eq!(s.up, Some(DVec3::Z));
    /// ```
    pub fn framing(points: &[DVec3], up: DVec3, fov_deg: f64, aspect: f64) -> Option<Staging> {
        let (lo, hi) = points.iter().fold(None, |b: Option<(DVec3, DVec3)>, &p| {
            Some(b.map_or((p, p), |(lo, hi)| (lo.min(p), hi.max(p))))
        })?;
        let up = up.try_normalize().unwrap_or(DVec3::Z);
        let c = (lo + hi) * 0.5;
        let r = (0.5 * (hi - lo).length()).max(f64::MIN_POSITIVE);
        let a = up.abs();
        let front = if a.z >= a.x && a.z >= a.y {
            -DVec3::Y
        } else if a.y >= a.x {
            DVec3::Z
        } else {
            DVec3::Y
        };
        let side = up.cross(front);
        let dir = (0.55 * side + front + 0.6 * up).normalize();
        // the camera's axes, looking along -dir
        let right = (-dir).cross(up).normalize();
        let cam_up = right.cross(-dir);
        let tan_v = (0.5 * fov_deg).to_radians().tan();
        let tan_h = tan_v * aspect.max(1e-3);
        // the nearest distance from `t` along `dir` that shows every point
        let fit = |t: DVec3| {
            points.iter().fold(0.0_f64, |dist, &p| {
                let d = p - t;
                // the point is seen at depth dist + behind
                let behind = -d.dot(dir);
                let need_h = d.dot(right).abs() / tan_h - behind;
                let need_v = d.dot(cam_up).abs() / tan_v - behind;
                dist.max(need_h).max(need_v).max(r * 1e-3 - behind)
            })
        };
        // centre the points' picture: move the target across the view by
        // the middle of their extent, then fit again
        let dist = fit(c);
        let (mut u, mut v) = ((f64::MAX, f64::MIN), (f64::MAX, f64::MIN));
        for &p in points {
            let d = p - c;
            let depth = dist - d.dot(dir);
            let (x, y) = (d.dot(right) / depth, d.dot(cam_up) / depth);
            u = (u.0.min(x), u.1.max(x));
            v = (v.0.min(y), v.1.max(y));
        }
        let target = c + (right * (u.0 + u.1) + cam_up * (v.0 + v.1)) * (0.5 * dist);
        let dist = fit(target);
        Some(Staging {
            eye: target + dir * (1.04 * dist).max(f64::MIN_POSITIVE),
            target,
            up: Some(up),
            light: c + (-0.4 * side + 0.5 * front + up).normalize() * 3.0 * r,
        })
    }
}

/// The test room of Liu & Wu's real-time shadow paper, rebuilt in code.
///
/// A 7 m × 5 m floor with a back, a left and a right wall 2.6 m high
/// (open toward the viewer at `y = -2.5`), two swivel chairs, a bookshelf
/// with books on three shelves, a flower pot with a plant, a rug, and a
/// coordinate-axis object on a pedestal in the middle of the room: x, y
/// and z arrows 1.1 m long from a small cube around `(0, 0, 0.12)`.
///
/// Groups: `floor`, `walls`, `rug`, `chair` (upholstery), `chair_frame`
/// (column, star base, backrest support), `bookshelf`, `books`, `pot`,
/// `soil`, `plant`, `flower`, `decor`, `axes`. The axis object is its own group, `axes`, so it
/// can be moved with [`Mesh::translate_group`]. Vertices are shared within
/// a group, never across groups.
///
/// ```
/// let room = shadow_scene::room();
/// assert!((300..=520).contains(&room.faces.len()));
/// let (lo, hi) = room.bounds().unwrap();
/// assert!(lo.z < 0.0 && hi.z > 2.5);
/// ```
pub fn room() -> Mesh {
    build_room().finish()
}

/// Half the room's width (x), its front and back (y), and the wall height.
const HALF_WIDTH: f64 = 3.5;
const FRONT: f64 = -2.5;
const BACK: f64 = 2.5;
const WALL_HEIGHT: f64 = 2.6;
const WALL: f64 = 0.1;

fn build_room() -> Builder {
    let mut b = Builder::new();
    let v = DVec3::new;
    let (x0, x1) = (-HALF_WIDTH, HALF_WIDTH);

    // floor slab (its top is z = 0) and walls standing on it
    b.group("floor")
        .cuboid(v(x0 - WALL, FRONT, -WALL), v(x1 + WALL, BACK + WALL, 0.0));
    b.group("walls")
        .cuboid(
            v(x0 - WALL, BACK, 0.0),
            v(x1 + WALL, BACK + WALL, WALL_HEIGHT),
        )
        .cuboid(v(x0 - WALL, FRONT, 0.0), v(x0, BACK, WALL_HEIGHT))
        .cuboid(v(x1, FRONT, 0.0), v(x1 + WALL, BACK, WALL_HEIGHT));
    b.group("rug").cuboid(v(-1.3, -1.0, 0.0), v(1.3, 1.0, 0.01));

    bookshelf(&mut b, v(1.2, BACK - 0.375, 0.0));
    swivel_chair(&mut b, v(-1.9, -0.2, 0.0), 40.0);
    swivel_chair(&mut b, v(2.0, -1.1, 0.0), -60.0);
    flower_pot(&mut b, v(-2.85, 1.95, 0.0));
    axis_object(&mut b, v(0.0, 0.0, 0.01));
    b
}

/// A five-legged swivel chair standing at `at` (on the floor), its front
/// turned `yaw_deg` degrees counter-clockwise from `-y`.
fn swivel_chair(b: &mut Builder, at: DVec3, yaw_deg: f64) {
    let (s, c) = yaw_deg.to_radians().sin_cos();
    // local frame: the seat faces -y, the backrest is at +y
    let dir = |x: f64, y: f64, z: f64| DVec3::new(c * x - s * y, s * x + c * y, z);
    let pt = |x: f64, y: f64, z: f64| at + dir(x, y, z);

    b.group("chair_frame");
    for k in 0..5 {
        let a = (yaw_deg + 90.0 + 72.0 * k as f64).to_radians();
        let out = DVec3::new(a.cos(), a.sin(), 0.0);
        let side = DVec3::new(-a.sin(), a.cos(), 0.0);
        b.parallelepiped(
            at + out * 0.03 - side * 0.02 + DVec3::Z * 0.07,
            out * 0.31 - DVec3::Z * 0.06,
            side * 0.04,
            DVec3::Z * 0.035,
        );
    }
    let hex = regular(6, yaw_deg);
    let hub: Vec<DVec3> = hex
        .iter()
        .map(|c| at + DVec3::new(c[0] * 0.07, c[1] * 0.07, 0.06))
        .collect();
    b.frustum(&hub, DVec3::Z * 0.06, 0.75)
        .lathe(
            at + DVec3::Z * 0.12,
            Axis::Z,
            &[(0.028, 0.0), (0.028, 0.28)],
            &hex,
        )
        .parallelepiped(
            pt(-0.1, -0.1, 0.40),
            dir(0.2, 0.0, 0.0),
            dir(0.0, 0.2, 0.0),
            dir(0.0, 0.0, 0.04),
        )
        // backrest support: from under the seat's back edge, rising backwards
        .parallelepiped(
            pt(-0.03, 0.25, 0.40),
            dir(0.06, 0.0, 0.0),
            dir(0.0, 0.04, 0.0),
            dir(0.0, 0.05, 0.34),
        );

    b.group("chair")
        .parallelepiped(
            pt(-0.25, -0.24, 0.44),
            dir(0.5, 0.0, 0.0),
            dir(0.0, 0.48, 0.0),
            dir(0.0, 0.0, 0.08),
        )
        // backrest, leaning back by about 11 degrees
        .parallelepiped(
            pt(-0.23, 0.27, 0.60),
            dir(0.46, 0.0, 0.0),
            dir(0.0, 0.06, 0.0),
            dir(0.0, 0.10, 0.52),
        );
}

/// A book standing upright: thickness, height, depth.
type Book = (f64, f64, f64);

/// A bookshelf against the back wall, its front-left-bottom corner at
/// `at`, with books on three shelves.
fn bookshelf(b: &mut Builder, at: DVec3) {
    let v = DVec3::new;
    let (w, d, h, side, back) = (0.9, 0.37, 1.9, 0.03, 0.015);
    let (x0, x1, y0, y1) = (at.x, at.x + w, at.y, at.y + d);
    let (xi0, xi1) = (x0 + side, x1 - side);
    b.group("bookshelf")
        .cuboid(v(x0, y0, 0.0), v(xi0, y1, h))
        .cuboid(v(xi1, y0, 0.0), v(x1, y1, h))
        .cuboid(v(xi0, y1 - back, 0.0), v(xi1, y1, h))
        .cuboid(v(xi0, y0, 0.0), v(xi1, y1 - back, 0.08))
        .cuboid(v(x0 - 0.01, y0 - 0.01, h), v(x1 + 0.01, y1, h + 0.03));
    let shelves = [0.52, 0.96, 1.40];
    for z in shelves {
        b.cuboid(v(xi0, y0 + 0.01, z), v(xi1, y1 - back, z + 0.025));
    }

    // books: (thickness, height, depth) per row, left to right
    let rows: [(f64, &[Book]); 3] = [
        (
            0.08,
            &[
                (0.075, 0.34, 0.25),
                (0.06, 0.36, 0.26),
                (0.085, 0.31, 0.24),
                (0.07, 0.33, 0.25),
                (0.055, 0.30, 0.23),
                (0.08, 0.35, 0.26),
                (0.065, 0.32, 0.24),
            ],
        ),
        (
            0.545,
            &[
                (0.05, 0.27, 0.21),
                (0.065, 0.30, 0.22),
                (0.045, 0.25, 0.20),
                (0.06, 0.29, 0.21),
                (0.055, 0.26, 0.20),
                (0.07, 0.28, 0.22),
            ],
        ),
        (
            0.985,
            &[
                (0.06, 0.28, 0.22),
                (0.05, 0.24, 0.20),
                (0.07, 0.26, 0.21),
                (0.055, 0.25, 0.20),
            ],
        ),
    ];
    b.group("books");
    let y_back = y1 - back - 0.01;
    for (z, books) in rows {
        let mut x = xi0 + 0.01;
        for &(t, bh, bd) in books {
            b.cuboid(v(x, y_back - bd, z), v(x + t, y_back, z + bh));
            x += t + 0.006;
        }
    }
    // one book leaning against the right side in the middle row: it rests
    // on its bottom right edge and touches the side with its top corner
    let (t, bh, bd, tilt) = (0.055, 0.27, 0.20, 20f64.to_radians());
    let (sn, cs) = tilt.sin_cos();
    let across = v(t * cs, 0.0, -t * sn);
    let up = v(bh * sn, 0.0, bh * cs);
    let x_left = xi1 - 0.003 - across.x - up.x;
    b.parallelepiped(
        v(x_left, y_back - bd, 0.545 + t * sn),
        across,
        v(0.0, bd, 0.0),
        up,
    );
    // a small stone pyramid on top
    let corner = v(x0 + 0.1, y0 + 0.06, h + 0.03);
    let base = [
        v(0.0, 0.0, 0.0),
        v(0.16, 0.0, 0.0),
        v(0.16, 0.16, 0.0),
        v(0.0, 0.16, 0.0),
    ];
    b.group("decor")
        .pyramid(&base.map(|p| corner + p), corner + v(0.08, 0.08, 0.14));
    b.group("books");
    // a short stack lying flat on the top shelf
    let mut z = 1.425;
    for (bw, bt, bd) in [(0.30, 0.045, 0.23), (0.26, 0.04, 0.21)] {
        b.cuboid(
            v(xi1 - 0.02 - bw, y_back - bd, z),
            v(xi1 - 0.02, y_back, z + bt),
        );
        z += bt;
    }
}

/// A flower pot with soil and a plant standing on the floor at `at`.
fn flower_pot(b: &mut Builder, at: DVec3) {
    let oct = regular(8, 22.5);
    b.group("pot").lathe(
        at,
        Axis::Z,
        &[(0.15, 0.0), (0.2, 0.36), (0.225, 0.36), (0.225, 0.42)],
        &oct,
    );
    let soil: Vec<DVec3> = oct
        .iter()
        .map(|c| at + DVec3::new(c[0] * 0.195, c[1] * 0.195, 0.42))
        .collect();
    b.group("soil").prism(&soil, DVec3::Z * 0.015);
    b.group("plant")
        .lathe(at, Axis::Z, &[(0.015, 0.435), (0.015, 1.3)], &SQUARE);
    // leaves around the stem, turning by the golden angle
    for k in 0..6 {
        let a = (k as f64 * 137.5 + 20.0).to_radians();
        let z = 0.62 + 0.11 * k as f64;
        let len = 0.5 - 0.045 * k as f64;
        let rise = (25.0 + 6.0 * k as f64).to_radians();
        let out = DVec3::new(a.cos() * rise.cos(), a.sin() * rise.cos(), rise.sin());
        let side = DVec3::new(-a.sin(), a.cos(), 0.0);
        let normal = out.cross(side);
        let base = at + DVec3::new(a.cos() * 0.015, a.sin() * 0.015, z);
        let tip = base + out * len;
        let mid = base + out * (len * 0.4);
        let width = q(0.095 - 0.008 * k as f64);
        b.bipyramid(
            &[base, mid - side * width, tip, mid + side * width],
            mid + normal * 0.01,
            mid - normal * 0.01,
        );
    }
    // a flower on top
    let top = at + DVec3::Z * 1.3;
    let petals: Vec<DVec3> = regular(6, 0.0)
        .iter()
        .map(|c| top + DVec3::new(c[0], c[1], 0.0) * 0.09)
        .collect();
    b.group("flower")
        .bipyramid(&petals, top + DVec3::Z * 0.06, top - DVec3::Z * 0.03);
}

/// A coordinate-axis object whose pedestal stands at `at`: x, y and z
/// arrows (square shafts, pyramid heads) from a small cube.
fn axis_object(b: &mut Builder, at: DVec3) {
    let v = DVec3::new;
    b.group("axes")
        .cuboid(at + v(-0.2, -0.2, 0.0), at + v(0.2, 0.2, 0.06))
        .cuboid(at + v(-0.05, -0.05, 0.06), at + v(0.05, 0.05, 0.16));
    let origin = at + v(0.0, 0.0, 0.11);
    let arrow = [(0.02, 0.0), (0.02, 0.86), (0.055, 0.86), (0.0, 1.1)];
    b.lathe(origin + v(0.05, 0.0, 0.0), Axis::X, &arrow, &SQUARE)
        .lathe(origin + v(0.0, 0.05, 0.0), Axis::Y, &arrow, &SQUARE)
        .lathe(origin + v(0.0, 0.0, 0.05), Axis::Z, &arrow, &SQUARE);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prim::tests::check_part;

    #[test]
    fn every_part_is_closed_outward_planar_and_convex() {
        let b = build_room();
        let parts = b.parts().to_vec();
        let mesh = b.finish();
        assert_eq!(parts.last().unwrap().end, mesh.faces.len());
        for p in parts {
            check_part(&mesh, p.clone()).unwrap_or_else(|e| panic!("part {p:?}: {e}"));
        }
    }

    #[test]
    fn room_has_the_named_groups_and_a_few_hundred_faces() {
        let room = room();
        for g in [
            "floor",
            "walls",
            "rug",
            "chair",
            "chair_frame",
            "bookshelf",
            "books",
            "pot",
            "soil",
            "plant",
            "flower",
            "decor",
            "axes",
        ] {
            let i = room
                .group_index(g)
                .unwrap_or_else(|| panic!("no group {g}"));
            assert!(
                room.faces.iter().any(|f| f.group == i),
                "group {g} is empty"
            );
        }
        assert!(
            (300..=520).contains(&room.faces.len()),
            "{}",
            room.faces.len()
        );
        assert!(
            room.faces.iter().any(|f| f.vertices.len() == 8),
            "octagons stay whole"
        );
        assert!(room.faces.iter().all(|f| f.line == 0));
    }

    #[test]
    fn room_is_a_union_of_closed_solids() {
        // vertices are never shared across groups, so a group whose solids
        // do not share edges (walls and bookshelf boards do) is closed on
        // its own; the axis object, moved later, must be
        let room = room();
        for g in [
            "axes",
            "chair",
            "chair_frame",
            "pot",
            "soil",
            "floor",
            "rug",
            "decor",
        ] {
            let gi = room.group_index(g).unwrap();
            let part = Mesh {
                positions: room.positions.clone(),
                faces: room
                    .faces
                    .iter()
                    .filter(|f| f.group == gi)
                    .cloned()
                    .collect(),
                groups: room.groups.clone(),
            };
            assert!(part.is_closed_oriented(), "group {g}");
            assert!(part.signed_volume() > 0.0, "group {g}");
        }
    }

    #[test]
    fn axes_point_along_x_y_z_from_the_middle() {
        let room = room();
        let gi = room.group_index("axes").unwrap();
        let pts: Vec<DVec3> = room
            .faces
            .iter()
            .filter(|f| f.group == gi)
            .flat_map(|f| f.vertices.iter().map(|&v| room.positions[v as usize]))
            .collect();
        let max = pts.iter().fold(DVec3::splat(f64::MIN), |m, p| m.max(*p));
        let near = |a: DVec3, b: DVec3| (a - b).abs().max_element() < 2e-3;
        assert!(near(max, DVec3::new(1.15, 1.15, 1.27)), "{max}");
        for tip in [
            DVec3::new(1.15, 0.0, 0.12),
            DVec3::new(0.0, 1.15, 0.12),
            DVec3::new(0.0, 0.0, 1.27),
        ] {
            assert!(pts.iter().any(|p| near(*p, tip)), "no tip at {tip}");
        }
    }

    #[test]
    fn small_scenes() {
        let cube = scene("cube").unwrap();
        assert_eq!((cube.faces.len(), cube.positions.len()), (6, 8));
        assert!(cube.is_closed_oriented());
        let chair = scene("chair").unwrap();
        assert!(chair.is_closed_oriented());
        assert_eq!(chair.groups, vec!["chair_frame", "chair"]);
    }
}
