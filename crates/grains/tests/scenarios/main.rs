//! The shipped flow scenarios: hopper, repose, mesh discharge, the silo
//! emptied through an outlet, `check`,
//! and the engine each is run on.
//!
//! One test binary per topic, so that `cargo test` links a few binaries
//! rather than one per file; each module holds the tests of one subject.

#[path = "../common/mod.rs"]
mod common;

mod cg_replay;
mod choose;
mod chute;
mod hopper;
mod inlet_bodies;
mod inlet_mixture;
mod inlet_sizes;
mod inlets;
mod mesh_discharge;
mod outlet_bodies;
mod packed_fill;
mod repose;
mod repose_clumps;
mod servo;
mod shear;
mod shipped_check;
mod silo;
mod size_distributions;
