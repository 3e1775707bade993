//! Measurements: quantities computed between steps from a read-only view
//! of an engine's grains ([`crate::view::GrainView`]) or a frame, never from
//! the engine itself.
//! Each keeps its own running state, keyed by grain id (grains are re-sorted
//! in memory), and reports scalars for summary.json plus its own files.

pub mod convection;
pub mod displacement;
pub mod displacement_draw;
pub mod draw;
pub mod fields;
pub mod flow_field;
pub mod gas;
pub mod impact;
pub(crate) mod measurements;
pub mod phase;
pub mod plot;
pub mod profiles;
pub mod rheology;
pub mod temperature;
pub mod tracer;
pub mod trajectories;

pub use convection::Convection;
pub use displacement::DisplacementField;
pub use flow_field::FlowField;
pub use phase::PhaseSnapshots;
pub use profiles::Profiles;
pub use rheology::Rheology;
pub use temperature::granular_temperature;
pub use tracer::Tracer;
pub use trajectories::Trajectories;

pub mod spacetime;
pub mod surface;
pub(crate) mod wall_table;

pub use spacetime::Spacetime;
pub use surface::{fit_line, refit_below, surface, SurfaceFit};
