//! The `[run]` and `[output]` tables of a scenario file.
//!
//! Integrator, time step, durations, device, and the files a run writes as
//! it goes.

use super::flow::EventsSpec;
use crate::integrate::Integrator;
use serde::{Deserialize, Serialize};

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
    #[serde(default = "super::yes")]
    pub frames: bool,
    /// How a frame is stored: "gathered" (one .vtp) or "pieces" (a .pvtp
    /// referencing one .vtp piece per rank, each written by its rank).
    #[serde(default)]
    pub frames_layout: FramesLayout,
    /// Write a LAMMPS text dump (dump.lammpstrj).
    #[serde(default)]
    pub dump: bool,
    /// Draw final.png.
    #[serde(default = "super::yes")]
    pub picture: bool,
    /// Draw movie.gif (and movie.mp4 with ffmpeg) from the frames at the end.
    #[serde(default)]
    pub movie: bool,
    /// Write each frame's contacts (contacts/*.vtp, *.csv, contacts.pvd).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub contacts: bool,
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
            contacts: false,
        }
    }
}
