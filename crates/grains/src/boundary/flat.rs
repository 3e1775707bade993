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
