//! What a run takes besides its scenario: the output directory, the step
//! count, the checkpoint interval, the stop flag, and a progress reporter.

use crate::checkpoint::interval::Every;
use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// What the caller (the command line) chooses beyond the scenario.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    pub out_dir: PathBuf,
    /// Replaces the measured run length (relaxation is then skipped).
    pub steps: Option<u64>,
    /// Write a checkpoint at this interval (see [`super::checkpointing`]).
    pub checkpoint_every: Option<Every>,
    /// Set (by a signal handler) to stop with a checkpoint at the end of
    /// the current stretch of steps (at most 256 steps on); the summary
    /// then says `"interrupted"`.
    pub stop: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    /// A fresh run into a folder that holds another run replaces that run's
    /// files instead of refusing the folder ([`crate::run_dir::claim`]).
    pub overwrite: bool,
}

/// Receives progress reports; the command line draws a bar or log lines.
pub trait Progress: Send {
    /// A phase begins with `total` steps.
    fn phase(&mut self, name: &str, total: u64);
    /// `done` steps of the phase are complete; `time` is the simulated time.
    fn advance(&mut self, done: u64, time: f64);
    fn finish(&mut self);
}

/// Progress that reports nothing.
pub struct Silent;

impl Progress for Silent {
    fn phase(&mut self, _: &str, _: u64) {}
    fn advance(&mut self, _: u64, _: f64) {}
    fn finish(&mut self) {}
}

/// Creates the output directory and proves it writable before any work.
pub fn prepare(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let probe = dir.join(".grains-write-test");
    std::fs::write(&probe, b"ok").map_err(|e| Error::io(&probe, e))?;
    std::fs::remove_file(&probe).map_err(|e| Error::io(&probe, e))?;
    Ok(())
}

/// Claims the output folder of a fresh run ([`crate::run_dir::claim`]:
/// refused when it holds another run, unless `opts.overwrite`) and
/// [`prepare`]s it.
pub fn prepare_fresh(opts: &RunOptions) -> Result<()> {
    crate::run_dir::claim(&opts.out_dir, opts.overwrite)?;
    prepare(&opts.out_dir)
}
