//! Streaming `.npy` input and output in the query commands (docs/INPUTS.md "Streaming"): results
//! evaluated chunk by chunk (`LUXEVAL_CHUNK_ROWS`) are bit for bit those of one chunk and of the
//! library, for every input layout. Refusals while streaming: stream_refusals.rs.

use crate::common;
use crate::support::*;

use std::path::Path;
use std::process::Output;

use luxeval::{Accumulate, Evaluator, Stage};
use luxeval_cli::io::npy;

/// Runs `luxeval ARGS` with `LUXEVAL_CHUNK_ROWS` set to `chunk` (unset: the default).
pub(crate) fn luxeval(args: &[&str], chunk: Option<&str>) -> Output {
    let mut c = command();
    c.args(args);
    match chunk {
        Some(rows) => c.env("LUXEVAL_CHUNK_ROWS", rows),
        None => c.env_remove("LUXEVAL_CHUNK_ROWS"),
    };
    c.output().expect("run luxeval")
}

pub(crate) fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A deterministic pseudo-random sequence in [-1, 1) (no dependency on a RNG crate's stream).
pub(crate) fn lcg(seed: u64) -> impl FnMut() -> f64 {
    let mut x = seed;
    move || {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (x >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

/// `n` rows: directions (no zero row) or points within a few metres of the studio.
pub(crate) fn rows(n: usize, seed: u64, scale: f64) -> Vec<[f64; 3]> {
    let mut r = lcg(seed);
    (0..n)
        .map(|_| {
            let v = [r() * scale, r() * scale, r() * scale];
            if v.iter().all(|c| *c == 0.0) {
                [0.0, 1.0, 0.0]
            } else {
                v
            }
        })
        .collect()
}

pub(crate) fn write_f32(path: &Path, rows: &[[f64; 3]]) {
    let f: Vec<[f32; 3]> = rows.iter().map(|r| r.map(|v| v as f32)).collect();
    npy::write_f32(path, &[f.len() as u64, 3], &f).unwrap();
}

pub(crate) fn write_f64(path: &Path, rows: &[[f64; 3]]) {
    use npyz::WriterBuilder;
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut w = npyz::WriteOptions::<f64>::new()
        .default_dtype()
        .shape(&[rows.len() as u64, 3])
        .writer(file)
        .begin_nd()
        .unwrap();
    w.extend(rows.iter().flatten().copied()).unwrap();
    w.finish().unwrap();
}

/// Runs a query and returns the output's bytes (asserting success).
pub(crate) fn run_bytes(args: &[&str], out: &Path, chunk: Option<&str>) -> Vec<u8> {
    let _ = std::fs::remove_file(out);
    let o = luxeval(args, chunk);
    assert!(
        o.status.success(),
        "{args:?} chunk {chunk:?}: {}",
        stderr(&o)
    );
    std::fs::read(out).unwrap()
}

#[test]
fn chunked_emission_and_radiance_equal_one_chunk_and_the_library() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // 1000 rows: no chunk size below divides it into equal chunks but 1 and 1000.
    let n = 1000;
    let dirs = d.join("dirs.npy");
    let points = d.join("points.npy");
    write_f32(&dirs, &rows(n, 1, 1.0));
    write_f32(&points, &rows(n, 2, 3.0));
    let out = d.join("out.npy");
    let scene = asset("studio.usda");
    let lights = Stage::load(Path::new(&scene), None)
        .unwrap()
        .evaluable(&[])
        .unwrap();
    let cpu = Evaluator::cpu();
    let dv = npy::read_directions(&dirs).unwrap();
    let pv = npy::read_points(&points).unwrap();

    for per_light in [false, true] {
        let acc = if per_light {
            Accumulate::PerLight
        } else {
            Accumulate::Sum
        };
        let mut emission = vec!["emission", &scene, "--dirs", s(&dirs), "-o", s(&out)];
        let mut radiance = vec![
            "radiance",
            &scene,
            "--points",
            s(&points),
            "--dirs",
            s(&dirs),
            "-o",
            s(&out),
        ];
        for a in [&mut emission, &mut radiance] {
            a.extend(["--device", "cpu"]);
            if per_light {
                a.push("--per-light");
            }
        }
        for (args, want) in [
            (&emission, cpu.emission(&lights, &dv, acc).unwrap()),
            (&radiance, cpu.radiance(&lights, &pv, &dv, acc).unwrap()),
        ] {
            let whole = run_bytes(args, &out, Some("1000000"));
            for chunk in ["1", "7", "333", "999"] {
                assert!(
                    run_bytes(args, &out, Some(chunk)) == whole,
                    "{args:?}: chunks of {chunk} rows differ from one chunk"
                );
            }
            // The default chunk (larger than the array) too.
            assert!(run_bytes(args, &out, None) == whole, "{args:?}");
            let (shape, values) = f32_values(&whole);
            let want_shape = if per_light {
                vec![lights.len() as u64, n as u64, 3]
            } else {
                vec![n as u64, 3]
            };
            assert_eq!(shape, want_shape, "{args:?}");
            let want: Vec<f32> = want.iter().flatten().copied().collect();
            assert!(
                values
                    .iter()
                    .map(|v| v.to_bits())
                    .eq(want.iter().map(|v| v.to_bits())),
                "{args:?}: the CLI differs from the library"
            );
        }
    }
    assert_eq!(files_in(d), vec![dirs, out, points], "no stray temporaries");
}

#[test]
fn chunked_irradiance_and_intensity_equal_one_chunk() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let n = 61;
    let points = d.join("points.npy");
    let normals = d.join("normals.npy");
    write_f32(&points, &rows(n, 3, 2.0));
    write_f32(&normals, &rows(n, 4, 1.0));
    let out = d.join("out.npy");
    let scene = asset("studio.usda");
    let irradiance = [
        "irradiance",
        &scene,
        "--points",
        s(&points),
        "--normals",
        s(&normals),
        "-o",
        s(&out),
        "--device",
        "cpu",
        "--per-light",
    ];
    let intensity = [
        "intensity",
        &scene,
        "--dirs",
        s(&normals),
        "-o",
        s(&out),
        "--device",
        "cpu",
    ];
    for args in [&irradiance[..], &intensity[..]] {
        let whole = run_bytes(args, &out, Some("61"));
        for chunk in ["8", "60"] {
            assert!(
                run_bytes(args, &out, Some(chunk)) == whole,
                "{args:?}: chunks of {chunk} rows differ from one chunk"
            );
        }
    }
}

#[test]
fn float64_and_fortran_inputs_stream_like_float32() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let n = 257;
    // Directions of every magnitude float64 holds: normalised in f64 as they are read.
    let mut r = rows(n, 5, 1.0);
    r[100] = [1e300, -2e300, 5e299];
    r[200] = [1e-320, 0.0, -3e-320];
    let dirs64 = d.join("dirs64.npy");
    write_f64(&dirs64, &r);
    let out = d.join("out.npy");
    let scene = asset("studio.usda");
    let args = [
        "emission",
        &scene,
        "--dirs",
        s(&dirs64),
        "-o",
        s(&out),
        "--device",
        "cpu",
    ];
    let whole = run_bytes(&args, &out, Some("100000"));
    assert!(run_bytes(&args, &out, Some("10")) == whole);
    let lights = Stage::load(Path::new(&scene), None)
        .unwrap()
        .evaluable(&[])
        .unwrap();
    let want = Evaluator::cpu()
        .emission(
            &lights,
            &npy::read_directions(&dirs64).unwrap(),
            Accumulate::Sum,
        )
        .unwrap();
    let (_, values) = f32_values(&whole);
    assert_eq!(values, want.iter().flatten().copied().collect::<Vec<_>>());

    // NumPy's layouts (tests/data/npy, written by tools/gen_npy_fixtures.py), read a row at a
    // time: Fortran order is read column by column at each chunk's offsets.
    let data = crate::repo().join("tests/data/npy");
    let c_order = data.join("dirs_f32.npy");
    let c_args = [
        "emission",
        &scene,
        "--dirs",
        s(&c_order),
        "-o",
        s(&out),
        "--device",
        "cpu",
    ];
    let want = run_bytes(&c_args, &out, None);
    for f in [
        "dirs_f32_fortran.npy",
        "dirs_f64.npy",
        "dirs_f32_bigendian.npy",
    ] {
        let p = data.join(f);
        let args = [
            "emission",
            &scene,
            "--dirs",
            s(&p),
            "-o",
            s(&out),
            "--device",
            "cpu",
        ];
        for chunk in ["1", "2", "3"] {
            assert!(
                run_bytes(&args, &out, Some(chunk)) == want,
                "{f}, chunk {chunk}"
            );
        }
    }
}

/// The GPU path reuses the scene's buffers from chunk to chunk (and reallocates for the last,
/// shorter one): chunked results equal one dispatch bit for bit.
#[test]
fn gpu_chunked_results_equal_one_chunk() {
    if common::gpu().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let n = 1000;
    let dirs = d.join("dirs.npy");
    let points = d.join("points.npy");
    write_f32(&dirs, &rows(n, 13, 1.0));
    write_f32(&points, &rows(n, 14, 3.0));
    let out = d.join("out.npy");
    let scene = asset("studio.usda");
    let emission = [
        "emission",
        &scene,
        "--dirs",
        s(&dirs),
        "-o",
        s(&out),
        "--device",
        "gpu",
        "--per-light",
    ];
    let radiance = [
        "radiance",
        &scene,
        "--points",
        s(&points),
        "--dirs",
        s(&dirs),
        "-o",
        s(&out),
        "--device",
        "gpu",
    ];
    let irradiance = [
        "irradiance",
        &scene,
        "--points",
        s(&points),
        "--normals",
        s(&dirs),
        "-o",
        s(&out),
        "--device",
        "gpu",
    ];
    for args in [&emission[..], &radiance[..], &irradiance[..]] {
        let whole = run_bytes(args, &out, Some("1000"));
        assert!(run_bytes(args, &out, Some("333")) == whole, "{args:?}");
    }
}
