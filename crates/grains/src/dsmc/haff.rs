//! Haff's law for the homogeneous cooling state: T(t) = T0 / (1 + t/τ0)².
//!
//! Energy balance: each collision loses (1 − e²) m (g·n)²/4, so
//! dT/dt = −ζ T with ζ = (1 − e²) ω (1 + 3a₂/16) / d (ω the collision
//! frequency per particle). With ω ∝ √T this integrates to Haff's law with
//! τ0 = 2d / ((1 − e²) ω0 (1 + 3a₂/16)).
//!
//! a₂ is the second Sonine coefficient of the cooling state's velocity
//! distribution (its departure from a Maxwellian; van Noije & Ernst,
//! Granular Matter 1, 57 (1998), eq. 3.13):
//! a₂ = 16 (1 − e)(1 − 2e²) / (9 + 24d − e(41 − 8d) + 30 (1 − e) e²).
//! At e = 0.9 it is −0.027 in 2D and −0.015 in 3D: the Maxwellian τ0 is
//! short by 0.5% (2D) and 0.3% (3D), which after ten τ0 puts T 1% and 0.5%
//! above the Maxwellian law. DSMC solves the Boltzmann equation and shows
//! this shift, so the comparisons use the corrected τ0.

/// The second Sonine coefficient a₂ of the homogeneous cooling state.
pub fn sonine_a2(dim: usize, restitution: f64) -> f64 {
    let (d, e) = (dim as f64, restitution);
    16.0 * (1.0 - e) * (1.0 - 2.0 * e * e)
        / (9.0 + 24.0 * d - e * (41.0 - 8.0 * d) + 30.0 * (1.0 - e) * e * e)
}

/// Haff's time τ0 = 2d / ((1 − e²) ω0 (1 + 3a₂/16)), ω0 the collision
/// frequency per particle at T0: T(t) = T0 / (1 + t/τ0)².
pub fn haff_time(dim: usize, restitution: f64, omega0: f64) -> f64 {
    let sonine = 1.0 + 3.0 * sonine_a2(dim, restitution) / 16.0;
    2.0 * dim as f64 / ((1.0 - restitution * restitution) * omega0 * sonine)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Elastic gas: a Maxwellian, no correction; the sign change at
    /// e = 1/√2 (the (1 − 2e²) factor); the e = 0.9 values quoted above.
    #[test]
    fn sonine_coefficient_limits() {
        assert_eq!(sonine_a2(2, 1.0), 0.0);
        assert_eq!(sonine_a2(3, 1.0), 0.0);
        assert!(
            (sonine_a2(3, 0.9) + 0.01456).abs() < 1e-4,
            "{}",
            sonine_a2(3, 0.9)
        );
        assert!(
            (sonine_a2(2, 0.9) + 0.02686).abs() < 1e-4,
            "{}",
            sonine_a2(2, 0.9)
        );
        assert!(sonine_a2(3, std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-15);
        assert!(sonine_a2(3, 0.5) > 0.0 && sonine_a2(2, 0.5) > 0.0);
        // The Maxwellian τ0 = 2d/((1 − e²) ω0) lengthened by 0.5% in 2D.
        let maxwellian = 4.0 / (1.0 - 0.81);
        assert!((haff_time(2, 0.9, 1.0) / maxwellian - 1.00506).abs() < 1e-4);
    }
}
