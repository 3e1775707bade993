//! The mirror's state given back in the CPU engine's terms.
//!
//! Its grains in the CPU engine's order, an [`MdState`] to import (with the
//! overlap statistics recomputed), a frame, and the bits compared with
//! another mirror's.

use super::Mirror;
use crate::dim::{Dim, D3};
use crate::gpu::grain_kernels::{add, dot, sub, FullList, Soa3};
use crate::io::Frame;
use crate::md::MdState;
use crate::neighbors::ListState;
use glam::DVec3;

fn dvec(s: &Soa3) -> Vec<DVec3> {
    (0..s.len()).map(|i| DVec3::from_array(s.get(i))).collect()
}

impl Mirror {
    /// How many grains differ from `other`'s in identity (order), position,
    /// velocity or spin bits, and whether the lists and springs differ.
    pub fn differences(&self, other: &Mirror) -> (usize, bool) {
        let grains = (0..self.len().max(other.len()))
            .filter(|&i| {
                i >= self.len()
                    || i >= other.len()
                    || self.id[i] != other.id[i]
                    || [
                        (&self.pos, &other.pos),
                        (&self.vel, &other.vel),
                        (&self.omega, &other.omega),
                    ]
                    .iter()
                    .any(|(a, b)| a.get(i).map(f64::to_bits) != b.get(i).map(f64::to_bits))
            })
            .count();
        let bits = |s: &Soa3| {
            [&s.x, &s.y, &s.z].map(|c| c.iter().map(|x| x.to_bits()).collect::<Vec<_>>())
        };
        let list = self.list != other.list || bits(&self.springs) != bits(&other.springs);
        (grains, list)
    }

    /// The same pipeline state with the grains stored in the CPU engine's
    /// order (rank k at index k), the list renumbered.
    fn cpu_ordered(&self) -> Mirror {
        let n = self.len();
        let mut by_rank = vec![0u32; n];
        for (k, &r) in self.rank.iter().enumerate() {
            by_rank[r as usize] = k as u32;
        }
        let mut m = self.clone();
        m.permute(&by_rank);
        m.reference = self.reference.gather(&by_rank);
        let (mut start, mut partner, mut image) = (vec![0u32], Vec::new(), Vec::new());
        let mut springs = Vec::new();
        for &k in &by_rank {
            for e in self.list.row(k as usize) {
                partner.push(self.rank[self.list.partner[e] as usize]);
                image.push(self.list.image[e]);
                springs.push(self.springs.get(e));
            }
            start.push(partner.len() as u32);
        }
        m.list = FullList {
            start,
            partner,
            image,
        };
        m.springs = Soa3::from_vecs(springs.into_iter());
        m.rank = (0..n as u32).collect();
        m
    }

    fn in_cpu_order(&self) -> bool {
        self.rank.iter().enumerate().all(|(k, &r)| r as usize == k)
    }

    /// The state as the CPU engine keeps it (in its order): its import
    /// continues the run with the same bits.
    pub fn to_state(&self) -> MdState<D3> {
        if !self.in_cpu_order() {
            return self.cpu_ordered().to_state();
        }
        let t = &self.template;
        let mut particles = t.particles.clone();
        particles.permute(&self.origin);
        particles.pos = dvec(&self.pos);
        particles.vel = dvec(&self.vel);
        particles.omega = dvec(&self.omega);
        particles.force = dvec(&self.force);
        particles.torque = dvec(&self.torque);
        let (mut pairs, mut image, mut springs) = (Vec::new(), Vec::new(), Vec::new());
        for g in 0..self.len() {
            for e in self.list.row(g) {
                let p = self.list.partner[e];
                if p as usize > g {
                    pairs.push([g as u32, p]);
                    image.push(self.list.image[e]);
                    springs.push(DVec3::from_array(self.springs.get(e)));
                }
            }
        }
        let (max_overlap, worst) = self.overlaps(&pairs, &image);
        let nw = self.params.walls.len();
        let slots = nw.max(1);
        let mut wall_springs = vec![DVec3::ZERO; self.len() * slots];
        for k in 0..self.len() * nw {
            wall_springs[k / nw * slots + k % nw] = DVec3::from_array(self.wall_springs.get(k));
        }
        MdState {
            time: self.time,
            step: self.step,
            particles,
            list: ListState {
                pairs,
                image,
                shifts: self.shifts.iter().map(|&s| DVec3::from_array(s)).collect(),
                ref_pos: dvec(&self.reference),
                builds: self.builds,
                built: self.builds > 0,
                shear: None,
            },
            springs,
            wall_springs,
            // The device runs no rigid clumps (refused when it is built).
            bodies: Vec::new(),
            // The mirror runs the Hooke law, which keeps no rolling springs.
            rolling: Vec::new(),
            wall_rolling: Vec::new(),
            // The device runs no mesh walls, so no loads are kept; the time
            // is that of the last force evaluation, as the CPU engine's.
            mesh_springs: Vec::new(),
            mesh_rolling: Vec::new(),
            wall_loads: (Vec::new(), self.time),
            // The device runs fixed walls only.
            servo: Vec::new(),
            rebuilds_since_sort: self.rebuilds_since_sort,
            contacts: self.stats.contacts,
            max_overlap,
            max_overlap_fraction: self.stats.max_fraction,
            worst_pair: worst.unwrap_or(t.worst_pair),
            // The device runs no sheared box.
            pressure_box: None,
        }
    }

    /// The largest overlap and the worst pair of the last force evaluation
    /// (`None` without contacts), as the CPU engine finds them: over the
    /// pairs in its list's order, then each mobile grain's walls, the first
    /// largest overlap fraction. The kernels sum only the contacts and the
    /// largest fraction; these are recomputed from the positions, at which
    /// a step's forces were evaluated, with the force kernel's operations.
    fn overlaps(&self, pairs: &[[u32; 2]], image: &[u8]) -> (f64, Option<(u64, Option<u64>)>) {
        let (mut max, mut fraction, mut worst) = (0.0f64, 0.0, None);
        for (&[i, j], &code) in pairs.iter().zip(image) {
            let (i, j) = (i as usize, j as usize);
            let del = sub(
                self.pos.get(i),
                add(self.pos.get(j), self.shifts[code as usize]),
            );
            let (ri, rj) = (self.radius[i], self.radius[j]);
            let r2 = dot(del, del);
            if r2 >= (ri + rj) * (ri + rj) {
                continue;
            }
            let overlap = ri + rj - r2.sqrt();
            max = max.max(overlap);
            if overlap > fraction * ri.min(rj) {
                fraction = overlap / ri.min(rj);
                worst = Some((self.id[i], Some(self.id[j])));
            }
        }
        let mut wall_fraction = 0.0;
        let mut wall_worst = None;
        for g in (0..self.len()).filter(|&g| self.frozen[g] == 0) {
            let (x, r) = (self.pos.get(g), self.radius[g]);
            for wall in &self.params.walls {
                let s = dot(sub(x, wall.point), wall.normal);
                let overlap = r - s;
                if overlap <= 0.0 || s < -r {
                    continue;
                }
                max = max.max(overlap);
                if overlap / r > wall_fraction {
                    wall_fraction = overlap / r;
                    wall_worst = Some((self.id[g], None));
                }
            }
        }
        if wall_fraction > fraction {
            worst = wall_worst;
        }
        (max, worst)
    }

    /// The grains now as a frame (the CPU engine's [`Md::frame`] layout
    /// and order).
    pub fn frame(&self, domain: &crate::domain::Domain<D3>) -> Frame {
        if !self.in_cpu_order() {
            return self.cpu_ordered().frame(domain);
        }
        let kind = &self.template.particles.kind;
        Frame {
            step: self.step,
            time: self.time,
            dim: 3,
            box_lo: D3::to_xyz(domain.lo),
            box_hi: D3::to_xyz(domain.hi),
            periodic: domain.periodic,
            id: self.id.clone(),
            kind: self.origin.iter().map(|&k| kind[k as usize]).collect(),
            pos: (0..self.len()).map(|i| self.pos.get(i)).collect(),
            vel: (0..self.len()).map(|i| self.vel.get(i)).collect(),
            omega: (0..self.len()).map(|i| self.omega.get(i)).collect(),
            radius: self.radius.clone(),
            body: None,
            orientation: None,
            mass: Vec::new(),
        }
    }
}
