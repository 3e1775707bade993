//! An MD run on the run loop, serial or decomposed over ranks: relaxation
//! (flow events, progress, checkpoints), then the measurement (also the
//! measurements and the outputs), then the final files and summary.json.

use super::checkpointer::Checkpointer;
use super::engine::MdView;
use super::options::{prepare_fresh, Progress, RunOptions};
use super::run_loop::{
    run_to, Control, Every, Hook, Interval, Record, Recorder, Report, Saved, StopFlag,
};
use crate::dim::Dim;
use crate::error::Result;
use crate::md::Md;
use crate::measure::measurements::Measurements;
use crate::measure::wall_table::WallTable;
use crate::output::{md_summary, Outputs};
use crate::scenario::flow::FlowRun;
use crate::scenario::{build_md, Loaded, Resolved};
use serde_json::{Map, Value};
use std::time::Instant;

/// Runs an MD scenario from step 0.
pub(super) fn run_dim<D: Dim>(
    loaded: &Loaded,
    opts: &RunOptions,
    progress: &mut dyn Progress,
) -> Result<Value> {
    prepare_fresh(opts)?;
    let loaded = &*crate::scenario::hopper::expand(loaded)?;
    let start = begin::<D>(loaded, opts)?;
    run_loop(loaded, opts, start, progress)
}

/// The engine built from the scenario at step 0, the outputs created, the
/// plan of steps.
pub(super) fn begin<D: Dim>(loaded: &Loaded, opts: &RunOptions) -> Result<Start<D, Md<D>>> {
    let (mut md, resolved) = build_md::<D>(loaded)?;
    md.timing.reset();
    let outputs = Outputs::create(&opts.out_dir, &loaded.scenario.output)?;
    let plan = match opts.steps {
        Some(n) => (0, n),
        None => (resolved.relax_steps, resolved.measure_steps),
    };
    Ok(Start {
        flow: Some(FlowRun::begin(loaded, &md)?),
        engine: md,
        resolved,
        outputs: Some(outputs),
        plan,
        restored: None,
    })
}

/// Where an MD run starts: step 0, or a restored checkpoint with its
/// measurement accumulators when it lies inside the measurement. `E` is
/// the serial engine or a decomposed one; the outputs and the flow run are
/// rank 0's.
pub(super) struct Start<D: Dim, E> {
    pub engine: E,
    pub resolved: Resolved,
    pub outputs: Option<Outputs>,
    pub flow: Option<FlowRun<D>>,
    /// (relaxation, measured) steps.
    pub plan: (u64, u64),
    pub restored: Option<Measurements>,
}

impl<D: Dim, E> Start<D, E> {
    /// The same start with the engine `wrap` makes of this one.
    pub fn with_engine<F>(self, wrap: impl FnOnce(E) -> Result<F>) -> Result<Start<D, F>> {
        Ok(Start {
            engine: wrap(self.engine)?,
            resolved: self.resolved,
            outputs: self.outputs,
            flow: self.flow,
            plan: self.plan,
            restored: self.restored,
        })
    }
}

/// An MD run's output: thermo.csv, frames, dump and walls.csv.
struct MdRecord<'a> {
    walls: Option<&'a mut WallTable>,
}

impl<E: MdView> Recorder<E> for MdRecord<'_> {
    fn record(&mut self, outputs: Option<&mut Outputs>, engine: &mut E) -> Result<()> {
        engine.write_piece()?;
        if let (Some(md), Some(out)) = (engine.whole()?, outputs) {
            out.record_md(md)?;
            if let Some(w) = self.walls.as_deref_mut() {
                w.record(&md.view())?;
            }
        }
        Ok(())
    }
}

/// The run from wherever `start.engine` stands to `relax + measure` steps,
/// then the final files; on every rank of a decomposed engine alike (the
/// summary on rank 0, `Value::Null` elsewhere).
pub(super) fn run_loop<D: Dim, E: MdView<D = D>>(
    loaded: &Loaded,
    opts: &RunOptions,
    start: Start<D, E>,
    progress: &mut dyn Progress,
) -> Result<Value> {
    let Start {
        mut engine,
        resolved,
        mut outputs,
        mut flow,
        plan: (relax, measure),
        restored,
    } = start;
    let started = Instant::now();
    let first_step = engine.step_count();
    let ck = Checkpointer::new(loaded, opts, engine.time_step(), (relax, measure))?;
    if ck.interval().is_some() && first_step == 0 {
        let saved = Saved {
            outputs: outputs.as_ref().map(Outputs::state).transpose()?,
            measurements: None,
            flow: flow.as_ref().map(FlowRun::save),
        };
        ck.write(&engine, &saved)?;
    }
    let mut walls_csv = match engine.whole()? {
        Some(md) => WallTable::create(&opts.out_dir, &md.view())?,
        None => None,
    };
    let mut interval = Interval(ck.interval());
    let mut stop = StopFlag(opts.stop.clone());
    // A decomposed engine's flow events and per-step measurements act at
    // every step: rank 0 alone knows when they read the grains.
    let lockstep = engine.lockstep();
    let flow_lockstep = lockstep
        && (crate::scenario::flow::sink_height(loaded).is_some()
            || loaded.scenario.run.events.is_some());
    let m = &loaded.scenario.measure;
    // The fields sample in `Measurements::step` at their own `every`, not
    // at the sampled steps; the hook stops only at their due steps.
    let per_step = m.phases.is_some() || m.trajectories.is_some() || m.impact || m.fields.is_some();

    if relax > engine.step_count().min(relax) {
        progress.phase("relax", relax);
        let stopped = {
            let mut events = FlowHook::new(flow.as_mut(), None, flow_lockstep);
            let mut record = Record {
                outputs: outputs.as_mut(),
                at: None,
                how: MdRecord { walls: None },
            };
            let mut report = Report::new(progress, 0, relax);
            let mut hooks: [&mut dyn Hook<E>; 5] = [
                &mut events,
                &mut record,
                &mut report,
                &mut interval,
                &mut stop,
            ];
            run_to(&mut engine, relax, &mut hooks, &ck)?
        };
        if let Some(summary) = stopped {
            progress.finish();
            return Ok(summary);
        }
    }
    progress.phase("run", measure);
    // Measured steps already done: none in a straight run after relaxing,
    // some when resumed inside the measurement. A checkpoint taken during
    // the measurement carries its accumulators; one taken before it does
    // not, and they begin here as in a straight run.
    let measure_done = engine.step_count() - engine.step_count().min(relax);
    let mut measurements = match (restored, engine.whole()?) {
        (Some(m), Some(_)) => Some(m),
        (None, Some(md)) => Some(Measurements::begin(
            loaded,
            &md.view(),
            measure - measure_done,
            resolved.dt,
        )?),
        (_, None) => None,
    };
    let mut record = Record {
        outputs: outputs.as_mut(),
        at: None,
        how: MdRecord {
            walls: walls_csv.as_mut(),
        },
    };
    if measure_done == 0 {
        record.now(&mut engine)?;
    }
    // Measured step k is engine step `base + k`. Sampling more often than
    // the output keeps the displacement unwrapping safe and the convection
    // average smooth.
    let base = engine.step_count() - measure_done;
    let end = base + measure;
    let every = resolved.output_every;
    let sample = Every::new(base, (every / 10).max(1), None);
    record.at = Some(Every::new(base, every, Some(end)));
    let stopped = {
        let mut events = FlowHook::new(flow.as_mut(), Some(sample), flow_lockstep);
        let mut meas = MeasureHook {
            m: measurements.as_mut(),
            sample,
            dt: engine.time_step(),
            per_step,
            lockstep,
        };
        let mut report = Report::new(progress, base, end);
        let mut hooks: [&mut dyn Hook<E>; 6] = [
            &mut events,
            &mut meas,
            &mut record,
            &mut report,
            &mut interval,
            &mut stop,
        ];
        run_to(&mut engine, end, &mut hooks, &ck)?
    };
    if let Some(summary) = stopped {
        progress.finish();
        return Ok(summary);
    }
    progress.finish();
    let wall_seconds = started.elapsed().as_secs_f64();
    let mut extra = Map::new();
    engine.summarize(&mut extra, wall_seconds);
    let stepped = engine.step_count() - first_step;
    let (Some(md), Some(mut measurements), Some(flow), Some(mut outputs)) =
        (engine.whole()?, measurements, flow, outputs)
    else {
        return Ok(Value::Null);
    };
    measurements.sample(&md.view());
    let last = md.frame();
    outputs.finish(&last, &md.walls, measurements.displacement.as_ref())?;
    measurements.write(&opts.out_dir, &md.view(), &last)?;
    let steps = relax + measure;
    let mut summary = md_summary(loaded, md, &resolved, steps, stepped, wall_seconds);
    summary.extend(extra);
    measurements.scalars(&mut summary);
    flow.finish(&opts.out_dir, md, &mut summary)?;
    let summary = Value::Object(summary);
    outputs.write_summary(&summary)?;
    Ok(summary)
}

/// The flow events as a hook of the run loop: after the stretches that end
/// where they act (at every step when `lockstep`: rank 0 alone knows its
/// stage), and (in the measured phase) the flow measurements at every
/// sample. The flow run is rank 0's.
struct FlowHook<'a, D: Dim> {
    flow: Option<&'a mut FlowRun<D>>,
    sample: Option<Every>,
    lockstep: bool,
}

impl<'a, D: Dim> FlowHook<'a, D> {
    fn new(flow: Option<&'a mut FlowRun<D>>, sample: Option<Every>, lockstep: bool) -> Self {
        Self {
            flow,
            sample,
            lockstep,
        }
    }
}

impl<D: Dim, E: MdView<D = D>> Hook<E> for FlowHook<'_, D> {
    fn next(&self, now: u64, horizon: u64) -> u64 {
        let h = self.sample.map_or(horizon, |s| s.next(now, horizon));
        match (&self.flow, self.lockstep) {
            (_, true) => (now + 1).min(h),
            (Some(f), false) => f.next_act(now, h),
            (None, false) => h,
        }
    }
    fn act(&mut self, engine: &mut E, now: u64) -> Result<Control> {
        engine.flow_events(self.flow.as_deref_mut());
        if self.sample.is_some_and(|s| s.due(now)) {
            if let (Some(md), Some(f)) = (engine.whole()?, self.flow.as_deref_mut()) {
                f.sample(md);
            }
        }
        Ok(Control::Go)
    }
    fn pack(&self, saved: &mut Saved) -> Result<()> {
        saved.flow = self.flow.as_deref().map(FlowRun::save);
        Ok(())
    }
}

/// Runs the measurements in the measured phase: the per-step ones
/// (phases, trajectories) at the steps they read the grains (at every step
/// when `lockstep`: rank 0 alone knows which), the sampled ones every
/// `sample` steps. The accumulators are rank 0's.
struct MeasureHook<'a> {
    m: Option<&'a mut Measurements>,
    sample: Every,
    dt: f64,
    /// Whether the scenario has per-step measurements.
    per_step: bool,
    lockstep: bool,
}

impl<E: MdView> Hook<E> for MeasureHook<'_> {
    fn next(&self, now: u64, horizon: u64) -> u64 {
        let h = self.sample.next(now, horizon);
        if self.per_step && self.lockstep {
            return (now + 1).min(h);
        }
        let Some(m) = self.m.as_deref() else {
            return h;
        };
        (now + 1..h)
            .find(|&s| m.due(s, s as f64 * self.dt))
            .unwrap_or(h)
    }
    fn act(&mut self, engine: &mut E, now: u64) -> Result<Control> {
        if self.per_step {
            let t = engine.sim_time();
            let want = self.m.as_deref().is_some_and(|m| m.due(now, t));
            if let (Some(md), Some(m)) = (engine.whole_if(want)?, self.m.as_deref_mut()) {
                m.step(&md.view());
            }
        }
        if self.sample.due(now) {
            if let (Some(md), Some(m)) = (engine.whole()?, self.m.as_deref_mut()) {
                m.sample(&md.view());
            }
        }
        Ok(Control::Go)
    }
    fn pack(&self, saved: &mut Saved) -> Result<()> {
        if let Some(m) = self.m.as_deref() {
            saved.measurements = Some(m.save());
        }
        Ok(())
    }
}
