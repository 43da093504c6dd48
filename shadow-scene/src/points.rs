//! Files of points: sensors for sun studies, one point a line.

use std::path::Path;

use glam::DVec3;

use crate::SceneError;

/// Reads a file of points ([`parse_points`]).
pub fn read_points(path: &Path) -> Result<Vec<DVec3>, SceneError> {
    let (text, shown) = read_text(path)?;
    parse_points(&text, &shown)
}

/// A file's text, and its path as messages name it.
fn read_text(path: &Path) -> Result<(String, String), SceneError> {
    let shown = path.display().to_string();
    match std::fs::read_to_string(path) {
        Ok(text) => Ok((text, shown)),
        Err(source) => Err(SceneError::Io {
            path: shown,
            source,
        }),
    }
}

/// Points from text, one a line: `x,y,z` or `x y z` (commas, spaces or
/// tabs between). Blank lines and lines starting with `#` are skipped, and
/// so is a first line with no number in it (a CSV header such as
/// `x,y,z`). Errors name the file and the line.
///
/// ```
/// let p = shadow_scene::parse_points("x,y,z\n1,2,3\n# a comment\n4 5 6.5\n", "s.csv").unwrap();
/// assert_eq!(p.len(), 2);
/// assert_eq!(p[1].z, 6.5);
/// let e = shadow_scene::parse_points("1,2\n", "s.csv").unwrap_err();
/// assert_eq!(e.to_string(), "s.csv:1: `1,2` has 2 numbers; a point is x,y,z");
/// ```
pub fn parse_points(text: &str, path_for_messages: &str) -> Result<Vec<DVec3>, SceneError> {
    let rows = parse_rows(text, path_for_messages, |n| n == 3, "a point is x,y,z")?;
    Ok(rows
        .into_iter()
        .map(|(_, r)| DVec3::from_slice(&r))
        .collect())
}

/// A sensor of a sun study: a point, and where given, the normal of the
/// surface it stands for (a window, a panel): it then counts only the
/// suns strictly in front of that surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sensor {
    /// Where it is.
    pub position: DVec3,
    /// The way its surface faces (any length but zero), if given.
    pub normal: Option<DVec3>,
}

impl Sensor {
    /// A sensor at `position`, facing `normal` where given; `None` for a
    /// zero normal, which faces no way.
    pub fn new(position: DVec3, normal: Option<DVec3>) -> Option<Sensor> {
        (normal != Some(DVec3::ZERO)).then_some(Sensor { position, normal })
    }

    /// The sensors' positions, in order.
    pub fn positions(sensors: &[Sensor]) -> Vec<DVec3> {
        sensors.iter().map(|s| s.position).collect()
    }
}

/// A point as a sensor that counts the sun from every side.
impl From<DVec3> for Sensor {
    fn from(position: DVec3) -> Sensor {
        Sensor {
            position,
            normal: None,
        }
    }
}

/// Reads a file of sensors ([`parse_sensors`]).
pub fn read_sensors(path: &Path) -> Result<Vec<Sensor>, SceneError> {
    let (text, shown) = read_text(path)?;
    parse_sensors(&text, &shown)
}

/// Sensors from text, one a line: `x,y,z` (a point that counts the sun
/// from every side) or `x,y,z,nx,ny,nz` (with its surface's normal), read
/// as [`parse_points`] reads points; a normal must not be zero.
///
/// ```
/// let s = shadow_scene::parse_sensors("x,y,z,nx,ny,nz\n1,2,3,0,0,1\n4 5 6\n", "s.csv").unwrap();
/// assert_eq!(s[0].normal, Some(glam::DVec3::Z));
/// assert_eq!(s[1].normal, None);
/// let e = shadow_scene::parse_sensors("1,2,3,0,0,0\n", "s.csv").unwrap_err();
/// assert_eq!(e.to_string(), "s.csv:1: `1,2,3,0,0,0`: the sensor's normal is zero");
/// ```
pub fn parse_sensors(text: &str, path_for_messages: &str) -> Result<Vec<Sensor>, SceneError> {
    let rows = parse_rows(
        text,
        path_for_messages,
        |n| n == 3 || n == 6,
        "a sensor is x,y,z or x,y,z,nx,ny,nz",
    )?;
    rows.into_iter()
        .map(|(line, r)| {
            let normal = (r.len() == 6).then(|| DVec3::from_slice(&r[3..]));
            Sensor::new(DVec3::from_slice(&r), normal).ok_or_else(|| {
                let text = r.iter().map(f64::to_string).collect::<Vec<_>>().join(",");
                SceneError::Parse {
                    path: path_for_messages.to_string(),
                    line,
                    message: format!("`{text}`: the sensor's normal is zero"),
                }
            })
        })
        .collect()
}

/// The rows of numbers of a file of points, each with its line number:
/// `count_ok` says how many numbers a row may have (`shape` says it in
/// the error).
fn parse_rows(
    text: &str,
    path_for_messages: &str,
    count_ok: impl Fn(usize) -> bool,
    shape: &str,
) -> Result<Vec<(usize, Vec<f64>)>, SceneError> {
    let error = |line: usize, message: String| SceneError::Parse {
        path: path_for_messages.to_string(),
        line,
        message,
    };
    // (a byte-order mark some spreadsheets write is no number)
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut out = Vec::new();
    let mut first = true;
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = (line.split([',', ' ', '\t']))
            .filter(|f| !f.is_empty())
            .collect();
        let numbers: Vec<Option<f64>> = fields.iter().map(|f| f.parse::<f64>().ok()).collect();
        if std::mem::take(&mut first) && numbers.iter().all(Option::is_none) {
            continue;
        }
        if !count_ok(fields.len()) {
            let n = fields.len();
            return Err(error(i + 1, format!("`{line}` has {n} numbers; {shape}")));
        }
        let mut row = Vec::with_capacity(fields.len());
        for (field, number) in fields.iter().zip(&numbers) {
            match number {
                Some(x) if x.is_finite() => row.push(*x),
                _ => return Err(error(i + 1, format!("`{field}` is not a finite number"))),
            }
        }
        out.push((i + 1, row));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_byte_order_mark_is_no_number() {
        let p = super::parse_points("\u{feff}1,2,3\n4,5,6\n", "bom.csv").unwrap();
        assert_eq!(
            p,
            [glam::DVec3::new(1., 2., 3.), glam::DVec3::new(4., 5., 6.)]
        );
    }

    use super::*;

    #[test]
    fn headers_comments_and_errors() {
        let p = parse_points("# sensors\n\n0 0 1.5\n\t2,\t3, 4\n", "g.xyz").unwrap();
        assert_eq!(
            p,
            vec![DVec3::new(0.0, 0.0, 1.5), DVec3::new(2.0, 3.0, 4.0)]
        );
        // a header only as the first line
        let e = parse_points("1 2 3\nx y z\n", "g.xyz").unwrap_err();
        assert_eq!(e.line(), Some(2));
        assert!(e.to_string().contains("`x` is not a finite number"), "{e}");
        let e = parse_points("1 2 inf\n", "g.xyz").unwrap_err();
        assert!(e.to_string().starts_with("g.xyz:1: `inf`"), "{e}");
        assert!(parse_points("", "g.xyz").unwrap().is_empty());
        // a point has three numbers; a sensor three, or six with a normal
        let e = parse_points("1 2 3 0 0 1\n", "g.xyz").unwrap_err();
        assert!(
            e.to_string().ends_with("has 6 numbers; a point is x,y,z"),
            "{e}"
        );
        let s = parse_sensors("1 2 3 0 0 2\n1 2 3\n", "s.csv").unwrap();
        assert_eq!(s[0].normal, Some(DVec3::new(0.0, 0.0, 2.0)));
        assert_eq!(s[1].normal, None);
        assert_eq!(s[1].position, DVec3::new(1.0, 2.0, 3.0));
        let e = parse_sensors("x,y,z\n1 2 3 0 1\n", "s.csv").unwrap_err();
        assert_eq!(e.line(), Some(2));
        assert!(
            e.to_string()
                .ends_with("a sensor is x,y,z or x,y,z,nx,ny,nz"),
            "{e}"
        );
        let e = parse_sensors("1 2 3 0 nan 1\n", "s.csv").unwrap_err();
        assert!(
            e.to_string().contains("`nan` is not a finite number"),
            "{e}"
        );
        let e = read_points(Path::new("/no/such/points.csv")).unwrap_err();
        assert!(e.to_string().starts_with("/no/such/points.csv: "), "{e}");
    }
}
