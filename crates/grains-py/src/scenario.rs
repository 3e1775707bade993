//! `grains.Scenario`: a scenario file's text with `set` overrides, checked
//! as `grains run --set` checks them.

use crate::errors::{guard, InputError};
use grains::scenario::{self, Loaded};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use std::path::PathBuf;

/// A scenario: the TOML text of a file (or string) and the overrides set
/// on it. Every change is checked at once against the schema, exactly as
/// `grains run --set KEY=VALUE` checks it.
#[pyclass(module = "grains")]
#[derive(Clone)]
pub struct Scenario {
    text: String,
    origin: String,
    base_dir: PathBuf,
    sets: Vec<String>,
    pub loaded: Loaded,
}

impl Scenario {
    fn build(text: String, origin: String, base_dir: PathBuf, sets: Vec<String>) -> PyResult<Self> {
        let loaded = guard(|| scenario::load_str(&text, &origin, base_dir.clone(), &sets))?;
        Ok(Self {
            text,
            origin,
            base_dir,
            sets,
            loaded,
        })
    }

    /// A scenario file with `--set` overrides (`KEY=VALUE` strings).
    pub fn from_file(path: PathBuf, sets: Vec<String>) -> PyResult<Self> {
        let text =
            guard(|| std::fs::read_to_string(&path).map_err(|e| grains::Error::io(&path, e)))?;
        let base_dir = path.parent().map(PathBuf::from).unwrap_or_default();
        Self::build(text, path.display().to_string(), base_dir, sets)
    }
}

/// A Python value as TOML (number, bool, string, list, dict).
pub(crate) fn toml_value(v: &Bound<'_, PyAny>, key: &str) -> PyResult<toml::Value> {
    if v.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        return Ok(toml::Value::Integer(v.extract()?));
    }
    if v.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(v.extract()?));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(v.extract()?));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let items: Vec<Bound<'_, PyAny>> = v.extract()?;
        return items
            .iter()
            .map(|x| toml_value(x, key))
            .collect::<PyResult<_>>()
            .map(toml::Value::Array);
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let mut t = toml::Table::new();
        for (k, x) in d.iter() {
            t.insert(k.extract::<String>()?, toml_value(&x, key)?);
        }
        return Ok(toml::Value::Table(t));
    }
    // numpy scalars and other numbers
    if let Ok(x) = v.extract::<f64>() {
        return Ok(toml::Value::Float(x));
    }
    Err(PyTypeError::new_err(format!(
        "set({key:?}, ...): a {} cannot be a scenario value; use a number, bool, str, list or dict",
        v.get_type().name()?
    )))
}

#[pymethods]
impl Scenario {
    /// Reads a scenario file (TOML); relative paths in it are taken from
    /// its directory. Raises `OSError` when it cannot be read, `InputError`
    /// when it does not parse or breaks the schema.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Self> {
        Self::from_file(path, Vec::new())
    }

    /// A scenario from TOML text; relative paths in it are taken from
    /// `base_dir` (default: the current directory).
    #[staticmethod]
    #[pyo3(signature = (text, base_dir=None))]
    fn from_toml(text: String, base_dir: Option<PathBuf>) -> PyResult<Self> {
        Self::build(
            text,
            "scenario text".into(),
            base_dir.unwrap_or_else(|| PathBuf::from(".")),
            Vec::new(),
        )
    }

    /// Sets a key by its dotted path, as `--set` does
    /// (`set("contact.mu", 0.3)`, `set("walls.0.motion.frequency", 60)`);
    /// raises `InputError` naming the key when the result breaks the
    /// schema (the scenario is then unchanged). Returns the scenario.
    fn set<'py>(
        mut slf: PyRefMut<'py, Self>,
        key: &str,
        value: &Bound<'py, PyAny>,
    ) -> PyResult<PyRefMut<'py, Self>> {
        let v = toml_value(value, key)?;
        let mut sets = slf.sets.clone();
        sets.push(format!("{key}={v}"));
        let next = Self::build(
            slf.text.clone(),
            slf.origin.clone(),
            slf.base_dir.clone(),
            sets,
        )
        .map_err(|e| {
            Python::attach(|py| InputError::new_err(format!("set({key:?}): {}", e.value(py))))
        })?;
        *slf = next;
        Ok(slf)
    }

    /// The scenario, overrides applied, as TOML text (every key written
    /// out, defaults included).
    fn to_toml(&self) -> PyResult<String> {
        toml::to_string(&self.loaded.scenario)
            .map_err(|e| InputError::new_err(format!("cannot write the scenario as TOML: {e}")))
    }

    /// The scenario's name.
    #[getter]
    fn name(&self) -> String {
        self.loaded.scenario.name.clone()
    }

    /// Where the scenario came from (a file, or "scenario text").
    #[getter]
    fn origin(&self) -> String {
        self.origin.clone()
    }

    /// The overrides applied so far, as `KEY=VALUE` strings.
    #[getter]
    fn overrides(&self) -> Vec<String> {
        self.sets.clone()
    }

    fn __repr__(&self) -> String {
        format!(
            "grains.Scenario({:?} from {}, {} override(s))",
            self.loaded.scenario.name,
            self.origin,
            self.sets.len()
        )
    }
}

/// A scenario argument: a `Scenario`, or the path of a scenario file.
pub fn scenario_arg(arg: &Bound<'_, PyAny>, sets: Vec<String>) -> PyResult<Scenario> {
    if let Ok(s) = arg.extract::<PyRef<'_, Scenario>>() {
        if sets.is_empty() {
            return Ok(s.clone());
        }
        let mut all = s.sets.clone();
        all.extend(sets);
        return Scenario::build(s.text.clone(), s.origin.clone(), s.base_dir.clone(), all);
    }
    match arg.extract::<PathBuf>() {
        Ok(p) => Scenario::from_file(p, sets),
        Err(_) => Err(PyTypeError::new_err(format!(
            "expected a grains.Scenario or the path of a scenario file, not {}",
            arg.get_type().name()?
        ))),
    }
}

/// `set=`: a dict {key: value}, a list of "KEY=VALUE" strings, or one.
pub(crate) fn sets_arg(set: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<String>> {
    let Some(set) = set.filter(|s| !s.is_none()) else {
        return Ok(Vec::new());
    };
    if let Ok(d) = set.cast::<PyDict>() {
        let mut out = Vec::new();
        for (k, v) in d.iter() {
            let k: String = k.extract()?;
            out.push(format!("{k}={}", toml_value(&v, &k)?));
        }
        return Ok(out);
    }
    if set.is_instance_of::<PyString>() {
        return Ok(vec![set.extract()?]);
    }
    if set.is_instance_of::<PyList>() || set.is_instance_of::<PyTuple>() {
        return set.extract();
    }
    Err(PyTypeError::new_err(
        "set: give a dict {\"contact.mu\": 0.3} or a list of \"KEY=VALUE\" strings",
    ))
}
