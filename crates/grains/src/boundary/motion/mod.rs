//! Prescribed wall motions: the wall's pose and velocity field at time t.
//! Walls are driven: the motion does not respond to the grains, except a
//! servo's, which moves by the load the grains put on it.
//!
//! The enum and what every kind answers are here; the vibrating plate's
//! own computations in `vibrate`, the servo's control in `servo`, the rigid
//! placement in `pose`.

mod pose;
mod servo;
mod vibrate;

use super::geom::{from3, to3};
use crate::dim::Dim;
use glam::{DQuat, DVec3};
pub(crate) use pose::Pose;
use serde::{Deserialize, Serialize};
pub use servo::ServoState;
use std::f64::consts::TAU;
pub use vibrate::PlateSurface;

/// How a wall moves in time. Times in seconds, frequencies in Hz.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(
    tag = "type",
    rename_all = "lowercase",
    bound(
        serialize = "D::V: Serialize, D::A: Serialize",
        deserialize = "D::V: Deserialize<'de>, D::A: Deserialize<'de>"
    )
)]
pub enum Motion<D: Dim> {
    /// The wall stays where it is.
    #[default]
    Fixed,
    /// Each point of the wall moves along `direction` (unit) with
    /// A(x) = A0 (1 − B cos(2π x_h / L)) sin(2π f t + phase), x_h the
    /// coordinate of the point along axis 0 (x): Gallas, Herrmann &
    /// Sokolowski 1992 eqs. (2)-(3), with A0 = `amplitude`, B =
    /// `modulation`, L = `wavelength`, f = `frequency`.
    /// B = 0 is a rigid plate.
    ///
    /// With B ≠ 0 the wall must be a plane whose normal is perpendicular to
    /// x: its surface is then the curve (3D: the ridged sheet) z0(x, t), whose
    /// normal tilts by the local slope ∂z0/∂x (up to 13° in Gallas, Herrmann
    /// & Sokolowski 1992 Fig. 2), so the plate also pushes sideways. See
    /// `lifted_plane` in `boundary/flat.rs`. The velocity is taken at the contact point's x.
    Vibrate {
        direction: D::V,
        amplitude: f64,
        modulation: f64,
        wavelength: f64,
        frequency: f64,
        phase: f64,
    },
    /// Elliptic (conveyor-belt) motion of the whole wall: displacement
    /// `amplitude · sin(2π f t + phase)` (Gallas, Herrmann & Sokolowski 1992
    /// eq. 4: x = A_x sin, z = A_z sin).
    /// Along an infinite plane the in-plane part changes only the velocity.
    Oscillate {
        amplitude: D::V,
        frequency: f64,
        phase: f64,
    },
    /// Rigid rotation with angular velocity `omega` about `center` (in 3D
    /// about the axis through `center` along `omega`), starting at t = 0.
    /// A shape symmetric about that axis (a drum about its own axis) keeps its
    /// geometry, but its surface moves with velocity ω × (x − center).
    Rotate { center: D::V, omega: D::A },
    /// Constant velocity, starting from the reference position at t = 0.
    Translate { velocity: D::V },
    /// A plane moved along its unit `normal` (the plane's, set by
    /// [`super::Wall::new`]) to hold the normal stress `pressure` (Pa; 2D
    /// N/m) on `area` (m²; 2D m), at speed g (P_target − P) capped at
    /// `max_speed`, from time `start` on (`servo.rs`).
    Servo {
        #[serde(skip)]
        normal: D::V,
        pressure: f64,
        gain: f64,
        max_speed: f64,
        area: f64,
        start: f64,
        /// Where the wall is and how it moves, from step to step.
        #[serde(skip)]
        state: ServoState,
    },
}

fn check_finite(x: f64, what: &str) -> Result<(), String> {
    if x.is_finite() {
        Ok(())
    } else {
        Err(format!("{what} is not finite"))
    }
}

fn check_frequency(f: f64) -> Result<(), String> {
    if f.is_finite() && f >= 0.0 {
        Ok(())
    } else {
        Err(format!("frequency must be >= 0 and finite, got {f}"))
    }
}

impl<D: Dim> Motion<D> {
    /// A short name of the motion kind, for messages.
    pub fn kind(&self) -> &'static str {
        match self {
            Motion::Fixed => "fixed",
            Motion::Vibrate { .. } => "vibrate",
            Motion::Oscillate { .. } => "oscillate",
            Motion::Rotate { .. } => "rotate",
            Motion::Translate { .. } => "translate",
            Motion::Servo { .. } => "servo",
        }
    }

    /// A servo at rest in its reference position, its normal still to be
    /// set from its plane ([`super::Wall::new`] does).
    pub fn servo(pressure: f64, gain: f64, max_speed: f64, area: f64, start: f64) -> Self {
        Motion::Servo {
            normal: D::zero(),
            pressure,
            gain,
            max_speed,
            area,
            start,
            state: ServoState::default(),
        }
    }

    /// Whether the wall moves by the grains' load on it.
    pub fn is_servo(&self) -> bool {
        matches!(self, Motion::Servo { .. })
    }

    /// Checks the parameters and normalizes `direction` in place.
    pub(crate) fn validate(&mut self) -> Result<(), String> {
        match self {
            Motion::Fixed => Ok(()),
            Motion::Vibrate {
                direction,
                amplitude,
                modulation,
                wavelength,
                frequency,
                phase,
            } => {
                if !D::is_finite(*direction) {
                    return Err("vibration direction is not finite".into());
                }
                let n = D::norm(*direction);
                if n == 0.0 {
                    return Err("vibration direction is the zero vector".into());
                }
                *direction = *direction / n;
                check_finite(*amplitude, "vibration amplitude")?;
                check_finite(*modulation, "vibration modulation")?;
                check_finite(*phase, "vibration phase")?;
                check_frequency(*frequency)?;
                if *modulation != 0.0 && !(wavelength.is_finite() && *wavelength > 0.0) {
                    return Err(format!(
                        "a modulated vibration needs a positive wavelength, got {wavelength}"
                    ));
                }
                Ok(())
            }
            Motion::Oscillate {
                amplitude,
                frequency,
                phase,
            } => {
                if !D::is_finite(*amplitude) {
                    return Err("oscillation amplitude is not finite".into());
                }
                check_finite(*phase, "oscillation phase")?;
                check_frequency(*frequency)
            }
            Motion::Rotate { center, omega } => {
                if !D::is_finite(*center) {
                    return Err("rotation center is not finite".into());
                }
                if !D::ang_to_xyz(*omega).iter().all(|x| x.is_finite()) {
                    return Err("rotation omega is not finite".into());
                }
                Ok(())
            }
            Motion::Translate { velocity } => {
                if D::is_finite(*velocity) {
                    Ok(())
                } else {
                    Err("translation velocity is not finite".into())
                }
            }
            Motion::Servo {
                pressure,
                gain,
                max_speed,
                area,
                start,
                ..
            } => servo::check(*pressure, *gain, *max_speed, *area, *start),
        }
    }

    /// The wall's placement at time `t`; `x` is the abscissa at which a
    /// modulated vibration is evaluated.
    pub(crate) fn pose(&self, t: f64, x: f64) -> Pose {
        let shift = |v: D::V| Pose {
            rot: None,
            shift: to3::<D>(v),
        };
        match self {
            Motion::Fixed => shift(D::zero()),
            Motion::Vibrate { .. } => {
                let (dir, a, _, arg) = self.vibration(x, t).expect("vibrate");
                shift(dir * (a * arg.sin()))
            }
            Motion::Oscillate {
                amplitude,
                frequency,
                phase,
            } => shift(*amplitude * (TAU * frequency * t + phase).sin()),
            Motion::Translate { velocity } => shift(*velocity * t),
            Motion::Servo { normal, state, .. } => shift(*normal * state.offset),
            Motion::Rotate { center, omega } => {
                let w = DVec3::from_array(D::ang_to_xyz(*omega));
                let speed = w.length();
                if speed == 0.0 {
                    return shift(D::zero());
                }
                let q = DQuat::from_axis_angle(w / speed, speed * t);
                Pose {
                    rot: Some((q, to3::<D>(*center))),
                    shift: DVec3::ZERO,
                }
            }
        }
    }

    /// Velocity at time `t` of the wall material at position `q` (a point on
    /// the moved wall).
    pub fn velocity_at(&self, q: D::V, t: f64) -> D::V {
        match self {
            Motion::Fixed => D::zero(),
            Motion::Vibrate { .. } => {
                let (dir, a, w, arg) = self.vibration(D::get(q, 0), t).expect("vibrate");
                dir * (a * w * arg.cos())
            }
            Motion::Oscillate {
                amplitude,
                frequency,
                phase,
            } => *amplitude * (TAU * frequency * (TAU * frequency * t + phase).cos()),
            Motion::Rotate { center, omega } => D::ang_cross(*omega, q - *center),
            Motion::Translate { velocity } => *velocity,
            Motion::Servo { normal, state, .. } => *normal * state.speed,
        }
    }

    /// The velocity at time `t` when it is the same at every point of the
    /// wall (`velocity_at` would give it for any point), else `None`.
    pub(crate) fn uniform_velocity(&self, t: f64) -> Option<D::V> {
        match self {
            Motion::Rotate { .. } => None,
            Motion::Vibrate { .. } if self.is_modulated() => None,
            // Any point: a vibration without modulation has one amplitude.
            _ => Some(self.velocity_at(D::zero(), t)),
        }
    }

    /// Where the reference-frame point `x` is at time `t`.
    pub fn place(&self, x: D::V, t: f64) -> D::V {
        from3::<D>(self.pose(t, D::get(x, 0)).apply(to3::<D>(x)))
    }
}

#[cfg(test)]
mod tests;
