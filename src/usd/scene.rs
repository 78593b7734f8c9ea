//! The resolved scene: every light of a USD stage at one time, as plain data, and the subset
//! luxeval evaluates as [`Light`]s.
//!
//! [`super::stage`] reads the stage (with openusd); this module decides
//! what each light means to luxeval: which types it evaluates, which it lists with a warning, and
//! which time the stage is read at (DESIGN.md §2 "Query time").
//! The conversion of each light prim into a model light is [`super::light`]'s.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use serde::Serialize;

use super::light::{NotEvaluated, Read, RefusedInput, read};
use super::progress::{LoadProgress, Reporter, Stopped};
use super::reading::on_large_stack;
use super::stage::{self as usd, UsdStage};
use super::unapplied::{LightList, LinkCollection};
use crate::error::{LuxError, Result};
use crate::model::{Input, Light, MeshLight, Portal, UpAxis};

/// Which time the stage was read at.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "rule", content = "time", rename_all = "snake_case")]
pub enum TimeRule {
    /// `--time T`.
    Given(f64),
    /// The stage's authored `startTimeCode`, as usdview opens a stage.
    StartTimeCode(f64),
    /// USD's EarliestTime: each attribute at its earliest time sample, or its default when it has
    /// none.
    Earliest,
}

/// One light of the stage, listed whether or not luxeval evaluates it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StageLight {
    pub path: String,
    /// The prim's USD type, e.g. `SphereLight`, `DomeLight_1`, or `Mesh` for a MeshLightAPI prim.
    pub usd_type: String,
    pub applied_schemas: Vec<String>,
    pub visible: bool,
    /// Local-to-world, USD row-vector convention (`world[3]` is the translation).
    pub world: [[f64; 4]; 4],
    /// Every attribute of [`crate::model::schema::attrs_for`] in its order.
    pub inputs: Vec<Input>,
    /// `Some` where luxeval evaluates the light (also when it is invisible). Serialized as the
    /// boolean `evaluable`.
    #[serde(rename = "evaluable", serialize_with = "serialize_is_some")]
    pub light: Option<Light>,
    /// Why the light is not evaluated, or a caveat about how it is; names the prim.
    pub warning: Option<String>,
    /// An input value the schema does not allow (a `texture:format` or `poleAxis` token): the
    /// queries refuse the light (exit 2), naming the prim and the attribute, rather than skip it.
    #[serde(skip)]
    pub refusal: Option<RefusedInput>,
    /// The targets of `light:filters`, as composed (spec/001 "light:filters"). luxeval does
    /// not apply light filters: the light is evaluated unfiltered.
    pub light_filters: Vec<String>,
    /// The light-link and shadow-link collections that restrict the light (spec/000
    /// "Linking"): those that name paths, exclude the root or author a membership expression.
    /// luxeval does not apply them: every receiver is lit, and nothing casts shadows.
    pub link_collections: Vec<LinkCollection>,
    /// `inputs:shaping:*` authored on a light without ShapingAPI: not part of the light (its
    /// schema does not have them), so luxeval evaluates it unshaped, as the schema says a
    /// renderer must (DESIGN.md §2). Empty where ShapingAPI is applied.
    pub shaping_without_api: Vec<String>,
    /// A `Mesh` with MeshLightAPI, read (DESIGN.md §7 M1, M2) and not evaluated yet: the
    /// queries skip it, as `light` is `None`. Serialized as a summary (triangle count, area,
    /// tint and its source, doubleSided, subdivision), absent for other lights.
    #[serde(
        serialize_with = "super::mesh::summary",
        skip_serializing_if = "Option::is_none"
    )]
    pub mesh: Option<MeshLight>,
    /// A `PortalLight`, read (DESIGN.md §8 P1) with the domes that name it; never a light of
    /// its own: a dome's [`Light::portals`] carries it (P2). Serialized as a summary, absent for
    /// other lights.
    #[serde(
        serialize_with = "super::portals::summary",
        skip_serializing_if = "Option::is_none"
    )]
    pub portal: Option<Portal>,
    /// A dome's `portals` relationship, its targets as composed (also those that are not
    /// PortalLights, which change nothing and are warned about); `None` for other lights.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub portals: Option<Vec<String>>,
}

fn serialize_is_some<S: serde::Serializer>(
    light: &Option<Light>,
    s: S,
) -> std::result::Result<S::Ok, S::Error> {
    s.serialize_bool(light.is_some())
}

/// A stage's lights at one time.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Stage {
    pub file: PathBuf,
    /// `Y` or `Z`; `Y` when the stage does not author it, as USD does.
    pub up_axis: String,
    /// 0.01 when the stage does not author it, as USD does.
    pub meters_per_unit: f64,
    pub time: TimeRule,
    /// In stage traversal order (depth-first, USD child order).
    pub lights: Vec<StageLight>,
    /// What reading the stage says out loud ([`UsdStage::warnings`]): layers left out of the
    /// composition, values read differently from how they were written.
    pub stage_warnings: Vec<String>,
    /// The light lists the stage authors (ListAPI / LightListAPI, spec/003), in traversal
    /// order. luxeval does not read them: it traverses the whole stage.
    pub light_lists: Vec<LightList>,
    /// Every file read to compose the stage (its layers and the packages holding them), the
    /// root layer first: what a command must never write over (DESIGN.md §4).
    #[serde(skip)]
    pub files_read: Vec<PathBuf>,
}

impl std::fmt::Display for TimeRule {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TimeRule::Given(t) => write!(f, "{t} (--time)"),
            TimeRule::StartTimeCode(t) => write!(f, "{t} (the stage's startTimeCode)"),
            TimeRule::Earliest => write!(f, "earliest (each attribute's earliest time sample)"),
        }
    }
}

impl Stage {
    /// Opens `path` (`.usda`, `.usdc`, `.usdz`) with every composition arc and payload loaded and
    /// resolves its lights at `time`; without one, at the stage's `startTimeCode` when authored,
    /// else at USD's EarliestTime (DESIGN.md §2).
    ///
    /// The stage is read on a thread of its own with a large stack (512 MiB reserved, touched
    /// only as deep as the stage goes), so that a legal deep stage does not overflow the
    /// caller's stack. That thread frees the composed stage after handing the lights back.
    pub fn load(path: &Path, time: Option<f64>) -> Result<Stage> {
        Self::load_reporting(path, time, None)
    }

    /// [`Stage::load`], telling `progress` where the reading has got to ([`LoadProgress`]: a
    /// step's start and end, and every 1,024 prims or lights within it; while none comes for a
    /// quarter of a second, the last one again). `progress` runs on the
    /// calling thread while the stage is read on its own; returning `Break` gives up: the call
    /// returns [`LuxError::Cancelled`] at once, and the reading thread stops at its next report
    /// (openusd's composition of the stage cannot be interrupted, so a stop asked for while
    /// the stage is being composed frees its memory only once that is done).
    pub fn load_with_progress(
        path: &Path,
        time: Option<f64>,
        mut progress: impl FnMut(LoadProgress) -> ControlFlow<()>,
    ) -> Result<Stage> {
        Self::load_reporting(path, time, Some(&mut progress))
    }

    fn load_reporting(
        path: &Path,
        time: Option<f64>,
        progress: Option<&mut dyn FnMut(LoadProgress) -> ControlFlow<()>>,
    ) -> Result<Stage> {
        check_time(time)?;
        let owned = path.to_path_buf();
        on_large_stack(path, progress, move |report| {
            let usd = UsdStage::open_reporting(&owned, report)?;
            let stage = usd.read_reporting(time, report)?;
            Ok((stage, usd))
        })
    }

    /// The portals the dome at `dome` names that are PortalLights of the stage, in the order of
    /// its `portals` relationship (DESIGN.md §8 P1); visibility is the caller's to apply.
    pub fn portals_of(&self, dome: &str) -> Vec<&Portal> {
        let Some(targets) = self
            .lights
            .iter()
            .find(|l| l.path == dome)
            .and_then(|l| l.portals.as_ref())
        else {
            return Vec::new();
        };
        targets
            .iter()
            .filter_map(|t| self.lights.iter().find(|l| &l.path == t))
            .filter_map(|l| l.portal.as_ref())
            .collect()
    }

    /// Visible, evaluable lights in traversal order; `select` (prim paths) filters when
    /// non-empty, and a selected path that is not a light of the stage is an error naming it.
    pub fn evaluable(&self, select: &[String]) -> Result<Vec<Light>> {
        for path in select {
            if !self.lights.iter().any(|l| &l.path == path) {
                // Name a few of the stage's lights to help spot a typo, not thousands.
                const SHOWN: usize = 8;
                let mut known: Vec<&str> = self
                    .lights
                    .iter()
                    .take(SHOWN)
                    .map(|l| l.path.as_str())
                    .collect();
                let more = self.lights.len().saturating_sub(SHOWN);
                let more = format!("{more} more");
                if self.lights.len() > SHOWN {
                    known.push(&more);
                }
                return Err(LuxError::input(
                    "--light",
                    format!(
                        "{path} is not a light of {} (its lights: {})",
                        self.file.display(),
                        if known.is_empty() {
                            "none".to_string()
                        } else {
                            known.join(", ")
                        }
                    ),
                ));
            }
        }
        let selected = || {
            self.lights
                .iter()
                .filter(|l| select.is_empty() || select.contains(&l.path))
                .filter(|l| l.visible)
        };
        if let Some((l, r)) = selected().find_map(|l| Some((l, l.refusal.as_ref()?))) {
            return Err(LuxError::attr(&l.path, &r.attr, &r.value, r.reason.clone()));
        }
        Ok(selected().filter_map(|l| l.light.clone()).collect())
    }

    /// The stage's own warnings ([`Stage::stage_warnings`]), then one line per light that is
    /// listed but skipped by the queries (unsupported type or feature, invisible), naming the
    /// prim.
    pub fn warnings(&self) -> Vec<String> {
        self.warnings_in(crate::model::PortalMode::default())
    }

    /// [`Stage::warnings`] for the queries of `mode`: a portal a dome names says how it is
    /// evaluated ("guides sampling only (hint mode)", "masks /World/Sky (mask mode)"), DESIGN.md
    /// §8 P2.
    pub fn warnings_in(&self, mode: crate::model::PortalMode) -> Vec<String> {
        let when = describe_time(self.time);
        let lights = self.lights.iter().filter_map(|l| {
            super::portals::named_portal_warning(l, mode, &when)
                .map(Some)
                .unwrap_or_else(|| Self::light_warning(l, self.time))
        });
        self.stage_warnings.iter().cloned().chain(lights).collect()
    }

    fn light_warning(l: &StageLight, time: TimeRule) -> Option<String> {
        match (&l.light, &l.warning) {
            (None, Some(w)) => Some(w.clone()),
            (None, None) => Some(format!("{}: not evaluated", l.path)),
            (Some(_), _) if !l.visible => Some(format!(
                "{}: invisible at {}, skipped",
                l.path,
                describe_time(time)
            )),
            _ => None,
        }
    }

    /// One line saying what the lights a query evaluates (visible, evaluable, `select`ed as
    /// [`Stage::evaluable`] selects them) and the stage author that a renderer applies and
    /// luxeval does not (light filters, light-link and shadow-link collections, shaping inputs
    /// without ShapingAPI, light lists), e.g. `2 lights have light filters, 1 has light-link
    /// collections: not applied by luxeval (see `luxeval lights`)`; `None` when there is
    /// nothing to say. The same text for the same stage on every run.
    pub fn unapplied(&self, select: &[String]) -> Option<String> {
        let evaluated: Vec<&StageLight> = self
            .lights
            .iter()
            .filter(|l| select.is_empty() || select.contains(&l.path))
            .filter(|l| l.visible && l.light.is_some())
            .collect();
        let count = |f: &dyn Fn(&StageLight) -> bool| evaluated.iter().filter(|l| f(l)).count();
        let link = |l: &StageLight, name: &str| l.link_collections.iter().any(|c| c.name == name);
        let counts = [
            (count(&|l| !l.light_filters.is_empty()), "light filters"),
            (count(&|l| link(l, "lightLink")), "light-link collections"),
            (count(&|l| link(l, "shadowLink")), "shadow-link collections"),
            (
                count(&|l| !l.shaping_without_api.is_empty()),
                "shaping inputs without ShapingAPI (evaluated unshaped)",
            ),
        ];
        let mut parts: Vec<String> = Vec::new();
        for (n, what) in counts.into_iter().filter(|(n, _)| *n > 0) {
            parts.push(match (n, parts.is_empty()) {
                (1, true) => format!("1 light has {what}"),
                (n, true) => format!("{n} lights have {what}"),
                (1, false) => format!("1 has {what}"),
                (n, false) => format!("{n} have {what}"),
            });
        }
        match self.light_lists.len() {
            0 => {}
            1 => parts.push("the stage has a light list (lightList)".to_string()),
            n => parts.push(format!("the stage has {n} light lists (lightList)")),
        }
        (!parts.is_empty()).then(|| {
            format!(
                "{}: not applied by luxeval (see `luxeval lights`)",
                parts.join(", ")
            )
        })
    }
}

impl UsdStage {
    /// The stage's lights at `time`; without one, at its `startTimeCode` when authored, else at
    /// USD's EarliestTime (DESIGN.md §2 "Query time").
    pub fn read(&self, time: Option<f64>) -> Result<Stage> {
        self.read_reporting(time, &mut Reporter::silent())
    }

    /// [`UsdStage::read`], reporting each light read to `report`.
    fn read_reporting(&self, time: Option<f64>, report: &mut Reporter) -> Result<Stage> {
        check_time(time)?;
        let rule = match time {
            Some(t) => TimeRule::Given(t),
            None => match self.info().start_time_code {
                Some(start) => TimeRule::StartTimeCode(start),
                None => TimeRule::Earliest,
            },
        };
        self.read_at_reporting(rule, report)
    }

    /// The stage's lights read as `rule` says.
    pub fn read_at(&self, rule: TimeRule) -> Result<Stage> {
        self.read_at_reporting(rule, &mut Reporter::silent())
    }

    fn read_at_reporting(&self, rule: TimeRule, report: &mut Reporter) -> Result<Stage> {
        let at = match rule {
            TimeRule::Given(t) | TimeRule::StartTimeCode(t) => {
                check_time(Some(t))?;
                usd::Time::Code(t)
            }
            TimeRule::Earliest => usd::Time::Earliest,
        };
        let info = self.info();
        let up = if info.up_axis == "Z" {
            UpAxis::Z
        } else {
            UpAxis::Y
        };
        let max_mesh_triangles = self.limits().max_mesh_triangles;
        let mut lights: Vec<StageLight> = self
            .lights_at(at, report)?
            .into_iter()
            .map(|p| StageLight::from_prim(p, up, max_mesh_triangles))
            .collect();
        let total = lights.len() as u64;
        report
            .report(LoadProgress::Reading { done: total, total })
            .map_err(|Stopped| usd::cancelled(self.file()))?;
        super::portals::attach(&mut lights);
        Ok(Stage {
            file: self.file().to_path_buf(),
            up_axis: info.up_axis.clone(),
            meters_per_unit: info.meters_per_unit,
            time: rule,
            lights,
            stage_warnings: self.warnings().to_vec(),
            light_lists: self.light_lists_at(at)?,
            files_read: self.files_read().to_vec(),
        })
    }
}

fn check_time(time: Option<f64>) -> Result<()> {
    match time.filter(|t| !t.is_finite()) {
        Some(t) => Err(LuxError::input(
            "--time",
            format!("{t} is not a finite time code"),
        )),
        None => Ok(()),
    }
}

fn describe_time(rule: TimeRule) -> String {
    match rule {
        TimeRule::Given(t) => format!("time {t}"),
        TimeRule::StartTimeCode(t) => format!("time {t} (the stage's startTimeCode)"),
        TimeRule::Earliest => "the earliest time".to_string(),
    }
}

impl StageLight {
    fn from_prim(p: usd::LightPrim, up: UpAxis, max_mesh_triangles: u64) -> StageLight {
        let (mut mesh, mut portal) = (None, None);
        let (light, warning, refusal) = match read(&p, up, max_mesh_triangles) {
            Ok((Read::Light(light), caveat)) => (Some(light), caveat, None),
            // Read, and skipped by every query until they are evaluated: said on every query.
            Ok((Read::Mesh(m), caveat)) => {
                let light = m.light(up);
                mesh = Some(m);
                (Some(light), caveat, None)
            }
            // What a portal's warning says depends on whether a dome names it (portals::attach)
            // and on the portal mode (Stage::warnings_in): only its own caveat here.
            Ok((Read::Portal(pl), caveat)) => {
                portal = Some(pl);
                (None, caveat, None)
            }
            Err(NotEvaluated::Skipped(why)) => (None, Some(why), None),
            Err(NotEvaluated::Refused(r)) => (
                None,
                Some(format!(
                    "{}: {} = {}: {}; the queries refuse this light",
                    p.path, r.attr, r.value, r.reason
                )),
                Some(r),
            ),
        };
        let is_dome = matches!(p.usd_type.as_str(), "DomeLight" | "DomeLight_1");
        StageLight {
            path: p.path,
            usd_type: p.usd_type,
            applied_schemas: p.applied_schemas,
            visible: p.visible,
            world: p.world,
            inputs: p.inputs,
            light,
            warning,
            refusal,
            light_filters: p.extras.filters,
            link_collections: p.extras.link_collections,
            shaping_without_api: p.extras.shaping_without_api,
            mesh,
            portal,
            portals: is_dome.then_some(p.portals),
        }
    }

    /// The input called `name`, if the light's schema has it.
    pub fn input(&self, name: &str) -> Option<&Input> {
        self.inputs.iter().find(|i| i.name == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::usd::light::tests::prim;

    fn max_triangles() -> u64 {
        crate::limits::Limits::default().max_mesh_triangles
    }

    #[test]
    fn evaluable_filters_and_rejects_unknown_selection() {
        let mut hidden =
            StageLight::from_prim(prim("SphereLight", &[]), UpAxis::Y, max_triangles());
        hidden.path = "/Lights/Hidden".into();
        hidden.visible = false;
        let scene = Stage {
            file: "x.usda".into(),
            up_axis: "Y".into(),
            meters_per_unit: 0.01,
            time: TimeRule::Earliest,
            lights: vec![
                StageLight::from_prim(prim("DiskLight", &[]), UpAxis::Y, max_triangles()),
                StageLight::from_prim(prim("PortalLight", &[]), UpAxis::Y, max_triangles()),
                hidden,
            ],
            stage_warnings: Vec::new(),
            light_lists: Vec::new(),
            files_read: vec!["x.usda".into()],
        };
        let all = scene.evaluable(&[]).unwrap();
        assert_eq!(all.len(), 1);
        assert_eq!(all[0].path, "/Lights/DiskLight");
        assert!(
            scene
                .evaluable(&["/Lights/Hidden".into()])
                .unwrap()
                .is_empty()
        );
        let e = scene.evaluable(&["/Nope".into()]).unwrap_err().to_string();
        assert!(e.contains("/Nope") && e.contains("x.usda"), "{e}");
        let w = scene.warnings();
        assert_eq!(w.len(), 2, "{w:?}");
        assert!(w[0].contains("/Lights/PortalLight"));
        assert!(w[1].contains("/Lights/Hidden") && w[1].contains("invisible"));
    }

    /// The query warning counts the lights a query evaluates (not a skipped or invisible one),
    /// says nothing when there is nothing, and adds the stage's light lists.
    #[test]
    fn unapplied_counts_the_evaluated_lights() {
        let with_filter = |ty: &str, visible: bool| {
            let mut l = StageLight::from_prim(prim(ty, &[]), UpAxis::Y, max_triangles());
            l.light_filters = vec!["/F".into()];
            l.visible = visible;
            l
        };
        let mut scene = Stage {
            file: "x.usda".into(),
            up_axis: "Y".into(),
            meters_per_unit: 0.01,
            time: TimeRule::Earliest,
            lights: vec![
                StageLight::from_prim(prim("DiskLight", &[]), UpAxis::Y, max_triangles()),
                with_filter("PortalLight", true),
                with_filter("SphereLight", false),
            ],
            stage_warnings: Vec::new(),
            light_lists: Vec::new(),
            files_read: vec!["x.usda".into()],
        };
        assert_eq!(scene.unapplied(&[]), None);
        scene.lights.push(with_filter("RectLight", true));
        let tail = ": not applied by luxeval (see `luxeval lights`)";
        assert_eq!(
            scene.unapplied(&[]).unwrap(),
            format!("1 light has light filters{tail}")
        );
        assert_eq!(scene.unapplied(&["/Lights/DiskLight".into()]), None);
        scene.light_lists.push(LightList {
            path: "/".into(),
            api: None,
            targets: Vec::new(),
            cache_behavior: None,
        });
        assert_eq!(
            scene.unapplied(&["/Lights/DiskLight".into()]).unwrap(),
            format!("the stage has a light list (lightList){tail}")
        );
    }

    #[test]
    fn json_shape() {
        let l = StageLight::from_prim(prim("SphereLight", &[]), UpAxis::Y, max_triangles());
        let v = serde_json::to_value(&l).unwrap();
        assert_eq!(v["evaluable"], serde_json::json!(true));
        assert_eq!(v["inputs"][0]["value"], serde_json::json!(1.0));
        let t = serde_json::to_value(TimeRule::StartTimeCode(1.0)).unwrap();
        assert_eq!(
            t,
            serde_json::json!({"rule": "start_time_code", "time": 1.0})
        );
        let t = serde_json::to_value(TimeRule::Earliest).unwrap();
        assert_eq!(t, serde_json::json!({"rule": "earliest"}));
    }
}
