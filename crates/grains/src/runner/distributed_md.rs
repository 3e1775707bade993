//! Runs an MD scenario over several ranks ([`crate::md::decomp`]).
//!
//! Every rank builds the whole engine from the scenario and keeps its box;
//! rank 0 keeps a second whole engine (the "mirror") into which the ranks
//! gather positions, velocities and spins at every sample and output step.
//! Rank 0 then measures and writes with the serial runner's code
//! (thermo.csv, frames, dump, measurement files, summary.json), so the
//! files have the serial run's layout; the numbers agree with a serial run
//! to rounding (see `docs/scaling.md`). The thermo row's contact count is
//! the sum over ranks, in which a contact across a box boundary counts
//! twice (both ranks evaluate it).
//!
//! Refused with a clear error, because they change the grains or walls
//! between steps or measure every step on the whole state: `[hopper]`
//! recycling, `run.events` (settle, wall removal, tilt),
//! `measure.phases` and `measure.trajectories`.

use super::output::Outputs;
use super::{flow, md_summary, prepare, Measurements, Progress, RunOptions};
use crate::comm::Comm;
use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::md::decomp::{index_by_id, DecomposedMd};
use crate::measure::granular_temperature;
use crate::scenario::{build_md, Loaded};
use serde_json::{json, Value};
use std::time::Instant;

/// The first scenario feature that the decomposed run cannot do yet.
fn unsupported(loaded: &Loaded) -> Option<&'static str> {
    let s = &loaded.scenario;
    if s.hopper.is_some() {
        Some("[hopper] (recycling discharged grains)")
    } else if s.run.events.is_some() {
        Some("run.events (settling, wall removal, tilt)")
    } else if s.measure.phases.is_some() {
        Some("measure.phases")
    } else if s.measure.trajectories.is_some() {
        Some("measure.trajectories")
    } else {
        None
    }
}

/// Runs `loaded` (method = "md") on the ranks of `comm`; the summary on
/// rank 0, `Value::Null` elsewhere.
pub fn run<D: Dim>(
    loaded: &Loaded,
    opts: &RunOptions,
    progress: &mut dyn Progress,
    comm: &dyn Comm,
) -> Result<Value> {
    if let Some(feature) = unsupported(loaded) {
        return Err(Error::input(format!(
            "{}: {feature} is not supported on {} MPI ranks yet; run it on one rank with --threads",
            loaded.origin,
            comm.size()
        )));
    }
    let root = comm.rank() == 0;
    if root {
        prepare(&opts.out_dir)?;
    }
    let loaded = &*flow::expand(loaded)?;
    let (full, resolved) = build_md::<D>(loaded)?;
    let mut mirror = if root {
        Some(build_md::<D>(loaded)?.0)
    } else {
        None
    };
    let index = mirror
        .as_ref()
        .map(|m| index_by_id(&m.particles))
        .unwrap_or_default();
    let mut dec = DecomposedMd::with_spec(full, comm, &loaded.scenario.parallel)?;
    let mut outputs = match root {
        true => Some(Outputs::create(&opts.out_dir, &loaded.scenario.output)?),
        false => None,
    };
    let (relax, measure) = match opts.steps {
        Some(n) => (0, n),
        None => (resolved.relax_steps, resolved.measure_steps),
    };
    let every = resolved.output_every;
    let sample_every = (every / 10).max(1);
    let started = Instant::now();
    if relax > 0 {
        progress.phase("relax", relax);
        for k in 1..=relax {
            dec.step()?;
            if k % 256 == 0 || k == relax {
                progress.advance(k, dec.md.time);
            }
        }
    }
    progress.phase("run", measure);
    let gather = |dec: &DecomposedMd<D>, mirror: &mut Option<crate::md::Md<D>>| {
        dec.gather(mirror.as_mut(), &index);
        if let Some(m) = mirror.as_mut() {
            m.stats = dec.md.stats.clone();
        }
    };
    gather(&dec, &mut mirror);
    let mut state = match (mirror.as_ref(), outputs.as_mut()) {
        (Some(m), Some(out)) => {
            let measurements = Measurements::begin(loaded, m, measure, resolved.dt)?;
            let flow = flow::FlowRun::begin(loaded, m)?;
            out.record(m, &m.frame(), granular_temperature(&m.particles))?;
            Some((measurements, flow))
        }
        _ => None,
    };
    for k in 1..=measure {
        dec.step()?;
        let sample = k % sample_every == 0;
        let output = k % every == 0 || k == measure;
        if sample || output {
            gather(&dec, &mut mirror);
        }
        if let (Some(m), Some((measurements, flow)), Some(out)) =
            (mirror.as_ref(), state.as_mut(), outputs.as_mut())
        {
            if sample {
                measurements.sample(m);
                flow.sample(m);
            }
            if output {
                out.record(m, &m.frame(), granular_temperature(&m.particles))?;
            }
        }
        if k % 256 == 0 || k == measure {
            progress.advance(k, dec.md.time);
        }
    }
    progress.finish();
    let wall_seconds = started.elapsed().as_secs_f64();
    let mut ghosts = [dec.n_ghosts() as u64];
    comm.sum_u64(&mut ghosts);
    let (Some(md), Some((mut measurements, flow)), Some(mut outputs)) = (mirror, state, outputs)
    else {
        return Ok(Value::Null);
    };
    measurements.sample(&md);
    let last = md.frame();
    outputs.finish(&last, measurements.displacement.as_ref())?;
    measurements.write(&opts.out_dir, &md, &last)?;
    let steps = relax + measure;
    let mut summary = md_summary(loaded, &md, &resolved, steps, steps, wall_seconds);
    summary.insert("neighbor_builds".into(), json!(dec.neighbor_builds()));
    measurements.scalars(&mut summary);
    flow.finish(&opts.out_dir, &md, &mut summary)?;
    summary.insert("ranks".into(), json!(comm.size()));
    let grid = dec.subdomains().describe(D::D);
    summary.insert("grid".into(), json!(grid));
    summary.insert("migrations".into(), json!(dec.migrations));
    summary.insert("ghosts".into(), json!(ghosts[0]));
    dec.balance.write(&mut summary);
    let summary = Value::Object(summary);
    outputs.write_summary(&summary)?;
    Ok(summary)
}
