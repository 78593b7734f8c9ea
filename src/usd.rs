//! Reading lights from USD stages: the only module that imports openusd.
//!
//! It opens `.usda`, `.usdc` and `.usdz` files with full composition (sublayers, references,
//! payloads all loaded, variant selections, inherits, specializes, instancing) and returns plain
//! data: stage metadata, and for every light prim its type, applied schemas, visibility, world
//! matrix and every attribute of [`crate::schema::attrs_for`] resolved at one time. What a light
//! means to luxeval is decided in [`crate::scene`].
//!
//! Value resolution and transforms are openusd's, checked against Pixar's usd-core in
//! `tests/usd_fixtures.rs`, except where openusd 0.8 gives other numbers than usd-core; there
//! this module computes what usd-core does:
//! - a time-sampled `orient` op between samples: usd-core's `GfSlerp` rounds to the
//!   quaternion's scalar type ([`usd_slerp`]);
//! - between a sample and a blocked one: usd-core holds the lower sample ([`held_before_block`]),
//!   for inputs, xformOps and `visibility` alike;
//! - spline-valued attributes, which openusd reads as unauthored, are refused
//!   ([`reject_spline`]).
//!
//! Fallbacks of unauthored attributes come from luxeval's schema table, not from openusd's
//! registry, so there is exactly one table of them.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use openusd::usd::{self as ousd, PrimPredicate, TimeCode};
use openusd::{gf, sdf};
use openusd_schemas::SchemaError;
use openusd_schemas::geom::{Imageable, XformCache, XformOp, XformOpKind, Xformable, XformableExt};

use crate::error::{LuxError, Result};
use crate::scene::{Input, Value};
use crate::schema::{self, Fallback};

/// Prim types that are lights.
pub const LIGHT_TYPES: &[&str] = &[
    "DistantLight",
    "SphereLight",
    "DiskLight",
    "RectLight",
    "CylinderLight",
    "DomeLight",
    "DomeLight_1",
    "PortalLight",
    "GeometryLight",
    "PluginLight",
];

/// API schemas that make a prim of any type a light.
pub const LIGHT_APIS: &[&str] = &["MeshLightAPI", "VolumeLightAPI"];

/// The time attributes are read at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Time {
    /// A numeric time code, interpolated between samples as USD does (linear for floating
    /// types, slerp for quaternions, held for bool, token and asset).
    Code(f64),
    /// USD's `EarliestTime`: every attribute (and xformOp) at its own earliest time sample, or
    /// its default value when it has none.
    Earliest,
}

impl Time {
    fn code(self) -> TimeCode {
        match self {
            Time::Code(t) => TimeCode::new(t),
            Time::Earliest => TimeCode::EARLIEST,
        }
    }
}

/// Stage metadata.
#[derive(Clone, Debug, PartialEq)]
pub struct StageInfo {
    /// `Y` when unauthored, as USD does.
    pub up_axis: String,
    /// 0.01 when unauthored, as USD does.
    pub meters_per_unit: f64,
    /// The root layer's `startTimeCode`, when authored.
    pub start_time_code: Option<f64>,
    /// The root layer's `endTimeCode`, when authored.
    pub end_time_code: Option<f64>,
}

/// One light prim resolved at one time.
#[derive(Clone, Debug, PartialEq)]
pub struct LightPrim {
    pub path: String,
    /// The prim's type name (`Mesh`, `Volume`, ... for MeshLightAPI / VolumeLightAPI prims).
    pub usd_type: String,
    /// The composed API schemas, as usd-core's `GetAppliedSchemas()` lists them (built-ins
    /// included, e.g. `LightAPI`), followed by authored names the schema registry does not know
    /// (e.g. a renderer's own `HoudiniViewportLightAPI`), which usd-core drops.
    pub applied_schemas: Vec<String>,
    /// `MeshLightAPI` or `VolumeLightAPI` when that is what makes the prim a light.
    pub light_api: Option<String>,
    /// False when `visibility` is `invisible` on the prim or an imageable ancestor.
    pub visible: bool,
    /// Local-to-world, USD row-vector convention; every entry NaN when it cannot be computed.
    pub world: [[f64; 4]; 4],
    /// Why `world` cannot be computed (e.g. `!invert!` of a singular `transform` op), naming
    /// the prim; the light is then listed but not evaluated.
    pub transform_error: Option<String>,
    /// Every attribute of `schema::attrs_for(usd_type, applied_schemas)`, in that order.
    pub inputs: Vec<Input>,
}

/// What does not change with time: found once at open.
struct LightSite {
    prim: ousd::Prim,
    path: String,
    usd_type: String,
    applied_schemas: Vec<String>,
    light_api: Option<String>,
    attrs: Vec<schema::SchemaAttr>,
    /// The prim or an ancestor has an xformOp that openusd 0.8 evaluates differently from
    /// usd-core between samples (see [`needs_own_xform`]); its world matrix is composed here.
    own_xform_chain: bool,
}

/// An open stage and its light prims.
pub struct UsdStage {
    file: PathBuf,
    info: StageInfo,
    lights: Vec<LightSite>,
    // Keeps the composed stage alive for the prim handles above.
    _stage: ousd::Stage,
}

impl UsdStage {
    /// Opens `path` with every payload loaded. A missing or unreadable file is
    /// [`LuxError::Io`]; a malformed one [`LuxError::Format`] (with the line for `.usda`); a
    /// sublayer, reference or payload that cannot be found or read is an error naming that layer.
    pub fn open(path: &Path) -> Result<UsdStage> {
        // The filesystem's own error (not found, permission denied) is the clearest message.
        let io = |source| LuxError::Io {
            path: path.to_path_buf(),
            source,
        };
        let meta = std::fs::metadata(path).map_err(io)?;
        if meta.is_dir() {
            return Err(io(std::io::Error::new(
                std::io::ErrorKind::IsADirectory,
                "is a directory, not a USD file",
            )));
        }
        std::fs::File::open(path).map_err(io)?;
        let name = path.to_str().ok_or_else(|| LuxError::Format {
            path: path.to_path_buf(),
            line: None,
            reason: "the path is not valid UTF-8, which openusd requires".into(),
        })?;
        let stage = ousd::Stage::builder()
            .schema_registry(openusd_schemas::schema_registry())
            .load(ousd::InitialLoadSet::LoadAll)
            .open(name)
            .map_err(|e| open_error(path, e))?;
        let e = |e: openusd::Error| stage_error(path, e);

        let up_axis = stage
            .stage_metadata("upAxis")
            .map_err(e)?
            .and_then(|v| v.cast::<String>().ok())
            .unwrap_or_else(|| "Y".to_string());
        let meters_per_unit = stage
            .stage_metadata("metersPerUnit")
            .map_err(e)?
            .and_then(|v| v.cast::<f64>().ok())
            .unwrap_or(0.01);
        let (start_time_code, end_time_code) = {
            let root = stage.root_layer();
            (
                root.has_start_time_code().then(|| root.start_time_code()),
                root.has_end_time_code().then(|| root.end_time_code()),
            )
        };
        let info = StageInfo {
            up_axis,
            meters_per_unit,
            start_time_code,
            end_time_code,
        };

        // Default predicate (active, loaded, defined, non-abstract) as usd-core's Traverse(),
        // descending into instances: a light inside an instanced asset lights the scene too.
        let mut paths = Vec::new();
        stage
            .traverse(PrimPredicate::DEFAULT_PROXIES, |p| paths.push(p.clone()))
            .map_err(e)?;
        check_composition(path, &stage)?;

        let mut lights = Vec::new();
        let mut own_xform: HashMap<String, bool> = HashMap::new();
        for p in paths {
            let prim = stage.prim(&p).map_err(|err| e(err.into()))?;
            let usd_type = prim
                .type_name()
                .map_err(e)?
                .map(|t| t.as_str().to_string())
                .unwrap_or_default();
            let applied_schemas: Vec<String> = prim
                .api_schemas()
                .map_err(e)?
                .iter()
                .map(|t| t.as_str().to_string())
                .collect();
            let light_api = if LIGHT_TYPES.contains(&usd_type.as_str()) {
                None
            } else {
                match applied_schemas
                    .iter()
                    .find(|s| LIGHT_APIS.contains(&s.as_str()))
                {
                    Some(api) => Some(api.clone()),
                    None => continue,
                }
            };
            let applied: Vec<&str> = applied_schemas.iter().map(String::as_str).collect();
            let attrs = schema::attrs_for(&usd_type, &applied);
            for a in &attrs {
                reject_spline(&p, &prim.attribute(a.name))?;
            }
            let mut own_xform_chain = false;
            let mut cur = Some(prim.clone());
            while let Some(q) = cur.filter(|q| !q.path().is_abs_root()) {
                let key = q.path().to_string();
                let own = match own_xform.get(&key) {
                    Some(own) => *own,
                    None => {
                        if let Some(x) = Xformable::from_prim(q.clone()).map_err(e)? {
                            let (ops, _) =
                                x.ordered_xform_ops().map_err(|err| xform_error(&p, err))?;
                            for op in &ops {
                                reject_spline(&p, op.attribute())?;
                            }
                        }
                        let own = needs_own_xform(&q).map_err(|err| xform_error(&p, err))?;
                        own_xform.insert(key, own);
                        own
                    }
                };
                own_xform_chain |= own;
                cur = q.parent();
            }
            lights.push(LightSite {
                path: p.to_string(),
                prim,
                usd_type,
                applied_schemas,
                light_api,
                attrs,
                own_xform_chain,
            });
        }
        // Reading attributes can compose more (e.g. the prims an inherit arc names).
        check_composition(path, &stage)?;
        Ok(UsdStage {
            file: path.to_path_buf(),
            info,
            lights,
            _stage: stage,
        })
    }

    pub fn info(&self) -> &StageInfo {
        &self.info
    }

    /// The file the stage was opened from.
    pub fn file(&self) -> &Path {
        &self.file
    }

    /// Every light prim, in traversal order, resolved at `time`.
    pub fn lights_at(&self, time: Time) -> Result<Vec<LightPrim>> {
        let tc = time.code();
        let e = |err: openusd::Error| stage_error(&self.file, err);
        let mut cache = XformCache::new(tc);
        let mut out = Vec::with_capacity(self.lights.len());
        for site in &self.lights {
            let visible = visible_at(&site.prim, tc).map_err(e)?;
            let world = match site.own_xform_chain {
                false => cache.local_to_world_transform(&site.prim),
                true => world_as_usd_core(&mut cache, &site.prim, tc),
            };
            // One broken transform must not hide the stage's other lights: it is reported
            // with the light instead of failing the load.
            let (world, transform_error) = match world {
                Ok(m) => (m.into(), None),
                Err(err) => (
                    [[f64::NAN; 4]; 4],
                    Some(format!(
                        "{}: world transform cannot be computed: {err}",
                        site.path
                    )),
                ),
            };
            let mut inputs = Vec::with_capacity(site.attrs.len());
            for a in &site.attrs {
                inputs.push(self.input(site, a, tc)?);
            }
            out.push(LightPrim {
                path: site.path.clone(),
                usd_type: site.usd_type.clone(),
                applied_schemas: site.applied_schemas.clone(),
                light_api: site.light_api.clone(),
                visible,
                world,
                transform_error,
                inputs,
            });
        }
        Ok(out)
    }

    /// One attribute at `tc`: its authored value converted to the kind of its table fallback,
    /// or the table fallback when nothing is authored.
    fn input(&self, site: &LightSite, a: &schema::SchemaAttr, tc: TimeCode) -> Result<Input> {
        let e = |err: openusd::Error| stage_error(&self.file, err);
        let attr = site.prim.attribute(a.name);
        let authored = attr.has_authored_value().map_err(e)?;
        let value = if authored {
            match value_at(&attr, tc).map_err(e)? {
                Some(v) => convert(&site.path, a, v)?,
                // A blocked value at this time: usd-core reports no value at all; luxeval has
                // to evaluate something, and a block means "no opinion", so the fallback.
                None => fallback_value(a.fallback),
            }
        } else {
            fallback_value(a.fallback)
        };
        Ok(Input {
            name: a.name.to_string(),
            value,
            authored,
        })
    }
}

/// openusd 0.8 parses a spline-valued attribute (`float x.spline = {...}`, USD 25.05+) but
/// resolves it as unauthored, so its value would silently be the fallback; usd-core evaluates
/// the spline. Refuse it, naming the light and attribute. (In a usdc file openusd cannot even
/// decode the spline field, which is reported the same way.)
fn reject_spline(light: &sdf::Path, attr: &ousd::Attribute) -> Result<()> {
    let spline = match attr.has_authored_metadata("spline") {
        Ok(spline) => spline,
        Err(err) => {
            // Only a spline field fails to decode this way; anything else is a real error.
            let text = err.to_string();
            if !format!("{err:?}").contains("\"spline\"") {
                return Err(LuxError::InvalidAttribute {
                    light: light.to_string(),
                    attr: attr.name().to_string(),
                    value: "?".into(),
                    reason: format!("cannot be read: {text}"),
                });
            }
            true
        }
    };
    if spline {
        return Err(LuxError::attr(
            &light.to_string(),
            attr.name(),
            "(spline)",
            "spline-valued attributes are not supported (openusd 0.8 does not evaluate them); \
             bake the spline to timeSamples",
        ));
    }
    Ok(())
}

/// `attr`'s value at `tc` as usd-core resolves it: openusd's, except where openusd has none
/// and usd-core holds the sample before a block (see [`held_before_block`]). `None` where
/// usd-core has no value either (a blocked value).
fn value_at(attr: &ousd::Attribute, tc: TimeCode) -> openusd::Result<Option<sdf::Value>> {
    if let Some(v) = attr.get_at::<sdf::Value>(tc)? {
        return Ok(Some(v));
    }
    let Some(samples) = attr.time_samples()? else {
        return Ok(None);
    };
    Ok(held_before_block(&samples, tc).map(|i| samples[i].1.clone()))
}

fn is_blocked(v: &sdf::Value) -> bool {
    matches!(v, sdf::Value::ValueBlock | sdf::Value::None)
}

/// The index of the sample usd-core holds at `tc` where openusd 0.8 has no value: `tc` lies
/// strictly between two samples, the upper a block and the lower not. usd-core holds the lower
/// sample up to the block; openusd treats any blocked bracket as no value.
fn held_before_block(samples: &sdf::TimeSampleMap, tc: TimeCode) -> Option<usize> {
    if tc.is_earliest_time() {
        return None;
    }
    let t = tc.value();
    let hi = samples.iter().position(|(st, _)| *st > t)?;
    let lo = hi.checked_sub(1)?;
    (samples[lo].0 < t && !is_blocked(&samples[lo].1) && is_blocked(&samples[hi].1)).then_some(lo)
}

/// `visibility` as usd-core's `UsdGeomImageable::ComputeVisibility` resolves it: invisible when
/// the prim or any imageable ancestor reads `invisible` at `tc` (values read with
/// [`value_at`], so a sample held before a block counts as usd-core counts it).
fn visible_at(prim: &ousd::Prim, tc: TimeCode) -> openusd::Result<bool> {
    let mut cur = Some(prim.clone());
    while let Some(p) = cur.filter(|p| !p.path().is_abs_root()) {
        // An opinion on a prim that is not imageable (an untyped prim) is ignored, as in C++.
        if Imageable::from_prim(p.clone())?.is_some()
            && let Some(v) = value_at(&p.attribute("visibility"), tc)?
            && v.as_str() == Some("invisible")
        {
            return Ok(false);
        }
        cur = p.parent();
    }
    Ok(true)
}

/// Whether `prim` has an xformOp openusd 0.8 evaluates differently from usd-core between
/// samples: a time-sampled orient (see [`usd_slerp`]), or any op with a blocked sample (see
/// [`held_before_block`]).
fn needs_own_xform(prim: &ousd::Prim) -> std::result::Result<bool, SchemaError> {
    let Some(x) = Xformable::from_prim(prim.clone())? else {
        return Ok(false);
    };
    let (ops, _) = x.ordered_xform_ops()?;
    for op in &ops {
        let Some(samples) = op.attribute().time_samples()? else {
            continue;
        };
        let orient = op.kind() == Some(XformOpKind::Orient) && samples.len() > 1;
        if orient || samples.iter().any(|(_, v)| is_blocked(v)) {
            return Ok(true);
        }
    }
    Ok(false)
}

fn xform_error(path: &sdf::Path, err: impl std::fmt::Display) -> LuxError {
    LuxError::InvalidTransform {
        light: path.to_string(),
        reason: format!("cannot be read: {err}"),
    }
}

/// The local-to-world matrix of `prim` as usd-core's XformCache computes it, for a prim whose
/// chain holds an op of [`needs_own_xform`]: the local transforms of the chain composed as
/// openusd's XformCache does (row-vector, `local * parent`, stopping at `!resetXformStack!`),
/// with the prims that own such an op evaluated by [`local_as_usd_core`].
fn world_as_usd_core(
    cache: &mut XformCache,
    prim: &ousd::Prim,
    tc: TimeCode,
) -> std::result::Result<gf::Matrix4d, SchemaError> {
    let mut world = gf::Matrix4d::IDENTITY;
    let mut cur = Some(prim.clone());
    while let Some(p) = cur.filter(|p| !p.path().is_abs_root()) {
        let (local, resets) = match needs_own_xform(&p)? {
            true => local_as_usd_core(&p, tc)?,
            false => cache.local_transformation(&p)?,
        };
        world = world * local;
        if resets {
            break;
        }
        cur = p.parent();
    }
    Ok(world)
}

/// `prim`'s local transform at `tc`, op by op as openusd's XformQuery composes it (an op beside
/// its own inverse is skipped with it), except that an orient op between two time samples is
/// interpolated with [`usd_slerp`], and an op held before a blocked sample is evaluated at the
/// held sample.
fn local_as_usd_core(
    prim: &ousd::Prim,
    tc: TimeCode,
) -> std::result::Result<(gf::Matrix4d, bool), SchemaError> {
    let Some(x) = Xformable::from_prim(prim.clone())? else {
        return Ok((gf::Matrix4d::IDENTITY, false));
    };
    let (ops, resets) = x.ordered_xform_ops()?;
    let mut m = gf::Matrix4d::IDENTITY;
    let mut rev = ops.iter().rev().peekable();
    while let Some(op) = rev.next() {
        if rev.peek().is_some_and(|next| {
            next.is_inverse_op() != op.is_inverse_op() && next.attribute() == op.attribute()
        }) {
            rev.next();
            continue;
        }
        let op_matrix = match interpolated_orient(op, tc)? {
            Some(q) => {
                let rotation = gf::Rotation::from_quat(gf::Quatd {
                    w: q[0],
                    x: q[1],
                    y: q[2],
                    z: q[3],
                });
                let rotation = match op.is_inverse_op() {
                    true => rotation.inverse(),
                    false => rotation,
                };
                gf::Matrix4d::from_quat(rotation.quat())
            }
            None => match op.attribute().time_samples()? {
                Some(samples) => match held_before_block(&samples, tc) {
                    Some(i) => op.op_transform(TimeCode::new(samples[i].0))?,
                    None => op.op_transform(tc)?,
                },
                None => op.op_transform(tc)?,
            },
        };
        m = m * op_matrix;
    }
    Ok((m, resets))
}

/// The value usd-core gives an orient op at `tc` when `tc` lies strictly between two of its
/// time samples, as `[w, x, y, z]`; `None` wherever no interpolation happens (on a sample,
/// outside the samples, EarliestTime, value clips, a blocked sample) and openusd's value is
/// usd-core's.
fn interpolated_orient(
    op: &XformOp,
    tc: TimeCode,
) -> std::result::Result<Option<[f64; 4]>, SchemaError> {
    if op.kind() != Some(XformOpKind::Orient) || tc.is_earliest_time() {
        return Ok(None);
    }
    let t = tc.value();
    let Some(samples) = op.attribute().time_samples()? else {
        return Ok(None);
    };
    let Some(hi) = samples.iter().position(|(st, _)| *st > t) else {
        return Ok(None);
    };
    if hi == 0 || samples[hi - 1].0 == t {
        return Ok(None);
    }
    let (t0, v0) = &samples[hi - 1];
    let (t1, v1) = &samples[hi];
    // USD's Usd_LinearInterpolator: the parametric time in double.
    let alpha = (t - t0) / (t1 - t0);
    Ok(match (v0, v1) {
        (sdf::Value::Quatd(a), sdf::Value::Quatd(b)) => Some(usd_slerp(
            alpha,
            [a.w, a.x, a.y, a.z],
            [b.w, b.x, b.y, b.z],
            Precision::DOUBLE,
        )),
        (sdf::Value::Quatf(a), sdf::Value::Quatf(b)) => Some(usd_slerp(
            alpha,
            [a.w, a.x, a.y, a.z].map(f64::from),
            [b.w, b.x, b.y, b.z].map(f64::from),
            Precision::FLOAT,
        )),
        (sdf::Value::Quath(a), sdf::Value::Quath(b)) => Some(usd_slerp(
            alpha,
            [a.w, a.x, a.y, a.z].map(|h| h.to_f64()),
            [b.w, b.x, b.y, b.z].map(|h| h.to_f64()),
            Precision::HALF,
        )),
        _ => None,
    })
}

/// How a quaternion's scalar type rounds: `store` is the scalar type itself, `compute` the type
/// C++ does its arithmetic in (GfHalf arithmetic happens in float).
#[derive(Clone, Copy)]
struct Precision {
    store: fn(f64) -> f64,
    compute: fn(f64) -> f64,
}

impl Precision {
    const DOUBLE: Precision = Precision {
        store: |x| x,
        compute: |x| x,
    };
    const FLOAT: Precision = Precision {
        store: |x| x as f32 as f64,
        compute: |x| x as f32 as f64,
    };
    // C++ converts double to half through float.
    const HALF: Precision = Precision {
        store: |x| gf::f16::from_f32(x as f32).to_f64(),
        compute: |x| x as f32 as f64,
    };
}

/// usd-core's `GfSlerp(alpha, q0, q1)` for `GfQuatd`/`GfQuatf`/`GfQuath`, operation by operation
/// (pxr/base/gf/quat.template.cpp): the cosine in double from the scalar-typed dot product, the
/// angle and its sine rounded to the scalar type, the weights in double but applied as scalars.
/// openusd 0.8 slerps in double throughout (and switches to a normalised lerp at cos > 0.9995),
/// so a `quatf` orient between samples came out a few float ulps away from usd-core.
fn usd_slerp(alpha: f64, q0: [f64; 4], q1: [f64; 4], p: Precision) -> [f64; 4] {
    let (s, c) = (p.store, p.compute);
    // GfDot of the imaginary parts returns the scalar type; + real * real in the compute type.
    let dot_i = s(c(c(c(q0[1] * q1[1]) + c(q0[2] * q1[2])) + c(q0[3] * q1[3])));
    let mut cos_theta = c(dot_i + c(q0[0] * q1[0]));
    let mut flip = false;
    if cos_theta < 0.0 {
        cos_theta = -cos_theta;
        flip = true;
    }
    let (scale0, mut scale1) = if 1.0 - cos_theta > 0.00001 {
        let theta = s(cos_theta.acos());
        let sin_theta = s(theta.sin());
        (
            ((1.0 - alpha) * theta).sin() / sin_theta,
            (alpha * theta).sin() / sin_theta,
        )
    } else {
        (1.0 - alpha, alpha)
    };
    if flip {
        scale1 = -scale1;
    }
    // `scale * q` converts the double scale to the scalar type first.
    let (w0, w1) = (s(scale0), s(scale1));
    std::array::from_fn(|i| s(c(s(c(q0[i] * w0)) + s(c(q1[i] * w1)))))
}

/// The scene value of a schema fallback.
pub fn fallback_value(f: Fallback) -> Value {
    match f {
        Fallback::Float(v) => Value::Float(v),
        Fallback::Bool(v) => Value::Bool(v),
        Fallback::Color(v) => Value::Color(v),
        Fallback::Token(v) => Value::Token(v.to_string()),
        Fallback::Asset => Value::Asset {
            authored: String::new(),
            resolved: None,
        },
    }
}

/// Converts an authored value to the kind the schema table gives the attribute. USD files do
/// author other precisions than the schema's (a `double` intensity, a `color3d`), which
/// usd-core reads as they are; numbers are widened to f64 exactly.
fn convert(light: &str, a: &schema::SchemaAttr, v: sdf::Value) -> Result<Value> {
    let shown = format!("{v:?}");
    let bad = |want: &str| {
        LuxError::attr(
            light,
            a.name,
            &shown,
            format!(
                "expected a {want} value, as the {} schema declares",
                a.schema
            ),
        )
    };
    Ok(match a.fallback {
        Fallback::Float(_) => Value::Float(match v {
            sdf::Value::Bool(_) => return Err(bad("floating-point")),
            other => other.cast::<f64>().map_err(|_| bad("floating-point"))?,
        }),
        Fallback::Bool(_) => Value::Bool(match v {
            sdf::Value::Bool(b) => b,
            // usda allows 0/1 for bools; openusd coerces them already, this is a safety net.
            other => match other.cast::<i64>() {
                Ok(0) => false,
                Ok(1) => true,
                _ => return Err(bad("bool")),
            },
        }),
        Fallback::Color(_) => Value::Color(v.cast::<[f64; 3]>().map_err(|_| bad("color3f"))?),
        Fallback::Token(_) => Value::Token(match v {
            sdf::Value::Token(t) => t.as_str().to_string(),
            sdf::Value::String(s) => s,
            _ => return Err(bad("token")),
        }),
        Fallback::Asset => match v {
            sdf::Value::AssetPath(p) => Value::Asset {
                authored: p.as_str().to_string(),
                resolved: p.resolved_path().map(str::to_string),
            },
            _ => return Err(bad("asset")),
        },
    })
}

/// Layer-level composition failures are errors: a light rig whose reference did not load would
/// otherwise be evaluated without its lights, silently. Other diagnostics (an arc to a prim the
/// layer lacks, a variant selection naming no variant) compose as usd-core does, with a warning.
fn check_composition(file: &Path, stage: &ousd::Stage) -> Result<()> {
    use openusd::pcp::CompositionDiagnostic as D;
    for d in stage.composition_errors() {
        match d {
            D::UnresolvedLayer {
                asset_path,
                arc,
                introduced_by,
                site_path,
            } => {
                return Err(LuxError::Io {
                    path: anchored(&introduced_by, &asset_path),
                    source: std::io::Error::new(
                        std::io::ErrorKind::NotFound,
                        format!(
                            "cannot open the {arc:?} layer @{asset_path}@ authored on {site_path} in {introduced_by}"
                        ),
                    ),
                });
            }
            D::UnresolvedSublayer {
                asset_path,
                introduced_by,
            } => {
                return Err(LuxError::Io {
                    path: anchored(&introduced_by, &asset_path),
                    source: std::io::Error::new(
                        std::io::ErrorKind::NotFound,
                        format!("cannot open the sublayer @{asset_path}@ of {introduced_by}"),
                    ),
                });
            }
            D::MalformedLayer {
                asset_path,
                arc,
                introduced_by,
                site_path,
                reason,
            } => {
                let (line, reason) = located(&reason);
                return Err(LuxError::Format {
                    path: anchored(&introduced_by, &asset_path),
                    line,
                    reason: format!(
                        "{reason} (the {arc:?} layer authored on {site_path} in {introduced_by})"
                    ),
                });
            }
            D::MalformedSublayer {
                asset_path,
                introduced_by,
                reason,
            } => {
                let (line, reason) = located(&reason);
                return Err(LuxError::Format {
                    path: anchored(&introduced_by, &asset_path),
                    line,
                    reason: format!("{reason} (a sublayer of {introduced_by})"),
                });
            }
            other => log::warn!("{}: {other}", file.display()),
        }
    }
    Ok(())
}

/// `asset` as a path: itself when absolute (openusd reports some resolved), else anchored to
/// the directory of the filesystem layer `layer` (inside a package, the authored path as is).
fn anchored(layer: &str, asset: &str) -> PathBuf {
    let a = Path::new(asset);
    if a.is_absolute() || layer.contains('[') {
        return a.to_path_buf();
    }
    match Path::new(layer).parent() {
        Some(dir) => dir.join(a),
        None => a.to_path_buf(),
    }
}

/// Splits openusd's rendered diagnostics (`error: why\n --> file:line:col\n | snippet`) into the
/// line and a one-line reason.
fn located(rendered: &str) -> (Option<usize>, String) {
    let mut lines = rendered.lines();
    let first = lines.next().unwrap_or_default();
    let reason = first.strip_prefix("error: ").unwrap_or(first).to_string();
    let line = rendered.lines().find_map(|l| {
        let loc = l.trim_start().strip_prefix("--> ")?;
        // `file:line:col`; the file may itself contain colons, so count from the right.
        let mut parts = loc.rsplitn(3, ':');
        let _col = parts.next()?;
        parts.next()?.parse::<usize>().ok()
    });
    (line, reason)
}

/// Maps a failure to open the root layer.
fn open_error(path: &Path, e: openusd::Error) -> LuxError {
    use openusd::Error as E;
    match e {
        E::Io(source) => LuxError::Io {
            path: path.to_path_buf(),
            source,
        },
        E::Format(sdf::FormatError::Io(source)) => LuxError::Io {
            path: path.to_path_buf(),
            source,
        },
        E::Parse(pe) => LuxError::Format {
            path: path.to_path_buf(),
            line: Some(pe.line()),
            reason: located(&pe.to_string()).1,
        },
        E::Format(sdf::FormatError::Decode(inner)) => {
            match inner.downcast_ref::<openusd::usda::ParseError>() {
                Some(pe) => LuxError::Format {
                    path: path.to_path_buf(),
                    line: Some(pe.line()),
                    reason: located(&pe.to_string()).1,
                },
                None => LuxError::Format {
                    path: path.to_path_buf(),
                    line: None,
                    reason: inner.to_string(),
                },
            }
        }
        E::UnresolvedAsset(_) => LuxError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::new(std::io::ErrorKind::NotFound, "cannot resolve the file"),
        },
        E::UnsupportedFormat(_) => LuxError::Format {
            path: path.to_path_buf(),
            line: None,
            reason: "not a USD file (expected .usda, .usdc or .usdz)".into(),
        },
        other => stage_error(path, other),
    }
}

/// Any other openusd failure while reading the stage: the file's content is what is wrong.
fn stage_error(path: &Path, e: openusd::Error) -> LuxError {
    let rendered = e.to_string();
    let (line, reason) = located(&rendered);
    LuxError::Format {
        path: path.to_path_buf(),
        line,
        reason,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn located_reads_line_and_reason() {
        let (line, reason) = located(
            "error: Expected a number\n --> /a/b:c.usda:5:30\n  |\n5 |  x = = 3\n  |      ^",
        );
        assert_eq!(line, Some(5));
        assert_eq!(reason, "Expected a number");
        assert_eq!(located("plain failure"), (None, "plain failure".into()));
    }

    /// `GfSlerp` results printed by usd-core 26.11 (`Gf.Slerp(alpha, Gf.Quat?(..), ..)`), bit for
    /// bit: the float and half results depend on where C++ rounds to the scalar type.
    #[test]
    fn usd_slerp_matches_gf_slerp() {
        // (precision, alpha, q0, q1, usd-core result), quaternions as [w, x, y, z].
        type Case = (Precision, f64, [f64; 4], [f64; 4], [f64; 4]);
        let cases: &[Case] = &[
            (
                Precision::FLOAT,
                0.125,
                [1.0, 0.0, 0.0, 0.0],
                [0.0, 0.0, 1.0, 0.0],
                [0.9807853102684021, 0.0, 0.19509032368659973, 0.0],
            ),
            (
                Precision::FLOAT,
                0.3,
                [0.9238795042037964, 0.0, 0.3826833963394165, 0.0],
                [0.5; 4],
                [
                    0.8585266470909119,
                    0.16828618943691254,
                    0.454193115234375,
                    0.16828618943691254,
                ],
            ),
            // Opposite hemispheres: the second quaternion is flipped.
            (
                Precision::FLOAT,
                0.6,
                [0.5; 4],
                [-0.5, -0.5, -0.5, -0.4999000132083893],
                [
                    0.5000060200691223,
                    0.5000060200691223,
                    0.5000060200691223,
                    0.4999459981918335,
                ],
            ),
            (
                Precision::HALF,
                0.125,
                [1.0, 0.0, 0.0, 0.0],
                [0.0, 0.0, 1.0, 0.0],
                [0.98046875, 0.0, 0.195068359375, 0.0],
            ),
            (
                Precision::HALF,
                0.3,
                [0.923828125, 0.0, 0.382568359375, 0.0],
                [0.5; 4],
                [0.8583984375, 0.168212890625, 0.4541015625, 0.168212890625],
            ),
            (
                Precision::DOUBLE,
                0.125,
                [1.0, 0.0, 0.0, 0.0],
                [0.0, 0.0, 1.0, 0.0],
                [0.9807852804032304, 0.0, 0.19509032201612825, 0.0],
            ),
            (
                Precision::DOUBLE,
                0.3,
                [0.9238795, 0.0, 0.3826834, 0.0],
                [0.5; 4],
                [
                    0.8585266761934467,
                    0.1682861908577956,
                    0.45419314706355307,
                    0.1682861908577956,
                ],
            ),
        ];
        for (i, (p, alpha, q0, q1, want)) in cases.iter().enumerate() {
            let got = usd_slerp(*alpha, *q0, *q1, *p);
            for k in 0..4 {
                assert!(
                    (got[k] - want[k]).abs() <= 1e-15,
                    "case {i}: {got:?} vs usd-core {want:?}"
                );
            }
        }
    }

    #[test]
    fn anchoring() {
        assert_eq!(
            anchored("/a/b/root.usda", "sub/x.usda"),
            PathBuf::from("/a/b/sub/x.usda")
        );
        assert_eq!(
            anchored("/a/root.usda", "/abs.usda"),
            PathBuf::from("/abs.usda")
        );
        assert_eq!(
            anchored("/a/p.usdz[root.usda]", "x.usda"),
            PathBuf::from("x.usda")
        );
    }
}
