//! The LAMMPS `gran/hooke/history` contact with its choices fixed at
//! compile time: linear spring (β = 1), reduced-mass damping,
//! Cundall–Strack spring with a finite Coulomb cap, rotation on.
//!
//! It is the spring–dashpot law of [`super::law`], the same code, with the
//! power-law, scaling and cap tests folded away; the results are the same
//! bits as the general [`ContactLaw`] (a test checks it). Written without
//! branches, it runs on the batched lanes of the pair loop.

use super::contract::{Contact, ContactModel, ContactOutcome, Step};
use super::law::{spring_dashpot, ContactLaw, SpringDashpot};
use super::mass_scaling::MassScaling;
use super::registered::{Registered, RunLaw};
use crate::dim::Dim;

/// Coefficients of a contact law that has the Hooke-with-history shape.
/// Laid out as the GPU kernels' `Hooke` (`gpu/kernels/common.cuh`), which
/// the GPU engine hands them as they are.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct HookeHistory {
    pub kn: f64,
    pub gamma_n: f64,
    pub gamma_t: f64,
    pub kt: f64,
    pub mu: f64,
}

impl HookeHistory {
    /// The kernel for `law`, when the law has this shape (the
    /// `lammps-hooke-history` preset and its variants); `None` otherwise.
    pub fn of(law: &ContactLaw) -> Option<Self> {
        let shape = law.beta == 1.0
            && law.scaling == MassScaling::Reduced
            && law.rotation
            && law.kt > 0.0
            && law.mu.is_finite();
        shape.then_some(Self {
            kn: law.kn,
            gamma_n: law.gamma_n,
            gamma_t: law.gamma_t,
            kt: law.kt,
            mu: law.mu,
        })
    }
}

impl SpringDashpot for HookeHistory {
    const KNOWN_SHAPE: bool = true;
    #[inline(always)]
    fn elastic(&self, overlap: f64) -> f64 {
        self.kn * overlap
    }
    #[inline(always)]
    fn damping_mass(&self, mi: f64, mj: f64) -> f64 {
        MassScaling::Reduced.damping_mass(mi, mj)
    }
    #[inline(always)]
    fn gamma_n(&self) -> f64 {
        self.gamma_n
    }
    #[inline(always)]
    fn gamma_t(&self) -> f64 {
        self.gamma_t
    }
    #[inline(always)]
    fn kt(&self) -> f64 {
        self.kt
    }
    #[inline(always)]
    fn mu(&self) -> f64 {
        self.mu
    }
}

impl ContactModel for HookeHistory {
    const LANES: bool = true;
    #[inline(always)]
    fn rotation(&self) -> bool {
        true
    }
    #[inline(always)]
    fn force_factor(&self, _: f64) -> f64 {
        // Reduced scaling: forces are not multiplied by a mass.
        1.0
    }
    #[inline(always)]
    fn elastic_wall(&self) -> Option<Self> {
        Some(Self {
            gamma_n: 0.0,
            ..*self
        })
    }
    #[inline(always)]
    fn evaluate<D: Dim>(&self, c: &Contact<D>, spring: &mut D::V, step: Step) -> ContactOutcome<D> {
        spring_dashpot(self, c, spring, step)
    }
}

/// The spring–dashpot law as a run holds it: its Hooke-with-history kernel
/// when the coefficients have that shape (the same bits, fewer tests per
/// contact), else the general one.
impl Registered for ContactLaw {
    #[inline(always)]
    fn with_kernel<R>(&self, run: impl RunLaw<R>) -> R {
        match HookeHistory::of(self) {
            Some(hooke) => run.run(&hooke),
            None => run.run(self),
        }
    }
    fn rotation(&self) -> bool {
        self.rotation
    }
    fn estimate(&self) -> &ContactLaw {
        self
    }
}

/// A law of the Hooke-with-history shape (LAMMPS chute's coefficients),
/// for tests.
#[cfg(test)]
pub(crate) fn lammps_law(gamma_t: f64) -> ContactLaw {
    ContactLaw {
        kn: 2e5,
        beta: 1.0,
        gamma_n: 50.0,
        gamma_t,
        kt: 2e5 * 2.0 / 7.0,
        mu: 0.5,
        scaling: MassScaling::Reduced,
        rotation: true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::{D2, D3};
    use glam::{DVec2, DVec3};
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    #[test]
    fn only_the_hooke_history_shape_gets_the_kernel() {
        assert!(HookeHistory::of(&lammps_law(0.0)).is_some());
        let mut hertz = lammps_law(0.0);
        hertz.beta = 1.5;
        let mut seed = lammps_law(0.0);
        seed.scaling = MassScaling::Seed;
        let mut no_spring = lammps_law(0.0);
        no_spring.kt = 0.0;
        let mut no_cap = lammps_law(0.0);
        no_cap.mu = f64::INFINITY;
        let mut still = lammps_law(0.0);
        still.rotation = false;
        for law in [hertz, seed, no_spring, no_cap, still] {
            assert!(HookeHistory::of(&law).is_none(), "{law:?}");
        }
    }

    /// Sticking, sliding, fresh and frozen-partner contacts: the kernel and
    /// the general law must give identical bits for force and spring.
    #[test]
    fn same_bits_as_the_general_law() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
        let mut sliding = 0;
        for gamma_t in [0.0, 25.0] {
            let law = lammps_law(gamma_t);
            let k = HookeHistory::of(&law).unwrap();
            for case in 0..2000 {
                let mut u = || rng.gen_range(-1.0..1.0);
                let n = DVec3::new(u(), u(), u()).normalize();
                let v = DVec3::new(u(), u(), u()) * 3.0;
                let s0 = if case % 5 == 0 {
                    DVec3::ZERO
                } else {
                    DVec3::new(u(), u(), u()) * 1e-3
                };
                let overlap = 1e-3 * (u() + 1.0);
                let (mi, mj) = (1.0 + u().abs(), 1.0 + u().abs());
                let mj = if case % 7 == 0 { f64::INFINITY } else { mj };
                let dm = law.damping_mass(mi, mj);
                let step = Step {
                    dt: 1e-4,
                    update: case % 11 != 0,
                };
                let c = Contact::<D3> {
                    overlap,
                    normal: n,
                    v_rel: v,
                    mi,
                    mj,
                    ri: 0.5,
                    rj: 0.5,
                    omega_rel: Default::default(),
                    pair: 0,
                };
                let (mut a, mut b) = (s0, s0);
                let g = law.evaluate(&c, &mut a, step);
                let h = k.evaluate(&c, &mut b, step);
                let bits = |x: DVec3| x.to_array().map(f64::to_bits);
                assert_eq!(bits(g.force), bits(h.force), "case {case}");
                assert_eq!(bits(g.tangential), bits(h.tangential), "case {case}");
                assert_eq!(bits(a), bits(b), "case {case}");
                let fn_abs = (2e5 * overlap - 50.0 * dm * v.dot(n)).abs();
                if (h.tangential.length() - 0.5 * fn_abs).abs() < 1e-9 * fn_abs {
                    sliding += 1;
                }
            }
            // 2D as well: disks use the same kernel.
            let mut a = DVec2::new(1e-3, 0.0);
            let mut b = a;
            let n = DVec2::new(0.6, 0.8);
            let v = DVec2::new(2.0, -1.0);
            let c = Contact::<D2> {
                overlap: 1e-4,
                normal: n,
                v_rel: v,
                mi: 1.0,
                mj: 1.0,
                ri: 0.5,
                rj: 0.5,
                omega_rel: Default::default(),
                pair: 0,
            };
            let step = Step {
                dt: 1e-4,
                update: true,
            };
            let g = law.evaluate(&c, &mut a, step);
            let h = k.evaluate(&c, &mut b, step);
            assert_eq!(g.force, h.force);
            assert_eq!(a, b);
        }
        // Both regimes were exercised.
        assert!(sliding > 100 && sliding < 3900, "{sliding} sliding");
    }
}
