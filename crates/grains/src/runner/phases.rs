//! One script for the run of every engine ([`run_phases`]): the step-0
//! checkpoint, the relaxation, the measurement, the final files and
//! summary.json, with the progress, checkpoint-interval and stop hooks.
//! An engine's run gives its own parts through [`Phases`]: its hooks of
//! each phase (acting first, in its order), what it does before relaxing
//! (nothing unless it says), the measurement's beginning, the final files.

use super::checkpointer::{Checkpointer, Saved};
use super::options::{Progress, RunOptions};
use super::run_loop::{run_to, Hook, Interval, Report, StopFlag};
use crate::engine::Engine;
use crate::error::Result;
use crate::output::Outputs;
use crate::scenario::Loaded;
use serde_json::{Map, Value};
use std::time::Instant;

/// An engine's hooks of one phase, borrowing its run's parts.
pub(crate) type Hooks<'a, E> = Vec<Box<dyn Hook<E> + 'a>>;
/// The output files, rank 0's.
pub(crate) type Out<'a> = Option<&'a mut Outputs>;
/// How the run went: (steps, stepped, wall seconds), see [`Phases::finish`].
pub(crate) type Ran = (u64, u64, f64);

/// An engine's parts of the run (rank 0 holds the files and accumulators;
/// every rank calls every method at the same point of the run).
pub(crate) trait Phases<E: Engine> {
    /// Called after the step-0 checkpoint, before relaxing.
    fn begin(&mut self, _engine: &mut E) -> Result<()> {
        Ok(())
    }
    /// The hooks of the relaxation (`measured` none; their states make the
    /// step-0 checkpoint) or of the measured phase whose step k is engine
    /// step `base + k`, the last `end` (`measured`: (base, end)).
    fn hooks<'a>(&'a mut self, e: &E, out: Out<'a>, measured: Option<(u64, u64)>) -> Hooks<'a, E>;
    /// Begins the measurement of `steps` (done, measure): `done` of its
    /// steps are done when resumed inside it; records the first output.
    fn begin_measure(&mut self, e: &mut E, out: Out, steps: (u64, u64)) -> Result<()>;
    /// Writes the final files; summary.json's content on rank 0. `ran`:
    /// the run's steps, those this process advanced (a resumed run's from
    /// its restart) and the wall-clock seconds.
    fn finish(self, e: &mut E, out: Out, ran: Ran) -> Result<Option<Map<String, Value>>>;
}

/// Where a run starts: its engine at step 0 or restored from a
/// checkpoint, the output files (rank 0's), the (relaxation, measured)
/// steps and the engine's parts of the run.
pub(crate) struct Start<E, P> {
    engine: E,
    outputs: Option<Outputs>,
    plan: (u64, u64),
    parts: P,
}

impl<E, P> Start<E, P> {
    /// A start from its parts.
    pub fn new(engine: E, outputs: Option<Outputs>, plan: (u64, u64), parts: P) -> Self {
        Self {
            engine,
            outputs,
            plan,
            parts,
        }
    }

    /// The same start with the engine `wrap` makes of this one.
    pub fn with_engine<F>(self, wrap: impl FnOnce(E) -> Result<F>) -> Result<Start<F, P>> {
        let engine = wrap(self.engine)?;
        Ok(Start::new(engine, self.outputs, self.plan, self.parts))
    }
}

/// Runs the engine from wherever it stands to `relax + measure` steps
/// (its plan), then writes the final files and summary.json; on every rank
/// of a decomposed engine alike (the summary on rank 0, `Value::Null`
/// elsewhere, or an interrupted run's summary when a signal stopped it).
pub(crate) fn run_phases<E: Engine, P: Phases<E>>(
    loaded: &Loaded,
    opts: &RunOptions,
    start: Start<E, P>,
    progress: &mut dyn Progress,
) -> Result<Value> {
    let (mut engine, mut outputs, mut parts) = (start.engine, start.outputs, start.parts);
    let (relax, measure) = start.plan;
    let started = Instant::now();
    let first_step = engine.step_count();
    let ck = Checkpointer::new(loaded, opts, engine.time_step(), (relax, measure))?;
    if ck.interval().is_some() && first_step == 0 {
        let mut saved = Saved::default();
        for hook in parts.hooks(&engine, outputs.as_mut(), None) {
            hook.pack(&mut saved)?;
        }
        ck.write(&engine, &saved)?;
    }
    parts.begin(&mut engine)?;
    let mut common = (Interval(ck.interval()), StopFlag(opts.stop.clone()), &ck);
    if relax > engine.step_count().min(relax) {
        progress.phase("relax", relax);
        let own = parts.hooks(&engine, outputs.as_mut(), None);
        if let Some(summary) = phase(&mut engine, own, (0, relax), progress, &mut common)? {
            return Ok(summary);
        }
    }
    progress.phase("run", measure);
    // Measured steps already done: none in a straight run after relaxing,
    // some when resumed inside the measurement.
    let done = engine.step_count() - engine.step_count().min(relax);
    parts.begin_measure(&mut engine, outputs.as_mut(), (done, measure))?;
    let base = engine.step_count() - done;
    let end = base + measure;
    let own = parts.hooks(&engine, outputs.as_mut(), Some((base, end)));
    if let Some(summary) = phase(&mut engine, own, (base, end), progress, &mut common)? {
        return Ok(summary);
    }
    progress.finish();
    let stepped = engine.step_count() - first_step;
    let ran = (relax + measure, stepped, started.elapsed().as_secs_f64());
    let Some(summary) = parts.finish(&mut engine, outputs.as_mut(), ran)? else {
        return Ok(Value::Null);
    };
    let summary = Value::Object(summary);
    if let Some(out) = &outputs {
        out.write_summary(&summary)?;
    }
    Ok(summary)
}

/// Runs a phase whose step k is engine step `base + k` to its `end`, with
/// the engine's hooks `own`, then the progress, interval and stop hooks.
/// Returns an interrupted run's summary when a hook stopped it.
fn phase<E: Engine>(
    engine: &mut E,
    mut own: Hooks<'_, E>,
    (base, end): (u64, u64),
    progress: &mut dyn Progress,
    (interval, stop, ck): &mut (Interval, StopFlag, &Checkpointer),
) -> Result<Option<Value>> {
    let mut report = Report::new(progress, base, end);
    let mut hooks: Vec<&mut dyn Hook<E>> = own.iter_mut().map(|h| &mut **h as _).collect();
    hooks.extend([&mut report as _, interval as _, stop as _]);
    let stopped = run_to(engine, end, &mut hooks, ck)?;
    drop(hooks);
    if stopped.is_some() {
        progress.finish();
    }
    Ok(stopped)
}
