//! Free rotation of a rigid body by the NO_SQUISH splitting of Miller,
//! Eleftheriou, Pattnaik, Ndirango, Newns & Martyna (2002), J. Chem. Phys.
//! 116, 8649: symplectic and time-reversible, the unit quaternion kept on
//! the unit sphere by construction.
//!
//! The orientation is a unit quaternion q = (w, x, y, z) turning the body
//! (principal) frame into the space frame; its conjugate momentum is
//! p = 2 q ⊗ (0, L_b), with L_b the angular momentum in the body frame. The
//! free-rotation Hamiltonian splits into one term per principal axis, each
//! of which turns (q, p) exactly in the plane of (q, P_k q); the step is
//! their symmetric product R3(dt/2) R2(dt/2) R1(dt) R2(dt/2) R3(dt/2).

use glam::{DMat3, DVec3};

/// A quaternion (w, x, y, z).
pub type Quat = [f64; 4];

/// The Hamilton product a ⊗ b.
#[inline(always)]
pub fn mul(a: Quat, b: Quat) -> Quat {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// The rotation matrix of a unit quaternion (body frame to space frame:
/// its columns are the body axes in the space frame).
pub fn matrix(q: Quat) -> DMat3 {
    let [w, x, y, z] = q;
    DMat3::from_cols(
        DVec3::new(
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y + w * z),
            2.0 * (x * z - w * y),
        ),
        DVec3::new(
            2.0 * (x * y - w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z + w * x),
        ),
        DVec3::new(
            2.0 * (x * z + w * y),
            2.0 * (y * z - w * x),
            1.0 - 2.0 * (x * x + y * y),
        ),
    )
}

/// The conjugate momentum p = 2 q ⊗ (0, L_b) of body-frame angular
/// momentum `l_body`.
#[inline(always)]
pub fn momentum_of(q: Quat, l_body: DVec3) -> Quat {
    mul(q, [0.0, l_body.x, l_body.y, l_body.z]).map(|c| 2.0 * c)
}

/// The body-frame angular momentum L_b = ½ vec(q* ⊗ p) of a unit `q`.
#[inline(always)]
pub fn body_momentum(q: Quat, p: Quat) -> DVec3 {
    let c = mul([q[0], -q[1], -q[2], -q[3]], p);
    DVec3::new(0.5 * c[1], 0.5 * c[2], 0.5 * c[3])
}

/// P_k of Miller et al.: the quaternion turned a quarter about principal
/// axis k (1, 2, 3).
#[inline(always)]
fn permute(k: usize, q: Quat) -> Quat {
    match k {
        1 => [-q[1], q[0], q[3], -q[2]],
        2 => [-q[2], -q[3], q[0], q[1]],
        _ => [-q[3], q[2], -q[1], q[0]],
    }
}

/// The exact flow of the free-rotation term of axis `k` (moment
/// `inertia`) over `dt`: both q and p turn by the angle dt p·P_k q / (4 I_k).
fn rotate(k: usize, q: &mut Quat, p: &mut Quat, inertia: f64, dt: f64) {
    let (s, c) = sin_cos(angle(k, *q, *p, inertia, dt));
    let (kq, kp) = (permute(k, *q), permute(k, *p));
    for a in 0..4 {
        q[a] = c * q[a] + s * kq[a];
        p[a] = c * p[a] + s * kp[a];
    }
}

/// The angle dt p·P_k q / (4 I_k) by which the term of axis `k` turns.
#[inline(always)]
fn angle(k: usize, q: Quat, p: Quat, inertia: f64, dt: f64) -> f64 {
    let kq = permute(k, q);
    dt * ((p[0] * kq[0] + p[1] * kq[1] + p[2] * kq[2] + p[3] * kq[3]) / (4.0 * inertia))
}

/// Below this angle [`sin_cos`] sums Taylor series (radians).
const SERIES_BELOW: f64 = 0.1;

/// sin and cos of `x`: for |x| < 0.1, the angles of a time step, their
/// Taylor series ([`series`]), inlined where a call of the library's
/// sincos cost a third of a clump run's step; the library's above.
#[inline]
fn sin_cos(x: f64) -> (f64, f64) {
    if x.abs() >= SERIES_BELOW {
        return x.sin_cos();
    }
    series(x)
}

/// The Taylor series of sin and cos to x⁹ and x¹⁰: for |x| < 0.1 the
/// first terms left out are below 3e-18 relative, under the rounding of
/// the sum.
#[inline(always)]
fn series(x: f64) -> (f64, f64) {
    let x2 = x * x;
    let s = x
        * (1.0
            + x2 * (-1.0 / 6.0
                + x2 * (1.0 / 120.0 + x2 * (-1.0 / 5040.0 + x2 * (1.0 / 362_880.0)))));
    let c = 1.0
        + x2 * (-0.5
            + x2 * (1.0 / 24.0
                + x2 * (-1.0 / 720.0 + x2 * (1.0 / 40_320.0 + x2 * (-1.0 / 3_628_800.0)))));
    (s, c)
}

/// One NO_SQUISH step of free rotation over `dt`: the orientation `q` and
/// the space-frame angular momentum `l` (constant in free rotation, turned
/// back from the body frame at the end). An axis of zero moment (a disk's
/// in-plane axes in 2D) is skipped: no momentum lies along it. The turns
/// keep |q| only to round-off, and the matrix of a q off the unit sphere
/// by ε is off orthogonal by ε, which shrank |L| by about 1e-12 per step
/// over 10⁵ steps: q is scaled back to unit length after each step.
pub fn free_rotation(q: &mut Quat, l: &mut DVec3, inertia: [f64; 3], dt: f64) {
    let mut p = momentum(*q, *l);
    for (k, h) in turns(dt) {
        turn(k, q, &mut p, inertia, h);
    }
    *l = finish(q, p).0;
}

/// The bodies [`Lanes`] turns together: a multiple of the widest vector
/// (eight lanes of AVX-512), small enough for the stack.
pub const BLOCK: usize = 32;

/// A block of up to [`BLOCK`] bodies in vector lanes (a structure of
/// arrays), turned together by [`Lanes::free_rotations`] with each body's
/// bits of [`free_rotation`]; after it, each body's rotation matrix and
/// spin ω = R I⁻¹ Rᵀ L, the bits of [`matrix`] and [`omega_turned`].
///
/// One body's five turns are a chain of dependent steps; taken turn by
/// turn over the block, lane by lane, the bodies' steps run side by side
/// in vector instructions (the loops are compiled for AVX2 and AVX-512,
/// [`crate::simd`]). A turn's sine and cosine come from the series in
/// every lane; the rare lane whose angle is beyond it takes the library's
/// afterwards, so the loops hold no call and no branch.
#[derive(Clone)]
pub struct Lanes {
    /// Bodies in the block; the lanes after them hold a body at rest.
    len: usize,
    dt: f64,
    q: [[f64; BLOCK]; 4],
    p: [[f64; BLOCK]; 4],
    l: [[f64; BLOCK]; 3],
    inertia: [[f64; BLOCK]; 3],
    /// The current turn's angle, sine and cosine per lane.
    angle: [f64; BLOCK],
    sin: [f64; BLOCK],
    cos: [f64; BLOCK],
    /// After the turns: the rotation matrix's columns and the spin.
    r: [[f64; BLOCK]; 9],
    omega: [[f64; BLOCK]; 3],
}

/// A body's rotation matrix and spin after its turns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Turned {
    pub r: DMat3,
    pub omega: DVec3,
}

impl Default for Lanes {
    fn default() -> Self {
        let mut q = [[0.0; BLOCK]; 4];
        q[0] = [1.0; BLOCK];
        Lanes {
            len: 0,
            dt: 0.0,
            q,
            p: [[0.0; BLOCK]; 4],
            l: [[0.0; BLOCK]; 3],
            inertia: [[1.0; BLOCK]; 3],
            angle: [0.0; BLOCK],
            sin: [0.0; BLOCK],
            cos: [0.0; BLOCK],
            r: [[0.0; BLOCK]; 9],
            omega: [[0.0; BLOCK]; 3],
        }
    }
}

impl Lanes {
    /// Empties the block.
    pub fn clear(&mut self) {
        self.len = 0;
    }

    /// Puts a body (q, L, principal moments) in the next lane; false when
    /// the block is full.
    pub fn push(&mut self, q: Quat, l: DVec3, inertia: [f64; 3]) -> bool {
        let j = self.len;
        if j == BLOCK {
            return false;
        }
        for (row, c) in self.q.iter_mut().zip(q) {
            row[j] = c;
        }
        for a in 0..3 {
            self.l[a][j] = l[a];
            self.inertia[a][j] = inertia[a];
        }
        self.len += 1;
        true
    }

    /// Body `j`'s orientation and angular momentum.
    pub fn body(&self, j: usize) -> (Quat, DVec3) {
        let l = DVec3::new(self.l[0][j], self.l[1][j], self.l[2][j]);
        (self.quat(j), l)
    }

    /// Body `j`'s rotation matrix and spin after [`Lanes::free_rotations`].
    pub fn turned(&self, j: usize) -> Turned {
        let col =
            |c: usize| DVec3::new(self.r[3 * c][j], self.r[3 * c + 1][j], self.r[3 * c + 2][j]);
        Turned {
            r: DMat3::from_cols(col(0), col(1), col(2)),
            omega: DVec3::new(self.omega[0][j], self.omega[1][j], self.omega[2][j]),
        }
    }

    /// The free rotation of every body over `dt` ([`free_rotation`]'s
    /// bits), then each one's matrix and spin.
    pub fn free_rotations(&mut self, dt: f64) {
        self.dt = dt;
        // The lanes after the bodies hold a body at rest.
        for j in self.len..BLOCK {
            for a in 0..4 {
                self.q[a][j] = if a == 0 { 1.0 } else { 0.0 };
            }
            for a in 0..3 {
                self.l[a][j] = 0.0;
                self.inertia[a][j] = 1.0;
            }
        }
        crate::simd::run_widest(self);
    }

    #[inline(always)]
    fn quat(&self, j: usize) -> Quat {
        [self.q[0][j], self.q[1][j], self.q[2][j], self.q[3][j]]
    }

    #[inline(always)]
    fn mom(&self, j: usize) -> Quat {
        [self.p[0][j], self.p[1][j], self.p[2][j], self.p[3][j]]
    }

    /// The turn about axis `K` over `h` in every lane (skipped where the
    /// moment is 0), as [`rotate`].
    #[inline(always)]
    fn turn<const K: usize>(&mut self, h: f64) {
        let mut beyond = false;
        for j in 0..BLOCK {
            let m = self.inertia[K - 1][j];
            let x = angle(K, self.quat(j), self.mom(j), m, h);
            let (s, c) = series(x);
            self.angle[j] = x;
            self.sin[j] = s;
            self.cos[j] = c;
            beyond |= m > 0.0 && x.abs() >= SERIES_BELOW;
        }
        if beyond {
            for j in 0..BLOCK {
                let x = self.angle[j];
                if self.inertia[K - 1][j] > 0.0 && x.abs() >= SERIES_BELOW {
                    (self.sin[j], self.cos[j]) = x.sin_cos();
                }
            }
        }
        for j in 0..BLOCK {
            let turns = self.inertia[K - 1][j] > 0.0;
            let (q, p) = (self.quat(j), self.mom(j));
            let (kq, kp) = (permute(K, q), permute(K, p));
            let (s, c) = (self.sin[j], self.cos[j]);
            for a in 0..4 {
                let (tq, tp) = (c * q[a] + s * kq[a], c * p[a] + s * kp[a]);
                self.q[a][j] = if turns { tq } else { q[a] };
                self.p[a][j] = if turns { tp } else { p[a] };
            }
        }
    }
}

impl crate::simd::Kernel for Lanes {
    #[inline(always)]
    fn run(&mut self) {
        for j in 0..BLOCK {
            let l = DVec3::new(self.l[0][j], self.l[1][j], self.l[2][j]);
            let p = momentum(self.quat(j), l);
            for (row, c) in self.p.iter_mut().zip(p) {
                row[j] = c;
            }
        }
        // The turns of [`turns`], written out for their axes.
        let (dt, half) = (self.dt, 0.5 * self.dt);
        self.turn::<3>(half);
        self.turn::<2>(half);
        self.turn::<1>(dt);
        self.turn::<2>(half);
        self.turn::<3>(half);
        for j in 0..BLOCK {
            let mut q = self.quat(j);
            let (l, r) = finish(&mut q, self.mom(j));
            let inertia = [self.inertia[0][j], self.inertia[1][j], self.inertia[2][j]];
            let w = omega_turned(r, l, inertia);
            for (row, c) in self.q.iter_mut().zip(q) {
                row[j] = c;
            }
            for a in 0..3 {
                self.l[a][j] = l[a];
                self.omega[a][j] = w[a];
                self.r[a][j] = r.x_axis[a];
                self.r[3 + a][j] = r.y_axis[a];
                self.r[6 + a][j] = r.z_axis[a];
            }
        }
    }
}

/// [`free_rotation`] of many bodies, each `(q, l, inertia)`, with the same
/// bits, a block of them at a time in [`Lanes`].
pub fn free_rotations(bodies: &mut [(Quat, DVec3, [f64; 3])], dt: f64) {
    let mut lanes = Lanes::default();
    for block in bodies.chunks_mut(BLOCK) {
        lanes.clear();
        for &(q, l, inertia) in block.iter() {
            lanes.push(q, l, inertia);
        }
        lanes.free_rotations(dt);
        for (j, (q, l, _)) in block.iter_mut().enumerate() {
            (*q, *l) = lanes.body(j);
        }
    }
}

/// The conjugate momentum of space-frame angular momentum `l`.
#[inline(always)]
fn momentum(q: Quat, l: DVec3) -> Quat {
    let l_body = matrix(q).transpose() * l;
    momentum_of(q, l_body)
}

/// The symmetric splitting's turns: axis and time.
fn turns(dt: f64) -> [(usize, f64); 5] {
    let half = 0.5 * dt;
    [(3, half), (2, half), (1, dt), (2, half), (3, half)]
}

/// The turn about axis `k` over `h`, skipped for a zero moment.
#[inline]
fn turn(k: usize, q: &mut Quat, p: &mut Quat, inertia: [f64; 3], h: f64) {
    if inertia[k - 1] > 0.0 {
        rotate(k, q, p, inertia[k - 1], h);
    }
}

/// q scaled back to unit length; the space-frame angular momentum and the
/// rotation matrix of the new q.
#[inline(always)]
fn finish(q: &mut Quat, p: Quat) -> (DVec3, DMat3) {
    let norm = q.iter().map(|c| c * c).sum::<f64>().sqrt();
    *q = q.map(|c| c / norm);
    let r = matrix(*q);
    (r * body_momentum(*q, p), r)
}

/// The space-frame angular velocity ω = R I⁻¹ Rᵀ L of a body of principal
/// moments `inertia` (an axis of zero moment gets none).
pub fn omega(q: Quat, l: DVec3, inertia: [f64; 3]) -> DVec3 {
    omega_turned(matrix(q), l, inertia)
}

/// [`omega`] with the body's rotation matrix `r` already at hand.
#[inline(always)]
pub fn omega_turned(r: DMat3, l: DVec3, inertia: [f64; 3]) -> DVec3 {
    let lb = r.transpose() * l;
    let inv = |m: f64| if m > 0.0 { 1.0 / m } else { 0.0 };
    r * DVec3::new(
        lb.x * inv(inertia[0]),
        lb.y * inv(inertia[1]),
        lb.z * inv(inertia[2]),
    )
}

/// Rotational kinetic energy ½ Σ L_b,k² / I_k.
pub fn rotational_energy(q: Quat, l: DVec3, inertia: [f64; 3]) -> f64 {
    let lb = matrix(q).transpose() * l;
    let e = |x: f64, m: f64| if m > 0.0 { x * x / m } else { 0.0 };
    0.5 * (e(lb.x, inertia[0]) + e(lb.y, inertia[1]) + e(lb.z, inertia[2]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit(q: Quat) -> Quat {
        let n = q.iter().map(|c| c * c).sum::<f64>().sqrt();
        q.map(|c| c / n)
    }

    /// The series against the library's sin and cos: within 2 units in
    /// the last place over the angles they serve, and the library's own
    /// from 0.1 on.
    #[test]
    fn sin_cos_series_matches_the_library() {
        let mut worst = 0.0f64;
        for k in -2000..=2000 {
            let x = k as f64 * 0.099_99 / 2000.0 + 1e-7;
            let (s, c) = sin_cos(x);
            let (ls, lc) = x.sin_cos();
            worst = worst.max(((s - ls) / ls).abs()).max(((c - lc) / lc).abs());
        }
        assert!(worst <= 2.3e-16, "worst relative difference {worst:e}");
        assert_eq!(sin_cos(0.5), 0.5f64.sin_cos());
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
    }

    /// Bodies for the lanes' tests: 2D ones (in-plane moments 0) and,
    /// every seventh, a spin fast enough that its turns go beyond the
    /// series (angles up to 0.25 at dt = 1e-3).
    fn test_bodies() -> Vec<(Quat, DVec3, [f64; 3])> {
        (0..70usize)
            .map(|j| {
                let k = j as f64;
                let q = unit([1.0 + k, 0.3 * k, -0.2, 0.1 * k]);
                let mut l = DVec3::new(0.5 - 0.01 * k, 0.3, k * 0.02);
                if j % 7 == 3 {
                    l *= 1000.0;
                }
                let inertia = if j.is_multiple_of(5) {
                    [0.0, 0.0, 1.0 + k]
                } else {
                    [1.0, 1.5 + 0.1 * k, 2.0 + k]
                };
                (q, l, inertia)
            })
            .collect()
    }

    /// Many bodies turned together give each body's bits of one by one,
    /// those whose turns go beyond the series too (planted: the block's
    /// momenta shifted by one body, fails; the library's sine left out
    /// beyond the series, fails).
    #[test]
    fn free_rotations_give_the_bits_of_one_by_one() {
        let bodies = test_bodies();
        let beyond = bodies.iter().filter(|(q, l, inertia)| {
            let p = momentum(*q, *l);
            (1..=3).any(|k| {
                inertia[k - 1] > 0.0 && angle(k, *q, p, inertia[k - 1], 1e-3).abs() >= SERIES_BELOW
            })
        });
        assert!(beyond.count() >= 5, "too few bodies beyond the series");
        let mut together = bodies.clone();
        free_rotations(&mut together, 1e-3);
        for ((mut q, mut l, inertia), got) in bodies.into_iter().zip(&together) {
            free_rotation(&mut q, &mut l, inertia, 1e-3);
            assert_eq!((q, l), (got.0, got.1));
        }
    }

    /// The lanes' matrix and spin after the turns are the bits of
    /// [`matrix`] and [`omega_turned`] of the turned body, in a full block
    /// and in a part-filled one (planted: the spin from the matrix of q
    /// before it is scaled back to unit length, fails).
    #[test]
    fn lanes_give_the_matrix_and_spin_of_the_turned_body() {
        let bodies = test_bodies();
        let mut lanes = Lanes::default();
        for block in [&bodies[..BLOCK], &bodies[BLOCK..BLOCK + 5]] {
            lanes.clear();
            for &(q, l, inertia) in block {
                assert!(lanes.push(q, l, inertia));
            }
            // A full block takes no more.
            assert_eq!(
                lanes.push(block[0].0, block[0].1, block[0].2),
                block.len() < BLOCK
            );
            lanes.free_rotations(1e-3);
            for (j, &(_, _, inertia)) in block.iter().enumerate() {
                let (q, l) = lanes.body(j);
                let r = matrix(q);
                let want = Turned {
                    r,
                    omega: omega_turned(r, l, inertia),
                };
                assert_eq!(lanes.turned(j), want);
            }
        }
    }

    #[test]
    fn matrix_turns_as_the_quaternion_does() {
        // v' = q ⊗ (0, v) ⊗ q*, written out against the matrix.
        let q = unit([0.3, -0.5, 0.7, 0.2]);
        let v = DVec3::new(0.4, -1.1, 2.3);
        let t = mul(mul(q, [0.0, v.x, v.y, v.z]), [q[0], -q[1], -q[2], -q[3]]);
        let m = matrix(q) * v;
        assert!((m - DVec3::new(t[1], t[2], t[3])).length() < 1e-14);
        // The momentum maps there and back.
        let back = body_momentum(q, momentum_of(q, v));
        assert!((back - v).length() < 1e-14);
    }
}
