//! Runs a `method = "dsmc"` scenario: build, relax, measure, write
//! thermo.csv, frames, profiles.csv and summary.json.

use super::checkpointing::{resume_plan, scenario_text, write_payload, RunHeader};
use super::output::Thermo;
use super::output::{frame_series, OutputState};
use super::{prepare, Progress, RunOptions};
use crate::checkpoint::codec::{Dec, DecResult, Enc};
use crate::checkpoint::dsmc as ckdsmc;
use crate::dim::{Dim, D2, D3};
use crate::domain::Domain;
use crate::dsmc::collide::{GasDim, Tally};
use crate::dsmc::diagnostics::Validity;
use crate::dsmc::engine::{haff_time, Dsmc, DsmcSettings, PlaneWall};
use crate::dsmc::spec::DsmcSpec;
use crate::dsmc::store::{particle_volume, Store};
use crate::error::{Error, Result};
use crate::io::{Frame, ThermoWriter, VtkSeries};
use crate::scenario::build::vector;
use crate::scenario::placement::{gas_in_cell_order, GasDraw, GasVelocity};
use crate::scenario::resolve::cycle_frequency;
use crate::scenario::schema::OutputSpec;
use crate::scenario::schema::{Dimension, MotionSpec, Placement, ShapeSpec, TimeStep};
use crate::scenario::Loaded;
use serde_json::{json, Map, Value};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
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
    build_reporting(loaded, &mut |_| {})
}

/// [`build`], telling `report` how the set-up goes (one line per pass of
/// [`gas_in_cell_order`]).
pub fn build_reporting<D: GasDim>(
    loaded: &Loaded,
    report: &mut dyn FnMut(&str),
) -> Result<(Dsmc<D>, Plan)> {
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
    let draw = GasDraw::<D> {
        seed: s.seed,
        purpose: 10,
        lo: rlo,
        hi: rhi,
        velocity: if ds.thermal_speed > 0.0 {
            GasVelocity::Maxwellian {
                thermal_speed: ds.thermal_speed,
            }
        } else {
            GasVelocity::Uniform {
                amplitude: ps.random_velocity,
            }
        },
    };
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
    // Drawn in parallel, straight into the engine's cell order.
    let grid = crate::dsmc::sort::CellGrid::for_domain(&domain, cell);
    let placed = gas_in_cell_order(&draw, ps.count, &grid, report)?;
    let speed_sum = placed.speed_sum;
    let store = Store::new(placed.particles, ps.d0, mass);
    let v2 = speed_sum / ps.count as f64;
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
    let sim = Dsmc::with_speed_sum(store, domain, gravity, walls, settings_probe(dt), speed_sum);
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

pub(super) fn frame<D: GasDim>(sim: &Dsmc<D>) -> Frame {
    let n = sim.store.len();
    let mut periodic = [false; 3];
    periodic[..D::D].copy_from_slice(&sim.domain.periodic[..D::D]);
    let (mut lo, mut hi) = (D::to_xyz(sim.domain.lo), D::to_xyz(sim.domain.hi));
    if D::D == 2 {
        lo[2] = -0.5;
        hi[2] = 0.5;
    }
    Frame {
        step: sim.step,
        time: sim.time,
        dim: D::D,
        box_lo: lo,
        box_hi: hi,
        periodic,
        // DSMC particles carry no identity: ids are store positions.
        id: (1..=n as u64).collect(),
        kind: vec![1; n],
        pos: sim.store.p.iter().map(|q| D::to_xyz(q.x)).collect(),
        vel: sim.store.p.iter().map(|q| D::to_xyz(q.v)).collect(),
        omega: vec![[0.0; 3]; n],
        radius: vec![0.5 * sim.store.diameter; n],
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

/// thermo.csv and the frames of a DSMC run: fresh, or reopened after a
/// resume (cut back to where they stood at the checkpoint).
pub(super) struct Outputs {
    pub(super) dir: PathBuf,
    pub(super) thermo: Thermo,
    pub(super) frames: Option<VtkSeries>,
}

impl Outputs {
    pub(super) fn create(dir: &Path, spec: &OutputSpec) -> Result<Self> {
        Ok(Self {
            dir: dir.to_path_buf(),
            thermo: Thermo::Fresh(ThermoWriter::create(
                &dir.join("thermo.csv"),
                &THERMO_COLUMNS,
            )?),
            frames: frame_series(dir, spec, None)?,
        })
    }

    fn resume(dir: &Path, spec: &OutputSpec, state: &OutputState) -> Result<Self> {
        let path = dir.join("thermo.csv");
        let file = std::fs::OpenOptions::new()
            .write(true)
            .open(&path)
            .map_err(|e| Error::io(&path, e))?;
        let have = file.metadata().map_err(|e| Error::io(&path, e))?.len();
        if have < state.thermo_len {
            return Err(Error::input(format!(
                "{}: {have} bytes, shorter than the {} bytes the checkpoint saw; \
                 the run directory was changed after the checkpoint",
                path.display(),
                state.thermo_len
            )));
        }
        file.set_len(state.thermo_len)
            .map_err(|e| Error::io(&path, e))?;
        drop(file);
        let file = std::fs::OpenOptions::new()
            .append(true)
            .open(&path)
            .map_err(|e| Error::io(&path, e))?;
        let frames = frame_series(dir, spec, Some(&state.frames))?;
        Ok(Self {
            dir: dir.to_path_buf(),
            thermo: Thermo::Appended { path, file },
            frames,
        })
    }

    fn state(&self) -> Result<OutputState> {
        let p = self.dir.join("thermo.csv");
        Ok(OutputState {
            thermo_len: std::fs::metadata(&p).map_err(|e| Error::io(&p, e))?.len(),
            dump_len: None,
            frames: self
                .frames
                .as_ref()
                .map(|f| f.collection.entries.clone())
                .unwrap_or_default(),
            last_step: None,
        })
    }

    pub(super) fn write_row(&mut self, values: &[f64]) -> Result<()> {
        self.thermo.write_row(values)
    }
}

/// What the measured part of a run accumulates (absent before it starts).
pub(super) struct Measure {
    pub(super) t_start: f64,
    pub(super) temp0: f64,
    pub(super) c0: Tally,
    pub(super) validity: Validity,
    pub(super) profiles: Option<Profiles>,
}

impl Measure {
    pub(super) fn new<D: GasDim>(sim: &Dsmc<D>, ds: &DsmcSpec) -> Self {
        Self {
            t_start: sim.time,
            temp0: sim.store.granular_temperature(),
            c0: sim.totals,
            validity: Validity::new(sim, ds.regions),
            profiles: (ds.profile_bins > 0).then(|| Profiles::new(sim, ds.profile_bins)),
        }
    }

    pub(super) fn encode(&self, e: &mut Enc) {
        e.f64(self.t_start);
        e.f64(self.temp0);
        e.u64(self.c0.candidates);
        e.u64(self.c0.collisions);
        self.validity.encode(e);
        e.bool(self.profiles.is_some());
        if let Some(p) = &self.profiles {
            p.encode(e);
        }
    }

    pub(super) fn decode<D: GasDim>(sim: &Dsmc<D>, ds: &DsmcSpec, d: &mut Dec) -> DecResult<Self> {
        let mut m = Self::new(sim, ds);
        m.t_start = d.f64("measure start")?;
        m.temp0 = d.f64("initial temperature")?;
        m.c0 = Tally {
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

/// Writes the checkpoints of a DSMC run. The payload has the layout of the
/// MD runner's (see `checkpointing`), so [`super::checkpointing::find`]
/// reads both; the engine field is a DSMC state
/// ([`crate::checkpoint::dsmc`], tagged) followed by the [`Measure`] state.
struct Checkpoints {
    dir: PathBuf,
    interval: Option<u64>,
    stop: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    scenario: String,
    origin: String,
    base_dir: String,
    plan: (u64, u64),
}

impl Checkpoints {
    fn new(loaded: &Loaded, opts: &RunOptions, dt: f64, plan: (u64, u64)) -> Result<Self> {
        Ok(Self {
            dir: opts.out_dir.clone(),
            interval: opts.checkpoint_every.map(|e| e.steps(dt)),
            stop: opts.stop.clone(),
            scenario: scenario_text(&loaded.scenario)?,
            origin: loaded.origin.clone(),
            base_dir: loaded.base_dir.to_string_lossy().into_owned(),
            plan,
        })
    }

    fn write<D: GasDim>(
        &self,
        sim: &Dsmc<D>,
        out: &Outputs,
        m: Option<&Measure>,
    ) -> Result<PathBuf> {
        let mut eng = Enc {
            buf: ckdsmc::encode(sim),
        };
        eng.bool(m.is_some());
        if let Some(m) = m {
            m.encode(&mut eng);
        }
        let run = RunHeader {
            scenario: &self.scenario,
            origin: &self.origin,
            base_dir: &self.base_dir,
            dim: D::D,
            plan: self.plan,
            interval: self.interval,
        };
        // DSMC keeps its measurement state inside its engine field; the MD
        // measurement section stays empty.
        write_payload(&self.dir, &run, &out.state()?, sim.step, &eng.buf, None)
    }

    /// After each step: a checkpoint at the interval; when a stop was asked
    /// for, a checkpoint and the summary of the interruption.
    fn after_step<D: GasDim>(
        &self,
        sim: &Dsmc<D>,
        out: &Outputs,
        m: Option<&Measure>,
    ) -> Result<Option<Value>> {
        if self.stop.as_ref().is_some_and(|s| s.load(Ordering::SeqCst)) {
            let path = self.write(sim, out, m)?;
            return Ok(Some(json!({
                "interrupted": true,
                "step": sim.step,
                "time": sim.time,
                "checkpoint": path.display().to_string(),
                "message": format!(
                    "stopped at step {} (t = {:.6e} s); checkpoint {}; continue with: grains resume {}",
                    sim.step, sim.time, path.display(), self.dir.display()
                ),
            })));
        }
        if let Some(n) = self.interval {
            if sim.step.is_multiple_of(n) {
                self.write(sim, out, m)?;
            }
        }
        Ok(None)
    }
}

fn run_dim<D: GasDim>(
    loaded: &Loaded,
    opts: &RunOptions,
    progress: &mut dyn Progress,
) -> Result<Value> {
    prepare(&opts.out_dir)?;
    let (sim, plan) = build::<D>(loaded)?;
    let summary = match describe(loaded, &sim, &plan) {
        Value::Object(m) => m,
        _ => Map::new(),
    };
    let outputs = Outputs::create(&opts.out_dir, &loaded.scenario.output)?;
    let steps = match opts.steps {
        Some(n) => (0, n),
        None => (plan.relax_steps, plan.measure_steps),
    };
    run_loop(
        loaded, opts, sim, &plan, steps, outputs, None, summary, progress,
    )
}

/// Continues a DSMC run from a checkpoint read by
/// [`super::checkpointing::find`].
#[allow(clippy::too_many_arguments)]
pub(super) fn resume(
    loaded: &Loaded,
    path: &Path,
    step: u64,
    plan: (u64, u64),
    outputs: &OutputState,
    engine: &[u8],
    steps: Option<u64>,
    opts: &RunOptions,
    progress: &mut dyn Progress,
) -> Result<Value> {
    let args = (path, step, plan, outputs, engine, steps);
    match loaded.scenario.dimension {
        Dimension::Two => resume_dim::<D2>(loaded, args, opts, progress),
        Dimension::Three => resume_dim::<D3>(loaded, args, opts, progress),
    }
}

type ResumeArgs<'a> = (
    &'a Path,
    u64,
    (u64, u64),
    &'a OutputState,
    &'a [u8],
    Option<u64>,
);

fn resume_dim<D: GasDim>(
    loaded: &Loaded,
    (path, step, saved_plan, outputs, engine, steps): ResumeArgs,
    opts: &RunOptions,
    progress: &mut dyn Progress,
) -> Result<Value> {
    let origin = path.display().to_string();
    let (mut sim, plan) = build::<D>(loaded)?;
    // The description of the run as it started (before the restore).
    let summary = match describe(loaded, &sim, &plan) {
        Value::Object(m) => m,
        _ => Map::new(),
    };
    let rest = ckdsmc::restore(&mut sim, engine, &origin)?;
    if sim.step != step {
        return Err(Error::input(format!(
            "checkpoint {origin}: header step {step} but engine step {}",
            sim.step
        )));
    }
    let ds = spec(loaded);
    let mut d = Dec::new(rest);
    let mut read = || -> DecResult<Option<Measure>> {
        let m = if d.bool("measure state")? {
            Some(Measure::decode(&sim, &ds, &mut d)?)
        } else {
            None
        };
        if d.remaining() != 0 {
            return Err(format!("{} unexpected bytes at the end", d.remaining()));
        }
        Ok(m)
    };
    let m = read().map_err(|e| Error::input(format!("checkpoint {origin}: {e}")))?;
    let (relax, measure) = resume_plan(saved_plan, sim.step, steps, &origin.to_string())?;
    let outputs = Outputs::resume(&opts.out_dir, &loaded.scenario.output, outputs)?;
    run_loop(
        loaded,
        opts,
        sim,
        &plan,
        (relax, measure),
        outputs,
        m,
        summary,
        progress,
    )
}

/// The run from wherever `sim` stands (step 0, or a restored checkpoint
/// with its measurement state `m`) to `relax + measure` steps, then the
/// final files.
#[allow(clippy::too_many_arguments)]
fn run_loop<D: GasDim>(
    loaded: &Loaded,
    opts: &RunOptions,
    mut sim: Dsmc<D>,
    plan: &Plan,
    (relax, measure): (u64, u64),
    mut outputs: Outputs,
    m: Option<Measure>,
    mut summary: Map<String, Value>,
    progress: &mut dyn Progress,
) -> Result<Value> {
    let ds = spec(loaded);
    let dir = &opts.out_dir;
    let every = plan.output_every;
    let started = Instant::now();
    let first_step = sim.step;
    let ck = Checkpoints::new(loaded, opts, sim.settings.dt, (relax, measure))?;
    if ck.interval.is_some() && sim.step == 0 {
        ck.write(&sim, &outputs, m.as_ref())?;
    }
    let relax_done = sim.step.min(relax);
    if relax > relax_done {
        progress.phase("relax", relax);
        for k in relax_done + 1..=relax {
            sim.step();
            if k % 256 == 0 || k == relax {
                progress.advance(k, sim.time);
            }
            if let Some(stop) = ck.after_step(&sim, &outputs, None)? {
                progress.finish();
                return Ok(stop);
            }
        }
    }
    let write = |sim: &Dsmc<D>, m: &Measure, outputs: &mut Outputs| -> Result<()> {
        outputs.write_row(&m.row(sim))?;
        if let Some(f) = &mut outputs.frames {
            f.write(&frame(sim))?;
        }
        Ok(())
    };
    progress.phase("run", measure);
    let mut m = match m {
        Some(m) => m,
        None => {
            let mut m = Measure::new(&sim, &ds);
            // Discard the relaxation's collisions from the validity window.
            m.validity.sample(&mut sim);
            write(&sim, &m, &mut outputs)?;
            m
        }
    };
    let profile_every = (every / 10).max(1);
    let measure_done = sim.step - relax;
    for k in measure_done + 1..=measure {
        sim.step();
        if let Some(p) = &mut m.profiles {
            if k % profile_every == 0 {
                p.sample(&sim);
            }
        }
        if k % every == 0 || k == measure {
            write(&sim, &m, &mut outputs)?;
            for w in m.validity.sample(&mut sim) {
                eprintln!("warning: {w}");
            }
        }
        if k % 256 == 0 || k == measure {
            progress.advance(k, sim.time);
        }
        if let Some(stop) = ck.after_step(&sim, &outputs, Some(&m))? {
            progress.finish();
            return Ok(stop);
        }
    }
    progress.finish();
    let wall = started.elapsed().as_secs_f64();
    super::output::finish_gas(dir, &loaded.scenario.output, &frame(&sim))?;
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
        json!(sim.totals.collisions - m.c0.collisions),
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
