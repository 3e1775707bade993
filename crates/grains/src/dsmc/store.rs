//! The particle store: a DSMC particle is its position and velocity, nothing
//! else (seed 000 §4: "only the position and velocity of every particle have
//! to be stored"). All particles share one diameter and one mass.
//!
//! Records are stored as one array of `{x, v}` (f64): 32 bytes in 2D, 48 in
//! 3D, so a collision touches one cache line per partner. Sorting adds one
//! `u32` per particle ([`super::sort`]); nothing else grows with N.

use crate::dim::Dim;

/// One particle: position and velocity.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Particle<D: Dim> {
    pub x: D::V,
    pub v: D::V,
}

/// All particles of a run and the properties they share.
#[derive(Clone, Debug)]
pub struct Store<D: Dim> {
    pub p: Vec<Particle<D>>,
    /// Diameter σ = 2R (m).
    pub diameter: f64,
    /// Mass of one particle (kg).
    pub mass: f64,
}

impl<D: Dim> Store<D> {
    pub fn new(p: Vec<Particle<D>>, diameter: f64, mass: f64) -> Self {
        Self { p, diameter, mass }
    }

    pub fn len(&self) -> usize {
        self.p.len()
    }

    pub fn is_empty(&self) -> bool {
        self.p.is_empty()
    }

    /// Volume (area in 2D) of one particle.
    pub fn particle_volume(&self) -> f64 {
        particle_volume(D::D, self.diameter)
    }

    /// Total kinetic energy (J).
    pub fn kinetic_energy(&self) -> f64 {
        0.5 * self.mass * self.p.iter().map(|q| D::norm2(q.v)).sum::<f64>()
    }

    /// Total momentum.
    pub fn momentum(&self) -> D::V {
        self.p.iter().fold(D::zero(), |a, q| a + q.v) * self.mass
    }

    /// Granular temperature m⟨v²⟩/d (J): kinetic energy per particle per
    /// degree of freedom, times two. (The mean velocity is not removed: in
    /// the homogeneous gas it is zero.)
    pub fn granular_temperature(&self) -> f64 {
        if self.p.is_empty() {
            return 0.0;
        }
        2.0 * self.kinetic_energy() / (D::D as f64 * self.p.len() as f64)
    }
}

/// Volume of a sphere (area of a disk in 2D) of diameter `d`.
pub fn particle_volume(dim: usize, d: f64) -> f64 {
    if dim == 2 {
        std::f64::consts::PI * d * d / 4.0
    } else {
        std::f64::consts::PI * d * d * d / 6.0
    }
}

/// The scattering cross section: 4R = 2σ in 2D (a length), 4πR² = πσ² in 3D.
pub fn cross_section(dim: usize, d: f64) -> f64 {
    if dim == 2 {
        2.0 * d
    } else {
        std::f64::consts::PI * d * d
    }
}
