//! End-to-end tests of the `grains` binary.
//!
//! One test binary per topic, so that `cargo test` links a few binaries
//! rather than one per file; each module holds the tests of one subject.

#[path = "../common/mod.rs"]
mod common;

mod bad_input;
mod cg;
mod check_law;
mod commands;
mod mesh_input;
mod progress;
mod restart;
mod resume;
mod view_movie;
