//! Grains inserted into and removed from a decomposed run between steps
//! (the inlets and outlets of a flow run under mpirun).
//!
//! Every rank edits at the same step (rank 0 decides on its mirror and
//! sends the edit to all): each inserts the new grains that lie in its own
//! box and removes its owned grains among the removed ids. The store then
//! holds owned grains only (the ghosts dropped, as the indices of the
//! owned ones shift); the springs are kept by grain id until the next
//! step, whose forces follow a rebuild on every rank (new ghost shells,
//! a new list, the springs put back by id), as a serial engine rebuilds
//! its stale list at the step after an insertion.

use super::{DecomposedMd, PairSprings, WallSpringsById};
use crate::dim::Dim;
use crate::error::Result;
use crate::md::wall_springs::WallSprings;
use crate::particles::ParticleRecord;
use std::collections::HashSet;

impl<D: Dim> DecomposedMd<'_, D> {
    /// Inserts `added` (grains of this rank's box, fresh ids) and removes
    /// the owned grains whose ids are in `removed` (ids of other ranks'
    /// grains are ignored), with their springs. Collective in effect: every
    /// rank calls it at the same step, with its own share, so that all
    /// rebuild at the next step.
    pub fn edit(&mut self, added: Vec<ParticleRecord<D>>, removed: &HashSet<u64>) -> Result<()> {
        let (mut pairs, mut walls) = self.springs_by_id();
        let md = &mut self.md;
        md.particles.clear_ghosts();
        // The wall springs go by id until the rebuild.
        md.wall_springs = WallSprings::from_entries(Vec::new());
        md.insert_grains(added)?;
        let p = &mut md.particles;
        let n = p.n_owned();
        let keep: Vec<u32> = (0..n as u32)
            .filter(|&i| !removed.contains(&p.id[i as usize]))
            .collect();
        if keep.len() < n {
            p.retain_owned(&keep);
            pairs.retain(|k, _| !(removed.contains(&k.0) || removed.contains(&k.1)));
            walls.retain(|w| !removed.contains(&w.0));
        }
        md.neighbors.invalidate();
        self.pending = Some((pairs, walls));
        Ok(())
    }

    /// The pair and wall springs by grain id: those kept since an edit, or
    /// read from the list now.
    pub(super) fn springs_by_id(&self) -> (PairSprings<D>, WallSpringsById<D>) {
        match &self.pending {
            Some(kept) => kept.clone(),
            None => (self.md.save_springs(), self.wall_springs_by_id()),
        }
    }
}
