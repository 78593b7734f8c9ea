//! ShapingAPI on the CPU (f64). Twin of `shaders/shared/shaping.wgsl`.
//!
//! spec/002, as pinned by DESIGN.md §2 "Shaping":
//! - θoff = angle between the emission direction and the light's primary axis (world image of
//!   local −Z), computed as atan2(|e × a|, e · a) for precision near 0;
//! - cone: `L ·= 1 − smoothstep(θoff; (1 − softness)·θcone, θcone)` on the angle, softness
//!   clamped to [0, 1]; θoff > θcone is always 0 ("guaranteed to be zero"); at softness 0 the
//!   cut-off is hard and the boundary itself is lit;
//! - focus: `f = |cos θoff|^focus`, `L ⊙= lerp(focusTint, 1, f)` = tint + f·(1 − tint);
//!   focus ≤ 0 is ignored;
//! - IES: the profile's value along the light-space direction multiplies as candela (§6 I7,
//!   [`super::ies`]).

use glam::DVec3;

use super::ies::ies_of;
use crate::prepare::Prepared;

/// θoff in radians, in [0, π].
pub fn off_axis_angle(axis: DVec3, e: DVec3) -> f64 {
    e.cross(axis).length().atan2(e.dot(axis))
}

/// UsdLux's `_Smoothstep(t, [lo, hi])` (value first): a zero-width range is a step that is 0 at
/// and below `lo`.
pub fn smoothstep_angle(t: f64, lo: f64, hi: f64) -> f64 {
    if hi - lo == 0.0 {
        return if t <= lo { 0.0 } else { 1.0 };
    }
    let s = ((t - lo) / (hi - lo)).clamp(0.0, 1.0);
    s * s * (3.0 - 2.0 * s)
}

/// `1 − smoothstep(θ; start, θcone)` with `start = (1 − softness)·θcone` (prepared), and the
/// spec's guarantee θ > θcone → 0.
pub fn cone_factor(theta: f64, cone: f64, start: f64) -> f64 {
    if theta > cone {
        return 0.0;
    }
    1.0 - smoothstep_angle(theta, start, cone)
}

/// `lerp(|cos|^focus, focusTint, 1)` per channel; white when focus ≤ 0.
pub fn focus_factor(focus: f64, tint: DVec3, cos: f64) -> DVec3 {
    if focus <= 0.0 {
        return DVec3::ONE;
    }
    let f = cos.abs().powf(focus);
    tint + f * (DVec3::ONE - tint)
}

/// The RGB factor ShapingAPI applies to emission along unit direction `e` (1 where the light is
/// not shaped).
pub fn shaping(p: &Prepared, e: DVec3) -> DVec3 {
    let Some(s) = &p.shaping else {
        return DVec3::ONE;
    };
    let cos = e.dot(p.axis);
    // θoff (an atan2: a third of a hard-coned textured rect's time) only where the cone
    // factor is not 1 or 0 for certain: the cosine clearly above cos(start) means θoff < start
    // (factor 1), clearly below cos(θcone) means θoff > θcone (factor 0). The margin, 1e-12,
    // is far above the rounding of the cosine and of atan2 (~1e-16 for a unit e), so the
    // factor is what θoff's own comparisons give, to the bit.
    const MARGIN: f64 = 1e-12;
    let cone = if cos > s.cos_start + MARGIN {
        1.0
    } else if cos < s.cos_cone - MARGIN {
        0.0
    } else {
        cone_factor(off_axis_angle(p.axis, e), s.cone, s.start)
    };
    let f = focus_factor(s.focus, s.focus_tint, cos) * cone;
    // DESIGN.md §6 I7: the IES value multiplies as candela, like the other factors.
    match &p.ies {
        Some(_) => f * ies_of(p, e),
        None => f,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The smoothstep start for `softness` (spec/002: softness clamped to [0, 1]).
    fn start(cone: f64, softness: f64) -> f64 {
        (1.0 - softness.clamp(0.0, 1.0)) * cone
    }

    /// reference/openusd-reference.md §3.2: angle 45°, softness 0.25 → factor 1 up to 33.75°,
    /// 0.5 at 39.375°, 0 at 45°.
    #[test]
    fn cone_softness_example() {
        let c = 45f64.to_radians();
        // softness 0.25: the smoothstep starts at 0.75·θcone.
        let cone_factor = |t: f64, c: f64, soft: f64| cone_factor(t, c, start(c, soft));
        assert_eq!(cone_factor(33.0f64.to_radians(), c, 0.25), 1.0);
        assert_eq!(cone_factor(33.75f64.to_radians(), c, 0.25), 1.0);
        assert!((cone_factor(39.375f64.to_radians(), c, 0.25) - 0.5).abs() < 1e-12);
        assert_eq!(cone_factor(45.0f64.to_radians(), c, 0.25), 0.0);
        assert_eq!(cone_factor(45.1f64.to_radians(), c, 0.25), 0.0);
    }

    #[test]
    fn hard_cone_boundary_is_lit_and_softness_is_clamped() {
        let c = 30f64.to_radians();
        let cone_factor = |t: f64, c: f64, soft: f64| cone_factor(t, c, start(c, soft));
        assert_eq!(cone_factor(c, c, 0.0), 1.0);
        assert_eq!(cone_factor(c + 1e-12, c, 0.0), 0.0);
        assert_eq!(cone_factor(c * 0.5, c, -3.0), 1.0); // softness −3 → 0: hard
        assert_eq!(cone_factor(0.2 * c, c, 7.0), cone_factor(0.2 * c, c, 1.0));
        // A negative cone angle lights nothing (θ ≥ 0 > θcone).
        assert_eq!(cone_factor(0.0, -0.1, 0.5), 0.0);
    }

    #[test]
    fn focus_tint_channels() {
        // reference/luxtest.md §6 A5: tint red leaves R at 1; G, B follow |cos|^focus.
        let f = focus_factor(2.0, DVec3::X, 0.5);
        assert_eq!(f, DVec3::new(1.0, 0.25, 0.25));
        // tint (0, .5, 0), focus 3: G = .5 + .5·cos³.
        let f = focus_factor(3.0, DVec3::new(0.0, 0.5, 0.0), -0.5);
        assert_eq!(f, DVec3::new(0.125, 0.5 + 0.5 * 0.125, 0.125));
        assert_eq!(focus_factor(0.0, DVec3::ZERO, 0.1), DVec3::ONE);
        assert_eq!(focus_factor(-1.0, DVec3::ZERO, 0.1), DVec3::ONE);
    }

    #[test]
    fn off_axis_angle_is_accurate_near_zero() {
        let axis = DVec3::NEG_Z;
        let tiny = 1e-9f64;
        let e = DVec3::new(tiny.sin(), 0.0, -tiny.cos());
        assert!((off_axis_angle(axis, e) - tiny).abs() < 1e-20);
    }

    /// A ShapingAPI whose factor is 1 everywhere is dropped by `prepare`; check that the factor
    /// it would have applied is indeed 1 everywhere, so that dropping it changes no value.
    #[test]
    fn identity_shaping_is_dropped_without_changing_values() {
        use crate::model::{Light, Shaping};
        use crate::prepare::{Prepared, ShapingConsts, TemperatureMode, shaping_is_identity};
        use crate::synthetic::Rng;
        let cone180 = Shaping {
            cone_angle: 180.0,
            ..Shaping::default()
        };
        assert!(shaping_is_identity(&cone180));
        assert!(shaping_is_identity(&Shaping {
            focus: 3.0,
            focus_tint: DVec3::ONE,
            ..cone180.clone()
        }));
        assert!(!shaping_is_identity(&Shaping::default())); // the 90° fallback cone
        assert!(!shaping_is_identity(&Shaping {
            cone_softness: 0.1,
            ..cone180.clone()
        }));
        assert!(!shaping_is_identity(&Shaping {
            focus: 1.0,
            ..cone180.clone()
        }));
        let light = Light::sphere(0.5).with_shaping(cone180.clone());
        let p = Prepared::new(&light, TemperatureMode::Spec).unwrap();
        assert!(p.light.shaping.is_none() && p.shaping.is_none());
        let s = ShapingConsts::new(&cone180);
        let mut rng = Rng::new(5);
        for _ in 0..1000 {
            let e = rng.unit();
            let f = focus_factor(s.focus, s.focus_tint, e.dot(p.axis))
                * cone_factor(off_axis_angle(p.axis, e), s.cone, s.start);
            assert_eq!(f, DVec3::ONE, "{e}");
            assert_eq!(crate::cpu::emission::emission(&p, e), p.base);
        }
    }

    /// `shaping` screens θoff by cosines (to skip the atan2): the factor must be what θoff's
    /// own comparisons give, bit for bit, at the smoothstep's ends, just inside and outside
    /// them, and for cones and starts outside [0, π] (cone angles over 180° or negative).
    #[test]
    fn the_cosine_screen_gives_the_angle_comparisons_factor() {
        use crate::model::{Light, Shaping};
        use crate::prepare::{Prepared, TemperatureMode};
        use crate::synthetic::Rng;
        let mut rng = Rng::new(11);
        let mut checked = 0;
        for (angle, softness) in [
            (35.0, 0.0),
            (30.0, 0.25),
            (90.0, 0.0),
            (120.0, 0.5),
            (179.9, 0.0),
            (200.0, 0.3),
            (-20.0, 0.0),
            (0.0, 0.0),
            (45.0, 1.0),
        ] {
            let shaping = Shaping {
                cone_angle: angle,
                cone_softness: softness,
                focus: 0.7,
                focus_tint: DVec3::new(0.2, 0.5, 1.0),
                ies: None,
            };
            let light = Light::rect(1.0, 1.0).with_shaping(shaping);
            let p = Prepared::new(&light, TemperatureMode::Spec).unwrap();
            let Some(s) = &p.shaping else { continue };
            let (u, v) = p.axis.any_orthonormal_pair();
            for _ in 0..2000 {
                // θ at or near an end of the smoothstep (within ±1e-9, down to single ulps),
                // or anywhere.
                let end = [s.start, s.cone][rng.below(2)];
                let theta = match rng.below(3) {
                    0 => end + (rng.f64() - 0.5) * 2e-9,
                    1 => end + (rng.below(9) as f64 - 4.0) * 1e-15,
                    _ => rng.f64() * std::f64::consts::PI,
                };
                let phi = rng.f64() * std::f64::consts::TAU;
                let e = (p.axis * theta.cos() + (u * phi.cos() + v * phi.sin()) * theta.sin())
                    .normalize();
                let exact = focus_factor(s.focus, s.focus_tint, e.dot(p.axis))
                    * cone_factor(off_axis_angle(p.axis, e), s.cone, s.start);
                assert_eq!(
                    super::shaping(&p, e),
                    exact,
                    "cone {angle} softness {softness} at {theta}"
                );
                checked += 1;
            }
        }
        assert!(checked >= 8 * 2000, "{checked}");
    }
}
