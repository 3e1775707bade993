//! Springs carried across a neighbour rebuild: saved by the ids of their
//! pair before the list changes, put back where the same pair stands in the
//! new list (so a pair that changes order or periodic image keeps its
//! spring, turned to the new order).

use super::pair_hash::PairHash;
use super::Md;
use crate::dim::Dim;
use rayon::prelude::*;
use std::collections::HashMap;

impl<D: Dim> Md<D> {
    /// The stretched springs, keyed by the ids of their pair (smaller first)
    /// and oriented as the displacement of the smaller id.
    pub(super) fn save_springs(&self) -> HashMap<(u64, u64), D::V, PairHash> {
        self.save_keyed(&self.springs)
    }

    /// The stretched rolling springs, as [`Md::save_springs`] keys them.
    pub(super) fn save_rolling(&self) -> HashMap<(u64, u64), D::V, PairHash> {
        self.save_keyed(&self.rolling)
    }

    /// Puts the rolling springs back after a rebuild (none unless the law
    /// keeps them).
    pub(super) fn restore_rolling(&mut self, saved: HashMap<(u64, u64), D::V, PairHash>) {
        let mut rolling = std::mem::take(&mut self.rolling);
        if self.rolling_history() {
            self.restore_keyed(saved, &mut rolling);
        }
        self.rolling = rolling;
    }

    /// `springs` (aligned with the pair list) keyed by pair ids.
    fn save_keyed(&self, springs: &[D::V]) -> HashMap<(u64, u64), D::V, PairHash> {
        let id = &self.particles.id;
        let stretched: Vec<((u64, u64), D::V)> = self
            .neighbors
            .pairs
            .par_iter()
            .zip(springs.par_iter())
            .with_min_len(crate::parallel::min_len(1))
            .filter(|(_, &s)| s != D::zero())
            .map(|(&[i, j], &s)| {
                let (a, b) = (id[i as usize], id[j as usize]);
                if a < b {
                    ((a, b), s)
                } else {
                    ((b, a), -s)
                }
            })
            .collect();
        let mut saved = HashMap::with_capacity_and_hasher(stretched.len(), PairHash::default());
        saved.extend(stretched);
        saved
    }

    pub(super) fn restore_springs(&mut self, saved: HashMap<(u64, u64), D::V, PairHash>) {
        let mut springs = std::mem::take(&mut self.springs);
        self.restore_keyed(saved, &mut springs);
        self.springs = springs;
    }

    /// `springs` aligned with the pair list again, from `saved`.
    fn restore_keyed(&self, saved: HashMap<(u64, u64), D::V, PairHash>, springs: &mut Vec<D::V>) {
        springs.clear();
        springs.resize(self.neighbors.pairs.len(), D::zero());
        if saved.is_empty() {
            return;
        }
        let id = &self.particles.id;
        springs
            .par_iter_mut()
            .zip(self.neighbors.pairs.par_iter())
            .with_min_len(crate::parallel::min_len(1))
            .for_each(|(spring, &[i, j])| {
                let (a, b) = (id[i as usize], id[j as usize]);
                if a < b {
                    if let Some(&s) = saved.get(&(a, b)) {
                        *spring = s;
                    }
                } else if let Some(&s) = saved.get(&(b, a)) {
                    *spring = -s;
                }
            });
    }
}
