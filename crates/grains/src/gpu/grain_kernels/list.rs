//! The list build's part of one GPU thread.
//!
//! A grain wrapped into the periodic box and binned into its cell, its
//! partners found in the neighbouring cells, a row of the full list put in
//! order, and the cells' Morton order.

use super::{dot, is_zero, neg, sub, FullList, Soa3, V3};

/// The periodic box, per axis: lower bound, length (0 on an axis that is
/// not periodic).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Box3 {
    pub lo: V3,
    pub length: V3,
    pub periodic: [bool; 3],
}

/// `Domain::wrap`: a coordinate outside a periodic axis's [lo, lo + L)
/// moved back by whole lengths.
#[inline(always)]
pub fn wrap(b: &Box3, mut p: V3) -> V3 {
    for (a, x) in p.iter_mut().enumerate() {
        if !b.periodic[a] {
            continue;
        }
        let (lo, l) = (b.lo[a], b.length[a]);
        if *x < lo || *x >= lo + l {
            *x -= l * ((*x - lo) / l).floor();
            if *x >= lo + l {
                *x -= l;
            }
        }
    }
    p
}

/// A cell grid (`neighbors::cell_grid::GridShape`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    pub dims: [usize; 3],
    pub lo: V3,
    pub inv_width: V3,
}

impl Grid {
    #[inline(always)]
    pub fn coord(&self, a: usize, x: f64) -> usize {
        let f = (x - self.lo[a]) * self.inv_width[a];
        (f.max(0.0) as usize).min(self.dims[a] - 1)
    }

    #[inline(always)]
    pub fn cell_of(&self, p: V3) -> usize {
        self.coord(0, p[0])
            + self.dims[0] * (self.coord(1, p[1]) + self.dims[1] * self.coord(2, p[2]))
    }

    pub fn ncells(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }
}

/// Grains binned into cells: cell c holds `members[start[c]..start[c + 1]]`,
/// ascending.
#[derive(Clone, Debug, Default)]
pub struct Bins {
    pub start: Vec<u32>,
    pub members: Vec<u32>,
    pub cell: Vec<u32>,
}

/// The cells of one axis a grain's stencil visits, with their image
/// digits (−1, 0, +1), as the CPU list build visits them.
#[derive(Clone, Copy, Debug)]
pub struct AxisCells {
    pub cells: [(usize, i32); 3],
    pub len: usize,
    /// Periodic with fewer than 3 cells: the image is the minimum one.
    pub min_image: bool,
}

#[inline(always)]
pub fn axis_cells(n: usize, periodic: bool, c: usize) -> AxisCells {
    let mut st = AxisCells {
        cells: [(0, 0); 3],
        len: 0,
        min_image: false,
    };
    if periodic && n < 3 {
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
        let mut k = c.saturating_sub(1);
        while k <= (c + 1).min(n - 1) {
            st.cells[st.len] = (k, 0);
            st.len += 1;
            k += 1;
        }
    }
    st
}

/// What the list kernels read.
pub struct ListArgs<'a> {
    pub pos: &'a Soa3,
    pub radius: &'a [f64],
    pub frozen: &'a [u8],
    /// CPU-order index of each grain (rows are ordered by it).
    pub rank: &'a [u32],
    pub bins: &'a Bins,
    pub grid: Grid,
    pub periodic: [bool; 3],
    pub length: V3,
    pub shifts: &'a [V3; 27],
    pub skin: f64,
    /// Grains per block of the CPU engine's pair reduction.
    pub block: usize,
}

/// The list kernel for grain `g`: visits its stencil (z, y, x; members
/// by ascending rank) and calls `found(partner, image code of g's side)` for every
/// partner within r_g + r_p + skin. Run twice: to count, then to fill.
#[inline(always)]
pub fn visit_partners(a: &ListArgs, g: usize, mut found: impl FnMut(usize, usize)) {
    let grid = &a.grid;
    let pg = a.pos.get(g);
    let rg = a.radius[g];
    let fg = a.frozen[g] != 0;
    let cell = a.bins.cell[g] as usize;
    let c = [
        cell % grid.dims[0],
        cell / grid.dims[0] % grid.dims[1],
        cell / grid.dims[0] / grid.dims[1],
    ];
    let st = [
        axis_cells(grid.dims[0], a.periodic[0], c[0]),
        axis_cells(grid.dims[1], a.periodic[1], c[1]),
        axis_cells(grid.dims[2], a.periodic[2], c[2]),
    ];
    let any_min_image = st[0].min_image || st[1].min_image || st[2].min_image;
    const POW3: [i32; 3] = [1, 3, 9];
    for &(z, sz) in &st[2].cells[..st[2].len] {
        for &(y, sy) in &st[1].cells[..st[1].len] {
            for &(x, sx) in &st[0].cells[..st[0].len] {
                let base = 13 + sx + 3 * sy + 9 * sz;
                let cl = x + grid.dims[0] * (y + grid.dims[1] * z);
                let members = a.bins.start[cl] as usize..a.bins.start[cl + 1] as usize;
                for &p in &a.bins.members[members] {
                    let p = p as usize;
                    if p == g || (fg && a.frozen[p] != 0) {
                        continue;
                    }
                    let pp = a.pos.get(p);
                    let mut code = base;
                    if any_min_image {
                        for ax in 0..3 {
                            if st[ax].min_image {
                                let dx = pg[ax] - pp[ax];
                                code += (dx / a.length[ax]).round() as i32 * POW3[ax];
                            }
                        }
                    }
                    let d = sub(sub(pg, pp), a.shifts[code as usize]);
                    let cut = rg + a.radius[p] + a.skin;
                    if dot(d, d) < cut * cut {
                        found(p, code as usize);
                    }
                }
            }
        }
    }
}

/// Where an entry of the row of the grain of rank g goes (p: the partner's
/// rank): lower partners of g's own block first (ascending), then higher
/// partners (in stencil order), then lower partners of earlier blocks
/// (ascending): the order in which the CPU engine's block reduction sums
/// g's contacts.
#[inline(always)]
pub fn row_key(g: usize, p: usize, block: usize) -> (u32, u32) {
    if p > g {
        (1, 0)
    } else if p >= g / block * block {
        (0, p as u32)
    } else {
        (2, p as u32)
    }
}

/// The fill kernel's last part for grain `g`: its row, written in stencil
/// order, put in the order of [`row_key`] (on ranks) by a stable insertion
/// sort in place (rows hold about a dozen entries).
pub fn order_row(list: &mut FullList, g: usize, block: usize, rank: &[u32]) {
    let r = list.row(g);
    let key_of = |p: u32| row_key(rank[g] as usize, rank[p as usize] as usize, block);
    for k in r.start + 1..r.end {
        let (p, code) = (list.partner[k], list.image[k]);
        let key = key_of(p);
        let mut m = k;
        while m > r.start && key_of(list.partner[m - 1]) > key {
            list.partner[m] = list.partner[m - 1];
            list.image[m] = list.image[m - 1];
            m -= 1;
        }
        list.partner[m] = p;
        list.image[m] = code;
    }
}

/// The image code of the other side of a pair (3D: each digit d becomes
/// 2 − d).
#[inline(always)]
pub fn mirrored(code: usize) -> usize {
    26 - code
}

/// The remap kernel for grain `g` after a rebuild: each new entry's spring
/// from the old list, found through `old_of` (the old index of each grain
/// after a re-sort; `None`: the grains kept their places), negated when the
/// pair's lower rank changed sides (`rank` now, `old_rank` by old index);
/// zero when the pair is new or its spring was not stretched.
pub fn remap_row(
    g: usize,
    (new, old): (&FullList, &FullList),
    old_of: Option<&[u32]>,
    (rank, old_rank): (&[u32], &[u32]),
    (old_springs, springs): (&Soa3, &mut Soa3),
) {
    let at = |k: usize| old_of.map_or(k, |o| o[k] as usize);
    let og = at(g);
    for e in new.row(g) {
        let p = new.partner[e] as usize;
        let op = at(p);
        let mut s = [0.0; 3];
        for k in old.row(og) {
            if old.partner[k] as usize == op {
                let o = old_springs.get(k);
                if !is_zero(o) {
                    s = if (rank[g] < rank[p]) == (old_rank[og] < old_rank[op]) {
                        o
                    } else {
                        neg(o)
                    };
                }
                break;
            }
        }
        springs.set(e, s);
    }
}

/// Entries a list buffer is given for `need` entries: a quarter more, so
/// that the list can grow a while before the stretch halts to reallocate.
pub fn list_capacity(need: usize) -> usize {
    need + need / 4 + 1024
}

/// Each cell's place in Morton order (bits of the x, y, z cell coordinates
/// interleaved, x lowest): cells near in space get near places, so grains
/// stored cell by cell in this order lie near in memory along all three
/// axes, not only along x.
pub fn morton_places(grid: &Grid) -> Vec<u32> {
    fn spread(mut v: u64) -> u64 {
        // 21 bits, each moved to every third place.
        v &= 0x1f_ffff;
        v = (v | v << 32) & 0x1f00000000ffff;
        v = (v | v << 16) & 0x1f0000ff0000ff;
        v = (v | v << 8) & 0x100f00f00f00f00f;
        v = (v | v << 4) & 0x10c30c30c30c30c3;
        (v | v << 2) & 0x1249249249249249
    }
    let [nx, ny, _] = grid.dims;
    let mut cells: Vec<(u64, u32)> = (0..grid.ncells())
        .map(|c| {
            let (x, y, z) = (c % nx, c / nx % ny, c / nx / ny);
            let code = spread(x as u64) | spread(y as u64) << 1 | spread(z as u64) << 2;
            (code, c as u32)
        })
        .collect();
    cells.sort_unstable();
    let mut place = vec![0u32; cells.len()];
    for (k, &(_, c)) in cells.iter().enumerate() {
        place[c as usize] = k as u32;
    }
    place
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a 4 × 4 × 4 grid every Morton code below 64 is a cell, so a
    /// cell's place is its code: x bits at 0 and 3, y at 1 and 4, z at 2
    /// and 5. On an uneven grid the places are a permutation.
    #[test]
    fn morton_places_interleave_the_cell_bits() {
        let grid = |dims| Grid {
            dims,
            lo: [0.0; 3],
            inv_width: [1.0; 3],
        };
        let places = morton_places(&grid([4, 4, 4]));
        let bit = |v: usize, b: usize| (v >> b) & 1;
        for (c, &place) in places.iter().enumerate() {
            let (x, y, z) = (c % 4, c / 4 % 4, c / 16);
            let code = (0..2)
                .map(|b| (bit(x, b) | bit(y, b) << 1 | bit(z, b) << 2) << (3 * b))
                .sum::<usize>();
            assert_eq!(place as usize, code, "cell ({x}, {y}, {z})");
        }
        let mut uneven = morton_places(&grid([5, 3, 7]));
        uneven.sort_unstable();
        assert_eq!(uneven, (0..105).collect::<Vec<u32>>());
    }
}
