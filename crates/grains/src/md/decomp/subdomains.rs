//! Which rank owns which part of the box in a decomposed MD run: a grid of
//! px × py (× pz) axis-aligned boxes, one per rank, cut by grain count.
//!
//! The cuts are staggered: the first cut axis is split into slabs by
//! count, then each slab separately along the next cut axis by count
//! within it, and so on, so a pile in one corner still spreads evenly. All
//! ranks know all boxes. A grain is a ghost on every other rank whose box,
//! widened by `reach` (largest diameter + skin) along the cut axes, holds
//! one of its periodic images (shift −L, 0, +L along each periodic cut
//! axis); the neighbours therefore need not be regular. Every box is at
//! least two reaches wide along each cut axis, so a rank never sees an
//! image of its own grains and never holds a grain twice with one shift.
//! An axis that is not cut keeps its own periodicity in every rank's box.
//! On an open axis the end boxes reach to infinity: grains beyond the box
//! ends still have an owner.

use super::balance::{cuts_by_count, keep_min_width};
use crate::comm::{Comm, SingleProcess};
use crate::dim::Dim;
use crate::domain::Domain;
use crate::error::{Error, Result};
use crate::settings::parallel::GridSpec;

const AXES: [&str; 3] = ["x", "y", "z"];

/// The boxes of all ranks.
#[derive(Clone, Debug)]
pub struct Subdomains {
    /// Ranks along each axis (1 on an uncut axis and beyond the dimension).
    pub grid: [usize; 3],
    /// The cut axes, in the order of the staggered cuts.
    order: Vec<usize>,
    /// `cuts[l][g]`: the bounds (ends included) along `order[l]` of the
    /// boxes in group g of level l (g numbers the boxes of levels < l).
    cuts: Vec<Vec<Vec<f64>>>,
    lo: [f64; 3],
    hi: [f64; 3],
    periodic: [bool; 3],
    /// Ghost shell width: largest diameter + skin.
    pub reach: f64,
}

/// A rank's box: lower and upper bound along each axis (±∞ at the open
/// ends of a cut axis, the box's ends on an uncut one).
pub type Cell = ([f64; 3], [f64; 3]);

impl Subdomains {
    /// Chooses the grid for `ranks` (see [`choose_grid`]) and cuts it by
    /// count of the grains at `pos`, which every rank holds at the start.
    pub fn by_count<D: Dim>(
        domain: &Domain<D>,
        pos: &[D::V],
        ranks: usize,
        reach: f64,
        spec: &GridSpec,
    ) -> Result<Self> {
        let mut lo = [0.0; 3];
        let mut hi = [0.0; 3];
        let mut periodic = [false; 3];
        for a in 0..D::D {
            lo[a] = D::get(domain.lo, a);
            hi[a] = D::get(domain.hi, a);
            periodic[a] = domain.is_periodic(a);
        }
        let lengths: Vec<f64> = (0..D::D).map(|a| hi[a] - lo[a]).collect();
        let grid = choose_grid(&lengths, &periodic[..D::D], ranks, reach, spec)?;
        let mut sub = Self {
            grid,
            order: (0..3).filter(|&a| grid[a] > 1).collect(),
            cuts: Vec::new(),
            lo,
            hi,
            periodic,
            reach,
        };
        let xyz: Vec<[f64; 3]> = pos.iter().map(|&p| D::to_xyz(domain.wrap(p))).collect();
        sub.cut_by_count(&SingleProcess, || xyz.iter().copied());
        Ok(sub)
    }

    /// Cuts all levels again so that every box holds about the same number
    /// of grains; each rank passes its own grains' (wrapped) positions.
    /// Collective: every rank calls it.
    pub fn cut_by_count<I: Iterator<Item = [f64; 3]>>(
        &mut self,
        comm: &dyn Comm,
        grains: impl Fn() -> I,
    ) {
        self.cuts.clear();
        let mut groups = 1;
        for l in 0..self.order.len() {
            let a = self.order[l];
            let parts = self.grid[a];
            let range = (self.lo[a], self.hi[a]);
            let inner = cuts_by_count(comm, groups, parts, range, || {
                grains().map(|x| (self.group(l, &x), x[a]))
            });
            let level = inner
                .into_iter()
                .map(|mut c| {
                    keep_min_width(&mut c, range, 2.0 * self.reach);
                    std::iter::once(range.0).chain(c).chain([range.1]).collect()
                })
                .collect();
            self.cuts.push(level);
            groups *= parts;
        }
    }

    /// The group of a position at level `l`: its box index over levels < l.
    fn group(&self, l: usize, x: &[f64; 3]) -> usize {
        let mut g = 0;
        for (k, level) in self.cuts.iter().enumerate().take(l) {
            let b = &level[g];
            let inner = &b[1..b.len() - 1];
            g = g * self.grid[self.order[k]] + inner.partition_point(|&c| c <= x[self.order[k]]);
        }
        g
    }

    pub fn ranks(&self) -> usize {
        self.grid.iter().product()
    }

    /// The rank that owns a grain at `x` (wrapped on the periodic axes).
    pub fn owner(&self, x: &[f64; 3]) -> usize {
        self.group(self.order.len(), x)
    }

    /// Rank `r`'s box.
    pub fn cell(&self, r: usize) -> Cell {
        let (mut lo, mut hi) = (self.lo, self.hi);
        let mut g = 0;
        let mut rest = r;
        let mut stride: usize = self.order.iter().map(|&a| self.grid[a]).product();
        for (l, &a) in self.order.iter().enumerate() {
            stride /= self.grid[a];
            let k = rest / stride;
            rest %= stride;
            let b = &self.cuts[l][g];
            lo[a] = b[k];
            hi[a] = b[k + 1];
            if !self.periodic[a] {
                if k == 0 {
                    lo[a] = f64::NEG_INFINITY;
                }
                if k + 1 == self.grid[a] {
                    hi[a] = f64::INFINITY;
                }
            }
            g = g * self.grid[a] + k;
        }
        (lo, hi)
    }

    /// The periodic shifts (in box lengths) a ghost may carry: −1, 0, +1
    /// along each periodic cut axis, 0 elsewhere.
    fn shifts(&self) -> Vec<[i8; 3]> {
        let mut out = vec![[0i8; 3]];
        for &a in &self.order {
            if self.periodic[a] {
                out = out
                    .into_iter()
                    .flat_map(|s| {
                        [-1i8, 0, 1].map(|k| {
                            let mut t = s;
                            t[a] = k;
                            t
                        })
                    })
                    .collect();
            }
        }
        out
    }

    /// The shift as a displacement.
    pub fn displacement(&self, s: [i8; 3]) -> [f64; 3] {
        let mut d = [0.0; 3];
        for a in 0..3 {
            d[a] = s[a] as f64 * (self.hi[a] - self.lo[a]);
        }
        d
    }

    /// The (other rank, shift) pairs that can receive ghosts of rank `r`:
    /// those whose widened box meets r's box moved by the shift.
    pub fn ghost_targets(&self, r: usize) -> Vec<(usize, [i8; 3], Cell)> {
        let mine = self.cell(r);
        let mut out = Vec::new();
        let shifts = self.shifts();
        for s in (0..self.ranks()).filter(|&s| s != r) {
            let (lo, hi) = self.widened(s);
            for &shift in &shifts {
                let d = self.displacement(shift);
                let meets = self
                    .order
                    .iter()
                    .all(|&a| mine.0[a] + d[a] < hi[a] && mine.1[a] + d[a] > lo[a]);
                if meets {
                    out.push((s, shift, (lo, hi)));
                }
            }
        }
        out
    }

    /// Rank `s`'s box widened by a reach along the cut axes.
    fn widened(&self, s: usize) -> Cell {
        let (mut lo, mut hi) = self.cell(s);
        for &a in &self.order {
            lo[a] -= self.reach;
            hi[a] += self.reach;
        }
        (lo, hi)
    }

    /// Whether `x` lies in `cell` (half open) along every cut axis (the
    /// others are not split).
    pub fn contains(&self, cell: &Cell, x: &[f64; 3]) -> bool {
        self.order
            .iter()
            .all(|&a| x[a] >= cell.0[a] && x[a] < cell.1[a])
    }

    /// Whether `x` is a reach or more inside rank `r`'s box `cell` along
    /// every cut axis (then it is nobody's ghost).
    pub fn deep_inside(&self, cell: &Cell, x: &[f64; 3]) -> bool {
        self.order
            .iter()
            .all(|&a| x[a] >= cell.0[a] + self.reach && x[a] < cell.1[a] - self.reach)
    }

    /// The box rank `r` builds its neighbour list in: its box widened by a
    /// reach along each cut axis, not periodic there (the ghosts are the
    /// images); the box's own ends at the open ends; uncut axes as they are.
    pub fn local_domain<D: Dim>(&self, global: &Domain<D>, r: usize) -> Domain<D> {
        let mut d = global.clone();
        let (lo, hi) = self.widened(r);
        for &a in &self.order {
            if lo[a].is_finite() {
                D::set(&mut d.lo, a, lo[a]);
            }
            if hi[a].is_finite() {
                D::set(&mut d.hi, a, hi[a]);
            }
            d.periodic[a] = false;
        }
        d
    }

    /// The ranks along each of the first `dims` axes.
    pub fn describe(&self, dims: usize) -> Vec<usize> {
        self.grid[..dims].to_vec()
    }
}

/// The grid of `ranks` boxes for a box of `lengths` (one per axis):
/// `"slabs"` cuts the longest axis (the first of equal ones) only; a fixed
/// `[px, py(, pz)]` is taken as given; `"auto"` takes the factorisation
/// with the smallest cut area (a periodic axis cut p times has p cut
/// planes, an open one p − 1), fewer cut axes on a tie. Every box must be
/// at least two reaches wide along each cut axis; otherwise a grid with
/// fewer cuts along that axis is taken, and when none fits, an error asks
/// for fewer ranks.
pub fn choose_grid(
    lengths: &[f64],
    periodic: &[bool],
    ranks: usize,
    reach: f64,
    spec: &GridSpec,
) -> Result<[usize; 3]> {
    let dims = lengths.len();
    let fits =
        |g: &[usize; 3]| (0..dims).all(|a| g[a] == 1 || lengths[a] >= g[a] as f64 * 2.0 * reach);
    let too_thin = |what: String| {
        Error::input(format!(
            "{ranks} MPI ranks as {what}: a box along a cut axis would be narrower than \
             2 × (largest diameter + neighbour skin) = {:.4} (box {}): run on fewer ranks",
            2.0 * reach,
            lengths
                .iter()
                .zip(AXES)
                .map(|(l, n)| format!("{n} {l}"))
                .collect::<Vec<_>>()
                .join(", ")
        ))
    };
    match spec {
        GridSpec::Slabs => {
            let axis = (0..dims)
                .max_by(|&a, &b| lengths[a].total_cmp(&lengths[b]).then(b.cmp(&a)))
                .unwrap_or(0);
            let mut g = [1; 3];
            g[axis] = ranks;
            if !fits(&g) {
                return Err(too_thin(format!("slabs along {}", AXES[axis])));
            }
            Ok(g)
        }
        GridSpec::Fixed(given) => {
            let mut g = [1; 3];
            g[..given.len().min(3)].copy_from_slice(&given[..given.len().min(3)]);
            if given.len() != dims || given.iter().product::<usize>() != ranks {
                return Err(Error::input(format!(
                    "parallel.grid = {given:?}: needs {dims} numbers whose product is the rank \
                     count {ranks}"
                )));
            }
            if !fits(&g) {
                return Err(too_thin(format!("the grid {given:?}")));
            }
            Ok(g)
        }
        GridSpec::Auto => {
            let volume: f64 = lengths.iter().product();
            let cost = |g: &[usize; 3]| -> (f64, usize) {
                let mut area = 0.0;
                let mut cut = 0;
                for a in 0..dims {
                    if g[a] > 1 {
                        let planes = if periodic[a] { g[a] } else { g[a] - 1 };
                        area += planes as f64 * volume / lengths[a];
                        cut += 1;
                    }
                }
                (area, cut)
            };
            let mut best: Option<([usize; 3], (f64, usize))> = None;
            for px in (1..=ranks).rev().filter(|p| ranks.is_multiple_of(*p)) {
                let rest = ranks / px;
                for py in (1..=rest).rev().filter(|p| rest.is_multiple_of(*p)) {
                    let pz = rest / py;
                    let g = [px, py, pz];
                    if (dims == 2 && pz != 1) || !fits(&g) {
                        continue;
                    }
                    let c = cost(&g);
                    let better = best.is_none_or(|(_, b)| {
                        c.0 < b.0 * (1.0 - 1e-12) || (c.0 <= b.0 * (1.0 + 1e-12) && c.1 < b.1)
                    });
                    if better {
                        best = Some((g, c));
                    }
                }
            }
            best.map(|(g, _)| g)
                .ok_or_else(|| too_thin("any grid".into()))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::D2;
    use glam::DVec2;

    #[test]
    fn a_long_box_gives_slabs_and_a_square_closed_one_a_square_grid() {
        let auto = GridSpec::Auto;
        let g = choose_grid(&[40.0, 10.0], &[true, true], 4, 1.2, &auto).unwrap();
        assert_eq!(g, [4, 1, 1]);
        // Closed square: 2×2 cuts 2 lengths, 4×1 three.
        let g = choose_grid(&[20.0, 20.0], &[false, false], 4, 1.2, &auto).unwrap();
        assert_eq!(g, [2, 2, 1]);
        // Periodic square: both cut 4 lengths; fewer cut axes win.
        let g = choose_grid(&[20.0, 20.0], &[true, true], 4, 1.2, &auto).unwrap();
        assert_eq!(g, [4, 1, 1]);
        // 3D bed, 8 ranks: never cut the short open z.
        let g = choose_grid(&[30.0, 30.0, 5.0], &[true, true, false], 8, 1.2, &auto).unwrap();
        assert_eq!(g, [4, 2, 1]);
        // Too thin for 12 slabs along x: 6 × 2 instead.
        let g = choose_grid(&[24.0, 12.0], &[true, true], 12, 1.3, &auto).unwrap();
        assert_eq!(g, [6, 2, 1]);
    }

    #[test]
    fn forced_grids_are_checked() {
        let s = GridSpec::Slabs;
        assert_eq!(
            choose_grid(&[20.0, 20.0], &[false, false], 4, 1.2, &s).unwrap(),
            [4, 1, 1]
        );
        let f = GridSpec::Fixed(vec![1, 4]);
        assert_eq!(
            choose_grid(&[20.0, 20.0], &[false, false], 4, 1.2, &f).unwrap(),
            [1, 4, 1]
        );
        let e = choose_grid(&[20.0, 20.0], &[false, false], 6, 1.2, &f).unwrap_err();
        assert!(e.to_string().contains("product"), "{e}");
        let e = choose_grid(&[24.0, 12.0], &[true, true], 12, 1.3, &s).unwrap_err();
        assert!(e.to_string().contains("run on fewer ranks"), "{e}");
        let e = choose_grid(&[24.0, 12.0], &[true, true], 37, 1.3, &GridSpec::Auto);
        assert!(e.unwrap_err().to_string().contains("run on fewer ranks"));
    }

    #[test]
    fn staggered_cuts_follow_the_count_in_each_slab() {
        // A closed 20 × 20 box, 2 × 2 ranks; grains: 100 spread over the
        // left half, 100 crowded in the lower right corner.
        let d = Domain::<D2>::new(DVec2::ZERO, DVec2::new(20.0, 20.0), [false, false, false]);
        let mut pos: Vec<DVec2> = (0..100)
            .map(|k| DVec2::new(0.5 + 0.09 * k as f64, 0.5 + 0.19 * k as f64))
            .collect();
        pos.extend((0..100).map(|k| DVec2::new(12.0 + 0.05 * k as f64, 1.0 + 0.04 * k as f64)));
        let s = Subdomains::by_count(&d, &pos, 4, 1.2, &GridSpec::Auto).unwrap();
        assert_eq!(s.grid, [2, 2, 1]);
        let mut counts = [0; 4];
        for p in &pos {
            counts[s.owner(&[p.x, p.y, 0.0])] += 1;
        }
        assert_eq!(counts, [50; 4]);
        // The right slab's y cut sits inside the pile, the left's mid-way.
        let (c0, c2) = (s.cell(0), s.cell(2));
        assert!(c2.1[1] > 2.9 && c2.1[1] < 3.1, "{c2:?}");
        assert!(c0.1[1] > 9.0 && c0.1[1] < 10.5, "{c0:?}");
        // Open ends reach to infinity; every owner's box holds the grain.
        assert_eq!(c0.0, [f64::NEG_INFINITY, f64::NEG_INFINITY, 0.0]);
        for p in &pos {
            let x = [p.x, p.y, 0.0];
            assert!(s.contains(&s.cell(s.owner(&x)), &x));
        }
    }

    #[test]
    fn periodic_neighbours_include_the_wrapped_ones() {
        let d = Domain::<D2>::new(DVec2::ZERO, DVec2::new(20.0, 20.0), [true, true, false]);
        let pos: Vec<DVec2> = (0..400)
            .map(|k| DVec2::new((k % 20) as f64 + 0.5, (k / 20) as f64 + 0.5))
            .collect();
        let s = Subdomains::by_count(&d, &pos, 4, 1.2, &GridSpec::Fixed(vec![2, 2])).unwrap();
        // Rank 0 (lower left) sees rank 3 (upper right) across the corner
        // with both shifts and directly; never itself.
        let t = s.ghost_targets(0);
        assert!(t.iter().all(|&(r, _, _)| r != 0));
        let to3: Vec<[i8; 3]> = t.iter().filter(|e| e.0 == 3).map(|e| e.1).collect();
        assert!(
            to3.contains(&[0, 0, 0]) && to3.contains(&[1, 1, 0]),
            "{to3:?}"
        );
        assert_eq!(to3.len(), 4);
    }
}
