//! Textured domes for the CPU-vs-GPU tests (tests/dome_conformance.rs): generated textures of
//! every format, a scene prepared with a chosen filter, and the directions to leave out of a pointwise
//! comparison because f32 may fall on the other side of a discontinuity there.

use glam::DVec3;

use crate::error::Result;
use crate::model::{Light, TextureFilter};
use crate::prepare::{self, TemperatureMode};
use crate::query::{Evaluator, PreparedScene};

/// `lights` with every texture (dome or rect) read through the nearest filter when `nearest`,
/// else bilinear: the model's [`Texture::filter`](crate::model::Texture), as `--texture-filter`
/// sets it.
pub fn with_filter(lights: &[Light], nearest: bool) -> Vec<Light> {
    let filter = if nearest {
        TextureFilter::Nearest
    } else {
        TextureFilter::Bilinear
    };
    lights
        .iter()
        .cloned()
        .map(|mut l| {
            if let Some(t) = &mut l.texture {
                t.filter = filter;
            }
            l
        })
        .collect()
}

/// `light` with its texture read through the chosen filter, prepared (spec temperature mode).
fn prepared_with_filter(light: &Light, nearest: bool) -> Result<prepare::Prepared> {
    let light = with_filter(std::slice::from_ref(light), nearest).remove(0);
    prepare::Prepared::new(&light, TemperatureMode::Spec)
}

/// Prepares `lights` on `eval` with every texture read through the chosen filter.
pub fn prepare_with_filter(
    eval: &Evaluator,
    lights: &[Light],
    nearest: bool,
) -> Result<PreparedScene> {
    eval.prepare(&with_filter(lights, nearest))
}

/// Per direction (world, toward the environment), whether the textured dome `light` read
/// through the nearest (`nearest`) or bilinear filter has a discontinuity within `margin` of it
/// that f32 may straddle: `check`'s own exclusion, [`crate::conformance::band::near_texture_edge`].
pub fn near_discontinuity(
    light: &Light,
    dirs: &[[f32; 3]],
    nearest: bool,
    margin: f64,
) -> Result<Vec<bool>> {
    let p = prepared_with_filter(light, nearest)?;
    Ok(dirs
        .iter()
        .map(|d| crate::conformance::band::near_texture_edge(&p, crate::cpu::dvec(*d), margin))
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
    let p = prepared_with_filter(light, nearest)?;
    Ok(normals
        .iter()
        .map(|&n| crate::cpu::irradiance::irradiance(&p, DVec3::ZERO, n))
        .collect())
}

/// A PNG of `w` × `h` random texels in [128, 255] per channel, in memory (the tests' textures).
pub fn random_png(w: u32, h: u32, rng: &mut crate::synthetic::Rng) -> crate::Asset {
    let img = image::RgbImage::from_fn(w, h, |_, _| {
        image::Rgb([0, 1, 2].map(|_| 128 + rng.below(128) as u8))
    });
    let mut bytes = std::io::Cursor::new(Vec::new());
    img.write_to(&mut bytes, image::ImageFormat::Png)
        .expect("an in-memory PNG encodes");
    crate::Asset::from_bytes(format!("gen-{w}x{h}.png"), bytes.into_inner())
}
