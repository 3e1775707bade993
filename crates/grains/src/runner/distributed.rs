//! Runs a scenario over several ranks (`mpirun -np N grains run ...`).
//!
//! MD scenarios go to [`super::distributed_md`]. DSMC: each rank steps its
//! slab ([`crate::dsmc::decomp`]);
//! at every sampling and output step the ranks gather the whole state on
//! rank 0, into an engine of the same run, and rank 0 measures and writes
//! it with the serial runner's code. The files are therefore the serial
//! run's, byte for byte (summary.json adds `ranks`, `imbalance`,
//! `rebalances`). The gather costs O(N) on rank 0 per sample: for very
//! large runs choose `output.every` and `dsmc.profile_bins` with that in
//! mind.
//!
//! Frames in pieces (`output.frames_layout = "pieces"`): each rank writes
//! its own particles as a piece (ids: serial store positions + 1, as in a
//! gathered frame), rank 0 the `.pvtp`.
//!
//! MD checkpoints and resume: see [`super::distributed_md`]. Not supported
//! yet for DSMC, with a clear error: checkpoints and resume under mpirun
//! (run or resume those on one process). A stop signal ends the run
//! without a checkpoint.

use super::checkpointing::{self, Found};
use super::dsmc::{build, gas_outputs, gas_summary, head, spec};
use super::engine::gas_frame as frame;
use super::options::{prepare, Progress, RunOptions};
use super::output::Pieces;
use crate::comm::Comm;
use crate::dim::{D2, D3};
use crate::dsmc::collide::GasDim;
use crate::dsmc::decomp::Decomposed;
use crate::dsmc::Method;
use crate::error::{Error, Result};
use crate::measure::gas::GasMeasurement as Measure;
use crate::scenario::schema::Dimension;
use crate::scenario::Loaded;
use serde_json::{json, Value};
use std::time::Instant;

/// Runs `loaded` on the ranks of `comm` (all of them call this). Returns the
/// summary on rank 0 and `Value::Null` elsewhere.
pub fn run(
    loaded: &Loaded,
    opts: &RunOptions,
    progress: &mut dyn Progress,
    comm: &dyn Comm,
) -> Result<Value> {
    let md = loaded.scenario.method != Method::Dsmc;
    if opts.checkpoint_every.is_some() && !md {
        return Err(Error::input(
            "--checkpoint-every is not supported for a DSMC run on several ranks yet; \
             run it on one process to checkpoint it",
        ));
    }
    // Not on rayon's pool here (unlike `super::run`): ranks that are
    // threads of one process would each hold a pool worker while waiting
    // for the others. The command line puts its single rank on the pool.
    match loaded.scenario.dimension {
        Dimension::Two if md => super::distributed_md::run::<D2>(loaded, opts, progress, comm),
        Dimension::Three if md => super::distributed_md::run::<D3>(loaded, opts, progress, comm),
        Dimension::Two => run_dim::<D2>(loaded, opts, progress, comm),
        Dimension::Three => run_dim::<D3>(loaded, opts, progress, comm),
    }
}

/// Continues a checkpoint (of a serial or a distributed MD run) on the
/// ranks of `comm`; all of them call this with the same checkpoint. Outputs
/// go to the checkpoint's directory, as with [`checkpointing::resume`].
pub fn resume(
    found: Found,
    steps: Option<u64>,
    opts: RunOptions,
    progress: &mut dyn Progress,
    comm: &dyn Comm,
) -> Result<Value> {
    if found.loaded().scenario.method == Method::Dsmc {
        return Err(Error::input(format!(
            "checkpoint {}: resuming a DSMC run on several ranks is not supported yet; \
             resume it without mpirun",
            found.path.display()
        )));
    }
    let opts = checkpointing::resume_options(&found, opts);
    match found.dim {
        2 => super::distributed_md::resume::<D2>(&found, steps, &opts, progress, comm),
        _ => super::distributed_md::resume::<D3>(&found, steps, &opts, progress, comm),
    }
}

fn run_dim<D: GasDim>(
    loaded: &Loaded,
    opts: &RunOptions,
    progress: &mut dyn Progress,
    comm: &dyn Comm,
) -> Result<Value> {
    let root = comm.rank() == 0;
    if root {
        prepare(&opts.out_dir)?;
    }
    // Every rank builds the same engine; rank 0 keeps a second one to
    // gather the whole state into.
    let (full, plan) = build::<D>(loaded)?;
    let mut mirror = if root {
        Some(build::<D>(loaded)?.0)
    } else {
        None
    };
    let mut summary = head(loaded, &full, &plan);
    let mut dec = Decomposed::new(full, comm).map_err(Error::input)?;
    let mut outputs = match root {
        true => Some(gas_outputs(&opts.out_dir, &loaded.scenario.output)?),
        false => None,
    };
    let (relax, measure) = match opts.steps {
        Some(n) => (0, n),
        None => (plan.relax_steps, plan.measure_steps),
    };
    if let Some(out) = outputs.as_mut() {
        out.set_ranks(comm.size());
    }
    // Frames in pieces: each rank writes its own particles at an output
    // step, with their serial store positions as ids (as when gathered).
    let pieces = Pieces::new(&loaded.scenario.output, &opts.out_dir, comm);
    let write_piece = |dec: &Decomposed<D>| {
        pieces.write(|| {
            let mut f = frame(&dec.sim);
            f.id = dec.keys().iter().map(|k| k + 1).collect();
            f
        })
    };
    let ds = spec(loaded);
    let every = plan.output_every;
    let started = Instant::now();
    if relax > 0 {
        progress.phase("relax", relax);
        for k in 1..=relax {
            dec.step();
            if k % 256 == 0 || k == relax {
                progress.advance(k, dec.sim.time);
            }
        }
    }
    progress.phase("run", measure);
    dec.gather(mirror.as_mut());
    write_piece(&dec)?;
    let mut m = None;
    if let (Some(sim), Some(out)) = (mirror.as_mut(), outputs.as_mut()) {
        let mut mm = Measure::new(sim, &ds);
        // Discard the relaxation's collisions from the validity window.
        mm.validity.sample(sim);
        out.record(&mm.origin.row(sim), &frame(sim), |_| None)?;
        m = Some(mm);
    }
    dec.reset_collisions();
    let profile_every = (every / 10).max(1);
    let profiles = ds.profile_bins > 0;
    for k in 1..=measure {
        dec.step();
        let output = k % every == 0 || k == measure;
        if output || (profiles && k % profile_every == 0) {
            dec.gather(mirror.as_mut());
        }
        if output {
            write_piece(&dec)?;
        }
        if let (Some(sim), Some(mm)) = (mirror.as_mut(), m.as_mut()) {
            if let Some(p) = &mut mm.profiles {
                if k % profile_every == 0 {
                    p.sample(sim);
                }
            }
            if output {
                let out = outputs.as_mut().expect("rank 0 writes");
                out.record(&mm.origin.row(sim), &frame(sim), |_| None)?;
                for w in mm.validity.sample(sim) {
                    eprintln!("warning: {w}");
                }
            }
        }
        if output {
            dec.reset_collisions();
        }
        if k % 256 == 0 || k == measure {
            progress.advance(k, dec.sim.time);
        }
    }
    progress.finish();
    let wall = started.elapsed().as_secs_f64();
    let (Some(sim), Some(m)) = (mirror.as_ref(), m.as_ref()) else {
        return Ok(Value::Null);
    };
    let dir = &opts.out_dir;
    super::output::finish_gas(dir, &loaded.scenario.output, &frame(sim))?;
    if let Some(p) = &m.profiles {
        crate::io::write_atomic(&dir.join("profiles.csv"), p.csv(sim).as_bytes())?;
    }
    let n = sim.store.len() as f64;
    summary.remove("source");
    summary.insert("steps".into(), json!(relax + measure));
    summary.insert("time".into(), json!(sim.time));
    summary.insert("wall_seconds".into(), json!(wall));
    summary.insert(
        "ns_per_particle_step".into(),
        json!(1e9 * wall / ((relax + measure).max(1) as f64 * n)),
    );
    gas_summary(&mut summary, sim, m);
    summary.insert("ranks".into(), json!(comm.size()));
    summary.insert("imbalance".into(), json!(dec.imbalance));
    summary.insert("rebalances".into(), json!(dec.rebalances));
    let summary = Value::Object(summary);
    let text = serde_json::to_string_pretty(&summary).expect("JSON values always serialize");
    crate::io::write_atomic(&dir.join("summary.json"), text.as_bytes())?;
    Ok(summary)
}
