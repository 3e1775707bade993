//! Measurements: quantities computed from the engine's state between steps.
//! Each keeps its own running state, keyed by grain id (grains are re-sorted
//! in memory), and reports scalars for summary.json plus its own files.

pub mod convection;
pub mod displacement;
pub mod temperature;

pub use convection::Convection;
pub use displacement::DisplacementField;
pub use temperature::granular_temperature;
