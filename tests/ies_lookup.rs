//! The f64 lookup against hand values (DESIGN.md §6 I2–I4). Profiles linear in (H, V) are
//! reproduced exactly by bilinear interpolation on any grid, so `I(H, V)` is known in closed form
//! wherever the direction lands; a transposed or mirrored frame gives a different number.
use crate::ies_common;

use glam::DVec3;
use ies_common::*;
use luxeval::testkit::ies_parts::ies_factor;

const C_LINEAR: fn(f64, f64) -> f64 = |h, v| 100.0 + h + v;

#[track_caller]
fn check(p: &luxeval::IesProfile, e: DVec3, want: f64) {
    let got = ies_factor(p, e.normalize(), 0.0);
    assert!(
        (got - want).abs() <= 1e-9 * want.abs().max(1.0),
        "e = {e}: got {got}, want {want}"
    );
}

/// Type C without symmetry: C0 = +X, C90 = +Y, nadir = −Z (§2, §6 I2).
#[test]
fn type_c_full_circle_frame() {
    let p = Ies::from_fn(
        1,
        &[0.0, 30.0, 90.0, 200.0, 360.0],
        &[0.0, 20.0, 90.0, 180.0],
        C_LINEAR,
    )
    .profile();
    check(&p, DVec3::NEG_Z, 100.0); // nadir: V = 0, H = atan2(0, 0) = 0
    check(&p, DVec3::new(1.0, 0.0, -1.0), 145.0); // toward +X, 45° from nadir: H 0, V 45
    check(&p, DVec3::new(0.0, 1.0, -1.0), 235.0); // +Y: H 90
    check(&p, DVec3::new(0.0, -1.0, 1.0), 100.0 + 270.0 + 135.0); // −Y, above the horizon
    check(&p, DVec3::new(-1.0, 0.0, 0.0), 100.0 + 180.0 + 90.0);
    for (h, v) in [(10.0, 5.0), (250.0, 100.0), (359.0, 179.0), (123.4, 56.7)] {
        check(&p, dir_c(h, v), 100.0 + h + v);
    }
}

/// `0..h_L`, h_L < 360: the span (h_L, 360) interpolates back to the 0 column (§6 I3).
#[test]
fn type_c_partial_circle_wraps_to_c0() {
    let p = Ies::from_fn(1, &[0.0, 90.0, 180.0, 270.0], &[0.0, 180.0], |h, _| {
        10.0 + h / 9.0
    })
    .profile();
    // Columns 10, 20, 30, 40.
    check(&p, dir_c(315.0, 60.0), 25.0);
    check(&p, dir_c(300.0, 60.0), 30.0); // 40 + (10 − 40)/3
    check(&p, dir_c(45.0, 60.0), 15.0);
}

#[test]
fn type_c_quadrant_half_and_c90_folds() {
    let v = [0.0, 90.0, 180.0];
    let q = Ies::from_fn(1, &[0.0, 30.0, 90.0], &v, C_LINEAR).profile();
    for (h, folded) in [
        (200.0, 20.0),
        (120.0, 60.0),
        (300.0, 60.0),
        (270.0, 90.0),
        (181.0, 1.0),
    ] {
        check(&q, dir_c(h, 40.0), 140.0 + folded);
    }
    let half = Ies::from_fn(1, &[0.0, 90.0, 180.0], &v, C_LINEAR).profile();
    for (h, folded) in [(300.0, 60.0), (181.0, 179.0), (90.0, 90.0), (359.0, 1.0)] {
        check(&half, dir_c(h, 40.0), 140.0 + folded);
    }
    // 90..270: symmetric about the 90–270 plane (LM-63), not "subtract 90" (Cycles).
    let c90 = Ies::from_fn(1, &[90.0, 180.0, 270.0], &v, C_LINEAR).profile();
    for (h, folded) in [(30.0, 150.0), (300.0, 240.0), (0.0, 180.0), (200.0, 200.0)] {
        check(&c90, dir_c(h, 40.0), 140.0 + folded);
    }
}

/// One horizontal angle (any value): rotationally symmetric.
#[test]
fn type_c_single_angle_is_rotational() {
    let p = Ies::from_fn(1, &[45.0], &[0.0, 90.0, 180.0], |_, v| 10.0 + v).profile();
    for h in [0.0, 45.0, 100.0, 271.0] {
        check(&p, dir_c(h, 33.0), 43.0);
    }
}

/// Vertical ranges 0–90, 90–180 and partial: outside → 0, ends inclusive.
#[test]
fn type_c_vertical_ranges() {
    let down = Ies::from_fn(1, &[0.0], &[0.0, 90.0], |_, v| 10.0 + v).profile();
    check(&down, dir_c(0.0, 90.0), 100.0);
    check(&down, dir_c(0.0, 90.001), 0.0);
    let up = Ies::from_fn(1, &[0.0], &[90.0, 180.0], |_, v| v).profile();
    check(&up, dir_c(10.0, 89.999), 0.0);
    check(&up, dir_c(10.0, 135.0), 135.0);
    check(&up, DVec3::Z, 180.0);
    let band = Ies::from_fn(1, &[0.0, 90.0], &[20.0, 60.0], |_, v| v).profile();
    check(&band, dir_c(30.0, 10.0), 0.0);
    check(&band, dir_c(30.0, 40.0), 40.0);
    check(&band, dir_c(30.0, 61.0), 0.0);
}

/// Type B: V = rotation about the light's Y axis (toward +X), H = elevation toward −Y
/// (§6 I2; Radiance's srcB mapping, not Cycles' transpose).
#[test]
fn type_b_frame_and_values() {
    let f = |h: f64, v: f64| 400.0 + h + 2.0 * v;
    let p = Ies::from_fn(
        2,
        &[-90.0, -30.0, 0.0, 40.0, 90.0],
        &[-90.0, -45.0, 0.0, 10.0, 90.0],
        f,
    )
    .profile();
    check(&p, DVec3::NEG_Z, 400.0);
    let (s, c) = 20f64.to_radians().sin_cos();
    check(&p, DVec3::new(s, 0.0, -c), 440.0); // toward +X: V = 20, H = 0
    let (s, c) = 30f64.to_radians().sin_cos();
    check(&p, DVec3::new(0.0, -s, -c), 430.0); // toward −Y: H = 30, V = 0 (a transpose gives 460)
    check(&p, DVec3::new(0.0, 1.0, 0.0), f(-90.0, 0.0));
    check(&p, DVec3::new(1.0, 0.0, 0.0), f(0.0, 90.0));
    check(&p, DVec3::new(0.0, 0.0, 1.0), 0.0); // ez > 0: |V| > 90, outside
    check(&p, DVec3::new(1.0, 0.0, 0.01), 0.0);
    for (h, v) in [(30.0, 20.0), (-60.0, -80.0), (89.0, 89.0), (-5.0, 45.0)] {
        check(&p, dir_b(h, v), f(h, v));
    }
}

/// A/B axes whose first angle is 0 are mirrored (§6 I3).
#[test]
fn type_b_mirrored_axes() {
    let f = |h: f64, v: f64| 400.0 + h + 2.0 * v;
    let p = Ies::from_fn(2, &[0.0, 30.0, 90.0], &[0.0, 45.0, 90.0], f).profile();
    check(&p, dir_b(-30.0, -45.0), f(30.0, 45.0));
    check(&p, dir_b(10.0, -80.0), f(10.0, 80.0));
    // Not mirrored when the first angle is not 0: the other half is dark.
    let half = Ies::from_fn(2, &[10.0, 90.0], &[-90.0, 90.0], f).profile();
    check(&half, dir_b(-30.0, 0.0), 0.0);
    check(&half, dir_b(30.0, 0.0), f(30.0, 0.0));
}

/// Type A: type C with V_A = θ − 90 and H_A = −φ; (0, 0) points along +X (§6 I2).
#[test]
fn type_a_frame_and_values() {
    let f = |h: f64, v: f64| 400.0 + h + 2.0 * v;
    let p = Ies::from_fn(3, &[-90.0, 0.0, 90.0], &[-90.0, 0.0, 45.0, 90.0], f).profile();
    check(&p, DVec3::X, 400.0);
    check(&p, DVec3::NEG_Y, f(90.0, 0.0)); // H = atan2(1, 0)
    check(&p, DVec3::Y, f(-90.0, 0.0));
    check(&p, DVec3::NEG_Z, f(0.0, -90.0)); // nadir: V = −90
    check(&p, DVec3::Z, f(0.0, 90.0));
    check(&p, DVec3::NEG_X, 0.0); // |H| = 180
    check(&p, DVec3::new(-1.0, 0.2, 0.1), 0.0);
    for (h, v) in [(30.0, 20.0), (-60.0, -80.0), (89.0, 60.0)] {
        check(&p, dir_a(h, v), f(h, v));
    }
}

/// A Type A file like a headlamp's (0..90 lateral, mirrored; −90..90 vertical): the kind of
/// file OpenUSD's pxrIES never finishes reading (its Type A loop counts a size_t down past 0,
/// reference/openusd-reference.md §3.3). Here it parses and evaluates.
#[test]
fn type_a_file_that_hangs_openusd_parses_and_evaluates() {
    let text = "IESNA:LM-63-2002\r\n[TEST] headlamp\r\nTILT=NONE\r\n\
        1 -1 1 5 3 3 2 0 0 0\r\n1 1 0\r\n-90 -45 0 45 90\r\n0 45 90\r\n\
        0 500 1000 500 0\r\n0 250 500 250 0\r\n0 100 200 100 0\r\n";
    let file = parse(text);
    assert_eq!(file.photometric_type, luxeval::PhotometricType::A);
    let p = luxeval::IesProfile::new(&file).unwrap();
    check(&p, DVec3::X, 1000.0); // beam axis along +X
    check(&p, dir_a(-45.0, 0.0), 500.0); // mirrored lateral
    check(
        &p,
        dir_a(22.5, 22.5),
        0.5 * (0.5 * (1000.0 + 500.0) + 0.5 * (500.0 + 250.0)),
    );
    check(&p, DVec3::NEG_X, 0.0);
    check(&p, DVec3::Z, 0.0); // V = 90 row is 0
    check(&p, dir_a(90.0, 0.0), 200.0);
}

/// A/B with a single horizontal angle: the plane holds for every H in [−90, 90] (pinned).
#[test]
fn type_a_b_single_horizontal_angle() {
    let b = Ies::from_fn(2, &[0.0], &[-90.0, 90.0], |_, v| 100.0 + v).profile();
    check(&b, dir_b(70.0, 30.0), 130.0);
    check(&b, dir_b(-89.0, -30.0), 70.0);
    let a = Ies::from_fn(3, &[0.0], &[-90.0, 90.0], |_, v| 100.0 + v).profile();
    check(&a, dir_a(80.0, 10.0), 110.0);
    check(&a, dir_a(95.0, 10.0), 0.0);
}

/// §6 I4: angleScale on θ (s > 0: θ/s, s < 0: (θ − 180)/(−s) + 180; outside [0, 180] → 0).
#[test]
fn angle_scale_type_c() {
    let p = Ies::from_fn(1, &[0.0], &[0.0, 180.0], |_, v| 10.0 + v).profile();
    let at = |theta: f64, s: f64| ies_factor(&p, dir_c(40.0, theta), s);
    assert_close(at(30.0, 0.5), 70.0, 1e-12);
    assert_close(at(120.0, 2.0), 70.0, 1e-12);
    assert_close(at(150.0, -2.0), 175.0, 1e-12);
    assert_close(at(30.0, 1.0), 40.0, 1e-12);
    assert_close(at(30.0, -1.0), 40.0, 1e-12);
    assert_eq!(at(100.0, 0.5), 0.0); // θ' = 200
    assert_eq!(at(30.0, -0.5), 0.0); // θ' = −120
}

/// For B and A, angleScale acts on θ of e and the I2 table reads e' (§6 I4).
#[test]
fn angle_scale_types_b_and_a() {
    let f = |h: f64, v: f64| 400.0 + h + 2.0 * v;
    let grid = [-90.0, -45.0, 0.0, 45.0, 90.0];
    let b = Ies::from_fn(2, &grid, &grid, f).profile();
    // θ = 30 toward +X, s = 0.5 → θ' = 60 toward +X: type B V = 60, H = 0.
    assert_close(ies_factor(&b, dir_c(0.0, 30.0), 0.5), f(0.0, 60.0), 1e-12);
    let a = Ies::from_fn(3, &grid, &grid, f).profile();
    // θ = 30 toward +Y, s = 0.5 → e' = (0, sin 60°, −cos 60°): V_A = −30, H_A = −90.
    assert_close(
        ies_factor(&a, dir_c(90.0, 30.0), 0.5),
        f(-90.0, -30.0),
        1e-12,
    );
    assert_eq!(ies_factor(&a, dir_c(90.0, 100.0), 0.5), 0.0);
}
