//! Volume, first and second moments of a union of spheres (or of disks),
//! overlaps counted once.
//!
//! The union is cut into pieces, one per sphere in input order: sphere i
//! contributes the points of its ball that no earlier sphere holds. That
//! piece is exact when at most one earlier sphere meets ball i: the ball
//! less its lens with that sphere, the lens being two caps cut by the
//! radical plane (Weisstein, "Sphere-Sphere Intersection"; a cap's moments
//! are slice integrals in closed form). When two or more earlier spheres
//! meet it, the piece is integrated on rays from the sphere's centre: along
//! each ray the covered intervals are exact (a quadratic per sphere), so
//! the radial integrals ∫t² dt, ∫t³ dt, ∫t⁴ dt are exact and only the
//! directions are a quadrature (Gauss–Legendre in cos θ times the
//! trapezoid rule in φ; the trapezoid rule in φ for disks), doubled until
//! two successive results agree to [`TOLERANCE`] of the piece's ball.

use glam::{DMat3, DVec3};
use std::f64::consts::PI;

/// Agreement of two successive quadratures at which the refinement
/// stops, relative to the moments of the sphere's whole ball. The
/// integrand has kinks where a ray grazes a sphere, so the error falls as
/// the square of the step: the last result is within about a third of
/// the last change.
pub const TOLERANCE: f64 = 1e-7;

/// Most polar nodes of the sphere quadrature (twice as many in φ).
const MAX_POLAR: usize = 1024;
/// Most directions of the disk quadrature.
const MAX_DIRECTIONS: usize = 1 << 21;

/// The moments of a region about the input origin: its measure (volume in
/// 3D, area in 2D), ∫x and ∫x xᵀ over it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Moments {
    pub m0: f64,
    pub m1: DVec3,
    pub m2: DMat3,
}

impl Moments {
    /// No region.
    pub const ZERO: Moments = Moments {
        m0: 0.0,
        m1: DVec3::ZERO,
        m2: DMat3::ZERO,
    };

    /// Moments about a centre `c` moved to the origin: ∫(c + y) and
    /// ∫(c + y)(c + y)ᵀ from ∫1, ∫y and ∫y yᵀ.
    fn shifted(c: DVec3, m0: f64, y1: DVec3, y2: DMat3) -> Moments {
        Moments {
            m0,
            m1: c * m0 + y1,
            m2: outer(c, c) * m0 + outer(c, y1) + outer(y1, c) + y2,
        }
    }

    fn add(self, o: Moments) -> Moments {
        Moments {
            m0: self.m0 + o.m0,
            m1: self.m1 + o.m1,
            m2: self.m2 + o.m2,
        }
    }

    fn sub(self, o: Moments) -> Moments {
        Moments {
            m0: self.m0 - o.m0,
            m1: self.m1 - o.m1,
            m2: self.m2 - o.m2,
        }
    }

    /// The centre of the region.
    pub fn centroid(&self) -> DVec3 {
        self.m1 / self.m0
    }

    /// ∫(x − x̄)(x − x̄)ᵀ, the second moment about the centroid.
    pub fn central(&self) -> DMat3 {
        self.m2 - outer(self.m1, self.m1) / self.m0
    }
}

/// The outer product a bᵀ.
pub fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// The largest |entry| of a matrix.
pub fn max_abs(m: DMat3) -> f64 {
    m.to_cols_array().iter().fold(0.0f64, |a, x| a.max(x.abs()))
}

/// How the union's moments were obtained.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Union {
    pub moments: Moments,
    /// True when every piece had a closed form.
    pub exact: bool,
    /// The largest last change of a refined quadrature, relative to its
    /// ball (0 when exact).
    pub last_change: f64,
}

/// A ball or a disk: centre (z = 0 for disks) and radius.
pub type Ball = (DVec3, f64);

/// Whether two balls share interior points.
fn overlap(a: Ball, b: Ball) -> bool {
    (a.0 - b.0).length() < a.1 + b.1
}

/// Moments of the union of balls (3D volume).
pub fn union_3d(balls: &[Ball]) -> Union {
    union(balls, &Solid)
}

/// Moments of the union of disks in the z = 0 plane (area).
pub fn union_2d(disks: &[Ball]) -> Union {
    union(disks, &Flat)
}

/// The exact pieces of one dimension: a whole ball and a cap.
trait Pieces {
    /// ∫1, ∫y, ∫y yᵀ of a ball of radius r about its centre.
    fn ball(&self, r: f64) -> (f64, DMat3);
    /// ∫1, ∫y·n and the second moments along n and across it (per
    /// transverse axis) of the cap {|y| ≤ r, y·n ≥ s}.
    fn cap(&self, r: f64, s: f64) -> [f64; 4];
    /// Transverse projector for the cap's second moment.
    fn across(&self, n: DVec3) -> DMat3;
    /// The piece of ball `i` no ball of `earlier` holds, by quadrature.
    fn quadrature(&self, b: Ball, earlier: &[Ball]) -> (Moments, f64);
}

struct Solid;
struct Flat;

impl Pieces for Solid {
    fn ball(&self, r: f64) -> (f64, DMat3) {
        let v = 4.0 / 3.0 * PI * r.powi(3);
        (
            v,
            DMat3::from_diagonal(DVec3::splat(4.0 * PI * r.powi(5) / 15.0)),
        )
    }

    fn cap(&self, r: f64, s: f64) -> [f64; 4] {
        // Slices z ∈ [s, r] of area π(r² − z²).
        let r2 = r * r;
        let f0 = |z: f64| PI * (r2 * z - z.powi(3) / 3.0);
        let f1 = |z: f64| PI * (r2 * z * z / 2.0 - z.powi(4) / 4.0);
        let fzz = |z: f64| PI * (r2 * z.powi(3) / 3.0 - z.powi(5) / 5.0);
        // A slice's second moment across: π ρ⁴ / 4 with ρ² = r² − z².
        let ftt = |z: f64| PI / 4.0 * (r2 * r2 * z - 2.0 * r2 * z.powi(3) / 3.0 + z.powi(5) / 5.0);
        [
            f0(r) - f0(s),
            f1(r) - f1(s),
            fzz(r) - fzz(s),
            ftt(r) - ftt(s),
        ]
    }

    fn across(&self, n: DVec3) -> DMat3 {
        DMat3::IDENTITY - outer(n, n)
    }

    fn quadrature(&self, b: Ball, earlier: &[Ball]) -> (Moments, f64) {
        let volume = self.ball(b.1).0;
        refine(b.1, volume, 16, MAX_POLAR, |n| sphere_rays(b, earlier, n))
    }
}

/// A ball's moments by `rays` over `n` directions, `n` doubled from
/// `start` until they change by less than [`TOLERANCE`] (relative to the
/// ball of radius `r` and size `size`) or `n` reaches `max`; with that last
/// change.
fn refine(
    r: f64,
    size: f64,
    start: usize,
    max: usize,
    rays: impl Fn(usize) -> Moments,
) -> (Moments, f64) {
    let mut n = start;
    let mut last = rays(n);
    loop {
        n *= 2;
        let next = rays(n);
        let change = change(&last, &next, r, size);
        last = next;
        if change < TOLERANCE || n >= max {
            return (last, change);
        }
    }
}

impl Pieces for Flat {
    fn ball(&self, r: f64) -> (f64, DMat3) {
        let a = PI * r * r;
        let m = PI * r.powi(4) / 4.0;
        (a, DMat3::from_diagonal(DVec3::new(m, m, 0.0)))
    }

    fn cap(&self, r: f64, s: f64) -> [f64; 4] {
        // Chords z ∈ [s, r] of length 2w, w = √(r² − z²); antiderivatives
        // of 2w, 2zw, 2z²w and the chord's own moment 2w³/3.
        let r2 = r * r;
        let w = |z: f64| (r2 - z * z).max(0.0).sqrt();
        let th = |z: f64| (z / r).clamp(-1.0, 1.0).asin();
        let f0 = |z: f64| z * w(z) + r2 * th(z);
        let f1 = |z: f64| -2.0 / 3.0 * w(z).powi(3);
        let fzz = |z: f64| z * (2.0 * z * z - r2) * w(z) / 4.0 + r2 * r2 * th(z) / 4.0;
        let ftt = |z: f64| z * (5.0 * r2 - 2.0 * z * z) * w(z) / 12.0 + r2 * r2 * th(z) / 4.0;
        [
            f0(r) - f0(s),
            f1(r) - f1(s),
            fzz(r) - fzz(s),
            ftt(r) - ftt(s),
        ]
    }

    fn across(&self, n: DVec3) -> DMat3 {
        // The one in-plane axis across n.
        let t = DVec3::new(-n.y, n.x, 0.0);
        outer(t, t)
    }

    fn quadrature(&self, b: Ball, earlier: &[Ball]) -> (Moments, f64) {
        let area = self.ball(b.1).0;
        refine(b.1, area, 64, MAX_DIRECTIONS, |n| disk_rays(b, earlier, n))
    }
}

/// The largest change between two quadratures of a piece, relative to
/// its ball's measure (times its radius for ∫y, its square for ∫y yᵀ),
/// both taken about the ball's centre.
fn change(a: &Moments, b: &Moments, r: f64, measure: f64) -> f64 {
    let d0 = (a.m0 - b.m0).abs();
    let d1 = (a.m1 - b.m1).abs().max_element() / r;
    let d2 = max_abs(a.m2 - b.m2) / (r * r);
    d0.max(d1).max(d2) / measure
}

fn union(balls: &[Ball], dim: &dyn Pieces) -> Union {
    let mut total = Moments::ZERO;
    let mut exact = true;
    let mut last_change = 0.0f64;
    for (i, &b) in balls.iter().enumerate() {
        let earlier: Vec<Ball> = balls[..i]
            .iter()
            .copied()
            .filter(|&e| overlap(b, e))
            .collect();
        let (v, y2) = dim.ball(b.1);
        let whole = Moments::shifted(b.0, v, DVec3::ZERO, y2);
        let piece = match earlier.as_slice() {
            [] => whole,
            [e] => whole.sub(lens(b, *e, dim)),
            _ => {
                exact = false;
                // The quadrature is about the ball's centre; moved after.
                let (m, c) = dim.quadrature((DVec3::ZERO, b.1), &shift(&earlier, b.0));
                last_change = last_change.max(c);
                Moments::shifted(b.0, m.m0, m.m1, m.m2)
            }
        };
        total = total.add(piece);
    }
    Union {
        moments: total,
        exact,
        last_change,
    }
}

fn shift(balls: &[Ball], by: DVec3) -> Vec<Ball> {
    balls.iter().map(|&(c, r)| (c - by, r)).collect()
}

/// The part of ball `a` that ball `b` holds.
fn lens(a: Ball, b: Ball, dim: &dyn Pieces) -> Moments {
    let d = (b.0 - a.0).length();
    if d + a.1 <= b.1 {
        // a inside b: all of a.
        let (v, y2) = dim.ball(a.1);
        return Moments::shifted(a.0, v, DVec3::ZERO, y2);
    }
    if d + b.1 <= a.1 {
        // b inside a: all of b.
        let (v, y2) = dim.ball(b.1);
        return Moments::shifted(b.0, v, DVec3::ZERO, y2);
    }
    let n = (b.0 - a.0) / d;
    // The radical plane, at s_a from a's centre towards b: beyond it
    // every point of ball a is in ball b, before it every point of ball
    // b is in ball a.
    let sa = (d * d + a.1 * a.1 - b.1 * b.1) / (2.0 * d);
    let sb = d - sa;
    cap(a, n, sa, dim).add(cap(b, -n, sb, dim))
}

/// Moments of the cap {|x − c| ≤ r, (x − c)·n ≥ s} about the origin.
fn cap(ball: Ball, n: DVec3, s: f64, dim: &dyn Pieces) -> Moments {
    let [m0, m1, mzz, mtt] = dim.cap(ball.1, s);
    let y2 = outer(n, n) * mzz + dim.across(n) * mtt;
    Moments::shifted(ball.0, m0, n * m1, y2)
}

/// The intervals of t ∈ [0, r] on the ray t u that the balls cover,
/// merged, as ∫ t^k over the uncovered rest for k = 1..4 (index k − 1).
fn uncovered(u: DVec3, r: f64, balls: &[Ball], cuts: &mut Vec<(f64, f64)>) -> [f64; 4] {
    cuts.clear();
    for &(c, rb) in balls {
        // |t u − c|² = rb²: t² − 2 t u·c + |c|² − rb² = 0.
        let b = u.dot(c);
        let disc = b * b - (c.length_squared() - rb * rb);
        if disc <= 0.0 {
            continue;
        }
        let q = disc.sqrt();
        let (t1, t2) = ((b - q).max(0.0), (b + q).min(r));
        if t1 < t2 {
            cuts.push((t1, t2));
        }
    }
    cuts.sort_by(|x, y| x.0.total_cmp(&y.0));
    let pow = |t: f64| {
        [
            t * t / 2.0,
            t.powi(3) / 3.0,
            t.powi(4) / 4.0,
            t.powi(5) / 5.0,
        ]
    };
    let mut out = pow(r);
    let mut end = 0.0f64;
    for &(a, b) in cuts.iter() {
        let a = a.max(end);
        if b > a {
            let (pa, pb) = (pow(a), pow(b));
            for k in 0..4 {
                out[k] -= pb[k] - pa[k];
            }
            end = b;
        }
    }
    out
}

/// The piece of ball `b` (centred at the origin) outside `balls`, by
/// `polar` Gauss–Legendre nodes in cos θ and 2·`polar` in φ.
fn sphere_rays(b: Ball, balls: &[Ball], polar: usize) -> Moments {
    let (nodes, weights) = gauss_legendre(polar);
    let azim = 2 * polar;
    let dphi = 2.0 * PI / azim as f64;
    let mut cuts = Vec::new();
    let mut m = Moments::ZERO;
    for (&mu, &w) in nodes.iter().zip(&weights) {
        let sin = (1.0 - mu * mu).max(0.0).sqrt();
        for k in 0..azim {
            let phi = (k as f64 + 0.5) * dphi;
            let u = DVec3::new(sin * phi.cos(), sin * phi.sin(), mu);
            let t = uncovered(u, b.1, balls, &mut cuts);
            let wd = w * dphi;
            m.m0 += wd * t[1];
            m.m1 += u * (wd * t[2]);
            m.m2 += outer(u, u) * (wd * t[3]);
        }
    }
    m
}

/// The piece of disk `b` (centred at the origin) outside `disks`, by the
/// trapezoid rule on `dirs` directions.
fn disk_rays(b: Ball, disks: &[Ball], dirs: usize) -> Moments {
    let dphi = 2.0 * PI / dirs as f64;
    let mut cuts = Vec::new();
    let mut m = Moments::ZERO;
    for k in 0..dirs {
        let phi = (k as f64 + 0.5) * dphi;
        let u = DVec3::new(phi.cos(), phi.sin(), 0.0);
        let t = uncovered(u, b.1, disks, &mut cuts);
        m.m0 += dphi * t[0];
        m.m1 += u * (dphi * t[1]);
        m.m2 += outer(u, u) * (dphi * t[2]);
    }
    m
}

/// Nodes and weights of the n-point Gauss–Legendre rule on [−1, 1]:
/// Newton's method on the Legendre polynomial from its three-term
/// recurrence, started at the Chebyshev-like guesses cos(π(i − ¼)/(n + ½)).
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n.div_ceil(2) {
        let mut z = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, 0.0);
            for j in 0..n {
                let p2 = p1;
                p1 = p0;
                p0 = ((2 * j + 1) as f64 * z * p1 - j as f64 * p2) / (j + 1) as f64;
            }
            dp = n as f64 * (z * p0 - p1) / (z * z - 1.0);
            let dz = p0 / dp;
            z -= dz;
            if dz.abs() < 1e-15 {
                break;
            }
        }
        x[i] = z;
        x[n - 1 - i] = -z;
        w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
        w[n - 1 - i] = w[i];
    }
    (x, w)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials() {
        let (x, w) = gauss_legendre(8);
        // ∫ x⁶ over [−1, 1] = 2/7; the rule is exact to degree 15.
        let s: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(6)).sum();
        assert!((s - 2.0 / 7.0).abs() < 1e-14, "{s}");
    }

    #[test]
    fn whole_caps_are_whole_balls() {
        for dim in [&Solid as &dyn Pieces, &Flat] {
            let (v, y2) = dim.ball(1.3);
            let [m0, m1, mzz, mtt] = dim.cap(1.3, -1.3);
            assert!((m0 - v).abs() < 1e-12 && m1.abs() < 1e-12, "{m0} {v} {m1}");
            assert!((mzz - y2.x_axis.x).abs() < 1e-12 && (mtt - y2.y_axis.y).abs() < 1e-12);
        }
    }

    #[test]
    fn quadrature_agrees_with_the_lens() {
        // Ball 1 met by one earlier ball: closed form against rays.
        let a = (DVec3::ZERO, 1.0);
        let b = (DVec3::new(0.3, 0.9, -0.4), 0.8);
        let exact = (Moments::shifted(DVec3::ZERO, 4.0 / 3.0 * PI, DVec3::ZERO, Solid.ball(1.0).1))
            .sub(lens(a, b, &Solid));
        let (q, _) = Solid.quadrature(a, &[b]);
        assert!((q.m0 - exact.m0).abs() < 1e-6 * exact.m0, "{q:?} {exact:?}");
        assert!((q.m1 - exact.m1).length() < 1e-6, "{q:?} {exact:?}");
        let exact2 = Moments::shifted(DVec3::ZERO, PI, DVec3::ZERO, Flat.ball(1.0).1).sub(lens(
            a,
            (b.0 * DVec3::new(1.0, 1.0, 0.0), b.1),
            &Flat,
        ));
        let (q2, _) = Flat.quadrature(a, &[(b.0 * DVec3::new(1.0, 1.0, 0.0), b.1)]);
        assert!(
            (q2.m0 - exact2.m0).abs() < 1e-6 * exact2.m0,
            "{q2:?} {exact2:?}"
        );
        assert!(max_abs(q2.m2 - exact2.m2) < 1e-6, "{q2:?} {exact2:?}");
    }
}
