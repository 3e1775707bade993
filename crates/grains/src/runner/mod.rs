//! Runs a scenario end to end: build the engine, relax, measure, write.
//!
//! Phases, in order: [`prepare`] the output directory (fails early when it is
//! not writable); relax (steps with no output); measure (steps with thermo
//! rows, frames and measurement samples at every output interval); finish
//! (the final frame, pictures, measurement files and summary.json).

pub(crate) mod checkpointer;
pub mod checkpointing;
pub mod choose;
mod device_md;
pub mod distributed;
mod distributed_md;
pub mod dsmc;
pub mod engine;
pub(crate) mod found;
pub(crate) mod md_run;
mod options;
mod phases;
mod run_loop;
pub mod saved;

pub use crate::engine::Engine;
pub use options::{prepare, prepare_fresh, Progress, RunOptions, Silent};

use crate::dim::Dim;
use crate::dsmc::collide::GasDim;
use crate::error::Result;
use crate::scenario::Loaded;
use choose::{choose, Runs};
use serde_json::Value;

/// Builds the engine of a scenario without running it, and reports what
/// `grains check` prints.
pub fn check(loaded: &Loaded) -> Result<Value> {
    struct Check<'a>(&'a Loaded);
    impl Runs for Check<'_> {
        type Out = Result<Value>;
        fn md<D: Dim>(self) -> Result<Value> {
            crate::scenario::law_report::md_check::<D>(&*crate::scenario::hopper::expand(self.0)?)
        }
        fn gas<D: GasDim>(self) -> Result<Value> {
            let (sim, plan) = dsmc::build::<D>(self.0)?;
            Ok(dsmc::describe(self.0, &sim, &plan))
        }
    }
    choose(&loaded.scenario, Check(loaded))
}

/// Runs a scenario; returns the summary that was written to summary.json.
pub fn run(loaded: &Loaded, opts: &RunOptions, progress: &mut dyn Progress) -> Result<Value> {
    crate::parallel::on_pool(|| run_on_pool(loaded, opts, progress))
}

fn run_on_pool(loaded: &Loaded, opts: &RunOptions, progress: &mut dyn Progress) -> Result<Value> {
    crate::scenario::device::check_device(loaded)?;
    struct Fresh<'a>(&'a Loaded, &'a RunOptions, &'a mut dyn Progress);
    impl Runs for Fresh<'_> {
        type Out = Result<Value>;
        fn md<D: Dim>(self) -> Result<Value> {
            md_run::run_dim::<D>(self.0, self.1, self.2)
        }
        fn gas<D: GasDim>(self) -> Result<Value> {
            dsmc::run_dim::<D>(self.0, self.1, self.2)
        }
        fn device(self) -> std::result::Result<Result<Value>, Self> {
            Ok(device_md::run_fresh(self.0, self.1, self.2))
        }
    }
    choose(&loaded.scenario, Fresh(loaded, opts, progress))
}
