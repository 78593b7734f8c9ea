//! A polar candela plot as photometric reports draw it: intensity against the angle from nadir
//! in two vertical planes through the light's axis, C0–C180 and C90–C270 (DESIGN.md §6 I2: C0
//! toward the light's +X, C90 toward +Y, nadir its −Z). Nadir (0°) points down, 90° sideways,
//! 180° up; the C0 (C90) half is on the right, C180 (C270) on the left. Rings are labelled in
//! candela.

use glam::DVec3;

use super::numbers::{decimal, nice_step};
use super::{Canvas, GRID, INK, PAPER};

/// One curve: `(signed angle from nadir in degrees, candela)` in drawing order; positive angles
/// are drawn on the right half, negative on the left.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    pub label: String,
    pub colour: [u8; 3],
    pub samples: Vec<(f64, f64)>,
}

pub const RED: [u8; 3] = [200, 30, 30];
pub const BLUE: [u8; 3] = [30, 70, 200];

/// A plane pair's label, colour and (signed angle, direction) samples.
pub type PlaneDirections = (&'static str, [u8; 3], Vec<(f64, DVec3)>);

/// The light-space unit directions of the two plane pairs, every `step` degrees: C0–C180
/// (`e = (sin s, 0, −cos s)`) and C90–C270 (`e = (0, sin s, −cos s)`), s the signed angle from
/// nadir in [−180°, 180°]; each with its label and colour.
pub fn plane_directions(step: f64) -> [PlaneDirections; 2] {
    let n = (360.0 / step).round().max(4.0) as usize;
    let sample = |plane: fn(f64, f64) -> DVec3| -> Vec<(f64, DVec3)> {
        (0..=n)
            .map(|k| {
                let s = -180.0 + 360.0 * k as f64 / n as f64;
                let (sn, cs) = s.to_radians().sin_cos();
                (s, plane(sn, cs))
            })
            .collect()
    };
    [
        ("C0-C180", RED, sample(|sn, cs| DVec3::new(sn, 0.0, -cs))),
        ("C90-C270", BLUE, sample(|sn, cs| DVec3::new(0.0, sn, -cs))),
    ]
}

/// The curves of intensity `f(e)` along [`plane_directions`].
pub fn c_plane_curves(mut f: impl FnMut(DVec3) -> f64, step: f64) -> [Curve; 2] {
    plane_directions(step).map(|(label, colour, dirs)| Curve {
        label: label.into(),
        colour,
        samples: dirs.into_iter().map(|(s, e)| (s, f(e))).collect(),
    })
}

const SIZE: u32 = 720;
const RADIUS: f64 = 290.0;
const TOP: f64 = 70.0;
const FONT: u32 = 2;

/// Renders the curves under `title` (and a second line `subtitle`).
pub fn render(title: &str, subtitle: &str, curves: &[Curve]) -> Canvas {
    let height = (TOP + 2.0 * RADIUS + 110.0) as u32;
    let mut c = Canvas::new(SIZE, height, PAPER);
    let (cx, cy) = (SIZE as f64 / 2.0, TOP + RADIUS + 20.0);
    let max = curves
        .iter()
        .flat_map(|k| k.samples.iter().map(|s| s.1))
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    let step = nice_step(max, 4.0);
    let rings = (max / step).ceil().max(1.0);
    let full = rings * step;
    // Rings and radial lines every 30°.
    for k in 1..=rings as usize {
        c.circle((cx, cy), RADIUS * k as f64 / rings, GRID);
    }
    for a in (0..360).step_by(30) {
        let (sn, cs) = (a as f64).to_radians().sin_cos();
        c.line((cx, cy), (cx + sn * RADIUS, cy + cs * RADIUS), 1, GRID);
        let shown = if a <= 180 { a } else { 360 - a };
        let label = format!("{shown}°");
        let w = Canvas::text_width(&label, FONT) as f64;
        let (lx, ly) = (cx + sn * (RADIUS + 26.0), cy + cs * (RADIUS + 16.0));
        c.text(&label, (lx - w / 2.0) as i64, (ly - 7.0) as i64, FONT, INK);
    }
    // Ring values along the 90° line on the right, just above it; the unit after the last.
    for k in 1..=rings as usize {
        let v = step * k as f64;
        let mut label = decimal(v, 6);
        if k == rings as usize {
            label.push_str(" cd");
        }
        let x = cx + RADIUS * k as f64 / rings;
        let w = Canvas::text_width(&label, FONT) as f64;
        c.text(&label, (x - w - 3.0) as i64, (cy - 18.0) as i64, FONT, INK);
    }
    // The curves.
    for curve in curves {
        let pts: Vec<(f64, f64)> = curve
            .samples
            .iter()
            .map(|&(s, v)| {
                let r = RADIUS * (v.max(0.0) / full);
                let (sn, cs) = s.to_radians().sin_cos();
                (cx + sn * r, cy + cs * r)
            })
            .collect();
        for w in pts.windows(2) {
            c.line(w[0], w[1], 2, curve.colour);
        }
    }
    c.text(title, 16, 12, FONT, INK);
    c.text(subtitle, 16, 34, FONT, INK);
    // Legend.
    let mut x = 16.0;
    let y = height as f64 - 36.0;
    for curve in curves {
        c.line((x, y + 7.0), (x + 40.0, y + 7.0), 3, curve.colour);
        c.text(&curve.label, (x + 50.0) as i64, y as i64, FONT, INK);
        x += 60.0 + Canvas::text_width(&curve.label, FONT) as f64 + 30.0;
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A curve of constant intensity traces a circle of the outer ring's radius when its value
    /// is a whole number of ring steps: the pixel at nadir, 90° and 180° of that radius is inked.
    #[test]
    fn a_constant_curve_is_a_circle_at_its_ring() {
        let curves = c_plane_curves(|_| 100.0, 1.0);
        assert!(curves[0].samples.iter().all(|s| s.1 == 100.0));
        let c = render("t", "s", &curves[..1]);
        let (cx, cy) = (SIZE as f64 / 2.0, TOP + RADIUS + 20.0);
        for (dx, dy) in [(0.0, RADIUS), (RADIUS, 0.0), (0.0, -RADIUS), (-RADIUS, 0.0)] {
            let (x, y) = ((cx + dx).round() as u32, (cy + dy).round() as u32);
            let near = (x - 1..=x + 1)
                .flat_map(|x| (y - 1..=y + 1).map(move |y| (x, y)))
                .any(|(x, y)| c.get(x, y) == RED);
            assert!(near, "no red near ({x}, {y})");
        }
    }

    #[test]
    fn plane_directions() {
        let [c0, c90] = c_plane_curves(|e| e.x + 10.0 * e.y, 90.0);
        // s = 90° in C0–C180 is +X; in C90–C270 it is +Y.
        assert!(
            c0.samples
                .iter()
                .any(|&(s, v)| s == 90.0 && (v - 1.0).abs() < 1e-12)
        );
        assert!(
            c90.samples
                .iter()
                .any(|&(s, v)| s == 90.0 && (v - 10.0).abs() < 1e-12)
        );
    }
}
