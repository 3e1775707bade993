//! The library's errors as Python exceptions, and the guard that keeps
//! every Rust panic from reaching Python.

use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};

pyo3::create_exception!(
    grains,
    InputError,
    PyValueError,
    "Bad input: a scenario key or value, an array of the wrong shape, a file that does not parse. The message names the key or the file."
);
pyo3::create_exception!(
    grains,
    UnstableError,
    PyRuntimeError,
    "The simulation became unstable (non-finite state, overlap beyond the limit); the message says why and suggests a time step."
);

/// A library error as the Python exception a user expects: `InputError`,
/// `UnstableError`, or `OSError` (with errno and file name, so Python picks
/// the subclass, e.g. `FileNotFoundError`).
pub fn to_py(e: grains::Error) -> PyErr {
    match e {
        grains::Error::Input(m) => InputError::new_err(m),
        grains::Error::Unstable(m) => UnstableError::new_err(format!("simulation unstable: {m}")),
        grains::Error::Io { path, source } => {
            let file = path.display().to_string();
            match source.raw_os_error() {
                Some(errno) => {
                    // Python adds the number and the file itself.
                    let text = source.to_string();
                    let suffix = format!(" (os error {errno})");
                    let text = text.strip_suffix(&suffix).unwrap_or(&text).to_string();
                    PyOSError::new_err((errno, text, file))
                }
                None => PyOSError::new_err(format!("{file}: {source}")),
            }
        }
    }
}

/// Runs `f`, turning a library error into its exception and a panic (a
/// bug of grains) into a `RuntimeError` that says so.
pub fn guard<T>(f: impl FnOnce() -> grains::Result<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r.map_err(to_py),
        Err(panic) => Err(internal(panic)),
    }
}

/// A caught panic as a `RuntimeError`.
pub fn internal(panic: Box<dyn std::any::Any + Send>) -> PyErr {
    let msg = panic
        .downcast_ref::<String>()
        .cloned()
        .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
        .unwrap_or_else(|| "unknown panic".into());
    PyRuntimeError::new_err(format!(
        "grains internal error (a bug, please report it): {msg}"
    ))
}
