//! `run.device`: where a scenario's engine runs. A run asking for the GPU
//! pipeline is checked before it starts and refused by name: the build's
//! feature, or what the pipeline does not run.

use super::schema::{Device, Dimension};
use super::Loaded;
use crate::dim::D3;
use crate::error::{Error, Result};
use crate::gpu;

/// Whether the GPU pipeline runs this scenario (`run.device = "gpu"` or
/// `"mirror"`); an error naming the first thing that stops it. A CPU run
/// passes at once.
pub fn check_device(loaded: &Loaded) -> Result<()> {
    let s = &loaded.scenario;
    if s.run.gpu_fma && s.run.device != Device::Gpu {
        return Err(Error::input(
            "run.gpu_fma = true goes with run.device = \"gpu\" (the CPU engine and the \
             mirror run without fused multiply-add)",
        ));
    }
    if s.run.device == Device::Cpu {
        return Ok(());
    }
    if s.run.device == Device::Gpu && !cfg!(feature = "cuda") {
        return Err(Error::input(gpu::NO_FEATURE));
    }
    let name = match s.run.device {
        Device::Mirror => "mirror",
        _ => "gpu",
    };
    let refuse = |what: &str| {
        Err(Error::input(format!(
            "run.device = \"{name}\": {what} is not supported by the GPU engine (it runs {})",
            gpu::SUPPORTED
        )))
    };
    if s.method == crate::dsmc::Method::Dsmc {
        return refuse("method = \"dsmc\"");
    }
    if s.dimension != Dimension::Three {
        return refuse("dimension = \"2d\"");
    }
    // The hooks of a GPU run read the grains; these change them.
    if s.hopper.is_some() {
        return refuse("[hopper] (its grains are recycled on the host)");
    }
    if s.run.events.is_some() {
        return refuse("run.events (they change walls and gravity on the host)");
    }
    if !s.inlets.is_empty() {
        return refuse(
            "[[inlets]] (grains are inserted on the host; the pipeline would have to take its \
             arrays back and upload them grown at every insertion)",
        );
    }
    if !s.outlets.is_empty() || !s.sensors.is_empty() {
        return refuse(
            "[[outlets]]/[[sensors]] (removing grains would need the device's arrays compacted \
             and its list rebuilt; sensors would read the grains every step)",
        );
    }
    let (md, _) = super::build_md::<D3>(loaded)?;
    gpu::check_supported(&md)?;
    Ok(())
}
