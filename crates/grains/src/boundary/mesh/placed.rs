//! A mesh wall at one time: its contacts with a grain, carried from the
//! reference frame by the pose worked out once per force evaluation.

use super::{Mesh, MeshCandidates, MeshScratch};
use crate::boundary::geom::{from3, to3};
use crate::boundary::{Motion, PlacedWall, QuickTest, Shape, WallContact};
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
    /// that is not a mesh. With `cached` (the pass's lists and the grain's
    /// index), the grain's own list of triangles is read when it still
    /// serves, the mesh's grid otherwise: the same contacts either way.
    pub fn mesh_contacts(
        &self,
        p: D::V,
        r: f64,
        cached: Option<(&MeshCandidates, usize)>,
        scratch: &mut MeshScratch,
        out: &mut Vec<(u32, WallContact<D>)>,
    ) {
        out.clear();
        let (Some(mesh), Some(pose), true) = (self.mesh(), &self.pose, self.active) else {
            return;
        };
        let local = pose.invert(to3::<D>(p));
        match cached.and_then(|(c, i)| c.list(i, local, r)) {
            Some(list) => mesh.touches_among(local, r, list, scratch),
            None => {
                if let Some(QuickTest::Reach(b)) = &self.quick {
                    if b.misses(local, r) {
                        return;
                    }
                }
                mesh.touches(local, r, scratch);
            }
        }
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

    /// Each grain's candidate triangles of this mesh wall for the grains
    /// at `pos` with radii `radius` (those for which `skip` holds get
    /// none), good while a grain stays within `margin` of where it is now
    /// in the mesh's frame ([`MeshCandidates`]); `None` for a removed wall,
    /// one that is not a mesh, or one that moves (a moving mesh carries its
    /// grains across its frame, so their lists would go stale within steps
    /// and cost more than the grid lookups they save).
    pub fn mesh_candidates(
        &self,
        pos: &[D::V],
        radius: &[f64],
        skip: impl Fn(usize) -> bool + Sync,
        margin: f64,
    ) -> Option<MeshCandidates> {
        let (Some(mesh), Some(pose), true) = (self.mesh(), &self.pose, self.active) else {
            return None;
        };
        if !matches!(self.wall.motion, Motion::Fixed) {
            return None;
        }
        let local = |i: usize| pose.invert(to3::<D>(pos[i]));
        Some(MeshCandidates::build(mesh, local, radius, skip, margin))
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
