//! The GPU's accurate atan2 (shaders/shared/math.wgsl) against f64, on lavapipe or any adapter:
//! the shaping and distant-cone angles depend on it (WGSL's builtin only promises 4096 ULP).
use crate::common;

use luxeval::testkit::Rng;
use luxeval::{Accumulate, Light, Reference, Shaping, TemperatureMode};

/// θoff is observable through a soft cone over the whole angle range: with softness 1 and a
/// 180° cone, emission = 1 − smoothstep(θ/π), so θ can be recovered from the GPU result.
#[test]
fn accurate_off_axis_angle_over_the_whole_range() {
    let Some(gpu) = common::gpu() else { return };
    let light = Light::sphere(1.0).with_shaping(Shaping {
        cone_angle: 180.0,
        cone_softness: 1.0,
        ..Shaping::default()
    });
    let p = Reference::new(&light, TemperatureMode::Spec).unwrap();
    let mut rng = Rng::new(3);
    let dirs: Vec<[f32; 3]> = (0..20000)
        .map(|_| rng.unit().as_vec3().to_array())
        .collect();
    let got = gpu.emission(&[light], &dirs, Accumulate::Sum).unwrap();
    let mut worst = 0f64;
    for (d, g) in dirs.iter().zip(&got) {
        let e = glam::Vec3::from_array(*d).as_dvec3().normalize();
        let theta = e.cross(p.axis()).length().atan2(e.dot(p.axis()));
        // Invert f = 1 − s²(3 − 2s), s = θ/π, where it is well conditioned (f in [0.05, 0.95]).
        let f = g[0] as f64;
        if !(0.05..=0.95).contains(&f) {
            continue;
        }
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        for _ in 0..60 {
            let s = 0.5 * (lo + hi);
            if 1.0 - s * s * (3.0 - 2.0 * s) > f {
                lo = s
            } else {
                hi = s
            }
        }
        worst = worst.max((0.5 * (lo + hi) * std::f64::consts::PI - theta).abs());
    }
    println!("largest |θ_gpu − θ_f64| = {worst:e} rad");
    // f32 resolution of θ ≤ π is 2.4e-7; the result's own rounding adds ~1e-7 through f.
    assert!(worst < 1e-6, "{worst}");
}
