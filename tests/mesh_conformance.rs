//! CPU (f64) vs GPU (f32, WGSL) conformance over randomised mesh lights (DESIGN.md §7: closed
//! convex, closed non-convex, open, double-sided; every transform kind, mirrors included; shaped
//! or not) and randomised domes masked by portals (§8 P2), through the same comparison `luxeval
//! check` prints (tolerance 1e-4 relative, samples within the band of an edge excluded).
//! What a GPU evaluator takes from the CPU reference is listed by the report (`host_only`), not
//! compared; everything else must be.

use crate::common;

use luxeval::testkit::check;
use luxeval::testkit::{MESH_CLASSES, Rng, random_mesh_lights, random_portal_dome};
use luxeval::{Asset, Light, PortalMode, Reference, TemperatureMode, Texture};

fn print(report: &check::CheckReport) {
    println!(
        "{} samples, {} excluded, largest relative error {:.3e}",
        report.samples,
        report.excluded,
        report.max_rel_error()
    );
    for r in &report.rows {
        println!(
            "  {:>10.3e} {:>5} compared ({:>4} non-zero, {:>3} excluded) {:?} {}",
            r.max_rel_error,
            r.samples - r.excluded,
            r.nonzero,
            r.excluded,
            r.query,
            r.light
        );
    }
    for (light, why) in &report.host_only {
        println!("  not compared: {light}: {why}");
    }
}

#[test]
fn gpu_matches_cpu_on_randomised_mesh_lights() {
    let Some(gpu) = common::gpu() else { return };
    let mut rng = Rng::new(0x3E5B_0022);
    let lights = random_mesh_lights(&mut rng, 2); // 5 classes × 7 transforms × 2 = 70 lights
    assert_eq!(lights.len(), MESH_CLASSES.len() * 7 * 2);
    let refs: Vec<Reference> = lights
        .iter()
        .map(|l| Reference::new(l, TemperatureMode::Spec).expect("valid mesh light"))
        .collect();
    let counts = check::Samples {
        emission: 200,
        intensity: 50,
        radiance: 400,
        irradiance: 4,
    };
    let report = check::check_with(&gpu, &refs, counts, 22).expect("GPU check runs");
    print(&report);
    // Radiance is the device's for every one of these meshes (none is deeper or larger than the
    // kernel takes): every light has a radiance row, and enough rays hit to mean something.
    let radiance: Vec<&check::QueryReport> = report
        .rows
        .iter()
        .filter(|r| r.query == check::CheckedQuery::Radiance)
        .collect();
    assert_eq!(radiance.len(), lights.len());
    let compared: usize = radiance.iter().map(|r| r.samples - r.excluded).sum();
    let lit: usize = radiance.iter().map(|r| r.nonzero).sum();
    assert!(
        lit * 5 >= compared,
        "only {lit} of {compared} compared rays hit"
    );
    assert!(
        report.excluded * 20 < report.samples,
        "the band swallowed {} of {}",
        report.excluded,
        report.samples
    );
    let failures: Vec<_> = report.rows.iter().filter(|r| !r.pass).collect();
    assert!(
        failures.is_empty(),
        "{} light/query pairs over {}: {:?}",
        failures.len(),
        check::TOLERANCE,
        failures.first()
    );
}

#[test]
fn gpu_matches_cpu_on_randomised_portal_scenes() {
    let Some(gpu) = common::gpu() else { return };
    let gpu = gpu.with_portal_mode(PortalMode::Mask);
    let mut rng = Rng::new(0x0090_87A1);
    let texture = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/textures/testImage.png")
        .display()
        .to_string();
    let domes: Vec<Light> = (0..10)
        .map(|i| {
            let d = random_portal_dome(&mut rng, i);
            if i % 2 == 1 {
                d.with_texture(Texture::new(Asset::file(texture.clone())))
            } else {
                d
            }
        })
        .collect();
    let refs: Vec<Reference> = domes
        .iter()
        .map(|l| {
            Reference::with_portal_mode(l, TemperatureMode::Spec, PortalMode::Mask)
                .expect("valid dome")
        })
        .collect();
    let counts = check::Samples {
        emission: 200,
        intensity: 50,
        radiance: 600,
        irradiance: 4,
    };
    let report = check::check_with(&gpu, &refs, counts, 8).expect("GPU check runs");
    print(&report);
    // Every dome's radiance is the device's (the portal crossings of shaders/portal.wgsl) and
    // compared, most rays aimed at its portals from their lit side, a fifth at least passing
    // through one; its irradiance is the host's (listed).
    for d in &domes {
        let radiance = report
            .rows
            .iter()
            .find(|r| r.light == d.path && r.query == check::CheckedQuery::Radiance)
            .unwrap_or_else(|| panic!("{}: radiance not compared", d.path));
        assert!(
            radiance.nonzero * 5 >= radiance.samples,
            "{}: {radiance:?}",
            d.path
        );
    }
    assert!(report.pass(), "{:?}", report.rows.iter().find(|r| !r.pass));
}

/// Unshaped random boxes under every transform kind (closed convex, one-sided: their
/// irradiance is the device's, `GpuPath::HostIntensityOnly`): `luxeval check` compares an
/// irradiance row for each, within the tolerance, and lists only their intensity as the host's.
#[test]
fn gpu_irradiance_of_unshaped_boxes_is_compared() {
    let Some(gpu) = common::gpu() else { return };
    let mut rng = Rng::new(0x00B0_C5E5);
    let mut lights = Vec::new();
    for xf in luxeval::testkit::TRANSFORMS {
        for _ in 0..3 {
            let id = lights.len();
            let mut b = luxeval::testkit::random_mesh_light("box", xf, &mut rng, id);
            b.shaping = None;
            lights.push(b);
        }
    }
    let refs: Vec<Reference> = lights
        .iter()
        .map(|l| Reference::new(l, TemperatureMode::Spec).expect("valid mesh light"))
        .collect();
    let counts = check::Samples {
        emission: 50,
        intensity: 10,
        radiance: 100,
        irradiance: 200,
    };
    let report = check::check_with(&gpu, &refs, counts, 22).expect("GPU check runs");
    print(&report);
    let irradiance: Vec<&check::QueryReport> = report
        .rows
        .iter()
        .filter(|r| r.query == check::CheckedQuery::Irradiance)
        .collect();
    assert_eq!(irradiance.len(), lights.len());
    let compared: usize = irradiance.iter().map(|r| r.samples - r.excluded).sum();
    let lit: usize = irradiance.iter().map(|r| r.nonzero).sum();
    assert!(lit * 3 >= compared, "only {lit} of {compared} lit");
    assert!(
        compared * 10 >= 9 * 200 * lights.len() / 2,
        "the band swallowed too many: {compared} compared"
    );
    for (light, why) in &report.host_only {
        assert!(why.contains("whose intensity the CPU"), "{light}: {why}");
    }
    let failures: Vec<_> = report.rows.iter().filter(|r| !r.pass).collect();
    assert!(
        failures.is_empty(),
        "{} light/query pairs over {}: {:?}",
        failures.len(),
        check::TOLERANCE,
        failures.first()
    );
}
