//! Streaming `.npy` input and output in the query commands (docs/INPUTS.md "Streaming"): results
//! evaluated chunk by chunk (`LUXEVAL_CHUNK_ROWS`) are bit for bit those of one chunk and of the
//! library; a bad row in a later chunk is named by its row in the whole file, exits 2 and leaves
//! no output (and an existing output untouched).

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use luxeval::{Accumulate, Evaluator, Stage};
use luxeval_cli::io::npy;

fn luxeval(args: &[&str], chunk: Option<&str>) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_luxeval"));
    c.args(args);
    match chunk {
        Some(rows) => c.env("LUXEVAL_CHUNK_ROWS", rows),
        None => c.env_remove("LUXEVAL_CHUNK_ROWS"),
    };
    c.output().expect("run luxeval")
}

fn asset(name: &str) -> String {
    crate::repo()
        .join("assets")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

fn bad(name: &str) -> String {
    crate::repo()
        .join("tests/data/bad")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A deterministic pseudo-random sequence in [-1, 1) (no dependency on a RNG crate's stream).
fn lcg(seed: u64) -> impl FnMut() -> f64 {
    let mut x = seed;
    move || {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (x >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

/// `n` rows: directions (no zero row) or points within a few metres of the studio.
fn rows(n: usize, seed: u64, scale: f64) -> Vec<[f64; 3]> {
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

fn write_f32(path: &Path, rows: &[[f64; 3]]) {
    let f: Vec<[f32; 3]> = rows.iter().map(|r| r.map(|v| v as f32)).collect();
    npy::write_f32(path, &[f.len() as u64, 3], &f).unwrap();
}

fn write_f64(path: &Path, rows: &[[f64; 3]]) {
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
fn run_bytes(args: &[&str], out: &Path, chunk: Option<&str>) -> Vec<u8> {
    let _ = std::fs::remove_file(out);
    let o = luxeval(args, chunk);
    assert!(
        o.status.success(),
        "{args:?} chunk {chunk:?}: {}",
        stderr(&o)
    );
    std::fs::read(out).unwrap()
}

fn f32_values(bytes: &[u8]) -> (Vec<u64>, Vec<f32>) {
    let f = npyz::NpyFile::new(bytes).unwrap();
    let shape = f.shape().to_vec();
    (shape, f.into_vec::<f32>().unwrap())
}

fn files_in(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    v.sort();
    v
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

#[test]
fn a_bad_row_in_a_later_chunk_names_its_row_and_leaves_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let n = 1000;
    let mut dr = rows(n, 6, 1.0);
    dr[523] = [0.0, f64::NAN, 1.0];
    let dirs = d.join("dirs_nan.npy");
    write_f32(&dirs, &dr);
    let mut pr = rows(n, 7, 3.0);
    pr[871] = [f64::INFINITY, 0.0, 0.0];
    let points = d.join("points_inf.npy");
    write_f32(&points, &pr);
    let good_dirs = d.join("dirs.npy");
    write_f32(&good_dirs, &rows(n, 8, 1.0));
    let mut zr = rows(n, 9, 1.0);
    zr[999] = [0.0, 0.0, 0.0];
    let zero_last = d.join("dirs_zero_last.npy");
    write_f64(&zero_last, &zr);
    let scene = asset("studio.usda");
    let out = d.join("out.npy");
    let before = files_in(d);

    let cases: [(Vec<&str>, &[&str]); 3] = [
        (
            vec!["emission", &scene, "--dirs", s(&dirs)],
            &["dirs_nan.npy", "row 523 ", "not finite"],
        ),
        (
            vec![
                "radiance",
                &scene,
                "--points",
                s(&points),
                "--dirs",
                s(&good_dirs),
            ],
            &["points_inf.npy", "row 871 ", "not finite"],
        ),
        (
            vec!["emission", &scene, "--dirs", s(&zero_last), "--per-light"],
            &["dirs_zero_last.npy", "row 999 ", "zero vector"],
        ),
    ];
    for (mut args, says) in cases {
        args.extend(["-o", s(&out), "--device", "cpu"]);
        for chunk in ["100", "7"] {
            // No output yet: none is left behind.
            let o = luxeval(&args, Some(chunk));
            assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
            for w in says {
                assert!(stderr(&o).contains(w), "{args:?}: {w:?} in {}", stderr(&o));
            }
            assert_eq!(files_in(d), before, "{args:?}: a file was left behind");
            // An existing output is left as it was.
            std::fs::write(&out, b"the previous output").unwrap();
            let o = luxeval(&args, Some(chunk));
            assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
            assert_eq!(std::fs::read(&out).unwrap(), b"the previous output");
            std::fs::remove_file(&out).unwrap();
            assert_eq!(files_in(d), before, "{args:?}: a temporary was left behind");
        }
    }
}

#[test]
fn a_result_overflowing_in_a_later_chunk_names_its_row() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A point light at the origin: a receiver 1e-30 below it overflows float32; the others
    // are a metre away.
    let n = 50;
    let mut p = vec![[0.0, -1.0, 0.0]; n];
    p[37] = [0.0, 1e-30, 0.0];
    let points = d.join("points.npy");
    write_f32(&points, &p);
    let normals = d.join("normals.npy");
    write_f32(&normals, &vec![[0.0, -1.0, 0.0]; n]);
    let out = d.join("out.npy");
    let scene = bad("point_light.usda");
    for per_light in [false, true] {
        let mut args = vec![
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
        ];
        if per_light {
            args.push("--per-light");
        }
        let o = luxeval(&args, Some("10"));
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(
            stderr(&o).contains("row 37 ") && stderr(&o).contains("overflows float32"),
            "{}",
            stderr(&o)
        );
        assert!(!out.exists());
    }
}

#[test]
fn truncated_files_and_mismatched_rows_are_refused_before_evaluation() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let dirs = d.join("dirs.npy");
    write_f32(&dirs, &rows(100, 10, 1.0));
    let bytes = std::fs::read(&dirs).unwrap();
    let cut = d.join("cut.npy");
    std::fs::write(&cut, &bytes[..bytes.len() - 5]).unwrap();
    let padded = d.join("padded.npy");
    std::fs::write(&padded, [&bytes[..], b"x"].concat()).unwrap();
    let short = d.join("short.npy");
    write_f32(&short, &rows(99, 11, 1.0));
    let out = d.join("out.npy");
    let scene = asset("studio.usda");
    let cases: [(Vec<&str>, &[&str]); 3] = [
        (
            vec!["emission", &scene, "--dirs", s(&cut)],
            &["cut.npy", "ends inside the data"],
        ),
        (
            vec!["emission", &scene, "--dirs", s(&padded)],
            &["padded.npy", "more data than the 100 rows"],
        ),
        (
            vec![
                "irradiance",
                &scene,
                "--points",
                s(&dirs),
                "--normals",
                s(&short),
            ],
            &["dirs.npy", "100 rows", "short.npy", "99"],
        ),
    ];
    for (mut args, says) in cases {
        args.extend(["-o", s(&out), "--device", "cpu"]);
        let o = luxeval(&args, Some("10"));
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        for w in says {
            assert!(stderr(&o).contains(w), "{w:?} in {}", stderr(&o));
        }
        assert!(!out.exists());
    }
}

/// From a pipe, which tells no size, a truncated stream is found when it ends, after earlier
/// chunks were evaluated: still exit 2, naming the file, and no output.
#[cfg(unix)]
#[test]
fn a_truncated_pipe_is_refused_when_it_ends() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let dirs = d.join("dirs.npy");
    write_f32(&dirs, &rows(100, 12, 1.0));
    let bytes = std::fs::read(&dirs).unwrap();
    let pipe = d.join("pipe.npy");
    let c = std::ffi::CString::new(s(&pipe)).unwrap();
    // SAFETY: a valid C string.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o644) }, 0);
    let out = d.join("out.npy");
    let scene = asset("studio.usda");
    for (data, code, says) in [
        (
            bytes[..bytes.len() - 12 * 30].to_vec(),
            Some(2),
            "ends inside the data",
        ),
        (
            [&bytes[..], b"xyz"].concat(),
            Some(2),
            "more data than the 100 rows",
        ),
        (bytes.clone(), Some(0), ""),
    ] {
        let writer = {
            let pipe = pipe.clone();
            std::thread::spawn(move || {
                use std::io::Write;
                let mut f = std::fs::OpenOptions::new().write(true).open(pipe).unwrap();
                // The reader may stop early (it refuses the stream): a broken pipe is fine.
                let _ = f.write_all(&data);
            })
        };
        let args = [
            "emission",
            &scene,
            "--dirs",
            s(&pipe),
            "-o",
            s(&out),
            "--device",
            "cpu",
        ];
        let o = luxeval(&args, Some("10"));
        writer.join().unwrap();
        assert_eq!(o.status.code(), code, "{}", stderr(&o));
        assert!(stderr(&o).contains(says), "{says:?} in {}", stderr(&o));
        if code == Some(0) {
            let want = run_bytes(
                &[
                    "emission",
                    &scene,
                    "--dirs",
                    s(&dirs),
                    "-o",
                    s(&out),
                    "--device",
                    "cpu",
                ],
                &out,
                None,
            );
            assert!(std::fs::read(&out).unwrap() == want);
        } else {
            assert!(!out.exists());
        }
        let _ = std::fs::remove_file(&out);
    }
}

#[test]
fn chunk_rows_must_be_a_positive_integer() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.npy");
    for bad in ["0", "-3", "lots", "1.5", ""] {
        let o = luxeval(
            &[
                "emission",
                &asset("studio.usda"),
                "--dirs",
                &asset("dirs.npy"),
                "-o",
                s(&out),
                "--device",
                "cpu",
            ],
            Some(bad),
        );
        assert_eq!(o.status.code(), Some(2), "{bad:?}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("LUXEVAL_CHUNK_ROWS") && stderr(&o).contains("positive integer"),
            "{}",
            stderr(&o)
        );
        assert!(!out.exists());
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
