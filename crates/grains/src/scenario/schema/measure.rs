//! The `[measure]` table of a scenario file: the measurements of a run.

use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, Default)]
#[serde(deny_unknown_fields)]
pub struct MeasureSpec {
    /// Displacement field from the end of relaxation to the end of the run:
    /// displacement.csv and displacement.png (seed 002 Figs. 2–3).
    #[serde(default)]
    pub displacement: bool,
    /// Convection strength: mean vertical velocity in the central band and
    /// the edge bands (fraction of the width each), averaged over the run.
    #[serde(default)]
    pub convection: Option<ConvectionSpec>,
    /// Snapshots at phases of the first vibrating wall (seed 002 Fig. 1):
    /// phase_<k>.csv/png, and phase_displacement.csv/png.
    #[serde(default)]
    pub phases: Option<PhasesSpec>,
    /// A tracer grain's trajectory: tracer.csv, tracer.png, `tracer_rms`.
    #[serde(default)]
    pub tracer: Option<TracerSpec>,
    /// Density and horizontal-velocity profiles against height, averaged
    /// over the run: profiles.csv, profile_*.png, `transport_velocity`.
    #[serde(default)]
    pub profiles: Option<ProfilesSpec>,
    /// Positions of every grain over the last cycle (seed 002 Fig. 4):
    /// trajectories.csv, trajectories.png.
    #[serde(default)]
    pub trajectories: Option<TrajectoriesSpec>,
    /// Slope of the free surface left at the end of the run (angle of
    /// repose): `repose_angle_deg`, surface.csv.
    #[serde(default)]
    pub repose: Option<SurfaceSpec>,
    /// Slope of the free surface averaged over the run (rotating drum):
    /// `dynamic_angle_deg`.
    #[serde(default)]
    pub surface_angle: Option<SurfaceSpec>,
    /// Density along the vertical axis against time: spacetime.csv/png.
    #[serde(default)]
    pub spacetime: Option<SpacetimeSpec>,
    /// Coarse-grained packing fraction, velocity and granular temperature
    /// on a grid, averaged over time: flow_field.csv/png.
    #[serde(default)]
    pub flow_field: Option<FlowFieldSpec>,
    /// Per collision of two bodies (two grains, or a grain and a wall): the
    /// largest overlap, peak normal force, duration, restitution and
    /// rebound angle: impacts.csv and `impact_*` (`measure::impact`).
    #[serde(default)]
    pub impact: bool,
    /// Coarse-grained stress, density, velocity, temperature, coordination
    /// and fabric fields: fields/*.vti, fields.pvd (docs/fields.md).
    #[serde(default)]
    pub fields: Option<super::fields::FieldsSpec>,
    /// The rheology of a sheared box (`domain.shear`): per sample the shear
    /// stress, pressure, μ = τ/P, inertial number, packing fraction and
    /// coordination from the contact virial and the grains' motion:
    /// rheology.csv and their averages in summary.json (`measure::rheology`).
    #[serde(default)]
    pub rheology: bool,
}

/// `measure.flow_field`: `cells` = [along x, along the vertical axis] over
/// the box (in 3D each cell is a slab through y), samples from time `from`
/// (s) on, the grid's top at `top` (m; default the box top).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct FlowFieldSpec {
    pub cells: Vec<usize>,
    #[serde(default)]
    pub from: f64,
    #[serde(default)]
    pub top: Option<f64>,
}

/// A free-surface fit: the top grain of each column of width `column` (d0)
/// within `x_range` (m, along x), heights above `min_height` (m) fitted by
/// least squares.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SurfaceSpec {
    /// Column width in units of d0; default 2.
    #[serde(default = "default_column")]
    pub column: f64,
    /// Range of x (m) over which columns are fitted.
    pub x_range: Vec<f64>,
    /// Columns whose top grain is below this height (m) are left out.
    #[serde(default)]
    pub min_height: f64,
}

fn default_column() -> f64 {
    2.0
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SpacetimeSpec {
    /// Bin length along the vertical axis, in units of d0; default 1.
    #[serde(default = "default_st_bin")]
    pub bin: f64,
}

fn default_st_bin() -> f64 {
    1.0
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PhasesSpec {
    /// Phases (rad) of the drive 2π f t + φ0 at which to take snapshots.
    pub phases: Vec<f64>,
    /// Velocity segments are |v| times this long (s); default 0.1 / f.
    #[serde(default)]
    pub segment_time: Option<f64>,
    /// Also the displacement from phase 0 to this many seconds later
    /// (seed 002 Fig. 1e: 0.015).
    #[serde(default)]
    pub displacement_after: Option<f64>,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TracerSpec {
    /// Id of the tracer grain (ids start at 1).
    pub id: u64,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ProfilesSpec {
    /// Bin height in units of d0; default 0.5.
    #[serde(default = "default_bin")]
    pub bin: f64,
}

fn default_bin() -> f64 {
    0.5
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TrajectoriesSpec {
    /// Steps between recorded positions; default 50 (the seed's Fig. 4).
    #[serde(default = "default_traj_every")]
    pub every: u64,
    /// Length of the recorded window at the end of the run, in cycles;
    /// default 1.
    #[serde(default = "default_traj_cycles")]
    pub cycles: f64,
}

fn default_traj_every() -> u64 {
    50
}
fn default_traj_cycles() -> f64 {
    1.0
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ConvectionSpec {
    /// Width of the central band and of each edge band, as a fraction of the
    /// domain's x length; default 0.2.
    #[serde(default = "default_band")]
    pub band: f64,
}

fn default_band() -> f64 {
    0.2
}
