//! The one place that chooses what runs a scenario: its method (MD or
//! DSMC), device (the CPU engine or the GPU pipeline) and dimension (2 or
//! 3) become one compiled engine type. Serial or over MPI ranks is the
//! entry that asks (`run`, `resume`, `check`, `distributed`, the Python
//! session): each is a [`Runs`] whose methods say what it does with the
//! engine chosen, so every entry dispatches alike and a new engine is one
//! arm here.

use crate::dim::{Dim, D2, D3};
use crate::dsmc::collide::GasDim;
use crate::dsmc::Method;
use crate::scenario::schema::{Dimension, Scenario};

/// What an entry does with the engine [`choose`] picks, generic over its
/// dimension.
pub trait Runs: Sized {
    type Out;
    /// The MD engine on the CPU (serial, or decomposed over ranks).
    fn md<D: Dim>(self) -> Self::Out;
    /// The DSMC engine.
    fn gas<D: GasDim>(self) -> Self::Out;
    /// The GPU pipeline (3D MD: `scenario::device` refuses the rest), or
    /// `Err(self)` where the entry builds the CPU engine of such a scenario
    /// instead (`grains check`, the session: the default).
    fn device(self) -> Result<Self::Out, Self> {
        Err(self)
    }
}

/// Runs `entry` on the engine that `scenario` asks for.
pub fn choose<R: Runs>(scenario: &Scenario, entry: R) -> R::Out {
    let entry = match (scenario.method, scenario.run.device.is_cpu()) {
        (Method::Dsmc, _) => {
            return match scenario.dimension {
                Dimension::Two => entry.gas::<D2>(),
                Dimension::Three => entry.gas::<D3>(),
            }
        }
        (Method::Md, false) => match entry.device() {
            Ok(out) => return out,
            Err(entry) => entry,
        },
        (Method::Md, true) => entry,
    };
    match scenario.dimension {
        Dimension::Two => entry.md::<D2>(),
        Dimension::Three => entry.md::<D3>(),
    }
}
