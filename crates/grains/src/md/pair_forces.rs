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
//!
//! This file is the reduction; [`kernels`] holds what one block does with
//! its pairs (the contact test and the contact law).

mod kernels;

use super::field_forces::{field_part, FieldInput, FieldPart, GrainView};
use super::phase_times::add_since;
use super::wall_springs::WallSprings;
use super::MdStats;
use crate::contact::Law;
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
    pub law: &'a Law,
    pub dt: f64,
    pub update: bool,
    pub neighbors: &'a NeighborList<D>,
    pub blocks: &'a PairBlocks,
    /// The masses the laws see when they are not the grains' own (rigid
    /// clumps: a sub-sphere's body's mass).
    pub mass: Option<&'a [f64]>,
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
    /// The rolling springs, aligned with `springs` (empty unless the law
    /// keeps them).
    rolling: &'a mut [D::V],
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
    (springs, rolling): (&mut [D::V], &mut [D::V]),
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
    let spring_parts = split_ranges(springs, pair_lens.clone());
    // No rolling springs: an empty slice for every block.
    let has_rolling = !rolling.is_empty();
    let rolling_lens = pair_lens.map(|l| if has_rolling { l } else { 0 });
    let rolling_parts = split_ranges(rolling, rolling_lens);
    let scratch = deferred.contacts.iter_mut();
    let mut tasks: Vec<Block<D>> = forces
        .into_iter()
        .zip(torques)
        .zip(spring_parts.into_iter().zip(rolling_parts))
        .zip(deferred.outbox.iter_mut())
        .zip(scratch)
        .enumerate()
        .map(
            |(b, ((((force, torque), (springs, rolling)), outbox), contacts))| Block {
                first: (blocks.block * b).min(n),
                force,
                torque,
                springs,
                rolling,
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
        mass: input.mass.unwrap_or(&p.mass),
        frozen: &p.frozen,
        id: &p.id,
        kind: &p.kind,
        owned,
    };
    // One block per job, so that the threads end the pass together.
    let min_len = if nb >= MIN_BLOCKS_TO_SHARE { 1 } else { nb };
    let block_stats: Vec<BlockStats> = tasks
        .par_iter_mut()
        .with_min_len(crate::parallel::min_len(min_len))
        .map(|t| {
            // Each law's kernel gets its own compiled loop.
            let mut s = input.law.with_kernel(kernels::BlockRun {
                input,
                grains: &grains,
                block: t,
            });
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
    let rotation = input.law.rotation();
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::hooke_history::lammps_law;
    use crate::contact::ContactLaw;
    use crate::dim::D3;
    use crate::domain::Domain;
    use crate::integrate::Integrator;
    use crate::md::{Md, MdSettings};
    use crate::particles::ParticleRecord;
    use glam::DVec3;

    /// The Hooke-with-history law (its own kernel) and a Hertz law (the
    /// general one).
    pub(super) fn both_compiled_laws() -> [ContactLaw; 2] {
        let hooke = lammps_law(0.0);
        let mut general = hooke.clone();
        general.beta = 1.5;
        [hooke, general]
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
