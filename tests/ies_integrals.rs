//! §6 I6: the exact mean intensity over the sphere. Worked values in closed form, and an
//! independent check of `mean_intensity` by Gauss–Legendre quadrature of `ies_factor` over the
//! whole sphere, for every type and symmetry.
use crate::ies_common;

use std::f64::consts::PI;

use glam::DVec3;
use ies_common::*;
use luxeval::testkit::ies_parts::ies_factor;

/// A constant profile's mean is the constant over 0–180 (so normalize gives 1 everywhere).
#[test]
fn constant_profile_mean_is_the_constant() {
    for c in [1.0, 7.25, 1234.5] {
        let p = Ies::from_fn(
            1,
            &[0.0, 90.0, 180.0, 270.0, 360.0],
            &[0.0, 10.0, 90.0, 180.0],
            |_, _| c,
        )
        .profile();
        assert_close(p.mean_intensity(), c, 1e-14);
        for e in [
            DVec3::X,
            DVec3::new(0.3, -0.4, 0.5).normalize(),
            DVec3::NEG_Z,
        ] {
            assert_close(ies_factor(&p, e, 0.0) / p.mean_intensity(), 1.0, 1e-14);
        }
    }
}

/// A uniform 1 cd point source emits 4π lm.
#[test]
fn uniform_unit_candela_is_four_pi_lumens() {
    let p = Ies::from_fn(1, &[0.0], &[0.0, 180.0], |_, _| 1.0).profile();
    assert_close(p.flux_lm(), 4.0 * PI, 1e-15);
}

/// Constant c over partial vertical ranges: `c (cos V₀ − cos V₁)/2`.
#[test]
fn constant_over_partial_vertical_ranges() {
    let c = 3.0;
    let mean = |v: &[f64]| {
        Ies::from_fn(1, &[0.0, 90.0], v, |_, _| c)
            .profile()
            .mean_intensity()
    };
    assert_close(mean(&[0.0, 90.0]), c / 2.0, 1e-15);
    assert_close(mean(&[90.0, 180.0]), c / 2.0, 1e-15);
    assert_close(
        mean(&[0.0, 50.0]),
        c * (1.0 - 50f64.to_radians().cos()) / 2.0,
        1e-14,
    );
    assert_close(
        mean(&[130.0, 180.0]),
        c * (1.0 + 130f64.to_radians().cos()) / 2.0,
        1e-14,
    );
}

/// 0–90 profile linear 1 → 0 in θ: `(1/2)∫₀^{π/2} (1 − 2θ/π) sin θ dθ = 1/2 − 1/π`.
#[test]
fn linear_quarter_profile() {
    let p = Ies::new(1, &[0.0], &[0.0, 90.0], &[1.0, 0.0]).profile();
    assert_close(p.mean_intensity(), 0.5 - 1.0 / PI, 1e-14);
    // The same with the linear ramp sampled on a non-uniform grid (exact: still linear).
    let p = Ies::from_fn(1, &[0.0, 90.0], &[0.0, 7.0, 30.0, 31.0, 90.0], |_, v| {
        1.0 - v / 90.0
    })
    .profile();
    assert_close(p.mean_intensity(), 0.5 - 1.0 / PI, 1e-14);
}

/// Types B and A measure their own solid angle: a constant lights a hemisphere (c/2), a
/// quarter (c/4), or, for one B plane held over H ∈ [−90, 90], the hemisphere ez ≤ 0.
#[test]
fn constant_type_a_and_b_profiles() {
    let c = 5.0;
    let full = [-90.0, 0.0, 90.0];
    let m = |kind, h: &[f64], v: &[f64]| {
        Ies::from_fn(kind, h, v, |_, _| c)
            .profile()
            .mean_intensity()
    };
    assert_close(m(2, &full, &full), c / 2.0, 1e-15); // B: ez ≤ 0
    assert_close(m(2, &[0.0, 45.0, 90.0], &[0.0, 90.0]), c / 2.0, 1e-15); // B mirrored twice
    assert_close(m(3, &[0.0, 90.0], &full), c / 2.0, 1e-15); // A mirrored: ex ≥ 0
    assert_close(
        m(3, &[-90.0, -30.0], &[-90.0, 90.0]),
        c / 2.0 * (60.0 / 180.0),
        1e-14,
    );
    assert_close(
        m(3, &[-90.0, -10.0], &[-90.0, 90.0]),
        c / 2.0 * (80.0 / 180.0),
        1e-14,
    );
    assert_close(m(2, &[0.0], &full), c / 2.0, 1e-15); // one B plane over all H
    assert_close(m(3, &[10.0], &full), c / 2.0, 1e-15); // one A plane over H ∈ [−90, 90]
    // A, H ∈ [−90, 0] as given and V ∈ [−90, 90]: the quarter ex ≥ 0, ey ≥ 0.
    assert_close(m(3, &[-90.0, 0.0], &full), c / 4.0, 1e-15);
}

/// Gauss–Legendre nodes and weights on [−1, 1], 5 points.
const GL5: [(f64, f64); 5] = [
    (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
    (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.0, 0.568_888_888_888_888_9),
    (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.906_179_845_938_664, 0.236_926_885_056_189_1),
];

/// `(1/4π)∫ ies_factor dω` by composite 5-point Gauss–Legendre on 2.5° panels in the type's own
/// coordinates covering the whole sphere once (C: V ∈ [0, 180], H ∈ [0, 360], dω = sin V;
/// B: H ∈ [−90, 90], V ∈ [−180, 180], dω = cos H; A: V ∈ [−90, 90], H ∈ [−180, 180],
/// dω = cos V), directions from §6 I2's inverse maps. Every test grid (and its fold images) lies
/// on the 2.5° lattice, so each panel's integrand is smooth and the rule converges to ~1e-13.
fn quadrature(p: &luxeval::IesProfile, kind: u8) -> f64 {
    let (xr, yr): ((f64, f64), (f64, f64)) = match kind {
        1 => ((0.0, 180.0), (0.0, 360.0)),
        2 => ((-90.0, 90.0), (-180.0, 180.0)),
        _ => ((-90.0, 90.0), (-180.0, 180.0)),
    };
    let step = 2.5;
    let (nx, ny) = (
        ((xr.1 - xr.0) / step) as usize,
        ((yr.1 - yr.0) / step) as usize,
    );
    let half = step.to_radians() / 2.0;
    let mut sum = 0.0;
    for a in 0..nx {
        let xc = xr.0 + (a as f64 + 0.5) * step;
        for &(gx, wx) in &GL5 {
            let x = xc + gx * step / 2.0;
            let weight = if kind == 1 {
                x.to_radians().sin()
            } else {
                x.to_radians().cos()
            };
            for b in 0..ny {
                let yc = yr.0 + (b as f64 + 0.5) * step;
                for &(gy, wy) in &GL5 {
                    let y = yc + gy * step / 2.0;
                    let e = match kind {
                        1 => dir_c(y, x),
                        2 => dir_b(x, y),
                        _ => dir_a(y, x),
                    };
                    sum += wx * wy * half * half * weight * ies_factor(p, e, 0.0);
                }
            }
        }
    }
    sum / (4.0 * PI)
}

/// Values that vary from node to node (1..41), so every cell's corners differ.
fn bumpy(h: f64, v: f64) -> f64 {
    let k = ((h * 7.0 + v * 13.0).abs() / 2.5).round() as i64;
    1.0 + (k.rem_euclid(11) as f64) * 4.0
}

#[test]
fn exact_mean_matches_quadrature_for_every_type_and_symmetry() {
    let v180 = [0.0, 2.5, 10.0, 45.0, 90.0, 92.5, 135.0, 180.0];
    let cases: Vec<(&str, u8, Vec<f64>, Vec<f64>)> = vec![
        ("C single", 1, vec![0.0], v180.to_vec()),
        (
            "C 0-90",
            1,
            vec![0.0, 15.0, 22.5, 90.0],
            vec![0.0, 30.0, 60.0, 90.0],
        ),
        (
            "C 0-180",
            1,
            vec![0.0, 45.0, 100.0, 180.0],
            vec![90.0, 120.0, 180.0],
        ),
        (
            "C 90-270",
            1,
            vec![90.0, 135.0, 250.0, 270.0],
            v180.to_vec(),
        ),
        (
            "C 0-360",
            1,
            vec![0.0, 45.0, 120.0, 250.0, 360.0],
            v180.to_vec(),
        ),
        (
            "C 0-300 wrap",
            1,
            vec![0.0, 40.0, 200.0, 300.0],
            vec![20.0, 50.0, 130.0],
        ),
        (
            "C 0-50 / partial",
            1,
            vec![0.0, 90.0, 180.0, 270.0, 360.0],
            vec![0.0, 25.0, 50.0],
        ),
        ("C 130-180", 1, vec![0.0, 180.0], vec![130.0, 150.0, 180.0]),
        (
            "B as given",
            2,
            vec![-90.0, -20.0, 35.0, 90.0],
            vec![-90.0, -30.0, 0.0, 60.0, 90.0],
        ),
        (
            "B mirrored",
            2,
            vec![0.0, 25.0, 60.0],
            vec![0.0, 45.0, 90.0],
        ),
        ("B one plane", 2, vec![0.0], vec![-70.0, 0.0, 50.0]),
        (
            "A as given",
            3,
            vec![-90.0, 0.0, 45.0],
            vec![-60.0, -10.0, 30.0, 90.0],
        ),
        (
            "A mirrored",
            3,
            vec![0.0, 30.0, 90.0],
            vec![0.0, 20.0, 90.0],
        ),
        ("A one plane", 3, vec![20.0], vec![-90.0, 15.0, 80.0]),
    ];
    for (name, kind, h, v) in cases {
        let p = Ies::from_fn(kind, &h, &v, bumpy).profile();
        let exact = p.mean_intensity();
        let numeric = quadrature(&p, kind);
        let rel = (exact - numeric).abs() / numeric;
        println!("{name}: rel {rel:e}");
        assert!(
            rel <= 1e-6,
            "{name}: exact {exact} vs quadrature {numeric} (rel {rel:e})"
        );
        assert!(numeric > 0.0, "{name}");
    }
}
