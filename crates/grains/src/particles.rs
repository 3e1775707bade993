//! The particle store: a structure of arrays, one entry per grain.
//!
//! Layout: the first `n_owned` entries are particles this process integrates;
//! entries after them are ghosts (periodic or halo copies owned elsewhere),
//! which receive no integration. A single process has no ghosts today; the
//! split exists so that MPI domain decomposition can append halo copies and
//! migrate particles with [`Particles::pack`] / [`Particles::push_record`]
//! without changing this type. Every per-particle array is listed in
//! [`Particles::permute`] and [`ParticleRecord`], so nothing is forgotten when
//! the store is sorted or a particle moves between domains.

use crate::dim::Dim;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// How a grain's mass follows from its diameter and the material density.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum MassModel {
    /// m = ρ π d³ / 6, also for disks in 2D (the seeds' and LAMMPS's choice).
    #[default]
    Sphere,
    /// m = ρ π d² / 4: a disk of unit thickness (ρ is then mass per area).
    Disk,
}

impl MassModel {
    pub fn mass(self, density: f64, diameter: f64) -> f64 {
        match self {
            MassModel::Sphere => density * PI * diameter.powi(3) / 6.0,
            MassModel::Disk => density * PI * diameter.powi(2) / 4.0,
        }
    }

    /// Moment of inertia about a diameter (sphere) or the symmetry axis (disk).
    pub fn inertia(self, mass: f64, radius: f64) -> f64 {
        match self {
            MassModel::Sphere => 0.4 * mass * radius * radius,
            MassModel::Disk => 0.5 * mass * radius * radius,
        }
    }
}

/// Everything one particle carries: what migrates between domains and what a
/// checkpoint stores.
#[derive(Clone, Debug, PartialEq)]
pub struct ParticleRecord<D: Dim> {
    pub id: u64,
    pub kind: u32,
    pub frozen: bool,
    pub radius: f64,
    pub mass: f64,
    pub inertia: f64,
    pub pos: D::V,
    pub vel: D::V,
    pub omega: D::A,
    /// Higher time derivatives kept by the Gear integrator (empty otherwise).
    pub gear: Vec<D::V>,
    pub gear_ang: Vec<D::A>,
}

impl<D: Dim> ParticleRecord<D> {
    /// A particle at rest.
    pub fn new(id: u64, pos: D::V, radius: f64, mass: f64, inertia: f64) -> Self {
        Self {
            id,
            kind: 1,
            frozen: false,
            radius,
            mass,
            inertia,
            pos,
            vel: D::zero(),
            omega: D::A::default(),
            gear: Vec::new(),
            gear_ang: Vec::new(),
        }
    }
}

/// Structure-of-arrays particle state.
#[derive(Clone, Debug, Default)]
pub struct Particles<D: Dim> {
    pub pos: Vec<D::V>,
    pub vel: Vec<D::V>,
    pub force: Vec<D::V>,
    pub omega: Vec<D::A>,
    pub torque: Vec<D::A>,
    pub radius: Vec<f64>,
    pub mass: Vec<f64>,
    /// 1/m, or 0 for frozen particles (they never move).
    pub inv_mass: Vec<f64>,
    /// 1/I, or 0 for frozen particles.
    pub inv_inertia: Vec<f64>,
    pub inertia: Vec<f64>,
    /// Global identity, stable under sorting and migration.
    pub id: Vec<u64>,
    /// User type (1-based, as in LAMMPS), for output and grouping.
    pub kind: Vec<u32>,
    pub frozen: Vec<bool>,
    /// Gear predictor–corrector history: scaled derivatives of order 2..=5
    /// (`gear[k][i]` is dt^(k+2)/(k+2)! times the (k+2)-th derivative of the
    /// position of particle i). Empty when the integrator keeps no history.
    pub gear: Vec<Vec<D::V>>,
    /// The same for the angular velocity (orders 1..=4 of ω).
    pub gear_ang: Vec<Vec<D::A>>,
    n_owned: usize,
}

impl<D: Dim> Particles<D> {
    pub fn new() -> Self {
        Self {
            pos: Vec::new(),
            vel: Vec::new(),
            force: Vec::new(),
            omega: Vec::new(),
            torque: Vec::new(),
            radius: Vec::new(),
            mass: Vec::new(),
            inv_mass: Vec::new(),
            inv_inertia: Vec::new(),
            inertia: Vec::new(),
            id: Vec::new(),
            kind: Vec::new(),
            frozen: Vec::new(),
            gear: Vec::new(),
            gear_ang: Vec::new(),
            n_owned: 0,
        }
    }

    /// A store of owned grains from records, in their order, without Gear
    /// history (as `push_record` on a new store). The records' memory is
    /// handed back while they are moved over (reversed in place, taken from
    /// the back into pre-sized arrays, the record array shrinking as it
    /// empties), so the two copies never coexist in full: for 10^6 grains
    /// that is the difference between about 330 and 190 bytes per grain at
    /// the peak of the set-up.
    pub fn from_records(mut records: Vec<ParticleRecord<D>>) -> Self {
        let mut p = Self::with_capacity(records.len());
        records.reverse();
        while let Some(r) = records.pop() {
            p.push_record(r);
            // Shrinking in place returns the emptied tail to the system.
            if records.capacity() > 4096 && records.len() < records.capacity() / 8 * 7 {
                records.shrink_to_fit();
            }
        }
        p
    }

    /// An empty store with room for `n` grains.
    pub fn with_capacity(n: usize) -> Self {
        let mut p = Self::new();
        p.reserve(n);
        p
    }

    fn reserve(&mut self, n: usize) {
        self.pos.reserve_exact(n);
        self.vel.reserve_exact(n);
        self.force.reserve_exact(n);
        self.omega.reserve_exact(n);
        self.torque.reserve_exact(n);
        self.radius.reserve_exact(n);
        self.mass.reserve_exact(n);
        self.inertia.reserve_exact(n);
        self.inv_mass.reserve_exact(n);
        self.inv_inertia.reserve_exact(n);
        self.id.reserve_exact(n);
        self.kind.reserve_exact(n);
        self.frozen.reserve_exact(n);
    }

    /// All entries, owned and ghost.
    pub fn len(&self) -> usize {
        self.pos.len()
    }

    pub fn is_empty(&self) -> bool {
        self.pos.is_empty()
    }

    /// Particles this process integrates (the first `n_owned` entries).
    pub fn n_owned(&self) -> usize {
        self.n_owned
    }

    /// Number of owned particles that are not frozen.
    pub fn n_mobile(&self) -> usize {
        self.frozen[..self.n_owned].iter().filter(|f| !**f).count()
    }

    /// Appends an owned particle. Must not be called while ghosts are present.
    pub fn push_record(&mut self, r: ParticleRecord<D>) {
        assert_eq!(
            self.n_owned,
            self.len(),
            "drop ghosts before adding owned particles"
        );
        self.push_raw(r);
        self.n_owned += 1;
    }

    /// Appends a ghost copy (after all owned particles).
    pub fn push_ghost(&mut self, r: ParticleRecord<D>) {
        self.push_raw(r);
    }

    /// Removes every ghost entry.
    pub fn clear_ghosts(&mut self) {
        let n = self.n_owned;
        self.truncate(n);
    }

    fn push_raw(&mut self, r: ParticleRecord<D>) {
        self.pos.push(r.pos);
        self.vel.push(r.vel);
        self.force.push(D::zero());
        self.omega.push(r.omega);
        self.torque.push(D::A::default());
        self.radius.push(r.radius);
        self.mass.push(r.mass);
        self.inertia.push(r.inertia);
        let (im, ii) = if r.frozen {
            (0.0, 0.0)
        } else {
            (1.0 / r.mass, 1.0 / r.inertia)
        };
        self.inv_mass.push(im);
        self.inv_inertia.push(ii);
        self.id.push(r.id);
        self.kind.push(r.kind);
        self.frozen.push(r.frozen);
        for (k, g) in self.gear.iter_mut().enumerate() {
            g.push(r.gear.get(k).copied().unwrap_or_default());
        }
        for (k, g) in self.gear_ang.iter_mut().enumerate() {
            g.push(r.gear_ang.get(k).copied().unwrap_or_default());
        }
    }

    fn truncate(&mut self, n: usize) {
        self.pos.truncate(n);
        self.vel.truncate(n);
        self.force.truncate(n);
        self.omega.truncate(n);
        self.torque.truncate(n);
        self.radius.truncate(n);
        self.mass.truncate(n);
        self.inertia.truncate(n);
        self.inv_mass.truncate(n);
        self.inv_inertia.truncate(n);
        self.id.truncate(n);
        self.kind.truncate(n);
        self.frozen.truncate(n);
        self.gear.iter_mut().for_each(|g| g.truncate(n));
        self.gear_ang.iter_mut().for_each(|g| g.truncate(n));
        self.n_owned = self.n_owned.min(n);
    }

    /// Everything particle `i` carries.
    pub fn pack(&self, i: usize) -> ParticleRecord<D> {
        ParticleRecord {
            id: self.id[i],
            kind: self.kind[i],
            frozen: self.frozen[i],
            radius: self.radius[i],
            mass: self.mass[i],
            inertia: self.inertia[i],
            pos: self.pos[i],
            vel: self.vel[i],
            omega: self.omega[i],
            gear: self.gear.iter().map(|g| g[i]).collect(),
            gear_ang: self.gear_ang.iter().map(|g| g[i]).collect(),
        }
    }

    /// Removes owned particle `i` (the last owned one takes its place) and
    /// returns it. Ghosts must have been cleared first.
    pub fn swap_remove_owned(&mut self, i: usize) -> ParticleRecord<D> {
        assert_eq!(self.n_owned, self.len(), "clear ghosts before migrating");
        let r = self.pack(i);
        let last = self.len() - 1;
        let mut perm: Vec<u32> = (0..self.len() as u32).collect();
        perm.swap(i, last);
        self.permute(&perm);
        self.truncate(last);
        r
    }

    /// Keeps the owned particles at `keep` (ascending indices), in that
    /// order, and drops the rest: the particles that migrated to another
    /// domain. Ghosts must have been cleared first.
    pub fn retain_owned(&mut self, keep: &[u32]) {
        assert_eq!(self.n_owned, self.len(), "clear ghosts before migrating");
        self.permute(keep);
        self.truncate(keep.len());
        self.n_owned = keep.len();
    }

    /// Makes room for the Gear history: `orders` derivative arrays each.
    pub fn ensure_gear_history(&mut self, orders: usize, ang_orders: usize) {
        let n = self.len();
        self.gear.resize_with(orders, || vec![D::zero(); n]);
        self.gear_ang
            .resize_with(ang_orders, || vec![D::A::default(); n]);
    }

    /// Reorders every per-particle array: entry `k` of the result is old entry
    /// `order[k]`. `order` must be a permutation of the owned range (ghosts
    /// follow unchanged when `order.len() == n_owned`).
    pub fn permute(&mut self, order: &[u32]) {
        fn apply<T: Copy>(v: &mut [T], order: &[u32], scratch: &mut Vec<T>) {
            scratch.clear();
            scratch.extend(order.iter().map(|&k| v[k as usize]));
            v[..order.len()].copy_from_slice(scratch);
        }
        assert!(order.len() <= self.len());
        // One scratch array per element type, reused across the arrays: a
        // large array freed goes back to the system, and a fresh one per
        // array would be faulted in and zeroed again (a tenth of the
        // set-up's page faults at 10⁷ grains).
        let (mut sv, mut sa, mut s) = (Vec::new(), Vec::new(), Vec::new());
        for v in [&mut self.pos, &mut self.vel, &mut self.force] {
            apply(v, order, &mut sv);
        }
        for g in &mut self.gear {
            apply(g, order, &mut sv);
        }
        for a in [&mut self.omega, &mut self.torque] {
            apply(a, order, &mut sa);
        }
        for g in &mut self.gear_ang {
            apply(g, order, &mut sa);
        }
        for x in [
            &mut self.radius,
            &mut self.mass,
            &mut self.inertia,
            &mut self.inv_mass,
            &mut self.inv_inertia,
        ] {
            apply(x, order, &mut s);
        }
        apply(&mut self.id, order, &mut Vec::new());
        apply(&mut self.kind, order, &mut Vec::new());
        apply(&mut self.frozen, order, &mut Vec::new());
    }

    /// Total translational kinetic energy ½Σmv² of owned particles.
    pub fn kinetic_energy(&self) -> f64 {
        self.kinetic_energy_of(|i| !self.frozen[i])
    }

    /// ½Σmv² of the owned particles `i` for which `counted(i)`, in store
    /// order.
    pub fn kinetic_energy_of(&self, counted: impl Fn(usize) -> bool) -> f64 {
        (0..self.n_owned)
            .filter(|&i| counted(i))
            .map(|i| 0.5 * self.mass[i] * D::norm2(self.vel[i]))
            .sum()
    }

    /// Total rotational kinetic energy ½ΣIω² of owned particles.
    pub fn rotational_energy(&self) -> f64 {
        self.rotational_energy_of(|i| !self.frozen[i])
    }

    /// ½ΣIω² of the owned particles `i` for which `counted(i)`, in store
    /// order.
    pub fn rotational_energy_of(&self, counted: impl Fn(usize) -> bool) -> f64 {
        (0..self.n_owned)
            .filter(|&i| counted(i))
            .map(|i| 0.5 * self.inertia[i] * D::ang_dot(self.omega[i], self.omega[i]))
            .sum()
    }

    /// Total momentum Σmv of owned, non-frozen particles.
    pub fn momentum(&self) -> D::V {
        let mut p = D::zero();
        for i in 0..self.n_owned {
            if !self.frozen[i] {
                p += self.vel[i] * self.mass[i];
            }
        }
        p
    }

    /// Largest radius in the store (0 when empty).
    pub fn max_radius(&self) -> f64 {
        self.radius.iter().copied().fold(0.0, f64::max)
    }
}

/// Diameters uniform in `[d0 (1 − w/2), d0 (1 + w/2)]`: a band of width `w·d0`
/// around `d0`, as in seed 002.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SizeBand {
    pub d0: f64,
    pub width: f64,
}

impl SizeBand {
    pub fn min(&self) -> f64 {
        self.d0 * (1.0 - 0.5 * self.width)
    }
    pub fn max(&self) -> f64 {
        self.d0 * (1.0 + 0.5 * self.width)
    }
    /// Maps a uniform number u ∈ [0, 1) to a diameter.
    pub fn diameter(&self, u: f64) -> f64 {
        self.min() + u * (self.max() - self.min())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::D2;
    use glam::DVec2;

    #[test]
    fn from_records_equals_pushing_them_in_order() {
        // More than the shrink threshold, so the record array shrinks on the way.
        let records: Vec<ParticleRecord<D2>> = (0..10_000u64)
            .map(|i| {
                let mut r = ParticleRecord::new(
                    100 + i,
                    DVec2::new(i as f64, 0.5 * i as f64),
                    0.5 + 1e-5 * i as f64,
                    1.0 + 1e-4 * i as f64,
                    0.1,
                );
                r.vel = DVec2::new(-(i as f64), 1.0);
                r.omega = 0.25 * i as f64;
                r.kind = 1 + (i % 3) as u32;
                r.frozen = i % 7 == 0;
                r
            })
            .collect();
        let mut pushed = Particles::<D2>::new();
        for r in records.clone() {
            pushed.push_record(r);
        }
        let built = Particles::from_records(records);
        assert_eq!(built.n_owned(), 10_000);
        assert_eq!(built.len(), 10_000);
        for i in [0, 1, 6999, 9999] {
            assert_eq!(built.pack(i), pushed.pack(i));
        }
        assert_eq!(built.pos, pushed.pos);
        assert_eq!(built.vel, pushed.vel);
        assert_eq!(built.inv_mass, pushed.inv_mass);
        assert_eq!(built.inv_inertia, pushed.inv_inertia);
        assert_eq!(built.id, pushed.id);
        assert_eq!(built.frozen, pushed.frozen);
        assert!(built.gear.is_empty() && built.gear_ang.is_empty());
    }

    fn store(n: usize) -> Particles<D2> {
        let mut p = Particles::<D2>::new();
        p.ensure_gear_history(4, 4);
        for i in 0..n {
            let mut r =
                ParticleRecord::<D2>::new(i as u64, DVec2::new(i as f64, 0.0), 0.5, 1.0, 0.1);
            r.gear = vec![DVec2::splat(i as f64); 4];
            p.push_record(r);
        }
        p
    }

    #[test]
    fn permute_moves_every_array_together() {
        let mut p = store(4);
        p.permute(&[2, 0, 3, 1]);
        assert_eq!(p.id, vec![2, 0, 3, 1]);
        assert_eq!(p.pos[0], DVec2::new(2.0, 0.0));
        assert_eq!(p.gear[3][2], DVec2::splat(3.0));
    }

    #[test]
    fn pack_then_push_round_trips() {
        let mut p = store(3);
        let r = p.swap_remove_owned(0);
        assert_eq!(r.id, 0);
        assert_eq!(p.len(), 2);
        assert_eq!(p.id, vec![2, 1]);
        p.push_record(r.clone());
        assert_eq!(p.pack(2), r);
    }

    #[test]
    fn retain_owned_keeps_the_chosen_grains_with_their_history() {
        let mut p = store(5);
        let kept: Vec<_> = [1, 3, 4].iter().map(|&i| p.pack(i)).collect();
        p.retain_owned(&[1, 3, 4]);
        assert_eq!((p.len(), p.n_owned()), (3, 3));
        for (k, r) in kept.iter().enumerate() {
            assert_eq!(&p.pack(k), r);
        }
        assert!(p.gear.iter().all(|g| g.len() == 3));
    }

    #[test]
    fn sphere_and_disk_masses() {
        let d = 2.0;
        assert!((MassModel::Sphere.mass(3.0, d) - 3.0 * PI * 8.0 / 6.0).abs() < 1e-12);
        assert!((MassModel::Disk.mass(3.0, d) - 3.0 * PI).abs() < 1e-12);
    }

    #[test]
    fn frozen_particles_have_zero_inverse_mass() {
        let mut p = Particles::<D2>::new();
        let mut r = ParticleRecord::<D2>::new(7, DVec2::ZERO, 0.5, 2.0, 0.1);
        r.frozen = true;
        p.push_record(r);
        assert_eq!(p.inv_mass[0], 0.0);
        assert_eq!(p.n_mobile(), 0);
    }
}
