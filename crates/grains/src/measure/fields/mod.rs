//! Coarse-grained continuum fields (`[measure.fields]`, docs/fields.md):
//! density, packing fraction, velocity, granular temperature, kinetic,
//! contact and total stress, coordination and fabric on a grid, averaged
//! over time windows, after Weinhart, Thornton, Luding & Bokhove (2012)
//! and Goldhirsch (2010).
//!
//! `kernel` and `cg` read plain data ([`Snapshot`]); `adapter` builds it
//! from the engine; `write` writes the windows as VTK image data and CSV.

pub mod adapter;
pub mod cg;
pub mod kernel;
pub mod replay;
pub mod write;

pub use crate::io::contact_records::{ContactRecord, Snapshot, WallRecord};
pub use adapter::snapshot;
pub use cg::{CoarseGrainer, Fields, Grid, Smoothing};
pub use kernel::{Kernel, Shape};

use crate::codec::{Dec, DecResult, Enc};
use crate::error::{Error, Result};
use crate::scenario::schema::FieldsSpec;
use serde_json::{json, Map, Value};
use std::path::Path;

/// The fields measurement of a run: the window being summed and those done.
pub struct FieldsMeasure {
    /// What `fields.json` records for `grains cg`: the table, d0, the box
    /// and the step at which the measurement began.
    spec: FieldsSpec,
    d0: f64,
    bx: ([f64; 3], [f64; 3], [bool; 3]),
    begun: u64,
    current: CoarseGrainer,
    /// The closed windows' sums (their fields are worked out when written).
    done: Vec<CoarseGrainer>,
}

impl FieldsMeasure {
    /// Checks `spec` against a box of dimension `dim` (`lo`, `hi`,
    /// `periodic`) and grains of mean diameter `d0`.
    pub fn begin(
        spec: &FieldsSpec,
        d0: f64,
        dim: usize,
        (lo, hi, periodic): ([f64; 3], [f64; 3], [bool; 3]),
    ) -> Result<Self> {
        let names = ["x", "y", "z"];
        let mut axes: Vec<(usize, usize)> = Vec::new();
        if spec.axes.len() != spec.cells.len() {
            return Err(Error::input(format!(
                "measure.fields: axes = {:?} and cells = {:?} must have the same length (one \
                 count of points per axis)",
                spec.axes, spec.cells
            )));
        }
        for (name, &n) in spec.axes.iter().zip(&spec.cells) {
            let Some(a) = names[..dim].iter().position(|x| x == name) else {
                return Err(Error::input(format!(
                    "measure.fields.axes: \"{name}\" is not an axis of this {dim}D box; allowed: {:?}",
                    &names[..dim]
                )));
            };
            if axes.iter().any(|&(b, _)| b == a) || n == 0 {
                return Err(Error::input(format!(
                    "measure.fields: axis \"{name}\" given twice or with 0 cells"
                )));
            }
            axes.push((a, n));
        }
        // Lowest axis first: the grid's points then run x fastest, as VTK's.
        axes.sort();
        let grid = Grid {
            dim,
            axes: axes.iter().map(|a| a.0).collect(),
            cells: axes.iter().map(|a| a.1).collect(),
            lo,
            hi,
            periodic,
        };
        if !(spec.width.is_finite() && spec.width > 0.0) {
            return Err(Error::input(format!(
                "measure.fields.width = {}: must be positive (units of d0)",
                spec.width
            )));
        }
        let shape = match spec.kernel.as_str() {
            "gaussian" => Shape::Gaussian,
            "lucy" => Shape::Lucy,
            other => {
                return Err(Error::input(format!(
                    "measure.fields.kernel = \"{other}\": allowed \"gaussian\", \"lucy\""
                )))
            }
        };
        if spec.every == 0 || !spec.start.is_finite() {
            return Err(Error::input(
                "measure.fields: every must be at least 1 (steps) and start a finite time (s)",
            ));
        }
        let smoothing = match grid.axes.len() {
            0 => Smoothing::Box,
            k => Smoothing::Kernel(Kernel::new(shape, spec.width * d0, k)),
        };
        Ok(Self {
            spec: spec.clone(),
            d0,
            bx: (lo, hi, periodic),
            begun: 0,
            current: CoarseGrainer::new(grid, smoothing),
            done: Vec::new(),
        })
    }

    /// The measurement began at `step` (samples follow it).
    pub fn begun_at(mut self, step: u64) -> Self {
        self.begun = step;
        self
    }

    /// Whether the state after step `step` is sampled (at time `t`).
    pub fn due(&self, step: u64) -> bool {
        step.is_multiple_of(self.spec.every)
    }

    /// The first step after `now` at which [`Self::due`] holds.
    pub fn next_due(&self, now: u64) -> u64 {
        (now / self.spec.every + 1) * self.spec.every
    }

    /// The step the measurement began at (samples are taken after it).
    pub fn begun(&self) -> u64 {
        self.begun
    }

    /// Whether a snapshot at `step`, time `t`, is taken.
    pub fn wants(&self, step: u64, t: f64) -> bool {
        self.due(step) && t >= self.spec.start
    }

    /// Adds one instant; a full window is closed.
    pub fn sample(&mut self, s: &Snapshot) {
        self.current.add(s);
        if self.spec.average > 0 && self.current.samples() >= self.spec.average {
            let fresh =
                CoarseGrainer::new(self.current.grid.clone(), self.current.smoothing.clone());
            self.done.push(std::mem::replace(&mut self.current, fresh));
        }
    }

    /// The windows: those closed and the one open, if it has samples.
    pub fn windows(&self) -> Vec<Fields> {
        (0..self.window_count())
            .filter_map(|k| self.window(k))
            .collect()
    }

    /// How many windows [`Self::windows`] gives, without working them out.
    pub fn window_count(&self) -> usize {
        self.done.len() + usize::from(self.current.samples() > 0)
    }

    /// Window `k` of [`Self::windows`], worked out alone.
    pub fn window(&self, k: usize) -> Option<Fields> {
        match self.done.get(k) {
            Some(w) => Some(w.fields()),
            None if k == self.done.len() && self.current.samples() > 0 => {
                Some(self.current.fields())
            }
            None => None,
        }
    }

    /// The last of [`Self::windows`]: the open one if it has samples.
    fn last_window(&self) -> Option<Fields> {
        self.window(self.window_count().checked_sub(1)?)
    }

    /// The step the measurement began at, the closed windows and the open
    /// one, as checkpoint bytes.
    pub fn save(&self, e: &mut Enc) {
        e.u64(self.begun);
        e.len(self.done.len());
        self.done.iter().for_each(|w| w.save(e));
        self.current.save(e);
    }

    /// This fresh measurement with the windows saved by [`Self::save`].
    pub fn load(mut self, d: &mut Dec) -> DecResult<Self> {
        self.begun = d.u64("fields start step")?;
        let fresh =
            || CoarseGrainer::new(self.current.grid.clone(), self.current.smoothing.clone());
        let n = d.len(32, "fields windows")?;
        let mut done = Vec::with_capacity(n);
        for _ in 0..n {
            done.push(fresh().load(d)?);
        }
        self.current = fresh().load(d)?;
        self.done = done;
        Ok(self)
    }

    /// fields/fields_NNNNN.vti, fields.pvd, and for a profile or the box
    /// fields/fields_NNNNN.csv; fields.json, what `grains cg` needs to
    /// sample the run's frames again.
    pub fn write(&self, dir: &Path) -> Result<()> {
        write::write_windows(dir, &self.windows())?;
        let (lo, hi, periodic) = self.bx;
        let settings = json!({
            "fields": self.spec,
            "d0": self.d0,
            "dim": self.current.grid.dim,
            "lo": lo,
            "hi": hi,
            "periodic": periodic,
            "begin_step": self.begun,
        });
        let text = serde_json::to_string_pretty(&settings).expect("plain JSON values");
        crate::io::write_atomic(&dir.join("fields.json"), text.as_bytes())
    }

    /// The last window's means over its points, into summary.json.
    pub fn scalars(&self, summary: &mut Map<String, Value>) {
        summary.insert("fields_windows".into(), json!(self.window_count()));
        let Some(f) = self.last_window() else {
            return;
        };
        let n = f.points.len().max(1) as f64;
        let mean = |v: &dyn Fn(usize) -> f64| (0..f.points.len()).map(v).sum::<f64>() / n;
        let d = f.grid.dim;
        summary.insert("fields_samples".into(), json!(f.samples));
        summary.insert("fields_density_mean".into(), json!(mean(&|i| f.density[i])));
        summary.insert(
            "fields_packing_fraction_mean".into(),
            json!(mean(&|i| f.packing_fraction[i])),
        );
        summary.insert(
            "fields_pressure_mean".into(),
            json!(mean(
                &|i| (0..d).map(|a| f.stress[i][a][a]).sum::<f64>() / d as f64
            )),
        );
        summary.insert(
            "fields_shear_stress_mean".into(),
            json!(mean(&|i| f.stress[i][0][d - 1])),
        );
        summary.insert(
            "fields_coordination_mean".into(),
            json!(mean(&|i| f.coordination[i])),
        );
    }
}
