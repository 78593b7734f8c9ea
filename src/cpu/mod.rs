//! The CPU reference: every query in f64, written for clarity (DESIGN.md §1).
//!
//! Each module that implements a concept evaluated per direction has a WGSL twin of the same
//! name under `shaders/` (`emission`, `radiance`, `irradiance`, `shared/shaping`,
//! `shared/shapes`). The per-light constants (`blackbody`, `normalize`) are computed here once in
//! f64 for both paths and have no WGSL twin; `quadrature` holds the rules (the GPU's fixed
//! Gauss–Legendre nodes reach WGSL through the generated prelude).

pub mod blackbody;
pub mod emission;
pub mod irradiance;
pub mod normalize;
pub mod quadrature;
pub mod radiance;
pub mod shapes;
pub mod shaping;

use glam::{DMat3, DVec3};
use rayon::prelude::*;

use crate::error::{LuxError, Result};
use crate::light::{Light, LightType};
pub use blackbody::TemperatureMode;

/// A validated light with its per-light constants, shared by the CPU reference and the GPU
/// packer so that both evaluate the same numbers.
#[derive(Clone, Debug)]
pub struct PreparedLight {
    /// The light as evaluated: the input, except that a ShapingAPI whose factor is 1 everywhere
    /// is dropped (see [`shaping_is_identity`]).
    pub light: Light,
    /// `intensity · 2^exposure · color ⊙ temperature(T) / sizeFactor` (DESIGN.md §2 "Emission").
    pub base: DVec3,
    /// The sizeFactor `base` was divided by (1 when normalize is off).
    pub size_factor: f64,
    /// World-space origin.
    pub origin: DVec3,
    /// World → local linear map (inverse of the light's linear map).
    pub to_local: DMat3,
    /// Unit primary axis in world space: the image of local −Z as a direction.
    pub axis: DVec3,
    /// Unit world normal of a rect or disk's emitting side: the inverse transpose applied to
    /// local −Z. Equals `axis` unless the transform shears.
    pub normal: DVec3,
}

impl PreparedLight {
    /// Validates `light` and computes its constants for `mode`.
    pub fn new(light: &Light, mode: TemperatureMode) -> Result<Self> {
        light.validate()?;
        let linear = light.linear();
        let to_local = linear.inverse();
        let size_factor = normalize::size_factor(light);
        let base = emission::base_radiance(light, mode) / size_factor;
        if size_factor == 0.0 {
            return Err(LuxError::attr(
                &light.path,
                "inputs:normalize",
                "true",
                "the light has zero world-space size, so normalize would divide by zero",
            ));
        }
        if !base.is_finite() {
            return Err(LuxError::attr(
                &light.path,
                "inputs:intensity",
                light.inputs.intensity,
                format!("intensity · 2^exposure · color overflows ({base})"),
            ));
        }
        let mut evaluated = light.clone();
        if evaluated.shaping.as_ref().is_some_and(shaping_is_identity) {
            evaluated.shaping = None;
        }
        Ok(PreparedLight {
            light: evaluated,
            base,
            size_factor,
            origin: light.origin(),
            to_local,
            axis: (linear * DVec3::NEG_Z).normalize(),
            normal: (to_local.transpose() * DVec3::NEG_Z).normalize(),
        })
    }

    pub fn kind(&self) -> &LightType {
        &self.light.kind
    }
}

/// Whether ShapingAPI's factor is exactly 1 along every direction: no focus (or a white tint) and
/// a cone whose smoothstep starts at or beyond 180° (luxtest authors cone 180, softness 0, to mean
/// "no cone"). Such a ShapingAPI is dropped from [`PreparedLight::light`]: the values are the
/// same, and irradiance can use its closed forms.
pub fn shaping_is_identity(s: &crate::light::Shaping) -> bool {
    let no_focus = s.focus <= 0.0 || s.focus_tint == DVec3::ONE;
    let start_deg = (1.0 - s.cone_softness.clamp(0.0, 1.0)) * s.cone_angle;
    no_focus && start_deg >= 180.0
}

/// Prepares every light, failing on the first invalid one.
pub fn prepare(lights: &[Light], mode: TemperatureMode) -> Result<Vec<PreparedLight>> {
    lights.iter().map(|l| PreparedLight::new(l, mode)).collect()
}

/// Converts an f32 triple to f64.
pub fn dvec(v: [f32; 3]) -> DVec3 {
    DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)
}

/// Evaluates `f(light, sample)` for every light and sample: the sum over lights per sample, or,
/// with `per_light`, one row per (light, sample) in light-major order.
pub(crate) fn batch<F>(lights: &[PreparedLight], n: usize, per_light: bool, f: F) -> Vec<DVec3>
where
    F: Fn(&PreparedLight, usize) -> DVec3 + Sync,
{
    if per_light {
        let mut out = vec![DVec3::ZERO; lights.len() * n];
        if n > 0 {
            out.par_chunks_mut(n)
                .zip(lights.par_iter())
                .for_each(|(rows, light)| {
                    rows.par_iter_mut()
                        .enumerate()
                        .for_each(|(i, o)| *o = f(light, i))
                });
        }
        out
    } else {
        (0..n)
            .into_par_iter()
            .map(|i| lights.iter().map(|l| f(l, i)).sum())
            .collect()
    }
}

/// emission(light, ω) for every light and direction (see [`emission::emission`]).
pub fn emission_batch(lights: &[PreparedLight], dirs: &[[f32; 3]], per_light: bool) -> Vec<DVec3> {
    batch(lights, dirs.len(), per_light, |l, i| {
        emission::emission(l, dvec(dirs[i]))
    })
}

/// radiance(x, ω) for every light and (point, direction) pair (see [`radiance::radiance`]).
pub fn radiance_batch(
    lights: &[PreparedLight],
    points: &[[f32; 3]],
    dirs: &[[f32; 3]],
    per_light: bool,
) -> Vec<DVec3> {
    batch(lights, dirs.len(), per_light, |l, i| {
        radiance::radiance(l, dvec(points[i]), dvec(dirs[i]))
    })
}

/// irradiance(x, n) for every light and (point, normal) pair (see [`irradiance::irradiance`]).
pub fn irradiance_batch(
    lights: &[PreparedLight],
    points: &[[f32; 3]],
    normals: &[[f32; 3]],
    per_light: bool,
) -> Vec<DVec3> {
    batch(lights, points.len(), per_light, |l, i| {
        irradiance::irradiance(l, dvec(points[i]), dvec(normals[i]))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::Rng;
    use crate::light::Shaping;

    #[test]
    fn identity_shaping_is_dropped_without_changing_values() {
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
        let p = PreparedLight::new(&light, TemperatureMode::Spec).unwrap();
        assert!(p.light.shaping.is_none());
        let mut rng = Rng::new(5);
        for _ in 0..1000 {
            let e = rng.unit();
            let s = shaping::shaping(&cone180, p.axis, e);
            assert_eq!(s, DVec3::ONE, "{e}");
            assert_eq!(emission::emission(&p, e), p.base);
        }
    }
}
