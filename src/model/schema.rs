//! UsdLux schema fallbacks: the one table of every attribute luxeval reads, with the value USD
//! supplies when the attribute is not authored.
//!
//! Every other module (the light model's constructors, the USD loader, `luxeval lights --json`)
//! reads fallbacks from here; none retypes a number. Values are those of the UsdLux schema
//! (spec/001 LightAPI, spec/002 ShapingAPI, spec/004 DomeLight_1, and the schema attribute table
//! in reference/openusd-reference.md §8), checked against Pixar's `usd-core` in the USD fixtures.
//!
//! Two schema-level facts live here as well because they change fallbacks:
//! - DistantLight overrides LightAPI's `inputs:intensity` fallback (1 → 50000).
//! - ShapingAPI's fallbacks apply only when ShapingAPI is applied; without it there is no shaping
//!   at all (DESIGN.md §2), which the model expresses as `Light::shaping == None`.

/// A fallback value as the schema types it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Fallback {
    Float(f64),
    Bool(bool),
    Color([f64; 3]),
    Token(&'static str),
    /// An `asset` attribute: no fallback (empty asset path).
    Asset,
}

/// One attribute of one schema.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SchemaAttr {
    /// The schema that declares the attribute, e.g. `LightAPI`, `SphereLight`.
    pub schema: &'static str,
    /// The full attribute name, e.g. `inputs:intensity`, `treatAsPoint`.
    pub name: &'static str,
    pub fallback: Fallback,
}

/// LightAPI fallbacks (spec/001).
pub mod light_api {
    pub const INTENSITY: f64 = 1.0;
    pub const EXPOSURE: f64 = 0.0;
    pub const DIFFUSE: f64 = 1.0;
    pub const SPECULAR: f64 = 1.0;
    pub const NORMALIZE: bool = false;
    pub const COLOR: [f64; 3] = [1.0, 1.0, 1.0];
    pub const ENABLE_COLOR_TEMPERATURE: bool = false;
    pub const COLOR_TEMPERATURE: f64 = 6500.0;
}

/// ShapingAPI fallbacks (spec/002); they hold only where ShapingAPI is applied.
pub mod shaping_api {
    pub const FOCUS: f64 = 0.0;
    pub const FOCUS_TINT: [f64; 3] = [0.0, 0.0, 0.0];
    pub const CONE_ANGLE: f64 = 90.0;
    pub const CONE_SOFTNESS: f64 = 0.0;
    pub const IES_ANGLE_SCALE: f64 = 0.0;
    pub const IES_NORMALIZE: bool = false;
}

/// ShadowAPI fallbacks. Shadows do not change an unoccluded query; they are reported only.
pub mod shadow_api {
    pub const ENABLE: bool = true;
    pub const COLOR: [f64; 3] = [0.0, 0.0, 0.0];
    pub const DISTANCE: f64 = -1.0;
    pub const FALLOFF: f64 = -1.0;
    pub const FALLOFF_GAMMA: f64 = 1.0;
}

/// Per-type fallbacks.
pub mod distant {
    /// DistantLight overrides LightAPI's intensity fallback.
    pub const INTENSITY: f64 = 50000.0;
    /// Full angular diameter in degrees (the sun's).
    pub const ANGLE: f64 = 0.53;
}
pub mod sphere {
    pub const RADIUS: f64 = 0.5;
    pub const TREAT_AS_POINT: bool = false;
}
pub mod disk {
    pub const RADIUS: f64 = 0.5;
}
pub mod rect {
    pub const WIDTH: f64 = 1.0;
    pub const HEIGHT: f64 = 1.0;
}
pub mod cylinder {
    pub const LENGTH: f64 = 1.0;
    pub const RADIUS: f64 = 0.5;
    pub const TREAT_AS_LINE: bool = false;
}
pub mod dome {
    pub const TEXTURE_FORMAT: &str = "automatic";
    pub const GUIDE_RADIUS: f64 = 1.0e5;
    /// DomeLight_1 only.
    pub const POLE_AXIS: &str = "scene";
}
pub mod portal {
    pub const WIDTH: f64 = 1.0;
    pub const HEIGHT: f64 = 1.0;
}
/// MeshLightAPI's own fallback (spec/001 "MeshLightAPI"; DESIGN.md §7 M2).
pub mod mesh_light_api {
    pub const MATERIAL_SYNC_MODE: &str = "materialGlowTintsLight";
}
/// The UsdGeom Mesh attributes a mesh light's geometry reads (DESIGN.md §7 M1): Gprim's
/// `orientation` and `doubleSided`, Mesh's `subdivisionScheme`.
pub mod mesh {
    pub const ORIENTATION: &str = "rightHanded";
    pub const DOUBLE_SIDED: bool = false;
    pub const SUBDIVISION_SCHEME: &str = "catmullClark";
}
/// UsdPreviewSurface's `inputs:emissiveColor` fallback, the tint of a mesh light whose bound
/// material authors none (DESIGN.md §7 M2). Not a light attribute, so not a row of [`TABLE`].
pub mod preview_surface {
    pub const EMISSIVE_COLOR: [f64; 3] = [0.0, 0.0, 0.0];
}

use Fallback::{Asset, Bool, Color, Float, Token};

const fn attr(schema: &'static str, name: &'static str, fallback: Fallback) -> SchemaAttr {
    SchemaAttr {
        schema,
        name,
        fallback,
    }
}

/// The table. Order within a schema is the order `luxeval lights` prints inputs in.
pub const TABLE: &[SchemaAttr] = &[
    // LightAPI
    attr("LightAPI", "inputs:intensity", Float(light_api::INTENSITY)),
    attr("LightAPI", "inputs:exposure", Float(light_api::EXPOSURE)),
    attr("LightAPI", "inputs:color", Color(light_api::COLOR)),
    attr(
        "LightAPI",
        "inputs:enableColorTemperature",
        Bool(light_api::ENABLE_COLOR_TEMPERATURE),
    ),
    attr(
        "LightAPI",
        "inputs:colorTemperature",
        Float(light_api::COLOR_TEMPERATURE),
    ),
    attr("LightAPI", "inputs:normalize", Bool(light_api::NORMALIZE)),
    attr("LightAPI", "inputs:diffuse", Float(light_api::DIFFUSE)),
    attr("LightAPI", "inputs:specular", Float(light_api::SPECULAR)),
    // ShapingAPI
    attr(
        "ShapingAPI",
        "inputs:shaping:focus",
        Float(shaping_api::FOCUS),
    ),
    attr(
        "ShapingAPI",
        "inputs:shaping:focusTint",
        Color(shaping_api::FOCUS_TINT),
    ),
    attr(
        "ShapingAPI",
        "inputs:shaping:cone:angle",
        Float(shaping_api::CONE_ANGLE),
    ),
    attr(
        "ShapingAPI",
        "inputs:shaping:cone:softness",
        Float(shaping_api::CONE_SOFTNESS),
    ),
    attr("ShapingAPI", "inputs:shaping:ies:file", Asset),
    attr(
        "ShapingAPI",
        "inputs:shaping:ies:angleScale",
        Float(shaping_api::IES_ANGLE_SCALE),
    ),
    attr(
        "ShapingAPI",
        "inputs:shaping:ies:normalize",
        Bool(shaping_api::IES_NORMALIZE),
    ),
    // ShadowAPI
    attr(
        "ShadowAPI",
        "inputs:shadow:enable",
        Bool(shadow_api::ENABLE),
    ),
    attr("ShadowAPI", "inputs:shadow:color", Color(shadow_api::COLOR)),
    attr(
        "ShadowAPI",
        "inputs:shadow:distance",
        Float(shadow_api::DISTANCE),
    ),
    attr(
        "ShadowAPI",
        "inputs:shadow:falloff",
        Float(shadow_api::FALLOFF),
    ),
    attr(
        "ShadowAPI",
        "inputs:shadow:falloffGamma",
        Float(shadow_api::FALLOFF_GAMMA),
    ),
    // Typed lights
    attr(
        "DistantLight",
        "inputs:intensity",
        Float(distant::INTENSITY),
    ),
    attr("DistantLight", "inputs:angle", Float(distant::ANGLE)),
    attr("SphereLight", "inputs:radius", Float(sphere::RADIUS)),
    attr("SphereLight", "treatAsPoint", Bool(sphere::TREAT_AS_POINT)),
    attr("DiskLight", "inputs:radius", Float(disk::RADIUS)),
    attr("RectLight", "inputs:width", Float(rect::WIDTH)),
    attr("RectLight", "inputs:height", Float(rect::HEIGHT)),
    attr("RectLight", "inputs:texture:file", Asset),
    attr("CylinderLight", "inputs:length", Float(cylinder::LENGTH)),
    attr("CylinderLight", "inputs:radius", Float(cylinder::RADIUS)),
    attr(
        "CylinderLight",
        "treatAsLine",
        Bool(cylinder::TREAT_AS_LINE),
    ),
    attr("DomeLight", "inputs:texture:file", Asset),
    attr(
        "DomeLight",
        "inputs:texture:format",
        Token(dome::TEXTURE_FORMAT),
    ),
    attr("DomeLight", "guideRadius", Float(dome::GUIDE_RADIUS)),
    attr("DomeLight_1", "inputs:texture:file", Asset),
    attr(
        "DomeLight_1",
        "inputs:texture:format",
        Token(dome::TEXTURE_FORMAT),
    ),
    attr("DomeLight_1", "guideRadius", Float(dome::GUIDE_RADIUS)),
    attr("DomeLight_1", "poleAxis", Token(dome::POLE_AXIS)),
    attr("PortalLight", "inputs:width", Float(portal::WIDTH)),
    attr("PortalLight", "inputs:height", Float(portal::HEIGHT)),
    // A MeshLightAPI prim is a Mesh (DESIGN.md §7 M1): the geometry's uniform attributes with
    // their fallbacks; the arrays (points, counts, indices, holes) have none and are read apart.
    attr("Mesh", "orientation", Token(mesh::ORIENTATION)),
    attr("Mesh", "doubleSided", Bool(mesh::DOUBLE_SIDED)),
    attr("Mesh", "subdivisionScheme", Token(mesh::SUBDIVISION_SCHEME)),
    attr(
        "MeshLightAPI",
        "light:materialSyncMode",
        Token(mesh_light_api::MATERIAL_SYNC_MODE),
    ),
];

/// The attributes of a prim of USD type `type_name` with the applied API schemas `applied`
/// (e.g. `["ShapingAPI"]`), each with its effective fallback. Type-level rows override API rows of
/// the same name (DistantLight's intensity), and the order is LightAPI, then the type's own
/// attributes, then the applied APIs'.
pub fn attrs_for(type_name: &str, applied: &[&str]) -> Vec<SchemaAttr> {
    let mut out: Vec<SchemaAttr> = Vec::new();
    let push = |a: SchemaAttr, out: &mut Vec<SchemaAttr>| {
        if let Some(slot) = out.iter_mut().find(|o| o.name == a.name) {
            *slot = a;
        } else {
            out.push(a);
        }
    };
    for a in TABLE.iter().filter(|a| a.schema == "LightAPI") {
        push(*a, &mut out);
    }
    for a in TABLE.iter().filter(|a| a.schema == type_name) {
        push(*a, &mut out);
    }
    for api in applied {
        if *api == "LightAPI" {
            continue;
        }
        for a in TABLE.iter().filter(|a| a.schema == *api) {
            push(*a, &mut out);
        }
    }
    out
}

/// The effective fallback of one attribute on a prim of `type_name` with `applied` APIs.
pub fn fallback(type_name: &str, applied: &[&str], name: &str) -> Option<Fallback> {
    attrs_for(type_name, applied)
        .into_iter()
        .find(|a| a.name == name)
        .map(|a| a.fallback)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distant_overrides_light_api_intensity() {
        assert_eq!(
            fallback("DistantLight", &[], "inputs:intensity"),
            Some(Float(50000.0))
        );
        assert_eq!(
            fallback("SphereLight", &[], "inputs:intensity"),
            Some(Float(1.0))
        );
        let attrs = attrs_for("DistantLight", &[]);
        assert_eq!(
            attrs
                .iter()
                .filter(|a| a.name == "inputs:intensity")
                .count(),
            1
        );
    }

    #[test]
    fn shaping_rows_only_when_applied() {
        assert_eq!(
            fallback("DiskLight", &[], "inputs:shaping:cone:angle"),
            None
        );
        assert_eq!(
            fallback("DiskLight", &["ShapingAPI"], "inputs:shaping:cone:angle"),
            Some(Float(90.0))
        );
    }

    #[test]
    fn no_duplicate_rows_within_a_schema() {
        for (i, a) in TABLE.iter().enumerate() {
            for b in &TABLE[i + 1..] {
                assert!(
                    !(a.schema == b.schema && a.name == b.name),
                    "{}.{} twice",
                    a.schema,
                    a.name
                );
            }
        }
    }
}
