//! What a run takes besides its scenario: the output directory, the step
//! count, the checkpoint interval, the stop flag, and a progress reporter.

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

/// A checkpoint interval: simulated seconds or a number of steps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Every {
    Seconds(f64),
    Steps(u64),
}

impl Every {
    /// Parses `0.01` (seconds) or `500steps` / `500 steps`.
    pub fn parse(text: &str) -> Result<Self> {
        let t = text.trim();
        let bad = || {
            Error::input(format!(
                "--checkpoint-every '{text}': give simulated seconds (e.g. 0.01) \
                 or a step count (e.g. 500steps)"
            ))
        };
        if let Some(n) = t.strip_suffix("steps").or_else(|| t.strip_suffix("step")) {
            let n: u64 = n.trim().parse().map_err(|_| bad())?;
            if n == 0 {
                return Err(bad());
            }
            return Ok(Every::Steps(n));
        }
        let s = t.strip_suffix('s').unwrap_or(t).trim();
        let v: f64 = s.parse().map_err(|_| bad())?;
        if !(v.is_finite() && v > 0.0) {
            return Err(bad());
        }
        Ok(Every::Seconds(v))
    }

    /// The interval in steps of `dt` (at least one).
    pub fn steps(self, dt: f64) -> u64 {
        match self {
            Every::Steps(n) => n.max(1),
            Every::Seconds(t) => {
                let n = (t / dt).round();
                if n >= 1.0 && n < u64::MAX as f64 {
                    n as u64
                } else {
                    1
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn intervals_parse() {
        assert_eq!(Every::parse("0.01").unwrap(), Every::Seconds(0.01));
        assert_eq!(Every::parse("500steps").unwrap(), Every::Steps(500));
        assert_eq!(Every::parse("20 steps").unwrap(), Every::Steps(20));
        assert_eq!(Every::Seconds(0.01).steps(1e-4), 100);
        for bad in ["", "0", "-1", "nan", "0steps", "xsteps", "inf"] {
            assert!(Every::parse(bad).is_err(), "{bad}");
        }
    }
}
