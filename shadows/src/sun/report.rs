//! What `shadow sunhours` writes and says of a study: the hours of
//! faces, sensors or regions ([`HoursOf`]) in the format the output's
//! name asks for ([`hours_report`]).

use glam::DVec3;

use super::{
    HeatView, HoursFormat, RegionFaces, SENSORS_NOT_A_PICTURE, SunPath, bre209_text,
    clip_to_outline, disc_study, faces_study, groups_in_sun_text, interval_hours, intervals_json,
    region_in_sun_text, region_study, regions_csv, regions_json, regions_obj, regions_ply,
    regions_png, sensor_hours_file, sensor_intervals_facing, sensors_csv, sensors_obj, sensors_ply,
};

/// What `shadow sunhours` writes and says of a study.
#[derive(Clone, Debug, PartialEq)]
pub struct HoursReport {
    /// The file's contents: text with one row per face or per sensor, a
    /// heat map in OBJ, or a picture in PNG.
    pub bytes: Vec<u8>,
    /// What the rows are, in words (`"6 faces"`, `"4 sensors among the
    /// faces"`).
    pub rows: String,
    /// Per group, the share that sees at least the hours asked for, one
    /// line each ([`groups_in_sun_text`]; empty for sensors or no hours).
    pub groups: String,
}

/// What a study reports the hours of.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum HoursOf<'a> {
    /// Every face: with the least and most hours of its points and the
    /// area per hours ([`sun_hours`](super::sun_hours)), or without them,
    /// for the cost of the shadows alone
    /// ([`sun_hours_mean`](super::sun_hours_mean): NaN in the data, empty
    /// in CSV, `null` in JSON).
    Faces {
        /// Whether to overlay the runs for the extremes.
        extremes: bool,
        /// The scene cut into this many tiles a side, each run shading
        /// one tile ([`sun_hours_in_tiles`](super::sun_hours_in_tiles);
        /// 1: not cut).
        tiles: usize,
    },
    /// Every face's mean hours with the sun a disc of this radius in
    /// degrees ([`sun_hours_disc`](super::sun_hours_disc); no extremes).
    DiscFaces {
        /// The disc's angular radius, degrees.
        radius_deg: f64,
    },
    /// The sensors of this file ([`sensor_hours_file`]).
    Sensors(&'a std::path::Path),
    /// The sensors of this file, each day's sun-on intervals in closed
    /// form on these paths ([`sensor_intervals_facing`]; JSON lists them).
    ExactSensors {
        /// The file.
        path: &'a std::path::Path,
        /// The days.
        paths: &'a [SunPath],
    },
    /// The cells of these faces ([`region_hours`](super::region_hours)),
    /// with the BRE 209 verdict if asked ([`bre209_text`]).
    Regions {
        /// The faces.
        faces: &'a RegionFaces,
        /// Whether to say the verdict.
        bre209: bool,
        /// A file of points outlining the region seen from above (such
        /// as a garden across a ground face): the cells cut to it
        /// ([`clip_to_outline`]).
        outline: Option<&'a std::path::Path>,
    },
}

impl<'a> HoursOf<'a> {
    /// At `sensors` if given, else on the faces of `regions` if given
    /// (with the BRE 209 verdict if `bre209`), else on every face (with
    /// their `extremes` if asked).
    pub fn of(
        sensors: Option<&'a std::path::Path>,
        regions: Option<&'a RegionFaces>,
        bre209: bool,
        extremes: bool,
    ) -> HoursOf<'a> {
        match (sensors, regions) {
            (Some(path), _) => HoursOf::Sensors(path),
            (None, Some(faces)) => HoursOf::Regions {
                faces,
                bre209,
                outline: None,
            },
            (None, None) => HoursOf::Faces { extremes, tiles: 1 },
        }
    }

    /// Sensors' hours with no time sampling, on `paths`, if given (for
    /// anything but sensors, `self`).
    pub fn exact_time(self, paths: Option<&'a [SunPath]>) -> HoursOf<'a> {
        match (self, paths) {
            (HoursOf::Sensors(path), Some(paths)) => HoursOf::ExactSensors { path, paths },
            _ => self,
        }
    }

    /// Regions' cells cut to the outline in the points file `path`, if
    /// given (for anything but regions, `self`).
    pub fn outline(self, path: Option<&'a std::path::Path>) -> HoursOf<'a> {
        match self {
            HoursOf::Regions { faces, bre209, .. } if path.is_some() => HoursOf::Regions {
                faces,
                bre209,
                outline: path,
            },
            _ => self,
        }
    }

    /// Faces' hours with the scene cut into `per_side × per_side` tiles
    /// (for anything but faces' hours with point suns, `self`).
    pub fn tiles(self, per_side: usize) -> HoursOf<'a> {
        match self {
            HoursOf::Faces { extremes, .. } => HoursOf::Faces {
                extremes,
                tiles: per_side,
            },
            _ => self,
        }
    }

    /// Faces' hours with the sun a disc of `radius_deg`, if given (for
    /// anything but faces' hours, `self`).
    pub fn sun_disc(self, radius_deg: Option<f64>) -> HoursOf<'a> {
        match (self, radius_deg) {
            (HoursOf::Faces { .. }, Some(radius_deg)) => HoursOf::DiscFaces { radius_deg },
            _ => self,
        }
    }
}

impl HoursReport {
    /// What `shadow sunhours` says when it has written the report to
    /// `output`: the rows, the scene's `name`, the study's days and suns,
    /// then the shares' lines.
    pub fn said(&self, output: &std::path::Path, name: &str, days: usize, suns: usize) -> String {
        let (out, rows) = (output.display(), &self.rows);
        let said =
            format!("wrote {out}: sun-hours of {rows} of {name}, {days} days, {suns} suns\n");
        said + &self.groups
    }
}

/// The study's hours of `of`, to be written to `output` in the format its
/// name asks for ([`HoursFormat::for_path`]; a picture of the faces
/// only); with `min_hours`, the shares of the groups (or of the region)
/// that see at least that many hours. A picture looks at the scene as
/// `view` says.
#[allow(clippy::too_many_arguments)] // (the study, the output, and what to tell)
pub fn hours_report(
    mesh: &crate::Mesh,
    suns: &[DVec3],
    step_hours: f64,
    output: &std::path::Path,
    of: HoursOf<'_>,
    min_hours: Option<f64>,
    view: HeatView,
    progress: &dyn crate::shadow_file::Progress,
) -> Result<HoursReport, crate::Error> {
    let format = HoursFormat::for_path(output)?;
    let sensors = matches!(of, HoursOf::Sensors(_) | HoursOf::ExactSensors { .. });
    if format == HoursFormat::Png && sensors {
        return Err(crate::Error::Format {
            path: output.to_path_buf(),
            why: SENSORS_NOT_A_PICTURE,
        });
    }
    let report = |text: String, rows: String, groups: String| HoursReport {
        bytes: text.into_bytes(),
        rows,
        groups,
    };
    match of {
        HoursOf::Sensors(path) => {
            let (text, n) = sensor_hours_file(mesh, path, suns, step_hours, format)?;
            Ok(report(
                text,
                format!("{n} sensors among the faces"),
                String::new(),
            ))
        }
        HoursOf::ExactSensors { path, paths } => {
            let sensors = shadow_scene::read_sensors(path).map_err(crate::Error::File)?;
            let on = sensor_intervals_facing(mesh, &sensors, paths);
            let points = super::Sensor::positions(&sensors);
            let text = match format {
                HoursFormat::Json => intervals_json(&points, paths, &on),
                HoursFormat::Csv => sensors_csv(&points, &interval_hours(&on)),
                HoursFormat::Ply => sensors_ply(&points, &interval_hours(&on)),
                _ => sensors_obj(&points, &interval_hours(&on)), // (Png refused above)
            };
            let rows = format!("{} sensors among the faces, exact time", points.len());
            Ok(report(text, rows, String::new()))
        }
        HoursOf::Regions {
            faces,
            bre209,
            outline,
        } => {
            let ids = faces.faces(mesh)?;
            let mut cells = region_study(mesh, suns, step_hours, &ids, progress)?;
            if let Some(path) = outline {
                let points = shadow_scene::read_points(path).map_err(crate::Error::File)?;
                cells = clip_to_outline(&cells, &points, view.up)?;
            }
            let bytes = match format {
                HoursFormat::Csv => regions_csv(mesh, &cells).into_bytes(),
                HoursFormat::Json => regions_json(&cells, suns.len()).into_bytes(),
                HoursFormat::Obj => regions_obj(&cells).into_bytes(),
                HoursFormat::Ply => regions_ply(&cells).into_bytes(),
                HoursFormat::Png => regions_png(mesh, &ids, &cells, suns.len(), view)?,
            };
            let mut lines = min_hours.map_or(String::new(), |h| region_in_sun_text(&cells, h));
            if bre209 {
                lines += &bre209_text(&cells);
            }
            let rows = format!("{} cells of {} faces", cells.len(), ids.len());
            Ok(HoursReport {
                bytes,
                rows,
                groups: lines,
            })
        }
        HoursOf::Faces { .. } | HoursOf::DiscFaces { .. } => {
            let extremes = matches!(of, HoursOf::Faces { extremes: true, .. });
            if !extremes && min_hours.is_some() {
                return Err(crate::Error::Region(
                    "the area that sees at least so many hours needs the extremes' overlay".into(),
                ));
            }
            let (disc, tiles) = match of {
                HoursOf::DiscFaces { radius_deg } => (Some(radius_deg), 1),
                HoursOf::Faces { tiles, .. } => (None, tiles),
                _ => (None, 1),
            };
            let hours = match disc {
                Some(r) => disc_study(mesh, suns, step_hours, r, progress)?,
                None => faces_study(mesh, suns, step_hours, extremes, tiles, progress)?,
            };
            let bytes = format.bytes(mesh, &hours, suns.len(), view)?;
            Ok(HoursReport {
                bytes,
                rows: format!("{} faces", hours.len()),
                groups: groups_in_sun_text(mesh, &hours, min_hours),
            })
        }
    }
}
