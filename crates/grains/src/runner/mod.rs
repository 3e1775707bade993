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
pub mod flow;
mod output;
pub mod session;
pub mod sweep_grid;
mod wall_table;

use crate::checkpoint::codec::{Dec, DecResult, Enc};
use crate::dim::{Dim, D2, D3};
use crate::error::{Error, Result};
use crate::io::Frame;
use crate::md::Md;
use crate::measure::phase::drive;
use crate::measure::{
    granular_temperature, Convection, DisplacementField, FlowField, PhaseSnapshots, Profiles,
    Tracer, Trajectories,
};
use crate::scenario::schema::Dimension;
use crate::scenario::{build_md, Loaded, Resolved};
use output::Outputs;
use serde_json::{json, Map, Value};
use std::path::{Path, PathBuf};
use std::time::Instant;

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
        let loaded = &*flow::expand(loaded)?;
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
        Dimension::Two => run_dim::<D2>(loaded, opts, progress),
        Dimension::Three => run_dim::<D3>(loaded, opts, progress),
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

/// Measurements the scenario asked for.
pub(crate) struct Measurements {
    displacement: Option<DisplacementField>,
    convection: Option<Convection>,
    phases: Option<PhaseSnapshots>,
    tracer: Option<Tracer>,
    profiles: Option<Profiles>,
    trajectories: Option<Trajectories>,
    flow_field: Option<FlowField>,
}

impl Measurements {
    /// `remaining`: steps of the measurement; `dt` the time step.
    fn begin<D: Dim>(loaded: &Loaded, md: &Md<D>, remaining: u64, dt: f64) -> Result<Self> {
        let m = &loaded.scenario.measure;
        let d0 = loaded.scenario.particles.d0;
        let phases = match &m.phases {
            Some(p) => Some(
                PhaseSnapshots::begin(md, &p.phases, p.segment_time, p.displacement_after)
                    .ok_or_else(|| {
                        Error::input("measure.phases needs a vibrating or oscillating wall")
                    })?,
            ),
            None => None,
        };
        let trajectories = match &m.trajectories {
            Some(t) => {
                let f = drive(&md.walls).map(|d| d.0).ok_or_else(|| {
                    Error::input("measure.trajectories needs a vibrating or oscillating wall")
                })?;
                let window = (t.cycles / (f * dt)).round() as u64;
                Some(Trajectories::new(md, t.every, remaining, window))
            }
            None => None,
        };
        if let Some(p) = &m.profiles {
            if !(p.bin.is_finite() && p.bin > 0.0) {
                return Err(Error::input(format!(
                    "measure.profiles.bin = {}: must be positive (units of d0)",
                    p.bin
                )));
            }
        }
        let flow_field = match &m.flow_field {
            Some(f) => Some(FlowField::for_md(md, &f.cells, f.from, f.top)?),
            None => None,
        };
        Ok(Self {
            flow_field,
            displacement: m.displacement.then(|| DisplacementField::begin(md)),
            convection: m.convection.as_ref().map(|c| Convection::new(c.band)),
            phases,
            tracer: m.tracer.as_ref().map(|t| Tracer::new(t.id)),
            profiles: m.profiles.as_ref().map(|p| Profiles::new(md, p.bin * d0)),
            trajectories,
        })
    }

    /// The accumulators as checkpoint bytes: for each measurement in a
    /// fixed order a presence flag, then its state.
    fn save(&self) -> Vec<u8> {
        let mut e = Enc::default();
        fn one<T>(e: &mut Enc, m: &Option<T>, save: impl Fn(&T, &mut Enc)) {
            e.bool(m.is_some());
            if let Some(m) = m {
                save(m, e);
            }
        }
        one(&mut e, &self.displacement, DisplacementField::save);
        one(&mut e, &self.convection, Convection::save);
        one(&mut e, &self.phases, PhaseSnapshots::save);
        one(&mut e, &self.tracer, Tracer::save);
        one(&mut e, &self.profiles, Profiles::save);
        one(&mut e, &self.trajectories, Trajectories::save);
        // Last, so that checkpoints from before it existed still load.
        if let Some(f) = &self.flow_field {
            e.bool(true);
            f.save(&mut e);
        }
        e.buf
    }

    /// The accumulators saved by [`Measurements::save`]; each must be present
    /// exactly when the scenario asks for it.
    fn load<D: Dim>(
        loaded: &Loaded,
        md: &Md<D>,
        bytes: &[u8],
    ) -> std::result::Result<Self, String> {
        let m = &loaded.scenario.measure;
        let mut d = Dec::new(bytes);
        fn one<T>(
            d: &mut Dec,
            name: &str,
            want: bool,
            load: impl Fn(&mut Dec) -> DecResult<T>,
        ) -> DecResult<Option<T>> {
            let has = d.bool(name)?;
            if has != want {
                return Err(format!(
                    "measurement {name}: {} in the checkpoint but {} in the scenario",
                    if has { "present" } else { "absent" },
                    if want { "asked for" } else { "not asked for" }
                ));
            }
            has.then(|| load(d)).transpose()
        }
        let out = Self {
            displacement: one(
                &mut d,
                "displacement",
                m.displacement,
                DisplacementField::load,
            )?,
            convection: one(
                &mut d,
                "convection",
                m.convection.is_some(),
                Convection::load,
            )?,
            phases: one(&mut d, "phases", m.phases.is_some(), PhaseSnapshots::load)?,
            tracer: one(&mut d, "tracer", m.tracer.is_some(), Tracer::load)?,
            profiles: one(&mut d, "profiles", m.profiles.is_some(), Profiles::load)?,
            trajectories: one(
                &mut d,
                "trajectories",
                m.trajectories.is_some(),
                Trajectories::load,
            )?,
            flow_field: None,
        };
        let mut out = out;
        // Written only when asked for (see `save`).
        let has_flow = d.remaining() > 0 && d.bool("flow_field")?;
        match (&m.flow_field, has_flow) {
            (Some(f), true) => {
                let fresh =
                    FlowField::for_md(md, &f.cells, f.from, f.top).map_err(|e| e.to_string())?;
                out.flow_field = Some(fresh.load(&mut d)?);
            }
            (None, false) => {}
            (want, _) => {
                return Err(format!(
                    "measurement flow_field: {} in the checkpoint but {} in the scenario",
                    if has_flow { "present" } else { "absent" },
                    if want.is_some() {
                        "asked for"
                    } else {
                        "not asked for"
                    }
                ))
            }
        }
        if d.remaining() != 0 {
            return Err(format!(
                "{} unexpected bytes after the measurements",
                d.remaining()
            ));
        }
        Ok(out)
    }

    /// Whether [`Self::step`] after engine step `step` at time `t` reads the
    /// grains (a decomposed run gathers them then). At any other step it
    /// only notes the drive's phase, so the serial runner skips it: judged
    /// from an older phase the answer is the same, as no target phase (nor
    /// cycle start) was crossed in between — else that step was due.
    fn due(&self, step: u64, t: f64) -> bool {
        self.phases.as_ref().is_some_and(|p| p.due(t))
            || self.trajectories.as_ref().is_some_and(|x| x.due(step))
    }

    /// After every step (phase- and step-exact measurements).
    fn step<D: Dim>(&mut self, md: &Md<D>) {
        if let Some(p) = &mut self.phases {
            p.step(md);
        }
        if let Some(t) = &mut self.trajectories {
            t.step(md);
        }
    }

    fn sample<D: Dim>(&mut self, md: &Md<D>) {
        if let Some(d) = &mut self.displacement {
            d.sample(md);
        }
        if let Some(c) = &mut self.convection {
            c.sample(md);
        }
        if let Some(t) = &mut self.tracer {
            t.sample(md);
        }
        if let Some(p) = &mut self.profiles {
            p.sample(md);
        }
        if let Some(f) = &mut self.flow_field {
            f.sample(md);
        }
    }

    fn write<D: Dim>(&self, dir: &Path, md: &Md<D>, last: &Frame) -> Result<()> {
        if let Some(c) = &self.convection {
            c.write(dir, &md.domain)?;
        }
        if let Some(p) = &self.phases {
            p.write(dir, &md.walls)?;
        }
        if let Some(t) = &self.tracer {
            t.write(dir, last)?;
        }
        if let Some(p) = &self.profiles {
            p.write(dir)?;
        }
        if let Some(t) = &self.trajectories {
            t.write(dir, last, &md.walls)?;
        }
        if let Some(f) = &self.flow_field {
            f.write(dir, last, &md.walls)?;
        }
        Ok(())
    }

    fn scalars(&self, summary: &mut Map<String, Value>) {
        if let Some(c) = &self.convection {
            summary.insert("convection_center_vz".into(), json!(c.center_vz()));
            summary.insert("convection_edge_vz".into(), json!(c.edge_vz()));
            summary.insert(
                "convection_strength".into(),
                json!(c.center_vz() - c.edge_vz()),
            );
            summary.insert("heap_height".into(), json!(c.heap_height()));
        }
        if let Some(t) = &self.tracer {
            summary.insert("tracer_rms".into(), json!(t.rms_spread()));
        }
        if let Some(p) = &self.profiles {
            summary.insert("transport_velocity".into(), json!(p.transport_velocity()));
        }
    }
}

fn run_dim<D: Dim>(
    loaded: &Loaded,
    opts: &RunOptions,
    progress: &mut dyn Progress,
) -> Result<Value> {
    prepare(&opts.out_dir)?;
    let loaded = &*flow::expand(loaded)?;
    let (md, resolved) = build_md::<D>(loaded)?;
    let outputs = Outputs::create(&opts.out_dir, &loaded.scenario.output)?;
    let (relax, measure) = match opts.steps {
        Some(n) => (0, n),
        None => (resolved.relax_steps, resolved.measure_steps),
    };
    run_loop(
        loaded,
        opts,
        md,
        &resolved,
        outputs,
        (relax, measure),
        None,
        progress,
    )
}

/// Steps between progress reports; also the longest stretch the run loop
/// advances without looking at a stop request.
const PROGRESS_EVERY: u64 = 256;

/// The step that ends the stretch after step `from`: the first step before
/// `end` after which a hook reads or changes the run (`hooks`), else `end`.
/// How the governor ran an engine's steps: the pool's size, the steps run
/// on all of it and on one thread (they depend on the machine's load, never
/// on the result).
pub(crate) fn threads_json<D: Dim>(md: &Md<D>) -> Value {
    let (wide, narrow) = md.governor.steps_wide_narrow();
    json!({ "pool": rayon::current_num_threads(), "steps_on_pool": wide, "steps_on_one": narrow })
}

/// The run loop advances to it with [`Md::advance`] (the fused pass) and
/// runs its hooks there only: at the steps in between they do nothing.
fn stretch_end(from: u64, end: u64, hooks: impl Fn(u64) -> bool) -> u64 {
    (from + 1..end).find(|&k| hooks(k)).unwrap_or(end)
}

/// The run loop from wherever `md` stands (step 0, or a restored
/// checkpoint) to `relax + measure` steps, then the final files.
#[allow(clippy::too_many_arguments)] // the loop's whole context, shared by run and resume
fn run_loop<D: Dim>(
    loaded: &Loaded,
    opts: &RunOptions,
    mut md: Md<D>,
    resolved: &Resolved,
    mut outputs: Outputs,
    (relax, measure): (u64, u64),
    restored: Option<Measurements>,
    progress: &mut dyn Progress,
) -> Result<Value> {
    let started = Instant::now();
    md.timing.reset();
    let first_step = md.step;
    let mut ckpt = checkpointing::Checkpointer::new(loaded, opts, &md, (relax, measure))?;
    ckpt.at_start(&md, &outputs)?;
    let mut flow = flow::FlowRun::begin(loaded, &md)?;
    let mut walls_csv = wall_table::WallTable::create(&opts.out_dir, &md)?;
    // Sampling more often than the output keeps the displacement unwrapping
    // safe and the convection average smooth.
    let every = resolved.output_every;
    let sample_every = (every / 10).max(1);

    let relax_done = md.step.min(relax);
    if relax > relax_done {
        progress.phase("relax", relax);
        let mut k = relax_done;
        while k < relax {
            // Relaxing, step k is engine step k.
            let hooks = |j: u64| j.is_multiple_of(PROGRESS_EVERY) || flow.acts_at(j) || ckpt.due(j);
            let next = stretch_end(k, relax, hooks);
            md.advance(next - k)?;
            k = next;
            flow.after_step(&mut md);
            if k.is_multiple_of(PROGRESS_EVERY) || k == relax {
                progress.advance(k, md.time);
            }
            if let Some(stop) = ckpt.after_step(&md, &outputs, None)? {
                progress.finish();
                return Ok(stop);
            }
        }
    }
    progress.phase("run", measure);
    // Measured steps already done: none in a straight run after relaxing
    // (md.step == relax here), some when resumed inside the measurement.
    let measure_done = md.step - md.step.min(relax);
    // A checkpoint taken during the measurement carries its accumulators;
    // one taken before it (relaxation, step 0) does not, and they begin here
    // as in a straight run.
    let mut measurements = match restored {
        Some(m) => m,
        None => Measurements::begin(loaded, &md, measure - measure_done, resolved.dt)?,
    };
    if measure_done == 0 {
        outputs.record(&md, &md.frame(), granular_temperature(&md.particles))?;
        if let Some(w) = &mut walls_csv {
            w.record(&md)?;
        }
    }
    // Measured step k is engine step `base + k`, at time (base + k) dt (as
    // `Md::step` sets it).
    let base = md.step - measure_done;
    let dt = md.settings.dt;
    let mut k = measure_done;
    while k < measure {
        let hooks = |j: u64| {
            let step = base + j;
            j.is_multiple_of(PROGRESS_EVERY)
                || j.is_multiple_of(sample_every)
                || j.is_multiple_of(every)
                || flow.acts_at(step)
                || measurements.due(step, step as f64 * dt)
                || ckpt.due(step)
        };
        let next = stretch_end(k, measure, hooks);
        md.advance(next - k)?;
        k = next;
        flow.after_step(&mut md);
        measurements.step(&md);
        if k.is_multiple_of(sample_every) {
            measurements.sample(&md);
            flow.sample(&md);
        }
        if k.is_multiple_of(every) || k == measure {
            outputs.record(&md, &md.frame(), granular_temperature(&md.particles))?;
            if let Some(w) = &mut walls_csv {
                w.record(&md)?;
            }
        }
        if k.is_multiple_of(PROGRESS_EVERY) || k == measure {
            progress.advance(k, md.time);
        }
        if let Some(stop) = ckpt.after_step(&md, &outputs, Some(&measurements))? {
            progress.finish();
            return Ok(stop);
        }
    }
    measurements.sample(&md);
    progress.finish();
    let wall_seconds = started.elapsed().as_secs_f64();

    let last = md.frame();
    outputs.finish(&last, &md.walls, measurements.displacement.as_ref())?;
    measurements.write(&opts.out_dir, &md, &last)?;
    let steps = relax + measure;
    let mut summary = md_summary(
        loaded,
        &md,
        resolved,
        steps,
        md.step - first_step,
        wall_seconds,
    );
    summary.insert("neighbor_builds".into(), json!(md.neighbor_builds()));
    // Seconds per phase of the step; `other` is mostly measurements and output.
    let phases = md.timing.to_json(wall_seconds, 1.0);
    summary.insert("phase_seconds".into(), phases);
    summary.insert("threads".into(), threads_json(&md));
    measurements.scalars(&mut summary);
    flow.finish(&opts.out_dir, &md, &mut summary)?;
    let summary = Value::Object(summary);
    outputs.write_summary(&summary)?;
    Ok(summary)
}
