//! Viscous dissipation: normal damping −γ_n m (v·n̂) n̂ (the seeds' eq. 1b) and
//! viscous shear friction −γ_t m (v·t̂) t̂ (eq. 1c), with m the mass factor
//! that [`super::MassScaling`] picks.

/// Damping force along one direction for a relative speed `v` along it.
#[inline(always)]
pub fn viscous(gamma: f64, mass_factor: f64, v: f64) -> f64 {
    -gamma * mass_factor * v
}

#[cfg(test)]
mod tests {
    #[test]
    fn opposes_motion() {
        assert_eq!(super::viscous(2.0, 0.5, 3.0), -3.0);
    }
}
