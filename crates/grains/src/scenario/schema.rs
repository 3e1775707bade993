//! The scenario file: serde types mirroring the TOML, SI units throughout.
//!
//! Every struct denies unknown keys so a typo is an error, not a silent
//! default. `docs/scenario-reference.md` documents each field; keep the two in
//! step. Vectors are arrays with one entry per axis of the chosen dimension.

use crate::boundary::PlateSurface;
use crate::contact::MassScaling;
use crate::integrate::Integrator;
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
    /// How a distributed (MPI) MD run splits the box over its ranks.
    #[serde(default)]
    pub parallel: crate::settings::ParallelSpec,
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
    /// Material density (kg/m³; with mass_model = "disk" in 2D, kg/m²).
    #[serde(default = "default_density")]
    pub density: f64,
    #[serde(default)]
    pub mass_model: MassModel,
    /// Region to fill (lattice, random); default the whole domain.
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
}

/// Contact law. A preset fills every field; fields given next to it override.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, Default)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// "spring-dashpot" (default: the coefficients below) or
    /// "hertz-mindlin" (from `[[materials]]`).
    #[serde(default)]
    pub model: Option<ContactModelKind>,
    #[serde(default)]
    pub preset: Option<ContactPreset>,
    /// Normal stiffness (seed scaling: s⁻² m^(1−β); reduced: N m^(−β)).
    pub kn: Option<f64>,
    /// Exponent of the elastic force k_n ξ^β.
    pub beta: Option<f64>,
    /// Normal damping γ_n (s⁻¹).
    pub gamma_n: Option<f64>,
    /// Normal restitution coefficient e ∈ (0, 1] of two of the lightest
    /// grains, instead of gamma_n (β = 1 only).
    pub restitution: Option<f64>,
    /// Viscous shear friction γ_t (s⁻¹), the seeds' γ_s.
    pub gamma_t: Option<f64>,
    /// Tangential spring stiffness (units of k_n with β = 1); 0 = no spring.
    pub kt: Option<f64>,
    /// Coulomb coefficient; a negative value is an error, omit for no cap.
    pub mu: Option<f64>,
    pub scaling: Option<MassScaling>,
    pub rotation: Option<bool>,
    /// Rolling resistance ("none", "constant", "epsd"; hertz-mindlin only,
    /// needs rotation; `contact::rolling`).
    pub rolling: Option<crate::contact::rolling::RollingModel>,
    /// k_r of LAMMPS's `rolling sds` (force per length), with
    /// `preset = "lammps-granular"` and `rolling = "epsd"` only.
    pub rolling_stiffness: Option<f64>,
    /// γ_r of LAMMPS's `rolling sds` (force per velocity), likewise.
    pub rolling_damping: Option<f64>,
    /// Cohesion ("none", "dmt", "jkr"; hertz-mindlin only, from the
    /// materials' surface_energy; `contact::cohesion`, `contact::jkr`).
    pub cohesion: Option<crate::contact::cohesion::CohesionModel>,
    /// Names of walls whose contacts have no normal damping (γ_n = 0, the
    /// grains' γ_t kept): elastic side walls beside a dissipative bulk.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub elastic_walls: Vec<String>,
}

/// Which contact law a scenario uses.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "kebab-case")]
pub enum ContactModelKind {
    /// k_n ξ^β with viscous damping and the Cundall–Strack spring, from
    /// coefficients (`kn`, `gamma_n`, …).
    #[default]
    SpringDashpot,
    /// Hertz–Mindlin from the materials' moduli, restitution and friction.
    HertzMindlin,
}

/// One material (SI units).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    pub name: String,
    /// kg/m³.
    pub density: f64,
    /// Pa.
    pub youngs_modulus: f64,
    /// In (−1, 0.5).
    pub poisson_ratio: f64,
    /// Normal restitution of two grains of this material, in (0, 1].
    pub restitution: f64,
    /// Sliding friction μ.
    pub friction: f64,
    /// Rolling friction μ_r (dimensionless); default 0.
    #[serde(default)]
    pub rolling_friction: f64,
    /// J/m², for cohesion; default 0.
    #[serde(default)]
    pub surface_energy: f64,
}

/// Values for one pair of materials instead of the mixing rules.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MaterialPairSpec {
    pub a: String,
    pub b: String,
    #[serde(default)]
    pub restitution: Option<f64>,
    #[serde(default)]
    pub friction: Option<f64>,
    #[serde(default)]
    pub rolling_friction: Option<f64>,
    #[serde(default)]
    pub surface_energy: Option<f64>,
}

#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
pub enum ContactPreset {
    /// Seed 002: Hooke, γ_n = 200 s⁻¹, γ_t = 400 s⁻¹, k_n = 5e7 s⁻², seed
    /// scaling, no spring, no rotation.
    #[serde(rename = "seed")]
    Seed,
    /// LAMMPS `gran/hooke/history Kn NULL γn NULL μ 0` of the shared benchmarks
    /// (k_n = 2e5, k_t = 2/7 k_n, γ_n = 50, γ_t = 0, μ = 0.5), reduced scaling,
    /// rotation on. Units are whatever the data file uses (LAMMPS `lj`).
    #[serde(rename = "lammps-hooke-history")]
    LammpsHookeHistory,
    /// LAMMPS `pair_style granular` with `pair_coeff * * hertz/material E e ν
    /// tangential mindlin NULL 1.0 μ damping tsuji [rolling sds k_r γ_r
    /// μ_r]`, from `[[materials]]` (E, ν, e, μ, μ_r) and, with
    /// `rolling = "epsd"`, `rolling_stiffness` and `rolling_damping`.
    #[serde(rename = "lammps-granular")]
    LammpsGranular,
}

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
        #[serde(default = "yes")]
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

fn yes() -> bool {
    true
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
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RunSpec {
    #[serde(default)]
    pub integrator: Integrator,
    /// Time step: a number of seconds or "auto" (t_c / dt_safety).
    #[serde(default)]
    pub dt: TimeStep,
    /// dt = t_c / dt_safety when dt = "auto"; default 50.
    #[serde(default = "default_safety")]
    pub dt_safety: f64,
    /// Typical impact speed (m/s) for the contact time when β ≠ 1; default
    /// the larger of √(g d0) and the fastest wall speed.
    #[serde(default)]
    pub impact_speed: Option<f64>,
    /// Measured duration in seconds ...
    #[serde(default)]
    pub duration: Option<f64>,
    /// ... or in cycles of the first vibrating wall.
    #[serde(default)]
    pub cycles: Option<f64>,
    /// Relaxation before measuring, in seconds ...
    #[serde(default)]
    pub relax: Option<f64>,
    /// ... or in cycles.
    #[serde(default)]
    pub relax_cycles: Option<f64>,
    /// Verlet skin in units of d0; default 0.2.
    #[serde(default = "default_skin")]
    pub skin: f64,
    /// Largest overlap allowed, as a fraction of the smaller radius.
    #[serde(default = "default_overlap")]
    pub max_overlap: f64,
    /// Threads for the force loop (0: all cores).
    #[serde(default)]
    pub threads: usize,
    /// Run events: settle, then remove a wall or tilt gravity.
    #[serde(default)]
    pub events: Option<EventsSpec>,
    /// Where the MD steps run: "cpu" (default), "gpu" or "mirror" (the
    /// GPU pipeline as loops on the CPU; docs/gpu.md).
    /// Left out when written (checkpoints) if "cpu", so that files read as
    /// they did before the key.
    #[serde(default, skip_serializing_if = "Device::is_cpu")]
    pub device: Device,
    /// With `device = "gpu"`: the kernels compiled with fused multiply-add
    /// (faster; deterministic, but not the CPU engine's bits: docs/gpu.md).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub gpu_fma: bool,
}

/// The processor an MD run steps on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Device {
    #[default]
    Cpu,
    /// The CUDA engine (feature `cuda`).
    Gpu,
    /// The GPU pipeline run as loops on the CPU: the same arrays, kernels
    /// and bits, slowly; for checking a GPU run's set-up without a GPU.
    Mirror,
}

impl Device {
    pub fn is_cpu(&self) -> bool {
        *self == Device::Cpu
    }
}

fn default_safety() -> f64 {
    50.0
}
fn default_skin() -> f64 {
    0.2
}
fn default_overlap() -> f64 {
    0.5
}

#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum TimeStep {
    #[default]
    Auto,
    Seconds(f64),
}

impl Serialize for TimeStep {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            TimeStep::Auto => s.serialize_str("auto"),
            TimeStep::Seconds(x) => s.serialize_f64(*x),
        }
    }
}

impl<'de> Deserialize<'de> for TimeStep {
    fn deserialize<De: serde::Deserializer<'de>>(d: De) -> Result<Self, De::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Raw {
            Num(f64),
            Int(i64),
            Text(String),
        }
        match Raw::deserialize(d)? {
            Raw::Num(x) => Ok(TimeStep::Seconds(x)),
            Raw::Int(x) => Ok(TimeStep::Seconds(x as f64)),
            Raw::Text(t) if t == "auto" => Ok(TimeStep::Auto),
            Raw::Text(t) => Err(serde::de::Error::custom(format!(
                "run.dt = \"{t}\": expected a number of seconds or \"auto\""
            ))),
        }
    }
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Interval between thermo rows and frames (s); default duration/100.
    #[serde(default)]
    pub every: Option<f64>,
    /// Write VTK frames (frames/*.vtp + frames.pvd).
    #[serde(default = "yes")]
    pub frames: bool,
    /// How a frame is stored: "gathered" (one .vtp) or "pieces" (a .pvtp
    /// referencing one .vtp piece per rank, each written by its rank).
    #[serde(default)]
    pub frames_layout: FramesLayout,
    /// Write a LAMMPS text dump (dump.lammpstrj).
    #[serde(default)]
    pub dump: bool,
    /// Draw final.png.
    #[serde(default = "yes")]
    pub picture: bool,
    /// Draw movie.gif (and movie.mp4 with ffmpeg) from the frames at the end.
    #[serde(default)]
    pub movie: bool,
}

/// The files of one VTK frame (`output.frames_layout`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum FramesLayout {
    /// One `frames/frame_NNNNNN.vtp` with every grain, written by rank 0.
    #[default]
    Gathered,
    /// `frames/frame_NNNNNN.pvtp` (rank 0) listing one piece per rank,
    /// `frames/piece_<step>_<rank>.vtp`, each with that rank's own grains.
    Pieces,
}

impl Default for OutputSpec {
    fn default() -> Self {
        Self {
            every: None,
            frames: true,
            frames_layout: FramesLayout::Gathered,
            dump: false,
            picture: true,
            movie: false,
        }
    }
}

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

/// Events during a run. Settling ends when the kinetic energy per mobile
/// grain falls below `settle_energy` m g d0 (m the mean grain mass), but not
/// before `settle_min` seconds; then `remove_wall` disappears, or gravity
/// starts to turn at `tilt_rate` (the box tilts) until the grains flow.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct EventsSpec {
    /// Threshold of the kinetic energy per grain, in units of m g d0; default 1e-3.
    #[serde(default = "default_settle_energy")]
    pub settle_energy: f64,
    /// Earliest end of settling (s); default 0.
    #[serde(default)]
    pub settle_min: f64,
    /// Name of the wall removed once settled.
    #[serde(default)]
    pub remove_wall: Option<String>,
    /// Tilting rate of gravity (degrees per second) once settled; the box is
    /// tilted so that the pile leans towards +x.
    #[serde(default)]
    pub tilt_rate: Option<f64>,
    /// The pile has failed when the kinetic energy per grain exceeds this
    /// (units of m g d0) while tilting; default 1e-2.
    #[serde(default = "default_fail_energy")]
    pub fail_energy: f64,
    /// Grains below this height (m) are taken out of the run: frozen and
    /// parked below it (they fell out of the box).
    #[serde(default)]
    pub sink: Option<f64>,
}

fn default_settle_energy() -> f64 {
    1e-3
}
fn default_fail_energy() -> f64 {
    1e-2
}

/// A flat-bottomed silo built from planes (sides) and segments/polygons
/// (the floor with a centred outlet). 2D: a slot of width `outlet`; 3D: a
/// square orifice of side `outlet`. Grains that leave through the outlet and
/// fall below `sink` are put back at the top (recycled), so discharge is
/// steady.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct HopperSpec {
    /// Outlet width D (m): the gap between the floor's edges.
    pub outlet: f64,
    /// Height of the floor (m); default 0.
    #[serde(default)]
    pub floor: f64,
    /// Grains below this height (m) are recycled; default floor − 10 d0.
    #[serde(default)]
    pub sink: Option<f64>,
    /// Height band (m) where recycled grains are put back, [low, high].
    pub refill: Vec<f64>,
    /// Discharge before the flow rate is measured (s); default 0.
    #[serde(default)]
    pub transient: f64,
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
