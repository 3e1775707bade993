//! The servo wall: a plane moved along its normal to hold a target normal
//! stress, by proportional control on the stress the grains put on it.
//!
//! After each force evaluation at time t the wall's pressure is measured
//! from the grains' load on it, P = −F·n / A (F the sum of the forces the
//! grains put on the wall this step, n the wall's unit normal toward the
//! grains, A the area it carries, a length in 2D), and the wall takes the
//! speed along n
//!
//!   v = clamp(g (P_target − P), −v_max, v_max)
//!
//! for the next step (explicit Euler: its offset grows by v dt). A wall
//! pressed too little advances into the grains, one pressed too much backs
//! away. `gain` g is in m/(s·Pa) (2D: m²/(N·s)). This is the proportional
//! stress control of LAMMPS `fix wall/servo` and of YADE's
//! `TriaxialStressController`, the latter choosing g = α A / (K dt) from
//! the wall's contact stiffness K (docs/servo-walls.md).

use super::Motion;
use crate::dim::Dim;
use glam::DVec3;

/// What a servo wall has done so far: the state a run carries from step to
/// step and in its checkpoints (`MdState::servo`).
///
/// It is not part of what the wall is: its `Debug` form leaves the numbers
/// out and any two states compare equal, so that a wall's description (the
/// checkpoint's fingerprint of the scenario) and the comparison of two
/// walls do not change as the wall moves.
#[derive(Clone, Copy, Default)]
pub struct ServoState {
    /// Displacement of the wall from its reference position along its
    /// normal (m).
    pub offset: f64,
    /// Its speed along the normal for the coming step (m/s).
    pub speed: f64,
    /// The pressure measured at the last force evaluation (Pa; 2D N/m).
    pub pressure: f64,
}

impl std::fmt::Debug for ServoState {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("ServoState")
    }
}

impl PartialEq for ServoState {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl ServoState {
    /// The state as three numbers (offset, speed, pressure), for a
    /// checkpoint.
    pub fn to_array(self) -> [f64; 3] {
        [self.offset, self.speed, self.pressure]
    }

    /// The state from [`ServoState::to_array`]'s numbers.
    pub fn from_array([offset, speed, pressure]: [f64; 3]) -> Self {
        Self {
            offset,
            speed,
            pressure,
        }
    }
}

/// Checks a servo's parameters; the messages name the scenario keys.
pub(super) fn check(
    pressure: f64,
    gain: f64,
    max_speed: f64,
    area: f64,
    start: f64,
) -> Result<(), String> {
    let positive = |v: f64, key: &str, unit: &str| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(format!(
                "servo {key} = {v}: must be a positive number ({unit})"
            ))
        }
    };
    if !(pressure.is_finite() && pressure >= 0.0) {
        return Err(format!(
            "servo pressure = {pressure}: must be a number >= 0 (Pa; 2D N/m)"
        ));
    }
    positive(gain, "gain", "m/(s·Pa); 2D m²/(N·s)")?;
    positive(max_speed, "max_speed", "m/s")?;
    positive(area, "area", "m²; 2D m")?;
    if !(start.is_finite() && start >= 0.0) {
        return Err(format!("servo start = {start}: must be a time >= 0 (s)"));
    }
    Ok(())
}

impl<D: Dim> Motion<D> {
    /// A servo's state (`None` for any other motion).
    pub fn servo_state(&self) -> Option<ServoState> {
        match self {
            Motion::Servo { state, .. } => Some(*state),
            _ => None,
        }
    }

    /// Puts back a servo's state (a resumed run); other motions ignore it.
    pub(crate) fn set_servo_state(&mut self, s: ServoState) {
        if let Motion::Servo { state, .. } = self {
            *state = s;
        }
    }

    /// The servo's control step after a force evaluation at time `t`:
    /// `load` is the sum of the forces the grains put on the wall then
    /// (3-vector). Records the pressure and sets the speed and offset of
    /// the next step (none before `start`). Other motions ignore it.
    pub(crate) fn servo_step(&mut self, load: DVec3, t: f64, dt: f64) {
        let Motion::Servo {
            normal,
            pressure,
            gain,
            max_speed,
            area,
            start,
            state,
        } = self
        else {
            return;
        };
        let n = DVec3::from_array(D::to_xyz(*normal));
        // The grains push against the normal: a compressive load is −F·n > 0.
        state.pressure = -load.dot(n) / *area;
        state.speed = if t < *start {
            0.0
        } else {
            (*gain * (*pressure - state.pressure)).clamp(-*max_speed, *max_speed)
        };
        state.offset += state.speed * dt;
    }
}

#[cfg(test)]
mod tests {
    //! The control law on loads given by hand.

    use crate::boundary::{Motion, Shape, Wall};
    use crate::dim::{D2, D3};
    use glam::{DVec2, DVec3};

    fn lid(start: f64) -> Wall<D3> {
        Wall::new(
            "lid",
            Shape::Plane {
                point: DVec3::new(0.0, 0.0, 1.0),
                normal: DVec3::new(0.0, 0.0, -2.0),
            },
            Motion::servo(1e4, 1e-6, 0.5, 0.04, start),
        )
        .unwrap()
    }

    #[test]
    fn an_unloaded_lid_advances_at_gain_times_error() {
        let mut w = lid(0.0);
        // No load: v = g P = 1e-6 · 1e4 = 0.01 m/s downward (along n).
        w.motion.servo_step(DVec3::ZERO, 0.0, 1e-3);
        let s = w.motion.servo_state().unwrap();
        assert_eq!(s.pressure, 0.0);
        assert!((s.speed - 0.01).abs() < 1e-15);
        assert!((s.offset - 1e-5).abs() < 1e-18);
        // The wall has moved down by the offset and moves down.
        let c = w
            .contact(DVec3::new(0.0, 0.0, 0.5), 0.5 + 1e-6, 0.0)
            .unwrap();
        assert!((c.point.z - (1.0 - 1e-5)).abs() < 1e-15);
        assert!((c.velocity - DVec3::new(0.0, 0.0, -0.01)).length() < 1e-15);
    }

    #[test]
    fn an_overloaded_lid_backs_away_at_most_at_max_speed() {
        let mut w = lid(0.0);
        // The grains push the lid up with 800 N on 0.04 m²: 20 kPa, twice
        // the target; g (P_target − P) = −0.01 m/s.
        w.motion.servo_step(DVec3::new(0.0, 0.0, 800.0), 0.0, 1e-3);
        let s = w.motion.servo_state().unwrap();
        assert!((s.pressure - 2e4).abs() < 1e-9);
        assert!((s.speed + 0.01).abs() < 1e-15);
        // 1 MPa: the speed is capped at max_speed = 0.5 m/s.
        w.motion.servo_step(DVec3::new(0.0, 0.0, 4e4), 0.0, 1e-3);
        assert_eq!(w.motion.servo_state().unwrap().speed, -0.5);
    }

    #[test]
    fn before_start_the_lid_stays_and_measures() {
        let mut w = lid(1.0);
        w.motion.servo_step(DVec3::new(0.0, 0.0, 40.0), 0.5, 1e-3);
        let s = w.motion.servo_state().unwrap();
        assert_eq!((s.speed, s.offset), (0.0, 0.0));
        assert!((s.pressure - 1e3).abs() < 1e-9);
    }

    #[test]
    fn a_servo_needs_a_plane_and_sane_keys() {
        let seg = Wall::<D2>::new(
            "piston",
            Shape::Segment {
                a: DVec2::ZERO,
                b: DVec2::X,
            },
            Motion::servo(1e3, 1e-6, 0.1, 1.0, 0.0),
        )
        .unwrap_err()
        .to_string();
        assert!(seg.contains("'piston'") && seg.contains("plane"), "{seg}");
        let plane = || Shape::Plane {
            point: DVec2::ZERO,
            normal: DVec2::Y,
        };
        let gain = Wall::<D2>::new("lid", plane(), Motion::servo(1e3, -1.0, 0.1, 1.0, 0.0))
            .unwrap_err()
            .to_string();
        assert!(gain.contains("gain") && gain.contains("m/(s·Pa)"), "{gain}");
        let p = Wall::<D2>::new("lid", plane(), Motion::servo(f64::NAN, 1.0, 0.1, 1.0, 0.0))
            .unwrap_err()
            .to_string();
        assert!(p.contains("pressure"), "{p}");
    }

    #[test]
    fn the_state_is_left_out_of_the_walls_description() {
        let (a, mut b) = (lid(0.0), lid(0.0));
        b.motion.servo_step(DVec3::ZERO, 0.0, 1e-3);
        assert_eq!(format!("{a:?}"), format!("{b:?}"));
        assert_eq!(a, b);
        assert_ne!(
            a.motion.servo_state().unwrap().offset,
            b.motion.servo_state().unwrap().offset
        );
    }
}
