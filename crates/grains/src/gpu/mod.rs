//! The GPU engine's pipeline: per-grain kernels over structure-of-arrays
//! data in cell order, a full neighbour list, no floating-point atomics
//! (see docs/gpu.md).
//!
//! [`grain_kernels`] holds what one thread does for one grain; [`mirror`]
//! runs the pipeline as plain loops on the CPU (always compiled, the same
//! bits as the CPU engine); `cuda` (feature `cuda`) runs the same kernels,
//! written in CUDA C under `kernels/`, on the device.

#[cfg(feature = "cuda")]
pub mod cuda;
pub mod grain_kernels;
pub mod mirror;

use crate::boundary::{Motion, Shape};
use crate::contact::hooke_history::HookeHistory;
use crate::dim::D3;
use crate::error::{Error, Result};
use crate::integrate::Integrator;
use crate::md::Md;
use grain_kernels::Hooke;

/// How a build without the feature answers `gpu`.
pub const NO_FEATURE: &str = "run.device = \"gpu\" (or --device gpu) needs grains built with \
     the cuda feature: cargo build --release --features cuda (docs/gpu.md)";

/// A scenario run asking for `run.device = "gpu"`: refused before the
/// run, naming what stops it (the build's feature, what the GPU engine
/// does not run, or that scenario runs are not wired to it yet).
pub fn check_scenario_device(loaded: &crate::scenario::Loaded) -> Result<()> {
    use crate::scenario::schema::{Device, Dimension};
    let s = &loaded.scenario;
    if s.run.device != Device::Gpu {
        return Ok(());
    }
    if !cfg!(feature = "cuda") {
        return Err(Error::input(NO_FEATURE));
    }
    if s.method == crate::dsmc::Method::Dsmc {
        return Err(Error::input(format!(
            "run.device = \"gpu\": method = \"dsmc\" is not supported by the GPU engine (it runs {SUPPORTED})"
        )));
    }
    if s.dimension != Dimension::Three {
        return Err(Error::input(format!(
            "run.device = \"gpu\": dimension = \"2d\" is not supported by the GPU engine (it runs {SUPPORTED})"
        )));
    }
    let (md, _) = crate::scenario::build_md::<D3>(loaded)?;
    check_supported(&md)?;
    Err(Error::input(
        "run.device = \"gpu\": scenario runs (outputs, measurements, checkpoints) are not \
         wired to the GPU engine yet; time it with `grains bench chute|bed3d --device gpu`",
    ))
}

/// What the GPU pipeline runs, in one line for messages.
pub const SUPPORTED: &str = "3D, integrator \"verlet\", the Hooke law with history \
     (preset \"lammps-hooke-history\" and its variants), fixed plane walls and gravity";

/// Whether the pipeline runs `md`: its law's coefficients, or an error
/// naming the first thing it does not run.
pub fn check_supported(md: &Md<D3>) -> Result<Hooke> {
    let refuse = |what: String| {
        Err(Error::input(format!(
            "run.device = \"gpu\": {what} is not supported by the GPU engine (it runs {SUPPORTED})"
        )))
    };
    let s = &md.settings;
    if s.integrator != Integrator::Verlet {
        return refuse(format!("run.integrator = \"{}\"", s.integrator.name()));
    }
    if s.materials.is_some() {
        return refuse("contact.model = \"hertz-mindlin\"".into());
    }
    if HookeHistory::of(&s.contact).is_none() {
        return refuse(format!(
            "the contact law {:?} (not the Hooke-with-history shape: beta = 1, reduced \
             scaling, rotation, kt > 0, finite mu)",
            s.contact
        ));
    }
    for w in &md.walls {
        let plane = matches!(w.shape, Shape::Plane { .. });
        if !plane || w.motion != Motion::Fixed || w.remove_at.is_some() {
            let what = if !plane {
                format!("shape {}", w.shape.kind())
            } else if w.motion != Motion::Fixed {
                format!("motion {}", w.motion.kind())
            } else {
                "remove_at".into()
            };
            return refuse(format!("wall '{}' ({what})", w.name));
        }
    }
    if md.particles.n_owned() != md.particles.len() {
        return refuse("a decomposed run (ghost grains)".into());
    }
    let c = &s.contact;
    Ok(Hooke {
        kn: c.kn,
        gamma_n: c.gamma_n,
        gamma_t: c.gamma_t,
        kt: c.kt,
        mu: c.mu,
    })
}
