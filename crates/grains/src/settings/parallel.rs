//! The `[parallel]` section of a scenario: how MD ranks cut the box.
//!
//! A distributed MD run splits the box over its ranks as it says; a serial
//! run ignores it (but still checks it). The scenario file reads it and
//! `crate::md::decomp` cuts by it.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// Default imbalance (max/mean − 1) above which the subdomain bounds move.
pub const DEFAULT_REBALANCE: f64 = 0.1;

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ParallelSpec {
    /// Imbalance of the owned grain counts (max/mean − 1) above which the
    /// bounds are moved by count at a neighbour rebuild; 0 never moves them.
    #[serde(default = "default_rebalance")]
    pub rebalance: f64,
    /// How the box is cut: "auto", "slabs" or the ranks per axis.
    #[serde(default)]
    pub grid: GridSpec,
}

/// `parallel.grid`: "auto" (the grid of least cut area), "slabs" (the
/// longest axis only, like the seeds) or `[px, py(, pz)]`.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, Default)]
#[serde(try_from = "RawGrid", into = "RawGrid")]
pub enum GridSpec {
    #[default]
    Auto,
    Slabs,
    Fixed(Vec<usize>),
}

#[derive(Clone, Serialize, Deserialize)]
#[serde(untagged)]
enum RawGrid {
    Word(String),
    Counts(Vec<usize>),
}

impl TryFrom<RawGrid> for GridSpec {
    type Error = String;
    fn try_from(raw: RawGrid) -> std::result::Result<Self, String> {
        match raw {
            RawGrid::Word(w) if w == "auto" => Ok(Self::Auto),
            RawGrid::Word(w) if w == "slabs" => Ok(Self::Slabs),
            RawGrid::Counts(c) if (2..=3).contains(&c.len()) && c.iter().all(|&p| p > 0) => {
                Ok(Self::Fixed(c))
            }
            RawGrid::Word(w) => Err(format!(
                "parallel.grid = \"{w}\": allowed are \"auto\", \"slabs\" or [px, py(, pz)]"
            )),
            RawGrid::Counts(c) => Err(format!(
                "parallel.grid = {c:?}: give one rank count ≥ 1 per axis, e.g. [2, 2]"
            )),
        }
    }
}

impl From<GridSpec> for RawGrid {
    fn from(g: GridSpec) -> Self {
        match g {
            GridSpec::Auto => Self::Word("auto".into()),
            GridSpec::Slabs => Self::Word("slabs".into()),
            GridSpec::Fixed(c) => Self::Counts(c),
        }
    }
}

fn default_rebalance() -> f64 {
    DEFAULT_REBALANCE
}

impl Default for ParallelSpec {
    fn default() -> Self {
        Self {
            rebalance: DEFAULT_REBALANCE,
            grid: GridSpec::Auto,
        }
    }
}

impl ParallelSpec {
    /// Refuses values out of range, naming the scenario and key; `dims`:
    /// the scenario's dimension.
    pub fn validate(&self, origin: &str, dims: usize) -> Result<()> {
        if let GridSpec::Fixed(g) = &self.grid {
            if g.len() != dims {
                return Err(Error::input(format!(
                    "{origin}: parallel.grid = {g:?}: give {dims} rank counts, one per axis \
                     (or \"auto\", \"slabs\")"
                )));
            }
        }
        let r = self.rebalance;
        if !(r.is_finite() && r >= 0.0) {
            return Err(Error::input(format!(
                "{origin}: parallel.rebalance = {r}: must be a number ≥ 0 (the imbalance \
                 max/mean − 1 that triggers moving the bounds, e.g. 0.1; 0 disables)"
            )));
        }
        Ok(())
    }
}
