//! The intensity query and total power (DESIGN.md §3 "intensity"), against closed forms and
//! independent quadratures written here: `I(ω) = ∫ L max(0, n·ω) dA` over the emitting surface
//! and `Φ = ∫ I dω` over the sphere.

use std::f64::consts::PI;

use glam::{DMat4, DQuat, DVec3};
use luxeval::testkit::Rng;
use luxeval::{Asset, Ies, Light, LightType, Reference, Shaping, TemperatureMode};

fn r(l: &Light) -> Reference {
    Reference::new(l, TemperatureMode::Spec).unwrap()
}

fn rel(a: f64, b: f64) -> f64 {
    if a == b {
        0.0
    } else {
        (a - b).abs() / a.abs().max(b.abs())
    }
}

/// `∫ max(0, n·ω) dA` over a parametrised surface `p(u, v)`, u, v ∈ [0, 1], by a midpoint rule on
/// `n × n` cells with the area element `|∂u p × ∂v p|` and the outward normal along
/// `orient · (∂u p × ∂v p)` (central differences).
fn projected(p: &dyn Fn(f64, f64) -> DVec3, orient: f64, w: DVec3, n: usize) -> f64 {
    let h = 1.0 / n as f64;
    let d = 1e-6;
    let mut sum = 0.0;
    for i in 0..n {
        for j in 0..n {
            let (u, v) = ((i as f64 + 0.5) * h, (j as f64 + 0.5) * h);
            let du = (p(u + d, v) - p(u - d, v)) / (2.0 * d);
            let dv = (p(u, v + d) - p(u, v - d)) / (2.0 * d);
            let c = du.cross(dv) * orient;
            sum += c.dot(w).max(0.0) * h * h;
        }
    }
    sum
}

#[test]
fn closed_forms_for_unit_frames() {
    let l = 3.0;
    let rect = r(&Light::rect(2.0, 0.5).with_intensity(l));
    let disk = r(&Light::disk(0.4).with_intensity(l));
    let sphere = r(&Light::sphere(0.3).with_intensity(l));
    let cyl = r(&Light::cylinder(2.0, 0.25).with_intensity(l));
    for theta in [0.0f64, 0.3, 1.0, 1.5] {
        let e = DVec3::new(theta.sin(), 0.0, -theta.cos());
        assert!(rel(rect.intensity(e).x, l * 1.0 * theta.cos()) < 1e-14);
        assert!(rel(disk.intensity(e).x, l * PI * 0.16 * theta.cos()) < 1e-14);
        assert!(rel(sphere.intensity(e).x, l * PI * 0.09) < 1e-14);
        // The cylinder's axis is X: sin of the angle to it is |e_yz|.
        let a = DVec3::new(theta.cos(), theta.sin(), 0.0);
        assert!(rel(cyl.intensity(a).x, l * 2.0 * 2.0 * 0.25 * theta.sin()) < 1e-14);
    }
    // Behind a one-sided rect, along a cylinder's axis, and at infinity: nothing.
    assert_eq!(rect.intensity(DVec3::Z), DVec3::ZERO);
    assert_eq!(cyl.intensity(DVec3::X), DVec3::ZERO);
    assert_eq!(r(&Light::distant(1.0)).intensity(DVec3::NEG_Z), DVec3::ZERO);
    assert_eq!(r(&Light::dome()).intensity(DVec3::NEG_Z), DVec3::ZERO);
    // treatAsPoint has the full-size sphere's intensity (DESIGN.md §2).
    let mut p = Light::sphere(0.3).with_intensity(l);
    p.kind = LightType::Sphere {
        radius: 0.3,
        treat_as_point: true,
    };
    assert_eq!(r(&p).intensity(DVec3::X), sphere.intensity(DVec3::X));
}

/// Under scale, shear and mirror: the intensity against the projected area of the transformed
/// surface integrated here (each surface parametrised in world space).
#[test]
fn projected_area_under_any_linear_map() {
    let mut rng = Rng::new(41);
    for _ in 0..6 {
        let m = DMat4::from_cols_array_2d(&[
            [
                rng.range(0.5, 2.0),
                rng.range(-0.5, 0.5),
                rng.range(-0.5, 0.5),
                0.0,
            ],
            [
                rng.range(-0.5, 0.5),
                rng.range(0.5, 2.0),
                rng.range(-0.5, 0.5),
                0.0,
            ],
            [
                rng.range(-0.5, 0.5),
                rng.range(-0.5, 0.5),
                rng.range(0.5, 2.0) * if rng.chance(0.3) { -1.0 } else { 1.0 },
                0.0,
            ],
            [1.0, 2.0, 3.0, 1.0],
        ]);
        let lin = glam::DMat3::from_mat4(m);
        let w = rng.unit();
        let (width, height, radius, length) = (1.3, 0.7, 0.4, 1.7);
        // Rect: emits toward its local −Z side; orientation of ∂u × ∂v = M(X) × M(Y) is local
        // +Z's cofactor image, so the emitting side is the opposite (−1), flipped by a mirror.
        let sign = -lin.determinant().signum();
        let rect = |u: f64, v: f64| lin * DVec3::new((u - 0.5) * width, (v - 0.5) * height, 0.0);
        let want = projected(&rect, sign, w, 200);
        let got = r(&Light::rect(width, height).with_transform(m)).projected_area(w);
        assert!(rel(got, want) < 1e-6, "rect {got} vs {want}");
        // Disk in polar parameters (u radius fraction, v angle).
        let disk = |u: f64, v: f64| {
            let (s, c) = (2.0 * PI * v).sin_cos();
            lin * DVec3::new(u * radius * c, u * radius * s, 0.0)
        };
        let want = projected(&disk, sign, w, 400);
        let got = r(&Light::disk(radius).with_transform(m)).projected_area(w);
        assert!(rel(got, want) < 1e-4, "disk {got} vs {want}");
        // Sphere (u polar, v azimuth); outward normal ∂θ × ∂φ (orientation flips with a mirror).
        let sphere = |u: f64, v: f64| {
            let (st, ct) = (PI * u).sin_cos();
            let (sp, cp) = (2.0 * PI * v).sin_cos();
            lin * DVec3::new(radius * st * cp, radius * st * sp, radius * ct)
        };
        let want = projected(&sphere, lin.determinant().signum(), w, 600);
        let got = r(&Light::sphere(radius).with_transform(m)).projected_area(w);
        assert!(rel(got, want) < 1e-4, "sphere {got} vs {want}");
        // Cylinder side along X (u along the axis, v around it); outward ∂φ × ∂x.
        let cylinder = |u: f64, v: f64| {
            let (s, c) = (2.0 * PI * v).sin_cos();
            lin * DVec3::new((u - 0.5) * length, radius * c, radius * s)
        };
        let want = projected(&cylinder, -lin.determinant().signum(), w, 600);
        let got = r(&Light::cylinder(length, radius).with_transform(m)).projected_area(w);
        assert!(rel(got, want) < 1e-4, "cylinder {got} vs {want}");
    }
}

/// Unshaped lights emit `π·L·A` (A the world-space emitting area); a cone-shaped sphere
/// `L·πr²·2π∫ c(θ) sin θ dθ` with the cone factor written here from spec/002.
#[test]
fn total_power_closed_forms() {
    let m = DMat4::from_scale_rotation_translation(
        DVec3::new(1.5, 0.7, 1.2),
        DQuat::from_rotation_y(0.4),
        DVec3::ZERO,
    );
    let rect = r(&Light::rect(2.0, 0.5).with_intensity(4.0).with_transform(m));
    let area = 2.0 * 0.5 * (1.5 * 0.7);
    assert!(rel(rect.flux().unwrap().x, PI * 4.0 * area) < 1e-12);
    assert!(r(&Light::distant(1.0)).flux().is_none());
    assert!(r(&Light::dome()).flux().is_none());
    // A 40° cone with softness 0.3 on a sphere: the smoothstep in angle space.
    let (cone, soft) = (40f64.to_radians(), 0.3);
    let start = (1.0 - soft) * cone;
    let c = |t: f64| {
        if t > cone {
            0.0
        } else if t <= start {
            1.0
        } else {
            let s = (t - start) / (cone - start);
            1.0 - s * s * (3.0 - 2.0 * s)
        }
    };
    let n = 200_000;
    let integral: f64 = (0..n)
        .map(|k| {
            let t = (k as f64 + 0.5) / n as f64 * cone;
            c(t) * t.sin() * cone / n as f64
        })
        .sum();
    let sphere = Light::sphere(0.2)
        .with_intensity(2.0)
        .with_shaping(Shaping {
            cone_angle: 40.0,
            cone_softness: soft,
            ..Shaping::default()
        });
    let want = 2.0 * PI * 0.04 * 2.0 * PI * integral;
    let got = r(&sphere).flux().unwrap().x;
    assert!(rel(got, want) < 1e-8, "{got} vs {want}");
}

/// An IES-shaped point-like sphere with `L·πr² = 1`: its intensity is the profile in candela,
/// so its flux is the profile's (exact, §6 I6) and a uniform 1 cd profile gives 4π lm.
#[test]
fn ies_flux_is_the_profiles() {
    let uniform = "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 180\n0\n1 1\n";
    let radius: f64 = 0.01;
    let unit = 1.0 / (PI * radius * radius);
    let with = |text: &str| {
        let mut s = Shaping {
            cone_angle: 180.0,
            ..Shaping::default()
        };
        s.ies = Some(Ies::new(Asset::from_bytes(
            "p.ies",
            text.as_bytes().to_vec(),
        )));
        Light::sphere(radius).with_intensity(unit).with_shaping(s)
    };
    let flux = r(&with(uniform)).flux().unwrap().x;
    assert!(rel(flux, 4.0 * PI) < 1e-9, "{flux}");
    // A non-uniform profile (linear in V, four H planes): the flux equals the profile's exact
    // integral.
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/luxtest/test_vstripes_hquadrants_nonuniform.ies"
    ))
    .unwrap();
    let file =
        luxeval::testkit::ies_parts::parse_any(text.as_bytes(), &|_| Err(String::new())).unwrap();
    let exact = luxeval::IesProfile::new(&file).unwrap().flux_lm();
    let flux = r(&with(&text)).flux().unwrap().x;
    assert!(rel(flux, exact) < 1e-6, "{flux} vs {exact}");
}
