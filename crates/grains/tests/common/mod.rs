//! Small builders shared by the physics tests.
#![allow(dead_code)]

pub mod normal;
pub mod runs;
pub mod vtk;

use grains::contact::{ContactLaw, MassScaling};
use grains::md::{Md, MdSettings};
use grains::{Dim, Domain, ParticleRecord, Particles};

pub fn hooke(kn: f64, gamma_n: f64, scaling: MassScaling) -> ContactLaw {
    ContactLaw {
        kn,
        beta: 1.0,
        gamma_n,
        gamma_t: 0.0,
        kt: 0.0,
        mu: f64::INFINITY,
        scaling,
        rotation: false,
    }
}

/// Hooke with damping (kn = 1e6, γn = 300), a tangential spring capped at
/// `mu` (none when `mu` is 0) and rotation on: the wall tests' law. The
/// spring's stiffness is kt = 2/7 kn for spheres and 1/3 kn for disks, so
/// that a grain's tangential and normal oscillations at a contact keep in
/// step (the ratio of the inverse effective masses of a rolling sphere or
/// disk).
pub fn wall_law<D: Dim>(mu: f64) -> ContactLaw {
    let ratio = if D::D == 3 { 2.0 / 7.0 } else { 1.0 / 3.0 };
    ContactLaw {
        kt: if mu > 0.0 { ratio * 1.0e6 } else { 0.0 },
        gamma_t: if mu > 0.0 { 100.0 } else { 0.0 },
        mu: if mu > 0.0 { mu } else { f64::INFINITY },
        rotation: true,
        ..hooke(1.0e6, 300.0, MassScaling::Reduced)
    }
}

/// A grain of diameter `d` and density 1 (sphere mass), at rest.
pub fn grain<D: Dim>(id: u64, pos: D::V, d: f64) -> ParticleRecord<D> {
    let m = grains::MassModel::Sphere.mass(1.0, d);
    let i = grains::MassModel::Sphere.inertia(m, 0.5 * d);
    ParticleRecord::new(id, pos, 0.5 * d, m, i)
}

/// An open (non-periodic) box large enough for a few grains.
pub fn open_box<D: Dim>(half: f64) -> Domain<D> {
    let mut lo = D::zero();
    let mut hi = D::zero();
    for a in 0..D::D {
        D::set(&mut lo, a, -half);
        D::set(&mut hi, a, half);
    }
    Domain::new(lo, hi, [false; 3])
}

pub fn engine<D: Dim>(
    grains: Vec<ParticleRecord<D>>,
    domain: Domain<D>,
    settings: MdSettings<D>,
) -> Md<D> {
    let mut p = Particles::new();
    for g in grains {
        p.push_record(g);
    }
    Md::new(p, domain, Vec::new(), settings).expect("valid test set-up")
}
