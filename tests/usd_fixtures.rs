//! The USD loader against Pixar's usd-core: every light of every fixture scene, at every time
//! code it authors and under the EarliestTime rule, must resolve to what usd-core resolved
//! (tests/data/usd/expected/*.json, written by tools/gen_usd_fixtures.py).
#![cfg(feature = "usd")]

use std::path::{Path, PathBuf};

use luxeval::{LightType, LuxError, Stage, StageLight, TimeRule, UsdStage, Value};
use serde_json::Value as Json;

fn data() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data")
}

fn expected(name: &str) -> Json {
    let path = data().join("usd/expected").join(format!("{name}.json"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap()
}

/// A resolved path as the fixtures spell it: relative to tests/data.
fn relative(resolved: &str) -> String {
    let prefix = format!("{}/", data().display());
    resolved
        .strip_prefix(&prefix)
        .unwrap_or(resolved)
        .to_string()
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    a == b || (a - b).abs() <= rel * b.abs().max(a.abs()).max(1e-30)
}

/// Compares one light with usd-core's record of it; returns every mismatch, each naming the
/// scene, time, prim and attribute.
fn compare(ctx: &str, ours: &StageLight, exp: &Json, problems: &mut Vec<String>) {
    let mut bad = |what: String| problems.push(format!("{ctx} {}: {what}", ours.path));
    if ours.path != exp["path"] {
        bad(format!("path, usd-core has {}", exp["path"]));
        return;
    }
    if ours.usd_type != exp["type"] {
        bad(format!(
            "type {} vs usd-core {}",
            ours.usd_type, exp["type"]
        ));
    }
    // usd-core's GetAppliedSchemas() drops authored names no registered schema declares;
    // ours lists them after the known ones (see luxeval::StageLight::applied_schemas).
    let mut applied: Vec<String> = exp["applied_schemas"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_str().unwrap().to_string())
        .collect();
    for s in exp["authored_api_schemas"].as_array().unwrap() {
        let s = s.as_str().unwrap().to_string();
        if !applied.contains(&s) {
            applied.push(s);
        }
    }
    if ours.applied_schemas != applied {
        bad(format!(
            "applied schemas {:?} vs usd-core {:?}",
            ours.applied_schemas, applied
        ));
    }
    if ours.visible != exp["visible"].as_bool().unwrap() {
        bad(format!(
            "visible {} vs usd-core {}",
            ours.visible, exp["visible"]
        ));
    }
    for r in 0..4 {
        for c in 0..4 {
            let want = exp["world"][r][c].as_f64().unwrap();
            let got = ours.world[r][c];
            if (got - want).abs() > 1e-9 * want.abs().max(1.0) {
                bad(format!("world[{r}][{c}] {got:e} vs usd-core {want:e}"));
            }
        }
    }
    let exp_inputs = exp["inputs"].as_array().unwrap();
    for input in &ours.inputs {
        let Some(e) = exp_inputs.iter().find(|e| e["name"] == input.name.as_str()) else {
            bad(format!("{}: usd-core has no such attribute", input.name));
            continue;
        };
        if input.authored != e["authored"].as_bool().unwrap() {
            bad(format!(
                "{}: authored {} vs usd-core {}",
                input.name, input.authored, e["authored"]
            ));
        }
        let v = &e["value"];
        // usd-core has no value at all where a blocked sample answers; luxeval reports the
        // schema fallback there (see luxeval::usd), so that is what to expect.
        let fallback;
        let v = if v.is_null() && !matches!(input.value, Value::Asset { .. }) {
            let applied: Vec<&str> = ours.applied_schemas.iter().map(String::as_str).collect();
            fallback = match luxeval::schema::fallback(&ours.usd_type, &applied, &input.name) {
                Some(luxeval::schema::Fallback::Float(f)) => serde_json::json!(f),
                Some(luxeval::schema::Fallback::Bool(b)) => serde_json::json!(b),
                Some(luxeval::schema::Fallback::Color(c)) => serde_json::json!(c),
                Some(luxeval::schema::Fallback::Token(t)) => serde_json::json!(t),
                other => panic!(
                    "{ctx} {}: no fallback for {} ({other:?})",
                    ours.path, input.name
                ),
            };
            &fallback
        } else {
            v
        };
        // USD stores these inputs as f32; usd-core and openusd may round an interpolated
        // value differently, and the table holds fallbacks as decimal f64 (0.53, not f32 0.53).
        let ok = match &input.value {
            Value::Float(x) => v.as_f64().is_some_and(|w| close(*x, w, 1e-6)),
            Value::Bool(b) => v.as_bool() == Some(*b),
            Value::Color(c) => v.as_array().is_some_and(|w| {
                w.len() == 3 && (0..3).all(|i| w[i].as_f64().is_some_and(|w| close(c[i], w, 1e-6)))
            }),
            Value::Token(t) => v.as_str() == Some(t.as_str()),
            Value::Asset { authored, resolved } => {
                if v.is_null() {
                    authored.is_empty() && resolved.is_none()
                } else {
                    v["authored"].as_str() == Some(authored.as_str())
                        && v["resolved"].as_str().map(str::to_string)
                            == resolved.as_deref().map(relative)
                }
            }
        };
        if !ok {
            bad(format!(
                "{} = {:?} vs usd-core {v}",
                input.name, input.value
            ));
        }
    }
}

/// Opens `scene` (relative to tests/data) and checks every light at every recorded time (also
/// the OpenUSD parity corpus's, tests/usd_parity.rs).
pub(crate) fn check_scene(fixture: &str) {
    let exp = expected(fixture);
    let path = data().join(exp["scene"].as_str().unwrap());
    let stage = UsdStage::open(&path).unwrap_or_else(|e| panic!("{fixture}: {e}"));
    let info = stage.info();
    assert_eq!(info.up_axis, exp["up_axis"].as_str().unwrap(), "{fixture}");
    assert_eq!(
        info.meters_per_unit,
        exp["meters_per_unit"].as_f64().unwrap(),
        "{fixture}"
    );
    assert_eq!(
        info.start_time_code,
        exp["start_time_code"].as_f64(),
        "{fixture}"
    );
    assert_eq!(
        info.end_time_code,
        exp["end_time_code"].as_f64(),
        "{fixture}"
    );

    let mut problems = Vec::new();
    let samples = exp["samples"].as_array().unwrap();
    assert!(!samples.is_empty());
    for sample in samples {
        let time = match sample["time"].as_f64() {
            Some(t) => TimeRule::Given(t),
            None => TimeRule::Earliest,
        };
        let ctx = format!("{fixture} @ {time:?}");
        let ours = stage
            .read_at(time)
            .unwrap_or_else(|e| panic!("{ctx}: {e}"))
            .lights;
        let theirs = sample["lights"].as_array().unwrap();
        let ours_paths: Vec<&str> = ours.iter().map(|l| l.path.as_str()).collect();
        let their_paths: Vec<&str> = theirs.iter().map(|l| l["path"].as_str().unwrap()).collect();
        if ours_paths != their_paths {
            problems.push(format!(
                "{ctx}: lights {ours_paths:?} vs usd-core {their_paths:?}"
            ));
            continue;
        }
        for (o, t) in ours.iter().zip(theirs) {
            compare(&ctx, o, t, &mut problems);
        }
    }
    assert!(
        problems.is_empty(),
        "{} mismatches with usd-core:\n{}",
        problems.len(),
        problems.join("\n")
    );
}

#[test]
fn luxtest_scenes_match_usd_core() {
    for name in [
        "cylinder",
        "disk",
        "distant",
        "dome",
        "iesDown",
        "iesLibPreview",
        "iesTest",
        "iesUp",
        "rect",
        "sphere",
        "visibleRect",
    ] {
        check_scene(&format!("luxtest_{name}"));
    }
}

#[test]
fn composition_usda_matches_usd_core() {
    check_scene("composition_root_usda");
}

#[test]
fn composition_usdc_matches_usd_core() {
    check_scene("composition_root_usdc");
}

#[test]
fn composition_usdz_matches_usd_core() {
    check_scene("composition_scene_usdz");
    check_scene("composition_rig_packaged_usdz");
}

/// A light inherits the transform of every Xformable ancestor, whatever its type (SkelRoot,
/// Skeleton, Volume, SpatialAudio, GenerativeProcedural), and none from prims that are not
/// Xformable (an untyped prim, a Scope), at every time, as usd-core computes it (it once got an
/// identity matrix under SkelRoot, Skeleton and Volume, silently).
#[test]
fn ancestors_of_every_xformable_type_match_usd_core() {
    check_scene("ancestors");
}

/// Lights written in every text form usd-core reads and openusd 0.8 alone refused (`//`
/// comments, `0.` and `.5`, an asset written as a string, `config`, a numeric bool,
/// `active = False`, a multi-line `"""` doc) resolve to what usd-core resolved; the MaterialX
/// reference and the missing sublayer beside them are left out, as usd-core leaves them out,
/// each with a warning naming the arc, the layer and the prim.
#[test]
fn every_text_form_usd_core_reads_matches_usd_core() {
    check_scene("reader_forms");
    let stage = UsdStage::open(&data().join("usd/reader/forms.usda")).unwrap();
    let w = stage.warnings();
    assert_eq!(w.len(), 2, "{w:#?}");
    assert!(
        w.iter().any(|w| w.contains("looks.mtlx@")
            && w.contains("</Looks>")
            && w.contains("format luxeval does not read")),
        "{w:#?}"
    );
    assert!(
        w.iter().any(|w| w.contains("@./missing_sublayer.usda@")
            && w.contains("forms.usda")
            && w.contains("cannot be found")),
        "{w:#?}"
    );
    // The same warnings, in the same order, every time the stage is opened.
    for _ in 0..3 {
        assert_eq!(
            UsdStage::open(&data().join("usd/reader/forms.usda"))
                .unwrap()
                .warnings(),
            w
        );
    }
}

/// The same scene as text, as Pixar's binary crate and packed in a usdz resolves to the same
/// lights; only asset paths differ, the usdz's resolving inside the package.
#[test]
fn usda_usdc_usdz_are_identical() {
    let dir = data().join("usd/composition");
    for time in [None, Some(0.0), Some(1.5), Some(3.0), Some(10.0)] {
        let a = Stage::load(&dir.join("root.usda"), time).unwrap();
        let c = Stage::load(&dir.join("root.usdc"), time).unwrap();
        let z = Stage::load(&dir.join("scene.usdz"), time).unwrap();
        assert_eq!(a.lights, c.lights, "usda vs usdc at {time:?}");
        assert_eq!(
            (&a.up_axis, a.meters_per_unit, a.time),
            (&c.up_axis, c.meters_per_unit, c.time)
        );
        assert_eq!(
            (&a.up_axis, a.meters_per_unit, a.time),
            (&z.up_axis, z.meters_per_unit, z.time)
        );
        assert_eq!(a.lights.len(), z.lights.len());
        let mut assets_checked = 0;
        for (la, lz) in a.lights.iter().zip(&z.lights) {
            let mut lz = lz.clone();
            for (ia, iz) in la.inputs.iter().zip(lz.inputs.iter_mut()) {
                if let (
                    Value::Asset {
                        authored: aa,
                        resolved: ra,
                    },
                    Value::Asset {
                        authored: az,
                        resolved: rz,
                    },
                ) = (&ia.value, &mut iz.value)
                {
                    assert_eq!(aa, az);
                    // <dir>/x/y.ies in the folder is <dir>/scene.usdz[x/y.ies] in the package.
                    let want = ra.as_ref().map(|r| {
                        let inner = r.strip_prefix(&format!("{}/", dir.display())).unwrap();
                        format!("{}[{inner}]", dir.join("scene.usdz").display())
                    });
                    assert_eq!(*rz, want, "{} {}", la.path, ia.name);
                    assets_checked += usize::from(want.is_some());
                    *rz = ra.clone();
                }
            }
            // The light's IES asset (shaping:ies:file) resolves the same way.
            let ies_of = |l: &luxeval::StageLight| {
                l.light
                    .as_ref()
                    .and_then(|l| l.shaping.as_ref())
                    .and_then(|s| s.ies.as_ref())
                    .and_then(|i| i.file.resolved.clone())
            };
            if let (Some(ra), Some(rz)) = (ies_of(la), ies_of(&lz)) {
                let inner = ra.strip_prefix(&format!("{}/", dir.display())).unwrap();
                assert_eq!(rz, format!("{}[{inner}]", dir.join("scene.usdz").display()));
                let ies = lz.light.as_mut().unwrap().shaping.as_mut().unwrap();
                ies.ies.as_mut().unwrap().file.resolved = Some(ra);
            }
            // And the light's texture (texture:file).
            let texture_of = |l: &luxeval::StageLight| {
                l.light
                    .as_ref()
                    .and_then(|l| l.texture.as_ref())
                    .and_then(|t| t.file.resolved.clone())
            };
            if let (Some(ra), Some(rz)) = (texture_of(la), texture_of(&lz)) {
                let inner = ra.strip_prefix(&format!("{}/", dir.display())).unwrap();
                assert_eq!(rz, format!("{}[{inner}]", dir.join("scene.usdz").display()));
                let t = lz.light.as_mut().unwrap().texture.as_mut().unwrap();
                t.file.resolved = Some(ra);
            }
            assert_eq!(*la, lz, "usda vs usdz at {time:?}");
        }
        assert!(assets_checked >= 4, "{assets_checked}");
    }
}

#[test]
fn packaged_assets_are_readable() {
    // What a later IES or texture reader needs: the resolved path opens through openusd's
    // resolver... and at least names the package and the inner file.
    let dir = data().join("usd/composition");
    let scene = Stage::load(&dir.join("rig_packaged.usdz"), None).unwrap();
    let spot = scene.lights.iter().find(|l| l.path == "/Rig/Spot").unwrap();
    let Some(Value::Asset { authored, resolved }) = spot
        .input("inputs:shaping:ies:file")
        .map(|i| i.value.clone())
    else {
        panic!("no ies:file");
    };
    assert_eq!(authored, "0/spot.ies");
    assert_eq!(
        resolved.as_deref(),
        Some(format!("{}[0/spot.ies]", dir.join("rig_packaged.usdz").display()).as_str())
    );
}

#[test]
fn time_rules() {
    let comp = data().join("usd/composition/root.usda");
    let sphere = data().join("luxtest/usd/sphere.usda");
    assert_eq!(Stage::load(&comp, None).unwrap().time, TimeRule::Earliest);
    assert_eq!(
        Stage::load(&sphere, None).unwrap().time,
        TimeRule::StartTimeCode(1.0)
    );
    assert_eq!(
        Stage::load(&sphere, Some(7.0)).unwrap().time,
        TimeRule::Given(7.0)
    );
    let e = Stage::load(&sphere, Some(f64::NAN)).unwrap_err();
    assert!(e.to_string().contains("--time"), "{e}");

    // Interpolation: /World/Anim intensity 10 @1 → 30 @3 (linear), normalize 0 @1, 1 @2 (held).
    let at = |t: f64| Stage::load(&comp, Some(t)).unwrap();
    let intensity = |s: &Stage| {
        let l = s.lights.iter().find(|l| l.path == "/World/Anim").unwrap();
        (
            l.input("inputs:intensity").unwrap().value.clone(),
            l.input("inputs:normalize").unwrap().value.clone(),
        )
    };
    assert_eq!(
        intensity(&at(1.5)),
        (Value::Float(15.0), Value::Bool(false))
    );
    assert_eq!(intensity(&at(2.5)), (Value::Float(25.0), Value::Bool(true)));
    // The earliest rule and the stage's default rule agree on a stage without startTimeCode.
    assert_eq!(
        intensity(&Stage::load(&comp, None).unwrap()),
        (Value::Float(10.0), Value::Bool(false))
    );
}

#[test]
fn scene_lights_and_warnings() {
    let scene = Stage::load(&data().join("usd/composition/root.usda"), Some(0.0)).unwrap();
    assert_eq!(scene.up_axis, "Z");
    assert_eq!(scene.meters_per_unit, 0.5);
    let get = |p: &str| {
        scene
            .lights
            .iter()
            .find(|l| l.path == p)
            .unwrap_or_else(|| panic!("{p}"))
    };

    // Reference + variant selection authored in the referencing layer.
    let fill = get("/World/Rig/Fill").light.clone().unwrap();
    assert_eq!(
        fill.kind,
        LightType::Rect {
            width: 2.0,
            height: 0.5
        }
    );
    assert!(fill.inputs.enable_color_temperature && fill.inputs.normalize);
    assert_eq!(fill.inputs.color_temperature, 8000.0);
    // Every unauthored type gets the model's fallbacks.
    let disk = get("/World/Defaults/Disk").light.clone().unwrap();
    assert_eq!(disk.kind, LightType::fallback("DiskLight").unwrap());
    assert_eq!(disk.inputs, luxeval::LightInputs::default());
    let distant = get("/World/Defaults/Distant").light.clone().unwrap();
    assert_eq!(distant.inputs.intensity, 50000.0);
    // ShapingAPI applied, nothing authored: the schema fallbacks.
    let shaped = get("/World/Defaults/ShapedDefaults").light.clone().unwrap();
    assert_eq!(shaped.shaping, Some(luxeval::Shaping::default()));
    let cone = get("/World/Shaped/Cone")
        .light
        .clone()
        .unwrap()
        .shaping
        .unwrap();
    assert!((cone.cone_angle - 35.0).abs() < 1e-6 && (cone.cone_softness - 0.3).abs() < 1e-6);
    // A negative radius passes through; validate() names it.
    let neg = get("/World/NegativeRadius").light.clone().unwrap();
    let e = neg.validate().unwrap_err().to_string();
    assert!(
        e.contains("/World/NegativeRadius") && e.contains("inputs:radius"),
        "{e}"
    );
    // The world matrix reaches the light model (row-vector USD → column-vector glam).
    let all_ops = get("/World/OpsA/OpsB/OpsC/AllOps");
    assert_eq!(all_ops.light.as_ref().unwrap().usd_matrix(), all_ops.world);

    let evaluable = scene.evaluable(&[]).unwrap();
    let paths: Vec<&str> = evaluable.iter().map(|l| l.path.as_str()).collect();
    // A Mesh with MeshLightAPI is a light the queries evaluate (DESIGN.md §7).
    let mesh = evaluable
        .iter()
        .find(|l| l.path == "/World/Defaults/MeshLight");
    assert!(
        mesh.is_some_and(|l| l.kind.usd_type() == "Mesh"),
        "{paths:?}"
    );
    for skipped in [
        "/World/Hidden/HiddenByParent",
        "/World/HiddenSelf",
        "/World/Blink", // invisible at 0, visible from 2
        "/World/Defaults/Portal",
    ] {
        assert!(!paths.contains(&skipped), "{skipped} evaluated");
        assert!(
            scene.warnings().iter().any(|w| w.starts_with(skipped)),
            "no warning for {skipped}: {:#?}",
            scene.warnings()
        );
    }
    // The IES-shaped light is evaluated, with its profile resolved beside the layer.
    let ies = get("/World/Shaped/Ies")
        .light
        .clone()
        .unwrap()
        .shaping
        .unwrap();
    let ies = ies.ies.expect("shaping:ies:file read");
    assert_eq!(ies.angle_scale, -0.5);
    assert!(
        ies.file
            .resolved
            .as_deref()
            .is_some_and(|r| r.ends_with("ies/spot.ies"))
    );
    // The textured dome is evaluated, with its texture resolved beside its layer.
    let sky = get("/World/Env/Sky").light.clone().unwrap();
    let sky = sky.texture.expect("texture:file read");
    assert!(
        sky.file
            .resolved
            .as_deref()
            .is_some_and(|r| r.ends_with("env/sky.png"))
    );
    // A texture that cannot be read is an error naming the prim and the file when the light is
    // prepared, never a skip or an untextured light.
    let missing = get("/World/Shaped/MissingTexture").light.clone().unwrap();
    let e = luxeval::Reference::new(&missing, luxeval::TemperatureMode::Spec)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("/World/Shaped/MissingTexture") && e.contains("does_not_exist.png"),
        "{e}"
    );
    for kept in [
        "/World/Shaped/Ies",
        "/World/Shaped/Textured",
        "/World/Shaped/MissingTexture",
        "/World/Env/Sky",
        "/World/Env/Uniform",
        "/World/Untyped/UnderUntyped",
        "/World/Shaped/Cone",
        "/World/Instanced/Fill",
    ] {
        assert!(paths.contains(&kept), "{kept} not evaluated");
    }
    let later = Stage::load(&data().join("usd/composition/root.usda"), Some(2.0)).unwrap();
    assert!(later.evaluable(&["/World/Blink".into()]).unwrap().len() == 1);

    let selected = scene
        .evaluable(&["/World/Shaped/Cone".into(), "/World/Rig/Fill".into()])
        .unwrap();
    // Traversal order, not selection order.
    let order: Vec<&str> = selected.iter().map(|l| l.path.as_str()).collect();
    assert_eq!(order, ["/World/Shaped/Cone", "/World/Rig/Fill"]);
    let e = scene.evaluable(&["/World/NotALight".into()]).unwrap_err();
    assert!(e.to_string().contains("/World/NotALight"), "{e}");
}

#[test]
fn malformed_usda_is_a_format_error_with_line() {
    let path = data().join("usd/errors/malformed.usda");
    match Stage::load(&path, None) {
        Err(LuxError::Format {
            path: p,
            line,
            reason,
        }) => {
            assert_eq!(p, path);
            assert_eq!(line, Some(5));
            assert!(!reason.is_empty() && !reason.contains('\n'), "{reason}");
        }
        other => panic!("{other:?}"),
    }
    let e = Stage::load(&path, None).unwrap_err().to_string();
    assert!(e.contains("malformed.usda:5:"), "{e}");

    let not_usd = data().join("usd/errors/not_usd.usda");
    assert!(matches!(
        Stage::load(&not_usd, None),
        Err(LuxError::Format { line: Some(1), .. })
    ));
    let ies = data().join("luxtest/test_linear_vertical.ies");
    assert!(
        matches!(Stage::load(&ies, None), Err(LuxError::Format { .. })),
        "{:?}",
        Stage::load(&ies, None).err()
    );
}

#[test]
fn missing_file_is_an_io_error() {
    let path = data().join("usd/errors/no_such_file.usda");
    match Stage::load(&path, None) {
        Err(LuxError::Io { path: p, source }) => {
            assert_eq!(p, path);
            assert_eq!(source.kind(), std::io::ErrorKind::NotFound);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_directory_is_an_io_error() {
    let dir = data().join("usd");
    assert!(matches!(Stage::load(&dir, None), Err(LuxError::Io { path, .. }) if path == dir));
}

/// A reference or sublayer that cannot be found is left out, as usd-core leaves it out, with a
/// warning naming it, its layer and the prim; the stage's other lights are read. A malformed one
/// is an error naming it and its line.
#[test]
fn missing_layers_are_warned_and_malformed_ones_refused() {
    let errs = data().join("usd/errors");
    let scene = Stage::load(&errs.join("missing_reference.usda"), None).unwrap();
    assert_eq!(scene.lights.len(), 1);
    assert_eq!(scene.lights[0].path, "/World/Ok");
    let w = scene.warnings();
    assert!(
        w.iter().any(|w| w.contains("missing_layer.usda")
            && w.contains("/World/Broken")
            && w.contains("missing_reference.usda")),
        "{w:?}"
    );

    let scene = Stage::load(&errs.join("missing_sublayer.usda"), None).unwrap();
    let w = scene.warnings();
    assert!(
        w.iter()
            .any(|w| w.contains("missing_sublayer_target.usda") && w.contains("sublayer")),
        "{w:?}"
    );

    match Stage::load(&errs.join("malformed_reference.usda"), None) {
        Err(LuxError::Format { path, line, reason }) => {
            assert_eq!(path, errs.join("malformed.usda"));
            assert_eq!(line, Some(5));
            assert!(reason.contains("malformed_reference.usda"), "{reason}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_broken_transform_is_a_warning_not_a_failed_load() {
    let scene = Stage::load(&data().join("usd/errors/singular_invert.usda"), None).unwrap();
    let broken = &scene.lights[0];
    assert_eq!(broken.path, "/World/Broken");
    assert!(broken.light.is_none());
    let w = broken.warning.as_deref().unwrap();
    assert!(
        w.starts_with("/World/Broken") && w.contains("singular"),
        "{w}"
    );
    assert!(scene.warnings().iter().any(|x| x == w));
    let lights = scene.evaluable(&[]).unwrap();
    assert_eq!(lights.len(), 1);
    assert_eq!(lights[0].path, "/World/Fine");
}

/// usd-core evaluates splines; openusd 0.8 reads them as unauthored, so they are refused with
/// the light and attribute named rather than silently replaced by the fallback. The refusal
/// asks about splines only where a layer read may hold one (`may_hold_splines`): a text root
/// without one whose light takes its spline through a reference is refused all the same.
#[test]
fn splines_are_refused_naming_the_attribute() {
    let errs = data().join("usd/errors");
    for (file, attr) in [
        ("spline_input.usda", "inputs:intensity"),
        ("spline_input.usdc", "inputs:intensity"),
        ("spline_xform.usda", "xformOp:rotateX"),
        ("spline_referenced.usda", "inputs:intensity"),
    ] {
        match Stage::load(&errs.join(file), None) {
            Err(LuxError::InvalidAttribute {
                light,
                attr: a,
                reason,
                ..
            }) => {
                assert_eq!(
                    light,
                    match file {
                        "spline_xform.usda" => "/Rig/L",
                        "spline_referenced.usda" => "/World/L",
                        _ => "/L",
                    }
                );
                assert_eq!(a, attr, "{file}");
                assert!(reason.contains("spline"), "{file}: {reason}");
            }
            other => panic!("{file}: {other:?}"),
        }
    }
}

/// The .ies files are LM-63 with CRLF line endings; git must not have normalised them.
#[test]
fn ies_bytes_survive() {
    // Sizes from research/data/README.md (the CRLF originals).
    let luxtest = [
        ("test_linear_vertical.ies", 329),
        ("test_stripes_uniform.ies", 3075),
        ("test_stripes_nonuniform.ies", 999),
        ("test_vstripes_hquadrants_nonuniform.ies", 3356),
        ("test_vstripes_hquadrants_nonuniform_aimDown.ies", 2202),
        ("test_vstripes_hquadrants_nonuniform_aimUp.ies", 2203),
    ];
    let ours = ("usd/composition/ies/spot.ies".to_string(), 139);
    for (name, len) in luxtest
        .iter()
        .map(|(n, l)| (format!("luxtest/{n}"), *l))
        .chain([ours])
    {
        let bytes = std::fs::read(data().join(&name)).unwrap();
        assert_eq!(bytes.len(), len, "{name}");
        let lf = bytes.iter().filter(|&&b| b == b'\n').count();
        let crlf = bytes.windows(2).filter(|w| w == b"\r\n").count();
        assert!(lf > 0 && lf == crlf, "{name}: {lf} LF, {crlf} CRLF");
    }
}

/// An input of another light schema authored on a light whose schema lacks it (a texture on a
/// SphereLight) is not read, and `lights` says so instead of ignoring it without a word; a
/// renderer's own namespaced input is not the schema table's and passes silently.
#[test]
fn inputs_a_light_type_does_not_have_are_said_out_loud() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("stray.usda");
    std::fs::write(
        &path,
        "#usda 1.0\ndef SphereLight \"L\"\n{\n    asset inputs:texture:file = @sky.exr@\n    \
         float inputs:karma:spread = 2\n}\n",
    )
    .unwrap();
    let stage = Stage::load(&path, None).unwrap();
    let l = &stage.lights[0];
    assert!(l.light.is_some(), "the light is still evaluated");
    let w = l.warning.as_deref().unwrap_or_default();
    assert!(
        w.starts_with("/L") && w.contains("inputs:texture:file") && w.contains("SphereLight"),
        "{w}"
    );
    assert!(!w.contains("karma"), "{w}");
}

/// usd-core composes a fixture scene's lights and light lists as these records; luxeval must
/// report of them what its rule says (`StageLight::link_collections`: a collection that names a
/// path, excludes the root or authors an expression).
#[test]
fn unapplied_scene_matches_usd_core() {
    check_scene("unapplied");
}

/// What a renderer applies and luxeval does not (light filters, light-link and shadow-link
/// collections, shaping inputs without ShapingAPI, light lists) is reported as usd-core
/// composes it: targets folded across layers, mapped through a reference and into an instance.
/// The expectations are usd-core's raw records (tools/gen_usd_fixtures.py --only-unapplied);
/// only the rule of which collections say something is applied here.
#[test]
fn filters_links_and_light_lists_match_usd_core() {
    let exp = expected("unapplied_links");
    let path = data().join(exp["scene"].as_str().unwrap());
    let strings = |v: &Json| -> Vec<String> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|s| s.as_str().unwrap().to_string())
            .collect()
    };
    let mut problems = Vec::new();
    for sample in exp["samples"].as_array().unwrap() {
        let time = sample["time"].as_f64();
        let ctx = format!("unapplied @ {time:?}");
        let stage = Stage::load(&path, time).unwrap_or_else(|e| panic!("{ctx}: {e}"));
        let theirs = exp["lights"].as_array().unwrap();
        assert_eq!(stage.lights.len(), theirs.len(), "{ctx}");
        for (ours, t) in stage.lights.iter().zip(theirs) {
            let mut bad = |what: String| problems.push(format!("{ctx} {}: {what}", ours.path));
            assert_eq!(ours.path, t["path"].as_str().unwrap(), "{ctx}");
            if ours.light_filters != strings(&t["filters"]) {
                bad(format!(
                    "light:filters {:?} vs usd-core {}",
                    ours.light_filters, t["filters"]
                ));
            }
            let said: Vec<Json> = t["collections"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|c| {
                    c["include_root"] == false
                        || !c["includes"].as_array().unwrap().is_empty()
                        || !c["excludes"].as_array().unwrap().is_empty()
                        || !c["membership_expression"].is_null()
                })
                .map(|c| {
                    serde_json::json!({
                        "name": c["name"],
                        "include_root": c["include_root"],
                        "includes": c["includes"],
                        "excludes": c["excludes"],
                        "expansion_rule": c["expansion_rule"],
                        "membership_expression": c["membership_expression"],
                    })
                })
                .collect();
            let ours_said = serde_json::to_value(&ours.link_collections).unwrap();
            if ours_said != Json::Array(said.clone()) {
                bad(format!(
                    "link collections {ours_said} vs usd-core {}",
                    Json::Array(said)
                ));
            }
            let mut shaping = match t["shaping_api"].as_bool().unwrap() {
                true => Vec::new(),
                false => strings(&t["authored_shaping_inputs"]),
            };
            shaping.sort();
            let mut ours_shaping = ours.shaping_without_api.clone();
            ours_shaping.sort();
            if ours_shaping != shaping {
                bad(format!(
                    "shaping without ShapingAPI {ours_shaping:?} vs usd-core {shaping:?}"
                ));
            }
        }
        let lists = serde_json::to_value(&stage.light_lists).unwrap();
        if lists != sample["light_lists"] {
            problems.push(format!(
                "{ctx}: light lists {lists} vs usd-core {}",
                sample["light_lists"]
            ));
        }
    }
    assert!(
        problems.is_empty(),
        "{} mismatches with usd-core:\n{}",
        problems.len(),
        problems.join("\n")
    );

    // The fixture holds every case: each kind reported somewhere, a light with ShapingAPI and
    // authored shaping inputs reported for nothing, and lights that author empty or
    // unrestricting collections (`Quiet`) reported for nothing.
    let stage = Stage::load(&path, None).unwrap();
    let light = |p: &str| stage.lights.iter().find(|l| l.path == p).unwrap();
    assert!(!light("/World/Filtered").light_filters.is_empty());
    assert!(!light("/World/Linked").link_collections.is_empty());
    assert!(!light("/World/UnshapedSpot").shaping_without_api.is_empty());
    for quiet in ["/World/ShapedSpot", "/World/Quiet"] {
        let l = light(quiet);
        assert!(
            l.light_filters.is_empty()
                && l.link_collections.is_empty()
                && l.shaping_without_api.is_empty()
                && l.warning.is_none(),
            "{l:?}"
        );
    }
    assert!(
        light("/World/ShapedSpot")
            .light
            .as_ref()
            .unwrap()
            .shaping
            .is_some()
    );
    // Unshaped: the inputs are not part of the light, and the light says so.
    let spot = light("/World/UnshapedSpot");
    assert!(spot.light.as_ref().unwrap().shaping.is_none());
    let w = spot.warning.as_deref().unwrap();
    assert!(
        w.contains("inputs:shaping:cone:angle") && w.contains("ShapingAPI is not applied"),
        "{w}"
    );
    assert!(
        !w.contains("has no such input"),
        "said once, not as a stray input: {w}"
    );
    assert!(stage.light_lists.len() > 1);
}

/// The mesh-light and portal scene's inputs (LightAPI's, and the Mesh and MeshLightAPI rows of
/// the schema table: orientation, doubleSided, subdivisionScheme, light:materialSyncMode) as
/// usd-core resolves them (tools/gen_usd_fixtures.py --only-mesh).
#[test]
fn mesh_light_inputs_match_usd_core() {
    check_scene("mesh_lights_inputs");
}

/// DESIGN.md §7 M1–M2 and §8 P1 against what usd-core and NumPy computed in the generator
/// (tests/data/usd/expected/mesh_lights.json), at every time it recorded: each mesh light's
/// fan triangle count, exact world area, per-triangle emitting front (leftHanded, mirroring),
/// doubleSided, subdivisionScheme, tint and its kind of source (the material bound through an
/// ancestor, one that does not glow, a shader that is not UsdPreviewSurface, a connected
/// emissiveColor, a NodeGraph, no material, materialSyncMode independent); each portal's size,
/// world matrix and naming domes; each dome's portals relationship.
#[test]
fn mesh_lights_and_portals_match_usd_core() {
    let exp = expected("mesh_lights");
    let path = data().join(exp["scene"].as_str().unwrap());
    let stage = UsdStage::open(&path).unwrap();
    let mut problems = Vec::new();
    for sample in exp["samples"].as_array().unwrap() {
        let time = match sample["time"].as_f64() {
            Some(t) => TimeRule::Given(t),
            None => TimeRule::Earliest,
        };
        let scene = stage.read_at(time).unwrap();
        let ctx = format!("{time:?}");
        let light = |path: &str| {
            scene
                .lights
                .iter()
                .find(|l| l.path == path)
                .unwrap_or_else(|| panic!("{ctx}: {path} not listed"))
        };
        let mut bad = |what: String| problems.push(format!("{ctx} {what}"));
        for e in sample["meshes"].as_array().unwrap() {
            let p = e["path"].as_str().unwrap();
            let l = light(p);
            let Some(m) = &l.mesh else {
                bad(format!("{p}: not read as a mesh light ({:?})", l.warning));
                continue;
            };
            let g = &m.geometry;
            if g.triangles.len() as u64 != e["triangles"].as_u64().unwrap() {
                bad(format!(
                    "{p}: {} triangles vs {}",
                    g.triangles.len(),
                    e["triangles"]
                ));
            }
            let area = e["area"].as_f64().unwrap();
            if !close(g.area, area, 1e-6) {
                bad(format!("{p}: area {} vs {area}", g.area));
            }
            for (i, (t, n)) in g
                .triangles
                .iter()
                .zip(e["normals"].as_array().unwrap())
                .enumerate()
            {
                let ours = (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).normalize();
                let theirs: Vec<f64> = n
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|x| x.as_f64().unwrap())
                    .collect();
                if (0..3).any(|k| (ours[k] - theirs[k]).abs() > 1e-6) {
                    bad(format!("{p}: triangle {i} front {ours} vs {theirs:?}"));
                }
            }
            let tint: Vec<f64> = e["tint"]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect();
            if (0..3).any(|k| !close(m.tint.rgb[k], tint[k], 1e-6)) {
                bad(format!("{p}: tint {} vs {tint:?}", m.tint.rgb));
            }
            let prefix = match e["tint_kind"].as_str().unwrap() {
                "emissive" => "emissiveColor of",
                "not_evaluated" => "not evaluated",
                "no_material" => "no material bound",
                "mode" => "materialSyncMode",
                other => panic!("unknown tint kind {other}"),
            };
            if !m.tint.source.starts_with(prefix) {
                bad(format!(
                    "{p}: tint source {:?}, want {prefix}…",
                    m.tint.source
                ));
            }
            if m.double_sided != e["double_sided"].as_bool().unwrap() {
                bad(format!("{p}: doubleSided {}", m.double_sided));
            }
            if m.subdivision_scheme != e["subdivision_scheme"].as_str().unwrap() {
                bad(format!("{p}: subdivisionScheme {}", m.subdivision_scheme));
            }
            // The cage note once per prim, and only where a scheme is set (M1).
            let w = l.warning.as_deref().unwrap_or("");
            let notes = w.matches("subdivisionScheme").count();
            if notes != usize::from(m.subdivision_scheme != "none") {
                bad(format!("{p}: {notes} subdivision notes in {w:?}"));
            }
            // Evaluated (DESIGN.md §7), as the light the queries see.
            if l.light.as_ref().map(|x| x.kind.usd_type()) != Some("Mesh")
                || w.contains("not evaluated yet")
            {
                bad(format!("{p}: not evaluated ({w:?})"));
            }
        }
        for e in sample["portals"].as_array().unwrap() {
            let p = e["path"].as_str().unwrap();
            let l = light(p);
            let Some(portal) = &l.portal else {
                bad(format!("{p}: not read as a portal"));
                continue;
            };
            assert!(l.light.is_none(), "{p}");
            if portal.width != e["width"].as_f64().unwrap()
                || portal.height != e["height"].as_f64().unwrap()
            {
                bad(format!("{p}: {} x {}", portal.width, portal.height));
            }
            for r in 0..4 {
                for c in 0..4 {
                    let want = e["world"][r][c].as_f64().unwrap();
                    if (l.world[r][c] - want).abs() > 1e-9 * want.abs().max(1.0)
                        || portal.world.col(r)[c] != l.world[r][c]
                    {
                        bad(format!("{p}: world[{r}][{c}] {} vs {want}", l.world[r][c]));
                    }
                }
            }
            let domes: Vec<&str> = e["domes"]
                .as_array()
                .unwrap()
                .iter()
                .map(|d| d.as_str().unwrap())
                .collect();
            if portal.domes != domes {
                bad(format!("{p}: domes {:?} vs {domes:?}", portal.domes));
            }
            // P1: a portal no dome names is listed with a warning.
            let unnamed = l.warning.as_deref().unwrap_or("").contains("no dome");
            if unnamed != domes.is_empty() {
                bad(format!("{p}: warning {:?}", l.warning));
            }
        }
        for e in sample["domes"].as_array().unwrap() {
            let p = e["path"].as_str().unwrap();
            let l = light(p);
            let targets: Vec<&str> = e["portals"]
                .as_array()
                .unwrap()
                .iter()
                .map(|d| d.as_str().unwrap())
                .collect();
            if l.portals
                .as_deref()
                .map(|v| v.iter().map(String::as_str).collect::<Vec<_>>())
                != Some(targets.clone())
            {
                bad(format!("{p}: portals {:?} vs {targets:?}", l.portals));
            }
            // The dome's own portals that are PortalLights, in the relationship's order.
            let portals: Vec<&str> = scene
                .portals_of(p)
                .iter()
                .map(|p| p.path.as_str())
                .collect();
            let named: Vec<&str> = targets
                .iter()
                .copied()
                .filter(|t| light(t).portal.is_some())
                .collect();
            assert_eq!(portals, named, "{ctx} {p}");
            // DESIGN.md §8 P1: the dome's light carries the visible ones, in that order.
            let carried: Vec<&str> = l
                .light
                .as_ref()
                .map(|d| d.portals.iter().map(|q| q.path.as_str()).collect())
                .unwrap_or_default();
            let visible: Vec<&str> = named.iter().copied().filter(|t| light(t).visible).collect();
            assert_eq!(carried, visible, "{ctx} {p}");
        }
        // Every query evaluates the dome and the visible mesh lights, in traversal order; the
        // portals are skipped and said to be.
        let evaluated: Vec<String> = scene
            .evaluable(&[])
            .unwrap()
            .into_iter()
            .map(|l| l.path)
            .collect();
        let want: Vec<&str> = scene
            .lights
            .iter()
            .filter(|l| l.visible && (l.path == "/World/Sky" || l.mesh.is_some()))
            .map(|l| l.path.as_str())
            .collect();
        assert!(want.len() > 1, "{ctx}");
        assert_eq!(evaluated, want, "{ctx}");
        // Every portal is said once: a portal no dome names is read, not evaluated; one a dome
        // names says how it is evaluated (DESIGN.md §8 P2; hint mode by default).
        let warnings = scene.warnings();
        let skipped = warnings
            .iter()
            .filter(|w| w.contains("read, not evaluated yet"))
            .count();
        let hints = warnings
            .iter()
            .filter(|w| w.contains("guides sampling only (hint mode)"))
            .count();
        let portals = sample["portals"].as_array().unwrap();
        let unnamed = portals
            .iter()
            .filter(|e| e["domes"].as_array().is_none_or(|d| d.is_empty()))
            .count();
        assert_eq!(skipped, unnamed, "{ctx}: {warnings:#?}");
        assert_eq!(skipped + hints, portals.len(), "{ctx}: {warnings:#?}");
        let masks = scene
            .warnings_in(luxeval::PortalMode::Mask)
            .iter()
            .filter(|w| w.contains("masks /World/Sky (mask mode)"))
            .count();
        assert_eq!(masks, hints, "{ctx}");
        // A dome's target that is not a PortalLight is said on the dome.
        let sky = light("/World/Sky").warning.clone().unwrap_or_default();
        assert!(
            sky.contains("/World/Signs/Quads") && sky.contains("not a PortalLight"),
            "{ctx}: {sky}"
        );
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// Bad topology (DESIGN.md §7 M1) is listed with a warning and refused by the queries, naming
/// the prim and the attribute (tools/gen_usd_fixtures.py BAD_MESHES; the CLI's exit 2 is
/// cli/tests/bad_inputs.rs's).
#[test]
fn bad_mesh_topology_is_refused_naming_the_attribute() {
    for (name, attr) in [
        ("count_below_3", "faceVertexCounts"),
        ("index_out_of_range", "faceVertexIndices"),
        ("negative_index", "faceVertexIndices"),
        ("counts_not_summing", "faceVertexIndices"),
        ("non_finite_point", "points"),
        ("hole_out_of_range", "holeIndices"),
    ] {
        let path = data().join(format!("usd/mesh/bad/{name}.usda"));
        let scene = Stage::load(&path, None).unwrap_or_else(|e| panic!("{name}: {e}"));
        let l = &scene.lights[0];
        assert!(l.mesh.is_none() && l.light.is_none(), "{name}");
        assert!(
            l.warning.as_deref().unwrap().contains(attr),
            "{name}: {:?}",
            l.warning
        );
        let e = scene.evaluable(&[]).unwrap_err();
        let text = e.to_string();
        assert!(
            matches!(e, LuxError::InvalidAttribute { .. })
                && text.contains("/Bad")
                && text.contains(attr),
            "{name}: {text}"
        );
    }
}
