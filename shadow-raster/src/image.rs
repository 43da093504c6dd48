//! Images: Lambert shading of a visibility and a lit buffer, PNG and PGM
//! output, side-by-side composites with labels.

use std::io::Write;
use std::path::Path;

use glam::DVec3;

use crate::RasterError;
use crate::hsr::{Frame, NONE, VisibilityBuffer};
use crate::lit::{LitBuffer, visible_normal};
use crate::scene::SceneLight;
use crate::shading::Lambert;

/// An 8-bit RGB image, row-major from the top-left corner.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `3 · width · height` bytes.
    pub rgb: Vec<u8>,
}

/// The background of images, as in the SVG views.
pub const BACKGROUND: [u8; 3] = [0xe9, 0xec, 0xf0];

impl Image {
    /// A `width × height` image filled with `color`.
    pub fn new(width: u32, height: u32, color: [u8; 3]) -> Image {
        let n = width as usize * height as usize;
        let mut rgb = crate::raster::filled(3 * n, 0u8);
        use rayon::prelude::*;
        rgb.par_chunks_mut(3)
            .for_each(|px| px.copy_from_slice(&color));
        Image { width, height, rgb }
    }

    /// The PNG encoding (fast deflate).
    pub fn encode_png(&self) -> Vec<u8> {
        let mut out = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut out, self.width, self.height);
            enc.set_color(png::ColorType::Rgb);
            enc.set_depth(png::BitDepth::Eight);
            enc.set_compression(png::Compression::Fast);
            let mut w = enc.write_header().expect("a PNG header in memory");
            w.write_image_data(&self.rgb).expect("PNG data in memory");
        }
        out
    }

    /// Writes the image as PNG.
    pub fn write_png(&self, path: &Path) -> Result<(), RasterError> {
        write_file(path, &self.encode_png())
    }

    /// Copies `o` into this image at `(x, y)` (clipped).
    pub fn blit(&mut self, o: &Image, x: u32, y: u32) {
        for row in 0..o.height.min(self.height.saturating_sub(y)) {
            let n = o.width.min(self.width.saturating_sub(x)) as usize * 3;
            let dst = ((y + row) as usize * self.width as usize + x as usize) * 3;
            let src = row as usize * o.width as usize * 3;
            self.rgb[dst..dst + n].copy_from_slice(&o.rgb[src..src + n]);
        }
    }

    /// Draws `text` (5×7 capitals, digits and `.%-:/(),=+_`, scaled by
    /// `scale`) with its top-left corner at `(x, y)`.
    pub fn text(&mut self, text: &str, x: u32, y: u32, scale: u32, color: [u8; 3]) {
        let mut cx = x;
        for ch in text.chars() {
            let rows = glyph(ch.to_ascii_uppercase());
            for (r, bits) in rows.iter().enumerate() {
                for c in 0..5 {
                    if bits >> (4 - c) & 1 == 0 {
                        continue;
                    }
                    for dy in 0..scale {
                        for dx in 0..scale {
                            let (px, py) = (cx + c * scale + dx, y + r as u32 * scale + dy);
                            if px < self.width && py < self.height {
                                let i = (py as usize * self.width as usize + px as usize) * 3;
                                self.rgb[i..i + 3].copy_from_slice(&color);
                            }
                        }
                    }
                }
            }
            cx += 6 * scale;
        }
    }
}

pub(crate) fn write_file(path: &Path, bytes: &[u8]) -> Result<(), RasterError> {
    let io = |e: std::io::Error| RasterError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    let mut f = std::fs::File::create(path).map_err(io)?;
    f.write_all(bytes).map_err(io)
}

/// The mask of the first light: 0 where a pixel sees nothing, 255 where its
/// visible surface is lit by the first light, 128 where it is not.
pub fn mask(vis: &VisibilityBuffer, lit: &LitBuffer) -> Vec<u8> {
    vis.prim
        .iter()
        .enumerate()
        .map(|(p, &prim)| match prim {
            NONE => 0,
            _ if lit.lights > 0 && lit.lit(p, 0) => 255,
            _ => 128,
        })
        .collect()
}

/// The pixels of a [`mask`] that see the scene (not 0) and those lit by
/// light 0 (255), counted in parallel.
///
/// ```
/// assert_eq!(shadow_raster::mask_counts(&[0, 128, 255, 255]), (3, 2));
/// ```
pub fn mask_counts(mask: &[u8]) -> (usize, usize) {
    use rayon::prelude::*;
    mask.par_chunks(1 << 16)
        .map(|c| {
            let seen: usize = c.iter().map(|&m| usize::from(m != 0)).sum();
            let lit: usize = c.iter().map(|&m| usize::from(m == 255)).sum();
            (seen, lit)
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
}

/// A binary PGM (P5) of a mask.
pub fn encode_pgm(width: u32, height: u32, mask: &[u8]) -> Vec<u8> {
    let mut out = format!("P5\n{width} {height}\n255\n").into_bytes();
    out.extend_from_slice(mask);
    out
}

/// Writes a mask as binary PGM (P5).
pub fn write_pgm(path: &Path, width: u32, height: u32, mask: &[u8]) -> Result<(), RasterError> {
    write_file(path, &encode_pgm(width, height, mask))
}

/// Per-prim shading terms kept from frame to frame by a
/// [`crate::Renderer`].
pub(crate) struct ShadeBuffers {
    /// Per drawn prim (by its slot in the frame's screen): colour and
    /// ambient light.
    base: Vec<(DVec3, f64)>,
    /// Per drawn prim and light: the weighted cosine.
    cosines: Vec<f64>,
    /// With one light, per drawn prim: its colour unlit and lit.
    two: Vec<[[u8; 3]; 2]>,
    /// Use `two` (tests turn it off).
    table: bool,
}

impl Default for ShadeBuffers {
    fn default() -> ShadeBuffers {
        ShadeBuffers {
            base: Vec::new(),
            cosines: Vec::new(),
            two: Vec::new(),
            table: true,
        }
    }
}

/// The colour `c · b` of a prim with colour and ambient `(c, b)`, with
/// the lit amounts `amount` of the lights whose weighted cosines are
/// `cosines` (at least as many).
#[inline]
fn mix((c, mut b): (DVec3, f64), amount: &[f32], cosines: &[f64]) -> [u8; 3] {
    for (&a, &cos) in amount.iter().zip(cosines) {
        b += a as f64 * cos;
    }
    // in [0.5, 255.5]: truncation rounds (no library call)
    let v = (c * b).clamp(DVec3::ZERO, DVec3::ONE) * 255.0 + 0.5;
    [v.x as u8, v.y as u8, v.z as u8]
}

/// Shading by the one lighting model ([`Lambert::SHADOWS`]), as the SVG
/// views: the face's colour times ambient light (more on surfaces facing
/// the viewer) plus each light's cosine times the amount of it that
/// reaches the pixel, the cosines taken at each prim's centre (so a face's lit parts share one shade and only the
/// shadow boundaries show).
pub(crate) fn shade(
    frame: &Frame<'_>,
    vis: &VisibilityBuffer,
    lit: &LitBuffer,
    lights: &[SceneLight],
    colors: &[DVec3],
) -> Image {
    shade_in(
        frame,
        vis,
        lit,
        lights,
        colors,
        None,
        &mut ShadeBuffers::default(),
    )
}

/// [`shade`] into the memory of `spare` and `bufs`.
pub(crate) fn shade_in(
    frame: &Frame<'_>,
    vis: &VisibilityBuffer,
    lit: &LitBuffer,
    lights: &[SceneLight],
    colors: &[DVec3],
    spare: Option<Image>,
    bufs: &mut ShadeBuffers,
) -> Image {
    use rayon::prelude::*;
    let (w, h) = (vis.width, vis.height);
    let n = w as usize * h as usize;
    let mut rgb = spare.map(|i| i.rgb).unwrap_or_default();
    if rgb.len() != 3 * n {
        rgb = crate::raster::filled(3 * n, 0u8);
    }
    let scene = frame.scene;
    let eye = frame.camera.eye();
    let weight = Lambert::weight(lights.len());
    let grey = DVec3::splat(0.7);
    let nl = lights.len();
    // per drawn prim, in one pass: colour, ambient, each light's weighted
    // cosine, and with one light its colours in shadow and in light (the
    // same bits as `color` below with an amount of 0 or 1)
    let drawn = &frame.screen.id;
    let table = nl == 1 && bufs.table;
    // (a spare cosine when there is no light: chunks are not empty)
    let per = nl.max(1);
    bufs.base.resize(drawn.len(), (DVec3::ZERO, 0.0));
    bufs.cosines.resize(drawn.len() * per, 0.0);
    bufs.two
        .resize(if table { drawn.len() } else { 0 }, [[0; 3]; 2]);
    let prim = |s: usize, base: &mut (DVec3, f64), cos: &mut [f64]| {
        let i = drawn[s] as usize;
        let pts = scene.prim(i);
        let centre = pts.iter().sum::<DVec3>() / pts.len() as f64;
        let n = visible_normal(frame, i);
        let to_eye = (eye - centre).normalize_or_zero();
        let c = colors.get(scene.face[i] as usize).copied().unwrap_or(grey);
        *base = (c, Lambert::SHADOWS.base(n, to_eye));
        for (cos, l) in cos.iter_mut().zip(lights) {
            *cos = Lambert::cosine(weight, n, l.world.toward(centre));
        }
    };
    let per_prim = bufs
        .base
        .par_iter_mut()
        .zip(bufs.cosines.par_chunks_mut(per));
    if table {
        per_prim
            .zip(bufs.two.par_iter_mut())
            .enumerate()
            .with_min_len(1024)
            .for_each(|(s, ((base, cos), two))| {
                prim(s, base, cos);
                *two = [mix(*base, &[0.0], cos), mix(*base, &[1.0], cos)];
            });
    } else {
        per_prim
            .enumerate()
            .with_min_len(1024)
            .for_each(|(s, (base, cos))| prim(s, base, cos));
    }
    let (base, cosines) = (&bufs.base, &bufs.cosines);
    // the colour of drawn prim `s` with the lit amounts `amount`
    let color = |s: usize, amount: &[f32]| mix(base[s], amount, &cosines[s * per..]);
    let two = &bufs.two;
    rgb.par_chunks_mut(3 * w as usize)
        .enumerate()
        .for_each(|(y, row)| {
            let w = w as usize;
            let prims = &vis.prim[y * w..(y + 1) * w];
            if table {
                // one light, a plain loop over the row
                let amounts = &lit.amount[y * w..(y + 1) * w];
                for ((out, &prim), &a) in row.chunks_exact_mut(3).zip(prims).zip(amounts) {
                    let v = if prim == NONE {
                        BACKGROUND
                    } else {
                        let s = frame.slot[prim as usize] as usize;
                        if a == 0.0 || a == 1.0 {
                            two[s][(a == 1.0) as usize]
                        } else {
                            color(s, &[a])
                        }
                    };
                    out.copy_from_slice(&v);
                }
                return;
            }
            for (x, out) in row.chunks_exact_mut(3).enumerate() {
                let pix = y * w + x;
                let prim = vis.prim[pix];
                if prim == NONE {
                    out.copy_from_slice(&BACKGROUND);
                    continue;
                }
                let s = frame.slot[prim as usize] as usize;
                let amount = &lit.amount[pix * nl..(pix + 1) * nl];
                let v = match amount.first() {
                    Some(&a) if table && (a == 0.0 || a == 1.0) => two[s][(a == 1.0) as usize],
                    _ => color(s, amount),
                };
                out.copy_from_slice(&v);
            }
        });
    Image {
        width: w,
        height: h,
        rgb,
    }
}

/// A 5×7 glyph: seven rows of five bits, most significant bit left.
fn glyph(c: char) -> [u8; 7] {
    match c {
        '0' => [0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E],
        '1' => [0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E],
        '2' => [0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F],
        '3' => [0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E],
        '4' => [0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02],
        '5' => [0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E],
        '6' => [0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E],
        '7' => [0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08],
        '8' => [0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E],
        '9' => [0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C],
        'A' => [0x0E, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11],
        'B' => [0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E],
        'C' => [0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E],
        'D' => [0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C],
        'E' => [0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F],
        'F' => [0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10],
        'G' => [0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F],
        'H' => [0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11],
        'I' => [0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E],
        'J' => [0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C],
        'K' => [0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11],
        'L' => [0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F],
        'M' => [0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11],
        'N' => [0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11],
        'O' => [0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E],
        'P' => [0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10],
        'Q' => [0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D],
        'R' => [0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11],
        'S' => [0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E],
        'T' => [0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04],
        'U' => [0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E],
        'V' => [0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04],
        'W' => [0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A],
        'X' => [0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11],
        'Y' => [0x11, 0x11, 0x11, 0x0A, 0x04, 0x04, 0x04],
        'Z' => [0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F],
        '.' => [0, 0, 0, 0, 0, 0x0C, 0x0C],
        '%' => [0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03],
        '-' => [0, 0, 0, 0x1F, 0, 0, 0],
        ':' => [0, 0x0C, 0x0C, 0, 0x0C, 0x0C, 0],
        '/' => [0, 0x01, 0x02, 0x04, 0x08, 0x10, 0],
        '(' => [0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02],
        ')' => [0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08],
        ',' => [0, 0, 0, 0, 0x0C, 0x04, 0x08],
        '=' => [0, 0, 0x1F, 0, 0x1F, 0, 0],
        '+' => [0, 0x04, 0x04, 0x1F, 0x04, 0x04, 0],
        '_' => [0, 0, 0, 0, 0, 0, 0x1F],
        _ => [0; 7],
    }
}

/// Panels side by side, `columns` to a row, each under a label bar.
pub fn composite(panels: &[(String, Image)], columns: usize) -> Image {
    let columns = columns.max(1);
    let (pw, ph) = panels
        .iter()
        .fold((1, 1), |(w, h), (_, i)| (w.max(i.width), h.max(i.height)));
    let bar = 22;
    let gap = 4;
    let rows = panels.len().div_ceil(columns).max(1) as u32;
    let cols = columns.min(panels.len()).max(1) as u32;
    let mut out = Image::new(
        cols * pw + (cols + 1) * gap,
        rows * (ph + bar) + (rows + 1) * gap,
        [0x30, 0x33, 0x38],
    );
    for (k, (label, img)) in panels.iter().enumerate() {
        let (c, r) = ((k % columns) as u32, (k / columns) as u32);
        let x = gap + c * (pw + gap);
        let y = gap + r * (ph + bar + gap);
        // twice the glyph size when the label fits the panel
        let scale = if 12 * label.chars().count() as u32 + 16 <= pw {
            2
        } else {
            1
        };
        out.text(
            label,
            x + 4,
            y + 4 + 4 * (2 - scale),
            scale,
            [0xf0, 0xf0, 0xf0],
        );
        out.blit(img, x, y + bar);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_light_colours_from_the_table_are_those_of_the_formula() {
        // every pixel of a one-light frame shaded through the unlit and
        // lit colours of its prim, and by the formula, with amounts of 0
        // and 1 only and with PCF fractions
        let mut shaded = 0;
        for (scene, lights, cams) in crate::testing::scenes() {
            for cam in &cams {
                let frame = crate::hsr::Frame::new(&scene, cam, false).unwrap();
                let vis = crate::hsr::visibility(&frame, crate::Hsr::ZBuffer);
                for pcf in [1, 5] {
                    let opts = crate::ShadowOptions::default()
                        .with_pcf(pcf)
                        .with_map_size(128);
                    let (lit, _) = crate::shadow::shadows(
                        &frame,
                        &vis,
                        &lights,
                        crate::Method::ShadowMap,
                        &opts,
                    )
                    .unwrap();
                    let colors = [DVec3::new(0.9, 0.5, 0.2), DVec3::new(0.1, 0.8, 0.6)];
                    let mut plain = ShadeBuffers {
                        table: false,
                        ..ShadeBuffers::default()
                    };
                    let a = shade(&frame, &vis, &lit, &lights, &colors);
                    let b = shade_in(&frame, &vis, &lit, &lights, &colors, None, &mut plain);
                    assert_eq!(a, b, "pcf {pcf}");
                    assert!(plain.two.is_empty());
                    shaded += vis.prim.iter().filter(|&&p| p != NONE).count();
                }
            }
        }
        assert!(shaded > 10_000, "{shaded}");
    }

    #[test]
    fn png_and_pgm_headers() {
        let img = Image::new(3, 2, [1, 2, 3]);
        let png = img.encode_png();
        assert_eq!(&png[1..4], b"PNG");
        let dec = png::Decoder::new(std::io::Cursor::new(png));
        let mut r = dec.read_info().unwrap();
        let mut buf = vec![0; r.output_buffer_size().unwrap()];
        let info = r.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (3, 2));
        assert_eq!(&buf[..info.buffer_size()], &img.rgb[..]);
        let pgm = encode_pgm(3, 2, &[0, 128, 255, 0, 0, 0]);
        assert!(pgm.starts_with(b"P5\n3 2\n255\n"));
        assert_eq!(pgm.len(), 11 + 6);
    }

    #[test]
    fn labels_draw_pixels() {
        let mut img = Image::new(40, 10, [0; 3]);
        img.text("A1%", 0, 0, 1, [255; 3]);
        assert!(img.rgb.contains(&255));
        let c = composite(&[("X".into(), Image::new(4, 4, [9; 3]))], 3);
        assert!(c.width >= 4 && c.height >= 4);
    }
}
