//! What takes grains out of a run and counts them: `[[outlets]]`,
//! `[[sensors]]` and the `[outflow]` settings of their files.
//!
//! An outlet is a region (a box, a cylinder) or the far side of a plane;
//! a grain whose centre is in it is removed. A sensor is a plane that
//! counts the grains whose centres cross it, with their sign, and removes
//! none. `scenario/outlet.rs` checks and runs them.

use serde::{Deserialize, Serialize};

/// One outlet; exactly one of `plane`, `box`, `cylinder`.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct OutletSpec {
    pub name: String,
    /// Removes the grains whose centre lies beyond the plane (on the side
    /// `normal` points to).
    #[serde(default)]
    pub plane: Option<PlaneSpec>,
    /// Removes the grains whose centre lies in [lo, hi] on every axis.
    #[serde(default, rename = "box")]
    pub region_box: Option<BoxSpec>,
    /// Removes the grains whose centre lies within `radius` of the segment
    /// a–b (3D; in 2D a disk of `radius` about `a`, `b` unused and optional).
    #[serde(default)]
    pub cylinder: Option<CylinderSpec>,
    /// Time (s) from which the outlet removes grains; default 0.
    #[serde(default)]
    pub start: f64,
    /// Steps between looks (default 1): a grain is removed at the first
    /// look with its centre in the region, at most `every` − 1 steps late.
    #[serde(default = "one")]
    pub every: u64,
}

/// A plane (3D) or line (2D) through `point` with normal `normal`.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PlaneSpec {
    pub point: Vec<f64>,
    pub normal: Vec<f64>,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct BoxSpec {
    pub lo: Vec<f64>,
    pub hi: Vec<f64>,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CylinderSpec {
    pub a: Vec<f64>,
    #[serde(default)]
    pub b: Option<Vec<f64>>,
    pub radius: f64,
}

/// A counting plane: a grain whose centre went from the back of the plane
/// to the side `normal` points to between two checks counts +1, back −1.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SensorSpec {
    pub name: String,
    pub point: Vec<f64>,
    pub normal: Vec<f64>,
    /// Steps between checks (default 1). A grain must not cross twice
    /// between two checks: a check every step is always safe.
    #[serde(default = "one")]
    pub every: u64,
}

fn one() -> u64 {
    1
}

/// `[outflow]`: rows of the files and the judgement of a steady discharge.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct OutflowSpec {
    /// Diameter edges (m) of the size classes counted in outflow.csv,
    /// ascending; classes are [-, e1), [e1, e2), …, [en, -). Default: the
    /// grains' diameter range split in `size_classes` equal parts.
    #[serde(default)]
    pub size_edges: Option<Vec<f64>>,
    /// Classes when `size_edges` is not given (default 4); none when the
    /// grains have one size.
    #[serde(default = "four")]
    pub size_classes: usize,
    /// The steady part of the discharge: the bins whose rate lies within
    /// this fraction of the median bin rate (default 0.2).
    #[serde(default = "fifth")]
    pub steady_tolerance: f64,
    /// Width (s) of the bins of sensors.csv and of the running rate;
    /// default: the removals' time span over 20.
    #[serde(default)]
    pub bin: Option<f64>,
}

fn four() -> usize {
    4
}
fn fifth() -> f64 {
    0.2
}

impl Default for OutflowSpec {
    fn default() -> Self {
        Self {
            size_edges: None,
            size_classes: four(),
            steady_tolerance: fifth(),
            bin: None,
        }
    }
}
