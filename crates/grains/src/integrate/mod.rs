//! Time integrators: the fifth-order Gear predictor–corrector the seeds used,
//! and velocity Verlet (LAMMPS's `nve/sphere`), the cheap second-order choice.
//!
//! Both split a step into a part before the forces are computed (`predict`,
//! or Verlet's first half-kick and drift) and a part after (`correct`, or the
//! second half-kick); the engine calls them around its force phase. Frozen
//! grains are never moved.

pub mod gear5;
pub mod velocity_verlet;

/// Grains per parallel chunk of the integrators.
const CHUNK: usize = 4096;

use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Integrator {
    /// Fifth-order Gear predictor–corrector (Allen & Tildesley), position
    /// corrector constant 3/20 because the forces depend on velocities.
    #[default]
    Gear5,
    /// Velocity Verlet: dissipative forces see the half-step velocities.
    Verlet,
}

impl Integrator {
    pub fn name(self) -> &'static str {
        match self {
            Integrator::Gear5 => "gear5",
            Integrator::Verlet => "verlet",
        }
    }
}
