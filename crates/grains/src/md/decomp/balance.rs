//! Load balance of the MD subdomains: cuts placed by grain count without
//! any rank seeing every coordinate.
//!
//! Each rank histograms the cut coordinate of its own grains; the
//! histograms are summed over the ranks (`sum_u64`, exact), and a cut goes
//! to the bin edge below which the wanted number of grains lies. A second,
//! equally fine histogram inside each bin that holds a cut refines it, so
//! the cuts are good to (box length) / `BINS`² while the messages stay a few
//! thousand integers whatever the grain count.

use crate::comm::Comm;

/// Bins of each of the two histogram passes.
pub const BINS: usize = 1024;

/// max/mean − 1 of per-rank grain counts (0 when there are no grains).
pub fn imbalance(counts: &[u64]) -> f64 {
    let total: u64 = counts.iter().sum();
    let max = counts.iter().copied().max().unwrap_or(0);
    if total == 0 {
        return 0.0;
    }
    max as f64 * counts.len() as f64 / total as f64 - 1.0
}

fn bin_of(x: f64, lo: f64, width: f64) -> usize {
    (((x - lo) / width).floor().max(0.0) as usize).min(BINS - 1)
}

/// The `parts − 1` inner cuts of [lo, hi] that split each of `groups`
/// groups of grains into `parts` runs of about equal count. `items()`
/// yields (group, coordinate) for this rank's grains (coordinates outside
/// [lo, hi] count at the ends). All ranks call this with the same
/// arguments but their own grains. A group without grains is cut evenly.
pub fn cuts_by_count<I>(
    comm: &dyn Comm,
    groups: usize,
    parts: usize,
    (lo, hi): (f64, f64),
    items: impl Fn() -> I,
) -> Vec<Vec<f64>>
where
    I: Iterator<Item = (usize, f64)>,
{
    let inner = parts.saturating_sub(1);
    let width = (hi - lo) / BINS as f64;
    let mut coarse = vec![0u64; groups * BINS];
    for (g, x) in items() {
        coarse[g * BINS + bin_of(x, lo, width)] += 1;
    }
    comm.sum_u64(&mut coarse);
    // For each cut: its coarse bin and how many grains of that bin lie below it.
    let mut at = vec![(0usize, 0u64); groups * inner];
    for g in 0..groups {
        let h = &coarse[g * BINS..(g + 1) * BINS];
        let total: u64 = h.iter().sum();
        for k in 1..parts {
            let target = (k as u64 * total).div_ceil(parts as u64);
            let (mut below, mut b) = (0u64, 0usize);
            while b + 1 < BINS && below + h[b] < target {
                below += h[b];
                b += 1;
            }
            at[g * inner + k - 1] = (b, target - below.min(target));
        }
    }
    let mut fine = vec![0u64; groups * inner * BINS];
    let sub = width / BINS as f64;
    for (g, x) in items() {
        let b = bin_of(x, lo, width);
        for k in 0..inner {
            if at[g * inner + k].0 == b {
                let edge = lo + b as f64 * width;
                fine[(g * inner + k) * BINS + bin_of(x, edge, sub)] += 1;
            }
        }
    }
    comm.sum_u64(&mut fine);
    (0..groups)
        .map(|g| {
            let total: u64 = coarse[g * BINS..(g + 1) * BINS].iter().sum();
            (0..inner)
                .map(|k| {
                    if total == 0 {
                        return lo + (hi - lo) * (k + 1) as f64 / parts as f64;
                    }
                    let (b, need) = at[g * inner + k];
                    let edge = lo + b as f64 * width;
                    if need == 0 {
                        return edge;
                    }
                    let h = &fine[(g * inner + k) * BINS..(g * inner + k + 1) * BINS];
                    let (mut below, mut j) = (0u64, 0usize);
                    while j + 1 < BINS && below + h[j] < need {
                        below += h[j];
                        j += 1;
                    }
                    edge + (j + 1) as f64 * sub
                })
                .collect()
        })
        .collect()
}

/// Moves `cuts` (increasing, inside [lo, hi]) as little as needed for every
/// part, the end ones included, to be at least `min_width` wide. Possible
/// when hi − lo ≥ parts × min_width (the grid choice makes sure of it).
pub fn keep_min_width(cuts: &mut [f64], (lo, hi): (f64, f64), min_width: f64) {
    let mut prev = lo;
    for c in cuts.iter_mut() {
        *c = c.max(prev + min_width);
        prev = *c;
    }
    let mut next = hi;
    for c in cuts.iter_mut().rev() {
        *c = c.min(next - min_width);
        next = *c;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::comm::{SingleProcess, ThreadComm};

    #[test]
    fn imbalance_is_max_over_mean_minus_one() {
        assert_eq!(imbalance(&[10, 10]), 0.0);
        assert!((imbalance(&[30, 10]) - 0.5).abs() < 1e-15);
        assert_eq!(imbalance(&[0, 0, 0]), 0.0);
    }

    #[test]
    fn cuts_split_grains_spread_over_ranks_by_count() {
        // 3000 grains crowded towards x = 0 (density ∝ (1 − x)²), dealt to
        // 3 ranks round robin: the cuts must give each of 4 parts 750 grains
        // to within the grains of one fine bin (none here: all distinct).
        let xs: Vec<f64> = (0..3000)
            .map(|k| 1.0 - (1.0 - (k as f64 + 0.5) / 3000.0).cbrt())
            .collect();
        let cuts = ThreadComm::run(3, |c| {
            let r = c.rank();
            cuts_by_count(c, 1, 4, (0.0, 1.0), || {
                xs.iter().skip(r).step_by(3).map(|&x| (0, x))
            })
        });
        assert!(cuts.iter().all(|c| c == &cuts[0]));
        let cuts = &cuts[0][0];
        let mut edges = vec![f64::NEG_INFINITY];
        edges.extend(cuts);
        edges.push(f64::INFINITY);
        for w in edges.windows(2) {
            let n = xs.iter().filter(|&&x| x >= w[0] && x < w[1]).count();
            assert_eq!(n, 750, "{cuts:?}");
        }
    }

    #[test]
    fn groups_are_cut_separately_and_empty_ones_evenly() {
        let items = [(0, 0.1), (0, 0.2), (0, 0.3), (0, 0.4), (2, 0.9), (2, 0.95)];
        let cuts = cuts_by_count(&SingleProcess, 3, 2, (0.0, 1.0), || items.iter().copied());
        assert!(cuts[0][0] > 0.2 && cuts[0][0] < 0.3, "{cuts:?}");
        assert_eq!(cuts[1], vec![0.5]);
        assert!(cuts[2][0] > 0.9 && cuts[2][0] < 0.95, "{cuts:?}");
    }

    #[test]
    fn narrow_parts_are_widened() {
        let mut cuts = vec![0.05, 0.06, 0.9];
        keep_min_width(&mut cuts, (0.0, 1.0), 0.2);
        assert_eq!(cuts, vec![0.2, 0.4, 0.8]);
    }
}
