//! The Python module `grains` (its native part, `grains._native`): drive
//! grains from scripts and notebooks with numpy arrays. See
//! `docs/python.md`.
//!
//! Everything here is a thin layer over the library: `Simulation` over
//! [`grains::session::Session`], `run` over [`grains::runner::run`]
//! (what `grains run` calls). Errors become `grains.InputError`,
//! `grains.UnstableError` or `OSError`; panics become a `RuntimeError`.

mod errors;
mod fields;
mod progress;
mod run;
mod scenario;
mod simulation;

use pyo3::prelude::*;

/// A JSON value (a summary) as Python objects, through the json module.
pub(crate) fn json_to_py<'py>(
    py: Python<'py>,
    v: &serde_json::Value,
) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(v).unwrap_or_else(|_| "null".into());
    py.import("json")?.call_method1("loads", (text,))
}

/// Panics inside [`errors::guard`] with `message`, for python/tests only
/// (not documented, not in the stubs): a bug on demand, to show that it
/// reaches Python as a `RuntimeError`. With `on_pool` the panic happens as
/// in `Simulation.run`: on a worker of a thread pool, the GIL released.
#[pyfunction]
#[pyo3(name = "_panic_for_tests", signature = (message, on_pool=false))]
fn panic_for_tests(py: Python<'_>, message: String, on_pool: bool) -> PyResult<()> {
    let fail = move || -> grains::Result<()> { panic!("{message}") };
    if !on_pool {
        return errors::guard(fail);
    }
    let pool = simulation::pool(Some(2))?;
    py.detach(|| errors::guard(|| pool.install(fail)))
}

/// Granular dynamics (soft-sphere DEM and DSMC) in 2D and 3D, driven from
/// Python: `Scenario`, `Simulation`, `run`, `sweep`.
#[pymodule(name = "_native")]
fn native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_class::<scenario::Scenario>()?;
    m.add_class::<simulation::Simulation>()?;
    m.add_function(wrap_pyfunction!(run::run, m)?)?;
    m.add_function(wrap_pyfunction!(run::sweep, m)?)?;
    m.add("InputError", py.get_type::<errors::InputError>())?;
    m.add("UnstableError", py.get_type::<errors::UnstableError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(panic_for_tests, m)?)?;
    Ok(())
}
