//! An MD run's parts of the phase script ([`super::phases`]), serial or
//! decomposed over ranks: the flow events while relaxing, then also the
//! measurements and the outputs, then the final files and summary.json.

use super::engine::MdView;
use super::options::{prepare_fresh, Progress, RunOptions};
use super::phases::{self, run_phases, Hooks, Out, Phases, Ran};
use super::run_loop::{Control, Every, Hook, Record, Recorder, Saved};
use crate::dim::Dim;
use crate::error::Result;
use crate::md::Md;
use crate::measure::measurements::Measurements;
use crate::measure::wall_table::WallTable;
use crate::output::{md_summary, Outputs};
use crate::scenario::flow::FlowRun;
use crate::scenario::{build_md, Loaded, Resolved};
use serde_json::{Map, Value};

/// Runs an MD scenario from step 0.
pub(super) fn run_dim<D: Dim>(
    loaded: &Loaded,
    opts: &RunOptions,
    progress: &mut dyn Progress,
) -> Result<Value> {
    prepare_fresh(opts)?;
    let loaded = &*crate::scenario::hopper::expand(loaded)?;
    let start = begin::<D>(loaded, opts)?;
    run_phases(loaded, opts, start, progress)
}

/// The engine built from the scenario at step 0, the outputs created, the
/// plan of steps.
pub(super) fn begin<'a, D: Dim>(loaded: &'a Loaded, opts: &'a RunOptions) -> Result<Start<'a, D>> {
    let (mut md, resolved) = build_md::<D>(loaded)?;
    md.timing.reset();
    let outputs = Outputs::create(&opts.out_dir, &loaded.scenario.output)?;
    let plan = opts.plan((resolved.relax_steps, resolved.measure_steps));
    let flow = Some(FlowRun::begin(loaded, &md)?);
    let parts = MdPhases::new((loaded, opts), resolved, flow, None);
    Ok(Start::new(md, Some(outputs), plan, parts))
}

/// Where an MD run starts: step 0, or a restored checkpoint with its
/// measurement accumulators when it lies inside the measurement. `E` is
/// the serial engine or a decomposed one.
pub(super) type Start<'a, D, E = Md<D>> = phases::Start<E, MdPhases<'a, D>>;

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

/// An MD run's parts of the phases: the flow run, the measurements and
/// walls.csv (rank 0's).
pub(super) struct MdPhases<'a, D: Dim> {
    loaded: &'a Loaded,
    opts: &'a RunOptions,
    resolved: Resolved,
    flow: Option<FlowRun<D>>,
    measurements: Option<Measurements>,
    walls_csv: Option<WallTable>,
}

impl<'a, D: Dim> MdPhases<'a, D> {
    /// The parts of a run of `loaded`, with the measurements `restored`
    /// from a checkpoint inside the measurement.
    pub fn new(
        (loaded, opts): (&'a Loaded, &'a RunOptions),
        resolved: Resolved,
        flow: Option<FlowRun<D>>,
        restored: Option<Measurements>,
    ) -> Self {
        let (measurements, walls_csv) = (restored, None);
        Self {
            loaded,
            opts,
            resolved,
            flow,
            measurements,
            walls_csv,
        }
    }
}

impl<D: Dim, E: MdView<D = D>> Phases<E> for MdPhases<'_, D> {
    fn begin(&mut self, engine: &mut E) -> Result<()> {
        if let Some(md) = engine.whole()? {
            self.walls_csv = WallTable::create(&self.opts.out_dir, &md.view())?;
        }
        Ok(())
    }
    // Sampling more often than the output keeps the displacement
    // unwrapping safe and the convection average smooth. A decomposed
    // engine's flow events and per-step measurements act at every step:
    // rank 0 alone knows when they read the grains.
    fn hooks<'a>(&'a mut self, e: &E, out: Out<'a>, measured: Option<(u64, u64)>) -> Hooks<'a, E> {
        let (loaded, every) = (self.loaded, self.resolved.output_every);
        let flow_lockstep = e.lockstep()
            && (crate::scenario::flow::sink_height(loaded).is_some()
                || loaded.scenario.run.events.is_some()
                || crate::scenario::flow::edits(loaded));
        let sample = measured.map(|(base, _)| Every::new(base, (every / 10).max(1), None));
        let events = FlowHook {
            flow: self.flow.as_mut(),
            sample,
            lockstep: flow_lockstep,
        };
        let walls = self.walls_csv.as_mut();
        let record = Record {
            outputs: out,
            at: measured.map(|(base, end)| Every::new(base, every, Some(end))),
            how: MdRecord { walls },
        };
        let Some(sample) = sample else {
            return vec![Box::new(events), Box::new(record)];
        };
        let m = &loaded.scenario.measure;
        let meas = MeasureHook {
            m: self.measurements.as_mut(),
            sample,
            dt: e.time_step(),
            // The fields sample in `Measurements::step` at their own
            // `every`, not at the sampled steps; the hook stops only at
            // their due steps.
            per_step: m.phases.is_some()
                || m.trajectories.is_some()
                || m.impact
                || m.fields.is_some(),
            lockstep: e.lockstep(),
        };
        vec![Box::new(events), Box::new(meas), Box::new(record)]
    }
    // A checkpoint taken during the measurement carries its accumulators;
    // one taken before it does not, and they begin here as in a straight
    // run.
    fn begin_measure(&mut self, e: &mut E, out: Out, (done, measure): (u64, u64)) -> Result<()> {
        self.measurements = match (self.measurements.take(), e.whole()?) {
            (Some(m), Some(_)) => Some(m),
            (None, Some(md)) => {
                let left = measure - done;
                Some(Measurements::begin(
                    self.loaded,
                    &md.view(),
                    left,
                    self.resolved.dt,
                )?)
            }
            (_, None) => None,
        };
        if done == 0 {
            let walls = self.walls_csv.as_mut();
            MdRecord { walls }.record(out, e)?;
        }
        Ok(())
    }
    fn finish(self, e: &mut E, out: Out, ran: Ran) -> Result<Option<Map<String, Value>>> {
        let (steps, stepped, wall) = ran;
        let mut extra = Map::new();
        e.summarize(&mut extra, wall);
        let (Some(md), Some(mut measurements), Some(flow), Some(outputs)) =
            (e.whole()?, self.measurements, self.flow, out)
        else {
            return Ok(None);
        };
        measurements.sample(&md.view());
        let last = md.frame();
        outputs.finish(&last, &md.walls, measurements.displacement.as_ref())?;
        let dir = &self.opts.out_dir;
        measurements.write(dir, &md.view(), &last)?;
        let mut summary = md_summary(self.loaded, md, &self.resolved, steps, stepped, wall);
        summary.extend(extra);
        measurements.scalars(&mut summary);
        flow.finish(dir, md, &mut summary)?;
        Ok(Some(summary))
    }
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
        engine.flow_events(self.flow.as_deref_mut())?;
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
