//! The `[[walls]]` of a scenario file: shapes and prescribed motions.

use crate::boundary::PlateSurface;
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct WallSpec {
    pub name: String,
    pub shape: ShapeSpec,
    #[serde(default)]
    pub motion: MotionSpec,
    /// Time (s) at which the wall disappears.
    #[serde(default)]
    pub remove_at: Option<f64>,
    /// The wall's material (default `particles.material`).
    #[serde(default)]
    pub material: Option<String>,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub enum ShapeSpec {
    /// Infinite line (2D) or plane (3D); grains live on the side `normal` points to.
    Plane { point: Vec<f64>, normal: Vec<f64> },
    /// Finite segment (2D).
    Segment { a: Vec<f64>, b: Vec<f64> },
    /// Convex planar polygon (3D); `seams`: edges shared with a coplanar
    /// neighbour (edge i from vertex i to i + 1), which give no contact.
    Polygon {
        vertices: Vec<Vec<f64>>,
        #[serde(default)]
        seams: Vec<usize>,
    },
    /// Circle (2D) or cylinder (3D) of `radius`; `inside` for pipes and drums.
    Cylinder {
        point: Vec<f64>,
        #[serde(default)]
        axis: Option<Vec<f64>>,
        radius: f64,
        #[serde(default = "super::yes")]
        inside: bool,
    },
    /// Fixed circular/spherical obstacle of `diameter` d1.
    Obstacle { center: Vec<f64>, diameter: f64 },
    /// Triangle mesh (3D) from an STL file (binary or ASCII; `file`
    /// relative to the scenario), scaled, turned about x, y, z (degrees)
    /// and shifted, in that order; `load_point`: the point torques on it
    /// are taken about (default its centroid).
    Mesh {
        file: String,
        #[serde(default = "unit_scale")]
        scale: f64,
        #[serde(default)]
        rotate_deg: Option<Vec<f64>>,
        #[serde(default)]
        translate: Option<Vec<f64>>,
        #[serde(default)]
        load_point: Option<Vec<f64>>,
    },
}

fn unit_scale() -> f64 {
    1.0
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, Default)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub enum MotionSpec {
    #[default]
    Fixed,
    /// z0(x, t) = A0 (1 − B cos(2π x / L)) sin(2π f t + phase) along `direction`
    /// (default vertical). `wavelength` L defaults to the domain's x length.
    Vibrate {
        amplitude: f64,
        frequency: f64,
        #[serde(default)]
        modulation: f64,
        #[serde(default)]
        wavelength: Option<f64>,
        #[serde(default)]
        phase: f64,
        #[serde(default)]
        direction: Option<Vec<f64>>,
        /// How a modulated plate meets a grain: "curved" (the curve z0(x, t),
        /// normal tilted by its slope) or "flat" (seed 002's 1992 reading:
        /// lifted to z0 under each grain, normal vertical).
        #[serde(default, skip_serializing_if = "PlateSurface::is_curved")]
        surface: PlateSurface,
    },
    /// Conveyor-belt ellipse: displacement = amplitude · sin(2π f t + phase).
    Oscillate {
        amplitude: Vec<f64>,
        frequency: f64,
        #[serde(default)]
        phase: f64,
    },
    /// Rigid rotation about `center` with angular velocity `omega` (rad/s;
    /// a one-element list `[w]` in 2D, a 3-vector in 3D).
    Rotate { center: Vec<f64>, omega: Vec<f64> },
    /// Constant velocity (m/s).
    Translate { velocity: Vec<f64> },
    /// A plane moved along its normal to hold the normal stress `pressure`
    /// (Pa; 2D N/m): speed `gain` × (pressure − measured), m/(s·Pa), at
    /// most `max_speed` (m/s), from `start` (s); `area` (m²; 2D m) the
    /// load is divided by, by default the box's cross-section across the
    /// normal (docs/servo-walls.md).
    Servo {
        pressure: f64,
        gain: f64,
        max_speed: f64,
        #[serde(default)]
        area: Option<f64>,
        #[serde(default)]
        start: f64,
    },
}
