//! Disk, cylinder and ellipsoid lights sampled in the light's own frame (f64), DESIGN.md §9 S2.
//!
//! The shapes keep their canonical form in the local frame (DESIGN.md §2 "Frames and shapes"),
//! so each is sampled there and the density carried to world solid angle by the Jacobian of the
//! direction map `ω ↦ ω_l = Aω/|Aω|` (A = M⁻¹, the world → local linear map):
//! `dω_l/dω = |det A| / |Aω|³` (the solid-angle Jacobian of a linear map of directions, as for
//! a dome's frame in DESIGN.md §6 D1). Under a similarity it is 1 and the local densities are
//! the world ones: uniform by visible area for disks and cylinders
//! (`pdf = d²/(A·|cos θ_l|)`), uniform in the subtended cone for spheres.
//!
//! A point of a disk or of the visible band of a cylinder is never hidden by the rest of the
//! shape: a disk is planar, and a cylinder point whose outward normal faces x lies on a convex
//! body's boundary with x outside its tangent plane; the map to world preserves both facts
//! (normals map by A^T, so `(x − y)·n` keeps its sign).

use glam::DVec3;
use std::f64::consts::PI;

use super::cone::Cone;
use crate::cpu::shapes::{cylinder_hit, disk_hit, plane_hit};
use crate::prepare::Prepared;

/// World solid angle → local solid angle at the world direction `w`: `|det A| / |Aω|³`.
pub fn local_jacobian(p: &Prepared, w: DVec3) -> f64 {
    let l = (p.to_local * w).length();
    1.0 / (p.det * l * l * l)
}

/// A local direction's sample carried to world: the unit world direction toward the local
/// point `y_l` from the local receiver `x_l`, and the world density for the local density `pdf_l`.
fn to_world(p: &Prepared, d_l: DVec3, pdf_l: f64) -> (DVec3, f64) {
    let w = (p.linear * d_l).normalize();
    (w, pdf_l * local_jacobian(p, w))
}

/// Disk of radius `r` (local XY plane, emitting toward −Z) seen from the local point `xl`
/// (`xl.z < 0`): a point uniform in the disk's area (Shirley & Chiu's concentric map,
/// "A Low Distortion Map Between Disk and Square", JGT 2(3), 1997), local density
/// `d_l² / (π r² cos θ_l)`.
pub fn disk_sample(p: &Prepared, xl: DVec3, r: f64, u: [f64; 2]) -> (DVec3, f64) {
    let (a, b) = (2.0 * u[0] - 1.0, 2.0 * u[1] - 1.0);
    let (rho, phi) = if a == 0.0 && b == 0.0 {
        (0.0, 0.0)
    } else if a.abs() > b.abs() {
        (a, PI / 4.0 * (b / a))
    } else {
        (b, PI / 2.0 - PI / 4.0 * (a / b))
    };
    let y = DVec3::new(r * rho * phi.cos(), r * rho * phi.sin(), 0.0);
    let d = y - xl;
    let dist2 = d.length_squared();
    let cos = d.z / dist2.sqrt();
    to_world(p, d, dist2 / (PI * r * r * cos))
}

/// The density [`disk_sample`] draws the world direction `w` with.
pub fn disk_pdf(p: &Prepared, xl: DVec3, r: f64, w: DVec3) -> f64 {
    let dl = p.to_local * w;
    if !disk_hit(xl, dl, r) {
        return 0.0;
    }
    let Some(y) = plane_hit(xl, dl) else {
        return 0.0;
    };
    let d = y - xl;
    let dist2 = d.length_squared();
    dist2 / (PI * r * r * (d.z / dist2.sqrt())) * local_jacobian(p, w)
}

/// The band of a cylinder (local X axis, half-length `hl`, radius `r`) that the local point
/// `xl` sees: azimuths within β = acos(r/ρ) of x's own, all of X ∈ [−hl, hl]. `None` from
/// inside the infinite cylinder (it delivers nothing there).
fn visible_band(xl: DVec3, r: f64) -> Option<(f64, f64)> {
    let rho = (xl.y * xl.y + xl.z * xl.z).sqrt();
    if !(rho > r) {
        return None;
    }
    Some((xl.z.atan2(xl.y), (r / rho).acos()))
}

/// `(x − y)·n` for the band point at azimuth Δ from x's own, `ρ cos Δ − r`, written
/// `2ρ sin((β + Δ)/2) sin((β − |Δ|)/2)` (cos β = r/ρ) so that it keeps its digits at the
/// silhouette, where the density `∝ 1/cos` is largest.
fn facing(xl: DVec3, r: f64, beta: f64, delta: f64) -> f64 {
    let rho = (xl.y * xl.y + xl.z * xl.z).sqrt();
    let _ = r;
    let a = delta.abs();
    2.0 * rho * (0.5 * (beta + a)).sin() * (0.5 * (beta - a)).sin()
}

/// A point uniform in the area of the visible band, local density
/// `d_l² / (A_band · cos θ_l)` with `A_band = 2β r · 2hl`.
pub fn cylinder_sample(
    p: &Prepared,
    xl: DVec3,
    hl: f64,
    r: f64,
    u: [f64; 2],
) -> Option<(DVec3, f64)> {
    let (phi_x, beta) = visible_band(xl, r)?;
    let delta = beta * (2.0 * u[1] - 1.0);
    let (s, c) = (phi_x + delta).sin_cos();
    let y = DVec3::new(hl * (2.0 * u[0] - 1.0), r * c, r * s);
    let d = y - xl;
    let dist2 = d.length_squared();
    let cos = facing(xl, r, beta, delta) / dist2.sqrt();
    if !(cos > 0.0) {
        return None;
    }
    Some(to_world(p, d, dist2 / (4.0 * beta * r * hl * cos)))
}

/// The density [`cylinder_sample`] draws the world direction `w` with: through the entry point
/// of the ray on the outer wall, where the ray sees the emitting side first.
pub fn cylinder_pdf(p: &Prepared, xl: DVec3, hl: f64, r: f64, w: DVec3) -> f64 {
    let dl = p.to_local * w;
    if !cylinder_hit(xl, dl, hl, r) {
        return 0.0;
    }
    let Some((_, beta)) = visible_band(xl, r) else {
        return 0.0;
    };
    // The nearer root of |(x + t d)_yz|² = r², in the cancellation-free form.
    let a = dl.y * dl.y + dl.z * dl.z;
    let b = 2.0 * (xl.y * dl.y + xl.z * dl.z);
    let c = xl.y * xl.y + xl.z * xl.z - r * r;
    let disc = (b * b - 4.0 * a * c).max(0.0);
    let q = -0.5 * (b + disc.sqrt().copysign(b));
    let t = (q / a).min(c / q);
    let y = xl + t * dl;
    let d = y - xl;
    let dist2 = d.length_squared();
    let delta = (xl.y * y.z - xl.z * y.y).atan2(xl.y * y.y + xl.z * y.z);
    let cos = facing(xl, r, beta, delta) / dist2.sqrt();
    if !(cos > 0.0) {
        return 0.0;
    }
    dist2 / (4.0 * beta * r * hl * cos) * local_jacobian(p, w)
}

/// The cone the local sphere of radius `r` subtends from `xl`, `None` from inside.
fn local_cone(xl: DVec3, r: f64) -> Option<Cone> {
    let d = xl.length();
    (d > r).then(|| Cone::subtended(-xl / d, r, d))
}

/// A sphere light under any transform (an ellipsoid in the world): uniform in the cone the
/// local sphere subtends, carried to world by the Jacobian (exactly the world cone under a
/// similarity).
pub fn ellipsoid_sample(p: &Prepared, xl: DVec3, r: f64, u: [f64; 2]) -> Option<(DVec3, f64)> {
    let cone = local_cone(xl, r)?;
    Some(to_world(p, cone.sample(u), 1.0 / cone.solid_angle()))
}

/// The density [`ellipsoid_sample`] draws the world direction `w` with.
pub fn ellipsoid_pdf(p: &Prepared, xl: DVec3, r: f64, w: DVec3) -> f64 {
    let Some(cone) = local_cone(xl, r) else {
        return 0.0;
    };
    let wl = (p.to_local * w).normalize();
    cone.pdf(wl) * local_jacobian(p, w)
}
