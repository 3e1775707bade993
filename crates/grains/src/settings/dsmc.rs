//! The method switch and the `[dsmc]` table of a scenario file.
//!
//! With its dense-gas choice: what the scenario file reads and the DSMC
//! engine runs by.

use serde::{Deserialize, Serialize};

/// Which engine runs a scenario.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// Soft-sphere molecular dynamics.
    #[default]
    Md,
    /// Direct Simulation Monte Carlo (hard spheres, stochastic collisions).
    Dsmc,
}

/// Which correction multiplies the ideal-gas collision frequency.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DenseGas {
    /// Ideal gas: χ = 1.
    None,
    /// Free volume Ṽ_c = V_c − V_b/ν_rcp (the seed's choice).
    #[default]
    FreeVolume,
    /// Enskog factor χ(ν) (Henderson 2D, Carnahan–Starling 3D).
    Enskog,
}

/// DSMC settings. Everything else (domain, particles, walls, gravity,
/// run.dt/duration, output) is shared with MD.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DsmcSpec {
    /// Normal restitution coefficient e of grain–grain collisions.
    #[serde(default = "one")]
    pub restitution: f64,
    /// Normal restitution of grain–wall collisions; default `restitution`.
    #[serde(default)]
    pub wall_restitution: Option<f64>,
    /// Cell edge (m); default: the edge that holds `particles_per_cell`
    /// particles on average.
    #[serde(default)]
    pub cell_size: Option<f64>,
    /// Mean particles per cell when `cell_size` is not given.
    #[serde(default = "ten")]
    pub particles_per_cell: f64,
    /// Dense-gas correction: "free_volume" (the seed's), "enskog" or "none".
    #[serde(default)]
    pub dense: DenseGas,
    /// Random-close-packing fraction; default 0.82 (2D), 0.64 (3D).
    #[serde(default)]
    pub rcp: Option<f64>,
    /// Initial Maxwellian with √(T/m) = this (m/s); 0 keeps the
    /// particles.random_velocity start.
    #[serde(default)]
    pub thermal_speed: f64,
    /// Horizontal slabs in which the validity of DSMC is checked.
    #[serde(default = "default_regions")]
    pub regions: usize,
    /// Bins of the density and temperature profiles versus height
    /// (profiles.csv); 0 writes none.
    #[serde(default)]
    pub profile_bins: usize,
}

fn one() -> f64 {
    1.0
}
fn ten() -> f64 {
    10.0
}
fn default_regions() -> usize {
    4
}

impl Default for DsmcSpec {
    fn default() -> Self {
        Self {
            restitution: 1.0,
            wall_restitution: None,
            cell_size: None,
            particles_per_cell: 10.0,
            dense: DenseGas::default(),
            rcp: None,
            thermal_speed: 0.0,
            regions: default_regions(),
            profile_bins: 0,
        }
    }
}
