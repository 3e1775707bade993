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

/// The ring's least length (a power of two): below it a store is moved
/// through a ring of its own size, with no side list.
const RING_MIN: usize = 1 << 12;
/// At most one record in this many may wait aside (in the ring or the side
/// list); a store that needs more is in no particular order, and the
/// permutation's cycles are followed instead.
const ASIDE_SHARE: usize = 2;
/// How many places ahead of the one being written its record is asked of
/// the cache: the reads are scattered over the span that records move, far
/// more than the caches hold in 3D, and one read is shorter than a memory
/// access.
const PREFETCH_AHEAD: usize = 16;

/// Scratch of [`gather_in_place`]: the records it must keep aside because
/// their place is overwritten before they reach their new one.
#[derive(Clone, Debug, Default)]
pub struct Aside<T> {
    /// Record s waits in slot s mod the ring's length while it moves
    /// forward by less than that length.
    ring: Vec<T>,
    /// Those that move farther (across the periodic seam, say), in order of
    /// their new place.
    far: Vec<T>,
    /// Old place of each far mover and its rank in `far`, by increasing old
    /// place.
    far_from: Vec<(u32, u32)>,
}

/// The ring for the moves in `order` (new place k holds old place
/// `order[k]`): the power of two that keeps the fewest records aside, a
/// ring slot each and about twice that for a far mover (its record, its
/// entry in the side list and its share of that list's sort). `None` when
/// more than one record in [`ASIDE_SHARE`] would wait.
fn ring_len(order: &[u32]) -> Option<usize> {
    let n = order.len();
    let top = n.next_power_of_two().max(1);
    if top <= RING_MIN {
        return Some(top);
    }
    // moves[b]: records moving forward by 2^b up to 2^(b+1) − 1 places.
    let mut moves = [0usize; usize::BITS as usize];
    for (k, &s) in order.iter().enumerate() {
        if k > s as usize {
            moves[(k - s as usize).ilog2() as usize] += 1;
        }
    }
    let mut farther: usize = moves[RING_MIN.ilog2() as usize..].iter().sum();
    let mut best = (usize::MAX, RING_MIN);
    for b in RING_MIN.ilog2()..=top.ilog2() {
        let cost = (1usize << b) + 2 * farther;
        if cost < best.0 {
            best = (cost, 1 << b);
        }
        farther -= moves[b as usize];
    }
    (best.0 <= n / ASIDE_SHARE).then_some(best.1)
}

/// Reorders `p` in place so that the new `p[k]` is the old `p[order[k]]`;
/// leaves `order[k] == k`.
///
/// A record of a store kept in cell order moves only a few rows of cells
/// between re-sorts, so the records are written in increasing place, each
/// read from where it is: ahead of the place being written it is still
/// there; behind, it was kept aside when its place was overwritten. Every
/// record passes through a ring, sized from the moves of this permutation
/// (a few layers of cells: [`ring_len`]); the few that move farther wait in
/// a side list in the order they are placed. Writes stream through memory
/// and the scattered reads are asked of the cache
/// [`PREFETCH_AHEAD`] places early. When too many records would wait (a
/// store in no particular order), the permutation's cycles are followed
/// instead, which needs no scratch but waits on memory at every hop.
pub fn gather_in_place<T: Copy + Default>(p: &mut [T], order: &mut [u32], aside: &mut Aside<T>) {
    let n = p.len();
    debug_assert_eq!(order.len(), n);
    let Some(ring) = ring_len(order) else {
        return follow_cycles(p, order);
    };
    let mask = ring - 1;
    // The far movers (record s goes to k ≥ s + ring), ranked by k.
    aside.far_from.clear();
    for (k, &s) in order.iter().enumerate() {
        if k >= s as usize + ring {
            let rank = aside.far_from.len() as u32;
            aside.far_from.push((s, rank));
        }
    }
    aside.far_from.sort_unstable_by_key(|e| e.0);
    aside.far.clear();
    aside.far.resize(aside.far_from.len(), T::default());
    aside.ring.clear();
    aside.ring.resize(ring, T::default());
    let mut next_from = 0;
    let mut next_far = 0;
    for k in 0..n {
        if let Some(&s) = order.get(k + PREFETCH_AHEAD) {
            let s = s as usize;
            // Still in place, or in the ring by the time it is read.
            if s >= k {
                prefetch(p.as_ptr().wrapping_add(s));
            } else if k + PREFETCH_AHEAD - s < ring {
                prefetch(aside.ring.as_ptr().wrapping_add(s & mask));
            }
        }
        // Keep the old record k (cheaper to always keep it than to ask
        // whether it moves forward): slot k mod ring last held record
        // k − ring, which moved by less than `ring`, so it is placed.
        let old = p[k];
        aside.ring[k & mask] = old;
        if let Some(&(from, rank)) = aside.far_from.get(next_from) {
            if from as usize == k {
                aside.far[rank as usize] = old;
                next_from += 1;
            }
        }
        let s = order[k] as usize;
        p[k] = if s >= k {
            p[s]
        } else if k - s < ring {
            aside.ring[s & mask]
        } else {
            next_far += 1;
            aside.far[next_far - 1]
        };
        order[k] = k as u32;
    }
    debug_assert_eq!(next_far, aside.far.len());
}

/// Asks the cache for the record at `p`, both its first and its last byte
/// (a 32- or 48-byte record may straddle two cache lines). A hint only (no
/// effect off x86-64).
#[inline(always)]
pub(super) fn prefetch<T>(p: *const T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch never faults, whatever the address.
    unsafe {
        use core::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        let first = p as *const i8;
        _mm_prefetch(first, _MM_HINT_T0);
        _mm_prefetch(
            first.wrapping_add(std::mem::size_of::<T>() - 1),
            _MM_HINT_T0,
        );
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
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
        // Moves of up to ±reach (the ring should cover about that), and
        // every 500th by up to the whole store (the side list).
        let reach = 1 << 13;
        let n = 40 * reach + 123;
        let mut rng = crate::dsmc::rng::Stream::new(3, 1, 4);
        let mut dest: Vec<(u64, u32)> = (0..n)
            .map(|s| {
                let reach = if s % 500 == 0 { n } else { reach };
                let d = s as i64 + rng.below(2 * reach as u32) as i64 - reach as i64;
                (
                    d.rem_euclid(n as i64) as u64 * n as u64 + s as u64,
                    s as u32,
                )
            })
            .collect();
        dest.sort_unstable();
        let order: Vec<u32> = dest.iter().map(|e| e.1).collect();
        let ring = ring_len(&order).expect("a nearly sorted store uses the ring");
        assert!((reach..=4 * reach).contains(&ring), "{ring}");
        let far = order
            .iter()
            .enumerate()
            .filter(|&(k, &s)| k >= s as usize + ring)
            .count();
        assert!(far > 0 && far < n / 100, "{far}");
        let mut p: Vec<u64> = (0..n as u64).map(|i| 7 * i + 1).collect();
        let want: Vec<u64> = order.iter().map(|&s| 7 * s as u64 + 1).collect();
        let mut o = order.clone();
        let mut aside = Aside::default();
        gather_in_place(&mut p, &mut o, &mut aside);
        assert_eq!(p, want);
        assert!(o.iter().enumerate().all(|(i, &d)| d as usize == i));
        assert_eq!((aside.ring.len(), aside.far.len()), (ring, far));
        // A store in no order: the cycles are followed instead.
        let mut shuffled: Vec<u32> = (0..n as u32).collect();
        for i in (1..n).rev() {
            shuffled.swap(i, rng.below(i as u32 + 1) as usize);
        }
        assert_eq!(ring_len(&shuffled), None);
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
