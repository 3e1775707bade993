//! Runs a `method = "dsmc"` scenario: build, relax, measure, write
//! thermo.csv, frames, profiles.csv and summary.json.

use super::checkpointing::{resume_plan, Checkpointer, Found};
use super::engine::{gas_frame, Engine};
use super::output::Outputs;
use super::run_loop::{run_to, Control, Every, Hook, Interval, Report, Saved, StopFlag};
use super::{prepare, Progress, RunOptions};
use crate::checkpoint::codec::{Dec, DecResult, Enc};
use crate::dim::{Dim, D2, D3};
use crate::domain::Domain;
use crate::dsmc::collide::{GasDim, Tally};
use crate::dsmc::diagnostics::Validity;
use crate::dsmc::engine::{haff_time, maxwellian, Dsmc, DsmcSettings, PlaneWall};
use crate::dsmc::rng::Stream;
use crate::dsmc::spec::DsmcSpec;
use crate::dsmc::store::{particle_volume, Particle, Store};
use crate::error::{Error, Result};
use crate::scenario::build::vector;
use crate::scenario::resolve::cycle_frequency;
use crate::scenario::schema::OutputSpec;
use crate::scenario::schema::{Dimension, MotionSpec, Placement, ShapeSpec, TimeStep};
use crate::scenario::Loaded;
use serde_json::{json, Map, Value};
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// Columns of a DSMC thermo.csv.
pub const THERMO_COLUMNS: [&str; 6] = [
    "step",
    "time",
    "kinetic_energy",
    "granular_temperature",
    "collisions_per_particle",
    "candidates_per_particle",
];

/// Step counts of a run.
#[derive(Clone, Copy, Debug)]
pub struct Plan {
    pub relax_steps: u64,
    pub measure_steps: u64,
    pub output_every: u64,
}

pub(super) fn spec(loaded: &Loaded) -> DsmcSpec {
    loaded.scenario.dsmc.clone().unwrap_or_default()
}

/// Builds the engine of a DSMC scenario.
pub fn build<D: GasDim>(loaded: &Loaded) -> Result<(Dsmc<D>, Plan)> {
    let s = &loaded.scenario;
    let ds = spec(loaded);
    let ps = &s.particles;
    let lo = vector::<D>("domain.lo", &s.domain.lo)?;
    let hi = vector::<D>("domain.hi", &s.domain.hi)?;
    let mut periodic = [false; 3];
    for (a, &p) in s.domain.periodic.iter().enumerate().take(3) {
        periodic[a] = p;
    }
    let domain = Domain::<D>::new(lo, hi, periodic);
    if !(ps.d0.is_finite() && ps.d0 > 0.0 && ps.density > 0.0) {
        return Err(Error::input(
            "particles.d0 and particles.density must be positive",
        ));
    }
    if ps.width != 0.0 {
        return Err(Error::input(
            "method = \"dsmc\" simulates one diameter: particles.width must be 0",
        ));
    }
    if !matches!(ps.placement, Placement::Random | Placement::Lattice) || ps.count == 0 {
        return Err(Error::input(
            "method = \"dsmc\" places particles.count particles uniformly at random in particles.region: use placement = \"random\" and count >= 1",
        ));
    }
    crate::scenario::memory::check(
        "particles.count",
        ps.count,
        crate::scenario::memory::dsmc_bytes_per_particle(D::D),
    )?;
    if !(ds.restitution > 0.0 && ds.restitution <= 1.0) {
        return Err(Error::input("dsmc.restitution must be in (0, 1]"));
    }
    let (rlo, rhi) = match &ps.region {
        Some(r) => (
            vector::<D>("particles.region.lo", &r.lo)?,
            vector::<D>("particles.region.hi", &r.hi)?,
        ),
        None => (lo, hi),
    };
    let mass = ps.mass_model.mass(ps.density, ps.d0);
    let mut rng = Stream::for_purpose(s.seed, 10);
    let p: Vec<Particle<D>> = (0..ps.count)
        .map(|_| {
            let mut x = D::zero();
            for a in 0..D::D {
                let (l, h) = (D::get(rlo, a), D::get(rhi, a));
                D::set(&mut x, a, l + rng.uniform() * (h - l));
            }
            let v = if ds.thermal_speed > 0.0 {
                maxwellian::<D>(&mut rng, ds.thermal_speed)
            } else {
                let mut v = D::zero();
                for a in 0..D::D {
                    D::set(&mut v, a, rng.symmetric() * ps.random_velocity);
                }
                v
            };
            Particle { x, v }
        })
        .collect();
    let store = Store::new(p, ps.d0, mass);
    let gravity = match &s.gravity {
        Some(g) => vector::<D>("gravity", g)?,
        None => D::zero(),
    };
    let mut walls = Vec::new();
    let mut wall_speed: f64 = 0.0;
    for (k, w) in s.walls.iter().enumerate() {
        let key = format!("walls[{k}] ({})", w.name);
        let ShapeSpec::Plane { point, normal } = &w.shape else {
            return Err(Error::input(format!(
                "{key}: method = \"dsmc\" supports plane walls with an axis-aligned normal only"
            )));
        };
        let point = vector::<D>(&format!("{key}.shape.point"), point)?;
        let normal = vector::<D>(&format!("{key}.shape.normal"), normal)?;
        let axis = (0..D::D).find(|&a| D::get(normal, a) != 0.0);
        let Some(axis) = axis.filter(|&a| (0..D::D).all(|b| b == a || D::get(normal, b) == 0.0))
        else {
            return Err(Error::input(format!(
                "{key}: the normal must lie along one axis for method = \"dsmc\""
            )));
        };
        let motion = match &w.motion {
            MotionSpec::Fixed | MotionSpec::Vibrate { .. } | MotionSpec::Translate { .. } => {
                crate::scenario::build::motion::<D>(&key, &w.motion, &domain)?
            }
            _ => {
                return Err(Error::input(format!(
                    "{key}: method = \"dsmc\" supports fixed, vibrate and translate motions"
                )))
            }
        };
        if let MotionSpec::Vibrate {
            amplitude,
            frequency,
            modulation,
            ..
        } = &w.motion
        {
            wall_speed = wall_speed
                .max(std::f64::consts::TAU * frequency * amplitude * (1.0 + modulation.abs()));
        }
        if w.remove_at.is_some() {
            return Err(Error::input(format!(
                "{key}: remove_at is not supported by method = \"dsmc\""
            )));
        }
        walls.push(PlaneWall {
            name: w.name.clone(),
            axis,
            sign: D::get(normal, axis).signum(),
            offset: D::get(point, axis),
            motion,
        });
    }
    let n = ps.count as f64 / domain.volume();
    let cell = match ds.cell_size {
        Some(c) if c > 0.0 => c,
        Some(c) => {
            return Err(Error::input(format!(
                "dsmc.cell_size = {c}: must be positive"
            )))
        }
        None => (ds.particles_per_cell / n).powf(1.0 / D::D as f64),
    };
    let v2 = store.p.iter().map(|q| D::norm2(q.v)).sum::<f64>() / ps.count as f64;
    let t0 = mass * v2 / D::D as f64;
    let nu = n * particle_volume(D::D, ps.d0);
    let settings_probe = |dt: f64| DsmcSettings {
        dt,
        restitution: ds.restitution,
        wall_restitution: ds.wall_restitution.unwrap_or(ds.restitution),
        dense: ds.dense,
        rcp: ds.rcp.unwrap_or(crate::dsmc::dense::default_rcp(D::D)),
        seed: s.seed,
        cell,
        vmax_floor: 2.0 * wall_speed + (gravity_norm::<D>(gravity) * ps.d0).sqrt(),
    };
    let dt = match s.run.dt {
        TimeStep::Seconds(dt) if dt > 0.0 => dt,
        TimeStep::Seconds(dt) => {
            return Err(Error::input(format!("run.dt = {dt}: must be positive")))
        }
        TimeStep::Auto => {
            // A tenth of the mean collision time at the start.
            let omega = crate::dsmc::engine::collision_frequency(
                D::D,
                n,
                ps.d0,
                1.0 / (1.0 - nu / 0.64).max(0.05),
                t0 / mass,
            );
            if omega.is_nan() || omega <= 0.0 {
                return Err(Error::input(
                    "run.dt = \"auto\" needs moving particles (dsmc.thermal_speed or particles.random_velocity); give run.dt in seconds",
                ));
            }
            0.1 / omega
        }
    };
    let sim = Dsmc::new(store, domain, gravity, walls, settings_probe(dt));
    let f = cycle_frequency(s);
    let span = |sec: Option<f64>, cyc: Option<f64>| -> f64 {
        match (sec, cyc, f) {
            (Some(t), _, _) => t,
            (None, Some(c), Some(f)) => c / f,
            _ => 0.0,
        }
    };
    let relax = span(s.run.relax, s.run.relax_cycles);
    let measure = span(s.run.duration, s.run.cycles);
    if measure.is_nan() || measure <= 0.0 {
        return Err(Error::input(
            "the run has no length: give run.duration (s) or run.cycles",
        ));
    }
    let every = s.output.every.unwrap_or(measure / 100.0);
    Ok((
        sim,
        Plan {
            relax_steps: (relax / dt).round() as u64,
            measure_steps: ((measure / dt).round() as u64).max(1),
            output_every: ((every / dt).round() as u64).max(1),
        },
    ))
}

fn gravity_norm<D: Dim>(g: D::V) -> f64 {
    D::norm(g)
}

pub(super) fn describe<D: GasDim>(loaded: &Loaded, sim: &Dsmc<D>, plan: &Plan) -> Value {
    let t = sim.store.granular_temperature();
    let n = sim.number_density();
    let nu = sim.packing_fraction();
    let omega = sim.kinetic_collision_frequency(n, nu, t);
    json!({
        "scenario": loaded.scenario.name,
        "source": loaded.origin,
        "method": "dsmc",
        "dimension": D::NAME,
        "particles": sim.store.len(),
        "walls": sim.walls.iter().map(|w| w.name.clone()).collect::<Vec<_>>(),
        "dt": sim.settings.dt,
        "cell_size": sim.grid.max_edge(),
        "cells": sim.grid.cells(),
        "number_density": n,
        "packing_fraction": nu,
        "diameter": sim.store.diameter,
        "particle_mass": sim.store.mass,
        "restitution": sim.settings.restitution,
        "dense": format!("{:?}", sim.settings.dense),
        "initial_temperature": t,
        "kinetic_collision_frequency": omega,
        "kinetic_mean_free_path": 1.0 / (std::f64::consts::SQRT_2 * n * crate::dsmc::store::cross_section(D::D, sim.store.diameter) * sim.selection().correction.mean_factor(nu)),
        "relax_steps": plan.relax_steps,
        "measure_steps": plan.measure_steps,
        "output_every_steps": plan.output_every,
    })
}

/// What `grains check` prints for a DSMC scenario.
pub fn check(loaded: &Loaded) -> Result<Value> {
    fn go<D: GasDim>(loaded: &Loaded) -> Result<Value> {
        let (sim, plan) = build::<D>(loaded)?;
        Ok(describe(loaded, &sim, &plan))
    }
    match loaded.scenario.dimension {
        Dimension::Two => go::<D2>(loaded),
        Dimension::Three => go::<D3>(loaded),
    }
}

/// Runs a DSMC scenario; returns the summary written to summary.json.
pub fn run(loaded: &Loaded, opts: &RunOptions, progress: &mut dyn Progress) -> Result<Value> {
    match loaded.scenario.dimension {
        Dimension::Two => run_dim::<D2>(loaded, opts, progress),
        Dimension::Three => run_dim::<D3>(loaded, opts, progress),
    }
}

/// Density and temperature versus height, accumulated over samples.
pub(super) struct Profiles {
    lo: f64,
    width: f64,
    count: Vec<f64>,
    vsum: Vec<[f64; 3]>,
    v2: Vec<f64>,
    samples: u64,
}

impl Profiles {
    fn new<D: GasDim>(sim: &Dsmc<D>, bins: usize) -> Self {
        let v = D::vertical();
        let lo = D::get(sim.domain.lo, v);
        Self {
            lo,
            width: sim.domain.length(v) / bins as f64,
            count: vec![0.0; bins],
            vsum: vec![[0.0; 3]; bins],
            v2: vec![0.0; bins],
            samples: 0,
        }
    }
    pub(super) fn sample<D: GasDim>(&mut self, sim: &Dsmc<D>) {
        let bins = self.count.len();
        for q in &sim.store.p {
            let h = (D::get(q.x, D::vertical()) - self.lo) / self.width;
            if h.is_nan() || h < 0.0 || h as usize >= bins {
                continue;
            }
            let b = h as usize;
            self.count[b] += 1.0;
            for a in 0..D::D {
                self.vsum[b][a] += D::get(q.v, a);
            }
            self.v2[b] += D::norm2(q.v);
        }
        self.samples += 1;
    }
    fn encode(&self, e: &mut Enc) {
        e.f64s(&self.count);
        e.len(self.vsum.len());
        self.vsum.iter().flatten().for_each(|&x| e.f64(x));
        e.f64s(&self.v2);
        e.u64(self.samples);
    }
    fn decode(&mut self, d: &mut Dec) -> DecResult<()> {
        let bins = self.count.len();
        let count = d.f64s("profile counts")?;
        let n = d.len(24, "profile velocities")?;
        let mut vsum = Vec::with_capacity(n);
        for _ in 0..n {
            vsum.push([d.f64("profile")?, d.f64("profile")?, d.f64("profile")?]);
        }
        let v2 = d.f64s("profile speeds")?;
        if count.len() != bins || vsum.len() != bins || v2.len() != bins {
            return Err(format!("profiles: the scenario has {bins} bins"));
        }
        (self.count, self.vsum, self.v2) = (count, vsum, v2);
        self.samples = d.u64("profile samples")?;
        Ok(())
    }
    pub(super) fn csv<D: GasDim>(&self, sim: &Dsmc<D>) -> String {
        let mut out = String::from("height,number_density,packing_fraction,granular_temperature\n");
        let slab = sim.domain.volume() / sim.domain.length(D::vertical()) * self.width;
        for b in 0..self.count.len() {
            let c = self.count[b];
            let n = c / (self.samples.max(1) as f64 * slab);
            let t = if c > 1.0 {
                let mean2: f64 = (0..D::D).map(|a| (self.vsum[b][a] / c).powi(2)).sum();
                sim.store.mass * (self.v2[b] / c - mean2) / D::D as f64
            } else {
                0.0
            };
            let _ = writeln!(
                out,
                "{},{},{},{}",
                self.lo + (b as f64 + 0.5) * self.width,
                n,
                n * sim.store.particle_volume(),
                t
            );
        }
        out
    }
}

/// Where the measurement began: the time and the collision tallies its
/// thermo rows count from.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Origin {
    pub(super) t_start: f64,
    pub(super) c0: Tally,
}

impl Origin {
    /// The thermo row of `sim` ([`THERMO_COLUMNS`]).
    pub(super) fn row<D: GasDim>(&self, sim: &Dsmc<D>) -> [f64; 6] {
        let n = sim.store.len() as f64;
        [
            sim.step as f64,
            sim.time - self.t_start,
            sim.store.kinetic_energy(),
            sim.store.granular_temperature(),
            2.0 * (sim.totals.collisions - self.c0.collisions) as f64 / n,
            (sim.totals.candidates - self.c0.candidates) as f64 / n,
        ]
    }
}

/// What the measured part of a run accumulates (absent before it starts).
pub(super) struct Measure {
    pub(super) origin: Origin,
    pub(super) temp0: f64,
    pub(super) validity: Validity,
    pub(super) profiles: Option<Profiles>,
}

impl Measure {
    pub(super) fn new<D: GasDim>(sim: &Dsmc<D>, ds: &DsmcSpec) -> Self {
        Self {
            origin: Origin {
                t_start: sim.time,
                c0: sim.totals,
            },
            temp0: sim.store.granular_temperature(),
            validity: Validity::new(sim, ds.regions),
            profiles: (ds.profile_bins > 0).then(|| Profiles::new(sim, ds.profile_bins)),
        }
    }

    pub(super) fn encode(&self, e: &mut Enc) {
        e.f64(self.origin.t_start);
        e.f64(self.temp0);
        e.u64(self.origin.c0.candidates);
        e.u64(self.origin.c0.collisions);
        self.validity.encode(e);
        e.bool(self.profiles.is_some());
        if let Some(p) = &self.profiles {
            p.encode(e);
        }
    }

    pub(super) fn decode<D: GasDim>(sim: &Dsmc<D>, ds: &DsmcSpec, d: &mut Dec) -> DecResult<Self> {
        let mut m = Self::new(sim, ds);
        m.origin.t_start = d.f64("measure start")?;
        m.temp0 = d.f64("initial temperature")?;
        m.origin.c0 = Tally {
            candidates: d.u64("initial candidates")?,
            collisions: d.u64("initial collisions")?,
        };
        m.validity.decode(d)?;
        let has = d.bool("profiles")?;
        match (&mut m.profiles, has) {
            (Some(p), true) => p.decode(d)?,
            (None, false) => {}
            _ => return Err("profiles: presence differs from the scenario".into()),
        }
        Ok(m)
    }

    /// The measurement state as checkpoint bytes.
    pub(super) fn to_bytes(&self) -> Vec<u8> {
        let mut e = Enc::default();
        self.encode(&mut e);
        e.buf
    }
}

/// Runs a DSMC scenario from step 0.
fn run_dim<D: GasDim>(
    loaded: &Loaded,
    opts: &RunOptions,
    progress: &mut dyn Progress,
) -> Result<Value> {
    prepare(&opts.out_dir)?;
    let (sim, plan) = build::<D>(loaded)?;
    let summary = head(loaded, &sim, &plan);
    let outputs = gas_outputs(&opts.out_dir, &loaded.scenario.output)?;
    let steps = match opts.steps {
        Some(n) => (0, n),
        None => (plan.relax_steps, plan.measure_steps),
    };
    let every = plan.output_every;
    run_loop(
        loaded, opts, sim, every, steps, outputs, None, summary, progress,
    )
}

/// The description of a run as it was built, summary.json's head.
pub(super) fn head<D: GasDim>(loaded: &Loaded, sim: &Dsmc<D>, plan: &Plan) -> Map<String, Value> {
    match describe(loaded, sim, plan) {
        Value::Object(m) => m,
        _ => Map::new(),
    }
}

/// The output files of a DSMC run (thermo columns of a gas, no dump).
pub(super) fn gas_outputs(dir: &Path, spec: &OutputSpec) -> Result<Outputs> {
    Outputs::with_columns(dir, spec, &THERMO_COLUMNS, false)
}

/// Continues a DSMC run from a checkpoint read by
/// [`super::checkpointing::find`].
pub(super) fn resume(
    found: &Found,
    steps: Option<u64>,
    opts: &RunOptions,
    progress: &mut dyn Progress,
) -> Result<Value> {
    match found.dim {
        2 => resume_dim::<D2>(found, steps, opts, progress),
        _ => resume_dim::<D3>(found, steps, opts, progress),
    }
}

/// A DSMC engine restored from a checkpoint.
pub(super) struct Restored<D: GasDim> {
    pub sim: Dsmc<D>,
    pub plan: Plan,
    /// The measurement state, when the checkpoint lies inside the measurement.
    pub measure: Option<Measure>,
    /// The description of the run as it started (before the restore).
    pub head: Map<String, Value>,
}

/// The engine of a DSMC checkpoint, with its scenario's plan.
pub(super) fn restore<D: GasDim>(found: &Found) -> Result<Restored<D>> {
    let loaded = found.loaded();
    let origin = found.path.display().to_string();
    let (mut sim, plan) = build::<D>(loaded)?;
    let head = head(loaded, &sim, &plan);
    sim.import(&found.engine, &origin)?;
    if sim.step != found.step {
        return Err(Error::input(format!(
            "checkpoint {origin}: header step {} but engine step {}",
            found.step, sim.step
        )));
    }
    let ds = spec(loaded);
    let m = match &found.measurements {
        Some(bytes) => {
            let mut d = Dec::new(bytes);
            let m = Measure::decode(&sim, &ds, &mut d).and_then(|m| match d.remaining() {
                0 => Ok(m),
                n => Err(format!("{n} unexpected bytes after the measurements")),
            });
            Some(m.map_err(|e| Error::input(format!("checkpoint {origin}: {e}")))?)
        }
        None => None,
    };
    Ok(Restored {
        sim,
        plan,
        measure: m,
        head,
    })
}

fn resume_dim<D: GasDim>(
    found: &Found,
    steps: Option<u64>,
    opts: &RunOptions,
    progress: &mut dyn Progress,
) -> Result<Value> {
    let loaded = found.loaded();
    let origin = found.path.display().to_string();
    let Restored {
        sim,
        plan,
        measure: m,
        head: summary,
    } = restore::<D>(found)?;
    let (relax, measure) = resume_plan(found.plan, sim.step, steps, &origin)?;
    let outputs = Outputs::resume(&opts.out_dir, &loaded.scenario.output, &found.outputs)?;
    run_loop(
        loaded,
        opts,
        sim,
        plan.output_every,
        (relax, measure),
        outputs,
        m,
        summary,
        progress,
    )
}

/// The output steps of a DSMC run: a thermo row (counted from the start
/// of the measurement `origin`) and a frame; while relaxing it never acts
/// but says where the files stand.
struct GasRecord<'a> {
    outputs: &'a mut Outputs,
    origin: Origin,
    at: Option<Every>,
}

impl<D: GasDim> Hook<Dsmc<D>> for GasRecord<'_> {
    fn next(&self, now: u64, horizon: u64) -> u64 {
        self.at.map_or(horizon, |a| a.next(now, horizon))
    }
    fn act(&mut self, sim: &mut Dsmc<D>, now: u64) -> Result<Control> {
        if self.at.is_some_and(|a| a.due(now)) {
            let row = self.origin.row(sim);
            self.outputs.record(&row, &gas_frame(sim), |_| None)?;
        }
        Ok(Control::Go)
    }
    fn pack(&self, saved: &mut Saved) -> Result<()> {
        saved.outputs = Some(self.outputs.state()?);
        Ok(())
    }
}

/// The measured phase's accumulators: density and temperature profiles
/// every `profile` steps, the validity window at every output step.
struct GasMeasure<'a> {
    m: &'a mut Measure,
    profile: Option<Every>,
    output: Every,
}

impl<D: GasDim> Hook<Dsmc<D>> for GasMeasure<'_> {
    fn next(&self, now: u64, horizon: u64) -> u64 {
        let h = self.output.next(now, horizon);
        self.profile.map_or(h, |p| p.next(now, h))
    }
    fn act(&mut self, sim: &mut Dsmc<D>, now: u64) -> Result<Control> {
        if let (Some(p), Some(at)) = (&mut self.m.profiles, self.profile) {
            if at.due(now) {
                p.sample(sim);
            }
        }
        if self.output.due(now) {
            for w in self.m.validity.sample(sim) {
                eprintln!("warning: {w}");
            }
        }
        Ok(Control::Go)
    }
    fn pack(&self, saved: &mut Saved) -> Result<()> {
        saved.measurements = Some(self.m.to_bytes());
        Ok(())
    }
}

/// The run from wherever `sim` stands (step 0, or a restored checkpoint
/// with its measurement state `m`) to `relax + measure` steps, then the
/// final files.
#[allow(clippy::too_many_arguments)] // the run's whole context, shared by run and resume
fn run_loop<D: GasDim>(
    loaded: &Loaded,
    opts: &RunOptions,
    mut sim: Dsmc<D>,
    every: u64,
    (relax, measure): (u64, u64),
    mut outputs: Outputs,
    m: Option<Measure>,
    mut summary: Map<String, Value>,
    progress: &mut dyn Progress,
) -> Result<Value> {
    let ds = spec(loaded);
    let dir = &opts.out_dir;
    let started = Instant::now();
    let first_step = sim.step;
    let ck = Checkpointer::new(loaded, opts, sim.settings.dt, (relax, measure))?;
    if ck.interval().is_some() && sim.step == 0 {
        let saved = Saved {
            outputs: Some(outputs.state()?),
            measurements: None,
        };
        ck.write(&sim, &saved)?;
    }
    let mut interval = Interval(ck.interval());
    let mut stop = StopFlag(opts.stop.clone());
    if relax > sim.step.min(relax) {
        progress.phase("relax", relax);
        let stopped = {
            let mut record = GasRecord {
                outputs: &mut outputs,
                origin: Origin::default(),
                at: None,
            };
            let mut report = Report::new(progress, 0, relax);
            let mut hooks: [&mut dyn Hook<Dsmc<D>>; 4] =
                [&mut record, &mut report, &mut interval, &mut stop];
            run_to(&mut sim, relax, &mut hooks, &ck)?
        };
        if let Some(summary) = stopped {
            progress.finish();
            return Ok(summary);
        }
    }
    progress.phase("run", measure);
    let mut m = match m {
        Some(m) => m,
        None => {
            let mut m = Measure::new(&sim, &ds);
            // Discard the relaxation's collisions from the validity window.
            m.validity.sample(&mut sim);
            outputs.record(&m.origin.row(&sim), &gas_frame(&sim), |_| None)?;
            m
        }
    };
    // Measured step k is engine step `relax + k`.
    let base = relax;
    let end = base + measure;
    let stopped = {
        let output = Every::new(base, every, Some(end));
        let profile = m
            .profiles
            .is_some()
            .then(|| Every::new(base, (every / 10).max(1), None));
        let mut record = GasRecord {
            outputs: &mut outputs,
            origin: m.origin,
            at: Some(output),
        };
        let mut gas = GasMeasure {
            m: &mut m,
            profile,
            output,
        };
        let mut report = Report::new(progress, base, end);
        let mut hooks: [&mut dyn Hook<Dsmc<D>>; 5] =
            [&mut record, &mut gas, &mut report, &mut interval, &mut stop];
        run_to(&mut sim, end, &mut hooks, &ck)?
    };
    if let Some(summary) = stopped {
        progress.finish();
        return Ok(summary);
    }
    progress.finish();
    let wall = started.elapsed().as_secs_f64();
    super::output::finish_gas(dir, &loaded.scenario.output, &gas_frame(&sim))?;
    if let Some(p) = &m.profiles {
        crate::io::write_atomic(&dir.join("profiles.csv"), p.csv(&sim).as_bytes())?;
    }
    let n = sim.store.len() as f64;
    let steps = relax + measure;
    summary.remove("source");
    summary.insert("steps".into(), json!(steps));
    summary.insert("time".into(), json!(sim.time));
    summary.insert("wall_seconds".into(), json!(wall));
    summary.insert(
        "ns_per_particle_step".into(),
        json!(1e9 * wall / ((sim.step - first_step).max(1) as f64 * n)),
    );
    gas_summary(&mut summary, &sim, &m);
    let summary = Value::Object(summary);
    let text = serde_json::to_string_pretty(&summary).expect("JSON values always serialize");
    crate::io::write_atomic(&dir.join("summary.json"), text.as_bytes())?;
    Ok(summary)
}

/// The gas's state at the end of a run, for summary.json: kinetic energy,
/// temperature, collisions counted while measuring, Haff's τ0 for an
/// inelastic gas, and the validity diagnostics (shared with the
/// distributed runner).
pub(super) fn gas_summary<D: GasDim>(summary: &mut Map<String, Value>, sim: &Dsmc<D>, m: &Measure) {
    summary.insert("kinetic_energy".into(), json!(sim.store.kinetic_energy()));
    summary.insert(
        "granular_temperature".into(),
        json!(sim.store.granular_temperature()),
    );
    summary.insert(
        "collisions".into(),
        json!(sim.totals.collisions - m.origin.c0.collisions),
    );
    if sim.settings.restitution < 1.0 {
        let omega0 =
            sim.kinetic_collision_frequency(sim.number_density(), sim.packing_fraction(), m.temp0);
        summary.insert(
            "haff_tau0".into(),
            json!(haff_time(D::D, sim.settings.restitution, omega0)),
        );
        summary.insert("haff_initial_temperature".into(), json!(m.temp0));
    }
    summary.insert("validity".into(), m.validity.summary(sim));
}
