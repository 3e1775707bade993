//! The inlets' part of a flow run's checkpoint: their counters (and the
//! bodies they made) saved and read back, and the inserted grains put back
//! into a freshly built engine as stand-ins before its state is imported.

use super::Inlets;
use crate::codec::{Dec, DecResult, Enc};
use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::md::Md;
use crate::particles::ParticleRecord;
use crate::rigid::BodySpec;

impl<D: Dim> Inlets<D> {
    /// The counters, for the flow run's checkpoint section.
    pub fn save(&self, e: &mut Enc) {
        e.u64(self.next_id);
        e.len(self.list.len());
        for inlet in &self.list {
            e.u64(inlet.inserted);
            e.f64(inlet.mass);
            e.u64(inlet.tries);
            e.u64(inlet.failed);
            e.u64(inlet.retry_at);
        }
        // Only with bodies, so that an inlet of spheres keeps its bytes.
        if self.with_bodies {
            e.len(self.made.len());
            for &(id, shape) in &self.made {
                e.u64(id);
                e.u32(shape);
            }
        }
    }

    /// Reads what [`Inlets::save`] wrote into inlets begun from the same
    /// scenario.
    pub fn load(&mut self, d: &mut Dec) -> DecResult<()> {
        let next_id = d.u64("inlets' next id")?;
        let n = d.len(40, "inlets")?;
        if n != self.list.len() {
            return Err(format!(
                "the checkpoint has {n} inlets, the scenario {}",
                self.list.len()
            ));
        }
        // Without inlets the id is unused: a checkpoint of another
        // scenario is then refused by the engine's own checks.
        if n > 0 {
            if next_id < self.first_id {
                return Err(format!(
                    "the inlets' next grain id {next_id} lies below the first, {}, that the \
                     scenario's grains leave: the checkpoint is another scenario's",
                    self.first_id
                ));
            }
            self.next_id = next_id;
        }
        for inlet in &mut self.list {
            inlet.inserted = d.u64("inlet grains")?;
            inlet.mass = d.f64("inlet mass")?;
            inlet.tries = d.u64("inlet attempts")?;
            inlet.failed = d.u64("inlet failed attempts")?;
            inlet.retry_at = d.u64("inlet retry step")?;
        }
        if self.with_bodies {
            let n = d.len(12, "inserted bodies")?;
            self.made = (0..n)
                .map(|_| Ok((d.u64("body's first id")?, d.u32("body's shape")?)))
                .collect::<DecResult<_>>()?;
        }
        Ok(())
    }

    /// The inserted grains put back into a freshly built engine, less
    /// `removed` (sorted ids), so that it holds the grains of the engine that
    /// wrote the checkpoint. They go in as stand-ins, whose state the
    /// checkpoint's engine state replaces; inserting builds no neighbour
    /// list, so their one place and size never meet a search.
    ///
    /// Inserted bodies go in as bodies of their shapes with their first
    /// ids (the engine's state replaces theirs too), unless they left:
    /// a body leaves whole, so its first id marks it.
    pub fn apply(&self, md: &mut Md<D>, removed: &[u64]) -> Result<()> {
        let sizes = md.shape_sizes();
        let mut in_body = std::collections::HashSet::new();
        let mut stand_in_bodies = Vec::new();
        for &(first, shape) in &self.made {
            let n = *sizes.get(shape as usize).ok_or_else(|| {
                Error::input(format!(
                    "an inserted body of shape {shape}, beyond the run's [[shapes]]"
                ))
            })? as u64;
            in_body.extend(first..first + n);
            if removed.binary_search(&first).is_err() {
                let spec = BodySpec {
                    shape: shape as usize,
                    kind: 1,
                    pos: md.domain.lo,
                    orientation: [1.0, 0.0, 0.0, 0.0],
                    vel: D::zero(),
                    omega: D::ang_from_xyz([0.0; 3]),
                };
                stand_in_bodies.push((first, spec));
            }
        }
        let stand_ins = (self.first_id..self.next_id)
            .filter(|id| removed.binary_search(id).is_err() && !in_body.contains(id))
            .map(|id| ParticleRecord::new(id, md.domain.lo, 1.0, 1.0, 1.0))
            .collect();
        md.insert_grains(stand_ins)?;
        md.insert_bodies(stand_in_bodies)
    }
}
