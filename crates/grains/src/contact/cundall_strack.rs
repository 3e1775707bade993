//! Static friction: the Cundall–Strack tangential spring with a Coulomb cap.
//!
//! The spring δs integrates the tangential relative velocity over the whole
//! life of a contact and is dropped when the contact opens. Each step the
//! increment is added first and the spring is then projected back into the
//! current tangent plane (so it turns with the contact); the tangential force
//! −(k_t δs + γ_t v_t) is capped at μ|F_n|, and when it slides the spring is
//! cut back to the length that gives exactly the capped force. This ordering
//! is LAMMPS's `gran/hooke/history`, which the shared benchmarks are checked
//! against.

use super::contract::Step;
use crate::dim::Dim;

/// Parameters of the tangential contact, with damping already multiplied by
/// its mass factor.
#[derive(Clone, Copy, Debug)]
pub struct Tangential {
    pub kt: f64,
    /// γ_t times the damping mass.
    pub gamma: f64,
    pub mu: f64,
}

impl Tangential {
    /// Tangential force on grain i for tangential contact velocity `vt`,
    /// normal `n` (unit) and normal force magnitude `fn_abs`. Updates the
    /// spring when `update` (false when forces are evaluated without time
    /// advancing, as at the start of a run).
    ///
    /// `known` says the caller's law always has a spring (k_t > 0) and a
    /// finite cap, so the tests for them fold away. The sliding case is a
    /// selection, not a branch (both outcomes computed, one kept), so that
    /// the batched lanes vectorize it; a law without a cap returns before
    /// any of it.
    #[inline(always)]
    pub fn force<D: Dim>(
        &self,
        spring: &mut D::V,
        vt: D::V,
        n: D::V,
        fn_abs: f64,
        step: Step,
        known: bool,
    ) -> D::V {
        let has_spring = known || self.kt > 0.0;
        if has_spring && step.update {
            *spring += vt * step.dt;
            let along_normal = D::dot(*spring, n);
            *spring -= n * along_normal;
        }
        let fs = -(*spring * self.kt + vt * self.gamma);
        if !(known || self.mu.is_finite()) {
            return fs;
        }
        let cap = self.mu * fn_abs;
        let fs2 = D::norm2(fs);
        let sliding = fs2 > cap * cap;
        let scale = cap / fs2.sqrt();
        // Sliding: the spring cut back to the length that gives the capped
        // force; a spring of length zero gives no force at all.
        let s2 = D::norm2(*spring);
        let cut = sliding && has_spring && s2 != 0.0;
        let kill = sliding && has_spring && s2 == 0.0;
        let damp = vt * (self.gamma / self.kt);
        let cut_spring = (*spring + damp) * scale - damp;
        *spring = if cut { cut_spring } else { *spring };
        let capped = if sliding { fs * scale } else { fs };
        if kill {
            D::zero()
        } else {
            capped
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::D3;
    use glam::DVec3;

    fn step(dt: f64) -> Step {
        Step { dt, update: true }
    }

    #[test]
    fn spring_stays_in_tangent_plane() {
        let t = Tangential {
            kt: 10.0,
            gamma: 0.0,
            mu: f64::INFINITY,
        };
        let mut s = DVec3::new(0.0, 0.0, 0.0);
        let n = DVec3::new(0.0, 0.0, 1.0);
        let f = t.force::<D3>(&mut s, DVec3::new(1.0, 0.0, 0.0), n, 1.0, step(0.1), false);
        assert_eq!(s, DVec3::new(0.1, 0.0, 0.0));
        assert_eq!(f, DVec3::new(-1.0, 0.0, 0.0));
        // The contact turns: the spring is projected onto the new plane.
        let n2 = DVec3::new(1.0, 0.0, 1.0).normalize();
        t.force::<D3>(&mut s, DVec3::ZERO, n2, 1.0, step(0.1), false);
        assert!(s.dot(n2).abs() < 1e-15);
    }

    #[test]
    fn coulomb_cap_cuts_spring_back() {
        let t = Tangential {
            kt: 100.0,
            gamma: 0.0,
            mu: 0.5,
        };
        let mut s = DVec3::new(0.05, 0.0, 0.0);
        let n = DVec3::Z;
        // Spring force 5 exceeds the cap 0.5 * 2 = 1.
        let f = t.force::<D3>(&mut s, DVec3::ZERO, n, 2.0, step(0.1), false);
        assert!((f.length() - 1.0).abs() < 1e-14);
        assert!((s.length() - 0.01).abs() < 1e-15);
    }
}
