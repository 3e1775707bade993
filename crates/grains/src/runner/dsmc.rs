//! Runs a `method = "dsmc"` scenario on the phase script (`phases.rs`),
//! serial or decomposed over ranks: build, relax, measure, write
//! thermo.csv, frames, profiles.csv and summary.json.

use super::engine::GasView;
use super::options::{prepare_fresh, Progress, RunOptions};
use super::phases::{run_phases, Hooks, Out, Phases, Ran, Start};
use super::run_loop::{Control, Every, Hook, Record, Recorder, Saved};
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
use crate::settings::DsmcSpec;
use serde_json::{json, Map, Value};
use std::path::Path;

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
    let steps = opts.plan((plan.relax_steps, plan.measure_steps));
    let parts = GasPhases::new((loaded, opts), plan.output_every, None, summary);
    let start = Start::new(sim, Some(outputs), steps, parts);
    run_phases(loaded, opts, start, progress)
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
    let parts = GasPhases::new((loaded, opts), plan.output_every, m, summary);
    let start = Start::new(sim, Some(outputs), (relax, measure), parts);
    run_phases(loaded, opts, start, progress)
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

/// A DSMC run's parts of the phases: the measurement (rank 0's) and
/// summary.json's head, the run as it was built.
pub(crate) struct GasPhases<'a> {
    loaded: &'a Loaded,
    dir: &'a Path,
    ds: DsmcSpec,
    every: u64,
    m: Option<GasMeasurement>,
    summary: Map<String, Value>,
}

impl<'a> GasPhases<'a> {
    /// The parts of a run of `loaded` writing every `every` steps, with
    /// the measurement `restored` from a checkpoint inside it.
    pub fn new(
        (loaded, opts): (&'a Loaded, &'a RunOptions),
        every: u64,
        restored: Option<GasMeasurement>,
        summary: Map<String, Value>,
    ) -> Self {
        let (dir, ds, m) = (opts.out_dir.as_path(), spec(loaded), restored);
        Self {
            loaded,
            dir,
            ds,
            every,
            m,
            summary,
        }
    }
}

impl<D: GasDim, E: GasView<D = D>> Phases<E> for GasPhases<'_> {
    fn hooks<'a>(&'a mut self, _: &E, out: Out<'a>, measured: Option<(u64, u64)>) -> Hooks<'a, E> {
        let every = self.every;
        let output = measured.map(|(base, end)| Every::new(base, every, Some(end)));
        let record = Record {
            outputs: out,
            at: output,
            how: GasRows(self.m.as_ref().map_or_else(Origin::default, |m| m.origin)),
        };
        let Some((output, (base, _))) = output.zip(measured) else {
            return vec![Box::new(record)];
        };
        let profile =
            (self.ds.profile_bins > 0).then(|| Every::new(base, (every / 10).max(1), None));
        let gas = GasMeasureHook {
            m: self.m.as_mut(),
            profile,
            output,
        };
        vec![Box::new(record), Box::new(gas)]
    }
    fn begin_measure(&mut self, engine: &mut E, out: Out, _: (u64, u64)) -> Result<()> {
        if self.m.is_some() {
            return Ok(());
        }
        self.m = engine.whole().map(|sim| {
            let mut m = GasMeasurement::new(sim, &self.ds);
            // Discard the relaxation's collisions from the validity window.
            m.validity.sample(sim);
            m
        });
        engine.tallies_read();
        let origin = self.m.as_ref().map_or_else(Origin::default, |m| m.origin);
        GasRows(origin).record(out, engine)
    }
    fn finish(mut self, e: &mut E, _: Out, ran: Ran) -> Result<Option<Map<String, Value>>> {
        let mut extra = Map::new();
        e.summarize(&mut extra);
        let (Some(sim), Some(m)) = (e.whole(), self.m) else {
            return Ok(None);
        };
        let dir = self.dir;
        crate::output::finish_gas(dir, &self.loaded.scenario.output, &gas_frame(sim))?;
        if let Some(p) = &m.profiles {
            crate::io::write_atomic(&dir.join("profiles.csv"), p.csv(sim).as_bytes())?;
        }
        let ((steps, stepped, wall), n) = (ran, sim.store.len() as f64);
        let ns = 1e9 * wall / (stepped.max(1) as f64 * n);
        let summary = &mut self.summary;
        summary.remove("source");
        summary.insert("steps".into(), json!(steps));
        summary.insert("time".into(), json!(sim.time));
        summary.insert("wall_seconds".into(), json!(wall));
        summary.insert("ns_per_particle_step".into(), json!(ns));
        gas_summary(summary, sim, &m);
        summary.extend(extra);
        Ok(Some(self.summary))
    }
}
