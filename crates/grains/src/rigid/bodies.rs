//! The body store of rigid clumps: per body its shape, centre of mass,
//! orientation, velocity, angular momentum and the force and torque summed
//! from its sub-spheres; velocity Verlet for the centre of mass and
//! NO_SQUISH ([`super::no_squish`]) for the rotation, as LAMMPS's
//! `fix rigid/small` splits a step.
//!
//! Everything is held in 3D (a 2D run's bodies lie in the xy plane and turn
//! about z only), so one code serves both dimensions.

use super::no_squish::{self, Quat, Turned};
use glam::{DMat3, DVec3};

/// A shape as the integrator needs it: sub-sphere centres in the principal
/// frame, mass and principal moments (an in-plane moment is 0 in 2D).
#[derive(Clone, Debug, PartialEq)]
pub struct BodyShape {
    pub name: String,
    pub centers: Vec<DVec3>,
    pub radii: Vec<f64>,
    pub mass: f64,
    pub inertia: [f64; 3],
}

/// One rigid body's state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Body {
    /// Index into [`Bodies::shapes`].
    pub shape: u32,
    /// Grain id of its first sub-sphere; the others follow consecutively.
    pub first_id: u64,
    pub pos: DVec3,
    /// Unit quaternion (w, x, y, z), body frame to space frame.
    pub quat: Quat,
    pub vel: DVec3,
    /// Angular momentum about the centre of mass, space frame.
    pub ang_mom: DVec3,
    /// Force and torque (about the centre of mass) of the last evaluation.
    pub force: DVec3,
    pub torque: DVec3,
}

/// Every body of a run and the shapes they are made of.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Bodies {
    pub shapes: Vec<BodyShape>,
    pub bodies: Vec<Body>,
}

impl Bodies {
    /// The shape of body `b`.
    pub fn shape(&self, b: usize) -> &BodyShape {
        &self.shapes[self.bodies[b].shape as usize]
    }

    /// The half-kick of velocity Verlet: v += ½dt F/M, L += ½dt τ.
    pub fn kick(&mut self, half: f64) {
        for b in &mut self.bodies {
            let m = self.shapes[b.shape as usize].mass;
            b.vel += b.force * (half / m);
            b.ang_mom += b.torque * half;
        }
    }

    /// The drift: x += dt v, and the free rotation over dt (the bodies
    /// turned together in [`no_squish::Lanes`]: each body's bits of
    /// [`no_squish::free_rotation`]); `turned` gets each body's rotation
    /// matrix and spin after it, for placing its sub-spheres.
    pub fn drift(&mut self, dt: f64, turned: &mut Vec<Turned>) {
        turned.clear();
        let mut lanes = no_squish::Lanes::default();
        for block in self.bodies.chunks_mut(no_squish::BLOCK) {
            lanes.clear();
            for b in block.iter_mut() {
                b.pos += b.vel * dt;
                let inertia = self.shapes[b.shape as usize].inertia;
                lanes.push(b.quat, b.ang_mom, inertia);
            }
            lanes.free_rotations(dt);
            for (j, b) in block.iter_mut().enumerate() {
                (b.quat, b.ang_mom) = lanes.body(j);
                turned.push(lanes.turned(j));
            }
        }
    }

    /// Body `b`'s rotation matrix.
    #[inline]
    pub fn rotation(&self, b: usize) -> DMat3 {
        no_squish::matrix(self.bodies[b].quat)
    }

    /// Body `b`'s angular velocity in the space frame.
    pub fn omega(&self, b: usize) -> DVec3 {
        let body = &self.bodies[b];
        no_squish::omega(body.quat, body.ang_mom, self.shape(b).inertia)
    }

    /// Translational kinetic energy Σ ½ M v².
    pub fn translational_energy(&self) -> f64 {
        (0..self.bodies.len())
            .map(|b| 0.5 * self.shape(b).mass * self.bodies[b].vel.length_squared())
            .sum()
    }

    /// Rotational kinetic energy Σ ½ L·ω, with the full inertia tensor.
    pub fn rotational_energy(&self) -> f64 {
        (0..self.bodies.len())
            .map(|b| {
                let body = &self.bodies[b];
                no_squish::rotational_energy(body.quat, body.ang_mom, self.shape(b).inertia)
            })
            .sum()
    }
}
