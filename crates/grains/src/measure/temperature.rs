//! Granular temperature of MD grains.

use crate::dim::Dim;
use crate::particles::Particles;

/// Mean kinetic energy of the velocity fluctuations per grain and per degree
/// of freedom, (1/(d N)) Σ m_i |v_i − V|², with V the mass-weighted mean
/// velocity (J). Frozen grains are left out.
pub fn granular_temperature<D: Dim>(p: &Particles<D>) -> f64 {
    let mobile: Vec<usize> = (0..p.n_owned()).filter(|&i| !p.frozen[i]).collect();
    if mobile.is_empty() {
        return 0.0;
    }
    let mass: f64 = mobile.iter().map(|&i| p.mass[i]).sum();
    let mean = mobile
        .iter()
        .fold(D::zero(), |acc, &i| acc + p.vel[i] * p.mass[i])
        / mass;
    let sum: f64 = mobile
        .iter()
        .map(|&i| p.mass[i] * D::norm2(p.vel[i] - mean))
        .sum();
    sum / (D::D as f64 * mobile.len() as f64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::D2;
    use crate::particles::ParticleRecord;
    use glam::DVec2;

    #[test]
    fn drift_is_not_temperature() {
        let mut p = Particles::<D2>::new();
        for (k, vx) in [1.0, 3.0].into_iter().enumerate() {
            let mut r = ParticleRecord::<D2>::new(k as u64, DVec2::ZERO, 0.5, 2.0, 0.1);
            r.vel = DVec2::new(vx, 0.0);
            p.push_record(r);
        }
        // Mean velocity 2; fluctuations ±1: Σ m v'² = 4, / (2 · 2) = 1.
        assert!((granular_temperature(&p) - 1.0).abs() < 1e-15);
    }
}
