//! Runs a `method = "dsmc"` scenario: build, relax, measure, write
//! thermo.csv, frames, profiles.csv and summary.json.

use super::{prepare, Progress, RunOptions};
use crate::dim::{Dim, D2, D3};
use crate::domain::Domain;
use crate::dsmc::collide::GasDim;
use crate::dsmc::diagnostics::Validity;
use crate::dsmc::engine::{haff_time, maxwellian, Dsmc, DsmcSettings, PlaneWall};
use crate::dsmc::rng::Stream;
use crate::dsmc::spec::DsmcSpec;
use crate::dsmc::store::{particle_volume, Particle, Store};
use crate::error::{Error, Result};
use crate::io::{render_particles, Frame, PictureOptions, ThermoWriter, VtkSeries};
use crate::scenario::build::vector;
use crate::scenario::resolve::cycle_frequency;
use crate::scenario::schema::{Dimension, MotionSpec, Placement, ShapeSpec, TimeStep};
use crate::scenario::Loaded;
use serde_json::{json, Map, Value};
use std::fmt::Write as _;
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

fn spec(loaded: &Loaded) -> DsmcSpec {
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

fn describe<D: GasDim>(loaded: &Loaded, sim: &Dsmc<D>, plan: &Plan) -> Value {
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

fn frame<D: GasDim>(sim: &Dsmc<D>) -> Frame {
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
struct Profiles {
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
    fn sample<D: GasDim>(&mut self, sim: &Dsmc<D>) {
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
    fn csv<D: GasDim>(&self, sim: &Dsmc<D>) -> String {
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

fn run_dim<D: GasDim>(
    loaded: &Loaded,
    opts: &RunOptions,
    progress: &mut dyn Progress,
) -> Result<Value> {
    prepare(&opts.out_dir)?;
    let ds = spec(loaded);
    let (mut sim, plan) = build::<D>(loaded)?;
    let mut summary = match describe(loaded, &sim, &plan) {
        Value::Object(m) => m,
        _ => Map::new(),
    };
    let dir = &opts.out_dir;
    let mut thermo = ThermoWriter::create(&dir.join("thermo.csv"), &THERMO_COLUMNS)?;
    let mut frames = if loaded.scenario.output.frames {
        Some(VtkSeries::new(dir)?)
    } else {
        None
    };
    let (relax, measure) = match opts.steps {
        Some(n) => (0, n),
        None => (plan.relax_steps, plan.measure_steps),
    };
    let every = plan.output_every;
    let started = Instant::now();
    if relax > 0 {
        progress.phase("relax", relax);
        for k in 1..=relax {
            sim.step();
            if k % 256 == 0 || k == relax {
                progress.advance(k, sim.time);
            }
        }
    }
    let t_start = sim.time;
    let temp0 = sim.store.granular_temperature();
    let c0 = sim.totals;
    let n = sim.store.len() as f64;
    let mut validity = Validity::new(&sim, ds.regions);
    let mut profiles = (ds.profile_bins > 0).then(|| Profiles::new(&sim, ds.profile_bins));
    let profile_every = (every / 10).max(1);
    let mut write = |sim: &Dsmc<D>, frames: &mut Option<VtkSeries>| -> Result<()> {
        thermo.write_row(&[
            sim.step as f64,
            sim.time - t_start,
            sim.store.kinetic_energy(),
            sim.store.granular_temperature(),
            2.0 * (sim.totals.collisions - c0.collisions) as f64 / n,
            (sim.totals.candidates - c0.candidates) as f64 / n,
        ])?;
        if let Some(f) = frames {
            f.write(&frame(sim))?;
        }
        Ok(())
    };
    progress.phase("run", measure);
    // Discard the relaxation's collisions from the validity window.
    validity.sample(&mut sim);
    write(&sim, &mut frames)?;
    for k in 1..=measure {
        sim.step();
        if let Some(p) = &mut profiles {
            if k % profile_every == 0 {
                p.sample(&sim);
            }
        }
        if k % every == 0 || k == measure {
            write(&sim, &mut frames)?;
            for w in validity.sample(&mut sim) {
                eprintln!("warning: {w}");
            }
        }
        if k % 256 == 0 || k == measure {
            progress.advance(k, sim.time);
        }
    }
    progress.finish();
    let wall = started.elapsed().as_secs_f64();
    if loaded.scenario.output.picture {
        render_particles(&frame(&sim), &PictureOptions::default())
            .save_png(&dir.join("final.png"))?;
    }
    if let Some(p) = &profiles {
        crate::io::write_atomic(&dir.join("profiles.csv"), p.csv(&sim).as_bytes())?;
    }
    let steps = relax + measure;
    summary.remove("source");
    summary.insert("steps".into(), json!(steps));
    summary.insert("time".into(), json!(sim.time));
    summary.insert("wall_seconds".into(), json!(wall));
    summary.insert(
        "ns_per_particle_step".into(),
        json!(1e9 * wall / (steps.max(1) as f64 * n)),
    );
    summary.insert("kinetic_energy".into(), json!(sim.store.kinetic_energy()));
    summary.insert(
        "granular_temperature".into(),
        json!(sim.store.granular_temperature()),
    );
    summary.insert(
        "collisions".into(),
        json!(sim.totals.collisions - c0.collisions),
    );
    if sim.settings.restitution < 1.0 {
        let omega0 =
            sim.kinetic_collision_frequency(sim.number_density(), sim.packing_fraction(), temp0);
        summary.insert(
            "haff_tau0".into(),
            json!(haff_time(D::D, sim.settings.restitution, omega0)),
        );
        summary.insert("haff_initial_temperature".into(), json!(temp0));
    }
    summary.insert("validity".into(), validity.summary(&sim));
    let summary = Value::Object(summary);
    let text = serde_json::to_string_pretty(&summary).expect("JSON values always serialize");
    crate::io::write_atomic(&dir.join("summary.json"), text.as_bytes())?;
    Ok(summary)
}
