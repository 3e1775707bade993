//! Remakes the fixed mesh walls' per-grain triangle lists after each neighbour-list rebuild.
//!
//! The lists are [`MeshCandidates`]. The margin is half the Verlet skin:
//! the neighbour list is rebuilt as soon as a grain has moved farther
//! than that, so a still mesh's lists serve every grain until the rebuild
//! remakes them, and the grid is searched only then. A grain whose list
//! no longer serves (its radius grew, or it was moved from outside) is
//! looked up in the grid, as without lists. Moving meshes get none: they
//! carry their grains across their frame, so lists would go stale within
//! steps. The lists never change a contact (see [`MeshCandidates`]), only
//! which triangles are read.

use crate::boundary::{MeshCandidates, PlacedWall};
use crate::dim::Dim;
use crate::particles::Particles;

/// Each mesh wall's lists, and the rebuild they were made after.
#[derive(Clone, Debug, Default)]
pub(crate) struct MeshLists {
    /// Per wall (`None` for walls that are not meshes); empty when no wall
    /// is a mesh.
    walls: Vec<Option<MeshCandidates>>,
    /// The neighbour-list build and grain count they were made at.
    made_at: Option<(u64, usize)>,
}

impl MeshLists {
    /// Makes the lists anew unless they were made after neighbour-list
    /// build `build` with the same grains (indices may change at a
    /// rebuild, and lists are kept by index).
    pub(crate) fn refresh<D: Dim>(
        &mut self,
        walls: &[PlacedWall<D>],
        p: &Particles<D>,
        build: u64,
        skin: f64,
    ) {
        let n = p.n_owned();
        if self.made_at == Some((build, n)) && self.walls.len() == walls.len() {
            return;
        }
        self.made_at = Some((build, n));
        self.walls.clear();
        if walls.iter().all(|w| w.mesh().is_none()) {
            return;
        }
        let (pos, radius, frozen) = (&p.pos[..n], &p.radius[..n], &p.frozen[..n]);
        self.walls = walls
            .iter()
            .map(|w| w.mesh_candidates(pos, radius, |i| frozen[i], 0.5 * skin))
            .collect();
    }

    /// The lists of each wall, by wall index (empty without mesh walls).
    pub(crate) fn walls(&self) -> &[Option<MeshCandidates>] {
        &self.walls
    }
}
