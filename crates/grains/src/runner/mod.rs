//! Runs a scenario end to end: build the engine, relax, measure, write.
//!
//! Phases, in order: [`prepare`] the output directory (fails early when it is
//! not writable); relax (steps with no output); measure (steps with thermo
//! rows, frames and measurement samples at every output interval); finish
//! (the final frame, pictures, measurement files and summary.json).

pub(crate) mod checkpointer;
pub mod checkpointing;
mod device_md;
pub mod distributed;
mod distributed_md;
pub mod dsmc;
pub mod engine;
pub(crate) mod found;
pub(crate) mod md_run;
mod options;
mod run_loop;

pub use engine::Engine;
pub use options::{prepare, prepare_fresh, Progress, RunOptions, Silent};

use crate::dim::{Dim, D2, D3};
use crate::error::Result;
use crate::md::Md;
use crate::scenario::schema::Dimension;
use crate::scenario::{build_md, Loaded, Resolved};
use serde_json::{json, Value};

/// Builds the engine of a scenario without running it, and reports what
/// `grains check` prints.
pub fn check(loaded: &Loaded) -> Result<Value> {
    if loaded.scenario.method == crate::dsmc::Method::Dsmc {
        return dsmc::check(loaded);
    }
    fn go<D: Dim>(loaded: &Loaded) -> Result<Value> {
        let loaded = &*crate::scenario::hopper::expand(loaded)?;
        let (md, r) = build_md::<D>(loaded)?;
        crate::scenario::flow::FlowRun::begin(loaded, &md)?;
        resolved_json(loaded, &md, &r)
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
    crate::scenario::device::check_device(loaded)?;
    if loaded.scenario.method == crate::dsmc::Method::Dsmc {
        return dsmc::run(loaded, opts, progress);
    }
    if !loaded.scenario.run.device.is_cpu() {
        return device_md::run_fresh(loaded, opts, progress);
    }
    match loaded.scenario.dimension {
        Dimension::Two => md_run::run_dim::<D2>(loaded, opts, progress),
        Dimension::Three => md_run::run_dim::<D3>(loaded, opts, progress),
    }
}

fn resolved_json<D: Dim>(loaded: &Loaded, md: &Md<D>, r: &Resolved) -> Result<Value> {
    use crate::scenario::law_report;
    let law = &r.law;
    // Under materials the law is the pair table's; `r.law` is only the
    // stand-in the time step was taken from.
    let contact = match &md.settings.materials {
        Some(m) => law_report::material_law(&loaded.scenario, md, m)?,
        None => json!({
            "kn": law.kn, "beta": law.beta, "gamma_n": law.gamma_n, "gamma_t": law.gamma_t,
            "kt": law.kt, "mu": if law.mu.is_finite() { json!(law.mu) } else { json!("inf") },
            "scaling": format!("{:?}", law.scaling).to_lowercase(), "rotation": law.rotation,
        }),
    };
    Ok(json!({
        "scenario": loaded.scenario.name,
        "source": loaded.origin,
        "dimension": D::NAME,
        "particles": md.particles.n_owned(),
        "sizes": crate::scenario::sizes::report(loaded)?,
        "frozen": md.particles.n_owned() - md.particles.n_mobile(),
        "walls": md.walls.iter().map(|w| w.name.clone()).collect::<Vec<_>>(),
        "contact": contact,
        "integrator": md.settings.integrator.name(),
        "time_step": law_report::time_step(md, r),
        "contact_time": r.contact_time,
        "dt": r.dt,
        "dt_origin": r.dt_origin,
        "steps_per_contact": r.contact_time / r.dt,
        "cycle_frequency": r.cycle_frequency,
        "relax_steps": r.relax_steps,
        "measure_steps": r.measure_steps,
        "output_every_steps": r.output_every,
        "skin": md.settings.skin,
        "memory": law_report::memory(md),
    }))
}
