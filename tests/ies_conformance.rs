//! CPU (f64) vs GPU (f32) conformance of IES-shaped lights (DESIGN.md §6, §5): random profiles
//! of every photometric type, symmetry and vertical range (testkit::ies::SHAPES), on every
//! area-light type under every transform kind, with and without angleScale and normalize,
//! combined with random cone and focus; emission, radiance and intensity within
//! check::TOLERANCE outside the excluded band (which includes the jumps of a profile at its
//! range ends, check::emission_margin). Irradiance of an IES-shaped light is the CPU
//! reference's on the GPU path as well (the f32 quadrature does not split at a profile's angle
//! nodes); the last test holds the GPU path to exactly that.

use crate::common;

use luxeval::testkit::check;
use luxeval::testkit::ies::{SHAPES, with_random_ies};
use luxeval::testkit::irradiance_samples;
use luxeval::testkit::{Rng, TRANSFORMS, random_light};
use luxeval::{Accumulate, Light, Reference, TemperatureMode};

fn lights(rng: &mut Rng, continuous: bool) -> Vec<Light> {
    let mut out = Vec::new();
    for shape in 0..SHAPES.len() {
        for ty in 1..=4 {
            for xf in TRANSFORMS {
                let id = out.len();
                let l = random_light(ty, xf, rng, id);
                out.push(with_random_ies(l, rng, shape, continuous));
            }
        }
    }
    out
}

#[test]
fn gpu_matches_cpu_on_ies_shaped_lights() {
    let Some(gpu) = common::gpu() else { return };
    let device = gpu.device_name();
    let mut rng = Rng::new(0x1E5_1E5);
    let mut reports = Vec::new();
    let (mut total, mut excluded) = (0, 0);
    for continuous in [false, true] {
        let lights = lights(&mut rng, continuous);
        let refs: Vec<Reference> = lights
            .iter()
            .map(|l| Reference::new(l, TemperatureMode::Spec).expect("valid light"))
            .collect();
        let counts = check::Samples {
            emission: 160,
            intensity: 160,
            radiance: 160,
            // Irradiance of IES-shaped lights is the CPU reference's on the GPU path too
            // (see gpu_irradiance_of_ies_lights_is_the_reference below).
            irradiance: 0,
        };
        let seed = 5 + continuous as u64;
        let report = check::check_with(&gpu, &refs, counts, seed).expect("GPU check runs");
        total += report.samples;
        excluded += report.excluded;
        reports.extend(report.rows);
    }
    reports.sort_by(|a, b| b.max_rel_error.total_cmp(&a.max_rel_error));
    println!("IES conformance on {device}: {total} samples, {excluded} excluded");
    for r in reports.iter().take(8) {
        println!(
            "  {:>10.3e}  {:?} {:>14} {}  worst {:?}",
            r.max_rel_error, r.query, r.light_type, r.light, r.worst
        );
    }
    assert!(total >= 100_000, "only {total} samples");
    assert!(excluded * 50 < total, "{excluded} of {total} excluded");
    let failures: Vec<_> = reports.iter().filter(|r| !r.pass).collect();
    assert!(
        failures.is_empty(),
        "{} light/query pairs over tolerance; worst {:?}",
        failures.len(),
        failures.first()
    );
}

#[test]
fn gpu_irradiance_of_ies_lights_is_the_reference() {
    let Some(gpu) = common::gpu() else { return };
    let mut rng = Rng::new(77);
    // An IES-shaped sphere and rect beside two plain lights, in a mixed order.
    let lights = vec![
        with_random_ies(random_light(1, "rotate", &mut rng, 0), &mut rng, 3, false),
        random_light(2, "uniform-scale", &mut rng, 1),
        with_random_ies(random_light(2, "translate", &mut rng, 2), &mut rng, 6, true),
        random_light(1, "identity", &mut rng, 3),
    ];
    let refs: Vec<Reference> = lights
        .iter()
        .map(|l| Reference::new(l, TemperatureMode::Spec).expect("valid light"))
        .collect();
    let (points, normals) = irradiance_samples(&refs[0], 40, &mut rng);
    let per = gpu
        .irradiance(&lights, &points, &normals, Accumulate::PerLight)
        .expect("GPU irradiance");
    let sum = gpu
        .irradiance(&lights, &points, &normals, Accumulate::Sum)
        .expect("GPU irradiance");
    let n = points.len();
    let mut lit = 0;
    for (k, r) in refs.iter().enumerate() {
        for i in 0..n {
            let x = glam::Vec3::from_array(points[i]).as_dvec3();
            let nn = glam::Vec3::from_array(normals[i]).as_dvec3().normalize();
            let cpu = r.irradiance(x, nn);
            let got = per[k * n + i];
            if k % 2 == 0 {
                // IES-shaped: the reference rounded to f32, exactly.
                assert_eq!(got, cpu.as_vec3().to_array(), "light {k} receiver {i}");
                lit += (cpu.max_element() > 0.0) as usize;
            } else {
                let e = check::rel_error(cpu, got);
                assert!(
                    e < 1e-4 || cpu.max_element() < 1e-30,
                    "light {k} receiver {i}: {e}"
                );
            }
        }
    }
    assert!(lit > 10, "only {lit} lit receivers of the IES lights");
    for i in 0..n {
        for c in 0..3 {
            let total: f64 = (0..refs.len()).map(|k| per[k * n + i][c] as f64).sum();
            let d = (sum[i][c] as f64 - total).abs();
            assert!(
                d <= 1e-6 * total.abs().max(1e-30),
                "receiver {i}: {} vs {total}",
                sum[i][c]
            );
        }
    }
}
