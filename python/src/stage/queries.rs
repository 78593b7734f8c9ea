//! The row queries of `Stage` (emission, intensity, radiance, irradiance) and `falloff`'s map,
//! evaluated in chunks with the GIL released.

use std::time::Instant;

use luxeval::{Accumulate, FalloffPlane as Plane, RowKind};
use numpy::prelude::*;
use numpy::{PyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use super::{Query, Stage, accumulate, paired};
use crate::args::{Options, resolution, vec3};
use crate::arrays;
use crate::chunks::{Chunks, zeros};
use crate::errors::{self, no_panic};

impl Stage {
    #[allow(clippy::too_many_arguments)]
    pub(super) fn query<'py>(
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
        let (acc, width) = accumulate(per_light, l);
        let mut out = zeros::<f32>(width.checked_mul(n).and_then(|x| x.checked_mul(3)))?;
        let mut chunks = Chunks::new(
            match q {
                Query::Irradiance => 256,
                _ => 1 << 14,
            },
            l,
        );
        let file = self.file();
        let scene = &*scene;
        chunks.run(py, n, |start, end| {
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
        })?;
        if matches!(q, Query::Irradiance) {
            self.warn_host_recomputed(py, scene.host_recomputed_rows() - recomputed, width * n)?;
        }
        let shape: Vec<usize> = if per_light { vec![l, n, 3] } else { vec![n, 3] };
        Ok(PyArray1::from_vec(py, out).reshape(shape)?.into_any())
    }

    /// `falloff` after its options are parsed: the plane's pixels' irradiance, whole rows of
    /// pixels per call.
    pub(super) fn falloff_map<'py>(
        &self,
        py: Python<'py>,
        o: Options,
        (origin, u, v): (&Bound<'py, PyAny>, &Bound<'py, PyAny>, &Bound<'py, PyAny>),
        res: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
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
}
