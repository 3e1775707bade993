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
//! Checkpoints (`--checkpoint-every`): at a checkpoint step every rank
//! sends its grains (Gear history, force and torque included) and springs
//! to rank 0, which writes the serial run's checkpoint format from the
//! mirror ([`DecomposedMd::gather_state`]). So `grains resume` continues
//! such a run on one process, and [`resume`] continues any checkpoint on
//! several ranks: every rank restores the whole engine and keeps its box.
//! A stop signal under mpirun ends the run without a checkpoint (the ranks
//! would have to agree on the step); the last interval's checkpoint stays.
//!
//! Flow events (`[hopper]` recycling, `run.events`: settle, wall removal,
//! tilt, sink) run on rank 0's mirror with the serial code and are sent to
//! every rank ([`flow_step`]).
//! The per-step measurements (`measure.phases`, `measure.trajectories`)
//! gather the grains only at the steps where they read them: rank 0 says
//! which (one summed flag per step).

use super::checkpointer::Checkpointer;
use super::checkpointing;
use super::flow;
use super::found::Found;
use super::md_run::md_summary;
use super::measurements::Measurements;
use super::options::{prepare, Progress, RunOptions};
use super::output::Outputs;
use super::run_loop::Saved;
use crate::comm::{Comm, Reader, Writer};
use crate::dim::Dim;
use crate::error::Result;
use crate::md::decomp::{get_vec, index_by_id, put_vec, DecomposedMd};
use crate::md::Md;
use crate::scenario::{build_md, Loaded, Resolved};
use serde_json::{json, Value};
use std::collections::HashMap;
use std::time::Instant;

/// Runs `loaded` (method = "md") on the ranks of `comm`; the summary on
/// rank 0, `Value::Null` elsewhere.
pub fn run<D: Dim>(
    loaded: &Loaded,
    opts: &RunOptions,
    progress: &mut dyn Progress,
    comm: &dyn Comm,
) -> Result<Value> {
    let root = comm.rank() == 0;
    if root {
        prepare(&opts.out_dir)?;
    }
    let loaded = &*crate::scenario::hopper::expand(loaded)?;
    let (full, resolved) = build_md::<D>(loaded)?;
    let mirror = match root {
        true => Some(build_md::<D>(loaded)?.0),
        false => None,
    };
    let outputs = match root {
        true => Some(Outputs::create(&opts.out_dir, &loaded.scenario.output)?),
        false => None,
    };
    let plan = match opts.steps {
        Some(n) => (0, n),
        None => (resolved.relax_steps, resolved.measure_steps),
    };
    let start = Start {
        full,
        mirror,
        resolved,
        outputs,
        plan,
        restored: None,
    };
    drive(loaded, opts, start, progress, comm)
}

/// Continues an MD checkpoint (written by a serial or a distributed run) on
/// the ranks of `comm`: every rank reads it and keeps its box. `opts` as
/// given by [`checkpointing::resume_options`].
pub(super) fn resume<D: Dim>(
    found: &Found,
    steps: Option<u64>,
    opts: &RunOptions,
    progress: &mut dyn Progress,
    comm: &dyn Comm,
) -> Result<Value> {
    let loaded = found.loaded();
    let r = found.restore::<D>(steps)?;
    let root = comm.rank() == 0;
    let (mirror, outputs) = match root {
        true => {
            checkpointing::prepare_resume(opts)?;
            let spec = &loaded.scenario.output;
            let out = Outputs::resume(&opts.out_dir, spec, &found.outputs)?;
            (Some(found.restore_md::<D>()?), Some(out))
        }
        false => (None, None),
    };
    let start = Start {
        full: r.md,
        mirror,
        resolved: r.resolved,
        outputs,
        plan: r.plan,
        restored: r.measurements,
    };
    drive(loaded, opts, start, progress, comm)
}

/// What [`drive`] starts from: the whole engine (every rank), rank 0's
/// mirror and outputs, the (relax, measured) plan, and the measurement
/// accumulators of a checkpoint taken inside the measurement.
struct Start<D: Dim> {
    full: Md<D>,
    mirror: Option<Md<D>>,
    resolved: Resolved,
    outputs: Option<Outputs>,
    plan: (u64, u64),
    restored: Option<Measurements>,
}

/// The run from `start.full.step` to the end of the plan (the serial
/// `run_loop`'s course, decomposed).
fn drive<D: Dim>(
    loaded: &Loaded,
    opts: &RunOptions,
    start: Start<D>,
    progress: &mut dyn Progress,
    comm: &dyn Comm,
) -> Result<Value> {
    let Start {
        full,
        mut mirror,
        resolved,
        mut outputs,
        plan: (relax, measure),
        restored,
    } = start;
    // Every rank makes the checkpointer and the flow run, so a scenario
    // either refuses stops all; rank 0 keeps the flow run (as the serial
    // run, made from the engine before its first step).
    let ckpt = Checkpointer::new(loaded, opts, full.settings.dt, (relax, measure))?;
    let flow = flow::FlowRun::begin(loaded, &full)?;
    // Rank 0 begins the measurements after relaxing; a scenario they refuse
    // (phases without a vibrating wall) must stop every rank now.
    let m = &loaded.scenario.measure;
    let per_step = m.phases.is_some() || m.trajectories.is_some();
    if per_step {
        Measurements::begin(loaded, &full, 0, resolved.dt)?;
    }
    let mut flow = mirror.is_some().then_some(flow);
    let index = mirror
        .as_ref()
        .map(|m| index_by_id(&m.particles))
        .unwrap_or_default();
    let first_step = full.step;
    let mut dec = match first_step {
        0 => DecomposedMd::with_spec(full, comm, &loaded.scenario.parallel)?,
        _ => DecomposedMd::resume(full, comm, &loaded.scenario.parallel)?,
    };
    let every = resolved.output_every;
    let sample_every = (every / 10).max(1);
    if let Some(out) = outputs.as_mut() {
        out.set_ranks(comm.size());
    }
    // Frames in pieces: each rank writes its own grains at an output step.
    let spec = &loaded.scenario.output;
    let pieces = super::output::Pieces::new(spec, &opts.out_dir, comm);
    let write_piece = |dec: &DecomposedMd<D>| pieces.write(|| dec.md.frame());
    let started = Instant::now();
    // A checkpoint at `dec.md.step` when due (all ranks call this).
    let checkpoint = |dec: &DecomposedMd<D>,
                      mirror: &mut Option<Md<D>>,
                      outputs: &Option<Outputs>,
                      meas: Option<&Measurements>|
     -> Result<()> {
        if !ckpt.due(dec.md.step) {
            return Ok(());
        }
        dec.gather_state(mirror.as_mut(), &index)?;
        if let (Some(m), Some(out)) = (mirror.as_ref(), outputs.as_ref()) {
            let saved = Saved {
                outputs: Some(out.state()?),
                measurements: meas.map(Measurements::save),
            };
            ckpt.write(m, &saved)?;
        }
        // The checkpoint wrapped the mirror's grains into the box; the
        // measurements follow the grains as the ranks hold them.
        dec.gather(mirror.as_mut(), &index);
        Ok(())
    };
    if first_step == 0 {
        checkpoint(&dec, &mut mirror, &outputs, None)?;
    }
    let gather = |dec: &DecomposedMd<D>, mirror: &mut Option<Md<D>>| {
        dec.gather(mirror.as_mut(), &index);
        if let Some(m) = mirror.as_mut() {
            m.stats = dec.md.stats.clone();
        }
    };
    let relax_done = dec.md.step.min(relax);
    if relax > relax_done {
        progress.phase("relax", relax);
        for k in relax_done + 1..=relax {
            dec.step()?;
            flow_step(
                loaded,
                &mut dec,
                (&mut mirror, &mut flow, &index),
                &gather,
                comm,
            );
            if k % 256 == 0 || k == relax {
                progress.advance(k, dec.md.time);
            }
            checkpoint(&dec, &mut mirror, &outputs, None)?;
        }
    }
    progress.phase("run", measure);
    let measure_done = dec.md.step - dec.md.step.min(relax);
    gather(&dec, &mut mirror);
    let mut state = match (mirror.as_ref(), outputs.as_mut()) {
        (Some(m), Some(out)) => {
            let measurements = match restored {
                Some(r) => r,
                None => Measurements::begin(loaded, m, measure - measure_done, resolved.dt)?,
            };
            if measure_done == 0 {
                write_piece(&dec)?;
                out.record_md(m)?;
            }
            Some(measurements)
        }
        _ => {
            if measure_done == 0 {
                write_piece(&dec)?;
            }
            None
        }
    };
    for k in measure_done + 1..=measure {
        dec.step()?;
        let mut fresh = flow_step(
            loaded,
            &mut dec,
            (&mut mirror, &mut flow, &index),
            &gather,
            comm,
        );
        if per_step {
            // Rank 0 knows when the measurements read the grains.
            let due = state
                .as_ref()
                .is_some_and(|s| s.due(dec.md.step, dec.md.time));
            let mut any = [u64::from(due)];
            comm.sum_u64(&mut any);
            if any[0] > 0 && !fresh {
                gather(&dec, &mut mirror);
                fresh = true;
            }
            if let (Some(m), Some(measurements)) = (mirror.as_mut(), state.as_mut()) {
                (m.time, m.step) = (dec.md.time, dec.md.step);
                measurements.step(m);
            }
        }
        let sample = k % sample_every == 0;
        let output = k % every == 0 || k == measure;
        if (sample || output) && !fresh {
            gather(&dec, &mut mirror);
        }
        if output {
            write_piece(&dec)?;
        }
        if let (Some(m), Some(measurements), Some(flow), Some(out)) = (
            mirror.as_ref(),
            state.as_mut(),
            flow.as_mut(),
            outputs.as_mut(),
        ) {
            if sample {
                measurements.sample(m);
                flow.sample(m);
            }
            if output {
                out.record_md(m)?;
            }
        }
        if k % 256 == 0 || k == measure {
            progress.advance(k, dec.md.time);
        }
        let meas = state.as_ref();
        checkpoint(&dec, &mut mirror, &outputs, meas)?;
    }
    progress.finish();
    let wall_seconds = started.elapsed().as_secs_f64();
    let mut ghosts = [dec.n_ghosts() as u64];
    comm.sum_u64(&mut ghosts);
    let (Some(md), Some(mut measurements), Some(flow), Some(mut outputs)) =
        (mirror, state, flow, outputs)
    else {
        return Ok(Value::Null);
    };
    measurements.sample(&md);
    let last = md.frame();
    outputs.finish(&last, &md.walls, measurements.displacement.as_ref())?;
    measurements.write(&opts.out_dir, &md, &last)?;
    let steps = relax + measure;
    let mut summary = md_summary(
        loaded,
        &md,
        &resolved,
        steps,
        dec.md.step - first_step,
        wall_seconds,
    );
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

/// Flow events of one step ([`flow::FlowRun::after_step`]) on every rank:
/// rank 0 runs them on the mirror with the serial code, then sends gravity,
/// the walls' removal times and the grains they moved (id, position, frozen)
/// to all ranks, whose owners put their grains there ([`flow::place`]). The
/// mirror is gathered first only when the events read the grains: when some
/// rank holds a mobile grain below the sink (a sum over the ranks), or at a
/// look of `run.events` (its kinetic energy, the pile's top and slope). A
/// moved grain jumps far beyond skin/2, so the next step's rebuild vote
/// migrates it to the rank of its new place. Returns whether the mirror
/// holds this step's state (gathered, then changed as the ranks change it).
///
/// Unlike the serial engine, the mirror never re-sorts its grains: when
/// several grains fall below the sink in one step, they draw their new spots
/// in another order than the serial run does (the same spots, other grains).
fn flow_step<D: Dim>(
    loaded: &Loaded,
    dec: &mut DecomposedMd<D>,
    (mirror, flow, index): MirrorFlow<D>,
    gather: &Gather<D>,
    comm: &dyn Comm,
) -> bool {
    let sink = flow::sink_height(loaded);
    let events = loaded.scenario.run.events.is_some();
    if sink.is_none() && !events {
        return false;
    }
    let v = D::vertical();
    let p = &dec.md.particles;
    let below = sink.map_or(0, |s| {
        (0..p.n_owned())
            .filter(|&i| !p.frozen[i] && D::get(p.pos[i], v) < s)
            .count() as u64
    });
    let mut need = [below];
    comm.sum_u64(&mut need);
    let read = need[0] > 0 || flow::looks_at(loaded, dec.md.step);
    if read {
        gather(dec, mirror);
    } else if !events {
        // Recycling alone changes nothing while no grain is below the sink.
        return false;
    }
    let mut w = Writer::default();
    if let (Some(m), Some(f)) = (mirror.as_mut(), flow.as_mut()) {
        m.time = dec.md.time;
        m.step = dec.md.step;
        let placed = f.after_step(m);
        put_vec::<D>(&mut w, m.settings.gravity);
        for wall in &m.walls {
            w.f64(wall.remove_at.unwrap_or(f64::NAN));
        }
        w.u64(placed.len() as u64);
        for (id, x) in placed {
            w.u64(id);
            put_vec::<D>(&mut w, x);
            w.u64(m.particles.frozen[index[&id]] as u64);
        }
    }
    let all = comm.all_gather_bytes(&w.buf);
    let mut rd = Reader::new(&all[0]);
    let md = &mut dec.md;
    md.settings.gravity = get_vec::<D>(&mut rd);
    for wall in md.walls.iter_mut() {
        let t = rd.f64();
        wall.remove_at = (!t.is_nan()).then_some(t);
    }
    let moved = rd.u64();
    if moved > 0 {
        let p = &mut md.particles;
        let owned = index_by_id(p);
        for _ in 0..moved {
            let (id, x, frozen) = (rd.u64(), get_vec::<D>(&mut rd), rd.u64() != 0);
            if let Some(&i) = owned.get(&id) {
                flow::place(p, i, x);
                p.frozen[i] = frozen;
            }
        }
    }
    read
}

/// Gathers the ranks' grains into rank 0's mirror.
type Gather<'a, D> = dyn Fn(&DecomposedMd<D>, &mut Option<Md<D>>) + 'a;

/// Rank 0's mirror and flow (none elsewhere), and the mirror's index of
/// grain ids (it never re-sorts, so the index built at the start holds).
type MirrorFlow<'a, D> = (
    &'a mut Option<Md<D>>,
    &'a mut Option<flow::FlowRun<D>>,
    &'a HashMap<u64, usize>,
);
