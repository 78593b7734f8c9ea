//! The shaping function of a light as the irradiance quadrature sees it (both backends): where
//! the factor of ShapingAPI (DESIGN.md §2 "Shaping", spec/002) is not smooth, as sets of
//! emission directions. Computed once per light; the CPU reference lists the kinks from here and
//! the GPU record carries them as flags and cosines (`gpu::record`).

use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, PI};

use super::ShapingConsts;

/// Where the integrand is not smooth, as sets of vectors w from the receiver x.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kink {
    /// Emission directions at angle acos(cos) from the axis: `−ŵ·a = cos` (cos ≠ 0).
    Cone { cos: f64 },
    /// The plane m·w = 0 through x; `graded` marks a plane where the integrand behaves like
    /// |m·ŵ|^p (the focus plane), which the inner quadrature grades toward.
    Plane { m: DVec3, graded: bool },
}

/// The kinks of a light's shaping factor.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Profile {
    pub kinks: Vec<Kink>,
    /// ShapingAPI makes the light dark everywhere (cone angle ≤ 0).
    pub dark: bool,
    /// The factor is not smooth at the axis directions themselves (θ = 0 when the smoothstep
    /// starts there, softness ≥ 1: a |θ|³ term; θ = π when the smoothstep is active there,
    /// cone > 180°: a |π − θ| cone point).
    pub axis_singular: bool,
}

impl Profile {
    /// The profile of a light with ShapingAPI constants `shaping` (None: unshaped) around the
    /// unit primary axis `axis`. The cone factor `1 − smoothstep(θ; start, cone)` has kinks at
    /// θ = start and θ = cone (a cone of directions, or the plane ⊥ axis at 90°); focus
    /// `|cos θ|^focus` is not smooth at θ = 90° (the plane ⊥ axis).
    pub fn new(shaping: Option<&ShapingConsts>, axis: DVec3) -> Self {
        let mut kinks = Vec::new();
        let mut dark = false;
        let mut axis_singular = false;
        if let Some(s) = shaping {
            let (cone, start) = (s.cone, s.start);
            dark = !(cone > 0.0);
            axis_singular = cone > 0.0 && (start == 0.0 || (cone > PI && start < PI));
            let mut focus_plane = false;
            for theta in [start, cone] {
                if theta > 0.0 && theta < PI {
                    if theta == FRAC_PI_2 {
                        focus_plane = true;
                    } else {
                        let k = Kink::Cone { cos: theta.cos() };
                        if !kinks.contains(&k) {
                            kinks.push(k);
                        }
                    }
                }
            }
            let focus_active = s.focus > 0.0 && s.focus_tint != DVec3::ONE;
            if focus_active || focus_plane {
                kinks.push(Kink::Plane {
                    m: axis,
                    graded: focus_active,
                });
            }
        }
        Profile {
            kinks,
            dark,
            axis_singular,
        }
    }
}
