//! Constant pressure on a sheared box's gradient axis: the box length L_g
//! follows the measured normal stress σ_gg, the grains rescaled affinely.
//!
//! Every `every` steps, at the end of the step (after the corrector, where
//! a run's hooks read the grains), the barostat reads σ_gg as
//! `measure::rheology` does, the virial stress over the box volume V,
//! compression positive, σ_gg = (Σ_grains m v_g² + Σ_contacts r_g f_g) / V
//! (the mean shear flow runs along the shear axis, so v_g needs no
//! subtraction), and stretches the box by 1 + ε with
//!
//!   ε = clamp((σ_gg − P) / P · every · dt / τ_p, ±[`MAX_STRAIN`]),
//!
//! the explicit step of dL/dt = L (σ_gg − P) / (P τ_p). A box squeezed
//! harder than P grows, one squeezed less shrinks; in a steady state L
//! stops drifting, so σ_gg averaged over the barostat's readings is P
//! (less τ_p ln(L_end / L_start) / T over a run of length T). The grains'
//! positions along g map as y → lo + (y − lo)(1 + ε), the images with the
//! box; their velocities are kept. Near the stress the box is stable when
//! ε per reading stays below the packing's elastic response:
//! every · dt / τ_p ≪ P / K for a bulk stiffness K.
//!
//! The neighbour list is rebuilt at every box change (its image shifts
//! hold L_g), so no pair is lost whatever the change; the sliding images'
//! offset is carried on continuously ([`crate::domain::Domain::stretch_gradient`]).

use super::Md;
use crate::dim::Dim;
use crate::error::{Error, Result};

/// The largest relative change of the box length at one reading: far
/// from the set pressure (a loose start) the box closes at 10⁻³ per
/// reading rather than at the rate the law asks.
pub const MAX_STRAIN: f64 = 1e-3;

/// The pressure control of a sheared box (`domain.shear.pressure`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Barostat {
    /// The normal stress P to hold on the gradient axis.
    pub pressure: f64,
    /// Relaxation time τ_p of the box length.
    pub relax_time: f64,
    /// Steps between readings.
    pub every: u64,
}

impl Barostat {
    /// The box's relative stretch ε for the normal stress `sigma` read now.
    pub fn strain(&self, sigma: f64, dt: f64) -> f64 {
        let rate = (sigma - self.pressure) / (self.pressure * self.relax_time);
        (rate * (self.every as f64 * dt)).clamp(-MAX_STRAIN, MAX_STRAIN)
    }
}

impl<D: Dim> Md<D> {
    /// The normal stress σ_aa of the box along `axis` now: the virial of
    /// the grain–grain contacts and the grains' momentum flux (mobile
    /// grains, velocities as they are), over the box volume, compression
    /// positive.
    pub fn normal_stress(&self, axis: usize) -> f64 {
        let p = &self.particles;
        let mut s = 0.0;
        for i in 0..p.n_owned() {
            if !p.frozen[i] {
                let v = D::get(p.vel[i], axis);
                s += p.mass[i] * v * v;
            }
        }
        let c = self.contact_list();
        for (r, f) in c.branch.iter().zip(&c.force) {
            s += D::get(*r, axis) * D::get(*f, axis);
        }
        s / self.domain.volume()
    }

    /// Whether the barostat reads the stress at the end of this step.
    pub(super) fn barostat_due(&self) -> bool {
        self.settings
            .barostat
            .is_some_and(|b| self.step.is_multiple_of(b.every.max(1)))
    }

    /// Steps from now to the barostat's next reading (`None`: no barostat).
    pub(super) fn steps_to_barostat(&self) -> Option<u64> {
        let every = self.settings.barostat?.every.max(1);
        Some(every - self.step % every)
    }

    /// Reads σ_gg and stretches the box and the grains along the gradient
    /// axis, then rebuilds the neighbour list for the new box.
    pub(super) fn apply_barostat(&mut self) -> Result<()> {
        let (Some(b), Some(shear)) = (self.settings.barostat, self.domain.shear) else {
            return Ok(());
        };
        let g = shear.gradient;
        let sigma = self.normal_stress(g);
        if !sigma.is_finite() {
            return Err(Error::Unstable(format!(
                "at step {} the normal stress on the gradient axis is {sigma}: \
                 the fixed-pressure box cannot follow it",
                self.step
            )));
        }
        let factor = 1.0 + b.strain(sigma, self.settings.dt);
        let lo = D::get(self.domain.lo, g);
        let n = self.particles.n_owned();
        for x in &mut self.particles.pos[..n] {
            let y = D::get(*x, g);
            D::set(x, g, lo + (y - lo) * factor);
        }
        self.domain.stretch_gradient(factor, self.time);
        self.rebuild_neighbors()
    }

    /// The box along the gradient axis as a checkpoint keeps it under a
    /// barostat: its upper bound and slide origin (t_0, Δ_0).
    pub(super) fn pressure_box(&self) -> Option<[f64; 3]> {
        let shear = self.domain.shear?;
        self.settings.barostat?;
        let [since, base] = self.domain.slide_origin;
        Some([D::get(self.domain.hi, shear.gradient), since, base])
    }

    /// Checks a box saved by [`Md::pressure_box`] against the scenario's.
    pub(super) fn check_pressure_box(&self, saved: [f64; 3]) -> Result<()> {
        let Some(shear) = self.domain.shear else {
            return Err(Error::input(
                "checkpoint state: a fixed-pressure box, but the scenario's box is not sheared",
            ));
        };
        let hi = saved[0];
        let finite = saved.iter().all(|x| x.is_finite());
        if !(finite && hi > D::get(self.domain.lo, shear.gradient)) {
            return Err(Error::input(format!(
                "checkpoint state: the fixed-pressure box {saved:?} (upper bound on the \
                 gradient axis, slide origin) is not a finite box above its lower bound"
            )));
        }
        Ok(())
    }

    /// Puts back a box checked by [`Md::check_pressure_box`], after the
    /// neighbour list (whose jump and slide origin follow it).
    pub(super) fn set_pressure_box(&mut self, saved: [f64; 3]) {
        let Some(shear) = self.domain.shear else {
            return;
        };
        let [hi, since, base] = saved;
        D::set(&mut self.domain.hi, shear.gradient, hi);
        self.domain.slide_origin = [since, base];
        self.neighbors.follow_box(&self.domain);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The law's step and its cap: 5 % over P with every · dt / τ_p = 10⁻³
    /// stretches the box by 5 × 10⁻⁵ (5 % under shrinks it as much), and a
    /// box far from P moves at the cap.
    #[test]
    fn strain_follows_the_law_and_its_cap() {
        let b = Barostat {
            pressure: 100.0,
            relax_time: 1.0,
            every: 10,
        };
        let dt = 1e-4;
        // (105 − 100) / 100 × 10⁻³ = 5 × 10⁻⁵.
        assert!((b.strain(105.0, dt) - 5e-5).abs() < 1e-18);
        assert!((b.strain(95.0, dt) + 5e-5).abs() < 1e-18);
        assert_eq!(b.strain(0.0, 1.0), -MAX_STRAIN);
        assert_eq!(b.strain(1e9, 1.0), MAX_STRAIN);
    }
}
