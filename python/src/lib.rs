//! `luxeval._luxeval`: the extension module behind the Python package `luxeval` (python/luxeval).
//!
//! It mirrors the library, not the command line: a [`stage::Stage`] is a USD stage read once
//! (`luxeval::Stage`), whose queries prepare the selected lights once per (selection, device,
//! colour-temperature mode) and keep the prepared scene — pipelines, uploaded records, reusable
//! buffers — for every later call. Arrays come in as anything NumPy reads as (N, 3) real numbers
//! and go out as float32 NumPy arrays. The GIL is released while the device works, and large
//! inputs are evaluated in chunks with a signal check between chunks, so that Ctrl-C stops a long
//! call with `KeyboardInterrupt`.
//!
//! Errors: bad input (a file, a prim's attribute, an argument) raises `InputError` (a
//! `ValueError`), a device or run-time failure `DeviceError` (a `RuntimeError`); a panic inside
//! the library is turned into a `DeviceError` that says it is a bug, never a `PanicException`.

mod args;
mod arrays;
mod chunks;
mod device;
mod errors;
mod stage;

use pyo3::prelude::*;

/// Evaluate USD lights (UsdLux) on the GPU (wgpu) or on the f64 CPU reference, with NumPy arrays
/// in and out. See `luxeval.Stage`.
#[pymodule]
fn _luxeval(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_class::<stage::Stage>()?;
    m.add("InputError", py.get_type::<errors::InputError>())?;
    m.add("DeviceError", py.get_type::<errors::DeviceError>())?;
    m.add("DeviceWarning", py.get_type::<errors::DeviceWarning>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(device::device_name, m)?)?;
    Ok(())
}
