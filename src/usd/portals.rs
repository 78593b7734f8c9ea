//! Portal lights on a stage (DESIGN.md §8 P1): each PortalLight attached to the domes whose
//! `portals` relationship names it, what changes nothing said, and the `lights --json` summary.
//! Each dome's model light carries the visible portals it names (P1); what they change is the
//! portal mode's to say (P2, `model::PortalMode`).

use serde::Serialize;

use super::scene::StageLight;
use crate::model::Portal;

/// A portal's `lights --json` summary (`StageLight::portal`).
pub(super) fn summary<S: serde::Serializer>(
    portal: &Option<Portal>,
    s: S,
) -> std::result::Result<S::Ok, S::Error> {
    let Some(p) = portal else {
        return s.serialize_none();
    };
    serde_json::json!({
        "width": p.width,
        "height": p.height,
        "intensity": p.intensity,
        "exposure": p.exposure,
        "color": p.color.to_array(),
        "enable_color_temperature": p.enable_color_temperature,
        "color_temperature": p.color_temperature,
        "domes": p.domes,
    })
    .serialize(s)
}

/// Attaches every PortalLight to the domes whose `portals` relationship names it, and says
/// what changes nothing (DESIGN.md §8 P1): a target that is not a PortalLight of the stage, and
/// a PortalLight that no dome names.
pub(super) fn attach(lights: &mut [StageLight]) {
    // By path, once: a stage of many lights stays linear (docs/INPUTS.md "big stages").
    let index: std::collections::HashMap<String, usize> = lights
        .iter()
        .enumerate()
        .map(|(i, l)| (l.path.clone(), i))
        .collect();
    let named: Vec<(usize, Vec<String>)> = lights
        .iter()
        .enumerate()
        .filter_map(|(i, l)| Some((i, l.portals.clone()?)))
        .collect();
    for (dome, targets) in named {
        let dome_path = lights[dome].path.clone();
        let mut not_portals = Vec::new();
        for target in targets {
            let portal = index.get(&target).and_then(|&i| lights[i].portal.as_mut());
            match portal {
                Some(portal) => portal.domes.push(dome_path.clone()),
                None => not_portals.push(target),
            }
        }
        if !not_portals.is_empty() {
            let l = &mut lights[dome];
            let w = format!(
                "{}: portals names {}, not a PortalLight of the stage: changes nothing (DESIGN.md §8 P1)",
                l.path,
                not_portals.join(", ")
            );
            add_warning(&mut l.warning, w);
        }
    }
    for l in lights.iter_mut() {
        if let Some(p) = &l.portal
            && p.domes.is_empty()
        {
            let read = format!("{}: portal read, not evaluated yet: skipped", l.path);
            let w = "no dome's portals relationship names this portal: it changes nothing \
                     (DESIGN.md §8 P1)"
                .to_string();
            let caveat = l.warning.take();
            l.warning = Some(read);
            if let Some(c) = caveat {
                add_warning(&mut l.warning, c);
            }
            add_warning(&mut l.warning, w);
        }
    }
    // Each dome's light carries the visible PortalLights it names, in relationship order (P1:
    // an invisible portal is ignored, as if not named).
    let domes: Vec<(usize, Vec<String>)> = lights
        .iter()
        .enumerate()
        .filter(|(_, l)| l.light.is_some())
        .filter_map(|(i, l)| Some((i, l.portals.clone()?)))
        .collect();
    for (dome, targets) in domes {
        let portals: Vec<crate::model::Portal> = targets
            .iter()
            .filter_map(|t| index.get(t).map(|&i| &lights[i]))
            .filter(|l| l.visible)
            .filter_map(|l| l.portal.clone())
            .collect();
        if let Some(light) = &mut lights[dome].light {
            light.portals = portals;
        }
    }
}

/// What a portal named by a dome does in `mode`, for the queries' warnings (DESIGN.md §8 P2),
/// with its own caveat (normalize or ShapingAPI authored) after it; `None` for lights that are
/// not such portals.
pub(super) fn named_portal_warning(
    l: &StageLight,
    mode: crate::model::PortalMode,
    when: &str,
) -> Option<String> {
    let p = l.portal.as_ref().filter(|p| !p.domes.is_empty())?;
    let what = if !l.visible {
        format!("{}: invisible at {when}: ignored, as if not named", l.path)
    } else {
        match mode {
            crate::model::PortalMode::Hint => format!(
                "{}: portal of {}: guides sampling only (hint mode), changes no value",
                l.path,
                p.domes.join(", ")
            ),
            crate::model::PortalMode::Mask => {
                format!("{}: masks {} (mask mode)", l.path, p.domes.join(", "))
            }
        }
    };
    Some(match &l.warning {
        Some(c) => format!("{what}; {c}"),
        None => what,
    })
}

fn add_warning(warning: &mut Option<String>, more: String) {
    *warning = Some(match warning.take() {
        Some(w) => format!("{w}; {more}"),
        None => more,
    });
}
