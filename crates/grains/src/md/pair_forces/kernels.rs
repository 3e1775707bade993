//! The contact kernels of one block of the pair loop: which listed pairs
//! touch, then the contact law on those, one by one or in batches of lanes,
//! each contact's force and torques deposited in the block's sums or its
//! outbox.

use super::super::field_forces::GrainView;
use super::{Block, BlockContacts, BlockStats, PairInput, Share};
use crate::contact::lanes::{evaluate_lanes, ContactLanes, LANES};
use crate::contact::RunLaw;
use crate::contact::{Contact, ContactModel, Step};
use crate::dim::Dim;

/// Grain `i`'s entry of `v`, unchecked.
///
/// SAFETY: callers pass indices read from the neighbour list, which was built
/// over this same store (every index is below its length; `pair_forces`
/// asserts the list and the store agree in size).
#[inline(always)]
pub(super) fn at<T: Copy>(v: &[T], i: u32) -> T {
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
pub(super) fn select_touching<D: Dim>(
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

/// [`select_touching`] for a law whose contacts are kept beyond touching
/// ([`ContactModel::BONDED`]): a pair whose `marks` entry is set (in
/// contact at the previous evaluation, or carried over a rebuild) stays in
/// contact while its surfaces are less than the law's reach apart.
pub(super) fn select_bonded<D: Dim, L: ContactModel>(
    law: &L,
    g: &GrainView<D>,
    (pairs, images, marks): (&[[u32; 2]], &[u8], &[D::V]),
    shifts: &[D::V; 32],
    (touching, words): (&mut Vec<u32>, &mut Vec<u64>),
) {
    for (w, ((pairs, images), marks)) in pairs
        .chunks(64)
        .zip(images.chunks(64))
        .zip(marks.chunks(64))
        .enumerate()
    {
        let mut mask = 0u64;
        for (b, ((&[i, j], &code), &mark)) in pairs.iter().zip(images).zip(marks).enumerate() {
            let del = at(g.pos, i) - (at(g.pos, j) + shifts[(code & 31) as usize]);
            let (ri, rj) = (at(g.radius, i), at(g.radius, j));
            let d2 = D::norm2(del);
            let mut radsum = ri + rj;
            if mark != D::zero() {
                radsum += law.reach(law.pair_index(at(g.kind, i), at(g.kind, j)), ri, rj);
            }
            mask |= ((d2 < radsum * radsum) as u64) << b;
        }
        words.push(mask);
        while mask != 0 {
            touching.push((64 * w) as u32 + mask.trailing_zeros());
            mask &= mask - 1;
        }
    }
}

pub(super) fn run_block<D: Dim, L: ContactModel>(
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
    // A sheared box's sliding images move relative to the grains they
    // image; unsheared, the kernels below never read these.
    let sheared = list.sheared();
    let mut vshifts = [D::zero(); 32];
    if sheared {
        for (code, v) in vshifts.iter_mut().enumerate().take(27) {
            *v = list.velocity_shift(code as u8);
        }
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
    if L::BONDED {
        let marks = (pairs, images, &*t.rolling);
        select_bonded(law, g, marks, &shifts, (touching, words));
    } else {
        select_touching(g, (pairs, images), &shifts, (touching, words));
    }
    // Contacts that opened drop their spring: the bits set in the previous
    // word and clear in this one. After a rebuild, every stretched spring
    // outside the contacts is dropped instead.
    drop_opened(t.springs, words, was_words, t.was_valid);
    if L::ROLLING_HISTORY || L::BONDED {
        drop_opened(t.rolling, words, was_words, t.was_valid);
    }
    if L::BONDED {
        // Every contact now is kept until it breaks.
        for &k in touching.iter() {
            t.rolling[k as usize] = crate::contact::jkr::mark::<D>();
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
        vshifts: &vshifts,
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
    let springs = (&mut *t.springs, &mut *t.rolling);
    // Sheared or not is chosen once here, not per contact: the unsheared
    // kernels are the ones compiled before shear existed.
    match (L::LANES, sheared) {
        (true, false) => contacts_in_lanes::<D, L, false>(law, input, g, &ctx, springs, dep),
        (true, true) => contacts_in_lanes::<D, L, true>(law, input, g, &ctx, springs, dep),
        (false, false) => contacts_one_by_one::<D, L, false>(law, input, g, &ctx, springs, dep),
        (false, true) => contacts_one_by_one::<D, L, true>(law, input, g, &ctx, springs, dep),
    }
    dep.stats
}

/// [`run_block`] for the run's law, as [`crate::contact::Law::with_kernel`]
/// compiles it.
pub(super) struct BlockRun<'a, 'b, D: Dim> {
    pub input: &'a PairInput<'a, D>,
    pub grains: &'a GrainView<'a, D>,
    pub block: &'a mut Block<'b, D>,
}

impl<D: Dim> RunLaw<BlockStats> for BlockRun<'_, '_, D> {
    #[inline(always)]
    fn run<L: ContactModel>(self, law: &L) -> BlockStats {
        run_block(law, self.input, self.grains, self.block)
    }
}

/// Contacts that opened drop their spring: the bits set in the previous
/// word and clear in this one. After a rebuild (`was_valid` false), every
/// stretched spring outside the contacts is dropped instead.
fn drop_opened<V: Copy + PartialEq + Default>(
    springs: &mut [V],
    words: &[u64],
    was_words: &[u64],
    was_valid: bool,
) {
    if was_valid {
        for (w, (&now, &was)) in words.iter().zip(was_words.iter()).enumerate() {
            let mut opened = was & !now;
            while opened != 0 {
                springs[64 * w + opened.trailing_zeros() as usize] = V::default();
                opened &= opened - 1;
            }
        }
    } else {
        for (&now, springs) in words.iter().zip(springs.chunks_mut(64)) {
            for (b, spring) in springs.iter_mut().enumerate() {
                if (now >> b) & 1 == 0 && *spring != V::default() {
                    *spring = V::default();
                }
            }
        }
    }
}

/// What the second pass reads about the block's pairs.
struct Pass2<'a, D: Dim> {
    pairs: &'a [[u32; 2]],
    images: &'a [u8],
    touching: &'a [u32],
    /// The list's image shifts, padded to 32 codes.
    shifts: &'a [D::V; 32],
    /// The images' velocities relative to their grains, padded likewise
    /// (read by the sheared kernels only).
    vshifts: &'a [D::V; 32],
}

impl<D: Dim> Pass2<'_, D> {
    /// The shift of pair `k`'s second grain.
    #[inline(always)]
    fn shift(&self, k: usize) -> D::V {
        self.shifts[(self.images[k] & 31) as usize]
    }

    /// `v_i − v_j` of pair `k` less the velocity of the second grain's
    /// image relative to that grain (`v_rel` itself unsheared).
    #[inline(always)]
    fn relative_velocity<const SHEARED: bool>(&self, k: usize, v_rel: D::V) -> D::V {
        if SHEARED {
            v_rel - self.vshifts[(self.images[k] & 31) as usize]
        } else {
            v_rel
        }
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

/// The law one contact at a time (`SHEARED`: through sliding images).
fn contacts_one_by_one<D: Dim, L: ContactModel, const SHEARED: bool>(
    law: &L,
    input: &PairInput<D>,
    g: &GrainView<D>,
    c: &Pass2<D>,
    (springs, rolling): (&mut [D::V], &mut [D::V]),
    dep: &mut Deposit<D>,
) {
    let rotation = law.rotation();
    let step = Step {
        dt: input.dt,
        update: input.update,
    };
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
        let mut v_rel = c.relative_velocity::<SHEARED>(k, at(g.vel, i) - at(g.vel, j));
        if rotation {
            // Contact-point velocities: ω_i × (−r_i n) − ω_j × (r_j n).
            v_rel -= D::ang_cross(at(g.omega, i) * ri + at(g.omega, j) * rj, n);
        }
        let (mi, mj) = (at(g.mass, i), at(g.mass, j));
        let contact = Contact::<D> {
            overlap,
            normal: n,
            v_rel,
            mi: effective_mass(g, i),
            mj: effective_mass(g, j),
            ri,
            rj,
            omega_rel: if L::ROLLING {
                at(g.omega, i) - at(g.omega, j)
            } else {
                D::A::default()
            },
            pair: law.pair_index(at(g.kind, i), at(g.kind, j)),
        };
        let out = law.evaluate(&contact, &mut springs[k], step);
        let (fi, fj) = (law.force_factor(mi), law.force_factor(mj));
        // Lever arms −r_i n and +r_j n, force on j is −F: both torques are
        // −r (n × F_t) with each grain's own radius and factor.
        let nt = if rotation {
            D::torque(n, out.tangential)
        } else {
            D::A::default()
        };
        let (li, lj) = (law.lever(ri, overlap), law.lever(rj, overlap));
        let (mut ti, mut tj) = (nt * (li * fi), nt * (lj * fj));
        if L::ROLLING {
            // The rolling torque T on i, −T on j (a law with rolling has
            // no mass factor).
            let mut none = D::zero();
            let spring = if L::ROLLING_HISTORY {
                &mut rolling[k]
            } else {
                &mut none
            };
            let t = law.rolling(&contact, &out, spring, step);
            ti -= t;
            tj += t;
        }
        dep.add([i, j], out.force * fi, -(out.force * fj), ti, tj);
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

/// The law over batches of contacts in component rows (vectorized; same
/// bits as [`contacts_one_by_one`]): gather a batch, run the kernel, add
/// the results back in the contacts' order.
fn contacts_in_lanes<D: Dim, L: ContactModel, const SHEARED: bool>(
    law: &L,
    input: &PairInput<D>,
    g: &GrainView<D>,
    c: &Pass2<D>,
    (springs, rolling): (&mut [D::V], &mut [D::V]),
    dep: &mut Deposit<D>,
) {
    let lanes = &mut ContactLanes::default();
    let rotation = law.rotation();
    let step = Step {
        dt: input.dt,
        update: input.update,
    };
    // The block's pair arrays have one length: a contact's index is then
    // checked once against it, not once per array. Lanes are counted up
    // to LANES so that the rows need no check either.
    assert!(c.pairs.len() == springs.len() && c.images.len() == springs.len());
    assert!(!L::ROLLING_HISTORY || rolling.len() == springs.len());
    for batch in c.touching.chunks(LANES) {
        for (l, &k) in (0..LANES).zip(batch) {
            let k = k as usize;
            let [i, j] = c.pairs[k];
            let del = at(g.pos, i) - (at(g.pos, j) + c.shift(k));
            let (ri, rj) = (at(g.radius, i), at(g.radius, j));
            let v_rel = c.relative_velocity::<SHEARED>(k, at(g.vel, i) - at(g.vel, j));
            // A law with rolling resistance gets ω_i and ω_j and forms
            // both the spin and ω_i − ω_j in its vector loop; the others
            // get the spin.
            if L::ROLLING {
                let wi = D::ang_to_xyz(at(g.omega, i));
                let wj = D::ang_to_xyz(at(g.omega, j));
                for a in 0..3 {
                    lanes.omega_i[a][l] = wi[a];
                    lanes.omega_j[a][l] = wj[a];
                }
            } else {
                let spin = if rotation {
                    D::ang_to_xyz(at(g.omega, i) * ri + at(g.omega, j) * rj)
                } else {
                    [0.0; 3]
                };
                for (a, w) in spin.into_iter().enumerate() {
                    lanes.spin[a][l] = w;
                }
            }
            let spring = springs[k];
            for a in 0..D::D {
                lanes.del[a][l] = D::get(del, a);
                lanes.v_rel[a][l] = D::get(v_rel, a);
                lanes.spring[a][l] = D::get(spring, a);
            }
            if L::ROLLING_HISTORY {
                let r = rolling[k];
                for a in 0..D::D {
                    lanes.rolling[a][l] = D::get(r, a);
                }
            }
            lanes.ri[l] = ri;
            lanes.rj[l] = rj;
            lanes.mi[l] = effective_mass(g, i);
            lanes.mj[l] = effective_mass(g, j);
            lanes.pair[l] = law.pair_index(at(g.kind, i), at(g.kind, j));
        }
        evaluate_lanes::<D, L>(law, lanes, step);
        for (l, &k) in (0..LANES).zip(batch) {
            let k = k as usize;
            let row = |r: &[[f64; LANES]; 3]| D::from_xyz([r[0][l], r[1][l], r[2][l]]);
            let ang = |r: &[[f64; LANES]; 3]| D::ang_from_xyz([r[0][l], r[1][l], r[2][l]]);
            springs[k] = row(&lanes.spring);
            if L::ROLLING_HISTORY {
                rolling[k] = row(&lanes.rolling);
            }
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
    use super::super::tests::both_compiled_laws;
    use super::*;
    use crate::contact::ContactLaw;
    use crate::dim::D3;
    use crate::domain::Domain;
    use crate::integrate::Integrator;
    use crate::md::{Md, MdSettings};
    use crate::particles::{ParticleRecord, Particles};
    use glam::DVec3;

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
        let kinds = vec![1u32; n];
        let g = GrainView::<D3> {
            pos: &pos,
            vel: &zeros,
            omega: &zeros,
            radius: &radius,
            mass: &mass,
            frozen: &frozen,
            id: &id,
            kind: &kinds,
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
}
