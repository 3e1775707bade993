//! A servo wall's motion from its scenario table: the keys checked and the
//! area the load is divided by resolved from the wall's plane and the box.

use super::schema::MotionSpec;
use crate::boundary::{Motion, Shape};
use crate::dim::Dim;
use crate::domain::Domain;
use crate::error::{Error, Result};

/// The servo `spec` (a `MotionSpec::Servo`) of the wall `shape`; `key`
/// names the wall in messages.
pub(super) fn motion<D: Dim>(
    key: &str,
    spec: &MotionSpec,
    shape: &Shape<D>,
    dom: &Domain<D>,
) -> Result<Motion<D>> {
    let MotionSpec::Servo {
        pressure,
        gain,
        max_speed,
        area,
        start,
    } = spec
    else {
        unreachable!("servo::motion is called for servo motions only");
    };
    let Shape::Plane { normal, .. } = shape else {
        return Err(Error::input(format!(
            "{key}: motion type \"servo\" needs shape type \"plane\" (a line in 2D), moved \
             along its normal; this wall is a {}",
            shape.kind()
        )));
    };
    let area = match area {
        Some(a) => *a,
        None => cross_section(dom, *normal).ok_or_else(|| {
            Error::input(format!(
                "{key}.motion.area: needed when the plane's normal is not along an axis \
                 (m²; 2D m): by default the area is the box's cross-section across an \
                 axis-aligned normal"
            ))
        })?,
    };
    Ok(Motion::servo(*pressure, *gain, *max_speed, area, *start))
}

/// The box's cross-section across `normal` when the normal lies along one
/// axis (the product of the box's lengths along the others; in 2D the one
/// other length): the area an infinite plane carries when the grains fill
/// the box across it, as in a box periodic along the plane.
fn cross_section<D: Dim>(dom: &Domain<D>, normal: D::V) -> Option<f64> {
    let along = |a: usize| D::get(normal, a) != 0.0;
    let axis = (0..D::D).find(|&a| along(a))?;
    if (0..D::D).any(|b| b != axis && along(b)) {
        return None;
    }
    Some(
        (0..D::D)
            .filter(|&b| b != axis)
            .map(|b| dom.length(b))
            .product(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::{D2, D3};
    use glam::{DVec2, DVec3};

    fn spec(area: Option<f64>) -> MotionSpec {
        MotionSpec::Servo {
            pressure: 1e4,
            gain: 1e-6,
            max_speed: 0.1,
            area,
            start: 0.0,
        }
    }

    #[test]
    fn the_default_area_is_the_boxs_cross_section() {
        let dom = Domain::<D3>::new(DVec3::ZERO, DVec3::new(0.2, 0.3, 1.0), [true, true, false]);
        let lid = Shape::Plane {
            point: DVec3::new(0.0, 0.0, 1.0),
            normal: DVec3::new(0.0, 0.0, -1.0),
        };
        let Motion::Servo { area, .. } = motion("lid", &spec(None), &lid, &dom).unwrap() else {
            panic!("not a servo");
        };
        assert_eq!(area, 0.2 * 0.3);
        let dom = Domain::<D2>::new(DVec2::ZERO, DVec2::new(0.25, 1.0), [true, false, false]);
        let lid = Shape::Plane {
            point: DVec2::new(0.0, 1.0),
            normal: DVec2::new(0.0, -1.0),
        };
        let Motion::Servo { area, .. } = motion("lid", &spec(None), &lid, &dom).unwrap() else {
            panic!("not a servo");
        };
        assert_eq!(area, 0.25);
        // A tilted plane needs its area.
        let tilted = Shape::Plane {
            point: DVec2::new(0.0, 1.0),
            normal: DVec2::new(0.1, -1.0),
        };
        let e = motion("walls[1] (lid)", &spec(None), &tilted, &dom)
            .unwrap_err()
            .to_string();
        assert!(e.contains("walls[1] (lid).motion.area"), "{e}");
        assert!(motion("lid", &spec(Some(0.3)), &tilted, &dom).is_ok());
        // Any shape but a plane is refused by name.
        let disk = Shape::Cylinder {
            point: DVec2::ZERO,
            axis: DVec2::ZERO,
            radius: 1.0,
            inside: true,
        };
        let e = motion("walls[2] (drum)", &spec(None), &disk, &dom)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("walls[2] (drum)") && e.contains("\"plane\"") && e.contains("cylinder"),
            "{e}"
        );
    }
}
