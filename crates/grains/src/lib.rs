//! grains: granular dynamics in 2D and 3D.
//!
//! Soft-sphere molecular dynamics (DEM) of polydisperse disks and spheres
//! after Gallas, Herrmann & Sokolowski and Herrmann & Müller. See
//! `ARCHITECTURE.md` at the repository root for how the modules fit.

pub mod boundary;
pub mod checkpoint;
pub mod codec;
pub mod comm;
pub mod contact;
pub mod dim;
pub mod domain;
pub mod dsmc;
pub mod engine;
pub mod error;
pub mod gpu;
pub mod integrate;
pub mod io;
pub mod md;
pub mod measure;
pub mod neighbors;
pub mod output;
pub mod parallel;
pub mod particles;
pub mod render;
pub mod rigid;
pub mod run_dir;
pub mod runner;
pub mod scenario;
pub mod session;
pub mod settings;
pub mod simd;
pub mod view;

pub use dim::{Dim, D2, D3};
pub use domain::Domain;
pub use error::{Error, Result};
pub use particles::{MassModel, ParticleRecord, Particles};
