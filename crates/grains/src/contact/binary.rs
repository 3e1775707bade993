//! Closed forms for a head-on collision of two grains (or a grain and a wall).
//!
//! The relative coordinate ξ of a binary contact obeys ξ'' = −κ ξ^β − γ ξ',
//! where κ and γ follow from the [`MassScaling`]:
//! - `Seed`: each grain feels k_n m_i ξ^β, so κ = 2 k_n and γ = 2 γ_n for two
//!   grains, κ = k_n and γ = γ_n against a wall;
//! - `Reduced`: m_eff ξ'' = −k_n ξ^β − γ_n m_eff ξ', so κ = k_n/m_eff, γ = γ_n.
//!
//! Linear spring (β = 1): ω0² = κ, ω = √(ω0² − (γ/2)²), t_c = π/ω,
//! e = exp(−γ t_c/2). Undamped power law: the maximum overlap follows from
//! energy, δ = ((β+1) v²/(2κ))^(1/(β+1)), and
//! t_c = 2 (δ/v) √π Γ(1 + 1/(β+1)) / Γ(1/2 + 1/(β+1)), e = 1.

use super::law::ContactLaw;
use super::mass_scaling::MassScaling;

/// The reduced equation of motion of a binary contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BinaryContact {
    pub kappa: f64,
    pub gamma: f64,
    pub beta: f64,
}

impl BinaryContact {
    /// Two grains of masses `mi`, `mj` (`mj` infinite for a wall or frozen grain).
    pub fn new(law: &ContactLaw, mi: f64, mj: f64) -> Self {
        let wall = mj.is_infinite();
        let (kappa, gamma) = match law.scaling {
            MassScaling::Seed if wall => (law.kn, law.gamma_n),
            MassScaling::Seed => (2.0 * law.kn, 2.0 * law.gamma_n),
            MassScaling::Reduced => {
                let meff = law.damping_mass(mi, mj);
                (law.kn / meff, law.gamma_n)
            }
        };
        Self {
            kappa,
            gamma,
            beta: law.beta,
        }
    }

    /// Duration of a linear (β = 1) damped contact; `None` when overdamped.
    pub fn linear_contact_time(&self) -> Option<f64> {
        let w2 = self.kappa - 0.25 * self.gamma * self.gamma;
        (w2 > 0.0).then(|| std::f64::consts::PI / w2.sqrt())
    }

    /// Normal restitution coefficient of a linear damped contact.
    pub fn linear_restitution(&self) -> Option<f64> {
        self.linear_contact_time()
            .map(|t| (-0.5 * self.gamma * t).exp())
    }

    /// Maximum overlap of an undamped contact at impact speed `v`.
    pub fn max_overlap(&self, v: f64) -> f64 {
        ((self.beta + 1.0) * v * v / (2.0 * self.kappa)).powf(1.0 / (self.beta + 1.0))
    }

    /// Duration of an undamped power-law contact at impact speed `v`.
    pub fn power_law_contact_time(&self, v: f64) -> f64 {
        let a = 1.0 / (self.beta + 1.0);
        2.0 * self.max_overlap(v) / v * std::f64::consts::PI.sqrt() * gamma_fn(1.0 + a)
            / gamma_fn(0.5 + a)
    }

    /// Contact time used to choose dt: the damped linear formula for β = 1,
    /// the undamped power-law formula at the speed `v` otherwise (damping
    /// lengthens a contact, so this errs on the short side).
    pub fn contact_time(&self, v: f64) -> f64 {
        if self.beta == 1.0 {
            self.linear_contact_time()
                .unwrap_or(std::f64::consts::PI / self.kappa.sqrt())
        } else {
            self.power_law_contact_time(v)
        }
    }
}

/// The Gamma function for x > 0 (Lanczos approximation, g = 7, n = 9;
/// relative error below 1e-13 on the range used here).
pub fn gamma_fn(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        return std::f64::consts::PI / ((std::f64::consts::PI * x).sin() * gamma_fn(1.0 - x));
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + G + 0.5;
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    (2.0 * std::f64::consts::PI).sqrt() * t.powf(x + 0.5) * (-t).exp() * a
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gamma_known_values() {
        assert!((gamma_fn(0.5) - std::f64::consts::PI.sqrt()).abs() < 1e-13);
        assert!((gamma_fn(5.0) - 24.0).abs() < 1e-11);
        assert!((gamma_fn(1.5) - 0.5 * std::f64::consts::PI.sqrt()).abs() < 1e-13);
    }

    #[test]
    fn linear_limit_of_power_law_time() {
        // For β = 1 the power-law formula must give the undamped π/√κ.
        let b = BinaryContact {
            kappa: 4.0,
            gamma: 0.0,
            beta: 1.0,
        };
        let t = b.power_law_contact_time(0.37);
        assert!((t - std::f64::consts::PI / 2.0).abs() < 1e-12, "{t}");
    }
}
