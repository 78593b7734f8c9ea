//! Randomised lights covering every type, transform kind and attribute: the conformance suite,
//! `luxeval check`'s own tests, and the benchmark's synthetic scene.

use glam::{DMat4, DQuat, DVec3};

use super::Rng;
use crate::model::{Light, LightType, Shaping};

/// The transform kinds the conformance suite covers for every type.
pub const TRANSFORMS: [&str; 7] = [
    "identity",
    "translate",
    "rotate",
    "uniform-scale",
    "nonuniform-scale",
    "shear",
    "mirror",
];

pub fn transform(kind: &str, rng: &mut Rng) -> DMat4 {
    let t = DVec3::new(
        rng.range(-3.0, 3.0),
        rng.range(-3.0, 3.0),
        rng.range(-3.0, 3.0),
    );
    let q = DQuat::from_axis_angle(rng.unit(), rng.range(0.0, std::f64::consts::TAU));
    match kind {
        "identity" => DMat4::IDENTITY,
        "translate" => DMat4::from_translation(t),
        "rotate" => DMat4::from_rotation_translation(q, t),
        "uniform-scale" => {
            DMat4::from_scale_rotation_translation(DVec3::splat(rng.range(0.3, 3.0)), q, t)
        }
        "nonuniform-scale" => DMat4::from_scale_rotation_translation(
            DVec3::new(
                rng.range(0.3, 3.0),
                rng.range(0.3, 3.0),
                rng.range(0.3, 3.0),
            ),
            q,
            t,
        ),
        "shear" => {
            // luxtest frames 26-30 use rows (1.25,0,0),(0,1,0),(0.6,0,0.75) under a rotation.
            let shear = DMat4::from_cols_array_2d(&[
                [rng.range(0.8, 1.5), rng.range(-0.5, 0.5), 0.0, 0.0],
                [0.0, 1.0, rng.range(-0.5, 0.5), 0.0],
                [rng.range(-0.8, 0.8), 0.0, rng.range(0.5, 1.2), 0.0],
                [0.0, 0.0, 0.0, 1.0],
            ]);
            DMat4::from_rotation_translation(q, t) * shear
        }
        "mirror" => {
            DMat4::from_rotation_translation(q, t)
                * DMat4::from_scale(DVec3::new(-1.0, rng.range(0.5, 2.0), 1.0))
        }
        other => panic!("unknown transform kind {other}"),
    }
}

/// A random light of type `ty` (0 distant, 1 sphere, 2 disk, 3 rect, 4 cylinder, 5 dome)
/// under transform kind `xf`, with random LightAPI and (70 %) ShapingAPI inputs.
pub fn random_light(ty: usize, xf: &str, rng: &mut Rng, id: usize) -> Light {
    let mut l = match ty {
        0 => Light::distant(if rng.chance(0.15) {
            0.0
        } else {
            rng.range(0.1, 250.0)
        }),
        1 => {
            let mut l = Light::sphere(rng.range(0.05, 1.0));
            if rng.chance(0.15) {
                l.kind = LightType::Sphere {
                    radius: rng.range(0.05, 1.0),
                    treat_as_point: true,
                };
            }
            l
        }
        2 => Light::disk(rng.range(0.05, 1.0)),
        3 => Light::rect(rng.range(0.1, 2.0), rng.range(0.1, 2.0)),
        4 => {
            let mut l = Light::cylinder(rng.range(0.2, 2.0), rng.range(0.05, 0.5));
            if rng.chance(0.15) {
                l.kind = LightType::Cylinder {
                    length: 1.0,
                    radius: 0.2,
                    treat_as_line: true,
                };
            }
            l
        }
        _ => Light::dome(),
    };
    let name = format!("/random/{id}_{}_{xf}", l.kind.usd_type());
    l = l
        .with_path(name)
        .with_intensity(rng.range(0.1, 100.0))
        .with_exposure(rng.range(-4.0, 4.0))
        .with_color(DVec3::new(
            rng.range(0.05, 1.0),
            rng.range(0.05, 1.0),
            rng.range(0.05, 1.0),
        ))
        .with_normalize(rng.chance(0.5))
        .with_transform(transform(xf, rng));
    if rng.chance(0.4) {
        l = l.with_temperature(rng.range(800.0, 16000.0));
    }
    if rng.chance(0.7) {
        let cone_angle = match rng.below(4) {
            0 => 90.0,
            1 => rng.range(5.0, 90.0),
            2 => rng.range(90.0, 180.0),
            _ => rng.range(-10.0, 200.0),
        };
        l = l.with_shaping(Shaping {
            focus: if rng.chance(0.6) {
                rng.range(-1.0, 8.0)
            } else {
                0.0
            },
            focus_tint: DVec3::new(rng.f64(), rng.f64(), rng.f64()),
            cone_angle,
            cone_softness: if rng.chance(0.3) {
                0.0
            } else {
                rng.range(-0.2, 1.3)
            },
            ies: None,
        });
    }
    l
}

/// Every type × transform kind, `per_combo` lights each.
pub fn random_lights(rng: &mut Rng, per_combo: usize) -> Vec<Light> {
    let mut lights = Vec::new();
    for ty in 0..6 {
        for xf in TRANSFORMS {
            for _ in 0..per_combo {
                let id = lights.len();
                lights.push(random_light(ty, xf, rng, id));
            }
        }
    }
    lights
}

/// The benchmark's lights: every analytic type under every transform kind (shaped or not),
/// cycled to `n`; deterministic.
pub fn synthetic_lights(n: usize) -> Vec<Light> {
    let mut rng = Rng::new(2026);
    let pool = random_lights(&mut rng, 1);
    // Domes are uniform and trivially cheap; keep the mix on the shapes.
    let shaped: Vec<Light> = pool
        .into_iter()
        .filter(|l| !matches!(l.kind, LightType::Dome))
        .collect();
    (0..n)
        .map(|i| shaped[(i * 7) % shaped.len()].clone())
        .collect()
}
