//! Helpers shared by the command-line tests.
#![allow(dead_code)]

// The library's tests read the VTK files back with the same helpers.
#[path = "../../../grains/tests/common/vtk.rs"]
mod vtk;
pub use vtk::*;
