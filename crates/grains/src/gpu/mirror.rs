//! The GPU pipeline on the CPU: the same arrays, the same per-grain kernels
//! ([`super::grain_kernels`]) and the same sequence of passes as the CUDA
//! engine, each pass a plain loop over the grains. It needs no GPU and is
//! compiled always: it is how the pipeline is tested (against the CPU
//! engine, bit for bit) and what the GPU engine is checked against.
//!
//! A mirror starts from a built [`Md`] (the scenario machinery stays on the
//! CPU side) and gives its state back as an [`MdState`], so checkpoints and
//! outputs go through the CPU engine's code.

use super::grain_kernels::{
    add, dot, grain_forces, kick_drift, mirrored, order_row, remap_row, sub, visit_partners, wrap,
    Bins, Box3, ForceArgs, FullList, GrainsIn, Grid, Hooke, KickArgs, ListArgs, Moving, Plane,
    Soa3, V3,
};
use crate::dim::{Dim, D3};
use crate::error::{Error, Result};
use crate::io::Frame;
use crate::md::{Md, MdState};
use crate::neighbors::{GridShape, ListState};
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
}

impl Params {
    /// The fixed part of `md`'s run, refusing by name what the pipeline
    /// does not do (see [`super::check_supported`]).
    pub fn of(md: &Md<D3>) -> Result<Self> {
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
            sort_grid: grid(GridShape::new(d, reach, usize::MAX)),
            list_grid: grid(GridShape::new(d, reach, max_cells)),
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
    /// The state built from: what an export does not take from the arrays.
    template: MdState<D3>,
}

fn v3(v: &[DVec3]) -> Soa3 {
    Soa3::from_vecs(v.iter().map(|x| x.to_array()))
}

fn dvec(s: &Soa3) -> Vec<DVec3> {
    (0..s.len()).map(|i| DVec3::from_array(s.get(i))).collect()
}

impl Mirror {
    /// The pipeline's state for `md` as it stands (its list built, its
    /// forces evaluated): the same grains in the same order, its half list
    /// turned into the full list.
    pub fn from_md(md: &Md<D3>) -> Result<Self> {
        let params = Params::of(md)?;
        let s = md.export_state()?;
        let p = &s.particles;
        let n = p.len();
        let (list, springs) = full_from_half(&s.list, &s.springs, n, params.block);
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
            template: s,
        })
    }

    pub fn len(&self) -> usize {
        self.id.len()
    }

    /// How many grains differ from `other`'s in identity (order), position,
    /// velocity or spin bits, and whether the lists and springs differ.
    pub fn differences(&self, other: &Mirror) -> (usize, bool) {
        let grains = (0..self.len().max(other.len()))
            .filter(|&i| {
                i >= self.len()
                    || i >= other.len()
                    || self.id[i] != other.id[i]
                    || [
                        (&self.pos, &other.pos),
                        (&self.vel, &other.vel),
                        (&self.omega, &other.omega),
                    ]
                    .iter()
                    .any(|(a, b)| a.get(i).map(f64::to_bits) != b.get(i).map(f64::to_bits))
            })
            .count();
        let bits = |s: &Soa3| {
            [&s.x, &s.y, &s.z].map(|c| c.iter().map(|x| x.to_bits()).collect::<Vec<_>>())
        };
        let list = self.list != other.list || bits(&self.springs) != bits(&other.springs);
        (grains, list)
    }

    pub fn is_empty(&self) -> bool {
        self.id.is_empty()
    }

    /// The state as the CPU engine keeps it: its import continues the run
    /// with the same bits.
    pub fn to_state(&self) -> MdState<D3> {
        let t = &self.template;
        let mut particles = t.particles.clone();
        particles.permute(&self.origin);
        particles.pos = dvec(&self.pos);
        particles.vel = dvec(&self.vel);
        particles.omega = dvec(&self.omega);
        particles.force = dvec(&self.force);
        particles.torque = dvec(&self.torque);
        let (mut pairs, mut image, mut springs) = (Vec::new(), Vec::new(), Vec::new());
        for g in 0..self.len() {
            for e in self.list.row(g) {
                let p = self.list.partner[e];
                if p as usize > g {
                    pairs.push([g as u32, p]);
                    image.push(self.list.image[e]);
                    springs.push(DVec3::from_array(self.springs.get(e)));
                }
            }
        }
        let (max_overlap, worst) = self.overlaps(&pairs, &image);
        let nw = self.params.walls.len();
        let slots = nw.max(1);
        let mut wall_springs = vec![DVec3::ZERO; self.len() * slots];
        for k in 0..self.len() * nw {
            wall_springs[k / nw * slots + k % nw] = DVec3::from_array(self.wall_springs.get(k));
        }
        MdState {
            time: self.time,
            step: self.step,
            particles,
            list: ListState {
                pairs,
                image,
                shifts: self.shifts.iter().map(|&s| DVec3::from_array(s)).collect(),
                ref_pos: dvec(&self.reference),
                builds: self.builds,
                built: self.builds > 0,
            },
            springs,
            wall_springs,
            // The mirror runs the Hooke law, which keeps no rolling springs.
            rolling: Vec::new(),
            wall_rolling: Vec::new(),
            // The device runs no mesh walls, so no loads are kept; the time
            // is that of the last force evaluation, as the CPU engine's.
            mesh_springs: Vec::new(),
            wall_loads: (Vec::new(), self.time),
            rebuilds_since_sort: self.rebuilds_since_sort,
            contacts: self.stats.contacts,
            max_overlap,
            max_overlap_fraction: self.stats.max_fraction,
            worst_pair: worst.unwrap_or(t.worst_pair),
        }
    }

    /// The largest overlap and the worst pair of the last force evaluation
    /// (`None` without contacts), as the CPU engine finds them: over the
    /// pairs in its list's order, then each mobile grain's walls, the first
    /// largest overlap fraction. The kernels sum only the contacts and the
    /// largest fraction; these are recomputed from the positions, at which
    /// a step's forces were evaluated, with the force kernel's operations.
    fn overlaps(&self, pairs: &[[u32; 2]], image: &[u8]) -> (f64, Option<(u64, Option<u64>)>) {
        let (mut max, mut fraction, mut worst) = (0.0f64, 0.0, None);
        for (&[i, j], &code) in pairs.iter().zip(image) {
            let (i, j) = (i as usize, j as usize);
            let del = sub(
                self.pos.get(i),
                add(self.pos.get(j), self.shifts[code as usize]),
            );
            let (ri, rj) = (self.radius[i], self.radius[j]);
            let r2 = dot(del, del);
            if r2 >= (ri + rj) * (ri + rj) {
                continue;
            }
            let overlap = ri + rj - r2.sqrt();
            max = max.max(overlap);
            if overlap > fraction * ri.min(rj) {
                fraction = overlap / ri.min(rj);
                worst = Some((self.id[i], Some(self.id[j])));
            }
        }
        let mut wall_fraction = 0.0;
        let mut wall_worst = None;
        for g in (0..self.len()).filter(|&g| self.frozen[g] == 0) {
            let (x, r) = (self.pos.get(g), self.radius[g]);
            for wall in &self.params.walls {
                let s = dot(sub(x, wall.point), wall.normal);
                let overlap = r - s;
                if overlap <= 0.0 || s < -r {
                    continue;
                }
                max = max.max(overlap);
                if overlap / r > wall_fraction {
                    wall_fraction = overlap / r;
                    wall_worst = Some((self.id[g], None));
                }
            }
        }
        if wall_fraction > fraction {
            worst = wall_worst;
        }
        (max, worst)
    }

    /// The grains now as a frame (the CPU engine's [`Md::frame`] layout).
    pub fn frame(&self, domain: &crate::domain::Domain<D3>) -> Frame {
        let kind = &self.template.particles.kind;
        Frame {
            step: self.step,
            time: self.time,
            dim: 3,
            box_lo: D3::to_xyz(domain.lo),
            box_hi: D3::to_xyz(domain.hi),
            periodic: domain.periodic,
            id: self.id.clone(),
            kind: self.origin.iter().map(|&k| kind[k as usize]).collect(),
            pos: (0..self.len()).map(|i| self.pos.get(i)).collect(),
            vel: (0..self.len()).map(|i| self.vel.get(i)).collect(),
            omega: (0..self.len()).map(|i| self.omega.get(i)).collect(),
            radius: self.radius.clone(),
        }
    }

    /// Advances `n` steps: the same bits as the CPU engine's
    /// [`Md::advance`] (and as `n` single steps).
    pub fn advance(&mut self, n: u64) -> Result<()> {
        if n == 0 {
            return Ok(());
        }
        let mut far = self.kick_pass(1, true) || self.builds == 0;
        for left in (0..n).rev() {
            self.step += 1;
            self.time = self.step as f64 * self.params.dt;
            if far {
                self.rebuild();
            }
            self.forces(true);
            if left == 0 {
                break;
            }
            if let Err(e) = self.check_overlap() {
                self.kick_pass(1, false);
                return Err(e);
            }
            if self.finite_check_due() {
                self.kick_pass(1, false);
                self.check_finite()?;
                far = self.kick_pass(1, true);
            } else {
                far = self.kick_pass(2, true);
            }
        }
        self.kick_pass(1, false);
        self.check_overlap()?;
        if self.finite_check_due() {
            self.check_finite()?;
        }
        Ok(())
    }

    /// The integration kernel over all grains; whether one is beyond the
    /// skin test (after a drift).
    fn kick_pass(&mut self, kicks: u32, drift: bool) -> bool {
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
        let mut far = false;
        for g in 0..self.id.len() {
            far |= kick_drift(&mut m, &args, g, kicks, drift);
        }
        far
    }

    /// The force kernel over all grains.
    pub fn forces(&mut self, update: bool) {
        let g = GrainsIn {
            pos: &self.pos,
            vel: &self.vel,
            omega: &self.omega,
            radius: &self.radius,
            mass: &self.mass,
            frozen: &self.frozen,
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
        self.stats = Stats {
            contacts: pair_ends / 2 + walls,
            max_fraction: worst,
        };
    }

    /// The checks after a step whose statistics a device computed: the
    /// overlap, and `non_finite` (a grain's state found not finite).
    pub fn step_checks(&self, non_finite: bool) -> Result<()> {
        self.check_overlap()?;
        if non_finite {
            return Err(Error::Unstable(format!(
                "at step {} (t = {:.6e} s) a grain has a non-finite position or velocity; \
                 dt = {:.3e} s may be too large",
                self.step, self.time, self.params.dt
            )));
        }
        Ok(())
    }

    /// Whether this step's checks include the finite-state test.
    pub fn finite_check_due(&self) -> bool {
        self.step.is_multiple_of(self.params.nan_check_every)
    }

    fn check_overlap(&self) -> Result<()> {
        if self.stats.max_fraction > self.params.max_overlap_fraction {
            return Err(Error::Unstable(format!(
                "at step {} (t = {:.6e} s) two grains, or a grain and a wall, overlap by \
                 {:.1}% of the smaller radius (limit {:.0}%): the contacts are too soft or \
                 dt = {:.3e} s is too large",
                self.step,
                self.time,
                100.0 * self.stats.max_fraction,
                100.0 * self.params.max_overlap_fraction,
                self.params.dt
            )));
        }
        Ok(())
    }

    fn check_finite(&self) -> Result<()> {
        let bad = (0..self.len()).find(|&i| {
            !(self.pos.get(i).iter().all(|x| x.is_finite())
                && self.vel.get(i).iter().all(|x| x.is_finite()))
        });
        match bad {
            Some(i) => Err(Error::Unstable(format!(
                "at step {} (t = {:.6e} s) grain {} has a non-finite position or velocity; \
                 dt = {:.3e} s may be too large",
                self.step, self.time, self.id[i], self.params.dt
            ))),
            None => Ok(()),
        }
    }

    /// The rebuild: wrap, re-sort when due, build the list, remap the
    /// springs onto it.
    pub fn rebuild(&mut self) {
        let n = self.len();
        for g in 0..n {
            self.pos.set(g, wrap(&self.params.bx, self.pos.get(g)));
        }
        let every = self.params.sort_every;
        let old_of: Vec<u32> = if every > 0 && self.rebuilds_since_sort.is_multiple_of(every) {
            let order = bin(&self.params.sort_grid, &self.pos).members;
            self.permute(&order);
            order
        } else {
            (0..n as u32).collect()
        };
        self.rebuilds_since_sort = self.rebuilds_since_sort.wrapping_add(1);
        let list = self.build_list();
        let mut springs = Soa3::zeros(list.partner.len());
        for g in 0..n {
            remap_row(g, (&list, &self.list), &old_of, &self.springs, &mut springs);
        }
        self.list = list;
        self.springs = springs;
        self.reference = self.pos.clone();
        self.builds += 1;
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
        let bins = bin(&self.params.list_grid, &self.pos);
        let args = ListArgs {
            pos: &self.pos,
            radius: &self.radius,
            frozen: &self.frozen,
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
        let start = exclusive_scan(&count);
        let total = start[n] as usize;
        let mut list = FullList {
            start,
            partner: vec![0; total],
            image: vec![0; total],
        };
        for g in 0..n {
            let mut k = list.start[g] as usize;
            visit_partners(&args, g, |p, code| {
                list.partner[k] = p as u32;
                list.image[k] = if p > g { code } else { mirrored(code) } as u8;
                k += 1;
            });
            order_row(&mut list, g, args.block);
        }
        list
    }
}

/// `counts` followed by their exclusive prefix sums' total: entry k is the
/// sum of the counts before k (n + 1 entries).
pub fn exclusive_scan(counts: &[u32]) -> Vec<u32> {
    let mut start = Vec::with_capacity(counts.len() + 1);
    let mut sum = 0u32;
    start.push(0);
    for &c in counts {
        sum += c;
        start.push(sum);
    }
    start
}

/// Bins the grains into `grid`'s cells, count–scan–fill, each cell's
/// members then sorted by index (on the GPU the fill's order depends on
/// the threads; the sort makes the bins a function of the positions).
pub fn bin(grid: &Grid, pos: &Soa3) -> Bins {
    let n = pos.len();
    let cell: Vec<u32> = (0..n).map(|i| grid.cell_of(pos.get(i)) as u32).collect();
    let mut count = vec![0u32; grid.ncells()];
    for &c in &cell {
        count[c as usize] += 1;
    }
    let start = exclusive_scan(&count);
    let mut cursor = start.clone();
    let mut members = vec![0u32; n];
    for (i, &c) in cell.iter().enumerate() {
        members[cursor[c as usize] as usize] = i as u32;
        cursor[c as usize] += 1;
    }
    for c in 0..grid.ncells() {
        let m = &mut members[start[c] as usize..start[c + 1] as usize];
        for k in 1..m.len() {
            let x = m[k];
            let mut j = k;
            while j > 0 && m[j - 1] > x {
                m[j] = m[j - 1];
                j -= 1;
            }
            m[j] = x;
        }
    }
    Bins {
        start,
        members,
        cell,
    }
}

/// The full list of a half list (pairs (i, j), i < j, grouped by i), rows
/// in the order of [`super::grain_kernels::row_key`], with the springs.
fn full_from_half(
    half: &ListState<D3>,
    springs: &[DVec3],
    n: usize,
    block: usize,
) -> (FullList, Soa3) {
    let mut count = vec![0u32; n];
    for &[i, j] in &half.pairs {
        count[i as usize] += 1;
        count[j as usize] += 1;
    }
    let start = exclusive_scan(&count);
    let total = start[n] as usize;
    let mut list = FullList {
        start,
        partner: vec![0; total],
        image: vec![0; total],
    };
    // The spring of each entry, as the pair's index in the half list, so
    // that the rows can be ordered first and the springs placed after.
    let mut cursor = list.start.clone();
    let mut pair_of = vec![0u32; total];
    for (k, &[i, j]) in half.pairs.iter().enumerate() {
        for (g, p) in [(i, j), (j, i)] {
            let e = cursor[g as usize] as usize;
            list.partner[e] = p;
            list.image[e] = half.image[k];
            pair_of[e] = k as u32;
            cursor[g as usize] += 1;
        }
    }
    // Rows are in ascending partner order for lower partners and in list
    // order for higher ones: the stable order puts them in place. The
    // pair index moves with its entry through a lookup by partner.
    for g in 0..n {
        let r = list.row(g);
        let mut row: Vec<(u32, u8, u32)> = r
            .clone()
            .map(|e| (list.partner[e], list.image[e], pair_of[e]))
            .collect();
        row.sort_by_key(|&(p, _, _)| super::grain_kernels::row_key(g, p as usize, block));
        for (e, (p, code, k)) in r.zip(row) {
            list.partner[e] = p;
            list.image[e] = code;
            pair_of[e] = k;
        }
    }
    let springs = Soa3::from_vecs(pair_of.iter().map(|&k| springs[k as usize].to_array()));
    (list, springs)
}
