//! Runs a `method = "dsmc"` scenario on the run loop, serial or decomposed
//! over ranks: build, relax, measure, write thermo.csv, frames,
//! profiles.csv and summary.json.

use super::checkpointer::Checkpointer;
use super::engine::GasView;
use super::options::{prepare_fresh, Progress, RunOptions};
use super::run_loop::{
    run_to, Control, Every, Hook, Interval, Record, Recorder, Report, Saved, StopFlag,
};
use crate::checkpoint::run::Found;
use crate::codec::Dec;
use crate::dsmc::collide::GasDim;
use crate::dsmc::contract::gas_frame;
use crate::dsmc::engine::Dsmc;
use crate::engine::Engine;
use crate::error::{Error, Result};
use crate::measure::gas::{GasMeasurement, Origin};
use crate::output::Outputs;
use crate::scenario::schema::OutputSpec;
use crate::scenario::Loaded;
use serde_json::{json, Map, Value};
use std::path::Path;
use std::time::Instant;

pub use crate::measure::gas::{gas_summary, THERMO_COLUMNS};
pub use crate::scenario::dsmc::{build_dsmc as build, describe, spec, Plan};

/// Runs a DSMC scenario from step 0.
pub(super) fn run_dim<D: GasDim>(
    loaded: &Loaded,
    opts: &RunOptions,
    progress: &mut dyn Progress,
) -> Result<Value> {
    prepare_fresh(opts)?;
    let (sim, plan) = build::<D>(loaded)?;
    let summary = head(loaded, &sim, &plan);
    let outputs = gas_outputs(&opts.out_dir, &loaded.scenario.output)?;
    let steps = match opts.steps {
        Some(n) => (0, n),
        None => (plan.relax_steps, plan.measure_steps),
    };
    let start = GasStart {
        engine: sim,
        every: plan.output_every,
        plan: steps,
        outputs: Some(outputs),
        restored: None,
        summary,
    };
    run_loop(loaded, opts, start, progress)
}

/// The description of a run as it was built, summary.json's head.
pub(crate) fn head<D: GasDim>(loaded: &Loaded, sim: &Dsmc<D>, plan: &Plan) -> Map<String, Value> {
    match describe(loaded, sim, plan) {
        Value::Object(m) => m,
        _ => Map::new(),
    }
}

/// The output files of a DSMC run (thermo columns of a gas, no dump).
pub(crate) fn gas_outputs(dir: &Path, spec: &OutputSpec) -> Result<Outputs> {
    Outputs::with_columns(dir, spec, &THERMO_COLUMNS, false)
}

/// A DSMC engine restored from a checkpoint.
pub(crate) struct Restored<D: GasDim> {
    pub sim: Dsmc<D>,
    pub plan: Plan,
    /// The measurement state, when the checkpoint lies inside the measurement.
    pub measure: Option<GasMeasurement>,
    /// The description of the run as it started (before the restore).
    pub head: Map<String, Value>,
}

/// The engine of a DSMC checkpoint, with its scenario's plan.
pub(crate) fn restore<D: GasDim>(found: &Found) -> Result<Restored<D>> {
    let loaded = found.loaded();
    let origin = found.path.display().to_string();
    let (mut sim, plan) = build::<D>(loaded)?;
    let head = head(loaded, &sim, &plan);
    sim.import(&found.engine, &origin)?;
    if sim.step != found.step {
        return Err(Error::input(format!(
            "checkpoint {origin}: header step {} but engine step {}",
            found.step, sim.step
        )));
    }
    let ds = spec(loaded);
    let m = match &found.measurements {
        Some(bytes) => {
            let mut d = Dec::new(bytes);
            let m = GasMeasurement::decode(&sim, &ds, &mut d).and_then(|m| match d.remaining() {
                0 => Ok(m),
                n => Err(format!("{n} unexpected bytes after the measurements")),
            });
            Some(m.map_err(|e| Error::input(format!("checkpoint {origin}: {e}")))?)
        }
        None => None,
    };
    Ok(Restored {
        sim,
        plan,
        measure: m,
        head,
    })
}

/// Continues a DSMC run from a checkpoint read by
/// [`super::checkpointing::find`].
pub(super) fn resume_dim<D: GasDim>(
    found: &Found,
    steps: Option<u64>,
    opts: &RunOptions,
    progress: &mut dyn Progress,
) -> Result<Value> {
    let loaded = found.loaded();
    let Restored {
        sim,
        plan,
        measure: m,
        head: summary,
    } = restore::<D>(found)?;
    let (relax, measure) = found.resume_plan(sim.step, steps)?;
    let outputs = Outputs::resume(&opts.out_dir, &loaded.scenario.output, &found.outputs)?;
    let start = GasStart {
        engine: sim,
        every: plan.output_every,
        plan: (relax, measure),
        outputs: Some(outputs),
        restored: m,
        summary,
    };
    run_loop(loaded, opts, start, progress)
}

/// A DSMC run's output: a thermo row (counted from the start of the
/// measurement `origin`) and a frame.
struct GasRows(Origin);

impl<E: GasView> Recorder<E> for GasRows {
    fn record(&mut self, outputs: Option<&mut Outputs>, engine: &mut E) -> Result<()> {
        engine.write_piece()?;
        if let (Some(sim), Some(out)) = (engine.whole(), outputs) {
            out.record(&self.0.row(sim), &gas_frame(sim), |_| None)?;
        }
        Ok(())
    }
}

/// The measured phase's accumulators (rank 0's): density and temperature
/// profiles every `profile` steps, the validity window at every output
/// step.
struct GasMeasureHook<'a> {
    m: Option<&'a mut GasMeasurement>,
    profile: Option<Every>,
    output: Every,
}

impl<E: GasView> Hook<E> for GasMeasureHook<'_> {
    fn next(&self, now: u64, horizon: u64) -> u64 {
        let h = self.output.next(now, horizon);
        self.profile.map_or(h, |p| p.next(now, h))
    }
    fn act(&mut self, engine: &mut E, now: u64) -> Result<Control> {
        if self.profile.is_some_and(|at| at.due(now)) {
            if let (Some(sim), Some(m)) = (engine.whole(), self.m.as_deref_mut()) {
                if let Some(p) = &mut m.profiles {
                    p.sample(sim);
                }
            }
        }
        if self.output.due(now) {
            if let (Some(sim), Some(m)) = (engine.whole(), self.m.as_deref_mut()) {
                for w in m.validity.sample(sim) {
                    eprintln!("warning: {w}");
                }
            }
            engine.tallies_read();
        }
        Ok(Control::Go)
    }
    fn pack(&self, saved: &mut Saved) -> Result<()> {
        if let Some(m) = self.m.as_deref() {
            saved.measurements = Some(m.to_bytes());
        }
        Ok(())
    }
}

/// Where a DSMC run starts: the engine (serial, or decomposed over ranks)
/// at step 0 or restored from a checkpoint with its measurement state; the
/// outputs and the measurement are rank 0's.
pub(crate) struct GasStart<E> {
    pub engine: E,
    pub every: u64,
    /// (relaxation, measured) steps.
    pub plan: (u64, u64),
    pub outputs: Option<Outputs>,
    pub restored: Option<GasMeasurement>,
    /// summary.json's head: the run as it was built.
    pub summary: Map<String, Value>,
}

/// The run from wherever the engine stands to `relax + measure` steps, then
/// the final files; on every rank of a decomposed engine alike (the
/// summary on rank 0, `Value::Null` elsewhere).
pub(crate) fn run_loop<D: GasDim, E: GasView<D = D>>(
    loaded: &Loaded,
    opts: &RunOptions,
    start: GasStart<E>,
    progress: &mut dyn Progress,
) -> Result<Value> {
    let GasStart {
        mut engine,
        every,
        plan: (relax, measure),
        mut outputs,
        restored,
        mut summary,
    } = start;
    let ds = spec(loaded);
    let dir = &opts.out_dir;
    let started = Instant::now();
    let first_step = engine.step_count();
    let ck = Checkpointer::new(loaded, opts, engine.time_step(), (relax, measure))?;
    if ck.interval().is_some() && first_step == 0 {
        let saved = Saved {
            outputs: outputs.as_ref().map(Outputs::state).transpose()?,
            ..Saved::default()
        };
        ck.write(&engine, &saved)?;
    }
    let mut interval = Interval(ck.interval());
    let mut stop = StopFlag(opts.stop.clone());
    if relax > engine.step_count().min(relax) {
        progress.phase("relax", relax);
        let stopped = {
            let mut record = Record {
                outputs: outputs.as_mut(),
                at: None,
                how: GasRows(Origin::default()),
            };
            let mut report = Report::new(progress, 0, relax);
            let mut hooks: [&mut dyn Hook<E>; 4] =
                [&mut record, &mut report, &mut interval, &mut stop];
            run_to(&mut engine, relax, &mut hooks, &ck)?
        };
        if let Some(summary) = stopped {
            progress.finish();
            return Ok(summary);
        }
    }
    progress.phase("run", measure);
    let mut m = match restored {
        Some(m) => Some(m),
        None => {
            let mut m = engine.whole().map(|sim| {
                let mut m = GasMeasurement::new(sim, &ds);
                // Discard the relaxation's collisions from the validity window.
                m.validity.sample(sim);
                m
            });
            engine.tallies_read();
            let mut record = Record {
                outputs: outputs.as_mut(),
                at: None,
                how: GasRows(m.as_mut().map_or_else(Origin::default, |m| m.origin)),
            };
            record.now(&mut engine)?;
            m
        }
    };
    // Measured step k is engine step `relax + k`.
    let base = relax;
    let end = base + measure;
    let stopped = {
        let output = Every::new(base, every, Some(end));
        let profile = (ds.profile_bins > 0).then(|| Every::new(base, (every / 10).max(1), None));
        let mut record = Record {
            outputs: outputs.as_mut(),
            at: Some(output),
            how: GasRows(m.as_ref().map_or_else(Origin::default, |m| m.origin)),
        };
        let mut gas = GasMeasureHook {
            m: m.as_mut(),
            profile,
            output,
        };
        let mut report = Report::new(progress, base, end);
        let mut hooks: [&mut dyn Hook<E>; 5] =
            [&mut record, &mut gas, &mut report, &mut interval, &mut stop];
        run_to(&mut engine, end, &mut hooks, &ck)?
    };
    if let Some(summary) = stopped {
        progress.finish();
        return Ok(summary);
    }
    progress.finish();
    let wall = started.elapsed().as_secs_f64();
    let stepped = engine.step_count() - first_step;
    let mut extra = Map::new();
    engine.summarize(&mut extra);
    let (Some(sim), Some(m)) = (engine.whole(), m) else {
        return Ok(Value::Null);
    };
    crate::output::finish_gas(dir, &loaded.scenario.output, &gas_frame(sim))?;
    if let Some(p) = &m.profiles {
        crate::io::write_atomic(&dir.join("profiles.csv"), p.csv(sim).as_bytes())?;
    }
    let n = sim.store.len() as f64;
    let steps = relax + measure;
    summary.remove("source");
    summary.insert("steps".into(), json!(steps));
    summary.insert("time".into(), json!(sim.time));
    summary.insert("wall_seconds".into(), json!(wall));
    summary.insert(
        "ns_per_particle_step".into(),
        json!(1e9 * wall / (stepped.max(1) as f64 * n)),
    );
    gas_summary(&mut summary, sim, &m);
    summary.extend(extra);
    let summary = Value::Object(summary);
    let text = serde_json::to_string_pretty(&summary).expect("JSON values always serialize");
    crate::io::write_atomic(&dir.join("summary.json"), text.as_bytes())?;
    Ok(summary)
}
