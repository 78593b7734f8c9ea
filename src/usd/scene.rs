//! The resolved scene: every light of a USD stage at one time, as plain data, and the subset
//! luxeval evaluates as [`Light`]s.
//!
//! [`super::stage`] reads the stage (with openusd); this module decides
//! what each light means to luxeval: which types it evaluates, which it lists with a warning, and
//! which time the stage is read at (DESIGN.md §2 "Query time").

use std::path::{Path, PathBuf};

use glam::DVec3;
use serde::Serialize;

use super::stage::{self as usd, UsdStage};
use crate::error::{LuxError, Result};
use crate::model::{
    Asset, Ies, Input, Light, LightInputs, LightType, PoleAxis, Shaping, Texture, TextureFormat,
    UpAxis, Value,
};

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
    /// caller's stack.
    pub fn load(path: &Path, time: Option<f64>) -> Result<Stage> {
        check_time(time)?;
        on_large_stack(path, || UsdStage::open(path)?.read(time))
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
        Ok(self
            .lights
            .iter()
            .filter(|l| select.is_empty() || select.contains(&l.path))
            .filter(|l| l.visible)
            .filter_map(|l| l.light.clone())
            .collect())
    }

    /// One line per light that is listed but skipped by the queries (unsupported type or
    /// feature, invisible), naming the prim.
    pub fn warnings(&self) -> Vec<String> {
        self.lights
            .iter()
            .filter_map(|l| match (&l.light, &l.warning) {
                (None, Some(w)) => Some(w.clone()),
                (None, None) => Some(format!("{}: not evaluated", l.path)),
                (Some(_), _) if !l.visible => Some(format!(
                    "{}: invisible at {}, skipped",
                    l.path,
                    describe_time(self.time)
                )),
                _ => None,
            })
            .collect()
    }
}

impl UsdStage {
    /// The stage's lights at `time`; without one, at its `startTimeCode` when authored, else at
    /// USD's EarliestTime (DESIGN.md §2 "Query time").
    pub fn read(&self, time: Option<f64>) -> Result<Stage> {
        check_time(time)?;
        let rule = match time {
            Some(t) => TimeRule::Given(t),
            None => match self.info().start_time_code {
                Some(start) => TimeRule::StartTimeCode(start),
                None => TimeRule::Earliest,
            },
        };
        self.read_at(rule)
    }

    /// The stage's lights read as `rule` says.
    pub fn read_at(&self, rule: TimeRule) -> Result<Stage> {
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
        let lights = self
            .lights_at(at)?
            .into_iter()
            .map(|p| StageLight::from_prim(p, up))
            .collect();
        Ok(Stage {
            file: self.file().to_path_buf(),
            up_axis: info.up_axis.clone(),
            meters_per_unit: info.meters_per_unit,
            time: rule,
            lights,
        })
    }
}

/// The stack of the thread that reads a stage. openusd's text parser and composition engine
/// recurse once or more per namespace level: on the 8 MiB main stack a debug build overflowed
/// at 3 000 levels and not at 1 000 (so 3–8 KiB a level), and a 10 000-level stage read with
/// this stack (the depth limit raised) had not overflowed after 20 minutes of composing. The depth limit (docs/INPUTS.md,
/// default 1 000) is checked before anything recurses; 512 MiB leaves room to raise it far
/// beyond what openusd composes in reasonable time. Memory is only reserved, and committed as
/// the stack grows.
pub const STACK_BYTES: usize = 512 << 20;

/// Runs `f` on a scoped thread with a [`STACK_BYTES`] stack and returns what it returns. A
/// panic on that thread becomes an error naming the stage: openusd 0.8 has debug assertions
/// that malformed files reach (found by fuzz/: a `.usdc` whose path table builds an invalid
/// variant path asserts in `sdf::Path::from_str_unchecked`), and a stage must never abort the
/// process.
fn on_large_stack<T: Send>(path: &Path, f: impl FnOnce() -> Result<T> + Send) -> Result<T> {
    std::thread::scope(|s| {
        let handle = std::thread::Builder::new()
            .name("luxeval-stage".into())
            .stack_size(STACK_BYTES)
            .spawn_scoped(s, f);
        match handle {
            Ok(h) => match h.join() {
                Ok(r) => r,
                Err(panic) => {
                    let msg = panic
                        .downcast_ref::<String>()
                        .map(String::as_str)
                        .or_else(|| panic.downcast_ref::<&str>().copied())
                        .unwrap_or("no message");
                    Err(LuxError::input(
                        path.display().to_string(),
                        format!("the USD reader failed on this file (it panicked: {msg})"),
                    ))
                }
            },
            // No thread (out of memory or address space): read on this one.
            Err(_) => Err(LuxError::input(
                "stage",
                "cannot start the thread that reads the stage (out of memory?)",
            )),
        }
    })
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
    fn from_prim(p: usd::LightPrim, up: UpAxis) -> StageLight {
        let (light, warning) = match convert(&p, up) {
            Ok((light, caveat)) => (Some(light), caveat),
            Err(why) => (None, Some(why)),
        };
        StageLight {
            path: p.path,
            usd_type: p.usd_type,
            applied_schemas: p.applied_schemas,
            visible: p.visible,
            world: p.world,
            inputs: p.inputs,
            light,
            warning,
        }
    }

    /// The input called `name`, if the light's schema has it.
    pub fn input(&self, name: &str) -> Option<&Input> {
        self.inputs.iter().find(|i| i.name == name)
    }
}

/// Reads typed inputs of one light; a missing input (the schema table lacks it) or a value of the
/// wrong kind becomes the reason the light is not evaluated, rather than a panic.
struct Reader<'a> {
    p: &'a usd::LightPrim,
}

impl Reader<'_> {
    fn get(&self, name: &str) -> std::result::Result<&Value, String> {
        self.p
            .inputs
            .iter()
            .find(|i| i.name == name)
            .map(|i| &i.value)
            .ok_or_else(|| format!("{}: {} has no input {name}", self.p.path, self.p.usd_type))
    }
    fn float(&self, name: &str) -> std::result::Result<f64, String> {
        match self.get(name)? {
            Value::Float(v) => Ok(*v),
            other => Err(self.kind(name, "float", other)),
        }
    }
    fn bool(&self, name: &str) -> std::result::Result<bool, String> {
        match self.get(name)? {
            Value::Bool(v) => Ok(*v),
            other => Err(self.kind(name, "bool", other)),
        }
    }
    fn color(&self, name: &str) -> std::result::Result<DVec3, String> {
        match self.get(name)? {
            Value::Color(v) => Ok(DVec3::from_array(*v)),
            other => Err(self.kind(name, "color", other)),
        }
    }
    fn token(&self, name: &str) -> std::result::Result<&str, String> {
        match self.get(name)? {
            Value::Token(v) => Ok(v),
            other => Err(self.kind(name, "token", other)),
        }
    }
    /// The asset `name` refers to (authored and resolved paths), `None` when empty.
    fn asset_ref(&self, name: &str) -> Option<Asset> {
        match self.get(name) {
            Ok(Value::Asset { authored, resolved }) if !authored.is_empty() => Some(Asset {
                authored: authored.clone(),
                resolved: resolved.clone(),
                bytes: None,
            }),
            _ => None,
        }
    }
    fn kind(&self, name: &str, want: &str, got: &Value) -> String {
        format!(
            "{}: {name} holds {got:?}, expected a {want} (schema table mismatch)",
            self.p.path
        )
    }
}

/// The light luxeval evaluates for `p`, with an optional caveat; or why it is not evaluated.
fn convert(p: &usd::LightPrim, up: UpAxis) -> std::result::Result<(Light, Option<String>), String> {
    let r = Reader { p };
    let path = &p.path;
    let ty = p.usd_type.as_str();
    if let Some(why) = &p.transform_error {
        return Err(why.clone());
    }
    if let Some(api) = &p.light_api
        && api == "LightAPI"
    {
        let on = match ty {
            "" => "an untyped prim".to_string(),
            ty => format!("a {ty} prim"),
        };
        return Err(format!(
            "{path}: LightAPI is applied to {on}, which is not a UsdLux light type; \
             luxeval does not evaluate it"
        ));
    }
    if let Some(api) = &p.light_api {
        let on = match ty {
            "" => "an untyped prim".to_string(),
            ty => format!("a {ty} prim"),
        };
        return Err(format!(
            "{path}: {api} lights (on {on}) are not supported yet"
        ));
    }
    let kind = match ty {
        "DistantLight" => LightType::Distant {
            angle: r.float("inputs:angle")?,
        },
        "SphereLight" => LightType::Sphere {
            radius: r.float("inputs:radius")?,
            treat_as_point: r.bool("treatAsPoint")?,
        },
        "DiskLight" => LightType::Disk {
            radius: r.float("inputs:radius")?,
        },
        "RectLight" => LightType::Rect {
            width: r.float("inputs:width")?,
            height: r.float("inputs:height")?,
        },
        "CylinderLight" => LightType::Cylinder {
            length: r.float("inputs:length")?,
            radius: r.float("inputs:radius")?,
            treat_as_line: r.bool("treatAsLine")?,
        },
        "DomeLight" | "DomeLight_1" => LightType::Dome,
        "PortalLight" => {
            return Err(format!(
                "{path}: PortalLight is not supported yet (it shapes a dome light's emission)"
            ));
        }
        "GeometryLight" => {
            return Err(format!(
                "{path}: GeometryLight is not supported (deprecated schema; use MeshLightAPI)"
            ));
        }
        "PluginLight" => {
            return Err(format!(
                "{path}: PluginLight is not supported (its emission is defined by a renderer plugin)"
            ));
        }
        other => return Err(format!("{path}: {other} is not a light type luxeval knows")),
    };
    let texture = match ty {
        "RectLight" | "DomeLight" | "DomeLight_1" => texture(&r, ty)?,
        _ => None,
    };
    let shaped = p.applied_schemas.iter().any(|s| s == "ShapingAPI");
    let inputs = LightInputs {
        intensity: r.float("inputs:intensity")?,
        exposure: r.float("inputs:exposure")?,
        color: r.color("inputs:color")?,
        enable_color_temperature: r.bool("inputs:enableColorTemperature")?,
        color_temperature: r.float("inputs:colorTemperature")?,
        normalize: r.bool("inputs:normalize")?,
        diffuse: r.float("inputs:diffuse")?,
        specular: r.float("inputs:specular")?,
    };
    let shaping = if shaped {
        Some(Shaping {
            focus: r.float("inputs:shaping:focus")?,
            focus_tint: r.color("inputs:shaping:focusTint")?,
            cone_angle: r.float("inputs:shaping:cone:angle")?,
            cone_softness: r.float("inputs:shaping:cone:softness")?,
            // DESIGN.md §6 I7: IES inputs are read only where ShapingAPI is applied.
            ies: match r.asset_ref("inputs:shaping:ies:file") {
                Some(file) => Some(Ies {
                    file,
                    angle_scale: r.float("inputs:shaping:ies:angleScale")?,
                    normalize: r.bool("inputs:shaping:ies:normalize")?,
                }),
                None => None,
            },
        })
    } else {
        None
    };
    let caveat = (shaped && !kind.is_shapeable())
        .then(|| format!("{path}: ShapingAPI has no effect on a {ty} (DESIGN.md §2), ignored"));
    let mut light = Light::new(kind).with_path(path.clone());
    light.inputs = inputs;
    light.shaping = shaping;
    light.texture = texture;
    Ok((light.with_usd_matrix(p.world).with_stage_up(up), caveat))
}

/// `inputs:texture:file`, `inputs:texture:format` (domes) and `poleAxis` (DomeLight_1), where
/// `texture:file` is authored (an empty asset path is no texture).
fn texture(r: &Reader, ty: &str) -> std::result::Result<Option<Texture>, String> {
    let Some(file) = r.asset_ref("inputs:texture:file") else {
        return Ok(None);
    };
    let mut t = Texture::new(file);
    if ty != "RectLight" {
        let token = r.token("inputs:texture:format")?;
        t.format = TextureFormat::from_token(token).ok_or_else(|| {
            format!(
                "{}: inputs:texture:format = {token:?} is not one of automatic, latlong, \
                 mirroredBall, angular, cubeMapVerticalCross",
                r.p.path
            )
        })?;
    }
    if ty == "DomeLight_1" {
        let token = r.token("poleAxis")?;
        t.pole_axis = Some(PoleAxis::from_token(token).ok_or_else(|| {
            format!(
                "{}: poleAxis = {token:?} is not one of scene, Y, Z",
                r.p.path
            )
        })?);
    }
    Ok(Some(t))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::schema;

    /// A light prim as `crate::usd` would return it, every input at its table fallback.
    fn prim(ty: &str, applied: &[&str]) -> usd::LightPrim {
        let inputs = schema::attrs_for(ty, applied)
            .into_iter()
            .map(|a| Input {
                name: a.name.to_string(),
                value: Value::fallback(a.fallback),
                authored: false,
            })
            .collect();
        usd::LightPrim {
            path: format!("/Lights/{ty}"),
            usd_type: ty.to_string(),
            applied_schemas: applied.iter().map(|s| s.to_string()).collect(),
            light_api: None,
            transform_error: None,
            visible: true,
            world: [
                [1.0, 0.0, 0.0, 0.0],
                [0.0, 1.0, 0.0, 0.0],
                [0.0, 0.0, 1.0, 0.0],
                [1.0, 2.0, 3.0, 1.0],
            ],
            inputs,
        }
    }

    fn set(p: &mut usd::LightPrim, name: &str, value: Value) {
        let i = p.inputs.iter_mut().find(|i| i.name == name).unwrap();
        i.value = value;
        i.authored = true;
    }

    #[test]
    fn fallback_lights_convert_to_the_model_fallbacks() {
        for ty in [
            "DistantLight",
            "SphereLight",
            "DiskLight",
            "RectLight",
            "CylinderLight",
            "DomeLight",
            "DomeLight_1",
        ] {
            let (light, caveat) = convert(&prim(ty, &[]), UpAxis::Y).unwrap();
            assert_eq!(caveat, None);
            let expected = Light::new(LightType::fallback(ty).unwrap())
                .with_path(format!("/Lights/{ty}"))
                .with_usd_matrix(prim(ty, &[]).world);
            assert_eq!(light, expected, "{ty}");
            assert_eq!(light.origin(), DVec3::new(1.0, 2.0, 3.0));
        }
    }

    #[test]
    fn shaping_only_where_applied() {
        let (plain, _) = convert(&prim("DiskLight", &[]), UpAxis::Y).unwrap();
        assert_eq!(plain.shaping, None);
        let mut p = prim("DiskLight", &["ShapingAPI"]);
        let (defaults, _) = convert(&p, UpAxis::Y).unwrap();
        assert_eq!(defaults.shaping, Some(Shaping::default()));
        set(&mut p, "inputs:shaping:cone:angle", Value::Float(30.0));
        set(
            &mut p,
            "inputs:shaping:focusTint",
            Value::Color([1.0, 0.5, 0.0]),
        );
        let (authored, _) = convert(&p, UpAxis::Y).unwrap();
        let s = authored.shaping.unwrap();
        assert_eq!(s.cone_angle, 30.0);
        assert_eq!(s.focus_tint, DVec3::new(1.0, 0.5, 0.0));
    }

    #[test]
    fn unsupported_features_name_the_prim_and_feature() {
        let mut rect = prim("RectLight", &[]);
        set(
            &mut rect,
            "inputs:texture:file",
            Value::Asset {
                authored: "tex.png".into(),
                resolved: None,
            },
        );
        // RectLight textures are evaluated: read into the model, not skipped.
        let (l, _) = convert(&rect, UpAxis::Y).unwrap();
        assert_eq!(l.texture.unwrap().file.authored, "tex.png");

        let mut ies = prim("SphereLight", &["ShapingAPI"]);
        set(
            &mut ies,
            "inputs:shaping:ies:file",
            Value::Asset {
                authored: "a.ies".into(),
                resolved: None,
            },
        );
        // IES inputs are read where ShapingAPI is applied; an unresolved file is reported when
        // the light is prepared (naming the prim and the file), not skipped here.
        let (l, _) = convert(&ies, UpAxis::Y).unwrap();
        let i = l.shaping.unwrap().ies.unwrap();
        assert_eq!((i.file.authored.as_str(), i.file.resolved), ("a.ies", None));
        assert_eq!((i.angle_scale, i.normalize), (0.0, false));

        // An authored but empty asset path is no texture.
        let mut empty = prim("DomeLight", &[]);
        set(
            &mut empty,
            "inputs:texture:file",
            Value::Asset {
                authored: String::new(),
                resolved: None,
            },
        );
        assert!(convert(&empty, UpAxis::Y).is_ok());

        for ty in ["PortalLight", "GeometryLight", "PluginLight"] {
            let e = convert(&prim(ty, &[]), UpAxis::Y).unwrap_err();
            assert!(e.contains(ty) && e.contains("/Lights/"), "{e}");
        }
        let mut mesh = prim("Mesh", &["MeshLightAPI"]);
        mesh.light_api = Some("MeshLightAPI".into());
        let e = convert(&mesh, UpAxis::Y).unwrap_err();
        assert!(e.contains("MeshLightAPI"), "{e}");
    }

    #[test]
    fn textures_are_read_into_the_model() {
        let asset = || Value::Asset {
            authored: "env.exr".into(),
            resolved: Some("/abs/env.exr".into()),
        };
        let mut d1 = prim("DomeLight_1", &[]);
        set(&mut d1, "inputs:texture:file", asset());
        let t = texture(&Reader { p: &d1 }, "DomeLight_1").unwrap().unwrap();
        assert_eq!(t.file.resolved.as_deref(), Some("/abs/env.exr"));
        // The schema fallbacks: automatic, poleAxis scene.
        assert_eq!(
            (t.format, t.pole_axis),
            (TextureFormat::Automatic, Some(PoleAxis::Scene))
        );
        set(
            &mut d1,
            "inputs:texture:format",
            Value::Token("mirroredBall".into()),
        );
        set(&mut d1, "poleAxis", Value::Token("Z".into()));
        let t = texture(&Reader { p: &d1 }, "DomeLight_1").unwrap().unwrap();
        assert_eq!(
            (t.format, t.pole_axis),
            (TextureFormat::MirroredBall, Some(PoleAxis::Z))
        );
        // A plain DomeLight has no pole offset; a RectLight no format.
        let mut d = prim("DomeLight", &[]);
        set(&mut d, "inputs:texture:file", asset());
        set(
            &mut d,
            "inputs:texture:format",
            Value::Token("angular".into()),
        );
        let t = texture(&Reader { p: &d }, "DomeLight").unwrap().unwrap();
        assert_eq!((t.format, t.pole_axis), (TextureFormat::Angular, None));
        let mut rect = prim("RectLight", &[]);
        set(&mut rect, "inputs:texture:file", asset());
        let t = texture(&Reader { p: &rect }, "RectLight").unwrap().unwrap();
        assert_eq!((t.format, t.pole_axis), (TextureFormat::Automatic, None));
        // A token outside the schema's list names the prim and the attribute.
        set(&mut d, "inputs:texture:format", Value::Token("cube".into()));
        let e = texture(&Reader { p: &d }, "DomeLight").unwrap_err();
        assert!(
            e.contains("/Lights/DomeLight") && e.contains("texture:format"),
            "{e}"
        );
        set(&mut d1, "poleAxis", Value::Token("X".into()));
        let e = texture(&Reader { p: &d1 }, "DomeLight_1").unwrap_err();
        assert!(e.contains("poleAxis"), "{e}");
        // A textured RectLight is evaluated, not skipped.
        assert!(convert(&rect, UpAxis::Y).unwrap().0.texture.is_some());
    }

    #[test]
    fn shaping_on_distant_is_a_caveat() {
        let (light, caveat) = convert(&prim("DistantLight", &["ShapingAPI"]), UpAxis::Y).unwrap();
        assert!(light.shaping.is_some());
        assert!(caveat.unwrap().contains("no effect"));
    }

    #[test]
    fn evaluable_filters_and_rejects_unknown_selection() {
        let mut hidden = StageLight::from_prim(prim("SphereLight", &[]), UpAxis::Y);
        hidden.path = "/Lights/Hidden".into();
        hidden.visible = false;
        let scene = Stage {
            file: "x.usda".into(),
            up_axis: "Y".into(),
            meters_per_unit: 0.01,
            time: TimeRule::Earliest,
            lights: vec![
                StageLight::from_prim(prim("DiskLight", &[]), UpAxis::Y),
                StageLight::from_prim(prim("PortalLight", &[]), UpAxis::Y),
                hidden,
            ],
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

    #[test]
    fn json_shape() {
        let l = StageLight::from_prim(prim("SphereLight", &[]), UpAxis::Y);
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
