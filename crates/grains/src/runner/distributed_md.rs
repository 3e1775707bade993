//! Runs an MD scenario over several ranks ([`crate::md::decomp`]).
//!
//! [`DistMd`] is the decomposed engine behind the run loop's [`Engine`] and
//! [`MdView`]: every rank builds the whole engine from the scenario and
//! keeps its box; rank 0 keeps a second whole engine (the "mirror") into
//! which the ranks gather positions, velocities and spins at the steps
//! where a hook reads them. The run is the serial one ([`run_phases`]), so
//! rank 0 measures and writes with the serial code (thermo.csv, frames,
//! dump, measurement files, summary.json) and the files have the serial
//! run's layout; the numbers agree with a serial run
//! to rounding (see `docs/scaling.md`). The thermo row's contact count is
//! the sum over ranks, in which a contact across a box boundary counts
//! twice (both ranks evaluate it).
//!
//! Checkpoints (`--checkpoint-every`): at a checkpoint step every rank
//! sends its grains (Gear history, force and torque included) and springs
//! to rank 0, which writes the serial run's checkpoint format from the
//! mirror ([`DecomposedMd::gather_state`]). So `grains resume` continues
//! such a run on one process, and [`resume`] continues any checkpoint on
//! several ranks: every rank restores the whole engine and keeps its box.
//! The command line sets no stop flag under mpirun: a signal ends the run
//! without a checkpoint and the last interval's checkpoint stays (a flag
//! set on any rank would stop all at one step, [`Engine::any_rank`]).
//!
//! Flow events (`[hopper]` recycling, `run.events`: settle, wall removal,
//! tilt, sink; inlets, outlets and sensors) run on rank 0's mirror with the
//! serial code and are sent to every rank ([`DistMd::flow_events`]): moved
//! grains go to their owners, inserted grains to the rank whose box holds
//! them, removed ids to every rank ([`DecomposedMd::edit`]).
//! The per-step measurements (`measure.phases`, `measure.trajectories`)
//! gather the grains only at the steps where they read them: rank 0 says
//! which (one summed flag per step).

use super::checkpointing;
use super::engine::MdView;
use super::md_run::{MdPhases, Start};
use super::options::{prepare_fresh, Progress, RunOptions};
use super::phases::run_phases;
use crate::checkpoint::run::Found;
use crate::comm::{Comm, Reader, Writer};
use crate::dim::Dim;
use crate::engine::Engine;
use crate::error::{Error, Result};
use crate::io::Frame;
use crate::md::decomp::{index_by_id, DecomposedMd};
use crate::md::Md;
use crate::measure::measurements::Measurements;
use crate::output::{Outputs, Pieces};
use crate::scenario::flow::{self, FlowRun};
use crate::scenario::{build_md, Loaded, Resolved};
use serde_json::{json, Map, Value};
use std::cell::RefCell;
use std::collections::HashMap;

/// Runs `loaded` (method = "md") on the ranks of `comm`; the summary on
/// rank 0, `Value::Null` elsewhere.
pub fn run<D: Dim>(
    loaded: &Loaded,
    opts: &RunOptions,
    progress: &mut dyn Progress,
    comm: &dyn Comm,
) -> Result<Value> {
    let root = comm.rank() == 0;
    if root {
        prepare_fresh(opts)?;
    }
    let loaded = &*crate::scenario::hopper::expand(loaded)?;
    let (full, resolved) = build_md::<D>(loaded)?;
    let mirror = match root {
        true => Some(build_md::<D>(loaded)?.0),
        false => None,
    };
    let outputs = match root {
        true => Some(Outputs::create(&opts.out_dir, &loaded.scenario.output)?),
        false => None,
    };
    let plan = opts.plan((resolved.relax_steps, resolved.measure_steps));
    // Every rank makes the flow run, so a scenario it refuses stops all.
    let flow = FlowRun::begin(loaded, &full)?;
    let restored = (None, flow);
    let engines = (full, mirror);
    start(
        loaded, opts, engines, resolved, outputs, plan, restored, progress, comm,
    )
}

/// Continues an MD checkpoint (written by a serial or a distributed run) on
/// the ranks of `comm`: every rank reads it and keeps its box. `opts` as
/// given by [`checkpointing::resume_options`].
pub(super) fn resume<D: Dim>(
    found: &Found,
    steps: Option<u64>,
    opts: &RunOptions,
    progress: &mut dyn Progress,
    comm: &dyn Comm,
) -> Result<Value> {
    let loaded = found.loaded();
    let r = found.restore::<D>(steps)?;
    let root = comm.rank() == 0;
    let (mirror, outputs) = match root {
        true => {
            checkpointing::prepare_resume(found, opts)?;
            let out = checkpointing::resumed_outputs(found, opts)?;
            (Some(found.restore_md::<D>()?), Some(out))
        }
        false => (None, None),
    };
    let restored = (r.measurements.filter(|_| root), r.flow);
    let engines = (r.md, mirror);
    start(
        loaded, opts, engines, r.resolved, outputs, r.plan, restored, progress, comm,
    )
}

/// Splits the whole engine (every rank) with rank 0's mirror into a
/// [`DistMd`] and runs the serial run's loop on it.
#[allow(clippy::too_many_arguments)] // the run's whole context, shared by run and resume
fn start<D: Dim>(
    loaded: &Loaded,
    opts: &RunOptions,
    (full, mirror): (Md<D>, Option<Md<D>>),
    resolved: Resolved,
    mut outputs: Option<Outputs>,
    plan: (u64, u64),
    (restored, flow): (Option<Measurements>, FlowRun<D>),
    progress: &mut dyn Progress,
    comm: &dyn Comm,
) -> Result<Value> {
    // Rank 0 keeps the flow run (begun, as the serial run's, from the
    // engine before its first step, or restored from the checkpoint).
    // Rank 0 begins the measurements after relaxing; a scenario they refuse
    // (phases without a vibrating wall) must stop every rank now.
    let m = &loaded.scenario.measure;
    if m.phases.is_some() || m.trajectories.is_some() || m.impact {
        Measurements::begin(loaded, &full.view(), 0, resolved.dt)?;
    }
    let flow = mirror.is_some().then_some(flow);
    if let Some(out) = outputs.as_mut() {
        out.set_ranks(comm.size());
    }
    let index = mirror
        .as_ref()
        .map(|m| index_by_id(&m.particles))
        .unwrap_or_default();
    // The inlets' largest grain widens the ghost shells from the start.
    let inserted = crate::scenario::inlet::extent(loaded)?.map_or(0.0, |(_, d)| 0.5 * d);
    let spec = &loaded.scenario.parallel;
    let dec = match full.step {
        0 => DecomposedMd::with_inserts(full, comm, spec, inserted)?,
        _ => DecomposedMd::resume(full, comm, spec, inserted)?,
    };
    let engine = DistMd {
        dec,
        comm,
        mirror: RefCell::new(mirror),
        index,
        fresh: None,
        pieces: Pieces::new(&loaded.scenario.output, &opts.out_dir, comm),
        sink: flow::sink_height(loaded),
        events: loaded.scenario.run.events.is_some(),
        edits: flow::edits(loaded),
    };
    let parts = MdPhases::new((loaded, opts), resolved, flow, restored);
    let start = Start::new(engine, outputs, plan, parts);
    run_phases(loaded, opts, start, progress)
}

/// The decomposed MD engine of one rank: its part of the run, and on rank
/// 0 the mirror, a whole engine of the same run into which the ranks
/// gather the grains where a hook reads them.
pub(super) struct DistMd<'c, D: Dim> {
    dec: DecomposedMd<'c, D>,
    comm: &'c dyn Comm,
    /// Rank 0's whole engine (a cell, as a checkpoint gathers into it
    /// through [`Engine::export`]).
    mirror: RefCell<Option<Md<D>>>,
    /// The mirror's place of each grain id (it never steps, so the index
    /// holds until the flow run inserts or removes grains, which renew it).
    index: HashMap<u64, usize>,
    /// The step at which the mirror last received the grains.
    fresh: Option<u64>,
    pieces: Pieces,
    /// Below this height the flow events move grains.
    sink: Option<f64>,
    /// Whether the scenario has `run.events`.
    events: bool,
    /// Whether it has inlets, outlets or sensors ([`flow::edits`]).
    edits: bool,
}

impl<'c, D: Dim> DistMd<'c, D> {
    fn comm(&self) -> &'c dyn Comm {
        self.comm
    }

    /// Gathers the whole state into rank 0's mirror, at most once a step
    /// (every rank calls this).
    fn gathered(&mut self) {
        let step = self.dec.md.step;
        let mirror = self.mirror.get_mut();
        if self.fresh != Some(step) {
            self.dec.gather(mirror.as_mut(), &self.index);
            if let Some(m) = mirror.as_mut() {
                m.stats = self.dec.md.stats.clone();
            }
            self.fresh = Some(step);
        }
    }
}

impl<D: Dim> Engine for DistMd<'_, D> {
    fn dim(&self) -> usize {
        D::D
    }
    fn step_count(&self) -> u64 {
        self.dec.md.step
    }
    fn sim_time(&self) -> f64 {
        self.dec.md.time
    }
    fn time_step(&self) -> f64 {
        self.dec.md.settings.dt
    }
    fn advance(&mut self, n: u64) -> Result<()> {
        self.dec.advance(n)
    }
    fn frame(&self) -> Result<Frame> {
        Ok(self.dec.md.frame())
    }
    fn export(&self) -> Result<Vec<u8>> {
        let mut mirror = self.mirror.borrow_mut();
        self.dec.gather_state(mirror.as_mut(), &self.index)?;
        let bytes = match mirror.as_ref() {
            Some(m) => Engine::export(m)?,
            None => Vec::new(),
        };
        // The checkpoint wrapped the mirror's grains into the box; the
        // measurements follow the grains as the ranks hold them.
        self.dec.gather(mirror.as_mut(), &self.index);
        Ok(bytes)
    }
    fn import(&mut self, _: &[u8], origin: &str) -> Result<()> {
        Err(Error::input(format!(
            "checkpoint {origin}: a decomposed engine is split from a restored whole one"
        )))
    }
    fn writes(&self) -> bool {
        self.comm().rank() == 0
    }
    fn any_rank(&mut self, flag: bool) -> bool {
        let mut n = [u64::from(flag)];
        self.comm().sum_u64(&mut n);
        n[0] > 0
    }
}

impl<D: Dim> MdView for DistMd<'_, D> {
    type D = D;
    fn whole(&mut self) -> Result<Option<&Md<D>>> {
        self.gathered();
        Ok(self.mirror.get_mut().as_ref())
    }
    fn whole_if(&mut self, want: bool) -> Result<Option<&Md<D>>> {
        if self.any_rank(want) {
            return self.whole();
        }
        let (time, step) = (self.dec.md.time, self.dec.md.step);
        let Some(m) = self.mirror.get_mut().as_mut() else {
            return Ok(None);
        };
        (m.time, m.step) = (time, step);
        Ok(Some(m))
    }
    fn lockstep(&self) -> bool {
        true
    }
    fn write_piece(&self) -> Result<()> {
        self.pieces.write(|| self.dec.md.frame())
    }
    /// Flow events of one step on every rank: rank 0 runs them on the
    /// mirror with the serial code (recycling, `run.events`, then the
    /// inlets, outlets and sensors), then sends gravity, the walls' removal
    /// times, the grains they moved (id, position, frozen), the grains the
    /// inlets inserted (whole records) and the ids the outlets removed to
    /// all ranks. The owners put their moved grains there ([`flow::place`]);
    /// each rank inserts the new grains in its box and removes its own
    /// removed ones ([`DecomposedMd::edit`]). The mirror is gathered first
    /// only when the events read the grains: when some rank holds a mobile
    /// grain below the sink (a sum over the ranks), at a look of
    /// `run.events` (its kinetic energy, the pile's top and slope), or when
    /// an inlet, outlet or sensor acts at this step (rank 0's word, in the
    /// same sum). A moved grain jumps far beyond skin/2, so the next step's
    /// rebuild vote migrates it to the rank of its new place; an edit makes
    /// every rank rebuild at the next step. The mirror then holds this
    /// step's state (gathered, then changed as the ranks change it).
    ///
    /// Unlike the serial engine, the mirror never re-sorts its grains: when
    /// several grains fall below the sink in one step, they draw their new
    /// spots in another order than the serial run does (the same spots,
    /// other grains).
    fn flow_events(&mut self, flow: Option<&mut FlowRun<D>>) -> Result<()> {
        if self.sink.is_none() && !self.events && !self.edits {
            return Ok(());
        }
        let v = D::vertical();
        let p = &self.dec.md.particles;
        let below = self.sink.map_or(0, |s| {
            (0..p.n_owned())
                .filter(|&i| !p.frozen[i] && D::get(p.pos[i], v) < s)
                .count() as u64
        });
        let step = self.dec.md.step;
        let due = flow.as_deref().is_some_and(|f| f.edits_at(step));
        let mut need = [below + u64::from(due)];
        self.comm().sum_u64(&mut need);
        let look = self.events && step.is_multiple_of(flow::LOOK_EVERY);
        if need[0] > 0 || look {
            self.gathered();
        } else if !self.events {
            // Recycling, inlets, outlets and sensors change nothing now.
            return Ok(());
        }
        let mut w = Writer::default();
        let mut failed = None;
        if let (Some(m), Some(f)) = (self.mirror.get_mut().as_mut(), flow) {
            let now = (self.dec.md.time, step);
            failed = f.step_on_mirror(m, &mut self.index, now, &mut w).err();
        }
        let all = self.comm().all_gather_bytes(&w.buf);
        let rank = self.comm().rank();
        flow::apply_on_rank(&mut self.dec, &mut Reader::new(&all[0]), rank, failed)
    }
    fn summarize(&mut self, summary: &mut Map<String, Value>, _: f64) {
        let mut ghosts = [self.dec.n_ghosts() as u64];
        self.comm().sum_u64(&mut ghosts);
        let size = self.comm().size();
        summary.insert("neighbor_builds".into(), json!(self.dec.neighbor_builds()));
        summary.insert("ranks".into(), json!(size));
        let grid = self.dec.subdomains().describe(D::D);
        summary.insert("grid".into(), json!(grid));
        summary.insert("migrations".into(), json!(self.dec.migrations));
        summary.insert("ghosts".into(), json!(ghosts[0]));
        self.dec.balance.write(summary);
    }
}
