//! GPU-resident light sampling (`PreparedScene::encode_sample`): a renderer's points and normals
//! in its own buffers, the light chosen on the device. Its rows must be those of the host path
//! (`PreparedScene::sample`) on the same device and lights: the same keys (DESIGN.md §9 S3) and
//! the same WGSL samplers, the light chosen by the same weights in f32 instead of f64 — so the
//! same light wherever the dimension-2 uniform is not within f32 rounding of a border between
//! two lights' shares, and the same direction, radiance and density there up to the f32
//! evaluation of `P(l | x)`.

use crate::resident::{Renderer, invalid_input, lights_with_ies, points, renderer, unit_rows};

use luxeval::testkit::Rng;
use luxeval::wgpu;
use luxeval::{Asset, Evaluator, Light, SampleOptions, Selection, Texture};

/// Floats per output row: ω, pdf, L, light.
const ROW: usize = 8;

/// Records encode_sample and reads its rows back.
fn resident_rows(
    r: &Renderer,
    scene: &luxeval::PreparedScene,
    pts: &[[f32; 3]],
    nrm: Option<&[[f32; 3]]>,
    count: usize,
    opts: &SampleOptions,
) -> Vec<f32> {
    let p = r.buffer(pts, wgpu::BufferUsages::STORAGE);
    let n = nrm.map(|n| r.buffer(n, wgpu::BufferUsages::STORAGE));
    // Garbage in every float, so that a row the call leaves unwritten shows.
    let out = r.output(pts.len() * count * ROW / 3 + 1);
    let mut enc = r.encoder();
    scene
        .encode_sample(
            &mut enc,
            &p,
            n.as_ref(),
            &out,
            pts.len() as u32,
            count as u32,
            opts,
        )
        .unwrap();
    r.finish_floats(enc, &out, pts.len() * count * ROW)
}

fn angle(a: [f32; 3], b: [f32; 3]) -> f64 {
    let a = glam::DVec3::from_array(a.map(f64::from));
    let b = glam::DVec3::from_array(b.map(f64::from));
    a.cross(b).length().atan2(a.dot(b))
}

fn rel(a: f64, b: f64) -> f64 {
    if a == b {
        0.0
    } else {
        (a - b).abs() / a.abs().max(b.abs())
    }
}

/// Compares resident rows with the host path's, row by row (module docs): the same light, the
/// same direction (1e-5 rad) and radiance (1e-5 relative), the density within 1e-4 relative
/// (the f32 `P(l | x)`); at least `min_lit` of the rows lit. Returns the rows whose light
/// differs.
fn compare(what: &str, resident: &[f32], host: &luxeval::Samples, min_lit: f64) -> usize {
    let rows = host.dirs.len();
    assert_eq!(resident.len(), rows * ROW, "{what}: row count");
    let (mut other_light, mut lit) = (0, 0);
    let (mut worst_angle, mut worst_pdf, mut worst_l) = (0.0f64, 0.0f64, 0.0f64);
    for i in 0..rows {
        let r = &resident[ROW * i..ROW * (i + 1)];
        let light = r[7];
        assert_eq!(
            light,
            light.round(),
            "{what}: row {i}: light {light} is no index"
        );
        if light as i32 != host.light[i] {
            other_light += 1;
            continue;
        }
        let dir = [r[0], r[1], r[2]];
        let a = angle(dir, host.dirs[i]);
        let p = rel(r[3] as f64, host.pdf[i] as f64);
        let l = (0..3)
            .map(|c| rel(r[4 + c] as f64, host.radiance[i][c] as f64))
            .fold(0.0, f64::max);
        if host.radiance[i].iter().any(|c| *c > 0.0) {
            lit += 1;
        }
        assert!(
            a <= 1e-5
                && (p <= 1e-4 || (r[3].is_infinite() && host.pdf[i].is_infinite()))
                && l <= 1e-5,
            "{what}: row {i} (light {light}): resident {r:?} vs host dir {:?} pdf {} L {:?} \
             (angle {a:.2e}, pdf {p:.2e}, L {l:.2e})",
            host.dirs[i],
            host.pdf[i],
            host.radiance[i]
        );
        worst_angle = worst_angle.max(a);
        if r[3].is_finite() {
            worst_pdf = worst_pdf.max(p);
        }
        worst_l = worst_l.max(l);
    }
    eprintln!(
        "{what}: {rows} rows, {lit} lit, {other_light} another light; worst angle {worst_angle:.2e} \
         rad, pdf {worst_pdf:.2e}, L {worst_l:.2e} relative"
    );
    assert!(
        lit as f64 >= min_lit * rows as f64 && lit > 0,
        "{what}: only {lit} of {rows} rows lit"
    );
    other_light
}

#[test]
fn resident_samples_match_the_host_path() {
    let Some(r) = renderer() else { return };
    let eval = Evaluator::from_wgpu(r.device.clone(), r.queue.clone()).unwrap();
    // Every analytic type, shaped and not, IES-shaped, delta lights among them.
    let lights = lights_with_ies();
    let scene = eval.prepare(&lights).unwrap();
    let mut rng = Rng::new(0x5E51_DE47);
    let n = 96;
    let pts = points(&mut rng, n);
    let nrm = unit_rows(&mut rng, n);
    let count = 24;
    let mut rows = 0;
    let mut other = 0;
    for selection in [Selection::Bound, Selection::Power] {
        for normals in [Some(&nrm[..]), None] {
            let opts = SampleOptions {
                seed: 7,
                selection,
                first_point: 1_000,
            };
            let host = scene.sample(&pts, normals, count, &opts).unwrap();
            let resident = resident_rows(&r, &scene, &pts, normals, count, &opts);
            other += compare(
                &format!("{selection:?}, normals {}", normals.is_some()),
                &resident,
                &host,
                0.25,
            );
            rows += host.dirs.len();
        }
    }
    // A border within f32 rounding of u: about 1e-6 of the rows at most, so none expected here.
    assert!(
        other * 10_000 <= rows,
        "{other} of {rows} rows chose another light"
    );
}

#[test]
fn resident_samples_do_not_depend_on_chunking_and_unlit_points_say_so() {
    let Some(r) = renderer() else { return };
    let eval = Evaluator::from_wgpu(r.device.clone(), r.queue.clone()).unwrap();
    // One spot: points behind it or outside its cone get no light (−1, pdf 0).
    let spot = Light::disk(0.5)
        .with_path("/spot")
        .with_intensity(5.0)
        .with_shaping(luxeval::Shaping {
            cone_angle: 60.0,
            ..Default::default()
        });
    let scene = eval.prepare(&[spot]).unwrap();
    let mut rng = Rng::new(3);
    let pts = points(&mut rng, 40);
    let opts = SampleOptions {
        seed: 11,
        selection: Selection::Bound,
        first_point: 0,
    };
    let whole = resident_rows(&r, &scene, &pts, None, 5, &opts);
    let second = resident_rows(
        &r,
        &scene,
        &pts[17..],
        None,
        5,
        &SampleOptions {
            first_point: 17,
            ..opts
        },
    );
    assert_eq!(
        &whole[17 * 5 * ROW..],
        &second[..],
        "a chunk draws what the whole draws"
    );
    let host = scene.sample(&pts, None, 5, &opts).unwrap();
    let unlit = host.light.iter().filter(|l| **l < 0).count();
    assert!(unlit > 0 && unlit < host.light.len(), "{unlit} unlit rows");
    for (i, l) in host.light.iter().enumerate() {
        if *l < 0 {
            let row = &whole[ROW * i..ROW * (i + 1)];
            assert_eq!(row[7], -1.0, "row {i}");
            assert_eq!(row[3], 0.0, "row {i}");
            assert_eq!(&row[4..7], &[0.0; 3], "row {i}");
            assert_eq!(&row[..3], &host.dirs[i], "row {i}");
        }
    }
    compare("one spot", &whole, &host, 0.0);
}

#[test]
fn resident_sampling_refusals_are_typed() {
    let Some(r) = renderer() else { return };
    let eval = Evaluator::from_wgpu(r.device.clone(), r.queue.clone()).unwrap();
    let scene = eval.prepare(&[Light::sphere(0.5).with_path("/s")]).unwrap();
    let n = 16;
    let pts = r.buffer(&vec![[0.0, -2.0, 0.0]; n], wgpu::BufferUsages::STORAGE);
    let out = r.output(n * 4 * ROW / 3);
    let mut enc = r.encoder();
    let opts = SampleOptions::default();
    let exact = SampleOptions {
        selection: Selection::Exact,
        ..opts
    };
    let (what, reason) = invalid_input(
        scene
            .encode_sample(&mut enc, &pts, None, &out, n as u32, 4, &exact)
            .unwrap_err(),
    );
    assert_eq!(what, "selection");
    assert!(reason.contains("PreparedScene::sample"), "{reason}");
    let (what, _) = invalid_input(
        scene
            .encode_sample(&mut enc, &pts, None, &out, n as u32, 0, &opts)
            .unwrap_err(),
    );
    assert_eq!(what, "count");
    // 5 samples a point need 5 × 16 rows of 32 bytes; the buffer holds 4 × 16.
    let (what, reason) = invalid_input(
        scene
            .encode_sample(&mut enc, &pts, None, &out, n as u32, 5, &opts)
            .unwrap_err(),
    );
    assert_eq!(what, "out");
    assert!(reason.contains("32 bytes a row"), "{reason}");
    let (what, _) = invalid_input(
        scene
            .encode_sample(&mut enc, &pts, Some(&pts), &pts, n as u32, 1, &opts)
            .unwrap_err(),
    );
    assert_eq!(what, "out");
    // A scene on the CPU reference has no device.
    let cpu = Evaluator::cpu().prepare(&[Light::sphere(0.5)]).unwrap();
    let (what, _) = invalid_input(
        cpu.encode_sample(&mut enc, &pts, None, &out, n as u32, 1, &opts)
            .unwrap_err(),
    );
    assert_eq!(what, "backend");
    r.queue.submit([enc.finish()]);
    r.device.poll(wgpu::PollType::wait_indefinitely()).unwrap();
}

/// A textured dome beside a sphere: the dome's rows come from its sampling tables on the device
/// (uploaded on the first sampling call), as the host path's do.
#[test]
fn resident_samples_of_a_textured_dome_match_the_host_path() {
    let Some(r) = renderer() else { return };
    let eval = Evaluator::from_wgpu(r.device.clone(), r.queue.clone()).unwrap();
    let mut rng = Rng::new(29);
    let img = image::RgbImage::from_fn(16, 8, |_, _| {
        image::Rgb([0, 1, 2].map(|_| 64 + rng.below(192) as u8))
    });
    let mut bytes = std::io::Cursor::new(Vec::new());
    img.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
    let dome = Light::dome()
        .with_path("/env")
        .with_texture(Texture::new(Asset::from_bytes(
            "env.png",
            bytes.into_inner(),
        )));
    let sphere = Light::sphere(0.3)
        .with_path("/key")
        .with_intensity(20.0)
        .with_transform(glam::DMat4::from_translation(glam::DVec3::new(
            0.0, 3.0, 0.0,
        )));
    let scene = eval.prepare(&[dome, sphere]).unwrap();
    let pts = points(&mut rng, 48);
    let nrm = unit_rows(&mut rng, 48);
    for normals in [Some(&nrm[..]), None] {
        let opts = SampleOptions {
            seed: 5,
            selection: Selection::Bound,
            first_point: 0,
        };
        let host = scene.sample(&pts, normals, 16, &opts).unwrap();
        let resident = resident_rows(&r, &scene, &pts, normals, 16, &opts);
        let other = compare(
            &format!("textured dome, normals {}", normals.is_some()),
            &resident,
            &host,
            0.25,
        );
        assert_eq!(other, 0);
        assert!(host.light.contains(&0), "the dome is drawn");
    }
}
