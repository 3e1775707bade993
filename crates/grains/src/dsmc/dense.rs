//! Dense-gas corrections to the collision frequency.
//!
//! Point particles with a cross section collide as an ideal gas; real beads
//! exclude volume, which raises the collision rate. Two corrections:
//!
//! - `free_volume` (seed 000 §4): the cell volume in M_c is replaced by the
//!   free volume Ṽ_c = V_c − V_b/ν_rcp, V_b the volume of the beads in the
//!   cell and ν_rcp the random-close-packing fraction (0.82 disks, 0.64
//!   spheres). The rate is multiplied by V_c/Ṽ_c ≈ 1 + ν/ν_rcp.
//! - `enskog`: the rate is multiplied by the pair correlation at contact χ
//!   of the local packing fraction: Henderson in 2D,
//!   χ = (1 − 7ν/16)/(1 − ν)², Carnahan–Starling in 3D,
//!   χ = (1 − ν/2)/(1 − ν)³. The local ν counts the other N_c − 2 beads of
//!   the cell (those around the chosen pair): with Poisson-distributed N_c
//!   this makes the cell-averaged rate carry χ of the mean ν to first order,
//!   where N_c would overstate ν by a factor (⟨N⟩ + 2)/⟨N⟩.

pub use crate::settings::dsmc::DenseGas;

/// The Enskog pair correlation at contact: Henderson (2D) or
/// Carnahan–Starling (3D).
pub fn enskog_chi(dim: usize, nu: f64) -> f64 {
    if dim == 2 {
        (1.0 - 7.0 * nu / 16.0) / ((1.0 - nu) * (1.0 - nu))
    } else {
        (1.0 - 0.5 * nu) / ((1.0 - nu) * (1.0 - nu) * (1.0 - nu))
    }
}

/// Default random-close-packing fraction: disks 0.82, spheres 0.64.
pub fn default_rcp(dim: usize) -> f64 {
    if dim == 2 {
        0.82
    } else {
        0.64
    }
}

/// The free volume is never taken below this fraction of the cell: a cell
/// that would be fuller than random close packing is outside DSMC's range
/// anyway (the validity diagnostics report it).
pub const MIN_FREE_FRACTION: f64 = 0.05;

/// The correction of one run, evaluated per cell from its particle count.
#[derive(Clone, Copy, Debug)]
pub struct Correction {
    pub kind: DenseGas,
    pub dim: usize,
    /// Bead volume over cell volume (packing fraction per bead).
    pub bead_fraction: f64,
    pub rcp: f64,
}

impl Correction {
    /// Multiplier of the ideal-gas rate in a cell with `n` particles.
    #[inline]
    pub fn factor(&self, n: usize) -> f64 {
        match self.kind {
            DenseGas::None => 1.0,
            DenseGas::FreeVolume => {
                let free = 1.0 - n as f64 * self.bead_fraction / self.rcp;
                1.0 / free.max(MIN_FREE_FRACTION)
            }
            DenseGas::Enskog => {
                let nu = (n.saturating_sub(2) as f64 * self.bead_fraction).min(self.rcp);
                enskog_chi(self.dim, nu)
            }
        }
    }

    /// The factor a homogeneous gas of packing fraction `nu` has on average
    /// (χ for Enskog, 1/(1 − ν/ν_rcp) for the free volume): the χ of the
    /// kinetic-theory formulas in docs/dsmc.md.
    pub fn mean_factor(&self, nu: f64) -> f64 {
        match self.kind {
            DenseGas::None => 1.0,
            DenseGas::FreeVolume => 1.0 / (1.0 - nu / self.rcp).max(MIN_FREE_FRACTION),
            DenseGas::Enskog => enskog_chi(self.dim, nu),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chi_limits() {
        assert_eq!(enskog_chi(2, 0.0), 1.0);
        assert_eq!(enskog_chi(3, 0.0), 1.0);
        // Carnahan–Starling at ν = 0.3: 0.85 / 0.343.
        assert!((enskog_chi(3, 0.3) - 0.85 / 0.343).abs() < 1e-12);
        let c = Correction {
            kind: DenseGas::FreeVolume,
            dim: 3,
            bead_fraction: 0.01,
            rcp: 0.64,
        };
        assert!((c.factor(32) - 1.0 / 0.5).abs() < 1e-12);
        assert_eq!(c.factor(1000), 1.0 / MIN_FREE_FRACTION);
    }
}
