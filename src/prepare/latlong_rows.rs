//! A latlong dome texture's row tables: what the device needs to integrate the dome's exact
//! irradiance (DESIGN.md §6 "Dome and texture irradiance: what 'exact' means") by rows of the
//! texture, `shaders/irradiance/latlong_rows.wgsl` and its f64 twin
//! `src/cpu/irradiance/latlong_rows.rs`, which carry the derivation.
//!
//! In the texture's column angle `u = 2π·px/W` (§6 D2: `d = (sin θ sin u, cos θ, −sin θ cos u)`,
//! `θ = π·py/H`), one row `j` of the filtered texture at a fixed `y` is a periodic function
//! `R_j(u)`, piecewise linear between column centres (bilinear) or constant on each column
//! (nearest). A receiver's clamped cosine at a fixed θ is positive on one arc of `u`, and its
//! integral over that arc needs only `∫ R_j {1, sin u, cos u} du` up to the arc's ends: the
//! prefix sums over whole pieces stored here, and the ends' partial pieces in closed form.
//!
//! Layout (words, f32 or u32 bit patterns, from the table's offset):
//! - `[W, H, filter code, 0]` ([`HEADER_WORDS`]);
//! - `W` column phases `(cos u_k, sin u_k)` of piece `k`'s start `u_k = u₀ + k·h`, `h = 2π/W`,
//!   `u₀ = h/2` (bilinear: pieces run between column centres) or 0 (nearest);
//! - per row `j` (top first), `W + 1` entries of [`ENTRY_WORDS`]: the prefix
//!   `∫ R_j {1, sin u, cos u} du` over pieces `0..k` (RGB each, exclusive, accumulated in f64),
//!   then the row's value at piece `k`'s start (texel `k`; entry `W` repeats texel 0, the end of
//!   the last bilinear piece under the columns' wrap).
//!
//! The tables take four times the texture's memory (101 MB for 2048 × 1024, 403 MB for
//! 4096 × 2048). The device holds them when they fit its storage binding limit beside the
//! scene's textures, halved as far as they go; the domes whose tables do not fit take their
//! irradiance from the CPU reference on that device (`gpu::texture_atlas::tables_beyond`, which
//! `query::PreparedScene` applies: a device's limit is known only once it is open). The kernel's
//! walk runs `W + H + 4` intervals of `rules::IRR_GL_ROWS` nodes: about `11(W + H)` loop
//! iterations as lavapipe counts them, inside its 65,535 up to `W + H` ≈ 5,900 (measured:
//! tests/dome_conformance.rs); a longer walk on lavapipe (a 4096 × 2048 map's 6,144) is cut
//! short, detected and recomputed by the reference (`irr_cut` in
//! shaders/shared/record.wgsl). A real GPU never cuts.

use std::f64::consts::PI;

use rayon::prelude::*;

use super::gpu_path::GpuPath;
use super::texture::{DomeFormat, Filter, Image, PreparedTexture};

/// Words before the column phases.
pub const HEADER_WORDS: usize = 4;
/// Words per row entry: prefix ∫R, ∫R sin u, ∫R cos u (RGB each), then the value.
pub const ENTRY_WORDS: usize = 12;

/// Where a textured dome's irradiance is integrated: on the device by rows for a latlong
/// texture under a conformal frame (rotation × uniform scale, where the dome-space integral is
/// the world one), where its tables fit the device (`gpu::texture_atlas::tables_beyond`); by
/// the CPU reference otherwise, with the reason.
pub fn gpu_path(t: &PreparedTexture) -> GpuPath {
    if t.format != DomeFormat::LatLong {
        GpuPath::HostIrradiance("it is a textured dome in a format other than latlong")
    } else if t.frame.conformal_weight().is_none() {
        GpuPath::HostIrradiance(
            "it is a textured dome whose transform is not a rotation times a uniform scale",
        )
    } else {
        GpuPath::Device
    }
}

/// The tables' length in words.
pub fn words_len(width: usize, height: usize) -> usize {
    HEADER_WORDS + 2 * width + ENTRY_WORDS * height * (width + 1)
}

/// The tables as the device reads them: the header, then [`tables`] in f32 (tests: the device's
/// copy is written in pieces, [`device_chunks`]).
#[cfg(test)]
pub fn device_words(img: &Image, filter: Filter) -> Vec<f32> {
    let mut out = Vec::with_capacity(words_len(img.width, img.height));
    for (_, words) in device_chunks(img, filter, usize::MAX) {
        out.extend(words);
    }
    debug_assert_eq!(out.len(), words_len(img.width, img.height));
    out
}

/// The tables as the device reads them (the header, then [`tables`] in f32) in pieces of at
/// most `max_words` words where a row's entries allow (one row at least): (offset in the
/// tables, words), the header and column phases first, then the rows in order. The device's
/// copy is written a piece at a time, so that the host never holds the whole tables (1.6 GB
/// for 8192 × 4096).
pub fn device_chunks(
    img: &Image,
    filter: Filter,
    max_words: usize,
) -> impl Iterator<Item = (usize, Vec<f32>)> + '_ {
    let (w, h) = (img.width, img.height);
    let row_words = ENTRY_WORDS * (w + 1);
    let rows_per_chunk = (max_words / row_words).clamp(1, h.max(1));
    let head = {
        let header = [w as u32, h as u32, filter.code(), 0];
        let mut out: Vec<f32> = header.map(f32::from_bits).to_vec();
        phases_into(w, filter, |v| v as f32, &mut out);
        out
    };
    let first = head.len();
    std::iter::once((0, head)).chain((0..h).step_by(rows_per_chunk).map(move |j0| {
        let j1 = (j0 + rows_per_chunk).min(h);
        let mut out = Vec::new();
        rows_into(img, filter, |v| v as f32, j0..j1, &mut out);
        (first + j0 * row_words, out)
    }))
}

/// The row tables of `img` under `filter` after the header (the column phases, then the rows,
/// built in parallel), each number converted by `conv` (f32 for the device, f64 for the twin),
/// appended to `out` (tests: the device's copy is built in pieces, [`device_chunks`]).
#[cfg(test)]
pub fn tables<T: Copy + Default + Send + Sync>(
    img: &Image,
    filter: Filter,
    conv: impl Fn(f64) -> T + Sync,
    out: &mut Vec<T>,
) {
    phases_into(img.width, filter, &conv, out);
    rows_into(img, filter, &conv, 0..img.height, out);
}

/// Piece `k`'s start `u_k` of a `width`-column texture under `filter`, as `(cos u_k, sin u_k)`.
fn phases(width: usize, filter: Filter) -> impl Iterator<Item = (f64, f64)> {
    let step = 2.0 * PI / width as f64;
    let start = if filter == Filter::Bilinear {
        0.5 * step
    } else {
        0.0
    };
    (0..width).map(move |k| {
        let (s, c) = (start + k as f64 * step).sin_cos();
        (c, s)
    })
}

/// The column phases ([`phases`]), converted by `conv`, appended to `out`.
fn phases_into<T>(width: usize, filter: Filter, conv: impl Fn(f64) -> T, out: &mut Vec<T>) {
    for (c, s) in phases(width, filter) {
        out.push(conv(c));
        out.push(conv(s));
    }
}

/// The entries of rows `rows` (built in parallel), converted by `conv`, appended to `out`.
fn rows_into<T: Copy + Default + Send + Sync>(
    img: &Image,
    filter: Filter,
    conv: impl Fn(f64) -> T + Sync,
    rows: std::ops::Range<usize>,
    out: &mut Vec<T>,
) {
    let w = img.width;
    let bilinear = filter == Filter::Bilinear;
    let step = 2.0 * PI / w as f64;
    let phases: Vec<(f64, f64)> = phases(w, filter).collect();
    // Every whole piece has τ = h: its J₀, J₁ once.
    let whole = PhaseIntegrals::new(step);
    let row_words = ENTRY_WORDS * (w + 1);
    let first = out.len();
    out.resize(first + rows.len() * row_words, T::default());
    out[first..]
        .par_chunks_mut(row_words)
        .zip(img.rgb[rows.start * w..rows.end * w].par_chunks(w))
        .for_each(|(dst, row)| {
            let mut acc = [[0.0f64; 3]; 3];
            for (k, entry) in dst.chunks_exact_mut(ENTRY_WORDS).enumerate() {
                let v0 = row[k % w];
                for (d, m) in entry.iter_mut().zip(acc.iter().flatten()) {
                    *d = conv(*m);
                }
                for (d, c) in entry[9..].iter_mut().zip(v0) {
                    *d = conv(f64::from(c));
                }
                if k == w {
                    break;
                }
                let v1 = if bilinear { row[(k + 1) % w] } else { v0 };
                let (cs, sn) = phases[k];
                for ch in 0..3 {
                    let m = whole.moments(f64::from(v0[ch]), f64::from(v1[ch]), step, cs, sn);
                    for (a, q) in acc.iter_mut().zip(m) {
                        a[ch] += q;
                    }
                }
            }
        });
}

/// `J₀ = ∫₀^τ e^{it} dt` and `J₁ = ∫₀^τ t e^{it} dt` as (real, imaginary) parts (see
/// [`piece_moments`]).
struct PhaseIntegrals {
    tau: f64,
    j0: (f64, f64),
    j1: (f64, f64),
}

impl PhaseIntegrals {
    fn new(tau: f64) -> PhaseIntegrals {
        let (s, c) = tau.sin_cos();
        let half = (0.5 * tau).sin();
        let vers = 2.0 * half * half;
        PhaseIntegrals {
            tau,
            j0: (s, vers),
            j1: (tau * s - vers, s - tau * c),
        }
    }

    /// [`piece_moments`] over this τ.
    fn moments(&self, v0: f64, v1: f64, len: f64, cos_k: f64, sin_k: f64) -> [f64; 3] {
        let (tau, j0, j1) = (self.tau, self.j0, self.j1);
        let beta = (v1 - v0) / len;
        let re = v0 * j0.0 + beta * j1.0;
        let im = v0 * j0.1 + beta * j1.1;
        [
            v0 * tau + 0.5 * beta * tau * tau,
            sin_k * re + cos_k * im,
            cos_k * re - sin_k * im,
        ]
    }
}

/// `∫₀^τ R(u_k + t) {1, sin, cos}(u_k + t) dt` for the piece starting at `u_k` (phase
/// `(cos u_k, sin u_k)`) of length `len`, on which `R` runs linearly from `v0` to `v1`:
/// with `β = (v1 − v0)/len`, `∫ (v0 + βt) e^{i(u_k + t)} dt = e^{iu_k} (v0 J₀ + β J₁)` where
/// `J₀ = (sin τ, 2 sin²(τ/2))` and `J₁ = (τ sin τ − 2 sin²(τ/2), sin τ − τ cos τ)` (real, imaginary
/// parts), written without differences of nearly equal sines so that a short piece keeps its
/// absolute accuracy. The WGSL twin's `piece_moments` is the same formula in f32.
pub fn piece_moments(v0: f64, v1: f64, len: f64, tau: f64, cos_k: f64, sin_k: f64) -> [f64; 3] {
    PhaseIntegrals::new(tau).moments(v0, v1, len, cos_k, sin_k)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The device's pieces, laid at their offsets, are the header and the tables built whole,
    /// whatever the piece size (one row at least: a size under a row's entries gives one row
    /// a piece).
    #[test]
    fn device_pieces_are_the_whole_tables() {
        let img = Image {
            width: 5,
            height: 7,
            rgb: (0..35)
                .map(|k| [k as f32, 1.0 / (1.0 + k as f32), 2.0])
                .collect(),
            envmap: None,
            source: "ramp.exr".into(),
        };
        for filter in [Filter::Bilinear, Filter::Nearest] {
            let mut whole: Vec<f32> = [5u32, 7, filter.code(), 0].map(f32::from_bits).to_vec();
            tables(&img, filter, |v| v as f32, &mut whole);
            assert_eq!(whole.len(), words_len(5, 7));
            let row = ENTRY_WORDS * 6;
            for max in [1, row, 3 * row + 5, usize::MAX] {
                let mut laid = vec![f32::NAN; whole.len()];
                let mut pieces = 0;
                for (o, words) in device_chunks(&img, filter, max) {
                    assert!(words.len() <= max.max(row), "{max}: {}", words.len());
                    laid[o..o + words.len()].copy_from_slice(&words);
                    pieces += 1;
                }
                let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&laid), bits(&whole), "{filter:?} {max}");
                let rows_a_piece = (max / row).clamp(1, 7);
                assert_eq!(pieces, 1 + 7usize.div_ceil(rows_a_piece), "{max}");
            }
        }
    }

    /// The packed length is `words_len`, and the last entry of a row holds its total.
    #[test]
    fn tables_hold_each_rows_total() {
        let img = Image {
            width: 3,
            height: 2,
            rgb: vec![[1.0, 2.0, 0.5]; 6],
            envmap: None,
            source: "flat.exr".into(),
        };
        for filter in [Filter::Bilinear, Filter::Nearest] {
            let words = device_words(&img, filter);
            assert_eq!(words.len(), words_len(3, 2));
            assert_eq!(words[0].to_bits(), 3);
            assert_eq!(words[2].to_bits(), filter.code());
            // Row 1's total of ∫R du: 2π × the constant value, per channel.
            let total = HEADER_WORDS + 2 * 3 + ENTRY_WORDS * (4 + 3);
            for (c, v) in [1.0, 2.0, 0.5].iter().enumerate() {
                let want = 2.0 * PI * v;
                assert!((f64::from(words[total + c]) - want).abs() < 1e-6 * want);
            }
        }
    }

    /// The closed form against a fine midpoint rule, for short and long pieces.
    #[test]
    fn piece_moments_match_a_midpoint_rule() {
        for &(v0, v1, len, tau, u) in &[
            (1.0, 3.0, 0.5, 0.3, 0.2),
            (2.0, -1.0, 2.0, 1.7, 4.0),
            (0.5, 0.5, 1e-3, 7e-4, 2.5),
            (1.0, 2.0, 2.0 * PI, 2.0 * PI, 0.0),
        ] {
            let n = 200_000;
            let mut q = [0.0f64; 3];
            for i in 0..n {
                let t = (i as f64 + 0.5) * tau / n as f64;
                let r = v0 + (v1 - v0) * t / len;
                let a = u + t;
                q[0] += r;
                q[1] += r * a.sin();
                q[2] += r * a.cos();
            }
            let got = piece_moments(v0, v1, len, tau, u.cos(), u.sin());
            for k in 0..3 {
                let want = q[k] * tau / n as f64;
                assert!(
                    (got[k] - want).abs() <= 1e-9 * (v0.abs() + v1.abs()) * tau,
                    "{k}: {} vs {want}",
                    got[k]
                );
            }
        }
    }
}
