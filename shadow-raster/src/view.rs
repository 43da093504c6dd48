//! Cameras: the perspective camera of the image (the public contract) and
//! the projections of light maps (cube faces and orthographic maps).
//!
//! A view maps a world point `p` to its frame coordinates
//! `c = ((p − o)·r, (p − o)·u, (p − o)·f)` and those to continuous pixel
//! coordinates, `x` to the right and `y` downward from the image's
//! top-left corner; pixel `(x, y)` is sampled at its centre
//! `(x + 0.5, y + 0.5)`. Depth is carried as *nearness* `w`: `1/z` for a
//! perspective view (`z` the distance along `f`), `−z` for an orthographic
//! one. Either is an affine function of the pixel coordinates over a
//! plane, which is what makes it perspective-correct.

use glam::DVec3;

use crate::RasterError;

/// Guard band in pixels around the image: polygons are clipped to the
/// image widened by this much on every side, which keeps fixed-point
/// screen coordinates within `±2^15` pixels.
pub(crate) const GUARD: f64 = 8192.0;

/// Largest image side in pixels (so that the guard band stays in range).
pub const MAX_SIZE: u32 = 16384;

/// Most pixels in an image (about 25 bytes each are kept while drawing).
pub const MAX_PIXELS: u64 = 1 << 26;

/// A perspective camera, the crate's contract for reproducing a pixel.
///
/// Right-handed look-at: `f = normalize(target − eye)`,
/// `r = normalize(f × up)`, `u = r × f`. Pixel `(x, y)` counts `x` to the
/// right and `y` downward from the top-left corner; its ray leaves the eye
/// in the direction
/// `f + ((2(x+0.5)/W) − 1)·tan(fov/2)·(W/H)·r + (1 − 2(y+0.5)/H)·tan(fov/2)·u`,
/// with `fov` the vertical field of view.
///
/// ```
/// use glam::DVec3;
/// use shadow_raster::Camera;
/// let cam = Camera::look_at(DVec3::new(0.0, -5.0, 0.0), DVec3::ZERO, DVec3::Z, 50.0, 64, 48)?;
/// // the ray of the pixel right of the centre points slightly to +x
/// let d = cam.pixel_ray(32, 23);
/// assert!(d.x > 0.0 && d.y > 0.0 && d.z > 0.0);
/// assert_eq!(cam.forward(), DVec3::Y);
/// # Ok::<(), shadow_raster::RasterError>(())
/// ```
#[derive(Clone, Debug)]
pub struct Camera {
    pub(crate) view: View,
    target: DVec3,
    fov_deg: f64,
}

/// Why a camera cannot be set up.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum CameraError {
    /// The eye, the target or the up vector is not finite.
    NotFinite,
    /// The field of view, in degrees, is not strictly between 0 and 180.
    FieldOfView(f64),
    /// The eye and the target are the same point.
    EyeAtTarget,
    /// The eye is so far from the target (the largest coordinate of their
    /// difference, given) that the square of the distance is not an `f64`.
    TooFar(f64),
    /// The up vector is zero.
    ZeroUp,
    /// The up vector is parallel to the view direction.
    UpAlongView,
}

impl std::fmt::Display for CameraError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CameraError::NotFinite => f.write_str("the eye, target and up vector must be finite"),
            CameraError::FieldOfView(deg) => write!(
                f,
                "field of view {deg} degrees: it must lie strictly between 0 and 180"
            ),
            CameraError::EyeAtTarget => f.write_str("the eye and the target coincide"),
            CameraError::TooFar(d) => write!(
                f,
                "the eye is {d:.3e} units from the target: too far for f64 (its square \
                 overflows)"
            ),
            CameraError::ZeroUp => f.write_str("the up vector must not be zero"),
            CameraError::UpAlongView => {
                f.write_str("the up vector is parallel to the view direction")
            }
        }
    }
}

impl std::error::Error for CameraError {}

/// Sine of the smallest angle between the view direction and the up
/// vector that still defines a camera roll.
const MIN_UP_SINE: f64 = 1e-6;

/// The up direction of a camera looking from `eye` at `target` when none
/// is given: `+Z`, or `+Y` when looking along the `z` axis.
pub fn default_up(eye: DVec3, target: DVec3) -> DVec3 {
    let forward = (target - eye).normalize_or_zero();
    if forward.cross(DVec3::Z).length() > MIN_UP_SINE {
        DVec3::Z
    } else {
        DVec3::Y
    }
}

impl Camera {
    /// A camera at `eye` looking at `target`, `up` giving the roll, with
    /// a vertical field of view of `fov_deg` degrees (strictly between 0
    /// and 180), for a `width × height` image (at most [`MAX_SIZE`] on a
    /// side and [`MAX_PIXELS`] in all).
    pub fn look_at(
        eye: DVec3,
        target: DVec3,
        up: DVec3,
        fov_deg: f64,
        width: u32,
        height: u32,
    ) -> Result<Camera, RasterError> {
        check_size(width, height)?;
        Camera::look_at_any_size(eye, target, up, fov_deg, width, height)
    }

    /// [`Camera::look_at`] for a picture of any size of at least a pixel
    /// (an SVG has no pixel buffer).
    pub(crate) fn look_at_any_size(
        eye: DVec3,
        target: DVec3,
        up: DVec3,
        fov_deg: f64,
        width: u32,
        height: u32,
    ) -> Result<Camera, RasterError> {
        if width == 0 || height == 0 {
            return Err(RasterError::Size { width, height });
        }
        let bad = RasterError::Camera;
        if !(eye.is_finite() && target.is_finite() && up.is_finite()) {
            return Err(bad(CameraError::NotFinite));
        }
        if !(fov_deg > 0.0 && fov_deg < 180.0) {
            return Err(bad(CameraError::FieldOfView(fov_deg)));
        }
        let to_target = target - eye;
        // (a difference whose square underflows, the eye a hair from the
        // target, still has a direction: scaled up first)
        let m = to_target.abs().max_element();
        let Some(f) = (to_target.try_normalize())
            .or_else(|| (m > 0.0 && m < 1.0).then(|| (to_target / m).normalize()))
        else {
            return Err(bad(match to_target == DVec3::ZERO {
                true => CameraError::EyeAtTarget,
                false => CameraError::TooFar(to_target.abs().max_element()),
            }));
        };
        let Some(upn) = up.try_normalize() else {
            return Err(bad(CameraError::ZeroUp));
        };
        if f.cross(upn).length() <= MIN_UP_SINE {
            return Err(bad(CameraError::UpAlongView));
        }
        let r = f.cross(up).normalize();
        let u = r.cross(f);
        let ky = (0.5 * fov_deg.to_radians()).tan();
        let kx = ky * width as f64 / height as f64;
        Ok(Camera {
            view: View {
                kind: Kind::Perspective { kx, ky },
                origin: eye,
                r,
                u,
                f,
                width,
                height,
                near: 0.0,
                scale: (0.0, 0.0),
            }
            .ready(),
            target,
            fov_deg,
        })
    }

    /// The eye.
    pub fn eye(&self) -> DVec3 {
        self.view.origin
    }

    /// The point looked at.
    pub fn target(&self) -> DVec3 {
        self.target
    }

    /// `f`, the unit view direction.
    pub fn forward(&self) -> DVec3 {
        self.view.f
    }

    /// `r`, the unit right vector.
    pub fn right(&self) -> DVec3 {
        self.view.r
    }

    /// `u`, the unit up vector of the image.
    pub fn up(&self) -> DVec3 {
        self.view.u
    }

    /// Vertical field of view in degrees.
    pub fn fov_deg(&self) -> f64 {
        self.fov_deg
    }

    /// Image width in pixels.
    pub fn width(&self) -> u32 {
        self.view.width
    }

    /// Image height in pixels.
    pub fn height(&self) -> u32 {
        self.view.height
    }

    /// The (unnormalized) direction of pixel `(x, y)`'s ray, exactly the
    /// contract's formula.
    pub fn pixel_ray(&self, x: u32, y: u32) -> DVec3 {
        self.view.dir(x as f64 + 0.5, y as f64 + 0.5)
    }

    /// The pixel whose area contains the projection of `p`, if `p` is in
    /// front of the eye and inside the image.
    pub fn pixel_of(&self, p: DVec3) -> Option<(u32, u32)> {
        let c = self.view.frame(p);
        if c.z <= 0.0 {
            return None;
        }
        let (x, y) = self.view.screen(c);
        let (w, h) = (self.view.width as f64, self.view.height as f64);
        ((0.0..w).contains(&x) && (0.0..h).contains(&y)).then_some((x as u32, y as u32))
    }

    /// The same camera with the near plane at distance `near` (set from
    /// the scene's size by the renderer).
    pub(crate) fn with_near(&self, near: f64) -> Camera {
        let mut c = self.clone();
        c.view.near = near;
        c
    }
}

/// Checks an image size.
pub(crate) fn check_size(width: u32, height: u32) -> Result<(), RasterError> {
    if width == 0
        || height == 0
        || width > MAX_SIZE
        || height > MAX_SIZE
        || width as u64 * height as u64 > MAX_PIXELS
    {
        return Err(RasterError::Size { width, height });
    }
    Ok(())
}

/// How a view projects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Kind {
    /// Perspective from `origin`: `tan` of half the horizontal and vertical
    /// fields of view.
    Perspective { kx: f64, ky: f64 },
    /// Parallel projection along `f`: world units per pixel.
    Orthographic { scale: f64 },
}

/// A view: a frame, a projection and an image size.
#[derive(Clone, Debug)]
pub(crate) struct View {
    pub(crate) kind: Kind,
    pub(crate) origin: DVec3,
    pub(crate) r: DVec3,
    pub(crate) u: DVec3,
    pub(crate) f: DVec3,
    pub(crate) width: u32,
    pub(crate) height: u32,
    /// Near plane distance (perspective views only).
    pub(crate) near: f64,
    /// The projection's scales, set by [`View::ready`]: perspective
    /// `(W/2/kx, H/2/ky)`, orthographic `(1/scale, 1/scale)`.
    pub(crate) scale: (f64, f64),
}

/// The rays of a view's pixel centres, split into a part per column and a
/// part per row, so that a pass over the pixels finds each pixel's point
/// without a division by the image size: [`Rays::point`] gives
/// [`View::point`]'s bits.
pub(crate) struct Rays<'a> {
    view: &'a View,
    /// Perspective: `((2·xc/W) − 1)·kx·r` per column (empty otherwise).
    col: Vec<DVec3>,
}

impl<'a> Rays<'a> {
    pub(crate) fn new(view: &'a View) -> Rays<'a> {
        let col = match view.kind {
            Kind::Perspective { kx, .. } => {
                let w = view.width as f64;
                (0..view.width)
                    .map(|x| ((2.0 * (x as f64 + 0.5) / w) - 1.0) * kx * view.r)
                    .collect()
            }
            Kind::Orthographic { .. } => Vec::new(),
        };
        Rays { view, col }
    }

    /// The part of row `y`.
    #[inline]
    pub(crate) fn row(&self, y: usize) -> DVec3 {
        match self.view.kind {
            Kind::Perspective { ky, .. } => {
                let h = self.view.height as f64;
                (1.0 - 2.0 * (y as f64 + 0.5) / h) * ky * self.view.u
            }
            Kind::Orthographic { .. } => DVec3::ZERO,
        }
    }

    /// The world point at the centre of pixel `(x, y)` with nearness `w`,
    /// `row` being [`Rays::row`]`(y)`.
    #[inline]
    pub(crate) fn point(&self, x: usize, y: usize, row: DVec3, w: f64) -> DVec3 {
        match self.col.get(x) {
            // the order of View::dir's sums
            Some(&c) => self.view.origin + (self.view.f + c + row) / w,
            None => self.view.point(x as f64 + 0.5, y as f64 + 0.5, w),
        }
    }
}

/// A plane `a · c + d >= 0` in frame coordinates.
pub(crate) type ClipPlane = (DVec3, f64);

impl View {
    /// The view with its projection's scales computed.
    pub(crate) fn ready(mut self) -> View {
        let (w, h) = (self.width as f64, self.height as f64);
        self.scale = match self.kind {
            Kind::Perspective { kx, ky } => (0.5 * w / kx, 0.5 * h / ky),
            Kind::Orthographic { scale } => (1.0 / scale, 1.0 / scale),
        };
        self
    }

    /// Frame coordinates of a world point.
    #[inline]
    pub(crate) fn frame(&self, p: DVec3) -> DVec3 {
        let d = p - self.origin;
        DVec3::new(d.dot(self.r), d.dot(self.u), d.dot(self.f))
    }

    /// Continuous pixel coordinates of frame coordinates (in front of a
    /// perspective view's eye).
    #[inline]
    pub(crate) fn screen(&self, c: DVec3) -> (f64, f64) {
        let (hw, hh) = (0.5 * self.width as f64, 0.5 * self.height as f64);
        let (sx, sy) = self.scale;
        match self.kind {
            Kind::Perspective { .. } => {
                let iz = 1.0 / c.z;
                (hw + c.x * iz * sx, hh - c.y * iz * sy)
            }
            Kind::Orthographic { .. } => (hw + c.x * sx, hh - c.y * sy),
        }
    }

    /// The ray direction through continuous pixel coordinates (for an
    /// orthographic view, `f`).
    #[inline]
    pub(crate) fn dir(&self, xc: f64, yc: f64) -> DVec3 {
        match self.kind {
            Kind::Perspective { kx, ky } => {
                let (w, h) = (self.width as f64, self.height as f64);
                self.f + ((2.0 * xc / w) - 1.0) * kx * self.r + (1.0 - 2.0 * yc / h) * ky * self.u
            }
            Kind::Orthographic { .. } => self.f,
        }
    }

    /// The world point seen at continuous pixel coordinates with nearness
    /// `w`.
    #[inline]
    pub(crate) fn point(&self, xc: f64, yc: f64, w: f64) -> DVec3 {
        match self.kind {
            Kind::Perspective { .. } => self.origin + self.dir(xc, yc) / w,
            Kind::Orthographic { scale } => {
                let (wd, h) = (self.width as f64, self.height as f64);
                self.origin + (xc - 0.5 * wd) * scale * self.r + (0.5 * h - yc) * scale * self.u
                    - w * self.f
            }
        }
    }

    /// The nearness over the plane `n · p + d = 0` (world) as
    /// `w = a·xc + (b·yc + c)` at continuous pixel coordinates; `None`
    /// when the view sees the plane edge-on. The coefficients of a plane
    /// and of its exact negation are equal, bit for bit.
    pub(crate) fn coeffs(&self, n: DVec3, d: f64) -> Option<[f64; 3]> {
        let (w, h) = (self.width as f64, self.height as f64);
        let (nr, nu, nf) = (n.dot(self.r), n.dot(self.u), n.dot(self.f));
        match self.kind {
            Kind::Perspective { kx, ky } => {
                let s = n.dot(self.origin) + d;
                if s == 0.0 || !s.is_finite() {
                    return None;
                }
                // 1/(−s) = −(1/s) exactly: a plane and its negation still
                // give the same bits
                let is = 1.0 / s;
                let a = -((2.0 * kx / w) * nr) * is;
                let b = ((2.0 * ky / h) * nu) * is;
                let c = -(nf - kx * nr + ky * nu) * is;
                Some([a, b, c])
            }
            Kind::Orthographic { scale } => {
                if nf == 0.0 {
                    return None;
                }
                let s = n.dot(self.origin) + d;
                let a = (scale * nr) / nf;
                let b = -(scale * nu) / nf;
                let c = (s - 0.5 * w * scale * nr + 0.5 * h * scale * nu) / nf;
                Some([a, b, c])
            }
        }
    }

    /// The clip planes in frame coordinates: the near plane (perspective)
    /// and the image widened by [`GUARD`] pixels on every side.
    pub(crate) fn clip_planes(&self) -> [ClipPlane; 5] {
        let (w, h) = (self.width as f64, self.height as f64);
        match self.kind {
            Kind::Perspective { kx, ky } => {
                let gx = (1.0 + 2.0 * GUARD / w) * kx;
                let gy = (1.0 + 2.0 * GUARD / h) * ky;
                [
                    (DVec3::Z, -self.near),
                    (DVec3::new(1.0, 0.0, gx), 0.0),
                    (DVec3::new(-1.0, 0.0, gx), 0.0),
                    (DVec3::new(0.0, -1.0, gy), 0.0),
                    (DVec3::new(0.0, 1.0, gy), 0.0),
                ]
            }
            Kind::Orthographic { scale } => {
                let hx = (0.5 * w + GUARD) * scale;
                let hy = (0.5 * h + GUARD) * scale;
                [
                    (DVec3::ZERO, 1.0),
                    (DVec3::X, hx),
                    (-DVec3::X, hx),
                    (DVec3::Y, hy),
                    (-DVec3::Y, hy),
                ]
            }
        }
    }

    /// Angular (perspective) or linear (orthographic) size of a pixel: a
    /// pixel at depth `z` is about `z · pixel_angle()` wide, or
    /// `pixel_angle()` for an orthographic view.
    pub(crate) fn pixel_size(&self, z: f64) -> f64 {
        match self.kind {
            Kind::Perspective { ky, .. } => z * 2.0 * ky / self.height as f64,
            Kind::Orthographic { scale } => scale,
        }
    }
}

/// Parses an up direction: an axis (`x`, `y`, `z`, `-x`, `-y`, `-z`) or
/// a non-zero `X,Y,Z`.
pub fn parse_up(s: &str) -> Result<DVec3, String> {
    let axis = match s.trim() {
        "x" | "+x" => Some(DVec3::X),
        "y" | "+y" => Some(DVec3::Y),
        "z" | "+z" => Some(DVec3::Z),
        "-x" => Some(DVec3::NEG_X),
        "-y" => Some(DVec3::NEG_Y),
        "-z" => Some(DVec3::NEG_Z),
        _ => None,
    };
    match axis {
        Some(a) => Ok(a),
        None => {
            let v = shadow_scene::parse_vec3(s)
                .map_err(|e| format!("{e}; or an axis: x, y, z, -x, -y, -z"))?;
            if v == DVec3::ZERO {
                return Err("the up direction must not be zero".to_string());
            }
            Ok(v)
        }
    }
}

/// Parses a field of view in degrees, between 1 and 170.
pub fn parse_fov(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    if (1.0..=170.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!(
            "{} is outside 1..=170 degrees",
            svbsp::input_number(v)
        ))
    }
}

/// `WxH`, each side between 1 and [`MAX_SIZE`].
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("`{s}` is not a size: expected WxH, such as 1280x720"))?;
    let side = |v: &str, what: &str| -> Result<u32, String> {
        let n: u32 = v
            .trim()
            .parse()
            .map_err(|_| format!("`{s}`: the {what} `{v}` is not a whole number (expected WxH)"))?;
        if n == 0 || n > MAX_SIZE {
            return Err(format!(
                "`{s}`: the {what} must lie between 1 and {} pixels",
                MAX_SIZE
            ));
        }
        Ok(n)
    };
    let (w, h) = (side(w, "width")?, side(h, "height")?);
    if w as u64 * h as u64 > MAX_PIXELS {
        return Err(format!("`{s}`: at most {} pixels in all", MAX_PIXELS));
    }
    Ok((w, h))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An eye a hair from its target looks at it (it was "too far for
    /// f64": the square of the distance underflowed); one whose square
    /// overflows is too far, and says so.
    #[test]
    fn eyes_near_and_far() {
        let look = |eye: DVec3| Camera::look_at(eye, DVec3::ZERO, DVec3::Y, 50.0, 8, 8);
        let near = look(DVec3::new(0.0, 0.0, 1e-300)).unwrap();
        assert_eq!(near.forward(), DVec3::NEG_Z);
        let far = look(DVec3::new(0.0, 0.0, 1e300)).unwrap_err().to_string();
        assert!(far.contains("too far for f64"), "{far}");
    }

    #[test]
    fn contract_ray_and_projection_agree() {
        let cam = Camera::look_at(
            DVec3::new(1.0, -4.0, 2.0),
            DVec3::new(0.0, 0.0, 0.5),
            DVec3::Z,
            50.0,
            64,
            40,
        )
        .unwrap();
        for (x, y) in [(0, 0), (63, 39), (10, 30), (32, 20)] {
            let d = cam.pixel_ray(x, y);
            let p = cam.eye() + d * 3.7;
            let (sx, sy) = cam.view.screen(cam.view.frame(p));
            assert!((sx - (x as f64 + 0.5)).abs() < 1e-9, "{sx}");
            assert!((sy - (y as f64 + 0.5)).abs() < 1e-9, "{sy}");
            assert_eq!(cam.pixel_of(p), Some((x, y)));
        }
        // r = normalize(f × up), u = r × f
        let f = cam.forward();
        assert!((cam.right() - f.cross(DVec3::Z).normalize()).length() < 1e-15);
        assert!((cam.up() - cam.right().cross(f)).length() < 1e-15);
    }

    #[test]
    fn nearness_over_a_plane_is_affine_and_exact_for_negated_planes() {
        let cam = Camera::look_at(
            DVec3::new(0.3, -6.0, 2.0),
            DVec3::ZERO,
            DVec3::Z,
            60.0,
            80,
            60,
        )
        .unwrap();
        let v = &cam.view;
        let (n, d) = (DVec3::new(0.2, 0.1, 1.0).normalize(), 0.4);
        let k = v.coeffs(n, d).unwrap();
        assert_eq!(k, v.coeffs(-n, -d).unwrap());
        for (x, y) in [(0.5, 0.5), (40.5, 30.5), (79.5, 12.5)] {
            let w = k[0] * x + (k[1] * y + k[2]);
            let p = v.point(x, y, w);
            assert!((n.dot(p) + d).abs() < 1e-12, "{}", n.dot(p) + d);
        }
        // orthographic
        let o = View {
            kind: Kind::Orthographic { scale: 0.05 },
            origin: DVec3::new(0.0, 0.0, 10.0),
            r: DVec3::X,
            u: DVec3::Y,
            f: -DVec3::Z,
            width: 32,
            height: 32,
            near: 0.0,
            scale: (0.0, 0.0),
        }
        .ready();
        let k = o.coeffs(n, d).unwrap();
        let w = k[0] * 3.5 + (k[1] * 9.5 + k[2]);
        let p = o.point(3.5, 9.5, w);
        assert!((n.dot(p) + d).abs() < 1e-12);
        let (sx, sy) = o.screen(o.frame(p));
        assert!((sx - 3.5).abs() < 1e-9 && (sy - 9.5).abs() < 1e-9);
    }

    #[test]
    fn bad_cameras_are_errors() {
        let e = |r: Result<Camera, RasterError>| r.unwrap_err().to_string();
        // an eye whose distance squared overflows is too far, not at the target
        let far = e(Camera::look_at(
            DVec3::new(1e300, 0.0, 0.0),
            DVec3::ZERO,
            DVec3::Z,
            50.0,
            10,
            10,
        ));
        assert!(
            far.contains("1.000e300 units from the target: too far"),
            "{far}"
        );
        assert!(
            e(Camera::look_at(
                DVec3::ONE,
                DVec3::ONE,
                DVec3::Z,
                50.0,
                10,
                10
            ))
            .contains("coincide")
        );
        assert!(
            e(Camera::look_at(
                DVec3::ZERO,
                DVec3::Z,
                DVec3::Z,
                50.0,
                10,
                10
            ))
            .contains("parallel")
        );
        assert!(
            e(Camera::look_at(
                DVec3::ZERO,
                DVec3::X,
                DVec3::ZERO,
                50.0,
                10,
                10
            ))
            .contains("zero")
        );
        assert!(
            e(Camera::look_at(
                DVec3::ZERO,
                DVec3::X,
                DVec3::Z,
                180.0,
                10,
                10
            ))
            .contains("180")
        );
        assert!(
            e(Camera::look_at(
                DVec3::ZERO,
                DVec3::X,
                DVec3::Z,
                50.0,
                0,
                10
            ))
            .contains("0x10")
        );
        assert!(
            e(Camera::look_at(
                DVec3::NAN,
                DVec3::X,
                DVec3::Z,
                50.0,
                10,
                10
            ))
            .contains("finite")
        );
    }
}
