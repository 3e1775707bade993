//! DSMC over several ranks: each rank owns a slab of whole horizontal
//! layers of collision cells (seed 000 §4: DSMC needs no halo, only the
//! particles that crossed a boundary move), so a cell never straddles two
//! ranks.
//!
//! A rank's step is the serial one on its slab: sort by the cells the last
//! streaming wrote, then per cell collide and stream (fused, as in
//! [`super::engine`]); then the particles whose new cell lies in another
//! slab migrate there, so that at the next sort every rank holds exactly
//! the particles of its cells.
//!
//! The result is the serial engine's bit for bit, on any rank count. Each
//! cell draws from its own stream (seed, step, global cell), and collides
//! its particles in the order of the serial store: every particle carries
//! its index in the serial store (`keys`), and a cell's particles are put
//! in that order when the rank sorts them into cells; at each physical
//! re-sort the serial store is cell-ordered, so the new index is the
//! number of particles on lower ranks plus the local position. Between
//! re-sorts the local store stays in key order except where particles left
//! (the last record fills the hole) or arrived (appended): only the cells
//! holding such records need their lists sorted by key, so migration costs
//! in proportion to the migrants, not to the store. Streaming
//! depends on nothing but the particle, so the order in which the ranks
//! fly theirs does not matter.
//!
//! Load balance: at the re-sorts, when the most loaded rank holds more than
//! `1 + threshold` times the mean, the layer boundaries move so that each
//! rank gets about the same number of particles. Moving boundaries cannot
//! change the result, only the time.
//!
//! Limits: every rank holds the whole cell table (24 bytes a cell) and the
//! initial placement is made on every rank before each keeps its slab.

use super::collide::{CellState, GasDim, Tally};
use super::engine::Dsmc;
use super::sort::gather_in_place;
use super::store::Particle;
use crate::comm::{Comm, Reader, Writer};
use crate::dim::Dim;

/// Default imbalance (max/mean − 1) above which the slabs are moved.
pub const DEFAULT_THRESHOLD: f64 = 0.1;

/// One rank's part of a decomposed DSMC run.
pub struct Decomposed<'c, D: GasDim> {
    /// This rank's particles; grid, cells and settings are the whole run's.
    pub sim: Dsmc<D>,
    comm: &'c dyn Comm,
    /// Index of each local particle in the serial store.
    keys: Vec<u64>,
    /// Store positions whose record may be out of key order (filled by a
    /// leaver's replacement or by an arrival) since the last re-sort.
    moved: Vec<u32>,
    /// First layer of each rank, then the number of layers (size + 1).
    bounds: Vec<usize>,
    /// Particles in the whole run.
    total: u64,
    /// Imbalance that triggers a move of the boundaries.
    pub threshold: f64,
    /// How often the boundaries moved.
    pub rebalances: u64,
    /// max/mean − 1 of the particle counts at the last re-sort.
    pub imbalance: f64,
}

/// Layer boundaries that split `counts` (particles per layer) into `parts`
/// runs of about equal sums, each at least one layer long.
pub fn split_layers(counts: &[u64], parts: usize) -> Vec<usize> {
    let layers = counts.len();
    let total: u64 = counts.iter().sum();
    let mut bounds = vec![0; parts + 1];
    bounds[parts] = layers;
    let mut acc = 0u64;
    let mut l = 0;
    for k in 1..parts {
        // Smallest boundary whose prefix reaches k/parts of the particles.
        let want = (total as u128 * k as u128).div_ceil(parts as u128) as u64;
        while l < layers && acc < want {
            acc += counts[l];
            l += 1;
        }
        let b = l.clamp(bounds[k - 1] + 1, layers - (parts - k));
        while l > b {
            l -= 1;
            acc -= counts[l];
        }
        while l < b {
            acc += counts[l];
            l += 1;
        }
        bounds[k] = b;
    }
    bounds
}

fn put<D: Dim>(w: &mut Writer, key: u64, q: &Particle<D>) {
    w.u64(key);
    for a in 0..D::D {
        w.f64(D::get(q.x, a));
    }
    for a in 0..D::D {
        w.f64(D::get(q.v, a));
    }
}

fn get<D: Dim>(r: &mut Reader) -> (u64, Particle<D>) {
    let key = r.u64();
    let mut q = Particle::<D>::default();
    for a in 0..D::D {
        D::set(&mut q.x, a, r.f64());
    }
    for a in 0..D::D {
        D::set(&mut q.v, a, r.f64());
    }
    (key, q)
}

impl<'c, D: GasDim> Decomposed<'c, D> {
    /// Splits `full`, a freshly built engine (identical on every rank), into
    /// slabs of about equal particle counts; keeps this rank's.
    pub fn new(mut full: Dsmc<D>, comm: &'c dyn Comm) -> Result<Self, String> {
        let (rank, size) = (comm.rank(), comm.size());
        if full.step != 0 {
            return Err(format!(
                "a decomposed DSMC run starts from a freshly built engine (this one is at step {})",
                full.step
            ));
        }
        let layers = full.grid.layers();
        if layers < size {
            return Err(format!(
                "{size} ranks but only {layers} layers of DSMC cells: each rank needs at least one layer (use fewer ranks or a smaller dsmc.cell_size)"
            ));
        }
        let per = full.grid.cells_per_layer();
        let counts: Vec<u64> = (0..layers)
            .map(|l| (full.start[(l + 1) * per] - full.start[l * per]) as u64)
            .collect();
        let bounds = split_layers(&counts, size);
        // The constructor sorted the store by cell: this rank's particles
        // are one contiguous run of it.
        let a = full.start[bounds[rank] * per] as usize;
        let b = full.start[bounds[rank + 1] * per] as usize;
        let total = full.store.len() as u64;
        full.store.p = full.store.p[a..b].to_vec();
        full.reindex();
        let mut me = Self {
            sim: full,
            comm,
            keys: (a as u64..b as u64).collect(),
            moved: Vec::new(),
            bounds,
            total,
            threshold: DEFAULT_THRESHOLD,
            rebalances: 0,
            imbalance: 0.0,
        };
        me.imbalance = me.measure_imbalance();
        Ok(me)
    }

    /// Particles in the whole run.
    pub fn total(&self) -> u64 {
        self.total
    }

    /// One time step, as [`Dsmc::step`]: sort this slab's particles by cell
    /// (every [`super::sort::RESORT_EVERY`] steps also the records, then renumber and
    /// perhaps move the boundaries), collide and stream cell by cell, then
    /// send the particles that flew into another rank's slab there.
    pub fn step(&mut self) {
        self.sort_cells();
        if self.sim.resort_due() {
            // Each cell lists its particles in serial order and the slabs
            // are runs of cells in rank order, so this is the serial
            // re-sort's slice.
            gather_in_place(
                &mut self.sim.store.p,
                &mut self.sim.order,
                &mut self.sim.aside,
            );
            self.moved.clear();
            self.renumber();
            self.imbalance = self.measure_imbalance();
            if self.imbalance > self.threshold {
                self.rebalance();
            }
        }
        let t = self.sim.collide_and_stream();
        self.sim.time += self.sim.settings.dt;
        self.sim.step += 1;
        // Streaming wrote every particle's new cell: the leavers are known.
        self.migrate();
        let mut s = [t.candidates, t.collisions];
        self.comm.sum_u64(&mut s);
        let t = Tally {
            candidates: s[0],
            collisions: s[1],
        };
        self.sim.last = t;
        self.sim.totals += t;
    }

    pub fn run(&mut self, steps: u64) {
        for _ in 0..steps {
            self.step();
        }
    }

    /// Sorts the particles into cells (counting sort, stable in store
    /// position), then puts the lists of the cells that hold a moved record
    /// in key order: every cell lists its particles as the serial store
    /// would.
    fn sort_cells(&mut self) {
        self.sim.sort_cells();
        if self.moved.is_empty() {
            return;
        }
        let sim = &mut self.sim;
        let n = sim.store.len();
        let mut cells: Vec<u32> = self
            .moved
            .iter()
            .filter(|&&i| (i as usize) < n)
            .map(|&i| sim.key[i as usize])
            .collect();
        cells.sort_unstable();
        cells.dedup();
        let keys = &self.keys;
        for c in cells {
            let (a, b) = (
                sim.start[c as usize] as usize,
                sim.start[c as usize + 1] as usize,
            );
            sim.order[a..b].sort_unstable_by_key(|&i| keys[i as usize]);
        }
    }

    /// Sends every particle whose cell (in `key`) another rank owns there:
    /// the store's last record fills its place. Arrivals are appended. Both
    /// kinds of place are remembered in `moved`, for the next sort.
    fn migrate(&mut self) {
        let per = self.sim.grid.cells_per_layer() as u32;
        let me = self.comm.rank();
        let lo = self.bounds[me] as u32 * per;
        let hi = self.bounds[me + 1] as u32 * per;
        let mut out = vec![Writer::default(); self.comm.size()];
        let sim = &mut self.sim;
        let mut i = 0;
        while i < sim.store.len() {
            let c = sim.key[i];
            if c >= lo && c < hi {
                i += 1;
                continue;
            }
            let r = self.bounds.partition_point(|&b| b as u32 * per <= c) - 1;
            put(&mut out[r], self.keys[i], &sim.store.p[i]);
            sim.store.p.swap_remove(i);
            sim.key.swap_remove(i);
            self.keys.swap_remove(i);
            // Position i now holds the former last record (checked next).
            self.moved.push(i as u32);
        }
        let out: Vec<Vec<u8>> = out.into_iter().map(|w| w.buf).collect();
        for blob in self.comm.exchange(&out) {
            let mut r = Reader::new(&blob);
            while !r.done() {
                let (k, q) = get::<D>(&mut r);
                self.moved.push(sim.store.len() as u32);
                sim.key.push(sim.grid.cell_of::<D>(q.x));
                sim.store.p.push(q);
                self.keys.push(k);
            }
        }
    }

    /// After a physical re-sort the serial store is in cell order: a
    /// particle's index is the count on lower ranks plus its local place.
    fn renumber(&mut self) {
        let n = self.sim.store.len() as u64;
        let all = self.comm.all_gather_bytes(&n.to_le_bytes());
        let offset: u64 = all[..self.comm.rank()]
            .iter()
            .map(|b| u64::from_le_bytes(b[..8].try_into().expect("8 bytes")))
            .sum();
        for (i, k) in self.keys.iter_mut().enumerate() {
            *k = offset + i as u64;
        }
    }

    /// Particles per rank: max/mean − 1.
    fn measure_imbalance(&self) -> f64 {
        let mut c = [self.sim.store.len() as f64];
        self.comm.max_f64(&mut c);
        let mean = self.total as f64 / self.comm.size() as f64;
        if mean > 0.0 {
            c[0] / mean - 1.0
        } else {
            0.0
        }
    }

    /// Moves the slab boundaries to even out the particle counts.
    fn rebalance(&mut self) {
        let per = self.sim.grid.cells_per_layer();
        let layers = self.sim.grid.layers();
        let mut counts: Vec<u64> = (0..layers)
            .map(|l| (self.sim.start[(l + 1) * per] - self.sim.start[l * per]) as u64)
            .collect();
        self.comm.sum_u64(&mut counts);
        let bounds = split_layers(&counts, self.comm.size());
        if bounds == self.bounds {
            return;
        }
        // Cell states follow their cells: replicate them, then change hands.
        self.share_cells();
        self.bounds = bounds;
        self.rebalances += 1;
        // The store was just put in cell order (`gather_in_place` leaves
        // the keys stale, streaming would rewrite them): its cells follow
        // from `start`, which migration reads.
        let sim = &mut self.sim;
        for c in 0..sim.cells.len() {
            let (a, b) = (sim.start[c] as usize, sim.start[c + 1] as usize);
            sim.key[a..b].fill(c as u32);
        }
        self.migrate();
        // The collisions need the new slab's sort.
        self.sort_cells();
        self.imbalance = self.measure_imbalance();
    }

    /// Gives every rank the state of every cell (each cell's owner has the
    /// true one; the others contribute zeros, so sums and maxima are exact).
    pub fn share_cells(&mut self) {
        let per = self.sim.grid.cells_per_layer();
        let me = self.comm.rank();
        let (c0, c1) = (self.bounds[me] * per, self.bounds[me + 1] * per);
        let n = self.sim.cells.len();
        let mut vmax = vec![0.0; n];
        let mut rem = vec![0.0; n];
        let mut col = vec![0u64; n];
        for c in c0..c1 {
            let s = &self.sim.cells[c];
            vmax[c] = s.vmax;
            rem[c] = s.remainder as f64;
            col[c] = s.collisions as u64;
        }
        self.comm.max_f64(&mut vmax);
        self.comm.sum_f64(&mut rem);
        self.comm.sum_u64(&mut col);
        for (c, s) in self.sim.cells.iter_mut().enumerate() {
            *s = CellState {
                vmax: vmax[c],
                remainder: rem[c] as f32,
                collisions: col[c] as u32,
            };
        }
    }

    /// Zeroes the collision counters the diagnostics read (on every rank,
    /// after [`Self::gather`] handed them to rank 0).
    pub fn reset_collisions(&mut self) {
        for s in &mut self.sim.cells {
            s.collisions = 0;
        }
    }

    /// Collective: on rank 0, makes `mirror` the serial engine's state
    /// (particles in serial order, cell states, counters); the other ranks
    /// pass None. `mirror` is an engine of the same run (same grid).
    pub fn gather(&mut self, mirror: Option<&mut Dsmc<D>>) {
        self.share_cells();
        let mut w = Writer::default();
        for (q, &k) in self.sim.store.p.iter().zip(&self.keys) {
            put(&mut w, k, q);
        }
        let Some(all) = self.comm.gather_bytes(&w.buf) else {
            return;
        };
        let mirror = mirror.expect("rank 0 gathers into an engine");
        let mut p = vec![Particle::<D>::default(); self.total as usize];
        for blob in &all {
            let mut r = Reader::new(blob);
            while !r.done() {
                let (k, q) = get::<D>(&mut r);
                p[k as usize] = q;
            }
        }
        mirror.store.p = p;
        mirror.cells.clone_from(&self.sim.cells);
        mirror.step = self.sim.step;
        mirror.time = self.sim.time;
        mirror.totals = self.sim.totals;
        mirror.last = self.sim.last;
        mirror.reindex();
    }

    /// The serial index of each local particle, in store order.
    pub fn keys(&self) -> &[u64] {
        &self.keys
    }

    /// Collective: the serial index of every particle of the run, on rank 0
    /// (for checks that nothing was lost or duplicated).
    pub fn gather_keys(&self) -> Option<Vec<u64>> {
        let mut w = Writer::default();
        self.keys.iter().for_each(|&k| w.u64(k));
        let all = self.comm.gather_bytes(&w.buf)?;
        let mut keys = Vec::with_capacity(self.total as usize);
        for blob in &all {
            let mut r = Reader::new(blob);
            while !r.done() {
                keys.push(r.u64());
            }
        }
        Some(keys)
    }
}

#[cfg(test)]
mod tests {
    use super::split_layers;

    #[test]
    fn split_layers_balances_and_keeps_every_part_nonempty() {
        assert_eq!(split_layers(&[10, 10, 10, 10], 2), vec![0, 2, 4]);
        assert_eq!(split_layers(&[30, 1, 1, 1, 1], 2), vec![0, 1, 5]);
        // A pile: everything in the bottom layer; the others still get one
        // layer each.
        assert_eq!(split_layers(&[100, 0, 0, 0], 4), vec![0, 1, 2, 3, 4]);
        assert_eq!(split_layers(&[0, 0, 0, 100], 3), vec![0, 2, 3, 4]);
        assert_eq!(split_layers(&[5; 8], 1), vec![0, 8]);
    }
}
