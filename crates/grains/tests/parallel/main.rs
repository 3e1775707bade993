//! Same bits on any number of threads and of ranks (ranks as threads).
//!
//! One test binary per topic, so that `cargo test` links a few binaries
//! rather than one per file; each module holds the tests of one subject.

#[path = "../common/mod.rs"]
mod common;

mod determinism;
mod distributed_dsmc;
mod distributed_flow;
mod distributed_inlets;
mod distributed_md;
