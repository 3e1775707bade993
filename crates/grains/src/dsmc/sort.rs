//! The cell grid and the in-place counting sort.
//!
//! After streaming, each particle's cell index is written into `key` (one
//! `u32` per particle). Every step a counting sort of the particle indices
//! (`order`, one more `u32`) lists each cell's particles; the collisions
//! reach them through it. Every few steps the records themselves are put
//! in that order, in place, by following the permutation's cycles (each
//! record read and written once, no second copy of the store), so that a
//! cell's particles stay close in memory: particles move less than a cell
//! per step, and a cell's members drift only a few rows of cells away
//! between re-sorts. Cells are numbered x fastest, the vertical axis
//! slowest, so a horizontal layer of cells is contiguous.
//!
//! Moving the records every step would cost a dependent cache miss per hop
//! of a permutation cycle; doing it every [`RESORT_EVERY`] steps amortizes
//! that while the index sort streams through memory.

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

/// Reorders `p` in place so that the new `p[k]` is the old `p[order[k]]`,
/// by following the permutation's cycles (each record is read and written
/// once, with one record of scratch); leaves `order[k] == k`.
pub fn gather_in_place<T: Copy>(p: &mut [T], order: &mut [u32]) {
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
        gather_in_place(&mut p, &mut order);
        assert_eq!(p, want);
        assert!(order.iter().enumerate().all(|(i, &d)| d as usize == i));
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
        let mut fill = vec![0; 8];
        let mut order = vec![0; 5];
        sort_indices(&key, &mut start, &mut fill, &mut order);
        assert_eq!(order, vec![1, 4, 3, 0, 2]);
        gather_in_place(&mut p, &mut order);
        assert_eq!(start, vec![0, 2, 3, 3, 3, 3, 3, 3, 5]);
        assert_eq!(p[0].x, DVec2::new(0.2, 0.1));
        assert_eq!(p[1].x, DVec2::new(0.7, 0.9));
        assert_eq!(p[3].x, DVec2::new(3.5, 1.5));
        assert_eq!(p[4].x, DVec2::new(3.9, 1.2));
    }
}
