//! The README's format pictures (assets/dome_formats/*.png, written by examples/dome_formats.rs
//! from DESIGN.md §6 D2–D5's forward maps, coded there independently of luxeval's lookup): each
//! picture, loaded as a dome of its format, shows the OpenUSD chart's colour (A8: +X green,
//! −X yellow, +Y cyan, −Y blue, +Z magenta, −Z red) around each axis, on the CPU reference and
//! the GPU. A lookup that disagreed with the forward map of its format (a mirrored or rotated
//! axis, a swapped face) would show another face's colour.

use crate::common;

use std::path::Path;

use glam::DVec3;
use luxeval::{Accumulate, Asset, Evaluator, Light, Texture, TextureFilter, TextureFormat};

fn file(rel: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(rel)
        .display()
        .to_string()
}

#[test]
fn each_format_picture_shows_the_chart_around_every_axis() {
    let chart = Light::dome().with_path("/Chart").with_texture(
        Texture::new(Asset::file(file("tests/data/textures/testImage.png")))
            .with_format(TextureFormat::LatLong)
            .with_filter(TextureFilter::Nearest),
    );
    // A8's colours, each axis tilted 25° toward a neighbouring axis: inside the axis'
    // cube face, away from the latlong seam and the disk formats' singular rim.
    let (c, s) = (25f64.to_radians().cos(), 25f64.to_radians().sin());
    let axes: [(DVec3, DVec3, [f32; 3]); 6] = [
        (DVec3::X, DVec3::Y, [0.0, 1.0, 0.0]),
        (-DVec3::X, DVec3::Z, [1.0, 1.0, 0.0]),
        (DVec3::Y, DVec3::X, [0.0, 1.0, 1.0]),
        (-DVec3::Y, DVec3::Z, [0.0, 0.0, 1.0]),
        (DVec3::Z, -DVec3::X, [1.0, 0.0, 1.0]),
        (-DVec3::Z, DVec3::Y, [1.0, 0.0, 0.0]),
    ];
    let dirs: Vec<[f32; 3]> = axes
        .iter()
        .map(|(a, b, _)| (*a * c + *b * s).as_vec3().to_array())
        .collect();
    let points = vec![[0.0f32; 3]; dirs.len()];
    let mut evals = vec![Evaluator::cpu()];
    evals.extend(common::gpu());
    for eval in &evals {
        let want = eval
            .radiance(
                std::slice::from_ref(&chart),
                &points,
                &dirs,
                Accumulate::Sum,
            )
            .unwrap();
        // The chart's faces are near-saturated (its cyan is (0, 0.86, 1) in linear): each
        // channel clearly on or off, as A8 names the colour.
        for (k, (_, _, colour)) in axes.iter().enumerate() {
            let on = want[k].map(|v| v > 0.5);
            assert!(
                on == colour.map(|v| v > 0.5) && want[k].iter().all(|v| *v > 0.5 || *v < 0.1),
                "the chart itself along {:?}: {:?}",
                dirs[k],
                want[k]
            );
        }
        for (format, name) in [
            (TextureFormat::LatLong, "latlong"),
            (TextureFormat::MirroredBall, "mirroredBall"),
            (TextureFormat::Angular, "angular"),
            (TextureFormat::CubeMapVerticalCross, "cubeMapVerticalCross"),
        ] {
            let dome = Light::dome().with_path(format!("/{name}")).with_texture(
                Texture::new(Asset::file(file(&format!(
                    "assets/dome_formats/{name}.png"
                ))))
                .with_format(format)
                .with_filter(TextureFilter::Nearest),
            );
            let got = eval
                .radiance(std::slice::from_ref(&dome), &points, &dirs, Accumulate::Sum)
                .unwrap();
            for k in 0..dirs.len() {
                assert_eq!(
                    got[k],
                    want[k],
                    "{name} on {}: along {:?}",
                    eval.device_name(),
                    dirs[k]
                );
            }
        }
    }
}
