//! The falloff PNG's option space on arbitrary bytes: map sizes (also very elongated ones),
//! scales, ranges (subnormal, negative, reversed, NaN), contours, plane vectors and pixel values
//! (NaN, infinite, negative, subnormal) through the size check and the renderer `luxeval falloff
//! --png` uses. Invariants beyond "no panic, no hang, bounded memory": a picture that renders
//! has the size it says and lies within the pixel limit.
#![no_main]

use glam::DVec3;
use luxeval::{FalloffMap, FalloffPlane};
use luxeval_cli::plot::falloff::{MAX_PNG_PIXELS, Scale, Style, check_size, render};

/// The most map pixels evaluated here (the size check itself sees any size).
const MAX_RENDERED: u64 = 1 << 14;

struct Bytes<'a>(&'a [u8]);

impl Bytes<'_> {
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let mut out = [0u8; N];
        let n = N.min(self.0.len());
        out[..n].copy_from_slice(&self.0[..n]);
        self.0 = &self.0[n..];
        out
    }
    fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.take())
    }
    fn f64(&mut self) -> f64 {
        f64::from_le_bytes(self.take())
    }
    fn f32(&mut self) -> f32 {
        f32::from_le_bytes(self.take())
    }
}

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let mut b = Bytes(data);
    let (w, h) = (b.u32(), b.u32());
    let flags = b.take::<1>()[0];
    let range = (flags & 4 != 0).then(|| (b.f64(), b.f64()));
    let style = Style {
        scale: if flags & 1 != 0 { Scale::Linear } else { Scale::Log },
        range,
        contours: flags & 2 != 0,
    };
    // Any size through the check alone (no panic, no overflow)...
    let _ = check_size(w, h);
    // ...and rendered sizes through both.
    let (w, h) = (w.clamp(1, 1 << 14), h.clamp(1, 1 << 14));
    let sized = check_size(w, h);
    if u64::from(w) * u64::from(h) > MAX_RENDERED {
        return;
    }
    let v = |b: &mut Bytes| DVec3::new(b.f64(), b.f64(), b.f64());
    let (origin, u, vv) = (v(&mut b), v(&mut b), v(&mut b));
    let plane = FalloffPlane::new(origin, u, vv, w, h).unwrap_or_else(|_| {
        FalloffPlane::new(DVec3::ZERO, DVec3::X, DVec3::Y, w, h).expect("a valid plane")
    });
    let rgb = (0..w as usize * h as usize)
        .map(|_| {
            let x = b.f32();
            [x, x * 0.5, x.abs()]
        })
        .collect();
    let map = FalloffMap { width: w, height: h, rgb };
    if let Ok(r) = render(&map, &plane, &style) {
        assert!(sized.is_ok(), "rendered a picture the size check refuses");
        let c = &r.canvas;
        assert_eq!(c.rgb.len() as u64, 3 * u64::from(c.width) * u64::from(c.height));
        assert!(u64::from(c.width) * u64::from(c.height) <= MAX_PNG_PIXELS);
    }
});
