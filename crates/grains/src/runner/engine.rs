//! The engine contract the run loop drives: advance in fused stretches,
//! show the state as a frame, export and import the complete state.
//!
//! Implemented here for the serial MD engine ([`Md`]) and the DSMC engine
//! ([`Dsmc`]), and in [`super::distributed_md`] and [`super::distributed`]
//! for their decompositions over ranks; the run loop ([`super::run_loop`])
//! and the Python session drive any of them through it. The MD and the gas
//! hooks see an engine through [`MdView`] and [`GasView`]: the whole state,
//! at hand in a serial engine, gathered on rank 0 in a decomposed one.

use crate::checkpoint;
use crate::dim::Dim;
use crate::dsmc::collide::GasDim;
use crate::dsmc::engine::Dsmc;
use crate::error::{Error, Result};
use crate::io::Frame;
use crate::md::Md;
use crate::scenario::flow::FlowRun;
use serde_json::{json, Map, Value};

/// A simulation engine as the run loop sees it. The method names differ
/// from the engines' own (`Md::step` is a field, `Dsmc::step` takes a
/// step), so that calling a getter never takes a step by accident.
pub trait Engine: Send {
    /// 2 or 3.
    fn dim(&self) -> usize;
    /// Steps taken since step 0.
    fn step_count(&self) -> u64;
    /// Simulated time (s).
    fn sim_time(&self) -> f64;
    /// The time step (s).
    fn time_step(&self) -> f64;
    /// Takes `n` steps, the same bits as `n` single steps, returning with
    /// every step complete (also on error).
    fn advance(&mut self, n: u64) -> Result<()>;
    /// The state now as a neutral frame, for outputs (this rank's part
    /// of a decomposed engine); fails only where the state must first be
    /// copied from a device.
    fn frame(&self) -> Result<Frame>;
    /// The complete state as bytes: a checkpoint's engine field. A
    /// decomposed engine gathers it (every rank calls this) and returns it
    /// on rank 0, no bytes elsewhere.
    fn export(&self) -> Result<Vec<u8>>;
    /// Puts back a state written by [`Engine::export`] into an engine
    /// freshly built from the same scenario; `origin` names the file in
    /// messages.
    fn import(&mut self, bytes: &[u8], origin: &str) -> Result<()>;
    /// Whether this process writes the run's files (rank 0 of a
    /// decomposed engine).
    fn writes(&self) -> bool {
        true
    }
    /// Whether `flag` is set on any rank (every rank calls this).
    fn any_rank(&mut self, flag: bool) -> bool {
        flag
    }
}

/// An MD engine as the MD hooks see it. Its methods that gather are
/// collective in a decomposed engine: every rank calls them at the same
/// steps.
pub(crate) trait MdView: Engine {
    /// The dimension.
    type D: Dim;
    /// The whole state now (gathered or copied from a device at most once
    /// a step); `None` on the ranks other than 0. Hooks read it and never
    /// change it: only the engine's steps and [`MdView::flow_events`] do,
    /// so an engine that keeps its state elsewhere never copies it back.
    fn whole(&mut self) -> Result<Option<&Md<Self::D>>>;
    /// The whole state now when `want` on some rank (rank 0 alone may
    /// know); else rank 0's whole engine with only its step and time
    /// current.
    fn whole_if(&mut self, want: bool) -> Result<Option<&Md<Self::D>>>;
    /// Whether the steps at which rank 0's measurements and flow events
    /// act are known to rank 0 alone, so that those hooks act at every
    /// step.
    fn lockstep(&self) -> bool {
        false
    }
    /// This rank's piece of the frame at an output step, when frames come
    /// in pieces from several ranks.
    fn write_piece(&self) -> Result<()> {
        Ok(())
    }
    /// The flow events after the step now (`flow` on rank 0).
    fn flow_events(&mut self, flow: Option<&mut FlowRun<Self::D>>);
    /// What the engine adds to summary.json after the common scalars
    /// (every rank calls this).
    fn summarize(&mut self, summary: &mut Map<String, Value>, wall_seconds: f64);
}

impl<D: Dim> MdView for Md<D> {
    type D = D;
    fn whole(&mut self) -> Result<Option<&Md<D>>> {
        Ok(Some(self))
    }
    fn whole_if(&mut self, _: bool) -> Result<Option<&Md<D>>> {
        Ok(Some(self))
    }
    fn flow_events(&mut self, flow: Option<&mut FlowRun<D>>) {
        if let Some(f) = flow {
            f.after_step(self);
        }
    }
    fn summarize(&mut self, summary: &mut Map<String, Value>, wall_seconds: f64) {
        md_scalars(self, summary, wall_seconds);
    }
}

/// What a serial MD engine adds to summary.json: its neighbour builds, the
/// seconds per phase of the step (`other` is mostly measurements and
/// output), and how the governor ran its steps (the pool's size, the steps
/// run on all of it and on one thread: they depend on the machine's load,
/// never on the result).
pub(crate) fn md_scalars<D: Dim>(md: &Md<D>, summary: &mut Map<String, Value>, wall_seconds: f64) {
    summary.insert("neighbor_builds".into(), json!(md.neighbor_builds()));
    let phases = md.timing.to_json(wall_seconds, 1.0);
    summary.insert("phase_seconds".into(), phases);
    let (wide, narrow) = md.governor.steps_wide_narrow();
    let pool = rayon::current_num_threads();
    summary.insert(
        "threads".into(),
        json!({ "pool": pool, "steps_on_pool": wide, "steps_on_one": narrow }),
    );
}

/// A DSMC engine as the gas hooks see it (collective as [`MdView`]).
pub(crate) trait GasView: Engine {
    /// The dimension.
    type D: GasDim;
    /// The whole gas now (gathered at most once a step); `None` on the
    /// ranks other than 0.
    fn whole(&mut self) -> Option<&mut Dsmc<Self::D>>;
    /// This rank's piece of the frame at an output step.
    fn write_piece(&self) -> Result<()> {
        Ok(())
    }
    /// The collision tallies were read at an output step: the ranks of a
    /// decomposed engine start theirs again.
    fn tallies_read(&mut self) {}
    /// What the engine adds to summary.json (every rank calls this).
    fn summarize(&mut self, _summary: &mut Map<String, Value>) {}
}

impl<D: GasDim> GasView for Dsmc<D> {
    type D = D;
    fn whole(&mut self) -> Option<&mut Dsmc<D>> {
        Some(self)
    }
}

impl<D: Dim> Engine for Md<D> {
    fn dim(&self) -> usize {
        D::D
    }
    fn step_count(&self) -> u64 {
        self.step
    }
    fn sim_time(&self) -> f64 {
        self.time
    }
    fn time_step(&self) -> f64 {
        self.settings.dt
    }
    fn advance(&mut self, n: u64) -> Result<()> {
        Md::advance(self, n)
    }
    fn frame(&self) -> Result<Frame> {
        Ok(Md::frame(self))
    }
    fn export(&self) -> Result<Vec<u8>> {
        checkpoint::engine::encode(self)
    }
    fn import(&mut self, bytes: &[u8], origin: &str) -> Result<()> {
        if checkpoint::dsmc::is_dsmc(bytes) {
            return Err(Error::input(format!(
                "checkpoint {origin}: holds a DSMC engine state, but its scenario is an MD run \
                 (method = \"dsmc\" is not set); the file cannot be resumed as MD"
            )));
        }
        checkpoint::engine::restore(self, bytes).map_err(|e| Error::input(format!("{origin}: {e}")))
    }
}

impl<D: GasDim> Engine for Dsmc<D> {
    fn dim(&self) -> usize {
        D::D
    }
    fn step_count(&self) -> u64 {
        self.step
    }
    fn sim_time(&self) -> f64 {
        self.time
    }
    fn time_step(&self) -> f64 {
        self.settings.dt
    }
    fn advance(&mut self, n: u64) -> Result<()> {
        self.run(n);
        Ok(())
    }
    fn frame(&self) -> Result<Frame> {
        Ok(gas_frame(self))
    }
    fn export(&self) -> Result<Vec<u8>> {
        Ok(checkpoint::dsmc::encode(self))
    }
    fn import(&mut self, bytes: &[u8], origin: &str) -> Result<()> {
        let rest = checkpoint::dsmc::restore(self, bytes, origin)?;
        match rest.len() {
            0 => Ok(()),
            n => Err(Error::input(format!(
                "checkpoint {origin}: {n} unexpected bytes after the DSMC state"
            ))),
        }
    }
}

/// A DSMC gas as a frame: point particles whose ids are their store
/// positions + 1 (they carry no identity), a 2D box one unit deep.
pub(crate) fn gas_frame<D: GasDim>(sim: &Dsmc<D>) -> Frame {
    let n = sim.store.len();
    let mut periodic = [false; 3];
    periodic[..D::D].copy_from_slice(&sim.domain.periodic[..D::D]);
    let (mut lo, mut hi) = (D::to_xyz(sim.domain.lo), D::to_xyz(sim.domain.hi));
    if D::D == 2 {
        lo[2] = -0.5;
        hi[2] = 0.5;
    }
    Frame {
        step: sim.step,
        time: sim.time,
        dim: D::D,
        box_lo: lo,
        box_hi: hi,
        periodic,
        id: (1..=n as u64).collect(),
        kind: vec![1; n],
        pos: sim.store.p.iter().map(|q| D::to_xyz(q.x)).collect(),
        vel: sim.store.p.iter().map(|q| D::to_xyz(q.v)).collect(),
        omega: vec![[0.0; 3]; n],
        radius: vec![0.5 * sim.store.diameter; n],
    }
}
