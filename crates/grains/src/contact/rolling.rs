//! Rolling resistance: a torque against the relative rolling of two bodies
//! in contact, limited to μ_r R* |F_n| (Ai, Chen, Rotter & Ooi 2011,
//! *Assessment of rolling resistance models in discrete element
//! simulations*, Powder Technology 206, 269).
//!
//! The relative rolling velocity at the contact is v_r = R* (ω_i − ω_j) × n
//! (Wang et al. 2015's form, which LAMMPS's `pair granular` uses); the
//! resisting "force" f_r acts along −v_r and the torque on body i is
//! R* n × f_r (the partner gets its negative). Two models:
//! - [`RollingModel::Constant`] (Ai's type A, constant directional torque):
//!   |f_r| = μ_r |F_n| whenever the bodies roll. It has no state; at rest it
//!   dithers about zero (the sign of ω flips each step), which is Ai's
//!   known drawback of type A: it stops rolling, it does not hold a slope.
//! - [`RollingModel::Epsd`] (Ai's type C, elastic–plastic spring–dashpot,
//!   LAMMPS's `rolling sds`): a spring on the integrated rolling
//!   displacement with a dashpot, the sum capped at μ_r |F_n| (the spring
//!   cut back when it slides), turned into the tangent plane each step:
//!   the Cundall–Strack algorithm of [`super::cundall_strack`] on v_r. With
//!   materials the stiffness is Ai's k_r = 2.25 μ_r² k_n R*² as a torsional
//!   stiffness, i.e. 2.25 μ_r² k_n on the displacement (k_n = 2 E* a, the
//!   Hertz contact's normal stiffness), and the dashpot is Ai's 0.3 of the
//!   critical 2 √(I_r k_r), I_r the contact's reduced moment of inertia
//!   about it (7/5 m r² per sphere).

use super::contract::Step;
use super::cundall_strack::Tangential;
use crate::dim::Dim;
use serde::{Deserialize, Serialize};

/// Which rolling resistance a scenario's contacts have.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum RollingModel {
    #[default]
    None,
    /// Ai's type A: a constant torque μ_r R* |F_n| against the rolling.
    Constant,
    /// Ai's type C: elastic–plastic spring–dashpot.
    Epsd,
}

impl RollingModel {
    pub fn name(self) -> &'static str {
        match self {
            Self::None => "none",
            Self::Constant => "constant",
            Self::Epsd => "epsd",
        }
    }

    /// Whether each contact keeps a rolling spring.
    pub fn has_history(self) -> bool {
        self == Self::Epsd
    }
}

/// Ai's critical damping ratio of the rolling dashpot.
pub const EPSD_DAMPING_RATIO: f64 = 0.3;

/// The rolling parameters of one contact, already resolved for its
/// geometry and normal force.
#[derive(Clone, Copy, Debug)]
pub struct RollingContact {
    /// R*.
    pub r_star: f64,
    /// μ_r |F_n|: the largest rolling "force" (the torque over R*).
    pub cap: f64,
    /// Spring stiffness on the rolling displacement (epsd only).
    pub k: f64,
    /// Dashpot on the rolling velocity (epsd only).
    pub gamma: f64,
}

/// The rolling torque on body i for relative spin `omega_rel` = ω_i − ω_j
/// and unit normal `n` (from the partner to i). `MODEL` is
/// [`RollingModel::Constant`] or [`RollingModel::Epsd`] as a number (1,
/// 2), so that the choice folds away in the compiled kernel; `spring` is
/// the epsd model's rolling displacement, advanced when `step.update`.
/// Written with selections, not branches, for the batched lanes.
#[inline(always)]
pub fn rolling_torque<D: Dim, const MODEL: u8>(
    omega_rel: D::A,
    n: D::V,
    c: RollingContact,
    spring: &mut D::V,
    step: Step,
) -> D::A {
    let vr = D::ang_cross(omega_rel, n) * c.r_star;
    let fr = if MODEL == 2 {
        Tangential {
            kt: c.k,
            gamma: c.gamma,
            mu: 1.0,
        }
        .force::<D>(spring, vr, n, c.cap, step, true)
    } else {
        let v2 = D::norm2(vr);
        let scale = if v2 > 0.0 { c.cap / v2.sqrt() } else { 0.0 };
        -(vr * scale)
    };
    D::torque(n, fr) * c.r_star
}

/// The epsd dashpot 0.3 · 2 √(I_r k_r) on the rolling displacement's
/// scale: γ = 0.6 √(I_r k) / R* with I_r the reduced 7/5 m r² of the two
/// bodies (a wall or frozen grain: infinitely heavy).
#[inline(always)]
pub fn epsd_damping(k: f64, (mi, ri): (f64, f64), (mj, rj): (f64, f64), r_star: f64) -> f64 {
    let ii = 1.4 * mi * ri * ri;
    let ij = 1.4 * mj * rj * rj;
    // 1/(1/a + 1/b) stays finite when one side is infinite.
    let i_r = 1.0 / (1.0 / ii + 1.0 / ij);
    2.0 * EPSD_DAMPING_RATIO * (i_r * k).sqrt() / r_star
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::{D2, D3};
    use glam::{DVec2, DVec3};

    fn step() -> Step {
        Step {
            dt: 1e-3,
            update: true,
        }
    }

    /// A sphere on a floor (n = +z) spinning about +y rolls towards +x:
    /// both models resist with a torque about −y, the constant one of
    /// exactly μ_r R* |F_n|.
    #[test]
    fn torque_opposes_rolling_3d() {
        let c = RollingContact {
            r_star: 0.5,
            cap: 2.0,
            k: 100.0,
            gamma: 0.0,
        };
        let mut s = DVec3::ZERO;
        let w = DVec3::new(0.0, 3.0, 0.0);
        let t = rolling_torque::<D3, 1>(w, DVec3::Z, c, &mut s, step());
        assert!((t - DVec3::new(0.0, -1.0, 0.0)).length() < 1e-15, "{t}");
        // Twisting about the normal is not rolling.
        let t = rolling_torque::<D3, 1>(DVec3::Z, DVec3::Z, c, &mut s, step());
        assert_eq!(t, DVec3::ZERO);
        // epsd: the spring stretched by v_r dt = 0.5 · 3 · 1e-3 along +x
        // gives k δ = 0.15, torque 0.5 · 0.15 about −y.
        let t = rolling_torque::<D3, 2>(w, DVec3::Z, c, &mut s, step());
        assert!((s - DVec3::new(1.5e-3, 0.0, 0.0)).length() < 1e-15);
        assert!((t - DVec3::new(0.0, -0.075, 0.0)).length() < 1e-14, "{t}");
        // Stretched past the limit it gives μ_r R* |F_n| and is cut back.
        let mut s = DVec3::new(1.0, 0.0, 0.0);
        let t = rolling_torque::<D3, 2>(w, DVec3::Z, c, &mut s, step());
        assert!((t.length() - 1.0).abs() < 1e-14);
        assert!((s.length() - 0.02).abs() < 1e-14, "{s}");
    }

    /// A disk on a floor (n = +y) spinning clockwise (ω_z < 0) rolls
    /// towards +x; the torque is counter-clockwise.
    #[test]
    fn torque_opposes_rolling_2d() {
        let c = RollingContact {
            r_star: 0.5,
            cap: 2.0,
            k: 0.0,
            gamma: 0.0,
        };
        let mut s = DVec2::ZERO;
        let t = rolling_torque::<D2, 1>(-3.0, DVec2::Y, c, &mut s, step());
        assert!((t - 1.0).abs() < 1e-15, "{t}");
        assert_eq!(
            rolling_torque::<D2, 1>(0.0, DVec2::Y, c, &mut s, step()),
            0.0
        );
    }

    #[test]
    fn damping_of_a_sphere_on_a_wall() {
        // I_r = 1.4 m r² against an infinitely heavy wall.
        let g = epsd_damping(4.0, (1.0, 0.5), (f64::INFINITY, f64::INFINITY), 0.5);
        let want = 0.6 * (1.4f64 * 0.25 * 4.0).sqrt() / 0.5;
        assert!((g - want).abs() < 1e-15);
    }
}
