//! A stage with a textured RectLight (tests/data/usd/rect/textured_rect.usda, the OpenUSD
//! orientation chart tests/data/textures/testImage.png on a 2 × 1 rect) is read and evaluated,
//! not skipped: radiance at texel centres equals intensity × the texel (decoded here with the
//! `image` crate and the sRGB curve of DESIGN.md §6), with pixel (0, 0) at the light's (+X, +Y)
//! corner; emission along the normal is intensity × the texel mean.
#![cfg(feature = "usd")]

use std::path::Path;

use luxeval::{Accumulate, Evaluator, Stage};

fn srgb(v: u8) -> f64 {
    let c = v as f64 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[test]
fn a_textured_rect_light_is_read_and_evaluated() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let scene = Stage::load(&root.join("usd/rect/textured_rect.usda"), None).unwrap();
    assert!(scene.warnings().is_empty(), "{:?}", scene.warnings());
    let lights = scene.evaluable(&[]).unwrap();
    assert_eq!(lights.len(), 1);
    assert!(lights[0].texture.is_some());
    let img = image::open(root.join("textures/testImage.png"))
        .unwrap()
        .to_rgb8();
    let (w, h) = (img.width(), img.height());
    let texel = |i: u32, j: u32| img.get_pixel(i, j).0.map(srgb);
    let scene = Evaluator::cpu().prepare(&lights).unwrap();
    // The rect is 2 × 1 at z = 3 facing −Z: look along +Z from z = 0 at texel centres.
    let picks = [
        (0, 0),
        (w - 1, 0),
        (0, h - 1),
        (w - 1, h - 1),
        (w / 3, h / 4),
    ];
    let (mut pts, mut dirs) = (Vec::new(), Vec::new());
    for (i, j) in picks {
        let s = (i as f64 + 0.5) / w as f64;
        let t = (j as f64 + 0.5) / h as f64;
        // s = 0.5 − x/w, t = 0.5 − y/h (DESIGN.md §6 "RectLight texture").
        pts.push([((0.5 - s) * 2.0) as f32, ((0.5 - t) * 1.0) as f32, 0.0]);
        dirs.push([0.0, 0.0, 1.0]);
    }
    let got = scene.radiance(&pts, &dirs, Accumulate::Sum).unwrap();
    for (k, (i, j)) in picks.into_iter().enumerate() {
        let want = texel(i, j).map(|c| 2.0 * c);
        for c in 0..3 {
            assert!(
                (got[k][c] as f64 - want[c]).abs() <= 1e-5 * want[c].max(1e-3),
                "texel ({i}, {j}): {:?} vs {want:?}",
                got[k]
            );
        }
    }
    // Emission along the normal (−Z): intensity × the texel mean.
    let mut mean = [0.0f64; 3];
    for p in img.pixels() {
        for (m, v) in mean.iter_mut().zip(p.0) {
            *m += srgb(v) / (w * h) as f64;
        }
    }
    let e = scene
        .emission(&[[0.0, 0.0, -1.0]], Accumulate::Sum)
        .unwrap();
    for c in 0..3 {
        assert!(
            (e[0][c] as f64 - 2.0 * mean[c]).abs() <= 1e-6 * mean[c].max(1e-3),
            "{e:?} vs {mean:?}"
        );
    }
}
