//! The crate's error type.

use std::fmt;

/// Errors reading scenes.
///
/// The `Display` form names the file and, for text formats, the 1-based
/// line: `bunny.obj:12: face index 9999 out of range (1..=1839)`.
#[derive(Debug)]
#[non_exhaustive]
pub enum SceneError {
    /// The file could not be read.
    Io {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// The file's content is malformed.
    Parse {
        /// The file.
        path: String,
        /// 1-based line (0 when the format has no lines, as binary STL).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The file extension is not a supported format.
    UnknownFormat {
        /// The file.
        path: String,
    },
}

impl SceneError {
    /// The file the error is about.
    ///
    /// ```
    /// use shadow_scene::parse_obj;
    /// let e = parse_obj("f 1 2 3\n", "tri.obj").unwrap_err();
    /// assert_eq!(e.path(), "tri.obj");
    /// ```
    pub fn path(&self) -> &str {
        match self {
            SceneError::Io { path, .. }
            | SceneError::Parse { path, .. }
            | SceneError::UnknownFormat { path } => path,
        }
    }

    /// The 1-based line of a parse error in a text format, if known.
    ///
    /// ```
    /// use shadow_scene::parse_obj;
    /// let e = parse_obj("v 0 0 0\n\nv 1 x 0\n", "bad.obj").unwrap_err();
    /// assert_eq!(e.line(), Some(3));
    /// ```
    pub fn line(&self) -> Option<usize> {
        match self {
            SceneError::Parse { line, .. } if *line > 0 => Some(*line),
            _ => None,
        }
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SceneError::Io { path, source } => write!(f, "{path}: {source}"),
            SceneError::Parse {
                path,
                line: 0,
                message,
            } => write!(f, "{path}: {message}"),
            SceneError::Parse {
                path,
                line,
                message,
            } => write!(f, "{path}:{line}: {message}"),
            SceneError::UnknownFormat { path } => write!(
                f,
                "{path}: unknown mesh format (expected .obj or .stl; CityJSON .json is read, not written)"
            ),
        }
    }
}

impl std::error::Error for SceneError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            SceneError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_names_file_and_line() {
        let e = SceneError::Parse {
            path: "bunny.obj".into(),
            line: 12,
            message: "face index 9999 out of range (1..=1839)".into(),
        };
        assert_eq!(
            e.to_string(),
            "bunny.obj:12: face index 9999 out of range (1..=1839)"
        );
        let e = SceneError::Parse {
            path: "part.stl".into(),
            line: 0,
            message: "invalid STL".into(),
        };
        assert_eq!(e.to_string(), "part.stl: invalid STL");
        assert_eq!(e.line(), None);
        let e = SceneError::UnknownFormat {
            path: "x.ply".into(),
        };
        assert!(e.to_string().starts_with("x.ply: unknown mesh format"));
    }

    #[test]
    fn io_error_keeps_its_source() {
        let e = SceneError::Io {
            path: "gone.obj".into(),
            source: std::io::Error::new(std::io::ErrorKind::NotFound, "not found"),
        };
        assert_eq!(e.to_string(), "gone.obj: not found");
        assert!(std::error::Error::source(&e).is_some());
    }
}
