//! Resuming a run from a checkpoint (see `docs/checkpoints.md`): the
//! newest valid `checkpoint-<step>.grck` of a run directory ([`find`]),
//! continued with the outputs cut back to where they stood at the
//! checkpoint, so no row or frame is written twice. A restart (the state
//! under a changed scenario, [`Found::restart_with`]) writes a new run's
//! files into a folder of its own instead.

use super::choose::{choose, Runs};
use super::md_run::{run_loop, Start};
use super::options::{prepare, prepare_fresh, Progress, RunOptions};
use crate::checkpoint;
use crate::dim::{Dim, D3};
use crate::dsmc::collide::GasDim;
use crate::error::{Error, Result};
use crate::md::Md;
use crate::output::Outputs;
use serde_json::Value;
use std::path::{Path, PathBuf};

pub use crate::checkpoint::interval::Every;
pub use crate::checkpoint::run::{decode, find, Found};

/// Continues a run from a checkpoint: to the end of its scenario, or for
/// `steps` more steps. Outputs go to the checkpoint's directory.
pub fn resume(
    found: Found,
    steps: Option<u64>,
    opts: RunOptions,
    progress: &mut dyn Progress,
) -> Result<Value> {
    crate::parallel::on_pool(move || resume_on_pool(found, steps, opts, progress))
}

/// The options of a resumed run: its outputs go to the checkpoint's
/// directory (a restart's to the one it was given, which it needs), and it
/// keeps the checkpoint's interval unless given another.
pub(super) fn resume_options(found: &Found, mut opts: RunOptions) -> Result<RunOptions> {
    if found.restart.is_some() {
        if opts.out_dir.as_os_str().is_empty() {
            return Err(Error::input(
                "a restart with changes writes a new run: give it an output directory (--out)",
            ));
        }
        return Ok(opts);
    }
    let dir = found
        .path
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default();
    opts.out_dir = if dir.as_os_str().is_empty() {
        PathBuf::from(".")
    } else {
        dir
    };
    if opts.checkpoint_every.is_none() && found.interval > 0 {
        opts.checkpoint_every = Some(Every::Steps(found.interval));
    }
    Ok(opts)
}

/// Rank 0's (or a single process's) preparation of a resumed run's
/// directory: its own, or a restart's new one claimed as a fresh run's.
pub(super) fn prepare_resume(found: &Found, opts: &RunOptions) -> Result<()> {
    if found.restart.is_some() {
        return prepare_fresh(opts);
    }
    prepare(&opts.out_dir)?;
    checkpoint::remove_stale_temporaries(&opts.out_dir);
    Ok(())
}

/// The output files of a resumed MD run: reopened and cut back to the
/// checkpoint, or a restart's fresh ones.
pub(super) fn resumed_outputs(found: &Found, opts: &RunOptions) -> Result<Outputs> {
    let spec = &found.loaded.scenario.output;
    match found.restart {
        Some(_) => Outputs::create(&opts.out_dir, spec),
        None => Outputs::resume(&opts.out_dir, spec, &found.outputs),
    }
}

fn resume_on_pool(
    found: Found,
    steps: Option<u64>,
    opts: RunOptions,
    progress: &mut dyn Progress,
) -> Result<Value> {
    let opts = resume_options(&found, opts)?;
    prepare_resume(&found, &opts)?;
    struct Resume<'a>(&'a Found, Option<u64>, &'a RunOptions, &'a mut dyn Progress);
    impl Runs for Resume<'_> {
        type Out = Result<Value>;
        fn md<D: Dim>(self) -> Result<Value> {
            let Resume(found, steps, opts, progress) = self;
            let start = restart::<D>(found, steps, opts)?;
            run_loop(&found.loaded, opts, start, progress)
        }
        fn gas<D: GasDim>(self) -> Result<Value> {
            super::dsmc::resume_dim::<D>(self.0, self.1, self.2, self.3)
        }
        fn device(self) -> std::result::Result<Result<Value>, Self> {
            let Resume(found, steps, opts, progress) = self;
            let mut go = || {
                crate::scenario::device::check_device(&found.loaded)?;
                let start = restart::<D3>(found, steps, opts)?;
                super::device_md::run(&found.loaded, opts, start, progress)
            };
            Ok(go())
        }
    }
    choose(
        &found.loaded.scenario,
        Resume(&found, steps, &opts, progress),
    )
}

/// The engine and flow run restored from the checkpoint, the outputs cut
/// back to it.
fn restart<D: Dim>(
    found: &Found,
    steps: Option<u64>,
    opts: &RunOptions,
) -> Result<Start<D, Md<D>>> {
    let mut r = found.restore::<D>(steps)?;
    r.md.timing.reset();
    let outputs = resumed_outputs(found, opts)?;
    Ok(Start {
        flow: Some(r.flow),
        engine: r.md,
        resolved: r.resolved,
        outputs: Some(outputs),
        plan: r.plan,
        restored: r.measurements,
    })
}
