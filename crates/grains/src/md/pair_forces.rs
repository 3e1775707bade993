//! Grain–grain contact forces over the Verlet list, on all cores, with a
//! result that does not depend on the number of threads.
//!
//! Grains are cut into fixed blocks of consecutive indices (the block size
//! depends on the grain count only, never on the thread count). The half
//! list is sorted by its first grain, so each block owns a contiguous range of
//! pairs. A block task adds each contact's force to its first grain and, when
//! the second grain lies in the same block, to that grain too: both are its
//! own. A contact whose second grain belongs to another block appends that
//! grain's share to the block's outbox for the grain's block instead; a
//! second pass then adds, for each block, the shares in its inboxes in
//! block order, each in contact order. Every force is therefore summed in the
//! same order whatever the threads, and no two tasks ever write the same
//! memory. Only contacts, not listed pairs, take a share.

use super::field_forces::{field_part, FieldInput, FieldPart, GrainView};
use super::phase_times::add_since;
use super::wall_springs::WallSprings;
use super::MdStats;
use crate::contact::hooke_history::HookeHistory;
use crate::contact::hooke_lanes::{ContactLanes, LANES};
use crate::contact::{ContactLaw, ContactOutcome};
use crate::dim::Dim;
use crate::neighbors::NeighborList;
use crate::particles::Particles;
use rayon::prelude::*;
use std::time::{Duration, Instant};

/// Fewest blocks for which the passes are shared among threads: a smaller
/// system runs them on one thread instead of paying to wake others every
/// step.
const MIN_BLOCKS_TO_SHARE: usize = 8;

/// Grains per block: large enough that few contacts cross blocks, small
/// enough that two to a few dozen cores find work. A power of two, so that
/// a grain's block is a shift of its index (a contact that crosses blocks
/// would otherwise pay an integer division).
pub fn block_size(n: usize) -> usize {
    n.div_ceil(64).next_power_of_two().clamp(1024, 8192)
}

/// How the pair list is cut into blocks; rebuilt with the neighbour list.
#[derive(Clone, Debug, Default)]
pub struct PairBlocks {
    block: usize,
    /// Pairs of block b: `pair_start[b]..pair_start[b + 1]`.
    pair_start: Vec<usize>,
    /// One more than the largest grain index in the list.
    grains: usize,
}

impl PairBlocks {
    pub fn build(pairs: &[[u32; 2]], n: usize) -> Self {
        let block = block_size(n);
        let n_blocks = n.div_ceil(block).max(1);
        let mut pair_start = vec![0usize; n_blocks + 1];
        let mut b = 0;
        for (k, &[i, _]) in pairs.iter().enumerate() {
            let bi = i as usize / block;
            while b < bi {
                b += 1;
                pair_start[b] = k;
            }
        }
        while b < n_blocks {
            b += 1;
            pair_start[b] = pairs.len();
        }
        let grains = pairs
            .iter()
            .map(|&[i, j]| i.max(j) as usize + 1)
            .max()
            .unwrap_or(0);
        Self {
            block,
            pair_start,
            grains,
        }
    }

    fn n_blocks(&self) -> usize {
        self.pair_start.len() - 1
    }
}

/// A contact's force and torque for its second grain, which another block owns.
#[derive(Clone, Copy, Debug)]
struct Share<D: Dim> {
    grain: u32,
    force: D::V,
    /// Subtracted from the grain's torque.
    torque: D::A,
}

/// Shares of deferred contacts for their second grain, and per-block scratch.
#[derive(Clone, Debug, Default)]
pub struct Deferred<D: Dim> {
    /// `outbox[b][c]`: block b's shares for grains of block c, in contact order.
    outbox: Vec<Vec<Vec<Share<D>>>>,
    /// Per block, which listed pairs touch.
    contacts: Vec<BlockContacts>,
    /// The neighbour-list build the previous evaluation's contacts refer to.
    list_build: Option<u64>,
}

/// Which of a block's listed pairs touch: their indices (within the
/// block), and the contact test's words (bit b of word w: pair 64 w + b)
/// now and at the previous evaluation.
#[derive(Clone, Debug, Default)]
struct BlockContacts {
    touching: Vec<u32>,
    words: Vec<u64>,
    was_words: Vec<u64>,
}

/// Inputs every block reads.
pub struct PairInput<'a, D: Dim> {
    pub law: &'a ContactLaw,
    pub dt: f64,
    pub update: bool,
    pub neighbors: &'a NeighborList<D>,
    pub blocks: &'a PairBlocks,
}

/// Statistics of one block, merged in block order.
#[derive(Clone, Copy, Debug, Default)]
struct BlockStats {
    contacts: usize,
    max_overlap: f64,
    max_fraction: f64,
    worst: (u64, u64),
}

/// One block's own slices.
struct Block<'a, D: Dim> {
    first: usize,
    force: &'a mut [D::V],
    torque: &'a mut [D::A],
    springs: &'a mut [D::V],
    pairs: std::ops::Range<usize>,
    outbox: &'a mut [Vec<Share<D>>],
    /// The pairs in contact: now, and at the previous evaluation when
    /// `was_valid` (same list since then).
    contacts: &'a mut BlockContacts,
    was_valid: bool,
}

/// Splits `v` into consecutive pieces of the given lengths.
fn split_ranges<T>(mut v: &mut [T], lengths: impl Iterator<Item = usize>) -> Vec<&mut [T]> {
    let mut out = Vec::new();
    for len in lengths {
        let (head, tail) = v.split_at_mut(len);
        out.push(head);
        v = tail;
    }
    out
}

/// Sets `p.force` / `p.torque` to the sums of the pair contact forces and
/// torques and updates the springs. Each block zeroes its own grains' sums
/// just before it accumulates into them, while they are in its cache, instead
/// of a separate pass over memory. Adds the time of the contact pass to
/// `contacts_time` and returns, with the wall parts, the instant the pass
/// of shares, walls and gravity began (the caller times that phase to its
/// end).
pub fn pair_forces<D: Dim>(
    input: &PairInput<D>,
    p: &mut Particles<D>,
    springs: &mut [D::V],
    deferred: &mut Deferred<D>,
    (stats, contacts_time): (&mut MdStats, &mut Duration),
    fields: (&FieldInput<D>, &WallSprings<D>),
) -> (Vec<FieldPart<D>>, Instant) {
    let start = Instant::now();
    let blocks = input.blocks;
    let n = p.len();
    let owned = p.n_owned();
    let nb = blocks.n_blocks();
    deferred.outbox.resize_with(nb, Vec::new);
    for out in &mut deferred.outbox {
        out.resize_with(nb, Vec::new);
    }
    deferred.contacts.resize_with(nb, Default::default);
    let build = input.neighbors.builds();
    let was_valid = deferred.list_build == Some(build);
    deferred.list_build = Some(build);
    // The unchecked reads in `run_block` rely on this.
    assert!(
        blocks.grains <= n,
        "neighbour list and particle store disagree"
    );

    // Grains beyond the blocks (none unless grains were added since the
    // last build) get no contact.
    let covered = (blocks.block * nb).min(n);
    p.force[covered..].fill(D::zero());
    p.torque[covered..].fill(D::A::default());
    let grain_lens = (0..nb).map(|b| (blocks.block * (b + 1)).min(n) - (blocks.block * b).min(n));
    let pair_lens = (0..nb).map(|b| blocks.pair_start[b + 1] - blocks.pair_start[b]);
    let forces = split_ranges(&mut p.force, grain_lens.clone());
    let torques = split_ranges(&mut p.torque, grain_lens);
    let spring_parts = split_ranges(springs, pair_lens);
    let scratch = deferred.contacts.iter_mut();
    let mut tasks: Vec<Block<D>> = forces
        .into_iter()
        .zip(torques)
        .zip(spring_parts)
        .zip(deferred.outbox.iter_mut())
        .zip(scratch)
        .enumerate()
        .map(
            |(b, ((((force, torque), springs), outbox), contacts))| Block {
                first: (blocks.block * b).min(n),
                force,
                torque,
                springs,
                pairs: blocks.pair_start[b]..blocks.pair_start[b + 1],
                outbox,
                contacts,
                was_valid,
            },
        )
        .collect();

    let grains = GrainView {
        pos: &p.pos,
        vel: &p.vel,
        omega: &p.omega,
        radius: &p.radius,
        mass: &p.mass,
        frozen: &p.frozen,
        id: &p.id,
        owned,
    };
    let hooke = HookeHistory::of(input.law);
    // One block per job, so that the threads end the pass together.
    let min_len = if nb >= MIN_BLOCKS_TO_SHARE { 1 } else { nb };
    let block_stats: Vec<BlockStats> = tasks
        .par_iter_mut()
        .with_min_len(crate::parallel::min_len(min_len))
        .map(|t| {
            // The LAMMPS-shaped law gets its own compiled loop.
            let mut s = match hooke {
                Some(h) => run_block(&h, input, &grains, t),
                None => run_block(input.law, input, &grains, t),
            };
            if s.contacts > 0 {
                s.worst = (grains.id[s.worst.0 as usize], grains.id[s.worst.1 as usize]);
            }
            s
        })
        .collect();
    drop(tasks);
    let fields_start = add_since(contacts_time, start);

    // Deferred shares: each block takes its inboxes in block order, then
    // its grains' wall contacts and gravity, while the sums are in cache.
    let block = blocks.block;
    let outbox = &deferred.outbox;
    let rotation = input.law.rotation;
    let (field_input, wall_springs) = fields;
    // One block per job too: this pass is short, and a thread that wakes
    // late still finds blocks left instead of the others waiting for a
    // share it took.
    let parts = p
        .force
        .par_chunks_mut(block)
        .zip(p.torque.par_chunks_mut(block))
        .with_min_len(crate::parallel::min_len(min_len))
        .enumerate()
        .map(|(c, (force, torque))| {
            let first = c * block;
            // Blocks past the list's (grains added since its build) have no inbox.
            for share in outbox.iter().filter_map(|out| out.get(c)).flatten() {
                let k = share.grain as usize - first;
                force[k] += share.force;
                if rotation {
                    torque[k] -= share.torque;
                }
            }
            field_part(field_input, &grains, wall_springs, first, force, torque)
        })
        .collect();

    for s in &block_stats {
        stats.contacts += s.contacts;
        stats.max_overlap = stats.max_overlap.max(s.max_overlap);
        if s.max_fraction > stats.max_overlap_fraction {
            stats.max_overlap_fraction = s.max_fraction;
            stats.worst_pair = (s.worst.0, Some(s.worst.1));
        }
    }
    (parts, fields_start)
}

/// What the pair loop needs from a contact law; implemented by the general
/// [`ContactLaw`] and by the fixed [`HookeHistory`] kernel, so that the loop
/// is compiled once for each.
trait PairLaw: Sync {
    fn rotation(&self) -> bool;
    /// The vectorized kernel, for the law that has one.
    fn lanes(&self) -> Option<&HookeHistory> {
        None
    }
    fn damping_mass(&self, mi: f64, mj: f64) -> f64;
    fn force_factor(&self, m: f64) -> f64;
    #[allow(clippy::too_many_arguments)]
    fn evaluate<D: Dim>(
        &self,
        overlap: f64,
        n: D::V,
        v_rel: D::V,
        damping_mass: f64,
        spring: &mut D::V,
        dt: f64,
        update: bool,
    ) -> ContactOutcome<D>;
}

impl PairLaw for ContactLaw {
    #[inline(always)]
    fn rotation(&self) -> bool {
        self.rotation
    }
    #[inline(always)]
    fn damping_mass(&self, mi: f64, mj: f64) -> f64 {
        ContactLaw::damping_mass(self, mi, mj)
    }
    #[inline(always)]
    fn force_factor(&self, m: f64) -> f64 {
        self.scaling.force_factor(m)
    }
    #[inline(always)]
    fn evaluate<D: Dim>(
        &self,
        overlap: f64,
        n: D::V,
        v_rel: D::V,
        damping_mass: f64,
        spring: &mut D::V,
        dt: f64,
        update: bool,
    ) -> ContactOutcome<D> {
        ContactLaw::evaluate(self, overlap, n, v_rel, damping_mass, spring, dt, update)
    }
}

impl PairLaw for HookeHistory {
    #[inline(always)]
    fn rotation(&self) -> bool {
        true
    }
    #[inline(always)]
    fn lanes(&self) -> Option<&HookeHistory> {
        Some(self)
    }
    #[inline(always)]
    fn damping_mass(&self, mi: f64, mj: f64) -> f64 {
        HookeHistory::damping_mass(mi, mj)
    }
    #[inline(always)]
    fn force_factor(&self, _: f64) -> f64 {
        // Reduced scaling: forces are not multiplied by a mass.
        1.0
    }
    #[inline(always)]
    fn evaluate<D: Dim>(
        &self,
        overlap: f64,
        n: D::V,
        v_rel: D::V,
        damping_mass: f64,
        spring: &mut D::V,
        dt: f64,
        update: bool,
    ) -> ContactOutcome<D> {
        HookeHistory::evaluate(self, overlap, n, v_rel, damping_mass, spring, dt, update)
    }
}

/// Grain `i`'s entry of `v`, unchecked.
///
/// SAFETY: callers pass indices read from the neighbour list, which was built
/// over this same store (every index is below its length; `pair_forces`
/// asserts the list and the store agree in size).
#[inline(always)]
fn at<T: Copy>(v: &[T], i: u32) -> T {
    debug_assert!((i as usize) < v.len());
    unsafe { *v.get_unchecked(i as usize) }
}

/// Appends to `touching`, ascending, the indices of the block's listed
/// pairs in contact, and to `words` the test's bit masks. The tests of 64
/// pairs fill a mask first, and the indices are read off it afterwards:
/// the tests then depend on nothing but their own loads (a third or fewer
/// of the pairs touch, in no predictable pattern, so a branch on each would
/// often be mispredicted, and a store whose place advances with each test
/// chains them all).
fn select_touching<D: Dim>(
    g: &GrainView<D>,
    (pairs, images): (&[[u32; 2]], &[u8]),
    shifts: &[D::V; 32],
    (touching, words): (&mut Vec<u32>, &mut Vec<u64>),
) {
    for (w, (pairs, images)) in pairs.chunks(64).zip(images.chunks(64)).enumerate() {
        let mut mask = 0u64;
        for (b, (&[i, j], &code)) in pairs.iter().zip(images).enumerate() {
            let del = at(g.pos, i) - (at(g.pos, j) + shifts[(code & 31) as usize]);
            let radsum = at(g.radius, i) + at(g.radius, j);
            mask |= ((D::norm2(del) < radsum * radsum) as u64) << b;
        }
        words.push(mask);
        while mask != 0 {
            touching.push((64 * w) as u32 + mask.trailing_zeros());
            mask &= mask - 1;
        }
    }
}

fn run_block<D: Dim, L: PairLaw>(
    law: &L,
    input: &PairInput<D>,
    g: &GrainView<D>,
    t: &mut Block<D>,
) -> BlockStats {
    let list = input.neighbors;
    let rotation = law.rotation();
    let range = t.pairs.clone();
    let pairs = &list.pairs[range.clone()];
    let images = &list.image[range.clone()];
    // The image shifts with room for any 5-bit code, so that looking one
    // up needs no bounds check (codes are below 27). A copy on the block's
    // stack: the same padded table kept in the list cost chute 22
    // instructions per particle-step more (callgrind).
    let mut shifts = [D::zero(); 32];
    for (code, s) in shifts.iter_mut().enumerate().take(27) {
        *s = list.shift(code as u8);
    }

    // Pass 1: which listed pairs touch.
    t.force.fill(D::zero());
    t.torque.fill(D::A::default());
    let BlockContacts {
        touching,
        words,
        was_words,
    } = t.contacts;
    std::mem::swap(words, was_words);
    touching.clear();
    words.clear();
    select_touching(g, (pairs, images), &shifts, (touching, words));
    // Contacts that opened drop their spring: the bits set in the previous
    // word and clear in this one. After a rebuild, every stretched spring
    // outside the contacts is dropped instead.
    if t.was_valid {
        for (w, (&now, &was)) in words.iter().zip(was_words.iter()).enumerate() {
            let mut opened = was & !now;
            while opened != 0 {
                t.springs[64 * w + opened.trailing_zeros() as usize] = D::zero();
                opened &= opened - 1;
            }
        }
    } else {
        for (&now, springs) in words.iter().zip(t.springs.chunks_mut(64)) {
            for (b, spring) in springs.iter_mut().enumerate() {
                if (now >> b) & 1 == 0 && *spring != D::zero() {
                    *spring = D::zero();
                }
            }
        }
    }
    for out in t.outbox.iter_mut() {
        out.clear();
    }

    // Pass 2: the contact law on the touching pairs only.
    let ctx = Pass2 {
        pairs,
        images,
        touching,
        shifts: &shifts,
    };
    let dep = &mut Deposit {
        first: t.first,
        force: t.force,
        torque: t.torque,
        outbox: t.outbox,
        block_shift: input.blocks.block.trailing_zeros(),
        rotation,
        stats: BlockStats::default(),
    };
    match law.lanes() {
        Some(h) => contacts_in_lanes(h, input, g, &ctx, t.springs, dep),
        None => contacts_one_by_one(law, input, g, &ctx, t.springs, dep),
    }
    dep.stats
}

/// What the second pass reads about the block's pairs.
struct Pass2<'a, D: Dim> {
    pairs: &'a [[u32; 2]],
    images: &'a [u8],
    touching: &'a [u32],
    /// The list's image shifts, padded to 32 codes.
    shifts: &'a [D::V; 32],
}

impl<D: Dim> Pass2<'_, D> {
    /// The shift of pair `k`'s second grain.
    #[inline(always)]
    fn shift(&self, k: usize) -> D::V {
        self.shifts[(self.images[k] & 31) as usize]
    }
}

/// Where a block puts each contact's force and torques.
struct Deposit<'a, D: Dim> {
    first: usize,
    force: &'a mut [D::V],
    torque: &'a mut [D::A],
    outbox: &'a mut [Vec<Share<D>>],
    /// log2 of the block size.
    block_shift: u32,
    rotation: bool,
    stats: BlockStats,
}

impl<D: Dim> Deposit<'_, D> {
    /// Adds a contact's force and torques: `fi` on grain `i`, `fj` on grain
    /// `j`; the torques `ti`, `tj` are subtracted. A second grain outside
    /// the block gets its share through the outbox of its block.
    #[inline(always)]
    fn add(&mut self, [i, j]: [u32; 2], fi: D::V, fj: D::V, ti: D::A, tj: D::A) {
        let (i, j) = (i as usize - self.first, j as usize);
        self.force[i] += fi;
        if self.rotation {
            self.torque[i] -= ti;
        }
        if j >= self.first && j - self.first < self.force.len() {
            let j = j - self.first;
            self.force[j] += fj;
            if self.rotation {
                self.torque[j] -= tj;
            }
        } else {
            self.outbox[j >> self.block_shift].push(Share {
                grain: j as u32,
                force: fj,
                torque: tj,
            });
        }
    }

    /// Counts a contact and keeps the largest overlap and overlap fraction.
    #[inline(always)]
    fn count(&mut self, [i, j]: [u32; 2], overlap: f64, ri: f64, rj: f64) {
        let s = &mut self.stats;
        s.contacts += 1;
        s.max_overlap = s.max_overlap.max(overlap);
        // Compare before dividing: the fraction is needed only for a new worst.
        let r_min = ri.min(rj);
        if overlap > s.max_fraction * r_min {
            s.max_fraction = overlap / r_min;
            s.worst = (i as u64, j as u64);
        }
    }
}

/// The general law, one contact at a time.
fn contacts_one_by_one<D: Dim, L: PairLaw>(
    law: &L,
    input: &PairInput<D>,
    g: &GrainView<D>,
    c: &Pass2<D>,
    springs: &mut [D::V],
    dep: &mut Deposit<D>,
) {
    let rotation = law.rotation();
    for &k in c.touching {
        let k = k as usize;
        let [i, j] = c.pairs[k];
        // del points from j to i.
        let del = at(g.pos, i) - (at(g.pos, j) + c.shift(k));
        let (ri, rj) = (at(g.radius, i), at(g.radius, j));
        let r = D::norm(del);
        let overlap = ri + rj - r;
        // One division, three multiplications.
        let n = del * (1.0 / r);
        let mut v_rel = at(g.vel, i) - at(g.vel, j);
        if rotation {
            // Contact-point velocities: ω_i × (−r_i n) − ω_j × (r_j n).
            v_rel -= D::ang_cross(at(g.omega, i) * ri + at(g.omega, j) * rj, n);
        }
        let (mi, mj) = (at(g.mass, i), at(g.mass, j));
        let out = law.evaluate::<D>(
            overlap,
            n,
            v_rel,
            law.damping_mass(effective_mass(g, i), effective_mass(g, j)),
            &mut springs[k],
            input.dt,
            input.update,
        );
        let (fi, fj) = (law.force_factor(mi), law.force_factor(mj));
        // Lever arms −r_i n and +r_j n, force on j is −F: both torques are
        // −r (n × F_t) with each grain's own radius and factor.
        let nt = if rotation {
            D::torque(n, out.tangential)
        } else {
            D::A::default()
        };
        dep.add(
            [i, j],
            out.force * fi,
            -(out.force * fj),
            nt * (ri * fi),
            nt * (rj * fj),
        );
        dep.count([i, j], overlap, ri, rj);
    }
}

/// Frozen grains count as infinitely heavy.
#[inline(always)]
fn effective_mass<D: Dim>(g: &GrainView<D>, i: u32) -> f64 {
    if at(g.frozen, i) {
        f64::INFINITY
    } else {
        at(g.mass, i)
    }
}

/// The Hooke-with-history law over batches of contacts in component rows
/// (vectorized; same bits as [`contacts_one_by_one`]): gather a batch, run
/// the kernel, add the results back in the contacts' order.
fn contacts_in_lanes<D: Dim>(
    law: &HookeHistory,
    input: &PairInput<D>,
    g: &GrainView<D>,
    c: &Pass2<D>,
    springs: &mut [D::V],
    dep: &mut Deposit<D>,
) {
    let lanes = &mut ContactLanes::default();
    // The block's pair arrays have one length: a contact's index is then
    // checked once against it, not once per array. Lanes are counted up
    // to LANES so that the rows need no check either.
    assert!(c.pairs.len() == springs.len() && c.images.len() == springs.len());
    for batch in c.touching.chunks(LANES) {
        for (l, &k) in (0..LANES).zip(batch) {
            let k = k as usize;
            let [i, j] = c.pairs[k];
            let del = at(g.pos, i) - (at(g.pos, j) + c.shift(k));
            let (ri, rj) = (at(g.radius, i), at(g.radius, j));
            let v_rel = at(g.vel, i) - at(g.vel, j);
            let spin = D::ang_to_xyz(at(g.omega, i) * ri + at(g.omega, j) * rj);
            let spring = springs[k];
            for a in 0..D::D {
                lanes.del[a][l] = D::get(del, a);
                lanes.v_rel[a][l] = D::get(v_rel, a);
                lanes.spring[a][l] = D::get(spring, a);
            }
            for (a, w) in spin.into_iter().enumerate() {
                lanes.spin[a][l] = w;
            }
            lanes.ri[l] = ri;
            lanes.rj[l] = rj;
            lanes.mi[l] = effective_mass(g, i);
            lanes.mj[l] = effective_mass(g, j);
        }
        law.evaluate_lanes::<D>(lanes, input.dt, input.update);
        for (l, &k) in (0..LANES).zip(batch) {
            let k = k as usize;
            let row = |r: &[[f64; LANES]; 3]| D::from_xyz([r[0][l], r[1][l], r[2][l]]);
            let ang = |r: &[[f64; LANES]; 3]| D::ang_from_xyz([r[0][l], r[1][l], r[2][l]]);
            springs[k] = row(&lanes.spring);
            let force = row(&lanes.force);
            let pair = c.pairs[k];
            dep.add(
                pair,
                force,
                -force,
                ang(&lanes.torque_i),
                ang(&lanes.torque_j),
            );
            dep.count(pair, lanes.overlap[l], lanes.ri[l], lanes.rj[l]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::hooke_history::lammps_law;
    use crate::dim::D3;
    use crate::domain::Domain;
    use crate::integrate::Integrator;
    use crate::md::{Md, MdSettings};
    use crate::particles::ParticleRecord;
    use glam::DVec3;

    /// The Hooke-with-history law (its own kernel) and a Hertz law (the
    /// general one).
    fn both_compiled_laws() -> [ContactLaw; 2] {
        let hooke = lammps_law(0.0);
        let mut general = hooke.clone();
        general.beta = 1.5;
        [hooke, general]
    }

    /// Two spheres touching, the second sliding past the first.
    fn sliding_pair(law: ContactLaw) -> Md<D3> {
        let mut p = Particles::new();
        p.push_record(ParticleRecord::new(1, DVec3::splat(5.0), 0.5, 1.0, 0.1));
        let mut b = ParticleRecord::new(2, DVec3::new(5.999, 5.0, 5.0), 0.5, 1.0, 0.1);
        b.vel = DVec3::new(0.0, 0.01, 0.0);
        p.push_record(b);
        let domain = Domain::new(DVec3::ZERO, DVec3::splat(10.0), [false; 3]);
        let mut settings = MdSettings::new(1e-4, law, 0.5);
        settings.integrator = Integrator::Verlet;
        Md::new(p, domain, Vec::new(), settings).unwrap()
    }

    /// An opened contact forgets its spring, whether or not the list was
    /// rebuilt since the previous evaluation, with either compiled law.
    #[test]
    fn opened_contacts_drop_their_spring() {
        for law in both_compiled_laws() {
            for rebuild in [false, true] {
                let mut md = sliding_pair(law.clone());
                md.run(20).unwrap();
                assert_eq!(md.springs.len(), 1);
                assert!(md.springs[0].length() > 1e-7, "{:?}", md.springs[0]);
                // Pull the second grain out of contact (still inside the skin).
                md.particles.pos[1].x += 0.01;
                let builds = md.neighbor_builds();
                if rebuild {
                    md.rebuild_neighbors().unwrap();
                }
                md.step().unwrap();
                assert_eq!(md.neighbor_builds(), builds + rebuild as u64);
                assert_eq!(md.springs[0], DVec3::ZERO, "rebuild {rebuild}");
                assert_eq!(md.stats.contacts, 0);
            }
        }
    }

    /// The contact test finds exactly the touching pairs, in order, across
    /// the 64-pair words of its mask.
    #[test]
    fn contact_test_finds_every_contact_in_order() {
        // Spheres of radius 0.5 on a line; pair (k, k + 1) touches when
        // the gap after grain k is 0.99 instead of 1.01.
        let n = 200;
        // Words of 64 pairs: first and last bit set among others, empty,
        // full, and a short last word.
        let touch = |k: usize| match k {
            0..64 => k.is_multiple_of(3) || k == 63,
            64..128 => false,
            128..192 => true,
            _ => k.is_multiple_of(2),
        };
        let mut pos = vec![DVec3::ZERO; n];
        for k in 1..n {
            let gap = if touch(k - 1) { 0.99 } else { 1.01 };
            pos[k] = pos[k - 1] + DVec3::new(gap, 0.0, 0.0);
        }
        let radius = vec![0.5; n];
        let pairs: Vec<[u32; 2]> = (0..n as u32 - 1).map(|k| [k, k + 1]).collect();
        let images = vec![13u8; pairs.len()];
        let shifts = [DVec3::ZERO; 32];
        let zeros = vec![DVec3::ZERO; n];
        let (mass, frozen, id) = (vec![1.0; n], vec![false; n], vec![0u64; n]);
        let g = GrainView::<D3> {
            pos: &pos,
            vel: &zeros,
            omega: &zeros,
            radius: &radius,
            mass: &mass,
            frozen: &frozen,
            id: &id,
            owned: n,
        };
        for len in [1, 63, 64, 65, 128, 199] {
            let (mut found, mut words) = (Vec::new(), Vec::new());
            let out = (&mut found, &mut words);
            select_touching(&g, (&pairs[..len], &images[..len]), &shifts, out);
            let want: Vec<u32> = (0..len as u32).filter(|&k| touch(k as usize)).collect();
            assert!(!want.is_empty(), "{len}");
            assert_eq!(found, want, "{len} pairs");
            // The words hold the same contacts, bit b of word w for pair 64 w + b.
            assert_eq!(words.len(), len.div_ceil(64), "{len} pairs");
            let from_words: Vec<u32> = (0..len as u32)
                .filter(|&k| (words[k as usize / 64] >> (k % 64)) & 1 == 1)
                .collect();
            assert_eq!(from_words, want, "{len} pairs");
        }
    }

    #[test]
    fn blocks_partition_pairs() {
        // 3000 grains, blocks of 1024: pairs inside and across blocks.
        let pairs: Vec<[u32; 2]> = vec![
            [0, 1],
            [0, 1500],
            [1023, 1024],
            [1100, 1101],
            [2047, 2999],
            [2500, 2501],
        ];
        let b = PairBlocks::build(&pairs, 3000);
        assert_eq!(b.block, 1024);
        assert_eq!(b.pair_start, vec![0, 3, 5, 6]);
        assert_eq!(b.grains, 3000);
        // No pair of the third block but the last: an empty block in the middle.
        let b = PairBlocks::build(&[[0, 1], [2500, 2501]], 3000);
        assert_eq!(b.pair_start, vec![0, 1, 1, 2]);
    }

    /// A compressed, sheared lattice of 3375 spheres (four blocks) in a
    /// periodic box, no gravity: the pair forces are equal and opposite, so
    /// they sum to zero up to rounding. A share lost or added twice between
    /// blocks would leave a force of the order of one contact.
    #[test]
    fn shares_across_blocks_arrive_once() {
        for law in both_compiled_laws() {
            let side = 15;
            let spacing = 0.995;
            let mut p = Particles::<D3>::new();
            for n in 0..side * side * side {
                let (x, y, z) = (n % side, n / side % side, n / (side * side));
                let c = DVec3::new(x as f64, y as f64, z as f64) * spacing + DVec3::splat(0.5);
                let mut g = ParticleRecord::new(n as u64 + 1, c, 0.5, 1.0, 0.1);
                g.vel = DVec3::new(0.01 * (z as f64), 0.003 * (x as f64 % 3.0), 0.0);
                g.omega = DVec3::new(0.0, 0.0, 0.02 * (y as f64 % 5.0));
                p.push_record(g);
            }
            let l = side as f64 * spacing;
            let domain = Domain::new(DVec3::ZERO, DVec3::splat(l), [true; 3]);
            let mut settings = MdSettings::new(1e-4, law, 0.1);
            settings.integrator = Integrator::Verlet;
            let mut md = Md::new(p, domain, Vec::new(), settings).unwrap();
            md.run(5).unwrap();
            let shares: usize = md.deferred.outbox.iter().flatten().map(Vec::len).sum();
            assert!(md.blocks.n_blocks() == 4 && shares > 500, "{shares} shares");
            let total = md.particles.force.iter().fold(DVec3::ZERO, |a, &f| a + f);
            let scale: f64 = md.particles.force.iter().map(|f: &DVec3| f.length()).sum();
            assert!(
                md.stats.contacts > 2 * 3375 && scale > 0.0,
                "{}",
                md.stats.contacts
            );
            assert!(total.length() < 1e-12 * scale, "{total} against {scale}");
        }
    }
}
