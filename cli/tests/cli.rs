//! Command-line integration tests (DESIGN.md §4): outputs equal the library's results, exit
//! codes and messages for bad input, and no partial output file after a failure; `--help`,
//! `bench --command`, `check`, and a headless machine's quiet. `lights`: lights.rs; irradiance
//! and falloff maps: maps.rs.

use crate::common;
use crate::support::*;

use std::path::Path;

use luxeval::Stage;
use luxeval::{Accumulate, Evaluator};
use luxeval_cli::io::npy;

#[test]
fn emission_on_the_bundled_scene_equals_the_library() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("e.npy");
    let o = luxeval(&[
        "emission",
        &asset("studio.usda"),
        "--dirs",
        &asset("dirs.npy"),
        "-o",
        out.to_str().unwrap(),
        "--device",
        "cpu",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (shape, values) = read_npy_f32(&out);
    assert_eq!(shape, vec![4096, 3]);
    let (lights, want) = studio_emission_on_cpu(Accumulate::Sum);
    assert_eq!(values, want);

    // Per light: (L, N, 3) in `lights` order, and each row matches the single-light result.
    let out = dir.path().join("p.npy");
    let o = luxeval(&[
        "emission",
        &asset("studio.usda"),
        "--dirs",
        &asset("dirs.npy"),
        "-o",
        out.to_str().unwrap(),
        "--device",
        "cpu",
        "--per-light",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (shape, values) = read_npy_f32(&out);
    assert_eq!(shape, vec![lights.len() as u64, 4096, 3]);
    assert_eq!(values, studio_emission_on_cpu(Accumulate::PerLight).1);
}

/// `--device auto`, the default (DESIGN.md §4): a hardware adapter when there is one, never a
/// software one. Where every adapter is a software one (lavapipe on CI), the default is the CPU
/// reference, bit for bit, and the first warning says so and why; `info` says what auto picks.
#[test]
fn the_default_device_is_a_hardware_gpu_else_the_cpu() {
    let info = luxeval(&["info", "--json"]);
    assert!(info.status.success(), "{}", stderr(&info));
    let info: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    let adapters = info["adapters"].as_array().unwrap();
    let hardware = adapters.iter().any(|a| a["device_type"] != "Cpu");
    let auto = info["auto"]["chosen"].as_str().unwrap();
    assert_eq!(auto.starts_with("the hardware adapter"), hardware, "{auto}");

    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str, device: &[&str]| {
        let out = dir.path().join(name);
        let mut args = vec![
            "emission",
            &asset("studio.usda"),
            "--dirs",
            &asset("dirs.npy"),
            "-o",
            out.to_str().unwrap(),
        ]
        .into_iter()
        .map(String::from)
        .collect::<Vec<_>>();
        args.extend(device.iter().map(|d| d.to_string()));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = luxeval(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        (stderr(&o), read_npy_f32(&out).1)
    };
    let (said, default) = run("default.npy", &[]);
    let (said_auto, auto_values) = run("auto.npy", &["--device", "auto"]);
    assert_eq!(default, auto_values);
    assert_eq!(said, said_auto);
    if !hardware {
        let (_, cpu) = run("cpu.npy", &["--device", "cpu"]);
        assert_eq!(
            default, cpu,
            "auto without a hardware adapter is the CPU reference"
        );
        let first = said
            .lines()
            .find(|l| l.starts_with("warning:"))
            .unwrap_or_default();
        assert!(
            first.starts_with("warning: --device auto: the CPU reference:"),
            "{said}"
        );
        let software: Vec<&str> = adapters.iter().filter_map(|a| a["name"].as_str()).collect();
        if !software.is_empty() {
            assert!(first.contains("only software ones"), "{first}");
            assert!(software.iter().all(|n| first.contains(n)), "{first}");
        }
    }
}

/// The bundled scene's lights and the library's CPU emission of them along assets/dirs.npy,
/// flattened as the CLI writes it.
fn studio_emission_on_cpu(acc: Accumulate) -> (Vec<luxeval::Light>, Vec<f32>) {
    let scene = Stage::load(Path::new(&asset("studio.usda")), None).unwrap();
    let lights = scene.evaluable(&[]).unwrap();
    // The CLI normalises directions in f64 as it reads them (docs/INPUTS.md).
    let dirs = npy::read_directions(Path::new(&asset("dirs.npy"))).unwrap();
    let want = Evaluator::cpu().emission(&lights, &dirs, acc).unwrap();
    (lights, want.iter().flatten().copied().collect())
}

#[test]
fn gpu_emission_and_radiance_match_the_cpu_through_the_cli() {
    let Some(_gpu) = common::gpu() else { return };
    let dir = tempfile::tempdir().unwrap();
    for (query, extra) in [
        ("emission", vec!["--dirs", "dirs.npy"]),
        (
            "radiance",
            vec!["--points", "floor_points.npy", "--dirs", "floor_up.npy"],
        ),
    ] {
        let mut files = vec![];
        for device in ["gpu", "cpu"] {
            let out = dir.path().join(format!("{query}_{device}.npy"));
            let mut args = vec![query.to_string(), asset("studio.usda")];
            for (k, a) in extra.iter().enumerate() {
                args.push(if k % 2 == 1 { asset(a) } else { a.to_string() });
            }
            args.extend([
                "-o".into(),
                out.to_string_lossy().into_owned(),
                "--device".into(),
                device.into(),
            ]);
            let o = command().args(&args).output().unwrap();
            assert!(o.status.success(), "{query} {device}: {}", stderr(&o));
            files.push(read_npy_f32(&out).1);
        }
        let (g, c) = (&files[0], &files[1]);
        for (k, (a, b)) in g.chunks(3).zip(c.chunks(3)).enumerate() {
            let scale = b.iter().fold(0f32, |m, v| m.max(v.abs()));
            let diff = a.iter().zip(b).fold(0f32, |m, (x, y)| m.max((x - y).abs()));
            assert!(
                diff <= 1e-4 * scale.max(1e-30) || diff == 0.0,
                "{query} row {k}: gpu {a:?} cpu {b:?}"
            );
        }
    }
}

#[test]
fn bad_inputs_exit_2_with_a_useful_message_and_leave_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.npy");
    let o_str = out.to_str().unwrap();
    // Malformed .usda: names the file and the line.
    let bad = dir.path().join("bad.usda");
    std::fs::write(
        &bad,
        "#usda 1.0\n\ndef SphereLight \"s\"\n{\n    float inputs:intensity = \n}\n",
    )
    .unwrap();
    let o = luxeval(&[
        "emission",
        bad.to_str().unwrap(),
        "--dirs",
        &asset("dirs.npy"),
        "-o",
        o_str,
        "--device",
        "cpu",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("bad.usda:5") || stderr(&o).contains("bad.usda:6"),
        "{}",
        stderr(&o)
    );
    // An invalid attribute value: names the stage, the prim and the attribute.
    let neg = dir.path().join("neg.usda");
    std::fs::write(
        &neg,
        "#usda 1.0\n\ndef SphereLight \"s\"\n{\n    float inputs:radius = -1\n}\n",
    )
    .unwrap();
    let o = luxeval(&[
        "emission",
        neg.to_str().unwrap(),
        "--dirs",
        &asset("dirs.npy"),
        "-o",
        o_str,
        "--device",
        "cpu",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("neg.usda")
            && stderr(&o).contains("/s")
            && stderr(&o).contains("inputs:radius"),
        "{}",
        stderr(&o)
    );
    // Missing scene.
    let o = luxeval(&[
        "emission",
        "/nonexistent/scene.usda",
        "--dirs",
        &asset("dirs.npy"),
        "-o",
        o_str,
        "--device",
        "cpu",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("/nonexistent/scene.usda"),
        "{}",
        stderr(&o)
    );
    // Wrongly shaped .npy.
    let npy_bad = crate::repo().join("tests/data/npy/dirs_shape_4x2.npy");
    let o = luxeval(&[
        "emission",
        &asset("studio.usda"),
        "--dirs",
        npy_bad.to_str().unwrap(),
        "-o",
        o_str,
        "--device",
        "cpu",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("dirs_shape_4x2.npy") && stderr(&o).contains("(N, 3)"),
        "{}",
        stderr(&o)
    );
    // Mismatched points/directions.
    let o = luxeval(&[
        "radiance",
        &asset("studio.usda"),
        "--points",
        &asset("floor_points.npy"),
        "--dirs",
        npy_bad.to_str().unwrap(),
        "-o",
        o_str,
        "--device",
        "cpu",
    ]);
    assert_eq!(o.status.code(), Some(2));
    // A light that is not in the stage.
    let o = luxeval(&[
        "emission",
        &asset("studio.usda"),
        "--dirs",
        &asset("dirs.npy"),
        "-o",
        o_str,
        "--device",
        "cpu",
        "--light",
        "/lights/nope",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("/lights/nope"), "{}", stderr(&o));
    // Nothing was written, not even a temporary.
    let mut left = files_in(dir.path());
    left.sort();
    assert_eq!(left, vec![bad, neg]);
}

#[test]
fn help_explains_every_subcommand() {
    let o = luxeval(&["--help"]);
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    for sub in [
        "info",
        "lights",
        "emission",
        "radiance",
        "irradiance",
        "falloff",
        "check",
        "bench",
    ] {
        assert!(text.contains(sub), "--help lacks {sub}");
        let o = luxeval(&[sub, "--help"]);
        assert!(o.status.success(), "{sub} --help");
    }
}

/// `bench --command` runs the command line as a child on each device (the GPU's only where an
/// adapter exists), last on the CPU: its output is then the CPU path's, and the report holds a
/// row per device with one wall time per run and the child's peak RSS.
#[test]
fn bench_command_times_the_command_on_each_device() {
    let gpu = common::gpu().is_some();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("e.npy");
    let command = format!(
        "emission {} --dirs {} -o {}",
        asset("studio.usda"),
        asset("dirs.npy"),
        out.display()
    );
    let o = luxeval(&[
        "bench",
        "--samples",
        "64",
        "--cpu-samples",
        "64",
        "--lights",
        "1",
        "--repeat",
        "2",
        "--no-dome",
        "--no-mesh",
        "--no-startup",
        "--json",
        "--command",
        &command,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let rows = v["commands"].as_array().unwrap();
    let devices: Vec<&str> = rows.iter().map(|r| r["device"].as_str().unwrap()).collect();
    assert_eq!(devices, if gpu { vec!["gpu", "cpu"] } else { vec!["cpu"] });
    for r in rows {
        assert_eq!(r["command"].as_str().unwrap(), command);
        let runs = r["runs_seconds"].as_array().unwrap();
        assert_eq!(runs.len(), 2);
        assert!(runs.iter().all(|t| t.as_f64().unwrap() > 0.0));
        // A process that loaded this binary holds more than a mebibyte.
        assert!(r["peak_rss_bytes"].as_u64().unwrap() > 1 << 20, "{r}");
    }
    assert_eq!(
        v["command_speedups"].as_array().unwrap().len(),
        usize::from(gpu)
    );
    let (shape, values) = read_npy_f32(&out);
    assert_eq!(shape, vec![4096, 3]);
    assert_eq!(values, studio_emission_on_cpu(Accumulate::Sum).1);
}

/// `bench` times a synthetic mesh light on each device: preparation, radiance and exact
/// irradiance, with the triangle count asked for (a bumpy torus: 2 · 21 · 17 = 714 ≥ 700).
#[test]
fn bench_times_a_mesh_light_on_each_device() {
    let gpu = common::gpu().is_some();
    let o = luxeval(&[
        "bench",
        "--samples",
        "256",
        "--cpu-samples",
        "256",
        "--lights",
        "1",
        "--repeat",
        "1",
        "--no-dome",
        "--no-startup",
        "--mesh-triangles",
        "700",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let rows = v["mesh"].as_array().unwrap();
    assert_eq!(rows.len(), 3 * (1 + usize::from(gpu)), "{rows:?}");
    for r in rows {
        let t = r["triangles"].as_u64().unwrap();
        assert!((700..800).contains(&t), "{r}");
        assert!(r["median_seconds"].as_f64().unwrap() > 0.0, "{r}");
        let expect = match r["query"].as_str().unwrap() {
            "prepare" => 1,
            "radiance" => 256,
            "irradiance" => 8,
            other => panic!("unexpected mesh row {other}"),
        };
        assert_eq!(r["samples"].as_u64().unwrap(), expect, "{r}");
    }
}

#[test]
fn check_passes_on_the_bundled_scene() {
    let Some(_gpu) = common::gpu() else { return };
    let o = luxeval(&["check", &asset("studio.usda"), "--samples", "500", "--json"]);
    assert!(
        o.status.success(),
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        stderr(&o)
    );
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(v["samples"].as_u64().unwrap() >= 500 * 6);
}

/// On a headless machine (no `XDG_RUNTIME_DIR`: render-farm nodes, CI runners, containers)
/// Mesa's Vulkan device-select layer prints "error: XDG_RUNTIME_DIR is invalid or not set"
/// while devices are enumerated; a successful command prints only luxeval's own output.
#[test]
fn a_headless_machine_hears_only_luxeval() {
    for args in [&["info"][..], &["info", "--json"]] {
        let o = command()
            .args(args)
            .env_remove("XDG_RUNTIME_DIR")
            .env_remove("NODEVICE_SELECT")
            .output()
            .unwrap();
        let err = stderr(&o);
        assert!(o.status.success(), "{err}");
        assert!(!err.contains("XDG_RUNTIME_DIR"), "{err}");
    }
}
