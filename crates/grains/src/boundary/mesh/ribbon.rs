//! A 2D mesh wall: polylines in the plane z = 0, extruded into a ribbon of
//! triangles across it so that the 3D mesh's contact rules hold unchanged.
//!
//! A disk lies in z = 0, and every point of the ribbon is farther from it
//! than the point of the same (x, y) at z = 0, so each patch's nearest
//! feature is a point of the polyline: a face is a segment, a vertical
//! edge a vertex. Collinear segments form one patch (a straight run pushes
//! once and keeps its spring across the joints), a convex corner pushes
//! once, a concave corner from both sides, as in 3D.

use super::{Mesh, MeshPlacement};
use crate::io::polyline::Polyline;

impl Mesh {
    /// The ribbon of `lines` (their points placed by `place` in the plane
    /// z = 0: scaled, turned about z, shifted); `source` names the file in
    /// messages. The ribbon reaches half the mean segment length above and
    /// below the plane, so the triangles' grid cells are about a segment
    /// wide (its height does not matter to a disk in the plane).
    pub fn from_polylines(
        source: &str,
        lines: &[Polyline],
        place: &MeshPlacement,
    ) -> Result<Self, String> {
        let placed: Vec<Vec<glam::DVec3>> = lines
            .iter()
            .map(|l| l.iter().map(|&[x, y]| place.apply([x, y, 0.0])).collect())
            .collect();
        place.check()?;
        for (i, l) in placed.iter().enumerate() {
            if l.len() < 2 {
                return Err(format!("polyline {i} has fewer than two points"));
            }
            if let Some(j) = l.windows(2).position(|w| (w[1] - w[0]).length() <= 0.0) {
                return Err(format!(
                    "polyline {i}: points {j} and {} coincide once placed",
                    j + 1
                ));
            }
        }
        let segments = placed.iter().map(|l| l.len() - 1).sum::<usize>();
        let total: f64 = placed
            .iter()
            .flat_map(|l| l.windows(2).map(|w| (w[1] - w[0]).length()))
            .sum();
        let h = 0.5 * total / segments as f64;
        let mut tris = Vec::with_capacity(2 * segments);
        for l in &placed {
            for w in l.windows(2) {
                let at = |p: glam::DVec3, z: f64| [p.x, p.y, z];
                let (a0, b0, b1, a1) = (at(w[0], -h), at(w[1], -h), at(w[1], h), at(w[0], h));
                tris.push([a0, b0, b1]);
                tris.push([a0, b1, a1]);
            }
        }
        // Placing again would move the points twice.
        Mesh::new(source, &tris, &MeshPlacement::default())
    }
}
