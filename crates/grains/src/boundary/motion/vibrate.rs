//! The vibrating plate (Gallas, Herrmann & Sokolowski 1992): its amplitude
//! A(x), the slope of a modulated plate, and how the plate meets a grain.

use super::Motion;
use crate::dim::Dim;
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// How a plate under a modulated vibration (B ≠ 0) meets a grain.
///
/// Both readings lift the plate to z0 = A(x) sin(2π f t + phase) under the
/// grain's x and move it there at A(x) ω cos(2π f t + phase) along the
/// vibration's direction; they differ in the contact normal.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PlateSurface {
    /// The curve z0(x, t) itself: the normal leans by the local slope
    /// ∂z0/∂x (up to 13° in Gallas, Herrmann & Sokolowski 1992 Fig. 2), so
    /// the plate also pushes sideways.
    #[default]
    Curved,
    /// Gallas, Herrmann & Sokolowski's (1992) reading: under each grain a
    /// flat plate at height z0(x, t), its normal the plate's rest normal
    /// (vertical), so the plate pushes only up whatever the modulation.
    Flat,
}

impl PlateSurface {
    /// Whether this is the default reading (for serde's skip).
    pub(crate) fn is_curved(&self) -> bool {
        *self == PlateSurface::Curved
    }

    /// The slope a grain's contact sees, given the curve's slope ∂z0/∂x.
    pub(crate) fn tilt(self, slope: f64) -> f64 {
        match self {
            PlateSurface::Curved => slope,
            PlateSurface::Flat => 0.0,
        }
    }
}

impl<D: Dim> Motion<D> {
    /// Vibration: the unit direction, the amplitude A(x) and the phase angle.
    pub(super) fn vibration(&self, x: f64, t: f64) -> Option<(D::V, f64, f64, f64)> {
        if let Motion::Vibrate {
            direction,
            amplitude,
            modulation,
            wavelength,
            frequency,
            phase,
        } = self
        {
            let a = if *modulation == 0.0 {
                *amplitude
            } else {
                amplitude * (1.0 - modulation * (TAU * x / wavelength).cos())
            };
            Some((*direction, a, TAU * frequency, TAU * frequency * t + phase))
        } else {
            None
        }
    }

    /// Slope along x of the displacement of a modulated vibration,
    /// d/dx [A(x) sin(2π f t + phase)] (a length per length, times the unit
    /// `direction`); `None` for any other motion or B = 0.
    pub(crate) fn modulation_slope(&self, x: f64, t: f64) -> Option<f64> {
        match self {
            Motion::Vibrate {
                amplitude,
                modulation,
                wavelength,
                frequency,
                phase,
                ..
            } if self.is_modulated() => {
                let k = TAU / wavelength;
                let da_dx = amplitude * modulation * k * (k * x).sin();
                Some(da_dx * (TAU * frequency * t + phase).sin())
            }
            _ => None,
        }
    }

    /// Bounds, over every x and t, on a modulated vibration's displacement
    /// |A(x) sin(2π f t + phase)| ≤ |A0| (1 + |B|) and on its slope
    /// |d/dx A(x) sin(…)| ≤ |A0 B| 2π/L (both along `direction`); `None`
    /// for any other motion or B = 0.
    pub(crate) fn modulation_bounds(&self) -> Option<(f64, f64)> {
        match self {
            Motion::Vibrate {
                amplitude,
                modulation,
                wavelength,
                ..
            } if self.is_modulated() => Some((
                amplitude.abs() * (1.0 + modulation.abs()),
                (amplitude * modulation).abs() * TAU / wavelength,
            )),
            _ => None,
        }
    }

    /// Whether the displacement differs from point to point (a vibration
    /// with B ≠ 0).
    pub fn is_modulated(&self) -> bool {
        matches!(self, Motion::Vibrate { modulation, .. } if *modulation != 0.0)
    }

    /// Unit direction of a vibration (`None` for other motions).
    pub(crate) fn vibration_direction(&self) -> Option<D::V> {
        match self {
            Motion::Vibrate { direction, .. } => Some(*direction),
            _ => None,
        }
    }
}
