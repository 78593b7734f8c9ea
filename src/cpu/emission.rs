//! emission(light, ω) on the CPU (f64). Twin of `shaders/emission.wgsl`.
//!
//! DESIGN.md §3: the RGB radiance leaving the light's emitting surface along ω (ω points away
//! from the light; for a dome, toward the environment), 0 where no part of the surface emits
//! along ω. With the emission formula of DESIGN.md §2 / spec/001:
//! `L = intensity · 2^exposure · color ⊙ temperature(T) / sizeFactor · shaping(ω)`.

use glam::DVec3;

use super::shaping::{off_axis_angle, shaping};
use super::texture::{dome_factor, rect_mean};
use crate::model::LightType;
use crate::prepare::Prepared;

/// emission along the unit direction `e`.
pub fn emission(p: &Prepared, e: DVec3) -> DVec3 {
    let base = p.base;
    match p.light.kind {
        // DESIGN.md §6 D1: every multiplier times the texture along e (1 without one).
        LightType::Dome => base * dome_factor(p, e),
        LightType::Distant { .. } => {
            // A delta light (θmax = 0) has emission 0 (DESIGN.md §2 "Edge cases"); a finite
            // cone's boundary is inclusive. Distant lights are never shaped.
            let theta_max = p.distant_half_angle();
            if theta_max > 0.0 && off_axis_angle(p.axis, e) <= theta_max {
                base
            } else {
                DVec3::ZERO
            }
        }
        // DESIGN.md §6 "RectLight texture": a textured rect's emission is L(ω) ⊙ the area mean
        // of its filtered texture (1 without one).
        LightType::Rect { .. } | LightType::Disk { .. } => surface_emission(p, e) * rect_mean(p),
        LightType::Cylinder { .. } => {
            // The side's outward normals are ⊥ to the axis, so some point faces e unless e is
            // parallel to the axis.
            let el = p.to_local * e;
            if el.y != 0.0 || el.z != 0.0 {
                base * shaping(p, e)
            } else {
                DVec3::ZERO
            }
        }
        // A sphere (and its point approximation) emits along every direction.
        LightType::Sphere { .. } => base * shaping(p, e),
        LightType::Mesh { .. } => super::mesh::emission(p, e),
    }
}

/// L(e) of a rect or disk before any texture: one-sided toward local −Z, strictly ω · n > 0
/// (edge-on is 0).
pub fn surface_emission(p: &Prepared, e: DVec3) -> DVec3 {
    if e.dot(p.normal) > 0.0 {
        p.base * shaping(p, e)
    } else {
        DVec3::ZERO
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Light, Shaping};
    use crate::prepare::TemperatureMode;
    use glam::{DMat4, DQuat};

    fn prep(l: &Light) -> Prepared {
        Prepared::new(l, TemperatureMode::Spec).unwrap()
    }

    /// reference/luxtest.md §6 A1: L = intensity·2^exposure·color for an unshaped light.
    #[test]
    fn a1_scalar_emission() {
        let l = Light::sphere(0.5)
            .with_intensity(5.0)
            .with_exposure(-11.0)
            .with_color(DVec3::new(1.0, 0.5, 0.25));
        let got = emission(&prep(&l), DVec3::new(0.3, -0.2, 0.9).normalize());
        let want = 5.0 / 2048.0 * DVec3::new(1.0, 0.5, 0.25);
        assert_eq!(got, want);
        // Any direction, even behind: a sphere emits everywhere.
        assert_eq!(emission(&prep(&l), DVec3::Z), want);
    }

    /// reference/luxtest.md §6 A2 sizeFactors as emission values (radius, width sweep of
    /// frames 6–15: normalize divides by the world area).
    #[test]
    fn a2_area_size_factors_as_emission() {
        for r in [0.1, 0.2, 0.3, 0.4, 0.5] {
            let s = prep(&Light::sphere(r).with_intensity(5.0).with_normalize(true));
            assert!(
                (emission(&s, DVec3::X).x - 5.0 / (4.0 * std::f64::consts::PI * r * r)).abs()
                    < 1e-12
            );
            let d = prep(&Light::disk(r).with_intensity(5.0).with_normalize(true));
            assert!(
                (emission(&d, DVec3::NEG_Z).x - 5.0 / (std::f64::consts::PI * r * r)).abs() < 1e-12
            );
            let c = prep(
                &Light::cylinder(1.0, r)
                    .with_intensity(5.0)
                    .with_normalize(true),
            );
            assert!(
                (emission(&c, DVec3::Y).x - 5.0 / (2.0 * std::f64::consts::PI * r)).abs() < 1e-12
            );
        }
        for w in [0.2, 0.65, 1.1, 1.55, 2.0] {
            let l = prep(&Light::rect(w, 2.0).with_intensity(5.0).with_normalize(true));
            assert!((emission(&l, DVec3::NEG_Z).x - 5.0 / (2.0 * w)).abs() < 1e-12);
        }
        // Distant: 0.3 lux at any angle once normalised: L = 0.3 / (π sin²θmax).
        let d = prep(
            &Light::distant(40.0)
                .with_intensity(0.3)
                .with_normalize(true),
        );
        let want = 0.3 / (std::f64::consts::PI * 20f64.to_radians().sin().powi(2));
        assert!((emission(&d, DVec3::NEG_Z).x - want).abs() < 1e-12);
    }

    #[test]
    fn one_sided_rect_and_distant_cone() {
        let r = prep(&Light::rect(1.0, 1.0));
        assert_eq!(emission(&r, DVec3::NEG_Z), DVec3::ONE);
        assert_eq!(emission(&r, DVec3::Z), DVec3::ZERO);
        assert_eq!(emission(&r, DVec3::X), DVec3::ZERO); // edge-on
        let d = prep(&Light::distant(10.0).with_intensity(1.0));
        assert_eq!(emission(&d, DVec3::NEG_Z), DVec3::ONE);
        let inside = DQuat::from_rotation_x(4.9f64.to_radians()) * DVec3::NEG_Z;
        let outside = DQuat::from_rotation_x(5.1f64.to_radians()) * DVec3::NEG_Z;
        assert_eq!(emission(&d, inside), DVec3::ONE);
        assert_eq!(emission(&d, outside), DVec3::ZERO);
        assert_eq!(
            emission(&prep(&Light::distant(0.0)), DVec3::NEG_Z),
            DVec3::ZERO
        );
    }

    /// Shaping uses the primary axis (direction image of −Z); one-sidedness uses the normal
    /// (inverse transpose). Under shear they differ.
    #[test]
    fn shear_separates_axis_and_normal() {
        let m = DMat4::from_cols_array_2d(&[
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [1.0, 0.0, 1.0, 0.0], // local Z -> (1, 0, 1)
            [0.0, 0.0, 0.0, 1.0],
        ]);
        let p = prep(&Light::disk(0.5).with_transform(m));
        assert!((p.axis - DVec3::new(-1.0, 0.0, -1.0).normalize()).length() < 1e-15);
        assert!((p.normal - DVec3::NEG_Z).length() < 1e-15);
        // Focus with a narrow power peaks along the axis, not along the normal.
        let s = Shaping {
            focus: 50.0,
            cone_angle: 180.0,
            ..Shaping::default()
        };
        let p = prep(&Light::disk(0.5).with_transform(m).with_shaping(s));
        assert!(emission(&p, p.axis).x > 0.999);
        assert!(emission(&p, DVec3::NEG_Z).x < 1e-6);
    }

    /// reference/luxtest.md §6 A4 as emission values: cone 30°, softness 0 / 0.5 / 1 and focus 2
    /// (tint black), I(θ)/I0 = S(θ); the table's E = I0·S(θ)·cos³θ/h² with h = 1.
    #[test]
    #[allow(clippy::approx_constant)] // 0.785398 is the table's I0 = L·π·r², as printed there
    fn a4_cone_and_focus_factors() {
        let i0 = 0.785398;
        let rows: [(f64, [f64; 4]); 6] = [
            (0.0, [0.785398, 0.785398, 0.785398, 0.785398]),
            (0.1, [0.773763, 0.773763, 0.700326, 0.766102]),
            (0.2, [0.740525, 0.740525, 0.504136, 0.712044]),
            (0.3, [0.690161, 0.665597, 0.286694, 0.633175]),
            (0.4, [0.628641, 0.358110, 0.115189, 0.541932]),
            (0.5, [0.561985, 0.074913, 0.020415, 0.449588]),
        ];
        let variants = [
            Shaping {
                cone_angle: 30.0,
                cone_softness: 0.0,
                ..Shaping::default()
            },
            Shaping {
                cone_angle: 30.0,
                cone_softness: 0.5,
                ..Shaping::default()
            },
            Shaping {
                cone_angle: 30.0,
                cone_softness: 1.0,
                ..Shaping::default()
            },
            Shaping {
                cone_angle: 180.0,
                focus: 2.0,
                ..Shaping::default()
            },
        ];
        for (x, want) in rows {
            let theta = f64::atan(x);
            let e = DVec3::new(theta.sin(), 0.0, -theta.cos());
            for (k, s) in variants.iter().enumerate() {
                let p = prep(&Light::sphere(0.005).with_shaping(s.clone()));
                let e_floor = i0 * emission(&p, e).x * theta.cos().powi(3);
                assert!(
                    (e_floor - want[k]).abs() < 1.5e-6,
                    "x={x} variant {k}: {e_floor} vs {}",
                    want[k]
                );
            }
        }
        // Beyond the cone (x = 0.6, θ = 30.96°) the cone variants are dark; focus is not.
        let theta = 0.6f64.atan();
        let e = DVec3::new(theta.sin(), 0.0, -theta.cos());
        for (k, s) in variants.iter().enumerate() {
            let p = prep(&Light::sphere(0.005).with_shaping(s.clone()));
            let e_floor = i0 * emission(&p, e).x * theta.cos().powi(3);
            let want = if k == 3 { 0.364118 } else { 0.0 };
            assert!((e_floor - want).abs() < 1.5e-6, "variant {k}");
        }
    }

    /// reference/luxtest.md §6 A5: focusTint separates channels.
    #[test]
    fn a5_focus_tint_channel_separation() {
        let s = Shaping {
            focus: 2.5,
            focus_tint: DVec3::X,
            cone_angle: 180.0,
            ..Shaping::default()
        };
        let p = prep(&Light::sphere(0.5).with_shaping(s));
        let theta = 0.7f64;
        let e = DVec3::new(0.0, theta.sin(), -theta.cos());
        let got = emission(&p, e);
        assert_eq!(got.x, 1.0);
        assert!((got.y - theta.cos().powf(2.5)).abs() < 1e-15);
        assert_eq!(got.y, got.z);
    }

    /// reference/luxtest.md §6 A7 through the emission formula, with the three modes.
    #[test]
    fn a7_temperature_in_emission() {
        let l = Light::rect(1.0, 1.0)
            .with_intensity(5.0)
            .with_temperature(2000.0);
        let spec = emission(
            &Prepared::new(&l, TemperatureMode::Spec).unwrap(),
            DVec3::NEG_Z,
        );
        let usd = emission(
            &Prepared::new(&l, TemperatureMode::Usd).unwrap(),
            DVec3::NEG_Z,
        );
        assert!(
            (usd - 5.0 * DVec3::new(2.52057, 0.64689, 0.02040))
                .abs()
                .max_element()
                < 5e-5
        );
        let white = DVec3::new(1.04333, 0.98362, 1.03461);
        assert!((spec - usd / white).abs().max_element() < 1e-4);
        let l6500 = l.clone().with_temperature(6500.0);
        assert_eq!(
            emission(
                &Prepared::new(&l6500, TemperatureMode::Spec).unwrap(),
                DVec3::NEG_Z
            ),
            DVec3::splat(5.0)
        );
    }
}
