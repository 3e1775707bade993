//! Checkpoints for a caller that holds an engine between calls (the
//! Python session): save one of an engine, open one and restore its
//! engine, in the format of `grains run --checkpoint-every`, without the
//! caller reading that format.

use super::dsmc::Restored;
use crate::checkpoint::run::{find, payload, Found, OutputState, RunHeader};
use crate::dim::Dim;
use crate::dsmc::collide::GasDim;
use crate::engine::Engine;
use crate::error::{Error, Result};
use crate::md::Md;
use crate::scenario::{Loaded, Resolved};
use std::path::{Path, PathBuf};

/// Writes a checkpoint of `engine`, a run of `loaded` with (relaxation,
/// measured) steps `plan`, to `path` (atomically): no output files belong
/// to it and no flow section; `measurements`, the engine's measurement
/// section if it keeps one. Returns the path.
pub fn save(
    path: &Path,
    loaded: &Loaded,
    plan: (u64, u64),
    engine: &dyn Engine,
    measurements: Option<&[u8]>,
) -> Result<PathBuf> {
    let run = RunHeader::new(loaded, plan, None)?;
    let bytes = engine.export().map_err(|e| match e {
        Error::Input(m) => Error::input(format!("save_checkpoint: {m}")),
        other => other,
    })?;
    let outputs = OutputState::default();
    let step = engine.step_count();
    let body = payload(&run, &outputs, step, &bytes, (measurements, None));
    crate::checkpoint::write_to(path, &body)?;
    Ok(path.to_path_buf())
}

/// A checkpoint opened to be continued by its caller.
pub struct Opened(Found);

impl Opened {
    /// The checkpoint file at `path`, or the newest valid one of a run
    /// directory, under its scenario changed by `sets` (`KEY=VALUE`; a
    /// restart, refused by key when a change would not leave the state
    /// meaningful). The files the scenario read must be as they were,
    /// unless `allow_changed_inputs`.
    pub fn open(path: &Path, sets: &[String], allow_changed_inputs: bool) -> Result<Self> {
        let (found, _skipped) = find(path)?;
        found.check_inputs(allow_changed_inputs)?;
        Ok(Self(match sets {
            [] => found,
            _ => found.restart_with_sets(sets)?,
        }))
    }
    /// The scenario the state continues under.
    pub fn loaded(&self) -> &Loaded {
        self.0.loaded()
    }
    /// The run's (relaxation, measured) steps.
    pub fn plan(&self) -> (u64, u64) {
        self.0.plan
    }
    /// The MD engine with the checkpoint's state, and its scenario's
    /// resolved settings.
    pub fn md<D: Dim>(&self) -> Result<(Md<D>, Resolved)> {
        let (md, resolved, _) = self.0.restore_built::<D>()?;
        Ok((md, resolved))
    }
    /// The DSMC engine with the checkpoint's state and measurements.
    pub(crate) fn gas<D: GasDim>(&self) -> Result<Restored<D>> {
        super::dsmc::restore::<D>(&self.0)
    }
}
