//! The engine contract the run loop drives: advance in fused stretches,
//! show the state as a frame, export and import the complete state.
//!
//! Implemented here for the serial MD engine ([`Md`]) and the DSMC engine
//! ([`Dsmc`]); the run loop ([`super::run_loop`]) and the Python session
//! drive either through it.

use crate::checkpoint;
use crate::dim::Dim;
use crate::dsmc::collide::GasDim;
use crate::dsmc::engine::Dsmc;
use crate::error::{Error, Result};
use crate::io::Frame;
use crate::md::Md;

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
    /// The state now as a neutral frame, for outputs.
    fn frame(&self) -> Frame;
    /// The complete state as bytes: a checkpoint's engine field.
    fn export(&self) -> Result<Vec<u8>>;
    /// Puts back a state written by [`Engine::export`] into an engine
    /// freshly built from the same scenario; `origin` names the file in
    /// messages.
    fn import(&mut self, bytes: &[u8], origin: &str) -> Result<()>;
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
    fn frame(&self) -> Frame {
        Md::frame(self)
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
    fn frame(&self) -> Frame {
        gas_frame(self)
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
