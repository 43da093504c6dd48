//! Built-in animations: a static scene, an object that moves in it, the
//! object's default motion and a default light.

use glam::DVec3;

use crate::mesh::{Face, Mesh};

/// The room's default point light: just below the top of the walls, right
/// of the room's centre and a little behind it.
pub const ROOM_LIGHT: DVec3 = DVec3::new(0.9, 0.3, 2.45);

/// The room's default viewpoint: from the open front side of the room,
/// slightly above, looking at [`ROOM_TARGET`] (the whole room in view).
pub const ROOM_EYE: DVec3 = DVec3::new(3.3, -7.4, 4.3);

/// The point the room's default viewpoint looks at: its middle.
pub const ROOM_TARGET: DVec3 = DVec3::new(-0.15, 0.3, 0.45);

/// The bunny scenes' default point light: above and in front of the bunny.
pub const BUNNY_LIGHT: DVec3 = DVec3::new(4.0, 20.6, 5.9);

/// Names accepted by [`animated`].
pub const ANIMATED_NAMES: &[&str] = &[
    "room",
    "bunny",
    "bunny-11k",
    "bunny-33k",
    "bunny-99k",
    "bunny-298k",
    "bunny-893k",
];

/// A static scene and an object moving in it.
#[derive(Clone, Debug)]
pub struct Animated {
    /// What stays put.
    pub statics: Mesh,
    /// What moves (its coordinates as in frame 0).
    pub moving: Mesh,
    /// The default spin axis.
    pub axis: DVec3,
    /// The default spin per frame, in degrees.
    pub degrees: f64,
    /// The default centre of the spin; `None`: the centre of the moving
    /// object's bounding box.
    pub centre: Option<DVec3>,
    /// The default point light.
    pub light: DVec3,
}

/// A built-in animation by name (see [`ANIMATED_NAMES`]):
///
/// - `room`: the room of Liu & Wu's paper with its coordinate-axis object
///   (group `axes`) spinning about the vertical axis through its centre,
///   15° a frame, lit by [`ROOM_LIGHT`];
/// - `bunny`, `bunny-11k` ... `bunny-893k`: the scanned bunny on its
///   ground ([`crate::bunny`]) with a torus of 5 000 triangles circling it
///   at 7 units from its vertical axis (6° a frame), through the bunny's
///   shadow and under [`BUNNY_LIGHT`].
///
/// ```
/// let a = shadow_scene::animated("room").unwrap();
/// let room = shadow_scene::room();
/// assert_eq!(a.statics.faces.len() + a.moving.faces.len(), room.faces.len());
/// let b = shadow_scene::animated("bunny").unwrap();
/// assert_eq!(b.moving.faces.len(), 5000);
/// assert!(shadow_scene::animated("kitchen").is_none());
/// ```
pub fn animated(name: &str) -> Option<Animated> {
    if name == "room" {
        let (statics, moving) = crate::room().split_off_group("axes")?;
        return Some(Animated {
            statics,
            moving,
            axis: DVec3::Z,
            degrees: 15.0,
            centre: None,
            light: ROOM_LIGHT,
        });
    }
    let steps = match name {
        "bunny" => 0,
        "bunny-11k" => 1,
        "bunny-33k" => 2,
        "bunny-99k" => 3,
        "bunny-298k" => 4,
        "bunny-893k" => 5,
        _ => return None,
    };
    let statics = crate::bunny(steps)?;
    let (lo, hi) = statics.bounds()?;
    let c = (lo + hi) * 0.5;
    let ring = torus(
        DVec3::new(c.x + 7.0, lo.y + 2.5, c.z),
        DVec3::new(0.3, 1.0, 0.2),
        1.6,
        0.45,
        50,
        50,
    );
    Some(Animated {
        statics,
        moving: ring,
        axis: DVec3::Y,
        degrees: 6.0,
        centre: Some(DVec3::new(c.x, lo.y, c.z)),
        light: BUNNY_LIGHT,
    })
}

/// A torus of `2 nu nv` triangles (group `torus`) around `centre`, its
/// hole along `axis`: ring radius `major`, tube radius `minor`, `nu`
/// segments around the ring and `nv` around the tube. A closed,
/// outward-oriented surface.
///
/// ```
/// use glam::DVec3;
/// let t = shadow_scene::torus(DVec3::ZERO, DVec3::Z, 2.0, 0.5, 8, 6);
/// assert_eq!(t.faces.len(), 96);
/// assert!(t.is_closed_oriented());
/// assert!(t.signed_volume() > 0.0);
/// ```
pub fn torus(centre: DVec3, axis: DVec3, major: f64, minor: f64, nu: u32, nv: u32) -> Mesh {
    let w = axis.normalize_or(DVec3::Z);
    let u = w.any_orthonormal_vector();
    let v = w.cross(u);
    let (nu, nv) = (nu.max(3), nv.max(3));
    let mut m = Mesh {
        positions: Vec::with_capacity((nu * nv) as usize),
        faces: Vec::with_capacity((2 * nu * nv) as usize),
        groups: vec!["torus".to_string()],
    };
    let tau = std::f64::consts::TAU;
    for i in 0..nu {
        let a = tau * i as f64 / nu as f64;
        let radial = u * a.cos() + v * a.sin();
        for j in 0..nv {
            let b = tau * j as f64 / nv as f64;
            let p = centre + radial * (major + minor * b.cos()) + w * (minor * b.sin());
            m.positions.push(p);
        }
    }
    let id = |i: u32, j: u32| (i % nu) * nv + (j % nv);
    for i in 0..nu {
        for j in 0..nv {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            for t in [[a, b, c], [a, c, d]] {
                m.faces.push(Face {
                    vertices: t.to_vec(),
                    line: 0,
                    group: 0,
                });
            }
        }
    }
    m
}
