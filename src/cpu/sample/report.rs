//! The sampler report (DESIGN.md §9 S4): for a light and a receiver (x, n), the relative variance
//! per sample `(E[f²/p] − I²) / I²` of the estimator `f/p`, `f = Y(L) · max(0, n·ω)`, for
//! luxeval's strategy and two baselines — uniform by area over the whole emitting surface (what
//! hdEmbree does for every shape; for a dome, uniform over the sphere) and cosine-weighted about
//! n — by deterministic cubature of `f²/p` ([`super::cubature`]), never by Monte Carlo. `I` is
//! the reference's exact irradiance (luminance, without `diffuse`). "Samples to 1 % noise" is
//! the relative variance / 10⁻⁴.
//!
//! Finite shapes are integrated over their visible surface in local parameters (where the
//! integrand is bounded), distant lights over their cone, domes over the receiver's hemisphere.
//! The area baseline's density of a direction sums over every point of the surface along it
//! (a sphere's far side is drawn too, and wasted).

use glam::DVec3;
use std::f64::consts::PI;

use super::area::local_jacobian;
use super::cone::basis;
use super::cubature::integrate;
use super::{LightAt, luminance};
use crate::cpu::irradiance::{Adaptive, irradiance_with};
use crate::cpu::radiance::radiance;
use crate::cpu::shaping::shaping;
use crate::model::LightType;
use crate::prepare::Prepared;
use crate::prepare::env_table::EnvTable;
use crate::prepare::normalize::world_area;

/// Relative variances per sample at one receiver (`None` where a strategy does not apply: the
/// area baseline of a distant or delta light, everything where the light delivers nothing).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StrategyVariance {
    /// The exact irradiance `∫ f dω` (luminance, without `diffuse`).
    pub irradiance: f64,
    /// luxeval's own strategy (0 for a point or delta distant light).
    pub luxeval: Option<f64>,
    /// Uniform by area over the whole emitting surface (uniform over the sphere for a dome).
    pub area: Option<f64>,
    /// Cosine-weighted about n.
    pub cosine: Option<f64>,
}

/// Where the surface's points along the world direction `w` from `x` are (the parameters t > 0
/// of `x + t w`, world distance since `w` is unit) and their unit world normals. `w` comes from
/// a point of the surface, so a quadric's discriminant is clamped at 0 (a ray to a rim point is
/// tangent, and rounding must not lose the point it was aimed at).
fn surface_hits(p: &Prepared, x: DVec3, w: DVec3, mut hit: impl FnMut(f64, DVec3)) {
    let xl = p.to_local * (x - p.origin);
    let dl = p.to_local * w;
    // Normals map to world by the inverse transpose, (M⁻¹)ᵀ.
    let mut push = |t: f64, nl: DVec3, on: bool| {
        if t > 0.0 && on {
            hit(t, (p.to_local.transpose() * nl).normalize());
        }
    };
    match p.light.kind {
        LightType::Rect { width, height } => {
            if dl.z != 0.0 {
                let t = -xl.z / dl.z;
                let y = xl + t * dl;
                push(
                    t,
                    -DVec3::Z,
                    y.x.abs() <= width / 2.0 && y.y.abs() <= height / 2.0,
                );
            }
        }
        LightType::Disk { radius } => {
            if dl.z != 0.0 {
                let t = -xl.z / dl.z;
                let y = xl + t * dl;
                push(t, -DVec3::Z, y.truncate().length() <= radius);
            }
        }
        LightType::Sphere { radius: r, .. } => {
            let (a, b, c) = (dl.length_squared(), xl.dot(dl), xl.length_squared() - r * r);
            let disc = (b * b - a * c).max(0.0);
            for t in [(-b - disc.sqrt()) / a, (-b + disc.sqrt()) / a] {
                push(t, (xl + t * dl) / r, true);
            }
        }
        LightType::Cylinder {
            length, radius: r, ..
        } => {
            let a = dl.y * dl.y + dl.z * dl.z;
            let b = xl.y * dl.y + xl.z * dl.z;
            let c = xl.y * xl.y + xl.z * xl.z - r * r;
            let disc = (b * b - a * c).max(0.0);
            if a > 0.0 {
                for t in [(-b - disc.sqrt()) / a, (-b + disc.sqrt()) / a] {
                    let y = xl + t * dl;
                    push(t, DVec3::new(0.0, y.y, y.z) / r, y.x.abs() <= length / 2.0);
                }
            }
        }
        LightType::Distant { .. } | LightType::Dome | LightType::Mesh { .. } => {}
    }
}

/// The area baseline's density of `w`: `Σ d² / (A |cos θ|)` over the surface's points along it.
fn area_density(p: &Prepared, area: f64, x: DVec3, w: DVec3) -> f64 {
    let mut sum = 0.0;
    surface_hits(p, x, w, |t, nw| {
        sum += t * t / (area * nw.dot(w).abs().max(1e-300));
    });
    sum
}

/// The local point, outward normal and area element of a finite shape at parameters (a, b)
/// of [`parameter_box`]: (x, y) for a rect, (ρ, φ) for a disk, (z, φ) for a sphere
/// (Archimedes: dA = r dz dφ), (x, φ) for a cylinder.
pub fn surface_point(p: &Prepared, a: f64, b: f64) -> (DVec3, DVec3, f64) {
    match p.light.kind {
        LightType::Rect { .. } => (DVec3::new(a, b, 0.0), -DVec3::Z, 1.0),
        LightType::Disk { .. } => (DVec3::new(a * b.cos(), a * b.sin(), 0.0), -DVec3::Z, a),
        LightType::Sphere { radius: r, .. } => {
            let s = (r * r - a * a).max(0.0).sqrt();
            let y = DVec3::new(s * b.cos(), s * b.sin(), a);
            (y, y / r, r)
        }
        LightType::Cylinder { radius: r, .. } => {
            let n = DVec3::new(0.0, b.cos(), b.sin());
            (DVec3::new(a, r * n.y, r * n.z), n, r)
        }
        LightType::Distant { .. } | LightType::Dome | LightType::Mesh { .. } => {
            (DVec3::ZERO, DVec3::Z, 0.0)
        }
    }
}

/// The rectangle of parameters [`surface_point`] takes.
pub fn parameter_box(p: &Prepared) -> ((f64, f64), (f64, f64)) {
    let tau = (0.0, 2.0 * PI);
    match p.light.kind {
        LightType::Rect { width, height } => {
            ((-width / 2.0, width / 2.0), (-height / 2.0, height / 2.0))
        }
        LightType::Disk { radius } => ((0.0, radius), tau),
        LightType::Sphere { radius, .. } => ((-radius, radius), tau),
        LightType::Cylinder { length, .. } => ((-length / 2.0, length / 2.0), tau),
        LightType::Distant { .. } | LightType::Dome | LightType::Mesh { .. } => ((0.0, 1.0), tau),
    }
}

/// `(E[f²/p] − I²) / I²` from the integral of `f²/p`.
fn rel(second: f64, i: f64) -> Option<f64> {
    (i > 0.0 && second.is_finite()).then(|| (second / (i * i) - 1.0).max(0.0))
}

/// The relative variances of light `p` at (x, n) (module docs).
pub fn strategy_variance(
    p: &Prepared,
    env: Option<&EnvTable>,
    x: DVec3,
    n: DVec3,
) -> StrategyVariance {
    // I without `diffuse` (S1 (iii)); a light with diffuse 0 is evaluated as if it were 1.
    let diffuse = p.light.inputs.diffuse;
    let i = if diffuse > 0.0 {
        luminance(irradiance_with(p, x, n, &Adaptive::REFERENCE)) / diffuse
    } else {
        let mut undiffused = p.clone();
        undiffused.light.inputs.diffuse = 1.0;
        luminance(irradiance_with(&undiffused, x, n, &Adaptive::REFERENCE))
    };
    let mut out = StrategyVariance {
        irradiance: i,
        ..Default::default()
    };
    if !(i > 0.0) {
        return out;
    }
    let at = LightAt::new(p, env, x, Some(n));
    let f = |w: DVec3| luminance(radiance(p, x, w)) * n.dot(w).max(0.0);
    let depth = 9;
    let tol = 1e-9 * i * i;
    match (&p.light.kind, &at) {
        (_, LightAt::Delta(..)) => out.luxeval = Some(0.0),
        (_, LightAt::Line { a, e, hl, k }) => {
            // X uniform on [−hl, hl]: v(X) = Y(k S(−ω)) cos / |w|³ (mod.rs `draw`).
            let v = |xx: f64| {
                let w = *a + *e * xx;
                let d = w.length();
                let dir = w / d;
                luminance(*k * shaping(p, -dir)) * n.dot(dir).max(0.0) / (d * d * d)
            };
            let g = |s: f64, _: f64| {
                let val = v(s);
                val * val
            };
            let (m2, _) = integrate(&g, (-*hl, *hl), (0.0, 1.0), depth, 2, tol);
            // E[v²] = m2 / 2hl; E[v] = I.
            out.luxeval = rel(m2 / (2.0 * hl), i);
        }
        (LightType::Distant { .. }, LightAt::Cone(c)) => {
            let c = *c;
            let dir = |t: f64, phi: f64| cone_dir(&c.axis, t, phi);
            let g_lux = |t: f64, phi: f64| {
                let w = dir(t, phi);
                let fv = f(w);
                if fv > 0.0 {
                    fv * fv / at.pdf(p, x, w)
                } else {
                    0.0
                }
            };
            let g_cos = |t: f64, phi: f64| {
                let w = dir(t, phi);
                let fv = f(w);
                if fv > 0.0 {
                    fv * fv * PI / n.dot(w)
                } else {
                    0.0
                }
            };
            let range = ((0.0, c.one_minus_cos), (0.0, 2.0 * PI));
            out.luxeval = rel(integrate(&g_lux, range.0, range.1, depth, 2, tol).0, i);
            out.cosine = rel(integrate(&g_cos, range.0, range.1, depth, 2, tol).0, i);
        }
        (LightType::Dome | LightType::Mesh { .. }, _) => {
            // The receiver's hemisphere about n: t = 1 − cos θ ∈ [0, 1] (a pdf of 0 where f > 0
            // is an infinite variance, as f²/0 says).
            let dir = |t: f64, phi: f64| cone_dir(&n, t, phi);
            let g = |pdf: &dyn Fn(DVec3) -> f64, t: f64, phi: f64| {
                let w = dir(t, phi);
                let fv = f(w);
                if fv > 0.0 { fv * fv / pdf(w) } else { 0.0 }
            };
            let range = ((0.0, 1.0), (0.0, 2.0 * PI));
            let variance = |pdf: &dyn Fn(DVec3) -> f64| {
                rel(
                    integrate(&|t, ph| g(pdf, t, ph), range.0, range.1, depth, 3, tol).0,
                    i,
                )
            };
            out.luxeval = variance(&|w| at.pdf(p, x, w));
            out.cosine = variance(&|w| n.dot(w) / PI);
            out.area = match p.light.kind {
                // The area baseline of a dome at infinity: uniform over the sphere.
                LightType::Dome => variance(&|_| 1.0 / (4.0 * PI)),
                // A mesh light's strategy is the uniform area density (cpu::mesh::sample).
                _ => out.luxeval,
            };
        }
        (LightType::Distant { .. }, _) => {}
        _ => {
            // A finite shape: over its visible surface (cos_l > 0 faces x: planar shapes from
            // their emitting side, convex ones by their normal), dω = (cos_l/d_l²) dA_l / J.
            let xl = p.to_local * (x - p.origin);
            let area = world_area(&p.light);
            let (ra, rb) = parameter_box(p);
            let point = |a: f64, b: f64| -> Option<(DVec3, f64)> {
                let (y, nl, da) = surface_point(p, a, b);
                let d = xl - y;
                let dist = d.length();
                let cos = nl.dot(d) / dist;
                if !(cos > 0.0) {
                    return None;
                }
                let w = (p.linear * (y - xl)).normalize();
                Some((w, cos / (dist * dist) / local_jacobian(p, w) * da))
            };
            let g = |which: u8, a: f64, b: f64| -> f64 {
                let Some((w, dw)) = point(a, b) else {
                    return 0.0;
                };
                let fv = f(w);
                if !(fv > 0.0) {
                    return 0.0;
                }
                let pdf = match which {
                    0 => at.pdf(p, x, w),
                    1 => area_density(p, area, x, w),
                    _ => n.dot(w) / PI,
                };
                if pdf > 0.0 {
                    fv * fv / pdf * dw
                } else {
                    f64::INFINITY
                }
            };
            out.luxeval = rel(integrate(&|a, b| g(0, a, b), ra, rb, depth, 2, tol).0, i);
            out.area = if area > 0.0 {
                rel(integrate(&|a, b| g(1, a, b), ra, rb, depth, 2, tol).0, i)
            } else {
                None
            };
            out.cosine = rel(integrate(&|a, b| g(2, a, b), ra, rb, depth, 2, tol).0, i);
        }
    }
    out
}

/// The direction at (t = 1 − cos θ, φ) about the unit `axis`.
fn cone_dir(axis: &DVec3, t: f64, phi: f64) -> DVec3 {
    let (a, b) = basis(*axis);
    let sin = (t * (2.0 - t)).max(0.0).sqrt();
    (a * (sin * phi.cos()) + b * (sin * phi.sin()) + *axis * (1.0 - t)).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Light;
    use crate::prepare::TemperatureMode;
    use glam::{DMat4, DQuat};

    fn prep(l: &Light) -> Prepared {
        Prepared::new(l, TemperatureMode::Spec).unwrap()
    }

    fn down(l: Light) -> Light {
        l.with_transform(DMat4::from_rotation_translation(
            DQuat::from_rotation_x(-PI / 2.0),
            DVec3::new(0.0, 2.0, 0.0),
        ))
    }

    /// Closed forms: a uniform dome's cosine-weighted estimator is exact (f/p = πL) and its
    /// uniform-sphere baseline has relative variance 5/3; a tiny rect far overhead is nearly
    /// exact by solid angle and by area, and costs the cosine baseline π/Ω − 1.
    #[test]
    fn closed_forms() {
        // Uniform dome: f = L cos on the hemisphere, I = πL. Uniform over the sphere:
        // E[f²/p] = 4π ∫ L² cos² dω = 4π L² (2π/3), relvar = 8π²/3 / π² − 1 = 5/3.
        let dome = prep(&Light::dome());
        let v = strategy_variance(&dome, None, DVec3::ZERO, DVec3::Y);
        assert!(
            v.cosine.unwrap() < 1e-9 && v.luxeval.unwrap() < 1e-9,
            "{v:?}"
        );
        assert!((v.area.unwrap() - 5.0 / 3.0).abs() < 1e-7, "{v:?}");
        // A tiny rect far above: every strategy but the cosine one is nearly exact.
        let rect = prep(&down(Light::rect(0.02, 0.02)));
        let v = strategy_variance(&rect, None, DVec3::ZERO, DVec3::Y);
        assert!(v.luxeval.unwrap() < 1e-4 && v.area.unwrap() < 1e-4, "{v:?}");
        // The cosine baseline: E[f²/p] = π ∫ L² cos dω ≈ π L² Ω, I ≈ L Ω: relvar ≈ π/Ω − 1.
        let omega = 0.02 * 0.02 / 4.0;
        assert!(
            (v.cosine.unwrap() / (PI / omega - 1.0) - 1.0).abs() < 1e-3,
            "{v:?}"
        );
    }

    /// The area baseline on a far sphere: per unit of the projected disc its density is
    /// `1/(2πr² cos)` (front and hidden far side), so `E[f²/p] = L² 2πr² ∫ cos dA = (4/3)(πr²L)²`
    /// and the relative variance tends to 1/3, while the cone's tends to 0.
    #[test]
    fn sphere_area_baseline_wastes_its_far_side() {
        let s = prep(&down(Light::sphere(0.01)));
        let v = strategy_variance(&s, None, DVec3::ZERO, DVec3::Y);
        assert!(v.luxeval.unwrap() < 1e-4, "{v:?}");
        assert!((v.area.unwrap() - 1.0 / 3.0).abs() < 1e-3, "{v:?}");
    }
}
