//! `luxeval lights`: every light of a stage with its type, visibility, world matrix and every
//! input, authored or the schema fallback; and what luxeval reads but does not apply (light
//! filters, light-link and shadow-link collections, shaping inputs without ShapingAPI, the
//! stage's light lists), said out loud.

use std::fmt::Write;
use std::path::Path;

use luxeval::{PortalMode, Power, Reference, StageLight, TemperatureMode, portal_multiplier};

use crate::exit::{CliResult, Failure};

/// A light's total emitted power (DESIGN.md §3 "intensity" integrated over the sphere):
/// `Ok(None)` for lights at infinity (distant, dome) or not evaluated; `Err` when the light
/// cannot be prepared (a missing IES file, ...). The JSON records get the same from
/// `luxeval::lights_json`.
fn power(l: &StageLight) -> Result<(Option<Power>, Option<String>), String> {
    let Some(light) = &l.light else {
        return Ok((None, None));
    };
    let r = Reference::new(light, TemperatureMode::default()).map_err(|e| e.to_string())?;
    Ok((r.power(), r.warning().map(str::to_string)))
}

pub fn run(path: &Path, json: bool, time: Option<f64>, portal_mode: PortalMode) -> CliResult {
    let scene = crate::open::load(path, time)?;
    if json {
        let runtime = |e: serde_json::Error| Failure::runtime(e.to_string());
        let mut v = serde_json::to_value(&scene).map_err(runtime)?;
        v["lights"] = luxeval::lights_json(&scene, portal_mode).map_err(runtime)?;
        // DESIGN.md §8 P2: the reading is reported with the lights it changes.
        v["portal_mode"] = portal_mode.name().into();
        outln!("{}", serde_json::to_string_pretty(&v).map_err(runtime)?);
        return Ok(());
    }
    outln!("{}", scene.file.display());
    outln!(
        "  upAxis {}, metersPerUnit {}, time {}, portal mode {}",
        scene.up_axis,
        scene.meters_per_unit,
        scene.time,
        portal_mode.name()
    );
    for w in &scene.stage_warnings {
        outln!("  warning: {w}");
    }
    for list in &scene.light_lists {
        let api = list
            .api
            .as_deref()
            .unwrap_or("no ListAPI / LightListAPI applied");
        let targets = match list.targets.is_empty() {
            true => "(no targets)".to_string(),
            false => list.targets.join(", "),
        };
        outln!(
            "  lightList on {} ({api}): {targets}; cacheBehavior {}  (not read: luxeval traverses the whole stage)",
            list.path,
            list.cache_behavior.as_deref().unwrap_or("(not authored)")
        );
    }
    for l in &scene.lights {
        // One write per light, not per line: stdout is line-buffered, and a stage of 100,000
        // lights is 2.5 million lines.
        let mut block = String::new();
        // Writing to a String cannot fail.
        macro_rules! put {
            ($($arg:tt)*) => {{
                let _ = writeln!(block, $($arg)*);
            }};
        }
        // DESIGN.md §8 P2: a portal a dome names is evaluated with the dome, as the mode says.
        let named = l.portal.as_ref().is_some_and(|p| !p.domes.is_empty());
        let read_only = l.portal.is_some();
        let status = match (&l.light, l.visible) {
            (Some(_), true) => "evaluated",
            (_, false) => "invisible: skipped",
            (None, true) if named => match portal_mode {
                PortalMode::Hint => "guides sampling only (hint mode)",
                PortalMode::Mask => "masks its dome (mask mode)",
            },
            (None, true) if read_only => "read, not evaluated yet",
            (None, true) => "not evaluated",
        };
        put!("\n{} ({}) [{}]", l.path, l.usd_type, status);
        if !l.applied_schemas.is_empty() {
            put!("  apiSchemas: {}", l.applied_schemas.join(", "));
        }
        if let Some(w) = &l.warning {
            put!("  warning: {w}");
        }
        if !l.light_filters.is_empty() {
            put!(
                "  light:filters  {}  (not applied)",
                l.light_filters.join(", ")
            );
        }
        for c in &l.link_collections {
            put!("  collection:{}  {}  (not applied)", c.name, c.describe());
        }
        if !l.shaping_without_api.is_empty() {
            put!(
                "  without ShapingAPI  {}  (not part of the light: evaluated unshaped)",
                l.shaping_without_api.join(", ")
            );
        }
        let power = power(l);
        if let Ok((_, Some(w))) = &power {
            put!("  warning: {w}");
        }
        match power.map(|(p, _)| p) {
            Ok(Some(p)) => put!(
                "  power  {:.6} lm ({:.6} W at 683 lm/W; RGB flux ({:.6}, {:.6}, {:.6}))",
                p.lumens,
                p.watts,
                p.rgb[0],
                p.rgb[1],
                p.rgb[2]
            ),
            Ok(None) => {}
            Err(e) => put!("  power  cannot be computed: {e}"),
        }
        // DESIGN.md §7 M1, M2: what the mesh light's evaluation will read.
        if let Some(m) = &l.mesh {
            let g = &m.geometry;
            put!(
                "  mesh  {} triangles ({} hole faces removed, {} degenerate triangles dropped), \
                 area {:.6}, doubleSided {}",
                g.triangles.len(),
                g.holes,
                g.degenerate,
                g.area,
                m.double_sided
            );
            let [r, gr, b] = m.tint.rgb.to_array();
            // The subdivision note is the light's warning (once per prim, M1).
            put!("  tint  ({r}, {gr}, {b}) from {}", m.tint.source);
        }
        // DESIGN.md §8 P1, P2.
        if let Some(p) = &l.portal {
            let [r, g, b] = portal_multiplier(p, TemperatureMode::default()).to_array();
            let domes = match p.domes.is_empty() {
                true => "no dome".to_string(),
                false => p.domes.join(", "),
            };
            put!(
                "  portal  {} x {}, multiplier ({r}, {g}, {b}), named by {domes}",
                p.width,
                p.height
            );
        }
        if let Some(portals) = &l.portals {
            match portals.is_empty() {
                true => put!("  portals  (none)"),
                false => put!("  portals  {}", portals.join(", ")),
            }
            // The visible PortalLights among them: what the dome is evaluated with (P1).
            if let Some(light) = &l.light
                && !light.portals.is_empty()
            {
                let paths: Vec<&str> = light.portals.iter().map(|p| p.path.as_str()).collect();
                put!(
                    "  portals evaluated ({} mode)  {}",
                    portal_mode.name(),
                    paths.join(", ")
                );
            }
        }
        for row in &l.world {
            put!(
                "  world  {:>12.6} {:>12.6} {:>12.6} {:>12.6}",
                row[0],
                row[1],
                row[2],
                row[3]
            );
        }
        for i in &l.inputs {
            put!(
                "  {:<34} {}{}",
                i.name,
                i.value,
                if i.authored { "" } else { "  (fallback)" }
            );
        }
        block.pop();
        outln!("{block}");
    }
    Ok(())
}
