//! The GPU pipeline on the CPU: the same arrays, the same per-grain kernels
//! ([`super::grain_kernels`]) and the same sequence of passes as the CUDA
//! engine, each pass a plain loop over the grains. It needs no GPU and is
//! compiled always: it is how the pipeline is tested (against the CPU
//! engine, bit for bit) and what the GPU engine is checked against.
//!
//! A mirror starts from a built [`Md`] (the scenario machinery stays on the
//! CPU side) and gives its state back as an [`MdState`], so checkpoints and
//! outputs go through the CPU engine's code.

mod export;

use super::grain_kernels::{
    gate, grain_forces, kick_drift, list_capacity, mirrored, morton_places, order_row, remap_row,
    step_begin, visit_partners, words, wrap, Box3, ForceArgs, FullList, GrainsIn, Grid, Hooke,
    KickArgs, ListArgs, Moving, Plane, Soa3, V3,
};
pub use super::list_build::{bin, exclusive_scan};
use super::list_build::{empty_rows, full_from_half, sort_slots};
use crate::dim::D3;
use crate::error::{Error, Result};
use crate::md::{Md, MdState};
use crate::neighbors::GridShape;
use glam::DVec3;

/// Bounds on the list grid's cells, as the CPU list build sets them.
const CELLS_PER_PARTICLE: usize = 16;
const MIN_CELLS: usize = 4096;
const MAX_CELLS: usize = 1 << 24;

/// Grains per block of the CPU engine's pair reduction
/// (`md::pair_forces::block_size`): the row order follows its blocks.
pub fn block_size(n: usize) -> usize {
    n.div_ceil(64).next_power_of_two().clamp(1024, 8192)
}

/// How the pipeline stores its grains between re-sorts: the sort grid's
/// cells in Morton order (near in memory along all axes), or in the CPU
/// engine's order (linear cell index, x fastest). Either way each grain
/// keeps its rank in the CPU engine's order, which decides the sums' order
/// and the pairs' orientation, so the bits are the CPU engine's.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CellOrder {
    #[default]
    Morton,
    Cpu,
}

/// What stays fixed through a run.
#[derive(Clone, Debug)]
pub struct Params {
    pub dt: f64,
    pub skin: f64,
    pub law: Hooke,
    pub walls: Vec<Plane>,
    pub gravity: V3,
    pub bx: Box3,
    /// Re-sort every this many rebuilds (0: never).
    pub sort_every: u32,
    pub max_overlap_fraction: f64,
    pub nan_check_every: u64,
    pub block: usize,
    /// The grid of the spatial sort and that of the list build.
    pub sort_grid: Grid,
    pub list_grid: Grid,
    /// The sort grid's cells' places in the stored order (`CellOrder`).
    pub order: CellOrder,
    pub places: Vec<u32>,
}

impl Params {
    /// The fixed part of `md`'s run, refusing by name what the pipeline
    /// does not do (see [`super::check_supported`]).
    pub fn of(md: &Md<D3>, order: CellOrder) -> Result<Self> {
        let law = super::check_supported(md)?;
        let s = &md.settings;
        let d = &md.domain;
        let mut walls = Vec::new();
        for w in &md.walls {
            if let crate::boundary::Shape::Plane { point, normal } = &w.shape {
                walls.push(Plane {
                    point: point.to_array(),
                    normal: normal.to_array(),
                    gamma_n: if w.is_elastic() { 0.0 } else { law.gamma_n },
                });
            }
        }
        let n = md.particles.len();
        let reach = 2.0 * md.particles.max_radius() + s.skin;
        let grid = |shape: GridShape| Grid {
            dims: shape.dims,
            lo: shape.lo,
            inv_width: shape.inv_width,
        };
        let max_cells = (CELLS_PER_PARTICLE * n).clamp(MIN_CELLS, MAX_CELLS);
        let sort_grid = grid(GridShape::new(d, reach, usize::MAX));
        let places = match order {
            CellOrder::Morton => morton_places(&sort_grid),
            CellOrder::Cpu => (0..sort_grid.ncells() as u32).collect(),
        };
        let periodic = [0, 1, 2].map(|a| d.is_periodic(a));
        Ok(Self {
            dt: s.dt,
            skin: s.skin,
            law,
            walls,
            gravity: s.gravity.to_array(),
            bx: Box3 {
                lo: d.lo.to_array(),
                length: [0, 1, 2].map(|a| if periodic[a] { d.length(a) } else { 0.0 }),
                periodic,
            },
            sort_every: s.sort_every,
            max_overlap_fraction: s.max_overlap_fraction,
            nan_check_every: s.nan_check_every.max(1),
            block: block_size(n),
            sort_grid,
            list_grid: grid(GridShape::new(d, reach, max_cells)),
            order,
            places,
        })
    }

    /// The image shifts: digit k on a periodic axis means k − 1 lengths.
    pub fn shifts(&self) -> [V3; 27] {
        std::array::from_fn(|code| {
            let mut s = [0.0; 3];
            let mut c = code;
            for (a, x) in s.iter_mut().enumerate() {
                *x = ((c % 3) as f64 - 1.0) * self.bx.length[a];
                c /= 3;
            }
            s
        })
    }
}

/// Statistics of the last force evaluation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stats {
    pub contacts: u64,
    pub max_fraction: f64,
}

/// The pipeline's state: grains in cell order, the full list and springs.
#[derive(Clone, Debug)]
pub struct Mirror {
    pub pos: Soa3,
    pub vel: Soa3,
    pub omega: Soa3,
    pub force: Soa3,
    pub torque: Soa3,
    pub radius: Vec<f64>,
    pub mass: Vec<f64>,
    pub inv_mass: Vec<f64>,
    pub inv_inertia: Vec<f64>,
    pub frozen: Vec<u8>,
    pub id: Vec<u64>,
    /// Each grain's index in the state the mirror was built from.
    pub origin: Vec<u32>,
    /// Each grain's index in the CPU engine's order, and the same before
    /// the last re-sort (by the index then).
    pub rank: Vec<u32>,
    old_rank: Vec<u32>,
    /// Positions at the last list build.
    pub reference: Soa3,
    pub list: FullList,
    /// Tangential springs, one per list entry, oriented as the
    /// displacement of the pair's lower index.
    pub springs: Soa3,
    /// Grain–wall springs, `walls.len()` per grain.
    pub wall_springs: Soa3,
    pub shifts: [V3; 27],
    pub params: Params,
    pub step: u64,
    pub time: f64,
    pub rebuilds_since_sort: u32,
    pub builds: u64,
    pub stats: Stats,
    /// The step words while a stretch runs ([`words`]).
    pub st: [u64; words::LEN],
    /// Entries each of the device's two list buffers holds: a list that
    /// does not fit halts the stretch ([`Self::advance`]).
    pub capacity: [usize; 2],
    /// The last re-sort's permutation (old index of each grain).
    old_of: Vec<u32>,
    /// The state built from: what an export does not take from the arrays.
    template: MdState<D3>,
}

fn v3(v: &[DVec3]) -> Soa3 {
    Soa3::from_vecs(v.iter().map(|x| x.to_array()))
}

impl Mirror {
    /// The pipeline's state for `md` as it stands (its list built, its
    /// forces evaluated): the same grains in the same order, its half list
    /// turned into the full list.
    pub fn from_md(md: &Md<D3>) -> Result<Self> {
        Self::from_md_in(md, CellOrder::default())
    }

    /// [`Self::from_md`] storing the grains in `order` from the first
    /// re-sort on.
    pub fn from_md_in(md: &Md<D3>, order: CellOrder) -> Result<Self> {
        if md.has_bodies() {
            return Err(crate::error::Error::input(
                "run.device = \"gpu\": rigid clumps ([[shapes]]) run on the CPU engine only \
                 (the device pipeline would need the bodies' integrator and force sums); \
                 use run.device = \"cpu\"",
            ));
        }
        let params = Params::of(md, order)?;
        let s = md.export_state()?;
        let p = &s.particles;
        let n = p.len();
        let (list, springs) = full_from_half(&s.list, &s.springs, n, params.block);
        let total = list.partner.len();
        let nw = params.walls.len();
        let slots = md.walls.len().max(1);
        let wall_springs = Soa3::from_vecs(
            (0..n * nw).map(|k| s.wall_springs[k / nw.max(1) * slots + k % nw.max(1)].to_array()),
        );
        let reference = if s.list.built {
            v3(&s.list.ref_pos)
        } else {
            Soa3::zeros(n)
        };
        Ok(Self {
            pos: v3(&p.pos),
            vel: v3(&p.vel),
            omega: v3(&p.omega),
            force: v3(&p.force),
            torque: v3(&p.torque),
            radius: p.radius.clone(),
            mass: p.mass.clone(),
            inv_mass: p.inv_mass.clone(),
            inv_inertia: p.inv_inertia.clone(),
            frozen: p.frozen.iter().map(|&f| f as u8).collect(),
            id: p.id.clone(),
            origin: (0..n as u32).collect(),
            rank: (0..n as u32).collect(),
            old_rank: (0..n as u32).collect(),
            reference,
            list,
            springs,
            wall_springs,
            shifts: params.shifts(),
            params,
            step: s.step,
            time: s.time,
            rebuilds_since_sort: s.rebuilds_since_sort,
            builds: if s.list.built { s.list.builds } else { 0 },
            stats: Stats {
                contacts: s.contacts,
                max_fraction: s.max_overlap_fraction,
            },
            st: [0; words::LEN],
            capacity: [list_capacity(total); 2],
            old_of: Vec::new(),
            template: s,
        })
    }

    pub fn len(&self) -> usize {
        self.id.len()
    }

    pub fn is_empty(&self) -> bool {
        self.id.is_empty()
    }

    /// Advances `n` steps as the device does: the predictor kick, then the
    /// steps with every decision (rebuild, re-sort, instability) taken on
    /// the step words, which the host reads only when the stretch ends
    /// ([`Self::finish`]); a list that outgrew its buffer halts the stretch
    /// at that rebuild, and the stretch resumes there once the buffer is
    /// grown. The same bits as the CPU engine's [`Md::advance`] (and as `n`
    /// single steps).
    pub fn advance(&mut self, n: u64) -> Result<()> {
        if n == 0 {
            return Ok(());
        }
        let target = self.step + n;
        self.load_words();
        // The predictor of the first step checks nothing (the CPU engine
        // checks a step's forces after its own kicks).
        self.kick_pass(1, true, 0, f64::INFINITY);
        let mut resume = false;
        loop {
            self.enqueue(target, resume);
            match self.finish(target)? {
                Some(next) => {
                    self.capacity[next] = list_capacity(self.st[words::NEED] as usize);
                    self.st[words::HALT] = 0;
                    resume = true;
                }
                None => return Ok(()),
            }
        }
    }

    /// The step words as the fields say at the start of a stretch.
    fn load_words(&mut self) {
        self.st = [0; words::LEN];
        self.st[words::BUILDS] = self.builds;
        self.st[words::SINCE_SORT] = self.rebuilds_since_sort as u64;
        self.st[words::WALLS] = self.stats.contacts;
        self.st[words::MAX_FRACTION] = self.stats.max_fraction.to_bits();
        self.st[words::STEP] = self.step;
    }

    /// The passes of the steps after `self.step` up to `target`, in the
    /// order the device runs them, each gated on the step words. `resume`:
    /// the first step's rebuild halted on a full list buffer after its
    /// wrap and re-sort, so it starts at the list build.
    fn enqueue(&mut self, target: u64, mut resume: bool) {
        let limit = self.params.max_overlap_fraction;
        let every = self.params.nan_check_every;
        let mut step = self.step;
        loop {
            step += 1;
            if !resume {
                step_begin(&mut self.st, self.params.sort_every);
                self.wrap_sort_pass();
            }
            resume = false;
            self.list_pass();
            self.force_pass(true);
            if step == target {
                break;
            }
            self.kick_pass(2, true, every, limit);
        }
        self.kick_pass(1, false, every, limit);
    }

    /// The host's look at the step words when a stretch ends: the
    /// counters and statistics, and why it stopped. `Ok(Some(buffer))`: the
    /// list buffer that must grow to `NEED` entries before the stretch
    /// resumes at `self.step + 1`.
    pub fn finish(&mut self, target: u64) -> Result<Option<usize>> {
        use words::*;
        let st = self.st;
        self.builds = st[BUILDS];
        self.rebuilds_since_sort = st[SINCE_SORT] as u32;
        self.stats = Stats {
            contacts: st[PAIR_ENDS] / 2 + st[WALLS],
            max_fraction: f64::from_bits(st[MAX_FRACTION]),
        };
        let halt = match st[HALT] {
            0 if st[NONFINITE] != 0 => HALT_NONFINITE,
            h => h,
        };
        self.step = match halt {
            0 => target,
            HALT_OVERFLOW => st[HALT_STEP] - 1,
            _ if st[HALT] == 0 => target,
            _ => st[HALT_STEP],
        };
        self.time = self.step as f64 * self.params.dt;
        match halt {
            0 => Ok(None),
            HALT_OVERFLOW => Ok(Some(((st[BUILDS] + 1) % 2) as usize)),
            HALT_OVERLAP => Err(Error::Unstable(format!(
                "at step {} (t = {:.6e} s) two grains, or a grain and a wall, overlap by \
                 {:.1}% of the smaller radius (limit {:.0}%): the contacts are too soft or \
                 dt = {:.3e} s is too large",
                self.step,
                self.time,
                100.0 * self.stats.max_fraction,
                100.0 * self.params.max_overlap_fraction,
                self.params.dt
            ))),
            _ => Err(Error::Unstable(format!(
                "at step {} (t = {:.6e} s) a grain has a non-finite position or velocity; \
                 dt = {:.3e} s may be too large",
                self.step, self.time, self.params.dt
            ))),
        }
    }

    /// The integration kernel over all grains (gated on a halt): first
    /// the overlap of the last force evaluation against `limit` (beyond
    /// it the stretch halts at this step, unkicked), then `kicks`
    /// half-kicks, the drift when `drift` (setting FAR for a grain beyond
    /// the skin test), the finiteness test after the first kick at a step
    /// that is a multiple of `check_every` (0: never).
    fn kick_pass(&mut self, kicks: u32, drift: bool, check_every: u64, limit: f64) {
        if !gate(&self.st, None) {
            return;
        }
        let step = self.st[words::STEP];
        if f64::from_bits(self.st[words::MAX_FRACTION]) > limit {
            self.st[words::HALT] = words::HALT_OVERLAP;
            self.st[words::HALT_STEP] = step;
            return;
        }
        let check = check_every > 0 && step.is_multiple_of(check_every);
        let args = KickArgs {
            force: &self.force,
            torque: &self.torque,
            inv_mass: &self.inv_mass,
            inv_inertia: &self.inv_inertia,
            frozen: &self.frozen,
            reference: &self.reference,
            limit2: 0.25 * self.params.skin * self.params.skin,
            dt: self.params.dt,
        };
        let mut m = Moving {
            pos: &mut self.pos,
            vel: &mut self.vel,
            omega: &mut self.omega,
        };
        let (mut far, mut bad) = (false, false);
        for g in 0..self.id.len() {
            let (f, b) = kick_drift(&mut m, &args, g, (kicks, drift, check));
            far |= f;
            bad |= b;
        }
        if far {
            self.st[words::FAR] = 1;
        }
        if bad {
            self.st[words::NONFINITE] = 1;
        }
    }

    /// The force kernel over all grains, gated on a halt, its statistics
    /// added to the step words.
    fn force_pass(&mut self, update: bool) {
        if !gate(&self.st, None) {
            return;
        }
        let (pair_ends, walls, worst) = self.forces(update);
        self.st[words::PAIR_ENDS] += pair_ends;
        self.st[words::WALLS] += walls;
        let bits = &mut self.st[words::MAX_FRACTION];
        *bits = (*bits).max(worst.to_bits());
    }

    /// The force kernel over all grains: pair-contact ends, wall contacts
    /// and the largest overlap fraction.
    pub fn forces(&mut self, update: bool) -> (u64, u64, f64) {
        let g = GrainsIn {
            pos: &self.pos,
            vel: &self.vel,
            omega: &self.omega,
            radius: &self.radius,
            mass: &self.mass,
            frozen: &self.frozen,
            rank: &self.rank,
        };
        let args = ForceArgs {
            law: self.params.law,
            list: &self.list,
            shifts: &self.shifts,
            walls: &self.params.walls,
            gravity: self.params.gravity,
            dt: self.params.dt,
            update,
        };
        let (mut pair_ends, mut walls, mut worst) = (0u64, 0u64, 0.0f64);
        for i in 0..self.id.len() {
            let r = grain_forces(&g, &args, i, &mut self.springs, &mut self.wall_springs);
            self.force.set(i, r.force);
            self.torque.set(i, r.torque);
            pair_ends += r.pair_contacts as u64;
            walls += r.wall_contacts as u64;
            worst = worst.max(r.max_fraction);
        }
        (pair_ends, walls, worst)
    }

    /// The rebuild's first part, gated on BUILD: wrap into the periodic
    /// box, and on SORT re-sort the grains by cell (the permutation kept
    /// for the springs' remap).
    fn wrap_sort_pass(&mut self) {
        if !gate(&self.st, Some(words::BUILD)) {
            return;
        }
        for g in 0..self.len() {
            self.pos.set(g, wrap(&self.params.bx, self.pos.get(g)));
        }
        if self.st[words::SORT] != 0 {
            let bins = bin(&self.params.sort_grid, &self.pos, &self.rank);
            let (order, rank) = sort_slots(&bins, &self.params.places);
            self.old_rank = std::mem::replace(&mut self.rank, rank);
            self.permute(&order);
            self.old_of = order;
        }
    }

    /// The rebuild's second part, gated on BUILD: the list into the other
    /// buffer, or, when it does not fit, a halt at `step` with the entries
    /// it needs; the springs remapped onto it, the reference positions,
    /// the build counted (which makes the other buffer current).
    fn list_pass(&mut self) {
        if !gate(&self.st, Some(words::BUILD)) {
            return;
        }
        let list = self.build_list();
        let next = ((self.st[words::BUILDS] + 1) % 2) as usize;
        if list.partner.len() > self.capacity[next] {
            self.st[words::HALT] = words::HALT_OVERFLOW;
            self.st[words::HALT_STEP] = self.st[words::STEP];
            self.st[words::NEED] = list.partner.len() as u64;
            return;
        }
        let sorted = self.st[words::SORT] != 0;
        let old_of = sorted.then_some(&self.old_of[..]);
        let old_rank = if sorted { &self.old_rank } else { &self.rank };
        let mut springs = Soa3::zeros(list.partner.len());
        for g in 0..self.len() {
            remap_row(
                g,
                (&list, &self.list),
                old_of,
                (&self.rank, old_rank),
                (&self.springs, &mut springs),
            );
        }
        self.list = list;
        self.springs = springs;
        self.reference = self.pos.clone();
        self.st[words::BUILDS] += 1;
    }

    /// A rebuild now, whatever the skin test says (a re-sort when one is
    /// due): wrap, re-sort, build the list, remap the springs onto it.
    pub fn rebuild(&mut self) {
        self.load_words();
        self.st[words::FAR] = 1;
        step_begin(&mut self.st, self.params.sort_every);
        self.wrap_sort_pass();
        let capacity = self.capacity;
        self.capacity = [usize::MAX; 2];
        self.list_pass();
        self.capacity = capacity;
        self.builds = self.st[words::BUILDS];
        self.rebuilds_since_sort = self.st[words::SINCE_SORT] as u32;
    }

    /// Puts the grains in `order` (entry k: the old index of new grain k).
    fn permute(&mut self, order: &[u32]) {
        self.pos = self.pos.gather(order);
        self.vel = self.vel.gather(order);
        self.omega = self.omega.gather(order);
        self.force = self.force.gather(order);
        self.torque = self.torque.gather(order);
        let pick = |v: &[f64]| order.iter().map(|&k| v[k as usize]).collect::<Vec<f64>>();
        self.radius = pick(&self.radius);
        self.mass = pick(&self.mass);
        self.inv_mass = pick(&self.inv_mass);
        self.inv_inertia = pick(&self.inv_inertia);
        self.frozen = order.iter().map(|&k| self.frozen[k as usize]).collect();
        self.id = order.iter().map(|&k| self.id[k as usize]).collect();
        self.origin = order.iter().map(|&k| self.origin[k as usize]).collect();
        let nw = self.params.walls.len();
        let slots: Vec<u32> = order
            .iter()
            .flat_map(|&k| (0..nw as u32).map(move |w| k * nw as u32 + w))
            .collect();
        self.wall_springs = self.wall_springs.gather(&slots);
    }

    /// The full list for the grains as they stand (wrapped): count, scan,
    /// fill, order each row.
    pub fn build_list(&self) -> FullList {
        let n = self.len();
        let bins = bin(&self.params.list_grid, &self.pos, &self.rank);
        let args = ListArgs {
            pos: &self.pos,
            radius: &self.radius,
            frozen: &self.frozen,
            rank: &self.rank,
            bins: &bins,
            grid: self.params.list_grid,
            periodic: self.params.bx.periodic,
            length: self.params.bx.length,
            shifts: &self.shifts,
            skin: self.params.skin,
            block: self.params.block,
        };
        let mut count = vec![0u32; n];
        for (g, c) in count.iter_mut().enumerate() {
            visit_partners(&args, g, |_, _| *c += 1);
        }
        let mut list = empty_rows(&count);
        for g in 0..n {
            let mut k = list.start[g] as usize;
            visit_partners(&args, g, |p, code| {
                list.partner[k] = p as u32;
                list.image[k] = if self.rank[p] > self.rank[g] {
                    code
                } else {
                    mirrored(code)
                } as u8;
                k += 1;
            });
            order_row(&mut list, g, args.block, &self.rank);
        }
        list
    }
}
