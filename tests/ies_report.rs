//! Report numbers: peak, beam and field angles (profile.rs documents the definition), rated
//! lumens against the integrated flux.
use crate::ies_common;

use std::f64::consts::PI;

use ies_common::*;
use luxeval::{IesPlane as Plane, IesProfile as Profile, IesSpread as Spread};

fn spread(p: &Profile, plane: Plane) -> Spread {
    p.spread(plane, &|e| p.candela(e, 0.0))
}

#[test]
fn peak_is_the_largest_node() {
    let p = Ies::new(
        1,
        &[0.0, 30.0, 90.0],
        &[0.0, 10.0, 90.0],
        &[5.0, 6.0, 1.0, 5.0, 9.0, 1.0, 5.0, 9.0, 0.0],
    )
    .profile();
    let peak = p.peak();
    assert_eq!((peak.candela, peak.h, peak.v), (9.0, 30.0, 10.0));
}

/// Rotational, I(V) = 100(1 − V/60) up to 60°, then 0: 50 % at V = 30, 10 % at V = 54, on both
/// sides of nadir: beam 60°, field 108°, in both planes.
#[test]
fn beam_and_field_of_a_rotational_cone() {
    let p = Ies::new(1, &[0.0], &[0.0, 60.0, 180.0], &[100.0, 0.0, 0.0]).profile();
    for plane in [Plane::C0C180, Plane::C90C270] {
        let s = spread(&p, plane);
        assert_eq!(s.max_candela, 100.0);
        assert_close(s.beam.unwrap(), 60.0, 1e-9);
        assert_close(s.field.unwrap(), 108.0, 1e-9);
    }
}

/// Different slopes per C-plane: C0 reaches 0 at 40°, C90 at 60°, C180 at 80°, C270 at 20°.
/// C0–C180: 50 % at +20 and −40 → 60°; 10 % at +36 and −72 → 108°.
/// C90–C270: 50 % at +30 and −10 → 40°; 10 % at +54 and −18 → 72°.
#[test]
fn beam_and_field_per_plane() {
    let ends = [40.0, 60.0, 80.0, 20.0];
    let v: Vec<f64> = vec![0.0, 20.0, 40.0, 60.0, 80.0, 180.0];
    let values: Vec<f64> = ends
        .iter()
        .flat_map(|&end| v.iter().map(move |&x| (100.0 * (1.0 - x / end)).max(0.0)))
        .collect();
    let p = Ies::new(1, &[0.0, 90.0, 180.0, 270.0], &v, &values).profile();
    let a = spread(&p, Plane::C0C180);
    assert_close(a.beam.unwrap(), 60.0, 1e-9);
    assert_close(a.field.unwrap(), 108.0, 1e-9);
    let b = spread(&p, Plane::C90C270);
    assert_close(b.beam.unwrap(), 40.0, 1e-9);
    assert_close(b.field.unwrap(), 72.0, 1e-9);
}

/// An intensity that never falls below 10 % has no field angle; a dark profile has neither.
#[test]
fn spread_without_crossings() {
    let p = Ies::new(1, &[0.0], &[0.0, 180.0], &[100.0, 20.0]).profile();
    let s = spread(&p, Plane::C0C180);
    // 50 % where 100 − 80·V/180 = 50, V = 112.5: beam 225°; 10 % (I = 10) is never reached.
    assert_close(s.beam.unwrap(), 225.0, 1e-9);
    assert_eq!(s.field, None);
    let dark = Ies::new(1, &[0.0], &[0.0, 180.0], &[0.0, 0.0]).profile();
    assert_eq!(
        spread(&dark, Plane::C0C180),
        Spread {
            max_candela: 0.0,
            beam: None,
            field: None
        }
    );
}

/// Rated lumens (2 lamps × 1000 lm) against the integrated flux of a constant 100 cd: 400π lm;
/// absolute photometry (−1) has no rated lumens.
#[test]
fn rated_lumens_against_integrated_flux() {
    let mut f = Ies::new(1, &[0.0], &[0.0, 180.0], &[100.0, 100.0]);
    f.lumens = 1000.0;
    let text = f.text().replacen("\r\n1 1000 ", "\r\n2 1000 ", 1);
    let file = parse(&text);
    assert_eq!(file.rated_lumens(), Some(2000.0));
    let p = Profile::new(&file).unwrap();
    assert_close(p.flux_lm(), 400.0 * PI, 1e-15);
    let check = p.flux_check(&file);
    assert_eq!(check.rated_lm, Some(2000.0));
    assert_close(check.ratio.unwrap(), 400.0 * PI / 2000.0, 1e-15);
    let absolute = Ies::new(1, &[0.0], &[0.0, 180.0], &[1.0, 1.0]).file();
    assert_eq!(absolute.rated_lumens(), None);
    assert_eq!(
        Profile::new(&absolute).unwrap().flux_check(&absolute).ratio,
        None
    );
}

/// ies:normalize divides by the mean; a dark profile's factor is 0, not a division by 0 (§6 I6).
#[test]
fn inverse_mean() {
    let p = Ies::new(1, &[0.0], &[0.0, 90.0], &[4.0, 4.0]).profile();
    assert_close(p.inverse_mean(), 0.5, 1e-15); // mean c/2 = 2
    let dark = Ies::new(1, &[0.0], &[0.0, 90.0], &[0.0, 0.0]).profile();
    assert_eq!(dark.inverse_mean(), 0.0);
}
