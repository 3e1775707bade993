//! What a contact law offers the registry of [`super::choice`]: its
//! compiled kernel handed to whatever runs contacts, and the few facts the
//! engine asks of it outside the contact loops.

use super::cohesion::CohesionModel;
use super::contract::ContactModel;
use super::law::ContactLaw;
use super::rolling::RollingModel;
use crate::error::Result;

/// Something to run with a contact law's compiled kernel: the pair loop,
/// the wall and mesh contacts, the contact list. A closure cannot be
/// generic over the kernel's type, so this trait stands in for one; `run`
/// is monomorphized per kernel, and each contact calls the law statically.
pub trait RunLaw<R> {
    fn run<L: ContactModel>(self, law: &L) -> R;
}

/// A law as a run holds it, registered in [`super::choice::Law`].
pub trait Registered {
    /// Hands `run` the law's kernel, its choices (rolling, cohesion, the
    /// shape of its coefficients) fixed at compile time.
    fn with_kernel<R>(&self, run: impl RunLaw<R>) -> R;

    /// Whether grains rotate (torques, ω in the contact-point velocity).
    fn rotation(&self) -> bool;

    /// The spring–dashpot coefficients the time step was estimated from
    /// (the law itself, or a stand-in of its stiffness), for the advice on
    /// dt and the checkpoint's fingerprint.
    fn estimate(&self) -> &ContactLaw;

    /// Refuses a run the law cannot serve, with grains up to `max_radius`
    /// and the Verlet skin `skin`.
    fn check(&self, _max_radius: f64, _skin: f64) -> Result<()> {
        Ok(())
    }

    /// The rolling resistance.
    fn rolling(&self) -> RollingModel {
        RollingModel::None
    }

    /// The cohesion.
    fn cohesion(&self) -> CohesionModel {
        CohesionModel::None
    }

    /// Whether contacts keep a second history (a rolling spring, a JKR
    /// contact's mark) in the rolling slots.
    fn keeps_second_history(&self) -> bool {
        false
    }
}
