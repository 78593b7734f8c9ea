//! Domes masked by portals (DESIGN.md §8) on arbitrary bytes: up to four portals whose sizes
//! (zero, negative, non-finite, huge), transforms (mirrors, shears, singular, non-finite) and
//! multipliers come from the bytes, read in mask mode and queried at a few points. The stage
//! side (a dome's `portals` relationship naming anything) is the stage targets' (usda, usdc,
//! usdz), which also read every stage in mask mode.
//! Invariants beyond "no panic, no hang, bounded memory": a dome that prepares gives finite
//! radiance and irradiance (a portal's intensity may be negative, so may they), the radiance no
//! larger in magnitude than the unmasked dome's times the largest multiplier (times 1 for a dome
//! that names no portal, which is unchanged).
#![no_main]

#[path = "bytes.rs"]
mod bytes;

use bytes::Bytes;
use glam::{DMat4, DVec3};
use luxeval::testkit::Rng;
use luxeval::{Light, Portal, PortalMode, Reference, TemperatureMode};

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let mut b = Bytes(data);
    let mut dome = Light::dome()
        .with_path("/Fuzz/Sky")
        .with_intensity(b.value().abs());
    let mut largest: f64 = 0.0;
    for k in 0..b.u8() % 5 {
        let mut cols = [0.0; 16];
        for (i, c) in cols.iter_mut().enumerate() {
            *c = if i % 4 == 3 {
                f64::from(u8::from(i == 15))
            } else {
                b.value()
            };
        }
        let world = if b.u8() % 2 == 0 {
            DMat4::from_cols_array(&cols)
        } else {
            DMat4::from_translation(DVec3::new(cols[12], cols[13], cols[14]))
        };
        let p = Portal::new(b.value(), b.value())
            .with_path(format!("/Fuzz/Portal{k}"))
            .with_transform(world)
            .with_intensity(b.value())
            .with_exposure(b.value());
        largest = largest.max(p.intensity.abs() * p.exposure.exp2());
        dome = dome.with_portal(p);
    }
    let Ok(unmasked) = Reference::new(&dome, TemperatureMode::Spec) else {
        return;
    };
    let Ok(r) = Reference::with_portal_mode(&dome, TemperatureMode::Spec, PortalMode::Mask) else {
        return;
    };
    let mut rng = Rng::new(u64::from(b.u8()));
    for _ in 0..4 {
        let x = rng.unit() * rng.range(0.0, 4.0);
        let w = rng.unit();
        let l = r.radiance(x, w);
        assert!(l.is_finite(), "radiance {l}");
        // A dome that names no portal is unchanged in either mode (P1).
        let bound = unmasked.radiance(x, w).abs()
            * if dome.portals.is_empty() {
                1.0
            } else {
                largest
            };
        assert!(
            (l.abs() - bound).max_element() <= 1e-9 * bound.max_element(),
            "radiance {l} over the dome's {bound}"
        );
        let e = r.irradiance(x, rng.unit());
        assert!(e.is_finite(), "irradiance {e}");
    }
});
