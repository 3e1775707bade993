//! Direct Simulation Monte Carlo of granular gases (seed 000 §4,
//! PHYSICS.md §2): particles stream ballistically under gravity, are sorted
//! into cells, and collide stochastically with partners of their own cell.
//! See `docs/dsmc.md`.

pub mod collide;
pub mod contract;
pub mod decomp;
pub mod dense;
pub mod diagnostics;
pub mod engine;
pub mod haff;
pub mod placement;
pub mod rng;
pub mod sort;
pub mod store;
pub mod stream;
pub mod workload;

pub use crate::settings::dsmc::{DsmcSpec, Method};
pub use collide::{CellState, GasDim, Tally};
pub use dense::DenseGas;
pub use engine::{collision_frequency, haff_time, maxwellian, Dsmc, DsmcSettings, PlaneWall};
pub use store::{Particle, Store};
