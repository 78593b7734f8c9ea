//! The asset-opening path on arbitrary bytes: the bytes as a `.usdz` package whose members a
//! light names (`pkg.usdz[a.ies]`, a nested `pkg.usdz[b.usdz[c.ies]]`, `pkg.usdz[tex.exr]`),
//! read by the one asset-opening function and the package reader, then parsed as an IES profile
//! or a texture by the CPU reference's preparation. Invariants beyond "no panic, no hang,
//! bounded memory": what prepares gives finite emission.
#![no_main]

use std::io::Write;

use glam::DVec3;
use luxeval::{Asset, Ies, Light, Reference, Shaping, TemperatureMode, Texture};

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let path = std::env::temp_dir().join(format!("luxeval-fuzz-asset-{}.usdz", std::process::id()));
    std::fs::File::create(&path)
        .and_then(|mut f| f.write_all(data))
        .expect("scratch file");
    let pkg = path.display().to_string();
    let member = |inner: &str| Asset::file(format!("{pkg}[{inner}]"));
    let mut lights = Vec::new();
    for inner in ["a.ies", "b.usdz[c.ies]", "missing.ies"] {
        lights.push(Light::sphere(0.5).with_path("/Spot").with_shaping(Shaping {
            ies: Some(Ies {
                file: member(inner),
                angle_scale: 0.0,
                normalize: true,
            }),
            ..Shaping::default()
        }));
    }
    for inner in ["tex.exr", "b.usdz[tex.png]"] {
        lights.push(Light::dome().with_path("/Dome").with_texture(Texture::new(member(inner))));
    }
    for light in &lights {
        if let Ok(r) = Reference::new(light, TemperatureMode::Spec) {
            let e = r.emission(DVec3::new(0.3, -0.4, -0.866).normalize());
            assert!(e.is_finite(), "emission {e}");
        }
    }
});
