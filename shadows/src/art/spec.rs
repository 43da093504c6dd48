//! The shadow-art SPEC file and its images: JSON, and PGM (P2, P5) or
//! PNG pictures thresholded into masks.

use std::path::{Path, PathBuf};

use glam::DVec3;
use serde_json::Value;

use super::region::Mask;
use super::{ArtError, ArtLight, ArtSpec, ArtView, ViewPlane};

impl ArtSpec {
    /// Reads `path` and the images it names (relative to its folder).
    pub fn load(path: &Path) -> Result<ArtSpec, ArtError> {
        let text = std::fs::read_to_string(path).map_err(|e| ArtError::Read {
            path: path.to_path_buf(),
            cause: e,
        })?;
        let base = path.parent().unwrap_or(Path::new("."));
        ArtSpec::from_json(&text, base).map_err(|e| match e {
            ArtError::Spec(m) => ArtError::Spec(format!("{}: {m}", path.display())),
            e => e,
        })
    }

    /// The spec of JSON `text`, its images' paths relative to `base`.
    pub fn from_json(text: &str, base: &Path) -> Result<ArtSpec, ArtError> {
        // (JSON has no byte-order mark, but some tools write one)
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let json: Value =
            serde_json::from_str(text).map_err(|e| ArtError::Spec(format!("not JSON: {e}")))?;
        let views = json
            .get("views")
            .and_then(Value::as_array)
            .ok_or_else(|| ArtError::Spec("no \"views\" list".into()))?;
        if views.is_empty() {
            return Err(ArtError::Spec("\"views\" is empty".into()));
        }
        let bounds = json
            .get("bounds")
            .and_then(Value::as_array)
            .filter(|b| b.len() == 2)
            .ok_or_else(|| {
                ArtError::Spec("\"bounds\" must be [[xmin, ymin, zmin], [xmax, ymax, zmax]]".into())
            })?;
        let lo = vec3(&bounds[0], "bounds[0]")?;
        let hi = vec3(&bounds[1], "bounds[1]")?;
        if !(lo.cmplt(hi).all()) {
            return Err(ArtError::Spec(format!(
                "\"bounds\": every minimum must be below its maximum ({lo} against {hi})"
            )));
        }
        let views = views
            .iter()
            .enumerate()
            .map(|(i, v)| view(v, base).map_err(|e| e.in_view(i)))
            .collect::<Result<_, _>>()?;
        Ok(ArtSpec {
            views,
            bounds: [lo, hi],
            simplify: None,
        })
    }
}

/// Three finite numbers.
fn vec3(v: &Value, what: &str) -> Result<DVec3, ArtError> {
    let a = v
        .as_array()
        .filter(|a| a.len() == 3)
        .and_then(|a| a.iter().map(Value::as_f64).collect::<Option<Vec<f64>>>())
        .filter(|a| a.iter().all(|x| x.is_finite()))
        .ok_or_else(|| ArtError::Spec(format!("\"{what}\" must be three finite numbers")))?;
    Ok(DVec3::new(a[0], a[1], a[2]))
}

/// One view of the spec.
fn view(v: &Value, base: &Path) -> Result<ArtView, ArtError> {
    let image = v
        .get("image")
        .and_then(Value::as_str)
        .ok_or_else(|| ArtError::Spec("no \"image\"".into()))?;
    let light = v
        .get("light")
        .ok_or_else(|| ArtError::Spec("no \"light\"".into()))?;
    let light = match (light.get("sun"), light.get("point")) {
        (Some(d), None) => ArtLight::Sun(vec3(d, "light.sun")?),
        (None, Some(p)) => ArtLight::Point(vec3(p, "light.point")?),
        _ => {
            return Err(ArtError::Spec(
                "\"light\" must be {\"sun\": [dx, dy, dz]} or {\"point\": [x, y, z]}".into(),
            ));
        }
    };
    if let ArtLight::Sun(d) = light
        && d == DVec3::ZERO
    {
        return Err(ArtError::Spec("\"light.sun\" has no direction".into()));
    }
    let plane = v
        .get("plane")
        .ok_or_else(|| ArtError::Spec("no \"plane\"".into()))?;
    let plane = ViewPlane {
        origin: vec3(plane.get("origin").unwrap_or(&Value::Null), "plane.origin")?,
        u: vec3(plane.get("u").unwrap_or(&Value::Null), "plane.u")?,
        v: vec3(plane.get("v").unwrap_or(&Value::Null), "plane.v")?,
    };
    let threshold = match v.get("threshold") {
        None => 128.0,
        Some(t) => t
            .as_f64()
            .filter(|t| (0.0..=65536.0).contains(t))
            .ok_or_else(|| ArtError::Spec("\"threshold\" must be a number from 0".into()))?,
    };
    let path = base.join(image);
    let mask = read_mask(&path, threshold)?;
    Ok(ArtView {
        image: path,
        light,
        plane,
        mask,
    })
}

/// The pixels of the image at `path` darker than `threshold`.
pub fn read_mask(path: &Path, threshold: f64) -> Result<Mask, ArtError> {
    let bytes = std::fs::read(path).map_err(|e| ArtError::Read {
        path: path.to_path_buf(),
        cause: e,
    })?;
    let bad = |m: String| ArtError::Image {
        path: path.to_path_buf(),
        message: m,
    };
    let (width, height, values) = if bytes.starts_with(b"\x89PNG") {
        png_values(&bytes).map_err(bad)?
    } else if bytes.starts_with(b"P2") || bytes.starts_with(b"P5") {
        pgm_values(&bytes).map_err(bad)?
    } else {
        return Err(bad("not a PGM (P2, P5) or PNG image".into()));
    };
    if width == 0 || height == 0 {
        return Err(bad("the image has no pixels".into()));
    }
    Ok(Mask {
        width,
        height,
        wanted: values.into_iter().map(|v| v < threshold).collect(),
    })
}

/// A PGM's size and grey values (P2 text or P5 binary, 8 or 16 bits).
fn pgm_values(bytes: &[u8]) -> Result<(u32, u32, Vec<f64>), String> {
    // the header: magic, width, height, maxval, with # comments
    let mut fields = Vec::new();
    let mut i = 2;
    while fields.len() < 3 {
        while i < bytes.len() && bytes[i].is_ascii_whitespace() {
            i += 1;
        }
        if i < bytes.len() && bytes[i] == b'#' {
            while i < bytes.len() && bytes[i] != b'\n' {
                i += 1;
            }
            continue;
        }
        let start = i;
        while i < bytes.len() && bytes[i].is_ascii_digit() {
            i += 1;
        }
        let field = std::str::from_utf8(&bytes[start..i]).unwrap_or("");
        fields.push(
            field
                .parse::<u32>()
                .map_err(|_| "a broken PGM header".to_string())?,
        );
    }
    let (w, h, max) = (fields[0], fields[1], fields[2]);
    if max == 0 || max > 65535 {
        return Err(format!("a PGM maximum of {max}"));
    }
    let n = w as usize * h as usize;
    // values scaled to 0..=255, as the threshold reads them
    let scale = 255.0 / f64::from(max);
    let values: Vec<f64> = if bytes[1] == b'5' {
        let data = &bytes[(i + 1).min(bytes.len())..];
        let wide = max > 255;
        let need = if wide { 2 * n } else { n };
        if data.len() < need {
            return Err(format!(
                "{} bytes of pixels where {w}×{h} need {need}",
                data.len()
            ));
        }
        if wide {
            data.chunks(2)
                .take(n)
                .map(|b| f64::from(u16::from_be_bytes([b[0], b[1]])) * scale)
                .collect()
        } else {
            data[..n].iter().map(|&b| f64::from(b) * scale).collect()
        }
    } else {
        let text = std::str::from_utf8(&bytes[i..])
            .map_err(|_| "a P2 PGM that is not text".to_string())?;
        let v: Vec<f64> = text
            .split_ascii_whitespace()
            .take(n)
            .map(|t| t.parse::<u32>().map(|x| f64::from(x) * scale))
            .collect::<Result<_, _>>()
            .map_err(|_| "a P2 pixel that is not a number".to_string())?;
        if v.len() < n {
            return Err(format!("{} pixels where {w}×{h} need {n}", v.len()));
        }
        v
    };
    Ok((w, h, values))
}

/// A PNG's size and grey values (0..=255): colour as luma, over white
/// where it is transparent.
fn png_values(bytes: &[u8]) -> Result<(u32, u32, Vec<f64>), String> {
    let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().map_err(|e| e.to_string())?;
    let size = reader.output_buffer_size().ok_or("a PNG too large")?;
    let mut buf = vec![0; size];
    let info = reader.next_frame(&mut buf).map_err(|e| e.to_string())?;
    let channels = info.color_type.samples();
    let px = buf[..info.buffer_size()].chunks(channels);
    let luma =
        |c: &[u8]| 0.299 * f64::from(c[0]) + 0.587 * f64::from(c[1]) + 0.114 * f64::from(c[2]);
    let values = px
        .map(|c| {
            let (grey, alpha) = match c.len() {
                1 => (f64::from(c[0]), 255.0),
                2 => (f64::from(c[0]), f64::from(c[1])),
                3 => (luma(c), 255.0),
                _ => (luma(c), f64::from(c[3])),
            };
            let a = alpha / 255.0;
            grey * a + 255.0 * (1.0 - a)
        })
        .collect();
    Ok((info.width, info.height, values))
}

/// Where a view's image came from, for messages.
pub(crate) fn name(p: &Path) -> String {
    PathBuf::from(p).display().to_string()
}
