//! `Stage.sample` and `Stage.pdf`: their rows checked and evaluated in chunks.

use luxeval::{RowKind, SampleOptions, Selection};
use numpy::prelude::*;
use numpy::{PyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::{Stage, accumulate, paired};
use crate::args::Options;
use crate::arrays;
use crate::chunks::{Chunks, zeros};
use crate::errors;

impl Stage {
    /// `sample`'s and `pdf`'s points and optional normals, checked (rows, pairing, and the
    /// normals that `selection="exact"` needs).
    #[allow(clippy::type_complexity)]
    pub(super) fn sampling_rows<'py>(
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

    /// `sample` after its arguments are parsed: `k` directions per point drawn with `opts`
    /// (`first_point` the row of `points[0]`), in chunks of about 2¹² samples.
    pub(super) fn sample_rows<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        normals: Option<&Bound<'py, PyAny>>,
        k: usize,
        opts: &SampleOptions,
        o: Options,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (p_arr, n_arr) = self.sampling_rows(py, points, normals, opts.selection)?;
        let pts = arrays::as_vec3(&p_arr)?;
        let nrm = n_arr.as_ref().map(arrays::as_vec3).transpose()?;
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
        let scene = &*scene;
        chunks.run(py, n, |start, end| {
            let opts = SampleOptions {
                seed: opts.seed,
                selection: opts.selection,
                first_point: opts.first_point + start as u64,
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
        })?;
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

    /// `pdf` after its arguments are parsed: the density of each (point, direction) pair,
    /// summed over the lights or one row per light.
    pub(super) fn pdf_rows<'py>(
        &self,
        py: Python<'py>,
        (points, dirs, normals): (
            &Bound<'py, PyAny>,
            &Bound<'py, PyAny>,
            Option<&Bound<'py, PyAny>>,
        ),
        per_light: bool,
        selection: Selection,
        o: Options,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (p_arr, n_arr) = self.sampling_rows(py, points, normals, selection)?;
        let d_arr = arrays::rows(py, dirs, "dirs", RowKind::Directions)?;
        let pts = arrays::as_vec3(&p_arr)?;
        let d = arrays::as_vec3(&d_arr)?;
        let nrm = n_arr.as_ref().map(arrays::as_vec3).transpose()?;
        paired("points", pts.len(), "dirs", d.len())?;
        let scene = self.prepare_for(py, &o)?;
        let m = pts.len();
        let l = scene.len();
        let (acc, width) = accumulate(per_light, l);
        let mut out = zeros::<f32>(width.checked_mul(m))?;
        let mut chunks = Chunks::new(1 << 10, l);
        let file = self.file();
        let scene = &*scene;
        chunks.run(py, m, |start, end| {
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
        })?;
        let shape: Vec<usize> = if per_light { vec![l, m] } else { vec![m] };
        Ok(PyArray1::from_vec(py, out).reshape(shape)?.into_any())
    }
}
