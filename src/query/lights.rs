//! The light records `luxeval lights --json` writes and the Python package's `Stage.lights`
//! returns: the stage's records with each light's total power (one definition for both).

use glam::DVec3;

use crate::model::{LightType, Portal};
use crate::prepare::{PortalMode, TemperatureMode};
use crate::usd::Stage;

use super::Reference;

/// `scene.lights` as JSON, each record with `power` ([`Reference::power`]: `rgb`, `lumens`,
/// `watts`; null for lights at infinity or not evaluated) and, when the light cannot be prepared
/// (a missing IES file, ...), `power_error` with the reason. A portal's record adds its
/// `multiplier` ([`portal_multiplier`]) to its `portal` summary. A dome's record adds
/// `portals_evaluated` (the visible PortalLights it names, in relationship order: what its
/// light carries, DESIGN.md §8 P1) and `masked` (whether `mode` masks it by them, P2).
pub fn lights_json(scene: &Stage, mode: PortalMode) -> serde_json::Result<serde_json::Value> {
    let mut v = serde_json::to_value(&scene.lights)?;
    if let Some(records) = v.as_array_mut() {
        for (json, l) in records.iter_mut().zip(&scene.lights) {
            json["power"] = serde_json::Value::Null;
            if let Some(p) = &l.portal {
                json["portal"]["multiplier"] = serde_json::to_value(
                    portal_multiplier(p, TemperatureMode::default()).to_array(),
                )?;
            }
            let Some(light) = &l.light else { continue };
            if light.kind == LightType::Dome {
                let named: Vec<&str> = light.portals.iter().map(|p| p.path.as_str()).collect();
                json["portals_evaluated"] = serde_json::to_value(&named)?;
                json["masked"] = (mode == PortalMode::Mask && !named.is_empty()).into();
            }
            match Reference::new(light, TemperatureMode::default()) {
                Ok(r) => {
                    json["power"] = serde_json::to_value(r.power())?;
                    // The light's own caveat (a filter it has, an input it lacks) and the
                    // power's (a zero-size light evaluated as a point) are both said.
                    if let Some(w) = r.warning() {
                        json["warning"] = match json["warning"].as_str() {
                            Some(own) if !own.is_empty() => format!("{own}; {w}").into(),
                            _ => w.into(),
                        };
                    }
                }
                Err(e) => json["power_error"] = e.to_string().into(),
            }
        }
    }
    Ok(v)
}

/// A portal's multiplier (DESIGN.md §8 P2): its own LightAPI product `intensity · 2^exposure ·
/// color ⊙ temperature(T)`, as a light's base radiance is formed.
pub fn portal_multiplier(p: &Portal, mode: TemperatureMode) -> DVec3 {
    crate::prepare::portal::multiplier(p, mode)
}
