//! Migration at a rebuild: grains that change rank, with their springs.
//!
//! The owned grains that left this rank's box are sent to their new owners
//! with their pair and wall springs, and those arriving are taken in.

use super::halo::{get_record, put_record};
use super::{get_vec, put_vec, DecomposedMd, PairSpring, PairSprings};
use crate::comm::{Reader, Writer};
use crate::dim::Dim;
use std::collections::HashMap;

impl<D: Dim> DecomposedMd<'_, D> {
    /// Sends the owned grains (wrapped) that another rank owns there, with
    /// their pair and wall springs, and takes in those that arrive; returns
    /// how many arrived (see [`Self::tally`]).
    pub(super) fn migrate(
        &mut self,
        saved: &mut PairSprings<D>,
        walls: &mut Vec<(u64, u32, D::V)>,
    ) -> u64 {
        let (r, size) = (self.comm.rank(), self.comm.size());
        let p = &mut self.md.particles;
        // Leaving grains travel with their springs.
        let mut out = vec![Writer::default(); size];
        let mut leaving: HashMap<u64, usize> = HashMap::new();
        let mut records: Vec<Vec<_>> = vec![Vec::new(); size];
        let mut keep = Vec::with_capacity(p.n_owned());
        for i in 0..p.n_owned() {
            let dest = self.sub.owner(&D::to_xyz(p.pos[i]));
            if dest == r {
                keep.push(i as u32);
            } else {
                leaving.insert(p.id[i], dest);
                records[dest].push(p.pack(i));
            }
        }
        let mut pair_out: Vec<Vec<PairSpring<D>>> = vec![Vec::new(); size];
        // Nothing to look up when no grain leaves (most rebuilds of a dense bed).
        if !leaving.is_empty() {
            for (&key, &s) in saved.iter() {
                // A pair whose two grains leave for different ranks goes to both.
                let d0 = leaving.get(&key.0);
                let d1 = leaving.get(&key.1);
                if let Some(&d) = d0 {
                    pair_out[d].push((key, s));
                }
                if let Some(&d) = d1 {
                    if d0 != Some(&d) {
                        pair_out[d].push((key, s));
                    }
                }
            }
        }
        let mut wall_out: Vec<Vec<(u64, u32, D::V)>> = vec![Vec::new(); size];
        walls.retain(|&(id, w, s)| match leaving.get(&id) {
            Some(&d) => {
                wall_out[d].push((id, w, s));
                false
            }
            None => true,
        });
        for d in 0..size {
            let w = &mut out[d];
            if records[d].is_empty() {
                continue;
            }
            w.u64(records[d].len() as u64);
            for rec in &records[d] {
                put_record(w, rec, &[0.0; 3]);
            }
            w.u64(pair_out[d].len() as u64);
            // Sorted so that the message does not depend on hash order.
            pair_out[d].sort_unstable_by_key(|e| e.0);
            for &((x, y), s) in &pair_out[d] {
                w.u64(x);
                w.u64(y);
                put_vec::<D>(w, s);
            }
            w.u64(wall_out[d].len() as u64);
            for &(id, wall, s) in &wall_out[d] {
                w.u64(id);
                w.u32(wall);
                put_vec::<D>(w, s);
            }
        }
        p.retain_owned(&keep);
        saved.retain(|k, _| !(leaving.contains_key(&k.0) && leaving.contains_key(&k.1)));
        let bufs: Vec<Vec<u8>> = out.into_iter().map(|w| w.buf).collect();
        let got = self.comm.exchange(&bufs);
        let mut arrived = 0u64;
        for buf in &got {
            if buf.is_empty() {
                continue;
            }
            let mut rd = Reader::new(buf);
            for _ in 0..rd.u64() {
                p.push_record(get_record::<D>(&mut rd));
                arrived += 1;
            }
            for _ in 0..rd.u64() {
                let key = (rd.u64(), rd.u64());
                saved.insert(key, get_vec::<D>(&mut rd));
            }
            for _ in 0..rd.u64() {
                walls.push((rd.u64(), rd.u32(), get_vec::<D>(&mut rd)));
            }
            assert!(rd.done(), "migration message longer than its layout");
        }
        arrived
    }
}
