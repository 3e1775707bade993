//! Tangential springs of grain–wall contacts, kept only where they are
//! stretched.
//!
//! Few grains touch a wall, so one spring per grain per wall (24 bytes per
//! grain and wall in 3D) was mostly zeros; here each stretched spring is an
//! entry keyed by (grain index, wall index), in ascending key order. A
//! missing entry is an unstretched spring, which is what a dense array
//! would hold, so the physics and its bits are unchanged. Checkpoints keep
//! the dense layout (`to_dense` / `from_dense`).

use crate::dim::Dim;
use std::ops::Range;

/// What a spring is keyed by: a grain index first, then what it touches.
pub trait SpringKey: Copy + Ord + std::fmt::Debug {
    fn grain(self) -> u32;
    /// The same key for the grain's new index.
    fn regrain(self, grain: u32) -> Self;
}

/// (grain, wall): one spring per grain and wall.
impl SpringKey for (u32, u32) {
    #[inline]
    fn grain(self) -> u32 {
        self.0
    }
    fn regrain(self, grain: u32) -> Self {
        (grain, self.1)
    }
}

/// (grain, wall, patch): a mesh wall's springs, one per flat patch a grain
/// touches ([`crate::boundary::Mesh`]).
impl SpringKey for (u32, u32, u32) {
    #[inline]
    fn grain(self) -> u32 {
        self.0
    }
    fn regrain(self, grain: u32) -> Self {
        (grain, self.1, self.2)
    }
}

/// The key of a mesh wall's springs.
pub type MeshKey = (u32, u32, u32);

/// One mesh spring as states and checkpoints list them: (key, spring).
pub type MeshEntry<V> = (MeshKey, V);

/// A kind of spring's two stores: plane-like walls' and mesh walls'.
pub type WallAndMesh<'a, D> = (&'a mut WallSprings<D>, &'a mut WallSprings<D, MeshKey>);

#[derive(Clone, Debug, Default, PartialEq)]
pub struct WallSprings<D: Dim, K = (u32, u32)> {
    /// Keys strictly ascending.
    keys: Vec<K>,
    springs: Vec<D::V>,
}

/// A chunk's springs after a force evaluation, appended in key order.
#[derive(Debug, Default)]
pub struct ChunkSprings<D: Dim, K = (u32, u32)> {
    keys: Vec<K>,
    springs: Vec<D::V>,
}

impl<D: Dim> ChunkSprings<D> {
    /// Keeps `spring` for (`grain`, `wall`) when it is stretched; keys must
    /// come in ascending order.
    #[inline]
    pub fn keep(&mut self, grain: usize, wall: usize, spring: D::V) {
        self.keep_key((grain as u32, wall as u32), spring);
    }
}

impl<D: Dim, K: SpringKey> ChunkSprings<D, K> {
    /// Keeps `spring` for `key` when it is stretched; keys must come in
    /// ascending order.
    #[inline]
    pub fn keep_key(&mut self, key: K, spring: D::V) {
        if spring != D::zero() {
            self.keys.push(key);
            self.springs.push(spring);
        }
    }
}

/// Reads one chunk's springs in key order.
pub struct Cursor<'a, D: Dim, K = (u32, u32)> {
    keys: &'a [K],
    springs: &'a [D::V],
    at: usize,
}

impl<D: Dim> Cursor<'_, D> {
    /// The spring of (`grain`, `wall`); queries must come in ascending order.
    #[inline]
    pub fn get(&mut self, grain: usize, wall: usize) -> D::V {
        self.get_key((grain as u32, wall as u32))
    }
}

impl<D: Dim, K: SpringKey> Cursor<'_, D, K> {
    /// The spring of `key`; queries must come in ascending order.
    #[inline]
    pub fn get_key(&mut self, key: K) -> D::V {
        while self.at < self.keys.len() && self.keys[self.at] < key {
            self.at += 1;
        }
        if self.at < self.keys.len() && self.keys[self.at] == key {
            self.springs[self.at]
        } else {
            D::zero()
        }
    }
}

impl<D: Dim, K: SpringKey> WallSprings<D, K> {
    /// The springs of grains in `grains`, for reading in key order.
    pub fn cursor(&self, grains: Range<usize>) -> Cursor<'_, D, K> {
        let lo = self
            .keys
            .partition_point(|k| (k.grain() as usize) < grains.start);
        let hi = self
            .keys
            .partition_point(|k| (k.grain() as usize) < grains.end);
        Cursor {
            keys: &self.keys[lo..hi],
            springs: &self.springs[lo..hi],
            at: 0,
        }
    }

    /// Replaces the springs by the chunks' (chunks in grain order).
    pub fn assemble(&mut self, chunks: impl IntoIterator<Item = ChunkSprings<D, K>>) {
        self.keys.clear();
        self.springs.clear();
        for c in chunks {
            self.keys.extend_from_slice(&c.keys);
            self.springs.extend_from_slice(&c.springs);
        }
    }

    /// Every stretched spring as (key, spring), in key order.
    pub fn entries(&self) -> impl Iterator<Item = (K, D::V)> + '_ {
        self.keys.iter().copied().zip(self.springs.iter().copied())
    }

    /// From (key, spring) entries in any order (distinct keys).
    pub fn from_entries(mut entries: Vec<(K, D::V)>) -> Self {
        entries.sort_unstable_by_key(|e| e.0);
        Self {
            keys: entries.iter().map(|e| e.0).collect(),
            springs: entries.iter().map(|e| e.1).collect(),
        }
    }

    /// Keeps the springs of the grains at `keep` (ascending old indices),
    /// renumbered to their place in `keep`; the others' springs go with
    /// their grains. Key order is kept, as the kept grains keep theirs.
    pub fn retain_grains(&mut self, keep: &[u32], old_len: usize) {
        if self.keys.is_empty() {
            return;
        }
        let mut new_index = vec![u32::MAX; old_len];
        for (k, &o) in keep.iter().enumerate() {
            new_index[o as usize] = k as u32;
        }
        let (keys, springs): (Vec<K>, Vec<D::V>) = self
            .keys
            .iter()
            .zip(&self.springs)
            .filter_map(|(&k, &s)| {
                let g = new_index[k.grain() as usize];
                (g != u32::MAX).then(|| (k.regrain(g), s))
            })
            .unzip();
        self.keys = keys;
        self.springs = springs;
    }

    /// Follows a reordering of the grains (`order[k]` = old index of new
    /// grain k).
    pub fn permute(&mut self, order: &[u32]) {
        if self.keys.is_empty() {
            return;
        }
        let mut new_index = vec![0u32; order.len()];
        for (k, &o) in order.iter().enumerate() {
            new_index[o as usize] = k as u32;
        }
        let mut entries: Vec<(K, D::V)> = self
            .keys
            .iter()
            .zip(&self.springs)
            .map(|(&k, &s)| (k.regrain(new_index[k.grain() as usize]), s))
            .collect();
        entries.sort_unstable_by_key(|e| e.0);
        self.keys = entries.iter().map(|e| e.0).collect();
        self.springs = entries.iter().map(|e| e.1).collect();
    }
}

impl<D: Dim> WallSprings<D> {
    /// The dense layout of checkpoints: `dense[i * slots + w]` is grain i's
    /// spring against wall w, `slots` per grain.
    pub fn to_dense(&self, grains: usize, slots: usize) -> Vec<D::V> {
        let mut dense = vec![D::zero(); grains * slots];
        for (&(g, w), &s) in self.keys.iter().zip(&self.springs) {
            dense[g as usize * slots + w as usize] = s;
        }
        dense
    }

    /// From the dense layout (see [`Self::to_dense`]).
    pub fn from_dense(dense: &[D::V], slots: usize) -> Self {
        let mut out = Self::default();
        for (k, &s) in dense.iter().enumerate() {
            if s != D::zero() {
                out.keys.push(((k / slots) as u32, (k % slots) as u32));
                out.springs.push(s);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::D3;
    use glam::DVec3;

    #[test]
    fn dense_round_trip_and_permutation() {
        // 5 grains, 2 walls; grains 1 and 4 touch wall 1, grain 3 both.
        let mut dense = vec![DVec3::ZERO; 10];
        dense[3] = DVec3::X;
        dense[6] = DVec3::Y;
        dense[7] = DVec3::Z;
        dense[9] = DVec3::splat(2.0);
        let s = WallSprings::<D3>::from_dense(&dense, 2);
        assert_eq!(s.keys.len(), 4);
        assert_eq!(s.to_dense(5, 2), dense);
        // Reverse the grains: old grain g becomes 4 − g.
        let mut p = s.clone();
        p.permute(&[4, 3, 2, 1, 0]);
        let moved = p.to_dense(5, 2);
        for g in 0..5 {
            for w in 0..2 {
                assert_eq!(moved[(4 - g) * 2 + w], dense[g * 2 + w]);
            }
        }
        // Cursors see each chunk's springs, zero where none is kept.
        let mut c = p.cursor(0..2);
        assert_eq!(c.get(0, 0), DVec3::ZERO);
        assert_eq!(c.get(0, 1), DVec3::splat(2.0));
        assert_eq!(c.get(1, 0), DVec3::Y);
        assert_eq!(c.get(1, 1), DVec3::Z);
        let mut c = p.cursor(2..5);
        assert_eq!(c.get(2, 1), DVec3::ZERO);
        assert_eq!(c.get(3, 1), DVec3::X);
        assert_eq!(c.get(4, 1), DVec3::ZERO);
    }

    #[test]
    fn assembling_chunks_keeps_only_stretched_springs() {
        let mut a = ChunkSprings::<D3>::default();
        a.keep(0, 0, DVec3::X);
        a.keep(1, 0, DVec3::ZERO);
        let mut b = ChunkSprings::<D3>::default();
        b.keep(7, 2, DVec3::Y);
        let mut s = WallSprings::default();
        s.assemble([a, b]);
        assert_eq!(s.keys.len(), 2);
        let d = s.to_dense(8, 3);
        assert_eq!(d[0], DVec3::X);
        assert_eq!(d[7 * 3 + 2], DVec3::Y);
    }
}
