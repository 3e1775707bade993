//! The engine contract the run loop drives: advance in fused stretches,
//! show the state as a frame, export and import the complete state.
//!
//! Each engine implements it in its own module (`md/contract.rs`,
//! `dsmc/contract.rs`, with its state's codec beside it); the runner adds
//! the decompositions over ranks and the GPU pipeline. The run loop and
//! the Python session drive any of them through it, and a checkpoint
//! carries [`Engine::export`]'s bytes without reading them.

use crate::error::Result;
use crate::io::Frame;

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
