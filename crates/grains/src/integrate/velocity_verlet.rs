//! Velocity Verlet in the kick–drift–kick form of LAMMPS's `nve/sphere`:
//! v += ½ dt F/m, x += dt v, ω += ½ dt τ/I; forces (with the half-step
//! velocities); v += ½ dt F/m, ω += ½ dt τ/I.
//!
//! Grains are independent, so both halves run over parallel chunks.

use super::CHUNK;
use crate::dim::Dim;
use crate::particles::Particles;
use rayon::prelude::*;

/// First half-kick and drift, before the forces.
pub fn predict<D: Dim>(p: &mut Particles<D>, dt: f64, rotation: bool) {
    let half = 0.5 * dt;
    let n = p.n_owned();
    let (force, torque, inv_m, inv_i, frozen) =
        (&p.force, &p.torque, &p.inv_mass, &p.inv_inertia, &p.frozen);
    p.pos[..n]
        .par_chunks_mut(CHUNK)
        .zip(p.vel[..n].par_chunks_mut(CHUNK))
        .zip(p.omega[..n].par_chunks_mut(CHUNK))
        .enumerate()
        .for_each(|(c, ((pos, vel), omega))| {
            for k in 0..pos.len() {
                let i = c * CHUNK + k;
                if frozen[i] {
                    continue;
                }
                vel[k] += force[i] * (half * inv_m[i]);
                pos[k] += vel[k] * dt;
                if rotation {
                    omega[k] += torque[i] * (half * inv_i[i]);
                }
            }
        });
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
