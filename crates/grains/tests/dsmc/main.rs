//! DSMC against kinetic theory, against MD, and its validity warnings.
//!
//! One test binary per topic, so that `cargo test` links a few binaries
//! rather than one per file; each module holds the tests of one subject.

mod md_crossval;
mod physics;
mod validity;
