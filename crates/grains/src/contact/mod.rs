//! Contact laws between grains, and between a grain and a wall.
//!
//! A contact force is composed of three parts, each in its own file:
//! - [`normal_power_law`]: the elastic repulsion k_n ξ^β (β = 1 Hooke,
//!   3/2 Hertz, 2 conical, any β > 0);
//! - [`damping`]: viscous normal dissipation γ_n and viscous shear friction γ_t;
//! - [`cundall_strack`]: the tangential spring with its Coulomb cap μ|F_n|.
//!
//! [`mass_scaling`] says how the coefficients meet the masses (the seeds'
//! "normalized by the mass" or the momentum-conserving reduced mass), and
//! [`law::ContactLaw`] puts the parts together. [`binary`] has the closed
//! forms of a two-grain collision that the tests and the automatic time step use.
//! [`hooke_history`] is the LAMMPS-shaped law fixed at compile time, for the
//! pair loop, and [`hooke_lanes`] the same law over batches of contacts in
//! component rows, which the compiler vectorizes.

pub mod binary;
pub mod cundall_strack;
pub mod damping;
pub mod hooke_history;
pub mod hooke_lanes;
pub mod law;
pub mod mass_scaling;
pub mod normal_power_law;

pub use law::{ContactLaw, ContactOutcome};
pub use mass_scaling::MassScaling;
