//! DSMC gas placement, drawn from one stream straight into cell order.
//!
//! Particles are drawn one after another from one stream of (seed,
//! purpose), each a uniform position in a box and a velocity.
//!
//! The draw ([`gas_in_cell_order`]) runs in parallel: a first pass finds
//! where each block of particles starts in the stream, the blocks then draw
//! their particles and write them straight to their places in cell order,
//! which the engine would otherwise reach by a random permutation of every
//! record.

use super::engine::maxwellian;
use super::rng::{Origin, Stream};
use super::sort::CellGrid;
use super::store::Particle;
use crate::dim::Dim;
use crate::error::{Error, Result};
use rayon::prelude::*;
use std::time::Instant;

/// How a DSMC particle's velocity is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GasVelocity {
    /// Maxwellian with √(T/m) = `thermal_speed` (Marsaglia's polar method:
    /// a variable number of draws).
    Maxwellian { thermal_speed: f64 },
    /// Each component uniform in ±`amplitude`.
    Uniform { amplitude: f64 },
}

/// The draws of a DSMC gas: each particle in turn takes its position,
/// uniform in the box `lo..hi`, then its velocity, from the stream of
/// (seed, purpose).
#[derive(Clone, Copy, Debug)]
pub struct GasDraw<D: Dim> {
    pub seed: u64,
    pub purpose: u64,
    pub lo: D::V,
    pub hi: D::V,
    pub velocity: GasVelocity,
}

impl<D: Dim> GasDraw<D> {
    /// The next particle of the stream.
    #[inline]
    pub fn draw(&self, rng: &mut Stream) -> Particle<D> {
        let x = self.position(rng);
        let v = match self.velocity {
            GasVelocity::Maxwellian { thermal_speed } => maxwellian::<D>(rng, thermal_speed),
            GasVelocity::Uniform { amplitude } => {
                let mut v = D::zero();
                for a in 0..D::D {
                    D::set(&mut v, a, rng.symmetric() * amplitude);
                }
                v
            }
        };
        Particle { x, v }
    }

    #[inline(always)]
    fn position(&self, rng: &mut Stream) -> D::V {
        let mut x = D::zero();
        for a in 0..D::D {
            let (l, h) = (D::get(self.lo, a), D::get(self.hi, a));
            D::set(&mut x, a, l + rng.uniform() * (h - l));
        }
        x
    }

    /// The draws of a particle's velocity, without computing it; returns
    /// how many they were.
    #[inline]
    fn skip_velocity(&self, rng: &mut Stream) -> u64 {
        match self.velocity {
            // `maxwellian`: one normal pair in 2D, two in 3D.
            GasVelocity::Maxwellian { .. } => {
                let mut used = rng.skip_normal_pair();
                if D::D == 3 {
                    used += rng.skip_normal_pair();
                }
                used
            }
            GasVelocity::Uniform { .. } => {
                for _ in 0..D::D {
                    rng.next_u64();
                }
                D::D as u64
            }
        }
    }

    /// `count` particles in the serial stream's order (for small gases
    /// and tests).
    pub fn serial(&self, count: usize) -> Vec<Particle<D>> {
        let mut rng = Stream::for_purpose(self.seed, self.purpose);
        (0..count).map(|_| self.draw(&mut rng)).collect()
    }
}

/// Particles per block of the parallel placement: each block knows where
/// its draws start and keeps its own counts per bucket.
const GAS_BLOCK: usize = 1 << 16;
/// Most particles a bucket of the parallel placement should hold: its
/// records (4 MB in 2D) are sorted by cell within a thread's caches.
const GAS_BUCKET: usize = 1 << 17;

/// A gas placed in cell order and what the set-up measured.
pub struct PlacedGas<D: Dim> {
    /// The particles of [`GasDraw::serial`], stably sorted by their cell.
    pub particles: Vec<Particle<D>>,
    /// Σ|v|² in the serial stream's order (the bits a serial sum gives).
    pub speed_sum: f64,
}

/// `count` particles of `draw`, the same as [`GasDraw::serial`] stably
/// sorted by their cell of `grid` (what the engine's first gather does),
/// built in parallel with no second copy of the records and no random
/// permutation of them (a cache and TLB miss per record at 10⁸).
///
/// Cells are grouped into buckets (contiguous ranges of cells, at most
/// about [`GAS_BUCKET`] particles each). Passes: (1) serial, the draw at
/// which every block of [`GAS_BLOCK`] particles starts, running only the
/// rejection tests of the velocities (a few ns a particle); (2) parallel,
/// each block counts its particles per bucket; (3) parallel, each block
/// draws its particles and appends them to its own run in each bucket
/// (blocks in order, so a bucket holds its particles in the stream's
/// order), keeping each |v|² in the stream's order; (4) parallel, each
/// bucket is sorted by cell, stably, within its own range; (5) serial,
/// Σ|v|² in the stream's order. `report` gets one line per pass, with its
/// time.
pub fn gas_in_cell_order<D: Dim>(
    draw: &GasDraw<D>,
    count: usize,
    grid: &CellGrid,
    report: &mut dyn FnMut(&str),
) -> Result<PlacedGas<D>> {
    place_gas(draw, count, grid, report, GAS_BLOCK, GAS_BUCKET)
}

/// [`gas_in_cell_order`] with `block` particles per block and buckets of
/// about `bucket` particles (small ones in the tests).
fn place_gas<D: Dim>(
    draw: &GasDraw<D>,
    count: usize,
    grid: &CellGrid,
    report: &mut dyn FnMut(&str),
    block: usize,
    bucket: usize,
) -> Result<PlacedGas<D>> {
    if count >= u32::MAX as usize {
        return Err(Error::input(format!(
            "particles.count = {count}: a DSMC run holds fewer than {} particles",
            u32::MAX
        )));
    }
    let origin = Origin::for_purpose(draw.seed, draw.purpose);
    let clock = Instant::now();
    let mut t = 0.0;
    let mut lap = |what: String| {
        let now = clock.elapsed().as_secs_f64();
        report(&format!("set-up: {what} ({:.1} s)", now - t));
        t = now;
    };

    // (1) Where each block starts in the stream.
    let mut starts = Vec::with_capacity(count.div_ceil(block));
    let mut drawn = 0u64;
    for k in 0..count {
        if k % block == 0 {
            starts.push(drawn);
        }
        // The position's draws are passed over without being made.
        let mut rng = origin.at(drawn + D::D as u64);
        drawn += D::D as u64 + draw.skip_velocity(&mut rng);
    }
    lap(format!("{count} particles, {drawn} random draws"));

    // (2) Each block's count per bucket.
    let cells = grid.cells();
    let buckets = count.div_ceil(bucket).clamp(1, cells);
    let per_bucket = cells.div_ceil(buckets);
    let buckets = cells.div_ceil(per_bucket);
    let bucket_of = |x: D::V| grid.cell_of::<D>(x) as usize / per_bucket;
    let block_len = |b: usize| block.min(count - b * block);
    let mut runs: Vec<Vec<u32>> = starts
        .par_iter()
        .enumerate()
        .map(|(b, &s)| {
            let mut n = vec![0u32; buckets];
            let mut rng = origin.at(s);
            for _ in 0..block_len(b) {
                n[bucket_of(draw.position(&mut rng))] += 1;
                draw.skip_velocity(&mut rng);
            }
            n
        })
        .collect();
    // Each block's first place in each bucket: buckets in order, blocks in
    // order within a bucket.
    let mut edges = Vec::with_capacity(buckets + 1);
    let mut next = 0u32;
    for k in 0..buckets {
        edges.push(next as usize);
        for run in runs.iter_mut() {
            let n = run[k];
            run[k] = next;
            next += n;
        }
    }
    edges.push(next as usize);
    lap(format!("{buckets} buckets of cells"));

    // (3) Each block draws its particles into its runs.
    let mut particles: Vec<Particle<D>> = Vec::with_capacity(count);
    let mut speed2 = vec![0.0f64; count];
    let out = SharedOut(particles.as_mut_ptr());
    speed2
        .par_chunks_mut(block)
        .zip(starts.par_iter())
        .zip(runs.par_iter_mut())
        .for_each(|((s2, &s), next)| {
            let out = &out;
            let mut rng = origin.at(s);
            for v2 in s2.iter_mut() {
                let q = draw.draw(&mut rng);
                *v2 = D::norm2(q.v);
                let at = &mut next[bucket_of(q.x)];
                // SAFETY: the runs of all blocks in all buckets tile
                // 0..count (the counts of pass 2, the same positions), so
                // every place is written once, by one block.
                unsafe { out.0.add(*at as usize).write(q) };
                *at += 1;
            }
        });
    drop(runs);
    // SAFETY: all `count` records were written above.
    unsafe { particles.set_len(count) };
    lap(format!("drew {count} particles"));

    // (4) Each bucket sorted by cell, stably.
    let mut slices = Vec::with_capacity(buckets);
    let mut rest = particles.as_mut_slice();
    for k in 0..buckets {
        let (head, tail) = rest.split_at_mut(edges[k + 1] - edges[k]);
        slices.push((k, head));
        rest = tail;
    }
    slices.into_par_iter().for_each_init(
        || (Vec::new(), Vec::new()),
        |(scratch, first), (k, slice)| {
            let lo = k * per_bucket;
            first.clear();
            first.resize(per_bucket + 1, 0usize);
            scratch.clear();
            scratch.extend_from_slice(slice);
            for q in scratch.iter() {
                first[grid.cell_of::<D>(q.x) as usize - lo + 1] += 1;
            }
            for c in 1..first.len() {
                first[c] += first[c - 1];
            }
            for q in scratch.iter() {
                let f = &mut first[grid.cell_of::<D>(q.x) as usize - lo];
                slice[*f] = *q;
                *f += 1;
            }
        },
    );
    lap(format!("sorted into {cells} cells"));

    // (5) Σ|v|² in the stream's order, the bits of a serial sum.
    let speed_sum = speed2.iter().copied().sum::<f64>();
    lap("mean square speed".to_string());
    Ok(PlacedGas {
        particles,
        speed_sum,
    })
}

/// The records being written by the blocks of [`gas_in_cell_order`].
struct SharedOut<T>(*mut T);
// SAFETY: the blocks write disjoint records (see `gas_in_cell_order`).
unsafe impl<T> Send for SharedOut<T> {}
unsafe impl<T> Sync for SharedOut<T> {}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::{D2, D3};

    /// The parallel placement is the serial draw stably sorted by cell,
    /// with the serial sum of |v|², on any number of threads; small blocks
    /// and buckets (21 blocks, 14 buckets) exercise the seams
    /// where it could go wrong.
    fn placement_matches_serial<D: Dim>(velocity: GasVelocity) {
        let mut hi = D::zero();
        for a in 0..D::D {
            D::set(&mut hi, a, 3.0 + a as f64);
        }
        let draw = GasDraw::<D> {
            seed: 9,
            purpose: 10,
            lo: D::zero(),
            hi,
            velocity,
        };
        let grid = CellGrid::new(D::D, [0.0; 3], D::to_xyz(hi), 0.25);
        let count = 20_123;
        let serial = draw.serial(count);
        let mut want = serial.clone();
        want.sort_by_key(|q| grid.cell_of::<D>(q.x)); // stable
        let want_sum = serial.iter().map(|q| D::norm2(q.v)).sum::<f64>();
        for threads in [1, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut lines = 0;
            let got = pool
                .install(|| place_gas(&draw, count, &grid, &mut |_| lines += 1, 1000, 1500))
                .unwrap();
            let bits = |p: &[Particle<D>]| -> Vec<[u64; 6]> {
                p.iter()
                    .map(|q| {
                        let (x, v) = (D::to_xyz(q.x), D::to_xyz(q.v));
                        [x[0], x[1], x[2], v[0], v[1], v[2]].map(f64::to_bits)
                    })
                    .collect()
            };
            assert!(bits(&got.particles) == bits(&want), "{threads} threads");
            assert_eq!(got.speed_sum.to_bits(), want_sum.to_bits());
            assert_eq!(lines, 5);
        }
    }

    #[test]
    fn gas_placement_is_the_serial_draw_in_cell_order() {
        let maxwell = GasVelocity::Maxwellian { thermal_speed: 2.0 };
        let uniform = GasVelocity::Uniform { amplitude: 0.5 };
        placement_matches_serial::<D2>(maxwell);
        placement_matches_serial::<D3>(maxwell);
        placement_matches_serial::<D2>(uniform);
        placement_matches_serial::<D3>(uniform);
    }
}
