//! One light prim as luxeval reads it: its typed inputs turned into a model [`Light`] (with an
//! optional caveat), or the reason it is not evaluated, naming the prim.

use glam::DVec3;

use super::stage as usd;
use crate::model::{
    Asset, Ies, Light, LightInputs, LightType, MeshLight, PoleAxis, Portal, Shaping, Texture,
    TextureFormat, UpAxis, Value,
};

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

/// Why a light prim is not evaluated.
#[derive(Debug)]
pub(super) enum NotEvaluated {
    /// luxeval does not evaluate it (yet): listed with this warning, skipped by the queries.
    Skipped(String),
    /// An input holds a value the schema does not allow: listed with a warning, and refused by
    /// every query that would evaluate it (exit 2), naming the prim and the attribute.
    Refused(RefusedInput),
}

/// An input value a query refuses: the attribute, its value as authored, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct RefusedInput {
    pub attr: String,
    pub value: String,
    pub reason: String,
}

impl std::fmt::Display for NotEvaluated {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NotEvaluated::Skipped(why) => f.write_str(why),
            NotEvaluated::Refused(r) => write!(f, "{} = {}: {}", r.attr, r.value, r.reason),
        }
    }
}

impl From<String> for NotEvaluated {
    fn from(why: String) -> Self {
        NotEvaluated::Skipped(why)
    }
}

/// What luxeval reads a light prim as.
#[derive(Debug)]
pub(super) enum Read {
    /// A light the queries evaluate.
    Light(Light),
    /// A mesh light (DESIGN.md §7): read, not evaluated yet.
    Mesh(MeshLight),
    /// A portal (DESIGN.md §8): read, not evaluated yet; its domes are filled in by the scene.
    Portal(Portal),
}

/// What `p` is read as, with an optional caveat (naming the prim); or why it is not read.
/// `max_mesh_triangles` bounds a mesh light's triangles (docs/INPUTS.md "Limits").
pub(super) fn read(
    p: &usd::LightPrim,
    up: UpAxis,
    max_mesh_triangles: u64,
) -> std::result::Result<(Read, Option<String>), NotEvaluated> {
    let r = Reader { p };
    let caveat = |mut own: Vec<String>| {
        own.extend(unapplied_caveats(p));
        (!own.is_empty()).then(|| own.join("; "))
    };
    if p.transform_error.is_none()
        && let Some(arrays) = &p.mesh
    {
        let (inputs, shaping) = light_inputs(&r)?;
        let (mesh, warnings) = super::mesh::convert(
            p,
            arrays,
            inputs,
            shaping,
            |name| r.token(name).map(str::to_string),
            |name| r.bool(name),
            max_mesh_triangles,
        )?;
        return Ok((Read::Mesh(mesh), caveat(warnings)));
    }
    if p.transform_error.is_none() && p.usd_type == "PortalLight" {
        let (portal, warnings) = portal(&r)?;
        return Ok((Read::Portal(portal), caveat(warnings)));
    }
    convert(p, up).map(|(light, caveat)| (Read::Light(light), caveat))
}

/// A `PortalLight` (DESIGN.md §8 P1): its size and multiplier inputs; normalize and ShapingAPI
/// do not apply to a portal, so authoring them is said.
fn portal(r: &Reader) -> std::result::Result<(Portal, Vec<String>), NotEvaluated> {
    let p = r.p;
    let mut warnings = Vec::new();
    if p.inputs
        .iter()
        .any(|i| i.name == "inputs:normalize" && i.authored)
    {
        warnings.push(format!(
            "{}: inputs:normalize does not apply to a portal (DESIGN.md §8 P1), ignored",
            p.path
        ));
    }
    if p.applied_schemas.iter().any(|s| s == "ShapingAPI") {
        warnings.push(format!(
            "{}: ShapingAPI does not apply to a portal (DESIGN.md §8 P1), ignored",
            p.path
        ));
    }
    Ok((
        Portal {
            path: p.path.clone(),
            width: r.float("inputs:width")?,
            height: r.float("inputs:height")?,
            intensity: r.float("inputs:intensity")?,
            exposure: r.float("inputs:exposure")?,
            color: r.color("inputs:color")?,
            enable_color_temperature: r.bool("inputs:enableColorTemperature")?,
            color_temperature: r.float("inputs:colorTemperature")?,
            world: glam::DMat4::from_cols_array_2d(&p.world),
            domes: Vec::new(),
        },
        warnings,
    ))
}

/// LightAPI's inputs and, where ShapingAPI is applied, the shaping (every light type's).
fn light_inputs(r: &Reader) -> std::result::Result<(LightInputs, Option<Shaping>), NotEvaluated> {
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
    let shaped = r.p.applied_schemas.iter().any(|s| s == "ShapingAPI");
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
    Ok((inputs, shaping))
}

/// The light luxeval evaluates for `p`, with an optional caveat; or why it is not evaluated.
pub(super) fn convert(
    p: &usd::LightPrim,
    up: UpAxis,
) -> std::result::Result<(Light, Option<String>), NotEvaluated> {
    let r = Reader { p };
    let path = &p.path;
    let ty = p.usd_type.as_str();
    if let Some(why) = &p.transform_error {
        return Err(why.clone().into());
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
        )
        .into());
    }
    if let Some(api) = &p.light_api {
        let on = match ty {
            "" => "an untyped prim".to_string(),
            ty => format!("a {ty} prim"),
        };
        // A Mesh with MeshLightAPI is read by [`read`]; MeshLightAPI on another type and
        // VolumeLightAPI are listed and skipped (DESIGN.md §7 M1).
        return Err(format!("{path}: {api} lights (on {on}) are not supported").into());
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
            // Read by [`read`] as a portal, never evaluated as a light (DESIGN.md §8 P1).
            return Err(format!("{path}: a PortalLight is a portal of a dome, not a light").into());
        }
        "GeometryLight" => {
            return Err(format!(
                "{path}: GeometryLight is not supported (deprecated schema; use MeshLightAPI)"
            )
            .into());
        }
        "PluginLight" => {
            return Err(format!(
                "{path}: PluginLight is not supported (its emission is defined by a renderer plugin)"
            ).into());
        }
        other => return Err(format!("{path}: {other} is not a light type luxeval knows").into()),
    };
    let texture = match ty {
        "RectLight" | "DomeLight" | "DomeLight_1" => texture(&r, ty)?,
        _ => None,
    };
    let shaped = p.applied_schemas.iter().any(|s| s == "ShapingAPI");
    let (inputs, shaping) = light_inputs(&r)?;
    let mut caveats: Vec<String> = Vec::new();
    if shaped && !kind.is_shapeable() {
        caveats.push(format!(
            "{path}: ShapingAPI has no effect on a {ty} (DESIGN.md §2), ignored"
        ));
    }
    if !p.stray_inputs.is_empty() {
        caveats.push(format!(
            "{path}: {} authored, but a {ty} has no such input; ignored",
            p.stray_inputs.join(", ")
        ));
    }
    caveats.extend(unapplied_caveats(p));
    let caveat = (!caveats.is_empty()).then(|| caveats.join("; "));
    let mut light = Light::new(kind).with_path(path.clone());
    light.inputs = inputs;
    light.shaping = shaping;
    light.texture = texture;
    Ok((light.with_usd_matrix(p.world).with_stage_up(up), caveat))
}

/// What the light authors that a renderer applies and luxeval does not, each said once
/// (the paths are in [`super::StageLight`]'s typed fields, listed by `luxeval lights`).
fn unapplied_caveats(p: &usd::LightPrim) -> Vec<String> {
    let path = &p.path;
    let x = &p.extras;
    let mut out = Vec::new();
    if !x.shaping_without_api.is_empty() {
        // ShapingAPI's inputs belong to the prims it is applied to (spec/003 "API classes";
        // DESIGN.md §2 "ShapingAPI not applied: no shaping").
        out.push(format!(
            "{path}: {} authored, but ShapingAPI is not applied, so they are not part of the \
             light; evaluated unshaped (apply ShapingAPI to shape it)",
            x.shaping_without_api.join(", ")
        ));
    }
    let mut unapplied = Vec::new();
    match x.filters.len() {
        0 => {}
        1 => unapplied.push("1 light filter (light:filters)".to_string()),
        n => unapplied.push(format!("{n} light filters (light:filters)")),
    }
    for c in &x.link_collections {
        let what = match c.name.as_str() {
            "lightLink" => "light linking",
            _ => "shadow linking",
        };
        unapplied.push(format!("{what} (collection:{})", c.name));
    }
    if !unapplied.is_empty() {
        // luxeval lights every receiver with every light, unfiltered, and computes no shadows
        // (DESIGN.md §2: lights do not occlude); a renderer applies these.
        out.push(format!(
            "{path}: not applied by luxeval: {}",
            unapplied.join(", ")
        ));
    }
    out
}

/// `inputs:texture:file`, `inputs:texture:format` (domes) and `poleAxis` (DomeLight_1), where
/// `texture:file` is authored (an empty asset path is no texture).
fn texture(r: &Reader, ty: &str) -> std::result::Result<Option<Texture>, NotEvaluated> {
    let Some(file) = r.asset_ref("inputs:texture:file") else {
        return Ok(None);
    };
    let mut t = Texture::new(file);
    // A token the schema does not allow is refused, never read as the fallback.
    let refused = |attr: &str, token: &str, allowed: &str| {
        NotEvaluated::Refused(RefusedInput {
            attr: attr.to_string(),
            value: format!("{token:?}"),
            reason: format!("not one of {allowed}"),
        })
    };
    if ty != "RectLight" {
        let token = r.token("inputs:texture:format")?;
        t.format = TextureFormat::from_token(token).ok_or_else(|| {
            refused(
                "inputs:texture:format",
                token,
                "automatic, latlong, mirroredBall, angular, cubeMapVerticalCross",
            )
        })?;
    }
    if ty == "DomeLight_1" {
        let token = r.token("poleAxis")?;
        t.pole_axis = Some(
            PoleAxis::from_token(token).ok_or_else(|| refused("poleAxis", token, "scene, Y, Z"))?,
        );
    }
    Ok(Some(t))
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::model::{Input, schema};

    /// A light prim as `crate::usd` would return it, every input at its table fallback.
    pub(crate) fn prim(ty: &str, applied: &[&str]) -> usd::LightPrim {
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
            stray_inputs: Vec::new(),
            extras: Default::default(),
            mesh: None,
            portals: Vec::new(),
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

        for ty in ["GeometryLight", "PluginLight"] {
            let e = convert(&prim(ty, &[]), UpAxis::Y).unwrap_err().to_string();
            assert!(e.contains(ty) && e.contains("/Lights/"), "{e}");
        }
        // MeshLightAPI on a prim that is not a Mesh has no geometry to read.
        let mut xform = prim("Xform", &["MeshLightAPI"]);
        xform.light_api = Some("MeshLightAPI".into());
        let e = convert(&xform, UpAxis::Y).unwrap_err().to_string();
        assert!(e.contains("MeshLightAPI") && e.contains("Xform"), "{e}");
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
        // A token outside the schema's list is refused (not skipped), naming the attribute.
        set(&mut d, "inputs:texture:format", Value::Token("cube".into()));
        let Err(NotEvaluated::Refused(r)) = texture(&Reader { p: &d }, "DomeLight") else {
            panic!("an unknown texture:format must be refused");
        };
        assert_eq!(
            (r.attr.as_str(), r.value.as_str()),
            ("inputs:texture:format", "\"cube\"")
        );
        set(&mut d1, "poleAxis", Value::Token("X".into()));
        let Err(NotEvaluated::Refused(r)) = texture(&Reader { p: &d1 }, "DomeLight_1") else {
            panic!("an unknown poleAxis must be refused");
        };
        assert_eq!(r.attr, "poleAxis");
        // A textured RectLight is evaluated, not skipped.
        assert!(convert(&rect, UpAxis::Y).unwrap().0.texture.is_some());
    }

    #[test]
    fn shaping_on_distant_is_a_caveat() {
        let (light, caveat) = convert(&prim("DistantLight", &["ShapingAPI"]), UpAxis::Y).unwrap();
        assert!(light.shaping.is_some());
        assert!(caveat.unwrap().contains("no effect"));
    }
}
