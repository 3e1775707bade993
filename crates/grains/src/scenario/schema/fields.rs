//! The `[measure.fields]` table: coarse-grained continuum fields
//! (docs/fields.md).

use serde::{Deserialize, Serialize};

/// `measure.fields`: a grid over the box along `axes` ("x", "y", "z"; none
/// for a single box, the average over the whole box) with `cells` points
/// along each, a `kernel` ("gaussian" or "lucy") of width `width` (units of
/// d0, the mean grain diameter), sampled every `every` steps from time
/// `start` (s), `average` samples per written window (0: one window to
/// the end of the run).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct FieldsSpec {
    #[serde(default)]
    pub axes: Vec<String>,
    #[serde(default)]
    pub cells: Vec<usize>,
    #[serde(default = "default_kernel")]
    pub kernel: String,
    #[serde(default = "default_width")]
    pub width: f64,
    #[serde(default)]
    pub start: f64,
    #[serde(default = "default_every")]
    pub every: u64,
    #[serde(default)]
    pub average: u64,
}

fn default_kernel() -> String {
    "gaussian".into()
}
fn default_width() -> f64 {
    1.0
}
fn default_every() -> u64 {
    100
}
