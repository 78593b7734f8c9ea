//! Texture files on arbitrary bytes, through the public API: a dome whose `texture:file` is the
//! input (format `automatic`, then latlong, both filters) prepared by the CPU reference, and the
//! emission looked up along a few directions. Invariants beyond "no panic, no hang, bounded
//! memory": a texture that loads gives finite, non-negative emission (texels are sanitised).
#![no_main]

use glam::DVec3;
use luxeval::{Asset, Light, Reference, TemperatureMode, Texture, TextureFilter, TextureFormat};

const DIRS: [[f64; 3]; 7] = [
    [0.0, 0.0, -1.0],
    [0.0, 0.0, 1.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.3, -0.4, -0.866],
    [-0.6, 0.48, 0.64],
];

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let file = Asset::from_bytes("fuzz.tex", data.to_vec());
    for (format, filter) in [
        (TextureFormat::Automatic, TextureFilter::Bilinear),
        (TextureFormat::LatLong, TextureFilter::Nearest),
    ] {
        let light = Light::dome().with_path("/Fuzz").with_texture(
            Texture::new(file.clone())
                .with_format(format)
                .with_filter(filter),
        );
        let Ok(r) = Reference::new(&light, TemperatureMode::Spec) else {
            continue;
        };
        for d in DIRS {
            let e = r.emission(DVec3::from_array(d).normalize());
            assert!(
                e.is_finite() && e.min_element() >= 0.0,
                "emission {e} along {d:?}"
            );
        }
    }
});
