//! Counter-seeded random streams: one small generator per (seed, step, cell),
//! so that the draws a cell makes do not depend on which thread runs it.
//!
//! The generator is SplitMix64 (Steele, Lea & Flood 2014): one 64-bit add and
//! a mixing function per draw. Its state is derived by mixing the three
//! counters, so neighbouring cells and steps get unrelated streams.

/// The SplitMix64 finalizer: a bijective mix of 64 bits.
#[inline(always)]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

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
        Stream {
            state: mix64(self.base ^ cell.wrapping_mul(0xD6E8_FEB8_6659_FD93)),
        }
    }
}

/// A SplitMix64 stream.
#[derive(Clone, Debug)]
pub struct Stream {
    state: u64,
}

impl Stream {
    /// The stream of one (seed, step, cell).
    #[inline(always)]
    pub fn new(seed: u64, step: u64, cell: u64) -> Self {
        StepStreams::new(seed, step).cell(cell)
    }

    /// A stream for a named purpose (initial positions, velocities).
    pub fn for_purpose(seed: u64, purpose: u64) -> Self {
        Self::new(seed, u64::MAX - purpose, u64::MAX)
    }

    #[inline(always)]
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(GOLDEN);
        mix64(self.state)
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
        loop {
            let (x, y) = (self.symmetric(), self.symmetric());
            let s = x * x + y * y;
            if s > 0.0 && s < 1.0 {
                let f = (-2.0 * s.ln() / s).sqrt();
                return (x * f, y * f);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
