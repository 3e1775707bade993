//! Rigid clumps from the scenario's side (docs/clumps.md): a shape's mass
//! properties against closed forms, random orientations uniform on
//! rotations, bodies placed without overlaps and in a mixture's numbers,
//! and the refusals of bad input by key.

mod engine;
mod errors;
mod mass;
mod orientation;
mod placement;
mod shipped;
