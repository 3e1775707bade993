//! How contact coefficients meet the masses of the two grains.

use serde::{Deserialize, Serialize};

/// Two conventions for the contact coefficients.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum MassScaling {
    /// The seeds' convention: every coefficient is "normalized by the mass"
    /// and multiplied by the mass m_i of the grain the force acts on. Grains
    /// of unequal mass then feel forces of unequal size (action ≠ reaction),
    /// but equal and opposite accelerations.
    #[default]
    Seed,
    /// Stiffness k_n, k_t in force units; damping γ_n, γ_t multiplied by the
    /// reduced mass m_i m_j/(m_i + m_j) (a frozen grain or a wall counts as
    /// infinitely heavy). Conserves momentum; equals LAMMPS `gran/*/history`.
    Reduced,
}

impl MassScaling {
    /// Mass multiplying the damping terms of a contact between masses
    /// `mi` and `mj` (`mj = ∞` for walls and frozen grains).
    #[inline(always)]
    pub fn damping_mass(self, mi: f64, mj: f64) -> f64 {
        match self {
            MassScaling::Seed => 1.0,
            MassScaling::Reduced => {
                if mj.is_infinite() {
                    mi
                } else if mi.is_infinite() {
                    mj
                } else {
                    mi * mj / (mi + mj)
                }
            }
        }
    }

    /// Factor turning the computed pair force into the force on a grain of
    /// mass `m`.
    #[inline(always)]
    pub fn force_factor(self, m: f64) -> f64 {
        match self {
            MassScaling::Seed => m,
            MassScaling::Reduced => 1.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reduced_mass_and_infinite_partner() {
        assert_eq!(MassScaling::Reduced.damping_mass(2.0, 2.0), 1.0);
        assert_eq!(MassScaling::Reduced.damping_mass(3.0, f64::INFINITY), 3.0);
        assert_eq!(MassScaling::Seed.damping_mass(3.0, 5.0), 1.0);
        assert_eq!(MassScaling::Seed.force_factor(3.0), 3.0);
    }
}
