//! Where the sun is: NREL's Solar Position Algorithm (Reda & Andreas,
//! 2004; the maintained `solar-positioning` crate, tested there against
//! NREL's reference data), turned into a direction in the scene's axes,
//! the light of a sun study.
//!
//! Scene axes: with `+z` up (the default), `+y` is north and `+x` east;
//! with `+y` up ([`Up::Y`], most scans and glTF), `−z` is north and `+x`
//! east. [`SunSite::north_deg`] turns true north clockwise (seen from
//! above) from that axis.

use chrono::{DateTime, FixedOffset};
use glam::DVec3;
use solar_positioning::{Location, RefractionCorrection, SolarPositions, delta_t};

/// Which scene axis points up.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Up {
    /// `+z` up, `+y` north.
    #[default]
    Z,
    /// `+y` up, `−z` north.
    Y,
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
    let bad = |e: solar_positioning::Error| SunError(e.to_string());
    let location = Location {
        latitude: site.latitude,
        longitude: site.longitude,
    };
    let dt = match site.delta_t {
        Some(d) => d,
        None => delta_t::estimate_from_date_like(time).map_err(bad)?,
    };
    let air = match site.air {
        Some((p, t)) => RefractionCorrection::new(p, t).map_err(bad)?,
        None => RefractionCorrection::standard(),
    };
    let p = SolarPositions::new()
        .at(time, location, site.height, dt, Some(air))
        .map_err(bad)?;
    let (az, el) = (p.azimuth(), p.elevation_angle());
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

#[cfg(test)]
mod tests {
    use super::*;

    /// NREL's reference case (Reda & Andreas 2004, table A4.1): Golden,
    /// Colorado, 17 October 2003 12:30:30 local standard time (UTC−7),
    /// 1830.14 m, 820 hPa, 11 °C, ΔT 67 s: topocentric zenith 50.11162°,
    /// azimuth 194.34024°.
    #[test]
    fn nrels_reference_case() {
        let site = SunSite {
            height: 1830.14,
            air: Some((820.0, 11.0)),
            delta_t: Some(67.0),
            ..SunSite::new(39.742476, -105.1786)
        };
        let time = parse_time("2003-10-17T12:30:30-07:00").unwrap();
        let p = sun_position(&site, &time).unwrap();
        assert!((p.azimuth_deg - 194.34024).abs() < 1e-4, "{p:?}");
        assert!((90.0 - p.elevation_deg - 50.11162).abs() < 1e-4, "{p:?}");
        // south-south-west and up, in the default axes
        let d = p.direction;
        assert!(d.y < 0.0 && d.x < 0.0 && d.z > 0.0 && (d.length() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn axes_and_north() {
        let time = parse_time("2026-03-21T12:00:00Z").unwrap();
        // at noon on the equinox at Greenwich, the sun stands south, high
        let p = sun_position(&SunSite::new(51.48, 0.0), &time).unwrap();
        // (the equation of time: solar noon is at about 12:07)
        assert!((p.azimuth_deg - 180.0).abs() < 3.0, "{p:?}");
        assert!(p.direction.y < -0.5 && p.direction.x.abs() < 0.05, "{p:?}");
        // y up: north is -z, so the southern sun is toward +z
        let y_up = SunSite {
            up: Up::Y,
            ..SunSite::new(51.48, 0.0)
        };
        let q = sun_position(&y_up, &time).unwrap();
        assert!(q.direction.z > 0.5 && q.direction.y > 0.5, "{q:?}");
        // north turned by 90 degrees: south lies along -x
        let turned = SunSite {
            north_deg: 90.0,
            ..SunSite::new(51.48, 0.0)
        };
        let r = sun_position(&turned, &time).unwrap();
        assert!(r.direction.x < -0.5, "{r:?}");
        assert!(parse_time("2026-03-21 12:00").is_err());
        let far = SunSite::new(95.0, 0.0);
        assert!(
            sun_position(&far, &time)
                .unwrap_err()
                .to_string()
                .contains("atitude")
        );
    }
}
