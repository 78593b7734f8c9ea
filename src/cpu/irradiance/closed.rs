//! The closed forms of irradiance (f64). Twin of `shaders/irradiance/closed.wgsl`.
//!
//! DESIGN.md §3 names them: uniform rect (Lambert's polygon formula), sphere caps (an unshaped
//! sphere under a similarity, a finite distant cone), the delta distant light, the dome, and
//! `treatAsPoint` (DESIGN.md §2 "Edge cases"). Each is exact in f64; the tests below and in
//! `tests/irradiance.rs` compare them with independent quadratures.

// `!(a > b)` is deliberate throughout: a NaN fails the test and takes the safe branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, PI};

use crate::cpu::shaping::shaping;
use crate::prepare::Prepared;

/// asin(k) − k for k in [0, 1] given also kc = √(1 − k²): by its series where the difference
/// cancels, else atan2(k, kc) − k (asin itself loses half the digits near 1).
pub fn asin_minus_x(k: f64, kc: f64) -> f64 {
    if k > 0.1 {
        return k.atan2(kc) - k;
    }
    // Σ_{j≥1} (2j)!/(4^j (j!)² (2j+1)) k^(2j+1); ten terms: truncation < 1e-21 relative at 0.1.
    let k2 = k * k;
    let mut c = 1.0f64; // (2j)!/(4^j (j!)²)
    let mut term_pow = k;
    let mut sum = 0.0;
    for j in 1..=10 {
        c *= (2 * j - 1) as f64 / (2 * j) as f64;
        term_pow *= k2;
        sum += c * term_pow / (2 * j + 1) as f64;
    }
    sum
}

/// [`cap_irradiance`] for α ≤ π/2.
fn cap_within_hemisphere(alpha: f64, sg: f64, cg: f64) -> f64 {
    let (sa, ca) = alpha.sin_cos();
    let gamma = sg.atan2(cg);
    if gamma >= alpha {
        return PI * sa * sa * sg;
    }
    if gamma <= -alpha {
        return 0.0;
    }
    // |γ| < α ≤ π/2, so cos γ > 0 and sin α > 0.
    let t = sg * ca / (cg * sa);
    let root = ((alpha - gamma).sin() * (alpha + gamma).sin())
        .max(0.0)
        .sqrt();
    let k = (root / cg).min(1.0);
    let sin_phi0 = root / (cg * sa);
    let phi0 = sin_phi0.atan2(-t);
    let (h, g) = ((0.5 * alpha).sin(), (0.5 * gamma).sin());
    // ψ0 = asin k, with cos ψ0 = cos α / cos γ (ψ0 ≤ π/2): atan2 stays accurate as k → 1.
    phi0 * sa * sa * sg + asin_minus_x(k, ca / cg) + k * (2.0 * h * h + 2.0 * ca * g * g)
}

/// ∫ max(0, n·ω) dω over the spherical cap of half-angle `alpha` (radians, (0, π]) around a unit
/// direction c, given `sg = n·c` (the sine of c's elevation γ above the receiver's horizon) and
/// `cg = |n × c|` (its cosine).
///
/// By Stokes' theorem, ∫_R n·ω dω = ½ ∮_∂R n·(ω × dω). For the part of the cap above the
/// horizon, ∂R is the cap's circle for |φ| ≤ φ0 (φ = azimuth around c from the side of n,
/// cos φ0 = −cot α·tan γ) and the horizon arc inside the cap (half-angle ψ0, sin ψ0 = sin α sin φ0):
/// `E = φ0 sin²α sin γ − sin α cos α cos γ sin φ0 + ψ0` (Snyder's sphere-light formula). With
/// k = sin α sin φ0 = √(sin(α−γ) sin(α+γ))/cos γ the last two terms are
/// `(asin k − k) + k·(2 sin²(α/2) + 2 cos α sin²(γ/2))`: no cancellation for small caps.
/// Fully above the horizon: `π sin²α sin γ`; fully below: 0. A cap wider than a hemisphere is
/// the sphere (π) minus its complement.
pub fn cap_irradiance(alpha: f64, sg: f64, cg: f64) -> f64 {
    if !(alpha > 0.0) {
        return 0.0;
    }
    if alpha > FRAC_PI_2 {
        let ac = PI - alpha;
        let gamma = sg.atan2(cg);
        if -gamma >= ac {
            // The complement lies wholly above the horizon of −n: π − π sin²ac·|sin γ|, written
            // as π(cos²ac + sin²ac·(1 − |sin γ|)).
            let (sa, ca) = ac.sin_cos();
            let q = (0.5 * (FRAC_PI_2 - gamma.abs())).sin();
            return PI * (ca * ca + sa * sa * 2.0 * q * q);
        }
        return PI - cap_within_hemisphere(ac, -sg, cg);
    }
    cap_within_hemisphere(alpha, sg, cg)
}

/// Unit-radiance irradiance of a uniform sphere of world radius `r` centred at `o`.
pub fn sphere_cap(o: DVec3, r: f64, x: DVec3, n: DVec3) -> f64 {
    let w = o - x;
    let d = w.length();
    if !(d > r) {
        return 0.0;
    }
    let c = w / d;
    // sin α = r/d, written through asin for the cap formula.
    let alpha = (r / d).asin();
    cap_irradiance(alpha, n.dot(c), n.cross(c).length())
}

/// Unit-radiance irradiance of an unshaped rect (half extents `hw`, `hh`) by Lambert's formula
/// on the parallelogram clipped to n·(P − x) ≥ 0. The caller checks that x is on the emitting
/// side.
pub fn rect_lambert(p: &Prepared, x: DVec3, n: DVec3, hw: f64, hh: f64) -> f64 {
    let m = p.linear;
    let o = p.origin - x;
    let q =
        [(-hw, -hh), (hw, -hh), (hw, hh), (-hw, hh)].map(|(a, b)| o + m * DVec3::new(a, b, 0.0));
    polygon_irradiance(&q, n)
}

/// Lambert's formula for a convex planar polygon given by the vectors `q` from x to its vertices
/// (in order), clipped to the receiver's upper half-space.
pub fn polygon_irradiance(q: &[DVec3], n: DVec3) -> f64 {
    if q.len() < 3 {
        return 0.0;
    }
    // Orientation: +1 when the vertices run counter-clockwise seen from x.
    let sigma = ((q[1] - q[0]).cross(q[2] - q[1])).dot(q[0]).signum();
    let clipped = clip_above(q, n);
    let mut sum = 0.0;
    for i in 0..clipped.len() {
        let (a, b) = (clipped[i], clipped[(i + 1) % clipped.len()]);
        let c = a.cross(b);
        let len = c.length();
        if len > 0.0 {
            sum += len.atan2(a.dot(b)) * n.dot(c) / len;
        }
    }
    (0.5 * sigma * sum).max(0.0)
}

/// The polygon `q` (vectors from x) clipped to the receiver's upper half-space `n·ω ≥ 0`
/// (Sutherland & Hodgman 1974).
pub fn clip_above(q: &[DVec3], n: DVec3) -> Vec<DVec3> {
    let mut clipped: Vec<DVec3> = Vec::with_capacity(q.len() + 1);
    for i in 0..q.len() {
        let (a, b) = (q[i], q[(i + 1) % q.len()]);
        let (da, db) = (n.dot(a), n.dot(b));
        if da >= 0.0 {
            clipped.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            clipped.push(a + (b - a) * (da / (da - db)));
        }
    }
    clipped
}

/// treatAsPoint: the full-size sphere's intensity from its origin (DESIGN.md §2).
pub fn point_irradiance(p: &Prepared, x: DVec3, n: DVec3, radius: f64) -> DVec3 {
    let w = p.origin - x;
    let d = w.length();
    if !(d > 0.0) {
        return DVec3::ZERO;
    }
    let cos_r = n.dot(w) / d;
    if !(cos_r > 0.0) {
        return DVec3::ZERO;
    }
    let e = -w / d;
    let xl = p.to_local * (x - p.origin);
    // Projected area of the ellipsoid {M y : |y| ≤ r} along e: π r² |det M| |M⁻¹ e|.
    let area = PI * radius * radius * p.det * xl.length() / d;
    p.base * shaping(p, e) * (area * cos_r / (d * d))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cpu::irradiance::tests::rel;
    use crate::cpu::quadrature::{Tolerance, integrate};

    #[test]
    fn asin_series_matches_direct() {
        for k in [1e-6f64, 1e-3, 0.02, 0.0999, 0.1, 0.5] {
            let direct = k.asin() - k;
            let kc = (1.0 - k * k).sqrt();
            assert!(rel(asin_minus_x(k, kc), direct) < 1e-9 || k < 1e-3, "{k}");
        }
        // Small k: the series is the accurate one.
        let k = 1e-3f64;
        assert!(
            rel(
                asin_minus_x(k, (1.0 - k * k).sqrt()),
                1e-9 / 6.0 + 3.0e-15 / 40.0
            ) < 1e-12
        );
    }

    #[test]
    fn cap_limits() {
        // Hemisphere around c at elevation γ: π(1 + sin γ)/2.
        for g in [-1.2f64, -0.3, 0.0, 0.4, 1.5] {
            let e = cap_irradiance(FRAC_PI_2, g.sin(), g.cos());
            assert!(rel(e, PI * (1.0 + g.sin()) / 2.0) < 1e-14, "{g}: {e}");
        }
        // The whole sphere: π for any receiver.
        assert!(rel(cap_irradiance(PI, 0.3, 0.3f64.asin().cos()), PI) < 1e-15);
        // Continuity across the full / partial boundary and across α = π/2.
        let a = 0.3f64;
        let e1 = cap_irradiance(a, (a + 1e-9).sin(), (a + 1e-9).cos());
        let e2 = cap_irradiance(a, (a - 1e-9).sin(), (a - 1e-9).cos());
        assert!(rel(e1, e2) < 1e-7);
        let g = -0.2f64;
        let e1 = cap_irradiance(FRAC_PI_2 - 1e-9, g.sin(), g.cos());
        let e2 = cap_irradiance(FRAC_PI_2 + 1e-9, g.sin(), g.cos());
        assert!(rel(e1, e2) < 1e-8, "{e1} {e2}");
    }

    /// The cap formula against an independent 2-D quadrature over the cap (polar coordinates
    /// around c, the receiver's max(0, ·) integrated in closed form over the azimuth).
    #[test]
    fn cap_against_quadrature() {
        for &(alpha, gamma) in &[
            (0.3f64, 0.1f64),
            (0.3, -0.25),
            (1.0, 0.2),
            (2.0, -0.5),
            (2.9, 0.3),
            (0.01, 0.004),
        ] {
            let q = integrate(
                &mut |t: f64| {
                    // ∫ max(0, sinγ cos t + cosγ sin t cos φ) dφ over [−π, π].
                    let (a, b) = (gamma.sin() * t.cos(), gamma.cos() * t.sin());
                    let v = if a >= b {
                        2.0 * PI * a
                    } else if a <= -b {
                        0.0
                    } else {
                        let ph = (-a / b).acos();
                        2.0 * (a * ph + b * ph.sin())
                    };
                    DVec3::splat(v * t.sin())
                },
                &[0.0, (FRAC_PI_2 - gamma).abs().min(alpha), alpha],
                Tolerance {
                    rel: 1e-13,
                    abs: 0.0,
                    max_intervals: 2000,
                },
            )
            .x;
            let e = cap_irradiance(alpha, gamma.sin(), gamma.cos());
            assert!(rel(e, q) < 1e-10, "α={alpha} γ={gamma}: {e} vs {q}");
        }
    }
}
