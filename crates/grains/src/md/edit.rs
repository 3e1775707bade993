//! Setting the grains' positions and velocities from outside the engine
//! (the Python bindings' setters), keeping the neighbour list, the springs
//! and the integrator's history consistent with the new state.

use super::Md;
use crate::dim::Dim;
use crate::error::{Error, Result};
use crate::integrate::{gear5, Integrator};

impl<D: Dim> Md<D> {
    /// Store indices of the owned grains in ascending id order.
    pub fn id_order(&self) -> Vec<u32> {
        id_order(&self.particles.id[..self.particles.n_owned()])
    }

    /// Replaces the positions and/or velocities of the owned grains (each
    /// slice in ascending id order) and restarts the engine from that state
    /// as [`Md::new`] starts a fresh one: the grains are put in id order,
    /// positions wrapped, sorted spatially, the neighbour list rebuilt, the
    /// forces evaluated without stretching any spring, and the Gear history
    /// set up anew. Stretched springs of pairs (and grain–wall contacts)
    /// that still touch are kept; the others are dropped. At step 0 the
    /// engine is then the one a scenario placing these grains in id order
    /// builds, bit for bit. Fails (input error) on a wrong length, a
    /// non-finite number, or a state whose overlaps exceed the stability
    /// limit; the new state is then kept as given.
    pub fn set_state(&mut self, pos: Option<&[D::V]>, vel: Option<&[D::V]>) -> Result<()> {
        let n = self.particles.n_owned();
        if n != self.particles.len() {
            return Err(Error::input(
                "grains with ghosts (a distributed run) cannot be set from outside",
            ));
        }
        for (what, v) in [("positions", pos), ("velocities", vel)] {
            let Some(v) = v else { continue };
            if v.len() != n {
                return Err(Error::input(format!(
                    "{what}: {} rows for {n} grains",
                    v.len()
                )));
            }
            if let Some(k) = v.iter().position(|&x| !D::is_finite(x)) {
                return Err(Error::input(format!(
                    "{what}: row {k} is not finite: every component must be a finite number"
                )));
            }
        }
        // Springs keyed by grain ids survive the reordering below.
        let saved = self.save_springs();
        let saved_rolling = self.save_rolling();
        let order = self.id_order();
        self.particles.permute(&order);
        self.wall_springs.permute(&order);
        self.mesh_springs.permute(&order);
        self.wall_rolling.permute(&order);
        self.mesh_rolling.permute(&order);
        if let Some(p) = pos {
            self.particles.pos[..n].copy_from_slice(p);
        }
        if let Some(v) = vel {
            self.particles.vel[..n].copy_from_slice(v);
        }
        // The list still indexes the old order: let the rebuild carry no
        // spring, then put the saved ones back by id.
        self.springs.iter_mut().for_each(|s| *s = D::zero());
        self.rolling.iter_mut().for_each(|s| *s = D::zero());
        self.rebuilds_since_sort = 0;
        self.rebuild_neighbors()?;
        self.restore_springs(saved);
        self.restore_rolling(saved_rolling);
        self.compute_forces(false);
        if self.settings.integrator == Integrator::Gear5 {
            gear5::initialize(&mut self.particles, self.settings.dt);
        }
        self.check_stability().map_err(|e| match e {
            Error::Unstable(m) => Error::input(format!("the new state is unusable: {m}")),
            other => other,
        })
    }
}

/// Indices of `ids` in ascending id order. Ids are almost always a dense
/// range (1..=n from a placement), which a linear scatter sorts; anything
/// else is sorted.
pub fn id_order(ids: &[u64]) -> Vec<u32> {
    let n = ids.len();
    let lo = ids.iter().copied().min().unwrap_or(0);
    let mut order = vec![u32::MAX; n];
    let dense = ids.iter().enumerate().all(|(i, &id)| {
        let k = (id - lo) as usize;
        k < n && std::mem::replace(&mut order[k], i as u32) == u32::MAX
    });
    if !dense {
        order = (0..n as u32).collect();
        order.sort_unstable_by_key(|&i| ids[i as usize]);
    }
    order
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn id_order_dense_and_sparse() {
        assert_eq!(id_order(&[3, 1, 2]), vec![1, 2, 0]);
        assert_eq!(id_order(&[30, 10, 20]), vec![1, 2, 0]);
        // A repeated id is not a dense range: the sort keeps both.
        assert_eq!(id_order(&[2, 1, 2]), vec![1, 0, 2]);
        assert!(id_order(&[]).is_empty());
    }

    #[test]
    fn mesh_springs_follow_their_grains_through_a_new_state() {
        use crate::boundary::{Mesh, MeshPlacement, Motion, Shape, Wall};
        use crate::contact::hooke_history::lammps_law;
        use crate::dim::D3;
        use crate::domain::Domain;
        use crate::md::MdSettings;
        use crate::particles::{ParticleRecord, Particles};
        use glam::DVec3;
        use std::collections::BTreeMap;
        use std::sync::Arc;
        // A row of grains sliding on a two-triangle floor, ids against x so
        // that the spatial sort puts them out of id order.
        let sheet = [
            [[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [10.0, 10.0, 0.0]],
            [[0.0, 0.0, 0.0], [10.0, 10.0, 0.0], [0.0, 10.0, 0.0]],
        ];
        let mesh = Mesh::new("sheet", &sheet, &MeshPlacement::default()).unwrap();
        let floor = Wall::new("floor", Shape::Mesh(Arc::new(mesh)), Motion::Fixed).unwrap();
        let mut p = Particles::<D3>::new();
        for k in 0..6u64 {
            let x = 8.5 - 1.5 * k as f64;
            let mut g = ParticleRecord::new(k, DVec3::new(x, 5.0, 0.49), 0.5, 1.0, 0.1);
            g.vel = DVec3::new(0.01 * (k + 1) as f64, 0.0, 0.0);
            p.push_record(g);
        }
        let domain = Domain::new(DVec3::splat(-1.0), DVec3::splat(11.0), [false; 3]);
        let mut settings = MdSettings::new(1e-4, lammps_law(0.0), 0.2);
        settings.gravity = DVec3::new(0.0, 0.0, -9.81);
        let mut md = Md::new(p, domain, vec![floor], settings).unwrap();
        md.advance(20).unwrap();
        let by_id = |md: &Md<D3>| -> BTreeMap<u64, DVec3> {
            md.mesh_springs
                .entries()
                .map(|((g, _, _), s)| (md.particles.id[g as usize], s))
                .collect()
        };
        let before = by_id(&md);
        assert_eq!(before.len(), 6, "every grain's spring is stretched");
        assert_ne!(
            md.id_order(),
            (0..6).collect::<Vec<u32>>(),
            "out of id order"
        );
        md.set_state(None, None).unwrap();
        assert_eq!(by_id(&md), before);
    }
}
