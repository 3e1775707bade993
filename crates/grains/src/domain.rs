//! The simulation box: bounds and, per axis, whether it is periodic.
//!
//! On a periodic axis positions are wrapped into `[lo, hi)` (at neighbour-list
//! rebuilds only, so that the image code stored with each pair stays valid).
//! On a non-periodic axis the bounds only size the cell grid: particles may
//! leave them (an open top), and the grid clamps them into its edge cells.
//!
//! A sheared box ([`Shear`]) has Lees–Edwards boundaries (Lees & Edwards
//! 1972): the images across the gradient axis slide along the shear axis
//! at the velocity jump γ̇ L_g, offset by Δ(t) = γ̇ L_g t (mod L_shear).

use crate::dim::Dim;

/// Lees–Edwards shear of a box periodic on both its axes: the image above
/// the box (one gradient length up) moves at `rate · L_g` along `axis`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shear {
    /// The axis the images slide along (the flow direction).
    pub axis: usize,
    /// The axis across which they slide (the velocity gradient).
    pub gradient: usize,
    /// Shear rate γ̇ (1/time).
    pub rate: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Domain<D: Dim> {
    pub lo: D::V,
    pub hi: D::V,
    /// Periodicity per axis; entries beyond `D::D` are ignored.
    pub periodic: [bool; 3],
    /// Lees–Edwards boundaries, if the box is sheared.
    pub shear: Option<Shear>,
    /// The time and image offset from which a sheared box's offset grows
    /// at γ̇ L_g: (0, 0) unless the gradient length changed (a box at fixed
    /// pressure), so that the offset stays continuous when L_g does.
    pub slide_origin: [f64; 2],
}

impl<D: Dim> Domain<D> {
    pub fn new(lo: D::V, hi: D::V, periodic: [bool; 3]) -> Self {
        Self {
            lo,
            hi,
            periodic,
            shear: None,
            slide_origin: [0.0; 2],
        }
    }

    /// The velocity jump γ̇ L_g of the image above the box (0 unsheared).
    pub fn shear_jump(&self) -> f64 {
        self.shear.map_or(0.0, |s| s.rate * self.length(s.gradient))
    }

    /// The image offset at time `t` as a whole number of shear lengths
    /// taken off and the rest, Δ(t) = Δ_0 + γ̇ L_g (t − t_0) − turns · L_s
    /// with (t_0, Δ_0) the [`Domain::slide_origin`], in
    /// [−L_s/2, L_s/2] (so that a cell search near it needs one image on
    /// each side); (0, 0) unsheared.
    pub fn shear_offset(&self, t: f64) -> (f64, f64) {
        match self.shear {
            None => (0.0, 0.0),
            Some(s) => {
                let [since, base] = self.slide_origin;
                // With the origin (0, 0) this is γ̇ L_g t to the bit.
                let total = base + self.shear_jump() * (t - since);
                let l = self.length(s.axis);
                let turns = (total / l).round();
                (turns, total - turns * l)
            }
        }
    }

    /// [`Domain::wrap`] under Lees–Edwards boundaries with image offset
    /// `offset`: a grain leaving through the top re-enters at the bottom
    /// shifted by −Δ along the shear axis with its velocity less the jump
    /// (the opposite through the bottom); then every periodic axis wraps.
    pub fn wrap_sheared(&self, p: &mut D::V, v: &mut D::V, offset: f64) {
        if let Some(s) = self.shear {
            let (g, a) = (s.gradient, s.axis);
            let lo = D::get(self.lo, g);
            let l = self.length(g);
            let y = D::get(*p, g);
            if y < lo || y >= lo + l {
                let k = ((y - lo) / l).floor();
                D::set(p, g, y - k * l);
                D::set(p, a, D::get(*p, a) - k * offset);
                D::set(v, a, D::get(*v, a) - k * self.shear_jump());
            }
        }
        *p = self.wrap(*p);
    }

    /// [`Domain::minimum_image`] of `d = p_i − p_j` under Lees–Edwards
    /// boundaries with image offset `offset`, with the images' velocity
    /// jump: the separation and what to subtract from `v_i − v_j`.
    pub fn minimum_image_sheared(&self, mut d: D::V, offset: f64) -> (D::V, D::V) {
        let mut dv = D::zero();
        if let Some(s) = self.shear {
            let l = self.length(s.gradient);
            let k = (D::get(d, s.gradient) / l).round();
            let (dg, dx) = (D::get(d, s.gradient), D::get(d, s.axis));
            D::set(&mut d, s.gradient, dg - k * l);
            D::set(&mut d, s.axis, dx - k * offset);
            D::set(&mut dv, s.axis, k * self.shear_jump());
        }
        (self.minimum_image(d), dv)
    }

    /// Stretches a sheared box along its gradient axis by `factor` about
    /// its lower bound at time `t`, the image offset carried on from its
    /// value at `t` (the grains are the caller's to move).
    pub fn stretch_gradient(&mut self, factor: f64, t: f64) {
        let Some(s) = self.shear else {
            return;
        };
        let (_, offset) = self.shear_offset(t);
        self.slide_origin = [t, offset];
        let lo = D::get(self.lo, s.gradient);
        let l = self.length(s.gradient);
        D::set(&mut self.hi, s.gradient, lo + l * factor);
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

    /// A grain through the top comes back at the bottom shifted by −Δ along
    /// x with its x velocity less γ̇ L_y (Lees & Edwards 1972), exactly.
    #[test]
    fn sheared_wrap_shifts_position_and_velocity() {
        let mut d = Domain::<D2>::new(DVec2::ZERO, DVec2::new(10.0, 4.0), [true, true, false]);
        d.shear = Some(Shear {
            axis: 0,
            gradient: 1,
            rate: 0.5,
        });
        assert_eq!(d.shear_jump(), 2.0);
        // γ̇ L t = 2 × 3.25 = 6.5 = 1 × 10 − 3.5.
        assert_eq!(d.shear_offset(3.25), (1.0, -3.5));
        let (mut p, mut v) = (DVec2::new(2.0, 4.25), DVec2::new(1.0, 0.5));
        d.wrap_sheared(&mut p, &mut v, 1.5);
        assert_eq!((p, v), (DVec2::new(0.5, 0.25), DVec2::new(-1.0, 0.5)));
        let (mut p, mut v) = (DVec2::new(9.0, -0.25), DVec2::new(1.0, 0.5));
        d.wrap_sheared(&mut p, &mut v, 1.5);
        assert_eq!((p, v), (DVec2::new(0.5, 3.75), DVec2::new(3.0, 0.5)));
        // A pair across the top: j near the bottom, its image up by L and
        // along by Δ, moving at +2 along x.
        let (sep, dv) = d.minimum_image_sheared(DVec2::new(1.0, 3.5), 1.5);
        assert_eq!((sep, dv), (DVec2::new(-0.5, -0.5), DVec2::new(2.0, 0.0)));
    }

    /// Stretching the gradient axis keeps the image offset continuous and
    /// then lets it grow at the new jump γ̇ L_g'.
    #[test]
    fn stretched_box_carries_the_offset_on() {
        let mut d = Domain::<D2>::new(DVec2::ZERO, DVec2::new(10.0, 4.0), [true, true, false]);
        d.shear = Some(Shear {
            axis: 0,
            gradient: 1,
            rate: 0.5,
        });
        // Δ(1) = 2, then L_g = 8 and the jump is 4: Δ(1.5) = 2 + 4 × 0.5.
        d.stretch_gradient(2.0, 1.0);
        assert_eq!(d.hi, DVec2::new(10.0, 8.0));
        assert_eq!(d.shear_offset(1.0), (0.0, 2.0));
        assert_eq!(d.shear_offset(1.5), (0.0, 4.0));
    }
}
