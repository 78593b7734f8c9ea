//! The arguments of the queries: the options every query takes ([`Options`]), the `lights`
//! selection, and `falloff`'s vectors and resolution, checked with errors naming the argument.

use glam::DVec3;
use luxeval::{
    Accumulate, FalloffPlane as Plane, PreparedScene, Selection, TemperatureMode, TextureFilter,
};
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::PyString;

use crate::arrays;
use crate::device::{self, Device};
use crate::errors;

/// The options every query takes.
pub(crate) struct Options {
    pub(crate) select: Vec<String>,
    pub(crate) device: Device,
    pub(crate) mode: TemperatureMode,
    pub(crate) filter: TextureFilter,
    /// How domes read their portals (`--portal-mode`, DESIGN.md §8 P2).
    pub(crate) portal: luxeval::PortalMode,
    /// Irradiance's relative tolerance (`luxeval irradiance --tolerance`); not part of the
    /// prepared scene, which takes it per call.
    tolerance: Option<f64>,
}

impl Options {
    pub(crate) fn parse(
        lights: Option<&Bound<'_, PyAny>>,
        device: &str,
        mode: &str,
        filter: &str,
        portal: &str,
    ) -> PyResult<Options> {
        Ok(Options {
            select: parse_lights(lights)?,
            device: Device::parse(device)?,
            mode: device::parse_mode(mode)?,
            filter: device::parse_filter(filter)?,
            portal: device::parse_portal_mode(portal)?,
            tolerance: None,
        })
    }

    /// With irradiance's tolerance, its range checked now (the GPU's bound per call).
    pub(crate) fn with_tolerance(mut self, rel: f64) -> PyResult<Options> {
        luxeval::Evaluator::cpu()
            .with_irradiance_tolerance(rel)
            .map_err(|e| errors::lux(e, None))?;
        self.tolerance = Some(rel);
        Ok(self)
    }

    pub(crate) fn irradiance(
        &self,
        scene: &PreparedScene,
        points: &[[f32; 3]],
        normals: &[[f32; 3]],
        acc: Accumulate,
    ) -> luxeval::Result<Vec<[f32; 3]>> {
        match self.tolerance {
            Some(rel) => scene.irradiance_with_tolerance(points, normals, acc, rel),
            None => scene.irradiance(points, normals, acc),
        }
    }
}

/// `None`: every light; a str: that prim path; an iterable of str: those prim paths.
pub(crate) fn parse_lights(lights: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<String>> {
    let Some(obj) = lights else {
        return Ok(Vec::new());
    };
    if obj.is_none() {
        return Ok(Vec::new());
    }
    if obj.is_instance_of::<PyString>() {
        return Ok(vec![obj.extract::<String>()?]);
    }
    let bad = || {
        errors::input(format!(
            "lights: expected None, a prim path or a list of prim paths, got {}",
            obj.repr().map(|r| r.to_string()).unwrap_or_default()
        ))
    };
    let mut out = Vec::new();
    for item in obj.try_iter().map_err(|_| bad())? {
        out.push(item?.extract::<String>().map_err(|_| bad())?);
    }
    if out.is_empty() {
        return Err(errors::input(
            "lights: an empty list selects no light; pass None for every light",
        ));
    }
    Ok(out)
}

/// A 3-vector argument of `falloff`: three finite numbers.
pub(crate) fn vec3(py: Python<'_>, obj: &Bound<'_, PyAny>, name: &str) -> PyResult<DVec3> {
    let np = py.import(intern!(py, "numpy"))?;
    let arr = np
        .call_method1(intern!(py, "asarray"), (obj, np.getattr("float64")?))
        .map_err(|e| {
            errors::input(format!(
                "{name}: expected three numbers X, Y, Z: {}",
                e.value(py)
            ))
        })?;
    let shape: Vec<usize> = arr.getattr(intern!(py, "shape"))?.extract()?;
    if shape != [3] {
        return Err(errors::input(format!(
            "{name}: shape {}; expected three numbers X, Y, Z",
            arrays::shape_str(&shape)
        )));
    }
    let list = arr.call_method0(intern!(py, "tolist"))?;
    let v: [f64; 3] = list.extract()?;
    if v.iter().any(|c| !c.is_finite()) {
        return Err(errors::input(format!(
            "{name}: {} is not finite",
            list.str()?
        )));
    }
    Ok(DVec3::from_array(v))
}

/// `res`: (width, height) in pixels.
pub(crate) fn resolution(res: &Bound<'_, PyAny>) -> PyResult<(u32, u32)> {
    let bad = || {
        errors::input(format!(
            "res: expected (width, height), two integers ≥ 1, got {}",
            res.repr().map(|r| r.to_string()).unwrap_or_default()
        ))
    };
    let (w, h): (i64, i64) = res.extract().map_err(|_| bad())?;
    let w = u32::try_from(w).ok().filter(|w| *w >= 1).ok_or_else(bad)?;
    let h = u32::try_from(h).ok().filter(|h| *h >= 1).ok_or_else(bad)?;
    if w as u64 * h as u64 > Plane::MAX_PIXELS {
        return Err(errors::input(format!(
            "res: {w}×{h} is more than {} pixels",
            Plane::MAX_PIXELS
        )));
    }
    Ok((w, h))
}

/// The `selection=` argument of `sample` and `pdf` (the CLI's `--selection`).
pub(crate) fn parse_selection(s: &str) -> PyResult<Selection> {
    match s {
        "power" => Ok(Selection::Power),
        "bound" => Ok(Selection::Bound),
        "exact" => Ok(Selection::Exact),
        other => Err(errors::input(format!(
            "selection: {other:?} is not one of \"power\", \"bound\", \"exact\""
        ))),
    }
}

/// The most samples per point `sample` draws (the CLI's `--count` limit).
pub(crate) const MAX_COUNT: usize = 1 << 20;

/// `sample`'s `count`: from 1 to [`MAX_COUNT`].
pub(crate) fn count(count: &Bound<'_, PyAny>) -> PyResult<usize> {
    let bad = || {
        errors::input(format!(
            "count: {} is not from 1 to {MAX_COUNT} samples per point (use more seeds for more)",
            count.repr().map(|r| r.to_string()).unwrap_or_default()
        ))
    };
    let k: i64 = integer(count).ok_or_else(bad)?;
    usize::try_from(k)
        .ok()
        .filter(|k| (1..=MAX_COUNT).contains(k))
        .ok_or_else(bad)
}

/// A non-negative integer argument (`seed`: at most 2³² − 1; `first_point`: at most 2⁶³ − 1).
pub(crate) fn unsigned(obj: &Bound<'_, PyAny>, name: &str, max: u64) -> PyResult<u64> {
    integer(obj)
        .and_then(|v| u64::try_from(v).ok())
        .filter(|v| *v <= max)
        .ok_or_else(|| {
            errors::input(format!(
                "{name}: {} is not an integer from 0 to {max}",
                obj.repr().map(|r| r.to_string()).unwrap_or_default()
            ))
        })
}

/// A Python or NumPy integer (not a bool, not a float) that fits an i64.
fn integer(obj: &Bound<'_, PyAny>) -> Option<i64> {
    if obj.is_instance_of::<pyo3::types::PyBool>() || obj.is_instance_of::<pyo3::types::PyFloat>() {
        return None;
    }
    obj.call_method0(intern!(obj.py(), "__index__"))
        .ok()?
        .extract::<i64>()
        .ok()
}
