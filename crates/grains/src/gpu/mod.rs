//! The GPU engine's pipeline: per-grain kernels over structure-of-arrays
//! data in cell order, a full neighbour list, no floating-point atomics
//! (see docs/gpu.md).
//!
//! [`grain_kernels`] holds what one thread does for one grain, and the step
//! words through which the device decides rebuilds; [`mirror`] runs the
//! pipeline as plain loops on the CPU (always compiled, the same bits as
//! the CPU engine), with [`list_build`]'s bins and prefix sums; `cuda`
//! (feature `cuda`) runs the same kernels, written in CUDA C under
//! `kernels/`, on the device, with their parameter structs in
//! `kernel_params`; [`pipeline`] is what a scenario run drives of either.

#[cfg(feature = "cuda")]
pub mod cuda;
pub mod engine;
pub mod grain_kernels;
#[cfg(feature = "cuda")]
mod kernel_params;
pub mod list_build;
pub mod mirror;
pub mod pipeline;

use crate::boundary::{Motion, Shape};
use crate::dim::D3;
use crate::error::{Error, Result};
use crate::integrate::Integrator;
use crate::md::Md;
use grain_kernels::Hooke;

/// How a build without the feature answers `gpu`.
pub const NO_FEATURE: &str = "run.device = \"gpu\" (or --device gpu) needs grains built with \
     the cuda feature: cargo build --release --features cuda (docs/gpu.md)";

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
    if s.law.materials().is_some() {
        return refuse("contact.model = \"hertz-mindlin\"".into());
    }
    // The table the CPU engine's kernel runs, as it is.
    let Some(law) = s.law.hooke_history() else {
        return refuse(format!(
            "the contact law {:?} (not the Hooke-with-history shape: beta = 1, reduced \
             scaling, rotation, kt > 0, finite mu)",
            s.law.estimate()
        ));
    };
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
    Ok(law)
}
