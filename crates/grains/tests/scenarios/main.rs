//! The shipped flow scenarios: hopper, repose, mesh discharge, `check`,
//! and the engine each is run on.
//!
//! One test binary per topic, so that `cargo test` links a few binaries
//! rather than one per file; each module holds the tests of one subject.

#[path = "../common/mod.rs"]
mod common;

mod choose;
mod chute;
mod hopper;
mod mesh_discharge;
mod repose;
mod shear;
mod shipped_check;
mod size_distributions;
