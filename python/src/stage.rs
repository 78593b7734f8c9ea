//! `luxeval.Stage`: a USD stage's lights read once, queried any number of times.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use luxeval::{
    Accumulate, FalloffPlane as Plane, PreparedScene, RowKind, SampleOptions, Selection,
    Stage as ReadStage, TemperatureMode, TextureFilter, TimeRule,
};
use numpy::prelude::*;
use numpy::{PyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyUserWarning;
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString, PyTuple, PyType};

use crate::args::{self, Options, parse_lights, resolution, vec3};
use crate::arrays;
use crate::chunks::{Chunks, zeros};
use crate::device;
use crate::errors::{self, no_panic};

/// A USD stage (``.usda``, ``.usdc``, ``.usdz``) and its lights, read once at one time.
///
/// ``Stage(path, time=None)`` opens the stage with every composition arc and payload loaded and
/// reads its lights at ``time`` (a USD time code); without one, at the stage's ``startTimeCode``
/// when it is authored, else at each attribute's earliest time sample (USD's EarliestTime), as
/// ``luxeval lights`` does.
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

    /// The prepared scene for these options, from the cache or prepared now.
    fn prepare_for(&self, py: Python<'_>, o: &Options) -> PyResult<Arc<PreparedScene>> {
        // Selection and attribute errors first: they cost nothing to find, a device does.
        let mut lights = self
            .scene
            .evaluable(&o.select)
            .map_err(|e| errors::lux(e, Some(self.file())))?;
        for l in &mut lights {
            l.validate()
                .map_err(|e| errors::lux(e, Some(self.file())))?;
            if let Some(t) = &mut l.texture {
                t.filter = o.filter;
            }
        }
        let eval = device::evaluator(py, o.device, o.mode)?.with_portal_mode(o.portal);
        let mut select = o.select.clone();
        select.sort();
        select.dedup();
        let key = Key {
            select,
            gpu: eval.is_gpu(),
            mode: o.mode,
            filter: o.filter,
            portal: o.portal,
        };
        if let Some(p) = self.cache().get(&key) {
            return Ok(p.clone());
        }
        if lights.is_empty() {
            let msg = format!(
                "{}: no light to evaluate; the result is all zeros",
                self.path.display()
            );
            let msg = std::ffi::CString::new(msg.replace('\0', " ")).expect("no NUL");
            PyErr::warn(py, &py.get_type::<PyUserWarning>(), &msg, 2)?;
        }
        let file = self.file();
        let scene = py.detach(|| {
            no_panic(|| {
                eval.prepare(&lights)
                    .map_err(|e| errors::lux(e, Some(file)))
            })
        })?;
        let scene = Arc::new(scene);
        Ok(self.cache().entry(key).or_insert(scene).clone())
    }

    /// The options of `sample` and `pdf`, checked as every query's (sampling runs where
    /// `device` says, as the other queries).
    fn sampling_options(
        &self,
        _py: Python<'_>,
        lights: Option<&Bound<'_, PyAny>>,
        device: &str,
        mode: &str,
        filter: &str,
        portal: &str,
    ) -> PyResult<Options> {
        Options::parse(lights, device, mode, filter, portal)
    }

    /// `sample`'s and `pdf`'s points and optional normals, checked (rows, pairing, and the
    /// normals that `selection="exact"` needs).
    #[allow(clippy::type_complexity)]
    fn sampling_rows<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        normals: Option<&Bound<'py, PyAny>>,
        selection: Selection,
    ) -> PyResult<(
        PyReadonlyArray2<'py, f32>,
        Option<PyReadonlyArray2<'py, f32>>,
    )> {
        let normals = normals.filter(|n| !n.is_none());
        if normals.is_none() && selection == Selection::Exact {
            return Err(errors::input(
                "normals: selection=\"exact\" needs a receiver normal per point (it weighs each \
                 light by its irradiance on the receiver)",
            ));
        }
        let p = arrays::rows(py, points, "points", RowKind::Points)?;
        let n = match normals {
            Some(n) => Some(arrays::rows(py, n, "normals", RowKind::Directions)?),
            None => None,
        };
        if let Some(n) = &n {
            paired("points", p.shape()[0], "normals", n.shape()[0])?;
        }
        Ok((p, n))
    }

    fn cache(&self) -> std::sync::MutexGuard<'_, HashMap<Key, Arc<PreparedScene>>> {
        self.prepared
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    #[allow(clippy::too_many_arguments)]
    fn query<'py>(
        &self,
        py: Python<'py>,
        q: Query,
        a: &Bound<'py, PyAny>,
        b: Option<&Bound<'py, PyAny>>,
        per_light: bool,
        o: Options,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (a_name, a_kind, b_name) = match q {
            Query::Emission | Query::Intensity => ("dirs", RowKind::Directions, ""),
            Query::Radiance => ("points", RowKind::Points, "dirs"),
            Query::Irradiance => ("points", RowKind::Points, "normals"),
        };
        let a_arr = arrays::rows(py, a, a_name, a_kind)?;
        let b_arr: Option<PyReadonlyArray2<'py, f32>> = match b {
            Some(b) => Some(arrays::rows(py, b, b_name, RowKind::Directions)?),
            None => None,
        };
        let a_rows = arrays::as_vec3(&a_arr)?;
        // Radiance and irradiance pair every row of `a` with one of `b` (a missing `b` counts
        // as an empty array and is refused here).
        let b_rows: &[[f32; 3]] = match &b_arr {
            Some(b) => arrays::as_vec3(b)?,
            None => &[],
        };
        if !matches!(q, Query::Emission | Query::Intensity) {
            paired(a_name, a_rows.len(), b_name, b_rows.len())?;
        }
        let scene = self.prepare_for(py, &o)?;
        let recomputed = scene.host_recomputed_rows();
        let n = a_rows.len();
        let l = scene.len();
        let (acc, width) = if per_light {
            (Accumulate::PerLight, l)
        } else {
            (Accumulate::Sum, 1)
        };
        let mut out = zeros::<f32>(width.checked_mul(n).and_then(|x| x.checked_mul(3)))?;
        let mut chunks = Chunks::new(
            match q {
                Query::Irradiance => 256,
                _ => 1 << 14,
            },
            l,
        );
        let file = self.file();
        let mut start = 0;
        while start < n {
            let end = (start + chunks.rows).min(n);
            let scene = &*scene;
            let out = &mut out;
            let t0 = Instant::now();
            py.detach(|| {
                no_panic(|| {
                    let a = &a_rows[start..end];
                    let rows = match q {
                        Query::Emission => scene.emission(a, acc),
                        Query::Intensity => scene.intensity(a, acc),
                        Query::Radiance => scene.radiance(a, &b_rows[start..end], acc),
                        Query::Irradiance => o.irradiance(scene, a, &b_rows[start..end], acc),
                    }
                    .map_err(|e| errors::lux(e, Some(file)))?;
                    let m = end - start;
                    for li in 0..width {
                        let dst = &mut out[(li * n + start) * 3..(li * n + end) * 3];
                        dst.copy_from_slice(rows[li * m..(li + 1) * m].as_flattened());
                    }
                    Ok(())
                })
            })?;
            if end < n {
                chunks.update(end - start, t0.elapsed().as_secs_f64());
            }
            py.check_signals()?;
            start = end;
        }
        if matches!(q, Query::Irradiance) {
            self.warn_host_recomputed(py, scene.host_recomputed_rows() - recomputed, width * n)?;
        }
        let shape: Vec<usize> = if per_light { vec![l, n, 3] } else { vec![n, 3] };
        Ok(PyArray1::from_vec(py, out).reshape(shape)?.into_any())
    }
}

impl Stage {
    /// A `UserWarning` when `k` of a call's `rows` irradiance rows were recomputed on the CPU
    /// reference because the device could not finish them
    /// (`PreparedScene::host_recomputed_rows`; the command line's `note:` line).
    fn warn_host_recomputed(&self, py: Python<'_>, k: usize, rows: usize) -> PyResult<()> {
        if k == 0 {
            return Ok(());
        }
        let msg = format!(
            "{}: {k} of {rows} irradiance rows were recomputed on the CPU reference: the device \
             could not finish their quadrature (more breakpoints than the kernel holds, or a \
             software GPU's loop budget)",
            self.path.display()
        );
        let msg = std::ffi::CString::new(msg.replace('\0', " ")).expect("no NUL");
        PyErr::warn(py, &py.get_type::<PyUserWarning>(), &msg, 2)
    }
}

#[pymethods]
impl Stage {
    #[new]
    #[pyo3(signature = (path, time = None))]
    fn new(py: Python<'_>, path: PathBuf, time: Option<f64>) -> PyResult<Stage> {
        if let Some(t) = time.filter(|t| !t.is_finite()) {
            return Err(errors::input(format!(
                "time: {t} is not a finite time code"
            )));
        }
        let absolute = std::path::absolute(&path).unwrap_or_else(|_| path.clone());
        let scene = py.detach(|| {
            no_panic(|| ReadStage::load(&path, time).map_err(|e| errors::lux(e, None)))
        })?;
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
        let origin = vec3(py, origin, "origin")?;
        let u = vec3(py, u, "u")?;
        let v = vec3(py, v, "v")?;
        let (w, h) = resolution(res)?;
        // Refuses a NaN length too (huge finite vectors can overflow to one).
        if u.cross(v).length().partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return Err(errors::input(format!(
                "u/v: u = {u} and v = {v} are parallel or zero: they span no plane"
            )));
        }
        let plane = Plane::new(origin, u, v, w, h).map_err(|e| errors::lux(e, None))?;
        let scene = self.prepare_for(py, &o)?;
        let recomputed = scene.host_recomputed_rows();
        let normal = plane.normal().as_vec3().to_array();
        let pixels = plane.pixels();
        let mut out = zeros::<f32>(pixels.checked_mul(3))?;
        // Whole rows of pixels per call, sized like the queries' chunks.
        let mut chunks = Chunks::new(256, scene.len());
        let file = self.file();
        let mut j0 = 0u32;
        while j0 < h {
            let rows = (chunks.rows / w as usize).clamp(1, h as usize) as u32;
            let j1 = (j0 + rows).min(h);
            let scene = &*scene;
            let plane = &plane;
            let out = &mut out;
            let t0 = Instant::now();
            py.detach(|| {
                no_panic(|| {
                    let points: Vec<[f32; 3]> = (j0..j1)
                        .flat_map(|j| (0..w).map(move |i| (i, j)))
                        .map(|(i, j)| plane.pixel_centre(i, j).as_vec3().to_array())
                        .collect();
                    let normals = vec![normal; points.len()];
                    let rgb = o
                        .irradiance(scene, &points, &normals, Accumulate::Sum)
                        .map_err(|e| errors::lux(e, Some(file)))?;
                    let at = j0 as usize * w as usize * 3;
                    out[at..at + rgb.len() * 3].copy_from_slice(rgb.as_flattened());
                    Ok(())
                })
            })?;
            if j1 < h {
                chunks.update((j1 - j0) as usize * w as usize, t0.elapsed().as_secs_f64());
            }
            py.check_signals()?;
            j0 = j1;
        }
        self.warn_host_recomputed(py, scene.host_recomputed_rows() - recomputed, pixels)?;
        Ok(PyArray1::from_vec(py, out)
            .reshape([h as usize, w as usize, 3])?
            .into_any())
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
        let o = self.sampling_options(
            py,
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
        let (p_arr, n_arr) = self.sampling_rows(py, points, normals, selection)?;
        let pts = arrays::as_vec3(&p_arr)?;
        let nrm = match &n_arr {
            Some(a) => Some(arrays::as_vec3(a)?),
            None => None,
        };
        let scene = self.prepare_for(py, &o)?;
        let n = pts.len();
        let total = n.checked_mul(k);
        let times3 = total.and_then(|t| t.checked_mul(3));
        let mut dirs = zeros::<f32>(times3)?;
        let mut pdf = zeros::<f32>(total)?;
        let mut radiance = zeros::<f32>(times3)?;
        let mut light_pdf = zeros::<f32>(total)?;
        let mut light = zeros::<i32>(total)?;
        // Points per call: a point costs K samples (at most 2²² samples per call).
        let mut chunks = Chunks::new(((1usize << 12) / k).max(1), k);
        let file = self.file();
        let mut start = 0;
        while start < n {
            let end = (start + chunks.rows).min(n);
            let scene = &*scene;
            let (dirs, pdf, radiance, light_pdf, light) = (
                &mut dirs,
                &mut pdf,
                &mut radiance,
                &mut light_pdf,
                &mut light,
            );
            let t0 = Instant::now();
            py.detach(|| {
                no_panic(|| {
                    let opts = SampleOptions {
                        seed,
                        selection,
                        first_point: first_point + start as u64,
                    };
                    let s = scene
                        .sample(&pts[start..end], nrm.map(|v| &v[start..end]), k, &opts)
                        .map_err(|e| errors::lux(e, Some(file)))?;
                    let (a, b) = (start * k, end * k);
                    dirs[a * 3..b * 3].copy_from_slice(s.dirs.as_flattened());
                    pdf[a..b].copy_from_slice(&s.pdf);
                    radiance[a * 3..b * 3].copy_from_slice(s.radiance.as_flattened());
                    light_pdf[a..b].copy_from_slice(&s.light_pdf);
                    light[a..b].copy_from_slice(&s.light);
                    Ok(())
                })
            })?;
            if end < n {
                chunks.update(end - start, t0.elapsed().as_secs_f64());
            }
            py.check_signals()?;
            start = end;
        }
        let out = PyDict::new(py);
        out.set_item("dirs", PyArray1::from_vec(py, dirs).reshape([n, k, 3])?)?;
        out.set_item("pdf", PyArray1::from_vec(py, pdf).reshape([n, k])?)?;
        out.set_item(
            "radiance",
            PyArray1::from_vec(py, radiance).reshape([n, k, 3])?,
        )?;
        out.set_item(
            "light_pdf",
            PyArray1::from_vec(py, light_pdf).reshape([n, k])?,
        )?;
        out.set_item("light", PyArray1::from_vec(py, light).reshape([n, k])?)?;
        Ok(out)
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
        let o = self.sampling_options(
            py,
            lights,
            device,
            temperature_mode,
            texture_filter,
            portal_mode,
        )?;
        let selection = args::parse_selection(selection)?;
        let (p_arr, n_arr) = self.sampling_rows(py, points, normals, selection)?;
        let d_arr = arrays::rows(py, dirs, "dirs", RowKind::Directions)?;
        let pts = arrays::as_vec3(&p_arr)?;
        let d = arrays::as_vec3(&d_arr)?;
        let nrm = match &n_arr {
            Some(a) => Some(arrays::as_vec3(a)?),
            None => None,
        };
        paired("points", pts.len(), "dirs", d.len())?;
        let scene = self.prepare_for(py, &o)?;
        let m = pts.len();
        let l = scene.len();
        let (acc, width) = if per_light {
            (Accumulate::PerLight, l)
        } else {
            (Accumulate::Sum, 1)
        };
        let mut out = zeros::<f32>(width.checked_mul(m))?;
        let mut chunks = Chunks::new(1 << 10, l);
        let file = self.file();
        let mut start = 0;
        while start < m {
            let end = (start + chunks.rows).min(m);
            let scene = &*scene;
            let out = &mut out;
            let t0 = Instant::now();
            py.detach(|| {
                no_panic(|| {
                    let v = scene
                        .pdf(
                            &pts[start..end],
                            nrm.map(|x| &x[start..end]),
                            &d[start..end],
                            selection,
                            acc,
                        )
                        .map_err(|e| errors::lux(e, Some(file)))?;
                    let c = end - start;
                    for li in 0..width {
                        out[li * m + start..li * m + end].copy_from_slice(&v[li * c..(li + 1) * c]);
                    }
                    Ok(())
                })
            })?;
            if end < m {
                chunks.update(end - start, t0.elapsed().as_secs_f64());
            }
            py.check_signals()?;
            start = end;
        }
        let shape: Vec<usize> = if per_light { vec![l, m] } else { vec![m] };
        Ok(PyArray1::from_vec(py, out).reshape(shape)?.into_any())
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

/// Two arrays that pair up row by row, or an `InputError` naming both and their lengths.
fn paired(a_name: &str, a: usize, b_name: &str, b: usize) -> PyResult<()> {
    if a != b {
        return Err(errors::input(format!(
            "{a_name}/{b_name}: {a} {a_name} but {b} {b_name}; they pair up row by row"
        )));
    }
    Ok(())
}
