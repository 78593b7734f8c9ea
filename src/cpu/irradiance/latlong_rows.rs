//! A latlong dome's exact irradiance by rows of its texture: the method of the device's kernel
//! (`shaders/irradiance/latlong_rows.wgsl`, whose f64 twin this is). The CPU reference
//! integrates the same filtered texture by pieces and bounding caps (`dome.rs`); the tests hold
//! this method to it within 1e-9, which checks both, since they share only the texture.
//!
//! **The integral** (DESIGN.md §6 D1, D2, "what 'exact' means"). Under a conformal frame the
//! dome-space normal is `n = normalize(A_eff⁻¹ n_world)` and `E = ∫ tex(d) max(0, n·d) dd`
//! (the Jacobian `|det A|/|A_eff d|³` and `|A_eff d|` cancel). In the texture's angles
//! `θ = π·py/H` and `u = 2π·px/W`, `d = (sin θ sin u, cos θ, −sin θ cos u)` (§6 D2's
//! `atan2(dx, dz) = π − u`), so `n·d = a + sin θ (p sin u + q cos u)` with `a = n_y cos θ`,
//! `p = n_x`, `q = −n_z`; with `ρ = √(p² + q²)` and `ψ = atan2(p, q)` it is `a + b cos(u − ψ)`,
//! `b = ρ sin θ`, positive on the arc `|u − ψ| < α`, `α = acos(−a/b)` (the whole circle when
//! `a ≥ b`, nothing when `−a ≥ b`). At a fixed θ the filtered texture is
//! `(1 − f_y) R_{j₀}(u) + f_y R_{j₁}(u)` (§6 D1's bilinear rows and weight, clamped; nearest: one
//! row), so
//!
//! `E = ∫₀^π sin θ [(1 − f_y) I_{j₀}(θ) + f_y I_{j₁}(θ)] dθ`,
//! `I_j(θ) = a Q⁰_j + sin θ (p Qˢ_j + q Qᶜ_j)`, `Q_j = ∫_arc R_j {1, sin u, cos u} du`,
//!
//! and `Q_j` is the difference of the cumulative integrals `C_j(ψ + α) − C_j(ψ − α)`: a prefix
//! sum over whole pieces (`prepare::latlong_rows`) plus the end's partial piece in closed form
//! (`prepare::latlong_rows::piece_moments`).
//!
//! **The θ integral** is Gauss–Legendre ([`crate::rules::IRR_GL_ROWS`] nodes) on the intervals
//! between every point where the integrand is not smooth: the piece rows' boundaries (`f_y`'s
//! kinks and the rows' change), the θ at which the arc's end crosses a piece boundary `u_k`
//! (`a + b cos(u_k − ψ) = 0`, i.e. `θ_k = atan2(|n_y|, −ρ cos(u_k − ψ) sgn n_y)`; there the
//! integrand's second derivative jumps), and the two tangencies `cos(u − ψ) = ±1` (the
//! horizon's highest and lowest latitudes, where the arc appears or closes and `α` has a
//! square-root branch point: the integrand behaves like `|θ − θ_t|^{3/2}`). Every interval is
//! integrated in `σ = √|θ − θ_t|` about the tangency nearest it, in which the integrand is
//! smooth however close the interval comes to θ_t (crossings cluster there: one just past a
//! tangency left the next interval nearly singular in θ, 2.7e-8 off on a 1 × 1 map), and
//! intervals longer than [`crate::rules::IRR_ROWS_MAX_SPAN`] (coarse maps) in equal parts. The
//! boundaries of each half of the circle (`u_k − ψ ∈ [0, π)` and `[−π, 0)`) give monotone θ's,
//! so the breakpoints are a merge of four sorted sequences: `W + H + 4` intervals in all.
//!
//! With [`crate::rules::IRR_GL_ROWS`] = 6 the method agrees with the reference within 4e-11 on
//! 1 × 1 … 64 × 32 maps (4 nodes: 5e-8, 8 nodes: 5e-13); the kernel's f32 tables and
//! arithmetic, not the rule, set its error.

use glam::DVec3;
use std::f64::consts::PI;

use crate::prepare::latlong_rows::{ENTRY_WORDS, piece_moments};
use crate::rules::{IRR_GL_ROWS, IRR_ROWS_MAX_SPAN, gauss_legendre};

/// The tables of one texture as the twin reads them (`prepare::latlong_rows::tables` in f64,
/// the header's numbers as fields).
pub struct Rows<'a> {
    pub data: &'a [f64],
    pub width: usize,
    pub height: usize,
    pub bilinear: bool,
}

/// `∫ R_j {1, sin u, cos u} du` per channel.
pub(crate) type Moments = [DVec3; 3];

/// The receiver's horizon in the texture's angles (module docs).
struct Horizon {
    ny: f64,
    p: f64,
    q: f64,
    rho: f64,
    psi: f64,
}

/// Row `j`'s entry `k` (prefix moments, then the value at the piece's start).
pub(crate) fn row_entry(t: &Rows, j: usize, k: usize) -> (Moments, DVec3) {
    let o = 2 * t.width + ENTRY_WORDS * (j * (t.width + 1) + k);
    let v = |i: usize| DVec3::new(t.data[o + i], t.data[o + i + 1], t.data[o + i + 2]);
    ([v(0), v(3), v(6)], v(9))
}

/// The partial piece: `∫` over the first `tau` of row `j`'s piece `k`.
pub(crate) fn piece_partial(t: &Rows, j: usize, k: usize, tau: f64) -> Moments {
    let step = 2.0 * PI / t.width as f64;
    let (_, v0) = row_entry(t, j, k);
    let v1 = if t.bilinear {
        row_entry(t, j, k + 1).1
    } else {
        v0
    };
    let (c, s) = (t.data[2 * k], t.data[2 * k + 1]);
    let mut out = [DVec3::ZERO; 3];
    for ch in 0..3 {
        let m = piece_moments(v0[ch], v1[ch], step, tau, c, s);
        for i in 0..3 {
            out[i][ch] = m[i];
        }
    }
    out
}

/// `C_j(u)`: the integral from the first piece's start `u₀` to `u` (any real `u`: whole turns
/// add the row's total).
pub(crate) fn cumulative(t: &Rows, j: usize, u: f64) -> Moments {
    let w = t.width as f64;
    let step = 2.0 * PI / w;
    let u0 = if t.bilinear { 0.5 * step } else { 0.0 };
    let x = (u - u0) / step;
    let turns = (x / w).floor();
    let xt = x - turns * w;
    let k = (xt.floor().max(0.0) as usize).min(t.width - 1);
    let tau = (xt - k as f64) * step;
    let (total, _) = row_entry(t, j, t.width);
    let (prefix, _) = row_entry(t, j, k);
    let part = piece_partial(t, j, k, tau);
    std::array::from_fn(|i| turns * total[i] + prefix[i] + part[i])
}

/// `I_j(θ)`: row `j`'s clamped-cosine integral at the node `(cos θ, sin θ)`.
fn row_value(t: &Rows, j: usize, hz: &Horizon, cos_t: f64, sin_t: f64) -> DVec3 {
    let a = hz.ny * cos_t;
    let b = hz.rho * sin_t;
    let q = if a >= b {
        row_entry(t, j, t.width).0
    } else if -a >= b {
        return DVec3::ZERO;
    } else {
        let alpha = (b * b - a * a).max(0.0).sqrt().atan2(-a);
        let hi = cumulative(t, j, hz.psi + alpha);
        let lo = cumulative(t, j, hz.psi - alpha);
        std::array::from_fn(|i| hi[i] - lo[i])
    };
    a * q[0] + sin_t * (hz.p * q[1] + hz.q * q[2])
}

/// The texture rows `(j₀, j₁)` the filtered texture blends at θ in piece row `r`, and the
/// weight `f_y` of `j₁` (§6 D1's bilinear rows, clamped; nearest: one row, weight 0).
pub(crate) fn row_pair(t: &Rows, r: usize, theta: f64) -> (usize, usize, f64) {
    let py = theta / PI * t.height as f64;
    if t.bilinear {
        let j0 = r.saturating_sub(1).min(t.height - 1);
        let j1 = r.min(t.height - 1);
        (j0, j1, (py - r as f64 + 0.5).clamp(0.0, 1.0))
    } else {
        (r.min(t.height - 1), r.min(t.height - 1), 0.0)
    }
}

/// The integrand `sin θ [(1 − f_y) I_{j₀} + f_y I_{j₁}]` at θ in piece row `r`.
fn node_value(t: &Rows, r: usize, hz: &Horizon, theta: f64) -> DVec3 {
    let (sin_t, cos_t) = theta.sin_cos();
    let (j0, j1, fy) = row_pair(t, r, theta);
    let mut v = row_value(t, j0, hz, cos_t, sin_t);
    if j1 != j0 {
        v += (row_value(t, j1, hz, cos_t, sin_t) - v) * fy;
    }
    sin_t * v
}

/// `∫_lo^hi` of the integrand in piece row `r`, in `σ = √|θ − θ_t|` about the tangency `θ_t`
/// nearest the interval (which never lies inside it): the integrand is a smooth function of σ
/// there, however close the interval comes to the tangency.
fn interval_integral(t: &Rows, r: usize, hz: &Horizon, lo: f64, hi: f64, tangent: f64) -> DVec3 {
    let (x, w) = gauss_legendre(IRR_GL_ROWS);
    about_tangent(lo, hi, tangent, (&x, &w), |theta| {
        node_value(t, r, hz, theta)
    })
}

/// `∫_lo^hi f(θ) dθ` by the Gauss–Legendre rule `(x, w)` on [0, 1] in `σ = √|θ − tangent|`
/// (`θ = tangent ± σ²`, `dθ = 2σ dσ`), `tangent` outside (lo, hi): where the horizon is tangent
/// to a row the lit arc's half-width has a square-root branch point, smooth in σ. Shared
/// with the CPU sweep's crossed pieces (`dome/latlong/crossed.rs`).
pub(crate) fn about_tangent(
    lo: f64,
    hi: f64,
    tangent: f64,
    (x, w): (&[f64], &[f64]),
    mut f: impl FnMut(f64) -> DVec3,
) -> DVec3 {
    let above = lo >= tangent;
    let (s0, s1) = if above {
        (
            (lo - tangent).max(0.0).sqrt(),
            (hi - tangent).max(0.0).sqrt(),
        )
    } else {
        (
            (tangent - hi).max(0.0).sqrt(),
            (tangent - lo).max(0.0).sqrt(),
        )
    };
    let len = s1 - s0;
    let mut sum = DVec3::ZERO;
    for (g, wt) in x.iter().zip(w) {
        let sigma = s0 + len * g;
        let theta = if above {
            tangent + sigma * sigma
        } else {
            tangent - sigma * sigma
        };
        sum += f(theta) * (wt * len * 2.0 * sigma);
    }
    sum
}

/// The θ at which the horizon crosses the meridian `u` with `cos(u − ψ) = c`.
fn crossing_theta(hz: &Horizon, c: f64) -> f64 {
    horizon_crossing(hz.ny, hz.rho, c)
}

/// The θ ∈ [0, π] where `a cos θ + ρ sin θ c = 0`: where the horizon `m·d = a cos θ + ρ sin θ
/// cos(φ − φ₀)` ends an arc at `cos(φ − φ₀) = c` (shared with `dome/latlong/crossed.rs`).
pub(crate) fn horizon_crossing(a: f64, rho: f64, c: f64) -> f64 {
    let sg = if a >= 0.0 { 1.0 } else { -1.0 };
    a.abs().atan2(-rho * c * sg)
}

/// `E = ∫ tex(d) max(0, n·d) dd` for the dome-space unit normal `n` (module docs).
pub fn latlong_irradiance(t: &Rows, n: DVec3) -> DVec3 {
    let (p, q) = (n.x, -n.z);
    let rho = (p * p + q * q).sqrt();
    let hz = Horizon {
        ny: n.y,
        p,
        q,
        rho,
        psi: p.atan2(q),
    };
    let w = t.width;
    let h = t.height as f64;
    let step = 2.0 * PI / w as f64;
    let u0 = if t.bilinear { 0.5 * step } else { 0.0 };
    // Row boundaries: py = 0, then (bilinear) 0.5, 1.5, … H − 0.5, or (nearest) 1, 2, … H − 1,
    // then H.
    let rows = if t.bilinear { t.height + 1 } else { t.height };
    let row_end = |r: usize| -> f64 {
        let py = if r + 1 >= rows {
            h
        } else if t.bilinear {
            r as f64 + 0.5
        } else {
            (r + 1) as f64
        };
        PI * py / h
    };
    // The piece boundaries on each half of the circle: δ = u_k − ψ = d_a + i·step, half A
    // i = 0..n_a (δ ∈ [0, π)), half B i = −1..−(W − n_a) (δ ∈ [−π, 0)).
    let k_a = ((hz.psi - u0) / step).ceil();
    let d_a = u0 + k_a * step - hz.psi;
    let n_a = (((PI - d_a) / step).ceil().max(0.0) as usize).min(w);
    let n_b = w - n_a;
    let up = hz.ny >= 0.0;
    // In θ order: for n_y ≥ 0 θ grows with cos δ, i.e. from the far end of each half.
    let a_delta = |m: usize| -> f64 {
        let i = if up { n_a - 1 - m } else { m };
        d_a + i as f64 * step
    };
    let b_delta = |m: usize| -> f64 {
        let i = if up { n_b - m } else { m + 1 };
        d_a - i as f64 * step
    };
    let sg = if up { 1.0 } else { -1.0 };
    let t_one = hz.ny.abs().atan2(-hz.rho * sg);
    let t_two = hz.ny.abs().atan2(hz.rho * sg);
    let tangents = [t_one.min(t_two), t_one.max(t_two)];
    let (mut r, mut ia, mut ib, mut it) = (0usize, 0usize, 0usize, 0usize);
    let mut cur = 0.0;
    let mut sum = DVec3::ZERO;
    while r < rows {
        let cand_r = row_end(r);
        let cand_a = if ia < n_a {
            crossing_theta(&hz, a_delta(ia).cos())
        } else {
            f64::INFINITY
        };
        let cand_b = if ib < n_b {
            crossing_theta(&hz, b_delta(ib).cos())
        } else {
            f64::INFINITY
        };
        let cand_t = if it < 2 { tangents[it] } else { f64::INFINITY };
        let next = cand_r.min(cand_a).min(cand_b).min(cand_t);
        let hi = next.max(cur);
        if hi > cur {
            // Long intervals (coarse textures) in equal parts of at most IRR_ROWS_MAX_SPAN.
            let parts = ((hi - cur) / IRR_ROWS_MAX_SPAN).ceil().max(1.0);
            let len = (hi - cur) / parts;
            let count = parts as usize;
            for i in 0..count {
                let a = cur + i as f64 * len;
                let b = if i + 1 == count { hi } else { a + len };
                // The nearer tangency (tangents[1] when the part lies at or above it).
                let tangent = if a >= tangents[1] || a - tangents[0] > tangents[1] - b {
                    tangents[1]
                } else {
                    tangents[0]
                };
                sum += interval_integral(t, r, &hz, a, b, tangent);
            }
        }
        cur = hi;
        if next == cand_t {
            it += 1;
        } else if next == cand_a {
            ia += 1;
        } else if next == cand_b {
            ib += 1;
        } else {
            r += 1;
        }
    }
    sum
}

#[cfg(test)]
mod tests {
    use glam::DMat3;

    use super::*;
    use crate::cpu::irradiance::dome::DomeIrradiance;
    use crate::cpu::irradiance::dome::latlong::tests::{image, normals};
    use crate::prepare::latlong_rows::tables;
    use crate::prepare::texture::{DomeFormat, DomeFrame, Filter};

    /// The row method against the CPU reference (the exact sum over texel pieces): independent
    /// integrations of the same filtered texture, so agreement to 1e-9 checks both.
    #[test]
    fn rows_match_the_reference_within_1e_9() {
        let mut worst = 0.0f64;
        for &(w, h, filter) in &[
            (1, 1, Filter::Bilinear),
            (2, 1, Filter::Nearest),
            (4, 2, Filter::Bilinear),
            (16, 8, Filter::Bilinear),
            (16, 8, Filter::Nearest),
            (48, 24, Filter::Bilinear),
            (7, 5, Filter::Bilinear),
            (64, 32, Filter::Nearest),
        ] {
            let img = image(w, h, (w * 31 + h) as u64, false);
            let mut data = Vec::new();
            tables(&img, filter, |v| v, &mut data);
            let rows = Rows {
                data: &data,
                width: w,
                height: h,
                bilinear: filter == Filter::Bilinear,
            };
            let frame = DomeFrame::new(DMat3::IDENTITY, DMat3::IDENTITY).unwrap();
            let reference =
                DomeIrradiance::new(img.clone(), DomeFormat::LatLong, filter, frame).unwrap();
            for n in normals() {
                let want = reference.irradiance(n);
                let got = latlong_irradiance(&rows, n);
                let scale = want.max_element().max(1e-3);
                let err = (got - want).abs().max_element() / scale;
                worst = worst.max(err);
                assert!(
                    err < 1e-9,
                    "{w}x{h} {filter:?} n={n}: {got} vs {want} ({err:.2e})"
                );
            }
        }
        eprintln!("worst relative difference {worst:.2e}");
    }
}
