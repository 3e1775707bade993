//! A scenario's engine held between calls, for driving a run step by step
//! from a script (the Python bindings): build MD or DSMC from a scenario,
//! advance in stretches, read the state as arrays in id order, set
//! positions and velocities, record thermo rows, report the summary, save
//! and resume checkpoints.
//!
//! The engine is the one `grains run` builds ([`build_md`], the DSMC
//! runner's `build`), advanced with the same calls, so `n` steps here give
//! the bits of `grains run --steps n`. Output files, `[hopper]` recycling,
//! `run.events` and the `measure` tables belong to the runner and are not
//! run here (see [`Session::new`]), except `[measure.fields]`: its windows
//! are sampled at the run's steps, so a session's fields are those
//! `grains run` writes ([`Session::fields_window`]).

mod dsmc_engine;
mod held;
mod md_engine;

use held::Held;
pub use held::{Column, Contacts};

use crate::dim::Dim;
use crate::dsmc::collide::GasDim;
use crate::error::{Error, Result};
use crate::measure::fields::{Fields, FieldsMeasure};
use crate::runner::choose::{choose, Runs};
use crate::runner::saved::{self, Opened};
use crate::scenario::Loaded;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// A scenario's engine, its thermo table, and its run plan.
pub struct Session {
    loaded: Loaded,
    engine: Box<dyn Held>,
    /// The scenario's (relaxation, measured) steps.
    plan: (u64, u64),
    output_every: u64,
    rows: Vec<Vec<f64>>,
    last_row: Option<u64>,
    /// Steps taken and wall time spent by this session's `advance` calls.
    stepped: u64,
    wall_seconds: f64,
    /// Seconds per step, as last measured (sizes the stretches).
    step_seconds: f64,
    /// `[measure.fields]`, begun at the end of the relaxation as the
    /// runner begins it (or at the first step after it a session holds).
    fields: Option<FieldsMeasure>,
}

impl Session {
    /// Builds the engine of a scenario (MD or DSMC, 2D or 3D) at step 0.
    /// Refuses `[hopper]` and `run.events`, which act between the runner's
    /// steps and are not run here: run such scenarios whole.
    pub fn new(loaded: &Loaded) -> Result<Self> {
        runner_only(loaded)?;
        struct Build<'a>(&'a Loaded);
        impl Runs for Build<'_> {
            type Out = Result<(Box<dyn Held>, (u64, u64), u64)>;
            fn md<D: Dim>(self) -> Self::Out {
                md_engine::build::<D>(self.0)
            }
            fn gas<D: GasDim>(self) -> Self::Out {
                dsmc_engine::build::<D>(self.0)
            }
        }
        let (engine, plan, every) = choose(&loaded.scenario, Build(loaded))?;
        Self::around(loaded.clone(), engine, plan, every)
    }

    fn around(loaded: Loaded, engine: Box<dyn Held>, plan: (u64, u64), every: u64) -> Result<Self> {
        let mut me = Self {
            loaded,
            engine,
            plan,
            output_every: every.max(1),
            rows: Vec::new(),
            last_row: None,
            stepped: 0,
            wall_seconds: 0.0,
            step_seconds: 0.0,
            fields: None,
        };
        me.record(false);
        me.measure_fields()?;
        Ok(me)
    }

    /// Resumes a session from a checkpoint file written by
    /// [`Session::save_checkpoint`] or by `grains run --checkpoint-every`
    /// (or the newest valid one of a run directory).
    pub fn resume(path: &Path) -> Result<Self> {
        Self::from_checkpoint(path, &[], false)
    }

    /// [`Session::resume`] under the checkpoint's scenario changed by `sets`
    /// (`KEY=VALUE`; a restart, refused by key when a change would not
    /// leave the state meaningful). The files the scenario read must be as
    /// they were, unless `allow_changed_inputs`.
    pub fn from_checkpoint(
        path: &Path,
        sets: &[String],
        allow_changed_inputs: bool,
    ) -> Result<Self> {
        let opened = Opened::open(path, sets, allow_changed_inputs)?;
        let loaded = opened.loaded().clone();
        runner_only(&loaded)?;
        struct Restore<'a>(&'a Opened);
        impl Runs for Restore<'_> {
            type Out = Result<(Box<dyn Held>, u64)>;
            fn md<D: Dim>(self) -> Self::Out {
                md_engine::restore::<D>(self.0)
            }
            fn gas<D: GasDim>(self) -> Self::Out {
                dsmc_engine::restore::<D>(self.0)
            }
        }
        let (engine, every) = choose(&loaded.scenario, Restore(&opened))?;
        Self::around(loaded, engine, opened.plan(), every)
    }

    /// The scenario the session runs.
    pub fn loaded(&self) -> &Loaded {
        &self.loaded
    }
    pub fn dim(&self) -> usize {
        self.engine.engine().dim()
    }
    /// Number of grains (particles, for DSMC).
    pub fn len(&self) -> usize {
        self.engine.len()
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    pub fn step(&self) -> u64 {
        self.engine.engine().step_count()
    }
    pub fn time(&self) -> f64 {
        self.engine.engine().sim_time()
    }
    pub fn dt(&self) -> f64 {
        self.engine.engine().time_step()
    }
    /// Whether the engine is DSMC.
    pub fn is_dsmc(&self) -> bool {
        self.loaded.scenario.method == crate::dsmc::Method::Dsmc
    }
    /// Steps of the scenario's whole run (relaxation and measurement).
    pub fn planned_steps(&self) -> u64 {
        self.plan.0 + self.plan.1
    }
    /// Steps between thermo rows.
    pub fn output_every(&self) -> u64 {
        self.output_every
    }

    /// Advances up to `steps` steps, returning once they are done or once
    /// `budget` of wall time has passed (at the end of a stretch, at least
    /// one step): the number taken. Stretches end at the steps that record
    /// a thermo row (multiples of the output interval), and at the end.
    /// Every step is complete when this returns, even on error.
    pub fn advance_for(&mut self, steps: u64, budget: Duration) -> Result<u64> {
        let started = Instant::now();
        let mut done = 0;
        while done < steps {
            let left = budget.saturating_sub(started.elapsed()).as_secs_f64();
            if done > 0 && left <= 0.0 {
                break;
            }
            // As many steps as fit the time left, judged from the last
            // stretch; the first stretch of a call is one step when the
            // speed is unknown.
            let fit = if self.step_seconds > 0.0 {
                (left / self.step_seconds).clamp(1.0, 1e9) as u64
            } else {
                1
            };
            let step = self.step();
            let to_row = self.output_every - step % self.output_every;
            let to_fields = self.fields_next().map_or(u64::MAX, |s| s - step);
            let n = fit.min(to_row).min(to_fields).min(steps - done).max(1);
            let t0 = Instant::now();
            let engine = self.engine.engine_mut();
            let r = crate::parallel::on_pool(|| engine.advance(n));
            let secs = t0.elapsed().as_secs_f64();
            self.wall_seconds += secs;
            self.stepped += n;
            self.step_seconds = secs / n as f64;
            r?;
            done += n;
            self.measure_fields()?;
            if self.step().is_multiple_of(self.output_every) || done == steps {
                self.record(true);
            }
        }
        Ok(done)
    }

    /// Advances `steps` steps (see [`Session::advance_for`]).
    pub fn advance(&mut self, steps: u64) -> Result<()> {
        self.advance_for(steps, Duration::MAX).map(|_| ())
    }

    /// A thermo row for the step now, unless it has one; `sampled`: the
    /// engine's output hook runs too (not at a session's first row, where
    /// the build or the checkpoint left it as the runner does).
    fn record(&mut self, sampled: bool) {
        let step = self.step();
        if self.last_row != Some(step) {
            self.last_row = Some(step);
            self.rows.push(self.engine.thermo_row());
            if sampled {
                self.engine.after_output();
            }
        }
    }

    /// The thermo table's columns (those of thermo.csv).
    pub fn thermo_columns(&self) -> &'static [&'static str] {
        self.engine.thermo_columns()
    }
    /// The thermo rows recorded so far: at the start, at every multiple of
    /// the output interval, and at the end of each [`Session::advance`].
    pub fn thermo_rows(&self) -> &[Vec<f64>] {
        &self.rows
    }

    pub fn ids(&self) -> Vec<u64> {
        self.engine.ids()
    }
    /// Writes a column of every grain, in id order, into `out` (a caller's
    /// buffer: a large array is best allocated where it will live).
    pub fn fill(&self, col: Column, out: &mut [f64]) -> Result<()> {
        let want = self.len() * col.width(self.dim());
        if out.len() != want {
            return Err(Error::input(format!(
                "{col:?}: a buffer of {} numbers for {want}",
                out.len()
            )));
        }
        self.engine.fill(col, out);
        Ok(())
    }
    /// A column of every grain, flat, in id order.
    pub fn column(&self, col: Column) -> Vec<f64> {
        let mut out = vec![0.0; self.len() * col.width(self.dim())];
        self.engine.fill(col, &mut out);
        out
    }
    pub fn positions(&self) -> Vec<f64> {
        self.column(Column::Positions)
    }
    pub fn velocities(&self) -> Vec<f64> {
        self.column(Column::Velocities)
    }
    pub fn frozen(&self) -> Vec<bool> {
        self.engine.frozen()
    }
    /// Replaces positions and/or velocities (flat, `dim` numbers per
    /// grain, in id order); the engine restarts from that state (see
    /// [`crate::md::Md::set_state`]).
    pub fn set_state(&mut self, pos: Option<&[f64]>, vel: Option<&[f64]>) -> Result<()> {
        let want = self.len() * self.dim();
        for (what, v) in [("positions", pos), ("velocities", vel)] {
            if let Some(v) = v {
                if v.len() != want {
                    return Err(Error::input(format!(
                        "{what}: {} numbers given; {} grains in {}D need {want} (shape ({}, {}))",
                        v.len(),
                        self.len(),
                        self.dim(),
                        self.len(),
                        self.dim()
                    )));
                }
            }
        }
        self.engine.set_state(pos, vel)
    }
    pub fn kinetic_energy(&self) -> f64 {
        self.engine.kinetic_energy()
    }
    pub fn rotational_energy(&self) -> f64 {
        self.engine.rotational_energy()
    }
    pub fn granular_temperature(&self) -> f64 {
        self.engine.granular_temperature()
    }
    /// The grain–grain contacts now (MD only).
    pub fn contacts(&self) -> Result<Contacts> {
        self.engine.contacts()
    }

    /// The rigid bodies (clumps) now, numbered from 1 as in bodies.csv;
    /// empty without clumps.
    pub fn body_rows(&self) -> Vec<crate::io::BodyRow> {
        self.engine.body_rows()
    }

    /// The next step after now at which the fields begin or may sample.
    fn fields_next(&self) -> Option<u64> {
        self.loaded.scenario.measure.fields.as_ref()?;
        let step = self.step();
        match &self.fields {
            Some(f) => Some(f.next_due(step)),
            None if step < self.plan.0 && !self.is_dsmc() => Some(self.plan.0),
            None => None,
        }
    }

    /// `[measure.fields]` at the step now, as the runner's measurement
    /// does: begun once the relaxation is over, then a sample at each of
    /// its steps after the beginning (`every`, from `start` on).
    fn measure_fields(&mut self) -> Result<()> {
        let Some(spec) = &self.loaded.scenario.measure.fields else {
            return Ok(());
        };
        let (step, t) = (self.step(), self.time());
        match &mut self.fields {
            Some(f) if step > f.begun() && f.wants(step, t) => {
                if let Some(s) = self.engine.snapshot() {
                    f.sample(&s);
                }
            }
            Some(_) => {}
            None if step >= self.plan.0 => {
                if let Some(s) = self.engine.snapshot() {
                    let d0 = self.loaded.scenario.particles.d0;
                    let bx = (s.lo, s.hi, s.periodic);
                    self.fields = Some(FieldsMeasure::begin(spec, d0, s.dim, bx)?.begun_at(step));
                }
            }
            None => {}
        }
        Ok(())
    }

    /// Windows of `[measure.fields]` with samples so far (closed and open);
    /// `None` when the scenario has no such table or the engine is DSMC.
    pub fn field_windows(&self) -> Option<usize> {
        if self.loaded.scenario.measure.fields.is_none() || self.is_dsmc() {
            return None;
        }
        Some(self.fields.as_ref().map_or(0, FieldsMeasure::window_count))
    }

    /// The time-averaged fields of window `k` (0 the first), as `grains
    /// run` writes them to `fields/fields_0000k.*`.
    pub fn fields_window(&self, k: usize) -> Option<Fields> {
        self.fields.as_ref()?.window(k)
    }

    /// The summary.json of a run that stopped here: what ran, the timing of
    /// this session's steps, the final energies (measurement scalars are
    /// the runner's and absent).
    pub fn summary(&self) -> Value {
        Value::Object(
            self.engine
                .summary(&self.loaded, self.stepped, self.wall_seconds),
        )
    }

    /// Writes a checkpoint of the engine to `path` (atomically), in the
    /// format of `grains run --checkpoint-every`, which
    /// [`Session::resume`] reads back to continue bit for bit.
    pub fn save_checkpoint(&self, path: &Path) -> Result<PathBuf> {
        let measurements = self.engine.measurements();
        let engine = self.engine.engine();
        saved::save(
            path,
            &self.loaded,
            self.plan,
            engine,
            measurements.as_deref(),
        )
    }
}

/// Refuses a scenario with `[hopper]`, `run.events` or `[[inlets]]`, which
/// act between the runner's steps and are not run by a session.
fn runner_only(loaded: &Loaded) -> Result<()> {
    let s = &loaded.scenario;
    if s.hopper.is_some() || s.run.events.is_some() || !s.inlets.is_empty() {
        return Err(Error::input(format!(
            "{}: [hopper] recycling, run.events and [[inlets]] act inside the scenario runner; \
             run this scenario with `grains run` (grains.run in Python)",
            loaded.origin
        )));
    }
    Ok(())
}

/// The output directory `grains run` picks for a scenario named `name`:
/// `runs/<name>` with the name made one harmless path component (no
/// separators, no leading dots).
pub fn default_out_dir(name: &str) -> PathBuf {
    let cleaned: String = name
        .chars()
        .map(|c| match c.is_alphanumeric() || "-_.".contains(c) {
            true => c,
            false => '_',
        })
        .collect();
    let cleaned = cleaned.trim_start_matches('.');
    Path::new("runs").join(match cleaned.is_empty() {
        true => "run",
        false => cleaned,
    })
}
