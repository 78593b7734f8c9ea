//! Query inputs: anything NumPy reads as an (N, 3) array of real numbers, as C-contiguous
//! float32 rows. A C-contiguous float32 array is used in place (no copy); any other float or
//! integer dtype, or Fortran order, is converted once by NumPy.

use numpy::prelude::*;
use numpy::{PyArray2, PyReadonlyArray2};
use pyo3::intern;
use pyo3::prelude::*;

use luxeval::{RowKind, RowProblem};

use crate::errors;

/// `obj` as a C-contiguous float32 (N, 3) array; `name` is the Python argument, used in errors.
pub fn rows<'py>(
    py: Python<'py>,
    obj: &Bound<'py, PyAny>,
    name: &str,
    kind: RowKind,
) -> PyResult<PyReadonlyArray2<'py, f32>> {
    let np = py.import(intern!(py, "numpy"))?;
    let arr = np
        .call_method1(intern!(py, "asarray"), (obj,))
        .map_err(|e| {
            errors::input(format!(
                "{name}: cannot be read as an array: {}",
                e.value(py)
            ))
        })?;
    let dtype = arr.getattr(intern!(py, "dtype"))?;
    let dkind: String = dtype.getattr(intern!(py, "kind"))?.extract()?;
    if !matches!(dkind.as_str(), "f" | "i" | "u") {
        return Err(errors::input(format!(
            "{name}: dtype {} is not a real number type; expected an (N, 3) array of floats",
            dtype.str()?
        )));
    }
    let shape: Vec<usize> = arr.getattr(intern!(py, "shape"))?.extract()?;
    if shape.len() != 2 || shape[1] != 3 {
        return Err(errors::input(format!(
            "{name}: shape {}; expected (N, 3)",
            shape_str(&shape)
        )));
    }
    // `arr` itself when it is already C-contiguous, aligned float32 (no copy); else one copy
    // (an array unpickled from a buffer may be misaligned). Values beyond float32's range become
    // ±inf, reported below, without NumPy's overflow warning.
    let quiet = pyo3::types::PyDict::new(py);
    quiet.set_item(intern!(py, "over"), intern!(py, "ignore"))?;
    let errstate = np
        .getattr(intern!(py, "errstate"))?
        .call((), Some(&quiet))?;
    errstate.call_method0(intern!(py, "__enter__"))?;
    let f32s = np.call_method1(
        intern!(py, "require"),
        (
            &arr,
            np.getattr(intern!(py, "float32"))?,
            (intern!(py, "C"), intern!(py, "A")),
        ),
    );
    errstate.call_method1(intern!(py, "__exit__"), (py.None(), py.None(), py.None()))?;
    let f32s = f32s?;
    let f32s = f32s
        .cast_into::<PyArray2<f32>>()
        .map_err(|e| errors::input(format!("{name}: {e}")))?;
    let ro = f32s.readonly();
    let data = as_vec3(&ro)?;
    // The library's one rule for input rows (luxeval::RowKind), its message with the row's
    // values as Python writes them.
    if let Err(mut bad) = py.detach(|| kind.check_f32(0, data)) {
        let row = arr.get_item(bad.row as usize)?;
        let finite: bool = np
            .call_method1(intern!(py, "isfinite"), (&row,))?
            .call_method0(intern!(py, "all"))?
            .extract()?;
        if bad.problem == RowProblem::NotFinite && finite {
            // Finite as given, infinite once rounded to float32.
            bad.problem = RowProblem::OutsideFloat32;
        }
        bad.values = row.call_method0(intern!(py, "tolist"))?.str()?.to_string();
        return Err(errors::input(format!("{name}: {bad}")));
    }
    Ok(ro)
}

/// The rows of a C-contiguous float32 (N, 3) array.
pub fn as_vec3<'a>(a: &'a PyReadonlyArray2<'_, f32>) -> PyResult<&'a [[f32; 3]]> {
    let flat = a
        .as_slice()
        .map_err(|e| errors::input(format!("array is not contiguous: {e}")))?;
    let (rows, rest) = flat.as_chunks::<3>();
    debug_assert!(rest.is_empty());
    Ok(rows)
}

pub fn shape_str(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(|d| d.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}
