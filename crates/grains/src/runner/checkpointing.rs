//! Resuming a run from a checkpoint (see `docs/checkpoints.md`): the
//! newest valid `checkpoint-<step>.grck` of a run directory ([`find`]),
//! continued with the outputs cut back to where they stood at the
//! checkpoint, so no row or frame is written twice. A restart (the state
//! under a changed scenario, [`Found::restart_with`]) writes a new run's
//! files into a folder of its own instead.

use super::md_run::{run_loop, Start};
use super::options::{prepare, prepare_fresh, Progress, RunOptions};
use crate::checkpoint;
use crate::dim::{Dim, D2, D3};
use crate::error::{Error, Result};
use crate::md::Md;
use crate::output::Outputs;
use serde_json::Value;
use std::path::{Path, PathBuf};

pub use super::options::Every;
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
    if found.loaded.scenario.method == crate::dsmc::Method::Dsmc {
        return super::dsmc::resume(&found, steps, &opts, progress);
    }
    let loaded = &found.loaded;
    if !loaded.scenario.run.device.is_cpu() {
        crate::scenario::device::check_device(loaded)?;
        let start = restart::<D3>(&found, steps, &opts)?;
        return super::device_md::run(loaded, &opts, start, progress);
    }
    match found.dim {
        2 => run_loop(
            loaded,
            &opts,
            restart::<D2>(&found, steps, &opts)?,
            progress,
        ),
        _ => run_loop(
            loaded,
            &opts,
            restart::<D3>(&found, steps, &opts)?,
            progress,
        ),
    }
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
