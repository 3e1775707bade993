//! Checkpoints: MD, flow and DSMC runs resume bit for bit; damaged files
//! are refused.
//!
//! One test binary per topic, so that `cargo test` links a few binaries
//! rather than one per file; each module holds the tests of one subject.

mod dsmc;
mod fields;
mod flow;
mod fuzz;
mod md;
mod mesh;
