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
    /// Cell c's triangles are `items[start[c]..start[c + 1]]`, each with
    /// its group (a mesh's patch), so that a lookup can pass over a group
    /// without reading the box.
    start: Vec<u32>,
    items: Vec<(u32, u32)>,
    /// Each item's triangle box, beside it: a cell's boxes are read in a
    /// row (looked up by triangle they were cache misses, a fifth of the
    /// lookup's time on a 1e5-triangle floor).
    item_boxes: Vec<(DVec3, DVec3)>,
    /// The one group of all a cell's items, `u32::MAX` when they are of
    /// several (or none): a cell of a skipped group is passed over without
    /// reading its items, so a flat floor costs one cell per lookup.
    cell_group: Vec<u32>,
}

/// Cells at most this many times the triangles (most of a surface's
/// bounding box is empty space).
const CELLS_PER_TRIANGLE: f64 = 4.0;

impl TriGrid {
    /// A grid over the boxes `boxes` (lo, hi per triangle) inside
    /// (`lo`, `hi`), with cells about as wide as a triangle.
    pub(crate) fn new(boxes: &[(DVec3, DVec3)], groups: &[u32], lo: DVec3, hi: DVec3) -> Self {
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
            item_boxes: Vec::new(),
            cell_group: Vec::new(),
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
        grid.items = vec![(0, 0); sum as usize];
        grid.item_boxes = vec![(DVec3::ZERO, DVec3::ZERO); sum as usize];
        for (t, b) in boxes.iter().enumerate() {
            let (l, h) = grid.range(b.0, b.1);
            for_cells(l, h, dims, |c| {
                grid.items[fill[c] as usize] = (t as u32, groups[t]);
                grid.item_boxes[fill[c] as usize] = *b;
                fill[c] += 1;
            });
        }
        grid.cell_group = (0..grid.start.len() - 1)
            .map(|c| {
                let cell = &grid.items[grid.start[c] as usize..grid.start[c + 1] as usize];
                match cell.first() {
                    Some(&(_, g)) if cell.iter().all(|i| i.1 == g) => g,
                    _ => u32::MAX,
                }
            })
            .collect();
        grid
    }

    /// The cell coordinates of `x`, clamped to the grid. (Truncation, not
    /// `floor`: the same for the non-negative values kept, and `floor` is a
    /// library call on plain x86-64.)
    #[inline]
    fn cell_of(&self, x: DVec3) -> [usize; 3] {
        let f = ((x - self.lo) * self.inv_cell).to_array();
        std::array::from_fn(|a| {
            if f[a] >= 0.0 {
                (f[a] as usize).min(self.dims[a] - 1)
            } else {
                0
            }
        })
    }

    /// The cells a box [`lo`, `hi`] overlaps with more than its boundary:
    /// a box ending exactly on a cell's lower face is not listed there
    /// (what touches only that face is farther than any reach the box was
    /// widened by).
    #[inline]
    fn range(&self, lo: DVec3, hi: DVec3) -> ([usize; 3], [usize; 3]) {
        let l = self.cell_of(lo);
        let f = ((hi - self.lo) * self.inv_cell).to_array();
        let h = std::array::from_fn(|a| {
            if f[a] >= 0.0 {
                let k = f[a] as usize;
                // On a face: the cell below, unless that is before `lo`'s.
                let k = if k as f64 == f[a] && k > l[a] {
                    k - 1
                } else {
                    k
                };
                k.min(self.dims[a] - 1)
            } else {
                0
            }
        });
        (l, h)
    }

    /// Calls `f` for each triangle whose box overlaps the box (`lo`, `hi`)
    /// in a cell, unless its group is in `skip` (which `f` may add to). A
    /// triangle listed in several cells is reported from the first cell of
    /// the overlap of its box with the query's, so no list of seen
    /// triangles is kept; and from the middle cell, which is read first
    /// and whole (so at most twice: the caller must allow that). In the
    /// middle cell the triangles that `leads` picks (by group and box) come
    /// first: a caller that can guess where its answer lies, and that skips
    /// a group once answered, then reads the rest of the cell for little.
    #[inline]
    pub(crate) fn visit(
        &self,
        (lo, hi): (DVec3, DVec3),
        skip: &mut Vec<u32>,
        mut leads: impl FnMut(u32, (DVec3, DVec3)) -> bool,
        mut f: impl FnMut(usize, &mut Vec<u32>),
    ) {
        let (l, h) = self.range(lo, hi);
        // The middle cell first: the nearest triangle is most often there,
        // and a flat patch met at its face needs none of the others.
        // Triangles whose first cell is another are reported there too:
        // at a corner shared by cells, rounding may put a triangle that
        // holds the middle in the cell below.
        let mid = self.cell_index(self.cell_of(0.5 * (lo + hi)));
        for lead in [true, false] {
            self.visit_cell(mid, (lo, hi), skip, &mut f, |g, b| leads(g, b) == lead);
        }
        for_cells(l, h, self.dims, |c| {
            if c != mid {
                self.visit_cell(c, (lo, hi), skip, &mut f, |_, (tl, _)| {
                    self.cell_index(self.cell_of(tl.max(lo))) == c
                });
            }
        });
    }

    /// [`Self::visit`] in cell `c` only, of the triangles `pick` takes.
    #[inline]
    fn visit_cell(
        &self,
        c: usize,
        (lo, hi): (DVec3, DVec3),
        skip: &mut Vec<u32>,
        f: &mut impl FnMut(usize, &mut Vec<u32>),
        mut pick: impl FnMut(u32, (DVec3, DVec3)) -> bool,
    ) {
        if skip.contains(&self.cell_group[c]) {
            return;
        }
        let cell = self.start[c] as usize..self.start[c + 1] as usize;
        for (&(t, group), &(tl, th)) in self.items[cell.clone()].iter().zip(&self.item_boxes[cell])
        {
            if skip.contains(&group) || tl.cmpgt(hi).any() || th.cmplt(lo).any() {
                continue;
            }
            if pick(group, (tl, th)) {
                f(t as usize, skip);
            }
        }
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
        let grid = TriGrid::new(&boxes, &[0; 400], DVec3::ZERO, DVec3::new(20.0, 20.0, 0.0));
        let (qlo, qhi) = (DVec3::new(3.5, 7.2, -0.4), DVec3::new(6.1, 9.0, 0.4));
        let mut seen = Vec::new();
        grid.visit(
            (qlo, qhi),
            &mut Vec::new(),
            |_, _| false,
            |t, _| seen.push(t),
        );
        seen.sort_unstable();
        seen.dedup();
        let mut want: Vec<usize> = (0..400)
            .filter(|&t| {
                let (l, h) = boxes[t];
                // More than a shared face (the box [9, 10] in y only
                // touches the query's face y = 9).
                !(l.cmpge(qhi).any() || h.cmple(qlo).any())
            })
            .collect();
        seen.sort_unstable();
        want.sort_unstable();
        assert_eq!(seen, want);
        // x cells 3 to 6, y cells 7 and 8.
        assert_eq!(want.len(), 4 * 2);
    }
}
