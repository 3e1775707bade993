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
}

impl<D: Dim> ContactLists<D> for Md<D> {
    fn pair_contacts(&self) -> ContactList<D> {
        self.contact_list()
    }
    fn wall_contacts(&self) -> WallContactList<D> {
        self.wall_contact_list()
    }
}
