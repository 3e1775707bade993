//! The scenario file: serde types mirroring the TOML, SI units throughout.
//!
//! Every struct denies unknown keys so a typo is an error, not a silent
//! default. `docs/scenario-reference.md` documents each field; keep the two in
//! step. Vectors are arrays with one entry per axis of the chosen dimension.

mod contact;
mod fields;
mod flow;
mod inlet;
mod measure;
mod outlet;
mod run;
mod shape;
mod size;
mod walls;

pub use contact::{ContactModelKind, ContactPreset, ContactSpec, MaterialPairSpec, MaterialSpec};
pub use fields::FieldsSpec;
pub use flow::{EventsSpec, HopperSpec};
pub use inlet::{InletRegion, InletSpec, MixtureSpec};
pub use measure::{
    ConvectionSpec, FlowFieldSpec, MeasureSpec, PhasesSpec, ProfilesSpec, SpacetimeSpec,
    SurfaceSpec, TracerSpec, TrajectoriesSpec,
};
pub use outlet::{BoxSpec, CylinderSpec, OutflowSpec, OutletSpec, PlaneSpec, SensorSpec};
pub use run::{Device, FramesLayout, OutputSpec, RunSpec, TimeStep};
pub use shape::{ClumpSpec, OrientationSpec, ShapeShare, ShapeUnits, SphereSpec};
pub use size::{SizeDistribution, SizeSpec, SizeWeight};
pub use walls::{MotionSpec, ShapeSpec, WallSpec};

use crate::particles::MassModel;
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Name of the run; default output directory is `runs/<name>`.
    pub name: String,
    #[serde(default)]
    pub description: String,
    /// "2d" (disks, y vertical) or "3d" (spheres, z vertical).
    pub dimension: Dimension,
    /// "md" (soft spheres, default) or "dsmc" (stochastic hard-sphere gas).
    #[serde(default)]
    pub method: crate::settings::Method,
    /// Seed of every random stream (placement, velocities).
    #[serde(default = "default_seed")]
    pub seed: u64,
    pub domain: DomainSpec,
    pub particles: ParticlesSpec,
    #[serde(default)]
    pub contact: ContactSpec,
    /// Materials, for `contact.model = "hertz-mindlin"`.
    #[serde(default)]
    pub materials: Vec<MaterialSpec>,
    /// Values of a pair of materials that replace the mixing rules.
    #[serde(default)]
    pub material_pairs: Vec<MaterialPairSpec>,
    #[serde(default)]
    pub walls: Vec<WallSpec>,
    /// Gravitational acceleration vector (m/s²); default zero.
    #[serde(default)]
    pub gravity: Option<Vec<f64>>,
    pub run: RunSpec,
    #[serde(default)]
    pub output: OutputSpec,
    #[serde(default)]
    pub measure: MeasureSpec,
    /// Settings of method = "dsmc".
    #[serde(default)]
    pub dsmc: Option<crate::settings::DsmcSpec>,
    /// A silo generated from a few numbers (`hopper.outlet` is the outlet width).
    #[serde(default)]
    pub hopper: Option<HopperSpec>,
    /// Grains arriving during an MD run (`scenario/inlet.rs`).
    #[serde(default)]
    pub inlets: Vec<InletSpec>,
    /// Regions and planes that take grains out of the run (`scenario/outlet.rs`).
    #[serde(default)]
    pub outlets: Vec<OutletSpec>,
    /// Planes that count the grains crossing them.
    #[serde(default)]
    pub sensors: Vec<SensorSpec>,
    /// Size classes of outflow.csv and the steady-discharge judgement.
    #[serde(default)]
    pub outflow: OutflowSpec,
    /// How a distributed (MPI) MD run splits the box over its ranks.
    #[serde(default)]
    pub parallel: crate::settings::ParallelSpec,
    /// Rigid clumps of spheres that bodies are made of (docs/clumps.md).
    #[serde(default)]
    pub shapes: Vec<ClumpSpec>,
}

fn default_seed() -> u64 {
    1
}

#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
pub enum Dimension {
    #[serde(rename = "2d")]
    Two,
    #[serde(rename = "3d")]
    Three,
}

impl Dimension {
    pub fn axes(self) -> usize {
        match self {
            Dimension::Two => 2,
            Dimension::Three => 3,
        }
    }
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DomainSpec {
    /// Lower corner (m).
    pub lo: Vec<f64>,
    /// Upper corner (m). On non-periodic axes this only sizes the cell grid.
    pub hi: Vec<f64>,
    /// Periodicity per axis; default none.
    #[serde(default)]
    pub periodic: Vec<bool>,
    /// Lees–Edwards shear of a periodic box (`scenario/shear.rs`).
    #[serde(default)]
    pub shear: Option<ShearSpec>,
}

/// `domain.shear = { axis, gradient_axis, rate, start_profile }`, checked
/// in `scenario/shear.rs`.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ShearSpec {
    /// The flow direction: "x" (the only one the cell search supports).
    pub axis: String,
    /// The direction of the velocity gradient: "y" (2D) or "y"/"z" (3D).
    pub gradient_axis: String,
    /// Shear rate γ̇ (1/s): the image above the box moves at γ̇ L_g.
    pub rate: f64,
    /// Start the grains on the linear profile u = γ̇ (y − y_mid) added to
    /// their velocities (default true), so that the cell starts sheared.
    #[serde(default = "yes")]
    pub start_profile: bool,
    /// Normal stress P (Pa) held on the gradient axis: the box length
    /// along it follows the measured σ_gg (`md::barostat`); absent, the
    /// box keeps its volume.
    #[serde(default)]
    pub pressure: Option<f64>,
    /// Relaxation time τ_p (s) of the box length under `pressure`.
    #[serde(default)]
    pub relax_time: Option<f64>,
    /// Steps between the barostat's readings of σ_gg (default 20).
    #[serde(default)]
    pub pressure_every: Option<u64>,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ParticlesSpec {
    /// How grains are created.
    #[serde(default)]
    pub placement: Placement,
    /// Number of grains to place (lattice and random placement).
    #[serde(default)]
    pub count: usize,
    /// Mean diameter d0 (m).
    #[serde(default = "default_d0")]
    pub d0: f64,
    /// Width w of the diameter band, in units of d0: d ∈ d0 [1 − w/2, 1 + w/2].
    #[serde(default)]
    pub width: f64,
    /// A size distribution in place of the band (lattice and random
    /// placement); d0, when not given, is then its number-mean diameter.
    #[serde(default)]
    pub size: Option<SizeSpec>,
    /// Material density (kg/m³; with mass_model = "disk" in 2D, kg/m²).
    #[serde(default = "default_density")]
    pub density: f64,
    #[serde(default)]
    pub mass_model: MassModel,
    /// Target packing fraction of placement = "packed" (the count
    /// follows from it).
    #[serde(default)]
    pub packing: Option<f64>,
    /// Region to fill (lattice, random, packed); default the whole domain.
    #[serde(default)]
    pub region: Option<RegionSpec>,
    /// Lattice spacing in units of the largest diameter (≥ 1); default 1.05.
    #[serde(default = "default_spacing")]
    pub spacing: f64,
    /// Random initial velocities: each component uniform in ±this (m/s).
    #[serde(default)]
    pub random_velocity: f64,
    /// Initial state file for placement = "file" (LAMMPS data or CSV).
    #[serde(default)]
    pub file: Option<String>,
    /// Format of `file`; default from its name (`.csv` → csv, else lammps).
    #[serde(default)]
    pub format: Option<FileFormat>,
    /// Types (LAMMPS `type` column) whose grains are frozen in place.
    #[serde(default)]
    pub frozen_types: Vec<u32>,
    /// Individual grains added after the placement above.
    #[serde(default)]
    pub add: Vec<GrainSpec>,
    /// The grains' material (a `[[materials]]` name); its density replaces
    /// `density`.
    #[serde(default)]
    pub material: Option<String>,
    /// Lattice and random placement make bodies of this `[[shapes]]` entry
    /// instead of spheres.
    #[serde(default)]
    pub shape: Option<String>,
    /// A mixture of shapes by number, in place of `shape`.
    #[serde(default)]
    pub shapes: Vec<ShapeShare>,
    /// Orientation of placed bodies: "random" (default) or a quaternion.
    #[serde(default)]
    pub orientation: Option<OrientationSpec>,
}

fn default_d0() -> f64 {
    1.0e-3
}
fn default_density() -> f64 {
    2500.0
}
fn default_spacing() -> f64 {
    1.05
}

#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "lowercase")]
pub enum Placement {
    /// Rows of grains from the bottom of the region up (seed 002: "placed
    /// regularly on the bottom").
    #[default]
    Lattice,
    /// Random non-overlapping positions in the region.
    Random,
    /// The region filled to `particles.packing` by growing the grains
    /// from a random placement (`scenario/packed.rs`).
    Packed,
    /// Read from `particles.file`.
    File,
    /// Only the grains listed in `particles.add`.
    None,
}

#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum FileFormat {
    Lammps,
    Csv,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RegionSpec {
    pub lo: Vec<f64>,
    pub hi: Vec<f64>,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct GrainSpec {
    pub position: Vec<f64>,
    /// Diameter (m); default d0.
    #[serde(default)]
    pub diameter: Option<f64>,
    #[serde(default)]
    pub velocity: Option<Vec<f64>>,
    #[serde(default)]
    pub frozen: bool,
    /// Type for output; default 1 (2 if frozen).
    #[serde(default)]
    pub kind: Option<u32>,
    /// Material of this grain (default `particles.material`); grains of one
    /// kind share one material.
    #[serde(default)]
    pub material: Option<String>,
    /// A body of this `[[shapes]]` entry instead of a sphere; `position`
    /// is then its centre of mass.
    #[serde(default)]
    pub shape: Option<String>,
    /// A body's orientation, a unit quaternion [w, x, y, z]; default [1, 0, 0, 0].
    #[serde(default)]
    pub orientation: Option<Vec<f64>>,
    /// Angular velocity (rad/s): [wx, wy, wz] in 3D, [wz] in 2D.
    #[serde(default)]
    pub omega: Option<Vec<f64>>,
}

/// `true`, the default of the switches that are on unless turned off.
fn yes() -> bool {
    true
}
