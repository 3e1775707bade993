//! The pair search of a neighbour-list build.
//!
//! The neighbouring cells of a grain's cell on each axis (with their
//! periodic shifts), and the scan of a range of grains against them.
//! In a sheared box the cells across the gradient boundary are searched
//! around the grain's place less the images' offset along x.

use super::POW3;
use crate::dim::Dim;
use crate::neighbors::cell_grid::CellGrid;
use std::ops::Range;

/// Neighbouring cells along one axis: (cell coordinate, shift in box lengths).
#[derive(Clone, Copy)]
struct AxisStencil {
    cells: [(usize, i32); 3],
    len: usize,
    /// The axis is periodic with fewer than 3 cells: every cell is visited
    /// once and the image is chosen per pair (the minimum image, unique
    /// within reach because the length is at least twice the reach).
    min_image: bool,
}

impl AxisStencil {
    fn new(n: usize, periodic: bool, c: usize) -> Self {
        let mut st = Self {
            cells: [(0, 0); 3],
            len: 0,
            min_image: false,
        };
        if periodic && n < 3 {
            // Offsets −1 and +1 would reach the same cell twice.
            for k in 0..n {
                st.cells[k] = (k, 0);
            }
            st.len = n;
            st.min_image = true;
        } else if periodic {
            let below = if c == 0 { (n - 1, -1) } else { (c - 1, 0) };
            let above = if c + 1 == n { (0, 1) } else { (c + 1, 0) };
            st.cells = [below, (c, 0), above];
            st.len = 3;
        } else {
            for k in c.saturating_sub(1)..=(c + 1).min(n - 1) {
                st.cells[st.len] = (k, 0);
                st.len += 1;
            }
        }
        st
    }

    /// The cells around unwrapped cell `k` of a periodic axis of `n ≥ 3`
    /// cells, with their shifts (−1, 0 or +1 box lengths for `k` within
    /// half a box of the box).
    fn around(n: usize, k: i64) -> Self {
        let n = n as i64;
        let cell = |k: i64| (k.rem_euclid(n) as usize, k.div_euclid(n) as i32);
        Self {
            cells: [cell(k - 1), cell(k), cell(k + 1)],
            len: 3,
            min_image: false,
        }
    }

    fn cells(&self) -> &[(usize, i32)] {
        &self.cells[..self.len]
    }
}

/// Read-only inputs of the pair search, shared by the parallel work units.
pub(super) struct Scan<'a, D: Dim> {
    pub(super) pos: &'a [D::V],
    pub(super) radius: &'a [f64],
    pub(super) frozen: &'a [bool],
    pub(super) grid: &'a CellGrid,
    pub(super) periodic: [bool; 3],
    pub(super) length: [f64; 3],
    pub(super) shifts: &'a [D::V; 27],
    pub(super) skin: f64,
    /// Lees–Edwards images sliding along x (axis 0).
    pub(super) shear: Option<ScanShear>,
}

/// What the search needs of a sheared box: the gradient axis and the
/// images' offset along x at the build.
#[derive(Clone, Copy)]
pub(super) struct ScanShear {
    pub gradient: usize,
    pub offset: f64,
}

impl<D: Dim> Scan<'_, D> {
    /// Appends the pairs (i, j > i) for every i in `range`, in order of i.
    pub(super) fn run(&self, range: Range<usize>, pairs: &mut Vec<[u32; 2]>, image: &mut Vec<u8>) {
        let shape = &self.grid.shape;
        let zero_code = (POW3[D::D - 1] * 3 - 1) / 2;
        for i in range {
            let pi = self.pos[i];
            let ri = self.radius[i];
            let fi = self.frozen[i];
            let c = shape.unlinear(self.grid.cell[i] as usize);
            let st: [AxisStencil; 3] =
                std::array::from_fn(|a| AxisStencil::new(shape.dims[a], self.periodic[a], c[a]));
            let any_min_image = st.iter().any(|s| s.min_image);
            // Across the gradient boundary (digit g = ±1) the partner's
            // image sits Δ·g further along x: search around x_i − Δ·g.
            let slid: Option<[AxisStencil; 2]> = self.shear.map(|sh| {
                std::array::from_fn(|k| {
                    let g = 2.0 * k as f64 - 1.0;
                    if st[0].min_image {
                        st[0]
                    } else {
                        let x = D::get(pi, 0) - g * sh.offset;
                        let f = ((x - shape.lo[0]) * shape.inv_width[0]).floor();
                        AxisStencil::around(shape.dims[0], f as i64)
                    }
                })
            });
            for &(z, sz) in st[2].cells() {
                for &(y, sy) in st[1].cells() {
                    let g = match self.shear {
                        Some(sh) if sh.gradient == 1 => sy,
                        Some(_) => sz,
                        None => 0,
                    };
                    let xs = match &slid {
                        Some(slid) if g != 0 => &slid[((g + 1) / 2) as usize],
                        _ => &st[0],
                    };
                    for &(x, sx) in xs.cells() {
                        let base = zero_code + sx + 3 * sy + 9 * sz;
                        let members = self.grid.cell_members(shape.linear([x, y, z]));
                        // Members are in ascending order: skip to those after i.
                        let from = members.partition_point(|&j| j as usize <= i);
                        for &j in &members[from..] {
                            let j = j as usize;
                            if fi && self.frozen[j] {
                                continue;
                            }
                            let pj = self.pos[j];
                            let mut code = base;
                            if any_min_image {
                                for (a, s) in st.iter().enumerate().take(D::D) {
                                    if s.min_image {
                                        let mut dx = D::get(pi, a) - D::get(pj, a);
                                        if a == 0 && g != 0 {
                                            // The partner's image slid by Δ·g.
                                            dx -= g as f64 * self.shear.map_or(0.0, |s| s.offset);
                                        }
                                        code += (dx / self.length[a]).round() as i32 * POW3[a];
                                    }
                                }
                            }
                            let d = (pi - pj) - self.shifts[code as usize];
                            let cut = ri + self.radius[j] + self.skin;
                            if D::norm2(d) < cut * cut {
                                pairs.push([i as u32, j as u32]);
                                image.push(code as u8);
                            }
                        }
                    }
                }
            }
        }
    }
}
