//! The MD engine seen through [`GrainView`], the read-only view that
//! measurements take.

use super::Md;
use crate::dim::Dim;
use crate::view::{
    ContactList, ContactLists, GrainView, Grains, MeshLoad, MeshLoads, WallContactList,
};

impl<D: Dim> Md<D> {
    /// The engine's grains, walls and loads now, read-only.
    pub fn view(&self) -> GrainView<'_, D> {
        GrainView {
            step: self.step,
            time: self.time,
            dt: self.settings.dt,
            domain: &self.domain,
            gravity: self.settings.gravity,
            walls: &self.walls,
            grains: Grains::owned(&self.particles),
            contacts: self.stats.contacts,
            loads: self,
            lists: self,
        }
    }
}

impl<D: Dim> MeshLoads for Md<D> {
    fn mesh_loads(&self) -> Vec<MeshLoad> {
        Md::mesh_loads(self)
    }

    /// From the contact list: the law on the present state, as the engine
    /// evaluates it.
    fn contact_virial(&self) -> Option<([[f64; 3]; 3], usize)> {
        let c = self.contact_list();
        let mut w = [[0.0; 3]; 3];
        for (r, f) in c.branch.iter().zip(&c.force) {
            let (r, f) = (D::to_xyz(*r), D::to_xyz(*f));
            for (a, row) in w.iter_mut().enumerate() {
                for (b, cell) in row.iter_mut().enumerate() {
                    *cell += r[a] * f[b];
                }
            }
        }
        Some((w, c.ids.len()))
    }
}

impl<D: Dim> ContactLists<D> for Md<D> {
    fn pair_contacts(&self) -> ContactList<D> {
        self.contact_list()
    }
    fn wall_contacts(&self) -> WallContactList<D> {
        self.wall_contact_list()
    }
}
