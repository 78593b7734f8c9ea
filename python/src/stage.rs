//! `luxeval.Stage`: a USD stage's lights read once, queried any number of times.

use std::collections::HashMap;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use luxeval::{
    Accumulate, LoadProgress, PreparedScene, SampleOptions, Stage as ReadStage, TemperatureMode,
    TextureFilter, TimeRule,
};
use pyo3::exceptions::PyTypeError;
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString, PyTuple, PyType};

use crate::args::{self, Options, parse_lights};
use crate::device;
use crate::errors::{self, no_panic};

mod prepared;
mod queries;
mod sampling;

/// A USD stage (``.usda``, ``.usdc``, ``.usdz``) and its lights, read once at one time.
///
/// ``Stage(path, time=None, progress=None)`` opens the stage with every composition arc and
/// payload loaded and reads its lights at ``time`` (a USD time code); without one, at the stage's
/// ``startTimeCode`` when it is authored, else at each attribute's earliest time sample (USD's
/// EarliestTime), as ``luxeval lights`` does. ``progress``, when given, is called as
/// ``progress(step, done, total)`` while a stage is read: ``step`` is ``"opening"``,
/// ``"checking"`` (every layer the root reaches), ``"composing"`` (``done`` prims found so far,
/// ``total`` None), ``"finding"`` (``done`` of ``total`` prims asked whether they are lights)
/// or ``"reading"`` (``done`` of ``total`` lights read), at each step's start and end, every
/// 1,024 items and, while nothing new comes, every quarter second again; an exception it raises
/// stops the reading and is raised by ``Stage``. Ctrl-C stops it with ``KeyboardInterrupt``, with
/// or without ``progress`` (openusd's parse and composition run on to their end in the
/// background first, then the reading thread stops).
///
/// The queries (``emission``, ``radiance``, ``irradiance``, ``falloff``, ``sample``, ``pdf``)
/// take NumPy arrays (any real dtype, C or Fortran order; C-contiguous float32 is used without a
/// copy) and return ``numpy.float32`` arrays (``sample``: a dict of arrays). The lights a query evaluates are prepared once per
/// (``lights``, device, ``temperature_mode``, ``texture_filter``) and kept on the stage: later calls reuse the
/// prepared lights, the GPU pipelines and buffers. The GIL is released while the device works,
/// and Ctrl-C stops a long call with ``KeyboardInterrupt`` between chunks.
///
/// Raises ``InputError`` (a ``ValueError``) when the file is missing, unreadable or malformed
/// (the message names the file and line or prim), and ``TypeError`` when ``path`` is not a str
/// or path-like object. A Stage can be pickled: unpickling opens the stage again (by its absolute
/// path, at the same requested time).
#[pyclass(module = "luxeval", frozen)]
pub struct Stage {
    /// As given.
    path: PathBuf,
    absolute: PathBuf,
    /// The `time` argument (`None`: the stage's default rule).
    requested_time: Option<f64>,
    scene: ReadStage,
    /// `scene.lights` as `luxeval lights --json` writes them.
    lights_json: String,
    prepared: Mutex<HashMap<Key, Arc<PreparedScene>>>,
}

/// What a prepared scene depends on.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct Key {
    /// The `lights` selection, sorted (empty: every light).
    select: Vec<String>,
    gpu: bool,
    mode: TemperatureMode,
    filter: TextureFilter,
    portal: luxeval::PortalMode,
}

/// `Stage(path, time)`'s arguments, as pickling records them.
type StageArgs = (String, Option<f64>);

#[derive(Clone, Copy, PartialEq, Eq)]
enum Query {
    Emission,
    Intensity,
    Radiance,
    Irradiance,
}

impl Stage {
    fn file(&self) -> &Path {
        &self.path
    }
}

#[pymethods]
impl Stage {
    #[new]
    #[pyo3(signature = (path, time = None, progress = None))]
    fn new(
        py: Python<'_>,
        path: PathBuf,
        time: Option<f64>,
        progress: Option<Py<PyAny>>,
    ) -> PyResult<Stage> {
        if let Some(t) = time.filter(|t| !t.is_finite()) {
            return Err(errors::input(format!(
                "time: {t} is not a finite time code"
            )));
        }
        if let Some(p) = &progress
            && !p.bind(py).is_callable()
        {
            return Err(PyTypeError::new_err("progress: must be callable or None"));
        }
        let absolute = std::path::absolute(&path).unwrap_or_else(|_| path.clone());
        // The stage is read on a thread of the library's own; this thread, the GIL released,
        // is told each step (and the last one again every quarter second), runs `progress`
        // and Python's signal handlers, and gives up on the first exception either raises
        // (KeyboardInterrupt included), which is then raised here.
        let mut raised: Option<PyErr> = None;
        let loaded = py.detach(|| {
            no_panic(|| {
                Ok(ReadStage::load_with_progress(&path, time, |p| {
                    Python::attach(|py| {
                        let r = py.check_signals().and_then(|()| match &progress {
                            Some(f) => {
                                let (step, done, total) = progress_args(p);
                                f.call1(py, (step, done, total)).map(drop)
                            }
                            None => Ok(()),
                        });
                        match r {
                            Ok(()) => ControlFlow::Continue(()),
                            Err(e) => {
                                raised = Some(e);
                                ControlFlow::Break(())
                            }
                        }
                    })
                }))
            })
        })?;
        let scene = match (loaded, raised) {
            (_, Some(e)) => return Err(e),
            (Ok(scene), None) => scene,
            (Err(e), None) => return Err(errors::lux(e, None)),
        };
        let lights_json = luxeval::lights_json(&scene, luxeval::PortalMode::Hint)
            .map(|v| v.to_string())
            .map_err(|e| errors::DeviceError::new_err(format!("serialising the lights: {e}")))?;
        Ok(Stage {
            path,
            absolute,
            requested_time: time,
            scene,
            lights_json,
            prepared: Mutex::new(HashMap::new()),
        })
    }

    /// The stage's path, as given.
    #[getter]
    fn path(&self) -> String {
        self.path.to_string_lossy().into_owned()
    }

    /// The time code the lights were read at, or ``None`` for USD's EarliestTime (each
    /// attribute's earliest time sample). See ``time_rule``.
    #[getter]
    fn time(&self) -> Option<f64> {
        match self.scene.time {
            TimeRule::Given(t) | TimeRule::StartTimeCode(t) => Some(t),
            TimeRule::Earliest => None,
        }
    }

    /// Why the lights were read at ``time``: ``"given"`` (the ``time`` argument),
    /// ``"start_time_code"`` (the stage's ``startTimeCode``) or ``"earliest"``.
    #[getter]
    fn time_rule(&self) -> &'static str {
        match self.scene.time {
            TimeRule::Given(_) => "given",
            TimeRule::StartTimeCode(_) => "start_time_code",
            TimeRule::Earliest => "earliest",
        }
    }

    /// ``"Y"`` or ``"Z"`` (``"Y"`` when the stage does not author ``upAxis``, as USD does).
    #[getter]
    fn up_axis(&self) -> &str {
        &self.scene.up_axis
    }

    /// The stage's ``metersPerUnit`` (0.01 when not authored, as USD does).
    #[getter]
    fn meters_per_unit(&self) -> f64 {
        self.scene.meters_per_unit
    }

    /// Every light of the stage in traversal order, evaluated or not, as dicts: the records of
    /// ``luxeval lights --json`` (``path``, ``usd_type``, ``applied_schemas``, ``visible``,
    /// ``world`` (row-vector, ``world[3]`` is the translation), ``inputs`` (each with ``name``,
    /// ``value``, ``authored``), ``evaluable``, ``warning``, ``power`` (``rgb``, ``lumens``,
    /// ``watts``; ``None`` for lights at infinity, mesh lights (their flux is not computed) or
    /// lights not evaluated) and, when the light cannot be
    /// prepared, ``power_error``; and what luxeval reads but does not apply: ``light_filters``
    /// (the ``light:filters`` targets), ``link_collections`` (the light-link and shadow-link
    /// collections that restrict the light, each with ``name``, ``include_root``,
    /// ``includes``, ``excludes``, ``expansion_rule``, ``membership_expression``) and
    /// ``shaping_without_api`` (``inputs:shaping:*`` authored without ShapingAPI: the light is
    /// evaluated unshaped)); a mesh light's ``mesh`` (``triangles``, ``area``, ``holes``,
    /// ``degenerate_triangles``, ``folded_faces``, ``tint``, ``tint_source``, ``double_sided``,
    /// ``subdivision_scheme``, ``subdivision``), a portal's ``portal`` (``width``, ``height``,
    /// its multiplier inputs, ``multiplier``, ``domes``) and a dome's ``portals`` (its targets),
    /// ``portals_evaluated`` (the visible PortalLights among them) and ``masked`` (always
    /// false here: ``portal_mode=`` is a query's option, DESIGN.md §8 P2). A new list on each
    /// access.
    #[getter]
    fn lights<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import(intern!(py, "json"))?
            .call_method1(intern!(py, "loads"), (&self.lights_json,))
    }

    /// The stage's light lists (ListAPI / LightListAPI), which luxeval does not read (it
    /// traverses the whole stage), as dicts: ``path``, ``api`` (``None`` where neither API is
    /// applied), ``targets``, ``cache_behavior`` (``None`` where not authored). The
    /// ``light_lists`` of ``luxeval lights --json``; a new list on each access.
    #[getter]
    fn light_lists<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let text = serde_json::to_string(&self.scene.light_lists).map_err(|e| {
            errors::DeviceError::new_err(format!("serialising the light lists: {e}"))
        })?;
        py.import(intern!(py, "json"))?
            .call_method1(intern!(py, "loads"), (text,))
    }

    /// What the stage's visible, evaluable lights have (light filters, light-link and
    /// shadow-link collections, shaping inputs without ShapingAPI) and the stage (light lists)
    /// that a renderer applies and luxeval does not, in one line, or ``None``: the warning
    /// every ``luxeval`` query command prints (after ``warning: SCENE:``).
    #[getter]
    fn unapplied(&self) -> Option<String> {
        self.scene.unapplied(&[])
    }

    /// What reading the stage said out loud (a sublayer, reference or payload left out, a value
    /// read differently from how it was written; each naming its layer), then one message per
    /// light that the queries skip (unsupported type or feature, invisible), naming its prim;
    /// ``luxeval`` prints the same lines as ``warning:`` on stderr.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.scene.warnings()
    }

    /// The prepared light sets cached on this stage, as (``lights`` selection as a sorted tuple
    /// or ``None`` for every light, ``"gpu"`` or ``"cpu"``, ``temperature_mode``,
    /// ``texture_filter``) tuples: each is prepared by the first query with those options and
    /// reused by every later one.
    #[getter]
    fn prepared<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyTuple>>> {
        let mut keys: Vec<Key> = self.cache().keys().cloned().collect();
        keys.sort_by(|a, b| {
            (
                &a.select,
                a.gpu,
                device::mode_name(a.mode),
                device::filter_name(a.filter),
            )
                .cmp(&(
                    &b.select,
                    b.gpu,
                    device::mode_name(b.mode),
                    device::filter_name(b.filter),
                ))
        });
        keys.into_iter()
            .map(|k| {
                let select: Py<PyAny> = if k.select.is_empty() {
                    py.None()
                } else {
                    PyTuple::new(py, &k.select)?.into_any().unbind()
                };
                PyTuple::new(
                    py,
                    [
                        select,
                        PyString::new(py, if k.gpu { "gpu" } else { "cpu" })
                            .into_any()
                            .unbind(),
                        PyString::new(py, device::mode_name(k.mode))
                            .into_any()
                            .unbind(),
                        PyString::new(py, device::filter_name(k.filter))
                            .into_any()
                            .unbind(),
                    ],
                )
            })
            .collect()
    }

    /// The prim paths a query with this ``lights=`` argument evaluates, in the order of the
    /// rows of ``per_light=True`` results: the visible, evaluable lights in stage order (the
    /// selection filters; it does not reorder). Raises ``InputError`` when a selected path is
    /// not a light of the stage.
    #[pyo3(signature = (lights = None))]
    fn light_paths(&self, lights: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<String>> {
        let select = parse_lights(lights)?;
        Ok(self
            .scene
            .evaluable(&select)
            .map_err(|e| errors::lux(e, Some(self.file())))?
            .into_iter()
            .map(|l| l.path)
            .collect())
    }

    /// The radiance leaving each light along each direction: ``dirs``
    /// points away from the light (for a dome, toward the environment), any non-zero length.
    ///
    /// ``dirs``: (N, 3), any real dtype. Returns float32 (N, 3), the sum over lights, or
    /// (L, N, 3) with ``per_light=True``, in the order of ``light_paths(lights)``.
    /// ``lights``: a prim path or a list of them (default: every visible, evaluable light).
    /// ``device``: ``"auto"`` (a hardware GPU, else the CPU reference with one ``DeviceWarning``),
    /// ``"gpu"`` (``DeviceError`` without one) or ``"cpu"`` (the f64 reference, rounded to
    /// float32). ``temperature_mode``: ``"spec"``, ``"usd"`` or ``"planckian"``.
    /// ``texture_filter``: ``"bilinear"`` or ``"nearest"`` (dome and rect textures).
    /// Raises ``InputError`` for a wrong shape or dtype, a non-finite or zero row, an unknown
    /// light, or a light attribute luxeval cannot evaluate (naming the file, prim, attribute).
    #[pyo3(signature = (dirs, *, per_light = false, lights = None, device = "auto", temperature_mode = "spec", texture_filter = "bilinear", portal_mode = "hint"))]
    #[allow(clippy::too_many_arguments)]
    fn emission<'py>(
        &self,
        py: Python<'py>,
        dirs: &Bound<'py, PyAny>,
        per_light: bool,
        lights: Option<&Bound<'py, PyAny>>,
        device: &str,
        temperature_mode: &str,
        texture_filter: &str,
        portal_mode: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let o = Options::parse(
            lights,
            device,
            temperature_mode,
            texture_filter,
            portal_mode,
        )?;
        self.query(py, Query::Emission, dirs, None, per_light, o)
    }

    /// The far-field intensity of each light along each direction, ``emission × projected
    /// area`` (cd for lights in nits; 0 for distant and dome lights, which are at infinity), as
    /// ``luxeval intensity``. A mesh light's projected area is its visible emitting
    /// area seen along ``dirs``, self-occlusion included.
    ///
    /// ``dirs``: (N, 3), any real dtype. Returns float32 (N, 3), or (L, N, 3) with
    /// ``per_light=True``. Options and errors as ``emission``.
    #[pyo3(signature = (dirs, *, per_light = false, lights = None, device = "auto", temperature_mode = "spec", texture_filter = "bilinear", portal_mode = "hint"))]
    #[allow(clippy::too_many_arguments)]
    fn intensity<'py>(
        &self,
        py: Python<'py>,
        dirs: &Bound<'py, PyAny>,
        per_light: bool,
        lights: Option<&Bound<'py, PyAny>>,
        device: &str,
        temperature_mode: &str,
        texture_filter: &str,
        portal_mode: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let o = Options::parse(
            lights,
            device,
            temperature_mode,
            texture_filter,
            portal_mode,
        )?;
        self.query(py, Query::Intensity, dirs, None, per_light, o)
    }

    /// The radiance arriving at each point from each direction:
    /// ``dirs[i]`` points from ``points[i]`` toward the light; 0 where the ray misses it.
    ///
    /// ``points``, ``dirs``: (N, 3) each, paired row by row. Returns float32 (N, 3), or
    /// (L, N, 3) with ``per_light=True``. Options and errors as ``emission``.
    #[pyo3(signature = (points, dirs, *, per_light = false, lights = None, device = "auto", temperature_mode = "spec", texture_filter = "bilinear", portal_mode = "hint"))]
    #[allow(clippy::too_many_arguments)]
    fn radiance<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        dirs: &Bound<'py, PyAny>,
        per_light: bool,
        lights: Option<&Bound<'py, PyAny>>,
        device: &str,
        temperature_mode: &str,
        texture_filter: &str,
        portal_mode: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let o = Options::parse(
            lights,
            device,
            temperature_mode,
            texture_filter,
            portal_mode,
        )?;
        self.query(py, Query::Radiance, points, Some(dirs), per_light, o)
    }

    /// The diffuse-weighted irradiance at each point on a one-sided receiver with the given
    /// normal: ``diffuse · ∫ radiance(x, ω) max(0, n·ω) dω``, no
    /// occlusion (lux for lights in nits).
    ///
    /// ``points``, ``normals``: (N, 3) each, paired row by row; normals any non-zero length.
    /// Returns float32 (N, 3), or (L, N, 3) with ``per_light=True``. Options and errors as
    /// ``emission``. ``tolerance``: relative, from 1e-9 to 0.1, as ``luxeval irradiance
    /// --tolerance`` (the CPU's quadrature stops there; the GPU takes none below 1e-4).
    #[pyo3(signature = (points, normals, *, per_light = false, lights = None, device = "auto", temperature_mode = "spec", texture_filter = "bilinear", portal_mode = "hint", tolerance = 1e-4))]
    #[allow(clippy::too_many_arguments)]
    fn irradiance<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        normals: &Bound<'py, PyAny>,
        per_light: bool,
        lights: Option<&Bound<'py, PyAny>>,
        device: &str,
        temperature_mode: &str,
        texture_filter: &str,
        portal_mode: &str,
        tolerance: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let o = Options::parse(
            lights,
            device,
            temperature_mode,
            texture_filter,
            portal_mode,
        )?
        .with_tolerance(tolerance)?;
        self.query(py, Query::Irradiance, points, Some(normals), per_light, o)
    }

    /// A falloff map, as ``luxeval falloff`` computes it: the summed irradiance at the pixel
    /// centres of the rectangle ``origin + s·u + t·v`` (s, t in [0, 1]), receiver normal
    /// ``normalize(u × v)``. ``origin``, ``u``, ``v``: three numbers each; ``res``:
    /// (width, height). Returns float32 (height, width, 3), row 0 at the top of the image
    /// (``origin + v`` side), column 0 at the ``origin`` side: pixel (row j, column i) is at
    /// ``origin + (i + ½)/W·u + (1 − (j + ½)/H)·v``. Options and errors as ``emission``;
    /// ``tolerance`` as ``irradiance``.
    #[pyo3(signature = (origin, u, v, res, *, lights = None, device = "auto", temperature_mode = "spec", texture_filter = "bilinear", portal_mode = "hint", tolerance = 1e-4))]
    #[allow(clippy::too_many_arguments)]
    fn falloff<'py>(
        &self,
        py: Python<'py>,
        origin: &Bound<'py, PyAny>,
        u: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        res: &Bound<'py, PyAny>,
        lights: Option<&Bound<'py, PyAny>>,
        device: &str,
        temperature_mode: &str,
        texture_filter: &str,
        portal_mode: &str,
        tolerance: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let o = Options::parse(
            lights,
            device,
            temperature_mode,
            texture_filter,
            portal_mode,
        )?
        .with_tolerance(tolerance)?;
        self.falloff_map(py, o, (origin, u, v), res)
    }

    /// Draws ``count`` directions per point toward the lights, with their densities, as
    /// ``luxeval sample`` does (DESIGN.md §9, docs/SAMPLING.md): at each point a light is chosen
    /// by ``selection``, then a direction by that light's strategy.
    ///
    /// ``points``: (N, 3); ``normals``: (N, 3) receiver normals paired with the points, or
    /// ``None`` (they make the choice of light receiver-aware and the dome cosine-weighted;
    /// ``selection="exact"`` needs them). ``count``: samples per point, K, from 1 to 2²⁰.
    /// ``seed``: 0 to 2³² − 1; the generator is keyed by (seed, row, sample), so the same seed
    /// draws the same directions however the rows are split. ``selection``: ``"bound"`` (each
    /// light weighed by what it can deliver at the receiver), ``"power"`` (by its flux) or
    /// ``"exact"`` (by its exact irradiance at (x, n)). ``first_point``: the row of
    /// ``points[0]`` in a larger input, so that a slice of it draws what the whole would draw
    /// for those rows (``luxeval.dask.sample`` passes each chunk's offset).
    ///
    /// Returns a dict of NumPy arrays, row i·K + j of the library's output at ``[i, j]``:
    /// ``"dirs"`` float32 (N, K, 3), unit directions from the point toward the chosen light;
    /// ``"pdf"`` float32 (N, K), P(light | x) · pdf_light(ω) per unit solid angle (``inf`` for a
    /// delta light: distant, or a point-like sphere; 0 where no light reaches the point);
    /// ``"radiance"`` float32 (N, K, 3), the chosen light's radiance along the direction (for a
    /// delta light, the value whose product with max(0, n·ω) is its irradiance, without
    /// ``diffuse``); ``"light_pdf"`` float32 (N, K), P(light | x); ``"light"`` int32 (N, K), the
    /// chosen light's row in ``light_paths(lights)``, −1 where no light reaches the point. The
    /// estimate ``radiance · max(0, n·ω) / pdf`` (``/ light_pdf`` where ``pdf`` is ``inf``)
    /// averages to the irradiance divided by each light's ``diffuse``.
    ///
    /// ``device`` as ``emission``: on a GPU the light is chosen on the host and each direction
    /// drawn by the WGSL samplers (within 1e-4 of the CPU reference; a textured dome's rows are
    /// the reference's on every device). With the same ``device`` the results are bitwise those
    /// of ``luxeval sample``. Other options as ``emission``.
    /// Raises ``InputError`` for a count, seed or selection out of range (naming it), missing
    /// normals with ``selection="exact"``, and the errors of ``emission``.
    #[pyo3(signature = (points, normals = None, *, count = None, seed = None, selection = "bound", lights = None, device = "auto", temperature_mode = "spec", texture_filter = "bilinear", portal_mode = "hint", first_point = None))]
    #[pyo3(
        text_signature = "(self, points, normals=None, *, count=1, seed=0, selection=\"bound\", lights=None, device=\"auto\", temperature_mode=\"spec\", texture_filter=\"bilinear\", portal_mode=\"hint\", first_point=0)"
    )]
    #[allow(clippy::too_many_arguments)]
    fn sample<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        normals: Option<&Bound<'py, PyAny>>,
        count: Option<&Bound<'py, PyAny>>,
        seed: Option<&Bound<'py, PyAny>>,
        selection: &str,
        lights: Option<&Bound<'py, PyAny>>,
        device: &str,
        temperature_mode: &str,
        texture_filter: &str,
        portal_mode: &str,
        first_point: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let o = Options::parse(
            lights,
            device,
            temperature_mode,
            texture_filter,
            portal_mode,
        )?;
        let k = match count {
            Some(c) => args::count(c)?,
            None => 1,
        };
        let seed = match seed {
            Some(s) => args::unsigned(s, "seed", u32::MAX.into())? as u32,
            None => 0,
        };
        let first_point = match first_point {
            Some(f) => args::unsigned(f, "first_point", i64::MAX as u64)?,
            None => 0,
        };
        let selection = args::parse_selection(selection)?;
        let opts = SampleOptions {
            seed,
            selection,
            first_point,
        };
        self.sample_rows(py, points, normals, k, &opts, o)
    }

    /// The density ``sample`` draws each direction with: for each (point, direction) pair,
    /// Σ over lights of P(light | x) · pdf_light(ω) per unit solid angle (delta lights add 0),
    /// as ``luxeval pdf`` computes it.
    ///
    /// ``points``, ``dirs``: (M, 3) each, paired row by row (``dirs[i]`` from ``points[i]``,
    /// any non-zero length); ``normals``: (M, 3) or ``None``, as given to ``sample`` (the
    /// density depends on them). Returns float32 (M,), or (L, M) with ``per_light=True`` (one
    /// row per light, in the order of ``light_paths(lights)``, whose sum is the summed
    /// density). ``selection``, ``device`` and errors as ``sample``; other options as
    /// ``emission``.
    #[pyo3(signature = (points, dirs, normals = None, *, per_light = false, selection = "bound", lights = None, device = "auto", temperature_mode = "spec", texture_filter = "bilinear", portal_mode = "hint"))]
    #[allow(clippy::too_many_arguments)]
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        dirs: &Bound<'py, PyAny>,
        normals: Option<&Bound<'py, PyAny>>,
        per_light: bool,
        selection: &str,
        lights: Option<&Bound<'py, PyAny>>,
        device: &str,
        temperature_mode: &str,
        texture_filter: &str,
        portal_mode: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let o = Options::parse(
            lights,
            device,
            temperature_mode,
            texture_filter,
            portal_mode,
        )?;
        let selection = args::parse_selection(selection)?;
        self.pdf_rows(py, (points, dirs, normals), per_light, selection, o)
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyType>, StageArgs)> {
        let me = slf.get();
        Ok((
            slf.get_type(),
            (
                me.absolute.to_string_lossy().into_owned(),
                me.requested_time,
            ),
        ))
    }

    fn __repr__(&self) -> String {
        let evaluated = self.scene.evaluable(&[]).map(|l| l.len()).unwrap_or(0);
        let at = match self.scene.time {
            TimeRule::Given(t) => format!("time {t}"),
            TimeRule::StartTimeCode(t) => format!("time {t} (startTimeCode)"),
            TimeRule::Earliest => "the earliest time".into(),
        };
        format!(
            "<luxeval.Stage {:?} at {at}: {} lights, {} evaluated>",
            self.path.to_string_lossy(),
            self.scene.lights.len(),
            evaluated
        )
    }
}

/// The accumulation a query asks for and the rows it returns per input row: one per light
/// (`per_light`, `lights` of them) or their sum.
fn accumulate(per_light: bool, lights: usize) -> (Accumulate, usize) {
    if per_light {
        (Accumulate::PerLight, lights)
    } else {
        (Accumulate::Sum, 1)
    }
}

/// Two arrays that pair up row by row, or an `InputError` naming both and their lengths.
fn paired(a_name: &str, a: usize, b_name: &str, b: usize) -> PyResult<()> {
    if a != b {
        return Err(errors::input(format!(
            "{a_name}/{b_name}: {a} {a_name} but {b} {b_name}; they pair up row by row"
        )));
    }
    Ok(())
}

/// `progress`'s arguments for one report: the step's name, the items done (prims found while
/// composing) and their total, `None` where a step has none.
fn progress_args(p: LoadProgress) -> (&'static str, Option<u64>, Option<u64>) {
    match p {
        LoadProgress::Opening => ("opening", None, None),
        LoadProgress::Checking => ("checking", None, None),
        LoadProgress::Traversing { prims } => ("composing", Some(prims), None),
        LoadProgress::Finding { done, total } => ("finding", Some(done), Some(total)),
        LoadProgress::Reading { done, total } => ("reading", Some(done), Some(total)),
        // A step a later library adds, without counts.
        _ => ("working", None, None),
    }
}
