//! Grains against walls: elastic bounces, triangle meshes and polylines.
//!
//! One test binary per topic, so that `cargo test` links a few binaries
//! rather than one per file; each module holds the tests of one subject.

#[path = "../common/mod.rs"]
mod common;

mod elastic_walls;
mod mesh_walls;
mod polyline_walls;
