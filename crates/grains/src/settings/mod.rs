//! The engines' settings as a scenario file gives them.
//!
//! Serde types and their checks, below both the scenario schema that reads
//! them and the engines that run by them: `dsmc` (the method switch,
//! `[dsmc]`), `parallel` (`[parallel]`, how ranks cut the box).

pub mod dsmc;
pub mod parallel;

pub use dsmc::{DenseGas, DsmcSpec, Method};
pub use parallel::{GridSpec, ParallelSpec};
