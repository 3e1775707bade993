//! Neighbour search: periodic cell grid, Verlet lists with a skin, spatial sorting.
//!
//! [`NeighborList`] finds every pair of grains that may touch before the next
//! rebuild; [`spatial_sort_order`] orders particles by cell so that the pair
//! loop stays cache friendly.

mod cell_grid;
mod spatial_sort;
mod verlet_list;

pub(crate) use cell_grid::GridShape;
pub use spatial_sort::spatial_sort_order;
pub use verlet_list::{ListState, NeighborList};
