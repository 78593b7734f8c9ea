//! CPU (f64) vs GPU (f32) conformance of textured domes (DESIGN.md §6 D1–D6, §5): generated
//! textures of every format (latlong, mirroredBall, angular, cubeMapVerticalCross) at several
//! sizes, both filters, plain DomeLight and DomeLight_1 with poleAxis Y and Z, with and without
//! a rotated transform; emission and radiance within a relative 1e-4 per channel. Irradiance:
//! a latlong dome's within 1e-4 too (the kernel's row integral), the other domes' the
//! reference's value (the last two tests).
//!
//! Excluded directions (documented divergence 1 of shaders/shared/texture.wgsl): with the nearest
//! filter, those within 1e-3 px of a texel edge (f32 pixel coordinates carry ~W·2⁻²⁴ px of
//! rounding and may pick the neighbour); with either filter, those within a relative 1e-4 of a
//! cube-cross face edge (each face clamps to its own edge texels). Both counted and bounded.
//! Texel values are linear in [0.21, 1] (8-bit sRGB 128..255), so a jump of one texel moves the
//! bilinear value by at most ~5 × the f32 weight error, far below 1e-4.

use crate::common;

use glam::{DMat4, DVec3};
use luxeval::testkit::Rng;
use luxeval::testkit::dome::{near_discontinuity, prepare_with_filter};
use luxeval::{
    Accumulate, Evaluator, Light, PoleAxis, Texture, TextureFilter, TextureFormat, UpAxis,
};

const TOL: f64 = 1e-4;

use luxeval::testkit::dome::random_png as png;

fn unit(rng: &mut Rng) -> [f32; 3] {
    let z: f64 = 2.0 * rng.f64() - 1.0;
    let p = std::f64::consts::TAU * rng.f64();
    let r = (1.0 - z * z).sqrt();
    [(r * p.cos()) as f32, (r * p.sin()) as f32, z as f32]
}

/// Every format at two or three sizes (explicit formats; the latlong 13 × 5 is not 2:1).
const CASES: [(TextureFormat, u32, u32); 9] = [
    (TextureFormat::LatLong, 16, 8),
    (TextureFormat::LatLong, 64, 32),
    (TextureFormat::LatLong, 13, 5),
    (TextureFormat::MirroredBall, 17, 17),
    (TextureFormat::MirroredBall, 32, 32),
    (TextureFormat::Angular, 9, 9),
    (TextureFormat::Angular, 64, 64),
    (TextureFormat::CubeMapVerticalCross, 12, 16),
    (TextureFormat::CubeMapVerticalCross, 48, 64),
];

fn domes(rng: &mut Rng) -> Vec<Light> {
    let mut out = Vec::new();
    for (k, (format, w, h)) in CASES.into_iter().enumerate() {
        let file = png(w, h, rng);
        for (j, pole) in [None, Some(PoleAxis::Y), Some(PoleAxis::Z)]
            .into_iter()
            .enumerate()
        {
            let mut t = Texture::new(file.clone()).with_format(format);
            if let Some(p) = pole {
                t = t.with_pole_axis(p);
            }
            let mut l = Light::dome()
                .with_path(format!("/Dome_{k}_{j}"))
                .with_intensity(1.5 + j as f64)
                .with_stage_up(UpAxis::Z)
                .with_texture(t);
            if (k + j) % 2 == 1 {
                let axis = DVec3::new(0.3, -0.5, 0.8).normalize();
                l = l.with_transform(DMat4::from_axis_angle(axis, 0.7 + k as f64));
            }
            out.push(l);
        }
    }
    out
}

fn rel(g: [f32; 3], c: [f32; 3]) -> f64 {
    (0..3)
        .map(|i| (g[i] as f64 - c[i] as f64).abs() / (c[i] as f64).abs().max(1e-30))
        .fold(0.0, f64::max)
}

#[test]
fn gpu_matches_cpu_on_textured_domes_of_every_format_and_filter() {
    let Some(gpu) = common::gpu() else { return };
    let cpu = Evaluator::cpu();
    let mut rng = Rng::new(0xD0_3E);
    let lights = domes(&mut rng);
    let n = 1500;
    let (mut total, mut excluded, mut worst) = (0usize, 0usize, (0.0f64, String::new()));
    let mut failures = Vec::new();
    for nearest in [false, true] {
        let g = prepare_with_filter(&gpu, &lights, nearest).expect("GPU scene");
        let c = prepare_with_filter(&cpu, &lights, nearest).expect("CPU scene");
        let dirs: Vec<[f32; 3]> = (0..n).map(|_| unit(&mut rng)).collect();
        let points: Vec<[f32; 3]> = (0..n).map(|_| unit(&mut rng).map(|x| 10.0 * x)).collect();
        let results = [
            (
                "emission",
                g.emission(&dirs, Accumulate::PerLight).unwrap(),
                c.emission(&dirs, Accumulate::PerLight).unwrap(),
            ),
            (
                "radiance",
                g.radiance(&points, &dirs, Accumulate::PerLight).unwrap(),
                c.radiance(&points, &dirs, Accumulate::PerLight).unwrap(),
            ),
        ];
        for (l, light) in lights.iter().enumerate() {
            let skip = near_discontinuity(light, &dirs, nearest, 1e-3).unwrap();
            let skip_cross = near_discontinuity(light, &dirs, false, 1e-4).unwrap();
            for (query, gv, cv) in &results {
                for i in 0..n {
                    if skip[i] || skip_cross[i] {
                        excluded += 1;
                        continue;
                    }
                    total += 1;
                    let e = rel(gv[l * n + i], cv[l * n + i]);
                    let what = format!(
                        "{query} {} nearest={nearest} dir {:?}: gpu {:?} cpu {:?}",
                        light.path,
                        dirs[i],
                        gv[l * n + i],
                        cv[l * n + i]
                    );
                    if e > worst.0 {
                        worst = (e, what.clone());
                    }
                    if e > TOL {
                        failures.push((e, what));
                    }
                }
            }
        }
    }
    println!(
        "dome conformance on {}: {total} compared, {excluded} excluded, worst {:.3e} ({})",
        gpu.device_name(),
        worst.0,
        worst.1
    );
    assert!(total >= 100_000, "only {total} compared");
    assert!(excluded * 50 < total, "{excluded} of {total} excluded");
    assert!(
        failures.is_empty(),
        "{} values over {TOL}; first: {:?}",
        failures.len(),
        &failures[..failures.len().min(5)]
    );
}

/// A scene without textured domes keeps its pipelines (built with DOME_ENABLED = false) and
/// values: an untextured dome next to a textured one is still its base radiance.
#[test]
fn untextured_domes_are_unchanged_beside_textured_ones() {
    let Some(gpu) = common::gpu() else { return };
    let mut rng = Rng::new(7);
    let plain = Light::dome().with_path("/Plain").with_intensity(2.0);
    let textured = Light::dome()
        .with_path("/Tex")
        .with_texture(Texture::new(png(8, 4, &mut rng)));
    let dirs: Vec<[f32; 3]> = (0..64).map(|_| unit(&mut rng)).collect();
    for lights in [vec![plain.clone()], vec![plain.clone(), textured]] {
        let out = gpu
            .prepare(&lights)
            .unwrap()
            .emission(&dirs, Accumulate::PerLight)
            .unwrap();
        assert!(out[..dirs.len()].iter().all(|v| *v == [2.0; 3]), "{out:?}");
    }
}

/// A textured latlong dome's irradiance is the kernel's (irradiance/latlong_rows.wgsl) under a
/// rotation, a rotation times a uniform scale and DomeLight_1's Z pole, with either filter and
/// at sizes from 1 × 1 to 64 × 32 (13 × 5: not 2:1): within 1e-4 of the reference per channel,
/// summed with the other lights' (an untextured dome, π · its radiance) and per light in
/// light-major order. Normals include the poles and the horizon's tangency cases (±Y, X, Z).
#[test]
fn gpu_irradiance_of_a_textured_latlong_dome_matches_the_reference() {
    let Some(gpu) = common::gpu() else { return };
    let mut rng = Rng::new(8);
    let axis = DVec3::new(0.3, -0.5, 0.8).normalize();
    let mut normals: Vec<[f32; 3]> = vec![
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 0.0, -1.0],
        [1e-4, 1.0, 0.0],
    ];
    normals.extend((0..40).map(|_| unit(&mut rng)));
    let points: Vec<[f32; 3]> = (0..normals.len())
        .map(|i| [i as f32, -(i as f32), 3.0])
        .collect();
    let n = normals.len();
    let cpu = Evaluator::cpu();
    let mut checked = 0;
    for (w, h, filter, frame) in [
        (1, 1, TextureFilter::Bilinear, 0),
        (8, 4, TextureFilter::Bilinear, 1),
        (8, 4, TextureFilter::Nearest, 0),
        (13, 5, TextureFilter::Bilinear, 2),
        (64, 32, TextureFilter::Bilinear, 3),
        (64, 32, TextureFilter::Nearest, 1),
    ] {
        let mut texture = Texture::new(png(w, h, &mut rng))
            .with_format(TextureFormat::LatLong)
            .with_filter(filter);
        if frame == 3 {
            texture = texture.with_pole_axis(PoleAxis::Z);
        }
        let mut tex = Light::dome().with_path("/Tex").with_texture(texture);
        tex = match frame {
            1 => tex.with_transform(DMat4::from_axis_angle(axis, 0.9)),
            2 => tex.with_transform(
                DMat4::from_axis_angle(axis, 0.4) * DMat4::from_scale(DVec3::splat(2.5)),
            ),
            _ => tex,
        };
        let plain = Light::dome().with_path("/Plain").with_intensity(0.5);
        let lights = vec![tex, plain];
        let want = cpu
            .irradiance(&lights, &points, &normals, Accumulate::PerLight)
            .unwrap();
        let got = gpu
            .irradiance(&lights, &points, &normals, Accumulate::PerLight)
            .unwrap();
        for i in 0..2 * n {
            assert!(
                rel(got[i], want[i]) < TOL,
                "{w}x{h} {filter:?} frame {frame} row {i} (normal {:?}): {:?} vs {:?}",
                normals[i % n],
                got[i],
                want[i]
            );
            checked += 1;
        }
        let sum = gpu
            .irradiance(&lights, &points, &normals, Accumulate::Sum)
            .unwrap();
        for i in 0..n {
            let expect = [0, 1, 2].map(|c| want[i][c] + want[n + i][c]);
            assert!(rel(sum[i], expect) < TOL, "{i}: {:?} {:?}", sum[i], expect);
        }
        assert!(got[..n].iter().any(|v| v[0] > 0.0));
        // The kernel integrated them: the host's rows would be the reference's bit for bit.
        assert!(got[..n] != want[..n], "{w}x{h}: the reference's rows");
        let worst = (0..n).map(|i| rel(got[i], want[i])).fold(0.0, f64::max);
        eprintln!("{w}x{h} {filter:?} frame {frame}: worst relative difference {worst:.1e}");
    }
    assert_eq!(checked, 6 * 2 * n);
}

/// A scene whose lights depend on the normal only (a textured latlong dome, a distant light)
/// is integrated once per distinct normal on the GPU path: a falloff-like batch of 300
/// receivers sharing 3 normals gives, bit for bit, the rows of those 3 normals evaluated alone
/// (at other points), summed and per light, within 1e-4 of the reference.
#[test]
fn normal_only_scenes_are_integrated_once_per_distinct_normal() {
    let Some(gpu) = common::gpu() else { return };
    let mut rng = Rng::new(10);
    let lights = vec![
        Light::dome()
            .with_path("/Env")
            .with_texture(Texture::new(png(16, 8, &mut rng)).with_format(TextureFormat::LatLong)),
        Light::distant(0.53).with_path("/Sun").with_intensity(3.0),
    ];
    let three: Vec<[f32; 3]> = (0..3).map(|_| unit(&mut rng)).collect();
    let normals: Vec<[f32; 3]> = (0..300).map(|i| three[(i * 7) % 3]).collect();
    let points: Vec<[f32; 3]> = (0..300).map(|i| [i as f32, 0.5, -(i as f32)]).collect();
    let alone_points = vec![[-4.0f32, 2.0, 1.0]; 3];
    let cpu = Evaluator::cpu();
    for acc in [Accumulate::Sum, Accumulate::PerLight] {
        let got = gpu.irradiance(&lights, &points, &normals, acc).unwrap();
        let alone = gpu.irradiance(&lights, &alone_points, &three, acc).unwrap();
        let want = cpu.irradiance(&lights, &points, &normals, acc).unwrap();
        let rows = if acc == Accumulate::PerLight { 2 } else { 1 };
        assert_eq!(got.len(), rows * 300);
        for r in 0..rows * 300 {
            let (l, i) = (r / 300, r % 300);
            assert_eq!(got[r], alone[l * 3 + (i * 7) % 3], "{acc:?} row {r}");
            assert!(rel(got[r], want[r]) < TOL, "{acc:?} row {r}");
        }
    }
}

/// A textured dome beside lights whose irradiance depends on the position: the kernel
/// integrates the dome (and the distant light) once per distinct normal and the others per
/// receiver (query's `irradiance_plan`), and adds them. Per light, each row is the row that
/// scenes of the normal-only lights or of the positional lights alone give (bit for bit: the
/// same kernel on the same inputs); summed, their sum; and within the tolerance of the
/// reference.
#[test]
fn a_textured_dome_beside_local_lights_is_integrated_once_per_distinct_normal() {
    let Some(gpu) = common::gpu() else { return };
    let mut rng = Rng::new(24);
    let dome = Light::dome()
        .with_path("/Env")
        .with_texture(Texture::new(png(16, 8, &mut rng)).with_format(TextureFormat::LatLong));
    let sun = Light::distant(0.53).with_path("/Sun").with_intensity(3.0);
    let sphere = Light::sphere(0.3)
        .with_path("/Bulb")
        .with_intensity(40.0)
        .with_transform(DMat4::from_translation(DVec3::new(0.5, 2.0, -0.5)));
    let rect = Light::rect(1.0, 0.5)
        .with_path("/Panel")
        .with_intensity(20.0)
        .with_transform(DMat4::from_translation(DVec3::new(-1.0, 3.0, 0.0)));
    // In scene order: positional and normal-only lights interleaved.
    let lights = vec![sphere.clone(), dome.clone(), rect.clone(), sun.clone()];
    let three: Vec<[f32; 3]> = vec![[0.0, 1.0, 0.0], unit(&mut rng), [0.3, 0.9, 0.1]];
    let normals: Vec<[f32; 3]> = (0..120).map(|i| three[(i * 7) % 3]).collect();
    let points: Vec<[f32; 3]> = (0..120)
        .map(|i| [(i % 11) as f32 * 0.3 - 1.5, 0.0, (i % 7) as f32 * 0.4 - 1.2])
        .collect();
    let per = gpu
        .irradiance(&lights, &points, &normals, Accumulate::PerLight)
        .unwrap();
    let normal_only = gpu
        .irradiance(&[dome, sun], &points, &normals, Accumulate::PerLight)
        .unwrap();
    let positional = gpu
        .irradiance(&[sphere, rect], &points, &normals, Accumulate::PerLight)
        .unwrap();
    let n = points.len();
    for i in 0..n {
        assert_eq!(per[i], positional[i], "sphere row {i}");
        assert_eq!(per[n + i], normal_only[i], "dome row {i}");
        assert_eq!(per[2 * n + i], positional[n + i], "rect row {i}");
        assert_eq!(per[3 * n + i], normal_only[n + i], "sun row {i}");
    }
    let sum = gpu
        .irradiance(&lights, &points, &normals, Accumulate::Sum)
        .unwrap();
    let want = Evaluator::cpu()
        .irradiance(&lights, &points, &normals, Accumulate::Sum)
        .unwrap();
    for i in 0..n {
        for c in 0..3 {
            let total: f64 = (0..4).map(|l| per[l * n + i][c] as f64).sum();
            assert!(
                (sum[i][c] as f64 - total).abs() <= 1e-6 * total.abs(),
                "row {i}: {} vs {total}",
                sum[i][c]
            );
        }
        assert!(
            rel(sum[i], want[i]) < TOL,
            "row {i}: {:?} vs {:?}",
            sum[i],
            want[i]
        );
    }
    let lit = (0..n)
        .filter(|&i| per[i][0] > 0.0 && per[2 * n + i][0] > 0.0)
        .count();
    assert!(
        lit * 3 >= n,
        "only {lit} of {n} receivers lit by both local lights"
    );
}

/// The domes the kernel does not integrate (other formats; a frame that is not a rotation times
/// a uniform scale) take their irradiance from the CPU reference (query's
/// `irradiance_on_host`): exactly the reference's value rounded to f32.
#[test]
fn gpu_irradiance_of_other_textured_domes_is_the_reference() {
    let Some(gpu) = common::gpu() else { return };
    let mut rng = Rng::new(9);
    let normals: Vec<[f32; 3]> = (0..24).map(|_| unit(&mut rng)).collect();
    let points: Vec<[f32; 3]> = (0..normals.len()).map(|i| [i as f32, 0.0, 1.0]).collect();
    let cpu = Evaluator::cpu();
    let angular = Light::dome()
        .with_texture(Texture::new(png(8, 8, &mut rng)).with_format(TextureFormat::Angular));
    let sheared = Light::dome()
        .with_texture(Texture::new(png(8, 4, &mut rng)).with_format(TextureFormat::LatLong))
        .with_transform(DMat4::from_scale(DVec3::new(1.0, 2.0, 0.7)));
    for light in [angular, sheared] {
        let lights = vec![light];
        let want = cpu
            .irradiance(&lights, &points, &normals, Accumulate::Sum)
            .unwrap();
        let got = gpu
            .irradiance(&lights, &points, &normals, Accumulate::Sum)
            .unwrap();
        assert_eq!(got, want);
        assert!(got.iter().any(|v| v[0] > 0.0));
    }
}

/// Latlong domes past the 2048 × 1024 the device once held (`W + H` over 4,096): a 5632 × 8
/// strip (5,640 steps of the row walk; lavapipe's loop budget allows about 5,900) is integrated
/// by the kernel within 1e-4 of the reference with either filter, and a 16384 × 4 strip's walk
/// (a 4096 × 2048 map's is 6,144 steps) is cut short on lavapipe, detected and recomputed by
/// the reference, the reference's value there (a real GPU integrates it; either way within
/// 1e-4).
#[test]
fn gpu_irradiance_of_latlong_domes_with_long_walks() {
    let Some(gpu) = common::gpu() else { return };
    let mut rng = Rng::new(10);
    let mut normals: Vec<[f32; 3]> = vec![[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]];
    normals.extend((0..5).map(|_| unit(&mut rng)));
    let points = vec![[0.0f32, 0.0, 0.0]; normals.len()];
    let cpu = Evaluator::cpu();
    for (w, h, filter) in [
        (5632, 8, TextureFilter::Bilinear),
        (5632, 8, TextureFilter::Nearest),
        (16384, 4, TextureFilter::Bilinear),
    ] {
        let texture = Texture::new(png(w, h, &mut rng))
            .with_format(TextureFormat::LatLong)
            .with_filter(filter);
        let lights = vec![Light::dome().with_texture(texture)];
        let want = cpu
            .irradiance(&lights, &points, &normals, Accumulate::Sum)
            .unwrap();
        let scene = gpu.prepare(&lights).unwrap();
        let got = scene
            .irradiance(&points, &normals, Accumulate::Sum)
            .unwrap();
        for i in 0..normals.len() {
            assert!(
                rel(got[i], want[i]) < TOL,
                "{w}x{h} {filter:?} normal {:?}: {:?} vs {:?}",
                normals[i],
                got[i],
                want[i]
            );
        }
        let redone = scene.host_recomputed_rows();
        let worst = (0..normals.len())
            .map(|i| rel(got[i], want[i]))
            .fold(0.0, f64::max);
        eprintln!("{w}x{h} {filter:?}: worst {worst:.1e}, {redone} rows recomputed by the host");
        if w < 16384 {
            // The kernel's own values: none recomputed, and not the reference's bit for bit.
            assert_eq!(redone, 0, "{w}x{h} {filter:?}");
            assert!(got != want, "{w}x{h} {filter:?}: the reference's rows");
        }
    }
}
