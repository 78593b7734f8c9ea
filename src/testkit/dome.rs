//! Textured domes for the CPU-vs-GPU tests (tests/dome_conformance.rs): generated textures of
//! every format, a scene prepared with a chosen filter, and the directions to leave out of a pointwise
//! comparison because f32 may fall on the other side of a discontinuity there.

use glam::DVec3;

use crate::error::Result;
use crate::model::Light;
use crate::prepare::dome::Filter;
use crate::prepare::{self, TemperatureMode};
use crate::query::{Evaluator, PreparedScene};

/// Prepares `lights` on `eval` with every dome texture read through `filter` (nearest when
/// `nearest`, else bilinear).
pub fn prepare_with_filter(
    eval: &Evaluator,
    lights: &[Light],
    nearest: bool,
) -> Result<PreparedScene> {
    let mut prepared = prepare::prepare(lights, TemperatureMode::Spec)?;
    for p in &mut prepared {
        if let Some(t) = &mut p.texture {
            t.filter = if nearest {
                Filter::Nearest
            } else {
                Filter::Bilinear
            };
        }
    }
    eval.prepare_prepared(prepared)
}

/// Per direction (world, toward the environment), whether the textured dome `light` read
/// through the nearest (`nearest`) or bilinear filter has a discontinuity within `margin` of it
/// that f32 may straddle: `check`'s own exclusion, [`crate::check::near_texture_edge`].
pub fn near_discontinuity(
    light: &Light,
    dirs: &[[f32; 3]],
    nearest: bool,
    margin: f64,
) -> Result<Vec<bool>> {
    let mut p = prepare::Prepared::new(light, TemperatureMode::Spec)?;
    if let Some(t) = &mut p.texture {
        t.filter = if nearest {
            Filter::Nearest
        } else {
            Filter::Bilinear
        };
    }
    Ok(dirs
        .iter()
        .map(|d| crate::check::near_texture_edge(&p, crate::cpu::dvec(*d), margin))
        .collect())
}

/// The CPU reference's irradiance of `light` (a textured dome) read through `filter` (nearest
/// when `nearest`, else bilinear) at the origin, for each unit receiver normal: the exact
/// integral of the filtered texture (src/cpu/irradiance/dome.rs), `diffuse` applied.
pub fn irradiance_with_filter(
    light: &Light,
    nearest: bool,
    normals: &[DVec3],
) -> Result<Vec<DVec3>> {
    let mut p = prepare::Prepared::new(light, TemperatureMode::Spec)?;
    if let Some(t) = &mut p.texture {
        t.filter = if nearest {
            Filter::Nearest
        } else {
            Filter::Bilinear
        };
    }
    Ok(normals
        .iter()
        .map(|&n| crate::cpu::irradiance::irradiance(&p, DVec3::ZERO, n))
        .collect())
}
