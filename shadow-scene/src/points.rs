//! Files of points: sensors for sun studies, one point a line.

use std::path::Path;

use glam::DVec3;

use crate::SceneError;

/// Reads a file of points ([`parse_points`]).
pub fn read_points(path: &Path) -> Result<Vec<DVec3>, SceneError> {
    let shown = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
        path: shown.clone(),
        source,
    })?;
    parse_points(&text, &shown)
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
        if fields.len() != 3 {
            let n = fields.len();
            return Err(error(
                i + 1,
                format!("`{line}` has {n} numbers; a point is x,y,z"),
            ));
        }
        let mut p = [0.0; 3];
        for (k, (field, number)) in fields.iter().zip(&numbers).enumerate() {
            match number {
                Some(x) if x.is_finite() => p[k] = *x,
                _ => return Err(error(i + 1, format!("`{field}` is not a finite number"))),
            }
        }
        out.push(DVec3::from_array(p));
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
        let e = read_points(Path::new("/no/such/points.csv")).unwrap_err();
        assert!(e.to_string().starts_with("/no/such/points.csv: "), "{e}");
    }
}
