//! A regular grid of cells over the domain, and particles binned into it by a
//! counting sort (flat arrays only, so rebuilding costs no per-cell
//! allocation).
//!
//! Cells are at least as wide as the largest interaction reach, so every pair
//! within reach sits in the same or in adjacent cells. On non-periodic axes the
//! domain bounds only size the grid: grains outside it are clamped into the
//! edge cells, which only brings cells closer and so never loses a pair.

use crate::dim::Dim;
use crate::domain::Domain;

/// Most cells along one axis: keeps cell indices far from overflow even for a
/// tiny requested side.
const MAX_CELLS_PER_AXIS: usize = 1 << 20;

/// Relative widening of the requested side, so that rounding in the cell
/// coordinate of a grain (about one ulp) cannot make a cell narrower than the
/// reach.
const SIDE_MARGIN: f64 = 1e-9;

/// The geometry of the grid: cells per axis and how a coordinate maps to one.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct GridShape {
    /// Cells per axis (1 on axes beyond the dimension).
    pub dims: [usize; 3],
    pub lo: [f64; 3],
    /// Cells per unit length (0 on an axis with a single cell).
    pub inv_width: [f64; 3],
}

impl GridShape {
    /// Cells of side at least `min_side` on every axis; if that would make more
    /// than `max_cells` cells, the side grows until it does not (wider cells
    /// stay correct, just slower).
    pub fn new<D: Dim>(domain: &Domain<D>, min_side: f64, max_cells: usize) -> Self {
        let longest = (0..D::D)
            .map(|a| domain.length(a))
            .filter(|l| l.is_finite())
            .fold(0.0, f64::max);
        let mut side = if min_side.is_finite() && min_side > 0.0 {
            min_side * (1.0 + SIDE_MARGIN)
        } else {
            0.0
        };
        side = side
            .max(longest / MAX_CELLS_PER_AXIS as f64)
            .max(f64::MIN_POSITIVE);
        loop {
            let shape = Self::with_side(domain, side);
            if shape.ncells() <= max_cells.max(1) {
                return shape;
            }
            side *= 1.25;
        }
    }

    fn with_side<D: Dim>(domain: &Domain<D>, side: f64) -> Self {
        let mut shape = Self {
            dims: [1; 3],
            lo: [0.0; 3],
            inv_width: [0.0; 3],
        };
        for a in 0..D::D {
            let l = domain.length(a);
            shape.lo[a] = D::get(domain.lo, a);
            if !(l.is_finite() && l > 0.0) {
                continue;
            }
            let mut n = (l / side).floor().clamp(1.0, MAX_CELLS_PER_AXIS as f64) as usize;
            while n > 1 && l / (n as f64) < side {
                n -= 1;
            }
            if n > 1 {
                shape.dims[a] = n;
                shape.inv_width[a] = n as f64 / l;
            }
        }
        shape
    }

    pub fn ncells(&self) -> usize {
        self.dims[0]
            .saturating_mul(self.dims[1])
            .saturating_mul(self.dims[2])
    }

    /// The cell coordinate of `x` along `axis`, clamped into the grid (a NaN
    /// lands in cell 0).
    #[inline]
    pub fn coord(&self, axis: usize, x: f64) -> usize {
        let f = (x - self.lo[axis]) * self.inv_width[axis];
        (f.max(0.0) as usize).min(self.dims[axis] - 1)
    }

    /// Linear index of a cell: x fastest, then y, then z.
    #[inline]
    pub fn linear(&self, c: [usize; 3]) -> usize {
        c[0] + self.dims[0] * (c[1] + self.dims[1] * c[2])
    }

    /// Cell coordinates from a linear index.
    #[inline]
    pub fn unlinear(&self, mut k: usize) -> [usize; 3] {
        let x = k % self.dims[0];
        k /= self.dims[0];
        [x, k % self.dims[1], k / self.dims[1]]
    }

    /// Linear index of the cell holding position `p`.
    #[inline]
    pub fn cell_of<D: Dim>(&self, p: D::V) -> usize {
        let mut c = [0usize; 3];
        for (a, ca) in c.iter_mut().enumerate().take(D::D) {
            *ca = self.coord(a, D::get(p, a));
        }
        self.linear(c)
    }
}

/// Particles binned into cells: the particles of cell `c` are
/// `members[start[c]..start[c + 1]]`, in ascending index order (the counting
/// sort is stable), which keeps the pair order deterministic.
#[derive(Clone, Debug, Default)]
pub(crate) struct CellGrid {
    pub shape: GridShape,
    pub start: Vec<u32>,
    pub members: Vec<u32>,
    /// Linear cell index of each particle.
    pub cell: Vec<u32>,
}

impl CellGrid {
    /// Bins `pos` into a grid of the given shape (whose cell count must fit
    /// in `u32`), reusing this grid's buffers.
    pub fn bin<D: Dim>(&mut self, shape: GridShape, pos: &[D::V]) {
        let ncells = shape.ncells();
        debug_assert!(ncells < u32::MAX as usize);
        self.cell.clear();
        self.cell
            .extend(pos.iter().map(|&p| shape.cell_of::<D>(p) as u32));
        self.start.clear();
        self.start.resize(ncells + 1, 0);
        for &c in &self.cell {
            self.start[c as usize + 1] += 1;
        }
        for k in 0..ncells {
            self.start[k + 1] += self.start[k];
        }
        self.members.clear();
        self.members.resize(pos.len(), 0);
        // `start[c]` serves as the fill cursor of cell c, then is restored.
        for (i, &c) in self.cell.iter().enumerate() {
            let slot = &mut self.start[c as usize];
            self.members[*slot as usize] = i as u32;
            *slot += 1;
        }
        for k in (1..=ncells).rev() {
            self.start[k] = self.start[k - 1];
        }
        self.start[0] = 0;
        self.shape = shape;
    }

    /// The particles in cell `c`.
    #[inline]
    pub fn cell_members(&self, c: usize) -> &[u32] {
        &self.members[self.start[c] as usize..self.start[c + 1] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::D2;
    use glam::DVec2;

    #[test]
    fn counting_sort_bins_every_particle_once_in_index_order() {
        let domain = Domain::<D2>::new(DVec2::ZERO, DVec2::new(4.0, 3.0), [false; 3]);
        let shape = GridShape::new(&domain, 1.0, 1000);
        assert_eq!(shape.dims, [3, 2, 1]);
        let pos = [
            DVec2::new(3.9, 2.9),
            DVec2::new(0.1, 0.1),
            DVec2::new(-5.0, 9.0), // outside: clamped to cell (0, 1)
            DVec2::new(3.5, 2.0),
            DVec2::new(0.2, 0.3),
        ];
        let mut grid = CellGrid::default();
        grid.bin::<D2>(shape, &pos);
        assert_eq!(grid.cell_members(0), &[1, 4]);
        assert_eq!(grid.cell_members(shape.linear([0, 1, 0])), &[2]);
        assert_eq!(grid.cell_members(shape.linear([2, 1, 0])), &[0, 3]);
        assert_eq!(grid.members.len(), pos.len());
        assert_eq!(shape.unlinear(shape.linear([2, 1, 0])), [2, 1, 0]);
    }

    #[test]
    fn cell_count_is_capped() {
        let domain = Domain::<D2>::new(DVec2::ZERO, DVec2::new(100.0, 100.0), [false; 3]);
        let shape = GridShape::new(&domain, 0.0, 64);
        assert!(shape.ncells() <= 64);
        assert!(shape.ncells() >= 16);
    }
}
