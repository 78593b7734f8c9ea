//! The total power a light emits: the integral of its intensity over the sphere (DESIGN.md §3
//! "intensity"; issue: "each light's total power, the exact integral of intensity over the
//! sphere"), RGB, in lumens per channel for L in nits.
//!
//! Unshaped, every surface element emits `L·max(0, n·ω)` and `∫ max(0, n·ω) dω = π`, so the
//! flux is `π · L · A` with A the world-space emitting area (the one normalize divides by).
//! Shaped (cone, focus, IES) it is integrated numerically in spherical coordinates around the
//! primary axis, where the cone and focus factors depend on the polar angle alone: split at the
//! smoothstep start, the cone edge and 90°, globally adaptive Gauss–Kronrod to ~1e-10 relative
//! in both angles.

use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, PI};

use super::intensity::intensity;
use super::quadrature::{Tolerance, integrate};
use crate::model::LightType;
use crate::prepare::Prepared;
use crate::prepare::normalize::world_area;

/// The RGB flux `∫ I(ω) dω` of the light; `None` for distant and dome lights (at infinity) and
/// for mesh lights, whose self-occlusion leaves no closed form (not computed yet).
pub fn flux(p: &Prepared) -> Option<DVec3> {
    if matches!(
        p.light.kind,
        LightType::Distant { .. } | LightType::Dome | LightType::Mesh { .. }
    ) {
        return None;
    }
    let Some(s) = &p.shaping else {
        // A textured rect emits its texture's mean (DESIGN.md §6 "RectLight texture").
        return Some(p.base * super::texture::rect_mean(p) * (PI * world_area(&p.light)));
    };
    let mut breaks = vec![0.0, FRAC_PI_2, PI];
    for t in [s.start, s.cone] {
        if t > 0.0 && t < PI {
            breaks.push(t);
        }
    }
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
    let (u, v) = p.axis.any_orthonormal_pair();
    let outer = Tolerance {
        rel: 1e-10,
        abs: 0.0,
        max_intervals: 2000,
    };
    let inner = Tolerance {
        rel: 1e-11,
        abs: 0.0,
        max_intervals: 400,
    };
    let total = integrate(
        &mut |theta: f64| {
            let (st, ct) = theta.sin_cos();
            if st == 0.0 {
                return DVec3::ZERO;
            }
            let ring = integrate(
                &mut |phi: f64| {
                    let (sp, cp) = phi.sin_cos();
                    intensity(p, p.axis * ct + (u * cp + v * sp) * st)
                },
                &[0.0, PI, 2.0 * PI],
                inner,
            );
            ring * st
        },
        &breaks,
        outer,
    );
    Some(total)
}
