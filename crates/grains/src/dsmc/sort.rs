//! The cell grid and the in-place counting sort.
//!
//! After streaming, each particle's cell index is written into `key` (one
//! `u32` per particle). Every step a counting sort of the particle indices
//! (`order`, one more `u32`) lists each cell's particles; the collisions
//! reach them through it. Every few steps the records themselves are put
//! in that order, in place (no second copy of the store), so that a
//! cell's particles stay close in memory: particles move less than a cell
//! per step, and a cell's members drift only a few rows of cells away
//! between re-sorts. Cells are numbered x fastest, the vertical axis
//! slowest, so a horizontal layer of cells is contiguous.
//!
//! Moving the records every step would cost a pass over the whole store;
//! doing it every [`RESORT_EVERY`] steps amortizes that while the index
//! sort streams through memory; the move is written for a store that is
//! nearly in order already ([`gather_in_place`]).

/// Steps between physical re-sorts of the records.
pub const RESORT_EVERY: u64 = 16;

use crate::dim::Dim;

/// A regular grid of cells covering the domain.
#[derive(Clone, Debug, PartialEq)]
pub struct CellGrid {
    pub dim: usize,
    pub lo: [f64; 3],
    /// Cells per axis (1 on unused axes).
    pub n: [u32; 3],
    /// Cell edge per axis (m).
    pub size: [f64; 3],
    inv: [f64; 3],
    /// n − 1 per axis, as a float.
    last: [f64; 3],
}

impl CellGrid {
    /// Cells of edge close to `cell` (at least one per axis) filling the box
    /// `lo..hi` exactly.
    pub fn new(dim: usize, lo: [f64; 3], hi: [f64; 3], cell: f64) -> Self {
        let mut n = [1u32; 3];
        let mut size = [1.0; 3];
        let mut inv = [0.0; 3];
        let mut last = [0.0; 3];
        for a in 0..dim {
            let l = hi[a] - lo[a];
            n[a] = ((l / cell).round() as u32).max(1);
            size[a] = l / n[a] as f64;
            inv[a] = 1.0 / size[a];
            last[a] = (n[a] - 1) as f64;
        }
        Self {
            dim,
            lo,
            n,
            size,
            inv,
            last,
        }
    }

    /// The grid of a domain (the engine's, [`super::engine::Dsmc::grid`]).
    pub fn for_domain<D: Dim>(domain: &crate::domain::Domain<D>, cell: f64) -> Self {
        Self::new(D::D, D::to_xyz(domain.lo), D::to_xyz(domain.hi), cell)
    }

    pub fn cells(&self) -> usize {
        self.n.iter().map(|&k| k as usize).product()
    }

    /// Volume (area in 2D) of one cell.
    pub fn cell_volume(&self) -> f64 {
        self.size[..self.dim].iter().product()
    }

    /// The largest cell edge.
    pub fn max_edge(&self) -> f64 {
        self.size[..self.dim].iter().copied().fold(0.0, f64::max)
    }

    /// Cells in one horizontal layer (all axes but the vertical one).
    pub fn cells_per_layer(&self) -> usize {
        self.n[..self.dim - 1].iter().map(|&k| k as usize).product()
    }

    /// Number of horizontal layers (cells along the vertical axis).
    pub fn layers(&self) -> usize {
        self.n[self.dim - 1] as usize
    }

    /// The cell holding `x`; positions outside the grid are clamped into the
    /// edge cells.
    #[inline(always)]
    pub fn cell_of<D: Dim>(&self, x: D::V) -> u32 {
        let mut idx = 0u32;
        let mut stride = 1u32;
        for a in 0..D::D {
            let f = (D::get(x, a) - self.lo[a]) * self.inv[a];
            // Clamped in floating point (NaN and negative go to 0) so that
            // the conversion needs no saturation checks.
            let f = f.max(0.0).min(self.last[a]);
            // SAFETY: f is finite and in [0, n − 1], which u32 holds.
            let k = unsafe { f.to_int_unchecked::<u32>() };
            idx += k * stride;
            stride *= self.n[a];
        }
        idx
    }
}

/// Counting sort of the particle indices by the cell indices in `key`.
/// On return `start` (length cells + 1) holds each cell's first entry in
/// `order`, and `order[start[c]..start[c + 1]]` lists the particles of cell
/// c in increasing index (a stable sort). `fill` is scratch of length cells.
pub fn sort_indices(key: &[u32], start: &mut [u32], fill: &mut [u32], order: &mut [u32]) {
    debug_assert_eq!(order.len(), key.len());
    debug_assert_eq!(start.len(), fill.len() + 1);
    start.fill(0);
    for &c in key {
        start[c as usize + 1] += 1;
    }
    for c in 1..start.len() {
        start[c] += start[c - 1];
    }
    fill.copy_from_slice(&start[..start.len() - 1]);
    for (i, &c) in key.iter().enumerate() {
        let f = &mut fill[c as usize];
        order[*f as usize] = i as u32;
        *f += 1;
    }
}

/// Records that move this far forward or more are kept in the sorted side
/// list of [`Aside`] instead of its ring (a power of two).
const RING: usize = 1 << 15;

/// Scratch of [`gather_in_place`]: the records it must keep aside because
/// their place is overwritten before they reach their new one.
#[derive(Clone, Debug, Default)]
pub struct Aside<T> {
    /// Record s waits in slot s mod the ring's length while it moves
    /// forward by less than that length.
    ring: Vec<T>,
    /// Those that move farther (across the periodic seam, say): old place
    /// and record, by increasing old place.
    far: Vec<(u32, T)>,
}

/// Reorders `p` in place so that the new `p[k]` is the old `p[order[k]]`;
/// leaves `order[k] == k`.
///
/// A record of a store kept in cell order moves only a few rows of cells
/// between re-sorts, so the records are written in increasing place, each
/// read from where it is: ahead of the place being written it is still
/// there; behind, it was kept aside when its place was overwritten (every
/// record passes through a ring of [`RING`] slots, enough for all but the
/// few that move farther, which a side list keeps). Every read and write
/// streams through memory. When more than one record in 16 moves that far
/// (a store in no particular order), the permutation's cycles are followed
/// instead, which needs no side list but waits on memory at every hop.
pub fn gather_in_place<T: Copy + Default>(p: &mut [T], order: &mut [u32], aside: &mut Aside<T>) {
    let n = p.len();
    debug_assert_eq!(order.len(), n);
    let ring = RING.min(n.next_power_of_two().max(1));
    let mask = ring - 1;
    // The far movers: record s goes to k ≥ s + ring.
    let mut far: Vec<u32> = Vec::new();
    for (k, &s) in order.iter().enumerate() {
        if k >= s as usize + ring {
            far.push(s);
            if far.len() > n / 16 {
                return follow_cycles(p, order);
            }
        }
    }
    far.sort_unstable();
    aside.far.clear();
    aside.far.reserve(far.len());
    aside.ring.clear();
    aside.ring.resize(ring, T::default());
    let mut next_far = far.iter().copied().peekable();
    for k in 0..n {
        // Keep the old record k (cheaper to always keep it than to ask
        // whether it moves forward): slot k mod ring last held record
        // k − ring, which moved by less than `ring`, so it is placed.
        let old = p[k];
        aside.ring[k & mask] = old;
        if next_far.peek() == Some(&(k as u32)) {
            next_far.next();
            aside.far.push((k as u32, old));
        }
        let s = order[k] as usize;
        p[k] = if s >= k {
            p[s]
        } else if k - s < ring {
            aside.ring[s & mask]
        } else {
            let at = aside
                .far
                .binary_search_by_key(&(s as u32), |e| e.0)
                .expect("a far mover was kept aside");
            aside.far[at].1
        };
        order[k] = k as u32;
    }
}

/// [`gather_in_place`] by following the permutation's cycles (each record is
/// read and written once, with one record of scratch).
fn follow_cycles<T: Copy>(p: &mut [T], order: &mut [u32]) {
    for i in 0..p.len() {
        if order[i] as usize == i {
            continue;
        }
        let first = p[i];
        let mut j = i;
        loop {
            let k = order[j] as usize;
            order[j] = j as u32;
            if k == i {
                p[j] = first;
                break;
            }
            p[j] = p[k];
            j = k;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::D2;
    use crate::dsmc::store::Particle;
    use glam::DVec2;

    #[test]
    fn gather_places_every_record() {
        let mut p: Vec<u32> = (0..10).map(|i| 100 + i).collect();
        let mut order = vec![3u32, 0, 1, 2, 9, 5, 8, 7, 6, 4];
        let want: Vec<u32> = order.iter().map(|&k| 100 + k).collect();
        gather_in_place(&mut p, &mut order, &mut Aside::default());
        assert_eq!(p, want);
        assert!(order.iter().enumerate().all(|(i, &d)| d as usize == i));
    }

    /// A permutation like the re-sort's: most records move a little either
    /// way, a few across the whole store (both ways), some not at all;
    /// larger than the ring, so records wait in it and in the side list.
    #[test]
    fn gather_of_a_nearly_sorted_store_places_every_record() {
        let n = 5 * RING + 123;
        let mut rng = crate::dsmc::rng::Stream::new(3, 1, 4);
        // Sort made-up destinations: each place moves by up to ±RING/2,
        // every 500th by up to the whole store.
        let mut dest: Vec<(u64, u32)> = (0..n)
            .map(|s| {
                let reach = if s % 500 == 0 { n } else { RING / 2 };
                let d = s as i64 + rng.below(2 * reach as u32) as i64 - reach as i64;
                (
                    d.rem_euclid(n as i64) as u64 * n as u64 + s as u64,
                    s as u32,
                )
            })
            .collect();
        dest.sort_unstable();
        let order: Vec<u32> = dest.iter().map(|e| e.1).collect();
        let far = order
            .iter()
            .enumerate()
            .filter(|&(k, &s)| k >= s as usize + RING)
            .count();
        assert!(far > 0 && far < n / 16, "{far}");
        let mut p: Vec<u64> = (0..n as u64).map(|i| 7 * i + 1).collect();
        let want: Vec<u64> = order.iter().map(|&s| 7 * s as u64 + 1).collect();
        let mut o = order.clone();
        gather_in_place(&mut p, &mut o, &mut Aside::default());
        assert_eq!(p, want);
        assert!(o.iter().enumerate().all(|(i, &d)| d as usize == i));
        // A store in no order: the cycles are followed instead.
        let mut shuffled: Vec<u32> = (0..n as u32).collect();
        for i in (1..n).rev() {
            shuffled.swap(i, rng.below(i as u32 + 1) as usize);
        }
        let mut p: Vec<u64> = (0..n as u64).collect();
        let want: Vec<u64> = shuffled.iter().map(|&s| s as u64).collect();
        gather_in_place(&mut p, &mut shuffled, &mut Aside::default());
        assert_eq!(p, want);
    }

    /// The counting sort is the stable sort by cell, with strays among
    /// nearly sorted keys and with empty and single-particle stores.
    #[test]
    fn sort_matches_a_stable_sort() {
        let mut rng = crate::dsmc::rng::Stream::new(5, 9, 2);
        for (n, cells) in [(0, 3), (1, 1), (3, 2), (17, 5), (4099, 37), (10_000, 1000)] {
            let key: Vec<u32> = (0..n)
                .map(|i| {
                    // Mostly sorted, with strays.
                    if rng.below(4) == 0 {
                        rng.below(cells)
                    } else {
                        (i as u64 * cells as u64 / n.max(1) as u64) as u32
                    }
                })
                .collect();
            let mut want: Vec<u32> = (0..n as u32).collect();
            want.sort_by_key(|&i| key[i as usize]);
            let mut start = vec![9; cells as usize + 1];
            let mut order = vec![0; n];
            let mut fill = vec![0; cells as usize];
            sort_indices(&key, &mut start, &mut fill, &mut order);
            assert_eq!(order, want, "n = {n}");
            for c in 0..cells as usize {
                let members = key.iter().filter(|&&k| k as usize == c).count();
                assert_eq!((start[c + 1] - start[c]) as usize, members);
            }
            assert_eq!(start[cells as usize] as usize, n);
        }
    }

    #[test]
    fn sort_groups_by_cell_stably() {
        let grid = CellGrid::new(2, [0.0; 3], [4.0, 2.0, 0.0], 1.0);
        assert_eq!(grid.cells(), 8);
        let xs = [(3.5, 1.5), (0.2, 0.1), (3.9, 1.2), (1.5, 0.5), (0.7, 0.9)];
        let mut p: Vec<Particle<D2>> = xs
            .iter()
            .map(|&(x, y)| Particle {
                x: DVec2::new(x, y),
                v: DVec2::new(x, 0.0),
            })
            .collect();
        let key: Vec<u32> = p.iter().map(|q| grid.cell_of::<D2>(q.x)).collect();
        let mut start = vec![0; 9];
        let mut order = vec![0; 5];
        sort_indices(&key, &mut start, &mut [0; 8], &mut order);
        assert_eq!(order, vec![1, 4, 3, 0, 2]);
        gather_in_place(&mut p, &mut order, &mut Aside::default());
        assert_eq!(start, vec![0, 2, 3, 3, 3, 3, 3, 3, 5]);
        assert_eq!(p[0].x, DVec2::new(0.2, 0.1));
        assert_eq!(p[1].x, DVec2::new(0.7, 0.9));
        assert_eq!(p[3].x, DVec2::new(3.5, 1.5));
        assert_eq!(p[4].x, DVec2::new(3.9, 1.2));
    }
}
