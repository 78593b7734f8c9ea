//! Sampling a dome light (DESIGN.md §9 S1, S2 "dome"), f64 reference.
//!
//! - **Textured** (an [`EnvTable`]): a texel by the alias table (probability ∝ luminance of the
//!   filtered footprint × world solid angle, `prepare/env_table.rs`), then a point of the
//!   texel's chart drawn with the alias pick's leftover uniform and `u[1]` (uniform in the
//!   texel's pixel square for latlong and cross; uniform in texel ∩ disk's chords for the disk
//!   formats, exact at the rim), mapped to the dome direction `d` (§6 D2–D5) and to the world
//!   direction `ω = A_eff d / |A_eff d|` (§6 D1). Its density per unit world solid angle is
//!   `pmf(k) · ρ_k(q) / J_k(d) · |A_eff d|³ / |det A|`: ρ_k the chart density within the texel,
//!   J_k the dome solid angle per unit chart area, and the last factor the dome solid angle per
//!   world solid angle (the inverse of §6 D1's Jacobian `|det A| / |A_eff d|³`).
//!   [`pdf_dome`] finds the texel and chart point of ω by the lookup's own forward maps
//!   (`cpu::texture`), so it names the texel the emission reads, and evaluates the same product.
//! - **Untextured** (or a texture that is 0 everywhere, whose `EnvTable::new` is `None`):
//!   cosine-weighted about the normal when one is given (`pdf = max(0, n·ω)/π`, which is 0 below
//!   the horizon, where a one-sided receiver gets nothing), else uniform over the sphere
//!   (`1/4π`).
//!
//! Nothing here allocates; everything precomputed lives in the [`EnvTable`].

use glam::{DVec2, DVec3};

use super::cone::basis;
use crate::cpu::texture::{angular_st, cross_st, latlong_st, mirrored_ball_st};
use crate::prepare::Prepared;
use crate::prepare::env_table::{EnvTable, ReceiverTiles};
use crate::prepare::texture::DomeFormat;

const PI: f64 = std::f64::consts::PI;

/// A direction toward the dome and its density per unit world solid angle (module docs). `p`
/// is the dome light; `table` its texture's [`EnvTable`] (None: untextured); `n` the receiver's
/// normal, if any (used only without a table; normalised here); `rt` the receiver's tile
/// probabilities (the product with its cosine, [`EnvTable::receiver_tiles`]; `None` without a
/// normal); `u` uniform in [0, 1)⁶: the point from u[0], u[1], the texel from u[2] (with 53
/// bits) and u[3] — within the tile drawn by u[4], u[5] where `rt` is given.
pub fn sample_dome(
    _p: &Prepared,
    table: Option<&EnvTable>,
    n: Option<DVec3>,
    rt: Option<&ReceiverTiles>,
    u: [f64; 6],
) -> (DVec3, f64) {
    let Some(t) = table else {
        return match unit(n) {
            Some(n) => {
                // Malley's method: uniform on the unit disk (r = √u₀, φ = 2πu₁) lifted to the
                // hemisphere about n, whose density is cos θ / π.
                let (r, phi) = (u[0].sqrt(), 2.0 * PI * u[1]);
                let z = (1.0 - u[0]).max(0.0).sqrt();
                let (b1, b2) = basis(n);
                let w = (b1 * (r * phi.cos()) + b2 * (r * phi.sin()) + n * z).normalize();
                (w, n.dot(w).max(0.0) / PI)
            }
            None => {
                // Uniform on the sphere: z uniform in [−1, 1] (Archimedes), φ uniform.
                let z = 1.0 - 2.0 * u[0];
                let r = (1.0 - z * z).max(0.0).sqrt();
                let phi = 2.0 * PI * u[1];
                (
                    DVec3::new(r * phi.cos(), r * phi.sin(), z),
                    1.0 / (4.0 * PI),
                )
            }
        };
    };
    // The texel from u[2] (53 bits: a 2k × 1k map has 2²¹ cells) and the coin u[3] — within
    // the tile u[4], u[5] draw by the receiver's product where it is given; the point within
    // the texel from u[0], u[1].
    let k = pick_texel(t, rt, &u);
    let q = t.texel_point(k, u[0], u[1]);
    let d = t.chart_direction(k, q);
    let ad = t.frame.a_eff * d;
    let l = ad.length();
    let w = ad / l;
    // The density is evaluated at ω itself, as pdf_dome does, so that the two agree to the
    // bit. The draw's own texel k and point q give the same value except through rounding:
    // near a latlong pole or the angular rim (−Z) the density grows like 1/sin θ, and the
    // rounding of ω alone (1e-16) moves it by 1e-16/sin θ relative. Only where ω's lookup
    // names a neighbouring texel of weight 0 (a texel edge, measure zero) is the draw's own
    // density returned instead, so that a drawn direction never has pdf 0.
    match textured_pdf(t, rt, w) {
        pdf if pdf > 0.0 => (w, pdf),
        // Dome solid angle per world solid angle = |A_eff d|³ / |det A| (§6 D1).
        _ => (w, density(t, rt, k, q, d) * (l * l * l) / t.frame.det_abs),
    }
}

/// The texel drawn by u[2] (53 bits), u[3] — within the tile u[4] + u[5]·2⁻²⁴ draws from the
/// receiver's product where `rt` is given ([`ReceiverTiles::pick`]; the plain table's
/// otherwise, or for a tile of weight 0, which the product never draws).
#[inline]
fn pick_texel(t: &EnvTable, rt: Option<&ReceiverTiles>, u: &[f64; 6]) -> usize {
    match rt {
        Some(rt) if !t.tiles.inner.is_empty() => {
            let tile = rt.pick(u[4], u[5]);
            match &t.tiles.inner[tile] {
                Some(inner) => t.texel_of(tile, inner.pick(u[2], u[3])),
                None => t.table.pick(u[2], u[3]),
            }
        }
        _ => t.table.pick(u[2], u[3]),
    }
}

/// The probability of texel k: the table's, or, with a receiver's tiles, `P(tile | n) ·
/// pmf(k) / W_tile`.
#[inline]
fn texel_pmf(t: &EnvTable, rt: Option<&ReceiverTiles>, k: usize) -> f64 {
    match rt {
        Some(rt) if !t.tiles.inner.is_empty() => {
            let (tile, local) = t.tile_of(k);
            match &t.tiles.inner[tile] {
                Some(inner) => rt.pmf(tile) * inner.pmf(local),
                None => 0.0,
            }
        }
        _ => t.table.pmf(k),
    }
}

/// The density per unit world solid angle with which [`sample_dome`] draws the unit world
/// direction `w` (0 where it never goes): same arguments.
pub fn pdf_dome(
    _p: &Prepared,
    table: Option<&EnvTable>,
    n: Option<DVec3>,
    rt: Option<&ReceiverTiles>,
    w: DVec3,
) -> f64 {
    match table {
        Some(t) => textured_pdf(t, rt, w),
        None => match unit(n) {
            Some(n) => n.dot(w).max(0.0) / PI,
            None => 1.0 / (4.0 * PI),
        },
    }
}

/// [`pdf_dome`] of a textured dome: the density per unit world solid angle of the unit world
/// direction w (module docs).
#[inline]
fn textured_pdf(t: &EnvTable, rt: Option<&ReceiverTiles>, w: DVec3) -> f64 {
    // §6 D1: d = normalize(A_eff⁻¹ ω); for a unit ω, |A_eff d| = 1 / |A_eff⁻¹ ω|.
    let v = t.frame.inv * w;
    let li = v.length();
    if !(li > 0.0 && li.is_finite()) {
        return 0.0;
    }
    let d = v / li;
    let (k, q) = locate(t, d);
    density(t, rt, k, q, d) / (li * li * li * t.frame.det_abs)
}

/// The density per unit **dome** solid angle at dome direction d, found in texel k at chart
/// point q: `pmf(k) · ρ_k(q) / J_k(d)` ([`texel_pmf`]). J is 0 only at a latlong pole or the
/// angular rim's point −Z (measure zero), where the density is unbounded; it is kept finite
/// there.
#[inline]
fn density(t: &EnvTable, rt: Option<&ReceiverTiles>, k: usize, q: DVec2, d: DVec3) -> f64 {
    let m = texel_pmf(t, rt, k) * t.chart_density(k, q);
    if m == 0.0 {
        return 0.0;
    }
    m / t.chart_jacobian(k, d).max(f64::MIN_POSITIVE)
}

/// The texel and chart point of dome direction d, by the lookup's forward maps (§6 D2–D5,
/// `cpu::texture`) and §6 D1's texel rule: texel `(⌊px⌋, ⌊py⌋)` with latlong columns wrapped,
/// everything else clamped (for the cross within the face's block).
#[inline]
pub(crate) fn locate(t: &EnvTable, d: DVec3) -> (usize, DVec2) {
    let (w, h) = (t.width as f64, t.height as f64);
    let texel = |x: f64, y: f64, wrap: bool| -> usize {
        let i = if wrap {
            (x.floor() as i64).rem_euclid(t.width as i64) as usize
        } else {
            (x.floor().max(0.0) as usize).min(t.width as usize - 1)
        };
        let j = (y.floor().max(0.0) as usize).min(t.height as usize - 1);
        j * t.width as usize + i
    };
    match t.format {
        DomeFormat::LatLong => {
            let st = latlong_st(d);
            let (x, y) = (st.x * w, st.y * h);
            (texel(x, y, true), DVec2::new(x, y))
        }
        DomeFormat::MirroredBall | DomeFormat::Angular => {
            let st = if t.format == DomeFormat::MirroredBall {
                mirrored_ball_st(d)
            } else {
                angular_st(d)
            };
            let k = texel(st.x * w, st.y * h, false);
            // Back to the chart (a, b) = (2s − 1, 1 − 2t) (§6 D3).
            (k, DVec2::new(2.0 * st.x - 1.0, 1.0 - 2.0 * st.y))
        }
        DomeFormat::Cross => {
            // Face-local (s_f, t_f) ∈ [0, 1]² and the face's block (column, row).
            let c = cross_st(d);
            let n = t.width as usize / 3;
            let nf = n as f64;
            let local = |v: f64| ((v * nf).floor().max(0.0) as usize).min(n - 1);
            let i = c.z as usize * n + local(c.x);
            let j = c.w as usize * n + local(c.y);
            (
                j * t.width as usize + i,
                DVec2::new((c.z + c.x) * nf, (c.w + c.y) * nf),
            )
        }
    }
}

/// `n` normalised, or None for a zero or non-finite normal.
#[inline]
fn unit(n: Option<DVec3>) -> Option<DVec3> {
    let n = n?;
    let l = n.length();
    (l > 0.0 && l.is_finite()).then(|| n / l)
}

#[cfg(test)]
mod tests;
