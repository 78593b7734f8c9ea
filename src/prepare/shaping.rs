//! ShapingAPI's inputs as the evaluation uses them, and when they change nothing.

use glam::DVec3;

use crate::model::Shaping;

/// ShapingAPI's inputs as the evaluation uses them (DESIGN.md §2 "Shaping", spec/002).
#[derive(Clone, Debug, PartialEq)]
pub struct ShapingConsts {
    /// `shaping:focus` (≤ 0: no focus).
    pub focus: f64,
    /// `shaping:focusTint`.
    pub focus_tint: DVec3,
    /// θcone in radians.
    pub cone: f64,
    /// Where the smoothstep starts: `(1 − softness)·θcone`, softness clamped to [0, 1].
    pub start: f64,
    /// `cos(start)` where start is in [0, π], else 2 (no direction is above it): a direction
    /// whose cosine with the axis is clearly above it has the cone factor 1 (`cpu::shaping`).
    pub cos_start: f64,
    /// `cos(θcone)` where θcone is in [0, π), else −2: a direction whose cosine is clearly
    /// below it has the cone factor 0.
    pub cos_cone: f64,
}

impl ShapingConsts {
    pub fn new(s: &Shaping) -> Self {
        let cone = s.cone_angle.to_radians();
        let start = (1.0 - s.cone_softness.clamp(0.0, 1.0)) * cone;
        let pi = std::f64::consts::PI;
        ShapingConsts {
            focus: s.focus,
            focus_tint: s.focus_tint,
            cone,
            start,
            cos_start: if (0.0..=pi).contains(&start) {
                start.cos()
            } else {
                2.0
            },
            cos_cone: if (0.0..pi).contains(&cone) {
                cone.cos()
            } else {
                -2.0
            },
        }
    }

    /// A bound of the shaping factor's size per channel, IES aside: the cone factor lies in
    /// [0, 1] and the focus factor `tint + f·(1 − tint)` (f in [0, 1]) between tint and 1.
    pub fn factor_bound(&self) -> DVec3 {
        DVec3::ONE.max(self.focus_tint.abs())
    }
}

/// Whether ShapingAPI's factor is exactly 1 along every direction: no focus (or a white tint), a
/// cone whose smoothstep starts at or beyond 180° (luxtest authors cone 180, softness 0, to mean
/// "no cone") and no IES profile. Such a ShapingAPI is dropped from [`Prepared::light`]: the
/// values are the same, and irradiance can use its closed forms.
pub fn shaping_is_identity(s: &Shaping) -> bool {
    let no_focus = s.focus <= 0.0 || s.focus_tint == DVec3::ONE;
    let start_deg = (1.0 - s.cone_softness.clamp(0.0, 1.0)) * s.cone_angle;
    no_focus && start_deg >= 180.0 && s.ies.is_none()
}
