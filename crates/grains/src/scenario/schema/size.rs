//! The `particles.size` table: the law the diameters of the grains made at
//! the start are drawn from (`scenario/sizes.rs` checks and draws it).

use serde::{Deserialize, Serialize};

/// `particles.size = { distribution = …, weight = …, min = …, max = …, … }`.
/// Which keys a law takes is checked by `scenario/sizes.rs`, naming the key.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SizeSpec {
    pub distribution: SizeDistribution,
    /// Whether the law gives the share of the grains' number or of their
    /// mass in each size; default "number" ("mass" for "sieve").
    #[serde(default)]
    pub weight: Option<SizeWeight>,
    /// Smallest and largest diameter (m): draws outside are drawn again.
    /// Required by uniform, normal and lognormal; for discrete and sieve
    /// they cut the table (default its ends).
    #[serde(default)]
    pub min: Option<f64>,
    #[serde(default)]
    pub max: Option<f64>,
    /// Mean and standard deviation of the diameter (m) of the untruncated
    /// law, in its weight (normal, lognormal).
    #[serde(default)]
    pub mean: Option<f64>,
    #[serde(default)]
    pub std: Option<f64>,
    /// `discrete`: rows of [diameter (m), fraction], fractions summing to 1.
    #[serde(default)]
    pub classes: Option<Vec<Vec<f64>>>,
    /// `sieve`: a CSV file of rows `diameter (m), cumulative % passing`.
    #[serde(default)]
    pub file: Option<String>,
}

#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum SizeDistribution {
    Uniform,
    Normal,
    Lognormal,
    Discrete,
    Sieve,
}

#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum SizeWeight {
    Number,
    Mass,
}
