//! Shared geometry: every wall computation is done on 3-vectors, a 2D vector
//! being embedded in the z = 0 plane (and a 2D spin being a rotation about z).
//! This keeps one implementation of each shape for both dimensions.

use crate::dim::Dim;
use glam::DVec3;

/// Embeds a `D::V` in 3D (z = 0 in 2D).
#[inline]
pub(crate) fn to3<D: Dim>(v: D::V) -> DVec3 {
    DVec3::from_array(D::to_xyz(v))
}

/// Reads the first `D` components of a 3-vector back into a `D::V`.
#[inline]
pub(crate) fn from3<D: Dim>(v: DVec3) -> D::V {
    D::from_xyz(v.to_array())
}

/// A contact computed against reference (unmoved) geometry, in 3D form.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Touch {
    pub overlap: f64,
    /// Unit vector from the wall toward the particle centre.
    pub normal: DVec3,
    /// Contact point on the wall surface.
    pub point: DVec3,
}

/// The point of segment `[a, b]` nearest to `p` (end caps included).
#[inline]
pub(crate) fn closest_on_segment(p: DVec3, a: DVec3, b: DVec3) -> DVec3 {
    let e = b - a;
    let len2 = e.length_squared();
    if len2 == 0.0 {
        return a;
    }
    let s = ((p - a).dot(e) / len2).clamp(0.0, 1.0);
    a + e * s
}

/// A unit vector perpendicular to the unit vector `a`.
pub(crate) fn perpendicular(a: DVec3) -> DVec3 {
    let helper = if a.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    a.cross(helper).normalize()
}

/// Two-sided contact of a sphere of radius `r` at `p` with a surface whose
/// nearest point to `p` is `q`. `fallback` is the normal used when `p` lies
/// exactly on the surface (distance zero, no direction defined).
/// Exactly touching (distance = r) is no contact.
#[inline]
pub(crate) fn touch_at(p: DVec3, q: DVec3, r: f64, fallback: DVec3) -> Option<Touch> {
    let d = p - q;
    let dist2 = d.length_squared();
    if dist2 >= r * r {
        return None;
    }
    let dist = dist2.sqrt();
    let normal = if dist > 0.0 { d / dist } else { fallback };
    Some(Touch {
        overlap: r - dist,
        normal,
        point: q,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::{D2, D3};
    use glam::{DVec2, DVec3};

    #[test]
    fn embedding_round_trips() {
        let v = DVec2::new(1.5, -2.0);
        assert_eq!(to3::<D2>(v), DVec3::new(1.5, -2.0, 0.0));
        assert_eq!(from3::<D2>(DVec3::new(1.5, -2.0, 0.0)), v);
        let w = DVec3::new(1.0, 2.0, 3.0);
        assert_eq!(from3::<D3>(to3::<D3>(w)), w);
    }

    #[test]
    fn segment_closest_point_clamps_to_ends() {
        let a = DVec3::ZERO;
        let b = DVec3::new(2.0, 0.0, 0.0);
        assert_eq!(
            closest_on_segment(DVec3::new(1.0, 3.0, 0.0), a, b),
            DVec3::new(1.0, 0.0, 0.0)
        );
        assert_eq!(closest_on_segment(DVec3::new(-1.0, 1.0, 0.0), a, b), a);
        assert_eq!(closest_on_segment(DVec3::new(5.0, 1.0, 0.0), a, b), b);
    }

    #[test]
    fn perpendicular_is_unit_and_orthogonal() {
        for a in [
            DVec3::X,
            DVec3::Y,
            DVec3::Z,
            DVec3::new(1.0, 2.0, -3.0).normalize(),
        ] {
            let n = perpendicular(a);
            assert!((n.length() - 1.0).abs() < 1e-14);
            assert!(n.dot(a).abs() < 1e-14);
        }
        // About z the perpendicular stays in the x-y plane (2D embedding).
        assert_eq!(perpendicular(DVec3::Z).z, 0.0);
    }

    #[test]
    fn touching_exactly_is_no_contact() {
        let q = DVec3::ZERO;
        assert!(touch_at(DVec3::new(0.0, 0.5, 0.0), q, 0.5, DVec3::Z).is_none());
        let t = touch_at(DVec3::new(0.0, 0.4, 0.0), q, 0.5, DVec3::Z).unwrap();
        assert!((t.overlap - 0.1).abs() < 1e-15);
        assert_eq!(t.normal, DVec3::Y);
        let t = touch_at(q, q, 0.5, DVec3::Z).unwrap();
        assert_eq!(t.normal, DVec3::Z);
        assert_eq!(t.overlap, 0.5);
    }
}
