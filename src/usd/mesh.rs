//! Mesh lights (DESIGN.md §7 M1, M2) as the stage authors them: the geometry arrays at the
//! query time and the emissive colour of the bound material, read with openusd; and their
//! conversion into a model [`MeshLight`]. The uniform attributes (`orientation`, `doubleSided`,
//! `subdivisionScheme`, `light:materialSyncMode`) are rows of the schema table and arrive as
//! the prim's inputs like every light's.

use glam::DVec3;
use openusd::sdf;
use openusd::usd::{self as ousd, TimeCode};
use serde::Serialize;

use super::light::{NotEvaluated, RefusedInput};
use super::stage as usd;
use super::values::{is_blocked, value_at};
use crate::error::{LuxError, Result};
use crate::limits::{ENV_MAX_MESH_TRIANGLES, raise_hint};
use crate::model::schema::preview_surface;
use crate::model::{LightInputs, MeshGeometry, MeshLight, MeshTopology, Shaping, Tint};

/// A mesh light's arrays at one time, as authored (unauthored or blocked: empty).
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct MeshArrays {
    pub points: Vec<[f64; 3]>,
    pub face_vertex_counts: Vec<i32>,
    pub face_vertex_indices: Vec<i32>,
    pub hole_indices: Vec<i32>,
    /// The bound material's glow, found whatever `light:materialSyncMode` says (which mode
    /// applies is the conversion's decision).
    pub glow: Glow,
}

/// What the material bound to a mesh light says about its tint (M2).
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) enum Glow {
    /// No `material:binding` on the prim or an ancestor.
    #[default]
    NoMaterial,
    /// The constant `inputs:emissiveColor` of the UsdPreviewSurface driving the bound
    /// material's surface (its fallback when unauthored).
    Emissive {
        material: String,
        shader: String,
        rgb: [f64; 3],
        authored: bool,
    },
    /// A binding luxeval does not evaluate; the words say what (and name the prims).
    NotEvaluated(String),
}

/// Reads `points`, `faceVertexCounts`, `faceVertexIndices`, `holeIndices` of `prim` at `tc`
/// (interpolated between time samples as USD does: [`value_at`]) and its material's glow. An
/// array of the wrong type is bad input naming the prim and attribute.
pub(crate) fn read_arrays(prim: &ousd::Prim, light: &str, tc: TimeCode) -> Result<MeshArrays> {
    let e = |attr: &str| {
        let attr = attr.to_string();
        move |err: openusd::Error| {
            LuxError::attr(light, &attr, "?", format!("cannot be read: {err}"))
        }
    };
    let get = |name: &str| -> Result<Option<sdf::Value>> {
        Ok(value_at(&prim.attribute(name), tc)
            .map_err(e(name))?
            .filter(|v| !is_blocked(v)))
    };
    let points = match get("points")? {
        None => Vec::new(),
        Some(v) => points(v).map_err(|shown| {
            LuxError::attr(
                light,
                "points",
                shown,
                "expected a point3f[] value, as the Mesh schema declares",
            )
        })?,
    };
    let ints = |name: &str| -> Result<Vec<i32>> {
        match get(name)? {
            None => Ok(Vec::new()),
            Some(sdf::Value::IntVec(v)) => Ok(v),
            Some(other) => Err(LuxError::attr(
                light,
                name,
                short(&other),
                "expected an int[] value, as the Mesh schema declares",
            )),
        }
    };
    Ok(MeshArrays {
        points,
        face_vertex_counts: ints("faceVertexCounts")?,
        face_vertex_indices: ints("faceVertexIndices")?,
        hole_indices: ints("holeIndices")?,
        glow: glow(prim, tc).map_err(e("material:binding"))?,
    })
}

/// A value as an error message shows it: its start, not megabytes of array.
fn short(v: &sdf::Value) -> String {
    let mut s = format!("{v:?}");
    if s.len() > 80 {
        s.truncate(77);
        s.push_str("...");
    }
    s
}

/// Any precision of point array, widened to f64 exactly; the shown value when it is none.
fn points(v: sdf::Value) -> std::result::Result<Vec<[f64; 3]>, String> {
    let widen = |p: [f32; 3]| p.map(f64::from);
    match v {
        sdf::Value::Vec3fVec(v) => Ok(v.into_iter().map(|p| widen(p.into())).collect()),
        sdf::Value::Vec3dVec(v) => Ok(v.into_iter().map(<[f64; 3]>::from).collect()),
        sdf::Value::Vec3hVec(v) => v
            .into_iter()
            .map(|p| {
                sdf::Value::Vec3h(p)
                    .cast::<[f64; 3]>()
                    .map_err(|e| e.to_string())
            })
            .collect(),
        other => Err(short(&other)),
    }
}

/// The material bound to `prim` for all purposes (M2): the nearest direct `material:binding`
/// on the prim or an ancestor, then the UsdPreviewSurface driving its `outputs:surface`.
/// Collection bindings and `bindMaterialAs` strengths, which can override the nearest direct
/// binding (UsdShadeMaterialBindingAPI's resolution), are not resolved: where any prim on the
/// way authors one the glow is [`Glow::NotEvaluated`]. A binding counts whether or not
/// MaterialBindingAPI is applied to its prim, as usd-core 26.11's `ComputeBoundMaterial` counts
/// it (with a warning).
fn glow(prim: &ousd::Prim, tc: TimeCode) -> openusd::Result<Glow> {
    let mut bound: Option<sdf::Path> = None;
    let mut cur = Some(prim.clone());
    while let Some(p) = cur.filter(|p| !p.path().is_abs_root()) {
        for name in p.authored_property_names()? {
            let name = name.as_str();
            if name.starts_with("material:binding:collection:") {
                return Ok(Glow::NotEvaluated(format!(
                    "a collection-based material binding ({} on {})",
                    name,
                    p.path()
                )));
            }
        }
        let rel = p.relationship("material:binding");
        if rel.has_authored_targets()? {
            if rel.get_metadata::<sdf::Value>("bindMaterialAs")?.is_some() {
                return Ok(Glow::NotEvaluated(format!(
                    "a bindMaterialAs binding strength (material:binding on {})",
                    p.path()
                )));
            }
            if bound.is_none() {
                bound = rel.targets()?.into_iter().next();
                if bound.is_none() {
                    // An empty binding blocks the ancestors' (no material).
                    return Ok(Glow::NoMaterial);
                }
            }
        }
        cur = p.parent();
    }
    let Some(material) = bound else {
        return Ok(Glow::NoMaterial);
    };
    let stage = prim.stage();
    let mat = stage.prim(&material).map_err(openusd::Error::from)?;
    let material_name = material.to_string();
    let not = |what: String| Ok(Glow::NotEvaluated(what));
    let mat_type = mat.type_name()?.map(|t| t.as_str().to_string());
    if mat_type.as_deref() != Some("Material") {
        return not(format!(
            "material:binding targets {material_name}, which is not a Material"
        ));
    }
    let surface = mat.attribute("outputs:surface").connections()?;
    let Some(source) = surface.first() else {
        return not(format!(
            "the material {material_name} has no connected outputs:surface"
        ));
    };
    let shader_path = source.prim_path();
    let shader = stage.prim(&shader_path).map_err(openusd::Error::from)?;
    let shader_name = shader_path.to_string();
    match shader
        .type_name()?
        .map(|t| t.as_str().to_string())
        .as_deref()
    {
        Some("Shader") => {}
        Some("NodeGraph") => {
            return not(format!(
                "the surface of {material_name} is routed through the NodeGraph {shader_name}"
            ));
        }
        other => {
            return not(format!(
                "the surface of {material_name} comes from {shader_name} ({}), not a Shader",
                other.unwrap_or("untyped")
            ));
        }
    }
    let id = value_at(&shader.attribute("info:id"), tc)?.and_then(|v| match v {
        sdf::Value::Token(t) => Some(t.as_str().to_string()),
        sdf::Value::String(s) => Some(s),
        _ => None,
    });
    if id.as_deref() != Some("UsdPreviewSurface") {
        return not(format!(
            "the surface shader {shader_name} of {material_name} is {}, not UsdPreviewSurface",
            id.map(|i| format!("{i:?}"))
                .unwrap_or_else(|| "without info:id".into())
        ));
    }
    let emissive = shader.attribute("inputs:emissiveColor");
    if emissive.has_authored_connections()? {
        return not(format!(
            "inputs:emissiveColor of {shader_name} (material {material_name}) is driven by a connection"
        ));
    }
    let authored = value_at(&emissive, tc)?.filter(|v| !is_blocked(v));
    let rgb = match &authored {
        Some(v) => match v.clone().cast::<[f64; 3]>() {
            Ok(rgb) => rgb,
            Err(_) => {
                return not(format!(
                    "inputs:emissiveColor of {shader_name} holds {}, not a color3f",
                    short(v)
                ));
            }
        },
        None => preview_surface::EMISSIVE_COLOR,
    };
    Ok(Glow::Emissive {
        material: material_name,
        shader: shader_name,
        rgb,
        authored: authored.is_some(),
    })
}

/// The mesh light of `p` (a `Mesh` with MeshLightAPI), its warnings (each naming the prim), or
/// why it is refused: bad topology or too many triangles (M1), naming the attribute.
pub(super) fn convert(
    p: &usd::LightPrim,
    arrays: &MeshArrays,
    inputs: LightInputs,
    shaping: Option<Shaping>,
    token: impl Fn(&str) -> std::result::Result<String, String>,
    flag: impl Fn(&str) -> std::result::Result<bool, String>,
    max_triangles: u64,
) -> std::result::Result<(MeshLight, Vec<String>), NotEvaluated> {
    let path = &p.path;
    let refused = |attr: &str, value: String, reason: String| {
        NotEvaluated::Refused(RefusedInput {
            attr: attr.to_string(),
            value,
            reason,
        })
    };
    let mut warnings = Vec::new();
    let orientation = token("orientation")?;
    let left_handed = match orientation.as_str() {
        "rightHanded" => false,
        "leftHanded" => true,
        other => {
            return Err(refused(
                "orientation",
                format!("{other:?}"),
                "not one of rightHanded, leftHanded".into(),
            ));
        }
    };
    let topology = MeshTopology {
        points: &arrays.points,
        face_vertex_counts: &arrays.face_vertex_counts,
        face_vertex_indices: &arrays.face_vertex_indices,
        hole_indices: &arrays.hole_indices,
        left_handed,
    };
    let from_topology = |e: crate::model::TopologyError| refused(e.attr, e.value, e.reason);
    // Counted before anything is allocated per triangle (docs/INPUTS.md "Limits").
    let fan = MeshGeometry::fan_triangles(&topology).map_err(from_topology)?;
    if fan > max_triangles {
        return Err(refused(
            "faceVertexCounts",
            format!("{} faces", arrays.face_vertex_counts.len()),
            format!(
                "{fan} triangles exceed the limit of {max_triangles} per mesh light ({})",
                raise_hint(ENV_MAX_MESH_TRIANGLES)
            ),
        ));
    }
    let world = glam::DMat4::from_cols_array_2d(&p.world);
    let geometry = MeshGeometry::triangulate(&topology, world).map_err(from_topology)?;
    let subdivision_scheme = token("subdivisionScheme")?;
    if cage_only(&subdivision_scheme) {
        warnings.push(format!(
            "{path}: subdivisionScheme {subdivision_scheme:?}: its control cage is evaluated as \
             polygons (no subdivision, DESIGN.md §7 M1)"
        ));
    }
    if !geometry.folded_faces.is_empty() {
        const SHOWN: usize = 8;
        let mut faces: Vec<String> = geometry
            .folded_faces
            .iter()
            .take(SHOWN)
            .map(u32::to_string)
            .collect();
        if geometry.folded_faces.len() > SHOWN {
            faces.push(format!("{} more", geometry.folded_faces.len() - SHOWN));
        }
        warnings.push(format!(
            "{path}: the fan of face {} folds over itself (a non-convex polygon): evaluated as \
             that fan, as Hydra renders it (DESIGN.md §7 M1)",
            faces.join(", ")
        ));
    }
    if geometry.triangles.is_empty() {
        warnings.push(format!(
            "{path}: the mesh has no triangles of non-zero area: it emits nothing"
        ));
    }
    let mode = token("light:materialSyncMode")?;
    let tint = match mode.as_str() {
        "materialGlowTintsLight" => match &arrays.glow {
            Glow::Emissive {
                material,
                shader,
                rgb,
                authored,
            } => {
                let rgb = DVec3::from_array(*rgb);
                if rgb == DVec3::ZERO {
                    warnings.push(format!(
                        "{path}: the bound material {material} does not glow (emissiveColor \
                         (0, 0, 0)): the light is dark (DESIGN.md §7 M2)"
                    ));
                }
                Tint {
                    rgb,
                    source: format!(
                        "emissiveColor of {shader} ({})",
                        if *authored { "authored" } else { "fallback" }
                    ),
                }
            }
            Glow::NoMaterial => {
                warnings.push(format!(
                    "{path}: materialSyncMode materialGlowTintsLight, but no material is bound: \
                     tint (1, 1, 1)"
                ));
                Tint {
                    rgb: DVec3::ONE,
                    source: "no material bound".into(),
                }
            }
            Glow::NotEvaluated(what) => {
                warnings.push(format!(
                    "{path}: not evaluated for the tint: {what}; tint (1, 1, 1)"
                ));
                Tint {
                    rgb: DVec3::ONE,
                    source: format!("not evaluated: {what}"),
                }
            }
        },
        "independent" | "noMaterialResponse" => Tint {
            rgb: DVec3::ONE,
            source: format!("materialSyncMode {mode}"),
        },
        other => {
            return Err(refused(
                "light:materialSyncMode",
                format!("{other:?}"),
                "not one of materialGlowTintsLight, independent, noMaterialResponse".into(),
            ));
        }
    };
    Ok((
        MeshLight {
            path: path.clone(),
            inputs,
            shaping,
            world,
            geometry: std::sync::Arc::new(geometry),
            double_sided: flag("doubleSided")?,
            tint,
            subdivision_scheme,
        },
        warnings,
    ))
}

/// Whether a mesh light's `subdivisionScheme` leaves its control cage to be evaluated as
/// polygons (anything but `none`, DESIGN.md §7 M1).
fn cage_only(scheme: &str) -> bool {
    scheme != "none"
}

/// A mesh light's `lights --json` summary (`StageLight::mesh`).
pub(super) fn summary<S: serde::Serializer>(
    mesh: &Option<MeshLight>,
    s: S,
) -> std::result::Result<S::Ok, S::Error> {
    let Some(m) = mesh else {
        return s.serialize_none();
    };
    let g = &m.geometry;
    serde_json::json!({
        "triangles": g.triangles.len(),
        "area": g.area,
        "holes": g.holes,
        "degenerate_triangles": g.degenerate,
        "folded_faces": g.folded_faces.len(),
        "tint": m.tint.rgb.to_array(),
        "tint_source": m.tint.source,
        "double_sided": m.double_sided,
        "subdivision_scheme": m.subdivision_scheme,
        "subdivision": if cage_only(&m.subdivision_scheme) {
            "not applied: the control cage is evaluated as polygons"
        } else {
            "none"
        },
    })
    .serialize(s)
}
