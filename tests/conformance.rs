//! CPU (f64) vs GPU (f32, WGSL) conformance over randomised lights and samples covering every
//! light type, transform kind and attribute (DESIGN.md §5).
//!
//! Tolerance: relative error ≤ 1e-4 (luxeval::check::TOLERANCE); the excluded band around
//! discontinuities is luxeval::check::BAND (1e-4 rad, or 1e-4 of the shape's size) — see
//! src/check.rs for exactly which samples it covers. The test prints its sample count, the
//! excluded count and the largest errors.

use crate::common;

use glam::DVec3;
use luxeval::testkit::check;
use luxeval::testkit::{Rng, TRANSFORMS, random_light, random_lights};
use luxeval::{Accumulate, Evaluator, Light, LightType, Reference, TemperatureMode};

fn references(lights: &[Light], mode: TemperatureMode) -> Vec<Reference> {
    lights
        .iter()
        .map(|l| Reference::new(l, mode).expect("valid light"))
        .collect()
}

#[test]
fn gpu_matches_cpu_on_randomised_lights() {
    let Some(gpu) = common::gpu() else { return };
    let device = gpu.device_name();
    let mut rng = Rng::new(0x1A7E_5EED);
    let lights = random_lights(&mut rng, 6); // 6 types × 7 transforms × 6 = 252 lights
    let samples_per_query = 200;
    let mut total = 0;
    let mut excluded = 0;
    let mut worst: Vec<check::QueryReport> = Vec::new();
    for (k, mode) in TemperatureMode::ALL.into_iter().enumerate() {
        // Every light under the spec mode; a third of them under the other two modes.
        let subset: Vec<&Light> = lights
            .iter()
            .enumerate()
            .filter(|(i, _)| k == 0 || i % 3 == k)
            .map(|(_, l)| l)
            .collect();
        let prepared: Vec<Reference> = subset
            .iter()
            .map(|l| Reference::new(l, mode).expect("valid light"))
            .collect();
        // Irradiance depends on the temperature mode only through the base radiance: a few
        // receivers per light under the spec mode here; tests below cover it in depth.
        let counts = check::Samples {
            emission: samples_per_query,
            intensity: samples_per_query,
            radiance: samples_per_query,
            irradiance: if k == 0 { 12 } else { 0 },
        };
        let report =
            check::check_with(&gpu, &prepared, counts, 7 + k as u64).expect("GPU check runs");
        total += report.samples;
        excluded += report.excluded;
        worst.extend(report.rows);
    }
    worst.sort_by(|a, b| b.max_rel_error.total_cmp(&a.max_rel_error));
    let compared_nonzero: usize = worst.iter().map(|r| r.nonzero).sum();
    println!("device: {device}");
    println!(
        "conformance: {total} (light, sample) pairs over {} lights; {excluded} excluded (within {} rad / {} of size of an edge, or {} of the cone angle of a cone edge); {compared_nonzero} compared samples with non-zero CPU value",
        lights.len(),
        check::BAND,
        check::BAND,
        check::CONE_BAND
    );
    println!("largest relative errors:");
    for r in worst.iter().take(8) {
        println!(
            "  {:>10.3e}  {:8} {:>14} {}  worst {:?}",
            r.max_rel_error,
            format!("{:?}", r.query),
            r.light_type,
            r.light,
            r.worst
        );
    }
    assert!(total >= 100_000, "only {total} samples");
    assert!(
        excluded * 100 < total,
        "excluded band swallowed {excluded} of {total}"
    );
    let failures: Vec<_> = worst.iter().filter(|r| !r.pass).collect();
    assert!(
        failures.is_empty(),
        "{} light/query pairs over tolerance {}; worst {:?}",
        failures.len(),
        check::TOLERANCE,
        failures.first()
    );
}

/// Summed and per-light batches, many lights at once, through the public Evaluator on both
/// backends: the GPU sum equals the CPU sum, and the per-light rows add up to the sum.
#[test]
fn summed_and_per_light_batches_agree() {
    let Some(gpu) = common::gpu() else { return };
    let cpu = Evaluator::cpu();
    let mut rng = Rng::new(99);
    let lights = random_lights(&mut rng, 1);
    let prepared = references(&lights, TemperatureMode::Spec);
    let n = 4000;
    let dirs: Vec<[f32; 3]> = (0..n).map(|_| rng.unit().as_vec3().to_array()).collect();
    let points: Vec<[f32; 3]> = (0..n)
        .map(|_| {
            DVec3::new(
                rng.range(-6.0, 6.0),
                rng.range(-6.0, 6.0),
                rng.range(-6.0, 6.0),
            )
            .as_vec3()
            .to_array()
        })
        .collect();
    for query in ["emission", "radiance"] {
        let run = |e: &Evaluator, acc| match query {
            "emission" => e.emission(&lights, &dirs, acc).unwrap(),
            _ => e.radiance(&lights, &points, &dirs, acc).unwrap(),
        };
        let (gs, gp, cs) = (
            run(&gpu, Accumulate::Sum),
            run(&gpu, Accumulate::PerLight),
            run(&cpu, Accumulate::Sum),
        );
        assert_eq!(gs.len(), n);
        assert_eq!(gp.len(), n * lights.len());
        let mut compared = 0;
        for i in 0..n {
            let x = glam::Vec3::from_array(points[i]).as_dvec3();
            let w = glam::Vec3::from_array(dirs[i]).as_dvec3();
            let near_edge = prepared.iter().any(|p| match query {
                "emission" => check::emission_margin(p, w) < check::BAND,
                _ => check::radiance_margin(p, x, w) < check::BAND,
            });
            let per_light_sum: glam::Vec3 = (0..lights.len())
                .map(|l| glam::Vec3::from_array(gp[l * n + i]))
                .sum();
            // Same kernel, same lights: the per-light rows add up to the summed row (f32 sums
            // in the same order).
            assert!(
                (per_light_sum - glam::Vec3::from_array(gs[i]))
                    .abs()
                    .max_element()
                    <= 1e-5 * per_light_sum.abs().max_element().max(1e-30),
                "row {i}"
            );
            if near_edge {
                continue;
            }
            compared += 1;
            let c = glam::Vec3::from_array(cs[i]).as_dvec3();
            // Summed over ~42 lights of very different magnitudes: relative to the sample's
            // largest per-light value, since cancellation cannot occur (all values ≥ 0 except
            // negative tints, which random_light never makes).
            let err = check::rel_error(c, gs[i]);
            assert!(
                err <= check::TOLERANCE,
                "{query} row {i}: cpu {c} gpu {:?} err {err:e}",
                gs[i]
            );
        }
        assert!(compared > n / 2, "{query}: only {compared} rows compared");
    }
}

/// Irradiance, GPU against the CPU reference, on every light type (including treatAsPoint and
/// treatAsLine, shaped or not) under every transform kind: 40 receivers per light, points
/// around the light and normals random or toward it (check::irradiance_samples), within
/// check::TOLERANCE outside the excluded band (check::irradiance_margin).
#[test]
fn irradiance_matches_cpu_on_every_type_and_transform() {
    let Some(gpu) = common::gpu() else { return };
    let device = gpu.device_name();
    let mut rng = Rng::new(0x1AAD_1A4C);
    let mut lights = random_lights(&mut rng, 2); // 84 lights
    for (i, xf) in TRANSFORMS.iter().enumerate() {
        for shaped in [false, true] {
            let mut p = random_light(1, xf, &mut rng, 1000 + 2 * i);
            p.kind = LightType::Sphere {
                radius: rng.range(0.05, 1.0),
                treat_as_point: true,
            };
            let mut c = random_light(4, xf, &mut rng, 1001 + 2 * i);
            c.kind = LightType::Cylinder {
                length: rng.range(0.2, 2.0),
                radius: rng.range(0.05, 0.5),
                treat_as_line: true,
            };
            for mut l in [p, c] {
                if !shaped {
                    l.shaping = None;
                }
                lights.push(l);
            }
        }
    }
    let prepared = references(&lights, TemperatureMode::Spec);
    let counts = check::Samples {
        emission: 0,
        intensity: 0,
        radiance: 0,
        irradiance: 40,
    };
    let report = check::check_with(&gpu, &prepared, counts, 11).expect("GPU check runs");
    let mut rows = report.rows.clone();
    rows.sort_by(|a, b| b.max_rel_error.total_cmp(&a.max_rel_error));
    let nonzero: usize = rows.iter().map(|r| r.nonzero).sum();
    println!(
        "irradiance conformance on {device}: {} receivers over {} lights; {} excluded; {nonzero} compared with non-zero CPU value",
        report.samples,
        lights.len(),
        report.excluded
    );
    for r in rows.iter().take(6) {
        println!(
            "  {:>10.3e}  {:>14} {}  worst {:?}",
            r.max_rel_error, r.light_type, r.light, r.worst
        );
    }
    for ty in [
        "DistantLight",
        "SphereLight",
        "DiskLight",
        "RectLight",
        "CylinderLight",
        "DomeLight",
    ] {
        assert!(
            rows.iter().any(|r| r.light_type == ty && r.nonzero > 0),
            "{ty} not covered"
        );
    }
    assert!(
        report.excluded * 50 < report.samples,
        "excluded band swallowed {} of {}",
        report.excluded,
        report.samples
    );
    assert!(nonzero * 2 > report.samples, "only {nonzero} non-zero");
    let failures: Vec<_> = rows.iter().filter(|r| !r.pass).collect();
    assert!(
        failures.is_empty(),
        "{} lights over tolerance {}; worst {:?}",
        failures.len(),
        check::TOLERANCE,
        failures.first()
    );
}

/// Each light alone: the GPU builds the irradiance pipeline with only the parts the scene's
/// lights need (the chart quadrature, treatAsLine: gpu::shaders::Features, chosen by
/// `Record::features`), so a light in a scene of its own must find every part it takes. One
/// light of each type, shaped and not, and a treatAsPoint sphere and a treatAsLine cylinder,
/// each within check::TOLERANCE of the CPU at receivers where the CPU's value is not zero.
#[test]
fn irradiance_of_each_light_alone_matches_cpu() {
    let Some(gpu) = common::gpu() else { return };
    let mut rng = Rng::new(0x0A10_4E11);
    let xf = TRANSFORMS[TRANSFORMS.len() - 1];
    let mut lights = Vec::new();
    for ty in 0..6 {
        for shaped in [false, true] {
            let mut l = random_light(ty, xf, &mut rng, 2000 + 2 * ty + usize::from(shaped));
            // The flags random_light draws by chance are set below, one light each.
            l.kind = match l.kind {
                LightType::Sphere { radius, .. } => LightType::Sphere {
                    radius,
                    treat_as_point: false,
                },
                LightType::Cylinder { length, radius, .. } => LightType::Cylinder {
                    length,
                    radius,
                    treat_as_line: false,
                },
                k => k,
            };
            if !shaped {
                l.shaping = None;
            }
            lights.push(l);
        }
    }
    let mut p = random_light(1, xf, &mut rng, 2100);
    p.kind = LightType::Sphere {
        radius: 0.3,
        treat_as_point: true,
    };
    let mut c = random_light(4, xf, &mut rng, 2101);
    c.kind = LightType::Cylinder {
        length: 1.5,
        radius: 0.2,
        treat_as_line: true,
    };
    lights.extend([p, c]);
    let counts = check::Samples {
        emission: 0,
        intensity: 0,
        radiance: 0,
        irradiance: 40,
    };
    for (i, light) in lights.iter().enumerate() {
        let prepared = references(std::slice::from_ref(light), TemperatureMode::Spec);
        let report =
            check::check_with(&gpu, &prepared, counts, 100 + i as u64).expect("GPU check runs");
        let row = &report.rows[0];
        assert!(
            row.nonzero > 0,
            "light {i} ({}): no receiver with a non-zero value",
            row.light_type
        );
        assert!(
            row.pass,
            "light {i} ({}) alone: {:e} over tolerance {}; worst {:?}",
            row.light_type,
            row.max_rel_error,
            check::TOLERANCE,
            row.worst
        );
    }
}

/// Irradiance through the public Evaluator on both backends, many lights at once: the GPU sum
/// equals the CPU sum, and per-light rows add up to the summed rows.
#[test]
fn irradiance_summed_and_per_light_agree() {
    let Some(gpu) = common::gpu() else { return };
    let cpu = Evaluator::cpu();
    let mut rng = Rng::new(4242);
    let lights = random_lights(&mut rng, 1); // 42 lights
    let prepared = references(&lights, TemperatureMode::Spec);
    let n = 40;
    let mut points = Vec::new();
    let mut normals = Vec::new();
    for _ in 0..n {
        let x = DVec3::new(
            rng.range(-6.0, 6.0),
            rng.range(-6.0, 6.0),
            rng.range(-6.0, 6.0),
        );
        points.push(x.as_vec3().to_array());
        normals.push((-x.normalize() + rng.unit() * 0.8).as_vec3().to_array());
    }
    let gs = gpu
        .irradiance(&lights, &points, &normals, Accumulate::Sum)
        .unwrap();
    let gp = gpu
        .irradiance(&lights, &points, &normals, Accumulate::PerLight)
        .unwrap();
    let cs = cpu
        .irradiance(&lights, &points, &normals, Accumulate::Sum)
        .unwrap();
    let cp = cpu
        .irradiance(&lights, &points, &normals, Accumulate::PerLight)
        .unwrap();
    assert_eq!((gs.len(), gp.len()), (n, n * lights.len()));
    let mut compared = 0;
    for i in 0..n {
        let x = glam::Vec3::from_array(points[i]).as_dvec3();
        let nn = glam::Vec3::from_array(normals[i]).as_dvec3();
        for (sum, per) in [(&gs, &gp), (&cs, &cp)] {
            let s: glam::Vec3 = (0..lights.len())
                .map(|l| glam::Vec3::from_array(per[l * n + i]))
                .sum();
            assert!(
                (s - glam::Vec3::from_array(sum[i])).abs().max_element()
                    <= 1e-5 * s.abs().max_element().max(1e-30),
                "row {i}"
            );
        }
        if prepared
            .iter()
            .any(|p| check::irradiance_margin(p, x, nn) < check::BAND)
        {
            continue;
        }
        compared += 1;
        let c = glam::Vec3::from_array(cs[i]).as_dvec3();
        let err = check::rel_error(c, gs[i]);
        if err > check::TOLERANCE {
            // Name the lights whose own rows disagree.
            let culprits: Vec<String> = (0..lights.len())
                .filter_map(|l| {
                    let (g, c) = (gp[l * n + i], cp[l * n + i]);
                    let e = check::rel_error(glam::Vec3::from_array(c).as_dvec3(), g);
                    (e > check::TOLERANCE)
                        .then(|| format!("{} {:?}: cpu {c:?} gpu {g:?}", l, lights[l].kind))
                })
                .collect();
            panic!(
                "row {i}: cpu {c} gpu {:?} err {err:e}; lights {culprits:#?}",
                gs[i]
            );
        }
    }
    assert!(compared > n / 2, "only {compared} rows compared");
}

/// More lights than one dispatch takes on llvmpipe (16384 per group; llvmpipe leaves a loop after
/// 65535 iterations in total): the summed result accumulates over the groups and still equals
/// the CPU sum, and per-light rows land in their own rows.
#[test]
fn light_groups_accumulate_over_many_lights() {
    let Some(gpu) = common::gpu() else { return };
    let cpu = Evaluator::cpu();
    let mut rng = Rng::new(99);
    let base = random_lights(&mut rng, 1);
    // 70 000 lights: every type and transform, repeated (the loop limit would cut a single
    // dispatch's loop near 65 535).
    let lights: Vec<Light> = (0..70_000).map(|i| base[i % base.len()].clone()).collect();
    let dirs: Vec<[f32; 3]> = (0..16).map(|_| rng.unit().as_vec3().to_array()).collect();
    let g = gpu.emission(&lights, &dirs, Accumulate::Sum).unwrap();
    let c = cpu.emission(&lights, &dirs, Accumulate::Sum).unwrap();
    for (i, (g, c)) in g.iter().zip(&c).enumerate() {
        let c = glam::Vec3::from_array(*c).as_dvec3();
        // f32 summation over 70 000 terms on the GPU: 1e-3 bounds its rounding (n·ε/2 = 4e-3
        // worst case; a cut loop would lose most of the sum).
        let err = check::rel_error(c, *g);
        assert!(err < 1e-3, "direction {i}: cpu {c} gpu {g:?} err {err:e}");
    }
}
