//! Spatial sorting: reorder particles so that grains close in space are close
//! in memory. The force loop then touches fewer cache lines per pair, and the
//! neighbour list's pairs (grouped by first index) walk memory mostly forward.

use super::cell_grid::GridShape;
use crate::dim::Dim;
use crate::domain::Domain;

/// A permutation (entry k = old index) ordering particles by their cell of
/// side `cell` (linear cell index with x fastest, then y, then z), stable
/// within a cell, for cache locality.
///
/// Cells are at least `cell` wide (each axis is split into a whole number of
/// cells). Positions on periodic axes are wrapped first; on other axes grains
/// outside the domain are clamped into the edge cells. Apply the result with
/// [`Particles::permute`](crate::particles::Particles::permute).
pub fn spatial_sort_order<D: Dim>(pos: &[D::V], domain: &Domain<D>, cell: f64) -> Vec<u32> {
    assert!(pos.len() < u32::MAX as usize, "too many particles to sort");
    // No cell arrays are allocated here, so the cell count need not be capped.
    let shape = GridShape::new(domain, cell, usize::MAX);
    // (cell, index) keys are distinct, so an unstable sort gives the stable order.
    let mut keyed: Vec<(usize, u32)> = pos
        .iter()
        .enumerate()
        .map(|(i, &p)| (shape.cell_of::<D>(domain.wrap(p)), i as u32))
        .collect();
    keyed.sort_unstable();
    keyed.into_iter().map(|(_, i)| i).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::D2;
    use glam::DVec2;
    use rand::{Rng, SeedableRng};

    #[test]
    fn order_is_a_permutation_grouped_by_cell() {
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(3);
        // x: 10 long, cell 1.5 → 6 cells of 10/6; y periodic, 4 long → 2 cells of 2.
        let domain = Domain::<D2>::new(DVec2::ZERO, DVec2::new(10.0, 4.0), [false, true, false]);
        let pos: Vec<DVec2> = (0..500)
            .map(|_| DVec2::new(rng.gen_range(-2.0..12.0), rng.gen_range(-4.0..8.0)))
            .collect();
        let order = spatial_sort_order::<D2>(&pos, &domain, 1.5);
        let mut seen = order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..pos.len() as u32).collect::<Vec<_>>());
        let key = |i: u32| {
            let p = pos[i as usize];
            let cx = ((p.x / (10.0 / 6.0)).floor()).clamp(0.0, 5.0) as usize;
            let cy = (p.y / 2.0).floor().rem_euclid(2.0) as usize;
            cx + 6 * cy
        };
        for w in order.windows(2) {
            let (a, b) = (key(w[0]), key(w[1]));
            assert!(
                a < b || (a == b && w[0] < w[1]),
                "not grouped by cell, stably"
            );
        }
        assert_eq!(key(order[0]), 0);
    }
}
