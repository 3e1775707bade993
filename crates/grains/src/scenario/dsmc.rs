//! A `method = "dsmc"` scenario to a DSMC engine: particles placed and
//! drawn from a Maxwellian, axis-aligned plane walls, the cell size, and the
//! time step plan (dt from the mean collision time unless given; relaxation,
//! measured and output steps).

use super::build::{motion, vector};
use super::resolve::cycle_frequency;
use super::schema::{MotionSpec, Placement, ShapeSpec, TimeStep};
use super::Loaded;
use crate::dim::Dim;
use crate::domain::Domain;
use crate::dsmc::collide::GasDim;
use crate::dsmc::engine::{Dsmc, DsmcSettings, PlaneWall};
use crate::dsmc::placement::{gas_in_cell_order, GasDraw, GasVelocity};
use crate::dsmc::store::{particle_volume, Store};
use crate::error::{Error, Result};
use crate::settings::DsmcSpec;
use serde_json::{json, Value};

/// Step counts of a run.
#[derive(Clone, Copy, Debug)]
pub struct Plan {
    pub relax_steps: u64,
    pub measure_steps: u64,
    pub output_every: u64,
}

pub fn spec(loaded: &Loaded) -> DsmcSpec {
    loaded.scenario.dsmc.clone().unwrap_or_default()
}

/// Builds the engine of a DSMC scenario.
pub fn build_dsmc<D: GasDim>(loaded: &Loaded) -> Result<(Dsmc<D>, Plan)> {
    build_dsmc_reporting(loaded, &mut |_| {})
}

/// [`build_dsmc`], telling `report` how the set-up goes (one line per pass
/// of [`gas_in_cell_order`]).
pub fn build_dsmc_reporting<D: GasDim>(
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
    if !s.inlets.is_empty() {
        return Err(Error::input(
            "[[inlets]] belong to method = \"md\"; a DSMC gas takes no inserted grains",
        ));
    }
    if s.output.dump {
        return Err(Error::input(
            "output.dump = true, but method = \"dsmc\" writes no LAMMPS dump (the gas's \
             positions go to the VTK frames, output.frames): remove output.dump or set it \
             to false",
        ));
    }
    if ps.size.is_some() {
        return Err(Error::input(
            "method = \"dsmc\" simulates one diameter: particles.size does not apply",
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
    super::memory::check(
        "particles.count",
        ps.count,
        super::memory::dsmc_bytes_per_particle(D::D),
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
                motion::<D>(&key, &w.motion, &domain)?
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

/// What `grains check` prints of a built DSMC engine and its plan.
pub fn describe<D: GasDim>(loaded: &Loaded, sim: &Dsmc<D>, plan: &Plan) -> Value {
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
