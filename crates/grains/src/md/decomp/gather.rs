//! The ranks' grains gathered on rank 0, and a whole engine split again.
//!
//! Every rank's grains gathered for the hooks, or with springs and history
//! for a checkpoint in the serial format; a restored whole engine split
//! over the ranks again.

use super::halo::{get_record, put_record};
use super::{get_ang, get_vec, put_ang, put_vec, DecomposedMd, PairSpring, PairSprings};
use crate::comm::{Comm, Reader, Writer};
use crate::dim::Dim;
use crate::error::Result;
use crate::md::Md;
use crate::particles::Particles;
use crate::settings::parallel::ParallelSpec;
use std::collections::{HashMap, HashSet};

impl<'c, D: Dim> DecomposedMd<'c, D> {
    /// Puts every rank's owned grains (position, velocity, spin) into
    /// `whole` on rank 0, an engine of the same run holding every grain
    /// (found by id); also its time and step. All ranks call this.
    pub fn gather(&self, whole: Option<&mut Md<D>>, index_of: &HashMap<u64, usize>) {
        let p = &self.md.particles;
        let mut w = Writer::default();
        for i in 0..p.n_owned() {
            w.u64(p.id[i]);
            put_vec::<D>(&mut w, p.pos[i]);
            put_vec::<D>(&mut w, p.vel[i]);
            put_ang::<D>(&mut w, p.omega[i]);
        }
        let Some(all) = self.comm.gather_bytes(&w.buf) else {
            return;
        };
        let Some(whole) = whole else { return };
        whole.time = self.md.time;
        whole.step = self.md.step;
        let q = &mut whole.particles;
        for blob in &all {
            let mut rd = Reader::new(blob);
            while !rd.done() {
                let i = index_of[&rd.u64()];
                q.pos[i] = get_vec::<D>(&mut rd);
                q.vel[i] = get_vec::<D>(&mut rd);
                q.omega[i] = get_ang::<D>(&mut rd);
            }
        }
    }

    /// Splits an engine restored from a checkpoint: as [`Self::with_spec`], but
    /// every grain keeps the checkpoint's force, torque and springs. The
    /// split's force evaluation sees the full-step velocities where the run
    /// saw Velocity Verlet's half-step ones: its forces would differ, and
    /// the Coulomb cap would cut sliding springs to other lengths.
    /// `inserted`: as for [`Self::with_inserts`].
    pub fn resume(
        full: Md<D>,
        comm: &'c dyn Comm,
        spec: &ParallelSpec,
        inserted: f64,
    ) -> Result<Self> {
        let p = &full.particles;
        let loads: HashMap<u64, (D::V, D::A)> = (0..p.n_owned())
            .map(|i| (p.id[i], (p.force[i], p.torque[i])))
            .collect();
        let stats = full.stats.clone();
        let springs = full.save_springs();
        let mut walls: HashMap<(u64, u32), D::V> = HashMap::new();
        for ((g, w), s) in full.wall_springs.entries() {
            walls.insert((p.id[g as usize], w), s);
        }
        let mut dec = Self::with_inserts(full, comm, spec, inserted)?;
        let md = &mut dec.md;
        let p = &mut md.particles;
        for i in 0..p.n_owned() {
            (p.force[i], p.torque[i]) = loads[&p.id[i]];
        }
        md.stats = stats;
        md.restore_springs(springs);
        let id = &md.particles.id;
        let entries = md
            .wall_springs
            .entries()
            .map(|((g, w), s)| {
                (
                    (g, w),
                    walls.get(&(id[g as usize], w)).copied().unwrap_or(s),
                )
            })
            .collect();
        md.wall_springs = crate::md::wall_springs::WallSprings::from_entries(entries);
        Ok(dec)
    }

    /// Puts the whole dynamic state into `whole` on rank 0, for a checkpoint
    /// in the serial format: every grain's record (Gear history included)
    /// with its force and torque, the pair springs (a pair that two ranks
    /// hold comes from the rank owning its smaller id) and the wall springs
    /// by grain id. `whole` (an engine of the same run, grains found by id)
    /// then builds its neighbour list at these positions and takes the
    /// springs on it. All ranks call this.
    pub fn gather_state(
        &self,
        whole: Option<&mut Md<D>>,
        index_of: &HashMap<u64, usize>,
    ) -> Result<()> {
        let p = &self.md.particles;
        let n = p.n_owned();
        let mut w = Writer::default();
        w.u64(n as u64);
        for i in 0..n {
            put_record(&mut w, &p.pack(i), &[0.0; 3]);
            put_vec::<D>(&mut w, p.force[i]);
            put_ang::<D>(&mut w, p.torque[i]);
        }
        let mine: HashSet<u64> = self.owned_ids().iter().copied().collect();
        let (pairs, walls) = self.springs_by_id();
        let mut pairs: Vec<PairSpring<D>> = pairs
            .into_iter()
            .filter(|(k, _)| mine.contains(&k.0))
            .collect();
        pairs.sort_unstable_by_key(|e| e.0);
        w.u64(pairs.len() as u64);
        for ((x, y), s) in pairs {
            w.u64(x);
            w.u64(y);
            put_vec::<D>(&mut w, s);
        }
        w.u64(walls.len() as u64);
        for (id, wall, s) in walls {
            w.u64(id);
            w.u32(wall);
            put_vec::<D>(&mut w, s);
        }
        let Some(all) = self.comm.gather_bytes(&w.buf) else {
            return Ok(());
        };
        let Some(whole) = whole else { return Ok(()) };
        whole.time = self.md.time;
        whole.step = self.md.step;
        whole.stats = self.md.stats.clone();
        whole.rebuilds_since_sort = self.md.rebuilds_since_sort;
        let mut springs = PairSprings::<D>::default();
        let mut wall_springs = Vec::new();
        let q = &mut whole.particles;
        for blob in &all {
            let mut rd = Reader::new(blob);
            for _ in 0..rd.u64() {
                let r = get_record::<D>(&mut rd);
                let i = index_of[&r.id];
                q.ensure_gear_history(r.gear.len(), r.gear_ang.len());
                // Wrapped, as a serial run's grains are after a list build.
                q.pos[i] = self.global.wrap(r.pos);
                q.vel[i] = r.vel;
                q.omega[i] = r.omega;
                r.gear.iter().zip(&mut q.gear).for_each(|(g, a)| a[i] = *g);
                (r.gear_ang.iter().zip(&mut q.gear_ang)).for_each(|(g, a)| a[i] = *g);
                q.force[i] = get_vec::<D>(&mut rd);
                q.torque[i] = get_ang::<D>(&mut rd);
            }
            for _ in 0..rd.u64() {
                let key = (rd.u64(), rd.u64());
                springs.insert(key, get_vec::<D>(&mut rd));
            }
            for _ in 0..rd.u64() {
                let (id, wall) = (rd.u64(), rd.u32());
                wall_springs.push(((index_of[&id] as u32, wall), get_vec::<D>(&mut rd)));
            }
            assert!(rd.done(), "state message longer than its layout");
        }
        whole
            .neighbors
            .build(&q.pos, &q.radius, &q.frozen, &whole.domain)?;
        // The run's build count, not the mirror's.
        let mut list = whole.neighbors.export_state();
        list.builds = self.neighbor_builds();
        whole.neighbors.import_state(list, q.len())?;
        whole.blocks = crate::md::PairBlocks::build(&whole.neighbors.pairs, q.len());
        whole.restore_springs(springs);
        whole.wall_springs = crate::md::wall_springs::WallSprings::from_entries(wall_springs);
        Ok(())
    }
}

/// The whole engine's index of every grain id, for [`DecomposedMd::gather`].
pub fn index_by_id<D: Dim>(p: &Particles<D>) -> HashMap<u64, usize> {
    p.id[..p.n_owned()]
        .iter()
        .enumerate()
        .map(|(i, &id)| (id, i))
        .collect()
}
