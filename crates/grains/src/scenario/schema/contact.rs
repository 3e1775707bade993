//! The contact keys of a scenario file.
//!
//! `[contact]` (the law, its preset and coefficients), `[[materials]]` and
//! `[[material_pairs]]`.

use crate::contact::MassScaling;
use serde::{Deserialize, Serialize};

/// Contact law. A preset fills every field; fields given next to it override.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, Default)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// "spring-dashpot" (default: the coefficients below) or
    /// "hertz-mindlin" (from `[[materials]]`).
    #[serde(default)]
    pub model: Option<ContactModelKind>,
    #[serde(default)]
    pub preset: Option<ContactPreset>,
    /// Normal stiffness (seed scaling: s⁻² m^(1−β); reduced: N m^(−β)).
    pub kn: Option<f64>,
    /// Exponent of the elastic force k_n ξ^β.
    pub beta: Option<f64>,
    /// Normal damping γ_n (s⁻¹).
    pub gamma_n: Option<f64>,
    /// Normal restitution coefficient e ∈ (0, 1] of two of the lightest
    /// grains, instead of gamma_n (β = 1 only).
    pub restitution: Option<f64>,
    /// Viscous shear friction γ_t (s⁻¹), the seeds' γ_s.
    pub gamma_t: Option<f64>,
    /// Tangential spring stiffness (units of k_n with β = 1); 0 = no spring.
    pub kt: Option<f64>,
    /// Coulomb coefficient; a negative value is an error, omit for no cap.
    pub mu: Option<f64>,
    pub scaling: Option<MassScaling>,
    pub rotation: Option<bool>,
    /// Rolling resistance ("none", "constant", "epsd"; hertz-mindlin only,
    /// needs rotation; `contact::rolling`).
    pub rolling: Option<crate::contact::rolling::RollingModel>,
    /// k_r of LAMMPS's `rolling sds` (force per length), with
    /// `preset = "lammps-granular"` and `rolling = "epsd"` only.
    pub rolling_stiffness: Option<f64>,
    /// γ_r of LAMMPS's `rolling sds` (force per velocity), likewise.
    pub rolling_damping: Option<f64>,
    /// Cohesion ("none", "dmt", "jkr"; hertz-mindlin only, from the
    /// materials' surface_energy; `contact::cohesion`, `contact::jkr`).
    pub cohesion: Option<crate::contact::cohesion::CohesionModel>,
    /// Names of walls whose contacts have no normal damping (γ_n = 0, the
    /// grains' γ_t kept): elastic side walls beside a dissipative bulk.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub elastic_walls: Vec<String>,
}

/// Which contact law a scenario uses.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "kebab-case")]
pub enum ContactModelKind {
    /// k_n ξ^β with viscous damping and the Cundall–Strack spring, from
    /// coefficients (`kn`, `gamma_n`, …).
    #[default]
    SpringDashpot,
    /// Hertz–Mindlin from the materials' moduli, restitution and friction.
    HertzMindlin,
}

/// One material (SI units).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    pub name: String,
    /// kg/m³.
    pub density: f64,
    /// Pa.
    pub youngs_modulus: f64,
    /// In (−1, 0.5).
    pub poisson_ratio: f64,
    /// Normal restitution of two grains of this material, in (0, 1].
    pub restitution: f64,
    /// Sliding friction μ.
    pub friction: f64,
    /// Rolling friction μ_r (dimensionless); default 0.
    #[serde(default)]
    pub rolling_friction: f64,
    /// J/m², for cohesion; default 0.
    #[serde(default)]
    pub surface_energy: f64,
}

/// Values for one pair of materials instead of the mixing rules.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MaterialPairSpec {
    pub a: String,
    pub b: String,
    #[serde(default)]
    pub restitution: Option<f64>,
    #[serde(default)]
    pub friction: Option<f64>,
    #[serde(default)]
    pub rolling_friction: Option<f64>,
    #[serde(default)]
    pub surface_energy: Option<f64>,
}

#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
pub enum ContactPreset {
    /// Seed 002: Hooke, γ_n = 200 s⁻¹, γ_t = 400 s⁻¹, k_n = 5e7 s⁻², seed
    /// scaling, no spring, no rotation.
    #[serde(rename = "seed")]
    Seed,
    /// LAMMPS `gran/hooke/history Kn NULL γn NULL μ 0` of the shared benchmarks
    /// (k_n = 2e5, k_t = 2/7 k_n, γ_n = 50, γ_t = 0, μ = 0.5), reduced scaling,
    /// rotation on. Units are whatever the data file uses (LAMMPS `lj`).
    #[serde(rename = "lammps-hooke-history")]
    LammpsHookeHistory,
    /// LAMMPS `pair_style granular` with `pair_coeff * * hertz/material E e ν
    /// tangential mindlin NULL 1.0 μ damping tsuji [rolling sds k_r γ_r
    /// μ_r]`, from `[[materials]]` (E, ν, e, μ, μ_r) and, with
    /// `rolling = "epsd"`, `rolling_stiffness` and `rolling_damping`.
    #[serde(rename = "lammps-granular")]
    LammpsGranular,
}
