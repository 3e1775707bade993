//! The DSMC engine: stream, sort, collide.
//!
//! ```text
//! Dsmc::step
//!   stream    x += v τ + g τ²/2, v += g τ; reflect at walls (at the wall's
//!             place and velocity at the end of the step); wrap periodic
//!             axes; write each particle's cell into `key`            (parallel)
//!   sort      counting sort by cell, in place                        (serial)
//!   collide   every cell with N_c ≥ 2, its own random stream
//!             derived from (seed, step, cell)                        (parallel)
//! ```
//!
//! Work is split into fixed chunks of particles (streaming) and of cells
//! (collisions), never by thread count, and each cell's random numbers come
//! from its own stream: the result is the same bit for bit on any number of
//! threads.

use super::collide::{collide_cell, CellState, GasDim, Selection, Tally};
use super::dense::{Correction, DenseGas};
use super::rng::Stream;
use super::sort::{gather_in_place, sort_indices, CellGrid, RESORT_EVERY};
use super::store::Particle;
use super::store::{cross_section, Store};
use crate::boundary::Motion;
use crate::dim::Dim;
use crate::domain::Domain;
use rayon::prelude::*;

/// Particles per streaming task.
const STREAM_CHUNK: usize = 8192;
/// Cells per collision task.
const CELL_CHUNK: usize = 512;

/// An axis-aligned plane wall, possibly moving (vibrating bottom).
#[derive(Clone, Debug, PartialEq)]
pub struct PlaneWall<D: Dim> {
    pub name: String,
    /// The axis the normal lies along.
    pub axis: usize,
    /// +1 when the particles live on the high side of the plane.
    pub sign: f64,
    /// Coordinate of the plane along `axis` at rest.
    pub offset: f64,
    /// Prescribed motion ([`crate::boundary::Motion`] kinematics).
    pub motion: Motion<D>,
}

impl<D: Dim> PlaneWall<D> {
    /// Whether the displacement is the same at every point of the plane.
    fn is_rigid(&self) -> bool {
        !matches!(self.motion, Motion::Vibrate { modulation, .. } if modulation != 0.0)
    }

    /// The plane's coordinate along `axis` and its velocity, at time `t`,
    /// under the point `at` (which only matters for a modulated vibration).
    fn surface(&self, at: D::V, t: f64) -> (f64, D::V) {
        let mut q = at;
        D::set(&mut q, self.axis, self.offset);
        let moved = self.motion.place(q, t);
        (D::get(moved, self.axis), self.motion.velocity_at(moved, t))
    }
}

/// The particle array shared by the collision tasks, each of which touches
/// only the particles of its own cells.
struct SharedParticles<D: Dim>(*mut Particle<D>);
// SAFETY: see `Dsmc::collide`: tasks write disjoint particles.
unsafe impl<D: Dim> Send for SharedParticles<D> {}
unsafe impl<D: Dim> Sync for SharedParticles<D> {}

/// A wall and, when rigid, its place and velocity at the end of the step.
type WallNow<'a, D> = (&'a PlaneWall<D>, Option<(f64, <D as Dim>::V)>);

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
    /// Particle indices sorted by cell: cell c holds
    /// `order[start[c]..start[c + 1]]`.
    pub order: Vec<u32>,
    /// First entry of each cell in `order` (length cells + 1).
    pub start: Vec<u32>,
    fill: Vec<u32>,
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
        let lo = D::to_xyz(domain.lo);
        let hi = D::to_xyz(domain.hi);
        let grid = CellGrid::new(D::D, lo, hi, settings.cell);
        let ncell = grid.cells();
        let n = store.len();
        let v2 = if n > 0 {
            store.p.iter().map(|q| D::norm2(q.v)).sum::<f64>() / n as f64
        } else {
            0.0
        };
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
        me
    }

    /// Cell of every particle, then the sort and the reordering of the
    /// records (at construction).
    fn sort_now(&mut self) {
        let grid = &self.grid;
        self.store
            .p
            .par_chunks(STREAM_CHUNK)
            .zip(self.key.par_chunks_mut(STREAM_CHUNK))
            .for_each(|(ps, ks)| {
                for (q, k) in ps.iter().zip(ks.iter_mut()) {
                    *k = grid.cell_of::<D>(q.x);
                }
            });
        sort_indices(&self.key, &mut self.start, &mut self.fill, &mut self.order);
        gather_in_place(&mut self.store.p, &mut self.order);
    }

    /// Cells and the index sort again after the store changed length or
    /// content (migration between ranks in `super::decomp`).
    pub(super) fn reindex(&mut self) {
        let n = self.store.len();
        self.key.resize(n, 0);
        self.order.resize(n, 0);
        let grid = &self.grid;
        for (q, k) in self.store.p.iter().zip(self.key.iter_mut()) {
            *k = grid.cell_of::<D>(q.x);
        }
        sort_indices(&self.key, &mut self.start, &mut self.fill, &mut self.order);
    }

    /// The index sort of the cells in `key` (kept aligned with the store by
    /// `super::decomp` when particles leave or arrive).
    pub(super) fn sort_cells(&mut self) {
        self.order.resize(self.store.len(), 0);
        sort_indices(&self.key, &mut self.start, &mut self.fill, &mut self.order);
    }

    /// The particles of cell `c`.
    pub fn cell_particles(&self, c: usize) -> impl Iterator<Item = &Particle<D>> + '_ {
        self.order[self.start[c] as usize..self.start[c + 1] as usize]
            .iter()
            .map(|&i| &self.store.p[i as usize])
    }

    /// The selection constants (for tests and diagnostics).
    pub fn selection(&self) -> &Selection {
        &self.selection
    }

    /// One time step.
    pub fn step(&mut self) {
        self.stream();
        sort_indices(&self.key, &mut self.start, &mut self.fill, &mut self.order);
        self.step += 1;
        if self.step.is_multiple_of(RESORT_EVERY) {
            gather_in_place(&mut self.store.p, &mut self.order);
        }
        let t = self.collide();
        self.last = t;
        self.totals += t;
    }

    pub fn run(&mut self, steps: u64) {
        for _ in 0..steps {
            self.step();
        }
    }

    /// Moves every particle over one step and writes its cell into `key`
    /// (also the first part of a decomposed step, `super::decomp`).
    pub(super) fn stream(&mut self) {
        let dt = self.settings.dt;
        let t_end = self.time + dt;
        let g = self.gravity;
        let drift = g * (0.5 * dt * dt);
        let kick = g * dt;
        let radius = 0.5 * self.store.diameter;
        let ew = self.settings.wall_restitution;
        // Rigid walls: place and velocity once per step.
        let walls: Vec<WallNow<D>> = self
            .walls
            .iter()
            .map(|w| {
                let s = w.is_rigid().then(|| w.surface(D::zero(), t_end));
                (w, s)
            })
            .collect();
        let mut periodic = [None; 3];
        for (a, slot) in periodic.iter_mut().enumerate().take(D::D) {
            if self.domain.is_periodic(a) {
                *slot = Some((D::get(self.domain.lo, a), self.domain.length(a)));
            }
        }
        let grid = &self.grid;
        self.store
            .p
            .par_chunks_mut(STREAM_CHUNK)
            .zip(self.key.par_chunks_mut(STREAM_CHUNK))
            .for_each(|(ps, ks)| {
                for (q, k) in ps.iter_mut().zip(ks.iter_mut()) {
                    let mut x = q.x + q.v * dt + drift;
                    let mut v = q.v + kick;
                    for (w, rigid) in &walls {
                        let (plane, u) = match rigid {
                            Some(s) => *s,
                            None => w.surface(x, t_end),
                        };
                        let touch = plane + w.sign * radius;
                        let pen = w.sign * (touch - D::get(x, w.axis));
                        if pen > 0.0 {
                            let ua = D::get(u, w.axis);
                            let vn = D::get(v, w.axis) - ua;
                            if w.sign * vn < 0.0 {
                                D::set(&mut v, w.axis, ua - ew * vn);
                            }
                            D::set(&mut x, w.axis, touch + w.sign * ew * pen);
                        }
                    }
                    for (a, p) in periodic.iter().enumerate().take(D::D) {
                        if let Some((lo, l)) = *p {
                            let xa = D::get(x, a);
                            if xa < lo || xa >= lo + l {
                                let mut w = xa - l * ((xa - lo) / l).floor();
                                if w >= lo + l {
                                    w -= l;
                                }
                                D::set(&mut x, a, w);
                            }
                        }
                    }
                    q.x = x;
                    q.v = v;
                    *k = grid.cell_of::<D>(x);
                }
            });
        self.time = t_end;
    }

    /// Collisions in every cell with two particles or more.
    pub(super) fn collide(&mut self) -> Tally {
        let start = &self.start;
        let order = &self.order;
        let sel = self.selection;
        let seed = self.settings.seed;
        let step = self.step;
        let base = SharedParticles(self.store.p.as_mut_ptr());
        self.cells
            .par_chunks_mut(CELL_CHUNK)
            .enumerate()
            .map(|(k, cs)| {
                let base = &base;
                let c0 = k * CELL_CHUNK;
                let mut t = Tally::default();
                for (i, st) in cs.iter_mut().enumerate() {
                    let c = c0 + i;
                    let idx = &order[start[c] as usize..start[c + 1] as usize];
                    if idx.len() < 2 {
                        continue;
                    }
                    let mut rng = Stream::new(seed, step, c as u64);
                    // SAFETY: `order` is a permutation of the particle
                    // indices and each cell lists its own disjoint part of
                    // it, so concurrent cells touch disjoint particles; the
                    // store is not otherwise borrowed during this loop.
                    t += unsafe { collide_cell(base.0, idx, st, &sel, &mut rng) };
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

/// Haff's time τ0 = 2d / ((1 − e²) ω0): T(t) = T0 / (1 + t/τ0)².
pub fn haff_time(dim: usize, restitution: f64, omega0: f64) -> f64 {
    2.0 * dim as f64 / ((1.0 - restitution * restitution) * omega0)
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
