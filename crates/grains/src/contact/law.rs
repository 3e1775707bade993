//! The spring–dashpot contact law: normal power law + viscous damping +
//! Cundall–Strack, written once ([`spring_dashpot`]) for the general law
//! of coefficients ([`ContactLaw`]) and for the laws that fix some of its
//! choices at compile time ([`super::hooke_history`]).

use super::contract::{Contact, ContactModel, ContactOutcome, Step};
use super::cundall_strack::Tangential;
use super::damping::viscous;
use super::mass_scaling::MassScaling;
use super::normal_power_law::elastic_force;
use crate::dim::Dim;
use crate::error::{Error, Result};

/// Parameters of the grain–grain (and grain–wall) contact.
///
/// Units depend on [`MassScaling`]: under `Seed` k_n is in s⁻²·m^(1−β)
/// (force per unit mass), under `Reduced` in N·m^(−β); γ_n and γ_t are in
/// s⁻¹ under both; k_t like k_n with β = 1.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactLaw {
    pub kn: f64,
    pub beta: f64,
    pub gamma_n: f64,
    pub gamma_t: f64,
    /// Tangential spring stiffness; 0 switches the Cundall–Strack spring off.
    pub kt: f64,
    /// Coulomb coefficient; infinity means no cap.
    pub mu: f64,
    pub scaling: MassScaling,
    /// Whether grains rotate (torques, ω in the contact-point velocity).
    pub rotation: bool,
}

impl ContactLaw {
    /// Checks the ranges; `what` names the place in the input for messages.
    pub fn validate(&self, what: &str) -> Result<()> {
        let bad = |key: &str, allowed: &str, v: f64| {
            Err(Error::input(format!(
                "{what}.{key} = {v}: must be {allowed}"
            )))
        };
        if !(self.kn.is_finite() && self.kn > 0.0) {
            return bad("kn", "a positive finite number", self.kn);
        }
        if !(self.beta.is_finite() && self.beta > 0.0) {
            return bad(
                "beta",
                "positive (1 Hooke, 1.5 Hertz, 2 conical)",
                self.beta,
            );
        }
        if !(self.gamma_n.is_finite() && self.gamma_n >= 0.0) {
            return bad("gamma_n", ">= 0", self.gamma_n);
        }
        if !(self.gamma_t.is_finite() && self.gamma_t >= 0.0) {
            return bad("gamma_t", ">= 0", self.gamma_t);
        }
        if !(self.kt.is_finite() && self.kt >= 0.0) {
            return bad("kt", ">= 0", self.kt);
        }
        if self.mu.is_nan() || self.mu < 0.0 {
            return bad(
                "mu",
                ">= 0 (omit it, or write the TOML number inf, for no Coulomb cap)",
                self.mu,
            );
        }
        Ok(())
    }

    /// Damping mass for a pair of grains, infinite mass for frozen ones.
    #[inline(always)]
    pub fn damping_mass(&self, mi: f64, mj: f64) -> f64 {
        self.scaling.damping_mass(mi, mj)
    }
}

/// The parts of a spring–dashpot law, as [`spring_dashpot`] reads them.
pub(super) trait SpringDashpot {
    /// Whether the law always has a tangential spring and a finite
    /// Coulomb cap (known at compile time).
    const KNOWN_SHAPE: bool;
    fn elastic(&self, overlap: f64) -> f64;
    fn damping_mass(&self, mi: f64, mj: f64) -> f64;
    fn gamma_n(&self) -> f64;
    fn gamma_t(&self) -> f64;
    fn kt(&self) -> f64;
    fn mu(&self) -> f64;
}

/// The spring–dashpot law on one contact: F_n = elastic(ξ) − γ_n m v_n
/// along n, plus the Cundall–Strack tangential force capped at μ|F_n|.
#[inline(always)]
pub(super) fn spring_dashpot<D: Dim, L: SpringDashpot>(
    law: &L,
    c: &Contact<D>,
    spring: &mut D::V,
    step: Step,
) -> ContactOutcome<D> {
    let n = c.normal;
    let damping_mass = law.damping_mass(c.mi, c.mj);
    let vn = D::dot(c.v_rel, n);
    let fn_total = law.elastic(c.overlap) + viscous(law.gamma_n(), damping_mass, vn);
    let vt = c.v_rel - n * vn;
    let tangential = Tangential {
        kt: law.kt(),
        gamma: law.gamma_t() * damping_mass,
        mu: law.mu(),
    }
    .force::<D>(spring, vt, n, fn_total.abs(), step, L::KNOWN_SHAPE);
    ContactOutcome {
        force: n * fn_total + tangential,
        tangential,
        normal_force: fn_total,
    }
}

impl SpringDashpot for ContactLaw {
    const KNOWN_SHAPE: bool = false;
    #[inline(always)]
    fn elastic(&self, overlap: f64) -> f64 {
        elastic_force(self.kn, self.beta, overlap)
    }
    #[inline(always)]
    fn damping_mass(&self, mi: f64, mj: f64) -> f64 {
        self.scaling.damping_mass(mi, mj)
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

impl ContactModel for ContactLaw {
    #[inline(always)]
    fn rotation(&self) -> bool {
        self.rotation
    }
    #[inline(always)]
    fn force_factor(&self, m: f64) -> f64 {
        self.scaling.force_factor(m)
    }
    fn elastic_wall(&self) -> Option<Self> {
        Some(ContactLaw {
            gamma_n: 0.0,
            ..self.clone()
        })
    }
    #[inline(always)]
    fn evaluate<D: Dim>(&self, c: &Contact<D>, spring: &mut D::V, step: Step) -> ContactOutcome<D> {
        spring_dashpot(self, c, spring, step)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::D2;
    use glam::DVec2;

    fn law() -> ContactLaw {
        ContactLaw {
            kn: 1000.0,
            beta: 1.0,
            gamma_n: 10.0,
            gamma_t: 5.0,
            kt: 0.0,
            mu: f64::INFINITY,
            scaling: MassScaling::Reduced,
            rotation: false,
        }
    }

    #[test]
    fn normal_and_shear_parts() {
        let mut s = DVec2::ZERO;
        // Approaching along the normal at 1 m/s and sliding at 2 m/s.
        // Two unit masses: the reduced mass is 1/2.
        let c = Contact::<D2> {
            overlap: 0.01,
            normal: DVec2::Y,
            v_rel: DVec2::new(2.0, -1.0),
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
        let out = law().evaluate(&c, &mut s, step);
        // Normal: 1000·0.01 + 10·0.5·1 = 15; shear: −5·0.5·2 = −5.
        assert!((out.force - DVec2::new(-5.0, 15.0)).length() < 1e-12);
        assert_eq!(out.tangential, DVec2::new(-5.0, 0.0));
    }

    #[test]
    fn rejects_bad_values() {
        let mut l = law();
        l.beta = 0.0;
        let e = l.validate("contact").unwrap_err().to_string();
        assert!(e.contains("contact.beta"), "{e}");
        let mut l = law();
        l.mu = -0.1;
        assert!(l.validate("contact").is_err());
    }
}
