//! Command-line integration tests (DESIGN.md §4): outputs equal the library's results, exit
//! codes and messages for bad input, and no partial output file after a failure; `lights`,
//! `--help`, `bench --command`, `check`, and a headless machine's quiet. Irradiance and
//! falloff maps: maps.rs.

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
fn lights_json_lists_every_input_and_whether_authored() {
    let o = luxeval(&["lights", &asset("studio.usda"), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let lights = v["lights"].as_array().unwrap();
    assert_eq!(lights.len(), 6);
    let key = lights.iter().find(|l| l["path"] == "/lights/key").unwrap();
    let inputs = key["inputs"].as_array().unwrap();
    let width = inputs.iter().find(|i| i["name"] == "inputs:width").unwrap();
    assert_eq!(width["authored"], true);
    let diffuse = inputs
        .iter()
        .find(|i| i["name"] == "inputs:diffuse")
        .unwrap();
    assert_eq!(diffuse["authored"], false);
}

/// `lights --json` lists each mesh light (triangle count, world area, tint and its source,
/// doubleSided, subdivision), each portal (size, multiplier, the domes naming it) and each
/// dome's portals (DESIGN.md §7, §8), with the numbers usd-core and NumPy computed for the
/// fixture (tests/data/usd/expected/mesh_lights.json, its earliest-time sample); the text
/// lists the same, and says the lights are read, not evaluated yet.
#[test]
fn lights_lists_mesh_lights_and_portals() {
    let scene = repo_file("tests/data/usd/mesh/mesh_lights.usda");
    let exp: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(repo_file("tests/data/usd/expected/mesh_lights.json")).unwrap(),
    )
    .unwrap();
    let earliest = &exp["samples"][0];
    assert!(earliest["time"].is_null());
    let o = luxeval(&["lights", &scene, "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let lights = v["lights"].as_array().unwrap();
    let record = |path: &str| lights.iter().find(|l| l["path"] == path).unwrap();
    for e in earliest["meshes"].as_array().unwrap() {
        let l = record(e["path"].as_str().unwrap());
        assert_eq!(l["evaluable"], false, "{l}");
        let m = &l["mesh"];
        assert_eq!(m["triangles"], e["triangles"], "{l}");
        let (area, want) = (m["area"].as_f64().unwrap(), e["area"].as_f64().unwrap());
        assert!((area - want).abs() <= 1e-6 * want, "{l}");
        assert_eq!(m["double_sided"], e["double_sided"], "{l}");
        assert_eq!(m["subdivision_scheme"], e["subdivision_scheme"], "{l}");
        for k in 0..3 {
            let t = m["tint"][k].as_f64().unwrap();
            assert!((t - e["tint"][k].as_f64().unwrap()).abs() <= 1e-6, "{l}");
        }
        assert!(
            m["tint_source"].as_str().is_some_and(|s| !s.is_empty()),
            "{l}"
        );
    }
    for e in earliest["portals"].as_array().unwrap() {
        let l = record(e["path"].as_str().unwrap());
        assert_eq!(l["portal"]["width"], e["width"], "{l}");
        assert_eq!(l["portal"]["height"], e["height"], "{l}");
        assert_eq!(l["portal"]["domes"], e["domes"], "{l}");
    }
    // intensity 2 · 2^exposure 1 · color (1, 0.5, 0.25).
    assert_eq!(
        record("/World/Window")["portal"]["multiplier"],
        serde_json::json!([4.0, 2.0, 1.0])
    );
    for e in earliest["domes"].as_array().unwrap() {
        assert_eq!(record(e["path"].as_str().unwrap())["portals"], e["portals"]);
    }
    // Other lights' records have no such fields.
    assert!(record("/World/Sky").get("mesh").is_none());

    let o = luxeval(&["lights", &scene]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    for want in [
        "/World/Signs/Quads (Mesh) [read, not evaluated yet]",
        "  mesh  4 triangles (0 hole faces removed, 0 degenerate triangles dropped), area 4.000000, doubleSided false",
        "  tint  (2, 1, 0.5) from emissiveColor of /World/Looks/Glow/Surface (authored)",
        "/World/Window (PortalLight) [read, not evaluated yet]",
        "  portal  2 x 1.5, multiplier (4, 2, 1), named by /World/Sky",
        "  portal  1 x 1, multiplier (1, 1, 1), named by no dome",
        "  portals  /World/Window, /World/Signs/Quads",
    ] {
        assert!(text.contains(want), "{want:?} not in:\n{text}");
    }

    // Bad topology: listed with the attribute named, refused by the queries.
    let o = luxeval(&[
        "lights",
        &repo_file("tests/data/usd/mesh/bad/count_below_3.usda"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("/Bad: faceVertexCounts") && text.contains("the queries refuse this light"),
        "{text}"
    );
}

/// The fixture of what a renderer applies and luxeval does not (tests/data/usd/unapplied/,
/// made with usd-core by tools/gen_usd_fixtures.py --only-unapplied).
fn unapplied_scene() -> String {
    repo_file("tests/data/usd/unapplied/unapplied.usda")
}

/// `lights` lists each light's filters, its restricting link collections and its shaping inputs
/// without ShapingAPI, and the stage's light lists, each marked as not applied; `--json` has
/// them as fields, as usd-core composes them (tests/data/usd/expected/unapplied_links.json).
#[test]
fn lights_says_what_luxeval_does_not_apply() {
    let o = luxeval(&["lights", &unapplied_scene()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    let block = |path: &str| -> String {
        let start = text
            .find(&format!("\n{path} ("))
            .unwrap_or_else(|| panic!("{path} not listed:\n{text}"));
        let rest = &text[start + 1..];
        rest[..rest.find("\n\n").unwrap_or(rest.len())].to_string()
    };
    for (path, says) in [
        (
            "/World/Filtered",
            &["light:filters  /World/Gobo, /World/Barn  (not applied)"][..],
        ),
        (
            "/World/Linked",
            &[
                "collection:lightLink  includeRoot false, includes /World/Geo/Floor, \
                 excludes /World/Geo/Floor/Tile, expansionRule explicitOnly  (not applied)",
                "collection:shadowLink  includeRoot true, excludes /World/Geo/Wall",
                "not applied by luxeval: light linking (collection:lightLink), shadow linking",
            ],
        ),
        (
            "/World/UnshapedSpot",
            &[
                "without ShapingAPI  inputs:shaping:cone:angle, inputs:shaping:cone:softness",
                "ShapingAPI is not applied",
            ],
        ),
        // Mapped into the instance, as usd-core maps them.
        (
            "/World/Inst/Key",
            &[
                "light:filters  /World/Inst/Gobo  (not applied)",
                "includes /World/Inst/Prop",
            ],
        ),
    ] {
        let b = block(path);
        for s in says {
            assert!(b.contains(s), "{path} lacks {s:?}:\n{b}");
        }
    }
    // ShapingAPI applied, an empty or unrestricting collection: nothing to say.
    for quiet in ["/World/ShapedSpot", "/World/Quiet"] {
        let b = block(quiet);
        assert!(
            !b.contains("not applied") && !b.contains("warning") && !b.contains("ShapingAPI  "),
            "{b}"
        );
    }
    assert!(text.contains(
        "lightList on /World (ListAPI): /World/Filtered, /World/Linked, /World/Rig/Key; \
         cacheBehavior consumeAndHalt"
    ));
    assert!(text.contains("lightList on /Lists (LightListAPI): /World/Linked;"));

    let o = luxeval(&["lights", &unapplied_scene(), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let usd_core: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(repo_file("tests/data/usd/expected/unapplied_links.json"))
            .unwrap(),
    )
    .unwrap();
    let lights = v["lights"].as_array().unwrap();
    for (ours, theirs) in lights.iter().zip(usd_core["lights"].as_array().unwrap()) {
        assert_eq!(ours["path"], theirs["path"]);
        assert_eq!(ours["light_filters"], theirs["filters"], "{}", ours["path"]);
        assert!(ours["link_collections"].is_array() && ours["shaping_without_api"].is_array());
    }
    let linked = lights
        .iter()
        .find(|l| l["path"] == "/World/Linked")
        .unwrap();
    let link = &linked["link_collections"][0];
    assert_eq!(
        (
            &link["name"],
            &link["include_root"],
            &link["expansion_rule"]
        ),
        (
            &serde_json::json!("lightLink"),
            &serde_json::json!(false),
            &serde_json::json!("explicitOnly")
        )
    );
    // At the stage's startTimeCode (0), as usd-core reads the lists then.
    let at_start = usd_core["samples"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["time"] == 0)
        .unwrap();
    assert_eq!(v["light_lists"], at_start["light_lists"]);
}

/// A query command says once, on stderr, what the lights it evaluates have that luxeval does
/// not apply, counted by kind, the same text on every run; it says nothing for a light (or a
/// stage) that has none of it.
#[test]
fn a_query_warns_once_about_what_it_does_not_apply() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("e.npy");
    let run = |extra: &[&str]| {
        let scene = unapplied_scene();
        let mut args = vec!["emission", &scene, "--dirs", &asset("dirs.npy")]
            .into_iter()
            .map(str::to_string)
            .collect::<Vec<_>>();
        args.extend(["-o", out.to_str().unwrap(), "--device", "cpu"].map(str::to_string));
        args.extend(extra.iter().map(|s| s.to_string()));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = luxeval(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let err = stderr(&o);
        err.lines()
            .filter(|l| l.contains("not applied by luxeval"))
            .map(str::to_string)
            .collect::<Vec<_>>()
    };
    // Counted by hand from the fixture: filters on Filtered, Rig/Key, Inst/Key; light links on
    // Linked, Expr, Rig/Key, Inst/Key; shadow links on Linked, RootOff; shaping inputs
    // without ShapingAPI on UnshapedSpot; light lists on /World, /Lists, /Bare.
    let want = format!(
        "warning: {}: 3 lights have light filters, 4 have light-link collections, \
         2 have shadow-link collections, 1 has shaping inputs without ShapingAPI (evaluated \
         unshaped), the stage has 3 light lists (lightList): not applied by luxeval (see \
         `luxeval lights`)",
        unapplied_scene()
    );
    assert_eq!(run(&[]), vec![want.clone()]);
    assert_eq!(run(&[]), vec![want], "the same text on every run");
    // Only the selected lights count; the stage's light lists always do.
    assert_eq!(
        run(&["--light", "/World/ShapedSpot"]),
        vec![format!(
            "warning: {}: the stage has 3 light lists (lightList): not applied by luxeval \
             (see `luxeval lights`)",
            unapplied_scene()
        )]
    );
    assert_eq!(
        run(&[
            "--light",
            "/World/Filtered",
            "--light",
            "/World/UnshapedSpot"
        ]),
        vec![format!(
            "warning: {}: 1 light has light filters, 1 has shaping inputs without ShapingAPI \
             (evaluated unshaped), the stage has 3 light lists (lightList): not applied by \
             luxeval (see `luxeval lights`)",
            unapplied_scene()
        )]
    );
    // A stage with none of it: no such line.
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
    assert!(!stderr(&o).contains("not applied"), "{}", stderr(&o));
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
