//! The maps of one piece of the chart quadrature (f64). Twin of
//! `shaders/irradiance/pieces.wgsl`.
//!
//! Each smooth piece `[t0, t1]` of an outer (Y) or inner (X) integral is mapped to the unit
//! parameter s ∈ [0, 1]:
//! - a tan map `t = c + w·tan u` when the integrand's nearest pole `c ± i·w` (the line's closest
//!   approach to x, a Lorentzian peak) lies within [`TAN_MAP_RHO`] of the piece in the
//!   Bernstein-ellipse sense: Gauss rules on a function with a pole converge like ρ^(−2n), and
//!   the map removes the peak;
//! - a cubic grading `g ~ s³` toward an end flagged as a focus plane, where `|cos θ|^focus` is
//!   not smooth;
//! - on outer pieces, the cosine map `Y = Y0 + (Y1 − Y0)(1 − cos πs)/2`, which makes the
//!   square-root ends of disk and cylinder charts smooth.
//!
//! Kinks at the ends of a piece cost nothing.

use std::f64::consts::PI;

use crate::rules::TAN_MAP_RHO;

/// The map of one piece [t0, t1] of an outer (cosine map) or inner (no cosine map) integral:
/// an optional tan map `t = c + w·tan u` around a near pole, then the unit parameter s.
#[derive(Clone, Copy, Debug)]
pub struct PieceMap {
    pub c: f64,
    pub w: f64,
    pub tan_map: bool,
    pub u0: f64,
    pub u1: f64,
    pub grade_lo: bool,
    pub grade_hi: bool,
}

/// The Bernstein-ellipse parameter ρ of the point c + i·w for the interval [t0, t1]: Gauss
/// rules on a function with a pole there converge like ρ^(−2n).
pub fn bernstein_rho(t0: f64, t1: f64, c: f64, w: f64) -> f64 {
    let half = 0.5 * (t1 - t0);
    if !(half > 0.0) {
        return f64::INFINITY;
    }
    let (zr, zi) = ((c - 0.5 * (t0 + t1)) / half, w / half);
    // ρ = |z ± √(z² − 1)|, the larger.
    let (ar, ai) = (zr * zr - zi * zi - 1.0, 2.0 * zr * zi);
    let m = (ar * ar + ai * ai).sqrt().sqrt();
    let ang = 0.5 * ai.atan2(ar);
    let (sr, si) = (m * ang.cos(), m * ang.sin());
    let p = ((zr + sr).powi(2) + (zi + si).powi(2)).sqrt();
    let q = ((zr - sr).powi(2) + (zi - si).powi(2)).sqrt();
    p.max(q)
}

/// The map of [t0, t1] for an integrand whose pole nearest to the real axis is `c + i·w`, with
/// cubic grading toward the flagged ends.
pub fn piece_map(t0: f64, t1: f64, c: f64, w: f64, grade_lo: bool, grade_hi: bool) -> PieceMap {
    let tan_map = w.is_finite() && w > 0.0 && bernstein_rho(t0, t1, c, w) < TAN_MAP_RHO;
    let (u0, u1) = if tan_map {
        (((t0 - c) / w).atan(), ((t1 - c) / w).atan())
    } else {
        (t0, t1)
    };
    PieceMap {
        c,
        w,
        tan_map,
        u0,
        u1,
        grade_lo,
        grade_hi,
    }
}

/// How many equal u-spans a piece is cut into: with `max_u_span` (the kernel's rule), a
/// tan-mapped piece spans at most that many radians of u each; the reference never cuts.
pub fn span_count(m: &PieceMap, max_u_span: Option<f64>) -> usize {
    match max_u_span {
        Some(max) if m.tan_map => ((m.u1 - m.u0).abs() / max).ceil().max(1.0) as usize,
        _ => 1,
    }
}

/// Span j of k of a piece (the grading stays on the piece's outer ends).
pub fn span(m: &PieceMap, j: usize, k: usize) -> PieceMap {
    PieceMap {
        u0: m.u0 + (m.u1 - m.u0) * j as f64 / k as f64,
        u1: m.u0 + (m.u1 - m.u0) * (j + 1) as f64 / k as f64,
        grade_lo: m.grade_lo && j == 0,
        grade_hi: m.grade_hi && j + 1 == k,
        ..*m
    }
}

/// (t, dt/ds) at s ∈ [0, 1]; `cosine` applies the square-root-removing cosine map.
pub fn map_eval(m: &PieceMap, s: f64, cosine: bool) -> (f64, f64) {
    let (mut g, mut dg) = (s, 1.0);
    if m.grade_lo || m.grade_hi {
        let (g2, dg2) = grading(g, m.grade_lo, m.grade_hi);
        g = g2;
        dg *= dg2;
    }
    if cosine {
        let (sn, cs) = (PI * g).sin_cos();
        dg *= 0.5 * PI * sn;
        g = 0.5 * (1.0 - cs);
    }
    let u = m.u0 + (m.u1 - m.u0) * g;
    let du = (m.u1 - m.u0) * dg;
    if m.tan_map {
        let tn = u.tan();
        (m.c + m.w * tn, m.w * (1.0 + tn * tn) * du)
    } else {
        (u, du)
    }
}

/// A cubic grading toward the flagged ends of [0, 1]: g ~ s³ there.
fn grading(s: f64, lo: bool, hi: bool) -> (f64, f64) {
    match (lo, hi) {
        (true, false) => (s * s * s, 3.0 * s * s),
        (false, true) => {
            let r = 1.0 - s;
            (1.0 - r * r * r, 3.0 * r * r)
        }
        _ => {
            let (a, b) = (s * s * s, (1.0 - s).powi(3));
            let d = a + b;
            let da = 3.0 * s * s;
            let db = -3.0 * (1.0 - s) * (1.0 - s);
            (a / d, (da * d - a * (da + db)) / (d * d))
        }
    }
}

/// A sub-interval with graded ends split so that only the quarter next to each graded end is
/// graded (the cubic grading starves the rest of the interval of nodes): (t0, t1, lo, hi).
pub fn graded_parts(
    t0: f64,
    t1: f64,
    g0: bool,
    g1: bool,
) -> arrayvec::ArrayVec<(f64, f64, bool, bool), 3> {
    let q = 0.25 * (t1 - t0);
    let parts: &[(f64, f64, bool, bool)] = match (g0, g1) {
        (false, false) => &[(t0, t1, false, false)],
        (true, false) => &[(t0, t0 + q, true, false), (t0 + q, t1, false, false)],
        (false, true) => &[(t0, t1 - q, false, false), (t1 - q, t1, false, true)],
        (true, true) => &[
            (t0, t0 + q, true, false),
            (t0 + q, t1 - q, false, false),
            (t1 - q, t1, false, true),
        ],
    };
    parts.iter().copied().collect()
}
