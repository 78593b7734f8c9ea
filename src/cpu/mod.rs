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

pub mod dome;
pub mod emission;
pub mod ies;
pub mod intensity;
pub mod irradiance;
pub mod power;
pub mod quadrature;
pub mod radiance;
pub mod roots;
pub mod shapes;
pub mod shaping;

use glam::DVec3;
use rayon::prelude::*;

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

/// Evaluates `f(light, sample)` for every light and sample: the sum over lights per sample, or,
/// with `per_light`, one row per (light, sample) in light-major order.
pub(crate) fn batch<F>(lights: &[Prepared], n: usize, per_light: bool, f: F) -> Vec<DVec3>
where
    F: Fn(&Prepared, usize) -> DVec3 + Sync,
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

/// emission(light, ω) for every light and direction (see [`emission::emission`]); directions
/// are normalised here (the caller rejects zero and non-finite rows).
pub fn emission_batch(lights: &[Prepared], dirs: &[[f32; 3]], per_light: bool) -> Vec<DVec3> {
    batch(lights, dirs.len(), per_light, |l, i| {
        emission::emission(l, dvec(dirs[i]).normalize())
    })
}

/// intensity(light, ω) for every light and direction (see [`intensity::intensity`]).
pub fn intensity_batch(lights: &[Prepared], dirs: &[[f32; 3]], per_light: bool) -> Vec<DVec3> {
    batch(lights, dirs.len(), per_light, |l, i| {
        intensity::intensity(l, dvec(dirs[i]).normalize())
    })
}

/// radiance(x, ω) for every light and (point, direction) pair (see [`radiance::radiance`]).
pub fn radiance_batch(
    lights: &[Prepared],
    points: &[[f32; 3]],
    dirs: &[[f32; 3]],
    per_light: bool,
) -> Vec<DVec3> {
    batch(lights, dirs.len(), per_light, |l, i| {
        radiance::radiance(l, dvec(points[i]), dvec(dirs[i]).normalize())
    })
}

/// irradiance(x, n) for every light and (point, normal) pair (see
/// [`irradiance::irradiance`]); a zero or non-finite normal gives 0.
pub fn irradiance_batch(
    lights: &[Prepared],
    points: &[[f32; 3]],
    normals: &[[f32; 3]],
    per_light: bool,
) -> Vec<DVec3> {
    batch(lights, points.len(), per_light, |l, i| {
        match unit(normals[i]) {
            Some(n) => irradiance::irradiance(l, dvec(points[i]), n),
            None => DVec3::ZERO,
        }
    })
}
