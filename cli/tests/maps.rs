//! Irradiance and falloff maps through the command line, and the textures they read: outputs
//! equal the library's (at the default and the reference tolerance), the falloff EXR and PNG,
//! refusals with exit 2 and no file, `--texture-filter`, textured domes and Blender's studio
//! maps on both paths.

use crate::common;
use crate::support::*;

use std::path::Path;

use luxeval::{Accumulate, Evaluator, Stage};
use luxeval_cli::io::npy;

/// The CLI's irradiance at its default `--tolerance` (1e-4) equals the library's at that
/// tolerance, and at `--tolerance 1e-9` the library's reference.
#[test]
fn irradiance_on_the_bundled_floor_equals_the_library() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Stage::load(Path::new(&asset("studio.usda")), None).unwrap();
    let lights = scene.evaluable(&[]).unwrap();
    let points = npy::read_vec3(Path::new(&asset("floor_points.npy"))).unwrap();
    let normals = npy::read_directions(Path::new(&asset("floor_up.npy"))).unwrap();
    let (studio, floor, up) = (
        asset("studio.usda"),
        asset("floor_points.npy"),
        asset("floor_up.npy"),
    );
    for (flags, eval) in [
        (
            &[][..],
            Evaluator::cpu().with_irradiance_tolerance(1e-4).unwrap(),
        ),
        (&["--tolerance", "1e-9"][..], Evaluator::cpu()),
    ] {
        let out = dir.path().join("e.npy");
        let mut args = vec![
            "irradiance",
            &studio,
            "--points",
            &floor,
            "--normals",
            &up,
            "-o",
            out.to_str().unwrap(),
            "--device",
            "cpu",
            "--per-light",
        ];
        args.extend(flags);
        let o = luxeval(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let (shape, got) = read_npy_f32(&out);
        assert_eq!(
            shape,
            vec![lights.len() as u64, points.len() as u64, 3],
            "(L, N, 3)"
        );
        let want = eval
            .irradiance(&lights, &points, &normals, Accumulate::PerLight)
            .unwrap();
        let want: Vec<f32> = want.iter().flatten().copied().collect();
        assert_eq!(got, want, "{flags:?}");
        assert!(got.iter().any(|v| *v > 0.0), "the floor is lit");
    }
}

#[test]
fn falloff_writes_an_exr_equal_to_the_library_and_a_png_with_its_colour_bar() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("rect.exr");
    let png = dir.path().join("rect.png");
    let o = luxeval(&[
        "falloff",
        &luxtest("rect.usda"),
        "--time",
        "5",
        "--origin",
        "-5,0,5",
        "--u",
        "10,0,0",
        "--v",
        "0,0,-10",
        "--res",
        "48,32",
        "-o",
        exr.to_str().unwrap(),
        "--png",
        png.to_str().unwrap(),
        "--contours",
        "--device",
        "cpu",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    // The EXR: the library's map of the same plane, pixel for pixel (row 0 at the top).
    let map = luxeval_cli::io::exr::read_exr(&exr).unwrap();
    assert_eq!((map.width, map.height), (48, 32));
    let scene = Stage::load(Path::new(&luxtest("rect.usda")), Some(5.0)).unwrap();
    let lights = scene.evaluable(&[]).unwrap();
    let plane = luxeval::FalloffPlane::new(
        glam::DVec3::new(-5.0, 0.0, 5.0),
        glam::DVec3::new(10.0, 0.0, 0.0),
        glam::DVec3::new(0.0, 0.0, -10.0),
        48,
        32,
    )
    .unwrap();
    let want = Evaluator::cpu()
        .irradiance(
            &lights,
            &plane.points(),
            &vec![[0.0, 1.0, 0.0]; plane.pixels()],
            Accumulate::Sum,
        )
        .unwrap();
    assert_eq!(map.rgb, want);
    assert!(map.rgb.iter().any(|p| p[1] > 1.0), "a lit floor");
    // The PNG: a real image, larger than the map (colour bar, labels), not blank.
    let decoder = ::png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&png).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert!(
        info.width > 48 && info.height > 32,
        "{}x{}",
        info.width,
        info.height
    );
    let distinct: std::collections::HashSet<&[u8]> = buf[..info.buffer_size()].chunks(3).collect();
    assert!(distinct.len() > 20, "only {} colours", distinct.len());
}

#[test]
fn falloff_and_irradiance_reject_bad_input_with_exit_2_and_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("m.exr");
    let base = |res: &str, u: &str| {
        luxeval(&[
            "falloff",
            &luxtest("rect.usda"),
            "--origin",
            "-5,0,5",
            "--u",
            u,
            "--v",
            "0,0,-10",
            "--res",
            res,
            "-o",
            exr.to_str().unwrap(),
            "--device",
            "cpu",
        ])
    };
    for (res, u, what) in [
        ("0,10", "10,0,0", "res"),
        ("10", "10,0,0", "res"),
        ("10,10", "10,0", "u"),
        ("10,10", "0,0,-10", "parallel"),
        ("10,10", "nan,0,0", "u"),
    ] {
        let o = base(res, u);
        assert_eq!(o.status.code(), Some(2), "{res} {u}: {}", stderr(&o));
        assert!(
            stderr(&o).to_lowercase().contains(what),
            "{res} {u}: expected '{what}' in: {}",
            stderr(&o)
        );
        assert!(files_in(dir.path()).is_empty(), "{res} {u}");
    }
    // Points and normals that do not pair up.
    let out = dir.path().join("e.npy");
    let o = luxeval(&[
        "irradiance",
        &asset("studio.usda"),
        "--points",
        &asset("floor_points.npy"),
        "--normals",
        &luxtest("../../npy/dirs_f32.npy"),
        "-o",
        out.to_str().unwrap(),
        "--device",
        "cpu",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("normals"), "{}", stderr(&o));
    assert!(!out.exists());
}

/// `--texture-filter` reaches the lights' textures: on luxtest's textured dome, the emission
/// with each filter equals the library's with that filter set on the light's texture, and the two
/// differ.
#[test]
fn texture_filter_selects_the_reconstruction() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Stage::load(Path::new(&luxtest("dome.usda")), Some(1.0)).unwrap();
    let dirs = npy::read_directions(Path::new(&asset("dirs.npy"))).unwrap();
    let mut outputs = Vec::new();
    for (arg, filter) in [
        (None, luxeval::TextureFilter::Bilinear),
        (Some("nearest"), luxeval::TextureFilter::Nearest),
        (Some("bilinear"), luxeval::TextureFilter::Bilinear),
    ] {
        let out = dir.path().join("e.npy");
        let mut args = vec!["emission", &*luxtest("dome.usda"), "--time", "1", "--dirs"]
            .into_iter()
            .map(String::from)
            .collect::<Vec<_>>();
        args.extend([asset("dirs.npy"), "-o".into(), out.display().to_string()]);
        args.extend(["--device".into(), "cpu".into()]);
        if let Some(a) = arg {
            args.extend(["--texture-filter".into(), a.into()]);
        }
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = luxeval(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let mut lights = scene.evaluable(&[]).unwrap();
        lights[0].texture.as_mut().unwrap().filter = filter;
        let want = Evaluator::cpu()
            .emission(&lights, &dirs, Accumulate::Sum)
            .unwrap();
        let (_, got) = read_npy_f32(&out);
        assert_eq!(got, want.iter().flatten().copied().collect::<Vec<f32>>());
        outputs.push(got);
    }
    assert_ne!(outputs[0], outputs[1]);
    assert_eq!(outputs[0], outputs[2]);
}

/// `falloff` works with luxtest's textured latlong dome (2048 × 1024) on the default (GPU) path:
/// the kernel's map is within 1e-4 of the CPU reference's irradiance (irradiance/latlong_rows.wgsl),
/// and every pixel of a plane receives the same value (a dome is at infinity).
#[test]
fn falloff_of_a_textured_dome_matches_the_reference() {
    let Some(_) = common::gpu() else { return };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("f.exr");
    let o = luxeval(&[
        "falloff",
        &luxtest("dome.usda"),
        "--time",
        "1",
        "--origin",
        "-1,0,-1",
        "--u",
        "2,0,0",
        "--v",
        "0,0,2",
        "--res",
        "8,4",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let scene = Stage::load(Path::new(&luxtest("dome.usda")), Some(1.0)).unwrap();
    let lights = scene.evaluable(&[]).unwrap();
    // u × v = (2,0,0) × (0,0,2) = (0,−4,0): the receivers face −Y.
    let want = Evaluator::cpu()
        .irradiance(&lights, &[[0.0; 3]], &[[0.0, -1.0, 0.0]], Accumulate::Sum)
        .unwrap()[0];
    let map = luxeval_cli::io::exr::read_exr(&out).unwrap();
    let px = &map.rgb;
    assert!(px.iter().all(|p| *p == px[0]), "{:?}", &px[..2]);
    for c in 0..3 {
        let rel = (f64::from(px[0][c]) - f64::from(want[c])).abs() / f64::from(want[c]);
        assert!(rel < 1e-4, "{:?} vs {want:?}", px[0]);
    }
    assert!(want[0] > 0.0);
}

/// Blender's studio map (tests/data/textures/README.md). The DWAB original decodes (the `exr`
/// crate decodes DWAA/DWAB since 1.74) to exactly the texels of the ZIP half re-encoding that
/// OpenEXR wrote from it: with the nearest filter, emission through the CLI is the same for both
/// stages (the ZIP stage's intensity is 2). The map evaluates on both paths: `check` passes,
/// every value is finite and non-negative, and irradiance is positive for every normal.
#[test]
fn blender_studio_maps_decode_and_evaluate() {
    let dir = tempfile::tempdir().unwrap();
    let mut outs = Vec::new();
    for stage in ["studio_dwab_dome.usda", "studio_dome.usda"] {
        let out = dir.path().join(format!("{stage}.npy"));
        let o = luxeval(&[
            "emission",
            &texture_data(stage),
            "--dirs",
            &asset("dirs.npy"),
            "-o",
            out.to_str().unwrap(),
            "--device",
            "cpu",
            "--texture-filter",
            "nearest",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        outs.push(read_npy_f32(&out).1);
    }
    let halved: Vec<f32> = outs[1].iter().map(|v| v / 2.0).collect();
    assert_eq!(outs[0], halved);

    let scene = Stage::load(Path::new(&texture_data("studio_dome.usda")), None).unwrap();
    let lights = scene.evaluable(&[]).unwrap();
    let dirs = npy::read_directions(Path::new(&asset("dirs.npy"))).unwrap();
    let cpu = Evaluator::cpu()
        .emission(&lights, &dirs, Accumulate::Sum)
        .unwrap();
    assert!(cpu.iter().flatten().all(|c| c.is_finite() && *c >= 0.0));
    assert!(cpu.iter().any(|v| v[0] > 0.0));
    // GPU against the CPU reference, as `luxeval check` compares them: within 1e-4 of the
    // bilinear footprint's largest texel (an HDR map's neighbouring texels differ 100-fold; see
    // check::texture_floor), texel and face edges excluded.
    if let Some(gpu) = common::gpu() {
        let r = luxeval::Reference::new(&lights[0], luxeval::TemperatureMode::Spec).unwrap();
        let report = luxeval::check_against_reference(&gpu, &[r], 4000, 1).unwrap();
        for row in &report.rows {
            assert!(row.pass, "{row:?}");
        }
        assert!(report.samples >= 8000, "{}", report.samples);
    }
    let normals: Vec<[f32; 3]> = dirs[..16].to_vec();
    let e = Evaluator::cpu()
        .irradiance(&lights, &[[0.0; 3]; 16], &normals, Accumulate::Sum)
        .unwrap();
    assert!(
        e.iter()
            .all(|v| v.iter().all(|c| c.is_finite() && *c > 0.0)),
        "{e:?}"
    );
}

/// A falloff map the device cannot finish everywhere says so: a plane 0.1 in front of a 2 × 2
/// rect shaped by a dense IES profile (`testkit::ies::dense_profile`), on the GPU. On lavapipe
/// its receivers go over the loop budget, the CPU reference recomputes them, and stderr says
/// how many (`PreparedScene::host_recomputed_rows`); on any device the map is the CPU path's
/// within the tolerance of each.
#[test]
fn falloff_says_which_receivers_the_host_recomputed() {
    let Some(gpu) = common::gpu() else { return };
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("dense.ies"),
        luxeval::testkit::ies::dense_profile(),
    )
    .unwrap();
    let stage = dir.path().join("dense.usda");
    std::fs::write(
        &stage,
        "#usda 1.0\ndef RectLight \"L\" (\n    prepend apiSchemas = [\"ShapingAPI\"]\n)\n{\n    \
         float inputs:width = 2\n    float inputs:height = 2\n    \
         asset inputs:shaping:ies:file = @dense.ies@\n}\n",
    )
    .unwrap();
    let mut maps = Vec::new();
    for device in ["gpu", "cpu"] {
        let out = dir.path().join(format!("{device}.exr"));
        let o = luxeval(&[
            "falloff",
            stage.to_str().unwrap(),
            "--origin",
            "-0.5,-0.5,-0.1",
            "--u",
            "1,0,0",
            "--v",
            "0,1,0",
            "--res",
            "4,2",
            "--device",
            device,
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let said = stderr(&o).contains("irradiance rows were recomputed on the CPU reference");
        if device == "cpu" {
            assert!(!said, "{}", stderr(&o));
        } else if gpu.device_name().contains("llvmpipe") {
            assert!(said, "no note on lavapipe: {}", stderr(&o));
            assert!(
                stderr(&o).contains("of 8 irradiance rows"),
                "{}",
                stderr(&o)
            );
        }
        maps.push(luxeval_cli::io::exr::read_exr(&out).unwrap().rgb);
    }
    for (g, c) in maps[0].iter().zip(&maps[1]) {
        for k in 0..3 {
            assert!(
                c[k] > 0.0 && (g[k] - c[k]).abs() <= 2e-4 * c[k],
                "{g:?} vs {c:?}"
            );
        }
    }
}
