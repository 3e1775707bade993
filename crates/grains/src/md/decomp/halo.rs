//! The messages of MD domain decomposition: the ghost shells each rank
//! receives from the others, and the byte layout of a migrating or ghost
//! grain.
//!
//! A rank owns the grains inside its box ([`Subdomains`]). It holds ghost
//! copies of the other ranks' grains (or of their periodic images) that
//! lie within `reach` = largest diameter + skin of its box: every pair that
//! can touch before the next neighbour rebuild (no grain moves more than
//! skin/2 in between) then has both grains on each rank that owns one of
//! them.

use super::subdomains::Subdomains;
use crate::comm::{Comm, Reader, Writer};
use crate::dim::Dim;
use crate::particles::{ParticleRecord, Particles};
use std::collections::BTreeMap;

fn put_v<D: Dim>(w: &mut Writer, v: D::V) {
    for x in &D::to_xyz(v)[..D::D] {
        w.f64(*x);
    }
}

fn get_v<D: Dim>(r: &mut Reader) -> D::V {
    let mut x = [0.0; 3];
    for c in x.iter_mut().take(D::D) {
        *c = r.f64();
    }
    D::from_xyz(x)
}

/// Spin: one component in 2D (about z), three in 3D.
fn put_a<D: Dim>(w: &mut Writer, a: D::A) {
    let x = D::ang_to_xyz(a);
    if D::D == 2 {
        w.f64(x[2]);
    } else {
        x.iter().for_each(|&c| w.f64(c));
    }
}

fn get_a<D: Dim>(r: &mut Reader) -> D::A {
    let x = if D::D == 2 {
        [0.0, 0.0, r.f64()]
    } else {
        [r.f64(), r.f64(), r.f64()]
    };
    D::ang_from_xyz(x)
}

/// `v` moved by `d` (the first `D::D` components).
fn moved<D: Dim>(v: D::V, d: &[f64; 3]) -> D::V {
    let mut x = D::to_xyz(v);
    x.iter_mut().zip(d).for_each(|(a, b)| *a += b);
    D::from_xyz(x)
}

/// Bytes of one ghost in a refresh: position, velocity and spin (one
/// component in 2D, three in 3D).
fn refresh_bytes<D: Dim>() -> usize {
    8 * (2 * D::D + if D::D == 2 { 1 } else { 3 })
}

/// A whole grain (what migrates, and a ghost's first copy), its position
/// moved by `shift`.
pub fn put_record<D: Dim>(w: &mut Writer, r: &ParticleRecord<D>, shift: &[f64; 3]) {
    w.u64(r.id);
    w.u32(r.kind);
    w.u32(r.frozen as u32);
    w.f64(r.radius);
    w.f64(r.mass);
    w.f64(r.inertia);
    put_v::<D>(w, moved::<D>(r.pos, shift));
    put_v::<D>(w, r.vel);
    put_a::<D>(w, r.omega);
    w.u32(r.gear.len() as u32);
    r.gear.iter().for_each(|&g| put_v::<D>(w, g));
    w.u32(r.gear_ang.len() as u32);
    r.gear_ang.iter().for_each(|&g| put_a::<D>(w, g));
}

pub fn get_record<D: Dim>(rd: &mut Reader) -> ParticleRecord<D> {
    let id = rd.u64();
    let kind = rd.u32();
    let frozen = rd.u32() != 0;
    let (radius, mass, inertia) = (rd.f64(), rd.f64(), rd.f64());
    let pos = get_v::<D>(rd);
    let vel = get_v::<D>(rd);
    let omega = get_a::<D>(rd);
    let gear = (0..rd.u32()).map(|_| get_v::<D>(rd)).collect();
    let gear_ang = (0..rd.u32()).map(|_| get_a::<D>(rd)).collect();
    ParticleRecord {
        id,
        kind,
        frozen,
        radius,
        mass,
        inertia,
        pos,
        vel,
        omega,
        gear,
        gear_ang,
    }
}

/// The ghost shells of one rank between two neighbour rebuilds: which owned
/// grains go to which rank (with their shift), and where the received
/// ghosts sit in the store.
#[derive(Clone, Debug, Default)]
pub struct Halo {
    /// (destination rank, shift added to the position, owned indices), in
    /// the order both ends read them.
    pub sends: Vec<(usize, [f64; 3], Vec<u32>)>,
    /// Ghost entries received from each rank, in rank order.
    pub recv_counts: Vec<usize>,
    /// Bytes of each rank's refresh message (its ghosts' position,
    /// velocity and spin), kept so that a refresh allocates no list.
    recv_bytes: Vec<usize>,
    /// The ranks this one exchanges ghosts with (symmetric: r sends to s
    /// or s to r), ascending.
    pub peers: Vec<usize>,
}

impl Halo {
    /// Chooses the shells of rank `r` from its owned grains (all wrapped
    /// and inside its box) and sends them whole to the other ranks; the
    /// ghosts received are appended to `p`.
    pub fn build<D: Dim>(
        sub: &Subdomains,
        r: usize,
        p: &mut Particles<D>,
        exchange: impl FnOnce(&[Vec<u8>]) -> Vec<Vec<u8>>,
    ) -> Self {
        let n = p.n_owned();
        let mine = sub.cell(r);
        let targets = sub.ghost_targets(r);
        // Keyed by (rank, shift) so that both ends agree on the order.
        let mut lists: BTreeMap<(usize, [i8; 3]), Vec<u32>> = BTreeMap::new();
        for i in 0..n {
            let x = D::to_xyz(p.pos[i]);
            if sub.deep_inside(&mine, &x) {
                continue;
            }
            for (s, shift, cell) in &targets {
                let d = sub.displacement(*shift);
                let y = [x[0] + d[0], x[1] + d[1], x[2] + d[2]];
                if sub.contains(cell, &y) {
                    lists.entry((*s, *shift)).or_default().push(i as u32);
                }
            }
        }
        let mut out = vec![Vec::new(); sub.ranks()];
        let mut sends = Vec::with_capacity(lists.len());
        for ((dest, shift), list) in lists {
            let d = sub.displacement(shift);
            let mut w = Writer {
                buf: std::mem::take(&mut out[dest]),
            };
            for &i in &list {
                put_record(&mut w, &p.pack(i as usize), &d);
            }
            out[dest] = w.buf;
            sends.push((dest, d, list));
        }
        let got = exchange(&out);
        let mut recv_counts = Vec::with_capacity(got.len());
        for buf in &got {
            let mut rd = Reader::new(buf);
            let mut k = 0;
            while !rd.done() {
                p.push_ghost(get_record::<D>(&mut rd));
                k += 1;
            }
            recv_counts.push(k);
        }
        let peers = (0..got.len())
            .filter(|&s| recv_counts[s] > 0 || sends.iter().any(|e| e.0 == s))
            .collect();
        let recv_bytes = recv_counts
            .iter()
            .map(|&c| c * refresh_bytes::<D>())
            .collect();
        Self {
            sends,
            recv_counts,
            recv_bytes,
            peers,
        }
    }

    /// Refreshes every ghost's position, velocity and spin from its owner
    /// (called once per step, after the integrator's prediction).
    pub fn refresh<D: Dim>(&self, p: &mut Particles<D>, comm: &dyn Comm) {
        let per_ghost = refresh_bytes::<D>();
        let mut out = vec![Vec::new(); self.recv_counts.len()];
        for (dest, shift, list) in &self.sends {
            let mut w = Writer {
                buf: std::mem::take(&mut out[*dest]),
            };
            w.buf.reserve(list.len() * per_ghost);
            for &i in list {
                let i = i as usize;
                put_v::<D>(&mut w, moved::<D>(p.pos[i], shift));
                put_v::<D>(&mut w, p.vel[i]);
                put_a::<D>(&mut w, p.omega[i]);
            }
            out[*dest] = w.buf;
        }
        // Only peers talk, and each knows how much the other sends.
        let got = comm.exchange_with(&self.peers, &out, &self.recv_bytes);
        let mut g = p.n_owned();
        for (buf, &count) in got.iter().zip(&self.recv_counts) {
            let mut rd = Reader::new(buf);
            for _ in 0..count {
                p.pos[g] = get_v::<D>(&mut rd);
                p.vel[g] = get_v::<D>(&mut rd);
                p.omega[g] = get_a::<D>(&mut rd);
                g += 1;
            }
            assert!(rd.done(), "ghost refresh longer than the shell");
        }
    }

    /// Whether a ghost sent from here moved more than `sqrt(limit2)` from
    /// `reference` (the positions of the last build, as the receivers keep
    /// them): the receivers' displacement test of their ghosts, done by the
    /// owner before the refresh with the same arithmetic (position and
    /// reference shifted alike), so the same answer.
    pub fn sent_beyond<D: Dim>(&self, pos: &[D::V], reference: &[D::V], limit2: f64) -> bool {
        self.sends.iter().any(|(_, shift, list)| {
            list.iter().any(|&i| {
                let i = i as usize;
                let (x, x0) = (moved::<D>(pos[i], shift), moved::<D>(reference[i], shift));
                D::norm2(x - x0) > limit2
            })
        })
    }

    /// Ghost entries in all.
    pub fn ghosts(&self) -> usize {
        self.recv_counts.iter().sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::{D2, D3};
    use glam::{DVec2, DVec3};

    #[test]
    fn records_round_trip_with_shift_and_history() {
        let mut r = ParticleRecord::<D3>::new(7, DVec3::new(1.0, 2.0, 3.0), 0.5, 2.0, 0.2);
        r.vel = DVec3::new(-1.0, 0.5, 0.25);
        r.omega = DVec3::new(0.1, 0.2, 0.3);
        r.frozen = true;
        r.kind = 3;
        r.gear = vec![DVec3::X, DVec3::Y];
        r.gear_ang = vec![DVec3::Z];
        let mut w = Writer::default();
        put_record(&mut w, &r, &[10.0, 0.0, 0.0]);
        let mut rd = Reader::new(&w.buf);
        let back = get_record::<D3>(&mut rd);
        assert!(rd.done());
        let mut want = r.clone();
        want.pos.x += 10.0;
        assert_eq!(back, want);

        let mut r2 = ParticleRecord::<D2>::new(1, DVec2::new(1.0, 2.0), 0.5, 2.0, 0.2);
        r2.omega = -3.5;
        let mut w = Writer::default();
        put_record(&mut w, &r2, &[0.0; 3]);
        assert_eq!(get_record::<D2>(&mut Reader::new(&w.buf)), r2);
    }
}
