//! The six luxtest profiles (reference/luxtest.md §6 A9; files copied byte-exact from
//! pmolodo/luxtest, CC-BY-4.0, CRLF line ends).
use crate::ies_common;

use glam::DVec3;
use ies_common::*;
use luxeval::IesProfile as Profile;
use luxeval::testkit::ies_parts::ies_factor;

fn load(name: &str) -> Profile {
    let path = format!("{}/tests/data/luxtest/{name}", env!("CARGO_MANIFEST_DIR"));
    let file = luxeval::read_ies(std::path::Path::new(&path)).unwrap_or_else(|e| panic!("{e}"));
    Profile::new(&file).unwrap()
}

/// Emission direction at polar angle θ from nadir (light −Z) and azimuth φ (degrees).
fn at(p: &Profile, theta: f64, phi: f64) -> f64 {
    ies_factor(p, dir_c(phi, theta), 0.0)
}

#[test]
fn files_are_the_crlf_originals() {
    let bytes = std::fs::read(format!(
        "{}/tests/data/luxtest/test_linear_vertical.ies",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    assert_eq!(bytes.len(), 329);
    assert!(bytes.windows(2).any(|w| w == b"\r\n"));
}

/// A9(a): the uniform (1° grid) and non-uniform stripes are the same interpolant.
#[test]
fn uniform_and_nonuniform_stripes_agree() {
    let u = load("test_stripes_uniform.ies");
    let n = load("test_stripes_nonuniform.ies");
    assert_eq!((u.v.len(), n.v.len()), (181, 36));
    for k in 0..=18000 {
        let theta = k as f64 * 0.01;
        for phi in [0.0, 77.0, 200.0] {
            let (a, b) = (at(&u, theta, phi), at(&n, theta, phi));
            assert!((a - b).abs() <= 1e-12, "θ = {theta}: {a} vs {b}");
        }
    }
    // Bands: white 10–19, black 20–29, ... (hand values from the file's description).
    assert_close(at(&n, 15.0, 0.0), 1.0, 1e-12);
    assert_eq!(at(&n, 25.0, 0.0), 0.0);
    assert_close(at(&n, 9.5, 0.0), 0.25 + 0.5 * 0.75, 1e-12); // between the cap and a white band
}

/// A9(b): linear vertical, `I(θ) = 1 − θ/180`, exact for a linear table; mean 0.5 (§6 I6).
#[test]
fn linear_vertical_values_and_mean() {
    let p = load("test_linear_vertical.ies");
    // Directions whose θ is exact in f64: nadir, ±45° diagonals, the horizon, zenith.
    let r = std::f64::consts::FRAC_1_SQRT_2;
    let dirs = [
        (DVec3::NEG_Z, 1.0),
        (DVec3::new(r, 0.0, -r), 0.75),
        (DVec3::X, 0.5),
        (DVec3::new(r, 0.0, r), 0.25),
        (DVec3::Z, 0.0),
    ];
    for (e, want) in dirs {
        assert_eq!(ies_factor(&p, e, 0.0), want, "{e}");
    }
    for (theta, want) in [
        (0.0, 1.0),
        (45.0, 0.75),
        (90.0, 0.5),
        (135.0, 0.25),
        (180.0, 0.0),
    ] {
        assert_close(at(&p, theta, 123.0), want, 1e-14);
    }
    assert_close(p.mean_intensity(), 0.5, 1e-15);
    // Normalised peak 2 (§6 I6; hdEmbree's patch sum would give π/4 instead of 0.5).
    assert_close(
        ies_factor(&p, DVec3::NEG_Z, 0.0) / p.mean_intensity(),
        2.0,
        1e-15,
    );
}

/// A9(c): aimDown lights only 0–50°, aimUp only 130–180° (0 beyond the table, §6 I3).
#[test]
fn aim_down_and_aim_up_are_dark_outside_their_range() {
    let down = load("test_vstripes_hquadrants_nonuniform_aimDown.ies");
    let up = load("test_vstripes_hquadrants_nonuniform_aimUp.ies");
    let mut lit = (0, 0);
    for k in 0..=3600 {
        let theta = k as f64 * 0.05;
        for phi in [10.0, 100.0, 190.0, 280.0] {
            let (d, u) = (at(&down, theta, phi), at(&up, theta, phi));
            if theta > 50.0 {
                assert_eq!(d, 0.0, "aimDown θ = {theta}");
            }
            if theta < 130.0 {
                assert_eq!(u, 0.0, "aimUp θ = {theta}");
            }
            lit.0 += (d > 0.0) as usize;
            lit.1 += (u > 0.0) as usize;
        }
    }
    assert!(lit.0 > 100 && lit.1 > 100, "{lit:?}");
    // Both hold 20 vertical angles, 9 horizontal (0..360 with both ends).
    assert_eq!(
        (down.v[0], down.v[19], up.v[0], up.v[19]),
        (0.0, 50.0, 130.0, 180.0)
    );
}

/// A9(d): the 0.25 cap is at nadir (θ = 0 is light −Z) and the 0.75 cap at zenith.
#[test]
fn caps_sit_at_nadir_and_zenith() {
    for name in [
        "test_stripes_uniform.ies",
        "test_stripes_nonuniform.ies",
        "test_vstripes_hquadrants_nonuniform.ies",
    ] {
        let p = load(name);
        assert_eq!(ies_factor(&p, DVec3::NEG_Z, 0.0), 0.25, "{name}");
        assert_eq!(ies_factor(&p, DVec3::Z, 0.0), 0.75, "{name}");
        assert_close(at(&p, 5.0, 300.0), 0.25, 1e-12);
        assert_close(at(&p, 175.0, 300.0), 0.75, 1e-12);
    }
}

/// The horizontal quadrants (file description): band 10–19 white for H 0–179, black (0 / .25)
/// for 180–359; band 20–29 black 0 in H 0–89, .25 in 90–179. C0 = +X, C90 = +Y.
#[test]
fn horizontal_quadrants_are_oriented() {
    let p = load("test_vstripes_hquadrants_nonuniform.ies");
    for (phi, want) in [(45.0, 1.0), (135.0, 1.0), (225.0, 0.0), (315.0, 0.25)] {
        assert_close(at(&p, 15.0, phi), want, 1e-12);
    }
    for (phi, want) in [(45.0, 0.0), (135.0, 0.25)] {
        assert_close(at(&p, 25.0, phi), want, 1e-12);
    }
    // Quadrant H 90–179 lies toward +Y and −X: e = (−1, 1, −1)/√3 has φ = 135° and
    // θ = acos(1/√3) = 54.7°, in band 50–59, white there (as 10–19); (−1, −1, −1)/√3 has
    // φ = 225°, where band 50–59 is black 0.
    assert_close(
        ies_factor(&p, DVec3::new(-1.0, 1.0, -1.0).normalize(), 0.0),
        1.0,
        1e-12,
    );
    assert_eq!(
        ies_factor(&p, DVec3::new(-1.0, -1.0, -1.0).normalize(), 0.0),
        0.0
    );
}
