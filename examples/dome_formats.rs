//! Writes `assets/dome_formats/{latlong,mirroredBall,angular,cubeMapVerticalCross}.png`: OpenUSD's
//! orientation chart (a lat-long rendering of a cube with coloured faces,
//! tests/data/textures/testImage.png) as an image of each `texture:format` would hold it.
//!
//! Each output pixel's direction comes from the format's forward map exactly as DESIGN.md §6
//! D2–D5 writes it (coded here, independently of luxeval's own lookup), and its colour is the
//! chart dome's radiance along that direction (luxeval's lookup, nearest filter). So loading an
//! output image as a dome of its format must give back the chart's colour in every direction;
//! tests/dome_formats.rs checks it at the six axes.
//!
//! Run: `cargo run --release --ignore-rust-version --example dome_formats`

use std::f64::consts::PI;
use std::path::Path;

use glam::DVec3;
use luxeval::{Accumulate, Asset, Evaluator, Light, Texture, TextureFilter, TextureFormat};

/// Direction of image point (s, t) (s right, t down, in [0, 1]), or None outside a disk format's
/// disk or the cross's six blocks.
fn direction(format: TextureFormat, s: f64, t: f64) -> Option<DVec3> {
    match format {
        // D2: s = 0.5 − atan2(dx, dz)/2π, t = θ/π from +Y.
        TextureFormat::LatLong => {
            let (phi, theta) = ((0.5 - s) * 2.0 * PI, t * PI);
            Some(DVec3::new(
                theta.sin() * phi.sin(),
                theta.cos(),
                theta.sin() * phi.cos(),
            ))
        }
        // D3: the reflection of the view ray (0, 0, −1) about the ball normal (a, b, √(1 − r²)).
        TextureFormat::MirroredBall => {
            let (a, b) = (2.0 * s - 1.0, 1.0 - 2.0 * t);
            let r2 = a * a + b * b;
            (r2 <= 1.0).then(|| {
                let k = (1.0 - r2).sqrt();
                DVec3::new(2.0 * a * k, 2.0 * b * k, 1.0 - 2.0 * r2)
            })
        }
        // D4: d = (a sin(πr)/r, b sin(πr)/r, cos πr).
        TextureFormat::Angular => {
            let (a, b) = (2.0 * s - 1.0, 1.0 - 2.0 * t);
            let r = (a * a + b * b).sqrt();
            (r <= 1.0).then(|| {
                if r == 0.0 {
                    DVec3::Z
                } else {
                    let k = (PI * r).sin() / r;
                    DVec3::new(a * k, b * k, (PI * r).cos())
                }
            })
        }
        // D5: the cube net seen from inside, 3 × 4 blocks, direction ∝ F + a·R + b·U.
        TextureFormat::CubeMapVerticalCross => {
            let (col, row) = ((s * 3.0).floor().min(2.0), (t * 4.0).floor().min(3.0));
            let (a, b) = (2.0 * (s * 3.0 - col) - 1.0, 1.0 - 2.0 * (t * 4.0 - row));
            let v = DVec3::new;
            let (f, r, u) = match (col as u32, row as u32) {
                (1, 0) => (v(0., 1., 0.), v(-1., 0., 0.), v(0., 0., -1.)),
                (0, 1) => (v(1., 0., 0.), v(0., 0., 1.), v(0., 1., 0.)),
                (1, 1) => (v(0., 0., 1.), v(-1., 0., 0.), v(0., 1., 0.)),
                (2, 1) => (v(-1., 0., 0.), v(0., 0., -1.), v(0., 1., 0.)),
                (1, 2) => (v(0., -1., 0.), v(-1., 0., 0.), v(0., 0., 1.)),
                (1, 3) => (v(0., 0., -1.), v(-1., 0., 0.), v(0., -1., 0.)),
                _ => return None,
            };
            Some((f + a * r + b * u).normalize())
        }
        TextureFormat::Automatic => None,
    }
}

/// Linear → 8-bit sRGB (the inverse of DESIGN.md §6's decoding).
fn srgb(c: f32) -> u8 {
    let c = c.clamp(0.0, 1.0) as f64;
    let e = if c <= 0.0031308 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (e * 255.0).round() as u8
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let chart = root.join("tests/data/textures/testImage.png");
    let dome = Light::dome().with_path("/Chart").with_texture(
        Texture::new(Asset::file(chart.display().to_string()))
            .with_format(TextureFormat::LatLong)
            .with_filter(TextureFilter::Nearest),
    );
    let out_dir = root.join("assets/dome_formats");
    std::fs::create_dir_all(&out_dir)?;
    let eval = Evaluator::cpu();
    for (format, name, w, h) in [
        (TextureFormat::LatLong, "latlong", 256u32, 128u32),
        (TextureFormat::MirroredBall, "mirroredBall", 160, 160),
        (TextureFormat::Angular, "angular", 160, 160),
        (
            TextureFormat::CubeMapVerticalCross,
            "cubeMapVerticalCross",
            120,
            160,
        ),
    ] {
        let mut dirs = Vec::new();
        let mut inside = Vec::new();
        for j in 0..h {
            for i in 0..w {
                let (s, t) = ((i as f64 + 0.5) / w as f64, (j as f64 + 0.5) / h as f64);
                let d = direction(format, s, t);
                inside.push(d.is_some());
                dirs.push(d.unwrap_or(DVec3::Z).as_vec3().to_array());
            }
        }
        let points = vec![[0.0f32; 3]; dirs.len()];
        let rgb = eval.radiance(std::slice::from_ref(&dome), &points, &dirs, Accumulate::Sum)?;
        let mut bytes = Vec::with_capacity(rgb.len() * 3);
        for (c, ok) in rgb.iter().zip(&inside) {
            let c = if *ok { *c } else { [0.0; 3] };
            bytes.extend(c.map(srgb));
        }
        let path = out_dir.join(format!("{name}.png"));
        let file = std::io::BufWriter::new(std::fs::File::create(&path)?);
        let mut enc = png::Encoder::new(file, w, h);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.write_header()?.write_image_data(&bytes)?;
        println!("{}", path.display());
    }
    Ok(())
}
