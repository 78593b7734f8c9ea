//! Refusals while the query commands stream (docs/INPUTS.md "Streaming"): a bad row or an
//! overflowing result in a later chunk is named by its row in the whole file, exits 2 and leaves
//! no output (and an existing output untouched); truncated files and pipes, mismatched row
//! counts and a bad `LUXEVAL_CHUNK_ROWS` are refused.

use crate::stream::{luxeval, rows, run_bytes, s, write_f32, write_f64};
use crate::support::*;

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
