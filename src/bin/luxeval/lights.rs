//! `luxeval lights`: every light of a stage with its type, visibility, world matrix and every
//! input, authored or the schema fallback.

use std::path::Path;

use crate::exit::{CliResult, Failure};

pub fn run(path: &Path, json: bool, time: Option<f64>) -> CliResult {
    let scene = crate::open::load(path, time)?;
    if json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&scene).map_err(|e| Failure::runtime(e.to_string()))?
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
