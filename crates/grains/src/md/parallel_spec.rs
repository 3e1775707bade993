//! The `[parallel]` section of a scenario: how a distributed MD run splits
//! the box over its ranks. A serial run ignores it (but still checks it).

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
}

fn default_rebalance() -> f64 {
    DEFAULT_REBALANCE
}

impl Default for ParallelSpec {
    fn default() -> Self {
        Self {
            rebalance: DEFAULT_REBALANCE,
        }
    }
}

impl ParallelSpec {
    /// Refuses values out of range, naming the scenario and key.
    pub fn validate(&self, origin: &str) -> Result<()> {
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
