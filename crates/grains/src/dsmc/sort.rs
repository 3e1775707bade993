//! The cell grid and the in-place counting sort.
//!
//! After streaming, each particle's cell index is written into `key` (one
//! `u32` per particle). A counting sort turns it into each particle's
//! destination, and the particles are moved there in place by following the
//! permutation's cycles: every record is read and written once, and no
//! second copy of the store is ever allocated. Particles move less than a
//! cell per step, so most of the permutation is local and the sort runs at
//! memory speed. After the sort the particles of cell c are the contiguous
//! slice `start[c]..start[c + 1]`, in the cells' order (x fastest, the
//! vertical axis slowest, so a horizontal layer of cells is contiguous too).

use super::store::Particle;
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
}

impl CellGrid {
    /// Cells of edge close to `cell` (at least one per axis) filling the box
    /// `lo..hi` exactly.
    pub fn new(dim: usize, lo: [f64; 3], hi: [f64; 3], cell: f64) -> Self {
        let mut n = [1u32; 3];
        let mut size = [1.0; 3];
        let mut inv = [0.0; 3];
        for a in 0..dim {
            let l = hi[a] - lo[a];
            n[a] = ((l / cell).round() as u32).max(1);
            size[a] = l / n[a] as f64;
            inv[a] = 1.0 / size[a];
        }
        Self {
            dim,
            lo,
            n,
            size,
            inv,
        }
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
            // `as` saturates: negative and NaN go to 0.
            let k = (f as u32).min(self.n[a] - 1);
            idx += k * stride;
            stride *= self.n[a];
        }
        idx
    }
}

/// Counting sort of `p` by the cell indices in `key`, in place. On return
/// `start` (length cells + 1) holds each cell's first particle and every
/// `key[i] == i`. `fill` is scratch of length cells.
pub fn sort_in_place<D: Dim>(
    p: &mut [Particle<D>],
    key: &mut [u32],
    start: &mut [u32],
    fill: &mut [u32],
) {
    debug_assert_eq!(p.len(), key.len());
    debug_assert_eq!(start.len(), fill.len() + 1);
    start.fill(0);
    for &c in key.iter() {
        start[c as usize + 1] += 1;
    }
    for c in 1..start.len() {
        start[c] += start[c - 1];
    }
    fill.copy_from_slice(&start[..start.len() - 1]);
    for k in key.iter_mut() {
        let c = *k as usize;
        *k = fill[c];
        fill[c] += 1;
    }
    permute_in_place(p, key);
}

/// Moves `p[i]` to `p[dest[i]]` for every i by following cycles; leaves
/// `dest[i] == i`. Each record is read once and written once.
pub fn permute_in_place<T: Copy>(p: &mut [T], dest: &mut [u32]) {
    for i in 0..p.len() {
        let mut d = dest[i] as usize;
        if d == i {
            continue;
        }
        let mut carry = p[i];
        loop {
            let next = dest[d] as usize;
            dest[d] = d as u32;
            std::mem::swap(&mut carry, &mut p[d]);
            if d == i {
                break;
            }
            d = next;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::D2;
    use glam::DVec2;

    #[test]
    fn permutation_places_every_record() {
        let mut p: Vec<u32> = (0..10).collect();
        let mut dest = vec![3u32, 0, 1, 2, 9, 5, 8, 7, 6, 4];
        let want_at = dest.clone();
        permute_in_place(&mut p, &mut dest);
        for (i, &d) in want_at.iter().enumerate() {
            assert_eq!(p[d as usize], i as u32);
        }
        assert!(dest.iter().enumerate().all(|(i, &d)| d as usize == i));
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
        let mut key: Vec<u32> = p.iter().map(|q| grid.cell_of::<D2>(q.x)).collect();
        let mut start = vec![0; 9];
        let mut fill = vec![0; 8];
        sort_in_place(&mut p, &mut key, &mut start, &mut fill);
        assert_eq!(start, vec![0, 2, 3, 3, 3, 3, 3, 3, 5]);
        assert_eq!(p[0].x, DVec2::new(0.2, 0.1));
        assert_eq!(p[1].x, DVec2::new(0.7, 0.9));
        assert_eq!(p[3].x, DVec2::new(3.5, 1.5));
        assert_eq!(p[4].x, DVec2::new(3.9, 1.2));
    }
}
