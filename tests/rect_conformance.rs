//! CPU (f64) vs GPU (f32) conformance of textured RectLights (DESIGN.md §6 "RectLight texture",
//! §5): generated textures of several sizes, both filters, identity, rotated, non-uniformly
//! scaled and sheared transforms, shaped and unshaped; emission, radiance and intensity within a
//! relative 1e-4 per channel. Irradiance: textured rects of up to `RECT_TEXELS_ON_DEVICE` texels
//! are integrated on the device (their receivers against the reference, the last test); larger
//! ones are the CPU reference's on both paths (`prepare::GpuPath::HostIrradiance`).
//!
//! Excluded radiance samples (documented divergences 1 and 7 of shaders/shared/texture.wgsl): rays
//! meeting the light's plane within a relative 1e-3 of the rect's edge (f32 may hit or miss),
//! and with the nearest filter within 1e-3 px of a texel edge (f32 may pick the neighbour).
//! Both counted and printed. Texel values are linear in [0.21, 1] (8-bit sRGB 128..255).

use crate::common;

use glam::{DMat3, DMat4, DQuat, DVec3};
use luxeval::testkit::ies::with_random_ies;
use luxeval::testkit::rect::{near_rect_discontinuity, prepare_rects_with_filter};
use luxeval::testkit::{Rng, check, irradiance_samples};
use luxeval::{
    Accumulate, Evaluator, Light, LightType, Reference, Shaping, TemperatureMode, Texture,
};

const TOL: f64 = 1e-4;

use luxeval::testkit::dome::random_png as png;

fn unit(rng: &mut Rng) -> DVec3 {
    let z: f64 = 2.0 * rng.f64() - 1.0;
    let p = std::f64::consts::TAU * rng.f64();
    let r = (1.0 - z * z).sqrt();
    DVec3::new(r * p.cos(), r * p.sin(), z)
}

fn f32s(v: DVec3) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

const SIZES: [(u32, u32); 4] = [(1, 1), (2, 3), (7, 5), (16, 9)];

fn transforms() -> [DMat4; 4] {
    let rot = DQuat::from_axis_angle(DVec3::new(0.3, -0.5, 0.8).normalize(), 0.9);
    let shear = DMat4::from_mat3(DMat3::from_cols(
        DVec3::new(1.3, 0.0, 0.0),
        DVec3::new(0.4, 0.8, 0.0),
        DVec3::new(0.0, 0.2, 1.1),
    ));
    [
        DMat4::IDENTITY,
        DMat4::from_rotation_translation(rot, DVec3::new(1.0, -2.0, 0.5)),
        DMat4::from_scale_rotation_translation(DVec3::new(2.0, 0.5, 1.5), rot, DVec3::Y),
        DMat4::from_rotation_translation(rot, DVec3::new(-0.5, 0.3, 2.0)) * shear,
    ]
}

/// Textured rects of the given texture sizes (one generated texture each) under every transform
/// of [`transforms`], shaped by cone, softness and focus on every other one.
fn rects(rng: &mut Rng, sizes: &[(u32, u32)]) -> Vec<(Light, DMat4)> {
    let mut out = Vec::new();
    for (k, &(w, h)) in sizes.iter().enumerate() {
        let file = png(w, h, rng);
        for (j, m) in transforms().into_iter().enumerate() {
            let mut l = Light::rect(1.0 + 0.3 * k as f64, 0.6 + 0.2 * j as f64)
                .with_path(format!("/Rect_{w}x{h}_{j}"))
                .with_intensity(1.5 + j as f64)
                .with_transform(m)
                .with_texture(Texture::new(file.clone()));
            if (k + j) % 2 == 1 {
                l = l.with_shaping(Shaping {
                    focus: 1.5,
                    focus_tint: DVec3::new(0.2, 0.5, 1.0),
                    cone_angle: 70.0,
                    cone_softness: 0.5,
                    ies: None,
                });
            }
            out.push((l, m));
        }
    }
    out
}

/// Relative difference per channel, against at least 1e-3 of the light's largest value of that
/// query (an absolute 1e-7 of the peak): a shaped light's smoothstep tail carries f32's relative
/// error of the smoothstep near its zero, which is the untextured shaping's divergence, not
/// the texture's (tests/conformance.rs bounds it).
fn rel(g: [f32; 3], c: [f32; 3], peak: f64) -> f64 {
    (0..3)
        .map(|i| {
            (g[i] as f64 - c[i] as f64).abs() / (c[i] as f64).abs().max(1e-3 * peak).max(1e-30)
        })
        .fold(0.0, f64::max)
}

#[test]
fn gpu_matches_cpu_on_textured_rects() {
    let Some(gpu) = common::gpu() else { return };
    let cpu = Evaluator::cpu();
    let mut rng = Rng::new(0x4EC7);
    let lights = rects(&mut rng, &SIZES);
    let models: Vec<Light> = lights.iter().map(|(l, _)| l.clone()).collect();
    let n = 800;
    let mut total = 0usize;
    let mut excluded = 0usize;
    let mut hits = 0usize;
    let mut worst = (0.0f64, String::new());
    let mut failures = Vec::new();
    for nearest in [false, true] {
        let g = prepare_rects_with_filter(&gpu, &models, nearest).expect("GPU scene");
        let c = prepare_rects_with_filter(&cpu, &models, nearest).expect("CPU scene");
        for (l, (light, m)) in lights.iter().enumerate() {
            // Emission and intensity: any direction (about half on the emitting side).
            let dirs: Vec<[f32; 3]> = (0..n).map(|_| f32s(unit(&mut rng))).collect();
            // Radiance: from points on the emitting side (local −Z) toward random points of the
            // rect (and a little beyond its edges).
            let (mut points, mut rays) = (Vec::new(), Vec::new());
            let LightType::Rect { width, height } = light.kind else {
                unreachable!()
            };
            for _ in 0..n {
                let from = DVec3::new(
                    2.0 * rng.f64() - 1.0,
                    2.0 * rng.f64() - 1.0,
                    -0.2 - 2.0 * rng.f64(),
                );
                let to = DVec3::new(
                    (rng.f64() - 0.5) * 1.1 * width,
                    (rng.f64() - 0.5) * 1.1 * height,
                    0.0,
                );
                let x = m.transform_point3(from);
                points.push(f32s(x));
                rays.push(f32s((m.transform_point3(to) - x).normalize()));
            }
            let skip = near_rect_discontinuity(light, &points, &rays, nearest, 1e-3).unwrap();
            let results = [
                (
                    "emission",
                    g.emission(&dirs, Accumulate::PerLight).unwrap(),
                    c.emission(&dirs, Accumulate::PerLight).unwrap(),
                    None,
                ),
                (
                    "intensity",
                    g.intensity(&dirs, Accumulate::PerLight).unwrap(),
                    c.intensity(&dirs, Accumulate::PerLight).unwrap(),
                    None,
                ),
                (
                    "radiance",
                    g.radiance(&points, &rays, Accumulate::PerLight).unwrap(),
                    c.radiance(&points, &rays, Accumulate::PerLight).unwrap(),
                    Some(&skip),
                ),
            ];
            for (query, gv, cv, skip) in &results {
                let peak = (0..n)
                    .map(|i| {
                        cv[l * n + i]
                            .iter()
                            .fold(0.0f64, |a, &b| a.max(b.abs() as f64))
                    })
                    .fold(0.0, f64::max);
                for i in 0..n {
                    if skip.is_some_and(|s| s[i]) {
                        excluded += 1;
                        continue;
                    }
                    let (gg, cc) = (gv[l * n + i], cv[l * n + i]);
                    if *query == "radiance" && cc != [0.0; 3] {
                        hits += 1;
                    }
                    total += 1;
                    let e = rel(gg, cc, peak);
                    let what = format!(
                        "{query} {} nearest={nearest} sample {i}: gpu {gg:?} cpu {cc:?}",
                        light.path
                    );
                    if e > worst.0 {
                        worst = (e, what.clone());
                    }
                    if e > TOL {
                        failures.push((e, what));
                    }
                }
            }
        }
    }
    println!(
        "rect texture conformance on {}: {total} compared ({hits} radiance hits), {excluded} excluded, worst {:.3e} ({})",
        gpu.device_name(),
        worst.0,
        worst.1
    );
    assert!(hits > total / 6, "too few radiance hits: {hits}");
    assert!(excluded < total / 20, "too many excluded: {excluded}");
    let mut by: std::collections::BTreeMap<String, usize> = Default::default();
    for (_, w) in &failures {
        let key: Vec<&str> = w.split_whitespace().take(3).collect();
        *by.entry(key.join(" ")).or_default() += 1;
    }
    println!("failures by light: {by:?}");
    failures.sort_by(|a, b| b.0.total_cmp(&a.0));
    assert!(
        failures.is_empty(),
        "{} of {total} beyond {TOL}: {:#?}",
        failures.len(),
        &failures[..failures.len().min(10)]
    );
}

/// The textures of the irradiance test: small enough that most receivers' quadratures fit
/// lavapipe's loop budget (a receiver cut short is recomputed on the host, and counted).
const IRRADIANCE_SIZES: [(u32, u32); 4] = [(1, 1), (2, 3), (3, 2), (4, 4)];

/// Textured rects of up to `RECT_TEXELS_ON_DEVICE` texels are integrated on the device, their
/// quadrature split at the texture's break lines (shaders/irradiance/line.wgsl, outer.wgsl):
/// per light, every receiver within `check::TOLERANCE` of the reference (the CPU's exact split
/// integral to 1e-9, src/cpu/irradiance/rect_texture.rs), both filters, every transform kind,
/// shaped and unshaped, three IES-shaped; receivers from 1.05 to 6 sizes away (`testkit::irradiance_samples`)
/// and close ones (0.02 to 0.5 of the smaller half-extent in front of the rect).
#[test]
fn gpu_irradiance_of_small_textured_rects_matches_the_reference() {
    let Some(gpu) = common::gpu() else { return };
    let mut rng = Rng::new(0x1EE7);
    let mut lights: Vec<Light> = rects(&mut rng, &IRRADIANCE_SIZES)
        .into_iter()
        .map(|(l, _)| l)
        .collect();
    // IES-shaped (continuous profiles of types C and A: their grid lines split the lines too,
    // streamed beside the texture's).
    let file = png(3, 2, &mut rng);
    for (j, shape) in [1usize, 4, 9].into_iter().enumerate() {
        let m = transforms()[j + 1];
        let l = Light::rect(1.4, 0.9)
            .with_path(format!("/Rect_ies_{shape}"))
            .with_intensity(2.0)
            .with_transform(m)
            .with_texture(Texture::new(file.clone()));
        lights.push(with_random_ies(l, &mut rng, shape, true));
    }
    let mut total = 0usize;
    let mut recomputed = 0usize;
    let mut lit = 0usize;
    let mut worst = (0.0f64, String::new());
    let mut failures = Vec::new();
    for nearest in [false, true] {
        let models = luxeval::testkit::dome::with_filter(&lights, nearest);
        for light in &models {
            let r = Reference::new(light, TemperatureMode::Spec).expect("valid light");
            let (mut points, mut normals) = irradiance_samples(&r, 24, &mut rng);
            let LightType::Rect { width, height } = light.kind else {
                unreachable!()
            };
            for _ in 0..8 {
                let local = DVec3::new(
                    (rng.f64() - 0.5) * 1.2 * width,
                    (rng.f64() - 0.5) * 1.2 * height,
                    -(0.02 + 0.48 * rng.f64()) * 0.5 * width.min(height),
                );
                let x = light.world.transform_point3(local);
                let toward = (light.world.transform_point3(DVec3::ZERO) - x).normalize();
                points.push(f32s(x));
                normals.push(f32s((toward + unit(&mut rng) * 0.5).normalize()));
            }
            let scene = gpu.prepare(std::slice::from_ref(light)).expect("GPU scene");
            let got = scene
                .irradiance(&points, &normals, Accumulate::Sum)
                .expect("GPU irradiance");
            recomputed += scene.host_recomputed_rows();
            for i in 0..points.len() {
                let v = |a: [f32; 3]| DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64);
                let cpu = r.irradiance(v(points[i]), v(normals[i]).normalize());
                total += 1;
                lit += (cpu.max_element() > 0.0) as usize;
                let e = check::rel_error(cpu, got[i]);
                let what = format!(
                    "{} nearest={nearest} receiver {i}: gpu {:?} cpu {cpu:?}",
                    light.path, got[i]
                );
                if e > worst.0 {
                    worst = (e, what.clone());
                }
                if e > check::TOLERANCE {
                    failures.push((e, what));
                }
            }
        }
    }
    println!(
        "textured rect irradiance on {}: {total} receivers ({lit} lit), {recomputed} recomputed \
         on the host, worst {:.3e} ({})",
        gpu.device_name(),
        worst.0,
        worst.1
    );
    assert!(lit * 2 > total, "only {lit} of {total} receivers lit");
    assert!(
        recomputed * 4 < total,
        "{recomputed} of {total} receivers recomputed on the host"
    );
    failures.sort_by(|a, b| b.0.total_cmp(&a.0));
    assert!(
        failures.is_empty(),
        "{} of {total} beyond {}: {:#?}",
        failures.len(),
        check::TOLERANCE,
        &failures[..failures.len().min(10)]
    );
}
