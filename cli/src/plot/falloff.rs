//! False-colour PNG of a falloff map: the Rec.709 luminance of the irradiance (lux for lights in
//! nits) through matplotlib's perceptually uniform viridis map, on a log (default) or linear
//! scale, with a colour bar labelled in lux, the plane's extent in scene units, and optional
//! isolux contours at the colour bar's ticks. Pixels that receive no light at all are black.

use std::path::Path;

use luxeval::{FalloffMap as Map, FalloffPlane as Plane, LuxError, Result};

pub use super::numbers::Scale;
use super::numbers::{decimal, label, ticks};
use super::viridis::VIRIDIS;
use super::{Canvas, INK, PAPER, font};

/// Rendering options.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Style {
    pub scale: Scale,
    /// (low, high) in lux; default: the map's maximum and, on a log scale, three decades below
    /// it (or the smallest lit value, if higher), on a linear scale 0.
    pub range: Option<(f64, f64)>,
    /// Draw isolux contours at the colour bar's tick values.
    pub contours: bool,
}

/// The picture with what it shows.
#[derive(Clone, Debug)]
pub struct Rendered {
    pub canvas: Canvas,
    /// The value range of the colour bar (lux).
    pub range: (f64, f64),
    /// The labelled values (and contour levels).
    pub ticks: Vec<f64>,
    /// Integer zoom of each map pixel.
    pub zoom: u32,
}

const MARGIN: u32 = 16;
const FONT_SCALE: u32 = 2;
const BAR_GAP: u32 = 24;
const BAR_WIDTH: u32 = 20;
const TEXT_H: u32 = font::HEIGHT * FONT_SCALE;
/// Maps smaller than this (largest side) are enlarged by an integer factor for legibility.
const MIN_DISPLAY: u32 = 384;

/// The most pixels a falloff PNG may have (3 bytes each while it is drawn: 768 MiB).
pub const MAX_PNG_PIXELS: u64 = 1 << 28;

/// Room around the map for the title, colour bar, labels and captions, at most (pixels).
const FRAME_W: u64 = 800;
const FRAME_H: u64 = 200;

/// The integer enlargement of a `width × height` map (small maps are drawn larger).
fn zoom(width: u32, height: u32) -> u32 {
    let side = width.max(height).max(1);
    MIN_DISPLAY
        .div_ceil(side)
        .min((4 * MIN_DISPLAY / side).max(1))
        .max(1)
}

/// Refuses a PNG for a `width × height` map that would have more than [`MAX_PNG_PIXELS`]
/// (a very elongated map: the colour bar and captions add a frame to both sides), before the
/// map is evaluated.
pub fn check_size(width: u32, height: u32) -> Result<()> {
    // In u128: any two u32 sides, enlarged and framed, multiply without overflow.
    let z = u128::from(zoom(width, height));
    let pixels = (u128::from(width) * z + u128::from(FRAME_W))
        * (u128::from(height) * z + u128::from(FRAME_H));
    if pixels > u128::from(MAX_PNG_PIXELS) {
        return Err(LuxError::input(
            "--png",
            format!(
                "a {width}×{height} map draws a picture of about {pixels} pixels, over the {MAX_PNG_PIXELS} a falloff PNG may have; write the EXR alone, or a less elongated --res"
            ),
        ));
    }
    Ok(())
}

/// The colour bar range for `values` under `style`.
pub fn auto_range(values: &[f64], style: &Style) -> (f64, f64) {
    if let Some(r) = style.range {
        return r;
    }
    let hi = values
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    if hi <= 0.0 {
        return (0.0, 1.0);
    }
    match style.scale {
        Scale::Linear => (0.0, hi),
        Scale::Log => {
            let min_lit = values
                .iter()
                .copied()
                .filter(|v| *v > 0.0)
                .fold(hi, f64::min);
            let lo = (hi * 1e-3).max(min_lit);
            if lo >= hi { (hi / 10.0, hi) } else { (lo, hi) }
        }
    }
}

fn position(v: f64, range: (f64, f64), scale: Scale) -> f64 {
    let (lo, hi) = range;
    let t = match scale {
        Scale::Log => {
            (v.max(f64::MIN_POSITIVE).log10() - lo.max(f64::MIN_POSITIVE).log10())
                / (hi.log10() - lo.max(f64::MIN_POSITIVE).log10())
        }
        Scale::Linear => (v - lo) / (hi - lo),
    };
    if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    }
}

fn colour(t: f64) -> [u8; 3] {
    VIRIDIS[(t * 255.0).round().clamp(0.0, 255.0) as usize]
}

fn fmt_vec(v: glam::DVec3) -> String {
    format!(
        "({}, {}, {})",
        decimal(v.x, 3),
        decimal(v.y, 3),
        decimal(v.z, 3)
    )
}

/// Renders `map` (sampled on `plane`) with `style`.
pub fn render(map: &Map, plane: &Plane, style: &Style) -> Result<Rendered> {
    if let Some((lo, hi)) = style.range {
        let bad = !(lo.is_finite() && hi.is_finite() && hi > lo)
            || (style.scale == Scale::Log && lo <= 0.0);
        if bad {
            return Err(LuxError::input(
                "--range",
                format!(
                    "{lo},{hi}: need low < high{}",
                    if style.scale == Scale::Log {
                        " and low > 0 on a log scale"
                    } else {
                        ""
                    }
                ),
            ));
        }
    }
    let values = map.luminance();
    let range = auto_range(&values, style);
    let ticks = ticks(range, style.scale);
    let labels: Vec<String> = ticks.iter().map(|t| label(*t)).collect();
    let zoom = zoom(map.width, map.height);
    let (mw, mh) = (map.width * zoom, map.height * zoom);
    let label_w = labels
        .iter()
        .map(|l| font::text_width(l, FONT_SCALE))
        .max()
        .unwrap_or(0)
        .max(font::text_width("lux", FONT_SCALE));
    let title = format!(
        "irradiance, {} scale",
        if style.scale == Scale::Log {
            "log"
        } else {
            "linear"
        }
    );
    let caption1 = format!(
        "{} x {} scene units",
        decimal(plane.u.length(), 3),
        decimal(plane.v.length(), 3)
    );
    let caption2 = format!("normal {}", fmt_vec(plane.normal()));
    let caption_w = [&title, &caption1, &caption2]
        .iter()
        .map(|s| font::text_width(s, FONT_SCALE))
        .max()
        .unwrap_or(0);
    let width =
        (MARGIN + mw + BAR_GAP + BAR_WIDTH + 12 + label_w + MARGIN).max(caption_w + 2 * MARGIN);
    let top = MARGIN + 2 * (TEXT_H + 6) + 4;
    let height = top + mh + 10 + 2 * (TEXT_H + 6) + MARGIN;
    if u64::from(width) * u64::from(height) > MAX_PNG_PIXELS {
        check_size(map.width, map.height)?;
        return Err(LuxError::input(
            "--png",
            format!("{width}×{height} pixels is over the {MAX_PNG_PIXELS} a falloff PNG may have"),
        ));
    }
    let mut c = Canvas::new(width, height, PAPER);

    c.text(&title, MARGIN as i64, MARGIN as i64, FONT_SCALE, INK);
    // The map.
    for j in 0..map.height {
        for i in 0..map.width {
            let v = values[(j * map.width + i) as usize];
            let col = if v > 0.0 {
                colour(position(v, range, style.scale))
            } else {
                [0, 0, 0]
            };
            for dy in 0..zoom {
                for dx in 0..zoom {
                    c.set(
                        (MARGIN + i * zoom + dx) as i64,
                        (top + j * zoom + dy) as i64,
                        col,
                    );
                }
            }
        }
    }
    if style.contours {
        // Isolux lines where neighbouring pixels straddle a tick level, drawn on the shared edge
        // of their enlarged blocks; black on light colours, white on dark ones.
        let level_of = |v: f64| ticks.iter().filter(|t| v >= **t).count();
        for j in 0..map.height {
            for i in 0..map.width {
                let v = values[(j * map.width + i) as usize];
                let here = level_of(v);
                let mut edges = Vec::new();
                if i + 1 < map.width && level_of(values[(j * map.width + i + 1) as usize]) != here {
                    edges.push((true, i + 1, j));
                }
                if j + 1 < map.height
                    && level_of(values[((j + 1) * map.width + i) as usize]) != here
                {
                    edges.push((false, i, j + 1));
                }
                for (vertical, ei, ej) in edges {
                    let (x0, y0) = (MARGIN + ei * zoom, top + ej * zoom);
                    for k in 0..zoom.max(1) {
                        let (x, y) = if vertical { (x0, y0 + k) } else { (x0 + k, y0) };
                        let under = c.get(x.min(width - 1), y.min(height - 1));
                        let luma = 0.2126 * under[0] as f64
                            + 0.7152 * under[1] as f64
                            + 0.0722 * under[2] as f64;
                        c.set(
                            x as i64,
                            y as i64,
                            if luma > 110.0 {
                                [0, 0, 0]
                            } else {
                                [255, 255, 255]
                            },
                        );
                    }
                }
            }
        }
    }
    // The colour bar, bottom = low.
    let bx = MARGIN + mw + BAR_GAP;
    for y in 0..mh {
        let t = 1.0 - (y as f64 + 0.5) / mh as f64;
        for x in 0..BAR_WIDTH {
            c.set((bx + x) as i64, (top + y) as i64, colour(t));
        }
    }
    for (t, l) in ticks.iter().zip(&labels) {
        let y = top as i64
            + ((1.0 - position(*t, range, style.scale)) * (mh as f64 - 1.0)).round() as i64;
        for x in 0..BAR_WIDTH / 3 {
            c.set((bx + BAR_WIDTH - x) as i64, y, INK);
        }
        for x in 0..4 {
            c.set((bx + BAR_WIDTH + 1 + x) as i64, y, INK);
        }
        c.text(
            l,
            (bx + BAR_WIDTH + 12) as i64,
            y - TEXT_H as i64 / 2,
            FONT_SCALE,
            INK,
        );
    }
    c.text(
        "lux",
        bx as i64,
        (MARGIN + TEXT_H + 6) as i64,
        FONT_SCALE,
        INK,
    );
    let cy = top + mh + 10;
    c.text(&caption1, MARGIN as i64, cy as i64, FONT_SCALE, INK);
    c.text(
        &caption2,
        MARGIN as i64,
        (cy + TEXT_H + 6) as i64,
        FONT_SCALE,
        INK,
    );
    Ok(Rendered {
        canvas: c,
        range,
        ticks,
        zoom,
    })
}

/// Writes a rendered image as an 8-bit sRGB PNG, atomically.
pub fn write(path: &Path, r: &Rendered) -> Result<()> {
    r.canvas.write_png(
        path,
        &format!("irradiance colour bar {} to {} lux", r.range.0, r.range.1),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// Any two sides, however large, are checked without overflow (found by fuzz/falloff_png).
    #[test]
    fn the_size_check_takes_any_sides() {
        assert!(check_size(u32::MAX, u32::MAX).is_err());
        assert!(check_size(u32::MAX, 1).is_err());
        assert!(check_size(33_818_560, 1).is_err());
        assert!(check_size(1024, 1024).is_ok());
    }

    #[test]
    fn auto_range_spans_three_decades() {
        let style = Style::default();
        assert_eq!(auto_range(&[0.0, 0.5, 1000.0], &style), (1.0, 1000.0));
        assert_eq!(auto_range(&[0.0, 5.0, 1000.0], &style), (5.0, 1000.0));
        assert_eq!(auto_range(&[0.0, 500.0, 1000.0], &style), (500.0, 1000.0));
        assert_eq!(auto_range(&[0.0, 0.0], &style), (0.0, 1.0));
    }

    #[test]
    fn renders_unlit_pixels_black_and_the_peak_yellow() {
        let plane = Plane::new(DVec3::ZERO, DVec3::X, DVec3::Y, 4, 2).unwrap();
        let map = Map {
            width: 4,
            height: 2,
            rgb: vec![
                [0.0; 3],
                [1.0; 3],
                [10.0; 3],
                [100.0; 3],
                [0.0; 3],
                [0.0; 3],
                [0.0; 3],
                [1000.0; 3],
            ],
        };
        let r = render(
            &map,
            &plane,
            &Style {
                contours: true,
                ..Style::default()
            },
        )
        .unwrap();
        let at = |i: u32, j: u32| {
            let (x, y) = (
                MARGIN + i * r.zoom + r.zoom / 2,
                MARGIN + 2 * (TEXT_H + 6) + 4 + j * r.zoom + r.zoom / 2,
            );
            r.canvas.get(x, y)
        };
        assert_eq!(at(0, 0), [0, 0, 0]);
        assert_eq!(at(3, 1), VIRIDIS[255]);
        assert_eq!(at(1, 0), VIRIDIS[0]); // 1 lux is the bottom of a 1..1000 bar
        assert_eq!(r.ticks, vec![1.0, 10.0, 100.0, 1000.0]);
        assert!(
            render(
                &map,
                &plane,
                &Style {
                    range: Some((0.0, 1.0)),
                    ..Style::default()
                }
            )
            .is_err()
        );
    }
}
