//! CPU (f64) vs GPU (f32) conformance of IES-shaped lights (DESIGN.md §6, §5): random profiles
//! of every photometric type, symmetry and vertical range (testkit::ies::SHAPES), on every
//! area-light type under every transform kind, with and without angleScale and normalize,
//! combined with random cone and focus; emission, radiance and irradiance within
//! check::TOLERANCE outside the excluded band (which includes the jumps of a profile at its
//! range ends, check::emission_margin).

mod common;

use luxeval::check;
use luxeval::testkit::ies::{SHAPES, with_random_ies};
use luxeval::testkit::{Rng, TRANSFORMS, random_light};
use luxeval::{Light, Reference, TemperatureMode};

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
            // Irradiance on continuous profiles (kinks only): the quadratures do not split at
            // a profile's jumps.
            irradiance: if continuous && std::env::var("IES_IRR").is_ok() { 6 } else { 0 },
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
