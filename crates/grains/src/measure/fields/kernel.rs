//! The coarse-graining kernels φ of Weinhart, Thornton, Luding & Bokhove
//! (2012, "From discrete particles to continuum fields near a boundary",
//! Granular Matter 14, 289) after Goldhirsch (2010, Granular Matter 12,
//! 239): a cut Gaussian and Lucy's polynomial, each normalised over its
//! support in the grid's number of dimensions, and the kernel's integral
//! along a segment (the contact stress's line integral): in closed form
//! (error functions) for the Gaussian, by Gauss–Legendre quadrature for
//! Lucy's kernel.

use std::f64::consts::PI;

/// Points of the Gauss–Legendre rule of a segment's line integral, on each
/// smooth piece of it (see [`Kernel::along`]).
pub const LINE_POINTS: usize = 12;

/// Below this length over w, the Gaussian's line integral takes the
/// quadrature: its closed form divides a difference of error functions,
/// each good to about 1e-16, by the length over w.
const SHORT_SEGMENT: f64 = 1e-2;

/// The shape of a kernel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    /// exp(−r²/2w²), cut at r = 3w.
    Gaussian,
    /// Lucy's (1977) (1 + 3r/c)(1 − r/c)³ for r < c, with c = √(21/2) w
    /// so that its one-dimensional standard deviation is w, as the
    /// Gaussian's (the variance of Lucy's kernel in 1D is 2c²/21).
    Lucy,
}

/// A radial kernel in `k` dimensions (1, 2 or 3), integrating to 1 over
/// k-space.
#[derive(Clone, Debug, PartialEq)]
pub struct Kernel {
    pub shape: Shape,
    /// The width w (m): the Gaussian's standard deviation.
    pub width: f64,
    /// The number of dimensions the kernel spreads over.
    pub k: usize,
    /// The cutoff radius.
    cutoff: f64,
    /// 1 / ∫ (unnormalised shape) d^k r.
    norm: f64,
    /// The line rule on [0, 1]: nodes and weights.
    nodes: Vec<(f64, f64)>,
}

impl Kernel {
    pub fn new(shape: Shape, width: f64, k: usize) -> Self {
        assert!((1..=3).contains(&k) && width > 0.0);
        let cutoff = match shape {
            Shape::Gaussian => 3.0 * width,
            Shape::Lucy => (21.0f64 / 2.0).sqrt() * width,
        };
        let norm = match shape {
            // S_k ∫_0^{3w} r^{k−1} exp(−r²/2w²) dr, the integrand analytic:
            // 64 Gauss–Legendre points give it to rounding.
            Shape::Gaussian => {
                let surface = [2.0, 2.0 * PI, 4.0 * PI][k - 1];
                let s: f64 = gauss_legendre(64)
                    .iter()
                    .map(|&(x, wt)| {
                        let r = 0.5 * cutoff * (x + 1.0);
                        0.5 * cutoff
                            * wt
                            * r.powi(k as i32 - 1)
                            * (-r * r / (2.0 * width * width)).exp()
                    })
                    .sum();
                1.0 / (surface * s)
            }
            // Lucy's closed forms: 5/4c, 5/πc², 105/16πc³.
            Shape::Lucy => match k {
                1 => 5.0 / (4.0 * cutoff),
                2 => 5.0 / (PI * cutoff * cutoff),
                _ => 105.0 / (16.0 * PI * cutoff.powi(3)),
            },
        };
        let nodes = gauss_legendre(LINE_POINTS)
            .into_iter()
            .map(|(x, w)| (0.5 * (x + 1.0), 0.5 * w))
            .collect();
        Self {
            shape,
            width,
            k,
            cutoff,
            norm,
            nodes,
        }
    }

    /// The radius beyond which φ is zero.
    pub fn cutoff(&self) -> f64 {
        self.cutoff
    }

    /// φ at squared distance `r2`.
    #[inline]
    pub fn at(&self, r2: f64) -> f64 {
        let c = self.cutoff;
        if r2 >= c * c {
            return 0.0;
        }
        match self.shape {
            Shape::Gaussian => self.norm * (-r2 / (2.0 * self.width * self.width)).exp(),
            Shape::Lucy => {
                let u = r2.sqrt() / c;
                let v = 1.0 - u;
                self.norm * (1.0 + 3.0 * u) * v * v * v
            }
        }
    }

    /// ∫_0^1 φ(|q − s b|) ds: the kernel along the segment from the origin
    /// to `b`, seen from `q` (both k-vectors, zero beyond `k`), over the
    /// part of the segment within the cutoff.
    ///
    /// The Gaussian's is the closed form [`Kernel::gaussian_along`] (the
    /// quadrature below on segments shorter than w/100). Lucy's is cut at
    /// the closest approach to `q`, where φ is smooth in s, and each piece
    /// gets [`LINE_POINTS`] Gauss–Legendre points: the error is below 1e-8
    /// of φ(0) (its r³ terms are not analytic in s near the closest
    /// approach); tests/physics/coarse_grain.rs measures both against a
    /// fine composite rule.
    pub fn along(&self, q: [f64; 3], b: [f64; 3]) -> f64 {
        let bb = dot(b, b);
        let qq = dot(q, q);
        let c2 = self.cutoff * self.cutoff;
        if bb == 0.0 {
            return self.at(qq);
        }
        // |q − s b|² = bb s² − 2 qb s + qq < c² between the roots.
        let qb = dot(q, b);
        let disc = qb * qb - bb * (qq - c2);
        if disc <= 0.0 {
            return 0.0;
        }
        let root = disc.sqrt();
        let (s0, s1) = (((qb - root) / bb).max(0.0), ((qb + root) / bb).min(1.0));
        if s1 <= s0 {
            return 0.0;
        }
        let closest = qb / bb;
        if self.shape == Shape::Gaussian && bb >= (SHORT_SEGMENT * self.width).powi(2) {
            return self.gaussian_along(q, b, closest, (s0, s1));
        }
        self.quadrature(q, b, closest, (s0, s1))
    }

    /// [`Kernel::along`] by [`LINE_POINTS`] Gauss–Legendre points on each
    /// side of the closest approach `closest` within `s0..s1`.
    fn quadrature(&self, q: [f64; 3], b: [f64; 3], closest: f64, (s0, s1): (f64, f64)) -> f64 {
        let mut sum = self.piece(q, b, s0, closest.clamp(s0, s1));
        sum += self.piece(q, b, closest.clamp(s0, s1), s1);
        sum
    }

    /// The Gaussian's line integral in closed form: with s* = `closest`
    /// and d = q − s* b, |q − s b|² = d² + |b|² (s − s*)², so
    ///
    /// ∫_{s0}^{s1} N e^{−|q − s b|²/2w²} ds = N e^{−d²/2w²} √(π/2) (w/|b|)
    /// [erf(t1) − erf(t0)], t = |b| (s − s*)/(√2 w),
    ///
    /// the difference taken from erfc on the side away from 0, where erf
    /// is near ±1 and its difference would lose digits.
    fn gaussian_along(&self, q: [f64; 3], b: [f64; 3], closest: f64, (s0, s1): (f64, f64)) -> f64 {
        let w = self.width;
        let len = dot(b, b).sqrt();
        let scale = len / (std::f64::consts::SQRT_2 * w);
        let (t0, t1) = ((s0 - closest) * scale, (s1 - closest) * scale);
        let between = if t0 >= 0.0 {
            libm::erfc(t0) - libm::erfc(t1)
        } else if t1 <= 0.0 {
            libm::erfc(-t1) - libm::erfc(-t0)
        } else {
            libm::erf(t1) - libm::erf(t0)
        };
        let d = [0, 1, 2].map(|a| q[a] - closest * b[a]);
        let across = (-dot(d, d) / (2.0 * w * w)).exp();
        self.norm * across * (0.5 * PI).sqrt() * (w / len) * between
    }

    fn piece(&self, q: [f64; 3], b: [f64; 3], s0: f64, s1: f64) -> f64 {
        let len = s1 - s0;
        if len <= 0.0 {
            return 0.0;
        }
        let mut sum = 0.0;
        for &(x, w) in &self.nodes {
            let s = s0 + len * x;
            let d = [q[0] - s * b[0], q[1] - s * b[1], q[2] - s * b[2]];
            sum += w * self.at(dot(d, d));
        }
        sum * len
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The `n`-point Gauss–Legendre rule on [−1, 1] (nodes, weights): the
/// roots of P_n by Newton's method from Tricomi's first guess.
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // P_n(x) and P_n'(x) by the three-term recurrence.
            let (mut p0, mut p1) = (1.0, x);
            for j in 2..=n {
                let jf = j as f64;
                let p2 = ((2.0 * jf - 1.0) * x * p1 - (jf - 1.0) * p0) / jf;
                p0 = p1;
                p1 = p2;
            }
            let (pn, pm) = (p1, p0);
            dp = n as f64 * (x * pn - pm) / (x * x - 1.0);
            let dx = pn / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        out.push((x, 2.0 / ((1.0 - x * x) * dp * dp)));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Gaussian's closed-form line integral equals the 12-point rule
    /// on each piece (itself within 1e-12 of φ(0) of a fine Simpson rule,
    /// tests/physics/coarse_grain.rs) to 1e-12 of φ(0), over segments from
    /// w/100 (the shortest it takes) to 6w, seen from points near and far,
    /// in 1, 2 and 3 dimensions.
    #[test]
    fn gaussian_closed_form_matches_the_quadrature() {
        let mut x = 0x2545_f491_4f6c_dd1du64;
        let mut uniform = |lo: f64, hi: f64| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            lo + (hi - lo) * (x >> 11) as f64 / (1u64 << 53) as f64
        };
        for k in 1..=3 {
            let w = 0.8;
            let kernel = Kernel::new(Shape::Gaussian, w, k);
            let mut worst: f64 = 0.0;
            for _ in 0..20_000 {
                let (mut q, mut b) = ([0.0; 3], [0.0; 3]);
                for (qa, ba) in q.iter_mut().zip(b.iter_mut()).take(k) {
                    *qa = uniform(-4.0 * w, 4.0 * w);
                    *ba = uniform(-1.0, 1.0);
                }
                // Lengths from w/100 to 6w, evenly in their logarithm.
                let want_len = w * 10f64.powf(uniform(-2.0, 0.78));
                let len = dot(b, b).sqrt();
                if len == 0.0 {
                    continue;
                }
                b = b.map(|e| e * want_len / len);
                let (bb, qb, qq) = (dot(b, b), dot(q, b), dot(q, q));
                let c2 = kernel.cutoff() * kernel.cutoff();
                let disc = qb * qb - bb * (qq - c2);
                if disc <= 0.0 {
                    continue;
                }
                let s0 = ((qb - disc.sqrt()) / bb).max(0.0);
                let s1 = ((qb + disc.sqrt()) / bb).min(1.0);
                if s1 <= s0 {
                    continue;
                }
                let closed = kernel.gaussian_along(q, b, qb / bb, (s0, s1));
                let rule = kernel.quadrature(q, b, qb / bb, (s0, s1));
                worst = worst.max((closed - rule).abs() / kernel.at(0.0));
            }
            assert!(worst < 1e-12, "{k}D: worst difference {worst:e} of φ(0)");
        }
    }

    /// The rule integrates x^{2n−1} exactly: ∫_{−1}^{1} x^{2m} = 2/(2m+1).
    #[test]
    fn gauss_legendre_is_exact_for_polynomials() {
        for n in [1, 2, 5, 12, 64] {
            let rule = gauss_legendre(n);
            for m in 0..n {
                let s: f64 = rule.iter().map(|&(x, w)| w * x.powi(2 * m as i32)).sum();
                let exact = 2.0 / (2 * m + 1) as f64;
                assert!((s - exact).abs() < 1e-13, "n {n} m {m}: {s} vs {exact}");
            }
        }
    }
}
