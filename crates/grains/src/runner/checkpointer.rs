//! Writes the checkpoints of a run, MD or DSMC: the run's payload (the
//! scenario as TOML with its origin, absolute base directory and input
//! files, the dimension, the
//! run plan, the checkpoint interval, the output state, the step, the
//! engine's exported state, the measurement section and the flow section:
//! each a flag, and when set the state's length-prefixed bytes) inside the
//! sealed file of [`crate::checkpoint`].

use super::options::RunOptions;
use crate::checkpoint;
use crate::checkpoint::run::{write_payload, OutputState, RunHeader};
use crate::engine::Engine;
use crate::error::Result;
use crate::scenario::Loaded;
use serde_json::{json, Value};
use std::path::PathBuf;

/// The hooks' parts of a checkpoint: where the output files stand, the
/// measurement accumulators once the measurement has begun, and an MD run's
/// flow state.
#[derive(Default)]
pub(crate) struct Saved {
    pub outputs: Option<OutputState>,
    pub measurements: Option<Vec<u8>>,
    pub flow: Option<Vec<u8>>,
}

/// Writes the checkpoints of one run, MD or DSMC: the run loop calls it
/// when a hook asks for one ([`super::run_loop::Control`]).
pub(crate) struct Checkpointer {
    dir: PathBuf,
    interval: Option<u64>,
    /// What each checkpoint says about the run.
    run: RunHeader,
}

impl Checkpointer {
    /// The checkpoints of a run of `loaded` with time step `dt` and
    /// (relaxation, measured) steps `plan`.
    pub(crate) fn new(
        loaded: &Loaded,
        opts: &RunOptions,
        dt: f64,
        plan: (u64, u64),
    ) -> Result<Self> {
        let interval = opts.checkpoint_every.map(|e| e.steps(dt));
        Ok(Self {
            dir: opts.out_dir.clone(),
            interval,
            run: RunHeader::new(loaded, plan, interval)?,
        })
    }

    /// Checkpoints into `dir` at `interval` of a run with no scenario text
    /// (for the run loop's tests).
    #[cfg(test)]
    pub(crate) fn in_dir(dir: &std::path::Path, interval: Option<u64>) -> Self {
        Self {
            dir: dir.to_path_buf(),
            interval,
            run: RunHeader {
                scenario: String::new(),
                origin: String::new(),
                base_dir: String::new(),
                inputs: Vec::new(),
                dim: 3,
                plan: (0, 0),
                interval,
            },
        }
    }

    /// The interval in steps, when the run takes checkpoints.
    pub(crate) fn interval(&self) -> Option<u64> {
        self.interval
    }

    /// The summary of a run stopped by a signal at the step `engine` stands
    /// at, with a checkpoint there.
    pub(crate) fn interrupt(&self, engine: &dyn Engine, saved: &Saved) -> Result<Value> {
        let (step, time) = (engine.step_count(), engine.sim_time());
        let path = self.write(engine, saved)?;
        Ok(json!({
            "interrupted": true,
            "step": step,
            "time": time,
            "checkpoint": path.display().to_string(),
            "message": format!(
                "stopped at step {step} (t = {time:.6e} s); checkpoint {}; continue with: grains resume {}",
                path.display(), self.dir.display()
            ),
        }))
    }

    /// Writes the checkpoint of `engine` with the hooks' `saved` parts (on
    /// the rank that writes; every rank calls this, as the engine's export
    /// may gather). Returns the file's path.
    pub(crate) fn write(&self, engine: &dyn Engine, saved: &Saved) -> Result<PathBuf> {
        let bytes = engine.export()?;
        if !engine.writes() {
            return Ok(self.dir.join(checkpoint::file_name(engine.step_count())));
        }
        debug_assert_eq!(engine.dim(), self.run.dim);
        let outputs = saved.outputs.clone().unwrap_or_default();
        write_payload(
            &self.dir,
            &self.run,
            &outputs,
            engine.step_count(),
            &bytes,
            (saved.measurements.as_deref(), saved.flow.as_deref()),
        )
    }
}
