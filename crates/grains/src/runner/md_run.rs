//! A serial MD run on the run loop: relaxation (flow events, progress,
//! checkpoints), then the measurement (also the measurements and the
//! outputs), then the final files and summary.json.

use super::checkpointer::Checkpointer;
use super::flow::{FlowHook, FlowRun};
use super::measurements::{MeasureHook, Measurements};
use super::options::{prepare, Progress, RunOptions};
use super::output::Outputs;
use super::run_loop::{run_to, Control, Every, Hook, Interval, Report, Saved, StopFlag};
use super::wall_table::WallTable;
use crate::dim::Dim;
use crate::error::Result;
use crate::md::Md;
use crate::measure::granular_temperature;
use crate::scenario::{build_md, Loaded, Resolved};
use serde_json::Map;
use serde_json::{json, Value};
use std::time::Instant;

/// Runs an MD scenario from step 0.
pub(super) fn run_dim<D: Dim>(
    loaded: &Loaded,
    opts: &RunOptions,
    progress: &mut dyn Progress,
) -> Result<Value> {
    prepare(&opts.out_dir)?;
    let loaded = &*crate::scenario::hopper::expand(loaded)?;
    let (md, resolved) = build_md::<D>(loaded)?;
    let outputs = Outputs::create(&opts.out_dir, &loaded.scenario.output)?;
    let plan = match opts.steps {
        Some(n) => (0, n),
        None => (resolved.relax_steps, resolved.measure_steps),
    };
    let start = Start {
        md,
        resolved,
        outputs,
        plan,
        restored: None,
    };
    run_loop(loaded, opts, start, progress)
}

/// Where an MD run starts: step 0, or a restored checkpoint with its
/// measurement accumulators when it lies inside the measurement.
pub(super) struct Start<D: Dim> {
    pub md: Md<D>,
    pub resolved: Resolved,
    pub outputs: Outputs,
    /// (relaxation, measured) steps.
    pub plan: (u64, u64),
    pub restored: Option<Measurements>,
}

/// The output steps of an MD run: thermo.csv, frames, dump and walls.csv
/// (never acting while relaxing, but saying where the files stand).
struct Record<'a> {
    outputs: &'a mut Outputs,
    walls: Option<&'a mut WallTable>,
    at: Option<Every>,
}

impl<D: Dim> Hook<Md<D>> for Record<'_> {
    fn next(&self, now: u64, horizon: u64) -> u64 {
        self.at.map_or(horizon, |a| a.next(now, horizon))
    }
    fn act(&mut self, md: &mut Md<D>, now: u64) -> Result<Control> {
        if self.at.is_some_and(|a| a.due(now)) {
            self.outputs.record_md(md)?;
            if let Some(w) = &mut self.walls {
                w.record(md)?;
            }
        }
        Ok(Control::Go)
    }
    fn pack(&self, saved: &mut Saved) -> Result<()> {
        saved.outputs = Some(self.outputs.state()?);
        Ok(())
    }
}

/// The run from wherever `start.md` stands to `relax + measure` steps,
/// then the final files.
pub(super) fn run_loop<D: Dim>(
    loaded: &Loaded,
    opts: &RunOptions,
    start: Start<D>,
    progress: &mut dyn Progress,
) -> Result<Value> {
    let Start {
        mut md,
        resolved,
        mut outputs,
        plan: (relax, measure),
        restored,
    } = start;
    let started = Instant::now();
    md.timing.reset();
    let first_step = md.step;
    let ck = Checkpointer::new(loaded, opts, md.settings.dt, (relax, measure))?;
    if ck.interval().is_some() && md.step == 0 {
        let saved = Saved {
            outputs: Some(outputs.state()?),
            measurements: None,
        };
        ck.write(&md, &saved)?;
    }
    let mut flow = FlowRun::begin(loaded, &md)?;
    let mut walls_csv = WallTable::create(&opts.out_dir, &md)?;
    let mut interval = Interval(ck.interval());
    let mut stop = StopFlag(opts.stop.clone());

    if relax > md.step.min(relax) {
        progress.phase("relax", relax);
        let stopped = {
            let mut events = FlowHook::new(&mut flow, None);
            let mut record = Record {
                outputs: &mut outputs,
                walls: None,
                at: None,
            };
            let mut report = Report::new(progress, 0, relax);
            let mut hooks: [&mut dyn Hook<Md<D>>; 5] = [
                &mut events,
                &mut record,
                &mut report,
                &mut interval,
                &mut stop,
            ];
            run_to(&mut md, relax, &mut hooks, &ck)?
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
    let measure_done = md.step - md.step.min(relax);
    let mut measurements = match restored {
        Some(m) => m,
        None => Measurements::begin(loaded, &md, measure - measure_done, resolved.dt)?,
    };
    if measure_done == 0 {
        outputs.record_md(&md)?;
        if let Some(w) = &mut walls_csv {
            w.record(&md)?;
        }
    }
    // Measured step k is engine step `base + k`. Sampling more often than
    // the output keeps the displacement unwrapping safe and the convection
    // average smooth.
    let base = md.step - measure_done;
    let end = base + measure;
    let every = resolved.output_every;
    let sample = Every::new(base, (every / 10).max(1), None);
    let stopped = {
        let mut events = FlowHook::new(&mut flow, Some(sample));
        let mut meas = MeasureHook {
            m: &mut measurements,
            sample,
            dt: md.settings.dt,
        };
        let mut record = Record {
            outputs: &mut outputs,
            walls: walls_csv.as_mut(),
            at: Some(Every::new(base, every, Some(end))),
        };
        let mut report = Report::new(progress, base, end);
        let mut hooks: [&mut dyn Hook<Md<D>>; 6] = [
            &mut events,
            &mut meas,
            &mut record,
            &mut report,
            &mut interval,
            &mut stop,
        ];
        run_to(&mut md, end, &mut hooks, &ck)?
    };
    if let Some(summary) = stopped {
        progress.finish();
        return Ok(summary);
    }
    measurements.sample(&md);
    progress.finish();
    let wall_seconds = started.elapsed().as_secs_f64();

    let last = md.frame();
    outputs.finish(&last, &md.walls, measurements.displacement.as_ref())?;
    measurements.write(&opts.out_dir, &md, &last)?;
    let steps = relax + measure;
    let stepped = md.step - first_step;
    let mut summary = md_summary(loaded, &md, &resolved, steps, stepped, wall_seconds);
    summary.insert("neighbor_builds".into(), json!(md.neighbor_builds()));
    // Seconds per phase of the step; `other` is mostly measurements and output.
    let phases = md.timing.to_json(wall_seconds, 1.0);
    summary.insert("phase_seconds".into(), phases);
    summary.insert("threads".into(), threads_json(&md));
    measurements.scalars(&mut summary);
    flow.finish(&opts.out_dir, &md, &mut summary)?;
    let summary = Value::Object(summary);
    outputs.write_summary(&summary)?;
    Ok(summary)
}

/// The summary scalars every MD run reports: what ran, how long it took
/// (`stepped` steps of this process's timing) and the final energies.
pub(crate) fn md_summary<D: Dim>(
    loaded: &Loaded,
    md: &Md<D>,
    resolved: &Resolved,
    steps: u64,
    stepped: u64,
    wall_seconds: f64,
) -> Map<String, Value> {
    let updates = (stepped.max(1) as f64) * md.particles.n_mobile().max(1) as f64;
    let mut summary = Map::new();
    summary.insert("scenario".into(), json!(loaded.scenario.name));
    summary.insert("dimension".into(), json!(D::NAME));
    summary.insert("particles".into(), json!(md.particles.n_owned()));
    summary.insert("steps".into(), json!(steps));
    summary.insert("time".into(), json!(md.time));
    summary.insert("dt".into(), json!(resolved.dt));
    summary.insert("contact_time".into(), json!(resolved.contact_time));
    summary.insert("wall_seconds".into(), json!(wall_seconds));
    summary.insert(
        "ns_per_particle_step".into(),
        json!(1e9 * wall_seconds / updates),
    );
    summary.insert(
        "kinetic_energy".into(),
        json!(md.particles.kinetic_energy()),
    );
    summary.insert(
        "rotational_energy".into(),
        json!(md.particles.rotational_energy()),
    );
    summary.insert(
        "granular_temperature".into(),
        json!(granular_temperature(&md.particles)),
    );
    summary
}

/// How the governor ran an engine's steps: the pool's size, the steps run
/// on all of it and on one thread (they depend on the machine's load, never
/// on the result).
pub(crate) fn threads_json<D: Dim>(md: &Md<D>) -> Value {
    let (wide, narrow) = md.governor.steps_wide_narrow();
    json!({ "pool": rayon::current_num_threads(), "steps_on_pool": wide, "steps_on_one": narrow })
}
