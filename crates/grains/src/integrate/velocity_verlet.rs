//! Velocity Verlet in the kick–drift–kick form of LAMMPS's `nve/sphere`:
//! v += ½ dt F/m, x += dt v, ω += ½ dt τ/I; forces (with the half-step
//! velocities); v += ½ dt F/m, ω += ½ dt τ/I.

use crate::dim::Dim;
use crate::particles::Particles;

/// First half-kick and drift, before the forces.
pub fn predict<D: Dim>(p: &mut Particles<D>, dt: f64, rotation: bool) {
    let half = 0.5 * dt;
    for i in 0..p.n_owned() {
        if p.frozen[i] {
            continue;
        }
        p.vel[i] += p.force[i] * (half * p.inv_mass[i]);
        p.pos[i] += p.vel[i] * dt;
        if rotation {
            p.omega[i] += p.torque[i] * (half * p.inv_inertia[i]);
        }
    }
}

/// Second half-kick, after the forces.
pub fn correct<D: Dim>(p: &mut Particles<D>, dt: f64, rotation: bool) {
    let half = 0.5 * dt;
    for i in 0..p.n_owned() {
        if p.frozen[i] {
            continue;
        }
        p.vel[i] += p.force[i] * (half * p.inv_mass[i]);
        if rotation {
            p.omega[i] += p.torque[i] * (half * p.inv_inertia[i]);
        }
    }
}
