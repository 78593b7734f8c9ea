//! Small raster drawing for luxeval's PNG reports (no font files, no plotting dependency): an RGB
//! canvas with lines, circles and 5×7 bitmap text, written as an 8-bit sRGB PNG atomically.
//! [`polar`] draws candela distributions the way photometric reports show them.

pub mod falloff;
pub(crate) mod font;
pub mod numbers;
pub mod polar;
mod viridis;

use std::path::Path;

use crate::io::write_atomic;
use luxeval::Result;

/// An RGB8 raster, row-major from the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Canvas {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<u8>,
}

pub const INK: [u8; 3] = [20, 20, 20];
pub const PAPER: [u8; 3] = [255, 255, 255];
pub const GRID: [u8; 3] = [200, 200, 200];

impl Canvas {
    pub fn new(width: u32, height: u32, background: [u8; 3]) -> Self {
        Canvas {
            width,
            height,
            rgb: background
                .iter()
                .copied()
                .cycle()
                .take(3 * width as usize * height as usize)
                .collect(),
        }
    }

    pub fn set(&mut self, x: i64, y: i64, c: [u8; 3]) {
        if x >= 0 && y >= 0 && (x as u32) < self.width && (y as u32) < self.height {
            let k = 3 * (y as usize * self.width as usize + x as usize);
            self.rgb[k..k + 3].copy_from_slice(&c);
        }
    }

    pub fn get(&self, x: u32, y: u32) -> [u8; 3] {
        let k = 3 * (y as usize * self.width as usize + x as usize);
        [self.rgb[k], self.rgb[k + 1], self.rgb[k + 2]]
    }

    /// A line from (x0, y0) to (x1, y1) of width `thick` pixels (a square brush).
    pub fn line(&mut self, (x0, y0): (f64, f64), (x1, y1): (f64, f64), thick: u32, c: [u8; 3]) {
        if !(x0.is_finite() && y0.is_finite() && x1.is_finite() && y1.is_finite()) {
            return;
        }
        let steps = ((x1 - x0).abs().max((y1 - y0).abs()).ceil() as usize).clamp(1, 1 << 16);
        let r = thick as i64 / 2;
        for k in 0..=steps {
            let t = k as f64 / steps as f64;
            let (x, y) = (x0 + (x1 - x0) * t, y0 + (y1 - y0) * t);
            let (xi, yi) = (x.round() as i64, y.round() as i64);
            for dy in -r..=(thick as i64 - 1 - r) {
                for dx in -r..=(thick as i64 - 1 - r) {
                    self.set(xi + dx, yi + dy, c);
                }
            }
        }
    }

    /// A circle of radius `r` around (cx, cy), one pixel wide.
    pub fn circle(&mut self, (cx, cy): (f64, f64), r: f64, c: [u8; 3]) {
        let n = ((2.0 * std::f64::consts::PI * r).ceil() as usize).clamp(8, 1 << 16);
        let mut prev = (cx + r, cy);
        for k in 1..=n {
            let a = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
            let p = (cx + r * a.cos(), cy - r * a.sin());
            self.line(prev, p, 1, c);
            prev = p;
        }
    }

    /// `s` with its top-left corner at (x, y), glyphs `scale` pixels per font pixel.
    pub fn text(&mut self, s: &str, x: i64, y: i64, scale: u32, c: [u8; 3]) {
        let mut pts = Vec::new();
        font::draw(s, x, y, scale, |px, py| pts.push((px, py)));
        for (px, py) in pts {
            self.set(px, py, c);
        }
    }

    /// The width of `s` in pixels at `scale`.
    pub fn text_width(s: &str, scale: u32) -> u32 {
        font::text_width(s, scale)
    }

    /// Writes the canvas as an 8-bit sRGB PNG with a text comment, atomically.
    pub fn write_png(&self, path: &Path, comment: &str) -> Result<()> {
        write_rgb_png(path, self.width, self.height, &self.rgb, comment)
    }
}

/// Writes `rgb` (RGB8, row-major from the top, `width × height`) as an 8-bit sRGB PNG with the
/// luxeval version and `comment` as text chunks, atomically (never a partial file).
pub fn write_rgb_png(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[u8],
    comment: &str,
) -> Result<()> {
    write_atomic(path, |w| {
        let mut enc = ::png::Encoder::new(w, width, height);
        enc.set_color(::png::ColorType::Rgb);
        enc.set_depth(::png::BitDepth::Eight);
        enc.set_source_srgb(::png::SrgbRenderingIntent::Perceptual);
        enc.add_text_chunk(
            "Software".into(),
            concat!("luxeval ", env!("CARGO_PKG_VERSION")).into(),
        )
        .map_err(std::io::Error::other)?;
        enc.add_text_chunk("Comment".into(), comment.into())
            .map_err(std::io::Error::other)?;
        let mut writer = enc.write_header().map_err(std::io::Error::other)?;
        writer
            .write_image_data(rgb)
            .map_err(std::io::Error::other)?;
        writer.finish().map_err(std::io::Error::other)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drawing_stays_inside_and_inks() {
        let mut c = Canvas::new(20, 10, PAPER);
        c.line((-5.0, -5.0), (30.0, 15.0), 3, INK);
        c.circle((10.0, 5.0), 4.0, INK);
        c.text("1°,a", 0, 0, 1, INK);
        assert!(c.rgb.chunks(3).any(|p| p == INK));
        assert_eq!(c.rgb.len(), 600);
    }
}
