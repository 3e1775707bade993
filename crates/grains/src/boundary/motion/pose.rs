//! A rigid placement of a wall: a rotation about a centre, then a shift.

use glam::{DQuat, DVec3};

/// A rigid placement: x ↦ center + rot (x − center) + shift, in 3D form.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Pose {
    pub(super) rot: Option<(DQuat, DVec3)>,
    pub(in crate::boundary) shift: DVec3,
}

impl Pose {
    pub(crate) fn apply(&self, x: DVec3) -> DVec3 {
        match self.rot {
            Some((q, c)) => c + q * (x - c) + self.shift,
            None => x + self.shift,
        }
    }

    /// The inverse placement: world position to reference frame.
    pub(crate) fn invert(&self, x: DVec3) -> DVec3 {
        match self.rot {
            Some((q, c)) => c + q.inverse() * (x - self.shift - c),
            None => x - self.shift,
        }
    }

    /// The shift, when the placement is a translation only.
    pub(crate) fn translation(&self) -> Option<DVec3> {
        self.rot.is_none().then_some(self.shift)
    }

    /// Turns a direction (no translation).
    pub(crate) fn turn(&self, v: DVec3) -> DVec3 {
        match self.rot {
            Some((q, _)) => q * v,
            None => v,
        }
    }
}
