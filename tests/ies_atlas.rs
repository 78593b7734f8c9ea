//! The packed f32 atlas and the CPU replay of ies.wgsl's reader against the f64 lookup.
use crate::ies_common;

use glam::{DVec3, Vec3};
use ies_common::*;
use luxeval::testkit::ies_parts::ies_factor;
use luxeval::testkit::ies_parts::lookup::{fold_h_type_c, fold_mirror, photometric_angles};
use luxeval::testkit::ies_replay::{AtlasError, HEADER_LEN, pack_atlas, replay_ies_factor};
use luxeval::{IesHFold as HFold, IesVFold as VFold};
use luxeval::{IesProfile as Profile, PhotometricType};

/// The layout of atlas.rs, checked field by field on two small profiles.
#[test]
fn layout_of_two_profiles() {
    let a = Ies::new(
        1,
        &[0.0, 90.0],
        &[0.0, 45.0, 90.0],
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0],
    )
    .profile();
    let mut b = Ies::new(2, &[0.0, 30.0], &[-90.0, 90.0], &[7.0, 8.0, 9.0, 10.0]);
    b.m = 2.0;
    let b = b.profile();
    let atlas = pack_atlas(&[&a, &b]).unwrap();
    // a: header 8, h 2, v 3, candela 6 = 19 floats; b starts at 19.
    assert_eq!(atlas.bases, vec![0, 19]);
    assert_eq!(
        &atlas.data[..8],
        &[1.0, 3.0, 0.0, 2.0, 3.0, 8.0, 10.0, 13.0]
    ); // C, quadrant
    assert_eq!(
        &atlas.data[8..19],
        &[0.0, 90.0, 0.0, 45.0, 90.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0]
    );
    assert_eq!(
        &atlas.data[19..27],
        &[2.0, 1.0, 0.0, 2.0, 2.0, 27.0, 29.0, 31.0]
    ); // B, mirror
    assert_eq!(
        &atlas.data[27..35],
        &[0.0, 30.0, -90.0, 90.0, 14.0, 16.0, 18.0, 20.0]
    );
    assert_eq!(atlas.data.len(), 35);
    assert_eq!(HEADER_LEN, 8);
    assert_eq!(pack_atlas(&[]).unwrap().data, vec![0.0]);
}

#[test]
fn values_beyond_f32_are_refused() {
    let mut p = Ies::new(1, &[0.0], &[0.0, 90.0], &[1.0, 1.0]).profile();
    p.candela[1] = 1e39;
    assert!(matches!(
        pack_atlas(&[&p]),
        Err(AtlasError::NotF32 { profile: 0, .. })
    ));
}

#[test]
fn wgsl_constants_are_generated_from_the_rust_codes() {
    // The prelude of every composed kernel carries them.
    let s = luxeval::testkit::wgsl::compose(
        luxeval::testkit::wgsl::Kernel::Emission,
        luxeval::testkit::wgsl::Features::ALL,
    );
    assert!(s.contains(&format!(
        "const IES_FOLD_FULL: u32 = {}u;",
        HFold::Full.code()
    )));
    assert!(s.contains(&format!(
        "const IES_V_MIRROR: u32 = {}u;",
        VFold::Mirror.code()
    )));
    assert!(s.contains(&format!(
        "const IES_TYPE_A: u32 = {}u;",
        PhotometricType::A.code()
    )));
}

/// A smooth intensity defined on the sphere, so every pole row is consistent (a real file's
/// must be: all planes meet there) and the f32 azimuth error near a pole carries no weight.
fn smooth(e: DVec3) -> f64 {
    let a = e.dot(DVec3::new(0.3, -0.5, 0.8));
    let b = e.dot(DVec3::new(0.6, 0.7, 0.1));
    100.0 + 8.0 * a + 6.0 * b * b
}

fn sampled(kind: u8, h: &[f64], v: &[f64]) -> Profile {
    let to_dir = |hh: f64, vv: f64| match kind {
        1 => dir_c(hh, vv),
        2 => dir_b(hh, vv),
        _ => dir_a(hh, vv),
    };
    Ies::from_fn(kind, h, v, |hh, vv| smooth(to_dir(hh, vv))).profile()
}

/// Folded f64 angles of `e`, to stay away from kinks and range ends.
fn folded(p: &Profile, e: DVec3, s: f64) -> Option<(f64, f64)> {
    let (h, v) = photometric_angles(p.kind, e, s)?;
    Some(if p.kind == PhotometricType::C {
        (fold_h_type_c(h, p.h_fold), v)
    } else {
        (
            fold_mirror(h, p.h_fold == HFold::Mirror),
            fold_mirror(v, p.v_fold == VFold::Mirror),
        )
    })
}

fn near_kink(p: &Profile, e: DVec3, s: f64, delta: f64) -> bool {
    let (_, theta) = luxeval::testkit::ies_parts::lookup::type_c_angles(e);
    let t = luxeval::testkit::ies_parts::lookup::scale_polar_angle(theta, s);
    if t.abs() < delta || (t - 180.0).abs() < delta {
        return true;
    }
    let Some((h, v)) = folded(p, e, s) else {
        return false;
    };
    let near = |nodes: &[f64], x: f64| nodes.iter().any(|&n| (n - x).abs() < delta);
    let h_nodes: Vec<f64> = match p.h_fold {
        HFold::Constant if p.kind == PhotometricType::C => vec![],
        HFold::Constant => vec![-90.0, 90.0], // A/B: the plane ends at |H| = 90
        HFold::Full => p.h.iter().copied().chain([360.0]).collect(),
        _ => p.h.clone(),
    };
    near(&h_nodes, h) || near(&p.v, v)
}

/// xorshift64*: a deterministic stream of uniform directions.
struct Rng(u64);
impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn dir(&mut self) -> DVec3 {
        let z = 2.0 * self.unit() - 1.0;
        let phi = 2.0 * std::f64::consts::PI * self.unit();
        let r = (1.0 - z * z).sqrt();
        DVec3::new(r * phi.cos(), r * phi.sin(), z)
    }
}

const SCALES: [f64; 6] = [0.0, 1.0, 0.5, 1.7, -0.6, -2.0];

/// Replay (f32, the WGSL's arithmetic on the packed atlas) vs `ies_factor` (f64) on the same
/// f32 direction: within 1e-5 relative away from grid kinks and range ends.
#[test]
fn replay_matches_the_f64_lookup() {
    let fine: Vec<f64> = (0..=360).map(|k| k as f64 * 0.5).collect();
    let long: Vec<f64> = (0..1000).map(|k| k as f64 * 0.36).collect();
    let profiles = [
        sampled(1, &[0.0], &[0.0, 2.5, 10.0, 45.0, 90.0, 92.5, 135.0, 180.0]),
        sampled(1, &[0.0, 15.0, 22.5, 90.0], &[0.0, 30.0, 60.0, 90.0]),
        sampled(1, &[0.0, 45.0, 100.0, 180.0], &[90.0, 120.0, 180.0]),
        sampled(1, &[90.0, 135.0, 250.0, 270.0], &[0.0, 60.0, 180.0]),
        sampled(1, &[0.0, 45.0, 120.0, 250.0, 360.0], &fine),
        sampled(1, &long, &[20.0, 50.0, 130.0]),
        sampled(
            2,
            &[-90.0, -20.0, 35.0, 90.0],
            &[-90.0, -30.0, 0.0, 60.0, 90.0],
        ),
        sampled(2, &[0.0, 25.0, 60.0], &[0.0, 45.0, 90.0]),
        sampled(2, &[0.0], &[-70.0, 0.0, 50.0]),
        sampled(3, &[-90.0, 0.0, 45.0], &[-60.0, -10.0, 30.0, 90.0]),
        sampled(3, &[0.0, 30.0, 90.0], &[0.0, 20.0, 90.0]),
        sampled(3, &[20.0], &[-90.0, 15.0, 80.0]),
    ];
    let refs: Vec<&Profile> = profiles.iter().collect();
    let atlas = pack_atlas(&refs).unwrap();
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for (k, p) in profiles.iter().enumerate() {
        let (mut checked, mut worst) = (0, 0f64);
        for _ in 0..20_000 {
            let e32 = rng.dir().as_vec3();
            let e = e32.as_dvec3();
            for s in SCALES {
                let want = ies_factor(p, e, s);
                let got = replay_ies_factor(&atlas.data, atlas.bases[k], e32, s as f32) as f64;
                if near_kink(p, e, s, 1e-3) {
                    continue;
                }
                checked += 1;
                if want == 0.0 {
                    assert_eq!(got, 0.0, "profile {k}, e = {e}, s = {s}");
                    continue;
                }
                let rel = (got - want).abs() / want;
                worst = worst.max(rel);
                assert!(
                    rel <= 1e-5,
                    "profile {k}, e = {e}, s = {s}: {got} vs {want}"
                );
            }
        }
        println!("profile {k}: {checked} samples, worst rel {worst:e}");
        assert!(
            checked > 100_000,
            "profile {k}: only {checked} samples away from kinks"
        );
    }
}

/// The luxtest stripes (0 → 1 over 1° cells): the replay stays within §5's 1e-4 of the peak.
/// (aimDown/aimUp ramp over 0.1° cells, 10 per degree: there the f32 angle and node rounding,
/// ~1e-5°, is ~1e-4 of the jump, ies.wgsl divergence 2; those ramps count as discontinuities.)
#[test]
fn replay_on_luxtest_profiles() {
    let dir = format!("{}/tests/data/luxtest", env!("CARGO_MANIFEST_DIR"));
    let mut rng = Rng(7);
    for name in [
        "test_stripes_uniform.ies",
        "test_vstripes_hquadrants_nonuniform.ies",
    ] {
        let p = Profile::new(
            &luxeval::read_ies(std::path::Path::new(&format!("{dir}/{name}"))).unwrap(),
        )
        .unwrap();
        let atlas = pack_atlas(&[&p]).unwrap();
        for _ in 0..20_000 {
            let e32: Vec3 = rng.dir().as_vec3();
            let want = ies_factor(&p, e32.as_dvec3(), 0.0);
            if near_kink(&p, e32.as_dvec3(), 0.0, 1e-3) {
                continue;
            }
            let got = replay_ies_factor(&atlas.data, 0, e32, 0.0) as f64;
            assert!(
                (got - want).abs() <= 1e-4 * p.peak().candela,
                "{name}: {got} vs {want}"
            );
        }
    }
}
