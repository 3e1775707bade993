//! Contact laws between grains, and between a grain and a wall.
//!
//! A contact force is composed of three parts, each in its own file:
//! - [`normal_power_law`]: the elastic repulsion k_n ξ^β (β = 1 Hooke,
//!   3/2 Hertz, 2 conical, any β > 0);
//! - [`damping`]: viscous normal dissipation γ_n and viscous shear friction γ_t;
//! - [`cundall_strack`]: the tangential spring with its Coulomb cap μ|F_n|.
//!
//! Materials ([`material`]: moduli, restitution, friction and their mixing
//! rules) give the Hertz–Mindlin law ([`hertz_mindlin`], with the damping of
//! [`tsuji_damping`]).
//!
//! [`rolling`] adds rolling resistance to the material law, [`cohesion`]
//! the DMT pull, [`jkr`] the JKR adhesion with its hysteresis.
//! [`lammps_granular`] is LAMMPS's `pair granular` with
//! `hertz/material`, `tsuji`, `mindlin` and `rolling sds` on the same
//! materials (`contact.preset = "lammps-granular"`).
//!
//! [`mass_scaling`] says how the coefficients meet the masses (the seeds'
//! "normalized by the mass" or the momentum-conserving reduced mass), and
//! [`law`] puts the parts together, once. [`contract`] is what every law
//! offers the loops ([`ContactModel`], one contact's [`Contact`] in).
//! [`hooke_history`] is the LAMMPS-shaped law with its choices fixed at
//! compile time, and [`lanes`] runs any law written for it over batches of
//! contacts in component rows, which the compiler vectorizes. [`binary`]
//! has the closed forms of a two-grain collision that the tests and the
//! automatic time step use.
//!
//! A run holds one [`Law`] ([`choice`]), a registered law ([`registered`]:
//! the spring–dashpot coefficients or a material law), and every loop gets
//! its compiled kernel from [`Law::with_kernel`].

pub mod binary;
pub mod choice;
pub mod cohesion;
pub mod contract;
pub mod cundall_strack;
pub mod damping;
pub mod hertz_mindlin;
pub mod hooke_history;
pub mod jkr;
pub mod lammps_granular;
pub mod lanes;
pub mod law;
pub mod mass_scaling;
pub mod material;
pub mod normal_power_law;
pub mod registered;
pub mod rolling;
pub mod tsuji_damping;

pub use choice::Law;
pub use contract::{Contact, ContactModel, ContactOutcome, Step};
pub use law::ContactLaw;
pub use mass_scaling::MassScaling;
pub use registered::{Registered, RunLaw};
