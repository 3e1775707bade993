//! `grains.run` and `grains.sweep`: whole runs exactly as the command line
//! makes them (output directory, files, summary.json), in a thread of
//! their own while Python keeps answering Ctrl-C.

use crate::errors::{guard, internal, InputError};
use crate::scenario::{scenario_arg, sets_arg, toml_value};
use crate::simulation::pool;
use grains::runner::{self, RunOptions, Silent};
use grains::scenario::sweep::{grid, variant_name, variant_sets};
use grains::scenario::{self, Loaded};
use grains::session::default_out_dir;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString};
use serde_json::Value;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{mpsc, Arc, Mutex};
use std::time::Duration;

/// The scenario to run: a `Scenario`, a path, or None (the built-in
/// default, seed 002 Fig. 2), with the overrides.
fn loaded_arg(scenario: Option<&Bound<'_, PyAny>>, sets: Vec<String>) -> PyResult<Loaded> {
    match scenario.filter(|s| !s.is_none()) {
        Some(s) => scenario_arg(s, sets).map(|s| s.loaded),
        None => guard(|| scenario::load_default(&sets)),
    }
}

/// Waits for `rx` while answering Python's signals: on Ctrl-C the run is
/// asked to stop (`stop`), waited for, and the `KeyboardInterrupt` raised.
fn wait<T: Send>(py: Python<'_>, mut rx: mpsc::Receiver<T>, stop: &AtomicBool) -> PyResult<T> {
    loop {
        // A unique borrow crosses to the detached closure (a receiver is
        // Send but not Sync).
        let r = &mut rx;
        match py.detach(move || r.recv_timeout(Duration::from_millis(100))) {
            Ok(r) => return Ok(r),
            Err(mpsc::RecvTimeoutError::Timeout) => {
                if let Err(e) = py.check_signals() {
                    stop.store(true, Ordering::SeqCst);
                    // The run writes its checkpoint and returns at the end
                    // of its stretch of steps.
                    let r = &mut rx;
                    let _ = py.detach(move || r.recv());
                    return Err(e);
                }
            }
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                return Err(internal(Box::new(
                    "the run's thread ended without a result",
                )))
            }
        }
    }
}

/// A run's result with a panic caught.
type Outcome = std::thread::Result<grains::Result<Value>>;

/// Runs a scenario exactly as `grains run` does (the same engine, files
/// and summary.json) and returns its summary as a dict. `scenario`: a
/// `Scenario`, a path, or None for the built-in default; `out`: the output
/// directory (default `runs/<name>`, or `runs/<name>-2`, … when that one
/// holds an earlier run); `overwrite`: replace the run in `out` (without
/// it, an `out` that holds another run raises InputError); `set`: overrides (a dict or
/// "KEY=VALUE" strings); `steps`: run this many steps instead of the
/// scenario's length; `checkpoint_every`: as `--checkpoint-every` ("0.01",
/// "500steps"). On Ctrl-C the run stops with a checkpoint, as `grains run`
/// does, and `KeyboardInterrupt` is raised.
#[pyfunction]
#[pyo3(signature = (scenario=None, out=None, set=None, steps=None, threads=None, quiet=true, checkpoint_every=None, overwrite=false))]
#[allow(clippy::too_many_arguments)] // the keyword arguments of `grains run`
pub fn run<'py>(
    py: Python<'py>,
    scenario: Option<&Bound<'py, PyAny>>,
    out: Option<PathBuf>,
    set: Option<&Bound<'py, PyAny>>,
    steps: Option<u64>,
    threads: Option<usize>,
    quiet: bool,
    checkpoint_every: Option<String>,
    overwrite: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let loaded = loaded_arg(scenario, sets_arg(set)?)?;
    if steps == Some(0) {
        return Err(InputError::new_err("steps must be at least 1"));
    }
    let every = guard(|| {
        checkpoint_every
            .as_deref()
            .map(runner::checkpointing::Every::parse)
            .transpose()
    })?;
    let from_file = Some(loaded.scenario.run.threads).filter(|&n| n > 0);
    let pool = pool(threads.or(from_file))?;
    let out_dir =
        out.unwrap_or_else(|| grains::run_dir::fresh(&default_out_dir(&loaded.scenario.name)));
    // Refused here, before the run's thread starts, as an InputError.
    guard(|| grains::run_dir::claim(&out_dir, overwrite))?;
    let stop = Arc::new(AtomicBool::new(false));
    let opts = RunOptions {
        out_dir: out_dir.clone(),
        steps,
        checkpoint_every: every,
        stop: Some(Arc::clone(&stop)),
        overwrite,
    };
    if !quiet {
        eprintln!("grains: running {} -> {}", loaded.origin, out_dir.display());
    }
    let (tx, rx) = mpsc::channel::<Outcome>();
    std::thread::spawn(move || {
        let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            pool.install(|| runner::run(&loaded, &opts, &mut Silent))
        }));
        let _ = tx.send(r);
    });
    let summary = match wait(py, rx, &stop)? {
        Ok(r) => guard(|| r)?,
        Err(p) => return Err(internal(p)),
    };
    if !quiet {
        eprintln!("grains: wrote {}", out_dir.display());
    }
    crate::json_to_py(py, &summary)
}

/// One value of a varied key as the text `--vary` would give.
fn value_text(v: &Bound<'_, PyAny>, key: &str) -> PyResult<String> {
    if v.is_instance_of::<PyString>() {
        return v.extract();
    }
    Ok(toml_value(v, key)?.to_string())
}

/// Runs a grid of variants of one scenario exactly as `grains sweep` does
/// (each in `out/<key=value_...>`, default out `runs/<name>-sweep`), `jobs`
/// at a time. `vary`: {key: [values]} (the grid is their product, the
/// first key slowest; "k1+k2" gives several keys the same value); `set`:
/// fixed overrides. Returns one dict per variant, in grid order: `values`
/// ({key: value}), `dir`, `summary` (the summary.json dict, None when it
/// failed) and `error` (the message, None when it ran). Every variant is
/// loaded first, so a bad key raises `InputError` before any runs; a
/// variant's directory that holds an earlier run raises it too, unless
/// `overwrite`.
#[pyfunction]
#[pyo3(signature = (scenario, vary, set=None, out=None, steps=None, jobs=1, threads=None, quiet=true, overwrite=false))]
#[allow(clippy::too_many_arguments)] // the keyword arguments of `grains sweep`
pub fn sweep<'py>(
    py: Python<'py>,
    scenario: &Bound<'py, PyAny>,
    vary: &Bound<'py, PyDict>,
    set: Option<&Bound<'py, PyAny>>,
    out: Option<PathBuf>,
    steps: Option<u64>,
    jobs: usize,
    threads: Option<usize>,
    quiet: bool,
    overwrite: bool,
) -> PyResult<Bound<'py, PyList>> {
    if jobs == 0 {
        return Err(InputError::new_err("jobs must be at least 1"));
    }
    if steps == Some(0) {
        return Err(InputError::new_err("steps must be at least 1"));
    }
    let mut axes = Vec::new();
    let mut originals = Vec::new();
    for (k, vals) in vary.iter() {
        let key: String = k.extract()?;
        let vals: Vec<Bound<'py, PyAny>> = vals
            .extract()
            .map_err(|_| PyTypeError::new_err(format!("vary[{key:?}]: give a list of values")))?;
        if key.split('+').any(|k| k.trim().is_empty()) || vals.is_empty() {
            return Err(InputError::new_err(format!(
                "vary[{key:?}]: a key (or k1+k2) with at least one value"
            )));
        }
        let texts = vals
            .iter()
            .map(|v| value_text(v, &key))
            .collect::<PyResult<Vec<_>>>()?;
        axes.push((key, texts));
        originals.push(vals);
    }
    if axes.is_empty() {
        return Err(InputError::new_err("vary: give at least one key"));
    }
    let base = scenario_arg(scenario, Vec::new())?;
    let fixed = sets_arg(set)?;
    let variants = grid(&axes);
    let mut loaded = Vec::new();
    for vals in &variants {
        let sets = variant_sets(&fixed, &axes, vals);
        loaded.push(scenario_arg(scenario, sets).map(|s| s.loaded)?);
    }
    let out = out.unwrap_or_else(|| {
        let mut d = default_out_dir(&base.loaded.scenario.name).into_os_string();
        d.push("-sweep");
        PathBuf::from(d)
    });
    guard(|| runner::prepare(&out))?;
    let names: Vec<String> = variants.iter().map(|v| variant_name(&axes, v)).collect();
    let dirs: Vec<PathBuf> = names.iter().map(|n| out.join(n)).collect();
    guard(|| grains::run_dir::claim_all(&dirs, overwrite))?;
    if !quiet {
        eprintln!(
            "grains: sweep of {} variants of {} with {jobs} jobs -> {}",
            variants.len(),
            base.loaded.origin,
            out.display()
        );
    }
    let pool = Arc::new(pool(threads)?);
    let stop = Arc::new(AtomicBool::new(false));
    let results: Arc<Mutex<Vec<Option<Outcome>>>> =
        Arc::new(Mutex::new((0..variants.len()).map(|_| None).collect()));
    let (tx, rx) = mpsc::channel::<()>();
    let next = Arc::new(AtomicUsize::new(0));
    let work = Arc::new((loaded, names.clone(), out.clone()));
    for _ in 0..jobs.min(variants.len()) {
        let (pool, stop, results, tx, next, work) = (
            Arc::clone(&pool),
            Arc::clone(&stop),
            Arc::clone(&results),
            tx.clone(),
            Arc::clone(&next),
            Arc::clone(&work),
        );
        std::thread::spawn(move || {
            let (loaded, names, out) = &*work;
            loop {
                let k = next.fetch_add(1, Ordering::SeqCst);
                if k >= loaded.len() || stop.load(Ordering::SeqCst) {
                    break;
                }
                let opts = RunOptions {
                    out_dir: out.join(&names[k]),
                    steps,
                    stop: Some(Arc::clone(&stop)),
                    overwrite,
                    ..RunOptions::default()
                };
                let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    pool.install(|| runner::run(&loaded[k], &opts, &mut Silent))
                }));
                if !quiet {
                    match &r {
                        Ok(Ok(_)) => eprintln!("grains: done {}", names[k]),
                        Ok(Err(e)) => eprintln!("grains: variant {} failed: {e}", names[k]),
                        Err(_) => eprintln!("grains: variant {} failed", names[k]),
                    }
                }
                if let Ok(mut all) = results.lock() {
                    all[k] = Some(r);
                }
            }
            let _ = tx.send(());
        });
    }
    drop(tx);
    // Every worker sends once when it ends; the channel then disconnects.
    let all_done = {
        let (done_tx, done_rx) = mpsc::channel::<()>();
        std::thread::spawn(move || {
            while rx.recv().is_ok() {}
            let _ = done_tx.send(());
        });
        done_rx
    };
    wait(py, all_done, &stop)?;
    let results = std::mem::take(&mut *results.lock().map_err(|_| internal(Box::new("lock")))?);
    let list = PyList::empty(py);
    for (k, (vals, r)) in variants.iter().zip(results).enumerate() {
        let d = PyDict::new(py);
        let values = PyDict::new(py);
        for (a, (key, _)) in axes.iter().enumerate() {
            let i = axes[a].1.iter().position(|v| v == &vals[a]).unwrap_or(0);
            values.set_item(key, &originals[a][i])?;
        }
        d.set_item("values", values)?;
        d.set_item("dir", out.join(&names[k]))?;
        match r {
            Some(Ok(Ok(summary))) => {
                d.set_item("summary", crate::json_to_py(py, &summary)?)?;
                d.set_item("error", py.None())?;
            }
            Some(Ok(Err(e))) => {
                d.set_item("summary", py.None())?;
                d.set_item("error", e.to_string())?;
            }
            Some(Err(_)) => {
                d.set_item("summary", py.None())?;
                d.set_item("error", "grains internal error (a bug, please report it)")?;
            }
            None => {
                d.set_item("summary", py.None())?;
                d.set_item("error", "not run")?;
            }
        }
        list.append(d)?;
    }
    Ok(list)
}
