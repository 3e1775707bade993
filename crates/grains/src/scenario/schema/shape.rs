//! `[[shapes]]`, rigid clumps of spheres, and the keys that make bodies of
//! them (`particles.shape`, `particles.shapes`, `particles.orientation`);
//! checked and built in `scenario/shapes.rs` and `scenario/clumps.rs`,
//! documented in docs/clumps.md.

use serde::{Deserialize, Serialize};

/// One `[[shapes]]` entry: a clump of spheres (disks in 2D), given by
/// `spheres` or by `file`.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ClumpSpec {
    /// The name bodies refer to.
    pub name: String,
    /// The spheres in the shape's own frame.
    #[serde(default)]
    pub spheres: Vec<SphereSpec>,
    /// A file of spheres, one `x y z r` per line (`#` starts a comment),
    /// relative to the scenario file; in place of `spheres`.
    #[serde(default)]
    pub file: Option<String>,
    /// Units of the centres and radii: "m" (default) or "d0" (multiples
    /// of particles.d0).
    #[serde(default)]
    pub units: ShapeUnits,
    /// A factor on every centre and radius, after the units.
    #[serde(default = "one")]
    pub scale: f64,
}

/// One sphere of a `[[shapes]]` entry.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SphereSpec {
    /// Centre, with one entry per axis (in 2D two, or three with z = 0).
    pub center: Vec<f64>,
    /// Radius.
    pub radius: f64,
}

/// The units of a shape's numbers.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "lowercase")]
pub enum ShapeUnits {
    /// Metres.
    #[default]
    M,
    /// Multiples of particles.d0.
    D0,
}

/// One entry of `particles.shapes`, a mixture by number of bodies.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ShapeShare {
    /// A `[[shapes]]` name.
    pub name: String,
    /// Fraction of the bodies (the fractions sum to 1).
    pub fraction: f64,
}

/// An orientation: the word "random" (uniform on rotations) or a unit
/// quaternion [w, x, y, z] turning the shape's input frame into space.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum OrientationSpec {
    Word(String),
    Quaternion(Vec<f64>),
}

fn one() -> f64 {
    1.0
}
