//! The simulation box: bounds and, per axis, whether it is periodic.
//!
//! On a periodic axis positions are wrapped into `[lo, hi)` (at neighbour-list
//! rebuilds only, so that the image code stored with each pair stays valid).
//! On a non-periodic axis the bounds only size the cell grid: particles may
//! leave them (an open top), and the grid clamps them into its edge cells.

use crate::dim::Dim;

#[derive(Clone, Debug, PartialEq)]
pub struct Domain<D: Dim> {
    pub lo: D::V,
    pub hi: D::V,
    /// Periodicity per axis; entries beyond `D::D` are ignored.
    pub periodic: [bool; 3],
}

impl<D: Dim> Domain<D> {
    pub fn new(lo: D::V, hi: D::V, periodic: [bool; 3]) -> Self {
        Self { lo, hi, periodic }
    }

    pub fn length(&self, axis: usize) -> f64 {
        D::get(self.hi, axis) - D::get(self.lo, axis)
    }

    pub fn is_periodic(&self, axis: usize) -> bool {
        axis < D::D && self.periodic[axis]
    }

    /// Volume (area in 2D) of the box.
    pub fn volume(&self) -> f64 {
        (0..D::D).map(|a| self.length(a)).product()
    }

    /// Maps a position into the primary box along periodic axes.
    pub fn wrap(&self, mut p: D::V) -> D::V {
        for a in 0..D::D {
            if self.is_periodic(a) {
                let lo = D::get(self.lo, a);
                let l = self.length(a);
                let mut x = D::get(p, a);
                if x < lo || x >= lo + l {
                    x -= l * ((x - lo) / l).floor();
                    // Guard against x == lo + l after rounding.
                    if x >= lo + l {
                        x -= l;
                    }
                    D::set(&mut p, a, x);
                }
            }
        }
        p
    }

    /// The shortest periodic image of a separation vector.
    pub fn minimum_image(&self, mut d: D::V) -> D::V {
        for a in 0..D::D {
            if self.is_periodic(a) {
                let l = self.length(a);
                let x = D::get(d, a);
                D::set(&mut d, a, x - l * (x / l).round());
            }
        }
        d
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::D2;
    use glam::DVec2;

    #[test]
    fn wrap_and_minimum_image() {
        let d = Domain::<D2>::new(DVec2::ZERO, DVec2::new(10.0, 5.0), [true, false, false]);
        assert_eq!(d.wrap(DVec2::new(-0.5, 7.0)), DVec2::new(9.5, 7.0));
        assert_eq!(d.wrap(DVec2::new(23.0, -1.0)), DVec2::new(3.0, -1.0));
        assert_eq!(d.minimum_image(DVec2::new(9.0, 4.0)), DVec2::new(-1.0, 4.0));
    }
}
