//! Elastic normal repulsion F = k_n ξ^β for an overlap ξ > 0.
//!
//! β = 1 is Hooke's linear spring (the seeds' eq. 1a), β = 3/2 Hertz's law for
//! spheres, β = 2 a conical contact. Any β > 0 is accepted.

/// Magnitude of the elastic force (per unit mass under `seed` scaling).
#[inline(always)]
pub fn elastic_force(kn: f64, beta: f64, overlap: f64) -> f64 {
    if beta == 1.0 {
        kn * overlap
    } else if beta == 1.5 {
        kn * overlap * overlap.sqrt()
    } else if beta == 2.0 {
        kn * overlap * overlap
    } else {
        kn * overlap.powf(beta)
    }
}

/// Elastic energy stored at overlap ξ: k_n ξ^(β+1) / (β+1).
pub fn elastic_energy(kn: f64, beta: f64, overlap: f64) -> f64 {
    kn * overlap.powf(beta + 1.0) / (beta + 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn special_exponents_match_powf() {
        for beta in [1.0, 1.5, 2.0, 2.5, 0.7] {
            let f = elastic_force(3.0, beta, 0.2);
            assert!((f - 3.0 * 0.2f64.powf(beta)).abs() < 1e-15, "beta {beta}");
        }
    }

    #[test]
    fn force_is_derivative_of_energy() {
        let (kn, beta, x, h) = (7.0, 1.5, 0.3, 1e-6);
        let num = (elastic_energy(kn, beta, x + h) - elastic_energy(kn, beta, x - h)) / (2.0 * h);
        assert!((num - elastic_force(kn, beta, x)).abs() < 1e-8);
    }
}
