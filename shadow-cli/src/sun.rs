//! `shadow sun`: where the sun is, in the scene's axes (the work is
//! `bsp_shadows::sun`'s).

use anyhow::Result;
use bsp_shadows::sun::{SunSite, Up, parse_time, sun_position};
use clap::Args;

use crate::output::emit;

#[derive(Args, Debug)]
pub(crate) struct SunArgs {
    /// Latitude, degrees north.
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    lat: f64,
    /// Longitude, degrees east.
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    lon: f64,
    /// The time with its offset, such as 2026-03-21T12:00:00+01:00.
    #[arg(long, value_name = "TIME")]
    time: String,
    /// True north, degrees clockwise from the scene's north (+y; -z with --up y).
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    north: f64,
    /// The scene's up axis: z (+y north) or y (-z north) [default: z].
    #[arg(long, value_name = "AXIS", value_parser = ["z", "y"])]
    up: Option<String>,
    /// Print one JSON object (azimuth, elevation, direction).
    #[arg(long)]
    json: bool,
    /// (Nothing to quiet: the answer is on stdout.)
    #[arg(long, short)]
    quiet: bool,
}

/// `shadow sun`.
pub(crate) fn run(a: &SunArgs) -> Result<()> {
    let up = if a.up.as_deref() == Some("y") {
        Up::Y
    } else {
        Up::Z
    };
    let site = SunSite {
        north_deg: a.north,
        up,
        ..SunSite::new(a.lat, a.lon)
    };
    let p = sun_position(&site, &parse_time(&a.time)?)?;
    emit(&((if a.json { p.json() } else { p.text() }) + "\n"))
}
