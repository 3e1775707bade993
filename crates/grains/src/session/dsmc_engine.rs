//! The DSMC engine of a [`super::Session`]. DSMC particles carry no
//! identity: their ids are their places in the store (1..=n), which the
//! engine reorders by cell every few steps, as in the runner's frames.

use super::held::{Column, Contacts, Held};
use crate::dsmc::collide::GasDim;
use crate::dsmc::engine::Dsmc;
use crate::engine::Engine;
use crate::error::{Error, Result};
use crate::measure::gas::GasMeasurement as Measure;
use crate::measure::gas::{gas_summary, THERMO_COLUMNS};
use crate::runner::saved::Opened;
use crate::scenario::dsmc::{build_dsmc, describe, spec, Plan};
use crate::scenario::Loaded;
use serde_json::{json, Map, Value};

struct DsmcEngine<D: GasDim> {
    sim: Dsmc<D>,
    /// The validity window and the collision tallies at the start, as the
    /// runner's measurement keeps them.
    measure: Measure,
    /// The description of the run as it was built (summary.json's head).
    head: Map<String, Value>,
}

type Built = (Box<dyn Held>, (u64, u64), u64);

/// The engine `grains run` builds for a DSMC scenario, its (relaxation,
/// measured) steps and its output interval; its measurement starts now,
/// as that of `grains run --steps`.
pub(super) fn build<D: GasDim>(loaded: &Loaded) -> Result<Built> {
    let (mut sim, plan) = build_dsmc::<D>(loaded)?;
    let head = head(loaded, &sim, &plan);
    let mut measure = Measure::new(&sim, &spec(loaded));
    // The runner discards the collisions before its measurement likewise.
    measure.validity.sample(&mut sim);
    let steps = (plan.relax_steps, plan.measure_steps);
    let every = plan.output_every;
    let engine = DsmcEngine { sim, measure, head };
    Ok((Box::new(engine), steps, every))
}

fn head<D: GasDim>(loaded: &Loaded, sim: &Dsmc<D>, plan: &Plan) -> Map<String, Value> {
    match describe(loaded, sim, plan) {
        Value::Object(mut m) => {
            m.remove("source");
            m
        }
        _ => Map::new(),
    }
}

/// The engine of a DSMC checkpoint (with its measurement state) and its
/// output interval.
pub(super) fn restore<D: GasDim>(opened: &Opened) -> Result<(Box<dyn Held>, u64)> {
    let loaded = opened.loaded();
    let r = opened.gas::<D>()?;
    let (sim, plan, measure) = (r.sim, r.plan, r.measure);
    let mut head = r.head;
    head.remove("source");
    let measure = measure.unwrap_or_else(|| Measure::new(&sim, &spec(loaded)));
    let every = plan.output_every;
    let engine = DsmcEngine { sim, measure, head };
    Ok((Box::new(engine), every))
}

impl<D: GasDim> Held for DsmcEngine<D> {
    fn engine(&self) -> &dyn Engine {
        &self.sim
    }
    fn engine_mut(&mut self) -> &mut dyn Engine {
        &mut self.sim
    }
    fn len(&self) -> usize {
        self.sim.store.len()
    }
    fn thermo_columns(&self) -> &'static [&'static str] {
        &THERMO_COLUMNS
    }
    fn thermo_row(&self) -> Vec<f64> {
        self.measure.origin.row(&self.sim).to_vec()
    }
    fn after_output(&mut self) {
        // Warnings are kept in the summary's validity section.
        let _ = self.measure.validity.sample(&mut self.sim);
    }
    fn ids(&self) -> Vec<u64> {
        (1..=self.sim.store.len() as u64).collect()
    }
    fn fill(&self, col: Column, out: &mut [f64]) {
        let store = &self.sim.store;
        let vector = |out: &mut [f64], get: &dyn Fn(usize) -> D::V| {
            for (k, o) in out.chunks_exact_mut(D::D).enumerate() {
                o.copy_from_slice(&D::to_xyz(get(k))[..D::D]);
            }
        };
        match col {
            Column::Positions => vector(out, &|k| store.p[k].x),
            Column::Velocities => vector(out, &|k| store.p[k].v),
            // Point particles: no spin.
            Column::AngularVelocities => out.fill(0.0),
            Column::Diameters => out.fill(store.diameter),
            Column::Masses => out.fill(store.mass),
        }
    }
    fn frozen(&self) -> Vec<bool> {
        vec![false; self.len()]
    }
    fn set_state(&mut self, pos: Option<&[f64]>, vel: Option<&[f64]>) -> Result<()> {
        for (what, v) in [("positions", pos), ("velocities", vel)] {
            if let Some(k) = v.and_then(|v| v.iter().position(|x| !x.is_finite())) {
                return Err(Error::input(format!(
                    "{what}: row {} is not finite: every component must be a finite number",
                    k / D::D
                )));
            }
        }
        if let Some(pos) = pos {
            let (lo, hi) = (D::to_xyz(self.sim.domain.lo), D::to_xyz(self.sim.domain.hi));
            for (k, c) in pos.chunks_exact(D::D).enumerate() {
                if let Some(a) = (0..D::D).find(|&a| !(lo[a]..=hi[a]).contains(&c[a])) {
                    return Err(Error::input(format!(
                        "positions: row {k} lies outside the domain on axis {a} ({} not in [{}, {}])",
                        c[a], lo[a], hi[a]
                    )));
                }
            }
        }
        let p = &mut self.sim.store.p;
        let set = |flat: &[f64], k: usize| {
            let mut x = [0.0; 3];
            x[..D::D].copy_from_slice(&flat[k * D::D..(k + 1) * D::D]);
            D::from_xyz(x)
        };
        for (k, q) in p.iter_mut().enumerate() {
            if let Some(pos) = pos {
                q.x = set(pos, k);
            }
            if let Some(vel) = vel {
                q.v = set(vel, k);
            }
        }
        // The cells of the moved particles.
        self.sim.sort_now();
        Ok(())
    }
    fn kinetic_energy(&self) -> f64 {
        self.sim.store.kinetic_energy()
    }
    fn rotational_energy(&self) -> f64 {
        0.0
    }
    fn granular_temperature(&self) -> f64 {
        self.sim.store.granular_temperature()
    }
    fn contacts(&self) -> Result<Contacts> {
        Err(Error::input(
            "contacts: a DSMC gas has no lasting contacts (method = \"dsmc\"); \
             its collisions are counted in the thermo table and the summary",
        ))
    }
    fn summary(&self, _: &Loaded, stepped: u64, wall_seconds: f64) -> Map<String, Value> {
        let sim = &self.sim;
        let mut s = self.head.clone();
        s.insert("steps".into(), json!(sim.step));
        s.insert("time".into(), json!(sim.time));
        s.insert("wall_seconds".into(), json!(wall_seconds));
        s.insert(
            "ns_per_particle_step".into(),
            json!(1e9 * wall_seconds / (stepped.max(1) as f64 * sim.store.len().max(1) as f64)),
        );
        gas_summary(&mut s, sim, &self.measure);
        s
    }
    fn measurements(&self) -> Option<Vec<u8>> {
        Some(self.measure.to_bytes())
    }
}
