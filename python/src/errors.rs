//! The exceptions of the package, and how library errors become them.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use luxeval::LuxError;
use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyRuntimeWarning, PyValueError};
use pyo3::prelude::*;

create_exception!(
    luxeval,
    InputError,
    PyValueError,
    "Bad input: an unreadable or malformed stage, an attribute luxeval cannot evaluate, an array of \
the wrong shape or with non-finite values, a bad argument. The message names the file, the prim \
and the attribute, or the argument."
);

create_exception!(
    luxeval,
    DeviceError,
    PyRuntimeError,
    "A run-time failure: no GPU adapter with device=\"gpu\", a device that could not be opened or \
was lost, a failed GPU computation."
);

create_exception!(
    luxeval,
    DeviceWarning,
    PyRuntimeWarning,
    "Issued once per process when device=\"auto\" finds no GPU adapter and falls back to the CPU \
reference."
);

/// A library error as the exception its kind calls for; `file` (the stage) prefixes errors about
/// its lights, as the command line does.
pub fn lux(e: LuxError, file: Option<&Path>) -> PyErr {
    let message = match (&e, file) {
        // The library names the command-line option; Python callers pass an argument.
        (LuxError::InvalidInput { what, reason }, _) if what == "--light" => {
            format!("lights: {reason}")
        }
        (
            LuxError::InvalidAttribute { .. }
            | LuxError::InvalidTransform { .. }
            | LuxError::InvalidInput { .. },
            Some(f),
        ) => format!("{}: {e}", f.display()),
        _ => e.to_string(),
    };
    if e.is_bad_input() {
        InputError::new_err(message)
    } else {
        DeviceError::new_err(message)
    }
}

/// Warns with the warning class `W` (`UserWarning`, `DeviceWarning`), attributed to the
/// caller of the luxeval method (stack level 2). A NUL in the message (from a file name) is
/// replaced so that it can be given to Python.
pub fn warn<W: pyo3::PyTypeInfo>(py: Python<'_>, message: &str) -> PyResult<()> {
    let msg = std::ffi::CString::new(message.replace('\0', " ")).expect("NULs replaced above");
    PyErr::warn(py, &py.get_type::<W>(), &msg, 2)
}

pub fn input(message: impl Into<String>) -> PyErr {
    InputError::new_err(message.into())
}

/// Runs `f`, turning a panic into a `DeviceError` that says it is a bug (a panic must never reach
/// Python as `PanicException`, which `except Exception` does not catch).
pub fn no_panic<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            Err(DeviceError::new_err(format!(
                "luxeval internal error (a bug; please report it): {what}"
            )))
        }
    }
}
