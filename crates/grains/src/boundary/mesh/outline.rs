//! A mesh's outline for pictures and the viewer: its feature edges, the
//! edges a CAD viewer draws (open borders and creases), chained into
//! polylines in the wall's reference frame.
//!
//! Drawing every triangle of a 10⁵-triangle mesh would bury the grains; a
//! faceted cone's or drum's gentle bends (a few degrees from facet to
//! facet) are not creases, so a hopper draws as its rims and a mixer blade
//! as its edges.

use super::Mesh;
use glam::DVec3;
use std::collections::HashMap;

/// Neighbouring triangles whose normals differ by more than this (degrees)
/// meet at a crease, which is drawn.
pub const CREASE_DEG: f64 = 30.0;

impl Mesh {
    /// The feature edges as polylines (reference frame): every edge used by
    /// one triangle only (a border) or by triangles whose normals differ by
    /// more than `crease_deg` either way round (meshes are two-sided, so a
    /// flipped winding is no crease), or by more than two triangles.
    pub fn outline(&self, crease_deg: f64) -> Vec<Vec<DVec3>> {
        let cos_crease = crease_deg.to_radians().cos();
        let mut users: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
        for (t, ids) in self.tris.iter().enumerate() {
            for k in 0..3 {
                let (i, j) = (ids[k], ids[(k + 1) % 3]);
                users
                    .entry((i.min(j), i.max(j)))
                    .or_default()
                    .push(t as u32);
            }
        }
        let mut edges: Vec<(u32, u32)> = users
            .into_iter()
            .filter(|(_, ts)| match ts[..] {
                [a, b] => {
                    let (na, nb) = (self.normals[a as usize], self.normals[b as usize]);
                    na.dot(nb).abs() < cos_crease
                }
                _ => true,
            })
            .map(|(e, _)| e)
            .collect();
        // Sorted, so that the same mesh always draws the same lines.
        edges.sort_unstable();
        chain(&edges)
            .into_iter()
            .map(|line| line.iter().map(|&v| self.vertices[v as usize]).collect())
            .collect()
    }
}

/// Joins edges that meet end to end into polylines (a vertex where more or
/// fewer than two chosen edges meet ends a line); a closed loop repeats its
/// first vertex.
fn chain(edges: &[(u32, u32)]) -> Vec<Vec<u32>> {
    let mut at: HashMap<u32, Vec<usize>> = HashMap::new();
    for (k, &(a, b)) in edges.iter().enumerate() {
        at.entry(a).or_default().push(k);
        at.entry(b).or_default().push(k);
    }
    let mut used = vec![false; edges.len()];
    let through = |v: u32| at[&v].len() == 2;
    let mut lines = Vec::new();
    // Open lines first, from their ends; then what is left are loops.
    let starts = edges
        .iter()
        .enumerate()
        .flat_map(|(k, &(a, b))| [(k, a), (k, b)])
        .filter(|&(_, v)| !through(v))
        .chain(edges.iter().enumerate().map(|(k, &(a, _))| (k, a)));
    for (k, v0) in starts {
        if used[k] {
            continue;
        }
        let mut line = vec![v0];
        let (mut k, mut v) = (k, v0);
        loop {
            used[k] = true;
            let (a, b) = edges[k];
            v = if a == v { b } else { a };
            line.push(v);
            if !through(v) {
                break;
            }
            match at[&v].iter().find(|&&e| !used[e]) {
                Some(&e) => k = e,
                None => break,
            }
        }
        lines.push(line);
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::mesh::MeshPlacement;

    /// An open box (five faces of the unit cube, no lid), two triangles a
    /// face.
    fn open_box() -> Mesh {
        let q = |a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]| [[a, b, c], [a, c, d]];
        let faces = [
            q([0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]),
            q([0., 0., 0.], [1., 0., 0.], [1., 0., 1.], [0., 0., 1.]),
            q([0., 1., 0.], [1., 1., 0.], [1., 1., 1.], [0., 1., 1.]),
            q([0., 0., 0.], [0., 1., 0.], [0., 1., 1.], [0., 0., 1.]),
            q([1., 0., 0.], [1., 1., 0.], [1., 1., 1.], [1., 0., 1.]),
        ];
        let tris: Vec<[[f64; 3]; 3]> = faces.into_iter().flatten().collect();
        Mesh::new("box", &tris, &MeshPlacement::default()).unwrap()
    }

    fn length(lines: &[Vec<DVec3>]) -> f64 {
        lines
            .iter()
            .flat_map(|l| l.windows(2).map(|w| (w[1] - w[0]).length()))
            .sum()
    }

    #[test]
    fn an_open_box_draws_its_twelve_cube_edges_and_no_diagonal() {
        let lines = open_box().outline(CREASE_DEG);
        // 4 floor edges + 4 upright edges (creases) + 4 rim edges (border):
        // the cube's 12 unit edges; the faces' diagonals are flat, not drawn.
        assert!((length(&lines) - 12.0).abs() < 1e-12, "{lines:?}");
        // Every corner of the box meets three drawn edges, so each edge is
        // a line of its own, along an axis (no diagonal).
        assert_eq!(lines.len(), 12);
        for l in &lines {
            let d = l[1] - l[0];
            assert_eq!(l.len(), 2);
            assert_eq!(d.abs().max_element(), d.abs().element_sum(), "{l:?}");
        }
    }

    #[test]
    fn gentle_bends_are_not_creases_but_sharp_ones_are() {
        // A strip folded by 10° along x = 1: a 30° crease angle hides the
        // fold, a 5° one draws it (length 1 more).
        let t = 10f64.to_radians();
        let (c, s) = (t.cos(), t.sin());
        let tris = [
            [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.]],
            [[0., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
            [[1., 0., 0.], [1. + c, 0., s], [1. + c, 1., s]],
            [[1., 0., 0.], [1. + c, 1., s], [1., 1., 0.]],
        ];
        let m = Mesh::new("strip", &tris, &MeshPlacement::default()).unwrap();
        // The border: two unit ends and four unit sides.
        assert!((length(&m.outline(30.0)) - 6.0).abs() < 1e-9);
        assert!((length(&m.outline(5.0)) - 7.0).abs() < 1e-9);
    }

    #[test]
    fn the_shipped_cone_hopper_is_closed_around_and_outlined_by_its_rims() {
        // An unclosed seam (vertices at 0 and 2π that differ by rounding)
        // would show as a line from rim to rim, and would push grains there
        // twice; the outline is the two rims only, each a regular 96-gon.
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../scenarios/meshes/cone-hopper.stl");
        let tris = crate::io::stl::read_stl(&path).unwrap();
        let m = Mesh::new("cone-hopper.stl", &tris, &MeshPlacement::default()).unwrap();
        let lines = m.outline(CREASE_DEG);
        assert_eq!(lines.len(), 2, "{} lines", lines.len());
        let mut radii = Vec::new();
        for l in &lines {
            assert_eq!(l.len(), 97);
            assert_eq!(l.first(), l.last());
            let r = l[0].truncate().length();
            let sides = 96.0;
            let perimeter = 2.0 * sides * r * (std::f64::consts::PI / sides).sin();
            assert!((length(std::slice::from_ref(l)) - perimeter).abs() < 1e-5 * perimeter);
            radii.push(r);
        }
        radii.sort_by(f64::total_cmp);
        // tools/make_mesh_stl.py: outlet radius 3, top radius 12 (float32).
        assert!((radii[0] - 3.0).abs() < 1e-6 && (radii[1] - 12.0).abs() < 1e-5);
    }
}
