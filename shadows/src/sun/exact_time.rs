//! Sun-hours at sensors with no time sampling (`--exact-time`): each
//! day's sun-on intervals in closed form.
//!
//! The model. Within each hour of the day's clock the sun's declination
//! `δ` is held at its value at the hour's middle (it moves by at most
//! 0.017° in an hour), and its hour angle `H` turns at 15° an hour (the
//! equation of time moves by at most 1.3 s in an hour); both are taken
//! from SPA's geometric position at the hour's middle. Within the hour
//! the sun's direction is `d(H) = cos δ cos H · e₁ + cos δ sin H · e₂ +
//! sin δ · p`, with `p` the earth's axis, `e₁` the celestial equator's top
//! in the meridian and `e₂` west: an arc of a cone around `p` in the
//! scene's axes.
//!
//! Every condition on the sun is a linear inequality `w · d(H) > c`, so it
//! holds on an arc of hour angles, `A cos H + B sin H > c'`, found in
//! closed form:
//!
//! - above the horizon: the sun's centre's geometric elevation above 0.
//!   Refraction is left out, in the horizon and in the shadows alike (it
//!   is not linear in the direction): the sampled study, which counts
//!   the apparent sun, sees an open sky's day longer by the refraction at
//!   each end, about 3 to 5 minutes at mid latitudes, and a shadow's edge
//!   that the sun crosses near the horizon a little later or sooner;
//! - not hidden by a triangle `abc`: the direction is in the cone from
//!   the sensor `x` over the triangle exactly when it is a non-negative
//!   combination of `a − x`, `b − x`, `c − x`, three inequalities
//!   (Cramer's rule) on `d`, whose arcs' intersection is the triangle's
//!   sun-off interval; faces of more than three corners are triangulated
//!   (earcut in their plane).
//!
//! The day's sun-on intervals are the horizon's arcs less the union of
//! every triangle's, in `f64` (a time, not a geometric decision; the
//! model's own error is the drift above within an hour, a few seconds
//! where a shadow's edge meets the sensor at a glancing angle). A sensor on a face does not see that
//! face as an occluder (it lies in its plane), and, as with the sampled
//! study, counts the sun on either side of it, unless it is given its
//! surface's normal `n`: then only while `n · d(H) > 0`, one more arc.

use chrono::NaiveDate;
use glam::DVec3;

use super::{Sensor, SunError, SunSite, Up};

/// The length below which a sensor's interval is the rounding of two
/// arcs that end together, not sun: under a microsecond (about 280,000
/// times `f64`'s spacing at 24 hours), far below the model's own error
/// (seconds, above).
const SLIVER_HOURS: f64 = 1e-9;

/// Hours of the day's clock, `[from, to)`, from its midnight.
pub type Interval = (f64, f64);

/// The sun's path over one day, as the model above has it.
#[derive(Clone, Debug, PartialEq)]
pub struct SunPath {
    /// The day.
    pub date: NaiveDate,
    /// Its clock, hours east of UTC.
    pub utc_offset_hours: f64,
    /// Per hour of the day, the declination and the hour angle at its
    /// middle, radians (hour angle 0: the sun in the meridian, positive:
    /// past it).
    hours: Vec<(f64, f64)>,
    /// The earth's axis, the equator's top in the meridian, and west, in
    /// the scene's axes.
    axes: [DVec3; 3],
    /// The scene's up.
    up: DVec3,
}

impl SunPath {
    /// The day `date` at `site`, its clock `utc_offset_hours` east of UTC.
    pub fn of_day(
        site: &SunSite,
        date: NaiveDate,
        utc_offset_hours: f64,
    ) -> Result<SunPath, SunError> {
        let offset = chrono::FixedOffset::east_opt((utc_offset_hours * 3600.0).round() as i32)
            .ok_or_else(|| SunError(format!(
            "a UTC offset of {utc_offset_hours} hours: it must lie strictly between -24 and 24"
        )))?;
        let midnight = date
            .and_hms_opt(0, 0, 0)
            .expect("midnight exists")
            .and_local_timezone(offset)
            .single()
            .expect("a fixed offset has one local time");
        let phi = site.latitude.to_radians();
        // east, north, up
        let pole = DVec3::new(0.0, phi.cos(), phi.sin());
        let top = DVec3::new(0.0, -phi.sin(), phi.cos());
        let west = DVec3::new(-1.0, 0.0, 0.0);
        let hours = (0..24)
            .map(|k| {
                let t = midnight + chrono::Duration::minutes(60 * k + 30);
                let (az, el) = geometric_position(site, &t)?;
                let (az, el) = (az.to_radians(), el.to_radians());
                let sun = DVec3::new(az.sin() * el.cos(), az.cos() * el.cos(), el.sin());
                let declination = sun.dot(pole).clamp(-1.0, 1.0).asin();
                Ok((declination, sun.dot(west).atan2(sun.dot(top))))
            })
            .collect::<Result<Vec<_>, SunError>>()?;
        let scene = |v: DVec3| scene_axes(site, v);
        Ok(SunPath {
            date,
            utc_offset_hours,
            hours,
            axes: [pole, top, west].map(scene),
            up: scene(DVec3::Z),
        })
    }

    /// The unit direction toward the sun at `hour` of the day's clock.
    pub fn direction(&self, hour: f64) -> DVec3 {
        let k = (hour.floor().max(0.0) as usize).min(23);
        let (declination, middle) = self.hours[k];
        let h = middle + (hour - k as f64 - 0.5) * std::f64::consts::PI / 12.0;
        let (s, c) = (declination.sin(), declination.cos());
        let [pole, top, west] = self.axes;
        c * h.cos() * top + c * h.sin() * west + s * pole
    }

    /// Whether the sun's centre is above the (geometric) horizon at
    /// `hour`.
    pub fn is_up(&self, hour: f64) -> bool {
        self.direction(hour).dot(self.up) > 0.0
    }

    /// The hours of the day (within `[0, 24)`) at which `w · d > c`:
    /// per hour, the arc of its model, clipped to the hour.
    fn when(&self, w: DVec3, c: f64) -> Vec<Interval> {
        let mut out: Vec<Interval> = Vec::new();
        for k in 0..self.hours.len() {
            for i in self.arc(k, w, c) {
                push_merged(&mut out, i);
            }
        }
        out
    }

    /// The part of hour `k` at which `w · d > c`, in the hour's model:
    /// none, one or two intervals, by start.
    fn arc(&self, k: usize, w: DVec3, c: f64) -> impl Iterator<Item = Interval> {
        let [pole, top, west] = self.axes;
        let (declination, middle) = self.hours[k];
        let (s, co) = (declination.sin(), declination.cos());
        // w · d(H) = a cos H + b sin H + s (w · pole)
        let (a, b, rest) = (co * w.dot(top), co * w.dot(west), c - s * w.dot(pole));
        let from = k as f64;
        let r = a.hypot(b);
        let mut out = [None, None];
        if r <= rest.abs() {
            // all of the hour or none of it (r == 0 included)
            out[0] = (rest < 0.0).then_some((from, from + 1.0));
        } else {
            // r cos(H − centre) > rest: H within `half` of `centre`; in
            // hours from the hour's middle, modulo a day
            let per_radian = 12.0 / std::f64::consts::PI;
            let half = (rest / r).acos() * per_radian;
            let centre = (b.atan2(a) - middle) * per_radian;
            // the hour of the arc's start, within [from - 0.5, from + 23.5)
            let start = (centre - half + 1.0).rem_euclid(24.0) + from - 0.5;
            for (slot, day) in out.iter_mut().zip([-24.0, 0.0]) {
                let lo = (start + day).max(from);
                let hi = (start + day + 2.0 * half).min(from + 1.0);
                *slot = (lo < hi).then_some((lo, hi));
            }
        }
        out.into_iter().flatten()
    }

    /// The hours the sun's centre is above the horizon.
    fn up_hours(&self) -> Vec<Interval> {
        self.when(self.up, 0.0)
    }

    /// The hours triangle `t` hides the sun from `x` within the hours
    /// `up` (whose sun is up): none where `x` is in its plane or the
    /// triangle is wholly below the horizon (then so is every direction
    /// into it), else, per hour, the intersection of its three arcs.
    fn hidden_by(
        &self,
        x: DVec3,
        t: &[DVec3; 3],
        up: &[usize],
        out: &mut Vec<Interval>,
        [hidden, arc, next]: &mut [Vec<Interval>; 3],
    ) {
        let [a, b, c] = t.map(|p| p - x);
        let det = a.dot(b.cross(c));
        if det == 0.0 || [a, b, c].iter().all(|g| g.dot(self.up) <= 0.0) {
            return;
        }
        let s = det.signum();
        let w = [b.cross(c), c.cross(a), a.cross(b)].map(|w| s * w);
        for &k in up {
            hidden.clear();
            hidden.extend(self.arc(k, w[0], 0.0));
            for w in &w[1..] {
                if hidden.is_empty() {
                    break;
                }
                arc.clear();
                arc.extend(self.arc(k, *w, 0.0));
                intersect_into(hidden, arc, next);
                std::mem::swap(hidden, next);
            }
            out.extend_from_slice(hidden);
        }
    }
}

/// Whether the ray from `x` along `d` meets triangle `t` (its inside,
/// not its plane): the test the intervals are made of, for sampling.
pub fn hides(x: DVec3, d: DVec3, t: &[DVec3; 3]) -> bool {
    let [a, b, c] = t.map(|p| p - x);
    let det = a.dot(b.cross(c));
    det != 0.0
        && [b.cross(c), c.cross(a), a.cross(b)]
            .iter()
            .all(|w| det.signum() * w.dot(d) > 0.0)
}

/// The triangles of `mesh`'s faces (faces of more than three corners by
/// earcut in their plane; faces without area give none).
pub fn triangles(mesh: &crate::Mesh) -> Vec<[DVec3; 3]> {
    let mut out = Vec::new();
    let mut cut = earcut::Earcut::new();
    let (mut flat, mut tri) = (Vec::new(), Vec::<u32>::new());
    for points in mesh.face_loops() {
        if let [a, b, c] = points[..] {
            out.push([a, b, c]);
            continue;
        }
        let xyz: Vec<[f64; 3]> = points.iter().map(|p| p.to_array()).collect();
        if !earcut::utils3d::project3d_to_2d(&xyz, xyz.len(), &mut flat) {
            continue;
        }
        cut.earcut(flat.iter().copied(), &[] as &[u32], &mut tri);
        out.extend(
            tri.chunks(3)
                .map(|t| [0, 1, 2].map(|k| points[t[k] as usize])),
        );
    }
    out
}

/// Each sensor's sun-on intervals on each day of `paths`, among the faces
/// of `mesh` (see the module's model): `[sensor][day]`, sorted and
/// disjoint, in hours of that day's clock. The sensors in parallel; the
/// same result for any thread count.
pub fn sensor_intervals(
    mesh: &crate::Mesh,
    sensors: &[DVec3],
    paths: &[SunPath],
) -> Vec<Vec<Vec<Interval>>> {
    let sensors: Vec<Sensor> = sensors.iter().map(|&p| p.into()).collect();
    sensor_intervals_facing(mesh, &sensors, paths)
}

/// [`sensor_intervals`] of sensors that may stand for a surface: one with
/// a normal `n` has the sun on only while it is strictly in front of
/// that surface (`n · d(H) > 0`, one more arc of the model's).
pub fn sensor_intervals_facing(
    mesh: &crate::Mesh,
    sensors: &[Sensor],
    paths: &[SunPath],
) -> Vec<Vec<Vec<Interval>>> {
    let tris = triangles(mesh);
    // each day's hours of sun above the horizon, and the hours they touch
    let days: Vec<(Vec<Interval>, Vec<usize>)> = paths
        .iter()
        .map(|path| {
            let up_hours = path.up_hours();
            let up = (0..24)
                .filter(|&k| (up_hours.iter()).any(|&(a, b)| a < (k + 1) as f64 && b > k as f64))
                .collect();
            (up_hours, up)
        })
        .collect();
    bsp_core::par::map(sensors.len(), |i| {
        let x = sensors[i].position;
        let mut scratch = Default::default();
        (paths.iter().zip(&days))
            .map(|(path, (up_hours, up))| {
                let mut hidden = Vec::new();
                for t in &tris {
                    path.hidden_by(x, t, up, &mut hidden, &mut scratch);
                }
                hidden.sort_by(|p, q| p.0.total_cmp(&q.0));
                let mut on = subtract(up_hours, &merged(hidden));
                if let Some(n) = sensors[i].normal {
                    let mut facing = Vec::new();
                    intersect_into(&on, &path.when(n, 0.0), &mut facing);
                    on = facing;
                }
                // (arcs found apart may overlap by an ulp where they end
                // together: the horizon's and a surface's facing down, or
                // two triangles' sun-off arcs, left 1e-15 h of "sun")
                on.retain(|(a, b)| b - a > SLIVER_HOURS);
                on
            })
            .collect()
    })
}

/// The hours of each sensor's intervals, summed over the days.
pub fn interval_hours(intervals: &[Vec<Vec<Interval>>]) -> Vec<f64> {
    intervals
        .iter()
        // (`+ 0.0`: an empty sum is -0)
        .map(|days| days.iter().flatten().map(|(a, b)| b - a).sum::<f64>() + 0.0)
        .collect()
}

/// A study's suns, the directions toward them ([`super::study_suns`]),
/// and, for `exact_time`, its days' paths ([`day_paths`]).
pub fn study_plan(
    site: &SunSite,
    dates: &[NaiveDate],
    step_minutes: f64,
    utc_offset_hours: f64,
    exact_time: bool,
) -> Result<(Vec<DVec3>, Option<Vec<SunPath>>), SunError> {
    let suns = super::study_suns(site, dates, step_minutes, utc_offset_hours)?;
    let paths = exact_time.then(|| day_paths(site, dates, utc_offset_hours));
    Ok((
        suns.iter().map(|s| s.direction).collect(),
        paths.transpose()?,
    ))
}

/// The days' paths of a study.
pub fn day_paths(
    site: &SunSite,
    dates: &[NaiveDate],
    utc_offset_hours: f64,
) -> Result<Vec<SunPath>, SunError> {
    dates
        .iter()
        .map(|&d| SunPath::of_day(site, d, utc_offset_hours))
        .collect()
}

/// Sensors' exact-time hours as JSON: per sensor its position, hours, and
/// per day its intervals in hours of the day's clock.
pub fn intervals_json(points: &[DVec3], paths: &[SunPath], days: &[Vec<Vec<Interval>>]) -> String {
    let hours = interval_hours(days);
    let sensors: Vec<serde_json::Value> = (points.iter().zip(days).zip(hours).enumerate())
        .map(|(i, ((p, days), h))| {
            let days: Vec<serde_json::Value> = (paths.iter().zip(days))
                .map(|(path, on)| {
                    let on: Vec<[f64; 2]> = on.iter().map(|&(a, b)| [a, b]).collect();
                    serde_json::json!({"date": path.date.to_string(), "sun": on})
                })
                .collect();
            serde_json::json!({"sensor": i, "position": [p.x, p.y, p.z], "sun_hours": h, "days": days})
        })
        .collect();
    let offset = paths.first().map_or(0.0, |p| p.utc_offset_hours);
    serde_json::to_string_pretty(&serde_json::json!({
        "model": "exact time: per hour of the day, the declination and the equation of time at its middle; no refraction",
        "utc_offset_hours": offset,
        "sensors": sensors
    }))
    .expect("JSON of numbers and strings")
        + "\n"
}

/// SPA's geometric (unrefracted) azimuth and elevation, degrees.
pub(crate) fn geometric_position(
    site: &SunSite,
    time: &chrono::DateTime<chrono::FixedOffset>,
) -> Result<(f64, f64), SunError> {
    super::spa(site, time, false)
}

/// A vector in true east, north, up as the scene's axes have it.
fn scene_axes(site: &SunSite, v: DVec3) -> DVec3 {
    let n = site.north_deg.to_radians();
    let (east, north) = (v.x * n.cos() + v.y * n.sin(), v.y * n.cos() - v.x * n.sin());
    match site.up {
        Up::Z => DVec3::new(east, north, v.z),
        Up::Y => DVec3::new(east, v.z, -north),
    }
}

/// The intersection of two sorted, disjoint interval lists.
#[cfg(test)]
fn intersect(p: &[Interval], q: &[Interval]) -> Vec<Interval> {
    let mut out = Vec::new();
    intersect_into(p, q, &mut out);
    out
}

/// The intersection of two sorted, disjoint interval lists (the tests'
/// `intersect`), written to `out` (cleared first).
fn intersect_into(p: &[Interval], q: &[Interval], out: &mut Vec<Interval>) {
    out.clear();
    let (mut i, mut j) = (0, 0);
    while i < p.len() && j < q.len() {
        let (a, b) = (p[i].0.max(q[j].0), p[i].1.min(q[j].1));
        if a < b {
            out.push((a, b));
        }
        if p[i].1 < q[j].1 {
            i += 1;
        } else {
            j += 1;
        }
    }
}

/// Pushes `i` (starting at or after the last interval's start) onto
/// `out`, merged with the last where they overlap or touch.
fn push_merged(out: &mut Vec<Interval>, (a, b): Interval) {
    match out.last_mut() {
        Some(last) if a <= last.1 => last.1 = last.1.max(b),
        _ => out.push((a, b)),
    }
}

/// Intervals sorted by start, merged where they overlap or touch.
fn merged(sorted: Vec<Interval>) -> Vec<Interval> {
    let mut out: Vec<Interval> = Vec::with_capacity(sorted.len());
    for i in sorted {
        push_merged(&mut out, i);
    }
    out
}

/// `p` less `q` (both sorted and disjoint).
fn subtract(p: &[Interval], q: &[Interval]) -> Vec<Interval> {
    let mut out = Vec::new();
    for &(mut a, b) in p {
        for &(c, d) in q {
            if d <= a || c >= b {
                continue;
            }
            if c > a {
                out.push((a, c));
            }
            a = a.max(d);
        }
        if a < b {
            out.push((a, b));
        }
    }
    out
}

#[cfg(test)]
mod tests;
