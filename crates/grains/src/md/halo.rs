//! The geometry and messages of MD domain decomposition: slabs along one
//! axis, the ghost shells each rank receives from its neighbours, and the
//! byte layout of a migrating or ghost grain.
//!
//! A rank owns the grains whose coordinate along the slab axis lies in its
//! slab `[bounds[r], bounds[r + 1])`. It holds ghost copies of the grains
//! of the two adjacent slabs that lie within `reach` = largest diameter +
//! skin of its own: every pair that can touch before the next neighbour
//! rebuild (no grain moves more than skin/2 in between) then has both
//! grains on each rank that owns one of them. Slabs are at least two
//! reaches wide, so only adjacent ranks exchange ghosts and a grain is
//! never a ghost twice on one rank.

use super::balance::{cuts_by_count, keep_min_width};
use crate::comm::{Comm, Reader, SingleProcess, Writer};
use crate::dim::Dim;
use crate::domain::Domain;
use crate::error::{Error, Result};
use crate::particles::{ParticleRecord, Particles};

/// Slabs along one axis, one per rank.
#[derive(Clone, Debug)]
pub struct Slabs {
    pub axis: usize,
    /// `bounds[r]..bounds[r + 1]` is rank r's slab; the ends are the box's.
    pub bounds: Vec<f64>,
    pub periodic: bool,
    /// Box length along the axis (the periodic shift).
    pub length: f64,
    /// Ghost shell width: largest diameter + skin.
    pub reach: f64,
}

impl Slabs {
    /// Cuts the longest axis of the box (the first of equal ones) so that
    /// each of `ranks` slabs holds about the same number of the grains at
    /// `coords` (their coordinates along that axis, wrapped).
    pub fn by_count<D: Dim>(
        domain: &Domain<D>,
        pos: &[D::V],
        ranks: usize,
        reach: f64,
    ) -> Result<Self> {
        let axis = (0..D::D)
            .max_by(|&a, &b| {
                domain
                    .length(a)
                    .total_cmp(&domain.length(b))
                    .then(b.cmp(&a))
            })
            .unwrap_or(0);
        let (lo, hi) = (D::get(domain.lo, axis), D::get(domain.hi, axis));
        let mut slabs = Self {
            axis,
            bounds: vec![lo, hi],
            periodic: domain.is_periodic(axis),
            length: hi - lo,
            reach,
        };
        if (hi - lo) < ranks as f64 * 2.0 * reach || hi.is_nan() || lo.is_nan() {
            let axis = ["x", "y", "z"][axis];
            return Err(Error::input(format!(
                "{ranks} MPI ranks cut the box along {axis} (length {}) into slabs; each must be \
                 at least 2 × (largest diameter + neighbour skin) = {:.4} wide: run on fewer ranks",
                hi - lo,
                2.0 * reach
            )));
        }
        // Every rank holds every grain at the start: count them locally.
        slabs.cut_by_count(&SingleProcess, ranks, || {
            pos.iter().map(|&p| D::get(domain.wrap(p), axis))
        });
        Ok(slabs)
    }

    /// Moves the inner bounds so that each of `ranks` slabs holds about the
    /// same number of grains (each rank passes its own grains' coordinates
    /// along the axis), keeping every slab two reaches wide.
    pub fn cut_by_count<I: Iterator<Item = f64>>(
        &mut self,
        comm: &dyn Comm,
        ranks: usize,
        coords: impl Fn() -> I,
    ) {
        let (lo, hi) = (self.bounds[0], self.bounds[self.bounds.len() - 1]);
        let mut cuts = cuts_by_count(comm, 1, ranks, (lo, hi), || coords().map(|x| (0, x)))
            .pop()
            .unwrap_or_default();
        keep_min_width(&mut cuts, (lo, hi), 2.0 * self.reach);
        self.bounds = std::iter::once(lo).chain(cuts).chain([hi]).collect();
    }

    pub fn ranks(&self) -> usize {
        self.bounds.len() - 1
    }

    /// The rank that owns a grain at coordinate `x` (wrapped on a periodic
    /// axis; beyond the box ends on an open one: the end slabs).
    pub fn owner(&self, x: f64) -> usize {
        let inner = &self.bounds[1..self.ranks()];
        inner.partition_point(|&b| b <= x)
    }

    /// The shells rank `r` sends: (neighbour rank, shift added to the
    /// coordinate, lower side of r's slab?) for the slab below and above.
    pub fn sends(&self, r: usize) -> Vec<(usize, f64, bool)> {
        let n = self.ranks();
        let mut out = Vec::new();
        if n < 2 {
            return out;
        }
        if r > 0 {
            out.push((r - 1, 0.0, true));
        } else if self.periodic {
            out.push((n - 1, self.length, true));
        }
        if r + 1 < n {
            out.push((r + 1, 0.0, false));
        } else if self.periodic {
            out.push((0, -self.length, false));
        }
        out
    }

    /// Whether a grain of rank `r` at `x` is within reach of the neighbour
    /// on the `lower` (or upper) side.
    pub fn in_shell(&self, r: usize, x: f64, lower: bool) -> bool {
        if lower {
            x < self.bounds[r] + self.reach
        } else {
            x >= self.bounds[r + 1] - self.reach
        }
    }

    /// The box rank `r` builds its neighbour list in: its slab widened by a
    /// reach on each side, not periodic along the slab axis (the ghosts are
    /// the images); the box's own ends where the axis is open.
    pub fn local_domain<D: Dim>(&self, global: &Domain<D>, r: usize) -> Domain<D> {
        let mut d = global.clone();
        if self.ranks() < 2 {
            return d;
        }
        let a = self.axis;
        let lo = if r == 0 && !self.periodic {
            D::get(global.lo, a)
        } else {
            self.bounds[r] - self.reach
        };
        let hi = if r + 1 == self.ranks() && !self.periodic {
            D::get(global.hi, a)
        } else {
            self.bounds[r + 1] + self.reach
        };
        D::set(&mut d.lo, a, lo);
        D::set(&mut d.hi, a, hi);
        d.periodic[a] = false;
        d
    }
}

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

/// A whole grain (what migrates, and a ghost's first copy), its position
/// moved by `shift` along `axis`.
pub fn put_record<D: Dim>(w: &mut Writer, r: &ParticleRecord<D>, axis: usize, shift: f64) {
    w.u64(r.id);
    w.u32(r.kind);
    w.u32(r.frozen as u32);
    w.f64(r.radius);
    w.f64(r.mass);
    w.f64(r.inertia);
    let mut pos = r.pos;
    let x = D::get(pos, axis) + shift;
    D::set(&mut pos, axis, x);
    put_v::<D>(w, pos);
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
    /// (destination rank, shift along the slab axis, owned indices).
    pub sends: Vec<(usize, f64, Vec<u32>)>,
    /// Ghost entries received from each rank, in rank order.
    pub recv_counts: Vec<usize>,
}

impl Halo {
    /// Chooses the shells of rank `r` from its owned grains (all wrapped
    /// and inside its slab) and sends them whole to the neighbours; the
    /// ghosts received are appended to `p`.
    pub fn build<D: Dim>(
        slabs: &Slabs,
        r: usize,
        p: &mut Particles<D>,
        exchange: impl FnOnce(&[Vec<u8>]) -> Vec<Vec<u8>>,
    ) -> Self {
        let n = p.n_owned();
        let a = slabs.axis;
        let mut sends = Vec::new();
        let mut out = vec![Vec::new(); slabs.ranks()];
        for (dest, shift, lower) in slabs.sends(r) {
            let list: Vec<u32> = (0..n as u32)
                .filter(|&i| slabs.in_shell(r, D::get(p.pos[i as usize], a), lower))
                .collect();
            let mut w = Writer { buf: Vec::new() };
            std::mem::swap(&mut w.buf, &mut out[dest]);
            for &i in &list {
                put_record(&mut w, &p.pack(i as usize), a, shift);
            }
            out[dest] = w.buf;
            sends.push((dest, shift, list));
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
        Self { sends, recv_counts }
    }

    /// Refreshes every ghost's position, velocity and spin from its owner
    /// (called once per step, after the integrator's prediction).
    pub fn refresh<D: Dim>(&self, axis: usize, p: &mut Particles<D>, comm: &dyn Comm) {
        let mut out = vec![Vec::new(); self.recv_counts.len()];
        for (dest, shift, list) in &self.sends {
            let mut w = Writer { buf: Vec::new() };
            std::mem::swap(&mut w.buf, &mut out[*dest]);
            w.buf.reserve(list.len() * 8 * (2 * D::D + 3));
            for &i in list {
                let i = i as usize;
                let mut pos = p.pos[i];
                let x = D::get(pos, axis) + shift;
                D::set(&mut pos, axis, x);
                put_v::<D>(&mut w, pos);
                put_v::<D>(&mut w, p.vel[i]);
                put_a::<D>(&mut w, p.omega[i]);
            }
            out[*dest] = w.buf;
        }
        // Only neighbours talk, and each knows how much the other sends.
        let per_ghost = 8 * (2 * D::D + if D::D == 2 { 1 } else { 3 });
        let mut peers: Vec<usize> = self.sends.iter().map(|s| s.0).collect();
        peers.dedup();
        let recv_len: Vec<usize> = self.recv_counts.iter().map(|&c| c * per_ghost).collect();
        let got = comm.exchange_with(&peers, &out, &recv_len);
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
        put_record(&mut w, &r, 0, 10.0);
        let mut rd = Reader::new(&w.buf);
        let back = get_record::<D3>(&mut rd);
        assert!(rd.done());
        let mut want = r.clone();
        want.pos.x += 10.0;
        assert_eq!(back, want);

        let mut r2 = ParticleRecord::<D2>::new(1, DVec2::new(1.0, 2.0), 0.5, 2.0, 0.2);
        r2.omega = -3.5;
        let mut w = Writer::default();
        put_record(&mut w, &r2, 1, 0.0);
        assert_eq!(get_record::<D2>(&mut Reader::new(&w.buf)), r2);
    }

    #[test]
    fn slabs_split_by_count_and_refuse_thin_ones() {
        let d = Domain::<D2>::new(DVec2::ZERO, DVec2::new(40.0, 10.0), [true, false, false]);
        // Grains crowd the left half: the cuts follow the count, not the box.
        let pos: Vec<DVec2> = (0..200).map(|k| DVec2::new(0.1 * k as f64, 1.0)).collect();
        let s = Slabs::by_count(&d, &pos, 2, 1.2).unwrap();
        assert_eq!(s.axis, 0);
        assert!(s.bounds[1] > 9.9 && s.bounds[1] < 9.91, "{:?}", s.bounds);
        assert_eq!((s.owner(0.0), s.owner(9.9), s.owner(10.0)), (0, 0, 1));
        // Rank 0 sends down to rank 1 with a +L shift, up without.
        assert_eq!(s.sends(0), vec![(1, 40.0, true), (1, 0.0, false)]);
        assert_eq!(s.sends(1), vec![(0, 0.0, true), (0, -40.0, false)]);
        // 16 slabs of 2.5 fit; the crowded left ones are widened to 2.4.
        let s = Slabs::by_count(&d, &pos, 16, 1.2).unwrap();
        assert!(s.bounds.windows(2).all(|w| w[1] - w[0] >= 2.4 - 1e-12));
        let err = Slabs::by_count(&d, &pos, 17, 1.2).unwrap_err().to_string();
        assert!(err.contains("run on fewer ranks"), "{err}");
    }
}
