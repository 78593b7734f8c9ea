//! The light records `luxeval lights --json` writes and the Python package's `Stage.lights`
//! returns: the stage's records with each light's total power (one definition for both).

use crate::prepare::TemperatureMode;
use crate::usd::Stage;

use super::Reference;

/// `scene.lights` as JSON, each record with `power` ([`Reference::power`]: `rgb`, `lumens`,
/// `watts`; null for lights at infinity or not evaluated) and, when the light cannot be prepared
/// (a missing IES file, ...), `power_error` with the reason.
pub fn lights_json(scene: &Stage) -> serde_json::Result<serde_json::Value> {
    let mut v = serde_json::to_value(&scene.lights)?;
    if let Some(records) = v.as_array_mut() {
        for (json, l) in records.iter_mut().zip(&scene.lights) {
            json["power"] = serde_json::Value::Null;
            let Some(light) = &l.light else { continue };
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
