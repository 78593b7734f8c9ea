//! A crossed piece's exact part in closed form across the columns (latlong.rs module docs
//! "Crossed pieces").

use glam::DVec3;

use super::Axes;
use crate::cpu::irradiance::dome::DomeIrradiance;
use crate::cpu::irradiance::latlong_rows::{about_tangent, horizon_crossing};

impl DomeIrradiance {
    /// A crossed piece's exact part, the value `DomeIrradiance::crossed` integrates with the
    /// general clip routine, in closed form across the columns (module docs "Crossed
    /// pieces"): `w ∫ sin θ ∫_lit L(φ, θ) (a cos θ + ρ sin θ cos ψ) dφ dθ`, `ψ = φ − φ₀`.
    pub(super) fn crossed_piece(&self, axes: &Axes, hz: &Horizon, i: usize, j: usize) -> DVec3 {
        let g = &self.grids[0];
        let (px, py) = (g.xs[i], g.ys[j]);
        let e = &axes.col_ends[i];
        let pi = std::f64::consts::PI;
        // ψ at the piece's lower φ end, in (−π, π], and the sines and cosines of ψ at its ends.
        let rot = |[s, c]: [f64; 2]| [s * hz.c0 - c * hz.s0, c * hz.c0 + s * hz.s0];
        let (at_lo, at_hi) = (rot(e.at_lo), rot(e.at_hi));
        let psi_lo = at_lo[0].atan2(at_lo[1]);
        let psi_hi = psi_lo + e.span;
        let tex = |ti: u32, tj: u32| crate::cpu::texture::tex_fetch(&self.img, ti, tj);
        let t = [
            [tex(px.i0, py.i0), tex(px.i0, py.i1)],
            [tex(px.i1, py.i0), tex(px.i1, py.i1)],
        ];
        let (h, w) = (self.geom.h, self.geom.w);
        let (theta0, theta1) = (pi * py.x0 / h, pi * py.x1 / h);
        // θ where an arc end passes one of the piece's column ends, and the tangencies.
        let mut cuts = [theta0, theta1, 0.0, 0.0, 0.0, 0.0];
        let mut n = 2;
        for c in [at_lo[1], at_hi[1]]
            .map(|c| hz.crossing(c))
            .into_iter()
            .chain(hz.tangents)
        {
            if c > theta0 && c < theta1 {
                cuts[n] = c;
                n += 1;
            }
        }
        let cuts = &mut cuts[..n];
        cuts.sort_by(f64::total_cmp);
        // The map along the columns at row y: ℓ0 + ℓ1 v, v = φ − φ_lo (φ decreases with x).
        let (x_lo, bilinear) = (px.x1, px.i0 != px.i1);
        let inner = |theta: f64| -> DVec3 {
            let (st, ct) = theta.sin_cos();
            let (wy0, wy1) = py.weights(theta * h / pi);
            let l = t.map(|[r0, r1]| r0 * wy0 + r1 * wy1);
            let (l0, l1) = if bilinear {
                let f = x_lo - px.origin;
                (
                    l[0] * (1.0 - f) + l[1] * f,
                    (l[1] - l[0]) * (-w / (2.0 * pi)),
                )
            } else {
                (l[0], DVec3::ZERO)
            };
            let (a, b) = (hz.a * ct, hz.rho * st);
            // The lit arc |ψ| < α: none, all, or its ends' sine and cosine.
            let (alpha, sin_a, cos_a) = if b <= 0.0 {
                if a > 0.0 {
                    (pi, 0.0, -1.0)
                } else {
                    return DVec3::ZERO;
                }
            } else {
                let kappa = -a / b;
                if kappa >= 1.0 {
                    return DVec3::ZERO;
                } else if kappa <= -1.0 {
                    (pi, 0.0, -1.0)
                } else {
                    (kappa.acos(), ((1.0 - kappa) * (1.0 + kappa)).sqrt(), kappa)
                }
            };
            // ∫ (ℓ0 + ℓ1 v)(a + b cos ψ) dψ = a(ℓ0 v + ℓ1 v²/2) + b(ℓ0 sin ψ + ℓ1 (v sin ψ + cos ψ)).
            let anti = |psi: f64, [sn, cs]: [f64; 2]| {
                let v = psi - psi_lo;
                (l0 * v + l1 * (0.5 * v * v)) * a + (l0 * sn + l1 * (v * sn + cs)) * b
            };
            let mut sum = DVec3::ZERO;
            for shift in [0.0, 2.0 * pi] {
                let (lo_arc, hi_arc) = (shift - alpha, shift + alpha);
                let start = if psi_lo >= lo_arc {
                    (psi_lo, at_lo)
                } else {
                    (lo_arc, [-sin_a, cos_a])
                };
                let end = if psi_hi <= hi_arc {
                    (psi_hi, at_hi)
                } else {
                    (hi_arc, [sin_a, cos_a])
                };
                if end.0 > start.0 {
                    sum += anti(end.0, end.1) - anti(start.0, start.1);
                }
            }
            sum * st
        };
        let (xs, ws) = hz.nodes;
        let mut total = DVec3::ZERO;
        for pair in cuts.windows(2) {
            let (lo, hi) = (pair[0], pair[1]);
            if hi <= lo {
                continue;
            }
            // The rule runs about the nearer tangency.
            let [t1, t2] = hz.tangents;
            let tangent = if lo >= t2 || lo - t1 > t2 - hi {
                t2
            } else {
                t1
            };
            total += about_tangent(lo, hi, tangent, (xs, ws), &inner);
        }
        total * hz.weight
    }
}

/// One normal's horizon in dome space, for [`DomeIrradiance::crossed_piece`]: `m·d = a cos θ +
/// ρ sin θ cos(φ − φ₀)`, with `(sin φ₀, cos φ₀)`, the two θ where it is tangent to a row, the
/// frame's constant weight and the θ rule's nodes.
pub(super) struct Horizon {
    pub(super) a: f64,
    pub(super) rho: f64,
    pub(super) s0: f64,
    pub(super) c0: f64,
    tangents: [f64; 2],
    weight: f64,
    nodes: &'static (Vec<f64>, Vec<f64>),
}

impl Horizon {
    pub(super) fn new(m: DVec3, weight: f64) -> Horizon {
        let (a, rho) = (m.y, m.x.hypot(m.z));
        let (s0, c0) = if rho > 0.0 {
            (m.x / rho, m.z / rho)
        } else {
            (0.0, 1.0)
        };
        let mut hz = Horizon {
            a,
            rho,
            s0,
            c0,
            tangents: [0.0; 2],
            weight,
            nodes: &CROSSED_RULE,
        };
        let (t1, t2) = (hz.crossing(-1.0), hz.crossing(1.0));
        hz.tangents = [t1.min(t2), t1.max(t2)];
        hz
    }

    /// The θ ∈ [0, π] where `a cos θ + ρ sin θ c = 0` (the arc end at `cos ψ = c`).
    fn crossing(&self, c: f64) -> f64 {
        horizon_crossing(self.a, self.rho, c)
    }
}

/// Gauss–Legendre nodes per smooth part of a crossed piece's θ span.
const CROSSED_NODES: usize = 8;
/// Their nodes and weights on [0, 1], computed once.
static CROSSED_RULE: std::sync::LazyLock<(Vec<f64>, Vec<f64>)> =
    std::sync::LazyLock::new(|| crate::rules::gauss_legendre(CROSSED_NODES));
