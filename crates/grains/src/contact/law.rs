//! The full contact law: normal power law + viscous damping + Cundall–Strack.

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

/// What one contact evaluation produced, before the mass factor of
/// [`MassScaling::force_factor`] is applied.
#[derive(Clone, Copy, Debug)]
pub struct ContactOutcome<D: Dim> {
    /// Force on grain i (the partner gets minus this, times its own factor).
    pub force: D::V,
    /// The tangential part of `force`, for torques.
    pub tangential: D::V,
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

    /// Evaluates one contact.
    ///
    /// `overlap` > 0; `n` the unit normal pointing from the partner to grain i;
    /// `v_rel` the velocity of i's contact point minus the partner's;
    /// `damping_mass` from [`MassScaling::damping_mass`]; `spring` the
    /// contact's tangential history, updated when `update`.
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
        let fn_total =
            elastic_force(self.kn, self.beta, overlap) + viscous(self.gamma_n, damping_mass, vn);
        let vt = v_rel - n * vn;
        let tangential = Tangential {
            kt: self.kt,
            gamma: self.gamma_t * damping_mass,
            mu: self.mu,
        }
        .force::<D>(spring, vt, n, fn_total.abs(), dt, update);
        ContactOutcome {
            force: n * fn_total + tangential,
            tangential,
        }
    }

    /// Damping mass for a pair of grains, infinite mass for frozen ones.
    #[inline(always)]
    pub fn damping_mass(&self, mi: f64, mj: f64) -> f64 {
        self.scaling.damping_mass(mi, mj)
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
        let out = law().evaluate::<D2>(
            0.01,
            DVec2::Y,
            DVec2::new(2.0, -1.0),
            0.5,
            &mut s,
            1e-4,
            true,
        );
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
