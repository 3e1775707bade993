//! The loads grains put on mesh walls: force and torque, for `walls.csv`.

use crate::dim::Dim;
use glam::DVec3;

/// The sum of the forces grains exert on one wall, and their moment about
/// the origin (a torque about any point c follows as M − c × F, so the sum
/// does not depend on where the wall is).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WallLoad {
    pub force: DVec3,
    pub moment: DVec3,
}

impl WallLoad {
    /// Adds the reaction to `on_grain`, the force a contact at `point` put
    /// on a grain.
    #[inline]
    pub fn add<D: Dim>(&mut self, on_grain: D::V, point: D::V) {
        let f = -DVec3::from_array(D::to_xyz(on_grain));
        self.force += f;
        self.moment += DVec3::from_array(D::to_xyz(point)).cross(f);
    }

    /// The torque about `c`.
    pub fn torque_about(&self, c: DVec3) -> DVec3 {
        self.moment - c.cross(self.force)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::D3;

    #[test]
    fn torque_about_a_point_is_the_lever_arm_cross_the_force() {
        let mut l = WallLoad::default();
        // Two grains pushed up by the wall at x = ±1: the wall is pushed
        // down at both, and about (2, 0, 0) it turns.
        l.add::<D3>(DVec3::new(0.0, 0.0, 1.0), DVec3::new(1.0, 0.0, 0.0));
        l.add::<D3>(DVec3::new(0.0, 0.0, 1.0), DVec3::new(-1.0, 0.0, 0.0));
        assert_eq!(l.force, DVec3::new(0.0, 0.0, -2.0));
        assert_eq!(l.torque_about(DVec3::ZERO), DVec3::ZERO);
        let c = DVec3::new(2.0, 0.0, 0.0);
        // Σ (x − c) × F = (−1 − 3) x̂ × (−ẑ) = 4 x̂ × ẑ = −4 ŷ.
        assert_eq!(l.torque_about(c), DVec3::new(0.0, -4.0, 0.0));
    }
}
