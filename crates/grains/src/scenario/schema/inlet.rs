//! `[[inlets]]`: regions where grains arrive during a run, at a rate or in
//! a total, with a size distribution and velocities (`scenario/inlet.rs`
//! checks and runs them).

use super::{OrientationSpec, ShapeShare, SizeSpec, SizeWeight};
use serde::{Deserialize, Serialize};

/// One inlet. Exactly one of `rate`, `mass_rate`, `count` and `mass` says
/// how many grains arrive; which keys apply is checked by
/// `scenario/inlet.rs`, naming the key.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct InletSpec {
    /// Where the grains' centres are drawn (each grain wholly inside).
    pub region: InletRegion,
    /// First time at which grains arrive (s); default 0.
    #[serde(default)]
    pub start: f64,
    /// Time after which none arrives (s); default the end of the run.
    #[serde(default)]
    pub stop: Option<f64>,
    /// Grains per second.
    #[serde(default)]
    pub rate: Option<f64>,
    /// Kilograms per second.
    #[serde(default)]
    pub mass_rate: Option<f64>,
    /// A number of grains, spread evenly over [start, stop] (all at start
    /// without stop).
    #[serde(default)]
    pub count: Option<u64>,
    /// A total mass (kg), spread as `count`.
    #[serde(default)]
    pub mass: Option<f64>,
    /// Velocity of the arriving grains (m/s); default zero.
    #[serde(default)]
    pub velocity: Option<Vec<f64>>,
    /// Each velocity component varies uniformly in ±this (m/s); default 0.
    #[serde(default)]
    pub velocity_spread: f64,
    /// The size distribution, as `particles.size`; default the grains' band
    /// (`particles.d0`, `particles.width`).
    #[serde(default)]
    pub size: Option<SizeSpec>,
    /// Type of the arriving grains (for output and their material);
    /// default 1.
    #[serde(default)]
    pub kind: Option<u32>,
    /// A mixture of `[[materials]]` by fraction, in place of `kind`
    /// (`scenario/inlet/mixture.rs`).
    #[serde(default)]
    pub materials: Option<Vec<MixtureSpec>>,
    /// Whether `materials[].fraction` is a share of the grains' number or
    /// of their mass; default "number".
    #[serde(default)]
    pub materials_weight: Option<SizeWeight>,
    /// The inlet brings rigid bodies of this `[[shapes]]` entry instead of
    /// spheres (`scenario/inlet/bodies.rs`).
    #[serde(default)]
    pub shape: Option<String>,
    /// A mixture of shapes by number of bodies, in place of `shape`.
    #[serde(default)]
    pub shapes: Vec<ShapeShare>,
    /// The bodies' orientation: "random" (uniform on rotations, the
    /// default) or a unit quaternion [w, x, y, z] turning the shape as
    /// written into space.
    #[serde(default)]
    pub orientation: Option<OrientationSpec>,
    /// Candidate positions tried for one grain at one step before it waits
    /// for the next; default 50.
    #[serde(default = "default_attempts")]
    pub attempts: u32,
}

/// One material of an inlet's mixture: `{ name, fraction, kind }`.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MixtureSpec {
    /// A `[[materials]]` name.
    pub name: String,
    /// The fraction of the inlet's grains of this material, by number or
    /// by mass (the inlet's `materials_weight`).
    pub fraction: f64,
    /// The type its grains get; default 1 + the material's place in
    /// `[[materials]]` (grains of one kind share one material).
    #[serde(default)]
    pub kind: Option<u32>,
}

fn default_attempts() -> u32 {
    50
}

/// `region = { shape = "box", lo, hi }` or `{ shape = "cylinder", center,
/// radius, lo, hi }` (a disc in 2D: `center` and `radius` on x, lo/hi the
/// vertical extent; in 3D a vertical cylinder).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, tag = "shape", rename_all = "lowercase")]
pub enum InletRegion {
    Box {
        lo: Vec<f64>,
        hi: Vec<f64>,
    },
    Cylinder {
        /// The axis's horizontal position: [x] in 2D, [x, y] in 3D.
        center: Vec<f64>,
        radius: f64,
        /// Vertical extent (m).
        bottom: f64,
        top: f64,
    },
}
