//! Opening a stage with openusd and reading its light prims at one time, as plain data.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::rc::Rc;

use openusd::sdf;
use openusd::usd::{self as ousd, PrimPredicate, TimeCode};
use openusd_schemas::geom::{Xformable, XformableExt};

use super::arcs::preflight;
use super::diagnostics::{check_composition, open_error, stage_error};
use super::mesh::{MeshArrays, read_arrays};
use super::progress::{LoadProgress, Reporter, Stopped};
use super::resolver::LimitedResolver;
use super::unapplied::{self, LightExtras, LightList, ListSite};
use super::values::{authors, convert, reject_spline, value_at, visible_at};
use super::xform::{WorldCache, ops_need_own_xform, world_as_usd_core, xform_error};
use crate::error::{LuxError, Result};
use crate::limits::{ENV_MAX_FILE_BYTES, Limits, raise_hint};
use crate::model::schema;
use crate::model::{Input, Value};

/// The error of a read the caller gave up on ([`Reporter`]).
pub(super) fn cancelled(path: &Path) -> LuxError {
    LuxError::Cancelled {
        path: path.to_path_buf(),
    }
}

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
pub(crate) enum Time {
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
pub(crate) struct LightPrim {
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
    /// Authored inputs of another light schema that this light's schema does not have (e.g.
    /// `inputs:texture:file` on a SphereLight): not read, and said so.
    pub stray_inputs: Vec<String>,
    /// Filters, link collections, shaping inputs without ShapingAPI: read, not applied, said so.
    pub extras: LightExtras,
    /// A `Mesh` with MeshLightAPI: its arrays and material glow at the time (DESIGN.md §7 M1).
    pub mesh: Option<MeshArrays>,
    /// A dome's `portals` relationship, its targets as composed (DESIGN.md §8 P1); empty for
    /// other lights.
    pub portals: Vec<String>,
}

/// What does not change with time: found once at open.
struct LightSite {
    prim: ousd::Prim,
    path: String,
    usd_type: String,
    applied_schemas: Vec<String>,
    light_api: Option<String>,
    /// Shared by the lights of one type and set of applied schemas.
    attrs: Rc<[schema::SchemaAttr]>,
    /// Per attribute of `attrs`: whether a layer authors it (the prim's authored property
    /// names hold it). One that none does has no value and no spline, and is read as its
    /// fallback without asking openusd.
    has_spec: Vec<bool>,
    /// See [`LightPrim::stray_inputs`].
    stray_inputs: Vec<String>,
    /// See [`LightPrim::extras`].
    extras: LightExtras,
    /// A `Mesh` with MeshLightAPI: its arrays are read at each time.
    mesh_light: bool,
    /// See [`LightPrim::portals`]; relationships do not vary with time.
    portals: Vec<String>,
    /// Whether the prim's authored property names hold `visibility` (when they do not, its
    /// own visibility is not asked about: see [`visible_at`]).
    authors_visibility: bool,
    /// The prim or an ancestor has an xformOp that openusd 0.8 evaluates differently from
    /// usd-core between samples (see [`super::xform::needs_own_xform`]); its world matrix is
    /// composed here.
    own_xform_chain: bool,
}

/// An open stage and its light prims.
pub struct UsdStage {
    file: PathBuf,
    /// Every file read to compose it (layers, the packages holding them), the root first.
    files: Vec<PathBuf>,
    info: StageInfo,
    lights: Vec<LightSite>,
    /// What was read differently from how it was written, or left out (see
    /// [`UsdStage::warnings`]).
    warnings: Vec<String>,
    /// The prims that author a `lightList`, in traversal order.
    light_lists: Vec<ListSite>,
    /// The limits in force when the stage was opened (a mesh light's triangles are counted at
    /// each read).
    limits: Limits,
    // Keeps the composed stage alive for the prim handles above.
    _stage: ousd::Stage,
}

impl UsdStage {
    /// Opens `path` with every payload loaded. A missing or unreadable file is
    /// [`LuxError::Io`]; a malformed one [`LuxError::Format`] (with the line for `.usda`), also
    /// when it is a sublayer, reference or payload of the stage. A sublayer, reference or payload
    /// that cannot be found, or is in a format luxeval does not read, is left out with a
    /// warning ([`UsdStage::warnings`]), as usd-core leaves it out.
    pub fn open(path: &Path) -> Result<UsdStage> {
        Self::open_reporting(path, &mut Reporter::silent())
    }

    /// [`UsdStage::open`], reporting each step to `report` and stopping when it says so
    /// ([`super::scene::Stage::load_with_progress`]). openusd's traversal cannot be interrupted: a stop
    /// asked for while the stage is composed takes effect once it is.
    pub(crate) fn open_reporting(path: &Path, report: &mut Reporter) -> Result<UsdStage> {
        let go = |r: std::result::Result<(), Stopped>| r.map_err(|Stopped| cancelled(path));
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
        let limits = Limits::from_env()?;
        // Every layer is read whole: what is not a regular file (an endless device) or is
        // larger than the limit is refused before openusd reads it.
        if !meta.is_file() {
            return Err(io(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "is not a regular file (a USD layer is read whole)",
            )));
        }
        if meta.len() > limits.max_file_bytes {
            return Err(LuxError::Format {
                path: path.to_path_buf(),
                line: None,
                reason: format!(
                    "{} bytes exceed the limit of {} bytes ({})",
                    meta.len(),
                    limits.max_file_bytes,
                    raise_hint(ENV_MAX_FILE_BYTES)
                ),
            });
        }
        let name = path.to_str().ok_or_else(|| LuxError::Format {
            path: path.to_path_buf(),
            line: None,
            reason: "the path is not valid UTF-8, which openusd requires".into(),
        })?;
        let resolver = LimitedResolver::new(&limits);
        go(report.report(LoadProgress::Opening))?;
        // Opening reads the root layer stack and composes nothing; the checks of `preflight`
        // run before anything is composed, on the layers the stage has read.
        let stage = ousd::Stage::builder()
            .registry(openusd::sdf::LayerRegistry::new(Box::new(resolver.clone())))
            .schema_registry(openusd_schemas::schema_registry())
            .load(ousd::InitialLoadSet::LoadAll)
            .open(name)
            .map_err(|e| open_error(path, e))?;
        go(report.report(LoadProgress::Checking))?;
        preflight(path, &resolver, &limits, &stage)?;
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
        // The query time defaults to startTimeCode: a NaN there would be used silently.
        for (name, t) in [
            ("startTimeCode", start_time_code),
            ("endTimeCode", end_time_code),
        ] {
            if let Some(t) = t.filter(|t| !t.is_finite()) {
                return Err(LuxError::Format {
                    path: path.to_path_buf(),
                    line: None,
                    reason: format!("{name} = {t} is not a finite time code"),
                });
            }
        }
        let info = StageInfo {
            up_axis,
            meters_per_unit,
            start_time_code,
            end_time_code,
        };

        // Default predicate (active, loaded, defined, non-abstract) as usd-core's Traverse(),
        // descending into instances: a light inside an instanced asset lights the scene too.
        let mut paths = Vec::new();
        go(report.report(LoadProgress::Traversing { prims: 0 }))?;
        // The visitor cannot end the traversal: once the caller gives up it only stops
        // reporting, and the stop is taken below.
        let mut stopped = Ok(());
        stage
            .traverse(PrimPredicate::DEFAULT_PROXIES, |p| {
                paths.push(p.clone());
                if stopped.is_ok() {
                    stopped = report.step(paths.len() as u64, |prims| LoadProgress::Traversing {
                        prims,
                    });
                }
            })
            .map_err(e)?;
        go(stopped)?;
        let total = paths.len() as u64;
        go(report.report(LoadProgress::Traversing { prims: total }))?;
        let mut warnings = check_composition(path, &stage)?;

        let mut lights = Vec::new();
        let mut light_lists = Vec::new();
        // Per prim already walked: whether it or an ancestor has an op of `needs_own_xform`.
        // A light's walk up stops at the first prim known, so each prim's ops are read once
        // however many lights it holds.
        let mut own_xform_chain_of: HashMap<sdf::Path, bool> = HashMap::new();
        let mut attrs_of: HashMap<(String, Vec<String>), Rc<[schema::SchemaAttr]>> = HashMap::new();
        go(report.report(LoadProgress::Finding { done: 0, total }))?;
        for (i, p) in paths.into_iter().enumerate() {
            go(report.step(i as u64, |done| LoadProgress::Finding { done, total }))?;
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
                Some(None)
            } else {
                applied_schemas
                    .iter()
                    .find(|s| LIGHT_APIS.contains(&s.as_str()))
                    // LightAPI on a prim of another type (an Xform, a renderer's own light
                    // type): listed with a warning, never dropped silently.
                    .or_else(|| applied_schemas.iter().find(|s| *s == "LightAPI"))
                    .map(|api| Some(api.clone()))
            };
            // A light's authored property names, listed once: they decide which of its
            // properties are asked about below (a property no layer authors has no spec, so
            // neither a value, targets nor a spline).
            let authored = light_api
                .as_ref()
                .map(|_| prim.authored_property_names())
                .transpose()
                .map_err(e)?;
            if let Some(site) =
                unapplied::list_site(&prim, &applied_schemas, authored.as_deref()).map_err(e)?
            {
                light_lists.push(site);
            }
            let (Some(light_api), Some(authored)) = (light_api, authored) else {
                continue;
            };
            let applied: Vec<&str> = applied_schemas.iter().map(String::as_str).collect();
            let attrs = attrs_of
                .entry((usd_type.clone(), applied_schemas.clone()))
                .or_insert_with(|| schema::attrs_for(&usd_type, &applied).into())
                .clone();
            // Only an attribute some layer authors can hold a value or a spline (openusd finds
            // neither without a spec): the others are not asked about, which spares a typical
            // light most of its per-attribute queries and the indexes openusd caches for them.
            let has_spec: Vec<bool> = attrs.iter().map(|a| authors(&authored, a.name)).collect();
            // Every layer this prim's properties come from has been read by now (listing its
            // authored names composed them); where none may hold a spline, no attribute has a
            // spline field to ask about (3.5 % of `luxeval lights` on 30,000 plain lights).
            let splines = resolver.may_hold_splines();
            if splines {
                for (a, _) in attrs.iter().zip(&has_spec).filter(|(_, s)| **s) {
                    reject_spline(&p, &prim.attribute(a.name))?;
                }
            }
            // Inputs of the schema table that this light's schema lacks (a renderer's own
            // namespaced inputs are not the table's, so they pass without a word).
            let stray_inputs: Vec<String> = authored
                .iter()
                .map(|t| t.as_str())
                .filter(|n| {
                    // The Mesh rows are geometry any Gprim may author, not light inputs.
                    schema::TABLE
                        .iter()
                        .any(|a| a.name == *n && a.schema != "Mesh")
                        && !attrs.iter().any(|a| a.name == *n)
                })
                .map(str::to_string)
                .collect();
            // Filters, link collections, shaping inputs without ShapingAPI (those are said on
            // their own, not as stray inputs).
            let extras = unapplied::light_extras(&prim, &applied_schemas, &authored).map_err(e)?;
            let stray_inputs = extras.not_shaping(stray_inputs);
            // The prims from the light up to the first one known, each with whether it has
            // such an op itself; its ops are checked for splines on the way.
            let mut walked: Vec<(sdf::Path, bool)> = Vec::new();
            let mut above = false;
            let mut cur = Some(prim.clone());
            while let Some(q) = cur.filter(|q| !q.path().is_abs_root()) {
                if let Some(&chain) = own_xform_chain_of.get(q.path()) {
                    above = chain;
                    break;
                }
                let own = match Xformable::from_prim(q.clone()).map_err(e)? {
                    Some(x) => {
                        let (ops, _) = x.ordered_xform_ops().map_err(|err| xform_error(&p, err))?;
                        if splines {
                            for op in &ops {
                                reject_spline(&p, op.attribute())?;
                            }
                        }
                        ops_need_own_xform(&ops).map_err(|err| xform_error(&p, err))?
                    }
                    None => false,
                };
                walked.push((q.path().clone(), own));
                cur = q.parent();
            }
            let mut own_xform_chain = above;
            for (path, own) in walked.into_iter().rev() {
                own_xform_chain |= own;
                own_xform_chain_of.insert(path, own_xform_chain);
            }
            let mesh_light = usd_type == "Mesh" && light_api.as_deref() == Some("MeshLightAPI");
            let portals = match usd_type.as_str() {
                "DomeLight" | "DomeLight_1" => prim
                    .relationship("portals")
                    .targets()
                    .map_err(e)?
                    .iter()
                    .map(sdf::Path::to_string)
                    .collect(),
                _ => Vec::new(),
            };
            lights.push(LightSite {
                authors_visibility: authors(&authored, "visibility"),
                mesh_light,
                portals,
                path: p.to_string(),
                prim,
                usd_type,
                applied_schemas,
                light_api,
                attrs,
                has_spec,
                stray_inputs,
                extras,
                own_xform_chain,
            });
        }
        go(report.report(LoadProgress::Finding { done: total, total }))?;
        // Reading attributes can compose more (e.g. the prims an inherit arc names).
        for w in check_composition(path, &stage)? {
            if !warnings.contains(&w) {
                warnings.push(w);
            }
        }
        warnings.extend(resolver.notes());
        let mut files = resolver.opened();
        if !files.iter().any(|f| f == path) {
            files.insert(0, path.to_path_buf());
        }
        Ok(UsdStage {
            file: path.to_path_buf(),
            files,
            info,
            lights,
            warnings,
            light_lists,
            limits,
            _stage: stage,
        })
    }

    /// Every file read to compose the stage (its layers, and the packages holding them), the
    /// root layer first: what a command must never write over (DESIGN.md §4).
    pub fn files_read(&self) -> &[PathBuf] {
        &self.files
    }

    /// What the stage's reading says out loud: sublayers, references and payloads left out of
    /// the composition (not found, or a format luxeval does not read), then values the text
    /// reader read differently from how they were written; each names its layer.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    pub fn info(&self) -> &StageInfo {
        &self.info
    }

    /// The limits in force since the stage was opened.
    pub fn limits(&self) -> &Limits {
        &self.limits
    }

    /// The file the stage was opened from.
    pub fn file(&self) -> &Path {
        &self.file
    }

    /// Every light prim, in traversal order, resolved at `time`, each reported to `report`.
    pub(crate) fn lights_at(&self, time: Time, report: &mut Reporter) -> Result<Vec<LightPrim>> {
        let tc = time.code();
        let e = |err: openusd::Error| stage_error(&self.file, err);
        let go = |r: std::result::Result<(), Stopped>| r.map_err(|Stopped| cancelled(&self.file));
        let mut cache = WorldCache::new(tc);
        let mut visible_of = HashMap::new();
        let mut out = Vec::with_capacity(self.lights.len());
        let total = self.lights.len() as u64;
        go(report.report(LoadProgress::Reading { done: 0, total }))?;
        for (i, site) in self.lights.iter().enumerate() {
            go(report.step(i as u64, |done| LoadProgress::Reading { done, total }))?;
            let visible =
                visible_at(&site.prim, site.authors_visibility, tc, &mut visible_of).map_err(e)?;
            let world = match site.own_xform_chain {
                false => cache.local_to_world(&site.prim),
                true => world_as_usd_core(&cache, &site.prim, tc),
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
            for (a, &has_spec) in site.attrs.iter().zip(&site.has_spec) {
                inputs.push(match has_spec {
                    true => self.input(site, a, tc)?,
                    false => Input {
                        name: a.name.to_string(),
                        value: Value::fallback(a.fallback),
                        authored: false,
                    },
                });
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
                stray_inputs: site.stray_inputs.clone(),
                extras: site.extras.clone(),
                mesh: match site.mesh_light {
                    true => Some(read_arrays(&site.prim, &site.path, tc)?),
                    false => None,
                },
                portals: site.portals.clone(),
            });
        }
        // The step's end is reported once the lights are converted (`UsdStage::read_at`).
        Ok(out)
    }

    /// The light lists the stage authors (ListAPI / LightListAPI), in traversal order, read
    /// at `time`.
    pub(crate) fn light_lists_at(&self, time: Time) -> Result<Vec<LightList>> {
        let tc = time.code();
        self.light_lists
            .iter()
            .map(|s| unapplied::light_list(s, tc).map_err(|err| stage_error(&self.file, err)))
            .collect()
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
                None => Value::fallback(a.fallback),
            }
        } else {
            Value::fallback(a.fallback)
        };
        Ok(Input {
            name: a.name.to_string(),
            value,
            authored,
        })
    }
}
