//! `shadow sun` and `shadow sunhours`: where the sun is, in the scene's
//! axes, and every face's sun-hours over days (the work is
//! `bsp_shadows::sun`'s).

use std::path::PathBuf;

use anyhow::Result;
use bsp_shadows::sun::{self as sun, HoursOf, SunSite, Up};
use clap::Args;

use crate::args::SourceArgs;
use crate::facade_error;
use crate::input::load_source_quiet;
use crate::output::{emit, write_file};
use crate::progress::Progress;

/// Where the study is, and how the scene sits there.
#[derive(Args, Debug)]
pub(crate) struct SiteArgs {
    /// Latitude, degrees north.
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    lat: f64,
    /// Longitude, degrees east.
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    lon: f64,
    /// True north, degrees clockwise from the scene's north (+y; -z with --up y) [default: 0].
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    north: Option<f64>,
    /// The scene's up axis: z (+y north) or y (-z north) [default: z].
    #[arg(long, value_name = "AXIS")]
    up: Option<Up>,
}

impl SiteArgs {
    fn site(&self) -> SunSite {
        SunSite::new(self.lat, self.lon)
            .with_axes(self.north.unwrap_or(0.0), self.up.unwrap_or_default())
    }
}

#[derive(Args, Debug)]
pub(crate) struct SunArgs {
    #[command(flatten)]
    site: SiteArgs,
    /// The time with its offset, such as 2026-03-21T12:00:00+01:00.
    #[arg(long, value_name = "TIME")]
    time: String,
    /// Print one JSON object (azimuth, elevation, direction).
    #[arg(long)]
    json: bool,
    /// (Nothing to quiet: the answer is on stdout.)
    #[arg(long, short)]
    quiet: bool,
}

/// `shadow sun`.
pub(crate) fn run(a: &SunArgs) -> Result<()> {
    let p = sun::sun_position(&a.site.site(), &sun::parse_time(&a.time)?)?;
    emit(&((if a.json { p.json() } else { p.text() }) + "\n"))
}

#[derive(Args, Debug)]
pub(crate) struct SunHoursArgs {
    #[command(flatten)]
    source: SourceArgs,
    #[command(flatten)]
    site: SiteArgs,
    /// The (first) day, YYYY-MM-DD.
    #[arg(long, value_name = "DATE")]
    date: String,
    /// The last day [default: --date].
    #[arg(long, value_name = "DATE")]
    to: Option<String>,
    /// Days from one studied day to the next.
    #[arg(long, value_name = "DAYS", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    every: u32,
    /// Minutes between suns, each at its interval's midpoint, from 1/60 (a second) to 1440 [default: 10].
    #[arg(long, value_name = "MIN")]
    step: Option<f64>,
    /// The days' clock, hours east of UTC [default: 0].
    #[arg(long, value_name = "H", allow_hyphen_values = true)]
    utc_offset: Option<f64>,
    /// Sensors' hours with no time sampling: each day's sun-on intervals in closed form (JSON lists them).
    #[arg(long, requires = "sensors")]
    exact_time: bool,
    /// Also say how much of each group (or of the regions) sees at least H hours.
    #[arg(long, value_name = "H")]
    min_hours: Option<f64>,
    /// Hours at sensors instead of faces: a file of x,y,z lines, or x,y,z,nx,ny,nz with the normal of the surface a sensor stands for (it then counts only the suns in front of it; a header line may lead).
    #[arg(long, value_name = "FILE")]
    sensors: Option<PathBuf>,
    /// Hours of the cells of these faces instead (a group, or ids such as 1,4,7-9): every step's lit parts overlaid.
    #[arg(long, value_name = "GROUP|IDS", conflicts_with = "sensors")]
    regions: Option<sun::RegionFaces>,
    /// Cut the regions to this outline seen from above (a file of x,y,z points, such as a garden's corners).
    #[arg(long, value_name = "FILE", requires = "regions")]
    outline: Option<PathBuf>,
    /// Say whether the regions pass the BRE 209 garden test: half their area 2 hours in sun on 21 March.
    #[arg(long, requires = "regions")]
    bre209: bool,
    /// The sun as a disc of DEG degrees [default: 0.2666]: faces' mean hours with its penumbra's share (slow).
    #[arg(long, value_name = "DEG", num_args = 0..=1, default_missing_value = "0.2666", conflicts_with_all = ["sensors", "regions", "min_hours"])]
    sun_disc: Option<f64>,
    /// Faces' mean hours only, for the cost of the shadows: no least and most hours (empty in CSV).
    #[arg(long, conflicts_with_all = ["min_hours", "regions"])]
    no_extremes: bool,
    /// Cut the scene into N × N tiles, each run shading one tile past only what may shade it (less memory a run; the areas' last bits may differ) [default: 1].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1024), conflicts_with_all = ["sensors", "regions", "sun_disc"])]
    tiles: Option<u32>,
    /// Output: CSV (one row per face, or per sensor), JSON, OBJ or PLY (a heat map) or PNG (its picture).
    #[arg(short, long, value_name = "OUT.csv|OUT.json|OUT.obj|OUT.ply|OUT.png")]
    output: PathBuf,
    /// No notes on stderr (errors still go there).
    #[arg(long, short)]
    quiet: bool,
}

/// `shadow sunhours`.
pub(crate) fn run_hours(a: &SunHoursArgs) -> Result<()> {
    let (mesh, name) = load_source_quiet(&a.source, a.quiet)?;
    let view = sun::HeatView::of(mesh.bounds().and_then(|b| a.source.staging(b)), a.site.up);
    let dates = sun::study_dates(&a.date, a.to.as_deref(), a.every)?;
    sun::check_bre209(a.bre209, &dates).map_err(facade_error)?;
    let (step, offset) = (a.step.unwrap_or(10.0), a.utc_offset.unwrap_or(0.0));
    if let Some(h) = a.min_hours
        && !h.is_finite()
    {
        anyhow::bail!("--min-hours {h}: give a number of hours");
    }
    // (a coarse step is allowed, but its error is not small: one sun a
    // day at noon counts the whole day as sunny)
    if step > 60.0 {
        crate::output::note(
            a.quiet,
            &format!(
                "note: each sun stands for {step} minutes: a point's hours may be off by up to \
                 {} minutes wherever its sun begins or ends (sunrise, sunset, a shadow's edge)",
                step / 2.0
            ),
        );
    }
    let (dirs, paths) = sun::study_plan(&a.site.site(), &dates, step, offset, a.exact_time)?;
    let (sensors, regions) = (a.sensors.as_deref(), a.regions.as_ref());
    let of = HoursOf::of(sensors, regions, a.bre209, !a.no_extremes).exact_time(paths.as_deref());
    let of = of.sun_disc(a.sun_disc).outline(a.outline.as_deref());
    let of = of.tiles(a.tiles.unwrap_or(1) as usize);
    let progress = Progress::new(!a.quiet);
    let (out, hours) = (&a.output, a.min_hours);
    let r = sun::hours_report(&mesh, &dirs, step / 60.0, out, of, hours, view, &progress);
    let r = r.map_err(facade_error)?;
    drop(progress);
    write_file(&a.output, &r.bytes)?;
    emit(&r.said(&a.output, &name, dates.len(), dirs.len()))
}
