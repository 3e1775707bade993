//! Initial placement of grains: regular rows from the bottom of a region, or
//! random non-overlapping positions. Random numbers come from a stream derived
//! from (scenario seed, purpose), so a run is reproducible bit for bit.
//!
//! A DSMC gas ([`gas_in_cell_order`]) is drawn particle after particle from
//! one stream, in parallel: a first pass finds where each block of
//! particles starts in the stream, the blocks then draw their particles and
//! write them straight to their places in cell order, which the engine
//! would otherwise reach by a random permutation of every record.

use crate::dim::Dim;
use crate::dsmc::engine::maxwellian;
use crate::dsmc::rng::{Origin, Stream};
use crate::dsmc::sort::CellGrid;
use crate::dsmc::store::Particle;
use crate::error::{Error, Result};
use crate::particles::SizeBand;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use rayon::prelude::*;
use std::collections::HashMap;
use std::time::Instant;

/// Purposes of the random streams, mixed into the seed.
pub const STREAM_DIAMETERS: u64 = 1;
pub const STREAM_POSITIONS: u64 = 2;
pub const STREAM_VELOCITIES: u64 = 3;

/// A generator for one purpose of one scenario seed.
pub fn stream(seed: u64, purpose: u64) -> Xoshiro256PlusPlus {
    // SplitMix-style mixing so nearby seeds give unrelated streams.
    let mut z = seed ^ purpose.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    Xoshiro256PlusPlus::seed_from_u64(z ^ (z >> 31))
}

/// `count` diameters from the band.
pub fn diameters(band: SizeBand, count: usize, seed: u64) -> Vec<f64> {
    let mut rng = stream(seed, STREAM_DIAMETERS);
    (0..count)
        .map(|_| band.diameter(rng.gen::<f64>()))
        .collect()
}

/// Rows of grains on a square (cubic) lattice of pitch `pitch`, filled
/// from the lower corner of the region along x first (then y in 3D), then up.
pub fn lattice<D: Dim>(lo: D::V, hi: D::V, pitch: f64, count: usize) -> Result<Vec<D::V>> {
    let per_axis: Vec<usize> = (0..D::D)
        .map(|a| ((D::get(hi, a) - D::get(lo, a)) / pitch).floor().max(0.0) as usize)
        .collect();
    let capacity: usize = per_axis.iter().product();
    if capacity < count {
        return Err(Error::input(format!(
            "particles.count = {count} does not fit the placement region on a lattice of pitch {pitch:.3e} m \
             (room for {capacity}); enlarge particles.region or the domain, or lower particles.spacing"
        )));
    }
    let mut out = Vec::with_capacity(count);
    for k in 0..count {
        let mut rest = k;
        let mut p = D::zero();
        for (a, &along) in per_axis.iter().enumerate() {
            let idx = if a + 1 == D::D { rest } else { rest % along };
            if a + 1 < D::D {
                rest /= along;
            }
            D::set(&mut p, a, D::get(lo, a) + (idx as f64 + 0.5) * pitch);
        }
        out.push(p);
    }
    Ok(out)
}

/// Random non-overlapping positions for grains of the given diameters
/// inside the region (centres at least a radius from its faces).
pub fn random<D: Dim>(lo: D::V, hi: D::V, diameters: &[f64], seed: u64) -> Result<Vec<D::V>> {
    let mut rng = stream(seed, STREAM_POSITIONS);
    let dmax = diameters.iter().copied().fold(0.0, f64::max);
    let cell = dmax.max(1e-300);
    let mut grid: HashMap<Vec<i64>, Vec<usize>> = HashMap::new();
    let mut placed: Vec<(D::V, f64)> = Vec::with_capacity(diameters.len());
    let key = |p: D::V| -> Vec<i64> {
        (0..D::D)
            .map(|a| (D::get(p, a) / cell).floor() as i64)
            .collect()
    };
    for (n, &d) in diameters.iter().enumerate() {
        let r = 0.5 * d;
        let mut ok = None;
        for _attempt in 0..10_000 {
            let mut p = D::zero();
            for a in 0..D::D {
                let (l, h) = (D::get(lo, a) + r, D::get(hi, a) - r);
                if h <= l {
                    return Err(Error::input("particles.region is narrower than a grain"));
                }
                D::set(&mut p, a, rng.gen_range(l..h));
            }
            let k = key(p);
            let mut free = true;
            let offsets = 3usize.pow(D::D as u32);
            'search: for o in 0..offsets {
                let mut kk = k.clone();
                let mut rest = o;
                for c in kk.iter_mut() {
                    *c += (rest % 3) as i64 - 1;
                    rest /= 3;
                }
                if let Some(list) = grid.get(&kk) {
                    for &j in list {
                        let (q, rq) = placed[j];
                        if D::norm(p - q) < r + rq {
                            free = false;
                            break 'search;
                        }
                    }
                }
            }
            if free {
                ok = Some(p);
                break;
            }
        }
        let Some(p) = ok else {
            return Err(Error::input(format!(
                "could not place grain {} of {} at random without overlap; the region is too dense \
                 (random placement reaches about half the dense packing): enlarge particles.region",
                n + 1,
                diameters.len()
            )));
        };
        grid.entry(key(p)).or_default().push(placed.len());
        placed.push((p, r));
    }
    Ok(placed.into_iter().map(|(p, _)| p).collect())
}

/// Random velocities, each component uniform in ±`amplitude`.
pub fn velocities<D: Dim>(count: usize, amplitude: f64, seed: u64) -> Vec<D::V> {
    let mut rng = stream(seed, STREAM_VELOCITIES);
    (0..count)
        .map(|_| {
            let mut v = D::zero();
            if amplitude > 0.0 {
                for a in 0..D::D {
                    D::set(&mut v, a, rng.gen_range(-amplitude..amplitude));
                }
            }
            v
        })
        .collect()
}

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
    use glam::{DVec2, DVec3};

    #[test]
    fn lattice_fills_rows_from_the_bottom() {
        let p = lattice::<D2>(DVec2::ZERO, DVec2::new(4.0, 10.0), 1.0, 6).unwrap();
        assert_eq!(p[0], DVec2::new(0.5, 0.5));
        assert_eq!(p[3], DVec2::new(3.5, 0.5));
        assert_eq!(p[4], DVec2::new(0.5, 1.5));
        assert!(lattice::<D2>(DVec2::ZERO, DVec2::new(2.0, 2.0), 1.0, 5).is_err());
    }

    #[test]
    fn random_placement_has_no_overlap() {
        let d = diameters(
            SizeBand {
                d0: 1.0,
                width: 0.5,
            },
            300,
            3,
        );
        let p = random::<D3>(DVec3::ZERO, DVec3::splat(12.0), &d, 3).unwrap();
        for i in 0..p.len() {
            for j in i + 1..p.len() {
                assert!((p[i] - p[j]).length() >= 0.5 * (d[i] + d[j]));
            }
        }
        assert_eq!(
            p,
            random::<D3>(DVec3::ZERO, DVec3::splat(12.0), &d, 3).unwrap()
        );
    }

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
