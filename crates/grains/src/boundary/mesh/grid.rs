//! A uniform grid over a mesh's triangles, so that a grain meets only the
//! few triangles near it whatever the mesh's size.
//!
//! A uniform grid rather than a tree: mesh walls are surfaces of fairly
//! even triangles (CAD exports), a grain's reach is about one cell, and a
//! lookup is then a handful of cells with no descent; written here because
//! it is forty lines over the triangles' boxes.

use glam::DVec3;

/// Triangles listed by the cells their bounding boxes overlap.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct TriGrid {
    lo: DVec3,
    inv_cell: f64,
    dims: [usize; 3],
    /// Cell c's triangles are `items[start[c]..start[c + 1]]`.
    start: Vec<u32>,
    items: Vec<u32>,
}

/// Cells at most this many times the triangles (most of a surface's
/// bounding box is empty space).
const CELLS_PER_TRIANGLE: f64 = 4.0;

impl TriGrid {
    /// A grid over the boxes `boxes` (lo, hi per triangle) inside
    /// (`lo`, `hi`), with cells about as wide as a triangle.
    pub(crate) fn new(boxes: &[(DVec3, DVec3)], lo: DVec3, hi: DVec3) -> Self {
        let size = (hi - lo).max(DVec3::splat(1e-300));
        let mean = boxes
            .iter()
            .map(|(a, b)| (*b - *a).max_element())
            .sum::<f64>()
            / boxes.len() as f64;
        let mut cell = mean.max(1e-12 * size.max_element());
        let dims_for = |cell: f64| size.to_array().map(|s| ((s / cell).ceil() as usize).max(1));
        let limit = CELLS_PER_TRIANGLE * boxes.len() as f64 + 64.0;
        while dims_for(cell).iter().map(|&d| d as f64).product::<f64>() > limit {
            cell *= 1.25;
        }
        let dims = dims_for(cell);
        let inv_cell = 1.0 / cell;
        let mut grid = Self {
            lo,
            inv_cell,
            dims,
            start: vec![0; dims[0] * dims[1] * dims[2] + 1],
            items: Vec::new(),
        };
        // Counting sort: count, prefix sums, fill.
        let mut counts = vec![0u32; grid.start.len()];
        for b in boxes {
            let (l, h) = grid.range(b.0, b.1);
            for_cells(l, h, dims, |c| counts[c] += 1);
        }
        let mut sum = 0u32;
        for (s, n) in grid.start.iter_mut().zip(&counts) {
            *s = sum;
            sum += n;
        }
        *grid.start.last_mut().unwrap() = sum;
        let mut fill = grid.start.clone();
        grid.items = vec![0; sum as usize];
        for (t, b) in boxes.iter().enumerate() {
            let (l, h) = grid.range(b.0, b.1);
            for_cells(l, h, dims, |c| {
                grid.items[fill[c] as usize] = t as u32;
                fill[c] += 1;
            });
        }
        grid
    }

    /// The cell coordinates of `x`, clamped to the grid.
    #[inline]
    fn cell_of(&self, x: DVec3) -> [usize; 3] {
        let f = ((x - self.lo) * self.inv_cell).to_array();
        std::array::from_fn(|a| {
            let i = f[a].floor();
            if i.is_nan() || i < 0.0 {
                0
            } else {
                (i as usize).min(self.dims[a] - 1)
            }
        })
    }

    #[inline]
    fn range(&self, lo: DVec3, hi: DVec3) -> ([usize; 3], [usize; 3]) {
        (self.cell_of(lo), self.cell_of(hi))
    }

    /// Calls `f` once for each triangle whose box overlaps the box (`lo`,
    /// `hi`) in a cell, given the triangles' boxes: a triangle listed in
    /// several cells is reported only from the first cell of the overlap
    /// of its box with the query's, so no list of seen triangles is kept.
    #[inline]
    pub(crate) fn visit(
        &self,
        lo: DVec3,
        hi: DVec3,
        boxes: &[(DVec3, DVec3)],
        mut f: impl FnMut(usize),
    ) {
        let (l, h) = self.range(lo, hi);
        for_cells(l, h, self.dims, |c| {
            for &t in &self.items[self.start[c] as usize..self.start[c + 1] as usize] {
                let (tl, th) = boxes[t as usize];
                if tl.cmpgt(hi).any() || th.cmplt(lo).any() {
                    continue;
                }
                if self.cell_index(self.cell_of(tl.max(lo))) == c {
                    f(t as usize);
                }
            }
        });
    }

    #[inline]
    fn cell_index(&self, i: [usize; 3]) -> usize {
        (i[2] * self.dims[1] + i[1]) * self.dims[0] + i[0]
    }
}

#[inline]
fn for_cells(l: [usize; 3], h: [usize; 3], dims: [usize; 3], mut f: impl FnMut(usize)) {
    for z in l[2]..=h[2] {
        for y in l[1]..=h[1] {
            let row = (z * dims[1] + y) * dims[0];
            for x in l[0]..=h[0] {
                f(row + x);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_overlapping_box_is_visited_once() {
        // A 20 x 20 sheet of unit boxes at z = 0, and a query box.
        let boxes: Vec<(DVec3, DVec3)> = (0..400)
            .map(|k| {
                let lo = DVec3::new((k % 20) as f64, (k / 20) as f64, 0.0);
                (lo, lo + DVec3::new(1.0, 1.0, 0.0))
            })
            .collect();
        let grid = TriGrid::new(&boxes, DVec3::ZERO, DVec3::new(20.0, 20.0, 0.0));
        let (qlo, qhi) = (DVec3::new(3.5, 7.2, -0.4), DVec3::new(6.1, 9.0, 0.4));
        let mut seen = Vec::new();
        grid.visit(qlo, qhi, &boxes, |t| seen.push(t));
        let mut want: Vec<usize> = (0..400)
            .filter(|&t| {
                let (l, h) = boxes[t];
                !(l.cmpgt(qhi).any() || h.cmplt(qlo).any())
            })
            .collect();
        seen.sort_unstable();
        want.sort_unstable();
        assert_eq!(seen, want);
        // x cells 3 to 6, y cells 7 to 9 (the box [9, 10] touches y = 9).
        assert_eq!(want.len(), 4 * 3);
    }
}
