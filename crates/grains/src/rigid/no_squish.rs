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
pub fn momentum_of(q: Quat, l_body: DVec3) -> Quat {
    mul(q, [0.0, l_body.x, l_body.y, l_body.z]).map(|c| 2.0 * c)
}

/// The body-frame angular momentum L_b = ½ vec(q* ⊗ p) of a unit `q`.
pub fn body_momentum(q: Quat, p: Quat) -> DVec3 {
    let c = mul([q[0], -q[1], -q[2], -q[3]], p);
    DVec3::new(0.5 * c[1], 0.5 * c[2], 0.5 * c[3])
}

/// P_k of Miller et al.: the quaternion turned a quarter about principal
/// axis k (1, 2, 3).
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
    let (kq, kp) = (permute(k, *q), permute(k, *p));
    let phi = (p[0] * kq[0] + p[1] * kq[1] + p[2] * kq[2] + p[3] * kq[3]) / (4.0 * inertia);
    let (s, c) = sin_cos(dt * phi);
    for a in 0..4 {
        q[a] = c * q[a] + s * kq[a];
        p[a] = c * p[a] + s * kp[a];
    }
}

/// Below this angle [`sin_cos`] sums Taylor series (radians).
const SERIES_BELOW: f64 = 0.1;

/// sin and cos of `x`: for |x| < 0.1, the angles of a time step, their
/// Taylor series to x⁹ and x¹⁰ (the first terms left out are below 3e-18
/// relative there, under the rounding of the sum), inlined where a call
/// of the library's sincos cost a third of a clump run's step; the
/// library's above.
#[inline]
fn sin_cos(x: f64) -> (f64, f64) {
    if x.abs() >= SERIES_BELOW {
        return x.sin_cos();
    }
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
    *l = finish(q, p);
}

/// The bodies [`free_rotations`] turns together (its scratch is on the
/// stack).
pub const BLOCK: usize = 32;

/// [`free_rotation`] of many bodies, each `(q, l, inertia)`, with the same
/// bits: turn after turn over all of them, not body after body. One
/// body's five turns are a chain of dependent steps (a sine and cosine
/// each); taken body by body the processor waits on every link, taken
/// turn by turn the bodies' links overlap.
pub fn free_rotations(bodies: &mut [(Quat, DVec3, [f64; 3])], dt: f64) {
    // Scratch on the stack, a block of bodies at a time.
    for block in bodies.chunks_mut(BLOCK) {
        let mut p = [[0.0; 4]; BLOCK];
        for (p, (q, l, _)) in p.iter_mut().zip(block.iter()) {
            *p = momentum(*q, *l);
        }
        for (k, h) in turns(dt) {
            for (p, (q, _, inertia)) in p.iter_mut().zip(block.iter_mut()) {
                turn(k, q, p, *inertia, h);
            }
        }
        for (p, (q, l, _)) in p.iter().zip(block.iter_mut()) {
            *l = finish(q, *p);
        }
    }
}

/// The conjugate momentum of space-frame angular momentum `l`.
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

/// q scaled back to unit length; the space-frame angular momentum.
fn finish(q: &mut Quat, p: Quat) -> DVec3 {
    let norm = q.iter().map(|c| c * c).sum::<f64>().sqrt();
    *q = q.map(|c| c / norm);
    matrix(*q) * body_momentum(*q, p)
}

/// The space-frame angular velocity ω = R I⁻¹ Rᵀ L of a body of principal
/// moments `inertia` (an axis of zero moment gets none).
pub fn omega(q: Quat, l: DVec3, inertia: [f64; 3]) -> DVec3 {
    omega_turned(matrix(q), l, inertia)
}

/// [`omega`] with the body's rotation matrix `r` already at hand.
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

    /// Many bodies turned together give each body's bits of one by one
    /// (planted: the block's momenta shifted by one body, fails).
    #[test]
    fn free_rotations_give_the_bits_of_one_by_one() {
        let bodies: Vec<(Quat, DVec3, [f64; 3])> = (0..70usize)
            .map(|j| {
                let k = j as f64;
                let q = unit([1.0 + k, 0.3 * k, -0.2, 0.1 * k]);
                let l = DVec3::new(0.5 - 0.01 * k, 0.3, k * 0.02);
                let inertia = if j.is_multiple_of(5) {
                    [0.0, 0.0, 1.0 + k]
                } else {
                    [1.0, 1.5 + 0.1 * k, 2.0 + k]
                };
                (q, l, inertia)
            })
            .collect();
        let mut together = bodies.clone();
        free_rotations(&mut together, 1e-3);
        for ((mut q, mut l, inertia), got) in bodies.into_iter().zip(&together) {
            free_rotation(&mut q, &mut l, inertia, 1e-3);
            assert_eq!((q, l), (got.0, got.1));
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
