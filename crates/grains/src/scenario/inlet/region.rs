//! An inlet's region: a box, or a vertical cylinder (a band in 2D), and
//! centres drawn uniformly inside it for grains that must fit wholly.

use super::super::keys::vector;
use super::super::schema::InletRegion;
use crate::dim::Dim;
use crate::error::{Error, Result};
use rand::Rng;

/// Where an inlet's grain centres are drawn.
#[derive(Clone, Debug)]
pub(super) enum Region<D: Dim> {
    Box {
        lo: D::V,
        hi: D::V,
    },
    /// A vertical cylinder (3D) or a band |x − c| < R (2D) between two
    /// heights.
    Cylinder {
        center: [f64; 2],
        radius: f64,
        bottom: f64,
        top: f64,
    },
}

impl<D: Dim> Region<D> {
    pub(super) fn new(spec: &InletRegion, key: &str) -> Result<Self> {
        Ok(match spec {
            InletRegion::Box { lo, hi } => {
                let lo = vector::<D>(&format!("{key}.lo"), lo)?;
                let hi = vector::<D>(&format!("{key}.hi"), hi)?;
                if (0..D::D).any(|a| D::get(hi, a) <= D::get(lo, a)) {
                    return Err(Error::input(format!(
                        "{key}: hi must exceed lo on every axis"
                    )));
                }
                Region::Box { lo, hi }
            }
            InletRegion::Cylinder {
                center,
                radius,
                bottom,
                top,
            } => {
                if center.len() != D::D - 1 || center.iter().any(|c| !c.is_finite()) {
                    return Err(Error::input(format!(
                        "{key}.center must be {} finite number(s): the axis's horizontal position",
                        D::D - 1
                    )));
                }
                if !(radius.is_finite() && *radius > 0.0) {
                    return Err(Error::input(format!(
                        "{key}.radius = {radius}: must be a positive length in metres"
                    )));
                }
                if !(bottom.is_finite() && top.is_finite() && top > bottom) {
                    return Err(Error::input(format!(
                        "{key}: top = {top} must exceed bottom = {bottom}"
                    )));
                }
                let mut c = [0.0; 2];
                c[..center.len()].copy_from_slice(center);
                Region::Cylinder {
                    center: c,
                    radius: *radius,
                    bottom: *bottom,
                    top: *top,
                }
            }
        })
    }

    /// The box around the region.
    pub(super) fn bounds(&self) -> (D::V, D::V) {
        match self {
            Region::Box { lo, hi } => (*lo, *hi),
            Region::Cylinder {
                center,
                radius,
                bottom,
                top,
            } => {
                let (mut lo, mut hi) = (D::zero(), D::zero());
                for (a, c) in center.iter().enumerate().take(D::D - 1) {
                    D::set(&mut lo, a, c - radius);
                    D::set(&mut hi, a, c + radius);
                }
                D::set(&mut lo, D::vertical(), *bottom);
                D::set(&mut hi, D::vertical(), *top);
                (lo, hi)
            }
        }
    }

    /// Whether a grain of radius `r` fits wholly inside.
    pub(super) fn fits(&self, r: f64) -> bool {
        let (lo, hi) = self.bounds();
        (0..D::D).all(|a| D::get(hi, a) - D::get(lo, a) > 2.0 * r)
    }

    /// A centre drawn uniformly among those that keep a grain of radius
    /// `r` inside (the caller checked [`Region::fits`]).
    pub(super) fn draw(&self, r: f64, rng: &mut impl Rng) -> D::V {
        let mut p = D::zero();
        match self {
            Region::Box { lo, hi } => {
                for a in 0..D::D {
                    let (l, h) = (D::get(*lo, a) + r, D::get(*hi, a) - r);
                    D::set(&mut p, a, l + rng.gen::<f64>() * (h - l));
                }
            }
            Region::Cylinder {
                center,
                radius,
                bottom,
                top,
            } => {
                let reach = radius - r;
                if D::D == 2 {
                    D::set(
                        &mut p,
                        0,
                        center[0] + reach * (2.0 * rng.gen::<f64>() - 1.0),
                    );
                } else {
                    // Uniform over the disc: radius ∝ √u.
                    let rho = reach * rng.gen::<f64>().sqrt();
                    let phi = std::f64::consts::TAU * rng.gen::<f64>();
                    D::set(&mut p, 0, center[0] + rho * phi.cos());
                    D::set(&mut p, 1, center[1] + rho * phi.sin());
                }
                let (l, h) = (bottom + r, top - r);
                D::set(&mut p, D::vertical(), l + rng.gen::<f64>() * (h - l));
            }
        }
        p
    }
}
