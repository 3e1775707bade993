//! Contact physics against closed forms and conservation laws.
//!
//! One test binary per topic, so that `cargo test` links a few binaries
//! rather than one per file; each module holds the tests of one subject.

#[path = "../common/mod.rs"]
mod common;

mod binary_collision;
mod body_weight;
mod chung_ooi;
mod clumps;
mod clumps_outputs;
mod clumps_statics;
mod coarse_grain;
mod conservation;
mod friction_and_walls;
mod impact;
mod jkr;
mod lammps_granular;
mod oblique;
mod pressure;
mod rebuild_springs;
mod rolling;
mod rolling_mesh;
mod rotation;
mod servo;
mod shapes;
mod shear;
