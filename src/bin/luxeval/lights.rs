//! `luxeval lights`: every light of a stage with its type, visibility, world matrix and every
//! input, authored or the schema fallback.

use std::path::Path;

use luxeval::{Reference, SceneLight, TemperatureMode};

use crate::exit::{CliResult, Failure};

/// A light's total emitted power (DESIGN.md §3 "intensity" integrated over the sphere) as
/// JSON; `Ok(None)` for lights at infinity (distant, dome) or not evaluated; `Err` when the light
/// cannot be prepared (a missing IES file, ...). The Python package reports the same.
fn power(l: &SceneLight) -> Result<Option<serde_json::Value>, String> {
    let Some(light) = &l.light else {
        return Ok(None);
    };
    let r = Reference::new(light, TemperatureMode::default()).map_err(|e| e.to_string())?;
    Ok(r.power().map(|p| serde_json::json!(p)))
}

pub fn run(path: &Path, json: bool, time: Option<f64>) -> CliResult {
    let scene = crate::open::load(path, time)?;
    if json {
        let mut v = serde_json::to_value(&scene).map_err(|e| Failure::runtime(e.to_string()))?;
        if let Some(lights) = v.get_mut("lights").and_then(|l| l.as_array_mut()) {
            for (json, l) in lights.iter_mut().zip(&scene.lights) {
                let (p, err) = match power(l) {
                    Ok(p) => (p.unwrap_or(serde_json::Value::Null), None),
                    Err(e) => (serde_json::Value::Null, Some(e)),
                };
                json["power"] = p;
                if let Some(e) = err {
                    json["power_error"] = e.into();
                }
            }
        }
        outln!(
            "{}",
            serde_json::to_string_pretty(&v).map_err(|e| Failure::runtime(e.to_string()))?
        );
        return Ok(());
    }
    outln!("{}", scene.file.display());
    outln!(
        "  upAxis {}, metersPerUnit {}, time {}",
        scene.up_axis,
        scene.meters_per_unit,
        scene.time
    );
    for l in &scene.lights {
        let status = match (&l.light, l.visible) {
            (Some(_), true) => "evaluated",
            (_, false) => "invisible: skipped",
            (None, true) => "not evaluated",
        };
        outln!("\n{} ({}) [{}]", l.path, l.usd_type, status);
        if !l.applied_schemas.is_empty() {
            outln!("  apiSchemas: {}", l.applied_schemas.join(", "));
        }
        if let Some(w) = &l.warning {
            outln!("  warning: {w}");
        }
        match power(l) {
            Ok(Some(p)) => {
                let num = |v: &serde_json::Value| v.as_f64().unwrap_or(f64::NAN);
                let rgb = &p["rgb"];
                outln!(
                    "  power  {:.6} lm ({:.6} W at 683 lm/W; RGB flux ({:.6}, {:.6}, {:.6}))",
                    num(&p["lumens"]),
                    num(&p["watts"]),
                    num(&rgb[0]),
                    num(&rgb[1]),
                    num(&rgb[2])
                )
            }
            Ok(None) => {}
            Err(e) => outln!("  power  cannot be computed: {e}"),
        }
        for row in &l.world {
            outln!(
                "  world  {:>12.6} {:>12.6} {:>12.6} {:>12.6}",
                row[0],
                row[1],
                row[2],
                row[3]
            );
        }
        for i in &l.inputs {
            outln!(
                "  {:<34} {}{}",
                i.name,
                i.value,
                if i.authored { "" } else { "  (fallback)" }
            );
        }
    }
    Ok(())
}
