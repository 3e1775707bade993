//! The host's parts of the list build: prefix sums, cell bins (both as the
//! device computes them), and the full list of the CPU engine's half list
//! (when a pipeline starts from a CPU state).

use super::grain_kernels::{Bins, FullList, Grid, Soa3};
use crate::dim::D3;
use crate::neighbors::ListState;
use glam::DVec3;

/// `counts` followed by their exclusive prefix sums' total: entry k is the
/// sum of the counts before k (n + 1 entries).
pub fn exclusive_scan(counts: &[u32]) -> Vec<u32> {
    let mut start = Vec::with_capacity(counts.len() + 1);
    let mut sum = 0u32;
    start.push(0);
    for &c in counts {
        sum += c;
        start.push(sum);
    }
    start
}

/// A full list with `count[g]` empty entries in grain g's row: the scan
/// step of a count–scan–fill build, rows ready for the fill.
pub fn empty_rows(count: &[u32]) -> FullList {
    let start = exclusive_scan(count);
    let total = start[count.len()] as usize;
    FullList {
        start,
        partner: vec![0; total],
        image: vec![0; total],
    }
}

/// Bins the grains into `grid`'s cells, count–scan–fill, each cell's
/// members then sorted by rank (on the GPU the fill's order depends on
/// the threads; the sort makes the bins a function of the positions, and
/// the order within a cell the CPU engine's).
pub fn bin(grid: &Grid, pos: &Soa3, rank: &[u32]) -> Bins {
    let n = pos.len();
    let cell: Vec<u32> = (0..n).map(|i| grid.cell_of(pos.get(i)) as u32).collect();
    let mut count = vec![0u32; grid.ncells()];
    for &c in &cell {
        count[c as usize] += 1;
    }
    let start = exclusive_scan(&count);
    let mut cursor = start.clone();
    let mut members = vec![0u32; n];
    for (i, &c) in cell.iter().enumerate() {
        members[cursor[c as usize] as usize] = i as u32;
        cursor[c as usize] += 1;
    }
    for c in 0..grid.ncells() {
        let m = &mut members[start[c] as usize..start[c + 1] as usize];
        for k in 1..m.len() {
            let x = m[k];
            let mut j = k;
            while j > 0 && rank[m[j - 1] as usize] > rank[x as usize] {
                m[j] = m[j - 1];
                j -= 1;
            }
            m[j] = x;
        }
    }
    Bins {
        start,
        members,
        cell,
    }
}

/// The full list of a half list (pairs (i, j), i < j, grouped by i), rows
/// in the order of [`super::grain_kernels::row_key`], with the springs.
pub(super) fn full_from_half(
    half: &ListState<D3>,
    springs: &[DVec3],
    n: usize,
    block: usize,
) -> (FullList, Soa3) {
    let mut count = vec![0u32; n];
    for &[i, j] in &half.pairs {
        count[i as usize] += 1;
        count[j as usize] += 1;
    }
    let mut list = empty_rows(&count);
    // The spring of each entry, as the pair's index in the half list, so
    // that the rows can be ordered first and the springs placed after.
    let mut cursor = list.start.clone();
    let mut pair_of = vec![0u32; list.partner.len()];
    for (k, &[i, j]) in half.pairs.iter().enumerate() {
        for (g, p) in [(i, j), (j, i)] {
            let e = cursor[g as usize] as usize;
            list.partner[e] = p;
            list.image[e] = half.image[k];
            pair_of[e] = k as u32;
            cursor[g as usize] += 1;
        }
    }
    // Rows are in ascending partner order for lower partners and in list
    // order for higher ones: the stable order puts them in place. The
    // pair index moves with its entry through a lookup by partner.
    for g in 0..n {
        let r = list.row(g);
        let mut row: Vec<(u32, u8, u32)> = r
            .clone()
            .map(|e| (list.partner[e], list.image[e], pair_of[e]))
            .collect();
        row.sort_by_key(|&(p, _, _)| super::grain_kernels::row_key(g, p as usize, block));
        for (e, (p, code, k)) in r.zip(row) {
            list.partner[e] = p;
            list.image[e] = code;
            pair_of[e] = k;
        }
    }
    let springs = Soa3::from_vecs(pair_of.iter().map(|&k| springs[k as usize].to_array()));
    (list, springs)
}

/// The re-sort's permutation from the sort grid's bins (members by rank):
/// the CPU engine's new order is the bins read cell by cell, so a grain's
/// new rank is its place q there; it is stored at its cell's start in the
/// cells' `place` order (Morton, or the cells' own for the CPU's order)
/// plus its place within the cell. Returns the old index of each stored
/// grain and its new rank. On the device: one thread per cell for the
/// counts in place order, a scan, one thread per q.
pub fn sort_slots(b: &Bins, place: &[u32]) -> (Vec<u32>, Vec<u32>) {
    let ncells = b.start.len() - 1;
    let mut counts = vec![0u32; ncells];
    for c in 0..ncells {
        counts[place[c] as usize] = b.start[c + 1] - b.start[c];
    }
    let first = exclusive_scan(&counts);
    let n = b.members.len();
    let (mut order, mut rank) = (vec![0u32; n], vec![0u32; n]);
    for (q, &k) in b.members.iter().enumerate() {
        let c = b.cell[k as usize] as usize;
        let slot = (first[place[c] as usize] + q as u32 - b.start[c]) as usize;
        order[slot] = k;
        rank[slot] = q as u32;
    }
    (order, rank)
}
