//! The contract every contact law meets: one contact's geometry and
//! velocities in, the force on the first body and its tangential part out.
//!
//! The pair loop (one contact at a time, or in batches of lanes), the wall
//! contacts and the contact list all call a law through [`ContactModel`];
//! a new law implements it once and runs on every path.

use crate::dim::Dim;

/// One contact as a law sees it: body i (a grain) against its partner (a
/// grain or a wall).
#[derive(Clone, Copy, Debug)]
pub struct Contact<D: Dim> {
    /// Overlap ξ = r_i + r_j − |x_i − x_j| > 0 (against a wall: r_i minus
    /// the distance to it); down to −[`ContactModel::reach`] for a kept
    /// contact of a `BONDED` law.
    pub overlap: f64,
    /// Unit normal from the partner to body i.
    pub normal: D::V,
    /// Velocity of i's contact point minus the partner's.
    pub v_rel: D::V,
    /// Masses; ∞ for a frozen grain or a wall.
    pub mi: f64,
    pub mj: f64,
    /// Radii; ∞ for a wall (flat).
    pub ri: f64,
    pub rj: f64,
    /// ω_i − ω_j (ω_i against a wall); zero without rotation. Read by
    /// rolling resistance only.
    pub omega_rel: D::A,
    /// The pair's entry in the law's table of coefficients
    /// ([`ContactModel::pair_index`]); 0 for a law of one pair.
    pub pair: u32,
}

/// How far time advances in this evaluation.
#[derive(Clone, Copy, Debug)]
pub struct Step {
    pub dt: f64,
    /// Whether the contact's history (springs) advances; false when forces
    /// are evaluated without time advancing (the start of a run, the
    /// contact list).
    pub update: bool,
}

/// What one contact evaluation produced, before the mass factor of
/// [`ContactModel::force_factor`] is applied.
#[derive(Clone, Copy, Debug)]
pub struct ContactOutcome<D: Dim> {
    /// Force on body i (the partner gets minus this, times its own factor).
    pub force: D::V,
    /// The tangential part of `force`, for torques.
    pub tangential: D::V,
    /// The normal load the Coulomb caps scale: F_n along the normal, plus
    /// twice the pull-off force under cohesion (LAMMPS's `Fncrit`).
    pub normal_force: f64,
}

/// A contact law.
pub trait ContactModel: Sync {
    /// Whether the law runs on the batched lanes of the pair loop: written
    /// without branches that keep the compiler from vectorizing it.
    const LANES: bool = false;

    /// Whether the law's coefficients come from a table indexed by
    /// [`Contact::pair`] (materials): the lanes then fix the entry of a
    /// batch whose contacts share one, so that the loads leave the loop.
    const PAIR_TABLE: bool = false;

    /// Whether the law has a rolling torque ([`ContactModel::rolling`]).
    const ROLLING: bool = false;
    /// Whether that torque keeps a rolling spring per contact.
    const ROLLING_HISTORY: bool = false;

    /// Whether a contact, once formed, is kept beyond touching, while the
    /// surfaces are less than [`ContactModel::reach`] apart (JKR). The
    /// loops mark such a contact in its rolling slot (a law with it keeps
    /// no rolling spring).
    const BONDED: bool = false;

    /// How far apart (a negative overlap's size) a formed contact of table
    /// entry `pair` between radii `ri` and `rj` (∞ for a wall) is kept;
    /// read only when `BONDED`.
    #[inline(always)]
    fn reach(&self, _pair: u32, _ri: f64, _rj: f64) -> f64 {
        0.0
    }

    /// Whether grains rotate (torques, ω in the contact-point velocity).
    fn rotation(&self) -> bool;

    /// Factor turning the law's force into the force on a body of mass `m`
    /// (the seeds' mass-normalized coefficients multiply by it).
    fn force_factor(&self, m: f64) -> f64;

    /// The entry of the coefficient table for grains of kinds `kind_i` and
    /// `kind_j` (their materials); laws of one pair need none.
    #[inline(always)]
    fn pair_index(&self, _kind_i: u32, _kind_j: u32) -> u32 {
        0
    }

    /// The entry for a grain of kind `kind_i` against wall `wall`.
    #[inline(always)]
    fn wall_pair_index(&self, _kind_i: u32, _wall: usize) -> u32 {
        0
    }

    /// The lever arm of the tangential force's torque on a body of radius
    /// `r` at overlap `overlap`: r (the default), or LAMMPS `pair
    /// granular`'s r − ξ/2.
    #[inline(always)]
    fn lever(&self, r: f64, _overlap: f64) -> f64 {
        r
    }

    /// The law an elastic wall (`contact.elastic_walls`) meets grains
    /// with: this one less its normal damping; `None` for this law itself
    /// (a material law's walls take their restitution from their material).
    #[inline(always)]
    fn elastic_wall(&self) -> Option<Self>
    where
        Self: Sized,
    {
        None
    }

    /// Evaluates one contact; `spring` is its tangential history (the
    /// displacement of i relative to the partner), advanced when
    /// `step.update`.
    fn evaluate<D: Dim>(&self, c: &Contact<D>, spring: &mut D::V, step: Step) -> ContactOutcome<D>;

    /// The rolling-resistance torque on body i (the partner gets minus
    /// it), given what [`ContactModel::evaluate`] returned; `spring` is the
    /// contact's rolling history (used when `ROLLING_HISTORY`). Called
    /// only when `ROLLING`.
    #[inline(always)]
    fn rolling<D: Dim>(
        &self,
        _c: &Contact<D>,
        _out: &ContactOutcome<D>,
        _spring: &mut D::V,
        _step: Step,
    ) -> D::A {
        D::A::default()
    }
}
