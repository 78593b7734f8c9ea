//! Random IES profiles of every photometric type, symmetry and vertical range, written as LM-63
//! text, for the CPU-vs-GPU conformance of IES-shaped lights.

use super::Rng;
use crate::model::{Asset, Ies, Light};

/// The profile shapes the conformance suite covers (DESIGN.md §6 I3): photometric type and
/// horizontal coverage / folds, with a vertical range.
pub const SHAPES: [&str; 12] = [
    "C single",
    "C 0-90",
    "C 0-180",
    "C 90-270",
    "C 0-360",
    "C 0-300 wrap",
    "B mirrored",
    "B as given",
    "B single",
    "A mirrored",
    "A as given",
    "A single",
];

/// `n + rng.below(spread)` increasing angles from `a` to `b` (inclusive), non-uniformly
/// spaced, at least ~1° apart.
fn grid(rng: &mut Rng, a: f64, b: f64, n: usize, spread: usize) -> Vec<f64> {
    let n = n + rng.below(spread);
    if n == 1 {
        return vec![a];
    }
    let mut w: Vec<f64> = (0..n - 1).map(|_| rng.range(1.0, 3.0)).collect();
    let total: f64 = w.iter().sum();
    for x in &mut w {
        *x *= (b - a) / total;
    }
    let mut out = vec![a];
    for x in w {
        let next = out[out.len() - 1] + x;
        out.push(next);
    }
    let last = out.len() - 1;
    out[last] = b;
    // Three decimals, as files print them; keep them increasing.
    out.iter().map(|x| (x * 1000.0).round() / 1000.0).collect()
}

/// A random profile of shape `SHAPES[shape]` as LM-63-2002 text. With `continuous`, the values
/// fall to 0 at vertical range ends that are not the sphere's own poles, so the interpolant has
/// no jump there (only kinks); otherwise the range ends are discontinuities.
pub fn random_profile(rng: &mut Rng, shape: usize, continuous: bool) -> Vec<u8> {
    let (kind, h, v) = match shape {
        0..=5 => {
            let v = match rng.below(4) {
                0 => grid(rng, 0.0, 90.0, 8, 10),
                1 => grid(rng, 90.0, 180.0, 8, 10),
                2 => grid(rng, 0.0, 180.0, 10, 15),
                _ => {
                    let end = rng.range(40.0, 70.0).round();
                    grid(rng, 0.0, end, 6, 8)
                }
            };
            let h = match shape {
                0 => vec![0.0],
                1 => grid(rng, 0.0, 90.0, 3, 6),
                2 => grid(rng, 0.0, 180.0, 4, 8),
                3 => grid(rng, 90.0, 270.0, 4, 8),
                4 => grid(rng, 0.0, 360.0, 6, 10),
                _ => grid(rng, 0.0, 300.0, 5, 8),
            };
            (1, h, v)
        }
        _ => {
            let kind = if shape < 9 { 2 } else { 3 };
            let h = match shape % 3 {
                0 => grid(rng, 0.0, 90.0, 4, 8),
                1 => grid(rng, -90.0, 90.0, 6, 10),
                _ => vec![0.0],
            };
            let v = match shape % 3 {
                0 => grid(rng, 0.0, 90.0, 5, 10),
                _ => grid(rng, -90.0, 90.0, 8, 12),
            };
            (kind, h, v)
        }
    };
    let (v0, v1) = (v[0], v[v.len() - 1]);
    let (a, b, c) = (
        rng.range(0.2, 1.0),
        rng.range(0.0, 2.0),
        rng.range(0.0, 3.0),
    );
    let mut values = Vec::new();
    for &hh in &h {
        for &vv in &v {
            let mut x = 100.0
                * (1.0 + a * (vv.to_radians() * 2.0 + b).cos() * 0.5)
                * (1.0 + 0.3 * (hh.to_radians() + c).sin());
            x *= rng.range(0.9, 1.1);
            // A type C range end that is not a pole of the sphere, and every A/B range end
            // (beyond them the profile is 0) but a mirror plane (a first angle of 0).
            let open_low = if kind == 1 { v0 > 0.0 } else { v0 != 0.0 };
            let open_high = if kind == 1 { v1 < 180.0 } else { true };
            if continuous && ((open_low && vv == v0) || (open_high && vv == v1)) {
                x = 0.0;
            }
            values.push((x * 1000.0).round() / 1000.0);
        }
    }
    let list = |xs: &[f64]| {
        xs.iter()
            .map(|x| format!("{x}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let mut s =
        String::from("IESNA:LM-63-2002\r\n[TEST] luxeval testkit random profile\r\nTILT=NONE\r\n");
    s += &format!(
        "1 -1 1 {} {} {kind} 2 0.1 0.1 0\r\n1 1 0\r\n",
        v.len(),
        h.len()
    );
    s += &format!("{}\r\n{}\r\n", list(&v), list(&h));
    for row in values.chunks(v.len()) {
        s += &list(row);
        s += "\r\n";
    }
    s.into_bytes()
}

/// `light` shaped by a random profile of `shape` (in memory), with a random angleScale (half
/// the time 0) and normalize.
pub fn with_random_ies(light: Light, rng: &mut Rng, shape: usize, continuous: bool) -> Light {
    let bytes = random_profile(rng, shape, continuous);
    let mut ies = Ies::new(Asset::from_bytes(
        format!("random-{}.ies", SHAPES[shape].replace(' ', "-")),
        bytes,
    ));
    if rng.chance(0.5) {
        ies.angle_scale = match rng.below(3) {
            0 => rng.range(0.5, 1.5),
            1 => rng.range(-1.5, -0.5),
            _ => 1.0,
        };
    }
    ies.normalize = rng.chance(0.5);
    let mut s = light.shaping.clone().unwrap_or_default();
    s.ies = Some(ies);
    light.with_shaping(s)
}

/// A 1°-by-5° type C profile (181 × 73 angles) falling off smoothly: a receiver near a large
/// light shaped by it crosses more of its grid surfaces than lavapipe's loop budget allows.
pub fn dense_profile() -> Vec<u8> {
    let v: Vec<f64> = (0..=180).map(f64::from).collect();
    let h: Vec<f64> = (0..=72).map(|k| 5.0 * k as f64).collect();
    let list = |xs: &[f64]| {
        xs.iter()
            .map(|x| format!("{x}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let mut s = String::from("IESNA:LM-63-2002\r\n[TEST] dense\r\nTILT=NONE\r\n");
    s += &format!("1 -1 1 {} {} 1 2 0.1 0.1 0\r\n1 1 0\r\n", v.len(), h.len());
    s += &format!("{}\r\n{}\r\n", list(&v), list(&h));
    for hh in &h {
        let row: Vec<f64> = v
            .iter()
            .map(|vv| 100.0 + 50.0 * (vv.to_radians() * 3.0).cos() * (hh.to_radians() * 2.0).sin())
            .collect();
        s += &list(&row);
        s += "\r\n";
    }
    s.into_bytes()
}
