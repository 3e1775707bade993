//! Grains taken out of a run (an outlet): the store, the springs, the
//! integrator's history and the neighbour list kept consistent without them.

use super::Md;
use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::particles::ParticleRecord;

impl<D: Dim> Md<D> {
    /// Removes the owned grains whose ids are in `ids` (between steps) and
    /// returns them, in ascending id order, as they were.
    ///
    /// The other grains keep their order in the store, their Gear history
    /// and their springs with each other and with the walls and meshes
    /// (carried by id); the springs the removed grains held go with them.
    /// The neighbour list is rebuilt at once (as a rebuild at a step would
    /// rebuild it, the spatial sort included when due), so the next step
    /// sees no removed grain. The forces of this step are kept: they were
    /// those of the step that ended with the grains still there, which the
    /// integrator's corrector already used. Nothing here draws a random
    /// number or depends on the thread count.
    ///
    /// The sub-spheres of a rigid body leave only all together, and their
    /// body with them.
    ///
    /// Fails (input error) on an id that is not an owned grain, a repeated
    /// id, part of a body's sub-spheres, or a distributed engine's store
    /// (grains with ghosts).
    pub fn remove_grains(&mut self, ids: &[u64]) -> Result<Vec<ParticleRecord<D>>> {
        if ids.is_empty() {
            return Ok(Vec::new());
        }
        let n = self.particles.n_owned();
        if n != self.particles.len() {
            return Err(Error::input(
                "grains with ghosts (a distributed run) cannot be removed here",
            ));
        }
        let mut wanted: Vec<u64> = ids.to_vec();
        wanted.sort_unstable();
        if let Some(w) = wanted.windows(2).find(|w| w[0] == w[1]) {
            return Err(Error::input(format!(
                "remove_grains: grain id {} given twice",
                w[0]
            )));
        }
        let id = &self.particles.id[..n];
        let mut gone: Vec<u32> = Vec::with_capacity(wanted.len());
        let mut keep: Vec<u32> = Vec::with_capacity(n.saturating_sub(wanted.len()));
        for (i, x) in id.iter().enumerate() {
            if wanted.binary_search(x).is_ok() {
                gone.push(i as u32);
            } else {
                keep.push(i as u32);
            }
        }
        if gone.len() != wanted.len() {
            let missing = wanted
                .iter()
                .find(|w| !id.contains(w))
                .expect("a wanted id is missing");
            return Err(Error::input(format!(
                "remove_grains: no grain has id {missing}"
            )));
        }
        // A rigid body's sub-spheres leave all together, with their body.
        self.drop_whole_bodies(&wanted)?;
        let mut removed: Vec<ParticleRecord<D>> = gone
            .iter()
            .map(|&i| self.particles.pack(i as usize))
            .collect();
        removed.sort_unstable_by_key(|r| r.id);
        // Springs keyed by grain ids: saved before the store changes (the
        // list still indexes it), put back after the rebuild.
        let saved = self.save_springs();
        let saved_rolling = self.save_rolling();
        self.particles.retain_owned(&keep);
        self.wall_springs.retain_grains(&keep, n);
        self.mesh_springs.retain_grains(&keep, n);
        self.wall_rolling.retain_grains(&keep, n);
        self.mesh_rolling.retain_grains(&keep, n);
        // The list indexes the old store: let the rebuild carry no spring.
        self.springs.iter_mut().for_each(|s| *s = D::zero());
        self.rolling.iter_mut().for_each(|s| *s = D::zero());
        self.rebuild_neighbors()?;
        self.restore_springs(saved);
        self.restore_rolling(saved_rolling);
        Ok(removed)
    }
}
