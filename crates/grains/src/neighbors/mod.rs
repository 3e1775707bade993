//! Neighbour search: periodic cell grid, Verlet lists with a skin, spatial sorting.
