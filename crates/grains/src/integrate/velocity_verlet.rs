//! Velocity Verlet in the kick–drift–kick form of LAMMPS's `nve/sphere`:
//! v += ½ dt F/m, x += dt v, ω += ½ dt τ/I; forces (with the half-step
//! velocities); v += ½ dt F/m, ω += ½ dt τ/I.
//!
//! Grains are independent, so both halves run over parallel chunks; the
//! drift also does the neighbour list's displacement test.

use super::{SkinCheck, CHUNK};
use crate::dim::Dim;
use crate::particles::Particles;
use rayon::prelude::*;

/// First half-kick and drift, before the forces. With `skin`, also the
/// neighbour list's displacement test: returns whether a grain moved beyond
/// it (false without `skin`).
pub fn predict<D: Dim>(
    p: &mut Particles<D>,
    dt: f64,
    rotation: bool,
    skin: Option<SkinCheck<D::V>>,
) -> bool {
    let n = p.n_owned();
    let inputs = Inputs {
        force: &p.force,
        torque: &p.torque,
        inv_m: &p.inv_mass,
        inv_i: &p.inv_inertia,
        frozen: &p.frozen,
    };
    p.pos[..n]
        .par_chunks_mut(CHUNK)
        .zip(p.vel[..n].par_chunks_mut(CHUNK))
        .zip(p.omega[..n].par_chunks_mut(CHUNK))
        .enumerate()
        .map(|(c, ((pos, vel), omega))| {
            let first = c * CHUNK;
            match skin {
                Some(s) => {
                    let reference = &s.reference[first..first + pos.len()];
                    let chunk = Moving {
                        first,
                        pos,
                        vel,
                        omega,
                    };
                    predict_chunk::<D, true>(&inputs, chunk, dt, rotation, reference, s.limit2)
                }
                None => {
                    let chunk = Moving {
                        first,
                        pos,
                        vel,
                        omega,
                    };
                    predict_chunk::<D, false>(&inputs, chunk, dt, rotation, &[], 0.0)
                }
            }
        })
        .reduce(|| false, |a, b| a || b)
}

/// Per-grain inputs of the kicks.
struct Inputs<'a, D: Dim> {
    force: &'a [D::V],
    torque: &'a [D::A],
    inv_m: &'a [f64],
    inv_i: &'a [f64],
    frozen: &'a [bool],
}

/// One chunk of grains: its first grain's index and its slices.
struct Moving<'a, D: Dim> {
    first: usize,
    pos: &'a mut [D::V],
    vel: &'a mut [D::V],
    omega: &'a mut [D::A],
}

/// One chunk of [`predict`]; `CHECK` compiles the displacement test in.
#[inline(always)]
fn predict_chunk<D: Dim, const CHECK: bool>(
    g: &Inputs<D>,
    Moving {
        first,
        pos,
        vel,
        omega,
    }: Moving<D>,
    dt: f64,
    rotation: bool,
    reference: &[D::V],
    limit2: f64,
) -> bool {
    let half = 0.5 * dt;
    let mut far = false;
    for k in 0..pos.len() {
        let i = first + k;
        if !g.frozen[i] {
            vel[k] += g.force[i] * (half * g.inv_m[i]);
            pos[k] += vel[k] * dt;
            if rotation {
                omega[k] += g.torque[i] * (half * g.inv_i[i]);
            }
        }
        // Every grain, frozen ones too: something else may have moved them.
        if CHECK {
            far |= D::norm2(pos[k] - reference[k]) > limit2;
        }
    }
    far
}

/// Second half-kick, after the forces.
pub fn correct<D: Dim>(p: &mut Particles<D>, dt: f64, rotation: bool) {
    let half = 0.5 * dt;
    let n = p.n_owned();
    let (force, torque, inv_m, inv_i, frozen) =
        (&p.force, &p.torque, &p.inv_mass, &p.inv_inertia, &p.frozen);
    p.vel[..n]
        .par_chunks_mut(CHUNK)
        .zip(p.omega[..n].par_chunks_mut(CHUNK))
        .enumerate()
        .for_each(|(c, (vel, omega))| {
            for k in 0..vel.len() {
                let i = c * CHUNK + k;
                if frozen[i] {
                    continue;
                }
                vel[k] += force[i] * (half * inv_m[i]);
                if rotation {
                    omega[k] += torque[i] * (half * inv_i[i]);
                }
            }
        });
}
