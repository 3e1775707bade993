//! The seeds' experiments: convection, conveyor, lift-off, readings.
//!
//! One test binary per topic, so that `cargo test` links a few binaries
//! rather than one per file; each module holds the tests of one subject.

#[path = "../common/mod.rs"]
mod common;

mod convection;
mod conveyor;
mod liftoff;
mod readings;
