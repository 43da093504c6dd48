//! Where the sun is: NREL's Solar Position Algorithm (Reda & Andreas,
//! 2004; the maintained `solar-positioning` crate, tested there against
//! NREL's reference data), turned into a direction in the scene's axes,
//! the light of a sun study.
//!
//! Scene axes: with `+z` up (the default), `+y` is north and `+x` east;
//! with `+y` up ([`Up::Y`], most scans and glTF), `−z` is north and `+x`
//! east. [`SunSite::north_deg`] turns true north clockwise (seen from
//! above) from that axis.

/// A study's day ([`parse_date`], [`study_dates`]).
pub use chrono::NaiveDate;
use chrono::{DateTime, FixedOffset};

mod exact_time;
mod ply;
mod regions;
mod report;
mod runs;
pub(crate) mod tiles;
pub use exact_time::{
    Interval, SunPath, day_paths, hides, interval_hours, intervals_json, sensor_intervals,
    sensor_intervals_facing, study_plan, triangles,
};
use glam::DVec3;
pub use shadow_scene::Sensor;
use smallvec::SmallVec;

use crate::shadow_file::{NoProgress, Progress};
pub use ply::{hours_ply, regions_ply, sensors_ply};
use regions::region_study;
pub use regions::{
    RegionCell, RegionFaces, area_in_sun, bre209_text, check_bre209, clip_to_outline, region_hours,
    region_in_sun_text, regions_csv, regions_json, regions_obj, regions_png,
};
pub use report::{HoursOf, HoursReport, hours_report};
use runs::Snapped;
pub use runs::{HoursRun, StudyScene};
use solar_positioning::{Location, RefractionCorrection, SolarPositions, delta_t};
pub use tiles::Tile;
pub(crate) use tiles::{grid_bounds, may_shade};

/// Which scene axis points up.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Up {
    /// `+z` up, `+y` north.
    #[default]
    Z,
    /// `+y` up, `−z` north.
    Y,
}

impl std::str::FromStr for Up {
    type Err = String;

    /// `z` or `y`.
    fn from_str(s: &str) -> Result<Up, String> {
        match s.trim() {
            "z" => Ok(Up::Z),
            "y" => Ok(Up::Y),
            other => Err(format!("`{other}`: the up axis is z or y")),
        }
    }
}

/// A place on the earth and how the scene sits there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunSite {
    /// Degrees north.
    pub latitude: f64,
    /// Degrees east.
    pub longitude: f64,
    /// Metres above sea level.
    pub height: f64,
    /// True north, in degrees clockwise (seen from above) from the
    /// scene's north axis.
    pub north_deg: f64,
    /// The scene's up axis.
    pub up: Up,
    /// Air pressure (hPa) and temperature (°C) for the refraction; `None`:
    /// the standard atmosphere (1013.25 hPa, 15 °C).
    pub air: Option<(f64, f64)>,
    /// TT − UT1 in seconds; `None`: estimated from the date.
    pub delta_t: Option<f64>,
}

impl SunSite {
    /// A site at sea level, the scene's axes as they are, the standard
    /// atmosphere.
    pub fn new(latitude: f64, longitude: f64) -> SunSite {
        SunSite {
            latitude,
            longitude,
            height: 0.0,
            north_deg: 0.0,
            up: Up::Z,
            air: None,
            delta_t: None,
        }
    }
}

impl SunSite {
    /// The site with the scene turned: true north `north_deg` clockwise
    /// from its north axis, and `up` its up axis.
    pub fn with_axes(self, north_deg: f64, up: Up) -> SunSite {
        SunSite {
            north_deg,
            up,
            ..self
        }
    }
}

/// The sun seen from a site at a time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunPosition {
    /// Degrees clockwise from true north.
    pub azimuth_deg: f64,
    /// Apparent elevation above the horizon (with refraction), degrees.
    pub elevation_deg: f64,
    /// The unit direction toward the sun, in the scene's axes.
    pub direction: DVec3,
}

impl SunPosition {
    /// One JSON object: `{"azimuth_deg": …, "elevation_deg": …,
    /// "direction": [x, y, z]}`.
    pub fn json(&self) -> String {
        let d = self.direction;
        format!(
            "{{\"azimuth_deg\": {}, \"elevation_deg\": {}, \"direction\": [{}, {}, {}]}}",
            self.azimuth_deg, self.elevation_deg, d.x, d.y, d.z
        )
    }

    /// One line for people: azimuth, apparent elevation, direction.
    pub fn text(&self) -> String {
        let d = self.direction;
        let below = if self.is_up() {
            ""
        } else {
            " (below the horizon)"
        };
        format!(
            "azimuth {:.4} deg, elevation {:.4} deg (apparent), direction {},{},{}{below}",
            self.azimuth_deg, self.elevation_deg, d.x, d.y, d.z
        )
    }

    /// Whether the sun's centre is above the horizon.
    pub fn is_up(&self) -> bool {
        self.elevation_deg > 0.0
    }
}

/// Why a position cannot be found: the message names the value.
#[derive(Debug)]
pub struct SunError(String);

impl std::fmt::Display for SunError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for SunError {}

/// The time of an ISO 8601 text with its offset, such as
/// `2026-03-21T12:00:00+01:00` (or `Z`).
pub fn parse_time(s: &str) -> Result<DateTime<FixedOffset>, SunError> {
    DateTime::parse_from_rfc3339(s.trim()).map_err(|e| {
        SunError(format!(
            "`{s}` is not a time with its offset such as 2026-03-21T12:00:00+01:00 ({e})"
        ))
    })
}

/// Where the sun is seen from `site` at `time` (SPA, with refraction).
pub fn sun_position(site: &SunSite, time: &DateTime<FixedOffset>) -> Result<SunPosition, SunError> {
    // (beyond a turn either way, an angle's degrees lose their precision)
    if site.north_deg.is_nan() || site.north_deg.abs() > 360.0 {
        return Err(SunError(format!(
            "true north at {} degrees: give an angle from -360 to 360",
            site.north_deg
        )));
    }
    let (az, el) = spa(site, time, true)?;
    // the horizontal way to the sun, turned by the scene's north
    let (turn, tilt) = ((az + site.north_deg).to_radians(), el.to_radians());
    let (east, north, up) = (turn.sin() * tilt.cos(), turn.cos() * tilt.cos(), tilt.sin());
    let direction = match site.up {
        Up::Z => DVec3::new(east, north, up),
        Up::Y => DVec3::new(east, up, -north),
    };
    Ok(SunPosition {
        azimuth_deg: az,
        elevation_deg: el,
        direction,
    })
}

/// SPA's topocentric azimuth and elevation (degrees) at `site` and
/// `time`: apparent (with the site's air's refraction) if `refracted`,
/// else geometric.
fn spa(
    site: &SunSite,
    time: &DateTime<FixedOffset>,
    refracted: bool,
) -> Result<(f64, f64), SunError> {
    let bad = |e: solar_positioning::Error| SunError(e.to_string());
    let location = Location {
        latitude: site.latitude,
        longitude: site.longitude,
    };
    let dt = match site.delta_t {
        Some(d) => d,
        None => delta_t::estimate_from_date_like(time)
            .map_err(|e| SunError(format!("{}: {e}", time.to_rfc3339())))?,
    };
    let air = match (refracted, site.air) {
        (false, _) => None,
        (true, Some((p, t))) => Some(RefractionCorrection::new(p, t).map_err(bad)?),
        (true, None) => Some(RefractionCorrection::standard()),
    };
    let p = SolarPositions::new()
        .at(time, location, site.height, dt, air)
        .map_err(bad)?;
    Ok((p.azimuth(), p.elevation_angle()))
}

/// The finest step of a study's suns: one second, in minutes (a day of
/// at most 86,400 suns).
pub const MIN_STEP_MINUTES: f64 = 1.0 / 60.0;

/// The suns of a study: on each of `dates`, the midpoints of the day's
/// `step_minutes`-long intervals from 00:00 to 24:00 at `utc_offset_hours`,
/// those with the sun's centre above the horizon. The midpoint rule: a
/// face's sun-hours are `step · Σ lit share` over these suns; the error
/// against the day's true integral is at most `step² / 24 · |f''|` per
/// interval for a lit share `f` smooth in time, and where a shadow edge
/// crosses a point within an interval, at most half a step for that point
/// (the sample is the interval's middle).
pub fn study_suns(
    site: &SunSite,
    dates: &[chrono::NaiveDate],
    step_minutes: f64,
    utc_offset_hours: f64,
) -> Result<Vec<SunPosition>, SunError> {
    // (the times are whole milliseconds, and a day of steps under a
    // second is a hang rather than a study: 1e-9 minutes made 1.4e12 suns)
    if !((MIN_STEP_MINUTES..=1440.0).contains(&step_minutes)) {
        return Err(SunError(format!(
            "a step of {step_minutes} minutes: from one second ({MIN_STEP_MINUTES:.4}) to 1440 \
             (the sun path's exact hours need no step: `--exact-time`)"
        )));
    }
    let offset = (utc_offset_hours.abs() < 24.0)
        .then(|| FixedOffset::east_opt((utc_offset_hours * 3600.0).round() as i32))
        .flatten()
        .ok_or_else(|| {
            SunError(format!(
                "a UTC offset of {utc_offset_hours} hours: it must lie strictly between -24 and 24"
            ))
        })?;
    // the first and the last day at once: a date the sun's model does
    // not reach fails before the days before it are worked out
    for date in [dates.first(), dates.last()].into_iter().flatten() {
        let noon = date.and_hms_opt(12, 0, 0).expect("noon exists");
        let noon = noon
            .and_local_timezone(offset)
            .single()
            .expect("one local noon");
        sun_position(site, &noon)?;
    }
    let steps = (1440.0 / step_minutes).floor() as i64;
    let mut out = Vec::new();
    for date in dates {
        let midnight = date.and_hms_opt(0, 0, 0).expect("midnight exists");
        let start = midnight
            .and_local_timezone(offset)
            .single()
            .expect("a fixed offset has one local time");
        for k in 0..steps {
            let ms = ((k as f64 + 0.5) * step_minutes * 60_000.0).round() as i64;
            let t = start + chrono::Duration::milliseconds(ms);
            let p = sun_position(site, &t)?;
            if p.is_up() {
                out.push(p);
            }
        }
    }
    Ok(out)
}

/// A date `YYYY-MM-DD` (spaces around it ignored).
pub fn parse_date(s: &str) -> Result<chrono::NaiveDate, SunError> {
    s.trim()
        .parse::<chrono::NaiveDate>()
        .map_err(|e| SunError(format!("`{s}` is not a date YYYY-MM-DD ({e})")))
}

/// The days of a study: `from` to `to` (default: `from`), every `every`
/// days, dates as `YYYY-MM-DD`.
pub fn study_dates(
    from: &str,
    to: Option<&str>,
    every: u32,
) -> Result<Vec<chrono::NaiveDate>, SunError> {
    let day = parse_date;
    let first = day(from)?;
    let last = to.map_or(Ok(first), day)?;
    if last < first || every == 0 {
        return Err(SunError(format!(
            "no days from {first} to {last} every {every} days"
        )));
    }
    let days = (last - first).num_days() as u64;
    Ok((0..=days / u64::from(every))
        .map(|k| first + chrono::Duration::days((k * u64::from(every)) as i64))
        .collect())
}

/// A face's sun-hours over a study.
#[derive(Clone, Debug, PartialEq)]
pub struct FaceHours {
    /// The face's area.
    pub area: f64,
    /// `∫ lit area dt / area`: the mean of its points' hours.
    pub sun_hours: f64,
    /// The fewest hours a point of it gets.
    pub min_hours: f64,
    /// The most hours a point of it gets.
    pub max_hours: f64,
    /// How much of its area gets how many hours: `(hours, area)`, by
    /// hours (the overlay's cells, `f64`).
    pub hours_area: Vec<(f64, f64)>,
}

impl FaceHours {
    /// The area of the face whose points get at least `hours` (within
    /// 10⁻⁹ hours: the steps' sums in `f64`).
    pub fn area_with_at_least(&self, hours: f64) -> f64 {
        (self.hours_area.iter())
            .filter(|(h, _)| *h >= hours - 1e-9)
            .map(|(_, a)| a)
            .sum()
    }
}

/// Per group of `mesh` (in the order of first use), its area and the
/// area of it whose points get at least `hours` of sun: the test of
/// planning rules such as the BRE's "half of a garden in sun for at
/// least two hours on 21 March". A face's share is measured on its
/// overlay's cells, so the shares of the group's faces add up.
pub fn groups_in_sun(
    mesh: &crate::Mesh,
    faces: &[FaceHours],
    hours: f64,
) -> Vec<(String, f64, f64)> {
    let mut out: Vec<(String, f64, f64)> = Vec::new();
    for (f, h) in faces.iter().enumerate() {
        let name = mesh.group_name(f);
        let total: f64 = h.hours_area.iter().map(|(_, a)| a).sum();
        let sunny = h.area_with_at_least(hours);
        match out.iter_mut().find(|g| g.0 == name) {
            Some(g) => (g.1, g.2) = (g.1 + total, g.2 + sunny),
            None => out.push((name.to_string(), total, sunny)),
        }
    }
    out
}

/// [`groups_in_sun`] for people, one line per group (nothing without
/// `hours`).
pub fn groups_in_sun_text(mesh: &crate::Mesh, faces: &[FaceHours], hours: Option<f64>) -> String {
    let Some(hours) = hours else {
        return String::new();
    };
    (groups_in_sun(mesh, faces, hours).iter())
        .map(|(name, total, sunny)| {
            let share = if *total > 0.0 {
                100.0 * sunny / total
            } else {
                0.0
            };
            format!(
                "{name}: {share:.1}% of its {total:.6} units² sees at least {hours} hours of sun\n"
            )
        })
        .collect()
}

/// How many suns a study shades at once (a run; [`HoursRun`]). The exact
/// engine takes up to [`svbsp::MAX_LIGHTS`] lights a run, but cuts every
/// fragment by every one of its lights' shadow boundaries, so a run's
/// cost grows faster than its suns: on bunny-11k one sun's shading took
/// 29 ms and 64 suns' 15.4 s (530 times as long). Runs of 4 suns made a
/// day's study (73 suns) of the room 6.4 times as fast for the mean hours
/// (0.83 s against 5.31 s) and 1.3 times with the extremes, whose
/// overlay of the runs' pieces then does the cutting; bunny-11k 3.2 and
/// 1.15 times.
pub const SUNS_A_RUN: usize = 4;

/// A face's cells with the number of suns each one's points see: one
/// [`Part`] per support plane of the face's polygons (one for a planar
/// face).
type FaceCells = Vec<Part>;

/// A part of a face (its polygons on one support plane) in a study's run
/// or fold: whole, every point seeing the same suns (most faces in most
/// runs: kept as its planes and count, not as an overlay), or its exact
/// cells.
#[derive(Clone, Debug, PartialEq)]
enum Part {
    /// The part whole: its support plane, its edge planes in turn, and
    /// how many suns its points see.
    Whole(bsp_core::Plane, SmallVec<[bsp_core::Plane; 6]>, u32),
    /// Its cells.
    Cells(svbsp::FaceOverlay),
}

impl Part {
    /// The part of one cell, or of several; `None` if a cell is not a
    /// strictly convex polygon on `support` ([`svbsp::FaceOverlay::new`]).
    fn new(
        support: bsp_core::Plane,
        cells: Vec<(SmallVec<[bsp_core::Plane; 6]>, u32)>,
    ) -> Option<Part> {
        if let [(planes, count)] = &cells[..] {
            // (checked as any cell is)
            svbsp::FaceOverlay::new(support, [(&planes[..], *count)])?;
        }
        Part::of_pieces(support, cells)
    }

    /// [`Part::new`] of the engine's pieces of a face, strictly convex by
    /// construction: a whole part is not checked again; the cells of
    /// several are joined where they can be ([`svbsp::FaceOverlay::join`]).
    fn of_pieces<P: AsRef<[bsp_core::Plane]>>(
        support: bsp_core::Plane,
        cells: Vec<(P, u32)>,
    ) -> Option<Part> {
        match &cells[..] {
            [(planes, count)] => Some(Part::Whole(
                support,
                planes.as_ref().iter().copied().collect(),
                *count,
            )),
            _ => svbsp::FaceOverlay::new(support, cells).map(|mut o| {
                o.join();
                Part::Cells(o)
            }),
        }
    }

    fn support(&self) -> &bsp_core::Plane {
        match self {
            Part::Whole(s, ..) => s,
            Part::Cells(o) => o.support(),
        }
    }

    /// The part as an overlay.
    fn overlay(&self) -> svbsp::FaceOverlay {
        match self {
            Part::Whole(support, planes, count) => {
                svbsp::FaceOverlay::new(*support, [(&planes[..], *count)])
                    .expect("a whole part's planes make a convex polygon (checked)")
            }
            Part::Cells(o) => o.clone(),
        }
    }

    /// This part overlaid with a later run's of the same polygons (a
    /// whole part's count added to each of the other's cells, which cover
    /// it; two parts' cells, which cover each other, overlaid as such:
    /// [`svbsp::FaceOverlay::plus_covering`]); `None` where they lie on
    /// other planes.
    fn plus(self, other: &Part) -> Option<Part> {
        if self.support() != other.support() {
            return None;
        }
        match (self, other) {
            (Part::Whole(s, p, a), Part::Whole(_, _, b)) => Some(Part::Whole(s, p, a + b)),
            (Part::Whole(_, _, a), Part::Cells(o)) => {
                let mut o = o.clone();
                o.add_count(a);
                Some(Part::Cells(o))
            }
            (Part::Cells(mut o), Part::Whole(_, _, b)) => {
                o.add_count(*b);
                Some(Part::Cells(o))
            }
            (Part::Cells(a), Part::Cells(b)) => a.plus_covering(b).map(Part::Cells),
        }
    }

    /// Each cell's corners (grid coordinates for measuring: correctly
    /// rounded, or within `2^-20` grid units of the exact points) and count.
    fn cells(&self) -> Vec<(Vec<[f64; 3]>, u32)> {
        match self {
            Part::Whole(support, planes, count) => {
                let p = bsp_core::Polygon::from_planes(*support, planes, 0)
                    .expect("a whole part's planes meet in turn (checked)");
                vec![(p.vertices_f64(), *count)]
            }
            Part::Cells(o) => (o.measured_corners().into_iter())
                .enumerate()
                .map(|(i, c)| (c, o.count(i)))
                .collect(),
        }
    }

    /// The counts of its cells.
    fn counts(&self) -> Vec<u32> {
        match self {
            Part::Whole(.., count) => vec![*count],
            Part::Cells(o) => (0..o.len()).map(|i| o.count(i)).collect(),
        }
    }
}

/// The sun-hours of every face of `mesh` (in face order) under `suns`
/// (directions toward them), each sun standing for `step_hours`: the
/// exact lit part of every face for every sun ([`crate::shadows`],
/// [`SUNS_A_RUN`] suns a run), its area summed over the suns
/// (`sun_hours`), and the fewest and most hours over the face's points,
/// from the runs' lit pieces overlaid (their hours added; the overlay is
/// exact: [`svbsp::FaceOverlay`]).
///
/// The same as [`HoursRun::new`] over the suns in runs of
/// [`SUNS_A_RUN`], folded in order by [`HoursRun::fold`]: runs
/// made elsewhere (on other processes or machines) and folded in the
/// same order give the same bits.
pub fn sun_hours(
    mesh: &crate::Mesh,
    suns: &[DVec3],
    step_hours: f64,
) -> Result<Vec<FaceHours>, crate::Error> {
    faces_study(mesh, suns, step_hours, true, 1, &NoProgress)
}

/// Every face's hours, with the `extremes` or the mean only, the scene
/// cut into `tiles × tiles` tiles (1: not cut), each run done told to
/// `progress`.
pub(crate) fn faces_study(
    mesh: &crate::Mesh,
    suns: &[DVec3],
    step_hours: f64,
    extremes: bool,
    tiles: usize,
    progress: &dyn Progress,
) -> Result<Vec<FaceHours>, crate::Error> {
    let pieces = extremes.then_some(None);
    study(mesh, suns, step_hours, pieces, tiles, progress, |runs| {
        HoursRun::fold(mesh.faces.len(), runs)
    })?
}

/// `fold` of a study's runs, in order: [`SUNS_A_RUN`] suns each, and of
/// each run of suns each of `tiles × tiles` tiles in order (1: one run
/// of every face), on the mesh snapped once ([`Snapped`]), with `pieces`
/// as [`HoursRun::make`] takes them; every run done told to `progress`.
fn study<T>(
    mesh: &crate::Mesh,
    suns: &[DVec3],
    step_hours: f64,
    pieces: Option<Option<&[bool]>>,
    tiles: usize,
    progress: &dyn Progress,
    fold: impl FnOnce(&mut (dyn Iterator<Item = Result<HoursRun, crate::Error>> + Send)) -> T,
) -> Result<T, crate::Error> {
    let cut: Vec<Option<Tile>> = match tiles {
        0 => {
            return Err(crate::Error::Tile {
                index: 0,
                per_side: 0,
            });
        }
        1 => vec![None],
        _ => Tile::all(tiles).map(Some).collect(),
    };
    // (no suns, as in a polar night: one run of none, which gives the
    // faces' areas and no hours; no faces: no runs, nothing to snap)
    let batches: Vec<&[DVec3]> = match (suns.is_empty(), mesh.faces.is_empty()) {
        (true, true) => Vec::new(),
        (true, false) => vec![&[]],
        (false, _) => suns.chunks(SUNS_A_RUN).collect(),
    };
    let snapped = (!batches.is_empty())
        .then(|| Snapped::new(mesh))
        .transpose()?;
    let count = batches.len() * cut.len();
    progress.phase("sun runs", count as u64);
    let mut runs = (snapped.iter())
        .flat_map(|s| batches.iter().map(move |&batch| (s, batch)))
        .flat_map(|(s, batch)| cut.iter().map(move |&t| (s, batch, t)))
        .map(|(s, batch, t)| {
            let run = HoursRun::make(mesh, batch, step_hours, pieces, s, t);
            progress.advance(1);
            run
        });
    Ok(fold(&mut runs))
}

/// [`sun_hours`] (with `extremes`) or [`sun_hours_mean`] with the scene
/// cut into `per_side × per_side` tiles ([`Tile`]): each run of suns
/// shades one tile's faces past only the occluders that may hide the sun
/// from them, in runs of [`SUNS_A_RUN`] suns, the tiles of a run in
/// order ([`HoursRun::of_tile`]). Every fragment's class is the whole
/// scene's; the areas may differ from the untiled study's in their last
/// bits (the fragments are cut differently), and are the same, bit for
/// bit, for runs made elsewhere and folded in this order. One tile a side
/// is the untiled study.
pub fn sun_hours_in_tiles(
    mesh: &crate::Mesh,
    suns: &[DVec3],
    step_hours: f64,
    per_side: usize,
    extremes: bool,
) -> Result<Vec<FaceHours>, crate::Error> {
    faces_study(mesh, suns, step_hours, extremes, per_side, &NoProgress)
}

/// [`sun_hours`] without the overlay: each face's exact `sun_hours` (and
/// area), with `min_hours` and `max_hours` NaN and `hours_area` empty.
/// (The same `sun_hours` as [`sun_hours`] gives, which keeps each between
/// the face's extremes: a sum of rounded areas may fall an ulp outside.)
/// The overlay of every run's pieces grows with the arrangement of all the
/// suns' shadow edges on a face (quadratic in the suns where shadows of
/// many suns cross one face, as on a ground under a detailed object);
/// the mean needs none of it, so a long study of a large scene costs the
/// shadows alone, run by run.
pub fn sun_hours_mean(
    mesh: &crate::Mesh,
    suns: &[DVec3],
    step_hours: f64,
) -> Result<Vec<FaceHours>, crate::Error> {
    faces_study(mesh, suns, step_hours, false, 1, &NoProgress)
}

/// Every face's mean sun-hours with each of `suns` (directions toward
/// their centres) a disc of `radius_deg` (the real sun's:
/// [`crate::SUN_RADIUS_DEG`]): per sun, the face's lit area (seeing all
/// of the disc) and each penumbra fragment's area times the share of the
/// disc seen at its centroid ([`crate::soft_file::SoftShadows::seen_area`]),
/// times the step. That share is of the disc's part in front of the face
/// (the soft shadows' definition, for irradiance); for hours it is scaled
/// to the whole disc by the share of a circle of the disc's radius in
/// front of the face's plane (`f64`), so that a face the sun's centre is
/// behind gets only the sliver it sees. No extremes (NaN). A sun at a
/// time through the soft shadows' engine, which is far slower than
/// [`sun_hours_mean`]'s point suns; a radius of 0 gives
/// [`sun_hours_mean`]'s hours.
pub fn sun_hours_disc(
    mesh: &crate::Mesh,
    suns: &[DVec3],
    step_hours: f64,
    radius_deg: f64,
) -> Result<Vec<FaceHours>, crate::Error> {
    disc_study(mesh, suns, step_hours, radius_deg, &NoProgress)
}

/// [`sun_hours_disc`], every sun done told to `progress`.
pub(crate) fn disc_study(
    mesh: &crate::Mesh,
    suns: &[DVec3],
    step_hours: f64,
    radius_deg: f64,
    progress: &dyn Progress,
) -> Result<Vec<FaceHours>, crate::Error> {
    let faces = mesh.faces.len();
    let (mut area, mut seen) = (vec![0.0; faces], vec![0.0; faces]);
    let normals = mesh.face_normals();
    // (discs add no point to the grid: the mesh snapped and imported once)
    let grid = svbsp::shared_soft_grid(&mesh.positions, &[], &[]).map_err(crate::Error::Light)?;
    let (polys, _) = crate::import_mesh(&grid, mesh).map_err(crate::Error::Import)?;
    progress.phase("suns", suns.len() as u64);
    for &direction in suns {
        let disc = crate::SoftSpec::SunDisc {
            direction,
            radius_deg,
        };
        let s = crate::soft_file::soft_shadows_on(grid, &polys, faces, &[], &[disc])?;
        let d = direction.normalize();
        for f in 0..faces {
            area[f] = s.face_area(f);
            let front = disc_in_front(normals[f].dot(d).clamp(-1.0, 1.0).asin(), radius_deg);
            seen[f] += s.seen_area(f, 0) * front * step_hours;
        }
        progress.advance(1);
    }
    Ok((0..faces)
        .map(|f| FaceHours {
            min_hours: f64::NAN,
            max_hours: f64::NAN,
            ..face_hours(area[f], seen[f], None, step_hours)
        })
        .collect())
}

/// The share of a circle of angular radius `radius_deg` whose centre is
/// `height` radians above a plane that lies in front of it: the circular
/// segment's, `(acos(−h) + h √(1 − h²)) / π` for `h` the height in radii.
fn disc_in_front(height: f64, radius_deg: f64) -> f64 {
    let r = radius_deg.to_radians();
    if height >= r {
        return 1.0;
    }
    if height <= -r {
        return 0.0;
    }
    let h = height / r;
    ((-h).acos() + h * (1.0 - h * h).sqrt()) / std::f64::consts::PI
}

/// A face's hours from its area, its lit area times hours, and its
/// overlaid cells with the grid they are on (`None`: no suns).
fn face_hours(
    area: f64,
    lit: f64,
    cells: Option<(&[Part], &bsp_core::Grid)>,
    step_hours: f64,
) -> FaceHours {
    let parts = cells.map_or(&[][..], |c| c.0);
    let seen = parts.iter().flat_map(Part::counts);
    let (min, max) = seen.fold((u32::MAX, 0), |(a, b), h| (a.min(h), b.max(h)));
    let (min, max) = (f64::from(min) * step_hours, f64::from(max) * step_hours);
    // (a face of area has cells, but none is no hours rather than a
    // fewest of u32::MAX steps)
    let none = parts.iter().all(|p| p.counts().is_empty()) || area == 0.0;
    let mut by: std::collections::BTreeMap<u32, f64> = Default::default();
    if let Some((parts, grid)) = cells {
        for (corners, count) in parts.iter().flat_map(Part::cells) {
            let ring: Vec<DVec3> = corners.into_iter().map(|c| grid.to_world(c)).collect();
            *by.entry(count).or_default() += svbsp::polygon_area(&ring);
        }
    }
    let hours_area = by.into_iter().map(|(n, a)| (f64::from(n) * step_hours, a));
    let (min, max) = if none { (0.0, 0.0) } else { (min, max) };
    // the mean is a sum of rounded areas, the extremes exact counts: the
    // mean kept between them (it fell an ulp below an equal least)
    let mean = if area > 0.0 { lit / area } else { 0.0 };
    FaceHours {
        area,
        sun_hours: if none { mean } else { mean.clamp(min, max) },
        min_hours: min,
        max_hours: max,
        hours_area: hours_area.collect(),
    }
}

/// The sun-hours at each point of `sensors` (input units) among the
/// faces of `mesh`, each of `suns` (directions toward them) standing for
/// `step_hours`: per sensor, the suns no face hides from its grid point,
/// exactly ([`svbsp::LightVolumes::reaching`]; a point on a shadow's edge is
/// reached), counted. A sensor on a face counts the suns in front of it
/// and behind it alike: give sensors a little off their surface, or give
/// them their surface's normal ([`sensor_hours_facing`]).
pub fn sensor_hours(
    mesh: &crate::Mesh,
    sensors: &[DVec3],
    suns: &[DVec3],
    step_hours: f64,
) -> Result<Vec<f64>, crate::Error> {
    let sensors: Vec<Sensor> = sensors.iter().map(|&p| p.into()).collect();
    sensor_hours_facing(mesh, &sensors, suns, step_hours)
}

/// [`sensor_hours`] of sensors that may stand for a surface: one with a
/// normal `n` counts only the suns strictly in front of it (`n · d > 0`
/// for the direction `d` toward the sun, in `f64`: a sun in the surface's
/// plane grazes it and is not counted), as Ladybug's "Direct Sun Hours"
/// counts a sensor's suns.
pub fn sensor_hours_facing(
    mesh: &crate::Mesh,
    sensors: &[Sensor],
    suns: &[DVec3],
    step_hours: f64,
) -> Result<Vec<f64>, crate::Error> {
    use crate::Error;
    let all: Vec<crate::Light> = suns.iter().map(|&d| crate::Light::Sun(d)).collect();
    let points = Sensor::positions(sensors);
    let positions = [&mesh.positions[..], &points].concat();
    let grid = svbsp::shared_grid(&positions, &all).map_err(Error::Light)?;
    let at: Vec<bsp_core::GridPoint> = (points.iter().enumerate())
        .map(|(index, &p)| grid.snap(p).map_err(|cause| Error::Sensor { index, cause }))
        .collect::<Result<_, _>>()?;
    let (polys, _) = crate::import_mesh(&grid, mesh).map_err(Error::Import)?;
    let solids = bsp_core::certify_solid_parts(&polys);
    let mut seen = vec![0u32; sensors.len()];
    for (batch, dirs) in all
        .chunks(svbsp::MAX_LIGHTS)
        .zip(suns.chunks(svbsp::MAX_LIGHTS))
    {
        let placed = svbsp::place_lights(&grid, batch).map_err(Error::Light)?;
        let kernel: Vec<svbsp::Light> = placed.iter().map(|l| l.light).collect();
        let trees =
            crate::face_trees(&polys, &kernel, &at, &solids, None).map_err(Error::Shadow)?;
        for ((n, &g), s) in seen.iter_mut().zip(&at).zip(sensors) {
            // the batch's suns in front of the sensor's surface
            let facing = s.normal.map_or(u64::MAX, |normal| {
                (dirs.iter().enumerate())
                    .filter(|(_, d)| normal.dot(**d) > 0.0)
                    .fold(0u64, |m, (i, _)| m | 1 << i)
            });
            *n += (trees.reaching(g) & facing).count_ones();
        }
    }
    Ok(seen
        .into_iter()
        .map(|n| f64::from(n) * step_hours)
        .collect())
}

/// The sun-hours at the sensors of the file `path`
/// ([`shadow_scene::read_sensors`]: points, each with its surface's
/// normal where given) among the faces of `mesh`
/// ([`sensor_hours_facing`]), as text in `format` ([`sensors_csv`],
/// [`sensors_json`], [`sensors_obj`]; not as a picture); and how many
/// sensors there are.
pub fn sensor_hours_file(
    mesh: &crate::Mesh,
    path: &std::path::Path,
    suns: &[DVec3],
    step_hours: f64,
    format: HoursFormat,
) -> Result<(String, usize), crate::Error> {
    if format == HoursFormat::Png {
        return Err(crate::Error::Format {
            path: path.to_path_buf(),
            why: SENSORS_NOT_A_PICTURE,
        });
    }
    let sensors = shadow_scene::read_sensors(path).map_err(crate::Error::File)?;
    let hours = sensor_hours_facing(mesh, &sensors, suns, step_hours)?;
    let points = Sensor::positions(&sensors);
    let text = match format {
        HoursFormat::Csv => sensors_csv(&points, &hours),
        HoursFormat::Json => sensors_json(&points, &hours, suns.len()),
        HoursFormat::Ply => sensors_ply(&points, &hours),
        HoursFormat::Obj | HoursFormat::Png => sensors_obj(&points, &hours), // (Png refused above)
    };
    Ok((text, points.len()))
}

/// Why sensors' hours are not drawn.
const SENSORS_NOT_A_PICTURE: &str =
    "a picture shows faces' hours: write sensors' hours as .csv, .json or .obj";

/// How a picture of a study ([`hours_png`]) looks at the scene.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HeatView {
    /// A built-in scene's camera ([`shadow_scene::Staging::of_scene`]);
    /// `None`: a camera that frames every vertex.
    pub staging: Option<shadow_scene::Staging>,
    /// The scene's up axis, the framing camera's up.
    pub up: Up,
}

impl HeatView {
    /// The view of a built-in scene's `staging`, or a framing one with
    /// `up` (default `z`) as up.
    pub fn of(staging: Option<shadow_scene::Staging>, up: Option<Up>) -> HeatView {
        HeatView {
            staging,
            up: up.unwrap_or_default(),
        }
    }
}

/// The size of a study's picture, in pixels.
pub const HEAT_PNG_SIZE: (u32, u32) = (1280, 720);

/// A picture of the study (PNG, [`HEAT_PNG_SIZE`]): every face coloured
/// by its sun-hours on the heat map's ramp ([`heat_colors`]: 0 hours dark
/// blue, the most any face gets yellow), seen as `view` says, lit from
/// the eye so the forms read, with the ramp, its range and the number of
/// suns along the bottom.
pub fn hours_png(
    mesh: &crate::Mesh,
    hours: &[FaceHours],
    suns: usize,
    view: HeatView,
) -> Result<Vec<u8>, crate::Error> {
    let most = hours.iter().map(|h| h.sun_hours).fold(0.0, f64::max);
    heat_picture(mesh, &heat_colors(hours, most), most, suns, view)
}

/// The picture of [`hours_png`] of `mesh` with its faces in `colors`,
/// the ramp's top at `most` hours.
fn heat_picture(
    mesh: &crate::Mesh,
    colors: &[DVec3],
    most: f64,
    suns: usize,
    view: HeatView,
) -> Result<Vec<u8>, crate::Error> {
    use shadow_raster::svg::{SvgViewpoint, ViewRequest};
    let (w, h) = HEAT_PNG_SIZE;
    let up = match view.up {
        Up::Z => DVec3::Z,
        Up::Y => DVec3::Y,
    };
    // (a built-in scene keeps its own camera's up)
    let request = ViewRequest {
        up: view.staging.is_none().then_some(up),
        ..ViewRequest::default()
    };
    let (at, _) = SvgViewpoint::choose(request, &mesh.positions, view.staging, (w, h), 40.0);
    let light = [svbsp::LightSpec::Point(at.eye)];
    let grid = svbsp::shared_grid(&mesh.positions, &light).map_err(crate::Error::Light)?;
    let lights = svbsp::place_lights(&grid, &light).map_err(crate::Error::Light)?;
    let (polys, _) = crate::import_mesh(&grid, mesh).map_err(crate::Error::Import)?;
    let raster = |e| crate::Error::Raster(e);
    let scene = shadow_raster::RasterScene::new(&grid, polys).map_err(raster)?;
    let bounds =
        (mesh.bounds()).ok_or(crate::Error::Raster(shadow_raster::RasterError::EmptyScene))?;
    let camera = at.camera(bounds).map_err(raster)?;
    let options = shadow_raster::RenderOptions::default();
    let mut picture = shadow_raster::render(&scene, &lights, &camera, colors, &options)
        .map_err(raster)?
        .image;
    // the ramp, between its ends' hours, along the bottom edge
    let (ink, y) = ([40, 40, 40], h - 28);
    picture.text("0 h", 10, y, 2, ink);
    for i in 0..256 {
        let rgb = viridis(f64::from(i) / 255.0).map(|c| (c * 255.0).round() as u8);
        picture.blit(&shadow_raster::Image::new(1, 14, rgb), 52 + i, y);
    }
    let label = format!("{most:.1} h of sun ({suns} suns)");
    picture.text(&label, 320, y, 2, ink);
    Ok(picture.encode_png())
}

/// Sensors' hours as CSV: `sensor,x,y,z,sun_hours`.
pub fn sensors_csv(points: &[DVec3], hours: &[f64]) -> String {
    let mut s = String::from(
        "sensor,x,y,z,sun_hours
",
    );
    for (i, (p, h)) in points.iter().zip(hours).enumerate() {
        s += &format!("{i},{},{},{},{h}\n", p.x, p.y, p.z);
    }
    s
}

/// Sensors' hours as JSON: `{"suns": n, "sensors": [{"sensor",
/// "position", "sun_hours"}, …]}`.
pub fn sensors_json(points: &[DVec3], hours: &[f64], suns: usize) -> String {
    let sensors: Vec<serde_json::Value> = (points.iter().zip(hours).enumerate())
        .map(|(i, (p, h))| {
            serde_json::json!({"sensor": i, "position": [p.x, p.y, p.z], "sun_hours": h})
        })
        .collect();
    format!(
        "{:#}\n",
        serde_json::json!({"suns": suns, "sensors": sensors})
    )
}

/// A file of sun-hours.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HoursFormat {
    /// [`hours_csv`].
    Csv,
    /// [`hours_json`].
    Json,
    /// [`hours_obj`]: a heat map to look at.
    Obj,
    /// [`hours_ply`]: the heat map with each face's hours.
    Ply,
    /// [`hours_png`]: a picture of the heat map.
    Png,
}

impl HoursFormat {
    /// The format a file name asks for (`.csv`, `.json`, `.obj`, `.ply`, `.png`),
    /// if any.
    pub fn of(path: &std::path::Path) -> Option<HoursFormat> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "json" => Some(HoursFormat::Json),
            "csv" => Some(HoursFormat::Csv),
            "obj" => Some(HoursFormat::Obj),
            "ply" => Some(HoursFormat::Ply),
            "png" => Some(HoursFormat::Png),
            _ => None,
        }
    }

    /// [`HoursFormat::of`], or an error naming the file and the formats.
    pub fn for_path(path: &std::path::Path) -> Result<HoursFormat, crate::Error> {
        HoursFormat::of(path).ok_or_else(|| crate::Error::Format {
            path: path.to_path_buf(),
            why: "a sun study is written as .csv, .json, .obj, .ply or .png",
        })
    }

    /// The hours of `mesh` in this format (`suns`: how many; a picture
    /// looks at the scene as `view` says).
    pub fn bytes(
        self,
        mesh: &crate::Mesh,
        hours: &[FaceHours],
        suns: usize,
        view: HeatView,
    ) -> Result<Vec<u8>, crate::Error> {
        Ok(match self {
            HoursFormat::Json => hours_json(mesh, hours, suns).into_bytes(),
            HoursFormat::Csv => hours_csv(mesh, hours).into_bytes(),
            HoursFormat::Obj => hours_obj(mesh, hours).into_bytes(),
            HoursFormat::Ply => hours_ply(mesh, hours).into_bytes(),
            HoursFormat::Png => hours_png(mesh, hours, suns, view)?,
        })
    }
}

/// The hours as a heat map in OBJ: every face with its own corners, each
/// coloured (`v x y z r g b`) by the face's sun-hours on a viridis ramp
/// from 0 hours (dark blue) to the most any face gets (yellow), named in
/// the first line; groups as the mesh's.
pub fn hours_obj(mesh: &crate::Mesh, hours: &[FaceHours]) -> String {
    let most = hours.iter().map(|h| h.sun_hours).fold(0.0, f64::max);
    let mut s = heat_header(most);
    let (mut next, mut group) = (1, None);
    for (f, (face, h)) in mesh.faces.iter().zip(hours).enumerate() {
        if group != Some(face.group) {
            group = Some(face.group);
            s += &format!("g {}\n", mesh.group_name(f));
        }
        let rgb = heat(h.sun_hours, most);
        for &v in &face.vertices {
            s += &colored_vertex(mesh.positions[v as usize], rgb);
        }
        let corners: Vec<String> = (next..next + face.vertices.len())
            .map(|i| i.to_string())
            .collect();
        s += &format!("f {}\n", corners.join(" "));
        next += face.vertices.len();
    }
    s
}

/// Sensors' hours as coloured points in OBJ (`v x y z r g b`, the ramp
/// of [`hours_obj`]).
pub fn sensors_obj(points: &[DVec3], hours: &[f64]) -> String {
    let most = hours.iter().copied().fold(0.0, f64::max);
    let mut s = heat_header(most);
    for (p, h) in points.iter().zip(hours) {
        s += &colored_vertex(*p, heat(*h, most));
    }
    s
}

/// The heat maps' first line: the ramp and its range.
fn heat_header(most: f64) -> String {
    format!("# sun-hours: viridis from 0 (dark blue) to {most} hours (yellow)\n")
}

/// An OBJ vertex with its colour.
fn colored_vertex(p: DVec3, [r, g, b]: [f64; 3]) -> String {
    format!("v {} {} {} {r:.4} {g:.4} {b:.4}\n", p.x, p.y, p.z)
}

/// The colour of `hours` on the ramp from 0 to `most` hours.
fn heat(hours: f64, most: f64) -> [f64; 3] {
    viridis(if most > 0.0 { hours / most } else { 0.0 })
}

/// Each face's colour in the heat maps ([`hours_obj`]): its sun-hours on
/// the viridis ramp from 0 to `most` hours (RGB in `[0, 1]`).
pub fn heat_colors(hours: &[FaceHours], most: f64) -> Vec<DVec3> {
    (hours.iter())
        .map(|h| DVec3::from_array(heat(h.sun_hours, most)))
        .collect()
}

/// A colour of the viridis ramp at `t` in `[0, 1]` (five stops, linear
/// between).
fn viridis(t: f64) -> [f64; 3] {
    const STOPS: [[f64; 3]; 5] = [
        [68.0, 1.0, 84.0],
        [59.0, 82.0, 139.0],
        [33.0, 145.0, 140.0],
        [94.0, 201.0, 98.0],
        [253.0, 231.0, 37.0],
    ];
    let x = t.clamp(0.0, 1.0) * 4.0;
    let i = (x.floor() as usize).min(3);
    let w = x - i as f64;
    std::array::from_fn(|k| ((1.0 - w) * STOPS[i][k] + w * STOPS[i + 1][k]) / 255.0)
}

/// The hours as CSV: `face,group,area,sun_hours,min_hours,max_hours`.
pub fn hours_csv(mesh: &crate::Mesh, hours: &[FaceHours]) -> String {
    let mut s = String::from("face,group,area,sun_hours,min_hours,max_hours\n");
    for (f, h) in hours.iter().enumerate() {
        // (no extremes: empty fields)
        let extreme = |x: f64| {
            if x.is_nan() {
                String::new()
            } else {
                x.to_string()
            }
        };
        s += &format!(
            "{f},{},{},{},{},{}\n",
            mesh.group_name(f),
            h.area,
            h.sun_hours,
            extreme(h.min_hours),
            extreme(h.max_hours)
        );
    }
    s
}

/// The hours as JSON: `{"suns": n, "faces": [{"face", "group", "area",
/// "sun_hours", "min_hours", "max_hours"}, …]}`.
pub fn hours_json(mesh: &crate::Mesh, hours: &[FaceHours], suns: usize) -> String {
    let faces: Vec<serde_json::Value> = (hours.iter().enumerate())
        .map(|(f, h)| {
            serde_json::json!({"face": f, "group": mesh.group_name(f), "area": h.area,
                "sun_hours": h.sun_hours, "min_hours": h.min_hours, "max_hours": h.max_hours})
        })
        .collect();
    format!("{:#}\n", serde_json::json!({"suns": suns, "faces": faces}))
}

#[cfg(test)]
mod tests;
