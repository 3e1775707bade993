//! A mesh wall at one time: its contacts with a grain, carried from the
//! reference frame by the pose worked out once per force evaluation.

use super::{Mesh, MeshScratch};
use crate::boundary::geom::{from3, to3};
use crate::boundary::{PlacedWall, QuickTest, Shape, WallContact};
use crate::dim::Dim;
use glam::DVec3;

impl<D: Dim> PlacedWall<'_, D> {
    /// The mesh, when this wall is one.
    #[inline]
    pub fn mesh(&self) -> Option<&Mesh> {
        match &self.wall.shape {
            Shape::Mesh(m) => Some(m),
            _ => None,
        }
    }

    /// The contacts of a grain (centre `p`, radius `r`) with this mesh
    /// wall, each with the patch that keys its tangential spring, in patch
    /// order, into `out` (cleared first). Nothing for a removed wall or one
    /// that is not a mesh.
    pub fn mesh_contacts(
        &self,
        p: D::V,
        r: f64,
        scratch: &mut MeshScratch,
        out: &mut Vec<(u32, WallContact<D>)>,
    ) {
        out.clear();
        let (Some(mesh), Some(pose), true) = (self.mesh(), &self.pose, self.active) else {
            return;
        };
        let local = pose.invert(to3::<D>(p));
        if let Some(QuickTest::Reach(b)) = &self.quick {
            if b.misses(local, r) {
                return;
            }
        }
        mesh.touches(local, r, scratch);
        for m in scratch.touches() {
            let point = from3::<D>(pose.apply(m.touch.point));
            out.push((
                m.patch,
                WallContact {
                    overlap: m.touch.overlap,
                    normal: from3::<D>(pose.turn(m.touch.normal)),
                    point,
                    velocity: match self.velocity {
                        Some(v) => v,
                        None => self.wall.motion.velocity_at(point, self.t),
                    },
                },
            ));
        }
    }

    /// Where a mesh's load point ([`Mesh::load_point`]) is at this time;
    /// `None` for walls that are not meshes.
    pub fn load_point(&self) -> Option<DVec3> {
        let (Shape::Mesh(m), Some(pose)) = (&self.wall.shape, &self.pose) else {
            return None;
        };
        Some(pose.apply(m.load_point()))
    }
}
