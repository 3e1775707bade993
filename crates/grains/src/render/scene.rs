//! `scene.json`: what a run directory carries besides its frames so that a
//! later `grains movie` or `grains view` can draw it as the run saw it: the
//! dimension, the box and its periodic axes, and the walls with their
//! motions and removal times (walls removed by a run event carry the time
//! it happened, as the file is written again at the end of the run).

use super::wires::{outline_wires_at, wires_at, MeshOutline, Wire};
use crate::boundary::Wall;
use crate::dim::{Dim, D2, D3};
use crate::error::{Error, Result};
use crate::io::{write_atomic, Frame};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::path::Path;

/// The file name under a run directory.
pub const SCENE_FILE: &str = "scene.json";

/// The walls of either dimension: the analytic ones, and the mesh walls
/// by their outlines.
#[derive(Clone, Debug)]
enum Walls {
    Two(Vec<Wall<D2>>, Vec<MeshOutline<D2>>),
    Three(Vec<Wall<D3>>, Vec<MeshOutline<D3>>),
}

/// The box and walls of a run.
#[derive(Clone, Debug)]
pub struct Scene {
    /// 2 or 3.
    pub dim: usize,
    pub box_lo: [f64; 3],
    pub box_hi: [f64; 3],
    pub periodic: [bool; 3],
    walls: Walls,
}

/// The file's layout; walls are kept as JSON until the dimension is known.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    dimension: usize,
    box_lo: [f64; 3],
    box_hi: [f64; 3],
    periodic: [bool; 3],
    walls: Value,
    /// Mesh walls' outlines (absent in files written before meshes were
    /// drawn, and in scenes without meshes).
    #[serde(default, skip_serializing_if = "Value::is_null")]
    meshes: Value,
}

impl Scene {
    /// The scene of `frame`'s box with `walls`.
    pub fn new<D: Dim>(walls: &[Wall<D>], frame: &Frame) -> Self {
        // D is D2 or D3 (the only dimensions): a downcast picks the variant.
        // Mesh walls are carried by their outlines, not their triangles.
        let meshes: Vec<MeshOutline<D>> = walls.iter().filter_map(MeshOutline::of).collect();
        let drawn: Vec<Wall<D>> = walls
            .iter()
            .filter(|w| !matches!(w.shape, crate::boundary::Shape::Mesh(_)))
            .cloned()
            .collect();
        let any: Box<dyn std::any::Any> = Box::new((drawn, meshes));
        let walls = match any.downcast::<(Vec<Wall<D2>>, Vec<MeshOutline<D2>>)>() {
            Ok(w) => Walls::Two(w.0, w.1),
            Err(any) => {
                let w = any
                    .downcast::<(Vec<Wall<D3>>, Vec<MeshOutline<D3>>)>()
                    .expect("walls are 2D or 3D");
                Walls::Three(w.0, w.1)
            }
        };
        Scene {
            dim: D::D,
            box_lo: frame.box_lo,
            box_hi: frame.box_hi,
            periodic: frame.periodic,
            walls,
        }
    }

    /// A scene with the box of `frame` and no walls (a run directory
    /// without scene.json, a DSMC run).
    pub fn bare(frame: &Frame) -> Self {
        Scene {
            dim: frame.dim,
            box_lo: frame.box_lo,
            box_hi: frame.box_hi,
            periodic: frame.periodic,
            walls: if frame.dim == 3 {
                Walls::Three(Vec::new(), Vec::new())
            } else {
                Walls::Two(Vec::new(), Vec::new())
            },
        }
    }

    /// The walls present at time `t`, cut to the box.
    pub fn wires(&self, t: f64) -> Vec<Wire> {
        match &self.walls {
            Walls::Two(w, m) => [
                wires_at(w, t, self.box_lo, self.box_hi),
                outline_wires_at(m, t),
            ],
            Walls::Three(w, m) => [
                wires_at(w, t, self.box_lo, self.box_hi),
                outline_wires_at(m, t),
            ],
        }
        .concat()
    }

    /// Gives a frame read back from VTK (which has no box) this scene's
    /// dimension, box and periodic axes.
    pub fn apply(&self, frame: &mut Frame) {
        frame.dim = self.dim;
        frame.box_lo = self.box_lo;
        frame.box_hi = self.box_hi;
        frame.periodic = self.periodic;
    }

    /// Writes `dir/scene.json` atomically.
    pub fn write(&self, dir: &Path) -> Result<()> {
        let (walls, meshes) = match &self.walls {
            Walls::Two(w, m) => (serde_json::to_value(w), serde_json::to_value(m)),
            Walls::Three(w, m) => (serde_json::to_value(w), serde_json::to_value(m)),
        };
        let walls = walls.expect("walls always serialize");
        let meshes = match meshes.expect("outlines always serialize") {
            Value::Array(m) if m.is_empty() => Value::Null,
            m => m,
        };
        let file = SceneFile {
            dimension: self.dim,
            box_lo: self.box_lo,
            box_hi: self.box_hi,
            periodic: self.periodic,
            walls,
            meshes,
        };
        let text = serde_json::to_string_pretty(&file).expect("scene always serializes");
        write_atomic(&dir.join(SCENE_FILE), text.as_bytes())
    }

    /// Reads `dir/scene.json`; `None` when the run directory has none.
    pub fn read(dir: &Path) -> Result<Option<Self>> {
        let path = dir.join(SCENE_FILE);
        let text = match std::fs::read_to_string(&path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(Error::io(&path, e)),
        };
        let bad = |e: serde_json::Error| Error::input(format!("{}: {e}", path.display()));
        let file: SceneFile = serde_json::from_str(&text).map_err(bad)?;
        let meshes = match file.meshes {
            Value::Null => Value::Array(Vec::new()),
            m => m,
        };
        let walls = match file.dimension {
            2 => Walls::Two(
                serde_json::from_value(file.walls).map_err(bad)?,
                serde_json::from_value(meshes).map_err(bad)?,
            ),
            3 => Walls::Three(
                serde_json::from_value(file.walls).map_err(bad)?,
                serde_json::from_value(meshes).map_err(bad)?,
            ),
            d => {
                return Err(Error::input(format!(
                    "{}: dimension = {d}; allowed: 2, 3",
                    path.display()
                )))
            }
        };
        Ok(Some(Scene {
            dim: file.dimension,
            box_lo: file.box_lo,
            box_hi: file.box_hi,
            periodic: file.periodic,
            walls,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::{Motion, Shape};
    use crate::io::atomic::tests::scratch_dir;
    use crate::io::frame::tests::sample_2d;
    use glam::{DVec2, DVec3};

    #[test]
    fn scene_round_trips_and_bad_files_are_named() {
        let dir = scratch_dir("scene");
        assert!(Scene::read(&dir).unwrap().is_none());
        let floor = Wall::<D2>::new(
            "floor",
            Shape::Segment {
                a: DVec2::new(1.0, 0.5),
                b: DVec2::new(4.0, 0.5),
            },
            Motion::Translate {
                velocity: DVec2::new(0.0, 2.0),
            },
        )
        .unwrap()
        .with_remove_at(3.0)
        .unwrap();
        let scene = Scene::new(&[floor], &sample_2d());
        scene.write(&dir).unwrap();
        let back = Scene::read(&dir).unwrap().unwrap();
        assert_eq!(back.dim, 2);
        assert_eq!(back.box_hi, sample_2d().box_hi);
        // The floor moved up by v t = 2 at t = 1, and is gone at t = 3.
        assert_eq!(
            back.wires(1.0),
            vec![Wire::Line {
                points: vec![[1.0, 2.5, 0.0], [4.0, 2.5, 0.0]]
            }]
        );
        assert!(back.wires(3.0).is_empty());
        std::fs::write(dir.join(SCENE_FILE), "{\"dimension\": 4}").unwrap();
        let err = Scene::read(&dir).unwrap_err().to_string();
        assert!(err.contains("scene.json"), "{err}");
    }

    #[test]
    fn a_mesh_wall_is_drawn_by_its_outline_turning_with_it() {
        use crate::boundary::{Mesh, MeshPlacement};
        // One unit square of two triangles in z = 0, turning about z at
        // π/2 per second about the origin.
        let tris = [
            [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.]],
            [[0., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
        ];
        let mesh = Mesh::new("square.stl", &tris, &MeshPlacement::default()).unwrap();
        let blade = Wall::<D3>::new(
            "blade",
            Shape::Mesh(std::sync::Arc::new(mesh)),
            Motion::Rotate {
                center: DVec3::ZERO,
                omega: DVec3::new(0.0, 0.0, std::f64::consts::FRAC_PI_2),
            },
        )
        .unwrap()
        .with_remove_at(2.0)
        .unwrap();
        let dir = scratch_dir("scene-mesh");
        let frame = Frame {
            dim: 3,
            box_lo: [-2.0; 3],
            box_hi: [2.0; 3],
            ..sample_2d()
        };
        Scene::new(&[blade], &frame).write(&dir).unwrap();
        let back = Scene::read(&dir).unwrap().unwrap();
        // The outline is the square's border (its diagonal is flat), one
        // closed loop; at t = 1 it has turned a quarter: x ∈ [−1, 0].
        let wires = back.wires(1.0);
        assert_eq!(wires.len(), 1, "{wires:?}");
        let Wire::Line { points } = &wires[0] else {
            panic!("{wires:?}")
        };
        assert_eq!(points.len(), 5);
        assert_eq!(points.first(), points.last());
        for p in points {
            assert!(p[0] > -1.0 - 1e-12 && p[0] < 1e-12, "{p:?}");
            assert!(p[1] > -1e-12 && p[1] < 1.0 + 1e-12, "{p:?}");
        }
        let perimeter: f64 = points
            .windows(2)
            .map(|w| {
                (0..3)
                    .map(|k| (w[1][k] - w[0][k]).powi(2))
                    .sum::<f64>()
                    .sqrt()
            })
            .sum();
        assert!((perimeter - 4.0).abs() < 1e-12);
        assert!(back.wires(2.0).is_empty());
    }
}
