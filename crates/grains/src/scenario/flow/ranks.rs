//! A flow run's step under mpirun: rank 0 runs it on its gathered mirror
//! with the serial code and writes what changed as one message
//! ([`FlowRun::step_on_mirror`]); every rank applies that message to its
//! part of the decomposed engine ([`apply_on_rank`]).

use super::{place, FlowRun};
use crate::comm::{Reader, Writer};
use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::md::decomp::halo::{get_record, put_record};
use crate::md::decomp::{get_vec, index_by_id, put_vec, DecomposedMd};
use crate::md::Md;
use std::collections::{HashMap, HashSet};

impl<D: Dim> FlowRun<D> {
    /// The step's events on the mirror `m` (at `time` and `step`), then
    /// the outlets and sensors, and the message to every rank: a failure
    /// flag, gravity, the walls' removal times, the moved grains (id,
    /// position, frozen), the inserted grains (whole records) and the
    /// removed ids. `index` (the mirror's place of each id) follows the
    /// grains inserted and removed.
    pub fn step_on_mirror(
        &mut self,
        m: &mut Md<D>,
        index: &mut HashMap<u64, usize>,
        (time, step): (f64, u64),
        w: &mut Writer,
    ) -> Result<()> {
        (m.time, m.step) = (time, step);
        let before = m.particles.n_owned();
        let placed = self.after_step(m);
        // The inlets appended their grains to the mirror.
        let p = &m.particles;
        let added: Vec<_> = (before..p.n_owned()).map(|i| p.pack(i)).collect();
        if !added.is_empty() {
            *index = index_by_id(p);
        }
        let frozen: Vec<bool> = placed.iter().map(|(id, _)| p.frozen[index[id]]).collect();
        let present = p.n_owned();
        let outflow = self.outflow(m);
        let gone = present - m.particles.n_owned();
        let removed = match (&outflow, &self.outlets) {
            (Ok(()), Some(o)) if gone > 0 => o.last_removed(gone),
            _ => Vec::new(),
        };
        if !removed.is_empty() {
            *index = index_by_id(&m.particles);
        }
        w.u64(u64::from(outflow.is_err()));
        put_vec::<D>(w, m.settings.gravity);
        for wall in &m.walls {
            w.f64(wall.remove_at.unwrap_or(f64::NAN));
        }
        w.u64(placed.len() as u64);
        for ((id, x), frozen) in placed.into_iter().zip(frozen) {
            w.u64(id);
            put_vec::<D>(w, x);
            w.u64(u64::from(frozen));
        }
        w.u64(added.len() as u64);
        w.u64(removed.len() as u64);
        for g in &added {
            put_record(w, g, &[0.0; 3]);
        }
        removed.iter().for_each(|&id| w.u64(id));
        outflow
    }
}

/// Applies rank 0's message of [`FlowRun::step_on_mirror`] to this rank's
/// part `dec`: gravity and the walls' removal times everywhere, the moved
/// grains by their owners ([`place`]), the inserted grains in this rank's
/// box and the removed ids ([`DecomposedMd::edit`], on every rank when any
/// grain came or went, so that all rebuild at the next step). Rank 0
/// returns its own error (`failed`) when its outlets failed, the others a
/// message saying so.
pub fn apply_on_rank<D: Dim>(
    dec: &mut DecomposedMd<'_, D>,
    rd: &mut Reader,
    rank: usize,
    failed: Option<Error>,
) -> Result<()> {
    if rd.u64() != 0 {
        return Err(failed.unwrap_or_else(|| {
            Error::Unstable("rank 0's outlets could not remove grains".into())
        }));
    }
    let md = &mut dec.md;
    md.settings.gravity = get_vec::<D>(rd);
    for wall in md.walls.iter_mut() {
        let t = rd.f64();
        wall.remove_at = (!t.is_nan()).then_some(t);
    }
    let moved = rd.u64();
    if moved > 0 {
        let p = &mut md.particles;
        let owned = index_by_id(p);
        for _ in 0..moved {
            let (id, x, frozen) = (rd.u64(), get_vec::<D>(rd), rd.u64() != 0);
            if let Some(&i) = owned.get(&id) {
                place(p, i, x);
                p.frozen[i] = frozen;
            }
        }
    }
    let (added, removed) = (rd.u64(), rd.u64());
    if added + removed == 0 {
        return Ok(());
    }
    let sub = dec.subdomains();
    let mine: Vec<_> = (0..added)
        .map(|_| get_record::<D>(rd))
        .filter(|g| sub.owner(&D::to_xyz(g.pos)) == rank)
        .collect();
    let gone: HashSet<u64> = (0..removed).map(|_| rd.u64()).collect();
    dec.edit(mine, &gone)
}
