//! Round walls: cylinders (circles in 2D) seen from inside or outside, and
//! fixed circular/spherical obstacles, in their reference position.

use super::geom::{perpendicular, touch_at, Touch};
use glam::DVec3;

/// Cylinder of radius `radius` around the line through `c` along unit `axis`
/// (in 2D: the circle about `c`, axis = z). `inside`: particles live inside
/// (a pipe or a drum); otherwise outside (a post).
///
/// Like a plane, the surface is one-sided: a particle whose centre has crossed
/// it keeps the overlap `r − (signed distance)` and is pushed back, but one
/// more than a radius beyond the surface is treated as lost (no contact).
/// A centre exactly on the axis gets an arbitrary radial direction.
pub(crate) fn cylinder(
    p: DVec3,
    c: DVec3,
    axis: DVec3,
    radius: f64,
    inside: bool,
    r: f64,
) -> Option<Touch> {
    let d = p - c;
    let h = d.dot(axis);
    let radial = d - axis * h;
    let rho = radial.length();
    // Signed distance from the surface, positive on the particles' side.
    let s = if inside { radius - rho } else { rho - radius };
    let overlap = r - s;
    if overlap <= 0.0 || s < -r {
        return None;
    }
    let out = if rho > 0.0 {
        radial / rho
    } else {
        perpendicular(axis)
    };
    Some(Touch {
        overlap,
        normal: if inside { -out } else { out },
        point: c + axis * h + out * radius,
    })
}

/// Fixed obstacle: a circle (2D) or sphere (3D) of diameter `diameter` at
/// `c`, two-sided like a grain: overlap = r + d1/2 − |p − c|, always pushed
/// out. A centre exactly at `c` is pushed upward (`up`).
pub(crate) fn obstacle(p: DVec3, c: DVec3, diameter: f64, r: f64, up: DVec3) -> Option<Touch> {
    let half = 0.5 * diameter;
    let t = touch_at(p, c, r + half, up)?;
    Some(Touch {
        overlap: t.overlap,
        normal: t.normal,
        point: c + t.normal * half,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cylinder_caps_lost_particles() {
        // Drum of radius 2: a particle beyond the shell by more than r is lost.
        assert!(cylinder(
            DVec3::new(2.4, 0.0, 0.0),
            DVec3::ZERO,
            DVec3::Z,
            2.0,
            true,
            0.5
        )
        .is_some());
        assert!(cylinder(
            DVec3::new(2.6, 0.0, 0.0),
            DVec3::ZERO,
            DVec3::Z,
            2.0,
            true,
            0.5
        )
        .is_none());
        // Post of radius 2: a centre deep inside is lost too.
        assert!(cylinder(
            DVec3::new(1.6, 0.0, 0.0),
            DVec3::ZERO,
            DVec3::Z,
            2.0,
            false,
            0.5
        )
        .is_some());
        assert!(cylinder(
            DVec3::new(1.4, 0.0, 0.0),
            DVec3::ZERO,
            DVec3::Z,
            2.0,
            false,
            0.5
        )
        .is_none());
    }

    #[test]
    fn obstacle_centre_on_centre() {
        let t = obstacle(DVec3::ZERO, DVec3::ZERO, 1.0, 0.5, DVec3::Z).unwrap();
        assert_eq!(t.overlap, 1.0);
        assert_eq!(t.normal, DVec3::Z);
        assert_eq!(t.point, DVec3::new(0.0, 0.0, 0.5));
    }
}

#[cfg(test)]
mod wall_tests {
    //! Wall contacts of cylinders and obstacles, through `Wall`.

    use crate::boundary::tests::{fixed2, fixed3, near, near2, near3};
    use crate::boundary::*;
    use glam::{DVec2, DVec3};

    #[test]
    fn cylinder_2d_inside_and_outside() {
        let drum = fixed2(Shape::Cylinder {
            point: DVec2::new(1.0, 1.0),
            axis: DVec2::ZERO,
            radius: 3.0,
            inside: true,
        });
        let c = drum.contact(DVec2::new(3.8, 1.0), 0.5, 0.0).unwrap();
        assert!(near(c.overlap, 0.3));
        assert!(near2(c.normal, -DVec2::X));
        assert!(near2(c.point, DVec2::new(4.0, 1.0)));
        assert!(drum.contact(DVec2::new(1.0, 1.0), 0.5, 0.0).is_none());
        let post = fixed2(Shape::Cylinder {
            point: DVec2::new(1.0, 1.0),
            axis: DVec2::ZERO,
            radius: 1.0,
            inside: false,
        });
        let c = post.contact(DVec2::new(1.0, 2.3), 0.5, 0.0).unwrap();
        assert!(near(c.overlap, 0.2));
        assert!(near2(c.normal, DVec2::Y));
        assert!(near2(c.point, DVec2::new(1.0, 2.0)));
        assert!(post.contact(DVec2::new(1.0, 2.5), 0.5, 0.0).is_none());
    }

    #[test]
    fn cylinder_3d_arbitrary_axis() {
        let axis = DVec3::new(1.0, 1.0, 0.0);
        let along = axis.normalize() * 5.0;
        let pipe = fixed3(Shape::Cylinder {
            point: DVec3::ZERO,
            axis,
            radius: 2.0,
            inside: true,
        });
        let c = pipe
            .contact(along + DVec3::new(0.0, 0.0, 1.8), 0.5, 0.0)
            .unwrap();
        assert!(near(c.overlap, 0.3));
        assert!(near3(c.normal, -DVec3::Z));
        assert!(near3(c.point, along + DVec3::new(0.0, 0.0, 2.0)));
        // Radial direction not along a coordinate axis.
        let radial = DVec3::new(1.0, -1.0, 0.0).normalize();
        let c = pipe.contact(along + radial * 1.9, 0.25, 0.0).unwrap();
        assert!(near(c.overlap, 0.15));
        assert!(near3(c.normal, -radial));
        let post = fixed3(Shape::Cylinder {
            point: DVec3::ZERO,
            axis,
            radius: 1.0,
            inside: false,
        });
        let c = post
            .contact(along + DVec3::new(0.0, 0.0, 1.2), 0.5, 0.0)
            .unwrap();
        assert!(near(c.overlap, 0.3));
        assert!(near3(c.normal, DVec3::Z));
        assert!(near3(c.point, along + DVec3::Z));
    }

    #[test]
    fn obstacle_2d_and_3d() {
        let w = fixed2(Shape::Obstacle {
            center: DVec2::new(5.0, 1.0),
            diameter: 1.0,
        });
        let c = w.contact(DVec2::new(5.6, 1.8), 0.6, 0.0).unwrap();
        assert!(near(c.overlap, 0.1));
        assert!(near2(c.normal, DVec2::new(0.6, 0.8)));
        assert!(near2(c.point, DVec2::new(5.3, 1.4)));
        let w = fixed3(Shape::Obstacle {
            center: DVec3::new(1.0, 2.0, 3.0),
            diameter: 2.0,
        });
        let c = w.contact(DVec3::new(1.0, 3.2, 4.6), 1.5, 0.0).unwrap();
        assert!(near(c.overlap, 0.5));
        assert!(near3(c.normal, DVec3::new(0.0, 0.6, 0.8)));
        assert!(near3(c.point, DVec3::new(1.0, 2.6, 3.8)));
    }
}
