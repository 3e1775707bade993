//! Runs a scenario end to end: build the engine, relax, measure, write.
//!
//! Phases, in order: [`prepare`] the output directory (fails early when it is
//! not writable); relax (steps with no output); measure (steps with thermo
//! rows, frames and measurement samples at every output interval); finish
//! (the final frame, pictures, measurement files and summary.json).

pub mod checkpointing;
pub mod distributed;
mod distributed_md;
pub mod dsmc;
pub mod engine;
pub mod flow;
mod md_run;
mod measurements;
mod output;
mod run_loop;
pub mod session;
pub mod sweep_grid;
mod wall_table;

pub use engine::Engine;

use crate::dim::{Dim, D2, D3};
use crate::error::{Error, Result};
use crate::md::Md;
use crate::measure::granular_temperature;
use crate::scenario::schema::Dimension;
use crate::scenario::{build_md, Loaded, Resolved};
use measurements::Measurements;
use serde_json::{json, Map, Value};
use std::path::{Path, PathBuf};

/// What the caller (the command line) chooses beyond the scenario.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    pub out_dir: PathBuf,
    /// Replaces the measured run length (relaxation is then skipped).
    pub steps: Option<u64>,
    /// Write a checkpoint at this interval (see [`checkpointing`]).
    pub checkpoint_every: Option<checkpointing::Every>,
    /// Set (by a signal handler) to stop with a checkpoint at the end of
    /// the current stretch of steps (at most 256 steps on); the summary
    /// then says `"interrupted"`.
    pub stop: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
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

/// Builds the engine of a scenario without running it, and reports what
/// `grains check` prints.
pub fn check(loaded: &Loaded) -> Result<Value> {
    if loaded.scenario.method == crate::dsmc::Method::Dsmc {
        return dsmc::check(loaded);
    }
    fn go<D: Dim>(loaded: &Loaded) -> Result<Value> {
        let loaded = &*crate::scenario::hopper::expand(loaded)?;
        let (md, r) = build_md::<D>(loaded)?;
        flow::FlowRun::begin(loaded, &md)?;
        Ok(resolved_json(loaded, &md, &r))
    }
    match loaded.scenario.dimension {
        Dimension::Two => go::<D2>(loaded),
        Dimension::Three => go::<D3>(loaded),
    }
}

/// Runs a scenario; returns the summary that was written to summary.json.
pub fn run(loaded: &Loaded, opts: &RunOptions, progress: &mut dyn Progress) -> Result<Value> {
    crate::parallel::on_pool(|| run_on_pool(loaded, opts, progress))
}

fn run_on_pool(loaded: &Loaded, opts: &RunOptions, progress: &mut dyn Progress) -> Result<Value> {
    if loaded.scenario.method == crate::dsmc::Method::Dsmc {
        return dsmc::run(loaded, opts, progress);
    }
    match loaded.scenario.dimension {
        Dimension::Two => md_run::run_dim::<D2>(loaded, opts, progress),
        Dimension::Three => md_run::run_dim::<D3>(loaded, opts, progress),
    }
}

/// Creates the output directory and proves it writable before any work.
pub fn prepare(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let probe = dir.join(".grains-write-test");
    std::fs::write(&probe, b"ok").map_err(|e| Error::io(&probe, e))?;
    std::fs::remove_file(&probe).map_err(|e| Error::io(&probe, e))?;
    Ok(())
}

/// The summary scalars every MD run reports: what ran, how long it took
/// (`stepped` steps of this process's timing) and the final energies.
fn md_summary<D: Dim>(
    loaded: &Loaded,
    md: &Md<D>,
    resolved: &Resolved,
    steps: u64,
    stepped: u64,
    wall_seconds: f64,
) -> Map<String, Value> {
    let updates = (stepped.max(1) as f64) * md.particles.n_mobile().max(1) as f64;
    let mut summary = Map::new();
    summary.insert("scenario".into(), json!(loaded.scenario.name));
    summary.insert("dimension".into(), json!(D::NAME));
    summary.insert("particles".into(), json!(md.particles.n_owned()));
    summary.insert("steps".into(), json!(steps));
    summary.insert("time".into(), json!(md.time));
    summary.insert("dt".into(), json!(resolved.dt));
    summary.insert("contact_time".into(), json!(resolved.contact_time));
    summary.insert("wall_seconds".into(), json!(wall_seconds));
    summary.insert(
        "ns_per_particle_step".into(),
        json!(1e9 * wall_seconds / updates),
    );
    summary.insert(
        "kinetic_energy".into(),
        json!(md.particles.kinetic_energy()),
    );
    summary.insert(
        "rotational_energy".into(),
        json!(md.particles.rotational_energy()),
    );
    summary.insert(
        "granular_temperature".into(),
        json!(granular_temperature(&md.particles)),
    );
    summary
}

fn resolved_json<D: Dim>(loaded: &Loaded, md: &Md<D>, r: &Resolved) -> Value {
    let law = &r.law;
    json!({
        "scenario": loaded.scenario.name,
        "source": loaded.origin,
        "dimension": D::NAME,
        "particles": md.particles.n_owned(),
        "frozen": md.particles.n_owned() - md.particles.n_mobile(),
        "walls": md.walls.iter().map(|w| w.name.clone()).collect::<Vec<_>>(),
        "contact": {
            "kn": law.kn, "beta": law.beta, "gamma_n": law.gamma_n, "gamma_t": law.gamma_t,
            "kt": law.kt, "mu": if law.mu.is_finite() { json!(law.mu) } else { json!("inf") },
            "scaling": format!("{:?}", law.scaling).to_lowercase(), "rotation": law.rotation,
        },
        "integrator": md.settings.integrator.name(),
        "contact_time": r.contact_time,
        "dt": r.dt,
        "dt_origin": r.dt_origin,
        "steps_per_contact": r.contact_time / r.dt,
        "cycle_frequency": r.cycle_frequency,
        "relax_steps": r.relax_steps,
        "measure_steps": r.measure_steps,
        "output_every_steps": r.output_every,
        "skin": md.settings.skin,
    })
}

/// How the governor ran an engine's steps: the pool's size, the steps run
/// on all of it and on one thread (they depend on the machine's load, never
/// on the result).
pub(crate) fn threads_json<D: Dim>(md: &Md<D>) -> Value {
    let (wide, narrow) = md.governor.steps_wide_narrow();
    json!({ "pool": rayon::current_num_threads(), "steps_on_pool": wide, "steps_on_one": narrow })
}
