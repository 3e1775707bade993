//! The LAMMPS `gran/hooke/history` contact as a fixed kernel for the hot
//! pair loop: linear spring (β = 1), reduced-mass damping, Cundall–Strack
//! spring with a finite Coulomb cap, rotation on.
//!
//! It is [`ContactLaw::evaluate`] with those choices made at compile time:
//! the same operations in the same order, so the results are the same bits
//! (a test checks it), but without the power-law, scaling and cap branches
//! that the general law tests on every contact.

use super::law::{ContactLaw, ContactOutcome};
use super::mass_scaling::MassScaling;
use crate::dim::Dim;

/// Coefficients of a contact law that has the Hooke-with-history shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HookeHistory {
    pub(super) kn: f64,
    pub(super) gamma_n: f64,
    pub(super) gamma_t: f64,
    pub(super) kt: f64,
    pub(super) mu: f64,
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

    /// Reduced mass, a frozen grain (infinite mass) leaving its partner's.
    #[inline(always)]
    pub fn damping_mass(mi: f64, mj: f64) -> f64 {
        MassScaling::Reduced.damping_mass(mi, mj)
    }

    /// As [`ContactLaw::evaluate`] (same arguments, same bits).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub fn evaluate<D: Dim>(
        &self,
        overlap: f64,
        n: D::V,
        v_rel: D::V,
        damping_mass: f64,
        spring: &mut D::V,
        dt: f64,
        update: bool,
    ) -> ContactOutcome<D> {
        let vn = D::dot(v_rel, n);
        let fn_total = self.kn * overlap + -self.gamma_n * damping_mass * vn;
        let vt = v_rel - n * vn;
        let gamma = self.gamma_t * damping_mass;
        if update {
            *spring += vt * dt;
            let along_normal = D::dot(*spring, n);
            *spring -= n * along_normal;
        }
        let mut fs = -(*spring * self.kt + vt * gamma);
        let cap = self.mu * fn_total.abs();
        let fs2 = D::norm2(fs);
        if fs2 > cap * cap {
            // Sliding: cut the spring back to the capped force.
            let scale = cap / fs2.sqrt();
            if D::norm2(*spring) == 0.0 {
                fs = D::zero();
            } else {
                let damp = vt * (gamma / self.kt);
                *spring = (*spring + damp) * scale - damp;
                fs *= scale;
            }
        }
        ContactOutcome {
            force: n * fn_total + fs,
            tangential: fs,
        }
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
                assert_eq!(HookeHistory::damping_mass(mi, mj).to_bits(), dm.to_bits());
                let update = case % 11 != 0;
                let (mut a, mut b) = (s0, s0);
                let g = law.evaluate::<D3>(overlap, n, v, dm, &mut a, 1e-4, update);
                let h = k.evaluate::<D3>(overlap, n, v, dm, &mut b, 1e-4, update);
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
            let g = law.evaluate::<D2>(1e-4, n, v, 0.5, &mut a, 1e-4, true);
            let h = k.evaluate::<D2>(1e-4, n, v, 0.5, &mut b, 1e-4, true);
            assert_eq!(g.force, h.force);
            assert_eq!(a, b);
        }
        // Both regimes were exercised.
        assert!(sliding > 100 && sliding < 3900, "{sliding} sliding");
    }
}
