//! The CPU reference: every query in f64, written for clarity (DESIGN.md §1). Depends on the
//! model and `prepare` only, never on `gpu`.
//!
//! Each module that implements a concept evaluated per direction has a WGSL twin of the same
//! name under `shaders/` (`emission`, `radiance`, `intensity`, `irradiance` and its parts in
//! `irradiance/`; `shaping`, `shapes`, `roots` and `ies` in `shaders/shared/`), with the same function
//! names in the same order (`tests/twins.rs` checks it). `quadrature` is the reference's own
//! adaptive integrator; `power` integrates intensity over the sphere.
//!
//! Contract shared with the kernels: directions passed to the per-light functions are unit
//! vectors; the batch entry points below normalise their inputs, as the kernels' entry points do.

pub mod emission;
pub mod ies;
pub mod intensity;
pub mod irradiance;
pub mod mesh;
pub mod portal;
pub mod power;
pub mod quadrature;
pub mod radiance;
pub mod roots;
pub mod sample;
pub mod shapes;
pub mod shaping;
pub mod texture;

use std::collections::HashMap;

use glam::DVec3;
use rayon::prelude::*;

use crate::model::LightType;
use crate::prepare::Prepared;

/// Converts an f32 triple to f64.
pub fn dvec(v: [f32; 3]) -> DVec3 {
    DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)
}

/// `v` normalised, or None for a zero or non-finite vector.
fn unit(v: [f32; 3]) -> Option<DVec3> {
    let d = dvec(v);
    let len = d.length();
    (len > 0.0 && len.is_finite()).then(|| d / len)
}

/// Evaluates `f(light index, sample)` for every light and sample: the sum over lights per
/// sample, or, with `per_light`, one row per (light, sample) in light-major order.
pub(crate) fn batch<F>(lights: usize, n: usize, per_light: bool, f: F) -> Vec<DVec3>
where
    F: Fn(usize, usize) -> DVec3 + Sync,
{
    if per_light {
        let mut out = vec![DVec3::ZERO; lights * n];
        if n > 0 {
            out.par_chunks_mut(n).enumerate().for_each(|(k, rows)| {
                rows.par_iter_mut()
                    .enumerate()
                    .for_each(|(i, o)| *o = f(k, i))
            });
        }
        out
    } else {
        (0..n)
            .into_par_iter()
            .map(|i| (0..lights).map(|k| f(k, i)).sum())
            .collect()
    }
}

/// emission(light, ω) for every light and direction (see [`emission::emission`]); directions
/// are normalised here (the caller rejects zero and non-finite rows).
pub fn emission_batch(lights: &[Prepared], dirs: &[[f32; 3]], per_light: bool) -> Vec<DVec3> {
    batch(lights.len(), dirs.len(), per_light, |k, i| {
        emission::emission(&lights[k], dvec(dirs[i]).normalize())
    })
}

/// intensity(light, ω) for every light and direction (see [`intensity::intensity`]).
pub fn intensity_batch(lights: &[Prepared], dirs: &[[f32; 3]], per_light: bool) -> Vec<DVec3> {
    batch(lights.len(), dirs.len(), per_light, |k, i| {
        intensity::intensity(&lights[k], dvec(dirs[i]).normalize())
    })
}

/// radiance(x, ω) for every light and (point, direction) pair (see [`radiance::radiance`]).
pub fn radiance_batch(
    lights: &[Prepared],
    points: &[[f32; 3]],
    dirs: &[[f32; 3]],
    per_light: bool,
) -> Vec<DVec3> {
    batch(lights.len(), dirs.len(), per_light, |k, i| {
        radiance::radiance(&lights[k], dvec(points[i]), dvec(dirs[i]).normalize())
    })
}

/// irradiance(x, n) for every light and (point, normal) pair by `rule` (see
/// [`irradiance::irradiance_with`]; closed forms and textured domes are exact either way); a
/// zero or non-finite normal gives 0.
pub fn irradiance_batch(
    lights: &[Prepared],
    points: &[[f32; 3]],
    normals: &[[f32; 3]],
    per_light: bool,
    rule: &irradiance::Adaptive,
) -> Vec<DVec3> {
    for l in lights.iter().filter(|l| l.portals.is_some()) {
        // Before the parallel loop below (DomeIrradiance::warm).
        if let Some(t) = irradiance::dome::tables(l) {
            t.warm(true, 0);
        }
    }
    let by_normal: Vec<Option<HashMap<[u32; 3], DVec3>>> = lights
        .iter()
        .map(|l| {
            // A dome masked by portals (DESIGN.md §8 P2) depends on x too: not shared.
            (matches!(l.light.kind, LightType::Dome)
                && l.dome_texture().is_some()
                && l.portals.is_none())
            .then(|| dome_by_normal(l, normals))
        })
        .collect();
    batch(lights.len(), points.len(), per_light, |k, i| {
        if let Some(values) = &by_normal[k] {
            return values[&normals[i].map(f32::to_bits)];
        }
        match unit(normals[i]) {
            Some(n) => irradiance::irradiance_with(&lights[k], dvec(points[i]), n, rule),
            None => DVec3::ZERO,
        }
    })
}

/// A textured dome's irradiance for each distinct normal among `normals` (keyed by their bits).
/// A dome lies at infinity, so its irradiance depends on the normal alone (DESIGN.md §2), and
/// its exact integral (irradiance/dome.rs) costs far more than a lookup: a falloff map, whose
/// receivers share one normal, needs one evaluation instead of one per pixel. Every tolerance
/// takes the exact integral: for a latlong dome under a conformal frame the sweep
/// (irradiance/dome/latlong.rs) is faster than the row rule that loose tolerances once took
/// for many normals (BENCHMARKS.md "The sweep's lit runs").
fn dome_by_normal(light: &Prepared, normals: &[[f32; 3]]) -> HashMap<[u32; 3], DVec3> {
    let mut keys: Vec<[u32; 3]> = normals.iter().map(|n| n.map(f32::to_bits)).collect();
    keys.sort_unstable();
    keys.dedup();
    if let Some(t) = irradiance::dome::tables(light) {
        // Before the parallel loop below (DomeIrradiance::warm).
        t.warm(false, keys.len());
    }
    keys.into_par_iter()
        .map(|key| {
            let e = match unit(key.map(f32::from_bits)) {
                Some(n) => irradiance::irradiance(light, DVec3::ZERO, n),
                None => DVec3::ZERO,
            };
            (key, e)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Light, Texture};
    use crate::prepare::TemperatureMode;

    /// A 16 × 8 latlong dome under a rotation times a uniform scale.
    fn textured_dome() -> Prepared {
        let png = crate::Asset::png(16, 8, |x, y| [15 * x as u8 + 10, 90, 30 * y as u8 + 5]);
        let axis = DVec3::new(0.3, -0.5, 0.8).normalize();
        let light = Light::dome()
            .with_transform(
                glam::DMat4::from_axis_angle(axis, 0.7)
                    * glam::DMat4::from_scale(DVec3::splat(2.0)),
            )
            .with_texture(Texture::new(png));
        Prepared::new(&light, TemperatureMode::Spec).expect("the dome prepares")
    }

    /// A batch of many distinct normals gives the exact integral's values at every tolerance,
    /// bit for bit (the row rule is no longer taken), one per distinct normal.
    #[test]
    fn dome_batches_take_the_exact_integral_at_every_tolerance() {
        let p = textured_dome();
        let normals: Vec<[f32; 3]> = (0..20)
            .map(|i| {
                let z = 1.0 - (i as f32 + 0.5) / 10.0;
                let phi = i as f32 * 2.4;
                let r = (1.0 - z * z).sqrt();
                [r * phi.cos(), z, r * phi.sin()]
            })
            .collect();
        let points = vec![[0.0f32; 3]; normals.len()];
        let lights = std::slice::from_ref(&p);
        for rel in [1e-2, 1e-4, 1e-9] {
            let rule = irradiance::Adaptive::for_tolerance(rel);
            let got = irradiance_batch(lights, &points, &normals, true, &rule);
            for (n, g) in normals.iter().zip(&got) {
                let n = unit(*n).expect("a unit normal");
                assert_eq!(*g, irradiance::irradiance(&p, DVec3::ZERO, n), "{rel}");
            }
        }
    }
}
