//! The point of a triangle nearest to a sphere's centre, and which feature
//! (the face, one of its edges, one of its corners) holds it.

use glam::DVec3;

/// Where on a triangle (a, b, c) the nearest point lies. Edge k runs from
/// corner k to corner k + 1 (0: ab, 1: bc, 2: ca).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Region {
    Face,
    Edge(u8),
    Corner(u8),
}

/// The nearest point of triangle (a, b, c) to `p`, by the signs of the
/// barycentric coordinates of `p`'s projection (the Voronoi regions of the
/// corners, edges and face; Ericson, *Real-Time Collision Detection* §5.1.5).
/// At a region's border both neighbours give the same point, so the nearest
/// point moves continuously with `p`.
#[inline]
pub(crate) fn closest_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> (DVec3, Region) {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, Region::Corner(0));
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, Region::Corner(1));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return (a + ab * (d1 / (d1 - d3)), Region::Edge(0));
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, Region::Corner(2));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return (a + ac * (d2 / (d2 - d6)), Region::Edge(2));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * w, Region::Edge(1));
    }
    // Inside: the projection onto the plane (the caller measures the
    // distance to its patch's plane, so only the region is used).
    let n = ab.cross(ac);
    (p - n * (ap.dot(n) / n.length_squared()), Region::Face)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
        // The nearest of a fine grid of barycentric points.
        let k = 400;
        let mut best = a;
        for i in 0..=k {
            for j in 0..=(k - i) {
                let (u, v) = (i as f64 / k as f64, j as f64 / k as f64);
                let q = a + (b - a) * u + (c - a) * v;
                if (q - p).length() < (best - p).length() {
                    best = q;
                }
            }
        }
        best
    }

    #[test]
    fn every_region_gives_the_nearest_point() {
        let (a, b, c) = (
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.1, 0.0),
            DVec3::new(0.3, 1.5, 0.4),
        );
        let mut seen = Vec::new();
        let mut s = 12345u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64 * 5.0 - 2.0
        };
        for _ in 0..300 {
            let p = DVec3::new(rnd(), rnd(), rnd());
            let (q, region) = closest_on_triangle(p, a, b, c);
            let want = brute(p, a, b, c);
            // The grid's spacing is 2.5e-3 of the sides.
            assert!(
                (q - p).length() <= (want - p).length() + 1e-12,
                "{p} {region:?}"
            );
            assert!((q - want).length() < 2e-2, "{p} {region:?}");
            if !seen.contains(&region) {
                seen.push(region);
            }
        }
        assert_eq!(seen.len(), 7, "all seven regions met: {seen:?}");
    }
}
