//! Textured domes for the CPU-vs-GPU tests (tests/dome_conformance.rs): generated textures of
//! every format, a scene prepared with a chosen filter (the model has no filter attribute; the
//! CLI's `--texture-filter` is still to come), and the directions to leave out of a pointwise
//! comparison because f32 may fall on the other side of a discontinuity there.

use glam::DVec3;

use crate::error::Result;
use crate::model::Light;
use crate::prepare::dome::{DomeFormat, Filter};
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

/// Per direction (world, toward the environment), whether the textured dome `light` has a
/// discontinuity within `margin` of it that f32 may straddle: with the nearest filter, a texel
/// edge within `margin` pixels (`s·W` or `t·H` of the block within `margin` of an integer);
/// with either filter, a cube-cross face edge (the two largest |d| within a relative `margin`,
/// each face clamps to its own edge texels). Computed in f64 on the CPU's dome direction.
pub fn near_discontinuity(
    light: &Light,
    dirs: &[[f32; 3]],
    nearest: bool,
    margin: f64,
) -> Result<Vec<bool>> {
    let p = prepare::Prepared::new(light, TemperatureMode::Spec)?;
    let Some(t) = &p.texture else {
        return Ok(vec![false; dirs.len()]);
    };
    let (w, h) = (t.image.width as f64, t.image.height as f64);
    let near_int = |x: f64| (x - x.round()).abs() < margin;
    Ok(dirs
        .iter()
        .map(|d| {
            let w_world = DVec3::new(d[0] as f64, d[1] as f64, d[2] as f64).normalize();
            let d = t.frame.to_dome(w_world);
            if t.format == DomeFormat::Cross {
                let mut a = d.abs().to_array();
                a.sort_by(f64::total_cmp);
                if a[2] - a[1] < margin * a[2] {
                    return true;
                }
            }
            if !nearest {
                return false;
            }
            let st = crate::cpu::dome::direction_to_st(t.format, d);
            near_int(st.x * w) || near_int(st.y * h)
        })
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
