//! The float32 check of a prepared light: every constant the GPU record holds and every output
//! value must fit float32 (docs/INPUTS.md "float32"), refused on both paths before any work.

use glam::DVec3;

use super::blackbody::{TemperatureMode, temperature_rgb};
use crate::error::{LuxError, Result};
use crate::model::{Light, LightType};

/// The largest magnitude of a length (a position, a size, an entry of the world transform or
/// its inverse) that luxeval evaluates: its square must fit float32 (3.4e38) with room to spare,
/// since the kernels square lengths.
pub const MAX_LENGTH: f64 = 1e18;

/// Refuses a light whose constants do not fit the float32 the GPU record holds and every output
/// is written in, naming the attribute that makes it so (docs/INPUTS.md "float32"). Both paths
/// refuse the same lights, before any work. The radiance bound leaves room for what the queries
/// multiply it by: the focus tint (emission, radiance) and π · diffuse (irradiance).
pub(super) fn check_fits_f32(
    light: &Light,
    base: DVec3,
    size_factor: f64,
    mode: TemperatureMode,
) -> Result<()> {
    let i = &light.inputs;
    let tint = light
        .shaping
        .as_ref()
        .map_or(1.0, |s| s.focus_tint.abs().max_element().max(1.0));
    let gain = tint * (std::f64::consts::PI * i.diffuse.abs()).max(1.0);
    let peak = base.abs().max_element() * gain;
    if !(peak <= f32::MAX as f64) {
        // Blame the factor that contributes most (in octaves) to the overflow.
        let temp = if i.enable_color_temperature {
            temperature_rgb(i.color_temperature, mode)
                .abs()
                .max_element()
        } else {
            1.0
        };
        let factors = [
            (
                "inputs:intensity",
                i.intensity.to_string(),
                i.intensity.abs(),
            ),
            (
                "inputs:exposure",
                i.exposure.to_string(),
                2f64.powf(i.exposure),
            ),
            (
                "inputs:color",
                format!("{:?}", i.color.to_array()),
                i.color.abs().max_element(),
            ),
            (
                "inputs:colorTemperature",
                i.color_temperature.to_string(),
                temp,
            ),
            ("inputs:normalize", "true".to_string(), 1.0 / size_factor),
            ("inputs:shaping:focusTint", format!("{tint}"), tint),
            ("inputs:diffuse", i.diffuse.to_string(), i.diffuse.abs()),
        ];
        let (attr, value, _) = factors
            .iter()
            .max_by(|a, b| a.2.log2().total_cmp(&b.2.log2()))
            .expect("non-empty");
        return Err(LuxError::attr(
            &light.path,
            attr,
            value,
            format!(
                "the light's radiance (intensity · 2^exposure · color / sizeFactor = {:e}, \
                 times focusTint and π · diffuse for its results) does not fit float32 \
                 (largest {:e}), which the GPU evaluates in and every output is written in",
                base.abs().max_element(),
                f32::MAX
            ),
        ));
    }
    let sizes: &[(&str, f64)] = match light.kind {
        LightType::Sphere { radius, .. } | LightType::Disk { radius } => {
            &[("inputs:radius", radius)]
        }
        LightType::Rect { width, height } => &[("inputs:width", width), ("inputs:height", height)],
        LightType::Cylinder { length, radius, .. } => {
            &[("inputs:length", length), ("inputs:radius", radius)]
        }
        LightType::Distant { .. } | LightType::Dome => &[],
        LightType::Mesh { ref geometry, .. } => {
            let far = geometry
                .triangles
                .iter()
                .flat_map(|t| t.p)
                .enumerate()
                .find(|(_, v)| v.abs().max_element() > MAX_LENGTH);
            if let Some((i, v)) = far {
                return Err(LuxError::attr(
                    &light.path,
                    "points",
                    format!(
                        "({}, {}, {}) in world space (triangle {})",
                        v.x,
                        v.y,
                        v.z,
                        i / 3
                    ),
                    format!("beyond {MAX_LENGTH:e}, whose square would overflow float32"),
                ));
            }
            // The triangles are in world space: the transform only orients shaping.
            if light.shaping.is_none() {
                return Ok(());
            }
            &[]
        }
    };
    for (attr, v) in sizes {
        if v.abs() > MAX_LENGTH {
            return Err(LuxError::attr(
                &light.path,
                attr,
                v,
                format!("larger than {MAX_LENGTH:e}, whose square would overflow float32"),
            ));
        }
    }
    let linear = light.linear();
    let to_local = linear.inverse();
    let entries = linear
        .to_cols_array()
        .into_iter()
        .chain(to_local.to_cols_array())
        .chain(light.origin().to_array());
    if let Some(v) = entries.into_iter().find(|v| v.abs() > MAX_LENGTH) {
        return Err(LuxError::InvalidTransform {
            light: light.path.clone(),
            reason: format!(
                "has an entry (or an entry of its inverse) of {v:e}, beyond {MAX_LENGTH:e}: \
                 its square would overflow float32"
            ),
        });
    }
    let det = linear.determinant().abs();
    if !(det >= f32::MIN_POSITIVE as f64 && det <= f32::MAX as f64) {
        return Err(LuxError::InvalidTransform {
            light: light.path.clone(),
            reason: format!("scales volumes by {det:e}, outside float32's normal range"),
        });
    }
    Ok(())
}
