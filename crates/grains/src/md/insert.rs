//! Grains added to a running engine (the inlets of a scenario): appended as
//! owned grains with fresh ids, the neighbour list marked stale so that the
//! next step rebuilds it and carries every spring over by grain id.

use super::Md;
use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::integrate::Integrator;
use crate::particles::ParticleRecord;

impl<D: Dim> Md<D> {
    /// Appends `grains` (their ids must be new to the engine) after the
    /// owned grains. Grains already there keep their index, springs,
    /// wall and mesh springs and integrator history, so their next step is
    /// the one they would have taken; the neighbour list is rebuilt at that
    /// step (with the springs carried by id, as every rebuild does). A new
    /// grain starts as in a freshly built engine: its force is its weight
    /// (it touches nothing: the caller places it clear of grains and walls),
    /// and its Gear-5 history is that force's second-order term, the rest
    /// zero, as `gear5::initialize` gives. Fails (input error) with ghosts
    /// present, on a repeated id, or on a non-finite or non-positive size.
    pub fn insert_grains(&mut self, grains: Vec<ParticleRecord<D>>) -> Result<()> {
        let p = &self.particles;
        if p.n_owned() != p.len() {
            return Err(Error::input(
                "grains cannot be inserted beside ghosts (a distributed run)",
            ));
        }
        let mut ids: std::collections::HashSet<u64> = p.id.iter().copied().collect();
        for g in &grains {
            if !ids.insert(g.id) {
                return Err(Error::input(format!(
                    "inserted grain id {} is already taken: ids are never reused",
                    g.id
                )));
            }
            let sane = g.radius.is_finite() && g.radius > 0.0 && g.mass > 0.0 && g.inertia > 0.0;
            if !(sane && D::is_finite(g.pos) && D::is_finite(g.vel)) {
                return Err(Error::input(format!(
                    "inserted grain {}: radius, mass and inertia must be positive and its \
                     position and velocity finite",
                    g.id
                )));
            }
        }
        let dt = self.settings.dt;
        let gear = self.settings.integrator == Integrator::Gear5;
        for mut g in grains {
            let weight = if g.frozen {
                D::zero()
            } else {
                self.settings.gravity * g.mass
            };
            g.gear.clear();
            g.gear_ang.clear();
            if gear {
                // gear5::initialize: the force's term, the higher ones zero.
                let inv_mass = if g.frozen { 0.0 } else { 1.0 / g.mass };
                g.gear.push(weight * (0.5 * dt * dt * inv_mass));
            }
            self.particles.push_record(g);
            let last = self.particles.len() - 1;
            self.particles.force[last] = weight;
        }
        // The list still holds the old grains only: the next predictor
        // finds it stale and rebuilds it before the forces.
        self.neighbors.invalidate();
        self.refresh_clumps();
        Ok(())
    }
}
