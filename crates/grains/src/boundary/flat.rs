//! Flat walls: infinite planes (lines in 2D), finite segments (2D) and convex
//! polygons (3D), all in their reference (unmoved) position.

use super::geom::{closest_on_segment, touch_at, Touch};
use glam::DVec3;
use std::f64::consts::PI;

/// One-sided plane through `point` with unit `normal`; particles live on the
/// side the normal points to.
///
/// With signed distance `s = (p − point)·n`, the overlap is `r − s`. A
/// particle whose centre has crossed the plane (`s < 0`) keeps that overlap, so
/// it is pushed back out, with the normal still `n`. But a particle more than
/// one radius behind (`s < −r`, wholly on the wrong side) is treated as lost:
/// no contact, rather than an ever larger force that would launch it.
#[inline]
pub(crate) fn plane(p: DVec3, point: DVec3, normal: DVec3, r: f64) -> Option<Touch> {
    let s = (p - point).dot(normal);
    let overlap = r - s;
    if overlap <= 0.0 || s < -r {
        return None;
    }
    Some(Touch {
        overlap,
        normal,
        point: p - normal * s,
    })
}

/// The surface of a plane whose points are lifted along its unit `normal`
/// by a(x) (a modulated vibrating plate, `normal` ⟂ x), met by a particle:
/// `lift` is a at the particle's x and `slope` is da/dx there. The surface
/// is replaced by its tangent at the particle's x, so the normal tilts to
/// (n − slope x̂)/√(1 + slope²) and the distance shrinks by the same root.
/// The true contact point lies about r·slope away along x, where the curve
/// leaves its tangent by ½·curvature·(r·slope)²: at most 1e-3 r in seed 002
/// Fig. 2 (curvature A0 B (2π/L)² = 0.074/d0, slope ≤ 0.24).
/// One-sided like [`plane`].
#[inline]
pub(crate) fn lifted_plane(
    p: DVec3,
    point: DVec3,
    normal: DVec3,
    lift: f64,
    slope: f64,
    r: f64,
) -> Option<Touch> {
    let tilted = (normal - DVec3::X * slope).normalize();
    let s = ((p - point).dot(normal) - lift) * tilted.dot(normal);
    let overlap = r - s;
    if overlap <= 0.0 || s < -r {
        return None;
    }
    Some(Touch {
        overlap,
        normal: tilted,
        point: p - tilted * s,
    })
}

/// Two-sided segment `[a, b]` in the z = 0 plane (a 2D wall), end caps
/// included. A centre lying exactly on the segment is pushed along the
/// segment's left normal (z × (b − a)).
#[inline]
pub(crate) fn segment(p: DVec3, a: DVec3, b: DVec3, r: f64) -> Option<Touch> {
    let q = closest_on_segment(p, a, b);
    let fallback = DVec3::Z.cross(b - a).normalize();
    touch_at(p, q, r, fallback)
}

/// Unit normal of a planar polygon by Newell's method, oriented so that the
/// vertices turn counter-clockwise about it. Zero for a degenerate polygon.
pub(crate) fn polygon_normal(n: usize, vert: impl Fn(usize) -> DVec3) -> DVec3 {
    let c = polygon_centroid(n, &vert);
    let mut sum = DVec3::ZERO;
    for i in 0..n {
        let a = vert(i) - c;
        let b = vert((i + 1) % n) - c;
        sum += a.cross(b);
    }
    sum.normalize_or_zero()
}

/// Mean of the vertices (the polygon's reference point).
pub(crate) fn polygon_centroid(n: usize, vert: impl Fn(usize) -> DVec3) -> DVec3 {
    let mut c = DVec3::ZERO;
    for i in 0..n {
        c += vert(i);
    }
    c / n as f64
}

/// Checks that the vertices form a non-degenerate, planar, convex polygon.
/// Collinear consecutive vertices are allowed; repeated ones are not.
pub(crate) fn check_polygon(v: &[DVec3]) -> Result<(), String> {
    let n = v.len();
    if n < 3 {
        return Err(format!("a polygon needs at least 3 vertices, got {n}"));
    }
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(format!("polygon vertex {i} is not finite"));
    }
    for i in 0..n {
        if v[i] == v[(i + 1) % n] {
            return Err(format!("polygon vertices {i} and {} coincide", (i + 1) % n));
        }
    }
    let normal = polygon_normal(n, |i| v[i]);
    if normal == DVec3::ZERO {
        return Err("polygon has zero area (collinear vertices)".into());
    }
    let c = polygon_centroid(n, |i| v[i]);
    let size = v.iter().map(|x| (*x - c).length()).fold(0.0, f64::max);
    for (i, x) in v.iter().enumerate() {
        let off = (*x - c).dot(normal);
        if off.abs() > 1e-9 * size {
            return Err(format!(
                "polygon vertices are not coplanar (vertex {i} is {off:e} off the plane)"
            ));
        }
    }
    let mut turning = 0.0;
    for i in 0..n {
        let e1 = v[(i + 1) % n] - v[i];
        let e2 = v[(i + 2) % n] - v[(i + 1) % n];
        let s = e1.cross(e2).dot(normal);
        let scale = e1.length() * e2.length();
        if s < -1e-12 * scale {
            return Err(format!(
                "polygon is not convex (turns the wrong way at vertex {})",
                (i + 1) % n
            ));
        }
        turning += s.atan2(e1.dot(e2));
    }
    // A convex polygon turns once; a star-shaped one (pentagram) more often.
    if turning > 3.0 * PI {
        return Err("polygon is not convex (its edges wind around more than once)".into());
    }
    Ok(())
}

/// Two-sided convex polygon with `n` vertices `vert(i)` and unit `normal`
/// (from [`polygon_normal`]). The nearest point is the projection of `p` when
/// that falls inside, otherwise the nearest point of the boundary. A centre
/// lying exactly in the polygon is pushed along `normal`.
///
/// Edges listed in `seams` are shared with a coplanar neighbour: a projection
/// outside whose nearest boundary point lies on a seam belongs to the
/// neighbour, so this piece gives no contact (a real edge collinear with a
/// seam, like an orifice rim, still acts). A
/// projection exactly on a seam goes to the piece that traverses the edge in
/// lexicographically increasing direction (the neighbour traverses it the
/// other way), so each point of the joined surface has exactly one owner.
pub(crate) fn polygon(
    p: DVec3,
    n: usize,
    vert: impl Fn(usize) -> DVec3,
    seams: &[usize],
    normal: DVec3,
    r: f64,
) -> Option<Touch> {
    let v0 = vert(0);
    let s = (p - v0).dot(normal);
    if s.abs() >= r {
        return None; // the whole polygon is at least |s| away
    }
    let q = p - normal * s;
    let mut inside = true;
    let mut best = q;
    let mut best_d2 = f64::INFINITY;
    let mut best_on_seam = false;
    for i in 0..n {
        let a = vert(i);
        let b = vert((i + 1) % n);
        let side = (b - a).cross(q - a).dot(normal);
        let seam = seams.contains(&i);
        if side < 0.0 {
            inside = false;
        } else if side == 0.0 && seam && closest_on_segment(q, a, b) == q {
            let e = (b - a).to_array();
            if !e.iter().find(|c| **c != 0.0).is_some_and(|c| *c > 0.0) {
                return None; // exactly on the seam: the neighbour's point
            }
        }
        let c = closest_on_segment(p, a, b);
        let d2 = (p - c).length_squared();
        // On a tie (a corner where a seam meets a real edge) the real edge wins.
        if d2 < best_d2 || (d2 == best_d2 && !seam) {
            best_d2 = d2;
            best = c;
            best_on_seam = seam;
        }
    }
    if inside {
        let side = if s < 0.0 { -normal } else { normal };
        return Some(Touch {
            overlap: r - s.abs(),
            normal: side,
            point: q,
        });
    }
    if best_on_seam {
        return None; // beyond a seam: the neighbour's face carries the grain
    }
    touch_at(p, best, r, normal)
}

#[cfg(test)]
mod tests {
    use super::*;

    const EPS: f64 = 1e-12;

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < EPS
    }

    #[test]
    fn plane_cap_behind() {
        let n = DVec3::Z;
        // In front, touching: overlap 0.1.
        let t = plane(DVec3::new(3.0, 4.0, 0.4), DVec3::ZERO, n, 0.5).unwrap();
        assert!((t.overlap - 0.1).abs() < EPS);
        assert!(close(t.point, DVec3::new(3.0, 4.0, 0.0)));
        // Centre crossed: overlap r − s, still pushed along +n.
        let t = plane(DVec3::new(0.0, 0.0, -0.3), DVec3::ZERO, n, 0.5).unwrap();
        assert!((t.overlap - 0.8).abs() < EPS);
        assert_eq!(t.normal, n);
        // Exactly r behind: still in contact (overlap 2r); beyond: lost.
        assert!(plane(DVec3::new(0.0, 0.0, -0.5), DVec3::ZERO, n, 0.5).is_some());
        assert!(plane(DVec3::new(0.0, 0.0, -0.51), DVec3::ZERO, n, 0.5).is_none());
        // Exactly touching: none.
        assert!(plane(DVec3::new(0.0, 0.0, 0.5), DVec3::ZERO, n, 0.5).is_none());
    }

    #[test]
    fn polygon_checks() {
        let sq = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
        ];
        assert!(check_polygon(&sq).is_ok());
        assert!(close(polygon_normal(4, |i| sq[i]), DVec3::Z));
        // Clockwise order flips the normal.
        let rev: Vec<_> = sq.iter().rev().copied().collect();
        assert!(close(polygon_normal(4, |i| rev[i]), -DVec3::Z));
        assert!(check_polygon(&rev).is_ok());
        // Non-convex (dart).
        let dart = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.5, 0.5, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
        ];
        assert!(check_polygon(&dart).unwrap_err().contains("convex"));
        // Pentagram: every turn to the left, but winds twice.
        let star: Vec<_> = (0..5)
            .map(|k| {
                let a = 2.0 * PI * (2 * k) as f64 / 5.0;
                DVec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        assert!(check_polygon(&star).unwrap_err().contains("convex"));
        // Not coplanar.
        let mut bent = sq;
        bent[2].z = 0.3;
        assert!(check_polygon(&bent).unwrap_err().contains("coplanar"));
        // Too few, collinear, repeated.
        assert!(check_polygon(&sq[..2]).unwrap_err().contains("at least 3"));
        let line = [DVec3::ZERO, DVec3::X, 2.0 * DVec3::X];
        assert!(check_polygon(&line).unwrap_err().contains("zero area"));
        let rep = [DVec3::ZERO, DVec3::ZERO, DVec3::X, DVec3::Y];
        assert!(check_polygon(&rep).unwrap_err().contains("coincide"));
    }
}

#[cfg(test)]
mod wall_tests {
    //! Wall contacts of planes, segments and polygons, through `Wall`.

    use crate::boundary::tests::{fixed2, fixed3, near, near2, near3};
    use crate::boundary::*;
    use glam::{DQuat, DVec2, DVec3};
    use std::f64::consts::FRAC_1_SQRT_2;

    #[test]
    fn plane_2d_arbitrary_orientation() {
        let w = fixed2(Shape::Plane {
            point: DVec2::new(1.0, 0.0),
            normal: DVec2::new(1.0, 1.0),
        });
        let c = w.contact(DVec2::new(2.0, 0.5), 1.2, 0.0).unwrap();
        assert!(near(c.overlap, 1.2 - 1.5 / 2f64.sqrt()));
        assert!(near2(c.normal, DVec2::new(FRAC_1_SQRT_2, FRAC_1_SQRT_2)));
        assert!(near2(c.point, DVec2::new(1.25, -0.25)));
        assert_eq!(c.velocity, DVec2::ZERO);
        assert!(w.contact(DVec2::new(2.0, 0.5), 1.0, 0.0).is_none());
    }

    #[test]
    fn plane_3d_arbitrary_orientation() {
        let w = fixed3(Shape::Plane {
            point: DVec3::new(0.0, 0.0, 1.0),
            normal: DVec3::new(1.0, 2.0, 2.0),
        });
        let c = w.contact(DVec3::new(1.0, 1.0, 2.0), 2.0, 0.0).unwrap();
        assert!(near(c.overlap, 1.0 / 3.0));
        assert!(near3(c.normal, DVec3::new(1.0, 2.0, 2.0) / 3.0));
        assert!(near3(c.point, DVec3::new(4.0, -1.0, 8.0) / 9.0));
        // Behind the plane (centre crossed by 0.5 < r): pushed back along n.
        let n = DVec3::new(1.0, 2.0, 2.0) / 3.0;
        let p = DVec3::new(0.0, 0.0, 1.0) - n * 0.5;
        let c = w.contact(p, 2.0, 0.0).unwrap();
        assert!(near(c.overlap, 2.5));
        assert!(near3(c.normal, n));
        // Deeply behind (more than r): lost, no contact.
        assert!(w
            .contact(DVec3::new(0.0, 0.0, 1.0) - n * 2.5, 2.0, 0.0)
            .is_none());
    }

    #[test]
    fn exactly_touching_is_no_contact() {
        let w = fixed2(Shape::Plane {
            point: DVec2::ZERO,
            normal: DVec2::Y,
        });
        assert!(w.contact(DVec2::new(0.3, 0.5), 0.5, 0.0).is_none());
        assert!(near(
            w.contact(DVec2::new(0.3, 0.25), 0.5, 0.0).unwrap().overlap,
            0.25
        ));
        let o = fixed3(Shape::Obstacle {
            center: DVec3::ZERO,
            diameter: 1.0,
        });
        assert!(o.contact(DVec3::new(0.0, 0.75, 0.0), 0.25, 0.0).is_none());
        let s = fixed2(Shape::Segment {
            a: DVec2::ZERO,
            b: DVec2::X,
        });
        assert!(s.contact(DVec2::new(0.5, -0.5), 0.5, 0.0).is_none());
    }

    #[test]
    fn segment_interior_and_end_caps() {
        let w = fixed2(Shape::Segment {
            a: DVec2::new(0.0, 0.0),
            b: DVec2::new(4.0, 0.0),
        });
        let c = w.contact(DVec2::new(1.0, 0.3), 0.5, 0.0).unwrap();
        assert!(near(c.overlap, 0.2));
        assert!(near2(c.normal, DVec2::Y));
        assert!(near2(c.point, DVec2::new(1.0, 0.0)));
        // Two-sided: from below the normal points down.
        let c = w.contact(DVec2::new(2.0, -0.1), 0.5, 0.0).unwrap();
        assert!(near(c.overlap, 0.4));
        assert!(near2(c.normal, -DVec2::Y));
        // End cap at b.
        let c = w.contact(DVec2::new(4.3, 0.4), 0.6, 0.0).unwrap();
        assert!(near(c.overlap, 0.1));
        assert!(near2(c.normal, DVec2::new(0.6, 0.8)));
        assert!(near2(c.point, DVec2::new(4.0, 0.0)));
        // End cap at a.
        let c = w.contact(DVec2::new(-0.3, -0.4), 0.6, 0.0).unwrap();
        assert!(near(c.overlap, 0.1));
        assert!(near2(c.normal, DVec2::new(-0.6, -0.8)));
        assert!(near2(c.point, DVec2::ZERO));
        // Beyond the cap: nothing.
        assert!(w.contact(DVec2::new(4.5, 0.1), 0.4, 0.0).is_none());
        // Centre on the segment: pushed along the left normal.
        let c = w.contact(DVec2::new(2.0, 0.0), 0.5, 0.0).unwrap();
        assert!(near(c.overlap, 0.5));
        assert!(near2(c.normal, DVec2::Y));
    }

    #[test]
    fn polygon_interior_edge_and_vertex() {
        let w = fixed3(Shape::Polygon {
            vertices: vec![
                DVec3::new(0.0, 0.0, 1.0),
                DVec3::new(2.0, 0.0, 1.0),
                DVec3::new(2.0, 2.0, 1.0),
                DVec3::new(0.0, 2.0, 1.0),
            ],
            seams: vec![],
        });
        // Interior, both sides.
        let c = w.contact(DVec3::new(1.0, 1.0, 1.3), 0.5, 0.0).unwrap();
        assert!(near(c.overlap, 0.2));
        assert!(near3(c.normal, DVec3::Z));
        assert!(near3(c.point, DVec3::new(1.0, 1.0, 1.0)));
        let c = w.contact(DVec3::new(0.5, 1.5, 0.8), 0.5, 0.0).unwrap();
        assert!(near(c.overlap, 0.3));
        assert!(near3(c.normal, -DVec3::Z));
        assert!(near3(c.point, DVec3::new(0.5, 1.5, 1.0)));
        // Edge region (beyond x = 2).
        let c = w.contact(DVec3::new(2.3, 1.0, 1.4), 0.6, 0.0).unwrap();
        assert!(near(c.overlap, 0.1));
        assert!(near3(c.normal, DVec3::new(0.6, 0.0, 0.8)));
        assert!(near3(c.point, DVec3::new(2.0, 1.0, 1.0)));
        // Vertex region (beyond the corner (2, 2)).
        let c = w.contact(DVec3::new(2.2, 2.2, 1.1), 0.5, 0.0).unwrap();
        assert!(near(c.overlap, 0.2));
        assert!(near3(c.normal, DVec3::new(2.0, 2.0, 1.0) / 3.0));
        assert!(near3(c.point, DVec3::new(2.0, 2.0, 1.0)));
        // Beside the polygon, in its plane, out of reach.
        assert!(w.contact(DVec3::new(3.0, 1.0, 1.0), 0.5, 0.0).is_none());
        assert!(w.contact(DVec3::new(1.0, 1.0, 1.5), 0.5, 0.0).is_none());
    }

    #[test]
    fn tilted_polygon() {
        // A triangle rotated about an arbitrary axis: the interior normal is the
        // rotated z, the distance the rotated height.
        let q = DQuat::from_axis_angle(DVec3::new(1.0, -2.0, 0.5).normalize(), 0.7);
        let o = DVec3::new(0.3, -1.0, 2.0);
        let tri = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(3.0, 0.0, 0.0),
            DVec3::new(0.0, 3.0, 0.0),
        ];
        let w = fixed3(Shape::Polygon {
            vertices: tri.iter().map(|v| o + q * *v).collect(),
            seams: vec![],
        });
        let c = w
            .contact(o + q * DVec3::new(1.0, 1.0, 0.35), 0.5, 0.0)
            .unwrap();
        assert!(near(c.overlap, 0.15));
        assert!(near3(c.normal, q * DVec3::Z));
        assert!(near3(c.point, o + q * DVec3::new(1.0, 1.0, 0.0)));
        // Near the hypotenuse x + y = 3, outside it, in the plane.
        let c = w
            .contact(o + q * DVec3::new(1.7, 1.7, 0.0), 0.5, 0.0)
            .unwrap();
        assert!(near(c.overlap, 0.5 - 0.4 / 2f64.sqrt()));
        assert!(near3(
            c.normal,
            q * DVec3::new(FRAC_1_SQRT_2, FRAC_1_SQRT_2, 0.0)
        ));
    }

    /// Two coplanar squares that share an edge marked as a seam on both act as
    /// one rectangle: a sphere anywhere across the seam (and exactly on it) feels
    /// the single-face overlap once, never an edge contact.
    #[test]
    fn polygon_seam_pushes_once() {
        let sq = |x0: f64, seams: Vec<usize>| {
            fixed3(Shape::Polygon {
                vertices: vec![
                    DVec3::new(x0, 0.0, 0.0),
                    DVec3::new(x0 + 1.0, 0.0, 0.0),
                    DVec3::new(x0 + 1.0, 1.0, 0.0),
                    DVec3::new(x0, 1.0, 0.0),
                ],
                seams,
            })
        };
        // Edge 1 of the left square (x = 1, going +y) meets edge 3 of the right
        // one (x = 1, going −y).
        let (left, right) = (sq(0.0, vec![1]), sq(1.0, vec![3]));
        for x in [0.7, 0.95, 1.0 - 1e-12, 1.0, 1.0 + 1e-12, 1.05, 1.3] {
            let p = DVec3::new(x, 0.5, 0.3);
            let touches: Vec<_> = [&left, &right]
                .iter()
                .filter_map(|w| w.contact(p, 0.5, 0.0))
                .collect();
            assert_eq!(touches.len(), 1, "x = {x}: {} contacts", touches.len());
            assert!(near(touches[0].overlap, 0.2), "x = {x}");
            assert!(near3(touches[0].normal, DVec3::Z), "x = {x}");
        }
        // Without seams both squares push a sphere near the shared edge.
        let (l, r) = (sq(0.0, vec![]), sq(1.0, vec![]));
        let p = DVec3::new(1.05, 0.5, 0.3);
        assert!(l.contact(p, 0.5, 0.0).is_some() && r.contact(p, 0.5, 0.0).is_some());
        // A real edge (not a seam) still acts: beyond x = 2 the right square's rim.
        let c = right.contact(DVec3::new(2.2, 0.5, 0.3), 0.5, 0.0).unwrap();
        assert!(c.overlap > 0.0 && c.normal.x > 0.0);
        // A rim collinear with a seam (an orifice beside a joint): x = 1 is a seam
        // for y < 1 and a real edge for 1 < y < 2.
        let piece = fixed3(Shape::Polygon {
            vertices: vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(1.0, 2.0, 0.0),
                DVec3::new(0.0, 2.0, 0.0),
            ],
            seams: vec![1],
        });
        let c = piece.contact(DVec3::new(1.2, 1.5, 0.1), 0.5, 0.0).unwrap();
        assert!(near(c.overlap, 0.5 - 0.05_f64.sqrt()) && c.normal.x > 0.0);
        assert!(piece.contact(DVec3::new(1.2, 0.5, 0.1), 0.5, 0.0).is_none());
    }
}
