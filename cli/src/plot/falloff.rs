//! False-colour PNG of a falloff map: the Rec.709 luminance of the irradiance (lux for lights in
//! nits) through matplotlib's perceptually uniform viridis map, on a log (default) or linear
//! scale, with a colour bar labelled in lux, the plane's extent in scene units, and optional
//! isolux contours at the colour bar's ticks. Pixels that receive no light at all are black.

use std::path::Path;

use super::viridis::VIRIDIS;
use luxeval::{FalloffMap as Map, FalloffPlane as Plane};
use luxeval::{LuxError, Result};
use super::font;

/// How values map to colours.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Scale {
    /// log10: falloff maps span decades (default).
    #[default]
    Log,
    Linear,
}

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

/// An RGB8 image with what it shows.
#[derive(Clone, Debug)]
pub struct Rendered {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<u8>,
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

/// Tick values inside `range`: decades (plus 2 and 5 when few) on a log scale, 1-2-5 steps on a
/// linear one.
pub fn ticks(range: (f64, f64), scale: Scale) -> Vec<f64> {
    let (lo, hi) = range;
    if !(hi > lo) {
        return vec![];
    }
    match scale {
        Scale::Log => {
            let lo = lo.max(f64::MIN_POSITIVE);
            let (k0, k1) = (lo.log10().ceil() as i32, hi.log10().floor() as i32);
            let decades: Vec<f64> = (k0..=k1).map(|k| 10f64.powi(k)).collect();
            if decades.len() >= 3 {
                return decades;
            }
            let mut t: Vec<f64> = (k0 - 1..=k1)
                .flat_map(|k| [1.0, 2.0, 5.0].map(|m| m * 10f64.powi(k)))
                .filter(|v| *v >= lo * (1.0 - 1e-12) && *v <= hi * (1.0 + 1e-12))
                .collect();
            t.dedup();
            t
        }
        Scale::Linear => {
            let raw = (hi - lo) / 5.0;
            let mag = 10f64.powf(raw.log10().floor());
            let step = [1.0, 2.0, 5.0, 10.0]
                .iter()
                .map(|m| m * mag)
                .find(|s| *s >= raw)
                .unwrap_or(10.0 * mag);
            let first = (lo / step).ceil() as i64;
            let last = (hi / step).floor() as i64;
            (first..=last).map(|k| k as f64 * step).collect()
        }
    }
}

/// A compact label: plain decimals from 0.001 to 99999, otherwise `1e6`-style.
pub fn label(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if (1e-3..1e5).contains(&a) {
        let s = format!("{v:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        // Four decimals may still be too many significant digits for values ≥ 10.
        let digits = (a.log10().floor() as i32 + 1).max(1) as usize;
        if digits >= 4 {
            format!("{v:.0}")
        } else {
            s.to_string()
        }
    } else {
        let e = a.log10().floor() as i32;
        let m = v / 10f64.powi(e);
        if (m.abs() - 1.0).abs() < 1e-9 {
            format!("{}1e{e}", if v < 0.0 { "-" } else { "" })
        } else {
            format!("{m:.1}e{e}")
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

struct Canvas {
    w: u32,
    h: u32,
    px: Vec<u8>,
}

impl Canvas {
    fn set(&mut self, x: i64, y: i64, c: [u8; 3]) {
        if x >= 0 && y >= 0 && (x as u32) < self.w && (y as u32) < self.h {
            let k = 3 * (y as usize * self.w as usize + x as usize);
            self.px[k..k + 3].copy_from_slice(&c);
        }
    }
    fn get(&self, x: u32, y: u32) -> [u8; 3] {
        let k = 3 * (y as usize * self.w as usize + x as usize);
        [self.px[k], self.px[k + 1], self.px[k + 2]]
    }
    fn text(&mut self, s: &str, x: i64, y: i64, c: [u8; 3]) {
        let mut pts = Vec::new();
        font::draw(s, x, y, FONT_SCALE, |px, py| pts.push((px, py)));
        for (px, py) in pts {
            self.set(px, py, c);
        }
    }
}

const INK: [u8; 3] = [20, 20, 20];
const PAPER: [u8; 3] = [255, 255, 255];

fn fmt_vec(v: glam::DVec3) -> String {
    format!("({}, {}, {})", short(v.x), short(v.y), short(v.z))
}

fn short(x: f64) -> String {
    let s = format!("{x:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.').to_string();
    if s == "-0" { "0".into() } else { s }
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
    let side = map.width.max(map.height);
    let zoom = MIN_DISPLAY
        .div_ceil(side)
        .min((4 * MIN_DISPLAY / side).max(1))
        .max(1);
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
        short(plane.u.length()),
        short(plane.v.length())
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
    let mut c = Canvas {
        w: width,
        h: height,
        px: PAPER.repeat((width * height) as usize),
    };

    c.text(&title, MARGIN as i64, MARGIN as i64, INK);
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
        c.text(l, (bx + BAR_WIDTH + 12) as i64, y - TEXT_H as i64 / 2, INK);
    }
    c.text("lux", bx as i64, (MARGIN + TEXT_H + 6) as i64, INK);
    let cy = top + mh + 10;
    c.text(&caption1, MARGIN as i64, cy as i64, INK);
    c.text(&caption2, MARGIN as i64, (cy + TEXT_H + 6) as i64, INK);
    Ok(Rendered {
        width,
        height,
        rgb: c.px,
        range,
        ticks,
        zoom,
    })
}

/// Writes a rendered image as an 8-bit sRGB PNG, atomically.
pub fn write(path: &Path, r: &Rendered) -> Result<()> {
    crate::plot::write_rgb_png(
        path,
        r.width,
        r.height,
        &r.rgb,
        &format!("irradiance colour bar {} to {} lux", r.range.0, r.range.1),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn ticks_and_labels() {
        assert_eq!(
            ticks((0.5, 2000.0), Scale::Log),
            vec![1.0, 10.0, 100.0, 1000.0]
        );
        assert_eq!(ticks((0.3, 4.0), Scale::Log), vec![0.5, 1.0, 2.0]);
        assert_eq!(
            ticks((0.0, 1.0), Scale::Linear),
            vec![0.0, 0.2, 0.4, 0.6000000000000001, 0.8, 1.0]
        );
        assert_eq!(label(0.25), "0.25");
        assert_eq!(label(1000.0), "1000");
        assert_eq!(label(1e6), "1e6");
        assert_eq!(label(2.5e-5), "2.5e-5");
        assert_eq!(label(12.5), "12.5");
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
            let k = 3 * (y * r.width + x) as usize;
            [r.rgb[k], r.rgb[k + 1], r.rgb[k + 2]]
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
