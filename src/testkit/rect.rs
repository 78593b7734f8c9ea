//! Textured rects for the tests (tests/rect_texture.rs, tests/rect_conformance.rs): a scene
//! prepared with a chosen filter, and the samples to leave out of a pointwise CPU-vs-GPU
//! comparison because f32 may fall on the other side of a discontinuity there.

use glam::DVec3;

use crate::error::Result;
use crate::model::{Light, LightType};
use crate::prepare::{Prepared, TemperatureMode};
use crate::query::{Evaluator, PreparedScene};

/// Prepares `lights` on `eval` with every rect texture read through the chosen filter (the
/// model's `Texture::filter`, see [`super::dome::with_filter`]).
pub fn prepare_rects_with_filter(
    eval: &Evaluator,
    lights: &[Light],
    nearest: bool,
) -> Result<PreparedScene> {
    eval.prepare(&super::dome::with_filter(lights, nearest))
}

/// Per radiance sample (point, direction), whether the textured rect `light` has a
/// discontinuity within `margin` of where the ray meets its plane, that f32 may straddle: the
/// rect's edge (hit or miss), within `margin` of the half extent in local units relative to
/// it; and with the nearest filter a texel edge within `margin` pixels. Computed in f64.
pub fn near_rect_discontinuity(
    light: &Light,
    points: &[[f32; 3]],
    dirs: &[[f32; 3]],
    nearest: bool,
    margin: f64,
) -> Result<Vec<bool>> {
    let p = Prepared::new(light, TemperatureMode::Spec)?;
    let (LightType::Rect { width, height }, Some(t)) = (&p.light.kind, p.rect_texture()) else {
        return Ok(vec![false; points.len()]);
    };
    let (iw, ih) = (t.image.width as f64, t.image.height as f64);
    let near_int = |x: f64| (x - x.round()).abs() < margin;
    let v = |a: [f32; 3]| DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64);
    Ok(points
        .iter()
        .zip(dirs)
        .map(|(x, d)| {
            let xl = p.to_local * (v(*x) - p.origin);
            let dl = p.to_local * v(*d).normalize();
            if !(dl.z != 0.0) {
                return false;
            }
            let h = xl - dl * (xl.z / dl.z);
            let (s, tt) = (0.5 - h.x / width, 0.5 - h.y / height);
            let edge = |u: f64| (u.abs() - 0.5).abs() < margin;
            if edge(h.x / width) || edge(h.y / height) {
                return true;
            }
            nearest && (near_int(s * iw) || near_int(tt * ih))
        })
        .collect())
}
