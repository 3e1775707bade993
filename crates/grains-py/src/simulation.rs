//! `grains.Simulation`: a scenario's engine driven from Python, its state
//! as numpy arrays.

use crate::errors::{guard, internal, InputError};
use crate::progress::Bar;
use crate::scenario::scenario_arg;
use crate::scenario::sets_arg;
use grains::session::{Column, Session};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, IxDyn, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::{PyIndexError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::time::Duration;

/// Longest stretch of steps between two looks at Python's signal handlers
/// (Ctrl-C): the GIL is re-taken at least this often during `run`.
const SIGNAL_CHECK: Duration = Duration::from_millis(200);

/// A thread pool of `threads` workers (None: one per core).
pub fn pool(threads: Option<usize>) -> PyResult<rayon::ThreadPool> {
    if threads == Some(0) {
        return Err(InputError::new_err("threads must be at least 1"));
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| InputError::new_err(format!("threads = {threads:?}: {e}")))
}

/// A running simulation of one scenario (MD or DSMC, 2D or 3D).
///
/// Arrays (`positions`, `velocities`, ...) are fresh copies in ascending id
/// order: changing them changes nothing in the engine; assign to
/// `positions` / `velocities` to set the state.
#[pyclass(module = "grains")]
pub struct Simulation {
    session: Session,
    pool: rayon::ThreadPool,
}

impl Simulation {
    /// Runs `f` on the simulation's thread pool with the GIL released.
    fn detached<T: Send>(
        &mut self,
        py: Python<'_>,
        f: impl FnOnce(&mut Session) -> grains::Result<T> + Send,
    ) -> PyResult<T> {
        let (pool, session) = (&self.pool, &mut self.session);
        py.detach(|| guard(|| pool.install(|| f(session))))
    }

    /// `f` on the simulation's thread pool (the arrays are gathered in
    /// parallel).
    fn pooled<T: Send>(&self, f: impl FnOnce(&Session) -> T + Send) -> T {
        let session = &self.session;
        self.pool.install(|| f(session))
    }

    /// A column of every grain as a new numpy array of shape (n,) or (n,
    /// width), filled in place: numpy's allocator backs a large array with
    /// huge pages, which spares the page faults of a fresh Rust buffer
    /// (most of the time of a 10^6-grain array).
    fn column<'py>(&self, py: Python<'py>, col: Column) -> PyResult<Bound<'py, PyAny>> {
        let n = self.session.len();
        let w = col.width(self.session.dim());
        let dims = if w == 1 { vec![n] } else { vec![n, w] };
        // SAFETY: `fill` writes every element before Python sees the array.
        let arr = unsafe { PyArrayDyn::<f64>::new(py, IxDyn(&dims), false) };
        {
            let mut rw = arr.readwrite();
            let out = rw
                .as_slice_mut()
                .map_err(|e| internal(Box::new(e.to_string())))?;
            guard(|| self.pooled(|s| s.fill(col, out)))?;
        }
        Ok(arr.into_any())
    }

    /// A float64 array of shape (n, dim) from any array-like, for a setter.
    fn state_arg(&self, what: &str, value: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
        let py = value.py();
        let np = py.import("numpy")?;
        let arr = np
            .call_method1("ascontiguousarray", (value, "float64"))
            .map_err(|e| {
                InputError::new_err(format!("{what}: not an array of numbers ({})", e.value(py)))
            })?;
        let arr = arr
            .cast::<PyArrayDyn<f64>>()
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        let (n, d) = (self.session.len(), self.session.dim());
        if arr.shape() != [n, d] {
            return Err(InputError::new_err(format!(
                "{what}: shape {:?}, but this simulation has {n} grains in {d}D: shape ({n}, {d})",
                arr.shape()
            )));
        }
        Ok(arr.readonly().as_slice()?.to_vec())
    }
}

#[pymethods]
impl Simulation {
    /// Builds the engine of a scenario (a `grains.Scenario` or the path of a
    /// scenario file) at step 0, exactly as `grains run` builds it.
    /// `threads`: worker threads (default: the scenario's `run.threads`,
    /// else one per core); results do not depend on it.
    #[new]
    #[pyo3(signature = (scenario, threads=None))]
    fn new(py: Python<'_>, scenario: &Bound<'_, PyAny>, threads: Option<usize>) -> PyResult<Self> {
        let s = scenario_arg(scenario, Vec::new())?;
        let from_file = Some(s.loaded.scenario.run.threads).filter(|&n| n > 0);
        let pool = pool(threads.or(from_file))?;
        let loaded = s.loaded;
        let session = py.detach(|| guard(|| pool.install(|| Session::new(&loaded))))?;
        Ok(Self { session, pool })
    }

    /// Continues from a checkpoint file (from `save_checkpoint`, or from
    /// `grains run --checkpoint-every`; a run directory means its newest
    /// valid checkpoint) bit for bit.
    #[staticmethod]
    #[pyo3(signature = (path, threads=None))]
    fn resume(py: Python<'_>, path: PathBuf, threads: Option<usize>) -> PyResult<Self> {
        let pool = pool(threads)?;
        let session = py.detach(|| guard(|| pool.install(|| Session::resume(&path))))?;
        Ok(Self { session, pool })
    }

    /// Continues from a checkpoint (a file, or a run directory's newest
    /// valid one) under its scenario changed by `set` (a dict or
    /// "KEY=VALUE" strings, as `grains resume DIR --set`): the contact law,
    /// materials, gravity, walls' motions, the run and outputs may change;
    /// the grains, box, walls' shapes, integrator and skin may not
    /// (`InputError` names the key). Input files (particles.file, meshes)
    /// that changed since the run read them raise `InputError` unless
    /// `allow_changed_inputs`.
    #[staticmethod]
    #[pyo3(signature = (path, set=None, threads=None, allow_changed_inputs=false))]
    fn from_checkpoint(
        py: Python<'_>,
        path: PathBuf,
        set: Option<&Bound<'_, PyAny>>,
        threads: Option<usize>,
        allow_changed_inputs: bool,
    ) -> PyResult<Self> {
        let sets = sets_arg(set)?;
        let pool = pool(threads)?;
        let session = py.detach(|| {
            guard(|| pool.install(|| Session::from_checkpoint(&path, &sets, allow_changed_inputs)))
        })?;
        Ok(Self { session, pool })
    }

    /// Advances `steps` steps, or the steps of `time` simulated seconds
    /// (rounded to whole steps), or, with neither, to the end of the
    /// scenario's run (relaxation and measurement). Releases the GIL while
    /// it computes; Ctrl-C raises `KeyboardInterrupt` within about a
    /// second, the engine left at a complete step. Raises `UnstableError`
    /// when the state blows up. With `progress=True` it draws a progress
    /// bar on `sys.stderr` (steps done, simulated time, time left), redrawn
    /// in place about five times a second and ended with a newline.
    #[pyo3(signature = (steps=None, time=None, progress=false))]
    fn run(
        &mut self,
        py: Python<'_>,
        steps: Option<i64>,
        time: Option<f64>,
        progress: bool,
    ) -> PyResult<()> {
        let n = match (steps, time) {
            (Some(_), Some(_)) => {
                return Err(InputError::new_err("run: give steps or time, not both"))
            }
            (Some(s), None) if s < 0 => {
                return Err(InputError::new_err(format!(
                    "run: steps = {s}: must be 0 or more"
                )))
            }
            (Some(s), None) => s as u64,
            (None, Some(t)) if !(t.is_finite() && t >= 0.0) => {
                return Err(InputError::new_err(format!(
                    "run: time = {t}: must be a finite number of seconds >= 0"
                )))
            }
            (None, Some(t)) => (t / self.session.dt()).round() as u64,
            (None, None) => self
                .session
                .planned_steps()
                .saturating_sub(self.session.step()),
        };
        let bar = progress.then(|| Bar::new(n));
        if let Some(b) = &bar {
            b.draw(py, 0, self.session.time())?;
        }
        let mut left = n;
        while left > 0 {
            let done = self.detached(py, |s| s.advance_for(left, SIGNAL_CHECK))?;
            left -= done;
            if let Some(b) = &bar {
                b.draw(py, n - left, self.session.time())?;
            }
            if let Err(e) = py.check_signals() {
                if let Some(b) = &bar {
                    b.end(py)?;
                }
                return Err(e);
            }
        }
        if let Some(b) = &bar {
            b.end(py)?;
        }
        Ok(())
    }

    /// Steps taken since the scenario's start.
    #[getter]
    fn step(&self) -> u64 {
        self.session.step()
    }
    /// Simulated time (s).
    #[getter]
    fn time(&self) -> f64 {
        self.session.time()
    }
    /// Time step (s).
    #[getter]
    fn dt(&self) -> f64 {
        self.session.dt()
    }
    /// 2 or 3.
    #[getter]
    fn dimension(&self) -> usize {
        self.session.dim()
    }
    /// "md" or "dsmc".
    #[getter]
    fn method(&self) -> &'static str {
        if self.session.is_dsmc() {
            "dsmc"
        } else {
            "md"
        }
    }
    /// The scenario's name.
    #[getter]
    fn name(&self) -> String {
        self.session.loaded().scenario.name.clone()
    }
    /// Number of grains (particles).
    fn __len__(&self) -> usize {
        self.session.len()
    }

    /// Grain ids, int64, shape (n,), ascending. (DSMC: places in the store.)
    #[getter]
    fn ids<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        let ids: Vec<i64> = self
            .pooled(Session::ids)
            .into_iter()
            .map(|i| i as i64)
            .collect();
        ids.into_pyarray(py).into_any()
    }
    /// Positions (m), float64, shape (n, dim), a copy in id order.
    #[getter]
    fn get_positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.column(py, Column::Positions)
    }
    /// Sets every position (array-like of shape (n, dim), id order); the
    /// engine restarts from the new state: neighbour list rebuilt, springs
    /// of pairs still touching kept, forces evaluated, integrator history
    /// set up as at a scenario's start.
    #[setter]
    fn set_positions(&mut self, py: Python<'_>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let v = self.state_arg("positions", value)?;
        self.detached(py, |s| s.set_state(Some(&v), None))
    }
    /// Velocities (m/s), float64, shape (n, dim), a copy in id order.
    #[getter]
    fn get_velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.column(py, Column::Velocities)
    }
    /// Sets every velocity (array-like of shape (n, dim), id order), as
    /// the `positions` setter does.
    #[setter]
    fn set_velocities(&mut self, py: Python<'_>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let v = self.state_arg("velocities", value)?;
        self.detached(py, |s| s.set_state(None, Some(&v)))
    }
    /// Angular velocities (rad/s), float64, a copy in id order: shape (n,)
    /// in 2D (the spin about z), (n, 3) in 3D.
    #[getter]
    fn angular_velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.column(py, Column::AngularVelocities)
    }
    /// The rigid bodies' orientations: unit quaternions (w, x, y, z) that
    /// turn each body's principal frame into space, float64, shape
    /// (bodies, 4), in body order (bodies.csv's ids 1, 2, …); (0, 4)
    /// without clumps.
    #[getter]
    fn orientations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let rows = self.session.body_rows();
        body_array(py, rows.iter().flat_map(|b| b.quat), rows.len(), 4)
    }
    /// The rigid bodies' angular momenta about their centres of mass
    /// (kg m²/s, space frame), float64, shape (bodies, 3) in 2D and 3D
    /// (in 2D only z is non-zero), in body order; (0, 3) without clumps.
    #[getter]
    fn angular_momenta<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let rows = self.session.body_rows();
        body_array(py, rows.iter().flat_map(|b| b.ang_mom), rows.len(), 3)
    }
    /// Diameters (m), float64, shape (n,), a copy in id order.
    #[getter]
    fn diameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.column(py, Column::Diameters)
    }
    /// Masses (kg), float64, shape (n,), a copy in id order.
    #[getter]
    fn masses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.column(py, Column::Masses)
    }
    /// Whether each grain is frozen in place, bool, shape (n,), id order.
    #[getter]
    fn frozen<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        self.pooled(Session::frozen).into_pyarray(py).into_any()
    }

    /// Translational kinetic energy of the mobile grains (J).
    #[getter]
    fn kinetic_energy(&self) -> f64 {
        self.session.kinetic_energy()
    }
    /// Rotational kinetic energy of the mobile grains (J).
    #[getter]
    fn rotational_energy(&self) -> f64 {
        self.session.rotational_energy()
    }
    /// Granular temperature: mean kinetic energy of the velocity
    /// fluctuations per grain and degree of freedom (J).
    #[getter]
    fn granular_temperature(&self) -> f64 {
        self.session.granular_temperature()
    }

    /// The grain–grain contacts now, as a dict of arrays: `ids` (m, 2)
    /// int64, `overlap` (m,) in m, `normal` (m, dim) unit vectors from the
    /// second grain to the first, `force` (m, dim) on the first grain in N
    /// (the law evaluated on the present state). MD only.
    fn contacts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let c = guard(|| self.session.contacts())?;
        let m = c.ids.len();
        let d = self.session.dim();
        let ids: Vec<i64> = c.ids.iter().flatten().map(|&i| i as i64).collect();
        let shape = |v: Vec<f64>, w: usize| {
            Array2::from_shape_vec((m, w), v).map_err(|e| internal(Box::new(e.to_string())))
        };
        let out = PyDict::new(py);
        let ids =
            Array2::from_shape_vec((m, 2), ids).map_err(|e| internal(Box::new(e.to_string())))?;
        out.set_item("ids", ids.into_pyarray(py))?;
        out.set_item("overlap", c.overlap.into_pyarray(py))?;
        out.set_item("normal", shape(c.normal, d)?.into_pyarray(py))?;
        out.set_item("force", shape(c.force, d)?.into_pyarray(py))?;
        Ok(out)
    }

    /// The coarse-grained fields of `[measure.fields]` (docs/fields.md)
    /// averaged over window `window` (default -1: the last, the open one
    /// if it has samples; negative counts from the end), sampled during
    /// `run` at the steps `grains run` samples them (every `every` steps
    /// after the relaxation, from `start` on), so that its values are
    /// those of `fields/fields_0000k.csv` of the same run. `None` before
    /// the first sample. The windows are not in `save_checkpoint`'s file:
    /// a resumed simulation begins new ones.
    ///
    /// A dict, G the grid's shape (`cells` along `axes`, in x, y, z
    /// order; () for the single box), d the dimension: `axes` (list of
    /// names), one 1D array of point coordinates (m) per grid axis named
    /// by it (`"z"`: shape (cells_z,)), `point_volume` (the volume each
    /// point stands for: Σ density × point_volume is the grains' mass),
    /// `samples`, `times` (first and last sampled time, s); float64
    /// arrays `density` G (kg/m^d), `packing_fraction` G, `velocity`
    /// G + (d,), `temperature` G (m²/s²), `kinetic_stress`,
    /// `contact_stress`, `stress` G + (d, d) (positive in compression),
    /// `coordination` G, `fabric` G + (d, d). Raises `InputError` when the
    /// scenario has no `[measure.fields]` (or is DSMC), `IndexError` for a
    /// window not there.
    #[pyo3(signature = (window=-1))]
    fn fields<'py>(&self, py: Python<'py>, window: i64) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(n) = self.session.field_windows() else {
            return Err(InputError::new_err(
                "fields: this scenario has no [measure.fields] table (MD only): add one, e.g. \
                 grains.Scenario.load(path).set(\"measure.fields.axes\", [\"z\"])\
                 .set(\"measure.fields.cells\", [60])",
            ));
        };
        if n == 0 {
            return Ok(None);
        }
        let k = if window < 0 {
            window + n as i64
        } else {
            window
        };
        let f = usize::try_from(k)
            .ok()
            .and_then(|k| self.session.fields_window(k))
            .ok_or_else(|| {
                PyIndexError::new_err(format!(
                    "fields: window {window}, but there are {n} (0..{n}, or -{n}..-1)"
                ))
            })?;
        crate::fields::fields_dict(py, &f).map(Some)
    }

    /// The summary of the run so far as a dict, with the keys of
    /// summary.json that describe the engine (scenario, particles, steps,
    /// time, dt, energies, timing; DSMC: the gas's diagnostics); the
    /// runner's measurement scalars are absent.
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        crate::json_to_py(py, &self.session.summary())
    }

    /// The thermo table: a row at the start, at every output interval and
    /// at the end of each `run`, with the columns of thermo.csv. A pandas
    /// DataFrame when pandas is installed, else a dict of numpy columns.
    #[getter]
    fn thermo<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let cols = PyDict::new(py);
        let rows = self.session.thermo_rows();
        for (k, name) in self.session.thermo_columns().iter().enumerate() {
            let col: Vec<f64> = rows.iter().map(|r| r[k]).collect();
            cols.set_item(*name, col.into_pyarray(py))?;
        }
        match py.import("pandas") {
            Ok(pd) => pd.call_method1("DataFrame", (cols,)),
            Err(_) => Ok(cols.into_any()),
        }
    }

    /// Writes a checkpoint of the engine to `path`; `Simulation.resume`
    /// continues from it bit for bit. Returns the path.
    fn save_checkpoint(&self, py: Python<'_>, path: PathBuf) -> PyResult<PathBuf> {
        let session = &self.session;
        py.detach(|| guard(|| session.save_checkpoint(&path)))
    }

    fn __repr__(&self) -> String {
        format!(
            "grains.Simulation({:?}, {}, {}D, {} grains, step {}, t = {:.6e} s)",
            self.session.loaded().scenario.name,
            self.method(),
            self.session.dim(),
            self.session.len(),
            self.session.step(),
            self.session.time()
        )
    }
}

/// A float64 array of shape (n, width) from `values` (row by row).
fn body_array<'py>(
    py: Python<'py>,
    values: impl Iterator<Item = f64>,
    n: usize,
    width: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let a = Array2::from_shape_vec((n, width), values.collect())
        .map_err(|e| internal(Box::new(e.to_string())))?;
    Ok(a.into_pyarray(py).into_any())
}
