//! `run.device`: where a scenario's engine runs. A run asking for the GPU
//! is checked before it starts and refused by name (the build's feature,
//! what the GPU engine does not run, or that scenario runs are not wired
//! to it yet).

use super::schema::{Device, Dimension};
use super::Loaded;
use crate::dim::D3;
use crate::error::{Error, Result};
use crate::gpu;

/// A scenario run asking for `run.device = "gpu"`: refused before the
/// run, naming what stops it (the build's feature, what the GPU engine
/// does not run, or that scenario runs are not wired to it yet).
pub fn check_device(loaded: &Loaded) -> Result<()> {
    let s = &loaded.scenario;
    if s.run.device != Device::Gpu {
        return Ok(());
    }
    if !cfg!(feature = "cuda") {
        return Err(Error::input(gpu::NO_FEATURE));
    }
    if s.method == crate::dsmc::Method::Dsmc {
        return Err(Error::input(format!(
            "run.device = \"gpu\": method = \"dsmc\" is not supported by the GPU engine (it runs {})",
            gpu::SUPPORTED
        )));
    }
    if s.dimension != Dimension::Three {
        return Err(Error::input(format!(
            "run.device = \"gpu\": dimension = \"2d\" is not supported by the GPU engine (it runs {})",
            gpu::SUPPORTED
        )));
    }
    let (md, _) = super::build_md::<D3>(loaded)?;
    gpu::check_supported(&md)?;
    Err(Error::input(
        "run.device = \"gpu\": scenario runs (outputs, measurements, checkpoints) are not \
         wired to the GPU engine yet; time it with `grains bench chute|bed3d --device gpu`",
    ))
}
