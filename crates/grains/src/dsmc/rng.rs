//! Counter-seeded random streams: one small generator per (seed, step, cell),
//! so that the draws a cell makes do not depend on which thread runs it.
//!
//! The generator is SplitMix64 (Steele, Lea & Flood 2014), the one of
//! `rand_xoshiro`: one 64-bit add and a mixing function per draw. Its state
//! is derived by mixing the three counters with the same finalizer, so
//! neighbouring cells and steps get unrelated streams. Because the state
//! only advances by a constant, draw k of a stream can be reached directly
//! ([`Origin::at`]): the set-up places particles in parallel
//! with the draws a serial loop would make.

use rand::{RngCore, SeedableRng};
use rand_xoshiro::SplitMix64;

/// The SplitMix64 finalizer: a bijective mix of 64 bits. It hashes the
/// counters into a stream's starting state (the generator itself applies
/// the same function to its state at every draw).
#[inline(always)]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// SplitMix64's state increment (the golden ratio in 64 bits).
const GOLDEN: u64 = 0x9E37_79B9_7F4A_7C15;

/// The streams of one (seed, step): the two counters mixed once per step,
/// so that a cell's stream costs one more mix.
#[derive(Clone, Copy, Debug)]
pub struct StepStreams {
    base: u64,
}

impl StepStreams {
    #[inline(always)]
    pub fn new(seed: u64, step: u64) -> Self {
        let a = mix64(seed ^ 0x5DEE_CE66_D1CE_4E5B);
        Self {
            base: mix64(a ^ step.wrapping_mul(GOLDEN)),
        }
    }

    /// The stream of one cell.
    #[inline(always)]
    pub fn cell(&self, cell: u64) -> Stream {
        Stream::from_state(self.base_state(cell))
    }

    /// The starting state of a cell's stream.
    #[inline(always)]
    fn base_state(&self, cell: u64) -> u64 {
        mix64(self.base ^ cell.wrapping_mul(0xD6E8_FEB8_6659_FD93))
    }
}

/// A SplitMix64 stream.
#[derive(Clone, Debug)]
pub struct Stream {
    core: SplitMix64,
}

impl Stream {
    /// The stream of one (seed, step, cell).
    #[inline(always)]
    pub fn new(seed: u64, step: u64, cell: u64) -> Self {
        StepStreams::new(seed, step).cell(cell)
    }

    /// The stream whose first draw mixes `state` + the increment.
    #[inline(always)]
    fn from_state(state: u64) -> Self {
        Self {
            core: SplitMix64::seed_from_u64(state),
        }
    }

    /// A stream for a named purpose (initial positions, velocities).
    pub fn for_purpose(seed: u64, purpose: u64) -> Self {
        Origin::for_purpose(seed, purpose).at(0)
    }

    #[inline(always)]
    pub fn next_u64(&mut self) -> u64 {
        self.core.next_u64()
    }

    /// Uniform in [0, 1) with 53 random bits.
    #[inline(always)]
    pub fn uniform(&mut self) -> f64 {
        // Through i64 (exact below 2⁵³): one signed conversion instruction.
        (self.next_u64() >> 11) as i64 as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in [-1, 1).
    #[inline(always)]
    pub fn symmetric(&mut self) -> f64 {
        2.0 * self.uniform() - 1.0
    }

    /// Uniform integer in [0, n) by multiply-shift on 32 bits; the bias,
    /// at most n / 2³², is immaterial for cells of a few hundred particles.
    #[inline(always)]
    pub fn below(&mut self, n: u32) -> u32 {
        (((self.next_u64() >> 32) * n as u64) >> 32) as u32
    }

    /// Two distinct indices i ≠ j uniform in [0, n) (n ≥ 2) from one draw:
    /// i from the high 32 bits, j from the low 32 over the n − 1 others.
    #[inline(always)]
    pub fn pair_below(&mut self, n: u32) -> (u32, u32) {
        let r = self.next_u64();
        let i = (((r >> 32) * n as u64) >> 32) as u32;
        let mut j = (((r & 0xFFFF_FFFF) * (n - 1) as u64) >> 32) as u32;
        if j >= i {
            j += 1;
        }
        (i, j)
    }

    /// Two independent standard normal deviates (Marsaglia's polar method).
    pub fn normal_pair(&mut self) -> (f64, f64) {
        let (x, y, s) = self.polar_point();
        let f = (-2.0 * s.ln() / s).sqrt();
        (x * f, y * f)
    }

    /// The draws of [`Self::normal_pair`] without its logarithm and square
    /// root; returns how many it took (two per try).
    #[inline]
    pub fn skip_normal_pair(&mut self) -> u64 {
        let mut draws = 0;
        loop {
            let (x, y) = (self.symmetric(), self.symmetric());
            draws += 2;
            if polar_accepts(x * x + y * y) {
                return draws;
            }
        }
    }

    /// A point uniform in the unit disk but its centre, with its squared
    /// radius: the polar method's rejection loop.
    #[inline]
    fn polar_point(&mut self) -> (f64, f64, f64) {
        loop {
            let (x, y) = (self.symmetric(), self.symmetric());
            let s = x * x + y * y;
            if polar_accepts(s) {
                return (x, y, s);
            }
        }
    }
}

/// Whether the polar method keeps a point of squared radius `s`.
#[inline(always)]
fn polar_accepts(s: f64) -> bool {
    s > 0.0 && s < 1.0
}

/// The start of a purpose stream, from which any of its draws is reached
/// directly (the state of SplitMix64 advances by a constant per draw).
#[derive(Clone, Copy, Debug)]
pub struct Origin {
    state: u64,
}

impl Origin {
    /// The origin of [`Stream::for_purpose`]`(seed, purpose)`.
    pub fn for_purpose(seed: u64, purpose: u64) -> Self {
        Self {
            state: StepStreams::new(seed, u64::MAX - purpose).base_state(u64::MAX),
        }
    }

    /// The stream after `draws` draws: what it gives next is its draw
    /// number `draws` (from 0).
    #[inline]
    pub fn at(self, draws: u64) -> Stream {
        Stream::from_state(self.state.wrapping_add(draws.wrapping_mul(GOLDEN)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PINNED: u64 = 0x50F4_302E_494B_F0C8;

    /// The library core gives the draws of SplitMix64 written out
    /// (state += increment, then the finalizer), which the streams were
    /// before it: the same bits in every run.
    #[test]
    fn library_core_is_splitmix64_and_jumps_ahead() {
        let start = mix64(0x1234_5678 ^ 99u64.wrapping_mul(0xD6E8_FEB8_6659_FD93));
        let mut r = Stream::from_state(start);
        for k in 1..=1000u64 {
            assert_eq!(
                r.next_u64(),
                mix64(start.wrapping_add(k.wrapping_mul(GOLDEN)))
            );
        }
        let mut serial = Stream::for_purpose(5, 10);
        let origin = Origin::for_purpose(5, 10);
        for k in 0..300u64 {
            let want = serial.next_u64();
            assert_eq!(origin.at(k).next_u64(), want, "draw {k}");
        }
        // Skipping a normal pair takes the draws drawing it takes.
        let (mut a, mut b) = (origin.at(7), origin.at(7));
        for _ in 0..1000 {
            a.normal_pair();
            let used = b.skip_normal_pair();
            assert!(used >= 2 && used % 2 == 0);
            assert_eq!(a.next_u64(), b.next_u64());
        }
        // A pinned value: a change of the stream derivation changes every
        // DSMC run's bits.
        assert_eq!(Stream::new(1, 2, 3).next_u64(), PINNED);
    }

    #[test]
    fn uniform_moments_and_below_range() {
        let mut r = Stream::new(7, 3, 11);
        let n = 200_000;
        let mut s = 0.0;
        let mut s2 = 0.0;
        for _ in 0..n {
            let u = r.uniform();
            assert!((0.0..1.0).contains(&u));
            s += u;
            s2 += u * u;
        }
        assert!((s / n as f64 - 0.5).abs() < 0.003);
        assert!((s2 / n as f64 - 1.0 / 3.0).abs() < 0.003);
        for _ in 0..1000 {
            assert!(r.below(7) < 7);
        }
        // Every ordered pair (i, j), i ≠ j, of 5 equally often.
        let mut h = [[0u32; 5]; 5];
        let draws = 200_000;
        for _ in 0..draws {
            let (i, j) = r.pair_below(5);
            assert_ne!(i, j);
            h[i as usize][j as usize] += 1;
        }
        let want = draws as f64 / 20.0;
        for (i, row) in h.iter().enumerate() {
            for (j, &c) in row.iter().enumerate() {
                if i != j {
                    // 4.5 standard deviations of a binomial count.
                    assert!((c as f64 - want).abs() < 4.5 * want.sqrt(), "{i} {j}: {c}");
                }
            }
        }
        assert_ne!(
            Stream::new(7, 3, 11).next_u64(),
            Stream::new(7, 3, 12).next_u64()
        );
        assert_ne!(
            Stream::new(7, 4, 11).next_u64(),
            Stream::new(7, 3, 11).next_u64()
        );
    }
}
