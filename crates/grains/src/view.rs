//! A read-only view of an engine's grains at one step: what measurements
//! read, borrowed from whichever engine holds the state (the MD engine, the
//! GPU engine's host copy, a decomposed engine gathered on rank 0), so that
//! a measurement is written once for all of them.
//!
//! It is plain borrowed slices of the owned grains plus the step, time,
//! box, gravity and walls; the loads on mesh walls, which cost a pass over
//! the walls, are worked out only when a measurement asks for them.

use crate::boundary::Wall;
use crate::dim::Dim;
use crate::domain::Domain;
use crate::io::Frame;
use crate::particles::Particles;
use glam::DVec3;

/// One mesh wall's load at the time of the last force evaluation.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshLoad {
    /// The wall's index among the engine's walls.
    pub wall: usize,
    /// The force the grains exert on it (N, or the scenario's units).
    pub force: DVec3,
    /// The torque about its load point, where that point is now.
    pub torque: DVec3,
    /// The load point at that time.
    pub point: DVec3,
}

/// An engine that can tell the loads the grains put on its mesh walls,
/// and the forces of its contacts.
pub trait MeshLoads {
    /// What the grains put on each mesh wall at the last force evaluation
    /// (walls that are not meshes are left out).
    fn mesh_loads(&self) -> Vec<MeshLoad>;

    /// The contact virial Σ r ⊗ f of the grain–grain contacts now (r the
    /// branch vector from the second grain's image to the first, f the
    /// force on the first; row r, column f) and their number; `None` where
    /// the engine cannot tell.
    fn contact_virial(&self) -> Option<([[f64; 3]; 3], usize)> {
        None
    }
}

/// The grain–grain contacts of an engine now: the touching pairs of its
/// neighbour list, in list order.
#[derive(Clone, Debug, Default)]
pub struct ContactList<D: Dim> {
    /// Ids of the two grains of each contact.
    pub ids: Vec<[u64; 2]>,
    /// Overlap r_i + r_j − |x_i − x_j| (m), positive (down to −δ_c for a
    /// JKR contact kept beyond touching).
    pub overlap: Vec<f64>,
    /// Unit normal from the second grain to the first.
    pub normal: Vec<D::V>,
    /// Branch vector from the second grain (its image across a periodic
    /// or sliding boundary) to the first.
    pub branch: Vec<D::V>,
    /// Force on the first grain (the second gets its negative times its own
    /// mass factor under the mass-normalized law of Gallas, Herrmann &
    /// Sokolowski 1992).
    pub force: Vec<D::V>,
}

/// The touching grain–wall pairs, in grain order and then wall order.
#[derive(Clone, Debug, Default)]
pub struct WallContactList<D: Dim> {
    /// Id of the grain of each contact.
    pub ids: Vec<u64>,
    /// Index of the wall among the engine's walls.
    pub wall: Vec<usize>,
    /// Contact point on the wall surface.
    pub point: Vec<D::V>,
    /// Unit normal from the wall towards the grain.
    pub normal: Vec<D::V>,
    /// Overlap (radius minus the distance to the wall).
    pub overlap: Vec<f64>,
    /// Force on the grain.
    pub force: Vec<D::V>,
}

/// An engine that can list its contacts now, with the force the contact
/// law gives on the present state (springs read, not advanced).
pub trait ContactLists<D: Dim> {
    /// Every grain–grain contact.
    fn pair_contacts(&self) -> ContactList<D>;
    /// Every grain–wall contact.
    fn wall_contacts(&self) -> WallContactList<D>;
}

/// The owned grains, one entry per grain in the engine's memory order (not
/// id order: measurements key their running state by `id`).
pub struct Grains<'a, D: Dim> {
    pub id: &'a [u64],
    /// User type (1-based, as in LAMMPS).
    pub kind: &'a [u32],
    pub pos: &'a [D::V],
    pub vel: &'a [D::V],
    pub omega: &'a [D::A],
    /// The total force of the last force evaluation (contacts, walls and
    /// gravity).
    pub force: &'a [D::V],
    pub radius: &'a [f64],
    pub mass: &'a [f64],
    pub frozen: &'a [bool],
}

impl<'a, D: Dim> Grains<'a, D> {
    /// The owned grains of a particle store (its ghosts left out).
    pub fn owned(p: &'a Particles<D>) -> Self {
        let n = p.n_owned();
        Self {
            id: &p.id[..n],
            kind: &p.kind[..n],
            pos: &p.pos[..n],
            vel: &p.vel[..n],
            omega: &p.omega[..n],
            force: &p.force[..n],
            radius: &p.radius[..n],
            mass: &p.mass[..n],
            frozen: &p.frozen[..n],
        }
    }

    /// The number of grains.
    pub fn len(&self) -> usize {
        self.id.len()
    }

    pub fn is_empty(&self) -> bool {
        self.id.is_empty()
    }
}

/// An engine's state at one step as measurements read it.
pub struct GrainView<'a, D: Dim> {
    /// Steps taken since step 0.
    pub step: u64,
    /// Simulated time (s).
    pub time: f64,
    /// The time step (s).
    pub dt: f64,
    pub domain: &'a Domain<D>,
    /// The acceleration of gravity.
    pub gravity: D::V,
    pub walls: &'a [Wall<D>],
    pub grains: Grains<'a, D>,
    /// Grain–grain and grain–wall contacts found by the last force
    /// evaluation.
    pub contacts: usize,
    /// Where the loads on the mesh walls come from when asked.
    pub loads: &'a dyn MeshLoads,
    /// Where the contact lists come from when asked.
    pub lists: &'a dyn ContactLists<D>,
}

impl<D: Dim> GrainView<'_, D> {
    /// What the grains put on each mesh wall at the last force evaluation.
    pub fn mesh_loads(&self) -> Vec<MeshLoad> {
        self.loads.mesh_loads()
    }

    /// The grain–grain contacts now (a pass over the neighbour list).
    pub fn pair_contacts(&self) -> ContactList<D> {
        self.lists.pair_contacts()
    }

    /// The grain–wall contacts now (a pass over the grains and walls).
    pub fn wall_contacts(&self) -> WallContactList<D> {
        self.lists.wall_contacts()
    }

    /// The contact virial of the grain–grain contacts now and their number
    /// ([`MeshLoads::contact_virial`]).
    pub fn contact_virial(&self) -> Option<([[f64; 3]; 3], usize)> {
        self.loads.contact_virial()
    }

    /// A neutral snapshot of the grains for the writers (2D boxes get a unit
    /// z extent, as LAMMPS writes them).
    pub fn frame(&self) -> Frame {
        let p = &self.grains;
        let mut periodic = [false; 3];
        periodic[..D::D].copy_from_slice(&self.domain.periodic[..D::D]);
        let (mut lo, mut hi) = (D::to_xyz(self.domain.lo), D::to_xyz(self.domain.hi));
        if D::D == 2 {
            lo[2] = -0.5;
            hi[2] = 0.5;
        }
        Frame {
            step: self.step,
            time: self.time,
            dim: D::D,
            box_lo: lo,
            box_hi: hi,
            periodic,
            id: p.id.to_vec(),
            kind: p.kind.to_vec(),
            pos: p.pos.iter().map(|&x| D::to_xyz(x)).collect(),
            vel: p.vel.iter().map(|&x| D::to_xyz(x)).collect(),
            omega: p.omega.iter().map(|&x| D::ang_to_xyz(x)).collect(),
            radius: p.radius.to_vec(),
            body: None,
            orientation: None,
            mass: Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::D2;
    use crate::particles::ParticleRecord;
    use glam::DVec2;

    /// An engine without mesh walls.
    struct NoLoads;
    impl MeshLoads for NoLoads {
        fn mesh_loads(&self) -> Vec<MeshLoad> {
            Vec::new()
        }
    }
    impl<D: Dim> ContactLists<D> for NoLoads {
        fn pair_contacts(&self) -> ContactList<D> {
            ContactList::default()
        }
        fn wall_contacts(&self) -> WallContactList<D> {
            WallContactList::default()
        }
    }

    /// Two owned disks and a ghost copy of the first: the view holds the
    /// two owned ones (a ghost read as a grain would be counted twice), and
    /// its frame gives a 2D box the unit z extent LAMMPS writes.
    #[test]
    fn a_view_holds_the_owned_grains_and_frames_them() {
        let mut p = Particles::<D2>::new();
        p.push_record(ParticleRecord::new(7, DVec2::new(0.25, 0.5), 0.1, 1.0, 0.1));
        p.push_record(ParticleRecord::new(3, DVec2::new(0.75, 0.5), 0.2, 2.0, 0.1));
        p.push_ghost(ParticleRecord::new(7, DVec2::new(1.25, 0.5), 0.1, 1.0, 0.1));
        let domain = Domain::<D2>::new(DVec2::ZERO, DVec2::ONE, [true, false, false]);
        let view = GrainView {
            step: 4,
            time: 0.5,
            dt: 0.125,
            domain: &domain,
            gravity: DVec2::new(0.0, -9.81),
            walls: &[],
            grains: Grains::owned(&p),
            contacts: 0,
            loads: &NoLoads,
            lists: &NoLoads,
        };
        assert_eq!(view.grains.len(), 2);
        assert_eq!(view.grains.mass, &[1.0, 2.0]);
        let f = view.frame();
        assert_eq!((f.step, f.time, f.dim), (4, 0.5, 2));
        assert_eq!(f.id, vec![7, 3]);
        assert_eq!(f.pos, vec![[0.25, 0.5, 0.0], [0.75, 0.5, 0.0]]);
        assert_eq!((f.box_lo, f.box_hi), ([0.0, 0.0, -0.5], [1.0, 1.0, 0.5]));
        assert_eq!(f.periodic, [true, false, false]);
        assert!(view.mesh_loads().is_empty());
        assert!(view.pair_contacts().ids.is_empty() && view.wall_contacts().ids.is_empty());
    }
}
