//! `inputs:normalize`: the sizeFactor of every light type (spec/001 "inputs:normalize"), and the
//! exact world-space areas it needs.
//!
//! Computed once per light in f64 and folded into the base radiance uploaded to the GPU, so this
//! module has no WGSL twin.
//!
//! Areas are exact for any linear map (DESIGN.md §2 "Edge cases"):
//! - rect: `w·h·|a × b|`, disk: `π r²·|a × b|` (a, b, c = images of local X, Y, Z);
//! - sphere → ellipsoid with semi-axes r·σᵢ (σ the singular values of the map):
//!   `S = 4π·abc·R_G(a⁻², b⁻², c⁻²)` (DLMF 19.30.5, `S = 3V·R_G`);
//! - cylinder side → `length·r·P`, P the perimeter of the ellipse with conjugate semi-diameters
//!   `a×b` and `a×c` (the side's area element is `|a × ∂φ p|`), `P = 8·R_G(0, λ₁, λ₂)`
//!   with λ the squared semi-axes (DLMF 19.30.1 with 19.25.1).
//!
//! Carlson's symmetric integrals are computed by duplication to full f64 precision.

use glam::{DMat3, DVec3};
use std::f64::consts::PI;

use crate::model::{Light, LightType};

/// The sizeFactor the light's luminance is divided by: 1 when `normalize` is off.
pub fn size_factor(light: &Light) -> f64 {
    if !light.inputs.normalize {
        return 1.0;
    }
    match light.kind {
        LightType::Distant { angle } => distant_size_factor(angle),
        LightType::Dome => 1.0,
        _ => world_area(light),
    }
}

/// The DistantLight sizeFactor (spec/001): θmax = clamp(radians(angle)/2, 0, π);
/// 1 at θmax = 0, π sin²θmax up to π/2, (2 − sin²θmax)π above.
pub fn distant_size_factor(angle_deg: f64) -> f64 {
    let theta_max = distant_half_angle(angle_deg);
    let s2 = theta_max.sin().powi(2);
    if theta_max == 0.0 {
        1.0
    } else if theta_max <= PI / 2.0 {
        PI * s2
    } else {
        (2.0 - s2) * PI
    }
}

/// θmax of a DistantLight: half its angular diameter, in radians, clamped to [0, π].
pub fn distant_half_angle(angle_deg: f64) -> f64 {
    (angle_deg.to_radians() / 2.0).clamp(0.0, PI)
}

/// The world-space emitting area of an area light (0 for distant and dome lights), including
/// every scale, shear and mirror of its transform. Sphere and cylinder areas are those of the
/// full-size shape even when `treatAsPoint` / `treatAsLine` is set.
pub fn world_area(light: &Light) -> f64 {
    let m = light.linear();
    let (a, b, c) = (m.x_axis, m.y_axis, m.z_axis);
    match light.kind {
        LightType::Rect { width, height } => width * height * a.cross(b).length(),
        LightType::Disk { radius } => PI * radius * radius * a.cross(b).length(),
        LightType::Sphere { radius, .. } => ellipsoid_area(m, radius),
        LightType::Cylinder { length, radius, .. } => {
            length * radius * ellipse_perimeter_conjugate(a.cross(b), a.cross(c))
        }
        LightType::Distant { .. } | LightType::Dome => 0.0,
        // DESIGN.md §7 M2: the triangles' world area, one side (also when double-sided).
        LightType::Mesh { ref geometry, .. } => geometry.area,
    }
}

/// Surface area of the image of the sphere of radius `r` under `m`.
pub fn ellipsoid_area(m: DMat3, r: f64) -> f64 {
    let s = singular_values(m) * r;
    if s.min_element() == 0.0 {
        // Flat: both faces of the ellipse.
        let mut v = s.to_array();
        v.sort_by(f64::total_cmp);
        return 2.0 * PI * v[1] * v[2];
    }
    4.0 * PI * s.x * s.y * s.z * carlson_rg(1.0 / (s.x * s.x), 1.0 / (s.y * s.y), 1.0 / (s.z * s.z))
}

/// Perimeter of the ellipse `{cos φ·u + sin φ·v}` given two conjugate semi-diameters.
pub fn ellipse_perimeter_conjugate(u: DVec3, v: DVec3) -> f64 {
    // Squared semi-axes = eigenvalues of the Gram matrix [[u·u, u·v], [u·v, v·v]].
    let (p, q, r) = (u.dot(u), u.dot(v), v.dot(v));
    let mean = 0.5 * (p + r);
    let dev = (0.25 * (p - r) * (p - r) + q * q).sqrt();
    let l1 = mean + dev;
    let l2 = (mean - dev).max(0.0);
    ellipse_perimeter(l1.sqrt(), l2.sqrt())
}

/// Perimeter of an ellipse with semi-axes `a`, `b`: `8·R_G(0, a², b²)`.
pub fn ellipse_perimeter(a: f64, b: f64) -> f64 {
    8.0 * carlson_rg(0.0, a * a, b * b)
}

#[allow(clippy::needless_range_loop)] // index form mirrors the rotation formulas
/// Singular values of a 3×3 matrix: square roots of the eigenvalues of `mᵀm` (cyclic Jacobi).
pub fn singular_values(m: DMat3) -> DVec3 {
    let ata = m.transpose() * m;
    let mut a = ata.to_cols_array_2d();
    for _sweep in 0..64 {
        let off = a[0][1].powi(2) + a[0][2].powi(2) + a[1][2].powi(2);
        let diag = a[0][0].powi(2) + a[1][1].powi(2) + a[2][2].powi(2);
        if off <= 1e-30 * diag {
            break;
        }
        for (p, q) in [(0usize, 1usize), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // Rotate rows/cols p and q of the symmetric matrix.
            for k in 0..3 {
                let akp = a[k][p];
                let akq = a[k][q];
                a[k][p] = c * akp - s * akq;
                a[k][q] = s * akp + c * akq;
            }
            for k in 0..3 {
                let apk = a[p][k];
                let aqk = a[q][k];
                a[p][k] = c * apk - s * aqk;
                a[q][k] = s * apk + c * aqk;
            }
        }
    }
    DVec3::new(a[0][0], a[1][1], a[2][2])
        .max(DVec3::ZERO)
        .powf(0.5)
}

/// Carlson's R_F(x, y, z), at most one argument zero (Carlson 1995, duplication).
pub fn carlson_rf(x: f64, y: f64, z: f64) -> f64 {
    let (mut x, mut y, mut z) = (x, y, z);
    for _ in 0..100 {
        let mu = (x + y + z) / 3.0;
        let (dx, dy, dz) = (1.0 - x / mu, 1.0 - y / mu, 1.0 - z / mu);
        if dx.abs().max(dy.abs()).max(dz.abs()) < 1e-4 {
            // Series: error O(d⁶) ≈ 1e-24.
            let e2 = dx * dy - dz * dz;
            let e3 = dx * dy * dz;
            return (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0)
                / mu.sqrt();
        }
        let (sx, sy, sz) = (x.sqrt(), y.sqrt(), z.sqrt());
        let lambda = sx * sy + sx * sz + sy * sz;
        x = 0.25 * (x + lambda);
        y = 0.25 * (y + lambda);
        z = 0.25 * (z + lambda);
    }
    unreachable!("R_F duplication converges in < 40 steps for valid arguments")
}

/// Carlson's R_D(x, y, z) = R_J(x, y, z, z), z > 0.
pub fn carlson_rd(x: f64, y: f64, z: f64) -> f64 {
    let (mut x, mut y, mut z) = (x, y, z);
    let mut sum = 0.0;
    let mut fac = 1.0;
    for _ in 0..100 {
        let mu = (x + y + 3.0 * z) / 5.0;
        let (dx, dy, dz) = (1.0 - x / mu, 1.0 - y / mu, 1.0 - z / mu);
        if dx.abs().max(dy.abs()).max(dz.abs()) < 1e-4 {
            let ea = dx * dy;
            let eb = dz * dz;
            let ec = ea - eb;
            let ed = ea - 6.0 * eb;
            let ee = ed + ec + ec;
            let s = ed * (-3.0 / 14.0 + 9.0 / 88.0 * ed - 4.5 / 26.0 * dz * ee)
                + dz * (ee / 6.0 + dz * (-9.0 / 22.0 * ec + 3.0 / 26.0 * dz * ea));
            return 3.0 * sum + fac * (1.0 + s) / (mu * mu.sqrt());
        }
        let (sx, sy, sz) = (x.sqrt(), y.sqrt(), z.sqrt());
        let lambda = sx * sy + sx * sz + sy * sz;
        sum += fac / (sz * (z + lambda));
        fac *= 0.25;
        x = 0.25 * (x + lambda);
        y = 0.25 * (y + lambda);
        z = 0.25 * (z + lambda);
    }
    unreachable!("R_D duplication converges in < 40 steps for valid arguments")
}

/// Carlson's R_G(x, y, z) (DLMF 19.21.10), computed with the largest argument in the z slot.
pub fn carlson_rg(x: f64, y: f64, z: f64) -> f64 {
    let mut v = [x, y, z];
    v.sort_by(f64::total_cmp);
    let [x, y, z] = v;
    if z == 0.0 {
        return 0.0;
    }
    if y == 0.0 {
        // R_G(0, 0, z) = √z / 2 (DLMF 19.20.4); R_F and R_D diverge there.
        return 0.5 * z.sqrt();
    }
    0.5 * (z * carlson_rf(x, y, z) - (x - z) * (y - z) * carlson_rd(x, y, z) / 3.0
        + (x * y / z).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{DMat4, DQuat};

    fn rel(a: f64, b: f64) -> f64 {
        ((a - b) / b).abs()
    }

    #[test]
    fn carlson_known_values() {
        // DLMF 19.20.1 / 19.20.3 special values.
        assert!(rel(carlson_rf(1.0, 1.0, 1.0), 1.0) < 1e-15);
        assert!(rel(carlson_rf(0.0, 1.0, 1.0), PI / 2.0) < 1e-15);
        assert!(rel(carlson_rg(0.0, 1.0, 1.0), PI / 4.0) < 1e-15);
        assert!(rel(carlson_rd(1.0, 1.0, 1.0), 1.0) < 1e-15);
        // R_D(0, 2, 1) = 3·Γ(3/4)²/√(2π) (Carlson 1995 test value 1.7972103521034).
        assert!(rel(carlson_rd(0.0, 2.0, 1.0), 1.797_210_352_103_4) < 1e-13);
    }

    #[test]
    fn ellipse_perimeters() {
        assert!(rel(ellipse_perimeter(1.0, 1.0), 2.0 * PI) < 1e-15);
        assert!(rel(ellipse_perimeter(1.0, 0.0), 4.0) < 1e-15);
        // a = 2, b = 1: 4a·E(√3/2) = 9.688448220547675... (standard value).
        assert!(rel(ellipse_perimeter(2.0, 1.0), 9.688_448_220_547_675) < 1e-14);
        // Conjugate diameters of a circle at 60° give the same ellipse family.
        let u = DVec3::new(1.0, 0.0, 0.0);
        let v = DVec3::new(0.0, 2.0, 0.0);
        assert!(
            rel(
                ellipse_perimeter_conjugate(u, v),
                ellipse_perimeter(2.0, 1.0)
            ) < 1e-14
        );
        // Any other pair of conjugate semi-diameters of the same ellipse (a phase shift of the
        // parametrisation) gives the same perimeter.
        let t = 0.4f64;
        let (u2, v2) = (t.cos() * u + t.sin() * v, -t.sin() * u + t.cos() * v);
        assert!(
            rel(
                ellipse_perimeter_conjugate(u2, v2),
                ellipse_perimeter(2.0, 1.0)
            ) < 1e-14
        );
    }

    /// Spheroids have elementary closed forms; compare the elliptic-integral path with them.
    #[test]
    fn spheroid_areas_match_closed_forms() {
        let (a, c) = (2.0f64, 1.0f64); // oblate: semi-axes a, a, c
        let e = (1.0 - c * c / (a * a)).sqrt();
        let oblate = 2.0 * PI * a * a * (1.0 + (1.0 - e * e) / e * e.atanh());
        let m = DMat3::from_diagonal(DVec3::new(a, a, c));
        assert!(rel(ellipsoid_area(m, 1.0), oblate) < 1e-13);
        let (a, b) = (3.0f64, 1.5f64); // prolate: semi-axes b, b, a
        let e = (1.0 - b * b / (a * a)).sqrt();
        let prolate = 2.0 * PI * b * b * (1.0 + a / (b * e) * e.asin());
        let m = DMat3::from_diagonal(DVec3::new(b, a, b));
        assert!(rel(ellipsoid_area(m, 1.0), prolate) < 1e-13);
    }

    /// A rotated, scaled, sheared sphere: area via singular values equals the area of the
    /// diagonal ellipsoid with those semi-axes, and a numeric surface integral agrees.
    #[test]
    fn sheared_ellipsoid_area_by_quadrature() {
        let m = DMat3::from_cols(
            DVec3::new(1.25, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.6, 0.0, 0.75),
        ) * DMat3::from_quat(DQuat::from_rotation_y(0.7));
        let r = 0.3;
        // Independent check: ∫∫ |∂θ p × ∂φ p| dθ dφ with p = r·m·(sinθ cosφ, sinθ sinφ, cosθ),
        // Gauss–Legendre in θ (via midpoint on a fine grid; smooth periodic in φ).
        let (nt, np) = (2000, 400);
        let mut sum = 0.0;
        for i in 0..nt {
            let th = (i as f64 + 0.5) * PI / nt as f64;
            for j in 0..np {
                let ph = (j as f64 + 0.5) * 2.0 * PI / np as f64;
                let dth = m * DVec3::new(th.cos() * ph.cos(), th.cos() * ph.sin(), -th.sin()) * r;
                let dph = m * DVec3::new(-th.sin() * ph.sin(), th.sin() * ph.cos(), 0.0) * r;
                sum += dth.cross(dph).length();
            }
        }
        let quad = sum * (PI / nt as f64) * (2.0 * PI / np as f64);
        let exact = ellipsoid_area(m, r);
        assert!(rel(exact, quad) < 1e-6, "{exact} vs {quad}");
    }

    #[test]
    fn cylinder_area_under_shear_by_quadrature() {
        let light = Light::cylinder(2.0, 0.25).with_transform(DMat4::from_cols_array_2d(&[
            [1.25, 0.0, 0.3, 0.0],
            [0.2, 1.0, 0.0, 0.0],
            [0.6, 0.0, 0.75, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]));
        let m = light.linear();
        let n = 4096;
        let mut sum = 0.0;
        for j in 0..n {
            let ph = (j as f64 + 0.5) * 2.0 * PI / n as f64;
            let dx = m * DVec3::X * 2.0;
            let dph = m * DVec3::new(0.0, -ph.sin(), ph.cos()) * 0.25;
            sum += dx.cross(dph).length();
        }
        let quad = sum * 2.0 * PI / n as f64;
        let exact = world_area(&light);
        assert!(rel(exact, quad) < 1e-12, "{exact} vs {quad}");
        assert!(
            rel(
                world_area(&Light::cylinder(2.0, 0.25)),
                2.0 * PI * 0.25 * 2.0
            ) < 1e-15
        );
    }

    #[test]
    fn rect_and_disk_under_shear() {
        let m = DMat4::from_cols_array_2d(&[
            [2.0, 0.0, 0.0, 0.0],
            [1.0, 3.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        // The unit square maps to a parallelogram of area |det| = 6.
        assert!(rel(world_area(&Light::rect(1.0, 1.0).with_transform(m)), 6.0) < 1e-15);
        assert!(rel(world_area(&Light::disk(1.0).with_transform(m)), 6.0 * PI) < 1e-15);
    }

    /// reference/luxtest.md §6 A2: the distant normalize table, as sizeFactors.
    #[test]
    fn a2_distant_size_factors() {
        assert_eq!(distant_size_factor(0.0), 1.0);
        assert_eq!(distant_size_factor(-5.0), 1.0);
        for (angle, e_off) in [
            (20.0, 0.02842),
            (40.0, 0.11025),
            (60.0, 0.23562),
            (80.0, 0.38941),
            (100.0, 0.55307),
            (120.0, 0.70686),
            (140.0, 0.83223),
            (160.0, 0.91406),
            (180.0, 0.94248),
        ] {
            // E (normalize off) = 0.3·π·sin²θmax = 0.3·sizeFactor for θmax ≤ 90°.
            assert!(
                (0.3 * distant_size_factor(angle) - e_off).abs() < 5e-6,
                "{angle}"
            );
        }
        // Above 180° the (2 − sin²)π branch: 270° → θmax = 135°, sin² = 1/2.
        assert!(rel(distant_size_factor(270.0), 1.5 * PI) < 1e-15);
        assert!(rel(distant_size_factor(720.0), 2.0 * PI) < 1e-15);
    }
}
