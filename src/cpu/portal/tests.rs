//! Expected values are computed here, independently of the code under test: Lambert's
//! formula written out for polygons wholly above the horizon, the overlap split by hand,
//! and a Monte Carlo of the radiance for the irradiance. The textured irradiance's proofs
//! of exactness are in `exact_tests.rs`.
use std::f64::consts::PI;

use glam::{DMat4, DQuat, DVec3};

use crate::model::{Asset, Light, Portal, Texture, TextureFormat};
use crate::prepare::{GpuPath, PortalMode, Prepared, TemperatureMode};
use crate::query::{Accumulate, Evaluator, SampleOptions, Selection};
use crate::synthetic::Rng;

/// Unit-radiance irradiance of a planar polygon wholly above the receiver's horizon, from
/// the vectors `v` from x to its vertices: `½ |Σ θ_i n·û_i|`, θ_i the angle between v_i and
/// v_{i+1}, û_i the unit normal of the plane through x and that edge (Lambert 1760).
fn lambert(v: &[DVec3], n: DVec3) -> f64 {
    assert!(
        v.iter().all(|q| n.dot(*q) > 0.0),
        "the test keeps polygons above the horizon"
    );
    let mut s = 0.0;
    for i in 0..v.len() {
        let (a, b) = (v[i].normalize(), v[(i + 1) % v.len()].normalize());
        let theta = a.dot(b).clamp(-1.0, 1.0).acos();
        s += theta * n.dot(a.cross(b).normalize());
    }
    0.5 * s.abs()
}

/// The corners of an axis-aligned w × h rectangle centred at `c` in the plane z = c.z.
fn square(c: DVec3, w: f64, h: f64) -> [DVec3; 4] {
    [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .map(|(a, b)| c + DVec3::new(a * w / 2.0, b * h / 2.0, 0.0))
}

fn rel(a: DVec3, b: DVec3) -> f64 {
    (a - b).abs().max_element() / b.abs().max_element()
}

fn at(p: DVec3) -> DMat4 {
    DMat4::from_translation(p)
}

fn mask(l: &Light) -> Prepared {
    let mut p = Prepared::new(l, TemperatureMode::Spec).unwrap();
    p.apply_portal_mode(PortalMode::Mask, TemperatureMode::Spec)
        .unwrap();
    p
}

fn f32s(v: &[DVec3]) -> Vec<[f32; 3]> {
    v.iter().map(|d| d.as_vec3().to_array()).collect()
}

/// A uniform dome of radiance (2, 1, 0.5) and diffuse 0.7 through one 2 × 1 portal tilted
/// and raised: `L ⊙ multiplier × diffuse × Lambert(portal)` from its −Z side, 0 from its +Z
/// side and where the portal is below the horizon.
#[test]
fn uniform_dome_through_one_portal_is_lambert() {
    let rot = DQuat::from_rotation_x(0.3) * DQuat::from_rotation_z(0.4);
    let world = DMat4::from_rotation_translation(rot, DVec3::new(0.2, -0.1, 3.0));
    let portal = Portal::new(2.0, 1.0)
        .with_path("/W")
        .with_transform(world)
        .with_intensity(3.0)
        .with_exposure(1.0)
        .with_color(DVec3::new(1.0, 0.5, 0.25));
    let dome = Light::dome()
        .with_intensity(2.0)
        .with_color(DVec3::new(1.0, 0.5, 0.25))
        .with_diffuse(0.7)
        .with_portal(portal);
    let p = mask(&dome);
    // Untextured, one portal: the device sums Lambert's formula (irradiance/portals.wgsl).
    assert_eq!(p.gpu_path, GpuPath::Device);
    let corners = [(-1.0, -0.5), (1.0, -0.5), (1.0, 0.5), (-1.0, 0.5)]
        .map(|(a, b)| world.transform_point3(DVec3::new(a, b, 0.0)));
    let l = DVec3::new(2.0, 1.0, 0.5) * DVec3::new(6.0, 3.0, 1.5) * 0.7;
    let mut worst: f64 = 0.0;
    for (x, n) in [
        (DVec3::ZERO, DVec3::Z),
        (
            DVec3::new(0.5, 0.3, -1.0),
            DVec3::new(0.1, -0.2, 1.0).normalize(),
        ),
        (
            DVec3::new(-2.0, 1.0, 0.5),
            DVec3::new(0.3, 0.0, 1.0).normalize(),
        ),
    ] {
        let v = corners.map(|c| c - x);
        let want = l * lambert(&v, n);
        let got = super::super::irradiance::irradiance(&p, x, n);
        worst = worst.max(rel(got, want));
        assert!(rel(got, want) <= 1e-12, "{x}: {got} vs {want}");
    }
    eprintln!("worst relative error against Lambert: {worst:e}");
    // From the portal's +Z side the dome is not seen through it.
    let above = world.transform_point3(DVec3::new(0.0, 0.0, 2.0));
    let e = super::super::irradiance::irradiance(&p, above, -DVec3::Z);
    assert_eq!(e, DVec3::ZERO);
    // Below the horizon: nothing.
    assert_eq!(
        super::super::irradiance::irradiance(&p, DVec3::ZERO, -DVec3::Z),
        DVec3::ZERO
    );
}

/// Two portals at different depths overlapping as seen from x: the nearer's multiplier
/// where they overlap, counted once; the farther's on the rest of it. Whatever the order
/// the dome names them in; and the radiance agrees.
#[test]
fn overlapping_portals_count_once_for_the_nearest() {
    // Near: 1 × 1 at z = 2 (seen as the 2 × 2 square at z = 4); far: 4 × 4 at z = 4.
    let near = Portal::new(1.0, 1.0)
        .with_path("/Near")
        .with_transform(at(DVec3::new(0.0, 0.0, 2.0)))
        .with_intensity(3.0);
    let far = Portal::new(4.0, 4.0)
        .with_path("/Far")
        .with_transform(at(DVec3::new(0.0, 0.0, 4.0)))
        .with_color(DVec3::new(0.5, 1.0, 2.0));
    let (x, n) = (DVec3::ZERO, DVec3::new(0.1, 0.05, 1.0).normalize());
    let inner = lambert(&square(DVec3::new(0.0, 0.0, 4.0), 2.0, 2.0), n);
    let outer = lambert(&square(DVec3::new(0.0, 0.0, 4.0), 4.0, 4.0), n);
    let want = 3.0 * inner * DVec3::ONE + (outer - inner) * DVec3::new(0.5, 1.0, 2.0);
    for order in [[&near, &far], [&far, &near]] {
        let dome = order
            .into_iter()
            .fold(Light::dome(), |d, p| d.with_portal(p.clone()));
        let p = mask(&dome);
        let got = super::super::irradiance::irradiance(&p, x, n);
        assert!(rel(got, want) <= 1e-12, "{got} vs {want}");
        let up = super::radiance(&p, p.portals.as_ref().unwrap(), x, DVec3::Z);
        assert_eq!(up, DVec3::splat(3.0));
        let side = DVec3::new(1.5, 0.0, 4.0).normalize();
        let got = super::radiance(&p, p.portals.as_ref().unwrap(), x, side);
        assert_eq!(got, DVec3::new(0.5, 1.0, 2.0));
    }
}

/// Radiance: inside the rectangle toward its +Z, the dome ⊙ multiplier; outside it, or
/// from the +Z side, 0; a nearer portal crossed toward its −Z is ignored (not opaque), for
/// radiance and irradiance alike.
#[test]
fn radiance_inside_outside_and_crossings_toward_minus_z() {
    let window = Portal::new(2.0, 2.0)
        .with_path("/Window")
        .with_transform(at(DVec3::new(0.0, 0.0, 4.0)))
        .with_intensity(0.5);
    let dome = Light::dome()
        .with_intensity(4.0)
        .with_portal(window.clone());
    let p = mask(&dome);
    let ports = p.portals.clone().unwrap();
    let x = DVec3::ZERO;
    // Inside (the edge is inclusive), outside.
    assert_eq!(super::radiance(&p, &ports, x, DVec3::Z), DVec3::splat(2.0));
    let edge = DVec3::new(1.0, 0.0, 4.0).normalize();
    assert_eq!(super::radiance(&p, &ports, x, edge), DVec3::splat(2.0));
    let out = DVec3::new(1.01, 0.0, 4.0).normalize();
    assert_eq!(super::radiance(&p, &ports, x, out), DVec3::ZERO);
    // Away from the portal, and from its +Z side toward it (a crossing toward −Z).
    assert_eq!(super::radiance(&p, &ports, x, -DVec3::Z), DVec3::ZERO);
    let above = DVec3::new(0.0, 0.0, 6.0);
    assert_eq!(super::radiance(&p, &ports, above, -DVec3::Z), DVec3::ZERO);
    assert_eq!(super::radiance(&p, &ports, above, DVec3::Z), DVec3::ZERO);
    // A nearer portal turned over (its +Z toward world −Z): x is on its +Z side, so the ray
    // crosses it toward its −Z and goes on to the window.
    let flipped = Portal::new(1.0, 1.0)
        .with_path("/Flipped")
        .with_transform(DMat4::from_rotation_translation(
            DQuat::from_rotation_x(PI),
            DVec3::new(0.0, 0.0, 2.0),
        ))
        .with_intensity(100.0);
    let both = Light::dome()
        .with_intensity(4.0)
        .with_portal(flipped)
        .with_portal(window);
    let q = mask(&both);
    let ports = q.portals.clone().unwrap();
    assert_eq!(super::radiance(&q, &ports, x, DVec3::Z), DVec3::splat(2.0));
    let want = 2.0 * lambert(&square(DVec3::new(0.0, 0.0, 4.0), 2.0, 2.0), DVec3::Z);
    let got = super::super::irradiance::irradiance(&q, x, DVec3::Z);
    assert!(rel(got, DVec3::splat(want)) <= 1e-12, "{got} vs {want}");
    // From above both, looking down: the window is crossed toward its −Z (ignored), the
    // flipped portal toward its +Z (world −Z): its multiplier.
    assert_eq!(
        super::radiance(&q, &ports, above, -DVec3::Z),
        DVec3::splat(400.0)
    );
    // From below the flipped one (z = 3 is between), looking down through it toward its +Z
    // (world −Z): its multiplier.
    let mid = DVec3::new(0.0, 0.0, 3.0);
    assert_eq!(
        super::radiance(&q, &ports, mid, -DVec3::Z),
        DVec3::splat(400.0)
    );
}

/// Cosine-weighted directions about n: `π/N Σ radiance` estimates the irradiance
/// (`diffuse` applied by hand); within 5σ of the exact value.
fn monte_carlo_agrees(dome: Light, n_samples: usize) {
    let p = mask(&dome);
    let ports = p.portals.clone().unwrap();
    let (x, n) = (
        DVec3::new(0.3, -0.2, 0.1),
        DVec3::new(0.2, 0.1, 1.0).normalize(),
    );
    let (t, b) = n.any_orthonormal_pair();
    let mut rng = Rng::new(7);
    let (mut sum, mut sum2) = (DVec3::ZERO, DVec3::ZERO);
    for _ in 0..n_samples {
        let (u1, u2) = (rng.f64(), rng.f64());
        let r = u1.sqrt();
        let phi = 2.0 * PI * u2;
        let w = t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt();
        let v = super::radiance(&p, &ports, x, w.normalize()) * PI;
        sum += v;
        sum2 += v * v;
    }
    let k = n_samples as f64;
    let mean = sum / k * dome.inputs.diffuse;
    let var = (sum2 / k - (sum / k) * (sum / k)) / k;
    let sigma = var.max(DVec3::ZERO).sqrt() * dome.inputs.diffuse;
    let exact = super::super::irradiance::irradiance(&p, x, n);
    // A channel the portals see none of is exactly 0 in both.
    for c in 0..3 {
        if sigma[c] == 0.0 {
            assert_eq!(mean[c], exact[c], "channel {c}");
        }
    }
    let z = ((mean - exact).abs() / sigma.max(DVec3::splat(f64::MIN_POSITIVE))).max_element();
    eprintln!("MC {mean} ± {sigma} vs {exact}: {z:.2} σ");
    assert!(exact.max_element() > 0.0);
    assert!(z < 5.0, "MC {mean} ± {sigma} vs {exact}: {z} σ");
}

/// Two portals of a room (a window and a skylight, overlapping as seen from x), for an
/// untextured dome and the textured ones (tests/data/textures/).
fn room(dome: Light) -> Light {
    let window = Portal::new(3.0, 2.0)
        .with_path("/Window")
        .with_transform(DMat4::from_rotation_translation(
            DQuat::from_rotation_y(0.5),
            DVec3::new(0.5, 0.0, 2.5),
        ))
        .with_color(DVec3::new(0.9, 0.8, 0.7));
    let skylight = Portal::new(2.0, 2.0)
        .with_path("/Skylight")
        .with_transform(at(DVec3::new(0.0, 0.5, 4.0)))
        .with_intensity(2.0);
    dome.with_diffuse(0.8)
        .with_portal(window)
        .with_portal(skylight)
}

/// A textured masked dome's irradiance is exact (docs/PORTALS.md), not adaptive: a query's
/// tolerance does not change it.
#[test]
fn textured_irradiance_does_not_depend_on_the_query_tolerance() {
    use crate::cpu::irradiance::{Adaptive, irradiance_with};
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/textures/testImage.png"
    );
    let tex = Texture::new(Asset::file(file)).with_format(TextureFormat::LatLong);
    let p = mask(&room(Light::dome().with_texture(tex)));
    let (x, n) = (
        DVec3::new(0.3, -0.2, 0.1),
        DVec3::new(0.2, 0.1, 1.0).normalize(),
    );
    let reference = irradiance_with(&p, x, n, &Adaptive::REFERENCE);
    for tol in [1e-3, 1e-4, 1e-6] {
        let got = irradiance_with(&p, x, n, &Adaptive::for_tolerance(tol));
        assert_eq!(got, reference, "{tol:e}");
    }
}

#[test]
fn monte_carlo_of_masked_radiance_untextured() {
    monte_carlo_agrees(room(Light::dome().with_intensity(1.5)), 400_000);
}

#[test]
fn monte_carlo_of_masked_radiance_textured() {
    // The orientation chart: the studio map's sun would leave σ at ~15 % of the mean.
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/textures/testImage.png"
    );
    let tex = Texture::new(Asset::file(file)).with_format(TextureFormat::LatLong);
    monte_carlo_agrees(room(Light::dome().with_texture(tex)), 400_000);
}

/// Hint mode (and mask mode for a dome naming no portal) gives bitwise the values of the
/// dome without portals, on every query, summed and per light.
#[test]
fn hint_mode_is_bitwise_no_portal() {
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/textures/studio_dwab.exr"
    );
    let tex = Texture::new(Asset::file(file)).with_format(TextureFormat::LatLong);
    let mut rng = Rng::new(3);
    let mut unit = || {
        DVec3::new(rng.f64() - 0.5, rng.f64() - 0.5, rng.f64() - 0.5)
            .normalize()
            .as_vec3()
            .to_array()
    };
    let dirs: Vec<[f32; 3]> = (0..64).map(|_| unit()).collect();
    let normals: Vec<[f32; 3]> = (0..64).map(|_| unit()).collect();
    let points: Vec<[f32; 3]> = (0..64).map(|i| [i as f32 * 0.1, 0.0, 0.5]).collect();
    for plain in [
        Light::dome().with_intensity(2.0),
        Light::dome().with_texture(tex),
    ] {
        let named = room(plain.clone());
        let plain = plain.with_diffuse(0.8);
        let cases = [(PortalMode::Hint, &named), (PortalMode::Mask, &plain)];
        for (mode, lights) in cases {
            let lights = [
                lights.clone(),
                Light::sphere(0.5).with_transform(at(DVec3::Y)),
            ];
            let without = [plain.clone(), lights[1].clone()];
            let eval = Evaluator::cpu().with_portal_mode(mode);
            let base = Evaluator::cpu();
            for acc in [Accumulate::Sum, Accumulate::PerLight] {
                assert!(
                    eval.emission(&lights, &dirs, acc).unwrap()
                        == base.emission(&without, &dirs, acc).unwrap()
                );
                assert!(
                    eval.intensity(&lights, &dirs, acc).unwrap()
                        == base.intensity(&without, &dirs, acc).unwrap()
                );
                assert!(
                    eval.radiance(&lights, &points, &dirs, acc).unwrap()
                        == base.radiance(&without, &points, &dirs, acc).unwrap()
                );
                assert!(
                    eval.irradiance(&lights, &points, &normals, acc).unwrap()
                        == base.irradiance(&without, &points, &normals, acc).unwrap()
                );
            }
            // Sampling too: hint mode samples as without portals.
            let opts = SampleOptions {
                seed: 1,
                selection: Selection::Bound,
                first_point: 0,
            };
            let a = eval.prepare(&lights).unwrap();
            let b = base.prepare(&without).unwrap();
            assert!(
                a.sample(&points, Some(&normals), 4, &opts).unwrap()
                    == b.sample(&points, Some(&normals), 4, &opts).unwrap()
            );
        }
    }
}

/// Mask mode changes what it should (radiance, irradiance), not emission or intensity;
/// sampling refuses a masked dome, naming it.
#[test]
fn mask_mode_changes_radiance_and_irradiance_and_refuses_sampling() {
    let dome = room(Light::dome().with_path("/World/Sky"));
    let dirs = f32s(&[DVec3::Z, DVec3::X, DVec3::new(0.1, 0.3, 1.0).normalize()]);
    let points = vec![[0.0f32; 3]; 3];
    let hint = Evaluator::cpu();
    let maskev = Evaluator::cpu().with_portal_mode(PortalMode::Mask);
    let l = [dome];
    let acc = Accumulate::Sum;
    assert!(hint.emission(&l, &dirs, acc).unwrap() == maskev.emission(&l, &dirs, acc).unwrap());
    assert!(
        hint.radiance(&l, &points, &dirs, acc).unwrap()
            != maskev.radiance(&l, &points, &dirs, acc).unwrap()
    );
    assert!(
        hint.irradiance(&l, &points, &dirs, acc).unwrap()
            != maskev.irradiance(&l, &points, &dirs, acc).unwrap()
    );
    let scene = maskev.prepare(&l).unwrap();
    let opts = SampleOptions {
        seed: 1,
        selection: Selection::Bound,
        first_point: 0,
    };
    let e = scene.sample(&points, None, 1, &opts).unwrap_err();
    assert!(matches!(e, crate::LuxError::NotSupported { .. }), "{e}");
    assert!(e.to_string().contains("/World/Sky"), "{e}");
}

/// A masked textured dome depends on the receiver's position, not its normal alone: the
/// batch path (which shares one integral per normal for unmasked textured domes) gives each
/// receiver its own value.
#[test]
fn batch_of_a_masked_textured_dome_is_per_receiver() {
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/textures/testImage.png"
    );
    let tex = Texture::new(Asset::file(file)).with_format(TextureFormat::LatLong);
    let dome = room(Light::dome().with_texture(tex));
    let p = mask(&dome);
    let points = [[0.0f32, 0.0, 0.0], [0.5, 0.3, 1.0], [-0.4, 0.2, 3.0]];
    let normals = [[0.0f32, 0.0, 1.0]; 3];
    let got = Evaluator::cpu()
        .with_portal_mode(PortalMode::Mask)
        .irradiance(&[dome], &points, &normals, Accumulate::Sum)
        .unwrap();
    for (x, row) in points.iter().zip(&got) {
        let x = DVec3::from_array(x.map(f64::from));
        let want = super::super::irradiance::irradiance(&p, x, DVec3::Z);
        assert_eq!(*row, want.as_vec3().to_array(), "{x}");
    }
    assert!(got[0] != got[1] && got[1] != got[2], "{got:?}");
}

/// A bad portal input is refused in mask mode, naming the portal and the attribute; hint
/// mode does not read portals (bitwise no portal), so it does not refuse them. A zero-size
/// portal passes no light: the dome is masked to 0.
#[test]
fn bad_portals_refused_in_mask_mode_only() {
    let cases = [
        (Portal::new(-1.0, 1.0), "inputs:width"),
        (Portal::new(1.0, f64::NAN), "inputs:height"),
        (
            Portal::new(1.0, 1.0).with_intensity(f64::INFINITY),
            "inputs:intensity",
        ),
        (
            Portal::new(1.0, 1.0).with_exposure(2000.0),
            "inputs:exposure",
        ),
    ];
    for (portal, attr) in cases {
        let dome = Light::dome().with_portal(portal.with_path("/World/Bad"));
        let mut p = Prepared::new(&dome, TemperatureMode::Spec).unwrap();
        let e = p
            .apply_portal_mode(PortalMode::Mask, TemperatureMode::Spec)
            .unwrap_err()
            .to_string();
        assert!(e.contains("/World/Bad") && e.contains(attr), "{attr}: {e}");
        p.apply_portal_mode(PortalMode::Hint, TemperatureMode::Spec)
            .unwrap();
        assert!(p.portals.is_none());
    }
    let dome = Light::dome().with_portal(Portal::new(0.0, 1.0));
    let p = mask(&dome);
    assert_eq!(p.portals.as_ref().map(Vec::len), Some(0));
    let e = super::super::irradiance::irradiance(&p, DVec3::ZERO, DVec3::Z);
    assert_eq!(e, DVec3::ZERO);
}

/// On a GPU evaluator a masked dome's emission and radiance are the device's (within f32
/// rounding of the reference: these rays pass far from the portals' edges), and so is its
/// irradiance (inclusion–exclusion over this room's overlapping portals:
/// `prepare::portal::overlaps`); its intensity is the reference's.
#[test]
fn gpu_takes_masked_domes_from_the_reference() {
    let Some(gpu) = crate::query::test_gpu() else {
        return;
    };
    let l = [room(Light::dome().with_intensity(1.5))];
    let dirs = f32s(&[DVec3::Z, DVec3::X, DVec3::new(0.1, 0.3, 1.0).normalize()]);
    let points = vec![[0.1f32, 0.0, 0.0]; 3];
    let cpu = Evaluator::cpu().with_portal_mode(PortalMode::Mask);
    let gpu = gpu.with_portal_mode(PortalMode::Mask);
    let close = |a: Vec<[f32; 3]>, b: Vec<[f32; 3]>| {
        assert_eq!(a.len(), b.len());
        for (a, b) in a.iter().zip(&b) {
            let (a, b) = (DVec3::from(a.map(f64::from)), DVec3::from(b.map(f64::from)));
            assert!(
                (a - b).abs().max_element() <= 1e-4 * b.abs().max_element(),
                "{a} vs {b}"
            );
        }
    };
    for acc in [Accumulate::Sum, Accumulate::PerLight] {
        let got = gpu.radiance(&l, &points, &dirs, acc).unwrap();
        assert!(got.iter().any(|v| v[0] > 0.0), "nothing lit: {got:?}");
        close(got, cpu.radiance(&l, &points, &dirs, acc).unwrap());
        close(
            gpu.emission(&l, &dirs, acc).unwrap(),
            cpu.emission(&l, &dirs, acc).unwrap(),
        );
        close(
            gpu.irradiance(&l, &points, &dirs, acc).unwrap(),
            cpu.irradiance(&l, &points, &dirs, acc).unwrap(),
        );
        assert_eq!(
            gpu.intensity(&l, &dirs, acc).unwrap(),
            cpu.intensity(&l, &dirs, acc).unwrap()
        );
    }
}
