//! The DSMC engine: sort, then collide and stream cell by cell.
//!
//! ```text
//! Dsmc::step
//!   sort      counting sort of the particle indices by the cells that
//!             the last streaming wrote into `key`; every few steps the
//!             records themselves are put in that order          (serial)
//!   per cell  collide: its own random stream derived from
//!             (seed, step, cell); then stream its particles:
//!             x += v τ + g τ²/2, v += g τ, walls at the end of
//!             the step, periodic wrap, new cell into `key`     (parallel)
//! ```
//!
//! Streaming is fused with the collisions so that each record comes from
//! memory once per step: a cell's particles are still in cache when they
//! fly (and the next cell's are prefetched while this one collides).
//! Between steps the state is consistent: positions and velocities at
//! `time`, `key` their cells. A step collides at the start of its interval
//! and then streams over it.
//!
//! Work is split into fixed chunks of cells, never by thread count, and
//! each cell's random numbers come from its own stream: the result is the
//! same bit for bit on any number of threads.

use super::collide::{collide_cell, CellState, GasDim, Selection, Tally};
use super::dense::{Correction, DenseGas};
pub use super::haff::haff_time;
use super::rng::{StepStreams, Stream};
use super::sort::{gather_in_place, prefetch, sort_indices, Aside, CellGrid, RESORT_EVERY};
use super::store::Particle;
use super::store::{cross_section, Store};
use super::stream::Flight;
pub use super::stream::PlaneWall;
use crate::dim::Dim;
use crate::domain::Domain;
use rayon::prelude::*;

/// The particle records and their cell keys, shared by the collision
/// tasks, each of which touches only the particles of its own cells.
struct Shared<D: Dim> {
    p: *mut Particle<D>,
    key: *mut u32,
}
// SAFETY: see `Dsmc::collide_and_stream`: tasks touch disjoint particles.
unsafe impl<D: Dim> Send for Shared<D> {}
unsafe impl<D: Dim> Sync for Shared<D> {}

/// Particles per streaming task (at construction).
const STREAM_CHUNK: usize = 8192;
/// Cells per collision task.
const CELL_CHUNK: usize = 512;
/// How many cells ahead the records are prefetched: a cell's work (about
/// 5 candidates and 10 flights) is shorter than a memory access.
const PREFETCH_CELLS: usize = 2;

/// Settings of a run.
#[derive(Clone, Debug, PartialEq)]
pub struct DsmcSettings {
    /// Time step τ (s).
    pub dt: f64,
    /// Normal restitution coefficient e of particle–particle collisions.
    pub restitution: f64,
    /// Normal restitution of particle–wall collisions.
    pub wall_restitution: f64,
    pub dense: DenseGas,
    /// Random-close-packing fraction for the free volume.
    pub rcp: f64,
    /// Seed of the collision streams.
    pub seed: u64,
    /// Cell edge asked for (m); the grid fits the box with the nearest size.
    pub cell: f64,
    /// Lower bound of the initial v_max of every cell (m/s).
    pub vmax_floor: f64,
}

/// The DSMC engine.
pub struct Dsmc<D: GasDim> {
    pub store: Store<D>,
    pub domain: Domain<D>,
    pub grid: CellGrid,
    pub gravity: D::V,
    pub walls: Vec<PlaneWall<D>>,
    pub settings: DsmcSettings,
    pub time: f64,
    pub step: u64,
    /// Cell of each particle, written by streaming.
    pub(super) key: Vec<u32>,
    /// Particle indices sorted by cell at the last sort: cell c held
    /// `order[start[c]..start[c + 1]]` when it collided.
    pub order: Vec<u32>,
    /// First entry of each cell in `order` (length cells + 1).
    pub start: Vec<u32>,
    fill: Vec<u32>,
    /// Scratch of the physical re-sorts.
    pub(super) aside: Aside<Particle<D>>,
    pub cells: Vec<CellState>,
    selection: Selection,
    /// Candidates and collisions since the start.
    pub totals: Tally,
    /// Of the last step.
    pub last: Tally,
}

impl<D: GasDim> Dsmc<D> {
    pub fn new(
        store: Store<D>,
        domain: Domain<D>,
        gravity: D::V,
        walls: Vec<PlaneWall<D>>,
        settings: DsmcSettings,
    ) -> Self {
        let speed_sum = store.p.iter().map(|q| D::norm2(q.v)).sum::<f64>();
        Self::with_speed_sum(store, domain, gravity, walls, settings, speed_sum)
    }

    /// [`Self::new`] given Σ|v|² over the particles (summed in the order
    /// they were drawn, when the store is already in cell order:
    /// `super::placement::gas_in_cell_order`).
    pub fn with_speed_sum(
        store: Store<D>,
        domain: Domain<D>,
        gravity: D::V,
        walls: Vec<PlaneWall<D>>,
        settings: DsmcSettings,
        speed_sum: f64,
    ) -> Self {
        let grid = CellGrid::for_domain(&domain, settings.cell);
        let ncell = grid.cells();
        let n = store.len();
        let v2 = if n > 0 { speed_sum / n as f64 } else { 0.0 };
        // Relative speeds of a Maxwellian exceed 3√2 v_rms with probability
        // below 1e-5; any larger one met raises the cell's bound.
        let vmax0 = (3.0 * (2.0 * v2).sqrt()).max(settings.vmax_floor);
        let cell_volume = grid.cell_volume();
        let selection = Selection {
            rate: cross_section(D::D, store.diameter) * settings.dt / (2.0 * cell_volume),
            half_one_plus_e: 0.5 * (1.0 + settings.restitution),
            correction: Correction {
                kind: settings.dense,
                dim: D::D,
                bead_fraction: store.particle_volume() / cell_volume,
                rcp: settings.rcp,
            },
        };
        let mut me = Self {
            store,
            domain,
            grid,
            gravity,
            walls,
            settings,
            time: 0.0,
            step: 0,
            key: vec![0; n],
            order: vec![0; n],
            start: vec![0; ncell + 1],
            fill: vec![0; ncell],
            aside: Aside::default(),
            cells: vec![
                CellState {
                    vmax: vmax0,
                    remainder: 0.0,
                    collisions: 0,
                };
                ncell
            ],
            selection,
            totals: Tally::default(),
            last: Tally::default(),
        };
        me.sort_now();
        me.gather();
        me
    }

    /// Cell of every particle (at construction and after a restore); the
    /// records are put in cell order by `gather`.
    pub fn sort_now(&mut self) {
        let grid = &self.grid;
        self.store
            .p
            .par_chunks(STREAM_CHUNK)
            .zip(self.key.par_chunks_mut(STREAM_CHUNK))
            .with_min_len(crate::parallel::min_len(1))
            .for_each(|(ps, ks)| {
                for (q, k) in ps.iter().zip(ks.iter_mut()) {
                    *k = grid.cell_of::<D>(q.x);
                }
            });
    }

    /// Puts the records in cell order (keys follow), for locality.
    fn gather(&mut self) {
        sort_indices(&self.key, &mut self.start, &mut self.fill, &mut self.order);
        gather_in_place(&mut self.store.p, &mut self.order, &mut self.aside);
        self.sort_now();
    }

    /// Cells of a store that was replaced or changed length (a slab cut out
    /// of the whole run, or the whole run gathered from the ranks,
    /// `super::decomp`), and the index sort of them.
    pub(super) fn reindex(&mut self) {
        self.key.resize(self.store.len(), 0);
        self.sort_now();
        self.sort_cells();
    }

    /// The index sort of the cells in `key` (`order`, `start`), the first
    /// part of a step.
    #[inline]
    pub(super) fn sort_cells(&mut self) {
        self.order.resize(self.store.len(), 0);
        sort_indices(&self.key, &mut self.start, &mut self.fill, &mut self.order);
    }

    /// Whether the step about to be taken puts the records in cell order.
    #[inline]
    pub(super) fn resort_due(&self) -> bool {
        (self.step + 1).is_multiple_of(RESORT_EVERY)
    }

    /// Every particle with its cell.
    pub fn particles_with_cells(&self) -> impl Iterator<Item = (usize, &Particle<D>)> + '_ {
        self.key
            .iter()
            .map(|&c| c as usize)
            .zip(self.store.p.iter())
    }

    /// The selection constants (for tests and diagnostics).
    pub fn selection(&self) -> &Selection {
        &self.selection
    }

    /// One time step.
    pub fn step(&mut self) {
        self.sort_cells();
        if self.resort_due() {
            // The keys are rewritten by streaming before they are read.
            gather_in_place(&mut self.store.p, &mut self.order, &mut self.aside);
        }
        let t = self.collide_and_stream();
        self.time += self.settings.dt;
        self.step += 1;
        self.last = t;
        self.totals += t;
    }

    pub fn run(&mut self, steps: u64) {
        for _ in 0..steps {
            self.step();
        }
    }

    /// Collisions of every cell, each followed by the flight of its
    /// particles, in parallel over fixed chunks of cells. Leaves `time` and
    /// `step` to the caller ([`Self::step`], or a rank's step in
    /// `super::decomp`, which sums the tallies of all ranks first).
    pub(super) fn collide_and_stream(&mut self) -> Tally {
        let flight = Flight::new(
            self.time,
            self.settings.dt,
            self.gravity,
            0.5 * self.store.diameter,
            self.settings.wall_restitution,
            &self.walls,
            &self.domain,
            &self.grid,
        );
        let sel = self.selection;
        // Streams are numbered by the step being taken (the first is 1).
        let streams = StepStreams::new(self.settings.seed, self.step + 1);
        let start = &self.start;
        let order = &self.order;
        let shared = Shared {
            p: self.store.p.as_mut_ptr(),
            key: self.key.as_mut_ptr(),
        };
        self.cells
            .par_chunks_mut(CELL_CHUNK)
            .with_min_len(crate::parallel::min_len(1))
            .enumerate()
            .map(|(k, cs)| {
                let shared = &shared;
                let c0 = k * CELL_CHUNK;
                let mut t = Tally::default();
                for (i, st) in cs.iter_mut().enumerate() {
                    let c = c0 + i;
                    let idx = &order[start[c] as usize..start[c + 1] as usize];
                    // Fetch a cell a few ahead while this one works.
                    if let Some(ahead) = start.get(c + PREFETCH_CELLS + 1) {
                        for &j in &order[start[c + PREFETCH_CELLS] as usize..*ahead as usize] {
                            prefetch(shared.p.wrapping_add(j as usize));
                        }
                    }
                    if idx.len() >= 2 {
                        let mut rng = streams.cell(c as u64);
                        // SAFETY: `order` is a permutation of the particle
                        // indices and each cell lists its own disjoint part
                        // of it, so concurrent cells touch disjoint
                        // particles; the store is not otherwise borrowed
                        // during this loop.
                        t += unsafe { collide_cell(shared.p, idx, st, &sel, &mut rng) };
                    }
                    for &j in idx {
                        // SAFETY: as above, particle j and its key belong
                        // to this cell only.
                        unsafe {
                            let q = &mut *shared.p.add(j as usize);
                            *shared.key.add(j as usize) = flight.advance(q);
                        }
                    }
                }
                t
            })
            .reduce(Tally::default, |mut a, b| {
                a += b;
                a
            })
    }

    /// Mean number density (particles per volume, per area in 2D).
    pub fn number_density(&self) -> f64 {
        self.store.len() as f64 / self.domain.volume()
    }

    /// Mean packing fraction.
    pub fn packing_fraction(&self) -> f64 {
        self.number_density() * self.store.particle_volume()
    }

    /// Kinetic-theory collision frequency per particle at temperature `t`
    /// (J) and packing fraction `nu`, number density `n`, with the run's
    /// dense-gas factor: ω = 2√π n σ χ √(T/m) (2D), 4√π n σ² χ √(T/m) (3D).
    pub fn kinetic_collision_frequency(&self, n: f64, nu: f64, t: f64) -> f64 {
        collision_frequency(
            D::D,
            n,
            self.store.diameter,
            self.selection.correction.mean_factor(nu),
            t / self.store.mass,
        )
    }
}

/// ω = 2√π n σ χ √(T/m) in 2D, 4√π n σ² χ √(T/m) in 3D; `t_over_m` = T/m.
pub fn collision_frequency(dim: usize, n: f64, sigma: f64, chi: f64, t_over_m: f64) -> f64 {
    let sp = std::f64::consts::PI.sqrt();
    if dim == 2 {
        2.0 * sp * n * sigma * chi * t_over_m.sqrt()
    } else {
        4.0 * sp * n * sigma * sigma * chi * t_over_m.sqrt()
    }
}

/// A Maxwellian velocity with `sqrt(T/m)` = `thermal_speed`.
pub fn maxwellian<D: Dim>(rng: &mut Stream, thermal_speed: f64) -> D::V {
    let mut v = D::zero();
    let (a, b) = rng.normal_pair();
    D::set(&mut v, 0, a * thermal_speed);
    D::set(&mut v, 1, b * thermal_speed);
    if D::D == 3 {
        let (c, _) = rng.normal_pair();
        D::set(&mut v, 2, c * thermal_speed);
    }
    v
}
