//! Helpers shared by the command-line tests.
#![allow(dead_code)]

// The library's tests read the VTK files back with the same helpers.
#[path = "../../../grains/tests/common/vtk.rs"]
pub mod vtk;

/// The `--set` overrides of the small silo of the library's thread-rank
/// tests (`grains/tests/parallel/distributed_md.rs`: 150 grains over a wide outlet,
/// recycled just below the floor), then `extra`.
pub fn small_hopper_sets<'a>(extra: &[&'a str]) -> Vec<&'a str> {
    let file = include_str!("../../../grains/tests/data/small-hopper.sets");
    file.lines().chain(extra.iter().copied()).collect()
}

/// The `--set` overrides of the small angle-of-repose pile of the same
/// tests (80 disks in `scenarios/repose-2d.toml` under 30 m/s², settled
/// after 3 ms), then `extra`.
pub fn small_repose_sets<'a>(extra: &[&'a str]) -> Vec<&'a str> {
    let file = include_str!("../../../grains/tests/data/small-repose.sets");
    file.lines().chain(extra.iter().copied()).collect()
}
